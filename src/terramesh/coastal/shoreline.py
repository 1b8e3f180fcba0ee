"""Shorelines (guide section 2.5): land polygons in a box, resampled to the mesh size and classified.

A :class:`Shoreline` turns land polygons (from an ESRI shapefile or
GeoPackage, from shapely geometry, or from a DEM contour) into what the mesh
generator and the size functions need, all in WGS84 longitude-latitude
degrees:

- ``water``: the box minus the land, the region to mesh (:meth:`Shoreline.domain`
  gives it on the Mercator plane as a :class:`~terramesh.geometry.Polygon`);
- ``mainland`` (land that reaches the box edge) and ``islands`` (land wholly
  inside it), whose boundaries inside the box form the ``coastline``;
- ``open_boundary``: the parts of the box edge that are water.

Processing, in order
--------------------
1. Features near the box are read (only those whose extent meets it), shifted
   by whole turns of longitude onto the box (files in 0..360 or -180..180,
   boxes across the antimeridian), repaired with ``shapely.make_valid`` when
   invalid (with a warning), and clipped to the box widened by ``2 h0``.
2. Overlapping or adjacent polygons (tiles, pieces split at 180 degrees) are
   merged; land smaller than ``minimum_island_area`` is dropped and lakes
   smaller than it are filled.
3. Every ring is resampled at equal ground arc length, ``h0 / 2`` or just
   under: long segments are densified and dense vertices decimated. Then one
   (``smooth``) pass of the ``[1/4, 1/2, 1/4]`` moving average along each ring
   takes the corners off without moving a straight or gently curved shore
   (a bend of radius ``r`` moves inwards by about ``h0**2 / (16 r)``).
4. The result is repaired and merged again, cut to the box (whose edge is
   densified to ``h0 / 2``), small parts and lakes dropped again, and the
   water is the box minus the land, so that land and water tile the box.
"""

import numbers
import os
import pathlib

import numpy as np
import shapely

from ..errors import GeometryError, MeshFormatError, SizingError, checked_number, warn_user
from ..geometry.polygon import Polygon
from .dem import DEM
from .grid import as_lonlat_box
from .projection import EARTH_RADIUS, to_mercator

__all__ = ["Shoreline", "read_shoreline", "DEFAULT_ISLAND_AREA_FACTOR"]

_METRES_PER_DEGREE = EARTH_RADIUS * np.pi / 180.0

DEFAULT_ISLAND_AREA_FACTOR = 4.0
"""Default ``minimum_island_area`` is this times ``h0**2``: land (and lakes) smaller than a ``2 h0`` square.

Such a feature is at most about two ``h0`` elements across, too few for the
mesh to represent its shape. The factor is oceanmesh's ``minimum_area_mult``
default, which that package applies to ``(h0 / 2)**2``; applied here to
``h0**2`` it drops features four times larger.
"""

_EDGE_TOLERANCE = 1e-9
MAX_RING_VERTICES = 5e7
"""Most vertices the shoreline and box edge may be resampled into (about 10 GB on the way through shapely)."""
"""Degrees: a vertex this close to the box boundary is on it (about 0.1 mm)."""

_MARGIN_EDGES = 2.0
"""Features are clipped to the box widened by this many ``h0``, so that resampling never moves the box edge."""

_NO_POLYGONS = np.empty(0, dtype=object)

_OPEN_WATER_HINT = "; to mesh open water alone, pass require_land=False (terramesh coastal --open-water)"


# ----------------------------------------------------------------------------------------------------------------
# small vectorized helpers on arrays of shapely geometries


def _ground_area(geometries):
    """Approximate ground area (m**2) of longitude-latitude polygons: degree area times the local metric."""
    geometries = np.asarray(geometries, dtype=object)
    if geometries.size == 0:
        return np.zeros(0)
    bounds = shapely.bounds(geometries)
    lat = np.radians(0.5 * (bounds[:, 1] + bounds[:, 3]))
    return shapely.area(geometries) * _METRES_PER_DEGREE**2 * np.cos(lat)


def _polygons_of(geometries):
    """Every polygon in the given geometries (multi-parts and collections flattened), as an array."""
    parts = np.asarray(geometries, dtype=object).ravel()
    parts = parts[~shapely.is_missing(parts)]
    for _ in range(3):  # collection -> multipolygon -> polygon
        parts = shapely.get_parts(parts)
    parts = parts[~shapely.is_empty(parts)]
    return parts[shapely.get_type_id(parts) == shapely.GeometryType.POLYGON]


def _multipolygon(polygons):
    polygons = _polygons_of(polygons)
    return shapely.MultiPolygon(list(polygons)) if len(polygons) else shapely.MultiPolygon()


def _repaired(polygons):
    """Valid polygons from possibly invalid ones (``make_valid``, polygonal parts kept)."""
    polygons = np.asarray(polygons, dtype=object)
    invalid = ~shapely.is_valid(polygons)
    if not invalid.any():
        return polygons, 0
    # make_valid raises GEOS's own error on NaN coordinates: name them instead
    bad = ~np.isfinite(shapely.get_coordinates(polygons[invalid])).all(axis=1)
    if bad.any():
        raise GeometryError(
            f"{int(bad.sum())} land polygon vertices have NaN or infinite coordinates: drop or fix them"
        )
    fixed = _polygons_of(shapely.make_valid(polygons[invalid]))
    return np.concatenate([polygons[~invalid], fixed]), int(invalid.sum())


def _merged(polygons):
    """The union of the polygons, as an array of disjoint valid polygons."""
    polygons, _ = _repaired(polygons)
    if len(polygons) == 0:
        return polygons
    return _polygons_of(shapely.union_all(polygons))


def _drop_small(polygons, minimum_area):
    """Polygons of at least ``minimum_area`` ground m**2, with their lakes under it filled."""
    polygons = _polygons_of(polygons)
    if minimum_area <= 0 or len(polygons) == 0:
        return polygons
    polygons = polygons[_ground_area(polygons) >= minimum_area]
    if len(polygons) == 0 or shapely.get_num_interior_rings(polygons).sum() == 0:
        return polygons
    rings, owner = shapely.get_rings(polygons, return_index=True)
    first = np.r_[True, owner[1:] != owner[:-1]]
    keep = first | (_ground_area(shapely.polygons(rings)) >= minimum_area)
    return shapely.polygons(rings[keep], indices=owner[keep])


def _shifted(geometries, shift):
    if shift == 0:
        return geometries
    return shapely.transform(geometries, lambda xy: xy + np.array([shift, 0.0]))


# ----------------------------------------------------------------------------------------------------------------
# rings: resampling at a ground spacing, densifying, splitting into runs


