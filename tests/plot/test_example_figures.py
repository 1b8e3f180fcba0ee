"""The example scripts' figures: what their colours mean is written on them."""

import importlib.util
import pathlib

import numpy as np

import terramesh as tm

EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "seismic" / "bp2004_layers.py"


def test_the_bp2004_layers_figure_has_a_velocity_colour_bar(tmp_path, monkeypatch):
    # bp2004_layers.png had no colour bar: nothing said the colours were velocities, nor in what unit
    from matplotlib.image import imread

    spec = importlib.util.spec_from_file_location("bp2004_layers", EXAMPLE)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    x, z = np.linspace(28_000.0, 36_000.0, 9), np.linspace(-7_000.0, -3_000.0, 5)
    model = tm.seismic.VelocityModel(1500.0 + 0.5 * np.add.outer(x - x[0], -z), (x, z))
    mesh = tm.generate_mesh(tm.geometry.Rectangle((29_000.0, -6_000.0), (35_000.0, -3_500.0)), 800.0, seed=0)
    figures = []
    import matplotlib.pyplot as plt

    real_close = plt.close
    monkeypatch.setattr(plt, "close", figures.append)  # keep the figure to read it back
    example._draw(tmp_path / "layers.png", model, ((mesh, "isotropic"), (mesh, "along the layers")))
    (figure,) = figures
    bars = [ax for ax in figure.axes if ax.get_ylabel() == "P-wave velocity (m/s)"]
    assert len(bars) == 1
    low, high = bars[0].get_ylim()
    inside = model.values[np.ix_((x >= 29_000) & (x <= 35_000), (z >= -6_000) & (z <= -3_500))]
    assert (low, high) == (inside.min(), inside.max())  # the scale of the window drawn, both panels
    assert imread(tmp_path / "layers.png").shape[2] in (3, 4)
    real_close(figure)
