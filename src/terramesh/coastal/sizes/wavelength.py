"""Wavelength size function (guide §3.2, eq. 5-6): elements per M2 tidal wavelength."""

import numpy as np

from ..._kernels.raster import wavelength_size as _kernel_wavelength_size
from ...errors import SizingError
from ._common import field, positive

__all__ = ["M2_PERIOD", "GRAVITY", "m2_wavelength", "wavelength_size"]

M2_PERIOD = 12.42 * 3600.0
"""Period of the M2 tide, seconds (12.42 hours, §3.2)."""

GRAVITY = 9.81
"""Acceleration due to gravity, m/s^2 (OceanMesh2D's code uses 9.807; the difference is 0.02 %)."""


def m2_wavelength(depth, *, period=M2_PERIOD, gravity=GRAVITY):
    """Shallow-water wavelength ``lambda = T sqrt(g h)`` of a wave of period ``T`` in depth ``h``, metres.

    Parameters
    ----------
    depth : float or array_like
        Depth ``h``, metres, positive down; must be non-negative.
    period : float, optional
        ``T``, seconds (M2 by default).
    gravity : float, optional
        ``g``, m/s^2.

    Returns
    -------
    float or ndarray
        Metres.

    Examples
    --------
    >>> round(float(m2_wavelength(100.0)))
    1400421
    """
    period = positive("period", period)
    gravity = positive("gravity", gravity)
    depth = np.asarray(depth, dtype=np.float64)
    if np.isnan(depth).any() or (depth < 0).any():
        raise SizingError("m2_wavelength needs non-negative, non-NaN depths (metres, positive down)")
    return period * np.sqrt(gravity * depth)


def wavelength_size(depth, *, elements_per_wavelength, period=M2_PERIOD, gravity=GRAVITY):
    """Wavelength size function, guide eq. 5-6: ``f_wl = lambda_M2 / alpha_wl = T_M2 sqrt(g H) / alpha_wl``.

    The total water depth ``H`` is taken as the still-water depth ``h``, as
    the guide does. Where ``h <= 0`` (land, or dry at mean sea level) there
    is no wave and the function does not constrain the size: ``inf``. The
    guide sets no shallow cut-off (OceanMesh2D's code applies it only below
    10 m and uses ``max(h, 1 m)``); bound the result with
    :func:`~terramesh.coastal.sizes.bound_sizes` instead.

    Parameters
    ----------
    depth : array_like
        ``h``, metres, positive down (land negative), e.g. shape (nx, ny).
    elements_per_wavelength : float
        ``alpha_wl``, elements per M2 wavelength (the guide's ``wl``).
    period : float, optional
        ``T_M2``, seconds: 12.42 h.
    gravity : float, optional
        ``g``, m/s^2.

    Returns
    -------
    ndarray
        Ground metres, the shape of ``depth``; ``inf`` where ``h <= 0``.

    Examples
    --------
    >>> f = wavelength_size([100.0, 4000.0, -5.0], elements_per_wavelength=60)
    >>> f.round(1).tolist()
    [23340.3, 147617.3, inf]
    """
    elements_per_wavelength = positive("elements_per_wavelength", elements_per_wavelength)
    period = positive("period", period)
    gravity = positive("gravity", gravity)
    depth = field("depth", depth)
    flat = _kernel_wavelength_size(depth.reshape(-1), period, gravity, elements_per_wavelength)
    return flat.reshape(depth.shape)  # one compiled kernel, any shape
