"""make_boundaries (the guide's makens): loops, open/mainland/island segments, ADCIRC traversal, fort.14 round trip."""

import warnings

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import GeometryError, MeshValidityError, TerrameshWarning
from terramesh.mesh.topology import boundary_edges

from ..conftest import hole_ring


@pytest.fixture(scope="module")
def plate():
    """A 2 x 1 rectangle with a round hole (an island), planar units."""
    domain = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (2, 1)), tm.geometry.Disk((1.0, 0.5), 0.2)])
    mesh = tm.generate_mesh(domain, 0.1)
    mesh.point_data["depth"] = 5.0 + 100.0 * mesh.points[:, 0]  # deeper eastwards, metres
    return mesh


def directed_edges(mesh):
    return {tuple(edge) for edge in boundary_edges(mesh.cells).tolist()}


def pairs(nodes):
    return list(zip(nodes[:-1].tolist(), nodes[1:].tolist(), strict=True))


def assert_adcirc_layout(result):
    """Every boundary edge in one segment, domain on the left; joints and closures as ADCIRC asks."""
    mesh_edges = directed_edges(result)
    b = result.boundaries
    used = [edge for segment in b.open + b.land for edge in pairs(segment.nodes)]
    assert sorted(used) == sorted(mesh_edges)  # a partition of the boundary, every edge in its mesh direction
    for island in (land for land in b.land if land.ibtype == 21):
        assert island.nodes[0] == island.nodes[-1]
        ring = result.points[island.nodes]
        area = 0.5 * np.sum(ring[:-1, 0] * ring[1:, 1] - ring[1:, 0] * ring[:-1, 1])
        assert area < 0  # clockwise: land on the right
    mainland = [land for land in b.land if land.ibtype == 20]
    open_ends = {int(o.nodes[-1]) for o in b.open}
    open_starts = {int(o.nodes[0]) for o in b.open}
    for land in mainland:
        if land.nodes[0] != land.nodes[-1]:  # not a closed basin: it joins open segments at both ends
            assert int(land.nodes[0]) in open_ends and int(land.nodes[-1]) in open_starts
    # mainland before islands
    kinds = [land.ibtype for land in b.land]
    assert kinds == sorted(kinds)


def test_bbox_edge_is_open_and_the_rest_mainland_and_island(plate):
    result = tm.coastal.make_boundaries(plate, bbox=(-1.0, 2.0, -1.0, 2.0), open_by="bbox")
    b = result.boundaries
    assert [o.ibtype for o in b.open] == [0] and len(b.open) == 1
    assert np.allclose(result.points[b.open[0].nodes, 0], 2.0)
    # the whole east side: from corner (2, 0) to corner (2, 1), counter-clockwise (northwards)
    assert np.allclose(result.points[b.open[0].nodes[[0, -1]]], [[2.0, 0.0], [2.0, 1.0]])
    assert [land.ibtype for land in b.land] == [20, 21]
    assert result.info["boundaries"]["open"] == 1 and result.info["boundaries"]["islands"] == 1
    assert_adcirc_layout(result)


def test_depth_rule_opens_the_deep_part_only(plate):
    result = tm.coastal.make_boundaries(plate, open_by="depth", depth_threshold=150.0)
    b = result.boundaries
    assert len(b.open) == 1
    # deep (> 150 m) at both ends of every open edge: x > 1.45
    assert np.all(result.points[b.open[0].nodes, 0] > 1.45)
    assert_adcirc_layout(result)


def test_default_is_bbox_or_depth(plate):
    both = tm.coastal.make_boundaries(plate, bbox=(0.0, 3.0, -1.0, 2.0), depth_threshold=150.0)
    # west side on the bbox, the deep east part by depth: two open segments, two mainland between them
    assert len(both.boundaries.open) == 2
    assert [land.ibtype for land in both.boundaries.land] == [20, 20, 21]
    assert_adcirc_layout(both)


