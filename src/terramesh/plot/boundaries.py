"""Draw a mesh's ADCIRC node strings: open, mainland and island boundaries over its faint edges."""

import numpy as np

from ..errors import MeshValidityError
from ..mesh.topology import checked_cells, checked_points
from ._checks import check_output_path
from ._figures import drawing, figure_size, laid_out, lonlat_aspect

__all__ = ["plot_boundaries"]

# colour per kind of string; islands and mainland told apart, as a modeller checks them
_STYLE = {
    "open": dict(color="tab:blue", linewidth=2.2),
    "mainland": dict(color="tab:brown", linewidth=1.2),
    "island": dict(color="tab:green", linewidth=1.2),
    "flux or barrier": dict(color="tab:purple", linewidth=1.2),
}
_ISLAND_IBTYPES = (1, 11, 21)  # no normal flow on an island (ADCIRC's fort.14 IBTYPE)
_MAINLAND_IBTYPES = (0, 10, 20)  # no normal flow on the mainland; the rest: fluxes, barriers
_START_LABEL = "start of an open string"

_LEGEND_DROP = 0.5
"""Inches from the axes' bottom edge down to the legend: below the tick labels and the axis label."""
_LEGEND_ROW = 0.25
"""Inches a created figure is made taller by for each of the legend's rows (two entries a row)."""


def _kind(ibtype):
    if ibtype in _ISLAND_IBTYPES:
        return "island"
    return "mainland" if ibtype in _MAINLAND_IBTYPES else "flux or barrier"


def _polyline(points, strings):
    """The node strings as one line's x and y, NaN between strings (one matplotlib artist per kind)."""
    pieces = [np.vstack([points[nodes], [np.nan, np.nan]]) for nodes in strings]
    xy = np.concatenate(pieces) if pieces else np.zeros((0, 2))
    return xy[:, 0], xy[:, 1]


