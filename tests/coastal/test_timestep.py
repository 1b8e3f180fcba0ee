"""courant_number (CalcCFL) and enforce_timestep (CheckTimestep): the definition, the decimation and its guarantees."""

import re

import numpy as np
import pytest

import terramesh as tm
from terramesh._kernels.timestep import _triangulate
from terramesh.coastal.sizes import wave_speed
from terramesh.coastal.timestep import edge_lengths
from terramesh.errors import MeshValidityError, SizingError, TerrameshWarning
from terramesh.mesh.topology import boundary_edges, signed_areas, unique_edges


@pytest.fixture(scope="module")
def graded():
    """A 1 km square, 20 m deep, with 15 m cells around (500, 500) grading to 80 m: planar metres."""

    def size(p):
        return np.minimum(15.0 + 0.25 * np.hypot(p[:, 0] - 500.0, p[:, 1] - 500.0), 80.0)

    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1000, 1000)), size, h0=15.0)
    mesh.point_data["depth"] = 20.0 + 0.01 * mesh.points[:, 0]
    return mesh


def reference_courant(mesh, dt, geographic=False):
    """Loop-free NumPy reference: the shortest edge at each vertex from a dense vertex-by-edge table."""
    edges = unique_edges(mesh.cells)
    lengths = edge_lengths(mesh.points, edges, geographic=geographic)
    table = np.full((mesh.n_points, len(edges)), np.inf)
    table[edges[:, 0], np.arange(len(edges))] = lengths
    table[edges[:, 1], np.arange(len(edges))] = lengths
    return wave_speed(mesh.depth) * dt / table.min(axis=1)


def test_courant_number_is_eq_10_with_the_shortest_edge(graded):
    cr = tm.coastal.courant_number(graded, 1.5)
    assert cr.shape == (graded.n_points,)
    assert np.allclose(cr, reference_courant(graded, 1.5))


def test_courant_number_on_the_sphere_and_the_critical_branch():
    points = np.array([[0.0, 60.0], [0.001, 60.0], [0.0, 60.001]])
    mesh = tm.Mesh(points, [[0, 1, 2]], point_data={"depth": np.array([1.0, -3.0, 100.0])}, crs="EPSG:4326")
    cr = tm.coastal.courant_number(mesh, 1.0)
    east = 6378137.0 * np.radians(0.001) * np.cos(np.radians(60.0))  # the shortest edge, ground metres
    # h < eta (land too): critical flow at eta = 2 m, speed 2 sqrt(g eta)
    assert np.allclose(cr[:2], 2 * np.sqrt(9.81 * 2.0) / east, rtol=1e-4)
    assert np.allclose(cr, reference_courant(mesh, 1.0, geographic=True))
    assert np.allclose(tm.coastal.courant_number(mesh, 1.0, eta=1.0)[0], 2 * np.sqrt(9.81) / east, rtol=1e-4)


def test_enforce_timestep_meets_the_target_and_keeps_the_mesh_valid(graded):
    dt = 1.0
    before = tm.coastal.courant_number(graded, dt)
    assert before.max() > 0.5
    result = tm.coastal.enforce_timestep(graded, dt)
    report = result.info["timestep"]
    assert tm.coastal.courant_number(result, dt).max() <= 0.5
    assert report["violations_after"] == 0 and report["max_courant_after"] <= 0.5
    assert report["violations_before"] == int(np.sum(before > 0.5)) and report["removed"] > 0
    assert result.n_points == graded.n_points - report["removed"]
    assert tm.cleanup.mesh_problems(result) == []
    assert tm.quality.triangle_quality(result.points, result.cells).min() >= 0.3
    # no vertex moved and each keeps its depth
    index = {tuple(p): i for i, p in enumerate(graded.points.tolist())}
    source = np.array([index[tuple(p)] for p in result.points.tolist()])
    assert np.array_equal(result.depth, graded.depth[source])
    # only vertices inside the fine zone went, and the square is still a square to within a sliver per corner
    gone = np.setdiff1d(np.arange(graded.n_points), source)
    assert np.all(np.hypot(*(graded.points[gone] - 500.0).T) < 300.0)
    assert abs(signed_areas(result.points, result.cells).sum() - 1e6) < 1e-6 * 1e6


