"""Quality and edge lengths in a metric: the plain measures where the metric is round, the mapped ones where not."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError, SizingError
from terramesh.mesh.topology import unique_edges
from terramesh.quality import metric_edge_lengths, metric_quality, triangle_quality
from terramesh.sizing import metric_tensor


@pytest.fixture(scope="module")
def disk():
    return tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, seed=0)


def test_a_round_metric_measures_as_the_plane_does(disk):
    metric = metric_tensor(0.1, 0.1, 0.7)
    assert np.allclose(metric_quality(disk.points, disk.cells, metric), triangle_quality(disk.points, disk.cells))
    edges = unique_edges(disk.cells)
    plain = np.hypot(*(disk.points[edges[:, 0]] - disk.points[edges[:, 1]]).T)
    assert np.allclose(metric_edge_lengths(disk.points, disk.cells, metric), plain / 0.1)


def test_a_stretched_mesh_measures_as_the_mesh_it_was_stretched_from(disk):
    # stretch the disk mesh 5 times along 40 degrees: in the metric that stretch asks for, nothing changed
    angle = np.radians(40)
    turn = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    stretched = disk.points @ turn @ np.diag([5.0, 1.0]) @ turn.T
    metric = metric_tensor(0.5, 0.1, angle)
    assert np.allclose(metric_quality(stretched, disk.cells, metric), triangle_quality(disk.points, disk.cells))
    assert triangle_quality(stretched, disk.cells).mean() < 0.5


def test_a_field_is_taken_at_the_corners_and_bad_input_is_refused(disk):
    def field(points):  # long along x on the right, along y on the left
        return metric_tensor(0.2, 0.05, np.where(points[:, 0] > 0, 0.0, np.pi / 2))

    assert metric_quality(disk.points, disk.cells, field).shape == (disk.n_cells,)
    # a cell with a different matrix at each corner is measured in their mean
    corners = np.array([[0.0, 0.0], [0.3, 0.05], [0.1, 0.2]])
    matrices = metric_tensor([0.2, 0.1, 0.3], [0.05, 0.08, 0.02], [0.0, 0.5, 1.0])
    mean = matrices.mean(axis=0)
    sides = corners[[1, 2, 0]] - corners
    area = 0.5 * (sides[0, 0] * -sides[2, 1] + sides[0, 1] * sides[2, 0])
    expected = 4 * np.sqrt(3) * area * np.sqrt(np.linalg.det(mean)) / np.einsum("ij,jk,ik->", sides, mean, sides)
    assert metric_quality(corners, [[0, 1, 2]], lambda p: matrices)[0] == pytest.approx(expected, rel=1e-12)
    with pytest.raises(SizingError, match="positive definite"):
        metric_quality(disk.points, disk.cells, lambda p: -np.tile(np.eye(2), (len(p), 1, 1)))
    with pytest.raises(MeshValidityError, match="do not exist"):
        metric_edge_lengths(disk.points, disk.cells + disk.n_points, np.eye(2))
    with pytest.raises(MeshValidityError, match=r"shape \(n, 2\)"):
        metric_quality(np.zeros((3, 3)), [[0, 1, 2]], np.eye(2))


@pytest.mark.parametrize("measure", [metric_quality, metric_edge_lengths])
def test_a_corner_that_is_nan_or_infinite_is_refused_not_scored(measure):
    """A NaN corner gave a metric quality of 0, a flat cell, without a word."""
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, np.nan]])
    with pytest.raises(MeshValidityError, match=r"NaN or infinite at 1 of 3 points \(index 2 first\)"):
        measure(points, [[0, 1, 2]], np.eye(2))
