"""Exact predicates and the incremental Delaunay kernel behind ``delaunay_with_neighbors``."""

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial import ConvexHull, Delaunay, QhullError, cKDTree

from terramesh._kernels import delaunay as kernel
from terramesh.errors import GenerationError
from terramesh.generation.seeding import hexagonal_lattice
from terramesh.generation.triangulate import delaunay_with_neighbors
from terramesh.mesh.topology import cell_neighbor_table

# --- exact references ---------------------------------------------------------------------------


def orient_exact(a, b, c):
    ax, ay, bx, by, cx, cy = (Fraction(float(v)) for v in (*a, *b, *c))
    return (ax - cx) * (by - cy) - (ay - cy) * (bx - cx)


def incircle_exact(a, b, c, d):
    ax, ay, bx, by, cx, cy, dx, dy = (Fraction(float(v)) for v in (*a, *b, *c, *d))
    adx, ady, bdx, bdy, cdx, cdy = ax - dx, ay - dy, bx - dx, by - dy, cx - dx, cy - dy
    return (
        (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy)
        + (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy)
        + (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady)
    )


def sign(x):
    return int(x > 0) - int(x < 0)


# --- the invariants a triangulation must satisfy -----------------------------------------------


def signed_areas(points, cells):
    a, b, c = points[cells[:, 0]], points[cells[:, 1]], points[cells[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def assert_valid_delaunay(points, cells, neighbors, duplicate_of, *, exact_circles=None):
    """Every cell CCW, neighbours consistent, hull covered, all points used, circumcircles empty."""
    n = len(points)
    # a power-of-two scale is exact: the checks below then never overflow or underflow
    points = np.ldexp(points, -int(np.frexp(np.abs(points).max())[1]))
    assert cells.dtype == np.int64 and neighbors.dtype == np.int64
    assert cells.shape == neighbors.shape and cells.shape[1] == 3
    # counter-clockwise with positive area: exactly where rounding cannot decide
    areas = signed_areas(points, cells)
    scale = np.abs(points).max() ** 2
    unsure = np.abs(areas) <= 1e-12 * scale
    assert np.all(areas[~unsure] > 0)
    for a, b, c in cells[unsure]:
        assert orient_exact(points[a], points[b], points[c]) > 0
    # neighbours: the table built by sorting edges, symmetric, shared edges traversed both ways
    np.testing.assert_array_equal(neighbors, cell_neighbor_table(cells))
    rows, corners = np.nonzero(neighbors >= 0)
    across = neighbors[rows, corners]
    back = np.argmax(neighbors[across] == rows[:, None], axis=1)
    np.testing.assert_array_equal(neighbors[across, back], rows)
    np.testing.assert_array_equal(cells[rows, (corners + 1) % 3], cells[across, (back + 2) % 3])
    np.testing.assert_array_equal(cells[rows, (corners + 2) % 3], cells[across, (back + 1) % 3])
    # every point is a vertex, or an exact duplicate of one
    used = np.zeros(n, dtype=bool)
    used[cells.ravel()] = True
    np.testing.assert_array_equal(used, duplicate_of < 0)
    skipped = np.flatnonzero(duplicate_of >= 0)
    assert np.all(used[duplicate_of[skipped]])
    np.testing.assert_array_equal(points[skipped], points[duplicate_of[skipped]])
    # one planar triangulated disk: Euler's formula with the hull's boundary edges
    boundary = np.count_nonzero(neighbors < 0)
    assert len(cells) == 2 * np.count_nonzero(used) - boundary - 2
    # the cells cover the convex hull
    try:
        hull_area = ConvexHull(points).volume
    except QhullError:
        hull_area = None  # too flat for Qhull; orientation and Euler above still hold
    if hull_area is not None:
        assert areas.sum() == pytest.approx(hull_area, rel=1e-9)
    # empty circumcircles
    if exact_circles is None:
        exact_circles = n <= 40
    if exact_circles:
        vertices = np.flatnonzero(used)
        for a, b, c in cells:
            for d in vertices:
                assert incircle_exact(points[a], points[b], points[c], points[d]) <= 0
    else:
        assert_empty_circumcircles(points, cells, used)


def assert_empty_circumcircles(points, cells, used):
    """No vertex strictly inside a circumcircle: KD-tree candidates, each decided exactly."""
    vertex_ids = np.flatnonzero(used)
    tree = cKDTree(points[vertex_ids])
    a, b, c = points[cells[:, 0]], points[cells[:, 1]], points[cells[:, 2]]
    bx, by = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    cx, cy = c[:, 0] - a[:, 0], c[:, 1] - a[:, 1]
    d = 2 * (bx * cy - by * cx)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ux = (cy * (bx**2 + by**2) - by * (cx**2 + cy**2)) / d
        uy = (bx * (cx**2 + cy**2) - cx * (bx**2 + by**2)) / d
        radius = np.hypot(ux, uy)
    centre = a + np.column_stack([ux, uy])
    # hull slivers have huge circles: the exact all-pairs check on small inputs covers those
    span = np.ptp(points, axis=0).max()
    fine = np.isfinite(radius) & (radius < 10 * span)
    candidates = tree.query_ball_point(centre[fine], radius[fine] * (1 + 1e-6))
    for cell, near in zip(cells[fine], candidates, strict=True):
        for d in vertex_ids[near]:
            if d not in cell:
                assert incircle_exact(*points[cell], points[d]) <= 0, (cell, d)


def triangulate(points):
    points = np.asarray(points, dtype=float)
    before = points.copy()
    cells, neighbors, duplicate_of = delaunay_with_neighbors(points, return_duplicates=True)
    np.testing.assert_array_equal(points, before)  # the input is not modified
    return cells, neighbors, duplicate_of


def check(points, **kwargs):
    points = np.asarray(points, dtype=float)
    cells, neighbors, duplicate_of = triangulate(points)
    assert_valid_delaunay(points, cells, neighbors, duplicate_of, **kwargs)
    return cells, neighbors, duplicate_of


# --- predicates ------------------------------------------------------------------------------------


def test_orient_sign_is_exact_near_a_line():
    # Shewchuk's classic: points a few ulps from the line y = x, where floating point gets the sign wrong
    ulp = 2.0**-53
    grid = 0.5 + ulp * np.arange(32)
    b, c = np.array([12.0, 12.0]), np.array([24.0, 24.0])
    wrong_in_float = 0
    for x in grid:
        for y in grid:
            points = np.array([[x, y], b, c])
            got = kernel.orient(points, 0, 1, 2, kernel.workspace())
            expected = sign(orient_exact(points[0], b, c))
            assert sign(got) == expected
            naive = (x - 24.0) * (12.0 - 24.0) - (y - 24.0) * (12.0 - 24.0)
            wrong_in_float += sign(naive) != expected
    assert wrong_in_float > 0  # the case is hard: the static filter had to hand over to the exact path


def test_incircle_sign_is_exact_near_a_circle():
    rng = np.random.default_rng(5)
    angles = rng.uniform(0, 2 * np.pi, size=(300, 4))
    centre = rng.uniform(-1, 1, size=(300, 1, 2)) * 1e3
    points = centre + np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    # nudge d by a few ulps so all three signs occur
    points[:, 3] += rng.integers(-2, 3, size=(300, 2)) * np.spacing(points[:, 3])
    signs = []
    for quad in points:
        a, b, c, d = quad
        if orient_exact(a, b, c) < 0:
            quad = quad[[1, 0, 2, 3]]
            a, b, c, d = quad
        expected = sign(incircle_exact(a, b, c, d))
        assert sign(kernel.incircle(np.ascontiguousarray(quad), 0, 1, 2, 3, kernel.workspace())) == expected
        signs.append(expected)
    assert set(signs) == {-1, 0, 1} or set(signs) == {-1, 1}


def test_incircle_exactly_cocircular_lattice_square():
    for offset in [0.0, 0.1, 1e6 + 0.1, 1e-30]:
        square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]) * 0.3 + offset
        exact = sign(incircle_exact(*square))
        assert sign(kernel.incircle(square, 0, 1, 2, 3, kernel.workspace())) == exact


