"""One mesh from several boxes, each with its own size options (the guide's multiscale workflow, §6.6).

Each box gets its own size function (:func:`~terramesh.coastal.size_function`
on its own grid, at its own ``min_el``, with its own shoreline and DEM), so
a 50 m estuary inside a 1 km shelf needs no 50 m grid over the shelf. The
fields are blended into one composite size function on the Mercator plane:

* inside a box, the innermost box holding the point sets the size (later
  boxes in the list override earlier ones);
* outside a box ``j``, its resolution relaxes at its grade:
  ``h(x) = min(h_owner(x), h_j(P_j x) + g_j |x - P_j x|)``, where ``P_j x``
  is the nearest point of the box (boxes are rectangles on the Mercator
  plane, so ``P_j`` is a clip), in ground metres: sizes on the ground and
  the great-circle distance, so the grade is ``g_j`` on the ground.

So the transition from fine to coarse is graded at ``g`` outside the fine
box and the fine box keeps its own sizes everywhere inside.

The water is also composed: each box's own shoreline inside it (the
innermost box's again), the outer box's elsewhere.

``method="once"`` (the default) meshes the composed water once with the
composite size function: a single force equilibrium, so there is no seam
and the transition is as smooth as anywhere else in a DistMesh mesh; the
generator's nested-lattice seeding keeps the work proportional to the
number of vertices, not to the area over the finest size. ``method="merge"``
follows the guide's script: each box is meshed on its own (its size field
already graded towards the boxes inside it) and the meshes are merged,
inner into outer (:func:`~terramesh.coastal.merge`); boxes can then be made
separately (or in parallel) at the price of a seam. ``method="grid"``
samples the composite field on one grid over the outer box at the finest
``min_el`` and grades it there (:func:`~terramesh.sizing.limit_gradient`):
the single-grid reference that multiscale meshing avoids, for comparison.
"""

import logging
import time

import numpy as np
import shapely

from .._kernels import read_only
from .._kernels.precompile import compile_ahead_on_first_run
from .._kernels.raster import graded_from_box
from ..errors import GeometryError, muted_warnings, warn_user
from ..generation.distmesh import generate_mesh
from ..generation.mesh_checks import REACHED_MAX_ITER, SIZES_MISSED
from ..generation.options import SIZES_JUMP
from ..geometry.polygon import Polygon
from ..sizing.gradation import limit_gradient
from .boundaries import checked_boundary_options, make_boundaries
from .build import BREAK_COURANT, repaired_and_cleaned, size_function
from .grid import GeoGrid, as_lonlat_box
from .merge import DEFAULT_GRADE, merge
from .messages import lonlat_messages
from .projection import EARTH_RADIUS, from_mercator, to_mercator

__all__ = ["build_multiscale", "CompositeSize", "METHODS"]

logger = logging.getLogger("terramesh.coastal")

METHODS = ("once", "merge", "grid")
"""Ways :func:`build_multiscale` can mesh the boxes (see the module notes)."""

_SLIVER_AREA = 4.0  # water polygons smaller than this many (finest min_el)**2 are dropped


