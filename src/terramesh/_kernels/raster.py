"""Raster kernels for the coastal size functions on a :class:`~terramesh.coastal.GeoGrid`.

Private: arrays are C-contiguous, of the documented dtype and unvalidated;
the public wrappers are in :mod:`terramesh.coastal.sizes`. Fields are
``(nx, ny)`` and indexed ``[ix, iy]``; the grid is separable, so a row
``iy`` has one latitude and a column ``ix`` one longitude.

* :func:`scanline_fill`: even-odd polygon fill, one scanline per grid row.
* :func:`mark_segments`, :func:`neighbourhood_segments` and :func:`nearest_segment_distance`: the coastline
  drawn onto the grid, then the exact distance to the segments found near
  the nearest drawn node.
* :func:`nearest_feature`: the nearest marked node of every node (exact Euclidean distance transform).
* :func:`nearest_node_distance`: ground distance to a given node.
* :func:`gradient_norm`: ``|grad f|`` per ground metre, of a field or of a
  distance signed by a water mask.
* :func:`box_pass_axis0` and :func:`box_pass_axis1`: one pass of an
  extended box filter, whose cascade is the Gaussian of the slope filter.
* :func:`with_company`: the nodes of a mask with enough others near them (the medial axis's pruning).
* :func:`thalweg_nodes`: the channel finder's valley bottoms.
* :func:`channel_circles`: the channel function's circles of influence.
* :func:`bilinear_lonlat`: a DEM's elevation at points, longitudes wrapped.
* :func:`value_census`: counts of NaN, infinite and non-positive values, the fields' checks in one pass.
* :func:`wave_speed` and :func:`wavelength_size`: the CFL and wavelength formulas, fused.
* :func:`lower_near_points`: a seismic size grid lowered around sources and receivers.
"""

import math

import numba
import numpy as np

from .arrays import count_below, sort_in_place
from .chunks import chunk_range

EARTH_RADIUS = 6378137.0  # the Mercator sphere of terramesh.coastal.projection


@numba.njit(cache=True)
def scanline_fill(lon0, lat0, lon1, lat1, lon, lat):
    """Nodes inside the rings whose edges run from ``(lon0, lat0)`` to ``(lon1, lat1)`` (even-odd rule).

    ``lon`` (nx,) and ``lat`` (ny,) are the ascending node coordinates. An
    edge crosses row ``iy`` when ``min(lat0, lat1) <= lat[iy] < max(...)``;
    a node is inside when an odd number of crossings lie at or left of it,
    which is the crossing-number test on the plane of the edges' coordinates.
    Returns a (ny, nx) bool array (rows first, for contiguous writes).
    """
    nx = lon.size
    ny = lat.size
    n_edges = lon0.size
    counts = np.zeros(ny + 1, np.int64)
    for e in range(n_edges):
        ya = lat0[e]
        yb = lat1[e]
        if ya == yb:
            continue
        first = count_below(lat, min(ya, yb))
        stop = count_below(lat, max(ya, yb))
        for iy in range(first, stop):
            counts[iy + 1] += 1
    offsets = np.cumsum(counts)
    crossings = np.empty(offsets[-1])
    filled = offsets[:-1].copy()
    for e in range(n_edges):
        ya = lat0[e]
        yb = lat1[e]
        if ya == yb:
            continue
        first = count_below(lat, min(ya, yb))
        stop = count_below(lat, max(ya, yb))
        slope = (lon1[e] - lon0[e]) / (yb - ya)
        for iy in range(first, stop):
            crossings[filled[iy]] = lon0[e] + (lat[iy] - ya) * slope
            filled[iy] += 1
    inside = np.zeros((ny, nx), np.bool_)
    for iy in range(ny):
        row = crossings[offsets[iy] : offsets[iy + 1]]
        sort_in_place(row, row.size)
        for k in range(0, row.size - 1, 2):
            start = count_below(lon, row[k])
            stop = count_below(lon, row[k + 1])
            for ix in range(start, stop):
                inside[iy, ix] = True
    return inside


@numba.njit(cache=True)
def mark_segments(ax, ay, bx, by, nx, ny):
    """The raster cells each segment (given in node units) passes: pairs ``(cell, segment)``.

    Each segment is sampled at most half a node spacing apart and every
    sample marks its nearest node, whose cell index is ``ix * ny + iy``;
    a segment's consecutive repeats of one cell are recorded once. Samples
    off the (nx, ny) raster are dropped. Returns int64 cells and int64
    segment indices, in drawing order.
    """
    total = 0
    for s in range(ax.size):
        dx = bx[s] - ax[s]
        dy = by[s] - ay[s]
        total += int(np.ceil(2.0 * np.sqrt(dx * dx + dy * dy))) + 2
    cells = np.empty(total, np.int64)
    segments = np.empty(total, np.int64)
    n_marks = 0
    for s in range(ax.size):
        dx = bx[s] - ax[s]
        dy = by[s] - ay[s]
        n = int(np.ceil(2.0 * np.sqrt(dx * dx + dy * dy))) + 1
        last = -1
        for k in range(n + 1):
            t = k / n
            ix = int(np.floor(ax[s] + t * dx + 0.5))
            iy = int(np.floor(ay[s] + t * dy + 0.5))
            if 0 <= ix < nx and 0 <= iy < ny:
                cell = ix * ny + iy
                if cell != last:
                    cells[n_marks] = cell
                    segments[n_marks] = s
                    n_marks += 1
                    last = cell
    return cells[:n_marks], segments[:n_marks]


