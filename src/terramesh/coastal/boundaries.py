"""ADCIRC node strings from a mesh's boundary: the OceanMesh2D guide's ``makens`` (§6.4).

The boundary edges of a valid triangle mesh form closed loops. With
counter-clockwise cells, each loop runs with the domain on its left: the
outer boundary of each connected part counter-clockwise (positive area),
the boundary of each hole (an island) clockwise. That is the traversal
ADCIRC asks for (fort.14 documentation, ``NBVV``): land boundary nodes are
listed "with land always on the right, i.e., in a counter clockwise
direction for external (e.g., mainland ...) boundaries and a clockwise
direction for internal (e.g., island ...) boundaries".

:func:`make_boundaries` splits every outer loop into open-ocean segments
(elevation specified, fort.14 ``NBDV``) and mainland segments (``NBVV``,
IBTYPE 20 by default), and makes every inner loop a closed island boundary
(IBTYPE 21 by default). The rules it follows are those of the ADCIRC
documentation ("General Notes for Normal Flow Boundary Conditions", in the
description of the flux-specified boundaries):

* external boundaries are listed in consecutive order around the outside
  of the domain before any internal (island) boundary;
* a segment that is not closed starts where two boundaries connect: each
  mainland segment starts at the last node of the open segment before it
  and ends at the first node of the open segment after it (those nodes
  belong to both);
* an island, and an external land boundary that surrounds the whole domain
  (no open segment), is closed by repeating its first node as its last;
* the direction of an open segment does not matter to ADCIRC (``NBDV``);
  here it is the same counter-clockwise traversal as the mainland.
"""

import hashlib
import inspect
import numbers

import numpy as np

from ..errors import MeshValidityError, warn_user
from ..mesh.boundaries import ISLAND_TYPES, PAIRED_TYPES, Boundaries, LandBoundary, OpenBoundary
from ..mesh.topology import boundary_edges, boundary_loops, signed_areas, sorted_unique
from .bathymetry import as_dem, longitudes_onto_dem, lonlat_on_dem

__all__ = ["make_boundaries", "node_string_problems", "cut_region", "boundary_loops", "OPEN_BY", "DEPTH_THRESHOLD"]

OPEN_BY = ("bbox_or_depth", "bbox", "depth")
"""The rules :func:`make_boundaries` can use to call an outer-boundary edge open ocean."""

SHALLOW_OPEN = 1.0
"""Metres: :func:`make_boundaries` warns of open segments less deep than this at every node."""

DEPTH_THRESHOLD = 100.0
"""The depth rule's default (``open_by="depth"``), metres (positive down), beyond which a boundary edge is open ocean.

The guide gives no value. The depth of a vertex on the shoreline is the
DEM averaged over its control area, which lies on the water side, so steep
shores read deep: up to 14 m at Sabine Pass (30 m DEM, 80 m mesh) and 80 m
in the Gulf of Maine (ETOPO1 at 0.1 degree, 3 km mesh). 10 m made spurious
open segments along both coasts; 100 m made none, and the bbox rule finds
the open boundary of a mesh cut from a box whatever its depth. Elsewhere
100 m is not enough: on ETOPO1 at 0.1 degree fjord walls, shelf breaks and
deep basins read deeper (23 open segments along Scoresby Sund's coast, 10
along Hispaniola and Yucatan), so the default rule, ``"bbox_or_depth"``,
opens water by its depth only where a ``depth_threshold`` is given.
"""

_EDGE_TOLERANCE = 1e-2
"""A boundary edge lies on a bbox side when both ends are within this fraction of the median boundary edge of it."""

_CHORD_SAG = 0.1
"""How far, as a fraction of its length, an edge's midpoint may lie off a region's outline that both its ends are on.

An edge along a curved outline is a chord: its midpoint lies ``L^2 / 8R``
inside, 0.0029 degrees for 15 km edges on a circle 0.8 degrees across,
where the ends' tolerance is 0.0011. A tenth of the edge admits radii down
to 1.25 edges and still keeps out an edge across a bay of the outline
(its midpoint half the bay's width away).
"""


def _parse_bbox(bbox, points, shoreline_bbox, geographic=False):
    """``(x_min, x_max, y_min, y_max)``: the given box, the shoreline's, or the mesh's extent.

    A geographic box in the other longitude convention (0..360 for a mesh in
    -180..180, or the reverse) is moved by 360 degrees onto the points; a box
    apart from the points is refused, since none of its sides could be open.
    """
    if bbox is None:
        bbox = shoreline_bbox
    if bbox is None:
        lo, hi = points.min(axis=0), points.max(axis=0)
        return float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1])
    try:
        values = [float(v) for v in np.asarray(bbox, dtype=np.float64).ravel()]
    except (TypeError, ValueError):
        raise MeshValidityError(f"bbox must be (x_min, x_max, y_min, y_max), got {bbox!r}") from None
    if len(values) != 4 or not np.all(np.isfinite(values)) or values[0] >= values[1] or values[2] >= values[3]:
        raise MeshValidityError(f"bbox must be (x_min, x_max, y_min, y_max) with min < max, got {bbox!r}")
    lo, hi = points.min(axis=0), points.max(axis=0)

    def overlaps(x_shift):
        x_min, x_max = values[0] + x_shift, values[1] + x_shift
        return x_min <= hi[0] and x_max >= lo[0] and values[2] <= hi[1] and values[3] >= lo[1]

    shift = next((shift for shift in (0.0, -360.0, 360.0) if overlaps(shift)), None) if geographic else 0.0
    if shift is None or not overlaps(shift):
        raise MeshValidityError(
            f"bbox {tuple(values)} does not overlap the mesh ({lo[0]:g}..{hi[0]:g}, {lo[1]:g}..{hi[1]:g}):"
            " give the box the mesh was cut from, in the points' units"
        )
    return values[0] + shift, values[1] + shift, values[2], values[3]


