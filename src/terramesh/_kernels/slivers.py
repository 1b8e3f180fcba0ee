"""Kernels of :mod:`terramesh.cleanup.slivers`: flips, vertex moves and contractions, flat boundary cells.

Private and unvalidated: ``points`` (n, 3) float64; the mesh is held as
``tets`` (capacity, 4) int64 positively oriented, ``neighbors`` (capacity,
4) int64 with the cell across the face opposite each corner (-1 on the
boundary), ``alive`` flags, a free list, and ``vertex_tet``: one live cell at
each vertex (-1 for an unused vertex). Every change goes through
``_replace_cells`` (a cell deleted outright: :func:`delete_flat_boundary_cells`),
keeping all of it consistent. A cell's quality is minus the cosine of its
smallest dihedral angle.
"""

import numba
import numpy as np

from .arrays import copy_head, copy_rows
from .cleanup import sorted3
from .delaunay3d import orient3d
from .tetra import face_normal, tet_largest_cosine

# degrees: every cell the 3D generator returns has a smallest dihedral angle at least this (re-exported by
# terramesh.cleanup.slivers; here for _FOLDED, which numba reads as a constant of this module)
MIN_DIHEDRAL = 10.0

_MAX_RING = 7  # largest number of cells around an edge that edge removal tries
_MAX_STAR = 512


_INVALID = -3.0  # the quality of a cell that is not positively oriented
# boundary faces whose normals are this close to opposite are folded onto each other, not two sides of an edge
_FOLDED = -np.cos(np.radians(MIN_DIHEDRAL))


@numba.njit(cache=True)
def _quality(points, a, b, c, d):
    """Minus the cosine of the smallest dihedral angle (rises with the angle, -1 to -1/3); _INVALID if not positive."""
    cosine = tet_largest_cosine(points, a, b, c, d)
    return _INVALID if cosine > 1.0 else -cosine


@numba.njit(cache=True)
def _face_of(tets, t, k):
    """Sorted vertices of the face of cell ``t`` opposite corner ``k``."""
    a = tets[t, (k + 1) & 3]
    b = tets[t, (k + 2) & 3]
    c = tets[t, (k + 3) & 3]
    return sorted3(a, b, c)


@numba.njit(cache=True)
def _allocate(tets, free, state):
    """A free cell slot (state[0]: slots used, state[1]: free-list length); -1 when full."""
    if state[1] > 0:
        state[1] -= 1
        return free[state[1]]
    if state[0] < tets.shape[0]:
        state[0] += 1
        return state[0] - 1
    return -1


