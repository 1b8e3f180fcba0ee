"""Mesh sizes for seismic wave propagation: wavelength, velocity gradient, CFL, bounds, gradation and padding.

All lengths are metres, velocities m/s, frequencies Hz and times seconds;
coordinates are ``(x, z)`` in 2-D and ``(x, y, z)`` in 3-D, with z negative
downward (see :mod:`terramesh.seismic.model`). The sizes are target
edge lengths on the velocity model's grid; 2-D and 3-D models go through
the same steps.

Cells per wavelength by element order
-------------------------------------
The wavelength size is ``h = v / (f n)``: ``n`` edges per wavelength
``v / f`` of the peak source frequency ``f``. The number needed depends on
the element. :data:`CELLS_PER_WAVELENGTH` holds, for mass-lumped (KMV)
triangles of degree 2-5, and :data:`CELLS_PER_WAVELENGTH_3D` for
tetrahedra of degree 2-3, the values spyro uses to size its automatic
meshes (``cells_per_wavelength`` in
``spyro/meshing/meshing_parameters.py`` of NDF-Poli-USP/spyro; its
earlier releases used 6.70, 3.55, 2.41, 1.84 for triangles and 5.85, 3.08
for tetrahedra); the approach is that of Roberts et al. (2022). Degree 1
takes the customary ten per wavelength of linear elements, the value
SeismicMesh's BP2004 example uses (``wl=10``): a rule of thumb, not a
calibrated value, and in 3-D the same rule of thumb carried over from 2-D
(spyro has no calibration for linear tetrahedra).

=============  ======================  ==============================
element order  2-D triangles (``n``)   3-D tetrahedra (``n``)
=============  ======================  ==============================
1              10 (rule of thumb)      10 (the 2-D rule of thumb)
2              7.02                    6.12
3              3.70                    3.72
4              2.67                    --
5              2.03                    --
=============  ======================  ==============================

Give ``cells_per_wavelength`` to use another value (e.g. for a different
element or accuracy target).

References
----------
K. J. Roberts, A. Olender, L. Franceschini, R. C. Kirby, R. S. Gioria and
B. S. Carmo, "spyro: a Firedrake-based wave propagation and
full-waveform-inversion finite-element solver", Geoscientific Model
Development 15, 8639-8667, 2022. :doi:`10.5194/gmd-15-8639-2022`
"""

import math
import numbers

import numpy as np

from .._kernels import physical_memory, read_only
from .._kernels.precompile import compile_ahead_on_first_run
from .._kernels.raster import largest_along_2d, largest_along_3d, lower_near_points
from ..errors import MeshValidityError, SizingError, checked_number, warn_user
from ..geometry.primitives import Rectangle
from ..geometry.primitives3d import Box
from ..mesh.mesh import Mesh
from ..mesh.topology import unique_edges
from ..sizing.edge_length import as_size_function
from ..sizing.edge_shrink import EDGE_SHRINK, EDGE_SHRINK_3D, EDGE_SHRINK_SEISMIC
from ..sizing.gradation import lift_to_floor, limit_gradient
from ..sizing.grid import SizeGrid
from .model import KM_PER_S_BELOW, MAX_VELOCITY, VelocityModel, unit_mismatch

__all__ = [
    "CELLS_PER_WAVELENGTH",
    "CELLS_PER_WAVELENGTH_3D",
    "COURANT",
    "EDGE_SHRINK",
    "EDGE_SHRINK_3D",
    "EDGE_SHRINK_SEISMIC",
    "PAD_STYLES",
    "ALIASES",
    "SeismicSize",
    "ModelBox",
    "size_function",
    "wavelength_size",
    "gradient_size",
    "cfl_size",
    "stable_timestep",
    "pad_model",
]

CELLS_PER_WAVELENGTH = {1: 10.0, 2: 7.02, 3: 3.70, 4: 2.67, 5: 2.03}
"""Edges per wavelength for triangles, by element order (see the module notes for the sources)."""

CELLS_PER_WAVELENGTH_3D = {1: 10.0, 2: 6.12, 3: 3.72}
"""Edges per wavelength for tetrahedra, by element order (spyro's calibration; order 1: the 2-D rule of thumb)."""

COURANT = 1.0
"""Default largest Courant number ``Cr = k v dt / h`` (SeismicMesh's ``cr_max`` default); set your solver's."""

PAD_STYLES = ("edge", "constant", "linear")
"""How the velocity is extended into the padding layer (``"linear_ramp"`` is accepted for ``"linear"``)."""


ALIASES = {
    "wl": "cells_per_wavelength",
    "freq": "frequency",
    "domain_pad": "pad",
    "cr_max": "courant",
    "space_order": "element_order",
}
"""SeismicMesh's option names that :func:`size_function` accepts for its own, mapped in this one place."""


def positive_number(name, value, *, unit=""):
    """``value`` as a finite float above 0, else a SizingError naming ``name`` and its ``unit`` (e.g. ``" (Hz)"``)."""
    return checked_number(value, f"{name} must be a positive finite number{unit}", SizingError, minimum=0, strict=True)


def _non_negative_length(name, value):
    """``value`` as a finite length >= 0 (metres), else SizingError."""
    return checked_number(value, f"{name} must be a non-negative length in metres", SizingError, minimum=0)


def _order(element_order):
    if not isinstance(element_order, numbers.Integral) or isinstance(element_order, bool) or element_order < 1:
        raise SizingError(f"element_order must be a positive integer (polynomial degree), got {element_order!r}")
    return int(element_order)


def _velocity(velocity):
    """Velocities as a float64 array, refusing NaN, infinite, zero and negative values, and km/s."""
    if isinstance(velocity, VelocityModel):
        array = velocity.values
    else:
        try:
            array = np.asarray(velocity, dtype=np.float64)
        except (TypeError, ValueError):
            raise SizingError("velocity must be numbers (m/s) or a VelocityModel") from None
        bad = ~np.isfinite(array)
        if bad.any():
            raise SizingError(f"velocity has {int(bad.sum())} NaN or infinite values")
        if np.any(array <= 0):
            raise SizingError(f"velocity has {int(np.sum(array <= 0))} zero or negative values")
    _refuse_km_per_s(array)
    return array


def _refuse_km_per_s(velocity, what="the velocities"):
    """Refuse velocities that look like km/s: sizes and time steps from them would be 1000 times too small."""
    if velocity.size and float(np.max(velocity)) < KM_PER_S_BELOW:
        raise SizingError(
            f"{what} are {float(np.min(velocity)):g}..{float(np.max(velocity)):g}, which look like km/s; "
            "sizes and time steps need m/s: read the model with units='km/s' (read_velocity; --units km/s on the "
            "command line) or multiply the values by 1000"
        )


def wavelength_size(velocity, *, frequency, cells_per_wavelength):
    """Wavelength size ``h = v / (f n)``: ``n`` edges per wavelength ``v / f``, metres.

    Parameters
    ----------
    velocity : array_like or VelocityModel
        P-wave velocity ``v``, m/s, positive.
    frequency : float
        Peak source frequency ``f``, Hz, positive.
    cells_per_wavelength : float
        ``n``, edges per wavelength (see :data:`CELLS_PER_WAVELENGTH`).

    Returns
    -------
    ndarray
        Metres, the shape of ``velocity``.

    Raises
    ------
    SizingError
        For a zero, negative or non-finite frequency or ``n``, or bad velocities (not finite and
        positive, or all below 20 m/s: km/s).

    Examples
    --------
    A 2 Hz wave in water (1500 m/s) is 750 m long; ten edges per wavelength:

    >>> wavelength_size([1500.0, 4500.0], frequency=2.0, cells_per_wavelength=10).tolist()
    [75.0, 225.0]
    """
    frequency = positive_number("frequency", frequency, unit=" (Hz)")
    cells_per_wavelength = positive_number("cells_per_wavelength", cells_per_wavelength)
    return _velocity(velocity) / (frequency * cells_per_wavelength)


