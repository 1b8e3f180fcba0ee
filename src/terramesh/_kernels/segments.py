"""Point-to-segment distances over candidate lists, and the pairs of segments that meet."""

import numba
import numpy as np

from .arrays import grown
from .delaunay import ORIENT_BOUND, WORK_SIZE, orient


@numba.njit(cache=True, inline="always")
def _on_segment(px, py, starts, ends, s):
    """Squared distance from ``(px, py)`` to segment ``s`` and the segment's nearest point.

    The distance is taken from the differences to the segment's start,
    which are exact for a point near it, not from the nearest point's
    coordinates: at 4e6 m those are rounded to 1e-9 m, which would tie
    the two sides of a crack that thin.
    """
    ax = starts[s, 0]
    ay = starts[s, 1]
    dx = ends[s, 0] - ax
    dy = ends[s, 1] - ay
    ux = px - ax
    uy = py - ay
    length2 = dx * dx + dy * dy
    t = 0.0
    if length2 > 0.0:
        t = (ux * dx + uy * dy) / length2
        t = min(max(t, 0.0), 1.0)
    ux -= t * dx
    uy -= t * dy
    return ux * ux + uy * uy, ax + t * dx, ay + t * dy, t


@numba.njit(cache=True, inline="always")
def _nearest_candidate(points, starts, ends, candidates, i):
    """Squared distance from ``points[i]`` to the nearest of its candidate segments, and that nearest point."""
    px = points[i, 0]
    py = points[i, 1]
    smallest = np.inf
    nearest_x = px
    nearest_y = py
    for j in range(candidates.shape[1]):
        distance2, x, y, _ = _on_segment(px, py, starts, ends, candidates[i, j])
        if distance2 < smallest:
            smallest = distance2
            nearest_x = x
            nearest_y = y
    return smallest, nearest_x, nearest_y


@numba.njit(cache=True, parallel=True)
def grid_nearest(points, starts, ends, origin, cell, nx, ny, cell_start, cell_items, max_ring):
    """Exact nearest point on the segments, searching the cells of a bucket grid ring by ring.

    ``cell_items[cell_start[c]:cell_start[c + 1]]`` are the segments meeting
    grid cell ``c = i * ny + j`` (side ``cell``, lower-left corner
    ``origin``). A segment not listed in the first ``r`` rings of cells
    around a point's cell does not meet them, so it is at least the
    point's distance to its cell's sides plus ``(r - 1) * cell`` away:
    the search stops once the best distance found is within that (a point
    on a coastline, nearly always after its own cell: 1 cell searched
    instead of 9). The last ring's bound leaves out the distance to the
    cell's sides, so which points are settled does not depend on where
    they lie in their cell. Returns ``(distance (n,), nearest
    (n, 2), found (n,) bool)``; ``found`` is False where ``max_ring`` rings
    did not settle it (a point far from every segment), and for each point
    settled the nearest segment and the parameter (0 at its start, 1 at its
    end) of the nearest point on it.
    """
    n = points.shape[0]
    distance = np.full(n, np.inf)
    nearest = np.empty((n, 2))
    found = np.zeros(n, dtype=np.bool_)
    segment = np.full(n, -1, dtype=np.int64)
    parameter = np.zeros(n)
    for p in numba.prange(n):
        px = points[p, 0]
        py = points[p, 1]
        ci = int(np.floor((px - origin[0]) / cell))
        cj = int(np.floor((py - origin[1]) / cell))
        x_low = origin[0] + ci * cell
        y_low = origin[1] + cj * cell
        # to the cell's nearest side, less a margin for the rounding of the sides and of the floor above
        margin = 1e-14 * (abs(px) + abs(py) + abs(origin[0]) + abs(origin[1])) + 1e-9 * cell
        to_side = min(px - x_low, x_low + cell - px, py - y_low, y_low + cell - py) - margin
        best = np.inf
        bx = px
        by = py
        bs = -1
        bt = 0.0
        for r in range(max_ring + 2):
            if r > 0:
                reach = (r - 1) * cell + (max(to_side, 0.0) if r <= max_ring else 0.0)
                if best <= reach * reach:
                    found[p] = True
                    break
            if r > max_ring:
                break
            for di in range(-r, r + 1):
                i = ci + di
                if i < 0 or i >= nx:
                    continue
                edge_row = di == -r or di == r
                dj = -r
                while dj <= r:
                    j = cj + dj
                    if 0 <= j < ny:
                        c = i * ny + j
                        for k in range(cell_start[c], cell_start[c + 1]):
                            distance2, x, y, t = _on_segment(px, py, starts, ends, cell_items[k])
                            if distance2 < best:
                                best = distance2
                                bx = x
                                by = y
                                bs = cell_items[k]
                                bt = t
                    dj += 1 if edge_row else 2 * r
        if found[p]:
            distance[p] = np.sqrt(best)
            nearest[p, 0] = bx
            nearest[p, 1] = by
            segment[p] = bs
            parameter[p] = bt
    return distance, nearest, found, segment, parameter


