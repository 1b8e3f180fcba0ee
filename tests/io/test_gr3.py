import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import MeshFormatError, TerrameshWarning
from terramesh.io import Boundaries, LandBoundary, OpenBoundary, read_gr3, write_gr3
from terramesh.mesh.topology import boundary_edges

from ..conftest import boundary_ring, hole_ring
from .test_fort14 import valid_cells

# the SCHISM manual's layout: land segments flagged 0, islands flagged 1 and not closed
SAMPLE = """\
hgrid.gr3 ! alphanumeric description; ignored by code
6 7 ! # of elements and nodes in the horizontal grid
1 0.0 0.0 10.0 ! node #, x,y, depth
2 2.0 0.0 10.0
3 2.0 2.0 5.0
4 0.0 2.0 5.0
5 0.8 0.8 1.0
6 1.2 0.8 1.0
7 1.0 1.2 1.0
1 3 1 2 6 ! element #, element type, nodes
2 3 2 3 6
3 3 6 3 7
4 3 7 3 4
5 3 4 5 7
6 3 4 1 5
1 = Number of open boundaries
2 = Total number of open boundary nodes
2 = Number of nodes for open boundary 1
1 ! first node on this segment
2 !last node on this segment
2 = number of land boundaries (including islands)
6 = Total number of land boundary nodes
3 0 = Number of nodes for land boundary 1 ('0' means the exterior land boundary)
2
3
4
3 1 = Number of nodes for island boundary 1 ('1' means island)
5
6
7 !last node on this island (note this is different from the first node)
"""


def test_reads_flags_and_closes_island_rings(tmp_path):
    path = tmp_path / "hgrid.gr3"
    path.write_text(SAMPLE)
    mesh = tm.read_mesh(path)
    assert (mesh.n_points, mesh.n_cells) == (7, 6)
    np.testing.assert_array_equal(mesh.point_data["depth"][:3], [10, 10, 5])
    (sea,) = mesh.boundaries.open
    np.testing.assert_array_equal(sea.nodes, [0, 1])
    land, island = mesh.boundaries.land
    assert (land.ibtype, island.ibtype) == (0, 1)
    np.testing.assert_array_equal(land.nodes, [1, 2, 3])
    np.testing.assert_array_equal(island.nodes, [4, 5, 6, 4])  # ADCIRC form: the ring repeats its first node


def test_fort14_island_becomes_a_flagged_open_ring_and_comes_back(tmp_path, plate_with_hole):
    domain, size = plate_with_hole
    mesh = tm.generate_mesh(domain, 0.1, seed=0)
    ring = hole_ring(mesh)
    outer = np.setdiff1d(np.unique(boundary_edges(mesh.cells)), ring)
    adcirc = tm.Mesh(
        mesh.points,
        mesh.cells,
        point_data={"depth": np.linspace(1, 20, mesh.n_points)},
        boundaries=Boundaries(
            open=[OpenBoundary(outer[:5], 0)],
            land=[LandBoundary(outer[4:], 20), LandBoundary(np.append(ring, ring[0]), 21)],
        ),
        title="plate with a hole",
    )
    fort14 = tmp_path / "fort.14"
    adcirc.write(fort14)
    from_fort14 = tm.read_mesh(fort14)
    np.testing.assert_array_equal(from_fort14.boundaries.land[1].nodes, np.append(ring, ring[0]))

    gr3 = tmp_path / "hgrid.gr3"
    from_fort14.write(gr3)
    lines = gr3.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith(f"{len(ring)} 1 "))
    island_nodes = [int(line) for line in lines[header + 1 : header + 1 + len(ring)]]
    assert island_nodes == (ring + 1).tolist()  # no closing node, flag 1
    assert island_nodes[-1] != island_nodes[0]
    assert lines[header - len(outer[4:]) - 1].split()[:2] == [str(len(outer[4:])), "0"]  # mainland: flag 0

    back = tm.read_mesh(gr3)
    np.testing.assert_array_equal(back.points, adcirc.points)
    np.testing.assert_array_equal(back.cells, adcirc.cells)
    np.testing.assert_array_equal(back.point_data["depth"], adcirc.point_data["depth"])
    assert back.title == "plate with a hole"
    mainland, island = back.boundaries.land
    np.testing.assert_array_equal(island.nodes, np.append(ring, ring[0]))  # closed again
    assert (mainland.ibtype, island.ibtype) == (0, 1)
    np.testing.assert_array_equal(back.boundaries.open[0].nodes, outer[:5])
    again = tmp_path / "again.14"
    back.write(again)
    np.testing.assert_array_equal(tm.read_mesh(again).boundaries.land[1].nodes, np.append(ring, ring[0]))


