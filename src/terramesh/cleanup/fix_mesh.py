"""Make a triangulation valid: orientation, degenerate cells, unused vertices, boundary."""

import numpy as np

from ..mesh.topology import boundary_edges, signed_areas
from ..quality.triangle import triangle_quality

__all__ = ["orient_cells", "remove_unused_points", "remove_degenerate_cells", "repair_boundary"]


def orient_cells(points, cells):
    """Return a copy of ``cells`` with every triangle counter-clockwise."""
    cells = np.array(cells, dtype=np.int64)
    clockwise = signed_areas(points, cells) < 0
    cells[clockwise] = cells[clockwise][:, [0, 2, 1]]
    return cells


def remove_unused_points(points, cells):
    """Drop vertices no cell uses and renumber the cells.

    Returns
    -------
    points : numpy.ndarray, shape (k, dim)
    cells : numpy.ndarray, shape (m, 3)
    kept : numpy.ndarray, shape (k,)
        Index in the input ``points`` of each vertex kept.
    """
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    kept = np.flatnonzero(used)
    renumber = np.full(len(points), -1, dtype=np.int64)
    renumber[kept] = np.arange(len(kept))
    return points[kept], renumber[cells], kept


def remove_degenerate_cells(points, cells, min_quality=1e-6):
    """Drop cells whose quality (guide eq. 1) is below ``min_quality``: flat slivers."""
    return cells[triangle_quality(points, cells) >= min_quality]


def repair_boundary(points, cells):
    """Delete cells until every boundary vertex has exactly two boundary edges.

    The OceanMesh2D guide's ``delete_interior_elements`` rule (§4.3): at
    each vertex with more than two boundary edges, delete the connected cell
    with the most boundary edges (two or three: a cell hanging by a vertex),
    the lowest-quality one among equals; repeat until no such vertex is left.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3), counter-clockwise

    Returns
    -------
    numpy.ndarray, shape (k, 3)
        The remaining cells (vertices may become unused; see
        :func:`remove_unused_points`).
    """
    cells = np.asarray(cells)
    while len(cells):
        edges = boundary_edges(cells)
        degree = np.bincount(edges.ravel(), minlength=len(points))
        bad_vertex = degree > 2
        if not bad_vertex.any():
            break
        # boundary edges per cell: an edge (a, b) of the cell that is a boundary edge
        edge_keys = edges[:, 0] * len(points) + edges[:, 1]
        directed = np.stack([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]], axis=1)
        cell_keys = directed[..., 0] * len(points) + directed[..., 1]
        n_boundary_edges = np.isin(cell_keys, edge_keys).sum(axis=1)
        quality = triangle_quality(points, cells)
        # per bad vertex pick one cell: most boundary edges first, then lowest quality
        touching = np.repeat(np.arange(len(cells)), 3)
        corner = cells.ravel()
        at_bad = bad_vertex[corner]
        touching, corner = touching[at_bad], corner[at_bad]
        order = np.lexsort((quality[touching], -n_boundary_edges[touching], corner))
        first = np.ones(len(order), dtype=bool)
        first[1:] = corner[order][1:] != corner[order][:-1]
        delete = np.zeros(len(cells), dtype=bool)
        delete[touching[order][first]] = True
        cells = cells[~delete]
    return cells
