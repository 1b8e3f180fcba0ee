import re
import warnings

import numpy as np
import pyproj
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import MeshFormatError, MeshValidityError, TerrameshWarning
from terramesh.io import Boundaries, LandBoundary, OpenBoundary

SAMPLE = """\
sample grid with boundaries   ! title
4 5      NE NP
11 -94.0 29.7 5.5
12 -93.9 29.7 6.0 extra text
13 -93.9 29.8 7.25
14 -94.0 29.8 1.0
15 -93.95 29.75 3.0
1 3 11 12 15
2 3 12 13 15
3 3 13 14 15
4 3 14 11 15
1 = Number of open boundaries
2 = Total number of open boundary nodes
2 = Number of nodes for open boundary 1 (no IBTYPEE)
11
12
2 = Number of land boundaries
5 = Total number of land boundary nodes
3 20 = Number of nodes for land boundary 1
12
13
14
1 24 = weir pair
13 15 1.5 1.0 0.9
"""


def write_sample(tmp_path, text=SAMPLE):
    path = tmp_path / "fort.14"
    path.write_text(text)
    return path


def test_reads_labels_comments_and_boundaries(tmp_path):
    mesh = tm.read_mesh(write_sample(tmp_path))
    assert mesh.title.startswith("sample grid")
    assert (mesh.n_points, mesh.n_cells) == (5, 4)
    np.testing.assert_array_equal(mesh.cells[0], [0, 1, 4])
    np.testing.assert_allclose(mesh.point_data["depth"], [5.5, 6.0, 7.25, 1.0, 3.0])
    (open_boundary,) = mesh.boundaries.open
    np.testing.assert_array_equal(open_boundary.nodes, [0, 1])
    assert open_boundary.ibtype is None
    land, weir = mesh.boundaries.land
    assert land.ibtype == 20 and land.values is None
    np.testing.assert_array_equal(land.nodes, [1, 2, 3])
    assert weir.ibtype == 24
    np.testing.assert_array_equal(weir.paired_nodes, [4])
    np.testing.assert_allclose(weir.values, [[1.5, 1.0, 0.9]])


def test_round_trip_is_lossless_and_counts_paired_nodes_twice(tmp_path):
    mesh = tm.read_mesh(write_sample(tmp_path))
    out = tmp_path / "again.14"
    mesh.write(out)
    lines = out.read_text().splitlines()
    assert lines[-7].startswith("5 ")  # NVEL: 3 + 2 * 1, the weir's back face counted
    again = tm.read_mesh(out)
    assert_same(mesh, again)


def assert_same(a, b):
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.cells, b.cells)
    np.testing.assert_array_equal(a.point_data["depth"], b.point_data["depth"])
    assert len(a.boundaries.open) == len(b.boundaries.open)
    assert len(a.boundaries.land) == len(b.boundaries.land)
    for x, y in zip(a.boundaries.open, b.boundaries.open, strict=True):
        np.testing.assert_array_equal(x.nodes, y.nodes)
        assert x.ibtype == y.ibtype
    for x, y in zip(a.boundaries.land, b.boundaries.land, strict=True):
        np.testing.assert_array_equal(x.nodes, y.nodes)
        assert x.ibtype == y.ibtype
        for field in ("paired_nodes", "values"):
            left, right = getattr(x, field), getattr(y, field)
            assert (left is None) == (right is None)
            if left is not None:
                np.testing.assert_array_equal(left, right)


finite = st.floats(-1e6, 1e6, allow_nan=False)


@st.composite
def valid_cells(draw):
    """``(points, cells)`` a fort.14 can hold: a jittered grid anywhere, nodes and cells in any order.

    Any floats as coordinates, any numbering, any first corner; but every
    cell counter-clockwise and of positive area, none twice, every node in
    a cell (the writer refuses others).
    """
    rows, columns = draw(st.integers(2, 6)), draw(st.integers(2, 7))
    n = rows * columns
    origin = np.array(draw(st.tuples(finite, finite)))
    spacing = np.array(draw(st.tuples(st.floats(1e-2, 1e3), st.floats(1e-2, 1e3))))
    # under a quarter of the spacing: each quad stays convex, both its triangles counter-clockwise
    jitter = np.array(draw(st.lists(st.tuples(*[st.floats(-0.2, 0.2)] * 2), min_size=n, max_size=n)))
    grid = np.column_stack([np.tile(np.arange(columns), rows), np.repeat(np.arange(rows), columns)])
    points = origin + (grid + jitter) * spacing
    corner = (np.arange(rows - 1)[:, None] * columns + np.arange(columns - 1)).ravel()
    cells = np.concatenate(
        [
            np.column_stack([corner, corner + 1, corner + columns + 1]),
            np.column_stack([corner, corner + columns + 1, corner + columns]),
        ]
    )
    order = np.array(draw(st.permutations(range(n))))  # node k of the grid is node order[k] of the mesh
    new_points = np.empty_like(points)
    new_points[order] = points
    cells = order[cells][np.array(draw(st.permutations(range(len(cells)))))]
    turns = np.array(draw(st.lists(st.integers(0, 2), min_size=len(cells), max_size=len(cells))))
    cells = np.take_along_axis(cells, (np.arange(3) + turns[:, None]) % 3, axis=1)  # the same cell, turned
    return new_points, cells


