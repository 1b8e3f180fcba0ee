"""tau0 (Calc_tau0) and internal_tide_friction (Calc_IT_Fric): the rules, the fort.13 round trip, renumbering."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.coastal.nodal_attributes import EARTH_ROTATION, M2_FREQUENCY
from terramesh.coastal.timestep import edge_lengths
from terramesh.errors import GeometryError, MeshValidityError, TerrameshWarning
from terramesh.mesh.topology import unique_edges


@pytest.fixture(scope="module")
def shelf():
    """Half a degree square at 40 N, 0.05 degree cells (about 4-5 km), depth 5 m to 2 km eastwards."""
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0.0, 40.0), (0.5, 40.5)), 0.05)
    mesh.crs = "EPSG:4326"
    mesh.point_data["depth"] = 5.0 + 4000.0 * mesh.points[:, 0] ** 2
    return mesh


def mean_edge_length(mesh):
    edges = unique_edges(mesh.cells)
    lengths = edge_lengths(mesh.points, edges, geographic=True)
    table = np.zeros((mesh.n_points, len(edges)))
    table[edges[:, 0], np.arange(len(edges))] = 1.0
    table[edges[:, 1], np.arange(len(edges))] = 1.0
    return table @ lengths / table.sum(axis=1)


def test_tau0_follows_oceanmesh2d_rule(shelf):
    attribute = tm.coastal.tau0(shelf)
    spacing, depth = mean_edge_length(shelf), shelf.depth
    expected = np.where(spacing > 2000.0, np.where(depth <= 10.0, 0.02, 0.005), 0.03)
    assert np.array_equal(attribute.values.ravel(), expected)
    assert attribute.units == "unitless"
    assert {0.02, 0.005} <= set(expected.tolist())
    # finer than the distance cutoff everywhere: the default
    fine = tm.coastal.tau0(shelf, distance_cutoff=1e5)
    assert np.all(fine.values == 0.03) and not fine.non_default.any()
    custom = tm.coastal.tau0(shelf, depth_cutoff=1e4, shallow=0.01)
    assert np.all(custom.values == 0.01)


def listed_nodes(path, name):
    """NumNodesNotDefaultVal of attribute ``name`` in a fort.13 file: the line after its second mention."""
    lines = path.read_text().splitlines()
    return int(lines[[i for i, line in enumerate(lines) if line == name][1] + 1])


def test_tau0_default_is_the_most_common_value_so_the_file_lists_the_fewest_nodes(shelf, tmp_path):
    # 4-5 km cells, coarser than the 2 km cutoff everywhere: no node takes the fine-mesh 0.03, most are deep
    attribute = tm.coastal.tau0(shelf)
    values, counts = np.unique(attribute.values, return_counts=True)
    assert 0.03 not in values
    assert attribute.default.tolist() == [values[np.argmax(counts)]] == [0.005]
    name = "primitive_weighting_in_continuity_equation"
    path = tmp_path / "fort.13"
    tm.coastal.write_fort13(path, {name: attribute}, shelf.n_points)
    assert listed_nodes(path, name) == shelf.n_points - counts.max() == int(np.sum(attribute.values == 0.02))
    back = tm.io.read_fort13(path)[name]
    assert np.array_equal(back.values, attribute.values) and np.array_equal(back.default, attribute.default)
    # mostly shallow: the shallow value is the default
    assert tm.coastal.tau0(shelf, depth_cutoff=1e4).default.tolist() == [0.02]


def test_a_negative_tau0_is_the_default_as_adcirc_reads_it(shelf):
    # ADCIRC applies its depth scheme to negative nodes only under a negative default
    attribute = tm.coastal.tau0(shelf, shallow=-1.0)
    assert attribute.default.tolist() == [-1.0]
    assert np.array_equal(attribute.non_default, attribute.values.ravel() != -1.0)
    with pytest.raises(MeshValidityError, match="negative"):
        tm.coastal.tau0(shelf, shallow=-1.0, deep=-2.0)


def test_tau0_needs_depth(shelf):
    with pytest.raises(MeshValidityError, match="depth"):
        tm.coastal.tau0(tm.Mesh(shelf.points, shelf.cells, crs="EPSG:4326"))
    with pytest.raises(MeshValidityError, match="default"):
        tm.coastal.tau0(shelf, default=np.nan)
    with pytest.raises(MeshValidityError, match="distance_cutoff must be positive"):
        tm.coastal.tau0(shelf, distance_cutoff=-1.0)


def reference_friction(n_b, n_m, hx, hy, lat, depth, c=0.2, cutoff=100.0):
    """The formula of Calc_IT_Fric (local_dir, crit Nb) for one vertex."""
    w = M2_FREQUENCY
    f = 2 * EARTH_ROTATION * np.sin(np.radians(lat))
    product = (n_b**2 - w**2) * (n_m**2 - w**2)
    friction = c * np.sqrt(max(product, 0.0)) / w
    alpha2 = (w**2 - f**2) / (n_b**2 - w**2)
    friction = 0.0 if alpha2 < 0 else friction / max((hx**2 + hy**2) / alpha2, 1.0)
    if depth < cutoff or hx**2 + hy**2 == 0:
        friction = 0.0
    return np.array([friction * hx**2, friction * hy**2, friction * hx * hy])


def test_internal_tide_friction_matches_the_formula_on_a_plane_slope():
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0.0, 40.0), (1.0, 41.0)), 0.1)
    mesh.crs = "EPSG:4326"
    north = 6378137.0 * np.pi / 180.0
    # depth rising 1500 m per degree east and 800 m per degree north: a uniform ground slope (to cos(lat) spread)
    mesh.point_data["depth"] = 200.0 + 1500.0 * mesh.points[:, 0] + 800.0 * (mesh.points[:, 1] - 40.0)
    lon, lat = np.linspace(-1.0, 2.0, 7), np.linspace(39.0, 42.0, 7)
    seabed = np.full((7, 7), 1.5e-3)
    mean = np.full((7, 7), 3e-3)
    attribute = tm.coastal.internal_tide_friction(mesh, (lon, lat, seabed, mean))
    assert attribute.values.shape == (mesh.n_points, 3)
    # no two nodes share a row: one of them is the default, every other one is listed
    assert int(attribute.non_default.sum()) == mesh.n_points - 1
    k = int(np.argmin(np.hypot(mesh.points[:, 0] - 0.5, mesh.points[:, 1] - 40.5)))  # an interior vertex
    hx = 1500.0 / (north * np.cos(np.radians(mesh.points[k, 1])))
    hy = 800.0 / north
    expected = reference_friction(1.5e-3, 3e-3, hx, hy, mesh.points[k, 1], mesh.depth[k])
    assert np.allclose(attribute.values[k], expected, rtol=0.02)
    # one field: N_b = N_m
    single = tm.coastal.internal_tide_friction(mesh, (lon, lat, seabed))
    assert np.allclose(single.values[k], reference_friction(1.5e-3, 1.5e-3, hx, hy, 40.5, 1000.0), rtol=0.02)


def test_internal_tide_friction_cutoffs_and_criticality():
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0.0, 40.0), (1.0, 41.0)), 0.1)
    mesh.crs = "EPSG:4326"
    mesh.point_data["depth"] = 50.0 + 100.0 * mesh.points[:, 0]  # shallower than 100 m west of 0.5 E
    grid = (np.array([-1.0, 2.0]), np.array([39.0, 42.0]), np.full((2, 2), 2e-3))
    friction = tm.coastal.internal_tide_friction(mesh, grid).values
    assert np.all(friction[mesh.depth < 100.0] == 0) and np.all(friction[mesh.depth > 100.0, 0] > 0)
    # a steep (supercritical) slope is normalised: friction grows less than the slope squared
    steep = tm.Mesh(mesh.points, mesh.cells, crs="EPSG:4326", point_data={"depth": 200.0 + 2e5 * mesh.points[:, 0]})
    gentle = tm.Mesh(mesh.points, mesh.cells, crs="EPSG:4326", point_data={"depth": 200.0 + 2e3 * mesh.points[:, 0]})
    gentle_friction = tm.coastal.internal_tide_friction(gentle, grid).values[:, 0]
    ratio = tm.coastal.internal_tide_friction(steep, grid).values[:, 0] / gentle_friction
    assert np.all(ratio < 0.5 * 100.0**2)
    free = tm.coastal.internal_tide_friction(steep, grid, criticality=False).values[:, 0]
    assert np.allclose(free / gentle_friction, 100.0**2, rtol=1e-6)


def test_no_internal_tide_friction_poleward_of_the_critical_latitude():
    """Above about 74.5 degrees the Coriolis frequency exceeds M2's: no freely propagating internal tide."""
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0.0, 76.0), (1.0, 77.0)), 0.2)
    mesh.crs = "EPSG:4326"
    mesh.point_data["depth"] = 500.0 + 1000.0 * mesh.points[:, 0]
    grid = (np.array([-1.0, 2.0]), np.array([70.0, 80.0]), np.full((2, 2), 2e-3))
    assert np.all(tm.coastal.internal_tide_friction(mesh, grid).values == 0)


