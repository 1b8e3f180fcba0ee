"""Repairs and checks of a large coastal mesh: fix_mesh, clean, mesh_problems, enforce_timestep.

Usage: python benchmarks/bench_repair.py [--mesh FILE.14]   (about 2 minutes; reads ../shared/data)

The mesh is the OceanMesh2D guide's §5.3 (318,567 vertices, 587,169 cells), made by
examples/coastal/us_east_coast_gulf.py here in about a minute unless ``--mesh`` names a
fort.14 of it (or of any mesh with depths). Each step's time is its fastest of five runs,
on a mesh that is valid already: what a repair costs when there is nothing to repair, as
in ``build``'s clean-up, after ``enforce_timestep``'s rounds and in ``merge``.
"""

import argparse
import pathlib
import subprocess
import sys
import tempfile
import time
import warnings

import terramesh as tm
from terramesh.cleanup import clean, fix_mesh, mesh_problems
from terramesh.coastal import enforce_timestep
from terramesh.mesh.topology import boundary_edges, cell_neighbor_table

ROOT = pathlib.Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
EXAMPLE = ROOT / "examples" / "coastal" / "us_east_coast_gulf.py"
RUNS = 5


def _guide_mesh():
    """The mesh of ``examples/coastal/us_east_coast_gulf.py``, made by the example in a scratch folder."""
    with tempfile.TemporaryDirectory() as scratch:
        subprocess.run([sys.executable, str(EXAMPLE), "--data", str(DATA), "--output", scratch], check=True)
        return tm.read_mesh(pathlib.Path(scratch) / "us_east_coast_gulf.14")


def _fastest(step):
    """The fastest of ``RUNS`` runs of ``step()`` (seconds) and its last result; one untimed run first."""
    step()
    seconds = []
    for _ in range(RUNS):
        started = time.perf_counter()
        result = step()
        seconds.append(time.perf_counter() - started)
    return min(seconds), result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", type=pathlib.Path, help="a fort.14 with depths (default: build the guide's §5.3)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    mesh = tm.read_mesh(args.mesh) if args.mesh else _guide_mesh()
    print(f"mesh: {mesh.n_points:,} vertices, {mesh.n_cells:,} cells, {len(mesh_problems(mesh))} problems")
    cases = [
        ("cell_neighbor_table", lambda: cell_neighbor_table(mesh.cells)),
        ("boundary_edges", lambda: boundary_edges(mesh.cells)),
        ("mesh_problems", lambda: mesh_problems(mesh)),
        ("fix_mesh", lambda: fix_mesh(mesh, disjoint_cutoff=0.0)),
        ("clean", lambda: clean(mesh)),
        ("enforce_timestep dt=8 s", lambda: enforce_timestep(mesh, 8.0)),
    ]
    print(f"{'step':>24} {'seconds':>8} {'vertices':>10} {'cells':>10}")
    for name, step in cases:
        seconds, result = _fastest(step)
        if isinstance(result, tm.Mesh):
            vertices, cells = f"{result.n_points:,}", f"{result.n_cells:,}"
        else:
            vertices = cells = "-"
        print(f"{name:>24} {seconds:8.3f} {vertices:>10} {cells:>10}")


if __name__ == "__main__":
    main()
