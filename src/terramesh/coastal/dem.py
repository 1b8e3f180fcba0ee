"""Digital elevation models (guide section 2.4): structured longitude-latitude grids of elevation.

A :class:`DEM` holds elevation in metres, positive up (land above zero, sea
floor below), on an evenly spaced WGS84 longitude-latitude grid, indexed
``[ix, iy]`` like :class:`terramesh.sizing.SizeGrid`. :func:`read_dem` reads
the part of a NetCDF or GeoTIFF file that covers a box, whatever the file's
latitude order, longitude convention (-180..180 or 0..360) or dimension
order.
"""

import logging
import operator
import os
import pathlib
import re

import numpy as np

from .._kernels import physical_memory, read_only
from .._kernels.raster import bilinear_lonlat, bilinear_lonlat_grid
from ..errors import GeometryError, MeshFormatError, SizingError, TerrameshError, warn_user
from ..readers.netcdf import check_classic_size
from .grid import as_lonlat_box
from .projection import EARTH_RADIUS

logger = logging.getLogger("terramesh.coastal")

__all__ = ["DEM", "read_dem"]

_METRES_PER_DEGREE = EARTH_RADIUS * np.pi / 180.0

SHORT_OF_THE_BBOX = "less than the bbox"  # the partial-coverage warning's words, by which a caller mutes it
_LON_NAMES = ("lon", "longitude", "long", "lons", "longitudes")
_LAT_NAMES = ("lat", "latitude", "lats", "latitudes")
# a variable of these names, or of a CF standard name "sea_floor_depth...", holds depths (positive down)
# unless its ``positive`` attribute says "up": ocean models' bathymetry files seldom carry that attribute
_DEPTH_NAMES = ("depth", "h", "dep", "deptho", "bathymetry_depth", "sea_floor_depth")
_ELEVATION_NAMES = ("z", "elevation", "band1", "elev", "height", "topo", "topography", "bathymetry", "altitude")

_READ_BYTES_PER_NODE = 32
"""Bytes of memory a DEM node takes at the peak of reading it (measured: 20-24 from NetCDF, 26 from a GeoTIFF).

The stored values, their mask, the float64 copy, the copy with the
missing cells filled and the one in metres overlap; the DEM keeps 8.
"""

_SPACING_RTOL = 1e-3
"""Largest deviation of a coordinate step from the mean step, relative to it, for an axis given as arrays."""

_FILE_SPACING_RTOL = 0.05
"""The same for coordinates read from a file, which are often float32 (about 1e-5 degrees of rounding)."""

_GEOTIFF_SUFFIXES = (".tif", ".tiff", ".gtiff", ".geotiff")

_LOWEST_ELEVATION = -11_500.0
"""Lowest elevation a DEM may hold, metres: the Challenger Deep (about -10,935 m) with room for datums and noise."""

_HIGHEST_ELEVATION = 9_000.0
"""Highest elevation a DEM may hold, metres: Everest (8,849 m) with the same room.

Beyond either lies no place on Earth: an undeclared fill value (-32768,
-9999, 1e30) read as a height, or heights not in metres. Read as they are,
a coastal build gave depths of 29 km there, silently.
"""

_IN_RANGE_FILL = -9999.0
"""The commonest fill value, which lies within Earth's range: refused unless the grid reaches a trench."""

_TRENCH_ELEVATION = -9_000.0
"""A grid with cells below this (the deepest trenches only) may hold -9999 as real data."""

_METRES_PER_UNIT = {
    **dict.fromkeys(("m", "metre", "metres", "meter", "meters"), 1.0),
    **dict.fromkeys(("km", "kilometre", "kilometres", "kilometer", "kilometers"), 1000.0),
    **dict.fromkeys(("cm", "centimetre", "centimetres", "centimeter", "centimeters"), 0.01),
    **dict.fromkeys(("ft", "foot", "feet", "international foot", "international feet"), 0.3048),
    **dict.fromkeys(
        ("us survey foot", "us survey feet", "survey foot", "survey feet", "ftus", "us ft"), 1200.0 / 3937.0
    ),
}
"""Metres in one of each length unit a ``units`` attribute may name (normalised by :func:`_unit_name`)."""

_RADIAN_UNITS = ("rad", "radian", "radians")


def _regular_axis(values, name, *, rtol):
    """Check a strictly increasing, evenly spaced axis; return it exactly regular, with its step."""
    try:
        values = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{name} must be an array of numbers") from None
    if values.ndim != 1 or values.size < 2:
        raise GeometryError(f"{name} must be a 1-D array of at least 2 values, got shape {values.shape}")
    if not np.all(np.isfinite(values)):
        raise GeometryError(f"{name} has non-finite values")
    steps = np.diff(values)
    if np.any(steps <= 0):
        raise GeometryError(f"{name} must be strictly increasing")
    step = (values[-1] - values[0]) / (values.size - 1)
    regular = values[0] + step * np.arange(values.size)
    # positions, not steps: steps each within the tolerance but leaning one way add up (4 % long over half an
    # axis and 4 % short over the other put its middle 20 cells off, and the DEM read there 22 km away)
    offset = np.abs(values - regular)
    if np.max(offset) > rtol * step:
        worst = int(np.argmax(offset))
        raise GeometryError(
            f"{name} is not evenly spaced: value {worst} is {values[worst]:.9g}, {offset[worst] / step:.3g} steps "
            f"off the regular axis from {values[0]:.9g} to {values[-1]:.9g} (steps {steps.min():.9g}.."
            f"{steps.max():.9g} degrees; a DEM must be a regular grid)"
        )
    return regular, float(step)


