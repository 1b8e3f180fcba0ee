"""CFL limiting of the size function (guide §4.2, eq. 10-12).

The Courant number of a shallow-water model with time step ``dt`` on an
element of size ``f`` is (eq. 10)

``Cr = (|u| + sqrt(g H)) dt / f``,

with ``H = h`` and the linear long-wave velocity ``|u| = eta sqrt(g / h)``
(eq. 11) where the still-water depth ``h >= eta``, and critical flow
``H = eta``, ``|u| = sqrt(g eta)`` where ``h < eta`` (land included). Both
branches give ``2 sqrt(g eta)`` at ``h = eta``, so the speed is
continuous. ``eta`` is 2 m by default, as in OceanMesh2D.

The guide is silent on the default Courant number (it mentions 0.8 as an
example); OceanMesh2D's code uses 0.5, the default here.

Two allowances keep the promise on the mesh, where the Courant number is
measured on each vertex's shortest edge. The floor of eq. 10 is divided by
:data:`~terramesh.sizing.edge_shrink.EDGE_SHRINK` (0.6), the measured ratio
of a DistMesh mesh's shortest edges to their size (:func:`cfl_timestep`
multiplies by it, so ``dt = 0`` gives the same sizes and a step the mesh
keeps); and :func:`terramesh.coastal.size_function` grades the floor upward
(:func:`terramesh.sizing.limit_gradient_up`) before taking it: OceanMesh2D
applies the bare floor after gradation, and where the depth rises fast (a
shelf break) the sizes then jump, which a mesh cannot follow (the Gulf of
Maine at ``dt = 60`` s reached 1.29 on the mesh, the Aegean 1.79).
"""

import numpy as np

from ..._kernels.raster import wave_speed as _kernel_wave_speed
from ...errors import SizingError
from ...sizing.edge_shrink import EDGE_SHRINK
from ._common import field, positive
from .wavelength import GRAVITY

__all__ = ["COURANT", "ETA", "wave_speed", "courant_number", "cfl_timestep", "cfl_floor", "cfl_limit"]

COURANT = 0.5
"""Default Courant number (OceanMesh2D's ``descfl``)."""

ETA = 2.0
"""Default free-surface amplitude ``eta``, metres (§4.2)."""


def wave_speed(depth, *, eta=ETA, gravity=GRAVITY):
    """Characteristic speed ``|u| + sqrt(g H)`` of eq. 10-11, m/s, with critical flow where ``h < eta``.

    Parameters
    ----------
    depth : array_like
        Still-water depth ``h``, metres, positive down (land negative).
    eta : float, optional
        Free-surface elevation ``eta``, metres.
    gravity : float, optional
        ``g``, m/s^2.

    Returns
    -------
    ndarray
        m/s, the shape of ``depth``.

    Examples
    --------
    >>> wave_speed([100.0, 1.0]).round(4).tolist()
    [31.9473, 8.8589]
    """
    eta = positive("eta", eta)
    gravity = positive("gravity", gravity)
    # max(h, eta) is h on the eq. 11 branch and eta on the critical one, where eta sqrt(g / eta) = sqrt(g eta)
    depth = field("depth", depth)
    return _kernel_wave_speed(depth.reshape(-1), eta, gravity).reshape(depth.shape)  # one compiled kernel, any shape


def courant_number(sizes, depth, *, dt, eta=ETA, gravity=GRAVITY):
    """Courant number of eq. 10, ``Cr = (|u| + sqrt(g H)) dt / f``, with ``|u|`` and ``H`` as in :func:`wave_speed`.

    Parameters
    ----------
    sizes : array_like
        Element sizes ``f``, ground metres.
    depth : array_like
        Metres, positive down, the shape of ``sizes``.
    dt : float
        Time step, seconds.
    eta, gravity : float, optional
        Metres and m/s^2.

    Returns
    -------
    ndarray
        Dimensionless, the shape of ``sizes``.

    Examples
    --------
    >>> round(float(courant_number(100.0, 100.0, dt=2.0)), 4)
    0.6389
    """
    dt = positive("dt", dt)
    sizes = field("sizes", sizes, allow_inf=True, positive_only=True)
    speed = wave_speed(depth, eta=eta, gravity=gravity)
    if speed.shape != sizes.shape:
        raise SizingError(f"sizes {sizes.shape} and depth {speed.shape} must have the same shape")
    return speed * dt / sizes


