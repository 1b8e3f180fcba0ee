"""Slope size function and its band-pass filter, guide eq. 7-8."""

import numpy as np
import pytest

from terramesh._kernels.raster import box_pass_axis0, box_pass_axis1
from terramesh.coastal import GeoGrid
from terramesh.coastal.projection import EARTH_RADIUS
from terramesh.coastal.sizes import auto_filter_length, filter_bathymetry, gaussian_lowpass, slope_size
from terramesh.coastal.sizes.slope import box_passes
from terramesh.errors import GeometryError, SizingError, TerrameshWarning


def test_automatic_filter_length_is_46_7_km_for_alpha_30():
    # eq. 8: lambda_M2(h = 100 m) / alpha_slp = 12.42 h * sqrt(9.81 * 100) / 30
    by_hand = 12.42 * 3600 * np.sqrt(9.81 * 100.0) / 30
    assert by_hand / 1e3 == pytest.approx(46.7, abs=0.05)
    assert auto_filter_length(30) == pytest.approx(by_hand, rel=1e-14)
    assert auto_filter_length(20) == pytest.approx(1.5 * by_hand, rel=1e-14)


# ---------------------------------------------------------------- the filter


def _extended_box(radius, weight):
    return np.r_[weight, np.ones(2 * radius + 1), weight] / (2 * radius + 1 + 2 * weight)


@pytest.mark.parametrize("sigma", [0.3, 1.0, 2.7, 9.4])
def test_box_passes_have_the_gaussian_variance(sigma):
    radius, weight = box_passes(np.array([sigma]))
    kernel = np.array([1.0])
    for _ in range(4):
        kernel = np.convolve(kernel, _extended_box(int(radius[0]), float(weight[0])))
    offsets = np.arange(kernel.size) - kernel.size // 2
    assert kernel.sum() == pytest.approx(1.0)
    assert (kernel * offsets**2).sum() == pytest.approx(sigma**2, rel=1e-12)
    assert 0.0 <= weight[0] < 1.0


def test_box_pass_kernels_match_numpy_convolution():
    rng = np.random.default_rng(3)
    values = rng.normal(size=(40, 30))
    radius = rng.integers(0, 4, size=30)
    weight = rng.random(30)
    start = 5
    along_x = np.empty_like(values)
    box_pass_axis0(values, along_x, radius, weight, start)
    along_y = np.empty_like(values)
    box_pass_axis1(values, along_y, radius, weight, start)
    for iy in range(30):
        kernel = _extended_box(radius[iy], weight[iy])
        full = np.convolve(values[:, iy], kernel, mode="same")
        assert np.allclose(along_x[start:-start, iy], full[start:-start], rtol=0, atol=1e-12)
    for ix in range(40):
        for j in range(start, 30 - start):
            kernel = _extended_box(radius[j], weight[j])
            r = radius[j] + 1
            assert along_y[ix, j] == pytest.approx(values[ix, j - r : j + r + 1] @ kernel, abs=1e-12)


def test_filter_leaves_a_plane_unchanged_borders_included():
    grid = GeoGrid((0, 1, 40, 40.8), 2e3)
    ix, iy = np.meshgrid(np.arange(grid.shape[0]), np.arange(grid.shape[1]), indexing="ij")
    plane = 3.0 * ix - 2.0 * iy + 7.0
    for length in (5e3, 40e3, 500e3):  # the last one is wider than the grid
        assert np.allclose(gaussian_lowpass(grid, plane, length), plane, rtol=0, atol=1e-9)