@settings(max_examples=200, deadline=None)
@given(
    # exactness holds while no fourth-degree product underflows (documented): keep magnitudes within 1e60
    arrays(np.float64, (4, 2), elements=st.floats(-1e3, 1e3).filter(lambda v: v == 0 or abs(v) > 1e-57)),
    st.integers(0, 40),
)
def test_predicates_match_rational_arithmetic(points, shrink):
    # squeezing towards one point makes cancellation severe while staying in floating point
    points = points[0] + (points - points[0]) * 2.0**-shrink
    assert sign(kernel.orient(points, 0, 1, 2, kernel.workspace())) == sign(orient_exact(*points[:3]))
    assert sign(kernel.incircle(points, 0, 1, 2, 3, kernel.workspace())) == sign(incircle_exact(*points))


def incircle_quads(rng, count, bits):
    """Quads of integers below ``2^bits`` times a power of two, a third of them exactly cocircular."""
    quads = rng.integers(-(2**bits) + 1, 2**bits, size=(count, 4, 2)).astype(float)
    # a rectangle's corners, and the corners of a square rotated by a Pythagorean angle, are cocircular
    rectangles = quads[: count // 6]
    rectangles[:, 1] = np.column_stack([rectangles[:, 2, 0], rectangles[:, 0, 1]])
    rectangles[:, 3] = np.column_stack([rectangles[:, 0, 0], rectangles[:, 2, 1]])
    radius = 2.0 ** (bits // 2 - 4)
    turned = np.array([[3.0, 4.0], [-4.0, 3.0], [-3.0, -4.0], [4.0, -3.0]]) * radius
    quads[count // 6 : count // 3] = np.round(quads[count // 6 : count // 3, :1] / 8) + turned
    return quads * 2.0 ** rng.integers(-80, 20, size=(count, 1, 1))


@pytest.mark.parametrize("bits", [3, 30, 53])
def test_incircle_integer_stage_matches_rational_arithmetic(bits):
    # the integers' full width, for the limb arithmetic's carries and signs; 53 bits span up to 58 here
    rng = np.random.default_rng(bits)
    quads = incircle_quads(rng, 600, bits)
    quads[:100, :, 0] += 2.0 ** (np.frexp(np.abs(quads[:100]).max(axis=(1, 2)))[1] + 4)[:, None]
    decided = set()
    for quad in quads:
        got = kernel._incircle_integer(*quad.ravel())
        if got == 2:
            continue
        assert got == sign(incircle_exact(*quad)), quad
        decided.add(got)
    assert decided == {-1, 0, 1}


def test_incircle_integer_stage_at_its_limits():
    # coordinates as wide as allowed (53-bit mantissas up to 2^58): the largest differences and products
    top = (2.0**53 - 1) * 2.0**5
    corners = np.array([[top, top], [-top, top], [-top, -top], [top, -top]])
    assert kernel._incircle_integer(*corners.ravel()) == 0
    # the last corner moved a step of the doubles there (32) in, or the others moved in
    inside, outside = corners.copy(), corners.copy()
    inside[3, 0] -= 32.0
    outside[:3] -= 32.0 * np.sign(corners[:3])
    assert kernel._incircle_integer(*inside.ravel()) == sign(incircle_exact(*inside)) == 1
    assert kernel._incircle_integer(*outside.ravel()) == sign(incircle_exact(*outside)) == -1
    rng = np.random.default_rng(9)
    for quad in rng.choice([-top, -1.0, 0.0, 1.0, top], size=(300, 4, 2)):
        assert kernel._incircle_integer(*quad.ravel()) == sign(incircle_exact(*quad))
    # beyond them the stage declines and the expansion arithmetic decides
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    spread = square.copy()
    spread[0, 0] = 2.0**-59  # 60 bits below the largest coordinate
    for quad in (square * 2.0**58, spread, square * 1e-300):
        assert kernel._incircle_integer(*quad.ravel()) == 2
        assert sign(kernel.incircle(np.ascontiguousarray(quad), 0, 1, 2, 3, kernel.workspace())) == sign(
            incircle_exact(*quad)
        )


# --- insertion order ---------------------------------------------------------------------------------


def hilbert_key_by_rotation(x, y, bits):
    """The textbook xy-to-index conversion, turning the coordinates level by level."""
    side, key, s = 1 << bits, 0, 1 << (bits - 1)
    while s > 0:
        rx, ry = int(x & s > 0), int(y & s > 0)
        key += s * s * ((3 * rx) ^ ry)
        if ry == 0:
            if rx == 1:
                x, y = side - 1 - x, side - 1 - y
            x, y = y, x
        s >>= 1
    return key


@settings(deadline=None, max_examples=30)
@given(st.integers(1, 20), st.integers(0, 2**32 - 1))
def test_hilbert_keys_equal_the_rotation_algorithm_and_walk_between_neighbouring_cells(bits, seed):
    rng = np.random.default_rng(seed)
    side = 1 << bits
    # integer points with the grid's corners: the bounding box maps each onto its own cell
    cells = np.vstack([rng.integers(0, side, size=(200, 2)), [[0, 0], [side - 1, side - 1]]])
    keys = kernel.hilbert_keys(cells.astype(float), bits)
    expected = [hilbert_key_by_rotation(int(x), int(y), bits) for x, y in cells]
    np.testing.assert_array_equal(keys, expected)
    if bits <= 6:  # the whole grid in curve order: each cell is next to the one before
        i, j = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
        grid = np.column_stack([i.ravel(), j.ravel()]).astype(float)
        walk = grid[np.argsort(kernel.hilbert_keys(grid, bits))]
        assert np.all(np.abs(np.diff(walk, axis=0)).sum(axis=1) == 1)


@settings(deadline=None, max_examples=40)
@given(st.integers(0, 3000), st.integers(1, 62), st.booleans(), st.integers(0, 2**32 - 1))
def test_key_sort_is_numpys_stable_argsort(n, key_bits, negative, seed):
    # Hilbert keys are below 2**40; others (negative, 2**55 and up) need all six digits of the radix sort
    rng = np.random.default_rng(seed)
    keys = rng.integers(-(2**key_bits) if negative else 0, 2**key_bits, size=n, dtype=np.int64)
    keys[: n // 3] = keys[n // 2 : n // 2 + n // 3]  # repeats: the order among equal keys is the input's
    order, sorted_keys = kernel._sort_keys(keys)
    np.testing.assert_array_equal(order, np.argsort(keys, kind="stable"))
    np.testing.assert_array_equal(sorted_keys, keys[order])


def test_hilbert_order_refines_clusters():
    rng = np.random.default_rng(6)
    cluster = 0.5 + 1e-9 * rng.random((2000, 2))
    points = np.vstack([rng.random((2000, 2)), cluster, np.repeat(cluster[:1], 50, axis=0)])
    order = kernel.hilbert_order(points, 20, 16)
    np.testing.assert_array_equal(np.sort(order), np.arange(len(points)))
    # consecutive cluster points are neighbours, not a random walk across the cluster
    in_cluster = order[(order >= 2000) & (order < 4000)]
    steps = np.hypot(*np.diff(points[in_cluster], axis=0).T)
    assert np.median(steps) < 0.05 * 1e-9


def test_clustered_points():
    rng = np.random.default_rng(7)
    check(np.vstack([rng.random((3000, 2)), 0.5 + 1e-9 * rng.random((3000, 2))]))


# --- triangulation: fixed cases -----------------------------------------------------------------------


def test_three_points():
    cells, neighbors, duplicate_of = check([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]])
    assert len(cells) == 1
    np.testing.assert_array_equal(neighbors, -1)


def test_agrees_with_qhull_in_general_position():
    points = np.random.default_rng(0).random((500, 2))
    cells, _, _ = check(points, exact_circles=False)
    ours = {tuple(sorted(c)) for c in cells.tolist()}
    theirs = {tuple(sorted(c)) for c in Delaunay(points).simplices.tolist()}
    assert ours == theirs


@pytest.mark.parametrize("n", [4, 10, 37, 1000, 20000])
def test_random_points(n):
    check(np.random.default_rng(n).random((n, 2)))


def test_hexagonal_lattice():
    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.01)
    check(points)


def test_small_hexagonal_lattice_exactly():
    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.25)
    check(points, exact_circles=True)


@pytest.mark.parametrize("side", [2, 5, 100])
def test_square_lattice_every_quad_cocircular(side):
    grid = np.stack(np.meshgrid(np.arange(side), np.arange(side)), axis=-1).reshape(-1, 2) * 0.1
    cells, _, _ = check(grid)
    assert len(cells) == 2 * (side - 1) ** 2


def test_points_on_a_circle_and_its_centre():
    angles = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    circle = np.column_stack([np.cos(angles), np.sin(angles)])
    check(circle, exact_circles=True)
    check(np.vstack([circle, [[0.0, 0.0]]]), exact_circles=True)


def test_exact_and_near_duplicates():
    rng = np.random.default_rng(1)
    points = rng.random((300, 2))
    near = points[:50] + 1e-15 * rng.standard_normal((50, 2))
    doubled = np.vstack([points, points[:100], near, points[:10]])
    cells, _, duplicate_of = check(doubled)
    assert np.count_nonzero(duplicate_of >= 0) >= 110


def test_near_duplicate_far_below_rounding_stays_a_vertex():
    # pinned: Qhull merges these two points; here they stay distinct vertices, and the
    # cell between them has a positive area that floating point rounds to zero
    points = np.array([[5.41416928e-138, 1.0], [0.5, 0.0], [0.0, 1.0], [1.0, 1.0]])
    cells, _, duplicate_of = check(points)
    assert len(cells) == 2
    np.testing.assert_array_equal(duplicate_of, -1)


def test_duplicates_of_lattice_and_hull_points():
    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.1)
    doubled = np.vstack([points, points[::-1]])
    cells, _, duplicate_of = check(doubled)
    assert np.count_nonzero(duplicate_of >= 0) == len(points)


