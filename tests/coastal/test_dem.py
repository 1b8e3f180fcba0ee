"""DEM: construction, reading NetCDF and GeoTIFF subsets, bilinear sampling."""

import re
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.coastal.dem import DEM, read_dem
from terramesh.errors import GeometryError, MeshFormatError, SizingError, TerrameshWarning


def _plane(lon, lat, a=3.0, b=-2.0, c=5.0):
    lon2, lat2 = np.meshgrid(lon, lat, indexing="ij")
    return a + b * lon2 + c * lat2


def _write_netcdf(
    path,
    lon,
    lat,
    z_lat_lon,
    *,
    order=("lat", "lon"),
    names=("lon", "lat", "z"),
    fill=None,
    dtype="f4",
    attributes=None,
):
    """A NetCDF DEM; ``fill=False`` writes no _FillValue, ``attributes`` maps a variable name to its attributes."""
    import netCDF4

    lon_name, lat_name, z_name = names
    with netCDF4.Dataset(path, "w") as out:
        out.createDimension(lat_name, len(lat))
        out.createDimension(lon_name, len(lon))
        out.createVariable(lat_name, "f8", (lat_name,))[:] = lat
        out.createVariable(lon_name, "f8", (lon_name,))[:] = lon
        dims = tuple(lat_name if d == "lat" else lon_name for d in order)
        z = out.createVariable(z_name, dtype, dims, fill_value=fill)
        z[:] = z_lat_lon if order == ("lat", "lon") else np.ascontiguousarray(z_lat_lon.T)
        for name, values in (attributes or {}).items():
            out[name].setncatts(values)
    return path


def _write_geotiff(path, z_rows, *, nodata=None, unit=None, west=10.0, north=56.0, step=0.1):
    """A one-band WGS84 GeoTIFF of ``z_rows`` (rows north to south), with no nodata unless given."""
    rasterio = pytest.importorskip("rasterio")
    height, width = z_rows.shape
    profile = {"driver": "GTiff", "height": height, "width": width, "count": 1, "dtype": z_rows.dtype.name}
    transform = rasterio.Affine(step, 0.0, west, 0.0, -step, north)
    with rasterio.open(path, "w", crs="EPSG:4326", transform=transform, nodata=nodata, **profile) as out:
        out.write(z_rows, 1)
        if unit is not None:
            out.set_band_unit(1, unit)
    return path


# ----------------------------------------------------------------------------------------------------------------
# the class


def test_sample_is_exact_on_a_plane():
    lon, lat = np.linspace(-94.0, -93.0, 11), np.linspace(29.0, 30.5, 7)
    dem = DEM(lon, lat, _plane(lon, lat))
    rng = np.random.default_rng(1)
    plon, plat = rng.uniform(-94, -93, 1000), rng.uniform(29, 30.5, 1000)
    assert np.allclose(dem.sample(plon, plat), 3.0 - 2.0 * plon + 5.0 * plat, rtol=0, atol=1e-9)
    # broadcasting and shape
    assert dem.sample(plon.reshape(10, 100), 29.5).shape == (10, 100)


def test_sample_clamps_outside_and_propagates_nan():
    lon, lat = np.linspace(0.0, 1.0, 5), np.linspace(0.0, 1.0, 3)
    dem = DEM(lon, lat, _plane(lon, lat))
    assert dem.sample(-5.0, 0.5) == pytest.approx(3.0 + 2.5)  # west edge at lon 0
    assert dem.sample(0.5, 7.0) == pytest.approx(3.0 - 1.0 + 5.0)  # north edge at lat 1
    assert np.isnan(dem.sample(np.nan, 0.5))


@settings(deadline=None, max_examples=40)
@given(st.integers(0, 2**32 - 1), st.integers(2, 9), st.integers(2, 9))
def test_sample_matches_scipy_on_wrapped_and_clamped_points(seed, nx, ny):
    from scipy.interpolate import RegularGridInterpolator

    rng = np.random.default_rng(seed)
    lon = -100.0 + 0.25 * np.arange(nx)
    lat = 10.0 + 0.5 * np.arange(ny)
    dem = DEM(lon, lat, rng.normal(size=(nx, ny)) * 1e3)
    plon = rng.uniform(-100.5, lon[-1] + 0.5, 300) + 360.0 * rng.integers(-2, 3, 300)
    plat = rng.uniform(9.0, lat[-1] + 1.0, 300)
    plon[::17], plat[::23] = np.nan, np.inf
    on_grid = lon[0] + np.mod(plon - lon[0], 360.0)
    wrapped = np.where(((plon < lon[0]) | (plon > lon[-1])) & (on_grid <= lon[-1]), on_grid, plon)
    finite = np.isfinite(plon) & np.isfinite(plat)
    clamped = np.column_stack([np.clip(wrapped[finite], lon[0], lon[-1]), np.clip(plat[finite], lat[0], lat[-1])])
    value = dem.sample(plon, plat)
    assert np.isnan(value[~finite]).all()
    expected = RegularGridInterpolator((lon, lat), dem.elevation)(clamped)
    np.testing.assert_allclose(value[finite], expected, rtol=1e-12, atol=1e-9)


@settings(deadline=None, max_examples=40)
@given(st.integers(0, 2**32 - 1), st.integers(2, 9), st.integers(2, 9), st.integers(0, 40), st.integers(0, 40))
def test_sample_grid_is_sample_on_the_meshgrid_to_the_bit(seed, nx, ny, n_lon, n_lat):
    """The size grid's depths: wrapped, clamped, NaN and infinite axes included."""
    rng = np.random.default_rng(seed)
    dem = DEM(-100.0 + 0.25 * np.arange(nx), 10.0 + 0.5 * np.arange(ny), rng.normal(size=(nx, ny)) * 1e3)
    lon = rng.uniform(-100.5, -99.5 + 0.25 * nx, n_lon) + 360.0 * rng.integers(-2, 3, n_lon)
    lat = rng.uniform(9.0, 11.0 + 0.5 * ny, n_lat)
    lon[::7], lat[::5] = np.nan, np.inf
    got = dem.sample_grid(lon, lat)
    assert got.shape == (n_lon, n_lat)
    np.testing.assert_array_equal(got, dem.sample(*np.meshgrid(lon, lat, indexing="ij")))