@st.composite
def meshes_with_boundaries(draw):
    points, cells = draw(valid_cells())
    n = len(points)
    depth = np.array(draw(st.lists(finite, min_size=n, max_size=n)))
    nodes = st.lists(st.integers(0, n - 1), min_size=1, max_size=10).map(np.array)
    opens = draw(st.lists(st.builds(OpenBoundary, nodes, st.one_of(st.none(), st.sampled_from([0, 1]))), max_size=3))
    lands = []
    for ibtype in draw(st.lists(st.sampled_from([0, 1, 20, 21, 3, 13, 23, 4, 24, 64, 5, 25]), max_size=4)):
        where = draw(nodes)
        columns = {3: 2, 13: 2, 23: 2, 4: 3, 24: 3, 64: 3, 5: 6, 25: 6}.get(ibtype, 0)
        paired = (
            draw(st.lists(st.integers(0, n - 1), min_size=len(where), max_size=len(where)))
            if ibtype in (4, 24, 64, 5, 25)
            else None
        )
        values = (
            np.array(
                draw(
                    st.lists(
                        st.lists(finite, min_size=columns, max_size=columns), min_size=len(where), max_size=len(where)
                    )
                )
            )
            if columns
            else None
        )
        lands.append(LandBoundary(where, ibtype, None if paired is None else np.array(paired), values))
    title = draw(st.text(st.characters(codec="ascii", exclude_categories=["Cc"]), max_size=30))
    return tm.Mesh(points, cells, point_data={"depth": depth}, boundaries=Boundaries(opens, lands), title=title)


@pytest.mark.filterwarnings("ignore:.*have a depth no place on Earth has")  # numbers, not places
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(meshes_with_boundaries())
def test_hypothesis_round_trip(tmp_path, mesh):
    before = (mesh.points.copy(), mesh.cells.copy())
    path = tmp_path / "random.14"
    mesh.write(path)
    np.testing.assert_array_equal(mesh.cells, before[1])  # the writer does not mutate
    np.testing.assert_array_equal(mesh.points, before[0])
    assert_same(mesh, tm.read_mesh(path))


@pytest.mark.parametrize(
    "cut, message",
    [
        (lambda text: text.splitlines()[:5], "expected 5 lines of node"),
        (lambda text: text.splitlines()[:9], "expected 4 lines of element"),
        (lambda text: text.splitlines()[:14], "expected 2 lines of open boundary"),
        (lambda text: text.splitlines()[:1], "NE NP"),
    ],
)
def test_truncated_files_raise_clear_errors(tmp_path, cut, message):
    path = write_sample(tmp_path, "\n".join(cut(SAMPLE)) + "\n")
    with pytest.raises(MeshFormatError, match=message):
        tm.read_mesh(path)


def test_bad_references_and_formats(tmp_path):
    bad = SAMPLE.replace("4 3 14 11 15", "4 3 14 11 99")
    with pytest.raises(MeshFormatError, match="node 99"):
        tm.read_mesh(write_sample(tmp_path, bad))
    with pytest.raises(MeshFormatError, match="from its name"):
        tm.write_mesh(tmp_path / "x.unknown", tm.read_mesh(write_sample(tmp_path)))
    with pytest.raises(FileNotFoundError):
        tm.read_mesh(tmp_path / "missing.14")
    (tmp_path / "run.14").mkdir()  # was a bare "[Errno 21] Is a directory"
    with pytest.raises(MeshFormatError, match=r"run.14 is a folder, not a mesh file"):
        tm.read_mesh(tmp_path / "run.14")


def _numbered(labels, corners=((0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4))):
    """A fort.14 of SAMPLE's five nodes numbered ``labels`` (in file order), its cells by position."""
    coordinates = [(-94.0, 29.7), (-93.9, 29.7), (-93.9, 29.8), (-94.0, 29.8), (-93.95, 29.75)]
    nodes = [f"{label} {x} {y} 1.0" for label, (x, y) in zip(labels, coordinates, strict=True)]
    cells = [f"{k + 1} 3 " + " ".join(str(labels[c]) for c in cell) for k, cell in enumerate(corners)]
    return "\n".join(["numbered", f"{len(cells)} {len(nodes)}", *nodes, *cells]) + "\n"


@pytest.mark.parametrize(
    "labels",
    [(11, 12, 13, 14, 15), (1, 2, 3, 4, 5), (13, 11, 15, 12, 14), (10, 20, 30, 40, 50), (5, 4, 3, 2, 1)],
)
def test_node_numbers_in_order_or_not_are_found(tmp_path, labels):
    mesh = tm.read_mesh(write_sample(tmp_path, _numbered(labels)))
    np.testing.assert_array_equal(mesh.cells, [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)])
    missing = _numbered(labels).replace(f"4 3 {labels[3]} {labels[0]} {labels[4]}", f"4 3 {labels[3]} 99 {labels[4]}")
    with pytest.raises(MeshFormatError, match="element refers to node 99 that does not exist"):
        tm.read_mesh(write_sample(tmp_path, missing))


@pytest.mark.parametrize("labels", [(11, 12, 13, 13, 15), (3, 1, 2, 1, 5)])
def test_repeated_node_numbers_are_refused(tmp_path, labels):
    with pytest.raises(MeshFormatError, match="node numbers are not unique"):
        tm.read_mesh(write_sample(tmp_path, _numbered(labels)))


def test_element_numbers_written_with_decimals_are_read_when_whole(tmp_path):
    """Elements are read as integers; a writer's ``3.0`` takes the float path and must be a whole number."""
    decimals = SAMPLE.replace("1 3 11 12 15", "1 3.0 11.0 12 15.0")
    mesh = tm.read_mesh(write_sample(tmp_path, decimals))
    np.testing.assert_array_equal(mesh.cells, tm.read_mesh(write_sample(tmp_path)).cells)
    with pytest.raises(MeshFormatError, match=r"element lines \(JE NHY NM1 NM2 NM3\) must hold whole numbers"):
        tm.read_mesh(write_sample(tmp_path, SAMPLE.replace("1 3 11 12 15", "1 3 11 12.5 15")))
    with pytest.raises(MeshFormatError, match="cannot read element lines"):
        tm.read_mesh(write_sample(tmp_path, SAMPLE.replace("1 3 11 12 15", "1 3 11 twelve 15")))


