"""Seismic sizes: formulas against hand computations, padding styles, gradation, CFL, acquisition, BP2004."""

import re
import warnings

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError, SizingError, TerrameshWarning
from terramesh.quality import triangle_quality
from terramesh.seismic import (
    CELLS_PER_WAVELENGTH,
    CELLS_PER_WAVELENGTH_3D,
    EDGE_SHRINK_SEISMIC,
    ModelBox,
    SeismicSize,
    VelocityModel,
    cfl_size,
    gradient_size,
    pad_model,
    read_velocity,
    size_function,
    stable_timestep,
    wavelength_size,
)
from terramesh.sizing import SizeGrid


def uniform(velocity=2000.0, nx=41, nz=21, spacing=10.0):
    """A constant model of (nx - 1) x (nz - 1) cells, top at z = 0."""
    return read_velocity(np.full((nz, nx), velocity), spacing=spacing, axis_order="zx")


def layered(spacing=10.0):
    """1500 m/s over 3000 m/s: 400 m wide, 200 m deep, the interface at z = -100."""
    depth = np.arange(21) * spacing
    return read_velocity(
        np.where(depth < 100, 1500.0, 3000.0)[:, None] * np.ones((21, 41)), spacing=spacing, axis_order="zx"
    )


def edge_ratios(mesh, size):
    edges = np.unique(
        np.sort(np.concatenate([mesh.cells[:, [0, 1]], mesh.cells[:, [1, 2]], mesh.cells[:, [2, 0]]]), axis=1), axis=0
    )
    a, b = mesh.points[edges[:, 0]], mesh.points[edges[:, 1]]
    return np.linalg.norm(b - a, axis=1) / size((a + b) / 2)


# --- formulas -----------------------------------------------------------------------------------


def test_wavelength_size_by_hand():
    # lambda = v / f; h = lambda / n
    assert wavelength_size(1500.0, frequency=5.0, cells_per_wavelength=10) == pytest.approx(30.0)
    assert wavelength_size([4790.0], frequency=2.0, cells_per_wavelength=7.02) == pytest.approx([341.168], abs=1e-3)


def test_cells_per_wavelength_table():
    assert CELLS_PER_WAVELENGTH == {1: 10.0, 2: 7.02, 3: 3.70, 4: 2.67, 5: 2.03}
    assert CELLS_PER_WAVELENGTH_3D == {1: 10.0, 2: 6.12, 3: 3.72}
    size = size_function(uniform(3000.0), frequency=4.0, element_order=3, hmin=1.0, velocity_window=0)
    np.testing.assert_allclose(size.values, 3000.0 / (4.0 * 3.70))
    assert size.settings["cells_per_wavelength"] == 3.70
    with pytest.raises(SizingError, match="element order 7"):
        size_function(uniform(), frequency=4.0, element_order=7, hmin=1.0)


def test_cfl_size_and_stable_timestep_by_hand():
    # h >= k v dt / Cr
    assert cfl_size(2000.0, dt=0.002, element_order=3, courant=0.6) == pytest.approx(3 * 2000.0 * 0.002 / 0.6)
    # dt = min Cr h / (k v): 0.5 * 20 / (2 * 2000) = 0.0025 at the slower node... and 0.5 * 30 / (2 * 4000)
    dt = stable_timestep([20.0, 30.0], [2000.0, 4000.0], element_order=2, courant=0.5)
    assert dt == pytest.approx(min(0.5 * 20 / (2 * 2000), 0.5 * 30 / (2 * 4000)))


def test_gradient_size_on_a_ramp():
    # v = 1000 + 2 x: |grad v| = 2 /s; h = v / (m |grad v|)
    x = np.arange(11) * 10.0
    v = np.outer(1000.0 + 2.0 * x, np.ones(5))
    h = gradient_size(v, 10.0, elements=4)
    np.testing.assert_allclose(h, v / (4 * 2.0))
    assert np.all(np.isinf(gradient_size(np.full((3, 3), 1500.0), 1.0, elements=4)))


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: wavelength_size(1500.0, frequency=0.0, cells_per_wavelength=10), "frequency"),
        (lambda: wavelength_size(1500.0, frequency=-2.0, cells_per_wavelength=10), "frequency"),
        (lambda: wavelength_size(1500.0, frequency=np.nan, cells_per_wavelength=10), "frequency"),
        (lambda: wavelength_size(1500.0, frequency=2.0, cells_per_wavelength=0), "cells_per_wavelength"),
        (lambda: wavelength_size([1500.0, np.nan], frequency=2.0, cells_per_wavelength=10), "NaN"),
        (lambda: wavelength_size([1500.0, 0.0], frequency=2.0, cells_per_wavelength=10), "zero or negative"),
        (lambda: cfl_size(1500.0, dt=0.0), "dt"),
        (lambda: cfl_size(1500.0, dt=0.001, element_order=0), "element_order"),
        (lambda: gradient_size(np.ones((3, 3)), 1.0, elements=-1), "elements"),
        # one value, no grid: was "min() arg is an empty sequence"
        (lambda: gradient_size(1500.0, 10.0, elements=2), "gradient_size needs velocities on a grid"),
        (lambda: stable_timestep([], []), "at least one size"),  # was NumPy's zero-size reduction error
        (lambda: stable_timestep(["a"], [1500.0]), "sizes must be numbers"),
        (
            lambda: stable_timestep(tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.5), [1500.0]),
            "a mesh's stable time step needs its VelocityModel",
        ),
        # a 2-D model for a 3-D mesh: was the size grid's "points ... must have shape (n, 2), not (n, 3)"
        (
            lambda: stable_timestep(
                tm.generate_mesh(tm.geometry.Box((0, 0, -200), (400, 200, 0)), 150.0, seed=0), uniform()
            ),
            "the model is 2-D but the mesh is 3-D",
        ),
    ],
)
def test_formulas_refuse_bad_input(call, message):
    with pytest.raises(SizingError, match=message):
        call()


