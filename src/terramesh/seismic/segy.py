"""SEG-Y velocity files: :func:`read_segy_header`, and the reader behind ``read_velocity`` for ``*.segy``, ``*.sgy``.

A file is a 2-D section (one trace per ``x``) or a 3-D volume (traces on an
inline/crossline grid), opened with segyio. Its headers give the shape, the
spacing (trace coordinates, and the sample interval read as millimetres) and
the sample format; they are checked against each other and against the
file's size before a trace is read, and a file whose binary header lays the
traces out wrongly is read as the file itself says, with a warning. The
samples may be decoded as IBM or IEEE floats whatever the format code says
(``sample_format``). The model is placed in the frame of
:mod:`terramesh.seismic.model` by :func:`read_segy`.
"""

import math
import os
import struct
import warnings

import numpy as np

from ..errors import MeshFormatError, SizingError, warn_user
from .model import MAX_VELOCITY, build_model, check_values, checked_spacing, reconcile_spacing, units_factor

__all__ = ["read_segy_header"]

DEPTH_STEP_RATIO = 100.0
"""Largest ratio, either way, of a SEG-Y file's depth step (its sample interval read as mm) to its trace spacing.

Velocity models for wave solvers are usually gridded with steps of one
order of size on every axis (BP2004: dz/dx = 6.25/12.5 = 1/2). SEG-Y rev 2
defines the sample interval as microseconds for time data and metres or
feet for depth data, while depth models such as BP2004 (a rev 0 file: 6250
for 6.25 m) store millimetres, as this reader takes it. Metres read as
millimetres make dz 1000 times too small, so such a grid whose true dz/dx is
below 10 comes out below 1/100 and is refused, while a true grid up to 100
times finer in depth than across (or coarser) is still read; beyond that,
the header or the trace coordinates are not what the reader takes them for.
"""


def _scalar_of(header_scalar):
    """SEG-Y coordinate scalar (bytes 71-72): positive multiplies, negative divides, zero means one."""
    if header_scalar == 0:
        return 1.0
    return float(header_scalar) if header_scalar > 0 else 1.0 / abs(float(header_scalar))


def read_segy_header(path, *, line_bytes=None):
    """Size, spacing and sample format of a SEG-Y file, 2-D section or 3-D volume, from its headers (no trace read).

    A file whose inline and crossline numbers (trace header bytes 189-192
    and 193-196, or ``line_bytes``) form a sorted grid of at least 2 x 2
    lines is a 3-D volume; any other file is a 2-D section, one trace per
    ``x``, unless its traces show the lines of a 3-D survey, which is
    refused: line numbers that cover half their grid or more (missing
    traces, or traces in neither order), or trace coordinates that run
    back line after line over an area (line numbers at other bytes).

    ``dz`` is the sample interval of the binary header (bytes 3217-3218),
    else of the first trace header (bytes 117-118), read as millimetres.
    SEG-Y rev 2 defines both fields as microseconds for time data, hertz
    for frequency data and metres or feet for depth data; depth models
    such as BP2004 store millimetres there instead (6250 for 6.25 m), and
    that is how this reader takes them. Rev 2's extended sample interval
    (bytes 3273-3280), which overrides the field when nonzero, is not read.
    A ``dz`` more than :data:`DEPTH_STEP_RATIO` (100) times larger or
    smaller than ``dx`` (or ``dy``) is taken for a misread field: this
    warns, and :func:`~terramesh.seismic.read_velocity` refuses the file unless given
    ``spacing``. Trace coordinates are scaled by the first trace's bytes
    71-72 and rounded to the unit they are stored in (1 m for a scalar of
    1, 0.01 m for -100): a step is the distance from the first trace to the
    last over the number of steps, kept only when every trace lies within
    one such unit of where it puts it, and given as the roundest length
    the stored coordinates fit (6.25 m stored in whole metres reads 6.25
    m, not 6.263). In 2-D, ``dx`` is that step along the line of the
    source (bytes 73-80), receiver group (81-88) or CDP (181-188) ``(x,
    y)`` coordinates, tried in that order; traces whose x (along a line at
    one x: y) decreases are turned around, as in 3-D, so that x increases
    and ``first_x`` is the last trace's x. In 3-D, the CDP, source or
    group coordinates, tried in that order, give the steps from one
    crossline to the next along the first inline and from one inline to
    the next along the first crossline (the traces checked). ``x`` is
    the axis along which the crossline number changes (along each inline,
    the usual layout) unless the coordinates say the inlines run along
    ``y`` instead; a coordinate that decreases is turned around so that
    both axes increase. A value the headers do not give is None. The
    measurement system code (bytes 3255-3256) is not applied: lengths are
    metres.

    Parameters
    ----------
    path : str or os.PathLike
        A SEG-Y file (any sample format segyio reads).
    line_bytes : tuple of int, optional
        The trace header bytes of the inline and crossline numbers,
        ``(inline, crossline)``, where a file has them elsewhere than SEG-Y's
        189 and 193 (some exports write them at 9 and 21).

    Returns
    -------
    dict
        ``"shape"``: ``(n_traces, n_samples)`` in 2-D, ``(nx, ny,
        n_samples)`` in 3-D; ``"spacing"``: ``(dx, dz)`` or ``(dx, dy,
        dz)`` in metres, each a float or None; ``"first_x"`` (and in 3-D
        ``"first_y"``): the scaled coordinate of the first node, metres, or
        None; ``"sample_format"``: segyio's name of the sample format. In
        3-D also ``"x_axis"``: ``"xline"`` (x follows the crossline
        numbers) or ``"iline"``; and ``"rotation"``: the angle from the
        coordinates' x axis to the model's x axis, degrees, 0 for a grid
        along the coordinate axes (None without coordinates).

    Raises
    ------
    MeshFormatError
        If segyio cannot open the file as SEG-Y (the message names what
        the binary header says and the file contradicts, where it can: a
        truncated file, a mislabelled sample format), for prestack data
        (more than one offset per inline/crossline), for a sample format
        code SEG-Y does not define or segyio does not read, or for a binary
        header sample count (bytes 3221-3222) unlike the trace headers'
        (bytes 115-116) where the file's size fits both; for the traces of
        a 3-D survey that do not form a sorted inline/crossline grid (the
        message says what is missing or, for line numbers at other bytes,
        which bytes may hold them), or ``line_bytes`` whose numbers form
        no grid.
    SizingError
        For ``line_bytes`` that are not two trace header fields.
    FileNotFoundError
        If there is no such file.

    Warns
    -----
    TerrameshWarning
        For a file holding fewer traces than its binary header declares
        (bytes 3213-3214: cut short, or cut from a larger file with its
        headers copied), and for trace headers whose sample count differs
        from the binary header's, which the file's size fits. For a file
        read otherwise than its binary header lays it out, naming the
        field passed over: an extended textual header count (bytes
        3505-3506) in a rev 0 file, or one the file's size fits only
        without; a sample count (bytes 3221-3222) the file's size does not
        fit where the first trace header's does; bytes after exactly the
        traces the binary header declares.

    Examples
    --------
    >>> import tempfile, os, numpy as np, segyio
    >>> path = os.path.join(tempfile.mkdtemp(), "tiny.segy")
    >>> spec = segyio.spec(); spec.format, spec.samples, spec.tracecount = 5, range(4), 3
    >>> with segyio.create(path, spec) as f:
    ...     f.bin[segyio.BinField.Interval] = 5000
    ...     for i in range(3):
    ...         f.header[i] = {segyio.TraceField.SourceX: 100 * i, segyio.TraceField.SourceGroupScalar: -10}
    ...         f.trace[i] = np.full(4, 1500.0, dtype=np.float32)
    >>> info = read_segy_header(path)
    >>> info["shape"], info["spacing"]
    ((3, 4), (10.0, 5.0))

    A 3-D volume of 2 inlines by 3 crosslines, CDP coordinates 25 m apart
    along the inlines (x) and 50 m across them (y):

    >>> path = os.path.join(tempfile.mkdtemp(), "cube.segy")
    >>> spec = segyio.spec(); spec.format, spec.samples, spec.sorting = 5, range(4), 2
    >>> spec.ilines, spec.xlines = [1, 2], [10, 11, 12]
    >>> with segyio.create(path, spec) as f:
    ...     f.bin[segyio.BinField.Interval] = 5000
    ...     for trace, (il, xl) in enumerate((il, xl) for il in spec.ilines for xl in spec.xlines):
    ...         f.header[trace] = {segyio.TraceField.INLINE_3D: il, segyio.TraceField.CROSSLINE_3D: xl,
    ...                            segyio.TraceField.CDP_X: 25 * xl, segyio.TraceField.CDP_Y: 50 * il}
    ...         f.trace[trace] = np.full(4, 1500.0, dtype=np.float32)
    >>> info = read_segy_header(path)
    >>> info["shape"], info["spacing"], (info["first_x"], info["first_y"]), info["x_axis"]
    ((3, 2, 4), (25.0, 50.0, 5.0), (250.0, 50.0), 'xline')
    """
    import segyio

    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such SEG-Y file: {path!r}")
    line_bytes = _line_bytes(line_bytes)
    try:
        with _open_segy(path, segyio, line_bytes) as f:
            header = _segy_header(f, segyio, path, line_bytes)
    except MeshFormatError as error:
        raise MeshFormatError(f"{path}: {error}") from None
    except Exception as error:  # segyio raises RuntimeError, OSError, ValueError... on malformed files
        problem = _unopened_problem(path)
        raise MeshFormatError(f"{path}: cannot read as SEG-Y: {problem or error}") from error
    problem = _depth_step_problem(header, path, reading=False)
    if problem is not None:
        warn_user(problem)
    return {key: value for key, value in header.items() if not key.startswith("_")}


