"""``terramesh post``: the guide's post-processing of written meshes, in its order, into one solver file.

Each step is a library function, run on the mesh files given:

0. ``--fix``: each file repaired (:func:`~terramesh.cleanup.fix_mesh`); an
   invalid one is refused otherwise;
1. several files are merged (the guide's ``a + b``, §6.5), the first keeping
   where they overlap (:func:`~terramesh.coastal.merge`), so the finest goes first;
2. ``--dem``: depths averaged over each vertex's area
   (:func:`~terramesh.coastal.interpolate_bathymetry`);
3. ``--boundaries``, or after a merge or a repair that changed a mesh (which drop
   them): ADCIRC open and land boundaries made again
   (:func:`~terramesh.coastal.make_boundaries`, the guide's ``makens``), open
   along the edge of the ``--bbox`` boxes where the water is not dry (all of
   that edge for a mesh without depths);
4. ``--dt``: the vertices that break the CFL condition removed
   (:func:`~terramesh.coastal.enforce_timestep`, the guide's ``CheckTimestep``);
5. ``--renumber``: reverse Cuthill-McKee (:func:`~terramesh.coastal.renumber`);
6. ``--fort13``: ADCIRC's ``tau0`` of the mesh written (:func:`~terramesh.coastal.tau0`),
   numbered as it is; ``--fort15``: the control file of a tidal run at ``--dt``
   (:func:`~terramesh.coastal.write_fort15`, the guide's ``Make_f15``), forced from a
   TPXO ``--tidal-atlas``.

A fort.14 records no coordinate system: coordinates in the longitude and
latitude ranges are read as degrees unless ``--planar`` says otherwise.
"""

import argparse
import os
import pathlib
import time

import shapely

from ..cleanup.fix_mesh import REPAIR_DROPS_BOUNDARIES, fix_mesh
from ..cleanup.validity import mesh_problems
from ..coastal.bathymetry import interpolate_bathymetry
from ..coastal.boundaries import make_boundaries
from ..coastal.merge import BOUNDARIES_DROPPED, merge
from ..coastal.timestep import enforce_timestep
from ..errors import GeometryError, MeshValidityError, TerrameshError, muted_warnings, warn_user
from ..io import format_from_name, read_mesh
from ..io.fort15 import check_fort15_options, write_fort15
from ..mesh.boundaries import has_boundaries
from ..postprocess.renumber import renumber
from ._options import finite_number, non_negative_number, positive_number
from .coastal import (
    add_fort13_argument,
    checked_outputs,
    contents,
    has_depths,
    write_mesh,
    write_mesh_plots,
    write_tau0,
)

HELP = (
    "post-process written meshes: repair, merge (finest first), put a DEM's depths on, make the ADCIRC "
    "boundaries, enforce a time step, renumber; one mesh file out, and a fort.13 and fort.15"
)


