"""Array chores inside kernels, written as loops: copies, growing, searching and sorting.

NumPy's own forms compile numba's library code at a fresh installation's
first run: a slice assignment from an array its shape checks and their
error messages (unicode formatting, 2-3 s), ``np.sort`` and ``np.argsort``
its quicksort or merge sort (1-2 s), ``np.searchsorted`` its comparisons.
These loops compile in a fraction of that and run as fast.
"""

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def copy_head(destination, source, count):
    """``destination[:count] = source[:count]`` for 1D arrays."""
    for i in range(count):
        destination[i] = source[i]


@numba.njit(cache=True, inline="always")
def copy_rows(destination, source, count):
    """``destination[:count] = source[:count]`` for 2D arrays of equal width."""
    for i in range(count):
        for j in range(source.shape[1]):
            destination[i, j] = source[i, j]


@numba.njit(cache=True)
def grown(array, size, fill):
    """A copy of C-contiguous ``array`` (1D or 2D) with ``size`` rows, those past the old ones ``fill``."""
    out = np.full((size,) + array.shape[1:], fill, dtype=array.dtype)
    flat_out = out.reshape(out.size)
    flat_in = array.reshape(array.size)
    for i in range(flat_in.shape[0]):
        flat_out[i] = flat_in[i]
    return out


@numba.njit(cache=True, inline="always")
def count_below(ascending, value):
    """How many of the ``ascending`` values are below ``value``: ``np.searchsorted(ascending, value)``."""
    low = 0
    high = ascending.shape[0]
    while low < high:
        middle = (low + high) // 2
        if ascending[middle] < value:
            low = middle + 1
        else:
            high = middle
    return low


@numba.njit(cache=True)
def sort_in_place(values, count):
    """Sort ``values[:count]`` ascending, in place (heapsort: no NaN among them).

    Not stable, which sorting plain numbers does not need: the result is
    the same array as ``np.sort`` gives.
    """
    for start in range(count // 2 - 1, -1, -1):
        _sift_down(values, start, count)
    for end in range(count - 1, 0, -1):
        values[0], values[end] = values[end], values[0]
        _sift_down(values, 0, end)


@numba.njit(cache=True, inline="always")
def _sift_down(values, root, count):
    """Restore the max-heap below ``root`` within ``values[:count]``."""
    while True:
        child = 2 * root + 1
        if child >= count:
            return
        if child + 1 < count and values[child] < values[child + 1]:
            child += 1
        if values[root] >= values[child]:
            return
        values[root], values[child] = values[child], values[root]
        root = child
