import numpy as np
from scipy.spatial import Delaunay

from terramesh._kernels.topology import cell_edges
from terramesh.mesh.topology import boundary_edges, cell_neighbor_table, unique_edges


def test_cell_edges_match_the_sorting_reference():
    points = np.random.default_rng(5).uniform(size=(500, 2))
    cells = Delaunay(points).simplices.astype(np.int64)
    neighbors = cell_neighbor_table(cells)
    np.testing.assert_array_equal(neighbors, Delaunay(points).neighbors)
    edges, on_boundary = cell_edges(cells, neighbors)
    np.testing.assert_array_equal(np.unique(np.sort(edges, axis=1), axis=0), unique_edges(cells))
    expected_boundary = np.unique(np.sort(boundary_edges(cells), axis=1), axis=0)
    np.testing.assert_array_equal(np.unique(np.sort(edges[on_boundary], axis=1), axis=0), expected_boundary)
