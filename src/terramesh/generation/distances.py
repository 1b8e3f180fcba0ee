"""Signed distances as the generator needs them: bounded far inside, kept lazily, and projections onto the boundary.

A terramesh geometry's distance is 1-Lipschitz, so a point's distance can
only change by as much as the point moved: :class:`LazyDistance` evaluates
again only the points that may have reached the boundary.
"""

import numpy as np

from .._kernels.forces import stale_distances
from ..geometry.base import distance_gradient
from ..mesh.columns import row_max, squared_row_norms
from ..mesh.topology import without_rows

LAZY_BAND = 0.1  # a point that may have come within this many local sizes of the boundary gets its distance again
DISTANCE_SLACK = 0.02  # relative error allowed to a distance far from the boundary (a polygon's is within 1 %)
DISTANCE_REACH = 8.0  # smallest sizes: distances are exact within this of the boundary, bounds farther in


LANDED = 4 * np.finfo(float).eps  # a projected point is on the boundary at this distance over its largest coordinate


def finite_difference_step(h0, bbox):
    """Step of the finite differences of the distance function for the Newton projections.

    The distance carries a rounding error of eps times the coordinates
    (large in UTM or Mercator metres) and a truncation error of the step over
    the boundary's curvature radius (about h0 or more); this step balances
    the two. (``sqrt(eps) h0``, the 2D step before, left a disk cut from a
    rectangle at an offset of 1e7 with h0 = 0.01 with its boundary vertices
    a size off the boundary: the difference of two distances there was
    rounding alone.)
    """
    return float(np.sqrt(np.finfo(float).eps * h0 * max(h0, float(np.abs(bbox).max()))))


def near_distance(domain, points, limit):
    """Signed distances, exact within ``limit`` of the boundary and outside it; ``-limit`` (a bound) farther inside."""
    distance = domain.distance_within(points, limit)
    out = np.flatnonzero(distance >= limit)
    if len(out):  # far outside (rare): a projection wants the exact distance
        distance[out] = domain.distance(points[out])
    return distance


def project_to_boundary(domain, points, distance, step, nearest=None):
    """Move points onto the zero level set: exactly where the domain can (``domain.project``), else by Newton.

    One Newton step along the forward-difference gradient of the distance;
    a polygon's exact projection saves its two further distance
    evaluations (a coastline's cost most of an iteration). ``nearest``, the
    boundary points already found with the distances (NaN where not), are
    taken as they are.
    """
    project = getattr(domain, "project", None)
    if callable(project):
        if nearest is None:
            return project(points) if len(points) else points.copy()
        unknown = np.flatnonzero(np.isnan(nearest[:, 0]))
        if len(unknown):
            nearest[unknown] = project(points[unknown])
        return nearest
    gradient = distance_gradient(domain, points, distance, step)
    norm2 = np.sum(gradient**2, axis=1)
    norm2[norm2 == 0] = 1.0
    return points - (distance / norm2)[:, None] * gradient


