"""Incremental 3D Delaunay tetrahedralisation (Bowyer-Watson) and kernels on tetrahedra.

Floating-point predicates; the cavity of each new point is grown until the
point sees all its faces, so the result is always a valid
tetrahedralisation (only nearly Delaunay where rounding misjudges
near-cospherical points). The public wrapper, which validates, scales the
points into the unit box, orders them along a Z-order curve and falls back
on SciPy's Qhull, is :func:`terramesh.generation.triangulate.delaunay_3d`.

Layout: ``cells`` (m, 4) int64 positively oriented
(``(b - a) . ((c - a) x (d - a)) > 0``); ``neighbors`` (m, 4) int64,
``neighbors[c, k]`` is the cell across the face opposite corner ``k``, -1 on
the boundary. Also here: the connectivity kernels the 3D generator runs on
such cells (incidence, unique edges, boundary vertices and fans, cells surely
inside, the quality mean and spread).
"""

import numba
import numpy as np

from .topology import vertex_cells

_OK = 0
_WALK_FAILED = 1
_CAVITY_FAILED = 2


@numba.njit(cache=True, inline="always")
def _orient(points, a, b, c, d):
    """Six times the signed volume of ``(a, b, c, d)``: positive when ``d`` sees ``a, b, c`` counter-clockwise."""
    bx = points[b, 0] - points[a, 0]
    by = points[b, 1] - points[a, 1]
    bz = points[b, 2] - points[a, 2]
    cx = points[c, 0] - points[a, 0]
    cy = points[c, 1] - points[a, 1]
    cz = points[c, 2] - points[a, 2]
    dx = points[d, 0] - points[a, 0]
    dy = points[d, 1] - points[a, 1]
    dz = points[d, 2] - points[a, 2]
    return bx * (cy * dz - cz * dy) - by * (cx * dz - cz * dx) + bz * (cx * dy - cy * dx)


@numba.njit(cache=True, inline="always")
def _insphere(points, a, b, c, d, e):
    """Positive when ``e`` lies inside the circumsphere of the positively oriented ``(a, b, c, d)``."""
    ax = points[a, 0] - points[e, 0]
    ay = points[a, 1] - points[e, 1]
    az = points[a, 2] - points[e, 2]
    bx = points[b, 0] - points[e, 0]
    by = points[b, 1] - points[e, 1]
    bz = points[b, 2] - points[e, 2]
    cx = points[c, 0] - points[e, 0]
    cy = points[c, 1] - points[e, 1]
    cz = points[c, 2] - points[e, 2]
    dx = points[d, 0] - points[e, 0]
    dy = points[d, 1] - points[e, 1]
    dz = points[d, 2] - points[e, 2]
    ab = ax * by - bx * ay
    bc = bx * cy - cx * by
    cd = cx * dy - dx * cy
    da = dx * ay - ax * dy
    ac = ax * cy - cx * ay
    bd = bx * dy - dx * by
    abc = az * bc - bz * ac + cz * ab
    bcd = bz * cd - cz * bd + dz * bc
    cda = cz * da + dz * ac + az * cd
    dab = dz * ab + az * bd + bz * da
    alift = ax * ax + ay * ay + az * az
    blift = bx * bx + by * by + bz * bz
    clift = cx * cx + cy * cy + cz * cz
    dlift = dx * dx + dy * dy + dz * dz
    # Shewchuk's insphere determinant, whose orientation convention is the opposite of ours
    return (alift * bcd - blift * cda) + (clift * dab - dlift * abc)


@numba.njit(cache=True, inline="always")
def _orient_replaced(points, tets, t, k, p):
    """Orientation of cell ``t`` with its corner ``k`` replaced by point ``p``."""
    v0 = p if k == 0 else tets[t, 0]
    v1 = p if k == 1 else tets[t, 1]
    v2 = p if k == 2 else tets[t, 2]
    v3 = p if k == 3 else tets[t, 3]
    return _orient(points, v0, v1, v2, v3)


