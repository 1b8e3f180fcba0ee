"""Gradient limiting of a mesh size grid (Persson 2006) by fast sweeping.

The steady state of Persson's gradient-limiting equation
``dh/dt + |grad h| = min(|grad h|, g)`` started from ``h0``, discretised with
an upwind ``|grad h|`` on a Cartesian grid, is the largest ``h <= h0`` whose
upwind gradient norm is at most ``g`` at every node. At a node whose size
is limited, ``h`` solves ``F(h) = g**2`` with

* ``PERSSON``: ``F(h) = sum over the four neighbours a, on axis k, of
  max(h - a, 0)**2 / d_k**2`` (``max(D-, 0)**2 + min(D+, 0)**2`` per axis, as
  in Persson's paper);
* ``GODUNOV``: ``F(h) = sum over axes k of max(h - min(a_k-, a_k+), 0)**2 / d_k**2``
  (the Godunov / Rouy-Tourin Hamiltonian, one upwind neighbour per axis).

Both are monotone and causal (a node only depends on smaller neighbours), so
the solution is the fixed point of ``h_i = min(h_i, solve_i(neighbours))``.
It is reached by Gauss-Seidel sweeps in the four axis orderings, repeated
until a sweep changes nothing (Zhao 2005). Measured on 2000 x 2000 grids this
is 10-20 times faster than the fast-marching (heap) order, whose heap
operations cost more than the few extra sweeps.

Private: arrays are C-contiguous float64 and unvalidated; the public wrapper
is :func:`terramesh.sizing.limit_gradient`. Written for 2D; 3D adds a third
neighbour pair per node (six terms for PERSSON, three for GODUNOV, same
sorted incremental solve), eight sweep orderings, and wavefronts over planes.
"""

import numba
import numpy as np

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
# rare three- and four-term path, which keeps the first compile near 7 s.


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
def _sorted_terms(a0, w0, a1, w1, a2, w2, a3, w3, g2):
    """Root of ``sum_k w_k max(u - a_k, 0)**2 = g2`` for ``a0 <= a1 <= a2 <= a3``.

    Adds terms in increasing order while the root so far lies above the
    next value; the pairwise form of the discriminant,
    ``g2 sum w - sum_{k<l} w_k w_l (a_k - a_l)**2``, avoids cancellation.
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
    return a0 + (moment + np.sqrt(max(g2 * weight - pairs, 0.0))) / weight


@numba.njit(cache=True, inline="always")
def _godunov_solve(ax, ay, c):
    """Limited size from the smaller x neighbour ``ax`` and y neighbour ``ay``."""
    wx, wy, gdx, gdy, g2, inverse_xy = c[0], c[1], c[2], c[3], c[4], c[5]
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
def _persson_solve(xl, xr, yl, yr, c):
    """Limited size from the four neighbours (x left/right, y left/right)."""
    wx, wy, gdx, gdy, g2, inverse_xy, inverse_xx, inverse_yy = c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]
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
    return _sorted_terms(a0, w0, a1, w1, a2, w2, a3, w3, g2)


@numba.njit(cache=True, inline="always")
def _node(before, row, after, iy, ny, c, limit2, scheme):
    """New value of ``row[iy]``: itself, or lower where its upwind gradient exceeds g.

    ``before`` and ``after`` are the neighbouring rows along x (a row of
    +inf beyond the grid edge, which never enters the upwind terms).
    """
    wx = c[0]
    wy = c[1]
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
        return _persson_solve(xl, xr, yl, yr, c)
    ax = min(xl, xr)
    ay = min(yl, yr)
    a = max(h - ax, 0.0)
    e = max(h - ay, 0.0)
    if wx * a * a + wy * e * e <= limit2:
        return h
    return _godunov_solve(ax, ay, c)


@numba.njit(cache=True, inline="always")
def _lower(row, iy, value):
    """Store ``value`` if it is lower; 1 if it was."""
    if value < row[iy]:
        row[iy] = value
        return 1
    return 0


@numba.njit(cache=True)
def _sweep_row(before, row, after, ny, forward, c, limit2, scheme):
    """Gauss-Seidel pass over one row; returns how many nodes decreased."""
    changed = 0
    if forward:
        for iy in range(ny):
            changed += _lower(row, iy, _node(before, row, after, iy, ny, c, limit2, scheme))
    else:
        for iy in range(ny - 1, -1, -1):
            changed += _lower(row, iy, _node(before, row, after, iy, ny, c, limit2, scheme))
    return changed


@numba.njit(cache=True)
def _sweep_band(before, r0, r1, r2, r3, after, ny, forward, c, limit2, scheme, changed):
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
            changed[0] += _lower(r0, i0, _node(before, r0, r1, i0, ny, c, limit2, scheme))
        if 0 <= i1 < ny:
            changed[1] += _lower(r1, i1, _node(r0, r1, r2, i1, ny, c, limit2, scheme))
        if 0 <= i2 < ny:
            changed[2] += _lower(r2, i2, _node(r1, r2, r3, i2, ny, c, limit2, scheme))
        if 0 <= i3 < ny:
            changed[3] += _lower(r3, i3, _node(r2, r3, after, i3, ny, c, limit2, scheme))


@numba.njit(cache=True)
def limit_gradient_2d(h, dx, dy, grade, scheme):
    """Lower ``h`` in place to the gradient-limited size field; returns the sweep count.

    ``h`` (nx, ny) C-contiguous float64, positive and finite, indexed
    ``[ix, iy]``; ``dx``, ``dy`` > 0 the node spacings; ``grade`` > 0;
    ``scheme`` PERSSON or GODUNOV.
    """
    nx, ny = h.shape
    wx = 1.0 / (dx * dx)
    wy = 1.0 / (dy * dy)
    g2 = grade * grade
    c = (wx, wy, grade * dx, grade * dy, g2, 1.0 / (wx + wy), 0.5 / wx, 0.5 / wy)
    limit2 = g2 * (1.0 + SLACK)
    edge = np.full(ny, np.inf)
    # Rows to visit: a row needs a pass only if it or a neighbouring row
    # changed since its last pass, which makes the last few sweeps cheap.
    dirty = np.ones(nx, np.bool_)
    marked = np.zeros(nx, np.bool_)
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
        while k < nx:
            ix = k if step == 1 else nx - 1 - k
            rows = min(4, nx - k)
            visit = marked[ix]
            for j in range(rows):
                visit = visit or dirty[ix + j * step]
            if visit:
                before = h[ix - step] if 0 <= ix - step < nx else edge
                if rows == 4:
                    last = ix + 4 * step
                    after = h[last] if 0 <= last < nx else edge
                    changed[:] = 0
                    _sweep_band(
                        before,
                        h[ix],
                        h[ix + step],
                        h[ix + 2 * step],
                        h[ix + 3 * step],
                        after,
                        ny,
                        forward,
                        c,
                        limit2,
                        scheme,
                        changed,
                    )
                else:
                    for j in range(rows):
                        r = ix + j * step
                        before = h[r - step] if 0 <= r - step < nx else edge
                        after = h[r + step] if 0 <= r + step < nx else edge
                        changed[j] = _sweep_row(before, h[r], after, ny, forward, c, limit2, scheme)
                for j in range(rows):
                    if changed[j]:
                        total += changed[j]
                        r = ix + j * step
                        for q in range(max(r - 1, 0), min(r + 2, nx)):
                            marked[q] = True
            k += rows
        if total == 0:
            return sweeps
        dirty, marked = marked, dirty
