import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import Delaunay

from terramesh._kernels.topology import (
    inner_cell_edges,
    quality_mean_std,
    rows_renumbered,
    subset,
    table_boundary_edges,
)
from terramesh.cleanup.fix_mesh import delete_interior_cells, delete_interior_cells_with_table
from terramesh.mesh.topology import boundary_edges, cell_neighbor_table, unique_edges


@pytest.mark.parametrize("fraction", [1.0, 0.7])
def test_inner_cell_edges_match_the_sorting_reference(fraction):
    points = np.random.default_rng(5).uniform(size=(500, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    neighbors = cell_neighbor_table(cells)
    np.testing.assert_array_equal(neighbors, Delaunay(points).neighbors)
    keep = np.random.default_rng(7).uniform(size=len(cells)) < fraction
    kept, edges, on_boundary = inner_cell_edges(cells, neighbors, keep, 0)
    np.testing.assert_array_equal(kept, cells[keep])
    np.testing.assert_array_equal(np.unique(np.sort(edges, axis=1), axis=0), unique_edges(cells[keep]))
    expected_boundary = np.unique(np.sort(boundary_edges(cells[keep]), axis=1), axis=0)
    np.testing.assert_array_equal(np.unique(np.sort(edges[on_boundary], axis=1), axis=0), expected_boundary)


@pytest.mark.parametrize("fraction", [1.0, 0.8, 0.5])
def test_the_tables_boundary_and_deletions_match_the_edge_matching_ones(fraction):
    # the generator's final clean-up follows the triangulation's table instead of matching edges
    points = np.random.default_rng(8).uniform(size=(400, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    keep = np.random.default_rng(9).uniform(size=len(cells)) < fraction  # pinched, non-manifold subsets
    kept, table = subset(cells, cell_neighbor_table(cells), keep)
    np.testing.assert_array_equal(table, cell_neighbor_table(kept))
    boundary = table_boundary_edges(kept, table)
    assert sorted(map(tuple, boundary)) == sorted(map(tuple, boundary_edges(kept)))  # same edges, same directions
    repaired, repaired_table = delete_interior_cells_with_table(points, kept, table)
    np.testing.assert_array_equal(repaired, delete_interior_cells(points, kept))
    np.testing.assert_array_equal(repaired_table, cell_neighbor_table(repaired))
    if fraction < 1:
        assert len(repaired) < len(kept)  # the draw has vertices with more than two boundary edges


def test_quality_statistics_match_numpy():
    from terramesh.quality import triangle_quality

    points = np.random.default_rng(6).uniform(size=(300, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    q = triangle_quality(points, cells)
    mean, std = quality_mean_std(points, cells)
    assert mean == pytest.approx(q.mean(), rel=1e-12)
    assert std == pytest.approx(q.std(), rel=1e-9)


def test_quality_statistics_are_the_same_to_the_bit_on_any_number_of_threads(one_thread):
    points = np.random.default_rng(7).uniform(size=(3000, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    with one_thread():
        alone = quality_mean_std(points, cells)
    assert quality_mean_std(points, cells) == alone


@settings(deadline=None, max_examples=30)
@given(st.integers(0, 2**32 - 1), st.sampled_from([2, 3]), st.floats(0.0, 0.05), st.sampled_from([60, 60, 9000]))
def test_classify_cells_follows_its_rule_and_only_proves_true_insides(seed, dim, tolerance, count):
    """Up to ~60k cells: several of the parallel pass's tasks."""
    from terramesh._kernels.topology import cell_centroids, classify_cells

    rng = np.random.default_rng(seed)
    points = rng.uniform(-1.2, 1.2, size=(count, dim))
    cells = Delaunay(points).simplices.astype(np.int64)
    distance = np.linalg.norm(points, axis=1) - 1.0  # the unit disk or ball: 1-Lipschitz
    bound = distance + rng.uniform(0, 0.1, size=len(points))  # upper bounds, as the generator keeps them
    state = classify_cells(points, cells, bound, tolerance, 0)
    centroids = cell_centroids(points, cells, np.arange(len(cells)), 0)
    # the rule: some vertex's bound plus its distance to the centroid is below -tolerance
    reach = bound[cells] + np.linalg.norm(points[cells] - centroids[:, None, :], axis=2)
    np.testing.assert_array_equal(state == 1, reach.min(axis=1) < -tolerance)
    assert np.all(np.linalg.norm(centroids[state == 1], axis=1) - 1.0 < -tolerance)
    assert np.all(classify_cells(points, cells, np.empty(0), tolerance, 0) == 0)  # no bound: all to evaluate


@settings(deadline=None, max_examples=40)
@given(st.integers(0, 2**32 - 1), st.sampled_from([2, 3]), st.floats(0.0, 1.0))
def test_rows_renumbered_match_the_numpy_definition(seed, width, share_removed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 60))
    table = rng.integers(0, n, size=(int(rng.integers(0, 200)), width))
    kept = rng.random(n) >= share_removed
    numbering = np.where(kept, np.cumsum(kept) - 1, -1)
    expected = (np.cumsum(kept) - 1)[table[kept[table].all(axis=1)]]
    np.testing.assert_array_equal(rows_renumbered(table, numbering), expected.reshape(-1, width))


@pytest.mark.parametrize("geographic", [True, False])
def test_shortest_sides_is_the_smallest_side_length_at_each_vertex(geographic):
    from terramesh._kernels.topology import shortest_sides
    from terramesh.coastal.projection import EARTH_RADIUS
    from terramesh.coastal.timestep import edge_lengths

    rng = np.random.default_rng(5)
    points = rng.uniform([-180, -80], [180, 80], (40, 2))
    cells = np.array([rng.permutation(40)[:3] for _ in range(60)])
    sides = np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
    expected = np.full(50, np.inf)  # vertices 40..49 in no cell: inf
    lengths = edge_lengths(points, sides, geographic=geographic)
    np.minimum.at(expected, sides[:, 0], lengths)
    np.minimum.at(expected, sides[:, 1], lengths)
    all_points = np.vstack([points, np.zeros((10, 2))])
    x, y = (np.radians(all_points[:, 0]), np.radians(all_points[:, 1])) if geographic else all_points.T.copy()
    radius = EARTH_RADIUS if geographic else 1.0
    found = shortest_sides(cells, x, y, np.cos(y), radius, geographic)
    np.testing.assert_allclose(found, expected, rtol=1e-13)
    assert np.all(np.isinf(found[40:]))
    assert np.array_equal(
        shortest_sides(np.zeros((0, 3), np.int64), x, y, np.cos(y), radius, geographic), np.full(50, np.inf)
    )