def _ring_layout(ring_index):
    """First vertex and vertex count of each ring of a flat (closed rings) coordinate array."""
    starts = np.flatnonzero(np.r_[True, ring_index[1:] != ring_index[:-1]])
    counts = np.diff(np.r_[starts, len(ring_index)])
    return starts, counts


def segment_lengths(a, b):
    """Ground length (metres) of the segments a -> b, longitude-latitude degrees, shape (n, 2)."""
    cos_lat = np.cos(np.radians(0.5 * (a[:, 1] + b[:, 1])))
    return _METRES_PER_DEGREE * np.hypot((b[:, 0] - a[:, 0]) * cos_lat, b[:, 1] - a[:, 1])


def _check_vertex_count(count, length, spacing):
    """Refuse to resample ``length`` metres of rings into more than ``MAX_RING_VERTICES`` vertices.

    A min_edge_length given in degrees (0.001 for 100 m) made 9e8 vertices of
    a 1-degree box and the process was killed for memory, with no message.
    """
    if count > MAX_RING_VERTICES:
        raise GeometryError(
            f"resampling {length / 1e3:,.0f} km of shoreline and box edge every {spacing:.3g} m (min_edge_length / 2) "
            f"would make {count:.3g} vertices, more than {MAX_RING_VERTICES:.0e}: min_edge_length is in metres "
            "(a degree is about 111 km); raise it or mesh a smaller box"
        )


def _resample_rings(coords, ring_index, spacing, smooth):
    """Closed rings resampled at equal ground arc length of at most ``spacing`` metres, then smoothed.

    Parameters
    ----------
    coords : ndarray, shape (n, 2)
        Vertices of closed rings (each ring ends with its first vertex),
        ring after ring, longitude-latitude degrees.
    ring_index : ndarray, shape (n,)
        Ring of each vertex, non-decreasing.
    spacing : float
        Largest ground distance between new vertices, metres.
    smooth : int
        Passes of the ``[1/4, 1/2, 1/4]`` moving average along each ring.

    Returns
    -------
    coords, ring_index : ndarray
        The new closed rings; every ring has at least 4 distinct vertices.
    """
    starts, counts = _ring_layout(ring_index)
    n_rings = len(starts)
    length = segment_lengths(coords[:-1], coords[1:])
    same_ring = ring_index[1:] == ring_index[:-1]
    # Arc length along all rings, with a gap between rings so that it strictly increases across them.
    arc = np.r_[0.0, np.cumsum(np.where(same_ring, length, spacing))]
    ring_start = arc[starts]
    ring_length = arc[starts + counts - 1] - ring_start
    n_new = np.maximum(np.ceil(ring_length / spacing - 1e-9), 4)
    _check_vertex_count(n_new.sum(), ring_length.sum(), spacing)
    n_new = n_new.astype(np.intp)
    new_starts = np.r_[0, np.cumsum(n_new)[:-1]]
    new_ring = np.repeat(np.arange(n_rings), n_new)
    k = np.arange(n_new.sum()) - new_starts[new_ring]
    position = ring_start[new_ring] + k * (ring_length / n_new)[new_ring]
    segment = np.searchsorted(arc, position, side="right") - 1
    segment = np.clip(segment, starts[new_ring], starts[new_ring] + counts[new_ring] - 2)
    span = arc[segment + 1] - arc[segment]
    t = np.divide(position - arc[segment], span, out=np.zeros_like(span), where=span > 0)
    points = coords[segment] + t[:, None] * (coords[segment + 1] - coords[segment])
    if smooth:
        before = np.where(k == 0, new_starts[new_ring] + n_new[new_ring] - 1, np.arange(len(k)) - 1)
        after = np.where(k == n_new[new_ring] - 1, new_starts[new_ring], np.arange(len(k)) + 1)
        for _ in range(int(smooth)):
            points = 0.5 * points + 0.25 * (points[before] + points[after])
    closed = np.insert(np.arange(len(points)), new_starts + n_new, new_starts)
    return points[closed], np.repeat(np.arange(n_rings), n_new + 1)


def _resample_polygons(polygons, spacing, smooth):
    """Polygons with every ring resampled by :func:`_resample_rings` (possibly invalid: repair them)."""
    if len(polygons) == 0:
        return polygons
    rings, owner = shapely.get_rings(polygons, return_index=True)
    coords, ring_index = shapely.get_coordinates(rings, return_index=True)
    coords, ring_index = _resample_rings(coords, ring_index, spacing, smooth)
    new_rings = shapely.linearrings(coords, indices=ring_index)
    return shapely.polygons(new_rings, indices=owner)


def _densify_polygons(polygons, spacing):
    """Polygons with vertices added on segments longer than ``spacing`` ground metres (none moved)."""
    rings, owner = shapely.get_rings(polygons, return_index=True)
    coords, ring_index = shapely.get_coordinates(rings, return_index=True)
    same_ring = ring_index[1:] == ring_index[:-1]
    a, b = coords[:-1][same_ring], coords[1:][same_ring]
    lengths = segment_lengths(a, b)
    pieces = np.maximum(np.ceil(lengths / spacing - 1e-9), 1)
    _check_vertex_count(pieces.sum(), lengths.sum(), spacing)
    pieces = pieces.astype(np.intp)
    segment = np.repeat(np.arange(len(a)), pieces)
    t = (np.arange(pieces.sum()) - np.repeat(np.cumsum(pieces) - pieces, pieces)) / pieces[segment]
    points = a[segment] + t[:, None] * (b[segment] - a[segment])
    index = ring_index[:-1][same_ring][segment]
    last = np.flatnonzero(np.r_[index[1:] != index[:-1], True])
    points = np.insert(points, last + 1, coords[np.r_[np.flatnonzero(~same_ring), len(coords) - 1]], axis=0)
    index = np.insert(index, last + 1, index[last])
    return shapely.polygons(shapely.linearrings(points, indices=index), indices=owner)


def _runs(rings, keep_segment):
    """Lines made of the maximal runs of ring segments for which ``keep_segment(a, b)`` is true.

    A ring kept whole comes back as one closed line. Vectorized over rings,
    except for a loop over the runs of rings that are kept in part.
    """
    rings = np.asarray(rings, dtype=object)
    if len(rings) == 0:
        return shapely.MultiLineString()
    coords, ring_index = shapely.get_coordinates(rings, return_index=True)
    same_ring = ring_index[1:] == ring_index[:-1]
    a, b = coords[:-1], coords[1:]
    keep = np.zeros(len(a), dtype=bool)
    keep[same_ring] = keep_segment(a[same_ring], b[same_ring])
    segments = np.bincount(ring_index[:-1][same_ring], minlength=len(rings))
    kept = np.bincount(ring_index[:-1][keep], minlength=len(rings))
    lines = []
    whole = (kept == segments) & (segments > 0)
    if whole.any():
        mask = whole[ring_index]
        _, dense_index = np.unique(ring_index[mask], return_inverse=True)
        lines.extend(shapely.linestrings(coords[mask], indices=dense_index))
    starts, counts = _ring_layout(ring_index)
    for ring in np.flatnonzero((kept > 0) & ~whole):
        start, count = starts[ring], counts[ring]
        flags = keep[start : start + count - 1]
        first_dropped = int(np.argmin(flags))
        flags = np.roll(flags, -first_dropped)
        points = np.roll(coords[start : start + count - 1], -first_dropped, axis=0)
        points = np.vstack([points, points[:1]])
        change = np.diff(np.r_[0, flags.astype(np.int8), 0])
        for run_start, run_end in zip(np.flatnonzero(change == 1), np.flatnonzero(change == -1), strict=True):
            lines.append(shapely.LineString(points[run_start : run_end + 1]))
    return shapely.MultiLineString(lines)


