"""Sliver removal for tetrahedral meshes: flips, vertex moves and contractions, flat boundary cells.

The final Delaunay mesh of :func:`~terramesh.generation.distmesh3d.generate_mesh_3d`
is cleaned here in rounds (:func:`remove_slivers`): flat cells with two or
more faces on the boundary are peeled off, the best edge removal (every
triangulation of the ring, by dynamic programming) or 2-3 flip replaces poor
cells, poor cells' vertices move to the best of a deterministic set of
nearby positions (on the boundary for boundary vertices), and interior
vertices that still hold slivers are contracted onto a neighbour. Every
change must raise the smallest dihedral angle of the cells it touches and
keep them positive. Cells below AIM_DIHEDRAL (15 degrees) are worked on;
the generator refuses a mesh with any cell below MIN_DIHEDRAL (10 degrees).
Then flips alone work on the cells below FLIP_AIM (30 degrees).

References
----------
L. A. Freitag and C. Ollivier-Gooch, "Tetrahedral mesh improvement using
swapping and smoothing", Int. J. Numer. Meth. Eng. 40(21), 3979-4002,
1997. :doi:`10.1002/(SICI)1097-0207(19971115)40:21<3979::AID-NME251>3.0.CO;2-9`

B. M. Klingner and J. R. Shewchuk, "Aggressive tetrahedral mesh
improvement", Proceedings of the 16th International Meshing Roundtable,
3-23, 2007 (edge removal by dynamic programming).
"""

import logging

import numpy as np

from .._kernels.delaunay3d import boundary_vertex_mask
from .._kernels.slivers import MIN_DIHEDRAL as MIN_DIHEDRAL  # re-exported: the generator's bound, degrees
from .._kernels.slivers import (
    collapse_vertices,
    delete_flat_boundary_cells,
    flip_slivers,
    perturb_vertices,
    qualities,
    try_positions,
)
from .._kernels.smoothing import CUBE_DIRECTIONS
from .._kernels.topology import cell_centroids
from ..mesh.topology import kept_cells

logger = logging.getLogger("terramesh.generation")  # sliver removal is a step of 3D generation; its log goes there

AIM_DIHEDRAL = 15.0  # degrees: sliver removal works on every cell below this
SHARP_TURN = 35.0  # degrees between two boundary faces' outward normals above which their common edge is sharp
SLIVER_ROUNDS = 12  # rounds of flips, perturbation and boundary deletion
# the slivers gone, cells below FLIP_AIM degrees are flipped, in up to FLIP_ROUNDS rounds, where that raises the
# smallest angle of the cells replaced: BP2004 3-D (65k vertices) smallest dihedral angle 15.1 -> 20.1 degrees, first
# percentile of the radius ratio 0.68 -> 0.75; the 25k ball of bench_3d.py 15.7 -> 21.7 and 0.60 -> 0.72
FLIP_AIM = 30.0
FLIP_ROUNDS = 5


# --- sliver removal: flips, vertex perturbation, flat boundary cells ----------------------------------
#
# The mesh is held as ``tets`` (capacity, 4) positively oriented, ``neighbors`` (capacity, 4) with the
# cell across the face opposite each corner (-1 on the boundary), ``alive`` flags, a free list, and
# ``vertex_tet``: one live cell at each vertex (-1 for an unused vertex). Every change goes through
# the kernels of :mod:`terramesh._kernels.slivers`, keeping all of it consistent.


def _aim(degrees):
    return -np.cos(np.radians(degrees))


STEPS = np.array([0.3, 0.15, 0.08, 0.04, 0.02])
"""Lengths of the moves a vertex tries, as fractions of the mean edge length at it, largest first."""


def feature_vertices(points, cells, neighbors, n_points, angle=25.0):
    """Boundary vertices on a sharp edge or corner, which stay put during sliver removal.

    A vertex is one when some boundary face around it turns more than
    ``angle`` degrees away from the mean normal there.
    """
    faces, normals = [], []
    for k in range(4):
        on = neighbors[:, k] < 0
        face = np.delete(cells[on], k, axis=1)
        a, b, c = (points[face[:, i]] for i in range(3))
        normal = np.cross(b - a, c - a)
        toward = points[cells[on, k]] - a
        normal *= -np.sign(np.einsum("ij,ij->i", normal, toward))[:, None]  # outward
        faces.append(face)
        normals.append(normal)
    faces, normals = np.concatenate(faces), np.concatenate(normals)
    length = np.sqrt(np.einsum("ij,ij->i", normals, normals))
    unit = normals / np.where(length > 0, length, 1.0)[:, None]
    mean = np.zeros((n_points, 3))
    for i in range(3):
        np.add.at(mean, faces[:, i], normals)
    mean /= np.maximum(np.sqrt(np.einsum("ij,ij->i", mean, mean)), 1e-300)[:, None]
    cosine = np.ones(n_points)
    for i in range(3):
        np.minimum.at(cosine, faces[:, i], np.einsum("ij,ij->i", unit, mean[faces[:, i]]))
    return cosine < np.cos(np.radians(angle))