def _check_earth_range(elevation, what):
    """Refuse finite elevations no place on Earth has, and lone -9999s; the message names the usual value."""
    # NaN compares False and infinities are missing cells: both are left to _fill_missing
    wrong = np.isfinite(elevation) & ((elevation < _LOWEST_ELEVATION) | (elevation > _HIGHEST_ELEVATION))
    reasons = [f"outside Earth's range {_LOWEST_ELEVATION:,.0f}..{_HIGHEST_ELEVATION:,.0f} m"] if wrong.any() else []
    # -9999, the commonest fill value, lies within that range: it is a fill value unless the grid reaches a trench
    # that deep (then real data may hit it exactly); a coastal grid with fill holes has no other cell below -9,000 m
    lone = elevation == _IN_RANGE_FILL
    if lone.any():
        trench = (elevation < _TRENCH_ELEVATION) & (elevation >= _LOWEST_ELEVATION) & ~lone
        if not trench.any():
            wrong |= lone
            reasons.append(f"exactly {_IN_RANGE_FILL:g} m with no other cell below {_TRENCH_ELEVATION:,.0f} m")
    count = int(np.count_nonzero(wrong))
    if count == 0:
        return
    values, counts = np.unique(elevation[wrong], return_counts=True)
    common = int(np.argmax(counts))
    advice = (
        "an undeclared fill value? Declare it (the NetCDF variable's _FillValue or missing_value attribute, the"
        " GeoTIFF band's nodata) or set those cells to NaN; if the elevations are not in metres, give the NetCDF"
        " variable a units attribute"
    )
    if values[0] > _HIGHEST_ELEVATION and values[-1] <= -_LOWEST_ELEVATION:
        # just past the highest peak, as deep as the deepest trench: a depth grid (positive down) read as heights
        advice += '; if they are depths (positive down), give the variable positive = "down" or negate them'
    found = (
        f"all {values[0]:g} m"
        if values.size == 1
        else f"{values[0]:g}..{values[-1]:g} m; most often {values[common]:g}, in {counts[common]:,} cells"
    )
    raise GeometryError(
        f"{what}: {count:,} of {elevation.size:,} cells have elevations {' or '.join(reasons)} ({found}): {advice}"
    )


def _unit_name(units):
    """A ``units`` attribute in one spelling: lower case, ``_`` and ``-`` as spaces, single spaces."""
    return " ".join(re.sub(r"[_\-]", " ", str(units)).lower().split())


def _metres_per_unit(units, what):
    """Metres in one ``units`` (a NetCDF attribute, a GeoTIFF band's unit); none given means metres."""
    name = _unit_name("" if units is None else units)
    if not name:
        return 1.0
    if name not in _METRES_PER_UNIT:  # "meters above sea level", "m (WGS84)": the unit, then words about it
        name = re.split(r"[\s,;(]", name)[0]
    if name not in _METRES_PER_UNIT:
        raise MeshFormatError(
            f"{what} has elevations in units {units!r}, not a length unit terramesh knows (m, km, cm, ft,"
            " US survey foot): correct the units attribute (NetCDF: ncatted -a units,<variable>,o,c,m file.nc)"
            " or convert the data to metres"
        )
    return _METRES_PER_UNIT[name]


def _check_degrees(variable, name, path):
    """Refuse a longitude or latitude coordinate whose ``units`` say radians or a length (a projected grid)."""
    units = getattr(variable, "units", None)
    unit = _unit_name("" if units is None else units)
    if unit in _RADIAN_UNITS:
        raise GeometryError(
            f"DEM {path.name}: the coordinate {name!r} is in {units!r}, not degrees: a DEM must be WGS84"
            " longitude-latitude in degrees (convert it: degrees = radians * 180 / pi)"
        )
    if unit in _METRES_PER_UNIT:
        raise GeometryError(
            f"DEM {path.name}: the coordinate {name!r} is in {units!r}, a projected grid, not degrees: reproject"
            " it to WGS84 longitude-latitude (e.g. gdalwarp -t_srs EPSG:4326)"
        )


def _band_number(band):
    """``band`` as a GeoTIFF band number (1-based), checked before the file is opened."""
    try:
        number = None if isinstance(band, (bool, np.bool_)) else operator.index(band)  # True is not band 1
    except TypeError:
        number = None
    if number is None or number < 1:
        raise GeometryError(f"band must be a positive integer (GeoTIFF bands count from 1), got {band!r}")
    return number


def _ground_spacing(dx, dy, lat):
    """Ground metres of a (dx, dy) degree cell at latitude ``lat`` (degrees)."""
    return dx * _METRES_PER_DEGREE * np.cos(np.radians(lat)), dy * _METRES_PER_DEGREE


def _fill_missing(elevation, spacing, what):
    """Fill non-finite cells in place from the nearest valid cell (on the ground), with a warning."""
    missing = ~np.isfinite(elevation)
    count = int(np.count_nonzero(missing))
    if count == 0:
        return
    if count == elevation.size:
        raise GeometryError(f"{what} has no valid elevation: all {count:,} cells are missing (NaN or fill value)")
    from scipy import ndimage

    nearest = ndimage.distance_transform_edt(missing, sampling=spacing, return_distances=False, return_indices=True)
    elevation[missing] = elevation[tuple(index[missing] for index in nearest)]
    warn_user(
        f"{what}: {count:,} of {elevation.size:,} cells ({100.0 * count / elevation.size:.3g} %) have no elevation;"
        " filled from the nearest valid cell",
    )


