import warnings
from collections import deque

import numpy as np
import pytest

import terramesh as tm
from terramesh.cleanup import (
    RepairReport,
    cell_components,
    delete_disjoint_parts,
    delete_interior_cells,
    fix_mesh,
    merge_duplicate_points,
    mesh_problems,
    remove_duplicate_cells,
    remove_overlapping_cells,
)
from terramesh.errors import MeshValidityError, TerrameshWarning
from terramesh.generation import delaunay
from terramesh.io import Boundaries, LandBoundary
from terramesh.mesh.topology import boundary_vertex_degree, cell_neighbours, signed_areas

LAGOON = tm.geometry.Rectangle((0, 0), (4, 2))


def barrier_islands(width=0.02):
    """Three barrier islands thinner than the 0.1 elements, in a 4 x 2 lagoon."""
    islands = [
        tm.geometry.Polygon(np.array([[0.3, y], [1.0 + 0.1 * k, y - width], [3.7, y + 0.05], [2.0, y + width]]))
        for k, y in enumerate([0.5, 1.0, 1.5])
    ]
    return tm.geometry.Difference([LAGOON, *islands])


def raw_barrier_triangulation():
    """The generator's points triangulated again, kept by centroid, *without* the generator's repair.

    Cells straddle the islands where they are thinner than an element, so
    vertices on both shores get four boundary edges (guide §4.3, Figure 2).
    """
    domain = barrier_islands()
    points = tm.generate_mesh(domain, 0.1, seed=0).points
    cells = delaunay(points)
    cells = cells[domain.distance(points[cells].mean(axis=1)) < 0]
    return domain, points, cells


@pytest.fixture(scope="module")
def barrier_case():
    return raw_barrier_triangulation()


@pytest.fixture(scope="module")
def lake_case():
    """A lagoon and a small lake joined to it by nothing."""
    domain = tm.geometry.Union([LAGOON, tm.geometry.Disk((5, 1), 0.15)])
    return tm.generate_mesh(domain, 0.1, seed=0)


def test_barrier_islands_make_every_boundary_vertex_traversable(barrier_case):
    domain, points, cells = barrier_case
    before = (points.copy(), cells.copy())
    degree = boundary_vertex_degree(cells, len(points))
    assert np.sum(degree > 2) >= 3  # the case the rule is for
    assert any("exactly two boundary edges" in p for p in mesh_problems(tm.Mesh(points, cells)))

    mesh = fix_mesh(points, cells)

    assert mesh_problems(mesh, domain) == []
    np.testing.assert_array_equal(boundary_vertex_degree(mesh.cells, mesh.n_points) % 2, 0)
    assert set(np.unique(boundary_vertex_degree(mesh.cells, mesh.n_points))) <= {0, 2}
    report = mesh.info["repair"]
    assert report.interior_cells >= 1
    # few cells go: the repair deletes around the offending vertices only
    assert report.interior_cells + report.disjoint_cells <= 0.02 * len(cells)
    # no vertex moved; every kept cell is an input cell
    assert {tuple(p) for p in mesh.points.tolist()} <= {tuple(p) for p in points.tolist()}
    np.testing.assert_array_equal(before[0], points)
    np.testing.assert_array_equal(before[1], cells)


def test_interior_deletion_alone_matches_the_guide_rule(barrier_case):
    _, points, cells = barrier_case
    cells = tm.cleanup.orient_cells(points, tm.cleanup.remove_degenerate_cells(points, cells))
    kept = delete_interior_cells(points, cells)
    assert np.all(np.isin(boundary_vertex_degree(kept, len(points)), [0, 2]))
    # deletions stay where the input was broken: each deleted cell has a vertex in the cells at an offending vertex
    offending = boundary_vertex_degree(cells, len(points)) > 2
    near = np.zeros(len(points), dtype=bool)
    near[cells[np.any(offending[cells], axis=1)].ravel()] = True
    gone = cells[~np.isin(_keys(cells), _keys(kept))]
    assert 1 <= len(gone) < 3 * offending.sum()
    assert np.all(np.any(near[gone], axis=1))


def _keys(cells):
    ordered = np.sort(cells, axis=1)
    return ordered[:, 0] * 10**12 + ordered[:, 1] * 10**6 + ordered[:, 2]


