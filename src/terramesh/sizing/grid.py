"""Mesh size given on a regular grid and interpolated (bi)linearly."""

import numpy as np

from .._kernels import read_only
from .._kernels.raster import bilinear, trilinear
from ..errors import SizingError

__all__ = ["SizeGrid"]


def checked_axis(values, name, error=SizingError):
    """One grid axis as float64: finite, increasing and evenly spaced (made exactly so), else ``error``."""
    try:
        given = np.asarray(values)
        axis = given.astype(np.float64)
    except (TypeError, ValueError) as exc:
        raise error(f"grid axis {name} must be a 1-D array of numbers, got {values!r}") from exc
    if axis.ndim != 1 or axis.size < 2:
        raise error(f"grid axis {name} must be a 1-D array of at least two coordinates")
    if not np.all(np.isfinite(axis)):
        raise error(f"grid axis {name} has non-finite coordinates")
    steps = np.diff(axis)
    if np.any(steps <= 0):
        raise error(f"grid axis {name} must be strictly increasing")
    # coordinates stored in float32 (a NetCDF's) are each rounded to their own precision
    rounding = 4.0 * np.finfo(given.dtype).eps * np.abs(axis).max() if given.dtype.kind == "f" else 0.0
    if np.ptp(steps) > 1e-6 * steps.mean() + rounding:
        raise error(f"grid axis {name} must be evenly spaced (steps range {steps.min():g} to {steps.max():g})")
    # exactly regular from its ends: a float32 axis's first step alone put its 2401st node 0.15 steps off
    return axis[0] + np.arange(axis.size) * ((axis[-1] - axis[0]) / (axis.size - 1))


def interpolate_on_grid(values, origin, spacing, points):
    """(Bi/tri)linear interpolation of node ``values`` at ``points``, clamped to the grid.

    ``values`` has shape ``(nx, ny[, nz])`` with at least two nodes per
    axis, node ``(ix, iy)`` at ``origin + (ix, iy) * spacing``; ``points``
    is ``(n, dim)`` float64. Points outside the grid take the value of the
    nearest grid point. Returns ``(n,)``. Shared by :class:`SizeGrid` and
    :class:`terramesh.geometry.GridDomain`; callers validate.
    """
    interpolate = bilinear if values.ndim == 2 else trilinear
    return interpolate(read_only(values), origin, spacing, np.ascontiguousarray(points, dtype=np.float64))


class SizeGrid:
    """Target edge length on a regular grid, linearly interpolated between nodes.

    Parameters
    ----------
    axes : sequence of array_like
        One evenly spaced, increasing coordinate array per dimension
        (x, y[, z]), in the domain's units.
    values : array_like, shape (len(x), len(y)[, len(z)])
        Edge length at the grid nodes, same units as the coordinates,
        indexed ``[ix, iy]`` (NumPy's ``indexing="ij"``). Must be finite and
        positive.

    Raises
    ------
    SizingError
        For other than 2 or 3 axes, an axis that is not evenly spaced and
        increasing, or values that are not numbers, do not match the axes'
        shape, or are not positive and finite; when called, for points not
        of shape ``(n, dim)``.

    Notes
    -----
    Points outside the grid take the value of the nearest grid edge.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(0, 1, 3); y = np.linspace(0, 2, 5)
    >>> size = SizeGrid((x, y), 0.1 + np.add.outer(x, 0 * y))
    >>> size([(0.25, 1.0), (5.0, 1.0)]).round(6).tolist()
    [0.35, 1.1]
    """

    def __init__(self, axes, values):
        try:
            axes = list(axes)
        except TypeError:
            message = f"axes must be a sequence of 2 or 3 coordinate arrays (x, y[, z]), got {axes!r}"
            raise SizingError(message) from None
        if len(axes) not in (2, 3):
            raise SizingError(f"a SizeGrid needs 2 or 3 coordinate arrays (x, y[, z]), got {len(axes)} axes")
        self.axes = tuple(checked_axis(axis, name) for axis, name in zip(axes, "xyz", strict=False))
        try:
            self.values = np.ascontiguousarray(values, dtype=np.float64)
        except (TypeError, ValueError) as error:
            raise SizingError("size grid values must be an array of numbers") from error
        shape = tuple(axis.size for axis in self.axes)
        if self.values.shape != shape:
            raise SizingError(f"size values have shape {self.values.shape}, the grid axes need {shape}")
        bad = ~np.isfinite(self.values)
        if bad.any():
            raise SizingError(f"size grid has {int(bad.sum())} NaN or infinite values")
        if np.any(self.values <= 0):
            raise SizingError(f"size grid has {int(np.sum(self.values <= 0))} values that are zero or negative")
        self._origin = np.array([axis[0] for axis in self.axes])
        self._spacing = np.array([axis[1] - axis[0] for axis in self.axes])

    @property
    def dim(self):
        """Number of space dimensions."""
        return len(self.axes)

    @property
    def axis_names(self):
        """The axes' names in messages: ``"xy"`` or ``"xyz"`` (a seismic section's are ``"xz"``)."""
        return "xyz"[: self.dim]

    @property
    def bbox(self):
        """Grid extent, shape ``(2, dim)``."""
        return np.array([[axis[0] for axis in self.axes], [axis[-1] for axis in self.axes]])

    def covered(self, low, high):
        """Share of each axis of the box ``low``..``high`` that the grid's nodes span; below 0 where apart.

        An axis along which the box is flat counts as covered (1). Beyond its
        nodes a grid gives its edge's sizes.

        Examples
        --------
        >>> grid = SizeGrid((np.linspace(0, 1, 3), np.linspace(0, 4, 3)), np.ones((3, 3)))
        >>> grid.covered((0.5, 0.0), (1.5, 2.0)).tolist()
        [0.5, 1.0]
        """
        low, high = np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64)
        first, last = self.bbox
        length = high - low
        spanned = np.minimum(last, high) - np.maximum(first, low)
        return np.where(length > 0, spanned / np.where(length > 0, length, 1.0), 1.0)

    def __call__(self, points):
        """Interpolated edge length at ``points`` (shape ``(n, dim)``), shape ``(n,)``."""
        try:
            points = np.asarray(points, dtype=np.float64)
        except (TypeError, ValueError) as error:
            raise SizingError(f"points must be an (n, {self.dim}) array of numbers") from error
        if points.ndim == 1 and points.size in (0, self.dim):  # no point, or one point (x, y[, z])
            points = points.reshape(-1, self.dim)
        if points.ndim != 2 or points.shape[1] != self.dim:
            raise SizingError(f"points of a {self.dim}-D size grid must have shape (n, {self.dim}), not {points.shape}")
        sizes = interpolate_on_grid(self.values, self._origin, self._spacing, points)
        if np.isnan(sizes).any():  # only where a point is NaN (infinite ones are clamped to the grid's edge)
            nan = np.isnan(points).any(axis=1)
            raise SizingError(
                f"{int(nan.sum())} of {len(points)} points have NaN coordinates (the first, index "
                f"{int(np.argmax(nan))}): a size grid takes finite points, or infinite ones"
            )
        return sizes
