import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from terramesh._kernels import read_only
from terramesh._kernels.raster import nearest_feature, transposed


@settings(deadline=None, max_examples=80)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.floats(0.0005, 0.5))
def test_nearest_feature_is_an_exact_euclidean_distance_transform(seed, nx, ny, density):
    """Each node's answer is a feature node at the distance scipy's transform finds (ties may differ)."""
    rng = np.random.default_rng(seed)
    feature = rng.random((nx, ny)) < density
    feature[rng.integers(nx), rng.integers(ny)] = True
    nearest_x, nearest_y = nearest_feature(feature)
    assert feature[nearest_x, nearest_y].all()
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    reference = ndimage.distance_transform_edt(~feature, return_distances=False, return_indices=True)
    np.testing.assert_array_equal(
        (i - nearest_x) ** 2 + (j - nearest_y) ** 2, (i - reference[0]) ** 2 + (j - reference[1]) ** 2
    )


def test_nearest_feature_without_features_is_minus_one():
    nearest_x, nearest_y = nearest_feature(np.zeros((3, 4), dtype=bool))
    assert (nearest_x == -1).all() and (nearest_y == -1).all()


@settings(deadline=None, max_examples=40)
@given(st.integers(0, 2**32 - 1), st.integers(1, 200), st.integers(1, 200))
def test_transposed_is_numpys_transpose(seed, rows, columns):
    # tiles of 64 nodes: shapes below, at and across a tile's edge
    mask = np.random.default_rng(seed).random((rows, columns)) < 0.5
    out = transposed(mask)
    assert out.flags.c_contiguous
    np.testing.assert_array_equal(out, mask.T)


@pytest.mark.parametrize("dim", [2, 3])
def test_largest_along_segments_is_the_largest_of_the_samples_interpolated(dim):
    """Against the points laid out in NumPy and interpolated by bilinear/trilinear: equal, bit for bit."""
    from terramesh._kernels.raster import bilinear, largest_along_2d, largest_along_3d, trilinear

    rng = np.random.default_rng(dim)
    values = read_only(rng.uniform(1500.0, 4500.0, (7, 5, 6)[:dim]))
    origin, spacing = rng.uniform(-10, 10, dim), rng.uniform(0.5, 2.0, dim)
    starts = rng.uniform(-5, 15, (200, dim))  # beyond the grid too: clamped
    ends = starts + rng.normal(0, 3, (200, dim))
    samples = rng.integers(2, 12, 200)
    largest_along, interpolate = (largest_along_2d, bilinear) if dim == 2 else (largest_along_3d, trilinear)
    got = largest_along(values, origin, spacing, starts, ends, samples)
    edge = np.repeat(np.arange(200), samples)
    first = np.cumsum(samples) - samples
    fraction = (np.arange(len(edge)) - np.repeat(first, samples)) / (np.repeat(samples, samples) - 1)
    along = starts[edge] + fraction[:, None] * (ends[edge] - starts[edge])
    np.testing.assert_array_equal(got, np.maximum.reduceat(interpolate(values, origin, spacing, along), first))


def test_graded_from_box_is_the_numpy_haversine_cone():
    """The multiscale cone around an inner box, against the NumPy formula it replaced (to rounding)."""
    from terramesh._kernels.raster import bilinear, graded_from_box

    rng = np.random.default_rng(5)
    radius = 6371e3
    values = read_only(rng.uniform(100.0, 1000.0, (9, 7)))
    origin, spacing = np.array([2e5, 3e6]), np.array([500.0, 700.0])
    offset = 4e4  # the box's own longitudes are east of the first box's
    box = np.array([origin[0] + offset, origin[0] + offset + 8 * 500.0, origin[1], origin[1] + 6 * 700.0])
    south, north = 0.45, 0.46
    x, y = rng.uniform(1.8e5, 2.9e5, 3000), rng.uniform(2.95e6, 3.05e6, 3000)
    latitude = 0.45 + (y - 3e6) / radius
    before = rng.uniform(200.0, 20000.0, 3000)
    size = before.copy()
    graded_from_box(x, y, latitude, size, values, origin, spacing, box, south, north, 0.2, offset, radius)
    near = np.column_stack([np.clip(x, box[0], box[1]), np.clip(y, box[2], box[3])])
    there = np.clip(latitude, south, north)
    half = (
        np.sin(0.5 * (latitude - there)) ** 2
        + np.cos(latitude) * np.cos(there) * np.sin(0.5 * (x - near[:, 0]) / radius) ** 2
    )
    distance = 2.0 * radius * np.arcsin(np.sqrt(np.minimum(half, 1.0)))
    own = bilinear(values, origin, spacing, near - [offset, 0.0])
    outside = (near[:, 0] != x) | (near[:, 1] != y)
    expected = np.where(outside, np.minimum(before, (own * np.cos(there) + 0.2 * distance) / np.cos(latitude)), before)
    assert 0 < outside.sum() < 3000 and np.sum(size < before) > 100
    np.testing.assert_allclose(size, expected, rtol=1e-13)


@pytest.mark.parametrize("seed", [0, 1])
def test_nearest_node_distance_is_the_mercator_length_times_cos_lat_at_the_middle(seed):
    from terramesh._kernels.raster import EARTH_RADIUS, nearest_node_distance

    rng = np.random.default_rng(seed)
    x = np.linspace(-1.1e7, -5.5e6, 40)
    y = np.linspace(-8e6, 1.5e7, 60)  # from 58 S to 87 N
    near_x, near_y = rng.integers(0, 40, (40, 60), dtype=np.int32), rng.integers(0, 60, (40, 60), dtype=np.int32)
    mercator = np.hypot(x[near_x] - x[:, None], y[near_y] - y[None, :])
    expected = mercator / np.cosh(0.5 * (y[None, :] + y[near_y]) / EARTH_RADIUS)
    np.testing.assert_allclose(nearest_node_distance(near_x, near_y, x, y), expected, rtol=2e-15, atol=0)


@settings(deadline=None, max_examples=60)
@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 30), st.integers(1, 40))
def test_neighbourhood_segments_lists_each_segment_of_the_block_once_in_scan_order(seed, nx, ny, n_segments):
    from terramesh._kernels.raster import mark_segments, neighbourhood_segments

    rng = np.random.default_rng(seed)
    ends = rng.uniform(-2, [nx + 1, ny + 1], size=(n_segments, 2, 2))  # some off the raster
    cells, segments = mark_segments(ends[:, 0, 0], ends[:, 0, 1], ends[:, 1, 0], ends[:, 1, 1], nx, ny)
    order = np.argsort(cells, kind="stable")
    cells, segments = cells[order], segments[order]
    first = np.full(nx * ny, -1, dtype=np.int32)
    starts = np.flatnonzero(np.r_[True, cells[1:] != cells[:-1]]) if cells.size else np.zeros(0, int)
    first[cells[starts]] = starts
    first = first.reshape(nx, ny)
    span, items = neighbourhood_segments(first, cells, segments, n_segments)
    for k in starts:
        cx, cy = divmod(int(cells[k]), ny)
        scanned = [
            int(segments[p])
            for i in range(max(cx - 1, 0), min(cx + 2, nx))
            for j in range(max(cy - 1, 0), min(cy + 2, ny))
            for p in np.flatnonzero(cells == i * ny + j)
        ]
        assert items[span[k, 0] : span[k, 1]].tolist() == list(dict.fromkeys(scanned))
