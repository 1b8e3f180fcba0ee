"""Gradient limiting of a mesh size grid (Persson 2006) by fast sweeping.

The steady state of Persson's gradient-limiting equation
``dh/dt + |grad h| = min(|grad h|, g)`` started from ``h0``, discretised with
an upwind ``|grad h|`` on a Cartesian grid, is the largest ``h <= h0`` whose
upwind gradient norm is at most ``g`` at every node. At a node whose size
is limited, ``h`` solves ``F(h) = g**2`` with

* ``PERSSON``: ``F(h) = sum over the 2 * dim neighbours a, on axis k, of
  max(h - a, 0)**2 / d_k**2`` (``max(D-, 0)**2 + min(D+, 0)**2`` per axis, as
  in Persson's paper);
* ``GODUNOV``: ``F(h) = sum over axes k of max(h - min(a_k-, a_k+), 0)**2 / d_k**2``
  (the Godunov / Rouy-Tourin Hamiltonian, one upwind neighbour per axis).

Both are monotone and causal (a node only depends on smaller neighbours), so
the solution is the fixed point of ``h_i = min(h_i, solve_i(neighbours))``,
``solve_i`` being the root of ``F = g**2``, whose terms are the neighbours
below the root. It is reached by Gauss-Seidel sweeps in the ``2**dim`` axis
orderings, repeated until a sweep changes nothing (Zhao 2005).
Measured on 2000 x 2000 grids this is 10-20 times faster than the
fast-marching (heap) order, whose heap operations cost more than the few
extra sweeps.

Private: arrays are C-contiguous float64 and unvalidated; the public wrapper
is :func:`terramesh.sizing.limit_gradient`. :func:`limit_gradient_2d` sweeps
rows along y, four at a time as a skewed wavefront, in two blocks of rows
side by side; :func:`limit_gradient_3d`
sweeps rows along z the same way, four neighbouring rows of an x-plane at a
time, in two blocks of x-planes side by side, with six neighbour terms per
node for PERSSON and three for GODUNOV.
"""

import numba
import numpy as np
from numba.core import types
from numba.extending import overload

PERSSON = 0
GODUNOV = 1

# A node is re-solved only when F(h) exceeds g**2 by more than this relative
# slack. Without it, nodes already on F(h) = g**2 fail the test half the time
# through rounding and get re-solved (to the same value) on every sweep, which
# costs more than the sweeps themselves; with it, |grad h| ends within
# g * (1 + SLACK / 2), far below any meshing tolerance.
SLACK = 1e-13

# Per-node functions are inlined into the sweeps (numba does not inline
# across njit functions otherwise; measured 2.5x slower without), except the
# rare PERSSON ridge paths (a node above both neighbours on an axis), which
# keeps the first compile of each kernel under about 10 s.


@numba.njit(cache=True)
def _ordered(a, wa, b, wb):
    """The two (value, weight) terms with the smaller value first."""
    if b < a:
        return b, wb, a, wa
    return a, wa, b, wb


@numba.njit(cache=True, inline="always")
def _two_terms(a, wa, b, wb, g2, inverse_weight):
    """Root above ``b`` of ``wa (u - a)**2 + wb (u - b)**2 = g2``, ``a <= b``.

    Written relative to ``a`` because ``u**2`` and ``a**2`` are much larger than
    ``g2 / w`` on fine grids, and the textbook quadratic loses most digits.
    ``inverse_weight`` is ``1 / (wa + wb)``, precomputed to keep a division
    off the sweep's dependency chain.
    """
    d = b - a
    discriminant = g2 * (wa + wb) - wa * wb * d * d
    return a + (wb * d + np.sqrt(max(discriminant, 0.0))) * inverse_weight


