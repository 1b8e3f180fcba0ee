"""BP2004 in 2D, terramesh against SeismicMesh 3.6.2 with SeismicMesh's README settings: prints a table.

Usage: python benchmarks/compare_seismic_bp2004.py [--repeat N] [--seed S] [--venv PATH] [--segy PATH]

The settings are those of SeismicMesh's README example: hmin 75 m, a 2 Hz
source, 10 cells per wavelength, dt 0.001 s (default Courant number 1),
grade 0.15, a 1000 m padding layer with pad_style "edge", and SeismicMesh
is called exactly as there. Its README passes the unpadded rectangle as the
domain, but its mesh covers the padded box (its generator takes the bbox of
the size function, which includes the pad), so both tools mesh the padded
box: 69 km x 12.9 km. In the layer terramesh grows the size at the grade
limit (``coarsen_pad=True``) where SeismicMesh keeps the edge sizes, so
the meshes differ there by design.

terramesh runs in this process; SeismicMesh (GPL-3, a benchmark-only peer)
runs in a subprocess with the python of its own virtual environment
(``bash benchmarks/peers/setup_seismicmesh.sh``). "sizing s" is reading the
SEG-Y file plus building the size function; "mesh s" is the
``generate_mesh`` call alone, after a warm-up mesh in each tool (imports and
the numba JIT excluded), the fastest of ``--repeat`` runs. SeismicMesh
always runs 50 force iterations, then deletes poor boundary cells and
smooths, all inside its call. Quality ``q = 4 sqrt(3) A / sum(l^2)`` is
measured on both meshes with ``terramesh.quality.triangle_quality``, on
counter-clockwise cells and in (x, z) order. "edge/h" is the median over
edges of the length over each tool's own size function at the edge's
middle.

The two tools do not place the model in the same box: SeismicMesh's README
stretches the 5,395 x 1,911 grid (12.5 m x 6.25 m, 67,425 m x 11,937.5 m)
onto its bbox of 67,000 m x 12,000 m; terramesh reads the spacing from the
SEG-Y headers. The areas differ by 0.1 %.
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
from terramesh import seismic
from terramesh.quality import triangle_quality

HERE = Path(__file__).resolve().parent
DEFAULT_VENV = HERE / "peers" / ".venv-seismicmesh"
DEFAULT_SEGY = HERE.parent.parent / "shared" / "data" / "seismic" / "vel_z6.25m_x12.5m_exact.segy"
SETTINGS = {"hmin": 75.0, "frequency": 2.0, "cells_per_wavelength": 10, "dt": 0.001, "grade": 0.15, "pad": 1000.0}
README_BBOX = (-12000.0, 0.0, 0.0, 67000.0)  # SeismicMesh's (zmin, zmax, xmin, xmax)

WORKER = r"""
import json, sys, time
import numpy as np
import SeismicMesh as sm

job = json.loads(sys.stdin.read())
s = job["settings"]
started = time.perf_counter()
ef = sm.get_sizing_function_from_segy(
    job["segy"], tuple(job["bbox"]), hmin=s["hmin"], wl=s["cells_per_wavelength"], freq=s["frequency"],
    dt=s["dt"], grade=s["grade"], domain_pad=s["pad"], pad_style="edge",
)
sizing = time.perf_counter() - started
sm.generate_mesh(domain=sm.Rectangle((0.0, 1.0, 0.0, 1.0)), edge_length=0.1, verbose=0)  # warm-up
results = []
for name, bbox in (("padded box", tuple(job["bbox"])),):  # the README's call; the mesh fills ef.bbox
    best = None
    for _ in range(job["repeat"]):
        started = time.perf_counter()
        points, cells = sm.generate_mesh(
            domain=sm.Rectangle(bbox), edge_length=ef, h0=s["hmin"], verbose=0, seed=job["seed"]
        )
        seconds = time.perf_counter() - started
        best = seconds if best is None else min(best, seconds)
    edges = np.unique(np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1), axis=0)
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    ratio = float(np.median(np.linalg.norm(b - a, axis=1) / ef.eval((a + b) / 2)))
    out = job["out"] + "_" + name.replace(" ", "_") + ".npz"
    np.savez(out, points=points[:, [1, 0]], cells=cells)  # SeismicMesh is (z, x): store (x, z)
    results.append({"name": name, "seconds": best, "edge_ratio": ratio, "file": out})
print("RESULT " + json.dumps({"sizing": sizing, "cases": results, "version": sm.__version__}))
"""


def edge_ratio(points, cells, size):
    """Median over unique edges of length / target size at the edge's midpoint."""
    edges = np.unique(np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1), axis=0)
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    return float(np.median(np.linalg.norm(b - a, axis=1) / size((a + b) / 2)))


def measure(points, cells):
    """Quality on counter-clockwise cells, the number of cells below 0.7, and validity problems."""
    q = triangle_quality(points, cells)
    clockwise = q < 0
    cells = np.where(clockwise[:, None], cells[:, [0, 2, 1]], cells)
    q = np.abs(q)
    problems = tm.cleanup.mesh_problems(tm.Mesh(points, cells))
    return q, int(clockwise.sum()), problems