def add_arguments(parser):
    """Declare the subcommand's arguments."""
    parser.add_argument(
        "meshes",
        nargs="+",
        metavar="MESH",
        help="mesh files (fort.14 or .grd, .gr3, .vtu, .msh, .xdmf); several are merged, each keeping where it"
        " overlaps those after it: the finest first",
    )
    parser.add_argument("-o", "--output", required=True, help="mesh file to write (.14, .gr3, .vtu, .msh, ...)")
    parser.add_argument(
        "--planar", action="store_true", help="coordinates are planar metres, even where they fit lon/lat"
    )
    parser.add_argument(
        "--fix",
        dest="fix_mesh",
        action="store_true",
        help="repair each MESH first (duplicate and unused vertices, flat, overlapping and clockwise cells, small"
        " parts); by default an invalid one is refused",
    )
    parser.add_argument(
        "--bbox",
        nargs=4,
        type=finite_number,
        action="append",
        metavar=("LON_MIN", "LON_MAX", "LAT_MIN", "LAT_MAX"),
        help="the box a MESH was made in, once per MESH in their order: a merge keeps the earlier meshes'"
        " boxes for them, and the boundaries are open along the edge of the boxes' union (default: the"
        " extent of the points)",
    )
    parser.add_argument(
        "--g",
        "--grade",
        type=positive_number,
        help="grade: largest size gradient across a merge's seam, dimensionless (default 0.2)",
    )
    parser.add_argument("--dem", help="NetCDF or GeoTIFF elevation, metres: its depths averaged onto the vertices")
    parser.add_argument(
        "--dem-variable", dest="variable", metavar="NAME", help="NetCDF variable of the elevation (several 2-D ones)"
    )
    parser.add_argument(
        "--dem-positive", choices=("up", "down"), help="the DEM's sign: up (elevation) or down (depths, negated)"
    )
    parser.add_argument(
        "--min-depth", type=finite_number, help="with --dem: metres, positive down; shallower depths raised to it"
    )
    parser.add_argument(
        "--boundaries",
        action="store_true",
        help="make the ADCIRC boundaries again (always after a merge): open where the boundary runs along a box's"
        " edge in water, mainland and islands elsewhere",
    )
    parser.add_argument(
        "--dry-depth",
        type=finite_number,
        help="metres, positive down: boundary water at most this deep counts as land, not open ocean (default 0)",
    )
    parser.add_argument(
        "--dt", type=positive_number, help="time step, s: remove the vertices whose Courant number exceeds --courant"
    )
    parser.add_argument("--courant", type=positive_number, help="with --dt: the largest Courant number (default 0.5)")
    parser.add_argument(
        "--eta", type=non_negative_number, help="with --dt: the surface elevation added to the depth, m (default 2)"
    )
    parser.add_argument("--renumber", action="store_true", help="renumber the vertices (reverse Cuthill-McKee)")
    add_fort13_argument(parser)
    parser.add_argument(
        "--fort15",
        metavar="FILE",
        help="also write an ADCIRC fort.15 for a tidal run of the mesh written, at --dt (with --start and --run-days;"
        " the guide's Make_f15)",
    )
    parser.add_argument("--start", help="with --fort15: the cold start, UTC (ISO 8601: 2024-01-01T00:00)")
    parser.add_argument("--run-days", type=positive_number, help="with --fort15: the run's length, days")
    parser.add_argument(
        "--tidal-atlas",
        metavar="PATH",
        help="with --fort15: a TPXO atlas (a folder of h_<con>_*.nc, or one h_tpxo*.nc) for the tide on the open"
        " boundaries; without one they are held at zero elevation",
    )
    parser.add_argument(
        "--constituents",
        type=_constituents,
        help="with --fort15: tidal constituents, comma-separated (default the major eight: M2,S2,N2,K2,K1,O1,P1,Q1)",
    )
    parser.add_argument(
        "--plots", metavar="FOLDER", help="also write PNGs: the mesh by quality, resolution and depth, the boundaries"
    )


def run(arguments):
    """Read, post-process, write and report; returns the exit status."""
    started = time.perf_counter()
    file_format = _checked(arguments)
    boxes = [_box(bbox) for bbox in arguments.bbox or []]
    meshes, repaired = _read(arguments)
    _check_boxes(boxes, meshes, arguments)
    # a merge keeps the depths only where every mesh has them
    has_depth = all(has_depths(mesh) for mesh in meshes)
    if not has_depth and arguments.dem is None:  # refused before any other work
        for flag, step in (("--dt", "the Courant numbers"), ("--fort13", "tau0")):
            if getattr(arguments, flag.lstrip("-")) is not None:
                raise TerrameshError(f"{flag} needs depths for {step}, and the mesh has none: give --dem")
    mesh = _merged(meshes, boxes, arguments)
    if arguments.dem is not None:
        options = {"variable": arguments.variable, "positive": arguments.dem_positive}
        mesh = interpolate_bathymetry(mesh, arguments.dem, min_depth=arguments.min_depth, **options)
        counts = mesh.info["bathymetry"]
        print(
            f"depths from {arguments.dem}: {counts['averaged']:,} vertices averaged, {counts['sampled']:,} sampled "
            f"(depth {mesh.depth.min():.1f} to {mesh.depth.max():.1f} m)"
        )
        has_depth = True
    if arguments.boundaries or len(meshes) > 1 or repaired:
        mesh = _with_boundaries(mesh, boxes, arguments.dry_depth, has_depth)
    if arguments.dt is not None:
        options = {
            name: getattr(arguments, name) for name in ("courant", "eta") if getattr(arguments, name) is not None
        }
        mesh = enforce_timestep(mesh, arguments.dt, **options)
        step = mesh.info["timestep"]
        print(
            f"time step {arguments.dt:g} s: largest Courant number {step['max_courant_before']:.2f} -> "
            f"{step['max_courant_after']:.2f} (at most {step['courant']:g}), {step['removed']:,} vertices removed "
            f"in {step['rounds']} rounds"
        )
    if arguments.renumber:
        mesh = renumber(mesh)
        numbers = mesh.info["renumber"]
        print(f"renumbered: bandwidth {numbers['bandwidth_before']:,} -> {numbers['bandwidth_after']:,}")
    if file_format in ("fort14", "gr3") and not has_boundaries(mesh.boundaries):
        # a fort.14 of "0 open, 0 land" boundaries, and a fort.15 with nothing to force, without a word
        warn_user(
            f"{arguments.output} gets no open or land boundaries (its mesh has none), which the model needs: "
            "give --boundaries to make them"
        )
    if arguments.fort15 is not None:  # first: the atlas may refuse the open-boundary nodes, and nothing is written
        _write_fort15(mesh, arguments)
    output = write_mesh(mesh, arguments.output)
    print(contents(mesh, file_format, has_depth=has_depth, no_dem="no depths in the mesh and no --dem"))
    if arguments.fort13 is not None:
        write_tau0(mesh, arguments.fort13)
    print(f"wrote {output} in {time.perf_counter() - started:.1f} s")
    if arguments.plots:
        folder = pathlib.Path(arguments.plots)
        folder.mkdir(parents=True, exist_ok=True)
        write_mesh_plots(folder, mesh, has_depth=has_depth)
    return 0


