import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.cleanup import delete_interior_cells, merge_duplicate_points, mesh_problems, remove_unused_points
from terramesh.errors import MeshValidityError


def bowtie():
    """Two triangles touching at one vertex: that vertex has four boundary edges."""
    points = np.array([[0.0, 0], [1, 0], [0.5, 0.5], [0, 1], [1, 1]])
    cells = np.array([[0, 1, 2], [2, 4, 3]])
    return points, cells


def test_problems_are_reported():
    points, cells = bowtie()
    problems = mesh_problems(tm.Mesh(points, cells))
    assert any("exactly two boundary edges" in p for p in problems)
    clockwise = mesh_problems(tm.Mesh(points, cells[:, ::-1]))
    assert any("clockwise" in p for p in clockwise)
    unused = mesh_problems(tm.Mesh(np.vstack([points, [[5, 5]]]), cells))
    assert any("not used" in p for p in unused)


def test_delete_interior_cells_deletes_until_manifold():
    points, cells = bowtie()
    repaired = delete_interior_cells(points, cells)
    assert len(repaired) == 1
    points, repaired, kept = remove_unused_points(points, repaired)
    assert mesh_problems(tm.Mesh(points, repaired)) == []
    assert len(kept) == 3


def test_repair_prefers_the_cell_with_most_boundary_edges():
    # a strip of three triangles plus a pendant triangle hanging off vertex 2;
    # the pendant has the better quality, so only the boundary-edge rule removes it
    points = np.array([[0.0, 0], [1, 0], [2, 0], [0.5, 1], [1.5, 1], [2.5, -0.8], [3, 0]])
    cells = np.array([[0, 1, 3], [1, 4, 3], [1, 2, 4], [2, 5, 6]])
    repaired = delete_interior_cells(points, cells)
    assert [2, 5, 6] not in repaired.tolist()
    assert len(repaired) == 3


def test_duplicate_cells_and_vertices_are_reported():
    points, cells = bowtie()
    doubled = mesh_problems(tm.Mesh(points, np.vstack([cells, cells[:1, [1, 2, 0]]])))
    assert "duplicate cells" in doubled
    twin = mesh_problems(tm.Mesh(np.vstack([points, points[:1]]), np.vstack([cells, [[5, 1, 2]]])))
    assert any("1 duplicate vertices" in p for p in twin)


@settings(deadline=None, max_examples=40)
@given(
    st.integers(1, 30),
    st.lists(st.tuples(st.integers(0, 29), st.integers(0, 29), st.integers(0, 29)), max_size=25),
    st.sampled_from([3, 4]),
)
def test_remove_unused_points_keeps_what_the_cells_use_in_order(n_points, triples, corners):
    points = np.arange(2.0 * n_points).reshape(-1, 2)
    cells = np.array([[v % n_points for v in (t + t[:1])[:corners]] for t in triples], dtype=np.int64)
    cells = cells.reshape(-1, corners)
    kept_points, renumbered, kept = remove_unused_points(points, cells)
    np.testing.assert_array_equal(kept, np.unique(cells))
    np.testing.assert_array_equal(kept_points, points[kept])
    np.testing.assert_array_equal(kept[renumbered], cells)


@settings(deadline=None, max_examples=60)
@given(
    st.lists(
        st.tuples(st.sampled_from([0.0, -0.0, 1.0, 2.5]), st.sampled_from([0.0, -0.0, 3.0])), min_size=1, max_size=40
    ),
    st.data(),
)
def test_merge_duplicate_points_keeps_the_first_of_each_spot_in_order(coordinates, data):
    points = np.array(coordinates)
    n = len(points)
    cells = np.array(data.draw(st.lists(st.tuples(*[st.integers(0, n - 1)] * 3), max_size=20)), dtype=np.int64)
    cells = cells.reshape(-1, 3)
    for tolerance in (0, 1e-3):
        merged, renumbered, kept = merge_duplicate_points(points, cells, tolerance=tolerance)
        # of every spot (-0.0 is 0.0) the first index a cell uses, or the first if no cell uses any; ascending
        spots = [tuple(p) for p in (points + 0.0).tolist()]
        used = set(cells.ravel().tolist())
        ranked = sorted(range(n), key=lambda k: (k not in used, k), reverse=True)
        expected = sorted({spots[k]: k for k in ranked}.values())
        assert kept.tolist() == expected
        np.testing.assert_array_equal(merged, points[kept])
        np.testing.assert_array_equal(merged[renumbered], points[cells] + 0.0)  # every corner at its old spot


def test_remove_unused_points_names_vertex_numbers_out_of_range():
    points, cells = bowtie()
    for bad in (5, -1):
        with pytest.raises(MeshValidityError, match="numbered 0 to 4"):
            remove_unused_points(points, np.vstack([cells, [[0, 1, bad]]]))
    with pytest.raises(MeshValidityError, match="2-D"):
        remove_unused_points(points, cells.ravel())
    empty_points, empty_cells, kept = remove_unused_points(points, [])
    assert empty_points.shape == (0, 2) and empty_cells.shape == (0, 3) and kept.shape == (0,)


def test_merge_tolerance_is_a_distance_not_a_grid():
    """Vertices 0.002 apart on either side of a 0.1 snap grid's line stayed two (two squares not glued)."""
    points = np.array([[0, 0], [1.049, 0], [1.049, 1], [0, 1], [1.051, 0], [2.1, 0], [2.1, 1], [1.051, 1]])
    cells = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    for shift in (0.0, 0.01, 0.037):
        fixed = tm.cleanup.fix_mesh(points + shift, cells, merge_tolerance=0.1, dj_cutoff=0)
        assert fixed.n_points == 6 and fixed.info["repair"].merged_points == 2
    _, _, kept = merge_duplicate_points(points, cells, tolerance=0.001)
    assert len(kept) == 8


