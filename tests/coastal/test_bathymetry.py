"""interpolate_bathymetry (the guide's GridData): median-dual cell averages of the DEM, fallback, clamp, file input."""

import warnings

import numpy as np
import pytest

import terramesh as tm
from terramesh.coastal.bathymetry import median_dual_average
from terramesh.errors import GeometryError, MeshValidityError, TerrameshWarning


def lonlat_mesh(x0, y0, x1, y1, h):
    mesh = tm.generate_mesh(tm.geometry.Rectangle((x0, y0), (x1, y1)), h)
    mesh.crs = "EPSG:4326"
    return mesh


def grid_dem(x0, x1, y0, y1, n, function):
    lon, lat = np.linspace(x0, x1, n), np.linspace(y0, y1, n)
    return tm.coastal.DEM(lon, lat, function(*np.meshgrid(lon, lat, indexing="ij")))


def reference_median_dual(points, cells, dem):
    """Brute force: every DEM node against every triangle; the node goes to the corner of largest barycentric weight."""
    gx, gy = np.meshgrid(dem.lon, dem.lat, indexing="ij")
    px, py = gx.ravel(), gy.ravel()
    a, b, c = (points[cells[:, k]] for k in range(3))
    det = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
    l0 = (b[:, 1] - c[:, 1])[None] * (px[:, None] - c[:, 0]) + (c[:, 0] - b[:, 0])[None] * (py[:, None] - c[:, 1])
    l1 = (c[:, 1] - a[:, 1])[None] * (px[:, None] - c[:, 0]) + (a[:, 0] - c[:, 0])[None] * (py[:, None] - c[:, 1])
    l0, l1 = l0 / det, l1 / det
    lam = np.stack([l0, l1, 1 - l0 - l1], axis=-1)  # (nodes, cells, 3)
    inside = np.all(lam >= -1e-12, axis=-1)
    node, cell = np.nonzero(inside)
    node, first = np.unique(node, return_index=True)
    cell = cell[first]
    vertex = cells[cell, np.argmax(lam[node, cell], axis=1)]
    depth = -dem.elevation.ravel()[node]
    count = np.bincount(vertex, minlength=len(points))
    total = np.bincount(vertex, weights=depth, minlength=len(points))
    return np.where(count > 0, total / np.maximum(count, 1), np.nan), count


def test_average_agrees_with_brute_force_reference():
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.2)
    # nodes 0.0125 off the square's sides: none on the boundary, where the generator leaves vertices within 1e-3 h
    dem = grid_dem(-0.1875, 1.1875, -0.1875, 1.1875, 56, lambda x, y: -(10.0 + 50.0 * np.sin(5 * x) * y))
    average, count = median_dual_average(mesh.points, mesh.cells, dem)
    expected, expected_count = reference_median_dual(mesh.points, mesh.cells, dem)
    assert np.array_equal(count, expected_count)
    assert np.allclose(average, expected, equal_nan=True)
    inside = (dem.lon[:, None] > 0) & (dem.lon[:, None] < 1) & (dem.lat[None, :] > 0) & (dem.lat[None, :] < 1)
    assert count.sum() == inside.sum()  # every DEM node inside the mesh, once; none outside


def test_constant_and_linear_dems():
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.1)
    flat = tm.coastal.interpolate_bathymetry(mesh, grid_dem(-0.5, 1.5, -0.5, 1.5, 201, lambda x, y: -7.5 + 0 * x))
    assert np.allclose(flat.depth, 7.5)
    assert flat.info["bathymetry"]["averaged"] == mesh.n_points
    plane = tm.coastal.interpolate_bathymetry(mesh, grid_dem(-0.5, 1.5, -0.5, 1.5, 201, lambda x, y: -(x + 2 * y)))
    # the mean of a plane over a cell is the plane at the cell's centroid, within a fraction of an edge of the vertex
    error = np.abs(plane.depth - (mesh.points[:, 0] + 2 * mesh.points[:, 1]))
    assert error.max() < 3 * 0.1 / 3 and np.median(error) < 0.03


