"""The force iterations (terramesh.generation.relax): points that meet, boundary gaps, progress."""

import logging

import numpy as np
import pytest

import terramesh as tm

from ..conftest import random_walk_coast


def test_iterations_are_logged_a_second_apart_with_their_bound(caplog, plate_with_hole, monkeypatch):
    import terramesh.generation.relax as relax_module

    class Clock:  # two seconds pass between any two looks: every iteration is due a line
        now = 0.0

        def perf_counter(self):
            self.now += 2.0
            return self.now

    monkeypatch.setattr(relax_module, "time", Clock())
    domain, _ = plate_with_hole
    with caplog.at_level(logging.INFO, logger="terramesh"):
        mesh = tm.generate_mesh(domain, 0.05, max_iter=40)
    lines = [record.getMessage() for record in caplog.records if record.getMessage().startswith("iteration ")]
    assert len(lines) >= mesh.info["iterations"] // 2  # a line each iteration of the last level, at least
    assert all(" of at most 40: " in line for line in lines)


def test_points_projected_onto_one_spot_cost_no_rebuilds():
    """Pinned: on a jagged coastline, points projected onto one polygon vertex (from either side of it)
    coincided; the flips cannot follow that, and while the doubled point stayed every later change
    triangulated from scratch (141 rebuilds here, 70 of 72 retriangulations in the guide's §5.3)."""
    coast = random_walk_coast(2000, 1)
    mesh = tm.generate_mesh(coast, 0.03, max_iter=100, seed=0)
    # valid as a mesh (its teeth narrower than a cell leave centroids outside: the coastal clean-up's job)
    assert tm.cleanup.mesh_problems(mesh) == []
    retriangulations = sum(level["retriangulations"] for level in mesh.info["levels"])
    rebuilds = sum(level["rebuilds"] for level in mesh.info["levels"])
    assert retriangulations >= 15 and rebuilds <= 2  # many chances to rebuild (85 before stale points were let wait)


def test_a_point_projected_onto_another_ones_spot_waits_where_it_was():
    from terramesh.generation.relax import _to_park

    previous = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [4.0, 0.0], [5.0, 0.0]])
    points = previous.copy()
    points[3] = points[1]  # 3 moved onto 1, which held its spot: 3 waits
    points[2] = points[5] = [9.0, 9.0]  # 2 and 5 both came: the later one waits
    points[0] = points[4]  # 0 (a fixed point) onto 4, which stayed: 4 keeps its spot, and 0 is fixed
    doubled, twin = tm.mesh.topology.coincident_points(points, return_twins=True)
    assert doubled.tolist() == [3, 4, 5] and twin.tolist() == [1, 0, 2]
    assert _to_park(points, previous, doubled, twin, 1).tolist() == [3, 5]
    assert _to_park(points, previous, doubled, twin, 0).tolist() == [0, 3, 5]


@pytest.mark.filterwarnings("ignore:mesh generation reached max_iter")
@pytest.mark.parametrize("max_iter", [5, 6, 12, 26, 41])
def test_points_waiting_at_the_stop_leave_no_trace(monkeypatch, max_iter):
    """Pinned: a point projected onto another one's spot waits, out of the forces, until the points
    change anyway; at these stops some wait still, and they go, leaving no vertex doubled or unused."""
    import terramesh.generation.relax as relax

    flushed = []
    without_points = relax._without_points

    def recorded(points, target, parked, *args):
        flushed.append(len(parked))
        return without_points(points, target, parked, *args)

    monkeypatch.setattr(relax, "_without_points", recorded)
    mesh = tm.generate_mesh(random_walk_coast(2000, 1), 0.03, max_iter=max_iter, seed=0)
    assert flushed[-1] > 0  # the stop's own flush had points to remove
    assert tm.cleanup.mesh_problems(mesh) == []
    assert len(tm.mesh.topology.coincident_points(mesh.points)) == 0
    assert np.array_equal(np.unique(mesh.cells), np.arange(mesh.n_points))


@pytest.mark.parametrize("vertices, seed, size", [(2000, 1, 0.03), (1000, 0, 0.02), (5000, 3, 0.01)])
def test_points_still_doubled_after_going_back_go_with_every_waiting_point(monkeypatch, vertices, seed, size):
    """The fallback: where going back leaves two points on one spot, they and all waiting points go at once."""
    import terramesh.generation.relax as relax

    to_park, calls = relax._to_park, []

    def every_other(*args):
        calls.append(len(calls) % 2)
        return to_park(*args) if calls[-1] else np.empty(0, dtype=np.int64)  # nobody goes back: still doubled

    monkeypatch.setattr(relax, "_to_park", every_other)
    mesh = tm.generate_mesh(random_walk_coast(vertices, seed), size, seed=0)
    assert len(calls) > 10
    assert tm.cleanup.mesh_problems(mesh) == []
    assert len(tm.mesh.topology.coincident_points(mesh.points)) == 0
    assert tm.quality.summary(mesh).min > 0.3


class _OneSpotBoundary:
    """A stand-in domain whose boundary projection sends every point to one spot (a polygon's vertex)."""

    def __init__(self, spot):
        self.spot = np.asarray(spot, dtype=float)

    def distance(self, points):
        return np.ones(len(points))

    def project(self, points):
        return np.tile(self.spot, (len(points), 1))


@pytest.mark.parametrize("spot, expected", [((2.0, 1.0), 0), ((5.0, 5.0), 1)])
def test_boundary_gap_points_never_land_on_a_point_or_on_each_other(spot, expected):
    from terramesh.generation.relax import _boundary_gaps
    from terramesh.generation.triangulate import Triangulation

    points = np.array([[0.0, 0.0], [4.0, 0.0], [2.0, 1.0], [8.0, 0.0], [4.0, 3.0]])
    triangulation = Triangulation(points, frame=True)
    # all longer than 1.3 sizes: three gaps, projected to one spot; point 2 on no edge of theirs
    edges = np.array([[0, 1], [1, 3], [0, 4]])
    gaps = _boundary_gaps(_OneSpotBoundary(spot), points, edges, np.ones(5), 1e-8, triangulation)
    assert len(gaps) == expected  # (2, 1) is point 2: none; elsewhere: one of the three
    assert len(_boundary_gaps(_OneSpotBoundary(spot), points, edges, np.full(5, 10.0), 1e-8, triangulation)) == 0