def test_nan_grid_cells_take_the_nearest_value_and_longitudes_wrap():
    mesh = tm.generate_mesh(tm.geometry.Rectangle((-1.0, 40.0), (0.0, 41.0)), 0.25)
    mesh.crs = "EPSG:4326"
    mesh.point_data["depth"] = 300.0 - 100.0 * mesh.points[:, 0]
    lon, lat = np.array([358.0, 359.0, 360.0, 361.0]), np.array([39.0, 40.0, 41.0, 42.0])  # 0..360 grid
    n = np.full((4, 4), 2e-3)
    n[2:, :] = np.nan  # unknown east of 359: the nearest known value is used
    values = tm.coastal.internal_tide_friction(mesh, (lon, lat, n)).values
    reference = tm.coastal.internal_tide_friction(mesh, (lon - 360.0, lat, np.full((4, 4), 2e-3))).values
    assert np.allclose(values, reference)


def test_attributes_write_read_and_follow_renumbering(shelf, tmp_path):
    grid = (np.array([-1.0, 2.0]), np.array([39.0, 42.0]), np.full((2, 2), 2e-3))
    attributes = {
        "primitive_weighting_in_continuity_equation": tm.coastal.tau0(shelf),
        "internal_tide_friction": tm.coastal.internal_tide_friction(shelf, grid),
    }
    path = tmp_path / "fort.13"
    tm.coastal.write_fort13(path, attributes, shelf.n_points)
    back = tm.io.read_fort13(path)
    for name, attribute in attributes.items():
        assert np.array_equal(back[name].values, attribute.values)
        assert np.array_equal(back[name].default, attribute.default)
    renumbered = tm.coastal.renumber(shelf)
    new_index = renumbered.info["renumber"]["new_index"]
    moved = attributes["primitive_weighting_in_continuity_equation"].renumbered(new_index)
    assert np.array_equal(moved.values, tm.coastal.tau0(renumbered).values)


