"""Tidal constituents, their astronomy, and harmonic constants from a TPXO atlas.

Three things an ADCIRC tidal run needs, in the conventions ADCIRC uses:

* the constituents (:data:`CONSTITUENTS`): angular frequency (rad/s),
  equilibrium potential amplitude (m) and earth tide reduction factor, the
  values ADCIRC's ``fort.15`` documentation and its ``tide_fac`` program list
  (Reid 1990);
* the nodal factor ``f`` and the Greenwich equilibrium argument ``V0 + u``
  (degrees) of a run (:func:`tidal_factors`), with the formulas of Schureman
  (1958) as ADCIRC's ``tide_fac`` evaluates them: ``V0`` at the start of the
  run, ``f`` and ``u`` at its middle;
* elevation amplitude (m) and Greenwich phase lag (degrees) at given
  longitudes and latitudes from a TPXO-format NetCDF atlas the user supplies
  (:func:`atlas_elevation_constants`).

The astronomical arguments are tide_fac's linear mean longitudes (Schureman
Table 1) counted in days from 1900-01-01 00:00 UT: the Moon's mean longitude
``s``, the Sun's ``h``, the lunar perigee ``p``, the solar perigee ``p1`` and
the Moon's ascending node ``N``, from which the inclination ``I`` of the lunar
orbit to the equator and the node terms ``nu``, ``xi``, ``nu'`` and ``2nu''``
follow (Schureman eqs. 191-224). tide_fac counts days with its own leap-year
rule, which equals the Gregorian calendar from 1901 to 2099; here the days
are true Gregorian days, so dates outside that range are handled correctly
rather than silently shifted.

References
----------
Schureman, P. (1958). *Manual of Harmonic Analysis and Prediction of Tides*.
US Coast and Geodetic Survey Special Publication 98. doi:10.25607/OBP-155.

Reid, R. O. (1990). Tides and storm surges. In *Handbook of Coastal and Ocean
Engineering*, vol. 1, ed. J. B. Herbich, Gulf Publishing, 533-590.

Egbert, G. D. and Erofeeva, S. Y. (2002). Efficient inverse modeling of
barotropic ocean tides. *J. Atmos. Oceanic Technol.* 19, 183-204.
doi:10.1175/1520-0426(2002)019<0183:EIMOBO>2.0.CO;2.
"""

import datetime as _dt
import os
import re
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from ..errors import ForcingError, MeshFormatError, checked_number, warn_user
from .projection import EARTH_RADIUS

__all__ = [
    "Constituent",
    "CONSTITUENTS",
    "get_constituent",
    "astronomical_arguments",
    "TidalFactors",
    "tidal_factors",
    "HarmonicConstants",
    "ATLAS_CELLS_OUTSIDE",
    "atlas_elevation_constants",
]


# Speeds of the astronomical arguments in degrees per mean solar hour (Schureman Table 1, as in tide_fac):
# T (hour angle of the mean Sun), s, h, p, p1.
_SPEEDS = np.array([15.0, 0.549016532, 0.0410686387, 0.004641834, 0.000001961])

# tide_fac's mean longitudes at 1900-01-01 00:00 UT (degrees) and their rates (degrees per day).
_EPOCH = _dt.datetime(1900, 1, 1)
_ELEMENTS_AT_EPOCH = {"s": 277.0256206, "h": 280.1895014, "p": 334.3837214, "p1": 281.2208569, "N": 259.1560564}
_ELEMENT_RATES = {"s": 13.176396768, "h": 0.9856473288, "p": 0.111404016, "p1": 0.000047064, "N": -0.0529539336}


@dataclass(frozen=True)
class Constituent:
    """One tidal constituent as ADCIRC forces it.

    Attributes
    ----------
    name : str
        Conventional name, e.g. ``"M2"``.
    species : int
        Cycles per day: 0 long period, 1 diurnal, 2 semidiurnal, 4 quarter diurnal.
    doodson : tuple of int
        Multipliers of ``(T, s, h, p, p1)`` in the equilibrium argument ``V``
        (Schureman Table 2); ``T = 180 + 15 * hour`` is the hour angle of the
        mean Sun at Greenwich.
    phase : float
        Constant part of ``V``, degrees (e.g. -90 for K1).
    node : tuple of int
        Multipliers of ``(xi, nu, nu', 2nu'')`` in the nodal angle ``u``.
    factor_formula : str
        Which Schureman node factor ``f`` applies: ``"1"``, ``"78"`` (M2
        family), ``"78^2"``, ``"75"`` (O1 family), ``"227"`` (K1), ``"235"``
        (K2), ``"74"`` (Mf) or ``"73"`` (Mm), after Schureman's equation numbers.
    potential_amplitude : float
        Amplitude of the equilibrium tide (m); 0 for shallow-water
        constituents, which have no tidal potential.
    earth_tide_reduction : float
        Earth tide reduction factor (1 + k - h of the Love numbers) that
        ADCIRC multiplies the potential by; 0 where there is no potential.

    Examples
    --------
    >>> m2 = CONSTITUENTS["M2"]
    >>> round(m2.speed, 7), round(m2.period_hours, 4)
    (28.9841042, 12.4206)
    """

    name: str
    species: int
    doodson: tuple
    phase: float
    node: tuple
    factor_formula: str
    potential_amplitude: float
    earth_tide_reduction: float

    @property
    def speed(self):
        """Angular speed, degrees per mean solar hour."""
        return float(np.dot(self.doodson, _SPEEDS))

    @property
    def frequency(self):
        """Angular frequency, rad/s (ADCIRC's AMIGT, AMIG, HAFREQ)."""
        return float(np.deg2rad(self.speed) / 3600.0)

    @property
    def period_hours(self):
        """Period, hours."""
        return 360.0 / self.speed


