import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshFormatError, MeshValidityError, TerrameshWarning
from terramesh.io import meshio_formats
from terramesh.io.meshio_formats import store_crs


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
    np.testing.assert_array_equal(again.point_data["depth"], mesh.point_data["depth"])  # .msh dropped it
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
    with pytest.raises(MeshFormatError, match=r"cannot read as vtu: the file is truncated or malformed \(ReadError\)$"):
        tm.read_mesh(cut)


@pytest.mark.parametrize("keep", [0.02, 0.3, 0.5, 0.8])
def test_a_truncated_gmsh_file_is_called_so_with_the_reason_after(tmp_path, mesh, keep):
    """NumPy's words inside meshio were all it said: "cannot reshape array of size 2 into shape (315,4)"."""
    whole = tmp_path / "whole.msh"
    mesh.write(whole)
    data = whole.read_bytes()
    cut = tmp_path / "cut.msh"
    cut.write_bytes(data[: int(keep * len(data))])
    with pytest.raises(
        MeshFormatError, match=r"cut\.msh: cannot read as gmsh: the file is truncated or malformed \(\w+"
    ):
        tm.read_mesh(cut)


def test_a_missing_xdmf_data_file_is_not_called_truncated(tmp_path, mesh):
    path = tmp_path / "mesh.xdmf"
    mesh.write(path)
    (tmp_path / "mesh.h5").unlink()
    with pytest.raises(MeshFormatError, match=r"cannot read as xdmf: FileNotFoundError") as raised:
        tm.read_mesh(path)
    assert "truncated" not in str(raised.value)


def _square(crs):
    """An 80 m x 80 m planar square (crs None) whose coordinates also fit longitude, latitude."""
    points = np.array([[0.0, 0.0], [80.0, 0.0], [80.0, 80.0], [0.0, 80.0], [40.0, 40.0]])
    cells = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    return tm.Mesh(points, cells, point_data={"depth": np.arange(5.0)}, crs=crs)


# the WKT's name holds what XML and JSON must escape; pyproj reads it (Mesh refuses a CRS it cannot read)
@pytest.mark.parametrize("crs", [None, "EPSG:4326", "EPSG:32618", 'LOCAL_CS["a & <b>", UNIT["metre", 1]]'])
@pytest.mark.parametrize("name", ["square.vtu", "square.xdmf", "square.msh"])
def test_crs_round_trips_through_vtu_xdmf_and_gmsh(tmp_path, name, crs):
    """read_mesh's guess made the planar square EPSG:4326 (and its quality that of a square on the sphere)."""
    import meshio

    path = tmp_path / name
    _square(crs).write(path)
    assert tm.read_mesh(path).crs == crs
    assert tm.read_mesh(path, crs="EPSG:3857").crs == "EPSG:3857"  # said by the caller: over what the file keeps
    data = meshio.read(path)  # meshio still reads the file (a Gmsh file's $Comments section skipped)
    np.testing.assert_array_equal(data.cells_dict["triangle"], _square(crs).cells)


@pytest.mark.parametrize("name", ["old.vtu", "old.xdmf", "old.msh"])
def test_a_file_that_keeps_no_crs_is_guessed(tmp_path, name):
    import meshio

    points = np.column_stack([_square(None).points, np.zeros(5)])
    path = tmp_path / name
    fmt = {".vtu": "vtu", ".xdmf": "xdmf", ".msh": "gmsh22"}[path.suffix]
    meshio.write(path, meshio.Mesh(points, [("triangle", _square(None).cells)]), file_format=fmt)
    assert tm.read_mesh(path).crs == "EPSG:4326"
    assert tm.read_mesh(path, crs=None).crs is None


@pytest.mark.parametrize(
    ("name", "old", "new"),
    [("bad.xdmf", 'Value="null"', 'Value="{not json"'), ("bad.msh", "crs null", "crs {not json")],
)
def test_a_malformed_stored_crs_is_a_format_error(tmp_path, name, old, new):
    path = tmp_path / name
    _square(None).write(path)
    path.write_text(path.read_text().replace(old, new))
    with pytest.raises(MeshFormatError, match=f"{name}: unreadable terramesh:crs"):
        tm.read_mesh(path)


def test_cells_of_another_kind_are_left_out_with_a_warning(tmp_path):
    """A triangle + quad file read as its triangles without a word."""
    import meshio

    points = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]])
    blocks = [("triangle", np.array([[0, 1, 2], [0, 2, 3]])), ("quad", np.array([[1, 4, 5, 2]]))]
    path = tmp_path / "mixed.vtu"
    meshio.vtu.write(path, meshio.Mesh(points, blocks))
    with pytest.warns(TerrameshWarning, match=r"mixed.vtu: read its 2 triangle cells only and left out 1 quad cells"):
        mesh = tm.read_mesh(path)
    assert mesh.n_cells == 2
    # boundary lines beside the triangles are no loss
    meshio.vtu.write(path, meshio.Mesh(points, [blocks[0], ("line", np.array([[0, 1], [1, 2]]))]))
    assert tm.read_mesh(path).n_cells == 2


