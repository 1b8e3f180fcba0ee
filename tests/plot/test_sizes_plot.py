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
    label = ax.collections[0].colorbar.ax.get_ylabel()
    assert "km" in label and "unconstrained" in label
    assert ax.get_xlabel() == "longitude (°)" and ax.get_ylabel() == "latitude (°)"
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


def test_plot_of_an_unconstrained_field_is_grey_without_a_colour_bar(field):
    # a channel field that found no channel got a made-up colour bar around 1 m, and the caller's title alone
    import matplotlib.pyplot as plt

    grid, _ = field
    figure = plot_size_field(grid, np.full(grid.shape, np.inf))
    ax = figure.axes[0]
    assert ax.get_title() == "no finite edge length"
    assert ax.collections[0].colorbar is None and not ax.child_axes and len(figure.axes) == 1
    plt.close(figure)
    figure = plot_size_field(grid, np.full(grid.shape, np.inf), title="size function ch")
    assert figure.axes[0].get_title() == "size function ch: no finite edge length"
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
    sizes[1:60:2, :] = 100.0  # 1.4 % of the nodes, all skipped by the picture (more than an outlier)
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


def _drawn_colorbar(figure):
    """The colour bar of the figure's picture, after a draw (ticks and positions are laid out then)."""
    figure.canvas.draw()
    return figure.axes[0].collections[0].colorbar


def test_a_few_tiny_sizes_do_not_give_the_rest_of_the_field_one_colour(field):
    # a wavelength field with 1e-18 m at zero depth: the scale ran over 20 decades, the sea one yellow
    import matplotlib.pyplot as plt

    grid, sizes = field
    sizes = sizes.copy()
    sizes[5, 5] = 1e-18  # one node of 266: under 0.5 % of them
    finite = sizes[np.isfinite(sizes)]
    figure = plot_size_field(grid, sizes)
    norm = figure.axes[0].collections[0].norm
    assert norm.vmin == pytest.approx(np.percentile(finite, 0.5) / 1e3)  # km
    assert norm.vmin > 0.1 and norm.vmax == pytest.approx(finite.max() / 1e3)
    assert _drawn_colorbar(figure).extend == "min"  # the bar says some sizes are below its colours
    assert figure.axes[0].get_title().startswith("edge length 1e-21 to")  # the title keeps the true range
    plt.close(figure)


def test_a_field_without_outliers_gets_its_whole_range_coloured(field):
    # the smallest size (200 m, one node) is within a factor 2 of the 0.5th percentile: no outlier to leave out
    import matplotlib.pyplot as plt

    grid, sizes = field
    figure = plot_size_field(grid, sizes)
    finite = sizes[np.isfinite(sizes)]
    assert finite.min() < np.percentile(finite, 0.5) < 2 * finite.min()
    assert _drawn_colorbar(figure).extend == "neither"
    assert figure.axes[0].collections[0].norm.vmin == pytest.approx(finite.min() / 1e3)
    plt.close(figure)


@pytest.mark.parametrize(
    "low, high",
    [(300.0, 8000.0), (2000.0, 9000.0), (500.0, 600.0), (500.0, 500.0), (1.0, 1e6), (108.6, 490.3)],
    ids=["1.4 decades", "0.65 decades", "a fifth more", "uniform", "6 decades", "0.65 decades, one 2 or 5"],
)
def test_a_log_colour_bar_has_three_plain_labels_or_more(low, high):
    # labelled at decades only: a bar from 0.3 to 8 km had the one label 10^0
    import matplotlib.pyplot as plt

    grid = GeoGrid((10.0, 11.0, 55.0, 55.8), 5e3)
    lon, _ = grid.lonlat()
    sizes = low + (high - low) * (lon - lon.min()) / np.ptp(lon)
    figure = plot_size_field(grid, sizes)
    colorbar = _drawn_colorbar(figure)
    vmin, vmax = colorbar.norm.vmin, colorbar.norm.vmax
    ticks = colorbar.ax.get_yticks()
    shown = ticks[(ticks >= vmin * (1 - 1e-9)) & (ticks <= vmax * (1 + 1e-9))]
    assert len(shown) >= 3, (vmin, vmax, ticks)
    labels = [label.get_text() for label in colorbar.ax.get_yticklabels() if label.get_text()]
    assert len(labels) >= 3 and not any("^" in label for label in labels), labels  # 0.5, 1, 2: not 10^0
    # and apart: 150, 200, ..., 450 (evenly spaced, crowding the top of a log bar) overlapped
    boxes = sorted(
        (label.get_window_extent() for label in colorbar.ax.get_yticklabels() if label.get_text()),
        key=lambda box: box.y0,
    )
    assert all(lower.y1 <= upper.y0 for lower, upper in zip(boxes[:-1], boxes[1:], strict=True)), labels
    plt.close(figure)


def test_a_shoreline_is_drawn_as_its_coastline(field):
    import matplotlib.pyplot as plt

    from terramesh.coastal import Shoreline

    grid, sizes = field
    land = shapely.MultiPolygon([shapely.box(9.0, 54.0, 10.3, 55.3), shapely.box(10.6, 55.1, 10.8, 55.3)])
    shoreline = Shoreline(land, (10.0, 11.0, 55.0, 55.8), 5e3)
    figure = plot_size_field(grid, sizes, coastline=shoreline)
    segments = figure.axes[0].collections[1].get_segments()
    drawn = np.concatenate(segments)
    assert len(segments) == 2 and np.allclose(drawn.min(axis=0), [10.0, 55.0]) and drawn[:, 0].max() == 10.8
    plt.close(figure)
