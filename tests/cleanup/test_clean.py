import warnings

import numpy as np
import pytest

import terramesh as tm
from terramesh.cleanup import clean, fix_mesh, low_valence_points, mesh_problems, smooth_points
from terramesh.errors import MeshValidityError, TerrameshWarning
from terramesh.mesh.topology import boundary_edges, signed_areas
from terramesh.quality import triangle_quality
from terramesh.sizing import metric_tensor

from .test_repair import raw_barrier_triangulation

LAGOON = tm.geometry.Rectangle((0, 0), (4, 2))


@pytest.fixture(scope="module")
def lagoon():
    return tm.generate_mesh(LAGOON, 0.2, seed=0)


@pytest.fixture(scope="module")
def barrier_raw():
    """Raw triangulation of a lagoon with barrier islands thinner than an element, before any repair."""
    return raw_barrier_triangulation()


def test_clean_after_repair_raises_the_quality_and_stays_valid(barrier_raw):
    domain, points, cells = barrier_raw
    fixed = fix_mesh(points, cells)
    cleaned = clean(points, cells, domain=domain)
    assert mesh_problems(cleaned, domain) == []
    # without the domain, shore vertices of the islands the cells cross are smoothed too: still a valid mesh
    assert mesh_problems(clean(points, cells)) == []
    report = cleaned.info["repair"]
    assert report.interior_cells >= fixed.info["repair"].interior_cells  # the fix ran first
    assert report.smoothed_points > 0.3 * cleaned.n_points  # the generator smoothed its points already
    q_fixed = triangle_quality(fixed.points, fixed.cells)
    q_clean = triangle_quality(cleaned.points, cleaned.cells)
    assert q_clean.min() >= q_fixed.min()
    assert q_clean.mean() - 3 * q_clean.std() > q_fixed.mean() - 3 * q_fixed.std()
    assert q_clean[_cells_with_boundary_edge(cleaned.cells)].min() >= 0.25
    # boundary vertices do not move: the shoreline stays where it was
    on_boundary = np.unique(boundary_edges(cleaned.cells))
    assert {tuple(p) for p in cleaned.points[on_boundary].tolist()} <= {tuple(p) for p in points.tolist()}


def _cells_with_boundary_edge(cells):
    table = tm.mesh.topology.cell_neighbor_table(cells)
    return np.flatnonzero(np.any(table < 0, axis=1))


