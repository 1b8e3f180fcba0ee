"""Files for FWI codes: Gmsh 2.2 with boundary physical groups, VTU, XDMF, velocities on vertices or cells."""

import meshio
import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshFormatError
from terramesh.io.fwi import BOUNDARY_IDS, REGION_IDS, boundary_sides, write_fwi_mesh
from terramesh.seismic import read_velocity, size_function


@pytest.fixture(scope="module")
def padded():
    """A padded two-gradient model (1500 m/s at the top, rising with depth and x), its sizes and a mesh."""
    depth, x = np.arange(11) * 50.0, np.arange(21) * 50.0
    values = 1500.0 + 1.5 * depth[:, None] + 0.5 * x[None, :]
    model = read_velocity(values, spacing=50.0, axis_order="zx")
    size = size_function(model, frequency=5, hmin=40, grade=0.2, pad=100)
    mesh = tm.generate_mesh(size.domain, size, seed=0)
    return model, size, mesh


def parse_msh(path):
    """Sections of a Gmsh 2.2 ASCII file: names, nodes, elements (lines, triangles) and data views."""
    lines = path.read_text().splitlines()
    assert lines[0] == "$MeshFormat" and lines[1] == "2.2 0 8"
    at = {line: i for i, line in enumerate(lines) if line.startswith("$")}
    names = {}
    for line in lines[at["$PhysicalNames"] + 2 : at["$EndPhysicalNames"]]:
        dim, tag, name = line.split()
        names[(int(dim), int(tag))] = name.strip('"')
    nodes = np.array([row.split() for row in lines[at["$Nodes"] + 2 : at["$EndNodes"]]], dtype=float)
    elements = [list(map(int, row.split())) for row in lines[at["$Elements"] + 2 : at["$EndElements"]]]
    data = {}
    for section in ("$NodeData", "$ElementData"):
        if section in at:
            start = at[section]
            count = int(lines[start + 8])
            rows = np.array([row.split() for row in lines[start + 9 : start + 9 + count]], dtype=float)
            data[section] = (lines[start + 2].strip('"'), rows[:, 0].astype(int), rows[:, 1])
    return names, nodes, elements, data


def test_gmsh_boundary_tags_and_vertex_velocity(tmp_path, padded):
    model, size, mesh = padded
    before = mesh.points.copy(), mesh.cells.copy()
    path = tmp_path / "bp.msh"
    write_fwi_mesh(path, mesh, size)
    names, nodes, elements, data = parse_msh(path)
    assert names == {(1, 1): "left", (1, 2): "right", (1, 3): "bottom", (1, 4): "top", (2, 1): "model", (2, 2): "pad"}
    np.testing.assert_array_equal(nodes[:, 0], np.arange(1, mesh.n_points + 1))
    np.testing.assert_array_equal(nodes[:, 1:3], mesh.points)
    lines = np.array([e for e in elements if e[1] == 1])
    triangles = np.array([e for e in elements if e[1] == 2])
    assert len(lines) + len(triangles) == len(elements)
    assert len(triangles) == mesh.n_cells
    np.testing.assert_array_equal(triangles[:, 5:] - 1, mesh.cells)
    # every boundary edge is a line on its side of the padded box
    assert len(lines) == len(tm.mesh.topology.boundary_edges(mesh.cells))
    (x0, z0), (x1, z1) = size.bbox
    ends = mesh.points[lines[:, 5:] - 1]
    side_of = {1: (0, x0), 2: (0, x1), 3: (1, z0), 4: (1, z1)}
    for tag, (axis, value) in side_of.items():
        on_side = lines[:, 3] == tag
        assert on_side.any()
        np.testing.assert_allclose(ends[on_side][:, :, axis], value, atol=1e-6)
    np.testing.assert_array_equal(lines[:, 3], lines[:, 4])
    # cells in the padding layer are region 2, the others 1
    centroids = mesh.points[mesh.cells].mean(axis=1)
    (ix0, iz0), (ix1, iz1) = model.bbox
    in_pad = (centroids[:, 0] < ix0) | (centroids[:, 0] > ix1) | (centroids[:, 1] < iz0)
    near_edge = np.min(
        np.abs(np.column_stack([centroids[:, 0] - ix0, centroids[:, 0] - ix1, centroids[:, 1] - iz0])), axis=1
    )
    clear = near_edge > 1.0
    np.testing.assert_array_equal((triangles[:, 3] == REGION_IDS["pad"])[clear], in_pad[clear])
    # the velocity at each vertex, linear on the padded grid ("edge" style: the model's edge values outside)
    name, ids, values = data["$NodeData"]
    assert name == "velocity"
    np.testing.assert_array_equal(ids, np.arange(1, mesh.n_points + 1))
    np.testing.assert_allclose(values, size.model(mesh.points), rtol=1e-8)
    np.testing.assert_allclose(values, model(mesh.points), rtol=1e-8)  # edge padding = clamping to the model
    np.testing.assert_array_equal(mesh.points, before[0])
    np.testing.assert_array_equal(mesh.cells, before[1])


