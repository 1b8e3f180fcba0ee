import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import terramesh as tm
from terramesh.errors import GeometryError
from terramesh.geometry import GridDomain

rng = np.random.default_rng(0)


def grid(spacing, dim, low=-1.3, high=1.3):
    """Equal axes from ``low`` to ``high`` and their ``indexing="ij"`` node coordinates."""
    x = np.arange(low, high + spacing / 2, spacing)
    return [x] * dim, np.meshgrid(*[x] * dim, indexing="ij")


def sphere_directions(n, dim):
    v = rng.normal(size=(n, dim))
    return v / np.linalg.norm(v, axis=1)[:, None]


def zero_radius(domain, directions, low=0.5, high=1.5):
    """Where the distance changes sign along each ray from the origin, by bisection."""
    lo, hi = np.full(len(directions), low), np.full(len(directions), high)
    for _ in range(45):
        mid = 0.5 * (lo + hi)
        negative = domain.distance(directions * mid[:, None]) < 0
        lo, hi = np.where(negative, mid, lo), np.where(negative, hi, mid)
    return lo


def cell_measure(mesh):
    """Total area (triangles) or volume (tetrahedra)."""
    p, c = mesh.points, mesh.cells
    if c.shape[1] == 3:
        u, v = p[c[:, 1]] - p[c[:, 0]], p[c[:, 2]] - p[c[:, 0]]
        return 0.5 * np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]).sum()
    u, v, w = (p[c[:, k]] - p[c[:, 0]] for k in (1, 2, 3))
    return np.abs(np.einsum("ij,ij->i", np.cross(u, v), w)).sum() / 6


@pytest.mark.parametrize("dim, spacing, bound", [(2, 0.05, 0.02), (3, 0.1, 0.05)])
def test_sampled_distance_matches_the_exact_one_near_the_boundary(dim, spacing, bound):
    axes, nodes = grid(spacing, dim)
    domain = GridDomain(axes, np.sqrt(sum(c**2 for c in nodes)) - 1.0)
    radius = rng.uniform(0.8, 1.2, 5000)
    points = sphere_directions(5000, dim) * radius[:, None]
    distance, exact = domain.distance(points), radius - 1.0
    assert np.abs(distance - exact).max() < bound * spacing
    clear = np.abs(exact) > bound * spacing
    np.testing.assert_array_equal(np.sign(distance[clear]), np.sign(exact[clear]))
    assert domain.dim == dim and domain.lipschitz is False


@pytest.mark.parametrize("smoothing", [0.0, 1.0])
@pytest.mark.parametrize("dim, spacing", [(2, 0.02), (3, 0.1)])
def test_mask_boundary_is_within_half_a_cell(dim, spacing, smoothing):
    axes, nodes = grid(spacing, dim)
    domain = GridDomain.from_mask(axes, sum(c**2 for c in nodes) < 1.0, smoothing=smoothing)
    radius = zero_radius(domain, sphere_directions(2000, dim))
    assert np.abs(radius - 1.0).max() <= 0.5 * spacing * (1 + 1e-6)
    # no systematic shrinking: the mean is far inside the half-cell bound
    assert abs(np.mean(radius - 1.0)) < 0.1 * spacing
    # away from the boundary the distance is the Euclidean one to within a cell
    points = sphere_directions(500, dim) * rng.uniform(0.3, 1.2, 500)[:, None]
    np.testing.assert_allclose(domain.distance(points), np.linalg.norm(points, axis=1) - 1.0, atol=spacing)


