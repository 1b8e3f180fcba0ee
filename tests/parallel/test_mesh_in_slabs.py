"""Meshing a 3D box in slabs: the merged mesh against one made whole, the cuts, and MPI against one process."""

import textwrap
import warnings

import numpy as np
import pytest

import terramesh as tm
import terramesh.parallel.mesh_in_slabs as slabs_module
from terramesh.errors import GenerationError, TerrameshWarning
from terramesh.geometry.primitives3d import Ball, Box
from terramesh.parallel import generate_mesh_parallel
from terramesh.parallel.mesh_in_slabs import section_points, slab_cuts
from terramesh.quality.tetra import min_max_dihedral, radius_ratio

from ..generation.test_distmesh3d import assert_follows_box, assert_valid
from .test_mesh_in_parts import (
    assert_a_part_failing_on_one_rank_makes_every_rank_raise,
    assert_a_size_failing_on_one_rank_before_the_parts_makes_every_rank_raise,
    assert_mpi_as_serial,
)

BOX = Box((0, 0, 0), (2, 1, 1))


def graded(p):
    """Finer at the bottom and about x = 1.6: h 0.07 to 0.2."""
    return 0.1 * (1 + 1.5 * p[:, 2]) * (1 + 0.3 * np.sin(3 * p[:, 0]))


@pytest.fixture(scope="module")
def whole():
    return tm.generate_mesh(BOX, graded, h0=0.07, seed=0)


def assert_like_the_whole_mesh(mesh, whole, box=BOX):
    assert_valid(mesh, box, 0.07, volume=float(np.prod(np.diff(box.bbox, axis=0))), rel=1e-9)
    assert_follows_box(mesh, box)  # no face of a cut is left on the boundary: the slabs meet face for face
    assert mesh.n_points == pytest.approx(whole.n_points, rel=0.05)
    # the cells along a cut are a little poorer: its section's points hold still in both slabs (three slabs of
    # about 500 vertices: mean radius ratio 0.859 against 0.878)
    assert radius_ratio(mesh.points, mesh.cells).mean() == pytest.approx(
        radius_ratio(whole.points, whole.cells).mean(), abs=0.025
    )


@pytest.mark.parametrize("parts", [2, 3])
def test_slabs_of_a_graded_box_merge_into_one_valid_mesh(whole, parts, monkeypatch):
    mesh = generate_mesh_parallel(BOX, graded, parts=parts, h0=0.07)
    assert_like_the_whole_mesh(mesh, whole)
    info = mesh.info
    assert info["axis"] == 0 and len(info["cuts"]) == parts - 1 and not info["remeshed"]
    assert len(info["parts"]) == parts and all(part["rank"] == 0 for part in info["parts"])
    # unpolished, each cut's section is in the mesh, its points shared by the slabs on both sides, none other on
    # the plane; the polish moves vertices near the cuts (some of those on them too), and no cell gets worse
    monkeypatch.setattr(slabs_module, "CUT_POLISH", 0.0)
    merged = generate_mesh_parallel(BOX, graded, parts=parts, h0=0.07)
    assert_like_the_whole_mesh(merged, whole)
    np.testing.assert_array_equal(merged.cells, mesh.cells)
    moved = np.any(merged.points != mesh.points, axis=1)
    assert moved.any()
    before, after = (
        radius_ratio(m.points, m.cells[np.isin(m.cells, np.flatnonzero(moved)).any(axis=1)]) for m in (merged, mesh)
    )
    assert after.min() >= before.min() and after.mean() > before.mean()
    for cut in info["cuts"]:
        section = section_points(BOX, graded, 0.07, 0, cut)
        on_plane = merged.points[merged.points[:, 0] == cut]
        assert sorted(map(tuple, on_plane)) == sorted(map(tuple, section))
        beside = np.isin(merged.cells, np.flatnonzero(merged.points[:, 0] == cut)).any(axis=1)
        centres = merged.points[merged.cells[beside]].mean(axis=1)[:, 0]
        assert (centres < cut).any() and (centres > cut).any()


def test_the_same_seed_gives_the_same_mesh():
    first, second = (generate_mesh_parallel(BOX, graded, parts=2, h0=0.07, seed=3) for _ in range(2))
    np.testing.assert_array_equal(first.points, second.points)
    np.testing.assert_array_equal(first.cells, second.cells)