class CompositeSize:
    """The boxes' size functions blended into one, on the Mercator plane (metres).

    Parameters
    ----------
    sizes : list of CoastalSizes
        One per box (its ``shoreline.bbox`` is the box), outermost first;
        later boxes override earlier ones inside them.
    grades : list of float
        Growth rate of each box's size outside it (the box's ``g``).
    nested : bool, optional
        True: inside a later box, its size holds. False: the first box's
        size holds everywhere and the others only refine it around them
        (the size of the first box's own mesh when boxes are meshed apart).
    shifts : list of float, optional
        Degrees of longitude (multiples of 360) that carry each box into the
        first box's longitudes: a box east of 180 E is kept in -180..180 by
        :func:`~terramesh.coastal.size_function`, the first box across the
        antimeridian in 0..360. Default none.

    Examples
    --------
    >>> import shapely, terramesh as tm
    >>> land = shapely.box(-1.0, -1.0, 0.0, 1.0)
    >>> outer = tm.coastal.size_function((-0.5, 0.5, -0.5, 0.5), land, min_el=4000, max_el=8000, dis=0.5)
    >>> inner = tm.coastal.size_function((-0.1, 0.1, -0.1, 0.1), land, min_el=1000, max_el=1000)
    >>> size = CompositeSize([outer, inner], [0.2, 0.2])
    >>> x, y = tm.coastal.to_mercator([0.0, 0.2], [0.0, 0.0])
    >>> h = size(np.column_stack([x, y]))
    >>> bool(abs(h[0] - 1000.0) < 1.0), bool(1000.0 < h[1] < 1000.0 + 0.2 * 12000.0)
    (True, True)
    """

    def __init__(self, sizes, grades, *, nested=True, shifts=None):
        self.nested = nested
        self.grids = [s.size_grid() for s in sizes]
        shifts = np.zeros(len(sizes)) if shifts is None else np.asarray(shifts, dtype=np.float64)
        # a box's own grid is in its own longitudes: points of the first box's are moved back into them
        self.offsets = to_mercator(shifts, np.zeros(len(sizes)))[0]
        # each box on the Mercator plane, where a longitude/latitude box is a rectangle
        boxes = np.array([s.shoreline.bbox for s in sizes], dtype=np.float64).reshape(-1, 4)
        x0, y0 = to_mercator(boxes[:, 0] + shifts, boxes[:, 2])
        x1, y1 = to_mercator(boxes[:, 1] + shifts, boxes[:, 3])
        self.rectangles = np.column_stack([x0, x1, y0, y1])
        self._latitudes = np.radians(np.column_stack([boxes[:, 2], boxes[:, 3]]))  # each box's south and north
        self.grades = [float(g) for g in grades]
        self.smallest = min(float(g.values.min()) for g in self.grids)

    def owner(self, points):
        """Index of the innermost (last) box holding each point (Mercator metres, ``(n, 2)``), shape ``(n,)``.

        0 outside all boxes, and everywhere when not ``nested``.
        """
        owner = np.zeros(len(points), dtype=np.int64)
        if not self.nested:
            return owner
        for j, (x0, x1, y0, y1) in enumerate(self.rectangles[1:], start=1):
            inside = (points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)
            owner[inside] = j
        return owner

    def __call__(self, points):
        """Size at ``points`` (shape ``(n, 2)``, Mercator metres), Mercator metres, shape ``(n,)``."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        owner = self.owner(points)
        size = np.empty(len(points))
        for j, grid in enumerate(self.grids):
            mine = owner == j
            if mine.any():
                size[mine] = grid(self._own(points[mine], j))
        if len(self.grids) > 1:
            # on the ground: ground sizes plus g times the great-circle distance (a Mercator cone grew up to
            # h tan(lat) / R faster along the meridians: 0.25 for g 0.2 at 82 N with 50 km sizes)
            x, y = np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1])
            latitude = np.radians(from_mercator(0.0, y)[1])
            for j, grid in enumerate(self.grids[1:], start=1):
                south, north = self._latitudes[j]
                graded_from_box(
                    x,
                    y,
                    latitude,
                    size,
                    read_only(grid.values),
                    grid._origin,
                    grid._spacing,
                    self.rectangles[j],
                    south,
                    north,
                    self.grades[j],
                    self.offsets[j],
                    EARTH_RADIUS,
                )
        return size

    def _own(self, points, j):
        """``points`` of the first box's Mercator plane in box ``j``'s own longitudes."""
        if self.offsets[j] == 0:
            return points
        return points - np.array([self.offsets[j], 0.0])


def _checked_boxes(boxes, shoreline, dem):
    """Each box as ``(bbox, shoreline, dem, options)``; the top-level shoreline and DEM are the defaults."""
    if isinstance(boxes, dict) or not hasattr(boxes, "__len__") or len(boxes) == 0:
        raise GeometryError("boxes must be a non-empty list of dicts, each with a 'bbox' and its size options")
    checked = []
    for i, box in enumerate(boxes):
        if not isinstance(box, dict) or "bbox" not in box:
            raise GeometryError(f"box {i} must be a dict with a 'bbox' (lon_min, lon_max, lat_min, lat_max)")
        options = dict(box)
        bbox = options.pop("bbox")
        checked.append((bbox, options.pop("shoreline", shoreline), options.pop("dem", dem), options))
    return checked


def _lonlat_box(bbox):
    """A box (or polygon) given as a bbox, as a shapely box in longitude/latitude."""
    if isinstance(bbox, shapely.Geometry):
        return shapely.box(*bbox.bounds)
    lon_min, lon_max, lat_min, lat_max = as_lonlat_box(bbox)
    return shapely.box(lon_min, lat_min, lon_max, lat_max)


def _as_bbox(extent):
    """A shapely box as the user writes a bbox, ``(lon_min, lon_max, lat_min, lat_max)``, for messages."""
    lon_min, lat_min, lon_max, lat_max = (float(v) for v in extent.bounds)
    return (lon_min, lon_max, lat_min, lat_max)


def _shifts(extents):
    """Degrees (multiples of 360) that carry each box's extent onto the first's longitudes: where they overlap most."""
    shifts = [0.0]
    for extent in extents[1:]:
        overlap = [shapely.intersection(extents[0], _shifted(extent, shift)).area for shift in (-360.0, 0.0, 360.0)]
        shifts.append((-360.0, 0.0, 360.0)[int(np.argmax(overlap))] if max(overlap) > 0 else 0.0)
    return shifts


def _shifted(geometry, shift):
    """A lon/lat geometry moved by ``shift`` degrees of longitude."""
    return geometry if shift == 0 else shapely.transform(geometry, lambda xy: xy + np.array([shift, 0.0]))


def _box_polygon(sizes, shift=0.0):
    lon_min, lon_max, lat_min, lat_max = sizes.shoreline.bbox
    return shapely.box(lon_min + shift, lat_min, lon_max + shift, lat_max)


def _composite_water(sizes, shifts):
    """The water of each box inside it and outside the boxes after it, in the first box's longitude/latitude."""
    boxes = [_box_polygon(s, shift) for s, shift in zip(sizes, shifts, strict=True)]
    parts = []
    for j, s in enumerate(sizes):
        own = _shifted(s.shoreline.water, shifts[j])
        water = own if j == 0 else shapely.intersection(own, boxes[0])
        later = boxes[j + 1 :]
        if later:
            water = shapely.difference(water, shapely.union_all(later))
        parts.append(water)
    return shapely.union_all(parts)


