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

from ..errors import GenerationError
from .seeding import seed_points

__all__ = ["coarse_levels", "coarse_levels_3d", "scaled", "refined_points", "uncovered_seeds"]

MAX_LEVELS = 3  # most coarse levels (the coarsest has 64x fewer points than the mesh in 2D, 512x in 3D)
COARSEST_VERTICES = 2_000  # levels are added while the coarsest keeps at least about this many vertices...
BOUNDARY_SHARE = 0.12  # ...and at most this share of them on the boundary (2D)...
BOUNDARY_SHARE_3D = 0.4  # ...or this share in 3D, where a box of 2,000 vertices has 40 % on its faces
MAX_LEVELS_3D = 1  # refined twice, 214k vertices had 2,262 cells of radius ratio < 0.3, not 878
VOLUME_PER_VERTEX = 0.6125  # of a tetrahedral mesh of edge h, in h**3 (the seeds' lattice: 2 per cube of 1.07 h)
_SAMPLE_3D = 32  # sample points per axis for the 3D vertex-count estimate
FILL_BAND = 2.0  # a feature a coarse level misses lies within this many local sizes of the boundary...
COVERED = 0.8  # ...and a lattice point there farther than this many local sizes from every refined point is added
_SAMPLE = 256  # sample points per axis for the vertex-count estimate


def scaled(size, factor):
    """The size function ``size`` times ``factor``."""
    if factor == 1:
        return size
    return lambda points: factor * size(points)


def coarse_levels(domain, size, bbox):
    """Coarse levels for ``domain``: as many as keep the coarsest level large and its boundary short, at most 3.

    From a 256 x 256 sample of the bbox: the vertex count is the integral
    of ``1 / (sqrt(3)/2 size**2)`` over the domain, the boundary vertex
    count that of ``1 / size`` along the boundary (the sample points within
    half a spacing of it). Each level has four times fewer vertices and
    twice the share on the boundary; a level is added while the coarsest
    keeps ``COARSEST_VERTICES`` and at most ``BOUNDARY_SHARE`` of its
    vertices on the boundary. A coastline is mostly boundary: a coarse
    level there misses the features its finer levels would have to seed,
    and refining its boundary gives a worse start than random points.
    """
    axes = [np.linspace(low, high, _SAMPLE) for low, high in bbox.T]
    sample = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
    cell_area = float(np.prod((bbox[1] - bbox[0]) / (_SAMPLE - 1)))
    spacing = np.sqrt(cell_area)
    distance = domain.distance_within(sample, spacing)  # compared with 0 and spacing / 2 only
    inside = distance < 0
    if not inside.any():
        return 0
    vertices = cell_area * float(np.sum(1.0 / (np.sqrt(3.0) / 2.0 * size(sample[inside]) ** 2)))
    on_boundary = np.abs(distance) < 0.5 * spacing
    boundary_share = spacing * float(np.sum(1.0 / size(sample[on_boundary]))) / vertices
    if not np.isfinite(vertices) or vertices <= COARSEST_VERTICES or boundary_share * 2 > BOUNDARY_SHARE:
        return 0
    by_count = np.log(vertices / COARSEST_VERTICES) / np.log(4.0)
    by_boundary = np.log(BOUNDARY_SHARE / max(boundary_share, 1e-12)) / np.log(2.0)
    return int(min(MAX_LEVELS, np.floor(by_count), np.floor(by_boundary)))


def coarse_levels_3d(domain, size, bbox):
    """Coarse levels for a 3D ``domain``, 0 or 1: as :func:`coarse_levels`, a level with eight times fewer vertices.

    From a 32 x 32 x 32 sample of the bbox: the vertex count is the
    integral of ``1 / (VOLUME_PER_VERTEX size**3)`` over the domain, the
    boundary's that of ``2 / (sqrt(3) size**2)`` over its area (the sample
    points within half a spacing of it, each standing for a spacing squared).
    A level is added while the coarsest keeps ``COARSEST_VERTICES`` and at
    most ``BOUNDARY_SHARE_3D`` of them on the boundary. A feature thinner
    than a coarse level's size is seeded again at the fine level
    (:func:`uncovered_seeds`).
    """
    axes = [np.linspace(low, high, _SAMPLE_3D) for low, high in bbox.T]
    sample = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    spacing = float(np.prod((bbox[1] - bbox[0]) / (_SAMPLE_3D - 1))) ** (1.0 / 3.0)
    distance = domain.distance_within(sample, spacing)  # compared with 0 and spacing / 2 only
    inside = distance < 0
    if not inside.any():
        return 0
    vertices = spacing**3 * float(np.sum(1.0 / (VOLUME_PER_VERTEX * size(sample[inside]) ** 3)))
    on_boundary = np.abs(distance) < 0.5 * spacing
    boundary_share = spacing**2 * float(np.sum(2.0 / (np.sqrt(3.0) * size(sample[on_boundary]) ** 2))) / vertices
    if not np.isfinite(vertices) or vertices <= 8 * COARSEST_VERTICES or boundary_share * 2 > BOUNDARY_SHARE_3D:
        return 0
    by_count = np.log(vertices / COARSEST_VERTICES) / np.log(8.0)
    by_boundary = np.log(BOUNDARY_SHARE_3D / max(boundary_share, 1e-12)) / np.log(2.0)
    return int(min(MAX_LEVELS_3D, np.floor(by_count), np.floor(by_boundary)))


def checked_levels(levels):
    """``levels`` as a non-negative int, or a GenerationError."""
    if isinstance(levels, bool) or not isinstance(levels, numbers.Integral) or levels < 0:
        raise GenerationError(f"levels must be a non-negative integer, got {levels!r}")
    return int(levels)


def refined_points(domain, points, edges, on_boundary, project):
    """Midpoints of ``edges``; those of boundary edges (``on_boundary``) moved onto the boundary by ``project``.

    ``project(points, distance)`` moves points onto the zero level set.
    """
    middle = 0.5 * (points[edges[:, 0]] + points[edges[:, 1]])
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
