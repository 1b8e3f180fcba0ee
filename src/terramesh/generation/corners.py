"""Domain corners a 2D mesh covers over, put back on its boundary by flips.

DistMesh keeps the Delaunay cells whose centroid is inside. By a sharp
corner of a hole (52.5 degrees at h = 0.3) the triangulation can take the
other diagonal of the quad at the corner: one cell spans the hole's tip,
49 % of it in the hole and its centroid just outside, and the corner's
vertex, fixed, ends up inside the mesh instead of on its boundary. Flipping
the diagonal gives one cell in the hole, which goes, and one outside it.
"""

import numpy as np

from ..mesh.topology import signed_areas

_WEIGHTS = np.array([[0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6]])
"""Barycentric weights of the three points a cell is probed at: each toward one of its corners."""

PROBE_OUTSIDE = 0.05
"""Local sizes outside the domain from which a probe of a cell at a covered corner counts as outside."""


def recover_corners(points, cells, boundary, fixed, domain, size, tolerance):
    """``cells`` with the fixed points on the domain's boundary that lie inside the mesh put back on its boundary.

    A fixed vertex (``fixed``: their indices; the domain's corners among
    them) within ``tolerance`` of the domain's boundary that is on none of
    the mesh's ``boundary`` edges has a cell at it reaching outside the
    domain. That cell's edge opposite the vertex is flipped with the cell
    beyond it; of the two new cells, the one whose centroid is outside
    goes. Kept only where that cell's vertices are on the domain's boundary
    and the vertex then is on the mesh's, which stays manifold; otherwise
    the cells are as they were. Only the fixed vertices off the mesh's
    boundary are looked at, and only a covered one's cells.

    Returns
    -------
    cells : numpy.ndarray, shape (m, 3)
    recovered : int
        How many were put back on the boundary.
    """
    inside = np.setdiff1d(fixed, boundary)
    if len(inside) == 0 or len(cells) == 0:
        return cells, 0
    covered = inside[np.abs(domain.distance(points[inside])) <= tolerance]
    if len(covered) == 0:
        return cells, 0
    # every look below stays within three rings of cells of a covered vertex (a flip's far vertex, and
    # the cells round it): they are taken out once. A jagged coast's mesh covers corners by design (150
    # in §5.3's 590k cells), and scanning all the cells for each took 3.3 s
    near = _rings_of_cells(cells, covered, 3)
    local, origin = cells[near], near
    recovered = 0
    for vertex in covered:
        attempt = _flipped_at(points, local, int(vertex), domain, size, tolerance)
        if attempt is not None:
            gone, new = attempt
            local = np.vstack([np.delete(local, gone, axis=0), new])
            origin = np.concatenate([np.delete(origin, gone), np.full(len(new), -1)])
            recovered += 1
    if recovered == 0:
        return cells, 0
    # the cells kept in their order, then the new ones in the order they were made, as flips of the whole would
    removed = np.setdiff1d(near, origin[origin >= 0])
    return np.vstack([np.delete(cells, removed, axis=0), local[origin < 0]]), recovered


def _rings_of_cells(cells, vertices, rings):
    """Indices (ascending) of the cells within ``rings`` steps of ``vertices``: a vertex's own cells are one."""
    near = np.zeros(len(cells), dtype=bool)
    for _ in range(rings):
        near = np.isin(cells, vertices).any(axis=1)
        vertices = np.unique(cells[near])
    return np.flatnonzero(near)


def _flipped_at(points, cells, vertex, domain, size, tolerance):
    """``(gone, new)``: rows of ``cells`` to delete and cells to add that flip the outside cell at ``vertex`` away.

    None where no flip mends it.
    """
    fan = np.flatnonzero(np.any(cells == vertex, axis=1))
    corners_of = points[cells[fan]]
    probes = np.einsum("pk,ckd->cpd", _WEIGHTS, corners_of).reshape(-1, 2)
    outside = domain.distance(probes).reshape(len(fan), 3).max(axis=1) / size(corners_of.mean(axis=1))
    order = np.argsort(-outside)
    for cell in fan[order][outside[order] > PROBE_OUTSIDE]:
        a, b = (int(v) for v in _ccw_from(cells[cell], vertex)[1:])
        beyond = np.flatnonzero(np.any(cells == a, axis=1) & np.any(cells == b, axis=1))
        beyond = beyond[beyond != cell]
        if len(beyond) != 1:
            continue
        other = int(next(v for v in cells[beyond[0]] if v not in (a, b)))
        new = np.array([[vertex, a, other], [vertex, other, b]])
        if np.any(signed_areas(points, new) <= 0):  # the quad is not convex there: no flip
            continue
        keep = domain.distance(points[new].mean(axis=1)) < 0
        if keep.all() or not keep.any():
            continue
        if np.any(np.abs(domain.distance(points[new[~keep][0]])) > tolerance):
            continue  # the cell that goes would leave a vertex off the domain's boundary on the mesh's
        trial = np.vstack([np.delete(cells, [cell, beyond[0]], axis=0), new[keep]])
        degrees = [_boundary_degree(trial, v) for v in (vertex, a, b, other)]
        if degrees[0] == 2 and all(degree in (0, 2) for degree in degrees):
            return np.array([cell, beyond[0]]), new[keep]
    return None


def _boundary_degree(cells, vertex):
    """How many boundary edges meet at ``vertex``: those of its cells that no other of its cells shares."""
    around = cells[np.any(cells == vertex, axis=1)]
    if len(around) == 0:
        return -1  # no longer used: not a mesh to keep
    others = around[around != vertex]
    _, counts = np.unique(others, return_counts=True)
    return int(np.count_nonzero(counts == 1))


def _ccw_from(cell, vertex):
    """The cell's three vertices in their (counter-clockwise) order, starting at ``vertex``."""
    start = int(np.flatnonzero(cell == vertex)[0])
    return np.roll(cell, -start)
