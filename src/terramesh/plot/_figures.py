"""The life of a figure a plotting function opens: drawn, saved, closed."""

import contextlib

__all__ = ["drawing"]


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
