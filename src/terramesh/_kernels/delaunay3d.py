"""Incremental 3D Delaunay tetrahedralisation (Bowyer-Watson) and kernels on tetrahedra.

Two kernels from one code: with plain floating-point predicates (the
quick one; the cavity of each new point is grown until the point sees all
its faces, so the result is a valid tetrahedralisation of points in
general position, only nearly Delaunay where rounding misjudges
near-cospherical points), and with exact ones (a filter with Shewchuk's
error bounds, then exact arithmetic on expansions), which numba compiles
when a workspace is passed instead of None. The quick kernel reports a
flat cell or a point in no cell, and the public wrapper, which validates,
scales the points, orders them along a Z-order curve, runs the exact
kernel then and falls back on SciPy's Qhull, is
:func:`terramesh.generation.triangulate.delaunay_3d`.

Layout: ``cells`` (m, 4) int64 positively oriented
(``(b - a) . ((c - a) x (d - a)) > 0``); ``neighbors`` (m, 4) int64,
``neighbors[c, k]`` is the cell across the face opposite corner ``k``, -1 on
the boundary. Also here: the kernels the 3D generator runs on such cells
(unique edges, boundary vertices and fans, the quality mean and spread,
exact duplicate points).
"""

import numba
import numpy as np

from .arrays import grown
from .expansions import EPSILON, difference, expansion_sum, minor, multiply, negate, sum_of_products
from .topology import vertex_cells

STATUS_OK = 0
_WALK_FAILED = 1
_CAVITY_FAILED = 2
_DOUBTFUL = 3  # a real point in no real cell, or a cell not surely positive: decide again, exactly


# Corner pairs: _OTHER_CORNERS[i, k] are the two corners of a cell other than i and k (i != k).
_OTHER_CORNERS = np.array(
    [[[j for j in range(4) if j != i and j != k] if i != k else [0, 0] for k in range(4)] for i in range(4)],
    dtype=np.int64,
)
# Status of a cavity search (_cavity_faces) besides a face count.
_FACES_FULL = -1
_HULL_FACE_HIDDEN = -2


@numba.njit(cache=True, inline="always")
def orient3d(points, a, b, c, d):
    """Six times the signed volume of ``(a, b, c, d)``: positive when ``d`` sees ``a, b, c`` counter-clockwise."""
    # unsigned indices spare numba's wrap-around of negative ones (a few per cent of a tetrahedralisation);
    # every caller passes vertex numbers, never -1
    a, b, c, d = np.uint64(a), np.uint64(b), np.uint64(c), np.uint64(d)
    bx, by, bz = _less(points, b, a)
    cx, cy, cz = _less(points, c, a)
    dx, dy, dz = _less(points, d, a)
    return bx * (cy * dz - cz * dy) - by * (cx * dz - cz * dx) + bz * (cx * dy - cy * dx)


# --- exact predicates ------------------------------------------------------------------------
# The signs of orient and insphere are exact: a floating-point evaluation with Shewchuk's
# static error bound decides nearly every case; the rest (cospherical points of a lattice,
# points on a face) are evaluated exactly with floating-point expansions. Exact signs keep a
# walk from cycling and a cavity star-shaped: no cavity swallows a vertex and no cell is flat. (A
# point on the hull can still end in cells of the enclosing tetrahedron alone; then Qhull.)

_ORIENT_BOUND = (7.0 + 56.0 * EPSILON) * EPSILON  # |float det - det| <= bound * permanent
_INSPHERE_BOUND = (16.0 + 224.0 * EPSILON) * EPSILON
# the workspace: first the bounds of the quick tests, which hold for cells of real points alone (whose
# coordinates differ by at most the points' extent), then scratch for the exact evaluations, carved into
# fixed slices (see _insphere_exact)
_ORIENT_SURE = 0
_INSPHERE_SURE = 1
_EXACT = 2
_WORK_SIZE = 93_940


@numba.njit(cache=True, inline="always")
def _less(points, u, origin):
    """``points[u] - points[origin]`` in floating point, as three numbers."""
    return points[u, 0] - points[origin, 0], points[u, 1] - points[origin, 1], points[u, 2] - points[origin, 2]