# ----------------------------------------------------------------------------------------------------------------
# input geometry: the box, polygons or closed lines


def region_of(bbox):
    """The box as ``(lon_min, lon_max, lat_min, lat_max)``, its polygon, and whether it is a rectangle."""
    if isinstance(bbox, shapely.Geometry):
        if not isinstance(bbox, (shapely.Polygon, shapely.MultiPolygon)) or bbox.is_empty:
            raise GeometryError(
                "bbox must be (lon_min, lon_max, lat_min, lat_max) or a non-empty shapely Polygon in degrees,"
                f" got {bbox.geom_type}"
            )
        if not bbox.is_valid:
            raise GeometryError(f"the bbox polygon is invalid: {shapely.is_valid_reason(bbox)}")
        x0, y0, x1, y1 = bbox.bounds
        box = as_lonlat_box((x0, x1, y0, y1))
        region = _shifted(bbox, box[0] - x0)
        rectangle = bool(shapely.equals(region, shapely.box(box[0], box[2], box[1], box[3])))
        return box, region, rectangle
    box = as_lonlat_box(bbox)
    return box, shapely.box(box[0], box[2], box[1], box[3]), True


def _margin(box, h0):
    """The widening of the box, degrees of longitude and latitude, that holds ``_MARGIN_EDGES * h0`` on the ground."""
    widest = min(max(abs(box[2]), abs(box[3])), 89.0)
    north = _MARGIN_EDGES * h0 / _METRES_PER_DEGREE
    return min(north / np.cos(np.radians(widest)), 10.0), min(north, 10.0)


def _closed_lines_to_polygons(lines, source):
    """Polygons bounded by closed lines, by the even-odd rule (a ring inside another is a lake)."""
    merged = shapely.get_parts(shapely.line_merge(shapely.MultiLineString(list(shapely.get_parts(lines)))))
    coords_first = shapely.get_coordinates(shapely.get_point(merged, 0))
    coords_last = shapely.get_coordinates(shapely.get_point(merged, -1))
    open_ = ~np.all(np.abs(coords_first - coords_last) <= 1e-9, axis=1) | (shapely.get_num_coordinates(merged) < 4)
    if open_.any():
        x, y = coords_first[np.argmax(open_)]
        raise GeometryError(
            f"{source}: {int(open_.sum())} of {len(merged)} coastline lines do not close into rings"
            f" (the first starts at lon {x:.6g}, lat {y:.6g}); coastlines given as lines must form closed rings,"
            " or give land polygons"
        )
    shells, _ = _repaired(
        shapely.polygons(shapely.linearrings(shapely.get_coordinates(merged), indices=_line_index(merged)))
    )
    if len(shells) < 2:
        return shells
    tree = shapely.STRtree(shells)
    inner, outer = tree.query(shapely.get_point(shapely.get_exterior_ring(shells), 0), predicate="within")
    depth = np.bincount(inner[inner != outer], minlength=len(shells))
    # Rings do not cross, so the rings at depth d + 1 lie inside those at depth d: land is the union over even d
    # of (rings at depth d) minus (rings at depth d + 1).
    level = [shapely.union_all(shells[depth == d]) for d in range(int(depth.max()) + 2)]
    land = [shapely.difference(level[d], level[d + 1]) for d in range(0, len(level) - 1, 2)]
    return _polygons_of(land)


def _line_index(lines):
    return np.repeat(np.arange(len(lines)), shapely.get_num_coordinates(lines))


def _rings_from_arrays(value, source):
    """Closed lines from the guide's NaN-delimited (k, 2) lon/lat polygon vector, or a list of (k, 2) arrays; else None.

    The guide (§2.5) gives land as one array of vertices whose polygons are
    separated by rows of NaN; each polygon is closed here if it is not.
    """
    if isinstance(value, shapely.Geometry) or isinstance(value, (str, bytes, os.PathLike)):
        return None
    items = [value] if isinstance(value, np.ndarray) and value.dtype != object else list(value)
    if not items or any(isinstance(item, shapely.Geometry) or item is None for item in items):
        return None
    rings = []
    for number, item in enumerate(items, start=1):
        try:
            vertices = np.asarray(item, dtype=np.float64)
        except (TypeError, ValueError):
            return None
        if vertices.ndim != 2 or vertices.shape[1] != 2:
            raise GeometryError(f"{source}: polygon array {number} must be (k, 2) lon/lat, got shape {vertices.shape}")
        gaps = np.isnan(vertices).any(axis=1)
        if np.isinf(vertices).any():
            raise GeometryError(f"{source}: polygon array {number} holds infinite coordinates")
        for piece in np.split(vertices, np.flatnonzero(gaps)):
            piece = piece[~np.isnan(piece).any(axis=1)]
            if len(piece) == 0:
                continue
            if len(np.unique(piece, axis=0)) < 3:
                raise GeometryError(f"{source}: a polygon of array {number} has fewer than 3 distinct vertices")
            if not np.array_equal(piece[0], piece[-1]):
                piece = np.vstack([piece, piece[:1]])
            rings.append(shapely.linearrings(piece))
    return rings