def test_averaging_removes_a_spike_point_sampling_keeps():
    """A one-node-wide trench 500 m deep in 10 m of water: bilinear sampling reports it, the average dilutes it."""
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.1)
    dem = grid_dem(-0.5, 1.5, -0.5, 1.5, 401, lambda x, y: np.where(np.abs(x - 0.5) < 1e-9, -500.0, -10.0))
    on_trench = np.abs(mesh.points[:, 0] - 0.5) < 1e-3
    sampled = tm.coastal.interpolate_bathymetry(mesh, dem, method="bilinear")
    averaged = tm.coastal.interpolate_bathymetry(mesh, dem)
    assert np.allclose(sampled.depth, -dem.sample(*mesh.points.T))
    if on_trench.any():
        assert sampled.depth[on_trench].max() > 400
    # the trench takes 1 of the ~20 DEM columns across a cell: at most a tenth of the spike survives anywhere
    assert averaged.depth.max() < 10 + 0.15 * 490


def test_coarse_dem_falls_back_to_bilinear():
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.1)
    dem = grid_dem(-1.0, 2.0, -1.0, 2.0, 4, lambda x, y: -(x + y))  # 1 degree spacing
    result = tm.coastal.interpolate_bathymetry(mesh, dem, min_samples=3)
    report = result.info["bathymetry"]
    assert report["averaged"] + report["sampled"] == mesh.n_points and report["sampled"] > 0.9 * mesh.n_points
    sampled = ~np.isfinite(median_dual_average(mesh.points, mesh.cells, dem, min_samples=3)[0])
    assert np.allclose(result.depth[sampled], -dem.sample(*mesh.points[sampled].T))


def test_min_depth_clamps_land_and_shallows():
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.1)
    dem = grid_dem(-0.5, 1.5, -0.5, 1.5, 101, lambda x, y: 20.0 * x - 12.0)  # land east of x = 0.6
    result = tm.coastal.interpolate_bathymetry(mesh, dem, min_depth=2.0)
    assert result.depth.min() == 2.0
    assert np.all(result.depth[mesh.points[:, 0] > 0.6] == 2.0)


def test_a_dem_that_makes_most_of_the_mesh_land_warns_of_its_sign():
    # the reviewer's ETOPO1 read with --dem-positive down: 98 % of a Gulf of Maine mesh's area on land, without a word
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.1)
    depths = grid_dem(-0.5, 1.5, -0.5, 1.5, 101, lambda x, y: 20.0 * x + 2.0)  # depths (positive down) as elevation
    with pytest.warns(TerrameshWarning, match=r"^100% of the mesh's area lies at or above 0 m in the DEM, where"):
        result = tm.coastal.interpolate_bathymetry(mesh, depths, min_depth=2.0)  # clamped after the count
    assert np.all(result.depth == 2.0)
    elevation = tm.coastal.DEM(depths.lon, depths.lat, -depths.elevation)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert tm.coastal.interpolate_bathymetry(mesh, elevation).depth.min() > 0


def test_file_input_matches_dem_object(shared_data):
    path = shared_data / "dem" / "CUDEM_equal.nc"
    mesh = lonlat_mesh(-93.9, 29.75, -93.88, 29.77, 0.002)
    from_file = tm.coastal.interpolate_bathymetry(mesh, path)
    dem = tm.coastal.read_dem(path, (-93.95, -93.85, 29.7, 29.8))
    from_object = tm.coastal.interpolate_bathymetry(mesh, dem)
    assert np.allclose(from_file.depth, from_object.depth)
    assert from_file.info["bathymetry"]["samples_median"] >= 20  # ~30 m DEM cells in ~200 m triangles


def test_a_file_is_read_with_the_readers_options(shared_data):
    path = shared_data / "dem" / "CUDEM_equal.nc"
    mesh = lonlat_mesh(-93.9, 29.75, -93.88, 29.77, 0.002)
    up = tm.coastal.interpolate_bathymetry(mesh, path, positive="up")
    down = tm.coastal.interpolate_bathymetry(mesh, path, positive="down", variable=None)  # None: the default
    np.testing.assert_array_equal(down.depth, -up.depth)
    assert np.median(up.depth) > 0  # CUDEM is elevation
    dem = tm.coastal.read_dem(path, (-93.95, -93.85, 29.7, 29.8))
    with pytest.raises(MeshValidityError, match="positive: for a DEM read from a file, not a DEM given"):
        tm.coastal.interpolate_bathymetry(mesh, dem, positive="down")
    with pytest.raises(TypeError, match="unexpected keyword argument.*margin"):
        tm.coastal.interpolate_bathymetry(mesh, path, margin=5)