def test_valence_three_vertex_goes_and_its_three_cells_become_one(lagoon):
    # split one interior cell at its centroid: the new vertex has valence 3
    interior = np.setdiff1d(np.arange(lagoon.n_cells), _cells_with_boundary_edge(lagoon.cells))
    target = interior[len(interior) // 2]
    a, b, c = lagoon.cells[target]
    centre = lagoon.n_points
    points = np.vstack([lagoon.points, lagoon.points[[a, b, c]].mean(axis=0)])
    cells = np.vstack([np.delete(lagoon.cells, target, axis=0), [[a, b, centre], [b, c, centre], [c, a, centre]]])
    assert low_valence_points(points, cells)[1].tolist() == [centre]
    assert low_valence_points(points, cells)[0].tolist() == []  # the rectangle's 90 degree corners are no spikes

    cleaned = clean(points, cells, smoothing_passes=0)
    assert cleaned.info["repair"].low_valence_points == 1
    assert (cleaned.n_points, cleaned.n_cells) == (lagoon.n_points, lagoon.n_cells)
    assert {tuple(sorted(c)) for c in cleaned.cells.tolist()} == {tuple(sorted(c)) for c in lagoon.cells.tolist()}
    assert signed_areas(cleaned.points, cleaned.cells).sum() == pytest.approx(8.0)


def test_spike_on_the_boundary_goes(lagoon):
    # a vertex below the bottom edge in one cell only: a spike of two boundary edges, 44 degrees sharp
    edges = boundary_edges(lagoon.cells)
    bottom = edges[np.all(lagoon.points[edges, 1] < 1e-9, axis=1)][0]
    spike = lagoon.n_points
    half = 0.5 * np.linalg.norm(np.diff(lagoon.points[bottom], axis=0))
    points = np.vstack([lagoon.points, lagoon.points[bottom].mean(axis=0) - [0, 2.5 * half]])
    cells = np.vstack([lagoon.cells, [[bottom[1], bottom[0], spike]]])
    assert mesh_problems(tm.Mesh(points, cells)) == []
    assert low_valence_points(points, cells)[0].tolist() == [spike]
    assert low_valence_points(points, cells, spike_angle=30)[0].tolist() == []

    cleaned = clean(points, cells, min_quality=0, smoothing_passes=0)
    assert cleaned.info["repair"].low_valence_points == 1
    assert cleaned.n_points == lagoon.n_points and cleaned.n_cells == lagoon.n_cells
    assert mesh_problems(cleaned) == []


def test_a_strip_one_cell_wide_goes_in_one_round(lagoon):
    # a spit of 14 equilateral cells below the bottom edge: only its tip is a spike (60 degrees) at first,
    # and each removal makes the next vertex one; removed once per round, it needed 14 rounds (limit 10)
    edges = boundary_edges(lagoon.cells)
    start, end = edges[np.all(lagoon.points[edges, 1] < 1e-9, axis=1)][0][::-1]
    corner_a, corner_b = lagoon.points[start], lagoon.points[end]
    along = corner_b - corner_a
    step = 0.5 * along + np.sqrt(3) / 2 * np.array([along[1], -along[0]]) * np.sign(along[0])  # down the strip
    strip = (np.stack([corner_a, corner_b])[None] + np.arange(1, 8)[:, None, None] * step).reshape(-1, 2)
    assert np.all(strip[:, 1] < 0)  # outside the lagoon
    points = np.vstack([lagoon.points, strip])
    chain = np.concatenate([[start, end], lagoon.n_points + np.arange(len(strip))])
    cells = np.column_stack([chain[:-2], chain[1:-1], chain[2:]])
    clockwise = signed_areas(points, cells) < 0
    cells[clockwise] = cells[clockwise][:, [1, 0, 2]]
    points_before, cells = points, np.vstack([lagoon.cells, cells])
    assert mesh_problems(tm.Mesh(points_before, cells)) == []
    assert len(low_valence_points(points_before, cells)[0]) == 1

    with pytest.warns(TerrameshWarning, match="clean removed 3.1 % of the mesh's area") as caught:  # the spit
        cleaned = clean(points_before, cells, min_quality=0, smoothing_passes=0, max_rounds=2)
    assert not any("max_rounds" in str(w.message) and "reached" in str(w.message) for w in caught)  # done

    assert cleaned.info["repair"].low_valence_points == 14
    assert (cleaned.n_points, cleaned.n_cells) == (lagoon.n_points, lagoon.n_cells)
    assert mesh_problems(cleaned) == []


def test_spike_angles_are_measured_on_the_ground_for_geographic_points():
    # at 60 N a cell 1 degree wide and 0.5 high has a right angle at its apex in degrees, 53 degrees on the
    # ground (longitudes shrink by cos(lat) = 0.5); its base angles are 45 and 63.5 degrees
    points = np.array([[0.0, 60.0], [1.0, 60.0], [0.5, 60.5]])
    cells = np.array([[0, 1, 2]])
    assert low_valence_points(points, cells)[0].tolist() == [0, 1]
    assert low_valence_points(points, cells, geographic=True)[0].tolist() == [0, 1, 2]
    assert low_valence_points(points, cells, spike_angle=50, geographic=True)[0].tolist() == []


def _spikes_removed_round_by_round(points, cells, spike_angle, geographic):
    """The reference: every spike of the mesh found and its cell removed, round after round, until none is left."""
    removed = 0
    while len(cells):
        spikes, centres = low_valence_points(points, cells, spike_angle=spike_angle, geographic=geographic)
        if len(spikes) == 0:
            return cells, removed, centres
        cells = cells[~np.isin(cells, spikes).any(axis=1)]
        removed += len(spikes)
    return cells, removed, np.empty(0, dtype=np.int64)


@pytest.mark.parametrize("geographic", [False, True])
@pytest.mark.parametrize("seed", range(12))
def test_spikes_peeled_as_round_by_round_removal_does(seed, geographic):
    # ragged meshes: a Delaunay triangulation of random points with a third of its cells deleted at random,
    # so strips, spits and pinched vertices abound, and each removal may expose the next spike
    from scipy.spatial import Delaunay

    from terramesh._kernels.cleanup import neighbor_table
    from terramesh.cleanup.clean import without_spikes

    rng = np.random.default_rng(seed)
    points = rng.random((300, 2)) * ([2.0, 1.0] if geographic else [1.0, 1.0]) + ([-70.0, 40.0] if geographic else 0)
    cells = Delaunay(points).simplices.astype(np.int64)
    cells = cells[rng.random(len(cells)) > 0.35]
    cells[signed_areas(points, cells) < 0] = cells[signed_areas(points, cells) < 0][:, [1, 0, 2]]
    table = neighbor_table(cells, len(points))
    spike_angle = rng.uniform(40.0, 100.0)

    peeled, peeled_table, removed, centres = without_spikes(points, cells, table, spike_angle, geographic)
    expected, expected_removed, expected_centres = _spikes_removed_round_by_round(
        points, cells, spike_angle, geographic
    )

    assert removed == expected_removed > 0
    np.testing.assert_array_equal(peeled, expected)
    np.testing.assert_array_equal(peeled_table, neighbor_table(expected, len(points)))
    np.testing.assert_array_equal(centres, expected_centres)


def test_smoothing_never_inverts_nor_lowers_the_worst_cell(lagoon):
    rng = np.random.default_rng(1)
    on_boundary = np.zeros(lagoon.n_points, dtype=bool)
    on_boundary[boundary_edges(lagoon.cells).ravel()] = True
    shift = np.where(on_boundary[:, None], 0.0, rng.normal(0, 0.05, lagoon.points.shape))
    # a tangled but valid start: no jitter for the vertices of a cell it would turn over (dropping such
    # cells instead left others lying over each other, which mesh_problems now sees)
    while np.any(signed_areas(lagoon.points + shift, lagoon.cells) <= 0):
        shift[lagoon.cells[signed_areas(lagoon.points + shift, lagoon.cells) <= 0].ravel()] = 0.0
    jittered, cells = lagoon.points + shift, lagoon.cells
    assert mesh_problems(tm.Mesh(jittered, cells)) == []
    start = triangle_quality(jittered, cells)
    before = jittered.copy()

    smoothed, moved = smooth_points(jittered, cells, passes=5)

    np.testing.assert_array_equal(jittered, before)  # input untouched
    after = triangle_quality(smoothed, cells)
    assert np.all(signed_areas(smoothed, cells) > 0)
    assert after.min() >= start.min()
    assert after.mean() > start.mean() + 0.02
    assert moved.sum() > 0.5 * np.sum(~on_boundary)
    fixed_boundary = np.unique(boundary_edges(cells))
    np.testing.assert_array_equal(smoothed[fixed_boundary], jittered[fixed_boundary])
    held = np.zeros(len(jittered), dtype=bool)
    held[::2] = True
    partly, moved_partly = smooth_points(jittered, cells, passes=2, fixed=held)
    np.testing.assert_array_equal(partly[held], jittered[held])
    assert not moved_partly[held].any()


def test_clean_keeps_a_good_mesh_and_its_area(lagoon):
    cleaned = clean(lagoon)
    report = cleaned.info["repair"]
    assert report.low_quality_cells == report.low_valence_points == 0
    assert cleaned.n_cells == lagoon.n_cells
    assert signed_areas(cleaned.points, cleaned.cells).sum() == pytest.approx(8.0)
    assert triangle_quality(cleaned.points, cleaned.cells).min() >= triangle_quality(lagoon.points, lagoon.cells).min()


def test_clean_options_are_checked(lagoon):
    with pytest.raises(MeshValidityError, match="min_quality"):
        clean(lagoon, min_quality=1.5)
    with pytest.raises(MeshValidityError, match="passes"):
        clean(lagoon, smoothing_passes=-1)
    with pytest.raises(MeshValidityError, match="not both"):
        clean(lagoon, disjoint_cutoff=0.1, dj_cutoff=0.3)


_TRIANGLE = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: low_valence_points(_TRIANGLE, [[0, 1, 7]]), "do not exist"),
        (lambda: smooth_points(_TRIANGLE, [[0, 1, -1]]), "do not exist"),
        (lambda: smooth_points(_TRIANGLE[:, :1], [[0, 1, 2]]), "shape \\(n, 2\\)"),
        (lambda: tm.cleanup.merge_duplicate_points([[0.0, 0], [np.nan, 1], [1, 0]], [[0, 1, 2]]), "NaN or infinite"),
        (lambda: fix_mesh(_TRIANGLE, [[0, 1, 2]], min_quality="high"), "min_quality"),
        (lambda: clean(_TRIANGLE, [[0, 1, 2]], spike_angle="sharp"), "spike_angle"),
        (lambda: low_valence_points(_TRIANGLE, [[0, 1, 2]], spike_angle=200), "spike_angle"),
    ],
)
def test_bad_arrays_and_options_are_named(call, message):
    with pytest.raises(MeshValidityError, match=message):
        call()


