"""Quality measures of tetrahedra: dihedral angles, radius ratio, volume.

The public functions are vectorised NumPy; the per-tetrahedron kernels at the
bottom (numba, private) serve the 3D generator's sliver removal, and the tests
check them against the NumPy versions. All measures are scale-invariant.
"""

from dataclasses import asdict, dataclass

import numba
import numpy as np

from ..errors import MeshValidityError
from ..mesh.topology import checked_cells, checked_points

__all__ = [
    "tetra_volumes",
    "dihedral_angles",
    "min_max_dihedral",
    "radius_ratio",
    "tetra_summary",
    "TetraQualitySummary",
]

# the edge shared by the faces opposite corners k and l joins the other two corners;
# rows: (k, l) face pair, then the edge (i, j) it is the dihedral angle of
_FACE_PAIRS = np.array([(2, 3), (1, 3), (1, 2), (0, 3), (0, 2), (0, 1)])
_EDGES = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])


def _corners(points, cells):
    """The four corner coordinate arrays, after checking shapes and indices (MeshValidityError)."""
    points = checked_points(points, 3)
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
    a, b, c, d = _corners(points, cells)
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6.0


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
    ``a, b, c`` the edges from the fourth vertex and ``l`` their lengths.

    Examples
    --------
    >>> import numpy as np
    >>> regular = np.array([[1.0, 1, 1], [-1, 1, -1], [1, -1, -1], [-1, -1, 1]])
    >>> radius_ratio(regular, np.array([[0, 1, 2, 3], [0, 2, 1, 3]])).round(12).tolist()
    [1.0, -1.0]
    """
    a, b, c, d = _corners(points, cells)
    u, v, w = a - d, b - d, c - d
    six_volume = -np.einsum("ij,ij->i", u, np.cross(v, w))  # (a - d) . ((b - d) x (c - d)) is -6 V
    areas = sum(0.5 * np.sqrt(np.einsum("ij,ij->i", n, n)) for n in _inward_normals(a, b, c, d))
    lifted = (
        np.einsum("ij,ij->i", u, u)[:, None] * np.cross(v, w)
        + np.einsum("ij,ij->i", v, v)[:, None] * np.cross(w, u)
        + np.einsum("ij,ij->i", w, w)[:, None] * np.cross(u, v)
    )
    lifted = np.sqrt(np.einsum("ij,ij->i", lifted, lifted))
    # 3 r_in / r_circ = 3 (3 V / A) (12 V / |lifted|) = 108 V^2 / (A |lifted|), V = six_volume / 6
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = 3.0 * six_volume * np.abs(six_volume) / (areas * lifted)
    return np.where((areas > 0) & (lifted > 0), ratio, 0.0)


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
    faces = np.sort(np.concatenate([np.delete(cells, k, axis=1) for k in range(4)]), axis=1)
    _, counts = np.unique(faces, axis=0, return_counts=True)
    return TetraQualitySummary(
        n_vertices=mesh.n_points,
        n_cells=len(cells),
        n_boundary_faces=int(np.sum(counts == 1)),
        min_dihedral=float(smallest.min()),
        mean_min_dihedral=float(smallest.mean()),
        max_dihedral=float(largest.max()),
        min_radius_ratio=float(ratio.min()),
        mean_radius_ratio=float(ratio.mean()),
        n_below_10_degrees=int(np.sum(smallest < 10.0)),
        n_inverted=int(np.sum(tetra_volumes(points, cells) <= 0)),
    )


# --- kernels for the generator (no validation) ---------------------------------------------


@numba.njit(cache=True, inline="always")
def _cross(ux, uy, uz, vx, vy, vz):
    return uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx


@numba.njit(cache=True)
def _tet_largest_cosine(points, a, b, c, d):
    """Cosine of the smallest dihedral angle of the tetrahedron ``a, b, c, d``; 2.0 when it is not positive."""
    ax, ay, az = points[a, 0], points[a, 1], points[a, 2]
    bx, by, bz = points[b, 0] - ax, points[b, 1] - ay, points[b, 2] - az
    cx, cy, cz = points[c, 0] - ax, points[c, 1] - ay, points[c, 2] - az
    dx, dy, dz = points[d, 0] - ax, points[d, 1] - ay, points[d, 2] - az
    # inward area normals of the faces opposite a, b, c, d (they sum to zero)
    n3x, n3y, n3z = _cross(bx, by, bz, cx, cy, cz)
    volume = n3x * dx + n3y * dy + n3z * dz
    if not volume > 0.0:
        return 2.0
    n1x, n1y, n1z = _cross(cx, cy, cz, dx, dy, dz)
    n2x, n2y, n2z = _cross(dx, dy, dz, bx, by, bz)
    n0x, n0y, n0z = -(n1x + n2x + n3x), -(n1y + n2y + n3y), -(n1z + n2z + n3z)
    l0 = np.sqrt(n0x * n0x + n0y * n0y + n0z * n0z)
    l1 = np.sqrt(n1x * n1x + n1y * n1y + n1z * n1z)
    l2 = np.sqrt(n2x * n2x + n2y * n2y + n2z * n2z)
    l3 = np.sqrt(n3x * n3x + n3y * n3y + n3z * n3z)
    if l0 == 0.0 or l1 == 0.0 or l2 == 0.0 or l3 == 0.0:
        return 1.0
    # the dihedral angle at the edge shared by the faces opposite k and l: cos = -n_k . n_l / (|n_k| |n_l|)
    largest = -(n0x * n1x + n0y * n1y + n0z * n1z) / (l0 * l1)
    largest = max(largest, -(n0x * n2x + n0y * n2y + n0z * n2z) / (l0 * l2))
    largest = max(largest, -(n0x * n3x + n0y * n3y + n0z * n3z) / (l0 * l3))
    largest = max(largest, -(n1x * n2x + n1y * n2y + n1z * n2z) / (l1 * l2))
    largest = max(largest, -(n1x * n3x + n1y * n3y + n1z * n3z) / (l1 * l3))
    largest = max(largest, -(n2x * n3x + n2y * n3y + n2z * n3z) / (l2 * l3))
    return min(largest, 1.0)


@numba.njit(cache=True)
def _tet_min_dihedral(points, a, b, c, d):
    """Smallest dihedral angle (degrees) of the tetrahedron ``a, b, c, d``; -1 when it is not positively oriented."""
    cosine = _tet_largest_cosine(points, a, b, c, d)
    if cosine > 1.0:
        return -1.0
    return np.degrees(np.arccos(cosine))


@numba.njit(cache=True)
def _min_dihedral_all(points, cells):
    """:func:`_tet_min_dihedral` of every cell, shape (m,)."""
    out = np.empty(cells.shape[0])
    for t in range(cells.shape[0]):
        out[t] = _tet_min_dihedral(points, cells[t, 0], cells[t, 1], cells[t, 2], cells[t, 3])
    return out
