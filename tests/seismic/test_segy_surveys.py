"""SEG-Y files a 2-D reading would get wrong: 3-D volumes in disguise, rounded or rotated coordinates."""

import numpy as np
import pytest
import segyio

from terramesh.errors import MeshFormatError, SizingError, TerrameshWarning
from terramesh.seismic import read_segy_header, read_velocity

NX, NY, NZ = 20, 10, 30  # crosslines (along x), inlines (along y), samples
VOLUME = (
    1500.0
    + 10.0 * np.arange(NX)[:, None, None]
    + 100.0 * np.arange(NY)[None, :, None]
    + 20.0 * np.arange(NZ)[None, None, :]
).astype(np.float32)  # every trace different, sample 0 on top


def write_cube(
    path,
    volume=VOLUME,
    *,
    line_bytes=(189, 193),
    dx=25.0,
    dy=50.0,
    angle=0.0,
    scalar=-100,
    drop=(),
    shuffle=False,
):
    """A 3-D SEG-Y volume from ``volume[x, y, sample]``, inline by inline, CDP coordinates rounded to the scalar's unit.

    ``line_bytes``: where the inline (from 1) and crossline (from 100) numbers go; ``angle``: the grid's rotation
    from the x axis of the coordinates, degrees; ``drop``: indices of traces left out; ``shuffle``: the traces in
    an order sorted by neither inline nor crossline.
    """
    nx, ny, nz = volume.shape
    traces = [(j, i) for j in range(ny) for i in range(nx)]  # (inline index, crossline index)
    traces = [trace for k, trace in enumerate(traces) if k not in set(drop)]
    if shuffle:
        traces = [traces[k] for k in np.random.default_rng(1).permutation(len(traces))]
    spec = segyio.spec()
    spec.format, spec.samples, spec.tracecount = 5, range(nz), len(traces)
    unit = 1.0 / abs(scalar) if scalar < 0 else float(scalar)
    c, s = np.cos(np.radians(angle)), np.sin(np.radians(angle))
    with segyio.create(str(path), spec) as f:
        f.bin[segyio.BinField.Interval] = 10000  # 10 m, as millimetres
        for k, (j, i) in enumerate(traces):
            x, y = 1000.0 + c * i * dx - s * j * dy, 2000.0 + s * i * dx + c * j * dy
            f.header[k] = {
                line_bytes[0]: 1 + j,
                line_bytes[1]: 100 + i,
                segyio.TraceField.SourceGroupScalar: scalar,
                segyio.TraceField.CDP_X: int(round(x / unit)),
                segyio.TraceField.CDP_Y: int(round(y / unit)),
            }
            f.trace[k] = volume[i, j]


def write_line(path, section, xs, *, ys=None, scalar=1):
    """A 2-D SEG-Y line of ``section[trace, sample]`` at source coordinates ``xs`` (``ys``), metres, stored rounded."""
    spec = segyio.spec()
    spec.format, spec.samples, spec.tracecount = 5, range(section.shape[1]), section.shape[0]
    unit = 1.0 / abs(scalar) if scalar < 0 else float(scalar)
    ys = np.zeros(len(xs)) if ys is None else ys
    with segyio.create(str(path), spec) as f:
        f.bin[segyio.BinField.Interval] = 10000
        for k, (x, y) in enumerate(zip(xs, ys, strict=True)):
            f.header[k] = {
                segyio.TraceField.SourceGroupScalar: scalar,
                segyio.TraceField.SourceX: int(round(x / unit)),
                segyio.TraceField.SourceY: int(round(y / unit)),
            }
            f.trace[k] = section[k].astype(np.float32)


SECTION = VOLUME[:, 0]  # 20 traces of 30 samples


