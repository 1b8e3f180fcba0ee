import logging
import warnings

import numpy as np
import pyogrio
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.errors import GenerationError, SizingError, TerrameshWarning
from terramesh.mesh.topology import signed_areas
from terramesh.quality import edge_length_ratio, triangle_quality

from ..conftest import assert_valid, random_walk_coast


@pytest.fixture(scope="module")
def disk_mesh():
    return tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.02, seed=0)


def test_uniform_disk_meets_the_quality_bars(disk_mesh):
    quality = triangle_quality(disk_mesh.points, disk_mesh.cells)
    assert quality.mean() >= 0.98
    assert quality.min() >= 0.70
    expected_cells = np.pi / (np.sqrt(3) / 4 * 0.02**2)
    assert abs(disk_mesh.n_cells / expected_cells - 1) < 0.10
    assert_valid(disk_mesh, tm.geometry.Disk((0, 0), 1), 0.02)


def test_generation_stops_before_max_iter_and_says_why(disk_mesh):
    info = disk_mesh.info
    assert info["stop_reason"] in {"converged", "stalled"}
    assert info["iterations"] < 300
    assert info["retriangulations"] >= 1 and info["seconds"] > 0


def test_area_is_covered(disk_mesh):
    area = tm.mesh.topology.signed_areas(disk_mesh.points, disk_mesh.cells).sum()
    assert area == pytest.approx(np.pi, rel=2e-3)


def test_graded_plate_meets_the_quality_and_fidelity_bars(plate_with_hole):
    domain, edge_length = plate_with_hole
    mesh = tm.generate_mesh(domain, edge_length=edge_length, h0=0.01, seed=0)
    quality = triangle_quality(mesh.points, mesh.cells)
    assert quality.min() >= 0.6
    assert quality.mean() >= 0.97
    ratio = np.median(edge_length_ratio(mesh.points, mesh.cells, edge_length))
    assert 0.9 <= ratio <= 1.15
    assert_valid(mesh, domain, 0.01)
    # the rectangle's corners are vertices
    for corner in [(0, 0), (2, 0), (2, 1), (0, 1)]:
        assert np.min(np.linalg.norm(mesh.points - corner, axis=1)) < 1e-12


@pytest.mark.parametrize(("offset", "h"), [(1e7, 0.02), (1e6, 0.002)])
def test_domains_projected_by_finite_differences_far_from_the_origin(offset, h):
    # a disk cut from a square at UTM-like northings: the step sqrt(eps) h0 was below the rounding of the distance
    # there, and the boundary vertices ended 0.7-1.6 sizes off the boundary, min q 0.21-0.34, without a word
    r = 20 * h
    domain = tm.geometry.Difference(
        [
            tm.geometry.Rectangle((offset - r, offset - r), (offset + r, offset + r)),
            tm.geometry.Disk((offset, offset), r / 2),
        ]
    )
    mesh = tm.generate_mesh(domain, h, seed=0)
    assert tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * h) == []
    assert triangle_quality(mesh.points - offset, mesh.cells).min() > 0.7
    area = signed_areas(mesh.points - offset, mesh.cells).sum()
    assert area == pytest.approx(4 * r * r - np.pi * r * r / 4, rel=2e-3)


@pytest.mark.parametrize("angle", [10, 12, 15])
@pytest.mark.parametrize("fixed", [False, True])
def test_an_acute_corner_stays_a_vertex(angle, fixed):
    # the cells filling a corner sharper than about 12 degrees are flat (q < 0.3) with every vertex on the
    # boundary: they were dropped with the corner, a fixed point or not, and the mesh stopped short of the tip
    a = np.radians(angle)
    wedge = tm.geometry.Polygon([[(0, 0), (1, 0), (np.cos(a), np.sin(a))]])
    mesh = tm.generate_mesh(wedge, 0.05, fixed_points=[(0.0, 0.0)] if fixed else None, seed=0)
    assert np.any(np.all(mesh.points == 0.0, axis=1))
    assert signed_areas(mesh.points, mesh.cells).sum() == pytest.approx(0.5 * np.sin(a), rel=1e-9)
    assert tm.cleanup.mesh_problems(mesh, wedge) == []


def test_graded_and_uniform_meshes_follow_their_sizes_without_a_warning():
    for size in [0.05, lambda p: 0.01 + 0.2 * np.abs(p[:, 0] - 0.3), lambda p: 0.005 * (1 + 24.5 * (p[:, 0] + 1))]:
        with warnings.catch_warnings():
            warnings.simplefilter("error", TerrameshWarning)
            tm.generate_mesh(tm.geometry.Disk((0, 0), 1), size, seed=0)