# Below this length of the two unit normals' sum at a vertex, the segments nearly fold back (a needle's tip)
# and the sum's direction is rounding: the exact turn there tells the side instead...
_FOLD = 1e-4
# ...as it does for a point about as near the segment across the fold (relatively) as to its own: which of
# the two is nearer is rounding where the needle is as thin as 1e-16 of the point's distance
_TIE = 1e-12


@numba.njit(cache=True, inline="always")
def _folded(normal, first, second):
    """Whether segments ``first`` and ``second`` (which follows it) nearly fold back at their common vertex."""
    dx = normal[first, 0] + normal[second, 0]
    dy = normal[first, 1] + normal[second, 1]
    return dx * dx + dy * dy < _FOLD * _FOLD


@numba.njit(cache=True, inline="always")
def _fold_side(starts, chained_ends, first, second, corner, work):
    """Side of the points nearest a fold of ``first`` then ``second``: right of a left turn, left of a right one.

    0 where the two segments fold back exactly (no side from them alone).
    """
    corner[0] = starts[first]
    corner[1] = starts[second]
    corner[2] = chained_ends[second]
    turn = orient(corner, 0, 1, 2, work)
    return -1 if turn > 0.0 else (1 if turn < 0.0 else 0)


@numba.njit(cache=True)
def nearest_sides(points, settled, segment, parameter, normal, before, after, starts, ends, chained_ends):
    """Side (1 left, -1 right, 0 on it or not settled) of each point from its nearest point on closed rings.

    ``segment`` and ``parameter`` as :func:`grid_nearest` returns them
    for the segments ``starts``-``ends``, ``normal`` each segment's left
    unit normal, ``before``/``after`` the segments meeting it at its start
    and end, ``starts``-``chained_ends`` the segments chained exactly. The
    side is taken from the point's offset to the segment's start, as the
    distance is (not from the rounded nearest point). Nearest to a vertex (parameter 0 or 1),
    the side is that of the two normals' sum there. Where they nearly
    cancel (a needle's tip, whose width may be a rounding), the exact turn
    of the vertex tells it, for the points nearest the vertex and those
    the two segments tie for; 0 (undecided) where they fold back exactly.
    """
    n = points.shape[0]
    side = np.zeros(n, dtype=np.int8)
    corner = np.empty((3, 2))
    work = np.empty(WORK_SIZE)
    for p in range(n):
        if not settled[p]:
            continue
        piece = segment[p]
        t = parameter[p]
        px = points[p, 0]
        py = points[p, 1]
        fold = -1
        if t <= 0.0 or t >= 1.0:
            first = before[piece] if t <= 0.0 else piece
            if _folded(normal, first, after[first]):
                fold = first
        else:
            for first in (before[piece], piece):
                other = first if first != piece else after[piece]
                if _folded(normal, first, after[first]):  # rare: the distances only then
                    own = _on_segment(px, py, starts, chained_ends, piece)[0]
                    across = _on_segment(px, py, starts, chained_ends, other)[0]
                    if abs(across - own) <= _TIE * own:
                        fold = first
        if fold >= 0:
            side[p] = _fold_side(starts, chained_ends, fold, after[fold], corner, work)
            continue
        dx = normal[piece, 0]
        dy = normal[piece, 1]
        if t <= 0.0:
            dx += normal[before[piece], 0]
            dy += normal[before[piece], 1]
        if t >= 1.0:
            dx += normal[after[piece], 0]
            dy += normal[after[piece], 1]
        dot = (px - starts[piece, 0] - t * (ends[piece, 0] - starts[piece, 0])) * dx + (
            py - starts[piece, 1] - t * (ends[piece, 1] - starts[piece, 1])
        ) * dy
        side[p] = 1 if dot > 0.0 else (-1 if dot < 0.0 else 0)
    return side


