"""terramesh.seismic.segy: the SEG-Y reader and read_segy_header (headers, layouts, sample formats, 2-D and 3-D)."""

import struct
import warnings

import numpy as np
import pytest
import segyio

from terramesh.errors import MeshFormatError, SizingError, TerrameshWarning
from terramesh.seismic import read_segy_header, read_velocity

from .test_velocity import SECTION_ZX, check_section, write_segy


def test_segy_of_ieee_floats_labelled_ibm_is_refused_naming_the_format(tmp_path):
    # format code 1 (IBM) on IEEE floats, a common mislabel: 1500..3030 m/s read silently as 42,000..570,000 m/s
    path = tmp_path / "labelled_ibm.segy"
    write_segy(path, SECTION_ZX)
    set_binary_field(path, 3225, 1)
    with pytest.raises(
        MeshFormatError,
        match=r"largest velocity is \d+ m/s, faster .* sample format code \(binary header bytes 3225-3226\) is 1 "
        r"\(4-byte IBM float\), but read as IEEE floats \(code 5\) the samples range 1500\.\.3030 m/s",
    ):
        read_velocity(path)
    # IEEE floats too fast whatever their label: the format code is named, and mislabelling as a possibility
    write_segy(path, SECTION_ZX * 10)
    with pytest.raises(MeshFormatError, match=r"30300 m/s.*sample format code .* is 5 \(4-byte IEEE float\).*IBM"):
        read_velocity(path)


def test_segy_of_ibm_floats_labelled_ieee_is_refused_naming_both_readings(tmp_path):
    # format code 5 (IEEE) on IBM floats: 1500..3030 m/s read as 222..379 m/s, within the accepted range; it only
    # warned, and the model was meshed with elements 7 times too small
    path = tmp_path / "labelled_ieee.segy"
    write_segy(path, SECTION_ZX, sample_format=1)
    set_binary_field(path, 3225, 5)
    with pytest.raises(
        MeshFormatError,
        match=r"format code \(binary header bytes 3225-3226\) is 5 \(IEEE float\), and read so the velocities range "
        r"221\.8\.\.378\.8 m/s, slower than water .* read as IBM floats \(code 1\) they range 1500\.\.3030 m/s: "
        r"likely IBM floats mislabelled IEEE\. If so, pass sample_format='ibm' .*set bytes 3225-3226 of a copy of the "
        r"file to 1.*really is this slow, pass sample_format='ieee'",
    ):
        read_velocity(path)
    check_section(read_velocity(path, sample_format="ibm"))  # read as the message says
    slow = read_velocity(path, sample_format="ieee")  # the label confirmed: read as it is
    assert slow.vmin == pytest.approx(221.75) and slow.vmax < 400
    set_binary_field(path, 3225, 1)  # relabelled as the message says: the true model, without a word
    check_section(read_velocity(path))
    write_segy(path, SECTION_ZX)  # true IEEE floats read as IBM are too fast: not refused as this
    check_section(read_velocity(path))


def test_segy_sample_format_reads_ieee_floats_labelled_ibm_and_is_refused_for_other_codes(tmp_path):
    path = tmp_path / "labelled_ibm.segy"
    write_segy(path, SECTION_ZX)
    set_binary_field(path, 3225, 1)
    with pytest.raises(MeshFormatError, match=r"likely IEEE floats mislabelled IBM.*pass sample_format='ieee'"):
        read_velocity(path)
    check_section(read_velocity(path, sample_format="ieee"))
    with pytest.raises(MeshFormatError, match=r"read as IBM floats, as sample_format='ibm' says.*code is 1"):
        read_velocity(path, sample_format="ibm")  # the label, confirmed wrongly: the advice does not send it back
    with pytest.raises(SizingError, match=r"sample_format must be one of \['ibm', 'ieee'\], got 'IEEE float'"):
        read_velocity(path, sample_format="IEEE float")
    integers = tmp_path / "integers.segy"
    write_segy(integers, SECTION_ZX)
    set_binary_field(integers, 3225, 2)  # 4-byte integers: sample_format tells only floats apart
    with pytest.raises(SizingError, match=r"code .* is 2 \(4-byte signed integer\), neither 1 .* nor 5"):
        read_velocity(integers, sample_format="ibm")
    with pytest.raises(SizingError, match="sample_format is not used for a binary file"):
        read_velocity(path, file_format="binary", sample_format="ibm")


