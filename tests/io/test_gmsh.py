"""The compiled Gmsh 2.2 ASCII reader: the same mesh as meshio's reader, and errors that say what is wrong."""

import meshio
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
import terramesh.io.meshio_formats as meshio_formats
from terramesh._kernels.text import ROWS_READ, real_rows
from terramesh.errors import MeshFormatError, TerrameshWarning
from terramesh.io.fwi import write_fwi_mesh
from terramesh.io.gmsh import read_gmsh22
from terramesh.seismic import VelocityModel


def read_by_meshio(path, monkeypatch):
    """``read_mesh(path)`` as it was: meshio's parser for every Gmsh file."""
    with monkeypatch.context() as patch:
        patch.setattr(meshio_formats, "read_gmsh22", lambda path: None)
        return tm.read_mesh(path)


def assert_same_mesh(mesh, expected):
    np.testing.assert_array_equal(mesh.points, expected.points)  # bit for bit: every coordinate rounded as strtod
    np.testing.assert_array_equal(mesh.cells, expected.cells)
    assert mesh.crs == expected.crs
    assert mesh.point_data.keys() == expected.point_data.keys()
    for name, values in expected.point_data.items():
        assert mesh.point_data[name].dtype == values.dtype
        np.testing.assert_array_equal(mesh.point_data[name], values)


@pytest.fixture(scope="module")
def disk():
    return tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2, seed=0)


@pytest.fixture(scope="module")
def box():
    """Tetrahedra of a 4 x 3 x 3 lattice box, 300 x 200 x 200 m with z down to -200, and a velocity model over it."""
    from terramesh.generation.triangulate import delaunay_3d

    axes = [np.linspace(0, 300, 4), np.linspace(0, 200, 3), np.linspace(-200, 0, 3)]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    points += np.random.default_rng(0).uniform(-5, 5, points.shape) * (
        np.abs(points - [150, 100, -100]) < [150, 100, 100]
    )
    speed = 1500.0 + np.meshgrid(*axes, indexing="ij")[2] * -2.0
    cells, _ = delaunay_3d(points)
    return tm.Mesh(points, cells), VelocityModel(speed, axes)


@pytest.mark.parametrize("crs", [None, "EPSG:32618"])
def test_round_trip_of_write_mesh_is_meshios_reading(tmp_path, monkeypatch, disk, crs):
    path = tmp_path / "disk.msh"
    mesh = tm.Mesh(disk.points * 1e3, disk.cells, crs=crs)
    mesh.write(path)
    again = tm.read_mesh(path)
    assert_same_mesh(again, read_by_meshio(path, monkeypatch))
    np.testing.assert_array_equal(again.points, mesh.points)
    np.testing.assert_array_equal(again.cells, mesh.cells)
    assert again.crs == crs


def test_round_trip_of_a_3d_mesh(tmp_path, monkeypatch, box):
    mesh, _ = box
    path = tmp_path / "box.msh"
    mesh.write(path)
    again = tm.read_mesh(path)
    assert_same_mesh(again, read_by_meshio(path, monkeypatch))
    np.testing.assert_array_equal(again.points, mesh.points)
    np.testing.assert_array_equal(again.cells, mesh.cells)