def test_small_detached_lake_is_deleted_by_default_and_kept_on_request(lake_case):
    lake = lake_case
    labels = cell_components(lake.cells)[1]
    sizes = np.bincount(labels)
    assert len(sizes) == 2 and sizes.min() < 0.01 * lake.n_cells

    mesh = fix_mesh(lake)
    report = mesh.info["repair"]
    assert (report.disjoint_parts, report.disjoint_cells) == (1, sizes.min())
    assert mesh.n_cells == sizes.max()
    assert np.all(mesh.points[:, 0] <= 4 + 1e-6)  # what is left is the lagoon
    assert mesh_problems(mesh) == []

    kept = fix_mesh(lake, dj_cutoff=0.001)
    assert kept.n_cells == lake.n_cells and kept.info["repair"].disjoint_parts == 0
    assert fix_mesh(lake, disjoint_cutoff=0).n_cells == lake.n_cells
    # by area the lake is ~0.9 % of the water: kept at 0.5 %, deleted at 1 %
    assert fix_mesh(lake, disjoint_cutoff=0.005, by="area").n_cells == lake.n_cells
    assert fix_mesh(lake, disjoint_cutoff=0.01, by="area").n_cells == sizes.max()


def test_cutoff_one_keeps_only_the_largest_part(lake_case):
    two_lagoons = tm.geometry.Union([LAGOON, tm.geometry.Rectangle((5, 0), (8, 2))])
    mesh = tm.generate_mesh(two_lagoons, 0.2, seed=0)
    assert cell_components(mesh.cells)[0] == 2
    assert fix_mesh(mesh).n_cells == mesh.n_cells  # both well above 1 %
    largest = fix_mesh(mesh, disjoint_cutoff=1.0)
    assert largest.info["repair"].disjoint_parts == 1
    assert cell_components(largest.cells)[0] == 1


def bfs_components(cells):
    """Reference: the guide's breadth-first 'spider search' over cells sharing an edge."""
    neighbours = [[] for _ in range(len(cells))]
    for a, b in cell_neighbours(cells):
        neighbours[a].append(b)
        neighbours[b].append(a)
    labels = np.full(len(cells), -1)
    part = 0
    for start in range(len(cells)):
        if labels[start] >= 0:
            continue
        labels[start] = part
        queue = deque([start])
        while queue:
            for other in neighbours[queue.popleft()]:
                if labels[other] < 0:
                    labels[other] = part
                    queue.append(other)
        part += 1
    return part, labels


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_components_agree_with_a_breadth_first_search(seed, barrier_case):
    _, points, cells = barrier_case
    rng = np.random.default_rng(seed)
    some = cells[rng.random(len(cells)) < 0.55]  # a random subset falls apart into many parts
    n_parts, labels = cell_components(some)
    ref_parts, ref_labels = bfs_components(some)
    assert n_parts == ref_parts > 5
    # the same partition: labels map one to one
    pairs = np.unique(np.column_stack([labels, ref_labels]), axis=0)
    assert len(pairs) == n_parts
    kept = delete_disjoint_parts(points, some, cutoff=0.05)
    sizes = np.bincount(labels)
    expected = sizes[labels] >= 0.05 * len(some)
    expected[labels == np.argmax(sizes)] = True
    np.testing.assert_array_equal(kept, some[expected])


def square_with_defects():
    """Unit square in 4 cells around a centre, with the defects fixmesh handles."""
    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [1, 0], [7, 7], [2, 0], [3, 0]])
    cells = np.array(
        [
            [0, 1, 4],
            [5, 2, 4],  # uses the duplicate of vertex 1
            [2, 4, 3],  # clockwise
            [3, 0, 4],
            [4, 0, 1],  # the first cell again, rotated
            [0, 7, 8],  # flat: three collinear vertices
            [2, 2, 3],  # repeated corner
        ]
    )
    return points, cells


def test_fixmesh_steps_are_counted_and_inputs_untouched():
    points, cells = square_with_defects()
    depth = np.arange(len(points), dtype=float)
    mesh = tm.Mesh(points, cells, point_data={"depth": depth})
    before = (points.copy(), cells.copy(), depth.copy())
    # vertex 5 duplicates vertex 1, both in use, with another depth: vertex 1's is kept, with a warning
    with pytest.warns(TerrameshWarning, match=r"point data differ \(depth\) at 1 vertices"):
        fixed = fix_mesh(mesh)
    assert mesh_problems(fixed) == []
    assert (fixed.n_points, fixed.n_cells) == (5, 4)
    report = fixed.info["repair"]
    assert report == RepairReport(
        merged_points=1, unused_points=3, duplicate_cells=2, reoriented_cells=1, degenerate_cells=1
    )
    assert "merged points: 1" in str(report)
    assert report.as_dict()["degenerate_cells"] == 1
    np.testing.assert_array_equal(fixed.point_data["depth"], [0, 1, 2, 3, 4])  # follows the kept vertices
    assert signed_areas(fixed.points, fixed.cells).sum() == pytest.approx(1.0)
    for original, now in zip(before, (points, cells, depth), strict=True):
        np.testing.assert_array_equal(original, now)
    np.testing.assert_array_equal(mesh.cells, cells)