def test_no_open_segment_is_a_closed_mainland(plate):
    result = tm.coastal.make_boundaries(plate, open_by="depth", depth_threshold=1e4)
    b = result.boundaries
    assert b.open == []
    assert [land.ibtype for land in b.land] == [20, 21]
    assert b.land[0].nodes[0] == b.land[0].nodes[-1]
    assert_adcirc_layout(result)


def test_all_open_loop_is_one_closed_open_boundary(plate):
    result = tm.coastal.make_boundaries(plate, bbox=(0.0, 2.0, 0.0, 1.0), open_by="bbox")
    b = result.boundaries
    assert len(b.open) == 1 and b.open[0].nodes[0] == b.open[0].nodes[-1]
    assert [land.ibtype for land in b.land] == [21]


def test_custom_ibtypes_and_no_ibtypee(plate):
    result = tm.coastal.make_boundaries(
        plate, bbox=(-1, 2, -1, 2), open_by="bbox", island_ibtype=1, mainland_ibtype=0, open_ibtype=None
    )
    assert [land.ibtype for land in result.boundaries.land] == [0, 1]
    assert result.boundaries.open[0].ibtype is None


def test_input_is_not_mutated_and_arrays_are_copies(plate):
    points, cells, depth = plate.points.copy(), plate.cells.copy(), plate.depth.copy()
    result = tm.coastal.make_boundaries(plate, bbox=(-1, 2, -1, 2))
    assert plate.boundaries is None
    assert np.array_equal(plate.points, points) and np.array_equal(plate.cells, cells)
    assert np.array_equal(plate.depth, depth)
    result.points[0] = 99.0
    assert plate.points[0, 0] != 99.0


def test_fort14_round_trip_keeps_the_boundaries(plate, tmp_path):
    result = tm.coastal.make_boundaries(plate, bbox=(0.0, 3.0, -1.0, 2.0), depth_threshold=150.0)
    path = tmp_path / "plate.14"
    result.write(path)
    back = tm.read_mesh(path)
    assert np.array_equal(back.points, result.points) and np.array_equal(back.cells, result.cells)
    assert len(back.boundaries.open) == len(result.boundaries.open)
    read_all, written_all = back.boundaries.open + back.boundaries.land, result.boundaries.open + result.boundaries.land
    for read, written in zip(read_all, written_all, strict=True):
        assert np.array_equal(read.nodes, written.nodes) and read.ibtype == written.ibtype


def test_dem_depth_replaces_mesh_depth():
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0.0, 0.0), (1.0, 0.5)), 0.1)
    mesh.crs = "EPSG:4326"
    lon, lat = np.linspace(-0.5, 1.5, 41), np.linspace(-0.5, 1.0, 31)
    dem = tm.coastal.DEM(lon, lat, np.repeat(-400.0 * lon[:, None], len(lat), axis=1))  # 400 m deeper per degree
    result = tm.coastal.make_boundaries(mesh, dem=dem, open_by="depth", depth_threshold=300.0)
    assert len(result.boundaries.open) == 1
    assert np.all(result.points[result.boundaries.open[0].nodes, 0] >= 0.75 - 1e-9)


def test_depth_rule_without_depth_raises():
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.25)
    with pytest.raises(MeshValidityError, match="depth"):
        tm.coastal.make_boundaries(mesh)
    assert tm.coastal.make_boundaries(mesh, open_by="bbox").boundaries.open  # the bbox rule needs none


