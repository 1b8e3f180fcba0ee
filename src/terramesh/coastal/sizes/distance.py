"""Distance to the coastline and the guide's two distance size functions (§3.1, eq. 2-4).

Everything lives on a :class:`~terramesh.coastal.GeoGrid`: fields are
``(nx, ny)`` float64 arrays in ground metres. The coastline is a shapely
geometry in longitude/latitude degrees, in the same longitude convention
as the grid's box (-180..180, or 0..360 for a box across the antimeridian).

The linear distance function (``dis``, eq. 2) and the feature size
function (``fs``, eq. 3-4) are mutually exclusive (§3.1);
:func:`shoreline_size` builds whichever one is asked for and refuses both.
"""

import numpy as np
import shapely

from ..._kernels.raster import (
    land_gap,
    mark_segments,
    nearest_feature,
    nearest_node_distance,
    nearest_segment_distance,
    neighbourhood_segments,
    scanline_fill,
    transposed,
    with_company,
)
from ...errors import GeometryError, SizingError, warn_user
from ...sizing.gradation import DEFAULT_GRADE
from ..projection import MAX_LATITUDE, from_mercator, to_mercator
from ._common import check_grid, field, ground_gradient_norm, mask, positive

__all__ = [
    "polygon_mask",
    "water_mask",
    "distance_to_coastline",
    "distance_size",
    "approximate_medial_axis",
    "feature_size",
    "shoreline_size",
    "MEDIAL_AXIS_GRADIENT",
]

MEDIAL_AXIS_GRADIENT = 0.9
"""Largest ``|grad d|`` of a node on the approximate medial axis (§3.1: "less than or equal to 0.90")."""

_MEDIAL_AXIS_DEPTH = 0.5  # h0: OceanMesh2D's depth test, d > h0 / 2 (its code, not the guide's text)
_MEDIAL_AXIS_REACH = 6  # nodes: the window (13 x 13 nodes) in which an axis node must have company...
_MEDIAL_AXIS_COMPANY = 3  # ...this many other axis nodes: a curve, even dotted, and not a spot
_NO_LAND = 2**29  # a node index no grid reaches, for "no land on this side" (int32, and twice it still fits)


def _geometry(value, name):
    if not isinstance(value, shapely.Geometry):
        raise GeometryError(f"{name} must be a shapely geometry in lon/lat degrees, got {type(value).__name__}")
    return value


def _flat_parts(geometry):
    """The non-collection parts of a geometry, as an array of geometries."""
    parts = shapely.get_parts(np.atleast_1d(geometry))
    while parts.size and np.any(shapely.get_type_id(parts) >= 4):
        parts = shapely.get_parts(parts)
    return parts[~shapely.is_empty(parts)] if parts.size else parts


