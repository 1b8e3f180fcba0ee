"""Kernels of :func:`terramesh.coastal.merge`: a triangulation with -1 across its boundary, exact predicates.

Private: ``points`` (n, 2) float64, ``cells`` (m, 3) int64 counter-clockwise,
``neighbors`` (m, 3) int64 with ``neighbors[c, k]`` the cell across the edge
opposite corner ``k`` (the edge ``cells[c, k+1], cells[c, k+2]``), -1 on the
boundary; unvalidated. Constrained edges are recovered by flips (Sloan 1993),
Lawson flips keep them, and points and boundary-edge splits are inserted
restoring Delaunay, all on the exact predicates of :mod:`.delaunay`.
"""

import numba
import numpy as np

from . import delaunay as _exact
from .arrays import grown

_RECOVER_ROUNDS = 50  # Sloan's queue may cycle this many times its length before giving up
_WORK_SIZE = _exact.WORK_SIZE


@numba.njit(cache=True)
def _orient(points, a, b, c, work):
    """Exact sign of the orientation of ``a, b, c`` (one compiled copy of the kernel's predicate)."""
    return _exact.orient(points, a, b, c, work)


@numba.njit(cache=True)
def _incircle(points, a, b, c, d, work):
    """Exact sign of ``d`` in the circle through counter-clockwise ``a, b, c``."""
    return _exact.incircle(points, a, b, c, d, work)


_replace = _exact.replace_neighbor


@numba.njit(cache=True)
def _flip(cells, neighbors, vcell, t1, k):
    """The kernel's flip of the edge opposite corner ``k`` of ``t1``, keeping ``vcell`` (a cell per vertex) right."""
    t2 = _exact.flip_edge(cells, neighbors, t1, k)
    for corner in range(3):
        vcell[cells[t1, corner]] = t1
    vcell[cells[t2, 2]] = t2
    return t2


@numba.njit(cache=True)
def _corner(cells, t, a):
    for i in range(3):
        if cells[t, i] == a:
            return i
    return -1


@numba.njit(cache=True)
def _find_edge(cells, neighbors, vcell, a, b):
    """The cell holding edge ``a b`` and its corner opposite that edge, by turning around ``a``; (-1, -1) if none."""
    start = vcell[a]
    for direction in range(2):
        t = start
        while True:
            i = _corner(cells, t, a)
            for k in range(3):
                if cells[t, k] == b:
                    return t, 3 - i - k
            following = neighbors[t, (i + 1) % 3] if direction == 0 else neighbors[t, (i + 2) % 3]
            if following < 0:
                break
            t = following
            if t == start:
                return -1, -1
    return -1, -1


@numba.njit(cache=True)
def _find_directed(cells, neighbors, vcell, a, b):
    """The cell holding the directed edge ``a -> b`` and its corner opposite it; (-1, -1) if none."""
    t, k = _find_edge(cells, neighbors, vcell, a, b)
    if t < 0:
        return -1, -1
    if cells[t, (k + 1) % 3] == a:
        return t, k
    t2 = neighbors[t, k]
    if t2 < 0:
        return -1, -1
    for j in range(3):
        if cells[t2, j] != a and cells[t2, j] != b:
            return t2, j
    return -1, -1


@numba.njit(cache=True)
def _crosses(points, a, b, c, d, work):
    """Whether the open segments ``a b`` and ``c d`` cross at one interior point (exact signs)."""
    if a == c or a == d or b == c or b == d:
        return False
    oc = _orient(points, a, b, c, work)
    od = _orient(points, a, b, d, work)
    if not ((oc > 0.0 and od < 0.0) or (oc < 0.0 and od > 0.0)):
        return False
    oa = _orient(points, c, d, a, work)
    ob = _orient(points, c, d, b, work)
    return (oa > 0.0 and ob < 0.0) or (oa < 0.0 and ob > 0.0)


@numba.njit(cache=True)
def _first_crossing(points, cells, neighbors, vcell, u, v, work):
    """Turn around ``u`` to the cell the segment ``u v`` leaves through.

    Returns ``(status, right, left)``: status 0 with the first crossed edge
    (its ends right and left of ``u -> v``), 1 when ``u v`` is an edge
    already, -1 when a vertex lies on the segment (it cannot be recovered).
    """
    start = vcell[u]
    for direction in range(2):
        t = start
        while True:
            i = _corner(cells, t, u)
            a = cells[t, (i + 1) % 3]
            b = cells[t, (i + 2) % 3]
            if a == v or b == v:
                return 1, -1, -1
            oa = _orient(points, u, v, a, work)
            ob = _orient(points, u, v, b, work)
            if oa < 0.0 and ob > 0.0:
                return 0, a, b
            ahead_a = (points[a, 0] - points[u, 0]) * (points[v, 0] - points[u, 0]) + (points[a, 1] - points[u, 1]) * (
                points[v, 1] - points[u, 1]
            ) > 0.0
            ahead_b = (points[b, 0] - points[u, 0]) * (points[v, 0] - points[u, 0]) + (points[b, 1] - points[u, 1]) * (
                points[v, 1] - points[u, 1]
            ) > 0.0
            if (oa == 0.0 and ahead_a) or (ob == 0.0 and ahead_b):
                return -1, -1, -1
            following = neighbors[t, (i + 1) % 3] if direction == 0 else neighbors[t, (i + 2) % 3]
            if following < 0:
                break
            t = following
            if t == start:
                break
    return -1, -1, -1


