"""From a bbox, a shoreline and a DEM to a graded coastal mesh in one call (the guide's §5 workflow)."""

import logging
import numbers
import time
from dataclasses import dataclass, field

import numpy as np
import shapely

from .._kernels.precompile import compile_ahead_on_first_run
from ..cleanup.clean import clean
from ..cleanup.fix_mesh import default_merge_tolerance, fix_mesh, nearest_used_vertex
from ..errors import GeometryError, SizingError, checked_number, muted_warnings, warn_user
from ..generation.distmesh import generate_mesh
from ..generation.mesh_checks import REACHED_MAX_ITER
from ..generation.options import BOUNDARY_TOLERANCE
from ..mesh.topology import checked_fixed_points
from ..sizing.gradation import DEFAULT_GRADE, checked_grade, lift_to_floor, limit_gradient
from .boundaries import checked_boundary_options, make_boundaries
from .dem import DEM, check_dem_cover
from .grid import GeoGrid, as_lonlat_box
from .messages import lonlat_messages
from .projection import from_mercator, to_mercator
from .shoreline import Shoreline, region_of
from .sizes import (
    COURANT,
    ETA,
    bound_sizes,
    cfl_floor,
    cfl_timestep,
    channel_size,
    distance_to_coastline,
    nearshore_mask,
    shoreline_size,
    slope_size,
    water_mask,
    wavelength_size,
)
from .sizes.slope import SLOPE_CUTOFF_DEPTH

__all__ = ["build", "size_function", "CoastalSizes", "ALIASES"]

logger = logging.getLogger("terramesh.coastal")

ALIASES = {
    "min_el": "min_edge_length",
    "h0": "min_edge_length",
    "max_el": "max_edge_length",
    "max_el_ns": "max_edge_length_nearshore",
    "dis": "distance_rate",
    "fs": "feature_size",
    "wl": "wavelength",
    "slp": "slope",
    "fl": "filter_lengths",
    "ch": "channels",
    "g": "grade",
    "dj_cutoff": "disjoint_cutoff",
    "itmax": "max_iter",
    "pfix": "fixed_points",
}
"""The OceanMesh2D guide's option names, each mapped to terramesh's long name."""

BREAK_COURANT = "vertices break Courant"  # the time-step check's words, by which a caller mutes it
CHANNEL_ELEMENTS_PER_SLOPE = 30.0  # alpha_slp of the slope function under the channel one when slp is not given


@dataclass
class CoastalSizes:
    """A coastal size function on its grid, with the pieces it was made of.

    Attributes
    ----------
    grid : GeoGrid
        The Mercator grid (see :mod:`terramesh.coastal.grid`).
    sizes : ndarray, shape (nx, ny)
        The final edge length, ground metres: the minimum of ``fields``,
        bounded, graded and CFL-limited.
    fields : dict of str to ndarray of float32
        Each size function that took part, ground metres (``inf`` where it
        sets no limit), by the guide's short name (``"dis"``, ``"fs"``,
        ``"wl"``, ``"slp"``, ``"ch"``), in single precision: for looking
        at (``sizes`` is their minimum in double precision).
    depth : ndarray or None
        Depth on the grid, metres, positive down (None without a DEM).
    water : ndarray of bool
        Grid nodes in the water.
    dt : float or None
        Time step the sizes were CFL-limited for, seconds.
    shoreline : Shoreline
    dem : DEM or None
    courant, eta : float
        The Courant number and free-surface amplitude (metres) of the CFL limit.
    """

    grid: GeoGrid
    sizes: np.ndarray
    fields: dict = field(default_factory=dict)
    depth: np.ndarray | None = None
    water: np.ndarray | None = None
    dt: float | None = None
    shoreline: Shoreline | None = None
    dem: DEM | None = None
    courant: float = COURANT
    eta: float = ETA

    def check_timestep(self, mesh):
        """The largest Courant number of ``mesh`` at the ``dt`` these sizes were made for; warns above ``courant``.

        Measured as :func:`terramesh.coastal.courant_number` does, on each
        vertex's shortest edge with the mesh's depths. The sizes allow for
        a DistMesh mesh's short edges; a coastline can still force shorter
        ones (an island's ring, a narrow inlet), and
        :func:`terramesh.coastal.enforce_timestep` removes the vertices
        that break the limit.

        Parameters
        ----------
        mesh : Mesh
            A mesh of these sizes with ``mesh.depth`` (longitude/latitude
            points, as :func:`build` returns them).

        Returns
        -------
        float or None
            The largest Courant number; None when the sizes have no ``dt``
            or the mesh no finite depth.

        Warns
        -----
        TerrameshWarning
            If it is above ``courant``, with the number of vertices and the remedy.
        """
        from .timestep import courant_number

        if self.dt is None or not np.isfinite(mesh.depth).any():
            return None
        numbers = courant_number(mesh, self.dt, eta=self.eta)
        largest = float(np.nanmax(numbers))
        if largest > self.courant:
            over = int(np.sum(numbers > self.courant))
            warn_user(
                f"{over} of the mesh's {mesh.n_points} {BREAK_COURANT} {self.courant:g} at dt = {self.dt:.4g} s "
                f"(up to {largest:.2f}): their shortest edges are shorter than the sizes allow for; "
                f"tm.coastal.enforce_timestep(mesh, {self.dt:.4g}) removes them (terramesh post --dt {self.dt:.4g} "
                "with the file written)",
            )
        return largest

    def size_grid(self):
        """The sizes as a :class:`~terramesh.sizing.SizeGrid` on the Mercator plane (what the generator uses)."""
        return self.grid.size_grid(self.sizes)

    def plot(self, path=None, *, name=None):
        """Draw the final size field (``name=None``) or one of ``fields`` (:func:`~terramesh.plot.plot_size_field`)."""
        from ..plot.sizes import plot_size_field

        values = self.sizes if name is None else self.fields[name]
        title = "final size function" if name is None else f"size function {name}"
        coastline = None if self.shoreline is None else self.shoreline.coastline
        return plot_size_field(self.grid, values, path, title=title, coastline=coastline)


