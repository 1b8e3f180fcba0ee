"""The OceanMesh2D guide's §5.2 and §6.6: a high-fidelity estuary, then the files of an ADCIRC run.

§5.2 meshes New York at 30 m from a 90 m DEM; the shared data's high-resolution DEM is
NOAA's CUDEM at Sabine Pass (Texas-Louisiana, 648 x 648 nodes over 0.2°: 34 m), so this runs
the guide's parameters there (max_el 1 km, max_el_ns 240 m, dt = 2 s, grade 0.2, R = 3) with
the coastline taken from the DEM's 0 m contour, and min_el 35 m where the guide has 30: the
contour has no detail finer than the DEM's spacing. It then follows §6.6's script:
depths averaged from the DEM over each vertex's cell (``GridData``), the 2 s step enforced
(``CheckTimestep``), reverse Cuthill-McKee numbering (``renum``), the ADCIRC boundaries
(``makens``) and tau0 (``Calc_tau0``). A tidal control file (``Make_f15``) needs a TPXO atlas,
which the shared data does not hold: ``tm.coastal.write_fort15(..., atlas=...)`` or
``terramesh post --fort15`` write it where one is at hand.

Run from the repository root (reads ../shared/data); writes sabine_pass.14, sabine_pass.13
and PNGs of the mesh, its boundaries and its Courant numbers into ./examples-output/.
"""

import argparse
import logging
import pathlib
import sys

import numpy as np

import terramesh as tm

DATA = pathlib.Path(__file__).resolve().parents[2].parent / "shared" / "data"
BBOX = (-93.99, -93.81, 29.71, 29.89)  # inside the DEM's 0.2° square, so that every side has depths
DT = 2.0


def main(argv=None):
    """Build the mesh, post-process it for ADCIRC, write it and print what each step did."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=pathlib.Path, default=DATA, help="the shared data folder (dem/)")
    parser.add_argument(
        "--output", type=pathlib.Path, default=pathlib.Path("examples-output"), help="folder for the files and PNGs"
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s", stream=sys.stderr)
    dem = tm.coastal.read_dem(args.data / "dem" / "CUDEM_equal.nc", BBOX)

    # §5.2: the mesh, stable at 2 s by its size function
    mesh = tm.coastal.build(BBOX, None, dem, min_el=35, max_el=1e3, max_el_ns=240, dt=DT, g=0.2, fs=3)
    built = mesh.n_points

    # §6.6: depths averaged over each vertex's cell, at least 1 m so that no vertex is dry
    mesh = tm.coastal.interpolate_bathymetry(mesh, dem, min_depth=1.0)
    largest_before = float(np.max(tm.coastal.courant_number(mesh, DT)))
    mesh = tm.coastal.enforce_timestep(mesh, DT)
    courant = tm.coastal.courant_number(mesh, DT)
    mesh = tm.coastal.renumber(mesh)
    mesh = tm.coastal.make_boundaries(mesh, dem=dem)
    problems = tm.coastal.node_string_problems(mesh)
    if problems:
        raise SystemExit(f"the boundaries are not ADCIRC's: {problems}")

    args.output.mkdir(parents=True, exist_ok=True)
    mesh.write(args.output / "sabine_pass.14")
    attribute = tm.coastal.tau0(mesh)
    tm.coastal.write_fort13(
        args.output / "sabine_pass.13", {"primitive_weighting_in_continuity_equation": attribute}, mesh.n_points
    )
    tm.plot.plot_mesh(mesh, args.output / "sabine_pass.png")
    tm.plot.plot_boundaries(mesh, args.output / "sabine_pass_boundaries.png")
    mesh.point_data["courant"] = tm.coastal.courant_number(mesh, DT)
    tm.plot.plot_mesh(mesh, args.output / "sabine_pass_courant.png", color_by="courant")

    quality = tm.quality.summary(mesh)
    print(
        f"Sabine Pass: {mesh.n_points:,} vertices ({built:,} built), {mesh.n_cells:,} elements, "
        f"mean q {quality.mean:.3f}, min q {quality.min:.3f}; largest Courant number at {DT:g} s "
        f"{largest_before:.2f} before enforce_timestep, {float(courant.max()):.2f} after; "
        f"{len(mesh.boundaries.open)} open and {len(mesh.boundaries.land)} land boundaries; "
        f"tau0 default {attribute.default[0]:g}, {int(attribute.non_default.sum()):,} nodes listed"
    )


if __name__ == "__main__":
    main()
