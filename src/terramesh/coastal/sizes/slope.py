"""Slope (topographic length scale) size function, guide §3.3 eq. 7-8, with its band-pass filter.

The bathymetry is filtered before its gradient is taken. The guide uses
``filt2``, a Gaussian filter whose standard deviation is ``sigma = lambda /
(2 pi)`` for a filter length ``lambda`` (so a wave of length ``lambda``
keeps ``exp(-1/2)``, about 61 %, of its amplitude), a high-pass being the
data minus its low-pass and a band-pass a high-pass followed by a low-pass.
Here the same Gaussian (same ``sigma``, in ground metres) is applied as
four cascaded *extended box* filters along each axis (Gwosdek et al. 2011):
each pass is a running mean whose two end weights are fractional, so that
the four passes' variances add up to ``sigma**2`` exactly, at every row's
own ground spacing. The cost is a few operations per node and pass,
whatever the filter length, where a direct Gaussian convolution of a
46.7 km filter on a 100 m grid would cost hundreds per node. The response
is within a few per cent of the Gaussian's at the wavelengths that matter
(see the tests). The borders are padded by point reflection about the
border value (``numpy.pad(..., "reflect", reflect_type="odd")``), so a
plane is left unchanged, borders included.

References
----------
Gwosdek, P., Grewenig, S., Bruhn, A., Weickert, J. (2011). Theoretical
foundations of Gaussian convolution by extended box filtering. Scale Space
and Variational Methods in Computer Vision, LNCS 6667, 447-458.
https://doi.org/10.1007/978-3-642-24785-9_38
"""

import numpy as np

from ..._kernels.raster import box_pass_axis0, box_pass_axis1
from ...errors import SizingError, warn_user
from ._common import check_grid, field, ground_gradient_norm, positive
from .wavelength import GRAVITY, M2_PERIOD, m2_wavelength

__all__ = [
    "SLOPE_CUTOFF_DEPTH",
    "LEAST_OVERLAND_DEPTH",
    "auto_filter_length",
    "gaussian_lowpass",
    "filter_bathymetry",
    "slope_size",
]

SLOPE_CUTOFF_DEPTH = 100.0
"""Depth, metres, shallower than which the slope function is off (§3.3) and at which eq. 8 is evaluated."""

LEAST_OVERLAND_DEPTH = 1.0
"""Metres: the least ``|h|`` of the slope function on land and at the shore (``min_depth=None``)."""

_PASSES = 4


def auto_filter_length(elements_per_slope, *, depth=SLOPE_CUTOFF_DEPTH, period=M2_PERIOD, gravity=GRAVITY):
    """The automatic low-pass filter length of guide eq. 8: ``fl_low = lambda_M2(h = 100 m) / alpha_slp``.

    Parameters
    ----------
    elements_per_slope : float
        ``alpha_slp``.
    depth : float, optional
        Depth at which the M2 wavelength is taken, metres (100 m in the guide).
    period, gravity : float, optional
        M2 period (s) and ``g`` (m/s^2).

    Returns
    -------
    float
        Ground metres (46.7 km for ``alpha_slp = 30``, as the guide says).

    Examples
    --------
    >>> round(auto_filter_length(30) / 1e3, 1)
    46.7
    """
    elements_per_slope = positive("elements_per_slope", elements_per_slope)
    depth = positive("depth", depth)
    return float(m2_wavelength(depth, period=period, gravity=gravity)) / elements_per_slope


def box_passes(sigma_cells):
    """Radius and end weight of each of four extended boxes whose variances sum to ``sigma_cells**2``."""
    variance = sigma_cells**2 / _PASSES
    radius = np.floor(0.5 * (np.sqrt(1.0 + 12.0 * variance) - 1.0)).astype(np.int64)
    # guard the floor against rounding: the plain box of this radius must not exceed the variance
    radius -= (radius * (radius + 1) / 3.0 > variance).astype(np.int64)
    weight = (2 * radius + 1) * (variance - radius * (radius + 1) / 3.0) / (2.0 * ((radius + 1) ** 2 - variance))
    return radius, np.clip(weight, 0.0, 1.0)