@pytest.mark.parametrize("velocity_on", [None, "vertices", "cells"])
@pytest.mark.parametrize("dim", [2, 3])
def test_fwi_files_read_as_meshio_reads_them(tmp_path, monkeypatch, disk, box, dim, velocity_on):
    """Boundary facets (2 tags) and regions beside the cells, $PhysicalNames, velocity data, $Comments."""
    if dim == 2:
        mesh = tm.Mesh(disk.points * 100.0 + [100.0, -100.0], disk.cells)
        model = VelocityModel(
            np.full((3, 3), 1500.0) + np.arange(3.0), [np.linspace(-1, 201, 3), np.linspace(-201, 1, 3)]
        )
    else:
        mesh, model = box
    path = tmp_path / "fwi.msh"
    if velocity_on is None:
        write_fwi_mesh(path, mesh)
    else:
        write_fwi_mesh(path, mesh, model, velocity_on)
    again = tm.read_mesh(path)
    assert_same_mesh(again, read_by_meshio(path, monkeypatch))
    np.testing.assert_array_equal(again.points, mesh.points)
    np.testing.assert_array_equal(again.cells, mesh.cells)
    assert list(again.point_data) == (["velocity"] if velocity_on == "vertices" else [])
    raw = read_gmsh22(path)
    assert [block.type for block in raw.cells] == (["line", "triangle"] if dim == 2 else ["triangle", "tetra"])


HAND_WRITTEN = """\
$Comments
written by hand
$EndComments
$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
2 7 "sea floor"
$EndPhysicalNames
$Nodes
6
30 0 0 0
10 1.0 0 0\r
20 1 1 0.0

70 0 1 0
50 2E0 0 0
60 2 1.0e+00 -0
$EndNodes
$Elements
7
1 15 2 0 1 30
2 1 2 0 1 30 10
3 2 2 7 1 30 10 20
4 2 3 7 1 9 30 20 70
5 3 2 0 1 10 50 60 20
6 2 0 10 50 60
7 1 1 3 70 30
$EndElements
$NodeData
1
"depth"
1
0.0
3
0
1
6
30 0.5
10 1.5
20 2.5
70 3.5
50 4.5
60 5.5
$EndNodeData
"""


UNIFORM_TAGS = (
    HAND_WRITTEN.replace("4 2 3 7 1 9 ", "4 2 2 7 1 ").replace("6 2 0 ", "6 2 2 0 1 ").replace("7 1 1 3 ", "7 1 2 3 1 ")
)


def test_a_hand_written_file_with_numbers_out_of_order_and_mixed_elements(tmp_path, monkeypatch):
    # meshio reads elements with 2 tags only (else "Incompatible cell data"): compared on such a file, and the
    # tags vary (0 to 3) in the other
    uniform = tmp_path / "uniform.msh"
    uniform.write_bytes(UNIFORM_TAGS.encode())
    path = tmp_path / "hand.msh"
    path.write_bytes(HAND_WRITTEN.encode())
    raw = read_gmsh22(path)
    by_meshio = meshio.gmsh.read(uniform)
    np.testing.assert_array_equal(raw.points, by_meshio.points)
    assert [block.type for block in raw.cells] == ["vertex", "line", "triangle", "quad"]
    for kind in ("vertex", "line", "triangle", "quad"):
        np.testing.assert_array_equal(raw.cells_dict[kind], by_meshio.cells_dict[kind])
    np.testing.assert_array_equal(raw.point_data["depth"], by_meshio.point_data["depth"])
    np.testing.assert_array_equal(raw.cells_dict["triangle"], [[0, 1, 2], [0, 2, 3], [1, 4, 5]])
    with pytest.warns(TerrameshWarning, match=r"hand.msh: read its 3 triangle cells only and left out 1 quad cells"):
        mesh = tm.read_mesh(path)
    with pytest.warns(TerrameshWarning, match="left out 1 quad cells"):
        assert_same_mesh(mesh, read_by_meshio(uniform, monkeypatch))
    np.testing.assert_array_equal(mesh.point_data["depth"], [0.5, 1.5, 2.5, 3.5, 4.5, 5.5])
    assert mesh.points.shape == (6, 2)


