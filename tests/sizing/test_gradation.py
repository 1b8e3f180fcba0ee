import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import SizingError
from terramesh.sizing import SizeGrid, lift_to_floor, limit_gradient, limit_gradient_up

SCHEMES = ["persson", "godunov"]

# (shape, dx, dy): single rows and columns, fewer rows than the kernel's
# four-row bands, row counts that leave a remainder, unequal spacings.
CASES = [
    ((1, 9), 1.0, 1.0),
    ((9, 1), 0.5, 2.0),
    ((3, 7), 0.3, 0.2),
    ((4, 5), 1.0, 2.0),
    ((5, 4), 2.0, 1.0),
    ((13, 9), 0.1, 0.1),
    ((11, 17), 0.07, 0.13),
    ((20, 20), 1.0, 0.5),
    ((30, 23), 0.05, 0.11),
]


def upwind_gradient(h, spacing, scheme):
    """The scheme's upwind |grad h| at every node of a 2-D or 3-D grid (no neighbour beyond the edge)."""
    padded = np.pad(h, 1, mode="edge")
    squared = np.zeros_like(h)
    for axis, step in enumerate(spacing):
        index = [slice(1, -1)] * h.ndim
        index[axis] = slice(None, -2)
        back = (h - padded[tuple(index)]) / step
        index[axis] = slice(2, None)
        ahead = (padded[tuple(index)] - h) / step
        if scheme == "persson":
            squared += np.maximum(back, 0) ** 2 + np.minimum(ahead, 0) ** 2
        else:
            squared += np.maximum(np.maximum(back, -ahead), 0) ** 2
    return np.sqrt(squared)


def explicit_reference(h0, spacing, grade, scheme, max_steps=200_000):
    """Persson's explicit time stepping h += dt (min(|grad h|, g) - |grad h|) until nothing changes.

    The time step keeps the scheme monotone, so the iteration decreases to
    the steady state from above.
    """
    h = np.array(h0, dtype=np.float64)
    dt = 0.9 / np.sqrt(sum(2 / step**2 for step in spacing))
    for _ in range(max_steps):
        gradient = upwind_gradient(h, spacing, scheme)
        new = h + dt * (np.minimum(gradient, grade) - gradient)
        if np.array_equal(new, h):
            return h
        h = new
    raise AssertionError("explicit reference did not converge")


def random_sizes(shape, seed):
    return np.random.default_rng(seed).uniform(0.05, 1.0, size=shape)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("shape, dx, dy", CASES)
@pytest.mark.parametrize("seed", [0, 1])
def test_matches_explicit_time_stepping(scheme, shape, dx, dy, seed):
    h0 = random_sizes(shape, seed)
    expected = explicit_reference(h0, (dx, dy), 0.2, scheme)
    assert np.any(expected < h0)  # the case limits something
    np.testing.assert_allclose(limit_gradient(h0, (dx, dy), 0.2, scheme=scheme), expected, rtol=1e-12, atol=0)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("dx, dy", [(0.02, 0.4), (0.4, 0.02)])
def test_matches_explicit_time_stepping_on_anisotropic_grid_with_sizes_over_three_decades(scheme, dx, dy):
    h0 = 10 ** np.random.default_rng(10).uniform(-3, 0, size=(64, 50))
    expected = explicit_reference(h0, (dx, dy), 0.2, scheme)
    np.testing.assert_allclose(limit_gradient(h0, (dx, dy), 0.2, scheme=scheme), expected, rtol=1e-12, atol=0)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("case", ["random", "cones from two corners"])