def test_segy_spacing_from_headers(tmp_path):
    path = tmp_path / "section.segy"
    write_segy(path, SECTION_ZX)
    header = read_segy_header(path)
    assert header["shape"] == (4, 3)
    assert header["spacing"] == (10.0, 5.0)
    assert header["first_x"] == 10.0
    check_section(read_velocity(path))
    check_section(read_velocity(path, spacing=(10.0, 5.0)))  # agreeing: no warning


def test_segy_given_spacing_wins_with_a_warning(tmp_path):
    path = tmp_path / "section.sgy"
    write_segy(path, SECTION_ZX)
    with pytest.warns(TerrameshWarning, match="differs from the file's"):
        model = read_velocity(path, spacing=(20.0, 5.0))
    check_section(model, dx=20.0)


def test_segy_without_coordinates_needs_spacing(tmp_path):
    path = tmp_path / "section.segy"
    write_segy(path, SECTION_ZX, dx_decimetres=0)
    assert read_segy_header(path)["spacing"] == (None, 5.0)
    with pytest.raises(SizingError, match="spacing"):
        read_velocity(path)
    check_section(read_velocity(path, spacing=(10.0, 5.0)))


def test_segy_in_km_per_s_and_malformed(tmp_path):
    path = tmp_path / "section.segy"
    write_segy(path, SECTION_ZX / 1000)
    check_section(read_velocity(path, units="km/s"))
    broken = tmp_path / "broken.segy"
    broken.write_bytes(b"not a seg-y file" * 10)
    with pytest.raises(MeshFormatError, match="SEG-Y"):
        read_velocity(broken)
    with pytest.raises(MeshFormatError, match="SEG-Y"):
        read_segy_header(broken)
    with pytest.raises(FileNotFoundError):
        read_velocity(tmp_path / "missing.segy")


def test_segy_section_whose_traces_run_against_x_is_turned_around(tmp_path):
    # traces at x = -10, -20, -30, -40 m: the headers' 10 m step was reported as missing ("does not state its grid
    # spacing"), and with spacing= given the model came out mirrored against the trace coordinates
    path = tmp_path / "right_to_left.segy"
    write_segy(path, SECTION_ZX[:, ::-1], dx_decimetres=-100)  # the trace at x = -40 m holds SECTION_ZX's first column
    header = read_segy_header(path)
    assert header["spacing"] == (10.0, 5.0)
    assert header["first_x"] == -40.0  # the smallest x: the first node once x increases
    check_section(read_velocity(path))
    check_section(read_velocity(path, origin=(header["first_x"], 0.0)), origin=(-40.0, 0.0))
    check_section(read_velocity(path, spacing=(10.0, 5.0)))  # agreeing: no warning, and not mirrored


def set_binary_field(path, byte, value):
    """Overwrite the 2-byte big-endian binary header field at SEG-Y byte ``byte`` (1-based), as in a damaged file."""
    data = bytearray(path.read_bytes())
    data[byte - 1 : byte + 1] = struct.pack(">h", value)
    path.write_bytes(bytes(data))


def set_trace_sample_counts(path):
    """Fill every trace header's sample count (bytes 115-116), as most writers do and segyio.create does not."""
    with segyio.open(str(path), "r+", ignore_geometry=True) as f:
        for i in range(f.tracecount):
            f.header[i] = {segyio.TraceField.TRACE_SAMPLE_COUNT: len(f.samples)}