def _ground_lengths(lines):
    """Lengths, metres on the ground (a sphere's, locally flat), of lon/lat lines."""
    lengths = []
    for line in lines:
        xy = np.radians(shapely.get_coordinates(line))
        middle = 0.5 * (xy[1:, 1] + xy[:-1, 1])
        lengths.append(EARTH_RADIUS * np.hypot(np.diff(xy[:, 0]) * np.cos(middle), np.diff(xy[:, 1])).sum())
    return np.array(lengths)


def _warn_of_walls_on_box_edges(water, sizes, shifts):
    """Warn where the composed coast runs along an inner box's edge for more than two of its elements.

    There the box's shoreline says water and the outer one's land, or the
    reverse (a DEM's 0 m contour against a coastline product in a marsh;
    one file, whose small features the outer box drops at its coarser
    min_el): the mesh gets a straight wall across what one of them calls
    water. A review's Sabine Lake box (CUDEM inside GSHHS) had 11 km of
    such walls, the longest 3.3 km; Chesapeake Bay at 0.8 km in a 4 km
    box of the same ne_10m file, 5.9 km.
    """
    outer_edge = shapely.buffer(shapely.boundary(_box_polygon(sizes[0], shifts[0])), 1e-9)
    coast = shapely.boundary(water)
    for j in range(1, len(sizes)):
        edge = shapely.difference(shapely.boundary(_box_polygon(sizes[j], shifts[j])), outer_edge)
        walls = shapely.line_merge(shapely.intersection(coast, shapely.buffer(edge, 1e-9)))
        pieces = shapely.get_parts(walls)
        pieces = pieces[shapely.get_type_id(pieces) == 1]  # lines: a corner's point is no wall
        if not len(pieces):
            continue
        lengths = _ground_lengths(pieces)
        long = lengths > 2 * sizes[j].shoreline.min_edge_length
        if long.any():
            middle = shapely.line_interpolate_point(pieces[np.argmax(lengths)], 0.5, normalized=True)
            where = shapely.get_coordinates(middle)[0]
            warn_user(
                f"box {j}'s shoreline and the outer boxes' disagree at its edge: the coast runs along the edge"
                f" for {lengths[long].sum() / 1e3:.3g} km in {int(long.sum())} pieces longer than two elements"
                f" (the longest {lengths.max() / 1e3:.3g} km, at {where[0]:.4f}, {where[1]:.4f}), straight walls"
                " across what one of them calls water (two shoreline files, or one file kept at each box's own"
                " min_el: the outer box's drops what is smaller than its elements); put the box's edge in open"
                " water or where the coasts agree"
            )


