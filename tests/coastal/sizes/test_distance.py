"""Distance to the coastline, water mask, and the distance/feature size functions (guide eq. 2-4)."""

import numpy as np
import pytest
import shapely

from terramesh._kernels.raster import with_company
from terramesh.coastal import GeoGrid
from terramesh.coastal.projection import EARTH_RADIUS
from terramesh.coastal.sizes import (
    approximate_medial_axis,
    distance_size,
    distance_to_coastline,
    feature_size,
    polygon_mask,
    shoreline_size,
    water_mask,
)
from terramesh.coastal.sizes._common import ground_gradient_norm
from terramesh.coastal.sizes.distance import land_gap_steps
from terramesh.errors import GeometryError, SizingError, TerrameshWarning

# ---------------------------------------------------------------- water mask


def _star(centre, r_out, r_in, n, phase):
    angles = phase + np.pi * np.arange(2 * n) / n
    radii = np.where(np.arange(2 * n) % 2 == 0, r_out, r_in)
    return np.c_[centre[0] + radii * np.cos(angles), centre[1] + radii * np.sin(angles)]


POLYGONS = {
    "star with hole": shapely.Polygon(
        _star((10.3, 55.2), 0.9, 0.35, 7, 0.1), [_star((10.3, 55.2), 0.2, 0.1, 5, 0.3)[::-1]]
    ),
    "two parts": shapely.MultiPolygon(
        [shapely.Polygon(_star((9.7, 54.7), 0.4, 0.2, 4, 0.2)), shapely.box(10.9, 55.6, 11.43, 56.07)]
    ),
    "beyond the grid": shapely.Polygon([(8.0, 54.0), (12.5, 54.9), (10.1, 57.0)]),
}


@pytest.mark.parametrize("name", list(POLYGONS))
def test_water_mask_agrees_with_shapely(name):
    polygon = POLYGONS[name]
    grid = GeoGrid((9.0, 11.5, 54.3, 56.1), 3e3)
    lon, lat = grid.lonlat()
    expected = shapely.contains_xy(polygon, lon, lat)
    got = water_mask(grid, polygon)
    assert got.shape == grid.shape and got.dtype == bool
    # nodes within 1e-9 degrees of an edge may fall on either side
    on_edge = shapely.dwithin(polygon.boundary, shapely.points(lon, lat), 1e-9)
    assert np.array_equal(got[~on_edge], expected[~on_edge])
    assert 0 < got.sum() < got.size


def test_polygon_mask_of_empty_and_collections():
    grid = GeoGrid((0, 1, 0, 1), 20e3)
    assert not polygon_mask(grid, shapely.Polygon()).any()
    collection = shapely.GeometryCollection([shapely.box(0.2, 0.2, 0.6, 0.6)])
    assert np.array_equal(polygon_mask(grid, collection), polygon_mask(grid, shapely.box(0.2, 0.2, 0.6, 0.6)))


@pytest.mark.parametrize("bad", [shapely.LineString([(0, 0), (1, 1)]), [(0, 0), (1, 0), (1, 1)], None])
def test_polygon_mask_refuses_non_polygons(bad):
    with pytest.raises(GeometryError):
        polygon_mask(GeoGrid((0, 1, 0, 1), 20e3), bad)


# ---------------------------------------------------------------- distance


def _great_circle(lon0, lat0, lon1, lat1):
    lon0, lat0, lon1, lat1 = (np.radians(v) for v in (lon0, lat0, lon1, lat1))
    a = np.sin((lat1 - lat0) / 2) ** 2 + np.cos(lat0) * np.cos(lat1) * np.sin((lon1 - lon0) / 2) ** 2
    return 2 * EARTH_RADIUS * np.arcsin(np.sqrt(a))


