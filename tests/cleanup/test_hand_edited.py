"""fix_mesh, clean and mesh_problems on meshes edited by hand or made by other tools."""

import warnings

import numpy as np
import pytest

import terramesh as tm
from terramesh.cleanup import clean, fix_mesh, mesh_problems, remove_overlapping_cells
from terramesh.cleanup.validity import hanging_on_boundary, hanging_vertices, near_seam_vertices
from terramesh.errors import MeshValidityError, TerrameshWarning
from terramesh.io import Boundaries
from terramesh.mesh.topology import boundary_edges, signed_areas


def grid(nx, ny, origin=(0.0, 0.0), step=1.0):
    """A structured grid of ``nx`` by ``ny`` nodes, each square cut along its rising diagonal."""
    xs, ys = np.meshgrid(origin[0] + step * np.arange(nx), origin[1] + step * np.arange(ny))
    points = np.column_stack([xs.ravel(), ys.ravel()])
    j, i = np.mgrid[0 : ny - 1, 0 : nx - 1]
    a = (j * nx + i).ravel()
    b, c = a + 1, a + nx
    return points, np.concatenate([np.column_stack([a, b, c + 1]), np.column_stack([a, c + 1, c])])


def covered_twice(points, cells):
    """Area covered by more than one cell: the cells' total area less their union's (shapely)."""
    import shapely

    triangles = shapely.polygons(points[cells])
    return float(np.sum(shapely.area(triangles)) - shapely.area(shapely.union_all(triangles)))


