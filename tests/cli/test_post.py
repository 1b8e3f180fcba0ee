"""``terramesh post``: the guide's post-processing chain on written meshes, the same as the library's."""

import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh.cli import main
from terramesh.errors import TerrameshWarning
from terramesh.postprocess.renumber import bandwidth

from ..conftest import write_atlas

WEST_BOX = (-70.5, -68.0, 41.5, 43.8)
EAST_BOX = (-69.0, -66.0, 42.5, 45.0)


@pytest.fixture(scope="module")
def written(shared_data, tmp_path_factory):
    """Two overlapping Gulf of Maine boxes (3 and 5 km at the coast) written as fort.14, and the west as Gmsh."""
    folder = tmp_path_factory.mktemp("post")
    land = shared_data / "coast" / "GSHHS_l_L1.shp"
    dem = shared_data / "dem" / "ETOPO1_0.1.grd"
    west = tm.coastal.build(WEST_BOX, land, dem, min_el=3000, max_el=15e3, fs=3, g=0.2)
    east = tm.coastal.build(EAST_BOX, land, dem, min_el=5000, max_el=25e3, fs=3, g=0.2)
    west.write(folder / "west.14")
    east.write(folder / "east.14")
    # vertices and cells only: no depths, no boundaries (a .msh keeps the depths it is given)
    tm.Mesh(west.points, west.cells, crs=west.crs).write(folder / "west.msh")
    # the west box with a node no cell uses, as hand-edited files have
    lines = (folder / "west.14").read_text().splitlines()
    lines[1] = f"{west.n_cells} {west.n_points + 1}"
    lines.insert(2 + west.n_points, f"{west.n_points + 1} -69.0 42.0 10.0")
    (folder / "unused_node.14").write_text("\n".join(lines) + "\n")
    return folder, dem


