"""Mesh-size gradation: limit how fast the target edge length may grow."""

import logging
import math
import numbers
import time

import numpy as np

from .._kernels.gradation import GODUNOV, PERSSON, limit_gradient_2d, limit_gradient_3d
from ..errors import SizingError
from .grid import SizeGrid

__all__ = ["DEFAULT_GRADE", "limit_gradient", "limit_gradient_up", "lift_to_floor"]

logger = logging.getLogger("terramesh.sizing")

_SCHEMES = {"persson": PERSSON, "godunov": GODUNOV}

DEFAULT_GRADE = 0.2
"""The grade ``g`` (largest ``|grad h|``) where none is given: the guide's §4.1 finds 0.2-0.3 good, and
OceanMesh2D's edgefx defaults to 0.2."""


def _grade(grade, g):
    """One place that maps the guide's short name ``g`` onto ``grade``."""
    if grade is not None and g is not None:
        raise SizingError("give the gradation as grade or as its alias g, not both")
    grade = g if grade is None else grade
    if grade is None:
        raise SizingError("limit_gradient needs a grade (largest |grad h|, e.g. 0.2)")
    return grade if _per_row(grade) else checked_grade(grade)


def _per_row(grade):
    """Whether ``grade`` is given as several numbers (one per row), not one."""
    return isinstance(grade, (list, tuple, np.ndarray)) and np.asarray(grade, dtype=object).ndim > 0


def _row_grades(grade, shape):
    """The kernel's grade of each row along y, ``(ny,)`` float64, from grades per row; or SizingError."""
    if len(shape) != 2:
        raise SizingError(
            f"a grade per row is for 2-D grids; a {len(shape)}-D grid (shape {shape}) takes one grade, got an array"
        )
    if not _is_real_array(grade):
        raise SizingError(f"grade must be a positive number or an array of them, got {grade!r}")
    grades = np.asarray(grade, dtype=np.float64)
    if grades.shape != (shape[1],):
        raise SizingError(
            f"a grade per row takes one grade per node along y, {shape[1]} for a grid of shape {shape}; got shape "
            f"{grades.shape}"
        )
    bad = ~(np.isfinite(grades) & (grades > 0))
    if bad.any():
        raise SizingError(f"grades per row must be positive and finite; {int(bad.sum())} are not")
    return np.array(grades, order="C")  # a writeable copy: a read-only one is another type, compiled again


def checked_grade(grade):
    """``grade`` as a float, positive or inf; SizingError naming it otherwise."""
    if not isinstance(grade, numbers.Real) or isinstance(grade, bool):
        raise SizingError(f"grade must be a positive number (inf: no limit), got {grade!r}")
    grade = float(grade)
    if np.isnan(grade) or grade <= 0:
        raise SizingError(f"grade must be a positive number (inf: no limit), got {grade}")
    return grade


LENGTH_RANGE = (1e-100, 1e100)
"""Sizes and spacings :func:`limit_gradient` takes, in units of its smallest step: squares stay finite, nonzero."""


def _spacing(spacing, dim):
    step = np.asarray(spacing, dtype=np.float64) if _is_real_array(spacing) else None
    if step is None or step.shape not in ((), (dim,)):
        names = ", ".join(f"d{axis}" for axis in "xyz"[:dim])
        raise SizingError(
            f"spacing must be one positive number or one per axis, ({names}), for a {dim}-D grid, got {spacing!r}"
        )
    step = np.broadcast_to(step, (dim,))
    if not np.all(np.isfinite(step)) or np.any(step <= 0):
        raise SizingError(f"spacing must be positive and finite, got {step.tolist()}")
    return tuple(float(d) for d in step)


def _is_real_array(value):
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):
        return False
    return kind in "iuf"


