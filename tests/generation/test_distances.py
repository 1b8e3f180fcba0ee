"""Distances as the generator keeps them (terramesh.generation.distances)."""

import numpy as np
import pytest

import terramesh as tm

from ..conftest import assert_valid, random_walk_coast


def test_lazy_distances_take_the_decisions_fresh_ones_would():
    """Also while points are removed and added (a settle round that removed as many as it added misled them)."""
    from terramesh.generation.distances import LazyDistance

    rng = np.random.default_rng(7)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 300))
    radii = 1.0 + 0.2 * rng.uniform(-1, 1, 300)
    domain = tm.geometry.Polygon(np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]))
    points = 0.9 * rng.uniform(-1, 1, (4000, 2)) * 0.7
    target = np.full(len(points), 0.02)
    lazy = LazyDistance(domain)
    lazy.update(points, np.zeros(len(points)), target)
    evaluated = []
    for iteration in range(60):
        if iteration % 7 == 3:
            # the generator removes crowded points and adds boundary points, here as many of
            # each: the distances must follow the points, not merely keep their number
            doomed = rng.choice(len(points), 25, replace=False)
            added = domain.project(rng.uniform(-1.2, 1.2, (25, 2)))
            points, target = np.vstack([np.delete(points, doomed, axis=0), added]), np.full(len(points), 0.02)
            lazy.remove(doomed)
            lazy.append(added)
            assert lazy.nearest(np.arange(len(points)), len(points)) is None  # not for points changed since
        step = 0.01 * rng.standard_normal((len(points), 2)) + 0.004 * points  # drifting outwards
        points = points + step
        distance = lazy.update(points, np.hypot(*step.T), target)
        fresh = domain.distance(points)
        # the nearest boundary points of the points evaluated now (all that can be outside)
        outside = np.flatnonzero(distance > 0)
        nearest = lazy.nearest(outside, len(points))
        np.testing.assert_array_equal(nearest, domain.project(points[outside]))
        np.testing.assert_array_equal(distance > 0, fresh > 0)
        np.testing.assert_array_equal(distance < -1e-5, fresh < -1e-5)
        assert np.all(lazy.upper_bound(len(points)) >= fresh - 1e-12)
        evaluated.append(np.count_nonzero(lazy.drift == 0))
    assert np.mean(evaluated) < 0.5 * len(points)  # most points were not evaluated again


@pytest.mark.parametrize("hole", [False, True])
def test_distances_clipped_far_inside_leave_the_mesh_as_full_ones_would(monkeypatch, hole):
    """The generator asks a polygon for its distance only within 8 smallest sizes; the mesh is the same to the bit."""
    coast = random_walk_coast(3000, 7)
    domain = coast - tm.geometry.Disk((0.1, 0.0), 0.3) if hole else coast
    size = lambda p: 0.01 + 0.05 * np.abs(p[:, 0] + 1)  # noqa: E731
    clipped = tm.generate_mesh(domain, size, h0=0.01, seed=3)
    searched = tm.geometry.Polygon.distance_and_nearest

    def full(self, points, limit=None):
        return searched(self, points)

    def full_clipped(self, points, limit):
        return np.clip(self.distance(points), -limit, limit)

    monkeypatch.setattr(tm.geometry.Polygon, "distance_and_nearest", full)
    monkeypatch.setattr(tm.geometry.Polygon, "distance_within", full_clipped)
    unclipped = tm.generate_mesh(domain, size, h0=0.01, seed=3)
    np.testing.assert_array_equal(clipped.points, unclipped.points)
    np.testing.assert_array_equal(clipped.cells, unclipped.cells)
    assert_valid(clipped, domain, 0.01)