@numba.njit(cache=True, parallel=True)
def candidate_segment_distance(points, starts, ends, candidates):
    """Smallest distance from ``points[i]`` to the segments ``candidates[i, :]``.

    ``points`` (n, 2), ``starts``/``ends`` (m, 2) float64, ``candidates`` (n, k)
    int64 with indices into the segments. Returns (n,) float64.
    """
    n = candidates.shape[0]
    best = np.empty(n)
    for i in numba.prange(n):
        best[i] = np.sqrt(_nearest_candidate(points, starts, ends, candidates, i)[0])
    return best


@numba.njit(cache=True, parallel=True)
def candidate_nearest_points(points, starts, ends, candidates):
    """The nearest point to ``points[i]`` on the segments ``candidates[i, :]``, and its distance.

    Arguments as for :func:`candidate_segment_distance`. Returns
    ``(distance (n,), nearest (n, 2))``.
    """
    n = candidates.shape[0]
    best = np.empty(n)
    nearest = np.empty((n, 2))
    for i in numba.prange(n):
        distance2, x, y = _nearest_candidate(points, starts, ends, candidates, i)
        best[i] = np.sqrt(distance2)
        nearest[i, 0] = x
        nearest[i, 1] = y
    return best, nearest


@numba.njit(cache=True, inline="always")
def _turn(ax, ay, bx, by, cx, cy):
    """Sign of the turn ``a, b, c`` (1 counter-clockwise, -1 clockwise), 0 where rounding could hide it.

    Shewchuk's first-stage bound: a sign it passes is exact.
    """
    left = (ax - cx) * (by - cy)
    right = (ay - cy) * (bx - cx)
    det = left - right
    if abs(det) <= ORIENT_BOUND * (abs(left) + abs(right)):
        return 0
    return 1 if det > 0.0 else -1


@numba.njit(cache=True, inline="always")
def _crosses(ax, ay, bx, by, cx, cy, px, py):
    """1 where segment ``c p`` crosses segment ``a b``, 0 where not, -1 where a turn is too close to call."""
    centre_turn = _turn(ax, ay, bx, by, cx, cy)
    point_turn = _turn(ax, ay, bx, by, px, py)
    if centre_turn != 0 and centre_turn == point_turn:
        return 0  # c and p on one side of the line a b
    start_turn = _turn(cx, cy, px, py, ax, ay)
    end_turn = _turn(cx, cy, px, py, bx, by)
    if start_turn != 0 and start_turn == end_turn:
        return 0  # a and b on one side of the line c p
    if centre_turn == 0 or point_turn == 0 or start_turn == 0 or end_turn == 0:
        return -1
    return 1