@numba.njit(cache=True)
def _replace_cells(tets, neighbors, alive, vertex_tet, free, state, old, n_old, new, n_new):
    """Replace cells ``old[:n_old]`` by ``new[:n_new]`` (vertex quadruples) filling the same region.

    Faces of the new cells are linked to each other and to the cells around
    the old ones by their vertex sets. Returns False (nothing changed) when
    the slots run out or a new face has no partner or more than one (the
    new cells would not fill the region as a manifold).
    """
    n_outer = 0
    outer_face = np.empty((4 * n_old, 3), dtype=np.int64)
    outer_cell = np.empty(4 * n_old, dtype=np.int64)
    for i in range(n_old):
        t = old[i]
        for k in range(4):
            o = neighbors[t, k]
            internal = False
            for j in range(n_old):
                if old[j] == o:
                    internal = True
            if not internal:
                x, y, z = _face_of(tets, t, k)
                outer_face[n_outer, 0] = x
                outer_face[n_outer, 1] = y
                outer_face[n_outer, 2] = z
                outer_cell[n_outer] = o
                n_outer += 1
    ids = np.empty(n_new, dtype=np.int64)
    for j in range(n_new):
        if j < n_old:
            ids[j] = old[j]
        else:
            ids[j] = _allocate(tets, free, state)
            if ids[j] < 0:
                for i in range(n_old, j):  # give back what was taken
                    free[state[1]] = ids[i]
                    state[1] += 1
                return False
    # check every new face has a partner before writing anything
    partner = np.full((n_new, 4), -2, dtype=np.int64)  # >= 0: new cell index j2 * 4 + k2; -1 - i: outer face i
    for j in range(n_new):
        for k in range(4):
            x, y, z = sorted3(new[j, (k + 1) & 3], new[j, (k + 2) & 3], new[j, (k + 3) & 3])
            found = 0
            for j2 in range(n_new):
                if j2 == j:
                    continue
                for k2 in range(4):
                    x2, y2, z2 = sorted3(new[j2, (k2 + 1) & 3], new[j2, (k2 + 2) & 3], new[j2, (k2 + 3) & 3])
                    if x == x2 and y == y2 and z == z2:
                        partner[j, k] = 4 * j2 + k2
                        found += 1
            for i in range(n_outer):
                if outer_face[i, 0] == x and outer_face[i, 1] == y and outer_face[i, 2] == z:
                    partner[j, k] = -1 - i
                    found += 1
            if found != 1:  # no partner, or a face in three cells: not a valid replacement
                for i in range(n_new - n_old):
                    free[state[1]] = ids[n_old + i]
                    state[1] += 1
                return False
    for j in range(n_new):
        t = ids[j]
        for k in range(4):
            tets[t, k] = new[j, k]
        alive[t] = True
    for j in range(n_new):
        t = ids[j]
        for k in range(4):
            p = partner[j, k]
            if p >= 0:
                neighbors[t, k] = ids[p >> 2]
            else:
                o = outer_cell[-1 - p]
                neighbors[t, k] = o
                if o >= 0:
                    x, y, z = sorted3(tets[t, (k + 1) & 3], tets[t, (k + 2) & 3], tets[t, (k + 3) & 3])
                    for k2 in range(4):
                        x2, y2, z2 = _face_of(tets, o, k2)
                        if x == x2 and y == y2 and z == z2:
                            neighbors[o, k2] = t
        for k in range(4):
            vertex_tet[tets[t, k]] = t
    for i in range(n_new, n_old):
        t = old[i]
        alive[t] = False
        free[state[1]] = t
        state[1] += 1
    return True


@numba.njit(cache=True)
def _edge_ring(tets, neighbors, t0, a, b, ring_cells, ring_vertices):
    """Cells and vertices around the edge ``a b`` of cell ``t0``, in order; -1 for a boundary or crowded edge.

    ``ring_cells[i]`` holds ``a, b, ring_vertices[i], ring_vertices[i + 1]`` (cyclically).
    """
    x = -1
    y = -1
    for k in range(4):
        v = tets[t0, k]
        if v != a and v != b:
            if x < 0:
                x = v
            else:
                y = v
    previous = x
    following = y
    current = t0
    count = 0
    while True:
        if count == ring_cells.shape[0]:
            return -1
        ring_cells[count] = current
        ring_vertices[count] = previous
        count += 1
        k = 0
        while k < 4 and tets[current, k] != previous:
            k += 1
        if k == 4:
            return -1  # the cells do not close round the edge (a pinched boundary): no ring to walk
        nxt = neighbors[current, k]
        if nxt < 0:
            return -1
        if nxt == t0:
            return count
        z = -1
        shared = 0
        for k in range(4):
            v = tets[nxt, k]
            if v == a or v == b or v == following:
                shared += 1
            else:
                z = v
        if shared != 3:
            return -1  # the neighbour across does not hold the edge and the ring's last vertex
        previous = following
        following = z
        current = nxt


@numba.njit(cache=True)
def _pair_quality(points, a, b, r0, r1, r2, sense):
    """Smaller quality of the cells joining triangle ``r0 r1 r2`` (in ring order) to ``a`` and to ``b``.

    ``sense`` is the sign of ``orient(a, b, r_i, r_i+1)`` along the ring: for
    -1, ``a`` lies on the positive side of the triangle taken in ring order
    and ``b`` on the negative side; for +1 the reverse. _INVALID when a
    cell is not positive.
    """
    if sense < 0:
        qa = _quality(points, r0, r1, r2, a)
        qb = _quality(points, r1, r0, r2, b)
    else:
        qa = _quality(points, r1, r0, r2, a)
        qb = _quality(points, r0, r1, r2, b)
    if qa == _INVALID or qb == _INVALID:
        return _INVALID
    return min(qa, qb)