def test_enforce_timestep_leaves_a_good_mesh_alone(graded):
    with_boundaries = tm.coastal.make_boundaries(graded, open_by="bbox")
    result = tm.coastal.enforce_timestep(with_boundaries, 0.2)
    assert result.info["timestep"]["removed"] == 0 and result.info["timestep"]["rounds"] == 0
    assert np.array_equal(result.points, graded.points) and np.array_equal(result.cells, graded.cells)
    assert np.array_equal(result.boundaries.open[0].nodes, with_boundaries.boundaries.open[0].nodes)


def test_boundaries_are_made_again_with_their_options(graded):
    mesh = tm.coastal.make_boundaries(graded, bbox=(0.0, 1000.0, -1.0, 2000.0), open_by="bbox")
    points, cells = mesh.points.copy(), mesh.cells.copy()
    result = tm.coastal.enforce_timestep(mesh, 1.0)
    assert np.array_equal(mesh.points, points) and np.array_equal(mesh.cells, cells)  # input untouched
    assert result.info["timestep"]["removed"] > 0
    assert len(result.boundaries.open) == 2  # west and east sides, as asked the first time
    assert result.boundaries.open[0].nodes.max() < result.n_points


def test_boundaries_edited_after_make_boundaries_are_carried_over(graded):
    # they were made again from make_boundaries' options: the edited IBTYPE and a weir's columns went, silently
    mesh = tm.coastal.make_boundaries(graded, bbox=(0.0, 1000.0, -1.0, 2000.0), open_by="bbox")
    for land in mesh.boundaries.land:
        land.ibtype = 23
        land.values = mesh.points[land.nodes].copy()
    result = tm.coastal.enforce_timestep(mesh, 1.0)
    assert result.info["timestep"]["removed"] > 0
    assert [land.ibtype for land in result.boundaries.land] == [23] * len(mesh.boundaries.land)
    for land in result.boundaries.land:
        assert np.array_equal(land.values, result.points[land.nodes])


def hand_made(mesh, bbox):
    """``mesh`` with boundaries as a fort.14 made elsewhere brings them: open on the ``bbox`` sides, the rest one
    IBTYPE 23 barrier string whose two columns are its nodes' coordinates, and no make_boundaries options."""
    from terramesh.io.fort14 import Boundaries, LandBoundary

    made = tm.coastal.make_boundaries(mesh, bbox=bbox, open_by="bbox").boundaries
    assert len(made.open) == 1 and len(made.land) == 1
    nodes = made.land[0].nodes
    barrier = LandBoundary(nodes, 23, None, mesh.points[nodes].copy())
    boundaries = Boundaries(made.open, [barrier])
    return tm.Mesh(mesh.points, mesh.cells, point_data=dict(mesh.point_data), boundaries=boundaries)


def test_hand_made_boundaries_are_renumbered_when_only_interior_vertices_go(graded):
    # they were replaced by one open ring round the whole outline, with no land boundary
    mesh = hand_made(graded, (-1.0, 1000.0, -1.0, 1001.0))
    result = tm.coastal.enforce_timestep(mesh, 1.0)
    assert result.info["timestep"]["removed"] > 0 and "boundaries" not in result.info
    (opened,), (barrier,) = result.boundaries.open, result.boundaries.land
    assert np.array_equal(result.points[opened.nodes], mesh.points[mesh.boundaries.open[0].nodes])
    assert barrier.ibtype == 23 and np.array_equal(result.points[barrier.nodes], mesh.boundaries.land[0].values)
    assert np.array_equal(barrier.values, mesh.boundaries.land[0].values)


def test_hand_made_boundaries_lose_only_the_nodes_removed():
    mesh = hand_made(boundary_graded(False), (-1.0, 400.0, -1.0, 301.0))  # open east, fine south in the barrier
    result = tm.coastal.enforce_timestep(mesh, 0.5)
    assert tm.coastal.courant_number(result, 0.5).max() <= 0.5
    (opened,), (barrier,) = result.boundaries.open, result.boundaries.land
    assert len(barrier.nodes) < len(mesh.boundaries.land[0].nodes)  # boundary vertices went
    # each row keeps its columns, the strings still meet at the east corners and tile the boundary
    assert barrier.ibtype == 23 and np.array_equal(barrier.values, result.points[barrier.nodes])
    assert np.array_equal(result.points[opened.nodes[[0, -1]]], [[400.0, 0.0], [400.0, 300.0]])
    assert opened.nodes[-1] == barrier.nodes[0] and barrier.nodes[-1] == opened.nodes[0]
    used = [(a, b) for string in (opened, barrier) for a, b in zip(string.nodes[:-1], string.nodes[1:], strict=True)]
    assert sorted(used) == sorted(map(tuple, boundary_edges(result.cells).tolist()))


