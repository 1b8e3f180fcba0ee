"""Make a triangulation valid (OceanMesh2D guide §2.2 and §4.3).

Composable steps on ``(points, cells)`` arrays, each returning new arrays
(inputs are never modified):

* :func:`merge_duplicate_points`, :func:`remove_unused_points`,
  :func:`remove_duplicate_cells`, :func:`orient_cells`,
  :func:`remove_degenerate_cells`, :func:`remove_overlapping_cells`:
  DistMesh's ``fixmesh`` and conformity (guide properties 1 to 3);
* :func:`~terramesh.cleanup.disjoint.delete_disjoint_parts`: the guide's
  ``delete_exterior_elements``;
* :func:`delete_interior_cells`: the guide's ``delete_interior_elements``
  (property 4, a boundary with two traversal paths).

:func:`fix_mesh` runs them all, in the guide's alternation, and reports what
it removed in a :class:`RepairReport`.
"""

import dataclasses
import numbers
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .._kernels.cleanup import boundary_degree, edge_census, edge_components, neighbor_table
from .._kernels.topology import first_equal_rows, subset, used_vertices
from ..errors import MeshValidityError, checked_number, warn_user
from ..mesh.boundaries import has_boundaries
from ..mesh.topology import (
    any_corner_in,
    boundary_edges,
    checked_cells,
    checked_points,
    densely_numbered,
    signed_areas,
    sorted_unique,
)
from ..quality.triangle import triangle_quality
from .disjoint import checked_cutoff, disjoint_parts_to_delete
from .validity import (
    FLAT,
    NEAR_SEAM,
    OVERLAP_DEPTH,
    hanging_on_boundary,
    mesh_problems,
    near_pairs,
    near_seam_pairs,
    overlap_problems,
)

__all__ = [
    "RepairReport",
    "fix_mesh",
    "merge_duplicate_points",
    "remove_unused_points",
    "remove_duplicate_cells",
    "orient_cells",
    "remove_degenerate_cells",
    "remove_overlapping_cells",
    "delete_interior_cells",
]

# DistMesh's fixmesh snap: points closer than this fraction of the bbox extent are one point
_SNAP = 1024 * np.finfo(np.float64).eps
PEELED_AREA = 0.02
REPAIR_DROPS_BOUNDARIES = "its boundaries are dropped"  # the warning's words, by which a caller mutes it
"""Share of the mesh's area beyond which :func:`fix_mesh` and :func:`~terramesh.cleanup.clean` warn of removing it.

The cells a spike's removal exposes go too, round after round: a 12-point
star lost 7.7 % of its area, its tips, without a word. Coastal builds lose
0.0-0.3 % (Gulf of Maine at 1 km, Chesapeake at 2 km, South Island at 1 km),
a coarse one of 399 vertices 1.06 % (five spikes' strips). Two blocks meeting
with nodes that match at every other seam node lost 27 % of their area, to
the cells deleted at the vertices where they touch, also without a word.
"""


@dataclass(frozen=True)
class RepairReport:
    """What a repair removed or changed; every field is a count.

    Attributes
    ----------
    merged_points : int
        Vertices merged into an earlier vertex at the same place.
    unused_points : int
        Vertices dropped because no cell used them (after the deletions).
    duplicate_cells : int
        Cells dropped for a repeated corner or a repeated vertex set.
    reoriented_cells : int
        Clockwise cells turned counter-clockwise (kept).
    untangled_points : int
        Interior vertices moved to the mean of their neighbours because a
        fold had carried them past a neighbour (their cells were inverted
        although they fit their neighbours edge to edge).
    degenerate_cells : int
        Flat (zero-area) cells dropped.
    overlapping_cells : int
        Cells dropped because they ran along an edge in the same direction as
        another cell (two cells on the same side of an edge overlap), or lay
        over a cell of a larger part (two meshes concatenated where they
        overlap).
    disjoint_parts, disjoint_cells : int
        Small disconnected parts deleted, and their cells.
    interior_cells : int
        Cells deleted so that every boundary vertex has two boundary edges.
    low_quality_cells : int
        Boundary cells below the minimum quality deleted by :func:`clean`.
    low_valence_points : int
        Vertices removed by :func:`clean` for their low valence.
    smoothed_points : int
        Vertices moved by smoothing in :func:`clean`.
    """

    merged_points: int = 0
    unused_points: int = 0
    duplicate_cells: int = 0
    reoriented_cells: int = 0
    untangled_points: int = 0
    degenerate_cells: int = 0
    overlapping_cells: int = 0
    disjoint_parts: int = 0
    disjoint_cells: int = 0
    interior_cells: int = 0
    low_quality_cells: int = 0
    low_valence_points: int = 0
    smoothed_points: int = 0

    def __add__(self, other):
        if not isinstance(other, RepairReport):
            return NotImplemented
        return RepairReport(
            **{f.name: getattr(self, f.name) + getattr(other, f.name) for f in dataclasses.fields(self)}
        )

    def as_dict(self):
        """The counts as a plain dict."""
        return dataclasses.asdict(self)

    def __str__(self):
        changed = {name: count for name, count in self.as_dict().items() if count}
        return ", ".join(f"{name.replace('_', ' ')}: {count:,}" for name, count in changed.items()) or "no change"


def merge_duplicate_points(points, cells, *, tolerance=None):
    """Merge vertices closer than ``tolerance`` and renumber the cells.

    Vertices within ``tolerance`` of each other (and chains of such, each
    link shorter than it) become the one with the smallest index among
    those a cell uses (the smallest index when no cell uses any: a leftover
    node no cell uses does not give its place or its data to a node in
    use); vertices keep their order otherwise. Exact duplicates are found by their bits
    (``tolerance=0``); otherwise by a KD-tree. (DistMesh's ``fixmesh``
    snaps to a grid instead, so that two vertices a hair apart on either
    side of a grid line stayed two.)

    Parameters
    ----------
    points : numpy.ndarray, shape (n, dim)
        Vertex coordinates, any units.
    cells : numpy.ndarray, shape (m, 3) or (m, 4)
        Vertex indices of each cell.
    tolerance : float, optional
        Distance in the units of ``points``; 0 merges exact duplicates only.
        By default ``1024 * eps`` times the larger bbox side.

    Returns
    -------
    points : numpy.ndarray, shape (k, dim)
    cells : numpy.ndarray, shape (m, 3) or (m, 4)
        Renumbered; a cell may now repeat a vertex (see
        :func:`remove_duplicate_cells`).
    kept : numpy.ndarray, shape (k,)
        Index in the input ``points`` of each vertex kept (its point data
        are the merged vertex's).

    Raises
    ------
    MeshValidityError
        For points not of shape (n, 2) or (n, 3), NaN or infinite points, a
        tolerance that is not a non-negative finite number, or cells that
        refer to vertices that do not exist.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [0, 1], [1, 0]])
    >>> new_points, new_cells, kept = merge_duplicate_points(points, np.array([[0, 1, 2], [3, 2, 1]]))
    >>> new_cells.tolist(), kept.tolist()
    ([[0, 1, 2], [1, 2, 1]], [0, 1, 2])
    """
    points, cells, kept, _ = _merged(points, cells, tolerance)
    return points, cells, kept