def test_a_seismic_model_in_two_slabs():
    """A 3-D velocity model's sizes (a Box domain, a SizeGrid): meshed in slabs as whole, its padding included."""
    x, y, z = np.arange(21) * 200.0, np.arange(11) * 200.0, -np.arange(11)[::-1] * 200.0
    grid = np.stack(np.meshgrid(x, y, z, indexing="ij"), axis=-1)
    values = np.where(grid[..., 2] > -1000, 1500.0, 3000.0) + grid[..., 0] / 4
    model = tm.seismic.VelocityModel(values, (x, y, z))
    size = tm.seismic.size_function(model, frequency=1.5, hmin=100.0, grade=0.2, pad=400.0)
    whole = tm.generate_mesh(size.domain, size, seed=0)
    mesh = generate_mesh_parallel(size.domain, size, parts=2)
    assert_like_the_whole_mesh(mesh, whole, size.domain)
    edges = tm.mesh.topology.unique_edges(mesh.cells)
    middles = mesh.points[edges].mean(axis=1)
    ratio = np.linalg.norm(np.diff(mesh.points[edges], axis=1)[:, 0], axis=1) / size(middles)
    assert 0.9 < np.median(ratio) < 1.1


def test_slab_cuts_share_the_estimated_vertex_count():
    axis, cuts = slab_cuts(BOX, graded, 4)
    bounds = np.concatenate([[0.0], cuts, [2.0]])
    counts = []
    rng = np.random.default_rng(0)
    sample = rng.random((200_000, 3)) * [2, 1, 1]
    for low, high in zip(bounds[:-1], bounds[1:], strict=True):
        inside = sample[(sample[:, 0] >= low) & (sample[:, 0] < high)]
        counts.append(np.sum(1.0 / graded(inside) ** 3))
    assert axis == 0 and np.all(np.diff(cuts) > 0)
    assert np.ptp(counts) / np.mean(counts) < 0.05


def test_a_users_fixed_points_on_and_near_a_cut_are_vertices(whole):
    balanced = slab_cuts(BOX, graded, 2)[1][0]
    on_cut = (balanced, 0.5, 0.5)
    near_cut = (balanced + 0.013, 0.3, 0.7)  # the cut moves off it
    mesh = generate_mesh_parallel(BOX, graded, parts=2, h0=0.07, fixed_points=[on_cut])
    assert_like_the_whole_mesh(mesh, whole)
    assert mesh.info["cuts"] == [balanced]
    assert np.any(np.all(mesh.points == on_cut, axis=1))
    moved = generate_mesh_parallel(BOX, graded, parts=2, h0=0.07, fixed_points=[near_cut])
    assert_like_the_whole_mesh(moved, whole)
    assert abs(moved.info["cuts"][0] - near_cut[0]) >= slabs_module.FIXED_CLEARANCE * graded(np.array([near_cut]))[0]
    assert np.any(np.all(moved.points == near_cut, axis=1))


def test_slabs_that_do_not_meet_are_tetrahedralised_again_as_one(monkeypatch, whole):
    monkeypatch.setattr(slabs_module, "_faces_left_on_cuts", lambda *args: 3)
    with pytest.warns(TerrameshWarning, match="3 faces on the cuts x = .* belong to one slab only"):
        mesh = generate_mesh_parallel(BOX, graded, parts=2, h0=0.07)
    assert mesh.info["remeshed"]
    assert_like_the_whole_mesh(mesh, whole)


def test_one_part_is_generate_mesh_of_any_3d_domain():
    ball = Ball((0, 0, 0), 1.0)
    mesh = generate_mesh_parallel(ball, 0.3, parts=1, seed=2)
    alone = tm.generate_mesh(ball, 0.3, seed=2)
    np.testing.assert_array_equal(mesh.points, alone.points)
    np.testing.assert_array_equal(mesh.cells, alone.cells)
    assert mesh.info["cuts"] == [] and len(mesh.info["parts"]) == 1


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: generate_mesh_parallel(Ball((0, 0, 0), 1.0), 0.3, parts=2), "when they are a box .* not a Ball"),
        (lambda: generate_mesh_parallel(BOX, graded, parts=40, h0=0.07), r"parts=40 is more slabs .* at most \d+ "),
        (lambda: generate_mesh_parallel(BOX, graded, parts=0), "parts must be a positive integer, got 0"),
        (lambda: generate_mesh_parallel(BOX, graded, parts=2.0), "parts must be a positive integer, got 2.0"),
        (lambda: generate_mesh_parallel(BOX, graded, parts=2, bogus=1), "unknown option 'bogus'"),
    ],
)
def test_bad_inputs(call, message):
    with pytest.raises(GenerationError, match=message):
        call()