def _values(values, overwrite):
    if not _is_real_array(values):
        raise SizingError("size values must be an array of real numbers")
    array = np.asarray(values)
    if array.ndim not in (2, 3):
        raise SizingError(
            f"size values must be a 2-D array indexed [ix, iy] or a 3-D array indexed [ix, iy, iz], "
            f"got shape {array.shape}"
        )
    if array.size == 0:
        raise SizingError(f"size values are empty (shape {array.shape})")
    # The kernel works in place: on a fresh C-contiguous copy unless the caller gave its array up (on the
    # 5483 x 7172 grid of the guide's §5.3 example the copy took 0.66 s, a third of the sweeps' time).
    in_place = overwrite and array.dtype == np.float64 and array.flags.c_contiguous and array.flags.writeable
    if not in_place:
        array = np.array(array, dtype=np.float64, order="C", copy=True)
    bad = ~np.isfinite(array)
    if bad.any():
        raise SizingError(f"size values have {int(bad.sum())} NaN or infinite entries")
    if np.any(array <= 0):
        raise SizingError(f"size values have {int(np.sum(array <= 0))} entries that are zero or negative")
    return array


def limit_gradient(values, spacing=None, grade=None, *, scheme="persson", overwrite_values=False, g=None):
    """Limit the gradient of a mesh size grid: the largest ``h <= h0`` with ``|grad h| <= grade``.

    Solves Persson's gradient-limiting equation
    ``dh/dt + |grad h| = min(|grad h|, grade)``, ``h(t=0) = h0``, to its
    steady state on a 2-D or 3-D grid (the OceanMesh2D guide's grading,
    §4.1). Sizes only go down: a size is lowered where a much smaller size
    nearby would otherwise make elements grow faster than ``grade`` per
    unit length. With one grade the continuous solution is
    ``h(x) = min_y (h0(y) + grade |x - y|)`` (with grades per row, the
    distance is measured in the metric ``|dx| / grade``); the grid solution
    approaches it to first order in the spacing.

    Parameters
    ----------
    values : array_like, shape (nx, ny) or (nx, ny, nz), or SizeGrid
        Target edge length ``h0`` at the grid nodes, indexed ``[ix, iy]``
        or ``[ix, iy, iz]`` (NumPy's ``indexing="ij"``), finite and
        positive, in the units of the coordinates (metres, or degrees for
        a geographic grid). A 2-D or 3-D :class:`SizeGrid` brings its own
        spacing.
    spacing : float or tuple of float
        Node spacing: one number for all axes, or one per axis, ``(dx, dy)``
        or ``(dx, dy, dz)``, in the same units as the sizes. Must be left
        out for a SizeGrid.
    grade : float or array_like, shape (ny,)
        Largest allowed ``|grad h|``, dimensionless (size change per unit
        length; 0.2 lets neighbouring elements differ by about 20%); ``inf``
        limits nothing (the sizes come back as they are, checked). A 2-D
        grid also takes one grade per node along y, positive and finite,
        for all the nodes of that y: on a Mercator grid (y the northing,
        spacing in Mercator metres), ground sizes graded at
        ``grade * cos(lat)`` per row are graded at ``grade`` on the ground.
    scheme : {"persson", "godunov"}, optional
        Upwind ``|grad h|`` on the grid. ``"persson"``, as in Persson (2006):
        ``sqrt(sum over axes of max(D-h, 0)**2 + min(D+h, 0)**2)``, one-sided
        differences on both sides counted. ``"godunov"``: the Godunov
        (Rouy-Tourin) form ``sqrt(sum over axes of max(D-h, -D+h, 0)**2)``,
        one side per axis. They differ only at ridges (a node above both
        neighbours on an axis), where ``"persson"`` gives slightly smaller
        sizes.
    overwrite_values : bool, optional
        Limit a float64 C-contiguous ``values`` array in place and return
        it, instead of a copy (saves a copy of the grid and its memory).
    g : float, optional
        Alias of ``grade``, the guide's name.

    Returns
    -------
    ndarray, same shape as ``values``, float64, or SizeGrid
        The limited sizes, ``h <= h0`` everywhere, same units; a new
        SizeGrid on the same axes for a SizeGrid input. The input is not
        modified, unless ``overwrite_values`` (then it is the result).

    Raises
    ------
    SizingError
        For NaN, infinite, zero or negative sizes, a shape other than 2-D
        or 3-D, a spacing whose length is not the number of axes, a
        non-positive spacing or grade, an unknown scheme, a spacing
        given together with a SizeGrid, or grades per row that are not one
        positive finite number per node along y of a 2-D grid.

    Notes
    -----
    The result is the steady state of the explicit upwind time stepping,
    found exactly (to a relative 1e-13 on ``|grad h|**2``): at each node
    either ``h = h0`` and the upwind ``|grad h| <= grade``, or the upwind
    ``|grad h| = grade``. It is computed by fast sweeping (Gauss-Seidel
    sweeps in the four, or in 3-D eight, axis orderings until nothing
    changes), taking 20 to 90 ns per node in 2-D and 90 to 500 ns per node
    in 3-D on one core (``benchmarks/bench_gradation.py``; in 3-D a size
    growing away from a surface curved both ways takes about 40 sweeps, a
    random field 15); Persson's fast-marching (heap) order reaches the same
    fixed point but was 10-20 times slower in 2-D. Grids of 128 rows (3-D:
    32 x-planes) or more are swept in two blocks side by side, each against
    copies of the other's edge, in rounds until the edges hold: 1.4 to 1.8
    times faster on two cores, and the same sizes with any number of
    threads (they differ from one block's by about 1e-14 relative at a
    few nodes, within the tolerance above).

    Because the upwind norm looks along the axes only, the gradient of the
    bilinear or piecewise-linear interpolant can exceed ``grade`` by up to
    a factor of sqrt(2) between diagonal neighbours (sqrt(3) in 3-D).

    References
    ----------
    P.-O. Persson, "Mesh size functions for implicit geometries and
    PDE-based gradient limiting", Engineering with Computers 22, 95-109,
    2006. :doi:`10.1007/s00366-006-0014-1`

    K. J. Roberts, W. J. Pringle and J. J. Westerink, "OceanMesh2D 1.0:
    MATLAB-based software for two-dimensional unstructured mesh generation
    in coastal ocean modeling", Geoscientific Model Development 12,
    1847-1868, 2019. :doi:`10.5194/gmd-12-1847-2019`

    H. Zhao, "A fast sweeping method for Eikonal equations", Mathematics
    of Computation 74, 603-627, 2005. :doi:`10.1090/S0025-5718-04-01678-3`

    Examples
    --------
    A small size at one end of a row of nodes grows by ``grade * dx`` per node:

    >>> import numpy as np
    >>> h0 = np.array([[0.1], [1.0], [1.0], [1.0], [1.0]])
    >>> limit_gradient(h0, 1.0, 0.2)[:, 0].round(6).tolist()
    [0.1, 0.3, 0.5, 0.7, 0.9]

    A SizeGrid gives its spacing and gets a SizeGrid back:

    >>> h0 = np.ones((5, 3))
    >>> h0[2, 1] = 0.1
    >>> grid = SizeGrid((np.linspace(0, 4, 5), np.linspace(0, 1, 3)), h0)
    >>> limit_gradient(grid, grade=0.2).values[:, 1].round(6).tolist()
    [0.5, 0.3, 0.1, 0.3, 0.5]

    In 3-D, with a coarser spacing along z (all in metres), the size grows
    by ``grade * dz = 0.4`` m per node along z:

    >>> h0 = np.full((5, 5, 5), 10.0)
    >>> h0[2, 2, 2] = 0.1
    >>> h = limit_gradient(h0, (1.0, 1.0, 2.0), 0.2)
    >>> h[2, 2, :].round(6).tolist()
    [0.9, 0.5, 0.1, 0.5, 0.9]
    >>> h[:, 2, 2].round(6).tolist()
    [0.5, 0.3, 0.1, 0.3, 0.5]

    A grade per y (here halved at the last two y), where sizes grow along y:

    >>> h0 = np.array([[0.1, 1.0, 1.0, 1.0, 1.0]])
    >>> limit_gradient(h0, 1.0, [0.2, 0.2, 0.2, 0.1, 0.1])[0].round(6).tolist()
    [0.1, 0.3, 0.5, 0.6, 0.7]
    """
    if isinstance(values, SizeGrid) and spacing is not None:
        # checked first: limit_gradient(grid, 0.2) passes the grade as spacing
        raise SizingError("a SizeGrid brings its own spacing: leave spacing out (pass grade=...)")
    grade = _grade(grade, g)
    if scheme not in _SCHEMES:
        raise SizingError(f"scheme must be one of {sorted(_SCHEMES)}, got {scheme!r}")
    if isinstance(values, SizeGrid):
        if values.dim not in (2, 3):
            raise SizingError(f"limit_gradient supports 2-D and 3-D grids, got a {values.dim}-D SizeGrid")
        steps = tuple(float(axis[1] - axis[0]) for axis in values.axes)
        return SizeGrid(values.axes, limit_gradient(values.values, steps, grade, scheme=scheme))
    if spacing is None:
        raise SizingError("limit_gradient needs the node spacing (dx, or one per axis) for an array of sizes")
    sizes = _values(values, overwrite_values)
    steps = _spacing(spacing, sizes.ndim)
    if not _per_row(grade) and grade == np.inf:
        return sizes
    grades = _row_grades(grade, sizes.shape) if _per_row(grade) else grade  # one grade: the kernel compiled for it
    # the kernels square steps and sizes and divide by them: in units of about the smallest step (a power of
    # two: exact both ways, and the grading is the same in any unit) they must stay within LENGTH_RANGE, or
    # a ZeroDivisionError or an overflow inside them (sizes 1e80 on a spacing of 1e-80 came out graded 2:1)
    unit = 2.0 ** round(math.log2(min(steps)))
    scaled = np.array([*steps, *((sizes.min(), sizes.max()) if sizes.size else (unit, unit))]) / unit
    if np.any(scaled < LENGTH_RANGE[0]) or np.any(scaled > LENGTH_RANGE[1]):
        raise SizingError(
            f"sizes ({sizes.min():g} to {sizes.max():g}) and spacing ({', '.join(f'{d:g}' for d in steps)}) differ"
            f" by more than {LENGTH_RANGE[1]:g} times: rescale the sizes (in the spacing's units?)"
        )
    started = time.perf_counter()
    if unit != 1.0:
        sizes /= unit
        steps = tuple(d / unit for d in steps)
    if sizes.ndim == 2:
        sweeps = limit_gradient_2d(sizes, *steps, grades, _SCHEMES[scheme])
    else:
        sweeps = limit_gradient_3d(sizes, *steps, grade, _SCHEMES[scheme])
    if unit != 1.0:
        sizes *= unit
    logger.debug(
        "gradient limiting of a %s grid: %d sweeps, %.3f s",
        " x ".join(map(str, sizes.shape)),
        sweeps,
        time.perf_counter() - started,
    )
    return sizes