def _constituent(name, species, doodson, phase, node, formula, amplitude=0.0, reduction=0.0):
    return Constituent(name, species, tuple(doodson), float(phase), tuple(node), formula, amplitude, reduction)


# Potential amplitudes and earth tide reduction factors: ADCIRC fort.15 documentation / tide_fac.f (Reid 1990);
# 2N2, Mf and Mm from the same table of equilibrium amplitudes, with the semidiurnal/long-period factor 0.693.
CONSTITUENTS = MappingProxyType(
    {
        c.name: c
        for c in (
            _constituent("M2", 2, (2, -2, 2, 0, 0), 0, (2, -2, 0, 0), "78", 0.242334, 0.693),
            _constituent("S2", 2, (2, 0, 0, 0, 0), 0, (0, 0, 0, 0), "1", 0.112841, 0.693),
            _constituent("N2", 2, (2, -3, 2, 1, 0), 0, (2, -2, 0, 0), "78", 0.046398, 0.693),
            _constituent("K2", 2, (2, 0, 2, 0, 0), 0, (0, 0, 0, -1), "235", 0.030704, 0.693),
            _constituent("K1", 1, (1, 0, 1, 0, 0), -90, (0, 0, -1, 0), "227", 0.141565, 0.736),
            _constituent("O1", 1, (1, -2, 1, 0, 0), 90, (2, -1, 0, 0), "75", 0.100514, 0.695),
            _constituent("P1", 1, (1, 0, -1, 0, 0), 90, (0, 0, 0, 0), "1", 0.046843, 0.706),
            _constituent("Q1", 1, (1, -3, 1, 1, 0), 90, (2, -1, 0, 0), "75", 0.019256, 0.695),
            _constituent("2N2", 2, (2, -4, 2, 2, 0), 0, (2, -2, 0, 0), "78", 0.006141, 0.693),
            _constituent("Mf", 0, (0, 2, 0, 0, 0), 0, (-2, 0, 0, 0), "74", 0.042017, 0.693),
            _constituent("Mm", 0, (0, 1, 0, -1, 0), 0, (0, 0, 0, 0), "73", 0.022191, 0.693),
            _constituent("M4", 4, (4, -4, 4, 0, 0), 0, (4, -4, 0, 0), "78^2"),
            _constituent("MS4", 4, (4, -2, 2, 0, 0), 0, (2, -2, 0, 0), "78"),
            _constituent("MN4", 4, (4, -5, 4, 1, 0), 0, (4, -4, 0, 0), "78^2"),
        )
    }
)
_BY_UPPER = {name.upper(): c for name, c in CONSTITUENTS.items()}


def get_constituent(name):
    """The :class:`Constituent` called ``name`` (case-insensitive).

    Parameters
    ----------
    name : str or Constituent

    Returns
    -------
    Constituent

    Raises
    ------
    ForcingError
        If the name is not one of :data:`CONSTITUENTS` (a ``ValueError``).

    Examples
    --------
    >>> get_constituent("mf").name
    'Mf'
    """
    if isinstance(name, Constituent):
        return name
    key = str(name).strip().upper()
    if key not in _BY_UPPER:
        raise ForcingError(f"unknown tidal constituent {name!r}; known: {', '.join(CONSTITUENTS)}")
    return _BY_UPPER[key]


def as_utc(time, what="time"):
    """A naive UTC datetime from a datetime, date, numpy datetime64, ISO 8601 or MATLAB datestr string."""
    if isinstance(time, np.datetime64):
        time = time.astype("datetime64[us]").item()
    elif isinstance(time, str):
        time = _parsed(time, what)
    if isinstance(time, _dt.date) and not isinstance(time, _dt.datetime):
        time = _dt.datetime(time.year, time.month, time.day)
    if not isinstance(time, _dt.datetime):
        raise ForcingError(f"{what} must be a datetime, date, numpy.datetime64 or ISO 8601 string, got {time!r}")
    if time.tzinfo is not None:
        time = time.astimezone(_dt.timezone.utc).replace(tzinfo=None)
    return time


_MATLAB_FORMATS = ("%d-%b-%Y %H:%M:%S", "%d-%b-%Y %H:%M", "%d-%b-%Y")
"""MATLAB's datestr forms, which OceanMesh2D's scripts give their times in ('01-Aug-2012 00:00')."""


def _parsed(text, what):
    """A datetime from an ISO 8601 string or one of MATLAB's datestr forms."""
    try:
        return _dt.datetime.fromisoformat(text.strip().replace("Z", "+00:00"))
    except ValueError as error:
        for form in _MATLAB_FORMATS:
            try:
                return _dt.datetime.strptime(text.strip(), form)
            except ValueError:
                continue
        raise ForcingError(
            f"cannot read {what} {text!r} as an ISO 8601 date (2012-08-01T00:00) or MATLAB's (01-Aug-2012 00:00): "
            f"{error}"
        ) from error


def _days_since_epoch(time):
    return (time - _EPOCH) / _dt.timedelta(days=1)


