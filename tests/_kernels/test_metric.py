"""The metric kernels: Delaunay flips in a metric, and forces, lengths and quality measured in it."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from terramesh._kernels import metric as kernel
from terramesh.generation.triangulate import delaunay_with_neighbors
from terramesh.mesh.topology import cell_neighbor_table, unique_edges
from terramesh.sizing import metric_tensor


def facing_angle_sums(points, cells, neighbors):
    """The two angles facing each inner edge, summed (pi or less everywhere: Delaunay)."""
    sums = []
    for t, k in zip(*np.nonzero(neighbors >= 0), strict=True):
        t2 = neighbors[t, k]
        if t2 < t:
            continue
        p, u, v = cells[t, k], cells[t, (k + 1) % 3], cells[t, (k + 2) % 3]
        z = cells[t2][~np.isin(cells[t2], (u, v))][0]
        total = 0.0
        for corner in (p, z):
            a, b = points[u] - points[corner], points[v] - points[corner]
            total += np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))
        sums.append(total)
    return np.array(sums)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(1.0, 30.0), st.floats(0.0, np.pi))
def test_flips_in_a_constant_metric_give_the_delaunay_triangulation_of_the_mapped_points(seed, ratio, angle):
    # a constant metric M = A^T A is the plane mapped by A: its Delaunay test is the plain one there
    points = np.random.default_rng(seed).random((300, 2))
    cells, neighbors = delaunay_with_neighbors(points)
    metric = metric_tensor(1.0, 1.0 / ratio, angle)
    flips = kernel.metric_delaunay_flips(points, cells, neighbors, np.tile(metric, (300, 1, 1)), 1000, 0.0)
    assert (ratio < 1.5 or flips > 0) and not kernel.inverted_cell_mask(points, cells).any()
    assert np.array_equal(neighbors, cell_neighbor_table(cells))  # the table follows the flips
    mapped = points @ np.linalg.cholesky(metric)  # x -> L^T x with M = L L^T: lengths in M are plain ones here
    assert facing_angle_sums(mapped, cells, neighbors).max() <= np.pi + 1e-9
    # and the plane's own test fails somewhere once the metric is far from round
    if ratio > 5:
        assert facing_angle_sums(points, cells, neighbors).max() > np.pi + 0.1


def test_forces_push_apart_what_is_short_and_pull_in_what_is_long_in_the_metric():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.1]])
    edges = np.array([[0, 1], [0, 2]])
    metric = np.tile(metric_tensor(2.0, 0.05, 0.0), (3, 1, 1))  # x edge: 0.5 long (short); y edge: 2 (long)
    moves, travelled = kernel.force_moves(points, edges, metric, 1.0, 0.2, 0)
    assert moves[1, 0] > 0 and moves[2, 1] < 0  # 1 pushed away along x, 2 pulled in along y
    assert travelled[1] == np.sqrt(moves[1, 0] ** 2 / 4.0)  # a move measured in the metric too
    _, travelled_fixed = kernel.force_moves(points, edges, metric, 1.0, 0.2, 3)
    assert not travelled_fixed.any()


def test_lengths_and_quality_are_the_metric_space_ones():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.05 * np.sqrt(3) / 2]])
    cells = np.array([[0, 1, 2]])
    metric = np.tile(metric_tensor(1.0, 0.05, 0.0), (3, 1, 1))
    assert np.allclose(kernel.edge_lengths(points, unique_edges(cells), metric), 1.0)
    assert np.isclose(kernel.cell_qualities(points, cells, metric)[0], 1.0)
    assert kernel.cell_qualities(points, cells[:, ::-1], metric)[0] < 0  # clockwise scores negative


def test_thinning_takes_one_end_of_each_short_edge_and_never_a_fixed_point():
    edges = np.array([[0, 1], [1, 2], [2, 3], [4, 5]])
    doomed = kernel.thinned_ends(edges, 6, 1)
    assert np.flatnonzero(doomed).tolist() == [1, 3, 5]  # (1, 2) kept: 1 goes already
    assert not kernel.thinned_ends(np.array([[0, 1]]), 2, 2).any()


def test_a_point_crossing_a_boundary_edge_is_found_with_its_cell():
    # the unit square fanned from an inner point 4, which a move takes across the bottom edge (0, 1)
    points = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, -0.1]])
    cells = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    neighbors = cell_neighbor_table(cells)
    inverted = kernel.inverted_cell_mask(points, cells)
    assert inverted.tolist() == [True, False, False, False]
    crossing, joining = kernel.crossed_boundary_edges(cells, neighbors, inverted, 5, 0)
    assert crossing.tolist() == [True, False, False, False] and joining.tolist() == [4]
    # a fixed point does not join the boundary (nor does one already on it: it would pinch it)
    _, none = kernel.crossed_boundary_edges(cells, neighbors, inverted, 5, 5)
    assert len(none) == 0
