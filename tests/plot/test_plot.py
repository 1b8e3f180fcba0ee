import numpy as np

import terramesh as tm
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
