"""Truss forces of the force-equilibrium mesh generator."""

import numba
import numpy as np

from .chunks import chunk_range, chunk_totals


@numba.njit(cache=True, inline="always")
def _edge(points, target, a, b, dim):
    """Squared length and unscaled rest length of the edge ``(a, b)`` of ``dim``-dimensional points.

    :func:`force_step` passes ``dim`` as a literal 2 or 3, so that the loop
    over the axes unrolls; the others pass ``points.shape[1]`` (unrolled,
    :func:`rest_length_scale` was no faster beyond the spread, and took
    twice as long to compile).
    """
    length2 = 0.0
    for d in range(dim):
        delta = points[a, d] - points[b, d]
        length2 += delta * delta
    return length2, 0.5 * (target[a] + target[b])


@numba.njit(cache=True)
def edge_size_ratios(points, edges, target):
    """Length of each edge over the mean of its ends' target sizes, shape (e,)."""
    ratio = np.empty(edges.shape[0])
    for e in range(edges.shape[0]):
        length2, rest = _edge(points, target, edges[e, 0], edges[e, 1], points.shape[1])
        ratio[e] = np.sqrt(length2) / rest
    return ratio


@numba.njit(cache=True, parallel=True)
def rest_length_scale(points, edges, target, length_factor, chunks):
    """``length_factor * sqrt(sum l**2 / sum r**2)``: what scales the rest lengths ``r`` (Persson & Strang).

    The sums run over ``chunks`` fixed parts of the edges (see :mod:`.chunks`).
    """
    sums = np.zeros((chunks, 2))
    for chunk in numba.prange(chunks):
        start, stop = chunk_range(chunk, edges.shape[0], chunks)
        sum_length2 = 0.0
        sum_rest2 = 0.0
        for e in range(start, stop):
            length2, rest = _edge(points, target, edges[e, 0], edges[e, 1], points.shape[1])
            sum_length2 += length2
            sum_rest2 += rest * rest
        sums[chunk, 0] = sum_length2
        sums[chunk, 1] = sum_rest2
    totals = chunk_totals(sums)
    sum_length2, sum_rest2 = totals[0], totals[1]
    if sum_rest2 == 0.0:  # no edge (no cell inside the domain yet): nothing to scale, and no division by zero
        return length_factor
    return length_factor * np.sqrt(sum_length2 / sum_rest2)


@numba.njit(cache=True)
def short_edge_ends(edges, points, target, scale, n_fixed):
    """One movable end of each edge shorter than half its scaled rest length, as a sorted index array.

    Persson's density control (the rest lengths times ``scale``, from
    :func:`rest_length_scale`, as in :func:`force_step`), removing one end
    instead of both so that a cluster thins out without leaving a hole: the
    end past ``n_fixed``, the second where both are.
    """
    crowded = np.zeros(points.shape[0], dtype=np.bool_)
    for e in range(edges.shape[0]):
        a = edges[e, 0]
        b = edges[e, 1]
        length2, rest = _edge(points, target, a, b, points.shape[1])
        if rest * scale > 2.0 * np.sqrt(length2):
            crowded[b if b >= n_fixed else a] = True
    crowded[:n_fixed] = False
    return np.flatnonzero(crowded)


@numba.njit(cache=True, parallel=True)
def force_step(points, edges, target, scale, time_step, n_fixed, chunks):
    """Move every point but the first ``n_fixed`` by ``time_step`` times its net repulsive spring force.

    Each edge ``(a, b)`` is a spring with rest length
    ``scale * 0.5 * (target[a] + target[b])``, ``scale`` from
    :func:`rest_length_scale` (Persson & Strang 2004), which the caller
    runs: a parallel kernel is called from Python only, never from another
    kernel (``tests/_kernels/test_precompile.py`` says why). Springs only
    push (no attraction). Lengths are computed twice rather than kept: two
    more arrays of one float per edge cost more in memory traffic (and,
    fresh each iteration, in page faults) than the arithmetic.

    ``points`` (n, 2) or (n, 3) float64, ``edges`` (e, 2) int64, ``target`` (n,)
    float64; the edges are summed in ``chunks`` fixed parts, in parallel
    (:mod:`.chunks`; 1 sums them in order). Returns the new (n, dim)
    positions and the (n,) length of each move.
    """
    # dim a literal in each copy of the body: the loops over the axes unroll (27 % faster in 2D and 3D)
    if points.shape[1] == 2:
        return _forces(points, edges, target, scale, time_step, n_fixed, chunks, 2)
    if points.shape[1] != 3:
        raise ValueError("force_step moves 2D or 3D points")
    return _forces(points, edges, target, scale, time_step, n_fixed, chunks, 3)


@numba.njit(cache=True, inline="always")
def _forces(points, edges, target, scale, time_step, n_fixed, chunks, dim):
    """:func:`force_step` for ``dim``-dimensional points."""
    n = points.shape[0]
    force = np.zeros((chunks, n, dim))  # one force array per chunk of edges, added up point by point
    for chunk in numba.prange(chunks):
        start, stop = chunk_range(chunk, edges.shape[0], chunks)
        for e in range(start, stop):
            a = edges[e, 0]
            b = edges[e, 1]
            length2, rest = _edge(points, target, a, b, dim)
            length = np.sqrt(length2)
            push = rest * scale - length
            if push > 0.0 and length > 0.0:
                ratio = push / length
                for d in range(dim):
                    component = ratio * (points[a, d] - points[b, d])
                    force[chunk, a, d] += component
                    force[chunk, b, d] -= component
    moved = np.empty_like(points)
    move = np.zeros(n)
    for i in numba.prange(n):
        if i < n_fixed:
            for d in range(dim):
                moved[i, d] = points[i, d]
            continue
        length2 = 0.0
        for d in range(dim):
            net = force[0, i, d]
            for chunk in range(1, chunks):
                net += force[chunk, i, d]
            step = time_step * net
            moved[i, d] = points[i, d] + step
            length2 += step * step
        move[i] = np.sqrt(length2)
    return moved, move


