"""Exact signed distance functions of simple shapes."""

import numpy as np

from ..errors import GeometryError
from .base import Domain, as_bbox

__all__ = ["Rectangle", "Disk"]


class Rectangle(Domain):
    """Axis-aligned rectangle with exact signed distance.

    Parameters
    ----------
    lower, upper : array_like, shape (2,)
        Opposite corners (x, y), any units.

    Examples
    --------
    >>> box = Rectangle((0, 0), (2, 1))
    >>> box.distance([(1.0, 0.5), (3.0, 0.5)]).tolist()
    [-0.5, 1.0]
    """

    def __init__(self, lower, upper):
        self.bbox = as_bbox([lower, upper], dim=2)
        self._center = self.bbox.mean(axis=0)
        self._half = 0.5 * (self.bbox[1] - self.bbox[0])

    def _distance(self, points):
        q = np.abs(points - self._center) - self._half
        outside = np.sqrt(np.sum(np.maximum(q, 0.0) ** 2, axis=1))
        inside = np.minimum(q.max(axis=1), 0.0)
        return outside + inside

    def corners(self):
        """The four corners, counter-clockwise from the lower left."""
        (x0, y0), (x1, y1) = self.bbox
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


class Disk(Domain):
    """Disk (filled circle) with exact signed distance.

    Parameters
    ----------
    center : array_like, shape (2,)
        Centre (x, y).
    radius : float
        Radius, positive, same units.

    Examples
    --------
    >>> Disk((0, 0), 1.0).distance([(0.0, 0.0), (2.0, 0.0)]).tolist()
    [-1.0, 1.0]
    """

    def __init__(self, center, radius):
        center = np.asarray(center, dtype=np.float64)
        radius = float(radius)
        if center.shape != (2,) or not np.all(np.isfinite(center)):
            raise GeometryError(f"Disk center must be two finite numbers, got {center!r}")
        if not np.isfinite(radius) or radius <= 0:
            raise GeometryError(f"Disk radius must be positive and finite, got {radius}")
        self.center = center
        self.radius = radius
        self.bbox = np.array([center - radius, center + radius])

    def _distance(self, points):
        return np.hypot(points[:, 0] - self.center[0], points[:, 1] - self.center[1]) - self.radius
