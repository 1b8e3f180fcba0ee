"""Gradient limiting (terramesh.sizing.limit_gradient) on n x n grids: prints a table.

Usage: python benchmarks/bench_gradation.py [n ...]   (default 1000 2000 4000)

The unit square with n nodes a side, grade 0.2, two size fields:

* random: sizes drawn uniformly from [0.001, 0.1], so nearly every node is
  limited, by cones around the local minima;
* smooth: a coastal-like field, 0.001 + 2 x the distance to a wavy line,
  capped by a rolling 0.1 +- 0.05, steeper than the grade almost everywhere.

Times are wall-clock seconds of one call, after a small call that loads
the compiled kernel; they include copying the input into a fresh output.
"""

import sys
import time

import numpy as np

from terramesh.sizing import limit_gradient

GRADE = 0.2


def fields(n, rng):
    x = np.linspace(0, 1, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    coast = 0.001 + 2.0 * np.abs(Y - 0.5 - 0.1 * np.sin(4 * np.pi * X))
    rolling = 0.1 + 0.05 * np.sin(6 * np.pi * X) * np.cos(4 * np.pi * Y)
    return {"random": rng.uniform(0.001, 0.1, size=(n, n)), "smooth": np.minimum(coast, rolling)}


def main(sizes):
    rng = np.random.default_rng(0)
    for scheme in ("persson", "godunov"):
        limit_gradient(rng.uniform(0.5, 1, size=(20, 20)), 0.1, GRADE, scheme=scheme)
    header = f"{'grid':>11} {'field':>7} {'scheme':>8} {'seconds':>8} {'ns/node':>8} {'limited':>8}"
    print(header)
    print("-" * len(header))
    for n in sizes:
        for name, h0 in fields(n, rng).items():
            for scheme in ("persson", "godunov"):
                started = time.perf_counter()
                h = limit_gradient(h0, 1 / (n - 1), GRADE, scheme=scheme)
                seconds = time.perf_counter() - started
                print(
                    f"{f'{n} x {n}':>11} {name:>7} {scheme:>8} {seconds:>8.3f} {1e9 * seconds / h.size:>8.1f} "
                    f"{np.mean(h < h0):>8.1%}",
                    flush=True,
                )
                del h


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [1000, 2000, 4000])
