"""Delaunay triangulation: terramesh's exact incremental kernel against SciPy's Qhull; prints a table.

Usage: python benchmarks/bench_delaunay.py [n ...]   (default 1e4 1e5 1e6)
       python benchmarks/bench_delaunay.py 3d [n ...]   (default 2.7e4 1e5)

Random points in the unit square and a hexagonal lattice of about the same
count (the DistMesh seed, with its many collinear rows). Times are the best
of a few runs (one at 1e6 and above) in seconds, after a JIT-warming call;
ours include the validation, Hilbert sort and output arrays of
``delaunay_with_neighbors``, Qhull's only ``Delaunay(points)``.

In 3D (``delaunay_3d``): random points in the unit cube, a cubic grid jittered
by 1 % of its spacing (as the generator's seeds are), and exact cubic grids,
in integers and in tenths (which no double holds), where the quick
floating-point kernel hands over to the exact one; "flat" counts cells below
10**-6 of the mean volume.
"""

import sys
import time

import numpy as np
from scipy.spatial import Delaunay

from terramesh.generation.seeding import hexagonal_lattice
from terramesh.generation.triangulate import delaunay_3d, delaunay_with_neighbors
from terramesh.quality.tetra import tetra_volumes


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


def cases_3d(n, rng):
    yield "random", rng.random((n, 3))
    side = round(n ** (1 / 3))
    grid = np.stack(np.meshgrid(*[np.arange(float(side))] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    yield "jittered grid", grid + rng.uniform(-0.01, 0.01, grid.shape)
    yield "integer grid", grid
    yield "grid in tenths", 0.1 * grid


def main_3d(sizes):
    rng = np.random.default_rng(0)
    delaunay_3d(rng.random((100, 3)))  # JIT warm-up (and cache load)...
    delaunay_3d(np.stack(np.meshgrid(*[np.arange(3.0)] * 3), axis=-1).reshape(-1, 3))  # ...of the exact kernel too
    header = f"{'points':<15} {'n':>9} {'terramesh s':>12} {'qhull s':>9} {'speed-up':>9} {'cells':>9} {'flat':>5}"
    print(f"{header} {'qhull cells':>11} {'qhull flat':>10}")
    for n in sizes:
        for name, points in cases_3d(n, rng):
            ours = best_time(lambda p=points: delaunay_3d(p), 3)
            qhull = best_time(lambda p=points: Delaunay(p), 3)
            cells = delaunay_3d(points)[0]
            theirs = Delaunay(points).simplices
            volumes = (np.abs(tetra_volumes(points, simplices)) for simplices in (cells, theirs))
            flat, flat_theirs = (int(np.sum(v < 1e-6 * v.mean())) for v in volumes)
            times = f"{ours:>12.3f} {qhull:>9.3f} {qhull / ours:>8.1f}x"
            counts = f"{len(cells):>9,} {flat:>5} {len(theirs):>11,} {flat_theirs:>10}"
            print(f"{name:<15} {len(points):>9,} {times} {counts}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["3d"]:
        main_3d([int(float(a)) for a in sys.argv[2:]] or [27_000, 100_000])
    else:
        main([int(float(a)) for a in sys.argv[1:]] or [10_000, 100_000, 1_000_000])
