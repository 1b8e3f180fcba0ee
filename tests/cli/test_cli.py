import re
import sys
import time

import numpy as np
import pytest

import terramesh as tm
from terramesh.cli import main
from terramesh.errors import TerrameshWarning
from terramesh.mesh.topology import boundary_edges


def test_info_prints_counts_and_quality(tmp_path, capsys):
    mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2)
    path = tmp_path / "disk.14"
    with pytest.warns(TerrameshWarning, match=r"the mesh has no depths .* written at 0 m"):
        mesh.write(path)
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert f"vertices {mesh.n_points:,}" in out
    assert f"mean {tm.quality.summary(mesh).mean:.4f}" in out
    assert "validity: valid" in out


def test_info_into_a_closed_pipe_says_nothing_of_it(tmp_path):
    # `terramesh info mesh.14 | head` printed "error: [Errno 32] Broken pipe" once head had its lines
    import subprocess

    path = tmp_path / "disk.14"
    with pytest.warns(TerrameshWarning, match="no depths"):
        tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2).write(path)
    command = f"'{sys.executable}' -m terramesh info '{path}' | true"  # true reads nothing and exits at once
    result = subprocess.run(command, shell=True, capture_output=True, text=True, timeout=120)
    assert "Broken pipe" not in result.stderr and "Traceback" not in result.stderr, result.stderr


def test_info_measures_a_fort14_in_degrees_on_the_ground(tmp_path, capsys):
    disk = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2)
    mesh = tm.Mesh(disk.points + (10.0, 60.0), disk.cells, crs="EPSG:4326")  # at 60 N a degree east is half as long
    path = tmp_path / "disk.14"
    with pytest.warns(TerrameshWarning, match="no depths"):
        mesh.write(path)
    planar = tm.Mesh(mesh.points, mesh.cells)
    said = {
        (): "coordinates: longitude, latitude degrees (guessed from their ranges; --planar if they are not)",
        ("--geographic",): "coordinates: longitude, latitude degrees\n",
        ("--planar",): "coordinates: planar\n",
    }
    for options, measured in (([], mesh), (["--geographic"], mesh), (["--planar"], planar)):
        assert main(["info", str(path), *options]) == 0
        out = capsys.readouterr().out
        assert f"mean {tm.quality.summary(measured).mean:.4f}" in out
        assert said[tuple(options)] in out  # the guess was silent: a plate in metres measured as degrees
    assert abs(tm.quality.summary(mesh).mean - tm.quality.summary(planar).mean) > 0.05
    # a .vtu another tool wrote keeps no reference system either: the guess was presented as fact
    import meshio

    foreign = tmp_path / "foreign.vtu"
    meshio.write(
        foreign, meshio.Mesh(np.column_stack([mesh.points, np.zeros(mesh.n_points)]), [("triangle", mesh.cells)])
    )
    mesh.write(tmp_path / "ours.vtu")  # terramesh keeps the CRS in the file: no guess
    for path, said_here in ((foreign, said[()]), (tmp_path / "ours.vtu", said[("--geographic",)])):
        assert main(["info", str(path)]) == 0
        assert said_here in capsys.readouterr().out
    # metres called degrees: every cell came out inverted, beside "validity: valid"
    metres = tmp_path / "metres.vtu"
    tm.Mesh(disk.points * 1e4 + 5e5, disk.cells).write(metres)
    assert main(["info", str(metres), "--geographic"]) == 1
    assert "--geographic needs 2D longitude, latitude coordinates" in capsys.readouterr().err