def limit_gradient_up(values, spacing, grade, *, scheme="persson"):
    """Raise a mesh size grid to the smallest ``h >= h0`` with ``|grad h| <= grade``: :func:`limit_gradient` mirrored.

    Where :func:`limit_gradient` lowers sizes next to small ones, this
    raises sizes next to large ones: ``h(x) = max_y (h0(y) - grade |x - y|)``.
    It grades a lower bound on the sizes, such as the CFL floor of a time
    step, which must hold everywhere and may rise faster than ``grade``
    (with the depth at a shelf break): taking the larger of that graded floor
    and sizes already graded keeps both the bound and the grade, where the
    floor alone would leave a jump that a mesh cannot follow (its edges
    beside the jump come out shorter than the floor).

    Parameters
    ----------
    values : array_like, shape (nx, ny) or (nx, ny, nz)
        ``h0`` at the grid nodes, finite and positive, indexed as in
        :func:`limit_gradient`.
    spacing : float or tuple of float
        Node spacing, one number or one per axis, in the units of the sizes.
    grade : float or array_like, shape (ny,)
        Largest allowed ``|grad h|``; ``inf`` raises nothing. A 2-D grid
        also takes one per node along y, as :func:`limit_gradient`.
    scheme : {"persson", "godunov"}, optional
        The upwind ``|grad h|`` of :func:`limit_gradient`, on the mirrored
        field (``"godunov"`` gives the exact cone along a row).

    Returns
    -------
    ndarray, float64
        The raised sizes, ``h >= h0`` everywhere, same units; a new array.

    Raises
    ------
    SizingError
        As :func:`limit_gradient`.

    Notes
    -----
    Computed as ``top - limit_gradient(top - h0)`` with ``top = 2 max h0``
    (so that ``top - h0`` is positive), the same sweeps on the mirrored
    field; a node within rounding (4 units in the last place of ``top``)
    of ``h0`` keeps ``h0`` exactly, so sizes already graded come back as
    they are.

    Examples
    --------
    A large size at one end of a row of nodes falls by ``grade * dx`` per node:

    >>> import numpy as np
    >>> h0 = np.array([[1.0], [0.1], [0.1], [0.1], [0.1]])
    >>> limit_gradient_up(h0, 1.0, 0.2)[:, 0].round(6).tolist()
    [1.0, 0.8, 0.6, 0.4, 0.2]
    """
    floor = _values(values, False)
    top = 2.0 * float(floor.max())
    raised = limit_gradient(np.subtract(top, floor), spacing, grade, scheme=scheme, overwrite_values=True)
    np.subtract(top, raised, out=raised)
    # the round trip through top - h0 moves an untouched node by a few units in the last place of top
    untouched = raised <= floor + 4.0 * np.finfo(np.float64).eps * top
    raised[untouched] = floor[untouched]
    return raised


