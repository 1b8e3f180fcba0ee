"""Curves given by a user: a polyline as a parametric curve, and checks that curves and points lie on a boundary.

The 3D generator holds a sharp edge by points it spaces along the edge by
the size function (:mod:`terramesh.generation.sharp_edges`). It needs each
edge as a callable ``t -> points`` for ``t`` in [0, 1]; a user's distance
function (:class:`~terramesh.geometry.FunctionDomain`) gives its edges as
such callables or as polylines, which :class:`PolylineCurve` turns into one.
"""

import numpy as np

from ..errors import GeometryError

ON_BOUNDARY = 1e-6  # a user's corner or edge point may read this share of the bbox's largest side off the boundary
CURVE_CHECKS = 17  # points along a callable edge at which the distance is read when the domain is built


class PolylineCurve:
    """A polyline as a curve ``t -> points``, ``t`` in [0, 1] proportional to arc length.

    Parameters
    ----------
    vertices : array_like, shape (m, dim)
        The polyline's vertices in order, at least two distinct; repeated
        consecutive ones are dropped. A polyline whose last vertex is its
        first is ``closed`` (a loop, which has no ends).

    Examples
    --------
    >>> edge = PolylineCurve([(0, 0, 0), (1, 0, 0), (1, 3, 0)])
    >>> edge([0.0, 0.125, 0.25, 1.0]).tolist()
    [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 3.0, 0.0]]
    >>> edge.closed
    False
    """

    def __init__(self, vertices):
        vertices = np.asarray(vertices, dtype=np.float64)
        if vertices.ndim != 2 or vertices.shape[1] not in (2, 3):
            raise GeometryError(f"a polyline needs vertices of shape (m, 2) or (m, 3), got shape {vertices.shape}")
        if not np.isfinite(vertices).all():
            raise GeometryError("a polyline's vertices must be finite numbers")
        steps = np.sqrt(np.sum(np.diff(vertices, axis=0) ** 2, axis=1))
        keep = np.concatenate([[True], steps > 0])
        self.vertices, steps = vertices[keep], steps[keep[1:]]
        if len(self.vertices) < 2:
            raise GeometryError("a polyline needs at least two distinct vertices")
        self.closed = bool(np.array_equal(self.vertices[0], self.vertices[-1]))
        arc = np.concatenate([[0.0], np.cumsum(steps)])
        self._at = arc / arc[-1]
        self._at[-1] = 1.0

    def __call__(self, t):
        """Points at parameters ``t`` (shape ``(m,)``, in [0, 1]), shape ``(m, dim)``."""
        t = np.asarray(t, dtype=np.float64).reshape(-1)
        if self.closed:
            t = t % 1.0
        segment = np.clip(np.searchsorted(self._at, t, side="right") - 1, 0, len(self._at) - 2)
        start, end = self._at[segment], self._at[segment + 1]
        local = np.clip((t - start) / (end - start), 0.0, 1.0)[:, None]
        points = self.vertices[segment] + local * (self.vertices[segment + 1] - self.vertices[segment])
        points[t >= 1.0] = self.vertices[-1]  # the end exactly, not a rounding off it
        return points


def checked_on_boundary(points, distance, bbox, what):
    """Raise a GeometryError when a point of ``points`` lies off the boundary ``distance`` describes.

    Off means ``|distance|`` above ``ON_BOUNDARY`` of the bbox's largest side;
    ``what`` names the points in the message.
    """
    if len(points) == 0:
        return
    reading = distance(points)
    off = np.abs(reading) > _on_boundary(bbox)
    if off.any():
        first = int(np.argmax(off))
        where = ", ".join(f"{value:.6g}" for value in points[first])
        raise GeometryError(
            f"{int(off.sum())} of the {len(points)} points of {what} lie off the boundary, the first at ({where}), "
            f"where the distance function reads {reading[first]:.3g}: they must lie on it"
        )


def checked_curves(curves, dim, distance, bbox):
    """``curves`` (each a callable ``t -> (m, 3) points`` or an ``(m, 3)`` polyline) as callables on the boundary.

    3D only. Each is read at ``CURVE_CHECKS`` parameters, which must give
    finite points on the boundary ``distance`` describes (see
    :func:`checked_on_boundary`).
    """
    if curves is None:
        return []
    given = curves
    one = callable(given) or isinstance(given, (str, bytes)) or (isinstance(given, np.ndarray) and given.ndim != 3)
    try:
        curves = [] if one else list(given)
    except TypeError:  # a number, say
        one, curves = True, []
    if dim != 3 and (one or curves):
        raise GeometryError("sharp_edges are for 3D domains; a 2D domain keeps its sharp points as corners")
    if one:
        raise GeometryError(
            f"sharp_edges must be a list of curves (polylines or callables), got one {type(given).__name__}: "
            "put a curve in a list"
        )
    checked = []
    for number, curve in enumerate(curves):
        if not callable(curve):
            try:
                shape = np.shape(curve)
            except ValueError:  # rows of different lengths
                shape = "ragged"
            if not (isinstance(shape, tuple) and len(shape) == 2):
                raise GeometryError(
                    f"sharp edge {number} has shape {shape}: each edge is an (m, 3) polyline or a callable of t; "
                    "one polyline given alone goes in a list"
                )
            curve = PolylineCurve(curve)
            if curve.vertices.shape[1] != 3:
                raise GeometryError(f"sharp edge {number} has 2D vertices; a 3D domain's edges need shape (m, 3)")
        sample = np.asarray(curve(np.linspace(0.0, 1.0, CURVE_CHECKS)), dtype=np.float64)
        if sample.shape != (CURVE_CHECKS, 3) or not np.isfinite(sample).all():
            raise GeometryError(
                f"sharp edge {number} maps {CURVE_CHECKS} parameters to an array of shape {sample.shape}"
                f"{', not all finite' if sample.shape == (CURVE_CHECKS, 3) else ''}: a sharp edge maps t in [0, 1], "
                "shape (m,), to finite points, shape (m, 3)"
            )
        checked_on_boundary(sample, distance, bbox, f"sharp edge {number}")
        if not getattr(curve, "closed", False) and np.all(np.abs(sample[-1] - sample[0]) <= _on_boundary(bbox)):
            curve = _Loop(curve)  # its two ends, one point, would be held twice
        checked.append(curve)
    return checked


class _Loop:
    """A callable curve whose ends coincide, marked ``closed`` (see :func:`checked_curves`)."""

    closed = True

    def __init__(self, curve):
        self.curve = curve

    def __call__(self, t):
        return np.asarray(self.curve(np.asarray(t, dtype=np.float64) % 1.0), dtype=np.float64)


def _on_boundary(bbox):
    """How far off the boundary (in its units) a user's corner or edge point may read."""
    return ON_BOUNDARY * float(np.max(bbox[1] - bbox[0]))


def curve_ends(curve):
    """A curve's two ends, shape ``(2, 3)``, or none for a loop (``closed``)."""
    if getattr(curve, "closed", False):
        return np.empty((0, 3))
    return np.asarray(curve(np.array([0.0, 1.0])), dtype=np.float64)