def test_segy_cut_at_a_trace_boundary_is_read_with_a_warning(tmp_path):
    # a file cut after whole traces opened as a smaller model, silently: the binary header still declared all the
    # traces. Refused, it also refused a valid file cut from a larger one with its headers copied (segyio's idiom)
    path = tmp_path / "cut.segy"
    write_segy(path, SECTION_ZX)
    trace = 240 + 3 * 4
    whole = path.read_bytes()
    path.write_bytes(whole[: 3600 + 2 * trace])
    message = r"the binary header \(bytes 3213-3214\) declares 4 traces, the file holds 2: read as a model of 2"
    with pytest.warns(TerrameshWarning, match=message):
        assert read_velocity(path, spacing=(10.0, 5.0)).shape == (2, 3)
    with pytest.warns(TerrameshWarning, match=message):
        read_segy_header(path)
    path.write_bytes(whole[: 3600 + 2 * trace + 100])  # cut within a trace: segyio's message named no field
    with pytest.raises(MeshFormatError, match=r"truncated mid-trace: .* 2 whole traces of 252 bytes .* and 100 bytes"):
        read_velocity(path)
    path.write_bytes(whole[:3600])
    with pytest.raises(MeshFormatError, match=r"no traces follow the headers \(the binary header declares 4 traces"):
        read_velocity(path)
    # fewer traces declared than held: the count of one ensemble (a CDP, a shot), not an error
    path.write_bytes(whole)
    set_binary_field(path, 3213, 1)
    check_section(read_velocity(path))


def test_bp2004_cut_at_a_trace_boundary_warns(tmp_path, bp2004_path):
    # the reviewer's case: BP2004 after 100 whole traces was meshed as a 100-trace model without a word
    path = tmp_path / "bp_cut.segy"
    with open(bp2004_path, "rb") as whole:
        path.write_bytes(whole.read(3600 + (240 + 1911 * 4) * 100))
    with pytest.warns(TerrameshWarning, match="declares 5395 traces, the file holds 100: read as a model of 100"):
        assert read_velocity(path).shape[0] == 100


def test_segy_trace_headers_that_disagree_with_a_binary_header_the_file_fits_warn(tmp_path):
    # every trace header said one sample fewer than the binary header, which the file's size fits: refused before
    path = tmp_path / "counts.segy"
    write_segy(path, SECTION_ZX)  # 3 samples
    set_trace_sample_counts(path)
    with segyio.open(str(path), "r+", ignore_geometry=True) as f:
        for i in range(f.tracecount):
            f.header[i] = {segyio.TraceField.TRACE_SAMPLE_COUNT: 2}
    with pytest.warns(TerrameshWarning, match=r"is 3 but the first trace header's \(bytes 115-116\) is 2; the file"):
        check_section(read_velocity(path))


def test_segy_sample_counts_that_disagree_are_named(tmp_path):
    # the binary header's sample count doubled against the trace headers' was reported as a missing spacing, then
    # refused, "one of them is wrong", although the file's size fits the trace headers' count alone
    path = tmp_path / "counts.segy"
    section = np.vstack([SECTION_ZX, SECTION_ZX + 500])  # 6 samples
    write_segy(path, section)
    set_trace_sample_counts(path)
    for wrong in (12, 0):
        set_binary_field(path, 3221, wrong)
        message = (
            rf"sample count \(bytes 3221-3222\) is {wrong} but the first trace header's \(bytes 115-116\) is 6, and "
            r"the file's size fits only the trace header's: read with 6 samples per trace"
        )
        with pytest.warns(TerrameshWarning, match=message):
            model = read_velocity(path)
        np.testing.assert_array_equal(model.values[:, ::-1].T, section)
    set_binary_field(path, 3221, 72)  # 2 traces of 72 samples fill the file as 4 of 6 do: no telling which
    with pytest.raises(MeshFormatError, match=r"is 72 but the first .* is 6: one of them is wrong"):
        read_velocity(path)
    set_binary_field(path, 3221, 6)
    with segyio.open(str(path), "r+", ignore_geometry=True) as f:
        f.header[f.tracecount - 1] = {segyio.TraceField.TRACE_SAMPLE_COUNT: 7}
    with pytest.raises(MeshFormatError, match=r"the last trace header says 7 samples, the first 6"):
        read_velocity(path)


