"""Seismic velocity models: the :class:`VelocityModel` grid, its frame, and the checks every reader applies.

Coordinates, once for the whole of :mod:`terramesh.seismic`: a 2-D model
lives in the plane ``(x, z)`` and a 3-D model in ``(x, y, z)``, in metres,
with ``z`` the elevation: **negative downward**, ``z = 0`` at the top of the
model (the free surface) unless an ``origin`` says otherwise. Points are
arrays of shape ``(n, 2)`` holding ``(x, z)`` (or ``(n, 3)`` holding
``(x, y, z)``), as everywhere in terramesh. The readers
(:func:`~terramesh.seismic.read_velocity`) put every file and
array into that frame, whatever its own axis order, so a user never swaps
axes: a SEG-Y trace is a column at one ``x`` (in a 3-D volume, at one
``(x, y)``) whose first sample is the top; a raw binary file or an array
names its axes with ``axis_order``.

Velocities are stored in m/s (float64). A :class:`VelocityModel` is indexed
like :class:`terramesh.sizing.SizeGrid`: ``values[i, j]`` is the velocity at
``(x[i], z[j])`` with both axes increasing, so ``values[:, -1]`` is the top
row and ``values[:, 0]`` the deepest.

The checks of values, units, axis order and spacing, and the step that
places a reader's array on its axes (:func:`build_model`), are shared by
the readers in :mod:`terramesh.seismic.velocity` (NetCDF, ``.npy``,
arrays), :mod:`terramesh.seismic.segy` and :mod:`terramesh.seismic.binary`.
"""

import numpy as np

from ..errors import SizingError, warn_user
from ..sizing.grid import SizeGrid, checked_axis

__all__ = ["VelocityModel", "UNITS"]

UNITS = {"m/s": 1.0, "km/s": 1000.0}
"""Velocity units a file or array may be in, with the factor that turns them into m/s."""

KM_PER_S_BELOW = 20.0
"""Velocities given as m/s whose largest value is below this (m/s) look like km/s and warn.

No rock, sediment or fluid is slower than about 100 m/s (air, 340 m/s, is not
modelled), while seismic velocities in km/s stay below 14."""

M_PER_S_ABOVE = 100.0
"""Velocities given as km/s whose smallest value is above this (km/s) look like m/s: refused with that advice."""

MAX_VELOCITY = 20_000.0
"""Largest velocity (m/s, after unit conversion) a model may hold; faster ones are refused as misread.

The fastest Earth materials stay well below it: P waves cross the lower
mantle at about 13.7 km/s and diamond at about 18 km/s. Values above it come
from samples decoded in the wrong format (IEEE floats labelled IBM in a
SEG-Y file read as 42,000 m/s and more), a wrong unit or a scale factor.
"""

MIN_VELOCITY = 100.0
"""Smallest velocity (m/s) a model faster than :data:`MIXED_UNITS_ABOVE` may hold; slower ones are refused as misread.

No rock, sediment or fluid is slower than about 100 m/s, and a velocity of
1.5 m/s makes the mesh size there a thousand times too small. Such values
beside m/s ones are km/s values (or placeholders) left in an m/s model.
"""

MIXED_UNITS_ABOVE = 1000.0
"""Largest velocity (m/s) from which a model is refused for holding velocities below :data:`MIN_VELOCITY`.

A slower model is left alone: one all in km/s read as m/s warns (see
:data:`KM_PER_S_BELOW`), and a slow near-surface model may be genuine.
"""

_SPACING_RTOL = 1e-4
"""Largest relative disagreement between a given spacing and a file's before a warning."""


