"""Nested hexagonal lattices: one level of the top-down thinning in one pass.

Lattice points are indices ``(i, j)`` of the finest lattice of spacing
``h0``: ``i * (h0, 0) + j * (h0 / 2, h0 * sqrt(3) / 2)`` from the lower-left
corner of the bbox; level ``L`` uses the points whose indices are multiples
of ``2**L``.
"""

import math

import numba
import numpy as np

_SQRT3_2 = np.sqrt(3.0) / 2.0


@numba.njit(cache=True)
def lattice_points(indices, corner, h0, low, high):
    """Coordinates of lattice ``indices`` and whether each lies in the box ``[low, high]`` (inclusive)."""
    n = indices.shape[0]
    points = np.empty((n, 2))
    in_box = np.empty(n, dtype=np.bool_)
    for k in range(n):
        x = corner[0] + h0 * (indices[k, 0] + 0.5 * indices[k, 1])
        y = corner[1] + h0 * _SQRT3_2 * indices[k, 1]
        points[k, 0] = x
        points[k, 1] = y
        in_box[k] = low[0] <= x <= high[0] and low[1] <= y <= high[1]
    return points, in_box


@numba.njit(cache=True, inline="always")
def _uniform(i, j, salt):
    """A uniform number in [0, 1) from a lattice point's indices and the seed (SplitMix64).

    Depends only on the point and the seed, not on the order points are visited.
    """
    z = (np.uint64(i) << np.uint64(32)) ^ np.uint64(j) ^ salt
    z = z + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return np.float64(z >> np.uint64(11)) / 9007199254740992.0  # 2**53


@numba.njit(cache=True)
def near_points(indices, points, distance, limit):
    """The lattice points with ``distance < limit``: their indices, coordinates and distances, in order."""
    count = 0
    for k in range(distance.shape[0]):
        if distance[k] < limit:
            count += 1
    near_indices = np.empty((count, 2), dtype=np.int64)
    near = np.empty((count, 2))
    near_distance = np.empty(count)
    count = 0
    for k in range(distance.shape[0]):
        if distance[k] < limit:  # element by element: a row assignment compiles numba's shape checks
            for d in range(2):
                near_indices[count, d] = indices[k, d]
                near[count, d] = points[k, d]
            near_distance[count] = distance[k]
            count += 1
    return near_indices, near, near_distance


@numba.njit(cache=True, inline="always")
def _before(ai, aj, bi, bj):
    """Whether lattice point ``(ai, aj)`` comes before ``(bi, bj)`` (by ``i``, then ``j``)."""
    return ai < bi or (ai == bi and aj < bj)


@numba.njit(cache=True)
def thin_level(indices, distance, target, level, top, h0, inside_tolerance, band, salt, j_max):
    """Which lattice points of level ``level`` to keep, and the next finer level's points to look at.

    ``indices`` are the level's points near the domain, sorted by ``i``
    then ``j``; ``distance`` their signed distances, ``target`` their
    sizes. A point is kept where its size falls in this level's octave
    (``[2**level, 2**(level+1)) * h0``; the top level takes every larger
    size too), it is inside, and its uniform number is below ``(2**level *
    h0 / target)**2``: the density asked. The finer level looks only
    around points whose size is below twice this level's spacing (sizes
    change less than that within a spacing), at the nine points of the
    finer lattice around each. With ``band >= 0`` only points within
    ``band`` sizes of the boundary are kept, and none deeper than a finer
    point of the band could be looked at.

    Returns ``(keep (n,) bool, smallest size inside, children (k, 2) int64)``,
    the children each once, sorted like ``indices``.
    """
    spacing = (1 << level) * h0
    half = (1 << level) // 2
    n = indices.shape[0]
    keep = np.zeros(n, dtype=np.bool_)
    smallest = np.inf
    # children by column offset: each of the three runs is sorted, as the parents are
    runs = np.empty((3, 3 * n if level > 0 else 0, 2), dtype=np.int64)
    lengths = np.zeros(3, dtype=np.int64)
    for k in range(n):
        d = distance[k]
        size = target[k]
        if band >= 0.0 and not d > -(2.0 * band * size + 2.0 * spacing):
            continue  # deep inside: no point of the band below it
        inside = d < inside_tolerance
        if inside and size < smallest:
            smallest = size
        own_level = math.frexp(max(size / h0, 1.0))[1] - 1  # floor(log2), exactly
        at_level = own_level == level or (level == top and own_level >= top)
        if at_level and inside and (band < 0.0 or d > -band * size):
            keep[k] = _uniform(indices[k, 0], indices[k, 1], salt) < (spacing / size) ** 2
        if level > 0 and size < 2.0 * spacing:
            for r in range(3):
                for dj in (-half, 0, half):
                    j = indices[k, 1] + dj
                    if 0 <= j <= j_max:
                        runs[r, lengths[r], 0] = indices[k, 0] + (r - 1) * half
                        runs[r, lengths[r], 1] = j
                        lengths[r] += 1
    # merge the three runs, each finer point once (neighbouring parents share children)
    children = np.empty((lengths.sum(), 2), dtype=np.int64)
    a = b = c = 0
    count = 0
    while a < lengths[0] or b < lengths[1] or c < lengths[2]:
        best = -1
        bi = bj = 0
        if a < lengths[0]:
            best, bi, bj = 0, runs[0, a, 0], runs[0, a, 1]
        if b < lengths[1] and (best < 0 or _before(runs[1, b, 0], runs[1, b, 1], bi, bj)):
            best, bi, bj = 1, runs[1, b, 0], runs[1, b, 1]
        if c < lengths[2] and (best < 0 or _before(runs[2, c, 0], runs[2, c, 1], bi, bj)):
            best, bi, bj = 2, runs[2, c, 0], runs[2, c, 1]
        if best == 0:
            a += 1
        elif best == 1:
            b += 1
        else:
            c += 1
        if count == 0 or children[count - 1, 0] != bi or children[count - 1, 1] != bj:
            children[count, 0] = bi
            children[count, 1] = bj
            count += 1
    return keep, smallest, children[:count]
