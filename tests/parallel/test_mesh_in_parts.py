"""Meshing in strips and merging: the merged mesh against one made whole, and MPI against one process."""

import os
import shutil
import subprocess
import sys
import textwrap
import time
import warnings

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import GenerationError, TerrameshWarning
from terramesh.parallel import generate_mesh_parallel, separator_points, strip_cuts
from terramesh.parallel.decompose import SHORTEST_PIECE, _chains_along, _clearances, cut_clearance
from terramesh.parallel.mesh_in_parts import _merged
from terramesh.quality import edge_length_ratio, triangle_quality
from terramesh.seismic import ModelBox
from terramesh.sizing.edge_length import as_size_function

from ..conftest import assert_valid, random_walk_coast, wedge_with_its_tip_fixed


def assert_like_a_whole_mesh(mesh, whole, domain, h0):
    assert_valid(mesh, domain, h0)  # a crack along a cut would leave boundary vertices off the boundary
    quality = triangle_quality(mesh.points, mesh.cells)
    assert quality.min() > 0.7 and quality.mean() > 0.98
    assert mesh.n_points == pytest.approx(whole.n_points, rel=0.03)
    assert tm.quality.summary(mesh).mean == pytest.approx(tm.quality.summary(whole).mean, abs=0.005)


@pytest.mark.parametrize("parts", [2, 3, 4])
def test_strips_of_a_disk_merge_into_one_valid_mesh(parts):
    disk = tm.geometry.Disk((0, 0), 1)
    mesh = generate_mesh_parallel(disk, 0.02, parts=parts)
    assert_like_a_whole_mesh(mesh, tm.generate_mesh(disk, 0.02, seed=0), disk, 0.02)
    assert len(mesh.info["parts"]) == parts and len(mesh.info["cuts"]) == parts - 1
    assert mesh.info["stitched"] == 0  # the strips met vertex for vertex: nothing was meshed anew
    # the strips hold about equal shares of the vertices
    counts = [strip["levels"][-1]["points"] for strip in mesh.info["parts"]]
    assert max(counts) < 1.15 * min(counts)
    # each cut lies inside the mesh: its points, shared by the strips beside it and then polished with their
    # neighbours, are vertices of cells that straddle it
    corners = mesh.points[mesh.cells][:, :, 0]
    for cut in mesh.info["cuts"]:
        assert np.sum((corners.min(axis=1) < cut) & (corners.max(axis=1) > cut)) > 50
    again = generate_mesh_parallel(disk, 0.02, parts=parts)
    np.testing.assert_array_equal(again.points, mesh.points)
    np.testing.assert_array_equal(again.cells, mesh.cells)


def test_the_merge_makes_shared_cut_points_one_and_keeps_each_strips_order():
    # two strips of two triangles each, meeting along x = 1 at (1, 0) and (1, 1); the right strip's
    # copy of (1, 1) is an ulp off the cut (each strip projects on its own; 1.0 + 1e-16 is 1.0 itself)
    left = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    right = np.array([[np.nextafter(1.0, 2.0), 1.0], [2.0, 0.0], [2.0, 1.0], [1.0, 0.0]])
    cells = [np.array([[0, 1, 2], [0, 2, 3]]), np.array([[3, 1, 2], [3, 2, 0]])]
    mesh = _merged([left, right], cells, 0, np.array([1.0]))
    np.testing.assert_array_equal(mesh.points, [*left, [2.0, 0.0], [2.0, 1.0]])
    np.testing.assert_array_equal(mesh.cells, [[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]])


def test_a_cut_through_two_pieces_of_an_annulus():
    ring = tm.geometry.Disk((0, 0), 1) - tm.geometry.Disk((0, 0), 0.5)
    points = separator_points(ring, lambda p: np.full(len(p), 0.05), 0.05, 0, 0.0)
    assert np.all(points[:, 0] == 0.0)
    assert np.sum(np.abs(points[:, 1]) < 0.5) == 0 and np.sum(points[:, 1] > 0) == np.sum(points[:, 1] < 0) == 11
    mesh = generate_mesh_parallel(ring, 0.05, parts=2)
    assert_like_a_whole_mesh(mesh, tm.generate_mesh(ring, 0.05, seed=0), ring, 0.05)


@pytest.mark.parametrize("h, held", [(0.5, False), (0.4, True)])
def test_a_piece_of_a_cut_shorter_than_half_a_size_gets_no_points(h, held):
    # the cut x = 0.28 crosses the small disk in a chord 0.215 long: 0.43 sizes at h = 0.5, 0.54 at 0.4. Held,
    # a piece a fraction of a size long fanned needles out of the strips' cells (sweep runs of random-walk
    # coasts in 2-3 strips: q 0.001, 0.046 and 0.174; 0.68, 0.52 and 0.57 without their points)
    union = tm.geometry.Disk((0, 0), 1) | tm.geometry.Disk((0, 1.5), 0.3)
    points = separator_points(union, lambda p: np.full(len(p), h), h, 0, 0.28)
    assert np.any(points[:, 1] > 1.2) == held
    assert np.sum(points[:, 1] < 1.0) >= 4  # the long piece through the large disk is kept either way


def test_bp2004_in_four_strips(shared_data):
    section = tm.seismic.read_velocity(shared_data / "seismic" / "vel_z6.25m_x12.5m_exact.segy")
    x, z = section.axes
    model = tm.seismic.VelocityModel(section.values[::8, ::8], (x[::8], z[::8]))
    size = tm.seismic.size_function(model, frequency=2.0, hmin=80.0, grade=0.15)
    mesh = generate_mesh_parallel(size.domain, size, parts=4)
    assert_like_a_whole_mesh(mesh, tm.generate_mesh(size.domain, size, seed=0), size.domain, 80.0)
    assert mesh.info["stitched"] == 0
    # a cut whose end lay 0.55 sizes from a node of the box's top side, both fixed, made a cell of q 0.73
    assert triangle_quality(mesh.points, mesh.cells).min() > 0.78  # whole: 0.80
    assert 0.95 < np.median(edge_length_ratio(mesh.points, mesh.cells, size)) < 1.05
    # the work is shared by the size, not the width: equal vertex counts in strips 14-21 km wide
    counts = [strip["levels"][-1]["points"] for strip in mesh.info["parts"]]
    assert max(counts) < 1.2 * min(counts)
    widths = np.diff([0.0, *mesh.info["cuts"], float(x[-1])])
    assert widths.max() > 1.3 * widths.min()


