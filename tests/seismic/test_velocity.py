"""Velocity models: readers (arrays, raw binary, SEG-Y, NetCDF, .npy), the (x, z) frame, units, bad input."""

import struct
import warnings

import numpy as np
import pytest
import segyio

from terramesh.errors import MeshFormatError, SizingError, TerrameshWarning
from terramesh.seismic import VelocityModel, read_segy_header, read_velocity
from terramesh.seismic.velocity import MAX_VELOCITY

# a 3 (depth) x 4 (x) section, top row first: 1500 at the top, 3000 at the bottom, rising with x
SECTION_ZX = np.array(
    [
        [1500.0, 1510.0, 1520.0, 1530.0],
        [2000.0, 2010.0, 2020.0, 2030.0],
        [3000.0, 3010.0, 3020.0, 3030.0],
    ]
)


def check_section(model, dx=10.0, dz=5.0, origin=(0.0, 0.0)):
    """The model of SECTION_ZX: (x, z) frame, z negative downward, first sample on top."""
    x0, ztop = origin
    assert model.dim == 2
    assert model.shape == (4, 3)
    assert model.spacing == pytest.approx((dx, dz))
    np.testing.assert_allclose(model.bbox, [[x0, ztop - 2 * dz], [x0 + 3 * dx, ztop]])
    # top-left, top-right, bottom-left, and a value between the two upper rows
    points = [(x0, ztop), (x0 + 3 * dx, ztop), (x0, ztop - 2 * dz), (x0 + dx, ztop - dz / 2)]
    np.testing.assert_allclose(model(points), [1500.0, 1530.0, 3000.0, 1760.0])


def test_array_in_either_axis_order_gives_the_same_model():
    before = SECTION_ZX.copy()
    check_section(read_velocity(SECTION_ZX, spacing=(10.0, 5.0), axis_order="zx"))
    check_section(read_velocity(SECTION_ZX.T.copy(), spacing=(10.0, 5.0), axis_order="xz"))
    np.testing.assert_array_equal(SECTION_ZX, before)  # the input is not modified


def test_a_read_checks_the_values_once_and_keeps_no_view_of_the_input(monkeypatch):
    # the reader checks them in the user's order; the model then copied and checked them again (a 3-D model of
    # 10^8 nodes: 800 MB more at the peak)
    from terramesh.seismic import model as velocity_model
    from terramesh.seismic import velocity

    checked = []
    check = velocity_model.check_values
    for module in (velocity, velocity_model):  # the array reader's check, and VelocityModel's
        monkeypatch.setattr(module, "check_values", lambda *args: checked.append(args[1]) or check(*args))
    section = SECTION_ZX.copy()
    model = read_velocity(section, spacing=(10.0, 5.0), axis_order="zx")
    assert len(checked) == 1 and not np.shares_memory(model.values, section)
    section[:] = 1.0
    check_section(model)
    VelocityModel(model.values, model.axes)
    assert len(checked) == 2  # a model made by hand is checked


def test_origin_and_single_spacing():
    model = read_velocity(SECTION_ZX, spacing=5.0, axis_order="zx", origin=(100.0, -50.0))
    check_section(model, dx=5.0, dz=5.0, origin=(100.0, -50.0))


def test_model_does_not_share_memory_with_input():
    values = SECTION_ZX.T[:, ::-1].copy()
    model = VelocityModel(values, (np.arange(4) * 10.0, np.arange(3) * 5.0 - 10))
    values[:] = 1.0
    assert model.vmin == 1500.0


def test_km_per_s_is_converted_and_detected():
    model = read_velocity(SECTION_ZX / 1000, spacing=(10.0, 5.0), axis_order="zx", units="km/s")
    check_section(model)
    with pytest.warns(TerrameshWarning, match="looks like km/s"):
        read_velocity(SECTION_ZX / 1000, spacing=(10.0, 5.0), axis_order="zx")
    # m/s given as km/s only warned, and went on as a model of 1,500,000 m/s and more
    with pytest.raises(SizingError, match=r"3\.03e\+06 m/s \(given as 3030 km/s\).*look like m/s.*units='m/s'"):
        read_velocity(SECTION_ZX, spacing=(10.0, 5.0), axis_order="zx", units="km/s")
    with pytest.raises(SizingError, match="units"):
        read_velocity(SECTION_ZX, spacing=(10.0, 5.0), axis_order="zx", units="ft/s")


