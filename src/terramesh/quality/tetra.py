"""Quality measures of tetrahedra: dihedral angles, radius ratio, volume.

Vectorised NumPy, the radius ratio a numba loop over the cells
(:mod:`terramesh._kernels.tetra`, whose per-tetrahedron measures serve the
3D generator's sliver removal and smoothing). All measures are scale-invariant.
Every one refuses NaN or infinite coordinates with a MeshValidityError, as
:class:`~terramesh.Mesh` does: a cell with such a corner has no volume or
angle (it scored 0, a flat cell, or NaN, depending on the measure).
"""

from dataclasses import asdict, dataclass

import numpy as np

from .._kernels.tetra import radius_ratio_all, volumes_all
from ..errors import MeshValidityError
from ..mesh.topology import boundary_faces, checked_cells, checked_points

__all__ = [
    "SLIVER_DEGREES",
    "tetra_volumes",
    "dihedral_angles",
    "min_max_dihedral",
    "radius_ratio",
    "tetra_summary",
    "TetraQualitySummary",
]

SLIVER_DEGREES = 10.0
"""Smallest dihedral angle, degrees, under which a tetrahedron counts as a sliver (``n_below_10_degrees``)."""

# the faces opposite corners k and l meet along the edge joining the other two corners: one row per edge
_FACE_PAIRS = np.array([(2, 3), (1, 3), (1, 2), (0, 3), (0, 2), (0, 1)])


def _corners(points, cells):
    """The four corner coordinate arrays, after checking shapes and indices (MeshValidityError)."""
    points = checked_points(points, 3, finite=True)
    cells = checked_cells(cells, 4, len(points))
    return [points[cells[:, k]] for k in range(4)]


def tetra_volumes(points, cells):
    """Signed volume of each tetrahedron, positive when ``(b - a) . ((c - a) x (d - a)) > 0``.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 3)
        Vertex coordinates, any length unit L.
    cells : numpy.ndarray, shape (m, 4)
        Vertex indices of each tetrahedron.

    Returns
    -------
    numpy.ndarray, shape (m,)
        Volume in L**3; negative for an inverted tetrahedron.

    Examples
    --------
    >>> import numpy as np
    >>> corner = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> tetra_volumes(corner, np.array([[0, 1, 2, 3], [0, 2, 1, 3]])).round(6).tolist()
    [0.166667, -0.166667]
    """
    points = checked_points(points, 3, finite=True)
    return volumes_all(points, checked_cells(cells, 4, len(points)))


def _inward_normals(a, b, c, d):
    """Area-weighted normals of the faces opposite a, b, c, d, pointing at that corner (positive cells)."""
    return [np.cross(d - b, c - b), np.cross(c - a, d - a), np.cross(d - a, b - a), np.cross(b - a, c - a)]


def dihedral_angles(points, cells):
    """The six interior dihedral angles of each tetrahedron, in degrees.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 3)
    cells : numpy.ndarray, shape (m, 4)

    Returns
    -------
    numpy.ndarray, shape (m, 6)
        Angle in degrees (0 to 180) at the edges (0, 1), (0, 2), (0, 3),
        (1, 2), (1, 3), (2, 3) of each cell; a regular tetrahedron has
        70.53 everywhere. The same for a cell and its mirror image (an
        inverted cell); 0 where a face has zero area.

    Examples
    --------
    >>> import numpy as np
    >>> regular = np.array([[1.0, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    >>> dihedral_angles(regular, np.array([[0, 1, 2, 3]])).round(2).tolist()
    [[70.53, 70.53, 70.53, 70.53, 70.53, 70.53]]
    """
    normals = _inward_normals(*_corners(points, cells))
    lengths = [np.sqrt(np.einsum("ij,ij->i", n, n)) for n in normals]
    angles = np.empty((len(normals[0]), 6))
    for column, (first, second) in enumerate(_FACE_PAIRS):
        norm = lengths[first] * lengths[second]
        with np.errstate(invalid="ignore", divide="ignore"):
            cosine = -np.einsum("ij,ij->i", normals[first], normals[second]) / norm
        angles[:, column] = np.where(norm > 0, np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))), 0.0)
    return angles


def min_max_dihedral(points, cells):
    """Smallest and largest dihedral angle of each tetrahedron, in degrees.

    A sliver (four nearly coplanar vertices) has a smallest angle near 0;
    see :func:`dihedral_angles`.

    Returns
    -------
    smallest, largest : numpy.ndarray, shape (m,)

    Examples
    --------
    >>> import numpy as np
    >>> corner = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> [a.round(2).tolist() for a in min_max_dihedral(corner, np.array([[0, 1, 2, 3]]))]
    [[54.74], [90.0]]
    """
    angles = dihedral_angles(points, cells)
    return angles.min(axis=1), angles.max(axis=1)