def test_post_runs_the_guides_chain_as_the_library_does(written, tmp_path, capsys):
    folder, dem = written
    atlas = tmp_path / "tpxo"
    atlas.mkdir()
    write_atlas(atlas, ["M2", "K1"], lon=(-72.0, -64.0), lat=(40.0, 46.0))
    output = tmp_path / "merged.14"
    status = main(
        ["post", str(folder / "west.14"), str(folder / "east.14"),
         "--bbox", *map(str, WEST_BOX), "--bbox", *map(str, EAST_BOX),
         "--dem", str(dem), "--min-depth", "1", "--dry-depth", "1", "--dt", "60", "--renumber",
         "-o", str(output), "--fort13", str(tmp_path / "fort.13"), "--plots", str(tmp_path / "pictures"),
         "--fort15", str(tmp_path / "fort.15"), "--start", "2024-01-01", "--run-days", "5",
         "--tidal-atlas", str(atlas), "--constituents", "M2,K1"]
    )  # fmt: skip
    assert status == 0
    said = capsys.readouterr()
    # the same steps by hand, on the same files: the command adds nothing of its own
    west, east = (tm.read_mesh(folder / name) for name in ("west.14", "east.14"))
    boxes = [shapely.box(x0, y0, x1, y1) for x0, x1, y0, y1 in (WEST_BOX, EAST_BOX)]
    with pytest.warns(TerrameshWarning, match="merge drops the open and land boundaries"):
        expected = tm.coastal.merge(west, east, region=boxes[0])
    expected = tm.coastal.interpolate_bathymetry(expected, dem, min_depth=1.0)
    expected = tm.coastal.make_boundaries(expected, bbox=shapely.union_all(boxes), dry_depth=1.0)
    timed = tm.coastal.enforce_timestep(expected, 60.0)
    expected = tm.coastal.renumber(timed)
    mesh = tm.read_mesh(output)
    np.testing.assert_allclose(mesh.points, expected.points, atol=1e-9)  # fort.14 keeps 10 decimals of a degree
    np.testing.assert_array_equal(mesh.cells, expected.cells)
    for kind in ("open", "land"):
        strings = [(string.ibtype, string.nodes.tolist()) for string in getattr(mesh.boundaries, kind)]
        assert strings == [(string.ibtype, string.nodes.tolist()) for string in getattr(expected.boundaries, kind)]
    # what a modeller checks of the file: valid, the west's vertices all kept, depths at least 1 m, the time
    # step met, the boundaries along the boundary edges with open ocean on the boxes' edges
    assert tm.cleanup.mesh_problems(mesh) == [] and mesh.n_points > west.n_points
    kept = {tuple(point) for point in np.round(mesh.points, 8)}
    removed = timed.info["timestep"]["removed"]
    assert sum(tuple(point) not in kept for point in np.round(west.points, 8)) <= removed
    assert mesh.depth.min() >= 1.0
    assert np.nanmax(tm.coastal.courant_number(mesh, 60.0)) <= 0.5 < timed.info["timestep"]["max_courant_before"]
    assert tm.coastal.node_string_problems(mesh) == []
    assert len(mesh.boundaries.open) >= 2 and len(mesh.boundaries.land) >= 1
    # the east box's south side, inside the points' extent: open sea there by the boxes' union (a wall by the extent)
    lon, lat = mesh.points[np.concatenate([string.nodes for string in mesh.boundaries.open])].T
    assert np.count_nonzero(np.isclose(lat, EAST_BOX[2]) & (lon > WEST_BOX[1])) >= 5
    assert bandwidth(mesh.cells) < bandwidth(timed.cells)
    assert f"{removed:,} vertices removed" in said.out
    # the fort.13 numbered as the fort.14 written: tau0 of the renumbered mesh
    attribute = tm.io.read_fort13(tmp_path / "fort.13")["primitive_weighting_in_continuity_equation"]
    np.testing.assert_array_equal(attribute.values, tm.coastal.tau0(expected).values)
    assert 0 < attribute.non_default.sum() < mesh.n_points
    # the fort.15 the library writes for that mesh, forced from the atlas at the open-boundary nodes
    tm.coastal.write_fort15(
        tmp_path / "expected.15", expected, start="2024-01-01", run_days=5, dt=60.0, tidal_atlas=atlas,
        constituents=["M2", "K1"], nodal_attributes=["primitive_weighting_in_continuity_equation"],
    )  # fmt: skip
    assert (tmp_path / "fort.15").read_text() == (tmp_path / "expected.15").read_text()
    assert "forced by" in said.out and "NBFR" in (tmp_path / "fort.15").read_text()
    assert f"bandwidth {bandwidth(timed.cells):,} -> {bandwidth(mesh.cells):,}" in said.out
    assert "merge drops the open and land boundaries" not in said.err  # they are made again: no advice to
    assert sorted(path.name for path in (tmp_path / "pictures").iterdir()) == [
        "boundaries.png", "depth.png", "mesh.png", "quality.png", "resolution.png",
    ]  # fmt: skip


def test_post_without_steps_converts_the_file(written, tmp_path, capsys):
    folder, _ = written
    status = main(["post", str(folder / "west.14"), "-o", str(tmp_path / "west.vtu")])
    assert status == 0
    west, copy = tm.read_mesh(folder / "west.14"), tm.read_mesh(tmp_path / "west.vtu")
    np.testing.assert_array_equal(copy.cells, west.cells)
    np.testing.assert_allclose(copy.points, west.points)
    np.testing.assert_allclose(copy.depth, west.depth)
    assert "not written: the boundaries" in capsys.readouterr().out  # a .vtu holds none of them


def test_post_puts_depths_on_a_mesh_without_them(written, tmp_path, capsys):
    folder, dem = written
    output = tmp_path / "west.14"
    assert main(["post", str(folder / "west.msh"), "--dem", str(dem), "--boundaries", "-o", str(output)]) == 0
    mesh = tm.read_mesh(output)
    expected = tm.coastal.interpolate_bathymetry(tm.read_mesh(folder / "west.msh"), dem)
    np.testing.assert_allclose(mesh.depth, expected.depth, atol=1e-6)
    assert len(mesh.boundaries.open) >= 1 and tm.coastal.node_string_problems(mesh) == []
    # a DEM of depths (positive down) read so: the same numbers, negated; here the DEM is elevation, which the
    # warnings say (as that the fort.14 has no boundaries without --boundaries)
    with pytest.warns(TerrameshWarning) as caught:
        assert (
            main(["post", str(folder / "west.msh"), "--dem", str(dem), "--dem-positive", "down", "-o", str(output)])
            == 0
        )
    sign, boundaries = sorted((str(warning.message) for warning in caught), key=lambda text: "boundaries" in text)
    assert "of the mesh's area lies at or above 0 m in the DEM (ETOPO1_0.1.grd)" in sign
    assert "(command line: --dem-positive up)" in sign
    assert boundaries.endswith(
        "gets no open or land boundaries (its mesh has none), which the model needs: give --boundaries to make them"
    )
    np.testing.assert_allclose(tm.read_mesh(output).depth, -expected.depth, atol=1e-6)


