"""mesh_problems on tetrahedral meshes: each rule broken on its own, on a real generated mesh."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh._kernels.cleanup import facet_census
from terramesh.cleanup import check_mesh, mesh_problems
from terramesh.cleanup.validity import cells_outside
from terramesh.errors import MeshValidityError

# two tetrahedra on either side of the face (0, 1, 2)
TWO = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.3, 0.3, -1]])
TWO_CELLS = np.array([[0, 1, 2, 3], [0, 2, 1, 4]])


@pytest.fixture(scope="module")
def ball():
    domain = tm.geometry.Ball((0, 0, 0), 1)
    return domain, tm.generate_mesh(domain, 0.25, seed=0)


def test_a_generated_mesh_and_two_tetrahedra_are_valid(ball):
    domain, mesh = ball
    assert mesh_problems(mesh, domain, boundary_tolerance=1e-6) == []
    assert mesh_problems(tm.Mesh(TWO, TWO_CELLS)) == []


def test_each_broken_rule_is_named(ball):
    domain, mesh = ball
    points, cells = mesh.points, mesh.cells
    cases = {
        "inverted or have zero volume": tm.Mesh(points, np.vstack([cells[1:], cells[:1, [1, 0, 2, 3]]])),
        "duplicate cells": tm.Mesh(points, np.vstack([cells, cells[:1, [1, 0, 3, 2]]])),  # listed otherwise
        "not used by any cell": tm.Mesh(np.vstack([points, [[5.0, 5, 5]]]), cells),
        # the fifth vertex moved to the same side of the shared face as the first cell's apex
        "both their cells on one side": tm.Mesh(np.vstack([TWO[:4], [[0.2, 0.2, 0.5]]]), [[0, 1, 2, 3], [0, 1, 2, 4]]),
        "more than two cells": tm.Mesh(np.vstack([TWO, [[0.3, 0.3, 2.0]]]), np.vstack([TWO_CELLS, [[0, 1, 2, 5]]])),
        # one vertex shared by two cells and nothing else: the boundary pinches there
        "boundary is not manifold": tm.Mesh(
            np.vstack([TWO[:4], [[-1.0, 0, 0], [0, -1, 0], [0, 0, -1]]]), [[0, 1, 2, 3], [0, 5, 4, 6]]
        ),
    }
    for phrase, broken in cases.items():
        problems = mesh_problems(broken)
        assert any(phrase in problem for problem in problems), (phrase, problems)
    # a face in three cells also leaves boundary edges on more than two boundary faces
    assert any("boundary edges" in p for p in mesh_problems(cases["more than two cells"]))
    with pytest.raises(MeshValidityError, match="invalid mesh: .*inverted"):
        check_mesh(cases["inverted or have zero volume"])


def test_duplicate_vertices_differing_in_z_only_are_found():
    # sorted by x and y alone, (0, 0, 2) came between (0, 0, 1) and its twin
    points = np.vstack([TWO, [[0.0, 0, 1], [0.0, 0, 2]]])
    problems = mesh_problems(tm.Mesh(points, np.vstack([TWO_CELLS, [[0, 1, 2, 5]]])))
    assert "1 duplicate vertices" in problems
    assert tm.mesh.topology.coincident_points(np.array([[0, 0, 1.0], [0, 0, 2.0], [0, 0, 1.0]])).tolist() == [2]


def test_the_domain_rules_apply_to_tetrahedra(ball):
    domain, mesh = ball
    smaller = tm.geometry.Ball((0, 0, 0), 0.9)
    problems = mesh_problems(mesh, smaller, boundary_tolerance=1e-6)
    assert any("centroid outside" in p for p in problems)
    assert any("off the domain boundary" in p for p in problems)


def test_a_surface_of_triangles_is_refused():
    surface = tm.Mesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]])
    with pytest.raises(MeshValidityError, match="triangles with 3D points"):
        mesh_problems(surface)


WATER = tm.geometry.Rectangle((-3, -3), (3, 3)) - tm.geometry.Disk((0, 0), 1)  # a round island of radius 1
GAP = tm.geometry.Rectangle((-2, -2), (2, 0)) | tm.geometry.Rectangle((-2, 0.1), (2, 2))  # two banks 0.1 apart


@pytest.mark.parametrize(
    ("domain", "corners", "outside"),
    [
        # two corners on the island 30 degrees either side of the x axis, the third 0.1 off it:
        # the centroid is 0.048 inside the island, the chord's middle 0.12
        (WATER, [[np.cos(0.5), np.sin(0.5)], [np.cos(0.5), -np.sin(0.5)], [1.1, 0.0]], False),
        # the third corner farther round the island than the chord: the centroid farther in than its middle
        (WATER, [[np.cos(0.5), np.sin(0.5)], [np.cos(0.5), -np.sin(0.5)], [0.95, 0.0]], True),
        # a chord of 120 degrees: the normals at its ends 120 degrees apart, no chord of a resolved boundary
        (WATER, [[np.cos(1.05), np.sin(1.05)], [np.cos(1.05), -np.sin(1.05)], [0.6, 0.0]], True),
        # across the gap: corners on its two banks (opposite normals), the centroid in the gap
        (GAP, [[0.0, 0.0], [1.0, 0.1], [0.5, -0.05]], True),
    ],
)
def test_cells_outside_excuses_chords_of_a_curved_boundary_only(domain, corners, outside):
    points = np.array(corners)
    cell = np.array([[0, 1, 2]]) if signed_area(points) > 0 else np.array([[1, 0, 2]])
    assert domain.distance(points[cell[0]].mean(axis=0)[None])[0] > 0
    assert cells_outside(domain, points, cell, np.array([True, True, False])).tolist() == [outside]
    # a cell with all its corners on the boundary is never excused
    assert cells_outside(domain, points, cell, np.ones(3, dtype=bool)).tolist() == [True]


def signed_area(points):
    (ax, ay), (bx, by), (cx, cy) = points
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


def test_cells_lying_over_each_other_are_found_when_asked():
    # two squares laid across each other, and a disk inside a square: every cell counter-clockwise, every
    # edge in at most two cells, and 14 % of the area covered twice passed every rule
    square = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.1, seed=0)
    for other, message in (
        (
            tm.generate_mesh(tm.geometry.Rectangle((0.5, 0.5), (1.5, 1.5)), 0.1, seed=0),
            "boundary edges cross: cells overlap by",
        ),
        (tm.generate_mesh(tm.geometry.Disk((0.5, 0.5), 0.2), 0.05, seed=0), "the mesh lies over itself"),
    ):
        stacked = tm.Mesh(
            np.vstack([square.points, other.points]), np.vstack([square.cells, other.cells + square.n_points])
        )
        assert mesh_problems(stacked, overlaps=False) == []  # the topology alone
        problems = mesh_problems(stacked)
        assert len(problems) == 1 and message in problems[0]
    apart = tm.generate_mesh(tm.geometry.Disk((3.0, 0.5), 0.4), 0.1, seed=0)
    side_by_side = tm.Mesh(
        np.vstack([square.points, apart.points]), np.vstack([square.cells, apart.cells + square.n_points])
    )
    plate = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)) - tm.geometry.Disk((1, 0.5), 0.2), 0.05)
    assert mesh_problems(side_by_side, overlaps=True) == [] and mesh_problems(plate, overlaps=True) == []


def test_smoothing_does_not_slide_a_vertex_onto_the_far_bank_of_a_strait(shared_data):
    # the Croatian coast at 0.12 degrees: a boundary vertex slid across a strait narrower than a cell and
    # two boundary edges crossed (cells over each other, all counter-clockwise)
    shore = tm.coastal.Shoreline.read(shared_data / "coast" / "ne_10m_land.shp", (13.5, 17.5, 42.5, 45.5), 3e3)
    domain = tm.geometry.Polygon.from_shapely(shore.water)
    mesh = tm.generate_mesh(domain, 0.1206, seed=0)
    assert mesh_problems(mesh, domain, overlaps=True) == []


# the unit cube cut into six positive tetrahedra around its diagonal from corner 0 to corner 7 (corner k at the
# bits of k: x = k >> 2, y = (k >> 1) & 1, z = k & 1)
KUHN = np.array([[0, 1, 3, 7], [0, 3, 2, 7], [0, 2, 6, 7], [0, 6, 4, 7], [0, 4, 5, 7], [0, 5, 1, 7]])


def cube_of_tetrahedra(n, origin=(0.0, 0.0, 0.0), size=1.0):
    """A cube of n**3 small cubes, each cut into six tetrahedra the same way: a conforming, positive mesh."""
    g = np.arange(n + 1)
    points = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3) * (size / n) + np.asarray(origin)
    i, j, k = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij"))
    corner = [((i + (c >> 2)) * (n + 1) + j + ((c >> 1) & 1)) * (n + 1) + k + (c & 1) for c in range(8)]
    cells = np.stack(corner, axis=1)[:, KUHN].reshape(-1, 4)
    volume = tm.quality.tetra.tetra_volumes(points, cells)
    return points, np.where((volume < 0)[:, None], cells[:, [1, 0, 2, 3]], cells)


def two_parts(first, second):
    (p, c), (q, d) = first, second
    return tm.Mesh(np.vstack([p, q]), np.vstack([c, d + len(p)]))


def test_a_cube_of_tetrahedra_is_valid_and_so_are_two_cubes_side_by_side():
    points, cells = cube_of_tetrahedra(3)
    assert tm.quality.tetra.tetra_volumes(points, cells).sum() == pytest.approx(1.0)
    assert mesh_problems(tm.Mesh(points, cells)) == []
    # touching along part of a face, no vertex shared: boundary edges lie in the other's boundary face, not through it
    beside = two_parts((points, cells), cube_of_tetrahedra(2, origin=(1.0, 0.25, 0.25)))
    assert mesh_problems(beside) == []


@pytest.mark.parametrize(
    ("second", "message"),
    [
        # wholly inside: no boundary face crosses another, the space inside the small cube is filled twice
        (cube_of_tetrahedra(2, origin=(0.3, 0.3, 0.3), size=0.4), "next to 48 boundary faces the mesh lies in itself"),
        # across a corner: the boundaries pass through each other
        (cube_of_tetrahedra(2, origin=(0.8, 0.75, 0.7), size=0.5), "boundary edges pass through boundary faces"),
    ],
)
def test_tetrahedra_lying_in_each_other_are_found_when_asked(second, message):
    # every cell positive, every face in at most two cells on its two sides, a closed manifold boundary: the
    # rules of the cells alone passed both
    stacked = two_parts(cube_of_tetrahedra(3), second)
    assert mesh_problems(stacked, overlaps=False) == []
    problems = mesh_problems(stacked)
    assert len(problems) == 1 and message in problems[0] and "cells overlap" in problems[0]
    with pytest.raises(MeshValidityError, match="cells overlap"):
        check_mesh(stacked)


def test_a_boundary_tolerance_needs_a_domain():
    # without a domain no vertex was measured and any mesh passed
    with pytest.raises(MeshValidityError, match="give the domain"):
        mesh_problems(tm.Mesh(TWO, TWO_CELLS), boundary_tolerance=1e-6)


def test_a_cell_flat_to_a_rounding_is_flat():
    # three vertices a rounding off one line: a positive area of 1e-18 passed as a valid cell
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1e-17], [0.5, 1.0]])
    cells = np.array([[0, 1, 2], [0, 2, 3], [2, 1, 3]])
    assert tm.mesh.topology.signed_areas(points, cells[:1])[0] > 0
    assert "1 cells are clockwise or have zero area" in tm.cleanup.mesh_problems(tm.Mesh(points, cells))
    long = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1e-3]])  # 1,000 times longer than high: a cell
    assert tm.cleanup.mesh_problems(tm.Mesh(long, [[0, 1, 2]])) == []


def test_an_anisotropic_mesh_at_a_thousand_to_one_has_no_flat_cells():
    square = tm.geometry.Rectangle((0, 0), (1, 1))
    mesh = tm.generate_anisotropic_mesh(square, tm.sizing.metric_tensor(1.0, 0.001, 0.4), seed=0)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.quality.triangle_quality(mesh.points, mesh.cells).min() > 1e-6  # five cells of area 1e-18


def _pairs_by_shapely(points, edges, among):
    """The meeting pairs as shapely's ``intersects`` finds them, sorted (the reference of crossing_edges)."""
    import shapely

    segments = shapely.linestrings(points[edges])
    queries = np.arange(len(edges)) if among is None else np.asarray(among, dtype=np.int64)
    found, second = shapely.STRtree(segments).query(segments[queries], predicate="intersects")
    first = queries[found]
    apart = ~np.any(edges[first][:, :, None] == edges[second][:, None, :], axis=(1, 2))
    apart &= (first < second) if among is None else (first != second)
    return _sorted_pairs(first[apart], second[apart])


