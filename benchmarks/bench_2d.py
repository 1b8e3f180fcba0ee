"""Unit-disk scaling of the 2D generator: prints a table.

Usage: python benchmarks/bench_2d.py [h ...]   (default 0.02 0.01 0.005 0.0025)

Each size runs in a fresh process so that peak memory is per case; the
first (JIT-warming) call on a tiny disk is not timed.
"""

import json
import subprocess
import sys

CASE = """
import json, resource, time, warnings
import numpy as np
import terramesh as tm
from terramesh.quality import triangle_quality
tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2)
h = {h}
started = time.perf_counter()
mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), h, seed=0)
seconds = time.perf_counter() - started
q = triangle_quality(mesh.points, mesh.cells)
print(json.dumps(dict(h=h, vertices=mesh.n_points, cells=mesh.n_cells, iterations=mesh.info["iterations"],
    stop=mesh.info["stop_reason"], triangulations=mesh.info["retriangulations"], seconds=seconds,
    mean_q=float(q.mean()), min_q=float(q.min()),
    peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)))
"""


def main(sizes):
    header = (
        f"{'h':>8} {'vertices':>10} {'cells':>10} {'iter':>5} {'stop':>9} {'tri':>4} {'seconds':>8} "
        f"{'us/vertex':>9} {'mean q':>7} {'min q':>6} {'peak MB':>8}"
    )
    print(header)
    print("-" * len(header))
    for h in sizes:
        output = subprocess.run([sys.executable, "-c", CASE.format(h=h)], capture_output=True, text=True, check=True)
        r = json.loads(output.stdout.strip().splitlines()[-1])
        print(
            f"{r['h']:>8g} {r['vertices']:>10,} {r['cells']:>10,} {r['iterations']:>5} {r['stop']:>9} "
            f"{r['triangulations']:>4} {r['seconds']:>8.2f} {1e6 * r['seconds'] / r['vertices']:>9.1f} "
            f"{r['mean_q']:>7.4f} {r['min_q']:>6.3f} {r['peak_mb']:>8.0f}",
            flush=True,
        )


if __name__ == "__main__":
    main([float(a) for a in sys.argv[1:]] or [0.02, 0.01, 0.005, 0.0025])