def test_a_cut_keeps_clear_of_side_nodes_it_would_leave_fixed_close_by():
    box = ModelBox((0.0, -1000.0), (4000.0, 0.0), 100.0)  # nodes on the top and bottom every 100 m
    size = as_size_function(100.0)
    corners = np.asarray(box.corners())

    def score(position):
        return cut_clearance(box, size, 100.0, 0, position, corners=corners)

    # a node 0.5-0.75 sizes from the cut's end stays fixed beside it (nearer, it gives way to the end)
    assert score(2010.0) == 0 and score(1990.0) == 0
    assert score(2060.0) == score(1940.0) == 2  # 0.6 sizes from the nodes at 2000, top and bottom
    assert score(2060.0) > cut_clearance(box, size, 100.0, 0, 2060.0)
    axis, cuts = strip_cuts(box, size, 2, h0=100.0)
    assert axis == 0 and score(cuts[0]) == 0


def _comb(teeth, width=0.1, height=1.0, base=0.2):
    """A comb as a Polygon: a base ``base`` high, ``teeth`` teeth ``width`` wide and apart, ``height`` tall."""
    ring = [(0.0, 0.0), ((2 * teeth - 1) * width, 0.0)]
    for k in reversed(range(teeth)):
        left = 2 * k * width
        ring += [(left + width, base), (left + width, base + height), (left, base + height), (left, base)]
    return tm.geometry.Polygon(np.array(ring[:-1]))


@pytest.mark.parametrize("parts", [4, 6])
def test_a_comb_in_strips_keeps_every_corner(parts):
    # a cut's end within half a size of a tooth's corner was fixed and the strip dropped the corner, its
    # cells then cut across it or reached past it; a cut along a tooth left the strip a sliver of it too
    # thin to mesh. In 4 and 6 strips 3 and 6 of the 36 corners went, the area off by 2e-4 and 2e-3
    comb = _comb(9)
    mesh = generate_mesh_parallel(comb, 0.07, parts=parts)
    assert_valid(mesh, comb, 0.07)
    corners = np.asarray(comb.corners())
    from scipy.spatial import cKDTree

    assert np.all(cKDTree(mesh.points).query(corners)[0] < 1e-9)
    area = tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum()
    assert area == pytest.approx(0.2 * 1.7 + 9 * 0.1 * 1.0, rel=1e-8)
    assert mesh.info["stitched"] > 0 and not mesh.info["remeshed"]


def test_only_corners_where_the_boundary_turns_hold_a_cut_point_off():
    """A model box's side nodes give way to a cut's points near them; its corners and the user's points do not."""
    from terramesh.parallel.mesh_in_parts import _anchors

    box = ModelBox((0.0, -1000.0), (4000.0, 0.0), 100.0)
    size = as_size_function(100.0)
    nodes = np.asarray(box.corners())
    cuts = np.array([30.0, 3990.0])  # by the side nodes at x = 0 and 100 and the corners at x = 4000
    user = np.array([[3950.0, -500.0]])
    anchors = _anchors(box, size, np.vstack([nodes, user]), user, 1e-3, 0, cuts)
    expected = [[0.0, -1000.0], [0.0, 0.0], [3950.0, -500.0], [4000.0, -1000.0], [4000.0, 0.0]]
    assert sorted(anchors.tolist()) == expected


def test_cuts_scored_together_match_each_cut_alone():
    """The cut placement samples all tried positions at once: the same points and scores as one by one."""
    coast = random_walk_coast(1000, 3)
    size = as_size_function(0.04)
    positions = np.linspace(-0.9, 0.9, 7)
    together = _chains_along(coast, size, 0.04, 0, positions)
    for position, chains in zip(positions, together, strict=True):
        alone = separator_points(coast, size, 0.04, 0, position)
        held = [chain for chain in chains if abs(chain[-1, 1] - chain[0, 1]) >= SHORTEST_PIECE * 0.04]
        np.testing.assert_array_equal(np.concatenate(held), alone)
        ends = np.concatenate([chain[[0, -1]] for chain in chains])
        assert np.abs(coast.distance(ends)).max() < 1e-12  # bisected onto the coast
        assert len(chains) >= 1 and np.all(alone[:, 0] == position)
    scores = _clearances(coast, size, 0.04, 0, positions)
    assert scores.tolist() == [cut_clearance(coast, size, 0.04, 0, p) for p in positions]
    assert scores.max() > 0  # a jagged coast: some positions come close to it


def test_cuts_shifted_toward_each_other_leave_no_strip_short():
    # a size graded across a rough coast: the second and third cuts each moved 0.115 toward the other (each
    # bounded by the other's balanced place), leaving a strip of 54 vertices beside four of 271-327
    coast = random_walk_coast(1500, 101, roughness=1.0, smallest_radius=0.2)

    def size(p):
        return 0.03 + 0.05 * np.abs(p[:, 1] + 0.3 * p[:, 0])

    _, balanced = strip_cuts(coast, size, 5)
    _, cuts = strip_cuts(coast, size, 5, h0=0.03)
    assert np.diff(cuts).min() > 0.5 * np.diff(balanced).min()  # before: 0.040 against 0.270
    mesh = generate_mesh_parallel(coast, size, h0=0.03, parts=5, seed=1)
    counts = [strip["levels"][-1]["points"] for strip in mesh.info["parts"]]
    assert min(counts) > 0.5 * max(counts)  # before: 54 and 327


