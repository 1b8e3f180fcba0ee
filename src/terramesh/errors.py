"""Exceptions and warnings raised by terramesh.

Every error terramesh raises on purpose derives from :class:`TerrameshError`.
Errors caused by bad user input also derive from :class:`ValueError`, so code
written against plain Python conventions (``except ValueError``) catches them.
"""

__all__ = [
    "TerrameshError",
    "GeometryError",
    "SizingError",
    "GenerationError",
    "MeshValidityError",
    "MeshFormatError",
    "ForcingError",
    "TerrameshWarning",
]


class TerrameshError(Exception):
    """Root of every exception terramesh raises on purpose."""


class GeometryError(TerrameshError, ValueError):
    """A domain (distance function, polygon, bbox) is unusable."""


class SizingError(TerrameshError, ValueError):
    """A mesh size (edge length) function or grid is unusable."""


class GenerationError(TerrameshError, ValueError):
    """Mesh generation was asked for something it cannot do."""


class MeshValidityError(TerrameshError):
    """A mesh breaks one of the validity rules (orientation, conformity, boundary)."""


class MeshFormatError(TerrameshError, ValueError):
    """A file (mesh, DEM, coastline, tidal atlas) is malformed, truncated or of an unknown format."""


class ForcingError(TerrameshError, ValueError):
    """Model forcing or control input (tidal constituents, dates, run options) is unusable."""


class TerrameshWarning(UserWarning):
    """Something the user should know about, but that did not stop the work."""
