"""Incremental 2D Delaunay triangulation with exact geometric predicates.

Points are inserted in Hilbert-curve order, so the walk that locates each
new point starts next to it. The containing cell is split in three (or the
two cells sharing an edge in four when the point lies exactly on that edge,
which lattices make common), and Lawson flips restore the Delaunay property.

The convex hull is closed by *ghost* cells: every hull edge ``a -> b`` (the
outside on its left) carries a cell ``(a, b, inf)`` whose third vertex is a
symbolic vertex at infinity, index ``n``. A point outside the hull lies in
a ghost cell; splitting it and flipping ghost edges while the new point sees
them keeps the hull exactly convex, with no enclosing triangle whose
position could cut off flat hull cells.

Orientation and in-circle signs are exact: a floating-point evaluation with
a static error bound (Shewchuk 1997, doi:10.1007/PL00009321) decides nearly
every case. Lattices bring the rest in numbers: exactly or nearly collinear
triples and cocircular quads. An orientation is then decided by the exact
determinant of the rounded coordinate differences (Shewchuk's second
stage, enough when the differences are exact); an in-circle test by exact
integer arithmetic when one power of two scales its coordinates to
integers of at most 58 bits, as it does for nearby points. What remains is
evaluated exactly with floating-point expansions (sums of non-overlapping
doubles), several times costlier. Exact signs make the flip
sequence terminate on cocircular lattices (an edge flips only when the
in-circle value is strictly positive) and make the output a valid
triangulation of the input as given. The arithmetic is exact as long as no
intermediate product overflows or underflows; the wrapper scales the
coordinates by a power of two (exact) so that overflow cannot happen.

Layout: ``cells`` (m, 3) int64 counter-clockwise; ``neighbors`` (m, 3)
int64, ``neighbors[c, k]`` is the cell across the edge opposite corner ``k``
(the edge ``cells[c, k+1], cells[c, k+2]``), -1 on the hull.
"""

import math

import numba
import numpy as np

from .arrays import copy_rows, count_below, grown
from .expansions import (
    EPSILON,
    difference,
    minor,
    product_difference,
    sum_of_products,
    two_sum,
)

# Shewchuk's first-stage bounds: |float det - det| <= bound * permanent
ORIENT_BOUND = (3.0 + 16.0 * EPSILON) * EPSILON
"""Error bound of the float orientation: trusted where ``|det| > ORIENT_BOUND * permanent``."""
_INCIRCLE_BOUND = (10.0 + 96.0 * EPSILON) * EPSILON
# second stage: |det of the rounded differences (rounded to a double) - det| <= bound * permanent
_ORIENT_BOUND_B = (2.0 + 12.0 * EPSILON) * EPSILON

# where the located point lies (see _locate)
INSIDE = 0
ON_EDGE = 1
OUTSIDE = 2
ON_VERTEX = 3

# kernel status codes
OK = 0
TOO_FEW_DISTINCT = 1
COLLINEAR = 2
WALK_FAILED = 3
NOT_VALID = 4
WRONG_SIZE = 5


# Exact evaluation scratch: one buffer, allocated once per triangulation and carved
# into fixed slices, because allocating per call made lattices (where near-zero
# in-circle values are common) several times slower.
WORK_SIZE = 6000
"""Length (float64 items) of the scratch buffer of the exact predicates (:func:`workspace`)."""
_SCAN_CELLS = 4096  # cells per task of the parallel scans (each task allocates its own predicate workspace)
_WALK_STEPS = 16  # a walk across a mesh of m cells costs about this many times sqrt(m) cells of a pass over them
_SEARCHED_DROPS = 64  # cells dropped at most for their neighbours' renumbering by binary search, not a table
_NO_STEP_LIMIT = 1 << 40  # a walk's step limit where the caller sets none


def workspace():
    """Scratch buffer for the exact predicates."""
    return np.empty(WORK_SIZE)


# --- predicates -----------------------------------------------------------------------------


@numba.njit(cache=True)
def _orient_exact(ax, ay, bx, by, cx, cy, work):
    # (ax - cx)(by - cy) - (ay - cy)(bx - cx), with every difference kept exactly
    acx = work[0:2]
    bcy = work[2:4]
    acy = work[4:6]
    bcx = work[6:8]
    acxlen = difference(ax, cx, acx)
    bcylen = difference(by, cy, bcy)
    acylen = difference(ay, cy, acy)
    bcxlen = difference(bx, cx, bcx)
    out = work[8:24]
    olen = minor(acx, acxlen, bcy, bcylen, acy, acylen, bcx, bcxlen, out, work[24:], np.True_)
    return out[olen - 1]


@numba.njit(cache=True)
def _orient_adaptive(ax, ay, bx, by, cx, cy, permanent, work):
    """The orientation sign where the floating-point filter could not decide it (Shewchuk's stage B).

    First the determinant of the rounded coordinate differences, exactly: the
    answer when the differences are exact, as they are between nearby points
    on lattices, where this stage meets exactly collinear triples; otherwise
    when it clears the rounding error of the differences. Else the full
    expansion arithmetic of :func:`_orient_exact`. ``permanent`` is
    ``|acx bcy| + |acy bcx|`` in floating point.
    """
    acx, acx_tail = two_sum(ax, -cx)
    bcx, bcx_tail = two_sum(bx, -cx)
    acy, acy_tail = two_sum(ay, -cy)
    bcy, bcy_tail = two_sum(by, -cy)
    det = work[0:4]
    detlen = product_difference(acx, bcy, acy, bcx, det)
    if acx_tail == 0.0 and bcx_tail == 0.0 and acy_tail == 0.0 and bcy_tail == 0.0:
        return det[detlen - 1]
    estimate = 0.0
    for i in range(detlen):
        estimate += det[i]
    if abs(estimate) >= _ORIENT_BOUND_B * permanent:
        return estimate
    return _orient_exact(ax, ay, bx, by, cx, cy, work)


@numba.njit(cache=True, inline="always")
def _corners(points, a, b, c):
    """The coordinates of points ``a, b, c``: ``ax, ay, bx, by, cx, cy``."""
    return points[a, 0], points[a, 1], points[b, 0], points[b, 1], points[c, 0], points[c, 1]


@numba.njit(cache=True, inline="always")
def orient(points, a, b, c, work):
    """Positive when ``a, b, c`` turn counter-clockwise, negative clockwise, 0 exactly when collinear.

    The magnitude is only approximate (twice the signed area, up to rounding);
    the sign is exact. ``work`` is a :func:`workspace`.
    """
    ax, ay, bx, by, cx, cy = _corners(points, a, b, c)
    left = (ax - cx) * (by - cy)
    right = (ay - cy) * (bx - cx)
    det = left - right
    # terms of opposite sign (or a zero term: a floating-point difference is zero only
    # between equal numbers, which lattice rows and columns make common) cannot cancel
    if left > 0.0:
        if right <= 0.0:
            return det
    elif left < 0.0:
        if right >= 0.0:
            return det
    else:
        return det
    permanent = abs(left) + abs(right)
    if abs(det) > ORIENT_BOUND * permanent:
        return det
    return _orient_adaptive(ax, ay, bx, by, cx, cy, permanent, work)


@numba.njit(cache=True)
def _incircle_exact(ax, ay, bx, by, cx, cy, dx, dy, work):
    adx = work[0:2]
    ady = work[2:4]
    bdx = work[4:6]
    bdy = work[6:8]
    cdx = work[8:10]
    cdy = work[10:12]
    adxlen = difference(ax, dx, adx)
    adylen = difference(ay, dy, ady)
    bdxlen = difference(bx, dx, bdx)
    bdylen = difference(by, dy, bdy)
    cdxlen = difference(cx, dx, cdx)
    cdylen = difference(cy, dy, cdy)
    scratch = work[12:40]
    # the three 2x2 minors and the three lifts |a - d|^2 etc., 16 components at most each
    bc = work[40:56]
    ca = work[56:72]
    ab = work[72:88]
    bclen = minor(bdx, bdxlen, cdy, cdylen, cdx, cdxlen, bdy, bdylen, bc, scratch, np.True_)
    calen = minor(cdx, cdxlen, ady, adylen, adx, adxlen, cdy, cdylen, ca, scratch, np.True_)
    ablen = minor(adx, adxlen, bdy, bdylen, bdx, bdxlen, ady, adylen, ab, scratch, np.True_)
    alift = work[88:104]
    blift = work[104:120]
    clift = work[120:136]
    alen = minor(adx, adxlen, adx, adxlen, ady, adylen, ady, adylen, alift, scratch, np.False_)
    blen = minor(bdx, bdxlen, bdx, bdxlen, bdy, bdylen, bdy, bdylen, blift, scratch, np.False_)
    clen = minor(cdx, cdxlen, cdx, cdxlen, cdy, cdylen, cdy, cdylen, clift, scratch, np.False_)
    # products of 16-component expansions: 512 components at most, 1,536 in the sum
    det = work[136:1672]
    detlen = sum_of_products(alift, alen, bc, bclen, blift, blen, ca, calen, clift, clen, ab, ablen, det, work[1672:])
    return det[detlen - 1]


# --- exact integer arithmetic --------------------------------------------------------------------
# Lattice points are nearby multiples of one small power of two, so an in-circle test
# among them is a polynomial in integers of some 50 bits. Evaluated exactly on integers
# split into 30-bit limbs it costs a fraction of the expansion arithmetic above; lattices
# make such tests common, as their cocircular and nearly cocircular quads defeat the
# floating-point filter.

