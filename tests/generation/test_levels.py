"""Coarse-to-fine generation: levels, refinement by midpoints, seeds of features a coarse level misses."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import GenerationError
from terramesh.generation.fixed_points import spread_mask
from terramesh.generation.levels import coarse_levels, refined_points, uncovered_seeds
from terramesh.generation.seeding import seed_points
from terramesh.generation.triangulate import Triangulation
from terramesh.mesh.topology import signed_areas
from terramesh.quality import edge_length_ratio, triangle_quality

from ..conftest import assert_valid

DISK = tm.geometry.Disk((0, 0), 1)


def graded(h_min):
    return lambda p: h_min * (1 + 4.0 * (p[:, 0] + 1))


@pytest.fixture(scope="module")
def graded_disk():
    # 48,000 vertices, 3,100 at the coarsest level (with fewer, the coarsest mesh's boundary
    # shifts the density: 250 there give edges 7 % short in the end)
    return tm.generate_mesh(DISK, graded(0.0025), h0=0.0025, levels=2, seed=0)


def test_a_graded_disk_from_two_coarse_levels_meets_the_bars(graded_disk):
    mesh = graded_disk
    assert_valid(mesh, DISK, 0.0025)
    quality = triangle_quality(mesh.points, mesh.cells)
    assert quality.min() >= 0.7 and quality.mean() >= 0.98
    ratio = edge_length_ratio(mesh.points, mesh.cells, graded(0.0025))
    assert 0.95 <= np.median(ratio) <= 1.05
    assert np.percentile(ratio, 99) < 1.4 and np.percentile(ratio, 1) > 0.7
    assert signed_areas(mesh.points, mesh.cells).sum() == pytest.approx(np.pi, rel=2e-3)


def test_each_level_has_about_four_times_the_points_and_stops_early(graded_disk):
    levels = graded_disk.info["levels"]
    assert len(levels) == 3
    counts = [level["points"] for level in levels]
    assert counts[-1] == graded_disk.n_points
    for coarse, fine in zip(counts, counts[1:], strict=False):
        assert 3.6 < fine / coarse < 4.4
    # random initial points need tens of iterations; a refined mesh is nearly in equilibrium
    assert levels[0]["iterations"] >= 20
    assert all(level["iterations"] <= 15 for level in levels[1:])
    assert graded_disk.info["iterations"] == levels[-1]["iterations"]
    assert graded_disk.info["stop_reason"] in {"stalled", "converged"}


def test_levels_give_the_quality_of_one_level(graded_disk):
    single = tm.generate_mesh(DISK, graded(0.0025), h0=0.0025, levels=0, seed=0)
    multi = graded_disk
    q_single = triangle_quality(single.points, single.cells)
    q_multi = triangle_quality(multi.points, multi.cells)
    assert len(single.info["levels"]) == 1
    assert abs(multi.n_points / single.n_points - 1) < 0.03
    assert q_multi.mean() >= q_single.mean() - 2e-3


def test_same_seed_same_mesh():
    first = tm.generate_mesh(DISK, graded(0.02), h0=0.02, levels=2, seed=4)
    again = tm.generate_mesh(DISK, graded(0.02), h0=0.02, levels=2, seed=4)
    np.testing.assert_array_equal(first.points, again.points)
    np.testing.assert_array_equal(first.cells, again.cells)


def test_islets_smaller_than_the_coarse_size_are_meshed():
    # three separate basins 0.12 across beside a square: a coarse level may hold no point in
    # them, so a finer level must seed them (at h = 0.02 they take about 30 vertices each)
    islets = [tm.geometry.Disk((1.5, y), 0.06) for y in (0.2, 0.5, 0.8)]
    domain = tm.geometry.Union([tm.geometry.Rectangle((0, 0), (1, 1)), *islets])
    mesh = tm.generate_mesh(domain, 0.02, levels=2, seed=0)
    assert_valid(mesh, domain, 0.02)
    assert sum(level["filled"] for level in mesh.info["levels"][:-1]) > 0
    centroids = mesh.points[mesh.cells].mean(axis=1)
    for islet in islets:
        cells = mesh.cells[islet.distance(centroids) < 0]
        assert signed_areas(mesh.points, cells).sum() == pytest.approx(np.pi * 0.06**2, rel=0.04)
    assert triangle_quality(mesh.points, mesh.cells).min() >= 0.5


def test_fixed_points_and_corners_survive_every_level():
    domain = tm.geometry.Rectangle((0, 0), (2, 1))
    fixed = np.array([[0.5, 0.5], [1.5, 0.25]])
    mesh = tm.generate_mesh(domain, lambda p: 0.01 + 0.05 * p[:, 0], levels=2, fixed_points=fixed, seed=0)
    assert_valid(mesh, domain, 0.01)
    for point in [*fixed, (0, 0), (2, 0), (2, 1), (0, 1)]:
        assert np.min(np.linalg.norm(mesh.points - point, axis=1)) == 0.0


def test_a_size_grid_with_levels():
    domain = tm.geometry.Rectangle((0, 0), (2, 1))
    x, y = np.linspace(0, 2, 41), np.linspace(0, 1, 21)
    grid = tm.sizing.SizeGrid((x, y), 0.01 + 0.02 * x[:, None] + 0 * y[None, :])
    mesh = tm.generate_mesh(domain, grid, levels=1, seed=0)
    assert_valid(mesh, domain, 0.01)
    assert 0.95 <= np.median(edge_length_ratio(mesh.points, mesh.cells, grid)) <= 1.05


def test_the_default_levels_follow_the_vertex_count():
    bbox = np.array(DISK.bbox, dtype=float)
    vertices = lambda h: np.pi / (np.sqrt(3) / 2 * h**2)  # noqa: E731
    assert coarse_levels(DISK, lambda p: np.full(len(p), 0.05), bbox) == 0  # 1,450 vertices
    assert coarse_levels(DISK, lambda p: np.full(len(p), 0.02), bbox) == 1  # 9,000
    assert coarse_levels(DISK, lambda p: np.full(len(p), 0.01), bbox) == 2  # 36,000
    assert coarse_levels(DISK, lambda p: np.full(len(p), 0.002), bbox) == 3  # 900,000: at most 3
    assert 4 < vertices(0.02) / 2_000 < 16 < vertices(0.01) / 2_000 < 64 < vertices(0.002) / 2_000
    mesh = tm.generate_mesh(DISK, 0.02, seed=0)
    assert len(mesh.info["levels"]) == 2


@pytest.mark.parametrize(
    "domain, size",
    [
        (DISK, lambda p: np.full(len(p), 0.01)),
        (DISK, graded(0.004)),
        (tm.geometry.Polygon([(0, 0), (3, 0), (3, 1), (1, 1), (1, 2.5), (0, 2.5)]), lambda p: 0.01 + 0.01 * p[:, 1]),
    ],
    ids=["uniform disk", "graded disk", "L-shaped polygon"],
)
def test_the_levels_from_the_sizes_sample_are_those_from_a_sample_of_their_own(domain, size):
    # the generator's sample of the bbox serves the levels too: the same counts, not a second sampling
    from terramesh.generation.options import size_sample

    for bbox in (np.array(domain.bbox, dtype=float), np.array([[-50.0, -50.0], [50.0, 50.0]])):
        sample = size_sample(size, domain, bbox)
        assert (sample.bbox_points is None) == (bbox[1, 0] == 50.0)  # a generous bbox is sampled again: not reused
        assert coarse_levels(domain, size, bbox, sample) == coarse_levels(domain, size, bbox)
    assert coarse_levels(domain, size, np.array(domain.bbox, dtype=float)) > 0


def test_a_boundary_as_long_as_a_coastline_gets_no_coarse_level():
    # 50 teeth 0.2 deep on the top of the unit square: 23 units of boundary, at h = 0.005
    # about 4,600 of 46,000 vertices; a coarse level would have a fifth of its vertices there
    x = np.linspace(0, 1, 101)
    top = np.column_stack([x[::-1], np.where(np.arange(101) % 2, 0.8, 1.0)])
    teeth = tm.geometry.Polygon(np.vstack([[(0, 0), (1, 0)], top]))
    bbox = np.array(teeth.bbox, dtype=float)
    uniform = lambda p: np.full(len(p), 0.005)  # noqa: E731
    assert coarse_levels(teeth, uniform, bbox) == 0
    assert coarse_levels(tm.geometry.Rectangle((0, 0), (1, 1)), uniform, bbox) == 2


def test_levels_asked_beyond_the_domain_stop_where_the_coarsest_still_holds_a_mesh():
    # a disk 8 sizes across at levels=3: the coarsest lattice (spacing 2) put 1 point inside, and the
    # call raised "cannot triangulate 1 points"; in strips a forced level raised on the narrower strips
    mesh = tm.generate_mesh(DISK, 0.25, levels=3, seed=0)
    assert mesh.info["levels"][0]["points"] >= 3
    assert tm.cleanup.mesh_problems(mesh, DISK) == []
    assert tm.generate_mesh(DISK, 0.25, levels=2, seed=0).n_points == mesh.n_points


@pytest.mark.parametrize("levels", [2, 3])
def test_a_coarsest_level_of_a_handful_of_points_is_not_meshed(levels):
    # a unit square at 0.05 forced to 3 levels started from 16 points and stayed a grid of right triangles
    # (mean q 0.943), at 2 levels from 46 (0.970); from 150 points at one level it is 0.989, as at none
    square = tm.geometry.Rectangle((0, 0), (1, 1))
    mesh = tm.generate_mesh(square, 0.05, levels=levels, seed=0)
    assert mesh.info["levels"][0]["points"] >= 100
    assert tm.quality.summary(mesh).mean > 0.985


@pytest.mark.parametrize("levels", [-1, 1.5, True, "2", "two", [1]])
def test_bad_levels_are_refused(levels):
    with pytest.raises(GenerationError, match="levels"):
        tm.generate_mesh(DISK, 0.1, levels=levels)


@pytest.mark.parametrize("levels", [-1, 1.5, True])
def test_levels_are_checked_in_3d_too(levels):
    with pytest.raises(GenerationError, match="levels must be a non-negative integer"):
        tm.generate_mesh(tm.geometry.Ball((0, 0, 0), 1), 0.3, levels=levels)


def test_band_seeds_are_the_seeds_near_the_boundary():
    size = graded(0.01)
    every, _ = seed_points(DISK, size, 0.01, np.array(DISK.bbox, float), np.random.default_rng(2), 1e-5)
    band, _ = seed_points(DISK, size, 0.01, np.array(DISK.bbox, float), np.random.default_rng(2), 1e-5, band=2.0)
    near = -DISK.distance(every) <= 2.0 * size(every)
    assert 0 < len(band) < 0.5 * len(every)
    assert set(map(tuple, band.tolist())) == set(map(tuple, every[near].tolist()))


def test_uncovered_seeds_fill_only_holes():
    size = lambda p: np.full(len(p), 0.05)  # noqa: E731
    bbox = np.array(DISK.bbox, float)
    lattice, _ = seed_points(DISK, size, 0.05, bbox, np.random.default_rng(0), 1e-5)
    assert len(uncovered_seeds(DISK, size, 0.05, bbox, 0, 1e-5, Triangulation(lattice).nearest_distances)) == 0
    # points only on the left half: the right half's boundary band is uncovered
    left = lattice[lattice[:, 0] < 0]
    seeds = uncovered_seeds(DISK, size, 0.05, bbox, 0, 1e-5, Triangulation(left, frame=True).nearest_distances)
    assert len(seeds) > 0 and np.all(seeds[:, 0] > -0.05)
    assert np.all(-DISK.distance(seeds) <= 2.0 * 0.05 + 1e-12)


def test_fixed_points_a_fine_edge_apart_are_thinned_on_coarse_levels():
    # a seismic model box fixes nodes one edge apart along its sides; fixed on a coarse level
    # they would crowd its boundary, and refining that would compound level after level
    box = tm.seismic.sizing.ModelBox((0.0, -2000.0), (6000.0, 0.0), 25.0)
    single = tm.generate_mesh(box, 25.0, levels=0, seed=0)
    multi = tm.generate_mesh(box, 25.0, levels=2, seed=0)
    assert_valid(multi, box, 25.0)
    assert abs(multi.n_points / single.n_points - 1) < 0.02
    assert 0.98 <= np.median(edge_length_ratio(multi.points, multi.cells, 25.0)) <= 1.02
    nodes = box.corners()
    assert len(nodes) > 600
    assert np.all(np.min(np.linalg.norm(multi.points[:, None] - nodes[None], axis=2), axis=0) == 0.0)
    counts = [level["points"] for level in multi.info["levels"]]
    assert 3.6 < counts[1] / counts[0] < 4.4 and 3.6 < counts[2] / counts[1] < 4.4


def test_fixed_points_a_fine_edge_apart_get_no_midpoints_between_them():
    # a strip's cut: points 1.05 sizes apart all stay fixed on the first coarse level (it keeps
    # those half its size apart); midpoints between them crowded and cost the finest level a
    # settle round (17 iterations instead of 6)
    half = tm.geometry.Disk((0, 0), 1) & tm.geometry.Rectangle((0, -1.1), (1.1, 1.1))
    cut = np.column_stack([np.zeros(191), np.linspace(-1, 1, 191)])
    mesh = tm.generate_mesh(half, 0.01, fixed_points=cut, levels=1, seed=0)
    assert_valid(mesh, half, 0.01)
    assert mesh.info["levels"][-1]["iterations"] <= 8
    assert np.all(np.min(np.linalg.norm(mesh.points[:, None] - cut[None], axis=2), axis=0) == 0.0)
    assert 0.98 <= np.median(edge_length_ratio(mesh.points, mesh.cells, 0.01)) <= 1.02
    assert triangle_quality(mesh.points, mesh.cells).min() > 0.7


def test_a_chain_of_fixed_points_exactly_half_a_coarse_size_apart_keeps_its_first():
    # a strip's cut at h = 0.002, one fine edge apart: half the first coarse level's size. Whether a
    # pair counted as close went by rounding (12 of 1,001 points dropped, at irregular places)
    y = np.linspace(-1, 1, 1001)
    cut = np.column_stack([np.zeros_like(y), y])
    np.testing.assert_array_equal(np.flatnonzero(spread_mask(cut, lambda p: np.full(len(p), 0.004))), [0])
    assert spread_mask(cut, lambda p: np.full(len(p), 0.0039)).all()


def test_refined_midpoints_move_by_the_jitter_asked_and_boundary_ones_land_on_it():
    ball = tm.geometry.primitives3d.Ball((0, 0, 0), 1.0)
    points = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 0], [0, 0, 0.5]])
    edges = np.array([[0, 1], [2, 3]])
    on_boundary = np.array([True, False])

    def project(middle, distance):  # onto the sphere along the radius
        return middle / np.linalg.norm(middle, axis=1)[:, None]

    plain = refined_points(ball, points, edges, on_boundary, project)
    jitter = np.array([[0.01, -0.01, 0.005], [-0.01, 0.01, 0.01]])
    moved = refined_points(ball, points, edges, on_boundary, project, jitter)
    assert np.allclose(moved[1] - plain[1], 0.5 * jitter[1])  # an interior midpoint: by its edge's length, 0.5
    assert abs(np.linalg.norm(moved[0]) - 1.0) < 1e-12 and not np.allclose(moved[0], plain[0])
