import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import terramesh as tm
from terramesh.errors import GenerationError
from terramesh.generation import delaunay
from terramesh.generation.seeding import hexagonal_lattice
from terramesh.mesh.topology import signed_areas


def assert_delaunay_of_hull(points, cells):
    from scipy.spatial import cKDTree

    # every distinct point is kept, so near-duplicates give cells whose area rounds to zero
    gap = cKDTree(points).query(points, k=2)[0][:, 1].min() / np.ptp(points)
    areas = signed_areas(points, cells)
    assert np.all(areas > 0) if gap > 1e-9 else np.all(areas >= 0)
    # total area equals the convex hull's
    from scipy.spatial import ConvexHull

    assert signed_areas(points, cells).sum() == pytest.approx(ConvexHull(points).volume, rel=1e-9)


def test_lattice_with_cocircular_points():
    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.05)
    assert_delaunay_of_hull(points, delaunay(points))
    square = np.array([[x, y] for x in range(10) for y in range(10)], dtype=float)
    assert_delaunay_of_hull(square, delaunay(square))


# the predicates are exact while coordinate differences stay within ~1e70 of the largest
# coordinate (documented): hypothesis otherwise finds 1e-255 next to 1, which underflows
_COORDINATE = st.floats(-1, 1).map(lambda x: 0.0 if abs(x) < 1e-60 else x)


@settings(max_examples=30, deadline=None)
@given(arrays(np.float64, st.tuples(st.integers(4, 60), st.just(2)), elements=_COORDINATE))
def test_random_points(points):
    """Well-spread input triangulates; degenerate input may only raise GenerationError."""
    from scipy.spatial import ConvexHull, QhullError

    points = np.unique(points, axis=0)
    try:
        spread = len(points) >= 3 and ConvexHull(points).volume > 1e-6
    except QhullError:
        spread = False
    if spread:
        assert_delaunay_of_hull(points, delaunay(points))
    else:
        try:
            cells = delaunay(points)
        except GenerationError:
            return
        assert np.all(signed_areas(points, cells) >= 0)


def test_collinear_points_raise():
    with pytest.raises(GenerationError, match="span a plane"):
        delaunay(np.column_stack([np.arange(5.0), np.zeros(5)]))
    with pytest.raises(GenerationError, match="too small"):
        delaunay(np.zeros((2, 2)))


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.integers(0, 20))
def test_sorting_spatially_renumbers_points_and_cells_together(seed, n_front):
    from terramesh.generation.triangulate import Triangulation

    rng = np.random.default_rng(seed)
    points = rng.random((500, 2))
    triangulation = Triangulation(points, frame=True)
    before = triangulation.cells_and_neighbors()[0]
    front = np.zeros(len(points), dtype=bool)
    front[rng.choice(len(points), n_front, replace=False)] = True
    order = triangulation.sort_spatially(front)
    new_number = np.empty(len(points), dtype=np.int64)
    new_number[order] = np.arange(len(points))
    assert sorted(order.tolist()) == list(range(len(points)))
    assert set(order[:n_front].tolist()) == set(np.flatnonzero(front).tolist())
    renumbered = points[order]
    np.testing.assert_array_equal(triangulation.positions, renumbered)
    cells, neighbors = triangulation.cells_and_neighbors()

    def triangles(cells):
        return set(map(tuple, np.sort(cells, axis=1).tolist()))

    assert triangles(cells) == triangles(new_number[before])
    # the neighbour table still pairs cells across shared edges
    for c, k in zip(*np.nonzero(neighbors >= 0), strict=True):
        edge = {cells[c, (k + 1) % 3], cells[c, (k + 2) % 3]}
        assert edge <= set(cells[neighbors[c, k]].tolist())
    # and it follows moved points as the unsorted one does (same frame, same moves)
    shift = 1e-3 * rng.standard_normal(points.shape)
    triangulation.move_points(renumbered + shift[order])
    unsorted = Triangulation(points, frame=True)
    unsorted.move_points(points + shift)
    assert triangles(triangulation.cells_and_neighbors()[0]) == triangles(new_number[unsorted.cells_and_neighbors()[0]])


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from(["random", "lattice", "duplicates", "clustered"]), st.booleans())
def test_nearest_distances_equal_a_kd_tree(seed, layout, frame):
    from scipy.spatial import cKDTree

    from terramesh.generation.triangulate import Triangulation

    rng = np.random.default_rng(seed)
    if layout == "lattice":  # cocircular everywhere; queries on points and halfway between them
        points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.1)
        queries = np.vstack([points[::3], 0.5 * (points[:-1] + points[1:])])
    else:
        points = rng.random((400, 2))
        if layout == "duplicates":
            points = np.vstack([points, points[:50]])
        elif layout == "clustered":  # a dense cluster far smaller than the spread
            points[:200] = 0.5 + 1e-6 * rng.random((200, 2))
        queries = rng.random((300, 2)) * 1.4 - 0.2  # some outside the points' hull
    # with a frame its corners are vertices too, but far beyond every query
    found = Triangulation(points, frame=frame).nearest_distances(queries)
    expected, _ = cKDTree(points).query(queries)
    np.testing.assert_allclose(found, expected, rtol=1e-12, atol=1e-15)


