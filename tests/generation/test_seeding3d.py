"""The BCC lattice seeding (terramesh.generation.seeding3d): density, sites, the band near the boundary."""

import numpy as np
import pytest

import terramesh.generation.seeding3d as seeding3d
from terramesh.generation.seeding3d import bcc_seed_points

from .test_distmesh3d import BALL, boundary_graded


@pytest.mark.parametrize("growth", [0.0, 3.0])
def test_seed_density_follows_the_size_field(growth):
    def size(p):
        return 0.05 * (1 + growth * (p[:, 0] + 1) / 2)

    points, smallest = bcc_seed_points(BALL, size, 0.05, BALL.bbox, np.random.default_rng(0), 1e-6)
    # two lattice points per cube of side 1.07 h: integrate over the ball by Monte Carlo
    sample = np.random.default_rng(1).uniform(-1, 1, (400_000, 3))
    sample = sample[BALL.distance(sample) < 0]
    expected = np.mean(2 / (seeding3d.LATTICE_FACTOR * size(sample)) ** 3) * 4 / 3 * np.pi
    assert len(points) == pytest.approx(expected, rel=0.04)
    assert np.all(BALL.distance(points) < 1e-6)
    assert 0.05 <= smallest <= 0.05 * (1 + growth * 0.02)
    again, _ = bcc_seed_points(BALL, size, 0.05, BALL.bbox, np.random.default_rng(0), 1e-6)
    np.testing.assert_array_equal(points, again)


def test_seed_points_are_distinct_and_on_the_lattice():
    """Neighbouring parents share children: each site is kept once, at its place (jittered by at most 1 %)."""
    size = lambda p: 0.04 + 0.3 * np.abs(BALL.distance(p))  # noqa: E731
    points, _ = bcc_seed_points(BALL, size, 0.04, BALL.bbox, np.random.default_rng(0), 1e-6)
    assert len(np.unique(points, axis=0)) == len(points)
    half = 0.5 * seeding3d.LATTICE_FACTOR * 0.04
    sites = np.round((points - BALL.bbox[0]) / half)
    assert np.abs((points - BALL.bbox[0]) / half - sites).max() <= 0.01
    parity = sites.astype(np.int64) % 2  # body-centred: the three indices all even or all odd
    assert np.all(parity.min(axis=1) == parity.max(axis=1))
    assert len(np.unique(sites, axis=0)) == len(sites)


def test_band_seeds_are_the_full_seeding_near_the_boundary():
    size, rng = boundary_graded, np.random.default_rng
    full, _ = bcc_seed_points(BALL, size, 0.06, BALL.bbox, rng(4), 1e-6)
    band, _ = bcc_seed_points(BALL, size, 0.06, BALL.bbox, rng(4), 1e-6, band=1.5)
    rows = {tuple(point) for point in full}
    assert all(tuple(point) in rows for point in band)  # the same sites, thinned and jittered alike
    # the band is decided at the lattice sites, before the jitter (1 % of the lattice): a margin for it
    clearly_near = full[BALL.distance(full) > -1.4 * size(full)]
    band_rows = {tuple(point) for point in band}
    assert all(tuple(point) in band_rows for point in clearly_near)
    assert 0 < len(band) < 0.6 * len(full)


def test_band_seeds_when_the_band_needs_no_fine_lattice():
    # the finest sizes lie deep inside (r = 0.5), the band at the sphere stops refining levels above h0
    def size(p):
        return np.abs(np.sqrt(np.sum(p**2, axis=1)) - 0.5) / 5 + 0.011

    band, _ = bcc_seed_points(BALL, size, 0.011, BALL.bbox, np.random.default_rng(0), 1e-6, band=2.0)
    assert len(band) > 1000
    assert np.all(BALL.distance(band) > -2.0 * size(band) - 0.02)