def polygon_mask(grid, polygon):
    """Grid nodes inside a (multi)polygon given in longitude/latitude degrees.

    A scanline fill (even-odd rule, so holes are honoured) of the rings'
    edges, each straight in longitude/latitude, exactly as
    ``shapely.contains_xy`` reads the polygon; nodes on an edge may fall on
    either side. Its cost is that of the crossings plus one pass over the
    grid: a 5,000 x 7,000 grid takes about a second, where
    ``shapely.contains_xy`` takes minutes.

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    polygon : shapely.Polygon or shapely.MultiPolygon
        Degrees, in either longitude convention (-180..180 or 0..360: it
        is moved by whole turns onto the grid); collections of polygons
        are accepted.

    Returns
    -------
    ndarray of bool, shape (nx, ny)
        True inside.

    Examples
    --------
    >>> import shapely
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 1, 0, 1), 10e3)
    >>> inside = polygon_mask(grid, shapely.box(0.25, 0.25, 0.75, 0.75))
    >>> inside.shape, int(inside.sum())
    ((13, 13), 36)
    """
    grid = check_grid(grid)
    parts = _flat_parts(_geometry(polygon, "polygon"))
    if parts.size and not np.all(shapely.get_type_id(parts) == 3):
        raise GeometryError("polygon must be a Polygon or MultiPolygon (lines and points have no inside)")
    rings = shapely.get_rings(parts) if parts.size else parts
    if rings.size == 0:
        return np.zeros(grid.shape, dtype=bool)
    coords, index = shapely.get_coordinates(rings, return_index=True)
    same = index[1:] == index[:-1]
    start = np.ascontiguousarray(coords[:-1][same])
    end = np.ascontiguousarray(coords[1:][same])
    # the polygon may be written in the other longitude convention (0..360 or -180..180): every whole turn
    # that takes it onto the grid counts
    west, east = coords[:, 0].min(), coords[:, 0].max()
    turns = [turn for turn in (0.0, -360.0, 360.0) if west + turn <= grid.lon[-1] and east + turn >= grid.lon[0]]
    inside = None
    for turn in turns:
        inside_rows = scanline_fill(
            start[:, 0] + turn, start[:, 1].copy(), end[:, 0] + turn, end[:, 1].copy(), grid.lon, grid.lat
        )
        inside = transposed(inside_rows) if inside is None else inside | transposed(inside_rows)
    return np.zeros(grid.shape, dtype=bool) if inside is None else inside


def water_mask(grid, water_polygon):
    """Grid nodes in the water: :func:`polygon_mask` of the water (multi)polygon, degrees.

    For a land polygon (a shoreline shapefile's islands and continents),
    negate the mask of the land: ``~water_mask(grid, land)``.

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    water_polygon : shapely.Polygon or shapely.MultiPolygon
        The water, in longitude/latitude degrees.

    Returns
    -------
    ndarray of bool, shape (nx, ny)
        True in the water.

    Examples
    --------
    >>> import shapely
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 1, 0, 1), 10e3)
    >>> sea = shapely.box(0, 0, 1, 1).difference(shapely.box(0.5, 0, 1, 1))
    >>> bool(water_mask(grid, sea)[0, 0]), bool(water_mask(grid, sea)[-1, 0])
    (True, False)
    """
    return polygon_mask(grid, water_polygon)


def _coastline_lines(coastline, lon_min, lon_max, lat_min, lat_max):
    """The coastline as line parts clipped to a lon/lat box (polygons give their rings)."""
    parts = _flat_parts(_geometry(coastline, "coastline"))
    if parts.size == 0:
        return parts
    kind = shapely.get_type_id(parts)
    lines = parts[(kind == 1) | (kind == 2)]
    polygons = parts[kind == 3]
    if polygons.size:
        rings = shapely.get_rings(polygons)
        coords, index = shapely.get_coordinates(rings, return_index=True)
        lines = np.concatenate([lines, shapely.linestrings(coords, indices=index)])
    # a LinearRing clipped by a rectangle stays a line (no rectangle edges are added)
    clipped = _flat_parts(shapely.clip_by_rect(lines, lon_min, lat_min, lon_max, lat_max))
    return clipped[np.isin(shapely.get_type_id(clipped), (1, 2))]


