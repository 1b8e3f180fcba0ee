import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull, Delaunay, cKDTree

import terramesh as tm
import terramesh.cleanup.slivers as slivers
import terramesh.generation.distmesh3d as distmesh3d
import terramesh.generation.finalize3d as finalize3d
import terramesh.generation.sharp_edges as sharp_edges
from terramesh.errors import GenerationError, GeometryError, SizingError
from terramesh.generation.distmesh3d import bcc_seed_points, delaunay_3d, generate_mesh_3d
from terramesh.generation.options import checked_options
from terramesh.geometry.primitives3d import Ball, Box, Cylinder
from terramesh.mesh.topology import unique_edges
from terramesh.quality.tetra import min_max_dihedral, radius_ratio, tetra_volumes

from ..conftest import wedge_prism

BALL = Ball((0, 0, 0), 1.0)


def centre_graded(p):
    """The issue's graded ball: h = 0.1 + 0.2 |x| (finest at the centre)."""
    return 0.1 + 0.2 * np.sqrt(np.sum(p**2, axis=1))


def boundary_graded(p):
    """Finest at the sphere, coarser inside: h = 0.06 + 0.15 |d|."""
    return 0.06 + 0.15 * np.abs(BALL.distance(p))


def assert_valid(mesh, domain, h_min, volume=None, rel=0.01):
    """Every rule of a valid tetrahedral mesh, the sliver bound, and optionally the volume."""
    points, cells = mesh.points, mesh.cells
    assert cells.shape[1] == 4 and points.shape[1] == 3
    assert tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * h_min) == []
    smallest = min_max_dihedral(points, cells)[0]
    assert smallest.min() >= finalize3d.MIN_DIHEDRAL, f"sliver: {smallest.min():.2f} degrees"
    assert mesh.info["min_dihedral"] == pytest.approx(smallest.min())
    if volume is not None:
        assert tetra_volumes(points, cells).sum() == pytest.approx(volume, rel=rel)


def boundary_triangles(cells):
    faces = np.sort(np.concatenate([np.delete(cells, k, axis=1) for k in range(4)]), axis=1)
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    return unique[counts == 1]