def cut_region(mesh):
    """The region a coastal mesh was cut from: a shapely polygon in its points' units, or None.

    A merged mesh's is the union of its parts' (``info["region"]``, set by
    :func:`~terramesh.coastal.merge`); a mesh from
    :func:`~terramesh.coastal.build`, its shoreline's region (its bbox, or
    the polygon given as one). Boundary edges on its edge are open ocean
    under the bbox rule of :func:`make_boundaries`.

    Examples
    --------
    >>> import shapely, terramesh as tm
    >>> from terramesh.coastal.build import build
    >>> land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    >>> mesh = build((0, 0.3, 0, 0.3), land, min_el=2000, max_el=6000, dis=0.3, g=0.3)
    >>> cut_region(mesh).bounds  # degrees: (lon_min, lat_min, lon_max, lat_max)
    (0.0, 0.0, 0.3, 0.3)

    A mesh from :func:`~terramesh.generate_mesh` was cut from no region:

    >>> print(cut_region(tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.5)))
    None
    """
    region = mesh.info.get("region")
    if region is None:
        region = getattr(getattr(mesh.info.get("sizes"), "shoreline", None), "region", None)
    return region


def _overlap_share(box, other):
    """Area of two ``(x_min, x_max, y_min, y_max)`` boxes' intersection over their union's (0 if one is flat)."""
    width = max(0.0, min(box[1], other[1]) - max(box[0], other[0]))
    height = max(0.0, min(box[3], other[3]) - max(box[2], other[2]))
    common = width * height
    union = (box[1] - box[0]) * (box[3] - box[2]) + (other[1] - other[0]) * (other[3] - other[2]) - common
    return common / union if union > 0 and box[1] > box[0] and box[3] > box[2] else 0.0


def _checked_bbox(bbox, points, geographic):
    """``bbox`` checked: four numbers, or a polygon (moved by 360 degrees onto geographic points), on the points."""
    import shapely

    if len(points) == 0:
        raise MeshValidityError("the mesh has no vertices to make boundaries of")
    if not isinstance(bbox, shapely.Geometry):
        box = _parse_bbox(bbox, points, None, geographic)
        lo, hi = points.min(axis=0), points.max(axis=0)
        extent = (lo[0], hi[0], lo[1], hi[1])
        swapped = (box[0], box[2], box[1], box[3])  # read as shapely's (x_min, y_min, x_max, y_max)
        if _overlap_share(box, extent) < 0.25 and _overlap_share(swapped, extent) > 0.5:
            warn_user(
                f"bbox {tuple(float(v) for v in box)} reads as x {box[0]:g}..{box[1]:g}, y {box[2]:g}..{box[3]:g},"
                f" far beyond the mesh (x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g}), whose extent it fits in"
                " shapely's order (x_min, y_min, x_max, y_max): the bbox is (x_min, x_max, y_min, y_max), and"
                " only edges on its sides are open"
            )
        return bbox
    if not isinstance(bbox, (shapely.Polygon, shapely.MultiPolygon)) or bbox.is_empty:
        raise MeshValidityError(
            f"bbox must be (x_min, x_max, y_min, y_max) or a non-empty polygon, got {bbox.geom_type}"
        )
    lo, hi = points.min(axis=0), points.max(axis=0)
    extent = shapely.box(lo[0], lo[1], hi[0], hi[1])
    for shift in (0.0, -360.0, 360.0) if geographic else (0.0,):
        moved = shapely.transform(bbox, lambda xy, shift=shift: xy + [shift, 0.0]) if shift else bbox
        if shapely.intersects(moved, extent):
            return moved
    raise MeshValidityError(
        f"the bbox polygon (bounds {bbox.bounds}) does not overlap the mesh ({lo[0]:g}..{hi[0]:g},"
        f" {lo[1]:g}..{hi[1]:g}): give the region the mesh was cut from, in the points' units"
    )


