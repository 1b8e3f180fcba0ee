"""Quality-safe Laplacian smoothing of a tetrahedral mesh, in place.

Private: ``points`` (n, 3) float64, ``cells`` (m, 4) int64 positively
oriented, ``movable`` (n,) bool; unvalidated.
"""

import numba
import numpy as np

from .smoothing import star_measures
from .tetra import edges_and_normals, largest_cosine_from_normals
from .topology import vertex_cells

_MEAN_RATIO_FACTOR = np.sqrt(2.0)  # 6 sqrt(2) V / l_rms**3 with 6 V the orientation determinant


@numba.njit(cache=True, inline="always")
def _neighbour_mean_3d(points, cells, star, v):
    """The mean over the tetrahedra ``star`` of ``v`` of their other corners, ``x, y, z``.

    Each neighbour weighs as many times as it shares cells with ``v``;
    summed in the cells' order, corner by corner. Three running sums where
    a loop over the axes (of any dimension) took twice as long.
    """
    sx = 0.0
    sy = 0.0
    sz = 0.0
    for s in range(star.shape[0]):
        for k in range(4):
            u = cells[star[s], k]
            if u != v:
                sx += points[u, 0]
                sy += points[u, 1]
                sz += points[u, 2]
    count = 3.0 * star.shape[0]
    return sx / count, sy / count, sz / count


@numba.njit(cache=True, inline="always")
def _ratio_and_cosine(points, a, b, c, d):
    """The mean ratio ``6 sqrt(2) V / l_rms**3`` and the largest dihedral cosine of the tetrahedron ``a, b, c, d``.

    The mean ratio is 1 for a regular tetrahedron, <= 0 for a flat or
    inverted one; the cosine is
    :func:`~terramesh._kernels.tetra.tet_largest_cosine`'s, from the
    same edges and normals.
    """
    bx, by, bz, cx, cy, cz, dx, dy, dz, n1x, n1y, n1z, n2x, n2y, n2z, n3x, n3y, n3z = edges_and_normals(
        points, a, b, c, d
    )
    six_volume = bx * n1x + by * n1y + bz * n1z
    squares = bx * bx + by * by + bz * bz + cx * cx + cy * cy + cz * cz + dx * dx + dy * dy + dz * dz
    squares += (cx - bx) ** 2 + (cy - by) ** 2 + (cz - bz) ** 2 + (dx - bx) ** 2 + (dy - by) ** 2 + (dz - bz) ** 2
    squares += (dx - cx) ** 2 + (dy - cy) ** 2 + (dz - cz) ** 2
    if squares == 0.0:
        ratio = 0.0
    else:
        rms = np.sqrt(squares / 6.0)
        ratio = _MEAN_RATIO_FACTOR * six_volume / (rms * rms * rms)
    return ratio, largest_cosine_from_normals(dx, dy, dz, n1x, n1y, n1z, n2x, n2y, n2z, n3x, n3y, n3z)


@numba.njit(cache=True)
def smooth_interior_3d(points, cells, movable, passes):
    """Move each ``movable`` vertex to the mean of its neighbours where its star's worst cell gets no worse.

    Worst by both measures: the smallest mean ratio of the cells at the
    vertex must not fall, nor their smallest dihedral angle (so the mesh's
    smallest angle, the sliver bound, is kept). Gauss-Seidel order, vertex
    by vertex in index order, so the result depends only on the input; no
    cell inverts. Each neighbour weighs as many times as it shares cells
    with the vertex. Each cell's two measures are kept and
    renewed when a vertex of it moves, so a star's present worst is read,
    not computed again, and a trial stops at its first cell below it.
    Returns the number of moves made.
    """
    start, index = vertex_cells(cells, points.shape[0])
    ratio = np.empty(cells.shape[0])
    cosine = np.empty(cells.shape[0])
    for c in range(cells.shape[0]):
        a, b, d, e = cells[c, 0], cells[c, 1], cells[c, 2], cells[c, 3]
        ratio[c], cosine[c] = _ratio_and_cosine(points, a, b, d, e)
    largest_star = 0
    for v in range(points.shape[0]):
        largest_star = max(largest_star, start[v + 1] - start[v])
    trial_ratio = np.empty(largest_star)
    trial_cosine = np.empty(largest_star)
    moves = 0
    for _ in range(passes):
        for v in range(points.shape[0]):
            if not movable[v] or start[v + 1] == start[v]:
                continue
            star = index[start[v] : start[v + 1]]
            x, y, z = _neighbour_mean_3d(points, cells, star, v)
            x0, y0, z0 = points[v, 0], points[v, 1], points[v, 2]
            points[v, 0], points[v, 1], points[v, 2] = x, y, z
            worst_ratio = np.inf
            worst_cosine = -np.inf
            for s in range(star.shape[0]):
                worst_ratio = min(worst_ratio, ratio[star[s]])
                worst_cosine = max(worst_cosine, cosine[star[s]])
            # two moves in three are refused: the first cell worse than the star's worst refuses it
            kept = True
            for s in range(star.shape[0]):
                c = star[s]
                a, b, d, e = cells[c, 0], cells[c, 1], cells[c, 2], cells[c, 3]
                trial_ratio[s], trial_cosine[s] = _ratio_and_cosine(points, a, b, d, e)
                if trial_ratio[s] < worst_ratio or trial_cosine[s] > worst_cosine:
                    kept = False
                    break
            if kept:
                for s in range(star.shape[0]):
                    ratio[star[s]] = trial_ratio[s]
                    cosine[star[s]] = trial_cosine[s]
                moves += 1
            else:
                points[v, 0], points[v, 1], points[v, 2] = x0, y0, z0
    return moves