def assert_follows_box(mesh, box, elsewhere=None):
    """Every boundary triangle on one face of ``box`` (or, where ``elsewhere`` says so, off the box), faces covered.

    ``elsewhere`` marks the vertices on another surface of a CSG domain; triangles with all three there are left out.
    """
    lower, upper = box.bbox
    scale = np.max(upper - lower)
    points, triangles = mesh.points, boundary_triangles(mesh.cells)
    if elsewhere is not None:
        triangles = triangles[~np.all(elsewhere(points)[triangles], axis=1)]
    offsets = np.abs(np.concatenate([points - lower, upper - points], axis=1))  # to the planes x0 y0 z0 x1 y1 z1
    vertices = np.unique(triangles)
    assert offsets[vertices].min(axis=1).max() <= 1e-12 * scale, "a boundary vertex off the box's faces"
    on = offsets <= 1e-9 * scale
    shared = on[triangles[:, 0]] & on[triangles[:, 1]] & on[triangles[:, 2]]
    assert np.all(shared.any(axis=1)), f"{np.sum(~shared.any(axis=1))} boundary triangles cut across an edge"
    a, b, c = (points[triangles[:, i]] for i in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    per_face = np.bincount(np.argmax(shared, axis=1), weights=area, minlength=6)
    extent = upper - lower
    face_area = np.tile([extent[1] * extent[2], extent[0] * extent[2], extent[0] * extent[1]], 2)
    if elsewhere is None:
        np.testing.assert_allclose(per_face, face_area, rtol=1e-8)
    return per_face, face_area


# --- the generator on the shapes ---------------------------------------------------------


@pytest.fixture(scope="module")
def uniform_ball():
    return generate_mesh_3d(BALL, 0.12, seed=0)


def test_uniform_ball(uniform_ball):
    assert_valid(uniform_ball, BALL, 0.12, volume=4 / 3 * np.pi)
    info = uniform_ball.info
    assert info["stop_reason"] in {"converged", "stalled"} and info["retriangulations"] >= 1
    assert {"iterations", "max_move", "seconds", "h0", "slivers_before", "sliver_rounds"} <= set(info)
    # mean cell quality well above the sliver bound, and edges near the size asked for
    assert min_max_dihedral(uniform_ball.points, uniform_ball.cells)[0].mean() > 50
    ratio = tm.quality.edge_length_ratio(uniform_ball.points, uniform_ball.cells, lambda p: np.full(len(p), 0.12))
    assert 0.9 <= np.median(ratio) <= 1.1


def test_ball_graded_towards_the_centre():
    mesh = generate_mesh_3d(BALL, centre_graded, seed=0)
    # h = 0.3 at the sphere: inscribed facets that large lose about 4 % of the volume, which is geometry
    assert_valid(mesh, BALL, 0.1, volume=4 / 3 * np.pi, rel=0.05)
    # vertices within r = 0.5 against the shell 0.5 to 0.8 (clear of the boundary layer): as the integrals of
    # r^2 / h^3 say, within 25 %
    radius = np.linalg.norm(mesh.points, axis=1)
    r = np.linspace(0, 0.8, 80_001)
    density = r**2 / (0.1 + 0.2 * r) ** 3
    expected = np.trapezoid(density[r <= 0.5], r[r <= 0.5]) / np.trapezoid(density[r >= 0.5], r[r >= 0.5])
    inner, shell = np.sum(radius < 0.5), np.sum((radius >= 0.5) & (radius < 0.8))
    assert inner / shell == pytest.approx(expected, rel=0.25)


def test_ball_graded_towards_the_boundary_keeps_the_volume():
    mesh = generate_mesh_3d(BALL, boundary_graded, seed=1)
    assert_valid(mesh, BALL, 0.06, volume=4 / 3 * np.pi)
    ratio = tm.quality.edge_length_ratio(mesh.points, mesh.cells, boundary_graded)
    assert 0.85 <= np.median(ratio) <= 1.15


def test_box_with_a_ball_removed():
    box = Box((0, 0, 0), (1, 1, 1))
    domain = box - Ball((0.5, 0.5, 0.5), 0.3)
    mesh = generate_mesh_3d(domain, 0.08, seed=0)
    assert_valid(mesh, domain, 0.08, volume=1 - 4 / 3 * np.pi * 0.3**3)
    for corner in box.corners():
        assert np.min(np.linalg.norm(mesh.points - corner, axis=1)) == 0.0
    # the box's edges, an operand's, are followed as a box's alone are
    per_face, face_area = assert_follows_box(
        mesh, box, elsewhere=lambda p: np.abs(np.linalg.norm(p - 0.5, axis=1) - 0.3) < 1e-9
    )
    np.testing.assert_allclose(per_face, face_area, rtol=1e-8)


@pytest.mark.parametrize("radius", [1.0, 1.25, 1.5])
def test_a_void_of_little_more_than_an_edge_length_is_meshed(radius):
    # flat boundary faces on a sphere of 1.25-1.5 edge lengths cut into it by their sag, and cells on them
    # had their centroid 0.01-0.05 edge lengths inside the ball: "centroid outside" on 5 of 8 seeds
    void = Ball((0.5, 0.5, 0.5), radius * 0.1)
    domain = Box((0, 0, 0), (1, 1, 1)) - void
    for seed in range(4):
        mesh = generate_mesh_3d(domain, 0.1, seed=seed)
        assert_valid(mesh, domain, 0.1)
        # the void is there, as an inscribed polyhedron (72-84 % of the ball's volume)
        ball_volume = 4 / 3 * np.pi * (radius * 0.1) ** 3
        assert 0.6 < (1 - tetra_volumes(mesh.points, mesh.cells).sum()) / ball_volume < 1.0
        assert np.sum(np.abs(void.distance(mesh.points)) < 1e-6) >= 20


@pytest.mark.parametrize("centre", [(0, 0, 0.5), (0.2, 0.3, 0.1)])
def test_a_void_of_one_and_a_half_edge_lengths_off_centre_in_a_ball_is_meshed(centre):
    # the README said one edge length: in a ball, off its centre, that was refused on 6 of 12 runs (its flat faces'
    # corners' normals 90 degrees apart, where a cell across a gap is told by normals that disagree)
    void = Ball(centre, 0.225)
    domain = Ball((0, 0, 0), 1) - void
    mesh = generate_mesh_3d(domain, 0.15, seed=0)
    assert_valid(mesh, domain, 0.15)
    assert np.sum(np.abs(void.distance(mesh.points)) < 1e-6) >= 20


@pytest.mark.parametrize(
    ("domain", "volume"),
    [
        (Box((0, 0, 0), (1, 1, 0.5)) | Box((0.2, 0.2, 0.5), (0.8, 0.8, 1.0)), 0.68),  # a block on a block
        (Box((0, 0, 0), (0.5, 1, 1)) | Box((0.5, 0, 0), (1, 1, 1)), 1.0),  # two halves of the unit cube
    ],
)
def test_solids_sharing_a_face_are_meshed_across_it(domain, volume):
    # the minimum of the two distances is zero on the shared face: cells with their centroid on it were
    # dropped, which left a crack (stacked: 4 of 4 seeds invalid; halves: one seed, another 5e-5 short)
    for seed in range(4):
        mesh = generate_mesh_3d(domain, 0.08, seed=seed)
        assert_valid(mesh, domain, 0.08)
        assert tetra_volumes(mesh.points, mesh.cells).sum() == pytest.approx(volume, rel=1e-9)


@pytest.mark.parametrize(
    "second", [Cylinder((0, 0, 0), 0.5, 3.0, axis=(0, 1, 0)), Cylinder((0, 0, 0), 0.4, 3.0, axis=(0, 0, 1))]
)
def test_crossing_cylinders(second):
    # Delaunay cells of boundary points alone: a flat one 20 sizes wide in the two cylinders' common
    # tangent plane (its centroid a rounding inside), a needle along one cylinder's straight line; their
    # vertices are all on the boundary, so sliver removal could not mend them (4 of these 8 runs raised)
    domain = Cylinder((0, 0, 0), 0.5, 3.0, axis=(1, 0, 0)) | second
    volume = np.pi * (0.5**2 + second.radius**2) * 3 - _cross_volume(0.5, second.radius)
    for size in (0.15, 0.1):
        for seed in (0, 1):
            mesh = generate_mesh_3d(domain, size, seed=seed)
            assert_valid(mesh, domain, size)
            # inscribed facets of a cylinder 3-7 sizes across lose 0.5-1.5 % of the volume
            assert 0.98 < tetra_volumes(mesh.points, mesh.cells).sum() / volume < 1.0


def test_a_lobed_salt_body_from_a_voxel_mask():
    # the salt of examples/seismic/bp2004_3d.py on a 100 m grid: flat cells hugging its boundary, their
    # corners on it or a few metres inside, outlived sliver removal (10 of 16 runs raised, 2-13 slivers)
    x, y, z = np.arange(26000, 33001, 100.0), np.arange(1000, 9001, 100.0), np.arange(-6000, -1999, 100.0)
    ux, uy, uz = np.meshgrid((x - 29500) / 2500, (y - 5000) / 3000, (z + 4000) / 1200, indexing="ij")
    rho = np.sqrt(ux**2 + uy**2 + uz**2)
    mask = rho <= 1 + 0.15 * np.sin(3 * np.arctan2(uy, ux)) * (1 - (uz / np.maximum(rho, 1e-12)) ** 2)
    salt = tm.geometry.GridDomain.from_mask((x, y, z), mask)
    for size, seed in ((400.0, 0), (400.0, 2), (300.0, 1), (250.0, 0)):
        mesh = generate_mesh_3d(salt, size, seed=seed)
        assert_valid(mesh, salt, size)
        assert 0.97 < tetra_volumes(mesh.points, mesh.cells).sum() / (mask.sum() * 100.0**3) < 1.0


def _cross_volume(big, small):
    """Volume common to perpendicular cylinders of radii ``big`` >= ``small`` whose axes cross, by quadrature."""
    # slices across the small one's axis: a rectangle 2 sqrt(small^2 - t^2) by 2 sqrt(big^2 - t^2)
    t = np.linspace(-small, small, 200001)
    return np.trapezoid(4 * np.sqrt(small**2 - t**2) * np.sqrt(big**2 - t**2), t)


# (lower, upper, size, seed): the two boxes of the report (h = 100 cut an edge, h = 110 did not), others of other
# proportions and sizes, one in UTM coordinates with a graded size
BOXES = [
    ((-200, -200, -600), (800, 600, 0), 100, 0),
    ((-200, -200, -600), (800, 600, 0), 100, 1),
    ((-200, -200, -600), (800, 600, 0), 100, 2),
    ((-200, -200, -600), (800, 600, 0), 110, 0),
    ((0, 0, 0), (800, 600, 600), 100, 0),
    ((0, 0, 0), (800, 600, 600), 100, 3),
    ((0, 0, 0), (800, 600, 600), 75, 1),
    ((-500, 0, -400), (500, 250, 0), 90, 4),
    ((0, 0, 0), (1, 1, 1), 0.15, 5),
    ((5.0e5, 4.0e6, -3000.0), (5.02e5, 4.0015e6, 0.0), "graded", 0),
]


@pytest.mark.parametrize(("lower", "upper", "size", "seed"), BOXES)
def test_box_edges_are_followed_and_its_volume_kept(lower, upper, size, seed):
    """Boundary triangles each on one face (none cutting an edge), faces and volume exact, no sliver."""
    box = Box(lower, upper)
    extent = box.bbox[1] - box.bbox[0]
    if size == "graded":
        # finer at the top: 125 m there, 250 m at the bottom
        size = lambda p: 125.0 + 125.0 * (box.bbox[1, 2] - p[:, 2]) / extent[2]  # noqa: E731
        h_min = 125.0
    else:
        h_min = size
    mesh = generate_mesh_3d(box, size, seed=seed)
    assert_valid(mesh, box, h_min)
    assert_follows_box(mesh, box)
    assert tetra_volumes(mesh.points, mesh.cells).sum() == pytest.approx(np.prod(extent), rel=1e-9)
    assert min_max_dihedral(mesh.points, mesh.cells)[0].min() >= finalize3d.MIN_DIHEDRAL


@pytest.mark.parametrize("seed", [0, 1])
def test_cylinder_rims_are_edges_of_the_mesh(seed):
    """Every boundary triangle on the side or on one end, none across a rim; no cap along the rims.

    Before the cylinder reported its rims as sharp edges, its meshes cut across them: with radius 0.5 and
    h = 0.1, caps of radius ratio 0.140 and 48 cells below 0.3 over 8 seeds (after: 0.315 and none).
    """
    domain = Cylinder((0, 0, 0), 0.5, 1.0)
    mesh = generate_mesh_3d(domain, 0.08, seed=seed)
    assert_valid(mesh, domain, 0.08, volume=np.pi * 0.25)
    points = mesh.points[boundary_triangles(mesh.cells)]  # (b, 3 corners, 3)
    side = np.abs(np.hypot(points[..., 0], points[..., 1]) - 0.5) <= 1e-9
    ends = [np.abs(points[..., 2] - end) <= 1e-12 for end in (-0.5, 0.5)]
    assert np.all(side.all(axis=1) | ends[0].all(axis=1) | ends[1].all(axis=1))
    assert radius_ratio(mesh.points, mesh.cells).min() >= 0.25


def test_tilted_cylinder_and_gridded_sizes():
    domain = Cylinder((0.1, 0, 0), 0.4, 1.2, axis=(1, 1, 0))
    x, y, z = (np.linspace(low, high, 9) for low, high in domain.bbox.T)
    grid = tm.sizing.SizeGrid((x, y, z), 0.07 + 0.04 * (x - x[0])[:, None, None] + 0 * y[:, None] + 0 * z)
    mesh = generate_mesh_3d(domain, grid, seed=3)
    assert mesh.info["h0"] == pytest.approx(0.07)
    assert_valid(mesh, domain, 0.07, volume=np.pi * 0.16 * 1.2)
    assert 0.85 <= np.median(tm.quality.edge_length_ratio(mesh.points, mesh.cells, grid)) <= 1.2


def test_sharp_edge_points_follow_the_size_and_stay_on_the_edges():
    box = Box((0, 0, 0), (1000, 800, 600))
    uniform = sharp_edges._sharp_edge_points(box, lambda p: np.full(len(p), 100.0), 100.0, box.bbox, 0.1)
    assert len(uniform) == 4 * (9 + 7 + 5)  # the ends, corners, left out
    on_faces = (uniform == box.bbox[0]) | (uniform == box.bbox[1])
    assert np.all(on_faces.sum(axis=1) == 2)
    # along x, h grows from 50 to 150: round(integral of dx / h) = round(10 ln 3) = 11 segments on each x edge
    graded = sharp_edges._sharp_edge_points(box, lambda p: 50.0 + 0.1 * p[:, 0], 50.0, box.bbox, 0.1)
    along_x = graded[(graded[:, 1] == 0) & (graded[:, 2] == 0)][:, 0]
    assert len(along_x) == 10
    gaps = np.diff(np.concatenate([[0.0], along_x, [1000.0]]))
    middle = 0.5 * (np.concatenate([[0.0], along_x]) + np.concatenate([along_x, [1000.0]]))
    np.testing.assert_allclose(gaps / (50.0 + 0.1 * middle), 10 * np.log(3) / 11, rtol=0.01)
    # an operand's edges only where they lie on the combination's boundary: the cap covers the top at x < 400
    cap = Box((-100, -100, 500), (400, 900, 700))
    union = sharp_edges._sharp_edge_points(box | cap, lambda p: np.full(len(p), 100.0), 100.0, (box | cap).bbox, 0.1)
    assert np.all(np.abs((box | cap).distance(union)) <= 1e-12)
    top_along_x = union[(union[:, 1] == 0) & (union[:, 2] == 600)][:, 0]
    assert len(top_along_x) and top_along_x.min() >= 400


def test_deleting_a_cell_never_cuts_a_sharp_edge_between_fixed_points():
    """Sliver removal peels cells with two boundary faces; at a box edge that would chord across it."""
    # a wedge on the edge x = y = 0 (c, d), its boundary faces on x = 0 and y = 0, two cells behind it
    points = np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.5], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.5]])
    cells = np.array([[0, 1, 2, 3], [0, 1, 2, 4], [0, 1, 3, 4]])
    negative = tetra_volumes(points, cells) < 0
    cells[negative] = cells[negative][:, [1, 0, 2, 3]]
    neighbors = np.full((3, 4), -1)
    for t, u in [(t, u) for t in range(3) for u in range(3) if t != u]:
        for k in range(4):
            if len(set(np.delete(cells[t], k)) & set(cells[u])) == 3:
                neighbors[t, k] = u

    def delete(fixed, sharp):
        alive = np.ones(3, dtype=bool)
        vertex_tet = np.array([0, 0, 0, 0, 1])
        deleted = slivers.delete_flat_boundary_cells(
            points, cells.copy(), neighbors.copy(), alive, vertex_tet, np.empty(3, dtype=np.int64),
            np.array([3, 0, 0]), np.array([0]), np.inf, fixed, sharp,
        )  # fmt: skip
        return deleted, alive[0]

    sharp = np.cos(np.radians(slivers.SHARP_TURN))
    on_edge = np.array([False, False, True, True, False])
    assert delete(on_edge, sharp) == (0, True)  # the edge's two fixed points: kept
    assert delete(np.zeros(5, dtype=bool), sharp) == (1, False)  # no fixed points: it goes, as before
    assert delete(on_edge, -2.0) == (1, False)  # peeling cells outside the domain ignores edges