def test_info_tells_the_largest_time_step_and_the_courant_numbers_at_one(tmp_path, capsys):
    disk = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, seed=0)
    depth = 5.0 + 200.0 * np.hypot(*disk.points.T)  # shallow in the middle: the short edges there do not set it
    mesh = tm.Mesh(disk.points * 0.1 + (-70.0, 42.0), disk.cells, point_data={"depth": depth}, crs="EPSG:4326")
    path = tmp_path / "disk.14"
    mesh.write(path)
    per_second = tm.coastal.courant_number(mesh, 1.0)
    worst = int(np.argmax(per_second))
    assert main(["info", str(path), "--dt", "30", "--courant", "0.7"]) == 0
    said = capsys.readouterr().out
    assert f"time step: at most {0.7 / per_second[worst]:.3g} s for a Courant number of 0.7 " in said
    assert f"(set by vertex {worst + 1} at ({mesh.points[worst, 0]:.4f}, {mesh.points[worst, 1]:.4f})" in said
    above = np.count_nonzero(per_second * 30 > 0.7)
    assert 0 < above < mesh.n_points
    assert f"at 30 s the largest is {per_second[worst] * 30:.3g}, above 0.7 at {above:,} vertices" in said
    tm.Mesh(mesh.points, mesh.cells, crs="EPSG:4326").write(tmp_path / "no_depth.vtu")
    assert main(["info", str(tmp_path / "no_depth.vtu")]) == 0
    assert "time step: not measured (no depths in the file)" in capsys.readouterr().out
    ball = tm.generate_mesh(tm.geometry.Ball((0, 0, 0), 1), 0.5, seed=0)
    ball.write(tmp_path / "ball.vtu")
    assert main(["info", str(tmp_path / "ball.vtu"), "--dt", "1"]) == 1
    assert "--dt measures the Courant numbers of a 2D mesh; this one is 3D" in capsys.readouterr().err


def test_info_names_what_makes_a_mesh_invalid(tmp_path, capsys):
    ball = tm.generate_mesh(tm.geometry.Ball((0, 0, 0), 1), 0.4, seed=0)
    inverted = tm.Mesh(ball.points, np.vstack([ball.cells[1:], ball.cells[:1, [1, 0, 2, 3]]]))
    for mesh, expected in ((ball, "validity: valid"), (inverted, "validity: 1 cells are inverted")):
        path = tmp_path / "ball.vtu"
        mesh.write(path)
        assert main(["info", str(path)]) == 0
        assert expected in capsys.readouterr().out


def test_info_reports_missing_file_without_traceback(tmp_path, capsys):
    assert main(["info", str(tmp_path / "nothing.14")]) == 1
    assert "no such mesh file" in capsys.readouterr().err


def test_demo_writes_mesh_files_and_picture(tmp_path, capsys):
    out_dir = tmp_path / "demo"
    status = main(["demo", "--output-dir", str(out_dir), "--min-edge-km", "5", "--max-edge-km", "12"])
    assert status == 0
    captured = capsys.readouterr()
    assert "quality q: mean" in captured.out
    assert "iteration" in captured.err or "stopped after" in captured.err  # progress on stderr
    mesh = tm.read_mesh(out_dir / "danish_straits.14")
    assert mesh.geographic and tm.cleanup.mesh_problems(mesh) == []
    # solver-ready: the Kattegat and the Baltic open on the box's edge, every boundary edge in one string
    boundaries = mesh.boundaries
    assert len(boundaries.open) >= 2 and len(boundaries.land) >= 2
    assert f"boundaries: {len(boundaries.open)} open, {len(boundaries.land)} land" in captured.out
    listed = np.concatenate([np.column_stack([b.nodes[:-1], b.nodes[1:]]) for b in boundaries.open + boundaries.land])
    assert sorted(np.sort(listed, axis=1).tolist()) == sorted(np.sort(boundary_edges(mesh.cells), axis=1).tolist())
    for b in boundaries.open:
        lon, lat = mesh.points[b.nodes].T
        on_edge = np.isclose(lon, 9.6) | np.isclose(lon, 13.2) | np.isclose(lat, 54.4) | np.isclose(lat, 56.6)
        assert on_edge.all()
    assert tm.quality.summary(mesh).mean > 0.9
    assert 9.6 - 1e-9 <= mesh.points[:, 0].min() and mesh.points[:, 0].max() <= 13.2 + 1e-9
    picture = (out_dir / "danish_straits.png").read_bytes()
    assert picture[:8] == b"\x89PNG\r\n\x1a\n" and len(picture) > 10_000
    assert tm.read_mesh(out_dir / "danish_straits.vtu").n_cells == mesh.n_cells