def _per_axis(name, value, dim, *, positive):
    """A number or one number per axis (x, [y,] z) as a float tuple of length ``dim``."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SizingError(f"{name} must be numbers, got {value!r}") from None
    if array.ndim == 0 or array.shape == (1,):  # a number, or a command line's one number
        array = np.full(dim, float(array.ravel()[0]))
    axes = "(dx, dz)" if dim == 2 else "(dx, dy, dz)"
    if array.shape != (dim,):
        raise SizingError(f"{name} must be one number or {dim} numbers {axes}, got {value!r}")
    if not np.all(np.isfinite(array)) or (positive and np.any(array <= 0)):
        kind = "positive and finite" if positive else "finite"
        raise SizingError(f"{name} must be {kind}, got {array.tolist()}")
    return tuple(float(v) for v in array)


def as_floats(values, where):
    """``values`` as a float64 array, a masked array's masked entries NaN (missing, as a NetCDF's fill values are).

    ``np.asarray`` drops a mask and keeps whatever the masked entries hold:
    a placeholder of 1 became a velocity of 1 m/s. ``where`` names the
    values in the SizingError for anything but real numbers: complex ones
    lost their imaginary part, with only NumPy's ComplexWarning to say so.
    """
    if np.iscomplexobj(values):  # refused even with no imaginary part: which part is the velocity is the user's call
        nonzero = int(np.count_nonzero(np.imag(values)))
        parts = f"{nonzero} of {np.size(values)} with a nonzero imaginary part" if nonzero else "imaginary parts all 0"
        raise SizingError(
            f"{where} holds complex numbers ({parts}): velocities are real numbers, m/s or km/s; pass (or save) the "
            "real part, values.real, if that is the velocity"
        )
    try:
        if np.ma.isMaskedArray(values):
            return np.ma.filled(values.astype(np.float64), np.nan)
        return np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise SizingError(f"{where} must be an array of numbers") from None


def check_values(values, where, axes=None):
    """Refuse NaN, infinite, zero and negative velocities, saying how many and where the first is.

    Readers call it on the array as the user or the file orders it, with
    ``axes`` naming its axes (``"xyz"``, or ``("trace", "sample")``), so
    the index given is one the user can look up.
    """
    named = "" if axes is None else f" ({', '.join(axes)})"
    bad = ~np.isfinite(values)
    if bad.any():
        first = tuple(int(i) for i in np.argwhere(bad)[0])
        raise SizingError(
            f"{where} has {int(bad.sum())} NaN or infinite velocities (the first at index {first}{named}); "
            "fill them (e.g. with the nearest valid value) before meshing"
        )
    low = values <= 0
    if low.any():
        first = tuple(int(i) for i in np.argwhere(low)[0])
        raise SizingError(
            f"{where} has {int(low.sum())} zero or negative velocities (the first, {values[first]:g}, at index "
            f"{first}{named}); velocities must be positive"
        )


def _check_slow(values, where, axes=None, factor=1.0):
    """Refuse velocities below :data:`MIN_VELOCITY` in a model faster than :data:`MIXED_UNITS_ABOVE`, as many and where.

    ``values`` have passed :func:`check_values` (finite and positive) and
    are in the unit ``factor`` turns into m/s; ``axes`` names their axes as
    for :func:`check_values`. A model of m/s with some cells in km/s (1.5
    beside 4500) was read without a word, and its sizes there came out a
    thousand times too small.
    """
    if values.size == 0:
        return
    high = float(values.max()) * factor
    if high <= MIXED_UNITS_ABOVE:
        return
    slow = values < MIN_VELOCITY / factor
    count = int(np.count_nonzero(slow))
    if count:
        first = tuple(int(i) for i in np.unravel_index(int(np.argmax(slow)), slow.shape))
        named = "" if axes is None else f" ({', '.join(axes)})"
        raise SizingError(
            f"{where} has {count} velocities below {MIN_VELOCITY:g} m/s (the first, {values[first] * factor:g} m/s, "
            f"at index {first}{named}) in a model reaching {high:g} m/s: no rock or fluid is that slow, and the mesh "
            "would be needlessly fine there; they look like km/s among m/s (or placeholders): convert them to m/s "
            "or fill them before meshing"
        )


class VelocityModel:
    """P-wave velocity on a regular grid in the ``(x, z)`` plane (or ``(x, y, z)``), m/s.

    Usually made by :func:`~terramesh.seismic.read_velocity` (or by
    :func:`terramesh.seismic.pad_model`) rather than directly.

    Parameters
    ----------
    values : array_like, shape (nx, nz) or (nx, ny, nz)
        Velocity at the grid nodes, m/s, indexed ``[ix, iz]`` (``[ix, iy,
        iz]``) with both axes increasing: the last z index is the top.
        Copied to float64; must be finite and positive.
    axes : sequence of array_like
        The evenly spaced, increasing node coordinates ``(x, z)`` or ``(x,
        y, z)``, metres; ``z`` is negative downward.
    pad : sequence of float, optional
        Widths of a padding layer already included in the grid, metres:
        ``(left, right, bottom)`` in 2-D, ``(x-, x+, y-, y+, bottom)`` in
        3-D. Zero (no padding) by default.
    source : str, optional
        Where the velocities came from (a file name), for messages.

    Attributes
    ----------
    values : numpy.ndarray, float64, m/s
    axes : tuple of numpy.ndarray
    pad : tuple of float
    source : str or None

    Raises
    ------
    SizingError
        For NaN, infinite, zero or negative velocities, velocities below
        :data:`MIN_VELOCITY` (100 m/s) in a model reaching above
        :data:`MIXED_UNITS_ABOVE` (1000 m/s), or axes that do not match the
        values.

    Examples
    --------
    >>> import numpy as np
    >>> model = VelocityModel(np.array([[2000.0, 1500.0], [2000.0, 1500.0]]), ([0.0, 10.0], [-5.0, 0.0]))
    >>> model.bbox.tolist(), model.spacing
    ([[0.0, -5.0], [10.0, 0.0]], (10.0, 5.0))
    >>> model([(5.0, -2.5)]).tolist()  # bilinear between the nodes
    [1750.0]
    """

    def __init__(self, values, axes, *, pad=None, source=None):
        values = np.array(as_floats(values, source or "the velocity model"), order="C", copy=True)
        if values.ndim not in (2, 3):
            raise SizingError(f"a velocity model is 2-D or 3-D, got an array of shape {values.shape}")
        check_values(values, source or "the velocity model")
        _check_slow(values, source or "the velocity model")
        self._setup(values, axes, pad, source)
        z = self.axes[-1]
        if z[0] >= 0 and z[-1] > 0:  # the readers place the top at z = 0 or below it, and never warn here
            warn_user(
                f"{source or 'the velocity model'}: its z axis runs {z[0]:g}..{z[-1]:g} m, all at or above 0, and z "
                "is the elevation (negative downward, values[..., -1] the top): for depths positive downward give "
                "-depth[::-1] as the axis and values[..., ::-1], or read the array with read_velocity"
            )

    @classmethod
    def _of_read_values(cls, values, axes, *, pad, source):
        """A model of the float64 array a reader made and checked, neither copied nor checked again.

        A 3-D model of 10^8 nodes is 800 MB: the copy doubled the reader's
        peak memory, and the reader checks the values in the file's own
        order, where the index it names is one the user can look up.
        """
        model = cls.__new__(cls)
        model._setup(np.ascontiguousarray(values, dtype=np.float64), axes, pad, source)
        return model

    def _setup(self, values, axes, pad, source):
        if len(axes) != values.ndim:
            raise SizingError(f"a {values.ndim}-D velocity model needs {values.ndim} axes, got {len(axes)}")
        names = "xz" if values.ndim == 2 else "xyz"
        for axis, name in zip(axes, names, strict=True):
            _check_axis(axis, name)
        shape = tuple(np.size(axis) for axis in axes)
        if values.shape != shape:  # said by the interpolant's grid, it read "size values have shape"
            raise SizingError(f"velocity values have shape {values.shape}, the axes ({', '.join(names)}) need {shape}")
        self._grid = SizeGrid(axes, values)  # also the interpolant
        self.values = self._grid.values
        self.axes = self._grid.axes
        zeros = (0.0,) * (3 if values.ndim == 2 else 5)
        self.pad = zeros if pad is None else tuple(float(w) for w in pad)
        if len(self.pad) != len(zeros) or any(w < 0 for w in self.pad):
            raise SizingError(f"pad must be {len(zeros)} non-negative widths, got {pad!r}")
        self.source = source

    @property
    def dim(self):
        """Number of space dimensions, 2 or 3."""
        return self.values.ndim

    @property
    def shape(self):
        """Number of nodes along x[, y], z."""
        return self.values.shape

    @property
    def spacing(self):
        """Node spacing ``(dx, dz)`` or ``(dx, dy, dz)``, metres."""
        return tuple(float(axis[1] - axis[0]) for axis in self.axes)

    @property
    def bbox(self):
        """Extent ``[[xmin, zmin], [xmax, zmax]]`` (3-D: with y), metres, shape ``(2, dim)``."""
        return self._grid.bbox

    @property
    def interior_bbox(self):
        """The extent without the padding layer (the bbox itself for an unpadded model), shape ``(2, dim)``."""
        box = self.bbox.copy()
        box[0, 0] += self.pad[0]
        box[1, 0] -= self.pad[1]
        if self.dim == 3:
            box[0, 1] += self.pad[2]
            box[1, 1] -= self.pad[3]
        box[0, -1] += self.pad[-1]
        return box

    @property
    def vmin(self):
        """Smallest velocity, m/s."""
        return float(self.values.min())

    @property
    def vmax(self):
        """Largest velocity, m/s."""
        return float(self.values.max())

    @property
    def domain(self):
        """The model's box as a terramesh geometry: a :class:`~terramesh.geometry.Rectangle` in 2-D, a Box in 3-D."""
        if self.dim == 2:
            from ..geometry.primitives import Rectangle

            return Rectangle(self.bbox[0], self.bbox[1])
        from ..geometry.primitives3d import Box

        return Box(self.bbox[0], self.bbox[1])

    def __call__(self, points):
        """Velocity at ``points`` (shape ``(n, dim)``, metres), m/s, shape ``(n,)``: (bi/tri)linear.

        Points outside the grid take the value at the nearest grid edge.
        """
        return self._grid(points)

    def __repr__(self):
        size = " x ".join(str(n) for n in self.shape)
        box = " x ".join(f"{hi - lo:g}" for lo, hi in self.bbox.T)
        return (
            f"<terramesh.seismic.VelocityModel: {size} nodes, {box} m, "
            f"{self.vmin:g}..{self.vmax:g} m/s{'' if self.source is None else ', ' + str(self.source)}>"
        )


