"""The figures the plotting functions open: closed once saved, filled by the picture, titled in good English."""

import io

import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh.coastal import GeoGrid
from terramesh.coastal.dem import DEM
from terramesh.coastal.shoreline import Shoreline
from terramesh.errors import MeshFormatError
from terramesh.plot import plot_mesh, plot_quality, plot_shoreline, plot_size_field
from terramesh.plot._figures import figure_size


def _mesh():
    return tm.generate_mesh(tm.geometry.Rectangle((10.0, 55.0), (10.4, 55.2)), 0.05, seed=0)


def _shoreline():
    return Shoreline(shapely.box(-1.0, -1.0, 0.0, 1.0), (-0.5, 0.5, -0.5, 0.5), 5000.0)


def _size_field():
    grid = GeoGrid((10, 11, 55, 56), 5e3)
    return grid, np.full(grid.shape, 800.0)


PLOTS = {
    "plot_mesh": lambda path, **options: plot_mesh(_mesh(), path, **options),
    "plot_quality": lambda path, **options: plot_quality(_mesh(), path, **options),
    "plot_shoreline": lambda path, **options: plot_shoreline(_shoreline(), None, path, **options),
    "plot_size_field": lambda path, **options: plot_size_field(*_size_field(), path, **options),
}


@pytest.mark.parametrize("name", PLOTS)
def test_a_figure_saved_to_a_path_is_closed_and_still_returned(tmp_path, name):
    # pyplot kept every figure open: 22 calls warned "More than 20 figures have been opened"
    import matplotlib.pyplot as plt

    plot = PLOTS[name]
    open_before = plt.get_fignums()
    for number in range(3):
        figure = plot(tmp_path / f"{number}.png")
        assert plt.get_fignums() == open_before
    assert (tmp_path / "2.png").read_bytes()[:4] == b"\x89PNG"
    assert figure.axes[0].get_title()  # the docstrings' Figure, still readable and savable
    figure.savefig(tmp_path / "again.png")
    assert (tmp_path / "again.png").stat().st_size > 1000


@pytest.mark.parametrize("name", PLOTS)
def test_a_figure_without_a_path_or_of_the_callers_axes_stays_open(name):
    import matplotlib.pyplot as plt

    plot = PLOTS[name]
    figure = plot(None)
    assert plt.fignum_exists(figure.number)  # for the caller to show or draw on
    plt.close(figure)
    mine, ax = plt.subplots()
    assert plot(io.BytesIO(), ax=ax) is mine
    assert plt.fignum_exists(mine.number)  # the caller's, saved or not
    plt.close(mine)


@pytest.mark.parametrize("name", PLOTS)
def test_a_figure_that_fails_to_save_is_closed(tmp_path, monkeypatch, name):
    import matplotlib.figure
    import matplotlib.pyplot as plt

    def full_disk(self, *args, **kwargs):
        raise OSError("No space left on device")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", full_disk)
    open_before = plt.get_fignums()
    with pytest.raises(OSError, match="No space left"):
        PLOTS[name](tmp_path / "picture.png")
    assert plt.get_fignums() == open_before


@pytest.mark.parametrize("name", PLOTS)
def test_an_extension_matplotlib_cannot_write_is_refused_before_drawing(tmp_path, name):
    # "m.xyz" was drawn, then refused by savefig, the figure left open
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(MeshFormatError, match="matplotlib writes no 'xyz' files; use one of .*png"):
        PLOTS[name](tmp_path / "picture.xyz")
    assert plt.get_fignums() == open_before and not (tmp_path / "picture.xyz").exists()
    plt.close(PLOTS[name](tmp_path / "no_extension"))  # matplotlib's default, PNG
    assert (tmp_path / "no_extension.png").read_bytes()[:4] == b"\x89PNG"


def test_plot_mesh_sizes_its_figure_for_the_aspect(tmp_path):
    # the Danish straits demo (3.6 x 2.2 degrees at 1 / cos(55.5)) was drawn in a box half the picture's width
    import matplotlib.pyplot as plt

    box = tm.geometry.Rectangle((9.6, 54.4), (13.2, 56.6))
    mesh = tm.generate_mesh(box, 0.4, seed=0)
    aspect = 1 / np.cos(np.radians(55.5))
    open_before = plt.get_fignums()
    for options in ({"aspect": aspect}, {"aspect": aspect, "color_by": None}, {}):
        figure = plot_mesh(mesh, tmp_path / "mesh.png", **options)
        _, _, width, height = figure.axes[0].get_position(original=False).bounds  # as drawn, at the aspect
        assert width > 0.75 and height > 0.75
        assert plt.get_fignums() == open_before