def test_default_return_is_cells_and_neighbors():
    result = delaunay_with_neighbors(np.random.default_rng(2).random((20, 2)))
    assert len(result) == 2


@pytest.mark.parametrize("scale", [1e-300, 1e-150, 1e-20, 1.0, 1e20, 1e150, 1e300])
def test_tiny_and_huge_scales(scale):
    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.1)
    rng = np.random.default_rng(3)
    for case in (points, rng.random((200, 2))):
        reference, _, _ = triangulate(case)
        cells, _, _ = check(case * scale)
        # scaling by a power of two is exact, so the triangulation is the same
        if np.log2(scale).is_integer():
            np.testing.assert_array_equal(cells, reference)


def test_large_offset_small_spread():
    # UTM-like coordinates: the differences carry few significant bits
    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.05)
    check(np.array([5.0e5, 6.0e6]) + points * 1e-6)


def test_near_collinear_points():
    x = np.linspace(0, 1, 100)
    rng = np.random.default_rng(4)
    line = np.column_stack([x, 0.3 * x + 0.1])
    # a few ulps off the line, on both sides
    line[:, 1] += rng.integers(-3, 4, size=100) * np.spacing(line[:, 1])
    cells, _, _ = check(line, exact_circles=True)
    assert len(cells) > 0