def _fort15_options(arguments):
    """:func:`~terramesh.coastal.write_fort15`'s options from the command line, with fort.13's tau0."""
    options = {} if arguments.constituents is None else {"constituents": arguments.constituents}
    attributes = [] if arguments.fort13 is None else ["primitive_weighting_in_continuity_equation"]
    return dict(
        start=arguments.start,
        run_days=arguments.run_days,
        dt=arguments.dt,
        tidal_atlas=arguments.tidal_atlas,
        nodal_attributes=attributes,
        **options,
    )


def _write_fort15(mesh, arguments):
    """The control file of a tidal run on ``mesh``."""
    write_fort15(arguments.fort15, mesh, **_fort15_options(arguments))
    nodes = sum(len(boundary.nodes) for boundary in mesh.boundaries.open) if mesh.boundaries is not None else 0
    forced = (
        f"forced by {arguments.tidal_atlas} at {nodes:,} open-boundary nodes" if arguments.tidal_atlas else "unforced"
    )
    print(
        f"wrote {arguments.fort15}: {arguments.run_days:g} days from {arguments.start} at {arguments.dt:g} s, {forced}"
    )


def _constituents(text):
    """``--constituents``: names separated by commas."""
    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names:
        raise argparse.ArgumentTypeError(f"constituent names separated by commas (M2,S2,K1), got {text!r}")
    return names


def _read(arguments):
    """The meshes, each valid (repaired with ``--fix``), and whether a repair changed one that had boundaries."""
    crs = None if arguments.planar else "auto"
    meshes, repaired = [], False
    for path in arguments.meshes:
        mesh = read_mesh(path, crs=crs)
        if arguments.fix_mesh:
            had_boundaries = has_boundaries(mesh.boundaries)
            with muted_warnings(REPAIR_DROPS_BOUNDARIES):  # made again, as the warning asks
                mesh = fix_mesh(mesh)
            repaired |= had_boundaries and mesh.boundaries is None
            print(f"repaired {path}: {mesh.info['repair']}")
        else:
            problems = mesh_problems(mesh)
            if problems:
                raise MeshValidityError(f"{path}: not a valid mesh ({'; '.join(problems)}): give --fix to repair it")
        meshes.append(mesh)
    return meshes, repaired


def _merged(meshes, boxes, arguments):
    """The meshes merged in order, each earlier one keeping where they overlap (within its ``--bbox``)."""
    mesh = meshes[0]
    for number, other in enumerate(meshes[1:], start=1):
        region = shapely.union_all(boxes[:number]) if boxes else None
        options = {} if arguments.g is None else {"grade": arguments.g}
        with muted_warnings(BOUNDARIES_DROPPED):  # made again, as the warning asks
            mesh = merge(mesh, other, region=region, **options)
        seam = mesh.info["merge"]
        seam_cells = len(seam["seam_cells"])
        quality = f" (q min {seam['seam_quality_min']:.2f})" if seam_cells else ""  # none: its minimum was "nan"
        print(
            f"merged {arguments.meshes[number]}: {seam['dropped_cells']:,} of its cells dropped, "
            f"{seam_cells:,} seam cells{quality}"
        )
    return mesh


def _with_boundaries(mesh, boxes, dry_depth, has_depth):
    """The ADCIRC boundaries made again: open along the boxes' edge (the points' extent without boxes).

    Without depths the whole of that edge is open (no dry stretch can be told).
    """
    options = {} if dry_depth is None else {"dry_depth": dry_depth}
    if boxes:
        options["bbox"] = shapely.union_all(boxes)
    if not has_depth:
        options["open_by"] = "bbox"
    mesh = make_boundaries(mesh, **options)
    made = mesh.info["boundaries"]
    islands = f"{made['islands']} island{'s' if made['islands'] != 1 else ''}"
    unsure = "" if has_depth else " (no depths: open along the whole edge of the box)"
    print(f"boundaries made: {made['open']} open, {made['mainland']} mainland, {islands}{unsure}")
    return mesh


