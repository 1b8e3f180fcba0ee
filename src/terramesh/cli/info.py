"""``terramesh info FILE``: counts, quality and validity of a mesh file, and the time step it allows."""

import numpy as np

from ..cleanup.validity import mesh_problems
from ..coastal.boundaries import node_string_problems
from ..coastal.timestep import COURANT, courant_number
from ..errors import MeshValidityError, SizingError
from ..io import format_from_name, read_mesh
from ..mesh.boundaries import has_boundaries
from ..mesh.mesh import guess_crs
from ..quality.summary import summary
from ._options import positive_number
from .coastal import has_depths

HELP = (
    "print counts, the quality summary, the validity and the largest time step of a mesh file "
    "(fort.14 or .grd, SCHISM .gr3 or .ll, .vtu, .msh, .xdmf)"
)


def add_arguments(parser):
    """Declare the subcommand's arguments."""
    parser.add_argument("file", help="mesh file: *.14, *.grd, *.gr3, *.ll, *.vtu, *.msh, *.xdmf")
    units = parser.add_mutually_exclusive_group()
    units.add_argument(
        "--geographic",
        action="store_true",
        help="coordinates are longitude, latitude: measure quality on the ground (a 2D mesh whose coordinates"
        " fit those ranges is read so anyway)",
    )
    units.add_argument("--planar", action="store_true", help="coordinates are planar, even where they fit lon/lat")
    parser.add_argument(
        "--dt", type=positive_number, help="time step, s: the Courant numbers at it (a mesh with depths; calcCFL)"
    )
    parser.add_argument(
        "--courant",
        type=positive_number,
        default=COURANT,
        help=f"the largest Courant number a time step may give (default {COURANT:g})",
    )


def run(arguments):
    """Print the summary; returns the exit status."""
    # --geographic reads without a CRS first: the coordinates are checked below, with the flag's own words
    crs = None if arguments.geographic or arguments.planar else "auto"
    format_from_name(arguments.file)  # the format the name says, or a message listing the known ones
    mesh = read_mesh(arguments.file, crs=crs)
    if mesh.dim == 3 and mesh.cells.shape[1] == 3:
        # quality and validity are of planar triangles and of tetrahedra: summary() failed on "points (n, 2)"
        raise MeshValidityError(
            f"{arguments.file}: a surface of {mesh.n_cells:,} triangle{'s' if mesh.n_cells != 1 else ''} in 3D "
            "(z not all 0): info measures planar triangle meshes and tetrahedral meshes only"
        )
    if arguments.geographic and (mesh.dim != 2 or guess_crs(mesh.points) is None):
        # measured "on the ground", metres read as degrees gave every cell inverted beside "validity: valid"
        raise MeshValidityError(
            f"{arguments.file}: --geographic needs 2D longitude, latitude coordinates (x in [-180, 360], y in "
            "[-90, 90]); these are not"
        )
    if arguments.dt is not None and mesh.dim != 2:
        raise MeshValidityError(f"{arguments.file}: --dt measures the Courant numbers of a 2D mesh; this one is 3D")
    if arguments.geographic:
        mesh.crs = "EPSG:4326"
    print(f"{arguments.file}: {mesh.dim}D mesh")
    if mesh.dim == 2:
        print(f"coordinates: {_coordinates(mesh, guessed=mesh.info.get('crs_guessed', False))}")
    print(summary(mesh))
    if has_boundaries(mesh.boundaries):
        print(
            f"boundaries: {len(mesh.boundaries.open)} open "
            f"({sum(len(b.nodes) for b in mesh.boundaries.open)} nodes), "
            f"{len(mesh.boundaries.land)} land ({sum(len(b.nodes) for b in mesh.boundaries.land)} nodes)"
        )
    left_out = mesh.info.get("cell_data_left_out", [])
    if mesh.point_data or left_out:
        read = f"point data: {', '.join(mesh.point_data) or 'none'}"
        print(read + (f"; cell data, not read: {', '.join(left_out)}" if left_out else ""))
    print(f"validity: {_validity(mesh)}")
    if has_boundaries(mesh.boundaries):
        print(f"node strings: {'; '.join(node_string_problems(mesh)) or 'along the boundary edges'}")
    if mesh.dim == 2:
        print(f"time step: {_time_step(mesh, arguments.dt, arguments.courant)}")
    return 0


def _coordinates(mesh, guessed):
    """How the coordinates were read, which the quality depends on (measured on the ground for degrees)."""
    if not mesh.geographic:
        return "planar" if mesh.crs is None else f"planar ({mesh.crs})"
    if guessed:
        # a 100 x 80 m plate fits those ranges too: read as degrees, its min q was 0.31 against 0.81
        return "longitude, latitude degrees (guessed from their ranges; --planar if they are not)"
    return "longitude, latitude degrees"


def _validity(mesh):
    """``valid``, the rules the mesh breaks (:func:`~terramesh.cleanup.mesh_problems`), or why it was not checked."""
    try:
        problems = mesh_problems(mesh)
    except MeshValidityError as error:
        return f"not checked ({error})"
    return "; ".join(problems) if problems else "valid"


def _time_step(mesh, dt, courant):
    """The largest time step for ``courant`` (the guide's ``calcCFL``), and the Courant numbers at ``dt``.

    A Courant number grows with the time step in proportion, so one at 1 s
    tells the largest step; the vertex that sets it is named, as the place
    to coarsen or deepen (:func:`~terramesh.coastal.enforce_timestep`).
    """
    if not has_depths(mesh):
        # a seismic mesh's step needs its model, which the file's velocities at the vertices do not make
        velocity = "velocity" in mesh.point_data or "velocity" in mesh.info.get("cell_data_left_out", [])
        seismic = "; a seismic mesh's: terramesh.seismic.stable_timestep(mesh, model)" if velocity else ""
        return f"not measured (no depths in the file{seismic})"
    try:
        per_second = courant_number(mesh, 1.0)
    except (MeshValidityError, SizingError) as error:
        return f"not measured ({error})"
    worst = int(np.argmax(per_second))
    x, y = mesh.points[worst]
    where = f"({x:.4f}, {y:.4f})" if mesh.geographic else f"({x:.6g}, {y:.6g})"
    said = (
        f"at most {courant / per_second[worst]:.3g} s for a Courant number of {courant:g} "
        f"(set by vertex {worst + 1} at {where}, {mesh.depth[worst]:.3g} m deep)"
    )
    if dt is not None:
        above = int(np.count_nonzero(per_second * dt > courant))
        said += f"; at {dt:g} s the largest is {per_second[worst] * dt:.3g}, above {courant:g} at {above:,} vertices"
    return said