@numba.njit(cache=True)
def _differences(points, corners, origin, out, lengths):
    """``points[corners] - points[origin]`` exactly, two components per coordinate, and their lengths."""
    for i in range(len(corners)):
        for axis in range(3):
            k = 3 * i + axis
            lengths[k] = difference(points[corners[i], axis], points[origin, axis], out[2 * k : 2 * k + 2])


@numba.njit(cache=True)
def _orient_exact(points, a, b, c, d, work):
    """:func:`orient3d` exactly, as the last (largest) component of an expansion."""
    # u, v, w = b - a, c - a, d - a; det = ux (vy wz - vz wy) + uy (vz wx - vx wz) + uz (vx wy - vy wx)
    uvw = work[0:18]
    n = np.empty(9, dtype=np.int64)
    _differences(points, (b, c, d), a, uvw, n)
    scratch = work[18:46]
    yz = work[46:62]
    zx = work[62:78]
    xy = work[78:94]
    yzl = minor(uvw[8:10], n[4], uvw[16:18], n[8], uvw[10:12], n[5], uvw[14:16], n[7], yz, scratch, True)
    zxl = minor(uvw[10:12], n[5], uvw[12:14], n[6], uvw[6:8], n[3], uvw[16:18], n[8], zx, scratch, True)
    xyl = minor(uvw[6:8], n[3], uvw[14:16], n[7], uvw[8:10], n[4], uvw[12:14], n[6], xy, scratch, True)
    det = work[94:286]
    length = sum_of_products(
        uvw[0:2], n[0], yz, yzl, uvw[2:4], n[1], zx, zxl, uvw[4:6], n[2], xy, xyl, det, work[286:678]
    )
    return det[length - 1]


@numba.njit(cache=True)
def _insphere_exact(points, a, b, c, d, e, work):
    """:func:`insphere`'s determinant exactly, as the last (largest) component of an expansion."""
    # the corners less e: x, y, z of a, then of b, c and d, two components each
    diff = work[0:24]
    n = np.empty(12, dtype=np.int64)
    _differences(points, (a, b, c, d), e, diff, n)
    scratch = work[24:52]
    # the six minors (first x)(second y) - (second x)(first y) of the pairs ab, bc, cd, da, ac, bd
    minors = work[52:148]
    minor_lengths = np.empty(6, dtype=np.int64)
    pairs = ((0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3))
    for m in range(6):
        i, j = pairs[m]
        minor_lengths[m] = minor(
            diff[6 * i : 6 * i + 2], n[3 * i], diff[6 * j + 2 : 6 * j + 4], n[3 * j + 1],
            diff[6 * j : 6 * j + 2], n[3 * j], diff[6 * i + 2 : 6 * i + 4], n[3 * i + 1],
            minors[16 * m : 16 * m + 16], scratch, True,
        )  # fmt: skip
    # abc = az bc - bz ac + cz ab, bcd = bz cd - cz bd + dz bc, cda = cz da + dz ac + az cd,
    # dab = dz ab + az bd + bz da: the corners whose z multiplies, the minors, the minors' signs
    corners = ((0, 1, 2), (1, 2, 3), (2, 3, 0), (3, 0, 1))
    which = ((1, 4, 0), (2, 5, 1), (3, 4, 2), (0, 5, 3))
    signs = ((1.0, -1.0, 1.0), (1.0, -1.0, 1.0), (1.0, 1.0, 1.0), (1.0, 1.0, 1.0))
    volumes = work[148:916]  # 192 components each
    volume_lengths = np.empty(4, dtype=np.int64)
    signed = work[916:964]
    for v in range(4):
        for k in range(3):
            m = which[v][k]
            for i in range(minor_lengths[m]):
                signed[16 * k + i] = signs[v][k] * minors[16 * m + i]
        i, j, k = corners[v]
        volume_lengths[v] = sum_of_products(
            diff[6 * i + 4 : 6 * i + 6], n[3 * i + 2], signed[0:16], minor_lengths[which[v][0]],
            diff[6 * j + 4 : 6 * j + 6], n[3 * j + 2], signed[16:32], minor_lengths[which[v][1]],
            diff[6 * k + 4 : 6 * k + 6], n[3 * k + 2], signed[32:48], minor_lengths[which[v][2]],
            volumes[192 * v : 192 * v + 192], work[964:1356],
        )  # fmt: skip
    # det = alift bcd - blift cda + clift dab - dlift abc: each corner's lift with the next volume
    lift = work[1356:1380]
    product = work[1380:10596]
    spare = work[10596:19812]
    term = work[19812:20196]
    total = work[20196:57060]
    other = work[57060:93924]
    squares = work[93924:93940]
    total_length = 0
    for corner in range(4):
        x = diff[6 * corner : 6 * corner + 2]
        y = diff[6 * corner + 2 : 6 * corner + 4]
        z = diff[6 * corner + 4 : 6 * corner + 6]
        xl, yl, zl = n[3 * corner], n[3 * corner + 1], n[3 * corner + 2]
        square_length = minor(x, xl, x, xl, y, yl, y, yl, squares, scratch, False)
        last_length = multiply(z, zl, z, zl, scratch[0:8], scratch[8:16], scratch[16:20])
        lift_length = expansion_sum(squares, square_length, scratch[0:8], last_length, lift)
        v = (corner + 1) % 4
        length = multiply(volumes[192 * v :], volume_lengths[v], lift, lift_length, product, spare, term)
        if corner % 2 == 1:
            negate(product, length)
        total_length = expansion_sum(total, total_length, product, length, other)
        total[:total_length] = other[:total_length]
    return total[total_length - 1]


