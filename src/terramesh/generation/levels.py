"""Coarse-to-fine levels: a mesh at twice the size, its edges split, starts the next level.

Random thinning of a lattice (the initial points of DistMesh where the size
varies) leaves density noise at every wavelength, and the truss forces
smooth long wavelengths slowly: a graded disk of 10**5 vertices needs about
70 iterations. A mesh of the same domain at twice the size has four times
fewer points and costs a quarter per iteration; splitting each of its
edges at the midpoint gives four similar triangles per cell, a mesh for the
size asked that is nearly in equilibrium already, so the fine level stops
after a handful of iterations. Levels nest: the coarsest level alone starts
from random points.

A coarse level cannot hold a feature narrower than its size (a channel, an
islet); the fine level seeds such places afresh: lattice points near the
boundary (the only place a missed feature can be) that no refined point
covers are added.

In 3D a mesh at twice the size has eight times fewer points, and its
vertices with its edges' midpoints start the finer level (tetrahedralised
afresh: splitting a tetrahedron in eight leaves an octahedron whose
diagonal is a choice, and the generator triangulates anew anyway).
"""

import numbers

import numpy as np

from ..errors import GenerationError, warn_user
from .fixed_points import with_fixed_first
from .seeding import seed_points

__all__ = ["coarse_levels", "scaled", "refined_points", "uncovered_seeds", "regular_sample"]

MAX_LEVELS = 3  # most coarse levels in 2D (the coarsest has 64x fewer points than the mesh)
COARSEST_VERTICES = 2_000  # levels are added while the coarsest keeps at least about this many vertices...
BOUNDARY_SHARE = 0.12  # ...and at most this share of them on the boundary (2D)...
BOUNDARY_SHARE_3D = 0.4  # ...or this share in 3D, where a box of 2,000 vertices has 40 % on its faces
MAX_LEVELS_3D = 1  # refined twice, 214k vertices had 2,262 cells of radius ratio < 0.3, not 878
VOLUME_PER_VERTEX = 0.6125  # of a tetrahedral mesh of edge h, in h**3 (the seeds' lattice: 2 per cube of 1.07 h)
_SAMPLE_3D = 32  # sample points per axis for the 3D vertex-count estimate
FILL_BAND = 2.0  # a feature a coarse level misses lies within this many local sizes of the boundary...
COVERED = 0.8  # ...and a lattice point there farther than this many local sizes from every refined point is added
LEVEL_SAMPLES = 256  # sample points per axis for the vertex-count estimate (2D; the sizes' sample too)


def scaled(size, factor):
    """The size function ``size`` times ``factor``."""
    if factor == 1:
        return size
    return lambda points: factor * size(points)


def regular_sample(bbox, samples):
    """The points of a grid of ``samples`` points per axis over ``bbox`` (2, dim), shape ``(samples**dim, dim)``.

    In ``np.meshgrid(..., indexing="ij")`` order, filled axis by axis:
    ``np.meshgrid`` and ``np.stack`` took 1.0 ms of a 256² sample, this 0.04.

    Examples
    --------
    >>> import numpy as np
    >>> regular_sample(np.array([[0.0, 0.0], [1.0, 2.0]]), 2).tolist()
    [[0.0, 0.0], [0.0, 2.0], [1.0, 0.0], [1.0, 2.0]]
    """
    dim = bbox.shape[1]
    grid = np.empty((samples,) * dim + (dim,))
    for axis, (low, high) in enumerate(bbox.T):
        grid[..., axis] = np.linspace(low, high, samples).reshape([-1 if k == axis else 1 for k in range(dim)])
    return grid.reshape(-1, dim)