def test_velocities_faster_than_any_earth_material_are_refused(tmp_path):
    # V * 400 (600,000..1,212,000 m/s) was read as a model without a word
    with pytest.raises(SizingError, match=r"largest velocity is 1\.212e\+06 m/s, faster than any Earth material"):
        read_velocity(SECTION_ZX * 400, spacing=(10.0, 5.0), axis_order="zx")
    with pytest.raises(SizingError, match=r"25000 m/s .*at most 20000 m/s"):
        read_velocity(SECTION_ZX / 1000 * 25 / 3.03, spacing=(10.0, 5.0), axis_order="zx", units="km/s")
    path = tmp_path / "vel.bin"
    (SECTION_ZX * 10).astype("<f4").tofile(path)
    with pytest.raises(SizingError, match=r"30300 m/s.*dtype \(now 'float32'\) and byte_order \(now 'little'\)"):
        read_velocity(path, shape=(3, 4), axis_order="zx", spacing=1.0)
    fastest = SECTION_ZX * MAX_VELOCITY / SECTION_ZX.max()
    assert read_velocity(fastest, spacing=1.0, axis_order="zx").vmax == pytest.approx(MAX_VELOCITY)


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


@pytest.mark.parametrize(
    "bad, message",
    [(np.nan, "NaN or infinite"), (np.inf, "NaN or infinite"), (0.0, "zero or negative"), (-5.0, "zero or negative")],
)
def test_nan_and_non_positive_velocities_are_refused(bad, message):
    values = SECTION_ZX.copy()
    values[1, 2] = bad
    # the index is the user's, in the user's axis order: it was the model's (x first, z flipped), (2, 1) here
    with pytest.raises(SizingError, match=rf"{message}.* at index \(1, 2\) \(z, x\)"):
        read_velocity(values, spacing=(10.0, 5.0), axis_order="zx")


def test_options_a_format_does_not_use_are_refused(tmp_path):
    # a SEG-Y file read with shape, dtype and axis_order ignored all three, silently
    path = tmp_path / "section.segy"
    write_segy(path, SECTION_ZX)
    for options, names in (
        ({"shape": (3, 4)}, "shape is"),
        ({"dtype": "float64", "axis_order": "zx"}, "dtype, axis_order are"),
        ({"variable": "vp", "byte_order": "big"}, "byte_order, variable are"),
    ):
        with pytest.raises(SizingError, match=f"section.segy: {names} not used for a segy file"):
            read_velocity(path, **options)
    for default in ("float32", np.float32, "<f4"):  # the default, said again (as np.dtype has it)
        assert read_velocity(path, dtype=default).shape == read_velocity(path).shape
    array = SECTION_ZX.copy()
    with pytest.raises(SizingError, match="the velocity array: shape, variable are not used for an array"):
        read_velocity(array, spacing=10.0, axis_order="zx", shape=(3, 4), variable="vp")


def test_masked_velocities_are_missing_ones():
    # the mask was dropped: a placeholder of 1 under it became a velocity of 1 m/s
    values = np.ma.masked_array(SECTION_ZX.copy(), mask=np.zeros(SECTION_ZX.shape, dtype=bool))
    values[1, 2] = 1.0
    values[1, 2] = np.ma.masked
    with pytest.raises(SizingError, match=r"1 NaN or infinite velocities \(the first at index \(1, 2\) \(z, x\)\)"):
        read_velocity(values, spacing=(10.0, 5.0), axis_order="zx")
    with pytest.raises(SizingError, match=r"1 NaN or infinite velocities \(the first at index \(2, 1\)\)"):
        VelocityModel(values.T, ([0.0, 10.0, 20.0, 30.0], [-10.0, -5.0, 0.0]))
    values.mask = False  # unmasked: taken as it is, and 1 m/s beside 3030 m/s is refused as such
    with pytest.raises(
        SizingError, match=r"1 velocities below 100 m/s \(the first, 1 m/s, at index \(1, 2\) \(z, x\)\)"
    ):
        read_velocity(values, spacing=(10.0, 5.0), axis_order="zx")


