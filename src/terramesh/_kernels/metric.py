"""Kernels of the anisotropic generator: lengths, forces, quality and flips measured in a metric.

``metric`` is always one symmetric 2 x 2 matrix per point, shape (n, 2, 2);
an edge or a cell is measured with the mean of its corners' matrices.
"""

import numba
import numpy as np

from .delaunay import flip_edge
from .raster import cell_and_fraction

SQRT3_4 = 4.0 * np.sqrt(3.0)


@numba.njit(cache=True, inline="always")
def _dot(metric, a, b, ux, uy, vx, vy):
    """``u^T M v`` with ``M`` the mean of the matrices of points ``a`` and ``b``."""
    m00 = 0.5 * (metric[a, 0, 0] + metric[b, 0, 0])
    m01 = 0.5 * (metric[a, 0, 1] + metric[b, 0, 1])
    m11 = 0.5 * (metric[a, 1, 1] + metric[b, 1, 1])
    return ux * (m00 * vx + m01 * vy) + uy * (m01 * vx + m11 * vy)


@numba.njit(cache=True, parallel=True)
def grid_metric(entries, origin, spacing, points):
    """The metric at ``points`` (n, 2), shape (n, 2, 2), from ``entries`` (nx, ny, 3): each node's m00, m01, m11.

    Bilinear in every entry, clamped to the grid, with one cell search a
    point for the three (three interpolations of one entry each searched
    three times and took 0.19 s of BP2004's 2.6 s anisotropic mesh).
    """
    nx, ny = entries.shape[0], entries.shape[1]
    out = np.empty((points.shape[0], 2, 2))
    for k in numba.prange(points.shape[0]):
        i, fx = cell_and_fraction(points[k, 0], origin[0], spacing[0], nx)
        j, fy = cell_and_fraction(points[k, 1], origin[1], spacing[1], ny)
        w00, w01, w10, w11 = (1.0 - fx) * (1.0 - fy), (1.0 - fx) * fy, fx * (1.0 - fy), fx * fy
        for entry in range(3):
            value = (
                w00 * entries[i, j, entry]
                + w01 * entries[i, j + 1, entry]
                + w10 * entries[i + 1, j, entry]
                + w11 * entries[i + 1, j + 1, entry]
            )
            if entry == 0:
                out[k, 0, 0] = value
            elif entry == 1:
                out[k, 0, 1] = value
                out[k, 1, 0] = value
            else:
                out[k, 1, 1] = value
    return out


@numba.njit(cache=True)
def edge_lengths(points, edges, metric):
    """Length of each edge in the mean metric of its ends, shape (e,)."""
    lengths = np.empty(edges.shape[0])
    for e in range(edges.shape[0]):
        a, b = edges[e, 0], edges[e, 1]
        dx = points[b, 0] - points[a, 0]
        dy = points[b, 1] - points[a, 1]
        lengths[e] = np.sqrt(_dot(metric, a, b, dx, dy, dx, dy))
    return lengths


@numba.njit(cache=True)
def force_moves(points, edges, metric, rest, time_step, n_fixed):
    """Each point's move: ``time_step`` times its net spring force, every rest length ``rest``.

    A spring of metric length ``L`` pushes its ends apart (``L < rest``) or
    pulls them together (``L > rest``) along the edge by ``(rest - L) / L``
    of its length: the metric and the plane agree on that fraction, so the
    move is the one DistMesh makes in the metric's own (locally flat)
    space. The first ``n_fixed`` points stay.
    Returns the moves (n, 2) and their lengths in each point's metric (n,).
    """
    n = points.shape[0]
    moves = np.zeros((n, 2))
    for e in range(edges.shape[0]):
        a, b = edges[e, 0], edges[e, 1]
        dx = points[b, 0] - points[a, 0]
        dy = points[b, 1] - points[a, 1]
        length = np.sqrt(_dot(metric, a, b, dx, dy, dx, dy))
        if 0.0 < length:
            push = time_step * (rest - length) / length
            moves[a, 0] -= push * dx
            moves[a, 1] -= push * dy
            moves[b, 0] += push * dx
            moves[b, 1] += push * dy
    moves[:n_fixed] = 0.0
    travelled = np.empty(n)
    for i in range(n):
        x, y = moves[i, 0], moves[i, 1]
        travelled[i] = np.sqrt(_dot(metric, i, i, x, y, x, y))
    return moves, travelled


