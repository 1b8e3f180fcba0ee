import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import GeometryError


@st.composite
def star_polygons(draw):
    """Random simple star-shaped polygons (with an optional hole) and query points."""
    n = draw(st.integers(3, 40))
    radii = draw(st.lists(st.floats(0.5, 2.0), min_size=n, max_size=n))
    angles = np.sort(draw(st.lists(st.floats(0, 2 * np.pi), min_size=n, max_size=n, unique=True)))
    if np.any(np.diff(np.concatenate([angles, [angles[0] + 2 * np.pi]])) < 1e-3):
        angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = np.column_stack([np.cos(angles), np.sin(angles)]) * np.array(radii)[:, None]
    rings = [ring]
    if draw(st.booleans()):
        rings.append(0.2 * np.array([[1, 0], [0, 1], [-1, 0], [0, -1]], dtype=float))
    queries = np.array(draw(st.lists(st.tuples(st.floats(-2.5, 2.5), st.floats(-2.5, 2.5)), min_size=1, max_size=30)))
    return rings, queries


@settings(max_examples=60, deadline=None)
@given(star_polygons())
def test_polygon_distance_matches_shapely(case):
    rings, queries = case
    if not shapely.is_simple(shapely.multilinestrings([shapely.linearrings(r) for r in rings])):
        with pytest.raises(GeometryError):
            tm.geometry.Polygon(rings)
        return
    polygon = tm.geometry.Polygon(rings)
    # even-odd rule: the second ring is a hole when inside the first, a separate part when not
    reference = shapely.Polygon(rings[0])
    for ring in rings[1:]:
        reference = shapely.symmetric_difference(reference, shapely.Polygon(ring))
    points = shapely.points(queries)
    expected = shapely.distance(reference.boundary, points)
    inside = shapely.contains(reference, points)
    got = polygon.distance(queries)
    np.testing.assert_allclose(np.abs(got), expected, rtol=1e-2, atol=1e-12)
    near = expected < 0.05
    np.testing.assert_allclose(np.abs(got[near]), expected[near], atol=1e-12)
    clear = expected > 1e-9
    assert np.all((got[clear] < 0) == inside[clear])


def test_even_odd_rule_with_island_in_hole():
    square = [(0, 0), (4, 0), (4, 4), (0, 4)]
    hole = [(1, 1), (3, 1), (3, 3), (1, 3)]
    island = [(1.5, 1.5), (2.5, 1.5), (2.5, 2.5), (1.5, 2.5)]
    polygon = tm.geometry.Polygon([square, hole, island])
    np.testing.assert_allclose(polygon.distance([(0.5, 2), (1.2, 2), (2, 2)]), [-0.5, 0.2, -0.5])


def test_many_vertices_stay_fast_and_exact():
    angles = np.linspace(0, 2 * np.pi, 20000, endpoint=False)
    circle = tm.geometry.Polygon(np.column_stack([np.cos(angles), np.sin(angles)]))
    points = np.random.default_rng(0).uniform(-1.1, 1.1, (20000, 2))
    exact = np.hypot(points[:, 0], points[:, 1]) - 1
    near = np.abs(exact) < 0.05
    # the polygon is inscribed in the circle: differences up to the sagitta (1.3e-8)
    np.testing.assert_allclose(circle.distance(points[near]), exact[near], atol=2e-8)


@pytest.mark.parametrize(
    "rings, message",
    [
        ([], "empty"),
        ([[(0, 0), (1, 1), (1, 0), (0, 1)]], r"self-intersect or touch each other \(near \(0.5, 0.5\)\)"),
        ([[(0, 0), (1, 0)]], "three distinct"),
        ([[(0, 0), (1, 0), (np.nan, 1)]], "non-finite"),
        ([[(0, 0), (2, 0), (2, 2), (0, 2)], [(1, 1), (3, 1), (3, 3)]], r"touch each other \(near \(2, [12]\)\)"),
    ],
)
def test_bad_polygons_raise(rings, message):
    with pytest.raises(GeometryError, match=message):
        tm.geometry.Polygon(rings)


def test_from_shapely_rejects_invalid_and_empty():
    with pytest.raises(GeometryError, match="empty"):
        tm.geometry.Polygon.from_shapely(shapely.Polygon())
    bowtie = shapely.Polygon([(0, 0), (1, 1), (1, 0), (0, 1)])
    with pytest.raises(GeometryError, match="Self-intersection"):
        tm.geometry.Polygon.from_shapely(bowtie)
    with pytest.raises(GeometryError, match="Polygon"):
        tm.geometry.Polygon.from_shapely(shapely.Point(0, 0))


