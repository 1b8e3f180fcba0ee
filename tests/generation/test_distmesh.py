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

from ..conftest import assert_valid, random_walk_coast, wedge_with_its_tip_fixed


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


def test_h0_is_the_smallest_size_on_the_boundary_too():
    """A size graded from the boundary is smallest there, between the sample's points: they missed it by 39 %."""
    size = lambda p: 0.01 + 0.5 * p[:, 1]  # noqa: E731
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 2)), size, seed=0)
    assert mesh.info["h0"] == pytest.approx(0.01, rel=1e-9)  # was 0.0139, a sample step up
    disk = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), lambda p: 0.03 + 0.3 * np.abs(1 - np.hypot(*p.T)), seed=0)
    assert disk.info["h0"] == pytest.approx(0.03, rel=1e-6)


@pytest.mark.parametrize("given", ["callable", "h0", "SizeGrid"])
def test_a_fine_spot_the_seeding_steps_over_is_warned_of(given):
    """The lattices refine only around sites whose own size is small: a spot 0.04 wide at 1e-3 in a unit square,
    between the coarsest sites, got none of its 1,450 vertices and the mesh 50, silently with h0 given or a
    SizeGrid."""
    centre = np.array([0.437, 0.611])

    def size(p):
        return np.where(np.hypot(*(p - centre).T) < 0.02, 1e-3, 0.2)

    edge_length, options = size, {"h0": 1e-3} if given == "h0" else {}
    if given == "SizeGrid":
        x = np.linspace(0, 1, 501)
        grid = np.stack(np.meshgrid(x, x, indexing="ij"), -1).reshape(-1, 2)
        edge_length, options = tm.sizing.SizeGrid((x, x), size(grid).reshape(501, 501)), {}
    with pytest.warns(TerrameshWarning, match=r"the mesh has \d+ vertices where its sizes ask for about \d+ \(near"):
        mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), edge_length, seed=0, **options)
    assert np.sum(np.hypot(*(mesh.points - centre).T) < 0.02) == 0


def test_a_spot_seeded_whole_and_lost_as_the_mesh_settles_is_warned_of():
    """A spot 0.012 across at 1e-3, off the coarsest sites: seeded (131 of its vertices) and lost to the last one
    as the forces settled the 200x jump around it."""
    centre = np.array([0.5, 0.5])  # a site of every lattice level

    def size(p):
        return np.where(np.hypot(*(p - centre).T) < 0.006, 1e-3, 0.2)

    with pytest.warns(TerrameshWarning, match=r"sizes change faster than a mesh can follow"):
        mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), size, h0=1e-3, seed=0)
    assert np.sum(np.hypot(*(mesh.points - centre).T) < 0.006) < 10


@pytest.mark.parametrize("length", [30, 100])
def test_a_long_strip_draws_no_warning_of_missed_sizes(length):
    # its 16 x 16 blocks were 1/16 high, below the mesh's row spacing (0.087): some held no vertex and warned
    strip = tm.geometry.Rectangle((0, 0), (length, 1))
    mesh = tm.generate_mesh(strip, 0.1, seed=0)  # the tests turn warnings into errors
    assert tm.cleanup.mesh_problems(mesh, strip) == []


def test_a_generous_bbox_is_sampled_again_around_the_domain():
    # the unit disk in +-100: 5 of the bbox's sample points inside, an area of 2.44 ("covers 129 %", warned) and
    # h0 estimated from 5 sizes
    disk = tm.geometry.Disk((0, 0), 1)

    def size(p):
        return 0.02 + 0.1 * np.abs(p[:, 0])

    loose = tm.generate_mesh(disk, size, bbox=[(-100, -100), (100, 100)], seed=0)
    snug = tm.generate_mesh(disk, size, seed=0)
    assert loose.info["h0"] == pytest.approx(snug.info["h0"], rel=0.05)
    assert tm.cleanup.mesh_problems(loose, disk) == []
    assert signed_areas(loose.points, loose.cells).sum() == pytest.approx(np.pi, rel=0.01)


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


def test_a_bbox_that_cuts_the_domain_is_refused():
    # it was meshed past the bbox: 51 vertices, 38 outside it, cells over 393 % of the quarter disk
    with pytest.raises(GenerationError, match=r"reaches out of the bbox .*tm\.geometry\.Intersection"):
        tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, bbox=[[0, 0], [1, 1]], seed=0)
    quarter = tm.geometry.Intersection([tm.geometry.Disk((0, 0), 1), tm.geometry.Rectangle((0, 0), (1, 1))])
    mesh = tm.generate_mesh(quarter, 0.1, seed=0)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum() == pytest.approx(np.pi / 4, rel=0.01)


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