def test_matches_explicit_time_stepping_across_the_kernels_row_blocks(scheme, case):
    # 150 rows: swept in two blocks side by side, each against copies of the other's edge row, in rounds;
    # a cone from a corner crosses the blocks' edge, and back from the other corner
    if case == "random":
        h0 = random_sizes((150, 37), 3)
    else:
        h0 = np.full((150, 23), 5.0)
        h0[0, 0] = h0[-1, -1] = 0.01
    expected = explicit_reference(h0, (0.1, 0.07), 0.2, scheme)
    np.testing.assert_allclose(limit_gradient(h0, (0.1, 0.07), 0.2, scheme=scheme), expected, rtol=1e-12, atol=0)
    assert np.any(expected[74:76] < h0[74:76])  # sizes limited either side of the blocks' edge


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("shape, dx, dy", CASES[-3:])
def test_limited_sizes_obey_the_grade(scheme, shape, dx, dy):
    h0 = random_sizes(shape, 5)
    h = limit_gradient(h0, (dx, dy), 0.15, scheme=scheme)
    assert np.all(h <= h0)
    assert upwind_gradient(h, (dx, dy), scheme).max() <= 0.15 * (1 + 1e-12)
    # any two axis neighbours differ by at most grade times their distance
    assert np.abs(np.diff(h, axis=0)).max() <= 0.15 * dx * (1 + 1e-12)
    assert np.abs(np.diff(h, axis=1)).max() <= 0.15 * dy * (1 + 1e-12)
    # a node either keeps its size or sits exactly at the grade
    lowered = h < h0
    np.testing.assert_allclose(upwind_gradient(h, (dx, dy), scheme)[lowered], 0.15, rtol=1e-12)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_is_idempotent(scheme):
    h = limit_gradient(random_sizes((40, 31), 2), (0.1, 0.07), 0.2, scheme=scheme)
    np.testing.assert_array_equal(limit_gradient(h, (0.1, 0.07), 0.2, scheme=scheme), h)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_graded_sizes_are_unchanged(scheme):
    x = np.linspace(0, 10, 41)[:, None]
    y = np.linspace(0, 6, 25)[None, :]
    h0 = 1 + 0.1 * x + 0.05 * y + 0.2 * np.sin(0.3 * x) * np.cos(0.2 * y)
    assert upwind_gradient(h0, (0.25, 0.25), scheme).max() < 0.2
    np.testing.assert_array_equal(limit_gradient(h0, 0.25, 0.2, scheme=scheme), h0)


def test_smallest_size_is_kept_and_larger_input_gives_larger_output():
    h0 = random_sizes((25, 18), 3)
    h = limit_gradient(h0, 0.1, 0.2)
    assert h.min() == h0.min()
    assert np.all(limit_gradient(h0 * 1.5 + 0.1, 0.1, 0.2) >= h)


@pytest.mark.parametrize("scheme, terms", [("persson", 4), ("godunov", 2)])
def test_spike_is_cut_to_the_pinned_value(scheme, terms):
    # one large value among equal neighbours: all `terms` upwind terms are active
    h0 = np.ones((5, 6))
    h0[2, 3] = 10.0
    dx, dy = 0.5, 0.8
    h = limit_gradient(h0, (dx, dy), 0.2, scheme=scheme)
    weight = terms / 2 * (1 / dx**2 + 1 / dy**2)
    assert h[2, 3] == pytest.approx(1 + 0.2 / np.sqrt(weight), rel=1e-14)
    h[2, 3] = 1.0
    np.testing.assert_array_equal(h, 1.0)


def test_godunov_on_a_row_is_the_exact_cone():
    h0 = random_sizes((60, 1), 4)
    x = 0.3 * np.arange(60)
    expected = np.min(h0[None, :, 0] + 0.2 * np.abs(x[:, None] - x[None, :]), axis=1)
    np.testing.assert_allclose(limit_gradient(h0, 0.3, 0.2, scheme="godunov")[:, 0], expected, rtol=1e-14)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("dx, dy", [(1.0, 1.0), (0.5, 0.8)])
def test_single_seed_approaches_the_euclidean_cone(scheme, dx, dy):
    # h(x) = min_y (h0(y) + g |x - y|) = seed + g r; the grid solution is never
    # below it and overshoots the increase g r by at most 21% (first diagonal
    # node), 5.5% at 20 spacings and 3% at 50 (measured: 20.7%, 4.5-5.5%, 2.4-2.9%).
    n, m = 201, 161
    h0 = np.full((n, m), 100.0)
    h0[100, 80] = 0.5
    h = limit_gradient(h0, (dx, dy), 0.2, scheme=scheme)
    r = np.hypot(dx * (np.arange(n) - 100)[:, None], dy * (np.arange(m) - 80)[None, :])
    cone = 0.5 + 0.2 * r
    assert np.all(h >= cone * (1 - 1e-12))
    overshoot = (h - cone) / np.where(r > 0, 0.2 * r, 1.0)
    assert overshoot.max() <= 0.21
    assert overshoot[r >= 20 * min(dx, dy)].max() <= 0.055
    assert overshoot[r >= 50 * min(dx, dy)].max() <= 0.03