def test_strip_cuts_share_the_vertex_count():
    square = tm.geometry.Rectangle((0, 0), (4, 1))
    axis, cuts = strip_cuts(square, lambda p: np.full(len(p), 0.1), 4)
    assert axis == 0
    np.testing.assert_allclose(cuts, [1, 2, 3], atol=0.02)
    np.testing.assert_array_equal(strip_cuts(square, lambda p: np.full(len(p), 0.1), np.int64(4))[1], cuts)
    # sizes 4x larger on the right half: 16x fewer vertices there, so the cuts crowd to the left
    axis, cuts = strip_cuts(square, lambda p: np.where(p[:, 0] < 2, 0.1, 0.4), 2)
    assert cuts[0] == pytest.approx(2 * 17 / 32, abs=0.05)
    axis, _ = strip_cuts(tm.geometry.Rectangle((0, 0), (1, 4)), lambda p: np.full(len(p), 0.1), 2)
    assert axis == 1


def _missing_a_cut_point_in_strip_1(monkeypatch):
    """Make the second strip mesh without the top point of the cut, as a strip whose cells fall short of it."""
    import terramesh.parallel.mesh_in_parts as parts_module

    whole = parts_module.separator_points

    def short_of_one(*args):
        points = whole(*args)
        return points[points[:, 1] < 0.9] if len(points) else points

    real = parts_module._mesh_strip

    def strip(domain, size, h0, axis, bounds, separators, *rest):
        if rest[1] == 1:
            separators = [short_of_one(domain, size, h0, axis, bounds[1])]
        return real(domain, size, h0, axis, bounds, separators, *rest)

    monkeypatch.setattr(parts_module, "_mesh_strip", strip)
    return parts_module


def _spy_on_the_stitch(monkeypatch, parts_module):
    """Record the merged strips (``points``, ``cells``) and the ``seam`` given to the stitch, and its arguments."""
    merged = {}
    real = parts_module._stitched

    def spy(domain, size, h0, tolerance, fixed, mesh, seam, *rest):
        merged.update(points=mesh.points, cells=mesh.cells, seam=seam)
        merged["arguments"] = (domain, size, h0, tolerance, fixed, mesh, seam, *rest)
        return real(domain, size, h0, tolerance, fixed, mesh, seam, *rest)

    monkeypatch.setattr(parts_module, "_stitched", spy)
    return merged


def test_strips_that_do_not_meet_are_stitched_near_the_mismatch(monkeypatch):
    parts_module = _missing_a_cut_point_in_strip_1(monkeypatch)
    merged = _spy_on_the_stitch(monkeypatch, parts_module)
    disk = tm.geometry.Disk((0, 0), 1)
    mesh = generate_mesh_parallel(disk, 0.05, parts=2)
    # the first strip's vertex at the cut's top point lay off the boundary, with the edges beside it
    assert mesh.info["stitched"] >= 1 and np.all(np.abs(merged["seam"][:, 0] - mesh.info["cuts"][0]) < 1e-3 * 0.05)
    assert_like_a_whole_mesh(mesh, tm.generate_mesh(disk, 0.05, seed=0), disk, 0.05)
    # only the cells about the seam were meshed anew: vertices and cells 4 sizes away and more are the strips'
    # own (meshing all the points anew, the far vertices held, changed 76 cells 4 sizes away)
    reach = (parts_module.SEAM_REACH + 1.0) * 0.05
    far = np.min(np.linalg.norm(mesh.points[:, None] - merged["seam"][None], axis=2), axis=1) > reach
    old = {tuple(point) for point in merged["points"]}
    assert far.sum() > 0.8 * mesh.n_points
    assert all(tuple(point) in old for point in mesh.points[far])
    assert_far_cells_kept(mesh, merged, reach)
    assert mesh.info["remeshed"] is False


def assert_far_cells_kept(mesh, merged, reach):
    """Every cell of ``mesh`` farther than ``reach`` from the seam is a cell of the merged strips, to the bit.

    ``reach`` is a length, or a callable giving it at the cells' centroids.
    """
    centroids = mesh.points[mesh.cells].mean(axis=1)
    reach = reach(centroids) if callable(reach) else reach
    far = np.min(np.linalg.norm(centroids[:, None] - merged["seam"][None], axis=2), axis=1) > reach
    old = {frozenset(map(tuple, corners)) for corners in merged["points"][merged["cells"]]}
    assert far.sum() > 0.8 * len(mesh.cells)
    assert all(frozenset(map(tuple, corners)) in old for corners in mesh.points[mesh.cells[far]])


def _rough_coast():
    """A rough random-walk coast and a size graded across it (0.03 to about 0.1)."""
    coast = random_walk_coast(1500, 101, roughness=1.0, smallest_radius=0.2)

    def size(p):
        return 0.03 + 0.05 * np.abs(p[:, 1] + 0.3 * p[:, 0])

    return coast, size


def test_a_rough_coast_in_five_strips_is_stitched_in_a_patch(monkeypatch):
    # five vertices where the strips do not meet; meshing all the points anew (the far ones held) made a
    # cell of quality 0.021 and changed 20 % of the cells more than 4 sizes away
    import terramesh.parallel.mesh_in_parts as parts_module

    merged = _spy_on_the_stitch(monkeypatch, parts_module)
    coast, size = _rough_coast()
    mesh = generate_mesh_parallel(coast, size, h0=0.03, parts=5, seed=1)
    assert mesh.info["stitched"] >= 3
    assert_valid(mesh, coast, 0.03)
    quality = triangle_quality(mesh.points, mesh.cells)
    assert quality.min() > 0.25 and quality.mean() > 0.96  # the strips' own: 0.33 and 0.965
    assert 0.9 < np.median(edge_length_ratio(mesh.points, mesh.cells, size)) < 1.1
    assert_far_cells_kept(mesh, merged, lambda at: (parts_module.SEAM_REACH + 1.0) * size(at))
    again = parts_module._stitched(*merged["arguments"])
    np.testing.assert_array_equal(again.points, mesh.points)
    np.testing.assert_array_equal(again.cells, mesh.cells)