def test_fill_values_for_depth_warn_with_their_nodes(tmp_path):
    # a depth of -99999 (no data) was read without a word: land 100 km high to ADCIRC
    filled = SAMPLE.replace("12 -93.9 29.7 6.0", "12 -93.9 29.7 -99999").replace(
        "13 -93.9 29.8 7.25", "13 -93.9 29.8 1e20"
    )
    message = (
        r"fort\.14: 2 of 5 nodes have a depth no place on Earth has \(more than 9000 m above the datum or 11100 m "
        r"below it\): node 12 \(line 4: -99999 m\), node 13 \(line 5: 1e\+20 m\); fill values for no data\?"
    )
    with pytest.warns(TerrameshWarning, match=message):
        mesh = tm.read_mesh(write_sample(tmp_path, filled))
    assert mesh.depth[1] == -99999
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tm.read_mesh(write_sample(tmp_path, SAMPLE.replace("12 -93.9 29.7 6.0", "12 -93.9 29.7 10900")))


@pytest.mark.parametrize("extension", [".14", ".gr3"])
def test_nan_depth_is_refused_and_nothing_is_written(tmp_path, extension):
    mesh = tm.read_mesh(write_sample(tmp_path))
    depth = mesh.point_data["depth"].copy()
    depth[[2, 4]] = [np.nan, np.inf]
    mesh.point_data["depth"] = depth
    target = tmp_path / f"no_dem{extension}"
    with pytest.raises(MeshFormatError, match="NaN or infinite at 2 of .* nodes \\(node 3 first"):
        tm.write_mesh(target, mesh)
    assert not target.exists()


@pytest.mark.parametrize("extension", [".14", ".gr3"])
@pytest.mark.parametrize("depth", [np.ones(3), np.full(5, "deep"), np.ones((5, 2))])
def test_depth_of_the_wrong_shape_or_type_is_refused(tmp_path, extension, depth):
    # numpy's own ValueError came from inside the writer
    mesh = tm.read_mesh(write_sample(tmp_path))
    mesh.point_data["depth"] = depth
    with pytest.raises(MeshFormatError, match=r"one number per node, shape \(5,\)"):
        tm.write_mesh(tmp_path / f"bad{extension}", mesh)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("2 = Total number of open", "7 = Total number of open", "line 13: NETA is 7, but the boundary strings hold 2"),
        ("5 = Total number of land", "9 = Total number of land", "line 18: NVEL is 9, but the boundary strings hold 5"),
        ("13 15 1.5 1.0 0.9\n", "13 15 1.5 1.0 0.9\n12\n13\n", "2 lines after the last land boundary"),
    ],
)
def test_boundary_totals_that_disagree_and_lines_left_unread_warn(tmp_path, old, new, message):
    with pytest.warns(TerrameshWarning, match=message):
        mesh = tm.read_mesh(write_sample(tmp_path, SAMPLE.replace(old, new)))
    assert len(mesh.boundaries.open) == 1 and len(mesh.boundaries.land) == 2


