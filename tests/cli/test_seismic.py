"""``terramesh seismic``: BP2004 (decimated, as a NumPy file) meshed, adapted to an update, and in strips."""

import os
import shutil
import subprocess
import sys
import warnings

import numpy as np
import pytest
from scipy.spatial import cKDTree

import terramesh as tm
from terramesh.cli import main
from terramesh.errors import TerrameshWarning

SIZING = ["--spacing", "200", "100", "--axis-order", "xz", "--frequency", "2", "--hmin", "60", "--grade", "0.15"]


@pytest.fixture(scope="module")
def models(shared_data, tmp_path_factory):
    """BP2004 every 16th node (200 m x 100 m), and the same with the velocity halved in an ellipse."""
    folder = tmp_path_factory.mktemp("models")
    section = tm.seismic.read_velocity(shared_data / "seismic" / "vel_z6.25m_x12.5m_exact.segy")
    old = section.values[::16, ::16].astype(np.float64)
    x = np.arange(old.shape[0]) * 200.0
    z = -np.arange(old.shape[1])[::-1] * 100.0
    updated = old.copy()
    updated[((x[:, None] - 30000) / 6000) ** 2 + ((z[None, :] + 3000) / 1500) ** 2 <= 1] *= 0.5
    np.save(folder / "old.npy", old)
    np.save(folder / "new.npy", updated)
    return folder


def read_checked(path):
    mesh = tm.read_mesh(path)
    assert tm.cleanup.mesh_problems(mesh) == []
    return mesh


def test_a_model_meshed_then_adapted_to_its_update(models, tmp_path, capsys):
    old_mesh, new_mesh = tmp_path / "old.msh", tmp_path / "new.msh"
    assert main(["seismic", str(models / "old.npy"), *SIZING, "-o", str(old_mesh), "-q"]) == 0
    assert f"wrote {old_mesh}" in capsys.readouterr().out
    old = read_checked(old_mesh)
    arguments = ["--adapt", str(old_mesh), "--old-model", str(models / "old.npy"), "-o", str(new_mesh), "-q"]
    assert main(["seismic", str(models / "new.npy"), *SIZING, *arguments]) == 0
    out = capsys.readouterr().out
    added = int(out.split("adapted ")[1].split(": ")[1].split(" points added")[0])
    new = read_checked(new_mesh)
    assert added > 100 and new.n_points > old.n_points + added // 2
    # far from the update the vertices are the old mesh's, to the bit
    far = old.points[np.abs(old.points[:, 0] - 30000) > 15000]
    assert np.mean(cKDTree(new.points).query(far)[0] == 0.0) > 0.95


def test_a_3d_model_meshed_then_adapted_to_its_update(tmp_path, capsys):
    """A 6 x 3 x 3 km block, 2,000 m/s over 3,000 m/s, the velocity lowered by 40 % in a ball in the update."""
    x, y, z = np.arange(31) * 200.0, np.arange(16) * 200.0, -np.arange(16)[::-1] * 200.0
    grid = np.stack(np.meshgrid(x, y, z, indexing="ij"), axis=-1)
    old = np.where(grid[..., 2] > -1500, 2000.0, 3000.0)
    updated = np.where(np.linalg.norm(grid - [4000, 1500, -1500], axis=-1) < 800, 0.6 * old, old)
    np.save(tmp_path / "old.npy", old)
    np.save(tmp_path / "new.npy", updated)
    sizing = ["--spacing", "200", "--axis-order", "xyz", "--frequency", "1", "--hmin", "100", "--grade", "0.2"]
    old_mesh, new_mesh = tmp_path / "old.vtu", tmp_path / "new.vtu"
    assert main(["seismic", str(tmp_path / "old.npy"), *sizing, "-o", str(old_mesh), "-q"]) == 0
    before = read_checked(old_mesh)
    arguments = ["--adapt", str(old_mesh), "--old-model", str(tmp_path / "old.npy"), "-o", str(new_mesh), "-q"]
    assert main(["seismic", str(tmp_path / "new.npy"), *sizing, *arguments]) == 0
    assert f"adapted {old_mesh}" in capsys.readouterr().out
    after = read_checked(new_mesh)
    assert after.cells.shape[1] == 4 and after.n_points > before.n_points
    # far from the ball, away from the block's edges, the old vertices stay, to the bit
    from_edges = np.sort(np.minimum(before.points - [0, 0, -3000], [6000, 3000, 0] - before.points), axis=1)[:, 1]
    far = (np.linalg.norm(before.points - [4000, 1500, -1500], axis=1) > 2500) & (from_edges > 1000)
    assert far.sum() > 50
    assert np.mean(cKDTree(after.points).query(before.points[far])[0] == 0.0) > 0.9