def test_strips_that_touch_at_a_point_of_a_cut_only_are_stitched():
    # the second cut crosses a neck of the coast where the strips' cells meet at one vertex, on the coast:
    # no vertex lay off it, so nothing was stitched and the mesh came back pinched there (invalid). The
    # first patch's cells do not join the kept ones across the coast's spikes of water; a wider one does
    coast, size = _rough_coast()
    mesh = generate_mesh_parallel(coast, size, h0=0.03, parts=4, seed=1)
    assert_valid(mesh, coast, 0.03)
    # the neck, and the third cut's two pieces of 0.16 and 0.20 sizes, which get no points (SHORTEST_PIECE):
    # the stitch there leaves a cell of 0.377 (0.47 when they were held)
    assert mesh.info["stitched"] == 2
    assert triangle_quality(mesh.points, mesh.cells).min() > 0.35


def test_a_patch_that_does_not_join_is_stitched_from_all_the_points(monkeypatch):
    parts_module = _missing_a_cut_point_in_strip_1(monkeypatch)
    tries = []

    def never(domain, tolerance, mesh, *rest):
        tries.append(1)
        return None, np.empty((0, 2))

    monkeypatch.setattr(parts_module, "_joined", never)
    merged = _spy_on_the_stitch(monkeypatch, parts_module)
    disk = tm.geometry.Disk((0, 0), 1)
    mesh = generate_mesh_parallel(disk, 0.05, parts=2)
    assert len(tries) == parts_module.PATCH_TRIES
    assert_like_a_whole_mesh(mesh, tm.generate_mesh(disk, 0.05, seed=0), disk, 0.05)
    # every point free: held far from the seam, the Danish straits in 6 strips kept a cap of q 0.09 at the coast
    assert mesh.info["remeshed"] is True and "seam" in merged


def test_strips_that_stay_apart_are_refused(monkeypatch):
    parts_module = _missing_a_cut_point_in_strip_1(monkeypatch)
    monkeypatch.setattr(parts_module, "_stitched", lambda domain, size, h0, tolerance, fixed, mesh, *rest: mesh)
    with pytest.raises(GenerationError, match="do not meet vertex for vertex along the cut at x = "):
        generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.05, parts=2)


def test_a_jagged_coast_in_strips_is_stitched_where_a_cut_crosses_it_badly():
    # headlands narrower than the size: a strip's cells fell short of its cut (14 of 72 runs on such coasts
    # in 2-4 strips raised); the crack is now meshed anew from both strips' points (this coast: two cracks)
    coast = random_walk_coast(1000, 20)
    whole = tm.generate_mesh(coast, 0.06, seed=0)
    mesh = generate_mesh_parallel(coast, 0.06, parts=2)
    assert mesh.info["stitched"] > 0
    assert_valid(mesh, coast, 0.06)
    assert mesh.n_points == pytest.approx(whole.n_points, rel=0.03)
    assert triangle_quality(mesh.points, mesh.cells).min() > 0.5  # whole: 0.71 (a jagged coast)
    assert tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum() == pytest.approx(
        tm.mesh.topology.signed_areas(whole.points, whole.cells).sum(), rel=0.01
    )


def test_cuts_crowded_by_a_graded_size_stay_in_order_inside_the_bbox():
    # sizes 31x smaller at the right: the balanced cuts crowd there, and moving the last one by up to
    # three tenths of the mean strip width, away from the jagged coast, took it past the bbox (the last
    # strip's box was inverted)
    coast = random_walk_coast(1000, 1)
    low, high = coast.bbox

    def size(p):
        return 0.04 * (1 + 30 * (high[0] - p[:, 0]) / (high[0] - low[0]))

    for parts in (3, 5):
        axis, cuts = strip_cuts(coast, size, parts, h0=0.04)
        assert axis == 0 and np.all(np.diff(cuts) > 0) and low[0] < cuts[0] and cuts[-1] < high[0]


def test_a_strip_that_cannot_be_meshed_is_named(monkeypatch):
    import terramesh.parallel.mesh_in_parts as parts_module

    real = parts_module.generate_mesh

    def failing(domain, *args, seed, **kwargs):
        if seed == 1:
            raise GenerationError("no cell survived: the domain is too small or thin for the mesh size")
        return real(domain, *args, seed=seed, **kwargs)

    monkeypatch.setattr(parts_module, "generate_mesh", failing)
    with pytest.raises(
        GenerationError, match=r"^strip 1 of 2 \(x [-.0-9e]+ to 1\): no cell survived.*fewer parts may do$"
    ):
        generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=2)


