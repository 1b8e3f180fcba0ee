"""layer_metric: seismic cells long along the layers, refined across a contrast only; on BP2004 and by hand."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import SizingError, TerrameshWarning
from terramesh.quality import metric_edge_lengths, metric_quality
from terramesh.seismic import layer_metric
from terramesh.sizing import MetricGrid, metric_sizes, metric_tensor

from ..conftest import assert_valid

OPTIONS = dict(frequency=2.0, hmin=80.0, grade=0.15)


def two_layers(dip=0.0):
    """1500 m/s over 3000 m/s, the contrast through (500, -250) dipping by ``dip`` radians, 25 m grid."""
    x, z = np.meshgrid(np.arange(0, 1001, 25.0), np.arange(-500, 1, 25.0), indexing="ij")
    below = (z + 250) < np.tan(dip) * (x - 500)
    return tm.seismic.VelocityModel(np.where(below, 3000.0, 1500.0), (x[:, 0], z[0]))


@pytest.mark.parametrize("dip", [0.0, 0.3])
def test_by_hand_the_cells_are_thin_across_the_contrast_and_follow_its_dip(dip):
    size = tm.seismic.size_function(two_layers(dip), frequency=5, hmin=10, grade=0.2)
    metric = layer_metric(size, gradient_refinement=20)
    # on the contrast: 30 m (1500 / (5 x 10)) along it, hmin across; 62.5 m above it (less, at the dip) graded
    # back up at 0.2 from hmin
    major, minor, angle = metric_sizes(metric([(500.0, -262.5), (500.0, -200.0)]))
    assert major[0] == pytest.approx(30.0, rel=0.1) and minor[0] == pytest.approx(10.0, rel=0.2)
    assert np.degrees(angle) == pytest.approx([np.degrees(dip)] * 2, abs=3.0)
    assert 1.5 * minor[0] < minor[1] < 10.0 + 0.2 * 62.5 * 1.1  # graded at 0.2 from the contrast, 50-62.5 m off


def test_the_cfl_floor_of_dt_holds_across_the_layers_too():
    # the isotropic refinement of sizes made for dt keeps them above the CFL floor; so must the metric
    options = dict(frequency=5, hmin=10, grade=0.2, dt=0.004)
    with pytest.warns(TerrameshWarning, match="CFL limit of dt=0.004 s raises 82 grid nodes"):
        refined = tm.seismic.size_function(two_layers(), gradient_refinement=20, **options)
    metric = layer_metric(tm.seismic.size_function(two_layers(), **options), gradient_refinement=20)
    _, minor, _ = metric_sizes(metric.values)
    assert refined.values.min() > 10.0  # the floor binds: 15 m at 3000 m/s
    assert minor.min() >= refined.values.min() * (1 - 1e-9)
    assert minor.min() < metric_sizes(metric.values)[0].min() or minor.min() == refined.values.min()


def test_bp2004_is_meshed_with_fewer_vertices_than_the_isotropic_refinement(bp2004):
    x, z = bp2004.axes
    model = tm.seismic.VelocityModel(bp2004.values[::8, ::8], (x[::8], z[::8]))
    size = tm.seismic.size_function(model, **OPTIONS)
    metric = layer_metric(size, gradient_refinement=40)
    mesh = tm.generate_anisotropic_mesh(size.domain, metric, seed=0)
    assert_valid(mesh, size.domain, 80.0)
    lengths = metric_edge_lengths(mesh.points, mesh.cells, metric)
    quality = metric_quality(mesh.points, mesh.cells, metric)
    # measured 2026-11-29: 56,305 vertices against 68,624 refined isotropically by the same gradient
    # (49,808 unrefined); median metric length 0.997 (5-95 % 0.86-1.15), quality mean 0.979, min 0.67
    isotropic = tm.generate_mesh(
        *(lambda s: (s.domain, s))(tm.seismic.size_function(model, gradient_refinement=40, **OPTIONS)), seed=0
    )
    assert mesh.n_points < 0.88 * isotropic.n_points
    assert 0.97 < np.median(lengths) < 1.03 and np.percentile(lengths, 95) < 1.2
    assert quality.mean() > 0.97 and quality.min() > 0.5


def test_bad_input_is_refused_by_name():
    model = two_layers()
    with pytest.raises(SizingError, match="without gradient_refinement"):
        layer_metric(
            tm.seismic.size_function(model, frequency=5, hmin=10, gradient_refinement=5), gradient_refinement=5
        )
    with pytest.raises(SizingError, match="gradient_refinement must be a positive finite number, got 0"):
        layer_metric(tm.seismic.size_function(model, frequency=5, hmin=10), gradient_refinement=0)
    with pytest.raises(SizingError, match="2-D sizes"):
        layer_metric(tm.sizing.SizeGrid((np.arange(3.0), np.arange(3.0)), np.ones((3, 3))), gradient_refinement=5)


def test_a_metric_grid_interpolates_its_entries_and_refuses_a_bad_one():
    axis = np.linspace(0.0, 1.0, 3)
    values = metric_tensor(np.full((3, 3), 0.2), 0.05, np.add.outer(axis, 0 * axis))
    grid = MetricGrid((axis, axis), values)
    assert np.allclose(grid([(0.5, 0.0)]), values[1, 0])
    assert np.allclose(grid([(0.25, 0.0)]), 0.5 * (values[0, 0] + values[1, 0]))
    assert np.allclose(grid([(-5.0, 9.0)]), values[0, 2])  # outside: the nearest edge's
    with pytest.raises(SizingError, match="not positive definite"):
        MetricGrid((axis, axis), -values)
    with pytest.raises(SizingError, match=r"the grid axes need \(3, 3, 2, 2\)"):
        MetricGrid((axis, axis), values[:2])