def astronomical_arguments(time):
    """Mean longitudes and lunar node terms at ``time`` (tide_fac's ORBIT).

    Parameters
    ----------
    time : datetime.datetime, numpy.datetime64 or str
        UTC; a timezone-aware datetime is converted to UTC.

    Returns
    -------
    dict of str to float
        Degrees: ``s`` (Moon's mean longitude), ``h`` (Sun's), ``p`` (lunar
        perigee), ``p1`` (solar perigee), ``N`` (Moon's ascending node), all
        in [0, 360); ``T`` (hour angle of the mean Sun, 180 at 00:00 UT);
        ``I`` (inclination of the lunar orbit to the equator); ``nu``, ``xi``,
        ``nu1`` (nu') and ``two_nu2`` (2nu''), in (-180, 180].

    Examples
    --------
    >>> args = astronomical_arguments("2000-01-01T12:00")
    >>> round(args["h"], 2), round(args["N"], 2)
    (280.47, 125.04)
    """
    time = as_utc(time)
    days = _days_since_epoch(time)
    out = {key: (_ELEMENTS_AT_EPOCH[key] + _ELEMENT_RATES[key] * days) % 360.0 for key in _ELEMENTS_AT_EPOCH}
    hours = time.hour + time.minute / 60.0 + (time.second + time.microsecond * 1e-6) / 3600.0
    out["T"] = (180.0 + 15.0 * hours) % 360.0
    node = np.deg2rad(out["N"])
    inclination = np.arccos(0.9136949 - 0.0356926 * np.cos(node))
    nu = np.arcsin(0.0897056 * np.sin(node) / np.sin(inclination))
    xi = node - 2.0 * np.arctan2(0.64412 * np.sin(node / 2.0), np.cos(node / 2.0)) - nu
    nu1 = np.arctan(np.sin(nu) / (np.cos(nu) + 0.334766 / np.sin(2.0 * inclination)))
    two_nu2 = np.arctan(np.sin(2.0 * nu) / (np.cos(2.0 * nu) + 0.0726184 / np.sin(inclination) ** 2))
    out["I"] = float(np.rad2deg(inclination))
    for key, value in (("nu", nu), ("xi", xi), ("nu1", nu1), ("two_nu2", two_nu2)):
        out[key] = float((np.rad2deg(value) + 180.0) % 360.0 - 180.0)
    return out


def _node_factors(inclination_deg, nu_deg):
    """Schureman's node factors by equation number, for I and nu in degrees."""
    i = np.deg2rad(inclination_deg)
    nu = np.deg2rad(nu_deg)
    sin_i, cos_half = np.sin(i), np.cos(i / 2.0)
    eq78 = cos_half**4 / 0.91544
    return {
        "1": 1.0,
        "73": (2.0 / 3.0 - sin_i**2) / 0.5021,
        "74": sin_i**2 / 0.1578,
        "75": sin_i * cos_half**2 / 0.37988,
        "78": eq78,
        "78^2": eq78**2,
        "227": np.sqrt(0.8965 * np.sin(2.0 * i) ** 2 + 0.6001 * np.sin(2.0 * i) * np.cos(nu) + 0.1006),
        # tide_fac adds 0.001 to Schureman's eq. 235; kept so the factors match what ADCIRC users compare with.
        "235": 0.001 + np.sqrt(19.0444 * sin_i**4 + 2.7702 * sin_i**2 * np.cos(2.0 * nu) + 0.0981),
    }


@dataclass(frozen=True)
class TidalFactors:
    """Nodal factors and equilibrium arguments of a run, one entry per constituent.

    Attributes
    ----------
    constituents : tuple of Constituent
    start : datetime.datetime
        Start of the run, UTC (naive).
    run_days : float
        Length of the run, days; ``f`` and ``u`` are taken at its middle.
    frequency : numpy.ndarray, shape (k,)
        Angular frequency, rad/s.
    nodal_factor : numpy.ndarray, shape (k,)
        Node factor ``f`` (dimensionless) at the middle of the run.
    equilibrium_argument : numpy.ndarray, shape (k,)
        ``V0 + u`` in degrees for the Greenwich meridian, in [0, 360):
        ``V0`` at the start, ``u`` at the middle of the run.
    """

    constituents: tuple
    start: _dt.datetime
    run_days: float
    frequency: np.ndarray
    nodal_factor: np.ndarray
    equilibrium_argument: np.ndarray

    @property
    def names(self):
        """Constituent names, in order."""
        return tuple(c.name for c in self.constituents)

    def __getitem__(self, name):
        """``(f, V0 + u)`` of one constituent, by name."""
        index = self.names.index(get_constituent(name).name)
        return float(self.nodal_factor[index]), float(self.equilibrium_argument[index])


