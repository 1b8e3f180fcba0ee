import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from terramesh._kernels.segments import candidate_segment_distance
from terramesh.errors import GeometryError
from terramesh.geometry import SegmentIndex


def brute_force(points, starts, ends):
    direction = ends - starts
    t = np.einsum("nkd,kd->nk", points[:, None, :] - starts, direction) / np.maximum(
        np.einsum("kd,kd->k", direction, direction), 1e-300
    )
    closest = starts + np.clip(t, 0, 1)[..., None] * direction
    return np.min(np.linalg.norm(points[:, None, :] - closest, axis=2), axis=1)


coordinates = arrays(np.float64, st.tuples(st.integers(1, 30), st.just(2)), elements=st.floats(-10, 10))


@settings(max_examples=80, deadline=None)
@given(coordinates, coordinates, coordinates)
@example(np.zeros((1, 2)), np.full((1, 2), 5e-324), np.zeros((1, 2)))  # found: a subnormal segment's grid cell was 0
def test_index_agrees_with_brute_force(starts, ends, points):
    count = min(len(starts), len(ends))
    starts, ends = starts[:count], ends[:count]
    got = SegmentIndex(starts, ends).distance(points)
    expected = brute_force(points, starts, ends)
    assert np.all(got >= expected - 1e-9)
    np.testing.assert_allclose(got, expected, rtol=1e-2, atol=1e-9)
    # the KD-tree alone, as for points the bucket grid already left unsettled: the same guarantee
    alone = SegmentIndex(starts, ends).distance(points, searched=True)
    assert np.all(alone >= expected - 1e-9)
    np.testing.assert_allclose(alone, expected, rtol=1e-2, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(coordinates, coordinates, st.integers(0, 2**32 - 1))
def test_nearest_segments_finds_a_segment_each_point_lies_on(starts, ends, seed):
    # points on the segments (a mesh's boundary vertices) are found on one of the segments they lie on,
    # points farther than the radius from all of them on none
    count = min(len(starts), len(ends))
    starts, ends = starts[:count], ends[:count]
    rng = np.random.default_rng(seed)
    on = rng.integers(0, count, 20)
    points = starts[on] + rng.uniform(0, 1, (20, 1)) * (ends[on] - starts[on])
    radius = 1e-6
    found = SegmentIndex(starts, ends).nearest_segments(np.vstack([points, [[50.0, 50.0]]]), radius)
    assert found[-1] == -1
    found = found[:-1]
    assert np.all(found >= 0)
    direction = ends[found] - starts[found]
    t = np.clip(
        np.einsum("nd,nd->n", points - starts[found], direction)
        / np.maximum(np.einsum("nd,nd->n", direction, direction), 1e-300),
        0,
        1,
    )
    assert np.all(np.linalg.norm(points - (starts[found] + t[:, None] * direction), axis=1) <= radius + 1e-12)


def test_one_long_segment_among_tiny_ones_is_cut_into_a_bounded_number_of_pieces():
    """Pieces of twice the median length would be 10**8 here (CI ran out of memory on such a draw)."""
    starts = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [-10.0, -10.0]])
    ends = starts + np.array([[1e-7, 0.0], [1e-7, 0.0], [1e-7, 0.0], [20.0, 0.0]])
    index = SegmentIndex(starts, ends)
    assert len(index.starts) <= 64 * 4 + 4
    points = np.random.default_rng(3).uniform(-12, 12, (200, 2))
    np.testing.assert_allclose(index.distance(points), brute_force(points, starts, ends), rtol=1e-2, atol=1e-9)


def test_kernel_matches_numpy_reference():
    rng = np.random.default_rng(1)
    starts, ends, points = rng.normal(size=(50, 2)), rng.normal(size=(50, 2)), rng.normal(size=(200, 2))
    candidates = rng.integers(0, 50, size=(200, 7))
    got = candidate_segment_distance(points, starts, ends, candidates)
    expected = [brute_force(points[i : i + 1], starts[c], ends[c])[0] for i, c in enumerate(candidates)]
    np.testing.assert_allclose(got, expected, rtol=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 400), st.floats(0.001, 0.5))
def test_bucket_grid_is_exact_near_the_segments_and_bounds_far_ones(seed, count, spread):
    rng = np.random.default_rng(seed)
    starts = rng.random((count, 2))
    ends = starts + spread * rng.standard_normal((count, 2)) * rng.random((count, 1))
    index = SegmentIndex(starts, ends)
    points = np.vstack([rng.random((300, 2)), 4.0 * rng.standard_normal((50, 2))])  # near, and far out
    direction = ends - starts
    length2 = np.maximum(np.sum(direction**2, axis=1), 1e-300)
    t = np.clip(np.einsum("pmd,md->pm", points[:, None] - starts[None], direction) / length2, 0, 1)
    brute = np.min(np.linalg.norm(starts[None] + t[..., None] * direction[None] - points[:, None], axis=2), axis=1)
    distance = index.distance(points)
    assert np.all(distance >= brute - 1e-12) and np.all(distance <= brute * (1 + 1e-2) + 1e-12)
    near = brute < 2.0 * index.half_length
    np.testing.assert_allclose(distance[near], brute[near], rtol=1e-12, atol=1e-14)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 300), st.floats(0.001, 0.3))