_LIMB_BITS = 30
_LIMB_MASK = (1 << _LIMB_BITS) - 1
# Coordinates scaled to integers below 2^58 have differences below 2^59: two limbs, the upper
# one below 2^29 in magnitude. Minors and lifts are then below 2^119 (four limbs, the upper
# below 2^29), their products below 2^238 (eight), and no column of limb products (each at
# most 2^60, four at most) sums to 2^63.
_INTEGER_BITS = 58


@numba.njit(cache=True, inline="always")
def _scaled_integer(value, scale):
    """``value scale`` as an integer, and whether that is exact."""
    scaled = value * scale
    integer = int(scaled)
    # the comparison converts back exactly: below 2^53 any integer, beyond it any double is one
    return integer, integer == scaled


@numba.njit(cache=True, inline="always")
def _limb_product_sum(x, y, u, v, sign):
    """``x y + sign u v`` for integers below ``2^59`` in magnitude, as four limbs.

    Limbs are low first, each in ``[0, 2^30)`` but the last, which carries
    the sign (the carries are floor divisions): below ``2^29`` in magnitude.
    """
    x0, x1 = x & _LIMB_MASK, x >> _LIMB_BITS
    y0, y1 = y & _LIMB_MASK, y >> _LIMB_BITS
    u0, u1 = u & _LIMB_MASK, u >> _LIMB_BITS
    v0, v1 = v & _LIMB_MASK, v >> _LIMB_BITS
    c0 = x0 * y0 + sign * (u0 * v0)
    c1 = x1 * y0 + x0 * y1 + sign * (u1 * v0 + u0 * v1) + (c0 >> _LIMB_BITS)
    c2 = x1 * y1 + sign * (u1 * v1) + (c1 >> _LIMB_BITS)
    return c0 & _LIMB_MASK, c1 & _LIMB_MASK, c2 & _LIMB_MASK, c2 >> _LIMB_BITS


@numba.njit(cache=True, inline="always")
def _limb_product(a, b):
    """Product of two numbers of four limbs (as :func:`_limb_product_sum` makes them), as eight limbs."""
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    c0 = a0 * b0
    c1 = a0 * b1 + a1 * b0 + (c0 >> _LIMB_BITS)
    c2 = a0 * b2 + a1 * b1 + a2 * b0 + (c1 >> _LIMB_BITS)
    c3 = a0 * b3 + a1 * b2 + a2 * b1 + a3 * b0 + (c2 >> _LIMB_BITS)
    c4 = a1 * b3 + a2 * b2 + a3 * b1 + (c3 >> _LIMB_BITS)
    c5 = a2 * b3 + a3 * b2 + (c4 >> _LIMB_BITS)
    c6 = a3 * b3 + (c5 >> _LIMB_BITS)
    return (
        c0 & _LIMB_MASK,
        c1 & _LIMB_MASK,
        c2 & _LIMB_MASK,
        c3 & _LIMB_MASK,
        c4 & _LIMB_MASK,
        c5 & _LIMB_MASK,
        c6 & _LIMB_MASK,
        c6 >> _LIMB_BITS,
    )


@numba.njit(cache=True)
def _incircle_integer(ax, ay, bx, by, cx, cy, dx, dy):
    """The exact in-circle sign (-1, 0 or 1) on integers, or 2 when the coordinates are not fit for it.

    They are when one power of two scales them all to integers below
    ``2^58``: they span at most 58 bits. The scale is never below 1 (which
    could lose bits) nor infinite.
    """
    largest = max(abs(ax), abs(ay), abs(bx), abs(by), abs(cx), abs(cy), abs(dx), abs(dy))
    _, exponent = math.frexp(largest)  # largest < 2^exponent
    if exponent > _INTEGER_BITS or exponent < _INTEGER_BITS - 1023:
        return 2
    scale = math.ldexp(1.0, _INTEGER_BITS - exponent)
    iax, ax_exact = _scaled_integer(ax, scale)
    iay, ay_exact = _scaled_integer(ay, scale)
    ibx, bx_exact = _scaled_integer(bx, scale)
    iby, by_exact = _scaled_integer(by, scale)
    icx, cx_exact = _scaled_integer(cx, scale)
    icy, cy_exact = _scaled_integer(cy, scale)
    idx, dx_exact = _scaled_integer(dx, scale)
    idy, dy_exact = _scaled_integer(dy, scale)
    if not (ax_exact and ay_exact and bx_exact and by_exact and cx_exact and cy_exact and dx_exact and dy_exact):
        return 2
    adx = iax - idx
    ady = iay - idy
    bdx = ibx - idx
    bdy = iby - idy
    cdx = icx - idx
    cdy = icy - idy
    a_term = _limb_product(_limb_product_sum(adx, adx, ady, ady, 1), _limb_product_sum(bdx, cdy, cdx, bdy, -1))
    b_term = _limb_product(_limb_product_sum(bdx, bdx, bdy, bdy, 1), _limb_product_sum(cdx, ady, adx, cdy, -1))
    c_term = _limb_product(_limb_product_sum(cdx, cdx, cdy, cdy, 1), _limb_product_sum(adx, bdy, bdx, ady, -1))
    # below 3 2^238 in magnitude: eight limbs again, the last signed, the others non-negative,
    # so the last decides the sign unless it is zero
    carry = 0
    lower_nonzero = False
    for k in range(7):
        limb = a_term[k] + b_term[k] + c_term[k] + carry
        carry = limb >> _LIMB_BITS
        lower_nonzero = lower_nonzero or (limb & _LIMB_MASK) != 0
    top = a_term[7] + b_term[7] + c_term[7] + carry
    if top != 0:
        return 1 if top > 0 else -1
    return 1 if lower_nonzero else 0


@numba.njit(cache=True, inline="always")
def incircle(points, a, b, c, d, work):
    """Positive when ``d`` lies inside the circle through counter-clockwise ``a, b, c``; 0 exactly when cocircular.

    The sign is exact; the magnitude only approximate, and 1 when integer
    arithmetic decided. ``work`` is a :func:`workspace`.
    """
    ax, ay, bx, by, cx, cy = _corners(points, a, b, c)
    dx = points[d, 0]
    dy = points[d, 1]
    adx = ax - dx
    ady = ay - dy
    bdx = bx - dx
    bdy = by - dy
    cdx = cx - dx
    cdy = cy - dy
    bdxcdy = bdx * cdy
    cdxbdy = cdx * bdy
    cdxady = cdx * ady
    adxcdy = adx * cdy
    adxbdy = adx * bdy
    bdxady = bdx * ady
    alift = adx * adx + ady * ady
    blift = bdx * bdx + bdy * bdy
    clift = cdx * cdx + cdy * cdy
    det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady)
    permanent = (
        (abs(bdxcdy) + abs(cdxbdy)) * alift + (abs(cdxady) + abs(adxcdy)) * blift + (abs(adxbdy) + abs(bdxady)) * clift
    )
    if abs(det) > _INCIRCLE_BOUND * permanent:
        return det
    sign = _incircle_integer(ax, ay, bx, by, cx, cy, dx, dy)
    if sign != 2:
        return float(sign)
    return _incircle_exact(ax, ay, bx, by, cx, cy, dx, dy, work)


# --- spatial order ----------------------------------------------------------------------------


def _hilbert_step(state, x_bit, y_bit):
    """One level of the Hilbert curve: ``(digit, next state)`` for a cell's quadrant bits.

    The state is how the sub-curve is turned: swapped axes (bit 1) and
    both axes reversed (bit 0). The quadrant's digit along the curve is
    ``3 x ^ y`` in the turned frame; the lower-left quadrant swaps the axes,
    the lower-right also reverses them (the usual xy-to-index rotation).
    """
    swapped, reversed_ = state >> 1, state & 1
    x = (y_bit if swapped else x_bit) ^ reversed_
    y = (x_bit if swapped else y_bit) ^ reversed_
    if y == 0:
        reversed_ ^= x
        swapped ^= 1
    return (3 * x) ^ y, (swapped << 1) | reversed_


def _hilbert_table():
    """Two levels at a time: ``[state, two x bits, two y bits] -> two digits << 2 | next state``."""
    table = np.empty((4, 4, 4), dtype=np.int64)
    for state in range(4):
        for x in range(4):
            for y in range(4):
                high, middle = _hilbert_step(state, x >> 1, y >> 1)
                low, after = _hilbert_step(middle, x & 1, y & 1)
                table[state, x, y] = ((4 * high + low) << 2) | after
    return table


_HILBERT_TABLE = _hilbert_table()


@numba.njit(cache=True)
def hilbert_keys(points, bits):
    """Index of each point along a Hilbert curve over its bounding box, on a ``2**bits`` grid.

    Two levels per table lookup (:func:`_hilbert_table`): five times faster
    than turning the coordinates level by level, the same keys.
    """
    n = points.shape[0]
    xmin = points[:, 0].min()
    ymin = points[:, 1].min()
    extent = max(points[:, 0].max() - xmin, points[:, 1].max() - ymin)
    side = 1 << bits
    scale = (side - 1) / extent if extent > 0 else 0.0
    keys = np.empty(n, dtype=np.int64)
    # an odd number of levels gets a leading level of zero bits, entered in the state that it
    # leaves unturned with digit 0 (swapped: the lower-left quadrant swaps back)
    first_state = 2 if bits & 1 else 0
    top = bits + (bits & 1) - 2
    for i in range(n):
        x = min(int((points[i, 0] - xmin) * scale), side - 1)
        y = min(int((points[i, 1] - ymin) * scale), side - 1)
        key = 0
        state = first_state
        for shift in range(top, -1, -2):
            entry = _HILBERT_TABLE[state, (x >> shift) & 3, (y >> shift) & 3]
            key = (key << 4) | (entry >> 2)
            state = entry & 3
        keys[i] = key
    return keys