def test_node_data_in_another_order_than_the_nodes_goes_to_its_nodes(tmp_path):
    """meshio ignores the node numbers of $NodeData; they say which node a value is for."""
    text = HAND_WRITTEN.replace("30 0.5\n10 1.5\n", "10 1.5\n30 0.5\n")
    path = tmp_path / "shuffled.msh"
    path.write_text(text)
    np.testing.assert_array_equal(read_gmsh22(path).point_data["depth"], [0.5, 1.5, 2.5, 3.5, 4.5, 5.5])


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("60 2 1.0e+00 -0\n", "", r"line 19: \$Nodes holds 5 nodes where its header counts 6"),
        ("$Nodes\n6\n", "$Nodes\n5\n", r"line 19: \$Nodes holds more nodes than the 5 its header counts"),
        ("20 1 1 0.0", "20 1 one 0.0", r"line 15: 'one' is not a number"),
        ("20 1 1 0.0", "20 1 1_0 0.0", r"line 15: '1_0' is not a number"),
        ("20 1 1 0.0", "20.5 1 1 0.0", r"line 15: '20.5' is not a whole number"),
        ("20 1 1 0.0", "20 1 1", r"line 15: too few numbers for one of its nodes: '20 1 1'"),
        ("20 1 1 0.0", "20 1 1 0 0", r"line 15: more numbers than one of its nodes holds: '20 1 1 0 0'"),
        ("70 0 1 0", "20 0 1 0", r"node number 20 appears twice in \$Nodes"),
        ("6 2 0 10 50 60", "6 2 0 10 50 99", r"element 6 refers to node 99, which \$Nodes does not hold"),
        ("6 2 0 10 50 60", "6 99 0 10 50 60", r"line 28: element type 99 is none Gmsh 2.2 knows"),
        ("6 2 0 10 50 60", "6 2 -1 10 50 60", r"line 28: negative tag count -1"),
        ("6 2 0 10 50 60", "6 2 0 10 50", r"line 28: too few numbers for one of its elements"),
        ("6 2 0 10 50 60", "6 2 0 10 50 60 70", r"line 28: more numbers than one of its elements holds"),
        ("$Elements\n7\n", "$Elements\nseven\n", r"line 22: 'seven' is no element count"),
        ("$EndElements\n", "$EndElement\n", r"line 30: \$EndElement where \$EndElements should be"),
        ("$EndPhysicalNames\n", "", r"the file ends inside its \$PhysicalNames section"),
        ("60 5.5\n", "", r"line 45: \$NodeData holds 5 values where its header counts 6"),
        ("1\n6\n30 0.5\n", "1\n5\n", r"\$NodeData 'depth' holds 5 values for 6 nodes"),
        ("60 5.5\n", "60 5.5\n80 6.5\n", r"\$NodeData holds more values than the 6"),
        ("1\n6\n30 0.5", "1\n7\n30 0.5", r"line 46: \$NodeData holds 6 values where its header counts 7"),
        ("3\n0\n1\n6\n", "2\n0\n1\n", r"\$NodeData needs a name and 3 integer tags"),
        ("50 4.5", "80 4.5", r"\$NodeData 'depth' gives a value for node 80, which \$Nodes does not hold"),
        ("$EndNodeData\n", "$EndNodeData\nnot a section\n", r"line 47: 'not a section' where a section"),
    ],
)
def test_malformed_files_name_the_problem(tmp_path, old, new, message):
    assert HAND_WRITTEN.count(old) == 1
    path = tmp_path / "bad.msh"
    path.write_text(HAND_WRITTEN.replace(old, new))
    with pytest.raises(MeshFormatError, match=r"bad\.msh: cannot read as gmsh: the file is truncated or malformed \("):
        read_gmsh22(path)
    with pytest.raises(MeshFormatError, match=message):
        tm.read_mesh(path)


