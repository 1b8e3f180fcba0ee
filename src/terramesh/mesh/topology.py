"""Connectivity of simplicial meshes: edges, boundary facets, neighbours.

All functions take ``cells`` as an ``(m, dim + 1)`` integer array of vertex
indices and are vectorized (sorting and unique, or a numba kernel; no Python
loops over cells).
"""

import numpy as np

from .._kernels.cleanup import neighbor_table
from .._kernels.cleanup import signed_areas as _signed_areas
from .._kernels.delaunay3d import tet_unique_edges
from .._kernels.topology import cell_centroids as _centroids
from .._kernels.topology import first_equal_rows, lone_edges, walk_loops
from ..errors import MeshValidityError
from .columns import fold_columns, rows_all

__all__ = [
    "unique_edges",
    "boundary_edges",
    "boundary_faces",
    "boundary_loops",
    "boundary_vertex_degree",
    "cell_neighbours",
    "signed_areas",
]

NO_INDICES = np.empty(0, dtype=np.int64)  # an empty index array, one rather than one per call


def checked_cells(cells, corners, n_points=None):
    """``cells`` as a C-contiguous int64 ``(m, corners)`` array of indices into ``n_points`` points.

    The numba kernels index without bounds checks, so the public functions
    check here, once per call (O(m), vectorised): an integer array of the
    right width whose indices are at least 0 and, when ``n_points`` is
    given, below it. An empty input of any integer or float dtype is no
    cells. Raises MeshValidityError, as :class:`terramesh.Mesh` does.
    """
    array = np.asarray(cells)
    if array.size == 0 and (array.ndim == 1 or (array.ndim == 2 and array.shape[1] == corners)):
        return np.zeros((0, corners), dtype=np.int64)
    if array.ndim != 2 or array.shape[1] != corners:
        raise MeshValidityError(f"cells must have shape (m, {corners}), got {array.shape}")
    if not np.issubdtype(array.dtype, np.integer):
        raise MeshValidityError(f"cells must be integer vertex indices, got dtype {array.dtype}")
    array = np.ascontiguousarray(array, dtype=np.int64)
    if array.size:
        low, high = int(array.min()), int(array.max())
        if low < 0 or (n_points is not None and high >= n_points):
            bound = f"0 to {n_points - 1}" if n_points is not None else "0 or more"
            raise MeshValidityError(
                f"cells refer to vertices that do not exist: indices {low} to {high}, the points are numbered {bound}"
            )
    return array


