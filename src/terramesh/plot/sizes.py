"""Draw a size (edge-length) field on a :class:`~terramesh.coastal.GeoGrid` (matplotlib, imported when called)."""

import numpy as np
import shapely

from ..coastal.sizes._common import check_grid, field
from ..errors import GeometryError
from ._checks import check_output_path
from ._figures import add_colorbar, drawing, figure_size, lonlat_aspect

__all__ = ["plot_size_field"]

_MAX_PIXELS = 1500
"""Largest number of grid nodes drawn along each axis; larger grids are drawn every k-th node."""

_LOW_PERCENTILE = 0.5
"""Percentile of the finite sizes where the colour scale starts when the smallest lie far below it (outliers)."""
_OUTLIER_FACTOR = 2.0
"""How many times smaller than the percentile the smallest size must be for the scale to start at the percentile."""


_MAX_LOG_LABELS = 7
"""Labels at most on a logarithmic colour bar: closer ones overlapped on a 1.4 inch bar."""


def _log_ticks(low, high):
    """Three or more round values from ``low`` to ``high``, spread evenly enough on a log scale to be read.

    Decades where the range spans enough of them, else 1, 2 and 5 times
    them, else every digit times them, each kept only a seventh of the
    range (in log) past the previous one; else four values evenly spaced
    in log, rounded to two or three significant digits.
    """
    span = max(np.log10(high / low), 1e-12)
    inside = (low * (1 - 1e-9), high * (1 + 1e-9))
    decades = 10.0 ** np.arange(np.floor(np.log10(low)), np.ceil(np.log10(high)) + 1)
    for subs in ((1.0,), (1.0, 2.0, 5.0), np.arange(1.0, 10.0)):
        candidates = np.sort(np.outer(decades, subs).ravel())
        kept = []
        for value in candidates[(candidates >= inside[0]) & (candidates <= inside[1])]:
            if not kept or np.log10(value / kept[-1]) >= span / _MAX_LOG_LABELS:
                kept.append(float(value))
        if len(kept) >= 3:
            return kept
    for digits in (2, 3, 4):
        values = [float(f"{value:.{digits}g}") for value in np.geomspace(low, high, 4)]
        kept = sorted({value for value in values if inside[0] <= value <= inside[1]})
        if len(kept) >= 3:
            return kept
    return [float(low), float(high)]


def label_log_ticks(colorbar, low, high):
    """Label a logarithmic colour bar from ``low`` to ``high`` at three values or more, written plainly.

    matplotlib labels decades only: a bar from 0.3 to 8 km had one label.
    Its ``LogLocator`` with 1, 2 and 5 times the decades falls back to
    evenly spaced values where it finds one tick only, which crowd at the
    top of a log scale (150, 200, ..., 450 overlapped): the values are
    chosen here instead (:func:`_log_ticks`).
    """
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter, NullLocator

    colorbar.locator = FixedLocator(_log_ticks(low, high))
    colorbar.formatter = FuncFormatter(lambda value, _: f"{value:g}")
    colorbar.minorlocator = NullLocator()
    colorbar.minorformatter = NullFormatter()


def _coastline_segments(coastline, box):
    """Coordinate arrays of a lon/lat geometry's lines (polygon rings included), clipped to ``box``."""
    parts = shapely.get_parts(np.atleast_1d(coastline))
    while parts.size and np.any(shapely.get_type_id(parts) >= 4):
        parts = shapely.get_parts(parts)
    kind = shapely.get_type_id(parts)
    lines = list(parts[(kind == 1) | (kind == 2)])
    polygons = parts[kind == 3]
    if polygons.size:
        lines.extend(shapely.get_rings(polygons))
    if not lines:
        return []
    lon_min, lon_max, lat_min, lat_max = box
    clipped = shapely.get_parts(shapely.clip_by_rect(np.array(lines), lon_min, lat_min, lon_max, lat_max))
    clipped = clipped[~shapely.is_empty(clipped)]
    return [shapely.get_coordinates(line) for line in clipped]


