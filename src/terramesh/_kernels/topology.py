"""Connectivity kernels on triangulations stored with a neighbour table.

``cells`` (m, 3) int64 counter-clockwise; ``neighbors`` (m, 3) int64,
``neighbors[c, k]`` the cell across the edge opposite corner ``k`` (the edge
``cells[c, k+1], cells[c, k+2]``), -1 on the boundary.
"""

import numba
import numpy as np

from .chunks import CHUNKS, chunk_range, chunk_totals

_CHUNK = 16384  # cells per task of a parallel pass (each has its own scratch); the output does not depend on it
_GROUP_TASKS = 64  # parallel tasks over the vertices' groups of edges; the output does not depend on it


@numba.njit(cache=True, parallel=True)
def inner_cell_edges(cells, neighbors, keep, first):
    """The cells ``keep`` marks, their edges once each, and a flag marking the edges on their boundary.

    An edge is a boundary edge of the kept cells when the cell across it
    is not kept (or there is none). Returns ``(kept cells (k, 3), edges
    (e, 2), boundary (e,) bool)``, vertex numbers less ``first`` (a
    triangulation's own arrays number its frame first, see
    :func:`classify_cells`); each edge comes from the kept cell of larger
    index that has it, so no sorting is needed. One pass instead of
    NumPy's mask, cumsum, fancy indexing and renumbering, which at 10**7
    cells each sweep the arrays and allocate a copy. Blocks of cells count
    their rows, then fill them from their offsets, in parallel: the same
    arrays as one pass in order (a generator calls this at every
    triangulation: 17 ms at 670k cells in one thread).
    """
    m = cells.shape[0]
    blocks = (m + _CHUNK - 1) // _CHUNK
    n_kept = np.zeros(blocks + 1, dtype=np.int64)
    n_edges = np.zeros(blocks + 1, dtype=np.int64)
    for block in numba.prange(blocks):
        kept_here = 0
        edges_here = 0
        for c in range(block * _CHUNK, min(m, (block + 1) * _CHUNK)):
            if not keep[c]:
                continue
            kept_here += 1
            for k in range(3):
                n = neighbors[c, k]
                if n < c or not keep[n]:
                    edges_here += 1
        n_kept[block + 1] = kept_here
        n_edges[block + 1] = edges_here
    n_kept = np.cumsum(n_kept)
    n_edges = np.cumsum(n_edges)
    kept = np.empty((n_kept[blocks], 3), dtype=cells.dtype)
    edges = np.empty((n_edges[blocks], 2), dtype=np.int64)
    boundary = np.empty(n_edges[blocks], dtype=np.bool_)
    for block in numba.prange(blocks):
        j = n_kept[block]
        i = n_edges[block]
        for c in range(block * _CHUNK, min(m, (block + 1) * _CHUNK)):
            if not keep[c]:
                continue
            for k in range(3):
                kept[j, k] = cells[c, k] - first
                n = neighbors[c, k]
                outer = n < 0 or not keep[n]
                if n < c or outer:
                    edges[i, 0] = cells[c, (k + 1) % 3] - first
                    edges[i, 1] = cells[c, (k + 2) % 3] - first
                    boundary[i] = outer
                    i += 1
            j += 1
    return kept, edges, boundary


@numba.njit(cache=True, inline="always")
def _first_corner(cells, c, k):
    """Whether corner ``k`` of cell ``c`` is its vertex's first occurrence in the cell."""
    for j in range(k):
        if cells[c, j] == cells[c, k]:
            return False
    return True


@numba.njit(cache=True)
def vertex_cells(cells, n_points):
    """The cells at each vertex as a compressed table: cells ``index[start[v]:start[v + 1]]`` contain ``v``.

    A cell with a repeated corner is listed once at that vertex.
    """
    corners = cells.shape[1]
    start = np.zeros(n_points + 1, dtype=np.int64)
    for c in range(cells.shape[0]):
        for k in range(corners):
            if _first_corner(cells, c, k):
                start[cells[c, k] + 1] += 1
    for v in range(n_points):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    index = np.empty(start[n_points], dtype=np.int64)
    for c in range(cells.shape[0]):
        for k in range(corners):
            if _first_corner(cells, c, k):
                v = cells[c, k]
                index[fill[v]] = c
                fill[v] += 1
    return start, index