def _outline_test(mesh, bbox, tolerance, vertices):
    """``on_outline(a, b)``: which boundary edges ``a[i] -> b[i]`` lie on the box the mesh was cut from.

    The sides of ``bbox`` (both ends on one side); for a polygon ``bbox``,
    or with none the region the mesh was cut from (:func:`cut_region`),
    which may be any polygon, its edge (the edge's ends on it and its
    midpoint within a chord's sag of it); else the extent of the points.
    """
    import shapely

    edges = boundary_edges(mesh.cells)
    lengths = np.linalg.norm(mesh.points[edges[:, 1]] - mesh.points[edges[:, 0]], axis=1)
    tol = _EDGE_TOLERANCE * float(np.median(lengths)) if tolerance is None else float(tolerance)
    shoreline = getattr(mesh.info.get("sizes"), "shoreline", None)
    region = bbox if isinstance(bbox, shapely.Geometry) else (cut_region(mesh) if bbox is None else None)
    rectangle = "region" not in mesh.info and shoreline is not None and region is shoreline.region
    if region is not None and not (
        rectangle and shapely.equals(region, shapely.box(*np.array(shoreline.bbox)[[0, 2, 1, 3]]))
    ):
        outline = shapely.boundary(region)
        shapely.prepare(outline)
        near = np.zeros(mesh.n_points, dtype=bool)
        near[vertices] = shapely.dwithin(outline, shapely.points(mesh.points[vertices]), tol)

        def on_outline(a, b):
            both = near[a] & near[b]
            a, b = mesh.points[a[both]], mesh.points[b[both]]
            sag = np.maximum(tol, _CHORD_SAG * np.linalg.norm(b - a, axis=1))
            both[both] = shapely.dwithin(outline, shapely.points(0.5 * (a + b)), sag)
            return both

        return on_outline
    box = _parse_bbox(bbox, mesh.points, getattr(shoreline, "bbox", None), mesh.geographic)
    side = np.zeros((mesh.n_points, 4), dtype=bool)  # per vertex: on each bbox side
    xy = mesh.points[vertices]
    for k, (axis, value) in enumerate(((0, box[0]), (0, box[1]), (1, box[2]), (1, box[3]))):
        side[vertices, k] = np.abs(xy[:, axis] - value) <= tol
    return lambda a, b: np.any(side[a] & side[b], axis=1)


def _boundary_depth(mesh, dem, vertices):
    """Depth (metres, positive down) at ``vertices``, and the :class:`DEM` it came from (bilinear) or None.

    From ``dem`` when given, else from ``mesh.depth``.
    """
    if dem is not None:
        dem = as_dem(dem, mesh.points[vertices], mesh.crs)
        return -dem.sample(*lonlat_on_dem(dem, mesh.points[vertices], "boundary vertices")[:2]), dem
    if mesh.depth is None:
        raise MeshValidityError(
            "open_by needs the depth of the boundary: the mesh has no point_data['depth']; give dem= or run"
            " interpolate_bathymetry first, or use open_by='bbox'"
        )
    return np.asarray(mesh.depth, dtype=np.float64)[vertices], None


def _warn_if_all_dry(mesh, dem):
    """Warn when no vertex is deeper than 0 m by ``dem`` (a :class:`DEM`, or None: ``mesh.depth``): elevations, likely.

    Every boundary vertex is then dry and none is open: an elevation
    (positive up) given as the depth made one land boundary round the whole
    mesh and no open one, without a word.
    """
    if dem is None:
        depth, source = np.asarray(mesh.depth, dtype=np.float64), "point_data['depth']"
        advice = "if these are elevations (positive up), give their negatives as the depth"
    else:
        depth = -dem.sample(longitudes_onto_dem(mesh.points[:, 0], dem), mesh.points[:, 1])
        source = f"the DEM {dem.source}" if dem.source else "the DEM"
        advice = f"{dem.sign_note or 'its values were taken as elevation'}; if that is wrong, read it with"
        advice += " tm.coastal.read_dem(path, positive='up' or 'down')"
    deepest = np.max(depth, where=np.isfinite(depth), initial=-np.inf)
    if -np.inf < deepest <= 0.0:
        warn_user(
            f"make_boundaries: no vertex of the mesh is deeper than 0 m by {source} (the deepest is {deepest:.4g} m),"
            " so every boundary vertex is dry and no boundary is open. The depth is metres, positive down:"
            f" {advice}"
        )


def _segments(nodes, is_open):
    """Split a closed loop into runs of open and land edges: ``[(is_open, nodes of the run), ...]``.

    ``is_open[i]`` is the class of the edge ``nodes[i] -> nodes[i + 1]``.
    Runs share their end nodes; the loop is rotated to start at an open run.
    """
    m = len(nodes)
    start = int(np.flatnonzero(is_open & ~np.roll(is_open, 1))[0])
    nodes, is_open = np.roll(nodes, -start), np.roll(is_open, -start)
    change = np.flatnonzero(is_open[1:] != is_open[:-1]) + 1
    bounds = np.concatenate([[0], change, [m]])
    closed = np.append(nodes, nodes[0])
    return [(bool(is_open[a]), closed[a : b + 1].copy()) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]


CLOSED_TYPES = (1, 11, 21)
"""Land boundary IBTYPEs of islands (internal boundaries), whose node string ends on its first node."""