# --- size_function ----------------------------------------------------------------------------


def test_uniform_model_by_hand_and_bounds():
    size = size_function(uniform(2000.0), frequency=10.0, cells_per_wavelength=10, hmin=5.0)
    assert isinstance(size, SeismicSize) and isinstance(size, SizeGrid)
    np.testing.assert_allclose(size.values, 20.0)  # 2000 / (10 * 10)
    np.testing.assert_allclose(size([(200.0, -100.0)]), [20.0])
    with pytest.warns(TerrameshWarning, match="uniform at hmin"):  # hmin beats the wavelength everywhere
        floor = size_function(uniform(2000.0), frequency=10.0, hmin=25.0)
    np.testing.assert_allclose(floor.values, 25.0)
    cap = size_function(uniform(2000.0), frequency=1.0, hmin=5.0, hmax=150.0)
    np.testing.assert_allclose(cap.values, 150.0)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"frequency": 0.0, "hmin": 10.0}, "frequency"),
        ({"frequency": -1.0, "hmin": 10.0}, "frequency"),
        ({"hmin": 10.0}, "frequency"),
        ({"frequency": 2.0}, "hmin"),
        ({"frequency": 2.0, "hmin": -75.0}, "hmin"),
        ({"frequency": 2.0, "hmin": 0.0}, "hmin"),
        ({"frequency": 2.0, "hmin": 50.0, "hmax": 20.0}, "hmax"),
        ({"frequency": 2.0, "hmin": 10.0, "grade": 0.0}, "grade"),
        ({"frequency": 2.0, "hmin": 10.0, "pad": -100.0}, "pad"),
        ({"frequency": 2.0, "hmin": 10.0, "pad": 100.0, "pad_style": "reflect"}, "pad_style"),
        ({"frequency": 2.0, "hmin": 10.0, "cells_per_wavelength": np.nan}, "cells_per_wavelength"),
        ({"frequency": 2.0, "hmin": 10.0, "dt": -0.001}, "dt"),
        ({"frequency": 2.0, "hmin": 10.0, "sources": [(200.0, 50.0)]}, "outside the model"),
        ({"frequency": 2.0, "hmin": 10.0, "acquisition_size": 5.0, "receivers": [(0.0, 0.0)]}, "below hmin"),
        # float("a") raised its own ValueError
        ({"frequency": 2.0, "hmin": 10.0, "velocity_window": "a"}, "velocity_window must be a non-negative length"),
        ({"frequency": 2.0, "hmin": 10.0, "velocity_window": -1.0}, "velocity_window"),
        ({"frequency": 2.0, "hmin": 10.0, "acquisition_radius": "a"}, "acquisition_radius must be a non-negative"),
        ({"frequency": 2.0, "hmin": 10.0, "acquisition_radius": [1.0]}, "acquisition_radius"),
    ],
)
def test_size_function_refuses_bad_input(options, message):
    with pytest.raises(SizingError, match=message):
        size_function(uniform(), **options)


def test_nan_velocities_never_reach_the_sizes():
    values = np.full((5, 5), 2000.0)
    values[2, 2] = np.nan
    with pytest.raises(SizingError, match="NaN"):
        read_velocity(values, spacing=10.0, axis_order="zx")
    with pytest.raises(SizingError, match="NaN"):
        VelocityModel(values, (np.arange(5.0), np.arange(5.0)))


def test_size_function_needs_a_velocity_model_and_points_of_its_dimension():
    with pytest.raises(SizingError, match="VelocityModel"):
        size_function(np.ones((4, 4)), frequency=2, hmin=10)
    with pytest.raises(SizingError, match=r"\(x, z\) points of this 2-D model"):
        size_function(uniform(), frequency=2, hmin=10, sources=[(100.0, 100.0, -50.0)])
    model3d = read_velocity(np.full((3, 3, 3), 2000.0), spacing=10.0, axis_order="zxy")
    assert size_function(model3d, frequency=20, hmin=10).dim == 3  # sizes of 10 m: at 2 Hz, 100 m on a 20 m cube


def test_seismicmesh_aliases_and_unknown_options():
    ours = size_function(layered(), frequency=5.0, cells_per_wavelength=8, hmin=5.0, pad=50.0, courant=0.5, dt=0.001)
    theirs = size_function(layered(), freq=5.0, wl=8, hmin=5.0, domain_pad=50.0, cr_max=0.5, dt=0.001)
    np.testing.assert_array_equal(ours.values, theirs.values)
    with pytest.raises(TypeError, match="hmin_"):
        size_function(layered(), frequency=5.0, hmin_=5.0)
    with pytest.raises(TypeError, match="same option"):
        size_function(layered(), frequency=5.0, freq=5.0, hmin=5.0)


