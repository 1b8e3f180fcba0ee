"""The Mesh container: what it accepts and refuses."""

import numpy as np
import pyproj
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError

TRIANGLE = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


@pytest.mark.parametrize(
    "points, cells, message",
    [
        (TRIANGLE, [[0, 1, 2.9]], "cells must be integer vertex indices, got float64"),  # was cast to [0, 1, 2]
        (TRIANGLE, [["a", "b", "c"]], "cells must be integer vertex indices"),
        ([["a", "b"]], [[0, 1, 2]], "points must be numbers"),
        (TRIANGLE, [[0, 1, 3]], "vertices that do not exist"),
        (np.array([[0.0, np.nan], [1, 0], [0, 1]]), [[0, 1, 2]], "NaN or infinite at 1 of 3 points"),
    ],
)
def test_bad_points_and_cells_are_refused_by_name(points, cells, message):
    with pytest.raises(MeshValidityError, match=message):
        tm.Mesh(points, cells)


def test_whole_numbers_and_unsigned_integers_are_cell_indices():
    for cells in ([[0, 1, 2.0]], np.array([[0, 1, 2]], dtype=np.uint32)):
        mesh = tm.Mesh(TRIANGLE, cells)
        assert mesh.cells.dtype == np.int64 and mesh.cells.tolist() == [[0, 1, 2]]


@pytest.mark.parametrize(
    "crs",
    [
        "EPSG:4326",
        "epsg:4326",
        "EPSG:4269",  # NAD83: counted as planar, courant_number took its degrees for metres
        "+proj=longlat +datum=WGS84",
        "EPSG:4326 ",
        "CRS84",
        "urn:ogc:def:crs:OGC:1.3:CRS84",
        4326,  # raised AttributeError ('int' object has no attribute 'upper')
        pyproj.CRS("EPSG:4269"),
    ],
)
def test_every_longitude_latitude_crs_is_geographic(crs):
    assert tm.Mesh(TRIANGLE, [[0, 1, 2]], crs=crs).geographic


@pytest.mark.parametrize("crs", ["EPSG:32633", 32633, pyproj.CRS("EPSG:3857"), None])
def test_projected_and_missing_crs_are_planar(crs):
    assert not tm.Mesh(TRIANGLE, [[0, 1, 2]], crs=crs).geographic


@pytest.mark.parametrize(
    "crs, kept",
    [
        (4326, "EPSG:4326"),
        (pyproj.CRS("EPSG:4269"), "EPSG:4269"),
        (" EPSG:32633\n", "EPSG:32633"),
        ("epsg:4326", "epsg:4326"),
    ],
)
def test_crs_is_kept_as_a_string_when_built_and_when_assigned(crs, kept):
    built = tm.Mesh(TRIANGLE, [[0, 1, 2]], crs=crs).crs
    assert isinstance(built, str) and built == kept  # a pyproj.CRS compares equal to its string: the type says
    mesh = tm.Mesh(TRIANGLE, [[0, 1, 2]])
    mesh.crs = crs
    assert isinstance(mesh.crs, str) and mesh.crs == kept


@pytest.mark.parametrize("crs", ["", "  ", "EPSG:4326x", "EPSG:99999", 4326.0, True, [4326]])
def test_unusable_crs_is_refused_by_name(crs):
    with pytest.raises(MeshValidityError, match="crs"):
        tm.Mesh(TRIANGLE, [[0, 1, 2]], crs=crs)


@pytest.mark.parametrize(
    "values, got",
    [
        (5.0, "got shape ()"),  # was a raw TypeError: object of type 'float' has no len()
        (np.ones(2), r"got shape \(2,\)"),
        ([[1.0], [2.0, 3.0], [4.0]], "got a ragged sequence"),
    ],
)
def test_point_data_that_is_not_one_value_per_point_is_refused_by_name(values, got):
    with pytest.raises(MeshValidityError, match=r"point_data\['depth'\] must hold one value per point.*" + got):
        tm.Mesh(TRIANGLE, [[0, 1, 2]], point_data={"depth": values})


