"""Draw the distribution of element quality: a histogram, its minimum and mean marked, the poor cells counted."""

import numpy as np

from ..errors import MeshValidityError
from ..mesh.topology import checked_cells, checked_points
from ..quality.metric import metric_quality
from ..quality.summary import POOR_QUALITY
from ..quality.tetra import SLIVER_DEGREES, min_max_dihedral, radius_ratio
from ..quality.triangle import triangle_quality
from ._checks import check_output_path
from ._figures import drawing, laid_out

__all__ = ["plot_quality"]

_BINS = 50  # over 0 to 1: 0.02 wide, fine enough to tell 0.96 from 0.98
_FIGURE_SIZE = (7.5, 4.2)  # inches: the axes and the legend beside them


def _measured(mesh, metric):
    """Quality per cell, its name and symbol, the count of poor cells and what makes them poor (2-D or 3-D)."""
    dim = mesh.points.shape[1] if mesh.points.ndim == 2 else None
    width = mesh.cells.shape[1] if mesh.cells.ndim == 2 else None
    if (dim, width) == (2, 3):
        points = checked_points(mesh.points, 2)
        cells = checked_cells(mesh.cells, 3, len(points))
        if metric is None:
            quality, name = triangle_quality(points, cells, geographic=mesh.geographic), "triangle quality q"
        else:
            quality, name = metric_quality(points, cells, metric), "triangle quality in the metric q"
        poor = int(np.count_nonzero(quality < POOR_QUALITY))
        return quality, name, "q", poor, f"with q < {POOR_QUALITY:g}"
    if metric is not None:
        raise MeshValidityError("plot_quality measures quality in a metric for 2-D triangles only")
    if (dim, width) == (3, 4):
        points = checked_points(mesh.points, 3)
        cells = checked_cells(mesh.cells, 4, len(points))
        smallest, _ = min_max_dihedral(points, cells)
        # slivers as quality.summary counts them: a fair radius ratio can hide a flat dihedral angle
        poor = int(np.count_nonzero(smallest < SLIVER_DEGREES))
        return radius_ratio(points, cells), "radius ratio 3 r_in / r_circ", "ratio", poor, "slivers (dihedral < 10°)"
    raise MeshValidityError(
        "plot_quality needs 2-D triangles (cells (m, 3), points (n, 2)) or tetrahedra (cells (m, 4), points "
        f"(n, 3)); got cells of shape {mesh.cells.shape} and points of shape {mesh.points.shape}"
    )