def cfl_timestep(nearshore_sizes, depth, *, courant=COURANT, eta=ETA, gravity=GRAVITY, min_edge_length=None):
    """Automatic time step of eq. 12, ``dt = min[f_hd Cr s / (|u| + sqrt(g H))]``, with ``s = EDGE_SHRINK``.

    ``f_hd`` is the coastline's size function, the distance or the feature
    size function (:func:`~terramesh.coastal.sizes.shoreline_size`), which
    controls the resolution at the coast: with this ``dt``, limiting the
    sizes (:func:`cfl_limit`) leaves ``f_hd`` untouched everywhere. The
    guide's eq. 12 has no ``s``: a mesh's shortest edges come out below
    their size (:data:`~terramesh.sizing.edge_shrink.EDGE_SHRINK`), and its
    step would have broken ``Cr`` on them. The
    minimum is over the nodes where ``f_hd`` is finite. As OceanMesh2D does,
    ``f_hd`` may first be raised to ``min_edge_length`` (the smallest size
    the mesh will have anyway), so that a tiny feature size at a sharp
    corner does not set the time step.

    Parameters
    ----------
    nearshore_sizes : array_like
        ``f_hd``, ground metres (``inf`` where undefined).
    depth : array_like
        Metres, positive down, the shape of ``nearshore_sizes``.
    courant : float, optional
        Target ``Cr`` (0.5).
    eta : float, optional
        Metres.
    gravity : float, optional
        m/s^2.
    min_edge_length : float, optional
        ``h0``, metres.

    Returns
    -------
    float
        Seconds.

    Examples
    --------
    >>> round(cfl_timestep([100.0, 500.0], [100.0, 1.0]), 4)
    0.939
    """
    courant = positive("courant", courant)
    sizes = field("nearshore_sizes", nearshore_sizes, allow_inf=True, positive_only=True)
    if min_edge_length is not None:
        sizes = np.maximum(sizes, positive("min_edge_length", min_edge_length))
    speed = wave_speed(depth, eta=eta, gravity=gravity)
    if speed.shape != sizes.shape:
        raise SizingError(f"nearshore_sizes {sizes.shape} and depth {speed.shape} must have the same shape")
    if sizes.size == 0:
        raise SizingError("nearshore_sizes and depth are empty")
    smallest = float(np.min(sizes / speed))  # inf sizes (undefined f_hd) never win the minimum
    if not np.isfinite(smallest):
        raise SizingError("nearshore_sizes is inf everywhere: eq. 12 needs the distance or feature size function")
    return smallest * courant * EDGE_SHRINK


def cfl_floor(depth, *, dt, courant=COURANT, eta=ETA, gravity=GRAVITY):
    """The smallest size whose mesh keeps ``Cr <= courant`` at ``dt``: ``dt (|u| + sqrt(g H)) / (Cr s)``, metres.

    Eq. 10-11 solved for the size, divided by ``s =``
    :data:`~terramesh.sizing.edge_shrink.EDGE_SHRINK`, the measured ratio
    of a DistMesh mesh's shortest edges to their size.

    Parameters
    ----------
    depth : array_like
        Still-water depth, metres, positive down.
    dt : float
        Time step, seconds (positive).
    courant, eta, gravity : float, optional
        Target ``Cr``, metres and m/s^2.

    Returns
    -------
    ndarray
        Ground metres, the shape of ``depth``.

    Examples
    --------
    >>> cfl_floor([100.0, 1.0], dt=2.0).round(2).tolist()
    [212.98, 59.06]
    """
    dt = positive("dt", dt)
    courant = positive("courant", courant)
    speed = wave_speed(depth, eta=eta, gravity=gravity)
    # in place: at 39M nodes each temporary of ``dt * speed / courant`` cost 0.2-0.3 s
    speed *= dt / (courant * EDGE_SHRINK)
    return speed


def cfl_limit(
    sizes, depth, *, dt, courant=COURANT, eta=ETA, gravity=GRAVITY, nearshore_sizes=None, min_edge_length=None
):
    """Raise sizes to the smallest that keeps ``Cr <= courant`` at time step ``dt``: eq. 10-11 solved for ``f``.

    ``f_min = dt (|u| + sqrt(g H)) / (Cr s)`` (:func:`cfl_floor`; :func:`wave_speed`
    gives the speed, with critical flow where ``h < eta``, and ``s`` is
    :data:`~terramesh.sizing.edge_shrink.EDGE_SHRINK`) and the result is
    ``max(sizes, f_min)``, the floor as it is (see the module's notes for
    the graded floor :func:`terramesh.coastal.size_function` takes). ``dt = 0`` asks for the automatic time step of
    eq. 12 (the guide's ``'dt', 0``), computed by :func:`cfl_timestep` from
    ``nearshore_sizes`` (and ``min_edge_length``); call that function to
    know the ``dt`` chosen.

    Parameters
    ----------
    sizes : array_like
        Ground metres (``inf`` allowed).
    depth : array_like
        Metres, positive down, the shape of ``sizes``.
    dt : float
        Time step, seconds; 0 for eq. 12.
    courant : float, optional
        Target ``Cr`` (0.5).
    eta, gravity : float, optional
        Metres and m/s^2.
    nearshore_sizes : array_like, optional
        ``f_hd`` for ``dt = 0``.
    min_edge_length : float, optional
        ``h0`` for ``dt = 0`` (see :func:`cfl_timestep`).

    Returns
    -------
    ndarray
        Ground metres, the shape of ``sizes``.

    Examples
    --------
    >>> cfl_limit([50.0, 500.0], [100.0, 100.0], dt=2.0).round(2).tolist()
    [212.98, 500.0]
    """
    dt = positive("dt", dt, allow_zero=True)
    courant = positive("courant", courant)
    sizes = field("sizes", sizes, allow_inf=True, positive_only=True)
    if dt == 0:
        if nearshore_sizes is None:
            raise SizingError("dt = 0 (eq. 12) needs nearshore_sizes: the distance or feature size function")
        dt = cfl_timestep(
            nearshore_sizes, depth, courant=courant, eta=eta, gravity=gravity, min_edge_length=min_edge_length
        )
    floor = cfl_floor(depth, dt=dt, courant=courant, eta=eta, gravity=gravity)
    if floor.shape != sizes.shape:
        raise SizingError(f"sizes {sizes.shape} and depth {floor.shape} must have the same shape")
    return np.maximum(sizes, floor, out=floor)