@numba.njit(cache=True)
def _push_long_runs(keys, start, max_run, stack, top):
    """Queue the runs of equal ``keys`` (sorted) longer than ``max_run``, offset by ``start``."""
    run_start = 0
    count = keys.shape[0]
    for i in range(1, count + 1):
        if i == count or keys[i] != keys[run_start]:
            if i - run_start > max_run:
                if top == stack.shape[0]:
                    stack = grown(stack, 2 * top, 0)
                stack[top, 0] = start + run_start
                stack[top, 1] = start + i
                top += 1
            run_start = i
    return stack, top


_RADIX_BITS = 11  # digits of the radix sort: 2048 buckets, four passes for the 40-bit keys of a 2**20 grid
_RADIX_MIN = 512  # fewer keys are sorted by insertion (the bucket counts would cost more)


@numba.njit(cache=True)
def _sort_keys(keys):
    """Stable sort of int64 ``keys``: ``(order, keys[order])``.

    A least-significant-digit radix sort of the keys less the smallest (as
    unsigned numbers), digit passes where all keys agree skipped: linear,
    and 10 times faster than numba's merge sort on a million random keys (the
    same permutation: both are stable). Fewer than ``_RADIX_MIN`` keys are
    sorted by insertion. No NumPy sort is called: numba compiled its merge
    sort and quicksort for 2 s of a fresh installation's first run (see :mod:`.arrays`).
    """
    n = keys.shape[0]
    order = np.empty(n, dtype=np.int64)
    current = keys.copy()
    smallest = keys[0] if n else 0
    largest = smallest
    for i in range(n):
        order[i] = i
        smallest = min(smallest, keys[i])
        largest = max(largest, keys[i])
    if n < _RADIX_MIN:
        for i in range(1, n):
            key = current[i]
            j = i - 1
            while j >= 0 and current[j] > key:
                current[j + 1] = current[j]
                order[j + 1] = order[j]
                j -= 1
            current[j + 1] = key
            order[j + 1] = i
        return order, current
    base = np.uint64(smallest)
    span = np.uint64(largest) - base  # the keys less the smallest lie in [0, span], even across zero
    mask = np.uint64((1 << _RADIX_BITS) - 1)
    spare_order = np.empty(n, dtype=np.int64)
    spare_keys = np.empty(n, dtype=np.int64)
    counts = np.empty((1 << _RADIX_BITS) + 1, dtype=np.int64)
    shift = np.uint64(0)
    while shift < 64 and (shift == 0 or (span >> shift) > 0):  # six 11-bit digits cover 64 bits
        counts[:] = 0
        for i in range(n):
            counts[((np.uint64(current[i]) - base) >> shift & mask) + 1] += 1
        if counts.max() < n:
            for d in range(1 << _RADIX_BITS):
                counts[d + 1] += counts[d]
            for i in range(n):
                digit = (np.uint64(current[i]) - base) >> shift & mask
                place = counts[digit]
                counts[digit] = place + 1
                spare_order[place] = order[i]
                spare_keys[place] = current[i]
            order, spare_order = spare_order, order
            current, spare_keys = spare_keys, current
        shift += np.uint64(_RADIX_BITS)
    return order, current


@numba.njit(cache=True)
def hilbert_order(points, bits, max_run):
    """Permutation putting ``points`` in Hilbert-curve order, refined inside crowded grid cells.

    Points sharing a cell of the ``2**bits`` grid over the bounding box (a
    cluster far smaller than the domain, as strongly graded meshes have) are
    ordered again on the grid over their own bounding box, and so on while
    more than ``max_run`` points share a cell; otherwise they would be
    inserted in input order and every walk would cross the cluster. Each
    refinement splits its run (its extreme points land in different cells),
    so this ends; a run of exact duplicates has no extent and is left as is.
    """
    order, sorted_keys = _sort_keys(hilbert_keys(points, bits))
    stack = np.empty((16, 2), dtype=np.int64)
    stack, top = _push_long_runs(sorted_keys, np.int64(0), max_run, stack, np.int64(0))
    while top > 0:
        top -= 1
        start = stack[top, 0]
        stop = stack[top, 1]
        run = order[start:stop].copy()
        members = np.empty((stop - start, 2))
        for i in range(stop - start):
            members[i, 0] = points[run[i], 0]
            members[i, 1] = points[run[i], 1]
        keys = hilbert_keys(members, bits)
        if keys.min() == keys.max():
            continue
        local, sorted_keys = _sort_keys(keys)
        for i in range(stop - start):
            order[start + i] = run[local[i]]
        stack, top = _push_long_runs(sorted_keys, start, max_run, stack, top)
    return order


# --- triangulation ----------------------------------------------------------------------------


@numba.njit(cache=True, inline="always")
def replace_neighbor(neighbors, cell, old, new):
    if cell < 0:
        return  # no cell across (a triangulation without ghost cells)
    for k in range(3):
        if neighbors[cell, k] == old:
            neighbors[cell, k] = new
            return


@numba.njit(cache=True, inline="always")
def _is_ghost(cells, t, infinite):
    return cells[t, 0] == infinite or cells[t, 1] == infinite or cells[t, 2] == infinite


@numba.njit(cache=True)
def _locate(points, cells, neighbors, start, p, infinite, state, max_steps, work):
    """Walk from cell ``start`` towards point ``p``.

    Returns ``(cell, where, corner, state)``: ``where`` is INSIDE a real cell,
    ON_EDGE opposite ``corner`` of a real cell, OUTSIDE the hull (``cell`` is
    the ghost beyond the hull edge that ``p`` lies strictly outside of), or
    ON_VERTEX ``cells[cell, corner]``; ``corner`` is -1 when it does not
    apply. ``where`` is -1 after ``max_steps`` steps. The edge tried first is
    drawn at random: a deterministic visibility walk can cycle on
    degenerate (cocircular) triangulations, a randomised one cannot.
    """
    t = start
    if _is_ghost(cells, t, infinite):
        for k in range(3):
            if cells[t, k] == infinite:
                t = neighbors[t, k]
                break
    previous = -1
    for _ in range(max_steps):
        state = (state * 6364136223846793005 + 1442695040888963407) & 0x7FFFFFFFFFFFFFFF
        first = (state >> 33) % 3
        moved = False
        zeros = 0
        zero_a = -1
        zero_b = -1
        for i in range(3):
            k = (first + i) % 3
            nb = neighbors[t, k]
            if nb == previous:
                continue  # p lies strictly on this side of the edge we came through
            o = orient(points, cells[t, (k + 1) % 3], cells[t, (k + 2) % 3], p, work)
            if o < 0.0:
                previous = t
                t = nb
                moved = True
                break
            if o == 0.0:
                if zeros == 0:
                    zero_a = k
                else:
                    zero_b = k
                zeros += 1
        if not moved:
            if zeros == 0:
                return t, INSIDE, -1, state
            if zeros == 1:
                return t, ON_EDGE, zero_a, state
            # on the lines of two edges: the point is their common vertex
            return t, ON_VERTEX, 3 - zero_a - zero_b, state
        if _is_ghost(cells, t, infinite):
            return t, OUTSIDE, -1, state
    return t, -1, -1, state


@numba.njit(cache=True)
def _push(stack, top, t):
    if top == stack.shape[0]:
        stack = grown(stack, 2 * top, 0)
    stack[top] = t
    return stack, top + 1


@numba.njit(cache=True, inline="always")
def _edge_quad(cells, neighbors, t1, k):
    """The edge opposite corner ``k`` of ``t1`` and its two cells.

    Returns ``(p, u, v)``, ``t1`` read from corner ``k``; ``t2``, the cell
    across; ``j``, the corner of ``t2`` facing ``t1``; ``z``, its vertex.
    """
    t2 = neighbors[t1, k]
    j = 0
    while neighbors[t2, j] != t1:
        j += 1
    return cells[t1, k], cells[t1, (k + 1) % 3], cells[t1, (k + 2) % 3], t2, j, cells[t2, j]


@numba.njit(cache=True, inline="always")
def _not_locally_delaunay(points, cells, neighbors, t1, k, infinite, work):
    """Whether the edge opposite corner ``k`` of ``t1`` must flip (ghost cells included).

    ``t1 = (p, u, v)`` read from corner ``k``, ``(z, v, u)`` the cell across.
    A real edge flips when ``z`` is strictly inside the circle through
    ``p, u, v``; a hull edge never does; an edge from a hull vertex to
    infinity flips when that vertex lies strictly inside the hull (it then
    leaves the hull).
    """
    p, u, v, t2, j, z = _edge_quad(cells, neighbors, t1, k)
    if p == infinite or z == infinite:
        return False
    if u == infinite:
        return orient(points, p, z, v, work) > 0.0
    if v == infinite:
        return orient(points, p, u, z, work) > 0.0
    return incircle(points, p, u, v, z, work) > 0.0


