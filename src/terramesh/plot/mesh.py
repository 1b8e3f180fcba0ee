"""Draw a triangle mesh coloured by element quality."""

import numpy as np

from ..quality.triangle import triangle_quality

__all__ = ["plot_mesh"]


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
    aspect : float or "equal"
        Axes aspect ratio; for longitude-latitude meshes pass
        ``1 / cos(latitude)`` so that the picture is not stretched.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if ax is None:
        import matplotlib.pyplot as plt

        width = np.ptp(mesh.points[:, 0]) or 1.0
        height = np.ptp(mesh.points[:, 1]) or 1.0
        figure, ax = plt.subplots(figsize=(9, max(3.0, min(12.0, 9 * height / width)) + 0.6), layout="constrained")
    figure = ax.figure
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    quality = triangle_quality(mesh.points, mesh.cells, geographic=mesh.geographic)
    if color_by == "quality":
        shaded = ax.tripcolor(x, y, mesh.cells, facecolors=quality, cmap="viridis", vmin=0.5, vmax=1.0)
        figure.colorbar(shaded, ax=ax, label="element quality q", shrink=0.8)
    ax.triplot(x, y, mesh.cells, color="k", linewidth=0.15)
    ax.set_aspect(aspect)
    ax.set_title(title or f"{mesh.n_points:,} vertices, {mesh.n_cells:,} cells, mean q {quality.mean():.3f}")
    if path is not None:
        figure.savefig(path, dpi=150)
    return figure
