"""Depth on the vertices of a mesh from a DEM: the OceanMesh2D guide's ``GridData`` (§6.6), cell averaged.

Point sampling a DEM much finer than the mesh aliases it: a vertex takes
whatever the one DEM cell under it says (a channel bottom, a pier), not the
depth of the water it stands for. :func:`interpolate_bathymetry` averages
the DEM over each vertex's control area, the median-dual cell, instead.
"""

import numbers
import os

import numpy as np

from ..cleanup.fix_mesh import as_triangle_arrays
from ..errors import GeometryError, MeshValidityError, muted_warnings, warn_user
from ..mesh.topology import signed_areas
from .dem import DEM, SHORT_OF_THE_BBOX

__all__ = ["interpolate_bathymetry", "median_dual_average", "METHODS", "DRY_SHARE"]

METHODS = ("cell_average", "bilinear")
"""The methods :func:`interpolate_bathymetry` knows."""

OUTSIDE = ("keep", "edge")
"""What :func:`interpolate_bathymetry` gives vertices outside the DEM: their own depth, or its edge's."""

_CHUNK = 1 << 22
"""Largest number of (triangle, DEM node) candidates handled at once (about 200 MB of temporaries)."""

_INSIDE = -1e-12
"""Barycentric coordinate from which a DEM node counts as inside a triangle (its edges included)."""


def as_dem(dem, lonlat, crs, read_options=None):
    """A :class:`DEM`, read from a file for the extent of ``lonlat`` (degrees, shape (n, 2)) when given a path.

    ``crs`` is the mesh's, for the messages; ``read_options`` those of
    :func:`read_dem` (``variable``, ``band``, ``positive``; None: its
    default), for a file only. The extent is the bbox the file is read for:
    the reader's messages about it ("bbox latitudes 3.29e+06.. are outside
    -90..90" for a mesh in metres) spoke of a bbox the user never gave, so
    the mesh's coordinates are checked and named here.
    """
    if not isinstance(dem, (DEM, str, os.PathLike)):
        raise MeshValidityError(f"dem must be a terramesh.coastal.DEM or a file path, got {type(dem).__name__}")
    lo, hi = np.min(lonlat, axis=0), np.max(lonlat, axis=0)
    extent = f"x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g}"
    if lo[0] < -360.0 or hi[0] > 720.0 or lo[1] < -90.0 or hi[1] > 90.0:  # as the DEM reader tells degrees
        units = f"the mesh is in {crs}" if crs is not None else "a mesh in metres, with no crs?"
        raise GeometryError(
            f"the mesh's coordinates span {extent}: not longitude, latitude degrees ({units}), and a DEM"
            " is in degrees. Give the mesh in longitude, latitude: its points transformed to EPSG:4326 (e.g. with"
            " pyproj.Transformer) and crs='EPSG:4326'"
        )
    read_options = {name: value for name, value in (read_options or {}).items() if value is not None}
    unknown = sorted(set(read_options) - {"variable", "band", "positive"})
    if unknown:
        raise TypeError(f"interpolate_bathymetry got unexpected keyword argument(s) {', '.join(unknown)}")
    if isinstance(dem, DEM):
        if read_options:
            raise MeshValidityError(f"{', '.join(sorted(read_options))}: for a DEM read from a file, not a DEM given")
        return dem
    pad = np.where(hi - lo > 0, 0.0, 1e-6)  # a box, even for one vertex or a line of them
    try:
        # a DEM short of the points' extent: the points outside it are counted and told of next (lonlat_on_dem)
        with muted_warnings(SHORT_OF_THE_BBOX):
            return DEM.read(dem, (lo[0] - pad[0], hi[0] + pad[0], lo[1] - pad[1], hi[1] + pad[1]), **read_options)
    except GeometryError as error:
        raise GeometryError(f"reading the DEM for the mesh's extent ({extent}) as its bbox: {error}") from None