def test_gridded_size_field(plate_with_hole):
    domain, _ = plate_with_hole
    x, y = np.linspace(0, 2, 41), np.linspace(0, 1, 21)
    grid = tm.sizing.SizeGrid((x, y), 0.03 + 0.04 * x[:, None] + 0 * y[None, :])
    mesh = tm.generate_mesh(domain, grid, seed=0)
    assert mesh.info["h0"] == pytest.approx(0.03)
    ratio = edge_length_ratio(mesh.points, mesh.cells, grid)
    assert 0.9 <= np.median(ratio) <= 1.15
    assert_valid(mesh, domain, 0.03)


def test_same_seed_same_mesh(plate_with_hole):
    domain, _ = plate_with_hole
    edge_length = lambda p: 0.03 + 0.2 * np.abs(domain.distance(p))  # noqa: E731
    first = tm.generate_mesh(domain, edge_length, seed=7)
    second = tm.generate_mesh(domain, edge_length, seed=7)
    np.testing.assert_array_equal(first.points, second.points)
    np.testing.assert_array_equal(first.cells, second.cells)


def test_fixed_points_are_kept():
    fixed = np.array([[0.0, 0.0], [0.5, 0.25]])
    mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, fixed_points=fixed)
    for point in fixed:
        assert np.min(np.linalg.norm(mesh.points - point, axis=1)) == 0.0
    with pytest.raises(GenerationError, match="outside the domain"):
        tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, fixed_points=[[3.0, 0.0]])


def test_fixed_points_on_the_boundary_stay_to_the_bit():
    # points along a cut of the disk, fixed: the strip's distance put them a rounding outside and the
    # projection moved every one by an ulp, so two strips meshed side by side did not share them
    cut = -0.26888284412955465
    strip = tm.geometry.Disk((0, 0), 1) & tm.geometry.Rectangle((-1, -1), (cut, 1))
    end = np.sqrt(1 - cut**2)
    fixed = np.column_stack([np.full(97, cut), np.linspace(-end, end, 99)[1:-1]])
    mesh = tm.generate_mesh(strip, 0.02, fixed_points=fixed, seed=0)
    assert (mesh.points[:, None, :] == fixed[None]).all(axis=2).any(axis=0).all()


@pytest.fixture(scope="module")
def hebrides_water(shared_data):
    """Water around the Outer Hebrides from Natural Earth 1:50m: several parts with island holes."""
    box = (-8.0, 56.0, -5.0, 58.5)
    _, _, wkb, _ = pyogrio.raw.read(shared_data / "coast" / "ne_50m_land.shp", bbox=box)
    land = shapely.union_all(shapely.clip_by_rect(shapely.from_wkb(wkb), *box))
    water = shapely.difference(shapely.box(*box), land)
    assert sum(len(part.interiors) for part in shapely.get_parts(water)) >= 3
    return tm.geometry.Polygon.from_shapely(water)


def test_real_coastline_polygon_gives_a_valid_mesh(hebrides_water):
    with pytest.warns(TerrameshWarning, match=r"1 disjoint part with no cells \(the longest 0.0172 long"):
        mesh = tm.generate_mesh(hebrides_water, 0.04, seed=0)
    assert_valid(mesh, hebrides_water, 0.04)
    assert tm.quality.summary(mesh).mean > 0.9
    area = tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum()
    assert area == pytest.approx(hebrides_water.geometry.area, rel=0.03)


def test_jagged_coastline_leaves_no_flat_cell(shared_data):
    # GSHHS water of the US East Coast and Gulf, graded from 0.1 degrees at the coast (bench_coastal.py).
    # The final projection once laid three vertices onto one straight stretch of coast (q 1e-14), and
    # points that crowded together after the last look (its rounds spent) left a cell of q 0.03
    shore = tm.coastal.Shoreline.read(shared_data / "coast" / "GSHHS_l_L1.shp", (-100, -50, 10, 60), 5e3)
    domain = tm.geometry.Polygon.from_shapely(shore.water)
    x, y = np.linspace(-100, -50, 501), np.linspace(10, 60, 501)
    grid = np.stack(np.meshgrid(x, y, indexing="ij"), axis=-1).reshape(-1, 2)
    coast_distance = np.abs(domain.distance(grid)).reshape(501, 501)
    size = tm.sizing.SizeGrid((x, y), np.minimum(0.1 + 0.2 * coast_distance, 0.5))
    # a barrier island of the Laguna Madre, narrower than the cells, is meshed over, and said so
    with pytest.warns(TerrameshWarning, match=r"1 hole covered by cells \(the longest 0.717 long, near \(-97.7"):
        mesh = tm.generate_mesh(domain, size, h0=0.1, seed=0)
    assert_valid(mesh, domain, 0.1)
    quality = triangle_quality(mesh.points, mesh.cells)
    assert quality.min() > 0.2 and quality.mean() > 0.96


