"""BP2004 in 3-D with a salt blob, terramesh against SeismicMesh 3.6.2 on the same velocity grid: prints a table.

Usage: python benchmarks/compare_seismic_3d.py [--seed S] [--hmin H] [--venv PATH] [--segy PATH]

The case is ``examples/seismic/bp2004_3d.py``: the BP2004 section cut to
x = 26-42 km and the top 7 km, on a 100 m grid, extruded 10 km along y,
with a lobed salt body (4500 m/s) set in; 1 Hz, 10 edges per wavelength,
hmin 300 m, grade 0.15, a 1000 m padding layer with ``pad_style="edge"``.

terramesh runs in this process. SeismicMesh (GPL-3, a benchmark-only
peer) runs in a subprocess with the python of its own virtual environment
(``bash benchmarks/peers/setup_seismicmesh.sh``) and reads the same 3-D
grid from a raw binary file: little-endian float32, z fastest (the first
sample of each trace the top), then x, then y, i.e. Fortran order of
``(nz, nx, ny)``: its ``get_sizing_function_from_segy(file, (zmin, zmax,
xmin, xmax, ymin, ymax), nz=, nx=, ny=, byte_order="little",
axes_order=(0, 1, 2), axes_order_sort="F")``. The bbox is the grid's exact
extent, so its interpolant's nodes are the model's. It is called as in
its README's 3-D (EAGE) example: ``generate_mesh(domain=Cube(bbox),
edge_length=ef, max_iter=75)`` then ``sliver_removal(points, domain=cube,
edge_length=ef, preserve=True)``; both calls are needed for its bound on
the dihedral angles, so both are in its "mesh s" (the split is printed
below the table). Its mesh covers the padded box (it rebuilds the cube
from the size function's bbox). terramesh's "mesh s" is one
``generate_mesh(size.domain, size)`` call, which includes its sliver
removal. Both are timed after a warm-up mesh (imports and the numba JIT
excluded); "sizing s" is reading the model plus building the sizes (for
SeismicMesh, the binary file it reads).

The size functions differ by design in three places: terramesh grows the
size at the grade limit in the padding layer (``coarsen_pad=True``) where
SeismicMesh copies the edge sizes outward; terramesh takes the smallest
velocity within an ``hmin`` window (``velocity_window``) where SeismicMesh
uses each node's own; and SeismicMesh grades with a cell length of
extent / n (98.6 m in z for this 100 m grid) rather than the spacing.
Quality is measured the same way on both meshes (terramesh's
``min_max_dihedral`` and ``radius_ratio``, cells oriented positively
first, in (x, y, z) order); "edge/h" is the median over edges of the
length over each tool's own size function at the edge's middle.
"""

import argparse
import importlib.util
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _runner import run_peer

import terramesh as tm
from terramesh.quality.tetra import min_max_dihedral, radius_ratio, tetra_volumes

HERE = Path(__file__).resolve().parent
DEFAULT_VENV = HERE / "peers" / ".venv-seismicmesh"
EXAMPLE = HERE.parent / "examples" / "seismic" / "bp2004_3d.py"

