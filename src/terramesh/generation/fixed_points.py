"""Fixed points: the user's, checked, the domain's corners, spread out, and the warnings about both.

Fixed points are vertices that never move; they come first in the point
array. The domain's sharp corners are fixed too, less those within
``CORNER_REACH`` local sizes of a given point or of each other.
"""

import numpy as np

from ..errors import GenerationError, point_text, warn_user
from ..mesh.topology import checked_fixed_points

CORNER_REACH = 0.5  # a domain corner this many local sizes from a given fixed point or an earlier corner is not fixed
REFLEX_EDGES = 1.0  # a polygon's gentle reflex corner is fixed where both its edges are at least this many sizes long
# warnings' words, by which the generators that add fixed points of their own (meshing in strips, its cuts'
# points; an anisotropic start, its metric's corners) mute them and ask the user's points alone
FIXED_NEAR_BOUNDARY = "fixed points lie less than half a size inside the boundary"
CORNERS_DISPLACED = "of the domain's corners are no vertices, being within half a size of a fixed point"


def spread_mask(points, size):
    """Mask of the ``points`` to keep: the later of each pair closer than half the larger of their sizes goes.

    A chain of close points keeps its first. A pair exactly half a size
    apart counts as close (to a millionth): points a fine edge apart, half
    a coarse level's size, went or stayed by rounding.
    """
    from scipy.spatial import cKDTree

    keep = np.ones(len(points), dtype=bool)
    if len(points) < 2:
        return keep
    reach = (0.5 + 5e-7) * size(points)
    pairs = cKDTree(points).query_pairs(float(reach.max()), output_type="ndarray")
    if len(pairs):
        close = np.linalg.norm(points[pairs[:, 0]] - points[pairs[:, 1]], axis=1) < np.maximum(
            reach[pairs[:, 0]], reach[pairs[:, 1]]
        )
        keep[pairs[close].max(axis=1)] = False
    return keep


def spread_corners(corners, given, size):
    """The domain's corners, less those within ``CORNER_REACH`` local sizes of a given point or an earlier corner.

    A coastline resampled near the mesh size has sharp vertices a fraction of
    an element apart; fixing both would pin a sliver pair between them.
    """
    if len(corners) == 0:
        return corners
    keep = spread_mask(corners, size)
    if len(given):
        from scipy.spatial import cKDTree

        keep &= cKDTree(given).query(corners)[0] >= CORNER_REACH * size(corners)
    return corners[keep]


def _corners_in(domain, bbox, size):
    """The domain's corners within ``bbox`` (shape (2, dim)), those a rounding outside moved onto it; shape (k, dim).

    A grid's axes end a rounding past the values given (``linspace(-0.7,
    0, 71)`` at 1.1e-16): a gridded block cut by a box at z = 0 had its
    four top corners there, outside the combination's bbox, and lost them.
    A polygon's gentle reflex corners count where both their edges are
    ``REFLEX_EDGES`` local sizes long or more (a coastline's wiggles, shorter,
    are bridged by design).
    """
    corners = np.asarray(domain.corners(), dtype=np.float64).reshape(-1, bbox.shape[1])
    if hasattr(domain, "gentle_reflex_corners"):
        gentle, shorter_edge = domain.gentle_reflex_corners()
        if len(gentle):
            corners = np.vstack([corners, gentle[shorter_edge >= REFLEX_EDGES * size(gentle)]])
    rounding = 1e-9 * float(np.max(bbox[1] - bbox[0]))
    corners = corners[np.all((corners >= bbox[0] - rounding) & (corners <= bbox[1] + rounding), axis=1)]
    return np.clip(corners, bbox[0], bbox[1])


def validated_fixed_points(fixed_points, domain, bbox, tolerance, size):
    """The user's fixed points, checked, and the domain's corners (spread out); 2D or 3D."""
    dim = bbox.shape[1]
    corners = _corners_in(domain, bbox, size)
    if fixed_points is None:
        return spread_corners(corners, np.empty((0, dim)), size)
    fixed = checked_fixed_points(fixed_points, dim, GenerationError)
    distance = domain.distance(fixed)
    outside = distance > tolerance
    if outside.any():
        raise GenerationError(
            f"{int(outside.sum())} fixed points lie outside the domain, e.g. {fixed[outside][0].tolist()}"
        )
    _warn_of_crowding(domain, fixed, distance, corners, tolerance, size)
    fixed = np.unique(np.vstack([fixed, spread_corners(corners, fixed, size)]), axis=0)
    return _merged_fixed_points(fixed, tolerance)


TURN_SAMPLES = 12  # directions about a corner in which the distance is sampled (in 3D the 26 of a cube's)...
TURN_RADIUS = 0.25  # ...this many local sizes out; the boundary turns there where the distance is not linear...
TURN_RESIDUAL = 0.01  # ...within this share of the radius (a polygon's vertex turning by 1 degree: about 0.009)
_ANGLES = 2.0 * np.pi * np.arange(TURN_SAMPLES) / TURN_SAMPLES
_CUBE = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1) if (i, j, k) != (0, 0, 0)])
# symmetric under the axes' swaps and flips, so each set's Gram matrix is (its size / dim) I
_TURN_DIRECTIONS = {
    2: np.stack([np.cos(_ANGLES), np.sin(_ANGLES)], axis=1),
    3: _CUBE / np.linalg.norm(_CUBE, axis=1)[:, None],
}


