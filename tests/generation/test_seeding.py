import numpy as np
import pytest

import terramesh as tm
from terramesh.generation.seeding import seed_points

disk = tm.geometry.Disk((0, 0), 1)


def expected_count(h_min, growth):
    """Integral over the unit disk of 1 / (sqrt(3)/2 h^2), h = h_min (1 + growth (x + 1))."""
    x = np.linspace(-1, 1, 20001)
    return np.trapezoid(2 * np.sqrt(1 - x**2) / (h_min * (1 + growth * (x + 1))) ** 2, x) / (np.sqrt(3) / 2)


@pytest.mark.parametrize("growth", [0.0, 2.0, 24.5])
def test_density_follows_the_size_field(growth):
    h_min = 0.004
    calls = []

    def size(p):
        calls.append(len(p))
        return h_min * (1 + growth * (p[:, 0] + 1))

    points, smallest = seed_points(disk, size, h_min, disk.bbox, np.random.default_rng(0), 1e-6)
    assert len(points) == pytest.approx(expected_count(h_min, growth), rel=0.04)
    assert h_min <= smallest <= h_min * (1 + growth * 0.02)  # lattice points lie within 0.02 of x = -1
    assert np.all(disk.distance(points) < 1e-6)
    # work follows the points kept (the coarsest level has ~10^3 sites), not the area over
    # h0^2 (the finest lattice): ~10 sizes per point kept where the size grows 50x
    finest_lattice = np.pi / (np.sqrt(3) / 2 * h_min**2)
    assert sum(calls) < 12 * len(points)
    if growth > 10:
        assert sum(calls) < 0.2 * finest_lattice


def test_same_seed_same_points_and_seeds_differ():
    size = lambda p: 0.01 * (1 + 3 * (p[:, 0] + 1))  # noqa: E731
    first, _ = seed_points(disk, size, 0.01, disk.bbox, np.random.default_rng(3), 1e-6)
    again, _ = seed_points(disk, size, 0.01, disk.bbox, np.random.default_rng(3), 1e-6)
    other, _ = seed_points(disk, size, 0.01, disk.bbox, np.random.default_rng(4), 1e-6)
    np.testing.assert_array_equal(first, again)
    assert len(first) != len(other) or not np.array_equal(first, other)


def test_points_come_from_the_lattice_of_their_own_octave():
    """A size between 2^k h0 and 2^(k+1) h0 takes points of the lattice of spacing 2^k h0 (at most 3 in 4 rejected).

    Up to a size of 50 h0 here: the coarsest lattice must be coarse enough that
    no size is thinned from a finer lattice much harder, into random points.
    """
    h_min = 0.004
    size = lambda p: h_min * (1 + 24.5 * (p[:, 0] + 1))  # noqa: E731
    points, _ = seed_points(disk, size, h_min, disk.bbox, np.random.default_rng(0), 1e-6)
    row = (points[:, 1] - disk.bbox[0, 1]) / (h_min * np.sqrt(3) / 2)
    j = np.rint(row).astype(np.int64)
    i = np.rint((points[:, 0] - disk.bbox[0, 0]) / h_min - 0.5 * j).astype(np.int64)
    np.testing.assert_allclose(row, j, atol=1e-6)  # on the finest lattice
    octave = np.floor(np.log2(size(points) / h_min)).astype(np.int64)
    assert octave.max() == 5
    stride = 1 << octave
    assert np.all((i % stride == 0) & (j % stride == 0))
