import numpy as np
import pytest
import shapely

from terramesh.coastal.dem import DEM
from terramesh.coastal.shoreline import Shoreline
from terramesh.errors import GeometryError
from terramesh.plot.coastal import plot_shoreline


@pytest.fixture(scope="module")
def bay():
    """A small DEM: land to the west with an island offshore, sea to the east."""
    lon, lat = np.linspace(-70.0, -69.8, 81), np.linspace(42.0, 42.2, 81)
    x, y = np.meshgrid(lon, lat, indexing="ij")
    z = -2000.0 * (x + 69.92) + 300.0 * np.exp(-((x + 69.85) ** 2 + (y - 42.1) ** 2) / 0.0002)
    dem = DEM(lon, lat, z)
    return dem, Shoreline.from_dem(dem, min_edge_length=300.0)


def test_plot_writes_png_with_the_classes(tmp_path, bay):
    import matplotlib.pyplot as plt

    dem, shore = bay
    assert len(shore.islands.geoms) == 1 and len(shore.mainland.geoms) == 1
    path = tmp_path / "shore.png"
    figure = plot_shoreline(shore, dem, path, title="bay")
    assert path.stat().st_size > 10_000 and path.read_bytes()[:4] == b"\x89PNG"
    ax = figure.axes[0]
    assert [text.get_text() for text in ax.get_legend().get_texts()] == ["mainland", "islands", "open boundary"]
    assert ax.get_title() == "bay"
    assert ax.get_aspect() == pytest.approx(1.0 / np.cos(np.radians(42.1)))
    assert len(ax.images) == 1 and ax.images[0].colorbar is not None  # the DEM and its colour bar
    assert "elevation" in ax.images[0].colorbar.ax.get_ylabel()
    assert ax.get_xlabel() == "longitude (°)" and ax.get_ylabel() == "latitude (°)"
    plt.close(figure)


def _overlap(box, other):
    """Whether two display boxes share some area."""
    return box.x0 < other.x1 and other.x0 < box.x1 and box.y0 < other.y1 and other.y0 < box.y1


@pytest.mark.parametrize(
    "with_dem, callers", [(True, False), (False, False), (True, True)], ids=["over a DEM", "alone", "caller's axes"]
)
def test_the_legend_covers_nothing(bay, with_dem, callers):
    # loc="best" put it on the coastline, in the middle of the South Island picture
    import matplotlib.pyplot as plt

    dem, shore = bay
    if callers:  # laid out as the figures made here are: room is made below the axes
        figure, ax = plt.subplots(figsize=(6.0, 7.0), layout="constrained")
        plot_shoreline(shore, dem if with_dem else None, ax=ax)
    else:
        figure = plot_shoreline(shore, dem if with_dem else None)
    figure.canvas.draw()
    ax = figure.axes[0]
    legend = ax.get_legend().get_window_extent()
    assert not _overlap(legend, ax.get_window_extent())  # not on the picture
    for text in [ax.xaxis.label, *ax.get_xticklabels()]:  # nor on the axis under it
        assert not _overlap(legend, text.get_window_extent())
    figure_box = figure.bbox
    assert figure_box.y0 <= legend.y0 and legend.x0 >= figure_box.x0 and legend.x1 <= figure_box.x1  # all seen
    if with_dem:
        assert not _overlap(legend, ax.images[0].colorbar.ax.get_window_extent())
    plt.close(figure)


def test_plot_into_given_axes_without_dem():
    import matplotlib.pyplot as plt

    shore = Shoreline(shapely.box(-1.0, -1.0, 0.0, 1.0), (-0.5, 0.5, -0.5, 0.5), 5000.0)
    figure, ax = plt.subplots()
    assert plot_shoreline(shore, ax=ax) is figure
    assert [text.get_text() for text in ax.get_legend().get_texts()] == ["mainland", "open boundary"]
    assert len(ax.images) == 0 and "1 mainland, 0 islands" in ax.get_title()
    plt.close(figure)


def test_plot_refuses_what_is_not_a_shoreline_or_a_dem(bay):
    dem, shore = bay
    with pytest.raises(GeometryError, match="shoreline must be a terramesh.coastal.Shoreline, got Polygon"):
        plot_shoreline(shore.land.geoms[0], dem)
    with pytest.raises(GeometryError, match="dem must be a terramesh.coastal.DEM or None, got ndarray"):
        plot_shoreline(shore, dem.elevation)


def test_plot_refuses_a_missing_directory_before_drawing(tmp_path, bay):
    import matplotlib.pyplot as plt

    dem, shore = bay
    open_before = plt.get_fignums()
    with pytest.raises(FileNotFoundError, match="directory .*nowhere.* does not exist"):
        plot_shoreline(shore, dem, str(tmp_path / "nowhere" / "shore.png"))
    assert plt.get_fignums() == open_before
