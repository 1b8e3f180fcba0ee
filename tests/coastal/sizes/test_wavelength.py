"""Wavelength size function, guide eq. 5-6."""

import numpy as np
import pytest

from terramesh.coastal.sizes import GRAVITY, M2_PERIOD, m2_wavelength, wavelength_size
from terramesh.errors import SizingError


def test_m2_period_is_12_42_hours():
    assert M2_PERIOD == 44712.0
    assert GRAVITY == 9.81


def test_wavelength_size_by_hand():
    # eq. 6: T_M2 sqrt(g H) / alpha_wl with T = 12.42 h = 44712 s, H = 100 m, alpha = 60
    by_hand = 44712.0 * np.sqrt(9.81 * 100.0) / 60.0
    assert by_hand == pytest.approx(23340.35, abs=0.01)
    sizes = wavelength_size(np.array([[100.0, 4000.0]]), elements_per_wavelength=60)
    assert sizes[0, 0] == pytest.approx(by_hand, rel=1e-12)
    assert sizes[0, 1] == pytest.approx(44712.0 * np.sqrt(9.81 * 4000.0) / 60.0, rel=1e-12)


def test_eq5_equals_eq6():
    depth = np.array([1.0, 10.0, 250.0, 5000.0])
    assert wavelength_size(depth, elements_per_wavelength=25) == pytest.approx(m2_wavelength(depth) / 25, rel=1e-14)


def test_period_and_gravity_are_used():
    sizes = wavelength_size([16.0], elements_per_wavelength=2, period=10.0, gravity=4.0)
    assert sizes.tolist() == [10.0 * 8.0 / 2]


def test_land_and_dry_nodes_do_not_constrain():
    sizes = wavelength_size([[-20.0, 0.0, 1e-6]], elements_per_wavelength=60)
    assert np.isinf(sizes[0, :2]).all()
    assert np.isfinite(sizes[0, 2])


def test_input_is_not_modified_and_shape_kept():
    depth = np.linspace(-10, 100, 12).reshape(3, 4)
    before = depth.copy()
    sizes = wavelength_size(depth, elements_per_wavelength=30)
    assert sizes.shape == (3, 4) and sizes.dtype == np.float64
    assert np.array_equal(depth, before)


@pytest.mark.parametrize("alpha", [0, -1, np.nan, np.inf, True, "60"])
def test_bad_elements_per_wavelength(alpha):
    with pytest.raises(SizingError, match="elements_per_wavelength"):
        wavelength_size([100.0], elements_per_wavelength=alpha)


def test_nan_depth_is_refused():
    with pytest.raises(SizingError, match="NaN"):
        wavelength_size([100.0, np.nan], elements_per_wavelength=60)


def test_m2_wavelength_refuses_negative_depth():
    with pytest.raises(SizingError):
        m2_wavelength(-1.0)
