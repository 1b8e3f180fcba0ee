"""Channel size function (guide §3.4): resolution along thalwegs from the slope function around them.

For each channel point the guide draws a circle whose radius comes from a
V-shaped channel profile with the point's depth and an "angle of reslope"
of 60 degrees, and assigns the ``alpha_ch``-th percentile of the slope size
function inside the circle. The radius here is ``tan(60 deg) |h|``, as in
OceanMesh2D's code: the half-width of a V of depth ``|h|`` whose sides make
60 degrees with the vertical. Channel points come from polylines (such as
the thalwegs of :func:`read_thalwegs`) or from the simple finder
:func:`find_channels`.

The slope function is off (``inf``) shallower than 100 m, where most
channels are, and on land, where overland channels are: give this
function the slope sizes of eq. 7 without the cut-off and on land too
(``slope_size(..., min_depth=None)``). Percentiles are taken over the
finite values in each circle.
"""

import numbers
import os
from collections.abc import Iterable, Mapping

import numpy as np
import shapely

from ..._kernels.raster import channel_circles, thalweg_nodes
from ...errors import GeometryError, SizingError, warn_user
from ..projection import MAX_LATITUDE, to_mercator
from ._common import check_grid, field, mask, positive

__all__ = ["ANGLE_OF_REPOSE", "read_thalwegs", "thalweg_polylines", "find_channels", "channel_size"]

ANGLE_OF_REPOSE = 60.0
"""Angle of the channel's V-shaped profile, degrees (§3.4)."""

_MAX_CELLS = 100


def read_thalwegs(path):
    """Read channel thalwegs from a MATLAB file holding a cell array ``pts2`` of polylines.

    This is the layout of OceanMesh2D's channel networks (for example
    ``ECGC_Thalwegs.mat``): a 1 x n cell array of (k, 2) longitude/latitude
    arrays, each polyline ended by a NaN row. Polylines are split at NaN
    rows, and the NaN rows dropped.

    Parameters
    ----------
    path : str or os.PathLike
        A MATLAB v5 ``.mat`` file (read with :func:`scipy.io.loadmat`).

    Returns
    -------
    list of ndarray, each shape (k, 2)
        Longitude and latitude, degrees.

    Raises
    ------
    GeometryError
        If the file has no ``pts2`` cell array of (k, 2) arrays.

    Examples
    --------
    >>> import os, tempfile, numpy as np, scipy.io
    >>> cells = np.empty((1, 1), dtype=object)
    >>> cells[0, 0] = np.array([[-74.0, 40.5], [-74.1, 40.6], [np.nan, np.nan]])
    >>> path = os.path.join(tempfile.mkdtemp(), "thalwegs.mat")
    >>> scipy.io.savemat(path, {"pts2": cells})
    >>> [line.shape for line in read_thalwegs(path)]
    [(2, 2)]
    """
    from scipy.io import loadmat

    try:
        contents = loadmat(path)
    except (OSError, ValueError, NotImplementedError) as error:
        raise GeometryError(f"cannot read thalwegs from {path}: {error}") from error
    if "pts2" not in contents or contents["pts2"].dtype != object:
        raise GeometryError(f"{path} holds no cell array pts2 of channel polylines")
    polylines = []
    for number, cell in enumerate(contents["pts2"].ravel(), start=1):
        try:
            points = np.asarray(cell, dtype=np.float64)
        except (TypeError, ValueError):
            raise GeometryError(
                f"{path}: channel polyline {number} of pts2 is not numbers (a {np.asarray(cell).dtype} array)"
            ) from None
        if points.size == 0:
            continue
        if points.ndim != 2 or points.shape[1] != 2:
            raise GeometryError(f"{path}: channel polylines must be (k, 2) lon/lat arrays, found shape {points.shape}")
        gaps = np.isnan(points).any(axis=1)
        pieces = np.split(points, np.flatnonzero(gaps))
        polylines.extend(piece[~np.isnan(piece).any(axis=1)] for piece in pieces)
    return [line for line in polylines if len(line)]