def test_a_model_meshed_in_strips(models, tmp_path, capsys):
    output = tmp_path / "strips.vtu"
    arguments = ["--parts", "3", "--velocity-on", "cells", "-o", str(output), "-q"]
    assert main(["seismic", str(models / "new.npy"), *SIZING, *arguments]) == 0
    assert "meshed in 3 strips" in capsys.readouterr().out
    mesh = read_checked(output)
    assert mesh.n_points > 1000


def test_a_model_meshed_along_its_layers(models, tmp_path, capsys):
    anisotropic, isotropic = tmp_path / "layers.msh", tmp_path / "refined.msh"
    refined = [*SIZING, "--gradient-refinement", "40"]
    assert main(["seismic", str(models / "old.npy"), *refined, "--anisotropic", "-o", str(anisotropic), "-q"]) == 0
    assert "meshed along the layers" in capsys.readouterr().out
    assert main(["seismic", str(models / "old.npy"), *refined, "-o", str(isotropic), "-q"]) == 0
    # the same refinement across the layers with fewer vertices: none spent on it along them
    assert read_checked(anisotropic).n_points < 0.9 * read_checked(isotropic).n_points


def test_a_model_without_its_axis_order_is_refused_by_name(models, capsys):
    sizing = ["--spacing", "200", "100", "--frequency", "2", "--hmin", "60"]
    assert main(["seismic", str(models / "old.npy"), *sizing, "-q"]) == 1
    assert "old.npy: say how its axes are ordered with --axis-order, e.g." in capsys.readouterr().err


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--old-model", "old.npy"], "--old-model is the model of the mesh given with --adapt"),
        (["--adapt", "old.msh", "--parts", "2"], "--adapt adapts one mesh in one process"),
        (["--adapt", "old.msh", "--seed", "3"], "--adapt starts from the mesh's own points and draws none"),  # ignored
        (["-o", "model.foo"], "cannot tell the FWI format of 'model.foo': FWI meshes are written as .msh, .vtu, .xdmf"),
        (["--anisotropic"], "--anisotropic refines across the layers by --gradient-refinement M: give it"),
        (["--anisotropic", "--gradient-refinement", "9", "--parts", "2"], "--anisotropic meshes in one process"),
    ],
)
def test_options_that_do_not_go_together_are_refused(models, capsys, arguments, message):
    assert main(["seismic", str(models / "new.npy"), *SIZING, *arguments, "-q"]) == 1
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("variable", ["PMI_SIZE", "OMPI_COMM_WORLD_SIZE"])
def test_started_by_mpiexec_without_mpi_warns(models, tmp_path, monkeypatch, variable):
    # every rank meshed the whole model and wrote the one file, without a word
    monkeypatch.setenv(variable, "2")
    with pytest.warns(TerrameshWarning, match="one of 2 processes started by mpiexec, but without --mpi"):
        assert main(["seismic", str(models / "new.npy"), *SIZING, "-o", str(tmp_path / "m.msh"), "-q"]) == 0


def test_anisotropic_is_refused_for_a_3d_model_before_the_sizes(tmp_path, capsys):
    # "layer_metric needs 2-D sizes from terramesh.seismic.size_function", after the sizes were made
    np.save(tmp_path / "block.npy", np.full((4, 3, 5), 2000.0))
    sizing = ["--spacing", "200", "--axis-order", "xyz", "--frequency", "1", "--hmin", "100"]
    arguments = ["--anisotropic", "--gradient-refinement", "9", "-o", str(tmp_path / "m.msh"), "-q"]
    assert main(["seismic", str(tmp_path / "block.npy"), *sizing, *arguments]) == 1
    assert "--anisotropic meshes 2-D sections; this model is 3-D: leave it out" in capsys.readouterr().err


