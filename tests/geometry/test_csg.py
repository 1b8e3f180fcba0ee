import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import GeometryError

points = st.tuples(st.floats(-2, 2), st.floats(-2, 2))


@given(points)
def test_csg_sign_matches_set_operations(point):
    a, b = tm.geometry.Disk((0, 0), 1), tm.geometry.Disk((0.8, 0), 0.7)
    da, db = a.distance([point])[0], b.distance([point])[0]
    assume_clear = min(abs(da), abs(db)) > 1e-9
    if not assume_clear:
        return
    assert ((a | b).distance([point])[0] < 0) == (da < 0 or db < 0)
    assert ((a & b).distance([point])[0] < 0) == (da < 0 and db < 0)
    assert ((a - b).distance([point])[0] < 0) == (da < 0 and db > 0)


@settings(max_examples=60, deadline=None)
@given(
    st.integers(0, 10_000),
    st.sampled_from(["union", "intersection", "difference"]),
    st.sampled_from([1e-6, 0.01, 0.3, 3.0]),
)
def test_distance_within_of_a_combination_is_its_distance_clipped(seed, operation, limit):
    """The operands' own clipped distances combined: a star polygon's fast path, exact where it matters."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(6, 60))
    angles = (np.arange(n) + rng.uniform(-0.4, 0.4, n)) * (2 * np.pi / n)
    radii = rng.uniform(0.6, 1.0, n)
    star = tm.geometry.Polygon(np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]))
    other = tm.geometry.Disk(rng.uniform(-0.5, 0.5, 2), rng.uniform(0.2, 0.8))
    domain = {"union": star | other, "intersection": star & other, "difference": star - other}[operation]
    on_star = shapely.get_coordinates(star.geometry.boundary.interpolate(rng.uniform(0, 1, 200), normalized=True))
    points = np.vstack(
        [
            on_star + 10.0 ** rng.uniform(-9, -1, (200, 1)) * rng.normal(size=(200, 2)),
            rng.uniform(-2, 2, (300, 2)),
        ]
    )
    distance = domain.distance(points)
    within = domain.distance_within(points, limit)
    assert np.all(np.abs(within) <= limit)
    np.testing.assert_array_equal(np.sign(within), np.sign(distance))
    near = np.abs(distance) < 0.99 * limit  # the star's far distances are within 1 % (Polygon.distance_within)
    np.testing.assert_allclose(within[near], distance[near], rtol=0, atol=1e-12)
    far = np.abs(distance) > 1.01 * limit
    np.testing.assert_array_equal(within[far], np.sign(distance[far]) * limit)


def test_bounding_boxes():
    a, b = tm.geometry.Rectangle((0, 0), (2, 1)), tm.geometry.Rectangle((1, -1), (3, 0.5))
    assert tm.geometry.Union([a, b]).bbox.tolist() == [[0, -1], [3, 1]]
    assert tm.geometry.Intersection([a, b]).bbox.tolist() == [[1, 0], [2, 0.5]]
    assert tm.geometry.Difference([a, b]).bbox.tolist() == [[0, 0], [2, 1]]


def test_difference_keeps_only_corners_on_its_boundary():
    plate = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (2, 1)), tm.geometry.Rectangle((1.5, -1), (3, 0.5))])
    corners = {tuple(c) for c in plate.corners().tolist()}
    assert (0.0, 0.0) in corners and (2.0, 1.0) in corners
    assert (2.0, 0.0) not in corners  # cut away


def test_empty_intersection_and_single_operand_raise():
    with pytest.raises(GeometryError, match="empty"):
        tm.geometry.Intersection([tm.geometry.Disk((0, 0), 1), tm.geometry.Disk((5, 0), 1)])
    with pytest.raises(GeometryError, match="at least two"):
        tm.geometry.Union([tm.geometry.Disk((0, 0), 1)])
    np.testing.assert_array_equal(tm.geometry.Disk((0, 0), 1).corners().shape, (0, 2))


# --- sharp edges of 3D combinations ---------------------------------------------------------------------

Box, Ball, Cylinder = tm.geometry.Box, tm.geometry.Ball, tm.geometry.Cylinder


def edge_ends(domain):
    """The reported edges as a set of frozensets of their two ends (exact coordinates)."""
    edges = domain.sharp_edges()
    assert not any(getattr(edge, "closed", False) for edge in edges)
    ends = [edge(np.array([0.0, 1.0])) for edge in edges]
    for edge, (start, end) in zip(edges, ends, strict=True):
        # straight: the middle is the mean of the ends, the coordinates constant along it exactly so
        middle = edge(np.array([0.5]))[0]
        np.testing.assert_allclose(middle, 0.5 * (start + end), atol=1e-15)
        assert np.sum(start == end) == 2 and np.all(middle[start == end] == start[start == end])
    return {frozenset((tuple(start), tuple(end))) for start, end in ends}


def segments(*pairs):
    return {frozenset((tuple(map(float, a)), tuple(map(float, b)))) for a, b in pairs}


def prism_edges(polygon, z0, z1):
    """The edges of a right prism over a polygon given as (x, y) corners in order."""
    ring = list(zip(polygon, polygon[1:] + polygon[:1], strict=True))
    return (
        segments(*[((x, y, z0), (x, y, z1)) for x, y in polygon])
        | segments(*[((*a, z0), (*b, z0)) for a, b in ring])
        | segments(*[((*a, z1), (*b, z1)) for a, b in ring])
    )


def test_l_shaped_union_reports_its_re_entrant_edge():
    ell = Box((0, 0, 0), (2, 1, 1)) | Box((0, 0, 0), (1, 2, 1))
    expected = prism_edges([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)], 0, 1)
    assert len(ell.sharp_edges()) == 18
    assert edge_ends(ell) == expected  # (1, 1, z) among them; no edge inside the shared faces x = 0, z = 0, z = 1
    corners = {tuple(c) for c in ell.corners().tolist()}
    assert corners == {p for edge in expected for p in edge}  # the 12 corners, not the operands' inside a face


def test_notch_cut_from_a_box_reports_its_edges():
    notched = Box((0, 0, 0), (2, 1, 1)) - Box((0.7, -0.1, 0.6), (1.3, 0.5, 1.1))
    # the box's edges but the front top one, which the notch splits in two, and the notch's eleven
    front_top = segments(((0, 0, 1), (2, 0, 1)))
    kept = {edge for edge in edge_ends(Box((0, 0, 0), (2, 1, 1))) if edge not in front_top}
    notch = segments(
        ((0, 0, 1), (0.7, 0, 1)), ((1.3, 0, 1), (2, 0, 1)),
        ((0.7, 0, 1), (0.7, 0, 0.6)), ((0.7, 0, 0.6), (1.3, 0, 0.6)), ((1.3, 0, 0.6), (1.3, 0, 1)),
        ((0.7, 0, 1), (0.7, 0.5, 1)), ((1.3, 0, 1), (1.3, 0.5, 1)), ((0.7, 0.5, 1), (1.3, 0.5, 1)),
        ((0.7, 0, 0.6), (0.7, 0.5, 0.6)), ((1.3, 0, 0.6), (1.3, 0.5, 0.6)), ((0.7, 0.5, 0.6), (1.3, 0.5, 0.6)),
        ((0.7, 0.5, 0.6), (0.7, 0.5, 1)), ((1.3, 0.5, 0.6), (1.3, 0.5, 1)),
    )  # fmt: skip
    assert edge_ends(notched) == kept | notch
    assert len(notched.sharp_edges()) == 24 and len(notched.corners()) == 16


def test_overlapping_boxes_report_the_edges_and_corners_they_create():
    both = Box((0, 0, 0), (1, 1, 1)) | Box((0.5, 0.4, 0.3), (1.5, 1.4, 1.3))
    edges = edge_ends(both)
    assert len(edges) == 30 and len(both.sharp_edges()) == 30
    # where a face of one meets a face of the other: x = 1 with y = 0.4 and with z = 0.3, and so on
    assert segments(((1, 0.4, 0.3), (1, 0.4, 1)), ((1, 0.4, 0.3), (1, 1, 0.3)), ((0.5, 1, 0.3), (0.5, 1, 1))) <= edges
    assert segments(((0.5, 0.4, 1), (0.5, 1, 1)), ((0.5, 0.4, 1), (1, 0.4, 1)), ((1, 1, 0.3), (0.5, 1, 0.3))) <= edges
    # the operands' edges only as far as they stay on the boundary: x = y = 1 below the other box
    assert segments(((1, 1, 0), (1, 1, 0.3))) <= edges
    assert not any((1.0, 1.0, 1.0) in edge for edge in edges)  # inside the other box
    corners = {tuple(c) for c in both.corners().tolist()}
    assert len(corners) == 20 and {(1.0, 0.4, 0.3), (0.5, 1.0, 1.0), (1.0, 1.0, 0.3)} <= corners
    assert np.abs(both.distance(both.corners())).max() <= 1e-15


def test_flat_and_tangent_meetings_make_no_edge():
    # two boxes making one: the shared face is inside, the coplanar faces are flat
    halves = Box((0, 0, 0), (1, 1, 1)) | Box((1, 0, 0), (2, 1, 1))
    assert edge_ends(halves) == prism_edges([(0, 0), (2, 0), (2, 1), (0, 1)], 0, 1)
    assert len(halves.corners()) == 8
    # a cylinder inscribed in a box touches four faces along lines: tangent, no edge
    inscribed = Box((0, 0, 0), (1, 1, 1)) | Cylinder((0.5, 0.5, 0.5), 0.5, 1.0, axis=(1, 0, 0))
    assert len(inscribed.sharp_edges()) == 12


@pytest.mark.parametrize(
    ("cutter", "circles"),
    [
        (Ball((0.5, 0.5, 1.0), 0.3), [(1.0, 0.3)]),  # a dent in the top face: one circle
        (Cylinder((0.5, 0.5, 0.5), 0.25, 2.0), [(0.0, 0.25), (1.0, 0.25)]),  # a hole through: its two rims
    ],
)
def test_round_cuts_report_circles_on_the_faces(cutter, circles):
    domain = Box((0, 0, 0), (1, 1, 1)) - cutter
    edges = domain.sharp_edges()
    loops = [edge for edge in edges if getattr(edge, "closed", False)]
    assert len(edges) == 12 + len(circles) and len(loops) == len(circles)
    for loop, (z, radius) in zip(sorted(loops, key=lambda e: e(np.array([0.0]))[0, 2]), circles, strict=True):
        points = loop(np.linspace(0.0, 1.0, 101))
        assert np.all(points[:, 2] == z)  # on the face exactly
        np.testing.assert_allclose(np.hypot(points[:, 0] - 0.5, points[:, 1] - 0.5), radius, rtol=1e-14)
        np.testing.assert_allclose(points[0], points[-1], atol=1e-15)
        # the whole circle, once round
        angle = np.unwrap(np.arctan2(points[:, 1] - 0.5, points[:, 0] - 0.5))
        assert abs(angle[-1] - angle[0]) == pytest.approx(2 * np.pi)


def test_ball_across_a_box_edge_splits_it_and_gives_arcs_ending_on_it():
    domain = Box((0, 0, 0), (1, 1, 1)) - Ball((1.0, 0.5, 1.0), 0.4)
    edges = domain.sharp_edges()
    chord = [np.linalg.norm(e(np.array([0.5]))[0] - e(np.array([0.0, 1.0])).mean(axis=0)) for e in edges]
    arcs = [edge for edge, off in zip(edges, chord, strict=True) if off > 0.1]
    assert len(edges) == 15 and len(arcs) == 2  # 11 whole box edges, the cut one's two ends, two half circles
    for arc in arcs:
        points = arc(np.linspace(0.0, 1.0, 65))
        np.testing.assert_allclose(np.linalg.norm(points - (1.0, 0.5, 1.0), axis=1), 0.4, rtol=1e-14)
        ends = points[[0, -1]][np.argsort(points[[0, -1], 1])]
        np.testing.assert_allclose(ends, [(1.0, 0.1, 1.0), (1.0, 0.9, 1.0)], rtol=0, atol=1e-15)  # solved, not sampled
        assert np.all(ends[:, [0, 2]] == 1.0)  # on both faces exactly
    corners = domain.corners()
    for corner in [(1.0, 0.1, 1.0), (1.0, 0.9, 1.0), (1.0, 1.0, 1.0)]:
        assert np.min(np.linalg.norm(corners - corner, axis=1)) <= 1e-15


def test_curved_intersections_lie_on_both_surfaces():
    domain = (Cylinder((0, 0, 0), 0.5, 2.0) | Cylinder((0, 0, 0), 0.3, 2.0, axis=(1, 0, 0))) - Ball((0, 0, 1), 0.4)
    edges = domain.sharp_edges()
    assert edges
    for edge in edges:
        points = edge(np.linspace(0.0, 1.0, 257))
        assert np.abs(domain.distance(points)).max() <= 1e-12


def test_sharp_edges_of_2d_combinations_are_none():
    assert tm.geometry.Union([tm.geometry.Disk((0, 0), 1), tm.geometry.Disk((1, 0), 1)]).sharp_edges() == []


def _as_set(points, digits=9):
    return {tuple(p) for p in np.round(np.asarray(points), digits).tolist()}


def test_crossing_boundaries_make_corners_in_2d():
    rectangle, hole = tm.geometry.Rectangle((0, 0), (2, 1)), tm.geometry.Disk((1.0, 0.0), 0.3)
    cut = rectangle - hole  # the hole's circle cuts the rectangle's bottom side
    assert _as_set(cut.corners()) == {(0, 0), (2, 0), (2, 1), (0, 1), (0.7, 0), (1.3, 0)}
    assert np.all(cut.corners()[:, 1] >= 0)  # on the side exactly, not a rounding below it
    ell = tm.geometry.Rectangle((0, 0), (2, 1)) | tm.geometry.Rectangle((1, 0.5), (3, 2))
    assert {(1.0, 1.0), (2.0, 0.5)} <= _as_set(ell.corners())  # the re-entrant corners
    lens = tm.geometry.Disk((0, 0), 1) & tm.geometry.Disk((1, 0), 1)
    np.testing.assert_allclose(lens.corners(), [[0.5, -np.sqrt(3) / 2], [0.5, np.sqrt(3) / 2]], atol=1e-12)
    # touching or nearly tangent circles: the boundary turns by less than SHARP_ANGLE there
    assert len((tm.geometry.Disk((0, 0), 1) | tm.geometry.Disk((2, 0), 1)).corners()) == 0
    assert len((tm.geometry.Disk((0, 0), 1) | tm.geometry.Disk((1.9999, 0), 1)).corners()) == 0


def test_meshes_keep_the_corners_where_boundaries_cross():
    cut = tm.geometry.Rectangle((0, 0), (2, 1)) - tm.geometry.Disk((1.0, 0.0), 0.3)
    ell = tm.geometry.Rectangle((0, 0), (2, 1)) | tm.geometry.Rectangle((1, 0.5), (3, 2))
    for domain, created in [(cut, [(0.7, 0.0), (1.3, 0.0)]), (ell, [(1.0, 1.0), (2.0, 0.5)])]:
        mesh = tm.generate_mesh(domain, 0.1, seed=0)
        assert tm.cleanup.mesh_problems(mesh) == []
        nearest = np.linalg.norm(mesh.points[:, None] - np.array(created)[None], axis=2).min(axis=0)
        assert np.all(nearest == 0)  # vertices exactly there (before: 0.02 to 0.03 away)
    area = tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum()
    assert area == pytest.approx(4.5, abs=1e-9)  # the union's polygon exactly


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.integers(0, 60), min_size=4, max_size=4, unique=True),
    st.lists(st.integers(0, 60), min_size=4, max_size=4, unique=True),
    st.sampled_from(["union", "difference", "intersection"]),
)
def test_crossings_of_two_rectangles_are_found_exactly(xs, ys, operation):
    """Against the crossings of their sides computed by hand (distinct coordinates: sides cross or miss)."""
    xs, ys = np.array(xs) / 10, np.array(ys) / 10
    boxes = [(min(xs[0], xs[1]), min(ys[0], ys[1]), max(xs[0], xs[1]), max(ys[0], ys[1]))]
    boxes.append((min(xs[2], xs[3]), min(ys[2], ys[3]), max(xs[2], xs[3]), max(ys[2], ys[3])))
    a, b = (tm.geometry.Rectangle(box[:2], box[2:]) for box in boxes)
    if operation == "intersection" and (
        max(boxes[0][0], boxes[1][0]) >= min(boxes[0][2], boxes[1][2])
        or max(boxes[0][1], boxes[1][1]) >= min(boxes[0][3], boxes[1][3])
    ):
        return  # empty
    domain = {"union": lambda: a | b, "difference": lambda: a - b, "intersection": lambda: a & b}[operation]()
    expected = []
    for first, second in [(boxes[0], boxes[1]), (boxes[1], boxes[0])]:
        for x in (first[0], first[2]):  # a vertical side of one, a horizontal side of the other
            for y in (second[1], second[3]):
                if first[1] < y < first[3] and second[0] < x < second[2]:
                    expected.append((x, y))
        expected += [(x, y) for x in (first[0], first[2]) for y in (first[1], first[3])]
    expected = np.array(expected)
    scale = np.max(domain.bbox[1] - domain.bbox[0])
    expected = expected[np.abs(domain.distance(expected)) < 1e-10 * scale]
    assert _as_set(domain.corners()) == _as_set(expected)


@settings(max_examples=60, deadline=None)
@given(
    split=st.floats(0.2, 0.8),
    axis=st.integers(0, 2),
    point=st.tuples(*[st.floats(-0.2, 1.2)] * 3),
    tolerance=st.sampled_from([1e-9, 1e-6, 1e-3]),
)
def test_a_face_two_operands_share_is_inside_their_union(split, axis, point, tolerance):
    # two boxes side by side along ``axis``: the minimum of their distances is zero on the face between
    # them (inside the union), and ``inside`` must say so there while agreeing with the distance elsewhere
    upper = np.ones(3)
    upper[axis] = split
    lower = np.zeros(3)
    lower[axis] = split
    union = tm.geometry.Box((0, 0, 0), upper) | tm.geometry.Box(lower, (1, 1, 1))
    on_face = np.full(3, 0.5)
    on_face[axis] = split
    assert abs(union.distance(on_face[None])[0]) < 1e-15  # zero but for rounding
    assert union.inside(on_face[None], tolerance).tolist() == [True]
    point = np.array([point])
    distance = union.distance(point)[0]
    inside = union.inside(point, tolerance)[0]
    if distance < -tolerance:
        assert inside
    if distance > 0 or np.any(point < tolerance) or np.any(point > 1 - tolerance):  # out, or near the box's faces
        assert not inside


def test_two_dimensional_unions_share_faces_too():
    stacked = tm.geometry.Rectangle((0, 0), (1, 0.5)) | tm.geometry.Rectangle((0.2, 0.5), (0.8, 1))
    along = np.column_stack([np.linspace(0.25, 0.75, 11), np.full(11, 0.5)])
    assert stacked.inside(along, 1e-6).all()
    # where the face is the boundary (the lower one's top beside the upper one) it is not inside,
    # nor is a re-entrant corner, whose axis neighbours all lie on the boundary or inside
    assert not stacked.inside(np.array([[0.1, 0.5], [0.9, 0.5], [0.2, 0.75], [0.5, 1.0], [0.2, 0.5]]), 1e-6).any()
    # a combination holding such a union (a strip of it, as the parallel mesher cuts) keeps the face inside
    strip = stacked & tm.geometry.Rectangle((0.4, -1), (2, 2))
    assert strip.inside(along[along[:, 0] > 0.45], 1e-6).all()


def _ellipse_scaled(scale):
    """A half-by-one ellipse whose implicit function grows ``scale`` times faster than a distance."""
    return tm.geometry.FunctionDomain(
        lambda p: scale * (p[:, 0] ** 2 + (p[:, 1] / 0.5) ** 2 - 1), [(-1, -0.5), (1, 0.5)]
    )


def test_a_combination_is_lipschitz_only_where_every_operand_is():
    # the generator skips far interior points on this promise: a combination claimed it whatever its
    # operands, and the 100x ellipse cut to a box came out with 71 % of its area, without a word
    disk, box = tm.geometry.Disk((0, 0), 1), tm.geometry.Rectangle((-3, -3), (3, 3))
    assert (disk | box).lipschitz and (disk - box).lipschitz
    ellipse = _ellipse_scaled(100)
    assert not (ellipse & box).lipschitz and not (box - ellipse).lipschitz and not (disk | ellipse).lipschitz
    mesh = tm.generate_mesh(ellipse & box, 0.05)
    area = tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum()
    assert area == pytest.approx(np.pi / 2, rel=0.01)


def test_a_domain_subclass_does_not_claim_lipschitz_unless_it_says_so():
    class Ellipse(tm.geometry.Domain):
        bbox = np.array([[-2.0, -1.0], [2.0, 1.0]])

        def _distance(self, p):
            return 100 * ((p[:, 0] / 2) ** 2 + p[:, 1] ** 2 - 1)

    assert not Ellipse().lipschitz
    mesh = tm.generate_mesh(Ellipse(), 0.05)
    edges = tm.mesh.topology.boundary_edges(mesh.cells)
    longest = np.linalg.norm(mesh.points[edges[:, 0]] - mesh.points[edges[:, 1]], axis=1).max()
    assert longest < 1.3 * 0.05  # claimed, boundary edges 3.3 sizes long


@pytest.mark.parametrize("offset", [(0.0, 0.0), (5e5, 5e6), (4.3e6, 3.2e6)])
def test_crossing_corners_are_found_far_from_the_origin(offset):
    # UTM metres: the corners' distances round to about 1e-9 there, and a tolerance of the extent's 1e-12
    # found none of two 30 m disks' corners; the boundary vertices there then stayed 0.042 sizes off it
    offset = np.array(offset)
    union = tm.geometry.Disk(offset, 30) | tm.geometry.Disk(offset + [57.0, 0.0], 30)
    corners = union.corners()
    expected = offset + [[28.5, -np.sqrt(30**2 - 28.5**2)], [28.5, np.sqrt(30**2 - 28.5**2)]]
    np.testing.assert_allclose(np.sort(corners, axis=0), np.sort(expected, axis=0), rtol=0, atol=1e-6)
    mesh = tm.generate_mesh(union, 1.5)
    assert tm.cleanup.mesh_problems(mesh, union, boundary_tolerance=1.5e-3) == []


@pytest.mark.parametrize("offset", [(0.0, 0.0), (5e5, 5e6)])
def test_an_l_shape_has_the_same_corners_anywhere(offset):
    # at UTM coordinates Newton's crossings along the shared side stopped 3.4e-6 short of the operands' corners,
    # and both were listed: (0, 999.9999966) and (0, 1000)
    offset = np.array(offset)
    union = tm.geometry.Rectangle(offset, offset + (2000, 1000)) | tm.geometry.Rectangle(offset, offset + (1000, 2000))
    corners = union.corners() - offset
    expected = [(0, 0), (1000, 0), (2000, 0), (0, 1000), (1000, 1000), (2000, 1000), (0, 2000), (1000, 2000)]
    np.testing.assert_allclose(corners[np.lexsort(corners.T[::-1])], sorted(expected), rtol=0, atol=1e-6)


@pytest.mark.parametrize(
    "combination",
    [
        tm.geometry.Disk((0, 0), 1) | tm.geometry.Disk((1, 0), 1),
        tm.geometry.Rectangle((0, 0), (2, 1)) - tm.geometry.Disk((0.5, 0.5), 0.2),
        tm.geometry.Box((0, 0, 0), (1, 1, 1)) & tm.geometry.Ball((1, 1, 1), 0.5),
    ],
)
def test_inside_refuses_points_of_another_dimension(combination):
    # 2-D: three points in 3-D came back as two answers ([True, False, True] for 2 points); 3-D: 3 in, 2 out
    wrong = np.zeros((6, 3 if combination.dim == 2 else 2))
    with pytest.raises(GeometryError, match=rf"points must have shape \(n, {combination.dim}\)"):
        combination.inside(wrong)