WORKER = r"""
import json, sys, time
import numpy as np
import SeismicMesh as sm

job = json.loads(sys.stdin.read())
s = job["settings"]
bbox = tuple(job["bbox"])
started = time.perf_counter()
ef = sm.get_sizing_function_from_segy(
    job["binary"], bbox, hmin=s["hmin"], wl=s["cells_per_wavelength"], freq=s["frequency"], grade=s["grade"],
    domain_pad=s["pad"], pad_style=s["pad_style"], nz=job["nz"], nx=job["nx"], ny=job["ny"],
    byte_order="little", axes_order=(0, 1, 2), axes_order_sort="F", dtype="float32",
)
sizing = time.perf_counter() - started
unit = sm.Cube((0.0, 1.0, 0.0, 1.0, 0.0, 1.0))
warm, _ = sm.generate_mesh(domain=unit, edge_length=0.25, verbose=0)
sm.sliver_removal(points=warm, domain=unit, edge_length=0.25, verbose=0)
cube = sm.Cube(bbox)
started = time.perf_counter()
points, cells = sm.generate_mesh(domain=cube, edge_length=ef, max_iter=75, seed=job["seed"], verbose=0)
generated = time.perf_counter() - started
points, cells = sm.sliver_removal(points=points, domain=cube, edge_length=ef, preserve=True, verbose=0)
seconds = time.perf_counter() - started
edges = np.unique(np.sort(cells[:, [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]].reshape(-1, 2), axis=1), axis=0)
a, b = points[edges[:, 0]], points[edges[:, 1]]
ratio = float(np.median(np.linalg.norm(b - a, axis=1) / ef.eval((a + b) / 2)))
np.savez(job["out"], points=points[:, [1, 2, 0]], cells=cells)  # SeismicMesh is (z, x, y): store (x, y, z)
print("RESULT " + json.dumps({
    "sizing": sizing, "seconds": seconds, "generate": generated, "edge_ratio": ratio, "bbox": list(ef.bbox),
    "version": sm.__version__,
}))
"""


