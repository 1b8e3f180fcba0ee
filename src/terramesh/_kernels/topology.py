"""Connectivity kernels on triangulations stored with a neighbour table.

``cells`` (m, 3) int64 counter-clockwise; ``neighbors`` (m, 3) int64,
``neighbors[c, k]`` the cell across the edge opposite corner ``k`` (the edge
``cells[c, k+1], cells[c, k+2]``), -1 on the boundary.
"""

import numba
import numpy as np


@numba.njit(cache=True)
def cell_edges(cells, neighbors):
    """Every edge once as (e, 2) vertex pairs, and a flag marking boundary edges.

    An edge is emitted by the cell with the larger index of the two that
    share it (or its only cell), so no sorting is needed.
    """
    m = cells.shape[0]
    count = 0
    for c in range(m):
        for k in range(3):
            if neighbors[c, k] < c:
                count += 1
    edges = np.empty((count, 2), dtype=np.int64)
    boundary = np.empty(count, dtype=np.bool_)
    i = 0
    for c in range(m):
        for k in range(3):
            n = neighbors[c, k]
            if n < c:
                edges[i, 0] = cells[c, (k + 1) % 3]
                edges[i, 1] = cells[c, (k + 2) % 3]
                boundary[i] = n < 0
                i += 1
    return edges, boundary


@numba.njit(cache=True)
def quality_mean_std(points, cells):
    """Mean and standard deviation of the triangle quality 4 sqrt(3) A / sum(l^2), in one pass."""
    m = cells.shape[0]
    total = 0.0
    total2 = 0.0
    factor = 4.0 * np.sqrt(3.0)
    for c in range(m):
        a = cells[c, 0]
        b = cells[c, 1]
        d = cells[c, 2]
        abx = points[b, 0] - points[a, 0]
        aby = points[b, 1] - points[a, 1]
        adx = points[d, 0] - points[a, 0]
        ady = points[d, 1] - points[a, 1]
        bdx = points[d, 0] - points[b, 0]
        bdy = points[d, 1] - points[b, 1]
        squares = abx * abx + aby * aby + adx * adx + ady * ady + bdx * bdx + bdy * bdy
        q = 0.0
        if squares > 0.0:
            q = factor * 0.5 * (abx * ady - aby * adx) / squares
        total += q
        total2 += q * q
    mean = total / max(m, 1)
    return mean, np.sqrt(max(total2 / max(m, 1) - mean * mean, 0.0))


@numba.njit(cache=True)
def cells_surely_inside(points, cells, distance_bound, tolerance):
    """Cells whose centroid is certainly deeper inside than ``tolerance``, from bounds at their vertices.

    ``distance_bound`` (n,) bounds a 1-Lipschitz signed distance from above
    at each point; the centroid lies within the longest edge of every
    vertex, so ``max bound + longest edge < -tolerance`` proves it inside.
    Returns a boolean (m,) mask; False means "evaluate it".
    """
    m = cells.shape[0]
    dim = points.shape[1]
    sure = np.zeros(m, dtype=np.bool_)
    for c in range(m):
        bound = -np.inf
        longest2 = 0.0
        for k in range(3):
            a = cells[c, k]
            b = cells[c, (k + 1) % 3]
            if distance_bound[a] > bound:
                bound = distance_bound[a]
            length2 = 0.0
            for d in range(dim):
                delta = points[a, d] - points[b, d]
                length2 += delta * delta
            if length2 > longest2:
                longest2 = length2
        sure[c] = bound + np.sqrt(longest2) < -tolerance
    return sure


@numba.njit(cache=True)
def cell_centroids(points, cells, which):
    """Centroids of the cells ``which`` (k,) int64, shape (k, dim)."""
    dim = points.shape[1]
    corners = cells.shape[1]
    out = np.empty((which.shape[0], dim))
    for i in range(which.shape[0]):
        c = which[i]
        for d in range(dim):
            total = 0.0
            for k in range(corners):
                total += points[cells[c, k], d]
            out[i, d] = total / corners
    return out