def test_strips_narrower_than_the_size_are_warned_of():
    disk = tm.geometry.Disk((0, 0), 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        generate_mesh_parallel(disk, 0.1, parts=10)  # the narrowest strip 1.5 sizes wide: min q 0.80 (whole 0.83)
    # 0.8 sizes: min q 0.71 (at 0.2 sizes, 80 strips, min q 0.23 and no word of it)
    with pytest.warns(TerrameshWarning, match=r"^18 of 20 strips are narrower than 1.5 sizes, e.g. strip 1\d \(x "):
        generate_mesh_parallel(disk, 0.1, parts=20)


def test_one_part_is_generate_mesh():
    coast = random_walk_coast(1_000, seed=3)
    size = lambda p: 0.04 * (1 + 0.7 * (1.5 + p @ np.array([-0.57, 0.82])) / 3)  # noqa: E731
    whole = tm.generate_mesh(coast, size, h0=0.04, seed=5, levels=0)
    in_one_part = generate_mesh_parallel(coast, size, h0=0.04, parts=1, seed=5, levels=0)
    assert np.array_equal(in_one_part.points, whole.points) and np.array_equal(in_one_part.cells, whole.cells)


def test_one_part_raises_what_generate_mesh_raises():
    """One part is the whole domain: no strip to name, no fewer parts to try (sweep run 40122 said both)."""
    thin = tm.geometry.Rectangle((0, 0), (1, 0.05))
    with pytest.raises(GenerationError) as whole:
        tm.generate_mesh(thin, 0.5)
    with pytest.raises(GenerationError) as in_one_part:
        generate_mesh_parallel(thin, 0.5, parts=1)
    assert str(in_one_part.value) == str(whole.value)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: generate_mesh_parallel(tm.geometry.Ball((0, 0, 0), 1), 0.2, parts=2), "when they are a box"),
        (lambda: generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=0), "positive integer"),
        (lambda: generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=1.5), "positive integer"),
        # 2.0 passed the check and raised a TypeError in range(); True was one strip
        (lambda: generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=2.0), "positive integer"),
        (lambda: generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=True), "positive integer"),
        (lambda: strip_cuts(tm.geometry.Disk((0, 0), 1), as_size_function(0.1), 2.0), "positive integer"),
        # not "strip 0 of 2 ...: seed must be ...; fewer parts may do"
        (lambda: generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=2, seed=-1), "^seed must be a non-"),
        (lambda: generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=2, bogus=1), "unknown option 'bogus'"),
    ],
)
def test_bad_inputs(call, message):
    with pytest.raises(GenerationError, match=message):
        call()


MPI_SCRIPT = textwrap.dedent(
    """
    import sys
    import numpy as np
    from mpi4py import MPI
    import terramesh as tm

    mesh = tm.parallel.generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.02, comm=MPI.COMM_WORLD)
    if MPI.COMM_WORLD.Get_rank() == 0:
        ranks = [strip["rank"] for strip in mesh.info["parts"]]
        np.savez(sys.argv[1], points=mesh.points, cells=mesh.cells, ranks=ranks)
    else:
        assert mesh is None
    """
)


def on_two_ranks(tmp_path, text, output, timeout, check=True):
    """Run the script ``text`` under ``mpiexec -n 2``, its first argument ``output`` (a path under tmp_path).

    With ``check`` a rank that fails fails the test; without, the run is
    returned with its output captured.
    """
    pytest.importorskip("mpi4py")  # the "mpi" extra; the test extra installs it
    launcher = shutil.which("mpiexec", path=os.path.dirname(sys.executable)) or shutil.which("mpiexec")
    assert launcher, "mpi4py is installed but mpiexec is not (pip install mpich)"
    script = tmp_path / "script.py"
    script.write_text(text)
    command = [launcher, "-n", "2", sys.executable, str(script), str(output)]
    return subprocess.run(command, check=check, timeout=timeout, capture_output=not check, text=True)


def test_mpi_ranks_mesh_the_strips_and_rank_0_gets_the_same_mesh(tmp_path):
    assert_mpi_as_serial(tmp_path, MPI_SCRIPT, generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.02, parts=2))


def assert_mpi_as_serial(tmp_path, script, serial):
    """``script`` on two ranks saved the mesh rank 0 got, whose parts came from ranks 0 and 1: ``serial``'s."""
    result = tmp_path / "mesh.npz"
    on_two_ranks(tmp_path, script, result, timeout=300)
    mpi = np.load(result)
    assert mpi["ranks"].tolist() == [0, 1]
    np.testing.assert_array_equal(mpi["points"], serial.points)
    np.testing.assert_array_equal(mpi["cells"], serial.cells)


FAILING_SCRIPT = textwrap.dedent(
    """
    import sys
    from mpi4py import MPI
    import terramesh as tm
    import terramesh.parallel.{module} as parts_module

    rank = MPI.COMM_WORLD.Get_rank()
    if rank == 1:
        def broken(*args):
            raise ValueError("no memory left, say")
        parts_module.{meshes_a_part} = broken
    try:
        tm.parallel.generate_mesh_parallel({domain}, {size}, comm=MPI.COMM_WORLD)
    except tm.errors.GenerationError as error:
        open(f"{{sys.argv[1]}}.{{rank}}", "w").write(str(error))
    """
)


def assert_a_part_failing_on_one_rank_makes_every_rank_raise(tmp_path, part, **script):
    """Rank 1's part raises in ``FAILING_SCRIPT`` filled with ``script``: both ranks raise, naming ``part`` 1 of 2."""
    # before, rank 0 waited in the gather for ever: the timeout would fire
    on_two_ranks(tmp_path, FAILING_SCRIPT.format(**script), tmp_path / "error", timeout=120)
    for rank in (0, 1):
        message = (tmp_path / f"error.{rank}").read_text()
        assert message.startswith(f"meshing in parts failed: {part} 1 of 2 (")
        assert message.endswith(" on rank 1: ValueError: no memory left, say")


def test_a_strip_failing_on_one_rank_makes_every_rank_raise(tmp_path):
    domain, module, function = "tm.geometry.Disk((0, 0), 1)", "mesh_in_parts", "_mesh_strip"
    assert_a_part_failing_on_one_rank_makes_every_rank_raise(
        tmp_path, "strip", module=module, meshes_a_part=function, domain=domain, size=0.05
    )