def test_max_iter_warns():
    with pytest.warns(TerrameshWarning, match="max_iter=2") as record:
        mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, max_iter=2)
    assert mesh.info["stop_reason"] == "max_iter"
    assert {warning.filename for warning in record} == {__file__}  # the user's line, not terramesh's


@pytest.mark.parametrize(
    ("domain", "edge_length"),
    [
        (tm.geometry.Disk((0, 0), 1), lambda p: 0.05 + 0.1 * np.abs(p[:, 0])),
        (tm.geometry.Ball((0, 0, 0), 1), lambda p: 0.15 + 0.1 * np.abs(p[:, 0])),  # through generate_mesh_3d
    ],
)
def test_size_below_h0_warns_at_the_users_line(domain, edge_length):
    with pytest.warns(TerrameshWarning, match="below h0") as record:
        tm.generate_mesh(domain, edge_length, h0=0.2 if domain.dim == 3 else 0.1)
    assert {warning.filename for warning in record if "below h0" in str(warning.message)} == {__file__}


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
            "no lattice point falls inside the domain: the bbox misses it",
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


@pytest.mark.parametrize(
    "option, message",
    [
        ({"h0": "a"}, "h0 must be positive and finite"),
        ({"max_iter": np.nan}, "max_iter must be a whole number of at least 1, got nan"),
        ({"max_iter": "x"}, "max_iter must be a whole number"),
        ({"max_iter": 2.5}, "max_iter must be a whole number"),
        ({"move_tolerance": None}, "move_tolerance must be positive and finite"),
        ({"seed": -1}, "seed must be a non-negative integer, got -1"),
        ({"seed": 1.5}, "seed must be a non-negative integer"),
        ({"seed": "x"}, "seed must be a non-negative integer"),
        ({"fixed_points": "abc"}, r"fixed_points must be numbers, shape \(k, 2\)"),
    ],
)
def test_options_of_the_wrong_type_are_named(option, message):
    # each gave a ValueError, OverflowError or TypeError from Python or NumPy
    for domain in (tm.geometry.Rectangle((0, 0), (1, 1)), tm.geometry.Box((0, 0, 0), (1, 1, 1))):
        if domain.dim == 3 and "fixed_points" in option:
            continue
        with pytest.raises(GenerationError, match=message):
            tm.generate_mesh(domain, 0.4, **option)


def test_fixed_points_on_one_spot_to_rounding_are_merged():
    # 1e-9 apart, both were kept: the mesh had a hole a quarter of the square (area 0.56, no error)
    square = tm.geometry.Rectangle((0, 0), (1, 1))
    with pytest.warns(TerrameshWarning, match="1 fixed points lie within 0.0001"):
        mesh = tm.generate_mesh(square, 0.1, fixed_points=[[0.5, 0.5], [0.5, 0.5 + 1e-9]])
    assert_valid(mesh, square, 0.1)
    assert tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum() == pytest.approx(1.0)
    assert np.any(np.all(mesh.points == [0.5, 0.5], axis=1))


@pytest.mark.parametrize(
    "domain, size",
    [
        (tm.geometry.Rectangle((0, 0), (1e5, 1e5)), 0.5),  # a square of 100 km meshed at 0.5: metres for km
        (tm.geometry.Rectangle((0, 0), (1, 1)), 1e-300),
        (tm.geometry.Box((0, 0, 0), (1e3, 1e3, 1e3)), 0.5),
    ],
)
def test_sizes_asking_more_vertices_than_memory_holds_are_refused_at_once(domain, size):
    # the first ran 67 s and ran out of memory deep in the seeding; the second overflowed formatting an error
    with pytest.raises(GenerationError, match=r"the sizes ask for about .* vertices .* same units\?"):
        tm.generate_mesh(domain, size)


def test_callable_domain_with_empty_inside():
    with pytest.raises(GenerationError, match="empty"):
        tm.generate_mesh(lambda p: np.ones(len(p)), lambda p: np.full(len(p), 0.1), bbox=[(0, 0), (1, 1)])


def test_domain_corners_closer_than_half_a_size_are_not_all_fixed():
    """Pinned: a coastline resampled near h0 had sharp kinks 4 % of h apart, both fixed, pinning a sliver pair."""
    notch = tm.geometry.Polygon([(0, 0), (1, 0), (1, 1), (0.5, 1), (0.5, 0.6), (0.49, 0.6), (0.49, 1), (0, 1)])
    mesh = tm.generate_mesh(notch, 0.25, seed=0)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.quality.summary(mesh).min > 0.3


def test_refinement_keeps_midpoints_off_each_others_spot():
    """Boundary midpoints projected onto one coastline vertex: one is left out, not a triangulation from scratch."""
    coast = random_walk_coast(5000, 0)
    mesh = tm.generate_mesh(coast, 0.015, levels=1, seed=0)
    # before: one such pair made the refinement rebuild six times, and the fine level twice
    assert [level["rebuilds"] for level in mesh.info["levels"]] == [0, 0]
    assert_valid(mesh, coast, 0.015)
    assert len(tm.mesh.topology.coincident_points(mesh.points)) == 0