def node_string_problems(mesh):
    """What is wrong with ``mesh.boundaries``' node strings: a list of sentences, empty when nothing is.

    Each string must run along the mesh's boundary, every two consecutive
    nodes joined by a boundary edge (a barrier's second face too), and an
    island (IBTYPE 1, 11, 21) must end on its first node. A fort.14 cut
    short in its last line read a node 11 for 1198: the island jumped 1.3
    degrees between its last two nodes, and its cells were valid.

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> mesh = tm.coastal.make_boundaries(tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.5), open_by="bbox")
    >>> node_string_problems(mesh)
    []
    >>> mesh.boundaries.open[0].nodes[1] = mesh.boundaries.open[0].nodes[0]
    >>> node_string_problems(mesh)[0][:55]
    'open boundary 1: nodes 1 and 2 (mesh nodes 1 and 1, num'
    """
    boundaries = mesh.boundaries
    if boundaries is None or mesh.cells.shape[1] != 3:
        return []
    n = mesh.n_points
    edges = boundary_edges(mesh.cells)
    keys = np.minimum(edges[:, 0], edges[:, 1]) * n + np.maximum(edges[:, 0], edges[:, 1])
    problems = []
    strings = [(f"open boundary {k + 1}", b.nodes) for k, b in enumerate(boundaries.open)]
    for k, land in enumerate(boundaries.land):
        strings.append((f"land boundary {k + 1} (IBTYPE {land.ibtype})", land.nodes))
        if land.paired_nodes is not None:
            strings.append((f"land boundary {k + 1}'s back face", land.paired_nodes))
        if land.ibtype in CLOSED_TYPES and len(land.nodes) and land.nodes[0] != land.nodes[-1]:
            problems.append(f"land boundary {k + 1} (IBTYPE {land.ibtype}, an island) does not end on its first node")
    for name, nodes in strings:
        nodes = np.asarray(nodes, dtype=np.int64)
        if len(nodes) < 2 or nodes.min() < 0 or nodes.max() >= n:
            continue  # the reader and writer refuse nodes the mesh lacks
        first, second = nodes[:-1], nodes[1:]
        off = np.flatnonzero(~np.isin(np.minimum(first, second) * n + np.maximum(first, second), keys))
        if len(off):
            i = int(off[0])
            problems.append(
                f"{name}: nodes {i + 1} and {i + 2} (mesh nodes {first[i] + 1} and {second[i] + 1}, numbered from 1)"
                f" are not joined by a boundary edge{f' ({len(off)} such pairs)' if len(off) > 1 else ''}"
            )
    return problems


def _warn_shallow_open(mesh, open_segments, vertices, depth):
    """Warn of the open segments less than SHALLOW_OPEN deep at every node (``depth`` at the boundary ``vertices``)."""
    at = np.full(mesh.n_points, np.nan)
    at[vertices] = depth
    shallow = [
        segment for segment in open_segments if not np.nanmax(at[segment.nodes], initial=-np.inf) >= SHALLOW_OPEN
    ]
    if shallow:
        where = mesh.points[shallow[0].nodes].mean(axis=0)
        warn_user(
            f"{len(shallow)} of {len(open_segments)} open boundaries are less than {SHALLOW_OPEN:g} m deep at every"
            f" node (the first {len(shallow[0].nodes)} nodes near ({where[0]:.4f}, {where[1]:.4f})): ADCIRC would"
            " force the tide over a pond or a flat there; give dry_depth (metres) to make such water land"
        )


def _checked_options(
    *, dem, depth_threshold, bbox, open_by, island_ibtype, mainland_ibtype, open_ibtype, tolerance, dry_depth
):
    """:func:`make_boundaries`' options checked and as it keeps them, all but ``bbox`` (checked against the mesh)."""
    if open_by not in OPEN_BY:
        raise MeshValidityError(f"open_by must be one of {', '.join(OPEN_BY)}; got {open_by!r}")
    island_ibtype = _ibtype(island_ibtype, "island_ibtype")
    mainland_ibtype = _ibtype(mainland_ibtype, "mainland_ibtype")
    if open_ibtype is not None:
        open_ibtype = _ibtype(open_ibtype, "open_ibtype")
    if depth_threshold is None:
        depth_threshold = DEPTH_THRESHOLD if open_by == "depth" else np.inf
    if not isinstance(depth_threshold, numbers.Real) or np.isnan(depth_threshold) or depth_threshold == -np.inf:
        raise MeshValidityError(f"depth_threshold must be a number of metres (inf: none), got {depth_threshold!r}")
    if isinstance(dry_depth, bool) or not isinstance(dry_depth, numbers.Real) or not np.isfinite(dry_depth):
        raise MeshValidityError(f"dry_depth must be a finite number of metres (positive down), got {dry_depth!r}")
    if open_by == "depth" and depth_threshold == np.inf:
        raise MeshValidityError('open_by="depth" with depth_threshold=inf opens nothing: give a depth in metres')
    valid_tolerance = isinstance(tolerance, numbers.Real) and np.isfinite(tolerance) and tolerance >= 0
    if tolerance is not None and not valid_tolerance:
        raise MeshValidityError(f"tolerance must be a non-negative distance, got {tolerance!r}")
    return {
        "dem": dem,
        "depth_threshold": float(depth_threshold),
        "bbox": bbox,
        "open_by": open_by,
        "island_ibtype": island_ibtype,
        "mainland_ibtype": mainland_ibtype,
        "open_ibtype": open_ibtype,
        "tolerance": tolerance,
        "dry_depth": float(dry_depth),
    }


