"""The decimation kernel of :func:`terramesh.coastal.enforce_timestep`: remove one vertex per star, fill the hole.

Private: ``xy`` (n, 2) float64 vertex coordinates, vertices and cells as
int64 vertex numbers; unvalidated. Each hole gets the triangulation that
maximises its worst triangle quality (guide eq. 1), by dynamic programming
over its sub-polygons.
"""

import numpy as np
from numba import njit


@njit(cache=True)
def _cross(xy, o, a, b):  # pragma: no cover - compiled
    """Twice the signed area of triangle (o, a, b)."""
    return (xy[a, 0] - xy[o, 0]) * (xy[b, 1] - xy[o, 1]) - (xy[a, 1] - xy[o, 1]) * (xy[b, 0] - xy[o, 0])


@njit(cache=True)
def _quality(xy, a, b, c):  # pragma: no cover - compiled
    """Guide eq. 1: ``4 sqrt(3) A / (l1^2 + l2^2 + l3^2)``."""
    squared = 0.0
    for p, q in ((a, b), (b, c), (c, a)):
        squared += (xy[q, 0] - xy[p, 0]) ** 2 + (xy[q, 1] - xy[p, 1]) ** 2
    if squared <= 0.0:
        return 0.0
    return 2.0 * np.sqrt(3.0) * _cross(xy, a, b, c) / squared


@njit(cache=True)
def _left(xy, a, b, c, eps):  # pragma: no cover - compiled
    """``c`` strictly left of the directed line ``a -> b``."""
    return _cross(xy, a, b, c) > eps


@njit(cache=True)
def _left_on(xy, a, b, c, eps):  # pragma: no cover - compiled
    """``c`` left of or on the directed line ``a -> b``."""
    return _cross(xy, a, b, c) >= -eps


@njit(cache=True)
def _in_cone(xy, ring, i, j, eps):  # pragma: no cover - compiled
    """The segment ``ring[i] -> ring[j]`` leaves ``ring[i]`` into the polygon's interior (O'Rourke's InCone)."""
    m = len(ring)
    a, b = ring[i], ring[j]
    a0, a1 = ring[(i - 1) % m], ring[(i + 1) % m]
    if _left_on(xy, a, a1, a0, eps):  # convex corner
        return _left(xy, a, b, a0, eps) and _left(xy, b, a, a1, eps)
    return not (_left_on(xy, a, b, a1, eps) and _left_on(xy, b, a, a0, eps))


@njit(cache=True)
def _crosses(xy, a, b, c, d, eps):  # pragma: no cover - compiled
    """Segments ``a-b`` and ``c-d`` meet anywhere (touching included)."""
    d1, d2 = _cross(xy, a, b, c), _cross(xy, a, b, d)
    d3, d4 = _cross(xy, c, d, a), _cross(xy, c, d, b)
    if ((d1 > eps and d2 < -eps) or (d1 < -eps and d2 > eps)) and (
        (d3 > eps and d4 < -eps) or (d3 < -eps and d4 > eps)
    ):
        return True
    # a point on the other segment (collinear within eps)
    for p, q, r, dist in ((a, b, c, d1), (a, b, d, d2), (c, d, a, d3), (c, d, b, d4)):
        if abs(dist) <= eps:
            lo_x, hi_x = min(xy[p, 0], xy[q, 0]), max(xy[p, 0], xy[q, 0])
            lo_y, hi_y = min(xy[p, 1], xy[q, 1]), max(xy[p, 1], xy[q, 1])
            if lo_x <= xy[r, 0] <= hi_x and lo_y <= xy[r, 1] <= hi_y:
                return True
    return False


@njit(cache=True)
def _diagonal(xy, ring, i, j, eps):  # pragma: no cover - compiled
    """``ring[i] - ring[j]`` is a diagonal of the simple polygon ``ring`` (inside it, crossing no side)."""
    m = len(ring)
    if not (_in_cone(xy, ring, i, j, eps) and _in_cone(xy, ring, j, i, eps)):
        return False
    for s in range(m):
        t = (s + 1) % m
        if s == i or s == j or t == i or t == j:
            continue
        if _crosses(xy, ring[i], ring[j], ring[s], ring[t], eps):
            return False
    return True


