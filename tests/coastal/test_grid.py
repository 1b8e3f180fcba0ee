"""The Mercator grid coastal size functions live on."""

import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from terramesh.coastal import GeoGrid, as_lonlat_box, from_mercator, scale_factor, to_mercator
from terramesh.errors import GeometryError, SizingError, TerrameshWarning


@given(st.floats(-180, 180), st.floats(-85, 85))
def test_mercator_round_trip(lon, lat):
    back = from_mercator(*to_mercator(lon, lat))
    assert np.allclose(back, (lon, lat), rtol=0, atol=1e-9)


def test_mercator_is_conformal():
    """A small step east and the same ground step north have equal Mercator lengths."""
    lat, step = 52.0, 1e-4
    x0, _ = to_mercator(10.0, lat)
    x1, _ = to_mercator(10.0 + step / np.cos(np.radians(lat)), lat)
    _, (y0, y1) = to_mercator(10.0, [lat - step / 2, lat + step / 2])
    assert (x1 - x0) == pytest.approx(y1 - y0, rel=1e-6)
    assert (x1 - x0) / (6378137.0 * np.radians(step)) == pytest.approx(scale_factor(lat), rel=1e-6)


@pytest.mark.parametrize("bbox", [(166, 176, -48, -40), (-100, -50, 10, 60), (-5, 5, -3, 2)])
def test_grid_ground_spacing_is_at_most_requested(bbox):
    grid = GeoGrid(bbox, 5000.0)
    assert grid.ground_step.max() <= 5000.0 * (1 + 1e-12)
    assert grid.ground_step.max() > 0.99 * 5000.0
    lon_min, lon_max, lat_min, lat_max = bbox
    assert grid.lon[0] == pytest.approx(lon_min) and grid.lon[-1] >= lon_max - 1e-9
    assert grid.lat[0] == pytest.approx(lat_min) and grid.lat[-1] >= lat_max - 1e-9


def test_size_grid_scales_rows_by_latitude():
    grid = GeoGrid((0, 10, 0, 60), 20e3)
    size = grid.size_grid(np.full(grid.shape, 1000.0))
    assert size.values[:, 0] == pytest.approx(1000.0 / np.cos(np.radians(grid.lat[0])))
    assert size.values[:, -1] == pytest.approx(1000.0 / np.cos(np.radians(grid.lat[-1])))


def test_bbox_in_0_360_is_shifted():
    assert as_lonlat_box((260, 310, 10, 60)) == (-100.0, -50.0, 10.0, 60.0)


@pytest.mark.parametrize(
    ("bbox", "message"),
    [
        ((10, 0, 0, 1), r"min < max, got \(10, 0, 0, 1\) \(the guide's order: longitudes first\)$"),
        # the command line said how a box across 180 degrees is written; the API said only "min < max"
        ((178, -178, -20, -15), r"; a box across the antimeridian is written with longitudes past 180: \(178, 182,"),
        ((10, -10, 0, 1), r"longitudes first\)$"),  # 20 degrees the wrong way round, not 340 across 180
        ((0, 1, 100, 120), "outside -90..90"),
        ((0, 1, 2), "lon_min, lon_max"),
        ((0, np.nan, 0, 1), "non-finite"),
        ((-10, 200, 0, 1), "not within -180..180 or 0..360$"),
        ((-185, -175, -20, -15), r"0..360; a box across the antimeridian is written in 0..360 \(175, 185, ...\)"),
    ],
)
def test_bad_bbox_is_named(bbox, message):
    with pytest.raises(GeometryError, match=message):
        as_lonlat_box(bbox)


def test_grid_too_large_asks_for_coarser_spacing():
    with pytest.raises(SizingError, match="larger minimum edge length"):
        GeoGrid((-179, 179, -80, 80), 10.0)


def test_polar_box_is_refused():
    with pytest.raises(GeometryError, match="Mercator"):
        GeoGrid((0, 10, 80, 89), 1000.0)


@pytest.mark.parametrize("lat_max", [84.99, 85.0])
def test_a_box_ending_near_85_degrees_ends_its_grid_there(lat_max):
    """Pinned: (80, 84.99) at 5 km raised "latitude 85.0009 is beyond +-85 degrees" (the last row overshot)."""
    grid = GeoGrid((-70, -60, 80, lat_max), 5000.0)
    assert grid.lat[-1] == lat_max and grid.lat[0] == pytest.approx(80.0)
    assert grid.ground_step.max() <= 5000.0 and grid.ground_step.max() > 0.99 * 5000.0
    np.testing.assert_allclose(np.diff(grid.y), grid.step)
    assert grid.lon[-1] >= -60.0 - 1e-9


@pytest.mark.parametrize("bbox", [(-180, 180, -10, 10), (0, 360, -10, 10)])
def test_a_box_all_the_way_round_is_refused(bbox):
    """Pinned: accepted, but distances did not wrap (40,009 km from -179.9 to an island ending at 179.9)."""
    with pytest.raises(GeometryError, match=r"go all the way round: the Mercator grid does not wrap"):
        GeoGrid(bbox, 10000.0)


def test_a_bbox_in_shapelys_order_warns():
    # (-71, 42, -66, 45) for the Gulf of Maine meshed longitudes -71..42 and latitudes -66..45, without a word
    with pytest.warns(
        TerrameshWarning, match=r"if it is in shapely's order .* a box of 15 square degrees, give \(-71, -66, 42, 45\)"
    ):
        assert as_lonlat_box((-71, 42, -66, 45)) == (-71.0, 42.0, -66.0, 45.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for box in [(-71, -66, 42, 45), (-100, -50, 10, 50), (-180, 180, -90, 90), (35, 45, 36, 46)]:
            as_lonlat_box(box)
