"""A user's corners and sharp edges on a FunctionDomain: polylines as curves, and the checks on them."""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial import cKDTree

import terramesh as tm
from terramesh.errors import GeometryError
from terramesh.geometry.curves import PolylineCurve

from ..conftest import wedge_prism


def slab(**options):
    """The box |x|, |y| <= 1, |z| <= 0.1 as a user's distance function."""
    return tm.geometry.FunctionDomain(
        lambda p: np.max(np.abs(p) - (1.0, 1.0, 0.1), axis=1), [(-1, -1, -0.1), (1, 1, 0.1)], **options
    )


SLAB_TOP = [(-1, -1, 0.1), (1, -1, 0.1), (1, 1, 0.1), (-1, 1, 0.1), (-1, -1, 0.1)]


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, st.tuples(st.integers(2, 8), st.just(3)), elements=st.floats(-10, 10, width=32)))
def test_a_polyline_is_walked_at_a_constant_speed_through_its_vertices(vertices):
    steps = np.linalg.norm(np.diff(vertices, axis=0), axis=1)
    assume((steps > 1e-3).all())  # repeated vertices are dropped: see below
    curve = PolylineCurve(vertices)
    arc = np.concatenate([[0.0], np.cumsum(steps)]) / steps.sum()
    assert np.allclose(curve(arc), vertices, atol=1e-9 * (1 + np.abs(vertices).max()))
    ends = curve(np.array([0.0, 1.0]))
    if not curve.closed:
        assert np.array_equal(ends, vertices[[0, -1]])  # exactly: the generator holds them as corners
    t = np.sort(np.concatenate([arc, np.linspace(0, 1, 201)]))
    walked = np.linalg.norm(np.diff(curve(t), axis=0), axis=1)
    assert np.allclose(walked, np.diff(t) * steps.sum(), rtol=1e-6, atol=1e-9 * steps.sum())


def test_repeated_vertices_are_dropped_and_a_polyline_ending_where_it_starts_is_a_loop():
    loop = PolylineCurve(SLAB_TOP[:2] + SLAB_TOP[1:])
    assert loop.closed and len(loop.vertices) == 5
    assert np.array_equal(loop(np.array([0.25, 1.25])), [(1, -1, 0.1), (1, -1, 0.1)])
    assert not PolylineCurve(SLAB_TOP[:3]).closed


def test_a_function_domain_keeps_the_corners_and_edges_it_is_given():
    edges = [SLAB_TOP, [(-1, -1, -0.1), (-1, -1, 0.1)]]
    domain = slab(corners=[(1, 1, -0.1)], sharp_edges=edges)
    assert len(domain.sharp_edges()) == 2 and domain.sharp_edges()[0].closed
    # the given corner and the open edge's two ends; a loop has none
    assert sorted(map(tuple, domain.corners())) == [(-1, -1, -0.1), (-1, -1, 0.1), (1, 1, -0.1)]
    assert slab().corners().shape == (0, 3) and slab().sharp_edges() == []


def test_a_callable_edge_whose_ends_meet_is_a_loop():
    rim = slab(sharp_edges=[lambda t: np.column_stack([np.cos(2 * np.pi * t), np.sin(2 * np.pi * t), 0.1 + 0 * t])])
    # not on the slab's boundary at all: the circle runs inside the top face, which is on it
    (curve,) = rim.sharp_edges()
    assert curve.closed and rim.corners().shape == (0, 3)
    assert np.allclose(curve(np.array([0.0, 1.0])), [(1, 0, 0.1), (1, 0, 0.1)])


@pytest.mark.parametrize(
    "options, message",
    [
        (
            {"corners": [(0.5, 0.0, 0.0)]},
            "1 of the 1 points of the corners lie off the boundary, the first at "
            "\\(0.5, 0, 0\\), where the distance function reads -0.1",
        ),
        ({"sharp_edges": [[(1, -1, 0.1), (-1, 1, -0.1)]]}, "points of sharp edge 0 lie off the boundary"),
        ({"sharp_edges": [[(1, 1, 0.1)]]}, "at least two distinct vertices"),
        ({"sharp_edges": [[(1, 1), (1, -1)]]}, "sharp edge 0 has 2D vertices"),
        ({"sharp_edges": [[(1, 1, 0.1), (1, np.nan, 0.1)]]}, "vertices must be finite"),
        ({"sharp_edges": [lambda t: np.zeros((len(t), 2))]}, "shape \\(17, 2\\): a sharp edge maps"),
        ({"sharp_edges": [lambda t: np.full((len(t), 3), np.inf)]}, "shape \\(17, 3\\), not all finite"),
        (
            {"sharp_edges": lambda t: np.zeros((len(t), 3))},
            "a list of curves .* got one function: put a curve in a list",
        ),
        ({"sharp_edges": np.array(SLAB_TOP)}, "got one ndarray: put a curve in a list"),
        ({"sharp_edges": SLAB_TOP}, "sharp edge 0 has shape \\(3,\\): .* one polyline given alone goes in a list"),
        ({"sharp_edges": 3}, "got one int: put a curve in a list"),
        ({"sharp_edges": [[(1, 1, 0.1), (1, -1)]]}, "sharp edge 0 has shape ragged"),
    ],
)
def test_corners_and_edges_off_the_boundary_or_malformed_are_refused(options, message):
    with pytest.raises(GeometryError, match=message):
        slab(**options)