def lonlat_on_dem(dem, lonlat, what, keep=False):
    """``lonlat``'s longitudes moved onto ``dem`` by whole turns, latitudes, and which lie outside it.

    Refused all outside it, warned some: they take its nearest edge value, or
    with ``keep`` keep the depth they have. ``what`` names the points in the
    messages ("vertices", "boundary vertices").
    """
    lon, lat = longitudes_onto_dem(lonlat[:, 0], dem), lonlat[:, 1]
    # beyond the outermost DEM nodes by more than a cell (a pixel-registered grid's nodes are half a cell in);
    # no longitude is beyond a DEM that goes all the way round: DEM.sample wraps onto it
    outside = (lat < dem.lat[0] - dem.dy) | (lat > dem.lat[-1] + dem.dy)
    if not _turn_columns(dem):
        outside |= (lon < dem.lon[0] - dem.dx) | (lon > dem.lon[-1] + dem.dx)
    fate = "keep their depth" if keep else "take the depth at its nearest edge"
    check_outside(outside, lonlat, what, "the DEM", dem.bbox, fate)
    return lon, lat, outside


def check_outside(outside, lonlat, what, grid, extent, fate):
    """Refuse points all ``outside`` a grid; warn where some are, saying their ``fate``.

    ``what`` names the points ("vertices"), ``grid`` the grid ("the DEM"),
    ``extent`` is its ``(lon_min, lon_max, lat_min, lat_max)``, ``fate``
    what the points outside get ("take the depth at its nearest edge").
    """
    extent = "lon {:g}..{:g}, lat {:g}..{:g}".format(*extent)
    if outside.all():
        raise GeometryError(
            f"all {len(lonlat)} {what} lie outside {grid} ({extent}) (they span x {lonlat[:, 0].min():g}.."
            f"{lonlat[:, 0].max():g}, y {lonlat[:, 1].min():g}..{lonlat[:, 1].max():g}): is the mesh in another"
            " place or in metres, not degrees?"
        )
    if outside.any():
        warn_user(f"{int(outside.sum())} of {len(lonlat)} {what} lie outside {grid} ({extent}): they {fate}")


def longitudes_onto_dem(lon, dem):
    """``lon`` moved by one whole turn (-360, 0 or 360) so that its range overlaps the DEM's most."""
    lo, hi = float(np.min(lon)), float(np.max(lon))
    overlaps = [min(hi + s, dem.lon[-1]) - max(lo + s, dem.lon[0]) for s in (0.0, -360.0, 360.0)]
    return lon + (0.0, -360.0, 360.0)[int(np.argmax(overlaps))]


def _turn_columns(dem):
    """Number of DEM columns in one turn of longitude for a DEM that goes all the way round, else 0.

    Such a DEM is periodic: column ``i + turn`` is column ``i`` a turn
    east, so a mesh across its seam (180 on a -180..180 grid) still finds
    DEM nodes on both sides. Both registrations count: nodes on -180 and
    180 (the last column repeats the first) or cell centres half a cell in
    from each (the gap across the seam is one step).
    """
    turn = int(round(360.0 / dem.dx))
    # a whole number of steps in 360 degrees, to far better than a node's share of a control area
    whole = abs(turn * dem.dx - 360.0) <= 1e-2 * dem.dx
    return turn if whole and dem.shape[0] >= turn else 0


