"""Channel size function (guide §3.4), the thalweg reader and the channel finder."""

import numpy as np
import pytest
import scipy.io

from terramesh.coastal import GeoGrid
from terramesh.coastal.sizes import channel_size, find_channels, read_thalwegs, slope_size
from terramesh.errors import GeometryError, SizingError, TerrameshWarning


def test_read_thalwegs_on_the_ecgc_network(shared_data):
    lines = read_thalwegs(shared_data / "channels" / "ECGC_Thalwegs.mat")
    assert len(lines) == 4050
    points = np.concatenate(lines)
    # 521,398 rows in the file: 517,348 points and one NaN row closing each of the 4,050 polylines
    assert len(points) == 517_348 == 521_398 - 4050
    assert np.isfinite(points).all() and all(line.shape[1] == 2 for line in lines)
    assert points[:, 0].min() > -98.0 and points[:, 0].max() < -60.0  # US East and Gulf coasts, lon first
    assert points[:, 1].min() > 24.0 and points[:, 1].max() < 46.0


def test_read_thalwegs_splits_at_nan_rows(tmp_path):
    cells = np.empty((1, 2), dtype=object)
    cells[0, 0] = np.array([[0.0, 0.0], [1.0, 1.0], [np.nan, np.nan], [2.0, 2.0], [np.nan, np.nan]])
    cells[0, 1] = np.zeros((0, 2))
    scipy.io.savemat(tmp_path / "t.mat", {"pts2": cells})
    lines = read_thalwegs(tmp_path / "t.mat")
    assert [line.tolist() for line in lines] == [[[0.0, 0.0], [1.0, 1.0]], [[2.0, 2.0]]]


def test_read_thalwegs_refuses_other_files(tmp_path):
    scipy.io.savemat(tmp_path / "other.mat", {"x": np.ones(3)})
    with pytest.raises(GeometryError, match="pts2"):
        read_thalwegs(tmp_path / "other.mat")
    (tmp_path / "junk.mat").write_bytes(b"not a mat file at all" * 20)
    with pytest.raises(GeometryError):
        read_thalwegs(tmp_path / "junk.mat")
    cells = np.empty((1, 2), dtype=object)
    cells[0, 0], cells[0, 1] = np.array([[0.0, 0.0], [1.0, 1.0]]), "a note"  # numpy's ValueError came out
    scipy.io.savemat(tmp_path / "text.mat", {"pts2": cells})
    with pytest.raises(GeometryError, match="channel polyline 2 of pts2 is not numbers"):
        read_thalwegs(tmp_path / "text.mat")


# ---------------------------------------------------------------- a synthetic V-shaped valley


# banks at 60 degrees from the vertical, the guide's V profile: 30 degrees from the horizontal
BANK_SLOPE = np.tan(np.radians(30.0))


def _valley(bank_slope=BANK_SLOPE, floor=300.0, axis=30):
    """A valley along a meridian: depth `floor` at column `axis`, rising `bank_slope` per ground metre."""
    grid = GeoGrid((0.0, 0.06, 0.0, 0.05), 100.0)
    east = grid.ground_step[None, :] * (np.arange(grid.shape[0])[:, None] - axis)
    return grid, floor - bank_slope * np.abs(east)


def test_find_channels_finds_the_valley_axis():
    grid, depth = _valley()
    found = find_channels(grid, depth)
    columns, rows = np.nonzero(found)
    assert set(columns.tolist()) == {30}
    assert set(rows.tolist()) == set(range(1, grid.shape[1] - 1))  # not on the border


def test_find_channels_ignores_planes_noise_and_gentle_valleys():
    grid, depth = _valley()
    ix, iy = np.meshgrid(np.arange(grid.shape[0]), np.arange(grid.shape[1]), indexing="ij")
    assert not find_channels(grid, 50.0 + 0.3 * ix - 0.2 * iy).any()
    noise = np.random.default_rng(5).normal(scale=0.1, size=grid.shape)  # 0.1 m over 100 m: slope ~0.001
    assert not find_channels(grid, 50.0 + noise).any()
    _, gentle = _valley(bank_slope=0.01)
    assert not find_channels(grid, gentle).any()
    assert find_channels(grid, gentle, min_bank_slope=0.005).any()