def distance_to_coastline(grid, coastline, *, margin=64):
    """Ground distance (metres) from every grid node to the nearest point of the coastline.

    The coastline's segments are drawn onto the grid (padded by ``margin``
    nodes each side, so that coastline just outside the box counts), each
    node's cell remembering every segment through it; the Euclidean
    distance transform (:func:`~terramesh._kernels.raster.nearest_feature`) gives
    each node its nearest drawn node, and the distance is then measured
    exactly to all the segments through that node's cell and its eight
    neighbours. Near the coastline this is, in practice, the exact distance
    (to 0.5 m on a 1 km grid in the tests); farther away the nearest
    segment may lie in another cell, and the answer (a true distance to the
    coastline) exceeds the nearest one by at most about one grid step (a
    quarter of a step in the tests, near the centre of a circle), a
    relative error below ``step / distance``.

    Approximations, all below the grid's own resolution:

    * segments are straight on the Mercator plane between their vertices
      (shapefile vertices are close together);
    * the nearest point is chosen in Mercator metres, which is the ground
      metric times ``1 / cos(lat)``, locally the same choice because the
      projection is conformal;
    * the distance to that point is the Mercator distance times ``cos(lat)``
      at the middle of the two (the conformal scale, taken where it is
      second-order accurate): on the sphere of
      :data:`~terramesh.coastal.projection.EARTH_RADIUS` (within 0.5 % of
      the ellipsoid's) this is the great-circle distance to a relative
      1e-5 at 100 km up to 45 degrees latitude, 3e-5 at 60 degrees (it grows
      like ``(d / R)**2 tan(lat)**2``).

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    coastline : shapely geometry
        Lon/lat degrees: (Multi)LineStrings, or (Multi)Polygons whose rings
        are used (pass the land, not a water polygon cut out of a box,
        whose box edges would count as coastline). Parts beyond the padded
        grid are ignored.
    margin : int, optional
        Nodes added on each side of the grid when drawing the coastline.

    Returns
    -------
    ndarray, shape (nx, ny)
        Metres; ``inf`` everywhere (with a :class:`TerrameshWarning`) when
        no coastline reaches the padded grid.

    Examples
    --------
    >>> import shapely
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 1, 0, 1), 5e3)
    >>> d = distance_to_coastline(grid, shapely.LineString([(0, -1), (0, 2)]))
    >>> d.shape, bool(abs(d[10, 0] - 10 * grid.ground_step[0]) < 1.0)
    ((24, 24), True)
    """
    grid = check_grid(grid)
    if isinstance(margin, bool) or not isinstance(margin, (int, np.integer)) or margin < 0:
        raise SizingError(f"margin must be a non-negative whole number of nodes, got {margin!r}")
    pad = int(margin)
    nx, ny = grid.shape
    x0 = grid.x[0] - pad * grid.step
    y0 = grid.y[0] - pad * grid.step
    (lon_lo, lon_hi), (lat_lo, lat_hi) = from_mercator(
        np.array([x0, grid.x[-1] + pad * grid.step]), np.array([y0, grid.y[-1] + pad * grid.step])
    )
    lines = _coastline_lines(coastline, lon_lo, lon_hi, max(lat_lo, -MAX_LATITUDE), min(lat_hi, MAX_LATITUDE))
    nxp, nyp = nx + 2 * pad, ny + 2 * pad
    cells = np.empty(0, dtype=np.int64)
    if lines.size:
        coords, index = shapely.get_coordinates(lines, return_index=True)
        same = index[1:] == index[:-1]
        mx, my = to_mercator(coords[:, 0], coords[:, 1])
        ax, ay = np.ascontiguousarray(mx[:-1][same]), np.ascontiguousarray(my[:-1][same])
        bx, by = np.ascontiguousarray(mx[1:][same]), np.ascontiguousarray(my[1:][same])
        step = grid.step
        cells, segments = mark_segments(
            (ax - x0) / step, (ay - y0) / step, (bx - x0) / step, (by - y0) / step, nxp, nyp
        )
    if cells.size == 0:
        warn_user(
            "the coastline does not reach the grid: the distance to it is inf everywhere",
        )
        return np.full(grid.shape, np.inf)
    order = np.argsort(cells, kind="stable")
    cells, segments = cells[order], segments[order]
    starts = np.flatnonzero(np.r_[True, cells[1:] != cells[:-1]])
    first = np.full(nxp * nyp, -1, dtype=np.int32 if cells.size < 2**31 else np.int64)
    first[cells[starts]] = starts
    first = first.reshape(nxp, nyp)
    nearest_x, nearest_y = nearest_feature(first >= 0)
    span, items = neighbourhood_segments(first, cells, segments, ax.size)
    return nearest_segment_distance(nearest_x, nearest_y, first, span, items, ax, ay, bx, by, grid.x, grid.y, pad)