def _locally_delaunay(triangulation):
    """Whether no interior edge of the triangulation has the opposite vertex strictly inside a circumcircle."""
    from terramesh._kernels.delaunay import incircle, workspace

    points = triangulation.positions
    cells, neighbors = triangulation.cells_and_neighbors()
    work = workspace()
    for c, k in zip(*np.nonzero(neighbors >= 0), strict=True):
        other = cells[neighbors[c, k]]
        apex = next(v for v in other if v not in cells[c])
        if incircle(points, cells[c, 0], cells[c, 1], cells[c, 2], apex, work) > 0:
            return False
    return True


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from(["disk", "random", "all"]), st.booleans())
def test_splitting_edges_quarters_the_kept_cells_and_stays_a_triangulation(seed, pick, lattice):
    from terramesh.generation.triangulate import Triangulation

    rng = np.random.default_rng(seed)
    if lattice:  # cocircular everywhere, as DistMesh's levels are
        points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.08)
        points = points + 1e-3 * rng.standard_normal(points.shape) * rng.integers(0, 2)
    else:
        points = rng.random((300, 2))
    triangulation = Triangulation(points, frame=True)
    cells, _ = triangulation.cells_and_neighbors()
    centroids = points[cells].mean(axis=1)
    keep = {
        "disk": np.linalg.norm(centroids - 0.5, axis=1) < 0.35,
        "random": rng.random(len(cells)) < 0.5,
        "all": np.ones(len(cells), dtype=bool),
    }[pick]
    edges, outer = triangulation.split_edges(keep)
    assert edges is not None
    # the kept cells' edges, each once; outer ones are on one kept cell only
    sides = np.sort(np.concatenate([cells[keep][:, [0, 1]], cells[keep][:, [1, 2]], cells[keep][:, [2, 0]]]), axis=1)
    unique, count = np.unique(sides, axis=0, return_counts=True)
    assert sorted(map(tuple, np.sort(edges, axis=1).tolist())) == sorted(map(tuple, unique.tolist()))
    assert set(map(tuple, np.sort(edges[outer], axis=1).tolist())) == set(map(tuple, unique[count == 1].tolist()))
    middle = 0.5 * (points[edges[:, 0]] + points[edges[:, 1]])
    every = np.vstack([points, middle])
    np.testing.assert_array_equal(triangulation.positions, every)
    # each kept cell is now four: its corner cells are there
    split, neighbors = triangulation.cells_and_neighbors()
    number = {tuple(sorted(e)): len(points) + i for i, e in enumerate(edges.tolist())}
    present = set(map(tuple, np.sort(split, axis=1).tolist()))
    for a, b, c in cells[keep][:20].tolist():
        ab, ca = number[tuple(sorted((a, b)))], number[tuple(sorted((c, a)))]
        assert tuple(sorted((a, ab, ca))) in present
    # a valid triangulation: counter-clockwise cells, neighbours across shared edges both ways
    assert np.all(signed_areas(every, split) > 0)
    for c, k in zip(*np.nonzero(neighbors >= 0), strict=True):
        assert {split[c, (k + 1) % 3], split[c, (k + 2) % 3]} <= set(split[neighbors[c, k]].tolist())
        assert c in neighbors[neighbors[c, k]]
    # flips make it Delaunay again: the cells a fresh triangulation has (up to cocircular ties)
    assert triangulation.move_points(every)
    assert _locally_delaunay(triangulation)
    fresh, _ = Triangulation(every, frame=True).cells_and_neighbors()
    assert len(triangulation.cells_and_neighbors()[0]) == len(fresh)