class DEM:
    """Elevation on an evenly spaced longitude-latitude grid (WGS84), metres, positive up.

    Parameters
    ----------
    lon : array_like, shape (nx,)
        Longitudes of the columns, degrees, strictly increasing and evenly
        spaced (to 0.1 % of the step; they are stored exactly regular).
    lat : array_like, shape (ny,)
        Latitudes of the rows, degrees, the same; ``dy`` may differ from ``dx``.
    elevation : array_like, shape (nx, ny)
        Height above the vertical datum, metres, positive up (land > 0, sea
        floor < 0), indexed ``[ix, iy]`` (NumPy ``indexing="ij"``). It is
        copied. Missing cells (NaN, inf) are filled from the nearest valid
        cell, with a :class:`~terramesh.errors.TerrameshWarning`. Finite
        values must lie within Earth's range, -11,500..9,000 m.
    source : str, optional
        Where the data came from, for messages (a file name).

    Attributes
    ----------
    lon, lat : ndarray, shape (nx,), (ny,)
        Read-only grid coordinates, degrees.
    elevation : ndarray, shape (nx, ny)
        Read-only float64 elevation, metres, positive up.
    dx, dy : float
        Grid steps, degrees.
    sign_note : str or None
        How :func:`read_dem` chose the values' sign (for example "... was
        read as depths (positive down) and negated: its name, as it has no
        positive attribute"); None for a DEM made from arrays.
    file_positive : {"up", "down"} or None
        The sign the file's values were read with: ``"down"`` for depths
        (negated), ``"up"`` for elevation; None for a DEM made from arrays.

    Raises
    ------
    GeometryError
        If the axes are not increasing and evenly spaced, latitudes are
        outside -90..90, the shapes disagree, no cell has a value, or an
        elevation is outside Earth's range (an undeclared fill value such as
        -32768 or -9999, or heights not in metres; the message gives the
        count and the most common such value).

    See Also
    --------
    read_dem : read a DEM from a NetCDF or GeoTIFF file.

    Examples
    --------
    >>> import numpy as np
    >>> lon = np.linspace(-94.0, -93.8, 21)
    >>> lat = np.linspace(29.7, 29.9, 11)
    >>> lon2, lat2 = np.meshgrid(lon, lat, indexing="ij")
    >>> dem = DEM(lon, lat, 100.0 * (lat2 - 29.8))
    >>> dem.shape, dem.bbox
    ((21, 11), (-94.0, -93.8, 29.7, 29.9))
    >>> [round(float(v), 6) for v in dem.sample([-93.9, -93.9], [29.75, 29.85])]
    [-5.0, 5.0]
    """

    def __init__(self, lon, lat, elevation, *, source=None):
        self._setup(lon, lat, elevation, source=source, rtol=_SPACING_RTOL)

    def _setup(self, lon, lat, elevation, *, source, rtol, sign_note=None, file_positive=None):
        self.source = None if source is None else str(source)
        self.sign_note, self.file_positive = sign_note, file_positive
        what = f"DEM {self.source}" if self.source else "DEM"
        lon, self.dx = _regular_axis(lon, "DEM longitudes", rtol=rtol)
        lat, self.dy = _regular_axis(lat, "DEM latitudes", rtol=rtol)
        if lat[0] < -90.0 - 1e-9 or lat[-1] > 90.0 + 1e-9:
            raise GeometryError(
                f"{what} latitudes {lat[0]:g}..{lat[-1]:g} are outside -90..90: the grid is not in degrees"
                " (reproject it to WGS84 longitude-latitude, e.g. gdalwarp -t_srs EPSG:4326)"
            )
        if lon[-1] - lon[0] > 360.0 + 1.5 * self.dx or lon[0] < -360.0 or lon[-1] > 720.0:
            raise GeometryError(
                f"{what} longitudes {lon[0]:g}..{lon[-1]:g} do not fit one turn of the globe:"
                " the grid is not in degrees (reproject it to WGS84, e.g. gdalwarp -t_srs EPSG:4326)"
            )
        try:
            elevation = np.array(elevation, dtype=np.float64)
        except (TypeError, ValueError):
            raise GeometryError(f"{what} elevation must be an array of numbers") from None
        if elevation.shape != (lon.size, lat.size):
            hint = (
                " (it looks like (lat, lon) order: pass elevation.T)" if elevation.shape == (lat.size, lon.size) else ""
            )
            raise GeometryError(
                f"{what} elevation has shape {elevation.shape}, expected (nx, ny) = ({lon.size}, {lat.size}),"
                f" indexed [ix, iy]{hint}"
            )
        _check_earth_range(elevation, what)
        mid = 0.5 * (lat[0] + lat[-1])
        _fill_missing(elevation, _ground_spacing(self.dx, self.dy, mid), what)
        for array in (lon, lat, elevation):
            array.flags.writeable = False
        self.lon, self.lat, self.elevation = lon, lat, np.ascontiguousarray(elevation)

    @classmethod
    def read(cls, path, bbox=None, *, margin=3, variable=None, band=1, positive=None):
        """Read the part of a NetCDF or GeoTIFF DEM that covers ``bbox``.

        See :func:`read_dem` for the parameters.

        Examples
        --------
        >>> import os, tempfile, netCDF4, numpy as np
        >>> folder = tempfile.mkdtemp()
        >>> path = os.path.join(folder, "tiny.nc")
        >>> with netCDF4.Dataset(path, "w") as out:
        ...     _ = out.createDimension("lat", 3), out.createDimension("lon", 4)
        ...     out.createVariable("lat", "f8", ("lat",))[:] = [31.0, 30.0, 29.0]
        ...     out.createVariable("lon", "f8", ("lon",))[:] = [265.0, 266.0, 267.0, 268.0]
        ...     out.createVariable("z", "f4", ("lat", "lon"))[:] = np.arange(12.0).reshape(3, 4)
        >>> dem = DEM.read(path, (-94.5, -92.5, 29.0, 31.0))
        >>> dem.bbox
        (-95.0, -92.0, 29.0, 31.0)
        >>> dem.elevation[:, 0].tolist()
        [8.0, 9.0, 10.0, 11.0]
        """
        return _read(cls, path, bbox, margin=margin, variable=variable, band=band, positive=positive)

    @property
    def shape(self):
        """``(nx, ny)``: the elevation array's shape."""
        return self.elevation.shape

    @property
    def bbox(self):
        """``(lon_min, lon_max, lat_min, lat_max)`` of the grid nodes, degrees (the guide's order)."""
        return float(self.lon[0]), float(self.lon[-1]), float(self.lat[0]), float(self.lat[-1])

    @property
    def resolution(self):
        """Ground size ``(dx, dy)`` of a cell at the centre latitude, metres."""
        east, north = _ground_spacing(self.dx, self.dy, 0.5 * (self.lat[0] + self.lat[-1]))
        return float(east), float(north)

    @property
    def depth(self):
        """Depth below the datum, metres, positive down (ADCIRC's sign): ``-elevation``, a new array."""
        return -self.elevation

    def sample(self, lon, lat):
        """Bilinear interpolation of the elevation at points.

        Parameters
        ----------
        lon, lat : array_like
            Point coordinates, degrees, broadcast against each other. A
            longitude a whole turn away from the grid is wrapped onto it;
            on a grid all the way round, one between its last column and
            the first's next turn is interpolated between the two.

        Returns
        -------
        ndarray
            Elevation, metres, positive up, of the broadcast shape. Outside
            the grid, the value at the nearest edge; NaN where a coordinate
            is NaN.

        Examples
        --------
        >>> import numpy as np
        >>> dem = DEM([0.0, 1.0], [0.0, 2.0], [[0.0, 2.0], [1.0, 3.0]])
        >>> dem.sample([0.5, 5.0, 360.5], [1.0, 1.0, 1.0]).tolist()
        [1.5, 2.0, 1.5]
        """
        lon, lat = np.broadcast_arrays(np.asarray(lon, dtype=np.float64), np.asarray(lat, dtype=np.float64))
        value = bilinear_lonlat(
            *self._kernel_grid(), np.ascontiguousarray(lon).ravel(), np.ascontiguousarray(lat).ravel()
        )
        return value.reshape(lon.shape)

    def sample_grid(self, lon, lat):
        """:meth:`sample` at every pair of ``lon`` and ``lat``: the elevation on a grid of those axes.

        Parameters
        ----------
        lon, lat : array_like, 1-D
            The grid's longitudes and latitudes, degrees.

        Returns
        -------
        ndarray, shape (len(lon), len(lat))
            Elevation, metres, positive up, indexed ``[lon, lat]``: what
            ``sample`` gives for ``np.meshgrid(lon, lat, indexing="ij")``,
            without making those two arrays.

        Raises
        ------
        GeometryError
            If an axis is not 1-D.

        Examples
        --------
        >>> dem = DEM([0.0, 1.0], [0.0, 2.0], [[0.0, 2.0], [1.0, 3.0]])
        >>> dem.sample_grid([0.0, 0.5], [0.0, 1.0, 2.0]).tolist()
        [[0.0, 1.0, 2.0], [0.5, 1.5, 2.5]]
        """
        lon = np.ascontiguousarray(lon, dtype=np.float64)
        lat = np.ascontiguousarray(lat, dtype=np.float64)
        if lon.ndim != 1 or lat.ndim != 1:
            raise GeometryError(f"sample_grid takes 1-D axes, got lon {lon.shape} and lat {lat.shape}: use sample")
        return bilinear_lonlat_grid(*self._kernel_grid(), lon, lat)

    def _kernel_grid(self):
        """The grid as the interpolation kernels take it: ``(elevation, origin, spacing, last longitude)``."""
        elevation = read_only(np.ascontiguousarray(self.elevation, dtype=np.float64))
        return elevation, np.array([self.lon[0], self.lat[0]]), np.array([self.dx, self.dy]), float(self.lon[-1])

    def sign_advice(self):
        """What to do about a DEM whose sea looks like land: its sign is probably the wrong way round."""
        if self.file_positive is None:
            return (
                "a DEM is elevation, positive up (the guide's §2.4); if it holds depths (positive down), negate it:"
                " tm.coastal.DEM(dem.lon, dem.lat, -dem.elevation)"
            )
        other = "up" if self.file_positive == "down" else "down"
        return (
            f"{self.sign_note}; if that is wrong, read it with tm.coastal.read_dem(path, bbox, positive={other!r})"
            f" (command line: --dem-positive {other})"
        )

    def __repr__(self):
        lon_min, lon_max, lat_min, lat_max = self.bbox
        return (
            f"DEM({self.shape[0]} x {self.shape[1]}, lon {lon_min:g}..{lon_max:g}, lat {lat_min:g}..{lat_max:g},"
            f" elevation {self.elevation.min():g}..{self.elevation.max():g} m)"
        )