def _land_polygons(geometries, source):
    """Land polygons (possibly invalid) from polygons, multi-polygons, closed lines or collections of them.

    Arrays of vertices are rings too: the guide's NaN-delimited polygon
    vector, or a list of (k, 2) arrays (:func:`_rings_from_arrays`).
    """
    rings = _rings_from_arrays(geometries, source)
    if rings is not None:
        geometries = rings
    if isinstance(geometries, shapely.Geometry):
        geometries = [geometries]
    try:
        geometries = np.asarray(geometries, dtype=object).ravel()
    except (TypeError, ValueError):
        raise GeometryError(f"{source}: land must be shapely geometries") from None
    if not all(isinstance(geometry, shapely.Geometry) for geometry in geometries if geometry is not None):
        raise GeometryError(f"{source}: land must be shapely geometries (polygons or closed lines)")
    parts = np.asarray(geometries, dtype=object)
    parts = parts[~shapely.is_missing(parts)]
    for _ in range(3):
        parts = shapely.get_parts(parts)
    parts = parts[~shapely.is_empty(parts)]
    kind = shapely.get_type_id(parts)
    polygons = parts[kind == shapely.GeometryType.POLYGON]
    is_line = (kind == shapely.GeometryType.LINESTRING) | (kind == shapely.GeometryType.LINEARRING)
    if is_line.any():
        polygons = np.concatenate([polygons, _closed_lines_to_polygons(parts[is_line], source)])
    if len(parts) and not len(polygons):
        kinds = sorted({geometry.geom_type for geometry in parts})
        raise GeometryError(f"{source} has no polygons or lines, only {', '.join(kinds)}")
    return polygons


# ----------------------------------------------------------------------------------------------------------------
# reading files


def _wgs84_transformer(crs, path):
    """A transformer to WGS84 longitude-latitude, or None when the data already are; and if they are geographic."""
    import pyproj

    try:
        source = pyproj.CRS.from_user_input(crs)
    except pyproj.exceptions.CRSError as error:
        raise GeometryError(f"{path}: unusable CRS {crs!r}: {error}") from None
    wgs84 = pyproj.CRS.from_epsg(4326)
    if source.equals(wgs84, ignore_axis_order=True) or source.equals(pyproj.CRS("OGC:CRS84")):
        return None, True
    return pyproj.Transformer.from_crs(source, wgs84, always_xy=True), source.is_geographic


def _lon_pieces(west, east):
    """The longitude range ``west..east`` (degrees, any turn) as pieces within -180..180, split at 180 degrees."""
    if east - west >= 360.0:
        return [(-180.0, 180.0)]
    shift = 360.0 * np.floor((west + 180.0) / 360.0)
    west, east = west - shift, east - shift  # west now in -180..180
    if east <= 180.0:
        return [(west, east)]
    return [(west, 180.0), (-180.0, east - 360.0)]


def _land_layer(path, layers, layer):
    """The layer of ``path`` to read as the land: ``layer`` (a name or a 0-based number) or the one land layer.

    ``layers``: pyogrio's ``list_layers``, rows of (name, geometry type,
    None for an attribute table). A number that is also a layer's name is
    the name (layers named by year, ``--layer 2020`` on the command line).
    Without ``layer``, the land is the file's polygon layers (and those of
    any geometry), or else its line layers (closed lines bound land); with
    several, which one is refused: GDAL reads the first, and a GeoPackage's
    points layer read as the land failed later as "no land polygon in the
    bbox", with advice to mesh open water. None: the file's only layer.
    """
    names = [str(name) for name, _ in layers]
    shown = ", ".join(f"{name} ({kind or 'no geometry'})" for name, kind in layers)
    if layer is not None:
        number = isinstance(layer, numbers.Integral) and not isinstance(layer, bool)
        if number and str(layer) in names:
            return str(layer)
        if (number and 0 <= layer < len(names)) or (isinstance(layer, str) and layer in names):
            return int(layer) if number else layer
        raise GeometryError(
            f"the shoreline file {path.name} has no layer {layer!r}; choose one of its {len(names)} layers by name or"
            f" 0-based number: {shown}"
        )
    if len(layers) < 2:
        return None
    # a layer of any geometry ('Unknown', a collection) may hold the polygons
    polygons = [str(name) for name, kind in layers if _kind_of(kind, ("polygon", "surface", "unknown", "collection"))]
    lines = [str(name) for name, kind in layers if _kind_of(kind, ("line", "curve", "string"))]
    candidates = polygons or lines
    if len(candidates) == 1:
        return candidates[0]
    if not candidates:
        raise GeometryError(f"the shoreline file {path.name} has no layer of land polygons or coastline lines: {shown}")
    shown = ", ".join(f"{name} ({kind})" for name, kind in layers if str(name) in candidates)
    kind = "polygon" if polygons else "line"
    raise GeometryError(
        f"the shoreline file {path.name} has {len(candidates)} {kind} layers: {shown}; choose the land's with "
        f"layer={candidates[0]!r} (a name or a 0-based number)"
    )


def _kind_of(kind, words):
    """Whether a layer's geometry type (pyogrio's name, None for an attribute table) holds one of ``words``."""
    return kind is not None and any(word in str(kind).lower() for word in words)


