"""Metric tensors: built from sizes and a direction, read back, and refused when they are not metrics."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from terramesh.errors import SizingError
from terramesh.sizing import as_metric_function, metric_sizes, metric_tensor
from terramesh.sizing.metric import mean_size


@settings(max_examples=200, deadline=None)
@given(st.floats(1e-3, 1e3), st.floats(1e-3, 1e3), st.floats(-np.pi / 2, np.pi / 2, exclude_min=True))
def test_the_sizes_and_direction_read_back(major, ratio, angle):
    minor = major * ratio  # anisotropy up to 1000: beyond, the matrices' rounding shows in the sixth digit
    metric = metric_tensor(major, minor, angle)
    direction = np.array([np.cos(angle), np.sin(angle)])
    across = np.array([-direction[1], direction[0]])
    # an edge of length `major` along the direction (and `minor` across) measures 1
    assert np.sqrt(major * direction @ metric @ direction * major) == pytest.approx(1.0, rel=1e-6)
    assert np.sqrt(minor * across @ metric @ across * minor) == pytest.approx(1.0, rel=1e-6)
    long, short, turned = metric_sizes(metric)
    assert (long, short) == pytest.approx((max(major, minor), min(major, minor)), rel=1e-6)
    assert mean_size(metric) == pytest.approx(np.sqrt(major * minor), rel=1e-6)
    if long > 1.001 * short:  # the direction of the longer size, modulo a half turn
        longer = angle if major >= minor else angle + np.pi / 2
        assert np.sin(turned - longer) == pytest.approx(0.0, abs=1e-4)


def test_arrays_broadcast_to_one_matrix_a_point():
    metric = metric_tensor(np.array([1.0, 2.0, 3.0]), 0.5, 0.0)
    assert metric.shape == (3, 2, 2)
    assert metric[:, 0, 0].tolist() == [1.0, 0.25, 1 / 9]


@pytest.mark.parametrize(
    "major, minor, angle, words",
    [
        (0.0, 1.0, 0.0, "major must be positive"),
        (1.0, -2.0, 0.0, "minor must be positive"),
        (1.0, np.nan, 0.0, "minor must be positive"),
        (1.0, 1.0, np.inf, "angle must be finite"),
        ([1.0, 2.0], [1.0, 2.0, 3.0], 0.0, "one shape"),
    ],
)
def test_bad_sizes_are_refused_by_name(major, minor, angle, words):
    with pytest.raises(SizingError, match=words):
        metric_tensor(major, minor, angle)


def test_a_function_of_points_is_checked_at_every_call():
    field = as_metric_function(lambda p: metric_tensor(0.1 + p[:, 0], 0.05, 0.0))
    assert field(np.array([[0.0, 0.0], [1.0, 0.0]])).shape == (2, 2, 2)
    with pytest.raises(SizingError, match=r"1 matrices that are not positive definite.*at \(-0\.2, 0\)"):
        as_metric_function(lambda p: np.stack([np.diag([x, 1.0]) for x in p[:, 0]]))(np.array([[1.0, 0], [-0.2, 0]]))
    with pytest.raises(SizingError, match="NaN"):
        as_metric_function(lambda p: np.full((len(p), 2, 2), np.nan))(np.zeros((3, 2)))
    with pytest.raises(SizingError, match="not symmetric"):
        as_metric_function(lambda p: np.tile([[1.0, 0.5], [0.0, 1.0]], (len(p), 1, 1)))(np.zeros((3, 2)))
    with pytest.raises(SizingError, match=r"shape \(n, 2, 2\).*got \(3,\) for 3 points"):
        as_metric_function(lambda p: np.ones(len(p)))(np.zeros((3, 2)))


def test_one_matrix_serves_the_whole_domain_and_a_bad_one_is_refused_at_once():
    field = as_metric_function(metric_tensor(0.2, 0.1, 0.3))
    assert np.allclose(field(np.zeros((4, 2))), metric_tensor(0.2, 0.1, 0.3))
    with pytest.raises(SizingError, match="not positive definite"):
        as_metric_function([[1.0, 2.0], [2.0, 1.0]])
    with pytest.raises(SizingError, match=r"one 2 x 2 matrix of real numbers, got float of shape \(\)"):
        as_metric_function(0.1)
    # a complex matrix of the right shape was blamed on its shape
    with pytest.raises(SizingError, match=r"got ndarray of complex128 values"):
        as_metric_function(np.array([[1.0, 0.0], [0.0, 1j]]))


def test_a_metric_grid_of_nan_is_named_as_such():
    from terramesh.sizing import MetricGrid

    axes = (np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    with pytest.raises(SizingError, match=r"^MetricGrid's values have 9 NaN or infinite entries"):  # not "returned"
        MetricGrid(axes, np.full((3, 3, 2, 2), np.nan))


@pytest.mark.parametrize("entry", [(0, 0), (0, 1), (1, 0), (1, 1)])
def test_an_infinite_entry_is_named_without_a_numpy_warning(entry):
    from terramesh.sizing.metric import checked_metric

    metric = np.tile(np.eye(2), (4, 1, 1))
    metric[(2, *entry)] = np.inf
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an inf off the diagonal made NumPy warn before the error
        with pytest.raises(SizingError, match=r"1 NaN or infinite entries"):
            checked_metric(metric)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 9), st.integers(2, 9))
def test_a_metric_grid_is_the_bilinear_interpolation_of_each_entry(seed, nx, ny):
    from scipy.interpolate import RegularGridInterpolator

    from terramesh.sizing import MetricGrid

    rng = np.random.default_rng(seed)
    x, y = np.linspace(-1.0, 2.0, nx), np.linspace(10.0, 10.5, ny)
    values = metric_tensor(
        rng.uniform(0.1, 1.0, (nx, ny)), rng.uniform(0.01, 0.1, (nx, ny)), rng.uniform(-2, 2, (nx, ny))
    )
    points = rng.uniform((-2.0, 9.5), (3.0, 11.0), (200, 2))  # a third or so outside: the nearest edge's value
    metric = MetricGrid((x, y), values)(points)
    clamped = np.clip(points, (x[0], y[0]), (x[-1], y[-1]))
    for row, column in ((0, 0), (0, 1), (1, 0), (1, 1)):
        expected = RegularGridInterpolator((x, y), values[:, :, row, column])(clamped)
        assert np.allclose(metric[:, row, column], expected, rtol=0.0, atol=1e-12 * np.abs(values).max())
    assert as_metric_function(MetricGrid((x, y), values))(points).shape == (200, 2, 2)
    with pytest.raises(SizingError, match="points must be finite"):
        MetricGrid((x, y), values)(np.array([[np.nan, 10.2]]))
    # 3D points were taken as half again as many 2D ones, silently (one of them: NumPy's reshape error)
    for wrong in (np.zeros((2, 3)), np.zeros((1, 3))):
        with pytest.raises(SizingError, match=rf"must have shape \(n, 2\), not \({wrong.shape[0]}, 3\)"):
            MetricGrid((x, y), values)(wrong)
    assert MetricGrid((x, y), values)(np.array([0.0, 10.2])).shape == (1, 2, 2)


def test_a_metric_grid_of_axes_that_are_not_a_sequence_is_refused_by_name():
    from terramesh.sizing import MetricGrid

    with pytest.raises(SizingError, match="axes must be a sequence of 2 coordinate arrays"):  # a bare TypeError
        MetricGrid(5, np.ones((2, 2, 2, 2)))
