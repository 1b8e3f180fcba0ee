"""Sharp edges of a 3D domain, sampled once by the size function and fixed as vertices.

The force equilibrium of :func:`~terramesh.generation.distmesh3d.generate_mesh_3d`
has no hold on a sharp edge (a box's twelve; of a CSG combination, the
operands' edges where they stay on its boundary and the edges it creates
where operands meet): points along them are placed here, spaced by the size
function, and kept fixed; before the final tetrahedralisation, free points
within the ball on a segment between two edge points (its diametral ball,
enlarged ``EDGE_BALL`` times) are dropped (:func:`sharp_edge_balls`,
:func:`encroaching_points`), so that the segment is an edge
of the cells.
"""

import numpy as np

from .fixed_points import spread_mask

EDGE_SAMPLING = 8  # samples per h0 along a sharp edge when its size function is integrated
EDGE_BALL = 1.25  # free points are kept this many half segment lengths from the middle of a sharp edge segment


def _sharp_edges(domain):
    """The domain's sharp edges as parametric curves (see ``Box.sharp_edges``, ``Union.sharp_edges``).

    A domain made of ``domains`` that reports none of its own: its operands'.
    """
    own = getattr(domain, "sharp_edges", None)
    if callable(own):
        return list(own())
    return [edge for operand in getattr(domain, "domains", ()) for edge in _sharp_edges(operand)]


def sharp_edge_chains(domain, size, h0):
    """Points along each of the domain's sharp edges, spaced by the size function, ends included; a list of (m, 3).

    See :func:`sampled_curves`.
    """
    return sampled_curves(_sharp_edges(domain), size, h0)


def sampled_curves(curves, size, h0, longest=None):
    """Points along each curve, spaced by the size function, ends included; a list of (m, dim) arrays.

    ``curves`` map parameters ``t`` in [0, 1] to points (2D or 3D). Each
    gets ``round(integral of ds / h)`` segments (at least one, and with
    ``longest`` none longer than that many sizes) of equal integral: the
    trapezoidal rule on EDGE_SAMPLING points per h0 of length. A curve
    marked ``closed`` (a circle) repeats its first point at the end; one of
    fewer than three segments is left out, as no three points can hold it.
    """
    edges = list(curves)
    if not edges:
        return []
    params, dense = [], []
    for curve in edges:
        coarse = curve(np.linspace(0.0, 1.0, 65))
        length = float(np.sum(np.sqrt(np.sum(np.diff(coarse, axis=0) ** 2, axis=1))))
        t = np.linspace(0.0, 1.0, int(np.clip(np.ceil(EDGE_SAMPLING * length / h0), 64, 1 << 16)) + 1)
        params.append(t)
        dense.append(curve(t))
    density = 1.0 / size(np.concatenate(dense))
    chains, start = [], 0
    for curve, t, points in zip(edges, params, dense, strict=True):
        w = density[start : start + len(t)]
        start += len(t)
        steps = np.sqrt(np.sum(np.diff(points, axis=0) ** 2, axis=1))
        cumulative = np.concatenate([[0.0], np.cumsum(steps * 0.5 * (w[1:] + w[:-1]))])
        total = cumulative[-1]
        segments = max(1, int(round(total)), 0 if longest is None else int(np.ceil(total / longest)))
        closed = getattr(curve, "closed", False)
        if closed and segments < 3:
            continue
        targets = total * np.arange(segments + 1) / segments
        targets[-1] = total  # total * k / k missed it by a rounding: a box's edge ended 1e-12 short of its corner
        chain = curve(np.interp(targets, cumulative, t))
        if closed:
            chain[-1] = chain[0]
        chains.append(chain)
    return chains