@numba.njit(cache=True)
def _orient_slow(points, a, b, c, d, det, work):
    """:func:`orient` where its quick test could not vouch for ``det``, its floating-point value.

    Out of line, so that the callers of the quick test stay small: Shewchuk's
    error bound on this cell's own permanent, then the exact value.
    """
    bx, by, bz = _less(points, b, a)
    cx, cy, cz = _less(points, c, a)
    dx, dy, dz = _less(points, d, a)
    permanent = abs(bx) * (abs(cy * dz) + abs(cz * dy))
    permanent += abs(by) * (abs(cx * dz) + abs(cz * dx))
    permanent += abs(bz) * (abs(cx * dy) + abs(cy * dx))
    if abs(det) > _ORIENT_BOUND * permanent:
        return det
    return _orient_exact(points, a, b, c, d, work[_EXACT:])


@numba.njit(cache=True)
def _insphere_slow(points, a, b, c, d, e, det, work):
    """:func:`insphere` where its quick test could not vouch for ``det``: the cell's own bound, then exactly."""
    ax, ay, az = _less(points, a, e)
    bx, by, bz = _less(points, b, e)
    cx, cy, cz = _less(points, c, e)
    dx, dy, dz = _less(points, d, e)
    ab = abs(ax * by) + abs(bx * ay)
    bc = abs(bx * cy) + abs(cx * by)
    cd = abs(cx * dy) + abs(dx * cy)
    da = abs(dx * ay) + abs(ax * dy)
    ac = abs(ax * cy) + abs(cx * ay)
    bd = abs(bx * dy) + abs(dx * by)
    alift = ax * ax + ay * ay + az * az
    blift = bx * bx + by * by + bz * bz
    clift = cx * cx + cy * cy + cz * cz
    dlift = dx * dx + dy * dy + dz * dz
    permanent = (abs(bz) * cd + abs(cz) * bd + abs(dz) * bc) * alift
    permanent += (abs(cz) * da + abs(dz) * ac + abs(az) * cd) * blift
    permanent += (abs(dz) * ab + abs(az) * bd + abs(bz) * da) * clift
    permanent += (abs(az) * bc + abs(bz) * ac + abs(cz) * ab) * dlift
    if abs(det) > _INSPHERE_BOUND * permanent:
        return det
    return _insphere_exact(points, a, b, c, d, e, work[_EXACT:])


