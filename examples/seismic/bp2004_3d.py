"""BP2004 in 3-D: the real 2-D section extruded along y, with a salt blob inserted, sized and meshed.

The model: the BP2004 velocity section (``vel_z6.25m_x12.5m_exact.segy``,
12.5 m x 6.25 m) read with :func:`terramesh.seismic.read_velocity`, cut to
x = 26-42 km (the salt column near x = 34-40 km and the sediments west of
it) and the top 7 km, decimated to a 100 m grid, and extruded 10 km along
y. A lobed ellipsoid of salt (4500 m/s, 5 x 6 x 2.4 km, its radius
modulated by three lobes around z) is set into the sediments at x =
29.5 km, y = 5 km, z = -4 km, so the model varies in all three
directions. The grid is 161 x 101 x 71 nodes.

The sizes: :func:`terramesh.seismic.size_function` with a 1 Hz source, 10
edges per wavelength (linear elements), hmin 300 m, grade 0.15 and a
1000 m padding layer (``pad_style="edge"``) on the four sides and the
bottom. The mesh: :func:`terramesh.generate_mesh` on ``size.domain``, a
Box over the padded model, timed after a warm-up mesh (the numba JIT
excluded).

Run from the repository root: ``python examples/seismic/bp2004_3d.py``
(``--help`` for the options). Prints the model, the sizes and the mesh's
numbers and writes the mesh with its velocities and boundary tags for an
FWI code (``examples-output/bp2004_3d.msh``);
``benchmarks/compare_seismic_3d.py`` meshes the same case with SeismicMesh.
"""

import argparse
import pathlib
import time

import numpy as np

import terramesh as tm
from terramesh import seismic
from terramesh.io.fwi import fwi_format_from_name

DATA = pathlib.Path(__file__).resolve().parents[2].parent / "shared" / "data"
SEGY = DATA / "seismic" / "vel_z6.25m_x12.5m_exact.segy"
X_RANGE = (26000.0, 42000.0)
"""The part of the section kept, metres along x."""
DEPTH = 7000.0
"""Metres below the surface kept."""
Y_LENGTH = 10000.0
"""Length of the extrusion along y, metres."""
STEP = 100.0
"""Grid spacing of the 3-D model on every axis, metres: every 8th trace and every 16th sample."""
SALT = {"center": (29500.0, 5000.0, -4000.0), "radii": (2500.0, 3000.0, 1200.0), "lobes": 0.15, "velocity": 4500.0}
"""The inserted salt body: centre (x, y, z) and semi-axes in metres, lobe amplitude, velocity in m/s."""
SETTINGS = {
    "frequency": 1.0,
    "cells_per_wavelength": 10,
    "hmin": 300.0,
    "grade": 0.15,
    "pad": 1000.0,
    "pad_style": "edge",
}
"""Options of :func:`terramesh.seismic.size_function` (Hz, metres)."""


def salt_body(x, y, z, *, center, radii, lobes, **_):
    """True inside the lobed ellipsoid: ``|u| <= 1 + lobes sin(3 theta) (1 - (u_z / |u|)^2)``.

    ``u`` is the position relative to ``center`` scaled by ``radii``, and
    ``theta`` its angle around the z axis: three lobes in plan view that fade
    towards the top and bottom, so the body stays smooth.
    """
    ux, uy, uz = ((c - c0) / r for c, c0, r in zip((x, y, z), center, radii, strict=True))
    rho = np.sqrt(ux**2 + uy**2 + uz**2)
    with np.errstate(invalid="ignore", divide="ignore"):
        flat = np.where(rho > 0, 1.0 - (uz / rho) ** 2, 0.0)
    return rho <= 1.0 + lobes * np.sin(3.0 * np.arctan2(uy, ux)) * flat