@numba.njit(cache=True)
def _grown(array, size, fill):
    out = np.full((size,) + array.shape[1:], fill, dtype=array.dtype)
    out[: array.shape[0]] = array
    return out


@numba.njit(cache=True, inline="always")
def _into_cavity(cavity, stack, n_cavity, cell):
    """``cavity`` with ``cell`` appended (both work arrays grown when full); returns ``(cavity, stack, n_cavity)``."""
    if n_cavity == cavity.shape[0]:
        cavity = _grown(cavity, 2 * n_cavity, -1)
        stack = _grown(stack, 2 * n_cavity, -1)
    cavity[n_cavity] = cell
    return cavity, stack, n_cavity + 1


@numba.njit(cache=True)
def _bowyer_watson(points, order):
    """Delaunay tetrahedra of ``points[:-4]`` inserted in ``order``; ``points[-4:]`` enclose them all.

    Returns ``(status, cells, neighbors, duplicate_of)``: positively oriented
    cells of the real points (those touching the enclosing tetrahedron
    dropped), ``neighbors[c, k]`` the cell across the face opposite corner
    ``k`` (-1 where none is kept), and for each point the vertex it
    coincides with exactly (-1 for vertices).
    """
    n_all = points.shape[0]
    n = n_all - 4
    capacity = 7 * n + 64
    tets = np.empty((capacity, 4), dtype=np.int64)
    neighbors = np.full((capacity, 4), -1, dtype=np.int64)
    alive = np.zeros(capacity, dtype=np.bool_)
    stamp = np.full(capacity, -1, dtype=np.int64)
    free = np.empty(capacity, dtype=np.int64)
    n_free = 0
    n_used = 1
    tets[0, 0] = n
    tets[0, 1] = n + 1
    tets[0, 2] = n + 2
    tets[0, 3] = n + 3
    if _orient(points, n, n + 1, n + 2, n + 3) < 0:
        tets[0, 2] = n + 3
        tets[0, 3] = n + 2
    alive[0] = True
    cavity = np.empty(256, dtype=np.int64)
    stack = np.empty(256, dtype=np.int64)
    face_tet = np.empty(512, dtype=np.int64)
    face_corner = np.empty(512, dtype=np.int64)
    table_size = 4096
    table_key = np.full(table_size, -1, dtype=np.int64)
    table_value = np.empty(table_size, dtype=np.int64)
    table_stamp = np.full(table_size, -1, dtype=np.int64)
    duplicate_of = np.full(n, -1, dtype=np.int64)
    last = 0
    rotation = 0
    generator = 12345
    for step in range(order.shape[0]):
        p = order[step]
        # locate p by a visibility walk from the last new cell
        t = last
        walked = 0
        while True:
            moved = False
            for kk in range(4):
                k = (kk + rotation) & 3
                if _orient_replaced(points, tets, t, k, p) < 0.0:
                    t = neighbors[t, k]
                    moved = True
                    break
            # the face tried first follows a pseudo-random sequence, so that the walk cannot cycle
            generator = (generator * 1103515245 + 12345) & 0x7FFFFFFF
            rotation = (generator >> 16) & 3
            if not moved:
                break
            walked += 1
            if walked > 1000 or t < 0:
                # rounding made the walk cycle (nearly coplanar points): search every cell
                t = -1
                best = -np.inf
                for c in range(n_used):
                    if not alive[c]:
                        continue
                    worst = np.inf
                    for k in range(4):
                        worst = min(worst, _orient_replaced(points, tets, c, k, p))
                    if worst > best:
                        best = worst
                        t = c
                    if worst >= 0.0:
                        break
                if t < 0:
                    return _WALK_FAILED, tets[:0], neighbors[:0], duplicate_of
                break
        duplicate = -1
        for k in range(4):
            v = tets[t, k]
            if points[v, 0] == points[p, 0] and points[v, 1] == points[p, 1] and points[v, 2] == points[p, 2]:
                duplicate = v
        if duplicate >= 0:
            duplicate_of[p] = duplicate
            continue
        # the cavity: cells whose circumsphere holds p, connected to the one containing it
        n_cavity = 1
        cavity[0] = t
        stamp[t] = step
        n_stack = 1
        stack[0] = t
        while n_stack > 0:
            n_stack -= 1
            c = stack[n_stack]
            for k in range(4):
                o = neighbors[c, k]
                if o >= 0 and stamp[o] != step:
                    if _insphere(points, tets[o, 0], tets[o, 1], tets[o, 2], tets[o, 3], p) > 0.0:
                        stamp[o] = step
                        cavity, stack, n_cavity = _into_cavity(cavity, stack, n_cavity, o)
                        stack[n_stack] = o
                        n_stack += 1
        # p must see every cavity face from inside (rounding can break that): grow the cavity until it does
        while True:
            n_faces = 0
            grown = False
            for ci in range(n_cavity):
                c = cavity[ci]
                for k in range(4):
                    o = neighbors[c, k]
                    if o >= 0 and stamp[o] == step:
                        continue
                    if _orient_replaced(points, tets, c, k, p) <= 0.0:
                        if o < 0:
                            return _CAVITY_FAILED, tets[:0], neighbors[:0], duplicate_of
                        stamp[o] = step
                        cavity, stack, n_cavity = _into_cavity(cavity, stack, n_cavity, o)
                        grown = True
                        continue
                    if n_faces == face_tet.shape[0]:
                        face_tet = _grown(face_tet, 2 * n_faces, -1)
                        face_corner = _grown(face_corner, 2 * n_faces, -1)
                    face_tet[n_faces] = c
                    face_corner[n_faces] = k
                    n_faces += 1
            if not grown:
                break
        # new cells: p joined to every cavity face; faces through p are matched by their other edge
        if 6 * n_faces > table_size:
            while 6 * n_faces > table_size:
                table_size *= 2
            table_key = np.full(table_size, -1, dtype=np.int64)
            table_value = np.empty(table_size, dtype=np.int64)
            table_stamp = np.full(table_size, -1, dtype=np.int64)
        mask = table_size - 1
        for f in range(n_faces):
            if n_free > 0:
                n_free -= 1
                nt = free[n_free]
            else:
                if n_used == tets.shape[0]:
                    size = 2 * tets.shape[0]
                    tets = _grown(tets, size, -1)
                    neighbors = _grown(neighbors, size, -1)
                    alive = _grown(alive, size, False)
                    stamp = _grown(stamp, size, -1)
                    free = _grown(free, size, -1)
                nt = n_used
                n_used += 1
            c = face_tet[f]
            k = face_corner[f]
            for j in range(4):
                tets[nt, j] = tets[c, j]
            tets[nt, k] = p
            alive[nt] = True
            stamp[nt] = -1
            o = neighbors[c, k]
            neighbors[nt, k] = o
            if o >= 0:
                for j in range(4):
                    if neighbors[o, j] == c:
                        neighbors[o, j] = nt
            for i in range(4):
                if i == k:
                    continue
                u = -1
                w = -1
                for j in range(4):
                    if j != i and j != k:
                        if u < 0:
                            u = tets[nt, j]
                        else:
                            w = tets[nt, j]
                if u > w:
                    u, w = w, u
                key = u * n_all + w
                h = (key * 2654435761) & mask
                while True:
                    if table_stamp[h] != step:
                        table_stamp[h] = step
                        table_key[h] = key
                        table_value[h] = 4 * nt + i
                        break
                    if table_key[h] == key:
                        other = table_value[h] >> 2
                        slot = table_value[h] & 3
                        neighbors[nt, i] = other
                        neighbors[other, slot] = nt
                        break
                    h = (h + 1) & mask
            last = nt
        for ci in range(n_cavity):
            c = cavity[ci]
            alive[c] = False
            free[n_free] = c
            n_free += 1
    renumber = np.full(n_used, -1, dtype=np.int64)
    count = 0
    for t in range(n_used):
        if alive[t] and tets[t, 0] < n and tets[t, 1] < n and tets[t, 2] < n and tets[t, 3] < n:
            renumber[t] = count
            count += 1
    cells = np.empty((count, 4), dtype=np.int64)
    cell_neighbors = np.empty((count, 4), dtype=np.int64)
    for t in range(n_used):
        r = renumber[t]
        if r >= 0:
            for j in range(4):
                cells[r, j] = tets[t, j]
                o = neighbors[t, j]
                cell_neighbors[r, j] = renumber[o] if o >= 0 else -1
    return _OK, cells, cell_neighbors, duplicate_of


