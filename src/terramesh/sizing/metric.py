"""Anisotropic mesh sizes: a metric tensor field that sets both the size and the direction of the cells.

A metric ``M`` (a symmetric positive definite 2 x 2 matrix at each point)
measures an edge ``e`` as ``sqrt(e^T M e)``; the mesh it asks for has every
edge of length 1 in that measure. With ``M = R diag(1 / major**2,
1 / minor**2) R^T`` (``R`` the rotation by ``angle``) the cells are
``major`` long along ``angle`` and ``minor`` across it (the seismic talk's
"Anisotropy" slide; an isotropic size ``h`` is ``major = minor = h``).
"""

import numpy as np

from .._kernels import read_only
from .._kernels.metric import grid_metric
from ..errors import SizingError
from .grid import checked_axis

__all__ = ["metric_tensor", "metric_sizes", "as_metric_function", "MetricGrid"]


def metric_tensor(major, minor, angle):
    """The metric of cells ``major`` long along ``angle`` and ``minor`` across it.

    Parameters
    ----------
    major, minor : float or array_like
        Edge lengths wanted along and across the direction ``angle``, in the
        domain's units; positive. Either may be the larger.
    angle : float or array_like
        Direction of ``major``, radians counter-clockwise from the x axis.
        The three arguments broadcast against each other.

    Returns
    -------
    numpy.ndarray, shape (..., 2, 2)
        ``R diag(1 / major**2, 1 / minor**2) R^T``, symmetric positive definite.

    Raises
    ------
    SizingError
        For sizes that are not positive and finite, or an angle that is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> metric_tensor(2.0, 0.5, 0.0).tolist()
    [[0.25, 0.0], [0.0, 4.0]]
    >>> m = metric_tensor(2.0, 0.5, np.pi / 2)   # long along y now
    >>> bool(np.isclose(np.sqrt([0, 2] @ m @ [0, 2]), 1.0))
    True
    """
    try:
        major, minor, angle = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (major, minor, angle)))
    except (TypeError, ValueError) as error:
        raise SizingError(f"metric_tensor needs numbers or arrays of one shape: {error}") from None
    for name, value in (("major", major), ("minor", minor)):
        bad = ~(np.isfinite(value) & (value > 0))
        if bad.any():
            first = value.reshape(-1)[int(np.argmax(bad.reshape(-1)))]
            raise SizingError(f"metric_tensor: {name} must be positive and finite (a length), got {first:g}")
    if not np.isfinite(angle).all():
        raise SizingError("metric_tensor: angle must be finite (radians)")
    cos, sin = np.cos(angle), np.sin(angle)
    with np.errstate(over="ignore", divide="ignore"):
        along, across = 1.0 / major**2, 1.0 / minor**2
    if not (np.isfinite(along).all() and np.isfinite(across).all()):
        raise SizingError(
            f"metric_tensor: sizes down to {min(major.min(), minor.min()):g} overflow 1 / size**2; give them in "
            "units nearer the domain's (metres, degrees)"
        )
    metric = np.empty(major.shape + (2, 2))
    metric[..., 0, 0] = along * cos**2 + across * sin**2
    metric[..., 1, 1] = along * sin**2 + across * cos**2
    metric[..., 0, 1] = metric[..., 1, 0] = (along - across) * cos * sin + 0.0  # + 0.0: no -0.0 along the axes
    return metric


