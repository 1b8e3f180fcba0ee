"""Idle OpenMP threads sleep soon after a parallel loop instead of spinning (``_kernels/__init__``)."""

import json
import os
import subprocess
import sys
import textwrap

import pytest

_SPIN_VARIABLES = ("GOMP_SPINCOUNT", "OMP_WAIT_POLICY")


def _run(code, **environment):
    """Run ``code`` in a fresh interpreter whose environment has none of the spin variables but ``environment``."""
    env = {key: value for key, value in os.environ.items() if key not in _SPIN_VARIABLES}
    env.update(environment)
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout.strip().splitlines()[-1])


_SETTINGS = """
    import json, os
    import terramesh
    print(json.dumps({name: os.environ.get(name) for name in ("GOMP_SPINCOUNT", "OMP_WAIT_POLICY")}))
"""


def test_importing_terramesh_shortens_the_spin():
    assert _run(_SETTINGS) == {"GOMP_SPINCOUNT": "1000", "OMP_WAIT_POLICY": None}


@pytest.mark.parametrize("name, value", [("OMP_WAIT_POLICY", "active"), ("GOMP_SPINCOUNT", "300000")])
def test_the_users_setting_wins(name, value):
    expected = {"GOMP_SPINCOUNT": None, "OMP_WAIT_POLICY": None, name: value}
    assert _run(_SETTINGS, **{name: value}) == expected


# a parallel kernel of terramesh's, then a pause after each call: what the process spends meanwhile is
# what its idle threads burn (all of each 10 ms pause with libgomp's own spin on the development machine)
_IDLE_CPU = """
    import json, time
    import numba, numpy as np
    from terramesh._kernels.forces import rest_length_scale
    rng = np.random.default_rng(0)
    points, target = rng.random((20_000, 2)), np.full(20_000, 0.01)
    edges = rng.integers(0, 20_000, (20_000, 2))
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))  # one thread to wake per loop, however many cores
    rest_length_scale(points, edges, target, 1.15, 8)
    cpu, wall = time.process_time(), time.perf_counter()
    for _ in range(30):
        rest_length_scale(points, edges, target, 1.15, 8)
        time.sleep(0.01)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    layer = numba.threading_layer()
    print(json.dumps({"layer": layer, "threads": numba.get_num_threads(), "cpu": cpu, "wall": wall}))
"""


def test_idle_threads_do_not_spin_through_a_pause():
    measured = _run(_IDLE_CPU)
    if measured["layer"] != "omp" or measured["threads"] < 2:
        pytest.skip(f"numba runs the {measured['layer']} layer on {measured['threads']} thread(s) here")
    # 30 pauses of 10 ms: spinning through them costs 0.3 s of CPU; on the development machine (other
    # work running) the whole loop took 19-25 ms of CPU, and 0.53 s with libgomp's own spin
    assert measured["cpu"] < 0.25 * measured["wall"], measured