def test_longitudes_a_turn_away_from_the_dem():
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.1)
    dem = grid_dem(359.5, 361.5, -0.5, 1.5, 101, lambda x, y: -(x - 350.0))  # the DEM in 0..360 past the meridian
    result = tm.coastal.interpolate_bathymetry(mesh, dem)
    assert result.info["bathymetry"]["averaged"] == mesh.n_points
    assert np.abs(result.depth - (10.0 + mesh.points[:, 0])).max() < 0.1


def seam_depth(lon):
    """A depth (metres) that is periodic in longitude and different on each side of 180."""
    return 1000.0 + 500.0 * np.cos(np.radians(3.0 * lon)) + 200.0 * np.sin(np.radians(lon))


@pytest.mark.parametrize("first", [-180.0, -179.95], ids=["node-registered", "pixel-registered"])
def test_global_dem_averages_a_mesh_across_the_seam(first):
    """A DEM all the way round is periodic: a mesh over 180 E averages the nodes on both sides, as away from it."""
    # 178..182 E, sides off the DEM nodes; every vertex's cell holds DEM nodes (none falls back to sampling)
    mesh = lonlat_mesh(178.03, -0.97, 182.03, 1.03, 0.4)
    lat = np.linspace(-2.0, 2.0, 41)
    columns = 3601 if first == -180.0 else 3600  # -180..180 with the seam twice, or cell centres -179.95..179.95
    lon = first + 0.1 * np.arange(columns)
    global_dem = tm.coastal.DEM(lon, lat, -np.repeat(seam_depth(lon)[:, None], lat.size, axis=1))
    regional_lon = (first + 360.0) % 1.0 + np.arange(170.0, 190.0, 0.1)  # the same nodes, unwrapped, 170..190
    regional_dem = tm.coastal.DEM(regional_lon, lat, -np.repeat(seam_depth(regional_lon)[:, None], lat.size, axis=1))
    # every cell averaged, one node or more (the default asks four): warnings are errors, no "outside the DEM"
    result = tm.coastal.interpolate_bathymetry(mesh, global_dem, min_samples=1)
    expected = tm.coastal.interpolate_bathymetry(mesh, regional_dem, min_samples=1)
    report = result.info["bathymetry"]
    assert report["averaged"] == expected.info["bathymetry"]["averaged"] == mesh.n_points
    assert report["sampled"] == 0
    average, count = median_dual_average(mesh.points, mesh.cells, global_dem)
    assert np.array_equal(count, median_dual_average(mesh.points, mesh.cells, regional_dem)[1])
    np.testing.assert_allclose(result.depth, expected.depth, rtol=1e-12)
    # a DEM that stops short of the seam is regional still
    short = tm.coastal.DEM(lon[:-20], lat, global_dem.elevation[:-20])
    with pytest.warns(TerrameshWarning, match="outside the DEM"):
        tm.coastal.interpolate_bathymetry(mesh, short)


def test_input_untouched_boundaries_and_point_data_kept():
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.2)
    mesh.point_data["depth"] = np.zeros(mesh.n_points)
    mesh.point_data["other"] = np.arange(mesh.n_points, dtype=float)
    mesh = tm.coastal.make_boundaries(mesh, open_by="bbox")
    points, depth = mesh.points.copy(), mesh.depth.copy()
    result = tm.coastal.interpolate_bathymetry(mesh, grid_dem(-0.5, 1.5, -0.5, 1.5, 41, lambda x, y: -3.0 + 0 * x))
    assert np.array_equal(mesh.points, points) and np.array_equal(mesh.depth, depth)
    assert np.allclose(result.depth, 3.0) and np.array_equal(result.point_data["other"], mesh.point_data["other"])
    assert np.array_equal(result.boundaries.open[0].nodes, mesh.boundaries.open[0].nodes)
    assert result.boundaries.open[0].nodes is not mesh.boundaries.open[0].nodes


def test_vertices_outside_the_dem_warn():
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.2)
    with pytest.warns(TerrameshWarning, match="outside the DEM"):
        tm.coastal.interpolate_bathymetry(mesh, grid_dem(0.0, 0.5, 0.0, 1.0, 21, lambda x, y: -1.0 + 0 * x))