def test_post_makes_boundaries_without_depths_open_along_the_box(written, tmp_path, capsys):
    folder, _ = written
    output = tmp_path / "west.14"
    assert (
        main(["post", str(folder / "west.msh"), "--boundaries", "--bbox", *map(str, WEST_BOX), "-o", str(output)]) == 0
    )
    assert "no depths: open along the whole edge of the box" in capsys.readouterr().out
    mesh = tm.read_mesh(output)
    expected = tm.coastal.make_boundaries(tm.read_mesh(folder / "west.msh"), bbox=WEST_BOX, open_by="bbox")
    assert [string.nodes.tolist() for string in mesh.boundaries.open] == [
        string.nodes.tolist() for string in expected.boundaries.open
    ]
    lon, lat = mesh.points[np.concatenate([string.nodes for string in mesh.boundaries.open])].T
    on_edge = np.isclose(lon, WEST_BOX[0]) | np.isclose(lon, WEST_BOX[1]) | np.isclose(lat, WEST_BOX[2])
    assert (on_edge | np.isclose(lat, WEST_BOX[3])).all() and tm.coastal.node_string_problems(mesh) == []


def test_post_repairs_only_when_asked(written, tmp_path, capsys):
    folder, _ = written
    output = tmp_path / "fixed.14"
    assert main(["post", str(folder / "unused_node.14"), "-o", str(output)]) == 1
    error = capsys.readouterr().err
    assert "unused_node.14: not a valid mesh (1 vertices are not used by any cell): give --fix" in error
    assert not output.exists()
    assert main(["post", str(folder / "unused_node.14"), "--fix", "-o", str(output)]) == 0
    said = capsys.readouterr()
    assert "repaired" in said.out and "unused points: 1" in said.out and "boundaries made" in said.out
    assert "dropped" not in said.err  # the boundaries the repair drops are made again: no advice to
    mesh, west = tm.read_mesh(output), tm.read_mesh(folder / "west.14")
    np.testing.assert_array_equal(mesh.cells, west.cells)
    assert tm.cleanup.mesh_problems(mesh) == [] and tm.coastal.node_string_problems(mesh) == []
    assert [s.nodes.tolist() for s in mesh.boundaries.open] == [s.nodes.tolist() for s in west.boundaries.open]


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["west.14", "--courant", "0.4"], "--courant is for --dt: give it too"),
        (["west.14", "--min-depth", "1"], "--min-depth is for --dem: give it too"),
        (["west.14", "--g", "0.3"], "--g is for a merge's seam: give two MESH files or more"),
        (["west.14", "--dry-depth", "1"], "--dry-depth is for --boundaries: give it too"),
        (["west.14", "east.14", "--bbox", "0", "1", "0", "1"], "--bbox given 1 time(s) for 2 MESH file(s)"),
        (["west.14", "--boundaries", "--bbox", "1", "0", "0", "1"], "--bbox 1 0 0 1: LON_MIN < LON_MAX and LAT_MIN"),
        (["west.14", "--bbox", "-71", "-68", "41", "44"], "--bbox is for a merge or --boundaries: give --boundaries"),
        (["west.14", "--planar", "--dem", "dem.nc"], "--dem puts depths on a mesh in longitude, latitude degrees"),
        (["west.msh", "--fort13", "fort.13"], "--fort13 needs depths for tau0, and the mesh has none: give --dem"),
        (["west.msh", "--dt", "60"], "--dt needs depths for the Courant numbers, and the mesh has none: give --dem"),
        (["missing.14"], "no such mesh file"),
        (["west.14", "--fort15", "x.15", "--dt", "60"], "--fort15 needs --start, --run-days"),
        (["west.14", "--start", "2024-01-01"], "--start is for --fort15: give it too"),
        (
            "west.14 --fort15 x.15 --dt 60 --start 2024-01-01 --run-days 5 --constituents M2,XX".split(),
            "unknown tidal constituent 'XX'",
        ),
        (
            "west.14 --fort15 x.15 --dt 60 --start 2024-01-01 --run-days 5 --constituents M2,M2".split(),
            "constituents lists a constituent twice: M2, M2",
        ),
        # the reviewer's s.14 as -o and --fort13: the fort.13 was written over the mesh
        ("west.14 --fort13 OUT".split(), "-o and --fort13 are both"),
        ("west.14 --fort13 west.14".split(), "--fort13 would overwrite the MESH input"),
        (
            "west.14 --fort13 a.13 --fort15 a.13 --dt 60 --start 2024-01-01 --run-days 5".split(),
            "--fort13 and --fort15 are both a.13",
        ),
        (
            "west.14 --planar --fort15 x.15 --dt 60 --start 2024-01-01 --run-days 5".split(),
            "--fort15 writes a run in longitude, latitude degrees (ICS = 2), and --planar says the mesh is not",
        ),
        (
            "west.14 --fort15 x.15 --dt 60 --start 2024-01-01 --run-days 5 --tidal-atlas gone".split(),
            "--tidal-atlas: no such file: 'gone'",
        ),
        ("west.14 --dem gone.nc".split(), "--dem: no such file: 'gone.nc'"),
        # latitudes first: taken, and the merge kept other cells
        ("west.14 --boundaries --bbox 41.5 43.8 -70.5 -68".split(), "--bbox 41.5 43.8 -70.5 -68 does not overlap"),
        # the library's "pass geographic=True" was said as "pass geographic=True"
        ("west.14 --planar --dt 30".split(), 'give the mesh crs="EPSG:4326" or leave out --planar (read as degrees'),
    ],
)
def test_post_refuses_what_does_not_go_together_and_writes_nothing(written, tmp_path, capsys, arguments, message):
    folder, _ = written
    output = tmp_path / "out.14"
    named = [str(folder / word) if word.endswith((".14", ".msh")) else word for word in arguments]
    named = [str(output) if word == "OUT" else word for word in named]
    assert main(["post", *named, "-o", str(output)]) == 1
    error = capsys.readouterr().err
    assert error.startswith("terramesh post: error: ") and message in error
    assert not output.exists()