def test_a_volume_with_its_line_numbers_at_other_bytes_is_refused_naming_them(tmp_path):
    # inline/crossline numbers at bytes 9 and 21 (as some exports write them): read as a section 200 traces wide
    # ("does not state its grid spacing"), and given a spacing, meshed as a 2-D model 5 km wide
    path = tmp_path / "petrel.segy"
    write_cube(path, line_bytes=(9, 21))
    message = (
        r"CDP coordinates \(trace header bytes 181-188\) run back 9 times, every 20 traces, and the 10 runs lie over "
        r"450 m across the first one: the lines of a 3-D survey, not one 2-D line.* bytes 9 and 21 hold numbers .* "
        r"pass line_bytes=\(9, 21\)"
    )
    for read in (read_velocity, read_segy_header):
        with pytest.raises(MeshFormatError, match=message):
            read(path)
    with pytest.raises(MeshFormatError, match="not one 2-D line"):
        read_velocity(path, spacing=(25.0, 10.0))  # a spacing does not make it a section
    model = read_velocity(path, line_bytes=(9, 21))
    assert model.shape == (NX, NY, NZ) and model.spacing == (25.0, 50.0, 10.0)
    np.testing.assert_array_equal(model.values, VOLUME[:, :, ::-1])
    assert read_segy_header(path, line_bytes=(9, 21))["shape"] == (NX, NY, NZ)


def test_line_bytes_that_hold_no_grid_or_no_field_are_refused(tmp_path):
    path = tmp_path / "cube.segy"
    write_cube(path)
    with pytest.raises(MeshFormatError, match=r"bytes 9 and 21\), given by line_bytes, take 1 and 1 values"):
        read_velocity(path, line_bytes=(9, 21))
    for bad in [(189,), (189, 189), (190, 193), "189,193"]:
        with pytest.raises(SizingError, match=r"line_bytes must be .* SEG-Y puts them at \(189, 193\)"):
            read_velocity(path, line_bytes=bad)
    model = read_velocity(path, line_bytes=(189, 193))  # SEG-Y's own, named
    assert model.shape == (NX, NY, NZ)


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (
            {"drop": (5, 77, 150)},
            r"take 10 and 20 values: a 3-D volume, not a 2-D section, but an irregular one: 197 of the 10 x 20 = 200 "
            r"traces of its grid, 3 missing \(the first at inline 1, crossline 105\).*fill the missing ones",
        ),
        ({"shuffle": True}, r"a 3-D volume, not a 2-D section, but its 200 traces are sorted by neither inline"),
    ],
)
def test_an_irregular_volume_is_refused_saying_what_is_wrong(tmp_path, damage, message):
    # segyio lays out only full, sorted grids: 3 traces missing read as a 2-D section of 197 traces
    path = tmp_path / "irregular.segy"
    write_cube(path, **damage)
    with pytest.raises(MeshFormatError, match=message):
        read_velocity(path, spacing=(25.0, 10.0))


def test_a_crooked_or_folded_2d_line_is_still_a_section(tmp_path):
    # an arbitrary line through a volume: inline and crossline numbers both change, over few of their pairs
    path = tmp_path / "arbitrary.segy"
    write_line(
        path,
        SECTION,
        xs=np.r_[np.arange(10) * 25.0, np.full(10, 225.0)],
        ys=np.r_[np.zeros(10), np.arange(1, 11) * 25.0],
    )
    with segyio.open(str(path), "r+", ignore_geometry=True) as f:
        for k in range(f.tracecount):
            f.header[k] = {
                segyio.TraceField.INLINE_3D: 1 + min(k, 9),
                segyio.TraceField.CROSSLINE_3D: 100 + max(k - 9, 0),
            }
    assert read_velocity(path, spacing=(25.0, 10.0)).shape == (20, NZ)
    folded = tmp_path / "folded.segy"  # a V: out along x and back, offset in y
    write_line(folded, SECTION, xs=np.r_[np.arange(10), np.arange(9, -1, -1)] * 25.0, ys=np.arange(20) * 10.0)
    assert read_velocity(folded, spacing=(25.0, 10.0)).shape == (20, NZ)


