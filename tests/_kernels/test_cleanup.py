"""Clean-up kernels agree with their sorting (NumPy, SciPy) definitions; smoothing keeps its guarantees."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import Delaunay

from terramesh._kernels.cleanup import (
    boundary_degree,
    centroids_surely_inside,
    edge_census,
    edge_components,
    neighbor_table,
    shortest_edges,
    signed_areas,
    smooth_vertices,
    table_components,
)
from terramesh._kernels.smoothing import smooth_interior
from terramesh._kernels.topology import lone_edges, subset
from terramesh.geometry import Disk
from terramesh.mesh.topology import boundary_edges, boundary_vertex_degree, cell_neighbor_table, cell_neighbours
from terramesh.quality import triangle_quality

# any triples of a few vertex numbers: repeated corners, repeated cells, edges in many cells
raw_cells = arrays(np.int64, st.tuples(st.integers(0, 12), st.just(3)), elements=st.integers(0, 5))


def conforming(seed, fraction):
    """A random subset of a Delaunay triangulation (conforming, with holes and detached parts)."""
    rng = np.random.default_rng(seed)
    points = rng.uniform(size=(60, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    return points, np.ascontiguousarray(cells[rng.uniform(size=len(cells)) < fraction])


def directed_edges(cells):
    """Edge 0-1 of every cell, then 1-2, then 2-0."""
    return np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]])


@settings(max_examples=200, deadline=None)
@given(raw_cells)
def test_lone_edges_are_the_edges_sorting_finds_once(cells):
    directed = directed_edges(cells)
    _, inverse, counts = np.unique(np.sort(directed, axis=1), axis=0, return_inverse=True, return_counts=True)
    np.testing.assert_array_equal(lone_edges(cells, 6), directed[counts[inverse.ravel()] == 1].reshape(-1, 2))


@settings(max_examples=200, deadline=None)
@given(raw_cells)
def test_edge_census_matches_sorting(cells):
    repeated, n_repeated_edges, degree = edge_census(cells, 6)
    first = np.unique(np.sort(cells, axis=1), axis=0, return_index=True)[1]
    expected = np.ones(len(cells), dtype=bool)
    expected[first] = False  # np.unique returns the first occurrence of each
    np.testing.assert_array_equal(repeated, expected)
    keys = directed_edges(cells) @ [6, 1]
    _, inverse, counts = np.unique(keys, return_inverse=True, return_counts=True)
    assert n_repeated_edges == np.sum(counts[inverse] > 1)
    np.testing.assert_array_equal(degree, boundary_vertex_degree(cells, 6))


@settings(max_examples=50, deadline=None)
@given(arrays(np.float64, (6, 2), elements=st.floats(-1e3, 1e3)), raw_cells)
def test_signed_areas_match_numpy(points, cells):
    a, b, c = (points[cells[:, i]] for i in range(3))
    expected = 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    np.testing.assert_array_equal(signed_areas(points, cells), expected)


@settings(max_examples=200, deadline=None)
@given(raw_cells)
def test_edge_components_match_scipy(cells):
    m = len(cells)
    pairs = cell_neighbours(cells)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(m, m))
    n_parts, labels = connected_components(graph, directed=False)
    found_parts, found = edge_components(cells, 6)
    assert found_parts == n_parts
    np.testing.assert_array_equal(found, labels)  # numbered alike: by each part's first cell


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.3, 1.0))
def test_neighbour_table_kernels_match_sorting_on_conforming_meshes(seed, fraction):
    points, cells = conforming(seed, fraction)
    table = neighbor_table(cells, len(points))
    np.testing.assert_array_equal(table, cell_neighbor_table(cells))
    degree = boundary_degree(cells, table, len(points))
    np.testing.assert_array_equal(degree, boundary_vertex_degree(cells, len(points)))
    n_parts, labels = table_components(table)
    expected_parts, expected = edge_components(cells, len(points))
    assert n_parts == expected_parts
    np.testing.assert_array_equal(labels, expected)
    keep = np.random.default_rng(seed).uniform(size=len(cells)) < 0.7
    kept, kept_table = subset(cells, table, keep)
    np.testing.assert_array_equal(kept, cells[keep])
    np.testing.assert_array_equal(kept_table, cell_neighbor_table(cells[keep]))


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.3, 1.0))
def test_shortest_edges_match_numpy(seed, fraction):
    points, cells = conforming(seed, fraction)
    edges = directed_edges(cells)
    expected = np.full(len(points), np.inf)
    length = np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)
    np.minimum.at(expected, edges.ravel(), np.repeat(length, 2))
    np.testing.assert_allclose(shortest_edges(points, cells), expected, rtol=1e-15)


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.0, 0.2))
def test_centroids_surely_inside_are_inside(seed, shift):
    points, cells = conforming(seed, 1.0)
    disk = Disk((0.5, 0.5), 0.45)
    moved = points + np.random.default_rng(seed).uniform(-shift, shift, points.shape)
    sure = centroids_surely_inside(moved, cells, points, disk.distance(points))
    centroids = moved[cells].mean(axis=1)
    assert np.all(disk.distance(centroids[sure]) < 0)
    assert sure.sum() > 0.5 * np.sum(disk.distance(centroids) < -0.2)  # deep cells need no evaluation


def jittered_patch(seed, amplitude, origin=(0.0, 0.0), scale=1.0):
    """A hexagonal 10 x 10 patch with its interior vertices jittered, and the mask of those."""
    rows, columns = np.meshgrid(np.arange(10), np.arange(10), indexing="ij")
    points = np.column_stack([columns.ravel() + 0.5 * (rows.ravel() % 2), np.sqrt(3) / 2 * rows.ravel()])
    cells = Delaunay(points).simplices.astype(np.int64)
    cells = np.ascontiguousarray(np.where((triangle_quality(points, cells) < 0)[:, None], cells[:, [0, 2, 1]], cells))
    movable = np.ones(len(points), dtype=bool)
    movable[boundary_edges(cells).ravel()] = False
    rng = np.random.default_rng(seed)
    points[movable] += amplitude * rng.uniform(-1, 1, (movable.sum(), 2))
    return np.asarray(origin) + scale * points, cells, movable


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.05, 0.35))
def test_smoothing_matches_the_generator_kernel_on_the_plane(seed, amplitude):
    points, cells, movable = jittered_patch(seed, amplitude)
    expected = points.copy()
    smooth_interior(expected, cells, movable, 3)
    smoothed = points.copy()
    moved = smooth_vertices(smoothed, cells, movable, 3, False)
    np.testing.assert_array_equal(smoothed, expected)
    np.testing.assert_array_equal(moved, np.any(smoothed != points, axis=1))


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.05, 0.35), st.floats(-70, 70))
def test_geographic_smoothing_never_lowers_the_worst_cell_on_the_ground(seed, amplitude, latitude):
    points, cells, movable = jittered_patch(seed, amplitude, origin=(-60.0, latitude), scale=0.02)
    before = triangle_quality(points, cells, geographic=True)
    smoothed = points.copy()
    moved = smooth_vertices(smoothed, cells, movable, 3, True)
    after = triangle_quality(smoothed, cells, geographic=True)
    assert after.min() >= before.min() and after.min() > 0
    assert not moved[~movable].any() and moved.sum() > 0
    np.testing.assert_array_equal(smoothed[~moved], points[~moved])