@pytest.mark.parametrize(
    ("name", "writer"),
    [("mesh.vtu", "meshio.vtu.write"), ("mesh.xdmf", "meshio.xdmf.write"), ("mesh.msh", "terramesh.write_gmsh22")],
)
def test_a_failed_write_leaves_the_previous_file_and_nothing_else(tmp_path, monkeypatch, mesh, name, writer):
    import meshio

    path = tmp_path / name
    mesh.write(path)
    before = sorted((entry.name, entry.read_bytes()) for entry in tmp_path.iterdir())

    def half_written(target, *args, **kwargs):
        if isinstance(target, str):
            with open(target, "w") as handle:
                handle.write("<VTKFile")
        else:  # Gmsh's tables go to the open temporary file
            target.write("$MeshFormat")
        raise KeyboardInterrupt

    owner, function = writer.rsplit(".", 1)
    owner = {"meshio.vtu": meshio.vtu, "meshio.xdmf": meshio.xdmf, "terramesh": meshio_formats}[owner]
    monkeypatch.setattr(owner, function, half_written)
    with pytest.raises(KeyboardInterrupt):
        mesh.write(path)
    assert sorted((entry.name, entry.read_bytes()) for entry in tmp_path.iterdir()) == before


@pytest.mark.parametrize("name", ["flags.vtu", "flags.xdmf"])
def test_boolean_point_data_is_written_as_zeros_and_ones(tmp_path, mesh, name):
    """meshio stopped with a bare ``KeyError: dtype('bool')``."""
    wet = mesh.points[:, 0] > 0
    flagged = tm.Mesh(mesh.points, mesh.cells, point_data={"wet": wet, "half": np.ones(mesh.n_points, np.float16)})
    flagged.write(tmp_path / name)
    back = tm.read_mesh(tmp_path / name).point_data
    assert back["wet"].dtype == np.uint8 and np.array_equal(back["wet"], wet)
    np.testing.assert_array_equal(back["half"], 1.0)


@pytest.mark.parametrize("name", ["text.vtu", "text.xdmf", "text.msh"])
def test_point_data_that_is_no_number_is_refused_by_name(tmp_path, mesh, name):
    labelled = tm.Mesh(mesh.points, mesh.cells, point_data={"label": np.array(["a"] * mesh.n_points)})
    with pytest.raises(MeshFormatError, match=r"point_data\['label'\] holds <U1 values; VTU, XDMF and Gmsh files"):
        labelled.write(tmp_path / name)
    assert not (tmp_path / name).exists()


@pytest.mark.parametrize("suffix", [".vtu", ".msh", ".xdmf"])
def test_a_file_whose_stored_crs_pyproj_cannot_read_is_read_as_planar(tmp_path, suffix):
    # terramesh kept any text as the crs before 2026-11-30 ("local grid"); reading such a file then raised
    # "malformed" for the whole mesh
    import meshio

    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.5)
    path = tmp_path / f"local{suffix}"
    file_format = {".vtu": "vtu", ".msh": "gmsh22", ".xdmf": "xdmf"}[suffix]
    meshio.write(str(path), meshio.Mesh(mesh.points, [("triangle", mesh.cells)]), file_format=file_format)
    store_crs(str(path), file_format, "local grid")
    with pytest.warns(TerrameshWarning, match="'local grid' is none pyproj can read: the mesh is read as planar"):
        read = tm.read_mesh(path)
    assert read.crs is None and read.n_points == mesh.n_points


@pytest.mark.parametrize("suffix", [".vtu", ".msh", ".xdmf"])
def test_metres_kept_as_degrees_are_read_as_planar_and_given_degrees_are_refused(tmp_path, suffix):
    """terramesh wrote UTM metres labelled EPSG:4326 (it took them); such a file reads, planar, with a warning."""
    import meshio

    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.5)
    points = mesh.points * 1e4 + (4e5, 3.3e6)
    path = tmp_path / f"utm{suffix}"
    file_format = {".vtu": "vtu", ".msh": "gmsh22", ".xdmf": "xdmf"}[suffix]
    meshio.write(str(path), meshio.Mesh(points, [("triangle", mesh.cells)]), file_format=file_format)
    store_crs(str(path), file_format, "EPSG:4326")
    with pytest.warns(
        TerrameshWarning, match="the reference system it keeps does not fit its points .* read as planar"
    ):
        read = tm.read_mesh(path)
    assert read.crs is None and read.n_points == mesh.n_points
    assert tm.read_mesh(path, crs="EPSG:32615").crs == "EPSG:32615"
    # given by the caller, it is the caller's mistake: not a "malformed" file
    with pytest.raises(MeshValidityError, match="outside longitude -360..360, latitude -90..90"):
        tm.read_mesh(path, crs="EPSG:4326")


def test_gmsh_files_keep_point_data_of_1_3_or_9_values_a_node(tmp_path, mesh):
    # a .msh kept no point data: a coastal mesh's depths were gone when read back, and a fort.14 of it said 0 m
    flow = np.column_stack([mesh.points, np.zeros(mesh.n_points)])
    pair = mesh.points.copy()
    rich = tm.Mesh(mesh.points, mesh.cells, point_data={"depth": mesh.point_data["depth"], "flow": flow, "pair": pair})
    with pytest.warns(TerrameshWarning, match=r"point_data \['pair'\] left out of the Gmsh file .*1, 3 or 9 values"):
        rich.write(tmp_path / "rich.msh")
    back = tm.read_mesh(tmp_path / "rich.msh").point_data
    assert sorted(back) == ["depth", "flow"]
    np.testing.assert_array_equal(back["depth"], mesh.point_data["depth"])
    np.testing.assert_array_equal(back["flow"], flow)