def tidal_factors(constituents, start, *, run_days=0.0):
    """Nodal factors and Greenwich equilibrium arguments as ADCIRC's tide_fac computes them.

    Parameters
    ----------
    constituents : sequence of str or Constituent
        Names from :data:`CONSTITUENTS` (case-insensitive).
    start : datetime.datetime, datetime.date, numpy.datetime64 or str
        Start of the run, UTC (ISO 8601 strings are accepted; an aware
        datetime is converted to UTC).
    run_days : float, optional
        Length of the run in days (>= 0). The node factors ``f`` and nodal
        angles ``u`` are evaluated at ``start + run_days / 2`` and ``V0`` at
        ``start``, as tide_fac does.

    Returns
    -------
    TidalFactors

    Raises
    ------
    ForcingError
        For an unknown constituent, an unreadable date or a negative,
        non-finite or non-numeric ``run_days`` (a ``ValueError``).

    Examples
    --------
    >>> factors = tidal_factors(["M2", "S2"], "2012-01-01T00:00", run_days=30)
    >>> f, v0u = factors["S2"]
    >>> f, v0u
    (1.0, 0.0)
    >>> bool(0.96 < factors["M2"][0] < 1.04)
    True
    """
    if isinstance(constituents, (str, Constituent)):
        constituents = [constituents]
    table = tuple(get_constituent(c) for c in constituents)
    start = as_utc(start, "start")
    run_days = checked_number(run_days, "run_days must be a finite number >= 0", ForcingError, minimum=0)
    at_start = astronomical_arguments(start)
    middle = astronomical_arguments(start + _dt.timedelta(days=run_days / 2.0))
    factors = _node_factors(middle["I"], middle["nu"])
    doodson = np.array([c.doodson for c in table], dtype=np.float64).reshape(-1, 5)
    node = np.array([c.node for c in table], dtype=np.float64).reshape(-1, 4)
    phase = np.array([c.phase for c in table], dtype=np.float64)
    v0 = doodson @ np.array([at_start[k] for k in ("T", "s", "h", "p", "p1")]) + phase
    u = node @ np.array([middle[k] for k in ("xi", "nu", "nu1", "two_nu2")])
    argument = (v0 + u) % 360.0
    argument[np.isclose(argument, 360.0, rtol=0.0, atol=1e-9)] = 0.0
    return TidalFactors(
        constituents=table,
        start=start,
        run_days=run_days,
        frequency=np.array([c.frequency for c in table]),
        nodal_factor=np.array([float(factors[c.factor_formula]) for c in table]),
        equilibrium_argument=argument,
    )


# ---------------------------------------------------------------------------------------------------------------------
# TPXO atlases


@dataclass(frozen=True)
class HarmonicConstants:
    """Elevation harmonic constants at a set of points.

    Attributes
    ----------
    constituents : tuple of str
    amplitude : numpy.ndarray, shape (k, n)
        Amplitude, metres, per constituent and point.
    phase : numpy.ndarray, shape (k, n)
        Greenwich phase lag, degrees in [0, 360).
    nearest : numpy.ndarray of bool, shape (k, n)
        True where the bilinear stencil touched land (or left the grid, by
        at most :data:`ATLAS_CELLS_OUTSIDE` cells) and the value of the
        nearest ocean cell was used instead.
    """

    constituents: tuple
    amplitude: np.ndarray
    phase: np.ndarray
    nearest: np.ndarray


_UNIT_SCALE = {
    "mm": 1e-3,
    "millimeter": 1e-3,
    "millimeters": 1e-3,
    "millimetre": 1e-3,
    "millimetres": 1e-3,
    "cm": 1e-2,
    "centimeter": 1e-2,
    "centimeters": 1e-2,
    "m": 1.0,
    "meter": 1.0,
    "meters": 1.0,
    "metre": 1.0,
    "metres": 1.0,
}


ATLAS_CELLS_OUTSIDE = 2
"""How far outside an atlas's grid of cell centres a point may lie, in atlas cells, and take the nearest ocean cell.

Farther out the atlas does not cover the point: :func:`atlas_elevation_constants` refuses it rather than extend the
atlas's edge over hundreds of kilometres."""