@numba.njit(cache=True)
def cell_qualities(points, cells, metric):
    """``4 sqrt(3) area / sum of squared edge lengths``, all in the cell's mean metric (1: equilateral there)."""
    quality = np.empty(cells.shape[0])
    for t in range(cells.shape[0]):
        a, b, c = cells[t, 0], cells[t, 1], cells[t, 2]
        m00 = (metric[a, 0, 0] + metric[b, 0, 0] + metric[c, 0, 0]) / 3.0
        m01 = (metric[a, 0, 1] + metric[b, 0, 1] + metric[c, 0, 1]) / 3.0
        m11 = (metric[a, 1, 1] + metric[b, 1, 1] + metric[c, 1, 1]) / 3.0
        ux, uy = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1]
        vx, vy = points[c, 0] - points[a, 0], points[c, 1] - points[a, 1]
        wx, wy = vx - ux, vy - uy
        squares = 0.0
        for ex, ey in ((ux, uy), (vx, vy), (wx, wy)):
            squares += m00 * ex * ex + 2.0 * m01 * ex * ey + m11 * ey * ey
        area = 0.5 * (ux * vy - uy * vx) * np.sqrt(max(m00 * m11 - m01 * m01, 0.0))
        quality[t] = SQRT3_4 * area / squares if squares > 0.0 else 0.0
    return quality


@numba.njit(cache=True, inline="always")
def _wants_flip(points, metric, p, u, v, z, slack):
    """Whether the edge ``(u, v)`` of the cells ``(p, u, v)`` and ``(z, v, u)`` fails the metric Delaunay test.

    The angles at ``p`` and ``z`` facing the edge must sum to at most pi in
    the metric ``M`` (the mean of the four corners' matrices):
    ``sin(alpha + beta) >= 0``, i.e. ``(a x b)(c^T M d) + (a^T M b)(c x d)
    >= 0`` (the seismic talk's test; both cross products carry the same
    factor ``sqrt(det M)``). It flips below ``-slack``, so that
    near-cocircular quads do not flip back and forth as the means change.
    """
    m00 = 0.25 * (metric[p, 0, 0] + metric[u, 0, 0] + metric[v, 0, 0] + metric[z, 0, 0])
    m01 = 0.25 * (metric[p, 0, 1] + metric[u, 0, 1] + metric[v, 0, 1] + metric[z, 0, 1])
    m11 = 0.25 * (metric[p, 1, 1] + metric[u, 1, 1] + metric[v, 1, 1] + metric[z, 1, 1])
    ax, ay = points[u, 0] - points[p, 0], points[u, 1] - points[p, 1]
    bx, by = points[v, 0] - points[p, 0], points[v, 1] - points[p, 1]
    cx, cy = points[v, 0] - points[z, 0], points[v, 1] - points[z, 1]
    dx, dy = points[u, 0] - points[z, 0], points[u, 1] - points[z, 1]
    ab = ax * (m00 * bx + m01 * by) + ay * (m01 * bx + m11 * by)
    cd = cx * (m00 * dx + m01 * dy) + cy * (m01 * dx + m11 * dy)
    sine = ((ax * by - ay * bx) * cd + ab * (cx * dy - cy * dx)) * np.sqrt(max(m00 * m11 - m01 * m01, 0.0))
    if sine >= 0.0:  # most edges: no square root of the lengths needed
        return False
    aa = ax * (m00 * ax + m01 * ay) + ay * (m01 * ax + m11 * ay)
    bb = bx * (m00 * bx + m01 * by) + by * (m01 * bx + m11 * by)
    cc = cx * (m00 * cx + m01 * cy) + cy * (m01 * cx + m11 * cy)
    dd = dx * (m00 * dx + m01 * dy) + dy * (m01 * dx + m11 * dy)
    return sine < -slack * np.sqrt(aa * bb * cc * dd)