def _read_features(path, box, h0, crs, layer, require_land):
    """Geometries of the features of ``path`` near the box, in WGS84 longitude-latitude (any longitude turn).

    A box beyond the file's extent is an error, unless ``require_land`` is
    False (open water: a regional coastline ends short of an offshore box).
    """
    path = pathlib.Path(os.fspath(path))
    if not path.exists():
        raise FileNotFoundError(f"shoreline file not found: {path}")
    if path.is_dir() and path.suffix.lower() != ".gdb":  # GDAL would read whichever file it finds first
        found = sorted(child.name for child in path.glob("*.shp"))[:5]
        raise GeometryError(f"the shoreline {path} is a folder: give the file itself (shapefiles in it: {found})")
    import pyogrio
    import pyogrio.errors

    errors = (pyogrio.errors.DataSourceError, pyogrio.errors.DataLayerError, pyogrio.errors.FeatureError)
    try:
        layer = _land_layer(path, pyogrio.list_layers(path), layer)
        info = pyogrio.read_info(path, layer=layer, force_total_bounds=True)
    except errors as error:
        raise MeshFormatError(
            f"cannot read the shoreline file {path} (not a vector file, or corrupt?): {error}"
        ) from None
    if info["features"] == 0:
        raise GeometryError(f"the shoreline file {path} has no features")
    file_crs = crs if crs is not None else info["crs"]
    projection_file = path.with_suffix(".prj")
    if file_crs is None and path.suffix.lower() == ".shp" and projection_file.exists():
        raise MeshFormatError(f"cannot read the CRS in {projection_file}: mend it, or pass crs=... (e.g. 'EPSG:4326')")
    x0, y0, x1, y1 = (float(v) for v in info["total_bounds"])
    extent = f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}"
    if file_crs is None:
        if not (-360 <= x0 and x1 <= 360 and -90 <= y0 and y1 <= 90):
            raise GeometryError(
                f"the shoreline file {path} has no CRS and its coordinates ({extent}) are not degrees: pass crs=... "
                "(its projection, e.g. 'EPSG:32619' for UTM zone 19N)"
            )
        transformer, geographic = None, True
    else:
        transformer, geographic = _wgs84_transformer(file_crs, path)
    mx, my = _margin(box, h0)
    lon_min, lon_max, lat_min, lat_max = box
    if geographic:
        windows = [
            (lon_min - mx - shift, max(lat_min - my, -90.0), lon_max + mx - shift, min(lat_max + my, 90.0))
            for shift in (-360.0, 0.0, 360.0)
        ]
    else:
        import pyproj

        back = pyproj.Transformer.from_crs(pyproj.CRS.from_epsg(4326), transformer.source_crs, always_xy=True)
        south, north = max(lat_min - my, -90.0), min(lat_max + my, 90.0)
        # A box across 180 degrees is read as its pieces on each side: transformed whole, its far side wraps to
        # the other end of the world and the window reached only as far as its sample points (land within
        # 0.1-0.2 degrees of 180 was dropped).
        windows = []
        for west, east in _lon_pieces(lon_min - mx, lon_max + mx):
            bounds = back.transform_bounds(west, south, east, north, densify_pts=21)
            if np.all(np.isfinite(bounds)):
                windows.append(tuple(float(v) for v in bounds))
    windows = [w for w in windows if w[0] <= x1 and w[2] >= x0 and w[1] <= y1 and w[3] >= y0]
    if not windows and require_land:
        raise GeometryError(
            f"the bbox {box} does not overlap the shoreline file {path.name} ({extent} in its CRS){_OPEN_WATER_HINT}"
        )
    if not windows:
        return _NO_POLYGONS
    fids, wkb = [], []
    try:
        for window in windows:
            _, window_fids, geometry, _ = pyogrio.raw.read(
                path, layer=layer, bbox=window, columns=[], return_fids=True, force_2d=True
            )
            fids.append(window_fids)
            wkb.append(geometry)
    except errors as error:
        raise MeshFormatError(f"cannot read the shoreline file {path} (truncated or corrupt?): {error}") from None
    fids, first = np.unique(np.concatenate(fids), return_index=True)
    wkb = np.concatenate(wkb)[first]
    geometries = shapely.from_wkb(wkb, on_invalid="ignore")
    missing = shapely.is_missing(geometries)
    # bytes GDAL read as a shape that is none: a corrupt record, whose land the mesh would take for water
    unreadable = missing & np.array([shape is not None for shape in wkb], dtype=bool)
    if unreadable.any():
        raise MeshFormatError(
            f"cannot read the shoreline file {path}: {int(unreadable.sum())} of the {len(wkb)} features near the box "
            f"are corrupt (feature ids {fids[unreadable][:5].tolist()}); the file is damaged"
        )
    geometries = geometries[~missing]  # null shapes: GDAL's window passes none, other sources may
    if transformer is not None and len(geometries):

        def to_wgs84(xy):
            x, y = transformer.transform(xy[:, 0], xy[:, 1])
            return np.column_stack([x, y])

        geometries = shapely.transform(geometries, to_wgs84)
        if not np.all(np.isfinite(shapely.bounds(geometries))):
            raise GeometryError(f"{path}: features could not be projected to WGS84 longitude-latitude")
    return geometries


# ----------------------------------------------------------------------------------------------------------------