def read_dem(path, bbox=None, *, margin=3, variable=None, band=1, positive=None):
    """Read the part of a DEM file that covers a box.

    Parameters
    ----------
    path : str or os.PathLike
        A NetCDF file (``.nc``, ``.grd``, ...: any name not ending in
        ``.tif``, ``.tiff``, ``.gtiff`` or ``.geotiff``) with 1-D longitude and latitude coordinates
        (named lon/lat, x/y or longitude/latitude, any case) and one 2-D
        elevation variable (``z``, ``Band1``, ``elevation``, ...); or a
        GeoTIFF in WGS84 longitude-latitude (needs ``terramesh[geotiff]``).
        The elevation's ``units`` (the NetCDF attribute, the GeoTIFF band's
        unit) may be m, km, cm, ft (international foot) or US survey foot,
        any of their spellings; none means metres.
    bbox : sequence of 4 float, optional
        ``(lon_min, lon_max, lat_min, lat_max)``, degrees, -180..180 or
        0..360 whatever the file uses; a box across the file's longitude
        seam is joined from both ends. Default: the whole file.
    margin : int
        Cells kept beyond the box on each side, so that interpolation near
        its edges needs nothing outside.
    variable : str, optional
        Name of the NetCDF elevation variable, when the file has several 2-D ones.
    band : int
        GeoTIFF band (1-based, a positive integer).
    positive : {None, "up", "down"}
        The values' sign: ``"up"`` for elevation (land above 0), ``"down"``
        for depths (sea floor above 0; they are negated). Default: from the
        file. A NetCDF variable's CF attribute ``positive`` decides; without
        it, a variable whose CF standard name starts with
        ``sea_floor_depth``, or named ``depth``, ``h``, ``dep``, ``deptho``,
        ``bathymetry_depth`` or ``sea_floor_depth``, is read as depths, any
        other as elevation; a GeoTIFF is read as elevation. The choice and
        its reason are logged and kept in :attr:`DEM.sign_note`, and
        :func:`terramesh.coastal.size_function` quotes them when the DEM's
        sea and the shoreline's water disagree.

    Returns
    -------
    DEM
        Ascending longitudes and latitudes; elevation in metres, positive up;
        masked and fill values filled from the nearest valid cell,
        with a :class:`~terramesh.errors.TerrameshWarning` giving the count.
        Only the subset is read from disk.

    Raises
    ------
    FileNotFoundError
        If there is no file at ``path``.
    MeshFormatError
        If the file is truncated, corrupt or has no usable grid, the GeoTIFF
        has no band ``band``, or the elevation's ``units`` is not a length
        unit listed above.
    GeometryError
        If ``path`` is not a path, ``band`` is not a positive integer,
        ``positive`` is not None, "up" or "down",
        ``bbox`` does not overlap the data (the message gives both
        extents), the grid is not evenly spaced degrees (coordinates whose
        ``units`` say radians or a length are refused by name), or an
        elevation is outside Earth's range, -11,500..9,000 m (an undeclared
        fill value: declare it as ``_FillValue`` or ``nodata``).
    SizingError
        If reading the box (the whole file without one) needs more memory
        than is free (about 32 bytes a node at the peak), before reading.
    ImportError
        If a GeoTIFF is given and rasterio is not installed.

    Warns
    -----
    TerrameshWarning
        If missing cells were filled, or the data cover less than the box;
        and for a GeoTIFF with no CRS, read as WGS84 longitude-latitude.

    Examples
    --------
    >>> import os, tempfile, netCDF4, numpy as np
    >>> path = os.path.join(tempfile.mkdtemp(), "ramp.nc")
    >>> with netCDF4.Dataset(path, "w") as out:
    ...     _ = out.createDimension("x", 5), out.createDimension("y", 4)
    ...     out.createVariable("x", "f8", ("x",))[:] = np.arange(5.0)
    ...     out.createVariable("y", "f8", ("y",))[:] = np.arange(4.0)
    ...     out.createVariable("elevation", "f4", ("y", "x"))[:] = np.arange(20.0).reshape(4, 5) - 10
    >>> dem = read_dem(path, (1.0, 2.0, 1.0, 2.0), margin=1)
    >>> dem.bbox, dem.shape
    ((0.0, 3.0, 0.0, 3.0), (4, 4))
    """
    return _read(DEM, path, bbox, margin=margin, variable=variable, band=band, positive=positive)


# ----------------------------------------------------------------------------------------------------------------
# reading