def test_velocity_window_takes_the_slowest_velocity_nearby():
    # a one-node-thick slow layer (1000 m/s) in 3000 m/s rock at z = -100
    values = np.full((21, 41), 3000.0)
    values[10] = 1000.0
    model = read_velocity(values, spacing=10.0, axis_order="zx")
    pointwise = size_function(model, frequency=10.0, hmin=5.0, velocity_window=0)
    windowed = size_function(model, frequency=10.0, hmin=5.0, velocity_window=40.0)  # 5 nodes across
    column = 20
    z = pointwise.axes[1]
    slow_rows = np.isclose(z, -100.0)
    np.testing.assert_allclose(pointwise.values[column, slow_rows], 10.0)
    np.testing.assert_allclose(pointwise.values[column, ~slow_rows], 30.0)
    near = np.abs(z + 100.0) <= 20.0 + 1e-9  # within half the window
    np.testing.assert_allclose(windowed.values[column, near], 10.0)
    np.testing.assert_allclose(windowed.values[column, ~near], 30.0)


def test_gradation_limits_the_size_gradient():
    size = size_function(layered(), frequency=5.0, hmin=5.0, grade=0.15, velocity_window=0)
    raw = size_function(layered(), frequency=5.0, hmin=5.0, velocity_window=0)
    assert np.all(size.values <= raw.values + 1e-12)  # gradation only lowers sizes
    dx, dz = size.model.spacing
    assert np.abs(np.diff(size.values, axis=0)).max() / dx <= 0.15 + 1e-9
    assert np.abs(np.diff(size.values, axis=1)).max() / dz <= 0.15 + 1e-9
    # below the last water node (z = -90) the size climbs from 30 m (1500 / 50) towards 60 m (3000 / 50)
    column = size.values[20]
    z = size.axes[1]
    expected = np.minimum(60.0, 30.0 + 0.15 * np.maximum(0.0, -90.0 - z))
    np.testing.assert_allclose(column, expected, atol=1e-9)


def test_gradient_refinement_lowers_sizes_at_contrasts():
    plain = size_function(layered(), frequency=2.0, hmin=5.0, velocity_window=0)
    refined = size_function(layered(), frequency=2.0, hmin=5.0, velocity_window=0, gradient_refinement=10)
    z = plain.axes[1]
    at_interface = np.isin(z, [-100.0, -90.0])  # the nodes either side of the jump from 1500 to 3000
    # v / (10 |grad v|) with |grad v| = 1500 / 20 (central difference over the step)
    expected = np.minimum(plain.values[20, at_interface], refined.model.values[20, at_interface] / (10 * 75.0))
    np.testing.assert_allclose(refined.values[20, at_interface], np.maximum(expected, 5.0))
    np.testing.assert_allclose(refined.values[20, ~at_interface], plain.values[20, ~at_interface])


# --- padding ---------------------------------------------------------------------------------


def test_pad_styles_by_hand():
    values = np.array([[1500.0, 1600.0], [2500.0, 2600.0]])  # (z, x): top row first
    model = read_velocity(values, spacing=10.0, axis_order="zx")
    edge = pad_model(model, 20.0, style="edge")
    constant = pad_model(model, 20.0, style="constant", velocity=4000.0)
    linear = pad_model(model, 20.0, style="linear", velocity=4000.0)
    for padded in (edge, constant, linear):
        assert padded.pad == (20.0, 20.0, 20.0)
        np.testing.assert_allclose(padded.bbox, [[-20.0, -30.0], [30.0, 0.0]])  # no layer on top
        np.testing.assert_allclose(padded.interior_bbox, model.bbox)
        np.testing.assert_allclose(padded([(0.0, 0.0), (10.0, -10.0)]), [1500.0, 2600.0])  # the model is kept
    np.testing.assert_allclose(edge([(-20.0, 0.0), (30.0, -30.0), (5.0, -30.0)]), [1500.0, 2600.0, 2550.0])
    np.testing.assert_allclose(constant([(-20.0, 0.0), (-10.0, 0.0), (5.0, -20.0)]), [4000.0, 4000.0, 4000.0])
    # the ramp: from the edge value at the model to 4000 at the outer boundary, in two steps of 10 m
    np.testing.assert_allclose(linear([(-10.0, 0.0), (-20.0, 0.0)]), [(1500.0 + 4000.0) / 2, 4000.0])
    np.testing.assert_allclose(linear([(0.0, -20.0), (0.0, -30.0)]), [(2500.0 + 4000.0) / 2, 4000.0])
    np.testing.assert_allclose(pad_model(model, 20.0, style="linear_ramp", velocity=4000.0).values, linear.values)
    np.testing.assert_array_equal(values, [[1500.0, 1600.0], [2500.0, 2600.0]])


def test_pad_widths_round_up_to_whole_cells_and_sides_differ():
    model = uniform(spacing=10.0)
    padded = pad_model(model, (15.0, 0.0, 31.0))
    assert padded.pad == (20.0, 0.0, 40.0)
    np.testing.assert_allclose(padded.bbox, [[-20.0, -240.0], [400.0, 0.0]])
    assert pad_model(model, 0.0) is model