def test_clearance_bounds_the_distance_from_below_and_grows_away_from_the_segments(seed, count, spread):
    rng = np.random.default_rng(seed)
    starts = rng.random((count, 2)) * [4.0, 1.0]  # a grid wider than the segments' clusters
    starts[: count // 2, 0] *= 0.1  # two clusters: empty cells between them
    ends = starts + spread * rng.standard_normal((count, 2)) * rng.random((count, 1))
    index = SegmentIndex(starts, ends)
    lower, upper = np.minimum(starts, ends).min(axis=0), np.maximum(starts, ends).max(axis=0)
    origin, cell, nx, ny = index._grid[:4]
    points = lower + (upper - lower) * rng.random((400, 2))  # on the grid
    points = np.vstack([points, origin + np.array([nx, ny]) * cell + rng.random((20, 2))])  # off the grid: no bound
    clearance = index.clearance(points)
    assert np.all(clearance <= brute_force(points, starts, ends))
    assert np.all(clearance[-20:] == 0.0)
    on_grid = points[:-20]
    far = brute_force(on_grid, starts, ends) > 4.0 * cell
    assert np.all(clearance[:-20][far] >= brute_force(on_grid[far], starts, ends) - 3.0 * cell)  # two diagonals


def sides_numpy(points, settled, segment, parameter, normal, before, after, starts, ends):
    """The side of each point by the bisector rule the kernel implements away from needles, in NumPy."""
    side = np.zeros(len(points), dtype=np.int8)
    at = np.flatnonzero(settled)
    piece, t = segment[at], parameter[at]
    direction = normal[piece]
    direction[t <= 0.0] += normal[before[piece[t <= 0.0]]]
    direction[t >= 1.0] += normal[after[piece[t >= 1.0]]]
    offset = points[at] - starts[piece] - t[:, None] * (ends[piece] - starts[piece])
    side[at] = np.sign(np.einsum("ij,ij->i", offset, direction))
    return side


@settings(max_examples=40, deadline=None)
@given(st.integers(3, 60), st.integers(0, 2**16), st.floats(0.0, 0.6))
def test_sides_on_a_star_ring_match_numpy_and_point_in_polygon(count, seed, roughness):
    """Vertex-nearest points included (the bisector rule): the kernel against NumPy, and against contains_xy."""
    import shapely

    from terramesh._kernels.segments import grid_nearest, nearest_sides

    rng = np.random.default_rng(seed)
    angle = np.sort(rng.uniform(0, 2 * np.pi, count))
    radius = 1 + roughness * rng.uniform(-1, 1, count)
    ring = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
    polygon = shapely.Polygon(ring)
    if len(np.unique(ring, axis=0)) < 3 or not polygon.is_valid or polygon.area <= 0:
        return  # angles within half a turn can leave the origin outside, and the ring crossing itself
    if not shapely.is_ccw(polygon.exterior):
        ring = ring[::-1]
    index = SegmentIndex(ring, np.roll(ring, -1, axis=0), following=np.roll(np.arange(count), -1))
    points = np.vstack([rng.uniform(-1.8, 1.8, (300, 2)), ring + 0.01 * rng.normal(size=ring.shape)])
    distance, side, settled = index.distance_and_side(points)
    origin, cell, nx, ny, cell_start, cell_items, rings = index._grid
    _, _, found, segment, parameter = grid_nearest(
        points, index.starts, index.ends, origin, cell, nx, ny, cell_start, cell_items, rings
    )
    before, after, normal = index._neighbours
    pieces = (index.starts, index.ends)
    expected = sides_numpy(points, found, segment, parameter, normal, before, after, *pieces)
    np.testing.assert_array_equal(
        nearest_sides(points, found, segment, parameter, normal, before, after, *pieces, index._chained_ends), expected
    )
    np.testing.assert_array_equal(side, expected)
    # counter-clockwise ring: left is inside
    clear = settled & (distance > 1e-9)
    inside = shapely.contains_xy(shapely.Polygon(ring), points[clear, 0], points[clear, 1])
    np.testing.assert_array_equal(side[clear] == 1, inside)


def test_distance_and_side_without_the_order_is_a_geometry_error():
    square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    index = SegmentIndex(square, np.roll(square, -1, axis=0))
    with pytest.raises(GeometryError, match="following="):  # a plain ValueError before
        index.distance_and_side(np.array([[0.5, 0.5]]))


def star_ring(rng, count, roughness, long_sides):
    """A star-shaped counter-clockwise ring; ``long_sides`` of its sides stretched (the index cuts them into pieces)."""
    angle = np.sort(rng.uniform(0, 2 * np.pi, count))
    angle[:long_sides] = np.linspace(0, np.pi / 2, long_sides, endpoint=False) if long_sides else angle[:0]
    angle = np.sort(angle)
    radius = 1 + roughness * rng.uniform(-1, 1, count)
    return np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])


