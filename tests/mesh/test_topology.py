import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError
from terramesh.mesh import topology

square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
two_cells = np.array([[0, 1, 2], [0, 2, 3]])


def test_edges_and_boundary():
    assert topology.unique_edges(two_cells).tolist() == [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]
    boundary = topology.boundary_edges(two_cells)
    assert sorted(map(tuple, boundary.tolist())) == [(0, 1), (1, 2), (2, 3), (3, 0)]
    np.testing.assert_array_equal(topology.boundary_vertex_degree(two_cells, 4), [2, 2, 2, 2])
    assert topology.cell_neighbours(two_cells).tolist() == [[0, 1]]
    np.testing.assert_allclose(topology.signed_areas(square, two_cells), [0.5, 0.5])


def test_mesh_rejects_bad_arrays():
    with pytest.raises(MeshValidityError, match="do not exist"):
        tm.Mesh(square, np.array([[0, 1, 7]]))
    with pytest.raises(MeshValidityError, match="shape"):
        tm.Mesh(square[:, :1], two_cells)
    with pytest.raises(MeshValidityError, match="point_data"):
        tm.Mesh(square, two_cells, point_data={"depth": np.ones(3)})