@numba.njit(cache=True)
def recover_edges(points, cells, neighbors, constraints):
    """Make every constraint an edge of the triangulation by flips (Sloan 1993); in place.

    ``constraints`` (k, 2) must not cross one another nor pass through a
    vertex. Returns the number of constraints that could not be recovered.
    """
    work = np.empty(_WORK_SIZE)
    n = points.shape[0]
    vcell = np.full(n, -1, dtype=np.int64)
    for t in range(cells.shape[0]):
        for k in range(3):
            vcell[cells[t, k]] = t
    failed = 0
    queue = np.empty((64, 2), dtype=np.int64)
    for c in range(constraints.shape[0]):
        u = constraints[c, 0]
        v = constraints[c, 1]
        status, right, left = _first_crossing(points, cells, neighbors, vcell, u, v, work)
        if status == 1:
            continue
        if status < 0:
            failed += 1
            continue
        # walk along u -> v collecting the crossed edges
        size = 0
        ok = True
        while True:
            if size == queue.shape[0]:
                queue = grown(queue, 2 * size, 0)
            queue[size, 0] = right
            queue[size, 1] = left
            size += 1
            t, k = _find_directed(cells, neighbors, vcell, left, right)
            if t < 0:
                ok = False
                break
            w = cells[t, k]  # the cell beyond the crossed edge runs left -> right
            if w == v:
                break
            ow = _orient(points, u, v, w, work)
            if ow > 0.0:
                left = w
            elif ow < 0.0:
                right = w
            else:
                ok = False
                break
        if not ok:
            failed += 1
            continue
        # flip the crossed edges away, in a queue (Sloan)
        head = 0
        count = size
        tries = 0
        limit = _RECOVER_ROUNDS * (size + 1)
        while count > 0 and tries < limit:
            tries += 1
            x = queue[head % queue.shape[0], 0]
            y = queue[head % queue.shape[0], 1]
            head += 1
            count -= 1
            t, k = _find_edge(cells, neighbors, vcell, x, y)
            if t < 0:
                continue
            t2 = neighbors[t, k]
            if t2 < 0:
                continue
            j = 0
            while neighbors[t2, j] != t:
                j += 1
            c1 = cells[t, k]
            d1 = cells[t2, j]
            if _crosses(points, x, y, c1, d1, work):
                _flip(cells, neighbors, vcell, t, k)
                if _crosses(points, u, v, c1, d1, work):
                    tail = (head + count) % queue.shape[0]
                    queue[tail, 0] = c1
                    queue[tail, 1] = d1
                    count += 1
            else:
                tail = (head + count) % queue.shape[0]
                queue[tail, 0] = x
                queue[tail, 1] = y
                count += 1
        if count > 0:
            failed += 1
    return failed


@numba.njit(cache=True)
def _is_constraint(keys, n, a, b):
    key = min(a, b) * n + max(a, b)
    i = np.searchsorted(keys, key)
    return i < keys.shape[0] and keys[i] == key


@numba.njit(cache=True)
def make_delaunay(points, cells, neighbors, keys):
    """Lawson flips until every edge that is not a constraint (nor on the boundary) is locally Delaunay."""
    work = np.empty(_WORK_SIZE)
    n = points.shape[0]
    vcell = np.zeros(n, dtype=np.int64)
    total = 0
    for _ in range(1000):
        flips = 0
        for t in range(cells.shape[0]):
            for k in range(3):
                t2 = neighbors[t, k]
                if t2 < 0:
                    continue
                u = cells[t, (k + 1) % 3]
                v = cells[t, (k + 2) % 3]
                if keys.shape[0] and _is_constraint(keys, n, u, v):
                    continue
                j = 0
                while neighbors[t2, j] != t:
                    j += 1
                if _incircle(points, cells[t, 0], cells[t, 1], cells[t, 2], cells[t2, j], work) > 0.0:
                    _flip(cells, neighbors, vcell, t, k)
                    flips += 1
                    break
        total += flips
        if flips == 0:
            break
    return total