def _read(cls, path, bbox, *, margin, variable, band, positive):
    # coastal.build and interpolate_bathymetry pass their dem argument here: anything else than a path (an
    # array, a number) failed inside os.fspath with a TypeError about str or bytes
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise GeometryError(
            f"dem must be a terramesh.coastal.DEM or a path to a NetCDF/GeoTIFF file, got {type(path).__name__}"
        )
    path = pathlib.Path(os.fsdecode(path))
    if not path.is_file():
        raise FileNotFoundError(f"DEM file not found: {path}")
    try:
        margin = int(margin)
    except (TypeError, ValueError):
        raise GeometryError(f"margin must be a whole number of cells, got {margin!r}") from None
    if margin < 0:
        raise GeometryError(f"margin must be >= 0 cells, got {margin}")
    band = _band_number(band)
    positive = _checked_positive(positive)
    box = None if bbox is None else as_lonlat_box(bbox)
    if path.suffix.lower() in _GEOTIFF_SUFFIXES:
        lon, lat, elevation, sign, note = _read_geotiff(path, box, margin, band, positive)
    else:
        lon, lat, elevation, sign, note = _read_netcdf(path, box, margin, variable, positive)
    logger.info("%s", note)
    dem = cls.__new__(cls)
    positive = "down" if sign < 0 else "up"
    dem._setup(lon, lat, elevation, source=path.name, rtol=_FILE_SPACING_RTOL, sign_note=note, file_positive=positive)
    if box is not None:
        check_dem_cover(dem, box)
    return dem


def check_dem_cover(dem, box):
    """Refuse a DEM apart from ``box``, and warn where it covers less of it.

    ``box`` is ``(lon_min, lon_max, lat_min, lat_max)``, degrees, in either
    longitude convention. A DEM read for a box is checked as it is read; one
    made or read elsewhere is checked here by whatever takes it with a box
    (:func:`~terramesh.coastal.size_function`), since sampling it outside
    gives its nearest edge value: a mesh elsewhere would get one depth
    everywhere.

    Raises
    ------
    GeometryError
        Where the DEM and the box do not overlap.
    """
    lon_min, lon_max, lat_min, lat_max = dem.bbox
    what = f"DEM {dem.source}" if dem.source else "DEM"
    extent = f"lon {lon_min:g}..{lon_max:g}, lat {lat_min:g}..{lat_max:g}"
    round_the_globe = lon_max - lon_min >= 360.0 - 1.5 * dem.dx  # every longitude, wrapped (see DEM.sample)
    turns = [0.0] if round_the_globe else [
        shift for shift in (0.0, -360.0, 360.0)
        if box[0] + shift <= lon_max + 0.5 * dem.dx and box[1] + shift >= lon_min - 0.5 * dem.dx
    ]  # fmt: skip
    if not turns or lat_min > box[3] + 0.5 * dem.dy or lat_max < box[2] - 0.5 * dem.dy:
        raise GeometryError(f"bbox {tuple(box)} does not overlap the {what} ({extent})")
    west, east = box[0] + turns[0], box[1] + turns[0]
    short_lon = not round_the_globe and (lon_min > west + dem.dx or lon_max < east - dem.dx)
    if short_lon or lat_min > box[2] + dem.dy or lat_max < box[3] - dem.dy:
        warn_user(
            f"{what} covers {extent}, {SHORT_OF_THE_BBOX} {tuple(box)}; sampling outside it gives the nearest edge "
            "value"
        )


def _axis_range(first, step, size, low, high, margin):
    """Index range ``[i0, i1)`` of the regular axis nodes within ``[low, high]``, widened by ``margin`` nodes."""
    i0 = int(np.floor((low - first) / step + 1e-9)) - margin
    i1 = int(np.ceil((high - first) / step - 1e-9)) + 1 + margin
    return max(i0, 0), min(i1, size)


def _subset_plan(lon, lat, box, margin, path):
    """Which rows and column pieces of a file grid to read for ``box``.

    ``lon`` and ``lat`` are the file's coordinates in file order. Returns
    ``rows`` (a slice in file order), ``flip_rows``, and ``pieces``: a list
    of ``(columns slice in file order, flip, shift)`` whose longitudes plus
    ``shift`` degrees, joined in order, make an increasing axis.
    """
    lon = np.asarray(lon, dtype=np.float64)
    lat = np.asarray(lat, dtype=np.float64)
    if lon.ndim != 1 or lat.ndim != 1 or lon.size < 2 or lat.size < 2:
        raise MeshFormatError(f"{path}: longitude and latitude must be 1-D with at least 2 values each")
    flip_x, flip_y = bool(lon[-1] < lon[0]), bool(lat[-1] < lat[0])
    x = lon[::-1] if flip_x else lon
    y = lat[::-1] if flip_y else lat
    x, dx = _regular_axis(x, f"{path.name} longitudes", rtol=_FILE_SPACING_RTOL)
    y, dy = _regular_axis(y, f"{path.name} latitudes", rtol=_FILE_SPACING_RTOL)

    def file_slice(start, stop, size, flip):
        return slice(size - stop, size - start) if flip else slice(start, stop)

    if box is None:
        return file_slice(0, y.size, y.size, flip_y), flip_y, [(file_slice(0, x.size, x.size, flip_x), flip_x, 0.0)]
    lon_min, lon_max, lat_min, lat_max = box
    extent = f"lon {x[0]:g}..{x[-1]:g}, lat {y[0]:g}..{y[-1]:g}"
    if x[0] < -360.0 or x[-1] > 720.0 or y[0] < -90.0 - 1e-9 or y[-1] > 90.0 + 1e-9:  # before "no overlap"
        raise GeometryError(
            f"DEM {path.name} ({extent}) is not in degrees: reproject it to WGS84 longitude-latitude"
            " (e.g. gdalwarp -t_srs EPSG:4326)"
        )
    pieces = []
    for shift in (-360.0, 0.0, 360.0):
        if x[0] + shift <= lon_max + 0.5 * dx and x[-1] + shift >= lon_min - 0.5 * dx:
            i0, i1 = _axis_range(x[0], dx, x.size, lon_min - shift, lon_max - shift, margin)
            pieces.append([i0, i1, shift])
    if not pieces or y[0] > lat_max + 0.5 * dy or y[-1] < lat_min - 0.5 * dy:
        raise GeometryError(f"bbox {box} does not overlap the DEM {path.name} ({extent})")
    j0, j1 = _axis_range(y[0], dy, y.size, lat_min, lat_max, margin)
    pieces.sort(key=lambda piece: x[piece[0]] + piece[2])
    joined = [pieces[0]]
    for i0, i1, shift in pieces[1:]:
        last_i0, last_i1, last_shift = joined[-1]
        last = x[last_i1 - 1] + last_shift
        while i0 < i1 and x[i0] + shift <= last + 0.5 * dx:
            i0 += 1  # the same meridian at both ends of a global grid (0 and 360)
        if i0 >= i1:
            continue
        if abs(x[i0] + shift - last - dx) > _FILE_SPACING_RTOL * dx:
            raise GeometryError(
                f"bbox {box} runs over the longitude seam of the DEM {path.name} ({extent}), which does not go"
                " all the way round the globe: there is a gap in the data"
            )
        joined.append([i0, i1, shift])
    # a box all the way round (-180..180, 0..360) takes margin columns at both ends of the join: keep one turn
    turn_end = x[joined[0][0]] + joined[0][2] + 360.0 - 0.5 * dx
    for piece in joined[1:]:
        piece[1] = min(piece[1], max(piece[0], int(np.searchsorted(x + piece[2], turn_end))))
    joined = [piece for piece in joined if piece[0] < piece[1]]
    rows = file_slice(j0, j1, y.size, flip_y)
    return rows, flip_y, [(file_slice(i0, i1, x.size, flip_x), flip_x, shift) for i0, i1, shift in joined]