def test_a_finer_dem_after_a_coarse_one_changes_only_where_it_covers(shared_data):
    # the guide's habit: GridData with the coarse DEM, then the fine one; its edge value had spread over the
    # rest of a Sabine Lake mesh (4,158 vertices, offshore median 26 m -> -0.1 m)
    mesh = lonlat_mesh(-94.3, 29.4, -93.6, 30.0, 0.03)
    coarse = tm.coastal.interpolate_bathymetry(mesh, shared_data / "dem" / "ETOPO1_0.1.grd")
    with pytest.warns(TerrameshWarning, match=r"lie outside the DEM .*: they keep their depth") as record:
        both = tm.coastal.interpolate_bathymetry(coarse, shared_data / "dem" / "CUDEM_equal.nc")
    assert len(record) == 1  # the reading's own "covers less than the bbox" is not said twice
    cudem = tm.coastal.read_dem(shared_data / "dem" / "CUDEM_equal.nc")
    lon, lat = mesh.points.T
    inside = (lon > cudem.lon[0]) & (lon < cudem.lon[-1]) & (lat > cudem.lat[0]) & (lat < cudem.lat[-1])
    far = (lon < cudem.lon[0] - 2 * cudem.dx) | (lon > cudem.lon[-1] + 2 * cudem.dx)
    far |= (lat < cudem.lat[0] - 2 * cudem.dy) | (lat > cudem.lat[-1] + 2 * cudem.dy)
    assert inside.sum() > 20 and far.sum() > 500
    assert np.array_equal(both.depth[far], coarse.depth[far])
    assert both.info["bathymetry"]["kept"] >= far.sum()
    assert np.abs(both.depth[inside] - coarse.depth[inside]).max() > 1.0  # the fine DEM was put on
    with pytest.warns(TerrameshWarning, match="at its nearest edge"):
        edge = tm.coastal.interpolate_bathymetry(coarse, shared_data / "dem" / "CUDEM_equal.nc", outside="edge")
    assert not np.array_equal(edge.depth[far], coarse.depth[far])
    with pytest.raises(MeshValidityError, match="has none"):
        tm.coastal.interpolate_bathymetry(mesh, shared_data / "dem" / "CUDEM_equal.nc", outside="keep")
    # build's mesh without a DEM has depths, all NaN: they were kept, 412 of 1,672 left NaN in a review
    unknown = tm.Mesh(mesh.points, mesh.cells, point_data={"depth": np.full(mesh.n_points, np.nan)}, crs=mesh.crs)
    with pytest.warns(TerrameshWarning, match="take the depth at its nearest edge"):
        filled = tm.coastal.interpolate_bathymetry(unknown, shared_data / "dem" / "CUDEM_equal.nc")
    assert np.isfinite(filled.depth).all()
    partly = coarse.depth.copy()
    partly[far.nonzero()[0][:10]] = np.nan
    partly_known = tm.Mesh(mesh.points, mesh.cells, point_data={"depth": partly}, crs=mesh.crs)
    with pytest.warns(TerrameshWarning, match="keep their depth"):
        mixed = tm.coastal.interpolate_bathymetry(partly_known, shared_data / "dem" / "CUDEM_equal.nc")
    assert np.isfinite(mixed.depth).all() and np.array_equal(mixed.depth[far][10:], coarse.depth[far][10:])
    with pytest.raises(MeshValidityError, match="outside must be one of"):
        tm.coastal.interpolate_bathymetry(coarse, shared_data / "dem" / "CUDEM_equal.nc", outside="nearest")


def test_a_mesh_all_outside_the_dem_is_refused():
    # every vertex took the DEM's nearest edge value, with a warning only: a mesh in metres, or elsewhere
    dem = grid_dem(0.0, 1.0, 0.0, 1.0, 21, lambda x, y: -1.0 + 0 * x)
    with pytest.raises(GeometryError, match=r"all \d+ vertices lie outside the DEM"):
        tm.coastal.interpolate_bathymetry(lonlat_mesh(5.0, 5.0, 6.0, 6.0, 0.2), dem)
    metres = tm.generate_mesh(tm.geometry.Rectangle((100, 100), (2e3, 2e3)), 400)
    with pytest.raises(GeometryError, match=r"^the mesh's coordinates span x 100..2000, y 100..2000: not longitude"):
        tm.coastal.interpolate_bathymetry(metres, dem)


