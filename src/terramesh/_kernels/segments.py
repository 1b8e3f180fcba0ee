"""Point-to-segment distances over candidate lists."""

import numba
import numpy as np


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
    ``origin``). A segment in the ``r``-th ring of cells around a point's
    cell is at least ``(r - 1) * cell`` away, so the search stops once the
    best distance found is within that. Returns ``(distance (n,), nearest
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
        best = np.inf
        bx = px
        by = py
        bs = -1
        bt = 0.0
        for r in range(max_ring + 2):
            if best <= ((r - 1) * cell) ** 2:
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