def test_cuts_moved_off_fixed_points_stay_in_order_where_the_slabs_are_thin():
    # a graded bar: the slabs at its fine end are a tenth of the slabs' mean; moved within a share of that mean,
    # a cut went past its neighbour and the mesh raised a GeometryError about a slab's bbox
    bar = Box((0, 0, 0), (30, 0.6, 0.6))

    def size(p):
        return np.minimum(0.06 + 0.3 * np.maximum(p[:, 0] - 1, 0), 0.6)

    balanced = slab_cuts(bar, size, 8)[1]
    near = [(balanced[2] + dx, 0.3, 0.3) for dx in (-0.01, 0.012)]
    moved = slab_cuts(bar, size, 8, near)[1]
    assert moved[2] != balanced[2] and np.all(np.diff(np.concatenate([[0.0], moved, [30.0]])) > 0)
    assert np.min(np.abs(moved[2] - np.array(near)[:, 0])) >= slabs_module.FIXED_CLEARANCE * 0.06
    crowded = [(balanced[2] + dx, 0.3, 0.3) for dx in np.arange(-0.11, 0.11, 0.02)]
    with pytest.raises(GenerationError, match="no place for the cut near x = 0.427.* mesh in fewer parts or in one"):
        slab_cuts(bar, size, 8, crowded)


def test_a_fixed_point_on_a_cut_and_on_the_box_moves_the_cut():
    # on a face of the box it would lie on a sharp edge of both slabs beside their own points there: two such
    # points 0.15 sizes apart made a slab refuse
    balanced = slab_cuts(BOX, graded, 2)[1][0]
    on_face = [(balanced, 0.0, 0.5), (balanced, 0.0, 0.52)]
    assert slab_cuts(BOX, graded, 2, on_face)[1][0] != balanced
    mesh = generate_mesh_parallel(BOX, graded, parts=2, h0=0.07, fixed_points=on_face)
    assert tm.cleanup.mesh_problems(mesh, BOX) == [] and not mesh.info["remeshed"]
    assert all(np.any(np.all(mesh.points == point, axis=1)) for point in on_face)


def test_a_fixed_point_no_cut_keeps_clear_of_is_refused():
    # fixed points every 0.02 along x about the balanced cut: no place within the window is half a size clear
    line = [(x, 0.5, 0.5) for x in np.arange(0.6, 1.8, 0.02)]
    with pytest.raises(GenerationError, match="no place for the cut near x = .* keeps 0.5 sizes clear of the fixed"):
        slab_cuts(BOX, graded, 2, line)


MPI_SCRIPT = textwrap.dedent(
    """
    import sys
    import numpy as np
    from mpi4py import MPI
    import terramesh as tm
    from terramesh.geometry.primitives3d import Box

    def graded(p):
        return 0.1 * (1 + 1.5 * p[:, 2]) * (1 + 0.3 * np.sin(3 * p[:, 0]))

    mesh = tm.parallel.generate_mesh_parallel(Box((0, 0, 0), (2, 1, 1)), graded, h0=0.07, comm=MPI.COMM_WORLD)
    if MPI.COMM_WORLD.Get_rank() == 0:
        ranks = [slab["rank"] for slab in mesh.info["parts"]]
        np.savez(sys.argv[1], points=mesh.points, cells=mesh.cells, ranks=ranks)
    else:
        assert mesh is None
    """
)


def test_mpi_ranks_mesh_the_slabs_and_rank_0_gets_the_same_mesh(tmp_path):
    assert_mpi_as_serial(tmp_path, MPI_SCRIPT, generate_mesh_parallel(BOX, graded, parts=2, h0=0.07))


def test_a_slab_failing_on_one_rank_makes_every_rank_raise(tmp_path):
    domain, module, function = "tm.geometry.primitives3d.Box((0, 0, 0), (2, 1, 1))", "mesh_in_slabs", "_mesh_slab"
    assert_a_part_failing_on_one_rank_makes_every_rank_raise(
        tmp_path, "slab", module=module, meshes_a_part=function, domain=domain, size=0.2
    )


