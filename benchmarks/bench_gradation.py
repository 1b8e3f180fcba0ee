"""Gradient limiting (terramesh.sizing.limit_gradient) on n x n and m x m x m grids: prints a table.

Usage: python benchmarks/bench_gradation.py [n ...] [--3d m ...]
(no arguments: 1000 2000 4000 --3d 200 300; with arguments, only the grids named)

The unit square or cube with n (m) nodes a side, grade 0.2, two size fields:

* random: sizes drawn uniformly from [0.001, 0.1], so nearly every node is
  limited, by cones around the local minima;
* smooth: a coastal-like field, 0.001 + 2 x the distance to a wavy line
  (a wavy surface in 3D), capped by a rolling 0.1 +- 0.05, steeper than the
  grade almost everywhere.

Times are wall-clock seconds of one call, after a small call that loads
the compiled kernel; they include copying the input into a fresh output.
"""

import argparse
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


def fields_3d(m, rng):
    x = np.linspace(0, 1, m)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    coast = 0.001 + 2.0 * np.abs(Z - 0.5 - 0.1 * np.sin(4 * np.pi * X) * np.cos(2 * np.pi * Y))
    rolling = 0.1 + 0.05 * np.sin(6 * np.pi * X) * np.cos(4 * np.pi * Y) * np.cos(2 * np.pi * Z)
    del X, Y, Z
    return {"random": rng.uniform(0.001, 0.1, size=(m, m, m)), "smooth": np.minimum(coast, rolling)}


def run(label, field_set):
    for name, h0 in field_set.items():
        for scheme in ("persson", "godunov"):
            started = time.perf_counter()
            h = limit_gradient(h0, 1 / (h0.shape[0] - 1), GRADE, scheme=scheme)
            seconds = time.perf_counter() - started
            print(
                f"{label:>15} {name:>7} {scheme:>8} {seconds:>8.3f} {1e9 * seconds / h.size:>8.1f} "
                f"{np.mean(h < h0):>8.1%}",
                flush=True,
            )
            del h


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sizes", nargs="*", type=int, help="n for n x n grids")
    parser.add_argument("--3d", dest="cubes", nargs="+", type=int, default=[], help="m for m x m x m grids")
    args = parser.parse_args(argv)
    sizes, cubes = args.sizes, args.cubes
    if not sizes and not cubes:
        sizes, cubes = [1000, 2000, 4000], [200, 300]
    rng = np.random.default_rng(0)
    for scheme in ("persson", "godunov"):
        limit_gradient(rng.uniform(0.5, 1, size=(20, 20)), 0.1, GRADE, scheme=scheme)
        limit_gradient(rng.uniform(0.5, 1, size=(8, 8, 8)), 0.1, GRADE, scheme=scheme)
    header = f"{'grid':>15} {'field':>7} {'scheme':>8} {'seconds':>8} {'ns/node':>8} {'limited':>8}"
    print(header)
    print("-" * len(header))
    for n in sizes:
        run(f"{n} x {n}", fields(n, rng))
    for m in cubes:
        run(f"{m} x {m} x {m}", fields_3d(m, rng))


if __name__ == "__main__":
    main()