def test_post_writes_nothing_when_the_atlas_refuses_the_open_boundary(written, tmp_path, capsys):
    # the mesh and fort.13 were written, then the fort.15 refused: a run half written, exit 1
    folder, _ = written
    atlas = tmp_path / "tpxo"
    atlas.mkdir()
    write_atlas(atlas, ["M2"])  # off Florida, far from the Gulf of Maine
    output, fort13 = tmp_path / "out.14", tmp_path / "fort.13"
    status = main(
        ["post", str(folder / "west.14"), "-o", str(output), "--fort13", str(fort13), "--dt", "60",
         "--fort15", str(tmp_path / "fort.15"), "--start", "2024-01-01", "--run-days", "5",
         "--tidal-atlas", str(atlas), "--constituents", "M2"]
    )  # fmt: skip
    assert status == 1
    assert "terramesh post: error: " in capsys.readouterr().err
    assert sorted(path.name for path in tmp_path.iterdir()) == ["tpxo"]


def test_post_takes_a_time_step_that_is_no_divisor_of_the_output_intervals(written, tmp_path):
    # 20.9 s, the step coastal --dt 0 had picked, was refused: station_interval (600 s) must be a whole multiple
    folder, _ = written
    fort15 = tmp_path / "fort.15"
    with pytest.warns(TerrameshWarning) as caught:
        status = main(
            ["post", str(folder / "west.14"), "-o", str(tmp_path / "out.14"), "--dt", "20.9", "--fort15", str(fort15),
             "--start", "2024-01-01", "--run-days", "5"]
        )  # fmt: skip
    assert status == 0
    said = [str(warning.message) for warning in caught]
    assert (
        "station_interval (600 s) is not a whole number of time steps of dt = 20.9 s: written as 29 steps"
        in "".join(said)
    )
    line = next(line for line in fort15.read_text().splitlines() if "NSPOOLE" in line)
    assert line.split("!")[0].split()[-1] == "29"
