"""Quality-safe smoothing of a triangle mesh, in place, and the moves that raise the worst cells of 2D and 3D meshes.

Private: ``points`` (n, 2) float64, ``cells`` (m, 3) int64 counter-clockwise,
``movable`` (n,) bool; unvalidated. :func:`raise_worst` and
:func:`move_where_better` take tetrahedra too: ``points`` (n, 3), ``cells``
(m, 4) positively oriented.
"""

import numba
import numpy as np

from .tetra import tet_largest_cosine, tet_radius_ratio
from .topology import corner_quality as _quality
from .topology import vertex_cells

# unit directions from a cube's centre to its faces, edges and corners: pattern searches in space
CUBE_DIRECTIONS = np.array(
    [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1) if (i, j, k) != (0, 0, 0)], dtype=np.float64
)
CUBE_DIRECTIONS /= np.sqrt(np.sum(CUBE_DIRECTIONS**2, axis=1))[:, None]


@numba.njit(cache=True, inline="always")
def star_corners(points, cells, star, v, corners, where):
    """The mean of the other corners of the triangles ``star`` of ``v``, gathered on the way into ``corners``.

    Row ``s`` of ``corners`` (at least ``len(star)`` by 4) gets the two
    corners that follow ``v`` in cell ``star[s]``'s counter-clockwise turn,
    ``x, y`` each, and ``where[s]`` the corner ``v`` is at, so that the
    cell can be measured with ``v`` moved (:func:`moved_corners`) without
    reading the cells and points again. The mean adds the corners cell by
    cell, each cell's in its index order (of an interior vertex each
    neighbour twice, in its two cells: their mean). A cell with ``v`` at
    two corners (not a valid cell) adds only its third, and ``where``
    says so: both corners move with ``v``.
    """
    sx = 0.0
    sy = 0.0
    for s in range(star.shape[0]):
        c = star[s]
        k = 0 if cells[c, 0] == v else (1 if cells[c, 1] == v else 2)
        u = cells[c, (k + 1) % 3]
        w = cells[c, (k + 2) % 3]
        where[s] = k + 3 * ((u == v) + 2 * (w == v))
        corners[s, 0] = points[u, 0]
        corners[s, 1] = points[u, 1]
        corners[s, 2] = points[w, 0]
        corners[s, 3] = points[w, 1]
        if k == 1 and w != v:  # corner 0 (w) comes before corner 2 (u)
            sx += corners[s, 2]
            sy += corners[s, 3]
        if u != v:
            sx += corners[s, 0]
            sy += corners[s, 1]
        if k != 1 and w != v:
            sx += corners[s, 2]
            sy += corners[s, 3]
    return sx / (2.0 * star.shape[0]), sy / (2.0 * star.shape[0])