def available_memory():
    """Bytes of memory free for a read: Linux's ``MemAvailable``, else ``SC_AVPHYS_PAGES``, else the machine's, or None.

    ``MemAvailable`` counts the file cache the kernel gives back; the free
    pages alone (``SC_AVPHYS_PAGES``) are a few percent of a busy
    machine's memory, and would refuse DEMs that fit.
    """
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_AVPHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return physical_memory()


def _check_fits_in_memory(path, lon, lat, rows, pieces, box):
    """Refuse to read ``rows`` x ``pieces`` of the grid when that needs more memory than is free.

    Read without a bbox, a 200,000 x 200,000 grid failed inside netCDF4
    with NumPy's MemoryError ("Unable to allocate 149. GiB"); one a little
    smaller than memory would take the machine down with it.
    """
    ny = rows.stop - rows.start
    nx = sum(columns.stop - columns.start for columns, _, _ in pieces)
    needed = nx * ny * _READ_BYTES_PER_NODE
    memory = available_memory()
    if memory is None or needed <= memory:
        return
    part = "all of it" if box is None else f"the part in the bbox ({ny:,} x {nx:,} nodes)"

    def gib(size):
        return f"{size / 2**30:,.1f}" if size >= 10 * 2**30 else f"{size / 2**30:.3g}"

    raise SizingError(
        f"the DEM {path.name} is a grid of {len(lat):,} x {len(lon):,} nodes (latitude x longitude): reading {part}"
        f" needs about {gib(needed)} GiB, more than the {gib(memory)} GiB of memory free. Give a bbox"
        " to read only the part the mesh needs (read_dem(path, bbox), Shoreline.from_dem(path, bbox)), or use a"
        " coarser file (gdal_translate -tr or gmt grdsample make one)"
    )


def _assemble(lon, lat, rows, flip_rows, pieces, read_block):
    """Read the planned blocks and join them into ascending (lon, lat, elevation[ix, iy])."""
    lon = np.asarray(lon, dtype=np.float64)
    lat = np.asarray(lat, dtype=np.float64)
    blocks, lons = [], []
    for columns, flip, shift in pieces:
        block = read_block(rows, columns)  # (rows, columns), file order
        block = block[:, ::-1] if flip else block
        blocks.append(block)
        piece = lon[columns] + shift
        lons.append(piece[::-1] if flip else piece)
    block = np.concatenate(blocks, axis=1) if len(blocks) > 1 else blocks[0]
    lat_part = lat[rows]
    if flip_rows:
        block, lat_part = block[::-1], lat_part[::-1]
    return np.concatenate(lons), lat_part, block.T


def _coordinate_rank(name, variable, axis):
    """How surely a NetCDF variable is the longitude (``axis="x"``) or latitude (``"y"``): lower is surer, None: not.

    0: a longitude (latitude) name; 1: its CF ``standard_name`` or ``units``
    say so; 2: named ``x`` (``y``), which is as often an index or a
    projected coordinate beside ``lon(x)`` (``lat(y)``).
    """
    names, index, standard, units = (
        (_LON_NAMES, "x", "longitude", "degrees_e") if axis == "x" else (_LAT_NAMES, "y", "latitude", "degrees_n")
    )
    if name.lower() in names:
        return 0
    attributes = {key.lower(): str(variable.getncattr(key)).lower() for key in variable.ncattrs()}
    if attributes.get("standard_name") == standard or attributes.get("units", "").startswith(units):
        return 1
    return 2 if name.lower() == index else None


def _coordinates(dataset, axis, ndim):
    """``(rank, name)`` of the ``ndim``-D variables that may be the ``axis`` coordinate, surest first."""
    found = [
        (_coordinate_rank(name, var, axis), order, name)
        for order, (name, var) in enumerate(dataset.variables.items())
        if var.ndim == ndim
    ]
    return [(rank, name) for rank, _, name in sorted(item for item in found if item[0] is not None)]