def metric_sizes(metric):
    """The sizes and direction a metric asks for: the inverse of :func:`metric_tensor`.

    Parameters
    ----------
    metric : array_like, shape (..., 2, 2)
        Symmetric positive definite matrices.

    Returns
    -------
    major, minor, angle : numpy.ndarray, shape (...)
        ``major >= minor`` (lengths) and the direction of ``major`` in
        radians, in ``(-pi / 2, pi / 2]``.

    Examples
    --------
    >>> import numpy as np
    >>> major, minor, angle = metric_sizes(metric_tensor(0.5, 2.0, 0.0))
    >>> float(major), float(minor), round(float(np.degrees(angle)))
    (2.0, 0.5, 90)
    """
    metric = np.asarray(metric, dtype=np.float64)
    if metric.ndim < 2 or metric.shape[-2:] != (2, 2):
        raise SizingError(f"metric_sizes needs 2 x 2 matrices, an array of shape (..., 2, 2), got {metric.shape}")
    checked_metric(metric.reshape(-1, 2, 2), what="metric_sizes got")
    a, b, c = metric[..., 0, 0], metric[..., 0, 1], metric[..., 1, 1]
    mean, radius = 0.5 * (a + c), np.hypot(0.5 * (a - c), b)
    # the smaller eigenvalue belongs to the longer size; its eigenvector is along (b, small - a)
    small, large = mean - radius, mean + radius
    angle = 0.5 * np.arctan2(-2.0 * b, c - a)
    angle = np.where(angle <= -0.5 * np.pi, angle + np.pi, angle)
    return 1.0 / np.sqrt(small), 1.0 / np.sqrt(large), angle


def mean_size(metric):
    """The isotropic size of the same point density, ``sqrt(major * minor) = det(M)**(-1/4)``, shape (...)."""
    metric = np.asarray(metric, dtype=np.float64)
    return (metric[..., 0, 0] * metric[..., 1, 1] - metric[..., 0, 1] * metric[..., 1, 0]) ** -0.25


class MetricGrid:
    """A metric on a regular 2D grid, its entries interpolated bilinearly between the nodes.

    Interpolating the entries keeps every matrix positive definite (a
    weighted mean of positive definite matrices is one); points outside
    the grid take the nearest edge's metric.

    Parameters
    ----------
    axes : sequence of two array_like
        Evenly spaced, increasing ``x`` and ``y`` node coordinates.
    metric : array_like, shape (len(x), len(y), 2, 2)
        Symmetric positive definite matrices at the nodes (see
        :func:`metric_tensor`), indexed ``[ix, iy]``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(0, 1, 3)
    >>> grid = MetricGrid((x, x), metric_tensor(np.add.outer(0.1 + x, 0 * x), 0.05, 0.0))
    >>> major, minor, angle = metric_sizes(grid([(0.5, 0.5)]))
    >>> float(major[0]) > 0.5, float(minor[0])
    (True, 0.05)
    """

    def __init__(self, axes, metric):
        try:
            axes = list(axes)
        except TypeError:
            raise SizingError(f"axes must be a sequence of 2 coordinate arrays (x, y), got {axes!r}") from None
        if len(axes) != 2:
            raise SizingError(f"a MetricGrid needs 2 coordinate arrays (x, y), got {len(axes)}")
        self.axes = tuple(checked_axis(axis, name) for axis, name in zip(axes, "xy", strict=True))
        self.values = read_only(np.array(metric, dtype=np.float64))  # a copy: the entries below are one too
        shape = (self.axes[0].size, self.axes[1].size, 2, 2)
        if self.values.shape != shape:
            raise SizingError(f"metric values have shape {self.values.shape}, the grid axes need {shape}")
        checked_metric(self.values.reshape(-1, 2, 2), what="MetricGrid's values have")
        self._entries = read_only(np.ascontiguousarray(self.values[:, :, [0, 0, 1], [0, 1, 1]]))
        self._origin = np.array([axis[0] for axis in self.axes])
        self._spacing = np.array([axis[1] - axis[0] for axis in self.axes])

    @property
    def bbox(self):
        """Grid extent, ``[[xmin, ymin], [xmax, ymax]]``."""
        return np.array([[axis[0] for axis in self.axes], [axis[-1] for axis in self.axes]])

    def __call__(self, points):
        """The interpolated metric at ``points`` (n, 2), shape (n, 2, 2)."""
        points = np.ascontiguousarray(points, dtype=np.float64)
        if points.ndim == 1 and points.size in (0, 2):  # no point, or one point (x, y)
            points = points.reshape(-1, 2)
        if points.ndim != 2 or points.shape[1] != 2:  # 3D points were read as more 2D ones, silently
            raise SizingError(f"points of a 2-D metric grid must have shape (n, 2), not {points.shape}")
        if not np.isfinite(points).all():
            raise SizingError("the metric's points must be finite (found NaN or infinity)")
        return grid_metric(self._entries, self._origin, self._spacing, points)