def test_no_corners_and_no_edges_given_as_empty_lists_are_none():
    square = tm.geometry.FunctionDomain(lambda p: np.max(np.abs(p) - 1, axis=1), [(-1, -1), (1, 1)], corners=[])
    assert square.corners().shape == (0, 2)
    assert tm.geometry.FunctionDomain(square.function, square.bbox, sharp_edges=[]).sharp_edges() == []
    assert slab(corners=[]).corners().shape == (0, 3) and slab(sharp_edges=[]).sharp_edges_given


def test_an_edge_ending_on_a_box_plane_ends_on_it_exactly():
    # bisection left the ends of a user's edge cut by a box's plane 7e-7 off it, here outside the combination's
    # bbox (x >= 0.2): the corner was dropped, and the nearest vertex came out 0.057 from it at h 0.06
    cut = wedge_prism(45, told=True) & tm.geometry.Box((0.2, -1, -1), (2, 2, 0.2))
    corners = cut.corners()
    bottom = corners[(corners[:, 0] == 0.2) & (corners[:, 2] == 0.0)]  # on both planes exactly...
    np.testing.assert_allclose(bottom, [(0.2, 0.0, 0.0), (0.2, 0.2, 0.0)], rtol=0, atol=1e-11)  # ...on the wedge too
    mesh = tm.generate_mesh(cut, 0.06, seed=0)
    assert tm.cleanup.mesh_problems(mesh, cut, boundary_tolerance=6e-5) == []
    assert cKDTree(mesh.points).query(corners)[0].max() < 1e-6


def test_an_edge_ending_where_a_distance_function_cuts_it_ends_there_not_on_a_plane_passing_by():
    # the wedge's vertical edges end on the top of a user's half-space (z = 0.1); a box far away has a face at
    # z = 0.1004, and the first fix moved the corners onto it, 4e-4 off the domain
    low = tm.geometry.FunctionDomain(lambda p: p[:, 2] - 0.1, [(-1, -1, -1), (2, 2, 0.1)], sharp_edges=[])
    domain = (wedge_prism(45, told=True) & low) | tm.geometry.Box((1.6, 1.6, 0.1004), (2, 2, 0.3))
    corners = domain.corners()
    top = corners[(np.abs(corners[:, 2] - 0.1) < 1e-3) & (corners[:, 0] <= 1)]  # the wedge's, not the box's
    assert len(top) == 3 and np.abs(top[:, 2] - 0.1).max() < 1e-11


def test_a_gridded_block_cut_by_a_box_keeps_the_corners_a_rounding_outside_the_bbox():
    # the grid's axes end at 1.1e-16 (linspace(-0.7, 0, 71)): its top corners lay that far above the box's top
    # at z = 0, outside the combination's bbox, and the mesh lost them (the nearest vertex 0.078 away)
    axes = [np.linspace(0, 1.6, 81), np.linspace(0, 1, 51), np.linspace(-0.7, 0, 71)]
    block = tm.geometry.GridDomain(axes, -np.ones((81, 51, 71))) & tm.geometry.Box((0, 0, -0.7), (0.8, 1, 0))
    mesh = tm.generate_mesh(block, 0.08, seed=0)
    assert tm.cleanup.mesh_problems(mesh, block, boundary_tolerance=8e-5) == []
    assert cKDTree(mesh.points).query(block.corners())[0].max() < 1e-9


def test_sharp_edges_are_refused_in_2d():
    with pytest.raises(GeometryError, match="sharp_edges are for 3D domains"):
        tm.geometry.FunctionDomain(
            lambda p: np.max(np.abs(p) - 1, axis=1), [(-1, -1), (1, 1)], sharp_edges=[[(1, -1), (1, 1)]]
        )


def test_a_2d_function_domain_keeps_its_corners():
    # without them the square's corners are rounded off: the nearest vertex 0.03 from (-1, -1) at h 0.13
    square = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    domain = tm.geometry.FunctionDomain(lambda p: np.max(np.abs(p) - 1, axis=1), [(-1, -1), (1, 1)], corners=square)
    mesh = tm.generate_mesh(domain, 0.13)
    assert tm.cleanup.mesh_problems(mesh, domain) == []
    assert (np.min(np.linalg.norm(mesh.points[:, None] - np.array(square)[None], axis=2), axis=0) == 0).all()