def test_no_two_vertices_end_on_one_spot_of_a_coastline(shared_data):
    # the Croatian coast: a vertex off the boundary was projected onto a fixed corner another vertex
    # held (GSHHS), or two boundary vertices slid onto one coastline vertex in the smoothing (Natural
    # Earth 1:10m): two vertices on one spot with a pinch between them
    for source, size in (("GSHHS_l_L1.shp", 0.05), ("ne_10m_land.shp", 0.1206)):
        shore = tm.coastal.Shoreline.read(shared_data / "coast" / source, (13.5, 17.5, 42.5, 45.5), 3e3)
        domain = tm.geometry.Polygon.from_shapely(shore.water)
        mesh = tm.generate_mesh(domain, size, seed=0)
        assert_valid(mesh, domain, size)


def test_boundary_vertices_of_a_gridded_domain_end_on_its_boundary(shared_data):
    # the salt of a 2D velocity model as a GridDomain: its interpolated distance bends between
    # nodes, so one Newton step left boundary vertices up to 4 % of h off it
    model = tm.seismic.read_velocity(shared_data / "seismic" / "vel_z6.25m_x12.5m_exact.segy")
    axes = (model.axes[0][::16], model.axes[1][::16])
    salt = tm.geometry.GridDomain.from_mask(axes, model.values[::16, ::16] >= 4400)
    mesh = tm.generate_mesh(salt, 200.0, seed=0)
    assert_valid(mesh, salt, 200.0)