def test_input_is_not_modified_and_may_be_read_only():
    h0 = random_sizes((12, 10), 6)
    h0.flags.writeable = False
    before = h0.copy()
    h = limit_gradient(h0, 0.1, 0.2)
    np.testing.assert_array_equal(h0, before)
    assert h.flags.c_contiguous and h.dtype == np.float64 and not np.shares_memory(h, h0)


def test_overwrite_values_limits_in_place_only_when_it_can():
    h0 = random_sizes((12, 10), 6)
    expected = limit_gradient(h0, 0.1, 0.2)
    h = limit_gradient(h0, 0.1, 0.2, overwrite_values=True)
    assert h is h0
    np.testing.assert_array_equal(h, expected)
    # a conversion is needed (Fortran order, integers, read-only): a copy, the input untouched
    for given in (np.asfortranarray(random_sizes((9, 7), 7)), np.array([[1, 9, 9, 9]])):
        before = given.copy()
        assert not np.shares_memory(limit_gradient(given, 10, 0.2, overwrite_values=True), given)
        np.testing.assert_array_equal(given, before)
    frozen = random_sizes((6, 6), 8)
    frozen.flags.writeable = False
    assert not np.shares_memory(limit_gradient(frozen, 0.1, 0.2, overwrite_values=True), frozen)
    bad = random_sizes((5, 5), 9)
    bad[2, 2] = np.nan
    with pytest.raises(SizingError, match="NaN or infinite"):
        limit_gradient(bad, 0.1, 0.2, overwrite_values=True)


def test_fortran_ordered_and_integer_input():
    h0 = np.asfortranarray(random_sizes((9, 7), 7))
    np.testing.assert_array_equal(limit_gradient(h0, 0.1, 0.2), limit_gradient(np.ascontiguousarray(h0), 0.1, 0.2))
    integers = np.array([[1, 9, 9, 9]])
    np.testing.assert_allclose(limit_gradient(integers, 10, 0.2), [[1, 3, 5, 7]])


def test_scalar_spacing_and_g_alias():
    h0 = random_sizes((8, 8), 8)
    h = limit_gradient(h0, (0.1, 0.1), 0.2)
    np.testing.assert_array_equal(limit_gradient(h0, 0.1, 0.2), h)
    np.testing.assert_array_equal(limit_gradient(h0, 0.1, g=0.2), h)


def test_size_grid_in_size_grid_out():
    x = np.linspace(0, 2, 11)
    y = np.linspace(-1, 2, 31)
    h0 = random_sizes((11, 31), 9)
    grid = SizeGrid((x, y), h0)
    limited = tm.sizing.limit_gradient(grid, grade=0.25)
    assert isinstance(limited, SizeGrid)
    np.testing.assert_array_equal(limited.axes[0], x)
    np.testing.assert_array_equal(limited.axes[1], y)
    np.testing.assert_array_equal(limited.values, limit_gradient(h0, (x[1] - x[0], y[1] - y[0]), 0.25))
    np.testing.assert_array_equal(grid.values, h0)


# 3-D (shape, (dx, dy, dz)): lines and planes along each axis, fewer rows
# along y than the kernel's four-row bands, remainders, unequal spacings.
CASES_3D = [
    ((1, 1, 9), (1.0, 1.0, 0.5)),
    ((1, 9, 1), (1.0, 0.5, 1.0)),
    ((9, 1, 1), (0.5, 1.0, 1.0)),
    ((1, 6, 7), (1.0, 0.3, 0.2)),
    ((6, 1, 7), (0.3, 1.0, 0.2)),
    ((6, 7, 1), (0.3, 0.2, 1.0)),
    ((2, 3, 4), (0.4, 0.3, 0.2)),
    ((3, 4, 5), (0.3, 0.2, 0.5)),
    ((5, 8, 3), (0.2, 0.2, 0.2)),
    ((7, 5, 6), (0.1, 0.25, 0.07)),
    ((4, 9, 7), (0.6, 0.15, 0.3)),
    ((10, 13, 6), (0.05, 0.11, 0.3)),
]


def random_case_3d(seed):
    """A random small grid: 1 to 9 nodes per axis, spacings from 0.05 to 1, unequal."""
    rng = np.random.default_rng(1000 + seed)
    shape = tuple(int(n) for n in rng.integers(1, 10, size=3))
    if np.prod(shape) < 2:
        shape = (2,) + shape[1:]
    return shape, tuple(float(d) for d in 10 ** rng.uniform(np.log10(0.05), 0, size=3))


