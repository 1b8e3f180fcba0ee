"""Meshing in strips (tm.parallel.generate_mesh_parallel) against meshing whole, serially and on MPI ranks.

Usage: python benchmarks/bench_parallel.py [h [ranks]]   (default 0.002 2: the unit disk, about 920k vertices)
       python benchmarks/bench_parallel.py small          (strips of small meshes: what they cost beyond the whole)
       python benchmarks/bench_parallel.py 3d [frequency [ranks]]   (default 1 Hz, 2: BP2004 3-D in slabs)

Rows: the disk meshed whole; in ``ranks`` strips one after the other in this
process; in ``ranks`` strips on ``ranks`` MPI ranks (``mpiexec``, from the
``mpich`` wheel of the ``mpi`` extra; skipped without mpi4py). Seconds are
wall time around the call, after a warm-up run of each (numba compilation);
on MPI, rank 0's, the gather and the merge included. The strips' own
seconds show how evenly the work was shared.

``3d``: the model of ``examples/seismic/bp2004_3d.py`` (BP2004 extruded, a
salt body set in; at 1 Hz 65k vertices, at 1.5 Hz about 210k) meshed whole,
in 2 and 4 slabs in this process and in ``ranks`` slabs on ``ranks`` MPI
ranks; quality is the radius ratio (mean, first percentile) and the smallest
dihedral angle, "near cuts" the mean radius ratio of the cells within a size
of a cut.

``small``: random-walk coasts of 1,000 vertices (as in ``bench_coastal.py``)
meshed whole and in 2-4 strips, fastest of three runs each; "cuts" is the
part of the strips' time spent placing the cuts (``strip_cuts``).
"""

import json
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np
from _runner import fastest
from bench_coastal import RANDOM_WALK

import terramesh as tm
from terramesh.generation.options import checked_options
from terramesh.parallel.decompose import strip_cuts
from terramesh.quality import triangle_quality

_MPI_RUN = textwrap.dedent(
    """
    import json, sys, time
    from mpi4py import MPI
    import terramesh as tm
    disk = tm.geometry.Disk((0, 0), 1)
    tm.parallel.generate_mesh_parallel(disk, 0.05, comm=MPI.COMM_WORLD)  # warm-up
    MPI.COMM_WORLD.Barrier()
    started = time.perf_counter()
    mesh = tm.parallel.generate_mesh_parallel(disk, float(sys.argv[1]), comm=MPI.COMM_WORLD)
    if MPI.COMM_WORLD.Get_rank() == 0:
        seconds = time.perf_counter() - started
        q = tm.quality.triangle_quality(mesh.points, mesh.cells)
        strips = [round(strip["seconds"], 2) for strip in mesh.info["parts"]]
        print(json.dumps(dict(vertices=mesh.n_points, seconds=seconds, min_q=float(q.min()), mean_q=float(q.mean()),
                              strips=strips)))
    """
)


def mpi_launcher():
    """``mpiexec`` beside this Python (the ``mpich`` wheel) or on the PATH; None, said, without it or mpi4py."""
    launcher = shutil.which("mpiexec", path=str(Path(sys.executable).parent)) or shutil.which("mpiexec")
    try:
        import mpi4py  # noqa: F401
    except ImportError:
        launcher = None
    if launcher is None:
        print("(no mpi4py / mpiexec: install the mpi extra for the MPI row)")
    return launcher


def row(method, vertices, seconds, min_q, mean_q, strips=""):
    print(f"{method:>18} {vertices:>10,} {seconds:>8.2f} {min_q:>6.3f} {mean_q:>7.4f}  {strips}", flush=True)


def timed(call, *args, **options):
    call(*args, **options)  # warm-up
    started = time.perf_counter()
    mesh = call(*args, **options)
    return mesh, time.perf_counter() - started


def report(method, mesh, seconds):
    q = triangle_quality(mesh.points, mesh.cells)
    strips = [round(strip["seconds"], 2) for strip in mesh.info.get("parts", [])]
    row(method, mesh.n_points, seconds, float(q.min()), float(q.mean()), strips or "")


def main(h=0.002, ranks=2):
    disk = tm.geometry.Disk((0, 0), 1)
    print(f"{'method':>18} {'vertices':>10} {'seconds':>8} {'min q':>6} {'mean q':>7}  strips' seconds")
    report("whole", *timed(tm.generate_mesh, disk, h, seed=0))
    report(f"{ranks} strips, serial", *timed(tm.parallel.generate_mesh_parallel, disk, h, parts=ranks))
    launcher = mpi_launcher()
    if launcher is None:
        return
    with tempfile.TemporaryDirectory() as folder:
        script = Path(folder) / "run.py"
        script.write_text(_MPI_RUN)
        output = subprocess.run(
            [launcher, "-n", str(ranks), sys.executable, str(script), str(h)],
            capture_output=True,
            text=True,
            check=True,
        )
    result = json.loads(output.stdout.strip().splitlines()[-1])
    row(
        f"{ranks} strips, {ranks} ranks",
        result["vertices"],
        result["seconds"],
        result["min_q"],
        result["mean_q"],
        result["strips"],
    )