def test_a_dem_apart_from_the_boundary_is_refused(shared_data, tmp_path):
    mesh = tm.generate_mesh(tm.geometry.Rectangle((-70.5, 41.5), (-70.0, 42.0)), 0.05)
    elsewhere = tm.coastal.read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", (0, 1, 0, 1))
    with pytest.raises(
        GeometryError, match=r"all \d+ boundary vertices lie outside the DEM \(lon -0.3..1.3, lat -0.3..1.3\)"
    ):
        tm.coastal.make_boundaries(mesh, dem=elsewhere)
    whole = tm.coastal.read_dem(shared_data / "dem" / "ETOPO1_0.1.grd")  # 0..360, the mesh -180..180
    depth = tm.coastal.interpolate_bathymetry(mesh, whole, method="bilinear").depth
    mesh.point_data["depth"] = depth
    etopo1 = shared_data / "dem" / "ETOPO1_0.1.grd"
    read_for_the_mesh = tm.coastal.interpolate_bathymetry(mesh, etopo1, method="bilinear").depth
    assert np.allclose(depth, read_for_the_mesh) and np.ptp(depth) > 50  # Massachusetts Bay, not the DEM's edge
    by_dem = tm.coastal.make_boundaries(mesh, dem=whole, open_by="depth", depth_threshold=float(np.median(depth)))
    by_depth = tm.coastal.make_boundaries(mesh, open_by="depth", depth_threshold=float(np.median(depth)))
    assert by_dem.info["boundaries"]["open_nodes"] == by_depth.info["boundaries"]["open_nodes"] > 0


def test_nan_depth_warns_and_counts_as_land():
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.25)
    mesh.point_data["depth"] = np.full(mesh.n_points, np.nan)
    with pytest.warns(TerrameshWarning, match="no depth"):
        result = tm.coastal.make_boundaries(mesh, open_by="depth")
    assert result.boundaries.open == []


def test_nan_depth_counts_as_land_under_the_bbox_rule_too():
    # a dry west shore (depth -1) with two NaN nodes: the bbox rule took the edges at them for open water
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.1)
    west = np.flatnonzero(mesh.points[:, 0] < 1e-9)
    depth = np.where(mesh.points[:, 0] < 1e-9, -1.0, 20.0)
    middle = west[np.argsort(mesh.points[west, 1])][[4, 5]]
    depth[middle] = np.nan
    mesh.point_data["depth"] = depth
    with pytest.warns(TerrameshWarning, match="count as land"):
        result = tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1))
    on_west = mesh.points[:, 0] < 1e-9
    for segment in result.boundaries.open:
        assert not np.any(on_west[segment.nodes[:-1]] & on_west[segment.nodes[1:]])
    assert not np.isin(middle, np.concatenate([b.nodes for b in result.boundaries.open])).any()
    assert_adcirc_layout(result)


def test_a_mesh_with_no_depth_above_zero_warns_that_its_depths_may_be_elevations(plate):
    # elevation given as depth: 0 open and 1 land boundary, without a word
    elevation = tm.Mesh(plate.points, plate.cells, point_data={"depth": -plate.depth})
    message = r"no vertex of the mesh is deeper than 0 m by point_data\['depth'\] \(the deepest is -5(\.\d+)? m\)"
    with pytest.warns(TerrameshWarning, match=message + ".*elevations \\(positive up\\)"):
        result = tm.coastal.make_boundaries(elevation)
    assert result.boundaries.open == [] and [land.ibtype for land in result.boundaries.land] == [20, 21]
    # a DEM of land: its values were taken as elevation, which read_dem's positive= says otherwise of
    lonlat = tm.Mesh(plate.points * 0.1, plate.cells, crs="EPSG:4326")
    lon, lat = np.linspace(-0.5, 0.5, 21), np.linspace(-0.5, 0.5, 21)
    land = tm.coastal.DEM(lon, lat, np.full((21, 21), 30.0))
    with pytest.warns(TerrameshWarning, match=r"by the DEM .*positive='up' or 'down'"):
        tm.coastal.make_boundaries(lonlat, dem=land)
    # a closed basin, dry at its edge and wet inside, and the bbox rule, which reads no depth: no warning
    on_edge = np.isin(np.arange(plate.n_points), boundary_edges(plate.cells))
    basin = tm.Mesh(plate.points, plate.cells, point_data={"depth": np.where(on_edge, -1.0, 10.0)})
    assert tm.coastal.make_boundaries(basin).boundaries.open == []
    assert tm.coastal.make_boundaries(elevation, open_by="bbox").boundaries.open


