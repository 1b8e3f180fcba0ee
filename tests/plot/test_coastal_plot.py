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
    assert len(ax.images) == 1 and len(figure.axes) == 2  # the DEM and its colour bar
    assert "elevation" in figure.axes[1].get_ylabel()
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