finite = st.floats(-1e6, 1e6, allow_nan=False)


@st.composite
def gr3_meshes(draw):
    points, cells = draw(valid_cells())
    n = len(points)
    depth = np.array(draw(st.lists(finite, min_size=n, max_size=n)))
    nodes = st.lists(st.integers(0, n - 1), min_size=2, max_size=8, unique=True).map(np.array)
    opens = draw(st.lists(st.builds(OpenBoundary, nodes, st.none()), max_size=3))
    lands = []
    for flag in draw(st.lists(st.sampled_from([0, 1]), max_size=4)):
        where = draw(nodes)
        lands.append(LandBoundary(np.append(where, where[0]) if flag else where, flag))  # islands in ADCIRC form
    title = draw(st.text(st.characters(codec="ascii", exclude_categories=["Cc"]), max_size=30)).strip() or "grid"
    return tm.Mesh(points, cells, point_data={"depth": depth}, boundaries=Boundaries(opens, lands), title=title)


@pytest.mark.filterwarnings("ignore:.*have a depth no place on Earth has")  # numbers, not places
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(gr3_meshes())
@example(  # its title came back "0 0"
    tm.Mesh(np.eye(3)[:, :2], [[2, 0, 1]], point_data={"depth": np.zeros(3)}, boundaries=Boundaries(), title="0  0")
)
def test_hypothesis_round_trip(tmp_path, mesh):
    before = (mesh.points.copy(), mesh.cells.copy(), [b.nodes.copy() for b in mesh.boundaries.land])
    path = tmp_path / "random.gr3"
    mesh.write(path)
    np.testing.assert_array_equal(mesh.points, before[0])  # the writer does not mutate
    np.testing.assert_array_equal(mesh.cells, before[1])
    for boundary, nodes in zip(mesh.boundaries.land, before[2], strict=True):
        np.testing.assert_array_equal(boundary.nodes, nodes)
    back = read_gr3(path)
    np.testing.assert_array_equal(back.points, mesh.points)
    np.testing.assert_array_equal(back.cells, mesh.cells)
    np.testing.assert_array_equal(back.point_data["depth"], mesh.point_data["depth"])
    assert back.title == mesh.title
    for x, y in zip(
        mesh.boundaries.open + mesh.boundaries.land, back.boundaries.open + back.boundaries.land, strict=True
    ):
        np.testing.assert_array_equal(x.nodes, y.nodes)
        assert x.ibtype == y.ibtype


def test_barriers_become_land_segments_with_a_warning(tmp_path):
    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    weir = LandBoundary(np.array([0, 1]), 24, paired_nodes=np.array([3, 2]), values=np.ones((2, 3)))
    mesh = tm.Mesh(points, np.array([[0, 1, 2], [0, 2, 3]]), boundaries=Boundaries(land=[weir]))
    mesh.point_data["depth"] = np.full(4, 5.0)
    path = tmp_path / "weir.gr3"
    with pytest.warns(TerrameshWarning, match="IBTYPE 24"):
        write_gr3(path, mesh)
    front, back = read_gr3(path).boundaries.land
    np.testing.assert_array_equal(front.nodes, [0, 1])
    np.testing.assert_array_equal(back.nodes, [3, 2])
    assert front.ibtype == back.ibtype == 0 and front.values is None