def test_barrier_nodes_and_the_ends_of_hand_made_strings_stay():
    from terramesh.io.fort14 import Boundaries, LandBoundary

    mesh = hand_made(boundary_graded(False), (-1.0, 400.0, -1.0, 301.0))
    # a weir pair (IBTYPE 24) along the fine southern side, its back face the fine foot of the western one
    x, y = mesh.points.T
    front = np.flatnonzero((y == 0) & (x > 150) & (x < 200))
    front = front[np.argsort(x[front])]
    back = np.flatnonzero(x == 0)[: len(front)]
    weir = LandBoundary(front, 24, back, np.arange(3.0 * len(front)).reshape(-1, 3))
    mesh.boundaries = Boundaries(mesh.boundaries.open, [*mesh.boundaries.land, weir])
    with pytest.warns(TerrameshWarning, match="end a boundary string or belong to a barrier, and were kept"):
        result = tm.coastal.enforce_timestep(mesh, 0.5)
    assert result.info["timestep"]["removed"] > 0
    kept = result.boundaries.land[-1]
    assert kept.ibtype == 24 and np.array_equal(kept.values, weir.values)
    assert np.array_equal(result.points[kept.nodes], mesh.points[front])
    assert np.array_equal(result.points[kept.paired_nodes], mesh.points[back])
    (opened,) = result.boundaries.open
    assert np.array_equal(result.points[opened.nodes[[0, -1]]], [[400.0, 0.0], [400.0, 300.0]])


def test_boundary_vertices_go_at_corners_with_room(graded):
    """A fine boundary (5 m edges along y = 0 in 10 m water): the boundary vertices go too."""

    def size(p):
        return np.minimum(5.0 + 0.3 * np.abs(p[:, 1]), 60.0)

    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (400, 300)), size, h0=5.0)
    mesh.point_data["depth"] = np.full(mesh.n_points, 10.0)
    result = tm.coastal.enforce_timestep(mesh, 0.5, courant=0.6)
    assert tm.coastal.courant_number(result, 0.5).max() <= 0.6
    assert tm.cleanup.mesh_problems(result) == []
    assert np.isclose(signed_areas(result.points, result.cells).sum(), 400 * 300, rtol=1e-3)


def test_warns_when_max_rounds_is_too_few(graded):
    with pytest.warns(TerrameshWarning, match="max_rounds"):
        result = tm.coastal.enforce_timestep(graded, 1.0, max_rounds=1)
    assert result.info["timestep"]["rounds"] == 1 and result.info["timestep"]["violations_after"] > 0


def test_bad_input_raises(graded):
    no_depth = tm.Mesh(graded.points, graded.cells)
    with pytest.raises(MeshValidityError, match="depth"):
        tm.coastal.courant_number(no_depth, 1.0)
    nan_depth = tm.Mesh(graded.points, graded.cells, point_data={"depth": np.full(graded.n_points, np.nan)})
    with pytest.raises(MeshValidityError, match="NaN"):
        tm.coastal.enforce_timestep(nan_depth, 1.0)
    for dt in (0.0, -1.0, np.inf):
        with pytest.raises(SizingError, match="dt"):
            tm.coastal.courant_number(graded, dt)
    with pytest.raises(SizingError, match="courant"):
        tm.coastal.enforce_timestep(graded, 1.0, courant=0.0)
    with pytest.raises(SizingError, match="max_rounds"):
        tm.coastal.enforce_timestep(graded, 1.0, max_rounds=-1)


def lonlat_square(crs):
    """A 0.1 degree square off Cape Cod (about 0.01 degree, 850-1,110 m edges), 20 m deep."""
    mesh = tm.generate_mesh(tm.geometry.Rectangle((-70.0, 40.0), (-69.9, 40.1)), 0.01)
    mesh.point_data["depth"] = np.full(mesh.n_points, 20.0)
    mesh.crs = crs
    return mesh