def test_collinear_plus_one_point():
    line = np.column_stack([np.arange(50.0), np.zeros(50)])
    cells, _, _ = check(np.vstack([line, [[3.3, 1e-9]]]), exact_circles=False)
    assert len(cells) == 49


def test_hull_with_many_collinear_points_and_outside_insertions():
    # the square's sides are lattice rows: collinear hull points, inserted from inside out and back
    side = np.arange(30.0)
    grid = np.stack(np.meshgrid(side, side), axis=-1).reshape(-1, 2)
    order = np.argsort(np.hypot(*(grid - 14.5).T))
    check(grid[order])
    check(grid[order[::-1]])


@pytest.mark.parametrize(
    "points",
    [
        np.column_stack([np.arange(5.0), np.zeros(5)]),
        np.column_stack([np.arange(5.0), 2 * np.arange(5.0) + 1]),
        np.zeros((7, 2)),
        np.array([[0.0, 0.0], [1.0, 1.0], [0.0, 0.0], [1.0, 1.0]]),
    ],
)
def test_degenerate_input_raises(points):
    with pytest.raises(GenerationError, match="span a plane"):
        delaunay_with_neighbors(points)


@pytest.mark.parametrize(
    "points", [np.zeros((2, 2)), np.zeros((5, 3)), np.array([[0.0, 0.0], [1.0, np.nan], [0.0, 1.0]])]
)
def test_bad_input_raises(points):
    with pytest.raises(GenerationError):
        delaunay_with_neighbors(points)