@numba.njit(cache=True)
def neighbor_lists(edges, n_points):
    """Each point's neighbours along ``edges``, compressed: ``neighbors[indptr[i]:indptr[i + 1]]`` are point ``i``'s."""
    indptr = np.zeros(n_points + 1, dtype=np.int64)
    for e in range(edges.shape[0]):
        indptr[edges[e, 0] + 1] += 1
        indptr[edges[e, 1] + 1] += 1
    for i in range(n_points):
        indptr[i + 1] += indptr[i]
    filled = indptr[:-1].copy()
    neighbors = np.empty(indptr[n_points], dtype=np.int64)
    for e in range(edges.shape[0]):
        a = edges[e, 0]
        b = edges[e, 1]
        neighbors[filled[a]] = b
        filled[a] += 1
        neighbors[filled[b]] = a
        filled[b] += 1
    return indptr, neighbors


@numba.njit(cache=True)
def sweep_step(points, indptr, neighbors, target, scale, relaxation, boundary_relaxation, n_fixed, normal):
    """One Gauss-Seidel sweep of the truss forces of :func:`force_step` over 2D ``points``.

    Point by point, each moves by ``relaxation`` times its net force, taken
    from its neighbours' positions as already moved in this sweep: a push
    crosses the mesh within one sweep instead of one edge per step. From
    thinned lattice points on a graded disk (2,700 points, retriangulated
    every step), 20 sweeps at 0.5 reached the mean quality 60 simultaneous
    steps at 0.3 reach (0.972 against 0.973). Rest lengths are scaled
    once, by ``scale`` from :func:`rest_length_scale` of the positions
    before the sweep. ``indptr`` and
    ``neighbors`` are :func:`neighbor_lists` of the mesh's edges.

    A point with a non-zero unit outward ``normal`` (it was projected onto
    the boundary in the last step) moves by ``boundary_relaxation`` times
    its force, less the outward part, so that the points after it see it on
    the boundary, not outside (the exact projection follows the sweep:
    rounding in the normal would leave it a hair inside). At the full step
    such points slid apart and opened gaps along the boundary in every
    iteration.

    Returns the new (n, 2) positions, the (n,) length of each move, and
    which points lost an outward part (they belong on the boundary).
    """
    n = points.shape[0]
    moved = points.copy()
    move = np.zeros(n)
    clamped = np.zeros(n, dtype=np.bool_)
    for i in range(n_fixed, n):
        x = moved[i, 0]
        y = moved[i, 1]
        fx = 0.0
        fy = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            j = neighbors[k]
            length2, rest = _edge(moved, target, i, j, 2)
            length = np.sqrt(length2)
            push = rest * scale - length
            if push > 0.0 and length > 0.0:
                dx = x - moved[j, 0]
                dy = y - moved[j, 1]
                fx += push / length * dx
                fy += push / length * dy
        nx = normal[i, 0]
        ny = normal[i, 1]
        step = relaxation
        if nx != 0.0 or ny != 0.0:
            step = boundary_relaxation
            outward = fx * nx + fy * ny
            if outward > 0.0:
                fx -= outward * nx
                fy -= outward * ny
                clamped[i] = True
        moved[i, 0] = x + step * fx
        moved[i, 1] = y + step * fy
        move[i] = step * np.sqrt(fx * fx + fy * fy)
    return moved, move, clamped


@numba.njit(cache=True)
def count_far(points, reference, target, ratio):
    """How many points lie farther than ``ratio * target`` from their ``reference`` position."""
    n, dim = points.shape
    count = 0
    for i in range(n):
        length2 = 0.0
        for d in range(dim):
            delta = points[i, d] - reference[i, d]
            length2 += delta * delta
        limit = ratio * target[i]
        if length2 > limit * limit:
            count += 1
    return count


@numba.njit(cache=True)
def stale_distances(distance, drift, moved, target, slack, band):
    """The points whose signed distance may have come within ``band * target`` of the boundary, ascending.

    Adds ``moved`` to each point's ``drift`` (in place); a point is listed
    where its bound ``distance + slack * |distance| + drift`` exceeds
    ``-band * target``, and its drift starts again from 0 (its distance is
    to be evaluated anew). One pass where NumPy made a dozen over every
    point in every iteration of a coastline (1 ms at 67k points).
    """
    n = distance.shape[0]
    stale = np.empty(n, dtype=np.int64)
    count = 0
    for i in range(n):
        drift[i] += moved[i]
        if distance[i] + slack * abs(distance[i]) + drift[i] > -band * target[i]:
            stale[count] = i
            count += 1
            drift[i] = 0.0
    return stale[:count]


@numba.njit(cache=True)
def largest_interior_move(move, target, distance, tolerance):
    """Largest ``move / target`` over the points with ``distance < -tolerance`` (0 when there are none)."""
    largest = 0.0
    for i in range(move.shape[0]):
        if distance[i] < -tolerance:
            relative = move[i] / target[i]
            if relative > largest:
                largest = relative
    return largest