def gradient_size(velocity, spacing, *, elements):
    """Velocity-gradient size ``h = v / (m |grad v|)``: ``m`` edges per velocity scale length, metres.

    ``L = v / |grad v|`` is the distance over which the velocity would change
    by 100 % at the local gradient, so sharp contrasts (a salt flank) get
    small elements. ``|grad v|`` is taken with second-order central
    differences (one-sided at the grid edges); where it is zero the size is
    ``inf`` (no limit).

    Parameters
    ----------
    velocity : array_like, shape (nx, nz) or (nx, ny, nz), or VelocityModel
        m/s, indexed ``[ix, iz]`` (``[ix, iy, iz]``).
    spacing : float or sequence of float
        ``(dx, dz)`` or ``(dx, dy, dz)``, metres (one number for all axes);
        taken from the model for a VelocityModel.
    elements : float
        ``m``, positive.

    Returns
    -------
    ndarray
        Metres, the shape of ``velocity``; ``inf`` where the velocity is
        locally constant.

    Raises
    ------
    SizingError
        For a non-positive ``elements``, bad velocities (not finite and positive, or all below
        20 m/s: km/s), or a spacing that
        is not positive or does not have one number per axis.

    Examples
    --------
    Velocity rising 1 m/s per metre from 1000 m/s, two edges per scale length:

    >>> v = np.outer([1.0, 1.0], [1000.0, 1010.0, 1020.0])
    >>> gradient_size(v, 10.0, elements=2).round(3).tolist()[0]
    [500.0, 505.0, 510.0]

    The same ramp in 3-D, the y axis 20 m apart:

    >>> gradient_size(np.stack([v, v], axis=1), (10.0, 20.0, 10.0), elements=2).round(3).tolist()[0][1]
    [500.0, 505.0, 510.0]
    """
    elements = positive_number("elements", elements)
    if isinstance(velocity, VelocityModel):
        spacing = velocity.spacing
    values = _velocity(velocity)
    try:
        steps = np.asarray(spacing, dtype=np.float64)
    except (TypeError, ValueError):
        steps = np.array([np.nan])
    if steps.ndim == 0:
        steps = np.full(values.ndim, float(steps))
    if steps.shape != (values.ndim,) or not np.all(np.isfinite(steps)) or np.any(steps <= 0):
        raise SizingError(
            f"spacing must be one positive length or {values.ndim} (one per axis) for velocities of shape "
            f"{values.shape}, got {spacing!r}"
        )
    if values.ndim == 0:
        raise SizingError("gradient_size needs velocities on a grid (at least 2 nodes per axis), got one value")
    if min(values.shape) < 2:
        raise SizingError(f"gradient_size needs at least 2 nodes per axis, got shape {values.shape}")
    square = np.zeros_like(values)
    for derivative in np.gradient(values, *steps):
        square += derivative**2
    with np.errstate(divide="ignore"):
        return values / (elements * np.sqrt(square))


def cfl_size(velocity, *, dt, element_order=1, courant=COURANT):
    """Smallest size that keeps ``Cr = k v dt / h`` at most ``courant``: ``h_cfl = k v dt / Cr``, metres.

    An order-``k`` element of size ``h`` has nodes about ``h / k`` apart, so
    the explicit time step ``dt`` is stable where ``v dt / (h / k) <= Cr``.
    This is the bound SeismicMesh applies with its ``cr_max`` and
    ``space_order``; the stable ``Cr`` depends on the time-stepping scheme
    and the element and is the solver's to give.

    Parameters
    ----------
    velocity : array_like or VelocityModel
        m/s.
    dt : float
        Time step, seconds, positive.
    element_order : int, optional
        ``k``, the polynomial degree.
    courant : float, optional
        Largest Courant number ``Cr``.

    Returns
    -------
    ndarray
        Metres, the shape of ``velocity``.

    Raises
    ------
    SizingError
        For a non-positive ``dt`` or ``courant``, a bad ``element_order``,
        or bad velocities (not finite and positive, or all below 20 m/s:
        km/s).

    Examples
    --------
    >>> cfl_size([1500.0, 4500.0], dt=0.01, element_order=2, courant=0.5).tolist()
    [60.0, 180.0]
    """
    dt = positive_number("dt", dt, unit=" (s)")
    courant = positive_number("courant", courant)
    return _order(element_order) * _velocity(velocity) * dt / courant


def _mesh_timestep(mesh, model, order, courant):
    """``min(Cr L / (k v_max))`` over a mesh's edges, ``v_max`` the model's largest along each edge.

    The velocity is sampled at both ends and at least every half grid step
    in between (so the midpoint too): an edge from slow into fast rock is
    limited by the fast side, and the midpoint alone (1500 m/s over 4500
    m/s) overestimated the time step by 27 %.
    """
    model = getattr(model, "model", model)  # a SeismicSize carries its (padded) model
    if not isinstance(model, VelocityModel):
        raise SizingError("a mesh's stable time step needs its VelocityModel (or its SeismicSize) as velocity")
    if model.dim != mesh.dim:  # else the model's grid refuses the mesh's points with its own, obscure, words
        raise SizingError(
            f"the model is {model.dim}-D but the mesh is {mesh.dim}-D: give the {mesh.dim}-D model (or size "
            "function) the mesh was made from"
        )
    _refuse_km_per_s(model.values, "the model's velocities")
    low, high = model.bbox
    mesh_box = np.array([mesh.points.min(axis=0), mesh.points.max(axis=0)])
    if unit_mismatch(mesh_box, model.bbox) == "km":  # within the model's box, and a time step 1000 times too short
        raise SizingError(
            "the mesh is about 1/1000 of the velocity model's extent on every axis: a mesh in km with a model in m? "
            "give the mesh in metres (tm.Mesh(mesh.points * 1000, mesh.cells))"
        )
    beyond = float(np.max(np.maximum(low - mesh_box[0], mesh_box[1] - high)))
    if beyond > 1e-6 * float(np.max(high - low)):
        # outside the grid a model reads its edge values: a padded mesh against the unpadded model missed the pad's
        # velocity (a 6000 m/s pad: a step 1.6 times too long)
        padded = "; its padding is in the size function's model (pass the size function)" if not any(model.pad) else ""
        raise SizingError(
            f"the mesh reaches {beyond:.4g} m beyond the velocity model's box{padded}: give the model (or size "
            "function) the mesh was made for, in the mesh's units"
        )
    edges = unique_edges(mesh.cells)
    if len(edges) == 0:
        raise SizingError("the mesh has no edges")
    start, end = mesh.points[edges[:, 0]], mesh.points[edges[:, 1]]
    lengths = np.sqrt(np.sum((end - start) ** 2, axis=1))
    collapsed = int(np.count_nonzero(lengths == 0))
    if collapsed:  # a time step of 0 was returned, as if the mesh allowed none
        repair = (
            "terramesh.cleanup.fix_mesh(mesh) merges such vertices and drops such cells"
            if mesh.dim == 2
            else "drop such cells and merge such vertices, or generate the mesh again"
        )
        raise MeshValidityError(
            f"the mesh has {collapsed} zero-length edges (of {len(edges)}): cells with a repeated corner, or two "
            f"vertices at one place, whose time step is 0; repair the mesh first: {repair}"
        )
    # 2 m + 1 samples per edge, m >= 1, at most half the smallest grid step apart, none stored (7.7 s of NumPy for
    # 800 thousand vertices in 2D, twice the generation's time at 200 thousand)
    samples = 2 * np.maximum(1, np.ceil(lengths / min(model.spacing)).astype(np.int64)) + 1
    grid = model._grid
    largest_along = largest_along_2d if mesh.dim == 2 else largest_along_3d
    fastest = largest_along(read_only(grid.values), grid._origin, grid._spacing, start, end, samples)
    return float(np.min(courant * lengths / (order * fastest)))


