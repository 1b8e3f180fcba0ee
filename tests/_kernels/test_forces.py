import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import Delaunay

from terramesh._kernels.chunks import CHUNKS
from terramesh._kernels.forces import (
    edge_size_ratios,
    force_step,
    neighbor_lists,
    rest_length_scale,
    stale_distances,
    sweep_step,
)
from terramesh.mesh.topology import unique_edges


def reference_forces(points, edges, target, factor):
    vectors = points[edges[:, 0]] - points[edges[:, 1]]
    lengths = np.linalg.norm(vectors, axis=1)
    rest = 0.5 * (target[edges[:, 0]] + target[edges[:, 1]])
    rest = rest * factor * np.sqrt(np.sum(lengths**2) / np.sum(rest**2))
    push = np.maximum(rest - lengths, 0)
    per_edge = (push / lengths)[:, None] * vectors
    force = np.zeros_like(points)
    np.add.at(force, edges[:, 0], per_edge)
    np.add.at(force, edges[:, 1], -per_edge)
    return force


def spring_forces(points, edges, target, factor):
    """The net force on each point: a step of time 1 from none fixed."""
    scale = rest_length_scale(points, edges, target, factor, CHUNKS)
    return force_step(points, edges, target, scale, 1.0, 0, CHUNKS)[0] - points


def sweep(points, edges, target, factor, relaxation, boundary_relaxation, n_fixed, normal):
    scale = rest_length_scale(points, edges, target, factor, CHUNKS)
    lists = neighbor_lists(edges, len(points))
    return sweep_step(points, *lists, target, scale, relaxation, boundary_relaxation, n_fixed, normal)


def test_force_step_matches_numpy_reference():
    rng = np.random.default_rng(3)
    points = rng.uniform(size=(300, 2))
    edges = unique_edges(Delaunay(points).simplices)
    target = rng.uniform(0.05, 0.1, size=300)
    scale = rest_length_scale(points, edges, target, 1.2, CHUNKS)
    moved, move = force_step(points, edges, target, scale, 0.2, 7, CHUNKS)
    expected = points + 0.2 * reference_forces(points, edges, target, 1.2)
    np.testing.assert_allclose(moved[7:], expected[7:], atol=1e-13)
    np.testing.assert_array_equal(moved[:7], points[:7])  # fixed, to the bit
    np.testing.assert_allclose(move, np.linalg.norm(moved - points, axis=1), atol=1e-13)


def test_forces_are_balanced():
    rng = np.random.default_rng(4)
    points = rng.uniform(size=(100, 3))
    edges = np.column_stack([np.arange(99), np.arange(1, 100)])
    force = spring_forces(points, edges, np.ones(100), 1.2)
    np.testing.assert_allclose(force.sum(axis=0), 0, atol=1e-12)


def test_force_step_is_the_same_to_the_bit_on_any_number_of_threads(one_thread):
    # the edges are summed in fixed chunks, not one per thread: the mesh must not depend on the machine
    rng = np.random.default_rng(5)
    points = rng.uniform(size=(2000, 2))
    edges = unique_edges(Delaunay(points).simplices)
    target = rng.uniform(0.01, 0.03, size=2000)
    with one_thread():
        scale_alone = rest_length_scale(points, edges, target, 1.2, CHUNKS)
        alone = force_step(points, edges, target, scale_alone, 0.2, 0, CHUNKS)
    scale = rest_length_scale(points, edges, target, 1.2, CHUNKS)
    together = force_step(points, edges, target, scale, 0.2, 0, CHUNKS)
    assert scale_alone == scale
    np.testing.assert_array_equal(alone[0], together[0])
    np.testing.assert_array_equal(alone[1], together[1])


@pytest.mark.parametrize("dim", [2, 3])
def test_edge_size_ratios_equal_numpys_to_the_bit(dim):
    rng = np.random.default_rng(4)
    points = rng.random((500, dim)) * rng.choice([1e-3, 1.0, 1e5], (500, dim))
    edges = rng.integers(0, 500, (5000, 2))
    target = rng.random(500) + 0.1
    lengths = np.sqrt(np.sum((points[edges[:, 0]] - points[edges[:, 1]]) ** 2, axis=1))
    expected = lengths / (0.5 * (target[edges[:, 0]] + target[edges[:, 1]]))
    np.testing.assert_array_equal(edge_size_ratios(points, edges, target), expected)


