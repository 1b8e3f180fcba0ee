"""Draw a triangle mesh coloured by element quality, resolution or a vertex field (the bathymetry)."""

import numbers

import numpy as np

from ..errors import MeshValidityError
from ..mesh.topology import checked_cells, checked_points, signed_areas
from ..quality.metric import metric_quality
from ..quality.summary import POOR_QUALITY
from ..quality.triangle import triangle_quality
from ._checks import check_output_path
from ._figures import add_colorbar, drawing, figure_size, lonlat_aspect

__all__ = ["plot_mesh"]


_EDGES_MAX_DENSITY = 1000.0
"""Cells per square inch of picture up to which ``edges="auto"`` draws a cell's edges: those of cells 1/1,000 in².

Such a cell is 0.05 inch (7 pixels at 150 dpi) a side: its edges still
leave its colour seen. At 5,000 a square inch (a 319k-cell disk on 8 by 8
inches) the black edges covered the colours: olive, not yellow. Judged
cell by cell, a multiscale mesh's fine box keeps its colours and the
coarse shelf around it shows its edges.
"""

_RASTERIZE_ABOVE = 20_000
"""Cells above which the fill and the edges are drawn as an image (150 dpi) in PDF and SVG output.

319k cells drawn as vector triangles made a 7 MB PDF in 14 to 29 seconds
(0.1 MB in 2 s as an image). Below some 20k cells the vector file is the
smaller (9k cells with edges: 0.34 MB, 1.1 MB as an image: the thin
antialiased edges compress badly), and sharp at any zoom.
"""


def _checked_aspect(aspect):
    """``aspect`` if matplotlib takes it: "equal", "auto" or a positive finite number; or None (chosen for the mesh)."""
    if aspect is None:
        return None
    if isinstance(aspect, str) and aspect in ("equal", "auto"):
        return aspect
    if isinstance(aspect, numbers.Real) and not isinstance(aspect, bool) and np.isfinite(aspect) and aspect > 0:
        return aspect
    raise MeshValidityError(f'aspect must be None, "equal", "auto" or a positive finite number, got {aspect!r}')


def _default_aspect(points, geographic):
    """1 / cos(middle latitude) for longitude-latitude points (degrees drawn in ground proportion), else "equal"."""
    if not geographic:
        return "equal"
    return lonlat_aspect(points[:, 1].min(), points[:, 1].max())


def _checked_edges(edges, color_by):
    """``edges`` if it is "auto", True or False, and draws something (the picture's size decides "auto")."""
    if not ((isinstance(edges, str) and edges == "auto") or isinstance(edges, (bool, np.bool_))):
        raise MeshValidityError(f'edges must be "auto", True or False, got {edges!r}')
    if color_by is None and not (isinstance(edges, str) or edges):
        raise MeshValidityError("edges=False with color_by=None draws nothing: give color_by='quality'")
    return edges


def _checked_color_by(mesh, color_by):
    """What ``color_by`` colours by: the cells' mean edge lengths, a vertex field, or None (quality, or nothing)."""
    if color_by is None or (isinstance(color_by, str) and color_by == "quality"):
        return None
    if isinstance(color_by, str) and color_by == "resolution":
        from ..coastal.timestep import edge_lengths

        cells = checked_cells(mesh.cells, 3, len(mesh.points))
        sides = np.stack([cells, np.roll(cells, -1, axis=1)], axis=2).reshape(-1, 2)
        return edge_lengths(mesh.points, sides, geographic=mesh.geographic).reshape(-1, 3).mean(axis=1)
    names = sorted(mesh.point_data)
    if not isinstance(color_by, str) or color_by not in mesh.point_data:
        raise MeshValidityError(
            f'color_by must be "quality", "resolution", None or a point_data name ({", ".join(names) or "none"}), '
            f"got {color_by!r}"
        )
    values = np.asarray(mesh.point_data[color_by])
    if values.shape != (len(mesh.points),) or values.dtype.kind not in "biuf":
        raise MeshValidityError(f"point_data[{color_by!r}] must be one number per vertex, got shape {values.shape}")
    values = values.astype(np.float64)
    if not np.isfinite(values).all():
        bad = int(np.count_nonzero(~np.isfinite(values)))
        raise MeshValidityError(f"point_data[{color_by!r}] has {bad} NaN or infinite values: no colour for them")
    return values


def _picture_inches(ax, width, height, aspect):
    """Width and height, inches, of a picture ``width`` by ``height`` (data units) in ``ax`` at ``aspect``.

    The axes' box as laid out now (before a constrained layout moves it a
    little), shrunk to the picture's proportions.
    """
    figure = ax.figure
    box = ax.get_position()
    box_width, box_height = box.width * figure.get_figwidth(), box.height * figure.get_figheight()
    if isinstance(aspect, str) and aspect == "auto":
        return box_width, box_height
    scale = 1.0 if isinstance(aspect, str) else float(aspect)
    ratio = (float(height) or 1.0) / (float(width) or 1.0) * scale
    drawn_width = min(box_width, box_height / ratio)
    return drawn_width, drawn_width * ratio