@numba.njit(cache=True, inline="always")
def flip_edge(cells, neighbors, t1, k):
    """Flip the edge opposite corner ``k`` of ``t1``: ``(p, u, v), (z, v, u)`` become ``(p, u, z), (p, z, v)``.

    ``t1`` keeps ``(p, u, z)``; returns the other cell.
    """
    p, u, v, t2, j, z = _edge_quad(cells, neighbors, t1, k)
    across_vp = neighbors[t1, (k + 1) % 3]
    across_pu = neighbors[t1, (k + 2) % 3]
    across_uz = neighbors[t2, (j + 1) % 3]
    across_zv = neighbors[t2, (j + 2) % 3]
    _set_cell(cells, neighbors, t1, p, u, z, across_uz, t2, across_pu)
    _set_cell(cells, neighbors, t2, p, z, v, across_zv, across_vp, t1)
    replace_neighbor(neighbors, across_uz, t2, t1)
    replace_neighbor(neighbors, across_vp, t1, t2)
    return t2


@numba.njit(cache=True)
def _legalize(points, cells, neighbors, stack, top, infinite, work):
    """Lawson flips around the new point; every stacked cell has it at corner 0.

    Returns the (possibly grown) stack and the number of flips.
    """
    flips = 0
    while top > 0:
        top -= 1
        t1 = stack[top]
        if not _not_locally_delaunay(points, cells, neighbors, t1, 0, infinite, work):
            continue
        t2 = flip_edge(cells, neighbors, t1, 0)
        flips += 1
        stack, top = _push(stack, top, t1)
        stack, top = _push(stack, top, t2)
    return stack, flips


@numba.njit(cache=True, inline="always")
def _set_cell(cells, neighbors, t, a, b, c, na, nb, nc):
    cells[t, 0] = a
    cells[t, 1] = b
    cells[t, 2] = c
    neighbors[t, 0] = na
    neighbors[t, 1] = nb
    neighbors[t, 2] = nc


@numba.njit(cache=True)
def _split_cell(cells, neighbors, t, p, m, m1):
    """Split cell ``t`` (real or ghost) at ``p`` into ``t, m, m1``, each with ``p`` at corner 0."""
    a = cells[t, 0]
    b = cells[t, 1]
    c = cells[t, 2]
    across_bc = neighbors[t, 0]
    across_ca = neighbors[t, 1]
    across_ab = neighbors[t, 2]
    _set_cell(cells, neighbors, t, p, b, c, across_bc, m, m1)
    _set_cell(cells, neighbors, m, p, c, a, across_ca, m1, t)
    _set_cell(cells, neighbors, m1, p, a, b, across_ab, t, m)
    replace_neighbor(neighbors, across_ca, t, m)
    replace_neighbor(neighbors, across_ab, t, m1)


@numba.njit(cache=True)
def _split_edge(cells, neighbors, t, k, p, m, m1):
    """Split the edge opposite corner ``k`` of ``t`` at ``p``: ``t``, its neighbour, ``m``, ``m1``."""
    w = cells[t, k]
    u = cells[t, (k + 1) % 3]
    v = cells[t, (k + 2) % 3]
    t2 = neighbors[t, k]
    across_vw = neighbors[t, (k + 1) % 3]
    across_wu = neighbors[t, (k + 2) % 3]
    j = 0
    while neighbors[t2, j] != t:
        j += 1
    z = cells[t2, j]  # t2 = (z, v, u)
    across_uz = neighbors[t2, (j + 1) % 3]
    across_zv = neighbors[t2, (j + 2) % 3]
    _set_cell(cells, neighbors, t, p, v, w, across_vw, m, m1)
    _set_cell(cells, neighbors, m, p, w, u, across_wu, t2, t)
    _set_cell(cells, neighbors, t2, p, u, z, across_uz, m1, m)
    _set_cell(cells, neighbors, m1, p, z, v, across_zv, t, t2)
    replace_neighbor(neighbors, across_wu, t, m)
    replace_neighbor(neighbors, across_zv, t2, m1)
    return t2


@numba.njit(cache=True)
def triangulate(points):
    """Delaunay triangulation of ``points`` (n, 2) float64, inserted in the given order.

    Returns ``(status, cells, neighbors, duplicate_of)``: ``status`` is OK,
    TOO_FEW_DISTINCT, COLLINEAR or WALK_FAILED (the arrays are then
    empty); ``cells`` and ``neighbors`` cover the convex hull; the
    ``duplicate_of[i]`` is the vertex that point ``i`` coincides with
    exactly, -1 for vertices.
    """
    n = points.shape[0]
    infinite = n
    duplicate_of = np.full(n, -1, dtype=np.int64)
    empty = np.empty((0, 3), dtype=np.int64)
    work = np.empty(WORK_SIZE)
    # the first three points in order that span a triangle
    if n < 3:
        return TOO_FEW_DISTINCT, empty, empty, duplicate_of
    i0 = 0
    i1 = -1
    for i in range(1, n):
        if points[i, 0] != points[0, 0] or points[i, 1] != points[0, 1]:
            i1 = i
            break
    if i1 < 0:
        return TOO_FEW_DISTINCT, empty, empty, duplicate_of
    i2 = -1
    for i in range(i1 + 1, n):
        if orient(points, i0, i1, i, work) != 0.0:
            i2 = i
            break
    if i2 < 0:
        return COLLINEAR, empty, empty, duplicate_of
    if orient(points, i0, i1, i2, work) < 0.0:
        i1, i2 = i2, i1
    # sphere of n + 1 vertices: 2 (n + 1) - 4 cells at most, ghosts included
    capacity = 2 * n + 4
    cells = np.empty((capacity, 3), dtype=np.int64)
    neighbors = np.empty((capacity, 3), dtype=np.int64)
    _set_cell(cells, neighbors, 0, i0, i1, i2, 1, 2, 3)
    _set_cell(cells, neighbors, 1, i2, i1, infinite, 3, 2, 0)
    _set_cell(cells, neighbors, 2, i0, i2, infinite, 1, 3, 0)
    _set_cell(cells, neighbors, 3, i1, i0, infinite, 2, 1, 0)
    stack = np.empty(64, dtype=np.int64)
    m = np.int64(4)
    last = np.int64(0)
    state = np.int64(12345)
    for p in range(n):
        if p == i0 or p == i1 or p == i2:
            continue
        outcome, t, state, stack = _insert(points, cells, neighbors, p, m, m + 1, last, state, stack, infinite, work)
        if outcome == FAILED:
            return WALK_FAILED, empty, empty, duplicate_of
        if outcome == DUPLICATE:
            duplicate_of[p] = t
        else:
            m += 2
            last = t
    return OK, cells[:m], neighbors[:m], duplicate_of


INSERTED = 0
DUPLICATE = 1
FAILED = -1


@numba.njit(cache=True)
def _insert(points, cells, neighbors, p, m, m1, last, state, stack, infinite, work):
    """Insert point ``p`` by a walk from cell ``last``, a split into the free cells ``m, m1`` and Lawson flips.

    Returns ``(outcome, index, state, stack)``: outcome INSERTED (``index``
    is a cell with ``p`` as a vertex), DUPLICATE (``p`` coincides exactly
    with vertex ``index``; nothing changed) or FAILED (the walk did not end).
    """
    max_steps = 8 * points.shape[0] + 64
    t, where, corner, state = _locate(points, cells, neighbors, last, p, infinite, state, max_steps, work)
    if where == ON_VERTEX:
        return DUPLICATE, cells[t, corner], state, stack
    if where < 0:
        return FAILED, t, state, stack
    if where == ON_EDGE:
        t2 = _split_edge(cells, neighbors, t, corner, p, m, m1)
        stack[0] = t
        stack[1] = m
        stack[2] = t2
        stack[3] = m1
        top = 4
    else:
        _split_cell(cells, neighbors, t, p, m, m1)
        stack[0] = t
        stack[1] = m
        stack[2] = m1
        top = 3
    stack, _ = _legalize(points, cells, neighbors, stack, top, infinite, work)
    return INSERTED, t, state, stack


@numba.njit(cache=True)
def insert_points(points, cells, neighbors, first, old_infinite, order):
    """Insert ``points[first:]`` into a triangulation of ``points[:first]`` with ghost cells.

    ``cells`` and ``neighbors`` are that triangulation (any vertex
    numbering, ``old_infinite`` its vertex at infinity); the new points are
    inserted in the order ``first + order`` (a permutation of their
    indices), each walk starting where the last ended, and keep their
    numbers: no renumbering pass over the cells afterwards.
    Returns ``(status, cells, neighbors, duplicate_of)`` with the vertex at
    infinity renumbered to ``len(points)``; ``duplicate_of`` as in
    :func:`triangulate`, for the new points.
    """
    n = points.shape[0]
    infinite = n
    m = cells.shape[0]
    grown_cells = np.empty((m + 2 * (n - first), 3), dtype=np.int64)
    grown_neighbors = np.empty((m + 2 * (n - first), 3), dtype=np.int64)
    for t in range(m):
        for k in range(3):
            v = cells[t, k]
            grown_cells[t, k] = infinite if v == old_infinite else v
            grown_neighbors[t, k] = neighbors[t, k]
    duplicate_of = np.full(n, -1, dtype=np.int64)
    work = np.empty(WORK_SIZE)
    stack = np.empty(64, dtype=np.int64)
    last = np.int64(0)
    state = np.int64(12345)
    for k in range(n - first):
        p = first + order[k]
        outcome, t, state, stack = _insert(
            points, grown_cells, grown_neighbors, p, m, m + 1, last, state, stack, infinite, work
        )
        if outcome == FAILED:
            return WALK_FAILED, grown_cells[:m], grown_neighbors[:m], duplicate_of
        if outcome == DUPLICATE:
            duplicate_of[p] = t
        else:
            m += 2
            last = t
    return OK, grown_cells[:m], grown_neighbors[:m], duplicate_of