CASES_3D += [random_case_3d(seed) for seed in range(16)]


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("shape, spacing", CASES_3D)
@pytest.mark.parametrize("seed", [0, 1])
def test_3d_matches_explicit_time_stepping(scheme, shape, spacing, seed):
    h0 = random_sizes(shape, seed)
    expected = explicit_reference(h0, spacing, 0.2, scheme)
    assert np.any(expected < h0)  # the case limits something
    np.testing.assert_allclose(limit_gradient(h0, spacing, 0.2, scheme=scheme), expected, rtol=1e-12, atol=0)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("spacing", [(0.02, 0.4, 0.1), (0.4, 0.1, 0.02)])
def test_3d_matches_explicit_time_stepping_on_anisotropic_grid_with_sizes_over_three_decades(scheme, spacing):
    h0 = 10 ** np.random.default_rng(11).uniform(-3, 0, size=(16, 14, 12))
    expected = explicit_reference(h0, spacing, 0.2, scheme)
    np.testing.assert_allclose(limit_gradient(h0, spacing, 0.2, scheme=scheme), expected, rtol=1e-12, atol=0)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("case", ["random", "cones from two corners"])
def test_3d_matches_explicit_time_stepping_across_the_kernels_plane_blocks(scheme, case):
    # 40 x-planes: swept in two blocks side by side, each against copies of the other's edge plane, in rounds
    if case == "random":
        h0 = random_sizes((40, 9, 7), 4)
    else:
        h0 = np.full((40, 6, 5), 5.0)
        h0[0, 0, 0] = h0[-1, -1, -1] = 0.01
    spacing = (0.1, 0.07, 0.13)
    expected = explicit_reference(h0, spacing, 0.2, scheme)
    np.testing.assert_allclose(limit_gradient(h0, spacing, 0.2, scheme=scheme), expected, rtol=1e-12, atol=0)
    assert np.any(expected[19:21] < h0[19:21])  # sizes limited either side of the blocks' edge


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("shape, spacing", [((17, 22, 19), (0.1, 0.07, 0.13)), ((25, 9, 30), (0.3, 0.05, 0.1))])
def test_3d_limited_sizes_obey_the_grade(scheme, shape, spacing):
    h0 = random_sizes(shape, 5)
    h = limit_gradient(h0, spacing, 0.15, scheme=scheme)
    assert np.all(h <= h0)
    assert h.min() == h0.min()
    gradient = upwind_gradient(h, spacing, scheme)
    assert gradient.max() <= 0.15 * (1 + 1e-12)
    for axis, step in enumerate(spacing):
        assert np.abs(np.diff(h, axis=axis)).max() <= 0.15 * step * (1 + 1e-12)
    # a node either keeps its size or sits exactly at the grade
    lowered = h < h0
    assert lowered.mean() > 0.5
    np.testing.assert_allclose(gradient[lowered], 0.15, rtol=1e-12)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_3d_is_idempotent_and_monotone_in_the_input(scheme):
    h0 = random_sizes((14, 11, 13), 2)
    spacing = (0.1, 0.07, 0.2)
    h = limit_gradient(h0, spacing, 0.2, scheme=scheme)
    np.testing.assert_array_equal(limit_gradient(h, spacing, 0.2, scheme=scheme), h)
    assert np.all(limit_gradient(h0 * 1.5 + 0.1, spacing, 0.2, scheme=scheme) >= h)


