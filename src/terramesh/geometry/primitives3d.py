"""Exact signed distance functions of simple solids: box, ball, cylinder.

They follow the domain protocol of :mod:`terramesh.geometry.base` with
``dim == 3``, so they combine with :class:`~terramesh.geometry.Union`,
:class:`~terramesh.geometry.Intersection` and
:class:`~terramesh.geometry.Difference` (or ``|``, ``&``, ``-``) and mesh with
:func:`terramesh.generate_mesh`. Coordinates are ``(x, y, z)`` in any one
unit; for seismic models z is negative downward.

A box also gives its twelve edges as parametric curves through
``sharp_edges()``, which the 3D generator samples and keeps as fixed
vertices so that the mesh follows them. Each solid also lists the surfaces
that bound it (``_surfaces()``: planes, a sphere, a cylinder's side), from
which CSG combinations find the edges where one operand's surface meets
another's.
"""

import numpy as np

from ..errors import GeometryError
from .base import Domain, as_bbox, as_points
from .primitives import box_distance, checked_positive, project_onto_box
from .primitives import checked_vector as _coordinates

__all__ = ["Box", "Ball", "Cylinder"]


def _vector(value, name, owner):
    return _coordinates(value, name, owner, 3)


def segment_curve(start, end, axis):
    """The edge from ``start`` to ``end`` along coordinate ``axis`` as a curve: t in [0, 1], shape (k,) -> (k, 3).

    ``t = 1`` gives ``end`` exactly.
    """

    def curve(t):
        points = np.repeat(start[None, :], len(t), axis=0)
        points[:, axis] = start[axis] + np.asarray(t, dtype=np.float64) * (end[axis] - start[axis])
        points[np.asarray(t) == 1.0, axis] = end[axis]
        return points

    return curve


class _Plane:
    """The plane ``normal . p = offset`` (unit normal), one face of a solid (its extent is the solid's business).

    ``axis`` is the coordinate axis the normal lies along, or None; on such a
    plane that coordinate equals ``coordinate`` exactly, and ``snap`` copies it.
    """

    kind = "plane"

    def __init__(self, normal, offset, *, axis=None, coordinate=None):
        self.normal = np.asarray(normal, dtype=np.float64)
        self.offset = float(offset)
        self.axis, self.coordinate = axis, coordinate

    def value(self, points):
        return points @ self.normal - self.offset

    def gradient(self, points):
        return np.broadcast_to(self.normal, points.shape)

    def snap(self, points):
        if self.axis is not None:
            points[:, self.axis] = self.coordinate
        return points


class _Sphere:
    """The sphere ``|p - center| = radius``."""

    kind = "sphere"
    axis = None

    def __init__(self, center, radius):
        self.center, self.radius = center, radius

    def value(self, points):
        return np.sqrt(np.sum((points - self.center) ** 2, axis=1)) - self.radius

    def gradient(self, points):
        relative = points - self.center
        return relative / np.maximum(np.sqrt(np.sum(relative**2, axis=1)), 1e-300)[:, None]

    def snap(self, points):
        return points


class _CylinderSide:
    """The infinite circular cylinder of unit ``axis`` through ``center``; ``u``, ``v``: unit vectors across it."""

    kind = "cylinder"
    axis = None

    def __init__(self, center, direction, radius):
        self.center, self.direction, self.radius = center, direction, radius
        self.u, self.v = perpendicular_pair(direction)

    def _radial(self, points):
        relative = points - self.center
        return relative - np.outer(relative @ self.direction, self.direction)

    def value(self, points):
        return np.sqrt(np.sum(self._radial(points) ** 2, axis=1)) - self.radius

    def gradient(self, points):
        radial = self._radial(points)
        return radial / np.maximum(np.sqrt(np.sum(radial**2, axis=1)), 1e-300)[:, None]

    def snap(self, points):
        return points


