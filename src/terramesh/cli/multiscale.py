"""``terramesh multiscale``: nested lon/lat boxes, each with its own size options, from a TOML file (guide §6.6).

The file holds the defaults for every box and one ``[[box]]`` table per
box, outermost first, with the options of
:func:`~terramesh.coastal.build_multiscale`'s boxes under the guide's names::

    shoreline = "coast/GSHHS_l_L1.shp"   # every box's, unless it names its own
    dem = "dem/ETOPO1_0.1.grd"
    method = "once"                      # or "merge", "grid"

    [[box]]                              # the outer box
    bbox = [-94.6, -93.2, 29.3, 30.2]    # lon_min, lon_max, lat_min, lat_max
    min_el = 1000
    max_el = 5000
    fs = 3
    g = 0.2

    [[box]]                              # an estuary inside it
    bbox = [-94.0, -93.8, 29.7, 29.9]
    shoreline = false                    # none: the 0 m contour of its DEM
    dem = "dem/CUDEM_equal.nc"
    min_el = 100
    max_el = 1000

Relative paths are taken from the file's folder, so a case travels with its
data. The command line's ``--method``, ``--itmax`` and ``--seed`` override
the file's.
"""

import inspect
import logging
import pathlib
import sys
import time

import numpy as np

from ..coastal.build import ALIASES, size_function
from ..coastal.multiscale import METHODS, build_multiscale
from ..errors import MeshFormatError
from ._options import whole_number_at_least_one
from .coastal import add_fort13_argument

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

logger = logging.getLogger("terramesh.cli")

HELP = "mesh nested lon/lat boxes, each with its own OceanMesh2D options, from a TOML file into one mesh"

# the file's top-level keys: the guide's names where it has them, and build_multiscale's
DEFAULTS = {
    "shoreline": "shoreline",
    "dem": "dem",
    "method": "method",
    "itmax": "max_iter",
    "max_iter": "max_iter",
    "seed": "seed",
    "dj_cutoff": "disjoint_cutoff",
    "disjoint_cutoff": "disjoint_cutoff",
    "dry_depth": "dry_depth",
}
FILES = ("shoreline", "dem", "thalwegs")  # keys whose strings are paths, relative to the file's folder
# a box's keys: its bbox and files, and size_function's options under their long or guide names
_SIZE_OPTIONS = {
    name
    for name, parameter in inspect.signature(size_function).parameters.items()
    if parameter.kind is parameter.KEYWORD_ONLY
}
_SIZE_OPTIONS.discard("polygon_bounds")  # shapely polygons: no TOML for them
BOX_KEYS = (
    {"bbox", "shoreline", "dem"} | _SIZE_OPTIONS | {name for name, long in ALIASES.items() if long in _SIZE_OPTIONS}
)


def add_arguments(parser):
    """Declare the subcommand's arguments."""
    parser.add_argument(
        "config",
        help="TOML file: the defaults (shoreline, dem, method, itmax, seed, dj_cutoff, dry_depth) and one [[box]]"
        " table per box, outermost first, each with its bbox (lon_min, lon_max, lat_min, lat_max, degrees) and its"
        " options under the guide's names (min_el, max_el, dis, fs, wl, slp, g, dt, ...); a box's shoreline or dem"
        " replaces the default, false for none",
    )
    parser.add_argument("--method", choices=METHODS, help="override the file's method (default once)")
    parser.add_argument("--itmax", type=whole_number_at_least_one, help="override the file's itmax (default 100)")
    parser.add_argument("--seed", type=int, help="override the file's seed (default 0)")
    parser.add_argument("-o", "--output", default="multiscale.14", help="mesh file to write (default multiscale.14)")
    add_fort13_argument(parser)
    parser.add_argument(
        "--plots",
        metavar="FOLDER",
        help="also write PNGs: each box's sizes, the mesh by quality, resolution and depth, the quality"
        " histogram, the boundary node strings",
    )