# --- connectivity kernels ------------------------------------------------------------------------


@numba.njit(cache=True)
def _unique_edges(cells, n_points):
    """Every edge of the cells once, as (e, 2) vertex pairs ``(a, b)`` with ``a < b``, ordered by ``a``.

    Through the cells around each vertex, with a stamp per vertex instead
    of sorting.
    """
    m = cells.shape[0]
    start, around = vertex_cells(cells, n_points)
    stamp = np.full(n_points, -1, dtype=np.int64)
    edges = np.empty((3 * m + n_points, 2), dtype=np.int64)  # at most 6 m / 2 + ... edges; grown if not
    count = 0
    for v in range(n_points):
        for i in range(start[v], start[v + 1]):
            t = around[i]
            for k in range(4):
                u = cells[t, k]
                if u > v and stamp[u] != v:
                    stamp[u] = v
                    if count == edges.shape[0]:
                        edges = _grown(edges, 2 * count, -1)
                    edges[count, 0] = v
                    edges[count, 1] = u
                    count += 1
    return edges[:count].copy()


@numba.njit(cache=True)
def _quality_mean_std(points, cells):
    """Mean and standard deviation of ``6 sqrt(2) V / l_rms**3`` (1 for a regular tetrahedron)."""
    m = cells.shape[0]
    total = 0.0
    total2 = 0.0
    factor = 6.0 * np.sqrt(2.0) / 6.0
    for t in range(m):
        a = cells[t, 0]
        squares = 0.0
        for i in range(3):
            for j in range(i + 1, 4):
                for d in range(3):
                    delta = points[cells[t, i], d] - points[cells[t, j], d]
                    squares += delta * delta
        six_volume = _orient(points, a, cells[t, 1], cells[t, 2], cells[t, 3])
        rms = np.sqrt(squares / 6.0)
        q = factor * six_volume / (rms * rms * rms) if rms > 0.0 else 0.0
        total += q
        total2 += q * q
    mean = total / max(m, 1)
    return mean, np.sqrt(max(total2 / max(m, 1) - mean * mean, 0.0))