@st.composite
def rings_and_points(draw):
    """A star-shaped shell, maybe a hole in it and an island apart, each turned either way; points near and far."""
    seed = draw(st.integers(0, 100_000))
    rng = np.random.default_rng(seed)

    def star(center, scale, n):
        angles = (np.arange(n) + rng.uniform(-0.4, 0.4, n)) * (2 * np.pi / n)  # gaps below 1.8 steps
        radii = scale * rng.uniform(0.6, 1.0, n)
        ring = np.column_stack([center[0] + radii * np.cos(angles), center[1] + radii * np.sin(angles)])
        return ring if rng.random() < 0.5 else ring[::-1]

    rings = [star((0, 0), 1.0, draw(st.integers(6, 60)))]  # keeps a disk of radius 0.35 clear
    if draw(st.booleans()):
        rings.append(star((0, 0), 0.2, draw(st.integers(3, 20))))
    if draw(st.booleans()):
        rings.append(star((2.5, 0), 0.5, draw(st.integers(3, 20))))
    vertices = np.concatenate(rings)
    near = vertices + 10.0 ** rng.uniform(-9, -1, (len(vertices), 1)) * rng.standard_normal((len(vertices), 2))
    middles = 0.5 * (vertices + np.concatenate([np.roll(r, -1, axis=0) for r in rings]))
    beside = middles + 10.0 ** rng.uniform(-9, -1, (len(middles), 1)) * rng.standard_normal((len(middles), 2))
    far = rng.uniform(-4, 4, (200, 2))
    return rings, np.vstack([near, beside, far])


@settings(max_examples=60, deadline=None)
@given(rings_and_points())
def test_the_sign_from_the_nearest_segment_is_point_in_polygon(case):
    rings, points = case
    polygon = tm.geometry.Polygon(rings)
    distance = polygon.distance(points)
    contains = shapely.contains_xy(polygon.geometry, points[:, 0], points[:, 1])
    clear = np.abs(distance) > 1e-12  # on the boundary either sign is right
    np.testing.assert_array_equal((distance < 0)[clear], contains[clear])
    for tolerance in (0.0, 1e-6, 0.05):
        expected = contains & (np.abs(distance) > tolerance)
        decided = np.abs(np.abs(distance) - tolerance) > 1e-12
        np.testing.assert_array_equal(polygon.inside(points, tolerance)[decided], expected[decided])


@settings(max_examples=60, deadline=None)
@given(rings_and_points(), st.sampled_from([1e-6, 0.01, 0.3, 3.0]))
def test_distance_within_is_the_distance_clipped_at_the_limit(case, limit):
    """The seeding's distances: exact below the limit, the limit with the right sign beyond it."""
    rings, points = case
    polygon = tm.geometry.Polygon(rings)
    distance = polygon.distance(points)
    within = polygon.distance_within(points, limit)
    near = np.abs(distance) < 0.99 * limit  # the far distances are within 1 %
    np.testing.assert_allclose(within[near], distance[near], rtol=0, atol=1e-12)
    far = np.abs(distance) > 1.01 * limit
    np.testing.assert_array_equal(within[far], np.sign(distance[far]) * limit)
    assert np.all(np.abs(within) <= limit)


@settings(max_examples=60, deadline=None)
@given(rings_and_points(), st.sampled_from([1e-6, 0.01, 0.3, 3.0]))
def test_distance_and_nearest_within_a_limit(case, limit):
    """Exact where the search reaches (within the limit at least), a bound of at least the limit beyond it."""
    rings, points = case
    polygon = tm.geometry.Polygon(rings)
    distance, nearest = polygon.distance_and_nearest(points)
    within, near_point = polygon.distance_and_nearest(points, limit)
    found = ~np.isnan(near_point[:, 0])
    np.testing.assert_allclose(within[found], distance[found], rtol=0, atol=1e-12)
    # beyond: between the limit and the distance (which the search without a limit gives within 1 % above)
    assert np.all(np.abs(within[~found]) >= limit) and np.all(np.abs(within[~found]) <= np.abs(distance[~found]))
    known = found & ~np.isnan(nearest[:, 0])  # the search without a limit reaches less far than a large one
    np.testing.assert_array_equal(near_point[known], nearest[known])
    reached = found & ~np.isnan(near_point[:, 0])
    np.testing.assert_allclose(np.hypot(*(near_point - points)[reached].T), np.abs(distance[reached]), atol=1e-12)
    assert found[np.abs(distance) < 0.99 * limit].all()
    np.testing.assert_array_equal(np.sign(within), np.sign(distance))
    np.testing.assert_array_equal(np.clip(within, -limit, limit), polygon.distance_within(points, limit))


