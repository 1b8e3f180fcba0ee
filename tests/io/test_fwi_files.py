"""Files for FWI codes: Gmsh 2.2 with boundary physical groups, VTU, XDMF, velocities on vertices or cells."""

import itertools

import meshio
import numpy as np
import pytest

import terramesh as tm
from terramesh.cli import main
from terramesh.errors import MeshFormatError, MeshValidityError
from terramesh.io.fwi import BOUNDARY_IDS, BOUNDARY_IDS_3D, REGION_IDS, boundary_sides, write_fwi_mesh
from terramesh.mesh.topology import signed_areas
from terramesh.seismic import VelocityModel, pad_model, read_velocity, size_function


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
    assert {name: values.tolist() for name, values in data.field_data.items()} == {
        "left": [1, 1],
        "right": [2, 1],
        "bottom": [3, 1],
        "top": [4, 1],
        "model": [1, 2],
        "pad": [2, 2],
    }
    types = [block.type for block in data.cells]
    assert types == ["line", "triangle"]
    assert set(data.cell_data["gmsh:physical"][0].tolist()) == {1, 2, 3, 4}
    np.testing.assert_allclose(data.point_data["velocity"], model(mesh.points), rtol=1e-8)
    np.testing.assert_array_equal(data.cells[1].data, mesh.cells)


def test_gmsh_cell_velocity(tmp_path, padded, capsys):
    _, size, mesh = padded
    path = tmp_path / "cells.msh"
    write_fwi_mesh(path, mesh, size, velocity_on="cells")
    _, _, elements, data = parse_msh(path)
    assert "$NodeData" not in data
    name, ids, values = data["$ElementData"]
    triangle_ids = [e[0] for e in elements if e[1] == 2]
    np.testing.assert_array_equal(ids, triangle_ids)
    np.testing.assert_allclose(values, size.model(mesh.points[mesh.cells].mean(axis=1)), rtol=1e-8)
    back = tm.read_mesh(path)  # read back, as terramesh info and --adapt do (meshio alone cannot)
    assert back.n_cells == mesh.n_cells and np.allclose(back.points, mesh.points)
    # what was left out is named (the velocity was gone without a word), and terramesh info says so
    assert back.point_data == {} and back.info["cell_data_left_out"] == ["velocity"]
    assert main(["info", str(path)]) == 0
    said = capsys.readouterr().out
    assert "point data: none; cell data, not read: velocity" in said
    assert "time step: not measured (no depths in the file; a seismic mesh's: terramesh.seismic.stable_timestep" in said
    write_fwi_mesh(tmp_path / "cells.vtu", mesh, size, velocity_on="cells")
    assert tm.read_mesh(tmp_path / "cells.vtu").info["cell_data_left_out"] == ["region", "velocity"]


@pytest.mark.parametrize("name", ["spyro.msh", "spyro.vtu", "spyro.xdmf"])
def test_km_files_read_back_planar(tmp_path, padded, name):
    # a model a few km across, in km, fits longitude and latitude: read back, it was guessed EPSG:4326 and its
    # quality and time steps measured on the sphere
    _, size, mesh = padded
    path = tmp_path / name
    write_fwi_mesh(path, mesh, size, units="km")
    back = tm.read_mesh(path)
    assert back.crs is None and not back.geographic
    np.testing.assert_allclose(back.points, mesh.points / 1000)


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
    # (z, x) mirrors the plane: the triangles stay counter-clockwise, the boundary lines outward, in the file's frame
    frame = nodes[:, 1:3]
    triangles = np.array([e[5:] for e in elements if e[1] == 2]) - 1
    assert np.all(signed_areas(frame, triangles) > 0)
    lines = np.array([e[5:] for e in elements if e[1] == 1]) - 1
    direction = frame[lines[:, 1]] - frame[lines[:, 0]]
    outward = np.column_stack([direction[:, 1], -direction[:, 0]])  # right of a line running counter-clockwise
    midpoints = frame[lines].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", outward, midpoints - frame.mean(axis=0)) > 0)  # the box is convex


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
    with pytest.raises(MeshFormatError, match="coordinate_order of a 2-D mesh"):
        write_fwi_mesh(tmp_path / "bp.msh", mesh, size, coordinate_order="zxy")
    with pytest.raises(MeshFormatError, match="bbox of a 2-D mesh"):
        write_fwi_mesh(tmp_path / "bp.msh", mesh, bbox=[[0, 0, 0], [1, 1, 1]])
    # the unpadded model of a padded mesh: every side was tagged 5 and the padding no region, silently
    beyond = r"reaches 100 m beyond the velocity model's box \(the padding of a size function\)"
    with pytest.raises(MeshFormatError, match=beyond):
        write_fwi_mesh(tmp_path / "bp.msh", mesh, padded[0])
    # a model built in km/s was written as 1.5 m/s, without a word
    in_km_per_s = VelocityModel(size.model.values / 1000, size.model.axes)
    with pytest.raises(MeshFormatError, match=r"velocities are 1\.5\.\.2\.75, which look like km/s"):
        write_fwi_mesh(tmp_path / "bp.msh", mesh, in_km_per_s)
    assert not (tmp_path / "bp.msh").exists()


