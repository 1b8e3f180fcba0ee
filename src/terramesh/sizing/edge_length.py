"""Turn what a user passes as ``edge_length`` into one validated size function."""

import numbers

import numpy as np

from ..errors import SizingError
from .grid import SizeGrid

__all__ = ["as_size_function"]


class ConstantSize:
    """A uniform size: ``value`` everywhere (what a number as ``edge_length`` becomes)."""

    def __init__(self, value):
        self.value = value

    def __call__(self, points):
        return np.full(len(points), self.value)


class _Checked:
    """Call a user's size function and refuse NaN, non-positive or misshapen output."""

    def __init__(self, function, name="edge_length"):
        self.function, self.name = function, name

    def __call__(self, points):
        values = np.asarray(self.function(points))
        if values.dtype.kind not in "iuf":  # complex parts were dropped with a NumPy warning a call
            raise SizingError(f"{self.name} must return real numbers, got an array of {values.dtype}")
        values = values.astype(np.float64, copy=False)
        if values.ndim == 0:
            values = np.full(len(points), float(values))
        values = values.reshape(-1)
        if values.shape[0] != len(points):
            raise SizingError(f"{self.name} returned {values.shape[0]} values for {len(points)} points")
        bad = ~np.isfinite(values)
        what = "NaN or infinite values"
        if not bad.any():
            bad = values <= 0
            what = "values that are zero or negative"
        if bad.any():
            first = int(np.argmax(bad))
            where = ", ".join(f"{float(v):.6g}" for v in np.asarray(points)[first])
            raise SizingError(
                f"{self.name} returned {int(bad.sum())} {what}, e.g. {values[first]:g} at ({where}): it must be "
                "positive wherever the generator asks, which includes points up to a few sizes outside the domain "
                "(the seeding's coarse lattices and the force steps reach past the boundary)"
            )
        return values


def as_size_function(edge_length, name="edge_length"):
    """Return a callable ``(n, dim) -> (n,)`` target edge length.

    Parameters
    ----------
    edge_length : float, callable or SizeGrid
        A positive number for a uniform mesh, a function of an ``(n, dim)``
        point array, or a :class:`SizeGrid`. Units are the domain's.
    name : str, optional
        The argument's name in error messages (``old_edge_length``, say).

    Raises
    ------
    SizingError
        For a non-positive or non-finite number, or anything else.

    Examples
    --------
    >>> as_size_function(0.5)([[0.0, 0.0], [1.0, 1.0]]).tolist()
    [0.5, 0.5]
    """
    if isinstance(edge_length, SizeGrid):
        return edge_length
    if isinstance(edge_length, numbers.Real) and not isinstance(edge_length, bool):
        value = float(edge_length)
        if not np.isfinite(value) or value <= 0:
            raise SizingError(f"{name} must be positive and finite, got {edge_length}")
        return ConstantSize(value)
    if callable(edge_length):
        return _Checked(edge_length, name)
    raise SizingError(
        f"{name} must be a number, a callable of an (n, dim) array or a SizeGrid, got {type(edge_length).__name__}"
    )