@numba.njit(cache=True, parallel=True)
def crossing_sides(
    points,
    starts,
    ends,
    chained_ends,
    origin,
    cell,
    nx,
    ny,
    cell_start,
    cell_items,
    centre_x,
    centre_y,
    centre_in,
    tolerance,
):
    """Side of closed rings by the parity of crossings from the centre of each point's bucket cell.

    The pieces ``starts``-``chained_ends`` chain exactly (each ends where
    the next begins: no gap for a crossing to slip through), the cells
    list every piece that meets them (as in :func:`grid_nearest`), and
    ``centre_in`` says which cell centres ``(centre_x[i], centre_y[j])``
    are inside. The segment from a point's cell centre to the point stays
    in the cell, so only that cell's pieces can cross it, each crossing
    flipping the centre's side. With ``tolerance >= 0`` a point inside and
    within ``tolerance`` of a piece ``starts``-``ends`` (the distance
    pieces of :func:`grid_nearest`) counts as outside. Returns int8 (n,):
    1 inside, -1 outside (beyond the grid too), 0 where a turn is too
    close to call (a point on a piece, or in line with one and the
    centre): the caller decides those another way.
    """
    n = points.shape[0]
    side = np.zeros(n, dtype=np.int8)
    for p in numba.prange(n):
        px = points[p, 0]
        py = points[p, 1]
        ci = int(np.floor((px - origin[0]) / cell))
        cj = int(np.floor((py - origin[1]) / cell))
        if ci < 0 or ci >= nx or cj < 0 or cj >= ny:
            side[p] = -1
            continue
        c = ci * ny + cj
        inside = centre_in[c]
        decided = True
        for k in range(cell_start[c], cell_start[c + 1]):
            s = cell_items[k]
            crossing = _crosses(
                starts[s, 0], starts[s, 1], chained_ends[s, 0], chained_ends[s, 1], centre_x[ci], centre_y[cj], px, py
            )
            if crossing < 0:
                decided = False
                break
            if crossing:
                inside = not inside
        if not decided:
            continue
        side[p] = 1 if inside else -1
        if not inside or tolerance < 0.0:
            continue
        i_low = max(int(np.floor((px - tolerance - origin[0]) / cell)), 0)
        i_high = min(int(np.floor((px + tolerance - origin[0]) / cell)), nx - 1)
        j_low = max(int(np.floor((py - tolerance - origin[1]) / cell)), 0)
        j_high = min(int(np.floor((py + tolerance - origin[1]) / cell)), ny - 1)
        for i in range(i_low, i_high + 1):
            for j in range(j_low, j_high + 1):
                near = i * ny + j
                for k in range(cell_start[near], cell_start[near + 1]):
                    distance2, _, _, _ = _on_segment(px, py, starts, ends, cell_items[k])
                    if np.sqrt(distance2) <= tolerance:
                        side[p] = -1
    return side


_CELLS_PER_EDGE = 16  # a meeting test's bucket grid has at most about this many cells per edge...
_CELL_VISITS = 16  # ...and grows them while the edges' visits to cells exceed this many per edge
_MOST_TESTS_PER_EDGE = 1024  # the sum over cells of their edges squared, per edge, beyond which the grid does not serve


@numba.njit(cache=True)
def _exact_turn(points, a, b, c, work):
    """The sign of the turn ``a, b, c``, exactly: 1 counter-clockwise, -1 clockwise, 0 collinear."""
    value = orient(points, a, b, c, work)
    return 1 if value > 0.0 else (-1 if value < 0.0 else 0)


@numba.njit(cache=True, inline="always")
def _in_box(points, a, b, c):
    """Whether point ``c`` lies in the closed bounding box of points ``a`` and ``b``."""
    return min(points[a, 0], points[b, 0]) <= points[c, 0] <= max(points[a, 0], points[b, 0]) and min(
        points[a, 1], points[b, 1]
    ) <= points[c, 1] <= max(points[a, 1], points[b, 1])


@numba.njit(cache=True)
def _segments_meet(points, a, b, c, d, work):
    """Whether the closed segments ``a b`` and ``c d`` have a point in common, decided exactly.

    They cross where each one's ends lie strictly on the two sides of the
    other's line; else they meet where an end lies on the other segment:
    on its line (an exact zero turn) and in its bounding box. Segments of
    zero length are points, on a segment or not.
    """
    turn_c = _exact_turn(points, a, b, c, work)
    turn_d = _exact_turn(points, a, b, d, work)
    turn_a = _exact_turn(points, c, d, a, work)
    turn_b = _exact_turn(points, c, d, b, work)
    if turn_c * turn_d < 0 and turn_a * turn_b < 0:
        return True
    return (
        (turn_c == 0 and _in_box(points, a, b, c))
        or (turn_d == 0 and _in_box(points, a, b, d))
        or (turn_a == 0 and _in_box(points, c, d, a))
        or (turn_b == 0 and _in_box(points, c, d, b))
    )


@numba.njit(cache=True, inline="always")
def _length(dx, dy):
    return np.sqrt(dx * dx + dy * dy)


@numba.njit(cache=True, inline="always")
def _cell_span(points, edges, e, x0, y0, cell, nx, ny, margin):
    """The bucket grid cells ``i0..i1, j0..j1`` that edge ``e``'s bounding box, grown by ``margin``, meets."""
    ax, ay = points[edges[e, 0], 0], points[edges[e, 0], 1]
    bx, by = points[edges[e, 1], 0], points[edges[e, 1], 1]
    i0 = min(max(int((min(ax, bx) - margin - x0) / cell), 0), nx - 1)
    i1 = min(max(int((max(ax, bx) + margin - x0) / cell), 0), nx - 1)
    j0 = min(max(int((min(ay, by) - margin - y0) / cell), 0), ny - 1)
    j1 = min(max(int((max(ay, by) + margin - y0) / cell), 0), ny - 1)
    return i0, i1, j0, j1