@numba.njit(cache=True)
def _shortest_edge_ratio(points, cells, star, v, sizes):
    """The smallest ``length / size`` of the edges at ``v`` in its cells ``star``, ``size`` the mean of its ends'."""
    shortest = np.inf
    for s in range(star.shape[0]):
        for k in range(4):
            u = cells[star[s], k]
            if u != v:
                length = np.sqrt(
                    (points[u, 0] - points[v, 0]) ** 2
                    + (points[u, 1] - points[v, 1]) ** 2
                    + (points[u, 2] - points[v, 2]) ** 2
                )
                shortest = min(shortest, 2.0 * length / (sizes[u] + sizes[v]))
    return shortest


@numba.njit(cache=True)
def short_edge_vertices(points, cells, sizes, floor):
    """Mask of the vertices with an edge shorter than ``floor`` times its size, the mean of its ends' ``sizes``."""
    short = np.zeros(points.shape[0], dtype=np.bool_)
    for c in range(cells.shape[0]):
        for i in range(3):
            for j in range(i + 1, 4):
                u, w = cells[c, i], cells[c, j]
                length = np.sqrt(
                    (points[u, 0] - points[w, 0]) ** 2
                    + (points[u, 1] - points[w, 1]) ** 2
                    + (points[u, 2] - points[w, 2]) ** 2
                )
                if 2.0 * length < floor * (sizes[u] + sizes[w]):
                    short[u] = short[w] = True
    return short


@numba.njit(cache=True)
def lengthen_short_edges(points, cells, sizes, vertices, candidates, floor, keep_quality):
    """Move each of ``vertices`` to the one of its ``candidates`` (k, c, 3) where its shortest edge is longest.

    Edges are measured over their size, the mean of their ends' ``sizes``,
    and up to ``floor``: of the candidates that reach it, the one whose
    cells' worst radius ratio is best. A candidate is refused where a
    dihedral angle of the vertex's cells becomes smaller than their smallest
    before, or their worst radius ratio falls below ``min(before,
    keep_quality)``; a vertex none of whose candidates lengthens its
    shortest edge stays. In order, so the result depends only on the input;
    no cell inverts. Returns the number of vertices moved.
    """
    start, index = vertex_cells(cells, points.shape[0])
    origin = np.empty(3)
    moves = 0
    for i in range(vertices.shape[0]):
        v = vertices[i]
        star = index[start[v] : start[v + 1]]
        if star.shape[0] == 0:
            continue
        start_ratio = _shortest_edge_ratio(points, cells, star, v, sizes)
        if start_ratio >= floor:  # a neighbour's move already lengthened it
            continue
        origin[:] = points[v]
        worst, largest_cosine = star_measures(points, cells, star)
        keep = min(worst, keep_quality)
        best_ratio, best_quality = start_ratio, -np.inf
        chosen = -1
        for j in range(candidates.shape[1]):
            points[v] = candidates[i, j]
            ratio = min(_shortest_edge_ratio(points, cells, star, v, sizes), floor)
            if ratio <= start_ratio or ratio < best_ratio:
                continue
            quality, cosine = star_measures(points, cells, star)
            if quality < keep or cosine > largest_cosine:
                continue
            if ratio > best_ratio or quality > best_quality:
                best_ratio, best_quality, chosen = ratio, quality, j
        if chosen >= 0:
            points[v] = candidates[i, chosen]
            moves += 1
        else:
            points[v] = origin
    return moves