def _open_segy(path, segyio, line_bytes=None):
    """The file opened with its inline/crossline geometry if it is a 3-D volume, else as a 2-D section.

    ``line_bytes``: the trace header bytes of the inline and crossline
    numbers, checked by :func:`_line_bytes`; SEG-Y's 189 and 193 if None.
    A file whose binary header lays the traces out wrongly where the file
    itself says how (:func:`_segy_layout`) is opened as the file says.
    """
    iline, xline = _SEGY_LINE_BYTES if line_bytes is None else line_bytes
    layout = _segy_layout(path)
    if layout is not None:
        return _open_laid_out(path, segyio, layout, iline, xline)
    with warnings.catch_warnings():
        # segyio reads an unknown sample format code as IBM floats with a warning; _check_segy_layout refuses it
        warnings.filterwarnings("ignore", message="Unknown trace value format")
        try:
            f = segyio.open(path, "r", iline=iline, xline=xline)
        except Exception:  # segyio finds no sorted inline/crossline grid: a section (or a broken file, reported next)
            return segyio.open(path, "r", ignore_geometry=True)
    if f.unstructured or len(f.ilines) < 2 or len(f.xlines) < 2:  # a single line is a section
        f.close()
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Unknown trace value format")
            return segyio.open(path, "r", ignore_geometry=True)
    return f


def _open_laid_out(path, segyio, layout, iline, xline):
    """The file opened by segyio with ``layout``, ``(samples, traces, extended headers, format code)``.

    segyio.open lays a file out from its binary header alone and has no way
    to be told otherwise; segyio.create sets a layout through the same
    private call used here, on a new file. segyio's own search for the
    inline/crossline grid checks the file's size against the binary header
    again, so the grid is found here (:func:`_grid_of`) and given to segyio
    with its public ``interpret``; a file without one, or with a single
    line, is a section, as :func:`_open_segy` opens it.
    """
    n_samples, n_traces, ext_headers, code = layout
    try:
        from segyio import _segyio

        fd = _segyio.segyiofd(path, "r", 0)  # 0: big-endian, SEG-Y's byte order
        fd.segymake(samples=n_samples, tracecount=n_traces, format=code, ext_headers=ext_headers)
    except (ImportError, AttributeError, TypeError) as error:  # segyio's private layer changed (tested on 1.9)
        raise MeshFormatError(
            f"{path}: its binary header lays the traces out wrongly; the file holds {n_traces} traces of"
            f" {n_samples} samples after {ext_headers} extended headers, which this segyio"
            f" ({getattr(segyio, '__version__', '?')}) cannot be told ({error}): correct the binary header"
            " (samples at bytes 3221-3222, extended headers at 3505-3506) or install segyio 1.9"
        ) from None
    f = segyio.SegyFile(fd, filename=path, mode="r", iline=iline, xline=xline, endian="big")
    f._samples = np.arange(n_samples, dtype=np.float64)  # their times are not read: dz comes from the interval field
    grid = _grid_of(f, segyio, iline, xline)
    if grid is not None and len(grid[0]) > 1 and len(grid[1]) > 1:
        f.interpret(*grid)
    return f


def _grid_of(f, segyio, iline, xline):
    """``(ilines, xlines, offsets, sorting)`` of traces that fill an inline/crossline/offset grid in order, or None.

    As segyio.open finds it: the line numbers in the order the traces
    first give them, the traces sorted by inline then crossline (inline
    sorting) or the other way round, offsets fastest.
    """
    numbers = [f.attributes(field)[:] for field in (iline, xline, segyio.TraceField.offset)]
    lines = [values[np.sort(np.unique(values, return_index=True)[1])] for values in numbers]
    ilines, xlines, offsets = lines
    if len(ilines) * len(xlines) * len(offsets) != f.tracecount:
        return None
    sortings = {segyio.TraceSortingFormat.INLINE_SORTING: (0, 1), segyio.TraceSortingFormat.CROSSLINE_SORTING: (1, 0)}
    for sorting, (slow, fast) in sortings.items():
        counts = (len(lines[slow]), len(lines[fast]), len(offsets))
        expected = (
            np.repeat(lines[slow], counts[1] * counts[2]),
            np.tile(np.repeat(lines[fast], counts[2]), counts[0]),
            np.tile(offsets, counts[0] * counts[1]),
        )
        if all(np.array_equal(numbers[axis], values) for axis, values in zip((slow, fast, 2), expected, strict=True)):
            return ilines, xlines, offsets, sorting
    return None