def stable_timestep(sizes, velocity=None, *, element_order=1, courant=COURANT):
    """Largest time step stable on these sizes, or on a mesh: ``dt = min(Cr h / (k v))``, seconds.

    Parameters
    ----------
    sizes : array_like, SizeGrid, SeismicSize or Mesh
        Edge lengths ``h``, metres, the shape of ``velocity`` (or a
        :class:`SeismicSize`, which brings its velocity). A mesh gives its
        own edges, each with the largest velocity along it (sampled at
        its ends and every half grid step): DistMesh's edges come out
        shorter than their size, so a mesh's limit is below its size
        function's, and it is the one the solver meets.
    velocity : array_like, VelocityModel or SeismicSize, optional
        m/s; leave out (None) for a :class:`SeismicSize`; for a mesh, its
        model (or the size function, which carries it).
    element_order : int, optional
        ``k``.
    courant : float, optional
        ``Cr``.

    Returns
    -------
    float
        Seconds.

    Raises
    ------
    SizingError
        For no sizes, sizes not positive and finite or not of the velocity's
        shape, bad velocities (not finite and positive, or all below 20
        m/s: km/s), a bad ``element_order`` or ``courant``, a mesh and a
        model of different dimensions, or a mesh about 1/1000 of its model's
        extent (a mesh in km against a model in m).
    MeshValidityError
        For a mesh with zero-length edges (a cell with a repeated corner,
        two vertices at one place), whose step would be 0.

    Examples
    --------
    >>> round(stable_timestep([75.0, 225.0], [1500.0, 4500.0]), 6)
    0.05
    """
    courant = positive_number("courant", courant)
    order = _order(element_order)
    if isinstance(sizes, Mesh):
        return _mesh_timestep(sizes, velocity, order, courant)
    if isinstance(sizes, SeismicSize) and velocity is None:
        velocity = sizes.model.values
    if velocity is None:
        raise SizingError("stable_timestep needs the velocity (m/s) unless the sizes are a SeismicSize")
    try:
        sizes = np.asarray(sizes.values if isinstance(sizes, SizeGrid) else sizes, dtype=np.float64)
    except (TypeError, ValueError):
        raise SizingError("sizes must be numbers (edge lengths, metres) or a SizeGrid") from None
    velocity = _velocity(velocity)
    if sizes.shape != velocity.shape:
        raise SizingError(f"sizes {sizes.shape} and velocity {velocity.shape} must have the same shape")
    if sizes.size == 0:
        raise SizingError("stable_timestep needs at least one size and velocity, got none")
    if not np.all(np.isfinite(sizes)) or np.any(sizes <= 0):
        raise SizingError("sizes must be positive and finite")
    return float(np.min(courant * sizes / (order * velocity)))


def _pad_widths(pad, dim):
    count = 3 if dim == 2 else 5
    names = "(left, right, bottom)" if dim == 2 else "(x-, x+, y-, y+, bottom)"
    try:
        widths = np.asarray(pad, dtype=np.float64)
    except (TypeError, ValueError):
        raise SizingError(f"pad must be a width in metres or {count} widths {names}, got {pad!r}") from None
    if widths.ndim == 0:
        widths = np.full(count, float(widths))
    if widths.shape != (count,):
        raise SizingError(f"pad must be a width in metres or {count} widths {names}, got {pad!r}")
    if not np.all(np.isfinite(widths)) or np.any(widths < 0):
        raise SizingError(f"pad widths must be finite and non-negative metres, got {widths.tolist()}")
    return widths


def pad_model(model, pad, *, style="edge", velocity=None):
    """Extend a velocity model by a padding (sponge) layer on the sides and the bottom, not the top.

    The top is the free surface and gets no layer. Each width is rounded up
    to a whole number of grid cells (the widths used are in the result's
    ``pad``). The velocity in the layer follows ``style``:

    * ``"edge"``: the velocity at the nearest model edge, constant outward;
    * ``"constant"``: ``velocity`` everywhere in the layer;
    * ``"linear"``: a linear ramp from the edge velocity to ``velocity`` at
      the outer boundary (``"linear_ramp"``, SeismicMesh's name, also works).

    Parameters
    ----------
    model : VelocityModel
        A 2-D or 3-D model (m/s, metres).
    pad : float or sequence of float
        Layer width, metres: one for every side, or ``(left, right,
        bottom)`` in 2-D (``(x-, x+, y-, y+, bottom)`` in 3-D).
    style : {"edge", "constant", "linear"}, optional
    velocity : float, optional
        m/s, for ``"constant"`` and ``"linear"`` (the ``"edge"`` style uses
        none, and refuses one); defaults to the model's largest velocity.

    Returns
    -------
    VelocityModel
        The padded model; its ``pad`` gives the widths (metres) and its
        ``interior_bbox`` the original extent. The input is not modified.

    Raises
    ------
    SizingError
        For a negative width, an unknown style, a bad velocity (one below
        20 m/s looks like km/s, as the model's would; one above 20 km/s is
        refused as theirs are), a velocity with the ``"edge"`` style, or
        widths whose padded model does not fit in memory beside the model.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.seismic import VelocityModel
    >>> model = VelocityModel(np.full((3, 2), 2000.0), ([0.0, 10.0, 20.0], [-10.0, 0.0]))
    >>> padded = pad_model(model, 15.0, style="constant", velocity=3000.0)
    >>> padded.pad, padded.bbox.tolist()
    ((20.0, 20.0, 20.0), [[-20.0, -30.0], [40.0, 0.0]])
    >>> padded([(-20.0, 0.0), (10.0, -5.0)]).tolist()
    [3000.0, 2000.0]

    In 3-D the five widths are ``(x-, x+, y-, y+, bottom)``:

    >>> cube = VelocityModel(np.full((2, 2, 2), 2000.0), ([0.0, 10.0], [0.0, 20.0], [-5.0, 0.0]))
    >>> pad_model(cube, (0.0, 10.0, 20.0, 0.0, 5.0)).bbox.tolist()
    [[0.0, -20.0, -10.0], [20.0, 20.0, 0.0]]
    """
    if not isinstance(model, VelocityModel):
        raise SizingError(f"pad_model needs a VelocityModel, got {type(model).__name__}")
    style = "linear" if style == "linear_ramp" else style
    if style not in PAD_STYLES:
        raise SizingError(f"pad_style must be one of {PAD_STYLES}, got {style!r}")
    widths = _pad_widths(pad, model.dim)
    value = model.vmax if velocity is None else _pad_velocity(velocity, style)
    spacing = model.spacing
    steps = [spacing[0], spacing[0]] + ([spacing[1], spacing[1]] if model.dim == 3 else []) + [spacing[-1]]
    cells = [int(math.ceil(w / d - 1e-9)) for w, d in zip(widths, steps, strict=True)]
    if not any(cells):
        return model
    # pad (before, after) per axis [x, (y,) z]; z is increasing upward, so the bottom is "before"
    padding = [(cells[0], cells[1])] + ([(cells[2], cells[3])] if model.dim == 3 else []) + [(cells[-1], 0)]
    _check_padded_size(model, padding, widths)
    if style == "edge":
        values = np.pad(model.values, padding, mode="edge")
    elif style == "constant":
        values = np.pad(model.values, padding, mode="constant", constant_values=value)
    else:
        values = np.pad(model.values, padding, mode="linear_ramp", end_values=value)
    axes = [
        axis[0] - step * before + step * np.arange(n)
        for axis, step, (before, _), n in zip(model.axes, spacing, padding, values.shape, strict=True)
    ]
    used = tuple(float(n * d) for n, d in zip(cells, steps, strict=True))
    total = tuple(a + b for a, b in zip(model.pad, used, strict=True))
    return VelocityModel(values, axes, pad=total, source=model.source)


