"""Options and output folders checked before any work, messages in the command line's words."""

import os
import subprocess
import sys

import meshio
import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh.cli import main

BOX = ["--bbox", "0", "0.3", "0", "0.3", "--min-el", "2000"]


@pytest.fixture
def built(monkeypatch):
    """Calls of the meshing behind ``coastal``, ``seismic`` and ``demo``: none is made when a command is refused."""
    calls = []

    def recorded(*args, **kwargs):
        calls.append(args)
        raise AssertionError("meshed although the command was to be refused first")

    monkeypatch.setattr(sys.modules["terramesh.cli.coastal"], "build", recorded)
    monkeypatch.setattr(sys.modules["terramesh.cli.seismic"], "_sizes", recorded)
    monkeypatch.setattr(sys.modules["terramesh.cli.demo"], "danish_straits_mesh", recorded)
    return calls


@pytest.fixture(scope="module")
def small_coastal_mesh():
    """A coastal mesh of a small box, as ``coastal.build`` returns it (built once)."""
    land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    return tm.coastal.build((0, 0.3, 0, 0.3), land, min_el=2000, max_el=6000, dis=0.3, g=0.3)


def test_unusable_output_folders_are_refused_before_meshing(tmp_path, capsys, built):
    # were found after the mesh was built, as a bare "[Errno 17] File exists: 'afile'"; with --plots the mesh
    # had been written and the exit status was 1 all the same
    afile = tmp_path / "afile"
    afile.write_text("not a folder")
    (tmp_path / "taken.14").mkdir()
    refused = [
        (["coastal", *BOX, "-o", str(afile / "c.14")], "-o: ", "is a file, not a folder"),
        (["coastal", *BOX, "-o", str(afile / "deeper" / "c.14")], "-o: ", "is a file, not a folder"),
        (["coastal", *BOX, "-o", str(tmp_path / "c.14"), "--plots", str(afile)], "--plots: ", "is a file"),
        (["coastal", *BOX, "-o", str(tmp_path / "taken.14")], "-o: ", "is a folder; give a file name"),
        (["seismic", "model.npy", "--frequency", "2", "--hmin", "50", "-o", str(afile / "s.msh")], "-o: ", "a file"),
        (["demo", "-o", str(afile / "demo")], "-o/--output-dir: ", "is a file, not a folder"),
    ]
    for arguments, flag, message in refused:
        assert main([*arguments, "-q"]) == 1
        err = capsys.readouterr().err
        assert f"error: {flag}" in err and message in err and "Errno" not in err
    assert built == [] and not (tmp_path / "c.14").exists()


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into any folder")
def test_an_output_folder_without_write_permission_is_refused_before_meshing(tmp_path, capsys, built):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        assert main(["coastal", *BOX, "-o", str(locked / "new" / "c.14"), "-q"]) == 1
    finally:
        locked.chmod(0o700)
    assert "-o: no permission to create" in capsys.readouterr().err and built == []


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["coastal", *BOX, "--dj-cutoff", "2"], "argument --dj-cutoff: a fraction between 0 and 1, got '2'"),
        (["coastal", *BOX, "--itmax", "0"], "argument --itmax: a whole number of at least 1, got 0"),
        # "dt must be a positive finite number", where --dt 0 chooses the step
        (["coastal", *BOX, "--dt", "-5"], "argument --dt: a time step of at least 0 s (0 chooses one), got '-5'"),
        (["coastal", *BOX, "--dry-depth", "nan"], "argument --dry-depth: a finite number, got 'nan'"),
        (
            ["coastal", "--bbox", "0", "1", "0", "1", "--min-el", "-5"],
            "argument --min-el/--h0: a number above 0, got '-5'",
        ),
        (["demo", "--min-edge-km", "-1"], "argument --min-edge-km: a number above 0, got '-1'"),
        (["demo", "--max-edge-km", "nan"], "argument --max-edge-km: a number above 0, got 'nan'"),
        (["demo", "--grade", "-0.1"], "argument --grade: a number of at least 0, got '-0.1'"),
        (["seismic", "model.npy", "--frequency", "2"], "the following arguments are required: --hmin"),
        (
            ["compile", "--processes", "abc"],
            "argument --processes: a whole number of at least 1, got 'abc'",
        ),
    ],
)
def test_option_ranges_are_refused_by_flag_before_any_work(capsys, built, arguments, message):
    # --dj-cutoff 2 was refused after meshing; --min-edge-km -1 by "edge_length returned 9234 values that are
    # zero or negative"; --processes abc by "invalid _at_least_one value"; no --hmin by "size_function needs hmin"
    with pytest.raises(SystemExit) as exit_:
        main(arguments)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "_at_least_one" not in err
    assert built == []


def test_a_box_across_180_degrees_written_from_170_to_minus_170_is_told_how(tmp_path, capsys, built):
    # "bbox must be (lon_min, lon_max, lat_min, lat_max) with min < max" left the user to guess 170 190
    arguments = ["coastal", "--bbox", "170", "-170", "-50", "-30", "--min-el", "10000", "--fs", "3"]
    assert main([*arguments, "-o", str(tmp_path / "a.14"), "-q"]) == 1
    assert (
        "error: --bbox 170 -170: LON_MIN is east of LON_MAX; a box across 180 degrees is written with longitudes past"
        " 180: --bbox 170 190 -50 -30" in capsys.readouterr().err
    )
    assert built == []
    # 10 -10 is a box written the wrong way round, not one of 340 degrees across 180: the library's "min < max"
    from terramesh.cli.coastal import _check_antimeridian

    _check_antimeridian((10.0, -10.0, 0.0, 1.0))