def atlas_elevation_constants(atlas, lon, lat, *, constituents, units=None):
    """Elevation amplitude and phase at points from a TPXO-format NetCDF atlas.

    The complex elevation ``hRe + i hIm`` is interpolated bilinearly between
    the four surrounding cell centres; where any of them is land (zero, NaN
    or masked) or the point lies just outside the grid (at most
    :data:`ATLAS_CELLS_OUTSIDE` cells beyond the outer cell centres), the
    nearest ocean cell (great-circle distance) is used instead. Points
    farther outside are refused: the atlas does not cover them. Longitudes
    wrap for global grids (0-360 or -180-180 either way).

    Parameters
    ----------
    atlas : str, os.PathLike or mapping of str to path
        One of: a folder holding one file per constituent named
        ``h_<con>_*.nc`` (TPXO9-atlas: variables ``hRe``, ``hIm`` and
        ``lon_z``, ``lat_z``); a single file with all constituents
        (``h_tpxo*.nc``: a ``con`` character variable and ``ha``/``hp``
        amplitude (m) and phase (degrees), or ``hRe``/``hIm``, with a leading
        constituent dimension); or a mapping from constituent name to its
        file. Coordinates are ``lon_z``/``lat_z`` (1-D, or 2-D on the
        ``nx``, ``ny`` grid), or ``lon``/``lat``; either axis order.
    lon, lat : array_like, shape (n,)
        Points, degrees east and north.
    constituents : sequence of str
        Constituents to read.
    units : {"mm", "cm", "m"}, optional
        Units of ``hRe``/``hIm`` (or ``ha``) when the file's ``units``
        attribute is missing; by default read from the attribute, else
        millimetres for integer data (TPXO9-atlas) and metres otherwise, with
        a warning.

    Returns
    -------
    HarmonicConstants
        Amplitude (m) and Greenwich phase lag (degrees) per constituent and point.

    Raises
    ------
    MeshFormatError
        If a file is missing or lacks the variables above, or a
        constituent has no ocean cell at all.
    ForcingError
        For points that are not finite 1-D arrays of one shape (or none),
        points more than :data:`ATLAS_CELLS_OUTSIDE` atlas cells outside
        the atlas's grid (the message gives how many, the farthest and the
        atlas's extent), an unknown ``units`` attribute or option, or a
        constituent the atlas does not hold.

    Warns
    -----
    TerrameshWarning
        When points fall back to the nearest ocean cell (with the largest
        distance, in km, from a point to the cell used), and when units are
        guessed.

    Examples
    --------
    >>> import numpy as np, netCDF4, os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "h_m2_tpxo9_atlas_30.nc")
    >>> with netCDF4.Dataset(path, "w") as nc:
    ...     _ = nc.createDimension("nx", 4), nc.createDimension("ny", 3)
    ...     nc.createVariable("lon_z", "f8", ("nx",))[:] = [0.0, 1.0, 2.0, 3.0]
    ...     nc.createVariable("lat_z", "f8", ("ny",))[:] = [10.0, 11.0, 12.0]
    ...     re = nc.createVariable("hRe", "i4", ("nx", "ny")); re.units = "millimeter"
    ...     im = nc.createVariable("hIm", "i4", ("nx", "ny")); im.units = "millimeter"
    ...     re[:], im[:] = np.full((4, 3), 300), np.full((4, 3), -400)
    >>> out = atlas_elevation_constants(os.path.dirname(path), [1.5], [11.2], constituents=["M2"])
    >>> round(float(out.amplitude[0, 0]), 6), round(float(out.phase[0, 0]), 4)
    (0.5, 53.1301)
    """
    lon = np.atleast_1d(np.asarray(lon, dtype=np.float64))
    lat = np.atleast_1d(np.asarray(lat, dtype=np.float64))
    if lon.shape != lat.shape or lon.ndim != 1 or len(lon) == 0:
        raise ForcingError(f"lon and lat must be 1-D arrays of one shape, not empty; got {lon.shape} and {lat.shape}")
    if not (np.all(np.isfinite(lon)) and np.all(np.isfinite(lat))):
        raise ForcingError("lon and lat must be finite")
    if units is not None and str(units).lower() not in _UNIT_SCALE:
        raise ForcingError(f"units must be one of mm, cm, m; got {units!r}")
    names = tuple(get_constituent(c).name for c in constituents)
    sources = _atlas_sources(atlas, names)
    amplitude = np.empty((len(names), len(lon)))
    phase = np.empty((len(names), len(lon)))
    nearest = np.zeros((len(names), len(lon)), dtype=bool)
    distance_km = np.zeros((len(names), len(lon)))
    for k, name in enumerate(names):
        grid = _AtlasField(sources[name], name, units)
        grid.check_coverage(lon, lat)
        values, nearest[k], distance_km[k] = grid.sample(lon, lat)
        amplitude[k] = np.abs(values)
        phase[k] = np.rad2deg(np.arctan2(-values.imag, values.real)) % 360.0
    if nearest.any():
        counts = ", ".join(f"{n}: {int(c)}" for n, c in zip(names, nearest.sum(axis=1), strict=True) if c)
        k, far = np.unravel_index(int(np.argmax(np.where(nearest, distance_km, -1.0))), nearest.shape)
        warn_user(
            f"tidal atlas: the interpolation stencil touched land or left the grid at some points; "
            f"the nearest ocean cell was used ({counts} of {len(lon)} points); the largest distance to the cell "
            f"used is {distance_km[k, far]:.1f} km ({names[k]} at lon {lon[far]:.4f}, lat {lat[far]:.4f})",
        )
    return HarmonicConstants(names, amplitude, phase, nearest)


def _atlas_sources(atlas, names):
    """Map each constituent to ``(path, index)``: index None for one-constituent files."""
    if isinstance(atlas, dict) or hasattr(atlas, "keys"):
        by_upper = {get_constituent(key).name: os.fspath(value) for key, value in atlas.items()}
        missing = [n for n in names if n not in by_upper]
        if missing:
            raise ForcingError(f"the tidal atlas mapping has no file for {', '.join(missing)}")
        return {n: (by_upper[n], None) for n in names}
    path = os.fspath(atlas)
    if os.path.isdir(path):
        files = sorted(f for f in os.listdir(path) if f.lower().endswith(".nc"))
        sources = {}
        for name in names:
            pattern = re.compile(rf"^h[_.]?{re.escape(name.lower())}[_.]", re.IGNORECASE)
            matches = [f for f in files if pattern.match(f)]
            if len(matches) > 1:
                raise ForcingError(f"{path}: several files for {name}: {', '.join(matches)}")
            if matches:
                sources[name] = (os.path.join(path, matches[0]), None)
        missing = [n for n in names if n not in sources]
        if missing:
            combined = [os.path.join(path, f) for f in files if _has_variable(os.path.join(path, f), "con")]
            if len(combined) == 1:
                sources.update(_combined_sources(combined[0], missing))
            else:
                raise ForcingError(
                    f"{path}: no h_<con>_*.nc file for {', '.join(missing)} and no single all-constituent file"
                )
        return sources
    if not os.path.isfile(path):
        raise MeshFormatError(f"tidal atlas not found: {path!r}")
    if _has_variable(path, "con"):
        return _combined_sources(path, names)
    if len(names) == 1:
        return {names[0]: (path, None)}
    raise ForcingError(f"{path} holds one constituent (no 'con' variable); pass a folder or a mapping for several")


def _netcdf():
    import netCDF4

    return netCDF4


def _has_variable(path, name):
    try:
        with _netcdf().Dataset(path) as nc:
            return name in nc.variables
    except OSError as error:
        raise MeshFormatError(f"cannot open tidal atlas file {path}: {error}") from error