def _merged(points, cells, tolerance):
    """:func:`merge_duplicate_points`, checks included, also returning the vertex each input vertex became.

    Returns ``(points, cells, kept, into)``: ``into[i]`` is the input index
    of the vertex that vertex ``i`` was merged into (``i`` itself if kept).
    """
    points = checked_points(points)
    n = len(points)
    corners = np.shape(cells)[1] if np.ndim(cells) == 2 and np.shape(cells)[1] == 4 else 3
    cells = checked_cells(cells, corners, n)
    if n == 0:
        return points.copy(), cells.copy(), np.arange(0), np.arange(0)
    if not np.all(np.isfinite(points)):
        raise MeshValidityError(f"points have {int(np.sum(~np.isfinite(points).all(axis=1)))} NaN or infinite rows")
    if tolerance is None:
        tolerance = default_merge_tolerance(points)
    requirement = "tolerance must be a non-negative finite number"
    tolerance = checked_number(tolerance, requirement, MeshValidityError, minimum=0)
    used = np.zeros(n, dtype=bool)
    used[cells.ravel()] = True
    if tolerance == 0:
        # equal rows by their bits in a hash table (+ 0.0 makes -0.0 the 0.0 it equals): a third of a lexsort's
        # time; the vertices in use first, so that the first of each spot is one in use where there is one
        if used.all():
            first = first_equal_rows(np.ascontiguousarray(points + 0.0).view(np.uint64))
        else:
            order = np.argsort(~used, kind="stable")
            first = np.empty(n, dtype=np.int64)
            first[order] = order[first_equal_rows(np.ascontiguousarray(points[order] + 0.0).view(np.uint64))]
    else:  # the pairs within the tolerance, exact duplicates among them, joined in chains
        first = np.arange(n)
        pairs = cKDTree(points).query_pairs(tolerance, output_type="ndarray")
        if len(pairs):
            graph = sparse.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
            _, label = connected_components(graph, directed=False)
            rank = np.where(used, np.arange(n), np.arange(n) + n)  # a vertex in use before any not in use
            smallest = np.full(label.max() + 1, 2 * n, dtype=np.int64)
            np.minimum.at(smallest, label, rank)
            first = smallest[label] % n
    is_first = first == np.arange(n)
    new_index = np.cumsum(is_first) - 1
    return points[is_first], new_index[first][cells], np.flatnonzero(is_first), first


def remove_unused_points(points, cells):
    """Drop vertices no cell uses and renumber the cells.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, dim)
    cells : numpy.ndarray, shape (m, 3) or (m, 4)

    Returns
    -------
    points : numpy.ndarray, shape (k, dim)
    cells : numpy.ndarray, shape (m, 3) or (m, 4)
    kept : numpy.ndarray, shape (k,)
        Index in the input ``points`` of each vertex kept.

    Raises
    ------
    MeshValidityError
        For cells that are not a 2-D array of integers (``2.7`` is no
        vertex number) or refer to vertices outside ``0 .. n - 1``.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[9.0, 9], [0, 0], [1, 0], [0, 1]])
    >>> _, cells, kept = remove_unused_points(points, np.array([[1, 2, 3]]))
    >>> cells.tolist(), kept.tolist()
    ([[0, 1, 2]], [1, 2, 3])
    """
    shape = np.shape(cells)
    if len(shape) != 2 and np.size(cells):
        raise MeshValidityError(f"cells must be a 2-D array of vertex numbers, got shape {shape}")
    # cast, [0, 1, 2.7] became [0, 1, 2]: another cell than the one given
    if points is None or np.ndim(points) != 2:
        raise MeshValidityError(
            f"points must be an (n, dim) array, got {'None' if points is None else np.shape(points)}"
        )
    points = np.asarray(points)  # any dim and dtype: the kept rows come back as they were
    cells = checked_cells(cells, shape[1] if len(shape) == 2 else 3, len(points))
    kept, renumbered, _ = used_vertices(cells, len(points))
    return points[kept], renumbered, kept


def remove_duplicate_cells(cells):
    """Drop cells with a repeated corner, and all but the first of cells with the same three vertices.

    Parameters
    ----------
    cells : numpy.ndarray, shape (m, 3)

    Returns
    -------
    numpy.ndarray, shape (k, 3)
        The remaining cells, in their original order.

    Examples
    --------
    >>> import numpy as np
    >>> remove_duplicate_cells(np.array([[0, 1, 2], [1, 1, 3], [2, 0, 1], [1, 3, 2]])).tolist()
    [[0, 1, 2], [1, 3, 2]]
    """
    cells = checked_cells(cells, 3)  # the kernel indexes without bounds checks
    if len(cells) == 0:
        return cells.copy()
    collapsed = (cells[:, 0] == cells[:, 1]) | (cells[:, 1] == cells[:, 2]) | (cells[:, 2] == cells[:, 0])
    dense, n_points, _ = densely_numbered(cells)
    return cells[~(collapsed | edge_census(dense, n_points)[0])]


def orient_cells(points, cells):
    """Return a copy of ``cells`` with every triangle counter-clockwise.

    Zero-area cells are left as they are.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3)

    Returns
    -------
    numpy.ndarray, shape (m, 3)

    Examples
    --------
    >>> import numpy as np
    >>> orient_cells(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([[0, 2, 1]])).tolist()
    [[0, 1, 2]]
    """
    return _turned(cells, signed_areas(points, cells) < 0)


def _turned(cells, clockwise):
    """A copy of ``cells`` with the ``clockwise`` ones turned counter-clockwise."""
    cells = np.array(cells, dtype=np.int64)
    cells[clockwise] = cells[clockwise][:, [0, 2, 1]]
    return cells


def remove_degenerate_cells(points, cells, min_quality=1e-6):
    """Drop cells whose quality (guide eq. 1) is below ``min_quality``: flat slivers.

    The quality is signed: orient the cells first (:func:`orient_cells`),
    or clockwise cells go too. Cells that
    :func:`~terramesh.cleanup.mesh_problems` calls flat (area at most
    :data:`~terramesh.cleanup.validity.FLAT` times the sum of their
    squared edges, quality below 7e-10) go whatever ``min_quality``: with
    0, a zero-area cell stayed, and the overlap repair dropped it as an
    overlap.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3)
    min_quality : float, optional
        Scale-free threshold in [0, 1); the default removes only cells flat
        to rounding.

    Returns
    -------
    numpy.ndarray, shape (k, 3)

    Raises
    ------
    MeshValidityError
        For a ``min_quality`` that is not a number in [0, 1) (NaN kept no
        cell), or malformed arrays.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [0, 1], [2, 0]])
    >>> remove_degenerate_cells(points, np.array([[0, 1, 2], [0, 1, 3]])).tolist()
    [[0, 1, 2]]
    """
    min_quality = _checked_min_quality(min_quality)
    quality = triangle_quality(points, cells)
    return np.asarray(cells)[(quality >= min_quality) & (quality > _FLAT_QUALITY)]


