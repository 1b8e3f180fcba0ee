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

import numpy as np

from ..._kernels.raster import channel_circles
from ...errors import GeometryError, SizingError
from ..projection import MAX_LATITUDE, to_mercator
from ._common import check_grid, field, mask, positive

__all__ = ["ANGLE_OF_REPOSE", "read_thalwegs", "find_channels", "channel_size"]

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
    for cell in contents["pts2"].ravel():
        points = np.asarray(cell, dtype=np.float64)
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
    nx, ny = grid.shape
    found = np.zeros(grid.shape, dtype=bool)
    if nx < 3 or ny < 3:
        return found
    centre = depth[1:-1, 1:-1]
    row_step = grid.ground_step[None, 1:-1]
    lines = (
        (depth[:-2, 1:-1], depth[2:, 1:-1], row_step),  # west, east
        (depth[1:-1, :-2], depth[1:-1, 2:], row_step),  # south, north
        (depth[:-2, :-2], depth[2:, 2:], np.sqrt(2.0) * row_step),  # south-west, north-east
        (depth[2:, :-2], depth[:-2, 2:], np.sqrt(2.0) * row_step),  # south-east, north-west
    )
    inner = found[1:-1, 1:-1]
    for before, after, spacing in lines:
        is_bottom = (centre > before) & (centre >= after)
        steep = (2.0 * centre - before - after) >= 2.0 * min_bank_slope * spacing
        inner |= is_bottom & steep
    return found


def _densified(thalwegs, step):
    """Mercator points of lon/lat polylines, no two consecutive ones more than ``step`` metres apart."""
    pieces = []
    for k, line in enumerate(thalwegs):
        points = np.asarray(line, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 2:
            raise GeometryError(f"thalweg {k} must be a (k, 2) lon/lat array, got shape {points.shape}")
        if not np.all(np.isfinite(points)):
            raise GeometryError(f"thalweg {k} has non-finite coordinates (split polylines at NaN rows first)")
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
    parts = np.maximum(np.ceil(np.hypot(x1 - x0, y1 - y0) / step).astype(np.int64), 1)
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
    thalwegs : list of array_like (k, 2), or ndarray of bool (nx, ny), optional
        Channel polylines in lon/lat degrees (e.g. :func:`read_thalwegs`),
        or a mask of channel nodes; None runs :func:`find_channels` with its
        defaults.
    angle_of_repose : float, optional
        Degrees (60 in the guide), strictly between 0 and 90.

    Returns
    -------
    ndarray, shape (nx, ny)
        Ground metres; ``inf`` away from channels.

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
    if thalwegs is None:
        thalwegs = find_channels(grid, depth)
    if isinstance(thalwegs, np.ndarray) and thalwegs.dtype == np.bool_:
        nodes = mask("thalwegs", thalwegs, grid.shape)
        ix, iy = np.nonzero(nodes)
        px, py = grid.x[ix], grid.y[iy]
    else:
        if isinstance(thalwegs, np.ndarray) and thalwegs.ndim == 2:
            thalwegs = [thalwegs]
        px, py = _densified(thalwegs, grid.step)
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
