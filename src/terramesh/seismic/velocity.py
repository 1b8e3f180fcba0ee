"""Reading seismic velocity models: :func:`read_velocity`, for SEG-Y, raw binary, NetCDF and ``.npy`` files and arrays.

:func:`read_velocity` chooses the reader from the file name (or
``file_format``) and refuses the options that reader would ignore
(:data:`READER_OPTIONS`). The NetCDF, ``.npy`` and array readers are here;
SEG-Y's is in :mod:`terramesh.seismic.segy`, raw binary's in
:mod:`terramesh.seismic.binary`. Every reader puts the model into the
``(x, z)`` (or ``(x, y, z)``) frame described in
:mod:`terramesh.seismic.model`: metres, z negative downward, m/s.

The model type, the units and the limits of the velocity checks, and the
SEG-Y and raw binary readers' public names, are importable from here as
well, where they were defined before those modules were split off.
"""

import math
import os
import pathlib

import numpy as np

from .._kernels import physical_memory
from ..errors import MeshFormatError, SizingError
from ..readers.netcdf import check_classic_size
from .binary import DECODED_RANGE as DECODED_RANGE
from .binary import read_binary
from .model import KM_PER_S_BELOW as KM_PER_S_BELOW
from .model import M_PER_S_ABOVE as M_PER_S_ABOVE
from .model import MAX_VELOCITY as MAX_VELOCITY
from .model import MIN_VELOCITY as MIN_VELOCITY
from .model import MIXED_UNITS_ABOVE as MIXED_UNITS_ABOVE
from .model import (
    UNITS,
    VelocityModel,
    as_floats,
    build_model,
    check_values,
    checked_axis_order,
    checked_spacing,
    reconcile_spacing,
    to_model_order,
    units_factor,
)
from .segy import DEPTH_STEP_RATIO as DEPTH_STEP_RATIO
from .segy import SAMPLE_FORMATS as SAMPLE_FORMATS
from .segy import STEP_SPREAD as STEP_SPREAD
from .segy import read_segy, read_segy_header

__all__ = ["VelocityModel", "read_velocity", "read_segy_header", "UNITS"]

_CF_UNITS = {"m/s": "m/s", "m.s-1": "m/s", "ms-1": "m/s", "km/s": "km/s", "km.s-1": "km/s", "kms-1": "km/s"}
"""A NetCDF ``units`` attribute, spaces removed and lower case (so CF's ``"km s-1"`` too), to its unit."""

_LENGTH_UNITS = {
    "m": 1.0,
    "metre": 1.0,
    "metres": 1.0,
    "meter": 1.0,
    "meters": 1.0,
    "km": 1000.0,
    "kilometre": 1000.0,
    "kilometres": 1000.0,
    "kilometer": 1000.0,
    "kilometers": 1000.0,
}
"""A NetCDF coordinate's ``units`` attribute, lower case, to the factor that turns it into metres."""

_SEGY_SUFFIXES = (".segy", ".sgy")
_NETCDF_SUFFIXES = (".nc", ".nc4", ".cdf", ".netcdf")
_AXIS_NAMES = {
    "x": ("x", "distance", "offset", "range", "easting", "inline", "nx"),
    "y": ("y", "northing", "crossline", "ny"),
    "z": ("z", "depth", "elevation", "height", "nz"),
}
_DEPTH_NAMES = ("depth",)
_ELEVATION_NAMES = ("elevation", "height")


def _axis_of(name):
    lowered = name.lower()
    for axis, names in _AXIS_NAMES.items():
        if lowered in names:
            return axis
    return None


def _is_depth(name, values, positive):
    """Whether a NetCDF z coordinate holds depths (positive downward) rather than elevations.

    Its ``positive`` attribute decides (CF: ``"down"`` or ``"up"``); without
    one, a name like ``depth`` means depth and ``elevation`` or ``height``
    elevation; a plain ``z`` holding no negative value is a depth axis from
    the surface (0, 10, 20... m down), the layout of model files, as an
    elevation axis of a model whose top is the free surface reaches below 0.
    """
    if positive in ("down", "up"):
        return positive == "down"
    lowered = name.lower()
    if lowered in _DEPTH_NAMES:
        return True
    if lowered in _ELEVATION_NAMES:
        return False
    return bool(np.all(values >= 0))


