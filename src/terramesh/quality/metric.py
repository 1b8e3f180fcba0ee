"""Quality and edge lengths measured in a metric: how well an anisotropic mesh meets what it was asked."""

from .._kernels import metric as _kernel
from ..mesh.topology import checked_cells, checked_points, unique_edges
from ..sizing.metric import as_metric_function

__all__ = ["metric_quality", "metric_edge_lengths"]


def _measured(points, cells, metric):
    points = checked_points(points, dim=2, finite=True)
    cells = checked_cells(cells, 3, len(points))
    return points, cells, as_metric_function(metric)(points)


def metric_quality(points, cells, metric):
    """Triangle quality in a metric: ``4 sqrt(3) A / (l1**2 + l2**2 + l3**2)`` with area and lengths measured in it.

    The guide's eq. (1) in the metric's own space: 1 for a cell that is
    equilateral there (long and thin in the plane as the metric asks), 0
    for a flat one; each cell is measured in the mean of its corners'
    matrices. With ``metric`` the identity it is
    :func:`~terramesh.quality.triangle_quality`.

    Parameters
    ----------
    points : array_like, shape (n, 2)
    cells : array_like, shape (m, 3)
        Counter-clockwise triangles (clockwise ones score negative).
    metric : callable or array_like, shape (2, 2)
        As for :func:`~terramesh.generation.generate_anisotropic_mesh`.

    Returns
    -------
    numpy.ndarray, shape (m,)

    Raises
    ------
    MeshValidityError
        For points not of shape ``(n, 2)`` or with a NaN or infinite
        coordinate, or cells that are not integer indices of them.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.sizing import metric_tensor
    >>> thin = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.0866]])   # equilateral once y counts 10 times
    >>> metric_quality(thin, [[0, 1, 2]], metric_tensor(1.0, 0.1, 0.0)).round(3).tolist()
    [1.0]
    """
    points, cells, values = _measured(points, cells, metric)
    return _kernel.cell_qualities(points, cells, values)


def metric_edge_lengths(points, cells, metric):
    """Length of every edge of the mesh in a metric (each in the mean of its ends' matrices): 1 is the size asked.

    Parameters
    ----------
    points : array_like, shape (n, 2)
    cells : array_like, shape (m, 3)
    metric : callable or array_like, shape (2, 2)
        As for :func:`~terramesh.generation.generate_anisotropic_mesh`.

    Returns
    -------
    numpy.ndarray, shape (e,)
        One length per unique edge, in the order of
        :func:`~terramesh.mesh.topology.unique_edges`.

    Examples
    --------
    >>> from terramesh.sizing import metric_tensor
    >>> metric_edge_lengths([[0, 0], [2, 0], [0, 0.5]], [[0, 1, 2]], metric_tensor(2.0, 0.5, 0.0)).round(3).tolist()
    [1.0, 1.0, 1.414]
    """
    points, cells, values = _measured(points, cells, metric)
    return _kernel.edge_lengths(points, unique_edges(cells), values)