def test_sample_grid_refuses_axes_that_are_not_1d():
    dem = DEM([0.0, 1.0], [0.0, 2.0], [[0.0, 2.0], [1.0, 3.0]])
    with pytest.raises(GeometryError, match="1-D axes"):
        dem.sample_grid([[0.0, 0.5]], [0.0, 1.0])


def test_constructor_copies_and_freezes():
    lon, lat = np.linspace(0.0, 1.0, 5), np.linspace(0.0, 1.0, 3)
    z = _plane(lon, lat)
    before = z.copy()
    dem = DEM(lon, lat, z)
    z[:] = -1.0
    assert np.array_equal(dem.elevation, before)
    with pytest.raises(ValueError):
        dem.elevation[0, 0] = 5.0
    assert np.array_equal(dem.depth, -before)


def test_properties():
    lon, lat = np.linspace(10.0, 12.0, 21), np.linspace(59.0, 61.0, 11)
    dem = DEM(lon, lat, _plane(lon, lat))
    assert dem.bbox == (10.0, 12.0, 59.0, 61.0)
    assert (dem.dx, dem.dy) == pytest.approx((0.1, 0.2))
    east, north = dem.resolution
    assert east == pytest.approx(0.1 * 111319.49 * 0.5, rel=1e-5)  # cos(60) = 1/2
    assert north == pytest.approx(0.2 * 111319.49, rel=1e-5)


@pytest.mark.parametrize(
    ("lon", "lat", "z", "match"),
    [
        (np.linspace(0, 1, 5), np.linspace(0, 1, 3), np.zeros((3, 5)), "pass elevation.T"),
        (np.linspace(0, 1, 5), np.linspace(0, 1, 3), np.zeros((4, 4)), "expected"),
        (np.array([0.0, 1.0, 3.0]), np.linspace(0, 1, 3), np.zeros((3, 3)), "evenly spaced"),
        (np.linspace(1, 0, 3), np.linspace(0, 1, 3), np.zeros((3, 3)), "increasing"),
        (np.linspace(0, 1, 3), np.linspace(0, 1e6, 3), np.zeros((3, 3)), "not in degrees"),
        (np.linspace(0, 1, 3), [0.0], np.zeros((3, 1)), "at least 2"),
    ],
)
def test_constructor_rejects_bad_grids(lon, lat, z, match):
    with pytest.raises(GeometryError, match=match):
        DEM(lon, lat, z)


def test_nan_cells_are_filled_with_a_warning():
    lon, lat = np.linspace(0.0, 1.0, 6), np.linspace(0.0, 1.0, 6)
    z = _plane(lon, lat)
    z[2, 3] = np.nan
    z[0, 0] = np.nan
    with pytest.warns(TerrameshWarning, match="2 of 36 cells"):
        dem = DEM(lon, lat, z)
    assert np.isfinite(dem.elevation).all()
    neighbours = [z[1, 3], z[3, 3], z[2, 2], z[2, 4]]
    assert dem.elevation[2, 3] in neighbours
    with pytest.raises(GeometryError, match="no valid elevation"):
        DEM(lon, lat, np.full((6, 6), np.nan))


# ----------------------------------------------------------------------------------------------------------------
# real files


def test_etopo_over_the_atlantic_box(shared_data):
    """ETOPO1 has lon 0..360: a -180..180 box must come back in -180..180, subset, with sensible values."""
    dem = read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", (-100, -50, 10, 60))
    lon_min, lon_max, lat_min, lat_max = dem.bbox
    assert -100.5 < lon_min <= -100.0 and -50.0 <= lon_max < -49.5
    assert 9.5 < lat_min <= 10.0 and 60.0 <= lat_max < 60.5
    assert dem.shape == (507, 507)  # 0.1 degree, 3 cells of margin
    gulf, kansas, atlantic, hudson_bay = dem.sample([-90.0, -98.0, -60.0, -86.0], [25.0, 38.5, 30.0, 60.0])
    assert gulf < -2500.0 and atlantic < -4000.0
    assert 200.0 < kansas < 1000.0
    assert -500.0 < hudson_bay < 0.0
    assert dem.resolution[1] == pytest.approx(11132.0, rel=1e-3)


def test_etopo_box_across_the_files_seam(shared_data):
    """A box over Greenwich takes columns from both ends of a 0..360 file."""
    dem = read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", (-10, 10, 40, 50), margin=0)
    assert dem.bbox[:2] == pytest.approx((-10.0, 10.0))
    assert np.allclose(np.diff(dem.lon), 0.1)
    full = read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", (0, 10, 40, 50), margin=0)
    west = read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", (350, 359.9, 40, 50), margin=0)
    assert np.array_equal(dem.elevation[100:], full.elevation)
    assert np.array_equal(dem.elevation[:100], west.elevation)
    madrid, paris = dem.sample([-3.7, 2.35], [40.4, 48.85])
    assert madrid > 400.0 and 0.0 < paris < 200.0