def _check_padded_size(model, padding, widths):
    """Refuse a padding whose model would not fit in memory beside the model (a width in the wrong units, most often).

    ``np.pad`` makes the padded model while the model is held: both must
    fit. A large model that fits is refused only where its padding does not.
    """
    memory = physical_memory()
    nodes = math.prod(n + before + after for n, (before, after) in zip(model.shape, padding, strict=True))
    needed = 8 * (nodes + math.prod(model.shape))
    if memory is not None and needed > memory:
        raise SizingError(
            f"a padding of {max(widths):g} m makes a model of {nodes:.3g} nodes: with the model it needs"
            f" {needed / 2**30:.3g} GiB, more than this machine's {memory / 2**30:.0f} GiB of memory: is the pad in"
            f" metres, as the model's {model.spacing[0]:g} m spacing is?"
        )


def _pad_velocity(velocity, style):
    """The padding's velocity, m/s, checked as the model's are (a km/s value refused), for a style that uses one."""
    if style == "edge":
        # the edge style extends the model's own edge velocities: a velocity given with it went unused, silently
        raise SizingError(
            f"pad_velocity={velocity!r} is for pad_style 'constant' or 'linear'; the 'edge' style extends the "
            "model's edge velocities and uses none: give pad_style='constant' or 'linear', or leave pad_velocity out"
        )
    value = positive_number("pad_velocity", velocity, unit=" (m/s)")
    if value < KM_PER_S_BELOW:  # the bound a model's velocities are refused below (size_function)
        raise SizingError(
            f"pad_velocity={value:g} looks like km/s (below {KM_PER_S_BELOW:g} m/s, where a model's velocities "
            f"are refused too); sizes need m/s: give {1000 * value:g}"
        )
    if value > MAX_VELOCITY:  # sizes of tens of kilometres beside the model's: a mesh that fails far later
        raise SizingError(
            f"pad_velocity={value:g} m/s is faster than any Earth material (at most {MAX_VELOCITY:g} m/s), as a"
            " model's velocities are refused"
        )
    return value


def _pad_mask(model):
    """Nodes of a padded model that lie in the padding layer: beyond the interior on any side but the top."""
    inner = model.interior_bbox
    tolerance = 1e-9 * max(model.spacing)
    layer = np.zeros(model.shape, dtype=bool)
    for k, axis in enumerate(model.axes):
        outside = axis < inner[0, k] - tolerance
        if k < model.dim - 1:  # the last axis is z, whose upper end is the free surface
            outside |= axis > inner[1, k] + tolerance
        layer |= outside.reshape([-1 if j == k else 1 for j in range(model.dim)])
    return layer


def _points(name, points, bbox):
    """Acquisition points as an ``(n, dim)`` array inside ``bbox`` (one point may be given flat)."""
    dim = bbox.shape[1]
    frame = "(x, z)" if dim == 2 else "(x, y, z)"
    if points is None:
        return np.empty((0, dim))
    try:
        array = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise SizingError(f"{name} must be {frame} points, an array of shape (n, {dim}), metres") from None
    if array.ndim == 1 and array.size in (0, dim):
        array = array.reshape(-1, dim)
    if array.ndim != 2 or array.shape[1] != dim:
        raise SizingError(
            f"{name} must be {frame} points of this {dim}-D model, an array of shape (n, {dim}) in metres; "
            f"got shape {array.shape}"
        )
    if not np.all(np.isfinite(array)):
        raise SizingError(f"{name} have NaN or infinite coordinates")
    outside = np.any((array < bbox[0] - 1e-9) | (array > bbox[1] + 1e-9), axis=1)
    if outside.any():
        raise SizingError(
            f"{int(outside.sum())} {name} lie outside the model {bbox.tolist()}, e.g. {array[outside][0].tolist()} "
            f"(coordinates are {frame}, z negative downward)"
        )
    return array


def _refine_near(values, axes, points, size, radius):
    """Lower ``values`` to ``size`` at the grid nodes within ``radius`` of any point (in place).

    A compiled loop over the points (a Python one took 0.33 s for 10,400
    sources and receivers, 7 % of a 3-D job; now 9 ms).
    """
    points = np.asarray(points, dtype=np.float64)
    if len(points) == 0:
        return
    work = np.ascontiguousarray(values, dtype=np.float64)  # the kernel writes through a view of it
    if len(axes) == 2:
        grid, (x, z), y = work.reshape(work.shape[0], 1, work.shape[1]), axes, np.zeros(1)
        points = np.column_stack([points[:, 0], np.zeros(len(points)), points[:, 1]])
    else:
        grid, (x, y, z) = work, axes
    lower_near_points(
        grid,
        *(np.ascontiguousarray(axis, dtype=np.float64) for axis in (x, y, z)),
        np.ascontiguousarray(points),
        float(size),
        float(radius),
    )
    if work is not values:
        values[...] = work


def _side_nodes(bbox, size):
    """Nodes along the four sides of a box, counter-clockwise from the lower left, spaced by ``size``.

    On each side the number of segments is the rounded integral of ``1 / h``
    along it, and the nodes split that integral evenly, so each segment is
    about the local size long.
    """
    (x0, z0), (x1, z1) = bbox
    corners = np.array([[x0, z0], [x1, z0], [x1, z1], [x0, z1]])
    size = as_size_function(size)
    smallest = float(np.min(size(np.vstack([corners, corners.mean(axis=0, keepdims=True)]))))
    nodes = []
    for start, end in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        length = float(np.hypot(*(end - start)))
        probe = start + np.linspace(0.0, 1.0, 4097)[:, None] * (end - start)
        smallest = min(smallest, float(size(probe).min()))
        samples = int(np.clip(np.ceil(16.0 * length / smallest), 64, 400_000))
        t = np.linspace(0.0, 1.0, samples + 1)
        inverse = 1.0 / size(start + t[:, None] * (end - start))
        walked = np.concatenate([[0.0], np.cumsum(0.5 * (inverse[1:] + inverse[:-1]) * (length / samples))])
        segments = max(1, int(round(walked[-1])))
        at = np.interp(np.linspace(0.0, walked[-1], segments + 1)[:-1], walked, t)
        nodes.append(start + at[:, None] * (end - start))
    return np.vstack(nodes)


class ModelBox(Rectangle):
    """The 2-D model's box as a domain whose sides carry nodes spaced by the mesh size.

    A :class:`~terramesh.geometry.Rectangle` (exact signed distance) whose
    :meth:`corners`, the points :func:`terramesh.generate_mesh` keeps fixed,
    are the four corners and, with a ``size``, nodes along the four sides
    about one local edge length apart. Long straight sides seeded that way
    start with an even row of boundary cells: on BP2004 (1 Hz, hmin 300 m)
    the worst cell's quality rose from 0.64-0.76 to 0.70-0.77 over five
    seeds.

    Parameters
    ----------
    lower, upper : array_like, shape (2,)
        Opposite corners ``(x, z)``, metres.
    size : float, callable or SizeGrid, optional
        Edge length along the sides, metres; without it only the four
        corners are fixed, as for a Rectangle.

    Examples
    --------
    >>> box = ModelBox((0.0, -100.0), (300.0, 0.0), 50.0)
    >>> len(box.corners())  # 6 + 2 + 6 + 2 segments around
    16
    """

    def __init__(self, lower, upper, size=None):
        super().__init__(lower, upper)
        if size is None:
            self._nodes = super().corners()
        else:
            self._nodes = _side_nodes(self.bbox, size)

    def corners(self):
        """The fixed boundary nodes, shape ``(n, 2)``: the corners and the side nodes, counter-clockwise."""
        return self._nodes.copy()