def plot_boundaries(mesh, path=None, *, ax=None, title=None):
    """Draw the node strings of ``mesh.boundaries``: open in blue, mainland in brown, islands in green.

    The cells' edges are drawn faint beneath them, the first node of each
    open string marked with a dot, and the legend, under the axes where it
    hides no string, counts each kind's strings and nodes with their
    IBTYPEs and explains the dots (inside the axes, where it covers the
    least, in a caller's figure without a constrained layout): what a modeller looks at before the first
    run, where a wall across open water or an open string on land shows
    at a glance (:func:`~terramesh.coastal.make_boundaries`).

    Parameters
    ----------
    mesh : Mesh
        A 2-D triangle mesh with ``boundaries``
        (:func:`~terramesh.coastal.make_boundaries`, or read from a
        fort.14 or hgrid.gr3 file).
    path : str or os.PathLike, optional
        Save the figure there (PNG, SVG, PDF by extension; 150 dpi).
    ax : matplotlib.axes.Axes, optional
        Draw into these axes instead of a new figure.
    title : str, optional
        Axes title; defaults to the counts of open, land and island strings.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on, closed when made here and saved to ``path``
        (as :func:`plot_mesh`'s).

    Raises
    ------
    MeshValidityError
        For a mesh that is not 2-D triangles, has no boundaries, or whose
        strings name vertices it does not have.
    FileNotFoundError
        For a ``path`` in a directory that does not exist (nothing is drawn).
    MeshFormatError
        For a ``path`` whose extension matplotlib cannot write (nothing is drawn).

    Examples
    --------
    >>> import terramesh as tm
    >>> import matplotlib.pyplot as plt
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.25, seed=0)
    >>> mesh = tm.coastal.make_boundaries(mesh, bbox=(-1, 2, -1, 2), open_by="bbox")
    >>> figure = plot_boundaries(mesh)
    >>> [text.get_text() for text in figure.axes[0].get_legend().get_texts()]
    ['open: 1 string, 6 nodes (IBTYPEE 0)', 'start of an open string', 'mainland: 1 string, 22 nodes (IBTYPE 20)']
    >>> plt.close(figure)
    """
    check_output_path(path)
    if getattr(mesh, "boundaries", None) is None:
        raise MeshValidityError(
            "the mesh has no boundaries to draw: make them (tm.coastal.make_boundaries) or read a fort.14 that has them"
        )
    points = checked_points(mesh.points, 2)
    cells = checked_cells(mesh.cells, 3, len(points))
    strings = list(mesh.boundaries.open) + list(mesh.boundaries.land)
    for string in strings:
        if len(string.nodes) and (np.min(string.nodes) < 0 or np.max(string.nodes) >= len(points)):
            raise MeshValidityError(
                f"a boundary string names vertex {int(np.max(string.nodes))}; the mesh has {len(points)}"
            )
    lo, hi = points.min(axis=0), points.max(axis=0)
    aspect = lonlat_aspect(lo[1], hi[1]) if mesh.geographic else "equal"
    created = ax is None
    if created:
        import matplotlib.pyplot as plt

        width, height = figure_size(hi[0] - lo[0], hi[1] - lo[1], aspect, colorbar=False, labels=True)
        entries = 1 + len({_kind(land.ibtype) for land in mesh.boundaries.land}) + bool(len(mesh.boundaries.open))
        rows = (entries + 1) // 2
        figure, ax = plt.subplots(figsize=(width, height + rows * _LEGEND_ROW + 0.1), layout="constrained")
    figure = ax.figure
    with drawing(figure, path, created=created):
        if len(cells):
            ax.triplot(points[:, 0], points[:, 1], cells, color="0.8", linewidth=0.2, rasterized=len(cells) > 20_000)
        kinds = {"open": [s for s in mesh.boundaries.open]}
        for land in mesh.boundaries.land:
            kinds.setdefault(_kind(land.ibtype), []).append(land)
        for kind in _STYLE:
            group = kinds.get(kind, [])
            if not group:
                continue
            x, y = _polyline(points, [string.nodes for string in group])
            nodes = sum(len(string.nodes) for string in group)
            types = sorted({int(string.ibtype) for string in group if string.ibtype is not None})
            named = "IBTYPEE" if kind == "open" else "IBTYPE"
            label = f"{kind}: {len(group)} string{'s' if len(group) > 1 else ''}, {nodes:,} nodes"
            label += f" ({named} {', '.join(map(str, types))})" if types else ""
            ax.plot(x, y, label=label, **_STYLE[kind])
            if kind == "open":  # where each open string starts: its direction, and two strings that meet
                starts = points[[string.nodes[0] for string in group if len(string.nodes)]]
                ax.plot(starts[:, 0], starts[:, 1], "o", color=_STYLE[kind]["color"], markersize=4, label=_START_LABEL)
        ax.set_aspect(aspect)
        ax.set_xlabel("longitude (°)" if mesh.geographic else "x")
        ax.set_ylabel("latitude (°)" if mesh.geographic else "y")
        if ax.get_legend_handles_labels()[0] and laid_out(figure):
            # under the axes, as plot_shoreline's: at loc="best" it covered boundary strings
            from matplotlib.transforms import ScaledTranslation

            below = ax.transAxes + ScaledTranslation(0.0, -_LEGEND_DROP, figure.dpi_scale_trans)
            ax.legend(
                loc="upper center",
                bbox_to_anchor=(0.5, 0.0),
                bbox_transform=below,
                ncols=2,
                fontsize="small",
                frameon=False,
            )
        elif ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best", fontsize="small")  # a caller's figure, no room made below the axes
        if not title:
            islands = len(kinds.get("island", []))
            title = (
                f"{len(kinds['open'])} open, {len(strings) - len(kinds['open']) - islands} land and"
                f" {islands} island strings"
            )
        ax.set_title(title)
    return figure