@pytest.mark.parametrize("name", ["CUDEM_equal.nc", "CUDEM_unequal.nc"])
def test_cudem(shared_data, name):
    dem = read_dem(shared_data / "dem" / name)
    assert dem.bbox[0] == pytest.approx(-94.0, abs=1e-3) and dem.bbox[3] == pytest.approx(29.9, abs=1e-3)
    assert dem.shape == {"CUDEM_equal.nc": (648, 648), "CUDEM_unequal.nc": (645, 690)}[name]
    assert -20.0 < dem.elevation.min() < -10.0 and 5.0 < dem.elevation.max() < 15.0
    channel, sabine_lake = dem.sample([-93.8613, -93.83], [29.72, 29.86])
    assert channel < -10.0 and -3.0 < sabine_lake < 0.0
    if name == "CUDEM_unequal.nc":
        assert dem.dx == pytest.approx(0.00031) and dem.dy == pytest.approx(0.00029)


def test_cudem_subset_matches_the_whole(shared_data):
    path = shared_data / "dem" / "CUDEM_equal.nc"
    whole = read_dem(path)
    part = read_dem(path, (-93.95, -93.9, 29.75, 29.8), margin=2)
    assert part.shape[0] < whole.shape[0] // 3
    i = int(np.argmin(np.abs(whole.lon - part.lon[0])))
    j = int(np.argmin(np.abs(whole.lat - part.lat[0])))
    assert np.array_equal(part.elevation, whole.elevation[i : i + part.shape[0], j : j + part.shape[1]])


# ----------------------------------------------------------------------------------------------------------------
# layouts written here


def test_descending_latitude_and_0_360_longitudes(tmp_path):
    lon, lat = np.arange(250.0, 260.0, 0.5), np.arange(40.0, 30.0, -0.5)
    z = _plane(lon - 360.0, lat).T  # (lat, lon)
    path = _write_netcdf(tmp_path / "descending.nc", lon, lat, z)
    dem = read_dem(path, (-108.0, -104.0, 32.0, 35.0), margin=1)
    assert np.all(np.diff(dem.lat) > 0) and np.all(np.diff(dem.lon) > 0)
    assert dem.bbox == pytest.approx((-108.5, -103.5, 31.5, 35.5))
    assert np.allclose(dem.elevation, _plane(dem.lon, dem.lat))


def test_lon_lat_dimension_order_and_other_names(tmp_path):
    lon, lat = np.linspace(-5.0, 5.0, 21), np.linspace(-3.0, 3.0, 13)
    z = _plane(lon, lat).T
    path = _write_netcdf(
        tmp_path / "lonlat.nc", lon, lat, z, order=("lon", "lat"), names=("Longitude", "LATITUDE", "Band1")
    )
    dem = read_dem(path)
    assert np.allclose(dem.elevation, _plane(lon, lat), atol=1e-5)
    assert dem.bbox == (-5.0, 5.0, -3.0, 3.0)


@pytest.mark.parametrize(
    ("name", "attributes", "sign"),
    [
        ("depth", {}, -1.0),  # was read as elevation: 50 m of water became land 50 m high, silently
        ("h", {"units": "m"}, -1.0),
        ("deptho", {}, -1.0),
        ("bed", {"standard_name": "sea_floor_depth_below_geoid"}, -1.0),
        ("depth", {"positive": "up"}, 1.0),
        ("z", {}, 1.0),
        ("z", {"positive": "down"}, -1.0),
    ],
)
def test_a_variable_of_depths_is_negated(tmp_path, name, attributes, sign):
    import netCDF4

    lon, lat = np.linspace(-5.0, 5.0, 21), np.linspace(-3.0, 3.0, 13)
    path = _write_netcdf(tmp_path / "grid.nc", lon, lat, _plane(lon, lat).T, names=("lon", "lat", name))
    with netCDF4.Dataset(path, "a") as out:
        out[name].setncatts(attributes)
    assert np.allclose(read_dem(path).elevation, sign * _plane(lon, lat), atol=1e-5)


def test_the_sign_can_be_given_and_says_how_it_was_chosen(tmp_path):
    # a variable named "depth" that held elevations was negated with no word: now the reading is logged, kept on
    # the DEM, and positive= overrides it
    lon, lat = np.linspace(-5.0, 5.0, 21), np.linspace(-3.0, 3.0, 13)
    path = _write_netcdf(tmp_path / "grid.nc", lon, lat, _plane(lon, lat).T, names=("lon", "lat", "depth"))
    guessed = read_dem(path)
    assert np.allclose(guessed.elevation, -_plane(lon, lat), atol=1e-5)
    assert guessed.sign_note == (
        "grid.nc variable 'depth' was read as depths (positive down) and negated: its name, as it has no positive"
        " attribute"
    )
    assert np.allclose(read_dem(path, positive="up").elevation, _plane(lon, lat), atol=1e-5)
    assert read_dem(path, positive="UP").sign_note.endswith('elevation (positive up): positive="up" was given')
    heights = _write_netcdf(tmp_path / "z.nc", lon, lat, _plane(lon, lat).T)
    assert np.allclose(DEM.read(heights, positive="down").elevation, -_plane(lon, lat), atol=1e-5)
    note = read_dem(heights).sign_note
    assert note.endswith("elevation (positive up): it has no positive attribute and no name of depths")
    assert (guessed.file_positive, read_dem(heights).file_positive) == ("down", "up")
    assert DEM(lon, lat, _plane(lon, lat)).sign_note is None and DEM(lon, lat, _plane(lon, lat)).file_positive is None


@pytest.mark.parametrize("positive", ["upward", 1, True, "", b"up", np.array(["up", "down"])])
def test_a_bad_sign_is_named(tmp_path, positive):
    lon, lat = np.linspace(-5.0, 5.0, 21), np.linspace(-3.0, 3.0, 13)
    path = _write_netcdf(tmp_path / "grid.nc", lon, lat, _plane(lon, lat).T)
    with pytest.raises(GeometryError, match=rf"positive must be \"up\" .* got {re.escape(repr(positive))}"):
        read_dem(path, positive=positive)