SIZE_FAILING_SCRIPT = textwrap.dedent(
    """
    import sys
    import numpy as np
    from mpi4py import MPI
    import terramesh as tm

    rank = MPI.COMM_WORLD.Get_rank()

    def size(p):
        if rank == 1:
            raise MemoryError("no memory left on rank 1, say")
        return np.full(len(p), 0.2)

    try:
        tm.parallel.generate_mesh_parallel({domain}, size, h0=0.2, comm=MPI.COMM_WORLD)
    except Exception as error:
        open(f"{{sys.argv[1]}}.{{rank}}", "w").write(f"{{type(error).__name__}}: {{error}}")
        raise
    """
)


def assert_a_size_failing_on_one_rank_before_the_parts_makes_every_rank_raise(tmp_path, domain):
    """The size raises on rank 1 alone in ``SIZE_FAILING_SCRIPT`` for ``domain``: both ranks fail, saying so at once."""
    # the sizes place the cuts, before the parts are shared out: rank 1 raised there alone, and rank 0 meshed its
    # part and waited in the gather for ever (the timeout fired; it fails in under 2 s)
    run = on_two_ranks(tmp_path, SIZE_FAILING_SCRIPT.format(domain=domain), tmp_path / "error", 60, check=False)
    assert run.returncode != 0
    said = "meshing in parts failed: the cuts on rank 1: MemoryError: no memory left on rank 1, say"
    assert [(tmp_path / f"error.{rank}").read_text() for rank in (0, 1)] == [f"GenerationError: {said}"] * 2
    assert said in run.stderr


def test_a_size_failing_on_one_rank_before_the_strips_makes_every_rank_raise(tmp_path):
    assert_a_size_failing_on_one_rank_before_the_parts_makes_every_rank_raise(
        tmp_path, "tm.geometry.Rectangle((0, 0), (2, 1))"
    )


def test_strips_of_a_union_mesh_across_the_face_its_operands_share():
    # the strips are intersections with the union, whose distance reads zero on the shared face x = 1:
    # cells with their centroid there were dropped, a crack 0.03 h wide (area 1.99914)
    halves = tm.geometry.Rectangle((0, 0), (1, 1)) | tm.geometry.Rectangle((1, 0), (2, 1))
    x, y = np.linspace(-0.2, 2.2, 60), np.linspace(-0.2, 1.2, 50)
    size = tm.sizing.SizeGrid((x, y), 0.03 * (1 + 0.8 * np.sin(1.5 * np.meshgrid(x, y, indexing="ij")[0]) ** 2))
    for parts, seed in ((2, 2), (5, 3)):
        mesh = generate_mesh_parallel(halves, size, parts=parts, h0=0.03, seed=seed)
        assert_valid(mesh, halves, 0.03)
        assert tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum() == pytest.approx(2.0, abs=1e-5)
        edges = tm.mesh.topology.boundary_edges(mesh.cells)
        assert not np.any(np.all(np.abs(mesh.points[edges][:, :, 0] - 1.0) < 1e-9, axis=1))


def test_a_coastline_in_two_to_six_strips(shared_data):
    # GSHHS around Cape Cod at 0.03 degrees: cuts at the balanced places ran along the coast at a
    # shallow angle (a cut point 0.3 h inside the water that one strip's cells fell short of), crossed
    # a strip of land 0.07 h wide (min q 0.11), or had a segment a strip split with a point of its own
    # (an ulp off the other's); 14 of 33 such runs raised
    shore = tm.coastal.Shoreline.read(shared_data / "coast" / "GSHHS_l_L1.shp", (-72, -69, 41, 43), 5e3)
    water = tm.geometry.Polygon.from_shapely(shore.water)
    whole = tm.generate_mesh(water, 0.03, seed=0)
    for parts in range(2, 7):
        mesh = generate_mesh_parallel(water, 0.03, parts=parts, h0=0.03)
        assert_valid(mesh, water, 0.03)
        assert mesh.n_points == pytest.approx(whole.n_points, rel=0.05)
        assert triangle_quality(mesh.points, mesh.cells).min() > 0.72  # whole: 0.81; 2-6 strips 0.74-0.81


@pytest.mark.parametrize("parts", [3, 5])
def test_cells_at_the_cuts_of_graded_strips_are_polished(parts):
    # Persson's two circles: each strip's cells settle against the cut's fixed points, and with sizes changing
    # along the cut they stayed poor (min q 0.68 in 3 strips, 0.44 in 5; whole 0.80)
    outer, inner = tm.geometry.Disk((0, 0), 1), tm.geometry.Disk((-0.4, 0), 0.55)
    domain = tm.geometry.Difference([outer, inner])

    def size(p):
        return np.minimum(
            np.minimum(0.15 - 0.2 * outer.distance(p), 0.06 + 0.2 * inner.distance(p)),
            (inner.distance(p) - outer.distance(p)) / 3,
        )

    mesh = generate_mesh_parallel(domain, size, parts=parts, h0=0.005, seed=0)
    assert tm.cleanup.mesh_problems(mesh, domain) == []
    assert triangle_quality(mesh.points, mesh.cells).min() > 0.75


NARROW_SCRIPT = textwrap.dedent(
    """
    import sys
    import warnings
    from mpi4py import MPI
    import terramesh as tm

    warnings.simplefilter("error")  # as pytest's settings and python -W error make it
    rank = MPI.COMM_WORLD.Get_rank()
    try:
        tm.parallel.generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=16, comm=MPI.COMM_WORLD)
        said = "returned"
    except tm.errors.TerrameshWarning as warning:
        said = str(warning)
    with open(f"{sys.argv[1]}.{rank}", "w") as out:
        out.write(said)
    """
)


def test_the_narrow_strips_warning_raised_as_an_error_strands_no_rank(tmp_path):
    # rank 0 warned before the gather: raised as an error, it never got there, and rank 1 waited for ever.
    # Now every rank raises it, before the strips are meshed
    on_two_ranks(tmp_path, NARROW_SCRIPT, tmp_path / "out", timeout=120)
    for rank in (0, 1):
        assert "strips are narrower than 1.5 sizes" in (tmp_path / f"out.{rank}").read_text()