@numba.njit(cache=True)
def metric_delaunay_flips(points, cells, neighbors, metric, max_passes, slack):
    """Lawson flips until every inner edge passes the metric Delaunay test; in place.

    Only strictly convex quads flip, so every cell stays counter-clockwise;
    boundary edges (neighbour -1) never flip. After the first pass only
    the cells a flip changed are looked at again (their edges are all the
    flip can have spoilt); an edge between two cells still to be looked at
    in a pass is tested once, from the later cell. Stops after ``max_passes`` passes (a metric that
    varies from cell to cell can make a few quads flip back and forth).
    Returns the number of flips.
    """
    m = cells.shape[0]
    dirty = np.ones(m, dtype=np.bool_)
    total = 0
    for _ in range(max_passes):
        flips = 0
        next_dirty = np.zeros(m, dtype=np.bool_)
        for t in range(m):
            if not dirty[t]:
                continue
            for k in range(3):
                t2 = neighbors[t, k]
                if t2 < 0 or (t2 > t and dirty[t2]):  # t2 tests it later in this pass (half the first pass's tests)
                    continue
                p, u, v = cells[t, k], cells[t, (k + 1) % 3], cells[t, (k + 2) % 3]
                j = 0
                while neighbors[t2, j] != t:
                    j += 1
                z = cells[t2, j]
                if not _wants_flip(points, metric, p, u, v, z, slack):
                    continue
                if _orient(points, p, u, z) <= 0.0 or _orient(points, p, z, v) <= 0.0:
                    continue
                flip_edge(cells, neighbors, t, k)
                next_dirty[t] = True
                next_dirty[t2] = True
                flips += 1
                break
        total += flips
        if flips == 0:
            break
        dirty = next_dirty
    return total


@numba.njit(cache=True, inline="always")
def _orient(points, a, b, c):
    return (points[b, 0] - points[a, 0]) * (points[c, 1] - points[a, 1]) - (points[b, 1] - points[a, 1]) * (
        points[c, 0] - points[a, 0]
    )


@numba.njit(cache=True)
def inverted_cell_mask(points, cells):
    """Whether each cell is not strictly counter-clockwise, shape (m,)."""
    inverted = np.empty(cells.shape[0], dtype=np.bool_)
    for t in range(cells.shape[0]):
        inverted[t] = _orient(points, cells[t, 0], cells[t, 1], cells[t, 2]) <= 0.0
    return inverted


@numba.njit(cache=True)
def thinned_ends(edges, n_points, n_fixed):
    """Which points go so that no edge of ``edges`` keeps both ends: the later end of each, in turn, shape (n_points,).

    An edge one of whose ends already goes is left alone (removing one
    point of a crowded pair suffices); a fixed point (below ``n_fixed``)
    never goes.
    """
    doomed = np.zeros(n_points, dtype=np.bool_)
    for e in range(edges.shape[0]):
        a, b = edges[e, 0], edges[e, 1]
        if doomed[a] or doomed[b]:
            continue
        later = max(a, b)
        if later >= n_fixed:
            doomed[later] = True
    return doomed


@numba.njit(cache=True)
def crossed_boundary_edges(cells, neighbors, inverted, n_points, n_fixed):
    """The inverted cells whose one boundary edge an interior point has crossed, and those points.

    A cell qualifies when it has exactly one boundary edge (neighbour -1)
    and the corner facing it is an interior vertex past ``n_fixed``; one
    cell per point, so that dropping the cells leaves a manifold boundary.
    Returns the mask over the cells and the points' indices.
    """
    on_boundary = np.zeros(n_points, dtype=np.bool_)
    for t in range(cells.shape[0]):
        for k in range(3):
            if neighbors[t, k] < 0:
                on_boundary[cells[t, (k + 1) % 3]] = True
                on_boundary[cells[t, (k + 2) % 3]] = True
    crossing = np.zeros(cells.shape[0], dtype=np.bool_)
    joining = np.empty(cells.shape[0], dtype=np.int64)
    count = 0
    for t in range(cells.shape[0]):
        if not inverted[t]:
            continue
        edge = -1
        for k in range(3):
            if neighbors[t, k] < 0:
                edge = k if edge == -1 else 3
        if edge < 0 or edge == 3:
            continue
        p = cells[t, edge]
        if p < n_fixed or on_boundary[p]:
            continue
        on_boundary[p] = True  # one cell a point
        crossing[t] = True
        joining[count] = p
        count += 1
    return crossing, joining[:count]
