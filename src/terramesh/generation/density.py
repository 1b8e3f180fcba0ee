"""The vertex density of a mesh against a size function, for adapting a mesh to new sizes (2D and 3D).

What each vertex stands for (how many vertices of a mesh of the target size
its share of the cells would hold), which vertices may go or get company,
and the edges to split: the measures :func:`~.adapt.adapt_mesh` and the 3D
restart use to match an old mesh to new sizes before the forces settle it.
"""

import numpy as np

from ..mesh.columns import row_norms
from ..mesh.topology import any_corner_in, signed_areas, sorted_unique
from ..quality.tetra import tetra_volumes
from .levels import VOLUME_PER_VERTEX

THIN_BELOW = 0.6  # a vertex standing for fewer vertices of a mesh of the new size than this may go (size grew)...
FILL_ABOVE = 1.5  # ...for more than this, it gets company (size fell, less than a split takes)...
CHANGED_DENSITY = 0.1  # ...or, with the old sizes, beyond this fraction of one where the size changed
SPLIT_RATIO = 1.5  # an edge longer than this many sizes (the mean of its ends') gets a point in its middle...
MAX_DENSITY_ROUNDS = 10  # ...in rounds, each halving what is left
SIZE_CHANGE = 0.02  # with the old sizes given, a vertex whose size changed by no more than this stays...
FREE_RINGS = 2  # ...unless it is this many neighbours or fewer from one that did, or from a new point


def vertices_stood_for(points, cells, edges, on_boundary, target):
    """How many vertices of a mesh of size ``target`` each point stands for, averaged with its neighbours.

    A vertex's third of its cells' area (twice that on the boundary, where
    the cells lie on one side) over a mesh vertex's area at its size
    (``sqrt(3)/2 target**2``). One vertex's alone spreads 0.5-1.5 in a
    settled mesh; averaged, it stays within 0.6-1.48 (BP2004 at 2 Hz, 50k
    vertices; a disk 0.99-1.10). Tetrahedra: a quarter of the cells'
    volume over ``VOLUME_PER_VERTEX target**3``, the density the 3D
    generator seeds and keeps (it has no density control).
    """
    if cells.shape[1] == 4:
        measure, per_vertex = np.abs(tetra_volumes(points, cells)), VOLUME_PER_VERTEX * target**3
    else:
        measure, per_vertex = np.abs(signed_areas(points, cells)), np.sqrt(3.0) / 2.0 * target**2
    corners = cells.shape[1]
    share = np.bincount(cells.ravel(), np.repeat(measure / corners, corners), minlength=len(points))
    share[sorted_unique(edges[on_boundary])] *= 2.0
    stands_for = share / per_vertex
    first, second = edges[:, 0], edges[:, 1]
    neighbours = np.bincount(first, stands_for[second], minlength=len(points))
    neighbours += np.bincount(second, stands_for[first], minlength=len(points))
    degree = np.bincount(edges.ravel(), minlength=len(points))
    return (stands_for + neighbours) / (1.0 + degree)


def with_neighbours(mask, edges, rings):
    """``mask`` of points grown by ``rings`` rings of neighbours along ``edges`` (or cells: rows of any width)."""
    mask = mask.copy()
    for _ in range(rings):
        mask[edges[any_corner_in(mask, edges)].ravel()] = True
    return mask


def diffused(amount):
    """Indices picked by error diffusion of ``amount`` (each in [0, 1)) along the points' order.

    The points are in Hilbert order, so the count picked follows the amounts
    locally, with no randomness.
    """
    taken = np.floor(np.cumsum(amount))
    return np.flatnonzero(np.diff(taken, prepend=0.0) > 0)


def edge_ratios(points, edges, target):
    """Each edge's length over the mean size at its ends."""
    lengths = row_norms(points[edges[:, 0]] - points[edges[:, 1]])
    return lengths / (0.5 * (target[edges[:, 0]] + target[edges[:, 1]]))


def longest_edges(points, edges, target):
    """Index of each point's longest edge against the size (-1 for a point on none)."""
    order = np.argsort(edge_ratios(points, edges, target), kind="stable")
    rank = np.empty(len(edges), dtype=np.int64)
    rank[order] = np.arange(len(edges))
    best = np.full(len(points), -1, dtype=np.int64)
    np.maximum.at(best, edges[:, 0], rank)
    np.maximum.at(best, edges[:, 1], rank)
    return np.where(best >= 0, order[np.maximum(best, 0)], -1)


def edges_of(edges, vertices):
    """Indices of the edges touching any of ``vertices``."""
    touching = np.zeros(max(edges.max(initial=-1), np.max(vertices, initial=-1)) + 1, dtype=bool)
    touching[vertices] = True
    return np.flatnonzero(any_corner_in(touching, edges))
