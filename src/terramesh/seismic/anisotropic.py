"""Seismic cells that follow the layers: the wavelength's length along them, refined across a velocity contrast."""

import numpy as np

from ..errors import SizingError
from ..sizing import DEFAULT_GRADE, limit_gradient
from ..sizing.metric import MetricGrid, metric_tensor
from .sizing import SeismicSize, mesh_cfl_floor, positive_number

__all__ = ["layer_metric"]

ORIENTATION_WIDTH = 2.0  # hmin (at least two grid steps): the Gaussian over which the layers' direction is averaged


def layer_metric(size, *, gradient_refinement, hmin=None):
    """A metric for cells as long as ``size`` asks along the layers and refined by the velocity gradient across them.

    The isotropic gradient refinement (:func:`size_function`'s
    ``gradient_refinement``: ``h = min(h, v / (m |grad v|))``) shrinks the
    cells in every direction, but a layered model changes only across its
    layers. Here the size along the layers stays ``size``'s (wavelength,
    bounds, padding, CFL) and only the size across them is refined:
    ``across = min(along, max(hmin, v / (m |grad v|)))``, graded from the
    contrasts at ``size``'s grade (the
    :func:`~terramesh.sizing.limit_gradient` of the sizes) and, for sizes
    made with ``dt``, kept above their CFL floor, so that the time step
    stays stable across the layers as well. The layers'
    direction is that of the velocity's structure tensor (the gradient's
    outer product averaged over ``ORIENTATION_WIDTH * hmin``), so it holds
    carried from the nearest contrast to the nodes between, where the
    gradient itself is zero.

    Parameters
    ----------
    size : SeismicSize
        2-D sizes from :func:`size_function`, made without
        ``gradient_refinement`` (here it acts across the layers only).
    gradient_refinement : float
        ``m``, edges per velocity scale length ``v / |grad v|`` across the layers.
    hmin : float, optional
        Smallest size across the layers, metres; defaults to ``size``'s ``hmin``.

    Returns
    -------
    MetricGrid
        The metric on ``size``'s grid, for
        :func:`~terramesh.generation.generate_anisotropic_mesh` with
        ``size.domain`` as the domain.

    Raises
    ------
    SizingError
        For 3-D sizes, sizes already refined by the gradient, or a
        non-positive ``gradient_refinement`` or ``hmin``.

    Examples
    --------
    Two layers, 1500 m/s over 3000 m/s: cells 30 m long along the contrast
    at z = -237.5 m and 10 m across it.

    >>> import numpy as np, terramesh as tm
    >>> v = np.where(np.arange(21)[:, None] < 10, 1500.0, 3000.0) * np.ones((21, 41))
    >>> model = tm.seismic.read_velocity(v, spacing=25.0, axis_order="zx")
    >>> size = tm.seismic.size_function(model, frequency=5, hmin=10, grade=0.2)
    >>> metric = layer_metric(size, gradient_refinement=20)
    >>> major, minor, angle = tm.sizing.metric_sizes(metric([(500.0, -225.0)]))
    >>> round(float(major[0]), 6), round(float(minor[0]), 6), round(float(np.degrees(angle[0])))
    (30.0, 10.0, 0)
    """
    if not isinstance(size, SeismicSize) or size.dim != 2:
        raise SizingError("layer_metric needs 2-D sizes from terramesh.seismic.size_function")
    if size.settings.get("gradient_refinement") is not None:
        raise SizingError(
            "make the sizes without gradient_refinement: layer_metric refines across the layers only, where the "
            "sizes' own refinement has already shrunk the cells along them too"
        )
    elements = positive_number("gradient_refinement", gradient_refinement)
    hmin = size.settings["hmin"] if hmin is None else positive_number("hmin", hmin, unit=" (metres)")
    from scipy.ndimage import distance_transform_edt, gaussian_filter

    velocity, spacing = size.model.values, np.asarray(size.model.spacing, dtype=np.float64)
    gradient_x, gradient_z = np.gradient(velocity, *spacing)
    along = size.values
    with np.errstate(divide="ignore"):
        scale = velocity / (elements * np.hypot(gradient_x, gradient_z))
    grade = size.settings.get("grade") or DEFAULT_GRADE
    across = np.minimum(limit_gradient(np.clip(scale, hmin, along), spacing, grade), along)
    settings = size.settings
    if settings.get("dt") is not None:  # the sizes' CFL floor holds across the layers too: the time step is theirs
        floor = mesh_cfl_floor(
            velocity, spacing, dt=settings["dt"], order=settings["element_order"], courant=settings["courant"]
        )
        across = np.minimum(np.maximum(across, floor), along)
    refined = across < along
    if not refined.any():
        return MetricGrid(size.axes, metric_tensor(along, along, 0.0))
    # the layers' normal: the leading eigenvector of the structure tensor (Gaussian-derivative gradients: central
    # differences of a layer stepping across the grid tilt it by 3-6 degrees), taken at the contrasts and carried
    # to the nodes their graded refinement reaches (the gradient there is zero, its direction noise)
    smooth_x = gaussian_filter(velocity, 1.0, order=(1, 0)) / spacing[0]
    smooth_z = gaussian_filter(velocity, 1.0, order=(0, 1)) / spacing[1]
    sigma = np.maximum(ORIENTATION_WIDTH * hmin / spacing, 2.0)
    xx = gaussian_filter(smooth_x * smooth_x, sigma)
    xz = gaussian_filter(smooth_x * smooth_z, sigma)
    zz = gaussian_filter(smooth_z * smooth_z, sigma)
    normal = 0.5 * np.arctan2(2.0 * xz, xx - zz)
    contrast = scale <= across * (1.0 + 1e-9)  # where the gradient set the size, not its grading
    if contrast.any():
        normal = normal[
            tuple(distance_transform_edt(~contrast, sampling=spacing, return_distances=False, return_indices=True))
        ]
    return MetricGrid(size.axes, metric_tensor(along, across, normal + 0.5 * np.pi))