def test_a_mesh_in_degrees_without_a_crs_is_refused_before_anything_goes():
    # its degrees were taken as metres: Cr 6,896 for 0.066 on a coastal mesh, and enforce_timestep removed 299 of
    # its 315 vertices with only a warning that 16 still broke the target
    degrees = lonlat_square(None)
    true_largest = tm.coastal.courant_number(lonlat_square("EPSG:4326"), 10.0).max()
    assert 0.1 < true_largest < 0.5
    with pytest.warns(TerrameshWarning, match=r'give the mesh crs="EPSG:4326" or pass geographic=True') as caught:
        taken_as_metres = tm.coastal.courant_number(degrees, 10.0)
    assert taken_as_metres.max() > 1e4 and f"is {true_largest:.3g})" in str(caught[0].message)
    assert np.allclose(tm.coastal.courant_number(degrees, 10.0, geographic=True), true_largest, atol=0.2)
    tm.coastal.courant_number(degrees, 10.0, geographic=False)  # metres said: no warning
    points, cells = degrees.points.copy(), degrees.cells.copy()
    with pytest.raises(SizingError, match=r"leave under 0.01 % of the \d+ vertices, so none was removed") as error:
        tm.coastal.enforce_timestep(degrees, 10.0)
    assert 'crs="EPSG:4326" or pass geographic=True' in str(error.value) and "dt is not in seconds" in str(error.value)
    assert np.array_equal(degrees.points, points) and np.array_equal(degrees.cells, cells)
    assert tm.coastal.enforce_timestep(degrees, 10.0, geographic=True).info["timestep"]["removed"] == 0


@pytest.mark.parametrize("dt", [60.0, 2000.0, 1e6])
def test_a_time_step_far_too_long_is_refused_before_anything_goes(graded, dt):
    # dt = 2000 s took a 315-vertex coastal mesh to 8 vertices with only a warning; here at 60 s (1 s in minutes)
    # Cr is 11 or more everywhere (median 17), where meeting 0.5 would keep about 0.1 % of the vertices
    message = re.escape(f"at dt = {dt:g} s") + ".* Likely causes: dt is not in seconds"
    with pytest.raises(SizingError, match=message) as error:
        tm.coastal.enforce_timestep(graded, dt)
    assert "crs" not in str(error.value)  # 0..1000: not degrees
    with pytest.raises(SizingError, match="Likely causes: the mesh has no crs"):
        tm.coastal.enforce_timestep(lonlat_square(None), dt)
    with pytest.raises(SizingError, match="Likely causes: dt is not in seconds"):
        tm.coastal.enforce_timestep(lonlat_square("EPSG:4326"), 100 * dt)


def test_a_small_metric_mesh_within_longitude_latitude_ranges_is_measured_in_metres():
    """A 150 m square whose coordinates could be degrees, 10 m cells at its centre, 20 m deep, dt = 1 s."""

    def size(p):
        return 10.0 + 0.3 * np.hypot(p[:, 0] - 75.0, p[:, 1] - 75.0)

    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (150, 80)), size, h0=10.0)
    mesh.point_data["depth"] = np.full(mesh.n_points, 20.0)
    assert tm.coastal.courant_number(mesh, 1.0).max() > 1.0  # above the target, and no warning
    result = tm.coastal.enforce_timestep(mesh, 1.0)
    assert result.info["timestep"]["removed"] > 0 and tm.coastal.courant_number(result, 1.0).max() <= 0.5


@pytest.mark.parametrize("case", ["a repeated corner", "three corners on a line", "a sliver 1e-5 m thick"])
def test_a_mesh_with_a_degenerate_cell_is_refused(graded, case):
    # a zero-length edge: NumPy's divide-by-zero warning and Cr = inf; enforce_timestep's repair dropped the cell
    # (as it drops any of quality below 1e-6, fix_mesh's degenerate cells)
    if case == "a repeated corner":
        cells = graded.cells.copy()
        cells[10] = [cells[10, 0], cells[10, 0], cells[10, 1]]
        mesh = tm.Mesh(graded.points, cells, point_data=dict(graded.point_data))
    elif case == "three corners on a line":
        points = np.array([[0.0, 0.0], [100.0, 0.0], [200.0, 0.0], [100.0, 100.0]])
        mesh = tm.Mesh(points, [[0, 1, 3], [1, 2, 3], [0, 1, 2]], point_data={"depth": np.full(4, 10.0)})
    else:  # quality 1.7e-7, below a 100 m triangle
        points = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [100.0, -1e-5]])
        mesh = tm.Mesh(points, [[0, 1, 2], [0, 3, 1]], point_data={"depth": np.full(4, 10.0)})
    for check in (tm.coastal.courant_number, tm.coastal.enforce_timestep):
        expected = check.__name__ + r": 1 of \d+ cells are degenerate, of zero area, .*\(terramesh\.cleanup\.fix_mesh\)"
        with pytest.raises(MeshValidityError, match=expected):
            check(mesh, 1.0)