def test_mask_signed_distance_is_half_a_cell_at_the_halfway_nodes():
    x = np.linspace(0.0, 1.0, 11)
    inside = np.zeros((11, 11), dtype=bool)
    inside[:6] = True  # the boundary halfway between x = 0.5 and x = 0.6
    domain = GridDomain.from_mask((x, x), inside, smoothing=0)
    points = [(0.55, 0.5), (0.5, 0.5), (0.6, 0.5), (0.45, 0.9), (0.8, 0.0)]
    np.testing.assert_allclose(domain.distance(points), [0, -0.05, 0.05, -0.1, 0.25], atol=1e-12)
    # the filter keeps a flat boundary, up to the grid's edge
    smoothed = GridDomain.from_mask((x, x), inside)
    np.testing.assert_allclose(smoothed.distance(points), [0, -0.05, 0.05, -0.1, 0.25], atol=1e-12)
    # the inside reaches the edge x = 0: the grid's edge cuts it
    np.testing.assert_allclose(domain.distance([(0.0, 0.5), (0.02, 0.5), (-0.1, 0.5)]), [0.0, -0.02, 0.1], atol=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_points_outside_the_grid_are_positive_and_grow_outward(dim):
    axes, nodes = grid(0.1, dim, low=-1.2, high=1.2)
    domain = GridDomain(axes, np.sqrt(sum(c**2 for c in nodes)) - 1.0)
    directions = sphere_directions(200, dim)
    steps = np.linspace(1.25, 20.0, 40)
    distance = np.stack([domain.distance(directions * r) for r in steps])
    assert np.all(distance > 0)
    assert np.all(np.diff(distance, axis=0) > 0)
    # at least the distance to the grid box, at most the distance to the inside of it plus the extra way
    gap = np.stack([np.linalg.norm(directions * r - np.clip(directions * r, -1.2, 1.2), axis=1) for r in steps])
    assert np.all(distance >= gap)
    np.testing.assert_allclose(domain.distance([[5.0] + [0.0] * (dim - 1)]), [4.0], atol=1e-12)


def test_a_shape_cut_by_the_grid_edge_has_its_corners_and_a_tight_bbox():
    x, y = np.linspace(0.0, 1.2, 61), np.linspace(-1.2, 1.2, 121)
    X, Y = np.meshgrid(x, y, indexing="ij")
    half = GridDomain((x, y), np.hypot(X, Y) - 1.0)  # the disk about (0, 0), half of it on the grid
    np.testing.assert_allclose(half.corners(), [(0.0, -1.0), (0.0, 1.0)], atol=1e-12)
    np.testing.assert_allclose(half.bbox, [(0.0, -1.0), (1.0, 1.0)], atol=1e-12)
    # the cut face is boundary: zero on it, positive beyond it, the box's distance near it
    np.testing.assert_allclose(half.distance([(0.0, 0.0), (-0.3, 0.0), (0.01, 0.0)]), [0.0, 0.3, -0.01], atol=1e-12)
    axes, nodes = grid(0.05, 2)
    whole = GridDomain(axes, np.hypot(*nodes) - 1.0)
    assert whole.corners().shape == (0, 2)
    sample = rng.uniform(-1.3, 1.3, (20000, 2))
    inside = sample[whole.distance(sample) < 0]
    assert np.all((inside >= whole.bbox[0]) & (inside <= whole.bbox[1]))


def test_cut_corners_in_3d_and_a_full_mask_is_the_box():
    x = np.linspace(0.0, 1.0, 11)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    slab = GridDomain((x, x, x), Z - 0.55)  # the half-space z < 0.55 cut by the unit cube
    corners = slab.corners()
    assert len(corners) == 8
    np.testing.assert_allclose(np.sort(np.unique(corners[:, 2])), [0.0, 0.55])
    full = GridDomain.from_mask((x, x, x), np.ones((11, 11, 11), dtype=bool))
    points = rng.uniform(-0.5, 1.5, (1000, 3))
    np.testing.assert_allclose(
        full.distance(points), tm.geometry.Box((0, 0, 0), (1, 1, 1)).distance(points), atol=1e-12
    )


def test_interpolation_is_the_size_grids():
    x, y = np.linspace(-1, 3, 9), np.linspace(10, 12, 5)
    values = np.add.outer((x - 1) ** 2, (y - 11) ** 2) - 0.5  # positive on the grid's edge: nothing cut
    points = np.column_stack([rng.uniform(-1, 3, 500), rng.uniform(10, 12, 500)])
    np.testing.assert_allclose(
        GridDomain((x, y), values).distance(points), tm.sizing.SizeGrid((x, y), values + 2)(points) - 2
    )


def test_inputs_are_copied_not_modified():
    axes, nodes = grid(0.1, 2)
    values = np.hypot(*nodes) - 1.0
    before = values.copy()
    domain = GridDomain(axes, values)
    values[:] = -1.0
    np.testing.assert_array_equal(domain.values, before)
    assert not domain.values.flags.writeable
    mask = np.hypot(*nodes) < 1.0
    mask_before = mask.copy()
    GridDomain.from_mask(axes, mask)
    np.testing.assert_array_equal(mask, mask_before)


x5 = np.linspace(0, 1, 5)
good = np.add.outer(x5, x5) - 1.0


@pytest.mark.parametrize(
    "axes, values, message",
    [
        ((x5, x5), np.where(good > 0.5, np.nan, good), "NaN or infinite"),
        ((x5, x5), np.where(good > 0.5, np.inf, good), "NaN or infinite"),
        ((x5, x5), good[:4], r"shape \(4, 5\), the grid axes need \(5, 5\)"),
        ((x5, x5), good.T[None], "shape"),
        ((x5, x5), np.abs(good), "no grid node has a negative distance"),
        ((x5, x5), np.zeros((5, 5)), "no grid node has a negative distance"),
        ((x5,), good[:, 0], "2-D or 3-D grid.*got 1 axes"),
        ((x5,) * 4, np.full((5,) * 4, -1.0), "2-D or 3-D grid.*got 4 axes"),
        (x5, good, "2-D or 3-D grid"),
        ((x5, x5**2), good, "evenly spaced"),
        ((x5[::-1], x5), good, "increasing"),
        ((x5, [0.0]), good, "at least two"),
        ((x5, x5), [["a"] * 5] * 5, "array of numbers"),
        (3.0, good, "sequence of 2 or 3"),
    ],
)
def test_bad_grids_raise(axes, values, message):
    with pytest.raises(GeometryError, match=message):
        GridDomain(axes, values)


@pytest.mark.parametrize(
    "mask, options, message",
    [
        (np.zeros((5, 5), dtype=bool), {}, "no node inside"),
        (np.ones((4, 5), dtype=bool), {}, r"shape \(4, 5\)"),
        (good, {}, "boolean"),
        (np.arange(25).reshape(5, 5) == 12, {}, "no node is inside after smoothing"),
        (np.eye(5, dtype=bool), {"smoothing": -1.0}, "zero or positive"),
        (np.eye(5, dtype=bool), {"smoothing": np.nan}, "zero or positive"),
        (np.eye(5, dtype=bool), {"smoothing": "wide"}, "number"),
    ],
)
def test_bad_masks_raise(mask, options, message):
    with pytest.raises(GeometryError, match=message):
        GridDomain.from_mask((x5, x5), mask, **options)


def test_a_0_1_mask_is_a_boolean_one():
    mask = np.eye(5, dtype=bool)
    np.testing.assert_array_equal(
        GridDomain.from_mask((x5, x5), mask.astype(np.uint8), smoothing=0).values,
        GridDomain.from_mask((x5, x5), mask, smoothing=0).values,
    )


@settings(max_examples=60, deadline=None)
@given(
    mask=st.one_of(
        arrays(np.bool_, st.tuples(st.integers(2, 9), st.integers(2, 9))),
        arrays(np.bool_, st.tuples(st.integers(2, 5), st.integers(2, 5), st.integers(2, 5))),
    ).filter(lambda m: m.any()),
    spacing=st.floats(0.01, 100.0),
    origin=st.floats(-1000.0, 1000.0),
)
def test_raw_mask_sign_agrees_with_the_mask_at_the_nodes(mask, spacing, origin):
    axes = [origin + spacing * np.arange(n) for n in mask.shape]
    domain = GridDomain.from_mask(axes, mask, smoothing=0)
    nodes = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, mask.ndim)
    distance = domain.distance(nodes).reshape(mask.shape)
    border = np.zeros(mask.shape, dtype=bool)
    for axis in range(mask.ndim):
        border[(slice(None),) * axis + (0,)] = border[(slice(None),) * axis + (-1,)] = True
    # inner nodes: the mask's sign; on the grid's edge an inside node is on the cut, so zero
    np.testing.assert_array_equal(distance[~border] < 0, mask[~border])
    assert np.all(distance[~mask] > 0)
    np.testing.assert_allclose(distance[border & mask], 0.0, atol=1e-9 * spacing)