def _distance(grid_shape, distance):
    distance = field("distance", distance, grid_shape, allow_inf=True)
    if (distance < 0).any():
        raise SizingError("distance must be non-negative (ground metres to the coastline)")
    return distance


def distance_size(distance, *, min_edge_length, rate):
    """Linear distance size function, guide eq. 2: ``f_dis = h0 + alpha_d d``.

    Parameters
    ----------
    distance : array_like
        Ground distance ``d`` to the coastline, metres (from
        :func:`distance_to_coastline`); ``inf`` gives ``inf``.
    min_edge_length : float
        ``h0``, metres.
    rate : float
        ``alpha_d``: metres of edge length per metre of distance
        (dimensionless; the guide's "percent change per decimal degree" is
        the same ratio with both lengths in degrees). The guide gives no
        default; oceanmesh uses 0.15.

    Returns
    -------
    ndarray
        Edge lengths, ground metres, the shape of ``distance``.

    Examples
    --------
    >>> distance_size([0.0, 1000.0], min_edge_length=100.0, rate=0.15).tolist()
    [100.0, 250.0]
    """
    min_edge_length = positive("min_edge_length", min_edge_length)
    rate = positive("rate", rate)
    distance = _distance(None, distance)
    return min_edge_length + rate * distance


def land_gap_steps(water, axis):
    """Grid steps between the land nodes before and after each node along ``axis`` (about 2**30 without land)."""
    return land_gap(np.ascontiguousarray(water, dtype=np.bool_), axis, _NO_LAND)


def approximate_medial_axis(grid, distance, water, *, min_edge_length):
    """Nodes on the approximate medial axis of the water, guide §3.1, pruned of spurious points.

    The guide's test: the gradient of a distance function has norm 1
    except where the nearest coastline point jumps (the medial axis, the
    skeleton between two coasts), where central differences straddle the
    ridge and give less, so a node is a candidate when ``|grad s| <= 0.90``
    (``s`` the signed distance, negative in the water, so that the
    coastline itself, where ``|d|`` has a kink, stays off the axis; the
    gradient is per ground metre, by central differences). The gradient
    also falls at convex land corners (an island's corner, a headland's
    tip), where the axis of the *land* runs into the corner and the water
    nodes around it straddle the corner or a tip thinner than a grid step;
    these points are not between two coasts, and they shrink the feature
    size around every such corner to a fraction of ``h0``. As OceanMesh2D's
    code does (the guide's text says only ``d <= h0``), a candidate is kept
    only

    * in the water (the land's own axis is what runs into convex corners);
    * deeper than ``h0 / 2`` from the coast, where the corners' spurious
      points do not reach, *or* in narrow water: the land nodes on either
      side along a grid axis at most ``sqrt(2) (h0 + step) + 2 step``
      apart. A channel up to ``h0 + step`` wide may have all its axis
      nodes (each within half a step of the centre line) within ``h0 / 2``
      of the coast; crossing the grid at 45 degrees it spans ``sqrt(2)``
      times its width along either grid axis, and the land nodes lie up
      to a step beyond each bank. Without this exception such channels
      lose their axis, and their feature size becomes that of the next
      channel (or inf); OceanMesh2D patches only channels one node wide;
    * with company: at least 3 other kept nodes within 6 nodes (Chebyshev),
      which the one or two nodes left at an island's corner on a coarse
      grid have not, and a curve has even where it is dotted (far from the
      coast, where the two nearest coasts lie in nearly the same direction,
      only nodes close to the ridge pass the gradient test): nodes up to 3
      steps apart along it, 2 at its ends (OceanMesh2D asks for a "line of
      around 7 points" in much the same way).

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    distance : array_like, shape (nx, ny)
        Ground distance to the coastline, metres (finite).
    water : array_like of bool, shape (nx, ny)
        True in the water (:func:`water_mask`).
    min_edge_length : float
        ``h0``, metres.

    Returns
    -------
    ndarray of bool, shape (nx, ny)
        True on the axis; always False on land.

    Examples
    --------
    >>> import numpy as np, shapely
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 0.3, 0, 0.2), 1e3)
    >>> banks = shapely.MultiLineString([[(-1, 0.05), (1, 0.05)], [(-1, 0.15), (1, 0.15)]])
    >>> d = distance_to_coastline(grid, banks)
    >>> water = np.broadcast_to((grid.lat > 0.05) & (grid.lat < 0.15), grid.shape)
    >>> axis = approximate_medial_axis(grid, d, water, min_edge_length=1e3)
    >>> sorted(set(np.round(grid.lat[np.nonzero(axis)[1]], 3).tolist()))
    [0.099, 0.108]
    """
    grid = check_grid(grid)
    min_edge_length = positive("min_edge_length", min_edge_length)
    distance = _distance(grid.shape, distance)
    if np.isinf(distance).any():
        raise SizingError("distance has inf values: the medial axis needs a coastline that reaches the grid")
    water = mask("water", water, grid.shape)
    axis = water & (ground_gradient_norm(grid, distance, water) <= MEDIAL_AXIS_GRADIENT)
    shallow = axis & (distance <= _MEDIAL_AXIS_DEPTH * min_edge_length)
    if shallow.any():
        widest = np.sqrt(2.0) * (min_edge_length / grid.ground_step + 1.0) + 2.0  # steps, per row (ny,)
        narrow = (land_gap_steps(water, 0) <= widest) | (land_gap_steps(water, 1) <= widest)
        axis &= ~shallow | narrow
    axis = with_company(np.ascontiguousarray(axis), _MEDIAL_AXIS_REACH, _MEDIAL_AXIS_COMPANY)
    return axis


