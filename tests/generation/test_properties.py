"""Property test: every mesh of a random polygon and size field is valid."""

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import terramesh as tm

from ..conftest import assert_valid, random_walk_coast


@st.composite
def polygon_and_size(draw):
    n = draw(st.integers(5, 24))
    angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    angles = angles + draw(st.floats(0, 0.5)) * (2 * np.pi / n) * np.array(
        draw(st.lists(st.floats(-0.9, 0.9), min_size=n, max_size=n))
    )
    radii = np.array(draw(st.lists(st.floats(0.6, 1.0), min_size=n, max_size=n)))
    rings = [np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])]
    if draw(st.booleans()):
        rings.append(0.15 * np.column_stack([np.cos(angles[::-1]), np.sin(angles[::-1])]) + 0.05)
    h_min = draw(st.floats(0.035, 0.08))
    growth = draw(st.floats(0.0, 0.4))
    direction = draw(st.floats(0, 2 * np.pi))
    return rings, h_min, growth, direction


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(polygon_and_size())
def test_random_polygons_and_size_fields_give_valid_meshes(case):
    rings, h_min, growth, direction = case
    domain = tm.geometry.Polygon(rings)
    unit = np.array([np.cos(direction), np.sin(direction)])

    def edge_length(p):
        return h_min * (1.0 + growth * (1.0 + p @ unit))

    mesh = tm.generate_mesh(domain, edge_length, h0=h_min, seed=1)  # a max_iter warning fails the suite
    assert_valid(mesh, domain, h_min)
    area = tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum()
    assert area == pytest.approx(domain.geometry.area, rel=0.05)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(polygon_and_size(), st.sampled_from([1, 2]))
def test_random_polygons_meshed_from_coarse_levels_give_valid_meshes(case, levels):
    rings, h_min, growth, direction = case
    h_min = h_min / 2  # 2,000 to 20,000 vertices: the coarsest level keeps a few hundred
    domain = tm.geometry.Polygon(rings)
    unit = np.array([np.cos(direction), np.sin(direction)])

    def edge_length(p):
        return h_min * (1.0 + growth * (1.0 + p @ unit))

    mesh = tm.generate_mesh(domain, edge_length, h0=h_min, seed=1, levels=levels)
    # a coarsest level under COARSEST_LEAST (100) points is not meshed: the next finer one starts
    assert 1 < len(mesh.info["levels"]) <= levels + 1 and mesh.info["levels"][0]["points"] >= 100
    assert_valid(mesh, domain, h_min)
    area = tm.mesh.topology.signed_areas(mesh.points, mesh.cells).sum()
    assert area == pytest.approx(domain.geometry.area, rel=0.05)
    ratio = tm.quality.edge_length_ratio(mesh.points, mesh.cells, edge_length)
    assert 0.85 <= np.median(ratio) <= 1.15


# the same draws on every run: a draw that finds a cell under q 0.2 on these coasts would fail CI by
# chance; the search for them goes on in benchmarks/sweep_validity.py ("poor" in 2d), and what it
# finds lands here as examples
@settings(max_examples=10, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(500, 3000), st.floats(0.3, 0.8), st.floats(0.02, 0.04), st.integers(0, 2**32 - 1))
@example(1838, 0.5, 0.028111379187470757, 267)  # a vertex projected 0.13 sizes from a fixed corner: q 0.17
@example(1325, 0.752249119091364, 0.025948259985710893, 46346)  # a slit of no width at a corner: a hanging node
@example(2709, 0.6160675587500835, 0.03620548704212598, 3725113205)  # two projected vertices 0.16 sizes apart: q 0.19
@example(1948, 0.7488670735465878, 0.036703664093845595, 1960354588)  # projected onto its cell's far edge: q 0.06
@example(1553, 0.7519818084591218, 0.03401954747080885, 2544499618)  # a merge took a cell onto land
@example(2919, 0.41639352383646683, 0.020069078921775705, 3920251213)  # one cell of q 0.01 at a corner of 104 degrees
@example(1941, 0.4817012295376945, 0.03878352023269689, 1545803787)  # q 0.19 before this session's repairs
@example(2353, 0.38048654558455347, 0.031154890947313843, 3629568596)  # q 0.027 before them
@example(1036, 1.068826640397398, 0.021390546800459143, 4212062595)  # the smoothing slid a vertex into a slit
@example(2942, 0.7621084482534121, 0.02941819770831515, 1366429243)  # a cap (q 0.021): a vertex on its far edge
@example(2854, 0.7614041879443795, 0.026888268893831602, 3262968051)  # a cap of q 0.15 in a jag the mesh bridges
def test_coastlines_jagged_below_the_mesh_size_give_valid_meshes(n, roughness, h, seed):
    # a closed random walk in radius: headlands and inlets far narrower than h, as on a real coast;
    # projecting the boundary vertices onto it once left cells over headlands (centroid on land)
    domain = random_walk_coast(n, seed, roughness, smallest_radius=0.3)
    mesh = tm.generate_mesh(domain, h, seed=0)
    assert_valid(mesh, domain, h)
    assert tm.quality.triangle_quality(mesh.points, mesh.cells).min() > 0.2