def test_mesh_of_a_disk_mask():
    axes, (X, Y) = grid(0.02, 2, low=-1.2, high=1.2)
    domain = GridDomain.from_mask(axes, X**2 + Y**2 < 1.0)
    mesh = tm.generate_mesh(domain, 0.05)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * 0.05) == []
    assert cell_measure(mesh) == pytest.approx(np.pi, rel=0.02)
    assert tm.quality.summary(mesh).min > 0.5


def test_mesh_of_a_water_mask_cut_by_the_raster_edge():
    x, y = np.linspace(0, 2, 101), np.linspace(0, 1, 51)
    X, Y = np.meshgrid(x, y, indexing="ij")
    coast = 0.5 + 0.1 * np.sin(3 * x)
    domain = GridDomain.from_mask((x, y), Y < coast[:, None])
    mesh = tm.generate_mesh(domain, 0.05)
    assert tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * 0.05) == []
    for corner in domain.corners():  # the raster's corners in the water and where the coast meets its sides
        assert np.min(np.linalg.norm(mesh.points - corner, axis=1)) < 1e-9
    assert cell_measure(mesh) == pytest.approx(1.0 + (np.cos(0) - np.cos(6)) / 30, rel=0.02)


def test_mesh_of_a_sampled_ball():
    axes, nodes = grid(0.1, 3, low=-1.2, high=1.2)
    domain = GridDomain(axes, np.sqrt(sum(c**2 for c in nodes)) - 1.0)
    mesh = tm.generate_mesh(domain, 0.15, seed=0)
    stats = tm.quality.summary(mesh)
    assert 1500 < mesh.n_points < 4000
    assert cell_measure(mesh) == pytest.approx(4 / 3 * np.pi, rel=0.03)
    assert stats.min_dihedral >= 10.0 and stats.n_inverted == 0
    assert np.all(domain.distance(mesh.points) < 1e-3 * 0.15)