@pytest.mark.parametrize(
    "call",
    [
        lambda cells: tm.cleanup.cell_components(cells),
        lambda cells: tm.cleanup.remove_duplicate_cells(cells),
        lambda cells: tm.cleanup.delete_disjoint_parts(np.zeros((3, 2)), cells),
        lambda cells: merge_duplicate_points(np.zeros((3, 2)), cells),
    ],
)
def test_negative_vertex_numbers_are_refused(call):
    # the kernels index without bounds checks: -3 crashed the process (cell_components), -1 wrapped around
    with pytest.raises(MeshValidityError, match="vertices that do not exist"):
        call(np.array([[0, 1, 2], [0, 1, -3]]))


FAN = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [0.8, 0.7]])
FAN_CELLS = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])


@pytest.mark.parametrize(
    ("call", "message"),
    [
        # NaN kept no cell (every comparison false) and a string raised from inside NumPy
        (lambda: tm.cleanup.remove_degenerate_cells(FAN, FAN_CELLS, np.nan), "min_quality must be a number in"),
        (lambda: tm.cleanup.remove_degenerate_cells(FAN, FAN_CELLS, "flat"), "min_quality must be a number in"),
        # vertex 9 of 5 came back in the cells as it went in
        (lambda: tm.cleanup.delete_interior_cells(FAN, np.vstack([FAN_CELLS, [[0, 1, 9]]])), "do not exist"),
        # a ValueError from inside scipy's KD-tree, and a TypeError from comparing a string
        (lambda: merge_duplicate_points(FAN.ravel(), FAN_CELLS), r"points must have shape"),
        (lambda: merge_duplicate_points(FAN, FAN_CELLS, tolerance="close"), "tolerance must be a non-negative"),
    ],
)
def test_bad_input_to_the_steps_is_named(call, message):
    with pytest.raises(MeshValidityError, match=message):
        call()


def test_fixed_points_follow_the_renumbering():
    # info["fixed_points"] was copied as it came: an unused vertex dropped in front shifted it to another vertex
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.2, fixed_points=[[0.5, 0.5]])
    gauge = int(np.flatnonzero(np.all(mesh.points == [0.5, 0.5], axis=1))[0])
    padded = tm.Mesh(
        np.vstack([[9.0, 9.0], mesh.points]), mesh.cells + 1, info={"fixed_points": np.array([gauge + 1, -1])}
    )
    fixed = tm.cleanup.fix_mesh(padded)
    assert fixed.info["repair"].unused_points == 1
    assert fixed.info["fixed_points"][1] == -1
    np.testing.assert_array_equal(fixed.points[fixed.info["fixed_points"][0]], [0.5, 0.5])


def test_cells_naming_huge_vertex_numbers_take_no_table_that_large():
    # one cell naming vertex 10**12 failed to allocate; 3e7 took 3.7 s and 650 MB
    big = 10**12
    cells = np.array([[0, 1, big], [big, 0, 1], [1, 0, big], [big, 1, 2]])
    small = np.where(cells == big, 3, cells)
    kept = tm.cleanup.remove_duplicate_cells(cells)
    np.testing.assert_array_equal(np.where(kept == big, 3, kept), tm.cleanup.remove_duplicate_cells(small))
    n_parts, labels = tm.cleanup.cell_components(cells)
    expected_parts, expected_labels = tm.cleanup.cell_components(small)
    assert n_parts == expected_parts and labels.tolist() == expected_labels.tolist()


def test_remove_unused_points_refuses_fractional_vertex_numbers():
    points, _ = bowtie()
    with pytest.raises(MeshValidityError, match="integer vertex indices"):
        remove_unused_points(points, np.array([[0, 1, 2.7]]))


@pytest.mark.parametrize(
    "call",
    [
        lambda: tm.cleanup.delete_interior_cells(None, None),
        lambda: tm.cleanup.delete_interior_cells(None, [[0, 1, 2]]),
        lambda: tm.cleanup.delete_disjoint_parts(None, [[0, 1, 2]]),
        lambda: tm.cleanup.remove_unused_points(None, [[0, 1, 2]]),
        lambda: tm.cleanup.mesh_problems([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
        lambda: tm.cleanup.check_mesh(None),
    ],
)
def test_helpers_refuse_what_is_not_a_mesh_clearly(call):
    # "object of type 'NoneType' has no len()" and "'list' object has no attribute 'points'" before
    with pytest.raises(MeshValidityError, match="points must be|give a terramesh Mesh"):
        call()


def test_helpers_take_plain_lists():
    # remove_unused_points indexed a list with an array: "only integer scalar arrays can be converted"
    points, cells, kept = tm.cleanup.remove_unused_points([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [5.0, 5.0]], [[0, 1, 2]])
    assert points.shape == (3, 2) and cells.tolist() == [[0, 1, 2]] and kept.tolist() == [0, 1, 2]
    # any number of columns, any dtype, as given (a review: (n, 4) refused and float32 made float64)
    wide = np.arange(16, dtype=np.float32).reshape(4, 4)
    points, _, _ = tm.cleanup.remove_unused_points(wide, [[0, 1, 2]])
    assert points.dtype == np.float32 and points.shape == (3, 4)
    flat = np.column_stack([np.eye(3)[:, :2], np.zeros(3)])  # triangles in the plane z = 0, (n, 3)
    assert tm.cleanup.delete_disjoint_parts(flat, [[0, 1, 2]]).shape == (1, 3)
