import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import MeshValidityError
from terramesh.mesh import topology

square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
two_cells = np.array([[0, 1, 2], [0, 2, 3]])


def test_boundary_loops_turn_counter_clockwise_outside_and_clockwise_around_holes():
    domain = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (2, 1)), tm.geometry.Disk((1.0, 0.5), 0.2)])
    plate = tm.generate_mesh(domain, 0.1, seed=0)
    loops, areas = topology.boundary_loops(plate.points, plate.cells)
    assert len(loops) == 2
    assert np.isclose(areas.max(), 2.0, rtol=1e-2)  # the rectangle
    assert np.isclose(areas.min(), -np.pi * 0.2**2, rtol=5e-2)  # the hole, clockwise
    assert sum(len(loop) for loop in loops) == len(topology.boundary_edges(plate.cells))
    # each loop follows its boundary edges, from its smallest vertex
    for loop in loops:
        assert loop[0] == loop.min()
        edges = set(map(tuple, topology.boundary_edges(plate.cells).tolist()))
        assert all((int(u), int(v)) in edges for u, v in zip(loop, np.roll(loop, -1), strict=True))
    # far from the origin the areas do not cancel (summed about each loop's first vertex)
    _, far = topology.boundary_loops(plate.points + 5e6, plate.cells)
    np.testing.assert_allclose(np.sort(far), np.sort(areas), rtol=1e-6)


def test_boundary_loops_refuse_a_pinched_boundary():
    bowtie = np.array([[0.0, 0], [1, 0], [0.5, 0.5], [0, 1], [1, 1]])
    with pytest.raises(MeshValidityError, match="more than two boundary edges"):
        topology.boundary_loops(bowtie, np.array([[0, 1, 2], [2, 4, 3]]))
    assert topology.boundary_loops(bowtie, np.zeros((0, 3), dtype=np.int64))[0] == []


def test_edges_and_boundary():
    assert topology.unique_edges(two_cells).tolist() == [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]
    boundary = topology.boundary_edges(two_cells)
    assert sorted(map(tuple, boundary.tolist())) == [(0, 1), (1, 2), (2, 3), (3, 0)]
    np.testing.assert_array_equal(topology.boundary_vertex_degree(two_cells, 4), [2, 2, 2, 2])
    assert topology.cell_neighbours(two_cells).tolist() == [[0, 1]]
    np.testing.assert_allclose(topology.signed_areas(square, two_cells), [0.5, 0.5])


def test_mesh_rejects_bad_arrays():
    with pytest.raises(MeshValidityError, match="do not exist"):
        tm.Mesh(square, np.array([[0, 1, 7]]))
    with pytest.raises(MeshValidityError, match="shape"):
        tm.Mesh(square[:, :1], two_cells)
    with pytest.raises(MeshValidityError, match="point_data"):
        tm.Mesh(square, two_cells, point_data={"depth": np.ones(3)})
    for bad in (np.nan, np.inf):
        points = square.copy()
        points[2, 1] = bad
        with pytest.raises(
            MeshValidityError, match="coordinates are NaN or infinite at 1 of 4 points \\(index 2 first\\)"
        ):
            tm.Mesh(points, two_cells)


def _boundary_edges_by_sorting(cells):
    """The definition: directed edges whose unordered pair occurs once among all cells' edges."""
    directed = np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]])
    _, inverse, counts = np.unique(np.sort(directed, axis=1), axis=0, return_inverse=True, return_counts=True)
    return directed[counts[inverse.ravel()] == 1]


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.booleans())
def test_boundary_edges_match_the_sorting_definition(seed, n_cells, degenerate):
    # random cell sets, not meshes: shared, repeated and non-manifold edges, duplicate and flat cells
    rng = np.random.default_rng(seed)
    cells = rng.integers(0, max(3, n_cells // 2), size=(n_cells, 3))
    if not degenerate:
        cells = cells[(cells[:, 0] != cells[:, 1]) & (cells[:, 1] != cells[:, 2]) & (cells[:, 0] != cells[:, 2])]
    if len(cells) > 2:
        cells = np.vstack([cells, cells[:2]])  # duplicates: their edges are no longer lone
    np.testing.assert_array_equal(topology.boundary_edges(cells), _boundary_edges_by_sorting(cells).reshape(-1, 2))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40))
