"""Unit-disk series of the 2D generator: prints a table.

Usage: python benchmarks/bench_2d.py [h ...]   (default 0.02 0.01 0.005 0.0025)

Each size runs in a fresh process, so peak memory (RSS) is per case; a
tiny JIT-warming call comes first and is not timed.
"""

import sys

from _runner import print_header, print_row, run_case


def main(sizes):
    print_header()
    for h in sizes:
        print_row(f"disk h={h:g}", run_case(f"edge_length = {h!r}\nh0 = None"))


if __name__ == "__main__":
    main([float(a) for a in sys.argv[1:]] or [0.02, 0.01, 0.005, 0.0025])