def triangulate(xy, ring, min_quality=0.0):
    out = np.empty((len(ring), 3), dtype=np.int64)
    ring = np.ascontiguousarray(ring, dtype=np.int64)
    k = _triangulate(np.ascontiguousarray(xy, dtype=np.float64), ring, 1e-12, min_quality, out, 0)
    return None if k < 0 else out[:k]


def polygon_area(xy):
    x, y = np.asarray(xy, dtype=float).T
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def test_hole_triangulation_is_valid_and_at_least_as_good_as_any_fan():
    angles = np.sort(np.random.default_rng(1).uniform(0, 2 * np.pi, 8))
    xy = np.column_stack([np.cos(angles), 0.6 * np.sin(angles)])
    cells = triangulate(xy, np.arange(8))
    assert len(cells) == 6 and np.all(signed_areas(xy, cells) > 0)
    assert np.isclose(signed_areas(xy, cells).sum(), polygon_area(xy))
    best = tm.quality.triangle_quality(xy, cells).min()
    for apex in range(8):  # every fan is one of the triangulations the search considered
        fan = np.array([[apex, (apex + i) % 8, (apex + i + 1) % 8] for i in range(1, 7)])
        assert best >= tm.quality.triangle_quality(xy, fan).min() - 1e-12


def test_hole_triangulation_of_a_non_convex_polygon_stays_inside():
    xy = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]])  # an L
    cells = triangulate(xy, np.arange(6))
    assert np.all(signed_areas(xy, cells) > 0) and np.isclose(signed_areas(xy, cells).sum(), 3.0)
    assert triangulate(xy, np.arange(6)[::-1]) is None  # clockwise: refused
    assert triangulate(xy, [0, 1, 2, 0, 4, 5]) is None  # a repeated vertex: not simple
    assert triangulate(xy, np.arange(6), min_quality=0.99) is None  # no triangulation that good


def test_a_vertex_that_cannot_go_gives_up_the_far_end_of_its_shortest_edge():
    from terramesh.coastal.timestep import _shortest_edge_ends

    xy = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.3], [2.0, 2.0]])
    edges = np.array([[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]])
    blocked = np.array([True, False, False, True])
    cr = np.array([0.9, 0.1, 0.2, 0.7])
    far_end, courant = _shortest_edge_ends(edges, xy, blocked, cr)
    # vertex 0: edges of length 1 and 0.3 -> vertex 2; vertex 3: sqrt(5) and sqrt(2 ** 2 + 1.7 ** 2) -> vertex 1
    assert far_end.tolist() == [2, 1] and courant.tolist() == [0.9, 0.7]


def test_a_boundary_vertex_is_not_removed_across_an_inlet(shared_data):
    # the chord closing a boundary vertex's hole met the far bank of a narrow inlet: the refilled hole lay
    # over cells there (7e-6 square degrees in the Gulf of Maine), which fix_mesh could not undo
    dem = shared_data / "dem" / "ETOPO1_0.1.grd"
    mesh = tm.coastal.build(
        (-71.0, -65.0, 41.0, 45.0), shared_data / "coast" / "GSHHS_l_L1.shp", dem,
        min_el=3000, max_el=30e3, fs=3, wl=40, slp=20, g=0.2, dt=0, itmax=30, boundaries={"dry_depth": 1.0},
    )  # fmt: skip
    mesh = tm.coastal.make_boundaries(tm.coastal.interpolate_bathymetry(mesh, dem, min_depth=1.0))
    enforced = tm.coastal.enforce_timestep(mesh, 60.0)
    assert tm.cleanup.mesh_problems(enforced) == []
    assert enforced.n_points < mesh.n_points and np.nanmax(tm.coastal.courant_number(enforced, 60.0)) <= 0.5 + 1e-9