def test_distance_within_beyond_the_segment_grid_reach():
    """Points many grid cells from every segment take the limit, signed by point in polygon."""
    side = np.linspace(0.0, 10.0, 101)[:-1]
    square = np.concatenate(
        [
            np.column_stack([side, 0 * side]),
            np.column_stack([10 + 0 * side, side]),
            np.column_stack([10 - side, 10 + 0 * side]),
            np.column_stack([0 * side, 10 - side]),
        ]
    )
    polygon = tm.geometry.Polygon(square)
    within = polygon.distance_within([(5.0, 5.0), (25.0, 5.0), (5.0, 0.05)], 0.5)
    np.testing.assert_allclose(within, [-0.5, 0.5, -0.05], atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(rings_and_points())
def test_nearest_points_found_with_the_distance_are_the_projection(case):
    """What the generator projects outside points onto: the same as project() near the boundary, NaN only far."""
    rings, points = case
    polygon = tm.geometry.Polygon(rings)
    distance, nearest = polygon.distance_and_nearest(points)
    np.testing.assert_array_equal(distance, polygon.distance(points))
    known = ~np.isnan(nearest[:, 0])
    np.testing.assert_array_equal(nearest[known], polygon.project(points[known]))
    np.testing.assert_allclose(np.hypot(*(nearest[known] - points[known]).T), np.abs(distance[known]), atol=1e-12)
    assert np.all(np.isnan(nearest[~known]))
    near = np.abs(distance) < 1e-2  # within the segment grid's reach of a boundary 0.1-1 across
    assert known[near].all()


def test_points_on_the_boundary_are_left_to_point_in_polygon_and_are_not_inside():
    """The crossing count cannot tell a point on a segment: the search for the nearest segment decides it."""
    rng = np.random.default_rng(4)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 40))
    ring = np.column_stack([np.cos(angles), np.sin(angles)]) * rng.uniform(0.7, 1.0, (40, 1))
    polygon = tm.geometry.Polygon([ring, 0.3 * ring[::4]])  # a hole
    on_boundary = np.vstack([ring, 0.3 * ring[::4], [0.5 * (ring[0] + ring[1])]])
    undecided = polygon._segments.sides(on_boundary, polygon._centre_inside()) == 0
    assert undecided[: len(ring)].all()  # exactly on a vertex: a turn of zero
    assert not polygon.inside(on_boundary[:-1], 0.0).any()
    # the rounded midpoint of a segment lies off it by a rounding (3e-17 here): the side it has, as shapely's exact test
    midpoint = on_boundary[-1:]
    contained = shapely.contains_xy(polygon.geometry, *midpoint.T)
    assert polygon.inside(midpoint, 0.0) == contained == (polygon.distance(midpoint) < 0)
    points = rng.uniform(-1.2, 1.2, (2000, 2))
    contains = shapely.contains_xy(polygon.geometry, points[:, 0], points[:, 1])
    np.testing.assert_array_equal(polygon.inside(points, 0.0), contains)
    np.testing.assert_array_equal(polygon.distance(points) < 0, contains)


@settings(max_examples=40, deadline=None)
@given(star_polygons(), st.sampled_from([5e5, 5e6, 1e8]))
def test_the_sign_holds_far_from_the_origin(case, offset):
    # UTM-like coordinates: a small hole's shoelace area cancelled to 0 from the raw products, the ring was
    # turned the wrong way and the hole's inside was inside the domain (318 cells outside a mesh)
    rings, queries = case
    shifted = [ring * 0.2 + offset for ring in rings]  # a small hole: 0.04 across
    if not shapely.is_simple(shapely.multilinestrings([shapely.linearrings(r) for r in shifted])):
        return
    polygon = tm.geometry.Polygon(shifted)
    reference = shapely.Polygon(shifted[0])
    for ring in shifted[1:]:
        reference = shapely.symmetric_difference(reference, shapely.Polygon(ring))
    at = queries * 0.2 + offset
    clear = shapely.distance(reference.boundary, shapely.points(at)) > 1e-6
    np.testing.assert_array_equal(
        (polygon.distance(at) < 0)[clear], shapely.contains(reference, shapely.points(at))[clear]
    )


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_query_points_are_named(bad):
    # distance and project raised SciPy's "'x' must be finite" from the KD-tree; inside said False
    square = tm.geometry.Polygon([(0, 0), (1, 0), (1, 1), (0, 1)])
    for query in (square.distance, square.project, square.inside, tm.geometry.Disk((0, 0), 1).distance):
        with pytest.raises(GeometryError, match=r"points must be finite: 1 of 2 have NaN or infinite .*index 1"):
            query([[0.5, 0.5], [bad, 0.5]])