def test_a_bad_sample_is_named_at_its_index_in_the_file(tmp_path):
    import netCDF4

    values = np.transpose(np.broadcast_to(SECTION_ZX, (2, 3, 4)), (1, 2, 0)).copy()  # z, x, y
    values[2, 1, 0] = 0.0
    path = tmp_path / "cube.bin"
    values.astype("<f4").tofile(path)
    with pytest.raises(SizingError, match=r"at index \(2, 1, 0\) \(z, x, y\)"):
        read_velocity(path, shape=values.shape, axis_order="zxy", spacing=10.0)
    path = tmp_path / "cube.nc"
    with netCDF4.Dataset(path, "w") as ds:
        for name, size in zip("zxy", values.shape, strict=True):
            ds.createDimension(name, size)
        ds.createVariable("vp", "f4", ("z", "x", "y"))[:] = values
    with pytest.raises(SizingError, match=r"at index \(2, 1, 0\) \(z, x, y\)"):
        read_velocity(path, spacing=10.0)


def test_a_raw_binary_model_with_a_few_nan_samples_is_told_to_fill_them(tmp_path):
    # they were blamed on the byte order, though every other value was a plausible velocity
    values = SECTION_ZX.astype("<f4")
    values[0, :2] = np.nan
    path = tmp_path / "holes.bin"
    values.tofile(path)
    with pytest.raises(
        SizingError, match=r"2 NaN or infinite velocities \(the first at index \(0, 0\) \(z, x\)\); fill"
    ):
        read_velocity(path, shape=(3, 4), axis_order="zx", spacing=1.0)


def test_a_top_first_z_axis_is_named_z_with_the_order_expected():
    # a z axis of 0, -5, -10 was refused as "grid axis y must be strictly increasing"
    values = SECTION_ZX.T[:, ::-1]
    with pytest.raises(
        SizingError, match=r"grid axis z decreases \(0, -5, -10\); it must increase upward, bottom first"
    ):
        VelocityModel(values, (np.arange(4) * 10.0, -np.arange(3) * 5.0))
    with pytest.raises(SizingError, match=r"grid axis x decreases \(30, 20, 10, \.\.\.\); it must increase"):
        VelocityModel(values, (np.arange(4)[::-1] * 10.0, np.arange(3) * 5.0 - 10))
    with pytest.raises(SizingError, match="grid axis z must be evenly spaced"):
        VelocityModel(values, (np.arange(4) * 10.0, [-10.0, -4.0, 0.0]))
    with pytest.raises(SizingError, match=r"grid axis z decreases .* bottom first"):
        VelocityModel(VOLUME, (np.arange(4) * 25.0, np.arange(3) * 50.0, -np.arange(5) * 5.0))
    with pytest.raises(SizingError, match=r"grid axis y decreases"):
        VelocityModel(VOLUME, (np.arange(4) * 25.0, -np.arange(3) * 50.0, np.arange(5) * 5.0 - 20.0))


