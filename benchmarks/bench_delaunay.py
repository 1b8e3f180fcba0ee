"""Delaunay triangulation: terramesh's exact incremental kernel against SciPy's Qhull; prints a table.

Usage: python benchmarks/bench_delaunay.py [n ...]   (default 1e4 1e5 1e6)

Random points in the unit square and a hexagonal lattice of about the same
count (the DistMesh seed, with its many collinear rows). Times are the best
of a few runs (one at 1e6 and above) in seconds, after a JIT-warming call;
ours include the validation, Hilbert sort and output arrays of
``delaunay_with_neighbors``, Qhull's only ``Delaunay(points)``.
"""

import sys
import time

import numpy as np
from scipy.spatial import Delaunay

from terramesh.generation.seeding import hexagonal_lattice
from terramesh.generation.triangulate import delaunay_with_neighbors


def best_time(function, repeats):
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def cases(n, rng):
    yield "random", rng.random((n, 2))
    spacing = np.sqrt(2.0 / (np.sqrt(3.0) * n))
    points, _ = hexagonal_lattice(np.array([[0.0, 0.0], [1.0, 1.0]]), spacing)
    yield "hex lattice", points


def main(sizes):
    rng = np.random.default_rng(0)
    delaunay_with_neighbors(rng.random((100, 2)))  # JIT warm-up (and cache load)
    print(f"{'points':<12} {'n':>9} {'terramesh s':>12} {'qhull s':>9} {'speed-up':>9} {'cells':>9}")
    for n in sizes:
        for name, points in cases(n, rng):
            repeats = 1 if len(points) >= 500_000 else 3
            ours = best_time(lambda p=points: delaunay_with_neighbors(p), repeats)
            qhull = best_time(lambda p=points: Delaunay(p), repeats)
            cells = len(delaunay_with_neighbors(points)[0])
            print(f"{name:<12} {len(points):>9,} {ours:>12.3f} {qhull:>9.3f} {qhull / ours:>8.1f}x {cells:>9,}")


if __name__ == "__main__":
    main([int(float(a)) for a in sys.argv[1:]] or [10_000, 100_000, 1_000_000])