def test_splitting_edges_is_refused_with_duplicate_points_and_changes_nothing():
    from terramesh.generation.triangulate import Triangulation

    points = np.random.default_rng(3).random((50, 2))
    triangulation = Triangulation(np.vstack([points, points[:2]]), frame=True)
    cells, _ = triangulation.cells_and_neighbors()
    assert triangulation.split_edges(np.ones(len(cells), dtype=bool)) == (None, None)
    assert triangulation.n_points == 52
    np.testing.assert_array_equal(triangulation.cells_and_neighbors()[0], cells)


def test_split_edges_and_nearest_distances_refuse_bad_input():
    from terramesh.generation.triangulate import Triangulation

    triangulation = Triangulation(np.random.default_rng(4).random((40, 2)), frame=True)
    n_cells = len(triangulation.cells_and_neighbors()[0])
    for wrong in (n_cells - 1, n_cells + 1):
        with pytest.raises(GenerationError, match=f"one flag per cell \\({n_cells}\\), got {wrong}"):
            triangulation.split_edges(np.ones(wrong, dtype=bool))
    assert triangulation.n_points == 40  # nothing changed
    with pytest.raises(GenerationError, match="finite"):
        triangulation.nearest_distances([[0.5, np.nan]])


@settings(deadline=None, max_examples=30)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.floats(0.0, 1.0))
def test_passes_over_the_triangulations_own_arrays_match_the_ghost_free_copy(seed, frame, fraction):
    # mesh_edges reads the arrays with ghost (and frame) cells to save a copy; it must see the same mesh
    from terramesh._kernels.topology import cell_centroids, classify_cells, inner_cell_edges
    from terramesh.generation.triangulate import Triangulation

    rng = np.random.default_rng(seed)
    points = rng.uniform(-1, 1, size=(int(rng.integers(3, 200)), 2))
    triangulation = Triangulation(points, frame=frame)
    cells, neighbors = triangulation.cells_and_neighbors()
    own_cells, own_neighbors, first = triangulation.cells_with_ghosts()
    bound = rng.uniform(-1.5, 0.5, size=len(points))
    state = classify_cells(points, own_cells, bound, 0.01, first)
    np.testing.assert_array_equal(own_cells[state >= 0] - first, cells)
    np.testing.assert_array_equal(state[state >= 0], classify_cells(points, cells, bound, 0.01, 0))
    every = np.arange(len(cells))
    np.testing.assert_array_equal(
        cell_centroids(points, own_cells, np.flatnonzero(state >= 0), first), cell_centroids(points, cells, every, 0)
    )
    keep = rng.uniform(size=len(cells)) < fraction
    own_keep = np.zeros(len(own_cells), dtype=bool)
    own_keep[state >= 0] = keep
    got = inner_cell_edges(own_cells, own_neighbors, own_keep, first)
    for got_array, expected in zip(got, inner_cell_edges(cells, neighbors, keep, 0), strict=True):
        np.testing.assert_array_equal(got_array, expected)


def test_mesh_edges_refuse_points_that_are_not_the_triangulations():
    # the triangulation's own arrays tell ghost cells by the number of points
    import terramesh as tm
    from terramesh.generation.cells_inside import mesh_edges
    from terramesh.generation.triangulate import Triangulation

    points = np.random.default_rng(3).uniform(-0.5, 0.5, size=(50, 2))
    triangulation = Triangulation(points, frame=True)
    disk = tm.geometry.Disk((0, 0), 1)
    assert len(mesh_edges(disk, triangulation, points, 1e-6)[0]) > 0
    with pytest.raises(GenerationError, match="49 points for a triangulation of 50"):
        mesh_edges(disk, triangulation, points[:-1], 1e-6)


