"""Quality-safe smoothing of tetrahedra: no worse worst cell, no smaller smallest angle, fixed vertices stay."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from terramesh._kernels.smoothing import move_where_better, raise_worst
from terramesh._kernels.smoothing3d import lengthen_short_edges, short_edge_vertices, smooth_interior_3d
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


def edge_ratios(points, cells, sizes):
    """Unique edges (e, 2) and their length over the mean of their ends' sizes."""
    edges = np.unique(
        np.sort(cells[:, [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]].reshape(-1, 2), axis=1), axis=0
    )
    lengths = np.linalg.norm(points[edges[:, 1]] - points[edges[:, 0]], axis=1)
    return edges, 2 * lengths / (sizes[edges[:, 0]] + sizes[edges[:, 1]])


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.5, 2.0))
def test_short_edge_vertices_are_the_ends_of_edges_below_the_floor(seed, scale):
    points, cells, _ = jittered_block(seed, 0.25)
    sizes = scale * np.random.default_rng(seed).uniform(0.8, 1.2, len(points))
    edges, ratios = edge_ratios(points, cells, sizes)
    expected = np.zeros(len(points), dtype=bool)
    expected[edges[ratios < 0.6].ravel()] = True
    np.testing.assert_array_equal(short_edge_vertices(points, cells, sizes, 0.6), expected)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000))
def test_lengthening_raises_the_shortest_edge_and_keeps_the_cells(seed):
    points, cells, movable = jittered_block(seed, 0.25)
    sizes = np.ones(len(points))
    floor, keep = 0.7, 0.3
    vertices = np.flatnonzero(short_edge_vertices(points, cells, sizes, floor) & movable)
    rng = np.random.default_rng(seed)
    candidates = points[vertices, None, :] + 0.2 * rng.uniform(-1, 1, (len(vertices), 30, 3))
    moved = points.copy()
    moves = lengthen_short_edges(moved, cells, sizes, vertices, candidates, floor, keep)
    changed = np.flatnonzero(np.any(moved != points, axis=1))
    assert moves == len(changed) > 0 and np.isin(changed, vertices).all()
    for v in changed:  # at one of its candidates; its shortest edge longer, its cells no worse than allowed
        assert (moved[v] == candidates[vertices == v][0]).all(axis=1).any()
    star = cells[np.isin(cells, vertices).any(axis=1)]
    before, after = radius_ratio(points, star), radius_ratio(moved, star)
    assert after.min() >= min(before.min(), keep) > 0
    assert min_max_dihedral(moved, star)[0].min() >= min_max_dihedral(points, star)[0].min() - 1e-9
    _, ratio_before = edge_ratios(points, cells, sizes)
    _, ratio_after = edge_ratios(moved, cells, sizes)
    assert np.sum(ratio_after < floor) < np.sum(ratio_before < floor)
    again = points.copy()
    lengthen_short_edges(again, cells, sizes, vertices, candidates, floor, keep)
    np.testing.assert_array_equal(again, moved)  # deterministic


def test_a_vertex_pushed_next_to_its_neighbour_moves_away():
    points, cells, movable = jittered_block(0, 0.0)
    centre = np.flatnonzero(np.all(np.abs(points - 2.5) < 0.01, axis=1))[0]  # a body centre, 8 corners at 0.87
    corner = np.flatnonzero(np.all(np.abs(points - 2.0) < 0.01, axis=1))[0]
    points[centre] += 0.6 * (points[corner] - points[centre])  # 0.35 from that corner
    cells, _ = delaunay_3d(points)
    sizes = np.ones(len(points))
    _, ratios = edge_ratios(points, cells, sizes)
    assert ratios.min() < 0.4
    directions = np.array(
        [[i, j, k] for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1) if (i, j, k) != (0, 0, 0)]
    )
    directions = directions / np.linalg.norm(directions, axis=1)[:, None]
    steps = np.array([0.3, 0.15, 0.08, 0.04, 0.02])
    vertices = np.array([centre])
    candidates = points[centre] + (steps[:, None, None] * directions[None]).reshape(1, -1, 3)
    assert lengthen_short_edges(points, cells, sizes, vertices, candidates, 0.7, 0.3) == 1
    _, ratios = edge_ratios(points, cells, sizes)
    assert ratios.min() >= 0.6