_MPI_RUN_3D = textwrap.dedent(
    """
    import importlib.util, json, sys, time
    from mpi4py import MPI
    import terramesh as tm
    spec = importlib.util.spec_from_file_location("bp2004_3d", sys.argv[2])
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    size = tm.seismic.size_function(example.build_model(), **dict(example.SETTINGS, frequency=float(sys.argv[1])))
    tm.parallel.generate_mesh_parallel(size.domain, size, comm=MPI.COMM_WORLD)  # warm-up
    MPI.COMM_WORLD.Barrier()
    started = time.perf_counter()
    mesh = tm.parallel.generate_mesh_parallel(size.domain, size, comm=MPI.COMM_WORLD)
    if MPI.COMM_WORLD.Get_rank() == 0:
        seconds = time.perf_counter() - started
        mesh.info["seconds"] = seconds
        tm.io.write_mesh(sys.argv[3], mesh)
        slabs = [round(slab["seconds"], 2) for slab in mesh.info["parts"]]
        print(json.dumps(dict(seconds=seconds, slabs=slabs, cuts=mesh.info["cuts"], axis=mesh.info["axis"])))
    """
)
EXAMPLE_3D = Path(__file__).resolve().parent.parent / "examples" / "seismic" / "bp2004_3d.py"


def row_3d(method, mesh, seconds, size, slabs=None):
    from terramesh.quality.tetra import min_max_dihedral, radius_ratio

    ratio = radius_ratio(mesh.points, mesh.cells)
    cuts = np.asarray(mesh.info.get("cuts") or [], dtype=np.float64)
    near = ""
    if len(cuts):
        centres = mesh.points[mesh.cells].mean(axis=1)
        gaps = np.min(np.abs(centres[:, mesh.info["axis"], None] - cuts[None, :]), axis=1) / size(centres)
        near = f"{ratio[gaps < 1].mean():.4f}"
    slabs = [round(slab["seconds"], 2) for slab in mesh.info.get("parts", [])] if slabs is None else slabs
    print(
        f"{method:>18} {mesh.n_points:>9,} {seconds:>8.2f} {ratio.mean():>7.4f} {np.percentile(ratio, 1):>6.3f} "
        f"{min_max_dihedral(mesh.points, mesh.cells)[0].min():>7.2f} {near:>9}  {slabs if len(cuts) else ''}",
        flush=True,
    )


def main_3d(frequency=1.0, ranks=2):
    import importlib.util

    spec = importlib.util.spec_from_file_location("bp2004_3d", EXAMPLE_3D)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    size = tm.seismic.size_function(example.build_model(), **dict(example.SETTINGS, frequency=frequency))
    quality = f"{'mean rr':>7} {'p1 rr':>6} {'min dih':>7} {'near cuts':>9}"
    print(f"{'method':>18} {'vertices':>9} {'seconds':>8} {quality}  slabs' seconds")
    row_3d("whole", *timed(tm.generate_mesh, size.domain, size, seed=0), size)
    for parts in (2, 4):
        mesh, seconds = timed(tm.parallel.generate_mesh_parallel, size.domain, size, parts=parts)
        row_3d(f"{parts} slabs, serial", mesh, seconds, size)
    launcher = mpi_launcher()
    if launcher is None:
        return
    with tempfile.TemporaryDirectory() as folder:
        script, written = Path(folder) / "run.py", Path(folder) / "mesh.vtu"
        script.write_text(_MPI_RUN_3D)
        output = subprocess.run(
            [launcher, "-n", str(ranks), sys.executable, str(script), str(frequency), str(EXAMPLE_3D), str(written)],
            capture_output=True,
            text=True,
            check=True,
        )
        result = json.loads(output.stdout.strip().splitlines()[-1])
        mesh = tm.io.read_mesh(written)
    mesh.info.update(cuts=result["cuts"], axis=result["axis"])
    row_3d(f"{ranks} slabs, {ranks} ranks", mesh, result["seconds"], size, result["slabs"])


def small():
    print(f"{'case':>20} {'parts':>5} {'vertices':>9} {'whole s':>8} {'strips s':>9} {'cuts s':>7} {'ratio':>6}")
    for seed, h in ((3, 0.04), (5, 0.06)):
        namespace = {"np": np, "tm": tm}
        exec(RANDOM_WALK.format(n=1000, seed=seed, h=h), namespace)  # defines domain
        domain = namespace["domain"]
        tm.parallel.generate_mesh_parallel(domain, h, parts=2)  # warm-up (numba compilation)
        _, whole = fastest(tm.generate_mesh, domain, h)
        size, h0, *_ = checked_options(domain, h, None, domain.bbox, None, 300, 1e-2)
        for parts in (2, 3, 4):
            mesh, strips = fastest(tm.parallel.generate_mesh_parallel, domain, h, parts=parts)
            _, cuts = fastest(strip_cuts, domain, size, parts, h0)
            case = f"walk 1000/{seed}, h {h}"
            columns = f"{parts:>5} {mesh.n_points:>9,} {whole:>8.3f} {strips:>9.3f} {cuts:>7.3f} {strips / whole:>6.1f}"
            print(f"{case:>20} {columns}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["small"]:
        small()
    elif sys.argv[1:2] == ["3d"]:
        main_3d(*(float(a) for a in sys.argv[2:3]), *(int(a) for a in sys.argv[3:4]))
    else:
        main(*(float(a) for a in sys.argv[1:2]), *(int(a) for a in sys.argv[2:3]))
