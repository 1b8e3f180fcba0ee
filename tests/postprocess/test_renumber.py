import numpy as np
import pytest
import scipy.linalg

import terramesh as tm
from terramesh.errors import MeshValidityError
from terramesh.io import Boundaries, LandBoundary, NodalAttribute, NodalAttributes, OpenBoundary
from terramesh.mesh.topology import boundary_edges, signed_areas
from terramesh.postprocess import bandwidth, rcm_permutation, renumber


@pytest.fixture(scope="module")
def shuffled_estuary():
    """A graded mesh of a 3 x 1 channel with an island, vertices in random order, with depth and boundaries."""
    domain = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (3, 1)), tm.geometry.Disk((1.5, 0.5), 0.2)])
    mesh = tm.generate_mesh(domain, lambda p: 0.02 + 0.08 * np.abs(domain.distance(p)), seed=0)
    rng = np.random.default_rng(7)
    new_index = rng.permutation(mesh.n_points)  # old vertex i becomes new_index[i]
    points = np.empty_like(mesh.points)
    points[new_index] = mesh.points
    cells = new_index[mesh.cells]
    depth = 5 + points[:, 0] ** 2  # a field tied to position, to check it follows its vertex
    edges = boundary_edges(cells)
    west = np.unique(edges[np.all(points[edges, 0] < 1e-9, axis=1)])
    island = np.unique(edges[np.all(np.hypot(*(points[edges] - [1.5, 0.5]).transpose(2, 0, 1)) < 0.21, axis=1)])
    pairs = island[:4]
    boundaries = Boundaries(
        open=[OpenBoundary(west, 0)],
        land=[
            LandBoundary(np.append(island, island[0]), 21),
            LandBoundary(pairs, 24, paired_nodes=pairs[::-1].copy(), values=np.ones((4, 3))),
        ],
    )
    return tm.Mesh(points, cells, point_data={"depth": depth}, boundaries=boundaries, info={"note": "kept"})


def test_rcm_shrinks_the_bandwidth_and_keeps_the_mesh(shuffled_estuary):
    mesh = shuffled_estuary
    before = (mesh.points.copy(), mesh.cells.copy())
    new = renumber(mesh)
    report = new.info["renumber"]
    assert report["bandwidth_before"] == bandwidth(mesh.cells) > 0.9 * mesh.n_points
    assert report["bandwidth_after"] == bandwidth(new.cells) < 0.05 * mesh.n_points
    assert report["reordered"] is True
    assert new.info["note"] == "kept"
    # the same mesh: every cell has the same corners, in the same order, with the same area
    np.testing.assert_array_equal(new.points[new.cells], mesh.points[mesh.cells])
    np.testing.assert_array_equal(signed_areas(new.points, new.cells), signed_areas(mesh.points, mesh.cells))
    np.testing.assert_array_equal(new.point_data["depth"], 5 + new.points[:, 0] ** 2)
    old_strings, new_strings = mesh.boundaries.open + mesh.boundaries.land, new.boundaries.open + new.boundaries.land
    for old, now in zip(old_strings, new_strings, strict=True):
        np.testing.assert_array_equal(new.points[now.nodes], mesh.points[old.nodes])
        assert now.ibtype == old.ibtype
    weir_old, weir_new = mesh.boundaries.land[1], new.boundaries.land[1]
    np.testing.assert_array_equal(new.points[weir_new.paired_nodes], mesh.points[weir_old.paired_nodes])
    np.testing.assert_array_equal(weir_new.values, weir_old.values)
    assert tm.cleanup.mesh_problems(new) == []
    # the input is untouched
    np.testing.assert_array_equal(mesh.points, before[0])
    np.testing.assert_array_equal(mesh.cells, before[1])


def test_new_index_carries_nodal_attributes(shuffled_estuary):
    mesh = shuffled_estuary
    new = renumber(mesh)
    tau0 = NodalAttribute.from_values(np.where(mesh.point_data["depth"] > 6, 0.005, 0.03))
    attributes = NodalAttributes({"primitive_weighting_in_continuity_equation": tau0})
    moved = attributes.renumbered(new.info["renumber"]["new_index"])
    expected = np.where(new.point_data["depth"] > 6, 0.005, 0.03)
    np.testing.assert_array_equal(moved["primitive_weighting_in_continuity_equation"].values[:, 0], expected)


def fan(k=21):
    """``k`` ring vertices around one hub (a fan of ``k - 1`` triangles), the hub numbered in the middle.

    The best order has bandwidth about ``k / 2``; RCM starts at a ring end
    and numbers the hub third, for a bandwidth of about ``k``.
    """
    angle = np.linspace(0.0, 0.9 * np.pi, k)
    arc = np.column_stack([np.cos(angle), np.sin(angle)])
    hub = k // 2
    points = np.vstack([arc[:hub], [[0.0, 0.0]], arc[hub:]])
    ring = np.r_[0:hub, hub + 1 : k + 1]
    cells = np.column_stack([np.full(k - 1, hub), ring[:-1], ring[1:]])
    return tm.Mesh(points, cells, point_data={"depth": points[:, 0] + 10.0})