class SeismicSize(SizeGrid):
    """A seismic mesh size function: a :class:`~terramesh.sizing.SizeGrid` with its domain and velocity.

    Made by :func:`size_function`; pass it to
    :func:`terramesh.generate_mesh` as the edge length, with
    :attr:`domain` as the domain.

    Attributes
    ----------
    values : ndarray, shape (nx, nz) or (nx, ny, nz)
        Target edge length at the grid nodes, metres.
    axes : tuple of ndarray
        ``(x, z)`` or ``(x, y, z)`` node coordinates, metres, z negative
        downward.
    domain : ModelBox or Box
        The (padded) model box: in 2-D a :class:`ModelBox` (a Rectangle
        with fixed nodes along its sides spaced by these sizes), in 3-D a
        :class:`~terramesh.geometry.Box`.
    model : VelocityModel
        The velocity on the same grid (padded as the sizes are), m/s, for
        writing velocities on a mesh (:func:`terramesh.io.write_fwi_mesh`).
    pad : tuple of float
        Widths of the padding layer, metres: ``(left, right, bottom)`` in
        2-D, ``(x-, x+, y-, y+, bottom)`` in 3-D.
    settings : dict
        The options the sizes were made with (frequency, cells per
        wavelength, element order, hmin, hmax, grade, dt, courant...).
    """

    def __init__(self, axes, values, *, model, settings):
        super().__init__(axes, values)
        self.model = model
        self.pad = model.pad
        self.settings = dict(settings)
        self._domain = None

    @property
    def axis_names(self):
        """``"xz"`` or ``"xyz"``: z is the section's second axis."""
        return "xz" if self.dim == 2 else "xyz"

    @property
    def domain(self):
        """The (padded) model box, metres: a :class:`ModelBox` with nodes along its sides in 2-D, a Box in 3-D."""
        if self._domain is None:
            if self.dim == 2:
                self._domain = ModelBox(self.bbox[0], self.bbox[1], self)
            else:
                self._domain = Box(self.bbox[0], self.bbox[1])
        return self._domain

    @property
    def interior_bbox(self):
        """The model's box without the padding layer, shape ``(2, dim)``, metres."""
        return self.model.interior_bbox

    def stable_timestep(self, *, courant=None):
        """The time step these sizes allow, seconds (:func:`stable_timestep` of the size grid): not a mesh's.

        A mesh's shortest edges come out shorter than their sizes, so its
        step is below this one (0.79-0.84 of it in 2-D; in 3-D on the BP2004
        example, two seeds, 0.59-0.63 without ``dt`` and 0.47-0.51 with 0.035 s,
        whose sizes allow for it): step a solver at :meth:`check_timestep` of the mesh. Uses
        the element order of the settings and ``courant`` (default: the
        settings' Courant number).
        """
        courant = self.settings["courant"] if courant is None else courant
        return stable_timestep(
            self.values, self.model.values, element_order=self.settings["element_order"], courant=courant
        )

    def check_timestep(self, mesh):
        """Stable time step of a mesh made from these sizes, seconds, warning if below the ``dt`` asked for.

        Parameters
        ----------
        mesh : Mesh
            A mesh of :attr:`domain` made with these sizes.

        Returns
        -------
        float
            :func:`stable_timestep` of the mesh at the settings' element
            order and Courant number, seconds.

        Warns
        -----
        TerrameshWarning
            If the sizes were made with ``dt`` and the mesh's step is
            below it, with both numbers.

        Examples
        --------
        >>> import numpy as np, terramesh as tm
        >>> from terramesh.seismic import read_velocity
        >>> model = read_velocity(np.full((11, 21), 3000.0), spacing=25.0, axis_order="zx")
        >>> size = size_function(model, frequency=4, hmin=20, dt=0.01)
        >>> mesh = tm.generate_mesh(size.domain, size, seed=0)
        >>> size.check_timestep(mesh) >= 0.01
        True
        """
        order, courant, dt = self.settings["element_order"], self.settings["courant"], self.settings["dt"]
        step = stable_timestep(mesh, self, element_order=order, courant=courant)
        if dt is not None and step < dt:
            warn_user(
                f"the mesh's stable time step is {step:.4g} s, below the dt={dt:g} s its sizes were made for "
                f"(element order {order}, Courant {courant:g}): its shortest edges came out shorter than "
                f"EDGE_SHRINK_SEISMIC allows for; step the solver at {step:.4g} s or make the sizes with "
                f"dt={dt * dt / step:.4g} s",
            )
        return step

    def __repr__(self):
        nodes = " x ".join(str(n) for n in self.values.shape)
        extent = " x ".join(f"{hi - lo:g}" for lo, hi in self.bbox.T)
        return (
            f"<terramesh.seismic.SeismicSize: {nodes} nodes over {extent} m, "
            f"h {self.values.min():g}..{self.values.max():g} m>"
        )


ALL_HMIN_FRACTION = 0.99
"""Share of the model's nodes whose size is below ``hmin`` from which :func:`size_function` warns."""


def _check_units(model, hmin):
    """Refuse a model in km/s or on a grid in km, which would give a mesh of hmin-sized elements or none."""
    _refuse_km_per_s(model.values, "the model's velocities")
    extent = model.bbox[1] - model.bbox[0]
    if hmin > extent.max():
        sides = " x ".join(f"{side:g}" for side in extent)
        raise SizingError(
            f"hmin={hmin:g} m exceeds the model's extent ({sides} m): is its spacing in km? "
            "Give the spacing in metres, or a smaller hmin"
        )


def _check_sizes_fit(sizes, padded, hmin, wavelength, dt=None, *, frequency):
    """Refuse sizes whose smallest exceeds the (padded) model's every side: no mesh fits it.

    A spacing and hmin in km with velocities in m/s pass :func:`_check_units`
    (hmin fits the model) but give sizes of ``v / (f n)`` metres on a model
    about a thousand times smaller: 75-87.5 on one 2.4 x 1.9 x 1.2 across,
    and generation failed later with "h0 is too large" or "no lattice point".
    The longest side, not the shortest, is the bound: a thin model may be
    about one size deep (sizes of 150 m on a model 100 m deep are left
    alone), while a mistake in units is a factor of 1000. ``wavelength`` is
    the smallest wavelength size, ``v_min / (f n)``. Sizes raised by the
    CFL floor of ``dt`` above ``hmin`` and the wavelength sizes name ``dt``
    (20 for 0.02 s was blamed on km). Otherwise the wavelength sizes
    exceed the model (hmin fits it, :func:`_check_units`): a frequency far
    too low does that as well as lengths in km, and is named (1e-6 Hz was
    blamed on km alone).
    """
    smallest = float(sizes.min())
    extent = padded.bbox[1] - padded.bbox[0]
    if smallest <= extent.max():
        return
    sides = " x ".join(f"{side:g}" for side in extent)
    if dt is not None and smallest > max(hmin, wavelength):
        raise SizingError(
            f"the smallest mesh size, {smallest:g} m, exceeds every side of the model ({sides} m, padded): the CFL "
            f"floor of dt={dt:g} s raised it (the wavelength sizes start at {wavelength:g} m). Is dt in seconds? "
            "Lower it"
        )
    raise SizingError(
        f"the smallest mesh size, {smallest:g} m, exceeds every side of the model ({sides} m, padded): no mesh "
        f"fits (the wavelength sizes v / (f n) start at {wavelength:g} m for the slowest velocity, {padded.vmin:g} "
        f"m/s, at frequency={frequency:g} Hz; hmin is {hmin:g} m). Are the spacing, hmin and pad in km, or is the "
        "frequency too low or not in Hz? Give lengths in metres, the frequency in Hz and the velocities in m/s (read "
        "them with units='km/s' to convert)"
    )


