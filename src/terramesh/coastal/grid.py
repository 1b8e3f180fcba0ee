"""The structured grid that coastal size functions are computed on."""

import numpy as np

from ..errors import GeometryError, SizingError, checked_number, warn_user
from ..sizing.grid import SizeGrid
from .projection import MAX_LATITUDE, from_mercator, scale_factor, to_mercator

__all__ = ["GeoGrid", "as_lonlat_box", "MAX_GRID_NODES"]

MAX_GRID_NODES = 200_000_000
"""Largest grid accepted (1.6 GB per float64 field); beyond it a coarser spacing is asked for."""


def as_lonlat_box(bbox):
    """Check a ``(lon_min, lon_max, lat_min, lat_max)`` box (the guide's order), degrees.

    Returns
    -------
    tuple of float
        The box, with longitudes in -180..180 when it fits there, else 0..360.

    Examples
    --------
    >>> as_lonlat_box((166, 176, -48, -40))
    (166.0, 176.0, -48.0, -40.0)
    >>> as_lonlat_box((260, 310, 10, 60))
    (-100.0, -50.0, 10.0, 60.0)
    """
    try:
        lon_min, lon_max, lat_min, lat_max = (float(v) for v in np.asarray(bbox, dtype=np.float64).ravel())
    except (TypeError, ValueError):
        raise GeometryError(f"bbox must be (lon_min, lon_max, lat_min, lat_max) in degrees, got {bbox!r}") from None
    if not all(np.isfinite([lon_min, lon_max, lat_min, lat_max])):
        raise GeometryError(f"bbox has non-finite values: {bbox!r}")
    if not (lon_min < lon_max and lat_min < lat_max):
        # 178 to -178 is a box across 180 degrees written as a map reads, as the command line says too
        across = (
            "; a box across the antimeridian is written with longitudes past 180:"
            f" ({lon_min:g}, {lon_max + 360:g}, {lat_min:g}, {lat_max:g})"
            if lon_max < 0 < lon_min and lon_max + 360 - lon_min <= 180 and lat_min < lat_max
            else ""
        )
        raise GeometryError(
            f"bbox must be (lon_min, lon_max, lat_min, lat_max) with min < max, got {bbox!r}"
            f" (the guide's order: longitudes first){across}"
        )
    if lat_min < -90 or lat_max > 90:
        raise GeometryError(f"bbox latitudes {lat_min:g}..{lat_max:g} are outside -90..90: are the axes swapped?")
    if lon_max - lon_min > 360 or lon_min < -180 or lon_max > 360 or (lon_min < 0 and lon_max > 180):
        across = (
            f"; a box across the antimeridian is written in 0..360 ({lon_min % 360:g}, {lon_max % 360:g}, ...)"
            if lon_min < -180 <= lon_max and lon_max - lon_min < 360
            else ""
        )
        raise GeometryError(f"bbox longitudes {lon_min:g}..{lon_max:g} are not within -180..180 or 0..360{across}")
    _warn_of_gis_order(lon_min, lon_max, lat_min, lat_max)
    if lon_min >= 180:
        lon_min, lon_max = lon_min - 360, lon_max - 360
    return lon_min, lon_max, lat_min, lat_max


GIS_ORDER_RATIO = 100.0
"""How many times larger a box in the guide's order must be than the same numbers in shapely's order to warn."""


def _warn_of_gis_order(a, b, c, d):
    """Warn of a box perhaps in shapely's (and most GIS tools') order, (xmin, ymin, xmax, ymax), read in the guide's.

    (-71, 42, -66, 45) for the Gulf of Maine read as longitudes -71..42 and
    latitudes -66..45: 314,271 vertices over a third of the globe, and no
    word. Warned of (not refused: longitudes 35..45 and latitudes 36..46
    read the same) where those numbers are also a box in shapely's order
    :data:`GIS_ORDER_RATIO` times smaller.
    """
    if a < c and b < d and -90 <= b and d <= 90 and (b - a) * (d - c) > GIS_ORDER_RATIO * (c - a) * (d - b):
        warn_user(
            f"bbox ({a:g}, {b:g}, {c:g}, {d:g}) is read in the guide's order (lon_min, lon_max, lat_min, lat_max): "
            f"longitudes {a:g}..{b:g}, latitudes {c:g}..{d:g}; if it is in shapely's order (xmin, ymin, xmax, ymax), "
            f"a box of {(c - a) * (d - b):g} square degrees, give ({a:g}, {c:g}, {b:g}, {d:g})"
        )


