"""Adapting a mesh to a velocity update (tm.adapt_mesh) against meshing the updated model afresh.

Usage: python benchmarks/bench_adapt.py [decimation [hmin]]   (default 4 40)
       python benchmarks/bench_adapt.py 3d [frequency]          (default 0.75 Hz)

BP2004 (decimated), 2 Hz, grade 0.15; the update multiplies the velocity by
0.5 (sizes halve) or 2 (sizes double) in an ellipse 12 km x 3 km centred at
x = 30 km, z = -3 km, or leaves it unchanged. For each: a fresh mesh of the
updated model and the old mesh adapted to it, without and with the old
sizes ("+old": vertices where the size did not change stay). "in update" is the median
edge length over the size for edges in the ellipse; "kept" the share of the
old vertices away from the update (outside 1.5 times the ellipse) that still
have a vertex within 5 % of the local size. Times are the fastest of three,
after a warm-up run (numba compilation) of each.

``3d``: a BP2004 window (x 26-34 km, the top 4 km, on a 200 m grid)
extruded 4 km along y, hmin 100 m, grade 0.15; the update lowers the
velocity by 40 % in an ellipsoid 3 x 2.4 x 1.6 km at x = 31 km, y = 2 km,
z = -2.5 km. "in update" is the median edge over the size for edges in the
ellipsoid's inner half; "kept" the share of the old vertices more than four
sizes from any vertex whose size changed and from the box's edges that are
in the adapted mesh to the bit; quality is the mean and smallest radius
ratio, and the smallest dihedral angle.
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


def row(case, method, mesh, seconds, size, old, old_size):
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
    columns = f"{'min q':>6} {'mean q':>7}"
    compare(model, options, size, inside, (("v x 0.5", 0.5), ("v x 2", 2.0), ("none", 1.0)), columns, row)


def compare(model, options, size, inside, cases, quality_columns, row):
    """The old mesh of ``size``, then for each case a fresh mesh of the update and the old one adapted to it."""
    old = tm.generate_mesh(size.domain, size, seed=0)
    tm.adapt_mesh(old, size.domain, size)  # warm-up
    print(f"old mesh: {old.n_points:,} vertices")
    print(
        f"{'update':>10} {'method':>6} {'vertices':>9} {'seconds':>8} {'iterations':>10} {quality_columns} "
        f"{'in update':>9} {'kept':>5}"
    )
    for case, factor in cases:
        values = model.values.copy()
        values[inside] *= factor
        new_size = tm.seismic.size_function(tm.seismic.VelocityModel(values, model.axes), **options)
        fresh, seconds = fastest(tm.generate_mesh, new_size.domain, new_size, seed=0)
        row(case, "fresh", fresh, seconds, new_size, old, size)
        adapted, seconds = fastest(tm.adapt_mesh, old, new_size.domain, new_size)
        row(case, "adapt", adapted, seconds, new_size, old, size)
        adapted, seconds = fastest(tm.adapt_mesh, old, new_size.domain, new_size, old_edge_length=size)
        row(case, "+old", adapted, seconds, new_size, old, size)


CENTRE_3D, AXES_3D = np.array([31000.0, 2000.0, -2500.0]), np.array([1500.0, 1200.0, 800.0])


def row_3d(case, method, mesh, seconds, size, old, old_size):
    ratio = tm.quality.radius_ratio(mesh.points, mesh.cells)
    pairs = [[a, b] for a in range(4) for b in range(a + 1, 4)]
    edges = np.unique(np.sort(np.concatenate([mesh.cells[:, pair] for pair in pairs]), axis=1), axis=0)
    ends = mesh.points[edges]
    middle = ends.mean(axis=1)
    lengths = np.linalg.norm(ends[:, 0] - ends[:, 1], axis=1) / size(middle)
    inner = np.sum(((middle - CENTRE_3D) / AXES_3D) ** 2, axis=1) <= 0.5
    points, (low, high) = old.points, size.domain.bbox
    changed = np.abs(size(points) / old_size(points) - 1.0) > 0.02
    from_changes = cKDTree(points[changed]).query(points)[0] if changed.any() else np.full(len(points), np.inf)
    from_edges = np.sort(np.minimum(points - low, high - points), axis=1)[:, 1]
    far = (from_changes > 4 * old_size(points)) & (from_edges > 4 * old_size(points))
    kept = np.mean(cKDTree(mesh.points).query(points[far])[0] == 0.0)
    print(
        f"{case:>10} {method:>6} {mesh.n_points:>9,} {seconds:>8.2f} {mesh.info['iterations']:>10} "
        f"{ratio.mean():>7.3f} {ratio.min():>6.3f} {mesh.info['min_dihedral']:>8.1f} "
        f"{np.median(lengths[inner]):>9.3f} {kept:>5.2f}",
        flush=True,
    )


def main_3d(frequency=0.75):
    section = tm.seismic.read_velocity(SEGY)
    x, z = section.axes
    columns, rows = (x >= 26000) & (x <= 34000), z >= -4000
    values = section.values[np.ix_(columns, rows)][::16, ::32]
    y = np.arange(0.0, 4001.0, 200.0)
    axes = (x[columns][::16], y, z[rows][::32])
    model = tm.seismic.VelocityModel(np.repeat(values[:, None, :], len(y), axis=1), axes)
    options = dict(frequency=frequency, hmin=100.0, grade=0.15)
    size = tm.seismic.size_function(model, **options)
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    inside = np.sum(((grid - CENTRE_3D) / AXES_3D) ** 2, axis=-1) <= 1
    columns = f"{'mean rr':>7} {'min rr':>6} {'min dih':>8}"
    compare(model, options, size, inside, (("v x 0.6", 0.6), ("v x 1.6", 1.6), ("none", 1.0)), columns, row_3d)


if __name__ == "__main__":
    if sys.argv[1:2] == ["3d"]:
        main_3d(*(float(a) for a in sys.argv[2:3]))
    else:
        main(*(int(sys.argv[1]),) if len(sys.argv) > 1 else (), *(float(a) for a in sys.argv[2:3]))