def test_nvel_counting_a_barrier_pair_once_is_read_quietly(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tm.read_mesh(write_sample(tmp_path, SAMPLE.replace("5 = Total number of land", "4 = Total number of land")))


@pytest.mark.parametrize("extension", [".14", ".gr3"])
def test_non_finite_coordinates_are_refused_and_nothing_is_written(tmp_path, extension):
    mesh = tm.read_mesh(write_sample(tmp_path))
    points = mesh.points.copy()
    points[3, 1], points[4, 0] = np.inf, np.nan
    mesh.points = points
    target = tmp_path / f"nan_points{extension}"
    with pytest.raises(MeshFormatError, match="coordinates are NaN or infinite at 2 of 5 nodes \\(node 4 first"):
        tm.write_mesh(target, mesh)
    assert not target.exists()


def test_non_finite_coordinates_in_a_file_are_refused(tmp_path):
    node_line = SAMPLE.splitlines()[3]
    broken = node_line.split()
    broken[2] = "NaN"
    with pytest.raises(MeshFormatError, match="coordinates are NaN or infinite at 1 of 5 nodes \\(node 2 first"):
        tm.read_mesh(write_sample(tmp_path, SAMPLE.replace(node_line, " ".join(broken))))


@pytest.mark.parametrize("extension", [".14", ".gr3"])
def test_nan_depths_in_a_file_are_refused_naming_the_nodes_and_lines(tmp_path, extension):
    """``nan`` reads as a number: the file was read without a word, and ``terramesh info`` called it valid."""
    text = SAMPLE.replace("13 -93.9 29.8 7.25", "13 -93.9 29.8 nan").replace(
        "15 -93.95 29.75 3.0", "15 -93.95 29.75 -inf"
    )
    path = tmp_path / f"nan_depth{extension}"
    path.write_text(text)
    said = r"nan_depth\.(14|gr3): depth is NaN or infinite at 2 of 5 nodes: node 13 \(line 5\), node 15 \(line 7\)\. "
    with pytest.raises(MeshFormatError, match=said + "ADCIRC and SCHISM read no such depth"):
        tm.read_mesh(path)


@pytest.mark.parametrize(
    "boundaries, message",
    [
        (Boundaries(open=[OpenBoundary(np.array([0, 100]))]), "open boundary refers to node 100 .* 5 nodes"),
        (Boundaries(land=[LandBoundary(np.array([-1, 2]), 20)]), "land boundary refers to node -1"),
        (Boundaries(land=[LandBoundary(np.array([1]), 24, np.array([5]), np.ones((1, 3)))]), "barrier pair .* 5"),
        (Boundaries(land=[LandBoundary(np.array([1, 2]), 24)]), "IBTYPE 24\\) needs paired_nodes"),
        (Boundaries(land=[LandBoundary(np.array([1]), 4, np.array([4]))]), "needs values of shape \\(1, 3\\)"),
        (Boundaries(land=[LandBoundary(np.array([1]), 5, np.array([4]), np.ones((1, 3)))]), "shape \\(1, 6\\)"),
        (Boundaries(land=[LandBoundary(np.array([1]), 23)]), "IBTYPE 23\\) needs values of shape \\(1, 2\\)"),
        (Boundaries(land=[LandBoundary(np.array([1]), 3, np.array([4]), np.ones((1, 2)))]), "not a paired"),
        (Boundaries(land=[LandBoundary(np.array([1]), 13, None, np.full((1, 2), np.nan))]), "NaN or infinite"),
    ],
)
def test_boundaries_the_file_cannot_hold_are_refused(tmp_path, boundaries, message):
    mesh = tm.read_mesh(write_sample(tmp_path))
    mesh.boundaries = boundaries
    target = tmp_path / "bad_boundaries.14"
    with pytest.raises(MeshFormatError, match=message):
        tm.write_mesh(target, mesh)
    assert not target.exists()


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(meshes_with_boundaries(), st.integers(0, 10**6), st.integers(0, 3), st.data())
def test_hypothesis_boundary_nodes_outside_the_mesh_are_refused(tmp_path, mesh, beyond, which, data):
    strings = [b.nodes for b in mesh.boundaries.open + mesh.boundaries.land]
    strings += [b.paired_nodes for b in mesh.boundaries.land if b.paired_nodes is not None]
    if not strings:
        mesh.boundaries.open.append(OpenBoundary(np.array([0])))
        strings = [mesh.boundaries.open[0].nodes]
    nodes = strings[which % len(strings)]
    nodes[data.draw(st.integers(0, len(nodes) - 1))] = data.draw(st.sampled_from([mesh.n_points + beyond, -1 - beyond]))
    path = tmp_path / "outside.14"
    with pytest.raises(MeshFormatError, match="refers to node -?[0-9]+ \\(0-based\\)"):
        mesh.write(path)
    assert not path.exists()


@pytest.mark.parametrize(
    "old, new, message",
    [
        ("2 = Number of nodes for open boundary 1", "-2 = Number of nodes", "line 14: negative NVDLL \\(-2\\)"),
        ("3 20 = Number of nodes for land boundary 1", "-3 20", "line 19: negative NVELL \\(-3\\)"),
        ("1 = Number of open boundaries", "-1 = Number of open boundaries", "line 12: negative NOPE"),
        ("2 = Number of land boundaries", "-2 = Number of land boundaries", "line 17: negative NBOU"),
    ],
)
def test_negative_boundary_counts_are_refused(tmp_path, old, new, message):
    assert old in SAMPLE
    with pytest.raises(MeshFormatError, match=message):
        tm.read_mesh(write_sample(tmp_path, SAMPLE.replace(old, new)))


def test_grid_without_boundary_section(tmp_path):
    text = "\n".join(SAMPLE.splitlines()[:11]) + "\n"
    mesh = tm.read_mesh(write_sample(tmp_path, text))
    assert mesh.boundaries.open == [] and mesh.boundaries.land == []


def test_coordinates_in_degrees_read_as_longitude_latitude(tmp_path):
    # fort.14 keeps no reference system; read as metres, a coastal mesh's courant numbers came out 4e4
    # times too large and enforce_timestep cut 1,302 vertices to 84
    planar = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2000, 1000)), 100.0)
    planar.point_data["depth"] = np.full(planar.n_points, 20.0)
    geographic = tm.Mesh(
        planar.points / 1e5 + (-70.0, 40.0), planar.cells, point_data=dict(planar.point_data), crs="EPSG:4326"
    )
    for extension in (".14", ".gr3"):
        for mesh, crs in ((geographic, "EPSG:4326"), (planar, None)):
            path = tmp_path / f"{crs}{extension}"
            mesh.write(path)
            back = tm.read_mesh(path)
            assert back.crs == crs
            assert np.allclose(tm.coastal.courant_number(back, 10.0), tm.coastal.courant_number(mesh, 10.0))
        # a planar mesh whose coordinates happen to fit, said so
        assert tm.read_mesh(tmp_path / f"EPSG:4326{extension}", crs=None).crs is None
    assert tm.read_mesh(tmp_path / "EPSG:4326.14", crs="EPSG:32619").crs == "EPSG:32619"
    # the meshio formats keep none either: the same rule (the demo's .vtu measured mean q 0.83 against 0.96)
    for extension in (".vtu", ".msh", ".xdmf"):
        planar.write(tmp_path / f"planar{extension}")
        geographic.write(tmp_path / f"geographic{extension}")
        assert tm.read_mesh(tmp_path / f"planar{extension}").crs is None
        assert tm.read_mesh(tmp_path / f"geographic{extension}").crs == "EPSG:4326"
        assert tm.read_mesh(tmp_path / f"geographic{extension}", crs=None).crs is None


GRID_ONLY = "\n".join(SAMPLE.splitlines()[:11]) + "\n"
OPEN_ONLY = "\n".join(SAMPLE.splitlines()[:16]) + "\n"


@pytest.mark.parametrize(
    ("text", "n_open", "n_land"),
    [
        (SAMPLE + "\n\n", 1, 2),
        (SAMPLE + "   \n\t\n", 1, 2),
        (GRID_ONLY + "\n", 0, 0),
        (GRID_ONLY + "\n  \n\n", 0, 0),
        (OPEN_ONLY + "\n", 1, 0),
    ],
)
@pytest.mark.parametrize("extension", [".14", ".gr3"])
def test_blank_lines_at_the_end_are_ignored(tmp_path, text, n_open, n_land, extension):
    """They were read as NOPE or NBOU: "line 12: NOPE needs 1 values, found 0"."""
    path = tmp_path / f"grid{extension}"
    path.write_text(text)
    if (n_open, n_land) == (1, 0):  # ADCIRC reads NBOU and NVEL next: said to be cut short
        with pytest.warns(TerrameshWarning, match="ends after the open boundaries"):
            mesh = tm.read_mesh(path)
    else:
        mesh = tm.read_mesh(path)
    assert (mesh.n_points, mesh.n_cells) == (5, 4)
    assert (len(mesh.boundaries.open), len(mesh.boundaries.land)) == (n_open, n_land)