def _warn_if_all_hmin(sizes, hmin, padded):
    """Warn when ``hmin`` overrides the wavelength size almost everywhere in the model (a uniform mesh)."""
    inside = sizes if not any(padded.pad) else sizes[~_pad_mask(padded)]
    below = float(np.mean(inside < hmin))
    if below >= ALL_HMIN_FRACTION:
        warn_user(
            f"hmin={hmin:g} m is above the wavelength size at {100 * below:.1f} % of the model's nodes "
            f"(largest {float(inside.max()):.3g} m): the mesh is uniform at hmin; lower hmin or the cells per "
            "wavelength, or check the units (m/s, metres) and frequency (Hz)",
        )


NARROW_WINDOW_GRADE = 1.0
"""The steepest grade for which the CFL floor's velocity window is :func:`mesh_cfl_floor`'s graded one."""


def mesh_cfl_floor(velocity, spacing, *, dt, order, courant, graded=False):
    """Sizes on the grid whose DistMesh mesh keeps ``dt`` stable: ``k v_max dt / (Cr s)``, metres.

    Two things make a mesh's time step (:func:`stable_timestep` of the mesh)
    fall below that of its size grid, ``k v dt / Cr``: an edge reaches half
    its length to either side of its midpoint, into faster rock next to a
    velocity contrast; and DistMesh's shortest edges come out below their
    size. ``s`` is :data:`EDGE_SHRINK_SEISMIC` (:data:`EDGE_SHRINK_3D`), the
    measured ratio, and allows for the second. For the first, ``v_max`` is
    the largest velocity within a window of the node. With ``graded`` (the
    floor is then graded upward, :func:`~terramesh.sizing.lift_to_floor`,
    at a grade of at most :data:`NARROW_WINDOW_GRADE`)
    the window is ``k V dt / (2 Cr)`` and one grid cell (``V`` the model's
    largest): an edge at least ``k V dt / Cr`` long keeps ``dt`` whatever
    it crosses, a shorter one reaches less than that half from its
    midpoint, whose size is interpolated from the nodes of its cell, and
    the velocity along it from the nodes of the cells it crosses. The
    ungraded floor keeps ``k V dt / (Cr s)`` (at least the graded window),
    5 times that half in 3-D (3.3 in 2-D): its jump at a contrast
    compresses the edges beside it below ``s`` of their size, and the wider
    window puts them in the slower rock (a thin 4500 m/s layer in 1500 m/s,
    2-D, no grade: 0.83-0.94 of ``dt`` at 0.01-0.02 s with the half window,
    0.94-1.04 with it).
    Graded, the half window keeps ``dt`` with more vertices where the
    floor binds (the BP2004 3-D example at 1 Hz and 0.04-0.08 s: 1.22-1.67
    ``dt`` with 48.3-7.7k vertices, against 1.15-1.69 with 43.4-5.4k).
    """
    from scipy.ndimage import maximum_filter

    shrink = EDGE_SHRINK_SEISMIC if velocity.ndim == 2 else EDGE_SHRINK_3D
    half = order * float(velocity.max()) * dt / (2 * courant)
    cells = [int(math.ceil(half / step)) + 1 for step in spacing]
    if not graded:  # never narrower than the graded window (a reach under a cell or two)
        reach = 2 * half / shrink
        cells = [max(count, int(math.ceil(reach / step))) for count, step in zip(cells, spacing, strict=True)]
    cells_across = tuple(2 * count + 1 for count in cells)
    fastest = maximum_filter(velocity, size=cells_across, mode="nearest")
    return cfl_size(fastest, dt=dt, element_order=order, courant=courant) / shrink


def _resolve_aliases(aliases, given):
    for short, value in aliases.items():
        if short not in ALIASES:
            known = ", ".join(sorted(ALIASES))
            raise TypeError(
                f"size_function() got an unexpected keyword argument {short!r} (SeismicMesh names: {known})"
            )
        long = ALIASES[short]
        if given[long] is not None:
            raise TypeError(f"{short!r} and {long!r} are the same option; give one")
        given[long] = value
    return given


