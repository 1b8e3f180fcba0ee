import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError
from terramesh.plot import plot_quality


def _cube():
    """A unit cube in 6 tetrahedra around its diagonal (Kuhn), positively oriented."""
    corners = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
    paths = [(1, 2, 4), (1, 4, 2), (2, 1, 4), (2, 4, 1), (4, 1, 2), (4, 2, 1)]  # the axes in each order, as bits
    cells = np.array([[0, p[0], p[0] + p[1], 7] for p in paths])
    volumes = tm.quality.tetra_volumes(corners, cells)
    cells[volumes < 0] = cells[volumes < 0][:, [1, 0, 2, 3]]
    return tm.Mesh(corners, cells)


def _legend_texts(ax):
    return [text.get_text() for text in ax.get_legend().get_texts()]


def test_a_triangle_mesh_histogram_marks_min_and_mean_and_counts_the_poor_cells(tmp_path, squashed_mesh):
    import matplotlib.colors
    import matplotlib.pyplot as plt

    mesh = squashed_mesh
    quality = tm.quality.triangle_quality(mesh.points, mesh.cells)
    figure = plot_quality(mesh, tmp_path / "quality.png")
    assert (tmp_path / "quality.png").read_bytes()[:4] == b"\x89PNG"
    ax = figure.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("triangle quality q", "cells")
    assert ax.get_title() == "120 triangles, 20 with q < 0.5"
    texts = _legend_texts(ax)
    assert texts == ["20 with q < 0.5 (17 %)", f"min q {quality.min():.3f}", f"mean q {quality.mean():.3f}"]
    marked = sorted(line.get_xdata()[0] for line in ax.lines)
    assert marked == pytest.approx(sorted([quality.min(), quality.mean()]))
    bars = ax.containers[0].patches  # the histogram (ax.patches also holds the span of poor q)
    heights = np.array([bar.get_height() for bar in bars])
    assert heights.sum() == 120 and ax.get_yscale() == "log"
    left = np.array([bar.get_x() for bar in bars])
    red = np.array([np.allclose(bar.get_facecolor(), matplotlib.colors.to_rgba("red")) for bar in bars])
    assert red[(left < 0.5) & (heights > 0)].all() and red[left < 0.5].any()  # as plot_mesh draws those cells
    assert not red[left >= 0.5].any()
    figure.canvas.draw()
    legend, axes_box = ax.get_legend().get_window_extent(), ax.get_window_extent()
    assert legend.x0 >= axes_box.x1  # beside the bars, on none of them
    assert figure.bbox.contains(legend.x1, legend.y0)
    plt.close(figure)


def test_a_tetrahedral_mesh_histogram_is_of_the_radius_ratio():
    import matplotlib.pyplot as plt

    mesh = _cube()
    ratio = tm.quality.radius_ratio(mesh.points, mesh.cells)
    figure, ax = plt.subplots()
    assert plot_quality(mesh, ax=ax, title="cube") is figure
    assert ax.get_xlabel() == "radius ratio 3 r_in / r_circ" and ax.get_title() == "cube"
    assert _legend_texts(ax) == [
        "0 slivers (dihedral < 10°) (0 %)",
        f"min ratio {ratio.min():.3f}",
        f"mean ratio {ratio.mean():.3f}",
    ]
    assert sum(bar.get_height() for bar in ax.containers[0]) == 6
    plt.close(figure)
    figure = plot_quality(mesh)
    assert figure.axes[0].get_title() == "6 tetrahedra, 0 slivers (dihedral < 10°)"
    plt.close(figure)


def test_inverted_cells_get_a_bar_below_zero():
    import matplotlib.pyplot as plt

    mesh = tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1], [1, 1]]), np.array([[0, 1, 2], [1, 2, 3]]))  # one clockwise
    figure = plot_quality(mesh)
    ax = figure.axes[0]
    assert ax.get_xlim()[0] <= -0.866 and sum(bar.get_height() for bar in ax.containers[0]) == 2
    assert ax.get_title() == "2 triangles, 1 with q < 0.5"
    plt.close(figure)


@pytest.mark.parametrize(
    "points, cells, message",
    [
        (np.eye(3), np.array([[0, 1, 2]]), "2-D triangles"),  # a surface in 3-D
        (np.zeros((0, 2)), np.zeros((0, 3), dtype=int), "at least one cell"),
    ],
    ids=["surface", "no cells"],
)
def test_plot_quality_refuses_what_it_cannot_measure_before_opening_a_figure(points, cells, message):
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(MeshValidityError, match=message):
        plot_quality(tm.Mesh(points, cells))
    assert plt.get_fignums() == open_before


def test_plot_quality_refuses_points_made_nan_after_the_mesh_checked_them(squashed_mesh):
    mesh = squashed_mesh
    mesh.points[3, 0] = np.nan
    with pytest.raises(MeshValidityError, match="NaN or infinite.*index 3"):
        plot_quality(mesh)


def test_an_anisotropic_mesh_is_measured_in_its_metric(tmp_path):
    import matplotlib.pyplot as plt

    square = tm.geometry.Rectangle((0, 0), (1, 1))
    metric = tm.sizing.metric_tensor(0.2, 0.04, 0.3)
    mesh = tm.generate_anisotropic_mesh(square, metric, seed=0)
    plain = plot_quality(mesh)
    assert plain.axes[0].get_title().endswith("with q < 0.5") and "0 with" not in plain.axes[0].get_title()
    figure = plot_quality(mesh, tmp_path / "metric.png", metric=metric)
    quality = tm.quality.metric_quality(mesh.points, mesh.cells, metric)
    ax = figure.axes[0]
    assert ax.get_xlabel() == "triangle quality in the metric q"
    assert f"mean q {quality.mean():.3f}" in _legend_texts(ax) and quality.mean() > 0.95
    picture = tm.plot.plot_mesh(mesh, metric=metric)
    assert picture.axes[0].collections[0].colorbar.ax.get_ylabel() == "element quality in the metric q"
    assert f"mean q {quality.mean():.3f}" in picture.axes[0].get_title()
    with pytest.raises(MeshValidityError, match="in a metric for 2-D triangles only"):
        plot_quality(_cube(), metric=metric)
    plt.close("all")


def test_a_mesh_without_poor_cells_fills_the_width():
    # min q 0.72 with the axis from 0 to 1: three quarters of the width empty
    import matplotlib.pyplot as plt

    x, y = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6), indexing="ij")
    index = np.arange(36).reshape(6, 6)
    a, b, c, d = index[:-1, :-1].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    mesh = tm.Mesh(np.c_[x.ravel(), y.ravel()], np.concatenate([np.c_[a, b, c], np.c_[a, c, d]]))  # q = 0.866
    figure = plot_quality(mesh)
    ax = figure.axes[0]
    assert ax.get_xlim() == pytest.approx((0.7, 1.0))  # a tenth below the minimum, rounded down to a tenth
    bars = ax.containers[0].patches
    assert sum(bar.get_height() for bar in bars) == 50 and min(bar.get_x() for bar in bars) >= 0.7 - 1e-9
    plt.close(figure)
