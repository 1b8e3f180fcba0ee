"""terramesh against SeismicMesh 3.6.2 on the same cases: prints a table.

Usage: python benchmarks/compare_seismicmesh.py [--cases NAME ...] [--repeat N] [--venv PATH]

terramesh runs in this process; SeismicMesh (GPL-3, a benchmark-only peer) runs
in a subprocess with the python of its own virtual environment, made by
``bash benchmarks/peers/setup_seismicmesh.sh``. Without that environment only
terramesh runs.

"seconds" is the wall time of the mesh generation call alone: imports and the
numba JIT compilation are excluded by meshing a tiny version of each case first
(in both tools), and both are timed with ``time.perf_counter`` around
``generate_mesh``. The fastest of ``--repeat`` runs (default 3) is shown. Quality
``q = 4 sqrt(3) A / sum(l^2)`` is measured on both meshes with
``terramesh.quality.triangle_quality`` after orienting cells counter-clockwise
(SeismicMesh's cell orientation is not part of its contract). "edge/h" is the
median edge length over the target size at the edge's midpoint: the two tools do
not put the same number of vertices in a domain for the same target, so compare
seconds together with vertices and edge/h.

SeismicMesh has no convergence test: it always runs ``max_iter`` force
iterations (default 50, passed explicitly here) and then deletes poor boundary
cells and runs a Laplacian smoothing; all of that is inside its timed call.
terramesh stops on convergence or stall, and reports why.
"""

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _runner import run_peer

import terramesh as tm
from terramesh.quality import triangle_quality

HERE = Path(__file__).resolve().parent
DEFAULT_VENV = HERE / "peers" / ".venv-seismicmesh"
SETUP = HERE / "peers" / "setup_seismicmesh.sh"
SEISMICMESH_MAX_ITER = 50  # SeismicMesh's default; it always runs exactly this many iterations

# name: (description, geometry, h0, graded). Graded sizes are h0 + 0.1 |d| with d the signed distance.
CASES = {
    "disk-0.01": ("unit disk, h = 0.01", "disk", 0.01, False),
    "disk-0.02": ("unit disk, h = 0.02", "disk", 0.02, False),
    "plate-graded": ("[0,2]x[0,1] minus disk((0.5,0.5), 0.2), h = 0.01 + 0.1|d|", "plate", 0.01, True),
}
# Tiny versions of each geometry, meshed first and not timed (JIT compilation, caches).
WARMUP = [("disk", 0.2, False), ("plate", 0.1, True)]

# Runs in the SeismicMesh venv; reads a JSON job from stdin, writes one .npz per case, prints JSON.
WORKER = r"""
import json, sys, time
import numpy as np
import SeismicMesh as sm

job = json.loads(sys.stdin.read())

def build(geometry, h0, graded):
    if geometry == "disk":
        domain = sm.Disk([0.0, 0.0], 1.0)
    else:
        domain = sm.Difference([sm.Rectangle((0.0, 2.0, 0.0, 1.0)), sm.Disk([0.5, 0.5], 0.2)])
    if graded:
        return domain, (lambda p: h0 + 0.1 * np.abs(domain.eval(p))), {"h0": h0}
    return domain, h0, {}

def mesh(geometry, h0, graded):
    domain, edge_length, extra = build(geometry, h0, graded)
    started = time.perf_counter()
    points, cells = sm.generate_mesh(
        domain=domain, edge_length=edge_length, verbose=0, max_iter=job["max_iter"], **extra
    )
    return points, cells, time.perf_counter() - started

for geometry, h0, graded in job["warmup"]:
    mesh(geometry, h0, graded)
results = []
for case in job["cases"]:
    best = None
    for _ in range(job["repeat"]):
        points, cells, seconds = mesh(case["geometry"], case["h0"], case["graded"])
        best = seconds if best is None else min(best, seconds)
    np.savez(case["out"], points=points, cells=cells)
    results.append({"name": case["name"], "seconds": best, "version": sm.__version__})
print("RESULT " + json.dumps(results))
"""


def terramesh_domain(geometry):
    if geometry == "disk":
        return tm.geometry.Disk((0.0, 0.0), 1.0)
    return tm.geometry.Difference([tm.geometry.Rectangle((0.0, 0.0), (2.0, 1.0)), tm.geometry.Disk((0.5, 0.5), 0.2)])


def target_size(geometry, h0, graded):
    """The case's edge-length target as a number or a function of an (n, 2) array."""
    if not graded:
        return h0
    domain = terramesh_domain(geometry)
    return lambda p: h0 + 0.1 * np.abs(domain.distance(p))


def edge_ratio(points, cells, size):
    """Median over unique edges of length / target size at the edge's midpoint."""
    edges = np.unique(np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1), axis=0)
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    target = size((a + b) / 2) if callable(size) else size
    return float(np.median(np.linalg.norm(b - a, axis=1) / target))