def test_valid_mesh_is_returned_unchanged_with_its_boundaries(lake_case):
    mesh = tm.generate_mesh(LAGOON, 0.25, seed=0)
    boundaries = Boundaries(land=[LandBoundary(np.array([0, 1]), 20)])
    mesh = tm.Mesh(mesh.points, mesh.cells, boundaries=boundaries, crs="EPSG:32615")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fixed = fix_mesh(mesh)
    np.testing.assert_array_equal(fixed.points, mesh.points)
    np.testing.assert_array_equal(fixed.cells, mesh.cells)
    assert fixed.boundaries is boundaries and fixed.crs == "EPSG:32615"
    assert str(fixed.info["repair"]) == "no change"
    with pytest.warns(TerrameshWarning, match="boundaries are dropped"):
        changed = fix_mesh(tm.Mesh(lake_case.points, lake_case.cells, boundaries=boundaries))
    assert changed.boundaries is None


def test_merge_snaps_near_duplicates_and_keeps_order():
    points = np.array([[0.0, 0], [1, 0], [0, 1], [1 + 1e-15, 0], [0.5, 0.5]])
    merged, cells, kept = merge_duplicate_points(points, np.array([[0, 3, 2], [1, 4, 2]]))
    np.testing.assert_array_equal(kept, [0, 1, 2, 4])
    np.testing.assert_array_equal(cells, [[0, 1, 2], [1, 3, 2]])
    _, _, exact = merge_duplicate_points(points, np.array([[0, 3, 2]]), tolerance=0)
    assert len(exact) == 5


def test_duplicate_and_overlapping_cells():
    assert remove_duplicate_cells(np.array([[0, 1, 2], [1, 2, 0], [3, 4, 5]])).tolist() == [[0, 1, 2], [3, 4, 5]]
    # three cells on one edge, two on the same side: the poorer of those two goes
    points = np.array([[0.0, 0], [1, 0], [0.5, 0.9], [0.5, 0.2], [0.5, -0.8]])
    cells = np.array([[0, 1, 2], [0, 1, 3], [1, 0, 4]])
    # each cell is a part of its own (the edge in three cells joins none): the smallest gives way, with a warning
    with pytest.warns(TerrameshWarning, match="1 cells with 10.53% of the cells' total area"):
        kept = remove_overlapping_cells(points, cells)
    assert kept.tolist() == [[0, 1, 2], [1, 0, 4]]
    assert mesh_problems(tm.Mesh(points, kept)) == ["1 vertices are not used by any cell"]
    with pytest.warns(TerrameshWarning, match="overlapped a larger part"):
        assert fix_mesh(points, cells).info["repair"].overlapping_cells == 1


def test_bad_input_and_hopeless_meshes_raise():
    points, cells = square_with_defects()
    with pytest.raises(MeshValidityError, match="NaN"):
        fix_mesh(np.where(points == 7, np.nan, points), cells)
    with pytest.raises(MeshValidityError, match=r"shape \(n, 2\)"):
        fix_mesh(points[:, :1], cells)
    with pytest.raises(MeshValidityError, match="do not exist"):
        fix_mesh(points, cells + 5)
    with pytest.raises(MeshValidityError, match="not both"):
        fix_mesh(points, cells, disjoint_cutoff=0.1, dj_cutoff=0.2)
    with pytest.raises(MeshValidityError, match="between 0 and 1"):
        fix_mesh(points, cells, disjoint_cutoff=5)
    with pytest.raises(MeshValidityError, match="by must be"):
        delete_disjoint_parts(points, cells[:4], by="volume")
    with pytest.raises(MeshValidityError, match="left no cell"):
        fix_mesh(points, np.array([[0, 7, 8]]))  # only a flat cell


def cut_squares(n, origin, size, flip=False):
    """A square of n x n squares, each cut in two along a diagonal (the other diagonal with ``flip``)."""
    g = np.linspace(0.0, size, n + 1)
    points = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2) + np.asarray(origin)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), indexing="ij"))
    a = i * (n + 1) + j  # corner (i, j); then (i + 1, j), (i + 1, j + 1), (i, j + 1)
    b, c, d = a + n + 1, a + n + 2, a + 1
    cells = np.column_stack([a, b, d, b, c, d] if flip else [a, b, c, a, c, d]).reshape(-1, 3)
    return points, cells