class GeoGrid:
    """Regular grid on the Mercator plane over a longitude/latitude box.

    Mercator is conformal (see :mod:`terramesh.coastal.projection`), so the
    grid is square on the ground at every node; it is separable, so each
    column has one longitude and each row one latitude. The Mercator
    spacing is chosen so that the ground spacing is at most ``spacing``
    everywhere (it equals it on the row nearest the equator). The grid
    covers the box, its last row and column up to a step beyond it; where
    that row would pass the Mercator limit of 85 degrees, the step is
    shortened so that the last row is on ``lat_max``.

    Parameters
    ----------
    bbox : sequence of 4 float
        ``(lon_min, lon_max, lat_min, lat_max)``, degrees.
    spacing : float
        Largest ground distance between neighbouring nodes, metres.

    Raises
    ------
    GeometryError
        For a bad box (:func:`as_lonlat_box`), one beyond +-85 degrees of
        latitude, or one of 360 degrees of longitude: the grid does not
        wrap at the antimeridian.
    SizingError
        For a spacing that is not a positive number, or a grid of more than
        :data:`MAX_GRID_NODES` nodes.

    Attributes
    ----------
    x, y : ndarray, shape (nx,), (ny,)
        Node coordinates on the Mercator plane, metres.
    lon, lat : ndarray, shape (nx,), (ny,)
        Node longitude of each column and latitude of each row, degrees.
    step : float
        Mercator spacing, metres (both axes).
    ground_step : ndarray, shape (ny,)
        Ground spacing of each row, metres: ``step * cos(lat)``.

    Examples
    --------
    >>> grid = GeoGrid((166, 176, -48, -40), 5000.0)
    >>> grid.shape
    (172, 192)
    >>> bool(grid.ground_step.max() <= 5000.0)
    True
    """

    def __init__(self, bbox, spacing):
        lon_min, lon_max, lat_min, lat_max = as_lonlat_box(bbox)
        spacing = checked_number(
            spacing, "grid spacing must be a positive number of metres", SizingError, minimum=0, strict=True
        )
        if lon_max - lon_min >= 360.0:
            raise GeometryError(
                f"bbox longitudes {lon_min:g}..{lon_max:g} go all the way round: the Mercator grid does not wrap"
                " at the antimeridian (distances across it would be a turn long); give a box under 360 degrees,"
                " or mesh a global domain in another projection"
            )
        (x0, x1), (y0, y1) = to_mercator([lon_min, lon_max], [lat_min, lat_max])
        # The last row may overshoot the box by up to one step, towards the equator when the box
        # is in the southern hemisphere: size the step for the latitude it really reaches.
        reach = (lat_min, lat_max)
        for _ in range(2):
            nearest_equator = 0.0 if reach[0] <= 0 <= reach[1] else min(abs(reach[0]), abs(reach[1]))
            self.step = spacing * float(scale_factor(nearest_equator))
            ny = int(np.ceil((y1 - y0) / self.step - 1e-9)) + 1
            reach = (lat_min, float(from_mercator(0.0, y0 + self.step * (ny - 1))[1]))
        ends_on_lat_max = reach[1] > MAX_LATITUDE
        if ends_on_lat_max:
            # poleward of the limit Mercator is refused: a box ending near it, such as 80..84.99 at 5 km (last
            # row at 85.0009), ends its grid on lat_max instead, with a step a little shorter than the spacing
            self.step = (y1 - y0) / (ny - 1)
        nx = int(np.ceil((x1 - x0) / self.step - 1e-9)) + 1
        if nx * ny > MAX_GRID_NODES:
            raise SizingError(
                f"a {spacing:g} m grid over this bbox has {nx} x {ny} = {nx * ny:,} nodes, more than "
                f"{MAX_GRID_NODES:,}: use a larger minimum edge length or split the box (multiscale)"
            )
        self.x = x0 + self.step * np.arange(nx)
        self.y = y0 + self.step * np.arange(ny)
        self.lon, _ = from_mercator(self.x, np.zeros(1))
        _, self.lat = from_mercator(np.zeros(1), self.y)
        if ends_on_lat_max:
            self.lat[-1] = lat_max  # not a rounding of it, which may lie beyond the limit
        self.ground_step = self.step / scale_factor(self.lat)

    @property
    def shape(self):
        """``(nx, ny)``: fields on the grid are indexed ``[ix, iy]``."""
        return self.x.size, self.y.size

    def lonlat(self):
        """Longitude and latitude of every node, two arrays of shape ``(nx, ny)``, degrees."""
        return np.meshgrid(self.lon, self.lat, indexing="ij")

    def ground_grade(self, grade):
        """The grade of each row on the grid's Mercator spacing that is ``grade`` on the ground, shape ``(ny,)``.

        A ground metre is ``1 / cos(lat)`` Mercator metres, so ground sizes
        graded on the grid at ``grade cos(lat)`` per row
        (:func:`~terramesh.sizing.limit_gradient`) grow by ``grade`` per
        ground metre along the parallels and the meridians alike. ``inf``
        (no limit) comes back as it is.

        Examples
        --------
        >>> grid = GeoGrid((0.0, 1.0, 59.0, 61.0), 5000.0)
        >>> round(float(grid.lat[0]), 6), round(float(grid.ground_grade(0.2)[0]), 4)
        (59.0, 0.103)
        """
        return grade * (self.ground_step / self.step) if np.isfinite(grade) else grade

    def to_mercator_sizes(self, sizes):
        """Ground sizes (metres, shape ``(nx, ny)``) as Mercator lengths: each row times ``1 / cos(lat)``."""
        sizes = np.asarray(sizes, dtype=np.float64)
        if sizes.shape != self.shape:
            raise SizingError(f"size field has shape {sizes.shape}, the grid is {self.shape}")
        return sizes * scale_factor(self.lat)[None, :]

    def size_grid(self, sizes):
        """A :class:`~terramesh.sizing.SizeGrid` on the Mercator plane from ground sizes in metres."""
        return SizeGrid((self.x, self.y), self.to_mercator_sizes(sizes))
