"""One-look statistics of a mesh."""

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import MeshValidityError
from ..mesh.topology import boundary_edges
from .tetra import tetra_summary
from .triangle import triangle_quality

__all__ = ["POOR_QUALITY", "QualitySummary", "summary"]

POOR_QUALITY = 0.5
"""Triangle quality ``q`` below which a cell counts as poor (``n_below_0_5``, the guide's threshold)."""


@dataclass(frozen=True)
class QualitySummary:
    """Counts and quality statistics of a triangle mesh.

    ``mean_minus_3std`` above 0.75 is the OceanMesh2D guide's "high quality"
    bar (§2.2).
    """

    n_vertices: int
    n_cells: int
    n_boundary_edges: int
    mean: float
    mean_minus_3std: float
    min: float
    n_below_0_5: int
    n_inverted: int

    def as_dict(self):
        """The fields as a plain dict."""
        return asdict(self)

    def __str__(self):
        return (
            f"vertices {self.n_vertices:,}  cells {self.n_cells:,}  boundary edges {self.n_boundary_edges:,}\n"
            f"quality q: mean {self.mean:.4f}  mean-3std {self.mean_minus_3std:.4f}  min {self.min:.4f}  "
            f"cells q<0.5: {self.n_below_0_5:,}  inverted: {self.n_inverted:,}"
        )


def summary(mesh):
    """Counts and quality statistics of a triangle or tetrahedral mesh.

    For triangles, the distribution of the quality ``q`` (guide eq. 1); for
    tetrahedra, dihedral angles and radius ratios (:func:`tetra_summary`).

    Parameters
    ----------
    mesh : terramesh.Mesh
        A 2-D triangle mesh (``(m, 3)`` cells) or a tetrahedral mesh
        (``(m, 4)`` cells). Longitude-latitude triangle meshes (``mesh.crs``
        geographic) are measured on the ground (see :func:`triangle_quality`).

    Returns
    -------
    QualitySummary or TetraQualitySummary
        For triangles a :class:`QualitySummary`: mean, mean minus three
        standard deviations and minimum of ``q``, plus vertex, cell,
        boundary-edge, poor-cell (q < 0.5) and inverted-cell counts. For
        tetrahedra a :class:`~terramesh.quality.TetraQualitySummary`:
        dihedral angles, radius ratios, boundary-face, sliver (below 10
        degrees) and inverted-cell counts.

    Raises
    ------
    MeshValidityError
        For triangles in 3-D space (a surface), which have no quality ``q``.

    Examples
    --------
    >>> import numpy as np
    >>> import terramesh as tm
    >>> square = tm.Mesh(np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]]), np.array([[0, 1, 2], [0, 2, 3]]))
    >>> round(tm.quality.summary(square).min, 4)
    0.866
    >>> corner = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> type(tm.quality.summary(tm.Mesh(corner, np.array([[0, 1, 2, 3]])))).__name__
    'TetraQualitySummary'
    """
    if mesh.cells.shape[1] == 4:
        return tetra_summary(mesh)
    if mesh.dim != 2:
        raise MeshValidityError(
            f"summary measures triangles in 2-D and tetrahedra; this mesh has triangles with {mesh.dim}-D points"
            " (a surface), which have no quality q: give its 2-D coordinates, e.g."
            " tm.Mesh(mesh.points[:, :2], mesh.cells) for one in the x-y plane"
        )
    quality = triangle_quality(mesh.points, mesh.cells, geographic=mesh.geographic)
    empty = quality.size == 0
    return QualitySummary(
        n_vertices=mesh.n_points,
        n_cells=mesh.n_cells,
        n_boundary_edges=len(boundary_edges(mesh.cells)) if not empty else 0,
        mean=float(quality.mean()) if not empty else float("nan"),
        mean_minus_3std=float(quality.mean() - 3 * quality.std()) if not empty else float("nan"),
        min=float(quality.min()) if not empty else float("nan"),
        n_below_0_5=int(np.sum(quality < POOR_QUALITY)),
        n_inverted=int(np.sum(quality <= 0)),
    )