def test_clockwise_cells_raise(plate):
    # the outer boundary came out as an island and the hole as mainland and open water
    clockwise = tm.Mesh(plate.points, plate.cells[:, ::-1], point_data=dict(plate.point_data))
    with pytest.raises(MeshValidityError, match=r"clockwise.*fix_mesh"):
        tm.coastal.make_boundaries(clockwise)
    one = plate.cells.copy()
    one[7] = one[7, ::-1]
    with pytest.raises(MeshValidityError, match=f"1 of {plate.n_cells} cells are clockwise"):
        tm.coastal.make_boundaries(tm.Mesh(plate.points, one, point_data=dict(plate.point_data)), open_by="bbox")


def test_carried_over_boundaries_are_shortened_closed_again_or_dropped():
    from terramesh.coastal.boundaries import carried_over
    from terramesh.io.fort14 import Boundaries, LandBoundary, OpenBoundary

    # a 5 x 5 grid of unit squares; vertex 0 (the south-west corner) goes and its two cells become one (1, 6, 5)
    xs, ys = np.meshgrid(np.arange(5.0), np.arange(5.0))
    a = (np.arange(4)[None, :] + 5 * np.arange(4)[:, None]).ravel()
    before = np.concatenate([np.column_stack([a, a + 1, a + 6]), np.column_stack([a, a + 6, a + 5])])
    after_cells = np.concatenate([before[(before != 0).all(axis=1)], [[1, 6, 5]]])
    new_index = np.arange(25) - 1  # vertex i of the old grid is i - 1 of the new one
    after = after_cells - 1
    outline = np.array([0, 1, 2, 3, 4, 9, 14, 19, 24, 23, 22, 21, 20, 15, 10, 5, 0])
    values = np.column_stack([outline, -outline]).astype(float)
    boundaries = Boundaries(
        open=[OpenBoundary(np.array([0, 1]), 0), OpenBoundary(np.array([20, 15, 10, 5, 0]), 0)],
        land=[
            LandBoundary(outline, 23, None, values),
            LandBoundary(np.array([1, 2, 3]), 24, np.array([21, 22, 0]), np.ones((3, 4))),
        ],
    )
    carried, lost = carried_over(boundaries, new_index, before, after, 24)
    assert [b.nodes.tolist() for b in carried.open] == [(np.array([20, 15, 10, 5]) - 1).tolist()]
    closed, barrier = carried.land
    assert closed.ibtype == 23 and closed.nodes.tolist() == (np.append(outline[1:-1], 1) - 1).tolist()
    assert np.array_equal(closed.values, np.vstack([values[1:-1], values[1]]))
    assert barrier.nodes.tolist() == [0, 1] and barrier.paired_nodes.tolist() == [20, 21]
    assert barrier.values.shape == (2, 4)
    assert lost == ["open boundary 1 (IBTYPEE 0) is dropped: fewer than two of its 2 nodes are left",
                    "land boundary 2 (IBTYPE 24) lost 1 of its 3 node pairs"]  # fmt: skip
    # without the cell over the corner, the string closed at 1 no longer runs along the boundary
    _, lost = carried_over(boundaries, new_index, before, after[:-1], 24)
    assert "land boundary 1 (IBTYPE 23) is dropped: its nodes no longer run along the mesh's boundary" in lost


def test_an_island_meshed_over_is_said_to_be(plate_with_hole):
    # enforce_timestep filled a small island's hole with cells 43-49 m deep, and said only that its nodes "no
    # longer run along the mesh's boundary"
    from terramesh.coastal.boundaries import carried_over
    from terramesh.io.fort14 import Boundaries, LandBoundary

    domain, _ = plate_with_hole
    mesh = tm.generate_mesh(domain, 0.1, seed=0)
    ring = hole_ring(mesh)
    filled = np.vstack([mesh.cells, [[ring[0], ring[k + 1], ring[k]] for k in range(1, len(ring) - 1)]])
    boundaries = Boundaries(land=[LandBoundary(np.array([*ring, ring[0]]), 21)])
    _, lost = carried_over(boundaries, np.arange(mesh.n_points), mesh.cells, filled, mesh.n_points)
    assert lost == [
        f"land boundary 1 (IBTYPE 21) is dropped: the island is meshed over ({len(ring) + 1} of its {len(ring) + 1} "
        "nodes lie inside the mesh now, its cells cover the island)"
    ]