def radius_ratio(points, cells):
    """Normalised radius ratio ``3 r_in / r_circ`` of each tetrahedron.

    1 for a regular tetrahedron, 0 for a degenerate one, negative (the same
    magnitude) for an inverted one. Scale-invariant.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 3)
    cells : numpy.ndarray, shape (m, 4)

    Returns
    -------
    numpy.ndarray, shape (m,)

    Notes
    -----
    ``r_in = 3 V / (A_1 + A_2 + A_3 + A_4)`` with ``A`` the face areas, and
    ``r_circ = |l_a^2 (b x c) + l_b^2 (c x a) + l_c^2 (a x b)| / (12 V)`` with
    ``a, b, c`` the edges from the first vertex and ``l`` their lengths.

    Examples
    --------
    >>> import numpy as np
    >>> regular = np.array([[1.0, 1, 1], [-1, 1, -1], [1, -1, -1], [-1, -1, 1]])
    >>> radius_ratio(regular, np.array([[0, 1, 2, 3], [0, 2, 1, 3]])).round(12).tolist()
    [1.0, -1.0]
    """
    points = checked_points(points, 3, finite=True)
    return radius_ratio_all(points, checked_cells(cells, 4, len(points)))


@dataclass(frozen=True)
class TetraQualitySummary:
    """Counts and quality statistics of a tetrahedral mesh.

    Angles are in degrees; ``mean_min_dihedral`` is the mean over cells of
    each cell's smallest dihedral angle.
    """

    n_vertices: int
    n_cells: int
    n_boundary_faces: int
    min_dihedral: float
    mean_min_dihedral: float
    max_dihedral: float
    min_radius_ratio: float
    mean_radius_ratio: float
    n_below_10_degrees: int
    n_inverted: int

    def as_dict(self):
        """The fields as a plain dict."""
        return asdict(self)

    def __str__(self):
        return (
            f"vertices {self.n_vertices:,}  cells {self.n_cells:,}  boundary faces {self.n_boundary_faces:,}\n"
            f"dihedral angles: min {self.min_dihedral:.2f}  mean of cell minima {self.mean_min_dihedral:.2f}  "
            f"max {self.max_dihedral:.2f} degrees  cells below 10 degrees: {self.n_below_10_degrees:,}\n"
            f"radius ratio: min {self.min_radius_ratio:.4f}  mean {self.mean_radius_ratio:.4f}  "
            f"inverted: {self.n_inverted:,}"
        )


def tetra_summary(mesh):
    """Counts, dihedral angles and radius ratios of a tetrahedral mesh.

    Parameters
    ----------
    mesh : terramesh.Mesh
        A mesh with ``(m, 4)`` cells.

    Returns
    -------
    TetraQualitySummary

    Raises
    ------
    MeshValidityError
        If the cells are not tetrahedra.

    Examples
    --------
    >>> import numpy as np
    >>> import terramesh as tm
    >>> corner = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> stats = tetra_summary(tm.Mesh(corner, np.array([[0, 1, 2, 3]])))
    >>> round(stats.min_dihedral, 2), stats.n_boundary_faces, stats.n_inverted
    (54.74, 4, 0)
    """
    points, cells = mesh.points, mesh.cells
    if cells.ndim != 2 or cells.shape[1] != 4:
        raise MeshValidityError(f"tetra_summary needs tetrahedra, shape (m, 4); got cells of shape {cells.shape}")
    nan = float("nan")
    if len(cells) == 0:
        return TetraQualitySummary(mesh.n_points, 0, 0, nan, nan, nan, nan, nan, 0, 0)
    smallest, largest = min_max_dihedral(points, cells)
    ratio = radius_ratio(points, cells)
    return TetraQualitySummary(
        n_vertices=mesh.n_points,
        n_cells=len(cells),
        n_boundary_faces=len(boundary_faces(cells)),
        min_dihedral=float(smallest.min()),
        mean_min_dihedral=float(smallest.mean()),
        max_dihedral=float(largest.max()),
        min_radius_ratio=float(ratio.min()),
        mean_radius_ratio=float(ratio.mean()),
        n_below_10_degrees=int(np.sum(smallest < SLIVER_DEGREES)),
        n_inverted=int(np.sum(tetra_volumes(points, cells) <= 0)),
    )
