"""Raw binary velocity files: bare samples, read given their ``shape``, ``dtype`` and byte order.

The reader behind :func:`~terramesh.seismic.read_velocity` for a file name
it does not know (``file_format="binary"``): the file's size must be
``shape`` times the sample size, and values no velocity model has (bytes
read in the wrong order or type, see :data:`DECODED_RANGE`) are refused
before the velocity checks of :mod:`terramesh.seismic.model`.
"""

import os

import numpy as np

from ..errors import MeshFormatError, SizingError
from .model import build_model, check_values, checked_axis_order, to_model_order, units_factor

DECODED_RANGE = (1e-2, 1e6)
"""Bounds on the largest magnitude in a raw binary model (either unit) beyond which its bytes were misread."""


def read_binary(path, shape, dtype, byte_order, axis_order, spacing, origin, units):
    """The model in the raw binary file ``path``: :func:`~terramesh.seismic.read_velocity` for ``"binary"``.

    The options are :func:`~terramesh.seismic.read_velocity`'s, ``spacing``
    a tuple checked by :func:`~terramesh.seismic.model.checked_spacing` or None.
    """
    if shape is None:
        raise SizingError(
            f"{path}: a raw binary file needs its shape, e.g. shape=(nz, nx) with axis_order='zx' (--shape and"
            " --axis-order on the command line)"
        )
    try:
        sizes = np.atleast_1d(np.asarray(shape, dtype=np.float64))
    except (TypeError, ValueError):
        sizes = np.zeros(0)
    if sizes.ndim != 1 or len(sizes) not in (2, 3) or np.any(sizes != np.round(sizes)) or sizes.min() < 2:
        raise SizingError(f"shape must be 2 or 3 whole numbers of samples, each at least 2, got {shape!r}")
    shape = tuple(int(n) for n in sizes)
    order = checked_axis_order(axis_order, len(shape), path)
    orders = {"little": "<", "big": ">", "native": "="}
    if byte_order is not None and byte_order not in orders:
        raise SizingError(f"byte_order must be one of {sorted(orders)}, got {byte_order!r}")
    try:
        kind = np.dtype(dtype)
    except TypeError:
        raise SizingError(f"dtype must be a NumPy number type such as 'float32', got {dtype!r}") from None
    named = _named_byte_order(dtype, kind)
    if named is not None and byte_order is not None and _resolved(orders[byte_order]) != _resolved(named):
        raise SizingError(
            f"dtype {dtype!r} is {_BYTE_ORDER_NAMES[_resolved(named)]}-endian but byte_order={byte_order!r}; "
            "give the byte order once"
        )
    if named is None:
        byte_order = "little" if byte_order is None else byte_order
        kind = kind.newbyteorder(orders[byte_order])
    else:
        byte_order = _BYTE_ORDER_NAMES[_resolved(named)]
    if kind.kind not in "fiu":
        raise SizingError(f"dtype must be a NumPy number type such as 'float32', got {dtype!r}")
    expected = int(np.prod(shape)) * kind.itemsize
    actual = os.path.getsize(path)
    if actual != expected:
        fits = ""
        if actual % kind.itemsize == 0:
            fits = f"; it holds {actual // kind.itemsize:,} values of {kind.itemsize} bytes"
        raise MeshFormatError(
            f"{path}: the file has {actual:,} bytes but shape {shape} of {np.dtype(dtype).name} needs "
            f"{expected:,} bytes{fits}; check shape and dtype"
        )
    with np.errstate(invalid="ignore"):  # misread bytes may be signalling NaNs: _check_decoded says so
        array = np.fromfile(path, dtype=kind).reshape(shape).astype(np.float64)
    _check_decoded(array, path, kind, byte_order)
    if spacing is None:
        raise SizingError(f"{path}: a raw binary file does not state its grid spacing: pass spacing=(dx, dz)")
    check_values(array, path, order)
    advice = f"check the units (m/s or km/s), dtype (now {kind.name!r}) and byte_order (now {byte_order!r})"
    factor = units_factor(array, units or "m/s", path, axes=order, advice=lambda _: advice)
    values = to_model_order(array, order) * factor
    return build_model(values, spacing, origin, None, path)


_BYTE_ORDER_NAMES = {"<": "little", ">": "big"}


def _resolved(order):
    """``"<"`` or ``">"`` for a NumPy byte-order character, ``"="`` (native) resolved to this machine's."""
    if order in "=|":
        return "<" if np.little_endian else ">"
    return ">" if order == "!" else order


def _named_byte_order(dtype, kind):
    """The byte order a dtype names (``"<"``, ``">"``, ``"!"`` or ``"="``), or None if it names none.

    ``np.dtype("<f4").byteorder`` is ``"="`` on a little-endian machine,
    like plain ``"f4"``'s, so a string is read from its first character.
    """
    if isinstance(dtype, str):
        return dtype[0] if dtype[:1] in ("<", ">", "!", "=") else None
    return kind.byteorder if kind.byteorder in "<>" else None


def _check_decoded(array, path, kind, byte_order):
    """Refuse raw binary values no velocity model has, in m/s or km/s: bytes read in the wrong order or type.

    Read in the wrong byte order, 1500.0 as float32 is 1.2e-38; float32 data
    read as float64 gives 1e23 and more; random-looking bits give NaN too.
    """
    finite = array[np.isfinite(array)]
    largest = float(np.abs(finite).max()) if finite.size else np.nan
    # a few NaNs among plausible values are the model's own (an unfilled water column): check_values names them
    if DECODED_RANGE[0] <= largest <= DECODED_RANGE[1]:
        return
    bad = int(array.size - finite.size)
    found = f"{bad:,} NaN or infinite values and " if bad else ""
    other = "big" if byte_order != "big" else "little"
    raise MeshFormatError(
        f"{path}: {found}largest magnitude {largest:.3g}, which no velocity model has (in m/s or km/s): the bytes "
        f"are likely read in the wrong order or type; check byte_order (now {byte_order!r}; try {other!r}) and "
        f"dtype (now {kind.name!r}); on the command line --byte-order and --dtype"
    )