def checked_points(points, dim=None, *, finite=False):
    """``points`` as a C-contiguous float64 ``(n, dim)`` array (``dim`` 2 or 3 unless given); else MeshValidityError.

    With ``finite``, NaN or infinite coordinates are refused too, as
    :class:`~terramesh.Mesh` refuses them (the quality measures gave a cell
    with a NaN corner quality 0, flat, without a word). Its smallest and
    largest coordinate tell (1 ms at 10**6 points); the points are counted
    only when one is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> checked_points([[0.0, np.nan], [1.0, 2.0]], 2, finite=True)
    Traceback (most recent call last):
    terramesh.errors.MeshValidityError: coordinates are NaN or infinite at 1 of 2 points (index 0 first)
    """
    try:
        array = None if points is None else np.ascontiguousarray(points, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise MeshValidityError(f"points must be an (n, {dim or 'dim'}) array of numbers") from error
    if array is None:
        raise MeshValidityError(f"points must be an (n, {dim or 'dim'}) array of numbers, got None")
    if array.ndim != 2 or (array.shape[1] != dim if dim is not None else array.shape[1] not in (2, 3)):
        expected = f"(n, {dim})" if dim is not None else "(n, 2) or (n, 3)"
        raise MeshValidityError(f"points must have shape {expected}, got {array.shape}")
    if finite and array.size and not (np.isfinite(array.min()) and np.isfinite(array.max())):
        bad = ~rows_all(np.isfinite(array))
        raise MeshValidityError(
            f"coordinates are NaN or infinite at {int(np.count_nonzero(bad))} of {len(array)} points "
            f"(index {int(np.argmax(bad))} first)"
        )
    return array


def checked_fixed_points(fixed_points, dim, error, units=""):
    """``fixed_points`` as a float64 ``(k, dim)`` array (one point or none taken too); else ``error``.

    One reading of the generator's, the clean-up's and the coastal build's
    fixed points: numbers, ``(k, dim)`` (a flat row of ``k * dim``
    coordinates, a single point among them, is taken too), finite.
    ``units`` names what the numbers are, for the message (``"lon/lat
    degrees, "``).
    """
    try:
        fixed = np.array(fixed_points, dtype=np.float64)
    except (TypeError, ValueError):
        raise error(f"fixed_points must be {units or ''}numbers, shape (k, {dim}), got {fixed_points!r}") from None
    if fixed.ndim <= 1 and fixed.size % dim == 0:  # none, one point, or the points' coordinates in a row
        fixed = fixed.reshape(-1, dim)
    if fixed.ndim != 2 or fixed.shape[1] != dim:
        raise error(f"fixed_points must have shape (k, {dim}), got {fixed.shape}")
    if not np.all(np.isfinite(fixed)):
        raise error("fixed_points has NaN or infinite coordinates")
    return fixed


def sorted_unique(values):
    """The distinct values of an integer array, flattened and ascending: ``np.unique(values)`` by a sort.

    NumPy 2.3 and later find plain ``np.unique``'s values by hashing: 0.88 s
    for the 1.76M edge keys of a 587k-cell mesh and 0.19 s for its cells'
    vertices, where sorting took 0.10 s and 0.10 s (NumPy 2.4.6).

    Examples
    --------
    >>> import numpy as np
    >>> sorted_unique(np.array([[3, 1], [1, 2]])).tolist()
    [1, 2, 3]
    """
    ordered = np.sort(values, axis=None)
    first = np.ones(len(ordered), dtype=bool)
    np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
    return ordered[first]


def _unique_rows(pairs, return_inverse=False):
    """``np.unique(pairs, axis=0)`` for non-negative int pairs, through one int64 key."""
    base = int(pairs.max()) + 1 if pairs.size else 1
    keys = pairs[:, 0].astype(np.int64) * base + pairs[:, 1]
    if not return_inverse:
        unique = sorted_unique(keys)
        return np.column_stack([unique // base, unique % base])
    unique, inverse, counts = np.unique(keys, return_inverse=True, return_counts=True)
    return np.column_stack([unique // base, unique % base]), inverse, counts


def sorted_cell_edges(cells):
    """Every edge of every cell, each row's two vertices ascending, shape (m * k * (k - 1) / 2, 2) for (m, k) cells.

    Edges shared by cells repeat; the rows come corner pair by corner pair
    (all cells' first pair, then all cells' second, ...).
    """
    corners = cells.shape[1]
    pairs = [(i, j) for i in range(corners) for j in range(i + 1, corners)]
    edges = np.concatenate([cells[:, [i, j]] for i, j in pairs])
    edges.sort(axis=1)
    return edges


def with_fixed_points_renumbered(info, new_index):
    """``info`` (a mesh's) with its ``fixed_points`` in a new numbering of the vertices, a copy if it has them.

    ``info["fixed_points"]`` lists the vertex of each fixed point (-1 for
    one the mesh lost): ``new_index[old]`` is each old vertex's new number,
    -1 where it went.

    Examples
    --------
    >>> import numpy as np
    >>> with_fixed_points_renumbered({"fixed_points": np.array([2, -1, 0])}, np.array([1, -1, 0]))
    {'fixed_points': array([ 0, -1,  1])}
    """
    if "fixed_points" not in info:
        return info
    fixed = np.asarray(info["fixed_points"], dtype=np.int64)
    return dict(info, fixed_points=np.where(fixed >= 0, np.asarray(new_index)[np.maximum(fixed, 0)], -1))


def any_corner_in(mask, cells):
    """Whether any corner of each cell is in the vertex ``mask``: column by column, far faster than ``any(axis=1)``.

    Examples
    --------
    >>> import numpy as np
    >>> any_corner_in(np.array([False, False, False, True]), np.array([[0, 1, 2], [1, 3, 2]])).tolist()
    [False, True]
    """
    return fold_columns(np.logical_or, (mask[cells[:, corner]] for corner in range(cells.shape[1])))


def all_corners_in(mask, cells):
    """Whether every corner of each cell is in the vertex ``mask``: column by column, as :func:`any_corner_in`.

    Examples
    --------
    >>> import numpy as np
    >>> all_corners_in(np.array([True, True, True, False]), np.array([[0, 1, 2], [1, 3, 2]])).tolist()
    [True, False]
    """
    return fold_columns(np.logical_and, (mask[cells[:, corner]] for corner in range(cells.shape[1])))


def unique_edges(cells):
    """Every edge once, as sorted vertex pairs, shape ``(e, 2)``.

    Examples
    --------
    >>> import numpy as np
    >>> unique_edges(np.array([[0, 1, 2], [2, 1, 3]])).tolist()
    [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
    """
    return _unique_rows(sorted_cell_edges(np.asarray(cells)))


def boundary_edges(cells):
    """Edges of a triangle mesh that belong to exactly one cell, oriented as in that cell.

    With counter-clockwise cells the edges run counter-clockwise around the
    outer boundary and clockwise around holes (domain on the left).

    Parameters
    ----------
    cells : numpy.ndarray, shape (m, 3)
        Non-negative integer vertex indices of each triangle.

    Returns
    -------
    numpy.ndarray, shape (b, 2)

    Raises
    ------
    MeshValidityError
        For cells that are not an integer ``(m, 3)`` array, or negative indices.

    Examples
    --------
    >>> import numpy as np
    >>> boundary_edges(np.array([[0, 1, 2]])).tolist()
    [[0, 1], [1, 2], [2, 0]]
    """
    cells = checked_cells(cells, 3)
    if len(cells) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    dense, n_points, used = densely_numbered(cells)
    edges = lone_edges(dense, n_points)
    return edges if used is None else used[edges]


def densely_numbered(cells):
    """``(cells, n_points, used)`` for the kernels whose tables are per vertex: vertices numbered densely if need be.

    Cells in a large mesh's numbering, few of them, name vertices far
    beyond their count: one cell naming vertex 3e7 took 3.7 s and 650 MB,
    one naming 10**9 allocated 8 GB, 10**12 failed. Past four vertex
    numbers per corner the used vertices are numbered ``0 .. k - 1`` and
    ``used`` (k,) maps them back; else ``cells`` come back as given and
    ``used`` is None. ``cells``: checked (non-negative int64, C order), not empty.
    """
    n_points = int(cells.max()) + 1
    if n_points <= 4 * cells.size:
        return cells, n_points, None
    used, dense = np.unique(cells, return_inverse=True)
    return np.ascontiguousarray(dense.reshape(cells.shape), dtype=np.int64), len(used), used


def boundary_faces(cells):
    """Faces of a tetrahedral mesh that belong to exactly one cell, each with its vertices ascending.

    Each face packed into one integer key (below 2**21 vertices; rows
    sorted by three keys above), sorted and compared with its neighbours:
    ``np.unique`` over rows took 0.7 s for 17k vertices' cells, sorted rows
    0.05 s; on 373k cells sorted rows took 0.51 s, packed keys 0.12-0.16 s.

    Parameters
    ----------
    cells : numpy.ndarray, shape (m, 4)
        Non-negative integer vertex indices of each tetrahedron.

    Returns
    -------
    numpy.ndarray, shape (b, 3)
        In lexicographic order.

    Examples
    --------
    >>> import numpy as np
    >>> boundary_faces(np.array([[0, 1, 2, 3], [1, 2, 3, 4]])).tolist()
    [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 4], [1, 3, 4], [2, 3, 4]]
    >>> boundary_faces(np.empty((0, 4), dtype=int)).shape
    (0, 3)
    """
    cells = checked_cells(cells, 4)
    if len(cells) == 0:
        return np.zeros((0, 3), dtype=np.int64)
    faces = np.sort(np.concatenate([np.delete(cells, k, axis=1) for k in range(4)]), axis=1)
    bits = max(int(faces[:, 2].max()).bit_length(), 1)
    if 3 * bits <= 63:
        # one key a face, sorted: a quarter of the time of sorting the rows by three keys (0.51 s on 373k cells)
        wide = faces.astype(np.int64)
        keys = np.sort((wide[:, 0] << (2 * bits)) | (wide[:, 1] << bits) | wide[:, 2])
        differs = keys[1:] != keys[:-1]
        keys = keys[np.append(differs, True) & np.insert(differs, 0, True)]
        mask = (1 << bits) - 1
        return np.column_stack([keys >> (2 * bits), (keys >> bits) & mask, keys & mask]).astype(faces.dtype)
    faces = faces[np.lexsort(faces.T[::-1])]
    differs = np.any(faces[1:] != faces[:-1], axis=1)
    alone = np.append(differs, True) & np.insert(differs, 0, True)  # unlike the face before it and the one after
    return faces[alone]


def boundary_vertex_degree(cells, n_points):
    """Number of boundary edges at each vertex, shape ``(n_points,)``.

    A valid 2D mesh has 0 (interior) or exactly 2 (boundary) everywhere.
    """
    edges = boundary_edges(cells)
    return np.bincount(edges.reshape(-1), minlength=n_points)


def cell_neighbours(cells):
    """Pairs of cells sharing a facet (an edge in 2D), shape ``(k, 2)``."""
    cells = np.asarray(cells)
    corners = cells.shape[1]
    facets = np.concatenate([np.delete(cells, i, axis=1) for i in range(corners)])
    facets.sort(axis=1)
    owner = np.tile(np.arange(len(cells)), corners)
    order = np.lexsort(facets.T[::-1])
    facets, owner = facets[order], owner[order]
    same = np.all(facets[1:] == facets[:-1], axis=1)
    return np.column_stack([owner[:-1][same], owner[1:][same]])


def signed_areas(points, cells):
    """Signed area of each triangle (positive when counter-clockwise), shape ``(m,)``.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3)
        Integer indices into ``points``.

    Raises
    ------
    MeshValidityError
        For points not of shape ``(n, 2)``, cells not an integer ``(m, 3)``
        array, or indices outside ``0 .. n - 1``.

    Examples
    --------
    >>> import numpy as np
    >>> signed_areas(np.array([[0.0, 0], [2, 0], [0, 1]]), np.array([[0, 1, 2], [0, 2, 1]])).tolist()
    [1.0, -1.0]
    """
    points = checked_points(points, 2)
    return _signed_areas(points, checked_cells(cells, 3, len(points)))


def cell_neighbor_table(cells):
    """Cell across each edge: ``table[c, k]`` shares the edge opposite corner ``k``; -1 on the boundary.

    Parameters
    ----------
    cells : numpy.ndarray, shape (m, 3)

    Returns
    -------
    numpy.ndarray, shape (m, 3), int64

    Examples
    --------
    >>> import numpy as np
    >>> cell_neighbor_table(np.array([[0, 1, 2], [2, 1, 3]])).tolist()
    [[1, -1, -1], [-1, -1, 0]]
    """
    cells = checked_cells(cells, 3)
    if len(cells) == 0:
        return np.zeros((0, 3), dtype=np.int64)
    return neighbor_table(*densely_numbered(cells)[:2])


def cell_centroids(points, cells):
    """The centroid of each cell (triangles or tetrahedra), shape (m, dim).

    Compiled: NumPy's ``points[cells].mean(axis=1)`` took 16 ms for 112k
    triangles (a copy of every corner, then a slow mean over a short axis).
    Raises MeshValidityError for cells that are not integer indices of
    the points.

    Examples
    --------
    >>> import numpy as np
    >>> cell_centroids(np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]]), np.array([[0, 1, 2]])).tolist()
    [[1.0, 1.0]]
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    corners = np.shape(cells)[1] if np.ndim(cells) == 2 else points.shape[1] + 1
    cells = checked_cells(cells, corners, len(points))
    return _centroids(points, cells, np.arange(len(cells)), 0)


def kept_cells(cells, neighbors, keep):
    """``cells[keep]`` and their neighbours renumbered among them (-1 for none or a cell not kept).

    ``neighbors`` (m, k) holds cell indices, -1 for none; ``keep`` is a
    boolean mask over the m cells.

    Examples
    --------
    >>> import numpy as np
    >>> cells, neighbors = np.array([[0, 1, 2], [1, 3, 2], [3, 4, 2]]), np.array([[1, -1, -1], [2, 0, -1], [-1, 1, -1]])
    >>> kept_cells(cells, neighbors, np.array([False, True, True]))[1].tolist()
    [[1, -1, -1], [-1, 0, -1]]
    """
    renumber = np.append(np.where(keep, np.cumsum(keep) - 1, -1), -1)  # the last for -1: no neighbour
    return cells[keep], renumber[neighbors[keep]]


def _lowest_at_each_spot(points, candidates):
    """The ``candidates`` (a mask, or None for all) as indices, and for each the lowest candidate at its exact spot."""
    index = np.arange(len(points)) if candidates is None else np.flatnonzero(candidates)
    # every coordinate is compared (3D points equal in x and y but not in z are apart); + 0.0 makes
    # -0.0 the 0.0 it equals, so equal coordinates have equal bits
    at = np.asarray(points, dtype=np.float64)[index] + 0.0  # a new C-ordered array
    return index, index[first_equal_rows(at.view(np.uint64))]


def lowest_twins(points, candidates):
    """Each point's number; a ``candidates`` point (a mask) at the exact spot of a lower-numbered one gets that one's.

    Examples
    --------
    >>> import numpy as np
    >>> lowest_twins(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]]), np.ones(3, dtype=bool)).tolist()
    [0, 1, 0]
    """
    numbering = np.arange(len(points))
    index, lowest = _lowest_at_each_spot(points, candidates)
    numbering[index] = lowest
    return numbering


def coincident_points(points, candidates=None, return_twins=False):
    """Indices of the points at exactly the position of a lower-numbered one, ascending.

    Only the ``candidates`` (a boolean mask; default all) are compared. The
    lowest number of each spot is not listed, so a generator that drops the
    listed points keeps its fixed points, numbered first. Points projected
    onto a polygon's vertex from either side of it land on one spot (a
    coastline has a vertex every few hundred metres). With
    ``return_twins``, also the lowest-numbered candidate at each listed
    point's spot.

    Examples
    --------
    >>> import numpy as np
    >>> coincident_points(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]])).tolist()
    [2]
    >>> [twins.tolist() for twins in coincident_points(np.zeros((3, 2)), return_twins=True)]
    [[1, 2], [0, 0]]
    """
    index, lowest = _lowest_at_each_spot(points, candidates)
    later = lowest != index
    if return_twins:
        return index[later], lowest[later]
    return index[later]


def without_rows(array, indices):
    """``np.delete(array, indices, axis=0)``, by a delete on the flat array.

    NumPy deletes rows of a 2D array through a boolean mask: 2 ms for one
    row of 184k points against 0.2 ms this way, and the generator drops a
    doubled point in most iterations on a coastline.

    Examples
    --------
    >>> import numpy as np
    >>> without_rows(np.arange(8.0).reshape(4, 2), [0, 2]).tolist()
    [[2.0, 3.0], [6.0, 7.0]]
    """
    array = np.ascontiguousarray(array)
    width = int(np.prod(array.shape[1:], dtype=np.int64))
    flat = (np.asarray(indices, dtype=np.int64).reshape(-1, 1) * width + np.arange(width)).ravel()
    return np.delete(array.reshape(-1), flat).reshape(-1, *array.shape[1:])


def boundary_loops(points, cells):
    """The closed boundary loops of a valid 2D triangle mesh, each with the domain on its left.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
        Vertex coordinates (any units; longitude, latitude for geographic meshes).
    cells : numpy.ndarray, shape (m, 3)
        Counter-clockwise triangles.

    Returns
    -------
    loops : list of numpy.ndarray
        Vertex indices of each loop in traversal order, not closed (the
        first vertex is not repeated); each starts at its smallest index.
    areas : numpy.ndarray, shape (len(loops),)
        Signed area of each loop (shoelace, units of ``points`` squared):
        positive for outer boundaries (counter-clockwise), negative for
        holes (clockwise).

    Raises
    ------
    MeshValidityError
        If a vertex has other than 0 or 2 boundary edges (repair the mesh
        first with :func:`terramesh.cleanup.fix_mesh`).

    Examples
    --------
    A square of two cells with no hole: one counter-clockwise loop.

    >>> import numpy as np
    >>> points = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> loops, areas = boundary_loops(points, np.array([[0, 1, 2], [0, 2, 3]]))
    >>> [loop.tolist() for loop in loops], areas.tolist()
    ([[0, 1, 2, 3]], [1.0])
    """
    return loops_along(points, boundary_edges(np.asarray(cells, dtype=np.int64)))


def loops_along(points, edges):
    """:func:`boundary_loops` of the mesh whose directed boundary edges (:func:`boundary_edges`) are ``edges``."""
    points = np.asarray(points, dtype=np.float64)
    n = len(points)
    if len(edges) == 0:
        return [], np.zeros(0)
    outgoing = np.bincount(edges[:, 0], minlength=n)
    incoming = np.bincount(edges[:, 1], minlength=n)
    if np.any(outgoing > 1) or np.any(incoming != outgoing):
        bad = int(np.count_nonzero((outgoing > 1) | (incoming != outgoing)))
        raise MeshValidityError(
            f"{bad} vertices have more than two boundary edges (or unpaired ones): the boundary is not a set of"
            " simple loops; repair the mesh first (terramesh.cleanup.fix_mesh)"
        )
    next_vertex = np.full(n, -1, dtype=np.int64)
    next_vertex[edges[:, 0]] = edges[:, 1]
    order, starts = walk_loops(next_vertex, np.sort(edges[:, 0]))
    following = next_vertex[order]
    x, y = points[order, 0], points[order, 1]
    # shoelace per loop, with coordinates relative to the loop's first vertex (no cancellation far from 0)
    first = np.repeat(order[starts[:-1]], np.diff(starts))
    x0, y0 = points[first, 0], points[first, 1]
    cross = (x - x0) * (points[following, 1] - y0) - (points[following, 0] - x0) * (y - y0)
    areas = 0.5 * np.add.reduceat(cross, starts[:-1])
    loops = [order[starts[i] : starts[i + 1]] for i in range(len(starts) - 1)]
    return loops, areas


def table_boundary_faces(cells, neighbors, opposite=False):
    """Faces of the cells with no cell across, shape (b, 3); with ``opposite``, also each cell's corner across it."""
    free = [neighbors[:, k] < 0 for k in range(4)]
    faces = np.concatenate([np.delete(cells, k, axis=1)[free[k]] for k in range(4)])
    if not opposite:
        return faces
    return faces, np.concatenate([cells[free[k], k] for k in range(4)])


def edges_on_faces(cells, faces, n_points):
    """The cells' unique edges (``a < b`` in each) and the mask of those on any of ``faces`` (boundary faces)."""
    edges = tet_unique_edges(np.ascontiguousarray(cells, dtype=np.int64), n_points)
    on = sorted_cell_edges(faces)
    return edges, np.isin(edges[:, 0] * n_points + edges[:, 1], on[:, 0] * n_points + on[:, 1])