@numba.njit(cache=True)
def _quick_bounds(points):
    """The quick tests' bounds on ``points`` (the last four enclose the rest): ``(orient, insphere)``.

    No coordinate difference between real points exceeds their extent, so no
    permanent of a cell of real points exceeds 6 extent**3 (orient) or 72
    extent**5 (insphere); the margin covers the rounding of these bounds.
    """
    extent = 0.0
    for axis in range(3):
        low = np.inf
        high = -np.inf
        for i in range(points.shape[0] - 4):
            low = min(low, points[i, axis])
            high = max(high, points[i, axis])
        extent = max(extent, high - low)
    return 1.01 * _ORIENT_BOUND * 6.0 * extent**3, 1.01 * _INSPHERE_BOUND * 72.0 * extent**5


@numba.njit(cache=True)
def bowyer_watson_workspace(points):
    """Scratch for the predicates on ``points`` (the last four enclose the rest): the quick tests' bounds first."""
    work = np.empty(_EXACT + _WORK_SIZE)
    work[_ORIENT_SURE], work[_INSPHERE_SURE] = _quick_bounds(points)
    return work


@numba.njit(cache=True, inline="always")
def orient(points, a, b, c, d, work):
    """:func:`orient3d` with an exact sign (0 exactly when coplanar); the magnitude is approximate."""
    a, b, c, d = np.uint64(a), np.uint64(b), np.uint64(c), np.uint64(d)
    det = orient3d(points, a, b, c, d)
    if work is None:  # the floating-point kernel
        return det
    n = np.uint64(points.shape[0] - 4)
    if abs(det) > work[_ORIENT_SURE] and a < n and b < n and c < n and d < n:
        return det
    return _orient_slow(points, a, b, c, d, det, work)


@numba.njit(cache=True, inline="always")
def insphere(points, a, b, c, d, e, work):
    """Positive when ``e`` lies inside the circumsphere of the positively oriented ``(a, b, c, d)``.

    The sign is exact (0 exactly when the five points are cospherical); the
    magnitude approximate.
    """
    a, b, c, d, e = np.uint64(a), np.uint64(b), np.uint64(c), np.uint64(d), np.uint64(e)
    ax, ay, az = _less(points, a, e)
    bx, by, bz = _less(points, b, e)
    cx, cy, cz = _less(points, c, e)
    dx, dy, dz = _less(points, d, e)
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
    det = (alift * bcd - blift * cda) + (clift * dab - dlift * abc)
    if work is None:
        return det
    n = np.uint64(points.shape[0] - 4)
    if abs(det) > work[_INSPHERE_SURE] and a < n and b < n and c < n and d < n:
        return det
    return _insphere_slow(points, a, b, c, d, e, det, work)


@numba.njit(cache=True, inline="always")
def _orient_replaced(points, tets, t, k, p, work):
    """Orientation of cell ``t`` with its corner ``k`` replaced by point ``p``.

    Measured from ``p`` (the corners' order changed to put it first, the
    sign kept), not from the cell's first corner: that corner may be one of
    the enclosing tetrahedron's, 10**4 away, and differences from it carry
    rounding errors of 10**-4 in the determinant. The two cells across a
    face then disagreed on the side ``p`` lies on, and the walk to ``p``
    went back and forth between them (on a box whose edge is the line
    ``x = y`` of the scaled points through an enclosing corner).
    """
    if k == 0:
        return orient(points, p, tets[t, 1], tets[t, 2], tets[t, 3], work)
    if k == 1:
        return -orient(points, p, tets[t, 0], tets[t, 2], tets[t, 3], work)
    if k == 2:
        return -orient(points, p, tets[t, 1], tets[t, 0], tets[t, 3], work)
    return -orient(points, p, tets[t, 1], tets[t, 2], tets[t, 0], work)


# The insertion runs in phases, each its own function: numba keeps the arrays of a function
# that never reassigns them in registers, where one function growing arrays in its loop
# reloads them from the stack at every access (a fifth of the time of a tetrahedralisation).