def coarse_levels(domain, size, bbox, sample=None):
    """Coarse levels for ``domain``: as many as keep the coarsest level large and its boundary short.

    From a regular sample of the bbox (256 x 256, or 32 x 32 x 32): the
    vertex count is the integral of ``1 / (sqrt(3)/2 size**2)`` over the
    domain (``1 / (VOLUME_PER_VERTEX size**3)`` in 3D), the boundary
    vertex count that of ``1 / size`` along the boundary (``2 / (sqrt(3)
    size**2)`` over its area in 3D), the sample points within half a
    spacing of it standing for the boundary. Each level has four (in 3D
    eight) times fewer vertices and twice the share on the boundary; a
    level is added while the coarsest keeps ``COARSEST_VERTICES`` and at
    most ``BOUNDARY_SHARE`` (``BOUNDARY_SHARE_3D``) of its vertices on the
    boundary, up to ``MAX_LEVELS`` (``MAX_LEVELS_3D``). A coastline is
    mostly boundary: a coarse level there misses the features its finer
    levels would have to seed, and refining its boundary gives a worse
    start than random points.

    ``sample``, the generator's :class:`~terramesh.generation.options.SizeSample`,
    brings the 2D sample's points, their distances and the sizes inside when
    it sampled this bbox (its ``bbox_points``): the same numbers without
    evaluating them again (1.8 ms of a 10⁴-vertex disk's 44 ms).
    """
    dim = bbox.shape[1]
    if dim == 2:
        samples, share, most = LEVEL_SAMPLES, BOUNDARY_SHARE, MAX_LEVELS
        per_vertex, per_boundary_vertex = np.sqrt(3.0) / 2.0, 1.0
    else:
        samples, share, most = _SAMPLE_3D, BOUNDARY_SHARE_3D, MAX_LEVELS_3D
        per_vertex, per_boundary_vertex = VOLUME_PER_VERTEX, np.sqrt(3.0) / 2.0
    cell = float(np.prod((bbox[1] - bbox[0]) / (samples - 1)))
    spacing = np.sqrt(cell) if dim == 2 else cell ** (1.0 / 3.0)
    if dim == 2 and sample is not None and sample.bbox_points is not None:
        # its distances are exact within two sample steps, more than the spacing / 2 compared with below
        points, distance, inside_sizes = sample.bbox_points, sample.bbox_distance, sample.sizes
    else:
        points = regular_sample(bbox, samples)
        distance = domain.distance_within(points, spacing)  # compared with 0 and spacing / 2 only
        inside_sizes = None
    inside = distance < 0
    if not inside.any():
        return 0
    if inside_sizes is None:
        inside_sizes = size(points[inside])
    vertices = cell * float(np.sum(1.0 / (per_vertex * inside_sizes**dim)))
    on_boundary = np.abs(distance) < 0.5 * spacing
    boundary = float(np.sum(1.0 / (per_boundary_vertex * size(points[on_boundary]) ** (dim - 1))))
    boundary_share = spacing ** (dim - 1) * boundary / vertices
    if not np.isfinite(vertices) or vertices <= COARSEST_VERTICES or boundary_share * 2 > share:
        return 0
    by_count = np.log(vertices / COARSEST_VERTICES) / np.log(2.0**dim)
    by_boundary = np.log(share / max(boundary_share, 1e-12)) / np.log(2.0)
    return int(min(most, np.floor(by_count), np.floor(by_boundary)))


def checked_levels(levels):
    """``levels`` as a non-negative int, or a GenerationError."""
    if isinstance(levels, bool) or not isinstance(levels, numbers.Integral) or levels < 0:
        raise GenerationError(f"levels must be a non-negative integer, got {levels!r}")
    return int(levels)


def refined_points(domain, points, edges, on_boundary, project, jitter=None):
    """Midpoints of ``edges``; those of boundary edges (``on_boundary``) moved onto the boundary by ``project``.

    ``project(points, distance)`` moves points onto the zero level set.
    ``jitter``, shape ``(len(edges), dim)``, moves each midpoint by that
    many of its edge's lengths before the projection.
    """
    middle = 0.5 * (points[edges[:, 0]] + points[edges[:, 1]])
    if jitter is not None:
        middle += np.sqrt(np.sum((points[edges[:, 1]] - points[edges[:, 0]]) ** 2, axis=1))[:, None] * jitter
    boundary = middle[on_boundary]
    middle[on_boundary] = project(boundary, domain.distance(boundary))
    return middle


def uncovered_seeds(domain, size, h0, bbox, seed, tolerance, nearest_distances, seeder=seed_points):
    """Lattice points within ``FILL_BAND`` sizes of the boundary that no point of the refined level covers.

    ``nearest_distances(seeds)`` gives each seed's distance to the nearest
    refined point (:meth:`Triangulation.nearest_distances`). A seed is
    covered when that is within ``COVERED`` times its size: in a mesh of
    that size every point of a cell is within ``1/sqrt(3)`` sizes of a
    vertex (in 3D, ``sqrt(3/8)``). ``seeder`` places the lattice points
    (:func:`~terramesh.generation.seeding.seed_points`, or the 3D
    ``bcc_seed_points``), taking ``band``.
    """
    seeds, _ = seeder(domain, size, h0, bbox, np.random.default_rng(seed), tolerance, band=FILL_BAND)
    if len(seeds) == 0:
        return seeds
    return seeds[nearest_distances(seeds) > COVERED * size(seeds)]


def level_start_points(domain, size, h0, bbox, fixed, seed, seeder, tolerance, warn_below_h0, scale=1.0):
    """The fixed points followed by the points ``seeder`` places (2D hexagonal or 3D BCC lattices).

    The lattice is ``scale`` times coarser and the sizes ``scale`` times
    larger than asked (a coarse level's seeds). With ``warn_below_h0``,
    sizes below h0 warn.
    """
    points, smallest = seeder(domain, scaled(size, scale), scale * h0, bbox, np.random.default_rng(seed), tolerance)
    if smallest < scale * h0 * (1 - 1e-9) and warn_below_h0:
        smallest = smallest / scale
        warn_user(
            f"edge_length goes down to {smallest:g}, below h0={h0:g}: the mesh will not be finer than h0",
        )
    return with_fixed_first(points, fixed, 0.5 * scale * h0)