def _sorted_pairs(first, second):
    return sorted(zip(first.tolist(), second.tolist(), strict=True))


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_crossing_edges_are_shapely_intersects_away_from_shared_vertices(data):
    # exact turns on a bucket grid replaced shapely's segments and tree (0.15 s for 50k boundary edges);
    # lattices give the touching, collinear and zero-length cases, the offset ones inexact coordinates
    from terramesh.cleanup.validity import crossing_edges

    n = data.draw(st.integers(2, 14))
    kind = data.draw(st.sampled_from(["lattice", "float", "offset"]))
    if kind == "float":
        points = np.array(data.draw(st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1)), min_size=n, max_size=n)))
    else:
        cells = np.array(data.draw(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3)), min_size=n, max_size=n)))
        points = cells.astype(float) if kind == "lattice" else 1e6 + 0.1 * cells
    edges = np.array(
        data.draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), min_size=1, max_size=25))
    )
    among = data.draw(st.none() | st.lists(st.integers(0, len(edges) - 1), max_size=6))
    among = None if among is None else np.array(among, dtype=np.int64)
    first, second = crossing_edges(points, edges, among)
    assert _sorted_pairs(first, second) == _pairs_by_shapely(points, edges, among)
    if among is None:
        assert np.all(first < second)
    else:  # query by query, in the order given (an edge given twice, twice)
        per_slot = [np.sum(first == q) // np.sum(among == q) for q in among]
        assert np.array_equal(first, np.repeat(among, per_slot))


def test_crossing_edges_of_a_jagged_coast_laid_over_itself():
    # a coast-like boundary of 569 edges: none cross; its vertices shaken, those that do are shapely's
    from terramesh.cleanup.validity import crossing_edges
    from terramesh.mesh.topology import boundary_edges

    rng = np.random.default_rng(3)
    angle = np.linspace(0, 2 * np.pi, 600, endpoint=False)
    radius = 1 + 0.4 * np.cumsum(rng.normal(size=600)) / np.sqrt(600)
    radius -= np.linspace(0, 1, 600) * (radius[-1] - radius[0])
    coast = tm.geometry.Polygon(np.column_stack([radius * np.cos(angle), radius * np.sin(angle)]))
    mesh = tm.generate_mesh(coast, 0.02, seed=0)
    edges = boundary_edges(mesh.cells)
    assert len(edges) > 500 and crossing_edges(mesh.points, edges)[0].size == 0
    points = mesh.points.copy()
    ends = np.unique(edges)
    points[ends] += rng.normal(scale=0.01, size=(len(ends), 2))
    first, second = crossing_edges(points, edges)
    assert len(first) > 10 and _sorted_pairs(first, second) == _pairs_by_shapely(points, edges, None)
    among = np.arange(0, len(edges), 7)
    first, _ = crossing_edges(points, edges, among)
    assert np.all(np.isin(first, among)) and np.all(np.diff(np.searchsorted(among, first)) >= 0)


def test_crossing_edges_refuse_indices_out_of_range():
    # the kernel reads without bounds checks: an index past the arrays crashed the process or gave garbage pairs
    from terramesh.cleanup.validity import crossing_edges

    points = np.random.default_rng(5).random((120, 2))
    edges = np.arange(120).reshape(-1, 2)
    for among in ([60], [-61], [10**6]):
        with pytest.raises(IndexError, match="among names edges outside -60 .. 59"):
            crossing_edges(points, edges, np.array(among))
    bad = edges.copy()
    bad[0, 0] = 10**6
    with pytest.raises(IndexError, match="edges name vertices outside 0 .. 119"):
        crossing_edges(points, bad)
    # a negative index counts from the end, as NumPy's (and is given back as it came)
    assert crossing_edges(points, edges, np.array([-1]))[1].tolist() == crossing_edges(points, edges, [59])[1].tolist()


def _vertices_on_edges_by_brute_force(points, edges, share):
    """Every (edge, end of another edge) pair on it, by testing all of them, sorted."""
    vertices = np.unique(edges)
    edge, vertex = (grid.ravel() for grid in np.meshgrid(np.arange(len(edges)), vertices, indexing="ij"))
    start, along = points[edges[edge, 0]], points[edges[edge, 1]] - points[edges[edge, 0]]
    offset = points[vertex] - start
    squared = np.maximum(np.sum(along**2, axis=1), np.finfo(np.float64).tiny)
    position = np.einsum("ij,ij->i", offset, along) / squared
    side = np.abs(along[:, 0] * offset[:, 1] - along[:, 1] * offset[:, 0]) / squared
    on = (position > share) & (position < 1 - share) & (side <= share)
    on &= (vertex != edges[edge, 0]) & (vertex != edges[edge, 1])
    return _sorted_pairs(edge[on], vertex[on])


@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_vertices_on_edges_are_every_end_within_the_share(data):
    # the hanging-node test's candidates on a bucket grid (KD-trees took 7 ms for a coast's 7,000 edges):
    # lattices put ends exactly on edges and at their ends, the jittered ones within or past the share
    from terramesh.cleanup.validity import vertices_on_other_edges

    n = data.draw(st.integers(2, 14))
    cells = np.array(data.draw(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4)), min_size=n, max_size=n)))
    jitter = data.draw(st.sampled_from([0.0, 1e-4, 1e-2]))
    points = cells + jitter * np.random.default_rng(data.draw(st.integers(0, 9))).normal(size=cells.shape)
    points = points * data.draw(st.sampled_from([1.0, 1e-5, 1e5]))
    edges = np.array(
        data.draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), min_size=1, max_size=25))
    )
    share = data.draw(st.sampled_from([1e-3, 0.05]))
    edge, vertex = vertices_on_other_edges(points, edges, share)
    assert _sorted_pairs(edge, vertex) == _vertices_on_edges_by_brute_force(points, edges, share)
    assert len(set(zip(edge.tolist(), vertex.tolist(), strict=True))) == len(edge)  # each pair once
    assert np.array_equal(np.lexsort((vertex, edge)), np.arange(len(edge)))  # by edge, then vertex: one host


