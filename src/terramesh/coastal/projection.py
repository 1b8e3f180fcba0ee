"""Spherical Mercator: the plane coastal meshes are built in.

Mercator is conformal, so a triangle that is equilateral in Mercator
coordinates is equilateral on the ground (to first order in its size): a
mesh generated there with sizes ``h_ground * scale_factor(lat)`` is
isotropic in metres at every latitude, with no single metres-per-degree
factor for both axes. The sphere has the WGS84 semi-major axis as its
radius (the same as EPSG:3857), so ground lengths are those of that sphere:
within 0.5 % of the ellipsoid's, far below any meshing tolerance.
"""

import numpy as np

from ..errors import GeometryError

__all__ = [
    "EARTH_RADIUS",
    "MAX_LATITUDE",
    "to_mercator",
    "from_mercator",
    "scale_factor",
    "metres_per_degree",
]

EARTH_RADIUS = 6378137.0
"""Radius of the Mercator sphere, metres (WGS84 semi-major axis)."""

MAX_LATITUDE = 85.0
"""Largest |latitude| accepted, degrees: the scale factor grows without bound at the poles."""


def _latitude(lat):
    lat = np.asarray(lat, dtype=np.float64)
    if np.any(np.abs(lat) > MAX_LATITUDE):
        worst = float(np.nanmax(np.abs(lat)))
        raise GeometryError(f"latitude {worst:g} is beyond +-{MAX_LATITUDE:g} degrees, where Mercator is unusable")
    return lat


def to_mercator(lon, lat):
    """Project longitude and latitude to spherical Mercator.

    Parameters
    ----------
    lon, lat : array_like
        Degrees (WGS84); ``|lat| <= 85``.

    Returns
    -------
    x, y : ndarray
        Metres on the Mercator plane (``x = R lon``, ``y = R ln tan(pi/4 + lat/2)``).

    Examples
    --------
    >>> x, y = to_mercator([0.0, 1.0], [0.0, 0.0])
    >>> round(float(x[1]), 3), abs(float(y[0])) < 1e-6
    (111319.491, True)
    """
    lat = _latitude(lat)
    x = EARTH_RADIUS * np.radians(np.asarray(lon, dtype=np.float64))
    y = EARTH_RADIUS * np.log(np.tan(0.25 * np.pi + 0.5 * np.radians(lat)))
    return x, y


def from_mercator(x, y):
    """Longitude and latitude (degrees) of Mercator coordinates (metres); inverse of :func:`to_mercator`.

    Examples
    --------
    >>> lon, lat = from_mercator(*to_mercator(-93.9, 29.8))
    >>> round(float(lon), 12), round(float(lat), 12)
    (-93.9, 29.8)
    """
    lon = np.degrees(np.asarray(x, dtype=np.float64) / EARTH_RADIUS)
    lat = np.degrees(2.0 * np.arctan(np.exp(np.asarray(y, dtype=np.float64) / EARTH_RADIUS)) - 0.5 * np.pi)
    return lon, lat


def scale_factor(lat):
    """Mercator metres per ground metre at latitude ``lat`` (degrees): ``1 / cos(lat)``.

    Examples
    --------
    >>> float(scale_factor(60.0).round(12))
    2.0
    """
    return 1.0 / np.cos(np.radians(_latitude(lat)))


def metres_per_degree(lat):
    """Ground metres per degree of longitude and of latitude at ``lat`` (degrees), on the Mercator sphere.

    Returns
    -------
    along_lon, along_lat : ndarray
        ``R cos(lat) pi/180`` and ``R pi/180``.

    Examples
    --------
    >>> east, north = metres_per_degree(60.0)
    >>> round(float(east), 1), round(float(north), 1)
    (55659.7, 111319.5)
    """
    lat = _latitude(lat)
    per_degree = EARTH_RADIUS * np.pi / 180.0
    return per_degree * np.cos(np.radians(lat)), per_degree * np.ones_like(lat)