class _Checked:
    """Call a user's metric function and refuse what is not a field of symmetric positive definite matrices."""

    def __init__(self, function):
        self.function = function

    def __call__(self, points):
        values = np.asarray(self.function(points))
        if values.dtype.kind not in "iuf":
            raise SizingError(f"metric must return real numbers, got an array of {values.dtype}")
        values = values.astype(np.float64, copy=False)
        if values.shape == (2, 2):
            values = np.broadcast_to(values, (len(points), 2, 2))
        if values.shape != (len(points), 2, 2):
            raise SizingError(
                f"metric must return an array of shape (n, 2, 2) for n points (one matrix a point, see "
                f"metric_tensor), got {values.shape} for {len(points)} points"
            )
        return np.ascontiguousarray(checked_metric(values, points))


def checked_metric(values, points=None, what="metric returned"):
    """``values`` (n, 2, 2) if each matrix is finite, symmetric and positive definite; else a SizingError naming it."""
    a, b, b_t, c = values[:, 0, 0], values[:, 0, 1], values[:, 1, 0], values[:, 1, 1]
    # entry by entry, as NumPy's all(axis=(1, 2)) over the 2 x 2 matrices is a loop per matrix
    finite = np.isfinite(a) & np.isfinite(b) & np.isfinite(b_t) & np.isfinite(c)
    with np.errstate(invalid="ignore", over="ignore"):  # the first test names non-finite entries before these
        problems = (
            (~finite, "NaN or infinite entries"),
            (np.abs(b - b_t) > 1e-9 * (np.abs(a) + np.abs(c)), "matrices that are not symmetric"),
            ((a <= 0) | (a * c - b * b_t <= 0), "matrices that are not positive definite (a size of zero or below)"),
        )
    for bad, problem in problems:
        if bad.any():
            first = int(np.argmax(bad))
            where = "" if points is None else " at (" + ", ".join(f"{v:.6g}" for v in np.asarray(points)[first]) + ")"
            raise SizingError(
                f"{what} {int(bad.sum())} {problem}, e.g. {values[first].tolist()}{where}; build it with "
                "metric_tensor(major, minor, angle) from positive sizes"
            )
    return values


def as_metric_function(metric):
    """Return a checked callable ``(n, 2) -> (n, 2, 2)`` from what a user gives as ``metric``.

    Parameters
    ----------
    metric : callable or array_like, shape (2, 2)
        A function of an ``(n, 2)`` array of points returning ``(n, 2, 2)``
        matrices (e.g. built with :func:`metric_tensor`), or one matrix for
        the whole domain.

    Examples
    --------
    >>> import numpy as np
    >>> field = as_metric_function(metric_tensor(0.2, 0.05, 0.0))
    >>> field(np.zeros((3, 2))).shape
    (3, 2, 2)
    """
    if isinstance(metric, MetricGrid):  # checked when built, and a mean of its matrices is positive definite
        return metric
    if callable(metric):
        return _Checked(metric)
    constant = np.asarray(metric)
    if constant.shape != (2, 2) or constant.dtype.kind not in "iuf":
        # a complex or text matrix of the right shape was blamed on its shape
        got = f"of shape {constant.shape}" if constant.shape != (2, 2) else f"of {constant.dtype} values"
        raise SizingError(
            "metric must be a function of an (n, 2) array of points returning (n, 2, 2) matrices, or one 2 x 2 "
            f"matrix of real numbers, got {type(metric).__name__} {got}"
        )
    checked_metric(constant[None].astype(np.float64), what="the metric has")
    return _Checked(lambda points: constant)