@pytest.mark.parametrize("scheme, terms", [("persson", 6), ("godunov", 3)])
def test_3d_spike_is_cut_to_the_pinned_value(scheme, terms):
    # one large value among equal neighbours: all `terms` upwind terms are active
    h0 = np.ones((5, 6, 4))
    h0[2, 3, 1] = 10.0
    dx, dy, dz = 0.5, 0.8, 0.3
    h = limit_gradient(h0, (dx, dy, dz), 0.2, scheme=scheme)
    weight = terms / 3 * (1 / dx**2 + 1 / dy**2 + 1 / dz**2)
    assert h[2, 3, 1] == pytest.approx(1 + 0.2 / np.sqrt(weight), rel=1e-14)
    h[2, 3, 1] = 1.0
    np.testing.assert_array_equal(h, 1.0)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_3d_grid_one_node_thick_matches_2d(scheme):
    h0 = random_sizes((37, 29), 12)
    expected = limit_gradient(h0, (0.1, 0.07), 0.2, scheme=scheme)
    for axis in range(3):
        spacing = [0.1, 0.07]
        spacing.insert(axis, 5.0)
        h = limit_gradient(np.expand_dims(h0, axis), spacing, 0.2, scheme=scheme)
        np.testing.assert_allclose(h.squeeze(axis), expected, rtol=1e-12, atol=0)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_3d_permuting_the_axes_permutes_the_result(scheme):
    h0 = random_sizes((9, 14, 11), 13)
    spacing = (0.1, 0.07, 0.13)
    h = limit_gradient(h0, spacing, 0.2, scheme=scheme)
    for order in [(0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]:
        permuted = limit_gradient(h0.transpose(order), [spacing[k] for k in order], 0.2, scheme=scheme)
        np.testing.assert_allclose(permuted, h.transpose(order), rtol=1e-12, atol=0)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("spacing", [(1.0, 1.0, 1.0), (0.5, 0.8, 0.65), (1.0, 0.3, 0.6)])
def test_3d_single_seed_approaches_the_euclidean_cone(scheme, spacing):
    # h(x) = min_y (h0(y) + g |x - y|) = seed + g r. The grid solution is never
    # below it and above it by the first-order upwind error for a point
    # source, O(d log(r / d)) with d the coarsest spacing: at most
    # 0.45 g d (1 + ln(r / d)) (measured: 0.28-0.41), which is 32% of the
    # increase g r at the first diagonal node and 7.5% at 20 spacings.
    shape, seed = (41, 37, 33), (20, 15, 18)
    h0 = np.full(shape, 100.0)
    h0[seed] = 0.5
    h = limit_gradient(h0, spacing, 0.2, scheme=scheme)
    axes = [step * (np.arange(n) - k) for step, n, k in zip(spacing, shape, seed, strict=True)]
    r = np.sqrt(sum(offset**2 for offset in np.meshgrid(*axes, indexing="ij")))
    cone = 0.5 + 0.2 * r
    assert np.all(h <= h0)
    assert np.all(h >= cone * (1 - 1e-12))
    d = max(spacing)
    assert np.all(h - cone <= 0.45 * 0.2 * d * (1 + np.log(np.maximum(r / d, 1))))


def test_3d_input_is_not_modified_and_may_be_read_only_or_fortran_ordered():
    h0 = random_sizes((8, 10, 7), 6)
    h0.flags.writeable = False
    before = h0.copy()
    h = limit_gradient(h0, (0.1, 0.2, 0.15), 0.2)
    np.testing.assert_array_equal(h0, before)
    assert h.shape == h0.shape and h.flags.c_contiguous and h.dtype == np.float64 and not np.shares_memory(h, h0)
    np.testing.assert_array_equal(limit_gradient(np.asfortranarray(h0), (0.1, 0.2, 0.15), 0.2), h)


def test_3d_scalar_spacing_and_g_alias():
    h0 = random_sizes((6, 7, 8), 8)
    h = limit_gradient(h0, (0.1, 0.1, 0.1), 0.2)
    np.testing.assert_array_equal(limit_gradient(h0, 0.1, 0.2), h)
    np.testing.assert_array_equal(limit_gradient(h0, 0.1, g=0.2), h)


def test_3d_size_grid_in_size_grid_out():
    axes = (np.linspace(0, 2, 11), np.linspace(-1, 2, 16), np.linspace(0, 0.5, 6))
    h0 = random_sizes((11, 16, 6), 9)
    grid = SizeGrid(axes, h0)
    limited = tm.sizing.limit_gradient(grid, grade=0.25, scheme="godunov")
    assert isinstance(limited, SizeGrid) and limited.dim == 3
    for axis, expected in zip(limited.axes, axes, strict=True):
        np.testing.assert_array_equal(axis, expected)
    steps = tuple(axis[1] - axis[0] for axis in axes)
    np.testing.assert_array_equal(limited.values, limit_gradient(h0, steps, 0.25, scheme="godunov"))
    np.testing.assert_array_equal(grid.values, h0)


def nan_at_corner():
    h = np.ones((4, 4))
    h[0, 0] = np.nan
    return h


@pytest.mark.parametrize(
    "values, spacing, grade, options, message",
    [
        (nan_at_corner(), 1.0, 0.2, {}, "NaN or infinite"),
        (np.full((3, 3), np.inf), 1.0, 0.2, {}, "NaN or infinite"),
        (np.zeros((3, 3)), 1.0, 0.2, {}, "zero or negative"),
        (-np.ones((3, 3)), 1.0, 0.2, {}, "zero or negative"),
        (np.ones(5), 1.0, 0.2, {}, "2-D array .* or a 3-D array"),
        (np.ones((2, 2, 2, 2)), 1.0, 0.2, {}, r"2-D array indexed \[ix, iy\] or a 3-D array"),
        (np.ones((2, 2, 2, 2)), (1.0, 1.0, 1.0, 1.0), 0.2, {}, r"got shape \(2, 2, 2, 2\)"),
        (np.ones((0, 3)), 1.0, 0.2, {}, "empty"),
        (np.array([["a", "b"]]), 1.0, 0.2, {}, "real numbers"),
        (np.ones((3, 3)) + 0j, 1.0, 0.2, {}, "real numbers"),
        (np.ones((3, 3)), 1.0, 0.0, {}, "grade must be a positive"),
        (np.ones((3, 3)), 1.0, -0.2, {}, "grade must be a positive"),
        (np.ones((3, 3)), 1.0, np.nan, {}, "grade must be a positive"),
        (np.ones((3, 3)), 1.0, "0.2", {}, "grade must be a positive"),
        (np.ones((3, 3)), 1.0, None, {}, "needs a grade"),
        (np.ones((3, 3)), 1.0, 0.2, {"g": 0.2}, "not both"),
        (np.ones((3, 3)), None, 0.2, {}, "spacing"),
        (np.ones((3, 3)), 0.0, 0.2, {}, "spacing must be positive"),
        (np.ones((3, 3)), (1.0, -1.0), 0.2, {}, "spacing must be positive"),
        (np.ones((3, 3)), (1.0, 1.0, 1.0), 0.2, {}, r"one per axis, \(dx, dy\), for a 2-D grid"),
        (np.ones((3, 3)), "1", 0.2, {}, "one per axis"),
        (np.ones((3, 3, 3)), (1.0, 1.0), 0.2, {}, r"one per axis, \(dx, dy, dz\), for a 3-D grid, got \(1.0, 1.0\)"),
        (np.ones((3, 3, 3)), [[1.0, 1.0, 1.0]], 0.2, {}, r"for a 3-D grid"),
        (np.ones((3, 3, 3)), (1.0, 0.0, 1.0), 0.2, {}, "spacing must be positive"),
        (np.ones((3, 3, 3)), None, 0.2, {}, "spacing"),
        (np.pad(nan_at_corner()[:, :, None], ((0, 0), (0, 0), (0, 2)), mode="edge"), 1.0, 0.2, {}, "NaN or infinite"),
        (-np.ones((2, 3, 4)), 1.0, 0.2, {}, "zero or negative"),
        (np.ones((2, 0, 4)), 1.0, 0.2, {}, "empty"),
        (np.ones((3, 3)), 1.0, 0.2, {"scheme": "upwind"}, "scheme must be one of"),
        # a ZeroDivisionError inside the kernel; sizes 1e80 on 1e-80 came out graded 2:1 where 1:1 is right
        (np.ones((3, 3)), 1e-170, 0.2, {}, r"spacing \(1e-170, 1e-170\) differ by more than 1e\+100 times"),
        (np.full((3, 3, 3), 1e80), 1e-80, 0.2, {}, r"sizes \(1e\+80 to 1e\+80\) and spacing"),
    ],
)
def test_bad_inputs_raise(values, spacing, grade, options, message):
    with pytest.raises(SizingError, match=message):
        limit_gradient(values, spacing, grade, **options)


@pytest.mark.parametrize("unit", [1e-160, 1e-3, 1e150])
def test_the_grading_is_the_same_in_any_unit(unit):
    # sizes and spacing of 1e-160 or 1e160 overflowed or divided by zero inside the kernels
    sizes = np.random.default_rng(4).uniform(1.0, 9.0, (6, 7, 5))
    for scheme in ("persson", "godunov"):
        graded = limit_gradient(sizes, (1.0, 1.5, 0.5), 0.2, scheme=scheme)
        scaled = limit_gradient(sizes * unit, (unit, 1.5 * unit, 0.5 * unit), 0.2, scheme=scheme)
        np.testing.assert_allclose(scaled / unit, graded, rtol=1e-12)


def test_bad_size_grid_calls_raise():
    axis = np.linspace(0, 1, 4)
    with pytest.raises(SizingError, match="own spacing"):
        limit_gradient(SizeGrid((axis, axis), np.ones((4, 4))), 0.2)
    with pytest.raises(SizingError, match="own spacing"):
        limit_gradient(SizeGrid((axis, axis, axis), np.ones((4, 4, 4))), (0.1, 0.1, 0.1), 0.2)
    with pytest.raises(SizingError, match="2 or 3 coordinate arrays"):  # a 1-D SizeGrid is refused when made
        limit_gradient(SizeGrid((axis,), np.ones(4)), grade=0.2)


def test_an_infinite_grade_limits_nothing():
    """inf turns the limit off (a box of build_multiscale graded with g=inf raised 'positive finite number')."""
    values = np.array([[1.0, 50.0], [3.0, 0.5]])
    np.testing.assert_array_equal(limit_gradient(values, 1.0, np.inf), values)
    assert limit_gradient(values, 1.0, 0.2)[0, 1] < 50.0
    with pytest.raises(SizingError, match="NaN or infinite"):
        limit_gradient(np.full((2, 2), np.nan), 1.0, np.inf)  # the sizes are still checked


@pytest.mark.parametrize("shape, dx, dy", CASES[3:7])
def test_limit_gradient_up_is_the_mirror_of_the_limiter(shape, dx, dy):
    # the smallest h >= h0 with |grad h| <= g: the limiter's steady state of the mirrored field, exactly
    h0 = random_sizes(shape, 3) * 100.0
    raised = limit_gradient_up(h0, (dx, dy), 0.2)
    top = 2.0 * h0.max()
    mirrored = explicit_reference(top - h0, (dx, dy), 0.2, "persson")
    np.testing.assert_allclose(raised, np.maximum(top - mirrored, h0), rtol=1e-12)
    assert np.all(raised >= h0)
    assert np.all(upwind_gradient(top - raised, (dx, dy), "persson") <= 0.2 * (1 + 1e-9))


def test_limit_gradient_up_on_a_row_is_the_exact_cone_and_keeps_graded_sizes():
    h0 = random_sizes((60, 1), 5)
    x = 0.3 * np.arange(60)
    expected = np.max(h0[None, :, 0] - 0.2 * np.abs(x[:, None] - x[None, :]), axis=1)
    np.testing.assert_allclose(limit_gradient_up(h0, 0.3, 0.2, scheme="godunov")[:, 0], expected, rtol=1e-13)
    graded = 1.0 + 0.1 * x[:, None]  # already within the grade: nothing raised
    np.testing.assert_array_equal(limit_gradient_up(graded, 0.3, 0.2), graded)
    assert np.array_equal(limit_gradient_up(h0, 0.3, np.inf), h0)


def test_limit_gradient_up_refuses_what_the_limiter_refuses():
    with pytest.raises(SizingError, match="NaN or infinite"):
        limit_gradient_up(np.array([[1.0, np.nan]]), 1.0, 0.2)
    with pytest.raises(SizingError, match="grade must be a positive number"):
        limit_gradient_up(np.ones((2, 2)), 1.0, -0.2)


@pytest.mark.parametrize(
    "shape, spacing", [((200, 150), (1.0, 0.7)), ((60, 50, 40), (1.0, 0.5, 2.0)), ((300, 1), (0.3,))]
)
@pytest.mark.parametrize("spots", [0, 1, 3, "all"])
def test_lift_to_floor_equals_the_whole_grid_graded_up(shape, spacing, spots):
    # only the box around the nodes whose floor is above the sizes, padded by their reach, is graded up
    rng = np.random.default_rng(len(shape) * 10 + (9 if spots == "all" else spots))
    spacing = spacing if len(spacing) == len(shape) else spacing * len(shape)
    sizes = limit_gradient(rng.uniform(1.0, 5.0, shape), spacing, 0.2)
    floor = np.full(shape, 0.5)
    if spots == "all":
        floor = rng.uniform(2.0, 8.0, shape)
    for _ in range(0 if spots == "all" else spots):  # a little above the sizes: a reach of 5-10 spacings
        spot = tuple(rng.integers(0, n) for n in shape)
        floor[spot] = sizes[spot] + rng.uniform(1.0, 2.0)
    expected = np.maximum(sizes, limit_gradient_up(floor, spacing, 0.2))
    lifted = lift_to_floor(sizes.copy(), floor, spacing, 0.2)
    np.testing.assert_array_equal(lifted, expected)
    if spots in (1, 3):  # the floor raised some nodes, and not the whole grid
        assert 0 < np.count_nonzero(lifted > sizes) < sizes.size // 2
    assert np.all(lifted >= floor) and np.all(lifted >= sizes)


def test_lift_to_floor_refuses_a_floor_that_is_not_finite():
    sizes = np.ones((4, 4))
    with pytest.raises(SizingError, match="floor has 1 NaN or infinite entries"):
        lift_to_floor(sizes, np.where(np.eye(4, dtype=bool) & (np.arange(4) == 2), np.inf, 0.5), 1.0, 0.2)


# a grade per row along y: the ground grade on a Mercator grid (g cos(lat) on the grid's own lengths)
def row_grades(ny, seed):
    return np.random.default_rng(seed).uniform(0.05, 0.4, ny)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("shape, dx, dy", CASES)
def test_a_grade_per_row_matches_explicit_time_stepping(scheme, shape, dx, dy):
    h0 = random_sizes(shape, 7)
    grades = row_grades(shape[1], 8)
    expected = explicit_reference(h0, (dx, dy), grades, scheme)
    graded = limit_gradient(h0, (dx, dy), grades, scheme=scheme)
    np.testing.assert_allclose(graded, expected, rtol=1e-12, atol=0)
    lowered = graded < h0
    assert lowered.any()
    # a node either keeps its size or sits exactly at its own row's grade
    np.testing.assert_allclose(
        upwind_gradient(graded, (dx, dy), scheme)[lowered], np.broadcast_to(grades, shape)[lowered], rtol=1e-12
    )


@pytest.mark.parametrize("scheme", SCHEMES)
def test_the_same_grade_on_every_row_is_the_single_grade(scheme):
    h0 = random_sizes((37, 29), 9)
    single = limit_gradient(h0, (0.1, 0.07), 0.2, scheme=scheme)
    np.testing.assert_array_equal(limit_gradient(h0, (0.1, 0.07), np.full(29, 0.2), scheme=scheme), single)
    np.testing.assert_array_equal(limit_gradient(h0, (0.1, 0.07), [0.2] * 29, scheme=scheme), single)


@pytest.mark.parametrize("spots", [1, 3, "all"])
def test_lift_to_floor_with_a_grade_per_row_equals_the_whole_grid_graded_up(spots):
    rng = np.random.default_rng(21 if spots == "all" else spots)
    shape, spacing = (120, 90), (1.0, 0.7)
    grades = 0.2 * np.cos(np.linspace(0.0, 1.4, shape[1]))  # 0.2 to 0.034
    sizes = limit_gradient(rng.uniform(1.0, 5.0, shape), spacing, grades)
    floor = rng.uniform(2.0, 8.0, shape) if spots == "all" else np.full(shape, 0.5)
    for _ in range(0 if spots == "all" else spots):
        spot = tuple(rng.integers(0, n) for n in shape)
        floor[spot] = sizes[spot] + rng.uniform(1.0, 2.0)
    expected = np.maximum(sizes, limit_gradient_up(floor, spacing, grades))
    np.testing.assert_array_equal(lift_to_floor(sizes.copy(), floor, spacing, grades), expected)
    top = 2.0 * floor.max()  # the raised floor falls by at most each row's grade
    raised = limit_gradient_up(floor, spacing, grades)
    assert np.all(upwind_gradient(top - raised, spacing, "persson") <= grades * (1 + 1e-9))


@pytest.mark.parametrize(
    "values, grade, message",
    [
        (np.ones((3, 4)), [0.2, 0.2, 0.2], r"one grade per node along y, 4 for a grid of shape \(3, 4\); got shape"),
        (np.ones((3, 4)), np.full((3, 4), 0.2), r"got shape \(3, 4\)"),
        (np.ones((3, 4, 5)), np.full(4, 0.2), r"for 2-D grids; a 3-D grid \(shape \(3, 4, 5\)\) takes one grade"),
        (np.ones((3, 4)), [[0.2, 0.2], [0.2]], "positive number or an array of them"),  # NumPy's ValueError
        (np.ones((3, 4)), [0.2, 0.0, 0.2, 0.2], "positive and finite; 1 are not"),
        (np.ones((3, 4)), [0.2, np.nan, np.inf, 0.2], "positive and finite; 2 are not"),
        (np.ones((3, 4)), ["a", "b", "c", "d"], "positive number or an array of them"),
    ],
)
def test_bad_grades_per_row_raise(values, grade, message):
    with pytest.raises(SizingError, match=message):
        limit_gradient(values, 1.0, grade)
    with pytest.raises(SizingError, match=message):
        lift_to_floor(np.ones_like(values), np.full(values.shape, 2.0), 1.0, grade)
