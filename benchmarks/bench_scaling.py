"""Cost per vertex from 10^4 to 10^7 vertices, uniform and graded (size varying 50x).

Usage: python benchmarks/bench_scaling.py [max_vertices [min_vertices]]   (default 1e6 1e4)

With max_vertices >= 1e7, the issue's largest case follows: the unit disk at
h = 0.0005 (14.5 million vertices; 58 s and 6.0 GB on 2 cores at the last measurement).

Uniform: unit disk, h chosen for the vertex count. Graded: unit disk with
h growing linearly 50x from x = -1 to x = 1, scaled to the same count.
Each case runs in a fresh process; peak RSS is per case.
"""

import sys

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


def main(limit=1e6, start=1e4):
    print_header()
    count = start
    while count <= limit:
        h = uniform_h(count)
        print_row(f"uniform {count:.0e}", run_case(f"edge_length = {h!r}\nh0 = None"))
        h_min = graded_h_min(count)
        setup = f"h0 = {h_min!r}\nedge_length = lambda p: h0 * (1 + 24.5 * (p[:, 0] + 1))"
        print_row(f"graded 50x {count:.0e}", run_case(setup))
        count *= 10
    if limit >= 1e7:
        print_row("uniform h=0.0005", run_case("edge_length = 0.0005\nh0 = None"))


if __name__ == "__main__":
    main(*(float(a) for a in sys.argv[1:3]))