def test_segy_first_trace_header_count_alone_wrong_is_read_with_the_binary_headers(tmp_path):
    # the reviewer's case: a warning said the binary header's count was used, then the read was refused blaming the
    # sample format code ("the last trace header says 120 samples, the first 130"), which was right
    path = tmp_path / "first.segy"
    write_segy(path, SECTION_ZX)  # 3 samples
    set_trace_sample_counts(path)
    with segyio.open(str(path), "r+", ignore_geometry=True) as f:
        f.header[0] = {segyio.TraceField.TRACE_SAMPLE_COUNT: 5}
    message = (
        r"sample count \(bytes 3221-3222\) is 3 but the first trace header's \(bytes 115-116\) is 5; the file's size "
        r"fits the binary header's, as does the last trace header's, which is used"
    )
    with pytest.warns(TerrameshWarning, match=message):
        check_section(read_velocity(path))
    with segyio.open(str(path), "r+", ignore_geometry=True) as f:  # three counts, none agreeing: named, not the code
        f.header[f.tracecount - 1] = {segyio.TraceField.TRACE_SAMPLE_COUNT: 7}
    message = r"is 3 but the first trace header's .* is 5, and the last trace header's, .* 7: .* correct the wrong"
    with pytest.raises(MeshFormatError, match=message):
        read_velocity(path)


@pytest.mark.parametrize("revision", [0, 1])
def test_segy_junk_extended_header_count_is_ignored_with_a_warning(tmp_path, revision):
    # the reviewer's case: bytes 3505-3506 of a complete rev 0 file said 3 extended textual headers, and the file
    # was refused as "truncated mid-trace: ... 146 whole traces"
    path = tmp_path / "junk.segy"
    write_segy(path, SECTION_ZX)
    set_binary_field(path, 3505, 3)
    set_binary_field(path, 3501, revision << 8)  # byte 3501 is the major revision
    why = r"a rev 0 file \(byte 3501 is 0\) has none" if revision == 0 else "only without them is the file whole"
    message = rf"bytes 3505-3506 say 3 extended textual headers, but {why}.*: read without them"
    with pytest.warns(TerrameshWarning, match=message):
        check_section(read_velocity(path))
    with pytest.warns(TerrameshWarning, match=message):
        assert read_segy_header(path)["shape"] == (4, 3)


def test_segy_genuine_extended_headers_are_read_past(tmp_path):
    path = tmp_path / "extended.segy"
    spec = segyio.spec()
    spec.format, spec.samples, spec.tracecount, spec.ext_headers = 5, range(3), 4, 1
    with segyio.create(str(path), spec) as f:
        f.bin[segyio.BinField.Interval] = 5000
        for i in range(4):
            f.header[i] = {segyio.TraceField.SourceX: 100 * (i + 1), segyio.TraceField.SourceGroupScalar: -10}
            f.trace[i] = SECTION_ZX[:, i].astype(np.float32)
    check_section(read_velocity(path))  # no warning: the count fits the file