WET_SHARE = 0.5
"""Share of the shoreline's water nodes below 0 m in the DEM under which :func:`size_function` warns of a DEM of depths.

Measured: 98 % of the Gulf of Maine's water on ETOPO1, 2 % with its sign turned."""


_GUIDE_HINTS = {
    "q": " (the guide's New York example passes the grade as 'q'; edgefx's option is g)",
    "R": " (R is the guide's variable for the fs option)",
}
"""What to say of names from the guide's examples that are not options of its functions."""


def _resolve_aliases(options, given):
    """Fold the guide's short names into ``given`` (long names); unknown, doubled or foreign names raise TypeError.

    A foreign name is one of the guide's that ``given`` has no slot for
    (``itmax`` is the generator's, not the size function's): ignoring it
    would drop what the user asked for without a word.
    """
    for short, value in options.items():
        if short not in ALIASES:
            known = ", ".join(sorted(name for name in ALIASES if ALIASES[name] in given))
            hint = _GUIDE_HINTS.get(short, "")
            raise TypeError(
                f"unknown option {short!r}{hint}; the guide's names accepted are: {known} (and build's dj_cutoff, "
                "itmax, pfix), besides terramesh's own (help(terramesh.coastal.size_function) lists them)"
            )
        long = ALIASES[short]
        if long not in given:
            raise TypeError(f"{short!r} is an option of build (the mesh), not of the size function")
        if given.get(long) is not None:
            raise TypeError(f"{short!r} and {long!r} are the same option; give one")
        given[long] = value
    return given


def _metres(name, value, default=None):
    """``value`` as a positive number of metres (``default`` for None; inf only when that is the default)."""
    if value is None and default is not None:
        return default
    if default == np.inf and value == np.inf:
        return np.inf
    return checked_number(value, f"{name} must be a positive number of metres", SizingError, minimum=0, strict=True)


_DEPTH_ROW_OPTIONS = {"max_edge_length": "max_el", "wavelength": "wl", "slope": "slp"}
"""Options OceanMesh2D also takes as rows ``[value, z_min, z_max]``, one value per depth range."""


def _refuse_depth_rows(options):
    """Refuse OceanMesh2D's per-depth rows of max_el, wl or slp, naming what terramesh takes for them."""
    for name, short in _DEPTH_ROW_OPTIONS.items():
        value = options[name]
        if value is None or isinstance(value, (str, bytes)) or np.ndim(value) == 0:
            continue
        raise SizingError(
            f"{name} ({short}) takes one number here, got {value!r}: OceanMesh2D's rows [value, z_min, z_max] "
            "bound the sizes by depth, which depth_bounds=[(min_size, max_size, min_depth, max_depth), ...] does "
            "(metres, depths positive down)"
        )


def as_shoreline(shoreline, dem, bbox, min_edge_length, minimum_island_area, require_land):
    """The :class:`Shoreline` for ``bbox``: one given (checked to be cut to that box), read, or the DEM's 0 m contour.

    ``shoreline`` is a Shoreline, a shapely geometry, a file or None (then
    the 0 m contour of ``dem``); ``min_edge_length`` is in metres.
    """
    if isinstance(shoreline, Shoreline):
        # the mesh is the shoreline's water: one cut to another box meshed that box, off the size grid
        box, region, _ = region_of(bbox)
        advice = "read it for the same box, or give its file"
        if not np.allclose(shoreline.bbox, box):
            raise GeometryError(f"the Shoreline was cut to the bbox {tuple(shoreline.bbox)}, not {box}: {advice}")
        if shapely.hausdorff_distance(region, shoreline.region) > 1e-9:
            raise GeometryError(f"the Shoreline was cut to another region than the one asked for: {advice}")
        return shoreline
    options = dict(minimum_island_area=minimum_island_area, require_land=require_land)
    if shoreline is None:
        if dem is None:
            raise GeometryError("give a shoreline (shapefile) or a DEM to take the 0 m contour from")
        logger.info("shoreline: 0 m contour of the DEM")
        return Shoreline.from_dem(dem, bbox, min_edge_length, **options)
    if isinstance(shoreline, shapely.Geometry):
        return Shoreline(shoreline, bbox, min_edge_length, **options)
    return Shoreline.read(shoreline, bbox, min_edge_length, **options)