def _combined_sources(path, names):
    """``{name: (path, index)}`` of a file of several constituents, or of one whose ``con`` names it.

    A TPXO9-atlas file of one constituent (``h_m2_tpxo9_atlas_30.nc``)
    names it in a 1-D ``con`` of characters, over 2-D fields: its index is
    None (it was split into letters and refused: "holds M, 2").
    """
    with _netcdf().Dataset(path) as nc:
        raw = np.asarray(nc.variables["con"][:])
        field = next((nc.variables[v] for v in ("hRe", "ha") if v in nc.variables), None)
        single = field is not None and len(field.dimensions) == 2
    if single and raw.dtype.kind == "S" and raw.ndim == 1 and raw.dtype.itemsize == 1:
        raw = np.array([b"".join(raw.tolist())])
    if raw.dtype.kind in "SU" and raw.ndim == 2:
        labels = [b"".join(row).decode() if raw.dtype.kind == "S" else "".join(row) for row in raw]
    elif raw.dtype.kind in "SUO":
        labels = [v.decode() if isinstance(v, bytes) else str(v) for v in raw.ravel()]
    else:
        raise MeshFormatError(f"{path}: cannot read the constituent names in 'con'")
    labels = [label.strip().strip("\x00").upper() for label in labels]
    sources = {}
    for name in names:
        if name.upper() not in labels:
            raise ForcingError(f"{path} has no {name}; it holds {', '.join(labels)}")
        sources[name] = (path, None if single else labels.index(name.upper()))
    return sources


