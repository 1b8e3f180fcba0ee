"""The figures the plotting functions open: closed once saved, filled by the picture, titled in good English."""

import io

import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh.coastal import GeoGrid
from terramesh.coastal.shoreline import Shoreline
from terramesh.errors import MeshFormatError
from terramesh.plot import plot_mesh, plot_shoreline, plot_size_field


def _mesh():
    return tm.generate_mesh(tm.geometry.Rectangle((10.0, 55.0), (10.4, 55.2)), 0.05, seed=0)


def _shoreline():
    return Shoreline(shapely.box(-1.0, -1.0, 0.0, 1.0), (-0.5, 0.5, -0.5, 0.5), 5000.0)


def _size_field():
    grid = GeoGrid((10, 11, 55, 56), 5e3)
    return grid, np.full(grid.shape, 800.0)


PLOTS = {
    "plot_mesh": lambda path, **options: plot_mesh(_mesh(), path, **options),
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
