"""Writing and reading mesh files: ADCIRC fort.14, SCHISM hgrid.gr3, ParaView .vtu and Gmsh 2.2 .msh, and fort.13.

Usage: python benchmarks/bench_io.py [h]   (default 0.002: the unit disk, about 917k vertices; a minute)

The mesh carries a depth per vertex (fort.14 and .gr3 need one). Seconds are
the fastest of three writes and three reads, each read checked against the
mesh written. The fort.13 holds a Manning's n that varies with the depth at
every node (one real per node) and a primitive weighting (tau0) that is 0.03
at most nodes and 0.005 at a third of them.
"""

import sys
import tempfile
from pathlib import Path

import numpy as np
from _runner import fastest

import terramesh as tm

FORMATS = ("14", "gr3", "vtu", "msh")


def main(h=0.002):
    mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), h, seed=0)
    mesh.point_data["depth"] = 10.0 + mesh.points[:, 0]
    print(f"unit disk at h = {h:g}: {mesh.n_points:,} vertices, {mesh.n_cells:,} cells")
    print(f"{'format':>6} {'MB':>7} {'write s':>8} {'read s':>7}")
    with tempfile.TemporaryDirectory() as folder:
        for extension in FORMATS:
            path = Path(folder) / f"mesh.{extension}"
            _, write = fastest(mesh.write, path)
            read_back, read = fastest(tm.read_mesh, path)
            if not np.array_equal(read_back.cells, mesh.cells) or not np.allclose(read_back.points, mesh.points):
                raise RuntimeError(f"{path.name} did not read back as written")
            print(f"{extension:>6} {path.stat().st_size / 1e6:>7.1f} {write:>8.2f} {read:>7.2f}", flush=True)
        depth = mesh.point_data["depth"]
        attributes = tm.io.fort13.NodalAttributes(
            {
                "mannings_n_at_sea_floor": tm.io.fort13.NodalAttribute.from_values(0.02 + 0.001 * np.sqrt(depth)),
                "primitive_weighting_in_continuity_equation": tm.io.fort13.NodalAttribute.from_values(
                    np.where(np.arange(mesh.n_points) % 3 == 0, 0.005, 0.03)
                ),
            }
        )
        path = Path(folder) / "mesh.13"
        _, write = fastest(tm.io.fort13.write_fort13, path, attributes, mesh.n_points)
        read_back, read = fastest(tm.io.fort13.read_fort13, path)
        for name, attribute in attributes.items():
            if not np.array_equal(read_back[name].values, attribute.values):
                raise RuntimeError(f"{path.name}: {name} did not read back as written")
        print(f"{'13':>6} {path.stat().st_size / 1e6:>7.1f} {write:>8.2f} {read:>7.2f}", flush=True)


if __name__ == "__main__":
    main(*(float(a) for a in sys.argv[1:2]))
