"""Run one meshing case in a fresh process (so peak memory is per case) and print tables.

A case's time is its fastest run: cases under a second run up to five times.
"""

import json
import os
import subprocess
import sys
import time

_CASE = """
import json, resource, time, warnings
import numpy as np
import terramesh as tm
from terramesh.quality import triangle_quality, edge_length_ratio
warnings.simplefilter("ignore")
# JIT warm-up, not timed: every kernel a case may call (a coarse level; graded: crowded points removed)
tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.02)
tm.generate_mesh(tm.geometry.Disk((0, 0), 1), lambda p: 0.004 * (1 + 24.5 * (p[:, 0] + 1)), h0=0.004)
domain = tm.geometry.Disk((0, 0), 1)
{setup}
# a case under a second runs again while the runs add up to a few seconds (at most 5 in all):
# the fastest run is its time, as timeit reports, free of the machine's noise at that scale
runs = []
while not runs or (len(runs) < 5 and sum(runs) + runs[0] < 3.0):
    started = time.perf_counter()
    mesh = tm.generate_mesh(domain, edge_length, h0=h0, seed=0)
    runs.append(time.perf_counter() - started)
seconds = min(runs)
q = triangle_quality(mesh.points, mesh.cells)
size = edge_length if callable(edge_length) else (lambda p: np.full(len(p), edge_length))
ratio = edge_length_ratio(mesh.points, mesh.cells, size)
print(json.dumps(dict(vertices=mesh.n_points, cells=mesh.n_cells, levels=len(mesh.info["levels"]) - 1,
    iterations=mesh.info["iterations"],
    stop=mesh.info["stop_reason"], triangulations=mesh.info["retriangulations"],
    rebuilds=sum(level.get("rebuilds", -1) for level in mesh.info["levels"]), seconds=seconds,
    mean_q=float(q.mean()), min_q=float(q.min()), edge_ratio=float(np.median(ratio)),
    peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)))
"""

COLUMNS = [
    ("case", "{:>22}"),
    ("vertices", "{:>11,}"),
    ("cells", "{:>11,}"),
    ("levels", "{:>6}"),
    ("iterations", "{:>10}"),
    ("stop", "{:>9}"),
    ("triangulations", "{:>14}"),
    ("rebuilds", "{:>8}"),
    ("seconds", "{:>8.2f}"),
    ("us_per_vertex", "{:>13.1f}"),
    ("mean_q", "{:>7.4f}"),
    ("min_q", "{:>6.3f}"),
    ("edge_ratio", "{:>10.3f}"),
    ("peak_mb", "{:>8.0f}"),
]


def run_case(setup, environment=None):
    """Mesh in a subprocess with ``setup``, Python defining ``edge_length``, ``h0`` (and ``domain``, or the disk).

    ``environment``: variables to set for the subprocess, besides this process's own.
    """
    env = None if environment is None else {**os.environ, **environment}
    output = subprocess.run(
        [sys.executable, "-c", _CASE.format(setup=setup)], capture_output=True, text=True, check=True, env=env
    )
    row = json.loads(output.stdout.strip().splitlines()[-1])
    row["us_per_vertex"] = 1e6 * row["seconds"] / row["vertices"]
    return row


def print_header():
    """Print the column names."""
    widths = [int(fmt.split(">")[1].split(",")[0].split(".")[0].rstrip("}")) for _, fmt in COLUMNS]
    header = " ".join(f"{name:>{width}}" for (name, _), width in zip(COLUMNS, widths, strict=True))
    print(header)
    print("-" * len(header))


def print_row(name, row):
    """Print one result row."""
    row = dict(row, case=name)
    print(" ".join(fmt.format(row[key]) for key, fmt in COLUMNS), flush=True)


def run_peer(python, worker, job):
    """Run ``worker`` (Python source) with a peer's interpreter ``python``, ``job`` as JSON on stdin.

    The worker prints one line ``RESULT <json>``; that JSON is returned.
    PYTHONPATH is dropped so the peer's virtual environment sees only its
    own packages.
    """
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run(
        [str(python), "-c", worker], input=json.dumps(job), capture_output=True, text=True, env=env, check=False
    )
    lines = [line for line in done.stdout.splitlines() if line.startswith("RESULT ")]
    if done.returncode != 0 or not lines:
        raise RuntimeError(f"peer worker failed (exit {done.returncode}):\n{done.stderr[-3000:]}")
    return json.loads(lines[-1][len("RESULT ") :])


def fastest(call, *args, repeat=3, **options):
    """``call(*args, **options)``'s result and its fastest time of ``repeat`` runs, in seconds."""
    seconds = []
    for _ in range(repeat):
        started = time.perf_counter()
        result = call(*args, **options)
        seconds.append(time.perf_counter() - started)
    return result, min(seconds)
