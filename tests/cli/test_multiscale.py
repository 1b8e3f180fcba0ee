"""``terramesh multiscale``: nested boxes from a TOML file, the same mesh as ``build_multiscale``."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.cli import main
from terramesh.cli.multiscale import read_config
from terramesh.errors import MeshFormatError, TerrameshWarning

# Gulf coast off Sabine Pass from GSHHS + ETOPO1 at 2 km, Sabine Pass from CUDEM's 0 m contour at 300 m; paths
# relative to the file, which sits beside a link to the shared data
CASE = """\
shoreline = "data/coast/GSHHS_l_L1.shp"
dem = "data/dem/ETOPO1_0.1.grd"
itmax = 60

[[box]]
bbox = [-94.6, -93.2, 29.3, 30.2]
min_el = 2000
max_el = 8000
fs = 3
g = 0.2

[[box]]
bbox = [-94.0, -93.8, 29.7, 29.9]
shoreline = false
dem = "data/dem/CUDEM_equal.nc"
min_el = 300
max_el = 1500
fs = 3
"""
WALLS = "box 1's shoreline and the outer boxes' disagree at its edge"


@pytest.fixture
def case(tmp_path, shared_data):
    (tmp_path / "data").symlink_to(shared_data)
    path = tmp_path / "case.toml"
    path.write_text(CASE)
    return path


def test_the_file_gives_the_mesh_build_multiscale_gives(case, tmp_path, capsys, shared_data):
    with pytest.warns(TerrameshWarning, match=WALLS):
        assert (
            main(
                ["multiscale", str(case), "-o", str(tmp_path / "out.14"), "--plots", str(tmp_path / "png"),
                 "--fort13", str(tmp_path / "out.13")]
            )
            == 0
        )  # fmt: skip
    printed = capsys.readouterr().out
    mesh = tm.read_mesh(tmp_path / "out.14")
    assert tm.cleanup.mesh_problems(mesh) == []
    boxes, options = read_config(case)
    assert boxes[1]["shoreline"] is None and boxes[1]["dem"] == tmp_path / "data" / "dem" / "CUDEM_equal.nc"
    assert options == {
        "shoreline": tmp_path / "data" / "coast" / "GSHHS_l_L1.shp",
        "dem": tmp_path / "data" / "dem" / "ETOPO1_0.1.grd",
        "max_iter": 60,
    }
    with pytest.warns(TerrameshWarning, match=WALLS):
        direct = tm.coastal.build_multiscale(
            [
                {"bbox": (-94.6, -93.2, 29.3, 30.2), "min_el": 2000, "max_el": 8000, "fs": 3, "g": 0.2},
                {
                    "bbox": (-94.0, -93.8, 29.7, 29.9),
                    "shoreline": None,
                    "dem": shared_data / "dem" / "CUDEM_equal.nc",
                    "min_el": 300,
                    "max_el": 1500,
                    "fs": 3,
                },
            ],
            shared_data / "coast" / "GSHHS_l_L1.shp",
            shared_data / "dem" / "ETOPO1_0.1.grd",
            max_iter=60,
        )
    np.testing.assert_allclose(mesh.points, direct.points, atol=1e-7)  # fort.14 keeps 10 digits
    np.testing.assert_array_equal(mesh.cells, direct.cells)
    np.testing.assert_allclose(mesh.depth, direct.depth, atol=1e-4)
    assert len(mesh.boundaries.open) == len(direct.boundaries.open) > 0
    # the estuary box is finer than the outer box
    edges = tm.mesh.topology.unique_edges(mesh.cells)
    middle = mesh.points[edges].mean(axis=1)
    length = np.linalg.norm(np.diff(mesh.points[edges], axis=1)[:, 0], axis=1)
    estuary = (middle[:, 0] > -94.0) & (middle[:, 0] < -93.8) & (middle[:, 1] > 29.7) & (middle[:, 1] < 29.9)
    assert np.median(length[estuary]) < 0.4 * np.median(length[~estuary])
    assert f"vertices {direct.n_points:,}" in printed and "boundaries:" in printed
    tau0 = tm.io.read_fort13(tmp_path / "out.13")["primitive_weighting_in_continuity_equation"]
    np.testing.assert_array_equal(tau0.values, tm.coastal.tau0(mesh).values)
    pictures = {path.name for path in (tmp_path / "png").iterdir()}
    assert {"size_box0.png", "size_box1.png", "mesh.png", "depth.png", "quality.png", "boundaries.png"} <= pictures


def test_the_command_line_overrides_the_files_method_and_seed(case, tmp_path):
    with pytest.warns(TerrameshWarning, match=WALLS):
        assert main(["multiscale", str(case), "-q", "-o", str(tmp_path / "a.14")]) == 0
    with pytest.warns(TerrameshWarning, match=WALLS):
        assert main(["multiscale", str(case), "-q", "--seed", "3", "-o", str(tmp_path / "b.14")]) == 0
    # merged box by box, the box's water ends at its edge as well: the same walls, which merge did not say
    with pytest.warns(TerrameshWarning, match=WALLS):
        assert main(["multiscale", str(case), "-q", "--method", "merge", "-o", str(tmp_path / "c.14")]) == 0
    a, b, c = (tm.read_mesh(tmp_path / name) for name in ("a.14", "b.14", "c.14"))
    assert a.n_points != b.n_points or not np.array_equal(a.points, b.points)
    for mesh in (b, c):
        assert tm.cleanup.mesh_problems(mesh) == []


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("dem = [1\n", "case.toml is not a TOML file"),
        ("min_el = 100\n[[box]]\nbbox = [0, 1, 0, 1]\n", "'min_el' is not an option of the file's top level"),
        ('shoreline = "x.shp"\n', "no [[box]] tables: give one per box"),
        ("[[box]]\nmin_el = 100\n", "box 0 has no bbox"),
        (
            "[[box]]\nbbox = [0, 1, 0, 1]\ndem = 3\n",
            "box 0: dem must be a file's path (a string) or false for none, got 3",
        ),
        (
            "itmax = 10\nmax_iter = 20\n[[box]]\nbbox = [0, 1, 0, 1]\n",
            "top level: 'itmax' and 'max_iter' name one option",
        ),
        ("[[box]]\nbbox = [0, 1, 0, 1]\nh0 = 100\nmin_el = 200\n", "box 0: 'h0' and 'min_el' name one option"),
        ("[[box]]\nbbox = [0, 1, 0, 1]\npolygon_bounds = 1\n", "box 0: 'polygon_bounds' is not an option of a box"),
    ],
)
def test_a_malformed_file_is_named_with_what_is_wrong(tmp_path, capsys, text, message):
    path = tmp_path / "case.toml"
    path.write_text(text)
    with pytest.raises(MeshFormatError, match=message.replace("[", r"\[").replace("(", r"\(").replace(")", r"\)")):
        read_config(path)
    assert main(["multiscale", str(path), "-o", str(tmp_path / "out.14")]) == 1
    assert message in capsys.readouterr().err


def test_tau0_needs_a_dem_and_is_refused_before_meshing_without_one(case, tmp_path, capsys):
    case.write_text(
        CASE.replace('dem = "data/dem/ETOPO1_0.1.grd"\n', "").replace('dem = "data/dem/CUDEM_equal.nc"', "")
    )
    assert (
        main(["multiscale", str(case), "-q", "-o", str(tmp_path / "out.14"), "--fort13", str(tmp_path / "x.13")]) == 1
    )
    assert "--fort13 writes tau0 from the depths, and no box of" in capsys.readouterr().err
    assert not (tmp_path / "out.14").exists()


def test_a_misspelled_box_option_and_a_missing_file_are_named(case, tmp_path, capsys):
    case.write_text(CASE.replace("fs = 3\ng = 0.2", "fs = 3\ngrade_rate = 0.2"))
    assert main(["multiscale", str(case), "-q", "-o", str(tmp_path / "out.14")]) == 1
    assert "box 0: 'grade_rate' is not an option of a box, which takes bbox, ch, channels" in capsys.readouterr().err
    case.write_text(CASE.replace("ETOPO1_0.1.grd", "ETOPO2.grd"))
    assert main(["multiscale", str(case), "-q", "-o", str(tmp_path / "out.14")]) == 1
    assert "ETOPO2.grd" in capsys.readouterr().err
    assert main(["multiscale", str(tmp_path / "none.toml"), "-q"]) == 1
    assert f"terramesh multiscale: error: no such case file: '{tmp_path / 'none.toml'}'" in capsys.readouterr().err