def boundary_graded(geographic):
    """A strip fine along its southern side (5 m, or 0.0005 degrees, about 43 m at 40 N), 10 m deep."""
    if geographic:
        box, fine, grade, coarse = ((0.0, 40.0), (0.2, 40.15)), 5e-4, 0.3, 6e-3
    else:
        box, fine, grade, coarse = ((0.0, 0.0), (400.0, 300.0)), 5.0, 0.3, 60.0

    def size(p):
        return np.minimum(fine + grade * np.abs(p[:, 1] - box[0][1]), coarse)

    mesh = tm.generate_mesh(tm.geometry.Rectangle(*box), size, h0=fine)
    mesh.point_data["depth"] = np.full(mesh.n_points, 10.0)
    if geographic:
        mesh.crs = "EPSG:4326"
    return mesh


@pytest.mark.parametrize("case", ["graded", "planar boundary", "geographic boundary"])
def test_rounds_that_repair_and_measure_only_what_they_changed_give_the_same_mesh(graded, case, monkeypatch):
    import terramesh.coastal.timestep as timestep

    mesh, dt = {
        "graded": (graded, 1.0),
        "planar boundary": (boundary_graded(False), 0.5),
        "geographic boundary": (boundary_graded(True), 3.0),
    }[case]
    repairs = []
    fix_mesh = timestep.fix_mesh
    monkeypatch.setattr(timestep, "fix_mesh", lambda *args, **kwargs: repairs.append(1) or fix_mesh(*args, **kwargs))
    local = tm.coastal.enforce_timestep(mesh, dt)
    local_repairs = len(repairs)
    # the whole mesh repaired and its Courant numbers computed again after every round
    monkeypatch.setattr(timestep, "_fills_need_no_repair", lambda *args: False)
    whole = tm.coastal.enforce_timestep(mesh, dt)
    report = local.info["timestep"]
    assert report["rounds"] > 2 and report["removed"] > 0 and local_repairs < report["rounds"]
    assert len(repairs) - local_repairs == report["rounds"]
    assert report == whole.info["timestep"]
    assert np.array_equal(local.points, whole.points) and np.array_equal(local.cells, whole.cells)
    assert local.point_data.keys() == whole.point_data.keys() == {"depth"}
    assert np.array_equal(local.depth, whole.depth)
    cr = tm.coastal.courant_number(local, dt)
    assert report["max_courant_after"] == float(cr.max()) and report["violations_after"] == int(np.sum(cr > 0.5))
    assert tm.cleanup.mesh_problems(local) == []


def test_a_valid_mesh_is_not_repaired_first_and_an_invalid_one_is(graded, monkeypatch):
    # the first round repaired every input (1.2 of 2.5 s on the guide's US East Coast mesh at dt = 8 s);
    # a valid one, which the repair returns as it is, now goes straight to the rounds' local checks
    import terramesh.coastal.timestep as timestep

    repairs = []
    fix_mesh = timestep.fix_mesh
    monkeypatch.setattr(timestep, "fix_mesh", lambda *args, **kwargs: repairs.append(1) or fix_mesh(*args, **kwargs))
    local = tm.coastal.enforce_timestep(graded, 1.0)
    assert local.info["timestep"]["removed"] > 0 and repairs == []
    # an unused vertex (a rule mesh_problems names) at the end: the first round repairs, and drops it
    extra = tm.Mesh(np.vstack([graded.points, [[2000.0, 2000.0]]]), graded.cells,
                    point_data={"depth": np.append(graded.depth, 20.0)})  # fmt: skip
    assert tm.cleanup.mesh_problems(extra) != []
    repaired = tm.coastal.enforce_timestep(extra, 1.0)
    assert len(repairs) >= 1
    assert np.array_equal(repaired.points, local.points) and np.array_equal(repaired.cells, local.cells)
    assert repaired.info["timestep"] == local.info["timestep"]