@pytest.mark.parametrize(("ratio", "low", "high"), [(0.25, 0.0, 1e-3), (1.0, 0.58, 0.64), (4.0, 0.95, 1.0)])
def test_filter_response(ratio, low, high):
    """A Gaussian with sigma = L / (2 pi): wavelength L keeps exp(-1/2) = 0.61, L / 4 vanishes, 4 L passes."""
    grid = GeoGrid((0, 3, 0, 0.3), 500.0)
    length = 40e3
    east = grid.ground_step[0] * np.arange(grid.shape[0])
    wave = np.sin(2 * np.pi * east / (ratio * length))
    filtered = gaussian_lowpass(grid, np.broadcast_to(wave[:, None], grid.shape), length)
    middle = slice(grid.shape[0] // 4, 3 * grid.shape[0] // 4)
    amplitude = np.abs(filtered[middle, grid.shape[1] // 2]).max()
    assert low <= amplitude <= high
    assert np.exp(-0.5 / ratio**2) == pytest.approx(amplitude, abs=0.03)


def test_filter_is_in_ground_metres_at_every_latitude():
    """The same ground wave is damped the same at 0 and 60 degrees, although its Mercator length doubles."""
    amplitudes = []
    for lat0 in (0.0, 60.0):
        grid = GeoGrid((0, 1.5, lat0, lat0 + 0.1), 500.0)
        east = grid.ground_step[None, :] * np.arange(grid.shape[0])[:, None]
        filtered = gaussian_lowpass(grid, np.sin(2 * np.pi * east / 30e3), 30e3)
        middle = slice(grid.shape[0] // 4, 3 * grid.shape[0] // 4)
        amplitudes.append(np.abs(filtered[middle, grid.shape[1] // 2]).max())
    assert amplitudes[0] == pytest.approx(amplitudes[1], abs=0.01)


def test_band_pass_low_pass_and_high_pass():
    grid = GeoGrid((0, 3, 0, 0.3), 500.0)
    east = grid.ground_step[0] * np.arange(grid.shape[0])
    short = np.sin(2 * np.pi * east / 5e3)
    middle_wave = np.sin(2 * np.pi * east / 60e3)
    depth = np.broadcast_to((1000.0 + 50 * short + 50 * middle_wave)[:, None], grid.shape)
    centre = (slice(grid.shape[0] // 4, 3 * grid.shape[0] // 4), grid.shape[1] // 2)
    low = filter_bathymetry(grid, depth, (20e3, 0.0))
    assert np.abs(low[centre] - (1000.0 + 50 * middle_wave[centre[0]] * np.exp(-0.5 * (20 / 60) ** 2))).max() < 0.5
    band = filter_bathymetry(grid, depth, (20e3, 300e3))  # the mean and the 5 km waves go, the 60 km wave stays
    assert np.abs(band[centre]).max() < 55 and np.abs(band[centre].mean()) < 5
    assert np.array_equal(filter_bathymetry(grid, depth, (0.0, 0.0)), depth)
    assert np.allclose(filter_bathymetry(grid, depth, [(0.0, 0.0), (0.0, 0.0)]), 2 * depth)
    with pytest.warns(TerrameshWarning, match="high-pass"):
        high = filter_bathymetry(grid, depth, (0.0, 20e3))
    assert np.abs(high[centre].mean()) < 2  # the mean is gone


def test_a_filter_shorter_than_the_grid_step_warns():
    grid = GeoGrid((0, 1, 0, 1), 500.0)
    depth = np.random.default_rng(0).uniform(10, 100, grid.shape)
    # 46.7 typed for 46.7 km: a Gaussian of sigma 7 m on a 500 m grid leaves the depths nearly as they were
    with pytest.warns(TerrameshWarning, match=r"\[46.7\] m are no longer than twice the grid's step \(500 m\)"):
        same = filter_bathymetry(grid, depth, (46.7, 0.0))
    assert np.allclose(same, depth, rtol=1e-2)  # 0.34 % at most, where 500 m changes them by up to 38 %


@pytest.mark.parametrize("lengths", [(1.0,), (1.0, 2.0, 3.0), [(-1.0, 0.0)], [(np.nan, 0.0)], []])
def test_bad_filter_lengths(lengths):
    grid = GeoGrid((0, 1, 0, 1), 20e3)
    with pytest.raises(SizingError, match="filter"):
        filter_bathymetry(grid, np.zeros(grid.shape), lengths)


# ---------------------------------------------------------------- eq. 7


def _shelf(grid, slope=0.01, top=-20.0):
    north = EARTH_RADIUS * np.radians(grid.lat)
    return np.broadcast_to(top + slope * (north - north[0]), grid.shape).copy()


def test_slope_size_on_a_linear_shelf_by_hand():
    # depth rises 0.01 m per ground metre northwards, from 20 m above sea level to ~1,100 m
    grid = GeoGrid((0, 0.5, 0, 1.0), 2e3)
    depth = _shelf(grid)
    sizes = slope_size(grid, depth, elements_per_slope=30)
    deep = depth >= 100
    # eq. 7: (2 pi / alpha) h / |grad h*|, |grad h*| = 0.01; the filter keeps planes in the grid's (Mercator)
    # indices, and the shelf is a plane in ground northing, so the filtered slope is 0.01 to 1e-5
    assert sizes[deep] == pytest.approx(2 * np.pi / 30 * depth[deep] / 0.01, rel=1e-4)
    node = np.argmin(np.abs(depth[0] - 500.0))
    assert sizes[0, node] == pytest.approx(2 * np.pi / 30 * depth[0, node] / 0.01, rel=1e-4)
    assert 2 * np.pi / 30 * 500.0 / 0.01 == pytest.approx(10471.98, abs=0.01)
    # switched off (inf) shallower than 100 m and on land
    assert np.isinf(sizes[~deep]).all() and (~deep).any()


def test_slope_cutoff_depth_is_adjustable():
    grid = GeoGrid((0, 0.5, 0, 1.0), 2e3)
    depth = _shelf(grid)
    sizes = slope_size(grid, depth, elements_per_slope=20, min_depth=0.0, filter_lengths=(0.0, 0.0))
    wet = depth > 0
    assert sizes[wet] == pytest.approx(2 * np.pi / 20 * depth[wet] / 0.01, rel=1e-9)  # unfiltered: exact
    assert np.isinf(sizes[~wet]).all()


def test_flat_bottom_does_not_constrain():
    grid = GeoGrid((0, 0.5, 0, 0.5), 5e3)
    assert np.isinf(slope_size(grid, np.full(grid.shape, 3000.0), elements_per_slope=30)).all()


def test_high_land_is_clipped_before_filtering():
    """A 3 km mountain next to a flat 500 m sea floor: clipped to 50 m, it changes the sea's slope far less."""
    grid = GeoGrid((0, 1, 0, 0.5), 2e3)
    depth = np.full(grid.shape, 500.0)
    depth[: grid.shape[0] // 3] = -3000.0
    clipped = slope_size(grid, depth, elements_per_slope=30)
    unclipped = slope_size(grid, depth, elements_per_slope=30, max_land_elevation=np.inf)
    # the filtered step's gradient is proportional to the step: (500 + 3000) / (500 + 50) times smaller sizes
    near = slice(grid.shape[0] // 3, grid.shape[0] // 3 + 5)
    assert clipped[near] / unclipped[near] == pytest.approx(3500 / 550, rel=1e-6)


def test_slope_size_refuses_bad_input():
    grid = GeoGrid((0, 1, 0, 1), 20e3)
    depth = np.full(grid.shape, 200.0)
    with pytest.raises(SizingError, match="elements_per_slope"):
        slope_size(grid, depth, elements_per_slope=0)
    with pytest.raises(SizingError, match="shape"):
        slope_size(grid, depth[1:], elements_per_slope=30)
    depth[3, 3] = np.nan
    with pytest.raises(SizingError, match="NaN"):
        slope_size(grid, depth, elements_per_slope=30)
    with pytest.raises(GeometryError):
        slope_size(None, depth, elements_per_slope=30)
