import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshFormatError


@pytest.fixture(scope="module")
def mesh():
    result = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.15)
    result.point_data["depth"] = np.hypot(result.points[:, 0], result.points[:, 1])
    return result


@pytest.mark.parametrize("name", ["mesh.vtu", "mesh.msh", "mesh.xdmf", "mesh.14"])
def test_round_trip(tmp_path, mesh, name):
    before = mesh.points.copy(), mesh.cells.copy()
    path = tmp_path / name
    mesh.write(path)
    again = tm.read_mesh(path)
    np.testing.assert_array_equal(again.points, mesh.points)
    np.testing.assert_array_equal(again.cells, mesh.cells)
    if not name.endswith(".msh"):
        np.testing.assert_allclose(again.point_data["depth"], mesh.point_data["depth"])
    np.testing.assert_array_equal(mesh.points, before[0])
    np.testing.assert_array_equal(mesh.cells, before[1])


def test_gmsh_file_is_version_2_2(tmp_path, mesh):
    path = tmp_path / "mesh.msh"
    mesh.write(path)
    assert path.read_text().splitlines()[1].startswith("2.2")


def test_unknown_and_malformed_files(tmp_path, mesh):
    with pytest.raises(MeshFormatError, match="unknown mesh format"):
        tm.write_mesh(tmp_path / "a.vtu", mesh, file_format="stl")
    broken = tmp_path / "broken.vtu"
    broken.write_text("<VTKFile> this is not a mesh")
    with pytest.raises(MeshFormatError, match="cannot read"):
        tm.read_mesh(broken)


def test_vtu_cells_past_the_last_vertex_are_a_format_error(tmp_path):
    import meshio

    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    path = tmp_path / "past_the_end.vtu"
    meshio.vtu.write(path, meshio.Mesh(points, [("triangle", np.array([[0, 1, 2], [0, 2, 3]]))]))
    with pytest.raises(MeshFormatError, match="past_the_end.vtu: malformed vtu file: cells refer to vertices"):
        tm.read_mesh(path)


@pytest.mark.parametrize("keep", [0.0, 0.5])
def test_empty_or_truncated_vtu_says_what_was_wrong(tmp_path, mesh, keep):
    whole = tmp_path / "whole.vtu"
    mesh.write(whole)
    data = whole.read_bytes()
    cut = tmp_path / "cut.vtu"
    cut.write_bytes(data[: int(keep * len(data))])
    with pytest.raises(MeshFormatError, match=r"cannot read as vtu: ReadError: truncated or not a vtu file$"):
        tm.read_mesh(cut)