class Shoreline:
    """Land and water in a longitude-latitude box, with the shoreline resampled to the mesh size.

    Parameters
    ----------
    land : shapely geometry, array_like of them, or arrays of vertices
        Land polygons (any mix of ``Polygon``, ``MultiPolygon``, collections)
        or closed coastline lines (a ring inside another bounds a lake), in
        WGS84 longitude-latitude degrees, -180..180 or 0..360; or the guide's
        polygon vector (§2.5): a (k, 2) array whose polygons are separated
        by rows of NaN, or a list of (k, 2) arrays, each polygon a ring.
    bbox : sequence of 4 float or shapely.Polygon
        The region to mesh: ``(lon_min, lon_max, lat_min, lat_max)``, degrees
        (the guide's order), or a polygon in longitude-latitude (an
        irregular outer boundary).
    min_edge_length : float
        The guide's ``h0``: the smallest mesh edge, ground metres. The
        shoreline is resampled at ``h0 / 2``.
    minimum_island_area : float, optional
        Ground m**2. Land and lakes smaller than it are dropped (the mesh
        cannot represent them). Default ``DEFAULT_ISLAND_AREA_FACTOR * h0**2``
        (a ``2 h0`` square); 0 keeps everything.
    smooth : int
        Passes of the ``[1/4, 1/2, 1/4]`` moving average along each resampled
        ring (0: none).
    source : str, optional
        Where the land came from, for messages.
    require_land : bool, optional
        True (default): a bbox with no land in it is an error (a bbox off
        the data, or degrees swapped, often looks like open sea). False: it
        is open water, ``water`` the whole region and ``coastline`` empty
        (an offshore refinement box of a multiscale mesh).

    Attributes
    ----------
    bbox : tuple of float
        ``(lon_min, lon_max, lat_min, lat_max)``, degrees, -180..180 when it fits.
    region : shapely.Polygon or shapely.MultiPolygon
        The box (or the bbox polygon), its edge densified to ``h0 / 2``.
    land : shapely.MultiPolygon
        Land inside the region, degrees.
    water : shapely.Polygon or shapely.MultiPolygon
        ``region - land``: the domain to mesh, degrees.
    mainland, islands : shapely.MultiPolygon
        The parts of ``land`` that touch the region's edge, and the others.
    coastline : shapely.MultiLineString
        The land boundary inside the region (the edge excluded): what size
        functions measure distance to.
    mainland_coastline : shapely.MultiLineString
        The part of ``coastline`` on ``mainland``.
    open_boundary : shapely.MultiLineString
        The parts of the region's edge that are water (open-ocean boundary).
    min_edge_length, minimum_island_area : float
        ``h0`` (metres) and the area threshold actually used (m**2).

    Raises
    ------
    GeometryError
        If there is no land polygon in the bbox (unless ``require_land`` is
        False), the bbox is all land, the bbox is malformed, or lines do not
        close into rings.
    SizingError
        If ``min_edge_length`` is not a positive number or ``minimum_island_area`` a number >= 0.

    Warns
    -----
    TerrameshWarning
        If input polygons were invalid (self-intersecting) and were repaired
        with ``shapely.make_valid``.

    Examples
    --------
    >>> import shapely
    >>> land = shapely.box(-1.0, -1.0, 0.0, 1.0).union(shapely.Point(0.5, 0.0).buffer(0.1))
    >>> shore = Shoreline(land, (-0.5, 1.0, -0.5, 0.5), 2000.0)
    >>> len(shore.mainland.geoms), len(shore.islands.geoms)
    (1, 1)
    >>> round(shore.water.area + shore.land.area, 9) == 1.5 * 1.0
    True
    >>> sea = Shoreline(land, (2.0, 3.0, 0.0, 1.0), 2000.0, require_land=False)
    >>> round(sea.water.area, 9), len(sea.coastline.geoms), round(sea.open_boundary.length, 9)
    (1.0, 0, 4.0)
    """

    def __init__(
        self, land, bbox, min_edge_length, *, minimum_island_area=None, smooth=1, source=None, require_land=True
    ):
        source = "the land geometry" if source is None else str(source)
        polygons = _land_polygons(land, source)
        self._initialize(polygons, bbox, min_edge_length, minimum_island_area, smooth, source, require_land, warn=True)

    def _initialize(self, polygons, bbox, min_edge_length, minimum_island_area, smooth, source, require_land, *, warn):
        self.source = source
        self.min_edge_length = h0 = _positive(min_edge_length, "min_edge_length (h0, metres)")
        if minimum_island_area is None:
            minimum_island_area = DEFAULT_ISLAND_AREA_FACTOR * h0**2
        self.minimum_island_area = _positive(minimum_island_area, "minimum_island_area (m**2)", zero=True)
        try:
            self.smooth = int(smooth)
        except (TypeError, ValueError):
            raise GeometryError(f"smooth must be a whole number of passes, got {smooth!r}") from None
        if self.smooth < 0:
            raise GeometryError(f"smooth must be >= 0, got {smooth}")
        self.bbox, region, rectangle = region_of(bbox)
        self._process(polygons, region, rectangle, require_land=require_land, warn=warn)

    # ------------------------------------------------------------------------------------------------------------

    @classmethod
    def read(
        cls,
        path,
        bbox,
        min_edge_length,
        *,
        minimum_island_area=None,
        crs=None,
        layer=None,
        smooth=1,
        require_land=True,
    ):
        """Read land polygons (or closed coastline lines) from an ESRI shapefile or GeoPackage.

        Parameters
        ----------
        path : str or os.PathLike, or land
            Any vector file pyogrio reads (``.shp``, ``.gpkg``, ...), or the
            land itself as :class:`Shoreline` takes it (shapely geometries,
            the guide's NaN-delimited polygon vector, a list of lon/lat rings).
        bbox, min_edge_length, minimum_island_area, smooth, require_land
            As for :class:`Shoreline`.
        crs : str, int or pyproj.CRS, optional
            The CRS of the file's coordinates, overriding the file's own
            (``.prj``); data not in WGS84 longitude-latitude are reprojected
            to it. A file with neither is taken as longitude-latitude.
        layer : str or int, optional
            Layer of a multi-layer file (GeoPackage), by name or 0-based
            number (a number that is also a layer's name, such as a year, is
            the name). Without it, the file's one polygon layer is read, or,
            with none, its one line layer; points layers and attribute
            tables are never the land.

        Returns
        -------
        Shoreline
            Only features whose extent meets the box are read from disk.

        Raises
        ------
        FileNotFoundError
            If the file does not exist.
        MeshFormatError
            If it cannot be read as vector data.
        GeometryError
            If it is empty, has no layer ``layer``, or has several polygon
            layers (none: several line layers, or none either) and ``layer``
            is not given (the message lists them), the bbox does not overlap it (the
            message gives both), or there is no land polygon in the bbox
            (unless ``require_land`` is False).

        Examples
        --------
        >>> import os, tempfile, numpy as np, pyogrio, shapely
        >>> path = os.path.join(tempfile.mkdtemp(), "land.gpkg")
        >>> land = [shapely.box(10.0, 0.0, 11.0, 1.0), shapely.box(11.4, 1.4, 11.5, 1.5)]
        >>> pyogrio.raw.write(path, shapely.to_wkb(land), [], [], geometry_type="Polygon", crs="EPSG:4326")
        >>> shore = Shoreline.read(path, (10.5, 12.0, 0.5, 2.0), 1000.0)
        >>> len(shore.mainland.geoms), len(shore.islands.geoms)
        (1, 1)
        """
        return _read(cls, path, bbox, min_edge_length, minimum_island_area, crs, layer, smooth, require_land)

    @classmethod
    def from_dem(
        cls, dem, bbox=None, min_edge_length=None, *, level=0.0, minimum_island_area=None, smooth=1, require_land=True
    ):
        """Land where a DEM is at or above ``level``: the guide's ``gdal_contour`` step, as filled polygons.

        Parameters
        ----------
        dem : DEM, str or os.PathLike
            Elevation, metres, positive up, or its NetCDF/GeoTIFF file (read
            for ``bbox``, see :func:`~terramesh.coastal.read_dem`).
        bbox : sequence of 4 float or shapely.Polygon, optional
            The region; default the DEM's extent. It may reach beyond the
            outermost DEM nodes by at most one cell.
        min_edge_length : float, optional
            ``h0``, ground metres; default the DEM's coarser ground resolution.
        level : float
            Elevation of the shoreline, metres (0: the DEM's datum).
        minimum_island_area, smooth, require_land
            As for :class:`Shoreline`.

        Returns
        -------
        Shoreline

        Examples
        --------
        >>> import numpy as np
        >>> from terramesh.coastal.dem import DEM
        >>> lon, lat = np.linspace(0.0, 0.1, 41), np.linspace(0.0, 0.1, 41)
        >>> x, y = np.meshgrid(lon, lat, indexing="ij")
        >>> hill = 10.0 - 500.0 * np.hypot(x - 0.05, y - 0.05)
        >>> shore = Shoreline.from_dem(DEM(lon, lat, hill), min_edge_length=300.0)
        >>> len(shore.islands.geoms), len(shore.mainland.geoms)
        (1, 0)
        """
        import contourpy

        try:
            level = float(level)
        except (TypeError, ValueError):
            raise GeometryError(f"level must be an elevation in metres, got {level!r}") from None
        if not np.isfinite(level):
            raise GeometryError(f"level must be finite, got {level!r}")
        if not isinstance(dem, DEM):  # a path, read for the box (DEM.read refuses anything else by name)
            dem = DEM.read(dem, None if bbox is None else region_of(bbox)[0])
        if min_edge_length is None:
            min_edge_length = max(dem.resolution)
        box, region, _ = region_of(dem.bbox if bbox is None else bbox)
        lon_min, lon_max, lat_min, lat_max = box
        lon, lat = dem.lon, dem.lat
        shift = 0.0
        if lon_max < lon[0] - dem.dx or lon_min > lon[-1] + dem.dx:
            shift = 360.0 if lon_max + 360.0 <= lon[-1] + dem.dx else -360.0
        reach = (lon_min + shift, lon_max + shift, lat_min, lat_max)
        if (
            reach[0] < lon[0] - dem.dx
            or reach[1] > lon[-1] + dem.dx
            or lat_min < lat[0] - dem.dy
            or lat_max > lat[-1] + dem.dy
        ):
            raise GeometryError(
                f"the bbox {box} reaches beyond the DEM (lon {lon[0]:g}..{lon[-1]:g}, lat {lat[0]:g}..{lat[-1]:g})"
                " by more than a cell, where its contour cannot make the shoreline: shrink the bbox to the DEM's"
                " extent, or give the land from a shoreline file (shoreline=PATH)"
            )
        i0 = max(int(np.floor((reach[0] - lon[0]) / dem.dx)) - 1, 0)
        i1 = min(int(np.ceil((reach[1] - lon[0]) / dem.dx)) + 2, lon.size)
        j0 = max(int(np.floor((lat_min - lat[0]) / dem.dy)) - 1, 0)
        j1 = min(int(np.ceil((lat_max - lat[0]) / dem.dy)) + 2, lat.size)
        x, y = lon[i0:i1] - shift, lat[j0:j1].copy()
        x[0], x[-1] = min(x[0], lon_min - 1e-6), max(x[-1], lon_max + 1e-6)  # stretch edge cells over the box
        y[0], y[-1] = min(y[0], lat_min - 1e-6), max(y[-1], lat_max + 1e-6)
        z = dem.elevation[i0:i1, j0:j1].T
        generator = contourpy.contour_generator(x, y, z, fill_type="ChunkCombinedOffsetOffset")
        # contourpy fills lower < z <= upper: from just below the level, so that land at it (a bathymetric
        # DEM's land, 0 m exactly) is land, as the docstring says
        points, offsets, outer_offsets = generator.filled(np.nextafter(level, -np.inf), np.inf)
        polygons = []
        for chunk_points, chunk_offsets, chunk_outer in zip(points, offsets, outer_offsets, strict=True):
            if chunk_points is None:
                continue
            rings = shapely.linearrings(
                chunk_points, indices=np.repeat(np.arange(len(chunk_offsets) - 1), np.diff(chunk_offsets))
            )
            owner = np.repeat(np.arange(len(chunk_outer) - 1), np.diff(chunk_outer))
            polygons.append(shapely.polygons(rings, indices=owner))
        land = np.concatenate(polygons) if polygons else np.empty(0, dtype=object)
        source = f"the DEM {dem.source}" if getattr(dem, "source", None) else "the DEM"
        shore = cls.__new__(cls)
        region_or_box = region if isinstance(bbox, shapely.Geometry) else box
        shore._initialize(
            land,
            region_or_box,
            min_edge_length,
            minimum_island_area,
            smooth,
            f"{source} (elevation >= {level:g} m)",
            require_land,
            warn=False,
        )
        return shore

    # ------------------------------------------------------------------------------------------------------------

    def _process(self, polygons, region, rectangle, *, require_land, warn):
        h0, minimum_area = self.min_edge_length, self.minimum_island_area
        spacing = 0.5 * h0
        box = self.bbox
        lon_min, lon_max, lat_min, lat_max = box
        mx, my = _margin(box, h0)
        where = f"{self.source} has no land polygon in the bbox {box}"
        polygons = np.asarray(polygons, dtype=object)
        # 1. Near the box, in its longitude turn, valid, clipped to the widened box.
        near, bounds = [], shapely.bounds(polygons) if len(polygons) else np.zeros((0, 4))
        repaired = 0
        for shift in (-360.0, 0.0, 360.0):
            x0, x1 = lon_min - mx - shift, lon_max + mx - shift
            y0, y1 = lat_min - my, lat_max + my
            hit = (bounds[:, 0] <= x1) & (bounds[:, 2] >= x0) & (bounds[:, 1] <= y1) & (bounds[:, 3] >= y0)
            if not hit.any():
                continue
            valid, count = _repaired(polygons[hit])
            repaired += count
            near.append(_shifted(shapely.clip_by_rect(valid, x0, y0, x1, y1), shift))
        if repaired and warn:
            warn_user(
                f"{self.source}: {repaired} invalid (self-intersecting) polygon(s) repaired with shapely.make_valid",
            )
        # 2. Merged; features too small to mesh dropped.
        land = _drop_small(_merged(np.concatenate(near)), minimum_area) if near else _NO_POLYGONS
        # 3. Resampled at h0 / 2 and smoothed; 4. repaired, merged, cut to the region.
        land = _merged(_resample_polygons(land, spacing, self.smooth))
        self.region = _multipolygon(_densify_polygons(_polygons_of(region), spacing))
        if len(self.region.geoms) == 1:
            self.region = self.region.geoms[0]
        land = _drop_small(shapely.intersection(land, self.region), minimum_area)
        if len(land) == 0 and require_land:
            raise GeometryError(f"{where}{self._area_note() if near else ''}{_OPEN_WATER_HINT}")
        water = _polygons_of(shapely.difference(self.region, shapely.MultiPolygon(list(land))))
        small = _ground_area(water) < minimum_area
        if small.any():  # slivers of water between the shore and the box edge: land
            water = water[~small]
            land = _polygons_of(shapely.difference(self.region, _multipolygon(water)))
        if len(water) == 0:
            raise GeometryError(f"the bbox {box} is all land in {self.source}: there is no water to mesh")
        self.land = _multipolygon(land)
        self.water = water[0] if len(water) == 1 else _multipolygon(water)
        # Classes.
        on_edge = self._on_edge_test(rectangle)
        land = np.asarray(list(self.land.geoms), dtype=object)
        touches = self._touches_edge(land, rectangle)
        self.mainland = _multipolygon(land[touches])
        self.islands = _multipolygon(land[~touches])
        self.mainland_coastline = _runs(shapely.get_rings(land[touches]), lambda a, b: ~on_edge(a, b))
        island_rings = shapely.get_rings(land[~touches])
        island_lines = []
        if len(island_rings):
            coords, index = shapely.get_coordinates(island_rings, return_index=True)
            island_lines = shapely.linestrings(coords, indices=index)
        self.coastline = shapely.MultiLineString(list(self.mainland_coastline.geoms) + list(island_lines))
        self.open_boundary = _runs(shapely.get_rings(water), on_edge)

    def _area_note(self):
        if self.minimum_island_area <= 0:
            return ""
        return f" (larger than minimum_island_area = {self.minimum_island_area:.4g} m**2)"

    def _touches_edge(self, parts, rectangle):
        if len(parts) == 0:
            return np.zeros(0, dtype=bool)
        if rectangle:
            lon_min, lon_max, lat_min, lat_max = self.bbox
            b = shapely.bounds(parts)
            tol = _EDGE_TOLERANCE
            return (
                (b[:, 0] <= lon_min + tol)
                | (b[:, 2] >= lon_max - tol)
                | (b[:, 1] <= lat_min + tol)
                | (b[:, 3] >= lat_max - tol)
            )
        edge = shapely.boundary(self.region)
        shapely.prepare(edge)
        return shapely.dwithin(edge, parts, _EDGE_TOLERANCE)

    def _on_edge_test(self, rectangle):
        """A function telling which segments ``a -> b`` (arrays (n, 2), degrees) lie on the region's edge."""
        tol = _EDGE_TOLERANCE
        if rectangle:
            lon_min, lon_max, lat_min, lat_max = self.bbox

            def on_edge(a, b):
                same_side = np.zeros(len(a), dtype=bool)
                for axis, value in ((0, lon_min), (0, lon_max), (1, lat_min), (1, lat_max)):
                    same_side |= (np.abs(a[:, axis] - value) <= tol) & (np.abs(b[:, axis] - value) <= tol)
                return same_side

            return on_edge
        edge = shapely.boundary(self.region)
        shapely.prepare(edge)

        def on_edge(a, b):
            near = [shapely.dwithin(edge, shapely.points(p), tol) for p in (a, b, 0.5 * (a + b))]
            return near[0] & near[1] & near[2]

        return on_edge

    # ------------------------------------------------------------------------------------------------------------

    def domain(self):
        """The water on the Mercator plane (metres), as a signed-distance :class:`~terramesh.geometry.Polygon`.

        Where water rings touch at a point (a valid shapely polygon, but not
        a valid :class:`~terramesh.geometry.Polygon`), the water is first
        eroded by ``1e-4 h0``.

        Raises
        ------
        GeometryError
            If some latitude is beyond +-85 degrees, or the water cannot be
            made into simple, disjoint rings.

        Examples
        --------
        >>> import shapely
        >>> shore = Shoreline(shapely.box(-1.0, -1.0, 0.0, 1.0), (-0.5, 0.5, -0.5, 0.5), 5000.0)
        >>> domain = shore.domain()
        >>> bool(domain.distance([(30000.0, 0.0)])[0] < 0)
        True
        """

        def mercator(xy):
            return np.column_stack(to_mercator(xy[:, 0], xy[:, 1]))

        water = shapely.transform(self.water, mercator)
        try:
            return Polygon.from_shapely(water)
        except GeometryError:
            eroded = shapely.buffer(water, -1e-4 * self.min_edge_length, quad_segs=2, join_style="mitre")
            eroded = _multipolygon(_polygons_of(eroded))
            return Polygon.from_shapely(eroded.geoms[0] if len(eroded.geoms) == 1 else eroded)

    def __repr__(self):
        return (
            f"Shoreline(bbox={self.bbox}, h0={self.min_edge_length:g} m, {len(self.mainland.geoms)} mainland,"
            f" {len(self.islands.geoms)} islands, {shapely.get_num_coordinates(self.coastline):,} coastline vertices)"
        )