@numba.njit(cache=True)
def _locate(points, tets, neighbors, alive, n_used, start, p, generator, work):
    """The cell that contains point ``p``, by a visibility walk from cell ``start``.

    The face tried first in each cell follows the pseudo-random sequence
    ``generator`` (a linear congruential state), so that the walk cannot
    cycle. Should rounding make it cycle anyway (nearly coplanar points),
    :func:`_best_cell` searches every live cell.

    Returns
    -------
    cell : int
        -1 when the search finds no live cell.
    generator : int
        The state after the walk.
    """
    t = start
    walked = 0
    while True:
        rotation = (generator >> 16) & 3
        moved = False
        for kk in range(4):
            k = (kk + rotation) & 3
            if _orient_replaced(points, tets, t, k, p, work) < 0.0:
                t = neighbors[t, k]
                moved = True
                break
        generator = (generator * 1103515245 + 12345) & 0x7FFFFFFF
        if not moved:
            return t, generator
        walked += 1
        if walked > 1000 or t < 0:
            return _best_cell(points, tets, alive, n_used, p, work), generator


@numba.njit(cache=True)
def _best_cell(points, tets, alive, n_used, p, work):
    """The live cell whose smallest barycentric coordinate of ``p`` is the largest: the one holding ``p``.

    Or the one nearest to holding it, should rounding put ``p`` just outside
    every cell (a point on a face). Barycentric coordinates, not the
    orientations they are made of: those scale with each cell's volume, and
    a small cell far away, with ``p`` slightly behind one face, would win
    over the large cell with ``p`` on its face (a hole of 1,773 points in a
    box less a ball). -1 when no cell is live.
    """
    best_cell = -1
    best = -np.inf
    for c in range(n_used):
        if not alive[c]:
            continue
        volume = orient3d(points, tets[c, 0], tets[c, 1], tets[c, 2], tets[c, 3])
        if volume <= 0.0:  # flat to rounding: no barycentric coordinates (and no division by zero)
            continue
        worst = np.inf
        for k in range(4):
            worst = min(worst, _orient_replaced(points, tets, c, k, p, work) / volume)
        if worst > best:
            best = worst
            best_cell = c
        if worst >= 0.0:
            break
    return best_cell


@numba.njit(cache=True)
def _conflict_cells(points, tets, neighbors, stamp, cavity, stack, t, p, step, work):
    """The cells whose circumsphere holds ``p``, connected to cell ``t`` (which contains it), by depth-first search.

    They are written to ``cavity`` and stamped ``step`` (``cavity`` and
    ``stack`` hold as many entries as ``tets``); returns their number.
    """
    outside = -2 - step  # tested and not in conflict: a cell next to several cavity cells is tested once
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
            if o >= 0 and stamp[o] != step and stamp[o] != outside:
                if insphere(points, tets[o, 0], tets[o, 1], tets[o, 2], tets[o, 3], p, work) > 0.0:
                    stamp[o] = step
                    cavity[n_cavity] = o
                    n_cavity += 1
                    stack[n_stack] = o
                    n_stack += 1
                else:
                    stamp[o] = outside
    return n_cavity


@numba.njit(cache=True)
def _cavity_faces(points, tets, neighbors, stamp, cavity, n_cavity, face_tet, face_corner, p, step, work):
    """The cavity's faces, grown until ``p`` sees every one from inside, as ``(face_tet, face_corner)`` pairs.

    Rounding can leave a face that ``p`` does not see strictly from inside
    it; the cell behind it then joins the cavity (appended to ``cavity``,
    stamped ``step``). Each cell is scanned once, in cavity order, so cells
    join in the order of a breadth-first search (rescanning a cell could add
    nothing), and a face recorded before the cell behind it joined is
    dropped at the end.

    Returns
    -------
    n_cavity : int
        Cells in the cavity now.
    n_faces : int
        Faces written, or _FACES_FULL when the face arrays ran out of room
        (grow them and call again: the cells added so far stay, and the
        search resumes as it would have gone on), or _HULL_FACE_HIDDEN
        when a face on the hull does not face ``p``.
    """
    n_faces = 0
    widened = False
    ci = 0
    while ci < n_cavity:
        c = cavity[ci]
        ci += 1
        for k in range(4):
            o = neighbors[c, k]
            if o >= 0 and stamp[o] == step:
                continue
            if _orient_replaced(points, tets, c, k, p, work) <= 0.0:
                if o < 0:
                    return n_cavity, _HULL_FACE_HIDDEN
                stamp[o] = step
                cavity[n_cavity] = o
                n_cavity += 1
                widened = True
                continue
            if n_faces == face_tet.shape[0]:
                return n_cavity, _FACES_FULL
            face_tet[n_faces] = c
            face_corner[n_faces] = k
            n_faces += 1
    if widened:
        kept = 0
        for f in range(n_faces):
            o = neighbors[face_tet[f], face_corner[f]]
            if o < 0 or stamp[o] != step:
                face_tet[kept] = face_tet[f]
                face_corner[kept] = face_corner[f]
                kept += 1
        n_faces = kept
    return n_cavity, n_faces