@numba.njit(cache=True)
def _try_edge_removal(points, tets, neighbors, t0, a, b, ring_cells, ring_vertices, new, best, choice, stack):
    """Best retriangulation of the cells around edge ``a b`` (dynamic programming over the ring's triangulations).

    Returns ``(quality, n_ring, n_new)``: the new cells' smallest quality
    and how many old and new cells, with the new cells in ``new``;
    quality _INVALID when impossible.
    """
    n = _edge_ring(tets, neighbors, t0, a, b, ring_cells, ring_vertices)
    if n < 3:
        return _INVALID, 0, 0
    sense = 1.0 if orient3d(points, a, b, ring_vertices[0], ring_vertices[1]) > 0.0 else -1.0
    for i in range(n):
        if orient3d(points, a, b, ring_vertices[i], ring_vertices[(i + 1) % n]) * sense <= 0.0:
            return _INVALID, n, 0  # the ring is not consistently oriented (an inverted cell): no removal
    for i in range(n):
        for j in range(n):
            best[i, j] = _INVALID
            choice[i, j] = -1
    for i in range(n - 1):
        best[i, i + 1] = 1e300
    for length in range(2, n):
        for i in range(n - length):
            j = i + length
            for k in range(i + 1, j):
                value = min(best[i, k], best[k, j])
                if value <= best[i, j]:
                    continue
                value = min(
                    value, _pair_quality(points, a, b, ring_vertices[i], ring_vertices[k], ring_vertices[j], sense)
                )
                if value > best[i, j]:
                    best[i, j] = value
                    choice[i, j] = k
    quality = best[0, n - 1]
    if quality == _INVALID:
        return _INVALID, n, 0
    n_new = 0
    top = 1
    stack[0, 0] = 0
    stack[0, 1] = n - 1
    while top > 0:
        top -= 1
        i = stack[top, 0]
        j = stack[top, 1]
        if j - i < 2:
            continue
        k = choice[i, j]
        r0 = ring_vertices[i]
        r1 = ring_vertices[k]
        r2 = ring_vertices[j]
        if sense < 0:
            new[n_new, 0], new[n_new, 1], new[n_new, 2], new[n_new, 3] = r0, r1, r2, a
            new[n_new + 1, 0], new[n_new + 1, 1], new[n_new + 1, 2], new[n_new + 1, 3] = r1, r0, r2, b
        else:
            new[n_new, 0], new[n_new, 1], new[n_new, 2], new[n_new, 3] = r1, r0, r2, a
            new[n_new + 1, 0], new[n_new + 1, 1], new[n_new + 1, 2], new[n_new + 1, 3] = r0, r1, r2, b
        n_new += 2
        stack[top, 0] = i
        stack[top, 1] = k
        stack[top + 1, 0] = k
        stack[top + 1, 1] = j
        top += 2
    return quality, n, n_new


@numba.njit(cache=True)
def _try_face_flip(points, tets, neighbors, t, k, new):
    """The 2-3 flip of the face of ``t`` opposite corner ``k``: the three new cells' smallest quality, or _INVALID.

    The new cells are ``t`` with one corner of that face replaced by the
    apex ``e`` of the cell across; all three are positive exactly when the
    segment from ``t``'s apex to ``e`` crosses the face.
    """
    o = neighbors[t, k]
    if o < 0:
        return _INVALID
    e = -1
    for j in range(4):
        v = tets[o, j]
        if v != tets[t, 0] and v != tets[t, 1] and v != tets[t, 2] and v != tets[t, 3]:
            e = v
    quality = 1e300
    row = 0
    for j in range(4):
        if j == k:
            continue
        for i in range(4):
            new[row, i] = tets[t, i]
        new[row, j] = e
        quality = min(quality, _quality(points, new[row, 0], new[row, 1], new[row, 2], new[row, 3]))
        row += 1
    return quality


