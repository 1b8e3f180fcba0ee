import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import GeometryError
from terramesh.geometry.primitives3d import Ball, Box, Cylinder

rng = np.random.default_rng(0)
SAMPLE = rng.uniform(-2.0, 2.0, (2000, 3))


def brute_force_box_distance(points, lower, upper):
    """Signed distance to an axis-aligned box from its faces, by cases."""
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    inside = np.all((points > lower) & (points < upper), axis=1)
    nearest = np.clip(points, lower, upper)
    outside = np.linalg.norm(points - nearest, axis=1)
    depth = np.min(np.concatenate([points - lower, upper - points], axis=1), axis=1)
    return np.where(inside, -depth, outside)


def rotation_to_z(axis):
    """Rotation matrix taking the unit vector ``axis`` to (0, 0, 1) (Rodrigues)."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    v = np.cross(axis, [0.0, 0.0, 1.0])
    c = axis[2]
    if np.linalg.norm(v) < 1e-12:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1 + c)


def brute_force_cylinder_distance(points, center, radius, height, axis):
    local = (points - center) @ rotation_to_z(axis).T
    r, z = np.hypot(local[:, 0], local[:, 1]), local[:, 2]
    dr, dz = r - radius, np.abs(z) - height / 2
    return np.where((dr < 0) & (dz < 0), np.maximum(dr, dz), np.hypot(np.maximum(dr, 0), np.maximum(dz, 0)))


def test_box_distance_matches_brute_force_and_has_eight_corners():
    box = Box((0.0, -1.0, 0.5), (1.0, 1.0, 1.5))
    np.testing.assert_allclose(
        box.distance(SAMPLE), brute_force_box_distance(SAMPLE, (0, -1, 0.5), (1, 1, 1.5)), atol=1e-12
    )
    corners = box.corners()
    assert corners.shape == (8, 3)
    np.testing.assert_allclose(box.distance(corners), 0.0, atol=1e-12)
    assert len(np.unique(corners, axis=0)) == 8
    np.testing.assert_array_equal(box.bbox, [[0, -1, 0.5], [1, 1, 1.5]])


def test_box_project_is_the_nearest_boundary_point():
    lower, upper = np.array([-200.0, -200.0, -600.0]), np.array([800.0, 600.0, 0.0])
    box = Box(lower, upper)
    points = np.random.default_rng(2).uniform(lower - 300, upper + 300, (4000, 3))
    copy = points.copy()
    projected = box.project(points)
    np.testing.assert_array_equal(points, copy)
    # on a face plane exactly, and as far away as the distance says
    assert np.all(np.any((projected == lower) | (projected == upper), axis=1))
    np.testing.assert_allclose(box.distance(projected), 0.0, atol=1e-12 * 1000)
    np.testing.assert_allclose(
        np.linalg.norm(projected - points, axis=1), np.abs(box.distance(points)), rtol=1e-12, atol=1e-9
    )
    # outside: clamped (onto an edge or a corner where two or three coordinates are out); inside: nearest face
    outside = box.distance(points) > 0
    np.testing.assert_array_equal(projected[outside], np.clip(points[outside], lower, upper))
    np.testing.assert_array_equal(box.project(projected), projected)


def test_box_sharp_edges_run_corner_to_corner_on_two_faces():
    box = Box((0.0, -1.0, 0.5), (1.0, 1.0, 1.5))
    corners = {tuple(c) for c in box.corners()}
    t = np.linspace(0.0, 1.0, 11)
    ends, directions = set(), []
    edges = box.sharp_edges()
    assert len(edges) == 12
    for edge in edges:
        points = edge(t)
        assert tuple(points[0]) in corners and tuple(points[-1]) in corners
        ends.add(tuple(sorted([tuple(points[0]), tuple(points[-1])])))
        on_face = (points == box.bbox[0]) | (points == box.bbox[1])
        assert np.all(on_face.sum(axis=1) >= 2)  # exactly on two faces: two coordinates copied from the corners
        np.testing.assert_allclose(box.distance(points), 0.0, atol=1e-15)
        directions.append(np.flatnonzero(points[-1] != points[0]))
    assert len(ends) == 12  # twelve different edges
    assert np.bincount(np.concatenate(directions), minlength=3).tolist() == [4, 4, 4]


def test_ball_distance_and_bbox():
    ball = Ball((0.5, 0.0, -1.0), 0.75)
    np.testing.assert_allclose(ball.distance(SAMPLE), np.linalg.norm(SAMPLE - (0.5, 0, -1), axis=1) - 0.75)
    np.testing.assert_allclose(ball.bbox, [[-0.25, -0.75, -1.75], [1.25, 0.75, -0.25]])
    assert ball.dim == 3 and len(ball.corners()) == 0


@pytest.mark.parametrize("axis", [(0, 0, 1), (1, 0, 0), (0, -2, 0), (1, 1, 0), (1, 2, 3)])
def test_cylinder_distance_matches_brute_force_for_any_axis(axis):
    center, radius, height = np.array([0.1, -0.2, 0.3]), 0.6, 1.5
    cylinder = Cylinder(center, radius, height, axis=axis)
    expected = brute_force_cylinder_distance(SAMPLE, center, radius, height, axis)
    np.testing.assert_allclose(cylinder.distance(SAMPLE), expected, atol=1e-12)


@pytest.mark.parametrize("axis", [(0, 0, 1), (1, 1, 0), (1, 2, 3)])
def test_cylinder_bbox_is_tight(axis):
    cylinder = Cylinder((0.0, 0.0, 0.0), 0.5, 2.0, axis=axis)
    # points on the two rims reach the extremes of the bbox on every axis
    unit = np.asarray(axis, float) / np.linalg.norm(axis)
    first = np.cross(unit, np.eye(3)[np.argmin(np.abs(unit))])
    first /= np.linalg.norm(first)
    second = np.cross(unit, first)
    angle = np.linspace(0, 2 * np.pi, 20001)[:, None]
    ring = 0.5 * (np.cos(angle) * first + np.sin(angle) * second)
    rims = np.vstack([ring + unit, ring - unit])
    np.testing.assert_allclose(cylinder.distance(rims), 0.0, atol=1e-12)
    np.testing.assert_allclose(rims.min(axis=0), cylinder.bbox[0], atol=1e-6)
    np.testing.assert_allclose(rims.max(axis=0), cylinder.bbox[1], atol=1e-6)


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.floats(-3, 3), min_size=3, max_size=3),
    st.lists(st.floats(-3, 3), min_size=3, max_size=3),
)
def test_distances_are_one_lipschitz(p, q):
    """The generator skips far interior points on this promise (Domain.lipschitz)."""
    p, q = np.array([p]), np.array([q])
    gap = np.linalg.norm(p - q)
    shapes = [
        Box((0, 0, 0), (1, 2, 1)),
        Ball((0, 0, 0), 1),
        Cylinder((0, 0, 0), 0.5, 1, axis=(1, 1, 1)),
        Box((-1, -1, -1), (1, 1, 1)) - Ball((0, 0, 0), 0.5),
    ]
    for shape in shapes:
        assert shape.lipschitz
        assert abs(shape.distance(p)[0] - shape.distance(q)[0]) <= gap + 1e-12


def test_csg_works_in_3d():
    box = Box((0, 0, 0), (1, 1, 1))
    hole = Ball((0.5, 0.5, 0.5), 0.3)
    plate = box - hole
    assert plate.dim == 3
    np.testing.assert_allclose(plate.distance([(0.5, 0.5, 0.5), (0.05, 0.5, 0.5)]), [0.3, -0.05])
    np.testing.assert_array_equal(plate.bbox, box.bbox)
    assert len(plate.corners()) == 8  # the box's corners are on the difference's boundary
    union = box | Ball((1.0, 0.5, 0.5), 0.5)
    np.testing.assert_allclose(union.bbox, [[0, 0, 0], [1.5, 1, 1]])
    assert union.distance([(1.4, 0.5, 0.5)])[0] < 0
    assert len(union.corners()) == 8  # the ball covers no corner of the box
    lens = Ball((0, 0, 0), 1) & Ball((1, 0, 0), 1)
    np.testing.assert_allclose(lens.distance([(0.5, 0.0, 0.0)]), [-0.5])


def test_csg_refuses_mixed_dimensions():
    with pytest.raises(GeometryError, match="different dimensions"):
        tm.geometry.Union([Box((0, 0, 0), (1, 1, 1)), tm.geometry.Disk((0, 0), 1)])


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: Box((0, 0, 0), (1, 0, 1)), "upper corner must exceed"),
        (lambda: Box((0, 0), (1, 1)), "three finite numbers"),
        (lambda: Box((0, 0, np.nan), (1, 1, 1)), "three finite numbers"),
        (lambda: Ball((0, 0, 0), 0), "positive"),
        (lambda: Ball((0, 0, 0), np.inf), "positive"),
        (lambda: Ball((0, 0, 0), "one"), "positive finite number"),
        (lambda: Ball((0, 0), 1), "three finite numbers"),
        (lambda: Cylinder((0, 0, 0), 1, -1), "height must be a positive finite number"),
        (lambda: Cylinder((0, 0, 0), 1, 1, axis=(0, 0, 0)), "zero vector"),
        (lambda: Cylinder((0, 0, 0), 1, 1, axis=(0, 1)), "three finite numbers"),
        (lambda: Ball(("a", 0, 0), 1), "Ball center must be three finite numbers"),  # was float()'s ValueError
        (lambda: Cylinder((0, 0, 0), 1, 1, axis=("a", 0, 1)), "three finite numbers"),
    ],
)
def test_bad_parameters_raise_geometry_error(make, message):
    with pytest.raises(GeometryError, match=message):
        make()


def test_wrong_point_shape_raises_and_inputs_are_not_mutated():
    ball = Ball((0, 0, 0), 1)
    with pytest.raises(GeometryError, match=r"shape \(n, 3\)"):
        ball.distance(np.zeros((4, 2)))
    points = SAMPLE.copy()
    for shape in [Box((0, 0, 0), (1, 1, 1)), ball, Cylinder((0, 0, 0), 1, 1)]:
        shape.distance(points)
    np.testing.assert_array_equal(points, SAMPLE)


def test_cylinder_distance_keeps_its_accuracy_far_along_a_long_axis():
    # across the axis from |r|**2 - along**2: 1e-3 of the distance lost 9.9e6 along a cylinder 2e7 long
    cylinder = tm.geometry.Cylinder((0.0, 0.0, 0.0), 1.0, 2e7)
    assert cylinder.distance(np.array([[1e-3, 0.0, 9.9e6], [0.0, 2.5, -9.9e6]])) == pytest.approx([-0.999, 1.5])