def turning_mask(domain, size, corners):
    """Mask of the ``corners`` where the boundary turns: the signed distance about them is not linear.

    It is sampled in ``TURN_SAMPLES`` directions (in 3D, 26) ``TURN_RADIUS``
    sizes out and fitted by the half-plane's (half-space's) linear function.
    """
    if len(corners) == 0:
        return np.zeros(0, dtype=bool)
    dim = corners.shape[1]
    directions = _TURN_DIRECTIONS[dim]
    radius = TURN_RADIUS * size(corners)
    distance = domain.distance((corners[:, None, :] + radius[:, None, None] * directions).reshape(-1, dim))
    distance = distance.reshape(len(corners), len(directions)) / radius[:, None]
    gradient = distance @ directions / (len(directions) / dim)  # least squares, the Gram matrix being n/dim I
    return np.max(np.abs(distance - gradient @ directions.T), axis=1) > TURN_RESIDUAL


def _warn_of_crowding(domain, fixed, distance, corners, tolerance, size):
    """Warn of ``fixed`` points less than ``CORNER_REACH`` sizes inside the boundary, and of the corners they displace.

    Neither the boundary nor the point can move: in a unit square at h 0.1
    a gauge 0.005 inside became a boundary vertex 0.005 off the boundary
    (the thin cells between went), one 0.01-0.03 inside left cells of q
    0.17-0.48; a corner within half a size of a fixed point is no vertex,
    and the cells cut across it, where the boundary turns there
    (:func:`turning_mask`: a model box's side nodes are on straight sides).
    """
    near = fixed_near_boundary_words(fixed, distance, size, tolerance)
    if near:
        warn_user(
            f"{near}: the cells between them and the boundary are poor, or go and leave a notch; move such points "
            "onto the boundary or half a size in"
        )
    if len(corners) == 0:
        return
    from scipy.spatial import cKDTree

    # a corner given as a fixed point displaces the others near it as the generator's own spreading would
    others = fixed[cKDTree(corners).query(fixed)[0] > tolerance]
    if len(others) == 0:
        return
    gap = cKDTree(others).query(corners)[0]
    displaced = corners[(gap > tolerance) & (gap < CORNER_REACH * size(corners))]
    displaced = displaced[turning_mask(domain, size, displaced)]
    if len(displaced):
        warn_user(
            f"{len(displaced)} {CORNERS_DISPLACED}, e.g. {point_text(displaced[0])}: the cells cut across them; move "
            "such points onto the corner or half a size from it"
        )


def fixed_near_boundary_words(fixed, distance, size, tolerance):
    """Words naming the ``fixed`` points (at ``distance``) less than ``CORNER_REACH`` sizes inside, or ``""``."""
    near = np.flatnonzero((distance < -tolerance) & (distance > -CORNER_REACH * size(fixed)))
    if len(near) == 0:
        return ""
    first = near[np.argmax(distance[near])]
    depth = -distance[first] / size(fixed[first : first + 1])[0]
    return f"{len(near)} {FIXED_NEAR_BOUNDARY}, e.g. {point_text(fixed[first])}, {depth:.2g} sizes in"


def warn_if_fixed_points_crowd_the_boundary(domain, fixed_points, size, tolerance):
    """:func:`_warn_of_crowding` for the (checked) ``fixed_points`` alone, shape (k, dim).

    For a generator that adds fixed points of its own (an anisotropic start,
    the metric's corners) and mutes the check of its run.
    """
    fixed = np.asarray(fixed_points, dtype=np.float64).reshape(-1, domain.dim)
    if len(fixed) == 0:
        return
    corners = _corners_in(domain, np.asarray(domain.bbox, dtype=np.float64), size)
    _warn_of_crowding(domain, fixed, domain.distance(fixed), corners, tolerance, size)


def _merged_fixed_points(fixed, tolerance):
    """``fixed`` without the points within ``tolerance`` of an earlier one, with a warning if any went.

    Two fixed points 1e-9 apart gave a mesh with a hole a quarter of the
    domain, and the boundary tolerance (1e-3 h0) cannot tell them apart.
    """
    from scipy.spatial import cKDTree

    pairs = cKDTree(fixed).query_pairs(tolerance, output_type="ndarray")
    if len(pairs) == 0:
        return fixed
    later = np.unique(pairs.max(axis=1))
    warn_user(
        f"{len(later)} fixed points lie within {tolerance:.3g} (1e-3 h0) of another one, e.g. "
        f"{fixed[later[0]].tolist()}: each is merged with the first of them",
    )
    return np.delete(fixed, later, axis=0)


def with_fixed_first(points, fixed, reach):
    """The ``fixed`` points followed by those of ``points`` farther than ``reach`` from all of them."""
    if len(fixed) == 0:
        return points
    return np.vstack([fixed, points[beyond_fixed(points, fixed, reach)]])


def beyond_fixed(points, fixed, reach):
    """Mask of the ``points`` farther than ``reach`` from every one of ``fixed``."""
    if len(fixed) == 0:
        return np.ones(len(points), dtype=bool)
    from scipy.spatial import cKDTree

    return cKDTree(fixed).query(points, distance_upper_bound=reach)[0] == np.inf
