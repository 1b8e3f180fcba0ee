"""Shared by the size functions: input checks (one place, one wording) and the ground gradient."""

import numbers

import numpy as np

from ..._kernels.raster import gradient_norm, value_census
from ...errors import GeometryError, SizingError
from ..grid import GeoGrid
from ..projection import EARTH_RADIUS


def check_grid(grid):
    """The grid, or :class:`GeometryError` if it is not a :class:`GeoGrid`."""
    if not isinstance(grid, GeoGrid):
        raise GeometryError(f"grid must be a terramesh.coastal.GeoGrid, got {type(grid).__name__}")
    return grid


def positive(name, value, *, allow_zero=False, allow_inf=False):
    """``value`` as a float, or :class:`SizingError` unless it is positive (or zero) and finite (or inf)."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise SizingError(f"{name} must be a number, got {value!r}")
    value = float(value)
    if np.isnan(value) or (np.isinf(value) and not allow_inf) or value < 0 or (value == 0 and not allow_zero):
        kind = "non-negative" if allow_zero else "positive"
        raise SizingError(f"{name} must be a {kind}{'' if allow_inf else ' finite'} number, got {value!r}")
    return value


def field(name, values, shape=None, *, allow_inf=False, positive_only=False, dtype=np.float64):
    """``values`` as a C-contiguous array of ``dtype`` and, if given, ``shape``; NaN is refused.

    Returns a new array only when a conversion is needed; callers never
    write into it.
    """
    try:
        array = np.asarray(values, dtype=dtype)
    except (TypeError, ValueError):
        raise SizingError(f"{name} must be an array of numbers") from None
    if not array.flags.c_contiguous:
        array = np.ascontiguousarray(array)
    if shape is not None and array.shape != tuple(shape):
        raise SizingError(f"{name} has shape {array.shape}, expected {tuple(shape)} (the grid's (nx, ny))")
    if array.dtype.kind == "f":
        flat = array.reshape(-1)
        nans, infinite, non_positive = value_census(flat if flat.dtype == np.float64 else flat.astype(np.float64))
        if nans:
            raise SizingError(f"{name} has {nans:,} NaN values: fill or mask them first")
        if not allow_inf and infinite:
            raise SizingError(f"{name} has infinite values")
        if positive_only and non_positive:
            raise SizingError(f"{name} must be positive everywhere (smallest {float(array.min()):g})")
    return array


def mask(name, values, shape):
    """``values`` as a C-contiguous bool array of ``shape``."""
    array = np.asarray(values)
    if array.dtype != np.bool_:
        raise SizingError(f"{name} must be a boolean mask, got dtype {array.dtype}")
    if array.shape != tuple(shape):
        raise SizingError(f"{name} has shape {array.shape}, expected {tuple(shape)} (the grid's (nx, ny))")
    return np.ascontiguousarray(array)


def ground_gradient_norm(grid, values, water=None):
    """``|grad f|`` of a field on the grid, per ground metre, shape (nx, ny).

    Central differences, one-sided on the border (a GeoGrid has at least
    two nodes per axis). The east spacing is each row's ground step
    ``step cos(lat)``; the north coordinate is ``R lat`` (radians), the
    ground northing on the sphere. With ``water``, ``f`` is the signed
    distance ``values`` negated in the water (no temporary array is made).
    """
    signed = water is not None
    water = water if signed else np.zeros((1, 1), dtype=bool)
    north = EARTH_RADIUS * np.radians(grid.lat)
    return gradient_norm(values, water, signed, grid.ground_step, north)