def _replace_line(number, new):
    """SAMPLE with its 1-based line ``number`` replaced by ``new`` (which may hold several lines)."""
    lines = SAMPLE.splitlines()
    lines[number - 1] = new
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        # blank lines inside tables gave numpy's "cannot reshape array of size 16 into shape (5,4)"
        (_replace_line(5, "\n13 -93.9 29.8 7.25"), r"line 5: blank line among the node lines"),
        (_replace_line(9, "2 3 12 13 15\n  "), r"line 10: blank line among the element lines"),
        (_replace_line(16, "\n12"), r"line 16: blank line among the open boundary nodes"),
        (_replace_line(21, "\n14"), r"line 21: blank line among the land boundary nodes \(IBTYPE 20\)"),
        # loadtxt's rows were counted within the table ("at row 2, column 3" for file line 5)
        (_replace_line(5, "13 -93.9 abc 7.25"), r"line 5: cannot read node lines \(JN X Y DP\): 'abc' is not a number"),
        (_replace_line(11, "4 3 14 11"), r"line 11: element lines \(JE NHY NM1 NM2 NM3\) need 5 values, found 4"),
        (_replace_line(24, "13 15 1.5 x 0.9"), r"line 24: cannot read land boundary nodes \(IBTYPE 24\): 'x'"),
        (_replace_line(8, "1 3 11 12 15.5"), r"line 8: element lines \(JE NHY NM1 NM2 NM3\) must hold whole numbers"),
        (_replace_line(11, "4 3 14 11 99"), r"line 11: element refers to node 99 that does not exist"),
        (_replace_line(20, "99"), r"line 20: land boundary refers to node 99 that does not exist"),
    ],
)
def test_table_errors_name_the_file_and_its_line(tmp_path, text, message):
    with pytest.raises(MeshFormatError, match=r"fort\.14: " + message):
        tm.read_mesh(write_sample(tmp_path, text))


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        # were truncated: the land boundary 1.9, 3.7 became nodes [0 2]
        ("12\n13\n14\n", "12\n13.7\n14\n", r"line 21: land boundary nodes \(IBTYPE 20\) must hold whole numbers"),
        ("11\n12\n2 = Number of land", "11\n12.5\n2 = Number of land", r"line 16: open boundary nodes must hold"),
        ("13 15 1.5", "13 15.2 1.5", r"line 24: land boundary nodes \(IBTYPE 24\) must hold whole numbers in columns"),
        ("12 -93.9 29.7 6.0", "12.9 -93.9 29.7 6.0", r"line 4: node lines .* whole numbers in column 1, found '12.9"),
    ],
)
def test_fractional_node_numbers_are_refused(tmp_path, old, new, message):
    assert old in SAMPLE
    with pytest.raises(MeshFormatError, match=message):
        tm.read_mesh(write_sample(tmp_path, SAMPLE.replace(old, new)))


def test_node_numbers_written_with_decimals_are_read_when_whole(tmp_path):
    whole = SAMPLE.replace("12 -93.9 29.7 6.0", "12.0 -93.9 29.7 6.0").replace("12\n13\n14\n", "12\n13.0\n14\n")
    assert_same(tm.read_mesh(write_sample(tmp_path, whole)), tm.read_mesh(write_sample(tmp_path)))


@pytest.mark.parametrize("start", [2**60, 2**63 - 5, -(2**63)])
def test_node_numbers_are_exact_up_to_the_int64_range(tmp_path, start):
    """Read as floats, 2**60 .. 2**60 + 3 were "not unique"."""
    labels = (start, start + 1, start + 3, start + 2, start + 4)
    mesh = tm.read_mesh(write_sample(tmp_path, _numbered(labels)))
    np.testing.assert_array_equal(mesh.cells, [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)])


def test_no_elements_reads_without_a_numpy_warning(tmp_path):
    """loadtxt warned "input contained no data" on NE = 0 (an error under the suite's filterwarnings)."""
    mesh = tm.read_mesh(write_sample(tmp_path, "points only\n0 3\n1 0 0 1\n2 1 0 1\n3 0 1 1\n"))
    assert (mesh.n_points, mesh.n_cells) == (3, 0)


@pytest.mark.parametrize("extension", [".14", ".gr3"])
def test_boundaries_given_as_lists_are_written(tmp_path, extension):
    """``boundary.nodes + 1`` raised TypeError on a list, half-way through the file."""
    mesh = tm.read_mesh(write_sample(tmp_path))
    mesh.boundaries = Boundaries(
        open=[OpenBoundary([0, 1])],
        land=[LandBoundary([1, 2, 3], 20), LandBoundary([2], 24, [4], [[1.5, 1.0, 0.9]])],
    )
    path = tmp_path / f"lists{extension}"
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "hgrid.gr3 has no barrier", TerrameshWarning)
        mesh.write(path)
    again = tm.read_mesh(path)
    np.testing.assert_array_equal(again.boundaries.open[0].nodes, [0, 1])
    np.testing.assert_array_equal(again.boundaries.land[0].nodes, [1, 2, 3])
    if extension == ".14":
        np.testing.assert_array_equal(again.boundaries.land[1].paired_nodes, [4])
        np.testing.assert_allclose(again.boundaries.land[1].values, [[1.5, 1.0, 0.9]])


def test_fractional_boundary_indices_are_refused_when_writing(tmp_path):
    mesh = tm.read_mesh(write_sample(tmp_path))
    mesh.boundaries = Boundaries(land=[LandBoundary(np.array([1.0, 2.5]), 20)])
    with pytest.raises(MeshFormatError, match="a land boundary refers to node 2.5: node indices must be whole"):
        mesh.write(tmp_path / "out.14")
    assert not (tmp_path / "out.14").exists()