def find_channels(grid, depth, *, min_bank_slope=0.02):
    """Thalweg nodes of a DEM: nodes deeper than both neighbours across the valley, with steep enough banks.

    A simple, local channel finder (the guide leaves its own out of scope).
    A node is a thalweg node when, along at least one of the four lines
    through it (east-west, north-south and the two diagonals), it is deeper
    than one neighbour and at least as deep as the other (ties go to the
    node with the larger index, so a flat-bottomed pair yields one node)
    and the mean drop to the two neighbours, per ground metre, is at least
    ``min_bank_slope``. This finds V- and U-shaped valleys whose bottom is
    narrower than about two grid steps, both submerged and overland, within
    one node of their axis (a valley running diagonally between nodes is
    marked on both sides of its axis); noise and gentle undulations are
    left out by the slope threshold. Border nodes are never thalweg nodes.

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    depth : array_like, shape (nx, ny)
        Metres, positive down (land negative).
    min_bank_slope : float, optional
        Smallest mean bank slope (metres of depth per ground metre). The
        guide is silent; 0.02 (about 1.1 degrees) keeps valleys a few
        metres deep on grids of a few hundred metres.

    Returns
    -------
    ndarray of bool, shape (nx, ny)

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 0.2, 0, 0.1), 500.0)
    >>> east = grid.ground_step[0] * np.arange(grid.shape[0])
    >>> valley = 40.0 - 0.1 * np.abs(east - east[20])
    >>> found = find_channels(grid, np.broadcast_to(valley[:, None], grid.shape))
    >>> sorted(set(np.nonzero(found)[0].tolist()))
    [20]
    """
    grid = check_grid(grid)
    min_bank_slope = positive("min_bank_slope", min_bank_slope, allow_zero=True)
    depth = field("depth", depth, grid.shape)
    found = np.zeros(grid.shape, dtype=bool)
    thalweg_nodes(depth, np.ascontiguousarray(grid.ground_step, dtype=np.float64), min_bank_slope, found)
    return found


_ACCEPTED = (
    "a path to a .mat file of thalwegs (read_thalwegs), a (k, 2) lon/lat array, a shapely LineString or "
    "MultiLineString, a list of those arrays or LineStrings, or a boolean (nx, ny) mask of channel nodes"
)


def _shapely_lines(geometry):
    """The (k, 2) lon/lat coordinates of a shapely LineString or MultiLineString's lines, or None for other objects."""
    if isinstance(geometry, shapely.LineString):  # a LinearRing too
        return [shapely.get_coordinates(geometry)]
    if isinstance(geometry, shapely.MultiLineString):
        return [shapely.get_coordinates(line) for line in geometry.geoms]
    return None


def thalweg_polylines(thalwegs):
    """Channel polylines as a list of (k, 2) lon/lat arrays, from any input :func:`channel_size` accepts.

    Parameters
    ----------
    thalwegs : str, os.PathLike, array_like (k, 2), shapely geometry or list
        A path to a MATLAB file of thalwegs (read with
        :func:`read_thalwegs`, as OceanMesh2D's ``ECGC_Thalwegs.mat``); one
        (k, 2) longitude/latitude array; a shapely ``LineString`` or
        ``MultiLineString`` in longitude/latitude (z dropped); or a list or
        tuple of (k, 2) arrays and ``LineString``/``MultiLineString``.

    Returns
    -------
    list of ndarray, each shape (k, 2)
        Longitude and latitude, degrees (float64, not yet checked for
        finiteness: :func:`channel_size` does that).

    Raises
    ------
    SizingError
        For any other input (a number, a mapping, a list of paths, ...),
        naming what is accepted.
    GeometryError
        If the file cannot be read as thalwegs, or a polyline is not a
        (k, 2) array.

    Examples
    --------
    >>> import shapely
    >>> lines = thalweg_polylines(shapely.MultiLineString([[(0, 0), (1, 1)], [(2, 2), (3, 2), (4, 3)]]))
    >>> [line.shape for line in lines]
    [(2, 2), (3, 2)]
    """
    if isinstance(thalwegs, (str, bytes, os.PathLike)):
        return read_thalwegs(os.fsdecode(thalwegs))
    lines = _shapely_lines(thalwegs)
    if lines is not None:
        return lines
    if isinstance(thalwegs, np.ndarray):
        if thalwegs.dtype == object:  # a cell array of polylines, as scipy.io.loadmat gives it
            thalwegs = thalwegs.ravel()
        elif thalwegs.dtype.kind not in "iuf":
            raise SizingError(f"thalwegs must be {_ACCEPTED}; got an array of dtype {thalwegs.dtype}")
        elif thalwegs.ndim in (2, 3):  # one polyline, or polylines of one length
            return list(np.asarray(thalwegs, dtype=np.float64).reshape(-1, *thalwegs.shape[-2:]))
        else:
            raise GeometryError(f"a thalweg array must be (k, 2) lon/lat, got shape {thalwegs.shape}")
    if isinstance(thalwegs, Mapping) or not isinstance(thalwegs, Iterable):
        raise SizingError(f"thalwegs must be {_ACCEPTED}; got {type(thalwegs).__name__}")
    polylines = []
    for k, item in enumerate(thalwegs):
        lines = _shapely_lines(item)
        if lines is not None:
            polylines.extend(lines)
            continue
        try:
            points = np.asarray(item, dtype=np.float64)
        except (TypeError, ValueError):
            raise SizingError(
                f"thalwegs must be {_ACCEPTED}; item {k} of the {type(thalwegs).__name__} is a {type(item).__name__}"
            ) from None
        polylines.append(points)
    return polylines