# --- triangulation: generated cases -------------------------------------------------------------------


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    arrays(np.int64, st.tuples(st.integers(3, 40), st.just(2)), elements=st.integers(-4, 4)),
    st.sampled_from([1.0, 0.1, 1e-7, 3e11]),
)
def test_small_integer_grids(points, scale):
    """Tiny grids: collinear, cocircular and duplicate points everywhere."""
    points = points * scale
    try:
        cells, neighbors, duplicate_of = triangulate(points)
    except GenerationError:
        distinct = np.unique(points, axis=0)
        assert len(distinct) < 3 or np.linalg.matrix_rank(distinct[1:] - distinct[0]) < 2
        return
    assert_valid_delaunay(points, cells, neighbors, duplicate_of, exact_circles=True)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(arrays(np.float64, st.tuples(st.integers(3, 30), st.just(2)), elements=st.floats(-1e6, 1e6, width=32)))
def test_random_float_points(points):
    try:
        cells, neighbors, duplicate_of = triangulate(points)
    except GenerationError:
        distinct = np.unique(points, axis=0)
        assert len(distinct) < 3 or all(orient_exact(distinct[0], distinct[1], q) == 0 for q in distinct[2:])
        return
    assert_valid_delaunay(points, cells, neighbors, duplicate_of, exact_circles=True)


# --- following moved points by flips (restore_delaunay through Triangulation) --------------------


def moved_and_checked(points, moved, *, expect_flips=True):
    from terramesh.generation.triangulate import Triangulation

    triangulation = Triangulation(points)
    followed = triangulation.move_points(moved)
    cells, neighbors = triangulation.cells_and_neighbors()
    assert_valid_delaunay(moved, cells, neighbors, np.full(len(moved), -1), exact_circles=len(moved) <= 40)
    assert followed == expect_flips
    return triangulation


@pytest.mark.parametrize("n", [10, 300, 20000])
def test_small_random_moves_are_followed_by_flips(n):
    rng = np.random.default_rng(n)
    points = rng.random((n, 2))
    spacing = 1 / np.sqrt(n)
    cells = delaunay_with_neighbors(points)[0]
    noise = rng.standard_normal((n, 2))
    # random points make slivers: the largest move that inverts none of them
    step = next(s for s in 0.2 * 0.5 ** np.arange(40) if np.all(signed_areas(points + s * spacing * noise, cells) > 0))
    moved = points + step * spacing * noise
    triangulation = moved_and_checked(points, moved)
    assert triangulation.rebuilds == 1


def test_lattice_jiggled_like_distmesh():
    """The first DistMesh moves: a cocircular lattice, every point nudged a little, hull points included."""
    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.02)
    rng = np.random.default_rng(4)
    moved = points + 0.002 * rng.standard_normal(points.shape)
    triangulation = moved_and_checked(points, moved)
    assert triangulation.flips > 0


def test_hull_vertex_moving_inwards_leaves_the_hull():
    angles = np.linspace(0, 2 * np.pi, 32, endpoint=False)
    points = np.vstack(
        [np.column_stack([np.cos(angles), np.sin(angles)]), 0.3 * np.random.default_rng(5).random((20, 2))]
    )
    moved = points.copy()
    moved[0] *= 0.9  # a hull vertex drops inside the hull of its two neighbours
    assert orient_exact(moved[31], moved[0], moved[1]) < 0  # clockwise turn: no longer convex there
    moved_and_checked(points, moved)


def test_collinear_hull_points_sliding_along_a_side():
    """Water domains have straight open boundaries: points on a hull side, sliding and rounding."""
    side = np.linspace(0, 1, 41)
    square = np.unique(
        np.vstack(
            [
                np.column_stack([side, 0 * side]),
                np.column_stack([side, 0 * side + 1]),
                np.column_stack([0 * side, side]),
                np.column_stack([0 * side + 1, side]),
            ]
        ),
        axis=0,
    )
    inner = 0.05 + 0.9 * np.random.default_rng(6).random((300, 2))
    points = np.vstack([square, inner])
    moved = points.copy()
    on_bottom = (points[:, 1] == 0) & (points[:, 0] > 0) & (points[:, 0] < 1)
    moved[on_bottom, 0] += 0.004
    moved[on_bottom, 1] = np.where(np.arange(on_bottom.sum()) % 2, 1e-17, -1e-17)  # rounding off the side
    moved_and_checked(points, moved)