@pytest.mark.parametrize(
    "ring", [[(0, 0), (1, 0), (1, 1), (0, 1), (0, 0), (0, 0)], [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0)]]
)
def test_a_repeated_closing_vertex_leaves_no_edge_of_no_length(ring):
    # [A, B, ..., A, A] (a water polygon joined from the boxes of a multiscale mesh) kept its last A: corners()
    # divided by a zero length (NumPy's RuntimeWarning out of build_multiscale)
    polygon = tm.geometry.Polygon([ring])
    assert polygon.rings[0].tolist() == [[0, 0], [1, 0], [1, 1], [0, 1]]
    assert len(polygon.corners()) == 4  # the tests turn the old warning into an error


def test_rings_touching_at_a_point_are_refused_with_advice_that_works():
    # a hole touching the shell at one point is valid to shapely: the advice, shapely.make_valid, changed nothing
    touching = shapely.Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], [[(0, 2), (1, 1.5), (1, 2.5)]])
    assert touching.is_valid
    with pytest.raises(GeometryError, match=r"touch at a point .* shapely\.buffer\(polygon, -d\)"):
        tm.geometry.Polygon.from_shapely(touching)
    parted = tm.geometry.Polygon.from_shapely(shapely.buffer(touching, -1e-6, join_style="mitre"))
    mesh = tm.generate_mesh(parted, 0.2, seed=0)
    assert tm.cleanup.mesh_problems(mesh, parted) == []


def test_corners_in_a_metric_are_the_corners_of_the_polygon_mapped_by_it():
    # a constant metric diag(1, 100) is the plane stretched 10 times along y: the corners it finds on a regular
    # octagon (135 degrees in the plane: none) are those of the stretched octagon, shrunk back
    turn = np.radians(np.arange(0, 360, 45))
    octagon = np.c_[np.cos(turn), np.sin(turn)]
    assert len(tm.geometry.Polygon(octagon).corners()) == 0
    squeezed = tm.geometry.Polygon(octagon).corners(metric=lambda p: np.tile(np.diag([1.0, 100.0]), (len(p), 1, 1)))
    stretched = tm.geometry.Polygon(octagon * [1.0, 10.0]).corners() / [1.0, 10.0]
    assert len(squeezed) > 0 and np.allclose(sorted(squeezed.tolist()), sorted(stretched.tolist()))


@pytest.mark.parametrize(("width", "bridged"), [(0.002, True), (0.04, False)])
def test_edges_across_a_thin_cut_are_found(width, bridged):
    # a cut h/25 wide is meshed straight across (the area covered changes by 0.1 %); one of h/1.25 is resolved
    cut = shapely.box(0, 0, 2, 1).difference(shapely.box(1 - width / 2, -0.1, 1 + width / 2, 0.8))
    domain = tm.geometry.Polygon.from_shapely(cut)
    mesh = tm.generate_mesh(domain, 0.05, seed=0)
    assert tm.cleanup.mesh_problems(mesh) == []  # the thin cut once left two boundary edges crossing
    edges = tm.mesh.topology.unique_edges(mesh.cells)
    indices, where = domain.bridged_edges(mesh.points, edges, 1e-5)
    a, b = mesh.points[edges[:, 0]], mesh.points[edges[:, 1]]
    across = (np.minimum(a[:, 0], b[:, 0]) < 1 - width / 2) & (np.maximum(a[:, 0], b[:, 0]) > 1 + width / 2)
    height = a[:, 1] + (1 - a[:, 0]) / np.where(across, b[:, 0] - a[:, 0], 1) * (b[:, 1] - a[:, 1])
    through = np.flatnonzero(across & (height < 0.8))
    assert set(indices.tolist()) <= set(through.tolist())
    if bridged:  # all but those near the cut's end, where the stretch cut off is short
        assert len(indices) >= 0.6 * len(through) >= 6
        assert np.allclose(where[:, 0], 1 - width / 2) and np.all((where[:, 1] > 0) & (where[:, 1] < 0.8))
    else:
        assert len(through) == 0 and len(indices) == 0