def _flips_toward(points, tets, adjacent, alive, vertex_tet, free, state, aim, rounds=FLIP_ROUNDS):
    """Flip the cells below quality ``aim`` where that raises the smallest angle of the cells replaced; the changes.

    On the working arrays of :func:`remove_slivers`: :func:`flip_slivers`
    (edge removals and 2-3 flips) on the cells below ``aim``, poorest
    first, in up to ``rounds`` rounds: a flip leaves new cells, and their
    neighbours may flip then. The points stay, and so do the boundary faces (a flip needs
    the cells on both sides of a face, or all about an edge).
    """
    changes = 0
    for _ in range(rounds):
        live = np.flatnonzero(alive[: state[0]])
        quality = qualities(points, tets, live)
        poor = quality < aim
        order = live[poor][np.argsort(quality[poor], kind="stable")]
        made = flip_slivers(points, tets, adjacent, alive, vertex_tet, free, state, order, aim) if len(order) else 0
        changes += made
        if made == 0:
            break
    return changes


def remove_slivers(domain, points, cells, neighbors, n_fixed, boundary_candidates):
    """Raise every cell's smallest dihedral angle towards AIM_DIHEDRAL; returns points, cells, neighbours, rounds.

    Then the cells below FLIP_AIM are flipped where that raises the
    smallest angle of the cells replaced (:func:`_flips_toward`).

    ``boundary_candidates(points, vertices)`` gives the positions on the
    domain's boundary that boundary ``vertices`` may slide to, shape
    (k, c, 3): the generator's, which owns the projection onto the boundary.
    """
    n = len(points)
    m = len(cells)
    capacity = m + m // 4 + 1024
    tets = np.full((capacity, 4), -1, dtype=np.int64)
    tets[:m] = cells
    adjacent = np.full((capacity, 4), -1, dtype=np.int64)
    adjacent[:m] = neighbors
    alive = np.zeros(capacity, dtype=bool)
    alive[:m] = True
    free = np.empty(capacity, dtype=np.int64)
    state = np.array([m, 0, 0], dtype=np.int64)  # slots used, free-list length, visit stamp
    vertex_tet = np.full(n, -1, dtype=np.int64)
    for k in range(4):
        vertex_tet[cells[:, k]] = np.arange(m)
    fixed = np.zeros(n, dtype=bool)
    fixed[:n_fixed] = True
    mark = np.full(capacity, -1, dtype=np.int64)
    feature = feature_vertices(points, cells, neighbors, n)
    aim = _aim(AIM_DIHEDRAL)
    sharp = np.cos(np.radians(SHARP_TURN))

    def peel_outside():
        """Delete boundary cells whose centroid lies outside (a bridge over a concave edge, say), sharp or not."""
        while True:
            live = np.flatnonzero(alive[: state[0]])
            outside = live[domain.distance(cell_centroids(points, tets, live, 0)) > 0]
            if len(outside) == 0 or not delete_flat_boundary_cells(
                points, tets, adjacent, alive, vertex_tet, free, state, outside, np.inf, fixed, -2.0
            ):
                return

    peel_outside()
    rounds = 0
    for rounds in range(1, SLIVER_ROUNDS + 1):
        live = np.flatnonzero(alive[: state[0]])
        quality = qualities(points, tets, live)
        poor = quality < aim
        if not poor.any():
            rounds -= 1
            break
        order = live[poor][np.argsort(quality[poor], kind="stable")]
        # flat cells on the boundary go first (peeled layer by layer), then flips, then vertex moves
        changes = 0
        while True:
            deleted = delete_flat_boundary_cells(
                points, tets, adjacent, alive, vertex_tet, free, state, order, aim, fixed, sharp
            )
            changes += deleted
            if deleted == 0:
                break
        order = order[alive[order]]
        changes += flip_slivers(points, tets, adjacent, alive, vertex_tet, free, state, order, aim)
        order = order[alive[order]]
        vertices = np.unique(tets[order])
        boundary = boundary_vertex_mask(tets, adjacent, alive, n)
        movable = ~fixed & ~boundary
        changes += perturb_vertices(
            points, tets, adjacent, vertex_tet, vertices, movable, mark, state, CUBE_DIRECTIONS, STEPS, aim
        )
        sliding = vertices[boundary[vertices] & ~fixed[vertices] & ~feature[vertices]]
        if len(sliding):
            candidates = boundary_candidates(points, sliding)
            changes += try_positions(points, tets, adjacent, vertex_tet, sliding, candidates, mark, state, aim)
        if rounds >= 2:  # what flips and moves could not mend: contract interior vertices of the slivers left
            live = np.flatnonzero(alive[: state[0]])
            stubborn = live[qualities(points, tets, live) < aim]
            changes += collapse_vertices(
                points, tets, adjacent, alive, vertex_tet, free, state, np.unique(tets[stubborn]), movable, mark, aim
            )
        logger.debug("sliver round %d: %d cells below the aim, %d changes", rounds, len(order), changes)
        if changes == 0:
            break
    # the slivers gone, flips alone raise the poorest cells further (they move no point, nor the boundary)
    flips = _flips_toward(points, tets, adjacent, alive, vertex_tet, free, state, _aim(FLIP_AIM))
    logger.debug("flips toward %g degrees: %d changes", FLIP_AIM, flips)
    peel_outside()
    live = np.zeros(len(tets), dtype=bool)
    live[: state[0]] = alive[: state[0]]
    tets, adjacent = kept_cells(tets, adjacent, live)
    return points, tets, adjacent, rounds
