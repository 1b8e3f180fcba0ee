"""The figures the plotting functions open: sized for the picture, drawn, saved, closed."""

import contextlib
import numbers

__all__ = ["drawing", "figure_size"]

_AXES_WIDTH = 8.0  # inches: the axes of a picture wider than tall...
_AXES_HEIGHT = 10.0  # ...and of one taller than wide (not taller than a page)
_AXES_SHORT_SIDE = 2.5  # at least, for a long thin picture: room for the colour bar, the title, the ticks


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
    it is wide, and at least 2.5 inches the other way (blank beside a long
    thin picture, where the title and colour bar need the room), plus
    fixed margins for the title, tick labels, axis labels and colour bar.

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
    (8.9, 3.5)
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
    axes_width, axes_height = max(_AXES_SHORT_SIDE, axes_width), max(_AXES_SHORT_SIDE, axes_height)
    return round(axes_width + margin_x, 2), round(axes_height + margin_y, 2)
