"""Cost per vertex from 10^4 to 10^7 vertices, uniform and graded (size varying 50x).

Usage: python benchmarks/bench_scaling.py [max_vertices [min_vertices]] [--rounds N]   (default 1e6 1e4, 1)

With max_vertices >= 1e7, the issue's largest case follows: the unit disk at
h = 0.0005 (14.5 million vertices; 51 s and 6.2 GB on 2 cores at the last measurement).

Uniform: unit disk, h chosen for the vertex count. Graded: unit disk with
h growing linearly 50x from x = -1 to x = 1, scaled to the same count.
Each case runs in a fresh process; peak RSS is per case.

With ``--rounds N`` the uniform and the graded case of each count run N
times in turn (uniform, graded, uniform, ...), each in a fresh process, and
a line per count gives the median cost per vertex of both and their ratio:
the machine's drift over minutes (15-30 % between identical runs) then
falls on both alike.
"""

import argparse
import statistics

import numpy as np
from _runner import print_header, print_row, run_case

DISK_AREA = np.pi
HEX_AREA_PER_VERTEX = np.sqrt(3) / 2  # times h^2


def uniform_h(vertices):
    return float(np.sqrt(DISK_AREA / (HEX_AREA_PER_VERTEX * vertices)))


def graded_h_min(vertices):
    # vertices = integral over the disk of 1 / (0.866 h(x)^2), h = h_min (1 + 24.5 (x + 1))
    x = np.linspace(-1, 1, 20001)
    chord = 2 * np.sqrt(1 - x**2)
    density = np.trapezoid(chord / (1 + 24.5 * (x + 1)) ** 2, x)
    return float(np.sqrt(density / (HEX_AREA_PER_VERTEX * vertices)))


def main(limit=1e6, start=1e4, rounds=1):
    print_header()
    count = start
    while count <= limit:
        h_min = graded_h_min(count)
        cases = {
            "uniform": f"edge_length = {uniform_h(count)!r}\nh0 = None",
            "graded 50x": f"h0 = {h_min!r}\nedge_length = lambda p: h0 * (1 + 24.5 * (p[:, 0] + 1))",
        }
        cost = {name: [] for name in cases}
        for _ in range(rounds):
            for name, setup in cases.items():
                row = run_case(setup)
                cost[name].append(row["us_per_vertex"])
                print_row(f"{name} {count:.0e}", row)
        if rounds > 1:
            uniform, graded = (statistics.median(cost[name]) for name in cases)
            ratio = graded / uniform
            print(f"{count:.0e}: median us per vertex uniform {uniform:.2f}, graded {graded:.2f}, ratio {ratio:.2f}")
        count *= 10
    if limit >= 1e7:
        print_row("uniform h=0.0005", run_case("edge_length = 0.0005\nh0 = None"))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("limit", nargs="?", type=float, default=1e6, help="largest vertex count (default 1e6)")
    parser.add_argument("start", nargs="?", type=float, default=1e4, help="smallest vertex count (default 1e4)")
    parser.add_argument("--rounds", type=int, default=1, help="runs of each case, in turn (default 1)")
    args = parser.parse_args()
    main(args.limit, args.start, args.rounds)
