"""terramesh.seismic.velocity: read_velocity, the format choice, and the NetCDF, .npy and array readers."""

import numpy as np
import pytest
import segyio

from terramesh.errors import MeshFormatError, SizingError
from terramesh.seismic import VelocityModel, read_velocity

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


def test_one_spacing_in_a_list_is_one_number():
    assert (
        read_velocity(SECTION_ZX, axis_order="zx", spacing=[10.0]).spacing
        == read_velocity(SECTION_ZX, axis_order="zx", spacing=10.0).spacing
    )


def test_npy_file(tmp_path):
    path = tmp_path / "vel.npy"
    np.save(path, SECTION_ZX)
    check_section(read_velocity(path, spacing=(10.0, 5.0), axis_order="zx"))


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
    with pytest.raises(
        MeshFormatError, match=rf"model.nc is truncated: {len(data) // 2:,} bytes, but its data end at byte"
    ):
        read_velocity(path)


def test_npz_archive_and_folder_are_named(tmp_path):
    # an .npz was read as raw binary ("a raw binary file needs its shape"); a folder raised a bare IsADirectoryError
    np.savez(tmp_path / "model.npz", vp=SECTION_ZX)
    with pytest.raises(MeshFormatError, match=r"model.npz: an .npz archive of arrays \['vp'\], not one .npy array"):
        read_velocity(tmp_path / "model.npz", spacing=1.0, axis_order="zx")
    with pytest.raises(IsADirectoryError, match=r"the velocity file '.*' is a folder; in it: \['model.npz'\]: give"):
        read_velocity(tmp_path, shape=(3, 4), spacing=1.0, axis_order="zx")