def test_registry_and_errors(tmp_path):
    assert "gr3" in tm.io.FORMATS
    mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.5, seed=0)
    with pytest.warns(TerrameshWarning, match=r"the mesh has no depths .* all \d+ nodes are written at 0 m"):
        tm.write_mesh(tmp_path / "grid.txt", mesh, file_format="gr3")
    assert tm.read_mesh(tmp_path / "grid.txt", file_format="gr3").n_cells == mesh.n_cells
    (tmp_path / "hgrid.ll").write_text(SAMPLE)
    assert tm.read_mesh(tmp_path / "hgrid.ll").n_points == 7
    with pytest.raises(MeshFormatError, match="only triangles"):
        (tmp_path / "quad.gr3").write_text(SAMPLE.replace("1 3 1 2 6 !", "1 4 1 2 6 3 !"))
        read_gr3(tmp_path / "quad.gr3")
    truncated = "\n".join(SAMPLE.splitlines()[:12])
    (tmp_path / "cut.gr3").write_text(truncated)
    with pytest.raises(MeshFormatError, match="file ends early"):
        read_gr3(tmp_path / "cut.gr3")
    with pytest.raises(MeshFormatError, match="2D triangle"):
        write_gr3(tmp_path / "tet.gr3", tm.Mesh(np.zeros((4, 3)), np.array([[0, 1, 2, 3]])))


def test_fortran_d_exponents_read_as_e_and_a_title_with_d_is_kept(tmp_path):
    """SCHISM's Fortran reads 1.0D+01 too; "'1.0D+01' is not a number" was raised."""
    fortran = (
        SAMPLE.replace("hgrid.gr3 ! alphanumeric", "hgrid.gr3 ! DEM 1.0D+01 m, dredged; alphanumeric")
        .replace("1 0.0 0.0 10.0 !", "1 0.0D0 0.0 1.0D+01 !")
        .replace("3 2.0 2.0 5.0", "3 2.0d0 2.0D+00 5.0d0")
        .replace("5 0.8 0.8 1.0", "5 8.0D-1 .8d0 1.0D0")
        .replace("7 1.0 1.2 1.0", "7 1.0 1.2D0 1D0")
        .replace("3 1 = Number of nodes for island", "3 1 = D-shaped island")
    )
    path = tmp_path / "hgrid.gr3"
    path.write_text(SAMPLE)
    plain = read_gr3(path)
    path.write_text(fortran)
    mesh = read_gr3(path)
    assert mesh.title == "hgrid.gr3 ! DEM 1.0D+01 m, dredged; alphanumeric description; ignored by code"
    np.testing.assert_array_equal(mesh.points, plain.points)
    np.testing.assert_array_equal(mesh.point_data["depth"], plain.point_data["depth"])
    np.testing.assert_array_equal(mesh.cells, plain.cells)
    for x, y in zip(mesh.boundaries.land, plain.boundaries.land, strict=True):
        np.testing.assert_array_equal(x.nodes, y.nodes)
    write_gr3(tmp_path / "again.gr3", mesh)
    back = read_gr3(tmp_path / "again.gr3")
    assert back.title == mesh.title
    np.testing.assert_array_equal(back.point_data["depth"], plain.point_data["depth"])


def test_rivers_become_open_boundaries_with_a_warning_naming_them(tmp_path):
    """A flux (river) boundary was written as a land segment: a wall, where SCHISM needs an open boundary."""
    points = np.array([[0.0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1]])
    cells = np.array([[0, 1, 4], [0, 4, 5], [1, 2, 3], [1, 3, 4]])
    boundaries = Boundaries(
        open=[OpenBoundary(np.array([0, 1, 2]))],
        land=[
            LandBoundary(np.array([2, 3]), 22),
            LandBoundary(np.array([3, 4, 5]), 20),
            LandBoundary(np.array([5, 0]), 52),
        ],
    )
    path = tmp_path / "river.gr3"
    with pytest.warns(TerrameshWarning, match=r"land boundary 1 \(IBTYPE 22\) as open boundary 2, land boundary 3 "):
        write_gr3(path, tm.Mesh(points, cells, boundaries=boundaries, point_data={"depth": np.ones(len(points))}))
    back = read_gr3(path).boundaries
    assert [b.nodes.tolist() for b in back.open] == [[0, 1, 2], [2, 3], [5, 0]]
    assert [(b.nodes.tolist(), b.ibtype) for b in back.land] == [([3, 4, 5], 0)]