def test_inverted_cell_falls_back_to_a_rebuild():
    rng = np.random.default_rng(7)
    points = rng.random((200, 2))
    moved = points.copy()
    moved[:20] = rng.random((20, 2))  # jumps across many cells
    triangulation = moved_and_checked(points, moved, expect_flips=False)
    assert triangulation.rebuilds == 2


def test_fold_that_keeps_cells_counter_clockwise_is_caught():
    """The area test: a triangulation whose cells all stay counter-clockwise but cover the hull twice."""
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    cells = np.array([[0, 1, 3], [0, 3, 2], [0, 1, 3]])  # the first cell counted twice
    infinite = 4
    assert kernel.covered_area_mismatch(
        points, np.vstack([cells, [[1, 0, infinite], [3, 1, infinite], [2, 3, infinite], [0, 2, infinite]]]), infinite
    ) == pytest.approx(0.5)


def lawson_one_stack(points, cells, neighbors, infinite):
    """Lawson flips in the order of one stack filled with every edge, from its cell of smaller index."""
    work = kernel.workspace()
    stack = [3 * t + k for t in range(len(cells)) for k in range(3) if t < neighbors[t, k]]
    flips = 0
    while stack:
        t1, k = divmod(stack.pop(), 3)
        if kernel._not_locally_delaunay(points, cells, neighbors, t1, k, infinite, work):
            flips += 1
            t2 = kernel.flip_edge(cells, neighbors, t1, k)
            stack += [3 * t1, 3 * t1 + 2, 3 * t2, 3 * t2 + 1]
    return flips


def test_lawson_flips_in_the_order_of_one_stack():
    """With cocircular quads left the flip order picks among Delaunay triangulations: the order is pinned."""
    grid = np.stack(np.meshgrid(np.arange(16), np.arange(16)), axis=-1).reshape(-1, 2) / 16.0
    grid = np.ascontiguousarray(grid[kernel.hilbert_order(grid, 16, 64)])
    status, cells, neighbors, _ = kernel.triangulate(grid)
    assert status == kernel.OK
    n = len(grid)
    rng = np.random.default_rng(0)
    moved = grid.copy()
    some = rng.random(n) < 0.3
    moved[some] += rng.integers(-2, 3, size=(np.count_nonzero(some), 2)) / 256.0  # still on a finer lattice
    real = cells[(cells < n).all(axis=1)]
    assert all(orient_exact(*moved[cell]) > 0 for cell in real)  # flips need a valid triangulation
    expected_cells, expected_neighbors = cells.copy(), neighbors.copy()
    expected = lawson_one_stack(moved, expected_cells, expected_neighbors, n)
    assert expected > 0
    # restore_delaunay flips only from the edges its parallel scan found, in the same order
    restored_cells, restored_neighbors, held = cells.copy(), neighbors.copy(), grid.copy()
    marked = np.empty(len(cells), dtype=np.uint8)
    inverted = kernel.unsettled_edges(moved, restored_cells, restored_neighbors, n, marked)
    status, flips = kernel.restore_delaunay(
        moved.copy(), held, restored_cells, restored_neighbors, n, 10 * len(cells), marked, inverted
    )
    assert (status, flips) == (kernel.OK, expected)
    np.testing.assert_array_equal(held, moved)
    np.testing.assert_array_equal(restored_cells, expected_cells)
    np.testing.assert_array_equal(restored_neighbors, expected_neighbors)
    assert kernel._lawson(moved, cells, neighbors, n, 10 * len(cells), kernel.workspace()) == expected
    np.testing.assert_array_equal(cells, expected_cells)
    np.testing.assert_array_equal(neighbors, expected_neighbors)


def jiggled_triangulation(n, jump, seed):
    """Random points, their triangulation and the points moved by up to ``jump`` spacings (cells invert)."""
    rng = np.random.default_rng(seed)
    points = np.ascontiguousarray(rng.random((n, 2)))
    status, cells, neighbors, _ = kernel.triangulate(points)
    assert status == kernel.OK
    return points, cells, neighbors, points + jump / np.sqrt(n) * rng.standard_normal((n, 2))


@settings(max_examples=25, deadline=None)
@given(n=st.integers(3, 9000), jump=st.floats(0.0, 2.0), seed=st.integers(0, 2**16))
def test_scan_marks_exactly_the_edges_to_flip_and_counts_inverted_cells(n, jump, seed):
    """The parallel scan against one edge at a time: 9000 points span several of its tasks."""
    _, cells, neighbors, moved = jiggled_triangulation(n, jump, seed)
    marked = np.full(len(cells), 255, dtype=np.uint8)
    inverted = kernel.unsettled_edges(moved, cells, neighbors, n, marked)
    work = kernel.workspace()
    expected = [
        sum(
            1 << k
            for k in range(3)
            if t < neighbors[t, k] and kernel._not_locally_delaunay(moved, cells, neighbors, t, k, n, work)
        )
        for t in range(len(cells))
    ]
    real = (cells < n).all(axis=1)
    flagged = np.array([r and kernel.orient(moved, *cell, work) <= 0 for r, cell in zip(real, cells, strict=True)])
    np.testing.assert_array_equal(marked, np.array(expected) + kernel._INVERTED * flagged)
    assert inverted == flagged.sum()