def test_a_z_axis_of_depths_positive_down_warns():
    # (x, z_depth) from 0 to 11,900 m was taken silently: the model upside down, above the free surface
    values = SECTION_ZX.T[:, ::-1]
    with pytest.warns(TerrameshWarning, match=r"its z axis runs 0\.\.10 m, all at or above 0, and z is the elevation"):
        VelocityModel(values, (np.arange(4) * 10.0, np.arange(3) * 5.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        VelocityModel(values, (np.arange(4) * 10.0, np.arange(3) * 5.0 - 10.0))  # the top at 0
        VelocityModel(values, (np.arange(4) * 10.0, np.arange(3) * 5.0 - 5.0))  # topography above the datum
        model = read_velocity(SECTION_ZX, spacing=5.0, axis_order="zx")
        again = read_velocity(model.values[..., ::-1], spacing=model.spacing, axis_order="xz")  # as documented
    np.testing.assert_array_equal(again.values, model.values)


def test_array_needs_axis_order_and_spacing():
    with pytest.raises(SizingError, match="axis_order"):
        read_velocity(SECTION_ZX, spacing=(10.0, 5.0))
    with pytest.raises(SizingError, match="axis_order"):
        read_velocity(SECTION_ZX, spacing=(10.0, 5.0), axis_order="zy")
    with pytest.raises(SizingError, match="spacing"):
        read_velocity(SECTION_ZX, axis_order="zx")
    with pytest.raises(SizingError, match="spacing"):
        read_velocity(SECTION_ZX, spacing=(10.0, -5.0), axis_order="zx")
    with pytest.raises(SizingError, match="2-D or 3-D"):
        read_velocity(np.ones(5), spacing=1.0, axis_order="zx")


def test_three_dimensional_array_is_x_y_z():
    nz, nx, ny = 3, 4, 2
    values = np.empty((nz, nx, ny))
    values[:] = (1500.0 + 500.0 * np.arange(nz))[:, None, None] + 10.0 * np.arange(nx)[None, :, None]
    values += 100.0 * np.arange(ny)[None, None, :]
    model = read_velocity(values, spacing=(10.0, 20.0, 5.0), axis_order="zxy")
    assert model.dim == 3 and model.shape == (4, 2, 3)
    np.testing.assert_allclose(model.bbox, [[0, 0, -10], [30, 20, 0]])
    np.testing.assert_allclose(model([(30.0, 20.0, 0.0), (0.0, 0.0, -10.0)]), [1500 + 30 + 100, 2500.0])


@pytest.mark.parametrize("byte_order, code", [("little", "<"), ("big", ">")])
@pytest.mark.parametrize("axis_order", ["zx", "xz"])
def test_raw_binary(tmp_path, byte_order, code, axis_order):
    array = SECTION_ZX if axis_order == "zx" else SECTION_ZX.T
    path = tmp_path / "vel.bin"
    array.astype(code + "f4").tofile(path)
    model = read_velocity(path, shape=array.shape, axis_order=axis_order, byte_order=byte_order, spacing=(10.0, 5.0))
    check_section(model)


def test_raw_binary_float64_and_3d(tmp_path):
    values = np.arange(1, 25, dtype=np.float64).reshape(2, 3, 4) * 100  # (z, x, y)
    path = tmp_path / "Saltf@@"
    values.astype(">f8").tofile(path)
    model = read_velocity(path, shape=(2, 3, 4), axis_order="zxy", dtype="float64", byte_order="big", spacing=10.0)
    assert model.shape == (3, 4, 2)
    assert model([(0.0, 0.0, 0.0)])[0] == 100.0  # the first value is the top of the first trace
    assert model([(0.0, 0.0, -10.0)])[0] == 1300.0


def test_raw_binary_of_the_wrong_size_names_both_byte_counts(tmp_path):
    path = tmp_path / "vel.bin"
    SECTION_ZX.astype("<f4").tofile(path)  # 12 values, 48 bytes
    with pytest.raises(MeshFormatError, match=r"48 bytes.*\(4, 4\).*needs 64 bytes"):
        read_velocity(path, shape=(4, 4), axis_order="zx", spacing=1.0)
    with pytest.raises(MeshFormatError, match="needs 96 bytes"):
        read_velocity(path, shape=(3, 4), axis_order="zx", dtype="float64", spacing=1.0)
    with pytest.raises(SizingError, match="shape"):
        read_velocity(path, axis_order="zx", spacing=1.0)
    with pytest.raises(SizingError, match="axis_order"):
        read_velocity(path, shape=(3, 4), spacing=1.0)
    with pytest.raises(SizingError, match="byte_order"):
        read_velocity(path, shape=(3, 4), axis_order="zx", spacing=1.0, byte_order="middle")


def test_raw_binary_byte_order_named_by_the_dtype(tmp_path):
    # dtype=">f4" was read little-endian (the default byte_order) and refused as misread bytes
    path = tmp_path / "vel.bin"
    SECTION_ZX.astype(">f4").tofile(path)
    options = dict(shape=(3, 4), axis_order="zx", spacing=1.0)
    expected = read_velocity(SECTION_ZX, axis_order="zx", spacing=1.0).values
    np.testing.assert_array_equal(read_velocity(path, dtype=">f4", **options).values, expected)
    np.testing.assert_array_equal(read_velocity(path, dtype=np.dtype(">f4"), **options).values, expected)
    np.testing.assert_array_equal(read_velocity(path, dtype=">f4", byte_order="big", **options).values, expected)
    with pytest.raises(SizingError, match="dtype '>f4' is big-endian but byte_order='little'"):
        read_velocity(path, dtype=">f4", byte_order="little", **options)
    SECTION_ZX.astype("<f4").tofile(path)
    np.testing.assert_array_equal(read_velocity(path, dtype="<f4", **options).values, expected)
    with pytest.raises(SizingError, match="little-endian but byte_order='big'"):
        read_velocity(path, dtype="<f4", byte_order="big", **options)


def test_raw_binary_read_in_the_wrong_order_or_type_is_refused(tmp_path):
    # misread, 1500 m/s became 1.2e-38 (which warned "looks like km/s") or 1e23, and random bits NaN
    path = tmp_path / "vel.bin"
    SECTION_ZX.astype(">f4").tofile(path)
    options = dict(shape=(3, 4), axis_order="zx", spacing=1.0)
    with pytest.raises(
        MeshFormatError, match=r"largest magnitude 1.*e-3\d.*check byte_order \(now 'little'; try 'big'\)"
    ):
        read_velocity(path, **options)
    SECTION_ZX.astype("<f4").tofile(path)
    with pytest.raises(MeshFormatError, match=r"e\+\d\d, which no velocity model has.*dtype \(now 'float64'\)"):
        read_velocity(path, **dict(options, shape=(2, 3)), dtype="float64")
    np.random.default_rng(0).random((50, 80)).astype(">f4").tofile(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no NumPy warning on the way
        with pytest.raises(MeshFormatError, match="NaN or infinite values and largest magnitude"):
            read_velocity(path, shape=(50, 80), axis_order="zx", spacing=1.0)


@pytest.mark.parametrize("shape", [(12,), (3, 2, 2, 1), "3x4", (3.5, 4)])
def test_raw_binary_shape_is_named_before_the_spacing(tmp_path, shape):
    path = tmp_path / "vel.bin"
    SECTION_ZX.astype("<f4").tofile(path)
    with pytest.raises(SizingError, match="shape must be 2 or 3 whole numbers"):
        read_velocity(path, shape=shape, axis_order="zx", spacing=(10.0, 5.0))


def test_one_spacing_in_a_list_is_one_number():
    assert (
        read_velocity(SECTION_ZX, axis_order="zx", spacing=[10.0]).spacing
        == read_velocity(SECTION_ZX, axis_order="zx", spacing=10.0).spacing
    )


def test_npy_file(tmp_path):
    path = tmp_path / "vel.npy"
    np.save(path, SECTION_ZX)
    check_section(read_velocity(path, spacing=(10.0, 5.0), axis_order="zx"))


@pytest.mark.parametrize("imaginary", [0.0, 30.0])
def test_complex_velocities_are_refused(tmp_path, imaginary):
    # a complex .npy drew NumPy's ComplexWarning and was read as its real part
    path = tmp_path / "vel.npy"
    values = SECTION_ZX + 0j
    values[1, 2] += 1j * imaginary
    np.save(path, values)
    parts = r"1 of 12 with a nonzero imaginary part" if imaginary else "imaginary parts all 0"
    message = rf"holds complex numbers \({parts}\): velocities are real numbers.* values\.real"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning on the way
        with pytest.raises(SizingError, match=r"vel\.npy " + message):
            read_velocity(path, spacing=(10.0, 5.0), axis_order="zx")
        with pytest.raises(SizingError, match="the velocity array " + message):
            read_velocity(values, spacing=(10.0, 5.0), axis_order="zx")
        with pytest.raises(SizingError, match="the velocity model " + message):
            VelocityModel(values.T, ([0.0, 10.0, 20.0, 30.0], [-10.0, -5.0, 0.0]))


@pytest.mark.parametrize("damage", ["truncated", "object", "not_npy", "npz", "empty"])
def test_unreadable_npy_file_is_a_format_error(tmp_path, damage):
    path = tmp_path / "vel.npy"
    if damage == "truncated":  # was NumPy's "Failed to read all data" ValueError
        np.save(path, np.ones((10, 10)))
        path.write_bytes(path.read_bytes()[:200])
    elif damage == "object":  # was "Object arrays cannot be loaded when allow_pickle=False"
        np.save(path, np.array([{}, 1.0], dtype=object), allow_pickle=True)
    elif damage == "not_npy":
        path.write_text("velocity 1500 m/s")
    elif damage == "npz":
        np.savez(tmp_path / "vel", v=SECTION_ZX)
        (tmp_path / "vel.npz").rename(path)
    else:
        path.write_bytes(b"")
    with pytest.raises(MeshFormatError, match=r"vel\.npy"):
        read_velocity(path, spacing=1.0, axis_order="zx")


def write_segy(path, section_zx, *, interval=5000, dx_decimetres=100, scalar=-10, sample_format=5):
    """A 2-D SEG-Y file: one trace per column, first sample on top, IEEE floats (``sample_format=1``: IBM)."""
    nz, nx = section_zx.shape
    spec = segyio.spec()
    spec.format, spec.samples, spec.tracecount = sample_format, range(nz), nx
    with segyio.create(str(path), spec) as f:
        f.bin[segyio.BinField.Interval] = interval
        for i in range(nx):
            f.header[i] = {
                segyio.TraceField.SourceX: dx_decimetres * (i + 1),
                segyio.TraceField.GroupX: dx_decimetres * (i + 1),
                segyio.TraceField.SourceGroupScalar: scalar,
                segyio.TraceField.TRACE_SAMPLE_INTERVAL: interval,
            }
            f.trace[i] = section_zx[:, i].astype(np.float32)


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
    rewrite_interval(path, 0, 10)  # only in the trace headers
    with pytest.raises(SizingError, match=r"trace header bytes 117-118\) " + readings):
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


def write_netcdf(
    path, section_zx, *, z_name="depth", z_values=None, z_positive=None, units="km/s", z_units=None, x_units=None
):
    import netCDF4

    nz, nx = section_zx.shape
    with netCDF4.Dataset(path, "w") as ds:
        ds.createDimension(z_name, nz)
        ds.createDimension("x", nx)
        z = ds.createVariable(z_name, "f8", (z_name,))
        z[:] = np.arange(nz) * 5.0 if z_values is None else z_values
        if z_positive:
            z.positive = z_positive
        if z_units:
            z.units = z_units
        x = ds.createVariable("x", "f8", ("x",))
        x[:] = (100.0 + np.arange(nx) * 10.0) / (1000.0 if x_units == "km" else 1.0)
        if x_units:
            x.units = x_units
        vp = ds.createVariable("vp", "f4", (z_name, "x"))
        vp.units = units
        vp[:] = section_zx / (1000.0 if units.lower().startswith("km") else 1.0)


def test_netcdf_with_depth_coordinates_and_units(tmp_path):
    path = tmp_path / "model.nc"
    write_netcdf(path, SECTION_ZX)
    check_section(read_velocity(path), origin=(100.0, 0.0))


@pytest.mark.parametrize("units", ["km s-1", "km.s-1", "KM/S"])
def test_netcdf_units_in_cf_spelling(tmp_path, units):
    path = tmp_path / "model.nc"
    write_netcdf(path, SECTION_ZX, units=units)
    check_section(read_velocity(path), origin=(100.0, 0.0))


@pytest.mark.parametrize(("z_units", "x_units"), [("km", None), ("kilometres", "km"), ("metre", "m"), ("m", "meters")])
def test_netcdf_coordinates_in_km_are_converted(tmp_path, z_units, x_units):
    # a z of 0, 0.005, 0.01 with units="km" made a model 0.01 m deep
    path = tmp_path / "model.nc"
    z_values = np.arange(3) * (0.005 if z_units.startswith("k") else 5.0)
    write_netcdf(path, SECTION_ZX, z_values=z_values, z_units=z_units, x_units=x_units)
    check_section(read_velocity(path), origin=(100.0, 0.0))


def test_netcdf_coordinates_in_other_units_are_refused(tmp_path):
    path = tmp_path / "model.nc"
    write_netcdf(path, SECTION_ZX, x_units="degrees_east")
    with pytest.raises(MeshFormatError, match=r"coordinate 'x' has units 'degrees_east', not a length .*origin="):
        read_velocity(path)
    with pytest.raises(MeshFormatError, match="'degrees_east'"):
        read_velocity(path, spacing=(10.0, 5.0))  # the origin would still come from the coordinates
    check_section(read_velocity(path, spacing=(10.0, 5.0), origin=(0.0, 0.0)))  # placed by hand, no warning
    write_netcdf(path, SECTION_ZX, z_units="ft")
    with pytest.raises(MeshFormatError, match="coordinate 'depth' has units 'ft'"):
        read_velocity(path)


def test_netcdf_units_that_are_no_velocity_are_named(tmp_path):
    path = tmp_path / "model.nc"
    write_netcdf(path, SECTION_ZX, units="degC")
    with pytest.raises(MeshFormatError, match="variable 'vp' has units 'degC', not a velocity"):
        read_velocity(path)


def test_netcdf_with_elevation_bottom_first(tmp_path):
    path = tmp_path / "model.nc"
    # z elevation increasing (bottom row first): the same section stored upside down
    write_netcdf(path, SECTION_ZX[::-1], z_name="z", z_values=[-10.0, -5.0, 0.0], units="m/s")
    check_section(read_velocity(path), origin=(100.0, 0.0))


def test_netcdf_positive_down_attribute(tmp_path):
    path = tmp_path / "model.nc"
    write_netcdf(path, SECTION_ZX, z_name="z", z_values=[0.0, 5.0, 10.0], z_positive="down")
    check_section(read_velocity(path), origin=(100.0, 0.0))


def test_netcdf_plain_z_of_depths_is_read_as_depth(tmp_path):
    # z = 0, 5, 10 m with no 'positive' attribute was read as elevation: the model sat upside down above z = 0
    path = tmp_path / "model.nc"
    write_netcdf(path, SECTION_ZX, z_name="z", z_values=[0.0, 5.0, 10.0], units="m/s")
    check_section(read_velocity(path), origin=(100.0, 0.0))
    write_netcdf(path, SECTION_ZX[::-1], z_name="z", z_values=[0.0, 5.0, 10.0], z_positive="up", units="m/s")
    check_section(read_velocity(path), origin=(100.0, 10.0))  # said to be elevation: top at z = 10
    write_netcdf(path, SECTION_ZX[::-1], z_name="height", z_values=[0.0, 5.0, 10.0], units="m/s")
    check_section(read_velocity(path), origin=(100.0, 10.0))


def test_netcdf_without_coordinates_or_known_names(tmp_path):
    import netCDF4

    path = tmp_path / "bare.nc"
    with netCDF4.Dataset(path, "w") as ds:
        ds.createDimension("rows", 3)
        ds.createDimension("cols", 4)
        ds.createVariable("velocity", "f4", ("rows", "cols"))[:] = SECTION_ZX
    with pytest.raises(SizingError, match="axis_order"):
        read_velocity(path, spacing=(10.0, 5.0))
    with pytest.raises(SizingError, match="spacing"):
        read_velocity(path, axis_order="zx")
    check_section(read_velocity(path, axis_order="zx", spacing=(10.0, 5.0)))


def test_netcdf_fill_values_are_nan_errors(tmp_path):
    import netCDF4

    path = tmp_path / "holes.nc"
    with netCDF4.Dataset(path, "w") as ds:
        ds.createDimension("z", 3)
        ds.createDimension("x", 4)
        vp = ds.createVariable("vp", "f4", ("z", "x"), fill_value=-999.0)
        data = np.ma.masked_array(SECTION_ZX, mask=np.zeros_like(SECTION_ZX, dtype=bool))
        data.mask[2, 3] = True
        vp[:] = data
    with pytest.raises(SizingError, match="1 NaN or infinite"):
        read_velocity(path, spacing=(10.0, 5.0))


def test_a_netcdf_model_too_large_for_memory_is_refused_before_reading(tmp_path, monkeypatch):
    # a 200,000 x 100,000 grid stopped with NumPy's MemoryError "Unable to allocate 149 GiB" from inside netCDF4
    import netCDF4

    import terramesh.seismic.velocity as velocity

    path = tmp_path / "huge.nc"
    with netCDF4.Dataset(path, "w") as ds:  # declared, never written: a small file
        ds.createDimension("x", 200_000)
        ds.createDimension("z", 100_000)
        ds.createVariable("vp", "f4", ("x", "z"), chunksizes=(1000, 1000))
    monkeypatch.setattr(velocity, "physical_memory", lambda: 64 * 2**30)
    message = (
        r"huge\.nc: variable 'vp' has shape \(200000, 100000\), 2e\+10 values: read with their float64 copy they "
        r"need 224 GiB, more than this machine's 64 GiB of memory; cut a window .* coarser grid"
    )
    with pytest.raises(SizingError, match=message):
        read_velocity(path, spacing=10.0)


def test_repr_and_domain():
    model = read_velocity(SECTION_ZX, spacing=(10.0, 5.0), axis_order="zx")
    assert "4 x 3 nodes" in repr(model) and "1500..3030 m/s" in repr(model)
    np.testing.assert_allclose(model.domain.bbox, model.bbox)
    np.testing.assert_allclose(model.interior_bbox, model.bbox)
    volume = VelocityModel(VOLUME, (np.arange(4) * 25.0, np.arange(3) * 50.0, np.arange(5) * 5.0 - 20.0))
    assert "4 x 3 x 5 nodes, 75 x 100 x 20 m" in repr(volume)
    assert volume.domain.dim == 3
    np.testing.assert_allclose(volume.domain.bbox, volume.bbox)


def test_truncated_classic_netcdf_is_named_truncated(tmp_path):
    # netCDF-C reads zeros past the end of a cut NETCDF3 file: reported as "has 10000 zero or negative velocities"
    import netCDF4

    path = tmp_path / "model.nc"
    with netCDF4.Dataset(path, "w", format="NETCDF3_CLASSIC") as ds:
        ds.createDimension("depth", 100)
        ds.createDimension("x", 200)
        ds.createVariable("depth", "f8", ("depth",))[:] = np.arange(100) * 5.0
        ds.createVariable("x", "f8", ("x",))[:] = np.arange(200) * 10.0
        ds.createVariable("vp", "f4", ("depth", "x"))[:] = np.linspace(1500.0, 4500.0, 100)[:, None] + np.zeros(200)
    assert read_velocity(path).vmax == pytest.approx(4500.0)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(MeshFormatError, match=rf"model.nc is truncated: {len(data) // 2:,} bytes, but its variables"):
        read_velocity(path)


def test_npz_archive_and_folder_are_named(tmp_path):
    # an .npz was read as raw binary ("a raw binary file needs its shape"); a folder raised a bare IsADirectoryError
    np.savez(tmp_path / "model.npz", vp=SECTION_ZX)
    with pytest.raises(MeshFormatError, match=r"model.npz: an .npz archive of arrays \['vp'\], not one .npy array"):
        read_velocity(tmp_path / "model.npz", spacing=1.0, axis_order="zx")
    with pytest.raises(IsADirectoryError, match=r"the velocity file '.*' is a folder; in it: \['model.npz'\]: give"):
        read_velocity(tmp_path, shape=(3, 4), spacing=1.0, axis_order="zx")