def _segy_layout(path):
    """How to lay out a SEG-Y file whose binary header lays its traces out wrongly, or None to follow the header.

    segyio takes the number of extended textual headers (bytes 3505-3506),
    the sample count (bytes 3221-3222) and the sample format code from the
    binary header, and refuses a file that is not a whole number of traces
    by them. Where the file says otherwise, it is read as it says, with a
    warning naming the field passed over:

    * extended textual headers that are junk: rev 0 files (byte 3501 is 0)
      have none and often leave bytes 3505-3506 unassigned, so a count
      there is ignored in a rev 0 file, and in any file where taking it
      leaves a part of a trace while ignoring it leaves whole traces;
    * a sample count that leaves a part of a trace (or is 0) where the
      first trace header's (bytes 115-116) leaves whole traces;
    * bytes after the last trace: the file holds exactly the traces the
      binary header declares (bytes 3213-3214, or rev 2's 3261-3264) and
      less than a trace more, which is no trace (a cut file holds fewer).
      A file holding another count and part of a trace is refused by
      :func:`_unopened_problem`.

    Returns ``(samples, traces, extended headers, format code)``.
    """
    try:
        with open(path, "rb") as stream:
            head = stream.read(3600)
            total = os.path.getsize(path)
    except OSError:
        return None
    if len(head) < 3600:
        return None
    (declared,) = struct.unpack(">h", head[3212:3214])
    n_samples, code = struct.unpack(">Hh", head[3220:3222] + head[3224:3226])
    revision, (ext_headers,) = head[3500], struct.unpack(">h", head[3504:3506])
    ext_traces, ext_samples = struct.unpack(">II", head[3260:3264] + head[3268:3272])
    if code not in _SEGY_SAMPLE_BYTES or (revision >= 2 and ext_samples not in (0, n_samples)):
        return None  # a code segyio does not read, or rev 2's extended sample count: as segyio lays it out
    if revision >= 2 and ext_traces:
        declared, traces_field = ext_traces, "bytes 3261-3264"
    else:
        traces_field = "bytes 3213-3214"
    size = _SEGY_SAMPLE_BYTES[code]

    def whole(extended, samples):  # the file is whole traces of this layout
        data = total - 3600 - 3200 * extended
        return samples > 0 and data > 0 and data % (240 + samples * size) == 0

    layout, notes = [n_samples, None, max(ext_headers, 0), code], []
    if ext_headers > 0 and whole(0, n_samples) and (revision == 0 or not whole(ext_headers, n_samples)):
        layout[2] = 0
        why = "only without them is the file whole traces"
        if revision == 0:
            why = "a rev 0 file (byte 3501 is 0) has none"
        notes.append(f"bytes 3505-3506 say {ext_headers} extended textual headers, but {why}: read without them")
    try:
        with open(path, "rb") as stream:
            stream.seek(3600 + 3200 * layout[2] + 114)
            (first,) = struct.unpack(">H", stream.read(2))
    except (OSError, struct.error):
        first = 0
    if first and first != n_samples and not whole(layout[2], n_samples) and whole(layout[2], first):
        layout[0] = first
        notes.append(
            f"the binary header's sample count (bytes 3221-3222) is {n_samples} but the first trace header's (bytes "
            f"115-116) is {first}, and the file's size fits only the trace header's: read with {first} samples per "
            "trace"
        )
    data, trace = total - 3600 - 3200 * layout[2], 240 + layout[0] * size
    if layout[0] and data > trace and data % trace:
        traces, left = divmod(data, trace)
        if traces == declared and _other_sample_size(data, declared, layout[0], size) is None:
            layout[1] = traces
            notes.append(
                f"{left} trailing bytes after the {traces} whole traces the binary header declares ({traces_field}): "
                "read the traces, the trailing bytes ignored"
            )
    if not notes:
        return None
    if layout[1] is None:
        layout[1] = data // trace
    warn_user(f"{path}: {'; '.join(notes)}")
    return tuple(layout)


_SEGY_LINE_BYTES = (189, 193)
"""The trace header bytes where SEG-Y puts the inline and crossline numbers of a 3-D volume."""

_SEGY_COORDINATES = {"source": (73, 77, "73-80"), "receiver group": (81, 85, "81-88"), "CDP": (181, 185, "181-188")}
"""Each ``(x, y)`` pair of trace header coordinates: the bytes of x and y, and the bytes the pair spans."""


def _line_bytes(line_bytes):
    """``line_bytes`` as two trace header field positions segyio reads, or None; a SizingError names a bad one."""
    if line_bytes is None:
        return None
    import segyio

    fields = {int(field) for field in segyio.TraceField.enums()}
    try:
        iline, xline = (int(byte) for byte in line_bytes)
        valid = iline == line_bytes[0] and xline == line_bytes[1] and iline != xline and {iline, xline} <= fields
    except (TypeError, ValueError):
        valid = False
    if not valid:
        raise SizingError(
            "line_bytes must be the first bytes of two different trace header fields holding the inline and crossline "
            f"numbers, as (inline, crossline): SEG-Y puts them at {_SEGY_LINE_BYTES}; got {line_bytes!r}"
        )
    return iline, xline


_SEGY_SAMPLE_BYTES = {1: 4, 2: 4, 3: 2, 5: 4, 6: 8, 8: 1, 9: 8, 10: 4, 11: 2, 12: 8, 16: 1}
"""Bytes per sample of each SEG-Y sample format code (binary header bytes 3225-3226) segyio reads."""

_SEGY_UNREADABLE_FORMATS = {
    4: "4-byte fixed point with gain",
    7: "3-byte signed integer",
    15: "3-byte unsigned integer",
}
"""Sample format codes SEG-Y defines but segyio does not read (it would decode them as IBM floats)."""

_SEGY_CODES_OF_SIZE = {1: "8", 2: "3 or 11", 4: "1 (IBM float), 5 (IEEE float), 2 or 10", 8: "6 (IEEE double), 9 or 12"}
"""The sample format codes whose samples have a given number of bytes, for the advice on a mislabelled code."""


def _format_code_problem(code):
    """Why a SEG-Y sample format code (binary header bytes 3225-3226) cannot be read, or None if it can."""
    if code in _SEGY_SAMPLE_BYTES:
        return None
    if code in _SEGY_UNREADABLE_FORMATS:
        return (
            f"sample format code {code} (binary header bytes 3225-3226: {_SEGY_UNREADABLE_FORMATS[code]}) is not "
            "read; convert the samples to IEEE floats (code 5)"
        )
    swapped = ((code & 0xFF) << 8) | ((code >> 8) & 0xFF)
    if swapped in _SEGY_SAMPLE_BYTES:  # a little-endian file: its 5 reads as 1280
        return (
            f"sample format code {code} (binary header bytes 3225-3226) is {swapped} read the other way round: the "
            "file is little-endian, which is not read; convert it to big-endian SEG-Y (the standard byte order)"
        )
    codes = ", ".join(str(c) for c in sorted({*_SEGY_SAMPLE_BYTES, *_SEGY_UNREADABLE_FORMATS}))
    return (
        f"sample format code {code} (binary header bytes 3225-3226) is none SEG-Y defines ({codes}): the binary "
        "header is damaged or the file is not SEG-Y; velocity models are usually 1 (IBM float) or 5 (IEEE float)"
    )