def gaussian_lowpass(grid, values, length):
    """Gaussian low-pass filter of a field on the grid with ``sigma = length / (2 pi)`` ground metres.

    Four extended-box passes per axis (module docstring); each row uses its
    own ground spacing, so the filter is the same in metres at every
    latitude. A plane (linear in the grid indices) is returned unchanged.

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    values : array_like, shape (nx, ny)
        The field (finite).
    length : float
        Filter length ``lambda``, ground metres; 0 returns a copy.

    Returns
    -------
    ndarray, shape (nx, ny)

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 1, 0, 1), 2e3)
    >>> ix, iy = np.meshgrid(np.arange(grid.shape[0]), np.arange(grid.shape[1]), indexing="ij")
    >>> plane = 3.0 * ix - 2.0 * iy + 7.0
    >>> bool(np.allclose(gaussian_lowpass(grid, plane, 20e3), plane, rtol=0, atol=1e-9))
    True
    """
    grid = check_grid(grid)
    length = positive("filter length", length, allow_zero=True)
    values = field("values", values, grid.shape)
    if length == 0:
        return values.copy()
    sigma_cells = length / (2.0 * np.pi) / grid.ground_step
    radius, weight = box_passes(sigma_cells)
    start = int(radius.max()) + 1
    pad = _PASSES * start + 1
    work = np.pad(values, pad, mode="reflect", reflect_type="odd")
    radius_p = np.ascontiguousarray(np.pad(radius, pad, mode="edge"))
    weight_p = np.ascontiguousarray(np.pad(weight, pad, mode="edge"))
    other = np.empty_like(work)
    for _ in range(_PASSES):
        box_pass_axis0(work, other, radius_p, weight_p, start)
        work, other = other, work
    for _ in range(_PASSES):
        box_pass_axis1(work, other, radius_p, weight_p, start)
        work, other = other, work
    del other  # before the copy out: three grids at the peak, not four
    return np.ascontiguousarray(work[pad:-pad, pad:-pad])


def _filter_rows(filter_lengths):
    rows = np.asarray(filter_lengths, dtype=np.float64)
    if rows.ndim == 1:
        rows = rows[None, :]
    if rows.ndim != 2 or rows.shape[1] != 2 or rows.shape[0] == 0:
        raise SizingError(f"filter_lengths must be pairs (fl_low, fl_high) in metres, got {filter_lengths!r}")
    if not np.all(np.isfinite(rows)) or np.any(rows < 0):
        raise SizingError(f"filter lengths must be non-negative and finite metres, got {rows.tolist()}")
    return rows


def filter_bathymetry(grid, depth, filter_lengths):
    """Band-pass filter the bathymetry as the slope function does (§3.3).

    Each row ``(fl_low, fl_high)`` of ``filter_lengths`` gives

    * ``fl_high == 0``: a low-pass, keeping wavelengths longer than ``fl_low``;
    * both positive: a band-pass keeping wavelengths between the two (a
      high-pass at the larger length, then a low-pass at the smaller, as
      ``filt2`` does);
    * ``fl_low == 0``: a high-pass at ``fl_high`` (the guide advises
      against it; a :class:`TerrameshWarning` says so);
    * both zero: the bathymetry unfiltered.

    Several rows are summed, as OceanMesh2D's code does (the guide does
    not say how ``n`` filters combine).

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    depth : array_like, shape (nx, ny)
        Metres (finite).
    filter_lengths : array_like, shape (2,) or (n, 2)
        Ground metres.

    Returns
    -------
    ndarray, shape (nx, ny)
        Metres.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 1, 0, 1), 2e3)
    >>> flat = np.full(grid.shape, 50.0)
    >>> bool(np.allclose(filter_bathymetry(grid, flat, (20e3, 0.0)), 50.0))
    True
    """
    grid = check_grid(grid)
    depth = field("depth", depth, grid.shape)
    rows = _filter_rows(filter_lengths)
    # a Gaussian of sigma = length / 2 pi a fraction of the grid's step changes next to nothing (filt2 warns too)
    step = float(grid.ground_step.max())
    too_short = rows[(rows > 0) & (rows <= 2 * step)]
    if len(too_short):
        warn_user(
            f"filter length(s) {sorted(set(too_short.tolist()))} m are no longer than twice the grid's step"
            f" ({step:.0f} m): they filter next to nothing (filter lengths are ground metres)",
        )
    total = None
    for low, high in rows:
        if low > 0 and high > 0:
            short, long = min(low, high), max(low, high)
            part = gaussian_lowpass(grid, depth - gaussian_lowpass(grid, depth, long), short)
        elif low > 0:
            part = gaussian_lowpass(grid, depth, low)
        elif high > 0:
            warn_user(
                "a high-pass filter of the bathymetry in the slope function is not recommended (guide §3.3)",
            )
            part = depth - gaussian_lowpass(grid, depth, high)
        else:
            part = depth
        if total is None:
            total = part.copy() if part is depth else part  # a new array, never the caller's
        else:
            total += part
    return total