def test_pad_grows_at_the_grade_limit():
    # uniform 20 m sizes; in a 200 m layer the size grows by grade x distance into it
    size = size_function(uniform(2000.0), frequency=10.0, hmin=5.0, grade=0.2, pad=200.0)
    np.testing.assert_allclose(size.bbox, [[-200.0, -400.0], [600.0, 0.0]])
    np.testing.assert_allclose(size.interior_bbox, [[0.0, -200.0], [400.0, 0.0]])
    x, z = size.axes
    middle = np.argmin(np.abs(x - 200.0))
    depth_into_pad = np.maximum(0.0, -200.0 - z)
    np.testing.assert_allclose(size.values[middle], 20.0 + 0.2 * depth_into_pad, atol=1e-9)
    top = size.values[:, -1]
    np.testing.assert_allclose(top, 20.0 + 0.2 * np.maximum(0.0, np.maximum(-x, x - 400.0)), atol=1e-9)
    capped = size_function(uniform(2000.0), frequency=10.0, hmin=5.0, hmax=40.0, grade=0.2, pad=200.0)
    assert capped.values.max() == pytest.approx(40.0)


def test_pad_without_coarsening_follows_the_pad_velocity():
    # without a grade the layer is not coarsened: its sizes are the pad velocity's wavelength
    size = size_function(
        uniform(2000.0), frequency=10.0, hmin=5.0, pad=100.0, pad_style="constant", pad_velocity=3000.0
    )
    np.testing.assert_allclose(size([(-50.0, -50.0), (200.0, -150.0), (200.0, -280.0)]), [30.0, 20.0, 30.0])
    np.testing.assert_allclose(size.model([(-50.0, -50.0)]), [3000.0])


@pytest.mark.parametrize(
    ("style", "velocity", "message"),
    [
        # 4.5 meant as km/s built a pad at 4.5 m/s, where the model itself is refused below 20 m/s
        ("constant", 4.5, r"pad_velocity=4\.5 looks like km/s .*give 4500"),
        ("linear", 4.5, r"pad_velocity=4\.5 looks like km/s"),
        ("constant", 0.0, "pad_velocity must be a positive finite number"),
        # the edge style uses none: it was ignored, silently
        ("edge", 4500.0, "pad_velocity=4500.0 is for pad_style 'constant' or 'linear'"),
        # a model this fast is refused; a pad this fast gave 20 km sizes and a mesh refused for a "neck"
        ("constant", 1e6, r"pad_velocity=1e\+06 m/s is faster than any Earth material"),
    ],
)
def test_pad_velocity_in_km_per_s_or_unused_is_refused(style, velocity, message):
    with pytest.raises(SizingError, match=message):
        size_function(uniform(), frequency=10.0, hmin=5.0, pad=100.0, pad_style=style, pad_velocity=velocity)
    with pytest.raises(SizingError, match=message):
        pad_model(uniform(), 100.0, style=style, velocity=velocity)


def test_options_for_what_was_not_asked_for_are_refused():
    # each was ignored, silently: no padding layer, no sources or receivers to refine around
    options = dict(frequency=10.0, hmin=5.0)
    with pytest.raises(SizingError, match="pad_style and pad_velocity shape the padding layer: give its width"):
        size_function(uniform(), **options, pad_style="constant", pad_velocity=4000.0)
    with pytest.raises(SizingError, match="pad_style and pad_velocity"):
        size_function(uniform(), **options, pad=0.0, pad_style="linear")
    with pytest.raises(SizingError, match="pad_style and pad_velocity"):
        size_function(uniform(), **options, pad=(0.0, 0.0, 0.0), pad_style="constant")
    # the CLI's --no-coarsen-pad wrote byte-identical meshes without --pad or --grade
    for missing in (dict(grade=0.15), dict(pad=100.0)):
        with pytest.raises(SizingError, match="coarsen_pad=False keeps a padding layer's sizes from growing"):
            size_function(uniform(), **options, **missing, coarsen_pad=False)
    size_function(uniform(), **options, pad=100.0, grade=0.15, coarsen_pad=False)
    # widths per side as an array: "the truth value of an array is ambiguous"
    sides = size_function(uniform(), **options, pad=np.array([100.0, 50.0, 20.0]), pad_style="constant")
    assert sides.domain.bbox.tolist() == [[-100.0, -220.0], [450.0, 0.0]]
    with pytest.raises(SizingError, match="acquisition_size and acquisition_radius refine around sources"):
        size_function(uniform(), **options, acquisition_size=20.0)
    with pytest.raises(SizingError, match="acquisition_size and acquisition_radius"):
        size_function(uniform(), **options, acquisition_radius=50.0)


def test_a_padding_larger_than_memory_is_refused():
    # a width in the wrong units: np.pad failed with a MemoryError for 24 GiB
    with pytest.raises(
        SizingError,
        match=r"a padding of 1e\+08 m makes a model of .* with the model it needs .* GiB of memory: is the pad in",
    ):
        pad_model(uniform(), 1e8)
    with pytest.raises(SizingError, match="is the pad in metres"):
        size_function(uniform(), frequency=10.0, hmin=5.0, pad=1e8)