def size_function(
    bbox,
    shoreline=None,
    dem=None,
    *,
    min_edge_length=None,
    max_edge_length=None,
    max_edge_length_nearshore=None,
    distance_rate=None,
    feature_size=None,
    wavelength=None,
    slope=None,
    filter_lengths=None,
    channels=None,
    thalwegs=None,
    depth_bounds=None,
    polygon_bounds=None,
    grade=None,
    dt=None,
    courant=0.5,
    eta=2.0,
    minimum_island_area=None,
    grid_spacing=None,
    require_land=True,
    **guide_names,
):
    """The OceanMesh2D size function (guide §3-4) on a Mercator grid over the box, in ground metres.

    Each requested size function is computed on the grid (see
    :mod:`terramesh.coastal.sizes` for the formulas), their minimum is
    bounded (``max_el_ns`` near the coast, then ``h0`` and ``max_el``),
    graded (eq. 9: ``g`` on the ground, on the Mercator grid at ``g cos(lat)``
    per row), and
    finally raised where it is too small for the time step ``dt``
    (eq. 10-12), where the floor of ``dt``
    (:func:`~terramesh.coastal.sizes.cfl_floor`, which allows for a mesh's
    shortest edges) is first graded upward
    (:func:`~terramesh.sizing.limit_gradient_up`), so that the sizes keep
    the grade and the mesh can follow them. CFL limiting comes last because
    ``dt`` is the hard requirement: it raises sizes, coarsening the mesh
    where the asked resolution and ``dt`` disagree.

    Parameters
    ----------
    bbox : sequence of 4 float or shapely.Polygon
        ``(lon_min, lon_max, lat_min, lat_max)`` in degrees (the guide's
        order), or a polygon in longitude/latitude.
    shoreline : str, os.PathLike, Shoreline or shapely geometry, optional
        Shapefile or GeoPackage of land polygons (any CRS), a
        :class:`Shoreline` cut to the same ``bbox``, or land polygons in
        lon/lat. Default: the DEM's 0 m contour.
    dem : str, os.PathLike or DEM, optional
        NetCDF or GeoTIFF elevation, metres, positive up (a :class:`DEM`
        must overlap ``bbox``). Needed by ``wavelength``, ``slope``,
        ``channels`` and ``dt``.
    min_edge_length : float
        ``h0``/``min_el``: smallest edge length, metres.
    max_edge_length : float, optional
        ``max_el``: largest edge length, metres (default: no limit).
    max_edge_length_nearshore : float, optional
        ``max_el_ns``: largest edge length near the coast, metres.
    distance_rate : float, optional
        ``dis``: eq. 2's growth of the size with distance from the coast
        (metres per metre). Exclusive with ``feature_size``.
    feature_size : float, optional
        ``fs``: eq. 3-4's ``R``, elements across a feature.
    wavelength : float, optional
        ``wl``: eq. 5-6's elements per M2 wavelength.
    slope : float, optional
        ``slp``: eq. 7's ``alpha_slp``.
    filter_lengths : array_like, optional
        ``fl``: band-pass filter lengths ``[fl_low, fl_high]`` in metres
        for the slope function (default eq. 8).
    channels : float, optional
        ``ch``: percentile of the slope function given to channels (the
        slope function without its 100 m cut-off, with ``slope``'s
        ``alpha_slp``, or 30 when ``slope`` is not given).
    thalwegs : path, (k, 2) arrays, shapely lines, or a list of them, optional
        Channel polylines in lon/lat, or a file of them such as OceanMesh2D's
        ``.mat`` (default: found in the DEM); see
        :func:`~terramesh.coastal.sizes.channels.thalweg_polylines`.
    depth_bounds : sequence of (min_size, max_size, min_depth, max_depth), optional
        Size bounds in metres by depth range (metres, positive down), as
        OceanMesh2D's ``max_el`` rows with depths: e.g. ``[(None, 2e3, 0,
        50)]`` caps the sizes at 2 km where the water is under 50 m deep.
        Needs a DEM. Applied with the other bounds, before grading (see
        :func:`~terramesh.coastal.sizes.bound_sizes`).
    polygon_bounds : sequence of (polygon, min_size, max_size), optional
        Size bounds in metres inside shapely polygons in lon/lat degrees
        (``None``: no bound), applied likewise.
    grade : float, optional
        ``g``: largest size gradient (eq. 9); default
        :data:`~terramesh.sizing.DEFAULT_GRADE` (0.2, OceanMesh2D's default
        and the low end of the guide's 0.2-0.3); ``inf`` turns the
        grading off.
    dt : float, optional
        Time step the mesh must be stable for, seconds; 0 picks one (eq. 12).
    courant : float, optional
        Target Courant number of the CFL limit.
    eta : float, optional
        Free-surface amplitude of eq. 11, metres.
    minimum_island_area : float, optional
        Islands smaller than this are dropped, m² (default: see :class:`Shoreline`).
    grid_spacing : float, optional
        Ground spacing of the size grid, metres (default ``min_edge_length``).
    require_land : bool, optional
        False: a box with no land is open water (see :class:`Shoreline`).
        There ``dis``, ``fs`` and ``max_el_ns`` have no coast to act on, so
        ``max_el`` and the DEM's functions (``wl``, ``slp``, ``ch``) set the
        sizes, and ``dt=0`` cannot be used.
    **guide_names
        The same options under the guide's names: ``min_el``, ``h0``,
        ``max_el``, ``max_el_ns``, ``dis``, ``fs``, ``wl``, ``slp``, ``fl``,
        ``ch``, ``g`` (see :data:`ALIASES`).

    Returns
    -------
    CoastalSizes

    Raises
    ------
    SizingError
        For a missing ``min_edge_length``, both ``dis`` and ``fs``, options
        that need a DEM without one, or no size function and no finite
        ``max_el``.

    Examples
    --------
    The distance function (``dis``) alone, with land from a shapely polygon
    in longitude/latitude and no DEM: sizes in ground metres between
    ``min_el`` and ``max_el``, growing away from the coast:

    >>> import shapely, terramesh as tm
    >>> land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    >>> sizes = tm.coastal.size_function((0, 0.3, 0, 0.3), land, min_el=2000, max_el=6000, dis=0.3)
    >>> list(sizes.fields), sizes.dt, sizes.depth is None
    (['dis'], None, True)
    >>> bool(2000 <= sizes.sizes.min() and sizes.sizes.max() <= 6000)
    True
    """
    options = _resolve_aliases(
        guide_names,
        dict(
            min_edge_length=min_edge_length,
            max_edge_length=max_edge_length,
            max_edge_length_nearshore=max_edge_length_nearshore,
            distance_rate=distance_rate,
            feature_size=feature_size,
            wavelength=wavelength,
            slope=slope,
            filter_lengths=filter_lengths,
            channels=channels,
            grade=grade,
        ),
    )
    _refuse_depth_rows(options)
    h0 = options["min_edge_length"]
    if h0 is None:
        raise SizingError("give min_edge_length (the guide's min_el or h0), in metres")
    h0 = _metres("min_edge_length", h0)
    max_el = _metres("max_edge_length", options["max_edge_length"], np.inf)
    if h0 > max_el:  # refused before the shoreline is read, not after (bound_sizes says it too)
        raise SizingError(f"min_edge_length {h0:g} exceeds max_edge_length {max_el:g}")
    grade = DEFAULT_GRADE if options["grade"] is None else checked_grade(options["grade"])
    if 1 <= grade < np.inf:
        warn_user(
            f"g = {grade:g} lets the size grow by {grade:g} m per metre: the guide's g is a fraction "
            f"(0.2 for 20 %); for {grade:g} % give g = {grade / 100:g}",
        )
    if options["filter_lengths"] is not None and options["slope"] is None and options["channels"] is None:
        raise SizingError(
            "filter_lengths (fl) filter the bathymetry of the slope function: give slope (slp) or channels (ch)"
        )
    if thalwegs is not None and options["channels"] is None:
        raise SizingError("thalwegs are the channel function's (ch): give channels (ch), its percentile, too")
    needs_dem = [name for name in ("wavelength", "slope", "channels") if options[name] is not None]
    if dt is not None:
        if not isinstance(dt, numbers.Real) or isinstance(dt, bool):  # "10" was taken, g="0.2" refused
            raise SizingError(f"dt must be a number of seconds (0 chooses one), got {dt!r}")
        needs_dem.append("dt")
    if depth_bounds is not None:
        needs_dem.append("depth_bounds")
    if isinstance(bbox, shapely.Geometry):
        lon_min, lat_min, lon_max, lat_max = bbox.bounds
        box = as_lonlat_box((lon_min, lon_max, lat_min, lat_max))
    else:
        box = as_lonlat_box(bbox)
    # the grid first: its node count refuses a min_el in kilometres (0.25 for 250 m) at once, where resampling
    # the South Island's coast at 0.125 m took 100 s and 8 GB before the grid's check was reached
    grid = GeoGrid(box, h0 if grid_spacing is None else grid_spacing)
    compiled = compile_ahead_on_first_run(["coastal"])  # size_function, then generate_mesh: the guide's two steps
    timings = {"compile ahead": compiled["seconds"]} if compiled else {}
    started = time.perf_counter()
    if isinstance(dem, DEM):
        check_dem_cover(dem, box)  # as DEM.read does for a path
    elif dem is not None:
        dem = DEM.read(dem, box)
    if needs_dem and dem is None:
        verb = "needs" if len(needs_dem) == 1 else "need"
        raise SizingError(f"{', '.join(needs_dem)} {verb} a DEM (depths), and none was given")
    shore = as_shoreline(shoreline, dem, bbox, h0, minimum_island_area, require_land)
    timings["read"] = time.perf_counter() - started
    logger.info("read the shoreline%s in %.1f s", "" if dem is None else " and the DEM", timings["read"])

    step = time.perf_counter()
    logger.info("size grid %d x %d (%.0f m)", *grid.shape, grid.ground_step.max())
    open_water = shore.land.is_empty
    distance = np.full(grid.shape, np.inf) if open_water else distance_to_coastline(grid, shore.coastline)
    water = water_mask(grid, shore.water)
    depth = None
    if dem is not None:
        depth = dem.sample_grid(grid.lon, grid.lat)
        np.negative(depth, out=depth)  # to depths, without a second grid
        wet = np.count_nonzero((depth > 0) & water)
        if not wet and shoreline is not None and np.any(depth > 0):
            # below 0 m only under the shoreline's land: a grid of depths read as elevation, most often
            raise SizingError(
                f"none of the shoreline's water lies below 0 m in the DEM ({dem.source}), only its land does: "
                f"{dem.sign_advice()}"
            )
        if not wet:
            raise SizingError(f"the DEM ({dem.source}) has no water (elevation below 0 m) in the box {box}")
        if shoreline is not None and wet < WET_SHARE * np.count_nonzero(water):
            # a grid of depths (positive down) read as elevation: the water is "land" to every depth function
            warn_user(
                f"only {wet / np.count_nonzero(water):.0%} of the shoreline's water lies below 0 m in the DEM "
                f"({dem.source}): {dem.sign_advice()}",
            )
        resolution = float(np.max(dem.resolution))
        if shoreline is None and h0 < resolution:
            warn_user(
                f"min_edge_length {h0:g} m is finer than the DEM's resolution ({resolution:.0f} m), "
                "which the shoreline is contoured from: it has no detail at that scale",
            )
    # One grid array, the running minimum of the fields, from here to the CFL limit, changed in place: at 39M
    # nodes (§5.3) each new array cost 0.05-0.7 s in page faults and copies, and each field is kept for the
    # user in single precision as soon as it is folded in (3.40 GB at the peak there when all were kept whole).
    # The first field folded in is that array (None until then)
    sizes = None
    fields = {}
    early_dt = None
    nearshore = None
    if open_water:
        logger.info("open water: no coastline in the box for dis, fs or max_el_ns to act on")
    else:
        if options["distance_rate"] is not None or options["feature_size"] is not None:
            coast_field = shoreline_size(
                grid,
                distance,
                water,
                min_edge_length=h0,
                rate=options["distance_rate"],
                elements_per_feature=options["feature_size"],
                fallback_rate=grade if np.isfinite(grade) else DEFAULT_GRADE,  # OceanMesh2D's: h0 + g d
            )
            if dt is not None and float(dt) == 0:
                early_dt = cfl_timestep(coast_field, depth, courant=courant, eta=eta, min_edge_length=h0)
            sizes = _fold(sizes, fields, "fs" if options["feature_size"] is not None else "dis", coast_field)
            del coast_field
        if options["max_edge_length_nearshore"] is not None:
            nearshore = nearshore_mask(grid, distance)
    del distance
    if options["wavelength"] is not None:
        sizes = _fold(sizes, fields, "wl", wavelength_size(depth, elements_per_wavelength=options["wavelength"]))
    if options["slope"] is not None or options["channels"] is not None:
        # eq. 7 without its 100 m cut-off, on land too: the channel function needs it in the shallows and
        # overland, where channels are
        elements_per_slope = CHANNEL_ELEMENTS_PER_SLOPE if options["slope"] is None else options["slope"]
        slope_field = slope_size(
            grid, depth, elements_per_slope=elements_per_slope, filter_lengths=options["filter_lengths"], min_depth=None
        )
        if options["channels"] is not None:
            channels = channel_size(grid, depth, slope_field, percentile=options["channels"], thalwegs=thalwegs)
        if options["slope"] is not None:
            slope_field[~(depth >= SLOPE_CUTOFF_DEPTH)] = np.inf
            sizes = _fold(sizes, fields, "slp", slope_field)
        del slope_field
        if options["channels"] is not None:
            sizes = _fold(sizes, fields, "ch", channels)
            del channels
    if sizes is None:  # no field: max_el alone bounds the sizes (refused below when it does not)
        sizes = np.full(grid.shape, np.inf)
    timings["size functions"] = time.perf_counter() - step
    logger.info("size functions %s in %.1f s", ", ".join(fields) or "(none)", timings["size functions"])

    step = time.perf_counter()
    if not np.isfinite(sizes).any() and not np.isfinite(max_el):
        # name each function asked for that came out inf everywhere, and why: "no size function was asked for"
        # was said of a flat sea floor's slp
        unconstrained = [f"{name} {_UNCONSTRAINED.get(name, 'is inf everywhere')}" for name in fields]
        if open_water:
            unconstrained.insert(0, f"the box {box} is open water, where dis and fs have no coast to act on")
        if not unconstrained:
            raise SizingError("no size function was asked for (dis, fs, wl, slp, ch) and max_el is unbounded")
        others = "a DEM function (wl, slp, ch)" if open_water else "another size function"
        raise SizingError(f"{'; '.join(unconstrained)}: give max_el, or {others}")
    sizes = bound_sizes(
        sizes,
        min_edge_length=h0,
        max_edge_length=max_el if np.isfinite(max_el) else None,
        max_edge_length_nearshore=options["max_edge_length_nearshore"],
        nearshore=nearshore,
        depth=depth,
        depth_bounds=depth_bounds,
        polygon_bounds=polygon_bounds,
        grid=grid,
        overwrite_sizes=True,
    )
    unbounded = ~np.isfinite(sizes)
    sizes[unbounded] = np.max(sizes, where=~unbounded, initial=-np.inf)
    chosen_dt, floor = None, None
    if dt is not None:
        chosen_dt = float(dt) if float(dt) != 0 else early_dt
        if not chosen_dt:  # no coast field to choose it from
            needs = f"a coastline, and the box {box} is open water" if open_water else "dis or fs"
            raise SizingError(f"dt = 0 (choose the time step, eq. 12) keeps the coast's resolution: it needs {needs}")
        floor = cfl_floor(depth, dt=chosen_dt, courant=courant, eta=eta)
    # ground sizes graded on the Mercator grid at g cos(lat) per row: a ground metre is sec(lat) Mercator
    # metres, so this is the grade g on the ground, along the parallels and the meridians alike
    ground_grade = grid.ground_grade(grade)
    sizes = limit_gradient(sizes, grid.step, ground_grade, overwrite_values=True)
    if floor is not None:
        # the floor graded upward, as the sizes were: the bare floor can rise faster than the grade (with the
        # depth at a shelf break), and the mesh's edges beside such a jump come out shorter than the floor
        too_coarse = _too_coarse(sizes, water, grid)
        lift_to_floor(sizes, floor, grid.step, ground_grade)
        _check_floor_fits(sizes, too_coarse, water, grid, chosen_dt)
        _warn_floor_past_max(sizes, water, max_el, chosen_dt)
        logger.info("CFL-limited for dt = %.3g s", chosen_dt)
    timings["bound, grade, cfl"] = time.perf_counter() - step
    logger.info("sizes bounded and graded in %.1f s", timings["bound, grade, cfl"])
    result = CoastalSizes(grid, sizes, fields, depth, water, chosen_dt, shore, dem, courant=courant, eta=eta)
    result.timings = timings
    return result