# ---- 3-D: tetrahedra, boundary triangles on the six faces of a box


def kuhn_box(lower, upper, n):
    """A structured tetrahedral mesh of a box: n[0] x n[1] x n[2] bricks, six positive tetrahedra each.

    Its vertices lie exactly on the box's faces, so areas come out exact.
    """
    axes = [np.linspace(lo, hi, k + 1) for lo, hi, k in zip(lower, upper, n, strict=True)]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    step = np.array([(n[1] + 1) * (n[2] + 1), n[2] + 1, 1])
    ix, iy, iz = np.meshgrid(*(np.arange(k) for k in n), indexing="ij")
    corner = (ix * step[0] + iy * step[1] + iz * step[2]).reshape(-1)
    cells = []
    for a, b in itertools.permutations(range(3), 2):  # the first two steps of each path to the far corner
        cells.append(np.column_stack([corner, corner + step[a], corner + step[a] + step[b], corner + step.sum()]))
    cells = np.concatenate(cells)
    negative = volumes(points, cells) < 0
    cells[negative, :2] = cells[negative, 1::-1]
    return tm.Mesh(points, cells)


def volumes(points, cells):
    a, b, c, d = (points[cells[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6


def reference_faces(cells):
    """Faces of exactly one tetrahedron, sorted vertex triples, and the vertex of that tetrahedron opposite each."""
    faces = np.concatenate([np.delete(cells, k, axis=1) for k in range(4)])
    opposite = np.concatenate([cells[:, k] for k in range(4)])
    keys = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    single = counts[inverse.reshape(-1)] == 1
    return {tuple(face): int(vertex) for face, vertex in zip(keys[single].tolist(), opposite[single], strict=True)}


def normals(points, triangles):
    """Area vectors (normal times area) of triangles, right-handed in their vertex order."""
    a, b, c = (points[triangles[:, i]] for i in range(3))
    return 0.5 * np.cross(b - a, c - a)


def assert_outward(points, triangles, cells):
    """Every triangle is a boundary face of the mesh whose normal points away from its tetrahedron."""
    faces = reference_faces(cells)
    assert sorted(tuple(sorted(t)) for t in triangles.tolist()) == sorted(faces)
    opposite = np.array([faces[tuple(sorted(t))] for t in triangles.tolist()])
    away = points[triangles].mean(axis=1) - points[opposite]
    assert np.all(np.einsum("ij,ij->i", normals(points, triangles), away) > 0)


def by_type(elements, gmsh_type):
    return np.array([e for e in elements if e[1] == gmsh_type])


@pytest.fixture(scope="module")
def padded3d():
    """A 3-D gradient model (600 x 400 x 400 m) padded by 200 m with a ramp to 4000 m/s, and a mesh of its box."""
    x, y, z = np.arange(7) * 100.0, np.arange(5) * 100.0, np.arange(-4, 1) * 100.0
    grid = np.meshgrid(x, y, z, indexing="ij")
    model = VelocityModel(1500.0 + 0.5 * grid[0] + 0.25 * grid[1] - 1.5 * grid[2], (x, y, z))
    padded = pad_model(model, 200.0, style="linear", velocity=4000.0)
    mesh = tm.generate_mesh(tm.geometry.Box(*padded.bbox), 110.0, seed=0)
    return model, padded, mesh


def test_gmsh_3d_boundary_tags_regions_and_vertex_velocity(tmp_path, padded3d):
    model, padded, mesh = padded3d
    before = mesh.points.copy(), mesh.cells.copy()
    path = tmp_path / "box.msh"
    write_fwi_mesh(path, mesh, padded)
    names, nodes, elements, data = parse_msh(path)
    assert names == {
        (2, 1): "x_min",
        (2, 2): "x_max",
        (2, 3): "y_min",
        (2, 4): "y_max",
        (2, 5): "bottom",
        (2, 6): "top",
        (3, 1): "model",
        (3, 2): "pad",
    }
    np.testing.assert_array_equal(nodes[:, 0], np.arange(1, mesh.n_points + 1))
    np.testing.assert_array_equal(nodes[:, 1:], mesh.points)
    triangles, tetrahedra = by_type(elements, 2), by_type(elements, 4)
    assert len(triangles) + len(tetrahedra) == len(elements)
    np.testing.assert_array_equal(tetrahedra[:, 5:] - 1, mesh.cells)
    np.testing.assert_array_equal(triangles[:, 3], triangles[:, 4])
    # every boundary face once, outward, tagged by the box face its vertices lie on; none left over as 7
    assert_outward(mesh.points, triangles[:, 5:] - 1, mesh.cells)
    corners = mesh.points[np.array(list(reference_faces(mesh.cells)))]
    box = padded.bbox
    for k, tag in enumerate(range(1, 7)):
        axis, end = divmod(k, 2)
        on_plane = np.all(np.abs(corners[:, :, axis] - box[end, axis]) < 1e-3, axis=1)
        assert np.sum(triangles[:, 3] == tag) == on_plane.sum() > 0
        on_side = mesh.points[triangles[triangles[:, 3] == tag, 5:] - 1][:, :, axis]
        np.testing.assert_allclose(on_side, box[end, axis], atol=1e-9)
    assert set(triangles[:, 3].tolist()) == set(range(1, 7))
    # cells in the padding layer (x, y sides and the bottom; not the top) are region 2
    centroids = mesh.points[mesh.cells].mean(axis=1)
    inner = padded.interior_bbox
    np.testing.assert_array_equal(inner, model.bbox)
    outside = np.any((centroids < inner[0]) | (centroids > inner[1]), axis=1)
    margin = np.min(np.abs(np.concatenate([centroids - inner[0], centroids[:, :2] - inner[1, :2]], axis=1)), axis=1)
    clear = margin > 5.0  # beyond the writer's tolerance, 1 % of an edge
    assert clear.mean() > 0.9
    np.testing.assert_array_equal((tetrahedra[:, 3] == REGION_IDS["pad"])[clear], outside[clear])
    assert set(tetrahedra[:, 3].tolist()) == {1, 2}
    # the velocity at each vertex: the padded model's, which ramps to 4000 m/s in the layer
    name, ids, values = data["$NodeData"]
    assert name == "velocity"
    np.testing.assert_array_equal(ids, np.arange(1, mesh.n_points + 1))
    np.testing.assert_allclose(values, padded(mesh.points), rtol=1e-8)
    inside = np.all((mesh.points >= inner[0]) & (mesh.points <= inner[1]), axis=1)
    np.testing.assert_allclose(values[inside], model(mesh.points[inside]), rtol=1e-8)
    assert values.max() > 3900.0
    np.testing.assert_array_equal(mesh.points, before[0])
    np.testing.assert_array_equal(mesh.cells, before[1])


@pytest.mark.parametrize("which", ["generated", "structured"])
def test_gmsh_3d_side_areas_and_orientation(tmp_path, padded3d, which):
    box = np.array([[-200.0, -200.0, -600.0], [800.0, 600.0, 0.0]])
    if which == "generated":
        mesh = padded3d[2]
        # the generator leaves boundary vertices up to ~5e-7 m off the faces, worth ~2e-9 of a face's area
        rtol = 1e-8
    else:
        mesh = kuhn_box(box[0], box[1], (5, 4, 3))
        rtol = 1e-9
    path = tmp_path / "box.msh"
    write_fwi_mesh(path, mesh, bbox=box)
    names, nodes, elements, _ = parse_msh(path)
    triangles = by_type(elements, 2)
    faces, tags = triangles[:, 5:] - 1, triangles[:, 3]
    vectors = normals(mesh.points, faces)
    for k, tag in enumerate(range(1, 7)):
        axis, end = divmod(k, 2)
        others = [a for a in range(3) if a != axis]
        side_area = np.prod(box[1, others] - box[0, others])
        on = tags == tag
        np.testing.assert_allclose(np.linalg.norm(vectors[on], axis=1).sum(), side_area, rtol=rtol)
        # outward: along -axis on the lower face, +axis on the upper
        assert np.all(vectors[on, axis] * (1 if end else -1) > 0)
    assert set(tags.tolist()) == set(range(1, 7))
    assert_outward(mesh.points, faces, mesh.cells)
    np.testing.assert_allclose(vectors.sum(axis=0), 0.0, atol=1e-6 * np.abs(vectors).sum())  # a closed surface


def test_boundary_sides_3d_on_a_structured_box():
    mesh = kuhn_box((0.0, 0.0, -3.0), (5.0, 4.0, 0.0), (5, 4, 3))
    faces, sides = boundary_sides(mesh)
    assert faces.shape == (2 * 2 * (5 * 4 + 5 * 3 + 4 * 3), 3)
    counts = np.bincount(sides, minlength=8)
    assert counts.tolist() == [0, 2 * 12, 2 * 12, 2 * 15, 2 * 15, 2 * 20, 2 * 20, 0]
    assert_outward(mesh.points, faces, mesh.cells)
    # the box given explicitly: faces on planes that are not the box's sides are "boundary"
    _, sides = boundary_sides(mesh, [[0.0, 0.0, -3.0], [5.0, 4.0, 1.0]])
    assert np.sum(sides == BOUNDARY_IDS_3D["boundary"]) == 2 * 20
    # cells of either orientation give outward faces
    flipped = tm.Mesh(mesh.points, mesh.cells[:, [1, 0, 2, 3]])
    assert_outward(mesh.points, boundary_sides(flipped)[0], mesh.cells)


def test_gmsh_3d_cell_velocity(tmp_path, padded3d):
    _, padded, mesh = padded3d
    path = tmp_path / "cells.msh"
    write_fwi_mesh(path, mesh, padded, velocity_on="cells")
    _, _, elements, data = parse_msh(path)
    assert "$NodeData" not in data
    name, ids, values = data["$ElementData"]
    assert name == "velocity"
    np.testing.assert_array_equal(ids, by_type(elements, 4)[:, 0])
    np.testing.assert_allclose(values, padded(mesh.points[mesh.cells].mean(axis=1)), rtol=1e-8)
    back = tm.read_mesh(path)
    assert back.n_cells == mesh.n_cells and np.allclose(back.points, mesh.points)


def test_meshio_reads_the_3d_gmsh_file(tmp_path, padded3d):
    _, padded, mesh = padded3d
    path = tmp_path / "box.msh"
    write_fwi_mesh(path, mesh, padded)
    data = meshio.gmsh.read(path)
    assert {name: values.tolist() for name, values in data.field_data.items()} == {
        **{name: [tag, 2] for name, tag in BOUNDARY_IDS_3D.items() if name != "boundary"},
        "model": [1, 3],
        "pad": [2, 3],
    }
    assert [block.type for block in data.cells] == ["triangle", "tetra"]
    assert set(data.cell_data["gmsh:physical"][0].tolist()) == set(range(1, 7))
    assert set(data.cell_data["gmsh:physical"][1].tolist()) == {1, 2}
    np.testing.assert_array_equal(data.points, mesh.points)
    np.testing.assert_array_equal(data.cells[1].data, mesh.cells)
    np.testing.assert_allclose(data.point_data["velocity"], padded(mesh.points), rtol=1e-8)


@pytest.mark.parametrize("name", ["box.vtu", "box.xdmf"])
@pytest.mark.parametrize("velocity_on", ["vertices", "cells"])
def test_vtu_and_xdmf_3d(tmp_path, padded3d, name, velocity_on):
    _, padded, mesh = padded3d
    path = tmp_path / name
    write_fwi_mesh(path, mesh, padded, velocity_on=velocity_on)
    data = meshio.read(path)
    np.testing.assert_array_equal(data.points, mesh.points)
    assert list(data.cells_dict) == ["tetra"]
    np.testing.assert_array_equal(data.cells_dict["tetra"], mesh.cells)
    centroids = mesh.points[mesh.cells].mean(axis=1)
    inner = padded.interior_bbox
    outside = np.any((centroids < inner[0] - 5) | (centroids > inner[1] + 5), axis=1)
    regions = data.cell_data["region"][0]
    assert set(regions.tolist()) == {1, 2}
    assert np.all(regions[outside] == REGION_IDS["pad"])
    if velocity_on == "vertices":
        np.testing.assert_allclose(data.point_data["velocity"], padded(mesh.points), rtol=1e-8)
    else:
        np.testing.assert_allclose(data.cell_data["velocity"][0], padded(centroids), rtol=1e-8)


@pytest.mark.parametrize("order", ["xyz", "zxy", "xzy", "yxz"])
def test_3d_km_units_and_coordinate_order(tmp_path, padded3d, order):
    _, padded, mesh = padded3d
    path = tmp_path / "spyro.msh"
    write_fwi_mesh(path, mesh, padded, units="km", coordinate_order=order)
    _, nodes, elements, data = parse_msh(path)
    frame = nodes[:, 1:]
    for column, axis in enumerate(order):
        np.testing.assert_allclose(frame[:, column], mesh.points[:, "xyz".index(axis)] / 1000)
    np.testing.assert_allclose(data["$NodeData"][2], padded(mesh.points) / 1000, rtol=1e-8)
    triangles, tetrahedra = by_type(elements, 2), by_type(elements, 4)
    top = triangles[triangles[:, 3] == BOUNDARY_IDS_3D["top"], 5:] - 1
    np.testing.assert_allclose(frame[top][:, :, order.index("z")], 0.0, atol=1e-9)  # the free surface, z = 0
    bottom = triangles[triangles[:, 3] == BOUNDARY_IDS_3D["bottom"], 5:] - 1
    np.testing.assert_allclose(frame[bottom][:, :, order.index("z")], -0.6, atol=1e-9)
    # mirrored orders ("xzy", "yxz") too: tetrahedra positive and faces outward in the file's own frame
    assert np.all(volumes(frame, tetrahedra[:, 5:] - 1) > 0)
    assert_outward(frame, triangles[:, 5:] - 1, tetrahedra[:, 5:] - 1)


def test_3d_non_box_domain(tmp_path):
    ball = tm.generate_mesh(tm.geometry.Ball((0.0, 0.0, -2.0), 1.0), 0.3, seed=0)
    path = tmp_path / "ball.msh"
    write_fwi_mesh(path, ball, coordinate_order="zxy")
    names, nodes, elements, data = parse_msh(path)
    assert data == {}
    assert names == {(2, 7): "boundary", (3, 1): "model"}  # a ball has no box faces
    triangles = by_type(elements, 2)
    assert set(triangles[:, 3].tolist()) == {BOUNDARY_IDS_3D["boundary"]}
    assert len(triangles) == len(reference_faces(ball.cells))
    frame = nodes[:, 1:]
    faces = triangles[:, 5:] - 1
    away = frame[faces].mean(axis=1) - np.array([-2.0, 0.0, 0.0])  # the centre, (z, x, y)
    assert np.all(np.einsum("ij,ij->i", normals(frame, faces), away) > 0)


def test_bad_requests_3d(tmp_path, padded, padded3d):
    _, size2d, mesh2d = padded
    _, model3d, mesh3d = padded3d
    with pytest.raises(MeshFormatError, match="coordinate_order of a 3-D mesh"):
        write_fwi_mesh(tmp_path / "box.msh", mesh3d, coordinate_order="zx")
    with pytest.raises(MeshFormatError, match="coordinate_order"):
        write_fwi_mesh(tmp_path / "box.msh", mesh3d, coordinate_order="zxx")
    with pytest.raises(MeshFormatError, match="3-D mesh needs a 3-D velocity model"):
        write_fwi_mesh(tmp_path / "box.msh", mesh3d, size2d)
    with pytest.raises(MeshFormatError, match="2-D mesh needs a 2-D velocity model"):
        write_fwi_mesh(tmp_path / "bp.msh", mesh2d, model3d)
    with pytest.raises(MeshFormatError, match="bbox of a 3-D mesh"):
        write_fwi_mesh(tmp_path / "box.msh", mesh3d, bbox=[[0, 0], [1, 1]])
    surface = tm.Mesh(np.eye(3), np.array([[0, 1, 2]]))  # triangles in 3-D space
    with pytest.raises(MeshFormatError, match="tetrahedral"):
        write_fwi_mesh(tmp_path / "surface.msh", surface)
    with pytest.raises(MeshFormatError, match="tetrahedral"):
        boundary_sides(surface)
    assert not (tmp_path / "box.msh").exists()


SQUARE = tm.Mesh(np.array([[0.0, -1], [1, -1], [1, 0], [0, 0]]), np.array([[0, 1, 2], [0, 2, 3]]))


@pytest.mark.parametrize("name", ["square.msh", "square.vtu", "square.xdmf"])
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_coordinates_and_node_data_are_refused(tmp_path, name, bad):
    points = SQUARE.points.copy()
    points[[2, 3], 1] = bad
    path = tmp_path / name
    broken = tm.Mesh(SQUARE.points, SQUARE.cells)
    broken.points = points  # a Mesh refuses them; changed afterwards, the writers still do
    with pytest.raises(MeshFormatError, match="coordinates are NaN or infinite at 2 of 4 nodes \\(node 3 first"):
        write_fwi_mesh(path, broken)
    with pytest.raises(MeshFormatError, match="coordinates are NaN or infinite at 2 of 4 nodes"):
        boundary_sides(broken)
    depth = np.array([0.0, 1.0, bad, 2.0])
    with_depth = tm.Mesh(SQUARE.points, SQUARE.cells, point_data={"depth": depth})
    if name.endswith(".msh"):  # Gmsh files carry no point data
        write_fwi_mesh(path, with_depth)
        assert path.exists()
    else:
        with pytest.raises(MeshFormatError, match="point_data\\['depth'\\] is NaN or infinite at 1 of 4 nodes"):
            write_fwi_mesh(path, with_depth)
        assert not path.exists()


@pytest.mark.parametrize("tolerance", [-1, -1e-12, "a", [0.1], np.nan, np.inf])
def test_boundary_sides_needs_a_finite_tolerance_of_at_least_zero(tolerance):
    with pytest.raises(MeshFormatError, match="tolerance must be a"):
        boundary_sides(SQUARE, tolerance=tolerance)
    _, sides = boundary_sides(SQUARE, tolerance=0)  # zero is fine: the square's corners lie on the box exactly
    assert sorted(sides.tolist()) == [1, 2, 3, 4]


@pytest.mark.parametrize("dim", [2, 3])
def test_a_mesh_without_cells_is_refused(tmp_path, dim):
    empty = tm.Mesh(np.eye(dim + 1, dim), np.empty((0, dim + 1), dtype=np.int64))
    with pytest.raises(MeshFormatError, match="write_fwi_mesh needs a mesh with at least one cell"):
        write_fwi_mesh(tmp_path / "empty.msh", empty)
    with pytest.raises(MeshFormatError, match="boundary_sides needs a mesh with at least one cell"):
        boundary_sides(empty)
    assert not (tmp_path / "empty.msh").exists()


@pytest.mark.parametrize("name", ["flags.vtu", "flags.xdmf"])
def test_boolean_point_data_goes_in_as_zeros_and_ones(tmp_path, padded, name):
    """meshio stopped with a bare ``KeyError: dtype('bool')``."""
    _, size, mesh = padded
    flagged = tm.Mesh(mesh.points, mesh.cells, point_data={"deep": mesh.points[:, 1] < -200})
    write_fwi_mesh(tmp_path / name, flagged, size)
    np.testing.assert_array_equal(meshio.read(tmp_path / name).point_data["deep"], flagged.point_data["deep"])


# ---- a mesh and a model or bbox that do not belong together, and invalid meshes: refused, no file written


def test_a_km_mesh_with_a_metre_model_is_refused(tmp_path, padded):
    # the reviewer's case: every vertex read the model's corner velocity (1486 m/s) and the lines were tagged
    # {5: 64, 4: 165} where the right file has {1, 2, 3, 4}
    model, size, mesh = padded
    in_km = tm.Mesh(mesh.points / 1000, mesh.cells)
    path = tmp_path / "km.msh"
    message = r"the mesh is about 1/1000 of the model's extent: a mesh in km with a model in m\?"
    extents = r"\(x -0\.1\.\.1\.1, z -0\.6\.\.0\) and the velocity model's box \(x -100\.\.1100, z -600\.\.0, metres\)"
    with pytest.raises(MeshFormatError, match=extents + ".*" + message):
        write_fwi_mesh(path, in_km, size)
    with pytest.raises(MeshFormatError, match=message):  # its own box in km does not make the model's velocities fit
        write_fwi_mesh(path, in_km, size, bbox=[[-0.1, -0.6], [1.1, 0.0]])
    # the other way round: a model whose spacing was read in km, against a mesh in metres
    km_model = VelocityModel(model.values, [axis / 1000 for axis in model.axes])
    with pytest.raises(MeshFormatError, match=r"reaches .* beyond .* the mesh is about 1000 times the model's extent"):
        write_fwi_mesh(path, mesh, km_model)
    assert not path.exists()


def test_a_mesh_of_part_of_a_model_needs_its_own_bbox(tmp_path, padded):
    model, size, _ = padded
    part = tm.generate_mesh(tm.geometry.Rectangle((100.0, -400.0), (600.0, -100.0)), 60.0, seed=0)
    path = tmp_path / "part.msh"
    with pytest.raises(MeshFormatError, match=r"share 30 % of their union, less than 50 %: .* bbox= the mesh's own"):
        write_fwi_mesh(path, part, model)
    assert not path.exists()
    write_fwi_mesh(path, part, model, bbox=[[100.0, -400.0], [600.0, -100.0]])
    names, _, elements, data = parse_msh(path)
    assert {tag for (dim, tag) in names if dim == 1} == {1, 2, 3, 4}
    np.testing.assert_allclose(data["$NodeData"][2], model(part.points), rtol=1e-8)


def test_a_bbox_the_boundary_is_not_on_is_refused(tmp_path, padded):
    # bbox=[[0, 0], [1, 1]] tagged the free surface (z = 0) 3, "bottom", and every other side 5
    _, size, mesh = padded
    path = tmp_path / "bbox.msh"
    message = r"bbox \(x 0\.\.1, z 0\.\.1\) is not the box of the mesh, which spans x -100\.\.1100, z -600\.\.0"
    with pytest.raises(MeshFormatError, match=message):
        write_fwi_mesh(path, mesh, bbox=[[0, 0], [1, 1]])
    with pytest.raises(MeshFormatError, match="beyond it by up to 100"):  # the unpadded model's box for a padded mesh
        write_fwi_mesh(path, mesh, size, bbox=[[0.0, -500.0], [1000.0, 0.0]])
    assert not path.exists()
    write_fwi_mesh(path, mesh, bbox=[[-100.0, -600.0], [1100.0, 0.0]])
    _, nodes, elements, _ = parse_msh(path)
    top = np.array([e[5:] for e in elements if e[1] == 1 and e[3] == BOUNDARY_IDS["top"]]) - 1
    np.testing.assert_array_equal(nodes[top][:, :, 2], 0.0)  # the free surface is "top"
    assert {e[3] for e in elements if e[1] == 1} == {1, 2, 3, 4}


@pytest.mark.parametrize(
    ("broken", "message"),
    [
        ("clockwise", r"write_fwi_mesh needs a valid mesh: 2 cells are clockwise or have zero area"),
        ("repeated corner", r"1 cells are clockwise or have zero area; .*"),
        ("unused vertex", r"1 vertices are not used by any cell"),
    ],
)
def test_invalid_2d_meshes_are_refused(tmp_path, broken, message):
    # clockwise and degenerate meshes were written without a word
    points, cells = SQUARE.points, SQUARE.cells.copy()
    if broken == "clockwise":
        cells = cells[:, ::-1]
    elif broken == "repeated corner":
        cells[1] = [0, 0, 2]
    else:
        points = np.vstack([points, [0.5, -0.5]])
    path = tmp_path / "square.msh"
    with pytest.raises(MeshValidityError, match=message + r".*repair it first with terramesh\.cleanup\.fix_mesh"):
        write_fwi_mesh(path, tm.Mesh(points, cells))
    assert not path.exists()


def test_inverted_tetrahedra_are_refused(tmp_path):
    box = kuhn_box((0.0, 0.0, -1.0), (2.0, 1.0, 0.0), (2, 1, 1))
    cells = box.cells.copy()
    cells[:3, :2] = cells[:3, 1::-1]
    path = tmp_path / "box.msh"
    with pytest.raises(MeshValidityError, match=r"3 cells are inverted or have zero volume.*swap two corners"):
        write_fwi_mesh(path, tm.Mesh(box.points, cells))
    assert not path.exists()


def test_a_mesh_whose_top_follows_topography_is_written_against_the_models_box(tmp_path):
    # bbox=model.bbox, the default's value, was refused as "not the box of the mesh" (its top 100 m below z = 0)
    x, z = np.linspace(0, 4000, 81), np.linspace(-2000, 0, 41)
    model = VelocityModel(1500 + 0 * x[:, None] - z[None, :], (x, z))
    top = [(xx, -100 - 200 * np.sin(np.pi * xx / 4000) ** 2) for xx in np.linspace(4000, 0, 41)]
    mesh = tm.generate_mesh(tm.geometry.Polygon([(0, -2000), (4000, -2000), *top]), 200.0, h0=200.0, seed=0)
    write_fwi_mesh(tmp_path / "default.msh", mesh, model)
    write_fwi_mesh(tmp_path / "given.msh", mesh, model, bbox=model.bbox)
    assert (tmp_path / "default.msh").read_bytes() == (tmp_path / "given.msh").read_bytes()
    with pytest.raises(MeshFormatError, match=r"is not the box of the mesh, which spans .* \(4.52 % of it on an axis"):
        write_fwi_mesh(tmp_path / "x.msh", mesh, model, bbox=[[0, -2000], [4000, 40000]])


def lexsorted_boundary_facets(points, cells):
    """The boundary facets as write_fwi_mesh found them before its census: a lexsort of every cell's facets."""
    corners = cells.shape[1]
    facets = np.concatenate([np.delete(cells, k, axis=1) for k in range(corners)])
    opposite = np.concatenate([cells[:, k] for k in range(corners)])
    keys = np.sort(facets, axis=1)
    order = np.lexsort(keys.T[::-1])
    same = np.all(keys[order][1:] == keys[order][:-1], axis=1)
    single = ~(np.concatenate([[False], same]) | np.concatenate([same, [False]]))
    chosen = np.sort(order[single])
    facets, opposite = facets[chosen], opposite[chosen]
    inward = np.linalg.det(points[facets] - points[opposite][:, None, :]) < 0
    facets[inward, :2] = facets[inward, 1::-1]
    return facets


def test_boundary_facets_are_those_of_sorting_every_facet(tmp_path, padded, padded3d):
    # the census replaced a lexsort of all facets (1.5-2 s at 750k tetrahedra): the same facets, order and
    # orientation, so the files are the same
    for mesh in (padded[2], padded3d[2]):
        expected = lexsorted_boundary_facets(mesh.points, mesh.cells)
        np.testing.assert_array_equal(boundary_sides(mesh)[0], expected)
        flipped = tm.Mesh(mesh.points, mesh.cells[:, [1, 0, *range(2, mesh.cells.shape[1])]])
        expected_flipped = lexsorted_boundary_facets(flipped.points, flipped.cells)
        np.testing.assert_array_equal(boundary_sides(flipped)[0], expected_flipped)
        path = tmp_path / f"{mesh.dim}d.msh"
        write_fwi_mesh(path, mesh)
        _, _, elements, _ = parse_msh(path)
        written = np.array([e[5:] for e in elements if e[1] == (1 if mesh.dim == 2 else 2)]) - 1
        np.testing.assert_array_equal(written, expected)


def broken_box(broken):
    """Two bricks of tetrahedra (18 vertices, 12 cells) with one thing wrong (inverted cells: above)."""
    box = kuhn_box((0.0, 0.0, -1.0), (2.0, 1.0, 0.0), (2, 1, 1))
    points, cells = box.points, box.cells.copy()
    if broken == "flat":  # a cell on a boundary face, its fourth corner at the face's centroid
        points = np.vstack([points, points[[0, 1, 3]].mean(axis=0)])
        cells = np.vstack([cells, [[0, 1, 3, len(box.points)]]])
    elif broken == "repeated corner":
        cells[0, 0] = cells[0, 1]
    elif broken == "unused vertex":
        points = np.vstack([points, [[5.0, 5.0, 5.0]]])
    elif broken == "face in three cells":  # a positive third cell on the inner face (0, 1, 7), apex above the box
        points = np.vstack([points, [[1.0, 0.5, 3.0]]])
        third = np.array([[0, 1, 7, len(box.points)]])
        third[volumes(points, third) < 0, :2] = third[volumes(points, third) < 0, 1::-1]
        cells = np.vstack([cells, third])
    return tm.Mesh(points, cells)


@pytest.mark.parametrize(
    ("broken", "message"),
    [
        ("flat", "1 cells are inverted or have zero volume; 1 faces have both their cells on one side"),
        (
            "repeated corner",
            "1 cells are inverted or have zero volume; 1 faces are shared by more than two cells; 3 boundary edges "
            "are not on exactly two boundary faces",
        ),
        ("unused vertex", "1 vertices are not used by any cell"),
        ("face in three cells", "1 faces are shared by more than two cells; 3 boundary edges are not on exactly two"),
    ],
)
def test_each_broken_rule_of_a_tetrahedral_mesh_is_named(tmp_path, broken, message):
    path = tmp_path / "box.msh"
    with pytest.raises(MeshValidityError, match=f"write_fwi_mesh needs a valid mesh: {message}.*swap two corners"):
        write_fwi_mesh(path, broken_box(broken))
    assert not path.exists()


@pytest.mark.parametrize("dim", [2, 3])
def test_cells_naming_a_missing_vertex_are_refused(tmp_path, dim):
    mesh = SQUARE if dim == 2 else broken_box(None)
    mesh = tm.Mesh(mesh.points, mesh.cells)
    mesh.cells = mesh.cells.copy()  # reassigned after construction, past the Mesh's own check
    mesh.cells[0, 0] = mesh.n_points
    message = f"cells refer to vertices that do not exist: indices 0 to {mesh.n_points}"
    with pytest.raises(MeshValidityError, match=message):
        write_fwi_mesh(tmp_path / "x.msh", mesh)
    with pytest.raises(MeshValidityError, match=message):  # the kernel reads without bounds checks
        boundary_sides(mesh)
    assert not (tmp_path / "x.msh").exists()
