"""Point-to-segment distances over candidate lists."""

import numba
import numpy as np

from .delaunay import _ORIENT_BOUND


@numba.njit(cache=True, inline="always")
def _on_segment(px, py, starts, ends, s):
    """Squared distance from ``(px, py)`` to segment ``s`` and the segment's nearest point."""
    ax = starts[s, 0]
    ay = starts[s, 1]
    dx = ends[s, 0] - ax
    dy = ends[s, 1] - ay
    length2 = dx * dx + dy * dy
    t = 0.0
    if length2 > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / length2
        t = min(max(t, 0.0), 1.0)
    x = ax + t * dx
    y = ay + t * dy
    return (x - px) * (x - px) + (y - py) * (y - py), x, y, t


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


@numba.njit(cache=True)
def nearest_sides(points, nearest, settled, segment, parameter, normal, before, after):
    """Side (1 left, -1 right, 0 on it or not settled) of each point from its nearest point on closed rings.

    ``segment`` and ``parameter`` as :func:`grid_nearest` returns them,
    ``normal`` each segment's left unit normal, ``before``/``after`` the
    segments meeting it at its start and end. Nearest to a vertex
    (parameter 0 or 1), the side is that of the two normals' sum there.
    """
    n = points.shape[0]
    side = np.zeros(n, dtype=np.int8)
    for p in range(n):
        if not settled[p]:
            continue
        piece = segment[p]
        t = parameter[p]
        dx = normal[piece, 0]
        dy = normal[piece, 1]
        if t <= 0.0:
            dx += normal[before[piece], 0]
            dy += normal[before[piece], 1]
        if t >= 1.0:
            dx += normal[after[piece], 0]
            dy += normal[after[piece], 1]
        dot = (points[p, 0] - nearest[p, 0]) * dx + (points[p, 1] - nearest[p, 1]) * dy
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
    if abs(det) <= _ORIENT_BOUND * (abs(left) + abs(right)):
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