def plot_size_field(grid, sizes, path=None, *, ax=None, title=None, coastline=None):
    """Draw a size field in longitude/latitude with a logarithmic colour scale.

    Parameters
    ----------
    grid : GeoGrid
        The grid the field lives on.
    sizes : array_like, shape (nx, ny)
        Edge lengths, ground metres; ``inf`` (no constraint) is drawn grey.
        Grids over 1,500 nodes along an axis are drawn every k-th node.
    path : str or os.PathLike, optional
        Save the figure there (PNG, SVG, PDF by extension; 150 dpi).
    ax : matplotlib.axes.Axes, optional
        Draw into these axes instead of a new figure.
    title : str, optional
        Axes title; defaults to the field's finite range (all nodes, drawn
        or not). A field without a finite size is said to be one, after
        the title given.
    coastline : shapely geometry or Shoreline, optional
        Lines or polygons in lon/lat degrees, or a
        :class:`~terramesh.coastal.Shoreline` (its coastline), drawn in
        black on top.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on. One made here (no ``ax``) and saved to ``path``
        is closed, so that pyplot does not keep it: it is returned all the
        same, its axes readable and ``figure.savefig`` working; without a
        ``path`` it stays open. A figure of ``ax`` is never closed.

    Raises
    ------
    GeometryError
        For a ``grid`` that is not a ``GeoGrid`` or a ``coastline`` that is
        neither a shapely geometry nor a ``Shoreline``.
    SizingError
        For ``sizes`` not of the grid's shape, with NaN, zero or negative values.
    FileNotFoundError
        For a ``path`` in a directory that does not exist (nothing is drawn).
    MeshFormatError
        For a ``path`` whose extension matplotlib cannot write (nothing is drawn).

    Notes
    -----
    The colour bar is in metres, or in kilometres when the largest finite
    size is 10 km or more. It starts at the smallest size, or at the 0.5th
    percentile of the finite sizes where the smallest is less than half of
    that: a few outliers (a wavelength field's 1e-18 m at zero depth) then
    do not give the rest one colour. They share the lowest colour, and the
    bar's lower end is pointed. It is labelled at three values or more
    (decades, or 1, 2 and 5 times them over a narrower range). A field with
    no finite size (a channel field that found no channel) is drawn grey,
    with no colour bar, and its title says "no finite edge length". The
    axes' aspect is ``1 / cos(latitude)`` at the middle of the box, so that
    the picture is not stretched east-west.

    Examples
    --------
    >>> import os, tempfile, numpy as np, shapely
    >>> import matplotlib.pyplot as plt
    >>> from terramesh.coastal import GeoGrid
    >>> grid = GeoGrid((10, 11, 55, 56), 5e3)
    >>> path = os.path.join(tempfile.mkdtemp(), "sizes.png")
    >>> figure = plot_size_field(grid, np.full(grid.shape, 800.0), path, coastline=shapely.box(10, 55, 10.3, 55.4))
    >>> os.path.getsize(path) > 0
    True
    >>> plt.fignum_exists(figure.number)  # saved: closed, still returned
    False
    """
    import matplotlib
    from matplotlib.collections import LineCollection
    from matplotlib.colors import ListedColormap, LogNorm

    grid = check_grid(grid)
    sizes = field("sizes", sizes, grid.shape, allow_inf=True, positive_only=True)
    from ..coastal.shoreline import Shoreline

    if isinstance(coastline, Shoreline):  # its coast within the box, as plot_shoreline draws it
        coastline = coastline.coastline
    if coastline is not None and not isinstance(coastline, shapely.Geometry):
        raise GeometryError(
            f"coastline must be a shapely geometry in lon/lat or a Shoreline, got {type(coastline).__name__}"
        )
    check_output_path(path)
    stride = max(1, int(np.ceil(max(grid.shape) / _MAX_PIXELS)))
    lon, lat = grid.lon[::stride], grid.lat[::stride]
    shown = sizes[::stride, ::stride]
    finite = np.isfinite(shown)
    aspect = lonlat_aspect(grid.lat[0], grid.lat[-1])
    # the range of the whole field: a strided picture may skip its smallest or largest node
    # (sizes are positive, not NaN: inf is the only value that is not finite)
    constrained = sizes < np.inf
    any_constrained = bool(constrained.any())
    created = ax is None
    if created:
        import matplotlib.pyplot as plt

        width, height = grid.lon[-1] - grid.lon[0], grid.lat[-1] - grid.lat[0]
        size = figure_size(width, height, aspect, colorbar=any_constrained, labels=True)
        figure, ax = plt.subplots(figsize=size, layout="constrained")
    figure = ax.figure
    with drawing(figure, path, created=created):
        if any_constrained:
            values = sizes[constrained]
            low, high = float(values.min()), float(values.max())
            # the colours start at a low percentile when the minimum is far below it: a wavelength field's
            # 1e-18 m at zero depth stretched the scale over 20 decades and drew every other node one colour
            # ``values`` is a copy made here: partitioning it in place spares a second one (0.7 of 0.85 s at 39M nodes)
            floor = float(np.percentile(values, _LOW_PERCENTILE, overwrite_input=True))
            floor = floor if low < floor / _OUTLIER_FACTOR else low
            scale, unit = (1e3, "km") if high >= 1e4 else (1.0, "m")
            # a uniform field still needs a colour range; the title keeps the true one
            spread = 1.1 if high <= floor else 1.0
            vmin, vmax = floor / spread / scale, high * spread / scale
            colours = matplotlib.colormaps["viridis"].with_extremes(bad="0.85")
            image = ax.pcolormesh(
                lon,
                lat,
                np.ma.masked_invalid(np.where(finite, shown, np.nan) / scale).T,
                shading="nearest",
                cmap=colours,
                norm=LogNorm(vmin=vmin, vmax=vmax),
                rasterized=True,
            )
            label = f"edge length ({unit})" + ("; grey: unconstrained" if not finite.all() else "")
            extend = "min" if low / scale < vmin else "neither"
            label_log_ticks(add_colorbar(ax, image, label=label, extend=extend), vmin, vmax)
            if title is None:
                if high > low:
                    title = f"edge length {low / scale:.3g} to {high / scale:.3g} {unit}"
                else:
                    title = f"edge length {low / scale:.3g} {unit}"
        else:
            # no size to colour by: the grey of "unconstrained" alone, and no colour bar for values there are not
            grey = ListedColormap(["0.85"])
            ax.pcolormesh(lon, lat, np.zeros((len(lat), len(lon))), shading="nearest", cmap=grey, rasterized=True)
            title = f"{title}: no finite edge length" if title else "no finite edge length"
        box = (float(grid.lon[0]), float(grid.lon[-1]), float(grid.lat[0]), float(grid.lat[-1]))
        if coastline is not None:
            ax.add_collection(LineCollection(_coastline_segments(coastline, box), colors="k", linewidths=0.6))
        ax.set_xlim(box[0], box[1])
        ax.set_ylim(box[2], box[3])
        ax.set_aspect(aspect)
        ax.set_xlabel("longitude (°)")
        ax.set_ylabel("latitude (°)")
        ax.set_title(title)
    return figure