# --- edges created by CSG: where one operand's surface meets another's -------------------------------------


def box_planes(lower, upper):
    """Offsets of points from the six face planes of a box, one function each."""
    return [lambda p, a=a, c=c: p[:, a] - c for a in range(3) for c in (lower[a], upper[a])]


# (domain, its surfaces as functions zero on them, its volume where polyhedral): the L-shape, notch and
# overlapping boxes, and round cuts whose rims are curves on the box's faces
CSG_SHAPES = {
    "l-shape": (
        Box((0, 0, 0), (2, 1, 1)) | Box((0, 0, 0), (1, 2, 1)),
        box_planes((0, 0, 0), (2, 1, 1)) + box_planes((0, 0, 0), (1, 2, 1)),
        3.0,
    ),
    "notch": (
        Box((0, 0, 0), (2, 1, 1)) - Box((0.7, -0.1, 0.6), (1.3, 0.5, 1.1)),
        box_planes((0, 0, 0), (2, 1, 1)) + box_planes((0.7, -0.1, 0.6), (1.3, 0.5, 1.1)),
        2.0 - 0.6 * 0.5 * 0.4,
    ),
    "overlapping": (
        Box((0, 0, 0), (1, 1, 1)) | Box((0.5, 0.4, 0.3), (1.5, 1.4, 1.3)),
        box_planes((0, 0, 0), (1, 1, 1)) + box_planes((0.5, 0.4, 0.3), (1.5, 1.4, 1.3)),
        2.0 - 0.5 * 0.6 * 0.7,
    ),
    "minus-ball": (
        Box((0, 0, 0), (1, 1, 1)) - Ball((1.0, 0.5, 1.0), 0.4),  # centred on an edge: arcs on two faces
        box_planes((0, 0, 0), (1, 1, 1)) + [lambda p: np.linalg.norm(p - (1.0, 0.5, 1.0), axis=1) - 0.4],
        None,
    ),
    "minus-cylinder": (
        Box((0, 0, 0), (1, 1, 1)) - Cylinder((0.5, 0.5, 0.5), 0.25, 2.0),  # a hole through: two circles
        box_planes((0, 0, 0), (1, 1, 1)) + [lambda p: np.hypot(p[:, 0] - 0.5, p[:, 1] - 0.5) - 0.25],
        None,
    ),
}