def test_a_geographic_bbox_in_the_other_longitude_convention_is_moved_onto_the_mesh(plate):
    # the mesh at -71..-69 E; its box given as 289..292 E made the west side a wall, silently
    mesh = tm.Mesh(plate.points + [-71.0, 41.0], plate.cells, point_data=dict(plate.point_data), crs="EPSG:4326")
    expected = tm.coastal.make_boundaries(mesh, bbox=(-71.0, -68.0, 40.0, 43.0), open_by="bbox").boundaries
    result = tm.coastal.make_boundaries(mesh, bbox=(289.0, 292.0, 40.0, 43.0), open_by="bbox").boundaries
    assert len(expected.open) == 1 and np.allclose(mesh.points[expected.open[0].nodes, 0], -71.0)  # west side
    assert [o.nodes.tolist() for o in result.open] == [o.nodes.tolist() for o in expected.open]
    with pytest.raises(MeshValidityError, match="does not overlap the mesh"):
        tm.coastal.make_boundaries(mesh, bbox=(10.0, 12.0, 41.0, 42.0), open_by="bbox")
    with pytest.raises(MeshValidityError, match="does not overlap the mesh"):  # planar: no shift
        tm.coastal.make_boundaries(plate, bbox=(360.0, 362.0, 0.0, 1.0), open_by="bbox")


def test_pinched_boundary_and_bad_options_raise(plate):
    # two triangles sharing one vertex: that vertex has four boundary edges
    pinched = tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1], [-1, 0], [0, -1]]), [[0, 1, 2], [0, 3, 4]])
    with pytest.raises(MeshValidityError, match="fix_mesh"):
        tm.coastal.make_boundaries(pinched, open_by="bbox")
    with pytest.raises(MeshValidityError, match="open_by"):
        tm.coastal.make_boundaries(plate, open_by="deep")
    with pytest.raises(MeshValidityError, match="IBTYPE"):
        tm.coastal.make_boundaries(plate, island_ibtype=-1)
    with pytest.raises(MeshValidityError, match="bbox"):
        tm.coastal.make_boundaries(plate, bbox=(2, 0, 0, 1))
    with pytest.raises(MeshValidityError, match="Mesh"):
        tm.coastal.make_boundaries(plate.points)
    # refused under the depth rule too, which does not use them: the options are kept for enforce_timestep
    deep = tm.Mesh(plate.points, plate.cells, point_data={"depth": np.full(plate.n_points, 500.0)})
    with pytest.raises(MeshValidityError, match="bbox"):
        tm.coastal.make_boundaries(deep, bbox=(2, 0, 0, 1), open_by="depth")
    for tolerance in (-1.0, np.nan, "0.1"):
        with pytest.raises(MeshValidityError, match="tolerance"):
            tm.coastal.make_boundaries(deep, tolerance=tolerance, open_by="depth")


@pytest.fixture(scope="module")
def square():
    return tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.1)


@settings(max_examples=40, deadline=None)
@given(st.data())
def test_any_depth_pattern_partitions_the_boundary(square, data):
    """Property: for any deep/shallow pattern, segments tile the boundary, alternate, and join where ADCIRC wants."""
    pattern = data.draw(st.lists(st.booleans(), min_size=square.n_points, max_size=square.n_points))
    mesh = tm.Mesh(square.points, square.cells, point_data={"depth": np.where(pattern, 50.0, 1.0)})
    result = tm.coastal.make_boundaries(mesh, open_by="depth", depth_threshold=10.0)
    assert_adcirc_layout(result)
    b = result.boundaries
    if b.open and len(b.land):
        assert len(b.open) == len([land for land in b.land if land.ibtype == 20])  # they alternate around the loop