def lift_to_floor(sizes, floor, spacing, grade):
    """Graded sizes raised to a lower bound, keeping the grade: ``max(sizes, limit_gradient_up(floor))``, in place.

    ``sizes`` must already be graded (:func:`limit_gradient` with the same
    ``grade``). Only the nodes where ``floor > sizes`` raise anything, and a
    node's floor raises its neighbours no farther than
    ``(floor - min sizes) / grade`` (the smallest grade, with grades per
    row): the floor is graded upward on the
    box around those nodes padded by that reach, not on the whole grid
    (on the guide's §5.3 grid of 39 million nodes, 315 nodes of a time
    step's floor were above the sizes: 0.3 s instead of 2 s).

    Parameters
    ----------
    sizes : ndarray, float64, C-contiguous, shape (nx, ny) or (nx, ny, nz)
        Graded sizes, finite and positive; raised in place.
    floor : array_like, the shape of ``sizes``
        The lower bound, finite and positive, same units.
    spacing : float or tuple of float
        Node spacing, one number or one per axis.
    grade : float or array_like, shape (ny,)
        Largest allowed ``|grad h|``: one, or one per node along y of a
        2-D grid, as in :func:`limit_gradient`.

    Returns
    -------
    ndarray
        ``sizes``, raised.

    Examples
    --------
    >>> import numpy as np
    >>> sizes = np.array([[0.1], [0.3], [0.5], [0.7], [0.9]])
    >>> lift_to_floor(sizes, np.array([[0.1], [0.1], [0.1], [0.1], [2.0]]), 1.0, 0.2)[:, 0].round(6).tolist()
    [1.2, 1.4, 1.6, 1.8, 2.0]
    """
    floor = np.asarray(floor, dtype=np.float64)
    if floor.shape != sizes.shape:
        raise SizingError(f"floor {floor.shape} and sizes {sizes.shape} must have the same shape")
    if not np.isfinite(floor).all():
        raise SizingError(f"floor has {int(np.sum(~np.isfinite(floor)))} NaN or infinite entries")
    above = floor > sizes
    if not above.any():
        return sizes
    steps = _spacing(spacing, sizes.ndim)
    grades = _row_grades(grade, sizes.shape) if _per_row(grade) else checked_grade(grade)
    # a floor falls at least at the smallest grade away from its node
    reach = (float(floor[above].max()) - float(sizes.min())) / float(np.min(grades))
    window = []
    for axis, step in enumerate(steps):
        other = tuple(a for a in range(sizes.ndim) if a != axis)
        nodes = np.flatnonzero(above.any(axis=other))
        pad = int(np.ceil(reach / step)) + 1
        window.append(slice(max(int(nodes[0]) - pad, 0), int(nodes[-1]) + pad + 1))
    window = tuple(window)
    if _per_row(grades):
        grades = grades[window[1]]
    np.maximum(sizes[window], limit_gradient_up(floor[window], steps, grades), out=sizes[window])
    return sizes