@numba.njit(cache=True)
def _boundary_vertex_mask(tets, neighbors, alive, n_points):
    """Vertices on a boundary face of a live cell."""
    mask = np.zeros(n_points, dtype=np.bool_)
    for t in range(tets.shape[0]):
        if alive[t]:
            for k in range(4):
                if neighbors[t, k] < 0:
                    for j in range(4):
                        if j != k:
                            mask[tets[t, j]] = True
    return mask


@numba.njit(cache=True)
def _link_components(faces, n_points):
    """Per vertex, the number of fans its boundary faces form: 1 where the surface is manifold, 0 off it.

    Faces around a vertex belong to one fan when a chain of them shares
    edges through the vertex (union-find over the faces at each vertex).
    """
    n = faces.shape[0]
    start, around = vertex_cells(faces, n_points)
    root = np.arange(n)
    components = np.zeros(n_points, dtype=np.int64)
    for v in range(n_points):
        low = start[v]
        high = start[v + 1]
        for i in range(low, high):
            root[around[i]] = around[i]
        for i in range(low, high):
            fi = around[i]
            for j in range(i + 1, high):
                fj = around[j]
                shared = False
                for a in range(3):
                    for b in range(3):
                        if faces[fi, a] == faces[fj, b] and faces[fi, a] != v:
                            shared = True
                if shared:
                    x = fi
                    while root[x] != x:
                        x = root[x]
                    y = fj
                    while root[y] != y:
                        y = root[y]
                    if x != y:
                        root[x] = y
        for i in range(low, high):
            if root[around[i]] == around[i]:
                components[v] += 1
    return components