MIN_ELEMENTS_ACROSS = 4
"""Elements across the box below which the CFL floor of ``dt`` leaves no mesh to speak of, and is refused."""


def _too_coarse(sizes, water, grid):
    """Whether ``sizes`` (ground metres) over half the water leave the box fewer than ``MIN_ELEMENTS_ACROSS``.

    Counted, not a median: on the guide's §5.3 grid (39 million nodes) a
    median of the water's sizes took 1.3 s, a count 0.1 s.
    """
    return np.count_nonzero((sizes > _across(grid) / MIN_ELEMENTS_ACROSS) & water) > 0.5 * np.count_nonzero(water)


def _across(grid):
    """The box's narrower extent on the ground, metres (its parallels' narrowest, or its meridians)."""
    return min((grid.x.size - 1) * float(grid.ground_step.min()), float(np.sum(grid.ground_step[:-1])))


def _warn_floor_past_max(sizes, water, max_el, dt):
    """Warn where the CFL floor of ``dt`` lifted ``sizes`` (ground metres) in the ``water`` past ``max_el``.

    Said, not refused: the step asked for rules the sizes, as the guide's
    CFL limit does; a 300 s step over the Gulf of Maine's shelf gave 39 km
    edges where 20 km was the most asked for, and nothing said so.
    """
    if not np.isfinite(max_el):
        return
    over = (sizes > max_el * (1.0 + 1e-9)) & water
    count = int(np.count_nonzero(over))
    if count:
        warn_user(
            f"the CFL limit of dt = {dt:g} s lifted the sizes past max_el = {max_el:g} m over "
            f"{100.0 * count / max(int(np.count_nonzero(water)), 1):.3g} % of the water (up to "
            f"{float(np.max(sizes, where=over, initial=0.0)) / 1e3:.3g} km): a smaller dt keeps them within it"
        )