def test_a_size_failing_on_one_rank_before_the_slabs_makes_every_rank_raise(tmp_path):
    assert_a_size_failing_on_one_rank_before_the_parts_makes_every_rank_raise(
        tmp_path, "tm.geometry.primitives3d.Box((0, 0, 0), (2, 1, 1))"
    )


def test_warnings_of_the_slabs_are_said_once():
    # a max_iter too small to converge warns in every slab: said once, after the merge
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        generate_mesh_parallel(BOX, graded, parts=3, h0=0.07, max_iter=3, levels=0)
    messages = [str(w.message) for w in caught if "max_iter" in str(w.message)]
    assert len(messages) == len(set(messages)) >= 1


def test_cells_along_the_cuts_are_smoothed(monkeypatch):
    # each slab's cells settled against its cuts' fixed points: along a cut they are poorer than elsewhere
    meshes = {}
    for reach in (0.0, slabs_module.CUT_POLISH):
        monkeypatch.setattr(slabs_module, "CUT_POLISH", reach)
        meshes[reach] = generate_mesh_parallel(BOX, graded, parts=2, h0=0.07)
    cut = meshes[0.0].info["cuts"][0]
    smallest, ratio = {}, {}
    for reach, mesh in meshes.items():
        centres = tm.mesh.topology.cell_centroids(mesh.points, mesh.cells)
        along = np.abs(centres[:, 0] - cut) < graded(centres)
        smallest[reach] = min_max_dihedral(mesh.points, mesh.cells[along])[0].min()
        ratio[reach] = radius_ratio(mesh.points, mesh.cells[along]).mean()
    polished = slabs_module.CUT_POLISH
    assert smallest[polished] >= smallest[0.0] and ratio[polished] > ratio[0.0] + 0.005


def test_a_section_that_cannot_be_meshed_is_named(monkeypatch):
    def refused(*args, **kwargs):
        raise GenerationError("a size too small, say")

    monkeypatch.setattr(slabs_module, "generate_mesh", refused)
    with pytest.raises(GenerationError, match=r"^the section at x = 1\.\d+: a size too small, say$"):
        generate_mesh_parallel(BOX, graded, parts=2, h0=0.07)


@pytest.mark.parametrize("near_face", [False, True])
def test_a_fixed_point_a_rounding_off_the_balanced_cut(near_face):
    # the vertex counts put the cut at 0.9999999999999952; a user's point at x = 1 takes it onto itself, unless it
    # is within half a size of a face (at 1e-5 from one, the section merged it into a point of its rim: lost)
    box, uniform = Box((0, 0, 0), (2, 1, 1)), lambda p: np.full(len(p), 0.1)
    balanced = slab_cuts(box, uniform, 2)[1][0]
    point = (1.0, 1e-5 if near_face else 0.5, 0.5)
    assert balanced != 1.0 and abs(balanced - 1.0) < 1e-12
    cut = slab_cuts(box, uniform, 2, [point])[1][0]
    assert (cut != 1.0) if near_face else (cut == 1.0)
    mesh = generate_mesh_parallel(box, uniform, parts=2, fixed_points=[point])
    assert tm.cleanup.mesh_problems(mesh, box) == [] and not mesh.info["remeshed"]
    assert np.any(np.all(mesh.points == point, axis=1))


class _Ranks:
    """A stand-in for an MPI communicator of ``size`` ranks, as far as the refusal of the cuts reads it."""

    def __init__(self, size):
        self.size = size

    def allgather(self, value):
        return [value] * self.size  # every rank refuses the cuts alike

    def Get_size(self):  # noqa: N802  (mpi4py's name)
        return self.size

    def Get_rank(self):  # noqa: N802
        return 0


@pytest.mark.parametrize(
    ("domain", "size", "what"),
    [(Box((0, 0, 0), (0.4, 0.4, 0.4)), 0.2, "slabs"), (tm.geometry.Rectangle((0, 0), (0.4, 0.4)), 0.2, "strips")],
)
def test_parts_set_by_the_ranks_say_so_when_refused(domain, size, what):
    # mpiexec -n 2 on a box too small for two slabs: "--parts 2 is more slabs ..." to a user who gave no --parts
    with pytest.raises(
        GenerationError, match=rf"^2 MPI ranks mesh 2 parts unless parts is given: parts=2 is more {what}"
    ):
        generate_mesh_parallel(domain, size, comm=_Ranks(2))
    with pytest.raises(GenerationError, match=rf"^parts=2 is more {what}"):
        generate_mesh_parallel(domain, size, parts=2, comm=_Ranks(2))