def test_pad_velocity_is_in_the_settings():
    # adapt_mesh's callers rebuild the sizes of the old model from them
    options = dict(frequency=10.0, hmin=5.0, pad=100.0)
    assert (
        size_function(uniform(), **options, pad_style="linear", pad_velocity=3000.0).settings["pad_velocity"] == 3000.0
    )
    assert size_function(uniform(), **options).settings["pad_velocity"] is None  # the model's largest


def test_acquisition_refinement():
    receivers = [(x, 0.0) for x in (100.0, 200.0, 300.0)]
    sources = [(50.0, -50.0)]
    size = size_function(
        uniform(2000.0),
        frequency=2.0,
        hmin=10.0,
        grade=0.25,
        sources=sources,
        receivers=receivers,
        acquisition_radius=0.0,
    )
    np.testing.assert_allclose(size(receivers + sources), 10.0)
    # away from them the size grows at most at the grade, up to the wavelength size 100 m
    between = size([(150.0, 0.0)])[0]
    assert 10.0 + 0.2 * 50.0 <= between <= 10.0 + 0.25 * 50.0 + 1e-9
    # the lower right corner, 100 m across and 200 m down from the nearest receiver: the grid's gradient
    # limit holds along the axes, so the growth lies between the Euclidean and the axis-by-axis distance
    assert 10.0 + 0.25 * np.hypot(100.0, 200.0) <= size.values[-1, 0] <= 10.0 + 0.25 * 300.0
    assert size.values.max() == size.values[-1, 0]
    wide = size_function(
        uniform(2000.0), frequency=2.0, hmin=10.0, receivers=receivers, acquisition_size=15.0, acquisition_radius=30.0
    )
    np.testing.assert_allclose(wide([(130.0, 0.0), (100.0, -30.0), (150.0, 0.0)]), [15.0, 15.0, 100.0])


@pytest.mark.parametrize("dim", [2, 3])
def test_acquisition_refinement_matches_a_brute_force_reference(dim):
    """The compiled loop over sources and receivers against every node's distance to every point."""
    from terramesh.seismic.sizing import _refine_near

    rng = np.random.default_rng(dim)
    axes = [np.linspace(0.0, 1000.0, 41), np.linspace(-500.0, 0.0, 21), np.linspace(0.0, 300.0, 13)][:dim]
    values = rng.uniform(50.0, 100.0, [len(axis) for axis in axes])
    points = np.column_stack([rng.uniform(axis[0] - 20.0, axis[-1] + 20.0, 30) for axis in axes])
    refined = values.copy()
    _refine_near(refined, axes, points, 20.0, 40.0)
    nodes = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, dim)
    distance = np.linalg.norm(nodes[:, None, :] - points[None, :, :], axis=2)
    near = (distance <= 40.0).any(axis=1)
    near[np.argmin(distance, axis=0)] = True  # each point's nearest node, however far
    expected = np.where(near, np.minimum(values.ravel(), 20.0), values.ravel()).reshape(values.shape)
    np.testing.assert_array_equal(refined, expected)


def test_cfl_raises_sizes_and_warns_when_it_beats_the_wavelength():
    # 1500 m/s down to 300 m depth, 3000 m/s below, 400 m deep
    depth = np.arange(41)[:, None] * 10.0
    model = read_velocity(np.where(depth < 300, 1500.0, 3000.0) * np.ones((41, 41)), spacing=10.0, axis_order="zx")
    # k v_max dt / (Cr s) = 2 * 3000 * 0.01 / (1 * 0.5) = 120 m within 120 m of the fast rock, 60 m beyond
    with pytest.warns(TerrameshWarning, match="CFL limit"):
        size = size_function(model, frequency=10.0, hmin=5.0, dt=0.01, element_order=2, velocity_window=0)
    assert EDGE_SHRINK_SEISMIC == 0.5
    assert np.all(size.values >= cfl_size(size.model.values, dt=0.01, element_order=2) / EDGE_SHRINK_SEISMIC - 1e-12)
    np.testing.assert_allclose(size([(200.0, -350.0), (200.0, -210.0), (200.0, -150.0)]), [120.0, 120.0, 60.0])
    assert size.stable_timestep() == pytest.approx(0.01 / EDGE_SHRINK_SEISMIC)
    with pytest.raises(SizingError, match="above hmax"):
        size_function(model, frequency=10.0, hmin=5.0, hmax=90.0, dt=0.01, element_order=2)
    quiet = size_function(model, frequency=2.0, hmin=5.0, dt=0.001)  # a small dt changes nothing
    np.testing.assert_allclose(quiet.values, size_function(model, frequency=2.0, hmin=5.0).values)


@pytest.mark.parametrize("seed", [0, 1])
def test_dt_is_stable_on_the_generated_mesh(seed):
    # the reviewer's case: sizes k v dt / Cr gave a mesh whose stable step was 0.0152 s for dt = 0.02 s
    velocity = np.full((41, 81), 3000.0)
    velocity[:10] = 1500.0
    model = read_velocity(velocity, spacing=25.0, axis_order="zx")
    with pytest.warns(TerrameshWarning, match="CFL limit"):
        size = size_function(model, frequency=4.0, hmin=20.0, grade=0.2, dt=0.02, courant=1.0)
    mesh = tm.generate_mesh(size.domain, size, seed=seed)
    assert stable_timestep(mesh, size, courant=1.0) >= 0.02
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert size.check_timestep(mesh) == stable_timestep(mesh, size, courant=1.0)