# the thinnest part of a shape: the walls between the cylinder's hole and the box's sides
THINNEST = {"minus-cylinder": 0.25}


@pytest.mark.parametrize("size", [0.1, 0.125, 0.15])
@pytest.mark.parametrize("name", list(CSG_SHAPES))
def test_csg_edges_are_followed(name, size):
    """Every boundary triangle on one surface of the shape (none cutting an edge), volume exact, no sliver.

    Before CSG reported the edges it creates, 80 of 200 runs of these shapes (sizes 0.08 to 0.2, seeds 0 to 7)
    raised (slivers left, or an invalid mesh) and only 9 followed every edge. A part thinner than two sizes
    may be refused, as the error says: the box less a cylinder at 0.15 (walls 1.7 sizes thick), 6 of 40 seeds
    before the 3D tetrahedralisation stopped losing points, 8 of 40 after; at 0.125 none of 40.
    """
    domain, surfaces, volume = CSG_SHAPES[name]
    scale = np.max(domain.bbox[1] - domain.bbox[0])
    thin = THINNEST.get(name, np.inf) < 2 * size
    for seed in range(3):
        try:
            mesh = generate_mesh_3d(domain, size, seed=seed)
        except GenerationError as error:
            assert thin and "thinner than about two edge lengths" in str(error)
            continue
        assert_valid(mesh, domain, size)
        triangles = boundary_triangles(mesh.cells)
        on = np.abs(np.stack([surface(mesh.points) for surface in surfaces], axis=1)) <= 1e-9 * scale
        one = on[triangles[:, 0]] & on[triangles[:, 1]] & on[triangles[:, 2]]
        assert np.all(one.any(axis=1)), f"seed {seed}: {np.sum(~one.any(axis=1))} boundary triangles cut an edge"
        if volume is not None:
            assert tetra_volumes(mesh.points, mesh.cells).sum() == pytest.approx(volume, rel=1e-6)
        for corner in domain.corners():
            assert np.min(np.linalg.norm(mesh.points - corner, axis=1)) == 0.0