def slope_size(
    grid,
    depth,
    *,
    elements_per_slope,
    filter_lengths=None,
    min_depth=SLOPE_CUTOFF_DEPTH,
    max_land_elevation=50.0,
    period=M2_PERIOD,
    gravity=GRAVITY,
):
    """Slope size function, guide eq. 7: ``f_slp = (2 pi / alpha_slp) h / |grad h*|``.

    ``h`` is the depth and ``h*`` the filtered depth (:func:`filter_bathymetry`),
    whose gradient is taken per ground metre (central differences). With
    ``filter_lengths=None`` the low-pass length is automatic, eq. 8:
    ``fl_low = lambda_M2(100 m) / alpha_slp``, ``fl_high = 0``.

    Where the function is off it returns ``inf`` (no constraint): in depths
    shallower than ``min_depth`` (100 m, §3.3: the guide's "f_slp = 0"
    there means switched off) and where the filtered bathymetry is flat
    (``|grad h*|`` below its rounding level, ``1e-12 (max|h*| + 1 m)`` per
    the grid's smallest ground step).
    Before filtering, land higher than ``max_land_elevation`` is lowered to
    it, so that mountains do not bleed into the sea through the filter
    (OceanMesh2D's code uses 50 m; the guide is silent).

    Parameters
    ----------
    grid : GeoGrid
        The grid.
    depth : array_like, shape (nx, ny)
        Metres, positive down (land negative), finite.
    elements_per_slope : float
        ``alpha_slp`` (the guide's ``slp``; about 20-30).
    filter_lengths : array_like, shape (2,) or (n, 2), optional
        ``[fl_low, fl_high]`` pairs, ground metres; ``(0, 0)`` turns the
        filter off; None is eq. 8.
    min_depth : float or None, optional
        Metres; shallower nodes get ``inf``. 0 keeps eq. 7 in all water;
        None keeps it on land too, with the depth's magnitude ``|h|`` (at
        least :data:`LEAST_OVERLAND_DEPTH`): the input of the channel
        function, whose overland channels are V-shaped valleys ``|h|``
        deep (OceanMesh2D's code takes ``max(1 m, |h|)`` there as well).
    max_land_elevation : float, optional
        Metres above sea level.
    period, gravity : float, optional
        For eq. 8 (s, m/s^2).

    Returns
    -------
    ndarray, shape (nx, ny)
        Ground metres.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((0, 1, 0, 1), 5e3)
    >>> north = 6378137.0 * np.radians(grid.lat)
    >>> depth = np.broadcast_to(200.0 + 0.01 * (north - north[0]), grid.shape)
    >>> f = slope_size(grid, depth, elements_per_slope=30)
    >>> bool(np.isclose(f[5, 10], 2 * np.pi / 30 * depth[5, 10] / 0.01, rtol=1e-6))
    True
    """
    grid = check_grid(grid)
    elements_per_slope = positive("elements_per_slope", elements_per_slope)
    if min_depth is not None:
        min_depth = positive("min_depth", min_depth, allow_zero=True)
    max_land_elevation = positive("max_land_elevation", max_land_elevation, allow_zero=True, allow_inf=True)
    depth = field("depth", depth, grid.shape)
    if filter_lengths is None:
        filter_lengths = (auto_filter_length(elements_per_slope, period=period, gravity=gravity), 0.0)
    filtered = filter_bathymetry(grid, np.maximum(depth, -max_land_elevation), filter_lengths)
    # gradients at the filter's rounding level (flat sea floor) count as zero
    flat = 1e-12 * (float(np.abs(filtered).max()) + 1.0) / float(grid.ground_step.min())
    gradient = ground_gradient_norm(grid, filtered)
    del filtered
    if min_depth is None:
        on = gradient > flat
        depth = np.abs(depth)
        np.maximum(depth, LEAST_OVERLAND_DEPTH, out=depth)
    else:
        on = (depth >= min_depth) & (depth > 0) & (gradient > flat)
    # in place under the mask: the slope's share of the water is near all of it, and depth[on] / gradient[on]
    # laid out four grids more (the peak of a coastal size function, 2.70 GB at 39M nodes)
    sizes = np.full(grid.shape, np.inf)
    np.multiply(2.0 * np.pi / elements_per_slope, depth, out=sizes, where=on)
    np.divide(sizes, gradient, out=sizes, where=on)
    return sizes