def test_a_2d_line_stored_in_whole_metres_gets_its_spacing(tmp_path):
    # 6.25 m steps stored in whole metres (6, 12, 19, 25, ...) were refused as irregular: the allowance was
    # 1e-6 of a step, not the metre the coordinates are rounded to
    path = tmp_path / "metres.segy"
    long = np.repeat(SECTION, 10, axis=0)  # 200 traces: the lengths they fit span 0.16 % of 6.25 m
    write_line(path, long, xs=(np.arange(10 * NX) + 1) * 6.25)
    assert read_segy_header(path)["spacing"] == (6.25, 10.0)
    model = read_velocity(path)
    assert model.spacing == (6.25, 10.0)
    np.testing.assert_array_equal(model.values, long[:, ::-1])
    # over 20 traces they span 1.7 %, and 6.24 to 6.26 fit as well as 6.25 (15 of 6.25 m read 6.2857): asked for
    short = tmp_path / "short.segy"
    write_line(short, SECTION, xs=(np.arange(NX) + 1) * 6.25)
    assert read_segy_header(short)["spacing"] == (None, 10.0)
    assert read_velocity(short, spacing=(6.25, 10.0)).spacing == (6.25, 10.0)
    # a dead trace without coordinates in a line at UTM coordinates is no second line of a survey
    dead = tmp_path / "dead.segy"
    xs, ys = 5e5 + (np.arange(NX) + 1) * 12.5, np.full(NX, 4.5e6)
    xs[9] = ys[9] = 0.0
    write_line(dead, SECTION, xs=xs, ys=ys)
    assert read_velocity(dead, spacing=(12.5, 10.0)).shape == (NX, 30)
    irregular = tmp_path / "irregular.segy"  # one trace 3 m off: more than the rounding
    xs = (np.arange(NX) + 1) * 6.25
    xs[7] += 3.0
    write_line(irregular, SECTION, xs=xs)
    assert read_segy_header(irregular)["spacing"] == (None, 10.0)
    with pytest.raises(SizingError, match="does not state its grid spacing"):
        read_velocity(irregular)


def test_a_2d_line_across_the_coordinate_axes_is_spaced_along_it(tmp_path):
    # a line at 36.87 degrees with 25 m steps (20 m in x): dx was read as 20 m, the x step alone
    path = tmp_path / "diagonal.segy"
    write_line(path, SECTION, xs=np.arange(NX) * 20.0, ys=np.arange(NX) * 15.0, scalar=-100)
    assert read_segy_header(path)["spacing"] == (25.0, 10.0)
    north = tmp_path / "north.segy"  # along y at one x: no spacing was read
    write_line(north, SECTION[::-1], xs=np.full(NX, 500.0), ys=np.arange(NX)[::-1] * 12.5, scalar=-10)
    header = read_segy_header(north)
    assert header["spacing"] == (12.5, 10.0)
    np.testing.assert_array_equal(read_velocity(north).values, SECTION[:, ::-1])  # turned so that y increases


def test_a_rotated_volume_stored_in_centimetres_gets_its_spacing_and_rotation(tmp_path):
    # the steps from one trace to the next, rounded to the centimetre, put the last line off by more than the
    # 1e-6 of a step allowed: no spacing, and the rotation unread
    path = tmp_path / "rotated.segy"
    write_cube(path, angle=30.0)
    header = read_segy_header(path)
    assert header["spacing"] == (25.0, 50.0, 10.0)
    assert header["rotation"] == pytest.approx(30.0, abs=1e-3)
    assert (header["first_x"], header["first_y"]) == (1000.0, 2000.0)
    with pytest.warns(TerrameshWarning, match="rotated 30.0 degrees"):
        model = read_velocity(path)
    np.testing.assert_array_equal(model.values, VOLUME[:, :, ::-1])
    # on the axes, in whole metres, 12.5 m steps over 20 crosslines: any step within 0.84 % of 12.5 m fits the
    # rounded coordinates (beyond STEP_SPREAD): the spacing is asked for, where a wrong one could be taken
    metres = tmp_path / "metres.segy"
    write_cube(metres, dx=12.5, scalar=1)
    assert read_segy_header(metres)["spacing"] == (None, None, 10.0)
