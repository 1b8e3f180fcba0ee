"""Record which kernels each stage of terramesh compiles, and for which argument types.

Usage: python tools/record_kernel_signatures.py [SHARED_DATA]   (default ../shared/data)

Runs a small job of each stage (2D generation; the bundled demo; a coastal build
with a DEM and the solver-file chain; a seismic mesh; 3D generation), each in a
fresh process on an empty numba cache, notes every kernel compiled from Python with
its argument types and compile seconds (and, without seconds, the kernels compiled
within them, which are cached with them), and writes
``src/terramesh/_kernels/signatures.json``, from which a first run compiles its
stages ahead in parallel (:mod:`terramesh._kernels.precompile`). Run it again when a
kernel's arguments change: ``tests/_kernels/test_precompile.py`` fails when a stage's
job calls a kernel with argument types the table does not list.
"""

import datetime
import json
import os
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
TABLE = ROOT / "src" / "terramesh" / "_kernels" / "signatures.json"

# both 3D stages' jobs end on it
_EXACT_CUBIC_LATTICE = """\
# an exact cubic lattice: the quick kernel reports flat cells, and the exact one is compiled too
from terramesh.generation.triangulate import delaunay_3d
delaunay_3d(np.stack(np.meshgrid(*[np.arange(7.0)] * 3, indexing="ij"), axis=-1).reshape(-1, 3))
"""

# one job per stage, each in its own process on an empty cache: a stage lists all it compiles
STAGES = {
    "generation": """
disk = tm.geometry.Disk((0, 0), 1)
tm.generate_mesh(disk, 0.05, seed=0)
tm.generate_mesh(disk, 0.01, seed=0)
tm.generate_mesh(disk, lambda p: 0.004 * (1 + 24.5 * (p[:, 0] + 1)), h0=0.004, seed=0)
angle = np.linspace(0, 2 * np.pi, 60, endpoint=False)
star = tm.geometry.Polygon(np.c_[np.cos(angle), np.sin(angle)] * (1 + 0.3 * np.cos(5 * angle))[:, None])
tm.generate_mesh(star, 0.05, seed=0)
plate = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (3, 1)), tm.geometry.Disk((1, 0.5), 0.2)])
tm.generate_mesh(plate, lambda p: 0.02 + 0.05 * p[:, 0], h0=0.02, seed=0)
# adapt_mesh compiles this stage ahead too: a disk refined by half around a spot
mesh = tm.generate_mesh(disk, 0.03, seed=0)
spot = lambda p: 0.03 * (1 - 0.5 * np.exp(-((p[:, 0] - 0.3) ** 2 + p[:, 1] ** 2) / 0.05))
tm.adapt_mesh(mesh, disk, spot, old_edge_length=0.03)
""",
    "demo": """
import argparse
from terramesh.cli import demo
parser = argparse.ArgumentParser()
demo.add_arguments(parser)
demo.run(parser.parse_args(["-o", str(scratch / "demo")]))
""",
    "coastal": """
dem = data / "dem" / "ETOPO1_0.1.grd"
mesh = tm.coastal.build((-71.0, -65.0, 41.0, 45.0), data / "coast" / "GSHHS_l_L1.shp", dem, min_el=3000,
                        max_el=30e3, fs=3, wl=40, slp=20, ch=0.5, g=0.2, dt=0, itmax=30)
mesh = tm.coastal.interpolate_bathymetry(mesh, dem, min_depth=1.0)
mesh = tm.coastal.make_boundaries(mesh)
tm.coastal.courant_number(mesh, 60.0)
mesh = tm.coastal.enforce_timestep(mesh, 60.0)
mesh = tm.coastal.renumber(mesh)
mesh.write(str(scratch / "gulf_of_maine.14"))
# the guide's a + b (multiscale method "merge"): a finer Cape Cod kept over the Gulf of Maine
cape_cod = tm.coastal.build((-70.8, -69.8, 41.4, 42.2), data / "coast" / "GSHHS_l_L1.shp", dem, min_el=1500,
                            max_el=10e3, fs=3, g=0.2, itmax=30)
tm.coastal.merge(cape_cod, mesh)
# multiscale sizes: the graded cone around an inner box
import shapely
from terramesh.coastal.multiscale import CompositeSize
land = shapely.box(-1.0, -1.0, 0.0, 1.0)
outer = tm.coastal.size_function((-0.5, 0.5, -0.5, 0.5), land, min_el=4000, max_el=8000, dis=0.5)
inner = tm.coastal.size_function((-0.1, 0.1, -0.1, 0.1), land, min_el=1000, max_el=1000)
CompositeSize([outer, inner], [0.2, 0.2])(np.column_stack(tm.coastal.to_mercator([0.0, 0.2], [0.0, 0.0])))
""",
    "seismic": """
model = tm.seismic.read_velocity(data / "seismic" / "vel_z6.25m_x12.5m_exact.segy")
size = tm.seismic.size_function(model, frequency=1.0, hmin=300.0, grade=0.15, pad=1000.0, gradient_refinement=4)
mesh = tm.generate_mesh(size.domain, size, seed=0)
mesh.write(str(scratch / "bp2004.msh"))
tm.read_mesh(scratch / "bp2004.msh")  # as --adapt reads the old mesh
tm.io.write_fwi_mesh(scratch / "bp2004_fwi.msh", mesh, size)  # the facet census of the boundary tags
tm.seismic.stable_timestep(mesh, size.model)  # the largest velocity along each edge
""",
    "generation-3d": """
from terramesh.generation.distmesh3d import generate_mesh_3d
ball = tm.geometry.Ball((0, 0, 0), 1)
generate_mesh_3d(ball, 0.15, seed=0)
generate_mesh_3d(ball, lambda p: 0.1 + 0.1 * np.abs(p[:, 0]), h0=0.1, seed=0)
generate_mesh_3d(tm.geometry.Box((0, 0, 0), (2, 1, 0.5)), 0.1, seed=0)
"""
    + _EXACT_CUBIC_LATTICE,
    "3d": """
from terramesh.generation.distmesh3d import generate_mesh_3d
axes = [np.linspace(0, 1000, 21)] * 3
speed = 1500 + np.meshgrid(*axes, indexing="ij")[2]
model = tm.seismic.VelocityModel(speed, axes)
size = tm.seismic.size_function(model, frequency=5.0, hmin=40.0, grade=0.2)
mesh = generate_mesh_3d(size.domain, size, seed=0)
tm.io.write_fwi_mesh(scratch / "cube_fwi.msh", mesh, model)
tm.seismic.stable_timestep(mesh, model)
generate_mesh_3d(tm.geometry.Ball((0, 0, 0), 1), 0.15, seed=0)
# a rough model with a pad: short edges whose ends are lengthened apart
rough = 1500 + 1000 * np.random.default_rng(0).random((21, 11, 11))
axes = [np.linspace(0, 2000, 21), np.linspace(0, 1000, 11), np.linspace(-1000, 0, 11)]
rough_model = tm.seismic.VelocityModel(rough, axes)
rough_size = tm.seismic.size_function(rough_model, frequency=3.0, hmin=80.0, grade=0.2, pad=200.0)
generate_mesh_3d(rough_size.domain, rough_size, seed=0)
"""
    + _EXACT_CUBIC_LATTICE,
}

