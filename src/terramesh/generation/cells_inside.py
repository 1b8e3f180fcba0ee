"""The cells of a triangulation that belong to the mesh: those whose centroid is inside the domain.

With upper bounds of the points' distances (:class:`~.distances.LazyDistance`)
only the cells near the boundary have their centroid's distance evaluated.
"""

import numpy as np

from .._kernels.topology import cell_centroids, classify_cells, inner_cell_edges, same_rows
from ..errors import GenerationError
from ..mesh.topology import kept_cells
from .triangulate import delaunay_3d

_NO_BOUND = np.empty(0)  # no bound on the distances (plain callables, points changed): every cell is evaluated


def cells_inside(domain, points, cells, tolerance, distance_bound=None, first=0, earlier=None, record=None):
    """Mask of the cells whose centroid lies inside the domain by more than ``tolerance``.

    With upper bounds of the points' distances, only cells near the
    boundary have their centroid's distance evaluated. Vertex ``v`` is point
    ``v - first``; cells not of the points (a triangulation's ghost and
    frame cells, see :meth:`~.triangulate.Triangulation.cells_with_ghosts`) are outside.
    A ``record`` (a dict) gets the cells and which of them were evaluated,
    for a later call as ``earlier``: when only points were added since (the
    others unmoved, their bounds the same), a cell still in the same row
    keeps the answer it got (the boundary gaps' second pass in :func:`~.relax.relax` at every
    triangulation of a coastline evaluated 170k centroids of the
    OceanMesh2D guide's §5.3 mesh again, nearly all unchanged).
    """
    bound = _NO_BOUND if distance_bound is None else distance_bound
    state = classify_cells(points, cells, bound, tolerance, first)
    inside = state > 0
    unsure = np.flatnonzero(state == 0)
    if record is not None:  # ``inside`` itself: the answers found below land in the record too
        record.update(cells=cells, evaluated=state == 0, inside=inside, first=first)
    if earlier is not None and earlier["first"] == first:
        before = earlier["cells"]
        known = np.searchsorted(unsure, len(before))  # rows that existed before: a prefix (ascending)
        head = unsure[:known]
        same = same_rows(cells, before, head, earlier["evaluated"])
        inside[head[same]] = earlier["inside"][head[same]]
        unsure = np.concatenate([head[~same], unsure[known:]])
    inside[unsure] = domain.inside(cell_centroids(points, cells, unsure, first), tolerance)
    return inside


def mesh_edges(domain, triangulation, points, tolerance, lazy_distance=None, earlier=None, record=None):
    """The triangulation's cells with their centroid inside, their unique edges, the boundary edges among them.

    With the ``lazy_distance`` that follows ``points``, only cells near the
    boundary have their centroid evaluated; ``earlier`` and ``record`` as
    for :func:`cells_inside`.
    """
    inner_cells, edges, on_boundary = flagged_mesh_edges(
        domain, triangulation, points, tolerance, lazy_distance, earlier, record
    )
    return inner_cells, edges, edges[on_boundary]


def flagged_mesh_edges(domain, triangulation, points, tolerance, lazy_distance=None, earlier=None, record=None):
    """As :func:`mesh_edges`, with a mask of the boundary edges instead of them."""
    if len(points) != triangulation.n_points:  # the own arrays tell ghost cells by the points' count
        raise GenerationError(f"{len(points)} points for a triangulation of {triangulation.n_points}")
    cells, neighbors, first = triangulation.cells_with_ghosts()
    bound = None if lazy_distance is None else lazy_distance.upper_bound(len(points))
    inside = cells_inside(domain, points, cells, tolerance, bound, first, earlier, record)
    return inner_cell_edges(cells, neighbors, inside, first)


def tetrahedralise(domain, points, tolerance, distance_bound=None, *, neighbors=False):
    """Delaunay cells with their centroid inside; with ``neighbors`` their neighbours (renumbered), else None.

    The force loop needs no neighbours (renumbering them takes 8 ms at
    25k points, 7 % of the tetrahedralisation).

    The points must be distinct (see :func:`~terramesh._kernels.delaunay3d.duplicate_points`).
    """
    cells, across = delaunay_3d(points)
    inside = cells_inside(domain, points, cells, tolerance, distance_bound)
    if not neighbors:
        return cells[inside], None
    return kept_cells(cells, across, inside)