def test_boundary_edges_of_cells_in_a_large_numbering(seed, n_cells):
    # a few cells of a big mesh keep its vertex numbers: up to 10**9 here, which once allocated
    # tables per vertex number (8 GB); the edges are those of the same cells numbered densely
    rng = np.random.default_rng(seed)
    dense = rng.integers(0, max(3, n_cells // 2), size=(n_cells, 3))
    numbers = np.sort(rng.choice(10**9, size=dense.max() + 1, replace=False))
    cells = numbers[dense]
    np.testing.assert_array_equal(topology.boundary_edges(cells), numbers[topology.boundary_edges(dense)])
    np.testing.assert_array_equal(topology.boundary_edges(cells), _boundary_edges_by_sorting(cells).reshape(-1, 2))


def _neighbors_by_sorting(cells):
    """The definition: each edge's slots ``k m + c`` in a stable sort, neighbours in it listing each other."""
    m = len(cells)
    opposite = np.sort(np.concatenate([cells[:, [1, 2]], cells[:, [2, 0]], cells[:, [0, 1]]]), axis=1)
    order = np.lexsort((opposite[:, 1], opposite[:, 0]))  # stable: equal edges in slot order
    pair = np.flatnonzero(np.all(opposite[order[1:]] == opposite[order[:-1]], axis=1))
    table = np.full(3 * m, -1)
    table[order[pair]] = order[pair + 1] % m
    table[order[pair + 1]] = order[pair] % m
    return table.reshape(3, m).T


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.booleans())
def test_cell_neighbor_table_matches_the_sorting_definition(seed, n_cells, large_numbering):
    # random cell sets: edges in three or more cells, repeated and collapsed cells; a big mesh's numbering
    rng = np.random.default_rng(seed)
    cells = rng.integers(0, max(3, n_cells // 2), size=(n_cells, 3))
    if large_numbering:
        cells = np.sort(rng.choice(10**9, size=cells.max() + 1, replace=False))[cells]
    np.testing.assert_array_equal(topology.cell_neighbor_table(cells), _neighbors_by_sorting(cells))


def test_cell_neighbor_table_of_an_edge_in_three_cells():
    # edge 0-1 in cells 0, 1, 2: the first lists the second, each other the one before it
    table = topology.cell_neighbor_table(np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]]))
    assert table[:, 2].tolist() == [1, 0, 1] and np.all(table[:, :2] == -1)
    with pytest.raises(MeshValidityError, match="do not exist"):
        topology.cell_neighbor_table([[0, 1, -1]])
    assert topology.cell_neighbor_table(np.empty((0, 3), dtype=np.int64)).shape == (0, 3)


def test_boundary_edges_of_a_generated_mesh():
    mesh = tm.generate_mesh(tm.geometry.Difference([tm.geometry.Disk((0, 0), 1), tm.geometry.Disk((0.3, 0), 0.3)]), 0.1)
    edges = topology.boundary_edges(mesh.cells)
    np.testing.assert_array_equal(edges, _boundary_edges_by_sorting(mesh.cells))
    assert np.all(np.bincount(edges.ravel()) <= 2) and len(edges) > 60


def test_coincident_points_are_found_among_the_candidates_only():
    points = np.array([[0.0, 0.0], [1.0, 1.0], [0.0, 0.0], [2.0, 2.0], [1.0, 1.0], [0.0, 0.0], [2.0, 2.0]])
    candidates = np.array([True, True, True, True, True, True, False])
    # the lowest number of each spot stays (a fixed point is numbered first); point 6 is no candidate
    assert topology.coincident_points(points, candidates).tolist() == [2, 4, 5]
    assert topology.coincident_points(points[[5, 0, 2]], np.ones(3, dtype=bool)).tolist() == [1, 2]
    assert topology.coincident_points(points, np.zeros(7, dtype=bool)).tolist() == []
    assert topology.coincident_points(points).tolist() == [2, 4, 5, 6]  # every point a candidate
    later, twins = topology.coincident_points(points, candidates, return_twins=True)
    assert later.tolist() == [2, 4, 5] and twins.tolist() == [0, 1, 0]  # each with the lowest candidate there


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**16), st.integers(0, 400), st.sampled_from([1, 2, 3]), st.integers(1, 6))
def test_coincident_points_are_the_later_twins_a_sort_finds(seed, count, dim, spots):
    """The hash table against a lexicographic sort: -0.0 equal to 0.0, equal in x and y but not in z apart."""
    rng = np.random.default_rng(seed)
    points = rng.integers(-spots, spots + 1, (count, dim)).astype(float)
    points[rng.random(points.shape) < 0.3] *= -1.0  # -0.0 among the zeros
    candidates = rng.random(count) < 0.8
    index = np.flatnonzero(candidates)
    at = points[index]
    order = np.lexsort((index, *at.T[::-1]))
    same = np.all(at[order[1:]] == at[order[:-1]], axis=1)
    expected = np.sort(index[order[1:][same]])
    np.testing.assert_array_equal(topology.coincident_points(points, candidates), expected)
    later, twins = topology.coincident_points(points, candidates, return_twins=True)
    np.testing.assert_array_equal(later, expected)
    lowest = np.array([index[np.all(at == points[i], axis=1)].min() for i in later], dtype=np.int64)
    np.testing.assert_array_equal(twins, lowest)


