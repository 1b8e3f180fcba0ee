"""BP2004 meshed along its layers: the velocity gradient refines across the contrasts only.

The model: the BP2004 velocity section (``vel_z6.25m_x12.5m_exact.segy``)
read with :func:`terramesh.seismic.read_velocity` and decimated by
``--decimation`` (default 8: a 100 m x 50 m grid). The sizes: a 2 Hz
source, 10 edges per wavelength, hmin 80 m, grade 0.15
(:func:`terramesh.seismic.size_function`). Two meshes refine them by the
velocity gradient, ``m`` = 40 edges per velocity scale length:

- isotropic: ``size_function(..., gradient_refinement=40)`` and
  :func:`terramesh.generate_mesh`, small cells in every direction at a
  contrast;
- along the layers: :func:`terramesh.seismic.layer_metric` and
  :func:`terramesh.generate_anisotropic_mesh`, cells as long as the
  wavelength asks along a contrast and as short as the gradient asks
  across it.

Run from the repository root: ``python examples/seismic/bp2004_layers.py``.
Prints both meshes' numbers and writes ``examples-output/bp2004_layers.png``
(the salt column's west flank, both meshes side by side in white over the
P-wave velocity, its colour bar in m/s) and
``examples-output/bp2004_layers.msh`` (the anisotropic mesh with its
velocities and boundary tags, for an FWI code).
"""

import argparse
import pathlib
import time

import numpy as np

import terramesh as tm

DATA = pathlib.Path(__file__).resolve().parents[2].parent / "shared" / "data"
SEGY = DATA / "seismic" / "vel_z6.25m_x12.5m_exact.segy"
WINDOW = ((29000.0, 35000.0), (-6000.0, -3500.0))
"""The part drawn, metres: the salt column's west flank and the layers against it."""


def main(decimation=8, output=pathlib.Path("examples-output"), segy=SEGY):
    """Mesh the model both ways, print their numbers and write the figure and the anisotropic mesh."""
    section = tm.seismic.read_velocity(segy)
    x, z = section.axes
    model = tm.seismic.VelocityModel(section.values[::decimation, ::decimation], (x[::decimation], z[::decimation]))
    options = dict(frequency=2.0, cells_per_wavelength=10, hmin=80.0, grade=0.15)
    size = tm.seismic.size_function(model, **options)
    refined = tm.seismic.size_function(model, gradient_refinement=40, **options)

    started = time.perf_counter()
    isotropic = tm.generate_mesh(refined.domain, refined, seed=0)
    isotropic_seconds = time.perf_counter() - started
    started = time.perf_counter()
    metric = tm.seismic.layer_metric(size, gradient_refinement=40)
    layers = tm.generate_anisotropic_mesh(size.domain, metric, seed=0)
    layers_seconds = time.perf_counter() - started

    quality = tm.quality.metric_quality(layers.points, layers.cells, metric)
    print(f"model {model.values.shape[0]} x {model.values.shape[1]} nodes, {np.ptp(x):.0f} m x {np.ptp(z):.0f} m")
    print(f"isotropic refinement: {isotropic.n_points:,} vertices in {isotropic_seconds:.2f} s")
    print(
        f"along the layers:     {layers.n_points:,} vertices in {layers_seconds:.2f} s, "
        f"quality in the metric mean {quality.mean():.3f}, min {quality.min():.3f}"
    )
    for name, mesh, sizes in (("isotropic", isotropic, refined), ("along the layers", layers, size)):
        print(f"  {name}: stable time step {tm.seismic.stable_timestep(mesh, sizes):.4g} s")

    output.mkdir(parents=True, exist_ok=True)
    tm.io.write_fwi_mesh(output / "bp2004_layers.msh", layers, size)
    _draw(output / "bp2004_layers.png", model, ((isotropic, "isotropic refinement"), (layers, "along the layers")))
    print(f"wrote {output / 'bp2004_layers.png'} and {output / 'bp2004_layers.msh'}")


def _draw(path, model, meshes):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, 2, figsize=(14, 3.6), sharey=True, layout="constrained")
    # one colour scale for both panels, that of the window drawn: the salt's 4.8 km/s against the layers
    x, z = model.axes
    inside = np.ix_((x >= WINDOW[0][0]) & (x <= WINDOW[0][1]), (z >= WINDOW[1][0]) & (z <= WINDOW[1][1]))
    vmin, vmax = float(model.values[inside].min()), float(model.values[inside].max())
    for ax, (mesh, title) in zip(axes, meshes, strict=True):
        image = ax.pcolormesh(
            x, z, model.values.T, cmap="viridis", vmin=vmin, vmax=vmax, shading="nearest", rasterized=True
        )
        ax.triplot(mesh.points[:, 0], mesh.points[:, 1], mesh.cells, color="white", linewidth=0.25)
        ax.set(xlim=WINDOW[0], ylim=WINDOW[1], aspect="equal", title=f"{title}: {mesh.n_points:,} vertices")
        ax.set_xlabel("x (m)")
    axes[0].set_ylabel("z (m)")
    figure.colorbar(image, ax=axes, label="P-wave velocity (m/s)", shrink=0.9)
    figure.savefig(path, dpi=110)
    plt.close(figure)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--decimation", type=int, default=8, help="keep every n-th node of the model (default 8)")
    parser.add_argument("--output", type=pathlib.Path, default=pathlib.Path("examples-output"), help="folder")
    parser.add_argument("--segy", type=pathlib.Path, default=SEGY, help="the BP2004 velocity SEG-Y file")
    arguments = parser.parse_args()
    if arguments.decimation < 1:
        parser.error(f"--decimation must be a whole number of nodes, 1 or more, got {arguments.decimation}")
    main(arguments.decimation, arguments.output, arguments.segy)