def test_sharp_edge_points_of_a_closed_curve_go_all_round():
    """A hole's rim is a closed curve: no end is left out, and the points are evenly spaced on it."""
    domain = Box((0, 0, 0), (1, 1, 1)) - Cylinder((0.5, 0.5, 0.5), 0.25, 2.0)
    points = sharp_edges._sharp_edge_points(domain, lambda p: np.full(len(p), 0.1), 0.1, domain.bbox, 1e-4)
    rim = points[(points[:, 2] == 1.0) & (np.abs(np.hypot(points[:, 0] - 0.5, points[:, 1] - 0.5) - 0.25) < 1e-12)]
    assert len(rim) == round(2 * np.pi * 0.25 / 0.1)  # 16
    angle = np.sort(np.arctan2(rim[:, 1] - 0.5, rim[:, 0] - 0.5))
    gaps = np.diff(np.append(angle, angle[0] + 2 * np.pi))
    np.testing.assert_allclose(gaps, 2 * np.pi / len(rim), rtol=1e-3)


def test_points_pushed_next_to_an_edge_are_dropped_before_the_final_cells():
    """A free point inside the ball on an edge segment would let cells bridge it; fixed points are kept."""
    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.1, 0.0], [0.5, 0.7, 0.0], [0.5, 0.0, 0.3]])
    centres, radii = np.array([[0.5, 0.0, 0.0]]), np.array([0.5])
    assert sharp_edges.encroaching_points(points, 2, centres, radii).tolist() == [False, False, True, False, True]
    assert sharp_edges.encroaching_points(points, 3, centres, radii).tolist() == [False, False, False, False, True]


# --- the sliver guarantee ------------------------------------------------------------------------------


def test_no_slivers_on_twenty_seeds():
    """Every seed reaches the bound (10 degrees); sliver removal aims at 15, and gets there."""
    smallest = []
    for seed in range(20):
        mesh = generate_mesh_3d(BALL, centre_graded, seed=seed)
        assert 1000 < mesh.n_cells < 5000
        assert_valid(mesh, BALL, 0.1)
        smallest.append(mesh.info["min_dihedral"])
    assert min(smallest) >= 10.0
    assert np.median(smallest) >= 14.0


@pytest.mark.parametrize(
    ("upper", "message"),
    [((0.05, 0.05, 0.05), "too large"), ((0.1, 0.1, 0.1), "too large"), ((0.6, 0.1, 0.1), "do not span a volume")],
)
def test_a_box_less_than_a_size_across_raises_clearly(upper, message):
    # all its points are corners and edge points, fixed: ordering the free ones (none) raised ValueError
    # from deep inside NumPy
    with pytest.raises(GenerationError, match=message):
        generate_mesh_3d(Box((0, 0, 0), upper), 0.2, h0=0.2, seed=0)


def test_a_box_of_corners_alone_is_meshed():
    box = Box((0, 0, 0), (0.15, 0.15, 0.15))
    mesh = generate_mesh_3d(box, 0.2, h0=0.2, seed=0)
    assert mesh.n_points == 8
    assert_valid(mesh, box, 0.2)
    assert tetra_volumes(mesh.points, mesh.cells).sum() == pytest.approx(0.15**3)


# --- determinism, options, bad inputs ----------------------------------------------------------------


def test_same_seed_same_mesh_and_seeds_differ():
    first = generate_mesh_3d(BALL, centre_graded, seed=7)
    again = generate_mesh_3d(BALL, centre_graded, seed=7)
    other = generate_mesh_3d(BALL, centre_graded, seed=8)
    np.testing.assert_array_equal(first.points, again.points)
    np.testing.assert_array_equal(first.cells, again.cells)
    assert first.n_points != other.n_points or not np.array_equal(first.points, other.points)


def test_fixed_points_are_kept_and_not_mutated():
    fixed = np.array([[0.5, 0.5, 0.5], [0.2, 0.8, 0.3]])
    copy = fixed.copy()
    mesh = generate_mesh_3d(Box((0, 0, 0), (1, 1, 1)), 0.2, fixed_points=fixed, seed=0)
    np.testing.assert_array_equal(fixed, copy)
    for point in fixed:
        assert np.min(np.linalg.norm(mesh.points - point, axis=1)) == 0.0
    assert mesh.info["min_dihedral"] >= 10