@numba.njit(cache=True)
def edges_by_lower_vertex(cells, n_points):
    """The edges of triangles grouped by their lower vertex, as a compressed table ``(start, index, upper)``.

    Edge ``e = 3 * c + k`` runs from corner ``k`` of cell ``c`` to corner
    ``k + 1``; the edges ``index[start[v]:start[v + 1]]``, in increasing
    ``e``, have ``v`` as their lower vertex and ``upper[start[v]:start[v + 1]]``
    as their higher one. Equal edges (as unordered pairs) share a group of
    a handful of edges, where their higher vertices match: finding them
    takes a few comparisons within a small contiguous run per edge and no
    sort, in 16 bytes per edge.
    """
    m = cells.shape[0]
    start = np.zeros(n_points + 1, dtype=np.int64)
    for c in range(m):
        for k in range(3):
            start[min(cells[c, k], cells[c, (k + 1) % 3]) + 1] += 1
    for v in range(n_points):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    index = np.empty(3 * m, dtype=np.int64)
    upper = np.empty(3 * m, dtype=np.int64)
    for c in range(m):
        for k in range(3):
            u = cells[c, k]
            w = cells[c, (k + 1) % 3]
            v = min(u, w)
            index[fill[v]] = 3 * c + k
            upper[fill[v]] = max(u, w)
            fill[v] += 1
    return start, index, upper


@numba.njit(cache=True, parallel=True)
def lone_edges(cells, n_points):
    """Directed edges of triangles that no other edge of any cell repeats (as an unordered pair).

    The same edges in the same order as sorting all edges and keeping the
    pairs seen once (edge 0-1 of every cell, then 1-2, then 2-0). Equal
    edges meet in one group of :func:`edges_by_lower_vertex`, so each edge is
    compared with the few others of its group: linear time, where scanning
    every edge of every cell around an edge's first vertex took about 18
    comparisons per edge, and the sort about a second per 10**6 cells. The
    groups are compared in parallel (an edge is in one group only) on the
    higher vertices the grouping lists beside them: 37-42 -> 33-35 ms at
    587k cells on 2 cores, the grouping's serial pass most of the rest.
    """
    m = cells.shape[0]
    start, index, upper = edges_by_lower_vertex(cells, n_points)
    lone = np.ones(3 * m, dtype=np.bool_)
    per_task = (n_points + _GROUP_TASKS - 1) // _GROUP_TASKS
    for task in numba.prange(_GROUP_TASKS):
        for v in range(task * per_task, min(n_points, (task + 1) * per_task)):
            for i in range(start[v], start[v + 1]):
                for j in range(i + 1, start[v + 1]):
                    if upper[i] == upper[j]:
                        lone[index[i]] = False
                        lone[index[j]] = False
    total = 0
    for e in range(3 * m):
        total += lone[e]
    edges = np.empty((total, 2), dtype=cells.dtype)
    row = 0
    for k in range(3):
        for c in range(m):
            if lone[3 * c + k]:
                edges[row, 0] = cells[c, k]
                edges[row, 1] = cells[c, (k + 1) % 3]
                row += 1
    return edges


@numba.njit(cache=True, inline="always")
def cross_and_squares(points, cells, c):
    """Twice the signed area of triangle ``c`` (positive counter-clockwise) and the sum of its squared sides."""
    a = cells[c, 0]
    b = cells[c, 1]
    d = cells[c, 2]
    abx = points[b, 0] - points[a, 0]
    aby = points[b, 1] - points[a, 1]
    adx = points[d, 0] - points[a, 0]
    ady = points[d, 1] - points[a, 1]
    bdx = points[d, 0] - points[b, 0]
    bdy = points[d, 1] - points[b, 1]
    return abx * ady - aby * adx, abx * abx + aby * aby + adx * adx + ady * ady + bdx * bdx + bdy * bdy


@numba.njit(cache=True, inline="always")
def corner_quality(ax, ay, bx, by, cx, cy):
    """Quality ``4 sqrt(3) A / sum(l**2)`` of the triangle of these corners: 1 equilateral, negative clockwise.

    0 when all corners coincide. The one formula the kernels compile: the
    mesh's qualities, the smoothing's trial moves.
    """
    abx = bx - ax
    aby = by - ay
    acx = cx - ax
    acy = cy - ay
    bcx = cx - bx
    bcy = cy - by
    squares = abx * abx + aby * aby + acx * acx + acy * acy + bcx * bcx + bcy * bcy
    if squares > 0.0:
        return 2.0 * np.sqrt(3.0) * (abx * acy - aby * acx) / squares
    return 0.0