def test_find_channels_in_a_diagonal_valley():
    grid = GeoGrid((0.0, 0.05, 0.0, 0.05), 100.0)
    ix, iy = np.meshgrid(np.arange(grid.shape[0]), np.arange(grid.shape[1]), indexing="ij")
    depth = 200.0 - 0.2 * 100.0 * np.abs(ix - iy) / np.sqrt(2)
    found = find_channels(grid, depth)
    axis = (ix == iy) & (ix > 0) & (ix < grid.shape[0] - 1)
    assert found[axis].all()
    assert np.all(np.abs(ix[found] - iy[found]) <= 1)  # within one node of the axis


def test_channel_size_on_a_v_valley_by_hand():
    """60-degree banks at 300 m depth: circles of radius tan(60) 300 = 519.6 m around the thalweg."""
    grid, depth = _valley()
    slope = np.broadcast_to(1000.0 + 10.0 * np.arange(grid.shape[0])[:, None], grid.shape)  # known field
    thalweg = np.c_[np.full(20, grid.lon[30]), np.linspace(grid.lat[5], grid.lat[-6], 20)]
    radius = np.tan(np.radians(60.0)) * 300.0
    assert radius == pytest.approx(519.615, abs=1e-3)
    # percentile 50 of a field linear across a circle centred on column 30: the value there, 1300
    median = channel_size(grid, depth, slope, percentile=50, thalwegs=[thalweg])
    reach = int(radius // grid.ground_step.max())  # 5 columns each side are inside the circles
    assert reach == 5
    assert set(np.unique(median[np.isfinite(median)]).tolist()) == {1300.0}
    columns = np.unique(np.nonzero(np.isfinite(median))[0])
    assert columns.tolist() == list(range(30 - reach, 30 + reach + 1))
    # percentile 0: the smallest slope size in a circle, 5 columns west of the axis
    smallest = channel_size(grid, depth, slope, percentile=0, thalwegs=[thalweg])
    assert set(np.unique(smallest[np.isfinite(smallest)]).tolist()) == {1000.0 + 10.0 * 25}
    # rows covered: the thalweg's extent plus a radius each side
    rows = np.unique(np.nonzero(np.isfinite(median))[1])
    assert rows.min() == 5 - reach and rows.max() == grid.shape[1] - 6 + reach


def test_overland_channels_are_resolved():
    """A valley on land (a floodplain mesh's domain) and one under water, fed by the slope function on land too."""
    grid = GeoGrid((0, 0.2, 0, 0.2), 200.0)
    lon, lat = grid.lonlat()
    east = (lon - 0.1) * 111e3
    depth = np.where(lat < 0.05, 30 + 200 * (0.05 - lat), -(2 + 0.003 * np.abs(east)))  # land below 50 m
    slope = slope_size(grid, depth, elements_per_slope=30, min_depth=None, filter_lengths=(0, 0))
    land = lat >= 0.05
    assert np.isfinite(slope[land]).all()
    # on land eq. 7 takes |h|: 2 pi / 30 * |h| / 0.003 in the valley's banks, away from its axis and the shore
    bank = land & (np.abs(east) > 1000) & (lat > 0.07)
    expected = 2 * np.pi / 30 * np.abs(depth[bank]) / 0.003
    assert np.allclose(slope[bank], expected, rtol=0.02)
    overland = [np.array([[0.1, 0.06], [0.1, 0.19]])]
    sizes = channel_size(grid, depth, slope, percentile=50, thalwegs=overland)
    # circles of radius tan(60) |h| around the thalweg (2 m deep: 3.5 m, the nearest node): every row it spans
    refined = np.isfinite(sizes)
    assert refined.sum() >= 70 and np.all(lat[refined] >= 0.05)
    # with the slope function off on land, as before, the overland channel got nothing
    water_only = slope_size(grid, depth, elements_per_slope=30, min_depth=0, filter_lengths=(0, 0))
    assert not np.isfinite(channel_size(grid, depth, water_only, percentile=50, thalwegs=overland)).any()
    assert np.array_equal(slope[~land], water_only[~land])  # in water (30 m and deeper) eq. 7 is unchanged


def test_channel_size_matches_a_numpy_reference():
    rng = np.random.default_rng(11)
    grid = GeoGrid((0.0, 0.04, 0.0, 0.03), 100.0)
    depth = rng.uniform(-50, 400, grid.shape)
    slope = rng.uniform(200, 5000, grid.shape)
    slope[rng.random(grid.shape) < 0.1] = np.inf
    nodes = np.zeros(grid.shape, dtype=bool)
    nodes[rng.integers(0, grid.shape[0], 15), rng.integers(0, grid.shape[1], 15)] = True
    got = channel_size(grid, depth, slope, percentile=30, thalwegs=nodes)
    expected = np.full(grid.shape, np.inf)
    ix_all, iy_all = np.meshgrid(np.arange(grid.shape[0]), np.arange(grid.shape[1]), indexing="ij")
    for ix, iy in zip(*np.nonzero(nodes), strict=True):
        radius = np.tan(np.radians(60)) * abs(depth[ix, iy])
        scale = grid.ground_step[iy] / grid.step
        ground = np.hypot((grid.x[ix_all] - grid.x[ix]) * scale, (grid.y[iy_all] - grid.y[iy]) * scale)
        circle = (ground <= radius) & (np.abs(ix_all - ix) <= 100) & (np.abs(iy_all - iy) <= 100)
        circle[ix, iy] = True
        values = slope[circle][np.isfinite(slope[circle])]
        if values.size:
            expected[circle] = np.minimum(expected[circle], np.percentile(values, 30))
    assert np.allclose(got, expected, rtol=1e-12)


def test_channel_size_defaults_to_the_finder():
    grid, depth = _valley()
    slope = np.full(grid.shape, 800.0)
    assert np.array_equal(
        channel_size(grid, depth, slope, percentile=10),
        channel_size(grid, depth, slope, percentile=10, thalwegs=find_channels(grid, depth)),
    )


def test_channel_size_on_the_ecgc_thalwegs(shared_data):
    lines = read_thalwegs(shared_data / "channels" / "ECGC_Thalwegs.mat")
    grid = GeoGrid((-74.3, -73.7, 40.3, 40.8), 500.0)  # New York Harbor
    depth = np.full(grid.shape, 20.0)
    slope = np.full(grid.shape, 700.0)
    sizes = channel_size(grid, depth, slope, percentile=10, thalwegs=lines)
    assert 0 < np.isfinite(sizes).sum() < sizes.size
    assert set(np.unique(sizes[np.isfinite(sizes)]).tolist()) == {700.0}


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"percentile": 101}, SizingError, "percentile"),
        ({"percentile": -1}, SizingError, "percentile"),
        ({"percentile": "10"}, SizingError, "percentile"),
        ({"percentile": 10, "angle_of_repose": 90}, SizingError, "90"),
        ({"percentile": 10, "thalwegs": [np.zeros((3, 3))]}, GeometryError, r"\(k, 2\)"),
        ({"percentile": 10, "thalwegs": [np.array([[0.0, np.nan]])]}, GeometryError, "non-finite"),
        ({"percentile": 10, "thalwegs": np.zeros((3, 3), dtype=bool)}, SizingError, "shape"),
    ],
)
def test_channel_size_refuses_bad_input(kwargs, error, match):
    grid, depth = _valley()
    with pytest.raises(error, match=match):
        channel_size(grid, depth, np.full(grid.shape, 800.0), **kwargs)