@numba.njit(cache=True)
def _sorted_terms(a0, w0, a1, w1, a2, w2, a3, w3, a4, w4, a5, w5, g2):
    """Root of ``sum_k w_k max(u - a_k, 0)**2 = g2`` for ``a0 <= a1 <= ... <= a5``.

    Adds terms in increasing order while the root so far lies above the
    next value; the pairwise form of the discriminant,
    ``g2 sum w - sum_{k<l} w_k w_l (a_k - a_l)**2``, avoids cancellation.
    Fewer terms are passed as ``a_k = inf``, which are never reached.
    """
    u = a0 + np.sqrt(g2 / w0)
    if u <= a1:
        return u
    d1 = a1 - a0
    weight = w0 + w1
    moment = w1 * d1
    pairs = w0 * w1 * d1 * d1
    u = a0 + (moment + np.sqrt(max(g2 * weight - pairs, 0.0))) / weight
    if u <= a2:
        return u
    d2 = a2 - a0
    pairs += w2 * (w0 * d2 * d2 + w1 * (d2 - d1) * (d2 - d1))
    weight += w2
    moment += w2 * d2
    u = a0 + (moment + np.sqrt(max(g2 * weight - pairs, 0.0))) / weight
    if u <= a3:
        return u
    d3 = a3 - a0
    pairs += w3 * (w0 * d3 * d3 + w1 * (d3 - d1) * (d3 - d1) + w2 * (d3 - d2) * (d3 - d2))
    weight += w3
    moment += w3 * d3
    u = a0 + (moment + np.sqrt(max(g2 * weight - pairs, 0.0))) / weight
    if u <= a4:
        return u
    d4 = a4 - a0
    pairs += w4 * (w0 * d4 * d4 + w1 * (d4 - d1) * (d4 - d1) + w2 * (d4 - d2) * (d4 - d2) + w3 * (d4 - d3) * (d4 - d3))
    weight += w4
    moment += w4 * d4
    u = a0 + (moment + np.sqrt(max(g2 * weight - pairs, 0.0))) / weight
    if u <= a5:
        return u
    d5 = a5 - a0
    pairs += w5 * (
        w0 * d5 * d5
        + w1 * (d5 - d1) * (d5 - d1)
        + w2 * (d5 - d2) * (d5 - d2)
        + w3 * (d5 - d3) * (d5 - d3)
        + w4 * (d5 - d4) * (d5 - d4)
    )
    weight += w5
    moment += w5 * d5
    return a0 + (moment + np.sqrt(max(g2 * weight - pairs, 0.0))) / weight


@numba.njit(cache=True)  # a plain call: inlined four times over in a band, it doubled the compile time
def _godunov_solve(ax, ay, c, grade):
    """Limited size from the smaller x neighbour ``ax`` and y neighbour ``ay``."""
    wx, wy, gdx, gdy, g2, inverse_xy = c[0], c[1], grade * c[2], grade * c[3], grade * grade, c[4]
    # One term (u = a + g d) is the common case and needs no square root.
    if ax <= ay:
        u = ax + gdx
        if u <= ay:
            return u
        return _two_terms(ax, wx, ay, wy, g2, inverse_xy)
    u = ay + gdy
    if u <= ax:
        return u
    return _two_terms(ay, wy, ax, wx, g2, inverse_xy)


@numba.njit(cache=True, inline="always")
def _persson_solve(xl, xr, yl, yr, c, grade):
    """Limited size from the four neighbours (x left/right, y left/right)."""
    wx, wy, gdx, gdy, inverse_xy, inverse_xx, inverse_yy = c[0], c[1], grade * c[2], grade * c[3], c[4], c[5], c[6]
    g2 = grade * grade
    x0 = min(xl, xr)
    x1 = max(xl, xr)
    y0 = min(yl, yr)
    y1 = max(yl, yr)
    # One or two upwind terms cover all but ridge nodes; try them without sorting.
    if x0 <= y0:
        u = x0 + gdx
        if u <= min(x1, y0):
            return u
        if y0 <= x1:
            u = _two_terms(x0, wx, y0, wy, g2, inverse_xy)
            if u <= min(x1, y1):
                return u
        else:
            u = _two_terms(x0, wx, x1, wx, g2, inverse_xx)
            if u <= y0:
                return u
    else:
        u = y0 + gdy
        if u <= min(y1, x0):
            return u
        if x0 <= y1:
            u = _two_terms(y0, wy, x0, wx, g2, inverse_xy)
            if u <= min(x1, y1):
                return u
        else:
            u = _two_terms(y0, wy, y1, wy, g2, inverse_yy)
            if u <= x0:
                return u
    # Three or four upwind terms: sort the pairs (x0 <= x1, y0 <= y1) merged.
    a0, w0, a2, w2 = _ordered(x0, wx, y0, wy)
    a1, w1, a3, w3 = _ordered(x1, wx, y1, wy)
    a1, w1, a2, w2 = _ordered(a1, w1, a2, w2)
    return _sorted_terms(a0, w0, a1, w1, a2, w2, a3, w3, np.inf, 0.0, np.inf, 0.0, g2)