def test_fill_values_become_nan_then_are_filled(tmp_path):
    lon, lat = np.linspace(0.0, 1.0, 11), np.linspace(0.0, 1.0, 11)
    z = _plane(lon, lat).T.astype(np.float32)
    z[4:6, 4:6] = -99999.0
    path = _write_netcdf(tmp_path / "holes.nc", lon, lat, z, fill=-99999.0)
    with pytest.warns(TerrameshWarning, match="4 of 121 cells"):
        dem = read_dem(path)
    assert dem.elevation.min() > -10.0


def test_a_geotiff_bands_scale_and_offset_are_applied(tmp_path):
    # int16 decimetres with GDAL's scale 0.1 read as metres: depths ten times too deep, inside the Earth's range
    rasterio = pytest.importorskip("rasterio")
    lon, lat = 10.05 + 0.1 * np.arange(20), 55.95 - 0.1 * np.arange(10)  # cell centres, north first
    metres = 300.0 * (lon[None, :] - 11.0) + 30.0 * (lat[:, None] - 55.0) - 40.0
    path = _write_geotiff(tmp_path / "scaled.tif", np.round((metres + 100.0) * 10).astype(np.int16), unit="m")
    with rasterio.open(path, "r+") as out:
        out.scales, out.offsets = (0.1,), (-100.0,)
    dem = read_dem(path)
    assert np.allclose(dem.elevation, metres[::-1].T, atol=0.051)  # rows south to north, indexed [ix, iy]


def test_geotiff_round_trip(tmp_path):
    rasterio = pytest.importorskip("rasterio")
    rng = np.random.default_rng(0)
    z = rng.normal(0.0, 100.0, size=(30, 40)).astype(np.float32)  # rows north to south
    west, north, step = -71.0, 43.0, 0.01
    path = tmp_path / "dem.tif"
    profile = {"driver": "GTiff", "height": 30, "width": 40, "count": 1, "dtype": "float32", "crs": "EPSG:4326"}
    with rasterio.open(path, "w", transform=rasterio.Affine(step, 0.0, west, 0.0, -step, north), **profile) as out:
        out.write(z, 1)
    dem = read_dem(path)
    assert np.array_equal(dem.elevation, z[::-1].T.astype(np.float64))
    assert np.allclose(dem.lon, west + step * (np.arange(40) + 0.5))
    assert np.allclose(dem.lat, north - step * (np.arange(30)[::-1] + 0.5))
    part = read_dem(path, (-70.8, -70.7, 42.8, 42.9), margin=0)
    i = int(np.argmin(np.abs(dem.lon - part.lon[0])))
    j = int(np.argmin(np.abs(dem.lat - part.lat[0])))
    assert np.array_equal(part.elevation, dem.elevation[i : i + part.shape[0], j : j + part.shape[1]])
    assert (
        dem.sign_note == "dem.tif band 1 was read as elevation (positive up): a GeoTIFF band says nothing of its sign"
    )
    assert np.array_equal(read_dem(path, positive="down").elevation, -dem.elevation)


# ----------------------------------------------------------------------------------------------------------------
# failures


def test_bbox_outside_the_data(shared_data):
    with pytest.raises(
        GeometryError,
        match=r"bbox \(-80.0, -79.0, 29.7, 29.9\) does not overlap the DEM CUDEM_equal.nc \(lon -93.9999..-93.8002",
    ):
        read_dem(shared_data / "dem" / "CUDEM_equal.nc", (-80.0, -79.0, 29.7, 29.9))


def test_partial_cover_warns(shared_data):
    with pytest.warns(TerrameshWarning, match="less than the bbox"):
        read_dem(shared_data / "dem" / "CUDEM_equal.nc", (-93.9, -93.7, 29.8, 29.85))


@pytest.mark.parametrize("fraction", [0.5, 0.003])
def test_truncated_files(shared_data, tmp_path, fraction):
    for name in ("CUDEM_equal.nc", "ETOPO1_0.1.grd"):
        data = (shared_data / "dem" / name).read_bytes()
        path = tmp_path / name
        path.write_bytes(data[: int(len(data) * fraction)])
        with pytest.raises(MeshFormatError, match=name):
            read_dem(path)


