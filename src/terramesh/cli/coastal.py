"""``terramesh coastal``: a coastal mesh from a bbox, a shoreline and a DEM, with its pictures.

The fort.14 it writes carries the ADCIRC boundaries of
:func:`~terramesh.coastal.make_boundaries` (the guide's ``makens``, its
defaults): open ocean where the boundary runs along the box's edge (where
the DEM has water there), mainland and islands elsewhere.
"""

import logging
import os
import pathlib
import time

import numpy as np

from ..coastal.build import build
from ..coastal.dem import read_dem
from ..coastal.nodal_attributes import tau0
from ..coastal.shoreline import Shoreline
from ..errors import GeometryError, SizingError, TerrameshError
from ..io import format_from_name
from ..io.fort13 import write_fort13
from ..mesh.boundaries import has_boundaries
from ..quality.summary import summary
from ._options import (
    check_launched_with_mpi,
    check_output_file,
    check_output_folder,
    finite_number,
    fraction,
    mpi_world,
    positive_number,
    time_step,
    whole_number_at_least_one,
)

logger = logging.getLogger("terramesh.cli")

SIZE_FUNCTIONS = ("--dis", "--fs", "--wl", "--slp", "--ch")
"""The size functions' flags: at least one of them, or a bounded ``--max-el``, sets the sizes."""

HELP = "mesh the water in a lon/lat box from a shoreline and/or DEM with the OceanMesh2D size functions"


def add_arguments(parser):
    """Declare the subcommand's arguments (the guide's option names)."""
    parser.add_argument(
        "--bbox",
        nargs=4,
        type=float,
        required=True,
        metavar=("LON_MIN", "LON_MAX", "LAT_MIN", "LAT_MAX"),
        help="box to mesh, degrees (the guide's order)",
    )
    parser.add_argument("--shoreline", help="shapefile or GeoPackage of land polygons (default: the DEM's 0 m contour)")
    parser.add_argument(
        "--layer",
        type=_layer,
        help="layer of the --shoreline file holding the land, by name or 0-based number (a name made of digits is"
        " the name): needed when the file (a GeoPackage) has several polygon layers",
    )
    parser.add_argument(
        "--crs",
        help="CRS of the --shoreline file's coordinates, for a file without one (a shapefile without its .prj) or"
        " with a wrong one: EPSG:32619, a PROJ string, WKT",
    )
    parser.add_argument("--dem", help="NetCDF or GeoTIFF elevation, metres (see --dem-positive for its sign)")
    # dest "variable", read_dem's name: the library's "choose ... with variable=NAME" then reads as this flag
    parser.add_argument(
        "--dem-variable",
        dest="variable",
        metavar="NAME",
        help="NetCDF variable of the elevation, when the --dem file has several 2-D ones",
    )
    parser.add_argument(
        "--dem-positive",
        choices=("up", "down"),
        help="the DEM's sign: up (elevation) or down (depths, negated); default: the NetCDF variable's positive"
        " attribute, else its standard_name (sea_floor_depth...: down) or name (depth, h, ...: down), else up",
    )
    sizes = parser.add_argument_group(
        "edge lengths and size functions (the guide's §3-4)",
        f"Give at least one size function ({', '.join(SIZE_FUNCTIONS)}) or a bounded --max-el: each function is off"
        " unless given, the sizes are the smallest of those given, bounded by --min-el and --max-el, then graded"
        " (--g).",
    )
    sizes.add_argument("--min-el", "--h0", type=positive_number, required=True, help="smallest edge length h0, metres")
    sizes.add_argument(
        "--max-el",
        type=float,
        help="largest edge length, metres (default: unbounded; with no size function it is the size everywhere)",
    )
    sizes.add_argument("--max-el-ns", type=float, help="largest edge length near the coast, metres (default: off)")
    sizes.add_argument(
        "--dis",
        type=float,
        help="size growth with distance from the coast, metres per metre (eq. 2; not with --fs); default: off",
    )
    sizes.add_argument("--fs", type=float, help="elements across a feature (eq. 3-4); default: off")
    sizes.add_argument("--wl", type=float, help="elements per M2 wavelength (eq. 5-6; needs --dem); default: off")
    sizes.add_argument("--slp", type=float, help="slope parameter alpha_slp (eq. 7; needs --dem); default: off")
    sizes.add_argument(
        "--fl",
        nargs=2,
        type=float,
        metavar=("FL_LOW", "FL_HIGH"),
        help="band-pass filter lengths of the slope function, metres, with --slp or --ch (default eq. 8's)",
    )
    sizes.add_argument(
        "--ch",
        type=float,
        help="percentile of the slope sizes along channels (§3.4; needs --dem); default: off",
    )
    sizes.add_argument(
        "--thalwegs",
        metavar="FILE",
        help="MATLAB file of channel thalwegs (a cell array pts2, as OceanMesh2D's ECGC_Thalwegs.mat) for --ch;"
        " by default channels are found in the DEM",
    )
    sizes.add_argument(
        "--g", "--grade", type=float, help="grade: largest size gradient (eq. 9), dimensionless; default 0.2, inf: off"
    )
    sizes.add_argument("--dt", type=time_step, help="time step to be stable for, s; 0 chooses one (eq. 12)")
    sizes.add_argument(
        "--courant", type=positive_number, help="with --dt: the largest Courant number allowed (default 0.5)"
    )
    sizes.add_argument(
        "--eta", type=float, help="with --dt: the surface elevation added to the depth in the wave speed, m (default 2)"
    )
    meshing = parser.add_argument_group("meshing and output")
    meshing.add_argument(
        "--open-water",
        action="store_true",
        help="mesh a box with no land in it as open sea (require_land=False); by default that is an error",
    )
    meshing.add_argument(
        "--dj-cutoff",
        type=fraction,
        default=0.01,
        help="delete parts with fewer than this fraction of cells (default 0.01)",
    )
    meshing.add_argument(
        "--dry-depth",
        type=finite_number,
        help="metres, positive down: boundary water at most this deep counts as land, not open ocean (default 0)",
    )
    meshing.add_argument(
        "--itmax", type=whole_number_at_least_one, default=100, help="most generator iterations (default 100)"
    )
    meshing.add_argument("--seed", type=int, default=0, help="generator seed (default 0)")
    meshing.add_argument("--parts", type=whole_number_at_least_one, help="mesh the water in this many strips and merge")
    meshing.add_argument("--mpi", action="store_true", help="share the strips over the MPI ranks (mpiexec)")
    meshing.add_argument("-o", "--output", default="coastal.14", help="mesh file to write (default coastal.14)")
    add_fort13_argument(meshing)
    meshing.add_argument(
        "--plots",
        metavar="FOLDER",
        help="also write PNGs: shoreline over DEM, each size field, the mesh by quality, resolution and depth, "
        "the quality histogram, the boundary node strings",
    )