def test_segy_trailing_bytes_after_the_declared_traces_are_read_past_with_a_warning(tmp_path):
    # a complete file with 100 bytes appended was refused as "truncated mid-trace" though every trace was whole
    path = tmp_path / "trailing.segy"
    write_segy(path, SECTION_ZX)
    path.write_bytes(path.read_bytes() + b"\0" * 100)
    message = r"100 trailing bytes after the 4 whole traces the binary header declares \(bytes 3213-3214\): read"
    with pytest.warns(TerrameshWarning, match=message):
        check_section(read_velocity(path))
    volume = tmp_path / "volume.segy"
    write_segy_3d(volume, VOLUME)
    volume.write_bytes(volume.read_bytes() + b"\0" * 100)
    with pytest.warns(TerrameshWarning, match="100 trailing bytes after the 12 whole traces"):
        check_volume(read_velocity(volume))
    # a count of one ensemble does not tell a cut file from trailing bytes: refused, naming both and the copy
    set_binary_field(path, 3213, 1)
    message = r"are 4 whole traces of 252 bytes .* and 100 bytes more; .* cut short within a trace, or 100 bytes after"
    with pytest.raises(MeshFormatError, match=message + r" the last; .* \(head -c 4608 FILE > COPY\)"):
        read_velocity(path)


@pytest.mark.parametrize(
    ("code", "message"),
    [
        (99, r"sample format code 99 \(binary header bytes 3225-3226\) is none SEG-Y defines"),
        (4, r"sample format code 4 .*fixed point with gain\) is not read"),
        (1280, r"sample format code 1280 .* is 5 read the other way round: the file is little-endian"),
    ],
)
def test_segy_format_codes_not_read_are_named(tmp_path, code, message):
    # code 99 was read as IBM floats (a segyio warning) and refused as "negative velocities"
    path = tmp_path / "code.segy"
    write_segy(path, SECTION_ZX)
    set_binary_field(path, 3225, code)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no segyio warning on the way
        with pytest.raises(MeshFormatError, match=message):
            read_velocity(path)
        with pytest.raises(MeshFormatError, match=message):
            read_segy_header(path)


@pytest.mark.parametrize(("nz", "nx"), [(3, 4), (30, 40)])
@pytest.mark.parametrize("code", [3, 8])
def test_segy_format_code_of_another_sample_size_is_named(tmp_path, nz, nx, code):
    # IEEE floats labelled 2-byte integers (code 3) were reported as a missing spacing, or failed to open with
    # segyio's "trace count inconsistent with file size"; a 30 x 40 file opens, as 48 traces of 2-byte samples
    path = tmp_path / "code.segy"
    write_segy(path, 1500.0 + np.arange(nz * nx, dtype=np.float64).reshape(nz, nx))
    set_trace_sample_counts(path)
    set_binary_field(path, 3225, code)
    message = rf"holds exactly the {nx} traces the binary header declares .* format code is likely wrong \(4-byte"
    with pytest.raises(MeshFormatError, match=message):
        read_velocity(path)
    with pytest.raises(MeshFormatError, match=message):
        read_segy_header(path)


def test_segy_genuine_integer_samples_still_read(tmp_path):
    path = tmp_path / "int16.segy"
    nz, nx = SECTION_ZX.shape
    spec = segyio.spec()
    spec.format, spec.samples, spec.tracecount = 3, range(nz), nx
    with segyio.create(str(path), spec) as f:
        f.bin[segyio.BinField.Interval] = 5000
        for i in range(nx):
            f.header[i] = {
                segyio.TraceField.SourceX: 100 * (i + 1),
                segyio.TraceField.SourceGroupScalar: -10,
                segyio.TraceField.TRACE_SAMPLE_COUNT: nz,
            }
            f.trace[i] = SECTION_ZX[:, i].astype(np.int16)
    check_section(read_velocity(path))


def rewrite_interval(path, binary, trace):
    """Set a SEG-Y file's sample interval in the binary header and in every trace header."""
    with segyio.open(str(path), "r+", ignore_geometry=True) as f:
        f.bin.update({segyio.BinField.Interval: binary})
        for i in range(f.tracecount):
            f.header[i] = {segyio.TraceField.TRACE_SAMPLE_INTERVAL: trace}