def concatenated(*parts):
    offsets = np.cumsum([0] + [len(points) for points, _ in parts[:-1]])
    cells = [part_cells + offset for (_, part_cells), offset in zip(parts, offsets, strict=True)]
    return np.vstack([points for points, _ in parts]), np.vstack(cells)


def cell_corners(points, cells):
    """Each cell as its sorted corner coordinates: the same cell whatever the vertex numbers."""
    return {tuple(sorted(map(tuple, np.round(points[cell], 12).tolist()))) for cell in cells}


def test_a_smaller_part_laid_over_a_larger_gives_way_whole():
    # 10 x 10 cut squares and 4 x 4 cut the other way over one corner: once the 25 shared vertices merge, the 32
    # small cells run the big square's grid edges in the same direction. Deciding pair by pair on quality (all
    # equal) dropped 16 of the big square's cells and all 32 small: 14 % of the square was left as holes, silently.
    big = cut_squares(10, (0.0, 0.0), 1.0)
    points, cells = concatenated(big, cut_squares(4, (0.6, 0.6), 0.4, flip=True))
    with pytest.warns(TerrameshWarning, match=r"32 cells with 13.79% of the cells' total area \(0.16\) overlapped"):
        fixed = fix_mesh(points, cells)
    assert mesh_problems(fixed) == []
    assert cell_corners(fixed.points, fixed.cells) == cell_corners(*big)
    assert signed_areas(fixed.points, fixed.cells).sum() == pytest.approx(1.0)
    assert fixed.info["repair"].overlapping_cells == 32


def test_of_two_parts_of_one_area_the_first_stays_whole():
    # the same cut squares shifted by half: ties broken by quality pair by pair had left holes in both
    first = cut_squares(10, (0.0, 0.0), 1.0)
    points, cells = concatenated(first, cut_squares(10, (0.5, 0.5), 1.0, flip=True))
    with pytest.warns(TerrameshWarning, match="50 cells"):
        fixed = fix_mesh(points, cells)
    assert mesh_problems(fixed) == []
    assert cell_corners(*first) <= cell_corners(fixed.points, fixed.cells)
    # the second part's cells outside the first stay, joined to it at the shared vertices: the union is covered
    assert signed_areas(fixed.points, fixed.cells).sum() == pytest.approx(1.75)


SQUARE = tm.geometry.Rectangle((0, 0), (1, 1))


@pytest.mark.parametrize(
    ("other", "dropped", "area"),
    [
        (tm.geometry.Rectangle((0.5, 0.5), (1.0, 1.0)), 65, 1.0),  # in a corner, two vertices on the square's
        (tm.geometry.Disk((0.5, 0.5), 0.2), 113, 1.0),  # wholly inside, nothing shared
        # across a corner: the cells over the square go, the rest stays beside it (the union is 1.33)
        (tm.geometry.Rectangle((0.6, 0.6), (1.3, 1.3)), 50, 1.2831),
    ],
)
def test_fix_mesh_drops_the_cells_of_a_smaller_mesh_laid_over_a_larger(other, dropped, area):
    # every cell counter-clockwise and each mesh conforming on its own: fix_mesh raised "could not make the mesh
    # valid: ... cells overlap"
    square = tm.generate_mesh(SQUARE, 0.1, seed=0)
    smaller = tm.generate_mesh(other, 0.05 if isinstance(other, tm.geometry.Disk) else 0.1, seed=0)
    points, cells = concatenated((square.points, square.cells), (smaller.points, smaller.cells))
    with pytest.warns(TerrameshWarning, match=f"{dropped} cells with .* overlapped a larger part"):
        fixed = fix_mesh(points, cells)
    assert mesh_problems(fixed) == []
    assert fixed.n_cells == len(cells) - dropped
    assert cell_corners(square.points, square.cells) <= cell_corners(fixed.points, fixed.cells)
    assert signed_areas(fixed.points, fixed.cells).sum() == pytest.approx(area, abs=1e-4)


@pytest.mark.parametrize("turn", [False, True])
def test_remove_overlapping_cells_reads_clockwise_cells_turned(turn):
    # the rules read directions along edges: with both meshes clockwise, 86 cells went, not the smaller one's 113
    square = tm.generate_mesh(SQUARE, 0.1, seed=0)
    disk = tm.generate_mesh(tm.geometry.Disk((0.5, 0.5), 0.2), 0.05, seed=0)
    points, cells = concatenated((square.points, square.cells), (disk.points, disk.cells))
    cells = cells[:, ::-1] if turn else cells
    with pytest.warns(TerrameshWarning, match="113 cells with"):
        kept = remove_overlapping_cells(points, cells)
    np.testing.assert_array_equal(kept, cells[: square.n_cells])  # the square's cells as given, the disk's gone
