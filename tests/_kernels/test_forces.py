import numpy as np
import pytest

from terramesh._kernels.forces import edge_size_ratios, spring_forces
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


def test_spring_forces_match_numpy_reference():
    rng = np.random.default_rng(3)
    points = rng.uniform(size=(300, 2))
    from scipy.spatial import Delaunay

    edges = unique_edges(Delaunay(points).simplices)
    target = rng.uniform(0.05, 0.1, size=300)
    np.testing.assert_allclose(
        spring_forces(points, edges, target, 1.2), reference_forces(points, edges, target, 1.2), atol=1e-13
    )


def test_forces_are_balanced():
    rng = np.random.default_rng(4)
    points = rng.uniform(size=(100, 3))
    edges = np.column_stack([np.arange(99), np.arange(1, 100)])
    force = spring_forces(points, edges, np.ones(100), 1.2)
    np.testing.assert_allclose(force.sum(axis=0), 0, atol=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_edge_size_ratios_equal_numpys_to_the_bit(dim):
    rng = np.random.default_rng(4)
    points = rng.random((500, dim)) * rng.choice([1e-3, 1.0, 1e5], (500, dim))
    edges = rng.integers(0, 500, (5000, 2))
    target = rng.random(500) + 0.1
    lengths = np.sqrt(np.sum((points[edges[:, 0]] - points[edges[:, 1]]) ** 2, axis=1))
    expected = lengths / (0.5 * (target[edges[:, 0]] + target[edges[:, 1]]))
    np.testing.assert_array_equal(edge_size_ratios(points, edges, target), expected)
