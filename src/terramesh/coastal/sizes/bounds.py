"""Bounds on the size function: ``min_el``, ``max_el``, ``max_el_ns``, and bounds per depth range or polygon.

These are the guide's edgefx options ``max_el``, ``max_el_ns`` and the
meshing ``h0`` (§5 examples). Depth-range bounds follow oceanmesh's rows
``[min size, max size, min elevation, max elevation]``, written here with
depths positive down.
"""

import numpy as np
import shapely

from ...errors import SizingError, warn_user
from ._common import check_grid, field, mask, positive
from .distance import polygon_mask

__all__ = ["NEARSHORE_WIDTH", "nearshore_mask", "bound_sizes"]

NEARSHORE_WIDTH = 100.0
"""Ground metres from the coastline within which ``max_el_ns`` applies (OceanMesh2D: ``|d| < 100`` m)."""


def nearshore_mask(grid, distance, *, width=NEARSHORE_WIDTH):
    """Nodes "nearshore", where ``max_el_ns`` applies: within ``width`` of the coastline, on either side.

    The guide does not define nearshore; OceanMesh2D's code takes the nodes
    within 100 m of the shoreline (water and land). On grids coarser than
    that, the band is widened to one grid step (the row's ground step), so
    that the nodes next to the coastline are always in it.

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    distance : array_like, shape (nx, ny)
        Ground distance to the coastline, metres.
    width : float, optional
        Metres.

    Returns
    -------
    ndarray of bool, shape (nx, ny)

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 0.1, 0, 0.1), 50.0)
    >>> nearshore_mask(grid, np.full(grid.shape, 80.0)).all()
    np.True_
    """
    grid = check_grid(grid)
    width = positive("width", width)
    distance = field("distance", distance, grid.shape, allow_inf=True)
    return distance <= np.maximum(width, grid.ground_step)[None, :]


def _size_or_none(name, value):
    return None if value is None else positive(name, value, allow_inf=True)


def _depth_rows(depth_bounds):
    rows = []
    for k, row in enumerate(depth_bounds):
        if len(row) != 4:
            raise SizingError(
                f"depth_bounds row {k} must be (min_edge_length, max_edge_length, min_depth, max_depth), got {row!r}"
            )
        low, high, shallow, deep = (np.nan if v is None else float(v) for v in row)
        if np.isnan(shallow) or np.isnan(deep) or shallow >= deep:
            raise SizingError(f"depth_bounds row {k}: need min_depth < max_depth (metres, positive down), got {row!r}")
        rows.append((_bound_pair(f"depth_bounds row {k}", low, high), shallow, deep))
    return rows


def _bound_pair(name, low, high):
    low = None if low is None or np.isnan(low) else positive(f"{name} min_edge_length", low)
    high = None if high is None or np.isnan(high) else positive(f"{name} max_edge_length", high, allow_inf=True)
    if low is not None and high is not None and low > high:
        raise SizingError(f"{name}: min_edge_length {low:g} exceeds max_edge_length {high:g}")
    return low, high


def _clip(sizes, where, low, high):
    if low is not None:
        np.maximum(sizes, low, out=sizes, where=where)
    if high is not None:
        np.minimum(sizes, high, out=sizes, where=where)