def median_dual_average(points, cells, dem, values=None, *, min_samples=1):
    """Average DEM values over each vertex's median-dual cell.

    The median-dual cell of a vertex is the union, over its triangles, of
    the quadrilateral bounded by the vertex, the midpoints of its two edges
    in that triangle and the triangle's centroid. Equivalently: the points
    of a triangle whose barycentric coordinate for that vertex is the
    largest of the three. The cells tile the mesh exactly, so each DEM node
    inside the mesh counts for one vertex, and DEM nodes outside the mesh
    (on land beyond the shoreline) count for none. The partition is made in
    longitude-latitude coordinates; barycentric coordinates are invariant
    under affine maps, so within a triangle it is the ground's to first
    order in the triangle's size.

    Every DEM node (a sample of the grid, node registered) has the same
    weight: the area a node stands for changes with ``cos(lat)``, by a
    negligible amount across one control area.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
        Longitude, latitude, degrees.
    cells : numpy.ndarray, shape (m, 3)
        Vertex indices of each triangle.
    dem : DEM
        One that goes all the way round in longitude is periodic: a mesh
        across its seam (180 on a -180..180 grid) gathers the nodes on both
        sides.
    values : numpy.ndarray, shape (nx, ny), optional
        Values on the DEM's grid to average; by default its depth (metres,
        positive down).
    min_samples : int, optional
        Vertices whose cell holds fewer DEM nodes get NaN.

    Returns
    -------
    average : numpy.ndarray, shape (n,)
        The mean of the nodes in each vertex's cell, NaN where there are
        fewer than ``min_samples``.
    count : numpy.ndarray, shape (n,)
        Number of DEM nodes in each vertex's cell.

    Examples
    --------
    A DEM of 11 x 11 nodes on the unit square, depth ``x + y``, and a mesh
    of two cells over it: every node counts once, and each corner gets the
    mean of the nodes nearest to it.

    >>> import numpy as np
    >>> grid = np.linspace(0.0, 1.0, 11)
    >>> dem = DEM(grid, grid, -np.add.outer(grid, grid))
    >>> points = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> average, count = median_dual_average(points, np.array([[0, 1, 2], [0, 2, 3]]), dem)
    >>> int(count.sum()), average.round(2).tolist()
    (121, [0.52, 1.02, 1.46, 0.99])
    """
    _, points, cells = as_triangle_arrays(points, cells)
    values = dem.depth if values is None else np.asarray(values, dtype=np.float64)
    if values.shape != dem.shape:
        raise MeshValidityError(f"values have shape {values.shape}, not the DEM's {dem.shape}")
    n, (nx, ny) = len(points), dem.shape
    turn = _turn_columns(dem)
    lon = longitudes_onto_dem(points[:, 0], dem)
    corner = np.stack([np.column_stack([lon[cells[:, k]], points[cells[:, k], 1]]) for k in range(3)], axis=1)
    low, high = corner.min(axis=1), corner.max(axis=1)
    # DEM node index ranges covering each triangle's bounding box; on a DEM that goes all the way round,
    # indices past either end stand for the columns a turn away, which the one shift of longitudes_onto_dem cannot
    # reach for a mesh across the seam
    i_lo = np.ceil((low[:, 0] - dem.lon[0]) / dem.dx - 1e-9)
    i_hi = np.floor((high[:, 0] - dem.lon[0]) / dem.dx + 1e-9)
    if not turn:
        i_lo, i_hi = np.clip(i_lo, 0, nx), np.clip(i_hi, -1, nx - 1)
    i_lo, i_hi = i_lo.astype(np.int64), i_hi.astype(np.int64)
    j_lo = np.clip(np.ceil((low[:, 1] - dem.lat[0]) / dem.dy - 1e-9), 0, ny).astype(np.int64)
    j_hi = np.clip(np.floor((high[:, 1] - dem.lat[0]) / dem.dy + 1e-9), -1, ny - 1).astype(np.int64)
    width = np.maximum(j_hi - j_lo + 1, 0)
    counts = np.maximum(i_hi - i_lo + 1, 0) * width
    triangles = np.flatnonzero(counts)
    ends = np.cumsum(counts[triangles])
    nodes, owners = [], []
    first = 0
    while first < len(triangles):
        start = ends[first - 1] if first else 0
        last = max(first + 1, int(np.searchsorted(ends, start + _CHUNK, side="right")))
        chunk = triangles[first:last]
        t = np.repeat(chunk, counts[chunk])
        offset = np.arange(len(t)) - np.repeat(np.cumsum(counts[chunk]) - counts[chunk], counts[chunk])
        ii = i_lo[t] + offset // width[t]
        jj = j_lo[t] + offset % width[t]
        if turn:
            ii, turns = np.mod(ii, turn), np.floor_divide(ii, turn)
            px = dem.lon[ii] + 360.0 * turns
        else:
            px = dem.lon[ii]
        py = dem.lat[jj]
        a, b, c = corner[t, 0], corner[t, 1], corner[t, 2]
        det = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            l0 = ((b[:, 1] - c[:, 1]) * (px - c[:, 0]) + (c[:, 0] - b[:, 0]) * (py - c[:, 1])) / det
            l1 = ((c[:, 1] - a[:, 1]) * (px - c[:, 0]) + (a[:, 0] - c[:, 0]) * (py - c[:, 1])) / det
        lam = np.column_stack([l0, l1, 1.0 - l0 - l1])
        inside = np.all(lam >= _INSIDE, axis=1) & (det != 0)
        vertex = cells[t[inside], np.argmax(lam[inside], axis=1)]
        node = ii[inside] * ny + jj[inside]
        node, keep = np.unique(node, return_index=True)
        nodes.append(node)
        owners.append(vertex[keep])
        first = last
    node = np.concatenate(nodes) if nodes else np.zeros(0, dtype=np.int64)
    owner = np.concatenate(owners) if owners else np.zeros(0, dtype=np.int64)
    node, keep = np.unique(node, return_index=True)  # a node on an edge between chunks counts once
    owner = owner[keep]
    count = np.bincount(owner, minlength=n)
    total = np.bincount(owner, weights=values.ravel()[node], minlength=n)
    with np.errstate(divide="ignore", invalid="ignore"):
        average = np.where(count >= max(int(min_samples), 1), total / count, np.nan)
    return average, count


