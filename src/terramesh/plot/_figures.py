"""The figures the plotting functions open: sized for the picture, drawn, saved, closed."""

import contextlib
import math
import numbers

__all__ = ["add_colorbar", "drawing", "figure_size", "laid_out", "lonlat_aspect"]

_AXES_WIDTH = 8.0  # inches: the axes of a picture wider than tall...
_AXES_HEIGHT = 10.0  # ...and of one taller than wide (not taller than a page)
_AXES_SHORT_SIDE = 2.5  # at least, across a tall thin picture: room for the title above it
_AXES_SHORT_HEIGHT = 1.5  # at least, up a wide thin picture: room for the colour bar's labels beside it
_COLORBAR_WIDTH = 0.18  # inches, beside the picture...
_COLORBAR_PAD = 0.12  # ...this far from its right edge


@contextlib.contextmanager
def drawing(figure, path, *, created):
    """Draw into ``figure`` in the ``with`` block, then save it to ``path`` (if given, 150 dpi).

    A figure the function ``created`` itself is closed once saved, and when
    drawing or saving fails: pyplot keeps every figure open until closed
    (memory, and matplotlib's "More than 20 figures" warning in a loop). A
    closed figure stays usable (its axes, ``figure.savefig``); only pyplot
    no longer holds it. Without a ``path`` it stays open, for the caller to
    show or draw on; a figure of the caller's (``ax=``) is never closed.
    """
    import matplotlib.pyplot as plt

    try:
        yield
        if path is not None:
            figure.savefig(path, dpi=150)
    except BaseException:
        if created:
            plt.close(figure)
        raise
    if created and path is not None:
        plt.close(figure)


def figure_size(width, height, aspect, *, colorbar, labels=False):
    """Figure (width, height), inches, whose axes a picture of ``width`` by ``height`` fills at ``aspect``.

    Every plotting function sizes its figure here, so that a long thin
    domain gets a figure of its own proportions whichever function draws
    it: 8 inches of axes across, or 10 inches up for a picture taller than
    it is wide, and at least 2.5 inches across a tall thin picture (the
    title above it needs the width) and 1.5 inches up a wide thin one (the
    colour bar's labels beside it; 2.5 left a 67 by 12 km seismic section
    between blank bands a third of the figure), plus fixed margins for the
    title, tick labels, axis labels and colour bar.

    Parameters
    ----------
    width, height : float
        Extent of the picture in data units (x and y); zero is taken as one.
    aspect : float, "equal" or "auto"
        Axes aspect as given to ``ax.set_aspect``: y units drawn per x unit
        ("equal": 1; "auto" fills any box, taken as 1).
    colorbar : bool
        Leave room for a colour bar and its label on the right.
    labels : bool, optional
        Leave room for x and y axis labels.

    Returns
    -------
    tuple of float
        ``(width, height)`` of the figure, inches.

    Examples
    --------
    >>> figure_size(10.0, 1.0, "equal", colorbar=False)
    (8.9, 2.5)
    >>> figure_size(1.0, 10.0, "equal", colorbar=True, labels=True)
    (4.7, 11.3)
    """
    width = float(width) or 1.0
    height = float(height) or 1.0
    scale = float(aspect) if isinstance(aspect, numbers.Real) else 1.0
    ratio = height / width * scale
    margin_x = 0.9 + (1.0 if colorbar else 0.0) + (0.3 if labels else 0.0)  # y tick labels, colour bar, y label
    margin_y = 1.0 + (0.3 if labels else 0.0)  # title and x tick labels, x label
    axes_width, axes_height = _AXES_WIDTH, _AXES_WIDTH * ratio
    if axes_height > _AXES_HEIGHT:
        axes_width, axes_height = _AXES_HEIGHT / ratio, _AXES_HEIGHT
    axes_width, axes_height = max(_AXES_SHORT_SIDE, axes_width), max(_AXES_SHORT_HEIGHT, axes_height)
    return round(axes_width + margin_x, 2), round(axes_height + margin_y, 2)


def add_colorbar(ax, mappable, *, label, extend="neither"):
    """A colour bar for ``mappable`` on the right of ``ax``, as tall as the picture drawn there, not its box.

    ``figure.colorbar(ax=ax)`` sizes the bar to the axes' box, which is
    taller than the picture of a long thin domain at a fixed aspect (a 1.5
    inch tall seismic section got a 2 inch bar). In a constrained-layout
    figure (every figure made here) the bar is therefore an inset of the
    axes, which follows the picture as the aspect shrinks it, and the
    layout makes room for it. Another layout (a caller's figure) has no
    room made for an inset: there the bar takes its room from the axes,
    as matplotlib does, at 80 % of their height.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes of the picture.
    mappable : matplotlib.cm.ScalarMappable
        What was drawn (``tripcolor``, ``pcolormesh``, ``imshow``): its
        colour map and norm.
    label : str
        Label along the bar, with the unit.
    extend : {"neither", "min", "max", "both"}, optional
        Pointed ends for values beyond the norm's limits.

    Returns
    -------
    matplotlib.colorbar.Colorbar
        Also ``mappable.colorbar``.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> figure, ax = plt.subplots(layout="constrained")
    >>> image = ax.imshow([[0.0, 1.0]])
    >>> add_colorbar(ax, image, label="value (m)", extend="min").extend
    'min'
    >>> plt.close(figure)
    """
    figure = ax.figure
    if not laid_out(figure):
        return figure.colorbar(mappable, ax=ax, label=label, extend=extend, shrink=0.8)
    # inset bounds are fractions of the axes: the width and the gap in inches, as the axes are laid out now
    width = max(ax.get_position().width * figure.get_figwidth(), 1.0)
    bar = ax.inset_axes([1.0 + _COLORBAR_PAD / width, 0.0, _COLORBAR_WIDTH / width, 1.0])
    return figure.colorbar(mappable, cax=bar, label=label, extend=extend)


def laid_out(figure):
    """Whether ``figure`` has a constrained layout, which makes room for what is drawn outside its axes.

    Every figure made here has one. In another (a caller's ``plt.subplots()``)
    a colour bar inset or a legend outside the axes may fall off the figure.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> figure = plt.figure(layout="constrained")
    >>> laid_out(figure), laid_out(plt.figure())
    (True, False)
    >>> plt.close("all")
    """
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    return isinstance(figure.get_layout_engine(), ConstrainedLayoutEngine)


_LATITUDE_LIMIT = 85.0  # degrees: 1 / cos(latitude) grows without bound toward a pole


def lonlat_aspect(lat_low, lat_high):
    """The aspect (y drawn per x) at which degrees of longitude and latitude are drawn in ground proportion.

    ``1 / cos`` of the middle latitude of the extent, one value for the
    mesh, shoreline and size pictures of one area (capped at 85 degrees).
    """
    middle = 0.5 * (float(lat_low) + float(lat_high))
    return 1.0 / math.cos(math.radians(min(abs(middle), _LATITUDE_LIMIT)))