@numba.njit(cache=True)
def flip_slivers(points, tets, neighbors, alive, vertex_tet, free, state, order, aim):
    """Improve each cell of ``order`` below quality ``aim`` by the best of edge removals and 2-3 flips around it.

    A change is made only when the smallest quality of the new cells exceeds
    that of the cells they replace. Returns the number of changes.
    """
    ring_cells = np.empty(_MAX_RING, dtype=np.int64)
    ring_vertices = np.empty(_MAX_RING, dtype=np.int64)
    best = np.empty((_MAX_RING, _MAX_RING))
    choice = np.empty((_MAX_RING, _MAX_RING), dtype=np.int64)
    stack = np.empty((2 * _MAX_RING, 2), dtype=np.int64)
    candidate = np.empty((2 * _MAX_RING, 4), dtype=np.int64)
    chosen = np.empty((2 * _MAX_RING, 4), dtype=np.int64)
    chosen_old = np.empty(_MAX_RING, dtype=np.int64)
    changes = 0
    for index in range(order.shape[0]):
        t = order[index]
        if not alive[t]:
            continue
        current = _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3])
        if current >= aim:
            continue
        best_gain = 0.0
        chosen_old_count = np.int64(0)
        chosen_new_count = np.int64(0)
        for i in range(3):
            for j in range(i + 1, 4):
                a = tets[t, i]
                b = tets[t, j]
                q, n_ring, n_new = _try_edge_removal(
                    points, tets, neighbors, t, a, b, ring_cells, ring_vertices, candidate, best, choice, stack
                )
                if q == _INVALID:
                    continue
                before = 1e300
                for r in range(n_ring):
                    c = ring_cells[r]
                    before = min(before, _quality(points, tets[c, 0], tets[c, 1], tets[c, 2], tets[c, 3]))
                if q - before > best_gain:
                    best_gain = q - before
                    chosen_old_count = n_ring
                    chosen_new_count = n_new
                    copy_head(chosen_old, ring_cells, n_ring)
                    copy_rows(chosen, candidate, n_new)
        for k in range(4):
            q = _try_face_flip(points, tets, neighbors, t, k, candidate)
            if q == _INVALID:
                continue
            o = neighbors[t, k]
            before = min(current, _quality(points, tets[o, 0], tets[o, 1], tets[o, 2], tets[o, 3]))
            if q - before > best_gain:
                best_gain = q - before
                chosen_old_count = 2
                chosen_new_count = 3
                chosen_old[0] = t
                chosen_old[1] = o
                copy_rows(chosen, candidate, 3)
        if chosen_new_count > 0:
            if _replace_cells(
                tets, neighbors, alive, vertex_tet, free, state, chosen_old, chosen_old_count, chosen, chosen_new_count
            ):
                changes += 1
    return changes


@numba.njit(cache=True, inline="always")
def _face_normal(points, tets, t, k):
    """First corner ``a`` of the face opposite corner ``k`` of ``t``, its normal (b - a) x (c - a) and its length."""
    a = tets[t, (k + 1) & 3]
    b = tets[t, (k + 2) & 3]
    c = tets[t, (k + 3) & 3]
    nx, ny, nz = face_normal(points, a, b, c)
    return a, nx, ny, nz, np.sqrt(nx * nx + ny * ny + nz * nz)


@numba.njit(cache=True)
def _star(tets, neighbors, vertex_tet, v, out, mark, stamp):
    """The cells around vertex ``v`` (breadth-first across the faces through ``v``); their count, -1 if too many."""
    t0 = vertex_tet[v]
    if t0 < 0:
        return 0
    count = 1
    out[0] = t0
    mark[t0] = stamp
    head = 0
    while head < count:
        t = out[head]
        head += 1
        for k in range(4):
            if tets[t, k] == v:
                continue
            o = neighbors[t, k]
            if o >= 0 and mark[o] != stamp:
                if count == out.shape[0]:
                    return -1
                mark[o] = stamp
                out[count] = o
                count += 1
    return count


@numba.njit(cache=True)
def _star_quality(points, tets, star, n_star, floor):
    """Smallest quality over the star; stops early (returning it) once at or below ``floor``."""
    worst = 1e300
    for s in range(n_star):
        t = star[s]
        q = _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3])
        if q < worst:
            worst = q
            if worst <= floor:
                return worst
    return worst


@numba.njit(cache=True, inline="always")
def _try_point(points, tets, star, n_star, v, x, y, z, best, bx, by, bz):
    """Put ``v`` at ``(x, y, z)``; that becomes the best position if its star's smallest quality beats ``best``.

    Returns the best quality and position so far; ``v`` is left at ``(x, y, z)``.
    """
    points[v, 0] = x
    points[v, 1] = y
    points[v, 2] = z
    q = _star_quality(points, tets, star, n_star, best)
    if q > best:
        return q, x, y, z
    return best, bx, by, bz