def feature_size(grid, distance, water, *, min_edge_length, elements_per_feature=3, fallback_rate=DEFAULT_GRADE):
    """Feature size function, guide eq. 3-4: ``f_fs = W / R = 2 (d_MA + d) / R``.

    ``d`` is the distance to the coastline and ``d_MA`` the distance from
    the node to the nearest node of the approximate medial axis
    (:func:`approximate_medial_axis`): across a channel of width ``W``,
    ``d + d_MA = W / 2`` at every node, so the channel gets ``R`` elements
    across. ``d_MA`` is found with a Euclidean distance transform on the
    grid and measured in ground metres as in :func:`distance_to_coastline`
    (Mercator length times ``cos(lat)`` at the middle). Land nodes get
    the same formula (OceanMesh2D also uses ``|d|`` there, for
    floodplains). Without any medial-axis node on the grid (a straight
    coast, an island alone in open water) there is no feature to measure,
    and, as OceanMesh2D's ``featfx`` does, the distance function
    ``h0 + fallback_rate d`` (eq. 2) is returned instead, with a warning.

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    distance : array_like, shape (nx, ny)
        Ground distance to the coastline, metres (:func:`distance_to_coastline`).
    water : array_like of bool, shape (nx, ny)
        True in the water.
    min_edge_length : float
        ``h0``, metres (enters the medial-axis test).
    elements_per_feature : float, optional
        ``R``, elements across a feature (the guide's examples use 3).
    fallback_rate : float, optional
        ``alpha_d`` of the distance function used when the grid holds no
        medial-axis node; OceanMesh2D takes the grade ``g`` (default
        :data:`~terramesh.sizing.DEFAULT_GRADE`, 0.2).

    Returns
    -------
    ndarray, shape (nx, ny)
        Ground metres.

    Warns
    -----
    TerrameshWarning
        When the grid holds no medial-axis node, and the distance function
        is returned.

    Examples
    --------
    >>> import numpy as np, shapely
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 0.3, 0, 0.2), 1e3)
    >>> banks = shapely.MultiLineString([[(-1, 0.05), (1, 0.05)], [(-1, 0.15), (1, 0.15)]])
    >>> water = np.broadcast_to((grid.lat > 0.05) & (grid.lat < 0.15), grid.shape)
    >>> fs = feature_size(grid, distance_to_coastline(grid, banks), water, min_edge_length=1e3)
    >>> width = 0.1 * np.pi / 180 * 6378137.0
    >>> bool(abs(fs[15, 10] - width / 3) < 0.05 * width / 3)
    True
    """
    grid = check_grid(grid)
    elements_per_feature = positive("elements_per_feature", elements_per_feature)
    fallback_rate = positive("fallback_rate", fallback_rate)
    medial = approximate_medial_axis(grid, distance, water, min_edge_length=min_edge_length)
    distance = _distance(grid.shape, distance)
    if not medial.any():
        warn_user(
            "no node is on the approximate medial axis (a straight coast, or islands alone in open water): the "
            f"feature size (fs) falls back to the distance function h0 + {fallback_rate:g} d (eq. 2), as "
            "OceanMesh2D's does; give dis for another rate",
        )
        return distance_size(distance, min_edge_length=min_edge_length, rate=fallback_rate)
    nearest_x, nearest_y = nearest_feature(np.ascontiguousarray(medial))
    to_axis = nearest_node_distance(nearest_x, nearest_y, grid.x, grid.y)
    to_axis += distance
    to_axis *= 2.0 / elements_per_feature
    return to_axis


