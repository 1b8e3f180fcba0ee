"""Draw a shoreline's classes over a DEM (the guide's ``plot(data, 'shp')`` and ``plot(data, 'dem')``)."""

import numpy as np
import shapely

from ..coastal.dem import DEM
from ..coastal.shoreline import Shoreline
from ..errors import GeometryError
from ._checks import check_output_path
from ._figures import add_colorbar, drawing, figure_size, laid_out, lonlat_aspect

__all__ = ["plot_shoreline"]

_STYLES = {
    "mainland": {"color": "black", "linewidth": 1.0},
    "islands": {"color": "tab:red", "linewidth": 1.0},
    "open boundary": {"color": "tab:blue", "linewidth": 2.0, "linestyle": "--"},
}

_LEGEND_DROP = 0.5
"""Inches from the axes' bottom edge down to the legend: below the tick labels and the axis label."""
_LEGEND_HEIGHT = 0.35
"""Inches a created figure is made taller by, for the legend's one row."""


def sea_colours():
    """128 RGBA rows of blue, from the deepest water (dark) up to the shoreline (light)."""
    import matplotlib

    return matplotlib.colormaps["Blues_r"](np.linspace(0.15, 0.85, 128))


def land_colours():
    """128 RGBA rows of the upper part of ``terrain``, from the shoreline (green) up to the highest ground."""
    import matplotlib

    return matplotlib.colormaps["terrain"](np.linspace(0.25, 1.0, 128))


def _terrain_colormap():
    """Blues below sea level, the upper part of ``terrain`` above it: the shoreline is where blue turns green."""
    import matplotlib.colors

    return matplotlib.colors.ListedColormap(np.vstack([sea_colours(), land_colours()]), name="terramesh_topo")


def _xy_with_breaks(lines):
    """x, y of all the lines, separated by NaN, ready for one ``ax.plot`` call."""
    parts = shapely.get_parts(lines)
    if len(parts) == 0:
        return np.zeros(0), np.zeros(0)
    coords, index = shapely.get_coordinates(parts, return_index=True)
    breaks = np.flatnonzero(index[1:] != index[:-1]) + 1
    coords = np.insert(coords, breaks, np.nan, axis=0)
    return coords[:, 0], coords[:, 1]


def plot_shoreline(shoreline, dem=None, path=None, *, ax=None, title=None):
    """Draw the mainland coastline, islands and open-ocean boundary, over the DEM if given.

    Parameters
    ----------
    shoreline : Shoreline
        A :class:`~terramesh.coastal.shoreline.Shoreline`, longitude-latitude degrees.
    dem : DEM, optional
        Drawn as an image in metres (positive up) with a colour bar: blues
        below the datum, terrain colours above.
    path : str or os.PathLike, optional
        Save the figure there (PNG, SVG, PDF by extension).
    ax : matplotlib.axes.Axes, optional
        Draw into these axes instead of a new figure.
    title : str, optional
        Axes title; defaults to ``h0`` and the numbers of mainland and
        island polygons.

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
        For a ``shoreline`` that is not a ``Shoreline`` or a ``dem`` that is
        not a :class:`~terramesh.coastal.dem.DEM`.
    FileNotFoundError
        For a ``path`` in a directory that does not exist (nothing is drawn).
    MeshFormatError
        For a ``path`` whose extension matplotlib cannot write (nothing is drawn).

    Notes
    -----
    The axes aspect is ``1 / cos(mid latitude)``, so that a degree of
    longitude and a degree of latitude have their ground proportions there.
    The legend is one row under the axes, where it hides no coastline (in
    axes of the caller's without a constrained layout, which makes no room
    for it there: inside, where it covers the least).

    Examples
    --------
    >>> import shapely
    >>> from terramesh.coastal.shoreline import Shoreline
    >>> shore = Shoreline(shapely.box(-1.0, -1.0, 0.0, 1.0), (-0.5, 0.5, -0.5, 0.5), 5000.0)
    >>> figure = plot_shoreline(shore)
    >>> [text.get_text() for text in figure.axes[0].get_legend().get_texts()]
    ['mainland', 'open boundary']
    >>> import matplotlib.pyplot as plt; plt.close(figure)
    """
    import matplotlib.pyplot as plt

    if not isinstance(shoreline, Shoreline):
        raise GeometryError(f"shoreline must be a terramesh.coastal.Shoreline, got {type(shoreline).__name__}")
    if dem is not None and not isinstance(dem, DEM):
        raise GeometryError(f"dem must be a terramesh.coastal.DEM or None, got {type(dem).__name__}")
    check_output_path(path)
    lon_min, lon_max, lat_min, lat_max = shoreline.bbox
    aspect = lonlat_aspect(lat_min, lat_max)
    created = ax is None
    if created:
        width, height = figure_size(lon_max - lon_min, lat_max - lat_min, aspect, colorbar=dem is not None, labels=True)
        figure, ax = plt.subplots(figsize=(width, height + _LEGEND_HEIGHT), layout="constrained")
    figure = ax.figure
    with drawing(figure, path, created=created):
        if dem is not None:
            import matplotlib.colors

            low, high = float(dem.elevation.min()), float(dem.elevation.max())
            norm = matplotlib.colors.TwoSlopeNorm(vmin=min(low, -1.0), vcenter=0.0, vmax=max(high, 1.0))
            extent = (
                dem.lon[0] - 0.5 * dem.dx,
                dem.lon[-1] + 0.5 * dem.dx,
                dem.lat[0] - 0.5 * dem.dy,
                dem.lat[-1] + 0.5 * dem.dy,
            )
            image = ax.imshow(
                dem.elevation.T,
                origin="lower",
                extent=extent,
                cmap=_terrain_colormap(),
                norm=norm,
                interpolation="nearest",
            )
            add_colorbar(ax, image, label="elevation (m, positive up)")
        classes = {
            "mainland": shoreline.mainland_coastline,
            "islands": shapely.boundary(shoreline.islands),
            "open boundary": shoreline.open_boundary,
        }
        for label, lines in classes.items():
            x, y = _xy_with_breaks(lines)
            if x.size:
                ax.plot(x, y, label=label, **_STYLES[label])
        if ax.get_legend_handles_labels()[0] and laid_out(figure):
            # one row under the axes, which it covers no part of: loc="best" put it on the coastline
            from matplotlib.transforms import ScaledTranslation

            below = ax.transAxes + ScaledTranslation(0.0, -_LEGEND_DROP, figure.dpi_scale_trans)
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below, ncols=3, frameon=False)
        elif ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best")  # a caller's figure, no room made below the axes: inside, where it covers least
        pad_x, pad_y = 0.02 * (lon_max - lon_min), 0.02 * (lat_max - lat_min)
        ax.set_xlim(lon_min - pad_x, lon_max + pad_x)
        ax.set_ylim(lat_min - pad_y, lat_max + pad_y)
        ax.set_aspect(aspect)
        ax.set_xlabel("longitude (°)")
        ax.set_ylabel("latitude (°)")
        islands = len(shoreline.islands.geoms)
        ax.set_title(
            title
            or f"h0 = {shoreline.min_edge_length:g} m: {len(shoreline.mainland.geoms)} mainland, "
            f"{islands} island{'s' if islands != 1 else ''}"
        )
    return figure