def _netcdf_layout(dataset, path, variable):
    """The longitudes and latitudes (1-D, degrees), their dimensions, and the name of the elevation variable.

    The coordinates are the surest pair (:func:`_coordinate_rank`) whose
    dimensions are both dimensions of a variable (of ``variable``, if given):
    ``lon(x)`` and ``lat(y)`` in degrees beside index coordinates ``x`` and
    ``y`` are the grid's, and a stray 1-D ``x(n)`` (stations) is no axis.
    """
    variables = dataset.variables
    # 2-D longitudes and latitudes (not x/y by name alone), which are no elevation
    two_d = [[name for rank, name in _coordinates(dataset, axis, 2) if rank < 2] for axis in "xy"]
    curvilinear = two_d[0] + two_d[1]
    grids = {name: var for name, var in variables.items() if var.ndim >= 2 and name not in curvilinear}
    if variable is not None and variable in grids:
        grids = {variable: grids[variable]}
    lons, lats = _coordinates(dataset, "x", 1), _coordinates(dataset, "y", 1)
    pairs = sorted(
        (lon_rank + lat_rank, lon_name, lat_name)
        for lon_rank, lon_name in lons
        for lat_rank, lat_name in lats
        if variables[lon_name].dimensions[0] != variables[lat_name].dimensions[0]
    )
    pair = next(
        (
            (lon_name, lat_name)
            for _, lon_name, lat_name in pairs
            if any(
                {variables[lon_name].dimensions[0], variables[lat_name].dimensions[0]} <= set(var.dimensions)
                for var in grids.values()
            )
        ),
        None,
    )
    # the 2-D longitudes and latitudes are the grid's with no 1-D pair, or beside x, y (an index, or GMT's degrees
    # without units): read if each is constant along one dimension
    if curvilinear and (
        pair is None
        or any(_coordinate_rank(name, variables[name], axis) == 2 for name, axis in zip(pair, "xy", strict=True))
    ):
        axes = next(
            (
                axes
                for lon_name in two_d[0]
                for lat_name in two_d[1]
                if any(set(variables[lon_name].dimensions) <= set(var.dimensions) for var in grids.values())
                and (axes := _rectilinear(variables[lon_name], variables[lat_name], path)) is not None
            ),
            None,
        )
        if axes is None:
            shown = ", ".join(f"{name}({', '.join(variables[name].dimensions)})" for name in curvilinear)
            raise MeshFormatError(
                f"{path}: its longitudes and latitudes are 2-D ({shown}): a curvilinear grid, which terramesh does"
                " not read; regrid it to a regular longitude-latitude grid with 1-D lon and lat (e.g. gdalwarp"
                " -t_srs EPSG:4326, or cdo remapbil)"
            )
        lon, lat, lon_dim, lat_dim = axes
        return lon, lat, lon_dim, lat_dim, _elevation_variable(path, grids, lon_dim, lat_dim, variable)
    if pair is None:
        if not lons or not lats:
            raise MeshFormatError(
                f"{path}: no 1-D longitude and latitude coordinate variables (looked for lon/lat, x/y,"
                f" longitude/latitude, any case; found {sorted(variables)})"
            )
        shown = ", ".join(f"{name}({variables[name].dimensions[0]})" for _, name in lons + lats)
        what = f"no variable {variable!r} on" if variable is not None else "no 2-D elevation variable on"
        raise MeshFormatError(f"{path}: {what} the grid of any of its coordinates {shown}; found {sorted(variables)}")
    lon_name, lat_name = pair
    lon_dim, lat_dim = variables[lon_name].dimensions[0], variables[lat_name].dimensions[0]
    lon, lat = (_values(variables[name], name, path) for name in pair)
    return lon, lat, lon_dim, lat_dim, _elevation_variable(path, grids, lon_dim, lat_dim, variable)


def _elevation_variable(path, grids, lon_dim, lat_dim, variable):
    """The name of the elevation among the ``grids`` (name: variable, 2-D or more) on ``(lat_dim, lon_dim)``."""
    on_grid = {name: var for name, var in grids.items() if {lon_dim, lat_dim} <= set(var.dimensions)}
    extra = {
        name: [
            (dim, size) for dim, size in zip(var.dimensions, var.shape, strict=True) if dim not in (lon_dim, lat_dim)
        ]
        for name, var in on_grid.items()
    }
    candidates = [name for name in on_grid if all(size == 1 for _, size in extra[name])]
    if variable is not None:
        if variable not in on_grid:
            raise MeshFormatError(
                f"{path}: no 2-D variable {variable!r} on ({lat_dim}, {lon_dim}); found {list(on_grid)}"
            )
        if variable in candidates:
            return variable
        candidates = []  # the one asked for has more dimensions: named below
    if not candidates:
        named = [name for name in on_grid if variable in (None, name)]
        shown = "; ".join(
            f"{name!r} has {', '.join(f'{dim} of size {size}' for dim, size in extra[name] if size != 1)}"
            for name in named
        )
        first = next(dim for dim, size in extra[named[0]] if size != 1)
        raise MeshFormatError(
            f"{path}: no 2-D elevation variable on the ({lat_dim}, {lon_dim}) grid, only ones with more dimensions"
            f" ({shown}): terramesh reads one 2-D field; take one out first (e.g. ncks -d {first},0 {path.name}"
            " out.nc)"
        )
    if len(candidates) > 1:
        preferred = [name for name in candidates if name.lower() in _ELEVATION_NAMES]
        if len(preferred) != 1:
            raise MeshFormatError(
                f"{path}: several 2-D variables on the ({lat_dim}, {lon_dim}) grid, {candidates}; choose the"
                " elevation with variable=NAME, one of them"
            )
        candidates = preferred
    return candidates[0]


def _values(variable, name, path):
    """The values of a 1-D coordinate (float64, NaN where masked), once its units are checked as degrees."""
    _check_degrees(variable, name, path)
    return np.ma.filled(variable[:].astype(np.float64), np.nan)


def _rectilinear(lon, lat, path, rows=1024):
    """``(lon, lat, lon_dim, lat_dim)`` of 2-D NetCDF longitudes and latitudes each constant along one dimension.

    None if they are not (a curvilinear grid), or not on the same two
    dimensions. Read ``rows`` at a time (the 2-D arrays of a global grid
    are gigabytes). The 1-D values are in degrees, NaN where masked.
    """
    dims = lon.dimensions
    if lat.dimensions != dims or len(set(dims)) != 2 or 0 in lon.shape:
        return None
    # longitudes run along the dimension they change most along in the first row and column
    along = 1 if np.ptp(lon[0, :]) >= np.ptp(lon[:, 0]) else 0
    lon_1d = np.ma.filled(lon[0, :] if along else lon[:, 0], np.nan).astype(np.float64)
    lat_1d = np.ma.filled(lat[:, 0] if along else lat[0, :], np.nan).astype(np.float64)
    # a metre on the ground: float32 coordinates of a rectilinear grid repeat exactly, a curvilinear one drifts more
    tolerance = 1e-5
    for start in range(0, lon.shape[0], rows):
        block = slice(start, start + rows)
        expected_lon = lon_1d[None, :] if along else lon_1d[block, None]
        expected_lat = lat_1d[block, None] if along else lat_1d[None, :]
        for values, expected in ((lon[block, :], expected_lon), (lat[block, :], expected_lat)):
            if not np.all(np.abs(np.ma.filled(values, np.nan).astype(np.float64) - expected) <= tolerance):
                return None
    _check_degrees(lon, lon.name, path)
    _check_degrees(lat, lat.name, path)
    return lon_1d, lat_1d, dims[along], dims[1 - along]


def _checked_positive(positive):
    if positive is None:
        return None
    if not isinstance(positive, str) or positive.strip().lower() not in ("up", "down"):
        raise GeometryError(
            f'positive must be "up" (elevation: land above 0) or "down" (depths: sea floor above 0), or None to'
            f" follow the file, got {positive!r}"
        )
    return positive.strip().lower()