def checked_boundary_options(boundaries, what):
    """The ``boundaries`` argument of :func:`~terramesh.coastal.build` (``what``) as make_boundaries options, or None.

    True gives no options (the caller's defaults), False None, a dict its
    options; checked before the mesh is made, so that a flag or an option
    misspelled fails at once, not after the meshing (``"yes"`` failed
    there in a dict update, with Python's "dictionary update sequence"
    error). ``bbox`` and ``dem`` are checked by make_boundaries, against
    the mesh.

    Raises
    ------
    MeshValidityError
        For anything else than True, False or a dict, an option
        make_boundaries does not have (naming the nearest), or a bad value.
    """
    import difflib
    from collections.abc import Mapping

    if isinstance(boundaries, (bool, np.bool_)):
        return {} if boundaries else None
    if not isinstance(boundaries, Mapping):
        raise MeshValidityError(
            f"{what}: boundaries must be True, False or a dict of make_boundaries options (such as"
            f" {{'dry_depth': 1.0}}), got {boundaries!r}"
        )
    known = tuple(_MAKE_BOUNDARIES_DEFAULTS)
    unknown = [name for name in boundaries if name not in known]
    if unknown:
        hints = []
        for name in unknown:
            close = difflib.get_close_matches(str(name), known, n=1)
            hints.append(f"{name!r} (did you mean {close[0]!r}?)" if close else repr(name))
        raise MeshValidityError(
            f"{what}: boundaries has options make_boundaries does not take: {', '.join(hints)}; its options are"
            f" {', '.join(known)}"
        )
    try:
        _checked_options(**dict(_MAKE_BOUNDARIES_DEFAULTS, **boundaries))
    except MeshValidityError as error:
        raise MeshValidityError(f"{what}: boundaries: {error}") from None
    return dict(boundaries)


def _ibtype(value, name):
    if not isinstance(value, numbers.Integral) or isinstance(value, bool) or value < 0:
        raise MeshValidityError(f"{name} must be a non-negative integer (an ADCIRC IBTYPE), got {value!r}")
    return int(value)