@pytest.mark.parametrize("extension", [".14", ".gr3"])
def test_a_failed_write_leaves_the_previous_file_and_nothing_else(tmp_path, monkeypatch, extension):
    """The file was opened in place: a failure half-way left a truncated grid."""
    from terramesh.io import fort14

    mesh = tm.read_mesh(write_sample(tmp_path))
    mesh.boundaries.land.pop()  # the weir, which a gr3 cannot hold (a warning)
    folder = tmp_path / "out"
    folder.mkdir()
    path = folder / f"grid{extension}"
    mesh.write(path)
    before = path.read_bytes()

    def disk_full(handle, boundaries):
        raise OSError("No space left on device")

    monkeypatch.setattr(fort14, "write_boundaries", disk_full)
    with pytest.raises(OSError, match="No space left"):
        mesh.write(path)
    assert path.read_bytes() == before
    assert [entry.name for entry in folder.iterdir()] == [path.name]


def test_title_is_written_on_one_line(tmp_path):
    """Only newlines were replaced: a form feed or U+2028 (line breaks to str.splitlines) broke the file."""
    mesh = tm.read_mesh(write_sample(tmp_path))
    mesh.title = "tides\x0cof\u2028the\r\ngulf\x1c "
    path = tmp_path / "title.14"
    mesh.write(path)
    again = tm.read_mesh(path)
    assert again.title == "tides of the gulf"
    assert_same(mesh, again)


def fortran_d(text, marker="D", plus=True):
    """``text`` with its numbers' exponents written as Fortran's double precision (``1e+17`` -> ``1D+17``).

    The first line (the title) is left as it is; ``plus=False`` drops the
    exponent's ``+`` (``1D17``).
    """
    title, _, rest = text.partition("\n")
    sign = {"+": "+" if plus else "", "-": "-"}
    return title + "\n" + re.sub(r"(?<=[0-9])e([+-])(?=[0-9])", lambda m: marker + sign[m[1]], rest)


# SAMPLE with D exponents (all three spellings) in coordinates, depths, node numbers and barrier values
SAMPLE_D = (
    SAMPLE.replace("sample grid with boundaries   ! title", "Delaware Bay DEM grid ! dredged to 1.0D+01 m")
    .replace("11 -94.0 29.7 5.5", "11 -9.4D+01 2.97d1 5.5D0")
    .replace("12 -93.9 29.7 6.0 extra text", "12 -93.9 29.7 6.0D+00 extra text: D and d")
    .replace("13 -93.9 29.8 7.25", "1.3D1 -93.9 29.8 725.0d-2")
    .replace("15 -93.95 29.75 3.0", "15 -93.95 29.75 3.0D0")
    .replace("4 3 14 11 15", "4 3.0D0 14 11 15")
    .replace("11\n12\n2 = Number of land", "1.1d+1\n12\n2 = Number of land")
    .replace("13 15 1.5 1.0 0.9", "13 15 1.5D+00 1.0d0 9.0D-1")
)


@pytest.mark.parametrize("extension", [".14", ".gr3"])
def test_fortran_d_exponents_read_as_e_and_a_title_with_d_is_kept(tmp_path, extension):
    """ADCIRC's list-directed READ takes 1.0D+01; "'1.0D+01' is not a number" was raised."""
    path = tmp_path / f"fortran{extension}"
    path.write_text(SAMPLE_D)
    mesh = tm.read_mesh(path)
    plain = tm.read_mesh(write_sample(tmp_path))
    assert mesh.title == "Delaware Bay DEM grid ! dredged to 1.0D+01 m"
    if extension == ".14":
        assert_same(mesh, plain)
    else:
        np.testing.assert_array_equal(mesh.points, plain.points)
        np.testing.assert_array_equal(mesh.point_data["depth"], plain.point_data["depth"])
    mesh.boundaries.land.pop()  # the weir, which a gr3 cannot hold (a warning)
    again = tmp_path / f"again{extension}"
    mesh.write(again)
    back = tm.read_mesh(again)
    assert back.title == "Delaware Bay DEM grid ! dredged to 1.0D+01 m"
    np.testing.assert_array_equal(back.points, mesh.points)
    np.testing.assert_array_equal(back.point_data["depth"], mesh.point_data["depth"])


@pytest.mark.parametrize(
    ("line", "new", "message"),
    [
        # quoted as written, not as the E it was tried as
        (5, "13 -93.9 29.8 1.0D+0X", r"line 5: cannot read node lines \(JN X Y DP\): '1\.0D\+0X' is not a number"),
        (5, "13 -93.9 1.0X+01 7.25", r"line 5: cannot read node lines \(JN X Y DP\): '1\.0X\+01' is not a number"),
        (5, "13 -93.9 D 7.25", r"line 5: cannot read node lines \(JN X Y DP\): 'D' is not a number"),
        (10, "3 3 13 14 1.55D1", r"line 10: element lines \(JE NHY NM1 NM2 NM3\) must hold whole numbers"),
        (24, "13 15 1.5 1.0d 0.9", r"line 24: cannot read land boundary nodes \(IBTYPE 24\): '1\.0d'"),
    ],
)
def test_bad_numbers_among_fortran_exponents_are_named_as_written(tmp_path, line, new, message):
    """The D exponents on lines 3 and 24 read; the error names the line and token that do not."""
    text = SAMPLE_D.splitlines()
    text[line - 1] = new
    with pytest.raises(MeshFormatError, match=r"fort\.14: " + message):
        tm.read_mesh(write_sample(tmp_path, "\n".join(text) + "\n"))


exponents = st.sampled_from([1.0, -1.0]).flatmap(
    lambda sign: st.one_of(st.floats(1e17, 1e300), st.floats(1e-300, 1e-5)).map(lambda x: sign * x)
)