@numba.njit(cache=True)
def nearest_vertex_distances(points, cells, neighbors, infinite, queries):
    """Distance from each of ``queries`` to the nearest vertex of a Delaunay triangulation of ``points``.

    ``cells`` and ``neighbors`` are a full triangulation with ghost cells
    (``infinite`` the vertex at infinity), as :func:`triangulate` returns
    them. A greedy descent: from the previous query's nearest vertex, step
    to the neighbour closest to the query while one is closer. In a
    Delaunay triangulation a vertex with no closer neighbour is the
    nearest (the segment from it to the query leaves its Voronoi cell
    through the cell of a neighbour at least as close), so this is exact;
    queries in spatial order keep the descents short.
    """
    n = points.shape[0]
    cell_of = np.full(n, -1, dtype=np.int64)
    for t in range(cells.shape[0]):
        for k in range(3):
            if cells[t, k] < n:
                cell_of[cells[t, k]] = t
    v = 0
    while cell_of[v] < 0:
        v += 1  # a duplicate point is no vertex
    out = np.empty(queries.shape[0])
    for j in range(queries.shape[0]):
        qx = queries[j, 0]
        qy = queries[j, 1]
        best = (points[v, 0] - qx) ** 2 + (points[v, 1] - qy) ** 2
        while True:
            closer = v
            start = cell_of[v]
            c = start
            while True:
                i = _corner_of(cells, c, v)
                u = cells[c, (i + 1) % 3]
                if u != infinite:
                    d = (points[u, 0] - qx) ** 2 + (points[u, 1] - qy) ** 2
                    if d < best:
                        best = d
                        closer = u
                c = neighbors[c, (i + 1) % 3]  # the next cell counter-clockwise around v
                if c == start:
                    break
            if closer == v:
                break
            v = closer
        out[j] = np.sqrt(best)
    return out