def build_model(segy=SEGY):
    """The 3-D model: the BP2004 section cut, decimated to ``STEP``, extruded along y, with the salt body.

    Returns
    -------
    terramesh.seismic.VelocityModel
        3-D, m/s, axes ``(x, y, z)`` in metres, z = 0 at the top.
    """
    section = seismic.read_velocity(segy)
    dx, dz = section.spacing
    every_x, every_z = round(STEP / dx), round(STEP / dz)
    if not (np.isclose(every_x * dx, STEP) and np.isclose(every_z * dz, STEP)):
        raise ValueError(f"{segy}: a spacing of {section.spacing} m does not divide the {STEP:g} m grid")
    x, z = section.axes
    keep_x = np.flatnonzero((x >= X_RANGE[0] - 1e-6) & (x <= X_RANGE[1] + 1e-6))[::every_x]
    keep_z = np.flatnonzero(z >= -DEPTH - 1e-6)[::-1][::every_z][::-1]  # counted from the top down
    values = section.values[np.ix_(keep_x, keep_z)]
    y = np.arange(0.0, Y_LENGTH + STEP / 2, STEP)
    volume = np.repeat(values[:, None, :], len(y), axis=1)
    grid = np.meshgrid(x[keep_x], y, z[keep_z], indexing="ij")
    volume[salt_body(*grid, **SALT)] = SALT["velocity"]
    return seismic.VelocityModel(volume, (x[keep_x], y, z[keep_z]), source=f"{pathlib.Path(segy).name}, 3-D")


def edge_ratio(points, cells, size):
    """Median over unique edges of length / target size at the edge's midpoint."""
    pairs = cells[:, [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]].reshape(-1, 2)
    edges = np.unique(np.sort(pairs, axis=1), axis=0)
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    return float(np.median(np.linalg.norm(b - a, axis=1) / size((a + b) / 2)))


def run(segy=SEGY, seed=0, settings=None):
    """Build the model, the sizes (``SETTINGS`` updated by ``settings``) and the mesh, with the seconds of each."""
    started = time.perf_counter()
    model = build_model(segy)
    size = seismic.size_function(model, **{**SETTINGS, **(settings or {})})
    sizing = time.perf_counter() - started
    tm.generate_mesh(tm.geometry.Box((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)), 0.25)  # warm-up: JIT and caches
    started = time.perf_counter()
    mesh = tm.generate_mesh(size.domain, size, seed=seed)
    return model, size, mesh, sizing, time.perf_counter() - started


def main(argv=None):
    """Mesh the 3-D BP2004 case and print its numbers."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segy", type=pathlib.Path, default=SEGY, help="the BP2004 velocity SEG-Y file")
    parser.add_argument("--seed", type=int, default=0, help="seed of the generator")
    parser.add_argument(
        "--output",
        type=pathlib.Path,
        default=pathlib.Path("examples-output") / "bp2004_3d.msh",
        help="mesh file for an FWI code (.msh Gmsh 2.2 with boundary tags, .vtu, .xdmf), velocity per vertex",
    )
    args = parser.parse_args(argv)
    try:  # checked before the minutes of meshing, not after
        fwi_format_from_name(args.output)
    except tm.errors.MeshFormatError as error:
        parser.error(f"--output: {error}")
    model, size, mesh, sizing, seconds = run(args.segy, args.seed)
    quality = tm.quality.summary(mesh)
    print(f"model  {model}")
    print(f"sizes  {size}")
    print(f"settings {SETTINGS}")
    print(
        f"mesh   {mesh.n_points:,} vertices, {mesh.n_cells:,} tets; sizing {sizing:.1f} s, mesh {seconds:.1f} s "
        f"({mesh.info['iterations']} iterations, {mesh.info['stop_reason']})"
    )
    print(
        f"       dihedral min {quality.min_dihedral:.2f}, mean of cell minima {quality.mean_min_dihedral:.2f} "
        f"degrees, {quality.n_below_10_degrees} tets below 10 degrees; radius ratio min "
        f"{quality.min_radius_ratio:.3f}, mean {quality.mean_radius_ratio:.3f}; "
        f"median edge/h {edge_ratio(mesh.points, mesh.cells, size):.3f}"
    )
    args.output.parent.mkdir(parents=True, exist_ok=True)
    tm.io.write_fwi_mesh(args.output, mesh, size)  # the padded model's velocity; the layer tagged "pad"
    print(f"wrote  {args.output}")


if __name__ == "__main__":
    main()