def _mercator_domain(water, smallest):
    """Water (degrees) as a :class:`Polygon` on the Mercator plane, slivers and specks dropped."""

    def mercator(xy):
        return np.column_stack(to_mercator(xy[:, 0], xy[:, 1]))

    water = shapely.transform(water, mercator)
    polygons = [p for p in shapely.get_parts(water) if isinstance(p, shapely.Polygon)]
    polygons = [p for p in polygons if p.area >= _SLIVER_AREA * smallest**2]
    if not polygons:
        raise GeometryError("the boxes hold no water to mesh")
    water = shapely.MultiPolygon(polygons) if len(polygons) > 1 else polygons[0]
    try:
        return Polygon.from_shapely(water)
    except GeometryError:
        # rings touching at a point where the boxes' shorelines meet: erode a hair
        eroded = shapely.buffer(water, -1e-4 * smallest, quad_segs=2, join_style="mitre")
        parts = [p for p in shapely.get_parts(eroded) if p.area >= _SLIVER_AREA * smallest**2]
        return Polygon.from_shapely(shapely.MultiPolygon(parts) if len(parts) > 1 else parts[0])


def _depth(sizes, points, shifts):
    """Depth at lon/lat points (degrees, the first box's longitudes) from the DEM of the innermost box holding each.

    Metres positive down. Where that box has no DEM (or its DEM gives NaN),
    the next box out with one.
    """
    depth = np.full(len(points), np.nan)
    for j in range(len(sizes) - 1, -1, -1):
        if sizes[j].dem is None:
            continue
        lon_min, lon_max, lat_min, lat_max = sizes[j].shoreline.bbox
        lon, lat = points[:, 0] - shifts[j], points[:, 1]
        todo = np.isnan(depth)
        if j:
            todo &= (lon >= lon_min) & (lon <= lon_max) & (lat >= lat_min) & (lat <= lat_max)
        if todo.any():
            depth[todo] = -sizes[j].dem.sample(lon[todo], lat[todo])
    return depth


def mesh_water(domain, size, h0, *, disjoint_cutoff, clean_quality, max_iter, seed):
    """Generate on the Mercator plane, repair and clean (as :func:`~terramesh.coastal.build` does)."""
    # a box meshed apart for merging: its sizes jump at a later box's edge, from the later box's fine sizes
    # outside it to its own inside it, where the later box's mesh replaces this one's
    jumps = isinstance(size, CompositeSize) and not size.nested and len(size.grids) > 1
    # their places in longitude, latitude, as build's
    with lonlat_messages(), muted_warnings(REACHED_MAX_ITER, *([SIZES_MISSED, SIZES_JUMP] if jumps else [])):
        mesh = generate_mesh(domain, size, h0=h0, max_iter=max_iter, seed=seed)
    generation = dict(mesh.info)
    with lonlat_messages():
        mesh = repaired_and_cleaned(mesh, domain, disjoint_cutoff=disjoint_cutoff, clean_quality=clean_quality)
    mesh.info.update(generation)
    return mesh


