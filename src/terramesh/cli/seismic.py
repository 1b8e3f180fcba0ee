"""``terramesh seismic``: a mesh for full-waveform inversion from a velocity model, or one adapted to its update."""

import argparse
import pathlib
import time
import warnings

import numpy as np

from ..errors import GenerationError, MeshFormatError, TerrameshError
from ..generation.adapt import adapt_mesh
from ..generation.anisotropic import generate_anisotropic_mesh
from ..generation.distmesh import generate_mesh
from ..io import format_from_name, read_mesh
from ..io.fwi import fwi_format_from_name, write_fwi_mesh
from ..parallel.mesh_in_parts import generate_mesh_parallel
from ..quality.metric import metric_quality
from ..quality.summary import summary
from ..seismic.anisotropic import layer_metric
from ..seismic.sizing import CELLS_PER_WAVELENGTH, CELLS_PER_WAVELENGTH_3D, COURANT, size_function
from ..seismic.velocity import READER_OPTIONS, format_of, read_velocity
from ._options import (
    check_launched_with_mpi,
    check_output_file,
    mpi_rank,
    mpi_world,
    whole_number_at_least_one,
)

HELP = "mesh a velocity model (SEG-Y, binary, NetCDF) for wave propagation, or adapt a mesh to a model update"


def add_arguments(parser):
    """Declare the subcommand's arguments (:func:`~terramesh.seismic.size_function`'s, dashed)."""
    parser.add_argument("model", help="velocity model: SEG-Y, raw binary (give --shape), NetCDF")
    parser.add_argument(
        "--spacing",
        nargs="+",
        type=float,
        help="grid spacing, metres, as dx [dy] dz whatever the file's order, or one for all (else the headers')",
    )
    parser.add_argument(
        "--shape",
        nargs="+",
        type=int,
        help="grid shape of a raw binary file, in the file's order (--axis-order): --shape NZ NX with zx",
    )
    parser.add_argument("--dtype", help="values of a raw binary file, e.g. float32 (default), float64")
    parser.add_argument("--axis-order", help="axes of a binary or NumPy file, slowest first: xz, zx, xyz, zxy...")
    parser.add_argument(
        "--byte-order", choices=("little", "big", "native"), help="of a raw binary file (default little)"
    )
    parser.add_argument("--variable", help="the velocity's name in a NetCDF file that holds several variables")
    parser.add_argument(
        "--sample-format",
        choices=("ibm", "ieee"),
        help="a SEG-Y file's float format where its header's code is wrong (default: the header's)",
    )
    parser.add_argument(
        "--line-bytes",
        nargs=2,
        type=int,
        metavar=("INLINE", "CROSSLINE"),
        help="trace header bytes of a SEG-Y cube's inline and crossline numbers (default 189 193)",
    )
    parser.add_argument(
        "--units",
        choices=("m/s", "km/s"),
        help="velocity units (default: a NetCDF variable's units attribute, else m/s); velocities all below"
        " 20 m/s look like km/s and are refused",
    )
    parser.add_argument("--frequency", type=float, required=True, help="peak frequency, Hz")
    parser.add_argument(
        "--cells-per-wavelength",
        type=float,
        help="elements (edges) per wavelength n, h = v / (f n); default by --element-order: "
        f"{_by_order(CELLS_PER_WAVELENGTH)} in 2-D, {_by_order(CELLS_PER_WAVELENGTH_3D)} in 3-D",
    )
    parser.add_argument(
        "--element-order",
        type=int,
        help="polynomial order k of the solver's elements, for the default --cells-per-wavelength and the CFL"
        " bound of --dt (default 1)",
    )
    parser.add_argument("--hmin", type=float, required=True, help="smallest edge length, metres")
    parser.add_argument("--hmax", type=float, help="largest edge length, metres (default: unbounded)")
    parser.add_argument(
        "--grade",
        type=float,
        help="grade: largest size gradient, dimensionless, e.g. 0.15; with --pad also the padding's growth"
        " (default: off, no grading)",
    )
    parser.add_argument(
        "--pad",
        type=_widths,
        metavar="WIDTH[,...]",
        help="padding (absorbing layer) width, metres: one for the sides and bottom, or LEFT,RIGHT,BOTTOM (2-D),"
        " X-,X+,Y-,Y+,BOTTOM (3-D)",
    )
    parser.add_argument("--pad-style", choices=("edge", "constant", "linear"), default="edge", help="default edge")
    parser.add_argument(
        "--pad-velocity",
        type=float,
        help="m/s, with --pad-style constant (the padding's velocity) or linear (the ramp's at the outer boundary);"
        " default the model's largest; refused with edge, and below 20 m/s (km/s)",
    )
    parser.add_argument(
        "--no-coarsen-pad", dest="coarsen_pad", action="store_false", help="keep the padding's sizes from growing"
    )
    parser.add_argument("--gradient-refinement", type=float, help="elements across a velocity change")
    parser.add_argument(
        "--anisotropic",
        action="store_true",
        help="2D: refine by --gradient-refinement across the layers only, cells long along them (layer_metric)",
    )
    parser.add_argument("--velocity-window", type=float, help="width of the slowest-velocity window, metres")
    parser.add_argument("--courant", type=float, help=f"largest Courant number Cr for --dt (default {COURANT:g})")
    parser.add_argument("--sources", metavar="FILE", help="text file of source positions, one x z (x y z) per line")
    parser.add_argument("--receivers", metavar="FILE", help="text file of receiver positions, as --sources")
    parser.add_argument("--acquisition-size", type=float, help="edge length near sources and receivers, metres")
    parser.add_argument("--acquisition-radius", type=float, help="distance from them within which it holds, metres")
    parser.add_argument(
        "--dt",
        type=float,
        help="time step (s) the sizes are made stable for (CFL: edges of at least k v dt / Cr); the mesh's own"
        " limit, on its shortest edges, is printed and warned about when below",
    )
    parser.add_argument("--seed", type=int, help="generator seed (default 0; --adapt starts from the mesh, none)")
    parser.add_argument("-o", "--output", default="seismic.msh", help="mesh file: .msh, .vtu, .xdmf (default .msh)")
    parser.add_argument("--velocity-on", choices=("vertices", "cells"), default="vertices", help="default vertices")
    parser.add_argument("--adapt", metavar="MESH", help="adapt this mesh (of an earlier model, 2D or 3D) instead")
    parser.add_argument(
        "--old-model", metavar="MODEL", help="with --adapt: the earlier model; vertices where its sizes hold stay"
    )
    parser.add_argument(
        "--old-spacing", nargs="+", type=float, help="with --old-model: its grid spacing, where not --spacing's"
    )
    parser.add_argument(
        "--parts", type=whole_number_at_least_one, help="mesh in this many strips (2D) or slabs (3D) and merge them"
    )
    parser.add_argument("--mpi", action="store_true", help="share the strips or slabs over the MPI ranks (mpiexec)")