def _check_floor_fits(sizes, too_coarse_before, water, grid, dt):
    """Refuse a ``dt`` whose CFL floor, graded up into ``sizes`` (ground metres), leaves the box few elements across.

    Only where the floor made them so (``too_coarse_before`` is
    :func:`_too_coarse` before it): sizes large of themselves (``wl``
    without ``max_el`` offshore) are not the step's doing.

    A step in minutes, not seconds, raised every size past the box: ``dt=600``
    over the Gulf of Maine asked for 273-379 km elements in a 500 km box,
    and the clean-up failed with "clean left no cell"; ``dt=300`` gave a
    mesh of 26 vertices, warned of only by the area it lost.
    """
    if too_coarse_before or not _too_coarse(sizes, water, grid):
        return
    typical = float(np.median(sizes[water]))  # for the message only
    raise SizingError(
        f"dt = {dt:g} s asks for elements of {typical / 1e3:.3g} km or more over half the water (the CFL limit, "
        f"eq. 10-11, graded), and the box is {_across(grid) / 1e3:.3g} km across: fewer than {MIN_ELEMENTS_ACROSS} "
        "elements. Is dt in seconds? Lower it (the floor is proportional to it)"
    )


def repaired_and_cleaned(mesh, domain, *, disjoint_cutoff, clean_quality, fixed_points=None):
    """A generated mesh made valid (:func:`~terramesh.cleanup.fix_mesh`) and, unless ``clean_quality`` is None, cleaned.

    :func:`~terramesh.cleanup.clean` begins with fix_mesh's repairs and its
    report counts them, so it runs alone (fix_mesh before it repeated them:
    0.4 s of §5.3's 2 s). ``fixed_points`` ((k, 2) Mercator metres, or
    None) are vertices that stay: clean keeps them; the returned mesh's
    ``info["fixed_points"]`` is the vertex of each (-1 for one the repairs
    removed, with a warning).
    """
    if clean_quality is not None:
        return clean(
            mesh, min_quality=clean_quality, domain=domain, disjoint_cutoff=disjoint_cutoff, fixed_points=fixed_points
        )
    mesh = fix_mesh(mesh, disjoint_cutoff=disjoint_cutoff)
    if fixed_points is not None:  # fix_mesh moves no vertex but may merge, drop and renumber them
        index, distance = nearest_used_vertex(fixed_points, mesh.points, mesh.cells)
        index[distance > default_merge_tolerance(mesh.points)] = -1
        if np.any(index < 0):
            warn_user(
                f"fix_mesh removed {int(np.sum(index < 0))} of the {len(index)} fixed points: they were in small"
                " disconnected parts (below disjoint_cutoff); info['fixed_points'] is -1 for them",
            )
        mesh.info["fixed_points"] = index
    return mesh


