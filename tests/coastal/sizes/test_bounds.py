"""Bounds on the size function: min_el, max_el, max_el_ns, per depth range and per polygon."""

import numpy as np
import pytest
import shapely

from terramesh.coastal import GeoGrid
from terramesh.coastal.sizes import NEARSHORE_WIDTH, bound_sizes, nearshore_mask, water_mask
from terramesh.errors import SizingError, TerrameshWarning

SIZES = np.array([[10.0, 5e3, np.inf], [300.0, 2e3, 800.0]])


def test_global_bounds_by_hand():
    sizes = SIZES.copy()
    bounded = bound_sizes(sizes, min_edge_length=50.0, max_edge_length=4e3)
    assert bounded.tolist() == [[50.0, 4e3, 4e3], [300.0, 2e3, 800.0]]
    assert np.array_equal(sizes, SIZES, equal_nan=True)  # not modified
    assert bound_sizes(sizes).tolist() == SIZES.tolist()  # nothing asked, nothing changed


def test_overwrite_sizes_clips_in_place():
    sizes = SIZES.copy()
    bounded = bound_sizes(sizes, min_edge_length=50.0, max_edge_length=4e3, overwrite_sizes=True)
    assert np.shares_memory(bounded, sizes)
    assert sizes.tolist() == [[50.0, 4e3, 4e3], [300.0, 2e3, 800.0]]
    listed = SIZES.tolist()  # a conversion: the caller's list stays as it was
    assert bound_sizes(listed, min_edge_length=50.0, overwrite_sizes=True)[0, 0] == 50.0
    assert listed[0][0] == 10.0


def test_nearshore_cap_applies_only_nearshore():
    nearshore = np.array([[True, True, True], [False, False, False]])
    bounded = bound_sizes(SIZES, max_edge_length_nearshore=1e3, nearshore=nearshore, max_edge_length=3e3)
    assert bounded.tolist() == [[10.0, 1e3, 1e3], [300.0, 2e3, 800.0]]


def test_depth_bounds_rows_in_order():
    depth = np.array([[5.0, 5.0, 50.0], [500.0, 500.0, -3.0]])
    rows = [
        (None, 1e3, 0.0, 10.0),  # shallow water: at most 1 km
        (400.0, np.nan, 100.0, np.inf),  # deep water: at least 400 m
        (20.0, 30.0, -np.inf, 0.0),  # land: 20 to 30 m
    ]
    bounded = bound_sizes(SIZES, depth=depth, depth_bounds=rows)
    assert bounded.tolist() == [[10.0, 1e3, np.inf], [400.0, 2e3, 30.0]]


def test_min_and_max_win_over_local_bounds():
    depth = np.zeros_like(SIZES)
    bounded = bound_sizes(SIZES, depth=depth, depth_bounds=[(1.0, 5.0, -1.0, 1.0)], min_edge_length=8.0)
    assert bounded.min() == 8.0 and bounded.max() == 8.0


def test_polygon_bounds_inside_the_polygon_only():
    grid = GeoGrid((0.0, 1.0, 0.0, 1.0), 10e3)
    sizes = np.full(grid.shape, 5e3)
    square = shapely.box(0.2, 0.2, 0.6, 0.6)
    bounded = bound_sizes(
        sizes, polygon_bounds=[(square, None, 1e3), (shapely.box(0.5, 0.5, 2, 2), 7e3, None)], grid=grid
    )
    inside = water_mask(grid, square)
    other = water_mask(grid, shapely.box(0.5, 0.5, 2, 2))
    assert np.all(bounded[inside & ~other] == 1e3)
    assert np.all(bounded[other] == 7e3)  # the later row wins where they overlap
    assert np.all(bounded[~inside & ~other] == 5e3)