class LazyDistance:
    """Signed distances kept up to date only where they matter: near the boundary.

    A distance function of a terramesh geometry changes by at most the
    distance a point moves (it is 1-Lipschitz), so a point whose last
    distance, plus ``DISTANCE_SLACK`` of it and its movement since, is still
    below minus ``LAZY_BAND`` local sizes is certainly inside and needs no
    new evaluation; only points that
    may have reached the boundary are evaluated. Every decision the
    generator takes from the distances (project a point, count it as
    interior, bound a cell's centroid) is the same as with fresh ones. That
    skips most points of a long coastline polygon in every iteration. Points
    removed or added (crowded points, boundary gaps) are followed one by one
    (:meth:`remove`, :meth:`append`), so such a change costs the new points'
    distances, not all of them again. Plain callables are evaluated in full,
    as nothing is known of their slope.
    """

    def __init__(self, domain):
        self.domain = domain
        self.enabled = getattr(domain, "lipschitz", False)
        self.distance = self.limit = None
        # a polygon finds each point's nearest boundary point with its distance: kept for the
        # projection of the points evaluated last (all that can be outside), a search saved
        self._with_nearest = getattr(domain, "distance_and_nearest", None)
        self._nearest = self._fresh = None

    def _evaluate(self, points):
        if self.limit is None:
            return (self.domain.distance(points), None) if self._with_nearest is None else self._with_nearest(points)
        if self._with_nearest is None:
            return near_distance(self.domain, points, self.limit), None
        distance, nearest = self._with_nearest(points, self.limit)
        out = np.flatnonzero(distance >= self.limit)
        if len(out):  # far outside (rare): the projection wants the exact distance
            distance[out], nearest[out] = self._with_nearest(points[out])
        return distance, nearest

    def update(self, points, moved, target):
        """The signed distances of ``points`` (a copy), evaluated again where a point may have reached the boundary.

        ``moved`` holds each point's move since the last update, ``target``
        its size; new arrays of another length are evaluated in full.
        """
        if not self.enabled or self.distance is None or len(self.distance) != len(points):
            # a polygon's distance far from its segments costs ten times one near them (0.76 against
            # 0.08 s for 180k points of a 20,000-vertex coast); an interior point needs only a bound
            self.limit = DISTANCE_REACH * float(np.min(target)) if self.enabled and len(target) else None
            self.distance, self._nearest = self._evaluate(points)
            self._fresh = None if self._nearest is None else np.ones(len(points), dtype=bool)
            self.drift = np.zeros(len(points))
            return self.distance.copy()
        stale = stale_distances(self.distance, self.drift, moved, target, DISTANCE_SLACK, LAZY_BAND)
        distance, nearest = self._evaluate(points[stale])
        self.distance[stale] = distance
        if nearest is not None:
            self._fresh = np.zeros(len(points), dtype=bool)
            self._fresh[stale] = True
            self._nearest[stale] = nearest
        return self.distance.copy()

    def nearest(self, which, n_points):
        """Nearest boundary points the last :meth:`update` found for the points ``which`` (indices) of ``n_points``.

        NaN where it found none (a point not evaluated, or far out); None
        when the domain gives none or points changed since.
        """
        if self._fresh is None or len(self._fresh) != n_points:
            return None
        nearest = self._nearest[which]
        nearest[~self._fresh[which]] = np.nan
        return nearest

    def upper_bound(self, n_points):
        """An upper bound of each point's signed distance, or None where unknown (non-Lipschitz, points changed)."""
        if not self.enabled or self.distance is None or len(self.distance) != n_points:
            return None
        return self.distance + DISTANCE_SLACK * np.abs(self.distance) + self.drift

    def remove(self, indices):
        """Follow the removal of the points ``indices`` (the rest keep their order)."""
        self._fresh = None  # the nearest points serve the update's own iteration only
        if self.enabled and self.distance is not None and len(indices):
            self.distance = np.delete(self.distance, indices)
            self.drift = np.delete(self.drift, indices)
            if self._nearest is not None:
                self._nearest = without_rows(self._nearest, indices)

    def moved(self, indices, lengths):
        """Follow the points ``indices`` moved by ``lengths`` after the last :meth:`update` (their bounds widen)."""
        if self.enabled and self.distance is not None:
            self.drift[indices] += lengths

    def append(self, points):
        """Follow new points appended after the others: their distances are evaluated (a few boundary points)."""
        self._fresh = None
        if self.enabled and self.distance is not None and len(points):
            distance, nearest = self._evaluate(points)
            self.distance = np.concatenate([self.distance, distance])
            self.drift = np.concatenate([self.drift, np.zeros(len(points))])
            if self._nearest is not None:
                self._nearest = np.concatenate([self._nearest, nearest])


def project_to_boundary_3d(domain, points, distance, step, *, newton_steps=2):
    """Move points onto the zero level set: exactly where the domain can (``domain.project``), else by Newton.

    Up to ``newton_steps`` steps along the forward-difference gradient, each
    only for the points whose distance is still above rounding (LANDED times
    their largest coordinate): a step leaves the error of that gradient
    (rounding over the difference step) times the distance, which the next
    step multiplies by it again. The difference step shrinks with the
    distance, to a quarter of it (but not below 4 LANDED times the
    coordinates), so that a point landing near an edge of the boundary,
    where the gradient jumps, does not difference across the edge.
    """
    project = getattr(domain, "project", None)
    if callable(project):
        return project(points)
    points = points.copy()
    distance = np.array(distance, dtype=np.float64)
    landed = LANDED * row_max(np.abs(points))
    active = np.flatnonzero(np.abs(distance) > landed)
    for _ in range(newton_steps):
        if len(active) == 0:
            break
        where, off = points[active], distance[active]
        local_step = np.clip(0.25 * np.abs(off), 4.0 * landed[active], step)
        gradient = distance_gradient(domain, where, off, local_step)
        norm2 = squared_row_norms(gradient)
        norm2[norm2 == 0] = 1.0
        points[active] = where - (off / norm2)[:, None] * gradient
        distance[active] = domain.distance(points[active])
        active = active[np.abs(distance[active]) > landed[active]]
    return points