def test_plain_distance_function_with_bbox():
    mesh = generate_mesh_3d(lambda p: np.linalg.norm(p, axis=1) - 1.0, 0.2, bbox=[(-1, -1, -1), (1, 1, 1)])
    assert_valid(mesh, BALL, 0.2, volume=4 / 3 * np.pi, rel=0.02)


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda: generate_mesh_3d(tm.geometry.Disk((0, 0), 1), 0.1), GenerationError, "3D domain"),
        (lambda: generate_mesh_3d(BALL), GenerationError, "give edge_length"),
        (lambda: generate_mesh_3d(BALL, 0.1, h0=-1.0), GenerationError, "h0 must be positive"),
        (lambda: generate_mesh_3d(BALL, 0.1, max_iter=0), GenerationError, "max_iter"),
        (lambda: generate_mesh_3d(BALL, -0.1), SizingError, "positive"),
        (lambda: generate_mesh_3d(BALL, lambda p: np.full(len(p), np.nan)), SizingError, "NaN"),
        (lambda: generate_mesh_3d(BALL, 0.1, bbox=[(5, 5, 5), (6, 6, 6)]), GenerationError, "inside the domain"),
        (lambda: generate_mesh_3d(BALL, 0.1, bbox=[(0, 0), (1, 1)]), GeometryError, r"bbox must have shape \(2, 3\)"),
        (lambda: generate_mesh_3d(BALL, 0.1, fixed_points=[(2.0, 0, 0)]), GenerationError, "outside the domain"),
        (lambda: generate_mesh_3d(BALL, 0.1, fixed_points=[(0.0, 0.0)]), GenerationError, r"shape \(k, 3\)"),
        (lambda: generate_mesh_3d(BALL, 5.0), GenerationError, "too large"),
        (
            lambda: generate_mesh_3d(tm.geometry.Box((0, 0, -50), (50, 50, 0)), 100.0),
            GenerationError,
            r"only 1 point fit in the domain \(its bbox 50 x 50 x 50\): h0=100 is too large",
        ),
        (  # a slab half a size thick came back with its edges bevelled off, 75-82 % of its volume, and no error
            lambda: generate_mesh_3d(tm.geometry.Box((0, 0, 0), (1, 1, 0.05)), 0.1, seed=0),
            GenerationError,
            r"\d+ boundary faces cut across the domain instead of lying on its boundary; the domain is 0\.05 "
            r"across its thinnest side, 0\.5 sizes \(its median size 0\.1\): too thin",
        ),
        (  # a velocity model one sample (50 m) thick at 50 m and more: the slivers' message said nothing of it
            lambda: generate_mesh_3d(tm.geometry.Box((0, 0, -450), (950, 50, 0)), 100.0, seed=0),
            GenerationError,
            r"(slivers remain|invalid mesh).* the domain is 50 across its thinnest side, 0.5 sizes "
            r"\(its median size 100\): too thin",
        ),
        (
            lambda: generate_mesh_3d(BALL, tm.sizing.SizeGrid(([0, 1], [0, 1]), np.ones((2, 2)))),
            GenerationError,
            "3-axis SizeGrid",
        ),
    ],
)
def test_bad_inputs(call, error, message):
    with pytest.raises(error, match=message):
        call()


# --- the parts: tetrahedralisation (the seeding's tests are in test_seeding3d.py) ---------------------


def test_delaunay_matches_qhull_on_random_points():
    points = np.random.default_rng(0).random((3000, 3))
    cells, neighbors = delaunay_3d(points)
    reference = Delaunay(points).simplices
    assert {tuple(c) for c in np.sort(cells, axis=1)} == {tuple(c) for c in np.sort(reference, axis=1)}
    assert np.all(tetra_volumes(points, cells) > 0)
    # the neighbour across the face opposite corner k holds that face
    for k in range(4):
        inner = neighbors[:, k] >= 0
        face = np.sort(np.delete(cells[inner], k, axis=1), axis=1)
        across = cells[neighbors[inner, k]]
        assert np.all((face[:, :, None] == across[:, None, :]).any(axis=2))


@pytest.mark.parametrize(
    ("spacing", "offset"),
    [(1.0, 0.0), (0.1, 0.0), (0.1, 5e5)],  # integers; tenths, which no double holds; far from the origin (UTM)
)
def test_delaunay_of_a_lattice_has_every_point_a_vertex_and_no_cell_inverted(spacing, offset):
    """Cospherical points (a cubic grid) and exact duplicates: the exact kernel, the hull filled."""
    grid = spacing * np.stack(np.meshgrid(*[np.arange(6.0)] * 3, indexing="ij"), axis=-1).reshape(-1, 3) + offset
    points = np.vstack([grid, grid[:3]])  # three exact duplicates
    cells, _, duplicate_of = delaunay_3d(points, return_duplicates=True)
    volumes = tetra_volumes(points - offset, cells)
    assert np.all(volumes > 0) and volumes.sum() == pytest.approx((5 * spacing) ** 3, rel=1e-9)
    assert np.array_equal(np.unique(cells), np.arange(len(grid)))
    if spacing == 1.0:  # an exact lattice: each cube split in six, none flat (Qhull made flat cells here)
        assert len(cells) == 6 * 5**3 and volumes.min() == 1 / 6
    # of each pair one is a vertex, the other points to it and is in no cell
    assert np.sum(duplicate_of >= 0) == 3
    left_out = np.flatnonzero(duplicate_of >= 0)
    np.testing.assert_array_equal(points[left_out], points[duplicate_of[left_out]])
    assert not np.isin(left_out, cells).any() and np.isin(duplicate_of[left_out], cells).all()