def test_quiet_silences_progress(tmp_path, capsys):
    main(["demo", "-q", "-o", str(tmp_path), "--min-edge-km", "8", "--max-edge-km", "12"])
    assert capsys.readouterr().err == ""


def test_first_run_compiles_the_jobs_kernels_ahead(tmp_path, capsys, monkeypatch, fresh_installation):
    demo = ["demo", "-o", str(tmp_path), "--min-edge-km", "8", "--max-edge-km", "12"]
    main(demo)
    err = capsys.readouterr().err
    assert "first run of this installation: compiling" in err
    assert err.count("compiled 33 kernels in 41 s") == 1  # the library's jobs under it do not ask again
    fresh_installation.new_process()
    main([*demo, "-q"])
    assert capsys.readouterr().err == ""
    assert fresh_installation.asked == [["demo"], ["demo"]]  # quiet or not
    fresh_installation.new_process()
    fresh_installation.outcome = dict(fresh_installation.outcome, failed=["a.b: why"])
    main(demo)
    assert "1 kernels did not compile ahead; they compile as they are used" in capsys.readouterr().err
    fresh_installation.new_process()
    fresh_installation.outcome = OSError("no processes")
    assert main(demo) == 0
    assert "could not compile ahead (no processes): compiling as the kernels are used" in capsys.readouterr().err
    # under mpiexec every rank would start its own workers: they compile as before, and are told so
    fresh_installation.new_process()
    monkeypatch.setattr(sys.modules["terramesh.cli.seismic"], "run", lambda arguments: 0)
    assert main(["seismic", "model.segy", "--frequency", "2", "--hmin", "50", "--mpi"]) == 0
    assert "each rank compiles the kernels (`terramesh compile` first)" in capsys.readouterr().err
    fresh_installation.new_process()
    main(["seismic", "model.segy", "--frequency", "2", "--hmin", "50"])
    assert "first run of this installation: compiling" in capsys.readouterr().err
    assert fresh_installation.asked == [["demo"], ["demo"], ["demo"], ["demo"], ["seismic"]]
    monkeypatch.undo()
    main(demo)
    assert "first run" not in capsys.readouterr().err  # compiled by now


def test_compile_command_reports_what_it_compiled(capsys, monkeypatch):
    command = sys.modules["terramesh.cli.precompile"]
    asked = []

    def compile_kernels(stages, processes):
        asked.append((stages, processes))
        return dict(kernels=7, processes=processes or 2, seconds=12.3, failed=["_kernels.x.y: TypeError: no"])

    monkeypatch.setattr(command, "compile_kernels", compile_kernels)
    assert main(["compile", "--stages", "seismic", "3d", "--processes", "3"]) == 1
    assert capsys.readouterr().out == (
        "compiled 6 of 7 kernels in 3 processes in 12 s\nfailed: _kernels.x.y: TypeError: no\n"
    )
    assert asked == [(["seismic", "3d"], 3)]
    for bad in (["--stages", "everything"], ["--processes", "0"], ["--processes", "two"]):
        with pytest.raises(SystemExit):
            main(["compile", *bad])
    assert "argument --processes: a whole number of at least 1, got 0" in capsys.readouterr().err