@numba.njit(cache=True)
def _legalize(points, cells, neighbors, vcell, stack, top, work):
    """Lawson flips around a new point, which is corner 0 of every stacked cell."""
    while top > 0:
        top -= 1
        t1 = stack[top]
        t2 = neighbors[t1, 0]
        if t2 < 0:
            continue
        j = 0
        while neighbors[t2, j] != t1:
            j += 1
        if _incircle(points, cells[t1, 0], cells[t1, 1], cells[t1, 2], cells[t2, j], work) <= 0.0:
            continue
        t2 = _flip(cells, neighbors, vcell, t1, np.int64(0))
        if top + 2 > stack.shape[0]:
            stack = grown(stack, 2 * stack.shape[0] + 2, 0)
        stack[top] = t1
        stack[top + 1] = t2
        top += 2
    return stack


@numba.njit(cache=True)
def insert_points(points, n_points, cells, n_cells, neighbors, where, new):
    """Insert ``new[i]`` into cell ``where[i]`` when it still lies strictly inside it; then restore Delaunay.

    ``points``, ``cells`` and ``neighbors`` have room for the new entries;
    returns the new counts.
    """
    work = np.empty(_WORK_SIZE)
    vcell = np.zeros(points.shape[0], dtype=np.int64)
    stack = np.empty(64, dtype=np.int64)
    for i in range(new.shape[0]):
        t = where[i]
        a = cells[t, 0]
        b = cells[t, 1]
        c = cells[t, 2]
        points[n_points, 0] = new[i, 0]
        points[n_points, 1] = new[i, 1]
        p = n_points
        if _orient(points, a, b, p, work) <= 0.0 or _orient(points, b, c, p, work) <= 0.0:
            continue
        if _orient(points, c, a, p, work) <= 0.0:
            continue
        n_points += 1
        m = n_cells
        m1 = n_cells + 1
        n_cells += 2
        across_bc = neighbors[t, 0]
        across_ca = neighbors[t, 1]
        across_ab = neighbors[t, 2]
        cells[t, 0], cells[t, 1], cells[t, 2] = p, b, c
        neighbors[t, 0], neighbors[t, 1], neighbors[t, 2] = across_bc, m, m1
        cells[m, 0], cells[m, 1], cells[m, 2] = p, c, a
        neighbors[m, 0], neighbors[m, 1], neighbors[m, 2] = across_ca, m1, t
        cells[m1, 0], cells[m1, 1], cells[m1, 2] = p, a, b
        neighbors[m1, 0], neighbors[m1, 1], neighbors[m1, 2] = across_ab, t, m
        _replace(neighbors, across_ca, t, m)
        _replace(neighbors, across_ab, t, m1)
        stack[0] = t
        stack[1] = m
        stack[2] = m1
        stack = _legalize(points, cells, neighbors, vcell, stack, np.int64(3), work)
    return n_points, n_cells


@numba.njit(cache=True)
def split_boundary_edges(points, n_points, cells, n_cells, neighbors, edges, new):
    """Split boundary edge ``edges[i] = (cell, corner, u, v)`` at ``new[i]``, then restore Delaunay.

    ``u -> v`` is the edge of ``cell`` opposite ``corner``; an edge changed
    by an earlier split or flip is left alone. Returns the new counts.
    """
    work = np.empty(_WORK_SIZE)
    vcell = np.zeros(points.shape[0], dtype=np.int64)
    stack = np.empty(64, dtype=np.int64)
    for i in range(edges.shape[0]):
        t = edges[i, 0]
        k = edges[i, 1]
        u = edges[i, 2]
        v = edges[i, 3]
        if neighbors[t, k] >= 0 or cells[t, (k + 1) % 3] != u or cells[t, (k + 2) % 3] != v:
            continue
        p = cells[t, k]
        m = n_points
        points[m, 0] = new[i, 0]
        points[m, 1] = new[i, 1]
        if _orient(points, m, v, p, work) <= 0.0 or _orient(points, m, p, u, work) <= 0.0:
            continue
        n_points += 1
        s = n_cells
        n_cells += 1
        across_vp = neighbors[t, (k + 1) % 3]
        across_pu = neighbors[t, (k + 2) % 3]
        cells[t, 0], cells[t, 1], cells[t, 2] = m, v, p
        neighbors[t, 0], neighbors[t, 1], neighbors[t, 2] = across_vp, s, -1
        cells[s, 0], cells[s, 1], cells[s, 2] = m, p, u
        neighbors[s, 0], neighbors[s, 1], neighbors[s, 2] = across_pu, -1, t
        _replace(neighbors, across_pu, t, s)
        stack[0] = t
        stack[1] = s
        stack = _legalize(points, cells, neighbors, vcell, stack, np.int64(2), work)
    return n_points, n_cells