@numba.njit(cache=True)
def perturb_vertices(points, tets, neighbors, vertex_tet, vertices, movable, mark, state, directions, steps, aim):
    """Move each movable vertex to the candidate that most raises the smallest quality of its star.

    Vertices whose star is at ``aim`` already are skipped. Candidates: the
    vertex pushed away from the opposite face of each poor cell of its
    star, and along 26 fixed directions, at
    steps shrinking from 0.3 to 0.02 of the mean edge length at the vertex
    (a deterministic pattern search). A move is kept only if every cell
    stays positive and the star's smallest quality rises. Returns the
    number of vertices moved.
    """
    star = np.empty(_MAX_STAR, dtype=np.int64)
    star_quality = np.empty(_MAX_STAR)
    extra = np.empty((_MAX_STAR, 3))
    moved = 0
    for index in range(vertices.shape[0]):
        v = vertices[index]
        if not movable[v]:
            continue
        state[2] += 1
        n_star = _star(tets, neighbors, vertex_tet, v, star, mark, state[2])
        if n_star <= 0:
            continue
        # worst cells first, so that candidates are refused after few evaluations
        for s in range(n_star):
            star_quality[s] = _quality(points, tets[star[s], 0], tets[star[s], 1], tets[star[s], 2], tets[star[s], 3])
        for i in range(1, n_star):
            j = i
            while j > 0 and star_quality[j - 1] > star_quality[j]:
                star_quality[j - 1], star_quality[j] = star_quality[j], star_quality[j - 1]
                star[j - 1], star[j] = star[j], star[j - 1]
                j -= 1
        current = star_quality[0]
        if current >= aim:
            continue  # fixed already, by the move of another vertex of its slivers
        # mean edge length at v and the directions away from poor cells' opposite faces
        total = 0.0
        n_edges = 0
        n_extra = 0
        for s in range(n_star):
            t = star[s]
            k = 0
            while tets[t, k] != v:
                k += 1
            for j in range(4):
                if j != k:
                    u = tets[t, j]
                    total += np.sqrt(
                        (points[u, 0] - points[v, 0]) ** 2
                        + (points[u, 1] - points[v, 1]) ** 2
                        + (points[u, 2] - points[v, 2]) ** 2
                    )
                    n_edges += 1
            q = _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3])
            if q < current + 0.05:
                a, nx, ny, nz, norm = _face_normal(points, tets, t, k)
                if norm > 0.0:
                    # the face normal pointing at v
                    side = nx * (points[v, 0] - points[a, 0]) + ny * (points[v, 1] - points[a, 1])
                    side += nz * (points[v, 2] - points[a, 2])
                    sign = 1.0 if side >= 0.0 else -1.0
                    extra[n_extra, 0] = sign * nx / norm
                    extra[n_extra, 1] = sign * ny / norm
                    extra[n_extra, 2] = sign * nz / norm
                    n_extra += 1
        scale = total / max(n_edges, 1)
        x0 = points[v, 0]
        y0 = points[v, 1]
        z0 = points[v, 2]
        improved = False
        for step in steps:
            length = step * scale
            bx = points[v, 0]
            by = points[v, 1]
            bz = points[v, 2]
            best = current
            cx = bx
            cy = by
            cz = bz
            for d in range(n_extra + directions.shape[0]):
                if d < n_extra:
                    dx, dy, dz = extra[d, 0], extra[d, 1], extra[d, 2]
                else:
                    dx = directions[d - n_extra, 0]
                    dy = directions[d - n_extra, 1]
                    dz = directions[d - n_extra, 2]
                x, y, z = cx + length * dx, cy + length * dy, cz + length * dz
                best, bx, by, bz = _try_point(points, tets, star, n_star, v, x, y, z, best, bx, by, bz)
            points[v, 0] = bx
            points[v, 1] = by
            points[v, 2] = bz
            if best > current:
                current = best
                improved = True
        if improved:
            moved += 1
        else:
            points[v, 0] = x0
            points[v, 1] = y0
            points[v, 2] = z0
    return moved


@numba.njit(cache=True, inline="always")
def _poor_star(points, tets, neighbors, vertex_tet, v, star, mark, state, aim):
    """The cells around ``v`` into ``star`` and their smallest quality, ``(n_star, quality)``.

    ``n_star`` is 0 when ``v`` has no star or its star is at ``aim`` already.
    """
    state[2] += 1
    n_star = _star(tets, neighbors, vertex_tet, v, star, mark, state[2])
    if n_star <= 0:
        return 0, 0.0
    current = _star_quality(points, tets, star, n_star, -1e300)
    if current >= aim:
        return 0, current
    return n_star, current