def _sign_reading(what, positive_down, why):
    """``(sign, note)``: the factor that makes the values elevation, and how their sign was chosen."""
    reading = "depths (positive down) and negated" if positive_down else "elevation (positive up)"
    return (-1.0 if positive_down else 1.0), f"{what} was read as {reading}: {why}"


def _netcdf_sign(name, variable, positive, path):
    """``(sign, note)`` of a NetCDF grid variable: ``positive`` if given, else its CF attribute, else its names."""
    what = f"{path.name} variable {name!r}"
    if positive is not None:
        return _sign_reading(what, positive == "down", f'positive="{positive}" was given')
    attribute = str(getattr(variable, "positive", "")).strip().lower()
    if attribute in ("up", "down"):
        return _sign_reading(what, attribute == "down", f'its attribute positive = "{attribute}"')
    standard_name = str(getattr(variable, "standard_name", "")).strip().lower()
    if standard_name.startswith("sea_floor_depth"):
        return _sign_reading(what, True, f'its standard_name "{standard_name}"')
    if name.lower() in _DEPTH_NAMES:
        # ocean models' bathymetry files seldom carry the attribute, but elevations are sometimes named so too
        return _sign_reading(what, True, "its name, as it has no positive attribute")
    return _sign_reading(what, False, "it has no positive attribute and no name of depths")


def _read_netcdf(path, box, margin, variable, positive):
    import netCDF4

    try:
        dataset = netCDF4.Dataset(path, "r")
    except OSError as error:
        raise MeshFormatError(f"{path} is not a readable NetCDF file (truncated or corrupt?): {error}") from None
    try:
        with dataset:
            check_classic_size(dataset, path)
            lon, lat, lon_dim, lat_dim, z_name = _netcdf_layout(dataset, path, variable)
            z = dataset[z_name]
            z.set_auto_maskandscale(True)
            sign, note = _netcdf_sign(z_name, z, positive, path)
            scale = sign * _metres_per_unit(getattr(z, "units", None), f"{path.name} variable {z_name!r}")

            def read_block(rows, columns):
                index = tuple(rows if dim == lat_dim else columns if dim == lon_dim else 0 for dim in z.dimensions)
                block = np.ma.filled(np.ma.asarray(z[index]).astype(np.float64), np.nan)
                order = [dim for dim in z.dimensions if dim in (lat_dim, lon_dim)]
                return scale * (block.T if order[0] == lon_dim else block)

            rows, flip_rows, pieces = _subset_plan(lon, lat, box, margin, path)
            _check_fits_in_memory(path, lon, lat, rows, pieces, box)
            return (*_assemble(lon, lat, rows, flip_rows, pieces, read_block), sign, note)
    except TerrameshError:
        raise
    except (OSError, RuntimeError, ValueError, IndexError, KeyError, TypeError) as error:
        raise MeshFormatError(f"cannot read the DEM {path} (truncated or corrupt?): {error}") from None


def _read_geotiff(path, box, margin, band, positive):
    try:
        import rasterio
        from rasterio.windows import Window
    except ImportError:
        raise ImportError(
            f"reading the GeoTIFF {path.name} needs rasterio: pip install 'terramesh[geotiff]'"
            " (or convert it to NetCDF: gdal_translate -of NetCDF in.tif out.nc)"
        ) from None
    try:
        source = rasterio.open(path)
    except rasterio.errors.RasterioError as error:
        raise MeshFormatError(
            f"{path} is not a readable GeoTIFF (truncated or corrupt?): {_with_causes(error)}"
        ) from None
    try:
        with source:
            if source.crs is not None and not source.crs.is_geographic:
                raise GeometryError(
                    f"the GeoTIFF {path.name} is in a projected CRS ({source.crs}); a DEM must be WGS84"
                    " longitude-latitude: gdalwarp -t_srs EPSG:4326"
                )
            if band > source.count:
                raise MeshFormatError(f"{path} has {source.count} band(s), no band {band}")
            what = f"{path.name} band {band}"
            sign, note = _sign_reading(
                what,
                positive == "down",
                "a GeoTIFF band says nothing of its sign" if positive is None else f'positive="{positive}" was given',
            )
            scale = sign * _metres_per_unit(source.units[band - 1], what)
            # a band stored as integers in decimetres, say, carries GDAL's scale and offset (as a NetCDF
            # variable its scale_factor and add_offset, which netCDF4 applies): ignored, depths were 10x
            stored_scale, offset = source.scales[band - 1], source.offsets[band - 1]
            transform = source.transform
            if transform.b != 0 or transform.d != 0:
                raise GeometryError(f"the GeoTIFF {path.name} is rotated or sheared; warp it to a north-up grid")
            lon = transform.c + (np.arange(source.width) + 0.5) * transform.a
            lat = transform.f + (np.arange(source.height) + 0.5) * transform.e

            def read_block(rows, columns):
                window = Window(columns.start, rows.start, columns.stop - columns.start, rows.stop - rows.start)
                block = source.read(band, window=window, masked=True).astype(np.float64)
                return scale * np.ma.filled(block * stored_scale + offset, np.nan)

            rows, flip_rows, pieces = _subset_plan(lon, lat, box, margin, path)
            _check_fits_in_memory(path, lon, lat, rows, pieces, box)
            if source.crs is None:  # taken for WGS84 without a word, as a file in any other CRS would be too
                west, east, south, north = lon.min(), lon.max(), lat.min(), lat.max()
                warn_user(
                    f"the GeoTIFF {path.name} has no CRS: its coordinates (lon {west:g}..{east:g}, lat"
                    f" {south:g}..{north:g}) were taken as WGS84 longitude, latitude. If they are, give it one"
                    f" (gdal_edit.py -a_srs EPSG:4326 {path.name}); if they are in another CRS, warp it"
                    " (gdalwarp -s_srs <its CRS> -t_srs EPSG:4326)"
                )
            return (*_assemble(lon, lat, rows, flip_rows, pieces, read_block), sign, note)
    except TerrameshError:
        raise
    except (rasterio.errors.RasterioError, OSError, ValueError) as error:
        raise MeshFormatError(
            f"cannot read the GeoTIFF {path} (truncated or corrupt?): {_with_causes(error)}"
        ) from None


def _with_causes(error):
    """``error``'s text with those of the exceptions it was raised from, each once.

    rasterio's "Read failed. See previous exception for details." left
    GDAL's own words, where the file broke, in the exception before it.
    """
    texts, seen = [], set()
    while error is not None and id(error) not in seen:
        seen.add(id(error))
        text = str(error).strip()
        if text and "See previous exception" not in text and not any(text in earlier for earlier in texts):
            texts.append(text)
        error = error.__cause__ or error.__context__
    return "; ".join(texts)