def test_demo_refuses_a_largest_edge_below_the_smallest(tmp_path, capsys, built):
    arguments = ["demo", "-o", str(tmp_path / "demo"), "--max-edge-km", "1", "--min-edge-km", "5", "-q"]
    assert main(arguments) == 1
    assert "error: --max-edge-km 1 is below --min-edge-km 5" in capsys.readouterr().err
    assert built == [] and not (tmp_path / "demo").exists()


def test_quiet_may_come_before_the_subcommand(monkeypatch, capsys):
    # "terramesh -q demo" was refused: -q was an option of each subcommand only
    def chatty(arguments):
        sys.modules["terramesh.cli.demo"].logger.info("meshing")
        return 0

    monkeypatch.setattr(sys.modules["terramesh.cli.demo"], "run", chatty)
    for arguments, err in ((["demo"], "terramesh: meshing\n"), (["-q", "demo"], ""), (["demo", "-q"], "")):
        assert main(arguments) == 0
        assert capsys.readouterr().err == err


def test_warnings_are_plain_lines_naming_the_command(tmp_path):
    # were shown as "<frozen runpy>:88: TerrameshWarning: ..." under `python -m terramesh`
    script = (
        "import sys, terramesh.cli.info as info, terramesh.errors as errors\n"
        "info.run = lambda arguments: errors.warn_user('the mesh is odd') or 0\n"
        "import runpy; sys.argv = ['terramesh', 'info', 'x.14']; runpy.run_module('terramesh', run_name='__main__')\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path, check=False)
    assert done.returncode == 0
    assert done.stderr == "terramesh info: warning: the mesh is odd\n"


def test_info_names_the_formats_it_reads(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["info", "--help"])
    out = capsys.readouterr().out
    for extension in tm.io.FORMAT_BY_EXTENSION:  # the help listed fort.14, .vtu, .msh, .xdmf: not gr3 and .ll
        assert f"*{extension}" in out
    unknown = tmp_path / "mesh.foo"
    unknown.write_text("")
    assert main(["info", str(unknown)]) == 1
    err = capsys.readouterr().err
    assert "cannot tell the mesh format of" in err and ".gr3" in err
    assert "file_format" not in err  # "... or pass file_format": an argument of read_mesh, not of the command


def test_info_refuses_a_triangle_surface_in_3d_by_saying_so(tmp_path, capsys):
    # printed "3D mesh", then failed with "points must have shape (n, 2), got (3, 3)"
    path = tmp_path / "surface.vtu"
    meshio.write_points_cells(path, np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 1]]), [("triangle", [[0, 1, 2]])])
    assert main(["info", str(path)]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "a surface of 1 triangle in 3D (z not all 0)" in captured.err and "shape" not in captured.err


@pytest.mark.parametrize(
    ("name", "holds"),
    [
        ("c.14", "boundaries: {open} open, {land} land (mainland and islands); depth 0 everywhere (no --dem)"),
        ("c.gr3", "boundaries: {open} open, {land} land (mainland and islands); depth 0 everywhere (no --dem)"),
        ("c.vtu", "holds vertices, cells and depth as point data 'depth' (0 everywhere: no --dem); not written: the"),
        ("c.xdmf", "holds vertices, cells and depth as point data 'depth' (0 everywhere: no --dem); not written: the"),
        ("c.msh", "the file holds vertices and cells only; not written: the boundaries ({open} open, {land} land"),
    ],
)
def test_coastal_says_what_the_written_file_holds(tmp_path, capsys, monkeypatch, small_coastal_mesh, name, holds):
    # "-o x.vtu" printed "boundaries: 4 open, 7 land" though VTU holds no boundaries (and .msh no depth)
    monkeypatch.setattr(sys.modules["terramesh.cli.coastal"], "build", lambda *args, **kwargs: small_coastal_mesh)
    assert main(["coastal", *BOX, "--dis", "0.3", "-o", str(tmp_path / name), "-q"]) == 0
    out = capsys.readouterr().out
    boundaries = tm.coastal.make_boundaries(small_coastal_mesh, open_by="bbox").boundaries
    assert holds.format(open=len(boundaries.open), land=len(boundaries.land)) in out
    written = tm.read_mesh(tmp_path / name)
    assert (written.boundaries is not None and len(written.boundaries.land) > 0) == name.endswith(("14", "gr3"))
    if "only fort.14 and .gr3 hold" in out:
        assert not out.count("boundaries: ")


def test_mpi_in_one_process_warns_and_without_mpi4py_is_refused(monkeypatch):
    # run without mpiexec, --mpi meshed its parts one after another without a word; without mpi4py it was
    # Python's ModuleNotFoundError
    import types

    from terramesh.cli._options import mpi_world
    from terramesh.errors import TerrameshError, TerrameshWarning

    world = types.SimpleNamespace(Get_size=lambda: 1)
    monkeypatch.setitem(sys.modules, "mpi4py", types.SimpleNamespace(MPI=types.SimpleNamespace(COMM_WORLD=world)))
    monkeypatch.setitem(sys.modules, "mpi4py.MPI", sys.modules["mpi4py"].MPI)
    assert mpi_world(False) is None
    with pytest.warns(TerrameshWarning, match="--mpi in a single process: its parts are meshed here one after"):
        assert mpi_world(True) is world
    monkeypatch.setitem(sys.modules, "mpi4py", None)
    with pytest.raises(TerrameshError, match=r"--mpi needs mpi4py and an MPI library: pip install 'terramesh\[mpi\]'"):
        mpi_world(True)