@numba.njit(cache=True)
def try_positions(points, tets, neighbors, vertex_tet, vertices, candidates, mark, state, aim):
    """Move each vertex to the best of its candidate positions (k, 3) if that raises its star's smallest quality.

    Vertices whose star is at ``aim`` already are skipped.
    """
    star = np.empty(_MAX_STAR, dtype=np.int64)
    moved = 0
    for index in range(vertices.shape[0]):
        v = vertices[index]
        n_star, current = _poor_star(points, tets, neighbors, vertex_tet, v, star, mark, state, aim)
        if n_star <= 0:
            continue
        x0 = points[v, 0]
        y0 = points[v, 1]
        z0 = points[v, 2]
        best = current
        bx, by, bz = x0, y0, z0
        for c in range(candidates.shape[1]):
            x, y, z = candidates[index, c, 0], candidates[index, c, 1], candidates[index, c, 2]
            best, bx, by, bz = _try_point(points, tets, star, n_star, v, x, y, z, best, bx, by, bz)
        points[v, 0] = bx
        points[v, 1] = by
        points[v, 2] = bz
        if best > current:
            moved += 1
    return moved


@numba.njit(cache=True)
def collapse_vertices(points, tets, neighbors, alive, vertex_tet, free, state, vertices, movable, mark, aim):
    """Remove each movable vertex whose star is below ``aim`` by contracting it onto its best neighbour.

    Every cell of the star that holds the neighbour disappears and the others
    get the neighbour in place of the vertex; the neighbour chosen gives the
    largest smallest quality, and the contraction is made only if that beats
    the star's, with every new cell positive and the result a manifold.
    Returns the number of vertices removed.
    """
    star = np.empty(_MAX_STAR, dtype=np.int64)
    new = np.empty((_MAX_STAR, 4), dtype=np.int64)
    best_new = np.empty((_MAX_STAR, 4), dtype=np.int64)
    candidates = np.empty(_MAX_STAR, dtype=np.int64)
    removed = 0
    for index in range(vertices.shape[0]):
        v = vertices[index]
        if not movable[v] or vertex_tet[v] < 0:
            continue
        n_star, current = _poor_star(points, tets, neighbors, vertex_tet, v, star, mark, state, aim)
        if n_star <= 0:
            continue
        n_candidates = 0
        for s in range(n_star):
            for j in range(4):
                u = tets[star[s], j]
                if u == v:
                    continue
                seen = False
                for c in range(n_candidates):
                    if candidates[c] == u:
                        seen = True
                if not seen:
                    candidates[n_candidates] = u
                    n_candidates += 1
        best = current
        best_count = np.int64(0)
        for c in range(n_candidates):
            u = candidates[c]
            worst = 1e300
            count = 0
            for s in range(n_star):
                t = star[s]
                holds_u = False
                for j in range(4):
                    if tets[t, j] == u:
                        holds_u = True
                if holds_u:
                    continue
                for j in range(4):
                    new[count, j] = u if tets[t, j] == v else tets[t, j]
                worst = min(worst, _quality(points, new[count, 0], new[count, 1], new[count, 2], new[count, 3]))
                count += 1
                if worst <= best:
                    break
            if count > 0 and worst > best:
                best = worst
                best_count = count
                copy_rows(best_new, new, count)
        if best_count > 0:
            if _replace_cells(tets, neighbors, alive, vertex_tet, free, state, star, n_star, best_new, best_count):
                vertex_tet[v] = -1
                removed += 1
    return removed


@numba.njit(cache=True)
def _edge_on_boundary(tets, neighbors, t0, a, b):
    """Whether the edge ``a b`` of cell ``t0`` lies on the boundary (its ring of cells is open)."""
    ring_cells = np.empty(64, dtype=np.int64)
    ring_vertices = np.empty(64, dtype=np.int64)
    return _edge_ring(tets, neighbors, t0, a, b, ring_cells, ring_vertices) < 0