def test_progress_is_logged(caplog, plate_with_hole):
    domain, _ = plate_with_hole
    with caplog.at_level(logging.INFO, logger="terramesh"):
        tm.generate_mesh(domain, 0.05, levels=1)
    assert "stopped after" in caplog.text
    # each level said as it starts, with its points: a 10^6-vertex run was silent for its levels
    assert "level 1 of 2 (sizes x 2): " in caplog.text and "level 2 of 2 (sizes x 1): " in caplog.text


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0), SizingError, "positive"),
        (lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), float("nan")), SizingError, "positive"),
        (
            lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), lambda p: -np.ones(len(p)), h0=0.1),
            SizingError,
            "negative",
        ),
        (
            lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), lambda p: np.full(len(p), np.nan), h0=0.1),
            SizingError,
            "NaN",
        ),
        (lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, bbox=[(5, 5), (6, 6)]), GenerationError, "misses"),
        (lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, h0=-1), GenerationError, "h0"),
        (lambda: tm.generate_mesh(lambda p: np.ones(len(p)), 0.1, bbox=[(0, 0), (1, 1)]), GenerationError, "misses"),
        (lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1)), GenerationError, "edge_length"),
        (lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, bbox=[0, 0, 1, 1]), ValueError, "shape"),
        (lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, max_iter=0), GenerationError, "max_iter"),
        (lambda: tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, move_tolerance=0), GenerationError, "positive"),
        (  # it said "cannot triangulate 1 points", beside a square whose four corners are fixed
            lambda: tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 2.0),
            GenerationError,
            r"only 1 point fit in the domain \(its bbox 1 x 1\): h0=2 is too large for it",
        ),
        (
            lambda: tm.generate_mesh(tm.geometry.Ball((0, 0, 0), 1), 0.3, move_tolerance=np.nan),
            GenerationError,
            "move_",
        ),
        (
            lambda: tm.generate_mesh(tm.geometry.Disk((10, 10), 1), 0.1, bbox=[(0, 0), (1, 1)]),
            GenerationError,
            "no lattice point falls inside the domain: it is empty, the bbox misses it",
        ),
        (  # a difference that leaves nothing: named as empty, among the causes (it read "the bbox misses it")
            lambda: tm.generate_mesh(
                tm.geometry.Difference(
                    [tm.geometry.Rectangle((0, 0), (1, 1)), tm.geometry.Rectangle((-1, -1), (2, 2))]
                ),
                0.1,
            ),
            GenerationError,
            "no lattice point falls inside the domain: it is empty",
        ),
        (lambda: tm.geometry.Polygon([[(0, 0), (1, 1), (1, 0), (0, 1)]]), ValueError, "self-intersect"),
        # no cell inside at all: the truss kernel divided by a sum over no edge (ZeroDivisionError from numba)
        (
            lambda: tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 0.05)), 0.5),
            GenerationError,
            "no cell survived: the domain is too small or thin for the mesh size",
        ),
        (
            lambda: tm.generate_mesh(tm.geometry.Polygon([(0, 0), (1, 0), (0.5, 0.1)]), 0.6),
            GenerationError,
            "too small or thin",
        ),
        (lambda: tm.generate_mesh(tm.geometry.Box((0, 0, 0), (1, 1, 0.05)), 0.5), GenerationError, "too small or thin"),
        # a ball about two sizes across whose last cells the sliver clean-up took (sweep run 30060: a
        # ValueError from numpy's minimum over no cell)
        (
            lambda: tm.generate_mesh(
                tm.geometry.Ball((0.1957, 0.3230, 0.4712), 0.4704),
                lambda p: 0.1708 * (1 + 2.9 * (2 + p @ np.array([0.6, -0.48, 0.64])) / 4),
                h0=0.1708,
                seed=42,
                levels=0,
            ),
            GenerationError,
            "no cell survived",
        ),
    ],
)
def test_bad_input_raises_clear_errors(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_refinement_keeps_midpoints_off_each_others_spot():
    """Boundary midpoints projected onto one coastline vertex: one is left out, not a triangulation from scratch."""
    coast = random_walk_coast(5000, 0)
    mesh = tm.generate_mesh(coast, 0.015, levels=1, seed=0)
    # before: one such pair made the refinement rebuild six times, and the fine level twice
    assert [level["rebuilds"] for level in mesh.info["levels"]] == [0, 0]
    assert_valid(mesh, coast, 0.015)
    assert len(tm.mesh.topology.coincident_points(mesh.points)) == 0


def slotted(width, depth=0.5, x=1.0):
    """A 2 x 1 rectangle with a slot ``width`` wide and ``depth`` deep from its bottom side at ``x``."""
    ring = [(0, 0), (x - width / 2, 0), (x, depth), (x + width / 2, 0), (2, 0), (2, 1), (0, 1)]
    return tm.geometry.Polygon(np.array(ring, dtype=float))


def test_a_slot_narrower_than_the_size_is_refused_not_meshed_over():
    # a pier gap 0.01 wide at h = 0.05: cells overlapping by 3.35e-6 and a hole 0.27 away were returned, with a
    # warning of "a corner the domain does not report"
    with pytest.raises(GenerationError, match=r"invalid mesh: a boundary vertex 1.7 sizes off .* at \(1.2"):
        tm.generate_mesh(slotted(0.01), 0.05)


@settings(max_examples=25, deadline=None)
@given(
    width=st.floats(0.001, 2.0),
    depth=st.floats(0.1, 0.8),
    x=st.floats(0.3, 1.7),
    offset=st.sampled_from([0.0, 5e5]),
    seed=st.integers(0, 3),
)
def test_a_slot_of_any_width_gives_a_valid_mesh_or_a_clear_error(width, depth, x, offset, seed):
    # 240 of 250 thin features in a review came out valid; the others overlapped, hung or had holes, silently
    h = 0.05
    domain = slotted(width * h, depth, x)
    if offset:  # at UTM coordinates, where the slot's sides are a few metres' rounding apart
        domain = tm.geometry.Polygon(domain.rings[0] + offset)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TerrameshWarning)
            mesh = tm.generate_mesh(domain, h, seed=seed)
    except GenerationError as error:
        assert "narrower than about an edge length" in str(error) or "no cell survived" in str(error)
        return
    assert tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=0.5 * h) == []


def test_boundary_vertices_left_off_the_boundary_are_warned_of():
    # two disks' union as one callable reports no corners: the boundary vertex at each was projected back
    # and forth across it and stayed 0.043 sizes inside, without a word
    def union(p):
        return np.minimum(np.hypot(p[:, 0], p[:, 1]) - 1, np.hypot(p[:, 0] - 1.9, p[:, 1]) - 1)

    domain = tm.geometry.FunctionDomain(union, [(-1, -1), (2.9, 1)])
    with pytest.warns(TerrameshWarning, match="off the domain's boundary after 10 repair passes") as caught:
        mesh = tm.generate_mesh(domain, 0.05)
    off = [w for w in caught if "repair passes" in str(w.message)]
    assert "(0.9" in str(off[0].message)  # where: a corner at (0.95, +-0.312)
    edges = tm.mesh.topology.boundary_edges(mesh.cells)
    assert np.abs(domain.distance(mesh.points[np.unique(edges)])).max() > 1e-3 * 0.05
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tm.generate_mesh(tm.geometry.Disk((0, 0), 1) | tm.geometry.Disk((1.9, 0), 1), 0.05)  # corners found
