"""Quality measures of triangles."""

import numpy as np

from .._kernels.topology import triangle_qualities
from ..mesh.topology import unique_edges

__all__ = ["triangle_quality", "edge_length_ratio"]


def triangle_quality(points, cells, *, geographic=False):
    """Shape quality ``q = 4 sqrt(3) A / (l1^2 + l2^2 + l3^2)`` of each triangle.

    Equation (1) of the OceanMesh2D user guide (Roberts & Pringle 2018,
    after Bank 1998): 1 for an equilateral triangle, 0 for a degenerate one,
    negative for a clockwise (inverted) one. Scale-invariant.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3)
    geographic : bool, optional
        Points are longitude, latitude (degrees): measure each cell on the
        ground, with longitudes scaled by the cosine of its centroid's
        latitude, so that a cell isotropic in metres scores as such.

    Returns
    -------
    numpy.ndarray, shape (m,)

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]])
    >>> float(triangle_quality(points, np.array([[0, 1, 2]]))[0].round(12))
    1.0
    """
    points = np.asarray(points, dtype=np.float64)
    cells = np.asarray(cells)
    if not geographic and cells.ndim == 2 and cells.shape[1] == 3 and len(points):
        return triangle_qualities(np.ascontiguousarray(points), np.ascontiguousarray(cells, dtype=np.int64))
    corner = [points[cells[:, i]] for i in range(3)]
    if geographic:
        shrink = np.cos(np.radians((corner[0][:, 1] + corner[1][:, 1] + corner[2][:, 1]) / 3.0))
        corner = [np.column_stack([c[:, 0] * shrink, c[:, 1]]) for c in corner]
    side = [corner[(i + 1) % 3] - corner[i] for i in range(3)]
    squared = sum(np.sum(s**2, axis=1) for s in side)
    area = 0.5 * (side[0][:, 0] * side[1][:, 1] - side[0][:, 1] * side[1][:, 0])
    with np.errstate(invalid="ignore", divide="ignore"):
        quality = 4.0 * np.sqrt(3.0) * area / squared
    return np.where(squared > 0, quality, 0.0)


def edge_length_ratio(points, cells, edge_length):
    """Each edge's length divided by the requested size at its midpoint.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, dim)
    cells : numpy.ndarray, shape (m, dim + 1)
    edge_length : float or callable
        Requested size: a number, or ``(k, dim) -> (k,)``; same units as
        ``points``.

    Returns
    -------
    numpy.ndarray, shape (e,)
        One ratio per unique edge; 1 means exactly as asked.
    """
    edges = unique_edges(cells)
    start, end = points[edges[:, 0]], points[edges[:, 1]]
    lengths = np.sqrt(np.sum((end - start) ** 2, axis=1))
    wanted = edge_length(0.5 * (start + end)) if callable(edge_length) else edge_length
    return lengths / np.asarray(wanted, dtype=np.float64)