def quiet(call, *args, **kwargs):
    """``call(*args, **kwargs)`` with every warning an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return call(*args, **kwargs)


# --- parts touching at one vertex (the overlap test read the boundary as loops before the pinch was mended)


def two_squares_at_a_corner(shared):
    """Two 2 x 2 squares touching at the corner (2, 2): one vertex number, or two at one spot."""
    first, first_cells = grid(3, 3)
    second, second_cells = grid(3, 3, origin=(2.0, 2.0))
    if not shared:
        return np.vstack([first, second]), np.vstack([first_cells, second_cells + len(first)])
    renumber = np.concatenate([[8], len(first) + np.arange(len(second) - 1)])
    return np.vstack([first, second[1:]]), np.vstack([first_cells, renumber[second_cells]])


def triangle_glued_at_a_corner():
    points, cells = grid(6, 5)
    return np.vstack([points, [[-1.0, -0.5], [-0.5, -1.0]]]), np.vstack([cells, [[0, 30, 31]]])


def stray_triangle_over_three_grid_vertices():
    points, cells = grid(6, 5)
    return points, np.vstack([cells, [[0, 2, 12]]])


PINCHED = {
    "shared vertex": lambda: two_squares_at_a_corner(shared=True),
    "duplicated vertex": lambda: two_squares_at_a_corner(shared=False),
    "triangle glued at a corner": triangle_glued_at_a_corner,
    "stray triangle": stray_triangle_over_three_grid_vertices,
}


@pytest.mark.parametrize("case", PINCHED)
def test_fix_mesh_and_clean_mend_parts_touching_at_a_vertex(case):
    points, cells = PINCHED[case]()
    for repair in (fix_mesh, clean):
        if case == "stray triangle":  # it lies over the grid: the smaller part gives way, with a warning
            with pytest.warns(TerrameshWarning, match="overlapped a larger part"):
                fixed = repair(tm.Mesh(points, cells))
        elif case.endswith("vertex"):  # two of the 16 cells go: more of the area than goes unsaid
            with pytest.warns(TerrameshWarning, match=r"removed 12 % of the mesh's area \(2 cells deleted at 1"):
                fixed = repair(tm.Mesh(points, cells))
        else:
            fixed = quiet(repair, tm.Mesh(points, cells))
        assert mesh_problems(fixed) == []
        assert covered_twice(fixed.points, fixed.cells) == pytest.approx(0.0, abs=1e-9)
    if case == "stray triangle":  # the grid stays whole
        assert fixed.n_cells == len(cells) - 1


def test_remove_overlapping_cells_compares_parts_that_touch_at_a_vertex_cell_by_cell():
    points, cells = two_squares_at_a_corner(shared=True)
    np.testing.assert_array_equal(quiet(remove_overlapping_cells, points, cells), cells)  # nothing overlaps
    points, cells = stray_triangle_over_three_grid_vertices()
    with pytest.warns(TerrameshWarning, match="1 cells with"):
        kept = remove_overlapping_cells(points, cells)
    np.testing.assert_array_equal(kept, cells[:-1])


# --- a fold: one interior node dragged past its neighbour


def folded_grid(shift=(150.0, 40.0), node=24):
    """A 7 x 7 grid of 100 m squares at UTM offsets with one node dragged: two cells turn over."""
    points, cells = grid(7, 7, origin=(5e5, 4e6), step=100.0)
    dragged = points.copy()
    dragged[node] += shift
    return points, dragged, cells


def test_mesh_problems_finds_the_ground_a_fold_covers_twice():
    """What fix_mesh returned before: the turned-over cells dropped, 3000 m^2 covered twice, called valid."""
    _, points, cells = folded_grid()
    kept = cells[signed_areas(points, cells) > 0]
    assert covered_twice(points, kept) == pytest.approx(3000.0)
    problems = mesh_problems(tm.Mesh(points, kept))
    assert len(problems) == 1 and "cells overlap: next to 1 boundary loops" in problems[0]
    assert "near (500" in problems[0]  # where
    # turned over instead of dropped: the cells no longer fit edge to edge
    turned = np.where((signed_areas(points, cells) < 0)[:, None], cells[:, ::-1], cells)
    assert any("same orientation" in p for p in mesh_problems(tm.Mesh(points, turned)))


@pytest.mark.parametrize("shift", [(150.0, 40.0), (260.0, 10.0), (-170.0, -30.0), (40.0, 210.0)])
def test_fix_mesh_moves_a_dragged_node_back_among_its_neighbours(shift):
    original, points, cells = folded_grid(shift)
    depth = np.arange(len(points), dtype=float)
    with pytest.warns(TerrameshWarning, match="moved 1 vertices that a fold had carried past their neighbours"):
        fixed = fix_mesh(tm.Mesh(points, cells, point_data={"depth": depth}))
    assert fixed.info["repair"] == tm.cleanup.RepairReport(untangled_points=1)
    np.testing.assert_array_equal(fixed.cells, cells)
    np.testing.assert_allclose(fixed.points, original, atol=1e-6)  # the mean of its grid neighbours
    np.testing.assert_array_equal(fixed.depth, depth)
    assert mesh_problems(fixed) == []
    assert covered_twice(fixed.points, fixed.cells) == pytest.approx(0.0, abs=1e-6)


def test_fix_mesh_untangles_two_neighbours_dragged_together_and_a_clockwise_listing():
    original, points, cells = folded_grid()
    points[25] += [140.0, -20.0]  # its neighbour too: no one node untangles the cells
    with pytest.warns(TerrameshWarning, match="fold had carried"):
        fixed = fix_mesh(points, cells)
    assert mesh_problems(fixed) == [] and fixed.n_cells == len(cells)
    assert covered_twice(fixed.points, fixed.cells) == pytest.approx(0.0, abs=1e-6)
    _, points, cells = folded_grid()
    with pytest.warns(TerrameshWarning, match="fold had carried"):
        fixed = fix_mesh(points, cells[:, ::-1])  # every cell listed clockwise: the fold's cells are the others
    assert fixed.info["repair"].untangled_points == 1 and fixed.info["repair"].reoriented_cells == len(cells)
    np.testing.assert_allclose(fixed.points, original, atol=1e-6)


@pytest.mark.parametrize("island", [False, True])
def test_fix_mesh_never_returns_a_fold_it_cannot_untangle(island):
    """A boundary node dragged inward: no neighbours' mean to go to; the result would cover ground twice.

    With a second part (an island 2 km off), fix_mesh looks the two parts
    over for overlaps and does not look again at the end: the fold must be
    found in that first look.
    """
    _, points, cells = folded_grid((0.0, 160.0), node=3)
    if island:
        far, far_cells = grid(7, 7, origin=(5.02e5, 4e6), step=100.0)
        points, cells = np.vstack([points, far]), np.vstack([cells, far_cells + len(points)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(MeshValidityError, match=r"could not make the mesh valid: .*overlap.*near \(5003"):
            fix_mesh(points, cells)
    assert any("2 cells are folded over their neighbours" in str(w.message) for w in caught)


# --- duplicate nodes, one unused


def test_a_merged_node_keeps_the_data_of_the_node_a_cell_uses():
    """A leftover node no cell uses (depth -99) lies on a node in use (depth 10): the merged node has 10."""
    points, cells = grid(4, 4, origin=(5e5, 4e6), step=100.0)
    points = np.vstack([points[:1], points])
    depth = np.concatenate([[-99.0], np.full(16, 10.0)])
    fixed = quiet(fix_mesh, tm.Mesh(points, cells + 1, point_data={"depth": depth}))  # no data differ in use
    np.testing.assert_array_equal(fixed.depth, np.full(16, 10.0))
    np.testing.assert_array_equal(fixed.points, points[1:])
    assert fixed.info["repair"] == tm.cleanup.RepairReport(merged_points=1)
    # by tolerance too, and in merge_duplicate_points
    nudged = points.copy()
    nudged[0] += 1e-3
    fixed = quiet(fix_mesh, tm.Mesh(nudged, cells + 1, point_data={"depth": depth}), merge_tolerance=0.01)
    np.testing.assert_array_equal(fixed.depth, np.full(16, 10.0))
    np.testing.assert_array_equal(fixed.points, points[1:])
    _, _, kept = tm.cleanup.merge_duplicate_points(nudged, cells + 1, tolerance=0.01)
    np.testing.assert_array_equal(kept, np.arange(1, 17))


def test_merged_nodes_in_use_with_other_data_draw_a_warning_that_counts_them():
    points, cells = two_squares_at_a_corner(shared=False)
    depth = np.arange(len(points), dtype=float)
    with warnings.catch_warnings(record=True) as caught:  # and one for the two cells it deletes at the corner
        warnings.simplefilter("always")
        fixed = fix_mesh(tm.Mesh(points, cells, point_data={"depth": depth}))
    said = [str(warning.message) for warning in caught if "point data differ" in str(warning.message)]
    assert len(said) == 1 and "point data differ (depth) at 1 vertices" in said[0]
    assert 8.0 in fixed.depth and 9.0 not in fixed.depth  # vertex 8 (in use) before vertex 9 at its spot


def test_boundaries_are_dropped_with_a_warning_only_when_there_were_some():
    """A fort.14 with an empty boundary section: nothing is dropped, so nothing to warn of."""
    points, cells = grid(3, 3)
    points, cells = np.vstack([points, points[4:5]]), np.where(cells == 4, 9, cells)  # node 4 unused, 9 on it
    none = tm.Mesh(points, cells, boundaries=Boundaries())
    fixed = quiet(fix_mesh, none)
    assert fixed.info["repair"] == tm.cleanup.RepairReport(merged_points=1)
    assert fixed.boundaries is none.boundaries
    land = Boundaries(land=[tm.io.LandBoundary(np.array([0, 1, 2]), 20)])
    with pytest.warns(TerrameshWarning, match="its boundaries are dropped"):
        assert fix_mesh(tm.Mesh(points, cells, boundaries=land)).boundaries is None


# --- seams that nearly join


def near_seam(gap):
    """Two 5 x 10 grids of 100 m squares, the right one's seam nodes ``gap`` m off the left one's."""
    left, left_cells = grid(6, 11, origin=(512345.6789, 4123456.789), step=100.0)
    right, right_cells = grid(6, 11, origin=(512845.6789 + gap, 4123456.789), step=100.0)
    return np.vstack([left, right]), np.vstack([left_cells, right_cells + len(left)])


def test_a_seam_that_did_not_merge_draws_a_warning_naming_merge_tolerance():
    points, cells = near_seam(4.5e-4)
    assert mesh_problems(tm.Mesh(points, cells)) == []  # valid: two parts side by side
    first, second, distance = near_seam_vertices(points, cells)
    assert len(first) == 11 and np.all(second - first == 61) and distance.max() < 5e-4
    with pytest.warns(TerrameshWarning, match=r"11 pairs of boundary vertices .* merge_tolerance=\.\.\.\) above"):
        fixed = fix_mesh(points, cells)
    assert fixed.n_points == len(points)  # not merged beyond the tolerance
    with pytest.warns(TerrameshWarning, match="11 pairs of boundary vertices"):
        clean(points, cells)
    assert quiet(fix_mesh, points, cells, merge_tolerance=0.01).n_points == len(points) - 11
    # a gap of a fifth of an edge is a channel, not a seam
    points, cells = near_seam(20.0)
    assert len(near_seam_vertices(points, cells)[0]) == 0
    quiet(fix_mesh, points, cells)


# --- tetrahedra and surfaces


def test_fix_mesh_and_clean_say_they_repair_2d_triangle_meshes_only():
    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    tetrahedra = tm.Mesh(cube, [[0, 1, 3, 4], [1, 2, 3, 6], [1, 4, 5, 6], [3, 6, 7, 4], [1, 3, 4, 6]])
    surface = tm.Mesh(cube, [[0, 1, 2], [0, 2, 3]])
    for repair in (fix_mesh, clean):
        for mesh in (tetrahedra, surface):
            with pytest.raises(MeshValidityError, match=f"{repair.__name__} repairs 2-D triangle meshes only"):
                repair(mesh)


def test_valid_meshes_with_islands_pass_without_a_word():
    """The winding test reads one point beside each loop: islands, a lake on an island, parts side by side."""
    points, cells = grid(21, 21)
    centroids = points[cells].mean(axis=1)
    ring = np.abs(np.max(np.abs(centroids - 10.0), axis=1) - 5.0) < 1.0  # a square annulus of water removed
    pieces = cells[~ring]
    mesh = tm.Mesh(*tm.cleanup.remove_unused_points(points, pieces)[:2])
    assert len(boundary_edges(mesh.cells)) > 80
    assert quiet(mesh_problems, mesh) == []
    fixed = quiet(fix_mesh, mesh, disjoint_cutoff=0)
    np.testing.assert_array_equal(fixed.cells, mesh.cells)


# --- blocks meshed apart and put side by side: seams with nodes that do not match


def blocks(right_origin_y, merge_shared=False):
    """A 4 x 4 block of unit squares and, on its right, a 2 x 4 block of squares of 2 starting at ``right_origin_y``."""
    left, left_cells = grid(5, 5)
    right, right_cells = grid(2, 3, origin=(4.0, right_origin_y), step=2.0)
    return np.vstack([left, right]), np.vstack([left_cells, right_cells + len(left)])


def test_hanging_nodes_are_named_and_warned_of():
    # seam nodes y = 0..4 against 0.5, 2.5, 4.5: no node shared, every seam node on the other block's edge
    points, cells = blocks(0.5)
    mesh = tm.Mesh(points, cells)
    problems = mesh_problems(mesh)
    assert len(problems) == 1 and problems[0].startswith("6 hanging nodes") and "(4, 1)" in problems[0]
    with pytest.raises(MeshValidityError, match="6 hanging nodes"):
        tm.cleanup.check_mesh(mesh)
    for repair in (fix_mesh, clean):
        with pytest.warns(TerrameshWarning, match=r"6 boundary vertices lie on another boundary edge.*hanging"):
            repaired = repair(mesh)
        assert repaired.n_cells == len(cells)  # nothing to delete, nothing joined
    assert mesh_problems(mesh, hanging_nodes=False) == []


def test_each_hanging_node_comes_with_its_edge_and_the_edge_back_along_it():
    points, cells = blocks(0.5)
    edges = boundary_edges(cells)
    vertex, host, back = hanging_on_boundary(points, edges)
    assert vertex.tolist() == hanging_vertices(points, cells)[0].tolist()
    assert len(vertex) == 6 and (points[vertex, 0] == 4).all()  # the seam's nodes
    assert (edges[host] != vertex[:, None]).all()  # on its host edge's inside, not at an end
    assert (edges[back] == vertex[:, None]).any(axis=1).all()
    host_along, back_along = (points[edges[rows, 1]] - points[edges[rows, 0]] for rows in (host, back))
    assert (np.einsum("ij,ij->i", host_along, back_along) < 0).all()  # the way back
    assert (host_along[:, 0] == 0).all() and (back_along[:, 0] == 0).all()  # both along the seam x = 4


def test_a_vertex_with_one_boundary_edge_is_found_whatever_the_last_edge():
    # vertices 2 and 3 on edge 0 -> 1, 3 with no edge out: the missing one (-1) read the last row, and a
    # last edge running back along the host overwrote the find
    points = np.array([[0.0, 0], [1, 0], [0.8, 0], [0.5, 0], [5, 5], [4, 5]])
    for last in ([4, 5], [5, 4]):
        vertex, host, back = hanging_on_boundary(points, np.array([[0, 1], [2, 3], last]))
        assert (vertex.tolist(), host.tolist(), back.tolist()) == ([2, 3], [0, 0], [1, 1])


def test_parts_touching_at_a_point_have_no_hanging_node():
    # a triangle's tip on the middle of a square's side: the banks leave each other, as where a strait pinches
    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [1, 0.5], [2, 0], [2, 1]])
    mesh = tm.Mesh(points, [[0, 1, 2], [0, 2, 3], [4, 5, 6]])
    assert quiet(mesh_problems, mesh) == []
    assert quiet(fix_mesh, mesh).n_cells == 3


def test_fix_mesh_warns_of_the_area_it_deletes_where_parts_touch():
    # the shared seam nodes (4, 0), (4, 2), (4, 4) merge; (4, 1) and (4, 3) hang: 4 cells, 27 % of the area, go
    points, cells = blocks(0.0)
    with pytest.warns(TerrameshWarning) as caught:
        fixed = fix_mesh(points, cells)
    messages = [str(warning.message) for warning in caught]
    assert any(
        message.startswith("fix_mesh removed 27 % of the mesh's area (4 cells deleted at 3 boundary vertices")
        for message in messages
    ), messages
    assert fixed.info["repair"].interior_cells == 4
    assert signed_areas(fixed.points, fixed.cells).sum() == pytest.approx(17.5)


def test_fixed_points_follow_a_merged_duplicate_to_the_vertex_at_their_place():
    points, cells = grid(5, 5)
    n = len(points)
    twin = np.vstack([points, points[12]])  # (2, 2) twice: the copy used by every other cell around it
    split = cells.copy()
    half = (split == 12).any(axis=1) & (np.arange(len(split)) % 2 == 0)
    split[half] = np.where(split[half] == 12, n, split[half])
    fixed = quiet(fix_mesh, tm.Mesh(twin, split, info={"fixed_points": np.array([n, 12, -1])}))
    index = fixed.info["fixed_points"]
    assert index[2] == -1
    np.testing.assert_array_equal(fixed.points[index[:2]], [[2.0, 2.0], [2.0, 2.0]])
    # a fixed point whose vertex its cells leave is -1, with a warning
    stray = np.vstack([points, [[20.0, 20], [21, 20], [20, 21]]])
    mesh = tm.Mesh(stray, np.vstack([cells, [[n, n + 1, n + 2]]]), info={"fixed_points": np.array([12, n])})
    with pytest.warns(TerrameshWarning, match=r"fix_mesh removed 1 of the 2 fixed points.*\(20, 20\)"):
        fixed = fix_mesh(mesh, disjoint_cutoff=0.5)
    assert fixed.info["fixed_points"][1] == -1
    np.testing.assert_array_equal(fixed.points[fixed.info["fixed_points"][0]], [2.0, 2.0])


def test_a_zero_area_cell_is_degenerate_even_at_min_quality_zero():
    points, cells = grid(5, 5)
    flat = np.vstack([cells, [[0, 1, 2]]])  # along the bottom edge
    fixed = quiet(fix_mesh, points, flat, min_quality=0)
    report = fixed.info["repair"]
    assert (report.degenerate_cells, report.overlapping_cells) == (1, 0)
    np.testing.assert_array_equal(fixed.cells, cells)


@pytest.mark.parametrize("fixed", [[0, 10**6], [0.5], [[1, 2]], [-2]])
def test_fixed_points_that_are_no_vertex_numbers_are_refused_by_name(fixed):
    # 10**6 was a bare IndexError in the renumbering, and 0.5 was taken as vertex 0
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.2, seed=0)
    mesh.info["fixed_points"] = np.array(fixed)
    with pytest.raises(MeshValidityError, match=r"info\['fixed_points'\] must be a 1-D array of vertex numbers 0\.\."):
        fix_mesh(mesh)
