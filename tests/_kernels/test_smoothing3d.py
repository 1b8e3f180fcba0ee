"""Quality-safe smoothing of tetrahedra: no worse worst cell, no smaller smallest angle, fixed vertices stay."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from terramesh._kernels.smoothing import move_where_better, raise_worst
from terramesh._kernels.smoothing3d import smooth_interior_3d
from terramesh.generation.triangulate import delaunay_3d
from terramesh.quality.tetra import min_max_dihedral, radius_ratio


def jittered_block(seed, amplitude):
    """The Delaunay cells of a 6 x 6 x 6 body-centred cubic block, its inner points jittered; outer ones fixed."""
    grid = np.stack(np.meshgrid(*[np.arange(6.0)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    centres = grid[np.all(grid < 5, axis=1)] + 0.5
    points = np.vstack([grid, centres])
    rng = np.random.default_rng(seed)
    points += 1e-3 * rng.uniform(-1, 1, points.shape)  # no five cospherical: one Delaunay choice
    movable = np.all((points > 0.5) & (points < 4.5), axis=1)
    points[movable] += amplitude * rng.uniform(-1, 1, (movable.sum(), 3))
    cells, _ = delaunay_3d(points)
    return points, cells, movable


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.05, 0.25))
def test_smoothing_never_lowers_the_worst_cell_nor_the_smallest_angle(seed, amplitude):
    points, cells, movable = jittered_block(seed, amplitude)
    smoothed = points.copy()
    moves = smooth_interior_3d(smoothed, cells, movable, 2)
    np.testing.assert_array_equal(smoothed[~movable], points[~movable])
    assert moves >= np.sum(np.any(smoothed != points, axis=1))  # a vertex may move in both passes
    assert radius_ratio(smoothed, cells).min() > 0  # nothing inverted
    # the fixed hull has flat cells of its own: the angles that can change are those of the inner cells
    inner = cells[movable[cells].any(axis=1)]
    smallest_before = min_max_dihedral(points, inner)[0].min()
    assert min_max_dihedral(smoothed, inner)[0].min() >= smallest_before - 1e-9


def test_smoothing_raises_the_quality_of_a_disordered_block():
    points, cells, movable = jittered_block(3, 0.2)
    smoothed = points.copy()
    moves = smooth_interior_3d(smoothed, cells, movable, 2)
    assert moves > 0.5 * movable.sum()
    before, after = radius_ratio(points, cells), radius_ratio(smoothed, cells)
    assert after.mean() > before.mean() + 0.02  # (the hull's flat cells, fixed, stay as they are)
    assert np.median(after) > np.median(before)
    again = points.copy()
    smooth_interior_3d(again, cells, movable, 2)
    np.testing.assert_array_equal(again, smoothed)  # deterministic


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.05, 0.3))
def test_raising_the_worst_cells_never_lowers_the_worst_cell_nor_the_smallest_angle(seed, amplitude):
    points, cells, movable = jittered_block(seed, amplitude)
    raised = points.copy()
    moves = raise_worst(raised, cells, movable, 0.3, 3)
    np.testing.assert_array_equal(raised[~movable], points[~movable])
    assert moves >= np.sum(np.any(raised != points, axis=1))
    inner = cells[movable[cells].any(axis=1)]  # (the fixed hull's flat cells stay as they are)
    assert radius_ratio(raised, inner).min() >= radius_ratio(points, inner).min() > 0
    assert min_max_dihedral(raised, inner)[0].min() >= min_max_dihedral(points, inner)[0].min() - 1e-9
    if radius_ratio(points, inner).min() >= 0.3:  # nothing poor, nothing moves
        np.testing.assert_array_equal(raised, points)


def test_raising_the_worst_cells_lifts_caps_and_needles_the_mean_leaves():
    points, cells, movable = jittered_block(3, 0.2)
    inner = cells[movable[cells].all(axis=1)]
    smoothed = points.copy()
    smooth_interior_3d(smoothed, cells, movable, 2)
    assert radius_ratio(smoothed, inner).min() < 0.15  # the neighbours' mean leaves a poor cell here (0.109)
    raised = smoothed.copy()
    assert raise_worst(raised, cells, movable, 0.3, 3) > 0
    assert radius_ratio(raised, inner).min() >= 0.3
    again = smoothed.copy()
    raise_worst(again, cells, movable, 0.3, 3)
    np.testing.assert_array_equal(again, raised)  # deterministic


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000))
def test_the_best_candidate_raises_the_worst_cell_and_keeps_the_smallest_angle(seed):
    points, cells, movable = jittered_block(seed, 0.2)
    vertices = np.flatnonzero(movable)[:12]
    rng = np.random.default_rng(seed)
    candidates = points[vertices, None, :] + 0.15 * rng.uniform(-1, 1, (len(vertices), 20, 3))
    moved = points.copy()
    moves = move_where_better(moved, cells, vertices, candidates)
    changed = np.flatnonzero(np.any(moved != points, axis=1))
    assert moves == len(changed) and np.isin(changed, vertices).all()
    for v in changed:  # at one of its candidates, its cells' worst better and no angle below their smallest
        assert (moved[v] == candidates[vertices == v][0]).all(axis=1).any()
    star = cells[np.isin(cells, vertices).any(axis=1)]
    assert radius_ratio(moved, star).min() >= radius_ratio(points, star).min()
    assert min_max_dihedral(moved, star)[0].min() >= min_max_dihedral(points, star)[0].min() - 1e-9