def _checked(arguments):
    """The output's format, after refusing (before any work) options that do not go together."""
    inputs = [("MESH", path) for path in arguments.meshes] + [
        (flag, getattr(arguments, name)) for flag, name in (("--dem", "dem"), ("--tidal-atlas", "tidal_atlas"))
    ]
    file_format = checked_outputs(
        arguments, [(flag, path) for flag, path in inputs if path is not None], in_place=arguments.meshes
    )
    for path in arguments.meshes:
        format_from_name(path)
    if arguments.bbox and len(arguments.bbox) != len(arguments.meshes):
        raise GeometryError(
            f"--bbox given {len(arguments.bbox)} time(s) for {len(arguments.meshes)} MESH file(s): give one box per "
            "MESH, in their order, or none"
        )
    merging = len(arguments.meshes) > 1
    for flag, given, needed, what in (
        ("--dem-variable", arguments.variable, arguments.dem is not None, "--dem: give it too"),
        ("--dem-positive", arguments.dem_positive, arguments.dem is not None, "--dem: give it too"),
        ("--min-depth", arguments.min_depth, arguments.dem is not None, "--dem: give it too"),
        ("--courant", arguments.courant, arguments.dt is not None, "--dt: give it too"),
        ("--eta", arguments.eta, arguments.dt is not None, "--dt: give it too"),
        ("--g", arguments.g, merging, "a merge's seam: give two MESH files or more"),
        ("--dry-depth", arguments.dry_depth, arguments.boundaries or merging, "--boundaries: give it too"),
        ("--bbox", arguments.bbox, arguments.boundaries or merging, "a merge or --boundaries: give --boundaries too"),
        ("--start", arguments.start, arguments.fort15 is not None, "--fort15: give it too"),
        ("--run-days", arguments.run_days, arguments.fort15 is not None, "--fort15: give it too"),
        ("--tidal-atlas", arguments.tidal_atlas, arguments.fort15 is not None, "--fort15: give it too"),
        ("--constituents", arguments.constituents, arguments.fort15 is not None, "--fort15: give it too"),
    ):
        if given is not None and not needed:
            raise TerrameshError(f"{flag} is for {what}")
    if arguments.fort15 is not None:
        missing = [
            flag for flag in ("--dt", "--start", "--run-days") if getattr(arguments, flag[2:].replace("-", "_")) is None
        ]
        if missing:
            raise TerrameshError(f"--fort15 needs {', '.join(missing)}: the run's time step, start and length")
        # the constituents' names, the start date and a --dt the output intervals are multiples of, checked before
        # the work, not after it
        check_fort15_options(**_fort15_options(arguments))
    if arguments.planar and arguments.fort15 is not None:
        raise TerrameshError(
            "--fort15 writes a run in longitude, latitude degrees (ICS = 2), and --planar says the mesh is not"
        )
    if arguments.planar and arguments.dem is not None:
        # interpolate_bathymetry takes a mesh without a CRS for degrees: metres would be read as such
        raise TerrameshError("--dem puts depths on a mesh in longitude, latitude degrees, and --planar says it is not")
    for flag, path in (("--dem", arguments.dem), ("--tidal-atlas", arguments.tidal_atlas)):
        if path is not None and not os.path.exists(path):  # read after the merge: named before it
            raise FileNotFoundError(f"{flag}: no such file: {path!r}")
    return file_format


def _check_boxes(boxes, meshes, arguments):
    """Refuse a ``--bbox`` that does not overlap its mesh: a box mistyped (latitudes first) changed the merge."""
    for box, mesh, path, bbox in zip(boxes, meshes, arguments.meshes, arguments.bbox or [], strict=False):
        low, high = mesh.points.min(axis=0), mesh.points.max(axis=0)
        if box.intersection(shapely.box(*low, *high)).area == 0:
            raise GeometryError(
                f"--bbox {' '.join(f'{v:g}' for v in bbox)} does not overlap {path}, which spans longitude "
                f"{low[0]:g} to {high[0]:g}, latitude {low[1]:g} to {high[1]:g}: give its box as LON_MIN LON_MAX "
                "LAT_MIN LAT_MAX, in the mesh's longitudes"
            )


def _box(bbox):
    """A ``--bbox`` (the guide's order) as a shapely box, refusing one whose sides are the wrong way round."""
    lon_min, lon_max, lat_min, lat_max = bbox
    if not (lon_min < lon_max and lat_min < lat_max):
        raise GeometryError(f"--bbox {' '.join(f'{v:g}' for v in bbox)}: LON_MIN < LON_MAX and LAT_MIN < LAT_MAX")
    return shapely.box(lon_min, lat_min, lon_max, lat_max)