def test_missing_and_not_a_dem(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothing.nc"):
        read_dem(tmp_path / "nothing.nc")
    text = tmp_path / "notes.nc"
    text.write_text("not a NetCDF file\n")
    with pytest.raises(MeshFormatError, match="notes.nc"):
        read_dem(text)
    tif = tmp_path / "broken.tif"
    tif.write_bytes(b"II*\x00garbage")
    with pytest.raises(MeshFormatError, match="broken.tif"):
        read_dem(tif)


def test_netcdf_without_coordinates(tmp_path):
    import netCDF4

    path = tmp_path / "bare.nc"
    with netCDF4.Dataset(path, "w") as out:
        out.createDimension("a", 3)
        out.createDimension("b", 4)
        out.createVariable("z", "f4", ("a", "b"))[:] = np.zeros((3, 4))
    with pytest.raises(MeshFormatError, match="no 1-D longitude and latitude"):
        read_dem(path)


def test_read_does_not_change_the_file(shared_data):
    path = shared_data / "dem" / "CUDEM_equal.nc"
    before = path.stat().st_mtime_ns
    DEM.read(path, (-94.0, -93.9, 29.7, 29.8))
    assert path.stat().st_mtime_ns == before


def test_a_grid_too_large_for_memory_is_refused_before_reading(tmp_path):
    # read without a bbox, a 200,000 x 200,000 grid failed inside netCDF4 with NumPy's MemoryError ("Unable to
    # allocate 149. GiB"). This one is 400,000 x 400,000 nodes, chunked and written in one corner only (6 MB)
    import netCDF4

    path = tmp_path / "huge.nc"
    with netCDF4.Dataset(path, "w") as out:
        out.createDimension("lat", 400_000)
        out.createDimension("lon", 400_000)
        out.createVariable("lat", "f8", ("lat",))[:] = np.linspace(-60.0, 60.0, 400_000)
        out.createVariable("lon", "f8", ("lon",))[:] = np.linspace(-170.0, 170.0, 400_000)
        out.createVariable("z", "f4", ("lat", "lon"), chunksizes=(500, 500))[:500, :500] = -10.0
    message = (
        r"^the DEM huge.nc is a grid of 400,000 x 400,000 nodes \(latitude x longitude\): reading all of it needs"
        r" about 4,768.4 GiB, more than the [\d,.]+ GiB of memory free. Give a bbox"
    )
    with pytest.raises(SizingError, match=message):
        read_dem(path)
    with pytest.raises(SizingError, match=message):
        tm.coastal.Shoreline.from_dem(path)
    corner = read_dem(path, (-169.99, -169.98, -59.99, -59.98))  # what the message asks for
    assert np.all(corner.elevation == -10.0)


def test_a_geotiff_too_large_for_the_memory_free_is_refused(tmp_path, monkeypatch):
    import terramesh.coastal.dem as dem_module

    assert dem_module.available_memory() > 0
    path = _write_geotiff(tmp_path / "dem.tif", np.full((20, 30), -5.0, dtype="f4"))
    monkeypatch.setattr(dem_module, "available_memory", lambda: 20 * 30 * 32 - 1)  # a byte short
    with pytest.raises(SizingError, match=r"is a grid of 20 x 30 nodes .* reading all of it needs about 1.79e-05 GiB"):
        read_dem(path)
    with pytest.raises(SizingError, match=r"reading the part in the bbox \(20 x 30 nodes\)"):
        read_dem(path, (10.2, 12.8, 54.1, 55.9), margin=1)
    assert read_dem(path, (10.2, 10.8, 54.1, 55.9), margin=1).shape == (10, 20)


def test_a_geotiff_with_no_crs_warns_that_it_is_taken_as_longitude_latitude(tmp_path):
    # it was taken as WGS84 without a word; the tests' GeoTIFFs (_write_geotiff) say EPSG:4326 and read silently
    rasterio = pytest.importorskip("rasterio")
    path = tmp_path / "nocrs.tif"
    profile = {"driver": "GTiff", "height": 20, "width": 30, "count": 1, "dtype": "float32"}
    with rasterio.open(path, "w", transform=rasterio.Affine(0.1, 0.0, 10.0, 0.0, -0.1, 56.0), **profile) as out:
        out.write(np.full((20, 30), -5.0, dtype="f4"), 1)
    message = (
        r"^the GeoTIFF nocrs.tif has no CRS: its coordinates \(lon 10.05..12.95, lat 54.05..55.95\) were taken as"
        r" WGS84 longitude, latitude. If they are, give it one \(gdal_edit.py -a_srs EPSG:4326 nocrs.tif\)"
    )
    with pytest.warns(TerrameshWarning, match=message):
        dem = read_dem(path)
    assert dem.bbox == pytest.approx((10.05, 12.95, 54.05, 55.95))
    read_dem(_write_geotiff(tmp_path / "wgs84.tif", np.full((20, 30), -5.0, dtype="f4")))  # a CRS: no warning


def test_a_box_across_the_antimeridian_written_as_a_map_reads_is_told_how_to_write_it(shared_data):
    # the command line said so; read_dem and read_shoreline said only "min < max ... longitudes first"
    with pytest.raises(GeometryError, match=r"written with longitudes past 180: \(178, 182, -20, -15\)$"):
        read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", (178, -178, -20, -15))


def test_geotiff_without_rasterio_names_the_extra(tmp_path, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "rasterio", None)
    path = tmp_path / "dem.tif"
    path.write_bytes(b"II*\x00")
    with pytest.raises(ImportError, match=r"terramesh\[geotiff\]"):
        read_dem(path)


def test_an_axis_whose_steps_drift_one_way_is_refused(tmp_path):
    # each step within 4 % of the mean, but long over the first half and short over the second: the middle
    # longitude was read 20 cells (0.2 degrees) from where the file put it, silently
    step = 0.01 * np.where(np.arange(1000) < 500, 1.04, 0.96)
    lon, lat = np.concatenate([[0.0], np.cumsum(step)]), np.linspace(0.0, 1.0, 11)
    path = _write_netcdf(tmp_path / "drift.nc", lon, lat, _plane(lon, lat).T)
    with pytest.raises(GeometryError, match=r"longitudes is not evenly spaced: value 500 is 5.2, 20 steps off"):
        read_dem(path)


@pytest.mark.parametrize("box", [(-180, 180, -10, 10), (0, 360, -10, 10)])
def test_a_box_all_the_way_round_reads_one_turn(shared_data, box):
    # with the default margin of 3 cells, columns from both ends of the join made 360.6 degrees, refused as
    # "not in degrees"
    path = shared_data / "dem" / "ETOPO1_0.1.grd"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and no warning that it covers less than the box
        dem = read_dem(path, box)
    assert dem.shape[0] == 3600 and np.allclose(np.diff(dem.lon), 0.1)
    tight = read_dem(path, box, margin=0)
    lon = np.array([box[0] + 0.05, 0.0, 100.0, box[1] - 0.05])  # the last half a cell before the seam too
    np.testing.assert_allclose(dem.sample(lon, np.full(4, 5.0)), tight.sample(lon, np.full(4, 5.0)))


def test_a_projected_grid_read_with_a_degree_box_is_named_so(tmp_path):
    # UTM metres: the box "did not overlap the DEM (lon 500000..501170)", which sent users to check the box
    x, y = np.linspace(5e5, 5.0117e5, 40), np.linspace(4.4e6, 4.401e6, 30)
    path = _write_netcdf(tmp_path / "utm.nc", x, y, np.zeros((30, 40)))
    with pytest.raises(GeometryError, match=r"utm.nc \(lon 500000..501170, .*\) is not in degrees: reproject"):
        read_dem(path, (-75.0, -74.0, 39.0, 40.0))


def test_a_grid_all_the_way_round_interpolates_across_its_seam():
    # -180..179 by 1 degree: between 179 and 180 a point took the value at 179, not a blend with -180's
    lon, lat = np.arange(-180.0, 180.0), np.array([0.0, 1.0])
    elevation = np.zeros((360, 2))
    elevation[-1], elevation[0] = 100.0, -100.0
    dem = DEM(lon, lat, elevation)
    np.testing.assert_allclose(dem.sample([179.25, 179.5, 180.0, 540.5], [0.5] * 4), [50.0, 0.0, -100.0, -50.0])
    np.testing.assert_allclose(dem.sample_grid([179.25, -179.75], [0.0]), [[50.0], [-75.0]])
    # west of the first column of a cell-centred grid (-179.5..179.5) too: -180 is 180
    centred = DEM(lon + 0.5, lat, elevation)
    np.testing.assert_allclose(centred.sample([-179.75, -180.0, 180.0, 179.75], [0.5] * 4), [-50.0, 0.0, 0.0, 50.0])
    # a grid short of a turn keeps its edge values
    part = DEM(lon[:300], lat, elevation[:300])
    np.testing.assert_allclose(part.sample([170.0, 179.5], [0.5, 0.5]), [0.0, 0.0])


# ----------------------------------------------------------------------------------------------------------------
# bad input: undeclared fill values, units, band, not a path


def _sea(holes_value, dtype):
    """A 21 x 21 sea floor 10..90 m deep, (lat, lon), with a 3 x 3 hole of ``holes_value``, and its axes."""
    lon, lat = np.linspace(10.0, 12.0, 21), np.linspace(54.0, 56.0, 21)
    z = np.tile(-50.0 + 40.0 * (lon - 11.0), (21, 1))
    z[5:8, 5:8] = holes_value
    return lon, lat, z.astype(dtype)


@pytest.mark.parametrize(
    ("value", "dtype", "shown"),
    [(-32768, "i2", "all -32768 m"), (-9999.0, "f4", "all -9999 m"), (1e30, "f4", "all 1e+30 m")],
    ids=["int16 -32768", "float -9999", "float 1e30"],
)
def test_an_undeclared_netcdf_fill_value_is_refused(tmp_path, value, dtype, shown):
    # without _FillValue these were read as heights: a coastal build gave depths of 29,480 m, silently
    lon, lat, z = _sea(value, dtype)
    path = _write_netcdf(tmp_path / "holes.nc", lon, lat, z, fill=False, dtype=dtype)
    with pytest.raises(
        GeometryError, match=rf"DEM holes.nc: 9 of 441 cells .*\({re.escape(shown)}\): an undeclared fill value\?"
    ):
        read_dem(path)
    # declared, the same value is a hole, filled with a warning
    declared = _write_netcdf(tmp_path / "declared.nc", lon, lat, z, fill=value, dtype=dtype)
    with pytest.warns(TerrameshWarning, match="9 of 441 cells"):
        assert read_dem(declared).elevation.min() >= -90.0


def test_an_undeclared_geotiff_nodata_is_refused(tmp_path):
    lon, lat, z = _sea(-32768, "i2")
    path = _write_geotiff(tmp_path / "holes.tif", z[::-1])
    with pytest.raises(GeometryError, match=r"9 of 441 cells have elevations outside Earth's range .*nodata"):
        read_dem(path)
    declared = _write_geotiff(tmp_path / "declared.tif", z[::-1], nodata=-32768)
    with pytest.warns(TerrameshWarning, match="9 of 441 cells"):
        assert read_dem(declared).elevation.min() >= -90.0


def test_the_constructor_refuses_elevations_outside_earths_range():
    lon, lat, z = _sea(-32768, "f8")
    z[0, 0] = 12_000.0
    with pytest.raises(GeometryError, match=r"10 of 441 cells .*\(-32768..12000 m; most often -32768, in 9 cells\)"):
        DEM(lon, lat, z.T)
    # positive-down depths of a trench, read as heights: the message says how to mark them
    with pytest.raises(GeometryError, match=r'positive = "down"'):
        DEM(lon, lat, np.full((21, 21), 10_500.0))
    # a grid that reaches a trench may hold -9999 as data; infinities stay missing cells, filled
    trench = np.linspace(-10_900.0, -8_000.0, 441).reshape(21, 21)
    trench[3, 3], trench[4, 4] = -9999.0, -np.inf
    with pytest.warns(TerrameshWarning, match="1 of 441 cells"):
        assert DEM(lon, lat, trench).elevation[3, 3] == -9999.0


def test_real_dems_are_within_earths_range(shared_data):
    etopo = read_dem(shared_data / "dem" / "ETOPO1_0.1.grd")
    assert (etopo.elevation.min(), etopo.elevation.max()) == (-10714.0, 8266.0)


@pytest.mark.parametrize(
    ("units", "metres"),
    [
        ("km", 1000.0),
        ("kilometers", 1000.0),
        ("ft", 0.3048),
        ("feet", 0.3048),
        ("US_survey_foot", 1200.0 / 3937.0),
        ("Metres", 1.0),
        ("m", 1.0),
        ("meters above mean sea level", 1.0),
        ("km (WGS84)", 1000.0),
        ("", 1.0),
    ],
)
def test_elevation_units_are_converted_to_metres(tmp_path, units, metres):
    # units were ignored: a grid in km gave depths of 0.02..0.08 m, one in feet was read as metres
    lon, lat = np.linspace(-5.0, 5.0, 21), np.linspace(-3.0, 3.0, 13)
    z = _plane(lon, lat).T / metres
    path = _write_netcdf(tmp_path / "units.nc", lon, lat, z, attributes={"z": {"units": units}})
    np.testing.assert_allclose(read_dem(path).elevation, _plane(lon, lat), rtol=1e-6, atol=1e-5)
    depths = _write_netcdf(
        tmp_path / "depths.nc", lon, lat, -z, names=("lon", "lat", "depth"), attributes={"depth": {"units": units}}
    )
    np.testing.assert_allclose(read_dem(depths).elevation, _plane(lon, lat), rtol=1e-6, atol=1e-5)


def test_geotiff_band_units_are_converted_to_metres(tmp_path):
    lon, lat, z = _sea(-50.0, "f8")  # (lat, lon), south to north
    path = _write_geotiff(tmp_path / "feet.tif", (z / 0.3048)[::-1].astype("f4"), unit="ft")
    np.testing.assert_allclose(read_dem(path).elevation, z.T, rtol=1e-6)


@pytest.mark.parametrize("units", ["furlong", "degrees", "1"])
def test_an_unknown_elevation_unit_is_named(tmp_path, units):
    lon, lat = np.linspace(-5.0, 5.0, 21), np.linspace(-3.0, 3.0, 13)
    path = _write_netcdf(tmp_path / "odd.nc", lon, lat, _plane(lon, lat).T, attributes={"z": {"units": units}})
    with pytest.raises(MeshFormatError, match=rf"odd.nc variable 'z' has elevations in units '{units}', not a length"):
        read_dem(path)


@pytest.mark.parametrize(
    ("names", "units", "match"),
    [
        (("lon", "lat", "z"), {"lon": {"units": "radians"}}, r"coordinate 'lon' is in 'radians', not degrees"),
        (("x", "y", "z"), {"x": {"units": "km"}, "y": {"units": "km"}}, r"coordinate 'x' is in 'km', a projected grid"),
        (("lon", "lat", "z"), {"lat": {"units": "metres"}}, r"coordinate 'lat' is in 'metres', a projected grid"),
    ],
)
def test_coordinates_not_in_degrees_are_named(tmp_path, names, units, match):
    # values that fit degrees (0.17..0.21 radians, 10..12 km) were read as degrees, silently
    lon, lat = np.linspace(0.17, 0.21, 21), np.linspace(0.94, 0.97, 13)
    path = _write_netcdf(tmp_path / "grid.nc", lon, lat, np.zeros((13, 21)), names=names, attributes=units)
    with pytest.raises(GeometryError, match=match):
        read_dem(path)
    with pytest.raises(GeometryError, match=match):
        read_dem(path, (0.18, 0.2, 0.95, 0.96))


@pytest.mark.parametrize("band", ["x", 0, -1, 1.5, True, None])
def test_a_bad_band_is_named(tmp_path, band):
    # "x" was reported as "cannot read the GeoTIFF (truncated or corrupt?)"
    path = _write_geotiff(tmp_path / "dem.tif", np.zeros((20, 20), dtype="f4"))
    with pytest.raises(GeometryError, match=rf"band must be a positive integer .*, got {band!r}"):
        read_dem(path, band=band)
    with pytest.raises(MeshFormatError, match="has 1 band"):
        read_dem(path, band=2)
    assert read_dem(path, band=np.int64(1)).shape == (20, 20)


@pytest.mark.parametrize(("dem", "kind"), [(np.zeros((3, 3)), "ndarray"), (5, "int"), ([1.0, 2.0], "list")])
def test_a_dem_that_is_not_a_dem_or_a_path_is_named(shared_data, dem, kind):
    # an array or a number failed in os.fspath with "expected str, bytes or os.PathLike object"
    message = rf"dem must be a terramesh.coastal.DEM or a path to a NetCDF/GeoTIFF file, got {kind}$"
    with pytest.raises(GeometryError, match=message):
        read_dem(dem)
    import terramesh as tm

    with pytest.raises(GeometryError, match=message):
        tm.coastal.build(
            (9.6, 13.2, 54.4, 56.6), shared_data / "coast" / "GSHHS_l_L1.shp", dem, min_el=3000, max_el=20e3
        )


def _write_layout(path, coordinates, z_dims, dims):
    """A NetCDF file of the given coordinate variables (name: (dims, values)), then a plane z on ``z_dims``."""
    import netCDF4

    with netCDF4.Dataset(path, "w") as out:
        for name, size in dims.items():
            out.createDimension(name, size)
        for name, (var_dims, values, attributes) in coordinates.items():
            var = out.createVariable(name, "f8", var_dims)
            var[:] = values
            var.setncatts(attributes)
        lon, lat = np.linspace(-94.0, -93.8, 21), np.linspace(29.7, 29.9, 11)
        z = out.createVariable("z", "f4", z_dims)
        z[:] = np.broadcast_to(_plane(lon, lat).T, tuple(dims[d] for d in z_dims))
    return path


LON, LAT = np.linspace(-94.0, -93.8, 21), np.linspace(29.7, 29.9, 11)
DEGREES = {"lon": (("x",), LON, {"units": "degrees_east"}), "lat": (("y",), LAT, {"units": "degrees_north"})}


@pytest.mark.parametrize(
    ("coordinates", "dims"),
    [
        # a stray 1-D x(n) (stations) before lon(lon): taken as the longitudes, and the grid refused as (lat, n)
        (
            {
                "x": (("n",), np.arange(5.0), {}),
                "lon": (("lon",), LON, {}),
                "lat": (("lat",), LAT, {}),
            },
            {"n": 5, "lat": 11, "lon": 21},
        ),
        # index coordinates x, y beside lon(x), lat(y) in degrees: "latitudes 0..10 are outside -90..90"
        ({"x": (("x",), np.arange(21.0), {}), "y": (("y",), np.arange(11.0), {}), **DEGREES}, {"y": 11, "x": 21}),
        # the same in metres: "the coordinate 'x' is in 'm', a projected grid"
        (
            {"x": (("x",), 100.0 * np.arange(21), {"units": "m"}), "y": (("y",), 100.0 * np.arange(11), {"units": "m"})}
            | DEGREES,
            {"y": 11, "x": 21},
        ),
    ],
)
def test_longitude_and_latitude_are_preferred_to_x_and_y_on_the_grid(tmp_path, coordinates, dims):
    lat_dim, lon_dim = ("lat", "lon") if "lon" in dims else ("y", "x")
    path = _write_layout(tmp_path / "dem.nc", coordinates, (lat_dim, lon_dim), dims)
    dem = read_dem(path)
    assert dem.bbox == pytest.approx((-94.0, -93.8, 29.7, 29.9))
    assert np.allclose(dem.elevation, _plane(LON, LAT), atol=1e-4)


def test_a_variable_with_another_dimension_is_named(tmp_path):
    # "no 2-D elevation variable on the (lat, lon) grid", with z(time, lat, lon) there
    coordinates = {"lon": (("lon",), LON, {}), "lat": (("lat",), LAT, {})}
    path = _write_layout(tmp_path / "series.nc", coordinates, ("time", "lat", "lon"), {"time": 2, "lat": 11, "lon": 21})
    message = r"only ones with more dimensions \('z' has time of size 2\).*ncks -d time,0 series.nc out.nc"
    with pytest.raises(MeshFormatError, match=message):
        read_dem(path)
    with pytest.raises(MeshFormatError, match=message):
        read_dem(path, variable="z")
    one = _write_layout(tmp_path / "one.nc", coordinates, ("time", "lat", "lon"), {"time": 1, "lat": 11, "lon": 21})
    assert np.allclose(read_dem(one).elevation, _plane(LON, LAT), atol=1e-4)  # a dimension of size 1 is no choice


@pytest.mark.parametrize("index", [False, True])
def test_two_dimensional_longitudes_and_latitudes_are_named_curvilinear(tmp_path, index):
    # lon(y, x), lat(y, x): "no 1-D longitude and latitude", or with index x, y: "latitudes 0..10 outside -90..90"
    lon, lat = np.meshgrid(LON - LON.mean(), LAT - LAT.mean())
    turn = np.radians(10.0)  # a grid turned 10 degrees: no longitude is constant along a row
    lon, lat = (
        LON.mean() + lon * np.cos(turn) - lat * np.sin(turn),
        LAT.mean() + lon * np.sin(turn) + lat * np.cos(turn),
    )
    coordinates = {"lon": (("y", "x"), lon, {}), "lat": (("y", "x"), lat, {})}
    if index:
        coordinates |= {"x": (("x",), np.arange(21.0), {}), "y": (("y",), np.arange(11.0), {})}
    path = _write_layout(tmp_path / "curvilinear.nc", coordinates, ("y", "x"), {"y": 11, "x": 21})
    with pytest.raises(MeshFormatError, match=r"longitudes and latitudes are 2-D \(lon\(y, x\), lat\(y, x\)\): a "
                       "curvilinear grid, which terramesh does not read"):  # fmt: skip
        read_dem(path)


@pytest.mark.parametrize("beside", ["nothing", "an index", "gmt degrees", "transposed"])
def test_two_dimensional_longitudes_and_latitudes_of_a_regular_grid_are_read(tmp_path, beside):
    # GMT's x(x), y(y) in degrees without units beside auxiliary lon(y, x), lat(y, x) of the same values was
    # refused as a curvilinear grid (read before), and so were such 2-D lon, lat alone or beside an index
    lon, lat = np.meshgrid(LON, LAT)
    dims = ("y", "x")
    if beside == "transposed":  # lon(x, y), lat(x, y): the longitudes run along the first dimension
        lon, lat, dims = lon.T, lat.T, ("x", "y")
    coordinates = {"lon": (dims, lon, {}), "lat": (dims, lat, {"units": "degrees_north"})}
    if beside == "an index":
        coordinates |= {"x": (("x",), np.arange(21.0), {}), "y": (("y",), np.arange(11.0), {})}
    if beside == "gmt degrees":
        coordinates = {"x": (("x",), LON, {}), "y": (("y",), LAT, {})} | coordinates
    path = _write_layout(tmp_path / "dem.nc", coordinates, ("y", "x"), {"y": 11, "x": 21})
    dem = read_dem(path)
    assert dem.bbox == pytest.approx((-94.0, -93.8, 29.7, 29.9))
    assert np.allclose(dem.elevation, _plane(LON, LAT), atol=1e-4)


def test_a_cut_geotiff_is_named_with_gdals_own_words(tmp_path):
    # rasterio's "Read failed. See previous exception for details." was all the message said of where it broke
    z = np.linspace(-50.0, 20.0, 400 * 400, dtype=np.float32).reshape(400, 400)
    path = _write_geotiff(tmp_path / "dem.tif", z, step=0.005)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(MeshFormatError) as raised:
        read_dem(path)
    said = str(raised.value)
    assert "dem.tif (truncated or corrupt?): " in said and "See previous exception" not in said
    # GDAL's and libtiff's words (here "IReadBlock failed at X offset 0, Y offset 100: TIFFReadEncodedStrip() failed.;
    # TIFFReadEncodedStrip:Read error at scanline ...; got 7577 bytes, expected 8000")
    assert re.search(r"(?i)(read error|failed).*\d", said.split("(truncated or corrupt?): ")[1]), said