def make_boundaries(
    mesh,
    *,
    dem=None,
    depth_threshold=None,
    bbox=None,
    open_by="bbox_or_depth",
    island_ibtype=21,
    mainland_ibtype=20,
    open_ibtype=0,
    tolerance=None,
    dry_depth=0.0,
):
    """Make ADCIRC open, mainland and island boundaries from the mesh's boundary (the guide's ``makens``).

    The boundary edges form closed loops (:func:`boundary_loops`). Each
    outer loop (counter-clockwise: the outside of a connected part) is cut
    into runs of open-ocean edges and land edges:

    * an edge is **on the bbox** when both its ends lie on the same side of
      ``bbox`` (within ``tolerance``), or, for a mesh built from a shoreline
      cut to a polygon region, when its ends and midpoint lie on the
      region's edge;
    * an edge is **deep** when the depth at both its ends exceeds
      ``depth_threshold`` (metres, positive down; ``mesh.depth``, or the
      DEM's bilinear depth at the vertices when ``dem`` is given);
    * ``open_by`` says which edges are open ocean: ``"bbox_or_depth"``
      (default: on the bbox and not dry, both ends at most ``dry_depth``
      deep or without a depth, or deep where a ``depth_threshold`` is
      given), ``"bbox"`` or ``"depth"``.

    Runs of open edges become :class:`~terramesh.io.fort14.OpenBoundary`
    node strings (IBTYPEE ``open_ibtype``), the runs between them mainland
    :class:`~terramesh.io.fort14.LandBoundary` strings (IBTYPE
    ``mainland_ibtype``). Each inner loop (clockwise: a hole in the mesh) is
    an island (IBTYPE ``island_ibtype``), whatever its depth.

    Traversal, as ADCIRC requires (fort.14 documentation, ``NBVV``; and the
    "General Notes for Normal Flow Boundary Conditions"): land boundaries
    run with land on the right, so mainland segments counter-clockwise
    around the domain and islands clockwise; open segments, whose direction
    ADCIRC leaves free (``NBDV``), counter-clockwise too. A mainland segment
    starts at the last node of the open segment before it and ends at the
    first node of the open segment after it; islands, and a mainland
    boundary with no open segment (a closed basin), repeat their first node
    as their last. Mainland segments come first, in order around each outer
    loop, then the islands.

    Parameters
    ----------
    mesh : Mesh
        A valid 2D triangle mesh (:func:`terramesh.cleanup.fix_mesh`), in
        longitude, latitude (degrees) or planar units.
    dem : DEM or str or os.PathLike, optional
        Take the depth of the boundary vertices from this DEM (bilinear)
        instead of ``mesh.depth``.
    depth_threshold : float, optional
        Metres, positive down: boundary water deeper than this is open
        ocean. By default none for ``"bbox_or_depth"`` (``inf``: the bbox's
        wet edges only; on a coarse DEM fjord walls and shelf breaks read
        deep, see :data:`DEPTH_THRESHOLD`) and 100 m for ``"depth"``; give
        it for a mesh whose outer boundary is not a box.
    bbox : sequence of 4 float or shapely.Polygon, optional
        ``(x_min, x_max, y_min, y_max)`` (the guide's order; degrees for
        geographic meshes, moved by 360 onto the points when given in the
        other longitude convention), or a polygon (or multipolygon) in the
        points' units (moved by 360 as a box is), whose edge is the open
        outline: the union of the boxes of meshes merged side by side. By
        default the region the mesh was cut from (:func:`cut_region`: the
        shoreline's of a mesh from :func:`build`, the union of the parts'
        of a merged mesh), else the extent of the points.
    open_by : {"bbox_or_depth", "bbox", "depth"}, optional
        Which edges of an outer loop are open ocean.
    island_ibtype, mainland_ibtype : int, optional
        ADCIRC IBTYPE of islands (21: internal, natural no normal flow) and
        of mainland segments (20: external, natural no normal flow).
    open_ibtype : int or None, optional
        IBTYPEE written after NVDLL (ADCIRC allows 0 only); None omits it.
    tolerance : float, optional
        Distance from a bbox side (units of the points) within which a
        vertex is on it; by default 1 % of the median boundary edge length.
    dry_depth : float, optional
        Metres, positive down: a boundary vertex at most this deep counts
        as land (default 0, mean sea level), so the bbox's edge across
        tidal flats or a marsh given 1 or 2 m is mainland, not an elevation
        boundary.

    Returns
    -------
    Mesh
        A new mesh, the same points, cells and ``point_data`` (copies),
        whose ``boundaries`` is a :class:`~terramesh.io.fort14.Boundaries`
        (``mesh.write("fort.14")`` writes it). ``info["boundaries"]`` holds
        the counts (``open``, ``mainland``, ``islands``, ``open_nodes``,
        ``land_nodes``), ``options``, the keyword arguments used, and
        ``made``, a fingerprint of the boundaries made:
        :func:`~terramesh.coastal.enforce_timestep` rebuilds them with those
        options while they are unchanged, and carries edited ones over.

    Raises
    ------
    MeshValidityError
        For a mesh that is not a valid 2D triangle mesh (clockwise cells,
        which would swap outer boundaries and holes, or a vertex with more
        than two boundary edges), a depth rule without depths, or bad
        options (a ``bbox`` apart from the mesh among them, whatever the
        rule: the options are kept and reused).

    Warns
    -----
    TerrameshWarning
        When some boundary vertices have no depth (NaN): they count as land
        (dry) under every rule, so no open segment runs between two of them
        or between one of them and a dry vertex. And for open segments
        less than ``SHALLOW_OPEN`` (1 m) deep at every node (a pond or a
        flat at the box's edge), where ADCIRC would force the tide. And for
        a ``bbox`` far beyond the mesh that would fit it read in shapely's
        order ``(x_min, y_min, x_max, y_max)``.

    References
    ----------
    ADCIRC Users Manual, "Grid and Boundary Information File (fort.14)" and
    "Flux Specified Boundaries", https://adcirc.org and
    https://github.com/adcirc/adcirc (docs/technical_reference).

    Examples
    --------
    A 2 x 1 rectangle whose east side is the bbox edge of a larger box:
    open there, mainland elsewhere.

    >>> import numpy as np, terramesh as tm
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.25)
    >>> result = make_boundaries(mesh, bbox=(-1, 2, -1, 2), open_by="bbox")
    >>> b = result.boundaries
    >>> len(b.open), [land.ibtype for land in b.land]
    (1, [20])
    >>> bool(np.allclose(mesh.points[b.open[0].nodes, 0], 2.0))
    True
    >>> int(b.land[0].nodes[0]) == int(b.open[0].nodes[-1])
    True
    """
    from ..mesh.mesh import Mesh

    if not isinstance(mesh, Mesh):
        raise MeshValidityError(f"make_boundaries takes a terramesh.Mesh, got {type(mesh).__name__}")
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise MeshValidityError("make_boundaries needs a 2D triangle mesh")
    options = _checked_options(
        dem=dem,
        depth_threshold=depth_threshold,
        bbox=bbox,
        open_by=open_by,
        island_ibtype=island_ibtype,
        mainland_ibtype=mainland_ibtype,
        open_ibtype=open_ibtype,
        tolerance=tolerance,
        dry_depth=dry_depth,
    )
    # checked whatever open_by: the options are kept and reused (enforce_timestep), perhaps with another rule
    if bbox is not None:
        options["bbox"] = bbox = _checked_bbox(bbox, mesh.points, mesh.geographic)
    depth_threshold, dry_depth = options["depth_threshold"], options["dry_depth"]
    island_ibtype, mainland_ibtype = options["island_ibtype"], options["mainland_ibtype"]
    open_ibtype = options["open_ibtype"]
    # outer loops and holes are told apart by their orientation, which holds only for counter-clockwise cells
    clockwise = int(np.count_nonzero(signed_areas(mesh.points, mesh.cells) < 0))
    if clockwise:
        raise MeshValidityError(
            f"make_boundaries needs counter-clockwise cells: {clockwise} of {mesh.n_cells} cells are clockwise, and"
            " the outer boundary would be taken for an island; repair the mesh first (terramesh.cleanup.fix_mesh)"
        )
    loops, areas = boundary_loops(mesh.points, mesh.cells)
    vertices = sorted_unique(np.concatenate(loops)) if loops else np.zeros(0, dtype=np.int64)
    is_open_vertex = np.zeros(mesh.n_points, dtype=bool)  # per vertex: deep enough (depth rule)
    is_dry = np.zeros(mesh.n_points, dtype=bool)  # per vertex: land (depth at most 0, or unknown)
    on_outline = None  # per outer-loop edge: on the bbox, or on the region's edge (bbox rule)
    depth = None
    if len(vertices) and open_by in ("bbox_or_depth", "depth"):
        depth, depth_dem = _boundary_depth(mesh, dem, vertices)
        missing = ~np.isfinite(depth)
        if missing.any():
            warn_user(
                f"{int(missing.sum())} of {len(vertices)} boundary vertices have no depth (NaN): they count as land",
            )
        with np.errstate(invalid="ignore"):
            is_open_vertex[vertices] = depth > depth_threshold
            is_dry[vertices] = (depth <= dry_depth) | missing
    if len(vertices) and open_by in ("bbox_or_depth", "bbox"):
        on_outline = _outline_test(mesh, bbox, tolerance, vertices)
    open_segments, mainland, islands = [], [], []
    for loop, area in zip(loops, areas, strict=True):
        if area < 0:  # a hole: an island, clockwise, closed
            islands.append(LandBoundary(np.append(loop, loop[0]), island_ibtype))
            continue
        following = np.roll(loop, -1)
        on_bbox = on_outline(loop, following) if on_outline is not None else np.zeros(len(loop), dtype=bool)
        deep = is_open_vertex[loop] & is_open_vertex[following]
        # the box's edge across land (where it meets the coast): an elevation boundary on dry nodes
        dry = is_dry[loop] & is_dry[following]
        is_open = (on_bbox & ~dry) | deep if open_by == "bbox_or_depth" else (on_bbox if open_by == "bbox" else deep)
        if not is_open.any():
            mainland.append(LandBoundary(np.append(loop, loop[0]), mainland_ibtype))
            continue
        if is_open.all():
            open_segments.append(OpenBoundary(np.append(loop, loop[0]), open_ibtype))
            continue
        for run_is_open, nodes in _segments(loop, is_open):
            if run_is_open:
                open_segments.append(OpenBoundary(nodes, open_ibtype))
            else:
                mainland.append(LandBoundary(nodes, mainland_ibtype))
    if depth is not None:
        _warn_shallow_open(mesh, open_segments, vertices, depth)
        if not open_segments:
            _warn_if_all_dry(mesh, depth_dem)
    boundaries = Boundaries(open=open_segments, land=mainland + islands)
    report = {
        "open": len(open_segments),
        "mainland": len(mainland),
        "islands": len(islands),
        "open_nodes": int(sum(len(b.nodes) for b in open_segments)),
        "land_nodes": int(sum(len(b.nodes) for b in mainland + islands)),
        "options": options,
        "made": boundaries_fingerprint(boundaries),
    }
    return Mesh(
        mesh.points.copy(),
        mesh.cells.copy(),
        point_data={name: np.array(values, copy=True) for name, values in mesh.point_data.items()},
        boundaries=boundaries,
        title=mesh.title,
        crs=mesh.crs,
        info=dict(mesh.info, boundaries=report),
    )


