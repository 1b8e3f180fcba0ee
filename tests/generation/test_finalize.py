"""The final repair of a generated mesh (terramesh.generation.finalize): what it refuses, caps it flips."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import GenerationError
from terramesh.generation.finalize import _check_repaired
from terramesh.quality import triangle_quality


def test_a_pinch_left_after_the_repairs_is_located_and_explained():
    """Two cells meeting at one vertex (sweep run 40122: the tip of a crack in a random-walk coast)."""
    points = np.array([(0, 0), (1, 0), (0.5, 0.5), (1, 1), (0, 1)], dtype=float)
    cells = np.array([(0, 1, 2), (2, 3, 4)])
    boundary = np.array([(0, 1), (1, 2), (2, 0), (2, 3), (3, 4), (4, 2)])
    with pytest.raises(GenerationError) as raised:
        _check_repaired(points, cells, boundary)
    message = str(raised.value)
    assert "1 boundary vertices without exactly two boundary edges (one at (0.5, 0.5))" in message
    assert "narrower than about an edge length" in message and "smaller edge length" in message
    _check_repaired(points, cells[:1], boundary[:3])  # one cell: nothing to say


def test_an_inverted_cell_left_after_the_repairs_is_located():
    points = np.array([(0, 0), (1, 0), (0, 1)], dtype=float)
    with pytest.raises(
        GenerationError, match=r"1 cells that are clockwise or flat \(one at \(0\.333333, 0\.333333\)\)"
    ):
        _check_repaired(points, np.array([(0, 2, 1)]), np.array([(0, 2), (2, 1), (1, 0)]))


def test_a_cap_is_flipped_into_its_neighbour_where_that_helps():
    # a boundary vertex projected onto its own cell's far edge leaves a cap (q 0.02 on a jagged coast): its
    # long edge flips where both new cells are better and inside the domain; on the boundary it stays
    from terramesh.generation.finalize import _flipped_caps
    from terramesh.mesh.topology import boundary_edges

    points = np.array([[1.0, -0.05], [2.0, 0.0], [0.0, 0.0], [1.0, 1.0]])  # the apex under the long edge
    cells = np.array([[0, 1, 2], [2, 1, 3]])
    room = tm.geometry.Rectangle((-1, -1), (3, 2))
    flipped = _flipped_caps(room, points, cells)
    assert sorted(map(tuple, flipped.tolist())) == [(0, 1, 3), (0, 3, 2)]
    assert triangle_quality(points, cells).min() < 0.1 < 0.5 < triangle_quality(points, flipped).min()
    assert sorted(map(tuple, boundary_edges(flipped).tolist())) == sorted(map(tuple, boundary_edges(cells).tolist()))
    lone = cells[:1]  # its long edge on the boundary
    assert _flipped_caps(room, points, lone) is lone
    holed = tm.geometry.Difference([room, tm.geometry.Disk((4 / 3, 0.95 / 3), 0.05)])  # a new cell's centroid off
    assert _flipped_caps(holed, points, cells) is cells
    # two caps on one long edge (a thin rhombus across it): one flip, onto the short diagonal
    rhombus = np.array([[1.0, -0.05], [2.0, 0.0], [0.0, 0.0], [1.0, 0.05]])
    flipped = _flipped_caps(room, rhombus, cells)
    assert sorted(map(tuple, flipped.tolist())) == [(0, 1, 3), (0, 3, 2)]
    assert triangle_quality(rhombus, flipped).min() > triangle_quality(rhombus, cells).max()


def test_caps_whose_flips_share_a_cell_flip_worst_first():
    # a cap of q 0.07 under a needle cap of q 0.25, whose long edge has a third cell beyond it: both flips
    # want the needle; refusing both (a cell in two flips) left the q 0.07 cell, pass after pass
    from terramesh.generation.finalize import _flipped_caps

    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.15], [0.5, -0.03], [0.25, 0.3]])
    cells = np.array([[0, 3, 1], [0, 1, 2], [2, 1, 4]])
    flipped = _flipped_caps(tm.geometry.Rectangle((-1, -1), (2, 2)), points, cells)
    assert triangle_quality(points, cells).min() < 0.07 and triangle_quality(points, flipped).min() > 0.45
    assert tm.cleanup.mesh_problems(tm.Mesh(points, flipped)) == []


def test_a_chain_of_caps_flips_worst_first_within_a_pass():
    # five cells whose flips want each other's cells in a chain: taking only the local worst of each pass left a
    # flip waiting for a worse one that was itself refused, and three passes ended at q 0.117 (review of 82aa888)
    from terramesh.generation.finalize import _flipped_caps

    points = np.array([[0.0739, 0.9817], [0.0421, 0.673], [0.1938, 0.441], [0.1168, 0.5329], [0.5683, 0.1657],
                       [0.6879, 0.9027], [0.9942, 0.0327]])  # fmt: skip
    cells = np.array([[5, 0, 1], [6, 5, 1], [4, 6, 2], [3, 2, 6], [1, 3, 6]])
    flipped = _flipped_caps(tm.geometry.Rectangle((-1, -1), (2, 2)), points, cells)
    assert triangle_quality(points, cells).min() < 0.08 and triangle_quality(points, flipped).min() >= 0.3
    assert tm.cleanup.mesh_problems(tm.Mesh(points, flipped)) == []


def test_a_flip_onto_a_centroid_on_the_boundary_is_refused():
    # the smoothing counts a centroid on the boundary as outside and freezes the cell's vertices: the flip
    # judges it the same way
    from terramesh.generation.finalize import _flipped_caps

    points = np.array([[1.0, -0.05], [2.0, 0.0], [0.0, 0.0], [1.0, 1.0]])
    cells = np.array([[0, 1, 2], [2, 1, 3]])
    tip = points[[0, 1, 3]].mean(axis=0)  # a new cell's centroid, at the tip of a sliver of land
    land = tm.geometry.Polygon([tip, tip + [0.01, 0.02], tip + [-0.01, 0.02]])
    assert _flipped_caps(tm.geometry.Rectangle((-1, -1), (3, 2)) - land, points, cells) is cells