def perpendicular_pair(direction):
    """Two unit vectors completing the unit ``direction`` to a right-handed frame; coordinate axes for an axis."""
    axes = np.flatnonzero(direction != 0.0)
    if len(axes) == 1:
        # exact unit vectors keep circles on axis-aligned planes exactly on them
        axis = int(axes[0])
        u, v = np.eye(3)[(axis + 1) % 3], np.eye(3)[(axis + 2) % 3]
        return u, v * np.sign(direction[axis])
    helper = np.eye(3)[int(np.argmin(np.abs(direction)))]
    u = np.cross(direction, helper)
    u /= np.sqrt(np.sum(u**2))
    return u, np.cross(direction, u)


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
    >>> box.sharp_edges()[0](np.array([0.0, 0.5, 1.0])).tolist()
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
    """

    lipschitz = True

    def __init__(self, lower, upper):
        self.bbox = as_bbox([_vector(lower, "lower", "Box"), _vector(upper, "upper", "Box")], dim=3)

    def _distance(self, points):
        return box_distance(points, self.bbox)

    def project(self, points):
        """The nearest point of the boundary to each point, exactly.

        Parameters
        ----------
        points : array_like, shape (n, 3)
            Coordinates in the box's units; not modified.

        Returns
        -------
        numpy.ndarray, shape (n, 3)
            Points outside are clamped to the box (onto a face, an edge or a
            corner); points inside move to the nearest face (the first axis
            among equally near ones). The coordinates fixed by a face are
            copied from the bounds, so the distance there is zero to rounding.

        Examples
        --------
        >>> Box((0, 0, 0), (2, 1, 1)).project([(3.0, 2.0, 0.5), (0.5, 0.5, 0.75)]).tolist()
        [[2.0, 1.0, 0.5], [0.5, 0.5, 1.0]]
        """
        return project_onto_box(as_points(points, 3), self.bbox)

    def corners(self):
        """The eight corners, shape ``(8, 3)``, x varying fastest."""
        (x0, y0, z0), (x1, y1, z1) = self.bbox
        return np.array([[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)])

    def sharp_edges(self):
        """The twelve edges as parametric curves, each from one corner to another.

        Returns
        -------
        list of callable
            Each maps parameters ``t`` in [0, 1], shape ``(m,)``, to points
            on the edge, shape ``(m, 3)``, in the box's units; the two
            coordinates that are constant along the edge are copied from the
            corners, so the points lie on both faces exactly.
        """
        corners = self.corners()
        edges = []
        for axis in range(3):
            # corners are numbered with bit ``axis`` for the coordinate ``axis``: pair each with its partner
            step = 1 << axis
            for start in range(8):
                if not start & step:
                    edges.append(segment_curve(corners[start], corners[start + step], axis))
        return edges

    def _surfaces(self):
        """The six face planes, lower then upper, x, y, z (see :class:`_Plane`)."""
        faces = []
        for side, sign in ((0, -1.0), (1, 1.0)):
            for axis in range(3):
                bound = self.bbox[side, axis]
                faces.append(_Plane(sign * np.eye(3)[axis], sign * bound, axis=axis, coordinate=bound))
        return faces


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

    lipschitz = True

    def __init__(self, center, radius):
        self.center = _vector(center, "center", "Ball")
        self.radius = checked_positive(radius, "radius", "Ball")
        self.bbox = np.array([self.center - self.radius, self.center + self.radius])

    def _distance(self, points):
        return np.sqrt(np.sum((points - self.center) ** 2, axis=1)) - self.radius

    def _surfaces(self):
        """The sphere (see :class:`_Sphere`)."""
        return [_Sphere(self.center, self.radius)]


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

    lipschitz = True

    def __init__(self, center, radius, height, *, axis=(0.0, 0.0, 1.0)):
        self.center = _vector(center, "center", "Cylinder")
        self.radius = checked_positive(radius, "radius", "Cylinder")
        self.height = checked_positive(height, "height", "Cylinder")
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
        # the part across the axis itself: |r|**2 - along**2 cancelled far along a long cylinder (1e-3 lost at 1e7)
        across = np.sqrt(np.sum((relative - along[:, None] * self.axis) ** 2, axis=1))
        radial = across - self.radius
        axial = np.abs(along) - 0.5 * self.height
        outside = np.sqrt(np.maximum(radial, 0.0) ** 2 + np.maximum(axial, 0.0) ** 2)
        inside = np.minimum(np.maximum(radial, axial), 0.0)
        return outside + inside

    def sharp_edges(self):
        """The two rims, where the side meets the flat ends, as closed parametric curves.

        The generator places fixed points along them, as along a box's
        edges; without them a lone cylinder's mesh cut across its rims (caps
        of radius ratio 0.12 along them, or slivers left).

        Returns
        -------
        list of callable
            Each maps parameters ``t`` in [0, 1], shape ``(m,)``, to points
            on a rim, shape ``(m, 3)``; ``closed`` is True (``t`` = 0 and 1
            give the same point). On an end normal to a coordinate axis the
            points have that coordinate exactly.

        Examples
        --------
        >>> rims = Cylinder((0, 0, 0), 0.5, 2.0).sharp_edges()
        >>> len(rims), rims[0].closed
        (2, True)
        >>> sorted({float(z) for rim in rims for z in rim(np.linspace(0.0, 1.0, 5))[:, 2]})
        [-1.0, 1.0]
        """
        from .csg import sharp_edge_pieces  # the rims are where its own surfaces meet, as in a combination

        return list(sharp_edge_pieces(self))

    def _surfaces(self):
        """The side (an infinite cylinder, see :class:`_CylinderSide`) and the two end planes."""
        ends = []
        for sign in (-1.0, 1.0):
            normal = sign * self.axis
            axes = np.flatnonzero(normal != 0.0)
            offset = normal @ self.center + 0.5 * self.height
            if len(axes) == 1:  # an axis-aligned end: its coordinate, exactly
                ends.append(_Plane(normal, offset, axis=int(axes[0]), coordinate=normal[axes[0]] * offset))
            else:
                ends.append(_Plane(normal, offset))
        return [_CylinderSide(self.center, self.axis, self.radius), *ends]