def _cell_colours(ax, points, cells, values, rasterized, **colour_scale):
    """Fill each cell with the colour of its value; a large mesh (``rasterized``) as one image's triangles.

    matplotlib draws per-cell colours as one polygon each: 587k cells took
    2.2-2.4 s to draw and save as PNG. A large mesh's cells are drawn
    instead as Gouraud-shaded triangles on vertices of their own, which Agg
    fills in one call (1.0 s), each cell's three corners carrying its value:
    one colour per cell all the same. Small meshes keep the polygons, sharp
    at any zoom in PDF and SVG, where Gouraud shading is emulated.
    """
    if not rasterized:
        return ax.tripcolor(points[:, 0], points[:, 1], cells, facecolors=values, rasterized=False, **colour_scale)
    corners = np.take(points, cells, axis=0).reshape(-1, 2)
    own_vertices = np.arange(len(corners)).reshape(-1, 3)
    return ax.tripcolor(
        corners[:, 0],
        corners[:, 1],
        own_vertices,
        np.repeat(values, 3),
        shading="gouraud",
        rasterized=True,
        **colour_scale,
    )


def plot_mesh(
    mesh,
    path=None,
    *,
    ax=None,
    title=None,
    color_by="quality",
    aspect=None,
    edges="auto",
    metric=None,
    units=None,
    axis_names=("x", "y"),
):
    """Draw the cells coloured by quality (guide eq. 1), with their edges where they can be seen.

    Parameters
    ----------
    mesh : Mesh
        A 2D triangle mesh.
    path : str or os.PathLike, optional
        Save the figure there (PNG, SVG, PDF by extension; 150 dpi).
    ax : matplotlib.axes.Axes, optional
        Draw into these axes instead of a new figure.
    title : str, optional
        Axes title; defaults to the counts, the mean quality and the number
        of poor cells (q < 0.5), if any.
    color_by : {"quality", "resolution"}, a ``point_data`` name, or None
        Fill cells by quality; by ``"resolution"``, each cell's mean edge
        length (ground metres for a geographic mesh, else the mesh's units;
        a log scale); by a vertex field of ``mesh.point_data`` (``"depth"``,
        metres positive down: the bathymetry on the mesh), shaded between
        the vertices; or draw edges only.
    aspect : None, float, "equal" or "auto", optional
        Axes aspect ratio, y units drawn per x unit. None (default):
        ``1 / cos(latitude)`` at the middle of a longitude-latitude mesh's
        extent (``mesh.geographic``), so that the picture is not squashed
        east-west, and "equal" for any other.
    edges : {"auto", True, False}, optional
        Draw the cell edges (black, 0.15 pt) over the colours. "auto"
        (default) draws those of the cells at least 1/1,000 square inch
        large in the picture, so that they do not hide the colours where
        the mesh is fine (such a cell is at least 7 pixels a side at 150
        dpi): a coarse shelf shows its edges, the fine estuary in it its
        colours. With ``color_by=None`` the edges are the picture: always
        drawn.
    metric : callable or array_like, shape (2, 2), optional
        For an anisotropic mesh: the quality (colours and title) is measured
        in this metric (:func:`~terramesh.quality.metric_quality`), where
        the long thin cells it asked for are equilateral.
    units : str, optional
        The length unit of a planar mesh's coordinates (``"m"`` for a
        seismic mesh), written on its axes and on the resolution's colour
        bar ("mesh units" without it); a longitude-latitude mesh's are
        degrees and its resolution ground metres.
    axis_names : (str, str), optional
        A planar mesh's axis names, ``("x", "z")`` for a seismic section.

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
        exist, a ``color_by``, ``aspect`` or ``edges`` not listed above, or
        ``edges=False`` with ``color_by=None`` (nothing to draw).
    FileNotFoundError
        For a ``path`` in a directory that does not exist (nothing is drawn).
    MeshFormatError
        For a ``path`` whose extension matplotlib cannot write (nothing is drawn).

    Notes
    -----
    The colour scale runs from q = 0.5 to 1 (viridis), where good meshes
    lie; cells below 0.5, the poor ones ``quality.summary`` counts, are
    drawn red, the colour of the bar's pointed lower end, so that they
    stand out (:func:`~terramesh.plot.plot_quality` gives their distribution). Axes are
    labelled longitude and latitude in degrees for a geographic mesh, x
    and y otherwise (the mesh carries no unit). A mesh of over 20,000
    cells is drawn as an image in PDF and SVG output (150 dpi), its axes,
    labels and colour bar as vectors: the file stays small and quick to
    write and to open.

    Examples
    --------
    >>> import terramesh as tm
    >>> import matplotlib.pyplot as plt
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((10.0, 55.0), (10.4, 55.2)), 0.05, seed=0)
    >>> mesh.crs = "EPSG:4326"
    >>> figure = plot_mesh(mesh)
    >>> ax = figure.axes[0]
    >>> round(ax.get_aspect(), 3), ax.get_xlabel(), ax.collections[0].colorbar.extend
    (1.748, 'longitude (°)', 'min')
    >>> plt.close(figure)
    """
    # everything is checked before a figure is opened (pyplot keeps figures open until closed)
    if np.ndim(mesh.points) != 2 or np.shape(mesh.points)[1] != 2:  # it said "points must have shape (n, 2)"
        raise MeshValidityError(
            f"plot_mesh draws 2D triangle meshes; this one's points have shape {np.shape(mesh.points)} (a 3D mesh:"
            " write it to .vtu and view it in ParaView, or plot its quality with plot_quality)"
        )
    field = _checked_color_by(mesh, color_by)
    aspect = _checked_aspect(aspect)
    edges = _checked_edges(edges, color_by)
    check_output_path(path)
    points = checked_points(mesh.points, 2)
    cells = checked_cells(mesh.cells, 3, len(points))
    if len(cells) == 0:
        raise MeshValidityError("plot_mesh needs a mesh with at least one cell, got none")
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if len(bad):
        raise MeshValidityError(f"points have {len(bad)} NaN or infinite rows (index {bad[0]} first)")
    geographic = mesh.geographic
    if aspect is None:
        aspect = _default_aspect(points, geographic)
    if metric is None:
        quality = triangle_quality(points, cells, geographic=geographic)
    else:  # an anisotropic mesh: long thin cells are what it asked for
        quality = metric_quality(points, cells, metric)
    width, height = np.ptp(points[:, 0]), np.ptp(points[:, 1])
    created = ax is None
    if created:
        import matplotlib.pyplot as plt

        size = figure_size(width, height, aspect, colorbar=color_by is not None, labels=True)
        figure, ax = plt.subplots(figsize=size, layout="constrained")
    figure = ax.figure
    with drawing(figure, path, created=created):
        import matplotlib

        drawn = cells
        if color_by is None:
            edges = True
        elif isinstance(edges, str):
            # cell by cell: a multiscale mesh's fine box, the area of interest, went black under its edges
            inches = np.prod(_picture_inches(ax, width, height, aspect)) / ((width or 1.0) * (height or 1.0))
            drawn = cells[np.abs(signed_areas(points, cells)) * inches * _EDGES_MAX_DENSITY > 1.0]
            edges = len(drawn) > 0
        rasterized = len(cells) > _RASTERIZE_ABOVE
        x, y = points[:, 0], points[:, 1]
        if color_by == "quality":
            colours = matplotlib.colormaps["viridis"].with_extremes(under="red")
            shaded = _cell_colours(ax, points, cells, quality, rasterized, cmap=colours, vmin=POOR_QUALITY, vmax=1.0)
            label = "element quality q" if metric is None else "element quality in the metric q"
            add_colorbar(ax, shaded, label=label, extend="min")
        elif color_by == "resolution":
            from matplotlib.colors import LogNorm

            from .sizes import _label_log_ticks

            low, high = float(field.min()), float(field.max())
            high = max(high, low * 1.001)  # a uniform mesh: a bar of one value has no range to draw
            shaded = _cell_colours(ax, points, cells, field, rasterized, cmap="viridis", norm=LogNorm(low, high))
            unit = "m" if geographic else units or "mesh units"
            _label_log_ticks(add_colorbar(ax, shaded, label=f"mean edge length ({unit})"), low, high)
        elif color_by is not None:
            shaded = ax.tripcolor(x, y, cells, field, shading="gouraud", cmap="viridis", rasterized=rasterized)
            label = "depth (m, positive down)" if color_by == "depth" else color_by
            add_colorbar(ax, shaded, label=label)
        if edges:
            ax.triplot(x, y, drawn, color="k", linewidth=0.15, rasterized=rasterized)
        ax.set_aspect(aspect)
        suffix = f" ({units})" if units else ""
        ax.set_xlabel("longitude (°)" if geographic else f"{axis_names[0]}{suffix}")
        ax.set_ylabel("latitude (°)" if geographic else f"{axis_names[1]}{suffix}")
        if not title:
            poor = int(np.count_nonzero(quality < POOR_QUALITY))
            title = f"{mesh.n_points:,} vertices, {mesh.n_cells:,} cells, mean q {quality.mean():.3f}"
            if poor:
                title += f", {poor:,} below {POOR_QUALITY:g}" + (" (red)" if color_by == "quality" else "")
        ax.set_title(title)
    return figure