def _other_sample_size(data, declared, n_samples, size):
    """The sample size, other than ``size``, with which ``data`` bytes of traces are exactly ``declared`` traces."""
    for other in sorted(set(_SEGY_CODES_OF_SIZE) - {size}):
        if declared > 0 and data == declared * (240 + n_samples * other):
            return other
    return None


def _mislabel_advice(declared, other, field="bytes 3213-3214"):
    return (
        f"with {other}-byte samples the file holds exactly the {declared} traces the binary header declares "
        f"({field}): the sample format code is likely wrong ({other}-byte samples are code "
        f"{_SEGY_CODES_OF_SIZE[other]})"
    )


def _check_segy_layout(f, segyio, path):
    """Refuse a SEG-Y file whose binary header contradicts its trace headers or its size, naming the fields.

    segyio lays the traces out from the binary header's sample format code
    and sample count alone; when either is wrong, every trace after the
    first is read from the wrong place, and the misread samples or trace
    coordinates were then reported as negative velocities or a missing
    spacing. A file cut at a trace boundary opened as a smaller model.
    The trace count (bytes 3213-3214, or rev 2's 3261-3264 when nonzero)
    counts the traces of one ensemble (a shot, a CDP) in prestack data, so
    a file holding more traces than it declares is not judged by it.
    """
    code = int(f.bin[segyio.BinField.Format])
    problem = _format_code_problem(code)
    if problem is not None:
        raise MeshFormatError(problem)
    n_samples, n_traces = len(f.samples), f.tracecount
    if int(f.bin[segyio.BinField.ExtSamples]) == n_samples != int(f.bin[segyio.BinField.Samples]):
        samples_field = "the binary header's extended sample count (bytes 3269-3272)"
    else:
        samples_field = "the binary header's sample count (bytes 3221-3222)"
    count = segyio.TraceField.TRACE_SAMPLE_COUNT
    first = int(f.header[0][count]) if n_traces else 0
    # where the layout puts the last trace header; a writer may leave later counts 0, so only a count tells
    last = int(f.header[n_traces - 1][count]) if n_traces > 1 else 0
    size = _SEGY_SAMPLE_BYTES[code]
    data = os.path.getsize(path) - 3600 - 3200 * int(f.ext_headers)
    # bytes 115-116 hold 16 bits: a longer trace's count wraps, so counts are compared modulo 2**16
    last_fits = bool(last) and (last - n_samples) % 65536 == 0
    last_unlike = bool(last) and (last - first) % 65536 != 0 and not last_fits
    disagree = None
    if first and (first - n_samples) % 65536:
        disagree = f"{samples_field} is {n_samples} but the first trace header's (bytes 115-116) is {first}"
        if data % (240 + first * size) == 0:  # the file is whole traces either way: no telling which is right
            raise MeshFormatError(f"{disagree}: one of them is wrong, and the traces cannot be laid out; correct it")
        if not last_unlike:  # else refused below, naming the three counts
            # segyio opened the file by the binary header's count: its size is whole traces of that count alone
            agrees = ", as does the last trace header's" if last_fits else ""
            warn_user(f"{path}: {disagree}; the file's size fits the binary header's{agrees}, which is used")
    # rev 2's extended count overrides when nonzero; before rev 2 (byte 3501) its bytes are unassigned, maybe junk
    extended = int(f.bin[segyio.BinField.ExtTraces]) if int(f.bin[segyio.BinField.SEGYRevision]) >= 2 else 0
    declared, traces_field = (
        (extended, "bytes 3261-3264") if extended else (int(f.bin[segyio.BinField.Traces]), "bytes 3213-3214")
    )
    other = None if declared == n_traces else _other_sample_size(data, declared, n_samples, size)
    where = f"sample format code {code} ({f.format}) and {n_samples} samples per trace"
    mislabel = None if other is None else _mislabel_advice(declared, other, traces_field)
    if first and last_unlike:
        if disagree is not None:  # the counts disagree already: the format code is not to blame
            raise MeshFormatError(
                f"{disagree}, and the last trace header's, where the binary header's count puts it, {last}: the "
                "traces cannot be laid out; correct the wrong counts"
            )
        raise MeshFormatError(
            f"the last trace header says {last} samples, the first {first}: the traces are not where the {where} "
            f"put them; {mislabel or 'the sample format code is likely wrong'}"
        )
    if mislabel is not None:
        raise MeshFormatError(f"the file holds {n_traces} traces by its {where}, but {mislabel}")
    if declared > n_traces:
        # a file cut short at a trace boundary, or one cut from a larger file with its headers copied (segyio's
        # own copy idiom does that): the file alone cannot tell, so the traces it holds are read, with a word
        warn_user(
            f"{path}: the binary header ({traces_field}) declares {declared} traces, the file holds {n_traces}: "
            f"read as a model of {n_traces} traces; if the file was cut short, copy or export it again"
        )


def _unopened_problem(path):
    """What in a SEG-Y file's binary header keeps segyio from opening it, or None if nothing there says.

    segyio's own message ("trace count inconsistent with file size") names
    no field; the format code, the sample counts and the file size do.
    """
    try:
        with open(path, "rb") as stream:
            head = stream.read(3600 + 240)
        total = os.path.getsize(path)
    except OSError:
        return None
    if len(head) < 3600:
        return f"the file ends at byte {len(head):,}, within the 3600 bytes of SEG-Y's headers: truncated, or not SEG-Y"
    (declared,) = struct.unpack(">h", head[3212:3214])
    n_samples, code = struct.unpack(">Hh", head[3220:3222] + head[3224:3226])
    problem = _format_code_problem(code)
    if problem is not None:
        return problem
    extended = max(struct.unpack(">h", head[3504:3506])[0], 0)
    if extended == 0 and len(head) == 3840:  # the first trace header follows the binary header
        (first,) = struct.unpack(">H", head[3600 + 114 : 3600 + 116])
        if first and first != n_samples:
            return (
                f"the binary header's sample count (bytes 3221-3222) is {n_samples} but the first trace header's "
                f"(bytes 115-116) is {first}: one of them is wrong, and the traces cannot be laid out; correct the "
                "wrong one"
            )
    size, data = _SEGY_SAMPLE_BYTES[code], total - 3600 - 3200 * extended
    other = _other_sample_size(data, declared, n_samples, size)
    if other is not None:
        return f"its size does not fit the sample format code {code} and {n_samples} samples per trace, but " + (
            _mislabel_advice(declared, other)
        )
    if data <= 0:
        declares = f" (the binary header declares {declared} traces, bytes 3213-3214)" if declared > 0 else ""
        return f"no traces follow the headers{declares}: the file is truncated"
    trace = 240 + n_samples * size
    if n_samples and data % trace:
        whole, left = divmod(data, trace)
        layout = (
            f"{whole} whole traces of {trace} bytes (a 240-byte header and {n_samples} samples of {size} bytes, by the "
            f"sample format code {code} and the binary header's sample count) and {left} bytes more"
        )
        if declared > whole:
            return (
                f"truncated mid-trace: the {data:,} bytes of traces are {layout}; the binary header declares "
                f"{declared} traces (bytes 3213-3214)"
            )
        # a count of one ensemble (prestack, 3-D), or none, does not tell a cut file from bytes after its traces
        declares = f"; the binary header declares {declared} traces (bytes 3213-3214)" if declared > 0 else ""
        return (
            f"the {data:,} bytes of traces are {layout}{declares}: cut short within a trace, or {left} bytes after "
            f"the last; if its traces are all there, read a copy without those bytes (head -c "
            f"{total - left} FILE > COPY)"
        )
    return None