def test_open_water_along_a_polygon_regions_slanted_edge_is_open(shared_data):
    # the bbox rule alone took the diagonal across Nantucket Shoals (14-60 m deep) for a mainland wall
    region = shapely.Polygon([(-71, 41), (-70, 41), (-69, 41.8), (-69, 43), (-71, 43)])
    # and Boston Harbor's entrance on the box's west edge, 0.25 m deep at 2 km: said so, by build and here
    with pytest.warns(TerrameshWarning, match="1 of 3 open boundaries are less than 1 m deep"):
        mesh = tm.coastal.build(
            region,
            shared_data / "coast" / "GSHHS_l_L1.shp",
            shared_data / "dem" / "ETOPO1_0.1.grd",
            min_el=2000,
            max_el=15000,
            fs=3,
            g=0.25,
        )
    with pytest.warns(TerrameshWarning, match="1 of 3 open boundaries are less than 1 m deep"):
        result = tm.coastal.make_boundaries(mesh)
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    on_diagonal = (np.abs((y - 41.0) - 0.8 * (x + 70.0)) < 1e-6) & (x > -70.0 + 1e-6) & (x < -69.0 - 1e-6)
    assert on_diagonal.sum() >= 5
    open_nodes = np.concatenate([b.nodes for b in result.boundaries.open])
    assert np.all(np.isin(np.flatnonzero(on_diagonal), open_nodes))
    for land in result.boundaries.land:  # a land segment may only end on the diagonal
        assert not on_diagonal[land.nodes[1:-1]].any()


def test_open_water_along_a_curved_region_is_open(shared_data):
    # a circle's chords have their midpoints inside by length^2 / 8R: 35 of its 50 water edges were mainland
    region = shapely.Point(-70.3, 41.9).buffer(0.8, 64)
    mesh = tm.coastal.build(region, shared_data / "coast" / "GSHHS_l_L1.shp", None, min_el=3000, max_el=15000, fs=3)
    on_circle = shapely.distance(shapely.boundary(region), shapely.points(mesh.points)) < 1e-6
    edges = boundary_edges(mesh.cells)
    along = edges[on_circle[edges].all(axis=1)]
    open_edges = {edge for segment in mesh.boundaries.open for edge in pairs(segment.nodes)}
    assert len(along) >= 40 and all(tuple(edge) in open_edges for edge in along.tolist())
    assert_adcirc_layout(mesh)
    land = np.concatenate([segment.nodes[1:-1] for segment in mesh.boundaries.land])
    assert not on_circle[land].any()  # a land segment may only end on the circle


def test_the_box_edge_across_land_is_not_open():
    # where the box's edge meets the coast it runs over dry nodes: an elevation boundary there (4 dry nodes
    # in the Gulf of Maine's open boundary at 4 km) is land now, unless said otherwise with open_by="bbox"
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.1)
    mesh.point_data["depth"] = np.where(mesh.points[:, 0] < 0.5, -5.0, 50.0)
    result = tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1), depth_threshold=100.0)
    assert len(result.boundaries.open) == 1 and len(result.boundaries.land) == 1
    inner = result.boundaries.open[0].nodes[1:-1]
    assert np.all(mesh.depth[inner] > 0)
    land = result.boundaries.land[0].nodes
    assert np.all(mesh.depth[land[1:-1]] <= 0) and np.all(mesh.points[land, 0] <= 0.5 + 0.1)
    everything = tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1), open_by="bbox").boundaries
    assert len(everything.open) == 1 and everything.land == []


def test_a_built_mesh_is_open_on_its_box_only_where_a_coarse_dem_reads_fjords_deep(shared_data):
    # Scoresby Sund on ETOPO1 at 0.1 degree: the depth rule opened 23 segments of its walls, tides forced on them
    mesh = tm.coastal.build(
        (-30, -20, 68, 72),
        shared_data / "coast" / "GSHHS_l_L1.shp",
        shared_data / "dem" / "ETOPO1_0.1.grd",
        min_el=2000,
        max_el=30e3,
        fs=3,
    )
    x0, x1, y0, y1 = mesh.info["sizes"].shoreline.bbox
    assert len(mesh.boundaries.open) == 2
    for segment in mesh.boundaries.open:
        lon, lat = mesh.points[segment.nodes[1:-1]].T  # its ends are where the coast meets the box
        assert np.all(np.isclose(lon, x0) | np.isclose(lon, x1) | np.isclose(lat, y0) | np.isclose(lat, y1))