def _by_order(cells):
    """``{1: 10.0, 2: 7.02}`` as ``10, 7.02 for orders 1-2``: a help's defaults, from the table the sizes use."""
    orders = sorted(cells)
    return f"{', '.join(f'{cells[order]:g}' for order in orders)} for orders {orders[0]}-{orders[-1]}"


def run(arguments):
    """Size, mesh (or adapt), write and report; returns the exit status."""
    started = time.perf_counter()
    if arguments.old_model and not arguments.adapt:
        raise GenerationError("--old-model is the model of the mesh given with --adapt: give that mesh too")
    if arguments.old_spacing and not arguments.old_model:
        raise GenerationError("--old-spacing is the grid spacing of --old-model: give that model too")
    if arguments.adapt and (arguments.parts is not None or arguments.mpi):
        raise GenerationError("--adapt adapts one mesh in one process: leave out --parts and --mpi")
    if arguments.adapt and arguments.seed is not None:  # it was ignored, silently
        raise GenerationError("--adapt starts from the mesh's own points and draws none: leave out --seed")
    seed = 0 if arguments.seed is None else arguments.seed
    if arguments.anisotropic and arguments.gradient_refinement is None:
        raise GenerationError("--anisotropic refines across the layers by --gradient-refinement M: give it")
    if arguments.anisotropic and (arguments.adapt or arguments.parts is not None or arguments.mpi):
        raise GenerationError("--anisotropic meshes in one process from scratch: leave out --adapt, --parts and --mpi")
    in_parts = arguments.parts is not None or arguments.mpi
    check_launched_with_mpi(arguments.mpi)
    # a name no format has, or a folder that cannot be written, is refused before the work, not after
    fwi_format_from_name(arguments.output)
    check_output_file(arguments.output, "-o")
    if arguments.adapt:
        format_from_name(arguments.adapt)
    comm = mpi_world(arguments.mpi)
    speaks = mpi_rank(arguments.mpi) == 0  # every rank reads and sizes the same model: one says so
    model = _model(arguments.model, arguments)
    if speaks:
        # before the sizes, which a misread model can fail: a --shape given swapped reads the same bytes into a
        # scrambled model, and only its extent (6 km wide and 20 km deep for 20 wide and 6 deep) shows it
        print(_described(model, pathlib.Path(arguments.model).name), flush=True)
    if arguments.anisotropic and model.dim == 3:  # was "layer_metric needs 2-D sizes", after the sizes
        raise GenerationError("--anisotropic meshes 2-D sections; this model is 3-D: leave it out")
    sizes = _sizes(model, arguments)
    if speaks and any(sizes.pad):
        print(_padded(sizes), flush=True)
    if arguments.adapt:
        # the old model may be in another format than the update (SEG-Y and .npy, say): it takes the reader
        # options its own format uses
        old = None
        if arguments.old_model is not None:
            try:
                old_model = _model(arguments.old_model, arguments, own_format_only=True, spacing=arguments.old_spacing)
                old = _sizes(old_model, arguments)
            except TerrameshError as error:  # "spacing must be ..." of --old-spacing read as --spacing's
                given = " with --old-spacing" if arguments.old_spacing else ""
                raise type(error)(f"the old model (--old-model{given}): {error}") from error
        mesh = adapt_mesh(read_mesh(arguments.adapt), sizes.domain, sizes, old_edge_length=old)
        done = f"adapted {arguments.adapt}: {mesh.info['added']} points added, {mesh.info['removed']} removed"
    elif in_parts:
        mesh = generate_mesh_parallel(sizes.domain, sizes, parts=arguments.parts, comm=comm, seed=seed)
        if mesh is None:  # an MPI rank other than 0: its strips went to rank 0
            return 0
        parts = len(mesh.info["parts"])
        done = f"meshed in {parts} {'strip' if model.dim == 2 else 'slab'}{'s' if parts != 1 else ''}"
    elif arguments.anisotropic:
        metric = layer_metric(sizes, gradient_refinement=arguments.gradient_refinement)
        mesh = generate_anisotropic_mesh(sizes.domain, metric, seed=seed)
        quality = metric_quality(mesh.points, mesh.cells, metric)
        done = (
            f"meshed along the layers (long and thin by design: in their metric, quality mean {quality.mean():.4f}, "
            f"min {quality.min():.4f})"
        )
    else:
        mesh = generate_mesh(sizes.domain, sizes, seed=seed)
        done = "meshed"
    output = pathlib.Path(arguments.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    write_fwi_mesh(output, mesh, sizes, velocity_on=arguments.velocity_on)
    print(summary(mesh))
    _report_timestep(mesh, sizes)
    print(f"{done}; wrote {output} in {time.perf_counter() - started:.1f} s (meshing {mesh.info['seconds']:.1f} s)")
    return 0


def _described(model, name):
    """One line on the model as read: nodes and spacing per axis, extent (metres, and in words), velocities.

    Examples
    --------
    >>> from terramesh.seismic import VelocityModel
    >>> values = np.linspace(1500.0, 4500.0, 801 * 241).reshape(801, 241)
    >>> model = VelocityModel(values, (np.arange(801) * 25.0, np.arange(-240, 1) * 25.0))
    >>> _described(model, "crop.bin")
    'model crop.bin: 801 x 241 nodes (x, z) 25 x 25 m apart, 20000 x 6000 m (20 km wide, 6 km deep), 1500..4500 m/s'
    """
    axes = "x, z" if model.dim == 2 else "x, y, z"
    extent = model.bbox[1] - model.bbox[0]
    across = " x ".join(_length(side) for side in extent[:-1])
    velocities = _speed(model.vmin) if model.vmin == model.vmax else f"{_speed(model.vmin)}..{_speed(model.vmax)}"
    return (
        f"model {name}: {' x '.join(str(n) for n in model.shape)} nodes ({axes}) "
        f"{' x '.join(f'{step:g}' for step in model.spacing)} m apart, {' x '.join(f'{side:g}' for side in extent)} m "
        f"({across} wide, {_length(extent[-1])} deep), {velocities} m/s"
    )


def _padded(sizes):
    """One line on the padded box the mesh fills: its extent, and the padding's widths."""
    extent = sizes.bbox[1] - sizes.bbox[0]
    sides, bottom = sizes.pad[:-1], sizes.pad[-1]  # (left, right) or (x-, x+, y-, y+), whole grid cells
    side = f"{sides[0]:g}" if len(set(sides)) == 1 else "/".join(f"{width:g}" for width in sides)
    widths = (
        f"{side} m on the sides and below" if set(sides) == {bottom} else f"{side} m on the sides, {bottom:g} m below"
    )
    return f"padded by {widths}: {' x '.join(f'{length:g}' for length in extent)} m"


def _length(metres):
    return f"{metres / 1000:.3g} km" if metres >= 1000 else f"{metres:.3g} m"


def _speed(value):
    return f"{value:.0f}" if value >= 100 else f"{value:.3g}"  # km/s mistaken for m/s stays readable


def _report_timestep(mesh, sizes):
    """Print the time step the mesh's edges allow (it warns when below the --dt the sizes were made for)."""
    order, courant = sizes.settings["element_order"], sizes.settings["courant"]
    limit = sizes.check_timestep(mesh)
    print(f"stable time step on the mesh's edges: {limit:.4g} s (Cr = k v dt / L at most {courant:g}, k = {order})")


def _model(path, arguments, own_format_only=False, spacing=None):
    """The velocity model at ``path`` read with the command's options (only those its format uses).

    ``spacing`` (the old model's ``--old-spacing``) stands for ``--spacing``.
    """
    names = (
        "spacing",
        "shape",
        "dtype",
        "byte_order",
        "axis_order",
        "units",
        "variable",
        "sample_format",
        "line_bytes",
    )
    if own_format_only:
        names = [name for name in names if name in READER_OPTIONS[format_of(path, None)]]
    reading = {name: getattr(arguments, name) for name in names}
    if spacing is not None:
        reading["spacing"] = spacing
    return read_velocity(path, **{name: value for name, value in reading.items() if value is not None})


def _widths(text):
    """``--pad``'s value: one width, or one per side joined by commas (spaces would take a model named after it)."""
    try:
        widths = [float(part) for part in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"widths in metres, one or one per side joined by commas, got {text!r}"
        ) from None
    return widths[0] if len(widths) == 1 else tuple(widths)


def _sizes(model, arguments):
    """The size function of the velocity ``model`` with the command's sizing options."""
    names = (
        "cells_per_wavelength", "element_order", "hmin", "hmax", "grade", "pad", "pad_velocity", "gradient_refinement",
        "velocity_window", "dt", "courant", "acquisition_size", "acquisition_radius",
    )  # fmt: skip
    options = {name: getattr(arguments, name) for name in names if getattr(arguments, name) is not None}
    if arguments.anisotropic:  # the metric refines across the layers; the sizes stay the wavelength's along them
        options.pop("gradient_refinement")
    for name in ("sources", "receivers"):
        if getattr(arguments, name) is not None:
            options[name] = _positions(getattr(arguments, name), name)
    return size_function(
        model,
        frequency=arguments.frequency,
        pad_style=arguments.pad_style,
        coarsen_pad=arguments.coarsen_pad,
        **options,
    )


def _positions(path, name):
    """Positions, one per line (x z, or x y z), metres, from a text file; MeshFormatError naming it if unreadable."""
    try:
        with warnings.catch_warnings():  # an empty file: NumPy warns, then the no-points error below says so
            warnings.filterwarnings("ignore", message="loadtxt: input contained no data", category=UserWarning)
            positions = np.loadtxt(path, ndmin=2, dtype=np.float64)
    except (OSError, ValueError) as error:
        raise MeshFormatError(f"--{name} {path}: cannot read positions (one x z or x y z per line): {error}") from None
    if positions.size == 0:
        raise MeshFormatError(f"--{name} {path}: the file has no points; give one x z (or x y z) per line")
    return positions