@settings(deadline=None, max_examples=50)
@given(st.lists(st.tuples(st.integers(0, 30), st.integers(0, 30)), max_size=120), st.integers(31, 40))
def test_neighbor_lists_hold_each_points_neighbours(pairs, n_points):
    edges = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    indptr, neighbors = neighbor_lists(edges, n_points)
    assert indptr[0] == 0 and indptr[-1] == 2 * len(edges) and np.all(np.diff(indptr) >= 0)
    for i in range(n_points):
        expected = sorted([b for a, b in pairs if a == i] + [a for a, b in pairs if b == i])
        assert sorted(neighbors[indptr[i] : indptr[i + 1]]) == expected


def reference_sweep(points, edges, target, factor, relaxation, boundary_relaxation, n_fixed, normal):
    """Point after point in Python, each force from the positions as moved so far."""
    scale = rest_length_scale(points, edges, target, factor, CHUNKS)
    moved = points.copy()
    for i in range(n_fixed, len(points)):
        force = np.zeros(2)
        for a, b in edges:
            if i in (a, b):
                j = b if a == i else a
                vector = moved[i] - moved[j]
                length = np.linalg.norm(vector)
                push = 0.5 * (target[i] + target[j]) * scale - length
                if push > 0:
                    force += push / length * vector
        step = relaxation
        if np.any(normal[i] != 0):
            step = boundary_relaxation
            force -= max(force @ normal[i], 0.0) * normal[i]
        moved[i] += step * force
    return moved


def crowded_patch(seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(size=(60, 2))
    return points, unique_edges(Delaunay(points).simplices), rng.uniform(0.1, 0.3, 60)


def test_a_sweep_moves_each_point_from_the_positions_moved_before_it():
    points, edges, target = crowded_patch(5)
    normal = np.zeros_like(points)
    moved, move, clamped = sweep(points, edges, target, 1.15, 0.5, 0.3, 10, normal)
    expected = reference_sweep(points, edges, target, 1.15, 0.5, 0.3, 10, normal)
    np.testing.assert_allclose(moved, expected, atol=1e-13)
    np.testing.assert_array_equal(moved[:10], points[:10])  # fixed
    np.testing.assert_allclose(move, np.linalg.norm(moved - points, axis=1), atol=1e-13)
    assert not clamped.any()
    # not a simultaneous step: the later points saw the earlier ones moved
    simultaneous = points + 0.5 * spring_forces(points, edges, target, 1.15)
    assert np.abs(moved[11:] - simultaneous[11:]).max() > 1e-3


def test_a_point_on_the_boundary_moves_along_it_not_out():
    points, edges, target = crowded_patch(6)
    force = spring_forces(points, edges, target, 1.15)
    normal = np.zeros_like(points)
    # the last point: the boundary's outward normal along its force (it would leave), then against it (it may go in)
    for sign, leaves in [(1.0, True), (-1.0, False)]:
        outward = np.array([force[-1, 1], -force[-1, 0]]) + 0.5 * force[-1]  # partly along the force
        normal[-1] = sign * outward / np.linalg.norm(outward)
        moved, _, clamped = sweep(points, edges, target, 1.15, 0.5, 0.3, 59, normal)
        step = moved[-1] - points[-1]
        expected = reference_sweep(points, edges, target, 1.15, 0.5, 0.3, 59, normal)
        np.testing.assert_allclose(step, expected[-1] - points[-1], atol=1e-15)
        assert clamped[-1] == leaves and not clamped[:-1].any()
        if leaves:
            assert abs(step @ normal[-1]) < 1e-15  # tangential only
        else:
            np.testing.assert_allclose(step, 0.3 * force[-1], atol=1e-15)


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**16), st.integers(0, 300))
def test_stale_distances_are_the_points_numpy_finds_near_the_boundary(seed, count):
    """The one pass against NumPy's formula, to the bit: the same points listed, the drifts the same."""
    rng = np.random.default_rng(seed)
    distance = rng.normal(-0.2, 0.3, count)
    distance[rng.random(count) < 0.2] = 0.0
    drift, moved, target = rng.exponential(0.01, count), rng.exponential(0.01, count), rng.uniform(0.01, 0.1, count)
    expected_drift = drift + moved
    stale = distance + 0.02 * np.abs(distance) + expected_drift > -0.1 * target
    expected_drift[stale] = 0.0
    listed = stale_distances(distance, drift, moved, target, 0.02, 0.1)
    np.testing.assert_array_equal(listed, np.flatnonzero(stale))
    np.testing.assert_array_equal(drift, expected_drift)