def _segy_header(f, segyio, path, line_bytes=None):
    """The public header fields, plus ``_``-prefixed ones that say how to lay a 3-D cube out."""
    _check_segy_layout(f, segyio, path)
    n_samples = len(f.samples)
    interval, field = int(f.bin[segyio.BinField.Interval]), "binary header bytes 3217-3218"
    if interval == 0 and f.tracecount:
        interval, field = int(f.header[0][segyio.TraceField.TRACE_SAMPLE_INTERVAL]), "trace header bytes 117-118"
        if (
            interval
        ):  # both reviewers of the readers took a cleared binary field for granted: BP2004's 6.25 m became 24.08
            warn_user(
                f"{path}: the binary header's sample interval (bytes 3217-3218) is 0; the first trace header's "
                f"(bytes 117-118), {interval}, is taken: dz = {interval / 1000:g} m if it is in millimetres; pass "
                "spacing if that is wrong"
            )
    if interval < 0:
        # segyio reads the field as a signed 16-bit number: a step of 50 m, stored as 50000 mm, read as -15536 and
        # was said to be missing
        warn_user(
            f"{path}: the sample interval ({field}) reads as {interval} when signed; taken as {interval + 65536}, "
            f"unsigned ({(interval + 65536) / 1000:g} m a sample, past the 32.767 m a signed field holds); pass "
            "spacing if that is wrong"
        )
        interval += 65536
    dz = interval / 1000.0 if interval > 0 else None
    if not f.unstructured:
        header = _segy_header_3d(f, segyio, n_samples, dz)
    else:
        header = _segy_header_2d(f, segyio, n_samples, dz, line_bytes)
    header.update(_interval=interval, _interval_field=field, _format_code=int(f.bin[segyio.BinField.Format]))
    header.update(_data_offset=3600 + 3200 * int(f.ext_headers), _traces=f.tracecount)
    return header


def _segy_header_2d(f, segyio, n_samples, dz, line_bytes):
    """The header fields of a file opened as a 2-D section, after refusing one that holds the lines of a 3-D survey."""
    n_traces = f.tracecount
    _refuse_irregular_volume(f, line_bytes)
    dx, first_x, decreasing = None, None, False
    if n_traces >= 2:
        unit = _scalar_of(int(f.header[0][segyio.TraceField.SourceGroupScalar]))
        for name, (x_byte, y_byte, span) in _SEGY_COORDINATES.items():
            points = unit * np.column_stack((f.attributes(x_byte)[:], f.attributes(y_byte)[:])).astype(np.float64)
            _refuse_survey_lines(f, segyio, points, unit, f"{name} coordinates (trace header bytes {span})")
            if dx is not None:
                continue  # found in an earlier pair; the later ones are only checked for a 3-D survey
            step = _even_step(points, unit)
            length = None if step is None else _roundest(points, step, unit)
            if length is not None:
                # along x, or along y for a line at one x (north-south): the traces are turned to increase
                decreasing = bool(step[0] < 0 if step[0] != 0 else step[1] < 0)
                dx = length
                first_x = _low_end(float(points[0, 0]), float(step[0]), n_traces)
    return {
        "shape": (n_traces, n_samples),
        "spacing": (dx, dz),
        "first_x": first_x,
        "sample_format": str(f.format),
        "_flip": (decreasing,),
    }


def _refuse_irregular_volume(f, line_bytes):
    """Refuse a file opened as a section whose inline/crossline numbers cover a grid: an incomplete or unsorted volume.

    segyio lays out only a full grid sorted by inline or crossline; any
    other was read as a 2-D section of all its traces side by side (a cube
    of 30 x 40 lines with 3 traces missing as a section 30 km wide). A
    crooked 2-D line taken from a volume (an arbitrary line) has both
    numbers changing too, but covers few of their pairs: it must fill half
    the grid to count, unless ``line_bytes`` are given (the user expects a
    volume), when a file whose numbers there form no grid at all is refused
    too.
    """
    iline, xline = _SEGY_LINE_BYTES if line_bytes is None else line_bytes
    numbers = np.column_stack((f.attributes(iline)[:], f.attributes(xline)[:]))
    inlines, crosslines = np.unique(numbers[:, 0]), np.unique(numbers[:, 1])
    pairs = np.unique(numbers, axis=0)
    n_il, n_xl, n_pairs = len(inlines), len(crosslines), len(pairs)
    where = f"the traces' inline and crossline numbers (trace header bytes {iline} and {xline})"
    # two traces a line on average at least: three traces on a staircase ((1, 1), (1, 2), (2, 2)) are a line
    crossing = n_il >= 2 and n_xl >= 2 and n_pairs >= 2 * max(n_il, n_xl)
    # with line_bytes given, the user says it is a volume: however few pairs it covers, it is one
    if not (crossing and (2 * n_pairs >= n_il * n_xl or line_bytes is not None)):
        if line_bytes is not None:
            raise MeshFormatError(
                f"{where}, given by line_bytes, take {n_il} and {n_xl} values in {n_pairs} pairs: no grid of inlines "
                "and crosslines (at least 2 x 2 lines, in inline or crossline order); check the bytes, or leave "
                "line_bytes out to read a 2-D section"
            )
        return
    seen = np.zeros((n_il, n_xl), dtype=bool)
    seen[np.searchsorted(inlines, pairs[:, 0]), np.searchsorted(crosslines, pairs[:, 1])] = True
    missing = n_il * n_xl - n_pairs
    if missing:
        i, j = np.argwhere(~seen)[0]
        why = (
            f"an irregular one: {n_pairs} of the {n_il} x {n_xl} = {n_il * n_xl} traces of its grid, {missing} missing "
            f"(the first at inline {inlines[i]}, crossline {crosslines[j]})"
        )
        advice = (
            "export the volume again with every trace of the grid, or fill the missing ones (with copies of their "
            "neighbours, say) and sort the traces by inline, then crossline"
        )
    elif f.tracecount > n_pairs:
        why = f"{f.tracecount - n_pairs} of its {f.tracecount} traces repeat an inline/crossline pair"
        advice = "keep one trace per pair (prestack gathers are no velocity model)"
    else:
        why = f"its {f.tracecount} traces are sorted by neither inline nor crossline"
        advice = "sort them by inline, then crossline"
    raise MeshFormatError(
        f"{where} take {n_il} and {n_xl} values: a 3-D volume, not a 2-D section, but {why}, which is not read; "
        f"{advice}"
    )


