"""Exact distance from many points to many line segments.

A KD-tree holds the midpoints of the segments, after long segments are split
(which leaves the polyline unchanged) so that every piece is at most ``2 *
half_length`` long. A segment whose midpoint is ``r`` away from a point is at
least ``r - half_length`` away, so after testing the ``k`` nearest segments
the true distance lies between ``r_k - half_length`` and the best found.
Points where that gap exceeds ``relative_tolerance`` times the distance are
queried again with a larger ``k``: the result is exact near the boundary,
where the mesh generator projects points, and within a relative error of
``relative_tolerance`` far from it, at ``O(log m)`` cost per point.
"""

import numpy as np
from scipy.spatial import cKDTree

from .._kernels.segments import candidate_nearest_points, candidate_segment_distance

__all__ = ["SegmentIndex"]

_FIRST_K = 8


class SegmentIndex:
    """Nearest-segment queries on a fixed set of 2D segments.

    Parameters
    ----------
    starts, ends : numpy.ndarray, shape (m, 2)
        Segment end points, float64.
    relative_tolerance : float, optional
        Largest relative error of a returned distance.

    Examples
    --------
    >>> import numpy as np
    >>> index = SegmentIndex(np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]))
    >>> index.distance(np.array([[0.5, 2.0], [2.0, 0.0]])).tolist()
    [2.0, 1.0]
    """

    def __init__(self, starts, ends, *, relative_tolerance=1e-2):
        self.relative_tolerance = float(relative_tolerance)
        lengths = np.hypot(*(ends - starts).T)
        extent = float(np.ptp(np.vstack([starts, ends]))) if len(starts) else 0.0
        usable = lengths[lengths > 1e-9 * extent]
        piece = 2.0 * float(np.median(usable)) if usable.size else max(extent, 1.0)
        counts = np.maximum(np.ceil(lengths / piece).astype(np.int64), 1)
        owner = np.repeat(np.arange(len(lengths)), counts)
        first = np.cumsum(counts) - counts
        step = np.arange(owner.size) - first[owner]
        fraction = (ends - starts)[owner] / counts[owner, None]
        self.starts = starts[owner] + step[:, None] * fraction
        self.ends = self.starts + fraction
        self.half_length = 0.5 * float(np.max(np.hypot(*fraction.T)))
        self._tree = cKDTree(0.5 * (self.starts + self.ends))

    def distance_upper_bound(self, points):
        """Distance to the segment with the nearest midpoint: at least the true distance, shape ``(n,)``."""
        nearest = self._tree.query(points, k=1, workers=-1)[1].astype(np.int64).reshape(-1, 1)
        return candidate_segment_distance(points, self.starts, self.ends, nearest)

    def distance(self, points):
        """Unsigned distance from each point to the nearest segment, shape ``(n,)``."""
        return self._nearest(points, candidate_segment_distance)

    def nearest_points(self, points):
        """The nearest point on the segments to each point, shape ``(n, 2)``.

        Exact where the distance is (near the segments); elsewhere a point
        of a segment within ``relative_tolerance`` of the nearest distance.

        Examples
        --------
        >>> import numpy as np
        >>> index = SegmentIndex(np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]))
        >>> index.nearest_points(np.array([[0.5, 2.0], [2.0, 1.0]])).tolist()
        [[0.5, 0.0], [1.0, 0.0]]
        """
        nearest = np.empty((len(points), 2))
        self._nearest(points, candidate_nearest_points, nearest)
        return nearest

    def _nearest(self, points, kernel, nearest=None):
        """Distances by ``kernel`` over ever more candidates until each is within the tolerance.

        ``kernel(points, starts, ends, candidates)`` returns the distances,
        or ``(distances, nearest points)``; the latter fill ``nearest``.
        """
        distance = np.empty(len(points))
        pending = np.arange(len(points))
        k = _FIRST_K
        total = len(self.starts)
        while pending.size:
            k = min(k, total)
            mid_distance, candidates = self._tree.query(points[pending], k=k, workers=-1)
            mid_distance = mid_distance.reshape(len(pending), k)
            candidates = candidates.reshape(len(pending), k).astype(np.int64, copy=False)
            found = kernel(points[pending], self.starts, self.ends, candidates)
            best, found = found if isinstance(found, tuple) else (found, None)
            lower_bound = mid_distance[:, -1] - self.half_length
            done = (k == total) | (best - lower_bound <= self.relative_tolerance * best)
            distance[pending[done]] = best[done]
            if nearest is not None:
                nearest[pending[done]] = found[done]
            pending = pending[~done]
            k *= 4
        return distance