def _refuse_too_large(shape, itemsize, path, variable):
    """Refuse a NetCDF variable whose values and their float64 copy do not fit in memory, before reading any.

    netCDF4 allocated the whole variable, and NumPy stopped with "Unable to
    allocate 149 GiB" from inside it (a 200,000 x 100,000 grid). The
    reader holds the file's values (``itemsize`` bytes each) and their
    float64 copy at once, so that much is needed at the least.
    """
    memory = physical_memory()
    count = math.prod(shape)
    needed = count * (itemsize + 8)
    if memory is not None and needed > memory:
        raise SizingError(
            f"{path}: variable {variable!r} has shape {tuple(shape)}, {count:.3g} values: read with their float64 copy "
            f"they need {needed / 2**30:.3g} GiB, more than this machine's {memory / 2**30:.0f} GiB of memory; cut a "
            "window of the model (ncks -d x,first,last in.nc out.nc, or xarray's isel) or take a coarser grid "
            "(ncks -d x,,,4 keeps every 4th sample) and read that"
        )


def _read_netcdf(path, variable, axis_order, spacing, origin, units):
    import netCDF4

    try:
        dataset = netCDF4.Dataset(path, "r")
    except OSError as error:
        raise MeshFormatError(f"{path}: cannot read as NetCDF: {error}") from error
    with dataset:
        # netCDF-C reads zeros past the end of a cut classic file: "zero or negative velocities" misnamed it
        check_classic_size(dataset, path)
        if variable is None:
            candidates = [
                name
                for name, var in dataset.variables.items()
                if var.ndim in (2, 3) and name not in dataset.dimensions and np.dtype(var.dtype).kind in "fiu"
            ]
            if len(candidates) != 1:
                raise MeshFormatError(
                    f"{path}: {'no' if not candidates else 'several'} 2-D or 3-D variables ({candidates}); "
                    "name the velocity with variable= (command line: --variable)"
                )
            variable = candidates[0]
        if variable not in dataset.variables:
            raise MeshFormatError(f"{path}: no variable {variable!r}; it has {list(dataset.variables)}")
        var = dataset.variables[variable]
        _refuse_too_large(var.shape, np.dtype(var.dtype).itemsize, path, variable)
        var.set_auto_mask(True)
        array = np.ma.filled(np.ma.asarray(var[...]).astype(np.float64), np.nan)
        dims = var.dimensions
        if units is None:
            units = str(getattr(var, "units", "m/s")).strip().replace(" ", "")
            attribute = units
            units = _CF_UNITS.get(units.replace(" ", "").lower())
            if units is None:
                raise MeshFormatError(
                    f"{path}: variable {variable!r} has units {attribute!r}, not a velocity this reads "
                    f"({', '.join(sorted(set(_CF_UNITS)))}); pass units='m/s' or 'km/s' if it is one"
                )
        coords = {}
        for dim in dims:
            if dim in dataset.variables and dataset.variables[dim].ndim == 1:
                coord = dataset.variables[dim]
                coords[dim] = (
                    np.asarray(coord[...], dtype=np.float64),
                    str(getattr(coord, "positive", "")).lower(),
                    str(getattr(coord, "units", "")).strip(),
                )
    if array.ndim not in (2, 3):
        raise MeshFormatError(f"{path}: variable {variable!r} has shape {array.shape}; a velocity model is 2-D or 3-D")
    if axis_order is None:
        named = [_axis_of(dim) for dim in dims]
        if None in named or len(set(named)) != len(named) or ("y" in named) != (array.ndim == 3):
            raise SizingError(
                f"{path}: cannot tell the axes of {variable!r} from its dimensions {dims}; pass axis_order"
            )
        axis_order = "".join(named)
    order = checked_axis_order(axis_order, array.ndim, path)
    check_values(array, path, dims)  # before the flips below: the index is the file's
    as_read = array  # np.flip gives views: the values are checked in this order below
    # coordinates as elevation (z up) in file order; a depth axis (see _is_depth) is negated
    found_spacing, found_origin, placed = [], [], True
    for axis in "xz" if array.ndim == 2 else "xyz":
        dim = dims[order.index(axis)]
        if dim not in coords:
            found_spacing = None
            break
        values, positive, length = coords[dim]
        scale = _LENGTH_UNITS.get(length.lower(), 1.0 if not length else None)  # no units: metres, as before
        if scale is None:
            if spacing is None or origin is None:
                raise MeshFormatError(
                    f"{path}: coordinate {dim!r} has units {length!r}, not a length this reads "
                    f"({', '.join(_LENGTH_UNITS)}); pass spacing= and origin= in metres to place the model "
                    "without the coordinates"
                )
            placed, scale = False, 1.0  # still orders the samples: only the signs of its steps are used
        values = values * scale
        if axis == "z" and _is_depth(dim, values, positive):
            values = -values
        steps = np.diff(values)
        if axis == "z" and np.all(steps > 0):  # bottom first: flip to top first, as to_model_order expects
            array = np.flip(array, axis=order.index("z"))
            values = values[::-1]
            steps = np.diff(values)
        step = abs(float(np.mean(steps)))
        if not np.all(np.isfinite(values)) or step == 0 or np.max(np.abs(np.abs(steps) - step)) > 1e-3 * step:
            raise MeshFormatError(f"{path}: coordinate {dim!r} is not evenly spaced")
        if axis != "z" and steps[0] < 0:
            array = np.flip(array, axis=order.index(axis))
            values = values[::-1]
        found_spacing.append(step)
        found_origin.append(float(values[0]))
    found_spacing = None if found_spacing is None or not placed else tuple(found_spacing)
    spacing = reconcile_spacing(checked_spacing(spacing, array.ndim), found_spacing, path, array.ndim)
    if origin is None and found_spacing is not None:
        origin = tuple(found_origin)
    factor = units_factor(as_read, units, path, axes=dims)
    values = to_model_order(array, order) * factor
    return build_model(values, spacing, origin, None, path)