def _refuse_survey_lines(f, segyio, points, unit, what):
    """Refuse a file opened as a section whose trace positions ``points`` run line after line over an area.

    The traces of a 2-D line move forward along it; those of a 3-D volume
    run along one line, jump back to the start of the next, and so on, and
    the lines lie side by side. Only jumps back by more than two steps
    count, so a line that turns back on itself (a V-shaped arbitrary line)
    is not taken for a volume, and the lines must spread across the first
    one's direction by more than a step, so traces lacking coordinates (0)
    in a line along x are not either. ``unit``: the coordinates' stored
    unit, metres. ``what`` names the coordinates for the message. Traces
    without coordinates (0, 0: dead or auxiliary traces in a line at UTM
    coordinates) are left out: one of them made a line "run back" once,
    across 4.5e6 m.
    """
    points = points[np.any(points != 0, axis=1)]
    steps = np.diff(points, axis=0)
    moving = np.flatnonzero(np.any(steps != 0, axis=1))
    if moving.size == 0:
        return
    length = float(np.hypot(*steps[moving[0]]))
    direction = steps[moving[0]] / length
    along, across = points @ direction, points @ np.array([-direction[1], direction[0]])
    starts = np.flatnonzero(np.diff(along) < -max(2.0 * length, 2.0 * unit)) + 1
    spread = float(np.ptp(across))
    if starts.size == 0 or spread <= max(length, 2.0 * unit):
        return
    runs = np.diff(np.concatenate(([0], starts, [len(points)])))
    every = f"every {runs[0]} traces" if np.all(runs == runs[0]) else f"after {runs.min()} to {runs.max()} traces"
    found = _line_number_bytes(f, segyio, int(runs[0]))
    if found is None:
        advice = (
            "give the trace header bytes of its inline and crossline numbers with line_bytes=(inline, crossline) "
            "to read it as a 3-D volume (some exports put them at 9 and 21)"
        )
    else:
        advice = (
            f"bytes {found[0]} and {found[1]} hold numbers that stay the same along each run and change along it: if "
            f"those are its inline and crossline numbers, pass line_bytes={found} to read it as a 3-D volume"
        )
    raise MeshFormatError(
        f"the traces' {what} run back {starts.size} times, {every}, and the {starts.size + 1} runs lie over "
        f"{spread:g} m across the first one: the lines of a 3-D survey, not one 2-D line; no inline/crossline grid "
        f"is at trace header bytes {_SEGY_LINE_BYTES[0]} and {_SEGY_LINE_BYTES[1]}, where SEG-Y puts the line "
        f"numbers; {advice}"
    )


def _line_number_bytes(f, segyio, run):
    """The trace header bytes of numbers constant along the first ``run`` traces and counting along them, or None.

    Those are a volume's line numbers where its first line is ``run``
    traces long: the one (inline) changes at the next trace, the other
    (crossline) starts again there. Coordinates are left out: along an
    axis-aligned line, y stays the same too.
    """
    if run < 2 or run >= f.tracecount:
        return None
    coordinates = {byte for x_byte, y_byte, _ in _SEGY_COORDINATES.values() for byte in (x_byte, y_byte)}
    constant, counting = [], []
    for byte in sorted({int(field) for field in segyio.TraceField.enums()} - coordinates):
        values = f.attributes(byte)[: run + 1]
        line, next_start = values[:run], values[run]
        if np.all(line == line[0]) and next_start != line[0]:
            constant.append(byte)
        steps = np.diff(line)
        if (np.all(steps > 0) or np.all(steps < 0)) and next_start == line[0]:
            counting.append(byte)
    if not constant or not counting:
        return None
    return constant[0], counting[0]


def _even_step(points, unit):
    """The step between evenly spaced positions ``points`` (shape ``(n, 2)``, metres), or None where there is none.

    The step is from the first position to the last over ``n - 1``, and
    every position must lie within one stored unit (``unit``, metres: the
    coordinate scalar's, 0.01 for -100) of where it puts it, plus float
    rounding: positions rounded to that unit (6.25 m steps stored in whole
    metres, a rotated grid in centimetres) are regular, within a unit.
    """
    count = len(points)
    step = (points[-1] - points[0]) / (count - 1)
    if not np.any(step):
        return None
    tolerance = unit + 1e-9 * float(np.max(np.abs(points)))
    if np.max(np.abs(points - points[0] - np.arange(count)[:, None] * step)) > tolerance:
        return None
    return step


def _roundest(points, step, unit):
    """The length of ``step`` between ``points`` stored to ``unit``, as the roundest length they fit; None if unclear.

    Rounded to whole metres, 6.25 m steps from 6.25 m read 6, 12, 19, 25...,
    and the step first to last over 20 traces is 6.263 m. Every length
    whose positions round to the stored ones (each along the line within
    half a unit per coordinate) is as true as that one. Lengths are tried
    by their decimals, fewest first: the one that fits alone is taken, or
    among several that fit (6.249, 6.250, 6.251 over 200 traces) the one
    multiple of 5 in its last decimal. Lengths that fit span
    ``2 unit / (n - 1)``; over more than :data:`STEP_SPREAD` of the length
    no length is told, and the reader asks for the spacing: over 8 traces
    3.125 m steps stored in metres fit 3 m best, and 15 traces at 6.25 m
    were read as 6.2857 m. Coordinates exactly on their line (within float
    rounding) fit only their own step, whatever their number.
    """
    length = float(np.hypot(*step))
    direction = step / length
    along = (points - points[0]) @ direction
    counts = np.arange(len(points))
    rounding = 1e-9 * float(np.max(np.abs(points)))
    if np.ptp(along - counts * length) <= rounding:
        fits = rounding  # on their line exactly (10 m stored in decimetres): that length alone
    else:
        fits = unit * float(np.sum(np.abs(direction))) + rounding
    reach = 2.0 * fits / (len(points) - 1)  # no length farther than this from the first-to-last one fits
    if reach > STEP_SPREAD * length:
        return None
    for decimals in range(-6, 16):
        scale = 10.0**decimals
        low, high = math.floor((length - reach) * scale), math.ceil((length + reach) * scale)
        if high - low > _MOST_LENGTHS:
            return None
        fitting = [k for k in range(max(low, 1), high + 1) if np.ptp(along - counts * (k / scale)) < fits]
        if len(fitting) > 1:
            fitting = [k for k in fitting if k % 5 == 0]
            return fitting[0] / scale if len(fitting) == 1 else None
        if fitting:
            return fitting[0] / scale
    return length


_MOST_LENGTHS = 1000  # lengths tried at one number of decimals: more, and the positions tell no length

STEP_SPREAD = 2e-3
"""Share of a trace step that the lengths its rounded coordinates fit may span for one of them to be taken.

The length taken is then within this share of the true one (2 m over 1,000
traces of a 12.5 m line); a wider spread asks for ``spacing``.
"""