def _checked_fixed_points(fixed_points, shoreline, domain):
    """The user's fixed points as (lon/lat, Mercator) (k, 2) arrays, or ``(None, None)``; else a GeometryError.

    Longitudes are taken by whole turns onto the box (a box in 0..360 takes
    -170 as 190). Points must lie in the box and in the water (the domain),
    both within :data:`~terramesh.generation.options.BOUNDARY_TOLERANCE`
    of ``h0`` (the generator's own tolerance is no smaller), and farther
    apart than that (the generator would merge them).
    """
    if fixed_points is None:
        return None, None
    lonlat = checked_fixed_points(fixed_points, 2, GeometryError, units="lon/lat degrees, ")
    region = shoreline.region
    inside = shapely.intersects_xy(region, lonlat[:, 0], lonlat[:, 1])
    for turn in (360.0, -360.0):  # the box may be in 0..360 and the points in -180..180, or the other way
        shifted = ~inside & shapely.intersects_xy(region, lonlat[:, 0] + turn, lonlat[:, 1])
        lonlat[shifted, 0] += turn
        inside |= shifted
    if not inside.all():
        first = int(np.flatnonzero(~inside)[0])
        lon, lat = lonlat[first].tolist()
        raise GeometryError(
            f"{int(np.sum(~inside))} of the {len(lonlat)} fixed points lie outside the box {shoreline.bbox}, the first"
            f" (fixed point {first}) at lon {lon!r}, lat {lat!r}"
        )
    mercator = np.column_stack(to_mercator(lonlat[:, 0], lonlat[:, 1]))
    tolerance = BOUNDARY_TOLERANCE * shoreline.min_edge_length
    on_land = domain.distance(mercator) > tolerance
    if on_land.any():
        first = int(np.flatnonzero(on_land)[0])
        lon, lat = lonlat[first].tolist()
        raise GeometryError(
            f"{int(on_land.sum())} of the {len(lonlat)} fixed points lie on land (not in the water to mesh), the"
            f" first (fixed point {first}) at lon {lon!r}, lat {lat!r}, "
            f"{domain.distance(mercator[first : first + 1])[0]:.4g} Mercator metres from the water"
        )
    if len(mercator) > 1:
        from scipy.spatial import cKDTree

        pairs = cKDTree(mercator).query_pairs(tolerance, output_type="ndarray")
        if len(pairs):
            first, second = np.sort(pairs[np.lexsort(pairs.T[::-1])[0]])
            raise GeometryError(
                f"fixed points {first} and {second} ({lonlat[first].tolist()}, {lonlat[second].tolist()}) are closer"
                f" than {tolerance:.3g} m: one mesh vertex cannot be both; give one"
            )
    return lonlat, mercator


