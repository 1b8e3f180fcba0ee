"""Checks shared by the plotting functions, made before a figure is opened."""

import os

__all__ = ["check_output_path"]


def check_output_path(path):
    """Raise FileNotFoundError when ``path`` (a file name) lies in a directory that does not exist.

    Checked before anything is drawn: matplotlib finds out only when saving,
    after the drawing (slow for a large mesh) and leaves the figure open.
    A file-like object is left to matplotlib.
    """
    if not isinstance(path, (str, bytes, os.PathLike)):
        return
    name = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(name))
    if not os.path.isdir(folder):
        raise FileNotFoundError(f"cannot save the figure as {name!r}: the directory {folder!r} does not exist")