def test_channel_size_refuses_non_positive_slope_sizes():
    grid, depth = _valley()
    with pytest.raises(SizingError, match="positive"):
        channel_size(grid, depth, np.zeros(grid.shape), percentile=10)


# ---------------------------------------------------------------- thalweg inputs (review 2, item 4)


def _harbour():
    """New York Harbor at 500 m, uniform depth and slope sizes, and one thalweg across it (lon, lat)."""
    grid = GeoGrid((-74.3, -73.7, 40.3, 40.8), 500.0)
    line = np.array([[-74.2, 40.4], [-74.0, 40.6], [-73.8, 40.7]])
    return grid, np.full(grid.shape, 20.0), np.full(grid.shape, 700.0), line


def test_channel_size_takes_a_path_and_shapely_lines(tmp_path):
    """A .mat path gave "could not convert string to float: '/'"; shapely lines gave raw TypeErrors."""
    shapely = pytest.importorskip("shapely")
    grid, depth, slope, line = _harbour()
    other = line[:2] + [0.05, -0.02]
    expected = channel_size(grid, depth, slope, percentile=10, thalwegs=[line, other])
    assert 0 < np.isfinite(expected).sum() < expected.size
    cells = np.empty((1, 2), dtype=object)
    cells[0, 0] = np.vstack([line, [np.nan, np.nan]])
    cells[0, 1] = np.vstack([other, [np.nan, np.nan]])
    scipy.io.savemat(tmp_path / "thalwegs.mat", {"pts2": cells})
    objects = np.empty((1, 2), dtype=object)
    objects[0, 0], objects[0, 1] = line, other
    inputs = [
        tmp_path / "thalwegs.mat",  # as OceanMesh2D users pass it
        str(tmp_path / "thalwegs.mat"),
        shapely.MultiLineString([line, other]),
        [shapely.LineString(line), shapely.LineString(other)],
        (shapely.LineString(line), other),
        [shapely.MultiLineString([line]), shapely.LineString(np.c_[other, np.zeros(2)])],  # z is dropped
        objects,  # polylines in an object array, as loadmat's cells (without their NaN rows)
    ]
    for thalwegs in inputs:
        got = channel_size(grid, depth, slope, percentile=10, thalwegs=thalwegs)
        np.testing.assert_array_equal(got, expected)
    one = channel_size(grid, depth, slope, percentile=10, thalwegs=line)
    np.testing.assert_array_equal(
        one, channel_size(grid, depth, slope, percentile=10, thalwegs=shapely.LineString(line))
    )
    with pytest.raises(GeometryError, match="cannot read thalwegs"):
        channel_size(grid, depth, slope, percentile=10, thalwegs=tmp_path / "missing.mat")