WARNED_SCRIPT = textwrap.dedent(
    """
    import sys
    import warnings
    from mpi4py import MPI
    import terramesh as tm

    rank = MPI.COMM_WORLD.Get_rank()
    raised = sys.argv[2] == "error"
    warnings.simplefilter("error" if raised else "always")  # python -W error, or every warning recorded
    with warnings.catch_warnings(record=not raised) as caught:
        try:
            tm.parallel.generate_mesh_parallel(
                tm.geometry.Rectangle((0, 0), (2, 1)), 0.1, h0=0.2, comm=MPI.COMM_WORLD, fixed_points=[[0.5, 0.01]]
            )
            said = [str(warning.message) for warning in caught] if caught is not None else ["returned"]
        except tm.errors.TerrameshWarning as warning:
            said = [str(warning)]
    with open(f"{sys.argv[1]}.{rank}", "w") as out:
        out.write("\\n".join(said))
    """
)


@pytest.mark.parametrize("filter_", ["error", "always"])
def test_warnings_before_the_strips_are_said_once_and_raised_on_every_rank(tmp_path, filter_):
    # a fixed point 0.1 sizes inside the boundary: rank 0 alone warned, before the gather; with -W error it
    # raised there and rank 1 waited in the gather for ever (the timeout fired). The strips' own warning of
    # sizes below h0 was said by each strip, on its rank
    script = WARNED_SCRIPT.replace("sys.argv[2]", repr(filter_))
    on_two_ranks(tmp_path, script, tmp_path / "out", timeout=120)
    said = [(tmp_path / f"out.{rank}").read_text().split("\n") for rank in (0, 1)]
    fixed = "1 fixed points lie less than half a size inside the boundary, e.g. (0.5, 0.01)"
    if filter_ == "error":
        assert all(len(lines) == 1 and lines[0].startswith(fixed) for lines in said)
    else:
        assert said[1] == [""]  # rank 1 says nothing: rank 0 says each warning once
        assert len(said[0]) == 2 and said[0][0].startswith(fixed)
        assert said[0][1] == "edge_length goes down to 0.1, below h0=0.2: the mesh will not be finer than h0"


COASTAL_SCRIPT = textwrap.dedent(
    """
    import sys
    import numpy as np
    from mpi4py import MPI
    import terramesh as tm

    shoreline, output = sys.argv[2], sys.argv[1]
    mesh = tm.coastal.build(
        (-71.0, -69.0, 41.0, 43.0), shoreline, min_el=4000, fs=3, comm=MPI.COMM_WORLD,
        fixed_points=[[-70.3, 42.6], [-69.5, 41.6]],
    )
    if MPI.COMM_WORLD.Get_rank() == 0:
        open_nodes = np.concatenate([b.nodes for b in mesh.boundaries.open])
        np.savez(output, points=mesh.points, cells=mesh.cells, fixed=mesh.info["fixed_points"], open=open_nodes)
    else:
        assert mesh is None
    """
)


def test_a_coastal_build_on_two_ranks_is_the_build_in_two_parts(tmp_path, shared_data):
    # build(comm=) with fixed points and boundaries was tested serially only
    shoreline = shared_data / "coast" / "GSHHS_l_L1.shp"
    result = tmp_path / "coast.npz"
    script = COASTAL_SCRIPT.replace("sys.argv[2]", repr(str(shoreline)))
    on_two_ranks(tmp_path, script, result, timeout=300)
    mpi = np.load(result)
    serial = tm.coastal.build(
        (-71.0, -69.0, 41.0, 43.0), shoreline, min_el=4000, fs=3, parts=2, fixed_points=[[-70.3, 42.6], [-69.5, 41.6]]
    )
    np.testing.assert_array_equal(mpi["points"], serial.points)
    np.testing.assert_array_equal(mpi["cells"], serial.cells)
    np.testing.assert_array_equal(mpi["fixed"], serial.info["fixed_points"])
    np.testing.assert_array_equal(mpi["open"], np.concatenate([b.nodes for b in serial.boundaries.open]))
    np.testing.assert_array_equal(serial.points[serial.info["fixed_points"]], [[-70.3, 42.6], [-69.5, 41.6]])


@pytest.mark.parametrize("parts", [2, 3])
def test_a_receiver_line_across_the_cuts_keeps_its_edges(parts):
    # the cut's own fixed points landed a third of a size from the receivers: edges of 0.31 and 0.28 sizes
    # (0.58 whole), which halve an explicit solver's time step
    domain = tm.geometry.Rectangle((0.0, 0.0), (2.0, 1.0))
    receivers = np.column_stack([np.linspace(0.1, 1.9, 60), np.full(60, 0.5)])  # 0.61 sizes apart
    mesh = generate_mesh_parallel(domain, 0.05, parts=parts, fixed_points=receivers)
    assert_valid(mesh, domain, 0.05)
    assert all(np.any(np.all(mesh.points == receiver, axis=1)) for receiver in receivers)
    edges = tm.mesh.topology.unique_edges(mesh.cells)
    shortest = np.linalg.norm(mesh.points[edges[:, 0]] - mesh.points[edges[:, 1]], axis=1).min()
    whole = tm.generate_mesh(domain, 0.05, fixed_points=receivers)
    whole_edges = tm.mesh.topology.unique_edges(whole.cells)
    whole_shortest = np.linalg.norm(whole.points[whole_edges[:, 0]] - whole.points[whole_edges[:, 1]], axis=1).min()
    assert shortest > 0.85 * whole_shortest and triangle_quality(mesh.points, mesh.cells).min() > 0.78