def test_a_vertex_beside_an_edge_across_a_cell_border_is_on_it():
    # the grid's cells are 4 wide from y = -4: the edge at y = -1e-6 and the vertex at y = 0 (its own edge
    # running up from it) fall in different rows of cells, and the edge looks one share of its length past its box
    from terramesh.cleanup.validity import vertices_on_other_edges

    points = np.array([[0.0, -4], [4, -4], [0, -1e-6], [4, -1e-6], [2, 0], [2, 4]])
    edge, vertex = vertices_on_other_edges(points, np.array([[0, 1], [2, 3], [4, 5]]), 1e-3)
    assert _sorted_pairs(edge, vertex) == [(1, 4)]


def test_hanging_nodes_refuse_vertex_numbers_out_of_range():
    # the kernel writes without bounds checks: a vertex number of 1e11 crashed the process
    from terramesh.cleanup.validity import hanging_on_boundary, hanging_vertices

    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    for cells in ([[0, 1, 2], [0, 2, 100_000_000_000]], [[0, 1, 2], [0, 2, 4]]):
        with pytest.raises(IndexError, match=r"edges name vertices outside 0 .. 3 \(of 4 points\)"):
            hanging_vertices(points, np.array(cells))
    with pytest.raises(IndexError, match="outside 0 .. 3"):
        hanging_on_boundary(points, np.array([[0, 1], [1, -1]]))