def load_example():
    """The 3-D BP2004 example as a module (examples/ is not a package)."""
    spec = importlib.util.spec_from_file_location("bp2004_3d", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_seismicmesh_binary(model, path):
    """The 3-D model as SeismicMesh reads it: float32 little-endian, Fortran order of (nz, nx, ny), top first."""
    top_first = model.values[:, :, ::-1]  # [x, y, z] with z increasing upward -> the first sample on top
    np.ascontiguousarray(top_first.transpose(1, 0, 2), dtype="<f4").tofile(path)  # C order of (y, x, z)


def measure(points, cells, box):
    """Cells oriented positively, their smallest dihedral angles and radius ratios, and validity problems."""
    volumes = tetra_volumes(points, cells)
    cells = np.where((volumes < 0)[:, None], cells[:, [0, 2, 1, 3]], cells)
    problems = []
    if np.any(volumes == 0):
        problems.append(f"{int(np.sum(volumes == 0))} flat cells")
    unused = np.bincount(cells.ravel(), minlength=len(points)) == 0
    if unused.any():
        problems.append(f"{int(unused.sum())} unused vertices")
    faces = np.sort(np.concatenate([np.delete(cells, k, axis=1) for k in range(4)]), axis=1)
    unique_faces, counts = np.unique(faces, axis=0, return_counts=True)
    if counts.max() > 2:
        problems.append(f"{int(np.sum(counts > 2))} faces in more than two cells")
    boundary = np.unique(unique_faces[counts == 1])
    off = np.abs(box.distance(points[boundary])) > 1.0  # metres
    if off.any():
        problems.append(f"{int(off.sum())} boundary vertices more than 1 m off the box")
    volume = float(np.abs(volumes).sum())
    box_volume = float(np.prod(box.bbox[1] - box.bbox[0]))
    if abs(volume - box_volume) > 1e-6 * box_volume:
        problems.append(f"volume {volume:.6g} m^3, {100 * (volume / box_volume - 1):+.4f} % off the box's")
    smallest = min_max_dihedral(points, cells)[0]
    return smallest, radius_ratio(points, cells), problems


def edge_ratio(points, cells, size):
    """Median over unique edges of length / target size at the edge's midpoint."""
    pairs = cells[:, [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]].reshape(-1, 2)
    edges = np.unique(np.sort(pairs, axis=1), axis=0)
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    return float(np.median(np.linalg.norm(b - a, axis=1) / size((a + b) / 2)))


def run_seismicmesh(python, model, settings, seed, workdir):
    binary = workdir / "bp2004_3d.bin"
    started = time.perf_counter()
    write_seismicmesh_binary(model, binary)
    writing = time.perf_counter() - started
    (x0, y0, z0), (x1, y1, z1) = model.bbox
    nx, ny, nz = model.shape
    job = {
        "binary": str(binary),
        "bbox": [z0, z1, x0, x1, y0, y1],
        "nx": nx,
        "ny": ny,
        "nz": nz,
        "settings": settings,
        "seed": seed,
        "out": str(workdir / "seismicmesh.npz"),
    }
    result = run_peer(python, WORKER, job)
    result["sizing"] += writing
    with np.load(job["out"]) as data:
        result["points"], result["cells"] = data["points"], data["cells"]
    return result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0, help="seed of both generators")
    parser.add_argument(
        "--hmin",
        type=float,
        default=None,
        help="override hmin (metres), e.g. 400 for a quicker run (still graded: from 479 m on it is uniform)",
    )
    parser.add_argument("--venv", type=Path, default=DEFAULT_VENV, help="SeismicMesh virtual environment")
    parser.add_argument("--segy", type=Path, default=None, help="the BP2004 velocity SEG-Y file")
    args = parser.parse_args(argv)

    example = load_example()
    settings = dict(example.SETTINGS)
    if args.hmin is not None:
        settings["hmin"] = args.hmin
    segy = args.segy or example.SEGY
    python = args.venv / "bin" / "python"
    print(f"terramesh {tm.__version__} (in process); python {sys.version.split()[0]}; {os.cpu_count()} CPU cores")
    print(f"BP2004 3-D from {segy.name}; settings {settings}")
    model, size, mesh, sizing, seconds = example.run(segy, args.seed, settings)
    print(f"model {model}")
    print(f"terramesh sizes {size}")
    peer = None
    if python.exists():
        with tempfile.TemporaryDirectory() as tmp:
            peer = run_seismicmesh(python, model, settings, args.seed, Path(tmp))
    else:
        print(f"SeismicMesh environment not found at {args.venv}; running terramesh only.")
    print()

    header = (
        f"{'tool':<12} {'vertices':>9} {'tets':>10} {'sizing s':>8} {'mesh s':>7} {'min dih':>7} "
        f"{'mean dih':>8} {'<10 deg':>7} {'min rr':>6} {'mean rr':>7} {'edge/h':>6} {'SM/tm':>6}"
    )
    print(header)
    print("-" * len(header))
    notes = []
    rows = [("terramesh", mesh.points, mesh.cells, sizing, seconds, edge_ratio(mesh.points, mesh.cells, size))]
    if peer:
        rows.append(("SeismicMesh", peer["points"], peer["cells"], peer["sizing"], peer["seconds"], peer["edge_ratio"]))
    for tool, points, cells, tool_sizing, tool_seconds, ratio in rows:
        smallest, rr, problems = measure(points, cells, size.domain)
        notes += [f"{tool}: {p}" for p in problems]
        speed = "" if tool == "terramesh" else f"{tool_seconds / seconds:.2f}"
        print(
            f"{tool:<12} {len(points):>9,} {len(cells):>10,} {tool_sizing:>8.2f} {tool_seconds:>7.1f} "
            f"{smallest.min():>7.2f} {smallest.mean():>8.2f} {int(np.sum(smallest < 10.0)):>7} "
            f"{rr.min():>6.3f} {rr.mean():>7.3f} {ratio:>6.3f} {speed:>6}"
        )
    print()
    print(
        "min dih / mean dih: smallest dihedral angle over the mesh / mean over cells of each cell's smallest, degrees."
    )
    print("<10 deg: tets whose smallest dihedral angle is below 10 degrees. rr: radius ratio 3 r_in / r_circ.")
    if peer:
        print(
            f"SeismicMesh {peer['version']}: generate_mesh {peer['generate']:.1f} s (75 iterations) + sliver_removal "
            f"{peer['seconds'] - peer['generate']:.1f} s. SM/tm: its mesh seconds / terramesh's (above 1: terramesh "
            "is faster)."
        )
    for tool, points, *_ in rows:
        extent = zip("xyz", points.min(axis=0), points.max(axis=0), strict=True)
        print(f"{tool} mesh extent: " + ", ".join(f"{axis} {lo:.6g}..{hi:.6g} m" for axis, lo, hi in extent))
    for note in notes:
        print(note)


if __name__ == "__main__":
    main()