@pytest.mark.parametrize("lat0", [0.0, 50.0])
def test_distance_to_a_straight_coast_is_exact(lat0):
    """A meridian coastline: the distance is the great-circle distance to the meridian."""
    grid = GeoGrid((0.0, 1.0, lat0, lat0 + 0.6), 2e3)
    coast = shapely.LineString([(0.3, lat0 - 5), (0.3, lat0 + 5)])
    d = distance_to_coastline(grid, coast)
    lon, lat = grid.lonlat()
    exact = EARTH_RADIUS * np.arcsin(np.abs(np.cos(np.radians(lat)) * np.sin(np.radians(lon - 0.3))))
    assert np.allclose(d, exact, rtol=1e-4, atol=1e-6)


def test_distance_to_a_circle():
    """Inside and outside a circle of radius r: | |x - c| - r |, exact near the coast, within a step elsewhere."""
    grid = GeoGrid((-0.5, 0.5, -0.5, 0.5), 1e3)
    radius = np.radians(0.2) * EARTH_RADIUS
    # a circle on the ground (r / cos(lat) wide in longitude), as a 1024-gon
    angle = np.linspace(0, 2 * np.pi, 1025)
    ring = np.c_[np.degrees(radius * np.cos(angle) / EARTH_RADIUS), np.degrees(radius * np.sin(angle) / EARTH_RADIUS)]
    d = distance_to_coastline(grid, shapely.Polygon(ring))
    lon, lat = grid.lonlat()
    exact = np.abs(_great_circle(lon, lat, 0.0, 0.0) - radius)
    error = np.abs(d - exact)
    near = exact < 2 * grid.step
    assert error[near].max() < 0.5  # the 1024-gon is within 0.12 m of the circle
    assert error.max() < 0.25 * grid.step  # worst near the centre, where every direction is nearly as close
    assert np.median(error) < 0.5


def test_coastline_just_outside_the_box_counts():
    grid = GeoGrid((0.0, 0.5, 0.0, 0.5), 2e3)
    coast = shapely.LineString([(-0.05, -1), (-0.05, 1)])
    d = distance_to_coastline(grid, coast)
    assert d[0, 0] == pytest.approx(np.radians(0.05) * EARTH_RADIUS, rel=1e-6)
    with pytest.warns(TerrameshWarning, match="does not reach"):
        far = distance_to_coastline(grid, coast, margin=0)
    assert np.isinf(far).all()


def test_polygon_coastlines_use_their_rings_only():
    """A land polygon wider than the grid: its rings, not the grid box, are the coastline."""
    grid = GeoGrid((0.0, 0.4, 0.0, 0.4), 2e3)
    land = shapely.box(-1.0, -1.0, 0.1, 1.0)  # coast along lon = 0.1, the rest far away
    d = distance_to_coastline(grid, land)
    lon, lat = grid.lonlat()
    exact = EARTH_RADIUS * np.arcsin(np.abs(np.cos(np.radians(lat)) * np.sin(np.radians(lon - 0.1))))
    assert np.allclose(d, exact, rtol=1e-4, atol=1e-6)


def test_distance_refuses_bad_input():
    grid = GeoGrid((0, 1, 0, 1), 20e3)
    with pytest.raises(GeometryError):
        distance_to_coastline(grid, [(0, 0), (1, 1)])
    with pytest.raises(SizingError, match="margin"):
        distance_to_coastline(grid, shapely.LineString([(0, 0), (1, 1)]), margin=-1)
    with pytest.raises(GeometryError, match="GeoGrid"):
        distance_to_coastline((0, 1, 0, 1), shapely.LineString([(0, 0), (1, 1)]))


def test_ground_gradient_kernel_matches_numpy():
    grid = GeoGrid((3.0, 3.5, 60.0, 60.3), 1e3)
    rng = np.random.default_rng(1)
    values = rng.normal(size=grid.shape)
    water = rng.random(grid.shape) < 0.5
    north = EARTH_RADIUS * np.radians(grid.lat)
    for signed in (False, True):
        f = np.where(water, -values, values) if signed else values
        east = np.gradient(f, axis=0) / grid.ground_step[None, :]  # uniform steps along a row
        padded_y = np.concatenate([f[:, :1], f, f[:, -1:]], axis=1)
        n = np.concatenate([north[:1], north, north[-1:]])
        gy = (padded_y[:, 2:] - padded_y[:, :-2]) / (n[2:] - n[:-2])[None, :]
        reference = np.hypot(east, gy)
        got = ground_gradient_norm(grid, values, water if signed else None)
        assert np.allclose(got, reference, rtol=1e-12, atol=0)