def test_parts_below_one_are_refused_by_argparse(models, capsys):
    with pytest.raises(SystemExit) as exit_status:
        main(["seismic", str(models / "new.npy"), *SIZING, "--parts", "0", "-q"])
    assert exit_status.value.code == 2
    assert "argument --parts: a whole number of at least 1, got 0" in capsys.readouterr().err


def test_one_spacing_serves_both_axes(models, tmp_path, capsys):
    # "--spacing 100" was refused by a message saying one number is allowed
    sizing = [*SIZING[3:], "--spacing", "100"]
    assert main(["seismic", str(models / "old.npy"), *sizing, "-o", str(tmp_path / "one.msh"), "-q"]) == 0
    mesh = read_checked(tmp_path / "one.msh")
    nx, nz = np.load(models / "old.npy").shape
    assert np.allclose(np.ptp(mesh.points, axis=0), [100.0 * (nx - 1), 100.0 * (nz - 1)])


def test_the_meshs_own_time_step_is_reported_and_meets_dt(models, tmp_path, capsys):
    # --dt made the sizes k v dt / Cr, but DistMesh's shortest edges are shorter: on BP2004 at dt = 0.05 s half
    # the edges had Cr > 1. The sizes now allow for it (EDGE_SHRINK), and the mesh's own limit is printed
    output = tmp_path / "cfl.msh"
    sizing = [*SIZING, "--dt", "0.008", "--courant", "0.9", "-o", str(output), "-q"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", tm.errors.TerrameshWarning)
        assert main(["seismic", str(models / "old.npy"), *sizing]) == 0
    printed = capsys.readouterr().out
    limit = float(printed.split("stable time step on the mesh's edges: ")[1].split(" s")[0])
    sizes = tm.seismic.size_function(
        tm.seismic.read_velocity(models / "old.npy", spacing=(200, 100), axis_order="xz"),
        frequency=2, hmin=60, grade=0.15, dt=0.008, courant=0.9,
    )  # fmt: skip
    expected = tm.seismic.stable_timestep(read_checked(output), sizes, element_order=1, courant=0.9)
    assert limit == pytest.approx(expected, rel=1e-3) and limit >= 0.008


def test_acquisition_geometry_from_text_files(models, tmp_path, capsys):
    sources = tmp_path / "sources.txt"
    np.savetxt(sources, [[10000.0, -500.0], [40000.0, -500.0]])
    output = tmp_path / "acquisition.msh"
    arguments = ["--sources", str(sources), "--acquisition-size", "60", "--acquisition-radius", "500"]
    assert main(["seismic", str(models / "old.npy"), *SIZING, *arguments, "-o", str(output), "-q"]) == 0
    mesh = read_checked(output)
    near = np.linalg.norm(mesh.points[:, None, :] - np.array([[10000.0, -500.0], [40000.0, -500.0]]), axis=2).min(
        axis=1
    )
    edges = tm.mesh.topology.unique_edges(mesh.cells)
    lengths = np.linalg.norm(mesh.points[edges[:, 1]] - mesh.points[edges[:, 0]], axis=1)
    assert np.median(lengths[(near[edges] < 300).all(axis=1)]) < 80  # 60 m asked; the model's own: 100s of m
    capsys.readouterr()
    (tmp_path / "bad.txt").write_text("x z\n1 two\n")
    assert main(["seismic", str(models / "old.npy"), *SIZING, "--receivers", str(tmp_path / "bad.txt"), "-q"]) == 1
    assert "--receivers" in capsys.readouterr().err


def test_units_help_says_what_happens_without_units(tmp_path, capsys):
    # the help promised units "guessed from the values"; the values are read as m/s and refused if they look like km/s
    with pytest.raises(SystemExit) as exit_status:
        main(["seismic", "--help"])
    assert exit_status.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "guessed" not in text
    assert "default: a NetCDF variable's units attribute, else m/s); velocities all below 20 m/s look like km/s" in text
    in_km_per_s = tmp_path / "km.npy"
    np.save(in_km_per_s, np.full((20, 10), 2.0))
    sizing = ["--axis-order", "xz", "--spacing", "100", "--frequency", "2", "--hmin", "60", "-q"]
    with pytest.warns(tm.errors.TerrameshWarning, match="looks like km/s"):
        assert main(["seismic", str(in_km_per_s), *sizing, "-o", str(tmp_path / "km.msh")]) == 1
    assert "look like km/s" in capsys.readouterr().err
    assert not (tmp_path / "km.msh").exists()


def test_an_empty_positions_file_is_said_to_have_no_points(tmp_path, capsys):
    # an empty --sources file was refused as "got shape (0, 1)", after NumPy's warning
    model = tmp_path / "model.npy"
    np.save(model, np.full((20, 10), 2000.0))
    sizing = ["--axis-order", "xz", "--spacing", "100", "--frequency", "2", "--hmin", "60", "-q"]
    for content in ("", "# x z\n"):
        (tmp_path / "sources.txt").write_text(content)
        arguments = ["--sources", str(tmp_path / "sources.txt"), "-o", str(tmp_path / "out.msh")]
        assert main(["seismic", str(model), *sizing, *arguments]) == 1
        assert "--sources " + str(tmp_path / "sources.txt") + ": the file has no points" in capsys.readouterr().err


def test_pad_velocity_help_and_misuse(tmp_path, capsys):
    # the help named --pad-style constant only, though linear ramps to it; with the default edge style it was
    # ignored, silently, and 4.5 (km/s) made a pad at 4.5 m/s
    with pytest.raises(SystemExit):
        main(["seismic", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert (
        "m/s, with --pad-style constant (the padding's velocity) or linear (the ramp's at the outer boundary)" in text
    )
    model = tmp_path / "model.npy"
    np.save(model, np.full((20, 10), 2000.0))
    sizing = ["--axis-order", "xz", "--spacing", "100", "--frequency", "2", "--hmin", "60", "--pad", "500", "-q"]
    for style, velocity, message in (
        ("edge", "4500", "--pad-velocity 4500.0 is for --pad-style 'constant' or 'linear'"),
        ("linear", "4.5", "--pad-velocity 4.5 looks like km/s"),
    ):
        output = tmp_path / f"{style}.msh"
        arguments = ["--pad-style", style, "--pad-velocity", velocity, "-o", str(output)]
        assert main(["seismic", str(model), *sizing, *arguments]) == 1
        assert message in capsys.readouterr().err
        assert not output.exists()


def test_errors_name_the_command_lines_flags(tmp_path, capsys):
    # the size function's words: "pass units='m/s'", "coarsen_pad=False keeps ...", which the command line
    # spells --units m/s and --no-coarsen-pad
    model = tmp_path / "model.npy"
    np.save(model, np.full((20, 10), 4.5))  # km/s
    sizing = ["--axis-order", "xz", "--spacing", "100", "--frequency", "2", "--hmin", "60", "-q"]
    with pytest.warns(tm.errors.TerrameshWarning, match="looks like km/s"):
        assert main(["seismic", str(model), *sizing, "-o", str(tmp_path / "a.msh")]) == 1
    assert "--units km/s" in capsys.readouterr().err
    np.save(model, np.full((20, 10), 2000.0))
    assert main(["seismic", str(model), *sizing, "--no-coarsen-pad", "-o", str(tmp_path / "b.msh")]) == 1
    error = capsys.readouterr().err
    assert "--no-coarsen-pad keeps a padding layer's sizes from growing" in error and "give --pad" in error
    assert "_" not in error.split("error:")[1]


def test_a_netcdf_of_several_variables_and_a_big_endian_file(tmp_path, capsys):
    # the readers' advice named variable= and byte_order=, which the command line had no flags for
    import netCDF4

    values = np.full((10, 20), 2000.0) + 10.0 * np.arange(20)  # z, x
    path = tmp_path / "model.nc"
    with netCDF4.Dataset(path, "w") as ds:
        ds.createDimension("z", 10)
        ds.createDimension("x", 20)
        ds.createVariable("vp", "f4", ("z", "x"))[:] = values
        ds.createVariable("vs", "f4", ("z", "x"))[:] = values / 1.7
    sizing = ["--spacing", "100", "--frequency", "2", "--hmin", "60", "-q"]
    assert main(["seismic", str(path), *sizing, "-o", str(tmp_path / "a.msh")]) == 1
    assert (
        "several 2-D or 3-D variables (['vp', 'vs']); name the velocity with variable= (command line: --variable)"
        in (capsys.readouterr().err)
    )
    assert main(["seismic", str(path), *sizing, "--variable", "vp", "-o", str(tmp_path / "a.msh")]) == 0
    mesh = read_checked(tmp_path / "a.msh")
    assert np.isclose(mesh.point_data["velocity"].max(), values.max(), rtol=1e-3)
    raw = tmp_path / "model.bin"
    values.astype(">f4").tofile(raw)
    binary = ["--shape", "10", "20", "--axis-order", "zx", *sizing, "-o", str(tmp_path / "b.msh")]
    assert main(["seismic", str(raw), *binary]) == 1
    assert (
        "try 'big') and dtype (now 'float32'); on the command line --byte-order and --dtype" in capsys.readouterr().err
    )
    assert main(["seismic", str(raw), *binary, "--byte-order", "big"]) == 0
    assert main(["seismic", str(path), *sizing, "--variable", "vp", "--shape", "10", "20"]) == 1
    assert "model.nc: shape is not used for a netcdf file" in capsys.readouterr().err


def test_an_update_adapted_from_an_old_model_in_another_format(tmp_path, capsys):
    # the old SEG-Y model was read with the update's --axis-order, which a SEG-Y file does not use: refused
    from ..seismic.test_velocity import write_segy

    old = np.full((20, 40), 2000.0)  # z, x
    old[10:] = 3000.0
    write_segy(tmp_path / "old.segy", old, interval=25000, dx_decimetres=250, scalar=-10)  # 25 m both ways
    new = old.copy()
    new[5:10, 10:20] = 1800.0
    np.save(tmp_path / "new.npy", new)
    common = ["--frequency", "2", "--hmin", "60", "-q"]
    assert main(["seismic", str(tmp_path / "old.segy"), *common, "-o", str(tmp_path / "old.msh")]) == 0
    update = [str(tmp_path / "new.npy"), "--axis-order", "zx", "--spacing", "25", *common]
    adapt = ["--adapt", str(tmp_path / "old.msh"), "--old-model", str(tmp_path / "old.segy")]
    assert main(["seismic", *update, *adapt, "-o", str(tmp_path / "new.msh")]) == 0
    assert tm.cleanup.mesh_problems(read_checked(tmp_path / "new.msh")) == []
    # the update itself still refuses what its own format does not use
    assert main(["seismic", *update, "--variable", "vp", *adapt, "-o", str(tmp_path / "new.msh")]) == 1
    assert "new.npy: variable is not used for a npy file" in capsys.readouterr().err


def test_an_old_model_on_another_grid_takes_its_own_spacing(models, tmp_path, capsys):
    # the old model was read with the update's --spacing: on half its grid, its sizes covered half the old
    # mesh, the rest took their edge's, and 6 of 9,744 old vertices were kept where the sizes held
    old_mesh, new_mesh = tmp_path / "old.msh", tmp_path / "new.msh"
    assert main(["seismic", str(models / "old.npy"), *SIZING, "-o", str(old_mesh), "-q"]) == 0
    fine = np.repeat(np.repeat(np.load(models / "new.npy"), 2, axis=0), 2, axis=1)  # the update on a 100 x 50 grid
    np.save(tmp_path / "fine.npy", fine)
    sizing = ["--spacing", "100", "50", *SIZING[3:]]
    adapt = ["--adapt", str(old_mesh), "--old-model", str(models / "old.npy"), "-o", str(new_mesh), "-q"]
    assert main(["seismic", str(tmp_path / "fine.npy"), *sizing, *adapt]) == 1
    assert "was the old model read with another spacing or origin than its own" in capsys.readouterr().err
    assert main(["seismic", str(tmp_path / "fine.npy"), *sizing, *adapt, "--old-spacing", "200", "100", "50"]) == 1
    assert "error: the old model (--old-model with --old-spacing): spacing must be" in capsys.readouterr().err
    assert main(["seismic", str(tmp_path / "fine.npy"), *sizing, *adapt, "--old-spacing", "200", "100"]) == 0
    assert f"wrote {new_mesh}" in capsys.readouterr().out


def test_paths_in_messages_are_left_as_the_user_wrote_them(tmp_path, capsys):
    # the flags' rewriting took the name in 'missing/old_model.npy' for --old-model: "no such velocity file:
    # 'missing/--old-model.npy'"
    folder = tmp_path / "velocity_window"
    folder.mkdir()
    np.save(folder / "model.npy", np.full((20, 10), 2000.0))
    sizing = ["--spacing", "100", "--frequency", "2", "--hmin", "60", "-q", "-o", str(tmp_path / "a.msh")]
    assert main(["seismic", str(folder / "model.npy"), *sizing]) == 1
    assert "velocity_window/model.npy: say how its axes are ordered with --axis-order" in capsys.readouterr().err


def test_a_3d_model_in_two_slabs(tmp_path, capsys):
    """A 6 x 3 x 3 km block, 2,000 m/s over 3,000 m/s, meshed in two slabs: one valid mesh, the cut inside it."""
    x, y, z = np.arange(31) * 200.0, np.arange(16) * 200.0, -np.arange(16)[::-1] * 200.0
    grid = np.stack(np.meshgrid(x, y, z, indexing="ij"), axis=-1)
    np.save(tmp_path / "block.npy", np.where(grid[..., 2] > -1500, 2000.0, 3000.0))
    sizing = ["--spacing", "200", "--axis-order", "xyz", "--frequency", "1", "--hmin", "100", "--grade", "0.2"]
    whole, slabs = tmp_path / "whole.vtu", tmp_path / "slabs.vtu"
    assert main(["seismic", str(tmp_path / "block.npy"), *sizing, "-o", str(whole), "-q"]) == 0
    assert main(["seismic", str(tmp_path / "block.npy"), *sizing, "--parts", "2", "-o", str(slabs), "-q"]) == 0
    assert "meshed in 2 slabs" in capsys.readouterr().out
    one, two = read_checked(whole), read_checked(slabs)
    assert two.cells.shape[1] == 4 and abs(two.n_points / one.n_points - 1) < 0.05
    corners = two.points[tm.mesh.topology.boundary_faces(two.cells)]
    on_a_side = np.zeros(len(corners), dtype=bool)
    for axis, bounds in enumerate(((0, 6000), (0, 3000), (-3000, 0))):
        for bound in bounds:
            on_a_side |= np.all(np.isclose(corners[:, :, axis], bound), axis=1)
    assert on_a_side.all()  # the cut is inside the mesh: none of its faces is left on the boundary


def test_more_parts_than_the_model_can_take_are_refused_by_flag(models, tmp_path, capsys):
    # a raw ValueError traceback from NumPy ("Maximum allowed size exceeded"); 1e9 ran out of memory
    output = tmp_path / "strips.msh"
    arguments = ["--parts", "99999999999999999999", "-o", str(output), "-q"]
    assert main(["seismic", str(models / "new.npy"), *SIZING, *arguments]) == 1
    err = capsys.readouterr().err
    assert "error: --parts 99999999999999999999 is more strips than the domain can be cut into at these sizes" in err
    assert "give fewer parts" in err and not output.exists()


def test_the_model_read_is_described_before_meshing(tmp_path, capsys):
    # a raw binary model read with --shape swapped (the same byte count) meshed a scrambled model, silently: the
    # command never said what it read
    values = np.linspace(2000.0, 3000.0, 10)[::-1, None] * np.ones(40)  # z (top first), x: 900 m deep, 3.9 km wide
    values.astype("<f4").tofile(tmp_path / "model.bin")
    sizing = ["--axis-order", "zx", "--spacing", "100", "--frequency", "2", "--hmin", "100", "-q"]
    arguments = ["seismic", str(tmp_path / "model.bin"), *sizing, "-o", str(tmp_path / "a.msh")]
    assert main([*arguments, "--shape", "10", "40", "--pad", "500"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[:2] == [
        "model model.bin: 40 x 10 nodes (x, z) 100 x 100 m apart, 3900 x 900 m (3.9 km wide, 900 m deep), 2000..3000"
        " m/s",
        "padded by 500 m on the sides and below: 4900 x 1400 m",
    ]
    assert main([*arguments, "--shape", "40", "10"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("model model.bin: 10 x 40 nodes (x, z) 100 x 100 m apart, 900 x 3900 m (900 m wide, 3.9")
    assert not out[1].startswith("padded")


def test_acquisition_and_frequency_errors_name_the_flags(models, tmp_path, capsys):
    # "give them (sources=, receivers=)"; and --frequency 1e-6 was blamed on km alone: "Are the spacing, hmin and
    # pad in km?"
    model = [str(models / "old.npy"), "--spacing", "200", "100", "--axis-order", "xz", "--hmin", "60", "-q"]
    output = ["-o", str(tmp_path / "a.msh")]
    assert main(["seismic", *model, "--frequency", "2", "--acquisition-size", "80", *output]) == 1
    err = capsys.readouterr().err
    assert "error: --acquisition-size and --acquisition-radius refine around sources and receivers" in err
    assert "give them (--sources, --receivers)" in err
    assert "=" not in err
    assert main(["seismic", *model, "--frequency", "1e-6", *output]) == 1
    err = capsys.readouterr().err
    assert "the wavelength sizes v / (f n) start at" in err and "at --frequency 1e-06 Hz" in err
    assert "Are the spacing, hmin and pad in km, or is the frequency too low or not in Hz?" in err


def test_under_mpi_rank_0_alone_says_the_model_and_the_warnings(tmp_path):
    # every rank printed each sizing warning: twice on two ranks (errors still come from every rank that meets one)
    pytest.importorskip("mpi4py")
    launcher = shutil.which("mpiexec", path=os.path.dirname(sys.executable)) or shutil.which("mpiexec")
    assert launcher, "mpi4py is installed but mpiexec is not (pip install mpich)"
    np.save(tmp_path / "cube.npy", np.full((9, 9, 9), 2000.0))
    # hmin above every wavelength size warns; two slabs of an 800 m cube at 400 m are refused
    command = [sys.executable, "-m", "terramesh", "seismic", str(tmp_path / "cube.npy"), "--axis-order", "xyz"]
    command += ["--spacing", "100", "--frequency", "1", "--hmin", "400", "--mpi", "-q", "-o", str(tmp_path / "a.vtu")]
    done = subprocess.run([launcher, "-n", "2", *command], capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode != 0
    assert done.stdout.count("model cube.npy: 9 x 9 x 9 nodes") == 1
    assert done.stderr.count("terramesh seismic: warning: --hmin 400 m is above the wavelength size") == 1
    said = "terramesh seismic: error: 2 MPI ranks mesh 2 parts unless parts is given: --parts 2 is more slabs than"
    assert done.stderr.count(said) >= 1, done.stderr


def test_pad_takes_a_width_per_side(tmp_path, capsys):
    # per-side widths were for the Python API only (a review)
    model = tmp_path / "model.npy"
    np.save(model, np.full((20, 10), 2000.0))
    arguments = ["seismic", str(model), "--axis-order", "xz", "--spacing", "100", "--frequency", "2", "--hmin", "100"]
    assert main([*arguments, "--pad", "500,1000,300", "-q", "-o", str(tmp_path / "a.vtu")]) == 0
    out = capsys.readouterr().out
    assert "padded by 500/1000 m on the sides, 300 m below: 3400 x 1200 m" in out
    mesh = tm.read_mesh(tmp_path / "a.vtu")
    np.testing.assert_allclose(mesh.points.min(axis=0), [-500.0, -1200.0], atol=1e-6)
    with pytest.raises(SystemExit) as exit_:
        main([*arguments, "--pad", "500,x", "-o", str(tmp_path / "b.vtu")])
    assert exit_.value.code == 2 and "widths in metres, one or one per side joined by commas" in capsys.readouterr().err