@numba.njit(cache=True, inline="always")
def _pair_appended(first, second, found, one, other):
    """``first`` and ``second`` with ``one`` and ``other`` at row ``found`` (grown when full), and ``found + 1``."""
    if found == first.shape[0]:
        first = grown(first, 2 * found, 0)
        second = grown(second, 2 * found, 0)
    first[found] = one
    second[found] = other
    return first, second, found + 1


@numba.njit(cache=True)
def _edge_buckets(points, edges):
    """A bucket grid of ``edges``: ``(x0, y0, cell, nx, ny, start, items, serves)``.

    ``items[start[c]:start[c + 1]]`` are the edges whose bounding boxes meet
    cell ``c = i * ny + j`` (side ``cell``, lower-left corner ``x0, y0``).
    The cells are about the mean edge length, at most about
    ``_CELLS_PER_EDGE`` per edge, and grow where long edges would visit more
    than ``_CELL_VISITS`` each. ``serves`` is False where the grid would
    not serve: coordinates not finite or beyond the floats' range, or
    edges crowding a few cells (tiny edges in one cell beside edges
    thousands of times longer), whose pairs would take more than
    ``_MOST_TESTS_PER_EDGE`` tests per edge.
    """
    n_edges = edges.shape[0]
    x0 = np.inf
    y0 = np.inf
    x1 = -np.inf
    y1 = -np.inf
    total_length = 0.0
    for e in range(n_edges):
        for k in range(2):
            v = edges[e, k]
            x0 = min(x0, points[v, 0])
            x1 = max(x1, points[v, 0])
            y0 = min(y0, points[v, 1])
            y1 = max(y1, points[v, 1])
        total_length += _length(
            points[edges[e, 1], 0] - points[edges[e, 0], 0], points[edges[e, 1], 1] - points[edges[e, 0], 1]
        )
    no_items = np.zeros(0, dtype=np.int64)
    extent = max(x1 - x0, y1 - y0)
    if not (extent < np.inf and total_length < np.inf):  # beyond the floats (1e308 apart) or not finite
        return x0, y0, 1.0, 1, 1, no_items, no_items, False
    # cells about an edge long, but no more than about _CELLS_PER_EDGE per edge in all and along either axis:
    # a coastline fills few of its box's cells, and the empty ones cost a pass each
    area = max(x1 - x0, 1e-300) * max(y1 - y0, 1e-300)
    most = _CELLS_PER_EDGE * n_edges
    cell = max(total_length / n_edges, np.sqrt(area / most), extent / most, 1e-300)
    while True:
        nx = int((x1 - x0) / cell) + 1
        ny = int((y1 - y0) / cell) + 1
        visits = 0
        for e in range(n_edges):
            i0, i1, j0, j1 = _cell_span(points, edges, e, x0, y0, cell, nx, ny, 0.0)
            visits += (i1 - i0 + 1) * (j1 - j0 + 1)
        if visits <= _CELL_VISITS * n_edges or cell >= extent:
            break
        cell *= 2.0
    start = np.zeros(nx * ny + 1, dtype=np.int64)
    for e in range(n_edges):
        i0, i1, j0, j1 = _cell_span(points, edges, e, x0, y0, cell, nx, ny, 0.0)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                start[i * ny + j + 1] += 1
    load = 0
    for c in range(nx * ny):
        load += start[c + 1] * start[c + 1]
        start[c + 1] += start[c]
    if load > _MOST_TESTS_PER_EDGE * n_edges:
        return x0, y0, cell, nx, ny, no_items, no_items, False
    fill = start[:-1].copy()
    items = np.empty(start[nx * ny], dtype=np.int64)
    for e in range(n_edges):
        i0, i1, j0, j1 = _cell_span(points, edges, e, x0, y0, cell, nx, ny, 0.0)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                items[fill[i * ny + j]] = e
                fill[i * ny + j] += 1
    return x0, y0, cell, nx, ny, start, items, True