def test_reaching_max_rounds_warns_and_the_mesh_is_still_valid(barrier_raw):
    _, points, cells = barrier_raw
    with pytest.warns(TerrameshWarning, match="max_rounds=1"):
        mesh = clean(points, cells, max_rounds=1)
    assert mesh_problems(mesh) == []


def test_smoothing_keeps_cells_inside_the_domain_and_its_shore_vertices(barrier_raw):
    # the islands are thinner than the cells: some moves would take a centroid into them
    domain, points, cells = barrier_raw
    fixed = fix_mesh(points, cells)
    points, cells = fixed.points, fixed.cells
    inside = domain.inside(points[cells].mean(axis=1))
    free_moves = smooth_points(points, cells, passes=5)[0]
    assert not domain.inside(free_moves[cells[inside]].mean(axis=1)).all()

    smoothed, moved = smooth_points(points, cells, passes=5, domain=domain)

    assert domain.inside(smoothed[cells[inside]].mean(axis=1)).all()
    assert np.all(signed_areas(smoothed, cells) > 0)
    assert triangle_quality(smoothed, cells).min() >= triangle_quality(points, cells).min()
    edges = np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]])
    shortest = np.full(len(points), np.inf)
    np.minimum.at(shortest, edges.ravel(), np.repeat(np.linalg.norm(np.diff(points[edges], axis=1)[:, 0], axis=1), 2))
    on_shore = np.abs(domain.distance(points)) <= 0.01 * shortest
    assert on_shore.sum() > 0 and not moved[on_shore].any()
    assert moved.sum() > 0.3 * len(points)
    # a plain distance function (no Lipschitz bound) has every moved cell evaluated: the same result
    plain = tm.geometry.FunctionDomain(domain.distance, domain.bbox)
    np.testing.assert_array_equal(smooth_points(points, cells, passes=5, domain=plain)[0], smoothed)


