"""Draw a triangle mesh coloured by element quality."""

import numbers

import numpy as np

from ..errors import MeshValidityError
from ..mesh.topology import checked_cells, checked_points
from ..quality.triangle import triangle_quality
from ._checks import check_output_path
from ._figures import drawing, figure_size

__all__ = ["plot_mesh"]


def _checked_aspect(aspect):
    """``aspect`` if matplotlib takes it: "equal", "auto" or a positive finite number."""
    if isinstance(aspect, str) and aspect in ("equal", "auto"):
        return aspect
    if isinstance(aspect, numbers.Real) and not isinstance(aspect, bool) and np.isfinite(aspect) and aspect > 0:
        return aspect
    raise MeshValidityError(f'aspect must be "equal", "auto" or a positive finite number, got {aspect!r}')


def plot_mesh(mesh, path=None, *, ax=None, title=None, color_by="quality", aspect="equal"):
    """Draw the mesh edges over cells coloured by quality (guide eq. 1).

    Parameters
    ----------
    mesh : Mesh
        A 2D triangle mesh.
    path : str or os.PathLike, optional
        Save the figure there (PNG, SVG, PDF by extension).
    ax : matplotlib.axes.Axes, optional
        Draw into these axes instead of a new figure.
    title : str, optional
        Axes title; defaults to the counts and mean quality.
    color_by : {"quality", None}
        Fill cells by quality, or draw edges only.
    aspect : float, "equal" or "auto"
        Axes aspect ratio; for longitude-latitude meshes pass
        ``1 / cos(latitude)`` so that the picture is not stretched.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on. One made here (no ``ax``) and saved to ``path``
        is closed, so that pyplot does not keep it: it is returned all the
        same, its axes readable and ``figure.savefig`` working; without a
        ``path`` it stays open. A figure of ``ax`` is never closed.

    Raises
    ------
    MeshValidityError
        For a mesh that is not 2-D triangles, has no cells, a NaN or
        infinite coordinate or cells referring to vertices that do not
        exist, or a ``color_by`` or ``aspect`` not listed above.
    FileNotFoundError
        For a ``path`` in a directory that does not exist (nothing is drawn).
    MeshFormatError
        For a ``path`` whose extension matplotlib cannot write (nothing is drawn).
    """
    # everything is checked before a figure is opened (pyplot keeps figures open until closed)
    if not (color_by is None or (isinstance(color_by, str) and color_by == "quality")):
        raise MeshValidityError(f'color_by must be "quality" or None, got {color_by!r}')
    aspect = _checked_aspect(aspect)
    check_output_path(path)
    points = checked_points(mesh.points, 2)
    cells = checked_cells(mesh.cells, 3, len(points))
    if len(cells) == 0:
        raise MeshValidityError("plot_mesh needs a mesh with at least one cell, got none")
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if len(bad):
        raise MeshValidityError(f"points have {len(bad)} NaN or infinite rows (index {bad[0]} first)")
    quality = triangle_quality(points, cells, geographic=mesh.geographic)
    created = ax is None
    if created:
        import matplotlib.pyplot as plt

        size = figure_size(np.ptp(points[:, 0]), np.ptp(points[:, 1]), aspect, colorbar=color_by == "quality")
        figure, ax = plt.subplots(figsize=size, layout="constrained")
    figure = ax.figure
    with drawing(figure, path, created=created):
        x, y = points[:, 0], points[:, 1]
        if color_by == "quality":
            shaded = ax.tripcolor(x, y, cells, facecolors=quality, cmap="viridis", vmin=0.5, vmax=1.0)
            figure.colorbar(shaded, ax=ax, label="element quality q", shrink=0.8)
        ax.triplot(x, y, cells, color="k", linewidth=0.15)
        ax.set_aspect(aspect)
        ax.set_title(title or f"{mesh.n_points:,} vertices, {mesh.n_cells:,} cells, mean q {quality.mean():.3f}")
    return figure
