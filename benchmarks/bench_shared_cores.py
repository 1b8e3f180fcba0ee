"""Generation while other processes share the cores: terramesh's short OpenMP spin against libgomp's own.

Usage: python benchmarks/bench_shared_cores.py [busy ...]   (default 0 1 2; about two minutes)

numba's parallel loops run on GNU OpenMP on Linux, whose idle threads spin for
milliseconds after each loop unless told otherwise. terramesh sets
``GOMP_SPINCOUNT=1000`` (about ten microseconds) at import, where the user has
set neither it nor ``OMP_WAIT_POLICY``. Each case runs with that and with
libgomp's own spin (``GOMP_SPINCOUNT=300000``), while ``busy`` other processes
(a Python loop each) keep cores busy, as other jobs or MPI ranks on the same
node do. Seconds are the fastest of up to five runs in a fresh process
(``_runner.run_case``), after a warm-up.
"""

import pathlib
import subprocess
import sys

from _runner import run_case
from bench_coastal import GSHHS
from bench_scaling import uniform_h

DATA = pathlib.Path(__file__).resolve().parents[2] / "shared" / "data"
LIBGOMP_SPIN = {"GOMP_SPINCOUNT": "300000"}  # libgomp's own count when neither variable is set
CASES = {
    "GSHHS US h0=0.1 deg": GSHHS.format(path=str(DATA / "coast" / "GSHHS_l_L1.shp"), h0=0.1),
    "unit disk 1e5": f"edge_length, h0 = {uniform_h(1e5)!r}, None",
}


def main(busy_counts):
    print(f"{'case':>20} {'busy':>4} {'vertices':>9} {'terramesh s':>11} {'libgomp s':>9} {'ratio':>6}")
    for busy in busy_counts:
        loops = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(busy)]
        try:
            for name, setup in CASES.items():
                ours = run_case(setup)
                theirs = run_case(setup, LIBGOMP_SPIN)
                ratio = theirs["seconds"] / ours["seconds"]
                columns = f"{ours['vertices']:>9,} {ours['seconds']:>11.2f} {theirs['seconds']:>9.2f} {ratio:>6.2f}"
                print(f"{name:>20} {busy:>4} {columns}", flush=True)
        finally:
            for loop in loops:
                loop.kill()


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [0, 1, 2])
