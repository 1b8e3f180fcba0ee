import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import GeometryError


@given(st.floats(-3, 3), st.floats(-3, 3))
def test_rectangle_distance_is_exact(x, y):
    box = tm.geometry.Rectangle((0, 0), (2, 1))
    inside = 0 <= x <= 2 and 0 <= y <= 1
    dx = max(0.0 - x, 0.0, x - 2.0)
    dy = max(0.0 - y, 0.0, y - 1.0)
    expected = -min(x, 2 - x, y, 1 - y) if inside else np.hypot(dx, dy)
    assert box.distance([[x, y]])[0] == pytest.approx(expected, abs=1e-12)


@given(st.floats(-3, 3), st.floats(-3, 3))
def test_disk_distance_is_exact(x, y):
    disk = tm.geometry.Disk((0.5, -0.5), 1.5)
    assert disk.distance([[x, y]])[0] == pytest.approx(np.hypot(x - 0.5, y + 0.5) - 1.5, abs=1e-12)


def test_rectangle_corners_and_bbox():
    box = tm.geometry.Rectangle((0, 0), (2, 1))
    assert box.bbox.tolist() == [[0, 0], [2, 1]]
    np.testing.assert_array_equal(box.corners(), [[0, 0], [2, 0], [2, 1], [0, 1]])


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: tm.geometry.Disk((0, 0), 0), "radius"),
        (lambda: tm.geometry.Disk((0, 0), float("nan")), "radius"),
        (lambda: tm.geometry.Rectangle((0, 0), (0, 1)), "upper corner"),
        (lambda: tm.geometry.Rectangle((0, 0), (np.nan, 1)), "non-finite"),
        # float() and np.asarray raised their own ValueError / TypeError
        (lambda: tm.geometry.Disk((0, 0), "a"), "Disk radius must be a positive finite number"),
        (lambda: tm.geometry.Disk((0, 0), None), "Disk radius must be a positive finite number"),
        # float(True) is 1.0: a flag where a number belongs gave a unit disk
        (lambda: tm.geometry.Disk((0, 0), True), "Disk radius must be a positive finite number, got True"),
        (lambda: tm.geometry.Disk(("a", 0), 1), r"Disk center must be two finite numbers"),
        (lambda: tm.geometry.Disk((0, 0, 0), 1), r"Disk center must be two finite numbers"),
        (lambda: tm.geometry.Rectangle(("a", 0), (1, 1)), "bbox must be numbers"),
        (lambda: tm.geometry.Rectangle((0, 0), None), "bbox must be numbers"),
    ],
)
def test_bad_shapes_raise_clear_errors(make, message):
    with pytest.raises(GeometryError, match=message):
        make()


def test_distance_rejects_wrong_point_shape():
    with pytest.raises(GeometryError, match=r"shape \(n, 2\)"):
        tm.geometry.Disk((0, 0), 1).distance(np.zeros((4, 3)))


def test_callable_domain_needs_bbox():
    with pytest.raises(GeometryError, match="bbox"):
        tm.geometry.as_domain(lambda p: p[:, 0])
    domain = tm.geometry.as_domain(lambda p: np.hypot(p[:, 0], p[:, 1]) - 1, bbox=[(-1, -1), (1, 1)])
    assert domain.distance([[0.0, 0.0]])[0] == -1.0


def test_a_distance_function_with_nan_is_named():
    # it came out later as "points must be finite (found NaN or infinity)" from the triangulation
    def half_nan(points):
        return np.where(points[:, 0] > 0.5, np.nan, np.hypot(points[:, 0], points[:, 1]) - 1)

    with pytest.raises(GeometryError, match=r"the distance function returned NaN or infinite values at \d+ of"):
        tm.generate_mesh(half_nan, 0.1, bbox=[(-1, -1), (1, 1)])


def test_a_complex_distance_function_is_refused_by_name():
    # its imaginary parts were dropped with only NumPy's ComplexWarning
    domain = tm.geometry.as_domain(lambda p: np.hypot(p[:, 0], p[:, 1]) - 1 + 0j, bbox=[(-1, -1), (1, 1)])
    with pytest.raises(GeometryError, match="must return real numbers, got an array of complex128"):
        domain.distance([[0.0, 0.0]])