@settings(max_examples=60, deadline=None)
@given(
    st.integers(3, 80),
    st.integers(0, 2**16),
    st.floats(0.0, 0.6),
    st.integers(0, 3),
    st.sampled_from([0.0, 1e3, 2e7]),
    st.sampled_from([None, 0.0, 1e-3, 0.1]),
)
def test_crossing_sides_are_point_in_polygon(count, seed, roughness, long_sides, offset, tolerance):
    """Far from the origin too (Mercator metres): a piece cut from a long side ends a rounding from where the next
    begins, and a crossing count on those pieces could slip through the gap."""
    import shapely

    rng = np.random.default_rng(seed)
    ring = star_ring(rng, count, roughness, min(long_sides, count)) * (1.0 if offset == 0 else 5e3) + offset
    polygon = shapely.Polygon(ring)
    if len(np.unique(ring, axis=0)) < 3 or not polygon.is_valid or polygon.area <= 0:
        return
    if not shapely.is_ccw(polygon.exterior):
        ring = ring[::-1]
    index = SegmentIndex(ring, np.roll(ring, -1, axis=0), following=np.roll(np.arange(len(ring)), -1))
    # the pieces used for counting chain exactly, ring by ring
    _, after, _ = index._neighbours
    np.testing.assert_array_equal(index._chained_ends, index.starts[after])
    scale = np.ptp(ring, axis=0).max()
    low, high = ring.min(axis=0) - 0.2 * scale, ring.max(axis=0) + 0.2 * scale
    vertices_nearby = ring + scale * 10.0 ** rng.uniform(-12, -2, (len(ring), 1)) * rng.standard_normal(ring.shape)
    points = np.vstack(
        [rng.uniform(low, high, (400, 2)), vertices_nearby, index.starts, 0.5 * (index.starts + index.ends)]
    )
    centres = index.cell_centres()
    tolerance = None if tolerance is None else tolerance * scale
    side = index.sides(points, shapely.contains_xy(polygon, centres[:, 0], centres[:, 1]), tolerance)
    contains = shapely.contains_xy(polygon, points[:, 0], points[:, 1])
    distance = brute_force(points, ring, np.roll(ring, -1, axis=0))
    expected = contains & (distance > (-1.0 if tolerance is None else tolerance))
    # the pieces' ends are the ring's points rounded: a point a rounding from the boundary may go either way
    rounding = 1e-9 * max(scale, np.abs(ring).max())
    decided = side != 0
    clear = decided & (distance > rounding)
    np.testing.assert_array_equal((side == 1)[clear], expected[clear])
    assert np.all(distance[~decided] <= rounding)  # left to the caller: only points on the boundary or next to it
    assert clear[:400].mean() > 0.9  # the points drawn in the box


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**16), st.integers(2, 300), st.sampled_from([0.0, 3e3, 2e7]))
def test_the_search_stopping_at_a_cells_sides_finds_the_nearest_piece(seed, count, offset):
    """Points on and next to the grid's cell sides, pieces just across them: a search that stops once the best
    distance is within the way to its cell's sides misses no nearer piece, and settles the points it did."""
    from terramesh._kernels.segments import grid_nearest

    rng = np.random.default_rng(seed)
    starts = offset + rng.random((count, 2))
    ends = starts + 0.05 * rng.standard_normal((count, 2))
    index = SegmentIndex(starts, ends)
    origin, cell, nx, ny, cell_start, cell_items, rings = index._grid
    sides = origin + cell * rng.integers(0, max(nx, ny) + 1, (400, 2))  # cell corners, exactly
    points = np.vstack([sides, sides + cell * 1e-9 * rng.standard_normal((400, 2)), offset + rng.random((300, 2))])
    points[:400, 1] = offset + rng.random(400)  # on a vertical side
    distance, _, found, segment, _ = grid_nearest(
        points, index.starts, index.ends, origin, cell, nx, ny, cell_start, cell_items, rings
    )
    brute = brute_force(points, index.starts, index.ends)
    np.testing.assert_allclose(distance[found], brute[found], rtol=1e-12, atol=1e-15 * (1 + offset))
    # every point the grid can reach is settled: within (rings - 1) cells of a piece
    assert np.all(found[brute < (rings - 1) * cell * (1 - 1e-9)])