_TILE = 64  # a tile of a transposition fits in the cache, read and written


@numba.njit(cache=True, parallel=True)
def transposed(array):
    """A C-ordered copy of the 2D ``array.T``, tile by tile.

    NumPy's element-by-element copy of a transposed 39M-node mask took
    0.17 s, its reads or its writes a cache line apart.
    """
    rows, columns = array.shape
    out = np.empty((columns, rows), dtype=array.dtype)
    for tile in numba.prange((columns + _TILE - 1) // _TILE):
        j0 = tile * _TILE
        j1 = min(columns, j0 + _TILE)
        for i0 in range(0, rows, _TILE):
            for i in range(i0, min(rows, i0 + _TILE)):
                for j in range(j0, j1):
                    out[j, i] = array[i, j]
    return out


@numba.njit(cache=True)
def neighbourhood_segments(first, cells, segments, n_segments):
    """For each marked cell, the segments through it and its eight neighbours, each once: the distance's candidates.

    ``cells`` and ``segments`` are the pairs of :func:`mark_segments` sorted
    by cell, ``first[i, j]`` (nxp, nyp) the position of cell ``(i, j)``'s
    first pair (-1 if none), ``n_segments`` the number of segments. A
    segment crosses about two cells, so a 3 x 3 block of cells lists about a
    third of its segments twice (9.9 pairs per node of the §5.3 grid, 6.8
    segments); listed once here, they are measured once per node. Returns
    ``(span, items)``: the candidates of the cell whose first pair is at
    position ``k`` are ``items[span[k, 0]:span[k, 1]]``, in the order of a
    scan of the block (so the nearest of two equally near is the one the
    scan meets first).
    """
    nxp, nyp = first.shape
    n_pairs = cells.size
    span = np.zeros((n_pairs, 2), np.int64)
    items = np.empty(9 * n_pairs, segments.dtype)
    listed_for = np.full(n_segments, -1, np.int64)  # the cell (its first pair) a segment was last listed for
    m = 0
    for k0 in range(n_pairs):
        if k0 > 0 and cells[k0] == cells[k0 - 1]:
            continue
        cx = cells[k0] // nyp
        cy = cells[k0] % nyp
        span[k0, 0] = m
        for i in range(max(cx - 1, 0), min(cx + 2, nxp)):
            for j in range(max(cy - 1, 0), min(cy + 2, nyp)):
                k = first[i, j]
                if k < 0:
                    continue
                key = i * nyp + j
                while k < n_pairs and cells[k] == key:
                    s = segments[k]
                    k += 1
                    if listed_for[s] != k0:
                        listed_for[s] = k0
                        items[m] = s
                        m += 1
        span[k0, 1] = m
    return span, items[:m].copy()


@numba.njit(cache=True, parallel=True)
def nearest_segment_distance(nearest_x, nearest_y, first, span, items, ax, ay, bx, by, x, y, pad):
    """Ground distance from every grid node to the coastline segments drawn near its nearest drawn node.

    The padded raster has shape ``first.shape`` (nxp, nyp); grid node
    ``(ix, iy)`` is padded node ``(ix + pad, iy + pad)``. ``first[i, j]``
    is the position of cell ``(i, j)``'s first pair of :func:`mark_segments`
    (-1 if none), and ``items[span[k, 0]:span[k, 1]]`` the segments through
    the cell whose first pair is ``k`` and its eight neighbours
    (:func:`neighbourhood_segments`). ``nearest_x``, ``nearest_y`` (nxp, nyp)
    give each padded node's nearest marked node (Euclidean distance
    transform; -1 without any). Those segments ``(ax, ay) -> (bx, by)``
    (Mercator metres) are the node's candidates; the one nearest in
    Mercator metres gives the closest point, and the result is the ground
    length of the Mercator segment from the node to it: its Mercator length
    times ``cos(lat)`` at its middle (``cos(lat) = 1 / cosh(y / R)`` on
    Mercator), which is the great-circle distance to a relative 1e-5 at
    100 km below 45 degrees latitude (growing like ``(d / R)**2 tan(lat)**2``).
    A node whose padded raster has no mark gets ``inf``. Returns (nx, ny).
    """
    nx = x.size
    ny = y.size
    out = np.empty((nx, ny))
    for ix in numba.prange(nx):
        px = x[ix]
        for iy in range(ny):
            py = y[iy]
            cx = nearest_x[ix + pad, iy + pad]
            best = np.inf
            qy = py
            low = high = 0
            if cx >= 0:  # a marked node: its first pair's position is >= 0
                k = first[cx, nearest_y[ix + pad, iy + pad]]
                low, high = span[k, 0], span[k, 1]
            for m in range(low, high):
                s = items[m]
                ex = bx[s] - ax[s]
                ey = by[s] - ay[s]
                length2 = ex * ex + ey * ey
                t = 0.0
                if length2 > 0.0:
                    t = ((px - ax[s]) * ex + (py - ay[s]) * ey) / length2
                    t = min(max(t, 0.0), 1.0)
                cxm = ax[s] + t * ex
                cym = ay[s] + t * ey
                d2 = (cxm - px) ** 2 + (cym - py) ** 2
                if d2 < best:
                    best = d2
                    qy = cym
            # ground length of the Mercator segment node -> point: times cos(lat) = 1 / cosh(y / R) at its middle
            out[ix, iy] = np.sqrt(best) / np.cosh(0.5 * (py + qy) / EARTH_RADIUS)
    return out


_COLUMN_BLOCK = 256  # columns swept together in the first pass: contiguous rows, one block per thread


@numba.njit(cache=True, parallel=True)
def nearest_feature(feature):
    """Index of the nearest ``True`` node of ``feature`` (nx, ny) to every node, in grid steps (exact EDT).

    Felzenszwalb & Huttenlocher's separable transform: the nearest feature
    along axis 0 by a forward and a backward sweep (rows in order, so every
    read is contiguous), then, along each row, the lower envelope of the
    parabolas ``(j - k)**2 + (i - nearest_i[i, k])**2``. Linear time, as
    scipy's ``distance_transform_edt(~feature, return_indices=True)``
    (ties may go to another node of the same distance), in a sixth of its
    time on the guide's §5.3 grid (0.4 s for 39M nodes). Returns ``(nearest_x,
    nearest_y)``, int32 (nx, ny); -1 everywhere without a feature node.
    """
    nx, ny = feature.shape
    near_i = np.empty((nx, ny), dtype=np.int32)
    for block in numba.prange((ny + _COLUMN_BLOCK - 1) // _COLUMN_BLOCK):
        low = block * _COLUMN_BLOCK
        high = min(low + _COLUMN_BLOCK, ny)
        for j in range(low, high):
            near_i[0, j] = 0 if feature[0, j] else -1
        for i in range(1, nx):
            for j in range(low, high):
                near_i[i, j] = i if feature[i, j] else near_i[i - 1, j]
        for i in range(nx - 2, -1, -1):
            for j in range(low, high):
                below = near_i[i + 1, j]
                here = near_i[i, j]
                if below >= 0 and (here < 0 or below - i < i - here):
                    near_i[i, j] = below
    nearest_x = np.empty((nx, ny), dtype=np.int32)
    nearest_y = np.empty((nx, ny), dtype=np.int32)
    for i in numba.prange(nx):
        apex = np.empty(ny, dtype=np.int64)  # the parabolas of the lower envelope, left to right...
        start = np.empty(ny + 1)  # ...and where each begins to be the lowest
        count = 0
        for k in range(ny):
            if near_i[i, k] < 0:
                continue
            height = float(k * k + (i - near_i[i, k]) ** 2)
            while count > 0:
                last = apex[count - 1]
                crossing = (height - float(last * last + (i - near_i[i, last]) ** 2)) / (2.0 * (k - last))
                if crossing > start[count - 1]:
                    break
                count -= 1
            start[count] = -np.inf if count == 0 else crossing
            apex[count] = k
            count += 1
        start[count] = np.inf
        if count == 0:  # no feature anywhere
            nearest_x[i, :] = -1
            nearest_y[i, :] = -1
            continue
        segment = 0
        for j in range(ny):
            while start[segment + 1] < j:
                segment += 1
            k = apex[segment]
            nearest_x[i, j] = near_i[i, k]
            nearest_y[i, j] = k
    return nearest_x, nearest_y


@numba.njit(cache=True, parallel=True)
def nearest_node_distance(nearest_x, nearest_y, x, y):
    """Ground distance (metres) from node ``(ix, iy)`` to node ``(nearest_x, nearest_y)[ix, iy]``.

    ``x`` (nx,), ``y`` (ny,): Mercator node coordinates. Measured as in
    :func:`nearest_segment_distance`: Mercator length times ``cos(lat)`` at
    the middle.
    """
    nx = x.size
    ny = y.size
    # cosh((y_i + y_j) / 2R) = cosh(y_i / 2R) cosh(y_j / 2R) + sinh(y_i / 2R) sinh(y_j / 2R): no cosh per node
    half = 0.5 * y / EARTH_RADIUS
    row_cosh = np.cosh(half)
    row_sinh = np.sinh(half)
    out = np.empty((nx, ny))
    for ix in numba.prange(nx):
        for iy in range(ny):
            jx = nearest_x[ix, iy]
            jy = nearest_y[ix, iy]
            dx = x[jx] - x[ix]
            dy = y[jy] - y[iy]
            middle = row_cosh[iy] * row_cosh[jy] + row_sinh[iy] * row_sinh[jy]
            out[ix, iy] = np.sqrt(dx * dx + dy * dy) / middle
    return out


@numba.njit(cache=True, parallel=True)
def gradient_norm(values, water, signed, east_step, north):
    """``|grad f|`` per ground metre by central differences (one-sided on the border).

    ``f`` is ``values``, or, when ``signed``, ``values`` negated where
    ``water`` (a signed distance). ``east_step`` (ny,) is each row's ground
    spacing; ``north`` (ny,) the rows' ground northings. Returns (nx, ny).
    """
    nx, ny = values.shape
    out = np.empty((nx, ny))
    for ix in numba.prange(nx):
        west = max(ix - 1, 0)
        east = min(ix + 1, nx - 1)
        for iy in range(ny):
            south = max(iy - 1, 0)
            north_i = min(iy + 1, ny - 1)
            fw = values[west, iy]
            fe = values[east, iy]
            fs = values[ix, south]
            fn = values[ix, north_i]
            if signed:
                if water[west, iy]:
                    fw = -fw
                if water[east, iy]:
                    fe = -fe
                if water[ix, south]:
                    fs = -fs
                if water[ix, north_i]:
                    fn = -fn
            gx = (fe - fw) / ((east - west) * east_step[iy])
            gy = (fn - fs) / (north[north_i] - north[south])
            out[ix, iy] = np.sqrt(gx * gx + gy * gy)
    return out


_BOX_PARTS = 64
"""Column blocks (axis 0) or row blocks (axis 1) of a box pass, one per task of a ``prange``: every sum runs
along its own column or row, so the result is the same bits whatever the threads."""


@numba.njit(cache=True)
def _box_columns(src, dst, radius, weight, start, first, stop):
    """:func:`box_pass_axis0` on the columns ``first:stop``.

    A kernel of its own: written inside the ``prange``, numba compiled the
    loop 2.5 times slower.
    """
    nx = src.shape[0]
    acc = np.zeros(stop - first)
    norm = np.empty(stop - first)
    for iy in range(first, stop):
        norm[iy - first] = 1.0 / (2 * radius[iy] + 1 + 2.0 * weight[iy])
        for k in range(-radius[iy], radius[iy] + 1):
            acc[iy - first] += src[start + k, iy]
    for i in range(start):
        for iy in range(first, stop):  # by element: a row assignment compiles numba's shape checks (see .arrays)
            dst[i, iy] = src[i, iy]
            dst[nx - 1 - i, iy] = src[nx - 1 - i, iy]
    for i in range(start, nx - start):
        for iy in range(first, stop):
            r = radius[iy]
            dst[i, iy] = (acc[iy - first] + weight[iy] * (src[i - r - 1, iy] + src[i + r + 1, iy])) * norm[iy - first]
            acc[iy - first] += src[i + r + 1, iy] - src[i - r, iy]


@numba.njit(cache=True, parallel=True)
def box_pass_axis0(src, dst, radius, weight, start):
    """One extended-box pass along axis 0, with radius ``radius[iy]`` and end weight ``weight[iy]`` per column.

    ``dst[i, iy] = (sum_{|k| <= r} src[i + k, iy] + a (src[i - r - 1, iy] + src[i + r + 1, iy])) / (2 r + 1 + 2 a)``
    for ``start <= i < nx - start`` (``start > max(radius) + 1``); other
    rows are copied. Running sums, so the cost does not depend on ``r``.
    """
    ny = src.shape[1]
    parts = min(_BOX_PARTS, ny)
    for part in numba.prange(parts):
        first, stop = chunk_range(part, ny, parts)
        _box_columns(src, dst, radius, weight, start, first, stop)


@numba.njit(cache=True)
def _box_rows(src, dst, radius, weight, start, first, stop):
    """:func:`box_pass_axis1` on the rows ``first:stop`` (a kernel of its own, as :func:`_box_columns`)."""
    ny = src.shape[1]
    prefix = np.empty(ny + 1)
    for i in range(first, stop):
        prefix[0] = 0.0
        for j in range(ny):
            prefix[j + 1] = prefix[j] + src[i, j]
        for j in range(start):
            dst[i, j] = src[i, j]
            dst[i, ny - 1 - j] = src[i, ny - 1 - j]
        for j in range(start, ny - start):
            r = radius[j]
            a = weight[j]
            total = prefix[j + r + 1] - prefix[j - r] + a * (src[i, j - r - 1] + src[i, j + r + 1])
            dst[i, j] = total / (2 * r + 1 + 2.0 * a)


@numba.njit(cache=True, parallel=True)
def box_pass_axis1(src, dst, radius, weight, start):
    """One extended-box pass along axis 1, with radius ``radius[j]`` and end weight ``weight[j]`` per output column.

    Same kernel as :func:`box_pass_axis0` along the contiguous axis, from
    prefix sums so that the radius may change from one output to the next.
    """
    nx = src.shape[0]
    parts = min(_BOX_PARTS, nx)
    for part in numba.prange(parts):
        first, stop = chunk_range(part, nx, parts)
        _box_rows(src, dst, radius, weight, start, first, stop)


@numba.njit(cache=True)
def land_gap(water, axis, no_land):
    """Grid steps between the land nodes before and after each node of ``water`` (nx, ny) bool along ``axis``.

    A land node is its own land on both sides (0); a side with no land counts
    as the index ``-no_land`` before or ``no_land`` after. Rows in memory
    order, down and back up: NumPy's ``maximum.accumulate`` along axis 0 of
    a 5483 x 7172 grid took 0.35 s, and the four accumulations of the two
    calls, with their ``where`` and ``flip``, 2 s of the US East Coast example.
    """
    nx, ny = water.shape
    gap = np.empty((nx, ny), dtype=np.int32)
    if axis == 0:
        last = np.full(ny, -no_land, dtype=np.int32)
        for i in range(nx):
            for j in range(ny):
                if not water[i, j]:
                    last[j] = i
                gap[i, j] = last[j]
        for j in range(ny):
            last[j] = no_land
        for i in range(nx - 1, -1, -1):
            for j in range(ny):
                if not water[i, j]:
                    last[j] = i
                gap[i, j] = last[j] - gap[i, j]
    else:
        for i in range(nx):
            before = -no_land
            for j in range(ny):
                if not water[i, j]:
                    before = j
                gap[i, j] = before
            after = no_land
            for j in range(ny - 1, -1, -1):
                if not water[i, j]:
                    after = j
                gap[i, j] = after - gap[i, j]
    return gap


@numba.njit(cache=True, parallel=True)
def with_company(nodes, reach, company):
    """The ``True`` nodes of ``nodes`` (nx, ny) bool with ``company`` other ``True`` nodes or more within ``reach``.

    The window is the ``(2 reach + 1)**2`` nodes around each (Chebyshev
    distance ``reach``), cut at the grid's edges. Only ``True`` nodes are
    counted around, and each stops at ``company``: a summed-area table of
    the whole grid took 0.5-0.6 s on a 5483 x 7172 grid where the medial
    axis holds 2 % of the nodes.
    """
    nx, ny = nodes.shape
    kept = np.zeros((nx, ny), dtype=np.bool_)
    for i in numba.prange(nx):
        first_row, stop_row = max(i - reach, 0), min(i + reach + 1, nx)
        for j in range(ny):
            if not nodes[i, j]:
                continue
            first_column, stop_column = max(j - reach, 0), min(j + reach + 1, ny)
            found = -1  # the node itself is counted in its window
            for k in range(first_row, stop_row):
                for m in range(first_column, stop_column):
                    if nodes[k, m]:
                        found += 1
                if found >= company:
                    kept[i, j] = True
                    break
    return kept


@numba.njit(cache=True)
def _percentile_sorted(values, q):
    """``np.percentile(values, q)`` (linear method) of an ascending array."""
    position = q / 100.0 * (values.size - 1)
    low = int(np.floor(position))
    high = min(low + 1, values.size - 1)
    return values[low] + (position - low) * (values[high] - values[low])


_CENSUS_PARTS = 64


@numba.njit(cache=True, parallel=True)
def value_census(values):
    """The numbers of NaN, of infinite and of non-positive (``<= 0``) values of the flat array ``values``.

    One pass where NumPy's ``isnan(...).any()`` and its kin made a mask
    each: 0.09 s per check of a 39M-node grid. Counts are integers, so the
    parts' sums are exact in any order.
    """
    n = values.size
    parts = max(1, min(_CENSUS_PARTS, n))
    counts = np.zeros((parts, 3), np.int64)
    for part in numba.prange(parts):
        first, stop = chunk_range(part, n, parts)
        nans = infinite = non_positive = 0
        for i in range(first, stop):
            value = values[i]
            if value != value:
                nans += 1
            else:
                if value <= 0.0:
                    non_positive += 1
                if value - value != 0.0:  # inf - inf is NaN; finite values give 0
                    infinite += 1
        counts[part, 0] = nans
        counts[part, 1] = infinite
        counts[part, 2] = non_positive
    return counts[:, 0].sum(), counts[:, 1].sum(), counts[:, 2].sum()


@numba.njit(cache=True, parallel=True)
def thalweg_nodes(depth, ground_step, min_bank_slope, found):
    """Mark in ``found`` the inner nodes deeper than one neighbour and as deep as the other along a line, banks steep.

    The four lines through a node: along axis 0, axis 1 and the two
    diagonals; the neighbours' spacing is the row's ``ground_step`` (times
    sqrt 2 on the diagonals). A node is marked when, along one of them,
    ``depth > before``, ``depth >= after`` and ``2 depth - before - after >=
    2 min_bank_slope spacing``; see
    :func:`terramesh.coastal.sizes.channels.find_channels`.
    """
    nx, ny = depth.shape
    diagonal = np.sqrt(2.0)
    for ix in numba.prange(1, nx - 1):
        for iy in range(1, ny - 1):
            centre = depth[ix, iy]
            straight = 2.0 * min_bank_slope * ground_step[iy]
            slanted = 2.0 * min_bank_slope * (diagonal * ground_step[iy])
            if (
                _bottom(centre, depth[ix - 1, iy], depth[ix + 1, iy], straight)
                or _bottom(centre, depth[ix, iy - 1], depth[ix, iy + 1], straight)
                or _bottom(centre, depth[ix - 1, iy - 1], depth[ix + 1, iy + 1], slanted)
                or _bottom(centre, depth[ix + 1, iy - 1], depth[ix - 1, iy + 1], slanted)
            ):
                found[ix, iy] = True


@numba.njit(cache=True, inline="always")
def _bottom(centre, before, after, least_drop):
    return centre > before and centre >= after and (2.0 * centre - before - after) >= least_drop


@numba.njit(cache=True)
def channel_circles(px, py, x0, y0, step, ground_step, depth, slope, tan_angle, q, max_cells, out):
    """Lower ``out`` to the ``q``-th percentile of ``slope`` in each channel point's circle.

    Channel point ``k`` is at Mercator ``(px[k], py[k])``; the grid's first
    node is at ``(x0, y0)`` with spacing ``step``. The depth at the point
    is interpolated bilinearly from ``depth``; the circle's radius is
    ``tan_angle * |depth|`` ground metres (at least the nearest node, at
    most ``max_cells`` nodes). Ground distances inside the circle are
    Mercator distances times ``cos(lat)`` at the point. Percentiles are of
    the finite slope sizes in the circle; circles without any are skipped.
    Returns the number of points that changed ``out``.
    """
    nx, ny = depth.shape
    buffer = np.empty((2 * max_cells + 1) ** 2)
    used = 0
    for k in range(px.size):
        fx = (px[k] - x0) / step
        fy = (py[k] - y0) / step
        if not (-0.5 <= fx <= nx - 0.5 and -0.5 <= fy <= ny - 0.5):
            continue
        ix0 = min(max(int(np.floor(fx + 0.5)), 0), nx - 1)
        iy0 = min(max(int(np.floor(fy + 0.5)), 0), ny - 1)
        # bilinear depth, clamped to the grid
        bx = min(max(fx, 0.0), nx - 1.0)
        by = min(max(fy, 0.0), ny - 1.0)
        i = min(int(bx), nx - 2) if nx > 1 else 0
        j = min(int(by), ny - 2) if ny > 1 else 0
        tx = bx - i
        ty = by - j
        i1 = min(i + 1, nx - 1)
        j1 = min(j + 1, ny - 1)
        h = (
            (1 - tx) * (1 - ty) * depth[i, j]
            + tx * (1 - ty) * depth[i1, j]
            + (1 - tx) * ty * depth[i, j1]
            + tx * ty * depth[i1, j1]
        )
        radius = tan_angle * abs(h)
        scale = ground_step[iy0] / step  # ground metres per Mercator metre at the point
        reach = min(int(np.ceil(radius / ground_step[iy0])), max_cells)
        r2 = radius * radius
        n = 0
        for a in range(max(ix0 - reach, 0), min(ix0 + reach + 1, nx)):
            for b in range(max(iy0 - reach, 0), min(iy0 + reach + 1, ny)):
                gx = (x0 + a * step - px[k]) * scale
                gy = (y0 + b * step - py[k]) * scale
                if (gx * gx + gy * gy <= r2 or (a == ix0 and b == iy0)) and np.isfinite(slope[a, b]):
                    buffer[n] = slope[a, b]
                    n += 1
        if n == 0:
            continue
        sort_in_place(buffer, n)
        value = _percentile_sorted(buffer[:n], q)
        changed = False
        for a in range(max(ix0 - reach, 0), min(ix0 + reach + 1, nx)):
            for b in range(max(iy0 - reach, 0), min(iy0 + reach + 1, ny)):
                gx = (x0 + a * step - px[k]) * scale
                gy = (y0 + b * step - py[k]) * scale
                if (gx * gx + gy * gy <= r2 or (a == ix0 and b == iy0)) and value < out[a, b]:
                    out[a, b] = value
                    changed = True
        if changed:
            used += 1
    return used


@numba.njit(cache=True, inline="always")
def cell_and_fraction(coordinate, origin, spacing, nodes):
    """The grid cell below ``coordinate`` along one axis and the fraction across it, clamped to the grid."""
    position = min(max((coordinate - origin) / spacing, 0.0), nodes - 1.0)
    lower = min(int(np.floor(position)), nodes - 2)
    return lower, position - lower


@numba.njit(cache=True, inline="always")
def _bilinear_at(values, origin, spacing, x, y):
    """Bilinear interpolation of node ``values`` (nx, ny) at ``(x, y)``, clamped to the grid."""
    nx, ny = values.shape
    i, fx = cell_and_fraction(x, origin[0], spacing[0], nx)
    j, fy = cell_and_fraction(y, origin[1], spacing[1], ny)
    gx = 1.0 - fx
    gy = 1.0 - fy
    return (
        gx * gy * values[i, j]
        + gx * fy * values[i, j + 1]
        + fx * gy * values[i + 1, j]
        + fx * fy * values[i + 1, j + 1]
    )


@numba.njit(cache=True, parallel=True)
def bilinear(values, origin, spacing, points):
    """Bilinear interpolation of node ``values`` (nx, ny) at ``points`` (n, 2), clamped to the grid."""
    out = np.empty(points.shape[0])
    for k in numba.prange(points.shape[0]):
        out[k] = _bilinear_at(values, origin, spacing, points[k, 0], points[k, 1])
    return out


@numba.njit(cache=True, parallel=True)
def graded_from_box(x, y, latitude, size, values, origin, spacing, box, south, north, grade, offset, radius):
    """Lower ``size`` to a box's size graded outward on the ground, at the points outside the box.

    ``x``, ``y`` Mercator metres (the first box's plane), ``latitude``
    theirs in radians; ``box`` ``(x0, x1, y0, y1)`` the box on that plane,
    ``south``/``north`` its latitudes (radians), ``values``/``origin``/
    ``spacing`` its Mercator size grid (in its own longitudes: ``offset``
    metres east of the first box's). A point outside takes the box's
    ground size at its nearest point plus ``grade`` times the great-circle
    distance to it (haversine), back on the Mercator plane; ``size`` keeps
    the smaller. In place: one pass, where NumPy made a dozen temporaries.
    """
    for k in numba.prange(x.shape[0]):
        near_x = min(max(x[k], box[0]), box[1])
        near_y = min(max(y[k], box[2]), box[3])
        if near_x == x[k] and near_y == y[k]:
            continue
        here = latitude[k]
        there = min(max(here, south), north)  # the nearest point's: latitude grows with y
        east = 0.5 * (x[k] - near_x) / radius
        half = math.sin(0.5 * (here - there)) ** 2 + math.cos(here) * math.cos(there) * math.sin(east) ** 2
        distance = 2.0 * radius * math.asin(math.sqrt(min(half, 1.0)))
        own = _bilinear_at(values, origin, spacing, near_x - offset, near_y)
        size[k] = min(size[k], (own * math.cos(there) + grade * distance) / math.cos(here))


@numba.njit(cache=True, inline="always")
def _along(starts, ends, k, axis, fraction):
    """Coordinate ``axis`` of the point ``fraction`` of the way along segment ``k``."""
    return starts[k, axis] + fraction * (ends[k, axis] - starts[k, axis])


@numba.njit(cache=True, parallel=True)
def largest_along_2d(values, origin, spacing, starts, ends, samples):
    """Largest bilinear value of node ``values`` (nx, ny) over ``samples[k]`` points evenly along segment ``k``.

    The points are the segment's ends and ``samples[k] - 2`` between them,
    as NumPy's ``start + (s / (samples - 1)) * (end - start)`` places them
    (``samples >= 2``); none is stored (an FWI mesh's edges sampled every
    half grid step made 6.7 million points for 157 thousand edges).
    """
    out = np.empty(starts.shape[0])
    for k in numba.prange(starts.shape[0]):
        largest = -np.inf
        for s in range(samples[k]):
            fraction = s / (samples[k] - 1)
            x = _along(starts, ends, k, 0, fraction)
            y = _along(starts, ends, k, 1, fraction)
            largest = max(largest, _bilinear_at(values, origin, spacing, x, y))
        out[k] = largest
    return out


# plain compiled loops, not numba.vectorize: a vectorized function is compiled again at every
# import (0.2-0.5 s of each process's `import terramesh`), its cache notwithstanding


@numba.njit(cache=True, parallel=True)
def wave_speed(depth, eta, gravity):
    """``eta sqrt(g / h) + sqrt(g h)`` with ``h = max(depth, eta)`` at each of ``depth`` (1-D), in one pass.

    NumPy took 2.3 s for 39M nodes.
    """
    out = np.empty_like(depth)
    for i in numba.prange(depth.shape[0]):
        h = max(depth[i], eta)
        out[i] = eta * math.sqrt(gravity / h) + math.sqrt(gravity * h)
    return out


@numba.njit(cache=True, parallel=True)
def wavelength_size(depth, period, gravity, elements_per_wavelength):
    """``period sqrt(g depth) / elements_per_wavelength`` where ``depth > 0``, else inf, at each of ``depth`` (1-D)."""
    out = np.empty_like(depth)
    for i in numba.prange(depth.shape[0]):
        out[i] = period * math.sqrt(gravity * depth[i]) / elements_per_wavelength if depth[i] > 0.0 else np.inf
    return out


@numba.njit(cache=True, parallel=True)
def bilinear_lonlat(values, origin, spacing, last_lon, lon, lat):
    """Bilinear interpolation of node ``values`` (nx, ny) at ``(lon[k], lat[k])``, clamped to the grid.

    A longitude off the grid that a whole number of turns (360) puts on it
    is moved there; NaN where a coordinate is not finite. ``last_lon`` is
    the grid's last longitude. One pass: the NumPy version made twenty
    temporaries the size of the input and took 13 s for a 5483 x 7172 size
    grid (the guide's §5.3).
    """
    nx, ny = values.shape
    out = np.empty(lon.shape[0])
    for k in numba.prange(lon.shape[0]):
        x = lon[k]
        y = lat[k]
        if not (np.isfinite(x) and np.isfinite(y)):
            out[k] = np.nan
            continue
        i, after, tx = _lon_cell(x, origin[0], last_lon, spacing[0], nx)
        j, ty = cell_and_fraction(y, origin[1], spacing[1], ny)
        out[k] = _bilinear(values, i, after, j, tx, ty)
    return out


@numba.njit(cache=True, parallel=True)
def bilinear_lonlat_grid(values, origin, spacing, last_lon, lon, lat):
    """:func:`bilinear_lonlat` at every ``(lon[a], lat[b])``, shape (len(lon), len(lat)), the same to the bit.

    Without the two coordinate arrays of the output's size (630 MB and 1 s
    of a 5483 x 7172 size grid's sampling).
    """
    nx, ny = values.shape
    out = np.empty((lon.shape[0], lat.shape[0]))
    rows = np.empty(lat.shape[0], dtype=np.int64)
    fractions = np.empty(lat.shape[0])
    for b in range(lat.shape[0]):
        rows[b], fractions[b] = (0, 0.0)  # a NaN row: its values are NaN below
        if np.isfinite(lat[b]):
            rows[b], fractions[b] = cell_and_fraction(lat[b], origin[1], spacing[1], ny)
    for a in numba.prange(lon.shape[0]):
        x = lon[a]
        if not np.isfinite(x):
            out[a, :] = np.nan
            continue
        i, after, tx = _lon_cell(x, origin[0], last_lon, spacing[0], nx)
        for b in range(lat.shape[0]):
            out[a, b] = _bilinear(values, i, after, rows[b], tx, fractions[b]) if np.isfinite(lat[b]) else np.nan
    return out


@numba.njit(cache=True, inline="always")
def _on_the_grid(x, first_lon, last_lon):
    """Longitude ``x`` moved by whole turns onto the grid's span where that puts it there."""
    if x < first_lon or x > last_lon:
        wrapped = first_lon + (x - first_lon) % 360.0
        if wrapped <= last_lon:
            return wrapped
    return x


@numba.njit(cache=True, inline="always")
def _lon_cell(x, first_lon, last_lon, dx, nx):
    """``(column, next column, fraction)`` of longitude ``x`` on a grid of ``nx`` columns from ``first_lon``.

    Moved by whole turns onto the grid where that puts it there; on a grid
    all the way round (its last column within 1.5 steps of the first's next
    turn), a longitude between the two is interpolated between the last
    column and the first, where it took the last column's value.
    """
    x = _on_the_grid(x, first_lon, last_lon)
    gap = first_lon + 360.0 - last_lon
    if (x > last_lon or x < first_lon) and 0.0 < gap <= 1.5 * dx:
        turned = first_lon + (x - first_lon) % 360.0
        if turned > last_lon:
            return nx - 1, 0, (turned - last_lon) / gap
    i, fraction = cell_and_fraction(x, first_lon, dx, nx)
    return i, i + 1, fraction


@numba.njit(cache=True, inline="always")
def _bilinear(values, i, after, j, tx, ty):
    """Bilinear in the cell of columns ``i`` and ``after`` (the next, or the first across a global grid's seam)."""
    return (1.0 - ty) * ((1.0 - tx) * values[i, j] + tx * values[after, j]) + ty * (
        (1.0 - tx) * values[i, j + 1] + tx * values[after, j + 1]
    )


@numba.njit(cache=True, inline="always")
def _trilinear_at(values, origin, spacing, x, y, z):
    """Trilinear interpolation of node ``values`` (nx, ny, nz) at ``(x, y, z)``, clamped to the grid."""
    nx, ny, nz = values.shape
    i, fx = cell_and_fraction(x, origin[0], spacing[0], nx)
    j, fy = cell_and_fraction(y, origin[1], spacing[1], ny)
    m, fz = cell_and_fraction(z, origin[2], spacing[2], nz)
    total = 0.0
    for a in range(2):
        wx = fx if a else 1.0 - fx
        for b in range(2):
            wy = wx * (fy if b else 1.0 - fy)
            for c in range(2):
                total += wy * (fz if c else 1.0 - fz) * values[i + a, j + b, m + c]
    return total


@numba.njit(cache=True)
def trilinear(values, origin, spacing, points):
    """Trilinear interpolation of node ``values`` (nx, ny, nz) at ``points`` (n, 3), clamped to the grid."""
    out = np.empty(points.shape[0])
    for k in range(points.shape[0]):
        out[k] = _trilinear_at(values, origin, spacing, points[k, 0], points[k, 1], points[k, 2])
    return out


@numba.njit(cache=True, parallel=True)
def largest_along_3d(values, origin, spacing, starts, ends, samples):
    """:func:`largest_along_2d` of node ``values`` (nx, ny, nz), trilinear."""
    out = np.empty(starts.shape[0])
    for k in numba.prange(starts.shape[0]):
        largest = -np.inf
        for s in range(samples[k]):
            fraction = s / (samples[k] - 1)
            x = _along(starts, ends, k, 0, fraction)
            y = _along(starts, ends, k, 1, fraction)
            z = _along(starts, ends, k, 2, fraction)
            largest = max(largest, _trilinear_at(values, origin, spacing, x, y, z))
        out[k] = largest
    return out


@numba.njit(cache=True, inline="always")
def _nearest_node(axis, p):
    """Index of the node of the sorted ``axis`` nearest ``p`` (the lower one of two as near)."""
    i = np.searchsorted(axis, p)
    if i == 0:
        return 0
    if i == axis.shape[0]:
        return i - 1
    return i - 1 if p - axis[i - 1] <= axis[i] - p else i


@numba.njit(cache=True)
def lower_near_points(values, x, y, z, points, size, radius):
    """Lower ``values`` (nx, ny, nz) to ``size`` at the nodes within ``radius`` of any of ``points`` (k, 3); in place.

    The node nearest each point counts however small the radius. A 2-D grid
    comes as (nx, 1, nz) with ``y`` one node at 0 and the points' y 0.
    """
    axes = (x, y, z)
    steps = np.zeros(3)
    for a in range(3):
        if axes[a].shape[0] > 1:
            steps[a] = axes[a][1] - axes[a][0]
    r2 = radius * radius
    for k in range(points.shape[0]):
        px, py, pz = points[k, 0], points[k, 1], points[k, 2]
        i0 = np.searchsorted(x, px - radius - steps[0])
        i1 = np.searchsorted(x, px + radius + steps[0])
        j0 = np.searchsorted(y, py - radius - steps[1])
        j1 = np.searchsorted(y, py + radius + steps[1])
        l0 = np.searchsorted(z, pz - radius - steps[2])
        l1 = np.searchsorted(z, pz + radius + steps[2])
        for i in range(i0, i1):
            dx2 = (x[i] - px) ** 2
            for j in range(j0, j1):
                dxy2 = dx2 + (y[j] - py) ** 2
                for m in range(l0, l1):
                    if dxy2 + (z[m] - pz) ** 2 <= r2 and values[i, j, m] > size:
                        values[i, j, m] = size
        i, j, m = _nearest_node(x, px), _nearest_node(y, py), _nearest_node(z, pz)
        if values[i, j, m] > size:
            values[i, j, m] = size