def plot_quality(mesh, path=None, *, ax=None, title=None, metric=None):
    """Draw a histogram of element quality, with the minimum and mean marked and the poor cells counted.

    Triangles (2-D) by the guide's quality ``q`` (eq. 1, as
    :func:`~terramesh.quality.triangle_quality`: on the ground for a
    longitude-latitude mesh), the bars coloured as :func:`plot_mesh`
    colours the cells, red below 0.5; tetrahedra (3-D) by the radius ratio
    ``3 r_in / r_circ`` (:func:`~terramesh.quality.radius_ratio`). Both are
    1 for an equilateral cell, 0 for a flat one, negative for an inverted
    one.

    Parameters
    ----------
    mesh : Mesh
        A 2-D triangle mesh or a tetrahedral mesh.
    path : str or os.PathLike, optional
        Save the figure there (PNG, SVG, PDF by extension; 150 dpi).
    ax : matplotlib.axes.Axes, optional
        Draw into these axes instead of a new figure.
    title : str, optional
        Axes title; defaults to the number of cells and the number of poor
        ones: triangles with q < 0.5, tetrahedra with a dihedral angle
        under 10 degrees (slivers, as ``quality.summary`` counts them).
    metric : callable or array_like, shape (2, 2), optional
        For an anisotropic triangle mesh: measure the quality in this metric
        (:func:`~terramesh.quality.metric_quality`), where the long thin
        cells it asked for are equilateral.

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
        For a mesh that is neither 2-D triangles nor tetrahedra (a surface
        of triangles in 3-D), has no cells, or cells referring to vertices
        that do not exist.
    FileNotFoundError
        For a ``path`` in a directory that does not exist (nothing is drawn).
    MeshFormatError
        For a ``path`` whose extension matplotlib cannot write (nothing is drawn).

    Notes
    -----
    The count axis is logarithmic, so that a handful of poor cells among a
    million good ones still makes a bar. The quality axis runs from 0 to
    1 (lower for inverted cells); for a mesh with no poor cell, from a
    tenth below its minimum, rounded down to a tenth (0.6 for a minimum of
    0.72), so that the bars fill the width. The legend, right of the axes
    (inside them in a caller's figure without a constrained layout), gives
    the poor cells' count and share, the minimum and the mean.

    Examples
    --------
    >>> import terramesh as tm
    >>> import matplotlib.pyplot as plt
    >>> mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2, seed=0)
    >>> figure = plot_quality(mesh)
    >>> figure.axes[0].get_xlabel(), figure.axes[0].get_ylabel()
    ('triangle quality q', 'cells')
    >>> plt.close(figure)
    """
    # everything is checked before a figure is opened (pyplot keeps figures open until closed)
    check_output_path(path)
    quality, name, symbol, poor, poor_name = _measured(mesh, metric)
    if quality.size == 0:
        raise MeshValidityError("plot_quality needs a mesh with at least one cell, got none")
    bad = np.flatnonzero(~np.isfinite(mesh.points).all(axis=1))
    if len(bad):  # changed since the Mesh checked them: a NaN quality has no bar
        raise MeshValidityError(f"points have {len(bad)} NaN or infinite rows (index {bad[0]} first)")
    created = ax is None
    if created:
        import matplotlib.pyplot as plt

        figure, ax = plt.subplots(figsize=_FIGURE_SIZE, layout="constrained")
    figure = ax.figure
    with drawing(figure, path, created=created):
        import matplotlib
        from matplotlib.colors import Normalize
        from matplotlib.ticker import FuncFormatter

        lowest, mean = float(quality.min()), float(quality.mean())
        # bins 0.02 wide from 0 to 1, reaching down far enough for inverted cells; with no poor cell, from a
        # tenth below the minimum: a mesh with min q 0.72 left three quarters of the width empty
        start = min(0.0, np.floor(lowest * _BINS) / _BINS)
        if poor == 0 and lowest >= 0.0:
            start = max(0.0, round(np.floor(lowest * 10.0) / 10.0 - 0.1, 10))
        edges = np.linspace(start, 1.0, int(round((1.0 - start) * _BINS)) + 1)
        counts, edges = np.histogram(np.clip(quality, start, 1.0), bins=edges)
        middles = 0.5 * (edges[:-1] + edges[1:])
        if symbol == "q":
            colours = matplotlib.colormaps["viridis"].with_extremes(under="red")
            faces = colours(Normalize(POOR_QUALITY, 1.0)(middles))
        else:
            faces = "0.55"
        ax.bar(edges[:-1], counts, width=np.diff(edges), align="edge", color=faces, edgecolor="none")
        share = 100.0 * poor / quality.size
        poor_label = f"{poor:,} {poor_name} ({share:.2g} %)"
        if symbol == "q":  # the poor range shaded, as the legend's key to the count
            ax.axvspan(start, POOR_QUALITY, color="red", alpha=0.08, linewidth=0, label=poor_label)
        else:
            ax.plot([], [], linestyle="none", label=poor_label)  # a legend line with no key: not a radius ratio
        ax.axvline(lowest, color="red", linestyle="--", linewidth=1.2, label=f"min {symbol} {lowest:.3f}")
        ax.axvline(mean, color="black", linewidth=1.2, label=f"mean {symbol} {mean:.3f}")
        ax.set_yscale("log")
        ax.set_ylim(bottom=0.5)  # a bar of one cell stands half a decade tall
        ax.set_xlim(start, 1.0)
        ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:,.0f}"))  # 1,000, not 10^3
        ax.set_xlabel(name)
        ax.set_ylabel("cells")
        if laid_out(figure):  # right of the axes: inside, it would hide bars of a poor mesh, spread over the width
            ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
        else:  # a caller's figure makes no room beside the axes
            ax.legend(loc="best")
        kind = "triangles" if symbol == "q" else "tetrahedra"
        ax.set_title(title or f"{quality.size:,} {kind}, {poor:,} {poor_name}")
    return figure