@numba.njit(cache=True)
def renumber(cells, neighbors, new_number):
    """Cells with vertices renamed by ``new_number`` and sorted by their smallest new vertex; neighbours follow.

    A counting sort (linear): cells of nearby vertices become nearby in
    memory. Returns ``(cells, neighbors)``; -1 neighbours stay -1.
    """
    m = cells.shape[0]
    n = new_number.shape[0]
    start = np.zeros(n + 1, dtype=np.int64)
    renamed = np.empty_like(cells)
    for c in range(m):
        smallest = n
        for k in range(3):
            v = new_number[cells[c, k]]
            renamed[c, k] = v
            smallest = min(smallest, v)
        start[smallest + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    place = np.empty(m, dtype=np.int64)
    for c in range(m):
        smallest = min(renamed[c, 0], renamed[c, 1], renamed[c, 2])
        place[c] = start[smallest]
        start[smallest] += 1
    out_cells = np.empty_like(cells)
    out_neighbors = np.empty_like(neighbors)
    for c in range(m):
        to = place[c]
        for k in range(3):
            out_cells[to, k] = renamed[c, k]
            across = neighbors[c, k]
            out_neighbors[to, k] = -1 if across < 0 else place[across]
    return out_cells, out_neighbors


@numba.njit(cache=True, inline="always")
def _is_real(cells, t, infinite, first):
    """Whether cell ``t`` is neither a ghost nor touching the frame (vertices below ``first``)."""
    a = cells[t, 0]
    b = cells[t, 1]
    c = cells[t, 2]
    return a != infinite and b != infinite and c != infinite and a >= first and b >= first and c >= first


@numba.njit(cache=True, inline="always")
def _corner_facing(cells, t, u, v):
    """The corner of cell ``t`` opposite its edge ``(u, v)``."""
    j = 0
    while cells[t, j] == u or cells[t, j] == v:
        j += 1
    return j


@numba.njit(cache=True)
def drop_ghosts(cells, neighbors, infinite, first=0):
    """The real cells and their neighbours, ghost neighbours replaced by -1.

    Cells with a vertex below ``first`` (a frame, see ``Triangulation``) go
    too, and vertex numbers are shifted down by ``first``.
    """
    m = cells.shape[0]
    new_index = np.full(m, -1, dtype=np.int64)
    count = 0
    for t in range(m):
        if _is_real(cells, t, infinite, first):
            new_index[t] = count
            count += 1
    out_cells = np.empty((count, 3), dtype=np.int64)
    out_neighbors = np.empty((count, 3), dtype=np.int64)
    for t in range(m):
        i = new_index[t]
        if i < 0:
            continue
        for k in range(3):
            out_cells[i, k] = cells[t, k] - first
            out_neighbors[i, k] = new_index[neighbors[t, k]]
    return out_cells, out_neighbors


@numba.njit(cache=True, inline="always")
def _link(neighbors, a, corner_a, b, corner_b):
    neighbors[a, corner_a] = b
    neighbors[b, corner_b] = a


@numba.njit(cache=True)
def split_edges(points, cells, neighbors, infinite, first, keep):
    """Split every edge of the kept cells at its midpoint: each kept cell into four similar ones.

    ``cells`` and ``neighbors`` are a full triangulation with ghost cells
    (``infinite`` the vertex at infinity, vertices below ``first`` a frame);
    ``keep`` marks cells in the order :func:`drop_ghosts` lists them. A
    cell outside whose edges border kept cells is split into two or three
    (at one or two midpoints), so the result is a triangulation again,
    numbered as :func:`insert_points` would (midpoint ``e`` is vertex ``n +
    e``, the vertex at infinity ``n + len(edges)``); it need not be
    Delaunay (an obtuse cell's four are not), which Lawson flips restore.
    The direct construction needs no point location and no flips, where
    inserting the midpoints one by one costs both.

    Returns ``(status, points, cells, neighbors, edges, outer)``: ``points``
    with the midpoints appended (status WRONG_SIZE, nothing changed, when
    ``keep`` does not have one flag per real cell); ``edges`` (e, 2), the split edges by their
    vertices less ``first``, in midpoint order; ``outer`` (e,) bool, the
    edges with a cell on one side only (the kept cells' boundary). Status
    NOT_VALID when a new cell is not strictly counter-clockwise (a midpoint
    rounded off a nearly flat cell's edge): the caller inserts the points
    instead.
    """
    n = points.shape[0]
    m = cells.shape[0]
    kept = np.zeros(m, dtype=np.bool_)
    count = 0
    for t in range(m):
        if _is_real(cells, t, infinite, first):
            if count < keep.shape[0]:
                kept[t] = keep[count]
            count += 1
    if count != keep.shape[0]:
        return WRONG_SIZE, points, cells, neighbors, np.empty((0, 2), dtype=np.int64), np.empty(0, dtype=np.bool_)
    # one midpoint per edge of a kept cell, numbered as the cells are visited
    middle = np.full((m, 3), -1, dtype=np.int64)
    edges = np.empty((3 * count + 3, 2), dtype=np.int64)
    outer = np.empty(3 * count + 3, dtype=np.bool_)
    e = 0
    for t in range(m):
        if not kept[t]:
            continue
        for k in range(3):
            if middle[t, k] >= 0:
                continue
            u = cells[t, (k + 1) % 3]
            v = cells[t, (k + 2) % 3]
            across = neighbors[t, k]
            j = _corner_facing(cells, across, u, v)
            middle[t, k] = e
            middle[across, j] = e
            edges[e, 0] = u - first
            edges[e, 1] = v - first
            outer[e] = not kept[across]
            e += 1
    infinite_new = n + e
    extended = grown(points, n + e, 0.0)
    for i in range(e):
        u = edges[i, 0] + first
        v = edges[i, 1] + first
        extended[n + i, 0] = 0.5 * (points[u, 0] + points[v, 0])
        extended[n + i, 1] = 0.5 * (points[u, 1] + points[v, 1])
    # cells 1 -> 1, 2, 3 or 4 by the number of split edges; each old edge half (k, h) remembers
    # the new cell and corner facing it (h = 0 the half at the edge's first vertex, cells[t, k + 1])
    start = np.empty(m + 1, dtype=np.int64)
    start[0] = 0
    for t in range(m):
        split = (middle[t, 0] >= 0) + (middle[t, 1] >= 0) + (middle[t, 2] >= 0)
        start[t + 1] = start[t] + split + 1
    total = start[m]
    new_cells = np.empty((total, 3), dtype=np.int64)
    new_neighbors = np.empty((total, 3), dtype=np.int64)
    facing = np.empty((m, 3, 2), dtype=np.int64)
    for t in range(m):
        base = start[t]
        c0 = cells[t, 0]
        c1 = cells[t, 1]
        c2 = cells[t, 2]
        if c0 == infinite:
            c0 = infinite_new
        if c1 == infinite:
            c1 = infinite_new
        if c2 == infinite:
            c2 = infinite_new
        corners = (c0, c1, c2)
        split = start[t + 1] - base - 1
        if split == 0:
            new_cells[base, 0] = c0
            new_cells[base, 1] = c1
            new_cells[base, 2] = c2
            for k in range(3):
                facing[t, k, 0] = 3 * base + k
                facing[t, k, 1] = 3 * base + k
        elif split == 3:
            m0 = n + middle[t, 0]
            m1 = n + middle[t, 1]
            m2 = n + middle[t, 2]
            a, b, c, d = base, base + 1, base + 2, base + 3
            new_cells[a, 0], new_cells[a, 1], new_cells[a, 2] = c0, m2, m1
            new_cells[b, 0], new_cells[b, 1], new_cells[b, 2] = m2, c1, m0
            new_cells[c, 0], new_cells[c, 1], new_cells[c, 2] = m1, m0, c2
            new_cells[d, 0], new_cells[d, 1], new_cells[d, 2] = m0, m1, m2
            _link(new_neighbors, a, 0, d, 0)
            _link(new_neighbors, b, 1, d, 1)
            _link(new_neighbors, c, 2, d, 2)
            facing[t, 0, 0], facing[t, 0, 1] = 3 * b, 3 * c
            facing[t, 1, 0], facing[t, 1, 1] = 3 * c + 1, 3 * a + 1
            facing[t, 2, 0], facing[t, 2, 1] = 3 * a + 2, 3 * b + 2
        elif split == 1:
            k = 0
            while middle[t, k] < 0:
                k += 1
            k1 = (k + 1) % 3
            k2 = (k + 2) % 3
            mid = n + middle[t, k]
            f, g = base, base + 1
            new_cells[f, 0], new_cells[f, 1], new_cells[f, 2] = corners[k], corners[k1], mid
            new_cells[g, 0], new_cells[g, 1], new_cells[g, 2] = corners[k], mid, corners[k2]
            _link(new_neighbors, f, 1, g, 2)
            facing[t, k, 0], facing[t, k, 1] = 3 * f, 3 * g
            facing[t, k2, 0], facing[t, k2, 1] = 3 * f + 2, 3 * f + 2
            facing[t, k1, 0], facing[t, k1, 1] = 3 * g + 1, 3 * g + 1
        else:
            k = 0
            while middle[t, k] >= 0:
                k += 1  # the edge left whole
            k1 = (k + 1) % 3
            k2 = (k + 2) % 3
            to_first = n + middle[t, k1]  # on the edge from corners[k2] to corners[k]
            to_second = n + middle[t, k2]  # on the edge from corners[k] to corners[k1]
            g, h1, h2 = base, base + 1, base + 2
            new_cells[g, 0], new_cells[g, 1], new_cells[g, 2] = corners[k], to_second, to_first
            new_cells[h1, 0], new_cells[h1, 1], new_cells[h1, 2] = to_second, corners[k1], corners[k2]
            new_cells[h2, 0], new_cells[h2, 1], new_cells[h2, 2] = to_second, corners[k2], to_first
            _link(new_neighbors, g, 0, h2, 1)
            _link(new_neighbors, h1, 1, h2, 2)
            facing[t, k, 0], facing[t, k, 1] = 3 * h1, 3 * h1
            facing[t, k1, 0], facing[t, k1, 1] = 3 * h2, 3 * g + 1
            facing[t, k2, 0], facing[t, k2, 1] = 3 * g + 2, 3 * h1 + 2
    # across an old edge: the half at its first vertex faces the other cell's half at its second
    for t in range(m):
        for k in range(3):
            across = neighbors[t, k]
            j = _corner_facing(cells, across, cells[t, (k + 1) % 3], cells[t, (k + 2) % 3])
            for h in range(2):
                mine = facing[t, k, h]
                theirs = facing[across, j, 1 - h]
                new_neighbors[mine // 3, mine % 3] = theirs // 3
    work = np.empty(WORK_SIZE)
    for t in range(total):
        a = new_cells[t, 0]
        b = new_cells[t, 1]
        c = new_cells[t, 2]
        if a != infinite_new and b != infinite_new and c != infinite_new and orient(extended, a, b, c, work) <= 0.0:
            return NOT_VALID, extended, new_cells, new_neighbors, edges[:e], outer[:e]
    return OK, extended, new_cells, new_neighbors, edges[:e], outer[:e]


@numba.njit(cache=True, inline="always")
def _queue_edge(stack, top, t, k):
    return _push(stack, top, 3 * t + k)


@numba.njit(cache=True, inline="always")
def _add_compensated(total, error, term):
    """``total + term`` and the running rounding error (Neumaier's compensated sum)."""
    new_total = total + term
    if abs(total) >= abs(term):
        error += (total - new_total) + term
    else:
        error += (term - new_total) + total
    return new_total, error


@numba.njit(cache=True, parallel=True)
def covered_area_mismatch(points, cells, infinite):
    """``|sum of real cell areas - hull polygon area|`` relative to the hull area, with compensated sums.

    The ghost cells' edges run clockwise around the hull, so their signed
    areas add up to minus the hull's. A triangulation whose real cells are
    all counter-clockwise covers its hull exactly once when the two agree;
    a fold that keeps every cell counter-clockwise covers part of it twice.
    The hull's terms are taken about one of the points: on raw coordinates
    far from the origin (UTM, 5e6 m) they cancelled to more than the 1e-9
    mismatch that calls a fold, and a valid triangulation was rebuilt.
    """
    m = cells.shape[0]
    reference = 1 if infinite == 0 else 0
    rx = points[reference, 0]
    ry = points[reference, 1]
    tasks = (m + _SCAN_CELLS - 1) // _SCAN_CELLS
    partial = np.empty((tasks, 2))  # each task's real-cell and hull sums
    for task in numba.prange(tasks):
        inside_sum = inside_error = hull_sum = hull_error = 0.0
        for t in range(task * _SCAN_CELLS, min(m, (task + 1) * _SCAN_CELLS)):
            a = cells[t, 0]
            b = cells[t, 1]
            c = cells[t, 2]
            if a == infinite or b == infinite or c == infinite:
                if a == infinite:
                    a, b = b, c
                elif b == infinite:
                    a, b = c, a
                term = -((points[a, 0] - rx) * (points[b, 1] - ry) - (points[a, 1] - ry) * (points[b, 0] - rx))
                hull_sum, hull_error = _add_compensated(hull_sum, hull_error, term)
            else:
                term = (points[b, 0] - points[a, 0]) * (points[c, 1] - points[a, 1]) - (points[b, 1] - points[a, 1]) * (
                    points[c, 0] - points[a, 0]
                )
                inside_sum, inside_error = _add_compensated(inside_sum, inside_error, term)
        partial[task, 0] = inside_sum + inside_error
        partial[task, 1] = hull_sum + hull_error
    inside = hull = inside_error = hull_error = 0.0
    for task in range(tasks):
        inside, inside_error = _add_compensated(inside, inside_error, partial[task, 0])
        hull, hull_error = _add_compensated(hull, hull_error, partial[task, 1])
    return abs((inside + inside_error) - (hull + hull_error)) / max(abs(hull + hull_error), 1e-300)


_INVERTED = 8  # bit of a cell's byte in the scan's marks: a real cell that is not counter-clockwise


@numba.njit(cache=True)
def _hold_back_inverting_moves(moved, held, cells, neighbors, infinite, back, marked, cell_of, work):
    """Put back to ``held`` the vertices of every cell that ``moved`` would invert, until none would.

    ``marked`` is the scan's (:func:`unsettled_edges`), its inverted cells
    flagged. Only the cells around a vertex put back can change, so only
    they are tested again, and their edges' marks are renewed. ``cells`` are
    strictly counter-clockwise at ``held``, so this ends, at worst with
    every vertex put back. Marks them in ``back`` and one cell of each in
    ``cell_of``; returns how many.
    """
    todo = np.flatnonzero(marked & _INVERTED)
    stack = np.empty(max(64, 2 * todo.shape[0]), dtype=np.int64)
    top = np.int64(0)
    for t in todo:
        stack, top = _push(stack, top, t)
    touched = np.zeros(cells.shape[0], dtype=np.bool_)
    around = np.empty(64, dtype=np.int64)  # the cells whose edges get new marks
    n_around = np.int64(0)
    count = 0
    while top > 0:
        top -= 1
        t = stack[top]
        a = cells[t, 0]
        b = cells[t, 1]
        c = cells[t, 2]
        if a == infinite or b == infinite or c == infinite or orient(moved, a, b, c, work) > 0.0:
            continue
        for v in (a, b, c):
            if back[v]:
                continue
            back[v] = True
            moved[v, 0] = held[v, 0]
            moved[v, 1] = held[v, 1]
            cell_of[v] = t
            count += 1
            star = t  # v's cells may invert now: test them again
            while True:
                stack, top = _push(stack, top, star)
                if not touched[star]:
                    touched[star] = True
                    around, n_around = _push(around, n_around, star)
                star = neighbors[star, (_corner_of(cells, star, v) + 1) % 3]
                if star == t:
                    break
    # an edge's flip test reads only its two cells: those of the moved-back vertices' stars are renewed
    for i in range(n_around):
        t = around[i]
        marked[t] &= np.uint8(255 - _INVERTED)
        for k in range(3):
            other = neighbors[t, k]
            owner, corner = t, k
            if other < t:
                owner, corner = other, _corner_of(neighbors, other, t)  # the corner facing t
            if _not_locally_delaunay(moved, cells, neighbors, owner, corner, infinite, work):
                marked[owner] |= np.uint8(1 << corner)
            else:
                marked[owner] &= np.uint8(255 - (1 << corner))
    return count


@numba.njit(cache=True)
def _lawson(points, cells, neighbors, infinite, max_flips, work):
    """Flip every edge that is not locally Delaunay until none is; returns the flips, or -1 past ``max_flips``.

    Needs a valid triangulation (every real cell counter-clockwise); ghost
    edges flip too, so a hull vertex that lies inside the hull leaves it.
    """
    m = cells.shape[0]
    # each edge once, from its cell of smaller index, marked before any flip rewrites the neighbours
    marked = np.empty(m, dtype=np.uint8)
    for t in range(m):
        marks = 0
        for k in range(3):
            if t < neighbors[t, k]:
                marks |= 1 << k
        marked[t] = marks
    return _flip_marked(points, cells, neighbors, infinite, max_flips, marked, work)


@numba.njit(cache=True)
def _flip_marked(points, cells, neighbors, infinite, max_flips, marked, work):
    """Lawson flips from the edges marked in ``marked`` (bit ``k`` of ``marked[t]``: the edge opposite corner ``k``).

    The marked edges are taken last cell first, each followed by the edges
    its flips queue, last queued first: the order of one stack filled with
    all marked edges up front, without that cost. An unmarked edge must be
    locally Delaunay (or become an edge of a flipped cell, which is queued).
    Returns the flips, or -1 past ``max_flips``.
    """
    stack = np.empty(64, dtype=np.int64)
    flips = 0
    for t in range(cells.shape[0] - 1, -1, -1):
        if marked[t] == 0:
            continue
        for k in range(2, -1, -1):
            if not marked[t] & (1 << k):
                continue
            stack[0] = 3 * t + k
            stack, flips = _flip_stacked(points, cells, neighbors, infinite, max_flips, stack, 1, flips, work)
            if flips < 0:
                return -1
    return flips


@numba.njit(cache=True, parallel=True)
def unsettled_edges(points, cells, neighbors, infinite, marked):
    """Mark the edges that are not locally Delaunay; returns how many real cells are not counter-clockwise.

    Bit ``k`` of ``marked[t]`` is set for the edge opposite corner ``k`` of
    cell ``t`` when ``t`` is the smaller of its two cells and the edge must
    flip; bit ``_INVERTED`` flags a real cell that is not counter-clockwise
    (the marks around it mean nothing then). Read-only on the
    triangulation, so it runs in parallel: after points moved a little
    nearly every edge is still locally Delaunay, and this scan was most of
    the work of restoring the triangulation.
    """
    m = cells.shape[0]
    inverted = 0
    for task in numba.prange((m + _SCAN_CELLS - 1) // _SCAN_CELLS):
        work = np.empty(WORK_SIZE)
        for t in range(task * _SCAN_CELLS, min(m, (task + 1) * _SCAN_CELLS)):
            a = cells[t, 0]
            b = cells[t, 1]
            c = cells[t, 2]
            marks = 0
            if a != infinite and b != infinite and c != infinite and orient(points, a, b, c, work) <= 0.0:
                inverted += 1
                marks = _INVERTED
            for k in range(3):
                if t < neighbors[t, k] and _not_locally_delaunay(points, cells, neighbors, t, k, infinite, work):
                    marks |= 1 << k
            marked[t] = marks
    return inverted


@numba.njit(cache=True)
def _lawson_around(points, cells, neighbors, infinite, max_flips, seeds, work):
    """:func:`_lawson` where only the edges of the cells ``seeds`` may be not locally Delaunay.

    An edge between two cells that did not change keeps its quad, so it
    stays locally Delaunay: after a local change only the changed cells'
    edges need a test (and the edges their flips queue).
    """
    stack = np.empty(max(64, 3 * seeds.shape[0]), dtype=np.int64)
    top = 0
    for t in seeds:
        for k in range(3):
            stack[top] = 3 * t + k
            top += 1
    stack, flips = _flip_stacked(points, cells, neighbors, infinite, max_flips, stack, top, 0, work)
    return flips


@numba.njit(cache=True, inline="always")
def _flip_stacked(points, cells, neighbors, infinite, max_flips, stack, top, flips, work):
    """Pop edges off ``stack`` (``top`` of them), flipping those not locally Delaunay and stacking their new edges.

    Returns ``(stack, flips)``, the stack possibly grown and ``flips`` the
    running count, or -1 once it passes ``max_flips``.
    """
    while top > 0:
        top -= 1
        t1 = stack[top] // 3
        k1 = stack[top] % 3
        if not _not_locally_delaunay(points, cells, neighbors, t1, k1, infinite, work):
            continue
        flips += 1
        if flips > max_flips:
            return stack, -1
        t2 = flip_edge(cells, neighbors, t1, k1)
        stack, top = _queue_edge(stack, top, t1, 0)
        stack, top = _queue_edge(stack, top, t1, 2)
        stack, top = _queue_edge(stack, top, t2, 0)
        stack, top = _queue_edge(stack, top, t2, 1)
    return stack, flips


@numba.njit(cache=True, inline="always")
def _corner_of(cells, t, v):
    for k in range(3):
        if cells[t, k] == v:
            return k
    return -1


@numba.njit(cache=True)
def _cell_with_vertex(points, cells, neighbors, v, guess, live, infinite, state, work):
    """A cell with vertex ``v``: ``guess`` if it has it, else found by a walk to ``v``'s position; -1 if none.

    The walk starts at ``guess``, or at ``live`` (a cell in use) when
    ``guess`` is -1 or a freed cell (all three corners at infinity).
    """
    if guess >= 0 and _corner_of(cells, guess, v) >= 0:
        return guess, state
    start = live if guess < 0 or (cells[guess, 0] == infinite and cells[guess, 1] == infinite) else guess
    t, where, corner, state = _locate(
        points, cells, neighbors, start, v, infinite, state, np.int64(_NO_STEP_LIMIT), work
    )
    if where == ON_VERTEX and cells[t, corner] == v:
        return t, state
    return -1, state


@numba.njit(cache=True)
def _remove_vertex(points, cells, neighbors, v, t, infinite, work):
    """Remove vertex ``v``, not on the hull, given a cell ``t`` that has it.

    Spokes of ``v`` are flipped away (each flip keeps every cell
    counter-clockwise, but for a flat one of ``v``'s when ``v`` lies on the
    new edge) until ``v`` has three neighbours, whose three cells then
    merge into one. The result is a valid triangulation without ``v``
    but not necessarily Delaunay (run :func:`_lawson`). Returns ``(merged,
    freed, freed)``: the merged cell and the two cells left unused, or
    ``(-1, -1, -1)`` when ``v`` is on the hull or no spoke could be flipped.
    """
    while True:
        degree = 0
        c = t
        while True:
            i = _corner_of(cells, c, v)
            if cells[c, (i + 1) % 3] == infinite or cells[c, (i + 2) % 3] == infinite:
                return -1, -1, -1
            degree += 1
            c = neighbors[c, (i + 1) % 3]  # the next cell counter-clockwise around v
            if c == t:
                break
        if degree == 3:
            i1 = _corner_of(cells, t, v)
            c2 = neighbors[t, (i1 + 1) % 3]
            i2 = _corner_of(cells, c2, v)
            c3 = neighbors[c2, (i2 + 1) % 3]
            i3 = _corner_of(cells, c3, v)
            a = cells[t, (i1 + 1) % 3]
            b = cells[t, (i1 + 2) % 3]
            c = cells[c2, (i2 + 2) % 3]
            across_ab = neighbors[t, i1]
            across_bc = neighbors[c2, i2]
            across_ca = neighbors[c3, i3]
            _set_cell(cells, neighbors, t, a, b, c, across_bc, across_ca, across_ab)
            replace_neighbor(neighbors, across_bc, c2, t)
            replace_neighbor(neighbors, across_ca, c3, t)
            return t, c2, c3
        flipped = False
        c = t
        for _ in range(degree):
            # c = (v, w, x); the cell before it around v is (v, y, w), across the spoke (v, w)
            i = _corner_of(cells, c, v)
            w = cells[c, (i + 1) % 3]
            x = cells[c, (i + 2) % 3]
            before = neighbors[c, (i + 2) % 3]
            y = cells[before, (_corner_of(cells, before, v) + 1) % 3]
            # v may lie on the new edge (y, x): that cell is flat, but it is v's and goes with v
            if orient(points, y, w, x, work) > 0.0 and orient(points, v, y, x, work) >= 0.0:
                flip_edge(cells, neighbors, c, (i + 2) % 3)  # c becomes (x, v, y), still around v
                t = c
                flipped = True
                break
            c = neighbors[c, (i + 1) % 3]
        if not flipped:
            return -1, -1, -1


@numba.njit(cache=True)
def restore_delaunay(moved, held, cells, neighbors, infinite, max_flips, marked, inverted):
    """Make a triangulation Delaunay again after its points moved, in place.

    ``cells`` and ``neighbors`` are a full triangulation with ghost cells, as
    :func:`triangulate` returns them (any vertex numbering, ``infinite`` the
    index of the vertex at infinity), Delaunay for the positions ``held``;
    ``moved`` are the new positions. Flips need a valid triangulation to
    start from, so a vertex of a cell that its move would invert (in
    practice a flat cell of boundary points sliding along the boundary)
    first keeps its held position; Lawson flips then make the
    triangulation Delaunay, and the vertices held back are removed, then
    inserted again at their new positions. ``held`` takes the new positions.
    ``marked`` and ``inverted`` are what :func:`unsettled_edges` found for
    ``moved`` (its parallel read-only scan finds both the inverted cells and
    the edges to flip); the flips start from those edges alone, in the order
    a full Lawson pass would take them. After the removals only the cells
    around the holes are flipped, and each insertion flips around its
    vertex. The caller runs the scan and the final check
    (:func:`covered_area_mismatch`): parallel kernels are called from Python
    only, as a serial kernel holding one can crash at its first call (see
    ``tests/_kernels/test_precompile.py``).

    Returns ``(status, flips)``: OK, or NOT_VALID when a vertex held back
    lies on the hull (it cannot be removed) or more than ``max_flips``
    flips were needed; the caller then triangulates anew. Where OK, the
    caller checks that the result covers its hull exactly once.
    """
    work = np.empty(WORK_SIZE)
    n = moved.shape[0]
    held_back = 0
    if inverted > 0:
        # only now: a copy of every position per call cost page faults at 10**6 points
        wanted = moved.copy()
        back = np.zeros(n, dtype=np.bool_)
        cell_of = np.full(n, -1, dtype=np.int64)
        held_back = _hold_back_inverting_moves(moved, held, cells, neighbors, infinite, back, marked, cell_of, work)
    flips = _flip_marked(moved, cells, neighbors, infinite, max_flips, marked, work)
    if flips < 0:
        return NOT_VALID, max_flips
    if held_back > 0:
        stack = np.empty(64, dtype=np.int64)
        state = np.int64(12345)
        # every held-back vertex comes out before any goes in again: two that trade places (one
        # moved exactly onto where the other was, both on a coastline's vertices) would collide
        removed = np.empty(held_back, dtype=np.int64)
        freed = np.empty((held_back, 2), dtype=np.int64)
        changed = np.zeros(cells.shape[0], dtype=np.bool_)
        count = 0
        live = np.int64(0)  # a cell in use: the latest merged or inserted one (removals free cells)
        for v in range(n):
            if not back[v] or (wanted[v, 0] == moved[v, 0] and wanted[v, 1] == moved[v, 1]):
                continue  # not held back, or held where it wanted to be anyway (a frame vertex)
            t, state = _cell_with_vertex(moved, cells, neighbors, v, cell_of[v], live, infinite, state, work)
            if t < 0:
                return NOT_VALID, flips
            _mark_star(cells, neighbors, v, t, changed)
            merged, freed[count, 0], freed[count, 1] = _remove_vertex(moved, cells, neighbors, v, t, infinite, work)
            if merged < 0:
                return NOT_VALID, flips
            for k in range(2):  # marked free: a later walk must not take one for the cell of a vertex
                cells[freed[count, k], :] = infinite
                changed[freed[count, k]] = False
            removed[count] = v
            count += 1
            live = merged
        # Delaunay again around the holes (edges between unchanged cells still are), so that
        # each insertion's own flips leave a Delaunay triangulation: no pass over every edge
        more = _lawson_around(moved, cells, neighbors, infinite, max_flips, np.flatnonzero(changed), work)
        if more < 0:
            return NOT_VALID, flips
        flips += more
        for k in range(count):
            v = removed[k]
            moved[v, 0] = wanted[v, 0]
            moved[v, 1] = wanted[v, 1]
            outcome, live, state, stack = _insert(
                moved, cells, neighbors, v, freed[k, 0], freed[k, 1], live, state, stack, infinite, work
            )
            if outcome != INSERTED:
                return NOT_VALID, flips
    copy_rows(held, moved, held.shape[0])
    return OK, flips


@numba.njit(cache=True, inline="always")
def _mark_star(cells, neighbors, v, t, changed):
    """Mark in ``changed`` the cells around vertex ``v``, starting from its cell ``t``.

    A vertex's removal rewrites only these: marked while ``v`` is still in them.
    """
    c = t
    while True:
        changed[c] = True
        c = neighbors[c, (_corner_of(cells, c, v) + 1) % 3]
        if c == t:
            break


@numba.njit(cache=True)
def _highest_in_star(cells, neighbors, v, t):
    """The highest-numbered cell around interior vertex ``v``, given one of them, ``t``."""
    highest = t
    c = neighbors[t, (_corner_of(cells, t, v) + 1) % 3]
    while c != t:
        highest = max(highest, c)
        c = neighbors[c, (_corner_of(cells, c, v) + 1) % 3]
    return highest


@numba.njit(cache=True)
def _cells_of(points, cells, neighbors, doomed, infinite, work):
    """For each vertex ``doomed`` marks, the highest-numbered cell that has it (-1 for the others).

    A few vertices are each found by a walk (the length of the mesh's side
    in steps) and a turn around it; many, by a pass over all the cells. The
    two give the same cells.
    """
    n = points.shape[0]
    m = cells.shape[0]
    cell_of = np.full(n, -1, dtype=np.int64)
    count = 0
    for v in range(n):
        count += doomed[v]
    if count * _WALK_STEPS * np.sqrt(m) < m:
        state = np.int64(54321)
        reached = True
        for v in range(n):
            if doomed[v] and reached:
                t, where, corner, state = _locate(
                    points, cells, neighbors, np.int64(0), v, infinite, state, np.int64(_NO_STEP_LIMIT), work
                )
                reached = where == ON_VERTEX and cells[t, corner] == v  # else the pass below finds them all
                if reached:
                    cell_of[v] = _highest_in_star(cells, neighbors, v, t)
        if reached:
            return cell_of
        cell_of[:] = -1
    for t in range(m):
        for k in range(3):
            if cells[t, k] < n:
                cell_of[cells[t, k]] = t
    return cell_of


@numba.njit(cache=True)
def _without_cells(cells, neighbors, marks, dropped):
    """``cells``, their ``neighbors`` and ``marks`` without the rows ``dropped`` (ascending, no live cell's neighbour).

    Compacted in place, in order (views of the first rows): a few dropped
    cells of a large triangulation cost one pass over it and no new arrays
    (allocating them cost more than the pass at 370k cells).
    """
    m = cells.shape[0]
    k = dropped.shape[0]
    searched = k <= _SEARCHED_DROPS  # a neighbour's new number by a binary search, else from a table
    renumber = np.empty(0 if searched else m, dtype=np.int64)
    j = 0
    for c in range(renumber.shape[0]):
        if j < k and dropped[j] == c:
            j += 1
        renumber[c] = c - j
    j = 0
    count = 0
    for c in range(m):
        if j < k and dropped[j] == c:
            j += 1
            continue
        marks[count] = marks[c]
        for q in range(3):
            cells[count, q] = cells[c, q]
            neighbor = neighbors[c, q]
            if neighbor >= 0:
                neighbor = neighbor - count_below(dropped, neighbor) if searched else renumber[neighbor]
            neighbors[count, q] = neighbor
        count += 1
    return cells[:count], neighbors[:count], marks[:count]


@numba.njit(cache=True)
def remove_points(points, cells, neighbors, doomed, infinite, numbering):
    """Remove the vertices marked in ``doomed`` (none on the hull) and make the rest Delaunay again.

    Only the cells around the removed vertices change, so only their edges
    are tested for flips afterwards. Returns ``(status, cells,
    neighbors)``: the cells compacted, their vertices renumbered by
    ``numbering`` (``infinite`` included: shape ``(infinite + 1,)``);
    status NOT_VALID, with the cells as they were left, when a doomed
    vertex is on the hull or cannot be removed.
    """
    work = np.empty(WORK_SIZE)
    n = points.shape[0]
    m = cells.shape[0]
    cell_of = _cells_of(points, cells, neighbors, doomed, infinite, work)
    changed = np.zeros(m, dtype=np.bool_)
    freed = np.empty(2 * n, dtype=np.int64)
    n_freed = 0
    state = np.int64(12345)
    live = np.int64(0)
    for v in range(n):
        if not doomed[v]:
            continue
        t, state = _cell_with_vertex(points, cells, neighbors, v, cell_of[v], live, infinite, state, work)
        if t < 0:
            return NOT_VALID, cells, neighbors
        _mark_star(cells, neighbors, v, t, changed)
        merged, free1, free2 = _remove_vertex(points, cells, neighbors, v, t, infinite, work)
        if merged < 0:
            return NOT_VALID, cells, neighbors
        for k in range(3):
            cell_of[cells[merged, k]] = merged  # the three vertices that may have pointed at a freed cell
        live = merged
        freed[n_freed] = free1
        freed[n_freed + 1] = free2
        n_freed += 2
        # parked out of the way: a free cell must not be walked into or flipped
        for k in range(3):
            cells[free1, k] = infinite
            cells[free2, k] = infinite
            neighbors[free1, k] = free1
            neighbors[free2, k] = free2
    out_cells, out_neighbors, changed = _without_cells(cells, neighbors, changed, _sort_keys(freed[:n_freed])[1])
    seeds = np.flatnonzero(changed)  # the changed cells' numbers among the compacted ones
    if _lawson_around(points, out_cells, out_neighbors, infinite, 10 * out_cells.shape[0] + 10000, seeds, work) < 0:
        return NOT_VALID, out_cells, out_neighbors
    for t in range(out_cells.shape[0]):
        for k in range(3):
            out_cells[t, k] = numbering[out_cells[t, k]]
    return OK, out_cells, out_neighbors