def test_check_timestep_warns_when_the_mesh_falls_short():
    model = read_velocity(np.full((11, 21), 3000.0), spacing=25.0, axis_order="zx")
    size = size_function(model, frequency=4.0, hmin=20.0, dt=0.01)
    finer = tm.generate_mesh(size.domain, lambda p: np.full(len(p), 20.0), seed=0)
    with pytest.warns(TerrameshWarning, match=r"stable time step is 0\.00\d+ s, below the dt=0\.01 s"):
        assert size.check_timestep(finer) < 0.01


def test_mesh_timestep_takes_the_fastest_velocity_along_each_edge():
    # 1500 over 4500 m/s: the midpoint velocity gave 0.00833 s, the fast end of edges across the contrast 0.00657 s
    velocity = np.full((41, 81), 4500.0)
    velocity[:20] = 1500.0
    model = read_velocity(velocity, spacing=25.0, axis_order="zx")
    size = size_function(model, frequency=4.0, hmin=20.0, grade=0.3, velocity_window=0)
    mesh = tm.generate_mesh(size.domain, size, seed=0)
    sides = np.concatenate([mesh.cells[:, [0, 1]], mesh.cells[:, [1, 2]], mesh.cells[:, [2, 0]]])
    edges = np.unique(np.sort(sides, axis=1), axis=0)
    a, b = mesh.points[edges[:, 0]], mesh.points[edges[:, 1]]
    fraction = np.linspace(0.0, 1.0, 201)[:, None, None]  # a dense reference: 201 samples per edge
    fastest = model((a + fraction * (b - a)).reshape(-1, 2)).reshape(201, -1).max(axis=0)
    reference = np.min(np.linalg.norm(b - a, axis=1) / fastest)
    assert stable_timestep(mesh, size) == pytest.approx(reference, rel=1e-3)
    assert stable_timestep(mesh, size) < 0.0075


def test_sizes_and_time_steps_refuse_km_per_s_and_a_mesh_in_km():
    # each returned a size or a step 1000 times too small: stable_timestep([75, 225], [1.5, 4.5]) gave 50 s
    for call in (
        lambda: wavelength_size([1.5, 4.5], frequency=2.0, cells_per_wavelength=10),
        lambda: cfl_size([1.5, 4.5], dt=0.01),
        lambda: gradient_size(np.outer([1.0, 1.0], [1.5, 4.5]), 10.0, elements=2),
        lambda: stable_timestep([75.0, 225.0], [1.5, 4.5]),
    ):
        with pytest.raises(SizingError, match=r"the velocities are 1\.5\.\.4\.5, which look like km/s"):
            call()
    model = read_velocity(np.full((11, 21), 3000.0), spacing=25.0, axis_order="zx")
    size = size_function(model, frequency=4.0, hmin=20.0)
    mesh = tm.generate_mesh(size.domain, size, seed=0)
    in_km_per_s = VelocityModel(model.values / 1000, model.axes)
    with pytest.raises(SizingError, match="the model's velocities are 3..3, which look like km/s"):
        stable_timestep(mesh, in_km_per_s)
    in_km = tm.Mesh(mesh.points / 1000, mesh.cells)  # within the model's box: it gave 3.2e-5 s, not 0.0071 s
    with pytest.raises(SizingError, match="the mesh is about 1/1000 of the velocity model's extent"):
        stable_timestep(in_km, size)
    with pytest.raises(SizingError, match="about 1/1000"):
        size.check_timestep(in_km)