@settings(max_examples=60, deadline=None)
@given(st.integers(3, 6), st.floats(0.3, 1.0), st.integers(0, 2**32 - 1))
def test_delaunay_of_part_of_a_lattice_fills_its_hull_with_positive_cells(side, share, seed):
    # coplanar and cospherical points everywhere; before the quick kernel's check allowed for rounding,
    # 31 of 300 such sets kept a flat cell (its orientation 7e-18 in the scaled coordinates)
    grid = np.stack(np.meshgrid(*[np.arange(float(side))] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    points = grid[np.random.default_rng(seed).random(len(grid)) < share]
    assume(len(points) >= 4 and np.linalg.matrix_rank(points[1:] - points[0]) == 3)
    cells, _ = delaunay_3d(points)
    volumes = tetra_volumes(points, cells)  # exact: sixths of integers
    assert volumes.min() > 0 and volumes.sum() == pytest.approx(ConvexHull(points).volume, rel=1e-12)
    assert np.array_equal(np.unique(cells), np.arange(len(points)))


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (np.zeros((3, 3)), "cannot tetrahedralise 3 points"),
        (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [2, 3, 0]]), "do not span a volume"),
        (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, np.nan]]), "finite"),
        (np.zeros((5, 2)), r"shape \(n, 3\)"),
    ],
)
def test_delaunay_bad_inputs(points, message):
    with pytest.raises(GenerationError, match=message):
        delaunay_3d(points)


def test_coplanar_points_are_said_to_be_in_one_plane_in_one_line():
    """Qhull's own message runs to 20 lines of options (sweep run 50335, a box meeting a cylinder 0.001 deep)."""
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [2, 3, 0]]) @ np.array(
        [[1.0, 0, 0], [0, 0.6, 0.8], [0, -0.8, 0.6]]
    )
    with pytest.raises(GenerationError) as raised:
        delaunay_3d(points)
    message = str(raised.value)
    assert message.startswith("the points to tetrahedralise do not span a volume: they lie in one plane, 2.4 across")
    assert "(Qhull: QH6154" in message and "thinner than the mesh size" in message and "\n" not in message


def test_generate_mesh_dispatches_3d_domains():
    """tm.generate_mesh takes 3D domains with the same call as 2D (needs the dispatch line in distmesh.py)."""
    mesh = tm.generate_mesh(Box((0, 0, 0), (1, 1, 1)), 0.25, seed=0)
    assert mesh.dim == 3 and mesh.cells.shape[1] == 4 and mesh.info["min_dihedral"] >= 10


# --- coarse-to-fine levels -----------------------------------------------------------------------


def shell_graded(p):
    """SeismicMesh's ball benchmark at a size a test can afford (12,700 vertices): fine cells at r = 0.5."""
    return np.abs(np.sqrt(np.sum(p**2, axis=1)) - 0.5) / 5 + 0.045


@pytest.fixture(scope="module")
def ball_one_level_and_two():
    return [generate_mesh_3d(BALL, shell_graded, seed=0, levels=levels) for levels in (0, 1)]


def test_a_coarse_level_starts_the_fine_one_near_equilibrium(ball_one_level_and_two):
    single, refined = ball_one_level_and_two
    assert_valid(refined, BALL, 0.045, volume=4 / 3 * np.pi, rel=0.02)
    coarse, fine = refined.info["levels"]
    assert coarse["points"] == pytest.approx(fine["points"] / 8, rel=0.1)  # the size doubled: 8x fewer points
    # the fine level starts from the coarse mesh's vertices and midpoints: far fewer iterations and
    # tetrahedralisations than from seeds (82 and 7 here at one level)
    assert fine["iterations"] <= 0.5 * single.info["iterations"]
    assert fine["retriangulations"] <= 0.5 * single.info["retriangulations"]
    assert refined.info["iterations"] == fine["iterations"]


def test_a_coarse_level_keeps_the_sizes_and_the_quality(ball_one_level_and_two):
    def median_edge_ratio(mesh):
        edges = unique_edges(mesh.cells)
        a, b = mesh.points[edges[:, 0]], mesh.points[edges[:, 1]]
        return np.median(np.linalg.norm(b - a, axis=1) / shell_graded(0.5 * (a + b)))

    single, refined = ball_one_level_and_two
    assert median_edge_ratio(refined) == pytest.approx(median_edge_ratio(single), abs=0.03)
    assert refined.n_points == pytest.approx(single.n_points, rel=0.05)
    ratio_single, ratio_refined = (radius_ratio(mesh.points, mesh.cells) for mesh in (single, refined))
    assert ratio_refined.mean() >= ratio_single.mean() - 0.015
    assert np.percentile(ratio_refined, 1) >= np.percentile(ratio_single, 1) - 0.05


def test_levels_pass_through_generate_mesh_and_repeat_exactly():
    first = tm.generate_mesh(BALL, shell_graded, seed=3, levels=1)
    again = generate_mesh_3d(BALL, shell_graded, seed=3, levels=1)
    assert len(first.info["levels"]) == 2
    np.testing.assert_array_equal(first.points, again.points)
    np.testing.assert_array_equal(first.cells, again.cells)


def test_a_refined_box_keeps_its_corners_edges_and_fixed_points():
    box = Box((0, 0, 0), (1.0, 0.8, 0.6))
    fixed = np.array([[0.5, 0.4, 0.3]])
    mesh = generate_mesh_3d(box, 0.07, fixed_points=fixed, seed=0, levels=1)
    assert len(mesh.info["levels"]) == 2
    assert_valid(mesh, box, 0.07, volume=0.48, rel=1e-9)
    assert_follows_box(mesh, box)
    corners = np.array([[x, y, z] for x in (0, 1.0) for y in (0, 0.8) for z in (0, 0.6)])
    for point in np.vstack([corners, fixed]):
        assert np.min(np.linalg.norm(mesh.points - point, axis=1)) == 0.0


