"""Disconnected parts of a triangulation (the guide's ``delete_exterior_elements``, §4.3)."""

import numbers

import numpy as np

from .._kernels.cleanup import edge_components, table_components
from ..errors import MeshValidityError
from ..mesh.topology import checked_cells, checked_points, densely_numbered, signed_areas

__all__ = ["cell_components", "delete_disjoint_parts"]


def cell_components(cells):
    """Label the edge-connected parts of a triangulation.

    Two cells are in the same part when a chain of cells, each sharing an
    edge with the next, joins them; cells touching at a vertex only are not
    connected. This is the guide's breadth-first "spider search", done as a
    union-find over the cells sharing each edge (linear time, any number of
    cells per edge).

    Parameters
    ----------
    cells : numpy.ndarray, shape (m, 3)

    Returns
    -------
    n_parts : int
    labels : numpy.ndarray, shape (m,)
        Part of each cell, ``0 .. n_parts - 1``, numbered in the order of
        each part's first cell.

    Examples
    --------
    >>> import numpy as np
    >>> cell_components(np.array([[0, 1, 2], [2, 1, 3], [3, 4, 5]]))[1].tolist()
    [0, 0, 1]
    """
    cells = checked_cells(cells, 3)  # the kernel indexes without bounds checks: -1 crashed the process
    if len(cells) == 0:
        return 0, np.zeros(0, dtype=np.int64)
    n_parts, labels = edge_components(*densely_numbered(cells)[:2])
    return int(n_parts), labels


def checked_cutoff(cutoff):
    """``cutoff`` (a part's share of the whole, 0 to 1) as a float, else MeshValidityError."""
    if not isinstance(cutoff, numbers.Real) or isinstance(cutoff, bool) or not 0 <= cutoff <= 1:
        raise MeshValidityError(f"the disjoint cutoff must be a fraction between 0 and 1, got {cutoff!r}")
    return float(cutoff)


def disjoint_parts_to_delete(points, cells, cutoff, by, table=None):
    """Mask of the cells in parts below ``cutoff`` of the total, and how many such parts.

    ``table``, the cells' neighbour table if known, gives the parts without
    looking for shared edges again.
    """
    cutoff = checked_cutoff(cutoff)
    if by not in ("cells", "area"):
        raise MeshValidityError(f"by must be 'cells' or 'area', got {by!r}")
    n_parts, labels = cell_components(cells) if table is None else table_components(table)
    if n_parts <= 1:
        return np.zeros(len(cells), dtype=bool), 0
    weight = np.abs(signed_areas(points, cells)) if by == "area" else None
    size = np.bincount(labels, weights=weight, minlength=n_parts)
    small = size < cutoff * size.sum()
    small[np.argmax(size)] = False  # the largest part always stays
    return small[labels], int(small.sum())


def delete_disjoint_parts(points, cells, *, cutoff=0.01, by="cells"):
    """Delete the disconnected parts that are a small fraction of the mesh.

    The OceanMesh2D guide's ``delete_exterior_elements`` (§4.3) with its
    ``dj_cutoff``: a lake joined to the sea by nothing, or by a channel
    narrower than one element, is a separate part; it is deleted when it
    holds fewer than ``cutoff`` of all cells. Raise ``cutoff`` to drop
    bigger bays, lower it to keep them.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
        Vertex coordinates (used when ``by="area"``).
    cells : numpy.ndarray, shape (m, 3)
    cutoff : float, optional
        Fraction in [0, 1]: parts smaller than ``cutoff`` times the total are
        deleted. The largest part always stays, so 1 keeps only the largest
        and 0 keeps everything.
    by : {"cells", "area"}, optional
        Size of a part: its number of cells (the guide) or its area.

    Returns
    -------
    numpy.ndarray, shape (k, 3)
        The remaining cells, in their original order (vertices of deleted
        parts become unused; see
        :func:`~terramesh.cleanup.remove_unused_points`).

    Raises
    ------
    MeshValidityError
        For a cutoff outside [0, 1] or an unknown ``by``.

    Examples
    --------
    Ten cells in a strip and one triangle far away:

    >>> import numpy as np
    >>> x = np.arange(6.0)
    >>> points = np.vstack([np.column_stack([x, 0 * x]), np.column_stack([x, 0 * x + 1]), [[9, 9], [10, 9], [9, 10]]])
    >>> strip = [[i, i + 1, i + 7] for i in range(5)] + [[i, i + 7, i + 6] for i in range(5)]
    >>> cells = np.array(strip + [[12, 13, 14]])
    >>> delete_disjoint_parts(points, cells, cutoff=0.2).shape
    (10, 3)
    >>> delete_disjoint_parts(points, cells, cutoff=0.05).shape
    (11, 3)
    """
    points = checked_points(points)
    cells = checked_cells(cells, 3, len(points))
    delete, _ = disjoint_parts_to_delete(points, cells, cutoff, by)
    return cells[~delete]
