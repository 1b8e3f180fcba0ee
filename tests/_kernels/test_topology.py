import numpy as np
import pytest
from scipy.spatial import Delaunay

from terramesh._kernels.topology import inner_cell_edges, quality_mean_std
from terramesh.mesh.topology import boundary_edges, cell_neighbor_table, unique_edges


@pytest.mark.parametrize("fraction", [1.0, 0.7])
def test_inner_cell_edges_match_the_sorting_reference(fraction):
    points = np.random.default_rng(5).uniform(size=(500, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    neighbors = cell_neighbor_table(cells)
    np.testing.assert_array_equal(neighbors, Delaunay(points).neighbors)
    keep = np.random.default_rng(7).uniform(size=len(cells)) < fraction
    kept, edges, on_boundary = inner_cell_edges(cells, neighbors, keep)
    np.testing.assert_array_equal(kept, cells[keep])
    np.testing.assert_array_equal(np.unique(np.sort(edges, axis=1), axis=0), unique_edges(cells[keep]))
    expected_boundary = np.unique(np.sort(boundary_edges(cells[keep]), axis=1), axis=0)
    np.testing.assert_array_equal(np.unique(np.sort(edges[on_boundary], axis=1), axis=0), expected_boundary)


def test_quality_statistics_match_numpy():
    from terramesh.quality import triangle_quality

    points = np.random.default_rng(6).uniform(size=(300, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    q = triangle_quality(points, cells)
    mean, std = quality_mean_std(points, cells)
    assert mean == pytest.approx(q.mean(), rel=1e-12)
    assert std == pytest.approx(q.std(), rel=1e-9)