def test_the_refined_start_covers_an_islet_the_coarse_level_misses():
    # a ball 0.3 across next to the unit ball, meshed at 0.1: at the coarse size (0.2) it holds a point or
    # none, so its vertices and midpoints leave it bare; lattice points near its boundary fill it
    domain = tm.geometry.Union([BALL, Ball((1.5, 0, 0), 0.15)])
    size, h0, tolerance, fixed, _, _, _ = checked_options(domain, 0.1, None, domain.bbox, None, 300)
    start = distmesh3d._refined_start(domain, size, h0, domain.bbox, tolerance, fixed, 1, 0, 300, 1e-2, [])
    seeds, _ = bcc_seed_points(domain, size, h0, domain.bbox, np.random.default_rng(0), tolerance, band=2.0)
    gaps = cKDTree(start).query(seeds)[0] > 0.8 * size(seeds)
    assert not gaps.any()
    assert np.sum(start[:, 0] > 1.3) >= 8  # the islet has points of its own


def test_coarse_levels_in_3d_by_size_and_shape():
    from terramesh.generation.levels import coarse_levels

    assert coarse_levels(BALL, lambda p: np.full(len(p), 0.12), BALL.bbox) == 0  # 4,000 vertices: none
    assert coarse_levels(BALL, lambda p: np.full(len(p), 0.05), BALL.bbox) == 1  # 55,000: one
    assert coarse_levels(BALL, lambda p: np.full(len(p), 0.02), BALL.bbox) == 1  # 860,000: one (at most)
    slab = Box((0, 0, 0), (4, 4, 0.15))  # as many vertices, a third of them on its faces at half the size
    assert coarse_levels(slab, lambda p: np.full(len(p), 0.03), slab.bbox) == 0


def test_a_refined_start_the_clean_up_refuses_is_meshed_again_at_one_level(monkeypatch):
    finalize, calls = distmesh3d.finalize_3d, []

    def refuses_the_first(*args, **kwargs):
        calls.append(len(args[2]))
        if len(calls) == 1:
            raise GenerationError("2 slivers remain")
        return finalize(*args, **kwargs)

    monkeypatch.setattr(distmesh3d, "finalize_3d", refuses_the_first)
    mesh = generate_mesh_3d(BALL, 0.15, seed=0, levels=1)
    assert len(calls) == 2 and len(mesh.info["levels"]) == 1
    assert_valid(mesh, BALL, 0.15, volume=4 / 3 * np.pi, rel=0.03)
    calls.clear()
    with pytest.raises(GenerationError, match="2 slivers remain"):
        generate_mesh_3d(BALL, 0.15, seed=0, levels=0)  # at one level the refusal stands


def test_a_refined_start_keeps_a_cylinders_side_at_its_size():
    # the coarse level's flat cells across the side have diagonals that are no boundary edges: their midpoints,
    # a sag inside, were pushed onto the side, which came out with 3,587 vertices where one level gives 2,021 and
    # 376 side edges under half their size; left out, the side had gaps (90 side edges over 1.6 sizes, one level 8)
    cylinder = Cylinder((0, 0, 0), 1.0, 2.0)
    meshes = [generate_mesh_3d(cylinder, 0.08, seed=0, levels=levels) for levels in (0, 1)]
    counts, short, long = [], [], []
    for mesh in meshes:
        points = mesh.points
        side = (np.abs(np.hypot(points[:, 0], points[:, 1]) - 1) < 1e-9) & (np.abs(points[:, 2]) < 1 - 1e-9)
        edges = unique_edges(mesh.cells)
        edges = edges[side[edges].all(axis=1)]
        ratios = np.linalg.norm(points[edges[:, 1]] - points[edges[:, 0]], axis=1) / 0.08
        counts.append(side.sum())
        short.append(np.sum(ratios < 0.5))
        long.append(np.sum(ratios > 1.6))
    assert counts[1] < 1.35 * counts[0]  # 2,563 against 2,021 when written
    assert short[1] < 60  # 26 when written
    assert long[1] <= max(2 * long[0], 10)  # 1 against 8
    assert_valid(meshes[1], cylinder, 0.08, volume=2 * np.pi, rel=0.02)


@pytest.mark.parametrize("h", [0.05, 0.08])
@pytest.mark.parametrize("degrees", [20, 30, 45, 60])
def test_a_function_domain_told_its_sharp_edges_meshes_valid(degrees, h):
    # without its edges each of these raised (rounded edges: slivers, or faces cutting across)
    domain = wedge_prism(degrees, told=True)
    mesh = generate_mesh_3d(domain, h)
    assert_valid(mesh, domain, h, volume=0.15 * np.tan(np.radians(degrees)), rel=1e-9)
    # the edges' ends are vertices, exactly
    assert cKDTree(mesh.points).query(domain.corners())[0].max() == 0.0


def test_flips_toward_30_degrees_raise_the_poorest_cells(monkeypatch):
    """After the sliver removal, flips alone: the same points, the smallest angles and the worst cells raised."""

    def size(p):
        return 0.06 + 0.1 * np.sqrt(np.sum(p**2, axis=1))

    flipped = generate_mesh_3d(BALL, size, seed=0)
    monkeypatch.setattr(slivers, "FLIP_AIM", 0.0)
    plain = generate_mesh_3d(BALL, size, seed=0)
    assert_valid(flipped, BALL, 0.06, volume=4 / 3 * np.pi, rel=0.02)
    assert flipped.n_points == plain.n_points
    smallest = {name: min_max_dihedral(m.points, m.cells)[0] for name, m in (("flipped", flipped), ("plain", plain))}
    assert smallest["flipped"].min() > smallest["plain"].min() + 5.0  # 17.1 -> 27.4 degrees when written
    assert np.mean(smallest["flipped"] < 20.0) < 0.2 * np.mean(smallest["plain"] < 20.0)
    worst = {
        name: np.percentile(radius_ratio(m.points, m.cells), 1) for name, m in (("flipped", flipped), ("plain", plain))
    }
    assert worst["flipped"] > worst["plain"] + 0.05  # first percentile 0.56 -> 0.68