def _segy_format_advice(path, header, factor):
    """What to try for a SEG-Y file whose samples decode faster than any Earth material: its format code may lie.

    IEEE floats labelled IBM (code 1), the common mislabel, decode 1500 m/s as
    about 576,000 m/s; the samples are decoded again as IEEE floats to say
    whether that is the mistake.
    """
    code = header["_format_code"]
    said = f"the sample format code (binary header bytes 3225-3226) is {code} ({header['sample_format']})"
    if code != 1:
        return f"{said}; the code may be mislabelled (1 is IBM float, 5 IEEE float), or the units wrong"
    try:
        samples = _segy_words(path, header).view(">f4")
    except (OSError, ValueError):  # the file changed since segyio read it: the plain advice
        samples = np.array([np.nan])
    with np.errstate(invalid="ignore"):
        plausible = np.all(np.isfinite(samples)) and samples.min() > 0 and samples.max() * factor <= MAX_VELOCITY
    if plausible:
        low, high = float(samples.min()) * factor, float(samples.max()) * factor
        # likely, not certain: IBM floats in a too small unit (cm/s) can decode as plausible IEEE floats too
        return (
            f"{said}, but read as IEEE floats (code 5) the samples range {low:g}..{high:g} m/s: likely IEEE floats "
            "mislabelled IBM, a common mistake; if so, pass sample_format='ieee' (or set bytes 3225-3226 of a copy of "
            "the file to 5: with segyio, open it 'r+', f.bin[segyio.BinField.Format] = 5), else check the units"
        )
    return f"{said}; the format may be mislabelled (IBM, code 1, against IEEE, code 5), or the units wrong"


def _low_end(start, step, count):
    """The smallest of ``count`` coordinates from ``start`` by ``step``: the first node once the axis increases."""
    return float(start + min(0.0, step * (count - 1)))


def _depth_step_problem(header, path, *, reading=True):
    """Why the header's depth step (the sample interval read as mm) is implausible next to the trace spacing, or None.

    See :data:`DEPTH_STEP_RATIO`; a file without trace spacing is not
    judged. ``reading``: the message is for
    :func:`~terramesh.seismic.read_velocity`'s error, else for
    :func:`read_segy_header`'s warning.
    """
    *across, dz = header["spacing"]
    steps = [(name, step) for name, step in zip(("dx", "dy"), across, strict=False) if step is not None]
    if dz is None or not steps:
        return None
    ratios = [(name, step, dz / step) for name, step in steps]
    name, step, ratio = max(ratios, key=lambda item: abs(np.log(item[2])))
    if 1.0 / DEPTH_STEP_RATIO <= ratio <= DEPTH_STEP_RATIO:
        return None
    interval, field = header["_interval"], header["_interval_field"]
    axes = "(dx, dz)" if len(across) == 1 else "(dx, dy, dz)"
    return (
        f"{path}: the sample interval ({field}) is {interval}; read as millimetres (BP2004 stores 6250 for 6.25 m) "
        f"it makes dz = {dz:g} m against {name} = {step:g} m between traces (dz/{name} = {ratio:.3g}, outside "
        f"1/{DEPTH_STEP_RATIO:g}..{DEPTH_STEP_RATIO:g}: the field is likely misread); SEG-Y rev 2 defines the field "
        f"in metres or feet for depth data (binary header bytes 3255-3256 say which), which makes dz = {interval:g} m "
        f"(or ft). {'State' if reading else 'read_velocity refuses it: state'} the grid steps with spacing={axes} in "
        "metres (--spacing on the command line)"
    )


def _segy_header_3d(f, segyio, n_samples, dz):
    if len(f.offsets) > 1:
        raise MeshFormatError(f"{len(f.offsets)} offsets per inline/crossline: prestack gathers, not a velocity model")
    n_il, n_xl = len(f.ilines), len(f.xlines)
    inline_sorted = f.sorting == segyio.TraceSortingFormat.INLINE_SORTING

    def trace(i, j):  # the trace of the i-th inline and j-th crossline
        return i * n_xl + j if inline_sorted else j * n_il + i

    layout = {"x_axis": "xline", "rotation": None, "_flip": (False, False), "_steps": (None, None), "_first": None}
    unit = _scalar_of(int(f.header[0][segyio.TraceField.SourceGroupScalar]))
    first_inline = slice(0, trace(0, n_xl - 1) + 1, trace(0, 1))  # its traces, crossline by crossline
    first_crossline = slice(0, trace(n_il - 1, 0) + 1, trace(1, 0))
    for name in ("CDP", "source", "receiver group"):
        x_byte, y_byte, _ = _SEGY_COORDINATES[name]
        row, column = (
            unit * np.column_stack((f.attributes(x_byte)[traces], f.attributes(y_byte)[traces])).astype(np.float64)
            for traces in (first_inline, first_crossline)
        )
        along_xl, along_il = _even_step(row, unit), _even_step(column, unit)  # one crossline on, one inline on
        if along_xl is None or along_il is None:
            continue
        length_xl, length_il = _roundest(row, along_xl, unit), _roundest(column, along_il, unit)
        if length_xl is None or length_il is None:
            continue
        origin = row[0]
        # aligned where the end of each line is off the axis by no more than the coordinates' rounding
        tolerance = unit + 1e-9 * max(float(np.max(np.abs(row))), float(np.max(np.abs(column))))
        off_xl, off_il = np.abs(along_xl) * (n_xl - 1), np.abs(along_il) * (n_il - 1)
        if off_xl[1] <= tolerance and off_il[0] <= tolerance:  # crosslines step along x
            steps = (np.copysign(length_xl, along_xl[0]), np.copysign(length_il, along_il[1]))
            layout.update(x_axis="xline", rotation=0.0, _steps=steps)
        elif off_xl[0] <= tolerance and off_il[1] <= tolerance:  # inlines step along x
            steps = (np.copysign(length_il, along_il[0]), np.copysign(length_xl, along_xl[1]))
            layout.update(x_axis="iline", rotation=0.0, _steps=steps)
        else:  # a rotated grid is kept in its own frame: x along the inlines, y across them
            rotation = float(np.degrees(np.arctan2(along_xl[1], along_xl[0])))
            steps = (length_xl, length_il)
            layout.update(x_axis="xline", rotation=rotation, _steps=steps)
        layout["_first"] = origin
        break
    nx, ny = (n_xl, n_il) if layout["x_axis"] == "xline" else (n_il, n_xl)
    dx = dy = first_x = first_y = None
    if layout["_first"] is not None:
        (sx, sy), (x0, y0) = layout["_steps"], layout["_first"]
        layout["_flip"] = (sx < 0, sy < 0)
        dx, dy = float(abs(sx)), float(abs(sy))
        if layout["rotation"] == 0.0:  # the first node is the smallest x and y once decreasing axes are turned
            first_x, first_y = _low_end(x0, sx, nx), _low_end(y0, sy, ny)
        else:
            first_x, first_y = float(x0), float(y0)
    return {
        "shape": (nx, ny, n_samples),
        "spacing": (dx, dy, dz),
        "first_x": None if first_x is None else float(first_x),
        "first_y": None if first_y is None else float(first_y),
        "sample_format": str(f.format),
        "x_axis": layout["x_axis"],
        "rotation": layout["rotation"],
        "_flip": layout["_flip"],
        "_inline_sorted": inline_sorted,
    }


SAMPLE_FORMATS = {"ibm": 1, "ieee": 5}
"""The values of :func:`~terramesh.seismic.read_velocity`'s ``sample_format``, with the SEG-Y format code of each."""