def test_internal_tide_friction_default_is_the_most_common_row_without_negative_zeros(shelf, tmp_path):
    grid = (np.array([-1.0, 2.0]), np.array([39.0, 42.0]), np.full((2, 2), 2e-3))
    attribute = tm.coastal.internal_tide_friction(shelf, grid)
    rows, counts = np.unique(attribute.values, axis=0, return_counts=True)
    assert np.array_equal(attribute.default, rows[np.argmax(counts)])
    assert int(attribute.non_default.sum()) == shelf.n_points - counts.max()
    # zero friction times a negative hx hy was -0.0: the default was written "-0" or such rows not merged
    assert not np.any(np.signbit(attribute.values) & (attribute.values == 0))
    assert not np.any(np.signbit(attribute.default))
    path = tmp_path / "fort.13"
    tm.coastal.write_fort13(path, {"internal_tide_friction": attribute}, shelf.n_points)
    assert listed_nodes(path, "internal_tide_friction") == shelf.n_points - counts.max()
    assert path.read_text().splitlines()[6] == "0.0 0.0 0.0"  # the default


def test_bad_grids_raise(shelf):
    lon, lat = np.array([0.0, 1.0]), np.array([39.0, 42.0])
    with pytest.raises(GeometryError, match="shape"):
        tm.coastal.internal_tide_friction(shelf, (lon, lat, np.ones((3, 2))))
    with pytest.raises(GeometryError, match="increasing"):
        tm.coastal.internal_tide_friction(shelf, (lon[::-1], lat, np.ones((2, 2))))
    with pytest.raises(GeometryError, match=">= 0"):
        tm.coastal.internal_tide_friction(shelf, (lon, lat, -np.ones((2, 2))))
    with pytest.raises(GeometryError, match="3 or 4"):
        tm.coastal.internal_tide_friction(shelf, (lon, lat))
    with pytest.raises(MeshValidityError, match="frequency"):
        tm.coastal.internal_tide_friction(shelf, (lon, lat, np.ones((2, 2))), frequency=0.0)


def test_a_mesh_in_metres_or_off_the_grid_is_refused(shelf):
    grid = (np.array([-1.0, 2.0]), np.array([39.0, 42.0]), np.full((2, 2), 2e-3))
    in_metres = tm.Mesh(shelf.points * 1e5, shelf.cells, point_data={"depth": shelf.depth})  # no CRS to say so
    with pytest.raises(MeshValidityError, match=r"points \(x 0..50000, y 4e\+06..4.05e\+06\) are not longitude"):
        tm.coastal.internal_tide_friction(in_metres, grid)
    elsewhere = (np.array([20.0, 22.0]), np.array([0.0, 2.0]), np.full((2, 2), 2e-3))
    with pytest.raises(GeometryError, match=r"all \d+ vertices lie outside the buoyancy grid \(lon 20..22, lat 0..2\)"):
        tm.coastal.internal_tide_friction(shelf, elsewhere)
    west = (np.array([-2.0, -0.8]), np.array([39.0, 42.0]), np.full((2, 2), 2e-3))  # a cell's reach: to 0.4 E
    with pytest.warns(TerrameshWarning, match=r"\d+ of \d+ vertices lie outside the buoyancy grid .* its frequencies"):
        tm.coastal.internal_tide_friction(shelf, west)
