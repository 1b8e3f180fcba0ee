"""CFL limiting, guide eq. 10-12."""

import numpy as np
import pytest

from terramesh.coastal.sizes import COURANT, ETA, cfl_limit, cfl_timestep, courant_number, wave_speed
from terramesh.errors import SizingError
from terramesh.sizing.edge_shrink import EDGE_SHRINK

G = 9.81


def test_defaults():
    assert ETA == 2.0  # the guide's default
    assert COURANT == 0.5  # OceanMesh2D's descfl


def test_wave_speed_by_hand_both_branches():
    # eq. 11 for h >= eta: |u| = eta sqrt(g / h), H = h
    deep = 2.0 * np.sqrt(G / 100.0) + np.sqrt(G * 100.0)
    assert deep == pytest.approx(31.947338, abs=1e-6)
    # h < eta: critical flow, H = eta, |u| = sqrt(g eta)
    shallow = np.sqrt(G * 2.0) + np.sqrt(G * 2.0)
    assert shallow == pytest.approx(8.858894, abs=1e-6)
    speed = wave_speed([100.0, 1.0, -3.0, 2.0])
    assert speed == pytest.approx([deep, shallow, shallow, shallow], rel=1e-12)


def test_wave_speed_is_continuous_at_eta():
    below, above = wave_speed([3.0 - 1e-9, 3.0 + 1e-9], eta=3.0)
    assert below == pytest.approx(above, rel=1e-8)


def test_cfl_limit_by_hand():
    # f_min = dt (|u| + sqrt(gH)) / (Cr s), eq. 10 solved for f, with the allowance s for a mesh's shortest edges
    dt, cr = 2.0, 0.5
    assert EDGE_SHRINK == 0.6
    f_deep = dt * (2.0 * np.sqrt(G / 100.0) + np.sqrt(G * 100.0)) / (cr * 0.6)
    f_shallow = dt * 2.0 * np.sqrt(G * 2.0) / (cr * 0.6)
    assert f_deep == pytest.approx(212.982, abs=1e-3)
    assert f_shallow == pytest.approx(59.0593, abs=1e-4)
    sizes = np.array([50.0, 500.0, 10.0, np.inf])
    depth = np.array([100.0, 100.0, 1.0, 100.0])
    limited = cfl_limit(sizes, depth, dt=dt, courant=cr)
    assert limited == pytest.approx([f_deep, 500.0, f_shallow, np.inf], rel=1e-12)
    assert sizes[0] == 50.0  # not modified


def test_cfl_limit_keeps_courant_below_target():
    rng = np.random.default_rng(4)
    depth = rng.uniform(-20, 6000, (40, 30))
    sizes = rng.uniform(10, 5000, (40, 30))
    limited = cfl_limit(sizes, depth, dt=3.0, courant=0.7)
    assert np.all(limited >= sizes)
    assert np.max(courant_number(limited, depth, dt=3.0)) <= 0.7 * EDGE_SHRINK * (1 + 1e-12)
    untouched = courant_number(sizes, depth, dt=3.0) <= 0.7 * EDGE_SHRINK
    assert np.array_equal(limited[untouched], sizes[untouched])


def test_courant_number_by_hand():
    speed = 2.0 * np.sqrt(G / 100.0) + np.sqrt(G * 100.0)
    assert courant_number(100.0, 100.0, dt=2.0) == pytest.approx(speed * 2.0 / 100.0)


def test_automatic_timestep_by_hand():
    # eq. 12 with the allowance: dt = min[f_hd Cr s / (|u| + sqrt(gH))]
    f_hd = np.array([100.0, 500.0, np.inf])
    depth = np.array([100.0, 1.0, 3000.0])
    speeds = [2.0 * np.sqrt(G / 100.0) + np.sqrt(G * 100.0), 2.0 * np.sqrt(G * 2.0)]
    by_hand = min(100.0 * 0.5 / speeds[0], 500.0 * 0.5 / speeds[1]) * 0.6
    assert by_hand == pytest.approx(0.939045, abs=1e-6)
    assert cfl_timestep(f_hd, depth) == pytest.approx(by_hand, rel=1e-12)


def test_automatic_timestep_keeps_the_coastal_resolution():
    rng = np.random.default_rng(7)
    depth = rng.uniform(-5, 300, (30, 20))
    f_hd = rng.uniform(50, 2000, (30, 20))
    sizes = np.minimum(f_hd, rng.uniform(20, 5000, (30, 20)))
    limited = cfl_limit(sizes, depth, dt=0, nearshore_sizes=f_hd)
    dt = cfl_timestep(f_hd, depth)
    assert np.array_equal(limited, cfl_limit(sizes, depth, dt=dt))
    # f_hd itself satisfies Cr <= 0.5 with that dt, so limiting never raises it
    assert np.array_equal(cfl_limit(f_hd, depth, dt=0, nearshore_sizes=f_hd), f_hd)
    assert np.max(courant_number(f_hd, depth, dt=dt)) == pytest.approx(0.5 * EDGE_SHRINK, rel=1e-12)


def test_min_edge_length_raises_f_hd_first():
    f_hd = np.array([10.0, 500.0])
    depth = np.array([100.0, 100.0])
    speed = 2.0 * np.sqrt(G / 100.0) + np.sqrt(G * 100.0)
    assert cfl_timestep(f_hd, depth, min_edge_length=80.0) == pytest.approx(80.0 * 0.5 * EDGE_SHRINK / speed)
    assert cfl_timestep(f_hd, depth) == pytest.approx(10.0 * 0.5 * EDGE_SHRINK / speed)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: cfl_limit([1.0], [1.0], dt=-1.0), "dt"),
        (lambda: cfl_limit([1.0], [1.0], dt=0.0), "nearshore_sizes"),
        (lambda: cfl_limit([1.0, 2.0], [1.0], dt=1.0), "shape"),
        (lambda: cfl_limit([1.0], [np.nan], dt=1.0), "NaN"),
        (lambda: cfl_limit([0.0], [1.0], dt=1.0), "positive"),
        (lambda: cfl_limit([1.0], [1.0], dt=1.0, courant=0), "courant"),
        (lambda: cfl_limit([1.0], [1.0], dt=1.0, eta=-2), "eta"),
        (lambda: cfl_timestep([np.inf], [10.0]), "inf everywhere"),
        (lambda: cfl_timestep([1.0], [10.0, 2.0]), "shape"),
    ],
)
def test_bad_input(call, message):
    with pytest.raises(SizingError, match=message):
        call()
