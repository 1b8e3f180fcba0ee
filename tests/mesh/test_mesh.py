"""The Mesh container: what it accepts and refuses."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError

TRIANGLE = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


@pytest.mark.parametrize(
    "points, cells, message",
    [
        (TRIANGLE, [[0, 1, 2.9]], "cells must be integer vertex indices, got float64"),  # was cast to [0, 1, 2]
        (TRIANGLE, [["a", "b", "c"]], "cells must be integer vertex indices"),
        ([["a", "b"]], [[0, 1, 2]], "points must be numbers"),
        (TRIANGLE, [[0, 1, 3]], "vertices that do not exist"),
        (np.array([[0.0, np.nan], [1, 0], [0, 1]]), [[0, 1, 2]], "NaN or infinite at 1 of 3 points"),
    ],
)
def test_bad_points_and_cells_are_refused_by_name(points, cells, message):
    with pytest.raises(MeshValidityError, match=message):
        tm.Mesh(points, cells)


def test_whole_numbers_and_unsigned_integers_are_cell_indices():
    for cells in ([[0, 1, 2.0]], np.array([[0, 1, 2]], dtype=np.uint32)):
        mesh = tm.Mesh(TRIANGLE, cells)
        assert mesh.cells.dtype == np.int64 and mesh.cells.tolist() == [[0, 1, 2]]
