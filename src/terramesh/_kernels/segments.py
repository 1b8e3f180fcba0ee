"""Point-to-segment distances over candidate lists."""

import numba
import numpy as np


@numba.njit(cache=True, parallel=True)
def candidate_segment_distance(points, starts, ends, candidates):
    """Smallest distance from ``points[i]`` to the segments ``candidates[i, :]``.

    ``points`` (n, 2), ``starts``/``ends`` (m, 2) float64, ``candidates`` (n, k)
    int64 with indices into the segments. Returns (n,) float64.
    """
    n, k = candidates.shape
    best = np.empty(n)
    for i in numba.prange(n):
        px = points[i, 0]
        py = points[i, 1]
        smallest = np.inf
        for j in range(k):
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
            ex = ax + t * dx - px
            ey = ay + t * dy - py
            distance2 = ex * ex + ey * ey
            if distance2 < smallest:
                smallest = distance2
        best[i] = np.sqrt(smallest)
    return best
