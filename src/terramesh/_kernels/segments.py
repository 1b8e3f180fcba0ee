"""Point-to-segment distances over candidate lists."""

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def _nearest_candidate(points, starts, ends, candidates, i):
    """Squared distance from ``points[i]`` to the nearest of its candidate segments, and that nearest point."""
    px = points[i, 0]
    py = points[i, 1]
    smallest = np.inf
    nearest_x = px
    nearest_y = py
    for j in range(candidates.shape[1]):
        s = candidates[i, j]
        ax = starts[s, 0]
        ay = starts[s, 1]
        dx = ends[s, 0] - ax
        dy = ends[s, 1] - ay
        length2 = dx * dx + dy * dy
        t = 0.0
        if length2 > 0.0:
            t = ((px - ax) * dx + (py - ay) * dy) / length2
            t = min(max(t, 0.0), 1.0)
        x = ax + t * dx
        y = ay + t * dy
        distance2 = (x - px) * (x - px) + (y - py) * (y - py)
        if distance2 < smallest:
            smallest = distance2
            nearest_x = x
            nearest_y = y
    return smallest, nearest_x, nearest_y


@numba.njit(cache=True, parallel=True)
def candidate_segment_distance(points, starts, ends, candidates):
    """Smallest distance from ``points[i]`` to the segments ``candidates[i, :]``.

    ``points`` (n, 2), ``starts``/``ends`` (m, 2) float64, ``candidates`` (n, k)
    int64 with indices into the segments. Returns (n,) float64.
    """
    n = candidates.shape[0]
    best = np.empty(n)
    for i in numba.prange(n):
        best[i] = np.sqrt(_nearest_candidate(points, starts, ends, candidates, i)[0])
    return best


@numba.njit(cache=True, parallel=True)
def candidate_nearest_points(points, starts, ends, candidates):
    """The nearest point to ``points[i]`` on the segments ``candidates[i, :]``, and its distance.

    Arguments as for :func:`candidate_segment_distance`. Returns
    ``(distance (n,), nearest (n, 2))``.
    """
    n = candidates.shape[0]
    best = np.empty(n)
    nearest = np.empty((n, 2))
    for i in numba.prange(n):
        distance2, x, y = _nearest_candidate(points, starts, ends, candidates, i)
        best[i] = np.sqrt(distance2)
        nearest[i, 0] = x
        nearest[i, 1] = y
    return best, nearest
