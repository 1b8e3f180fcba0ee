"""Exact signed distance functions of simple solids: box, ball, cylinder.

They follow the domain protocol of :mod:`terramesh.geometry.base` with
``dim == 3``, so they combine with :class:`~terramesh.geometry.Union`,
:class:`~terramesh.geometry.Intersection` and
:class:`~terramesh.geometry.Difference` (or ``|``, ``&``, ``-``) and mesh with
:func:`terramesh.generate_mesh`. Coordinates are ``(x, y, z)`` in any one
unit; for seismic models z is negative downward.
"""

import numpy as np

from ..errors import GeometryError
from .base import Domain, as_bbox

__all__ = ["Box", "Ball", "Cylinder"]


def _vector(value, name, owner):
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise GeometryError(f"{owner} {name} must be three finite numbers (x, y, z), got {value!r}")
    return array


def _positive(value, name, owner):
    try:
        number = float(value)
    except (TypeError, ValueError) as error:
        raise GeometryError(f"{owner} {name} must be a positive number, got {value!r}") from error
    if not np.isfinite(number) or number <= 0:
        raise GeometryError(f"{owner} {name} must be positive and finite, got {value!r}")
    return number


class Box(Domain):
    """Axis-aligned box (cuboid) with exact signed distance.

    Parameters
    ----------
    lower, upper : array_like, shape (3,)
        Opposite corners ``(x, y, z)``, any units; ``upper`` exceeds
        ``lower`` on every axis.

    Examples
    --------
    >>> box = Box((0, 0, 0), (2, 1, 1))
    >>> box.distance([(1.0, 0.5, 0.5), (3.0, 0.5, 0.5), (3.0, 2.0, 0.5)]).round(6).tolist()
    [-0.5, 1.0, 1.414214]
    >>> box.corners().shape
    (8, 3)
    """

    def __init__(self, lower, upper):
        self.bbox = as_bbox([_vector(lower, "lower", "Box"), _vector(upper, "upper", "Box")], dim=3)
        self._center = self.bbox.mean(axis=0)
        self._half = 0.5 * (self.bbox[1] - self.bbox[0])

    def _distance(self, points):
        q = np.abs(points - self._center) - self._half
        outside = np.sqrt(np.sum(np.maximum(q, 0.0) ** 2, axis=1))
        inside = np.minimum(q.max(axis=1), 0.0)
        return outside + inside

    def corners(self):
        """The eight corners, shape ``(8, 3)``, x varying fastest."""
        (x0, y0, z0), (x1, y1, z1) = self.bbox
        return np.array([[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)])


class Ball(Domain):
    """Solid sphere with exact signed distance.

    Parameters
    ----------
    center : array_like, shape (3,)
        Centre ``(x, y, z)``.
    radius : float
        Radius, positive, same units.

    Examples
    --------
    >>> Ball((0, 0, 0), 1.0).distance([(0.0, 0.0, 0.0), (0.0, 2.0, 0.0)]).tolist()
    [-1.0, 1.0]
    """

    def __init__(self, center, radius):
        self.center = _vector(center, "center", "Ball")
        self.radius = _positive(radius, "radius", "Ball")
        self.bbox = np.array([self.center - self.radius, self.center + self.radius])

    def _distance(self, points):
        return np.sqrt(np.sum((points - self.center) ** 2, axis=1)) - self.radius


class Cylinder(Domain):
    """Solid circular cylinder with flat ends, exact signed distance.

    Parameters
    ----------
    center : array_like, shape (3,)
        Midpoint of the axis ``(x, y, z)``.
    radius : float
        Radius, positive.
    height : float
        Length along the axis, positive; the ends lie ``height / 2`` from ``center``.
    axis : array_like, shape (3,), optional
        Direction of the axis (any length but zero); default ``(0, 0, 1)``.

    Examples
    --------
    >>> can = Cylinder((0, 0, 0), 0.5, 2.0)
    >>> can.distance([(0.0, 0.0, 0.0), (0.0, 0.0, 1.5), (1.0, 0.0, 0.0)]).tolist()
    [-0.5, 0.5, 0.5]
    >>> can.bbox.tolist()
    [[-0.5, -0.5, -1.0], [0.5, 0.5, 1.0]]
    """

    def __init__(self, center, radius, height, *, axis=(0.0, 0.0, 1.0)):
        self.center = _vector(center, "center", "Cylinder")
        self.radius = _positive(radius, "radius", "Cylinder")
        self.height = _positive(height, "height", "Cylinder")
        axis = _vector(axis, "axis", "Cylinder")
        length = float(np.sqrt(np.sum(axis**2)))
        if length == 0.0:
            raise GeometryError("Cylinder axis must not be the zero vector")
        self.axis = axis / length
        # per coordinate: half the height along the axis' component, the radius across it
        reach = 0.5 * self.height * np.abs(self.axis) + self.radius * np.sqrt(np.maximum(1.0 - self.axis**2, 0.0))
        self.bbox = np.array([self.center - reach, self.center + reach])

    def _distance(self, points):
        relative = points - self.center
        along = relative @ self.axis
        across = np.sqrt(np.maximum(np.sum(relative**2, axis=1) - along**2, 0.0))
        radial = across - self.radius
        axial = np.abs(along) - 0.5 * self.height
        outside = np.sqrt(np.maximum(radial, 0.0) ** 2 + np.maximum(axial, 0.0) ** 2)
        inside = np.minimum(np.maximum(radial, axial), 0.0)
        return outside + inside