def format_of(path, file_format):
    """The reader for the file ``path``: ``"segy"``, ``"binary"``, ``"netcdf"`` or ``"npy"``.

    ``file_format`` if given (another name is a MeshFormatError), else the
    one of the file name's suffix: ``"binary"`` for a suffix of no other.
    """
    formats = ("segy", "binary", "netcdf", "npy")
    if file_format is not None:
        if file_format not in formats:
            raise MeshFormatError(f"unknown velocity file format {file_format!r}; known: {', '.join(formats)}")
        return file_format
    suffix = pathlib.Path(path).suffix.lower()
    if suffix in _SEGY_SUFFIXES:
        return "segy"
    if suffix in _NETCDF_SUFFIXES:
        return "netcdf"
    if suffix in (".npy", ".npz"):  # an .npz is refused by name when read, not as raw bytes without a shape
        return "npy"
    return "binary"


def read_velocity(
    path_or_array,
    *,
    spacing=None,
    shape=None,
    dtype="float32",
    byte_order=None,
    axis_order=None,
    units=None,
    origin=None,
    variable=None,
    file_format=None,
    sample_format=None,
    line_bytes=None,
):
    """Read a P-wave velocity model into the ``(x, z)`` (or ``(x, y, z)``) frame, z negative downward, m/s.

    ========================  ===========  ================================================
    input                     format       what must be given
    ========================  ===========  ================================================
    ``*.segy``, ``*.sgy``     SEG-Y        ``spacing`` only if the headers lack it
    ``*.nc``, ``*.nc4``       NetCDF       ``spacing`` without coordinate variables;
                                           ``axis_order`` for unrecognised dimension names
    ``*.npy``                 NumPy        ``spacing``, ``axis_order`` (an ``*.npz``
                                           archive is refused by name)
    any other file name       raw binary   ``shape``, ``axis_order``, ``spacing`` (and
                                           ``dtype``, ``byte_order`` if not float32 little)
    a NumPy array             array        ``spacing``, ``axis_order``
    ========================  ===========  ================================================

    A SEG-Y file is a 2-D section, each trace a column at one ``x`` with its
    first sample on top, unless its inline and crossline numbers (trace
    header bytes 189 and 193, or ``line_bytes``) form a sorted grid of at
    least 2 x 2 lines: then it is a 3-D volume, read with
    :func:`segyio.tools.cube`, each
    trace a column at one ``(x, y)``, x along the inlines (the crossline
    number changes along x) unless the trace coordinates say otherwise.
    Its spacing comes from the headers (see :func:`read_segy_header`); a
    ``spacing`` given as well wins, with a warning if the two disagree.
    Traces whose coordinates decrease along x (or y) are turned around so
    that the model's axes increase. A depth step (the sample interval read
    as millimetres) more than 100 times larger or smaller than the trace
    spacing is refused unless ``spacing`` is given. The
    header coordinates do not move the model: pass ``origin`` (e.g. from
    :func:`read_segy_header`'s ``first_x``, ``first_y``) to place it. The
    traces of a 3-D survey that form no such grid (missing traces, line
    numbers at other bytes) are refused, not read as a section. In every
    other layout, the first sample along z is the top (the
    shallowest), as in SEG-Y and in finite-difference model files (a
    model's own ``values`` are the other way up, ``values[..., -1]`` the
    top: read them back as ``values[..., ::-1]``), except
    in a NetCDF file with a z coordinate variable, which places the
    samples: it holds depths (positive downward) if its ``positive``
    attribute is ``"down"``, or without that attribute if it is named
    ``depth`` or, not named ``elevation`` or ``height``, has no negative
    value (a ``z`` of 0, 10, 20... m is depth); otherwise elevations. Give
    an all-positive elevation axis ``positive="up"``. NetCDF coordinates
    are in the length their ``units`` attribute names: ``m`` (``metre``,
    ``meter``), ``km`` (``kilometre``, ``kilometer``), or metres without
    one; other units (degrees, feet) are refused unless ``spacing`` and
    ``origin`` are given, which then place the model.

    Parameters
    ----------
    path_or_array : str, os.PathLike or array_like
        A file, or velocities as a 2-D or 3-D array.
    spacing : float or sequence of float, optional
        Node spacing ``(dx, dz)`` or ``(dx, dy, dz)``, metres (one number
        for all axes).
    shape : sequence of int, optional
        Raw binary only: the number of samples along each axis, in the
        file's axis order (``axis_order``; slowest varying first, C order).
    dtype : str or numpy.dtype, optional
        Raw binary only: the sample type, ``"float32"`` by default; one
        that names a byte order (``">f4"``) is read in that order.
    byte_order : {"little", "big", "native"}, optional
        Raw binary only: the byte order of a ``dtype`` that names none,
        ``"little"`` by default; naming another order than ``dtype`` does
        is a SizingError.
    axis_order : str, optional
        The axes of the array or file, slowest varying first: ``"zx"``
        (rows are depths: the image layout) or ``"xz"`` (rows are traces)
        in 2-D, a permutation of ``"xyz"`` in 3-D. Required for arrays, raw
        binary and ``.npy`` files; NetCDF recognises dimensions named like
        x/distance/offset, y and z/depth.
    units : {"m/s", "km/s"}, optional
        Units of the values; velocities are converted to m/s. Defaults to
        the NetCDF variable's ``units`` attribute, else ``"m/s"``. Values
        whose largest is below 20 given as m/s look like km/s and warn;
        values faster than :data:`MAX_VELOCITY` (20,000 m/s) once converted
        are refused, saying so when they look like m/s given as km/s
        (smallest above 100).
    origin : sequence of float, optional
        Coordinates of the first trace's top sample: ``(x0, z_top)`` or
        ``(x0, y0, z_top)``, metres. Defaults to NetCDF coordinates where a
        file has them, else zeros: the model spans ``x`` (and ``y``) from 0 and
        ``z`` from 0 down to ``-(nz - 1) dz``.
    variable : str, optional
        NetCDF only: the variable to read; by default the only 2-D or 3-D one.
    file_format : {"segy", "binary", "netcdf", "npy"}, optional
        Overrides the format chosen from the file name.
    sample_format : {"ibm", "ieee"}, optional
        SEG-Y only: read the 4-byte float samples as IBM or IEEE floats
        whatever the sample format code (binary header bytes 3225-3226, 1
        or 5) says: for a mislabelled file, or to confirm the label of a
        model so slow that it reads as IBM floats mislabelled IEEE.
    line_bytes : tuple of int, optional
        SEG-Y only: the trace header bytes of the inline and crossline
        numbers, ``(inline, crossline)``, where a 3-D volume has them
        elsewhere than SEG-Y's 189 and 193 (see :func:`read_segy_header`).

    Returns
    -------
    VelocityModel
        Velocities in m/s on axes in metres, z negative downward.

    Raises
    ------
    MeshFormatError
        For a file that cannot be read as its format, a SEG-Y file
        :func:`read_segy_header` refuses (prestack, cut within a trace,
        headers that contradict each other, a 3-D survey that is no sorted
        grid), a SEG-Y file whose velocities exceed :data:`MAX_VELOCITY`
        (the message names the sample format code and, for IEEE floats
        labelled IBM, says so), a SEG-Y file of format code 5 (IEEE) whose
        samples read slower than water but decode as plausible IBM floats
        (code 1), naming both ranges (``sample_format`` reads it either
        way), a NetCDF coordinate whose
        ``units`` are no length (unless ``spacing`` and ``origin`` are
        given), or a raw binary file whose size is not ``shape`` x the
        ``dtype``'s size (the message gives both byte counts).
    SizingError
        For complex values (even with no imaginary part), NaN, infinite,
        zero or negative velocities, velocities above
        :data:`MAX_VELOCITY` (20,000 m/s) once in m/s, velocities below
        :data:`MIN_VELOCITY` (100 m/s) in a model reaching above
        :data:`MIXED_UNITS_ABOVE` (1000 m/s: km/s values among m/s ones),
        bad ``sample_format`` or ``line_bytes``, missing or bad
        ``spacing``, ``shape`` or ``axis_order``, unknown ``units``, a
        ``byte_order`` that contradicts ``dtype``, an option the file's format
        does not use (``shape`` for a SEG-Y file, say), a NetCDF variable
        whose values and their float64 copy exceed this machine's memory
        (shape and size named, before any is read), or, without
        ``spacing``, a SEG-Y depth step implausible next to its trace spacing.
    FileNotFoundError
        If there is no such file.
    IsADirectoryError
        If the path is a folder.

    Warns
    -----
    TerrameshWarning
        For values given as m/s that look like km/s.

    Examples
    --------
    Two traces (rows, ``axis_order="xz"``) of three samples, top first:

    >>> import numpy as np
    >>> model = read_velocity(np.array([[1.5, 2.0, 2.5], [1.5, 2.0, 3.0]]), spacing=(100.0, 50.0),
    ...                       axis_order="xz", units="km/s")
    >>> model.bbox.tolist()
    [[0.0, -100.0], [100.0, 0.0]]
    >>> model([(0.0, 0.0), (100.0, -100.0)]).tolist()  # the top of trace 1, the bottom of trace 2
    [1500.0, 3000.0]
    """
    if isinstance(path_or_array, (str, os.PathLike)):
        path = os.fspath(path_or_array)
        if not os.path.exists(path):
            raise FileNotFoundError(f"no such velocity file: {path!r}")
        if os.path.isdir(path):
            inside = sorted(os.listdir(path))
            shown = f"; in it: {inside[:5]}{' ...' if len(inside) > 5 else ''}" if inside else ", an empty one"
            raise IsADirectoryError(f"the velocity file {path!r} is a folder{shown}: give the file itself")
        kind = format_of(path, file_format)
        _refuse_unused(
            kind,
            path,
            shape=shape,
            dtype=dtype,
            byte_order=byte_order,
            axis_order=axis_order,
            variable=variable,
            sample_format=sample_format,
            line_bytes=line_bytes,
        )
        if kind == "segy":
            return read_segy(path, spacing, origin, units, sample_format, line_bytes)
        if kind == "netcdf":
            return _read_netcdf(path, variable, axis_order, spacing, origin, units)
        if kind == "binary":
            ndim = None if shape is None else np.size(shape)
            return read_binary(
                path, shape, dtype, byte_order, axis_order, checked_spacing(spacing, ndim), origin, units
            )
        try:
            array = np.load(path, allow_pickle=False)
        except (ValueError, EOFError, OSError) as error:  # truncated, object (pickled) or not a .npy file
            raise MeshFormatError(f"{path}: cannot read as .npy: {error}") from error
        if not isinstance(array, np.ndarray):  # an .npz archive: np.load gives a lazy NpzFile
            names = list(array.files)
            array.close()
            raise MeshFormatError(
                f"{path}: an .npz archive of arrays {names}, not one .npy array; save the velocities with np.save "
                f"(np.save('model.npy', np.load({path!r})[{(names or ['name'])[0]!r}]))"
            )
        where = path
    else:
        array, where = path_or_array, "the velocity array"
        _refuse_unused(
            "array",
            where,
            shape=shape,
            dtype=dtype,
            byte_order=byte_order,
            variable=variable,
            sample_format=sample_format,
            line_bytes=line_bytes,
        )
    array = as_floats(array, where)
    if array.ndim not in (2, 3) or min(array.shape) < 2:
        raise SizingError(f"{where} must be a 2-D or 3-D array with at least 2 samples per axis, got {array.shape}")
    order = checked_axis_order(axis_order, array.ndim, where)
    spacing = checked_spacing(spacing, array.ndim)
    if spacing is None:
        raise SizingError(f"{where} needs its grid spacing: pass spacing=(dx, dz) in metres")
    check_values(array, where, order)
    factor = units_factor(array, units or "m/s", where, axes=order)
    source = None if where.startswith("the") else where
    return build_model(to_model_order(array, order) * factor, spacing, origin, None, source)


READER_OPTIONS = {
    "segy": {"spacing", "origin", "units", "sample_format", "line_bytes"},
    "netcdf": {"spacing", "origin", "units", "axis_order", "variable"},
    "binary": {"spacing", "origin", "units", "axis_order", "shape", "dtype", "byte_order"},
    "npy": {"spacing", "origin", "units", "axis_order"},
    "array": {"spacing", "origin", "units", "axis_order"},
}
"""The options of :func:`read_velocity` each kind of input uses (:func:`format_of`'s kinds, and arrays)."""


def _refuse_unused(kind, where, **given):
    """Refuse options given (not None; ``dtype`` not float32) that ``kind``'s reader would ignore, silently."""
    try:
        default_dtype = given.get("dtype") is None or np.dtype(given["dtype"]) == np.dtype("float32")
    except TypeError:
        default_dtype = False  # a bad dtype: refused as unused here, or by name by the binary reader
    names = [
        name
        for name, value in given.items()
        if value is not None and not (name == "dtype" and default_dtype) and name not in READER_OPTIONS[kind]
    ]
    if names:
        what = "an array" if kind == "array" else f"a {kind} file"
        raise SizingError(f"{where}: {', '.join(names)} {'is' if len(names) == 1 else 'are'} not used for {what}")
