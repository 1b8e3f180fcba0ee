"""Exact projection onto the boundary: rectangles, disks and polygons (the generator's fast path)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.geometry.segments import SegmentIndex

coordinate = st.floats(-3.0, 3.0, allow_nan=False)
point = st.tuples(coordinate, coordinate)


def star_polygon(n, seed):
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0, 2 * np.pi, n))
    radii = rng.uniform(0.5, 1.5, n)
    return tm.geometry.Polygon(np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]))


DOMAINS = {
    "rectangle": tm.geometry.Rectangle((-1.0, -0.5), (2.0, 1.0)),
    "disk": tm.geometry.Disk((0.3, -0.2), 1.3),
    "polygon": star_polygon(40, 0),
    "polygon with a hole": tm.geometry.Polygon(
        [[(-2, -2), (2, -2), (2, 2), (-2, 2)], [(0, 0), (0, 1), (1, 1), (1, 0)]]
    ),
}


@pytest.mark.parametrize("name", DOMAINS)
@settings(max_examples=60, deadline=None)
@given(st.lists(point, min_size=1, max_size=20))
def test_projection_lands_on_the_boundary_at_the_distance(name, points):
    domain = DOMAINS[name]
    points = np.array(points, dtype=float)
    projected = domain.project(points)
    assert projected.shape == points.shape
    np.testing.assert_allclose(domain.distance(projected), 0.0, atol=1e-12)
    # the nearest boundary point: it is as far as the distance says (exact within 1 % far
    # from a polygon's boundary, exactly within a unit of it)
    moved = np.linalg.norm(projected - points, axis=1)
    distance = np.abs(domain.distance(points))
    near = distance < 1.0
    np.testing.assert_allclose(moved[near], distance[near], rtol=1e-9, atol=1e-12)
    assert np.all(moved <= 1.01 * distance + 1e-12)


def test_nearest_points_on_segments_match_brute_force():
    rng = np.random.default_rng(3)
    starts = rng.random((300, 2))
    ends = starts + 0.05 * rng.standard_normal((300, 2))
    index = SegmentIndex(starts, ends)
    points = rng.random((500, 2))
    direction = ends - starts
    t = np.einsum("pmd,md->pm", points[:, None] - starts[None], direction) / np.sum(direction**2, axis=1)
    foot = starts[None] + np.clip(t, 0, 1)[..., None] * direction[None]
    gap = np.linalg.norm(foot - points[:, None], axis=2)
    best = foot[np.arange(len(points)), np.argmin(gap, axis=1)]
    nearest = index.nearest_points(points)
    np.testing.assert_allclose(np.linalg.norm(nearest - points, axis=1), gap.min(axis=1), rtol=1e-2)
    exact = gap.min(axis=1) < 0.05
    np.testing.assert_allclose(nearest[exact], best[exact], atol=1e-12)


def test_the_disk_centre_projects_to_angle_zero():
    assert tm.geometry.Disk((1.0, 2.0), 0.5).project([(1.0, 2.0)]).tolist() == [[1.5, 2.0]]