@njit(cache=True)
def _triangulate(xy, ring, eps, min_quality, out, k):  # pragma: no cover - compiled
    """Triangulate a counter-clockwise simple polygon into ``out[k:]``, maximising its worst triangle quality.

    Dynamic programming over the sub-polygons ``ring[i..j]`` (O(m^3)
    triangles, O(m) per diagonal test; ``m`` is a vertex's valence here).
    Returns the new ``k``, or -1 when the polygon has no triangulation whose
    worst quality reaches ``min_quality`` (or is not simple).
    """
    m = len(ring)
    for i in range(m):
        for j in range(i + 1, m):
            if ring[i] == ring[j]:
                return -1
    valid = np.zeros((m, m), dtype=np.bool_)
    for i in range(m):
        for j in range(i + 1, m):
            if j == i + 1 or (i == 0 and j == m - 1):
                valid[i, j] = True
            else:
                valid[i, j] = _diagonal(xy, ring, i, j, eps)
    best = np.full((m, m), -1.0)
    split = np.full((m, m), -1, dtype=np.int64)
    for i in range(m - 1):
        best[i, i + 1] = np.inf
    for span in range(2, m):
        for i in range(m - span):
            j = i + span
            if not valid[i, j]:
                continue
            for c in range(i + 1, j):
                if not (valid[i, c] and valid[c, j]) or best[i, c] < 0 or best[c, j] < 0:
                    continue
                if _cross(xy, ring[i], ring[c], ring[j]) <= eps:
                    continue
                worst = min(best[i, c], best[c, j], _quality(xy, ring[i], ring[c], ring[j]))
                if worst > best[i, j]:
                    best[i, j], split[i, j] = worst, c
    if best[0, m - 1] < min_quality:
        return -1
    stack = np.empty((2 * m, 2), dtype=np.int64)
    stack[0, 0], stack[0, 1] = 0, m - 1
    top = 1
    while top:
        top -= 1
        i, j = stack[top, 0], stack[top, 1]
        if j - i < 2:
            continue
        c = split[i, j]
        out[k, 0], out[k, 1], out[k, 2] = ring[i], ring[c], ring[j]
        k += 1
        stack[top, 0], stack[top, 1] = i, c
        stack[top + 1, 0], stack[top + 1, 1] = c, j
        top += 2
    return k


@njit(cache=True)
def fill_stars(vertices, starts, a, b, is_boundary, corner_free, xy, min_quality):  # pragma: no cover - compiled
    """Remove each vertex of ``vertices`` and re-triangulate the hole its star leaves.

    ``a[s:e], b[s:e]`` (``s, e = starts[i], starts[i + 1]``) are the other two
    corners of the cells around ``vertices[i]``, each cell ``(v, a, b)``
    counter-clockwise. Interior vertex: the link ``a -> b`` is a cycle, the
    hole is the polygon of the link. Boundary vertex: the link is a path
    ``u0 .. uk`` and the hole is closed by the chord ``uk -> u0``; it is
    only tried where ``corner_free[i]``: no other vertex lies in the
    triangle ``(uk, v, u0)``, so the hole is a simple polygon.

    Returns ``accepted`` (bool per vertex) and the new cells, shape (k, 3).
    """
    n_sel = len(vertices)
    out = np.empty((max(len(a), 1), 3), dtype=np.int64)
    accepted = np.zeros(n_sel, dtype=np.bool_)
    k = np.int64(0)
    for i in range(n_sel):
        s, e = starts[i], starts[i + 1]
        d = e - s
        v = vertices[i]
        boundary = is_boundary[v]
        # link order
        start = a[s]
        if boundary:
            found = 0
            for j in range(s, e):
                in_b = False
                for q in range(s, e):
                    if b[q] == a[j]:
                        in_b = True
                        break
                if not in_b:
                    start = a[j]
                    found += 1
            if found != 1:
                continue
        size = d + 1 if boundary else d
        polygon = np.empty(size, dtype=np.int64)
        polygon[0] = start
        current = start
        ok = True
        for step in range(1, size + (0 if boundary else 1)):
            nxt = -1
            for j in range(s, e):
                if a[j] == current:
                    nxt = b[j]
                    break
            if nxt < 0:
                ok = False
                break
            if step == size:  # interior: the cycle must close here
                ok = nxt == start
                break
            polygon[step] = nxt
            current = nxt
        if not ok:
            continue
        # a scale for the orientation tolerance: the polygon's extent
        x0, x1, y0, y1 = xy[v, 0], xy[v, 0], xy[v, 1], xy[v, 1]
        for q in polygon:
            x0, x1 = min(x0, xy[q, 0]), max(x1, xy[q, 0])
            y0, y1 = min(y0, xy[q, 1]), max(y1, xy[q, 1])
        eps = 1e-12 * max(x1 - x0, y1 - y0) ** 2
        if boundary:
            if not corner_free[i] or polygon[0] == polygon[size - 1]:
                continue
            if d == 1:  # one cell: delete it
                accepted[i] = True
                continue
        new_k = _triangulate(xy, polygon, eps, min_quality, out, k)
        if new_k < 0:
            continue
        k = new_k
        accepted[i] = True
    return accepted, out[:k].copy()