_FLAT_QUALITY = 4 * np.sqrt(3) * FLAT  # quality = 4 sqrt(3) area / squared edges


def _checked_min_quality(min_quality):
    """``min_quality`` as a float in [0, 1), or a MeshValidityError."""
    if not isinstance(min_quality, numbers.Real) or isinstance(min_quality, bool) or not 0 <= min_quality < 1:
        raise MeshValidityError(f"min_quality must be a number in [0, 1), got {min_quality!r}")
    return float(min_quality)


def remove_overlapping_cells(points, cells, *, geographic=False):
    """Drop cells until none lies over another: of two overlapping parts, the smaller gives way.

    With counter-clockwise cells, two cells that traverse an edge in the
    same direction lie on the same side of it and overlap; so do three or
    more cells on one edge, and cells of two parts laid over each other
    (two meshes concatenated where they overlap, one inside the other).
    The parts are the cells joined through edges that two cells run in
    opposite directions. Where cells of two parts overlap, the cell of the
    part with the smaller area goes, so the larger part stays whole;
    within one part the cell of higher quality (guide eq. 1) stays. Cells
    of two parts overlap when each reaches into the other by more than
    :data:`~terramesh.cleanup.validity.OVERLAP_DEPTH` of the longer of
    their longest edges; only the cells in the bounding box shared by two
    parts are compared. Cells dropped because another part
    lies over them are counted in a warning.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3)
        Counter-clockwise (see :func:`orient_cells`).
    geographic : bool, optional
        Points are longitude, latitude: measure quality on the ground.

    Returns
    -------
    numpy.ndarray, shape (k, 3)
        The remaining cells, in their original order. The parts that gave
        way may be left in pieces, beside the larger part but not joined to
        it (to join two meshes, see :func:`terramesh.coastal.merge`).

    Raises
    ------
    MeshValidityError
        For points not of shape (n, 2) or cells not an integer (m, 3) array
        of indices into them.

    Examples
    --------
    Two cells on the same side of the edge 0-1, each a part of its own:
    the smaller gives way, with a warning.

    >>> import warnings
    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [0.5, 0.9], [0.5, 0.2]])
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     kept = remove_overlapping_cells(points, np.array([[0, 1, 2], [0, 1, 3]]))
    >>> kept.tolist(), str(caught[0].message)[:61]
    ([[0, 1, 2]], "1 cells with 18.18% of the cells' total area (0.1) overlapped")
    """
    points = checked_points(points, 2)
    return _without_overlaps(points, checked_cells(cells, 3, len(points)), geographic)[0]


def _without_overlaps(points, given, geographic):
    """:func:`remove_overlapping_cells` on checked arrays: ``(cells, overlap_free)``.

    ``overlap_free`` is True when the cells were looked over whole and none
    overlapped (one part alone is not: a fold within it is left to
    :func:`~terramesh.cleanup.mesh_problems`); deleting cells keeps it so,
    and :func:`fix_mesh` does not look again (0.3 s of 1.7 s on the guide's
    §5.3 mesh).
    """
    n, m = len(points), len(given)
    if m == 0:
        return given.copy(), True
    signed = signed_areas(points, given)
    # the rules read directions along edges: a clockwise cell is read turned (two clockwise stacked squares
    # lost 86 cells, not the smaller square's 217)
    cells = np.where((signed < 0)[:, None], given[:, ::-1], given)
    _, repeated_edges, degree = edge_census(cells, n)
    conforming = repeated_edges == 0
    n_parts, labels = edge_components(cells, n) if conforming else _parts_across_edges(cells, n)
    # parts that fit edge to edge lie over each other only where their boundaries say so (a disk in an
    # annulus's hole, 202k cells: 0.42 s cell by cell, 0.11 s by the boundaries); the boundaries are read
    # as loops, so parts that touch at a vertex (more than two boundary edges there, mended later by
    # delete_interior_cells) are compared cell by cell
    if conforming and n_parts == 1:
        return given.copy(), False
    if conforming and degree.max() <= 2 and not overlap_problems(points, cells):
        return given.copy(), True
    area = np.abs(signed)
    part_area = np.bincount(labels, weights=area, minlength=n_parts)[labels]
    lose = np.zeros(m, dtype=bool)
    under = np.zeros(m, dtype=bool)  # dropped for a cell of another part
    outline = np.ones(m, dtype=bool)
    if conforming:  # a part reaches farthest at its boundary vertices: their cells give the part's box
        outline = any_corner_in(degree > 0, cells)
    else:
        quality = triangle_quality(points, cells, geographic=geographic)
        loser, winner = _same_side_losers(cells, n, part_area, labels, quality)
        lose[loser] = True
        under[loser[labels[loser] != labels[winner]]] = True
    if n_parts > 1:
        kept = np.flatnonzero(~lose)
        first, second = _cross_part_overlaps(points, cells[kept], labels[kept], outline[kept])
        first, second = kept[first], kept[second]
        # the cell of the smaller part gives way; of two parts of one area, the later one's
        first_gives_way = (part_area[first] < part_area[second]) | (
            (part_area[first] == part_area[second]) & (labels[first] > labels[second])
        )
        loser = np.where(first_gives_way, first, second)
        lose[loser] = under[loser] = True
    if under.any():
        dropped = area[under].sum()
        warn_user(
            f"{int(under.sum())} cells with {dropped / area.sum():.2%} of the cells' total area ({dropped:.4g})"
            " overlapped a larger part of the mesh and were dropped; to join two overlapping meshes use"
            " terramesh.coastal.merge",
        )
    return given[~lose], False


def _same_side_losers(cells, n_points, part_area, labels, quality):
    """``(loser, winner)`` cells: of the cells running an edge in one direction, every one but the best loses.

    The best is the cell of the largest part (of parts of one area, the
    first), then of the highest ``quality``, then the first: the decision
    between two parts is the same at every edge they share, so no part is
    left with holes where the other lost elsewhere.
    """
    m = len(cells)
    rank = np.empty(m, dtype=np.int64)
    rank[np.lexsort((-np.arange(m), quality, -labels, part_area))] = np.arange(m)
    key = (cells * n_points + cells[:, [1, 2, 0]]).ravel()
    owner = np.repeat(np.arange(m), 3)
    order = np.lexsort((rank[owner], key))
    key, owner = key[order], owner[order]
    new_group = np.ones(len(key), dtype=bool)
    new_group[1:] = key[1:] != key[:-1]
    last = np.append(new_group[1:], True)  # the best of its group, sorted last
    group = np.cumsum(new_group) - 1
    return owner[~last], owner[last][group[~last]]