def test_a_mesh_in_metres_is_named_not_a_bbox_the_user_never_gave(shared_data):
    # the DEM is read for the mesh's extent: "bbox latitudes 3.29e+06..3.30e+06 are outside -90..90"
    utm = tm.generate_mesh(tm.geometry.Rectangle((409000.0, 3291000.0), (418000.0, 3302000.0)), 2000.0)
    utm.point_data["depth"] = np.full(utm.n_points, 5.0)
    path = shared_data / "dem" / "CUDEM_equal.nc"
    expected = r"^the mesh's coordinates span x 409000..418000, y 3.291e\+06..3.302e\+06: not longitude, latitude"
    with pytest.raises(GeometryError, match=expected + r" degrees \(a mesh in metres, with no crs\?\).*EPSG:4326'"):
        tm.coastal.interpolate_bathymetry(utm, path)
    utm.crs = "EPSG:32615"
    with pytest.raises(GeometryError, match=expected + r" degrees \(the mesh is in EPSG:32615\)"):
        tm.coastal.make_boundaries(utm, dem=path)
    with pytest.raises(GeometryError, match=r"^reading the DEM for the mesh's extent \(x -89.*\) as its bbox: bbox"):
        tm.coastal.interpolate_bathymetry(lonlat_mesh(-89.0, 34.0, -88.9, 34.1, 0.05), path)


def test_bad_input_raises():
    mesh = lonlat_mesh(0.0, 0.0, 1.0, 1.0, 0.25)
    dem = grid_dem(-0.5, 1.5, -0.5, 1.5, 11, lambda x, y: -1.0 + 0 * x)
    with pytest.raises(MeshValidityError, match="method"):
        tm.coastal.interpolate_bathymetry(mesh, dem, method="nearest")
    with pytest.raises(MeshValidityError, match="min_depth"):
        tm.coastal.interpolate_bathymetry(mesh, dem, min_depth=np.nan)
    with pytest.raises(MeshValidityError, match="dem must be"):
        tm.coastal.interpolate_bathymetry(mesh, 3.0)
    projected = tm.Mesh(mesh.points, mesh.cells, crs="EPSG:3857")
    with pytest.raises(MeshValidityError, match="degrees"):
        tm.coastal.interpolate_bathymetry(projected, dem)
    with pytest.raises(MeshValidityError, match="do not exist"):
        median_dual_average(mesh.points, mesh.cells + mesh.n_points, dem)
    with pytest.raises(MeshValidityError, match="not the DEM's"):
        median_dual_average(mesh.points, mesh.cells, dem, values=np.zeros(3))


def test_a_mesh_taken_as_degrees_says_so_for_the_steps_after():
    # crs None read as degrees here, returned as None, then as planar metres by courant_number: 37,135 where
    # 0.454, and enforce_timestep removed 101 of 517 vertices from a mesh that met its time step
    mesh = tm.generate_mesh(tm.geometry.Rectangle((-70, 42), (-69, 43)), 0.05, seed=0)
    assert mesh.crs is None
    dem = tm.coastal.DEM(np.linspace(-71, -68, 301), np.linspace(41, 44, 301), np.full((301, 301), -50.0))
    deep = tm.coastal.interpolate_bathymetry(mesh, dem)
    assert deep.crs == "EPSG:4326"
    assert tm.coastal.courant_number(deep, 60.0).max() < 1.0


def test_a_dem_as_coarse_as_the_mesh_is_interpolated_not_picked_node_by_node():
    # with one DEM node enough to average, a vertex whose cell caught one took that node's value, up to half a
    # DEM cell away, beside bilinear neighbours: 25 m off on a plane where bilinear is exact
    lon = lat = np.arange(-2, 2.001, 0.1)
    dem = tm.coastal.DEM(lon, lat, -(1000 + 500 * lon[:, None] + 0 * lat[None, :]))
    mesh = tm.generate_mesh(tm.geometry.Rectangle((-1, -1), (1, 1)), 0.12, seed=0)
    mesh.crs = "EPSG:4326"
    depth = tm.coastal.interpolate_bathymetry(mesh, dem).depth
    np.testing.assert_allclose(depth, 1000 + 500 * mesh.points[:, 0], atol=1.0)