# ---------------------------------------------------------------- eq. 2


def test_distance_size_by_hand():
    # eq. 2: h0 + alpha_d d
    d = np.array([0.0, 1000.0, 1e4, np.inf])
    assert distance_size(d, min_edge_length=100.0, rate=0.15).tolist() == [100.0, 250.0, 1600.0, np.inf]
    assert d[1] == 1000.0


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"distance": [-1.0], "min_edge_length": 1.0, "rate": 0.1}, "non-negative"),
        ({"distance": [np.nan], "min_edge_length": 1.0, "rate": 0.1}, "NaN"),
        ({"distance": [1.0], "min_edge_length": 0.0, "rate": 0.1}, "min_edge_length"),
        ({"distance": [1.0], "min_edge_length": 1.0, "rate": -0.1}, "rate"),
    ],
)
def test_distance_size_refuses_bad_input(kwargs, match):
    distance = kwargs.pop("distance")
    with pytest.raises(SizingError, match=match):
        distance_size(distance, **kwargs)


# ---------------------------------------------------------------- eq. 3-4


def _channel(step=250.0, width_deg=0.1):
    grid = GeoGrid((0.0, 0.3, 0.0, 0.2), step)
    south, north = 0.1 - width_deg / 2, 0.1 + width_deg / 2
    banks = shapely.MultiLineString([[(-1, south), (1, south)], [(-1, north), (1, north)]])
    water = np.broadcast_to((grid.lat > south) & (grid.lat < north), grid.shape)
    width = np.radians(width_deg) * EARTH_RADIUS
    return grid, distance_to_coastline(grid, banks), water, width


def test_medial_axis_is_the_channel_centre_line():
    grid, d, water, width = _channel()
    axis = approximate_medial_axis(grid, d, water, min_edge_length=250.0)
    rows = np.unique(np.nonzero(axis)[1])
    centre = np.radians(0.1) * EARTH_RADIUS
    north = np.radians(grid.lat[rows]) * EARTH_RADIUS
    assert rows.size in (1, 2)
    assert np.all(np.abs(north - centre) <= grid.step)
    assert axis[:, rows].all()  # the whole length of the channel


def test_feature_size_across_a_channel_is_width_over_r():
    # eq. 4 with d + d_MA = W / 2 at every node across the channel: f = 2 (W / 2) / R = W / R
    grid, d, water, width = _channel()
    R = 3
    fs = feature_size(grid, d, water, min_edge_length=250.0, elements_per_feature=R)
    assert width / R == pytest.approx(3710.6, abs=0.1)
    inside = fs[water]
    # the discrete medial axis is within one step of the centre line, so W is within 2 steps
    assert np.all(np.abs(inside - width / R) <= 2 * grid.step / R + 1e-6)
    assert np.median(inside) == pytest.approx(width / R, rel=0.05)
    assert fs.shape == grid.shape and np.isfinite(fs).all()


def test_feature_size_scales_with_r():
    grid, d, water, _ = _channel(step=500.0)
    three = feature_size(grid, d, water, min_edge_length=500.0, elements_per_feature=3)
    six = feature_size(grid, d, water, min_edge_length=500.0, elements_per_feature=6)
    assert np.allclose(three, 2 * six)


