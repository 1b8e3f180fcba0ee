import io

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError
from terramesh.plot import plot_mesh


def test_plot_writes_png(tmp_path):
    mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2)
    path = tmp_path / "mesh.png"
    figure = plot_mesh(mesh, path)
    assert path.read_bytes()[:4] == b"\x89PNG"
    assert figure.axes[0].get_title().startswith(f"{mesh.n_points:,} vertices")
    import matplotlib.pyplot as plt

    plt.close(figure)


def test_plot_into_given_axes_without_colour():
    import matplotlib.pyplot as plt

    mesh = tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([[0, 1, 2]]))
    figure, ax = plt.subplots()
    assert plot_mesh(mesh, ax=ax, color_by=None, title="one") is figure
    assert ax.get_title() == "one"
    plt.close(figure)


def _triangle():
    return tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([[0, 1, 2]]))


@pytest.mark.parametrize(
    "points, cells",
    [(np.zeros((0, 2)), np.zeros((0, 3), dtype=int)), (np.array([[0.0, 0], [1, 0], [0, 1]]), np.zeros((0, 3), int))],
    ids=["no points", "no cells"],
)
def test_plot_mesh_refuses_a_mesh_without_cells(points, cells):
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(MeshValidityError, match="at least one cell"):
        plot_mesh(tm.Mesh(points, cells))
    assert plt.get_fignums() == open_before


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_plot_mesh_refuses_non_finite_points(bad):
    with pytest.raises(MeshValidityError, match="NaN or infinite.*index 3"):
        tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1], [bad, 0]]), np.array([[0, 1, 2]]))
    mesh = tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1], [2, 0]]), np.array([[0, 1, 2]]))
    mesh.points[3, 0] = bad  # changed after the Mesh checked them: the plot checks again
    with pytest.raises(MeshValidityError, match="NaN or infinite.*index 3"):
        plot_mesh(mesh)


@pytest.mark.parametrize("color_by", ["qualty", "Quality", 1])
def test_plot_mesh_refuses_an_unknown_color_by(color_by):
    with pytest.raises(MeshValidityError, match="color_by"):
        plot_mesh(_triangle(), color_by=color_by)


@pytest.mark.parametrize("aspect", ["square", 0, -1.0, np.nan, np.inf, [1.0], True])
def test_plot_mesh_refuses_a_bad_aspect(aspect):
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(MeshValidityError, match="aspect"):
        plot_mesh(_triangle(), aspect=aspect)
    assert plt.get_fignums() == open_before


@pytest.mark.parametrize("aspect", ["equal", "auto", 2, np.float64(1.7)])
def test_plot_mesh_takes_the_aspects_matplotlib_takes(aspect):
    import matplotlib.pyplot as plt

    figure = plot_mesh(_triangle(), aspect=aspect)
    assert figure.axes[0].get_aspect() == (aspect if aspect != "equal" else 1.0)
    plt.close(figure)


def test_plot_mesh_refuses_a_3d_mesh_before_opening_a_figure():
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(MeshValidityError, match=r"shape \(n, 2\)"):
        plot_mesh(tm.Mesh(np.eye(4, 3), np.array([[0, 1, 2, 3]])))
    assert plt.get_fignums() == open_before


def test_plot_mesh_refuses_a_missing_directory_before_drawing(tmp_path):
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(FileNotFoundError, match="directory .*nowhere.* does not exist"):
        plot_mesh(_triangle(), tmp_path / "nowhere" / "mesh.png")
    assert plt.get_fignums() == open_before
    buffer = io.BytesIO()  # a file object is still matplotlib's to handle
    plt.close(plot_mesh(_triangle(), buffer))
    assert buffer.getvalue()[:4] == b"\x89PNG"