@numba.njit(cache=True)
def _boundary_turns_sharply(points, tets, neighbors, t, sharp, normals):
    """Whether two boundary faces of cell ``t`` have outward unit normals whose cosine is below ``sharp``.

    The normals are oriented by the vertex order of the positively oriented
    cell, not by the side of its fourth corner, which a flat cell leaves
    undecided. Faces folded onto each other (normals within MIN_DIHEDRAL of
    opposite) do not count: that is a flat cell lying in the boundary (a
    small face over a large one), not a chord of a domain edge, which would
    be a wedge too thin for any cell to pass the sliver bound. ``normals``
    is scratch space, shape (4, 3).
    """
    count = 0
    for k in range(4):
        if neighbors[t, k] >= 0:
            continue
        a, nx, ny, nz, norm = _face_normal(points, tets, t, k)
        if norm == 0.0:
            continue
        # corners k + 1, k + 2, k + 3 turn counter-clockwise seen from outside for even k (an odd cyclic shift)
        scale = (1.0 if k % 2 == 0 else -1.0) / norm
        normals[count, 0] = nx * scale
        normals[count, 1] = ny * scale
        normals[count, 2] = nz * scale
        for j in range(count):
            cosine = normals[j, 0] * normals[count, 0] + normals[j, 1] * normals[count, 1]
            cosine += normals[j, 2] * normals[count, 2]
            if _FOLDED < cosine < sharp:
                return True
        count += 1
    return False


@numba.njit(cache=True)
def delete_flat_boundary_cells(points, tets, neighbors, alive, vertex_tet, free, state, order, aim, fixed, sharp):
    """Delete cells of ``order`` below quality ``aim`` with two or three boundary faces, where that keeps it manifold.

    Two boundary faces: the two other faces become boundary, allowed when
    the edge they share is not on the boundary already, nor joins two fixed
    points where the faces' outward normals have a cosine below ``sharp``:
    that is a piece of a sharp edge of the domain (a box's, sampled with
    fixed points), which the new boundary faces would cut across, losing
    volume. Three: the vertex shared by the three boundary faces (no other
    cell reaches it across a face) must not be fixed; it becomes unused.
    Four: a cell apart from the rest goes unless it holds a fixed point.
    Returns the number deleted.
    """
    normals = np.empty((4, 3))
    deleted = 0
    for index in range(order.shape[0]):
        t = order[index]
        if not alive[t]:
            continue
        if _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]) >= aim:
            continue
        n_boundary = 0
        for k in range(4):
            if neighbors[t, k] < 0:
                n_boundary += 1
        if n_boundary == 2:
            a = np.int64(-1)
            b = np.int64(-1)
            for k in range(4):
                if neighbors[t, k] < 0:
                    if a < 0:
                        a = tets[t, k]
                    else:
                        b = tets[t, k]
            # the exposed faces share the edge a b (a, b: the corners opposite the boundary faces)
            if _edge_on_boundary(tets, neighbors, t, a, b):
                continue
            pinned = True
            for k in range(4):
                v = tets[t, k]
                if v != a and v != b and not fixed[v]:
                    pinned = False
            if pinned and _boundary_turns_sharply(points, tets, neighbors, t, sharp, normals):
                continue
        elif n_boundary == 3:
            # the tip, on all three boundary faces, is the corner opposite the fourth face
            tip = -1
            for k in range(4):
                if neighbors[t, k] >= 0:
                    tip = tets[t, k]
            if fixed[tip]:
                continue
        elif n_boundary < 4:
            continue
        elif fixed[tets[t, 0]] or fixed[tets[t, 1]] or fixed[tets[t, 2]] or fixed[tets[t, 3]]:
            continue  # a cell on its own, but holding a fixed point
        alive[t] = False
        free[state[1]] = t
        state[1] += 1
        for k in range(4):
            o = neighbors[t, k]
            if o >= 0:
                for j in range(4):
                    if neighbors[o, j] == t:
                        neighbors[o, j] = -1
        for k in range(4):
            v = tets[t, k]
            if vertex_tet[v] == t:
                vertex_tet[v] = -1
                for j in range(4):
                    o = neighbors[t, j]
                    if o >= 0 and j != k:
                        vertex_tet[v] = o
        deleted += 1
    return deleted


@numba.njit(cache=True)
def qualities(points, tets, which):
    """The quality (minus the cosine of the smallest dihedral angle) of each cell ``which`` of ``tets``, shape (k,)."""
    out = np.empty(which.shape[0])
    for i in range(which.shape[0]):
        t = which[i]
        out[i] = _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3])
    return out
