"""Anisotropic meshes (tm.generate_anisotropic_mesh): time, size and how well the cells meet the metric.

Usage: python benchmarks/bench_anisotropic.py [scale]   (default 1; 2 halves every size: 4x the vertices)
       python benchmarks/bench_anisotropic.py coasts [N]   (default 48)

Cases: a constant 4:1 metric at 30 degrees on the unit square; a wall's
boundary layer on the unit disk (0.08 along the rim, 0.005 across it at the
rim, growing inward: 16:1 there); a field whose long axis turns with x on a
plate with a hole (ratio 6); BP2004 (every 8th node, 2 Hz, hmin 80 m, grade
0.15) with the velocity gradient (m = 40) across its layers only
(tm.seismic.layer_metric), beside the isotropic refinement by the same
gradient. Columns: vertices; seconds (fastest of three after a warm-up),
of them the isotropic start's; iterations and why they stopped; the metric
edge lengths (median, 5 and 95 %: 1 is the size asked); the quality
measured in the metric (mean, min); and the plain quality's mean, which
shows the stretch.

``coasts``: the hardest boundaries, N random-walk coasts of 400 vertices
(the validity sweep's, seeds 0..N-1), meshed at a constant 20:1 (0.3 along
x, 0.015 across) and a 10:1 field turning round the centre (0.2 along the
circles, 0.02 across) in turn, once each after one warm-up; a row per coast
(vertices, seconds, iterations, retriangulations, the boundary ratio a
relaxed run used) and the total.
"""

import sys
import time
import warnings
from pathlib import Path

import numpy as np
from _runner import fastest
from sweep_validity import random_walk_coast

import terramesh as tm
from terramesh.quality import metric_edge_lengths, metric_quality, triangle_quality
from terramesh.sizing import metric_tensor

SEGY = Path(__file__).resolve().parents[2] / "shared" / "data" / "seismic" / "vel_z6.25m_x12.5m_exact.segy"


def cases(scale):
    def layer(points):
        radius = np.hypot(points[:, 0], points[:, 1])
        across = (0.005 + 0.1 * np.clip(1 - radius, 0, None)) / scale
        return metric_tensor(0.08 / scale, across, np.arctan2(points[:, 1], points[:, 0]) + np.pi / 2)

    def swirl(points):
        return metric_tensor(0.12 / scale, 0.02 / scale, np.arctan2(points[:, 1] - 0.5, points[:, 0] - 1) + np.pi / 2)

    plate = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (3, 1)), tm.geometry.Disk((1, 0.5), 0.2)])
    yield (
        "square 4:1 at 30 deg",
        tm.geometry.Rectangle((0, 0), (1, 1)),
        metric_tensor(0.1 / scale, 0.025 / scale, np.radians(30)),
    )
    yield "disk boundary layer", tm.geometry.Disk((0, 0), 1), layer
    yield "plate, turning 6:1", plate, swirl
    section = tm.seismic.read_velocity(SEGY)
    x, z = section.axes
    model = tm.seismic.VelocityModel(section.values[::8, ::8], (x[::8], z[::8]))
    size = tm.seismic.size_function(model, frequency=2.0, hmin=80.0 / scale, grade=0.15)
    yield "BP2004 layers", size.domain, tm.seismic.layer_metric(size, gradient_refinement=40)
    refined = tm.seismic.size_function(model, frequency=2.0, hmin=80.0 / scale, grade=0.15, gradient_refinement=40)
    yield "BP2004 isotropic", refined.domain, refined  # a SizeGrid: meshed by tm.generate_mesh


def main(scale=1.0):
    print(
        f"{'case':>22} {'vertices':>9} {'seconds':>8} {'start':>6} {'iter':>9} "
        f"{'len med':>8} {'5 %':>6} {'95 %':>6} {'q mean':>7} {'q min':>6} {'plain q':>8}"
    )
    for name, domain, field in cases(scale):
        isotropic = isinstance(field, tm.sizing.SizeGrid)
        generate = tm.generate_mesh if isotropic else tm.generate_anisotropic_mesh
        generate(domain, field, seed=0)  # warm-up: numba's compilation, not timed
        mesh, seconds = fastest(generate, domain, field, seed=0)
        metric = (lambda p, size=field: metric_tensor(size(p), size(p), 0.0)) if isotropic else field
        lengths = metric_edge_lengths(mesh.points, mesh.cells, metric)
        quality = metric_quality(mesh.points, mesh.cells, metric)
        start = 0.0 if isotropic else mesh.info["start"]["seconds"]
        stop = f"{mesh.info['iterations']} {mesh.info['stop_reason'][:4]}"
        print(
            f"{name:>22} {mesh.n_points:>9,} {seconds:>8.2f} {start:>6.2f} {stop:>9} {np.median(lengths):>8.3f} "
            f"{np.percentile(lengths, 5):>6.3f} {np.percentile(lengths, 95):>6.3f} {quality.mean():>7.4f} "
            f"{quality.min():>6.3f} {triangle_quality(mesh.points, mesh.cells).mean():>8.4f}",
            flush=True,
        )


def turning(points):
    """10:1, the long axis along the circles round the origin."""
    return metric_tensor(0.2, 0.02, np.arctan2(points[:, 1], points[:, 0]) + np.pi / 2)


def coasts(count=48):
    tm.generate_anisotropic_mesh(tm.geometry.Disk((0, 0), 1), metric_tensor(0.3, 0.1, 0.0), seed=0)  # compiles
    print(f"{'coast':>5} {'vertices':>9} {'seconds':>8} {'iter':>5} {'retri':>6} {'relaxed to':>11}")
    total, vertices, relaxed = 0.0, 0, 0
    for seed in range(count):
        coast = random_walk_coast(np.random.default_rng(seed), 400)
        metric = metric_tensor(0.3, 0.015, 0.0) if seed % 2 == 0 else turning
        started = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a relaxed run's warning: the last column says it
            mesh = tm.generate_anisotropic_mesh(coast, metric, seed=0)
        seconds = time.perf_counter() - started
        ratio = mesh.info["boundary_ratio"]
        total, vertices, relaxed = total + seconds, vertices + mesh.n_points, relaxed + (ratio is not None)
        print(
            f"{seed:>5} {mesh.n_points:>9,} {seconds:>8.2f} {mesh.info['iterations']:>5} "
            f"{mesh.info['retriangulations']:>6} {'' if ratio is None else f'{ratio:g}:1':>11}",
            flush=True,
        )
    per_vertex = 1e3 * total / vertices
    print(f"{count} coasts: {vertices:,} vertices in {total:.1f} s ({per_vertex:.2f} ms a vertex), {relaxed} relaxed")


if __name__ == "__main__":
    if sys.argv[1:2] == ["coasts"]:
        coasts(*(int(value) for value in sys.argv[2:3]))
    else:
        main(*(float(value) for value in sys.argv[1:2]))