def test_geographic_smoothing_never_lowers_the_worst_cell_on_the_ground(lagoon):
    # the lagoon in degrees at 60 N, where a degree of longitude is half one of latitude on the ground
    rng = np.random.default_rng(2)
    on_boundary = np.zeros(lagoon.n_points, dtype=bool)
    on_boundary[boundary_edges(lagoon.cells).ravel()] = True
    points = lagoon.points * [0.02, 0.01] + [-5.0, 60.0]
    points = points + np.where(on_boundary[:, None], 0.0, rng.normal(0, 0.0005, points.shape))
    cells = lagoon.cells
    assert mesh_problems(tm.Mesh(points, cells)) == []
    before = triangle_quality(points, cells, geographic=True)

    smoothed, moved = smooth_points(points, cells, passes=3, geographic=True)

    after = triangle_quality(smoothed, cells, geographic=True)
    assert after.min() >= before.min() and np.all(signed_areas(smoothed, cells) > 0)
    assert after.mean() > before.mean() and moved.sum() > 0


def test_smoothing_takes_no_boundary_cell_below_min_quality():
    """It kept the worst quality around a vertex, not every cell's: a boundary cell went from above 0.25 to
    0.129 beside a poorer one, and a second clean deleted it."""
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(122)
    points = rng.random((int(rng.integers(15, 60)), 2))
    cells = Delaunay(points).simplices
    with pytest.warns(TerrameshWarning, match="clean removed 3 % of the mesh's area"):  # the hull's slivers
        cleaned = clean(points, cells, dj_cutoff=0)
    on_boundary = np.any(tm.mesh.topology.cell_neighbor_table(cleaned.cells) < 0, axis=1)
    assert triangle_quality(cleaned.points, cleaned.cells[on_boundary]).min() >= 0.25  # 0.524
    assert cleaned.info["repair"].smoothed_points > 0
    again = clean(cleaned, dj_cutoff=0)
    np.testing.assert_array_equal(again.cells, cleaned.cells)