def _layer(text):
    """A layer name, or a number when it is digits alone: the reader takes it as the name of a layer of that name.

    Digits that do not read back as the number (``007``) stay a name.
    """
    return int(text) if text.isascii() and text.isdigit() and str(int(text)) == text else text


def _check_antimeridian(bbox):
    """Refuse a box across 180 degrees written from 170 to -170, saying how it is written: 170 to 190.

    The library's "min < max" alone left the user to guess that the box
    takes longitudes past 180 (0..360) there.
    """
    lon_min, lon_max, lat_min, lat_max = bbox
    if lon_max < 0 < lon_min and lon_max + 360 - lon_min <= 180:  # 10 -10 is a box written the wrong way round
        raise GeometryError(
            f"--bbox {lon_min:g} {lon_max:g}: LON_MIN is east of LON_MAX; a box across 180 degrees is written with "
            f"longitudes past 180: --bbox {lon_min:g} {lon_max + 360:g} {lat_min:g} {lat_max:g}"
        )


def _check_sizes_asked_for(arguments):
    """Refuse, before any file is read, a job with no size function and no bounded ``--max-el``: nothing sets the sizes.

    build said so after reading the shoreline and the DEM (seconds, or
    minutes for a large DEM).
    """
    asked = [flag for flag in SIZE_FUNCTIONS if getattr(arguments, flag[2:]) is not None]
    if not asked and (arguments.max_el is None or arguments.max_el == np.inf):  # NaN: build's own check names it
        raise SizingError(f"no size function was asked for ({', '.join(SIZE_FUNCTIONS)}) and --max-el is unbounded")