_MAKE_BOUNDARIES_DEFAULTS = {
    name: parameter.default
    for name, parameter in inspect.signature(make_boundaries).parameters.items()
    if parameter.kind is inspect.Parameter.KEYWORD_ONLY
}
"""make_boundaries' options and their defaults: what build's ``boundaries`` dict may hold."""


def _edge_keys(cells, n):
    """Sorted keys ``min * n + max`` of the boundary edges of ``cells`` (``n`` vertices)."""
    edges = boundary_edges(cells)
    return np.sort(np.minimum(edges[:, 0], edges[:, 1]) * n + np.maximum(edges[:, 0], edges[:, 1]))


def _runs_along(nodes, keys, n):
    """Whether each consecutive pair of ``nodes`` is a boundary edge (``keys``, from :func:`_edge_keys`)."""
    a, b = nodes[:-1], nodes[1:]
    wanted = np.minimum(a, b) * n + np.maximum(a, b)
    if len(wanted) == 0:
        return True
    if len(keys) == 0:
        return False
    # a search in the sorted keys: one string costs its own length, not the whole boundary's
    found = np.minimum(np.searchsorted(keys, wanted), len(keys) - 1)
    return bool(np.all(keys[found] == wanted))


def string_ends(boundaries, n_points):
    """Per vertex: the first or last node of a string that is not closed, or a node of a paired barrier.

    Removing such a vertex would leave a gap between two strings that share
    it, or break a barrier's node pairs: :func:`~terramesh.coastal.enforce_timestep`
    keeps them when it carries hand-made boundaries over (:func:`carried_over`).
    """
    kept = np.zeros(n_points, dtype=bool)
    for string in boundaries.open + boundaries.land:
        nodes = np.asarray(string.nodes)
        if len(nodes) and nodes[0] != nodes[-1]:
            kept[nodes[[0, -1]]] = True
    for string in boundaries.land:
        if string.ibtype in PAIRED_TYPES:
            kept[np.asarray(string.nodes)] = True
            if string.paired_nodes is not None:
                kept[np.asarray(string.paired_nodes)] = True
    return kept