def test_a_mesh_poor_all_through_is_not_peeled_away():
    """A stretched grid, every cell q 0.21: each round peeled a layer until no cell was left (an error)."""
    x, y = np.meshgrid(np.arange(5) * 8.0, np.arange(5) * 1.0)
    points = np.column_stack([x.ravel(), y.ravel()])
    square = [[0, 1, 6], [0, 6, 5]]
    cells = np.array([[5 * j + i + k for k in cell] for j in range(4) for i in range(4) for cell in square])
    assert mesh_problems(tm.Mesh(points, cells)) == []
    poor = r"14 of the 14 boundary cells are below min_quality=0.25: a boundary poor by design"
    with pytest.warns(TerrameshWarning, match=poor):
        cleaned = clean(points, cells)
    assert cleaned.n_cells == 32
    assert len(clean(points, cells, min_quality=0.2).cells) == 32  # below every cell's quality: no warning


def test_smooth_points_takes_an_empty_list_of_fixed_vertices():
    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [0.8, 0.7]])
    cells = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    smoothed, moved = smooth_points(points, cells, passes=1, fixed=[])  # an IndexError: [] is a float array
    assert moved.tolist() == [False, False, False, False, True]


@pytest.mark.parametrize(
    ("fixed", "message"),
    [
        ([False] * 4, r"a mask of the 5 vertices, got shape \(4,\)"),  # read as "hold none": vertex 4 moved
        ([7], "from 7 to 7; the vertices are 0 to 4"),  # an IndexError from inside NumPy
        ([-1], "from -1 to -1"),  # held the last vertex
        ([4.5], "vertex numbers, got dtype float64"),  # held vertex 4
    ],
)
def test_smooth_points_names_fixed_vertices_that_are_not_the_meshs(fixed, message):
    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [0.8, 0.7]])
    cells = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    with pytest.raises(MeshValidityError, match=message):
        smooth_points(points, cells, passes=1, fixed=fixed)
    assert smooth_points(points, cells, passes=1, fixed=[4])[1].tolist() == [False] * 5