def test_a_fill_that_breaks_a_rule_where_it_lies_is_repaired():
    from scipy.spatial import cKDTree

    from terramesh.coastal.timestep import _fills_need_no_repair, _Round
    from terramesh.mesh.topology import boundary_edges

    # a square's four cells around its centre (4), which goes: the hole filled by two cells
    points = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]])
    before = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    alive, tree = np.ones(5, dtype=bool), cKDTree(points)
    none = np.zeros(0, dtype=np.int64)

    def fine(cells, new_cells):
        step = _Round(cells, np.zeros(5, dtype=bool), np.array([4]), new_cells, np.arange(4), (none,) * 3,
                      boundary_edges(before))  # fmt: skip
        return _fills_need_no_repair(points, tree, alive, step, False)

    fill = np.array([[0, 1, 2], [0, 2, 3]])
    assert fine(fill, fill)
    assert not fine(fill[:, ::-1], fill[:, ::-1])  # clockwise
    assert not fine(np.array([[0, 1, 2], [0, 2, 3], [0, 1, 3]]), fill)  # two cells on one side of 0-1
    assert not fine(np.zeros((0, 3), dtype=np.int64), np.zeros((0, 3), dtype=np.int64))  # nothing left


@pytest.mark.parametrize("case", ["a side's vertex", "an island of three", "an island of four from two sides"])
def test_the_boundary_after_a_round_is_the_cells_boundary(case):
    # carried from round to round instead of found among every edge of the mesh (8-26 ms a round at 587k
    # cells): a boundary vertex's two edges give way to its chord; an island that closes up leaves no boundary
    from scipy.spatial import Delaunay

    from terramesh.coastal.timestep import _boundary_after, _Round
    from terramesh.mesh.topology import boundary_edges, signed_areas

    extra, gone = {
        "a side's vertex": ([[2.0, 0.0], [2.0, 2.0], [3.0, 3.0]], [4]),
        "an island of three": ([[1.5, 1.5], [2.5, 1.5], [2.0, 2.5]], [4]),
        "an island of four from two sides": ([[2.0, 1.5], [2.5, 2.0], [2.0, 2.5], [1.5, 2.0]], [4, 6]),
    }[case]
    points = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]] + extra)
    island = np.arange(4, len(points)) if case.startswith("an island") else np.zeros(0, dtype=np.int64)

    def triangulated(kept, hole):
        cells = kept[Delaunay(points[kept]).simplices]
        clockwise = signed_areas(points, cells) < 0
        cells[clockwise] = cells[clockwise][:, ::-1]
        return cells[~np.all(np.isin(cells, island), axis=1)] if hole else cells

    before = triangulated(np.arange(len(points)), hole=True)
    boundary = boundary_edges(before)
    following = dict(boundary.tolist())
    previous = {b: a for a, b in boundary.tolist()}
    after = triangulated(np.setdiff1d(np.arange(len(points)), gone), hole=False)
    gone = np.array(gone)
    corners = (np.array([previous[v] for v in gone]), gone, np.array([following[v] for v in gone]))
    step = _Round(after, np.zeros(len(points), dtype=bool), gone, after[:0], np.arange(4), corners, boundary)
    assert sorted(map(tuple, _boundary_after(step).tolist())) == sorted(map(tuple, boundary_edges(after).tolist()))
    assert len(boundary) == {"a side's vertex": 5, "an island of three": 7}.get(case, 8)
    assert len(_boundary_after(step)) == 4


def test_a_chord_across_a_long_boundary_edge_far_from_its_ends_crosses_it():
    # edges longer than LONG_EDGE medians (241 km offshore among 1.6 km ones) are looked at by every chord, not
    # found near it: a chord's reach sized by them took in 5,000 vertices each (review of 7103ef8)
    from scipy.spatial import cKDTree

    from terramesh.coastal.timestep import _chords_cross

    shore = np.column_stack([np.arange(50.0), np.zeros(50)])  # 49 unit edges along y = 0
    points = np.vstack([shore, [[-500.0, 10.0], [500.0, 10.0], [0.0, 9.0], [0.0, 11.0], [20.0, 9.0], [21.0, 9.0]]])
    edges = np.vstack([np.column_stack([np.arange(49), np.arange(1, 50)]), [[50, 51]]])  # and one 1,000 long at y = 10
    crossing = _chords_cross(points, cKDTree(points), edges, np.array([52, 54]), np.array([53, 55]))
    assert crossing.tolist() == [True, False]  # (0, 9)-(0, 11) crosses the long edge 500 from either end
