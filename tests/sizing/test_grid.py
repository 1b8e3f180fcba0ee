import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import SizingError

x = np.linspace(-1, 3, 9)
y = np.linspace(10, 12, 5)


@settings(deadline=None)  # the first example may compile a numba kernel
@given(st.floats(-1, 3), st.floats(10, 12))
def test_bilinear_is_exact_on_bilinear_functions(px, py):
    values = 1 + 0.5 * x[:, None] + 0.25 * y[None, :] + 0.1 * np.outer(x, y)
    grid = tm.sizing.SizeGrid((x, y), values)
    assert grid([[px, py]])[0] == pytest.approx(1 + 0.5 * px + 0.25 * py + 0.1 * px * py, rel=1e-12)


def test_bilinear_at_many_points_at_once():
    """The parallel pass over 10^5 points: exact on a bilinear function, clamped outside."""
    values = 1 + 0.5 * x[:, None] + 0.25 * y[None, :] + 0.1 * np.outer(x, y)
    grid = tm.sizing.SizeGrid((x, y), values)
    points = np.random.default_rng(3).uniform([-2, 9], [4, 13], size=(100_000, 2))
    px, py = np.clip(points[:, 0], -1, 3), np.clip(points[:, 1], 10, 12)
    np.testing.assert_allclose(grid(points), 1 + 0.5 * px + 0.25 * py + 0.1 * px * py, rtol=1e-12)


@settings(deadline=None)  # the first example may compile a numba kernel
@given(st.floats(-1.5, 3.5), st.floats(9.5, 12.5), st.floats(-0.5, 1.5))
def test_trilinear_is_exact_on_trilinear_functions_and_clamps_outside(px, py, pz):
    z = np.linspace(0, 1, 4)
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")

    def f(X, Y, Z):
        return 1 + 0.5 * X + 0.25 * Y - 0.3 * Z + 0.1 * X * Y + 0.05 * Y * Z - 0.02 * X * Y * Z

    grid = tm.sizing.SizeGrid((x, y, z), f(X, Y, Z) + 5)
    cx, cy, cz = np.clip(px, -1, 3), np.clip(py, 10, 12), np.clip(pz, 0, 1)
    assert grid([[px, py, pz]])[0] == pytest.approx(f(cx, cy, cz) + 5, rel=1e-12)


def test_outside_points_take_the_nearest_edge_value():
    values = np.add.outer(x, 0 * y) + 2
    grid = tm.sizing.SizeGrid((x, y), values)
    np.testing.assert_allclose(grid([[-50, 11], [50, 11], [0, -50]]), [1, 5, 2])


@pytest.mark.parametrize(
    "axes, values, message",
    [
        ((x, y), np.full((9, 5), np.nan), "NaN"),
        ((x, y), np.zeros((9, 5)), "zero or negative"),
        ((x, y), np.ones((5, 9)), "shape"),
        ((x[::-1], y), np.ones((9, 5)), "increasing"),
        ((np.array([0, 1, 3.0]), y), np.ones((3, 5)), "evenly spaced"),
    ],
)
def test_bad_grids_raise(axes, values, message):
    with pytest.raises(SizingError, match=message):
        tm.sizing.SizeGrid(axes, values)


def test_float32_axes_are_evenly_spaced_to_their_precision():
    # a float32 longitude axis of 2401 nodes (NetCDF) was refused as not evenly spaced
    lon, lat = np.linspace(-100, -40, 2401).astype(np.float32), np.linspace(10, 60, 201).astype(np.float32)
    grid = tm.sizing.SizeGrid((lon, lat), np.add.outer(np.arange(2401.0), np.zeros(201)) + 1)
    np.testing.assert_allclose(grid([[-100.0, 30.0], [-40.0, 30.0]]), [1.0, 2401.0], rtol=1e-5)
    with pytest.raises(SizingError, match="evenly spaced"):
        tm.sizing.SizeGrid((np.array([0, 1, 2.5, 3], dtype=np.float32), lat), np.ones((4, 201)))


@pytest.mark.parametrize(
    "value, message", [(0, "positive"), (-1, "positive"), (float("nan"), "positive"), ("a", "number")]
)
def test_bad_edge_length_raises(value, message):
    with pytest.raises(SizingError, match=message):
        tm.sizing.as_size_function(value)


def test_callable_sizes_are_checked():
    size = tm.sizing.as_size_function(lambda p: np.where(p[:, 0] > 0, np.nan, 1.0))
    with pytest.raises(SizingError, match="NaN"):
        size(np.array([[1.0, 0.0], [-1.0, 0.0]]))
    with pytest.raises(SizingError, match="2 values for 3 points"):
        tm.sizing.as_size_function(lambda p: np.ones(2))(np.zeros((3, 2)))


@pytest.mark.parametrize(
    "axes, values, message",
    [
        ((np.linspace(0, 1, 4),), np.ones(4), "2 or 3 coordinate arrays"),  # a 1-D grid failed in numba when called
        ((np.linspace(0, 1, 2),) * 4, np.ones((2,) * 4), "2 or 3 coordinate arrays"),
        (None, np.ones((2, 2)), "sequence of 2 or 3"),
        ((["a", "b"], [0.0, 1.0]), np.ones((2, 2)), "axis x must be a 1-D array of numbers"),
        (([0.0, 1.0], [0.0, 1.0]), [["a", "b"], ["c", "d"]], "values must be an array of numbers"),
    ],
)
def test_grids_of_other_dimensions_or_not_numbers_raise(axes, values, message):
    with pytest.raises(SizingError, match=message):
        tm.sizing.SizeGrid(axes, values)


@pytest.mark.parametrize("shape", [(4, 3), (3, 3), (2, 1), (6,), (2, 2, 2)])
def test_points_of_the_wrong_shape_raise(shape):
    # (4, 3) gave 6 values from a silent reshape, (3, 3) NumPy's reshape error
    axis = np.linspace(0, 1, 3)
    size = tm.sizing.SizeGrid((axis, axis), np.ones((3, 3)))
    with pytest.raises(SizingError, match=r"shape \(n, 2\)"):
        size(np.zeros(shape))
    with pytest.raises(SizingError, match="array of numbers"):
        size([["a", "b"]])


def test_points_of_the_grid_dimension_still_work():
    axis = np.linspace(0, 1, 3)
    size = tm.sizing.SizeGrid((axis, axis), 1.0 + np.add.outer(axis, 0 * axis))
    assert size([0.5, 0.0]).tolist() == [1.5]  # one point as (x, y)
    assert size(np.zeros((0, 2))).shape == (0,) and size([]).shape == (0,)
    cube = tm.sizing.SizeGrid((axis, axis, axis), np.ones((3, 3, 3)))
    assert cube(np.zeros((5, 3))).tolist() == [1.0] * 5
    with pytest.raises(SizingError, match=r"shape \(n, 3\)"):
        cube(np.zeros((3, 2)))


def test_nan_points_are_refused_and_infinite_ones_clamped():
    # NaN points came back as NaN sizes (a MetricGrid and every distance refuse them)
    axis = np.linspace(0, 1, 3)
    size = tm.sizing.SizeGrid((axis, axis), np.ones((3, 3)))
    with pytest.raises(SizingError, match=r"1 of 2 points have NaN coordinates \(the first, index 1\)"):
        size([(0.5, 0.5), (np.nan, 0.5)])
    assert size([(np.inf, 0.5)]).tolist() == [1.0]
    with pytest.raises(SizingError, match="NaN coordinates"):
        tm.sizing.SizeGrid((axis, axis, axis), np.ones((3, 3, 3)))([(0.5, np.nan, 0.5)])