def carried_over(boundaries, new_index, before_cells, after_cells, n_after):
    """``boundaries`` in the numbering of a mesh some vertices were removed from: ``(Boundaries, lost)``.

    ``new_index[i]`` is the vertex of the new mesh (``after_cells``,
    ``n_after`` vertices) that vertex ``i`` of the old one
    (``before_cells``) became, -1 for one removed. Every string keeps its
    kind, IBTYPE and order; a removed node is dropped with its row of extra
    columns, and a closed string (first node repeated last) whose first
    node went is closed again at its new first node. A row of a paired
    barrier (IBTYPE 4, 24, 64, 5, 25) goes when its node or its back-face
    node went. A string is dropped when it lost nodes and fewer than two
    are left, or when it ran along the old mesh's boundary and no longer
    runs along the new one's (an island that closed up). ``lost`` says, in
    words, which strings were dropped and which barriers lost node pairs.
    """
    n_before = len(new_index)
    keys_before = _edge_keys(before_cells, n_before)
    keys_after = _edge_keys(after_cells, n_after)
    carried, lost = Boundaries(), []
    for kind, strings in (("open", boundaries.open), ("land", boundaries.land)):
        for number, string in enumerate(strings, start=1):
            nodes = np.asarray(string.nodes)
            paired = None if kind == "open" or string.paired_nodes is None else np.asarray(string.paired_nodes)
            values = None if kind == "open" or string.values is None else np.asarray(string.values)
            keep = new_index[nodes] >= 0
            if paired is not None:
                keep &= new_index[paired] >= 0
            rows = np.flatnonzero(keep)
            closed = len(nodes) > 2 and nodes[0] == nodes[-1]
            if closed and not keep[0] and len(rows):  # the repeated first node went: close at the new first
                rows = np.append(rows, rows[0])
            name = f"{kind} boundary {number} ({'IBTYPEE' if kind == 'open' else 'IBTYPE'} {string.ibtype})"
            new_nodes = new_index[nodes[rows]]
            shortened = len(rows) < len(nodes)
            if shortened and len(np.unique(new_nodes)) < 2:
                lost.append(f"{name} is dropped: fewer than two of its {len(nodes)} nodes are left")
                continue
            sequences = [(nodes, new_nodes)]
            if paired is not None:
                sequences.append((paired, new_index[paired[rows]]))
            if any(
                _runs_along(old, keys_before, n_before) and not _runs_along(new, keys_after, n_after)
                for old, new in sequences
            ):
                on_boundary = np.isin(new_nodes, np.concatenate([keys_after // n_after, keys_after % n_after]))
                if string.ibtype in ISLAND_TYPES and on_boundary.mean() < 0.5:
                    # its hole closed: water cells (deep, as the DEM says) now cover what was land
                    lost.append(
                        f"{name} is dropped: the island is meshed over ({np.count_nonzero(~on_boundary)} of its "
                        f"{len(new_nodes)} nodes lie inside the mesh now, its cells cover the island)"
                    )
                else:
                    lost.append(f"{name} is dropped: its nodes no longer run along the mesh's boundary")
                continue
            if kind == "open":
                carried.open.append(OpenBoundary(new_nodes, string.ibtype))
                continue
            if shortened and string.ibtype in PAIRED_TYPES:
                lost.append(f"{name} lost {len(nodes) - len(rows)} of its {len(nodes)} node pairs")
            carried.land.append(
                LandBoundary(
                    new_nodes,
                    string.ibtype,
                    None if paired is None else new_index[paired[rows]],
                    None if values is None else np.array(values[rows], copy=True),
                )
            )
    return carried, lost


def boundaries_fingerprint(boundaries):
    """A digest of every string's kind, IBTYPE, nodes, pairs and extra columns.

    It tells whether ``mesh.boundaries`` is still what :func:`make_boundaries`
    made (``mesh.info["boundaries"]["made"]``), or was edited since.
    """
    digest = hashlib.sha256()
    for kind, strings in (("open", boundaries.open), ("land", boundaries.land)):
        for string in strings:
            digest.update(f"{kind} {string.ibtype};".encode())
            for array in (string.nodes, getattr(string, "paired_nodes", None), getattr(string, "values", None)):
                if array is None:
                    digest.update(b"-;")
                else:
                    array = np.ascontiguousarray(array)
                    digest.update(f"{array.dtype.str}{array.shape};".encode())
                    digest.update(array.tobytes())
    return digest.hexdigest()