@pytest.mark.parametrize(
    ("bbox", "line", "same_line"),
    [
        ((-70.0, -69.0, 41.0, 42.0), [[290.2, 41.2], [290.8, 41.8]], [[-69.8, 41.2], [-69.2, 41.8]]),
        ((179.5, 180.5, -17.0, -16.0), [[179.6, -16.8], [-179.6, -16.2]], [[179.6, -16.8], [180.4, -16.2]]),
    ],
    ids=["thalweg in 0..360, box in -180..180", "thalweg across the antimeridian in -180..180"],
)
def test_thalwegs_in_the_other_longitude_convention(bbox, line, same_line):
    """Pinned: thalwegs in 0..360 for a box in -180..180 were dropped, "no thalweg in the box" (they were in it)."""
    grid = GeoGrid(bbox, 1000.0)
    depth, slope = np.full(grid.shape, 20.0), np.full(grid.shape, 700.0)
    expected = channel_size(grid, depth, slope, percentile=10, thalwegs=np.array(same_line))
    assert np.isfinite(expected).sum() > 50
    np.testing.assert_array_equal(channel_size(grid, depth, slope, percentile=10, thalwegs=np.array(line)), expected)


@pytest.mark.parametrize(
    ("thalwegs", "match"),
    [
        (5, "got int"),
        ({"pts2": []}, "got dict"),
        (["a.mat", "b.mat"], "item 0 of the list is a str"),
        ([np.zeros((2, 2)), "oops"], "item 1 of the list is a str"),
        (np.array(["a.mat"]), "dtype <U5"),
    ],
)
def test_channel_size_refuses_other_thalweg_inputs_by_name(thalwegs, match):
    grid, depth, slope, _ = _harbour()
    with pytest.raises(SizingError, match=rf"thalwegs must be a path to a \.mat file.*shapely LineString.*{match}"):
        channel_size(grid, depth, slope, percentile=10, thalwegs=thalwegs)
    with pytest.raises(GeometryError, match=r"\(k, 2\).*shape \(4,\)"):
        channel_size(grid, depth, slope, percentile=10, thalwegs=np.zeros(4))


def test_channel_size_warns_when_no_thalweg_is_in_the_box():
    """Thalwegs in lat/lon order were taken silently, and the channel function refined nothing."""
    grid, depth, slope, line = _harbour()
    with pytest.warns(
        TerrameshWarning, match=r"no thalweg in the box.*lon/lat order\? With the two columns swapped, 3"
    ):
        swapped = channel_size(grid, depth, slope, percentile=10, thalwegs=[line[:, ::-1]])
    assert not np.isfinite(swapped).any()
    with pytest.warns(TerrameshWarning, match=r"no thalweg in the box \(lon -74.3\.\..*3 thalweg points span lon -69"):
        channel_size(grid, depth, slope, percentile=10, thalwegs=[line + [5.0, 0.0]])
    with pytest.warns(TerrameshWarning, match="thalwegs is empty"):
        channel_size(grid, depth, slope, percentile=10, thalwegs=[])
    # a thalweg in the box, or a mask of channel nodes: no warning (warnings are errors in the tests)
    assert np.isfinite(channel_size(grid, depth, slope, percentile=10, thalwegs=[line])).any()
    channel_size(grid, depth, slope, percentile=10, thalwegs=np.zeros(grid.shape, dtype=bool))
    # the finder finding nothing (a flat bottom): ch did nothing without a word
    with pytest.warns(TerrameshWarning, match=r"the channel function \(ch\) found no channel in the DEM"):
        assert not np.isfinite(channel_size(grid, depth, slope, percentile=10)).any()