def _check_axis(axis, name):
    """Refuse a bad model axis, naming it x, y or z (a SizeGrid says x, y[, z]), and say how a decreasing one goes."""
    try:
        coordinates = np.asarray(axis, dtype=np.float64)
    except (TypeError, ValueError):
        coordinates = None
    if coordinates is not None and coordinates.ndim == 1 and coordinates.size >= 2 and np.all(np.diff(coordinates) < 0):
        shown = ", ".join(f"{value:g}" for value in coordinates[:3]) + (", ..." if coordinates.size > 3 else "")
        if name == "z":
            expected = (
                "it must increase upward, bottom first (z is the elevation, negative downward: e.g. -10, -5, 0), "
                "with values[..., -1] the top"
            )
        else:
            expected = "it must increase"
        raise SizingError(f"grid axis {name} decreases ({shown}); {expected}: reverse the axis and the values along it")
    checked_axis(axis, name)


def checked_axis_order(axis_order, ndim, what):
    """``axis_order`` in lower case, once it names each of the ``ndim`` axes once; ``what`` names the data.

    A SizingError says how to give a missing one (with an example) or what a bad one lacks.
    """
    if axis_order is None:
        example = "'zx' (rows are depths, the image layout) or 'xz' (rows are traces)" if ndim == 2 else "'zxy'"
        raise SizingError(
            f"{what}: say how its axes are ordered with axis_order (--axis-order on the command line), e.g. {example}"
        )
    order = str(axis_order).lower()
    wanted = set("xz") if ndim == 2 else set("xyz")
    if len(order) != ndim or set(order) != wanted:
        raise SizingError(
            f"axis_order must name each of the axes {''.join(sorted(wanted))} once for a {ndim}-D model, "
            f"got {axis_order!r}"
        )
    return order


