"""Generation on coastlines: jagged random-walk coasts and the GSHHS coast of the guide's §5.3.

Usage: python benchmarks/bench_coastal.py [--quick]   (about a minute; reads ../shared/data;
--quick: the two smaller random walks and GSHHS at 0.1 degrees only, about 10 s)

A coastline is mostly boundary: points pushed onto it land on the polygon's
vertices, often two on one spot, and the Delaunay repair cannot follow two
points onto one. The ``rebuilds`` column counts the retriangulations that
fell back to triangulating from scratch.

Random-walk coasts: a closed polygon of n vertices whose radius follows a
random walk (seeded), meshed at a uniform size. GSHHS: the water of the
US East Coast and Gulf box (-100..-50 E, 10..60 N, low resolution, shoreline
resampled at 5 km) with sizes growing from h0 at the coast by 0.2 per unit
of distance, at most 0.5 degrees, on a 501 x 501 grid.
"""

import argparse
import pathlib

from _runner import print_header, print_row, run_case

DATA = pathlib.Path(__file__).resolve().parents[2] / "shared" / "data"

RANDOM_WALK = """
def random_walk_coast(n, seed, roughness=0.6):
    rng = np.random.default_rng(seed)
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    radius = 1 + roughness * np.cumsum(rng.normal(size=n)) / np.sqrt(n)
    radius -= np.linspace(0, 1, n) * (radius[-1] - radius[0])
    return tm.geometry.Polygon(np.column_stack([radius * np.cos(angle), radius * np.sin(angle)]))
domain = random_walk_coast({n}, {seed})
edge_length, h0 = {h!r}, None
"""

GSHHS = """
shore = tm.coastal.Shoreline.read({path!r}, (-100, -50, 10, 60), 5e3)
domain = tm.geometry.Polygon.from_shapely(shore.water)
x, y = np.linspace(-100, -50, 501), np.linspace(10, 60, 501)
grid = np.stack(np.meshgrid(x, y, indexing="ij"), axis=-1).reshape(-1, 2)
h0 = {h0!r}
distance = np.abs(domain.distance(grid)).reshape(501, 501)
edge_length = tm.sizing.SizeGrid((x, y), np.minimum(h0 + 0.2 * distance, 0.5))
"""


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the smaller cases only")
    quick = parser.parse_args(argv).quick
    print_header()
    walks = ((2_000, 1, 0.03), (1_000, 0, 0.02), (20_000, 2, 0.005))
    for n, seed, h in walks[:2] if quick else walks:
        print_row(f"random walk {n} h={h:g}", run_case(RANDOM_WALK.format(n=n, seed=seed, h=h)))
    for h0 in (0.1,) if quick else (0.1, 0.05):
        path = str(DATA / "coast" / "GSHHS_l_L1.shp")
        print_row(f"GSHHS US h0={h0:g} deg", run_case(GSHHS.format(path=path, h0=h0)))


if __name__ == "__main__":
    main()