class _AtlasField:
    """One constituent's complex elevation on a regular lon/lat grid, read lazily by window."""

    def __init__(self, source, name, units):
        self.path, self.index = source
        self.name = name
        self.units = units
        with _netcdf().Dataset(self.path) as nc:
            self._layout(nc)

    def _layout(self, nc):
        variables = nc.variables
        if "hRe" in variables and "hIm" in variables:
            self.kind, first = "complex", variables["hRe"]
        elif "ha" in variables and "hp" in variables:
            self.kind, first = "polar", variables["ha"]
        else:
            raise MeshFormatError(f"{self.path}: no hRe/hIm or ha/hp variables for {self.name}")
        dims = first.dimensions
        if self.index is not None:
            if len(dims) != 3:
                raise MeshFormatError(f"{self.path}: expected (constituent, x, y) fields, got dimensions {dims}")
            dims = dims[1:]
        elif len(dims) != 2:
            raise MeshFormatError(f"{self.path}: expected 2-D fields, got dimensions {dims}")
        self.field_dims = dims
        lon_var = next((variables[v] for v in ("lon_z", "lon", "longitude", "x") if v in variables), None)
        lat_var = next((variables[v] for v in ("lat_z", "lat", "latitude", "y") if v in variables), None)
        if lon_var is None or lat_var is None:
            raise MeshFormatError(f"{self.path}: no lon_z/lat_z (or lon/lat) coordinates")
        self.lon, lon_axis = self._axis(lon_var, dims, "longitude")
        self.lat, lat_axis = self._axis(lat_var, dims, "latitude")
        if lon_axis == lat_axis:
            raise MeshFormatError(f"{self.path}: longitude and latitude vary along the same axis")
        self.lon_axis = lon_axis
        self.scale = self._scale(first)
        if np.any(np.diff(self.lat) == 0) or np.any(np.diff(self.lon) <= 0):
            raise MeshFormatError(f"{self.path}: longitudes must increase and latitudes be monotonic")
        self.lat_flipped = bool(self.lat[0] > self.lat[-1])
        if self.lat_flipped:
            self.lat = self.lat[::-1]
        span = self.lon[-1] - self.lon[0]
        step = span / max(len(self.lon) - 1, 1)
        self.periodic = bool(len(self.lon) > 2 and span + 1.5 * step >= 360.0)

    def _axis(self, variable, dims, what):
        """The 1-D coordinate and which field axis (0 or 1) it runs along."""
        values = np.ma.filled(np.asarray(variable[:], dtype=np.float64), np.nan)
        if values.ndim == 1:
            if variable.dimensions[0] in dims:
                return values, dims.index(variable.dimensions[0])
            raise MeshFormatError(f"{self.path}: the {what} dimension {variable.dimensions} is not one of {dims}")
        if values.ndim == 2 and tuple(variable.dimensions) == tuple(dims):
            along0 = np.nanmax(np.abs(np.diff(values, axis=0))) if values.shape[0] > 1 else 0.0
            along1 = np.nanmax(np.abs(np.diff(values, axis=1))) if values.shape[1] > 1 else 0.0
            axis = 0 if along0 >= along1 else 1
            line = values[:, 0] if axis == 0 else values[0, :]
            expanded = line[:, None] if axis == 0 else line[None, :]
            if not np.allclose(values, np.broadcast_to(expanded, values.shape)):
                raise MeshFormatError(f"{self.path}: only regular (rectilinear) atlas grids are supported")
            return line, axis
        raise MeshFormatError(f"{self.path}: cannot read the {what} coordinate of shape {values.shape}")

    def _scale(self, variable):
        unit = getattr(variable, "units", None)
        if unit is not None:
            key = str(unit).strip().lower()
            if key not in _UNIT_SCALE:
                raise ForcingError(f"{self.path}: unknown units {unit!r} of {variable.name}")
            return _UNIT_SCALE[key]
        if self.units is not None:
            return _UNIT_SCALE[str(self.units).lower()]
        guess = "mm" if variable.dtype.kind in "iu" else "m"
        warn_user(
            f"{self.path}: {variable.name} has no units attribute; reading it as {guess} "
            f"(pass units= to say otherwise)",
        )
        return _UNIT_SCALE[guess]

    def _read(self, nc, name, lon_slice, lat_slice):
        """A (lat, lon) block of one variable, NaN where masked."""
        index = [slice(None), slice(None)]
        index[self.lon_axis] = lon_slice
        index[1 - self.lon_axis] = lat_slice
        if self.index is not None:
            index = [self.index, *index]
        block = np.ma.filled(np.ma.asarray(nc.variables[name][tuple(index)]).astype(np.float64), np.nan)
        return block if self.lon_axis == 1 else block.T

    def _window(self, lon_indices, lat_lo, lat_hi):
        """Complex field on the window: columns ``lon_indices`` (may wrap), rows lat_lo..lat_hi (sorted lat)."""
        n_lat = len(self.lat)
        if self.lat_flipped:
            lat_slice = slice(n_lat - lat_hi, n_lat - lat_lo)
        else:
            lat_slice = slice(lat_lo, lat_hi)
        # contiguous runs of column indices, so netCDF reads slabs
        breaks = np.flatnonzero(np.diff(lon_indices) != 1) + 1
        runs = np.split(lon_indices, breaks)
        blocks = []
        with _netcdf().Dataset(self.path) as nc:
            for run in runs:
                cols = slice(int(run[0]), int(run[-1]) + 1)
                if self.kind == "complex":
                    real = self._read(nc, "hRe", cols, lat_slice)
                    imag = self._read(nc, "hIm", cols, lat_slice)
                    blocks.append((real + 1j * imag) * self.scale)
                else:
                    amp = self._read(nc, "ha", cols, lat_slice) * self.scale
                    pha = np.deg2rad(self._read(nc, "hp", cols, lat_slice))
                    blocks.append(amp * np.exp(-1j * pha))
        field = np.concatenate(blocks, axis=1)
        if self.lat_flipped:
            field = field[::-1]
        return field

    def _load(self, lo_i, hi_i, lo_j, hi_j):
        """Window of columns lo_i..hi_i (wrapping when periodic) and sorted rows lo_j..hi_j."""
        nx, ny = len(self.lon), len(self.lat)
        lo_j, hi_j = max(lo_j, 0), min(hi_j, ny)
        if self.periodic:
            if hi_i - lo_i >= nx:
                # the whole turn, with the last column again in front of the first (a turn west): points
                # between the last and the first cell centres, which sample puts there, keep their stencil
                lo_i, hi_i = -1, nx
            positions = np.arange(lo_i, hi_i)
            columns = positions % nx
            window_lon = self.lon[columns] + 360.0 * np.floor_divide(positions, nx)
            whole_x = hi_i - lo_i >= nx
            edge_x = (whole_x, whole_x)
        else:
            lo_i, hi_i = max(lo_i, 0), min(hi_i, nx)
            columns = np.arange(lo_i, hi_i)
            window_lon = self.lon[columns]
            edge_x = (lo_i == 0, hi_i == nx)
        field = self._window(columns, lo_j, hi_j)
        window = {
            "lon": window_lon,
            "lat": self.lat[lo_j:hi_j],
            "field": field,
            "ocean": np.isfinite(field) & (field != 0),
            # whether the window reaches the end of the grid on each side (nothing further out to search)
            "edge": (*edge_x, lo_j == 0, hi_j == ny),
            "bounds": (lo_i, hi_i, lo_j, hi_j),
            "whole": len(columns) >= nx and lo_j == 0 and hi_j == ny,
        }
        return window

    @property
    def steps(self):
        """Typical cell size (median spacing of the centres), degrees of longitude and latitude."""
        step_x = float(np.median(np.diff(self.lon))) if len(self.lon) > 1 else 1.0
        step_y = float(np.median(np.abs(np.diff(self.lat)))) if len(self.lat) > 1 else 1.0
        return step_x, step_y

    def check_coverage(self, lon, lat):
        """:class:`ForcingError` for points more than :data:`ATLAS_CELLS_OUTSIDE` cells outside the grid's centres.

        Nearer points (coastal cells masked as land, points between the
        outer centres and the atlas's edge) take the nearest ocean cell.
        """
        x = self._unwrap(lon)
        step_x, step_y = self.steps
        # the nearest point of the grid's rectangle of centres (a global grid has no east or west side)
        cx = x if self.periodic else np.clip(x, self.lon[0], self.lon[-1])
        cy = np.clip(lat, self.lat[0], self.lat[-1])
        cells = np.maximum(np.abs(x - cx) / step_x, np.abs(lat - cy) / step_y)
        outside = cells > ATLAS_CELLS_OUTSIDE
        if not outside.any():
            return
        angle = np.rad2deg(np.arccos(np.clip(np.sum(_unit_vectors(x, lat) * _unit_vectors(cx, cy), axis=1), -1, 1)))
        km = np.deg2rad(angle) * EARTH_RADIUS / 1000.0
        far = int(np.argmax(np.where(outside, km, -1.0)))
        lon_extent = "all longitudes" if self.periodic else f"lon {self.lon[0]:g}..{self.lon[-1]:g}"
        raise ForcingError(
            f"{int(outside.sum())} of {len(x)} points lie more than {ATLAS_CELLS_OUTSIDE} atlas cells outside the "
            f"tidal atlas {self.path} ({self.name}: cell centres {lon_extent}, lat {self.lat[0]:g}..{self.lat[-1]:g}, "
            f"cells {step_x:g} x {step_y:g} degrees); the farthest, lon {lon[far]:.4f}, lat {lat[far]:.4f}, is "
            f"{km[far]:.0f} km outside. The atlas does not cover the open boundary: use one that does"
        )

    def sample(self, lon, lat):
        """Complex elevation at the points, a mask of those that used the nearest ocean cell, and its distance (km).

        The distance is 0 where the bilinear stencil was used.
        """
        x = self._unwrap(lon)
        margin = 2
        lo_i = self._column(x.min()) - margin
        hi_i = self._column(x.max()) + margin
        lo_j = int(np.searchsorted(self.lat, lat.min())) - margin
        hi_j = int(np.searchsorted(self.lat, lat.max())) + margin
        step_x, step_y = self.steps
        while True:
            window = self._load(lo_i, hi_i, lo_j, hi_j)
            if not window["ocean"].any():
                if window["whole"]:
                    raise MeshFormatError(f"{self.path}: {self.name} has no ocean (non-zero) cell at all")
                grow_x, grow_y = max(len(self.lon) // 8, 4), max(len(self.lat) // 8, 4)
            else:
                xw = x
                if self.periodic:
                    xw = window["lon"][0] + np.mod(x - window["lon"][0], 360.0)
                values, ok = _bilinear(window["lon"], window["lat"], window["field"], window["ocean"], xw, lat)
                if ok.all():
                    return values, ~ok, np.zeros(len(x))
                near, distance = _nearest(window, xw[~ok], lat[~ok])
                reach = _reach(window, xw[~ok], lat[~ok])
                if window["whole"] or np.all(distance <= reach):
                    values[~ok] = near
                    distance_km = np.zeros(len(x))
                    distance_km[~ok] = np.deg2rad(distance) * EARTH_RADIUS / 1000.0
                    return values, ~ok, distance_km
                # the nearest ocean cell may lie outside the window: widen it by the distance found
                needed = float(np.max(distance - reach))
                grow_x = int(np.ceil(needed / (step_x * max(np.cos(np.deg2rad(np.max(np.abs(lat)))), 0.05)))) + 2
                grow_y = int(np.ceil(needed / step_y)) + 2
            lo_i, hi_i, lo_j, hi_j = window["bounds"]
            lo_i, hi_i, lo_j, hi_j = lo_i - grow_x, hi_i + grow_x, lo_j - grow_y, hi_j + grow_y

    def _unwrap(self, lon):
        """Point longitudes shifted by whole turns to lie nearest the grid's centre.

        On a global grid, to lie in one run east from the end of their
        widest gap instead: points on both sides of the grid's seam (0 on a
        0..360 atlas) then need only the columns around it, not the whole
        turn.
        """
        centre = 0.5 * (self.lon[0] + self.lon[-1])
        x = centre + np.mod(lon - centre + 180.0, 360.0) - 180.0
        if not self.periodic or len(x) < 2:
            return x
        ordered = np.sort(x)
        gaps = np.diff(ordered, append=ordered[0] + 360.0)
        start = ordered[(int(np.argmax(gaps)) + 1) % len(ordered)]
        return start + np.mod(x - start, 360.0)

    def _column(self, x):
        """Where longitude ``x`` falls among the columns (``np.searchsorted``), counting on past a global grid's end."""
        if not self.periodic:
            return int(np.searchsorted(self.lon, x))
        turns = int(np.floor((x - self.lon[0]) / 360.0))
        return int(np.searchsorted(self.lon, x - 360.0 * turns)) + len(self.lon) * turns


def _bilinear(grid_lon, grid_lat, field, ocean, x, y):
    """Bilinear values on cell centres and whether the stencil was all ocean and inside the grid."""
    values = np.zeros(len(x), dtype=np.complex128)
    if len(grid_lon) < 2 or len(grid_lat) < 2:
        return values, np.zeros(len(x), dtype=bool)
    inside = (x >= grid_lon[0]) & (x <= grid_lon[-1]) & (y >= grid_lat[0]) & (y <= grid_lat[-1])
    i = np.clip(np.searchsorted(grid_lon, x, side="right") - 1, 0, len(grid_lon) - 2)
    j = np.clip(np.searchsorted(grid_lat, y, side="right") - 1, 0, len(grid_lat) - 2)
    tx = np.clip((x - grid_lon[i]) / (grid_lon[i + 1] - grid_lon[i]), 0.0, 1.0)
    ty = np.clip((y - grid_lat[j]) / (grid_lat[j + 1] - grid_lat[j]), 0.0, 1.0)
    ok = inside.copy()
    for row, col, weight in (
        (j, i, (1 - tx) * (1 - ty)),
        (j, i + 1, tx * (1 - ty)),
        (j + 1, i, (1 - tx) * ty),
        (j + 1, i + 1, tx * ty),
    ):
        wet = ocean[row, col]
        ok &= wet
        values += weight * np.where(wet, field[row, col], 0.0)
    return values, ok


def _reach(window, x, y):
    """Angular distance (degrees) from each point to the nearest side of the window that is not the grid's end."""
    lon, lat = window["lon"], window["lat"]
    west, east, south, north = window["edge"]
    scale = np.maximum(np.cos(np.deg2rad(y)), 1e-3)
    sides = [
        np.inf if west else (x - lon[0]) * scale,
        np.inf if east else (lon[-1] - x) * scale,
        np.inf if south else y - lat[0],
        np.inf if north else lat[-1] - y,
    ]
    return np.maximum(np.min(np.broadcast_arrays(*sides), axis=0), 0.0)


def _unit_vectors(lon, lat):
    lon, lat = np.deg2rad(lon), np.deg2rad(lat)
    return np.column_stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])


def _nearest(window, x, y):
    """Value of the nearest ocean cell centre and its angular distance (degrees) from each point."""
    from scipy.spatial import cKDTree

    rows, cols = np.nonzero(window["ocean"])
    tree = cKDTree(_unit_vectors(window["lon"][cols], window["lat"][rows]))
    chord, index = tree.query(_unit_vectors(x, y))
    distance = np.rad2deg(2.0 * np.arcsin(np.clip(chord / 2.0, 0.0, 1.0)))
    return window["field"][rows[index], cols[index]], distance