def shoreline_size(
    grid, distance, water=None, *, min_edge_length, rate=None, elements_per_feature=None, fallback_rate=DEFAULT_GRADE
):
    """The coastline's size function ``f_hd``: eq. 2 (``rate``) or eq. 3-4 (``elements_per_feature``), never both.

    The guide makes the two mutually exclusive (§3.1); this is where that
    is enforced. ``f_hd`` is also what the automatic time step of eq. 12
    (:func:`~terramesh.coastal.sizes.cfl_timestep`) preserves.

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    distance : array_like, shape (nx, ny)
        Ground distance to the coastline, metres.
    water : array_like of bool, shape (nx, ny), optional
        True in the water; needed by the feature size.
    min_edge_length : float
        ``h0``, metres.
    rate : float, optional
        ``alpha_d`` of eq. 2 (the guide's ``dis``).
    elements_per_feature : float, optional
        ``R`` of eq. 3-4 (the guide's ``fs``).
    fallback_rate : float, optional
        The feature size's rate where the grid has no medial axis (see
        :func:`feature_size`).

    Returns
    -------
    ndarray, shape (nx, ny)
        Ground metres.

    Raises
    ------
    SizingError
        If both or neither of ``rate`` and ``elements_per_feature`` are given.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 1, 0, 1), 50e3)
    >>> shoreline_size(grid, np.zeros(grid.shape), min_edge_length=100.0, rate=0.2).max()
    np.float64(100.0)
    """
    if (rate is None) == (elements_per_feature is None):
        raise SizingError(
            "give exactly one of the distance function (dis, distance_rate, rate: eq. 2) and the feature size "
            "(fs, feature_size, elements_per_feature: eq. 3-4): the guide makes them mutually exclusive"
        )
    grid = check_grid(grid)
    if rate is not None:
        distance = _distance(grid.shape, distance)
        return distance_size(distance, min_edge_length=min_edge_length, rate=rate)
    if water is None:
        raise SizingError("the feature size needs the water mask (water_mask(grid, water_polygon))")
    return feature_size(
        grid,
        distance,
        water,
        min_edge_length=min_edge_length,
        elements_per_feature=elements_per_feature,
        fallback_rate=fallback_rate,
    )