def _parts_across_edges(cells, n_points):
    """``(n_parts, labels)``: the parts of cells joined through edges that exactly two cells run in opposite directions.

    An edge run twice in one direction (cells lying over each other) joins
    nothing, so two parts laid over each other stay two. One sort of the
    edges as unordered pairs puts each edge's cells side by side.
    """
    tail = cells.ravel()
    head = cells[:, [1, 2, 0]].ravel()
    key = np.minimum(tail, head) * n_points + np.maximum(tail, head)
    order = np.argsort(key, kind="stable")
    key, forward = key[order], (tail < head)[order]
    same = key[1:] == key[:-1]  # entry i and i + 1 are one edge
    alone_before = np.append(True, ~same[:-1])  # entry i is the first of its edge
    alone_after = np.append(~same[1:], True)  # entry i + 1 is the last of its edge
    join = np.flatnonzero(same & alone_before & alone_after & (forward[1:] != forward[:-1]))
    m = len(cells)
    graph = sparse.coo_matrix((np.ones(len(join)), (order[join] // 3, order[join + 1] // 3)), shape=(m, m))
    return connected_components(graph, directed=False)


def _cross_part_overlaps(points, cells, labels, outline):
    """The pairs ``(i, j)`` of cells of different parts (``labels``) that overlap.

    Only the cells in a bounding box two parts share are compared, so a
    mesh with its parts apart costs a box per part: each part's box is
    that of its ``outline`` cells (those that reach as far as the part),
    and the cells out of every shared box are told by the sides of it
    their corners lie beyond (Cohen-Sutherland outcodes), without a box
    per cell.
    """
    outline = np.flatnonzero(outline)
    low, high = _cell_boxes(points, cells[outline])
    # the parts' boxes over their outline cells sorted by part (np.minimum.at took four times as long)
    order = np.argsort(labels[outline], kind="stable")
    starts = np.flatnonzero(np.diff(labels[outline][order], prepend=-1))
    present = labels[outline][order][starts]
    part_low = np.full((int(labels.max()) + 1, 2), np.inf)
    part_high = np.full((int(labels.max()) + 1, 2), -np.inf)
    part_low[present] = np.minimum.reduceat(low[order], starts)
    part_high[present] = np.maximum.reduceat(high[order], starts)
    a, b = _meeting_boxes(part_low[present], part_high[present], part_low[present], part_high[present])
    a, b = present[a[a < b]], present[b[a < b]]
    if len(a) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    shared_low, shared_high = np.maximum(part_low[a], part_low[b]), np.minimum(part_high[a], part_high[b])
    top, bottom = shared_high.max(axis=0), shared_low.min(axis=0)
    x, y = points[:, 0], points[:, 1]
    beyond = np.column_stack([x <= bottom[0], x >= top[0], y <= bottom[1], y >= top[1]])
    code = np.packbits(beyond, axis=1, bitorder="little")[:, 0]
    near = np.flatnonzero((code[cells[:, 0]] & code[cells[:, 1]] & code[cells[:, 2]]) == 0)
    corners = points[cells[near]]
    low, high = _cell_boxes(points, cells[near])
    cell, pair = _meeting_boxes(low, high, shared_low, shared_high)
    part = labels[near]
    candidates = np.unique(cell[(part[cell] == a[pair]) | (part[cell] == b[pair])])
    i, j = _meeting_boxes(low[candidates], high[candidates], low[candidates], high[candidates])
    i, j = candidates[i], candidates[j]
    keep = (i < j) & (part[i] != part[j])
    i, j = i[keep], j[keep]
    overlap = _triangles_overlap(corners[i], corners[j])
    return near[i[overlap]], near[j[overlap]]


def _cell_boxes(points, cells):
    """The lower and upper corners (m, 2) of the cells' bounding boxes.

    Corner by corner: a reduction over the middle axis of (m, 3, 2) took
    four times as long.
    """
    low, high = np.empty((len(cells), 2)), np.empty((len(cells), 2))
    for axis in range(2):
        at = points[:, axis][cells]
        low[:, axis] = np.minimum(np.minimum(at[:, 0], at[:, 1]), at[:, 2])
        high[:, axis] = np.maximum(np.maximum(at[:, 0], at[:, 1]), at[:, 2])
    return low, high


def _meeting_boxes(first_low, first_high, second_low, second_high):
    """The pairs ``(i, j)`` of boxes, one from each set, whose interiors meet."""
    first_centre, second_centre = 0.5 * (first_low + first_high), 0.5 * (second_low + second_high)
    i, j = near_pairs(
        first_centre,
        np.hypot(*(first_high - first_low).T) / 2,
        second_centre,
        np.hypot(*(second_high - second_low).T) / 2,
    )
    meet = np.all((first_low[i] < second_high[j]) & (second_low[j] < first_high[i]), axis=1)
    return i[meet], j[meet]


def _triangles_overlap(first, second):
    """Whether counter-clockwise triangles ``first`` and ``second`` (k, 3, 2) reach into each other.

    Two convex shapes are apart exactly when a line along an edge of one
    has the other wholly outside (separating axes): here, outside or
    within :data:`~terramesh.cleanup.validity.OVERLAP_DEPTH` of the longer
    of the two longest edges. Cells on the two sides of a shared edge are
    apart by that edge.
    """
    both = np.concatenate([first, second], axis=1)
    sides = np.roll(both.reshape(-1, 2, 3, 2), -1, axis=2).reshape(-1, 6, 2) - both
    length = np.sqrt(np.sum(sides**2, axis=2))
    depth = OVERLAP_DEPTH * length.max(axis=1)
    apart = np.zeros(len(first), dtype=bool)
    for edge in range(6):
        other = second if edge < 3 else first
        outward = np.column_stack([sides[:, edge, 1], -sides[:, edge, 0]]) / length[:, edge, None]
        distance = np.einsum("ikj,ij->ik", other - both[:, edge, None], outward)
        apart |= distance.min(axis=1) >= -depth
    return ~apart


def delete_interior_cells(points, cells, *, geographic=False):
    """Delete cells until every boundary vertex has exactly two boundary edges.

    The OceanMesh2D guide's ``delete_interior_elements`` rule (§4.3), for
    features thinner than an element (the barrier-island case): at each
    vertex with more than two boundary edges, delete the connected cell with
    the most boundary edges (two, or three for a cell hanging by a vertex),
    the lowest-quality one among equals; repeat until no such vertex is left.
    Each round handles every offending vertex at once.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3), counter-clockwise
    geographic : bool, optional
        Points are longitude, latitude: measure quality on the ground.

    Returns
    -------
    numpy.ndarray, shape (k, 3)
        The remaining cells, in their original order (vertices may become
        unused, see :func:`remove_unused_points`; small parts may come off,
        see :func:`~terramesh.cleanup.delete_disjoint_parts`).

    Raises
    ------
    MeshValidityError
        For cells not an integer (m, 3) array of indices into ``points``.

    Examples
    --------
    Two triangles touching at one vertex (a "bowtie"): one must go.

    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [0.5, 0.5], [0, 1], [1, 1]])
    >>> delete_interior_cells(points, np.array([[0, 1, 2], [2, 4, 3]])).shape
    (1, 3)
    """
    points = checked_points(points)
    n = len(points)
    cells = checked_cells(cells, 3, n)  # a vertex number past the points came back as it went in
    while len(cells):
        edges = boundary_edges(cells)
        bad_vertex = np.bincount(edges.ravel(), minlength=n) > 2
        if not bad_vertex.any():
            break
        touching = np.flatnonzero(any_corner_in(bad_vertex, cells))
        local = cells[touching]
        # boundary edges per cell: an edge (a, b) of the cell that is a boundary edge (same direction)
        directed = np.stack([local[:, [0, 1]], local[:, [1, 2]], local[:, [2, 0]]], axis=1)
        n_boundary_edges = np.isin(directed[..., 0] * n + directed[..., 1], edges[:, 0] * n + edges[:, 1]).sum(axis=1)
        cells = cells[~_interior_deletions(points, cells, bad_vertex, touching, n_boundary_edges, geographic)]
    return cells


def _interior_deletions(points, cells, bad_vertex, touching, n_boundary_edges, geographic):
    """One round of :func:`delete_interior_cells`: the mask of the cells to delete.

    ``touching`` are the cells at a vertex of ``bad_vertex`` and
    ``n_boundary_edges`` their boundary edges; only they compete, so only
    theirs are measured.
    """
    local = cells[touching]
    quality = triangle_quality(points, local, geographic=geographic)
    # per bad vertex pick one cell: most boundary edges first, then lowest quality
    row, k = np.nonzero(bad_vertex[local])
    corner = local[row, k]
    order = np.lexsort((quality[row], -n_boundary_edges[row], corner))
    first = np.ones(len(order), dtype=bool)
    first[1:] = corner[order][1:] != corner[order][:-1]
    delete = np.zeros(len(cells), dtype=bool)
    delete[touching[row[order][first]]] = True
    return delete


def delete_interior_cells_with_table(points, cells, table, geographic=False):
    """:func:`delete_interior_cells` for conforming cells with their neighbour table: ``(cells, table)``.

    A conforming mesh's boundary edges are its table's -1 entries, so the
    table, followed through the deletions, replaces the search for them.
    """
    n = len(points)
    while len(cells):
        bad_vertex = boundary_degree(cells, table, n) > 2
        if not bad_vertex.any():
            break
        touching = np.flatnonzero(any_corner_in(bad_vertex, cells))
        n_boundary_edges = np.sum(table[touching] < 0, axis=1)
        cells, table = subset(
            cells, table, ~_interior_deletions(points, cells, bad_vertex, touching, n_boundary_edges, geographic)
        )
    return cells, table


def as_triangle_arrays(mesh_or_points, cells, what=None):
    """``(mesh or None, points, cells)`` validated: (n, 2) finite floats, (m, 3) ints in range.

    ``what`` names the caller in the error for a tetrahedral mesh or 3-D
    points (the repairs are for 2-D triangle meshes).
    """
    from ..mesh.mesh import Mesh

    if isinstance(mesh_or_points, Mesh):
        if cells is not None:
            raise MeshValidityError("give a Mesh, or points and cells, not a Mesh and cells")
        mesh = mesh_or_points
        points, cells = mesh.points, mesh.cells
    else:
        if cells is None:
            raise MeshValidityError("give a Mesh, or points and cells")
        mesh = None
        points = mesh_or_points
    point_shape, cell_shape = np.shape(points), np.shape(cells)
    if (len(point_shape) == 2 and point_shape[1] == 3) or (len(cell_shape) == 2 and cell_shape[1] == 4):
        raise MeshValidityError(
            f"{what or 'this function'} repairs 2-D triangle meshes only (points (n, 2), cells (m, 3)); got points"
            f" of shape {point_shape} and cells of shape {cell_shape} (tetrahedra, or triangles in 3-D)"
        )
    points = checked_points(points, 2)
    if not np.all(np.isfinite(points)):
        raise MeshValidityError(f"points have {int(np.sum(~np.isfinite(points).all(axis=1)))} NaN or infinite rows")
    return mesh, points, checked_cells(cells, 3, len(points))


def resolved_disjoint_cutoff(disjoint_cutoff, dj_cutoff):
    """One place that maps the guide's short name ``dj_cutoff`` onto ``disjoint_cutoff``."""
    if dj_cutoff is not None:
        if disjoint_cutoff is not None and disjoint_cutoff != dj_cutoff:
            raise MeshValidityError("give the cutoff as disjoint_cutoff or as its alias dj_cutoff, not both")
        disjoint_cutoff = dj_cutoff
    return checked_cutoff(0.01 if disjoint_cutoff is None else disjoint_cutoff)


def finished_mesh(
    mesh,
    points,
    cells,
    source,
    report,
    *,
    n_points,
    n_cells,
    what,
    merge_tolerance=None,
    keep_fixed=True,
    overlap_free=False,
):
    """Drop unused vertices, check the rules, build the returned Mesh and warn of seams that did not merge.

    The input mesh's ``info["fixed_points"]`` follow the vertices (see
    :func:`_fixed_points_followed`), or are dropped unless ``keep_fixed``.
    ``overlap_free``: the cells are known not to overlap (not looked for again).
    """
    from ..mesh.mesh import Mesh

    if len(cells) == 0:
        raise MeshValidityError(f"{what} left no cell: the mesh is too thin or too small to repair")
    points, cells, kept = remove_unused_points(points, cells)
    source = source[kept]
    report = dataclasses.replace(report, unused_points=n_points - report.merged_points - len(points))
    if mesh is None:
        result = Mesh(points, cells, info={"repair": report})
    else:
        unchanged = len(points) == n_points and len(cells) == n_cells and np.array_equal(source, np.arange(n_points))
        boundaries = mesh.boundaries
        if has_boundaries(boundaries) and not unchanged:
            warn_user(
                f"{what} changed the mesh ({report}): {REPAIR_DROPS_BOUNDARIES}; make them again",
            )
            boundaries = None
        info = dict(mesh.info, repair=report)
        if "fixed_points" in info and keep_fixed:
            new_index = np.full(n_points, -1)  # each input vertex's number in the result (-1: merged or dropped)
            new_index[source] = np.arange(len(source))
            tolerance = default_merge_tolerance(mesh.points) if merge_tolerance is None else merge_tolerance
            info["fixed_points"] = _fixed_points_followed(
                info["fixed_points"], new_index, mesh.points, points, cells, tolerance, what
            )
        else:
            info.pop("fixed_points", None)
        result = Mesh(
            points,
            cells,
            point_data={name: np.asarray(values)[source] for name, values in mesh.point_data.items()},
            boundaries=boundaries,
            title=mesh.title,
            crs=mesh.crs,
            info=info,
        )
    # hanging nodes: no repair joins them, warned of below
    problems = mesh_problems(result, overlaps=not overlap_free, hanging_nodes=False)
    if problems:
        raise MeshValidityError(f"{what} could not make the mesh valid: " + "; ".join(problems))
    edges = boundary_edges(result.cells)
    _warn_near_seams(result.points, edges, what, merge_tolerance)
    _warn_hanging(result.points, edges, what)
    return result


def _fixed_points_followed(fixed, new_index, given_points, points, cells, tolerance, what):
    """A mesh's ``info["fixed_points"]`` (vertex numbers, -1 for lost) in the result's numbering ``new_index``.

    A vertex merged into a duplicate, or left in no cell, is followed to the
    vertex in use at its place, as :func:`~terramesh.cleanup.clean` follows
    its fixed points (:func:`at_their_place`); the fixed points lost all
    the same are -1, with a warning.
    """
    given = np.asarray(fixed)
    n = len(given_points)
    if given.ndim != 1 or given.dtype.kind not in "iu" or np.any(given >= n) or np.any(given < -1):
        # an IndexError deep in the renumbering, or 0.5 taken as vertex 0
        shown = np.array2string(given.ravel()[:6], separator=", ")
        raise MeshValidityError(
            f"info['fixed_points'] must be a 1-D array of vertex numbers 0..{n - 1} (-1: lost), got {shown}"
            f"{' ...' if given.size > 6 else ''} of {given.dtype}"
        )
    fixed = given.astype(np.int64)
    had = fixed >= 0
    index = np.where(had, new_index[np.maximum(fixed, 0)], -1)
    index[had] = at_their_place(index[had], given_points[fixed[had]], points, cells, tolerance)
    lost = np.flatnonzero(had & (index < 0))
    if len(lost):
        x, y = given_points[fixed[lost[0]]]
        warn_user(
            f"{what} removed {len(lost)} of the {len(fixed)} fixed points (info['fixed_points']), the first at"
            f" ({x:.9g}, {y:.9g}): the repairs deleted their cells (a small disconnected part below disjoint_cutoff,"
            " or cells deleted at a pinched boundary vertex); info['fixed_points'] is -1 for them",
        )
    return index


def at_their_place(index, given, points, cells, tolerance):
    """``index`` (k,), vertex numbers among ``points`` (-1: gone), with each gone or unused one at ``given`` followed.

    A fixed point's vertex merged into a duplicate (or whose cells went)
    is replaced by the vertex in use nearest to its coordinates ``given``
    (k, 2), if within ``tolerance``; else -1. Returns a new array.
    """
    index = np.array(index, dtype=np.int64)
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    lost = (index < 0) | ~used[np.maximum(index, 0)]
    if lost.any():
        nearest, distance = nearest_used_vertex(given[lost], points, cells)
        index[lost] = np.where(distance <= tolerance, nearest, -1)
    return index


def nearest_used_vertex(given, points, cells):
    """The vertex used by ``cells`` nearest to each of ``given``, and its distance (inf when no vertex is used)."""
    used = sorted_unique(cells)
    if len(used) == 0 or len(given) == 0:
        return np.full(len(given), -1, dtype=np.int64), np.full(len(given), np.inf)
    distance, nearest = cKDTree(points[used]).query(given)
    return used[nearest], distance


def _warn_hanging(points, edges, what):
    """Warn of hanging nodes (:func:`~terramesh.cleanup.validity.hanging_vertices`) on the boundary ``edges``."""
    vertex, _, _ = hanging_on_boundary(points, edges)
    if len(vertex) == 0:
        return
    x, y = points[vertex[0]]
    warn_user(
        f"{len(vertex)} boundary vertices lie on another boundary edge, the first at ({x:.6g}, {y:.6g}): hanging"
        f" nodes, where parts meet along a line with nodes that do not match and are not joined; {what} cannot join"
        " them, and mesh_problems lists them: give the parts matching nodes along the seam (or remesh it)",
    )


def default_merge_tolerance(points):
    """``merge_tolerance``'s default: ``_SNAP`` times the larger side of the points' bbox."""
    return _SNAP * max(float(np.ptp(points, axis=0).max()), np.finfo(np.float64).tiny)


def _warn_near_seams(points, edges, what, merge_tolerance):
    """Warn when boundary vertices of two loops of ``edges`` nearly coincide: a seam the merge did not close."""
    first, second, distance = near_seam_pairs(points, edges)
    if len(first) == 0:
        return
    if merge_tolerance is None:
        merge_tolerance = default_merge_tolerance(points)
    x, y = points[first[0]]
    warn_user(
        f"{len(first)} pairs of boundary vertices on different boundary loops lie within {NEAR_SEAM:g} of their"
        f" shortest boundary edge of each other (at most {distance.max():.3g} apart, near ({x:.6g}, {y:.6g})):"
        f" a seam of two meshes whose nodes differ by rounding? {what} merged only vertices closer than merge_tolerance"
        f" ({merge_tolerance:.3g}); fix_mesh(mesh, merge_tolerance=...) above {distance.max():.3g} joins them",
    )


def fix_mesh(
    mesh_or_points,
    cells=None,
    *,
    disjoint_cutoff=None,
    dj_cutoff=None,
    by="cells",
    merge_tolerance=None,
    min_quality=1e-6,
    geographic=None,
):
    """Make a triangle mesh valid (OceanMesh2D guide §2.2 properties 1 to 4, §4.3).

    In order: merge duplicate vertices (a vertex a cell uses is kept before
    one no cell uses; merged vertices in use whose ``point_data`` differ
    draw a warning); drop cells with a repeated corner and repeated cells;
    move interior vertices that a fold carried past their neighbours to
    the mean of their neighbours, with a warning (a cell turned over by a
    dragged vertex still fits its neighbours edge to edge: turning it back
    would cover ground twice); turn clockwise cells counter-clockwise; drop flat
    cells; drop cells that overlap, along an edge or where two parts lie
    over each other (the smaller part gives way, with a warning; see
    :func:`remove_overlapping_cells`); then, as the guide's
    ``fix_bad_edges_and_mesh``, alternate deleting small disconnected parts
    (``delete_exterior_elements``) and interior cells at vertices with more
    than two boundary edges (``delete_interior_elements``; a warning when
    they take more than :data:`PEELED_AREA` of the area) until neither
    changes anything; finally drop unused vertices.

    Parameters
    ----------
    mesh_or_points : Mesh or numpy.ndarray, shape (n, 2)
        A mesh, or vertex coordinates (any units) with ``cells``.
    cells : numpy.ndarray, shape (m, 3), optional
        Vertex indices of each triangle, when ``mesh_or_points`` is points.
    disjoint_cutoff : float, optional
        Parts with fewer cells than this fraction of all cells are deleted;
        the largest part always stays. 0.01 by default (the guide's
        ``dj_cutoff``); 0 keeps every part, 1 only the largest.
    dj_cutoff : float, optional
        Alias of ``disjoint_cutoff`` (the guide's name).
    by : {"cells", "area"}, optional
        Measure the parts by cell count (the guide) or by area.
    merge_tolerance : float, optional
        Vertices closer than this (units of the points) are merged; see
        :func:`merge_duplicate_points`.
    min_quality : float, optional
        Cells of lower quality (guide eq. 1) count as flat and are dropped.
    geographic : bool, optional
        Points are longitude, latitude (degrees); by default taken from the
        mesh's ``crs`` (False for arrays). Only the quality used to choose
        among cells depends on it.

    Returns
    -------
    Mesh
        A new valid mesh (:func:`~terramesh.cleanup.mesh_problems` is empty,
        but for hanging nodes).
        ``info["repair"]`` is a :class:`RepairReport` of what was removed.
        ``point_data`` follows the vertices kept; ``boundaries`` are kept only
        when nothing changed (a warning says when they are dropped);
        ``info["fixed_points"]`` (vertex numbers) follow the vertices, a
        merged duplicate's to the vertex at its place (-1, with a warning,
        for those deleted). Boundary
        vertices of two boundary loops closer than
        :data:`~terramesh.cleanup.validity.NEAR_SEAM` of their shortest
        boundary edge (a seam of two meshes whose nodes differ by rounding)
        draw a warning naming ``merge_tolerance``; they are not merged.
        Hanging nodes (boundary vertices on another boundary edge: parts
        that meet along a line with nodes that do not match, see
        :func:`~terramesh.cleanup.validity.hanging_vertices`) draw a
        warning; no repair joins them, and ``mesh_problems`` names them.

    Raises
    ------
    MeshValidityError
        For malformed arrays or options, or when nothing valid remains.

    Examples
    --------
    A square of two cells, one clockwise, with a duplicated vertex, plus a
    detached triangle:

    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [1, 1], [5, 5], [6, 5], [5, 6]])
    >>> cells = np.array([[0, 1, 2], [0, 3, 4], [5, 6, 7]])
    >>> mesh = fix_mesh(points, cells, disjoint_cutoff=0.4)
    >>> mesh.n_points, mesh.n_cells
    (4, 2)
    >>> print(mesh.info["repair"])
    merged points: 1, unused points: 3, reoriented cells: 1, disjoint parts: 1, disjoint cells: 1
    """
    mesh, points, cells = as_triangle_arrays(mesh_or_points, cells, "fix_mesh")
    min_quality = _checked_min_quality(min_quality)
    if geographic is None:
        geographic = mesh is not None and mesh.geographic
    n_points, n_cells = len(points), len(cells)
    points, cells, source, report, _, overlap_free = fix_arrays(
        points,
        cells,
        cutoff=resolved_disjoint_cutoff(disjoint_cutoff, dj_cutoff),
        by=by,
        merge_tolerance=merge_tolerance,
        min_quality=min_quality,
        geographic=geographic,
        point_data=None if mesh is None else mesh.point_data,
    )
    return finished_mesh(
        mesh,
        points,
        cells,
        source,
        report,
        n_points=n_points,
        n_cells=n_cells,
        what="fix_mesh",
        merge_tolerance=merge_tolerance,
        overlap_free=overlap_free,
    )


def fix_arrays(
    points, cells, *, cutoff, by, merge_tolerance, min_quality, geographic, point_data=None, what="fix_mesh"
):
    """The steps of :func:`fix_mesh` on validated arrays: ``(points, cells, source, report, table, overlap_free)``.

    ``source`` is the input index of each returned vertex; vertices may be
    unused (``report.unused_points`` is left for :func:`finished_mesh`); ``table``
    is the cells' neighbour table (None when there were no cells);
    ``overlap_free`` says the cells were found not to overlap (see
    :func:`_without_overlaps`). The
    mesh's ``point_data``, if given, are compared where duplicates merge.
    """
    n_points = len(points)
    given = cells
    points, cells, source, into = _merged(points, cells, merge_tolerance)
    if point_data and len(source) < n_points:
        _warn_merged_data_differ(point_data, into, given, what)
    counts = {"merged_points": n_points - len(points)}
    before = len(cells)
    cells = remove_duplicate_cells(cells)
    counts["duplicate_cells"] = before - len(cells)
    signed = signed_areas(points, cells)
    clockwise = signed < 0
    if clockwise.any() and not clockwise.all():
        points, moved, folded = _untangle(points, cells, signed, min_quality, geographic)
        if len(folded):
            x, y = points[cells[folded[0]]].mean(axis=0)
            warn_user(
                f"{len(folded)} cells are folded over their neighbours (inverted, though they fit their neighbours"
                f" edge to edge: a vertex moved past a neighbour?) near ({x:.6g}, {y:.6g}), and moving vertices to"
                f" the mean of their neighbours did not untangle them; {what} turns them over and cuts away the"
                " ground they cover twice, if it can: move the vertex back or delete its cells",
            )
        if moved.any():
            counts["untangled_points"] = int(moved.sum())
            x, y = points[np.argmax(moved)]
            warn_user(
                f"{what} moved {int(moved.sum())} vertices that a fold had carried past their neighbours (their"
                f" cells were inverted, though they fit their neighbours edge to edge) to the mean of their"
                f" neighbours, the first to ({x:.6g}, {y:.6g}); their point data are kept",
            )
            clockwise = signed_areas(points, cells) < 0
    counts["reoriented_cells"] = int(clockwise.sum())
    cells = _turned(cells, clockwise)
    before = len(cells)
    cells = remove_degenerate_cells(points, cells, min_quality)
    counts["degenerate_cells"] = before - len(cells)
    before = len(cells)
    cells, overlap_free = _without_overlaps(points, cells, geographic)
    counts["overlapping_cells"] = before - len(cells)
    cells, topology, table = repair_topology(points, cells, cutoff=cutoff, by=by, geographic=geographic, what=what)
    return points, cells, source, RepairReport(**counts) + topology, table, overlap_free


def _warn_merged_data_differ(point_data, into, cells, what):
    """Warn when vertices merged into one, each used by a cell, had different ``point_data``.

    ``into[i]`` is the vertex that input vertex ``i`` became and ``cells``
    the input cells; the merged vertex keeps its own values (of the
    lowest-numbered vertex in use), so values of the others are lost.
    """
    used = np.zeros(len(into), dtype=bool)
    used[cells.ravel()] = True
    merged = np.flatnonzero(used & (into != np.arange(len(into))))
    if len(merged) == 0:
        return
    differ = np.zeros(len(merged), dtype=bool)
    names = []
    for name, values in point_data.items():
        values = np.asarray(values)
        if len(values) != len(into) or name.startswith("_"):  # a caller's own working data (enforce_timestep's)
            continue
        mine, kept = values[merged], values[into[merged]]
        unequal = mine != kept
        if values.dtype.kind in "fc":
            unequal &= ~(np.isnan(mine) & np.isnan(kept))
        unequal = unequal.reshape(len(merged), -1).any(axis=1)
        if unequal.any():
            names.append(name)
            differ |= unequal
    if differ.any():
        count = len(np.unique(into[merged[differ]]))
        warn_user(
            f"{what} merged duplicate vertices, each used by cells, whose point data differ ({', '.join(names)})"
            f" at {count} vertices: each keeps the values of its lowest-numbered vertex in use",
        )


_UNTANGLE_ROUNDS = 8
"""Most rounds of :func:`_untangle`; a fold still there after them is left as it was."""


def _untangle(points, cells, signed, min_quality, geographic):
    """Move interior vertices that a fold carried past their neighbours to the mean of their neighbours.

    A cell listed with its corners in the wrong order runs each of its
    edges the same way as the cell across it; a cell turned over by a
    vertex dragged past its neighbour (a fold) still fits its neighbours
    edge to edge, and only its sign disagrees with theirs. So the parts
    whose cells fit edge to edge are found, each part's orientation is the
    sign of its total signed area (the area its boundary encloses, which a
    fold does not change), and its cells of the other sign (of quality
    ``min_quality`` or more: flat cells are dropped later) are folded.
    Turning them over would leave ground covered twice.

    A vertex of a folded cell that has no boundary edge goes to the mean of
    its neighbours when that gives every one of its cells the part's
    orientation, so its cells fill the polygon of its neighbours exactly
    once; of the vertices of one cell that could, the one farthest from
    its neighbours' mean (the one dragged) moves, so no two moved vertices
    share a cell. Where no single vertex can (two neighbours dragged), all
    of them move at once, as in a smoothing pass. The rounds repeat while
    folded cells are left, at most :data:`_UNTANGLE_ROUNDS`. ``signed`` are
    the cells' signed areas. Returns ``(points, moved, folded)``: a new
    array, the (n,) mask of the vertices moved and the folded cells left
    (their indices; then no vertex moved). A fold
    it cannot undo (at a boundary vertex, or a neighbourhood the means do
    not untangle) is left as it was, every vertex in place, to the later
    steps and the final check.
    """
    n = len(points)
    n_parts, labels = _parts_across_edges(cells, n)
    orientation = np.sign(np.bincount(labels, weights=signed, minlength=n_parts))[labels]

    def folded_cells(points, signed):
        """The cells turned against their part, less those flat enough for the later steps to drop."""
        folded = np.flatnonzero(signed * orientation < 0)
        return folded[np.abs(triangle_quality(points, cells[folded], geographic=geographic)) >= min_quality]

    folded = folded_cells(points, signed)
    moved = np.zeros(n, dtype=bool)
    if len(folded) == 0:
        return points, moved, folded
    given, points, first_folded = points, points.copy(), folded
    interior = np.ones(n, dtype=bool)
    interior[boundary_edges(cells).ravel()] = False
    for _ in range(_UNTANGLE_ROUNDS):
        candidate = np.zeros(n, dtype=bool)
        candidate[cells[folded].ravel()] = True
        candidate &= interior
        star = np.flatnonzero(any_corner_in(candidate, cells))
        row, corner = np.nonzero(candidate[cells[star]])
        cell = star[row]
        vertex = cells[cell, corner]
        here = points[vertex]
        after = points[cells[cell, (corner + 1) % 3]] - here
        before = points[cells[cell, (corner + 2) % 3]] - here
        count = np.bincount(vertex, minlength=n)
        # each neighbour of an interior vertex is in two of its cells
        shift = (
            np.column_stack([np.bincount(vertex, weights=after[:, k] + before[:, k], minlength=n) for k in range(2)])
            / np.maximum(2 * count, 1)[:, None]
        )
        # the cells of each candidate with it at its neighbours' mean: the part's orientation, not flat
        after, before = after - shift[vertex], before - shift[vertex]
        area = orientation[cell] * (after[:, 0] * before[:, 1] - after[:, 1] * before[:, 0])
        squares = np.sum(after**2, axis=1) + np.sum(before**2, axis=1) + np.sum((after - before) ** 2, axis=1)
        good = (area > 0) & (2 * np.sqrt(3) * area >= min_quality * squares)
        movable = candidate & _one_label(vertex, labels[cell], n)
        fixes = movable & (np.bincount(vertex, weights=~good, minlength=n) == 0)
        if fixes.any():
            # of the candidates sharing a cell, the one farthest from its neighbours' mean (then the lowest) moves
            distance = np.where(fixes, np.hypot(shift[:, 0], shift[:, 1]), -1.0)
            rank = np.empty(n, dtype=np.int64)
            rank[np.lexsort((-np.arange(n), distance))] = np.arange(n)
            best = np.full(len(cells), -1, dtype=np.int64)
            np.maximum.at(best, cell[fixes[vertex]], rank[vertex[fixes[vertex]]])
            chosen = fixes & (np.bincount(vertex, weights=best[cell] != rank[vertex], minlength=n) == 0)
        else:  # no one vertex untangles its cells (two neighbours dragged): all move at once, as a smoothing pass
            chosen = movable
        if not chosen.any():
            break
        points[chosen] += shift[chosen]
        moved |= chosen
        folded = folded_cells(points, signed_areas(points, cells))
        if len(folded) == 0:
            return points, moved, folded
    return given, np.zeros(n, dtype=bool), first_folded  # not untangled: left to the later steps and the final check


def _one_label(vertex, label, n):
    """Whether all the ``label`` entries of each vertex (``vertex`` numbers entries) are one: (n,) mask."""
    low = np.full(n, np.iinfo(np.int64).max, dtype=np.int64)
    high = np.full(n, -1, dtype=np.int64)
    np.minimum.at(low, vertex, label)
    np.maximum.at(high, vertex, label)
    return (high < 0) | (low == high)


def repair_topology(points, cells, *, cutoff, by, geographic, table=None, what=None):
    """The guide's ``fix_bad_edges_and_mesh``: alternate the exterior and interior deletions until stable.

    ``cells`` are conforming (each edge in at most two cells, in opposite
    directions); ``table`` is their neighbour table, if known. Both
    deletions follow the table, made once. Returns ``(cells, report,
    table)``, the table of the returned cells. With ``what`` (the caller's
    name), the interior deletions that take more than :data:`PEELED_AREA`
    of the area are warned of (:func:`~terramesh.cleanup.clean`'s rounds
    count theirs in its own warning).
    """
    if table is None and len(cells):
        table = neighbor_table(cells, len(points))
    parts = disjoint = interior = 0
    area_before = area_left = total_signed_area(points, cells)
    pinched = np.zeros(0, dtype=np.int64)  # the first round's vertices with more than two boundary edges
    while len(cells):
        delete, n_parts = disjoint_parts_to_delete(points, cells, cutoff, by, table=table)
        if n_parts:
            area_left -= total_signed_area(points, cells[delete])
            cells, table = subset(cells, table, ~delete)
            parts, disjoint = parts + n_parts, disjoint + int(delete.sum())
        before = len(cells)
        if what is not None and not interior:
            pinched = np.flatnonzero(boundary_degree(cells, table, len(points)) > 2)
        cells, table = delete_interior_cells_with_table(points, cells, table, geographic)
        interior += before - len(cells)
        if len(cells) == before:
            break
    if what is not None and interior:
        x, y = points[pinched[0]]
        warn_if_area_lost(
            area_before,
            area_before - (area_left - total_signed_area(points, cells)),
            what,
            f"{interior} cells deleted at {len(pinched)} boundary vertices with more than two boundary edges,"
            f" the first at ({x:.6g}, {y:.6g})",
            "there two parts touch, and the cells go until they do not (the guide's delete_interior_elements);"
            " where parts meet along a line with nodes that do not match (hanging nodes), give them matching"
            " nodes there instead",
        )
    return cells, RepairReport(disjoint_parts=parts, disjoint_cells=disjoint, interior_cells=interior), table


def total_signed_area(points, cells):
    """The cells' total signed area, in the points' units (degrees squared on longitude, latitude: a share counts)."""
    return float(np.sum(signed_areas(points, cells))) if len(cells) else 0.0


def warn_if_area_lost(before, after, what, removed, advice):
    """Warn when ``what`` took more than :data:`PEELED_AREA` of the area ``before``: ``removed`` says what went."""
    if before > 0 and before - after > PEELED_AREA * before:
        warn_user(f"{what} removed {100 * (before - after) / before:.2g} % of the mesh's area ({removed}): {advice}")