def test_axis_company_and_land_gap_match_numpy():
    rng = np.random.default_rng(7)
    for nodes in [
        rng.random((23, 31)) < 0.3,
        rng.random((23, 31)) < 0.05,
        np.ones((2, 3), bool),
        rng.random((1, 9)) < 0.5,
    ]:
        count = np.array(
            [
                [nodes[max(i - 3, 0) : i + 4, max(j - 3, 0) : j + 4].sum() for j in range(nodes.shape[1])]
                for i in range(nodes.shape[0])
            ]
        )
        for company in (0, 1, 3, 8):
            assert np.array_equal(with_company(nodes, 3, company), nodes & (count > company))
    grids = [rng.random((23, 31)) < 0.7, np.ones((4, 5), bool), np.zeros((5, 4), bool), rng.random((1, 9)) < 0.5]
    for water in grids + [rng.random((9, 1)) < 0.5, np.asfortranarray(rng.random((6, 7)) < 0.5)]:
        for axis in (0, 1):
            lines = np.moveaxis(~water, axis, 0)
            gap = np.moveaxis(land_gap_steps(water, axis), axis, 0)
            for j in range(lines.shape[1]):
                land = np.flatnonzero(lines[:, j])
                for i in range(lines.shape[0]):
                    before = land[land <= i].max() if (land <= i).any() else -(2**29)
                    after = land[land >= i].min() if (land >= i).any() else 2**29
                    assert gap[i, j] == after - before


def _corner_case(shape):
    """Land with one convex corner (or four) on a 1 km grid, h0 = 1 km; the mainland's coast along lat 0.2."""
    if shape == "square island":
        land, corners = shapely.box(0.4, 0.4, 0.6, 0.6), [(0.4, 0.4), (0.6, 0.4), (0.4, 0.6), (0.6, 0.6)]
    else:  # a 60-degree headland from the mainland, its tip at (0.5, 0.6)
        half = 0.5 * np.tan(np.radians(30))
        land, corners = shapely.Polygon([(0.5 - half, 0.1), (0.5 + half, 0.1), (0.5, 0.6)]), [(0.5, 0.6)]
    land = shapely.union(land, shapely.box(-1, -1, 2, 0.2))
    grid = GeoGrid((0.0, 1.0, 0.0, 1.0), 1e3)
    lon, lat = grid.lonlat()
    corners = np.array(corners)
    to_corner = np.min(
        _great_circle(lon[..., None], lat[..., None], corners[:, 0], corners[:, 1]), axis=-1
    )  # metres, to the nearest corner
    to_mainland = np.radians(corners[:, 1].min() - 0.2) * EARTH_RADIUS
    return grid, distance_to_coastline(grid, land), ~water_mask(grid, land), to_corner, to_mainland


@pytest.mark.parametrize(("shape", "gap_over_r"), [("square island", 7421), ("headland", 14842)])
def test_convex_corners_do_not_shrink_the_feature_size(shape, gap_over_r):
    """Pinned: the medial axis ran into convex land corners and gave 138 m to 266 m (h0 = 1 km) at them."""
    grid, d, water, to_corner, to_mainland = _corner_case(shape)
    axis = approximate_medial_axis(grid, d, water, min_edge_length=1e3)
    assert not axis[to_corner < 3e3].any()
    assert not axis[~water].any()
    fs = feature_size(grid, d, water, min_edge_length=1e3)
    near = water & (to_corner < 3e3)
    # the narrowest water around a corner is the gap to the mainland: at least that over R
    assert to_mainland / 3 == pytest.approx(gap_over_r, abs=1)
    assert fs[near].min() >= 0.9 * gap_over_r


def test_an_island_alone_in_open_water_has_no_medial_axis():
    """Pinned: its four corners put 12 nodes on the axis (feature size 138 m at them, h0 = 1 km)."""
    grid = GeoGrid((0.0, 1.0, 0.0, 1.0), 1e3)
    island = shapely.box(0.4, 0.4, 0.6, 0.6)
    d, water = distance_to_coastline(grid, island), ~water_mask(grid, island)
    assert not approximate_medial_axis(grid, d, water, min_edge_length=1e3).any()
    with pytest.warns(TerrameshWarning, match="medial axis"):
        fs = feature_size(grid, d, water, min_edge_length=1e3)
    np.testing.assert_array_equal(fs, distance_size(d, min_edge_length=1e3, rate=0.2))  # OceanMesh2D's fallback


