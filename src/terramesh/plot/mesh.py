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

_EDGES_SMOOTHING = 3
"""Rounds of neighbourhood averaging (cells to vertices to cells) before ``edges="auto"`` outlines a cell.

Cell by cell, a 17k-vertex seismic mesh got its 57 largest cells
outlined, a few dozen scattered black triangles and hexagons that looked
like flagged bad cells. A cell is outlined where at least half of its
neighbourhood (three rings of cells) is large enough: clusters of a few
cells fade out, the coarse part of a graded mesh keeps its edges.
"""

_EDGES_MIN_SHARE = 0.05
"""Share of the mesh's area the outlined cells must cover, else ``edges="auto"`` outlines none: specks read as flags."""

_FIELD_LABELS = {
    "depth": "depth (m, positive down)",
    "elevation": "elevation (m, positive up)",
    "velocity": "velocity (m/s)",
    "vp": "P-wave velocity (m/s)",
    "vs": "S-wave velocity (m/s)",
}
"""Colour bar labels, with units, of the ``point_data`` names terramesh writes; other names are written as they are."""

_CLIP_PERCENTILES = (0.5, 99.5)
"""Percentiles of a vertex field between which its colours run, where values lie far beyond them (outliers)."""
_CLIP_TAIL = 1.0
"""How many times the range between those percentiles a tail must reach beyond them to be clipped."""

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


def _auto_edges(points, cells, inches_per_area):
    """Cells whose edges ``edges="auto"`` draws: those large on the picture, where most of their neighbours are.

    A cell passes when it is at least 1/1,000 square inch on the picture
    (:data:`_EDGES_MAX_DENSITY`). The passes are averaged over each
    vertex's cells and back over each cell's vertices,
    :data:`_EDGES_SMOOTHING` times, and the cells scoring at least one half
    are outlined; none are unless they cover :data:`_EDGES_MIN_SHARE` of
    the mesh's area.
    """
    areas = np.abs(signed_areas(points, cells))
    score = (areas * inches_per_area * _EDGES_MAX_DENSITY > 1.0).astype(np.float64)
    if not score.any():
        return cells[:0]
    corners = cells.ravel()
    counts = np.maximum(np.bincount(corners, minlength=len(points)), 1)
    for _ in range(_EDGES_SMOOTHING):
        vertex_score = np.bincount(corners, weights=np.repeat(score, 3), minlength=len(points)) / counts
        score = vertex_score[cells].mean(axis=1)
    outlined = score >= 0.5
    if areas[outlined].sum() < _EDGES_MIN_SHARE * areas.sum():
        return cells[:0]
    return cells[outlined]


def _field_limits(values):
    """Colour limits of a vertex field and its bar's ``extend``: the percentiles where outliers lie far beyond them.

    One vertex at 1e9 in a 1.5-4.8 km/s velocity field drew every other
    vertex one colour. A tail reaching beyond the 0.5th or 99.5th
    percentile by more than the range between them is clipped there (its
    vertices get the end colours, the bar a pointed end); a smooth field
    keeps its whole range.
    """
    low, high = float(values.min()), float(values.max())
    floor, ceiling = (float(v) for v in np.percentile(values, _CLIP_PERCENTILES))
    span = ceiling - floor
    below = floor - low > _CLIP_TAIL * span and span > 0
    above = high - ceiling > _CLIP_TAIL * span and span > 0
    vmin, vmax = (floor if below else low), (ceiling if above else high)
    if vmax <= vmin:  # a uniform field: a bar of one value has no range to draw
        pad = max(abs(vmin) * 1e-3, 1e-12)
        vmin, vmax = vmin - pad, vmax + pad
    extend = {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}
    return vmin, vmax, extend[below, above]


def _depth_colours(vmin, vmax):
    """Colour map and norm of a depth field (metres, positive down): blues in the water, land colours above it.

    Plain viridis over -100..+45 m drew the deep water yellow and the dry
    ground purple, with nothing at 0 m. The blues and land colours of
    :func:`~terramesh.plot.plot_shoreline`'s DEM meet at 0 m; each side
    gets its own half of the bar (a ``TwoSlopeNorm``), a field all wet or
    all dry the colours of its side only.
    """
    import matplotlib.colors

    from .coastal import land_colours, sea_colours

    sea, land = sea_colours()[::-1], land_colours()[::-1]  # positive down: deep water dark at the top
    if vmin < 0.0 < vmax:
        colours = matplotlib.colors.ListedColormap(np.vstack([land, sea]), name="terramesh_depth")
        return colours, matplotlib.colors.TwoSlopeNorm(vcenter=0.0, vmin=vmin, vmax=vmax)
    side = sea if vmin >= 0.0 else land
    return matplotlib.colors.ListedColormap(side, name="terramesh_depth"), matplotlib.colors.Normalize(vmin, vmax)


def _number(value):
    """``value`` as a title writes it: ``"4,790"``, ``"45.1"``, ``"0.0123"`` (no exponent below a billion)."""
    if 1e3 <= abs(value) < 1e9:
        return f"{value:,.0f}"
    return f"{value:.3g}"


def _range_text(values):
    """A field's range as the title writes it: ``"-102 to 45.1"``, ``"1,429 to 4,790"``."""
    low, high = float(values.min()), float(values.max())
    return _number(low) if high == low else f"{_number(low)} to {_number(high)}"