def test_vertices_on_edges_where_a_grid_does_not_serve():
    # 1,500 short edges on a lattice crowding one cell beside two edges 2e4 long: KD-trees answer, as the grid would
    from terramesh.cleanup.validity import vertices_on_other_edges

    rng = np.random.default_rng(1)
    points = np.vstack([0.01 * rng.integers(0, 10, size=(1_500, 2)), [[-1e4, -1], [1e4, -1], [0.5, -1], [0.5, 1e4]]])
    edges = np.vstack([rng.integers(0, 1_500, size=(1_500, 2)), [[1_500, 1_501], [1_502, 1_503]]])
    edge, vertex = vertices_on_other_edges(points, edges, 1e-3)
    assert len(edge) > 1_000 and (1_500, 1_502) in _sorted_pairs(edge, vertex)
    assert _sorted_pairs(edge, vertex) == _vertices_on_edges_by_brute_force(points, edges, 1e-3)
    assert np.array_equal(np.lexsort((vertex, edge)), np.arange(len(edge)))  # in the kernel's order


def test_crossing_edges_where_a_grid_does_not_serve():
    # 20k tiny edges in a 1 x 0.001 strip beside 4 edges 2e4 long: the grid's cells held thousands each (15 s);
    # coordinates 2e308 apart overflowed its extent
    from terramesh.cleanup.validity import crossing_edges

    rng = np.random.default_rng(0)
    chain = np.c_[np.sort(rng.random(20_000)), 0.001 * rng.random(20_000)]
    points = np.vstack([chain, [[-1e4, -1], [1e4, -1], [1e4, 1], [-1e4, 1]]])
    square = 20_000 + np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    edges = np.vstack([np.c_[np.arange(19_999), np.arange(1, 20_000)], square])
    first, second = crossing_edges(points, edges)
    assert _sorted_pairs(first, second) == _pairs_by_shapely(points, edges, None)
    far = np.array([[-1e308, 0.0], [1e308, 0.0], [0.0, -1.0], [0.0, 1.0]])
    assert _sorted_pairs(*crossing_edges(far, np.array([[0, 1], [2, 3]]))) == [(0, 1)]