def _warn_if_outside(grid, polylines, x, y):
    """Warn when no point of the (densified, Mercator) thalwegs ``x, y`` lies in the grid's box."""
    inside = (x >= grid.x[0]) & (x <= grid.x[-1]) & (y >= grid.y[0]) & (y <= grid.y[-1])
    if inside.any():
        return
    box = f"lon {grid.lon[0]:.6g}..{grid.lon[-1]:.6g}, lat {grid.lat[0]:.6g}..{grid.lat[-1]:.6g}"
    points = np.concatenate([np.reshape(line, (-1, 2)) for line in polylines]) if polylines else np.empty((0, 2))
    if not len(points):
        warn_user(f"no thalweg in the box ({box}): thalwegs is empty, so the channel function refines nothing")
        return
    lon, lat = points[:, 0], points[:, 1]
    span = f"lon {lon.min():.6g}..{lon.max():.6g}, lat {lat.min():.6g}..{lat.max():.6g}"
    swapped = (lat >= grid.lon[0]) & (lat <= grid.lon[-1]) & (lon >= grid.lat[0]) & (lon <= grid.lat[-1])
    hint = (
        f"? With the two columns swapped, {int(swapped.sum())} points would be in the box."
        if swapped.any()
        else ", and is the box the right one?"
    )
    warn_user(
        f"no thalweg in the box ({box}): {len(points)} thalweg points span {span}, so the channel function "
        f"refines nothing. Are the thalwegs in lon/lat order{hint}"
    )


def _densified(thalwegs, grid):
    """Mercator points of lon/lat polylines, no two consecutive ones more than a grid step apart.

    Each polyline is moved by whole turns of longitude onto the grid (a
    file in 0..360 for a box in -180..180, or the other way round), and
    runs on across the antimeridian rather than jumping a turn back.
    """
    centre = 0.5 * (grid.lon[0] + grid.lon[-1])
    pieces = []
    for k, line in enumerate(thalwegs):
        points = np.array(line, dtype=np.float64)  # a copy: its longitudes are moved
        if points.ndim != 2 or points.shape[1] != 2:
            raise GeometryError(f"thalweg {k} must be a (k, 2) lon/lat array, got shape {points.shape}")
        if not np.all(np.isfinite(points)):
            raise GeometryError(f"thalweg {k} has non-finite coordinates (split polylines at NaN rows first)")
        if len(points):
            points[:, 0] = np.unwrap(points[:, 0], period=360.0)
            points[:, 0] += 360.0 * np.round((centre - points[:, 0].mean()) / 360.0)
        pieces.append(points)
    if not pieces:
        return np.empty(0), np.empty(0)
    counts = np.array([len(p) for p in pieces])
    points = np.concatenate(pieces)
    # points beyond Mercator's reach cannot be on the grid: drop them and the segments touching them
    keep = np.abs(points[:, 1]) <= MAX_LATITUDE
    x, y = to_mercator(points[:, 0], np.clip(points[:, 1], -MAX_LATITUDE, MAX_LATITUDE))
    first = np.zeros(len(points), dtype=bool)
    first[np.cumsum(counts)[:-1]] = True
    # segment k runs from point k to k + 1 unless k + 1 starts a new polyline
    inside = keep[:-1] & keep[1:] & ~first[1:]
    x0, y0, x1, y1 = x[:-1][inside], y[:-1][inside], x[1:][inside], y[1:][inside]
    parts = np.maximum(np.ceil(np.hypot(x1 - x0, y1 - y0) / grid.step).astype(np.int64), 1)
    owner = np.repeat(np.arange(parts.size), parts - 1)
    rank = np.arange(owner.size) - np.repeat(np.cumsum(parts - 1) - (parts - 1), parts - 1)
    t = (rank + 1) / parts[owner]
    extra_x = x0[owner] + t * (x1 - x0)[owner]
    extra_y = y0[owner] + t * (y1 - y0)[owner]
    x, y = x[keep], y[keep]
    return np.concatenate([x, extra_x]), np.concatenate([y, extra_y])