def test_renumber_keeps_the_order_when_rcm_is_no_better():
    """Was: the fan's bandwidth went from 11 to 19; a second renumbering of a mesh went from 38 to 40."""
    mesh = fan()
    order = rcm_permutation(mesh.cells, mesh.n_points)
    assert bandwidth(np.argsort(order)[mesh.cells]) > bandwidth(mesh.cells) == 11  # RCM alone is worse here
    new = renumber(mesh)
    report = new.info["renumber"]
    assert report["bandwidth_before"] == report["bandwidth_after"] == bandwidth(new.cells) == 11
    assert report["reordered"] is False
    np.testing.assert_array_equal(report["new_index"], np.arange(mesh.n_points))
    np.testing.assert_array_equal(new.points, mesh.points)
    np.testing.assert_array_equal(new.cells, mesh.cells)
    np.testing.assert_array_equal(new.point_data["depth"], mesh.point_data["depth"])
    # renumbering an RCM-ordered mesh again never makes it worse
    domain = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (3, 1)), tm.geometry.Disk((1.5, 0.5), 0.2)])
    once = renumber(tm.generate_mesh(domain, lambda p: 0.02 + 0.08 * np.abs(p[:, 0] - 1.5), seed=0))
    twice = renumber(once)
    assert twice.info["renumber"]["bandwidth_after"] <= once.info["renumber"]["bandwidth_after"]
    assert twice.info["renumber"]["bandwidth_after"] == bandwidth(twice.cells)
    assert tm.cleanup.mesh_problems(twice) == []


def test_bandwidth_matches_the_dense_matrix():
    mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.3, seed=0)
    cells = np.random.default_rng(0).permutation(mesh.n_points)[mesh.cells]
    matrix = np.eye(mesh.n_points)
    for i in range(3):
        for j in range(3):
            matrix[cells[:, i], cells[:, j]] = 1
    lower, upper = scipy.linalg.bandwidth(matrix)
    assert bandwidth(cells) == lower == upper
    assert bandwidth(np.zeros((0, 3), dtype=int)) == 0
    order = rcm_permutation(cells, mesh.n_points)
    assert sorted(order.tolist()) == list(range(mesh.n_points))


@pytest.mark.parametrize(
    "cells, message",
    [
        ([[0.5, 1.7, 2.2]], "integer"),  # was truncated to [0, 1, 2]: bandwidth 2
        ([[-5, 1, 2]], "do not exist"),  # was 7
        ([[np.nan, 1, 2]], "integer"),
        ([0, 1, 2], "shape"),
        (np.zeros((2, 3, 3), dtype=int), "shape"),  # was 0
        ([[1], [2]], "shape"),
    ],
)
def test_bandwidth_refuses_what_is_not_integer_cells(cells, message):
    with pytest.raises(MeshValidityError, match=message):
        bandwidth(cells)


@pytest.mark.parametrize(
    "cells, n_points, message",
    [
        ([[0, 1, 5]], 3, "do not exist"),
        ([[0, 1, -1]], 3, "do not exist"),
        ([[0.2, 1.9, 2.5]], 3, "integer"),
        ([[0, 1, 2]], 3.0, "n_points"),
        ([[0, 1, 2]], "3", "n_points"),
        ([[0, 1, 2]], True, "n_points"),
        ([[0, 1, 2]], None, "n_points"),
        (np.zeros((0, 3), dtype=int), -1, "n_points"),
    ],
)
def test_rcm_permutation_refuses_bad_cells_and_counts(cells, n_points, message):
    with pytest.raises(MeshValidityError, match=message):
        rcm_permutation(cells, n_points)


def test_renumber_refuses_cells_outside_the_points():
    mesh = tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([[0, 1, 2]]))
    mesh.cells = np.array([[0, 1, 5]])  # changed after the checks of Mesh()
    with pytest.raises(MeshValidityError, match="do not exist"):
        renumber(mesh)


def test_renumber_of_an_empty_mesh():
    assert rcm_permutation(np.zeros((0, 3), dtype=int), 0).shape == (0,)
    assert rcm_permutation([], 2).tolist() in ([0, 1], [1, 0])
    new = renumber(tm.Mesh(np.zeros((0, 2)), np.zeros((0, 3), dtype=int)))
    assert new.n_points == new.n_cells == 0
    assert new.info["renumber"]["bandwidth_after"] == 0 and new.info["renumber"]["new_index"].shape == (0,)


def test_boundaries_naming_vertices_the_mesh_lacks_are_refused_by_name():
    # node 99 of a mesh of 25: a bare IndexError from the renumbering of the boundaries
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.25)
    mesh.boundaries = Boundaries(open=[OpenBoundary(np.array([0, 1, mesh.n_points + 50]))])
    with pytest.raises(MeshValidityError, match=f"refers to node {mesh.n_points + 50} "):
        renumber(mesh)