@numba.njit(cache=True, inline="always")
def _quality(points, cells, c):
    """:func:`corner_quality` of triangle ``c`` of ``cells``."""
    a, b, d = cells[c, 0], cells[c, 1], cells[c, 2]
    return corner_quality(points[a, 0], points[a, 1], points[b, 0], points[b, 1], points[d, 0], points[d, 1])


@numba.njit(cache=True)
def triangle_qualities(points, cells):
    """Quality of every triangle, shape (m,): one pass where NumPy makes a dozen (m, 2) temporaries."""
    out = np.empty(cells.shape[0])
    for c in range(cells.shape[0]):
        out[c] = _quality(points, cells, c)
    return out


@numba.njit(cache=True, parallel=True)
def quality_mean_std(points, cells):
    """Mean and standard deviation of the triangle quality 4 sqrt(3) A / sum(l^2), in one pass (:mod:`.chunks`)."""
    m = cells.shape[0]
    sums = np.zeros((CHUNKS, 2))
    for chunk in numba.prange(CHUNKS):
        start, stop = chunk_range(chunk, m, CHUNKS)
        total = 0.0
        total2 = 0.0
        for c in range(start, stop):
            q = _quality(points, cells, c)
            total += q
            total2 += q * q
        sums[chunk, 0] = total
        sums[chunk, 1] = total2
    totals = chunk_totals(sums)
    total, total2 = totals[0], totals[1]
    mean = total / max(m, 1)
    return mean, np.sqrt(max(total2 / max(m, 1) - mean * mean, 0.0))


@numba.njit(cache=True, parallel=True)
def classify_cells(points, cells, distance_bound, tolerance, first):
    """Sort cells (triangles or tetrahedra) for an inside test: 1 certainly inside, 0 to evaluate, -1 not a cell.

    Vertex ``v`` of a cell is point ``v - first``; a cell with a vertex
    outside ``[first, first + n)`` is not a cell of the ``n`` points (a
    triangulation's ghost or frame cells: -1), so its own arrays serve
    without a ghost-free copy. ``distance_bound`` (n,) bounds a 1-Lipschitz
    signed distance from above at each point (empty: no bound), so the
    distance at the centroid is at most ``bound[v] + |centroid - v|`` for
    every vertex ``v``; below ``-tolerance`` for one of them proves it
    deeper inside than ``tolerance``. One vertex inside suffices: a cell on
    a coastline, two vertices on it, is proved by its third.
    Returns an int8 (m,) array.
    """
    # the shape a literal in each copy of the body: its loops unroll
    if cells.shape[1] == 3 and points.shape[1] == 2:
        return _classified(points, cells, distance_bound, tolerance, first, 3, 2)
    if cells.shape[1] != 4 or points.shape[1] != 3:
        raise ValueError("classify_cells sorts triangles in 2D or tetrahedra in 3D")
    return _classified(points, cells, distance_bound, tolerance, first, 4, 3)