def test_shoreline_title_counts_one_island_in_the_singular():
    # the title said "1 islands"
    import matplotlib.pyplot as plt

    land = shapely.MultiPolygon([shapely.box(-1.0, -1.0, 0.0, 1.0), shapely.box(0.1, 0.1, 0.2, 0.2)])
    figure = plot_shoreline(Shoreline(land, (-0.5, 0.5, -0.5, 0.5), 500.0))
    assert figure.axes[0].get_title().endswith("1 mainland, 1 island")
    plt.close(figure)
    figure = plot_shoreline(_shoreline())
    assert figure.axes[0].get_title().endswith("1 mainland, 0 islands")
    plt.close(figure)


def _long_thin_plots(shape):
    """Every plot of a domain 10 times wider than tall ("wide") or taller than wide ("tall"), on the ground."""
    lon0, lon1, lat0, lat1 = (0.0, 10.0, -0.5, 0.5) if shape == "wide" else (0.0, 1.0, -5.0, 5.0)
    mesh = tm.generate_mesh(tm.geometry.Rectangle((lon0, lat0), (lon1, lat1)), 0.5, seed=0)
    land = shapely.box(lon0 - 1, lat0 - 1, 0.7 * lon0 + 0.3 * lon1, lat1 + 1)  # the west 30 %
    shore = Shoreline(land, (lon0, lon1, lat0, lat1), 20e3)
    lon, lat = np.linspace(lon0, lon1, 21), np.linspace(lat0, lat1, 21)
    dem = DEM(lon, lat, 100.0 * np.add.outer(lon - lon.mean(), lat))
    grid = GeoGrid((lon0, lon1, lat0, lat1), 20e3)
    return {
        "plot_mesh": lambda: plot_mesh(mesh, io.BytesIO()),
        "plot_mesh, edges only": lambda: plot_mesh(mesh, io.BytesIO(), color_by=None),
        "plot_shoreline": lambda: plot_shoreline(shore, None, io.BytesIO()),
        "plot_shoreline over a DEM": lambda: plot_shoreline(shore, dem, io.BytesIO()),
        "plot_size_field": lambda: plot_size_field(grid, np.full(grid.shape, 5e3), io.BytesIO()),
    }


@pytest.mark.parametrize("shape", ["wide", "tall"])
def test_every_plot_gives_a_long_thin_domain_a_figure_of_its_proportions(shape):
    # the shoreline and size-field plots were 9 and 8 inches wide whatever the domain: 9 x 12.6 and
    # 8 x 12.8 inches for one 10 times taller than wide, the picture a strip of 13 % and 16 % of the width
    for name, plot in _long_thin_plots(shape).items():
        figure = plot()
        width, height = figure.get_size_inches()
        assert 2.5 <= min(width, height) and max(width, height) <= 14.0, name
        assert (width / height >= 2.0) if shape == "wide" else (width / height <= 0.5), name
        _, _, axes_width, axes_height = figure.axes[0].get_position(original=False).bounds  # as drawn
        assert (axes_width if shape == "wide" else axes_height) > 0.75, name


def test_figure_size_follows_the_aspect():
    # a degree of longitude at 60 degrees north is drawn half as long as a degree of latitude
    assert figure_size(2.0, 1.0, 2.0, colorbar=False) == figure_size(1.0, 1.0, "equal", colorbar=False)
    assert figure_size(1.0, 1.0, "auto", colorbar=False) == figure_size(1.0, 1.0, 1.0, colorbar=False)
    wide, tall = figure_size(100.0, 1.0, 1.0, colorbar=True), figure_size(1.0, 100.0, 1.0, colorbar=True)
    # 8 and 10 inches of axes, 1.5 up a wide picture (blank bands a third of the figure at 2.5), 2.5 across a tall one
    assert wide == (9.9, 2.5) and tall == (4.4, 11.0)
    assert figure_size(0.0, 0.0, "equal", colorbar=False) == figure_size(1.0, 1.0, "equal", colorbar=False)