@numba.njit(cache=True, inline="always")
def moved_corners(corners, where, s, x, y):
    """Cell ``s`` of :func:`star_corners` in its corner order, its vertex at ``(x, y)``: ``ax, ay, bx, by, cx, cy``."""
    k = where[s] % 3
    ux, uy = (x, y) if (where[s] // 3) & 1 else (corners[s, 0], corners[s, 1])
    wx, wy = (x, y) if (where[s] // 3) & 2 else (corners[s, 2], corners[s, 3])
    if k == 0:
        return x, y, ux, uy, wx, wy
    if k == 1:
        return wx, wy, x, y, ux, uy
    return ux, uy, wx, wy, x, y


@numba.njit(cache=True)
def smooth_interior(points, cells, movable, passes):
    """Move each ``movable`` vertex to the mean of its neighbours where its star's worst cell does not get worse.

    Gauss-Seidel order (vertex by vertex, in index order, each seeing the
    moves before it), so every accepted move keeps the mesh's worst
    quality and no cell inverts; the result depends only on the input.
    Each cell's quality is kept and renewed when a vertex of it moves, so
    a vertex's present worst is read, not computed again: the same
    numbers (the same corners in the same order), 10-14 % faster. The
    star's corners are read once for the mean and the trial qualities
    (:func:`star_corners`): a pass over 107k vertices 12.3 -> 8.9 ms.
    Returns the number of moves made.
    """
    start, index = vertex_cells(cells, points.shape[0])
    quality = np.empty(cells.shape[0])
    for c in range(cells.shape[0]):
        a, b, d = cells[c, 0], cells[c, 1], cells[c, 2]
        quality[c] = _quality(points[a, 0], points[a, 1], points[b, 0], points[b, 1], points[d, 0], points[d, 1])
    largest_star = 0
    for v in range(points.shape[0]):
        largest_star = max(largest_star, start[v + 1] - start[v])
    trial = np.empty(largest_star)
    corners = np.empty((largest_star, 4))
    where = np.empty(largest_star, dtype=np.int64)
    moves = 0
    for _ in range(passes):
        for v in range(points.shape[0]):
            if not movable[v] or start[v + 1] == start[v]:
                continue
            star = index[start[v] : start[v + 1]]
            x, y = star_corners(points, cells, star, v, corners, where)
            before = np.inf
            after = np.inf
            for s in range(star.shape[0]):
                before = min(before, quality[star[s]])
                ax, ay, bx, by, cx, cy = moved_corners(corners, where, s, x, y)
                trial[s] = _quality(ax, ay, bx, by, cx, cy)
                after = min(after, trial[s])
            if after >= before:
                points[v, 0] = x
                points[v, 1] = y
                for s in range(star.shape[0]):
                    quality[star[s]] = trial[s]
                moves += 1
    return moves


@numba.njit(cache=True)
def move_where_better(points, cells, vertices, candidates):
    """Move each of ``vertices`` to the best of its ``candidates`` (k, c, dim) that makes its star's worst cell better.

    Triangles or tetrahedra, measured as in :func:`raise_worst` (of
    tetrahedra, no dihedral angle smaller than their smallest before).
    Gauss-Seidel order, like :func:`smooth_interior`; a vertex none of whose
    candidates raises the worst quality of its cells stays. Returns the
    number of moves made.
    """
    start, index = vertex_cells(cells, points.shape[0])
    origin = np.empty(points.shape[1])
    moves = 0
    for i in range(vertices.shape[0]):
        v = vertices[i]
        star = index[start[v] : start[v + 1]]
        if star.shape[0] == 0:
            continue
        origin[:] = points[v]
        best, largest_cosine = star_measures(points, cells, star)
        chosen = -1
        for j in range(candidates.shape[1]):
            points[v] = candidates[i, j]
            worst, cosine = star_measures(points, cells, star)
            if worst > best and cosine <= largest_cosine:
                best = worst
                chosen = j
        if chosen >= 0:
            points[v] = candidates[i, chosen]
            moves += 1
        else:
            points[v] = origin
    return moves


@numba.njit(cache=True, inline="always")
def _cell_quality(points, cells, c):
    """Quality of cell ``c``: ``_quality`` of a triangle, the radius ratio of a tetrahedron."""
    if cells.shape[1] == 3:
        a, b, d = cells[c, 0], cells[c, 1], cells[c, 2]
        return _quality(points[a, 0], points[a, 1], points[b, 0], points[b, 1], points[d, 0], points[d, 1])
    return tet_radius_ratio(points, cells[c, 0], cells[c, 1], cells[c, 2], cells[c, 3])


@numba.njit(cache=True)
def star_measures(points, cells, star):
    """The smallest quality of the cells ``star`` and, of tetrahedra, their largest dihedral cosine (else -inf)."""
    worst = np.inf
    cosine = -np.inf
    for s in range(star.shape[0]):
        c = star[s]
        worst = min(worst, _cell_quality(points, cells, c))
        if cells.shape[1] == 4:
            cosine = max(cosine, tet_largest_cosine(points, cells[c, 0], cells[c, 1], cells[c, 2], cells[c, 3]))
    return worst, cosine


@numba.njit(cache=True)
def _search_directions(dim):
    """Unit directions of the pattern search: 16 in the plane, or the 26 of ``CUBE_DIRECTIONS`` in space."""
    if dim == 2:
        directions = np.empty((16, 2))
        for d in range(16):
            angle = 2.0 * np.pi * d / 16.0
            directions[d, 0] = np.cos(angle)
            directions[d, 1] = np.sin(angle)
        return directions
    return CUBE_DIRECTIONS.copy()


@numba.njit(cache=True)
def raise_worst(points, cells, movable, below, passes):
    """Move each ``movable`` vertex of a cell of quality below ``below`` to the nearby place best for its worst cell.

    Triangles (quality ``4 sqrt(3) A / sum(l**2)``) or tetrahedra (radius
    ratio, and then no dihedral angle of the vertex's cells may become
    smaller than their smallest before). A pattern search: 16 directions
    in the plane (26 in space, to a cube's faces, edges and corners) at
    steps of a quarter, a tenth and a twenty-fifth of the vertex's shortest
    edge, each step from the best place so far, which is kept when it
    raises the worst quality of the vertex's cells; repeated up to
    ``passes`` times (until a pass moves nothing). Laplacian smoothing
    moves a vertex to its neighbours' mean, which need not help the one
    poor cell of its star (in 3D a cap or a needle, whose angles the
    sliver bound does not see); this targets that cell. Vertex by vertex
    in index order, so the result depends only on the input; no cell
    inverts. Returns the number of moves made.
    """
    n, dim = points.shape
    directions = _search_directions(dim)
    start, index = vertex_cells(cells, n)
    origin = np.empty(dim)
    best_at = np.empty(dim)
    around = np.empty(dim)
    moves = 0
    for _ in range(passes):
        poor = np.zeros(n, dtype=np.bool_)
        for c in range(cells.shape[0]):
            if _cell_quality(points, cells, c) < below:
                for k in range(cells.shape[1]):
                    poor[cells[c, k]] = True
        changed = 0
        for v in range(n):
            if not poor[v] or not movable[v] or start[v + 1] == start[v]:
                continue
            star = index[start[v] : start[v + 1]]
            origin[:] = points[v]
            shortest = np.inf
            for s in range(star.shape[0]):
                for k in range(cells.shape[1]):
                    u = cells[star[s], k]
                    if u == v:
                        continue
                    if dim == 2:
                        length = np.hypot(points[u, 0] - origin[0], points[u, 1] - origin[1])
                    else:
                        length2 = 0.0
                        for axis in range(dim):
                            length2 += (points[u, axis] - origin[axis]) ** 2
                        length = np.sqrt(length2)
                    shortest = min(shortest, length)
            best, largest_cosine = star_measures(points, cells, star)
            best_at[:] = origin
            for fraction in (0.25, 0.1, 0.04):
                step = fraction * shortest
                around[:] = best_at
                for d in range(directions.shape[0]):
                    for axis in range(dim):
                        points[v, axis] = around[axis] + step * directions[d, axis]
                    worst, cosine = star_measures(points, cells, star)
                    if worst > best and cosine <= largest_cosine:
                        best = worst
                        best_at[:] = points[v]
            points[v] = best_at
            if np.any(best_at != origin):
                changed += 1
        moves += changed
        if changed == 0:
            break
    return moves