def bound_sizes(
    sizes,
    *,
    min_edge_length=None,
    max_edge_length=None,
    max_edge_length_nearshore=None,
    nearshore=None,
    depth=None,
    depth_bounds=None,
    polygon_bounds=None,
    grid=None,
    overwrite_sizes=False,
):
    """Clip a size function to the guide's bounds, in this order.

    1. ``max_edge_length_nearshore`` (``max_el_ns``) where ``nearshore``;
    2. each row of ``depth_bounds``, in order, where its depth range holds;
    3. each row of ``polygon_bounds``, in order, inside its polygon;
    4. ``min_edge_length`` (``h0``) and ``max_edge_length`` (``max_el``)
       everywhere, last, so the result always lies between them.

    OceanMesh2D applies the nearshore cap, then ``h0``, then ``max_el``
    (its depth ranges included), in the same spirit.

    Parameters
    ----------
    sizes : array_like, shape (nx, ny)
        Ground metres (``inf`` where nothing constrains); not modified
        unless ``overwrite_sizes``.
    min_edge_length, max_edge_length : float, optional
        Metres.
    max_edge_length_nearshore : float, optional
        Metres; needs ``nearshore``.
    nearshore : array_like of bool, optional
        Where the nearshore cap applies (:func:`nearshore_mask`).
    depth : array_like, optional
        Metres, positive down; needed by ``depth_bounds``.
    depth_bounds : sequence of (min_size, max_size, min_depth, max_depth), optional
        Each row clips sizes to ``[min_size, max_size]`` where
        ``min_depth <= depth < max_depth`` (metres, positive down;
        ``-inf``/``inf`` for open ranges, ``None`` or NaN for no size bound).
    polygon_bounds : sequence of (polygon, min_size, max_size), optional
        Shapely polygons in lon/lat degrees (-180..180 or 0..360, whichever
        the grid's box is in), with metres bounds (``None`` for none); needs
        ``grid``. A polygon that covers no grid node draws a warning.
    grid : GeoGrid, optional
        For ``polygon_bounds``.
    overwrite_sizes : bool, optional
        Clip a float64 C-contiguous ``sizes`` array in place and return it,
        instead of a copy.

    Returns
    -------
    ndarray
        Ground metres, a new array (``sizes`` itself if overwritten).

    Warns
    -----
    TerrameshWarning
        For a row of ``polygon_bounds`` whose polygon covers no grid node.

    Examples
    --------
    >>> import numpy as np
    >>> sizes = np.array([[10.0, 5e3], [np.inf, 2e3]])
    >>> bound_sizes(sizes, min_edge_length=50.0, max_edge_length=4e3).tolist()
    [[50.0, 4000.0], [4000.0, 2000.0]]
    >>> depth = np.array([[5.0, 5.0], [500.0, 500.0]])
    >>> bound_sizes(sizes, depth=depth, depth_bounds=[(None, 1e3, 0.0, 10.0)]).tolist()
    [[10.0, 1000.0], [inf, 2000.0]]
    """
    result = field("sizes", sizes, allow_inf=True, positive_only=True)
    # np.asarray may hand back a view of the same memory (a float64 whose dtype object differs): that counts
    if not (overwrite_sizes and np.may_share_memory(result, sizes) and result.flags.writeable):
        result = result.copy()
    low = _size_or_none("min_edge_length", min_edge_length)
    high = _size_or_none("max_edge_length", max_edge_length)
    if low is not None and high is not None and low > high:
        raise SizingError(f"min_edge_length {low:g} exceeds max_edge_length {high:g}")
    if max_edge_length_nearshore is not None:
        cap = positive("max_edge_length_nearshore", max_edge_length_nearshore, allow_inf=True)
        if nearshore is None:
            raise SizingError("max_edge_length_nearshore needs the nearshore mask (nearshore_mask(grid, distance))")
        if low is not None and cap < low:
            raise SizingError(f"max_edge_length_nearshore {cap:g} is below min_edge_length {low:g}")
        _clip(result, mask("nearshore", nearshore, result.shape), None, cap)
    elif nearshore is not None:
        raise SizingError("nearshore was given without max_edge_length_nearshore")
    if depth_bounds is not None:
        if depth is None:
            raise SizingError("depth_bounds needs depth (metres, positive down)")
        depth = field("depth", depth, result.shape)
        for (row_low, row_high), shallow, deep in _depth_rows(depth_bounds):
            _clip(result, (depth >= shallow) & (depth < deep), row_low, row_high)
    if polygon_bounds is not None:
        if grid is None:
            raise SizingError("polygon_bounds needs the grid")
        grid = check_grid(grid)
        if grid.shape != result.shape:
            raise SizingError(f"sizes have shape {result.shape}, the grid is {grid.shape}")
        for k, row in enumerate(polygon_bounds):
            if len(row) != 3:
                raise SizingError(f"polygon_bounds row {k} must be (polygon, min_edge_length, max_edge_length)")
            polygon, row_low, row_high = row
            row_low, row_high = _bound_pair(
                f"polygon_bounds row {k}",
                None if row_low is None else float(row_low),
                None if row_high is None else float(row_high),
            )
            inside = polygon_mask(grid, polygon)
            if not inside.any():
                west, south, east, north = shapely.bounds(polygon).tolist()
                warn_user(
                    f"polygon_bounds row {k} (lon {west:g}..{east:g}, lat {south:g}..{north:g}) covers no node of "
                    f"the size grid (lon {grid.lon[0]:g}..{grid.lon[-1]:g}, lat {grid.lat[0]:g}..{grid.lat[-1]:g}): "
                    "its bounds do nothing; is it in the box, in lon/lat order, and wider than a grid step?"
                )
            _clip(result, inside, row_low, row_high)
    _clip(result, True, low, high)
    return result
