"""The generators' options, checked (terramesh.generation.options): refusals, h0, the sizes' sample, SizeGrids."""

import warnings

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import GenerationError, SizingError, TerrameshWarning
from terramesh.generation.distmesh3d import generate_mesh_3d
from terramesh.geometry.primitives3d import Ball, Box
from terramesh.mesh.topology import signed_areas, unique_edges


def test_h0_is_the_smallest_size_on_the_boundary_too():
    """A size graded from the boundary is smallest there, between the sample's points: they missed it by 39 %."""
    size = lambda p: 0.01 + 0.5 * p[:, 1]  # noqa: E731
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 2)), size, seed=0)
    assert mesh.info["h0"] == pytest.approx(0.01, rel=1e-9)  # was 0.0139, a sample step up
    disk = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), lambda p: 0.03 + 0.3 * np.abs(1 - np.hypot(*p.T)), seed=0)
    assert disk.info["h0"] == pytest.approx(0.03, rel=1e-6)


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


def test_a_bbox_that_cuts_the_domain_is_refused():
    # it was meshed past the bbox: 51 vertices, 38 outside it, cells over 393 % of the quarter disk
    with pytest.raises(GenerationError, match=r"reaches out of the bbox .*tm\.geometry\.Intersection"):
        tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, bbox=[[0, 0], [1, 1]], seed=0)
    quarter = tm.geometry.Intersection([tm.geometry.Disk((0, 0), 1), tm.geometry.Rectangle((0, 0), (1, 1))])
    mesh = tm.generate_mesh(quarter, 0.1, seed=0)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum() == pytest.approx(np.pi / 4, rel=0.01)


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


def test_h0_is_the_smallest_size_on_the_boundary_too_in_3d():
    """Sizes graded from a face: the 64³ sample's inside points missed the face's size by a step's growth."""
    size = lambda p: 0.1 + 0.5 * p[:, 2]  # noqa: E731
    mesh = generate_mesh_3d(Box((0, 0, 0), (1, 1, 1)), size, seed=0)
    assert mesh.info["h0"] == pytest.approx(0.1, rel=1e-9)  # was 0.108
    points, edges = mesh.points, unique_edges(mesh.cells)
    on_face = np.all(points[edges, 2] == 0, axis=1)
    length = np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)
    ratio = length[on_face] / size(points[edges[on_face]].mean(axis=1))
    assert 0.85 <= np.median(ratio) <= 1.2


def test_a_bbox_that_cuts_the_domain_is_refused_in_3d():
    # it was meshed past the bbox: 46 vertices, 37 outside it, a volume of 3.28 for the octant's 0.524
    with pytest.raises(GenerationError, match=r"reaches out of the bbox .*tm\.geometry\.Intersection"):
        generate_mesh_3d(Ball((0, 0, 0), 1.0), 0.3, bbox=[[0, 0, 0], [1, 1, 1]], seed=0)


def _options(domain, size, h0=None):
    from terramesh.generation.options import checked_options

    bbox = np.asarray(domain.bbox, dtype=np.float64)
    return checked_options(domain, size, h0, bbox, None, 100)


def test_sizes_that_step_instead_of_grading_are_named_where():
    # 0.001 for x < 0.05 and 0.1 beyond: cells of q 0.057 without a word; against 1, an error blaming a narrow part
    square = tm.geometry.Rectangle((0, 0), (1, 1))
    step = lambda p: np.where(p[:, 0] < 0.05, 0.001, 0.1)  # noqa: E731
    message = r"the sizes change faster than cells can follow: from 0.001 to 0.1 within 0.0039\d+ near \(0.049"
    with pytest.warns(TerrameshWarning, match=message):
        _options(square, step)
    # in 3D the same
    box_step = lambda p: np.where(p[:, 0] < 0.5, 0.01, 0.2)  # noqa: E731
    with pytest.warns(TerrameshWarning, match=r"from 0.01 to 0.2 within 0.0159 near \(0.5"):
        _options(Box((0, 0, 0), (1, 1, 1)), box_step)


@pytest.mark.parametrize(
    "size",
    [
        lambda p: np.where(p[:, 0] > 0.2, 0.05, 0.1),  # doubled from one cell to the next: meshed well (adapt's test)
        lambda p: 0.004 * (1 + 24.5 * (p[:, 0] + 1)),  # 50 times across the disk, graded
        lambda p: 0.01 + 0.1 * np.hypot(*p.T),
    ],
)
def test_sizes_that_grade_or_double_say_nothing(size):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _options(tm.geometry.Disk((0, 0), 1), size)