@pytest.mark.parametrize(
    ("bbox", "polygon", "same_polygon"),
    [
        ((-70.0, -63.0, 39.0, 46.0), shapely.box(292, 41, 294, 43), shapely.box(-68, 41, -66, 43)),  # 0..360 given
        ((175.0, 185.0, -20.0, -14.0), shapely.box(-179, -17, -177, -15), shapely.box(181, -17, 183, -15)),
    ],
    ids=["polygon in 0..360, box in -180..180", "polygon in -180..180, box across the antimeridian"],
)
def test_polygon_bounds_in_the_other_longitude_convention(bbox, polygon, same_polygon):
    """Pinned: a Gulf of Maine polygon written in 0..360 capped nothing (the box is moved to -180..180)."""
    grid = GeoGrid(bbox, 20e3)
    inside = water_mask(grid, same_polygon)
    assert inside.sum() > 50
    np.testing.assert_array_equal(water_mask(grid, polygon), inside)
    bounded = bound_sizes(np.full(grid.shape, 50e3), polygon_bounds=[(polygon, None, 2500.0)], grid=grid)
    assert np.all(bounded[inside] == 2500.0) and np.all(bounded[~inside] == 50e3)


def test_a_polygon_bound_that_covers_no_node_is_warned_of():
    grid = GeoGrid((0.0, 1.0, 0.0, 1.0), 10e3)
    sizes = np.full(grid.shape, 5e3)
    elsewhere = shapely.box(10.0, 10.0, 11.0, 11.0)
    with pytest.warns(TerrameshWarning, match=r"polygon_bounds row 1 \(lon 10..11, lat 10..11\) covers no node"):
        bounded = bound_sizes(
            sizes, polygon_bounds=[(shapely.box(0, 0, 1, 1), 1e3, None), (elsewhere, None, 1e3)], grid=grid
        )
    np.testing.assert_array_equal(bounded, sizes)


def test_nearshore_mask_is_100_m_or_one_grid_step():
    assert NEARSHORE_WIDTH == 100.0
    fine = GeoGrid((0.0, 0.01, 0.0, 0.01), 20.0)
    distance = np.broadcast_to(np.linspace(0, 300, fine.shape[0])[:, None], fine.shape)
    assert np.array_equal(nearshore_mask(fine, distance), distance <= 100.0)
    coarse = GeoGrid((0.0, 0.5, 60.0, 60.5), 1e3)
    assert coarse.ground_step.min() > 980.0
    assert nearshore_mask(coarse, np.full(coarse.shape, 900.0)).all()  # widened to the ~1 km grid step
    assert not nearshore_mask(coarse, np.full(coarse.shape, 1200.0)).any()
    assert nearshore_mask(coarse, np.full(coarse.shape, 1200.0), width=1300.0).all()
    assert nearshore_mask(coarse, np.full(coarse.shape, np.inf)).sum() == 0


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"min_edge_length": 10.0, "max_edge_length": 5.0}, "exceeds"),
        ({"max_edge_length_nearshore": 100.0}, "nearshore mask"),
        ({"nearshore": np.ones((2, 3), bool)}, "without max_edge_length_nearshore"),
        ({"max_edge_length_nearshore": 5.0, "min_edge_length": 10.0, "nearshore": np.ones((2, 3), bool)}, "below"),
        ({"max_edge_length_nearshore": 50.0, "nearshore": np.ones((3, 2), bool)}, "shape"),
        ({"depth_bounds": [(1.0, 2.0, 0.0, 1.0)]}, "needs depth"),
        ({"depth_bounds": [(1.0, 2.0, 0.0)], "depth": np.zeros((2, 3))}, "row 0"),
        ({"depth_bounds": [(1.0, 2.0, 5.0, 1.0)], "depth": np.zeros((2, 3))}, "min_depth < max_depth"),
        ({"depth_bounds": [(3.0, 2.0, 0.0, 1.0)], "depth": np.zeros((2, 3))}, "exceeds"),
        ({"polygon_bounds": [(shapely.box(0, 0, 1, 1), 1.0, 2.0)]}, "needs the grid"),
        ({"min_edge_length": -1.0}, "min_edge_length"),
    ],
)
def test_bad_bounds(kwargs, match):
    with pytest.raises(SizingError, match=match):
        bound_sizes(SIZES, **kwargs)


def test_bad_sizes():
    with pytest.raises(SizingError, match="NaN"):
        bound_sizes(np.array([1.0, np.nan]))
    with pytest.raises(SizingError, match="positive"):
        bound_sizes(np.array([1.0, 0.0]))