def _grade_at(grades, iy):
    """The grade at ``iy``: ``grades[iy]``, or ``grades`` itself when it is one number."""
    return grades if np.ndim(grades) == 0 else grades[iy]


@overload(_grade_at, inline="always")
def _grade_at_compiled(grades, iy):
    # one number is compiled apart from an array, as the kernel was before grades per row: 4-11 % faster
    if isinstance(grades, types.Float):
        return lambda grades, iy: grades
    return lambda grades, iy: grades[iy]


@numba.njit(cache=True, inline="always")
def _node(before, row, after, iy, ny, c, grades, scheme):
    """New value of ``row[iy]``: itself, or lower where its upwind gradient exceeds its row's grade.

    ``before`` and ``after`` are the neighbouring rows along x (a row of
    +inf beyond the grid edge, which never enters the upwind terms).
    """
    wx = c[0]
    wy = c[1]
    grade = _grade_at(grades, iy)
    limit2 = grade * grade * (1.0 + SLACK)
    h = row[iy]
    xl = before[iy]
    xr = after[iy]
    yl = row[iy - 1] if iy > 0 else np.inf
    yr = row[iy + 1] if iy < ny - 1 else np.inf
    # F(h) > g**2 is the cheap exact test for "can decrease"; only then solve.
    if scheme == PERSSON:
        a = max(h - xl, 0.0)
        b = max(h - xr, 0.0)
        e = max(h - yl, 0.0)
        f = max(h - yr, 0.0)
        if wx * (a * a + b * b) + wy * (e * e + f * f) <= limit2:
            return h
        return _persson_solve(xl, xr, yl, yr, c, grade)
    ax = min(xl, xr)
    ay = min(yl, yr)
    a = max(h - ax, 0.0)
    e = max(h - ay, 0.0)
    if wx * a * a + wy * e * e <= limit2:
        return h
    return _godunov_solve(ax, ay, c, grade)


@numba.njit(cache=True, inline="always")
def _lower(row, iy, value):
    """Store ``value`` if it is lower; 1 if it was."""
    if value < row[iy]:
        row[iy] = value
        return 1
    return 0


@numba.njit(cache=True)
def _sweep_row(before, row, after, ny, forward, c, grades, scheme):
    """Gauss-Seidel pass over one row; returns how many nodes decreased."""
    changed = 0
    if forward:
        for iy in range(ny):
            changed += _lower(row, iy, _node(before, row, after, iy, ny, c, grades, scheme))
    else:
        for iy in range(ny - 1, -1, -1):
            changed += _lower(row, iy, _node(before, row, after, iy, ny, c, grades, scheme))
    return changed


@numba.njit(cache=True)
def _sweep_band(before, r0, r1, r2, r3, after, ny, forward, c, grades, scheme, changed):
    """Gauss-Seidel pass over four rows (in sweep order), as a skewed wavefront.

    Row ``k`` runs ``k`` nodes behind row ``k - 1``, so the four nodes of a
    step do not depend on each other and the CPU overlaps their square
    roots; a plain row-by-row pass is bound by the latency of one node
    waiting for the previous one. Each node still sees exactly the
    neighbour values of the row-by-row order, so the results are identical.
    """
    for t in range(ny + 3):
        if forward:
            i0, i1, i2, i3 = t, t - 1, t - 2, t - 3
        else:
            i0, i1, i2, i3 = ny - 1 - t, ny - t, ny + 1 - t, ny + 2 - t
        if 0 <= i0 < ny:
            changed[0] += _lower(r0, i0, _node(before, r0, r1, i0, ny, c, grades, scheme))
        if 0 <= i1 < ny:
            changed[1] += _lower(r1, i1, _node(r0, r1, r2, i1, ny, c, grades, scheme))
        if 0 <= i2 < ny:
            changed[2] += _lower(r2, i2, _node(r1, r2, r3, i2, ny, c, grades, scheme))
        if 0 <= i3 < ny:
            changed[3] += _lower(r3, i3, _node(r2, r3, after, i3, ny, c, grades, scheme))