def test_segy_depth_step_in_metres_is_refused_naming_both_readings(tmp_path):
    # a sample interval of 10 meaning 10 m (SEG-Y rev 2 for depth data) was read as 10 mm: dz = 0.01 m next to
    # traces 10 m apart, with no word, and padding then built grids 1000 times too fine
    path = tmp_path / "depth_in_metres.segy"
    write_segy(path, SECTION_ZX, interval=10)
    readings = r"is 10; read as millimetres .* dz = 0\.01 m against dx = 10 m .* dz = 10 m \(or ft\)"
    with pytest.raises(SizingError, match=r"binary header bytes 3217-3218\) " + readings + r".* spacing=\(dx, dz\)"):
        read_velocity(path)
    with pytest.warns(TerrameshWarning, match="read_velocity refuses it"):
        assert read_segy_header(path)["spacing"] == (10.0, 0.01)
    check_section(read_velocity(path, spacing=(10.0, 10.0)), dz=10.0)  # stated: read, with no "differs" warning
    rewrite_interval(path, 0, 10)  # only in the trace headers: taken, and said to be (it was taken in silence)
    taken = r"binary header's sample interval \(bytes 3217-3218\) is 0; the first trace header's \(bytes 117-118\), 10,"
    with (
        pytest.warns(TerrameshWarning, match=taken),
        pytest.raises(SizingError, match=r"trace header bytes 117-118\) " + readings),
    ):
        read_velocity(path)


@pytest.mark.parametrize(
    ("interval", "dx_centimetres", "refused"),
    [
        (100, 1000, False),  # dz = 0.1 m, dx = 10 m: 1/100, the finest dz read
        (99, 1000, True),
        (6250, 1250, False),  # BP2004's steps
        (25000, 25, False),  # dz = 25 m, dx = 0.25 m: 100, the coarsest
        (25000, 20, True),  # dz/dx = 125: the coordinates or the interval are misread
    ],
)
def test_segy_depth_step_bounds(tmp_path, interval, dx_centimetres, refused):
    path = tmp_path / "section.segy"
    write_segy(path, SECTION_ZX, interval=interval, dx_decimetres=dx_centimetres, scalar=-100)
    if refused:
        with pytest.raises(SizingError, match=f"sample interval .* is {interval};"):
            read_velocity(path)
    else:
        assert read_velocity(path).spacing == pytest.approx((dx_centimetres / 100, interval / 1000))


def test_a_depth_step_past_the_signed_field_is_read_unsigned(tmp_path):
    # 50 m stored as 50000 mm reads as -15536 in segyio's signed field: "does not state its grid spacing"
    path = tmp_path / "section.segy"
    write_segy(path, SECTION_ZX, interval=50000, dx_decimetres=500)
    taken = r"reads as -15536 when signed; taken as 50000, unsigned \(50 m a sample"
    with pytest.warns(TerrameshWarning, match=taken):
        assert read_velocity(path).spacing == pytest.approx((50.0, 50.0))


# a 3-D volume [x, y, sample] of 4 x 3 traces of 5 samples, top first: every node's velocity is different
VOLUME = (
    1500.0
    + 100.0 * np.arange(4)[:, None, None]
    + 10.0 * np.arange(3)[None, :, None]
    + 200.0 * np.arange(5)[None, None, :]
)


