"""``terramesh demo``: mesh the bundled Danish straits coastline."""

import logging
import os

import numpy as np

from ..errors import SizingError
from ..examples.danish_straits import danish_straits_mesh
from ..quality.summary import summary
from ._options import check_output_folder, non_negative_number, positive_number

HELP = "mesh the bundled Danish straits coastline and write mesh files and a picture"

logger = logging.getLogger("terramesh.cli")


def add_arguments(parser):
    """Declare the subcommand's arguments."""
    parser.add_argument("-o", "--output-dir", default="terramesh-demo", help="folder for the results (created)")
    parser.add_argument(
        "--min-edge-km", type=positive_number, default=1.5, help="edge length at the coast, km (default 1.5)"
    )
    parser.add_argument("--max-edge-km", type=positive_number, default=8.0, help="largest edge length, km (default 8)")
    parser.add_argument(
        "--grade",
        type=non_negative_number,
        default=0.25,
        help="grade: size gradient, dimensionless: the edge length grows from --min-edge-km by GRADE km per km of"
        " distance from the coast, up to --max-edge-km, so GRADE is also the largest size gradient (coastal's --dis"
        " and --g in one); 0: --min-edge-km everywhere (default 0.25)",
    )
    parser.add_argument("--seed", type=int, default=0, help="generator seed (default 0)")


def run(arguments):
    """Build the mesh, write fort.14, VTU and PNG, print the summary."""
    from ..plot.mesh import plot_mesh

    if arguments.max_edge_km < arguments.min_edge_km:
        raise SizingError(
            f"--max-edge-km {arguments.max_edge_km:g} is below --min-edge-km {arguments.min_edge_km:g}: "
            "the largest edge length cannot be the smaller"
        )
    check_output_folder(arguments.output_dir, "-o/--output-dir")
    os.makedirs(arguments.output_dir, exist_ok=True)
    logger.info("meshing the Danish straits (Natural Earth 1:50m coastline)")
    mesh = danish_straits_mesh(
        min_edge_km=arguments.min_edge_km,
        max_edge_km=arguments.max_edge_km,
        grade=arguments.grade,
        seed=arguments.seed,
    )
    # no DEM is bundled: the fort.14 says 0 m at every node, and the summary says so (not a warning at a first run)
    mesh.point_data["depth"] = np.zeros(mesh.n_points)
    written = []
    for name in ("danish_straits.14", "danish_straits.vtu"):
        path = os.path.join(arguments.output_dir, name)
        mesh.write(path)
        written.append(path)
    picture = os.path.join(arguments.output_dir, "danish_straits.png")
    plot_mesh(mesh, picture, title=f"Danish straits: {mesh.n_points:,} vertices")
    written.append(picture)
    print(
        f"Danish straits demo: {mesh.info['iterations']} iterations ({mesh.info['stop_reason']}), "
        f"{mesh.info['seconds']:.1f} s"
    )
    print(summary(mesh))
    boundaries = mesh.boundaries
    print(f"boundaries: {len(boundaries.open)} open, {len(boundaries.land)} land (mainland and islands)")
    print("wrote " + ", ".join(written))
    print("depths: 0 m at every node, no DEM being bundled (terramesh post FILE.14 --dem DEM -o OUT.14 puts them on)")
    return 0