def _to_lonlat(mesh, sizes, shifts):
    """The mesh's points from the Mercator plane to longitude/latitude, with depth from the boxes' DEMs."""
    lon, lat = from_mercator(mesh.points[:, 0], mesh.points[:, 1])
    mesh.points = np.column_stack([lon, lat])
    mesh.crs = "EPSG:4326"
    mesh.point_data["depth"] = _depth(sizes, mesh.points, shifts)
    return mesh


def build_multiscale(
    boxes,
    shoreline=None,
    dem=None,
    *,
    method="once",
    disjoint_cutoff=0.01,
    clean_quality=0.5,
    max_iter=100,
    seed=0,
    boundaries=True,
):
    """Mesh several nested boxes, each with its own size options, into one graded mesh (guide §6.6).

    Parameters
    ----------
    boxes : list of dict
        Outermost first. Each dict has ``"bbox"``, ``(lon_min, lon_max,
        lat_min, lat_max)`` in degrees, and the box's options of
        :func:`~terramesh.coastal.size_function` under their long or
        guide names (``min_el``, ``max_el``, ``fs``, ``wl``, ``g``, ``dt``,
        ...); optionally its own ``"shoreline"`` (``None``: the DEM's 0 m
        contour) and ``"dem"`` (``None``: none), e.g. a regional coastline
        and atlas for the outer box and a survey DEM for an estuary. Inner
        boxes should lie inside the first; a later box overrides earlier
        ones inside it. An inner box with no land in it is open water
        (``require_land=False`` of :func:`~terramesh.coastal.size_function`):
        its ``max_el`` and its DEM's functions (``wl``, ``slp``) set its
        sizes, e.g. a refinement over a seamount or a shelf break.
    shoreline, dem : optional
        Defaults for the boxes that name none (see :func:`~terramesh.coastal.build`):
        files or land geometry, which each box cuts to itself; a
        :class:`~terramesh.coastal.Shoreline` object is cut to one box
        already, so it goes in that box's dict, not here.
    method : {"once", "merge", "grid"}, optional
        ``"once"``: one generation with the composite size function (no
        seam); ``"merge"``: each box meshed on its own, then merged inner
        into outer (the guide's script); ``"grid"``: the composite field
        sampled on a single grid at the finest ``min_el`` over the first
        box (a reference: its memory grows with area / min_el**2). See the
        module notes.
    disjoint_cutoff, clean_quality, max_iter, seed, boundaries
        As in :func:`~terramesh.coastal.build`; the boundaries are open on
        the first box's edge (and in deep water where a box has a DEM).

    Returns
    -------
    Mesh
        Longitude/latitude degrees (``crs == "EPSG:4326"``), ``depth``
        (metres, positive down) from the DEM of the innermost box holding
        each vertex. ``mesh.info["sizes"]`` is the list of
        :class:`~terramesh.coastal.CoastalSizes`, ``info["size"]`` the
        :class:`CompositeSize`, ``info["timings"]`` seconds per stage,
        ``info["method"]`` the method and ``info["grid_nodes"]`` the size
        nodes used (sum over the boxes' grids, or the single grid); with
        ``dt`` in a box, ``info["dt"]`` the smallest of the boxes' steps
        (seconds), the one the mesh is to be stepped at, and
        ``info["largest_courant"]`` the largest Courant number at it.

    Warns
    -----
    TerrameshWarning
        With ``dt``, if vertices break the Courant number at ``info["dt"]``
        (:meth:`~terramesh.coastal.CoastalSizes.check_timestep`); when
        some boxes have a ``dt`` and others none, that those are not
        limited for it instead.

    Raises
    ------
    GeometryError
        For malformed boxes, a box outside the first, a box that contains
        the first (boxes listed inner-first), or no water; for an inner box
        with no water, naming the box.
    MeshValidityError
        For ``boundaries`` other than True, False or a dict of
        :func:`~terramesh.coastal.make_boundaries` options, before anything
        is meshed.
    SizingError
        From the boxes' size functions, or a single grid too large (``"grid"``).

    Notes
    -----
    Inside an inner box its own sizes hold even where the outer box asks
    for finer ones; the outer box's sizes are only ever refined near an
    inner box. Time-step (CFL) limits hold inside each box for its own
    ``dt``; the graded transition outside a box, being finer than the
    outer field, can ask for a smaller step there, which the check of
    ``info["dt"]`` reports. Boxes are put into the first box's longitudes:
    an inner box east of 180 E in a first box across the antimeridian
    (178-186 E around the Chatham Islands) is found there.

    Examples
    --------
    >>> import shapely, terramesh as tm
    >>> land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    >>> boxes = [
    ...     {"bbox": (0, 0.3, 0, 0.3), "min_el": 2500, "max_el": 6000, "dis": 0.3, "g": 0.3},
    ...     {"bbox": (0.05, 0.15, 0.05, 0.15), "min_el": 1000, "max_el": 2000, "dis": 0.3, "g": 0.3},
    ... ]
    >>> mesh = build_multiscale(boxes, land)
    >>> mesh.crs, tm.cleanup.mesh_problems(mesh)
    ('EPSG:4326', [])
    """
    if method not in METHODS:
        raise GeometryError(f"method must be one of {METHODS}, got {method!r}")
    boundary_options = checked_boundary_options(boundaries, "build_multiscale")
    started = time.perf_counter()
    checked = _checked_boxes(boxes, shoreline, dem)
    extents = [_lonlat_box(bbox) for bbox, *_ in checked]
    # a box east of 180 E is in -180..180, a first box across the antimeridian in 0..360: one frame, the first's
    shifts = _shifts(extents)
    extents = [_shifted(extent, shift) for extent, shift in zip(extents, shifts, strict=True)]
    for i, extent in enumerate(extents[1:], start=1):
        # listed inner-first, the outer box would be cut down to the inner one and meshing fails far later
        if shapely.covers(extent, extents[0]) and not shapely.equals(extent, extents[0]):
            raise GeometryError(
                f"box {i} {_as_bbox(extent)} contains the first box {_as_bbox(extents[0])}: list the boxes "
                "outermost first, the first box being the outer one that contains the others"
            )
        if not shapely.intersects(extents[0], extent):
            raise GeometryError(
                f"box {i} {_as_bbox(extent)} does not overlap the first (outer) box {_as_bbox(extents[0])}"
            )
        if not shapely.covers(extents[0], extent):
            warn_user(
                f"box {i} {_as_bbox(extent)} reaches out of the first box: only its part inside is meshed",
            )
    compiled = compile_ahead_on_first_run(["coastal"])  # after the boxes' checks: a bad box said at once
    timings = {"compile ahead": compiled["seconds"]} if compiled else {}
    sizes, grades = [], []
    for i, (bbox, box_shoreline, box_dem, options) in enumerate(checked):
        step = time.perf_counter()
        try:
            # an inner box offshore is open water: the first box's coast is what its water is cut from
            sizes.append(size_function(bbox, box_shoreline, box_dem, **{"require_land": i == 0, **options}))
        except GeometryError as error:
            if i == 0:
                raise
            raise GeometryError(f"box {i}: {error}") from error  # which of several boxes has no water
        grade = options.get("g", options.get("grade"))
        grades.append(DEFAULT_GRADE if grade is None else float(grade))
        timings[f"sizes box {i}"] = time.perf_counter() - step
    composite = CompositeSize(sizes, grades, shifts=shifts)
    grid_nodes = sum(int(np.prod(s.grid.shape)) for s in sizes)
    generate = dict(disjoint_cutoff=disjoint_cutoff, clean_quality=clean_quality, max_iter=max_iter, seed=seed)
    step = time.perf_counter()
    finest = min(s.shoreline.min_edge_length for s in sizes)
    # the coast the boxes compose: walls along an inner box's edge warn whichever way it is meshed (merge said none)
    water = _composite_water(sizes, shifts)
    _warn_of_walls_on_box_edges(water, sizes, shifts)
    if method == "merge":
        mesh = None
        first = _box_polygon(sizes[0])
        for j, s in enumerate(sizes):
            # box j alone, graded towards the boxes after it
            # in box j's own longitudes, then moved into the first box's
            relative = [shift - shifts[j] for shift in shifts]
            own = CompositeSize([s, *sizes[j + 1 :]], [grades[j], *grades[j + 1 :]], nested=False, shifts=relative[j:])
            box = _box_polygon(s, shifts[j])
            if shapely.covers(first, box):
                domain = s.shoreline.domain()
            else:  # only its part inside the first box, as the other methods mesh (and the warning above says)
                box = shapely.intersection(box, first)
                water = shapely.intersection(s.shoreline.water, _shifted(first, -shifts[j]))
                if water.area == 0:
                    continue  # its water all outside: nothing of it is meshed, as with the other methods
                domain = _mercator_domain(water, s.shoreline.min_edge_length)
            part = mesh_water(domain, own, own.smallest, **generate)
            part = _to_lonlat(part, sizes, relative)  # depth from the innermost box with a DEM, as the others
            part.points[:, 0] += shifts[j]
            mesh = part if mesh is None else merge(part, mesh, grade=grades[j], region=box)
        # the seams' new vertices got depths interpolated by the merge (off by up to 68 m): the DEMs' instead
        mesh.point_data["depth"] = _depth(sizes, mesh.points, shifts)
        timings["generation and merging"] = time.perf_counter() - step
    else:
        domain = _mercator_domain(water, finest)
        timings["water"] = time.perf_counter() - step
        size = composite
        if method == "grid":
            step = time.perf_counter()
            grid = GeoGrid(sizes[0].shoreline.bbox, finest)
            x, y = np.meshgrid(grid.x, grid.y, indexing="ij")
            values = composite(np.column_stack([x.ravel(), y.ravel()])).reshape(grid.shape)
            ground = values * (grid.ground_step / grid.step)[None, :]  # graded on the ground, as one box's sizes
            graded = limit_gradient(ground, grid.step, grid.ground_grade(min(grades)), overwrite_values=True)
            size = grid.size_grid(graded)
            grid_nodes = int(np.prod(grid.shape))
            timings["single grid"] = time.perf_counter() - step
        step = time.perf_counter()
        mesh = mesh_water(domain, size, composite.smallest, **generate)
        mesh = _to_lonlat(mesh, sizes, shifts)
        timings["generation"] = time.perf_counter() - step
    timings["total"] = time.perf_counter() - started
    mesh.info.update(sizes=sizes, size=composite, timings=timings, method=method, grid_nodes=grid_nodes)
    made_for = [s for s in sizes if s.dt is not None]
    if made_for:
        # the mesh is stepped at the smallest of the boxes' steps: said, and checked on the whole mesh
        smallest = min(made_for, key=lambda s: s.dt)
        mesh.info["dt"] = smallest.dt
        unlimited = [i for i, s in enumerate(sizes) if s.dt is None]
        if not unlimited:
            mesh.info["largest_courant"] = smallest.check_timestep(mesh)
        else:
            # removing vertices there (enforce_timestep, the check's remedy) would undo the boxes' resolution
            with muted_warnings(BREAK_COURANT):
                mesh.info["largest_courant"] = smallest.check_timestep(mesh)
            boxes_named = ", ".join(str(i) for i in unlimited)
            warn_user(
                f"box{'es' if len(unlimited) > 1 else ''} {boxes_named} {'have' if len(unlimited) > 1 else 'has'}"
                f" no dt: {'their' if len(unlimited) > 1 else 'its'} sizes are not limited for the dt ="
                f" {smallest.dt:.4g} s of box {sizes.index(smallest)} (info['dt'];"
                f" largest Courant number {mesh.info['largest_courant'] or float('nan'):.2f}): give every box"
                " a dt, the same or 0, rather than enforce_timestep on this mesh, which would coarsen them"
            )
    if boundary_options is not None:
        # the outer box, in the longitudes the boxes were put into; open where wet on it, as build's
        options = {"bbox": sizes[0].shoreline.bbox}
        options["open_by"] = "bbox_or_depth" if any(s.dem is not None for s in sizes) else "bbox"
        options.update(boundary_options)
        mesh = make_boundaries(mesh, **options)
    logger.info(
        "multiscale mesh (%s, %d boxes): %d vertices, %d cells in %.1f s",
        method,
        len(sizes),
        mesh.n_points,
        mesh.n_cells,
        timings["total"],
    )
    return mesh