def test_hgrid_ll_holds_degrees_converted_from_the_meshs_crs(tmp_path):
    # a UTM mesh written as hgrid.ll kept its metres, and SCHISM read them as degrees
    from pyproj import Transformer

    domain = tm.geometry.Difference(
        [tm.geometry.Rectangle((500e3, 4.6e6), (520e3, 4.61e6)), tm.geometry.Disk((510e3, 4.605e6), 2e3)]
    )
    mesh = tm.generate_mesh(domain, 1e3, seed=0)
    mesh = tm.coastal.make_boundaries(mesh, bbox=(5e5, 5.3e5, 4.5e6, 4.7e6), open_by="bbox")
    mesh.point_data["depth"] = np.linspace(1.0, 30.0, mesh.n_points)
    mesh.crs = "EPSG:32618"
    mesh.write(tmp_path / "hgrid.ll")
    mesh.write(tmp_path / "hgrid.gr3")
    ll, gr3 = tm.read_mesh(tmp_path / "hgrid.ll"), tm.read_mesh(tmp_path / "hgrid.gr3")
    lon, lat = Transformer.from_crs("EPSG:32618", "EPSG:4326", always_xy=True).transform(*mesh.points.T)
    assert ll.geographic and np.allclose(ll.points, np.column_stack([lon, lat]), atol=1e-7)
    assert np.array_equal(ll.cells, gr3.cells) and np.array_equal(ll.depth, gr3.depth)
    assert [b.nodes.tolist() for b in ll.boundaries.land] == [b.nodes.tolist() for b in gr3.boundaries.land]
    assert np.array_equal(mesh.points, gr3.points) and mesh.crs == "EPSG:32618"  # the mesh is not modified
    # degrees are written as they are; metres without a crs are refused, and nothing is written
    tm.write_mesh(tmp_path / "again.ll", ll)
    assert np.array_equal(tm.read_mesh(tmp_path / "again.ll").points, ll.points)
    bare = tm.Mesh(mesh.points, mesh.cells)
    with pytest.raises(MeshFormatError, match="no crs to convert them from"):
        bare.write(tmp_path / "metres.ll")
    assert not (tmp_path / "metres.ll").exists()


def test_an_open_boundary_all_the_way_round_is_written_as_two_segments(tmp_path, plate_with_hole):
    # a box round islands, open all the way round: one segment from node 1 back to node 1, where SCHISM stops
    # ("Looped open bnd"); its manual asks for two that meet
    domain, _ = plate_with_hole
    mesh = tm.generate_mesh(domain, 0.1, seed=0)
    hole = hole_ring(mesh)
    outer = boundary_ring(mesh, ~np.isin(boundary_edges(mesh.cells)[:, 0], hole)).tolist()
    ring = Boundaries(
        open=[OpenBoundary(np.array([*outer, outer[0]]))], land=[LandBoundary(np.append(hole, hole[0]), 21)]
    )
    path = tmp_path / "hgrid.gr3"
    write_gr3(
        path, tm.Mesh(mesh.points, mesh.cells, point_data={"depth": np.full(mesh.n_points, 10.0)}, boundaries=ring)
    )
    first, second = read_gr3(path).boundaries.open
    assert first.nodes[0] != first.nodes[-1] and second.nodes[0] != second.nodes[-1]
    assert first.nodes[-1] == second.nodes[0] and second.nodes[-1] == first.nodes[0]  # they meet at both ends
    assert sorted({*first.nodes.tolist(), *second.nodes.tolist()}) == sorted(outer)