def test_an_infinite_depth_threshold_opens_the_wet_box_edges_only(plate):
    # depth_threshold=inf (build's): the wet part of the box's edge only; inf was refused as "not finite"
    wet = tm.Mesh(plate.points, plate.cells, point_data={"depth": np.where(plate.points[:, 1] > 0.5, -2.0, 500.0)})
    result = tm.coastal.make_boundaries(wet, bbox=(-1.0, 2.0, -1.0, 2.0), depth_threshold=np.inf)
    (segment,) = result.boundaries.open  # 500 m deep along the south side, which is no box edge: land
    assert np.allclose(result.points[segment.nodes, 0], 2.0) and result.points[segment.nodes, 1].max() <= 0.55
    for bad in (np.nan, -np.inf, "100"):
        with pytest.raises(MeshValidityError, match="depth_threshold must be a number of metres"):
            tm.coastal.make_boundaries(wet, depth_threshold=bad)
    # the default rule opens no water by its depth unless told; the depth rule's default is 100 m
    (alone,) = tm.coastal.make_boundaries(wet, bbox=(-1.0, 2.0, -1.0, 2.0)).boundaries.open
    assert np.array_equal(alone.nodes, segment.nodes)
    assert len(tm.coastal.make_boundaries(wet, open_by="depth").boundaries.open) == 1  # the 500 m south side
    with pytest.raises(MeshValidityError, match='open_by="depth" with depth_threshold=inf opens nothing'):
        tm.coastal.make_boundaries(wet, open_by="depth", depth_threshold=np.inf)


def test_build_takes_the_depth_rule_with_its_own_default(shared_data):
    # boundaries={"open_by": "depth"} kept build's depth_threshold=inf and opened nothing (a closed basin)
    mesh = tm.coastal.build(
        (-71.0, -65.0, 41.0, 45.0),
        shared_data / "coast" / "GSHHS_l_L1.shp",
        shared_data / "dem" / "ETOPO1_0.1.grd",
        min_el=4000,
        max_el=30e3,
        fs=3,
        boundaries={"open_by": "depth"},
    )
    assert mesh.info["boundaries"]["options"]["depth_threshold"] == 100.0 and len(mesh.boundaries.open) >= 1


def test_a_narrow_inlet_on_the_box_stays_open_and_a_node_just_wet_warns():
    # one wet node between dry ones on the box's edge: a strait one edge across at the mesh's size (the Oresund at
    # 3 km: -12.3 and 2.1 m) is open; one just wet (Boston Harbor's entrance: -1.2 and 0.25 m) is warned of
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.1)
    south = np.flatnonzero(mesh.points[:, 1] < 1e-9)
    middle = south[np.argmin(np.abs(mesh.points[south, 0] - 1.0))]
    depth = np.full(mesh.n_points, -5.0)
    depth[middle] = 10.0
    mesh.point_data["depth"] = depth
    inlet = tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1)).boundaries.open
    assert len(inlet) == 1 and len(inlet[0].nodes) == 3 and inlet[0].nodes[1] == middle
    depth[middle] = 0.3
    with pytest.warns(TerrameshWarning, match="1 of 1 open boundaries are less than 1 m deep"):
        assert len(tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1)).boundaries.open) == 1
    assert tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1), dry_depth=1.0).boundaries.open == []