def test_every_truncation_is_a_format_error_or_the_whole_mesh(tmp_path):
    """Cut anywhere, a file raises MeshFormatError (never NumPy's words), unless only its comments went."""
    whole = tmp_path / "whole.msh"
    square = tm.Mesh(
        np.array([[0.0, -1], [1, -1], [1, 0], [0, 0], [0.5, -0.5]]), [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
    )
    write_fwi_mesh(whole, square)
    data = whole.read_bytes()
    end_of_elements = data.index(b"$EndElements\n") + len(b"$EndElements\n")
    cut = tmp_path / "cut.msh"
    for keep in range(len(data)):
        cut.write_bytes(data[:keep])
        try:
            read = tm.read_mesh(cut, crs=None)
        except MeshFormatError as error:
            # a file cut before its elements is whole too, with no cells
            no_cells = keep <= data.index(b"$Elements") and str(error).endswith(
                "cut.msh: no triangle or tetrahedron cells"
            )
            assert no_cells or "cut.msh: cannot read as gmsh: the file is truncated or malformed (" in str(error), keep
            continue
        # read whole or not at all: a file cut after its elements misses only its comments (the crs)
        assert keep >= end_of_elements - len(b"\n"), keep
        np.testing.assert_array_equal(read.points, square.points)
        np.testing.assert_array_equal(read.cells, square.cells)


def test_binary_and_version_4_files_are_left_to_meshio(tmp_path, disk):
    points = np.column_stack([disk.points, np.zeros(disk.n_points)])
    data = meshio.Mesh(points, [("triangle", disk.cells)])
    for name, version, binary in [("binary.msh", "2.2", True), ("four.msh", "4.1", False)]:
        path = tmp_path / name
        meshio.gmsh.write(path, data, fmt_version=version, binary=binary)
        assert read_gmsh22(path) is None
        np.testing.assert_array_equal(tm.read_mesh(path).cells, disk.cells)


def test_a_file_without_elements_has_no_cells(tmp_path):
    path = tmp_path / "nodes.msh"
    path.write_text(HAND_WRITTEN[: HAND_WRITTEN.index("$Elements")])
    with pytest.raises(MeshFormatError, match=r"nodes\.msh: no triangle or tetrahedron cells"):
        tm.read_mesh(path)


_REALS = st.floats(allow_nan=False, allow_infinity=False, allow_subnormal=True, width=64)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(_REALS, _REALS, _REALS), min_size=1, max_size=30), st.sampled_from(["%r", "%.17g", "%.16e"]))
def test_reals_read_as_strtod_rounds_them(rows, spelling):
    """Every double written with 17 digits reads back bit for bit; shorter spellings round as Python's float."""
    lines = "".join(f"{i + 1} " + " ".join(spelling % value for value in row) + "\n" for i, row in enumerate(rows))
    text = np.frombuffer(lines.encode(), dtype=np.uint8)
    numbers, values, deferred, done, status, _ = real_rows(text, 0, len(rows), 3)
    assert status == ROWS_READ and done == len(rows)
    np.testing.assert_array_equal(numbers, np.arange(1, len(rows) + 1))
    expected = np.array([[float(spelling % value) for value in row] for row in rows])
    flat = values.reshape(-1)
    for index, start, end in deferred:  # left to the caller: subnormals here
        flat[index] = float(text[start:end].tobytes())
    assert np.array_equal(values.view(np.uint64), expected.view(np.uint64))


@settings(max_examples=100, deadline=None)
@given(
    st.integers(0, 19).flatmap(lambda digits: st.integers(0, 10**digits)),
    st.integers(-30, 30),
    st.integers(-340, 310),
)
def test_decimal_spellings_round_as_pythons_float(significand, point, exponent):
    """Halfway cases and long significands: the kernel agrees with Python's correctly rounded float."""
    digits = str(significand)
    at = max(0, min(len(digits), len(digits) + point))
    token = f"-{digits[:at]}.{digits[at:]}e{exponent}" if at < len(digits) else f"{digits}e{exponent}"
    text = np.frombuffer(f"1 {token}\n".encode(), dtype=np.uint8)
    _, values, deferred, _, status, _ = real_rows(text, 0, 1, 1)
    assert status == ROWS_READ
    if len(deferred) == 0:
        assert values[0, 0] == float(token) and np.signbit(values[0, 0]) == np.signbit(float(token))