MIN_SAMPLES = 4
"""DEM nodes a control area holds, at the fewest, for :func:`interpolate_bathymetry` to average them.

With one, a vertex whose cell caught a single node of a DEM as coarse as
the mesh took that node's value, up to half a DEM cell away, beside
bilinear neighbours: on a plane of 500 m per degree sampled every 0.1
degree, errors of 25 m where bilinear has none; 104 m in the Gulf of
Maine against ETOPO1, 698 m near Fiji. Four nodes (a DEM about twice as
fine as the mesh or finer) make a mean.
"""


DRY_SHARE = 0.75
"""Share of a mesh's area at or above 0 m in the DEM beyond which :func:`interpolate_bathymetry` warns.

A coastal mesh is of the sea, and the sea is below 0 m: most of it above is
a DEM of depths (positive down) read as elevation. Measured on a Gulf of
Maine mesh (-71 -66 42 45, 2 km at the coast) on ETOPO1: 1.9 % of its area
(22 % of its vertices, which crowd the coast), 98 % with the DEM's sign
turned. A box over land and sea (Sabine Lake, uniform) is 43 % or 57 %
either way, and is left alone.
"""


def _warn_if_mostly_dry(points, cells, depth, given, dem):
    """Warn when most of the area given depths by ``dem`` is land: its sign is probably the wrong way round.

    Each vertex weighs a third of its cells' area (planar degrees: a share,
    not an area); ``given`` marks the vertices that took the DEM's depth.
    """
    areas = np.abs(signed_areas(points, cells))
    weight = np.bincount(cells.ravel(), weights=np.repeat(areas / 3.0, 3), minlength=len(points))[given]
    dry = float(weight[depth[given] <= 0].sum())
    if weight.size and dry > DRY_SHARE * float(weight.sum()):
        where = "the DEM" if dem.source is None else f"the DEM ({dem.source})"
        warn_user(
            f"{dry / float(weight.sum()):.0%} of the mesh's area lies at or above 0 m in {where}, where a coastal "
            f"mesh is mostly of the sea: {dem.sign_advice()}"
        )