def run(arguments):
    """Build, write and report the mesh; returns the exit status."""
    started = time.perf_counter()
    inputs = [("--shoreline", arguments.shoreline), ("--dem", arguments.dem), ("--thalwegs", arguments.thalwegs)]
    file_format = checked_outputs(arguments, [(flag, path) for flag, path in inputs if path is not None])
    check_launched_with_mpi(arguments.mpi)
    _check_antimeridian(arguments.bbox)
    if arguments.dt is None and (arguments.courant is not None or arguments.eta is not None):
        raise SizingError("--courant and --eta are for the time step: give --dt (0 chooses one) with them")
    comm = mpi_world(arguments.mpi)
    options = {
        name: getattr(arguments, name)
        for name in ("max_el", "max_el_ns", "dis", "fs", "wl", "slp", "fl", "ch", "g", "dt", "courant", "eta")
        if getattr(arguments, name) is not None
    }
    if arguments.thalwegs is not None:
        options["thalwegs"] = arguments.thalwegs
    if arguments.dry_depth is not None:
        options["boundaries"] = {"dry_depth": arguments.dry_depth}
    dem, shoreline = arguments.dem, arguments.shoreline
    for given, needs, file, says in (
        (arguments.dem_positive, "--dem", dem, "--dem-positive gives the sign of a DEM"),
        (arguments.variable, "--dem", dem, "--dem-variable names the elevation variable of a DEM"),
        (arguments.layer, "--shoreline", shoreline, "--layer chooses the layer of a shoreline file"),
        (arguments.crs, "--shoreline", shoreline, "--crs gives the CRS of a shoreline file"),
        (arguments.fort13, "--dem", dem, "--fort13 writes tau0 from the depths of a DEM"),
    ):
        if given is not None and file is None:
            raise GeometryError(f"{says}: give {needs} too")
    _check_sizes_asked_for(arguments)
    # options build does not take: the DEM and the shoreline are read here with them, and passed on read
    read_started = time.perf_counter()
    if arguments.dem_positive is not None or arguments.variable is not None:
        dem = read_dem(dem, arguments.bbox, variable=arguments.variable, positive=arguments.dem_positive)
    if arguments.layer is not None or arguments.crs is not None:
        shoreline = Shoreline.read(
            shoreline,
            arguments.bbox,
            arguments.min_el,
            crs=arguments.crs,
            layer=arguments.layer,
            require_land=not arguments.open_water,
        )
    read_here = time.perf_counter() - read_started
    mesh = build(
        arguments.bbox,
        shoreline,
        dem,
        min_el=arguments.min_el,
        disjoint_cutoff=arguments.dj_cutoff,
        max_iter=arguments.itmax,
        seed=arguments.seed,
        require_land=not arguments.open_water,
        parts=arguments.parts,
        comm=comm,
        **options,
    )
    if mesh is None:  # an MPI rank other than 0: its strips went to rank 0, which writes the file
        return 0
    # a DEM or shoreline read here (for their options) is part of the job's reading, as when build reads them
    for stage in ("read", "total"):
        mesh.info["timings"][stage] += read_here
    output = write_mesh(mesh, arguments.output)
    print(contents(mesh, file_format, has_depth=bool(arguments.dem)))
    if arguments.fort13 is not None:
        write_tau0(mesh, arguments.fort13)
    sizes = mesh.info["sizes"]
    if sizes.dt is not None:
        print(f"CFL-limited for a time step of {sizes.dt:.3g} s")
        # measured by build, which warns (with the remedy) where vertices break the target
        largest = mesh.info.get("largest_courant")
        if largest is not None:
            print(f"largest Courant number on the mesh's shortest edges: {largest:.2f}, the target {sizes.courant:g}")
    print(f"wrote {output} in {time.perf_counter() - started:.1f} s (meshing {mesh.info['timings']['total']:.1f} s)")
    if arguments.plots:
        _write_plots(pathlib.Path(arguments.plots), mesh)
    return 0


def add_fort13_argument(parser):
    """Declare ``--fort13``, written by :func:`write_tau0`."""
    parser.add_argument(
        "--fort13",
        metavar="FILE",
        help="also write a fort.13 of ADCIRC's tau0 for the mesh written (primitive_weighting_in_continuity_equation,"
        " OceanMesh2D's Calc_tau0 rule from depth and spacing)",
    )