@numba.njit(cache=True)
def _swallows_vertex(tets, cavity, n_cavity, face_tet, face_corner, n_faces, seen, step):
    """Whether a corner of the cavity's cells lies on none of its faces: joining ``p`` to them would lose it.

    Exactly, a cavity holds no vertex inside it. Widened by rounding (see
    :func:`_cavity_faces`), it might: the point would vanish from the
    tetrahedralisation and leave a hole in the mesh. ``seen`` (one entry per
    point) is stamped ``step`` at the faces' corners.
    """
    for f in range(n_faces):
        for j in range(4):
            if j != face_corner[f]:
                seen[tets[face_tet[f], j]] = step
    for ci in range(n_cavity):
        for j in range(4):
            if seen[tets[cavity[ci], j]] != step:
                return True
    return False


@numba.njit(cache=True)
def _new_cells(
    tets, neighbors, alive, stamp, free, n_free, n_used, face_tet, face_corner, n_faces, p, step, table, n_all
):
    """Join ``p`` to every cavity face; returns ``(n_free, n_used, last)``, ``last`` the last cell made.

    Cells are taken from the top of the ``free`` stack, then past
    ``n_used`` (the arrays must have room for them). The faces through
    ``p`` are matched by their other edge, ``u * n_all + w`` with ``u < w``,
    in the open-addressing hash table ``table``: rows of (stamp, key,
    value), a power of two of them, at least 4 ``n_faces``.
    """
    mask = table.shape[0] - 1
    nt = -1
    for f in range(n_faces):
        if n_free > 0:
            n_free -= 1
            nt = free[n_free]
        else:
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
            u = tets[nt, _OTHER_CORNERS[i, k, 0]]
            w = tets[nt, _OTHER_CORNERS[i, k, 1]]
            if u > w:
                u, w = w, u
            key = u * n_all + w
            h = (key * 2654435761) & mask
            while True:
                if table[h, 0] != step:
                    table[h, 0] = step
                    table[h, 1] = key
                    table[h, 2] = 4 * nt + i
                    break
                if table[h, 1] == key:
                    other = table[h, 2] >> 2
                    neighbors[nt, i] = other
                    neighbors[other, table[h, 2] & 3] = nt
                    break
                h = (h + 1) & mask
    return n_free, n_used, nt


