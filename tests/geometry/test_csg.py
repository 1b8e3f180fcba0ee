import numpy as np
import pytest
from hypothesis import given
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