def _positive(value, name, *, zero=False):
    requirement = f"{name} must be {'a finite number >= 0' if zero else 'a positive finite number'}"
    return checked_number(value, requirement, SizingError, minimum=0, strict=not zero)


def read_shoreline(
    path, bbox, min_edge_length, *, minimum_island_area=None, crs=None, layer=None, smooth=1, require_land=True
):
    """Read a shoreline file: the same as :meth:`Shoreline.read`.

    Parameters
    ----------
    path : str or os.PathLike
        Any vector file pyogrio reads (``.shp``, ``.gpkg``, ...) of land
        polygons or closed coastline lines. Land itself (shapely geometries
        or the guide's polygon arrays, longitude-latitude degrees) is taken
        too, as :class:`Shoreline` takes it, without ``crs`` or ``layer``.
    bbox : sequence of 4 float or shapely.Polygon
        The region to mesh: ``(lon_min, lon_max, lat_min, lat_max)``,
        degrees (the guide's order), or a polygon in longitude-latitude.
    min_edge_length : float
        The guide's ``h0``: the smallest mesh edge, ground metres; the
        shoreline is resampled at ``h0 / 2``.
    minimum_island_area : float, optional
        Ground m**2; land and lakes smaller than it are dropped (default
        ``DEFAULT_ISLAND_AREA_FACTOR * h0**2``, a ``2 h0`` square; 0 keeps
        everything).
    crs : str, int or pyproj.CRS, optional
        The CRS of the file's coordinates, overriding the file's own
        (``.prj``); data not in WGS84 longitude-latitude are reprojected.
        A file with neither is taken as longitude-latitude.
    layer : str or int, optional
        Layer of a multi-layer file (GeoPackage), by name or 0-based number;
        without it the file's one polygon layer (or, with none, its one line
        layer) is read.
    smooth : int, optional
        Passes of the ``[1/4, 1/2, 1/4]`` moving average along each
        resampled ring (0: none).
    require_land : bool, optional
        True (default): a bbox with no land in it is an error. False: it is
        open water.

    Returns
    -------
    Shoreline
        Cut to ``bbox``, in longitude-latitude degrees.

    Raises
    ------
    FileNotFoundError, MeshFormatError, GeometryError, SizingError
        As :meth:`Shoreline.read` and :class:`Shoreline`.

    Examples
    --------
    >>> import os, tempfile, pyogrio, shapely
    >>> path = os.path.join(tempfile.mkdtemp(), "coast.shp")
    >>> land = shapely.to_wkb([shapely.box(0.0, 0.0, 1.0, 1.0)])
    >>> pyogrio.raw.write(path, land, [], [], geometry_type="Polygon", crs="EPSG:4326")
    >>> shore = read_shoreline(path, (0.5, 1.5, 0.0, 1.0), 2000.0)
    >>> shore.bbox, len(shore.open_boundary.geoms)
    ((0.5, 1.5, 0.0, 1.0), 1)
    """
    return _read(Shoreline, path, bbox, min_edge_length, minimum_island_area, crs, layer, smooth, require_land)


def _read(cls, path, bbox, min_edge_length, minimum_island_area, crs, layer, smooth, require_land):
    if not isinstance(path, (str, bytes, os.PathLike)):  # land itself: geometries or the guide's polygon arrays
        if crs is not None or layer is not None:
            raise GeometryError("crs and layer are options of a shoreline file; land given as arrays is lon/lat")
        return cls(
            path,
            bbox,
            min_edge_length,
            minimum_island_area=minimum_island_area,
            smooth=smooth,
            source="the land arrays",
            require_land=require_land,
        )
    h0 = _positive(min_edge_length, "min_edge_length (h0, metres)")
    box, region, _ = region_of(bbox)
    geometries = _read_features(path, box, h0, crs, layer, require_land)
    source = f"the shoreline file {pathlib.Path(os.fspath(path)).name}"
    shore = cls.__new__(cls)
    region_or_box = region if isinstance(bbox, shapely.Geometry) else box
    polygons = _land_polygons(geometries, source)
    shore._initialize(polygons, region_or_box, h0, minimum_island_area, smooth, source, require_land, warn=True)
    return shore