@numba.njit(cache=True)
def meeting_edges(points, edges, queries, each_pair_once):
    """The pairs of segments ``edges`` (vertex index pairs into ``points``) that meet, sharing no vertex.

    For each of ``queries`` in turn, the edges whose closed segments have a
    point in common with it (a crossing, an end on the other segment, or
    collinear overlap, decided with exact turns) and no vertex number in
    common; with ``each_pair_once`` only those of larger index. The edges
    are bucketed on a grid (:func:`_edge_buckets`), so a query tests the
    few edges near it. Returns ``(first, second, done)``: int64 arrays of
    the query's edge and the other, in the order found (by query, then by
    cell), and False (with no pairs) where the grid would not serve.
    """
    n_edges = edges.shape[0]
    first = np.empty(16, dtype=np.int64)
    second = np.empty(16, dtype=np.int64)
    if n_edges == 0 or queries.shape[0] == 0:
        return first[:0], second[:0], True
    x0, y0, cell, nx, ny, start, items, serves = _edge_buckets(points, edges)
    if not serves:
        return first[:0], second[:0], False
    seen = np.full(n_edges, -1, dtype=np.int64)  # the last query that tested each edge
    work = np.empty(WORK_SIZE)
    found = 0
    for q in range(queries.shape[0]):
        e = queries[q]
        a, b = edges[e, 0], edges[e, 1]
        i0, i1, j0, j1 = _cell_span(points, edges, e, x0, y0, cell, nx, ny, 0.0)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(start[i * ny + j], start[i * ny + j + 1]):
                    other = items[k]
                    if seen[other] == q:
                        continue
                    seen[other] = q
                    if other == e or (each_pair_once and other < e):
                        continue
                    c, d = edges[other, 0], edges[other, 1]
                    if a == c or a == d or b == c or b == d:
                        continue
                    if _segments_meet(points, a, b, c, d, work):
                        first, second, found = _pair_appended(first, second, found, e, other)
    return first[:found], second[:found], True


@numba.njit(cache=True)
def vertices_on_edges(points, edges, share):
    """The pairs ``(edge, vertex)`` of ``edges`` and an end of another edge lying on it, to ``share`` of its length.

    An end ``v`` of any edge, other than the edge's own ends ``a``, ``b``,
    lies on it where, with ``t = (v - a) . (b - a) / |b - a|**2`` and
    ``s = |(b - a) x (v - a)| / |b - a|**2``, ``share < t < 1 - share``
    and ``s <= share`` (scale-free: a hanging node of a mesh at any
    coordinates). Each pair once, by edge, on the bucket grid of
    :func:`_edge_buckets`; ``(edge, vertex, done)`` with ``done`` False
    (no pairs) where the grid would not serve.
    """
    n_edges = edges.shape[0]
    found_edge = np.empty(16, dtype=np.int64)
    found_vertex = np.empty(16, dtype=np.int64)
    if n_edges == 0:
        return found_edge[:0], found_vertex[:0], True
    x0, y0, cell, nx, ny, start, items, serves = _edge_buckets(points, edges)
    if not serves:
        return found_edge[:0], found_vertex[:0], False
    seen = np.full(points.shape[0], -1, dtype=np.int64)  # the last edge that tested each vertex
    tiny = np.finfo(np.float64).tiny
    found = 0
    for e in range(n_edges):
        a, b = edges[e, 0], edges[e, 1]
        ax, ay = points[a, 0], points[a, 1]
        dx, dy = points[b, 0] - ax, points[b, 1] - ay
        squared = max(dx * dx + dy * dy, tiny)
        # a vertex within share of the length beside the edge may sit in a cell just past its bounding box
        i0, i1, j0, j1 = _cell_span(points, edges, e, x0, y0, cell, nx, ny, 2.0 * share * np.sqrt(squared))
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(start[i * ny + j], start[i * ny + j + 1]):
                    other = items[k]
                    for end in range(2):
                        v = edges[other, end]
                        if v == a or v == b or seen[v] == e:
                            continue
                        seen[v] = e
                        ox, oy = points[v, 0] - ax, points[v, 1] - ay
                        position = (ox * dx + oy * dy) / squared
                        side = abs(dx * oy - dy * ox) / squared
                        if share < position < 1.0 - share and side <= share:
                            found_edge, found_vertex, found = _pair_appended(found_edge, found_vertex, found, e, v)
    return found_edge[:found], found_vertex[:found], True