def test_features_thinner_than_the_sizes_are_warned_about():
    # a strip 20 wide meshed at 100 is left out (the disk at its end meshed alone, "converged"); a hole 17
    # wide in a strip 57 wide meshed at 50 is bridged by cells: both came back without a word
    bulb = tm.geometry.Union([tm.geometry.Rectangle((0, -10), (10000, 10)), tm.geometry.Disk((0, 0), 200)])
    with pytest.warns(TerrameshWarning, match=r"covers 40 % of the domain's area .* parts thinner than the mesh"):
        tm.generate_mesh(bulb, 100.0)
    strip = tm.geometry.Polygon(
        [[(0, 0), (3000, 0), (3000, 57), (0, 57)], [(100, 20), (2900, 20), (2900, 37), (100, 37)]]
    )
    with pytest.warns(TerrameshWarning, match=r"covers 1\d\d % of the domain's area .* cells bridge gaps or holes"):
        tm.generate_mesh(strip, 50.0)


def test_holes_and_parts_smaller_than_the_cells_are_named():
    # a hexagonal hole 0.04 across and a square part 0.03 across beside a unit square meshed at 0.1: both were
    # gone without a word, the area covered within 0.2 % of the domain's
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    angles = np.linspace(0, 2 * np.pi, 7)[:-1]
    hole = np.column_stack([0.3 + 0.02 * np.cos(angles), 0.6 + 0.02 * np.sin(angles)])
    part = [(2, 0), (2.03, 0), (2.03, 0.03), (2, 0.03)]
    island_in_hole = [(0.7, 0.2), (0.8, 0.2), (0.8, 0.3), (0.7, 0.3)]
    big_hole = [(0.6, 0.1), (0.9, 0.1), (0.9, 0.4), (0.6, 0.4)]
    domain = tm.geometry.Polygon([square, hole, part, big_hole, island_in_hole])
    with pytest.warns(TerrameshWarning) as caught:
        mesh = tm.generate_mesh(domain, 0.1)
    messages = [str(warning.message) for warning in caught]
    assert len(messages) == 1, messages
    assert "1 hole covered by cells and 1 disjoint part with no cells" in messages[0]
    assert "the longest 0.04 long, near (0.3, 0.6), where the size is 0.1" in messages[0]
    assert_valid(mesh, domain, 0.1)
    # the hole 0.3 across and the island 0.1 across in it are meshed: no word of them
    assert np.any(np.all(np.isclose(mesh.points, (0.8, 0.3)), axis=1))
    assert np.any(np.all(np.isclose(mesh.points, (0.9, 0.4)), axis=1))
    # at sizes that fit them, every ring is in the mesh, and nothing is said
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fine = tm.generate_mesh(domain, lambda p: np.where(np.abs(p[:, 0] - 1.15) > 0.8, 0.008, 0.1), h0=0.008)
    assert fine.points[:, 0].max() == pytest.approx(2.03)


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


@pytest.mark.parametrize(
    ("fixed", "words"),
    [
        ([(0.5, 0.009)], "1 fixed points lie less than half a size inside the boundary, e.g. (0.5, 0.009), 0.09"),
        ([(0.01, 0.0)], "1 of the domain's corners are no vertices, being within half a size of a fixed point"),
    ],
)
def test_fixed_points_that_crowd_the_boundary_are_warned_of(fixed, words):
    # a gauge 0.009 inside a square's side became a boundary vertex 0.009 off it, and one 0.01 from a
    # corner took the corner's place: the cells cut across it. Neither said a word
    square = tm.geometry.Rectangle((0, 0), (1, 1))
    with pytest.warns(TerrameshWarning, match=words.replace("(", r"\(").replace(")", r"\)")):
        tm.generate_mesh(square, 0.1, fixed_points=fixed)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tm.generate_mesh(square, 0.1, fixed_points=[(0.5, 0.5), (0.5, 0.0), (0.0, 0.0)])


def test_meshing_in_strips_warns_of_the_users_points_alone():
    square = tm.geometry.Rectangle((0, 0), (2, 1))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tm.parallel.generate_mesh_parallel(square, 0.1, parts=3, fixed_points=[(0.5, 0.03)])
    crowding = [w for w in caught if "less than half a size" in str(w.message)]
    assert len(crowding) == 1 and "(0.5, 0.03)" in str(crowding[0].message)