def channel_size(grid, depth, slope_sizes, *, percentile, thalwegs=None, angle_of_repose=ANGLE_OF_REPOSE):
    """Channel size function, guide §3.4: the ``alpha_ch``-th percentile of the slope function around channels.

    Every channel point gets a circle of radius ``tan(angle) |h|`` ground
    metres (``h`` interpolated bilinearly at the point), always including
    its nearest node and at most 100 nodes wide each side; all nodes in it
    get the ``percentile``-th percentile (linear interpolation, as
    :func:`numpy.percentile`) of the finite slope sizes in it, the smallest
    value winning where circles overlap. Polylines are first densified so
    that consecutive points are at most one grid step apart (otherwise a
    coarse polyline would leave gaps between circles). Ground distances in
    a circle are Mercator distances times ``cos(lat)`` at its centre.

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    depth : array_like, shape (nx, ny)
        Metres, positive down (land negative; overland channels use ``|h|``).
    slope_sizes : array_like, shape (nx, ny)
        The slope function (eq. 7, ground metres; ``inf`` allowed), best
        without its 100 m cut-off and on land too:
        ``slope_size(..., min_depth=None)``.
    percentile : float
        ``alpha_ch``, 0-100 (the guide's ``ch``; it has no default: it is
        "the only argument the user needs to specify").
    thalwegs : path, array_like (k, 2), shapely geometry, list, or ndarray of bool (nx, ny), optional
        Channel polylines in lon/lat degrees (-180..180 or 0..360, each
        moved by whole turns onto the grid): a path to a MATLAB file
        (read with :func:`read_thalwegs`), one (k, 2) array, a shapely
        ``LineString`` or ``MultiLineString``, or a list of arrays and
        shapely lines (see :func:`thalweg_polylines`); or a mask of
        channel nodes; None runs :func:`find_channels` with its defaults.
    angle_of_repose : float, optional
        Degrees (60 in the guide), strictly between 0 and 90.

    Returns
    -------
    ndarray, shape (nx, ny)
        Ground metres; ``inf`` away from channels.

    Raises
    ------
    SizingError
        For a bad ``percentile``, ``angle_of_repose``, field, or
        ``thalwegs`` of a kind not listed above.
    GeometryError
        For a polyline that is not a finite (k, 2) array, or a file that
        holds no thalwegs.

    Warns
    -----
    TerrameshWarning
        When no thalweg point falls in the grid's box (the channel function
        then refines nothing): the polylines are elsewhere, or in lat/lon
        order; or, without ``thalwegs``, when :func:`find_channels` finds
        none.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 0.2, 0, 0.1), 500.0)
    >>> depth = np.full(grid.shape, 20.0)
    >>> slope = np.broadcast_to(1000.0 + np.arange(grid.shape[0])[:, None], grid.shape)
    >>> line = [np.array([[0.1, 0.0], [0.1, 0.1]])]
    >>> f = channel_size(grid, depth, slope, percentile=50, thalwegs=line)
    >>> np.unique(f[np.isfinite(f)]).tolist()
    [1022.0]
    """
    grid = check_grid(grid)
    if isinstance(percentile, bool) or not isinstance(percentile, numbers.Real) or not 0 <= percentile <= 100:
        raise SizingError(f"percentile must be a number from 0 to 100, got {percentile!r}")
    angle = positive("angle_of_repose", angle_of_repose)
    if angle >= 90:
        raise SizingError(f"angle_of_repose must be below 90 degrees, got {angle:g}")
    depth = field("depth", depth, grid.shape)
    slope_sizes = field("slope_sizes", slope_sizes, grid.shape, allow_inf=True)
    if (slope_sizes <= 0).any():
        raise SizingError("slope_sizes must be positive (ground metres)")
    found = thalwegs is None
    if found:
        thalwegs = find_channels(grid, depth)
    if isinstance(thalwegs, np.ndarray) and thalwegs.dtype == np.bool_:
        nodes = mask("thalwegs", thalwegs, grid.shape)
        if found and not nodes.any():  # ch was asked for and does nothing: say so, as for thalwegs elsewhere
            warn_user(
                "the channel function (ch) found no channel in the DEM over the box: it refines nothing; give "
                "thalwegs (e.g. OceanMesh2D's ECGC_Thalwegs.mat) or lower find_channels' min_bank_slope"
            )
        ix, iy = np.nonzero(nodes)
        px, py = grid.x[ix], grid.y[iy]
    else:
        polylines = thalweg_polylines(thalwegs)
        px, py = _densified(polylines, grid)
        _warn_if_outside(grid, polylines, px, py)
    out = np.full(grid.shape, np.inf)
    channel_circles(
        np.ascontiguousarray(px, dtype=np.float64),
        np.ascontiguousarray(py, dtype=np.float64),
        float(grid.x[0]),
        float(grid.y[0]),
        float(grid.step),
        grid.ground_step,
        depth,
        slope_sizes,
        float(np.tan(np.radians(angle))),
        float(percentile),
        _MAX_CELLS,
        out,
    )
    return out