def interpolate_bathymetry(
    mesh, dem, *, min_depth=None, method="cell_average", min_samples=MIN_SAMPLES, outside=None, **read_options
):
    """Put the DEM's depth on the mesh vertices, averaged over each vertex's control area (the guide's ``GridData``).

    With ``method="cell_average"`` (the guide's cell-averaged approach)
    each vertex's depth is the mean of the DEM nodes inside its control
    area, the median-dual cell: the points of the vertex's triangles that
    are closer, in barycentric terms, to it than to the other two corners
    (the quadrilaterals bounded by the vertex, the midpoints of its edges
    and the centroids of its triangles; see :func:`median_dual_average`).
    The cells tile the mesh, so every DEM node inside the mesh counts once
    and DEM nodes outside it (beyond the shoreline) not at all. Vertices
    whose cell holds fewer than ``min_samples`` DEM nodes (where the DEM is
    as coarse as the mesh or coarser) take the DEM's bilinear interpolation
    at the vertex instead. ``method="bilinear"`` point samples everywhere.

    Parameters
    ----------
    mesh : Mesh
        A 2D triangle mesh in longitude, latitude degrees (``crs``
        EPSG:4326, or None for points known to be longitude, latitude:
        the mesh returned then says ``EPSG:4326``, so that the steps after,
        such as :func:`courant_number`, measure it in degrees too).
    dem : DEM or str or os.PathLike
        Elevation, metres, positive up; a file is read for the mesh's
        extent (:func:`terramesh.coastal.read_dem`).
    min_depth : float, optional
        Metres, positive down: depths shallower than this (land included)
        are raised to it, e.g. 1 m for a model without wetting and drying.
    method : {"cell_average", "bilinear"}, optional
    min_samples : int, optional
        Fewest DEM nodes a control area must hold to be averaged
        (:data:`MIN_SAMPLES`, 4).
    outside : {"keep", "edge"}, optional
        What vertices outside the DEM get (beyond its outermost nodes by
        more than a cell): ``"keep"`` their depth (``mesh.depth``), as
        the guide's ``GridData`` does, so that a fine DEM put on after a
        coarse one changes only where it covers (a vertex whose depth is
        NaN takes the edge value); ``"edge"`` the DEM's nearest edge
        value. By default ``"keep"`` for a mesh with finite depths,
        ``"edge"`` for one without.
    **read_options
        For a ``dem`` given as a file: :func:`~terramesh.coastal.read_dem`'s
        ``variable``, ``band`` and ``positive``.

    Returns
    -------
    Mesh
        A new mesh (the input is not modified) whose ``point_data["depth"]``
        (``mesh.depth``) is the depth, metres, positive down (ADCIRC's
        sign); ``boundaries`` and the other ``point_data`` are kept.
        ``info["bathymetry"]`` counts the vertices ``averaged`` and
        ``sampled`` (bilinear), with the median number of DEM nodes per
        averaged vertex (``samples_median``), and those outside the DEM
        that ``kept`` their depth.

    Raises
    ------
    MeshValidityError
        For a mesh that is not a 2D triangle mesh in degrees, or bad options.
    GeometryError
        When every vertex lies outside the DEM (a mesh elsewhere, or in metres).

    Warns
    -----
    TerrameshWarning
        When vertices lie outside the DEM (by more than one DEM cell): they
        keep their depth, or take its nearest edge value (``outside``). No
        longitude is outside a DEM that goes all the way round. When more
        than :data:`DRY_SHARE` of the area it gives depths to is at or
        above 0 m (a DEM of depths read as elevation).

    See Also
    --------
    median_dual_average : the average on its own, for any field on the DEM's grid.

    Examples
    --------
    A DEM on a 0.01 degree grid, deepening eastwards by 100 m per degree,
    and a mesh of 0.1 degree triangles: each vertex gets the mean of the
    DEM nodes around it.

    >>> import numpy as np, terramesh as tm
    >>> lon, lat = np.linspace(-1.0, 1.0, 201), np.linspace(-1.0, 1.0, 201)
    >>> dem = tm.coastal.DEM(lon, lat, np.repeat(-100.0 * (lon[:, None] + 2.0), 201, axis=1))
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((-0.5, -0.5), (0.5, 0.5)), 0.1)
    >>> mesh.crs = "EPSG:4326"
    >>> result = interpolate_bathymetry(mesh, dem, min_depth=160.0)
    >>> bool(np.all(result.depth >= 160.0)), result.info["bathymetry"]["averaged"] == mesh.n_points
    (True, True)
    >>> expected = np.maximum(100.0 * (mesh.points[:, 0] + 2.0), 160.0)
    >>> inner = np.abs(mesh.points[:, 0]) < 0.45  # the cells of vertices on the edge are one-sided
    >>> bool(np.abs(result.depth - expected)[inner].max() < 1.0)
    True
    """
    from ..mesh.mesh import Mesh

    if not isinstance(mesh, Mesh):
        raise MeshValidityError(f"interpolate_bathymetry takes a terramesh.Mesh, got {type(mesh).__name__}")
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise MeshValidityError("interpolate_bathymetry needs a 2D triangle mesh")
    if mesh.crs is not None and not mesh.geographic:
        raise MeshValidityError(f"the mesh is in {mesh.crs}; interpolate_bathymetry needs longitude, latitude degrees")
    if method not in METHODS:
        raise MeshValidityError(f"method must be one of {', '.join(METHODS)}; got {method!r}")
    if min_depth is not None and (not isinstance(min_depth, numbers.Real) or not np.isfinite(min_depth)):
        raise MeshValidityError(f"min_depth must be a finite number of metres, got {min_depth!r}")
    if not isinstance(min_samples, numbers.Integral) or isinstance(min_samples, bool) or min_samples < 1:
        raise MeshValidityError(f"min_samples must be a positive integer, got {min_samples!r}")
    if mesh.n_points == 0:
        raise MeshValidityError("the mesh has no vertices")
    # build's mesh without a DEM has depths, all NaN: none to keep
    has_depth = "depth" in mesh.point_data and bool(np.isfinite(mesh.depth).any())
    if outside is None:
        outside = "keep" if has_depth else "edge"
    if outside not in OUTSIDE:
        raise MeshValidityError(f"outside must be one of {', '.join(OUTSIDE)}; got {outside!r}")
    if outside == "keep" and not has_depth:
        raise MeshValidityError('outside="keep" keeps the depths the mesh has, and it has none: use "edge"')
    dem = as_dem(dem, mesh.points, mesh.crs, read_options)
    lon, lat, beyond = lonlat_on_dem(dem, mesh.points, "vertices", keep=outside == "keep")
    sampled = -dem.sample(lon, lat)
    if method == "cell_average":
        average, count = median_dual_average(mesh.points, mesh.cells, dem, min_samples=min_samples)
        averaged = np.isfinite(average)
        depth = np.where(averaged, average, sampled)
    else:
        averaged, count = np.zeros(mesh.n_points, dtype=bool), np.zeros(mesh.n_points, dtype=np.int64)
        depth = sampled
    if outside == "keep":
        beyond &= np.isfinite(mesh.depth)  # a vertex without a depth takes the edge's, as with "edge"
        depth = np.where(beyond, mesh.depth, depth)
    given = ~beyond if outside == "keep" else np.ones(mesh.n_points, dtype=bool)
    _warn_if_mostly_dry(mesh.points, mesh.cells, depth, given, dem)
    if min_depth is not None:
        depth = np.maximum(depth, float(min_depth))
    report = {
        "method": method,
        "averaged": int(averaged.sum()),
        "sampled": int(mesh.n_points - averaged.sum()),
        "samples_median": float(np.median(count[averaged])) if averaged.any() else 0.0,
        "kept": int(beyond.sum()) if outside == "keep" else 0,
        "min_depth": None if min_depth is None else float(min_depth),
        "dem": repr(dem),
    }
    point_data = {name: np.array(values, copy=True) for name, values in mesh.point_data.items()}
    point_data["depth"] = depth
    boundaries = None if mesh.boundaries is None else mesh.boundaries.renumbered(np.arange(mesh.n_points))
    return Mesh(
        mesh.points.copy(),
        mesh.cells.copy(),
        point_data=point_data,
        boundaries=boundaries,
        title=mesh.title,
        # taken as degrees here, and so from here on: read as planar metres, courant_number made 37,135 of 0.454
        # and enforce_timestep removed 101 of 517 vertices from a mesh that met its time step
        crs="EPSG:4326" if mesh.crs is None else mesh.crs,
        info=dict(mesh.info, bathymetry=report),
    )
