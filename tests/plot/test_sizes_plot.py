import numpy as np
import pytest
import shapely

from terramesh.coastal import GeoGrid
from terramesh.errors import GeometryError, SizingError
from terramesh.plot.sizes import plot_size_field


@pytest.fixture
def field():
    grid = GeoGrid((10.0, 11.0, 55.0, 55.8), 5e3)
    lon, lat = grid.lonlat()
    sizes = 200.0 + 30e3 * np.hypot(lon - 10.5, lat - 55.4)
    sizes[lon < 10.2] = np.inf  # unconstrained
    return grid, sizes


def test_plot_writes_png_with_coastline(tmp_path, field):
    import matplotlib.pyplot as plt

    grid, sizes = field
    path = tmp_path / "sizes.png"
    coast = shapely.MultiPolygon([shapely.box(10.0, 55.0, 10.3, 55.3), shapely.box(10.7, 55.5, 12, 57)])
    figure = plot_size_field(grid, sizes, path, coastline=coast, title="test field")
    data = path.read_bytes()
    assert data[:4] == b"\x89PNG" and len(data) > 10_000
    ax = figure.axes[0]
    assert ax.get_title() == "test field"
    assert ax.get_xlim() == pytest.approx((grid.lon[0], grid.lon[-1]))
    assert ax.get_aspect() == pytest.approx(1 / np.cos(np.radians(0.5 * (grid.lat[0] + grid.lat[-1]))))
    assert len(ax.collections) == 2  # the field and the coastline
    assert "km" in figure.axes[1].get_ylabel() and "unconstrained" in figure.axes[1].get_ylabel()
    assert np.isinf(sizes).any()  # the caller's array is not modified
    plt.close(figure)


def test_plot_in_metres_into_given_axes(field):
    import matplotlib.pyplot as plt

    grid, _ = field
    figure, ax = plt.subplots()
    assert plot_size_field(grid, np.full(grid.shape, 500.0), ax=ax) is figure
    assert "(m)" in figure.axes[1].get_ylabel()
    assert ax.get_title().startswith("edge length")
    plt.close(figure)


def test_plot_of_an_unconstrained_field(field):
    import matplotlib.pyplot as plt

    grid, _ = field
    figure = plot_size_field(grid, np.full(grid.shape, np.inf))
    assert figure.axes[0].get_title() == "no finite edge length"
    plt.close(figure)


def test_plot_refuses_bad_input(field):
    grid, sizes = field
    with pytest.raises(SizingError, match="shape"):
        plot_size_field(grid, sizes[1:])
    with pytest.raises(GeometryError, match="coastline"):
        plot_size_field(grid, sizes, coastline=[(0, 0), (1, 1)])


def test_title_of_a_uniform_field_gives_its_size(field):
    import matplotlib.pyplot as plt

    grid, _ = field
    figure = plot_size_field(grid, np.full(grid.shape, 500.0))
    assert figure.axes[0].get_title() == "edge length 500 m"
    norm = figure.axes[0].collections[0].norm  # a colour range around the one value, as before
    assert (norm.vmin, norm.vmax) == pytest.approx((500 / 1.1, 550))
    plt.close(figure)


def test_title_and_colours_span_the_whole_field_when_it_is_drawn_strided():
    import matplotlib.pyplot as plt

    grid = GeoGrid((10.0, 11.0, 55.0, 55.02), 30.0)
    assert max(grid.shape) > 1500  # drawn every 2nd node
    sizes = np.full(grid.shape, 1000.0)
    sizes[1, 5] = 100.0  # a node the picture skips
    sizes[:, 0] = np.inf
    figure = plot_size_field(grid, sizes)
    assert figure.axes[0].get_title() == "edge length 100 to 1e+03 m"
    norm = figure.axes[0].collections[0].norm
    assert (norm.vmin, norm.vmax) == (100.0, 1000.0)
    plt.close(figure)


def test_plot_refuses_a_missing_directory_before_drawing(tmp_path, field):
    import matplotlib.pyplot as plt

    grid, sizes = field
    open_before = plt.get_fignums()
    with pytest.raises(FileNotFoundError, match="directory .*nowhere.* does not exist"):
        plot_size_field(grid, sizes, tmp_path / "nowhere" / "sizes.png")
    assert plt.get_fignums() == open_before
