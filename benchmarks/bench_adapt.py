"""Adapting a mesh to a velocity update (tm.adapt_mesh) against meshing the updated model afresh.

Usage: python benchmarks/bench_adapt.py [decimation [hmin]]   (default 4 40)

BP2004 (decimated), 2 Hz, grade 0.15; the update multiplies the velocity by
0.5 (sizes halve) or 2 (sizes double) in an ellipse 12 km x 3 km centred at
x = 30 km, z = -3 km, or leaves it unchanged. For each: a fresh mesh of the
updated model and the old mesh adapted to it, without and with the old
sizes ("+old": vertices where the size did not change stay). "in update" is the median
edge length over the size for edges in the ellipse; "kept" the share of the
old vertices away from the update (outside 1.5 times the ellipse) that still
have a vertex within 5 % of the local size. Times are the fastest of three,
after a warm-up run (numba compilation) of each.
"""

import sys
from pathlib import Path

import numpy as np
from _runner import fastest
from scipy.spatial import cKDTree

import terramesh as tm
from terramesh.quality import triangle_quality

SEGY = Path(__file__).resolve().parents[2] / "shared" / "data" / "seismic" / "vel_z6.25m_x12.5m_exact.segy"
CENTRE, AXES = np.array([30000.0, -3000.0]), np.array([6000.0, 1500.0])


def in_update(points, scale=1.0):
    return np.sum(((points - CENTRE) / (AXES * scale)) ** 2, axis=1) <= 1


def row(case, method, mesh, seconds, size, old):
    quality = triangle_quality(mesh.points, mesh.cells)
    edges = tm.mesh.topology.unique_edges(mesh.cells)
    middle = 0.5 * (mesh.points[edges[:, 0]] + mesh.points[edges[:, 1]])
    lengths = np.linalg.norm(mesh.points[edges[:, 0]] - mesh.points[edges[:, 1]], axis=1)
    updated = in_update(middle)
    away = old.points[~in_update(old.points, 1.5)]
    kept = np.mean(cKDTree(mesh.points).query(away)[0] < 0.05 * size(away))
    print(
        f"{case:>10} {method:>6} {mesh.n_points:>9,} {seconds:>8.2f} {mesh.info['iterations']:>10} "
        f"{quality.min():>6.3f} {quality.mean():>7.4f} {np.median(lengths[updated] / size(middle[updated])):>9.3f} "
        f"{kept:>5.2f}",
        flush=True,
    )


def main(decimation=4, hmin=40.0):
    section = tm.seismic.read_velocity(SEGY)
    x, z = section.axes
    model = tm.seismic.VelocityModel(section.values[::decimation, ::decimation], (x[::decimation], z[::decimation]))
    options = dict(frequency=2.0, hmin=hmin, grade=0.15)
    size = tm.seismic.size_function(model, **options)
    grid = np.stack(np.meshgrid(*model.axes, indexing="ij"), axis=-1).reshape(-1, 2)
    inside = in_update(grid).reshape(model.values.shape)
    old = tm.generate_mesh(size.domain, size, seed=0)
    tm.adapt_mesh(old, size.domain, size)  # warm-up
    print(f"old mesh: {old.n_points:,} vertices")
    print(
        f"{'update':>10} {'method':>6} {'vertices':>9} {'seconds':>8} {'iterations':>10} {'min q':>6} "
        f"{'mean q':>7} {'in update':>9} {'kept':>5}"
    )
    for case, factor in (("v x 0.5", 0.5), ("v x 2", 2.0), ("none", 1.0)):
        values = model.values.copy()
        values[inside] *= factor
        new_size = tm.seismic.size_function(tm.seismic.VelocityModel(values, model.axes), **options)
        fresh, seconds = fastest(tm.generate_mesh, new_size.domain, new_size, seed=0)
        row(case, "fresh", fresh, seconds, new_size, old)
        adapted, seconds = fastest(tm.adapt_mesh, old, new_size.domain, new_size)
        row(case, "adapt", adapted, seconds, new_size, old)
        adapted, seconds = fastest(tm.adapt_mesh, old, new_size.domain, new_size, old_edge_length=size)
        row(case, "+old", adapted, seconds, new_size, old)


if __name__ == "__main__":
    main(*(int(sys.argv[1]),) if len(sys.argv) > 1 else (), *(float(a) for a in sys.argv[2:3]))