@pytest.mark.parametrize(
    "call, message",
    [
        # past the last point: the numba kernels read (and crashed on) memory they do not own
        (lambda: topology.signed_areas(square, [[0, 1, 10**9]]), "do not exist"),
        (lambda: topology.signed_areas(square, [[0, 1, 4]]), "do not exist"),
        (lambda: topology.signed_areas(square, [[0, 1, -1]]), "do not exist"),
        (lambda: topology.boundary_edges([[0, 1, -5]]), "do not exist"),
        (lambda: topology.signed_areas(square, [[0.0, 1.0, 2.0]]), "integer"),
        (lambda: topology.boundary_edges([[0.0, 1.0, 2.0]]), "integer"),
        (lambda: topology.signed_areas(square, [[0, 1, 2, 3]]), r"shape \(m, 3\)"),
        (lambda: topology.boundary_edges([[0, 1, 2, 3]]), r"shape \(m, 3\)"),  # was reshaped into triangles
        (lambda: topology.signed_areas(square[:, :1], [[0, 1, 2]]), r"shape \(n, 2\)"),
        (lambda: topology.cell_centroids(square, [[0, 1, 10**5]]), "do not exist"),
        (lambda: topology.cell_centroids(square, [[0, 1.7, 2]]), "integer"),
    ],
)
def test_malformed_cells_raise_before_reaching_a_kernel(call, message):
    with pytest.raises(MeshValidityError, match=message):
        call()


def test_cell_centroids_are_the_corners_mean_for_triangles_and_tetrahedra():
    rng = np.random.default_rng(0)
    for dim in (2, 3):
        points = rng.normal(size=(40, dim))
        cells = rng.integers(0, 40, (25, dim + 1)).astype(np.int32)  # any integer dtype
        assert np.allclose(topology.cell_centroids(points, cells), points[cells].mean(axis=1), rtol=0, atol=1e-15)
    assert topology.cell_centroids(square, np.empty((0, 3), dtype=np.int64)).shape == (0, 2)


def test_no_cells_stay_no_cells():
    assert topology.boundary_edges([]).shape == (0, 2)
    assert topology.boundary_edges(np.empty((0, 3), dtype=np.int64)).shape == (0, 2)
    assert topology.signed_areas(square, np.empty((0, 3), dtype=np.int32)).shape == (0,)


def test_mesh_refuses_tetrahedra_in_the_plane():
    with pytest.raises(MeshValidityError, match=r"4 corners need 3-D points.*\(m, dim \+ 1\)"):
        tm.Mesh(square, np.array([[0, 1, 2, 3]]))  # summary() then failed with NumPy's ValueError
    assert tm.Mesh(np.eye(3), np.array([[0, 1, 2]])).dim == 3  # a surface in 3-D (read from a file) stays allowed


@settings(max_examples=60, deadline=None)
@given(
    st.integers(1, 300),
    st.sampled_from([(), (2,), (3,), (2, 2)]),
    st.sampled_from([np.float64, np.int64]),
    st.data(),
)
def test_without_rows_is_numpys_row_delete(n, trailing, dtype, data):
    """Rows go by index, as np.delete(axis=0) takes them: repeats and order do not matter."""
    array = np.arange(n * int(np.prod(trailing, dtype=int)), dtype=dtype).reshape(n, *trailing)
    indices = data.draw(st.lists(st.integers(0, n - 1), max_size=min(n, 20)))
    expected = np.delete(array, indices, axis=0)
    got = topology.without_rows(array, indices)
    assert got.dtype == array.dtype and got.shape == expected.shape
    np.testing.assert_array_equal(got, expected)
    columns = np.asfortranarray(array)  # not C-contiguous: the same rows
    np.testing.assert_array_equal(topology.without_rows(columns, indices), expected)


@settings(max_examples=200, deadline=None)
@given(
    values=st.lists(st.integers(-(2**62), 2**62), max_size=60) | st.lists(st.integers(0, 5), max_size=60),
    columns=st.sampled_from([1, 2, 3]),
)
def test_sorted_unique_is_numpys_unique(values, columns):
    # NumPy 2.3+ hashes for a plain np.unique: 8x slower on a mesh's edge keys; the sort must give the same
    values = np.array(values[: len(values) // columns * columns], dtype=np.int64).reshape(-1, columns)
    assert np.array_equal(topology.sorted_unique(values), np.unique(values))
    assert topology.sorted_unique(values).dtype == np.unique(values).dtype


@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.sampled_from([5, 40, 2**22]))
@settings(max_examples=60, deadline=None)
def test_boundary_faces_are_the_faces_of_one_cell_each(seed, n_cells, n_points):
    """As counted face by face; the packed keys (below 2**21 vertices) and the three-key sort (above) alike."""
    from collections import Counter

    rng = np.random.default_rng(seed)
    cells = np.array([rng.choice(n_points, 4, replace=False) for _ in range(n_cells)])
    counts = Counter(tuple(sorted(np.delete(cell, k))) for cell in cells.tolist() for k in range(4))
    expected = sorted(face for face, count in counts.items() if count == 1)
    assert topology.boundary_faces(cells).tolist() == [list(face) for face in expected]