def _counted(count, one, many):
    """``"1 cell"``, ``"2 cells"``: a one-cell mesh's title said "1 cells"."""
    return f"{count:,} {one if count == 1 else many}"


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
    label=None,
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
        Axes title; defaults, for a quality map or edges only, to the
        counts, the mean quality and the number of poor cells (q < 0.5), if
        any; for a resolution or vertex-field map, to the colour bar's label
        and the field's whole range (``"depth (m, positive down): -12 to 45"``).
    color_by : {"quality", "resolution"}, a ``point_data`` name, or None
        Fill cells by quality; by ``"resolution"``, each cell's mean edge
        length (ground metres for a geographic mesh, else the mesh's units;
        a log scale); by a vertex field of ``mesh.point_data``, shaded
        between the vertices (``"depth"``, metres positive down, the
        bathymetry on the mesh: blues in the water, land colours on dry
        ground, meeting at 0 m); or draw edges only.
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
        colours. It decides by neighbourhood, not cell by cell: a cell is
        outlined where most cells around it are that large, and none are
        unless they make up 5 % of the mesh's area, so that a few large
        cells scattered over a fine mesh are not outlined like flags. With
        ``color_by=None`` the edges are the picture: always drawn.
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
    label : str, optional
        The colour bar's label, with the field's unit (``"vp (km/s)"``).
        Defaults: ``"depth (m, positive down)"``, ``"elevation (m, positive
        up)"``, ``"velocity (m/s)"``, ``"vp"`` and ``"vs"`` in m/s, the
        quality's or the mean edge length's; any other ``point_data`` name
        as it is.

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
    stand out, and circled in red, since they are often too small on the
    picture to be seen (:func:`~terramesh.plot.plot_quality` gives their
    distribution). A vertex field's colours run over its whole range, or
    between its 0.5th and 99.5th percentiles where a tail reaches beyond
    one of them by more than the range between them (one vertex at 1e9 in
    a velocity field): the outliers get the end colour, the bar a pointed
    end, the title the whole range. Axes are
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
    >>> mesh.point_data["velocity"] = 1500.0 + 1000.0 * (mesh.points[:, 0] - 10.0)
    >>> figure = plot_mesh(mesh, color_by="velocity")
    >>> figure.axes[0].get_title()
    'velocity (m/s): 1,500 to 1,900'
    >>> plt.close("all")
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
        import matplotlib.colors

        drawn = cells
        if color_by is None:
            edges = True
        elif isinstance(edges, str):
            # by neighbourhood: a multiscale mesh's fine box, the area of interest, went black under its edges
            # when the whole mesh decided, and a seismic mesh's few largest cells were outlined like flags
            # when each cell decided alone
            inches = np.prod(_picture_inches(ax, width, height, aspect)) / ((width or 1.0) * (height or 1.0))
            drawn = _auto_edges(points, cells, inches)
            edges = len(drawn) > 0
        rasterized = len(cells) > _RASTERIZE_ABOVE
        x, y = points[:, 0], points[:, 1]
        poor = quality < POOR_QUALITY
        if color_by == "quality":
            colours = matplotlib.colormaps["viridis"].with_extremes(under="red")
            shaded = _cell_colours(ax, points, cells, quality, rasterized, cmap=colours, vmin=POOR_QUALITY, vmax=1.0)
            default = "element quality q" if metric is None else "element quality in the metric q"
            add_colorbar(ax, shaded, label=label or default, extend="min")
        elif color_by == "resolution":
            from matplotlib.colors import LogNorm

            from .sizes import label_log_ticks

            low, high = float(field.min()), float(field.max())
            high = max(high, low * 1.001)  # a uniform mesh: a bar of one value has no range to draw
            shaded = _cell_colours(ax, points, cells, field, rasterized, cmap="viridis", norm=LogNorm(low, high))
            unit = "m" if geographic else units or "mesh units"
            label = label or f"mean edge length ({unit})"
            label_log_ticks(add_colorbar(ax, shaded, label=label), low, high)
        elif color_by is not None:
            vmin, vmax, extend = _field_limits(field)
            if color_by == "depth":
                colours, norm = _depth_colours(vmin, vmax)
            else:
                colours, norm = matplotlib.colormaps["viridis"], matplotlib.colors.Normalize(vmin, vmax)
            shaded = ax.tripcolor(x, y, cells, field, shading="gouraud", cmap=colours, norm=norm, rasterized=rasterized)
            label = label or _FIELD_LABELS.get(color_by, color_by)
            add_colorbar(ax, shaded, label=label, extend=extend)
        if edges:
            ax.triplot(x, y, drawn, color="k", linewidth=0.15, rasterized=rasterized)
        if color_by == "quality" and poor.any():
            # a poor cell is often a pixel or two: its red alone does not show where the title counts it
            centroids = points[cells[poor]].mean(axis=1)
            ax.plot(
                centroids[:, 0],
                centroids[:, 1],
                linestyle="none",
                marker="o",
                markersize=6,
                markerfacecolor="none",
                markeredgecolor="red",
                markeredgewidth=1.0,
                gid="poor cells",
                rasterized=rasterized,
            )
        ax.set_aspect(aspect)
        suffix = f" ({units})" if units else ""
        ax.set_xlabel("longitude (°)" if geographic else f"{axis_names[0]}{suffix}")
        ax.set_ylabel("latitude (°)" if geographic else f"{axis_names[1]}{suffix}")
        if not title and field is not None:
            # a depth or velocity map is read for its values: "mean q" over it read as the field's
            title = f"{label}: {_range_text(field)}"
        elif not title:
            count = int(np.count_nonzero(poor))
            title = (
                f"{_counted(mesh.n_points, 'vertex', 'vertices')}, {_counted(mesh.n_cells, 'cell', 'cells')},"
                f" mean q {quality.mean():.3f}"
            )
            if count:
                title += f", {count:,} below {POOR_QUALITY:g}" + (" (red, circled)" if color_by == "quality" else "")
        ax.set_title(title)
    return figure