def write_segy_3d(
    path,
    volume,
    *,
    sorting=segyio.TraceSortingFormat.INLINE_SORTING,
    x_along="xline",
    coordinates=(segyio.TraceField.CDP_X, segyio.TraceField.CDP_Y),
    dx=25.0,
    dy=50.0,
    origin=(1000.0, 2000.0),
    y_decreasing=False,
    direction=(1.0, 0.0),
    offsets=(1,),
    interval=5000,
):
    """A 3-D SEG-Y volume from ``volume[x, y, sample]`` (sample 0 on top), inline numbers from 10, crosslines from 20.

    ``x_along="xline"``: the crossline number grows along x (x is along each inline); ``"iline"``: the inline
    number does. ``y_decreasing`` numbers the lines against y; ``direction`` rotates the x axis of the grid in
    the coordinates' frame. Coordinates are stored in decimetres (scalar -10).
    """
    nx, ny, n_samples = volume.shape
    n_xl, n_il = (nx, ny) if x_along == "xline" else (ny, nx)
    spec = segyio.spec()
    spec.format, spec.samples, spec.sorting = 5, range(n_samples), sorting
    spec.ilines, spec.xlines, spec.offsets = list(range(10, 10 + n_il)), list(range(20, 20 + n_xl)), list(offsets)
    if sorting == segyio.TraceSortingFormat.INLINE_SORTING:
        order = [(i, j, o) for i in range(n_il) for j in range(n_xl) for o in offsets]
    else:
        order = [(i, j, o) for j in range(n_xl) for i in range(n_il) for o in offsets]
    ux, uy = direction
    with segyio.create(str(path), spec) as f:
        f.bin[segyio.BinField.Interval] = interval
        for trace, (i, j, offset) in enumerate(order):
            ix, iy = (j, i) if x_along == "xline" else (i, j)
            iy = ny - 1 - iy if y_decreasing else iy
            along, across = dx * ix, dy * iy
            x, y = origin[0] + ux * along - uy * across, origin[1] + uy * along + ux * across
            f.header[trace] = {
                segyio.TraceField.INLINE_3D: 10 + i,
                segyio.TraceField.CROSSLINE_3D: 20 + j,
                segyio.TraceField.offset: offset,
                segyio.TraceField.SourceGroupScalar: -10,
                coordinates[0]: int(round(10 * x)),
                coordinates[1]: int(round(10 * y)),
            }
            f.trace[trace] = volume[ix, iy].astype(np.float32)


def check_volume(model, dx=25.0, dy=50.0, dz=5.0):
    """The model of VOLUME: (x, y, z) frame, z negative downward, first sample on top, origin (0, 0, 0)."""
    assert model.dim == 3 and model.shape == (4, 3, 5)
    assert model.spacing == pytest.approx((dx, dy, dz))
    np.testing.assert_allclose(model.bbox, [[0.0, 0.0, -4 * dz], [3 * dx, 2 * dy, 0.0]])
    np.testing.assert_array_equal(model.values, VOLUME[:, :, ::-1])


@pytest.mark.parametrize(
    "sorting", [segyio.TraceSortingFormat.INLINE_SORTING, segyio.TraceSortingFormat.CROSSLINE_SORTING]
)
def test_segy_volume_in_either_sorting(tmp_path, sorting):
    path = tmp_path / "volume.segy"
    write_segy_3d(path, VOLUME, sorting=sorting)
    header = read_segy_header(path)
    assert header["shape"] == (4, 3, 5)
    assert header["spacing"] == (25.0, 50.0, 5.0)
    assert (header["first_x"], header["first_y"], header["x_axis"], header["rotation"]) == (
        1000.0,
        2000.0,
        "xline",
        0.0,
    )
    model = read_velocity(path)
    check_volume(model)
    assert model([(75.0, 100.0, 0.0)])[0] == 1500.0 + 300.0 + 20.0  # the top of the last trace
    moved = read_velocity(path, origin=(header["first_x"], header["first_y"], 0.0))
    np.testing.assert_allclose(moved.bbox, [[1000.0, 2000.0, -20.0], [1075.0, 2100.0, 0.0]])


def test_segy_volume_whose_inlines_run_along_x(tmp_path):
    path = tmp_path / "volume.sgy"
    write_segy_3d(path, VOLUME, x_along="iline")
    assert read_segy_header(path)["x_axis"] == "iline"
    check_volume(read_velocity(path))