def to_model_order(array, axis_order):
    """Transpose an array whose axes are named by ``axis_order`` to ``[x, (y,) z]`` with z increasing upward.

    The first sample along z in the input is the top (the shallowest).
    """
    target = "xz" if array.ndim == 2 else "xyz"
    array = np.transpose(array, [axis_order.index(axis) for axis in target])
    return array[..., ::-1]


def units_factor(values, units, where, *, axes=None, error=SizingError, advice=None):
    """The factor that turns ``values`` in ``units`` into m/s, after checking that they look like that unit.

    Values given as m/s that look like km/s warn (a slow model is possible,
    if unlikely); values above :data:`MAX_VELOCITY` once converted are
    refused with ``error``, as no model can hold them. ``advice``: a
    function of the unit factor that says what the caller knows about how
    the values were decoded (a SEG-Y file's sample format), said in place of
    the plain advice to check the units; called only to refuse. Then
    velocities below :data:`MIN_VELOCITY` among fast ones are refused (see
    :func:`_check_slow`, which ``axes`` is for).
    """
    if units not in UNITS:
        raise SizingError(f"units must be one of {sorted(UNITS)}, got {units!r}")
    # the range without a copy of the finite values (10 million of them, a SEG-Y section's: 0.21 s, now 7 ms)
    floats = values if values.dtype.kind == "f" else values.astype(np.float64)  # integer samples
    high, low = float(np.nanmax(floats, initial=-np.inf)), float(np.nanmin(floats, initial=np.inf))
    if np.isinf([high, low]).any() and np.isfinite(values).any():  # an infinity among them: the finite ones' range
        finite = values[np.isfinite(values)]
        high, low = float(finite.max()), float(finite.min())
    if np.isfinite(high) and np.isfinite(low):
        if units == "m/s" and 0 < high < KM_PER_S_BELOW:
            warn_user(
                f"{where}: velocities range {low:g}..{high:g}, which looks like km/s, but units='m/s'; "
                "pass units='km/s' if they are",
            )
        if high * UNITS[units] > MAX_VELOCITY:
            if units == "km/s" and low > M_PER_S_ABOVE:  # every value too fast as km/s: m/s are meant
                advice = "they look like m/s, but units='km/s': pass units='m/s' if they are"
            elif advice is None:
                advice = "check the units (m/s or km/s) and any scale factor applied to the values"
            else:
                advice = advice(UNITS[units])
            given = "" if units == "m/s" else f" (given as {high:g} km/s)"
            raise error(
                f"{where}: the largest velocity is {high * UNITS[units]:g} m/s{given}, faster than any Earth material "
                f"(at most {MAX_VELOCITY:g} m/s); {advice}"
            )
    _check_slow(values, where, axes, UNITS[units])
    return UNITS[units]