@numba.njit(cache=True)
def bowyer_watson(points, order, work):
    """Delaunay tetrahedra of ``points[:-4]`` inserted in ``order``; ``points[-4:]`` enclose them all.

    With ``work`` None the predicates are plain floating point (the quick
    kernel, whose exact twin numba compiles from the same code); with a
    :func:`bowyer_watson_workspace` of ``points`` their signs are exact. Returns
    ``(status, cells, neighbors, duplicate_of)``: positively oriented
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
    # a cavity can hold every cell: no check while it is searched
    cavity = np.empty(capacity, dtype=np.int64)
    stack = np.empty(capacity, dtype=np.int64)
    n_free = np.int64(0)
    n_used = np.int64(1)
    tets[0, 0] = n
    tets[0, 1] = n + 1
    tets[0, 2] = n + 2
    tets[0, 3] = n + 3
    if orient3d(points, n, n + 1, n + 2, n + 3) < 0:
        tets[0, 2] = n + 3
        tets[0, 3] = n + 2
    alive[0] = True
    face_tet = np.empty(512, dtype=np.int64)
    face_corner = np.empty(512, dtype=np.int64)
    table = np.full((4096, 3), -1, dtype=np.int64)
    duplicate_of = np.full(n, -1, dtype=np.int64)
    seen = np.full(n_all, -1, dtype=np.int64)
    last = np.int64(0)
    generator = np.int64(12345)
    for step in range(order.shape[0]):
        p = order[step]
        t, generator = _locate(points, tets, neighbors, alive, n_used, last, p, generator, work)
        if t < 0:
            return _WALK_FAILED, tets[:0], neighbors[:0], duplicate_of
        duplicate = -1
        for k in range(4):
            v = tets[t, k]
            if points[v, 0] == points[p, 0] and points[v, 1] == points[p, 1] and points[v, 2] == points[p, 2]:
                duplicate = v
        if duplicate >= 0:
            duplicate_of[p] = duplicate
            continue
        n_conflict = _conflict_cells(points, tets, neighbors, stamp, cavity, stack, t, p, step, work)
        n_cavity = n_conflict
        while True:
            n_cavity, n_faces = _cavity_faces(
                points, tets, neighbors, stamp, cavity, n_cavity, face_tet, face_corner, p, step, work
            )
            if n_faces == _HULL_FACE_HIDDEN:
                return _CAVITY_FAILED, tets[:0], neighbors[:0], duplicate_of
            if n_faces != _FACES_FULL:
                break
            face_tet = grown(face_tet, 2 * face_tet.shape[0], -1)
            face_corner = grown(face_corner, 2 * face_corner.shape[0], -1)
        if n_cavity > n_conflict and _swallows_vertex(
            tets, cavity, n_cavity, face_tet, face_corner, n_faces, seen, step
        ):
            return _CAVITY_FAILED, tets[:0], neighbors[:0], duplicate_of
        while 4 * n_faces > table.shape[0]:
            table = np.full((2 * table.shape[0], 3), -1, dtype=np.int64)
        if n_used + n_faces - n_free > tets.shape[0]:
            size = 2 * tets.shape[0]
            while n_used + n_faces - n_free > size:
                size *= 2
            tets = grown(tets, size, -1)
            neighbors = grown(neighbors, size, -1)
            alive = grown(alive, size, False)
            stamp = grown(stamp, size, -1)
            free = grown(free, size, -1)
            cavity = grown(cavity, size, -1)
            stack = grown(stack, size, -1)
        n_free, n_used, last = _new_cells(
            tets, neighbors, alive, stamp, free, n_free, n_used, face_tet, face_corner, n_faces, p, step, table, n_all
        )
        for ci in range(n_cavity):
            free[n_free] = cavity[ci]
            alive[cavity[ci]] = False
            n_free += 1
    renumber = np.full(n_used, -1, dtype=np.int64)
    count = 0
    used = duplicate_of >= 0
    status = STATUS_OK
    # a cell counts as positive when its orientation clears the rounding error (exactly, with work)
    positive = 0.0 if work is not None else _quick_bounds(points)[0]
    for t in range(n_used):
        if alive[t] and tets[t, 0] < n and tets[t, 1] < n and tets[t, 2] < n and tets[t, 3] < n:
            renumber[t] = count
            count += 1
            for j in range(4):
                used[tets[t, j]] = True
            if orient(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3], work) <= positive:
                status = _DOUBTFUL
    if not used.all():
        status = _DOUBTFUL
    cells = np.empty((count, 4), dtype=np.int64)
    cell_neighbors = np.empty((count, 4), dtype=np.int64)
    for t in range(n_used):
        r = renumber[t]
        if r >= 0:
            for j in range(4):
                cells[r, j] = tets[t, j]
                o = neighbors[t, j]
                cell_neighbors[r, j] = renumber[o] if o >= 0 else -1
    return status, cells, cell_neighbors, duplicate_of


# --- connectivity kernels ------------------------------------------------------------------------


@numba.njit(cache=True)
def tet_unique_edges(cells, n_points):
    """Every edge of the cells once, as (e, 2) vertex pairs ``(a, b)`` with ``a < b``, ordered by ``a``.

    Around each vertex, its cells in increasing order, their corners in
    order, with a stamp per vertex instead of sorting. The cells are first
    copied out per corner, grouped by vertex (a counting sort), so that the
    scan reads memory in order rather than jumping between cells.
    """
    m = cells.shape[0]
    start = np.zeros(n_points + 1, dtype=np.int64)
    for t in range(m):
        for k in range(4):
            start[cells[t, k] + 1] += 1
    for v in range(n_points):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    around = np.empty((start[n_points], 4), dtype=np.int64)  # the cells at vertex v: rows start[v]:start[v + 1]
    for t in range(m):
        for k in range(4):
            row = fill[cells[t, k]]
            fill[cells[t, k]] = row + 1
            for j in range(4):
                around[row, j] = cells[t, j]
    stamp = np.full(n_points, -1, dtype=np.int64)
    edges = np.empty((3 * m + n_points, 2), dtype=np.int64)  # room for the edges of a tetrahedralisation
    count = 0
    for v in range(n_points):
        for row in range(start[v], start[v + 1]):
            if count + 4 > edges.shape[0]:
                edges = grown(edges, 2 * edges.shape[0], -1)
            # without branches (whether a corner is new is a coin toss): every corner is written, and counted
            # when new; stamping a corner u <= v is harmless, as only corners above the vertex are read
            for k in range(4):
                u = around[row, k]
                edges[count, 0] = v
                edges[count, 1] = u
                count += (u > v) & (stamp[u] != v)
                stamp[u] = v
    return edges[:count].copy()


@numba.njit(cache=True)
def tet_quality_mean_std(points, cells, on_boundary):
    """Mean and standard deviation of ``6 sqrt(2) V / l_rms**3`` (1 for a regular tetrahedron).

    Cells with all four corners ``on_boundary`` (a boolean per point) are
    left out.
    """
    m = 0
    total = 0.0
    total2 = 0.0
    factor = 6.0 * np.sqrt(2.0) / 6.0
    for t in range(cells.shape[0]):
        a = cells[t, 0]
        if on_boundary[a] and on_boundary[cells[t, 1]] and on_boundary[cells[t, 2]] and on_boundary[cells[t, 3]]:
            continue
        m += 1
        squares = 0.0
        for i in range(3):
            for j in range(i + 1, 4):
                for d in range(3):
                    delta = points[cells[t, i], d] - points[cells[t, j], d]
                    squares += delta * delta
        six_volume = orient3d(points, a, cells[t, 1], cells[t, 2], cells[t, 3])
        rms = np.sqrt(squares / 6.0)
        q = factor * six_volume / (rms * rms * rms) if rms > 0.0 else 0.0
        total += q
        total2 += q * q
    mean = total / max(m, 1)
    return mean, np.sqrt(max(total2 / max(m, 1) - mean * mean, 0.0))


@numba.njit(cache=True)
def duplicate_points(points):
    """Points that coincide exactly with a point of lower index, as a boolean mask.

    One pass with an open-addressing hash table of the coordinates' bits
    (-0.0 counted as 0.0; NaN equals nothing), where sorting the points
    takes several times as long.
    """
    n = points.shape[0]
    coords = points + 0.0  # turns -0.0 into 0.0, which it equals
    bits = coords.view(np.uint64)
    log_size = 4
    while (1 << log_size) < 2 * n:
        log_size += 1
    mask = np.uint64((1 << log_size) - 1)
    table = np.full(1 << log_size, -1, dtype=np.int64)
    doomed = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        # multiplicative hashing (SplitMix64's constants), the top bits of the product
        mixed = bits[i, 0] * np.uint64(0x9E3779B97F4A7C15) ^ bits[i, 1] * np.uint64(0xBF58476D1CE4E5B9) ^ bits[i, 2]
        h = (mixed * np.uint64(0x94D049BB133111EB)) >> np.uint64(64 - log_size)
        while table[h] >= 0:
            j = table[h]
            if coords[j, 0] == coords[i, 0] and coords[j, 1] == coords[i, 1] and coords[j, 2] == coords[i, 2]:
                doomed[i] = True
                break
            h = (h + np.uint64(1)) & mask
        if not doomed[i]:
            table[h] = i
    return doomed


@numba.njit(cache=True)
def boundary_vertex_mask(tets, neighbors, alive, n_points):
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
def link_components(faces, n_points):
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