_JOB = """
import json, pathlib, sys, time, warnings
import numpy as np
from numba.core import event
warnings.simplefilter("ignore")
import terramesh as tm
data, scratch = pathlib.Path({data!r}), pathlib.Path({scratch!r})
records, stack = [], []

class Listener(event.Listener):
    def on_start(self, ev):
        stack.append(time.perf_counter())

    def on_end(self, ev):
        seconds = time.perf_counter() - stack.pop()
        # compiled from Python: what a worker asks for; or inside another kernel: cached with it (no time)
        records.append((stage, ev.data["dispatcher"], ev.data["args"], None if stack else seconds))

event.register("numba:compile", Listener())
# the jobs' first call would compile the table's kernels in worker processes, unseen here
import terramesh._kernels.precompile
terramesh._kernels.precompile._ahead["tried"] = True
stage = {stage!r}
exec({job!r})
from terramesh._kernels.precompile import spelled_types
rows = []
for stage, kernel, args, seconds in records:
    if not kernel.py_func.__module__.startswith("terramesh."):
        continue  # numba's own implementations (np.empty, sorting), compiled within a kernel
    if getattr(sys.modules[kernel.py_func.__module__], kernel.py_func.__name__, None) is not kernel:
        assert seconds is None, (kernel, args)
        continue  # a lambda that a kernel's overload returns, compiled within it: no name to look up
    try:
        rows.append((stage, kernel.py_func.__module__, kernel.py_func.__name__, spelled_types(args), seconds))
    except ValueError:  # a literal constant's type: only another kernel can pass one
        assert seconds is None, (kernel, args)
print(json.dumps(rows))
"""


def record(data, stage):
    """Rows ``(stage, module, function, argument types, seconds)`` from a run of a stage on an empty cache."""
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as scratch:
        job = _JOB.format(data=str(data), scratch=scratch, stage=stage, job=STAGES[stage])
        output = subprocess.run(
            [sys.executable, "-c", job],
            env=dict(os.environ, NUMBA_CACHE_DIR=cache),
            capture_output=True,
            text=True,
            check=True,
        )
    return json.loads(output.stdout.strip().splitlines()[-1])


def write_table(rows):
    """Write the table (JSON, a row per line), each stage's kernels slowest first, then those compiled within."""
    lines = []
    for stage in STAGES:
        mine = sorted((row for row in rows if row[0] == stage), key=lambda row: -(row[4] or 0.0))
        kernels = [
            json.dumps([module.removeprefix("terramesh."), function, types, seconds and round(seconds, 1)])
            for _, module, function, types, seconds in mine
        ]
        lines.append(f"    {json.dumps(stage)}: [\n      " + ",\n      ".join(kernels) + "\n    ]")
    note = (
        f"written by tools/record_kernel_signatures.py on {datetime.date.today()}: each stage's kernels, "
        "their argument types and seconds to compile on the development machine (2 cores); null: compiled "
        "within another kernel of the stage"
    )
    TABLE.write_text("{\n  " + f'"note": {json.dumps(note)},\n  "stages": {{\n' + ",\n".join(lines) + "\n  }\n}\n")


def main(data=None):
    """Record every stage from the data folder ``data``, write the table, print each stage's totals."""
    data = pathlib.Path(data) if data else ROOT.parent / "shared" / "data"
    rows = [row for stage in STAGES for row in record(data, stage)]
    write_table(rows)
    for stage in STAGES:
        mine = [row for row in rows if row[0] == stage]
        compiled = [row[4] for row in mine if row[4] is not None]
        print(f"{stage:>10}: {len(compiled):3d} kernels, {sum(compiled):6.1f} s to compile, {len(mine)} in all")


if __name__ == "__main__":
    main(*sys.argv[1:2])