def _sharp_edge_points(domain, size, h0, bbox, tolerance, chains=None):
    """Points along the domain's sharp edges, spaced by the size function, their ends left out; shape (k, 3).

    See :func:`sharp_edge_chains` (``chains``, if already made); a closed
    curve has no ends to leave out. Only the points on the domain's
    boundary are kept, and of points closer than half the local size to
    one another only the first.
    """
    if chains is None:
        chains = sharp_edge_chains(domain, size, h0)
    samples = [chain[:-1] if np.array_equal(chain[0], chain[-1]) else chain[1:-1] for chain in chains]
    samples = [sample for sample in samples if len(sample)]
    if not samples:
        return np.empty((0, 3))
    samples = np.concatenate(samples)
    samples = samples[np.all((samples >= bbox[0]) & (samples <= bbox[1]), axis=1)]
    samples = samples[np.abs(domain.distance(samples)) <= tolerance]
    return samples[spread_mask(samples, size)] if len(samples) else samples


def sharp_edge_balls(domain, chains, tolerance):
    """Centres and radii of the balls on the segments of the chains that lie on the boundary; (k, 3), (k,).

    A segment between consecutive edge points is an edge of the Delaunay
    tetrahedralisation when no other point lies in the ball it is the
    diameter of. A free point there (a point pushed close to the edge)
    lets cells bridge the edge: across a re-entrant edge they then cover
    part of the outside with their centroid inside.
    """
    if not chains:
        return np.empty((0, 3)), np.empty(0)
    starts = np.concatenate([chain[:-1] for chain in chains])
    ends = np.concatenate([chain[1:] for chain in chains])
    on = (np.abs(domain.distance(starts)) <= tolerance) & (np.abs(domain.distance(ends)) <= tolerance)
    centres = 0.5 * (starts[on] + ends[on])
    return centres, 0.5 * np.sqrt(np.sum((ends[on] - starts[on]) ** 2, axis=1))


def encroaching_points(points, n_fixed, centres, radii):
    """Mask of the points past the first ``n_fixed`` inside a ball of :func:`sharp_edge_balls` times ``EDGE_BALL``."""
    mask = np.zeros(len(points), dtype=bool)
    if len(centres) == 0 or len(points) == n_fixed:
        return mask
    from scipy.spatial import cKDTree

    inside = cKDTree(points[n_fixed:]).query_ball_point(centres, radii * (EDGE_BALL - 1e-9))
    hits = [index for ball in inside for index in ball]
    mask[n_fixed + np.asarray(hits, dtype=np.int64)] = True
    return mask


def with_sharp_edges(domain, size, h0, bbox, tolerance, points, n_fixed, chains=None):
    """``points`` with fixed points along the domain's sharp edges after the first ``n_fixed``; the new count.

    Force equilibrium has no hold on a sharp edge: a point there that any
    force pushes into one face's side is projected onto the other face, so
    edges lose their points and the final cells cut across them. Fixed
    points spaced by the size, as the corners are, keep the edges in the mesh.
    Edge points within half the local size of a fixed point, and lattice
    points within half the local size of an edge point, are left out.
    """
    edge, near = sharp_edge_points_among(domain, size, h0, bbox, tolerance, points[:n_fixed], points[n_fixed:], chains)
    if len(edge) == 0:
        return points, n_fixed
    return np.vstack([points[:n_fixed], edge, points[n_fixed:][~near]]), n_fixed + len(edge)


def sharp_edge_points_among(domain, size, h0, bbox, tolerance, fixed, free, chains=None):
    """The sharp edges' points among ``fixed`` and ``free`` points: ``(edge points, mask of the free they displace)``.

    Edge points within half the local size of a fixed point are left out;
    a free point within half the local size of an edge point is displaced.
    """
    from scipy.spatial import cKDTree

    edge = _sharp_edge_points(domain, size, h0, bbox, tolerance, chains)
    if len(fixed) and len(edge):
        edge = edge[cKDTree(fixed).query(edge)[0] >= 0.5 * size(edge)]
    if len(edge) == 0:
        return edge, np.zeros(len(free), dtype=bool)
    reach = 0.5 * size(edge)
    distance, nearest = cKDTree(edge).query(free, distance_upper_bound=float(reach.max()))
    return edge, distance < np.append(reach, 0.0)[nearest]  # nearest == len(edge) where none is within the bound