@numba.njit(cache=True, inline="always")
def _classified(points, cells, distance_bound, tolerance, first, corners, dim):
    """:func:`classify_cells` of cells of ``corners`` vertices in ``dim`` dimensions."""
    m = cells.shape[0]
    n = points.shape[0]
    bounded = distance_bound.shape[0] > 0
    state = np.zeros(m, dtype=np.int8)
    for task in numba.prange((m + _CHUNK - 1) // _CHUNK):
        centroid = np.empty(dim)  # one scratch per task
        for c in range(task * _CHUNK, min(m, (task + 1) * _CHUNK)):
            real = True
            lowest = np.inf
            for i in range(corners):
                v = cells[c, i] - first
                if v < 0 or v >= n:
                    real = False
                elif bounded:
                    lowest = min(lowest, distance_bound[v])
            if not real:
                state[c] = -1
                continue
            if lowest >= -tolerance:
                continue  # every vertex near the boundary (or no bound): nothing can prove it inside
            for d in range(dim):
                total = 0.0
                for i in range(corners):
                    total += points[cells[c, i] - first, d]
                centroid[d] = total / corners
            for i in range(corners):
                v = cells[c, i] - first
                if distance_bound[v] < -tolerance:
                    length2 = 0.0
                    for d in range(dim):
                        delta = centroid[d] - points[v, d]
                        length2 += delta * delta
                    if distance_bound[v] + np.sqrt(length2) < -tolerance:
                        state[c] = 1
                        break
    return state


@numba.njit(cache=True)
def cell_centroids(points, cells, which, first):
    """Centroids of the cells ``which`` (k,) int64, shape (k, dim); vertex ``v`` is point ``v - first``."""
    dim = points.shape[1]
    corners = cells.shape[1]
    out = np.empty((which.shape[0], dim))
    for i in range(which.shape[0]):
        c = which[i]
        for d in range(dim):
            total = 0.0
            for k in range(corners):
                total += points[cells[c, k] - first, d]
            out[i, d] = total / corners
    return out


@numba.njit(cache=True)
def used_vertices(cells, n_points):
    """The vertices the ``cells`` use, ascending, and the cells renumbered to them: ``(kept (k,), cells, ok)``.

    Two passes over the cells; NumPy's mask, flatnonzero and two fancy
    indexings take three times as long at 10**7 cells. ``ok`` is False
    (and the arrays empty) when a vertex number is outside ``[0, n_points)``.
    """
    renumber = np.full(n_points, -1, dtype=np.int64)
    for c in range(cells.shape[0]):
        for k in range(cells.shape[1]):
            v = cells[c, k]
            if v < 0 or v >= n_points:
                return np.empty(0, dtype=np.int64), np.empty((0, cells.shape[1]), dtype=cells.dtype), False
            renumber[v] = 0
    count = 0
    for v in range(n_points):
        if renumber[v] == 0:
            renumber[v] = count
            count += 1
    kept = np.empty(count, dtype=np.int64)
    for v in range(n_points):
        if renumber[v] >= 0:
            kept[renumber[v]] = v
    renumbered = np.empty_like(cells)
    for c in range(cells.shape[0]):
        for k in range(cells.shape[1]):
            renumbered[c, k] = renumber[cells[c, k]]
    return kept, renumbered, True


@numba.njit(cache=True)
def rows_renumbered(table, numbering):
    """The rows of ``table`` (cells or edges) whose vertices all have ``numbering >= 0``, renumbered by it.

    One pass; NumPy's mask, ``all`` and two fancy indexings took 13 ms
    for a coastline's 135k cells, 200k edges and their boundary, the
    generator's cost of dropping one doubled point.
    """
    out = np.empty_like(table)
    count = 0
    for r in range(table.shape[0]):
        kept = True
        for k in range(table.shape[1]):
            out[count, k] = numbering[table[r, k]]
            kept = kept and out[count, k] >= 0
        count += kept
    return out[:count]


@numba.njit(cache=True)
def table_boundary_edges(cells, table):
    """The edges of ``cells`` with no cell across (``table`` -1), as in their cell, cell by cell: shape (b, 2).

    For conforming cells with their neighbour table, the edges
    :func:`lone_edges` finds (in another order) without matching every edge.
    """
    count = 0
    for c in range(cells.shape[0]):
        for k in range(3):
            count += table[c, k] < 0
    edges = np.empty((count, 2), dtype=cells.dtype)
    i = 0
    for c in range(cells.shape[0]):
        for k in range(3):
            if table[c, k] < 0:
                edges[i, 0] = cells[c, (k + 1) % 3]
                edges[i, 1] = cells[c, (k + 2) % 3]
                i += 1
    return edges


@numba.njit(cache=True)
def subset(cells, table, keep):
    """The cells ``keep`` marks and their neighbour table, renumbered; an edge shared with a dropped cell becomes -1."""
    m = table.shape[0]
    renumber = np.empty(m, dtype=np.int64)
    count = 0
    for c in range(m):
        renumber[c] = count if keep[c] else -1
        count += keep[c]
    kept = np.empty((count, 3), dtype=cells.dtype)
    out = np.empty((count, 3), dtype=np.int64)
    for c in range(m):
        if keep[c]:
            for k in range(3):
                kept[renumber[c], k] = cells[c, k]
                n = table[c, k]
                out[renumber[c], k] = renumber[n] if n >= 0 else -1
    return kept, out


@numba.njit(cache=True)
def first_equal_rows(bits):
    """For each row, the first row equal to it (itself if none before): a hash table of the rows seen, one pass.

    ``bits`` (n, d) uint64: the rows' coordinates as bit patterns (equal
    floats, -0.0 made 0.0 first, have equal bits). A sort of every
    candidate point took 8-10 ms at 80k boundary points, in every
    iteration on a coastline; this takes one.
    """
    n, d = bits.shape
    size = 2
    while size < 2 * n:
        size *= 2
    mask = size - 1
    table = np.full(size, -1, dtype=np.int64)
    first = np.arange(n)
    for k in range(n):
        h = np.uint64(0x9E3779B97F4A7C15)
        for j in range(d):
            h = (h ^ bits[k, j]) * np.uint64(0xBF58476D1CE4E5B9)
            h ^= h >> np.uint64(31)
        slot = np.int64(h & np.uint64(mask))
        while table[slot] >= 0:
            other = table[slot]
            same = True
            for j in range(d):
                if bits[other, j] != bits[k, j]:
                    same = False
                    break
            if same:
                first[k] = other
                break
            slot = (slot + 1) & mask
        if first[k] == k:
            table[slot] = k
    return first


@numba.njit(cache=True)
def same_rows(table, before, rows, wanted):
    """Which of ``rows`` are ``wanted`` and hold the same entries in ``table`` as in ``before``.

    NumPy's ``wanted[rows] & all(table[rows] == before[rows], axis=1)``
    copied the rows out first (5 ms for 116k rows of cells; this, 0.3).
    """
    same = np.zeros(rows.shape[0], dtype=np.bool_)
    for k in range(rows.shape[0]):
        r = rows[k]
        if not wanted[r]:
            continue
        equal = True
        for j in range(table.shape[1]):
            if table[r, j] != before[r, j]:
                equal = False
                break
        same[k] = equal
    return same


@numba.njit(cache=True)
def walk_loops(next_vertex, vertices):
    """Follow ``next_vertex`` from each unvisited vertex of ``vertices`` (ascending): the loops, concatenated."""
    order = np.empty(len(vertices), dtype=np.int64)
    starts = np.empty(len(vertices) + 1, dtype=np.int64)
    visited = np.zeros(len(next_vertex), dtype=np.bool_)
    k = 0
    n_loops = 0
    for v in vertices:
        if visited[v]:
            continue
        starts[n_loops] = k
        n_loops += 1
        w = v
        while not visited[w]:
            visited[w] = True
            order[k] = w
            k += 1
            w = next_vertex[w]
    starts[n_loops] = k
    return order, starts[: n_loops + 1]


@numba.njit(cache=True, inline="always")
def _side_length(x, y, cos_y, a, b, radius, geographic):
    """Length of the side ``a, b`` (``a < b``): great-circle (radians, ``radius``) or Euclidean."""
    if not geographic:
        return np.hypot(x[b] - x[a], y[b] - y[a])
    h = np.sin(0.5 * (y[b] - y[a])) ** 2 + cos_y[a] * cos_y[b] * np.sin(0.5 * (x[b] - x[a])) ** 2
    return 2.0 * radius * np.arcsin(np.sqrt(min(max(h, 0.0), 1.0)))


@numba.njit(cache=True, parallel=True)
def shortest_sides(cells, x, y, cos_y, radius, geographic):
    """The shortest side of the cells at each vertex, shape (n,); inf at vertices no cell uses.

    ``x, y`` are the vertices' coordinates, longitude and latitude in
    radians with ``cos_y`` the latitudes' cosines when ``geographic`` (the
    haversine on a sphere of ``radius``); else planar. Each side is
    measured from its lower vertex, so that it measures the same from
    either cell. The sides are measured in parallel, cell by cell, and the
    smallest found at each vertex in one pass: 63 ms for the 587k cells of
    the guide's §5.3 mesh (radians and cosines included), where sorting
    the sides, measuring them in NumPy and taking the minima took 430 ms.
    """
    m = cells.shape[0]
    lengths = np.empty((m, 3))
    for c in numba.prange(m):
        for k in range(3):
            a = cells[c, k]
            b = cells[c, (k + 1) % 3]
            lengths[c, k] = _side_length(x, y, cos_y, min(a, b), max(a, b), radius, geographic)
    smallest = np.full(x.shape[0], np.inf)
    for c in range(m):
        for k in range(3):
            for v in (cells[c, k], cells[c, (k + 1) % 3]):
                if lengths[c, k] < smallest[v]:
                    smallest[v] = lengths[c, k]
    return smallest