@pytest.mark.filterwarnings("ignore:.*have a depth no place on Earth has")  # numbers, not places
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(meshes_with_boundaries(), exponents, st.sampled_from(["D", "d"]), st.booleans())
def test_hypothesis_fortran_d_exponents_read_as_written_with_e(tmp_path, mesh, depth, marker, plus):
    """Every number written with D or d (``1D+17``, ``1d-05``, ``1D17``) reads as the float written with e."""
    mesh.point_data["depth"][0] = depth  # one number at least with an exponent
    path = tmp_path / "random.14"
    mesh.write(path)
    text = path.read_text()
    path.write_text(fortran_d(text, marker, plus))
    assert marker in path.read_text()
    back = tm.read_mesh(path)
    assert_same(mesh, back)
    assert back.title == (mesh.title.strip() or "terramesh")  # inner blanks kept (a title reads back as written)


@pytest.mark.parametrize("separator", [",", ", ", " , "])
def test_commas_separate_values_as_in_fortran_list_directed_input(tmp_path, separator):
    """``1,0.0,0.0,1.0`` was refused in the tables (the header lines took commas): ADCIRC's READ takes it."""
    lines = SAMPLE.splitlines()
    # every space between two numbers (and none in the comments) made a separator
    commas = lines[:2] + [re.sub(r"(?<=\d) +(?=[-\d])", separator, line) for line in lines[2:]]
    assert "11" + separator + "-94.0" in commas[2] and "1" + separator + "24 = weir pair" in commas[-2]
    assert_same(tm.read_mesh(write_sample(tmp_path)), tm.read_mesh(write_sample(tmp_path, "\n".join(commas) + "\n")))


def test_an_empty_value_between_commas_is_refused_not_shifted(tmp_path):
    """Fortran's null value (``,,``) would shift the columns after it: refused, naming the line."""
    text = SAMPLE.replace("12 -93.9 29.7 6.0 extra text", "12,,-93.9,29.7,6.0")
    with pytest.raises(MeshFormatError, match=r"line 4: no value between commas among the node lines"):
        tm.read_mesh(write_sample(tmp_path, text))


def test_an_open_boundary_flag_after_a_comma_is_read(tmp_path):
    text = SAMPLE.replace("2 = Number of nodes for open boundary 1 (no IBTYPEE)", "2,12 = Number of nodes")
    assert tm.read_mesh(write_sample(tmp_path, text)).boundaries.open[0].ibtype == 12


@pytest.mark.parametrize(
    "land, opened, message",
    [
        (20.5, None, r"land boundary 1: IBTYPE must be a whole number .*, got 20\.5"),
        (None, None, r"land boundary 1: IBTYPE must be a whole number .*, got None"),  # was written as "3 None"
        ("x", None, r"land boundary 1: IBTYPE must be a whole number .*, got 'x'"),
        (20, "x", r"open boundary 1: IBTYPEE must be a whole number or None \(no flag\), got 'x'"),
        (20, 0.5, r"open boundary 1: IBTYPEE must be a whole number or None \(no flag\), got 0\.5"),
    ],
)
def test_an_ibtype_that_is_no_whole_number_is_refused_before_writing(tmp_path, land, opened, message):
    mesh = tm.Mesh(
        np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]]),
        [[0, 1, 2], [0, 2, 3]],
        boundaries=Boundaries(open=[OpenBoundary(np.array([0, 1]), opened)], land=[LandBoundary([1, 2, 3], land)]),
    )
    for name in ("fort.14", "hgrid.gr3"):
        with pytest.raises(MeshFormatError, match=message):
            mesh.write(tmp_path / name)
        assert not (tmp_path / name).exists()


def test_whole_number_ibtypes_of_any_type_are_written_as_integers(tmp_path):
    """``20.0`` and ``np.float64(21)`` were written as ``20.0`` and ``21.0``, which ADCIRC and read_fort14 refuse."""
    boundaries = Boundaries(
        open=[OpenBoundary(np.array([0, 1]), 0.0)],
        land=[
            LandBoundary(np.array([1, 2]), 20.0),
            LandBoundary(np.array([2, 3]), np.float64(21)),
            LandBoundary([3, 0], "22"),
        ],
    )
    mesh = tm.Mesh(np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]]), [[0, 1, 2], [0, 2, 3]], boundaries=boundaries)
    mesh.point_data["depth"] = np.full(4, 3.0)
    path = tmp_path / "fort.14"
    mesh.write(path)
    flags = [line.split("=")[0].split() for line in path.read_text().splitlines() if "Number of nodes for" in line]
    assert flags == [["2", "0"], ["2", "20"], ["2", "21"], ["2", "22"]]
    back = tm.read_mesh(path).boundaries
    assert [b.ibtype for b in back.open + back.land] == [0, 20, 21, 22]
    assert mesh.boundaries.land[0].ibtype == 20.0 and isinstance(mesh.boundaries.land[0].ibtype, float)  # not mutated


@pytest.mark.parametrize("crs", [4326, pyproj.CRS("EPSG:4326"), "EPSG:4269 "])
def test_read_mesh_takes_an_epsg_code_or_pyproj_crs(tmp_path, crs):
    """``read_mesh(path, crs=4326)`` gave a mesh whose ``.geographic`` raised AttributeError."""
    mesh = tm.read_mesh(write_sample(tmp_path), crs=crs)
    assert mesh.geographic and mesh.crs in ("EPSG:4326", "EPSG:4269")


def test_a_non_finite_scalar_is_refused_as_one_row():
    from terramesh.io.fort14 import refuse_non_finite

    with pytest.raises(MeshFormatError, match="depth is NaN or infinite at 1 of 1 nodes \\(node 1 first, index 0\\)"):
        refuse_non_finite(np.float64(np.nan), "depth is")
    refuse_non_finite(2.5, "depth is")


def test_a_file_cut_before_its_land_boundaries_warns(tmp_path):
    # cut just before NBOU, a file read with no land boundaries and said nothing: written back, ADCIRC got none
    path = write_sample(tmp_path, OPEN_ONLY)
    with pytest.warns(TerrameshWarning, match="ends after the open boundaries, without NBOU and NVEL"):
        mesh = tm.read_mesh(path)
    assert len(mesh.boundaries.open) == 1 and mesh.boundaries.land == []


SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]])
FAN = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])  # counter-clockwise around the centre


@pytest.mark.parametrize("extension", [".14", ".gr3"])
@pytest.mark.parametrize(
    "points, cells, message",
    [
        (SQUARE, FAN[[0, 1, 2, 3]][:, [0, 2, 1]], r"4 of 4 cells are clockwise, inverted \(first: cell 1\)"),
        (SQUARE, np.vstack([FAN, [[0, 4, 2]]]), r"1 of 5 cells have zero area \(first: cell 5\)"),
        (
            SQUARE,
            np.vstack([FAN, [[4, 2, 3]]]),
            r"1 of 5 cells repeat the vertices of an earlier cell \(first: cell 5\)",
        ),
        (np.vstack([SQUARE, [[2.0, 2.0]]]), FAN, r"1 of 6 nodes are in no cell \(first: node 6\)"),
        (
            np.vstack([SQUARE, [[2.0, 2.0]]]),
            np.vstack([FAN[:, [1, 0, 2]], [[4, 4, 4]]]),
            r"4 of 5 cells are clockwise, inverted \(first: cell 1\); 1 of 5 cells have zero area \(first: cell 5\); "
            r"1 of 6 nodes are in no cell \(first: node 6\); numbered from 1",
        ),
    ],
)
def test_cells_and_nodes_the_models_cannot_take_are_refused_and_nothing_is_written(
    tmp_path, extension, points, cells, message
):
    """Inverted, flat and repeated cells and unused nodes were written without a word; ADCIRC and SCHISM then failed."""
    target = tmp_path / f"invalid{extension}"
    mesh = tm.Mesh(points, cells, crs="EPSG:4326")
    with pytest.raises(MeshValidityError, match=message + ".*repair the mesh first with terramesh.cleanup.fix_mesh"):
        mesh.write(target)
    assert not target.exists()
    tm.Mesh(SQUARE, FAN, crs="EPSG:4326", point_data={"depth": np.ones(len(SQUARE))}).write(target)  # the valid fan
    np.testing.assert_array_equal(tm.read_mesh(target).cells, FAN)


def test_cells_across_the_antimeridian_are_written_as_they_lie_on_the_ground(tmp_path):
    # a global mesh keeps longitudes in -180..180: a cell across 180 has corners at 179.5 and -179.5, which the
    # orientation check counted clockwise (and fix_mesh, the advice, flipped)
    points = np.array([[179.0, 0.0], [179.5, 0.5], [-179.5, 0.0], [-179.0, 0.5], [179.5, -0.5], [-179.5, -0.5]])
    cells = np.array([[0, 2, 1], [2, 3, 1], [0, 4, 2], [4, 5, 2]])
    mesh = tm.Mesh(points, cells, crs="EPSG:4326", point_data={"depth": np.full(6, 100.0)})
    for name in ("fort.14", "hgrid.gr3"):
        mesh.write(tmp_path / name)
        back = tm.read_mesh(tmp_path / name)
        np.testing.assert_array_equal(back.cells, cells)
    flipped = tm.Mesh(points, cells[:, ::-1], crs="EPSG:4326", point_data={"depth": np.full(6, 100.0)})
    with pytest.raises(MeshValidityError, match="4 of 4 cells are clockwise"):
        flipped.write(tmp_path / "flipped.14")


def test_a_mesh_without_depths_is_written_at_0_m_with_a_warning(tmp_path):
    # a mesh from another format without depths (a .msh then kept none) was written at 0 m without a word
    mesh = tm.Mesh(SQUARE, FAN, crs="EPSG:4326", point_data={"depth": np.array([5.0, 6.0, 7.0, 8.0, 9.0])})
    tm.Mesh(SQUARE, FAN, crs="EPSG:4326").write(tmp_path / "grid.vtu")
    converted = tm.read_mesh(tmp_path / "grid.vtu")
    assert "depth" not in converted.point_data
    with pytest.warns(TerrameshWarning, match=r"the mesh has no depths .* all 5 nodes are written at 0 m"):
        converted.write(tmp_path / "fort.14")
    assert tm.read_mesh(tmp_path / "fort.14").depth.tolist() == [0.0] * 5
    with warnings.catch_warnings():  # with depths: nothing to say
        warnings.simplefilter("error")
        mesh.write(tmp_path / "deep.14")


def test_an_ne_short_of_the_elements_is_named_at_the_next_element(tmp_path):
    # the fifth element's line was read as NOPE: "file ends early ... expected ... open boundary nodes"
    short = SAMPLE.replace("4 5      NE NP", "3 5      NE NP")
    with pytest.raises(MeshFormatError, match=r"line 11 is element 4 \(JE NHY NM1 NM2 NM3\), after the 3 elements"):
        tm.read_mesh(write_sample(tmp_path, short))
    gr3 = tmp_path / "hgrid.gr3"
    gr3.write_text(short)
    with pytest.raises(MeshFormatError, match="NE is short of the elements the file holds"):
        tm.read_mesh(gr3)


def test_a_file_cut_inside_its_last_number_is_warned_of(tmp_path):
    # the weir's last value, 0.9, cut to "0.": read without a word as 0 (a last node "985" as 98)
    text = SAMPLE.rstrip("\n")
    path = write_sample(tmp_path, text[:-1])
    cut = r"fort.14 does not end with a line break: it may have been cut short, and its last line, '13 15 1.5 1.0 0.',"
    with pytest.warns(TerrameshWarning, match=cut):
        tm.read_mesh(path)
    with warnings.catch_warnings():  # whole, with or without blank lines after: nothing to say
        warnings.simplefilter("error")
        tm.read_mesh(write_sample(tmp_path, text + "\r\n"))
        tm.read_mesh(write_sample(tmp_path, text + "\n\n"))
