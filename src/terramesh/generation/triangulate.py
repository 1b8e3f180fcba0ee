"""Delaunay triangulation behind one small function, so the backend can be swapped."""

import numpy as np
from scipy.spatial import Delaunay, QhullError

from ..errors import GenerationError
from ..mesh.topology import signed_areas

__all__ = ["delaunay"]


def delaunay(points):
    """Delaunay triangulation of a 2D point set, counter-clockwise cells.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)

    Returns
    -------
    numpy.ndarray, shape (m, 3), int64

    Raises
    ------
    GenerationError
        If the points do not span a plane (fewer than three, or all collinear).

    Examples
    --------
    >>> import numpy as np
    >>> delaunay(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])).shape
    (2, 3)
    """
    if len(points) < 3:
        raise GenerationError(f"cannot triangulate {len(points)} points: the domain is too small for the mesh size")
    try:
        cells = Delaunay(points).simplices.astype(np.int64)
    except QhullError as error:
        raise GenerationError(f"the points to triangulate do not span a plane: {str(error).splitlines()[0]}") from error
    clockwise = signed_areas(points, cells) < 0
    cells[clockwise] = cells[clockwise][:, [0, 2, 1]]
    return cells