def test_units_that_would_give_an_all_hmin_mesh_are_refused():
    velocity = np.where(np.arange(20)[:, None] < 10, 1.5, 3.0) * np.ones((20, 30))  # km/s
    in_km_per_s = VelocityModel(velocity.T, (np.arange(30) * 25.0, np.arange(-19, 1) * 25.0))
    with pytest.raises(SizingError, match=r"velocities are 1\.5\.\.3, which look like km/s"):
        size_function(in_km_per_s, frequency=5.0, hmin=10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # read_velocity's own km/s warning
        read = read_velocity(velocity, spacing=25.0, axis_order="zx")
    with pytest.raises(SizingError, match="look like km/s"):
        size_function(read, frequency=5.0, hmin=10.0)
    grid_in_km = read_velocity(velocity * 1000.0, spacing=0.025, axis_order="zx")
    with pytest.raises(SizingError, match=r"hmin=10 m exceeds the model's extent \(0\.725 x 0\.475 m\)"):
        size_function(grid_in_km, frequency=5.0, hmin=10.0)
    # spacing and hmin in km, velocities in m/s: hmin fits, the sizes (v / (f n) metres) do not; generation
    # failed later with "h0 is too large" (3-D) or "cannot triangulate 1 points" (2-D)
    with pytest.raises(
        SizingError,
        match=r"smallest mesh size, 30 m, exceeds every side of the model \(0\.725 x 0\.475 m, padded\).*"
        r"start at 30 m .*hmin is 0\.01 m\)\. Are the spacing, hmin and pad in km",
    ):
        size_function(grid_in_km, frequency=5.0, hmin=0.01)
    cube_in_km = read_velocity(np.full((11, 9, 7), 1500.0), spacing=0.05, axis_order="xyz")
    with pytest.raises(SizingError, match=r"75 m, exceeds every side of the model \(0\.9 x 0\.8 x 0\.5 m, padded"):
        size_function(cube_in_km, frequency=2.0, hmin=0.075, pad=0.2)
    with pytest.warns(TerrameshWarning, match=r"hmin=40 m is above the wavelength size at 100\.0 %"):
        size_function(read_velocity(velocity * 1000.0, spacing=25.0, axis_order="zx"), frequency=10.0, hmin=40.0)


def test_model_box_places_nodes_by_the_size():
    box = ModelBox((0.0, -100.0), (400.0, 0.0), lambda p: 10.0 + 0.1 * p[:, 0])
    nodes = box.corners()
    assert len(np.unique(nodes, axis=0)) == len(nodes)
    np.testing.assert_allclose(box.distance(nodes), 0.0, atol=1e-9)
    bottom = np.sort(nodes[nodes[:, 1] == -100.0][:, 0])
    steps = np.diff(bottom)
    middles = (bottom[1:] + bottom[:-1]) / 2
    np.testing.assert_allclose(steps, 10.0 + 0.1 * middles, rtol=0.05)
    assert len(ModelBox((0.0, 0.0), (1.0, 1.0)).corners()) == 4


def test_synthetic_mesh_is_valid_and_follows_the_sizes():
    size = size_function(layered(), frequency=5.0, hmin=20.0, grade=0.2, pad=100.0)
    assert isinstance(size.domain, ModelBox)
    np.testing.assert_allclose(size.domain.bbox, size.bbox)
    mesh = tm.generate_mesh(size.domain, size, seed=0)
    assert tm.cleanup.mesh_problems(mesh, size.domain, boundary_tolerance=1e-3 * 20.0) == []
    assert 0.85 <= np.median(edge_ratios(mesh, size)) <= 1.15
    assert triangle_quality(mesh.points, mesh.cells).min() >= 0.5


# --- BP2004 ----------------------------------------------------------------------------------


def test_bp2004_sizes_by_hand(bp2004):
    size = size_function(bp2004, frequency=1.0, hmin=300.0, grade=0.15, pad=1000.0)
    np.testing.assert_allclose(size.bbox, [[-1000.0, -12937.5], [68425.0, 0.0]])
    assert size.values.min() == pytest.approx(300.0)  # water: 1486 / (1 * 10) < hmin
    # deep, far from any contrast the wavelength size holds: v_min within 300 m / 10
    x, z = 30000.0, -11000.0
    i, j = np.searchsorted(bp2004.axes[0], x), np.searchsorted(bp2004.axes[1], z)
    window = bp2004.values[i - 12 : i + 13, j - 24 : j + 25]
    assert size([(x, z)])[0] <= window.min() / 10 + 1e-9


def test_bp2004_coarse_mesh(bp2004):
    size = size_function(bp2004, frequency=1.0, hmin=300.0, grade=0.15, pad=1000.0, pad_style="edge")
    mesh = tm.generate_mesh(size.domain, size, seed=0)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.cleanup.mesh_problems(mesh, size.domain, boundary_tolerance=0.3) == []
    q = triangle_quality(mesh.points, mesh.cells)
    assert q.min() >= 0.70
    assert q.mean() >= 0.98
    assert 0.9 <= np.median(edge_ratios(mesh, size)) <= 1.15
    assert 6000 < mesh.n_points < 10000


def test_the_time_step_asked_for_holds_across_a_velocity_contrast():
    # the CFL floor was applied after grading and jumped at the contrast (150 to 600 m): the mesh could not
    # follow, its edges came out at 0.26 of their size, and it kept 0.91-0.97 of dt (0.69 in 3D)
    velocity = np.full((161, 71), 1500.0)
    velocity[:, :35] = 4500.0  # slow over fast, 16 x 7 km
    model = tm.seismic.VelocityModel(velocity, (np.arange(161) * 100.0, np.arange(71) * 100.0 - 7000.0))
    with pytest.warns(TerrameshWarning, match="raises .* grid nodes above their wavelength size"):
        size = size_function(model, frequency=2, hmin=50, grade=0.15, dt=0.04)
    for seed in (0, 1):
        mesh = tm.generate_mesh(size.domain, size, seed=seed)
        assert tm.seismic.stable_timestep(mesh, size) >= 0.04


def test_the_cfl_warning_counts_the_nodes_the_graded_floor_raised():
    # counted on the bare floor, it said 1,127 nodes where the graded floor took 4,669 above their wavelength size
    x, z = np.arange(0, 4000.1, 25.0), np.arange(-2000, 0.1, 12.5)
    model = tm.seismic.VelocityModel(np.where(z[None] < -1000, 4500.0, 1500.0) * np.ones((len(x), 1)), (x, z))
    with pytest.warns(TerrameshWarning, match=r"raises (\d+) grid nodes") as caught:
        size = size_function(model, frequency=5, grade=0.15, dt=0.01, hmin=25)
    warned = int(re.search(r"raises (\d+) grid nodes", str(caught[0].message)).group(1))
    wavelength = np.clip(model.values / (5 * size.settings["cells_per_wavelength"]), 25, None)
    assert warned >= np.sum(size.values > 1.0001 * wavelength) > 4000


# --- the pad's own velocity, and time steps against the wrong model -------------------------------------------


@pytest.mark.parametrize("style", ["constant", "linear"])
def test_a_fast_pad_does_not_refine_the_model_beside_it(style):
    # the gradient was taken on the padded velocity: the jump to a 6000 m/s pad refined the model's edge strip to
    # hmin (20 m where 74.3 m was due, 23 % more vertices on a BP2004 crop)
    options = dict(frequency=2.0, hmin=5.0, velocity_window=0, gradient_refinement=10, pad=60.0)
    edge = size_function(layered(), **options)
    fast = size_function(layered(), pad_style=style, pad_velocity=6000.0, **options)
    (x0, z0), (x1, z1) = edge.interior_bbox
    x, z = edge.axes
    inside = ((x >= x0) & (x <= x1))[:, None] & ((z >= z0) & (z <= z1))[None, :]
    np.testing.assert_array_equal(fast.values[inside], edge.values[inside])


def test_a_fast_constant_pad_is_named_in_the_cfl_warning():
    model = uniform(1500.0, nx=81, nz=41)
    with pytest.warns(TerrameshWarning, match=r"the constant pad's 4500 m/s raises the sizes beside it as well"):
        size_function(
            model, frequency=2.0, hmin=20.0, grade=0.2, pad=200.0, pad_style="constant", pad_velocity=4500.0, dt=0.02
        )


def test_a_mesh_beyond_the_model_has_no_step_from_it():
    # a padded mesh against the unpadded model read the pad at the model's edge velocity: a step 1.6 times too long
    model = uniform(2000.0, nx=41, nz=21)
    size = size_function(
        model, frequency=5.0, hmin=20.0, grade=0.2, pad=100.0, pad_style="constant", pad_velocity=6000.0
    )
    mesh = tm.generate_mesh(size.domain, size, seed=0)
    assert stable_timestep(mesh, size) > 0
    with pytest.raises(SizingError, match=r"the mesh reaches 100 m beyond the velocity model's box; its padding is"):
        stable_timestep(mesh, model)
    kilometres = tm.Mesh(mesh.points * 1000.0, mesh.cells)
    with pytest.raises(SizingError, match="beyond the velocity model's box"):
        stable_timestep(kilometres, size)


def test_a_mesh_with_a_zero_length_edge_has_no_step():
    # one cell with a repeated corner made the step 0.0, returned as if the mesh allowed no step at all
    model = uniform(2000.0, nx=41, nz=21)
    size = size_function(model, frequency=5.0, hmin=20.0, grade=0.2)
    mesh = tm.generate_mesh(size.domain, size, seed=0)
    cells = mesh.cells.copy()
    cells[0] = [cells[0, 0], cells[0, 0], cells[0, 1]]
    message = r"the mesh has 1 zero-length edges \(of \d+\): .* terramesh\.cleanup\.fix_mesh\(mesh\) merges"
    with pytest.raises(MeshValidityError, match=message):
        stable_timestep(tm.Mesh(mesh.points, cells), size)
    twin = np.vstack([mesh.points, mesh.points[cells[1, 0]]])  # a cell's corner and a vertex at its place
    cells[1, 1] = len(twin) - 1
    with pytest.raises(MeshValidityError, match="the mesh has 2 zero-length edges"):
        stable_timestep(tm.Mesh(twin, cells), size)


def test_a_time_step_in_milliseconds_is_named():
    # dt=20 (ms meant) was blamed on km: "Are the spacing, hmin and pad in km?"
    with pytest.raises(SizingError, match=r"the CFL floor of dt=20 s raised it .* Is dt in seconds"):
        size_function(uniform(), frequency=2.0, hmin=40.0, dt=20)


def test_a_pad_thinner_than_an_element_and_an_acquisition_size_the_cfl_floor_raised_are_named():
    # pad=1 (km meant) became a 10 m layer silently; the settings said acquisition_size 25 where the floor made 60
    with pytest.warns(TerrameshWarning, match=r"layer is 10 m wide \(pad=1.0, in whole grid cells\), less than"):
        size_function(uniform(), frequency=2.0, hmin=20.0, pad=1.0)
    with pytest.warns(TerrameshWarning, match=r"raises the size at 1 of the 1 sources and receivers above acq"):
        size_function(uniform(), frequency=5.0, hmin=20.0, dt=0.01, sources=[(200.0, -100.0)], acquisition_size=25.0)


def test_a_grid_too_coarse_for_the_acquisition_radius_is_not_blamed_on_dt():
    # 100 m nodes around a source at a 40 m size: 122.5 m between them with or without dt, blamed on dt=1e-6
    model = read_velocity(np.full((41, 21), 3000.0), spacing=100.0, axis_order="xz")
    sources = [(1550.0, -50.0), (2050.0, -1050.0)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        size_function(model, frequency=2.0, hmin=40.0, sources=sources, dt=1e-6)
        size_function(model, frequency=2.0, hmin=40.0, pad=30.0)  # laid as 100 m, a whole cell: not thin