def size_function(
    model,
    *,
    frequency=None,
    cells_per_wavelength=None,
    element_order=None,
    hmin=None,
    hmax=None,
    grade=None,
    pad=None,
    pad_style="edge",
    pad_velocity=None,
    coarsen_pad=True,
    gradient_refinement=None,
    velocity_window=None,
    dt=None,
    courant=None,
    sources=None,
    receivers=None,
    acquisition_size=None,
    acquisition_radius=None,
    **aliases,
):
    """Mesh sizes for seismic wave propagation from a 2-D or 3-D velocity model.

    On the model's grid, in this order (all lengths in metres), the same
    steps in 2-D and 3-D:

    1. pad the model (:func:`pad_model`): ``pad`` metres on the left, right
       (in 3-D also the front and back, y- and y+) and bottom, none on top
       (the free surface), velocities per ``pad_style``;
    2. wavelength: ``h = v_min / (f n)``, where ``v_min`` is the smallest
       velocity within a ``velocity_window`` square (cube in 3-D) around
       the node (so a slow layer thinner than an element still sets the
       element size) and ``n`` is ``cells_per_wavelength`` (by default
       from :data:`CELLS_PER_WAVELENGTH`, or :data:`CELLS_PER_WAVELENGTH_3D`
       for a 3-D model, for ``element_order``);
    3. velocity gradient, with ``gradient_refinement=m``:
       ``h = min(h, v / (m |grad v|))`` (:func:`gradient_size`);
    4. bounds: ``h = min(max(h, hmin), hmax)``;
    5. padding layer, with ``grade`` and ``coarsen_pad``: the size grows
       away from the model at the grade limit, ``h = h_edge + grade d`` at a
       distance ``d`` into the layer (up to ``hmax``);
    6. acquisition: ``h <= acquisition_size`` within ``acquisition_radius``
       of each source and receiver;
    7. gradation, with ``grade``: ``|grad h| <= grade``
       (:func:`terramesh.sizing.limit_gradient`; sizes only go down);
    8. CFL, with ``dt``: ``h = max(h, k v_max dt / (Cr s))``, so that the
       time step ``dt`` is stable on the mesh (:func:`stable_timestep` of
       the mesh at least ``dt``) for order-``k`` elements at Courant number
       ``Cr``. ``v_max`` is the largest velocity near the node (an edge
       across a contrast meets the fast side): with ``grade``, within half
       the longest edge that could still break ``dt``, ``k V dt / (2 Cr)``
       (``V`` the model's largest), and one grid cell; without, within
       ``k V dt / (Cr s)``, away from the floor's jump. ``s`` is
       :data:`EDGE_SHRINK_SEISMIC` (0.5; :data:`EDGE_SHRINK_3D`, 0.4, in 3-D), the
       measured ratio of a DistMesh mesh's shortest edges to their size,
       so the grid's own step (:meth:`SeismicSize.stable_timestep`) is
       about ``dt / s``. A measured margin, not a proof: check a mesh with
       :meth:`SeismicSize.check_timestep` (in 2-D, edges under a flat top
       came out at 0.53-0.59 of their size, below the 0.6 used before: 0.92-0.98
       of ``dt``). Applied last,
       as a stability limit must hold; with ``grade`` the floor is graded
       upward (:func:`terramesh.sizing.lift_to_floor`), so that the sizes
       keep the grade where it raises them (a jump at a contrast left edges
       at 0.26 of their size); where it raises them above the wavelength
       size a warning says so.

    Parameters
    ----------
    model : VelocityModel
        2-D or 3-D velocity model, m/s, metres
        (:func:`~terramesh.seismic.read_velocity`).
    frequency : float
        Peak source frequency ``f``, Hz (alias ``freq``).
    cells_per_wavelength : float, optional
        ``n``, edges per wavelength (alias ``wl``); defaults to the table
        value for ``element_order`` and the model's dimension (10 for
        linear elements in 2-D and 3-D: a rule of thumb).
    element_order : int, optional
        Polynomial degree ``k`` of the elements the mesh is for, 1 by
        default (alias ``space_order``); sets the default ``n`` and the CFL
        bound.
    hmin : float
        Smallest edge length, metres.
    hmax : float, optional
        Largest edge length, metres.
    grade : float, optional
        Largest ``|grad h|`` (dimensionless, e.g. 0.15); no gradation if None.
    pad : float or sequence of float, optional
        Padding (sponge) layer width, metres, on every side but the top, or
        ``(left, right, bottom)`` in 2-D, ``(x-, x+, y-, y+, bottom)`` in
        3-D (alias ``domain_pad``); none by default. Each width is rounded
        up to whole grid cells.
    pad_style : {"edge", "constant", "linear"}, optional
        Velocity in the layer (see :func:`pad_model`).
    pad_velocity : float, optional
        m/s, for ``"constant"`` and ``"linear"`` (refused with ``"edge"``,
        which uses none, and below 20 m/s, as km/s); the model's largest by
        default.
    coarsen_pad : bool, optional
        Let the size grow at the grade limit in the layer (step 5). With
        False, the layer is sized from its velocity like the model (as
        without a ``grade``); False needs ``pad`` and ``grade``, else it
        changes nothing and is refused.
    gradient_refinement : float, optional
        ``m``, edges per velocity scale length ``v / |grad v|`` (step 3).
    velocity_window : float, optional
        Width of the window of ``v_min`` in step 2, metres; ``hmin`` by
        default; 0 uses each node's own velocity.
    dt : float, optional
        Time step, seconds, that the mesh must keep stable (step 8).
    courant : float, optional
        ``Cr`` (alias ``cr_max``), :data:`COURANT` by default.
    sources, receivers : array_like, shape (n, 2) or (n, 3), optional
        Acquisition geometry, ``(x, z)`` (2-D) or ``(x, y, z)`` (3-D)
        metres, inside the model (step 6).
    acquisition_size : float, optional
        Size at sources and receivers, metres, at least ``hmin``; ``hmin``
        by default.
    acquisition_radius : float, optional
        Metres; ``acquisition_size`` by default.
    **aliases
        SeismicMesh's names for the options above (:data:`ALIASES`); any
        other keyword is a TypeError.

    Returns
    -------
    SeismicSize
        A SizeGrid on the (padded) model grid, of the model's dimension,
        with ``.domain`` (the padded box: a :class:`ModelBox` in 2-D, a
        :class:`~terramesh.geometry.Box` in 3-D), ``.bbox``, ``.model`` (the
        padded velocity) and ``.pad``.

    Raises
    ------
    SizingError
        For a zero, negative or missing frequency or ``hmin``, velocities
        that look like km/s (largest below 20), an ``hmin`` larger than
        the model (a spacing in km?), ``hmax < hmin``, a bad grade, pad, element order or style, sources or
        receivers outside the model or not of its dimension (``(x, z)``
        points for a 3-D model), a ``dt`` whose CFL size exceeds
        ``hmax``, a ``pad_velocity`` in km/s or with the ``"edge"`` style,
        or sizes larger than the model: the smallest above the padded
        model's longest side (spacing and hmin in km, velocities in m/s).
    TypeError
        For an unknown keyword.

    Warns
    -----
    TerrameshWarning
        When ``hmin`` is above the wavelength (and gradient) size at 99 %
        of the model's nodes or more (:data:`ALL_HMIN_FRACTION`): the mesh
        would be uniform at ``hmin``; and when the CFL limit of ``dt``
        raises sizes above the wavelength size.

    Examples
    --------
    Two layers, 1500 m/s over 3000 m/s, meshed for a 5 Hz source:

    >>> import numpy as np, terramesh as tm
    >>> from terramesh.seismic import read_velocity
    >>> v = np.where(np.arange(21)[:, None] < 10, 1500.0, 3000.0) * np.ones((21, 41))
    >>> model = read_velocity(v, spacing=25.0, axis_order="zx")
    >>> size = size_function(model, frequency=5, hmin=30, grade=0.2, pad=100)
    >>> size.bbox.tolist()  # 1000 x 500 m, padded by 100 m on the sides and the bottom
    [[-100.0, -600.0], [1100.0, 0.0]]
    >>> float(size([(500.0, -100.0)])[0]), float(size([(500.0, -400.0)])[0])  # 1500/(5*10), 3000/(5*10)
    (30.0, 60.0)
    >>> mesh = tm.generate_mesh(size.domain, size)
    >>> tm.cleanup.mesh_problems(mesh)
    []

    In 3-D the axes are ``(x, y, z)``, the pad has five sides and the
    domain is a Box: 2000 m/s with a 3000 m/s lens, 600 x 400 x 300 m:

    >>> x, y, z = np.meshgrid(np.arange(13), np.arange(9), np.arange(7), indexing="ij")
    >>> v = np.where((x - 6) ** 2 + (y - 4) ** 2 + 4 * (z - 3) ** 2 < 9, 3000.0, 2000.0)
    >>> model = read_velocity(v, spacing=50.0, axis_order="xyz")
    >>> size = size_function(model, frequency=2, hmin=50, pad=(0, 100, 0, 0, 50), velocity_window=0)
    >>> size.bbox.tolist(), size.pad  # padded on x+ and at the bottom only
    ([[0.0, 0.0, -350.0], [700.0, 400.0, 0.0]], (0.0, 100.0, 0.0, 0.0, 50.0))
    >>> size([(300.0, 200.0, -150.0), (100.0, 100.0, -50.0)]).tolist()  # 3000/(2*10), 2000/(2*10)
    [150.0, 100.0]
    >>> mesh = tm.generate_mesh(size.domain, size, seed=0)
    >>> mesh.cells.shape[1], mesh.info["min_dihedral"] >= 10
    (4, True)
    """
    given = _resolve_aliases(
        aliases,
        {
            "frequency": frequency,
            "cells_per_wavelength": cells_per_wavelength,
            "element_order": element_order,
            "pad": pad,
            "courant": courant,
        },
    )
    if not isinstance(model, VelocityModel):
        raise SizingError(f"size_function needs a VelocityModel (see read_velocity), got {type(model).__name__}")
    if given["frequency"] is None:
        raise SizingError("size_function needs the peak source frequency: frequency=... (Hz)")
    if hmin is None:
        raise SizingError("size_function needs hmin, the smallest edge length (metres)")
    frequency = positive_number("frequency", given["frequency"], unit=" (Hz)")
    order = _order(1 if given["element_order"] is None else given["element_order"])
    cells = given["cells_per_wavelength"]
    if cells is None:
        table = CELLS_PER_WAVELENGTH if model.dim == 2 else CELLS_PER_WAVELENGTH_3D
        if order not in table:
            raise SizingError(
                f"no cells-per-wavelength value for element order {order} in {model.dim}-D (known: {sorted(table)}); "
                "give cells_per_wavelength"
            )
        cells = table[order]
    cells = positive_number("cells_per_wavelength", cells)
    hmin = positive_number("hmin", hmin, unit=" (metres)")
    _check_units(model, hmin)
    if hmax is not None:
        hmax = positive_number("hmax", hmax, unit=" (metres)")
        if hmax < hmin:
            raise SizingError(f"hmax ({hmax:g} m) is smaller than hmin ({hmin:g} m)")
    if grade is not None:
        grade = positive_number("grade", grade)
        if grade >= 1:  # 5 for 5 %: taken as it came, a grade that limits nothing
            warn_user(
                f"grade={grade:g} lets the size grow by {grade:g} m per metre: a grade is a fraction (0.15 for 15 %); "
                f"for {grade:g} % give grade={grade / 100:g}"
            )
    courant = COURANT if given["courant"] is None else positive_number("courant", given["courant"])
    if dt is not None:
        dt = positive_number("dt", dt, unit=" (s)")
    window = hmin if velocity_window is None else _non_negative_length("velocity_window", velocity_window)
    if gradient_refinement is not None:
        gradient_refinement = positive_number("gradient_refinement", gradient_refinement)
    acquisition_given = acquisition_size is not None or acquisition_radius is not None
    acquisition_size = hmin if acquisition_size is None else positive_number("acquisition_size", acquisition_size)
    if acquisition_size < hmin:
        raise SizingError(f"acquisition_size ({acquisition_size:g} m) is below hmin ({hmin:g} m)")
    radius = acquisition_size
    if acquisition_radius is not None:
        radius = _non_negative_length("acquisition_radius", acquisition_radius)
    points = np.vstack([_points("sources", sources, model.bbox), _points("receivers", receivers, model.bbox)])
    # options that only shape something not asked for: ignored, silently, they let a user believe it was applied
    no_pad = given["pad"] is None or not np.any(_pad_widths(given["pad"], model.dim))
    if no_pad and (pad_velocity is not None or pad_style != "edge"):
        raise SizingError("pad_style and pad_velocity shape the padding layer: give its width, pad=... (metres)")
    if not coarsen_pad and (no_pad or grade is None):
        # the layer's sizes grow only with a padding and a grade to grow by: without both there is nothing to keep
        raise SizingError(
            "coarsen_pad=False keeps a padding layer's sizes from growing, which they do only with a padding and a "
            "grade: give pad=... (metres) and grade=..., or leave coarsen_pad out"
        )
    if acquisition_given and not len(points):
        raise SizingError(
            "acquisition_size and acquisition_radius refine around sources and receivers: give them (sources=,"
            " receivers=)"
        )
    compile_ahead_on_first_run(["seismic"] if model.dim == 2 else ["3d"])  # a bad option said first, at once

    padded = pad_model(model, 0.0 if given["pad"] is None else given["pad"], style=pad_style, velocity=pad_velocity)
    widths = np.array(padded.pad)  # as laid, whole grid cells
    thin = widths[(widths > 0) & (widths < hmin)]
    if len(thin):  # pad=1 (km meant) became a layer of one grid cell, thinner than an element
        warn_user(
            f"the padding layer is {thin.min():g} m wide (pad={given['pad']!r}, in whole grid cells), less than "
            f"hmin={hmin:g} m: thinner than one element (widths are metres: in km?)"
        )
    velocity = padded.values
    spacing = padded.spacing
    local = velocity
    if window > 0:
        from scipy.ndimage import minimum_filter

        cells_across = tuple(max(1, 2 * int(round(window / (2 * step))) + 1) for step in spacing)
        if max(cells_across) > 1:
            local = minimum_filter(velocity, size=cells_across, mode="nearest")
    sizes = local / (frequency * cells)
    if gradient_refinement is not None:
        # on the model padded by its edge values: a constant or linear pad's jump at the model's side is no geology
        # (it refined the model's edge strip to hmin: 23 % more vertices on a BP2004 crop)
        plain = velocity if pad_style == "edge" else pad_model(model, given["pad"], style="edge").values
        sizes = np.minimum(sizes, gradient_size(plain, spacing, elements=gradient_refinement))
    _warn_if_all_hmin(sizes, hmin, padded)
    np.clip(sizes, hmin, hmax, out=sizes)
    wavelength = sizes
    layer = _pad_mask(padded) if any(padded.pad) else None
    if layer is not None and coarsen_pad and grade is not None:
        sizes = sizes.copy()
        extent = float(np.max(padded.bbox[1] - padded.bbox[0]))
        sizes[layer] = hmax if hmax is not None else float(sizes.max()) + grade * extent
    if len(points):
        sizes = sizes.copy() if sizes is wavelength else sizes
        _refine_near(sizes, padded.axes, points, acquisition_size, radius)
    if grade is not None:
        sizes = limit_gradient(sizes, spacing, grade)
    raised = None
    before_cfl = sizes.copy() if dt is not None and len(points) else None  # lift_to_floor works in place
    if dt is not None:
        # a steep grade lets the floor jump nearly as an ungraded one does (grade 10, 2-D: 0.83-0.94 dt with the
        # narrow window and EDGE_SHRINK 0.6)
        graded = grade is not None and grade <= NARROW_WINDOW_GRADE
        floor = mesh_cfl_floor(velocity, spacing, dt=dt, order=order, courant=courant, graded=graded)
        if hmax is not None and floor.max() > hmax:
            raise SizingError(
                f"dt={dt:g} s needs edges of at least {floor.max():g} m where v={velocity.max():g} m/s "
                f"(k v dt / Cr with k={order}, Cr={courant:g}), above hmax={hmax:g} m: lower dt or raise hmax"
            )
        if grade is None:
            sizes = np.maximum(sizes, floor)
        else:
            # the floor graded upward as the sizes were: it jumped from 150 m to 599 m at a contrast, which a
            # mesh cannot follow (edges came out at 0.26 of their size), and BP2004 in 3D kept 0.69 of dt
            sizes = lift_to_floor(np.ascontiguousarray(sizes, dtype=np.float64), floor, spacing, grade)
        # counted on the sizes it made, the graded floor's reach included (the bare floor's count was 1,127
        # nodes where 4,669 went above their wavelength size)
        coarse = sizes > wavelength if layer is None else (sizes > wavelength) & ~layer
        if coarse.any():
            # a pad faster than the model beside it raises the sizes next to it too (edges reach into it)
            pad_note = (
                f" (the {pad_style} pad's {padded.vmax:g} m/s raises the sizes beside it as well; pad_style='edge' "
                "does not)"
                if layer is not None and pad_style != "edge"
                else ""
            )
            raised = (
                f"the CFL limit of dt={dt:g} s raises {int(coarse.sum())} grid nodes above their wavelength size "
                f"(up to {sizes[coarse].max():g} m): the mesh under-resolves the wavelength there; lower dt{pad_note}"
            )
    _check_sizes_fit(sizes, padded, hmin, padded.vmin / (frequency * cells), dt, frequency=frequency)
    if raised:  # after the check, which names a dt that left no mesh at all
        warn_user(raised)
    if dt is not None and len(points):
        at_points = SizeGrid(padded.axes, sizes)(points)
        # raised by the floor, not a grid too coarse for acquisition_radius (its nodes around a point stay larger)
        raised_here = (at_points > acquisition_size * (1 + 1e-9)) & (
            at_points > SizeGrid(padded.axes, before_cfl)(points) * (1 + 1e-9)
        )
        if raised_here.any():  # settings still said the size asked for
            warn_user(
                f"the CFL limit of dt={dt:g} s raises the size at {int(raised_here.sum())} of the {len(points)} "
                f"sources and receivers above acquisition_size={acquisition_size:g} m (to "
                f"{at_points[raised_here].max():g} m); lower dt to keep it"
            )
    settings = {
        "frequency": frequency,
        "cells_per_wavelength": cells,
        "element_order": order,
        "hmin": hmin,
        "hmax": hmax,
        "grade": grade,
        "pad_style": pad_style,
        "pad_velocity": None if pad_velocity is None else float(pad_velocity),  # None: the model's largest
        "coarsen_pad": bool(coarsen_pad),
        "gradient_refinement": gradient_refinement,
        "velocity_window": window,
        "dt": dt,
        "courant": courant,
        "acquisition_size": acquisition_size if len(points) else None,
        "acquisition_radius": radius if len(points) else None,
    }
    return SeismicSize(padded.axes, sizes, model=padded, settings=settings)