def reconcile_spacing(given, found, where, dim=2):
    """The spacing to use: the given one (warning if the file disagrees), else the file's, else an error."""
    if given is not None:
        if found is not None and not np.allclose(given, found, rtol=_SPACING_RTOL, atol=0):
            warn_user(
                f"{where}: the spacing given, {list(given)}, differs from the file's, {list(found)}; "
                "using the one given",
            )
        return given
    if found is None:
        axes = "(dx, dz)" if dim == 2 else "(dx, dy, dz)"
        raise SizingError(f"{where} does not state its grid spacing: pass spacing={axes} in metres")
    return found


def build_model(values, spacing, origin, pad, source):
    """A model from ``values[x, (y,) z]`` (z increasing upward), spacing and origin ``(x0, [y0,] z_top)``."""
    dim = values.ndim
    origin = (0.0,) * dim if origin is None else _per_axis("origin", origin, dim, positive=False)
    axes = [origin[k] + spacing[k] * np.arange(values.shape[k]) for k in range(dim - 1)]
    nz = values.shape[-1]
    axes.append(origin[-1] - spacing[-1] * (nz - 1) + spacing[-1] * np.arange(nz))
    return VelocityModel._of_read_values(values, axes, pad=pad, source=source)


def checked_spacing(spacing, ndim):
    """A validated spacing tuple of length ``ndim`` (None stays None)."""
    if spacing is None:
        return None
    if ndim not in (2, 3):  # a raw binary file without a valid shape: the shape error comes first
        ndim = np.size(spacing) if np.size(spacing) in (2, 3) else 2
    return _per_axis("spacing", spacing, ndim, positive=True)


UNIT_RATIO = (500.0, 2000.0)  # extents this many times apart on every axis: km against m


def unit_mismatch(mesh_box, box):
    """How a mesh's extent and a model's box disagree in units: ``"km"``, ``"m"`` or ``""``.

    ``"km"`` where ``box`` is 500 to 2000 times ``mesh_box`` on every axis
    (a mesh in km against a model in m), ``"m"`` where it is that fraction
    of it (a model whose spacing was read in km), else ``""``. Both are
    ``[[xmin, (ymin,) zmin], [xmax, (ymax,) zmax]]``.

    Examples
    --------
    >>> unit_mismatch([[0, -3], [9.2, 0]], [[0, -3000], [9200, 0]])
    'km'
    >>> unit_mismatch([[0, -3000], [9200, 0]], [[0, -3000], [9200, 0]])
    ''
    """
    ratio = np.ptp(np.asarray(box, dtype=np.float64), axis=0) / np.ptp(np.asarray(mesh_box, dtype=np.float64), axis=0)
    low, high = UNIT_RATIO
    if np.all((ratio > low) & (ratio < high)):
        return "km"
    if np.all((ratio > 1 / high) & (ratio < 1 / low)):
        return "m"
    return ""