@pytest.mark.parametrize("angle", [0.0, 30.0, 45.0])
@pytest.mark.parametrize("width_in_h0", [0.8, 1.2, 1.5, 2.5])
def test_channels_narrower_than_2_h0_keep_their_axis(width_in_h0, angle):
    """Near the coast (d <= h0 / 2) only narrow water keeps axis nodes: these channels have no others."""
    h0 = 1e3
    grid = GeoGrid((0.0, 0.3, 0.0, 0.3), h0)
    width = width_in_h0 * h0
    along = np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))])
    across = np.array([-along[1], along[0]]) * np.degrees(width / EARTH_RADIUS) / 2
    centre = np.array([0.15, 0.1537])  # off the nodes
    banks = [np.array([centre + side * across - 2 * along, centre + side * across + 2 * along]) for side in (-1, 1)]
    channel = shapely.Polygon(np.r_[banks[0], banks[1][::-1]])
    d, water = distance_to_coastline(grid, shapely.MultiLineString(banks)), water_mask(grid, channel)
    fs = feature_size(grid, d, water, min_edge_length=h0)[3:-3, 3:-3]  # the channel's ends are cut by the box
    # as for a wide channel, within two steps of W / R; narrower is the coarse grid's doing and h0 bounds it
    assert fs[water[3:-3, 3:-3]].max() <= (width + 2 * grid.step) / 3


def test_a_straight_coast_falls_back_to_the_distance_function():
    """Pinned: with no medial axis the feature size was inf everywhere, the coast left unresolved.

    OceanMesh2D's featfx falls back to ``h0 + g |d|`` there ("No medial points, resorting to distance function").
    """
    grid = GeoGrid((0.0, 0.3, 0.0, 0.3), 1e3)
    d = distance_to_coastline(grid, shapely.LineString([(0.1, -1), (0.1, 1)]))
    lon, _ = grid.lonlat()
    with pytest.warns(TerrameshWarning, match=r"no node is on the approximate medial axis .* h0 \+ 0.3 d \(eq. 2\)"):
        fs = feature_size(grid, d, lon > 0.1, min_edge_length=1e3, fallback_rate=0.3)
    np.testing.assert_allclose(fs, 1e3 + 0.3 * d)
    assert fs[np.abs(lon - 0.1) < 0.01].max() < 1.5e3  # the coast resolved at about h0


def test_feature_size_refuses_bad_input():
    grid, d, water, _ = _channel(step=1e3)
    with pytest.raises(SizingError, match="boolean"):
        feature_size(grid, d, water.astype(int), min_edge_length=1e3)
    with pytest.raises(SizingError, match="shape"):
        feature_size(grid, d[1:], water, min_edge_length=1e3)
    with pytest.raises(SizingError, match="inf"):
        feature_size(grid, np.full(grid.shape, np.inf), water, min_edge_length=1e3)
    with pytest.raises(SizingError, match="elements_per_feature"):
        feature_size(grid, d, water, min_edge_length=1e3, elements_per_feature=0)


def test_dis_and_fs_are_mutually_exclusive():
    grid, d, water, _ = _channel(step=1e3)
    with pytest.raises(SizingError, match="mutually exclusive"):
        shoreline_size(grid, d, water, min_edge_length=1e3, rate=0.1, elements_per_feature=3)
    with pytest.raises(SizingError, match="mutually exclusive"):
        shoreline_size(grid, d, water, min_edge_length=1e3)
    with pytest.raises(SizingError, match="water"):
        shoreline_size(grid, d, min_edge_length=1e3, elements_per_feature=3)
    assert np.array_equal(
        shoreline_size(grid, d, min_edge_length=1e3, rate=0.1), distance_size(d, min_edge_length=1e3, rate=0.1)
    )
    assert np.array_equal(
        shoreline_size(grid, d, water, min_edge_length=1e3, elements_per_feature=3),
        feature_size(grid, d, water, min_edge_length=1e3),
    )
