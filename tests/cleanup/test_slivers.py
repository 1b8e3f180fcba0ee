"""Flips toward a higher dihedral angle (``flipped_toward``), on generated and jittered tetrahedral meshes."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.cleanup.slivers import flipped_toward
from terramesh.geometry.primitives3d import Ball
from terramesh.mesh.topology import boundary_faces, cell_centroids
from terramesh.quality.tetra import min_max_dihedral, tetra_volumes


@pytest.fixture(scope="module")
def ball():
    return tm.generate_mesh(Ball((0, 0, 0), 1.0), lambda p: 0.08 + 0.1 * np.linalg.norm(p, axis=1), seed=0)


def test_flips_raise_the_smallest_angles_and_keep_the_volume_and_the_boundary(ball):
    points, cells = ball.points, ball.cells
    flipped = flipped_toward(points, cells, 30.0)
    before, after = min_max_dihedral(points, cells)[0], min_max_dihedral(points, flipped)[0]
    assert after.min() > before.min() + 5.0  # 17 -> 27 degrees
    assert np.mean(after < 30.0) < 0.5 * np.mean(before < 30.0)
    volumes = tetra_volumes(points, flipped)
    assert volumes.min() > 0 and volumes.sum() == pytest.approx(tetra_volumes(points, cells).sum(), rel=1e-12)
    np.testing.assert_array_equal(boundary_faces(flipped), boundary_faces(cells))
    assert np.array_equal(np.unique(flipped), np.arange(len(points)))
    assert tm.cleanup.mesh_problems(tm.Mesh(points, flipped)) == []


def test_flips_keep_to_the_cells_asked(ball):
    points, cells = ball.points, ball.cells

    def upper(which):
        return cell_centroids(points, which)[:, 2] > 0.2

    flipped = flipped_toward(points, cells, 30.0, near=upper)
    lower = cell_centroids(points, cells)[:, 2] < -0.1  # no flip reaches a cell this far from those asked
    kept = {tuple(sorted(cell)) for cell in flipped.tolist()}
    assert all(tuple(sorted(cell)) in kept for cell in cells[lower].tolist())
    assert len(kept) != len(cells) or kept != {tuple(sorted(cell)) for cell in cells.tolist()}


def test_a_mesh_above_the_aim_is_left_as_it_is(ball):
    flipped = flipped_toward(ball.points, ball.cells, 5.0)
    np.testing.assert_array_equal(flipped, ball.cells)