@settings(max_examples=25, deadline=None)
@given(n=st.integers(3, 3000), jump=st.floats(0.0, 3.0), seed=st.integers(0, 2**16))
def test_moves_held_back_locally_leave_no_cell_inverted_and_marks_fresh(n, jump, seed):
    """Holding back only around inverted cells: every cell counter-clockwise after, marks as a new scan's."""
    held, cells, neighbors, wanted = jiggled_triangulation(n, jump, seed)
    moved = wanted.copy()
    marked = np.empty(len(cells), dtype=np.uint8)
    inverted = kernel.unsettled_edges(moved, cells, neighbors, n, marked)
    back = np.zeros(n + 1, dtype=bool)
    cell_of = np.full(n, -1)
    count = kernel._hold_back_inverting_moves(
        moved, held, cells, neighbors, n, back, marked, cell_of, kernel.workspace()
    )
    assert (count > 0) == (inverted > 0) and count == back.sum()
    np.testing.assert_array_equal(moved[back[:n]], held[back[:n]])
    np.testing.assert_array_equal(moved[~back[:n]], wanted[~back[:n]])
    assert all(cell_of[v] >= 0 and v in cells[cell_of[v]] for v in np.flatnonzero(back[:n]))
    fresh = np.empty_like(marked)
    assert kernel.unsettled_edges(moved, cells, neighbors, n, fresh) == 0
    np.testing.assert_array_equal(marked, fresh)