@pytest.mark.parametrize(
    "boundaries, message",
    [
        ({"open": [np.array([0, 1, 99])]}, "an open boundary refers to node 99 .* 3 nodes"),
        ({"land": [np.array([-1, 2])]}, "a land boundary refers to node -1"),
        ({"open": [np.array([0.0, 1.5])]}, "an open boundary refers to node 1.5: node indices must be whole"),
    ],
)
def test_boundaries_naming_vertices_the_mesh_lacks_are_refused(boundaries, message):
    # node 99 on a mesh of 3 was taken, and renumber failed with a bare IndexError
    from terramesh.io import Boundaries, LandBoundary, OpenBoundary

    strings = Boundaries(
        open=[OpenBoundary(nodes) for nodes in boundaries.get("open", [])],
        land=[LandBoundary(nodes, 20) for nodes in boundaries.get("land", [])],
    )
    with pytest.raises(MeshValidityError, match="boundaries do not fit the mesh: " + message):
        tm.Mesh(TRIANGLE, [[0, 1, 2]], boundaries=strings)
    fitting = Boundaries(open=[OpenBoundary(np.array([0, 1]))], land=[LandBoundary(np.array([1, 2, 0]), 20)])
    assert tm.Mesh(TRIANGLE, [[0, 1, 2]], boundaries=fitting).boundaries is fitting


# coastal.14 of the review: a Gulf coast patch near 94 W, 29.8 N, in UTM zone 15 N metres
UTM = np.array([[409220.9, 3291413.0], [417894.9, 3291413.0], [417894.9, 3302523.0]])


@pytest.mark.parametrize("crs", ["EPSG:4326", "EPSG:4269", "+proj=longlat +datum=WGS84"])
def test_metres_labelled_degrees_are_refused_when_built_assigned_or_copied(crs):
    """UTM metres labelled EPSG:4326 were taken: 260 of 523 cells inverted, a Courant number 300 times too small."""
    import dataclasses

    said = r"x 409220.9..417894.9, y 3291413..3302523, outside longitude -360..360, latitude -90..90: .*EPSG:326"
    with pytest.raises(MeshValidityError, match=said):
        tm.Mesh(UTM, [[0, 1, 2]], crs=crs)
    planar = tm.Mesh(UTM, [[0, 1, 2]])
    with pytest.raises(MeshValidityError, match=said):
        planar.crs = crs
    assert planar.crs is None  # the refused crs was not kept
    with pytest.raises(MeshValidityError, match=said):
        dataclasses.replace(tm.Mesh(TRIANGLE, [[0, 1, 2]], crs=crs), points=UTM)
    assert tm.Mesh(UTM, [[0, 1, 2]], crs="EPSG:32615").crs == "EPSG:32615"  # its own CRS


@pytest.mark.parametrize(
    "lon, lat",
    [
        ((0.0, 359.9), (-90.0, 90.0)),  # 0..360 longitudes, both poles
        ((-360.0, -180.0), (10.0, 20.0)),
        ((170.0, 190.0), (-60.0, -50.0)),  # across the antimeridian: the latitudes looked at apart
        ((-1.0, 1.0), (-90.0 - 1e-9, 90.0 + 1e-9)),  # a pole after a reprojection's rounding
    ],
)
def test_degrees_anywhere_in_their_ranges_are_taken(lon, lat):
    points = np.array([[lon[0], lat[0]], [lon[1], lat[0]], [lon[0], lat[1]]])
    assert tm.Mesh(points, [[0, 1, 2]], crs="EPSG:4326").geographic
    mesh = tm.Mesh(points, [[0, 1, 2]])
    mesh.crs = "EPSG:4269"
    assert mesh.geographic


@pytest.mark.parametrize("x, y", [(0.0, 90.001), (0.0, -90.001), (360.001, 0.0), (-360.001, 0.0), (200.0, 100.0)])
def test_a_coordinate_just_beyond_the_degrees_ranges_is_refused(x, y):
    points = np.array([[0.0, 0.0], [1.0, 0.0], [x, y]])
    with pytest.raises(MeshValidityError, match="outside longitude -360..360, latitude -90..90"):
        tm.Mesh(points, [[0, 1, 2]], crs="EPSG:4326")
    assert tm.Mesh(points, [[0, 1, 2]]).crs is None  # planar: any coordinates