def test_a_fixed_point_too_close_to_the_boundary_is_named_not_the_cut():
    # a gauge 0.009 inside the side at h 0.1 is a boundary vertex off the boundary in its strip (a notch), which
    # no stitch mends: the error blamed the cut at x = 0.67, a third of the box away
    square = tm.geometry.Rectangle((0, 0), (2, 1))
    with pytest.raises(GenerationError, match=r"the fixed point \[0.5, 0.009\] lies 0.09 sizes inside the boundary"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TerrameshWarning)
            generate_mesh_parallel(square, 0.1, parts=3, fixed_points=[(0.5, 0.009)])


@pytest.mark.parametrize(("h", "parts"), [(0.05, 2), (0.052, 4)])
@pytest.mark.parametrize("as_callable", [False, True])
def test_a_cut_on_the_face_two_operands_of_a_union_share_moves_off_it(h, parts, as_callable):
    # the distance reads zero on the face x = 1, y 0.5 to 1: the cut there found no point inside, was scored
    # clear of the boundary and stayed; each strip put its own vertices along the face and the merge joined
    # them with slivers (min q 0.011 and 0.081, whole 0.80) with no word
    low, high = tm.geometry.Rectangle((0, 0), (1, 1)), tm.geometry.Rectangle((1, 0.5), (2, 1.5))
    union = low | high
    domain = tm.geometry.FunctionDomain(lambda p: np.minimum(low.distance(p), high.distance(p)), union.bbox)
    mesh = generate_mesh_parallel(domain if as_callable else union, h, parts=parts, seed=0)
    assert_valid(mesh, union, h)
    assert triangle_quality(mesh.points, mesh.cells).min() > 0.75
    # the callable reports no corners: its re-entrant ones are cut a little, as in the whole domain's mesh
    area = tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum()
    assert area == pytest.approx(2.0, abs=3e-3 if as_callable else 1e-8)
    points = separator_points(union, as_size_function(h), h, 0, 1.0)  # the face itself is inside: a piece
    assert len(points) > 5 and points[:, 1].min() == pytest.approx(0.5) and points[:, 1].max() == pytest.approx(1.0)


def test_strips_joined_by_slivers_at_a_cut_are_warned_of(monkeypatch):
    # a domain whose distance reads zero on a face inside it, that the cut's pieces are not looked for
    # on (as before): the merged cells at the cut, min q 0.011 where the strips' own were 0.80, passed silently
    import terramesh.parallel.decompose as decompose

    monkeypatch.setattr(decompose, "_inside", lambda domain, axis, points, spacing: domain.distance(points) < 0)
    union = tm.geometry.Rectangle((0, 0), (1, 1)) | tm.geometry.Rectangle((1, 0.5), (2, 1.5))
    with pytest.warns(TerrameshWarning, match=r"^cells where the strips meet at the cut x = 1 reach quality 0\.0"):
        generate_mesh_parallel(union, 0.05, parts=2, seed=0)


@pytest.mark.parametrize("parts", [10**9, 99999999999999999999, 5000, 40])
def test_more_parts_than_the_domain_can_take_are_refused_at_once(parts):
    # a raw MemoryError (1e9), a raw ValueError (1e20), a run of minutes (5000) on a disk of about 300 vertices
    started = time.perf_counter()
    with pytest.raises(GenerationError, match=rf"^parts={parts} is more strips than .*: at most 39 \(strips"):
        generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=parts)
    assert time.perf_counter() - started < 2.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TerrameshWarning)  # narrow strips
        assert len(generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=39).info["parts"]) == 39


@pytest.mark.parametrize("parts", [2, 4])
def test_a_strips_warning_the_merge_resolves_is_not_said(parts):
    # a slot 0.4 sizes wide by a cut: a strip warned of "1 boundary vertices ... off the domain's boundary after
    # 10 repair passes ... give it as a fixed point", though the merged mesh's lay within 2e-9 of it
    domain = tm.geometry.Rectangle((0, 0), (4, 1)) - tm.geometry.Rectangle((1.99, 0.05), (2.01, 1.1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = generate_mesh_parallel(domain, 0.05, parts=parts, seed=2)
    assert_valid(mesh, domain, 0.05)


def test_a_strips_warning_that_holds_is_said_once():
    # every strip warned of its sizes below h0, three times over
    with pytest.warns(TerrameshWarning) as said:
        generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, h0=0.2, parts=3)
    assert [str(warning.message) for warning in said] == [
        "edge_length goes down to 0.1, below h0=0.2: the mesh will not be finer than h0"
    ]


def test_a_users_fixed_point_the_strips_cannot_keep_is_warned_of_once():
    # the strips' own warnings of their cut points are muted; the merged mesh is asked of the user's points
    def in_strips(domain, fixed):
        return generate_mesh_parallel(domain, 0.02, parts=2, seed=0, fixed_points=fixed)

    mesh, dropped = wedge_with_its_tip_fixed(in_strips, 6)
    assert len(dropped) == 1 and "first at (0, 0)" in dropped[0]
    assert not np.any(np.all(mesh.points == 0.0, axis=1)) and np.any(np.all(mesh.points == (0.5, 0.0), axis=1))


@pytest.mark.parametrize("parts", [1, 3])
def test_a_hole_smaller_than_the_cells_is_said_once_whatever_the_parts(parts):
    # a strip is the domain cut by a rectangle, which cannot say its rings: the merged mesh is looked at
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    hole = [(0.5, 0.52), (0.52, 0.52), (0.52, 0.5), (0.5, 0.5)]
    with pytest.warns(TerrameshWarning) as caught:
        tm.parallel.generate_mesh_parallel(tm.geometry.Polygon([square, hole]), 0.1, parts=parts)
    said = [str(warning.message) for warning in caught]
    assert len(said) == 1 and "1 hole covered by cells (the longest 0.02 long, near (0.51, 0.51)" in said[0], said