def test_covered_area_summed_over_several_tasks():
    """Cells of many scan tasks: a Delaunay triangulation covers its hull once; a duplicated cell shows."""
    points = np.ascontiguousarray(np.random.default_rng(8).random((20000, 2)))
    status, cells, _, _ = kernel.triangulate(points)
    assert status == kernel.OK and len(cells) > 4 * kernel._SCAN_CELLS
    n = len(points)
    assert kernel.covered_area_mismatch(points, cells, n) < 1e-12
    real = np.flatnonzero((cells < n).all(axis=1))
    twice = np.vstack([cells, cells[real[len(real) // 2]]])
    a, b, c = points[twice[-1]]
    area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    hull = ConvexHull(points).volume
    assert kernel.covered_area_mismatch(points, twice, n) == pytest.approx(2 * area / (2 * hull), rel=1e-6)


def triangle_set(cells):
    return set(map(tuple, np.sort(cells, axis=1).tolist()))


def test_framed_triangulation_moves_adds_and_removes_without_rebuilding():
    """The generator's use: every point interior (a far frame), so any point can move, come or go locally."""
    from terramesh.generation.triangulate import Triangulation

    rng = np.random.default_rng(8)
    points = rng.random((3000, 2))
    triangulation = Triangulation(points, frame=True)
    moved = points + 0.004 * rng.standard_normal(points.shape)  # enough to invert some random cells
    assert not np.all(signed_areas(moved, delaunay_with_neighbors(points)[0]) > 0)
    assert triangulation.move_points(moved)
    added = rng.random((80, 2))
    triangulation.add_points(added)
    everything = np.vstack([moved, added])
    doomed = rng.choice(len(everything), 400, replace=False)
    triangulation.remove_points(doomed)
    remaining = np.delete(everything, doomed, axis=0)
    assert triangulation.rebuilds == 1
    np.testing.assert_array_equal(triangulation.positions, remaining)
    cells, neighbors = triangulation.cells_and_neighbors()
    # the Delaunay cells of the points, less flat ones along the hull that the frame replaces
    reference = triangle_set(delaunay_with_neighbors(remaining)[0])
    ours = triangle_set(cells)
    assert ours <= reference and len(reference - ours) < 0.01 * len(reference)
    assert np.all(signed_areas(remaining, cells) > 0)
    np.testing.assert_array_equal(neighbors, cell_neighbor_table(cells))


@pytest.mark.parametrize("pairs", [5, 20])
def test_vertices_trading_places_are_followed_without_rebuilding(pairs):
    """Pinned: on a jagged coastline a point was projected exactly onto the vertex where a neighbour
    had been, while the neighbour moved off; both moves invert cells, so both are held back, and
    putting the first in again while the second still sat at its old place collided (a rebuild)."""
    from terramesh.generation.triangulate import Triangulation

    rng = np.random.default_rng(9)
    points = rng.random((2000, 2))
    triangulation = Triangulation(points, frame=True)
    cells, _ = triangulation.cells_and_neighbors()
    moved = points.copy()
    taken = set()
    for a, b, _ in cells[rng.permutation(len(cells))]:
        if len(taken) == 2 * pairs:
            break
        if a in taken or b in taken:
            continue
        taken |= {a, b}
        moved[a] = points[b]  # exactly onto b's old place...
        moved[b] = points[a] + 0.1 * (points[b] - points[a])  # ...while b moves most of the way to a's
    assert triangulation.move_points(moved)
    assert triangulation.rebuilds == 1
    np.testing.assert_array_equal(triangulation.positions, moved)
    cells, neighbors = triangulation.cells_and_neighbors()
    assert np.all(signed_areas(moved, cells) > 0)
    reference = triangle_set(delaunay_with_neighbors(moved)[0])
    ours = triangle_set(cells)
    assert ours <= reference and len(reference - ours) < 0.01 * len(reference)
    np.testing.assert_array_equal(neighbors, cell_neighbor_table(cells))


@settings(deadline=None, max_examples=40)
@given(seed=st.integers(0, 2**32 - 1), share=st.floats(0.02, 0.7), lattice=st.booleans())
def test_removal_leaves_every_circumcircle_empty(seed, share, lattice):
    """Removal tests for flips only the edges of the cells around the removed vertices (an edge
    between unchanged cells keeps its quad): on random points and on a lattice, where a removed
    point leaves its six neighbours on one circle, every circumcircle is still empty."""
    rng = np.random.default_rng(seed)
    points, triangulation = _removal_case(rng, lattice, 0.05, 500)
    doomed = rng.choice(len(points), max(1, int(share * len(points))), replace=False)
    triangulation.remove_points(doomed)
    remaining, cells = _removed_locally(points, triangulation, doomed)
    assert_empty_circumcircles(remaining, cells, np.ones(len(remaining), dtype=bool))


def _removal_case(rng, lattice, spacing, n_random):
    """A lattice ``spacing`` apart or ``n_random`` random points in the unit square, and their framed triangulation."""
    from terramesh.generation.triangulate import Triangulation

    if lattice:
        points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), spacing)
    else:
        points = rng.random((n_random, 2))
    return points, Triangulation(points, frame=True)


def _removed_locally(points, triangulation, doomed):
    """The points left and the cells, checked: no rebuild, counter-clockwise, a consistent neighbour table."""
    assert triangulation.rebuilds == 1
    remaining = np.delete(points, doomed, axis=0)
    cells, neighbors = triangulation.cells_and_neighbors()
    assert np.all(signed_areas(remaining, cells) > 0)
    np.testing.assert_array_equal(neighbors, cell_neighbor_table(cells))
    return remaining, cells


@settings(deadline=None, max_examples=10)
@given(seed=st.integers(0, 2**32 - 1), count=st.integers(1, 10), lattice=st.booleans())
def test_a_few_removed_vertices_are_found_by_walks_as_a_pass_over_the_cells_would(seed, count, lattice):
    """The removal starts at the highest-numbered cell of each vertex: walked to when they are few."""
    rng = np.random.default_rng(seed)
    points, triangulation = _removal_case(rng, lattice, 0.007, 20_000)
    held, cells, neighbors = triangulation._held, triangulation._cells, triangulation._neighbors
    assert count * kernel._WALK_STEPS * np.sqrt(len(cells)) < len(cells)  # the walks, not the pass
    doomed = np.zeros(len(held), dtype=bool)
    picked = triangulation._offset + rng.choice(len(points), count, replace=False)
    doomed[picked] = True
    found = kernel._cells_of(held, cells, neighbors, doomed, len(held), np.empty(kernel.WORK_SIZE))
    highest = {v: int(np.flatnonzero((cells == v).any(axis=1)).max()) for v in picked}
    assert {v: int(found[v]) for v in picked} == highest
    assert np.all(found[~doomed] == -1)
    triangulation.remove_points(picked - triangulation._offset)
    remaining, cells = _removed_locally(points, triangulation, picked - triangulation._offset)
    if not lattice:  # general position: one Delaunay triangulation, but for the cells the frame takes at the hull
        ours, reference = triangle_set(cells), triangle_set(Delaunay(remaining).simplices)
        assert ours <= reference and len(reference - ours) < 0.01 * len(reference)


def test_removal_of_most_points_and_of_hull_points():
    from terramesh.generation.triangulate import Triangulation

    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), 0.05)
    unframed = Triangulation(points)
    unframed.remove_points([0])  # a hull vertex: not removable locally, so rebuilt
    assert unframed.rebuilds == 2
    framed = Triangulation(points, frame=True)
    kept = [
        int(np.argmin(np.sum((points - centre) ** 2, axis=1))) for centre in ([0.5, 0.5], [0.56, 0.5], [0.52, 0.55])
    ]
    framed.remove_points(np.setdiff1d(np.arange(len(points)), kept))
    assert framed.rebuilds == 1
    np.testing.assert_array_equal(framed.positions, points[np.sort(kept)])
    cells, _ = framed.cells_and_neighbors()
    assert len(cells) == 1 and set(cells[0]) == {0, 1, 2}
