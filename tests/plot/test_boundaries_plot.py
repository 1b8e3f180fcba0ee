"""plot_boundaries: each kind of node string drawn along its nodes, counted in the legend; bad input refused."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError
from terramesh.plot.boundaries import plot_boundaries


@pytest.fixture(scope="module")
def plate():
    """A 2 x 1 rectangle with a round island, open on its east side (the bbox's edge)."""
    domain = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (2, 1)), tm.geometry.Disk((1.0, 0.5), 0.2)])
    mesh = tm.generate_mesh(domain, 0.1, seed=0)
    return tm.coastal.make_boundaries(mesh, bbox=(-1, 2, -1, 2), open_by="bbox")


def test_each_kind_is_drawn_along_its_nodes_and_counted(plate, tmp_path):
    import matplotlib.pyplot as plt

    figure = plot_boundaries(plate, tmp_path / "boundaries.png")
    assert (tmp_path / "boundaries.png").stat().st_size > 10_000
    ax = figure.axes[0]
    texts = [text.get_text() for text in ax.get_legend().get_texts()]
    b = plate.boundaries
    assert texts == [
        f"open: 1 string, {len(b.open[0].nodes)} nodes (IBTYPEE 0)",
        "start of an open string",  # the dots explained
        f"mainland: 1 string, {len(b.land[0].nodes)} nodes (IBTYPE 20)",
        f"island: 1 string, {len(b.land[1].nodes)} nodes (IBTYPE 21)",
    ]
    (dots,) = [line for line in ax.lines if line.get_label() == "start of an open string"]
    assert np.allclose(dots.get_xydata(), plate.points[[b.open[0].nodes[0]]]) and dots.get_marker() == "o"
    lines = {line.get_label(): line for line in ax.lines}
    open_line = lines[texts[0]]
    x = open_line.get_xdata()
    assert np.allclose(x[np.isfinite(x)], 2.0)  # the east side, node by node
    island = lines[texts[3]].get_xydata()
    island = island[np.isfinite(island).all(axis=1)]
    assert np.allclose(np.hypot(island[:, 0] - 1.0, island[:, 1] - 0.5), 0.2, atol=1e-9)
    assert ax.get_title() == "1 open, 1 land and 1 island strings"
    plt.close(figure)


def test_a_mesh_without_boundaries_or_with_strings_past_its_vertices_is_refused(plate):
    bare = tm.Mesh(plate.points, plate.cells)
    with pytest.raises(MeshValidityError, match="no boundaries to draw: make them"):
        plot_boundaries(bare)
    broken = tm.Mesh(plate.points[:-5], plate.cells[np.all(plate.cells < len(plate.points) - 5, axis=1)])
    broken.boundaries = plate.boundaries
    with pytest.raises(MeshValidityError, match="names vertex"):
        plot_boundaries(broken)


def test_the_legend_lies_under_the_axes_covering_no_string(plate, tmp_path):
    # at loc="best" it covered boundary strings
    import matplotlib.pyplot as plt

    figure = plot_boundaries(plate, tmp_path / "boundaries.png")
    figure.canvas.draw()
    ax = figure.axes[0]
    legend, axes_box = ax.get_legend().get_window_extent(), ax.get_window_extent()
    labels = ax.xaxis.label.get_window_extent()
    assert legend.y1 <= labels.y0 + 1 and legend.y1 < axes_box.y0  # under the x label, off the picture
    assert figure.bbox.contains(legend.x0, legend.y0) and figure.bbox.contains(legend.x1, legend.y1)
    plt.close(figure)
    figure, ax = plt.subplots()  # a caller's figure with no room made below: inside, as before
    plot_boundaries(plate, ax=ax)
    assert ax.get_legend() is not None
    plt.close(figure)