_UNCONSTRAINED = {
    "slp": (
        "is inf everywhere: the slope function is off where the water is shallower than 100 m (eq. 7's cut-off)"
        " and where the filtered sea floor is flat, which is every node of the grid"
    ),
    "ch": "is inf everywhere: no channel (thalweg) lies in the box",
}
"""Why a size function asked for can come out ``inf`` (no constraint) everywhere, by its short name.

The others cannot, with a coast in the box: ``dis`` and ``fs`` (the distance
function where there is no medial axis) are finite at every node, ``wl`` in
the water, which the DEM is checked to have."""


def _fold(sizes, fields, name, values):
    """Take the field ``values`` into the running minimum ``sizes``, returned; keep it in ``fields`` as float32.

    The first field (``sizes`` None) becomes the running minimum itself, so
    the caller gives up ``values``: a grid of ``inf`` to take it into cost
    0.4 s of page faults on the guide's §5.3 grid. Single precision (7
    digits, 0.1 mm in 1 km) is ample for looking at a field, and halves
    what a :class:`CoastalSizes` holds; the minimum is taken in double
    precision.
    """
    fields[name] = values.astype(np.float32)
    if sizes is None:
        return np.require(values, dtype=np.float64, requirements=["C", "W", "O"])
    np.minimum(sizes, values, out=sizes)
    return sizes