def run_terramesh(segy, repeat, seed):
    started = time.perf_counter()
    model = seismic.read_velocity(segy)
    size = seismic.size_function(model, pad_style="edge", **SETTINGS)
    sizing = time.perf_counter() - started
    tm.generate_mesh(tm.geometry.Rectangle((0.0, 0.0), (1.0, 1.0)), 0.1)  # warm-up: JIT and caches
    domains = {"padded box": size.domain}
    results = {}
    for name, domain in domains.items():
        best, mesh = None, None
        for _ in range(repeat):
            started = time.perf_counter()
            mesh = tm.generate_mesh(domain, size, seed=seed)
            seconds = time.perf_counter() - started
            best = seconds if best is None else min(best, seconds)
        results[name] = (mesh, best, edge_ratio(mesh.points, mesh.cells, size))
    return model, size, sizing, results


def run_seismicmesh(python, segy, repeat, seed, workdir):
    job = {
        "segy": str(segy),
        "bbox": README_BBOX,
        "settings": SETTINGS,
        "repeat": repeat,
        "seed": seed,
        "out": str(workdir / "seismicmesh"),
    }
    result = run_peer(python, WORKER, job)
    for case in result["cases"]:
        with np.load(case["file"]) as data:
            case["points"], case["cells"] = data["points"], data["cells"]
    return result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1, help="runs per case; the fastest is shown")
    parser.add_argument("--seed", type=int, default=0, help="seed of both generators")
    parser.add_argument("--venv", type=Path, default=DEFAULT_VENV, help="SeismicMesh virtual environment")
    parser.add_argument("--segy", type=Path, default=DEFAULT_SEGY, help="the BP2004 velocity SEG-Y file")
    args = parser.parse_args(argv)

    python = args.venv / "bin" / "python"
    print(f"terramesh {tm.__version__} (in process); python {sys.version.split()[0]}; {os.cpu_count()} CPU cores")
    print(f"BP2004 {args.segy.name}; settings {SETTINGS}, pad_style 'edge'")
    model, size, sizing, ours = run_terramesh(args.segy, args.repeat, args.seed)
    print(f"terramesh model {model}")
    print(f"terramesh sizes {size}")
    peer = None
    if python.exists():
        with tempfile.TemporaryDirectory() as tmp:
            peer = run_seismicmesh(python, args.segy, args.repeat, args.seed, Path(tmp))
    else:
        print(f"SeismicMesh environment not found at {args.venv}; running terramesh only.")
    print()

    header = (
        f"{'case':<11} {'tool':<12} {'vertices':>9} {'cells':>9} {'sizing s':>8} {'mesh s':>7} "
        f"{'min q':>6} {'mean q':>7} {'q<0.7':>5} {'edge/h':>6} {'SM/tm':>6}"
    )
    print(header)
    print("-" * len(header))
    notes = []
    for name in ("padded box",):
        mesh, seconds, ratio = ours[name]
        q, clockwise, problems = measure(mesh.points, mesh.cells)
        notes += [f"{name}, terramesh: {p}" for p in problems]
        print(
            f"{name:<11} {'terramesh':<12} {mesh.n_points:>9,} {mesh.n_cells:>9,} {sizing:>8.2f} {seconds:>7.2f} "
            f"{q.min():>6.3f} {q.mean():>7.4f} {int(np.sum(q < 0.7)):>5} {ratio:>6.3f} {'':>6}"
        )
        if peer:
            case = next(c for c in peer["cases"] if c["name"] == name)
            q, clockwise, problems = measure(case["points"], case["cells"])
            notes += [f"{name}, SeismicMesh: {p}" for p in problems]
            if clockwise:
                notes.append(f"{name}, SeismicMesh: {clockwise} clockwise cells (quality measured re-oriented)")
            print(
                f"{'':<11} {'SeismicMesh':<12} {len(case['points']):>9,} {len(case['cells']):>9,} "
                f"{peer['sizing']:>8.2f} {case['seconds']:>7.2f} {q.min():>6.3f} {q.mean():>7.4f} "
                f"{int(np.sum(q < 0.7)):>5} {case['edge_ratio']:>6.3f} {case['seconds'] / seconds:>6.2f}"
            )
    print()
    if peer:
        print(f"SeismicMesh {peer['version']}: 50 iterations, boundary-cell deletion and smoothing in its call.")
        print("SM/tm: SeismicMesh mesh seconds / terramesh mesh seconds (above 1: terramesh is faster).")
    print("q<0.7: cells below quality 0.7. edge/h: median edge length / the tool's own target size.")
    for tool, points in [("terramesh", ours["padded box"][0].points)] + (
        [("SeismicMesh", peer["cases"][0]["points"])] if peer else []
    ):
        (x0, z0), (x1, z1) = points.min(axis=0), points.max(axis=0)
        print(f"{tool} mesh extent: x {x0:g}..{x1:g} m, z {z0:g}..{z1:g} m")
    for note in notes:
        print(note)


if __name__ == "__main__":
    main()