def _census_by_sorting(points, cells):
    """:func:`facet_census` by sorting every facet: lone mask, facets in > 2 cells, one-sided pairs, repeated cells."""
    corners = cells.shape[1]
    facets = np.sort(np.concatenate([np.delete(cells, k, axis=1) for k in range(corners)]), axis=1)
    far = cells.T.ravel()
    _, inverse, counts = np.unique(facets, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    pairs = np.flatnonzero(counts == 2)
    first = np.array([np.flatnonzero(inverse == p) for p in pairs], dtype=np.int64).reshape(-1, 2)
    a, b = points[facets[first[:, 0], 0]], points[facets[first[:, 0], 1]]
    if corners == 4:
        normal = np.cross(b - a, points[facets[first[:, 0], 2]] - a)
        sides = [np.einsum("ij,ij->i", points[far[first[:, s]]] - a, normal) for s in range(2)]
    else:
        u, w = b - a, [points[far[first[:, s]]] - a for s in range(2)]
        sides = [u[:, 0] * w[s][:, 1] - u[:, 1] * w[s][:, 0] for s in range(2)]
    repeated = len(np.unique(np.sort(cells, axis=1), axis=0)) < len(cells)
    return counts[inverse] == 1, int(np.sum(counts > 2)), int(np.sum(sides[0] * sides[1] >= 0)), repeated


@settings(max_examples=200, deadline=None)
@given(st.integers(3, 4), st.data())
def test_facet_census_matches_sorting(corners, data):
    # a few vertices at small whole coordinates (exact sides): repeated corners and cells, facets in many cells
    dim = corners - 1
    points = data.draw(st.lists(st.integers(-3, 3), min_size=6 * dim, max_size=6 * dim))
    points = np.array(points, dtype=np.float64).reshape(6, dim)
    cells = data.draw(st.lists(st.lists(st.integers(0, 5), min_size=corners, max_size=corners), max_size=12))
    cells = np.array(cells, dtype=np.int64).reshape(-1, corners)
    lone, n_crowded, n_one_sided, repeated = facet_census(points, cells)
    expected = _census_by_sorting(points, cells)
    np.testing.assert_array_equal(lone, expected[0])
    assert (n_crowded, n_one_sided, repeated) == expected[1:]


def test_the_census_gives_the_rules_sorting_gave_on_a_generated_mesh(ball):
    _, mesh = ball
    lone, n_crowded, n_one_sided, repeated = facet_census(mesh.points, mesh.cells)
    assert (n_crowded, n_one_sided, repeated) == (0, 0, False)
    np.testing.assert_array_equal(lone, _census_by_sorting(mesh.points, mesh.cells)[0])
    faces = np.sort(np.concatenate([np.delete(mesh.cells, k, axis=1) for k in range(4)])[lone], axis=1)
    np.testing.assert_array_equal(faces[np.lexsort(faces.T[::-1])], tm.mesh.topology.boundary_faces(mesh.cells))
