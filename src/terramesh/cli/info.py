"""``terramesh info FILE``: counts and quality of a mesh file."""

from ..io import read_mesh
from ..quality.summary import summary

HELP = "print counts and the quality summary of a mesh file (fort.14, .vtu, .msh, .xdmf)"


def add_arguments(parser):
    """Declare the subcommand's arguments."""
    parser.add_argument("file", help="mesh file")
    parser.add_argument(
        "--geographic", action="store_true", help="coordinates are longitude, latitude: measure quality on the ground"
    )


def run(arguments):
    """Print the summary; returns the exit status."""
    mesh = read_mesh(arguments.file)
    if arguments.geographic:
        mesh.crs = "EPSG:4326"
    print(f"{arguments.file}: {mesh.dim}D mesh")
    print(summary(mesh))
    if mesh.boundaries is not None and (mesh.boundaries.open or mesh.boundaries.land):
        print(
            f"boundaries: {len(mesh.boundaries.open)} open "
            f"({sum(len(b.nodes) for b in mesh.boundaries.open)} nodes), "
            f"{len(mesh.boundaries.land)} land ({sum(len(b.nodes) for b in mesh.boundaries.land)} nodes)"
        )
    return 0
