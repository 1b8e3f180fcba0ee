"""Exceptions and warnings raised by terramesh.

Every error terramesh raises on purpose derives from :class:`TerrameshError`.
Errors caused by bad user input also derive from :class:`ValueError`, so code
written against plain Python conventions (``except ValueError``) catches them.
"""

import contextlib
import math
import os
import re
import sys
import warnings

import numpy as np

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


class MeshValidityError(TerrameshError, ValueError):
    """A mesh breaks a validity rule (orientation, conformity, boundary), or a mesh operation got a bad option."""


class MeshFormatError(TerrameshError, ValueError):
    """A file (mesh, DEM, coastline, tidal atlas) is malformed, truncated or of an unknown format."""


class ForcingError(TerrameshError, ValueError):
    """Model forcing or control input (tidal constituents, dates, run options) is unusable."""


class TerrameshWarning(UserWarning):
    """Something the user should know about, but that did not stop the work."""


def checked_number(value, requirement, error, *, minimum=-math.inf, strict=False):
    """``value`` as a finite float of at least ``minimum`` (above it with ``strict``).

    A string that reads as a number is taken (the command line's text, a
    file's field); anything else, a bool or None included, raises ``error`` with
    ``"{requirement}, got {value!r}"``: one rule for the options that every
    stage takes as plain numbers, each stage with its own error class.
    """
    number = math.nan
    if not isinstance(value, (bool, np.bool_)):  # float(True) is 1.0: a flag where a number belongs is a mistake
        try:
            number = float(value)
        except (TypeError, ValueError, OverflowError):
            pass
    if not math.isfinite(number) or number < minimum or (strict and number == minimum):
        raise error(f"{requirement}, got {value!r}")
    return number


_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep
_CONTEXTLIB = os.path.abspath(contextlib.__file__)  # a terramesh context manager's exit gives its held warnings


def _passed_through(filename):
    """Whether a frame of ``filename`` is terramesh's own, or contextlib's between two of terramesh's."""
    path = os.path.abspath(filename)
    return path.startswith(_PACKAGE) or path == _CONTEXTLIB


def point_text(point):
    """``point`` for a message: its coordinates to six significant digits, ``(1.5, -2e-07)``."""
    return "(" + ", ".join(f"{float(x):.6g}" for x in point) + ")"


def warn_user(message, category=TerrameshWarning):
    """Warn with ``message``, attributed to the first caller outside terramesh.

    A warning raised deep in a pipeline (``coastal.build`` reading a DEM,
    ``generate_mesh`` handing over to the 3D generator) points at the
    user's line whichever way it was reached; counting a fixed
    ``stacklevel`` by hand was right for one way in only. contextlib's
    frames are passed through too: warnings that a coastal stage held and
    gave again on leaving its ``with`` block pointed at contextlib.py.
    """
    frame, level = sys._getframe(1), 2
    while frame is not None and _passed_through(frame.f_code.co_filename):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level)


@contextlib.contextmanager
def muted_warnings(*words, category=TerrameshWarning):
    """Within the block, ignore the warnings of ``category`` whose message contains any of ``words``.

    ``words`` are the message constants that the warning's own module
    exports (e.g. ``mesh_checks.REACHED_MAX_ITER``), not copies of its text:
    a warning reworded where it is raised stays muted where it is meant to
    be, and no other warning is.

    Examples
    --------
    >>> with muted_warnings("of no interest here"):
    ...     warn_user("a message of no interest here")
    """
    with warnings.catch_warnings():
        for text in words:
            warnings.filterwarnings("ignore", message=".*" + re.escape(text), category=category)
        yield
