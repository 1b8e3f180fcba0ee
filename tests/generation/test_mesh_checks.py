"""Warnings about a generated mesh (terramesh.generation.mesh_checks): max_iter, area, rings and sizes missed."""

import re
import warnings

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import TerrameshWarning
from terramesh.generation.distmesh3d import generate_mesh_3d
from terramesh.quality import edge_length_ratio

from ..conftest import assert_valid
from .test_distmesh3d import BALL


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
    with pytest.warns(TerrameshWarning) as caught:
        mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), edge_length, seed=0, **options)
    said = " | ".join(str(warning.message) for warning in caught)
    assert re.search(r"the mesh has \d+ vertices where its sizes ask for about \d+ \(near", said)
    assert "the sizes change faster than cells can follow: from 0.2 to 0.001" in said  # before meshing, too
    assert np.sum(np.hypot(*(mesh.points - centre).T) < 0.02) == 0


def test_a_spot_seeded_whole_and_lost_as_the_mesh_settles_is_warned_of():
    """A spot 0.012 across at 1e-3, off the coarsest sites: seeded (131 of its vertices) and lost to the last one
    as the forces settled the 200x jump around it."""
    centre = np.array([0.5, 0.5])  # a site of every lattice level

    def size(p):
        return np.where(np.hypot(*(p - centre).T) < 0.006, 1e-3, 0.2)

    with pytest.warns(TerrameshWarning) as caught:
        mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), size, h0=1e-3, seed=0)
    said = " | ".join(str(warning.message) for warning in caught)
    assert "sizes change faster than a mesh can follow" in said
    assert "the sizes change faster than cells can follow: from 0.2 to 0.001" in said  # before meshing, too
    assert np.sum(np.hypot(*(mesh.points - centre).T) < 0.006) < 10


@pytest.mark.parametrize("length", [30, 100])
def test_a_long_strip_draws_no_warning_of_missed_sizes(length):
    # its 16 x 16 blocks were 1/16 high, below the mesh's row spacing (0.087): some held no vertex and warned
    strip = tm.geometry.Rectangle((0, 0), (length, 1))
    mesh = tm.generate_mesh(strip, 0.1, seed=0)  # the tests turn warnings into errors
    assert tm.cleanup.mesh_problems(mesh, strip) == []


def test_max_iter_warns():
    with pytest.warns(TerrameshWarning, match="max_iter=2") as record:
        mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.1, max_iter=2)
    assert mesh.info["stop_reason"] == "max_iter"
    assert {warning.filename for warning in record} == {__file__}  # the user's line, not terramesh's


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
    # a wedge of 2 degrees, a size wide at two thirds of its length, meshed in four pieces: 28 % of it gone unsaid
    tip = np.radians(2.0)
    wedge = tm.geometry.Polygon([(0, 0), (1, 0), (np.cos(tip), np.sin(tip))])
    with pytest.warns(TerrameshWarning, match=r"covers 7\d % of the domain's area .* parts thinner than the mesh"):
        tm.generate_mesh(wedge, 0.02)


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
        fine = tm.generate_mesh(
            domain, lambda p: np.clip(0.008 + 0.3 * (0.8 - np.abs(p[:, 0] - 1.15)), 0.008, 0.1), h0=0.008
        )
    assert fine.points[:, 0].max() == pytest.approx(2.03)


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


def test_max_iter_warns_in_3d():
    with pytest.warns(TerrameshWarning, match="max_iter=3"):
        mesh = generate_mesh_3d(BALL, 0.25, max_iter=3)
    assert mesh.info["stop_reason"] == "max_iter" and mesh.info["min_dihedral"] >= 10