def checked_outputs(arguments, inputs=(), *, in_place=()):
    """The format of ``-o``, refusing before the work (not after) a name no format has or files not writable.

    Two outputs on one file are refused (``--fort13`` over the mesh, or over
    ``--fort15``, which then names a fort.13 that is gone), and so is an
    output on an input, ``(flag, path)`` in ``inputs``, except ``-o`` on
    those in ``in_place`` (a mesh ``post`` reads before it writes anything).
    """
    file_format = format_from_name(arguments.output)
    outputs = [("-o", arguments.output)] + [
        (flag, getattr(arguments, flag[2:], None)) for flag in ("--fort13", "--fort15")
    ]
    written = {}
    for flag, path in outputs:
        if path is None:
            continue
        check_output_file(path, flag)
        same = written.setdefault(os.path.realpath(path), flag)
        if same != flag:
            raise TerrameshError(f"{same} and {flag} are both {path}: give each output its own file")
    kept = {os.path.realpath(path) for path in in_place}
    for flag, path in inputs:
        where = os.path.realpath(path)
        if where in written and not (written[where] == "-o" and where in kept):
            raise TerrameshError(
                f"{written[where]} would overwrite the {flag} input, {path}: give it another file name"
            )
    if arguments.plots:
        check_output_folder(arguments.plots, "--plots")
    return file_format


def has_depths(mesh):
    """Whether the mesh has a depth at every vertex, not 0 at all of them (a fort.14 written without a DEM)."""
    return mesh.depth is not None and bool(np.isfinite(mesh.depth).all() and np.any(mesh.depth != 0))


def write_tau0(mesh, path):
    """Write ADCIRC's tau0 of ``mesh`` (:func:`~terramesh.coastal.tau0`) as a fort.13 at ``path``, and say so."""
    attribute = tau0(mesh)
    write_fort13(path, {"primitive_weighting_in_continuity_equation": attribute}, mesh.n_points)
    listed = int(attribute.non_default.sum())
    print(f"wrote {path}: tau0 {attribute.default[0]:g} by default, another value at {listed:,} nodes")


def write_mesh(mesh, output):
    """Write ``mesh`` to ``output`` (its folder made), NaN depths as 0, and print its summary; returns the path."""
    output = pathlib.Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    if mesh.depth is None or not np.isfinite(mesh.depth).all():  # fort.14 needs a number: no DEM, depth 0
        mesh.point_data["depth"] = np.zeros(mesh.n_points) if mesh.depth is None else np.nan_to_num(mesh.depth, nan=0.0)
    mesh.write(output)
    print(summary(mesh))
    return output


def contents(mesh, file_format, *, has_depth, no_dem="no --dem"):
    """What the written file holds of the mesh's boundaries and depths: fort.14 and gr3 all, the others less."""
    made = has_boundaries(mesh.boundaries)
    boundaries = (
        f"{len(mesh.boundaries.open)} open, {len(mesh.boundaries.land)} land (mainland and islands)" if made else "none"
    )
    if file_format in ("fort14", "gr3"):
        depth = "" if has_depth else f"; depth 0 everywhere ({no_dem})"
        return f"boundaries: {boundaries}{depth}"
    # meshio's formats hold no boundaries; the Gmsh file no point data either
    depth = "depth as point data 'depth'" + ("" if has_depth else f" (0 everywhere: {no_dem})")
    holds = "vertices and cells only" if file_format == "gmsh22" else f"vertices, cells and {depth}"
    if not made:
        return f"the file holds {holds}"
    return f"the file holds {holds}; not written: the boundaries ({boundaries}), which only fort.14 and .gr3 hold"


def _write_plots(folder, mesh):
    from ..plot.coastal import plot_shoreline

    folder.mkdir(parents=True, exist_ok=True)
    logger.info("drawing the pictures into %s/", folder)
    sizes = mesh.info["sizes"]
    plot_shoreline(sizes.shoreline, sizes.dem, folder / "shoreline.png")
    for name in sizes.fields:
        sizes.plot(folder / f"size_{name}.png", name=name)
    sizes.plot(folder / "size_final.png")
    write_mesh_plots(folder, mesh, has_depth=sizes.dem is not None)


def write_mesh_plots(folder, mesh, *, has_depth):
    """The mesh by quality, resolution and depth, the quality histogram and the boundaries, as PNGs in ``folder``."""
    from ..plot.boundaries import plot_boundaries
    from ..plot.mesh import plot_mesh
    from ..plot.quality import plot_quality

    plot_mesh(mesh, folder / "mesh.png")
    plot_mesh(mesh, folder / "resolution.png", color_by="resolution")
    if has_depth:
        plot_mesh(mesh, folder / "depth.png", color_by="depth")
    plot_quality(mesh, folder / "quality.png")
    if mesh.boundaries is not None:
        plot_boundaries(mesh, folder / "boundaries.png")
    print(f"pictures in {folder}/")