def read_segy(path, spacing, origin, units, sample_format=None, line_bytes=None):
    """The model in the SEG-Y file ``path``: :func:`~terramesh.seismic.read_velocity` for ``*.segy``, ``*.sgy``.

    The options are :func:`~terramesh.seismic.read_velocity`'s, ``spacing``
    a tuple checked by :func:`~terramesh.seismic.model.checked_spacing` or None.
    """
    import segyio

    if sample_format is not None and sample_format not in SAMPLE_FORMATS:
        raise SizingError(f"sample_format must be one of {sorted(SAMPLE_FORMATS)}, got {sample_format!r}")
    line_bytes = _line_bytes(line_bytes)
    try:
        with _open_segy(path, segyio, line_bytes) as f:
            header = _segy_header(f, segyio, path, line_bytes)
            if f.unstructured:
                raw = f.trace.raw[:]
            else:
                raw = segyio.tools.cube(f)  # [inline, crossline, sample] or, crossline sorted, [crossline, inline, ...]
    except MeshFormatError as error:
        raise MeshFormatError(f"{path}: {error}") from None
    except Exception as error:  # segyio raises RuntimeError, OSError, ValueError... on malformed files
        problem = _unopened_problem(path)
        raise MeshFormatError(f"{path}: cannot read as SEG-Y: {problem or error}") from error
    if sample_format is not None and SAMPLE_FORMATS[sample_format] != header["_format_code"]:
        raw = _decode_segy_samples(path, header, sample_format).reshape(raw.shape)
    dim = len(header["shape"])
    if min(raw.shape) < 2:
        what = "a 2-D velocity section needs at least 2 traces" if dim == 2 else "a 3-D velocity volume needs traces"
        raise MeshFormatError(f"{path}: {what} of at least 2 samples, got shape {raw.shape}")
    # the values are checked in the file's order (views of it), so that the index a message names is the file's
    as_read = raw
    if dim == 2:
        axes = ("trace", "sample")
    else:
        axes = ("inline", "crossline", "sample") if header["_inline_sorted"] else ("crossline", "inline", "sample")
        lines_first = raw if header["_inline_sorted"] else raw.transpose(1, 0, 2)
        raw = lines_first.transpose(1, 0, 2) if header["x_axis"] == "xline" else lines_first
        if header["rotation"] not in (None, 0.0):
            warn_user(
                f"{path}: the inline/crossline grid is rotated {header['rotation']:.1f} degrees from the x axis of its "
                "coordinates; the model is in the grid's own frame: x along the inlines, y across them",
            )
    flip = [axis for axis, turned in enumerate(header["_flip"]) if turned]  # decreasing x (y): turned to increase
    raw = np.flip(raw, axis=flip) if flip else raw
    spacing = checked_spacing(spacing, dim)
    found = header["spacing"]
    found = None if None in found else found
    problem = _depth_step_problem(header, path)
    if problem is not None:
        if spacing is None:
            raise SizingError(problem)
        found = None  # the dz given replaces the misread one, without a warning that they differ
    spacing = reconcile_spacing(spacing, found, path, dim)
    check_values(as_read, path, axes)

    def advice(factor):  # what to try for samples too fast: the format code may lie, unless the user overrode it
        if sample_format is None:
            return _segy_format_advice(path, header, factor)
        return (
            f"the samples were read as {sample_format.upper()} floats, as sample_format={sample_format!r} says (the "
            f"file's sample format code is {header['_format_code']}): check sample_format and the units"
        )

    factor = units_factor(as_read, units or "m/s", path, axes=axes, error=MeshFormatError, advice=advice)
    if sample_format is None and header["_format_code"] == 5:
        _refuse_ibm_labelled_ieee(as_read, path, factor)
    values = raw[..., ::-1].astype(np.float64) * factor  # samples go down: z increasing upward
    return build_model(values, spacing, origin, None, path)


def _segy_words(path, header):
    """A SEG-Y file's samples as big-endian 32-bit words, shape ``(traces, samples)``, read past segyio's decoding."""
    n_samples = header["shape"][-1]
    words = np.fromfile(path, dtype=">u4", offset=header["_data_offset"], count=header["_traces"] * (60 + n_samples))
    return words.reshape(header["_traces"], 60 + n_samples)[:, 60:]


def _decode_segy_samples(path, header, sample_format):
    """A SEG-Y file's samples decoded as ``sample_format`` floats against its format code, shape ``(traces, samples)``.

    Only 4-byte floats are told apart: IBM (code 1) against IEEE (code 5).
    """
    code = header["_format_code"]
    if code not in SAMPLE_FORMATS.values():
        raise SizingError(
            f"{path}: sample_format={sample_format!r} tells IBM from IEEE floats, but the sample format code (binary "
            f"header bytes 3225-3226) is {code} ({header['sample_format']}), neither 1 (IBM float) nor 5 (IEEE "
            "float): leave sample_format out"
        )
    words = _segy_words(path, header)
    if sample_format == "ibm":
        return _ibm_to_float(words)
    return words.view(">f4").astype(np.float32)


def _ibm_to_float(words):
    """IBM System/360 single-precision floats from their 32-bit words: ``(-1)**s * 0.f * 16**(e - 64)``."""
    words = np.asarray(words, dtype=np.uint32)
    fraction = (words & 0x00FFFFFF).astype(np.float64)
    exponent = ((words >> 24) & 0x7F).astype(np.int64)
    sign = np.where(words >> 31, -1.0, 1.0)
    return sign * np.ldexp(fraction, 4 * (exponent - 64) - 24)


def _refuse_ibm_labelled_ieee(samples, path, factor):
    """Refuse IEEE samples (format code 5) that read slower than water but decode as plausible IBM floats.

    IBM floats labelled IEEE read as about 1/7 of their value (1500 m/s as
    221 m/s), within the accepted range, and were meshed so with a warning:
    a mesh of elements 7 times too small. Plausible as IBM (all of them
    100..MAX_VELOCITY m/s) implies below 1024 m/s as IEEE (in m/s), which
    only unconsolidated near-surface (S-wave) models reach; those are read
    with ``sample_format='ieee'``, as the message says. ``samples`` have
    passed :func:`~terramesh.seismic.model.check_values` (positive: sign bit 0), so as words they
    order as normalised IBM floats do, and the extremes are decoded alone,
    without a float64 copy of a large volume.
    """
    if samples.dtype != np.float32 or samples.size == 0:
        return
    low, high = float(samples.min()) * factor, float(samples.max()) * factor
    if high >= 1024.0:  # every model faster than that (nearly all) stops here, before a pass over its words
        return
    words = samples.view(np.uint32)
    if np.any((words & 0x00F00000) == 0):  # a zero leading hex digit: not the normalised floats IBM writers make
        return
    ibm_low, ibm_high = (float(_ibm_to_float(word)) * factor for word in (words.min(), words.max()))
    if not (100.0 <= ibm_low and ibm_high <= MAX_VELOCITY and high < ibm_low):
        return
    raise MeshFormatError(
        f"{path}: the sample format code (binary header bytes 3225-3226) is 5 (IEEE float), and read so the "
        f"velocities range {low:.4g}..{high:.4g} m/s, slower than water (about 1500 m/s); read as IBM floats (code 1) "
        f"they range {ibm_low:.4g}..{ibm_high:.4g} m/s: likely IBM floats mislabelled IEEE. If so, pass "
        "sample_format='ibm' (or set bytes 3225-3226 of a copy of the file to 1: with segyio, open it 'r+', "
        "f.bin[segyio.BinField.Format] = 1); if the model really is this slow, pass sample_format='ieee'"
    )
