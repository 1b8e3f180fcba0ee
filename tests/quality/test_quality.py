import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.quality import triangle_quality

equilateral = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]])


def test_reference_values():
    assert triangle_quality(equilateral, np.array([[0, 1, 2]]))[0] == pytest.approx(1.0)
    right = np.array([[0.0, 0], [1, 0], [0, 1]])
    # 4 sqrt(3) * 0.5 / (1 + 1 + 2)
    assert triangle_quality(right, np.array([[0, 1, 2]]))[0] == pytest.approx(np.sqrt(3) / 2)
    assert triangle_quality(right, np.array([[0, 2, 1]]))[0] == pytest.approx(-np.sqrt(3) / 2)
    flat = np.array([[0.0, 0], [1, 0], [2, 0]])
    assert triangle_quality(flat, np.array([[0, 1, 2]]))[0] == 0


@settings(deadline=None)  # the first example may compile a numba kernel
@given(st.floats(1e-6, 1e6), st.floats(-1e3, 1e3), st.floats(-1e3, 1e3))
def test_quality_is_invariant_to_scale_and_shift(scale, dx, dy):
    points = equilateral * scale + np.array([dx, dy])
    assert triangle_quality(points, np.array([[0, 1, 2]]))[0] == pytest.approx(1.0, rel=1e-6)


def test_geographic_quality_measures_on_the_ground():
    latitude = 60.0
    ground = equilateral * 0.01
    degrees = ground / np.array([np.cos(np.radians(latitude)), 1.0]) + np.array([10.0, latitude])
    cells = np.array([[0, 1, 2]])
    assert triangle_quality(degrees, cells)[0] < 0.8
    assert triangle_quality(degrees, cells, geographic=True)[0] == pytest.approx(1.0, abs=1e-3)


def test_summary_counts_and_statistics():
    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    mesh = tm.Mesh(points, np.array([[0, 1, 2], [0, 2, 3]]))
    result = tm.quality.summary(mesh)
    assert (result.n_vertices, result.n_cells, result.n_boundary_edges) == (4, 2, 4)
    assert result.mean == pytest.approx(np.sqrt(3) / 2)
    assert result.mean_minus_3std == pytest.approx(np.sqrt(3) / 2)
    assert result.n_below_0_5 == 0 and result.n_inverted == 0
    assert "mean 0.8660" in str(result)


def test_edge_length_ratio_against_a_number_or_a_function():
    points = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]])
    cells = np.array([[0, 1, 2]])
    by_number = tm.quality.edge_length_ratio(points, cells, 0.5)
    by_function = tm.quality.edge_length_ratio(points, cells, lambda p: 0.5 + 0.5 * p[:, 0])
    # unique edges, sorted: (0, 1) length 2, (0, 2) length 1, (1, 2) length sqrt(5)
    np.testing.assert_allclose(by_number, [4.0, 2.0, 2 * np.sqrt(5)])
    np.testing.assert_allclose(by_function, [2.0 / 1.0, 1.0 / 0.5, np.sqrt(5) / 1.0])


def test_quality_matches_the_formula_on_random_triangles():
    rng = np.random.default_rng(5)
    points = rng.random((500, 2))
    cells = rng.integers(0, 500, (2000, 3))
    a, b, c = (points[cells[:, i]] for i in range(3))
    area = 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    squares = sum(np.sum(side**2, axis=1) for side in (b - a, c - b, a - c))
    expected = np.where(squares > 0, 4 * np.sqrt(3) * area / np.where(squares > 0, squares, 1), 0.0)
    np.testing.assert_allclose(triangle_quality(points, cells), expected, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize(
    "points, cells, message",
    [
        (equilateral, [[0, 1, 10**9]], "do not exist"),  # crashed the interpreter in the numba kernel
        (equilateral, [[0, 1, 3]], "do not exist"),
        (equilateral, [[0, 1, -1]], "do not exist"),
        (equilateral, [[0.0, 1.0, 2.0]], "integer"),
        (np.vstack([equilateral, [[0.5, 0.3]]]), [[0, 1, 2, 3]], r"shape \(m, 3\)"),  # was q of the first 3 columns
        (np.column_stack([equilateral, [0.0, 0.0, 5.0]]), [[0, 1, 2]], r"shape \(n, 2\)"),  # z was dropped
        (equilateral[:, :1], [[0, 1, 2]], r"shape \(n, 2\)"),
    ],
)
@pytest.mark.parametrize("geographic", [False, True])
def test_triangle_quality_refuses_malformed_input(points, cells, message, geographic):
    with pytest.raises(tm.errors.MeshValidityError, match=message):
        triangle_quality(points, cells, geographic=geographic)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize(
    "measure",
    [
        lambda points, cells: triangle_quality(points, cells),
        lambda points, cells: triangle_quality(points, cells, geographic=True),
        lambda points, cells: tm.quality.edge_length_ratio(points, cells, 1.0),
    ],
)
def test_a_corner_that_is_nan_or_infinite_is_refused_not_scored(measure, bad):
    """A NaN corner gave quality 0, a flat cell, without a word; the summary counted it among the poor."""
    points = np.vstack([equilateral, [[2.0, 0.0]]])
    points[1, 0] = bad
    with pytest.raises(tm.errors.MeshValidityError, match=r"NaN or infinite at 1 of 4 points \(index 1 first\)"):
        measure(points, np.array([[0, 1, 2], [1, 3, 2]]))


def test_summary_of_tetrahedra_is_a_tetra_summary():
    corner = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    result = tm.quality.summary(tm.Mesh(corner, np.array([[0, 1, 2, 3]])))
    assert isinstance(result, tm.quality.TetraQualitySummary)
    doc = tm.quality.summary.__doc__
    assert "TetraQualitySummary" in doc and "tetrahedral" in doc


@pytest.mark.parametrize(
    "edge_length, message",
    [
        (0, "positive and finite"),  # gave inf and a RuntimeWarning
        (-1.0, "positive and finite"),  # gave negative ratios
        (float("nan"), "positive and finite"),
        (lambda p: np.ones(2), "2 values for 3 points"),  # a raw broadcast error
        (lambda p: np.zeros(len(p)), "zero or negative"),
        ("big", "edge_length must be"),
    ],
)
def test_edge_length_ratio_refuses_bad_sizes(edge_length, message):
    points = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]])
    with pytest.raises(tm.errors.SizingError, match=message):
        tm.quality.edge_length_ratio(points, np.array([[0, 1, 2]]), edge_length)


def test_edge_length_ratio_checks_cells_and_takes_a_size_grid():
    points = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]])
    with pytest.raises(tm.errors.MeshValidityError, match="do not exist"):
        tm.quality.edge_length_ratio(points, np.array([[0, 1, 5]]), 0.5)
    axis = np.linspace(-1, 3, 5)
    grid = tm.sizing.SizeGrid((axis, axis), np.full((5, 5), 0.5))
    np.testing.assert_allclose(tm.quality.edge_length_ratio(points, [[0, 1, 2]], grid), [4.0, 2.0, 2 * np.sqrt(5)])


def test_summary_of_a_surface_says_it_is_one():
    # the message was "points must have shape (n, 2), got (3, 3)"
    surface = tm.Mesh(np.column_stack([equilateral, [0.0, 0.0, 1.0]]), np.array([[0, 1, 2]]))
    with pytest.raises(tm.errors.MeshValidityError, match=r"triangles with 3-D points \(a surface\)"):
        tm.quality.summary(surface)