def test_open_water_shallower_than_a_metre_warns_and_dry_depth_makes_it_land():
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.1)
    mesh.point_data["depth"] = np.where(mesh.points[:, 0] > 1.95, 0.5, -5.0)  # a flat along the east side
    with pytest.warns(TerrameshWarning, match=r"1 of 1 open boundaries are less than 1 m deep.*dry_depth"):
        result = tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1))
    assert len(result.boundaries.open) == 1 and np.all(mesh.depth[result.boundaries.open[0].nodes[1:-1]] == 0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        land = tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1), dry_depth=1.0)
    assert land.boundaries.open == [] and land.info["boundaries"]["options"]["dry_depth"] == 1.0
    with pytest.raises(MeshValidityError, match="dry_depth must be a finite number"):
        tm.coastal.make_boundaries(mesh, bbox=(0, 2, 0, 1), dry_depth=float("nan"))


def test_node_string_problems_name_a_jump_and_an_island_left_open(plate):
    mesh = tm.coastal.make_boundaries(plate, open_by="bbox")
    assert tm.coastal.node_string_problems(mesh) == []
    island = next(k for k, land in enumerate(mesh.boundaries.land) if land.ibtype == 21)
    mesh.boundaries.land[island].nodes = mesh.boundaries.land[island].nodes[:-1]
    problems = tm.coastal.node_string_problems(mesh)
    assert problems == [f"land boundary {island + 1} (IBTYPE 21, an island) does not end on its first node"]
    nodes = mesh.boundaries.land[island].nodes
    nodes[[1, 3]] = nodes[[3, 1]]
    problems = tm.coastal.node_string_problems(mesh)
    assert len(problems) == 2 and "nodes 1 and 2" in problems[1] and "(2 such pairs)" in problems[1]


def test_a_bbox_in_shapelys_order_warns_and_a_polygon_bbox_is_checked(plate):
    mesh = tm.Mesh(plate.points + [-71.0, 41.0], plate.cells, point_data=dict(plate.point_data), crs="EPSG:4326")
    # (x_min, y_min, x_max, y_max) read as (x_min, x_max, y_min, y_max): a box 110 degrees wide, no side on the mesh
    with pytest.warns(TerrameshWarning, match="shapely's order"):
        result = tm.coastal.make_boundaries(mesh, bbox=(-71.0, 41.0, -69.0, 42.0), open_by="bbox")
    opened = mesh.points[np.concatenate([o.nodes for o in result.boundaries.open])]
    assert not np.any(np.isclose(opened[:, 0], -69.0) & (opened[:, 1] < 41.9))  # its east side, x = 41, is far
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tm.coastal.make_boundaries(mesh, bbox=(-71.0, -69.0, 41.0, 42.0), open_by="bbox")
        tm.coastal.make_boundaries(mesh, bbox=(-72.0, -69.0, 40.0, 42.0), open_by="bbox")  # a bay's box: no warning
    box = shapely.box(-71.0, 41.0, -69.0, 42.0)
    by_polygon = tm.coastal.make_boundaries(mesh, bbox=box, open_by="bbox").boundaries
    by_numbers = tm.coastal.make_boundaries(mesh, bbox=(-71.0, -69.0, 41.0, 42.0), open_by="bbox").boundaries
    assert [o.nodes.tolist() for o in by_polygon.open] == [o.nodes.tolist() for o in by_numbers.open]
    with pytest.raises(MeshValidityError, match="does not overlap the mesh"):
        tm.coastal.make_boundaries(mesh, bbox=shapely.box(10, 10, 11, 11), open_by="bbox")
    with pytest.raises(MeshValidityError, match="non-empty polygon"):
        tm.coastal.make_boundaries(mesh, bbox=shapely.LineString([(-71, 41), (-69, 42)]), open_by="bbox")
    east = tm.coastal.make_boundaries(mesh, bbox=shapely.box(289.0, 41.0, 291.0, 42.0), open_by="bbox").boundaries
    assert [o.nodes.tolist() for o in east.open] == [o.nodes.tolist() for o in by_numbers.open]  # 0..360, moved
    with pytest.raises(MeshValidityError, match="no vertices"):
        tm.coastal.make_boundaries(tm.Mesh(np.zeros((0, 2)), np.zeros((0, 3), dtype=int)), bbox=box)