def test_a_uniform_mesh_draws_no_warning_of_missed_sizes():
    # a ring with a bar across, at one size: rows of the bar's vertices just past a block's edge left the
    # block with 5 of the 10 vertices its sizes ask for, and the mesh was said to miss its sizes
    domain = (tm.geometry.Disk((0, 0), 1) - tm.geometry.Disk((0, 0), 0.7)) | tm.geometry.Rectangle(
        (-1.2, -0.1), (1.2, 0.1)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = tm.generate_mesh(domain, 0.05)
    assert 0.95 < np.median(edge_length_ratio(mesh.points, mesh.cells, lambda p: np.full(len(p), 0.05))) < 1.05


def test_receivers_along_a_model_boxs_straight_top_draw_no_corner_warning():
    # the box's side nodes are corners only in name (on straight sides): 14 were said to be cut across
    velocity = np.where(np.arange(41)[:, None] < 20, 1500.0, 3000.0) * np.ones((41, 161))
    model = tm.seismic.read_velocity(velocity, spacing=25.0, axis_order="zx")
    size = tm.seismic.size_function(model, frequency=5, hmin=50, grade=0.2)
    receivers = np.column_stack([np.arange(100.0, 3900.0, 25.0), np.zeros(152)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = tm.generate_mesh(size.domain, size, fixed_points=receivers, seed=0)
    assert tm.cleanup.mesh_problems(mesh) == []


def test_an_anisotropic_mesh_warns_of_the_users_fixed_points_by_a_corner():
    square = tm.geometry.Rectangle((0, 0), (1, 1))
    metric = tm.sizing.metric_tensor(0.1, 0.1, 0.0)
    with pytest.warns(TerrameshWarning, match="1 of the domain's corners are no vertices") as caught:
        tm.generate_anisotropic_mesh(square, metric, fixed_points=[(0.01, 0.0)], seed=0)
    assert sum("corners are no vertices" in str(w.message) for w in caught) == 1


def test_a_fixed_point_by_a_box_corner_is_warned_of_in_3d():
    # the check of the corners a fixed point displaces sampled the distance in 2D directions: a ValueError
    with pytest.warns(TerrameshWarning, match=r"1 of the domain's corners are no vertices.*\(0, 0, 0\)"):
        mesh = tm.generate_mesh(tm.geometry.Box((0, 0, 0), (1, 1, 1)), 0.2, fixed_points=[(0.02, 0.0, 0.0)])
    assert tm.cleanup.mesh_problems(mesh) == []


@pytest.mark.parametrize("degrees", [6, 8])
def test_a_fixed_point_the_mesh_cannot_keep_is_warned_of(degrees):
    # at the tip of a 6-degree wedge meshed at a fiftieth of its sides the slivers went as flat and the tip's
    # cell with them: the mesh came back without the fixed point, silently; at 8 degrees the tip is kept
    mesh, dropped = wedge_with_its_tip_fixed(
        lambda domain, fixed: tm.generate_mesh(domain, 0.02, fixed_points=fixed), degrees
    )
    assert np.any(np.all(mesh.points == 0.0, axis=1)) == (degrees == 8) and len(dropped) == (degrees == 6)
    if dropped:
        assert dropped[0].startswith("1 of the 2 fixed points are no vertices of the mesh, the first at (0, 0)")


def test_a_size_grid_apart_from_the_domain_is_refused_and_one_covering_little_of_it_warns():
    # a grid of longitude and latitude with a domain in UTM metres: every point sized at the grid's corner, silently
    lon, lat = np.linspace(-70.0, -69.0, 11), np.linspace(42.0, 43.0, 11)
    degrees = tm.sizing.SizeGrid((lon, lat), np.full((11, 11), 420.0))
    utm = tm.geometry.Rectangle((500e3, 4.65e6), (510e3, 4.66e6))
    with pytest.raises(SizingError, match=r"SizeGrid \(x -70..-69, y 42..43\) and the domain .* do not overlap"):
        tm.generate_mesh(utm, degrees)
    x = np.linspace(0.0, 0.3, 4)
    partial = tm.sizing.SizeGrid((x, np.linspace(0.0, 1.0, 4)), np.full((4, 4), 0.1))
    with pytest.warns(TerrameshWarning, match=r"covers 30 % of the domain .* along x"):
        tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), partial)
    # a seismic section's axes are x and z: a domain at positive z was said to miss the sizes "along y"
    model = tm.seismic.read_velocity(np.full((11, 21), 2000.0), spacing=25.0, axis_order="zx")
    section = tm.seismic.size_function(model, frequency=4, hmin=20)
    above = r"SizeGrid \(x 0..500, z -250..0\) covers 0 % of the domain \(x 0..500, z 0..250\) along z"
    with pytest.warns(TerrameshWarning, match=above):
        tm.generate_mesh(tm.geometry.Rectangle((0, 0), (500, 250)), section)
