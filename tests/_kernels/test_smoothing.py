"""Quality-safe smoothing kernels: no cell gets worse than the worst before, fixed vertices stay."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from terramesh._kernels.smoothing import move_where_better, raise_worst, smooth_interior
from terramesh.generation.triangulate import delaunay
from terramesh.mesh.topology import boundary_edges
from terramesh.quality import triangle_quality


def perturbed_lattice(seed, amplitude):
    """A hexagonal patch (8 x 8) with its interior vertices jittered; boundary vertices marked fixed."""
    rows, columns = np.meshgrid(np.arange(8), np.arange(8), indexing="ij")
    points = np.column_stack([columns.ravel() + 0.5 * (rows.ravel() % 2), np.sqrt(3) / 2 * rows.ravel()])
    cells = delaunay(points)
    movable = np.ones(len(points), dtype=bool)
    movable[boundary_edges(cells).ravel()] = False
    rng = np.random.default_rng(seed)
    points[movable] += amplitude * rng.uniform(-1, 1, (movable.sum(), 2))
    return points, cells, movable


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.05, 0.3))
def test_smoothing_never_lowers_the_worst_cell_nor_moves_fixed_vertices(seed, amplitude):
    points, cells, movable = perturbed_lattice(seed, amplitude)
    before = triangle_quality(points, cells)
    for smooth in (
        lambda p: smooth_interior(p, cells, movable, 3),
        lambda p: raise_worst(p, cells, movable, 0.95, 3),
    ):
        moved = points.copy()
        smooth(moved)
        after = triangle_quality(moved, cells)
        assert after.min() >= before.min() - 1e-12 and after.min() > 0
        np.testing.assert_array_equal(moved[~movable], points[~movable])


def smooth_reference(points, cells, movable, passes):
    """Laplacian smoothing that keeps each star's worst cell, every quality computed afresh (the rule, plainly)."""

    def worst(star):
        return triangle_quality(points, cells[star]).min()

    stars = [np.flatnonzero((cells == v).any(axis=1)) for v in range(len(points))]
    for _ in range(passes):
        for v in np.flatnonzero(movable):
            star = stars[v]
            if len(star) == 0:
                continue
            corners = cells[star].ravel()
            target = points[corners[corners != v]].mean(axis=0)
            before, old = worst(star), points[v].copy()
            points[v] = target
            if worst(star) < before:
                points[v] = old


@pytest.mark.parametrize("seed", [0, 1])
def test_smooth_interior_keeps_each_cells_quality_in_step_with_its_vertices(seed):
    # it reads a vertex's present worst from kept qualities: they must follow every move
    points, cells, movable = perturbed_lattice(seed, 0.3)
    expected = points.copy()
    smooth_reference(expected, cells, movable, 3)
    got = points.copy()
    smooth_interior(got, cells, movable, 3)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
    assert not np.array_equal(got, points)


def test_raise_worst_lifts_the_one_poor_cell():
    points, cells, movable = perturbed_lattice(0, 0.0)
    centre = np.argmin(np.linalg.norm(points - points.mean(axis=0), axis=1))
    points[centre] += [0.42, 0.1]  # towards a neighbour: one squeezed cell
    before = triangle_quality(points, cells).min()
    moves = raise_worst(points, cells, movable, 0.9, 3)
    after = triangle_quality(points, cells).min()
    assert before < 0.65 and after > 0.85 and moves >= 1  # a local search: 0.60 -> 0.89 here


def test_move_where_better_takes_only_improving_candidates():
    points, cells, movable = perturbed_lattice(0, 0.0)
    centre = np.argmin(np.linalg.norm(points - points.mean(axis=0), axis=1))
    home = points[centre].copy()
    points[centre] += [0.3, 0.0]
    candidates = np.array([[[home[0] + 0.6, home[1]], home]])  # worse, then the lattice site
    assert move_where_better(points, cells, np.array([centre]), candidates) == 1
    np.testing.assert_array_equal(points[centre], home)
    assert move_where_better(points, cells, np.array([centre]), candidates) == 0  # nothing better than home


def test_a_cell_with_its_vertex_twice_moves_both_corners():
    # the star's corners are read once; a cell (4, 4, 2) must still count 2 alone in the mean and move
    # both of its corners at 4 with it (so it stays flat, quality 0), as the corner-by-corner reading did
    from terramesh._kernels.cleanup import smooth_vertices

    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [0.8, 0.7]])
    cells = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [4, 4, 2]])
    movable = np.array([False, False, False, False, True])
    moved = points.copy()
    smooth_interior(moved, cells, movable, 1)
    assert np.array_equal(moved[4], [0.5, 0.5])  # (2 * (0 + 1 + 1 + 0) + 1) / 10 and likewise; worst 0 either way
    moved = points.copy()
    smooth_vertices(moved, cells, movable, 1, False)
    assert np.array_equal(moved, points)  # its flat cell keeps quality 0, not above: no move