def _pinned_lagoon(lagoon):
    """The lagoon with what clean takes away or moves: a spike, a strip one cell wide, a flat boundary cell, a
    valence-3 vertex and jittered interior vertices. Returns ``(points, cells, named vertices)``."""
    rng = np.random.default_rng(3)
    points, cells = lagoon.points.copy(), lagoon.cells.copy()
    on_boundary = np.zeros(len(points), dtype=bool)
    on_boundary[boundary_edges(cells).ravel()] = True
    shift = np.where(on_boundary[:, None], 0.0, rng.normal(0, 0.03, points.shape))
    while np.any(signed_areas(points + shift, cells) <= 0):
        shift[cells[signed_areas(points + shift, cells) <= 0].ravel()] = 0.0
    points = points + shift
    edges = boundary_edges(cells)
    bottom = edges[np.all(points[edges, 1] < 1e-9, axis=1)]
    top = edges[np.all(points[edges, 1] > 2 - 1e-9, axis=1)]
    left = edges[np.all(points[edges, 0] < 1e-9, axis=1)]
    new = []

    def add(point):
        new.append(point)
        return len(points) + len(new) - 1

    # a spike below the bottom edge (44 degrees at its tip)
    a, b = bottom[0]
    half = 0.5 * np.linalg.norm(points[a] - points[b])
    spike = add(0.5 * (points[a] + points[b]) - [0, 2.5 * half])
    added = [[b, a, spike]]
    a, b = bottom[-1]  # and another, not pinned
    loose = add(0.5 * (points[a] + points[b]) - [0, 2.5 * half])
    added.append([b, a, loose])
    # a flat cell above the top edge: an obtuse lone vertex (no spike) in a cell of quality well below 0.25
    a, b = top[len(top) // 2]
    flat = add(0.5 * (points[a] + points[b]) + [0, 0.05 * half])
    added.append([b, a, flat])
    # a strip of equilateral cells left of the left edge: only its tip is a spike, and each removal exposes the next
    start, end = left[len(left) // 2][::-1]
    along = points[end] - points[start]
    step = 0.5 * along + np.sqrt(3) / 2 * np.array([along[1], -along[0]])
    if (points[start] + step)[0] > 0:
        step = 0.5 * along - np.sqrt(3) / 2 * np.array([along[1], -along[0]])
    chain = [start, end] + [add(points[start if k % 2 == 0 else end] + (k // 2 + 1) * step) for k in range(6)]
    strip = np.column_stack([chain[:-2], chain[1:-1], chain[2:]])
    tip = chain[-1]
    # an interior cell split at its centroid: a vertex of valence 3
    interior = np.setdiff1d(np.arange(len(cells)), _cells_with_boundary_edge(cells))
    target = interior[len(interior) // 3]
    a, b, c = cells[target]
    centre = add(points[[a, b, c]].mean(axis=0) + [0.01, 0.0])
    cells = np.vstack([np.delete(cells, target, axis=0), [[a, b, centre], [b, c, centre], [c, a, centre]], added])
    points = np.vstack([points, new])
    strip[signed_areas(points, strip) < 0] = strip[signed_areas(points, strip) < 0][:, [1, 0, 2]]
    cells = np.vstack([cells, strip])
    assert mesh_problems(tm.Mesh(points, cells)) == []
    moving = np.flatnonzero(~on_boundary)[::7]  # jittered interior vertices smoothing moves
    named = {"spike": spike, "loose": loose, "flat": flat, "tip": tip, "centre": centre, "moving": moving}
    return points, cells, named


def test_fixed_points_stay_bit_for_bit_and_in_cells(lagoon):
    # clean moved fixed points 527 m and 2537 m (the guide's pfix: gauges, river inflow nodes) and had no option
    points, cells, named = _pinned_lagoon(lagoon)
    pinned = np.concatenate([[named["spike"], named["flat"], named["tip"], named["centre"]], named["moving"]])
    fixed_points = points[pinned]

    free = clean(points, cells)  # without them, clean removes or moves every one of them
    kept = {tuple(p) for p in free.points.tolist()}
    assert not any(tuple(p) in kept for p in fixed_points.tolist())
    assert free.info["repair"].low_quality_cells >= 1 and free.info["repair"].low_valence_points >= 8

    cleaned = clean(points, cells, fixed_points=fixed_points)

    index = cleaned.info["fixed_points"]
    assert index.shape == (len(pinned),) and np.all(index >= 0)
    np.testing.assert_array_equal(cleaned.points[index], fixed_points)
    assert np.all(np.isin(index, cleaned.cells))
    assert mesh_problems(cleaned) == []
    report = cleaned.info["repair"]
    assert report.smoothed_points > 0 and report.low_valence_points == 1  # the rest was still cleaned
    assert tuple(points[named["loose"]]) not in {tuple(p) for p in cleaned.points.tolist()}
    # the centre's three cells, the spike's and the flat cell, and the strip whole under its pinned tip
    assert cleaned.n_cells == lagoon.n_cells + 2 + 2 + 6
    # a point within 1024 eps of the mesh's size of a vertex is that vertex, which keeps its own coordinates
    nudged = fixed_points + 1e-14
    np.testing.assert_array_equal(clean(points, cells, fixed_points=nudged).points[index], fixed_points)
    # a Mesh with an info["fixed_points"] of its own, cleaned without fixed points, loses it (renumbered)
    assert "fixed_points" not in clean(cleaned).info


def test_a_fixed_point_that_is_no_vertex_is_refused(lagoon):
    vertex = lagoon.points[5]
    with pytest.raises(MeshValidityError, match=r"1 of the 2 fixed points are no vertex of the mesh.*fixed point 1"):
        clean(lagoon, fixed_points=[vertex, vertex + [0.013, 0.0]])
    with pytest.raises(MeshValidityError, match=r"shape \(k, 2\)"):
        clean(lagoon, fixed_points=np.zeros((2, 3)))
    with pytest.raises(MeshValidityError, match="NaN"):
        clean(lagoon, fixed_points=[[np.nan, 0.0]])
    assert clean(lagoon, fixed_points=np.empty((0, 2))).info["fixed_points"].tolist() == []


def test_a_fixed_point_in_a_deleted_part_is_named(lagoon):
    # fix_mesh's repairs inside clean may still delete it: a small disconnected part goes, with a warning
    islet = np.array([[10.0, 10.0], [10.2, 10.0], [10.1, 10.17]])
    points = np.vstack([lagoon.points, islet])
    cells = np.vstack([lagoon.cells, [[lagoon.n_points, lagoon.n_points + 1, lagoon.n_points + 2]]])
    with pytest.warns(TerrameshWarning, match=r"clean removed 1 of the 2 fixed points, the first \(10, 10\)"):
        cleaned = clean(points, cells, fixed_points=[islet[0], lagoon.points[7]])
    index = cleaned.info["fixed_points"]
    assert index[0] == -1
    np.testing.assert_array_equal(cleaned.points[index[1]], lagoon.points[7])


def _spikes_removed_sparing(points, cells, spike_angle, geographic, is_fixed):
    """The reference of spike removal with fixed vertices: every spike but the fixed ones found, round after round,
    and its cell removed unless a fixed vertex is in it alone."""
    removed = 0
    while len(cells):
        spikes = low_valence_points(points, cells, spike_angle=spike_angle, geographic=geographic)[0]
        spikes = spikes[~is_fixed[spikes]]
        doomed = np.isin(cells, spikes).any(axis=1)
        alone = is_fixed & (np.bincount(cells.ravel(), minlength=len(points)) == 1)
        doomed &= ~alone[cells].any(axis=1)
        if not doomed.any():
            return cells, removed
        removed += int(np.isin(spikes, cells[doomed]).sum())
        cells = cells[~doomed]
    return cells, removed


@pytest.mark.parametrize("seed", range(6))
def test_spikes_peeled_around_fixed_vertices_as_round_by_round_removal_does(seed):
    from scipy.spatial import Delaunay

    from terramesh._kernels.cleanup import neighbor_table
    from terramesh.cleanup.clean import without_spikes

    rng = np.random.default_rng(seed)
    points = rng.random((300, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    cells = cells[rng.random(len(cells)) > 0.35]
    cells[signed_areas(points, cells) < 0] = cells[signed_areas(points, cells) < 0][:, [1, 0, 2]]
    table = neighbor_table(cells, len(points))
    spike_angle = rng.uniform(40.0, 100.0)
    # fixed: some of the spikes and some vertices of their cells, which peeling without them would strand
    spikes = low_valence_points(points, cells, spike_angle=spike_angle)[0]
    is_fixed = np.zeros(len(points), dtype=bool)
    is_fixed[spikes[::3]] = True
    is_fixed[cells[np.isin(cells, spikes[1::3]).any(axis=1)][:, 0]] = True

    peeled, peeled_table, removed, centres = without_spikes(points, cells, table, spike_angle, False, is_fixed)
    expected, expected_removed = _spikes_removed_sparing(points, cells, spike_angle, False, is_fixed)

    assert removed == expected_removed > 0
    np.testing.assert_array_equal(peeled, expected)
    np.testing.assert_array_equal(peeled_table, neighbor_table(expected, len(points)))
    assert np.all(np.isin(np.flatnonzero(is_fixed & np.isin(np.arange(len(points)), cells)), peeled))
    assert not is_fixed[centres].any()


def test_clean_warns_when_it_peels_away_sharp_features():
    # a 12-point star (tips of about 12.5 degrees): each round took the cells the last one exposed, and
    # the tips went, 7.7 % of the area, without a word
    angles = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    radii = np.where(np.arange(24) % 2 == 0, 1.0, 0.3)
    star = tm.geometry.Polygon(np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]))
    mesh = tm.generate_mesh(star, 0.05)
    with pytest.warns(TerrameshWarning, match=r"clean removed [0-9.]+ % of the mesh's area"):
        cleaned = tm.cleanup.clean(mesh, domain=star)
    assert tm.mesh.topology.signed_areas(cleaned.points, cleaned.cells).sum() < 0.95 * star.geometry.area
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tm.cleanup.clean(tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.05))  # nothing sharp to peel


def test_a_boundary_poor_by_design_is_said_once():
    # a Delaunay triangulation of random points: slivers along its convex hull (11 of 18 boundary cells); clean
    # said "poor all through (anisotropic?)" three times; its hull is kept, with one warning that names it
    from scipy.spatial import Delaunay

    points = np.random.default_rng(5).random((3000, 2))
    cleaned, said = _poor_all_through_said(lambda: clean(points, Delaunay(points).simplices))
    assert len(said) == 1 and "or a raw triangulation's hull" in said[0]
    assert cleaned.info["repair"].low_quality_cells == 0
    # a grid stretched 10:1 is poor all through (q 0.17 everywhere): said once, nothing deleted
    xs, ys = np.meshgrid(np.arange(21.0), 0.1 * np.arange(11.0))
    grid = np.column_stack([xs.ravel(), ys.ravel()])
    j, i = np.mgrid[0:10, 0:20]
    a = (j * 21 + i).ravel()
    cells = np.concatenate([np.column_stack([a, a + 1, a + 22]), np.column_stack([a, a + 22, a + 21])])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        stretched = clean(grid, cells, smoothing_passes=0)
    said = [str(warning.message) for warning in caught if "poor by design" in str(warning.message)]
    assert len(said) == 1 and said[0].startswith("58 of the 58 boundary cells are below")
    assert stretched.n_cells == len(cells) and stretched.info["repair"].low_quality_cells == 0


def _poor_all_through_said(call):
    """The mesh ``call()`` returns and its 'poor by design' warnings."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = call()
    return mesh, [str(warning.message) for warning in caught if "poor by design" in str(warning.message)]


@pytest.mark.parametrize("growth", [0.1, 1.0, 3.0])
def test_an_anisotropic_boundary_layer_is_kept_whole_with_one_warning(growth):
    # generation's boundary layer (cells 16 times as long as high along the rim, isotropic inside), many rows thick
    # (growth 0.1) to one (3.0): clean peeled 790 cells of the thick one (5.5 % of the area), all of the thin ones
    def boundary_layer(points):
        radius = np.hypot(points[:, 0], points[:, 1])
        return metric_tensor(
            0.08,
            np.minimum(0.08, 0.005 + growth * np.clip(1 - radius, 0, None)),
            np.arctan2(points[:, 1], points[:, 0]) + np.pi / 2,
        )

    mesh = tm.generate_anisotropic_mesh(tm.geometry.Disk((0, 0), 1), boundary_layer, seed=0)
    cleaned, said = _poor_all_through_said(lambda: clean(mesh))
    assert len(said) == 1 and " boundary cells are below min_quality=0.25" in said[0]
    assert cleaned.n_cells == mesh.n_cells and cleaned.info["repair"].low_quality_cells == 0
    np.testing.assert_allclose(
        signed_areas(cleaned.points, cleaned.cells).sum(), signed_areas(mesh.points, mesh.cells).sum()
    )


def test_rows_stretched_along_two_sides_are_kept():
    # a 4 x 1 rectangle, 4 rows of cells 0.1 long and 0.01 high along top and bottom, square cells between: 44 % of
    # the cells are poor, and clean peeled the 635 of the rows, 8 % of the area
    from scipy.spatial import Delaunay

    xs, ys = np.meshgrid(np.linspace(0, 4, 41), np.r_[0:0.041:0.01, np.linspace(0.1, 0.9, 9), 0.96:1.001:0.01])
    points = np.column_stack([xs.ravel(), ys.ravel()])
    cells = Delaunay(points).simplices
    flipped = signed_areas(points, cells) < 0
    cells[flipped] = cells[flipped][:, ::-1]
    cleaned, said = _poor_all_through_said(lambda: clean(points, cells))
    assert len(said) == 1 and said[0].startswith("94 of the 114 boundary cells are below")
    assert cleaned.n_cells == len(cells)
    assert signed_areas(cleaned.points, cleaned.cells).sum() == pytest.approx(4.0)