@settings(deadline=None, max_examples=30)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.integers(1, 30))
def test_cells_left_alone_by_insertions_keep_the_sides_found_before(seed, frame, added):
    """The boundary gaps' second pass: the answers taken over from the first are the ones a fresh pass gives."""
    import terramesh as tm
    from terramesh.generation.cells_inside import mesh_edges
    from terramesh.generation.distances import LazyDistance
    from terramesh.generation.triangulate import Triangulation

    rng = np.random.default_rng(seed)
    domain = tm.geometry.Polygon(np.column_stack([np.cos(a := np.sort(rng.uniform(0, 6.28, 40))), np.sin(a)]))
    points = rng.uniform(-1.1, 1.1, size=(300, 2))
    lazy = LazyDistance(domain)
    lazy.update(points, np.zeros(len(points)), np.full(len(points), 0.1))
    triangulation = Triangulation(points, frame=frame)
    sides = {}
    mesh_edges(domain, triangulation, points, 1e-3, lazy, record=sides)
    new = domain.project(rng.uniform(-1.1, 1.1, size=(added, 2)))  # boundary points, as the gaps' are
    triangulation.add_points(new)
    lazy.append(new)
    points = np.vstack([points, new])
    again = mesh_edges(domain, triangulation, points, 1e-3, lazy, earlier=sides)
    fresh = mesh_edges(domain, triangulation, points, 1e-3, lazy)
    for got, expected in zip(again, fresh, strict=True):
        np.testing.assert_array_equal(got, expected)


def test_removing_every_duplicate_needs_no_rebuild():
    """A generator drops the point a rebuild found doubled: that must not cost a second rebuild."""
    from terramesh.generation.triangulate import Triangulation

    points = np.random.default_rng(5).random((60, 2))
    doubled = np.vstack([points, points[[3, 7, 7]]])  # points 60, 61, 62 lie on vertices 3, 7, 7
    triangulation = Triangulation(doubled, frame=True)
    assert triangulation.duplicate_of[60:].tolist() == [3, 7, 7]
    # the duplicates and one vertex go; the cells are those of a fresh triangulation of the rest
    triangulation.remove_points([10, 60, 61, 62])
    assert triangulation.rebuilds == 1
    rest = np.delete(points, 10, axis=0)
    np.testing.assert_array_equal(triangulation.positions, rest)
    assert (triangulation.duplicate_of == -1).all()
    assert _locally_delaunay(triangulation)
    fresh, _ = Triangulation(rest, frame=True).cells_and_neighbors()
    assert len(triangulation.cells_and_neighbors()[0]) == len(fresh)
    # a duplicate left behind (point 62) while its vertex goes needs a triangulation from scratch
    again = Triangulation(doubled, frame=True)
    again.remove_points([7, 61])
    assert again.rebuilds == 2
    assert again.n_points == len(doubled) - 2
    assert np.flatnonzero(again.duplicate_of >= 0).tolist() == [59]  # point 60 still doubles vertex 3
    np.testing.assert_array_equal(again.positions[60], points[7])  # point 62 took its vertex's place


def test_a_repair_that_folds_the_triangulation_is_rebuilt(monkeypatch):
    # the repair's coverage check runs after the kernel (a parallel kernel is called from Python only):
    # a repaired triangulation that covers part of its hull twice must be built again, not kept
    from terramesh._kernels import delaunay as kernel
    from terramesh.generation.triangulate import Triangulation

    rng = np.random.default_rng(3)
    points = rng.random((300, 2))
    moved = points + 2e-3 * rng.standard_normal(points.shape)
    kept = Triangulation(points, frame=True)
    built = kept.rebuilds
    assert kept.move_points(moved) and kept.rebuilds == built and kept.flips > 0
    folded = Triangulation(points, frame=True)
    monkeypatch.setattr(kernel, "covered_area_mismatch", lambda points, cells, infinite: 0.5)
    assert not folded.move_points(moved)
    assert folded.rebuilds == built + 1
    rebuilt, repaired = folded.cells_and_neighbors()[0], kept.cells_and_neighbors()[0]
    assert np.all(signed_areas(moved, rebuilt) > 0)
    assert {tuple(np.roll(c, -np.argmin(c))) for c in rebuilt} == {tuple(np.roll(c, -np.argmin(c))) for c in repaired}


def test_moving_points_far_from_the_origin_repairs_without_rebuilding():
    """The fold test summed the hull's area on raw coordinates: at 5e6 (UTM) it cancelled to 1.9e-9 of the area,
    above the 1e-9 that calls a fold, and a valid triangulation was rebuilt (8 times for a 10 m disk)."""
    from terramesh.generation.triangulate import Triangulation

    points = np.random.default_rng(0).random((2000, 2)) * 1000.0 + 5e6
    triangulation = Triangulation(points)
    assert triangulation.move_points(points + 1e-3) and triangulation.rebuilds == 1
    mesh = tm.generate_mesh(tm.geometry.Disk((5e5 + 10, 5e6 + 10), 10), 0.4, levels=0, seed=0)
    assert mesh.info["rebuilds"] == 0
