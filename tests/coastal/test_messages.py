"""Places in a coastal build's messages told in longitude, latitude instead of Mercator metres."""

import sys

import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh.coastal import to_mercator
from terramesh.coastal.messages import in_lonlat
from terramesh.errors import GenerationError, TerrameshWarning


def test_points_and_places_along_an_axis_become_degrees():
    x, y = to_mercator(np.array([-76.37, 10.5]), np.array([38.88, 55.25]))
    x, y = x.tolist(), y.tolist()  # a list's text, as error messages show points: [1168854.65..., 7410537.97...]
    text = f"near ({x[0]:.9g}, {y[0]:.9g}); e.g. {[x[1], y[1]]}; strip (y {y[0]:.9g} to {y[1]:.9g}); x = {x[1]:.9g}"
    assert in_lonlat(text) == (
        "near (-76.37, 38.88) (lon, lat); e.g. [10.5, 55.25] (lon, lat); strip (lat 38.88 to 55.25); lon = 10.5"
    )
    # a shape, a count or a pair of whole numbers is no point on the plane
    assert in_lonlat("points of shape (k, 2), 3 of (3, 2) rows") == "points of shape (k, 2), 3 of (3, 2) rows"


def test_a_coastal_builds_errors_and_warnings_are_told_in_degrees(monkeypatch):
    # the generator and the clean-up run on the Mercator plane: "cells overlap ... near (-8.50125e+06,
    # 4.705e+06)" was the upper Chesapeake, and strips were placed by Mercator northings
    build_module = sys.modules["terramesh.coastal.build"]
    x, y = to_mercator(np.array([0.1, 0.1]), np.array([0.2, 0.4]))

    def failing(*args, **kwargs):
        tm.errors.warn_user(f"a strip (y {y[0]:.9g} to {y[1]:.9g}) is narrow")
        raise GenerationError(f"an invalid mesh (one cell at ({x[0]:.9g}, {y[0]:.9g}))")

    monkeypatch.setattr(build_module, "generate_mesh", failing)
    land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    with (
        pytest.warns(TerrameshWarning, match=r"a strip \(lat 0.2 to 0.4\) is narrow"),
        pytest.raises(GenerationError, match=r"one cell at \(0.1, 0.2\) \(lon, lat\)"),
    ):
        tm.coastal.build((0, 0.3, 0, 0.3), land, min_el=2000, max_el=6000, dis=0.3, g=0.3)


def test_multiscale_tells_its_places_in_degrees_too(monkeypatch):
    multiscale = sys.modules["terramesh.coastal.multiscale"]
    x, y = to_mercator(np.array([0.1]), np.array([0.2]))

    def failing(*args, **kwargs):
        raise GenerationError(f"an invalid mesh (one cell at ({x[0]:.9g}, {y[0]:.9g}))")

    monkeypatch.setattr(multiscale, "generate_mesh", failing)
    land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    boxes = [{"bbox": (0, 0.3, 0, 0.3), "min_el": 2500, "max_el": 6000, "dis": 0.3, "g": 0.3}]
    with pytest.raises(GenerationError, match=r"one cell at \(0.1, 0.2\) \(lon, lat\)"):
        tm.coastal.build_multiscale(boxes, land)


def test_counts_and_shapes_are_left_alone_and_whole_metres_converted():
    # "a 16 x 16 grid" became "a 16 lon 0.00014373 grid"; whole-metre points 1-9 degrees from (0, 0) stayed metres
    text = "4 blocks of a 16 x 16 grid, 256 x 256 samples, points of shape (k, 2) and (3, 2)"
    assert in_lonlat(text) == text
    x, y = to_mercator(np.array([3.4]), np.array([6.4]))
    assert in_lonlat(f"near ({round(x[0])}, {round(y[0])})") == "near (3.4, 6.4) (lon, lat)"


def test_warnings_held_in_a_stage_are_given_when_it_fails_otherwise():
    from terramesh.coastal.messages import lonlat_messages

    x, y = to_mercator(np.array([1.0]), np.array([2.0]))
    with pytest.warns(TerrameshWarning, match=r"narrow at \(1, 2\) \(lon, lat\)"), pytest.raises(MemoryError):
        with lonlat_messages():
            tm.errors.warn_user(f"narrow at ({x[0]:.9g}, {y[0]:.9g})")
            raise MemoryError("out")


def test_lengths_beside_a_point_are_told_in_ground_metres_there():
    # the generator's lengths are Mercator metres, 1 / cos(lat) of the ground's: at 60 degrees a "size" of 500 was 250 m
    x, y = to_mercator(np.array([10.0]), np.array([60.0]))
    rings = f"2 holes covered by cells (the longest 2000 long, near ({x[0]:.9g}, {y[0]:.9g}), where the size is 500)"
    assert in_lonlat(rings) == (
        "2 holes covered by cells (the longest 1 km long, near (10, 60) (lon, lat), where the size is 250 m)"
    )
    apart = f"boundary nodes within the shortest edge (at most 12.5 apart, near ({x[0]:.9g}, {y[0]:.9g})): 3 pairs"
    assert in_lonlat(apart).startswith("boundary nodes within the shortest edge (at most 6.25 m apart, near (10, 60)")
    # without a point there is no latitude to measure at, and counts are no lengths
    assert in_lonlat("the longest 2000 long; 3 cells long") == "the longest 2000 long; 3 cells long"