def read_config(path):
    r"""The boxes and the options of :func:`~terramesh.coastal.build_multiscale` in a TOML file.

    Parameters
    ----------
    path : str or pathlib.Path
        The file (see the module notes for its layout).

    Returns
    -------
    boxes : list of dict
        One per ``[[box]]`` table, its files' paths made absolute and
        ``false`` made ``None``.
    options : dict
        The file's defaults under :func:`~terramesh.coastal.build_multiscale`'s
        names; ``dry_depth`` under ``boundaries``.

    Raises
    ------
    MeshFormatError
        For a file that is not TOML, a key that is not an option (with the
        ones there are), no ``[[box]]``, or a box without a ``bbox``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "case.toml").write_text('dem = "dem.nc"\n[[box]]\nbbox = [0, 1, 0, 1]\nmin_el = 500\n')
    >>> boxes, options = read_config(folder / "case.toml")
    >>> boxes[0]["bbox"], boxes[0]["min_el"], options["dem"] == folder / "dem.nc"
    ([0, 1, 0, 1], 500, True)
    """
    path = pathlib.Path(path)
    if not path.exists():  # Python's own words were "[Errno 2] No such file or directory: 'case.toml'"
        raise FileNotFoundError(f"no such case file: {str(path)!r}")
    with open(path, "rb") as file:
        try:
            content = tomllib.load(file)
        except tomllib.TOMLDecodeError as error:
            raise MeshFormatError(f"{path} is not a TOML file: {error}") from error
    unknown = sorted(set(content) - set(DEFAULTS) - {"box"})
    if unknown:
        raise MeshFormatError(
            f"{path}: {_not_options(unknown)} of the file's top level, which takes {', '.join(DEFAULTS)} and the"
            " [[box]] tables; a box's size options go in its [[box]] table"
        )
    boxes = content.get("box")
    if not isinstance(boxes, list) or not boxes or not all(isinstance(box, dict) for box in boxes):
        raise MeshFormatError(f"{path}: no [[box]] tables: give one per box, outermost first, each with a bbox")
    folder = path.parent
    top = {key: value for key, value in content.items() if key != "box"}
    _refuse_twice_given(top, DEFAULTS, f"{path}: the file's top level")
    options = {
        DEFAULTS[key]: _resolved(key, value, folder, f"{path}: the file's top level") for key, value in top.items()
    }
    if "dry_depth" in options:
        options["boundaries"] = {"dry_depth": options.pop("dry_depth")}
    resolved = []
    for number, box in enumerate(boxes):
        if "bbox" not in box:
            raise MeshFormatError(f"{path}: box {number} has no bbox (lon_min, lon_max, lat_min, lat_max)")
        unknown = sorted(set(box) - BOX_KEYS)
        if unknown:
            raise MeshFormatError(
                f"{path}: box {number}: {_not_options(unknown)} of a box, which takes {', '.join(sorted(BOX_KEYS))}"
            )
        where = f"{path}: box {number}"
        _refuse_twice_given(box, ALIASES, where)
        resolved.append({key: _resolved(key, value, folder, where) for key, value in box.items()})
    return resolved, options


def _not_options(names):
    """``'a' is not an option`` or ``'a', 'b' are not options``."""
    return f"{', '.join(map(repr, names))} {'is not an option' if len(names) == 1 else 'are not options'}"


def _refuse_twice_given(table, names, where):
    """Refuse two keys of ``table`` that ``names`` maps to one option (``itmax`` and ``max_iter``, say)."""
    given = {}
    for key in table:
        given.setdefault(names.get(key, key), []).append(key)
    twice = [keys for keys in given.values() if len(keys) > 1]
    if twice:
        raise MeshFormatError(f"{where}: {' and '.join(map(repr, twice[0]))} name one option: give one of them")


def _resolved(key, value, folder, where):
    """A file's path (or, for thalwegs, a list of them) from the config's folder, ``false`` as ``None`` (no file)."""
    if key not in FILES:
        return value
    if value is False:
        return None
    if key == "thalwegs" and isinstance(value, list) and value and all(isinstance(item, str) for item in value):
        return [folder / pathlib.Path(item).expanduser() for item in value]
    if not isinstance(value, str):
        raise MeshFormatError(f"{where}: {key} must be a file's path (a string) or false for none, got {value!r}")
    return folder / pathlib.Path(value).expanduser()


def run(arguments):
    """Read the file, build, write and report the mesh; returns the exit status."""
    from .coastal import checked_outputs, contents, write_mesh, write_mesh_plots, write_tau0

    started = time.perf_counter()
    file_format = checked_outputs(arguments, [("CASE", arguments.config)])
    boxes, options = read_config(arguments.config)
    if arguments.fort13 is not None and not any(box.get("dem", options.get("dem")) for box in boxes):
        raise MeshFormatError(f"--fort13 writes tau0 from the depths, and no box of {arguments.config} has a dem")
    for name, key in (("method", "method"), ("itmax", "max_iter"), ("seed", "seed")):
        if getattr(arguments, name) is not None:
            options[key] = getattr(arguments, name)
    mesh = build_multiscale(boxes, **options)
    has_depth = bool(np.isfinite(mesh.depth).any())
    output = write_mesh(mesh, arguments.output)
    print(contents(mesh, file_format, has_depth=has_depth, no_dem="no box has a dem"))
    if arguments.fort13 is not None:
        write_tau0(mesh, arguments.fort13)
    if mesh.info.get("dt") is not None:
        print(f"CFL-limited for a time step of {mesh.info['dt']:.3g} s (the smallest of the boxes')")
        largest = mesh.info.get("largest_courant")
        if largest is not None:
            print(f"largest Courant number on the mesh's shortest edges: {largest:.2f}")
    seconds = mesh.info["timings"]["total"]
    print(f"wrote {output} in {time.perf_counter() - started:.1f} s (meshing {len(boxes)} boxes {seconds:.1f} s)")
    if arguments.plots:
        folder = pathlib.Path(arguments.plots)
        folder.mkdir(parents=True, exist_ok=True)
        logger.info("drawing the pictures into %s/", folder)
        for number, sizes in enumerate(mesh.info["sizes"]):
            sizes.plot(folder / f"size_box{number}.png")
        write_mesh_plots(folder, mesh, has_depth=has_depth)
    return 0