def test_the_grid_box_edges_inside_are_sharp_edges_ending_at_the_corners():
    x = np.linspace(0.0, 1.0, 11)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    # z < 0.55: the 4 bottom edges, the 4 vertical ones cut at 0.55, and the line z = 0.55 on each side face
    slab = GridDomain((x, x, x), Z - 0.55)
    edges = slab.sharp_edges()
    ends = np.vstack([edge(np.array([0.0, 1.0])) for edge in edges])
    assert len(edges) == 12
    np.testing.assert_allclose(np.unique(ends.round(12), axis=0), slab.corners(), atol=1e-12)
    middle = np.vstack([edge(np.linspace(0, 1, 7)) for edge in edges])
    assert np.abs(slab.distance(middle)).max() < 1e-12  # on two box faces, inside the shape
    hollow = GridDomain((x, x, x), 0.3 - np.sqrt((X - 0.5) ** 2 + (Y - 0.5) ** 2 + (Z - 0.5) ** 2))
    assert len(hollow.sharp_edges()) == 12  # a void inside leaves the box's edges whole
    assert GridDomain((x, x), -np.ones((11, 11))).sharp_edges() == []


def test_contours_on_the_grid_box_faces_lie_on_the_boundary():
    # a topography z = f(x, y) reaching the box's sides: a wavy line on each side face, a closed
    # loop where a bump pierces the top face; marching squares cuts the curve between grid lines
    x = np.linspace(0.0, 1.0, 11)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    surface = 0.7 + 0.25 * np.sin(3 * X) * np.cos(2 * Y) + 0.4 * np.exp(-((X - 0.5) ** 2 + (Y - 0.5) ** 2) / 0.02)
    terrain = GridDomain((x, x, x), Z - surface)
    edges = terrain.sharp_edges()
    contours = [edge for edge in edges if getattr(edge, "closed", None) is not None]
    assert any(edge.closed for edge in contours) and sum(not edge.closed for edge in contours) == 4
    t = np.linspace(0.0, 1.0, 97)
    for edge in edges:
        points = edge(t)
        assert np.abs(terrain.distance(points)).max() < 1e-9
        on_faces = np.sum((points == 0.0) | (points == 1.0), axis=1)
        assert np.all(on_faces >= 1)


@pytest.mark.parametrize("name", ["block", "block with a void", "block under a topography"])
def test_mesh_of_a_shape_cut_by_the_grid_box_in_3d(name):
    # a velocity model's box, as a gridded shape reaching its edges: the box's edges and the topography's
    # line on its sides, not held, left slivers of 5 degrees that no removal mended ("slivers remain")
    axes = [np.linspace(0, 1.6, 81), np.linspace(0, 1, 51), np.linspace(-0.7, 0, 71)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    values = {
        "block": -np.ones(X.shape),
        "block with a void": 0.2 - np.sqrt((X - 0.8) ** 2 + (Y - 0.5) ** 2 + (Z + 0.35) ** 2),
        "block under a topography": Z - (-0.08 + 0.04 * np.sin(X / 0.3) * np.cos(Y / 0.25)),
    }[name]
    domain = GridDomain(axes, values)
    mesh = tm.generate_mesh(domain, 0.05, seed=0)
    assert tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=5e-5) == []
    assert tm.quality.summary(mesh).min_dihedral >= 10.0


@pytest.mark.parametrize("above", [3e-4, -3e-4])
def test_a_corner_a_grid_makes_is_not_taken_by_a_box_face_passing_near_it(above):
    # a box 1.1 away whose top lies 3e-4 above the corner where the topography meets the other box's edge:
    # Newton's method on the two edge planes and that top put the corner there, 3e-4 off the domain; 3e-4
    # below, the edge's piece ended at that top's crossing (one sample interval held both), on the edge
    axes = [np.linspace(0, 1.6, 81), np.linspace(0, 1, 51), np.linspace(-0.7, 0, 71)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    terrain = GridDomain(axes, Z - (-0.08 + 0.04 * np.sin(X / 0.3) * np.cos(Y / 0.25)))
    base = terrain & tm.geometry.Box((0.2, 0.2, -0.5), (1.2, 0.8, 0.1))
    corner = base.corners()[np.argmin(np.linalg.norm(base.corners() - (0.2, 0.2, -0.06), axis=1))]
    domain = base - tm.geometry.Box((1.3, 0.3, -0.45), (1.5, 0.7, corner[2] + above))
    found = domain.corners()[np.argmin(np.linalg.norm(domain.corners() - corner, axis=1))]
    assert np.linalg.norm(found - corner) < 1e-12 and abs(domain.distance(found[None])[0]) < 1e-12