def build(
    bbox,
    shoreline=None,
    dem=None,
    *,
    disjoint_cutoff=0.01,
    clean_quality=0.5,
    max_iter=100,
    seed=0,
    parts=None,
    comm=None,
    boundaries=True,
    fixed_points=None,
    **size_options,
):
    """Mesh the water in a box: a coastal mesh in one call (the guide's §5 workflow).

    Builds the size function (:func:`size_function`, which takes every
    option of the guide under its long or short name), meshes the water on
    the Mercator plane (conformal, so the triangles are isotropic in metres
    at every latitude), makes the mesh valid
    (:func:`terramesh.cleanup.fix_mesh`, deleting parts smaller than
    ``disjoint_cutoff``) and cleans it (:func:`terramesh.cleanup.clean`),
    returns the points to longitude/latitude and samples the DEM's depth
    (bilinear) at the vertices. Points given as ``fixed_points`` (the
    guide's ``pfix``: tide gauges, river inflow nodes) are vertices of the
    mesh at exactly the coordinates given.

    Parameters
    ----------
    bbox, shoreline, dem
        See :func:`size_function`.
    disjoint_cutoff : float, optional
        ``dj_cutoff``: parts with fewer than this fraction of the cells are deleted.
    clean_quality : float or None, optional
        After generation, :func:`terramesh.cleanup.clean` removes boundary
        cells below this quality and low-valence vertices and smooths the
        rest; None skips it.
    max_iter : int, optional
        ``itmax``: most generator iterations.
    seed : int, optional
        Seed of the generator; the same inputs and seed give the same mesh.
    parts, comm : optional
        Mesh the water in ``parts`` strips and merge them
        (:func:`~terramesh.parallel.generate_mesh_parallel`), shared over
        the ranks of the MPI communicator ``comm`` if given (every rank
        calls ``build`` with the same arguments and computes the size
        function; rank 0 repairs, cleans and returns the mesh, the others
        None). With neither, the water is meshed whole.
    boundaries : bool or dict, optional
        Make the ADCIRC boundaries (:func:`~terramesh.coastal.make_boundaries`,
        the guide's ``makens``), so that ``mesh.write("fort.14")`` writes a
        file a solver can run: open ocean on the box's edge (with a DEM,
        where it is wet), mainland and islands elsewhere. A dict gives
        ``make_boundaries`` its options (``{"depth_threshold": 100.0}`` also
        opens water deeper than 100 m, which on a coarse DEM opens fjord
        walls and shelf breaks); False leaves them out.
    fixed_points : array_like, shape (k, 2), optional
        ``pfix``: longitude, latitude (degrees) of points that must be mesh
        vertices. They must lie in the box and in the water (within
        ``1e-3 h0`` of it: on the shoreline is in), at least ``1e-3 h0``
        apart; longitudes are taken by whole turns onto the box. They are
        fixed in the generator (on the Mercator plane) and in the clean-up,
        and the vertices get exactly the coordinates given (not their round
        trip through Mercator). The repairs still delete a small
        disconnected part (``disjoint_cutoff``) with any fixed point in it,
        with a warning.
    **size_options
        Options of :func:`size_function` (e.g. ``min_el=250, max_el=20e3, fs=3, g=0.2``).

    Returns
    -------
    Mesh or None
        None on MPI ranks other than 0. Points in longitude, latitude (degrees, ``mesh.crs == "EPSG:4326"``);
        ``mesh.depth`` is the DEM's depth per vertex, metres positive down
        (NaN without a DEM); ``mesh.info["sizes"]`` the :class:`CoastalSizes`
        and ``mesh.info["timings"]`` seconds per stage (with "compile
        ahead" on a fresh installation's first run); with ``dt``,
        ``mesh.info["dt"]`` the time step (the one chosen for ``dt=0``)
        and ``mesh.info["largest_courant"]`` the largest Courant number at
        it (:meth:`CoastalSizes.check_timestep`); with ``fixed_points``,
        ``mesh.info["fixed_points"]`` the (k,) vertex index of each (-1 for
        one the repairs deleted).

    Raises
    ------
    GeometryError
        For fixed points that are malformed, outside the box, on land, or
        closer together than ``1e-3 h0``.
    MeshValidityError
        For ``boundaries`` other than True, False or a dict of
        :func:`~terramesh.coastal.make_boundaries` options (an option
        misspelled, a bad value), before anything is meshed.
    TypeError
        For both ``pfix`` and ``fixed_points``, or an unknown option.

    Warns
    -----
    TerrameshWarning
        With ``dt``, if vertices of the mesh break the Courant number at it
        (:meth:`CoastalSizes.check_timestep`).
    TerrameshWarning
        If the repairs deleted fixed points (in small disconnected parts).

    Examples
    --------
    >>> import shapely, terramesh as tm
    >>> land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    >>> mesh = tm.coastal.build((0, 0.3, 0, 0.3), land, min_el=2000, max_el=6000, dis=0.3, g=0.3)
    >>> mesh.crs, bool(mesh.points[:, 1].max() <= 0.3 + 1e-9)
    ('EPSG:4326', True)
    """
    aliases = {name: size_options.pop(name) for name in ("dj_cutoff", "itmax", "pfix") if name in size_options}
    if "dj_cutoff" in aliases:
        disjoint_cutoff = aliases["dj_cutoff"]
    if "itmax" in aliases:
        max_iter = aliases["itmax"]
    if "pfix" in aliases:
        if fixed_points is not None:
            raise TypeError("'pfix' and 'fixed_points' are the same option; give one")
        fixed_points = aliases["pfix"]
    boundary_options = checked_boundary_options(boundaries, "build")
    started = time.perf_counter()
    sizes = size_function(bbox, shoreline, dem, **size_options)
    timings = dict(sizes.timings)
    step = time.perf_counter()
    domain = sizes.shoreline.domain()
    fixed_lonlat, fixed = _checked_fixed_points(fixed_points, sizes.shoreline, domain)
    # as in the guide, stopping at itmax is the normal end of a coastal mesh's generation
    with lonlat_messages(), muted_warnings(REACHED_MAX_ITER):
        if parts is None and comm is None:
            mesh = generate_mesh(domain, sizes.size_grid(), fixed_points=fixed, max_iter=max_iter, seed=seed)
        else:
            from ..parallel.mesh_in_parts import generate_mesh_parallel

            mesh = generate_mesh_parallel(
                domain, sizes.size_grid(), parts=parts, comm=comm, fixed_points=fixed, max_iter=max_iter, seed=seed
            )
            if mesh is None:  # an MPI rank other than 0: its strips went to rank 0
                return None
    timings["generation"] = time.perf_counter() - step
    logger.info("repairing and cleaning up the mesh (%d vertices)", mesh.n_points)
    step = time.perf_counter()
    generation_info = dict(mesh.info)
    # repairs on the Mercator plane, where the domain is and angles are the ground's
    with lonlat_messages():
        mesh = repaired_and_cleaned(
            mesh, domain, disjoint_cutoff=disjoint_cutoff, clean_quality=clean_quality, fixed_points=fixed
        )
    repair = mesh.info.get("repair")
    fixed_vertices = mesh.info.get("fixed_points")
    lon, lat = from_mercator(mesh.points[:, 0], mesh.points[:, 1])
    mesh.points = np.column_stack([lon, lat])
    if fixed is not None:  # the given coordinates, not their round trip through Mercator
        kept = fixed_vertices >= 0
        mesh.points[fixed_vertices[kept]] = fixed_lonlat[kept]
    mesh.crs = "EPSG:4326"
    depth = np.full(mesh.n_points, np.nan) if sizes.dem is None else -sizes.dem.sample(*mesh.points.T)
    mesh.point_data["depth"] = depth
    timings["repair"] = time.perf_counter() - step
    mesh.info.update(generation_info, sizes=sizes, timings=timings, repair=repair)
    if fixed is not None:
        mesh.info["fixed_points"] = fixed_vertices
    if boundary_options is not None:
        step = time.perf_counter()
        # the open sea is the box's edge, where wet (make_boundaries opens deep water elsewhere only if told: a
        # coarse DEM reads fjord walls deep). Without a DEM every depth is unknown: the box's edge alone
        options = {"open_by": "bbox_or_depth" if sizes.dem is not None else "bbox"}
        options.update(boundary_options)
        mesh = make_boundaries(mesh, **options)  # the box or region is the shoreline's (info["sizes"])
        timings["boundaries"] = time.perf_counter() - step
    timings["total"] = time.perf_counter() - started
    mesh.info["largest_courant"] = sizes.check_timestep(mesh)
    if sizes.dt is not None:  # the step dt = 0 chose, where build_multiscale puts its own
        mesh.info["dt"] = sizes.dt
    logger.info("coastal mesh: %d vertices, %d cells in %.1f s", mesh.n_points, mesh.n_cells, timings["total"])
    return mesh