# Rows of a 2D grid are swept in this many blocks side by side (one thread each), every block against
# copies of its neighbours' edge rows, again until no edge row changes: on the guide's §5.3 grid (5483 x
# 7172) 2.1-2.8 s in one block, 1.4-1.6 s in two; four were slower on 2 cores (more rounds). A fixed
# number, not one per thread, so that the sizes are the same on any machine (the order of the sweeps
# changes the last bit of a few nodes: 0.35 % of §5.3's, by 2e-15 at most).
_BLOCKS = 2
_BLOCK_ROWS = 64  # fewer rows per block than this: one block (the edges would cost more rounds than they save)


@numba.njit(cache=True)
def _converge(h, lo, hi, first_before, last_after, dirty, c, grades, scheme):
    """Sweep the rows ``lo:hi`` of ``h`` until a sweep changes nothing; returns the sweep count.

    Row ``lo``'s outer neighbour is ``first_before``, row ``hi - 1``'s is
    ``last_after`` (rows held fixed: copies, or +inf beyond the grid);
    ``dirty`` (``hi - lo``,) marks the rows to visit in the first sweep.
    """
    n = hi - lo
    ny = h.shape[1]
    marked = np.zeros(n, np.bool_)
    changed = np.zeros(4, np.int64)
    sweeps = 0
    # Terminates: a pass only lowers values, each by a relative amount of at
    # least about SLACK, and values never go below the solution.
    while True:
        order = sweeps % 4
        sweeps += 1
        step = 1 if order < 2 else -1
        forward = order == 0 or order == 3
        total = 0
        marked[:] = False
        k = 0
        while k < n:
            ix = k if step == 1 else n - 1 - k
            rows = min(4, n - k)
            visit = marked[ix]
            for j in range(rows):
                visit = visit or dirty[ix + j * step]
            if visit:
                if rows == 4:
                    changed[:] = 0
                    _sweep_band(
                        _block_row(h, lo, n, ix - step, first_before, last_after),
                        h[lo + ix],
                        h[lo + ix + step],
                        h[lo + ix + 2 * step],
                        h[lo + ix + 3 * step],
                        _block_row(h, lo, n, ix + 4 * step, first_before, last_after),
                        ny,
                        forward,
                        c,
                        grades,
                        scheme,
                        changed,
                    )
                else:
                    for j in range(rows):
                        r = ix + j * step
                        before = _block_row(h, lo, n, r - step, first_before, last_after)
                        after = _block_row(h, lo, n, r + step, first_before, last_after)
                        changed[j] = _sweep_row(before, h[lo + r], after, ny, forward, c, grades, scheme)
                for j in range(rows):
                    if changed[j]:
                        total += changed[j]
                        r = ix + j * step
                        for q in range(max(r - 1, 0), min(r + 2, n)):
                            marked[q] = True
            k += rows
        if total == 0:
            return sweeps
        dirty, marked = marked, dirty


@numba.njit(cache=True, inline="always")
def _block_row(h, lo, n, r, first_before, last_after):
    """Row ``r`` of the block of ``n`` rows from ``lo``, or the fixed row beyond its edge."""
    if r < 0:
        return first_before
    if r >= n:
        return last_after
    return h[lo + r]


@numba.njit(cache=True, parallel=True)
def converge_blocks(h, bounds, edges, dirty, sweeps, dx, dy, grades, scheme):
    """:func:`_converge` on each block of rows ``bounds[b]:bounds[b + 1]`` of ``h``, side by side.

    Block ``b``'s fixed outer rows are ``edges[2 b]`` and ``edges[2 b + 1]``
    and its rows to visit first ``dirty[bounds[b]:bounds[b + 1]]``; its
    sweeps are added to ``sweeps[b]``. A kernel of its own, called from
    Python (see :func:`limit_gradient_2d`): the whole driver compiled as a
    parallel kernel took 22 s to compile, against 11 s for the one-block
    kernel before it.
    """
    wx = 1.0 / (dx * dx)
    wy = 1.0 / (dy * dy)
    c = (wx, wy, dx, dy, 1.0 / (wx + wy), 0.5 / wx, 0.5 / wy)
    for b in numba.prange(bounds.size - 1):
        lo, hi = bounds[b], bounds[b + 1]
        sweeps[b] += _converge(h, lo, hi, edges[2 * b], edges[2 * b + 1], dirty[lo:hi].copy(), c, grades, scheme)