def run_terramesh(geometry, h0, graded, repeat=1):
    domain = terramesh_domain(geometry)
    edge_length = target_size(geometry, h0, graded)
    best = None
    for _ in range(repeat):
        started = time.perf_counter()
        mesh = tm.generate_mesh(domain, edge_length, h0=h0, seed=0)
        seconds = time.perf_counter() - started
        best = seconds if best is None else min(best, seconds)
    return mesh, best


def run_seismicmesh(python, names, repeat, workdir):
    cases = [
        {"name": n, "geometry": CASES[n][1], "h0": CASES[n][2], "graded": CASES[n][3], "out": str(workdir / f"{n}.npz")}
        for n in names
    ]
    job = {"cases": cases, "warmup": WARMUP, "repeat": repeat, "max_iter": SEISMICMESH_MAX_ITER}
    results = run_peer(python, WORKER, job)
    for r in results:
        with np.load(workdir / f"{r['name']}.npz") as data:
            r["points"], r["cells"] = data["points"], data["cells"]
    return results


def clockwise(points, cells):
    """Number of clockwise (negatively oriented) cells."""
    return int(np.count_nonzero(triangle_quality(points, cells) < 0))


def shape_quality(points, cells):
    """Quality of each cell, measured on the counter-clockwise re-oriented cell."""
    return np.abs(triangle_quality(points, cells))


def row(case, tool, points, cells, iterations, stop, seconds, ratio=""):
    _, geometry, h0, graded = CASES[case]
    q = shape_quality(points, cells)
    edge = edge_ratio(points, cells, target_size(geometry, h0, graded))
    return (
        f"{case:<13} {tool:<12} {len(points):>9,} {len(cells):>9,} {iterations:>5} {stop:<10} {seconds:>8.2f} "
        f"{q.min():>6.3f} {q.mean():>7.4f} {edge:>6.3f} {ratio:>7}"
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES), help="cases to run")
    parser.add_argument("--repeat", type=int, default=3, help="runs per case; the fastest is shown")
    parser.add_argument("--venv", type=Path, default=DEFAULT_VENV, help="SeismicMesh virtual environment")
    args = parser.parse_args(argv)

    python = args.venv / "bin" / "python"
    have_peer = python.exists()
    print(f"terramesh {tm.__version__} (in process); python {sys.version.split()[0]}; {os.cpu_count()} CPU cores")
    if not have_peer:
        print(f"SeismicMesh environment not found at {args.venv}; running terramesh only.")
        print(f"Create it with:  bash {SETUP}   (installs libcgal-dev with apt-get; compiles for a few minutes)")
    for name in args.cases:
        print(f"  {name:<13} {CASES[name][0]}")
    print()

    for geometry, h0, graded in WARMUP:
        run_terramesh(geometry, h0, graded)
    ours = {}
    for name in args.cases:
        _, geometry, h0, graded = CASES[name]
        ours[name] = run_terramesh(geometry, h0, graded, args.repeat)

    peer = {}
    if have_peer:
        with tempfile.TemporaryDirectory() as tmp:
            for r in run_seismicmesh(python, args.cases, args.repeat, Path(tmp)):
                peer[r["name"]] = r

    header = (
        f"{'case':<13} {'tool':<12} {'vertices':>9} {'cells':>9} {'iter':>5} {'stop':<10} {'seconds':>8} "
        f"{'min q':>6} {'mean q':>7} {'edge/h':>6} {'SM/tm':>7}"
    )
    print(header)
    print("-" * len(header))
    notes = []
    for name in args.cases:
        mesh, seconds = ours[name]
        if n := clockwise(mesh.points, mesh.cells):
            notes.append(f"{name}: terramesh returned {n} clockwise cells (quality measured re-oriented)")
        info = mesh.info
        print(row(name, "terramesh", mesh.points, mesh.cells, info["iterations"], info["stop_reason"], seconds))
        if name in peer:
            r = peer[name]
            if n := clockwise(r["points"], r["cells"]):
                notes.append(f"{name}: SeismicMesh returned {n} clockwise cells (quality measured re-oriented)")
            ratio = f"{r['seconds'] / seconds:.2f}"
            print(row(name, "SeismicMesh", r["points"], r["cells"], SEISMICMESH_MAX_ITER, "fixed", r["seconds"], ratio))
    print()
    if peer:
        version = next(iter(peer.values()))["version"]
        print(
            f"SeismicMesh {version}: always {SEISMICMESH_MAX_ITER} iterations (its default max_iter; no convergence "
            "test), then boundary-cell deletion and Laplacian smoothing, all inside the timed call."
        )
        print("SM/tm: SeismicMesh seconds / terramesh seconds (above 1: terramesh is faster).")
    print("edge/h: median over edges of length / target size at the edge's midpoint (1 is on target).")
    for note in notes:
        print(note)


if __name__ == "__main__":
    main()
