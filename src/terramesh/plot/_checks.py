"""Checks shared by the plotting functions, made before a figure is opened."""

import os

from ..errors import MeshFormatError

__all__ = ["check_output_path"]


def check_output_path(path):
    """Raise unless a picture can be saved as ``path`` (a file name): its folder exists, matplotlib has its format.

    Checked before anything is drawn: matplotlib finds out only when saving,
    after the drawing (slow for a large mesh). A name without an extension
    is matplotlib's default format (PNG); a file-like object is left to
    matplotlib.

    Raises
    ------
    FileNotFoundError
        For a ``path`` in a directory that does not exist.
    MeshFormatError
        For an extension matplotlib cannot write (``.xyz``).
    """
    if not isinstance(path, (str, bytes, os.PathLike)):
        return
    name = os.fsdecode(path)
    folder = os.path.dirname(os.path.abspath(name))
    if not os.path.isdir(folder):
        raise FileNotFoundError(f"cannot save the figure as {name!r}: the directory {folder!r} does not exist")
    extension = os.path.splitext(name)[1][1:].lower()
    if extension:
        from matplotlib.backend_bases import FigureCanvasBase

        known = FigureCanvasBase.get_supported_filetypes()
        if extension not in known:
            raise MeshFormatError(
                f"cannot save the figure as {name!r}: matplotlib writes no {extension!r} files; "
                f"use one of {', '.join(sorted(known))}"
            )
