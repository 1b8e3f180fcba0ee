"""The distance function's finite-difference gradient, alone and with the distance from one call."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.geometry import base

STAR = tm.geometry.Polygon(
    [(np.cos(t) * r, np.sin(t) * r) for t, r in zip(np.linspace(0, 2 * np.pi, 11)[:-1], [1, 0.4] * 5, strict=True)]
)


class Counting:
    """A domain that counts the calls of its distance."""

    def __init__(self, domain):
        self.domain, self.calls = domain, 0

    def distance(self, points):
        self.calls += 1
        return self.domain.distance(points)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 200), st.sampled_from([1e-7, 1e-4]), st.booleans())
def test_one_call_gives_the_distance_and_the_per_axis_gradient(seed, count, step, per_point_step):
    points = np.random.default_rng(seed).uniform(-1.2, 1.2, (count, 2))
    step = np.full(count, step) if per_point_step else step
    counting = Counting(STAR)
    distance, gradient = base.distance_and_gradient(counting, points, step)
    assert counting.calls == 1
    assert np.array_equal(distance, STAR.distance(points))
    per_axis = np.column_stack(
        [(STAR.distance(points + np.eye(2)[axis] * np.c_[step]) - distance) / step for axis in (0, 1)]
    )
    assert np.array_equal(gradient, per_axis)
    assert np.array_equal(base.distance_gradient(STAR, points, distance, step), per_axis)


def test_many_points_take_one_call_per_axis_and_give_the_same(monkeypatch):
    points = np.random.default_rng(0).uniform(-1.2, 1.2, (50, 2))
    expected = base.distance_and_gradient(STAR, points, 1e-6)
    monkeypatch.setattr(base, "ONE_CALL_COORDINATES", 10)  # bounds the memory of 10**7 points' shifted copies
    counting = Counting(STAR)
    distance, gradient = base.distance_and_gradient(counting, points, 1e-6)
    assert counting.calls == 3
    assert np.array_equal(distance, expected[0]) and np.array_equal(gradient, expected[1])