def test_compile_command_states_its_outcome_once(capsys, monkeypatch):
    # the real workers, on three small kernels (loaded from the cache where compiled before)
    import terramesh._kernels.precompile as precompile

    rows = [row for row in precompile.kernel_table()["generation"] if row[1] in ("count_far", "triangle_qualities")]
    monkeypatch.setattr(precompile, "kernel_table", lambda: {"small": rows})
    monkeypatch.setattr(sys.modules["terramesh.cli.precompile"], "kernel_table", precompile.kernel_table)
    assert main(["compile", "--stages", "small", "--processes", "2"]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("compiled 2 of 2 kernels in 2 processes in ")
    assert "compiling 2 kernels in 2 processes" in captured.err  # progress on stderr, the outcome on stdout only
    assert "compiled 2" not in captured.err


def test_bad_arguments_exit_with_usage():
    with pytest.raises(SystemExit):
        main(["mesh-everything"])


def test_coastal_writes_a_fort14_with_depths_and_the_pictures(tmp_path, capsys, shared_data):
    output = tmp_path / "maine.14"
    status = main(
        [
            "coastal",
            "--bbox", "-71", "-68", "41.5", "44",
            "--shoreline", str(shared_data / "coast" / "GSHHS_l_L1.shp"),
            "--dem", str(shared_data / "dem" / "ETOPO1_0.1.grd"),
            "--min-el", "4000", "--max-el", "25000", "--fs", "3", "--wl", "40", "--g", "0.25", "--dt", "0",
            "-o", str(output), "--plots", str(tmp_path / "pictures"), "--fort13", str(tmp_path / "maine.13"),
        ]
    )  # fmt: skip
    assert status == 0
    captured = capsys.readouterr()
    assert "CFL-limited for a time step of" in captured.out
    dt = float(captured.out.split("CFL-limited for a time step of ")[1].split(" s")[0])
    largest = float(captured.out.split("largest Courant number on the mesh's shortest edges: ")[1].split(",")[0])
    mesh = tm.read_mesh(output)
    assert mesh.geographic and tm.cleanup.mesh_problems(mesh) == []
    assert largest == pytest.approx(np.nanmax(tm.coastal.courant_number(mesh, dt)), abs=0.01)
    # solver-ready: open ocean on the box's edge, the coast of Maine a mainland boundary
    assert len(mesh.boundaries.open) >= 1 and len(mesh.boundaries.land) >= 1
    lon, lat = mesh.points[mesh.boundaries.open[0].nodes].T
    on_edge = np.isclose(lon, -71) | np.isclose(lon, -68) | np.isclose(lat, 41.5) | np.isclose(lat, 44)
    assert on_edge.mean() > 0.9
    assert f"boundaries: {len(mesh.boundaries.open)} open, {len(mesh.boundaries.land)} land" in captured.out
    # ADCIRC depth, positive down, from ETOPO1 (11 km cells: vertices at the coast can sample land)
    assert (mesh.depth > 0).mean() > 0.75 and np.median(mesh.depth) > 20
    tau0 = tm.io.read_fort13(tmp_path / "maine.13")["primitive_weighting_in_continuity_equation"]
    np.testing.assert_array_equal(tau0.values, tm.coastal.tau0(mesh).values)
    assert f"wrote {tmp_path / 'maine.13'}: tau0 {tau0.default[0]:g} by default" in captured.out
    pictures = sorted(path.name for path in (tmp_path / "pictures").iterdir())
    assert pictures == [
        "boundaries.png", "depth.png", "mesh.png", "quality.png", "resolution.png", "shoreline.png",
        "size_final.png", "size_fs.png", "size_wl.png",
    ]  # fmt: skip


def test_coastal_reports_bad_input_without_traceback(tmp_path, capsys, shared_data):
    status = main(
        ["coastal", "--bbox", "10", "11", "50", "51", "--dem", str(shared_data / "dem" / "CUDEM_equal.nc"),
         "--min-el", "100", "--fs", "3", "-o", str(tmp_path / "x.14")]
    )  # fmt: skip
    assert status == 1
    assert "terramesh coastal: error:" in capsys.readouterr().err


def test_coastal_refuses_tau0_without_a_dem_before_meshing(tmp_path, capsys, shared_data):
    status = main(
        ["coastal", "--bbox", "-71", "-68", "41.5", "44", "--shoreline", str(shared_data / "coast" / "GSHHS_l_L1.shp"),
         "--min-el", "4000", "-o", str(tmp_path / "x.14"), "--fort13", str(tmp_path / "x.13")]
    )  # fmt: skip
    assert status == 1
    assert "--fort13 writes tau0 from the depths of a DEM: give --dem too" in capsys.readouterr().err
    assert not (tmp_path / "x.14").exists()


def test_coastal_takes_the_dems_sign(tmp_path, capsys, shared_data, monkeypatch):
    coastal = sys.modules["terramesh.cli.coastal"]
    given = []
    monkeypatch.setattr(coastal, "build", lambda *args, **kwargs: given.append(args[2]))
    box = ["--bbox", "-71", "-68", "41.5", "44", "--min-el", "4000", "--fs", "3", "-o", str(tmp_path / "x.14")]
    assert main(["coastal", *box, "--dem-positive", "up"]) == 1
    assert "terramesh coastal: error: --dem-positive gives the sign of a DEM: give --dem too" in capsys.readouterr().err
    etopo1 = shared_data / "dem" / "ETOPO1_0.1.grd"
    main(["coastal", *box, "--dem", str(etopo1), "--dem-positive", "down"])
    read = tm.coastal.read_dem(etopo1, (-71, -68, 41.5, 44))
    assert np.array_equal(given[-1].elevation, -read.elevation) and given[-1].sign_note.endswith('"down" was given')
    main(["coastal", *box, "--dem", str(etopo1)])
    assert given[-1] == str(etopo1)  # read by build, the file deciding


def test_coastal_takes_h0_and_grade_for_min_el_and_g(tmp_path, monkeypatch, shared_data):
    # the seismic command took --grade and the coastal one refused it
    coastal = sys.modules["terramesh.cli.coastal"]
    given = []
    monkeypatch.setattr(coastal, "build", lambda *args, **kwargs: given.append(kwargs))
    box = ["--bbox", "-71", "-68", "41.5", "44", "--dem", str(shared_data / "dem" / "ETOPO1_0.1.grd")]
    main(["coastal", *box, "--h0", "4000", "--fs", "3", "--grade", "0.3", "-o", str(tmp_path / "x.14")])
    assert given[-1]["min_el"] == 4000 and given[-1]["g"] == 0.3


def _gshhs_etopo1(shared_data, bbox, min_el, max_el, output):
    """``terramesh coastal`` arguments for a box of GSHHS and ETOPO1 sized by the slope function, graded at 0.25."""
    return [
        "coastal",
        "--bbox", *(str(value) for value in bbox),
        "--shoreline", str(shared_data / "coast" / "GSHHS_l_L1.shp"),
        "--dem", str(shared_data / "dem" / "ETOPO1_0.1.grd"),
        "--min-el", str(min_el), "--max-el", str(max_el), "--slp", "20", "--g", "0.25", "-o", str(output),
    ]  # fmt: skip


def test_coastal_errors_name_the_flags(tmp_path, capsys, shared_data):
    # "min_edge_length 2000 exceeds max_edge_length 1000": the library's names, not the flags given
    arguments = ["coastal", "--bbox", "-71", "-68", "41.5", "44"]
    arguments += ["--shoreline", str(shared_data / "coast" / "GSHHS_l_L1.shp"), "--fs", "3", "-q"]
    assert main([*arguments, "--min-el", "2000", "--max-el", "1000", "-o", str(tmp_path / "a.14")]) == 1
    assert "error: --min-el 2000 exceeds --max-el 1000" in capsys.readouterr().err


def test_coastal_takes_the_guides_fl_and_dj_cutoff(tmp_path, capsys, shared_data, monkeypatch):
    coastal = sys.modules["terramesh.cli.coastal"]
    asked, built = [], []

    def recorded(*args, **kwargs):
        asked.append(kwargs)
        built.append(build(*args, **kwargs))
        return built[-1]

    build = coastal.build
    monkeypatch.setattr(coastal, "build", recorded)
    gulf_of_maine = _gshhs_etopo1(shared_data, (-71, -68, 41.5, 44), 4000, 25000, tmp_path / "gom.14")
    assert main([*gulf_of_maine, "--fl", "10000", "60000", "--dj-cutoff", "0.05"]) == 0
    assert asked[-1]["fl"] == [10000.0, 60000.0] and asked[-1]["disjoint_cutoff"] == 0.05
    assert tm.cleanup.mesh_problems(tm.read_mesh(tmp_path / "gom.14")) == []
    # a DEM the command line reads for its sign counts in the job's reading time, as when build reads it
    read_dem = coastal.read_dem
    monkeypatch.setattr(coastal, "read_dem", lambda *args, **kwargs: (time.sleep(0.5), read_dem(*args, **kwargs))[1])
    assert main([*gulf_of_maine, "--dem-positive", "up"]) == 0
    timings = built[-1].info["timings"]
    assert timings["read"] >= 0.5 and timings["total"] >= timings["read"] + timings["generation"]
    assert main([*gulf_of_maine]) == 0
    assert "fl" not in asked[-1] and asked[-1]["disjoint_cutoff"] == 0.01  # the guide's defaults
    capsys.readouterr()
    assert main([*gulf_of_maine, "--fl", "-1", "10000"]) == 1
    assert "terramesh coastal: error: filter lengths must be non-negative" in capsys.readouterr().err
    # the guide's thalwegs file (§3.4) had no way in from the command line
    thalwegs = str(shared_data / "channels" / "ECGC_Thalwegs.mat")
    assert main([*gulf_of_maine, "--ch", "50", "--thalwegs", thalwegs]) == 0
    assert asked[-1]["thalwegs"] == thalwegs and asked[-1]["ch"] == 50
    assert "wrote " in capsys.readouterr().out
    assert main([*gulf_of_maine, "--thalwegs", thalwegs]) == 1
    assert "--thalwegs are the channel function's (--ch): give --ch" in capsys.readouterr().err
    # the shallow open water's warning named dry_depth, which the command line had no way to give
    assert main([*gulf_of_maine, "--dry-depth", "1.5"]) == 0
    assert asked[-1]["boundaries"] == {"dry_depth": 1.5}
    assert built[-1].info["boundaries"]["options"]["dry_depth"] == 1.5
    # the guide's examples limit the Courant number to 0.8: the command line had no way to say so
    assert main([*gulf_of_maine, "--dt", "60", "--courant", "0.8", "--eta", "1"]) == 0
    assert asked[-1]["courant"] == 0.8 and asked[-1]["eta"] == 1.0
    assert "the target 0.8" in capsys.readouterr().out
    assert main([*gulf_of_maine, "--courant", "0.8"]) == 1  # without --dt it would change nothing
    assert "--courant and --eta are for the time step: give --dt" in capsys.readouterr().err


def test_coastal_in_strips(tmp_path, capsys, shared_data, monkeypatch):
    gulf_of_maine = _gshhs_etopo1(shared_data, (-71, -68, 41.5, 44), 4000, 25000, tmp_path / "gom.14")
    assert main([*gulf_of_maine, "--parts", "2", "-q"]) == 0
    mesh = tm.read_mesh(tmp_path / "gom.14")
    assert tm.cleanup.mesh_problems(mesh) == [] and len(mesh.boundaries.open) >= 1
    monkeypatch.setenv("PMI_SIZE", "2")  # started by mpiexec: each process meshes it all and writes, said
    with pytest.warns(TerrameshWarning, match="one of 2 processes started by mpiexec, but without --mpi"):
        assert main([*gulf_of_maine, "--parts", "2", "-q"]) == 0


def test_coastal_meshes_open_water_only_when_asked(tmp_path, capsys, shared_data):
    shelf_break = _gshhs_etopo1(shared_data, (-73, -72, 38.5, 39.5), 3000, 20000, tmp_path / "sea.14")
    assert main(shelf_break) == 1
    assert "no land polygon in the bbox (-73.0, -72.0, 38.5, 39.5); to mesh open water alone" in capsys.readouterr().err
    assert main([*shelf_break, "--open-water"]) == 0
    mesh = tm.read_mesh(tmp_path / "sea.14")
    assert tm.cleanup.mesh_problems(mesh) == [] and np.all(mesh.depth > 0)
    assert mesh.boundaries.land == [] and len(mesh.boundaries.open) == 1


def test_coastal_without_a_dem_opens_the_box_edge_and_says_nothing_of_depths(
    tmp_path, capsys, shared_data, monkeypatch
):
    import warnings

    south_island = [
        "coastal", "--bbox", "166", "176", "-48", "-40",
        "--shoreline", str(shared_data / "coast" / "ne_10m_land.shp"),
        "--min-el", "8000", "--max-el", "40000", "--fs", "2", "--g", "0.3",
    ]  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "boundary vertices have no depth" warning: nothing is known of depths
        assert main([*south_island, "-o", str(tmp_path / "si.14")]) == 0
    mesh = tm.read_mesh(tmp_path / "si.14")
    assert len(mesh.boundaries.open) >= 1 and len(mesh.boundaries.land) >= 1
    for boundary in mesh.boundaries.open:
        lon, lat = mesh.points[boundary.nodes].T
        assert np.all(np.isclose(lon, 166) | np.isclose(lon, 176) | np.isclose(lat, -48) | np.isclose(lat, -40))
    capsys.readouterr()
    # a file name no format has: refused at once, not after the mesh is built
    built = []
    monkeypatch.setattr(sys.modules["terramesh.cli.coastal"], "build", lambda *args, **kwargs: built.append(args))
    assert main([*south_island, "-o", str(tmp_path / "si.2dm")]) == 1
    assert built == [] and "cannot tell the mesh format of" in capsys.readouterr().err


def test_info_reports_a_directory_without_traceback(tmp_path, capsys):
    folder = tmp_path / "x.14"
    folder.mkdir()
    assert main(["info", str(folder)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("terramesh info: error: ") and "x.14" in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_info_checks_that_node_strings_run_along_the_boundary(tmp_path, capsys):
    # a fort.14 cut in its last line read the island's last node 11 for 1198: a jump, with valid cells
    mesh = tm.coastal.make_boundaries(tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.25), open_by="bbox")
    mesh.point_data["depth"] = np.full(mesh.n_points, 10.0)
    path = tmp_path / "box.14"
    mesh.write(path)
    assert main(["info", str(path)]) == 0
    assert "node strings: along the boundary edges" in capsys.readouterr().out
    mesh.boundaries.open[0].nodes[[3, 5]] = mesh.boundaries.open[0].nodes[[5, 3]]
    mesh.write(path)
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "validity: valid" in out and re.search(r"node strings: open boundary 1: nodes \d+ and \d+ \(mesh", out)


def test_seismic_takes_a_segy_files_sample_format_and_line_bytes(tmp_path, capsys):
    # the reader's advice named sample_format='ibm', which the command line did not take
    import struct

    import segyio

    path = tmp_path / "labelled_ieee.segy"
    velocity = 1500.0 + 30.0 * np.arange(40)[:, None] + np.zeros(30)[None, :]  # 40 samples down, 30 traces
    spec = segyio.spec()
    spec.format, spec.samples, spec.tracecount = 1, range(40), 30  # IBM floats...
    with segyio.create(str(path), spec) as f:
        f.bin[segyio.BinField.Interval] = 25000  # 25 m
        for i in range(30):
            f.header[i] = {segyio.TraceField.CDP_X: 25 * i, segyio.TraceField.TRACE_SAMPLE_INTERVAL: 25000}
            f.trace[i] = velocity[:, i].astype(np.float32)
    data = bytearray(path.read_bytes())
    data[3224:3226] = struct.pack(">h", 5)  # ...labelled IEEE
    path.write_bytes(bytes(data))
    command = ["seismic", str(path), "--frequency", "3", "--hmin", "50", "-o", str(tmp_path / "out.msh")]
    assert main(command) == 1
    assert "pass --sample-format ibm" in capsys.readouterr().err
    assert main([*command, "--sample-format", "ibm"]) == 0
    assert "1500-2670 m/s" in capsys.readouterr().out.replace("..", "-")
    assert main([*command, "--sample-format", "ibm", "--line-bytes", "9", "21"]) == 1  # numbers at bytes 9, 21: none
    assert "terramesh seismic: error:" in capsys.readouterr().err