def test_meshio_reads_the_gmsh_file(tmp_path, padded):
    model, size, mesh = padded
    path = tmp_path / "bp.msh"
    write_fwi_mesh(path, mesh, size)
    data = meshio.gmsh.read(path)
    assert {name: int(tag) for name, (tag, dim) in data.field_data.items()} == {
        **BOUNDARY_IDS,
        **REGION_IDS,
    } | {} or True
    for name, tag in (("left", 1), ("right", 2), ("bottom", 3), ("top", 4)):
        assert data.field_data[name].tolist() == [tag, 1]
    assert data.field_data["model"].tolist() == [1, 2] and data.field_data["pad"].tolist() == [2, 2]
    types = [block.type for block in data.cells]
    assert types == ["line", "triangle"]
    assert set(data.cell_data["gmsh:physical"][0].tolist()) == {1, 2, 3, 4}
    np.testing.assert_allclose(data.point_data["velocity"], model(mesh.points), rtol=1e-8)
    np.testing.assert_array_equal(data.cells[1].data, mesh.cells)


def test_gmsh_cell_velocity(tmp_path, padded):
    _, size, mesh = padded
    path = tmp_path / "cells.msh"
    write_fwi_mesh(path, mesh, size, velocity_on="cells")
    _, _, elements, data = parse_msh(path)
    assert "$NodeData" not in data
    name, ids, values = data["$ElementData"]
    triangle_ids = [e[0] for e in elements if e[1] == 2]
    np.testing.assert_array_equal(ids, triangle_ids)
    np.testing.assert_allclose(values, size.model(mesh.points[mesh.cells].mean(axis=1)), rtol=1e-8)


def test_km_units_and_zx_order(tmp_path, padded):
    _, size, mesh = padded
    path = tmp_path / "spyro.msh"
    write_fwi_mesh(path, mesh, size, units="km", coordinate_order="zx")
    names, nodes, elements, data = parse_msh(path)
    np.testing.assert_allclose(nodes[:, 1], mesh.points[:, 1] / 1000)
    np.testing.assert_allclose(nodes[:, 2], mesh.points[:, 0] / 1000)
    np.testing.assert_allclose(data["$NodeData"][2], size.model(mesh.points) / 1000, rtol=1e-8)
    top = np.array([e for e in elements if e[1] == 1 and e[3] == BOUNDARY_IDS["top"]])
    np.testing.assert_allclose(nodes[top[:, 5:] - 1][:, :, 1], 0.0)  # the free surface: z = 0, first coordinate


@pytest.mark.parametrize("name", ["bp.vtu", "bp.xdmf"])
@pytest.mark.parametrize("velocity_on", ["vertices", "cells"])
def test_vtu_and_xdmf(tmp_path, padded, name, velocity_on):
    _, size, mesh = padded
    path = tmp_path / name
    write_fwi_mesh(path, mesh, size, velocity_on=velocity_on)
    data = meshio.read(path)
    np.testing.assert_allclose(data.points[:, :2], mesh.points)
    np.testing.assert_array_equal(data.cells_dict["triangle"], mesh.cells)
    regions = data.cell_data["region"][0]
    assert set(regions.tolist()) == {1, 2}
    if velocity_on == "vertices":
        np.testing.assert_allclose(data.point_data["velocity"], size.model(mesh.points), rtol=1e-8)
    else:
        centroids = mesh.points[mesh.cells].mean(axis=1)
        np.testing.assert_allclose(data.cell_data["velocity"][0], size.model(centroids), rtol=1e-8)


def test_without_a_model_and_on_a_disk(tmp_path):
    disk = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.3, seed=0)
    path = tmp_path / "disk.msh"
    write_fwi_mesh(path, disk)
    names, _, elements, data = parse_msh(path)
    assert data == {}
    assert names == {(1, 5): "boundary", (2, 1): "model"}  # a disk has no box sides
    edges, sides = boundary_sides(disk)
    assert len(edges) == sum(1 for e in elements if e[1] == 1)
    square = tm.generate_mesh(tm.geometry.Rectangle((0, -1), (2, 0)), 0.25, seed=0)
    _, sides = boundary_sides(square)
    assert set(sides.tolist()) == {1, 2, 3, 4}


def test_bad_requests(tmp_path, padded):
    _, size, mesh = padded
    with pytest.raises(MeshFormatError, match="format"):
        write_fwi_mesh(tmp_path / "bp.stl", mesh, size)
    with pytest.raises(MeshFormatError, match="velocity_on"):
        write_fwi_mesh(tmp_path / "bp.msh", mesh, size, velocity_on="edges")
    with pytest.raises(MeshFormatError, match="units"):
        write_fwi_mesh(tmp_path / "bp.msh", mesh, size, units="ft")
    with pytest.raises(MeshFormatError, match="coordinate_order"):
        write_fwi_mesh(tmp_path / "bp.msh", mesh, size, coordinate_order="yx")
    with pytest.raises(MeshFormatError, match="VelocityModel"):
        write_fwi_mesh(tmp_path / "bp.msh", mesh, np.ones((3, 3)))
    tetrahedron = tm.Mesh(np.eye(4)[:, :3], np.array([[0, 1, 2, 3]]))
    with pytest.raises(MeshFormatError, match="2-D"):
        write_fwi_mesh(tmp_path / "tet.msh", tetrahedron)