def _block_bounds(n, least):
    """The first row (or plane) of each of ``_BLOCKS`` blocks of ``n``, and ``n``; one block under ``least`` a block."""
    blocks = _BLOCKS if n >= _BLOCKS * least else 1
    return np.array([(n * b) // blocks for b in range(blocks + 1)], dtype=np.int64)


def _in_rounds(h, least, converge):
    """Sweep ``h`` in blocks along its first axis, in rounds until no block's edge changes; the most sweeps of a block.

    ``converge(bounds, edges, dirty, sweeps)`` converges each block of
    ``h[bounds[b]:bounds[b + 1]]`` side by side against its fixed outer
    rows (2D) or planes (3D) ``edges[2 b]`` and ``edges[2 b + 1]`` (+inf at
    the grid's), visiting first the rows ``dirty`` marks (``h[ix]`` in 2D,
    ``h[ix, iy]`` in 3D), and adds its sweeps to ``sweeps[b]``. After a
    round, the edges are copied again; a block visits again only the rows
    beside an edge row that changed, and when none did, every node holds
    its limit against its actual neighbours.
    """
    bounds = _block_bounds(h.shape[0], least)
    blocks = bounds.size - 1
    edges = np.full((2 * blocks, *h.shape[1:]), np.inf)
    # Rows to visit: a row needs a pass only if it or a neighbouring row
    # changed since its last pass, which makes the last few sweeps cheap.
    dirty = np.ones(h.shape[:-1], dtype=np.bool_)
    sweeps = np.zeros(blocks, dtype=np.int64)
    inner, outer = bounds[1:-1], bounds[1:-1] - 1  # the first row of each block but the first, the row before it
    while True:
        edges[2:-1:2] = h[outer]  # each block's edge before it, but the first block's
        edges[1:-2:2] = h[inner]  # each block's edge after it, but the last block's
        converge(bounds, edges, dirty, sweeps)
        before_changed = np.any(h[outer] != edges[2:-1:2], axis=-1)  # per row of the edge
        after_changed = np.any(h[inner] != edges[1:-2:2], axis=-1)
        if not (before_changed.any() or after_changed.any()):
            return int(sweeps.max())
        dirty[:] = False
        dirty[inner] = before_changed  # a block whose edge before changed visits its first rows beside it again
        dirty[outer] = after_changed  # and one whose edge after changed, its last


def limit_gradient_2d(h, dx, dy, grades, scheme):
    """Lower ``h`` in place to the gradient-limited size field; returns the most sweeps of a block.

    ``h`` (nx, ny) C-contiguous float64, positive and finite, indexed
    ``[ix, iy]``; ``dx``, ``dy`` > 0 the node spacings; ``grades`` (ny,)
    C-contiguous float64, finite and > 0, the grade at each ``iy`` (the
    kernel's rows ``h[ix]`` run along y, so it varies along each row), or
    one float; ``scheme`` PERSSON or GODUNOV. The rows are swept in
    ``_BLOCKS`` blocks side by side (:func:`converge_blocks`), each
    against copies of the rows beyond its edges, in rounds until no edge
    row changed in a round: then every node holds its limit against its
    actual neighbours, the fixed point the row-by-row sweeps reach. The
    rounds run here in Python (four or five on the §5.3 grid): a kernel
    that calls a parallel kernel cannot be cached apart from it.
    """
    return _in_rounds(h, _BLOCK_ROWS, lambda *blocks: converge_blocks(h, *blocks, float(dx), float(dy), grades, scheme))


# 3D: rows run along z (the contiguous axis); a node's x and y neighbours
# sit at the same index of the four neighbouring rows.


@numba.njit(cache=True, inline="always")
def _excess(t):
    """``max(t, 0)**2``: one term of F."""
    t = max(t, 0.0)
    return t * t


@numba.njit(cache=True, inline="always")
def _three_terms(ax, ay, az, c):
    """Root of ``sum over axes k of w_k max(u - a_k, 0)**2 = g2`` (one value per axis).

    A value is a term of the root exactly when F at that value is below
    ``g2`` (F increases), so the terms are found without sorting: no
    branches for the CPU to mispredict, about twice as fast as sorting on
    random sizes. The root is the pairwise form of :func:`_sorted_terms`.
    """
    wx, wy, wz, g2 = c[0], c[1], c[2], c[3]
    a0 = min(ax, min(ay, az))
    # Values above a0 + grade * (largest spacing) are never terms; capping
    # them keeps inf (beyond the grid edge) out of the arithmetic.
    top = a0 + c[4]
    ax = min(ax, top)
    ay = min(ay, top)
    az = min(az, top)
    fx = wy * _excess(ax - ay) + wz * _excess(ax - az)
    fy = wx * _excess(ay - ax) + wz * _excess(ay - az)
    fz = wx * _excess(az - ax) + wy * _excess(az - ay)
    vx = wx if fx < g2 else 0.0
    vy = wy if fy < g2 else 0.0
    vz = wz if fz < g2 else 0.0
    tx = ax - a0 if fx < g2 else 0.0
    ty = ay - a0 if fy < g2 else 0.0
    tz = az - a0 if fz < g2 else 0.0
    weight = vx + vy + vz
    moment = vx * tx + vy * ty + vz * tz
    pairs = vx * (vy * (tx - ty) * (tx - ty) + vz * (tx - tz) * (tx - tz)) + vy * vz * (ty - tz) * (ty - tz)
    return a0 + (moment + np.sqrt(max(g2 * weight - pairs, 0.0))) / weight


@numba.njit(cache=True)
def _persson_ridge_3d(x0, x1, y0, y1, z0, z1, c):
    """Persson's root where an upper neighbour is upwind too (a ridge): all six values, pairs ``x0 <= x1`` etc."""
    a0, w0, a2, w2 = _ordered(x0, c[0], y0, c[1])
    a1, w1, a3, w3 = _ordered(x1, c[0], y1, c[1])
    a1, w1, a2, w2 = _ordered(a1, w1, a2, w2)
    # insert z0, then z1 >= z0, into the sorted four
    a3, w3, a4, w4 = _ordered(a3, w3, z0, c[2])
    a2, w2, a3, w3 = _ordered(a2, w2, a3, w3)
    a1, w1, a2, w2 = _ordered(a1, w1, a2, w2)
    a0, w0, a1, w1 = _ordered(a0, w0, a1, w1)
    a4, w4, a5, w5 = _ordered(a4, w4, z1, c[2])
    a3, w3, a4, w4 = _ordered(a3, w3, a4, w4)
    a2, w2, a3, w3 = _ordered(a2, w2, a3, w3)
    a1, w1, a2, w2 = _ordered(a1, w1, a2, w2)
    return _sorted_terms(a0, w0, a1, w1, a2, w2, a3, w3, a4, w4, a5, w5, c[3])


@numba.njit(cache=True, inline="always")
def _node_3d(x_before, x_after, y_before, row, y_after, iz, nz, c, limit2, scheme):
    """New value of ``row[iz]``, given its neighbouring rows along x and y (+inf rows beyond the grid)."""
    wx = c[0]
    wy = c[1]
    wz = c[2]
    h = row[iz]
    xl = x_before[iz]
    xr = x_after[iz]
    yl = y_before[iz]
    yr = y_after[iz]
    zl = row[iz - 1] if iz > 0 else np.inf
    zr = row[iz + 1] if iz < nz - 1 else np.inf
    if scheme == PERSSON:
        a = max(h - xl, 0.0)
        b = max(h - xr, 0.0)
        e = max(h - yl, 0.0)
        f = max(h - yr, 0.0)
        k = max(h - zl, 0.0)
        m = max(h - zr, 0.0)
        if wx * (a * a + b * b) + wy * (e * e + f * f) + wz * (k * k + m * m) <= limit2:
            return h
        x0 = min(xl, xr)
        x1 = max(xl, xr)
        y0 = min(yl, yr)
        y1 = max(yl, yr)
        z0 = min(zl, zr)
        z1 = max(zl, zr)
        # With the lower neighbour per axis only, this is the Godunov root;
        # it is Persson's too unless it lies above an upper neighbour (a ridge).
        u = _three_terms(x0, y0, z0, c)
        if u <= min(x1, min(y1, z1)):
            return u
        return _persson_ridge_3d(x0, x1, y0, y1, z0, z1, c)
    ax = min(xl, xr)
    ay = min(yl, yr)
    az = min(zl, zr)
    a = max(h - ax, 0.0)
    e = max(h - ay, 0.0)
    k = max(h - az, 0.0)
    if wx * a * a + wy * e * e + wz * k * k <= limit2:
        return h
    return _three_terms(ax, ay, az, c)


@numba.njit(cache=True, inline="always")
def _row(h, lo, n, ix, iy, planes, edge):
    """Row ``[ix, iy]`` of the block of ``n`` x-planes from ``lo``: ``h[lo + ix, iy]``, else a fixed row.

    ``planes[0]`` and ``planes[1]`` are the fixed planes before and after
    the block (copies of a neighbouring block's edge plane, or +inf beyond
    the grid); ``edge`` is the +inf row beyond the grid along y.
    """
    if iy < 0 or iy >= h.shape[1]:
        return edge
    if ix < 0:
        return planes[0, iy]
    if ix >= n:
        return planes[1, iy]
    return h[lo + ix, iy]


@numba.njit(cache=True)
def _sweep_row_3d(h, lo, n, ix, iy, planes, edge, forward, c, limit2, scheme):
    """Gauss-Seidel pass over row ``h[lo + ix, iy]``; returns how many nodes decreased."""
    nz = h.shape[2]
    row = h[lo + ix, iy]
    x_before = _row(h, lo, n, ix - 1, iy, planes, edge)
    x_after = _row(h, lo, n, ix + 1, iy, planes, edge)
    y_before = _row(h, lo, n, ix, iy - 1, planes, edge)
    y_after = _row(h, lo, n, ix, iy + 1, planes, edge)
    changed = 0
    if forward:
        for iz in range(nz):
            changed += _lower(row, iz, _node_3d(x_before, x_after, y_before, row, y_after, iz, nz, c, limit2, scheme))
    else:
        for iz in range(nz - 1, -1, -1):
            changed += _lower(row, iz, _node_3d(x_before, x_after, y_before, row, y_after, iz, nz, c, limit2, scheme))
    return changed


@numba.njit(cache=True)
def _sweep_band_3d(h, lo, n, ix, iy, step, planes, edge, forward, c, limit2, scheme, changed):
    """Gauss-Seidel pass over rows ``h[lo + ix, iy + k * step]``, k = 0..3, as a skewed wavefront.

    As :func:`_sweep_band`, within the plane ``ix``: the neighbouring rows
    along x belong to planes that are either done or not yet started in
    this sweep, so the results equal the row-by-row order.
    """
    nz = h.shape[2]
    r0 = h[lo + ix, iy]
    r1 = h[lo + ix, iy + step]
    r2 = h[lo + ix, iy + 2 * step]
    r3 = h[lo + ix, iy + 3 * step]
    before = _row(h, lo, n, ix, iy - step, planes, edge)
    after = _row(h, lo, n, ix, iy + 4 * step, planes, edge)
    p0 = _row(h, lo, n, ix - 1, iy, planes, edge)
    q0 = _row(h, lo, n, ix + 1, iy, planes, edge)
    p1 = _row(h, lo, n, ix - 1, iy + step, planes, edge)
    q1 = _row(h, lo, n, ix + 1, iy + step, planes, edge)
    p2 = _row(h, lo, n, ix - 1, iy + 2 * step, planes, edge)
    q2 = _row(h, lo, n, ix + 1, iy + 2 * step, planes, edge)
    p3 = _row(h, lo, n, ix - 1, iy + 3 * step, planes, edge)
    q3 = _row(h, lo, n, ix + 1, iy + 3 * step, planes, edge)
    for t in range(nz + 3):
        if forward:
            i0, i1, i2, i3 = t, t - 1, t - 2, t - 3
        else:
            i0, i1, i2, i3 = nz - 1 - t, nz - t, nz + 1 - t, nz + 2 - t
        if 0 <= i0 < nz:
            changed[0] += _lower(r0, i0, _node_3d(p0, q0, before, r0, r1, i0, nz, c, limit2, scheme))
        if 0 <= i1 < nz:
            changed[1] += _lower(r1, i1, _node_3d(p1, q1, r0, r1, r2, i1, nz, c, limit2, scheme))
        if 0 <= i2 < nz:
            changed[2] += _lower(r2, i2, _node_3d(p2, q2, r1, r2, r3, i2, nz, c, limit2, scheme))
        if 0 <= i3 < nz:
            changed[3] += _lower(r3, i3, _node_3d(p3, q3, r2, r3, after, i3, nz, c, limit2, scheme))


@numba.njit(cache=True)
def _converge_3d(h, lo, hi, planes, dirty, c, limit2, scheme):
    """Sweep the x-planes ``lo:hi`` of ``h`` until a sweep changes nothing; returns the sweep count.

    ``planes`` (2, ny, nz): the fixed planes before and after the block;
    ``dirty`` (``hi - lo``, ny) marks the rows ``[ix, iy]`` to visit in the
    first sweep.
    """
    n = hi - lo
    ny, nz = h.shape[1], h.shape[2]
    edge = np.full(nz, np.inf)
    # Rows h[ix, iy] to visit, as in 2D: a row needs a pass only if it or
    # one of its four neighbouring rows changed since its last pass.
    marked = np.zeros((n, ny), np.bool_)
    changed = np.zeros(4, np.int64)
    sweeps = 0
    while True:
        # The eight orderings in Gray-code order, one axis reversed at a time.
        order = sweeps % 8
        order ^= order >> 1
        sweeps += 1
        step_x = -1 if order & 4 else 1
        step_y = -1 if order & 2 else 1
        forward = (order & 1) == 0
        total = 0
        marked[:, :] = False
        for kx in range(n):
            ix = kx if step_x == 1 else n - 1 - kx
            k = 0
            while k < ny:
                iy = k if step_y == 1 else ny - 1 - k
                rows = min(4, ny - k)
                visit = False
                for j in range(rows):
                    r = iy + j * step_y
                    visit = visit or dirty[ix, r] or marked[ix, r]
                if visit:
                    if rows == 4:
                        changed[:] = 0
                        _sweep_band_3d(h, lo, n, ix, iy, step_y, planes, edge, forward, c, limit2, scheme, changed)
                    else:
                        for j in range(rows):
                            changed[j] = _sweep_row_3d(
                                h, lo, n, ix, iy + j * step_y, planes, edge, forward, c, limit2, scheme
                            )
                    for j in range(rows):
                        if changed[j]:
                            total += changed[j]
                            r = iy + j * step_y
                            for q in range(max(ix - 1, 0), min(ix + 2, n)):
                                marked[q, r] = True
                            for q in range(max(r - 1, 0), min(r + 2, ny)):
                                marked[ix, q] = True
                k += rows
        if total == 0:
            return sweeps
        dirty, marked = marked, dirty


# A 3D grid's x-planes are swept in _BLOCKS blocks side by side, as a 2D grid's rows.
_BLOCK_PLANES = 16  # fewer planes per block than this: one block


@numba.njit(cache=True, parallel=True)
def converge_blocks_3d(h, bounds, edges, dirty, sweeps, dx, dy, dz, grade, scheme):
    """:func:`_converge_3d` on each block of x-planes ``bounds[b]:bounds[b + 1]`` of ``h``, side by side.

    Block ``b``'s fixed outer planes are ``edges[2 b]`` and ``edges[2 b + 1]``
    and its rows to visit first ``dirty[bounds[b]:bounds[b + 1]]``; its
    sweeps are added to ``sweeps[b]``. Called from Python, as
    :func:`converge_blocks`.
    """
    wx = 1.0 / (dx * dx)
    wy = 1.0 / (dy * dy)
    wz = 1.0 / (dz * dz)
    g2 = grade * grade
    c = (wx, wy, wz, g2, 2.0 * grade * max(dx, max(dy, dz)))
    limit2 = g2 * (1.0 + SLACK)
    for b in numba.prange(bounds.size - 1):
        lo, hi = bounds[b], bounds[b + 1]
        planes = edges[2 * b : 2 * b + 2]
        sweeps[b] += _converge_3d(h, lo, hi, planes, dirty[lo:hi].copy(), c, limit2, scheme)


def limit_gradient_3d(h, dx, dy, dz, grade, scheme):
    """Lower ``h`` in place to the gradient-limited size field; returns the most sweeps of a block.

    ``h`` (nx, ny, nz) C-contiguous float64, positive and finite, indexed
    ``[ix, iy, iz]``; ``dx``, ``dy``, ``dz`` > 0 the node spacings;
    ``grade`` > 0; ``scheme`` PERSSON or GODUNOV. The x-planes are swept in
    blocks side by side (:func:`converge_blocks_3d`) in rounds, as the rows
    of :func:`limit_gradient_2d`; a round after the first visits only the
    rows next to a fixed plane that changed.
    """
    return _in_rounds(
        h,
        _BLOCK_PLANES,
        lambda *blocks: converge_blocks_3d(h, *blocks, float(dx), float(dy), float(dz), float(grade), scheme),
    )