def test_segy_volume_with_lines_numbered_against_y_and_source_coordinates(tmp_path):
    path = tmp_path / "volume.segy"
    sources = (segyio.TraceField.SourceX, segyio.TraceField.SourceY)
    write_segy_3d(path, VOLUME, y_decreasing=True, coordinates=sources)
    header = read_segy_header(path)
    assert header["spacing"] == (25.0, 50.0, 5.0) and header["first_y"] == 2000.0
    check_volume(read_velocity(path))  # turned around so that y increases


def test_segy_volume_on_a_rotated_grid_is_kept_in_its_own_frame(tmp_path):
    path = tmp_path / "volume.segy"
    write_segy_3d(path, VOLUME, direction=(0.6, 0.8))  # 53.13 degrees; steps of (15, 20) and (-40, 30) m
    assert read_segy_header(path)["rotation"] == pytest.approx(53.130102)
    with pytest.warns(TerrameshWarning, match="rotated 53.1 degrees"):
        model = read_velocity(path)
    check_volume(model)


def test_segy_volume_without_coordinates_needs_spacing(tmp_path):
    path = tmp_path / "volume.segy"
    write_segy_3d(path, VOLUME, dx=0.0, dy=0.0)
    assert read_segy_header(path)["spacing"] == (None, None, 5.0)
    with pytest.raises(SizingError, match=r"spacing=\(dx, dy, dz\)"):
        read_velocity(path)
    with pytest.raises(SizingError, match="3 numbers"):
        read_velocity(path, spacing=(10.0, 5.0))  # a 2-D spacing for a 3-D file
    check_volume(read_velocity(path, spacing=(10.0, 20.0, 5.0)), dx=10.0, dy=20.0)
    with pytest.warns(TerrameshWarning, match="differs from the file's"):
        write_segy_3d(path, VOLUME)
        check_volume(read_velocity(path, spacing=(10.0, 20.0, 5.0)), dx=10.0, dy=20.0)


def test_segy_volume_depth_step_in_metres_is_refused(tmp_path):
    path = tmp_path / "volume.segy"
    write_segy_3d(path, VOLUME, interval=5)  # 5 m as rev 2 has it: 5 mm next to 25 m and 50 m between traces
    with pytest.raises(SizingError, match=r"dz = 0\.005 m against dy = 50 m .* spacing=\(dx, dy, dz\)"):
        read_velocity(path)
    check_volume(read_velocity(path, spacing=(25.0, 50.0, 5.0)))


def test_a_single_line_of_a_survey_and_prestack_data(tmp_path):
    line = tmp_path / "line.segy"
    write_segy_3d(line, VOLUME[:, :1])  # one inline: a 2-D section along x
    model = read_velocity(line)
    assert model.dim == 2 and model.shape == (4, 5)
    np.testing.assert_array_equal(model.values, VOLUME[:, 0, ::-1])
    prestack = tmp_path / "gathers.segy"
    write_segy_3d(prestack, VOLUME, offsets=(100, 200))
    with pytest.raises(MeshFormatError, match="prestack"):
        read_velocity(prestack)
    with pytest.raises(MeshFormatError, match="prestack"):
        read_segy_header(prestack)


def test_bp2004_headers(bp2004_path):
    header = read_segy_header(bp2004_path)
    assert header["shape"] == (5395, 1911)
    assert header["spacing"] == (12.5, 6.25)
    assert "IBM" in header["sample_format"]


def test_bp2004_model(bp2004):
    assert bp2004.shape == (5395, 1911)
    assert bp2004.spacing == (12.5, 6.25)
    np.testing.assert_allclose(bp2004.bbox, [[0.0, -11937.5], [67425.0, 0.0]])
    assert 1400 < bp2004.vmin < 1500 and 4700 < bp2004.vmax < 4800  # water on top, salt below
    top, bottom = bp2004([(30000.0, 0.0), (30000.0, -11937.5)])
    assert top == pytest.approx(1486.0, abs=1.0)  # sea water at the surface
    assert bottom > 3000