def test_bridged_edges_checks_its_edges():
    square = tm.geometry.Polygon([(0, 0), (1, 0), (1, 1), (0, 1)])
    points = [(0.2, 0.2), (0.8, 0.8)]
    indices, where = square.bridged_edges(points, np.empty((0, 2), dtype=int))
    assert indices.shape == (0,) and where.shape == (0, 2)
    assert square.bridged_edges(points, [(0, 1)])[0].tolist() == []
    with pytest.raises(GeometryError, match=r"edges refer to vertices 0..2, of 2 points"):
        square.bridged_edges(points, [(0, 2)])
    with pytest.raises(GeometryError, match=r"an \(e, 2\) array of vertex indices"):
        square.bridged_edges(points, [(0.0, 1.0)])


def test_an_edge_clipping_both_banks_of_a_channel_bridges_nothing():
    # the pair of crossings where it comes back in and leaves again was taken for a thin part of the outside
    channel = tm.geometry.Polygon(
        [(0, 0), (5.0, 0), (5.0, 0.02), (5.02, 0.02), (5.02, 0), (10, 0), (10, 0.1), (5.07, 0.1), (5.07, 0.08),
         (5.05, 0.08), (5.05, 0.1), (0, 0.1)]
    )  # fmt: skip
    indices, _ = channel.bridged_edges([(4.99, 0.005), (5.075, 0.0985)], [(0, 1)])
    assert indices.tolist() == []


@settings(max_examples=60, deadline=None)
@given(
    st.sampled_from(["crack", "spike"]),
    st.integers(-16, -3),
    st.floats(0, 2 * np.pi),
    st.sampled_from([(0.0, 0.0), (5e5, 4.2e6)]),
    st.integers(0, 2**32 - 1),
)
def test_the_sign_holds_at_a_needle_as_thin_as_a_rounding(kind, log_width, angle, offset, seed):
    # at a needle's tip the two normals cancel and their sum's direction was rounding; beside it the two
    # sides tied (the distances taken from coordinates rounded to 1e-9 at 4e6): 25 % of the points within
    # 0.5 of a 1e-9 crack at UTM coordinates, and 2-5 % of those of a 1e-15 needle at the origin, had the
    # wrong sign
    width = 10.0**log_width
    tip = (1.0, 1.0) if kind == "crack" else (3.0, 1.0)
    ring = np.array([(0, 0), (2, 0), (2, 1 - width / 2), tip, (2, 1 + width / 2), (2, 2), (0, 2)])
    turn = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    ring = ring @ turn.T + offset
    reference = shapely.Polygon(ring)
    if not reference.is_valid:  # a width below the coordinates' rounding closes the needle
        return
    polygon = tm.geometry.Polygon(ring)
    points = ring[3] + np.random.default_rng(seed).uniform(-0.5, 0.5, (500, 2))
    clear = shapely.distance(reference.boundary, shapely.points(points)) > 1e-6
    contains = shapely.contains_xy(reference, points[:, 0], points[:, 1])
    np.testing.assert_array_equal((polygon.distance(points) < 0)[clear], contains[clear])
    np.testing.assert_array_equal(polygon.inside(points)[clear], contains[clear])


def test_gentle_reflex_corners_of_an_outer_ring_and_of_a_hole():
    # a reflex vertex turns into the domain: on the outer ring a notch, on a hole a point of the hole poking out
    notch = [(0, 0), (4, 0), (4, 4), (2, 3.5), (0, 4)]  # (2, 3.5): inner angle 208 degrees
    arrow = [(1, 1), (3, 1), (2, 1.6)]  # a hole whose vertices are all convex for the hole, reflex for the domain
    polygon = tm.geometry.Polygon([notch, arrow])
    points, shorter_edge = polygon.gentle_reflex_corners()
    # the hole's corners turn by more than 60 degrees: corners(), not gentle
    assert points.tolist() == [[2.0, 3.5]]
    assert shorter_edge.tolist() == pytest.approx([np.hypot(2, 0.5)])
    assert polygon.gentle_reflex_corners(angle=150)[0].shape == (0, 2)  # 152 degrees between its edges
    # convex vertices are never gentle reflex corners, however gently they turn
    convex = tm.geometry.Polygon([(0, 0), (2, 0), (2, 1), (1, 1.3), (0, 1)])
    assert convex.gentle_reflex_corners()[0].shape == (0, 2)
