"""Quality measures of triangles."""

import numpy as np

from .._kernels.topology import triangle_qualities
from ..mesh.columns import squared_row_norms
from ..mesh.topology import checked_cells, checked_points, unique_edges
from ..sizing.edge_length import as_size_function

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
        Integer indices into ``points``.
    geographic : bool, optional
        Points are longitude, latitude (degrees): measure each cell on the
        ground, with longitudes scaled by the cosine of its centroid's
        latitude, so that a cell isotropic in metres scores as such.

    Returns
    -------
    numpy.ndarray, shape (m,)

    Raises
    ------
    MeshValidityError
        For points not of shape ``(n, 2)`` (tetrahedra: see
        :mod:`terramesh.quality.tetra`) or with a NaN or infinite
        coordinate (no quality, where 0 would call the cell flat), cells
        not an integer ``(m, 3)`` array, or indices outside ``0 .. n - 1``.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]])
    >>> float(triangle_quality(points, np.array([[0, 1, 2]]))[0].round(12))
    1.0
    """
    points = checked_points(points, 2, finite=True)
    cells = checked_cells(cells, 3, len(points))
    if not geographic:
        return triangle_qualities(points, cells)
    corner = [points[cells[:, i]] for i in range(3)]
    shrink = np.cos(np.radians((corner[0][:, 1] + corner[1][:, 1] + corner[2][:, 1]) / 3.0))
    corner = [np.column_stack([c[:, 0] * shrink, c[:, 1]]) for c in corner]
    side = [corner[(i + 1) % 3] - corner[i] for i in range(3)]
    squared = sum(squared_row_norms(s) for s in side)
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
        Integer indices into ``points``; in 3-D also ``(m, 3)`` surface triangles.
    edge_length : float, callable or terramesh.sizing.SizeGrid
        Requested size: a positive number, ``(k, dim) -> (k,)`` or a size
        grid; same units as ``points``.

    Returns
    -------
    numpy.ndarray, shape (e,)
        One ratio per unique edge; 1 means exactly as asked.

    Raises
    ------
    SizingError
        For a size that is not positive and finite (a number, or any value
        a callable returns), or a callable returning the wrong number of values.
    MeshValidityError
        For points not of shape ``(n, 2)`` or ``(n, 3)`` or with a NaN or
        infinite coordinate, cells not an integer ``(m, dim + 1)`` array (or
        ``(m, 3)`` triangles in 3-D), or indices outside ``0 .. n - 1``.
    """
    size = as_size_function(edge_length)
    points = checked_points(points, finite=True)
    # 3-D points: tetrahedra, or triangles of a surface (edges are edges either way)
    surface = points.shape[1] == 3 and np.ndim(cells) == 2 and np.shape(cells)[1] == 3
    cells = checked_cells(cells, 3 if surface else points.shape[1] + 1, len(points))
    edges = unique_edges(cells)
    start, end = points[edges[:, 0]], points[edges[:, 1]]
    lengths = np.sqrt(np.sum((end - start) ** 2, axis=1))
    return lengths / size(0.5 * (start + end))
