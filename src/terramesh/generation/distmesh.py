"""The force-equilibrium mesh generator (Persson & Strang 2004), 2D.

One screen: seed points by the size function, triangulate, push points along
truss forces, project escaped points back onto the boundary, retriangulate
when points have moved far enough, stop when they stop moving (or the
quality stops improving); then triangulate once more, make the result valid
and smooth it without lowering any cell's worst quality.
"""

import logging
import numbers
import time
import weakref
from typing import NamedTuple

import numpy as np

from .._kernels import physical_memory, threads_for
from .._kernels.chunks import CHUNKS
from .._kernels.forces import (
    count_far,
    force_step,
    largest_interior_move,
    neighbor_lists,
    rest_length_scale,
    short_edge_ends,
    stale_distances,
    sweep_step,
)
from .._kernels.precompile import compile_ahead_on_first_run
from .._kernels.smoothing import move_where_better, raise_worst, smooth_interior
from .._kernels.topology import (
    cell_centroids,
    classify_cells,
    inner_cell_edges,
    quality_mean_std,
    rows_renumbered,
    same_rows,
    subset,
    table_boundary_edges,
    triangle_qualities,
)
from ..cleanup.fix_mesh import delete_interior_cells, delete_interior_cells_with_table, remove_unused_points
from ..cleanup.validity import _overlap_problems, cells_of_edges, crossing_edges, hanging_on_boundary
from ..errors import GenerationError, SizingError, checked_number, warn_user
from ..geometry.base import as_bbox, as_domain, distance_gradient
from ..mesh.columns import bounds, row_norms
from ..mesh.mesh import Mesh
from ..mesh.topology import (
    all_corners_in,
    any_corner_in,
    boundary_edges,
    checked_fixed_points,
    coincident_points,
    lowest_twins,
    signed_areas,
    sorted_unique,
    without_rows,
)
from ..quality.tetra import tetra_volumes
from ..sizing.edge_length import ConstantSize, as_size_function
from ..sizing.grid import SizeGrid
from .corners import recover_corners
from .levels import (
    LEVEL_SAMPLES,
    checked_levels,
    coarse_levels,
    refined_points,
    regular_sample,
    scaled,
    uncovered_seeds,
)
from .seeding import seed_points
from .triangulate import Triangulation

__all__ = ["generate_mesh"]

logger = logging.getLogger("terramesh.generation")

TIME_STEP = 0.3  # fraction of the net force a point moves per iteration (all points at once)...
RELAXATION = 0.5  # ...or, in a Gauss-Seidel sweep at the coarsest level, one after the other...
BOUNDARY_RELAXATION = 0.3  # ...and a point projected in the last iteration, along the boundary
LENGTH_FACTOR = 1.15  # rest lengths exceed actual ones, so springs push (Persson & Strang)
RETRIANGULATE_AFTER = 0.1  # move since the last triangulation, in local edge lengths, that makes a point stale
MAX_SETTLE_ROUNDS = 5  # times generation may thin crowded points and go on instead of stopping
SETTLE_ITERATIONS = 10  # iterations after such a round before generation may stop again...
TOUCH_UP = 4  # ...or, after a round that moved at most this many points...
TOUCH_UP_ITERATIONS = 3  # ...this many, and a final stop
STALE_ALLOWED = 0.002  # fraction of stale points tolerated before triangulating again in sweeps...
STALE_ALLOWED_STEPPED = 0.03  # ...and in simultaneous steps (one level, refined levels), see _relax
BOUNDARY_TOLERANCE = 1e-3  # inside/outside and on-boundary tolerance, in units of h0
GAP_RATIO = 1.3  # a boundary edge longer than this many local sizes gets a point in its middle
SPLIT_RATIO = 1.3  # an edge shorter than this many of the finer level's sizes gets no midpoint at refinement
FLAT_QUALITY = 0.3  # a final cell below this quality hugging the boundary is dropped
NEAR_BOUNDARY = 0.1  # ...where all its vertices are this close to it, in local sizes
ACUTE_CORNER = 30.0  # degrees: a fixed point whose flat cells meet at less is a sharp corner of the domain, kept
DEGENERATE_QUALITY = 1e-6  # a final cell below this quality is flat to rounding and goes wherever it is
STALL_WINDOW = 20  # iterations in which the best mean - 3 std of the quality must improve...
SWEPT_STALL_WINDOW = 10  # ...or this many where Gauss-Seidel sweeps move the points (they anneal sooner)...
REFINED_STALL_WINDOW = 5  # ...or this many at a level started from a refined coarser mesh (nearly in equilibrium)
STALL_GAIN = 1e-2  # ...by at least this much, or generation stops as stalled (the final smoothing does the rest)
LAZY_BAND = 0.1  # a point that may have come within this many local sizes of the boundary gets its distance again
DISTANCE_SLACK = 0.02  # relative error allowed to a distance far from the boundary (a polygon's is within 1 %)
DISTANCE_REACH = 8.0  # smallest sizes: distances are exact within this of the boundary, bounds farther in
COARSEST_LEAST = 100  # a coarse level is meshed only with at least this many points (see _coarsest_points)
MAX_REPAIR_PASSES = 10  # rounds of boundary repair and projection in the final clean-up
HOLE_OFF = 0.5  # sizes off the boundary beyond which a boundary vertex left by the repair is a hole, refused
POLISH_PASSES = 3  # passes of quality-safe Laplacian smoothing of the interior vertices after generation...
POOR_QUALITY = 0.8  # ...then of moving the vertices of cells below this quality to where their worst cell is best
DENSITY_CONTROL_EVERY = 10  # iterations between removals of crowded points (Persson 2005)
BYTES_PER_VERTEX = {2: 420, 3: 2000}  # peak memory per vertex: 6.0 GB at 14.5M (2D); 3D a bound, not measured
COVERED = (0.5, 1.25)  # fractions of the domain's sampled area the cells may cover without a warning
TIGHT_SAMPLE_SHARE = 1 / 16  # a domain on fewer of the bbox's sample points is sampled again over its own box
TWIN_REACH = 0.25  # a projected boundary vertex this many local sizes from its boundary neighbour merges into it
CORNER_REACH = 0.5  # a domain corner this many local sizes from a given fixed point or an earlier corner is not fixed
_NO_BOUND = np.empty(0)  # no bound on the distances (plain callables, points changed): every cell is evaluated
_NO_INDICES = np.empty(0, dtype=np.int64)
_NO_POINTS = np.empty((0, 2))


def _finite_difference_step(h0, bbox):
    """Step of the finite differences of the distance function for the Newton projections.

    The distance carries a rounding error of eps times the coordinates
    (large in UTM or Mercator metres) and a truncation error of the step over
    the boundary's curvature radius (about h0 or more); this step balances
    the two. (``sqrt(eps) h0``, the 2D step before, left a disk cut from a
    rectangle at an offset of 1e7 with h0 = 0.01 with its boundary vertices
    a size off the boundary: the difference of two distances there was
    rounding alone.)
    """
    return float(np.sqrt(np.finfo(float).eps * h0 * max(h0, float(np.abs(bbox).max()))))


class SizeSample(NamedTuple):
    """A regular sample of the sizes over the domain (:func:`_size_sample`)."""

    inside: np.ndarray  # the sample points inside the domain, (k, dim)
    sizes: np.ndarray  # their sizes, (k,)
    share: float  # the area (or volume) each sample point stands for
    near: np.ndarray  # the sample points within a sample step of the boundary...
    near_distance: np.ndarray  # ...and their signed distances
    bbox_points: np.ndarray | None  # all the points of the bbox's own sample (2D: 256²), None if sampled again...
    bbox_distance: np.ndarray | None  # ...and their signed distances, exact within two sample steps


def _size_sample(size, domain, bbox):
    """A regular sample of the bbox (256² or 64³): the points inside the domain and their sizes.

    A domain that fills little of a generous bbox (the unit disk in a bbox
    of +-100: 5 sample points inside, an area of 2.44) is sampled again
    over the box around its points, so that its area, its smallest size
    and the checks of the mesh against its sizes stand on as many points
    as a snug bbox gives. Otherwise the bbox's sample is kept, for the
    choice of coarse levels (:func:`~terramesh.generation.levels.coarse_levels`).
    """
    inside, distance, sample, share, step = _sampled(domain, bbox)
    bbox_points, bbox_distance = sample, distance
    if 0 < len(inside) < TIGHT_SAMPLE_SHARE * len(sample):
        low, high = bounds(inside)
        low, high = np.maximum(low - 2.0 * step, bbox[0]), np.minimum(high + 2.0 * step, bbox[1])
        inside, distance, sample, share, step = _sampled(domain, np.array([low, high]), check_cut=False)
        bbox_points = bbox_distance = None
    near = np.abs(distance) < step
    sizes = np.asarray(size(inside), dtype=np.float64)
    return SizeSample(inside, sizes, share, sample[near], distance[near], bbox_points, bbox_distance)


def _sampled(domain, bbox, check_cut=True):
    """The regular sample of ``bbox``: its points inside, the distances and points, each point's share and the step."""
    dim = bbox.shape[1]
    samples = LEVEL_SAMPLES if dim == 2 else 64
    shape = (samples,) * dim
    sample = regular_sample(bbox, samples)
    share = float(np.prod(bbox[1] - bbox[0])) / len(sample)
    step = float(max(np.linspace(low, high, samples)[1] - low for low, high in bbox.T))  # the sample's own step
    # only the sign and the distances near the boundary are wanted: a coastline's exact distances took
    # 0.13 s here, the bounded ones a tenth
    distance = domain.distance_within(sample, 2.0 * step)
    # DistMesh meshes a domain inside its bbox; one cut by it was meshed past the bbox, cells bridging
    on_faces = np.zeros(shape, dtype=bool)
    for axis in range(dim):
        on_faces[(slice(None),) * axis + (0,)] = on_faces[(slice(None),) * axis + (-1,)] = True
    cut = on_faces.ravel() & (distance < -step)
    if check_cut and cut.any():
        where = ", ".join(f"{v:.6g}" for v in sample[np.flatnonzero(cut)[0]])
        raise GenerationError(
            f"the domain reaches out of the bbox {bbox.tolist()} (inside at ({where}) on its side): give a bbox"
            " that contains the domain, or intersect the domain with a box (tm.geometry.Intersection)"
        )
    # np.compress, not a boolean index: NumPy 2.4 indexes the rows of an (n, 2) array 10x slower
    return np.compress(distance < 0, sample, axis=0), distance, sample, share, step


def _smallest_size(size, domain, sample):
    """Smallest edge length requested in the domain, from ``sample`` (:func:`_size_sample`) for a callable.

    The sample's points near the boundary are projected onto it and their
    sizes taken too: a size graded from the boundary is smallest there,
    where the inside points miss it by up to a sample step times its
    gradient (64³ on a 2-unit box graded at 0.5: h0 0.056 for 0.04, and the
    boundary's edges 1.5 sizes long).
    """
    if isinstance(size, SizeGrid):
        return float(size.values.min())
    if isinstance(size, ConstantSize):
        return float(size.value)
    inside, sizes, share = sample.inside, sample.sizes, sample.share
    near, near_distance = sample.near, sample.near_distance
    if len(inside) == 0:
        raise GenerationError(
            "no sample point of the bbox is inside the domain: the bbox misses it, or the domain is empty or "
            "thinner than the sample; give h0"
        )
    smallest = float(sizes.min())
    if len(near):
        step = 1e-3 * share ** (1.0 / inside.shape[1])
        on_boundary = _project_to_boundary(domain, near, near_distance, step)
        with np.errstate(invalid="ignore"):
            boundary_sizes = np.asarray(size(on_boundary), dtype=np.float64)
        usable = boundary_sizes[np.isfinite(boundary_sizes) & (boundary_sizes > 0)]
        if len(usable):
            smallest = min(smallest, float(usable.min()))
    return smallest


def _check_vertex_estimate(sample, dim):
    """Refuse sizes that ask for more vertices than this machine's memory holds (a unit mistake, most often).

    Returns the domain's area (or volume) as the sample measures it.

    The count is the sizes' vertex density (equilateral cells: 2 / (√3 h²)
    per unit area; regular tetrahedra: √2 / h³ per unit volume) summed over
    a regular sample of the domain. A square of 100 km meshed at 0.5 (metres
    taken for kilometres) ran 67 s and then ran out of memory deep in the
    seeding.
    """
    inside, sizes, share = sample.inside, sample.sizes, sample.share
    memory = physical_memory()
    if memory is None:  # no limit known
        return share * len(inside)
    with np.errstate(divide="ignore", over="ignore"):
        density = 2.0 / (np.sqrt(3.0) * sizes**2) if dim == 2 else np.sqrt(2.0) / sizes**3
        estimate = float(np.sum(density) * share)
    most = memory / BYTES_PER_VERTEX[dim]
    if estimate > most:
        raise GenerationError(
            f"the sizes ask for about {estimate:.3g} vertices (the domain's {'area' if dim == 2 else 'volume'} over "
            f"each size's share), more than this machine's {memory / 2**30:.0f} GiB of memory holds (about "
            f"{most:.2g}): are the sizes and the domain in the same units?"
        )
    return share * len(inside)


def _warn_if_partly_covered(mesh, measure):
    """Warn when the cells cover much less or much more than the domain's sampled area (or volume) ``measure``.

    Features thinner than the sizes are not meshed as they are: a polygon
    thin in most places (a needle 57 wide meshed at 50) came out as 5
    vertices over 21 % of its area, "converged"; a hole 17 wide in a strip
    meshed at 50 was bridged by cells covering 133 % of the area.
    """
    volumes = signed_areas(mesh.points, mesh.cells) if mesh.dim == 2 else tetra_volumes(mesh.points, mesh.cells)
    ratio = float(volumes.sum()) / measure if measure > 0 else 1.0
    if not COVERED[0] <= ratio <= COVERED[1]:
        why = "parts thinner than the mesh size were left out" if ratio < 1 else "cells bridge gaps or holes"
        warn_user(
            f"the mesh covers {100 * ratio:.0f} % of the domain's {'area' if mesh.dim == 2 else 'volume'} (about "
            f"{measure:.4g}): {why}{'' if ratio < 1 else ' thinner than the mesh size'}; give smaller sizes there",
        )


def _warn_if_rings_missed(mesh, domain, size, tolerance):
    """Warn of the rings of a polygon ``domain`` that no boundary vertex of the 2D ``mesh`` lies on.

    DistMesh keeps the cells whose centroid is inside: a hole smaller than
    the cells around it is covered, a part smaller than them gets none (a
    hole 0.04 across in a unit square meshed at 0.1, a part 0.03 square
    beside it: both gone, the area covered within 0.2 % of the domain's; a
    barrier island 0.7 degrees long in GSHHS's Gulf of Mexico, narrower than
    the 0.1 degree cells, covered). Domains other than :class:`~terramesh.geometry.Polygon` have no list of
    their boundary's pieces and are not checked.
    """
    if not hasattr(domain, "rings_missed") or mesh.n_cells == 0:
        return
    holes, parts = domain.rings_missed(mesh.points[sorted_unique(boundary_edges(mesh.cells))], tolerance)
    if not holes and not parts:
        return
    missed = holes + parts
    extent = np.array([np.ptp(domain.rings[ring], axis=0).max() for ring in missed])
    largest = missed[int(np.argmax(extent))]
    where = domain.rings[largest].mean(axis=0)
    said = [
        f"{len(rings)} {word}{'s' if len(rings) > 1 else ''} {fate}"
        for rings, word, fate in ((holes, "hole", "covered by cells"), (parts, "disjoint part", "with no cells"))
        if rings
    ]
    warn_user(
        f"the domain's boundary has pieces smaller or narrower than the cells there that are not in the mesh: "
        f"{' and '.join(said)} (the longest {_plain(extent.max())} long, near ({where[0]:.6g}, {where[1]:.6g}), "
        f"where the size is {_plain(float(size(where[None])[0]))}); give smaller sizes there to keep them",
    )


def _plain(length):
    """``length`` to three significant digits, without an exponent between 1e-4 and 1e9 (11600 m, not 1.16e+04)."""
    if 1e-4 <= abs(length) < 1e9:
        return np.format_float_positional(length, precision=3, unique=False, fractional=False, trim="-")
    return f"{length:.3g}"


SIZE_BLOCKS = 16  # the 2D check of the mesh against its sizes counts vertices in this many blocks a side of the bbox
FEWEST_EXPECTED = 10  # ...in the blocks where the sizes ask for this many vertices or more...
LEAST_SHARE = 0.5  # ...and warns where the mesh has fewer than this share of them


def _warn_if_sizes_missed(mesh, sample, h0):
    """Warn where the 2D mesh has far fewer vertices than its sizes ask for (a spot the sizes change too fast for).

    The sizes' ``sample`` (:func:`_size_sample`) gives each square block of
    a grid over the domain (``SIZE_BLOCKS`` along its longer side) the vertex count its sizes (not
    below ``h0``) ask for, ``1 / (sqrt(3)/2 h**2)`` over its area; where that
    is ``FEWEST_EXPECTED`` or more and the mesh has under ``LEAST_SHARE`` of
    it, the sizes fell faster than the mesh could follow: the seeding's
    lattices, refined only around sites whose own size is small, stepped
    over a spot of small sizes between their coarse sites (a spot 0.04
    across at 1e-3 in a unit square at 0.2 had none of its 1,450 vertices,
    silently with h0 given or a SizeGrid), or the forces of the coarse
    cells around a spot that was seeded squeezed it to its middle and
    thinned it (0.012 across: from 131 vertices to none).
    """
    inside, sizes, share = sample.inside, sample.sizes, sample.share
    if len(inside) == 0 or len(mesh.points) == 0:
        return
    # square blocks, SIZE_BLOCKS along the longer side: on a strip 30 x 1 blocks 1/16 high fell between
    # the mesh's rows and missed every vertex
    low, high = bounds(inside)
    side = max(float(np.max(high - low)) / SIZE_BLOCKS, np.finfo(float).tiny)
    counts = np.maximum(np.ceil((high - low) / side).astype(np.int64), 1)

    def block(points):
        # column by column: NumPy 2.4 took twice as long over the (n, 2) array
        index = 0
        for axis in range(2):
            cell = ((points[:, axis] - low[axis]) / side).astype(np.int64)
            np.clip(cell, 0, counts[axis] - 1, out=cell)
            index = index * counts[axis] + cell
        return index

    blocks = block(inside)
    asked = np.bincount(
        blocks, weights=share / (np.sqrt(3.0) / 2.0 * np.maximum(sizes, h0) ** 2), minlength=int(np.prod(counts))
    )
    found = np.bincount(block(mesh.points), minlength=int(np.prod(counts)))
    # and short in the block's 3 x 3 neighbourhood too: a row of vertices just past a block's edge left a
    # bar 0.2 wide (a block's share of it asked for 10) with 5, at the size asked everywhere
    around = [_neighbourhood_sums(values.reshape(counts)).ravel() for values in (asked, found)]
    short = np.flatnonzero(
        (asked >= FEWEST_EXPECTED) & (found < LEAST_SHARE * asked) & (around[1] < LEAST_SHARE * around[0])
    )
    if len(short) == 0:
        return
    worst = short[np.argmin(found[short] / asked[short])]
    in_worst = blocks == worst
    where = inside[in_worst][np.argmin(sizes[in_worst])]
    warn_user(
        f"the mesh has {int(found[worst])} vertices {SIZES_MISSED} {asked[worst]:.0f} (near "
        f"({where[0]:.6g}, {where[1]:.6g}), sizes down to {sizes[in_worst].min():.3g}; {len(short)} such "
        f"blocks of a {counts[0]} x {counts[1]} grid over the domain): the sizes change faster than a mesh "
        "can follow; grade them (tm.sizing.limit_gradient) so that the region of small sizes is wider",
    )


def _neighbourhood_sums(grid):
    """Each value of the 2D ``grid`` summed with its (up to) eight neighbours'."""
    padded = np.pad(grid.astype(np.float64), 1)
    rows, columns = grid.shape
    return sum(padded[i : i + rows, j : j + columns] for i in range(3) for j in range(3))


def _near_distance(domain, points, limit):
    """Signed distances, exact within ``limit`` of the boundary and outside it; ``-limit`` (a bound) farther inside."""
    distance = domain.distance_within(points, limit)
    out = np.flatnonzero(distance >= limit)
    if len(out):  # far outside (rare): a projection wants the exact distance
        distance[out] = domain.distance(points[out])
    return distance


def _project_to_boundary(domain, points, distance, step, nearest=None):
    """Move points onto the zero level set: exactly where the domain can (``domain.project``), else by Newton.

    One Newton step along the forward-difference gradient of the distance;
    a polygon's exact projection saves its two further distance
    evaluations (a coastline's cost most of an iteration). ``nearest``, the
    boundary points already found with the distances (NaN where not), are
    taken as they are.
    """
    project = getattr(domain, "project", None)
    if callable(project):
        if nearest is None:
            return project(points) if len(points) else points.copy()
        unknown = np.flatnonzero(np.isnan(nearest[:, 0]))
        if len(unknown):
            nearest[unknown] = project(points[unknown])
        return nearest
    gradient = distance_gradient(domain, points, distance, step)
    norm2 = np.sum(gradient**2, axis=1)
    norm2[norm2 == 0] = 1.0
    return points - (distance / norm2)[:, None] * gradient


def _rest_scale(points, edges, target):
    """What scales the edges' rest lengths (Persson & Strang), the same for the forces and the density control."""
    return rest_length_scale(points, edges, target, LENGTH_FACTOR, CHUNKS)


def _crowded_points(points, edges, target, n_fixed):
    """One movable end point of each edge shorter than half its rest length (Persson's density control)."""
    return short_edge_ends(edges, points, target, _rest_scale(points, edges, target), n_fixed)


def _boundary_gaps(domain, points, edges, target, finite_step, triangulation):
    """Boundary-projected midpoints of boundary edges that are too long.

    Boundary points slide along the boundary under weak tangential forces
    only, so gaps there heal slowly and leave flat cells whose third vertex
    is stuck just inside. A point in the gap lets the forces push that
    vertex inward. A midpoint projected onto a point of ``triangulation``
    (Delaunay for ``points``), or onto the spot of another midpoint (a
    polygon's vertex), is left out.
    """
    start, end = points[edges[:, 0]], points[edges[:, 1]]
    lengths = np.sqrt(np.sum((end - start) ** 2, axis=1))
    wanted = 0.5 * (target[edges[:, 0]] + target[edges[:, 1]])
    gap = lengths > GAP_RATIO * wanted
    if not gap.any():
        return _NO_POINTS
    middle = 0.5 * (start[gap] + end[gap])
    middle = _project_to_boundary(domain, middle, domain.distance(middle), finite_step)
    middle = without_rows(middle, coincident_points(middle))
    return middle[triangulation.nearest_distances(middle) > 0]


class _LazyDistance:
    """Signed distances kept up to date only where they matter: near the boundary.

    A distance function of a terramesh geometry changes by at most the
    distance a point moves (it is 1-Lipschitz), so a point whose last
    distance, plus ``DISTANCE_SLACK`` of it and its movement since, is still
    below minus ``LAZY_BAND`` local sizes is certainly inside and needs no
    new evaluation; only points that
    may have reached the boundary are evaluated. Every decision the
    generator takes from the distances (project a point, count it as
    interior, bound a cell's centroid) is the same as with fresh ones. That
    skips most points of a long coastline polygon in every iteration. Points
    removed or added (crowded points, boundary gaps) are followed one by one
    (:meth:`remove`, :meth:`append`), so such a change costs the new points'
    distances, not all of them again. Plain callables are evaluated in full,
    as nothing is known of their slope.
    """

    def __init__(self, domain):
        self.domain = domain
        self.enabled = getattr(domain, "lipschitz", False)
        self.distance = self.limit = None
        # a polygon finds each point's nearest boundary point with its distance: kept for the
        # projection of the points evaluated last (all that can be outside), a search saved
        self._with_nearest = getattr(domain, "distance_and_nearest", None)
        self._nearest = self._fresh = None

    def _evaluate(self, points):
        if self.limit is None:
            return (self.domain.distance(points), None) if self._with_nearest is None else self._with_nearest(points)
        if self._with_nearest is None:
            return _near_distance(self.domain, points, self.limit), None
        distance, nearest = self._with_nearest(points, self.limit)
        out = np.flatnonzero(distance >= self.limit)
        if len(out):  # far outside (rare): the projection wants the exact distance
            distance[out], nearest[out] = self._with_nearest(points[out])
        return distance, nearest

    def update(self, points, moved, target):
        if not self.enabled or self.distance is None or len(self.distance) != len(points):
            # a polygon's distance far from its segments costs ten times one near them (0.76 against
            # 0.08 s for 180k points of a 20,000-vertex coast); an interior point needs only a bound
            self.limit = DISTANCE_REACH * float(np.min(target)) if self.enabled and len(target) else None
            self.distance, self._nearest = self._evaluate(points)
            self._fresh = None if self._nearest is None else np.ones(len(points), dtype=bool)
            self.drift = np.zeros(len(points))
            return self.distance.copy()
        stale = stale_distances(self.distance, self.drift, moved, target, DISTANCE_SLACK, LAZY_BAND)
        distance, nearest = self._evaluate(points[stale])
        self.distance[stale] = distance
        if nearest is not None:
            self._fresh = np.zeros(len(points), dtype=bool)
            self._fresh[stale] = True
            self._nearest[stale] = nearest
        return self.distance.copy()

    def nearest(self, which, n_points):
        """Nearest boundary points the last :meth:`update` found for the points ``which`` (indices) of ``n_points``.

        NaN where it found none (a point not evaluated, or far out); None
        when the domain gives none or points changed since.
        """
        if self._fresh is None or len(self._fresh) != n_points:
            return None
        nearest = self._nearest[which]
        nearest[~self._fresh[which]] = np.nan
        return nearest

    def upper_bound(self, n_points):
        """An upper bound of each point's signed distance, or None where unknown (non-Lipschitz, points changed)."""
        if not self.enabled or self.distance is None or len(self.distance) != n_points:
            return None
        return self.distance + DISTANCE_SLACK * np.abs(self.distance) + self.drift

    def remove(self, indices):
        """Follow the removal of the points ``indices`` (the rest keep their order)."""
        self._fresh = None  # the nearest points serve the update's own iteration only
        if self.enabled and self.distance is not None and len(indices):
            self.distance = np.delete(self.distance, indices)
            self.drift = np.delete(self.drift, indices)
            if self._nearest is not None:
                self._nearest = without_rows(self._nearest, indices)

    def moved(self, indices, lengths):
        """Follow the points ``indices`` moved by ``lengths`` after the last :meth:`update` (their bounds widen)."""
        if self.enabled and self.distance is not None:
            self.drift[indices] += lengths

    def append(self, points):
        """Follow new points appended after the others: their distances are evaluated (a few boundary points)."""
        self._fresh = None
        if self.enabled and self.distance is not None and len(points):
            distance, nearest = self._evaluate(points)
            self.distance = np.concatenate([self.distance, distance])
            self.drift = np.concatenate([self.drift, np.zeros(len(points))])
            if self._nearest is not None:
                self._nearest = np.concatenate([self._nearest, nearest])


class _Sweeps:
    """Gauss-Seidel force steps (:func:`sweep_step`) with what they keep between iterations.

    The neighbour lists follow the edges (built again when the edges are
    new arrays; a weak reference, so replaced edges are freed at once).
    The outward normals of the points projected onto the boundary after a
    sweep serve the next sweep if the points are still that array (an
    insertion or removal makes a new one). A projection shorter than
    ``shortest`` gives no direction: rounding would make one up, and the
    point keeps the normal it had.
    """

    def __init__(self, shortest):
        self._shortest = shortest
        self._edges = self._lists = self._normal = self._normal_of = None

    def step(self, points, edges, target, n_fixed):
        """The points after one sweep, each one's move, and which ones belong on the boundary."""
        if self._edges is None or self._edges() is not edges:
            self._lists = None
            self._lists = neighbor_lists(edges, len(points))
            self._edges = weakref.ref(edges)
        if self._normal_of is not points:
            self._normal = np.zeros_like(points)
        scale = _rest_scale(points, edges, target)
        return sweep_step(points, *self._lists, target, scale, RELAXATION, BOUNDARY_RELAXATION, n_fixed, self._normal)

    def projected(self, points, outside, escaped, distance):
        """Note that the points ``outside`` (indices) went onto the boundary from ``escaped`` (at ``distance``)."""
        offset = (escaped - points[outside]) * np.sign(distance)[:, None]
        length = np.sqrt(np.sum(offset**2, axis=1))
        direction = offset / np.maximum(length, self._shortest)[:, None]
        normal = np.zeros_like(points)
        normal[outside] = np.where((length > self._shortest)[:, None], direction, self._normal[outside])
        self._normal, self._normal_of = normal, points


def _changed_points(points, removed, added, triangulation, lazy_distance):
    """``points`` less the indices ``removed``, with ``added`` after them; the triangulation and distances follow.

    The three must change together: distances out of step with the points
    once left boundary points unprojected for an iteration.
    """
    triangulation.remove_points(removed)
    triangulation.add_points(added)
    lazy_distance.remove(removed)
    lazy_distance.append(added)
    return np.vstack([without_rows(points, removed), added])


def _without_vertices(removed, n_points, *tables, renumbered=True):
    """``tables`` of cells or edges without the rows that touch the ``removed`` points, renumbered as the rest.

    The forces go on with the other edges until the next triangulation,
    where a full pass to find them again (the cells near a coastline need
    their centroids tested) cost 0.15 s at 360,000 points. Without
    ``renumbered`` the points keep their numbers (they stay, detached).
    """
    kept = np.ones(n_points, dtype=bool)
    kept[removed] = False
    numbering = np.where(kept, np.cumsum(kept) - 1 if renumbered else np.arange(n_points), -1)
    return [rows_renumbered(table, numbering) for table in tables]


def _without_duplicates(points, target, triangulation, lazy_distance, n_fixed):
    """``points`` and ``target`` less the points a triangulation from scratch found doubled; it follows.

    Such a point (a boundary gap's new point projected onto one already
    there) is no vertex, so no force moves it away, and while the
    triangulation holds one every change to it is a rebuild: before points
    were kept apart at projection (:func:`coincident_points`), one such point made
    70 of the 72 retriangulations of the OceanMesh2D guide's §5.3 full ones
    (22 s of 53). A fixed point stays; its free twin goes.
    """
    duplicate_of = triangulation.duplicate_of
    doubled = np.flatnonzero(duplicate_of >= 0)
    if len(doubled) == 0:
        return points, target
    doomed = np.where(doubled < n_fixed, duplicate_of[doubled], doubled)
    doomed = np.unique(doomed[doomed >= n_fixed])
    return _without_points(points, target, doomed, triangulation, lazy_distance)


def _to_park(points, previous, doubled, twin, n_fixed):
    """Of each spot the ``doubled`` points share with their ``twin``, the free points that moved there in the last step.

    ``previous`` holds the positions before the step. A point that held the
    spot before stays and the one that came is parked; of two that came,
    the later is. Ascending; no fixed point.
    """
    stayed = np.all(points[doubled] == previous[doubled], axis=1)
    park = np.where(stayed, twin, doubled)
    return np.unique(park[park >= n_fixed])


def _without_points(points, target, removed, triangulation, lazy_distance):
    """``points`` and ``target`` less the points ``removed`` (indices); the triangulation and distances follow."""
    if len(removed) == 0:
        return points, target
    return _changed_points(points, removed, _NO_POINTS, triangulation, lazy_distance), np.delete(target, removed)


def _inside(domain, points, cells, tolerance, distance_bound=None, first=0, earlier=None, record=None):
    """Mask of the cells whose centroid lies inside the domain by more than ``tolerance``.

    With upper bounds of the points' distances, only cells near the
    boundary have their centroid's distance evaluated. Vertex ``v`` is point
    ``v - first``; cells not of the points (a triangulation's ghost and
    frame cells, see :meth:`Triangulation.cells_with_ghosts`) are outside.
    A ``record`` (a dict) gets the cells and which of them were evaluated,
    for a later call as ``earlier``: when only points were added since (the
    others unmoved, their bounds the same), a cell still in the same row
    keeps the answer it got (the boundary gaps' second pass at every
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


def _mesh_edges(domain, triangulation, points, tolerance, lazy_distance=None, earlier=None, record=None):
    """The triangulation's cells with their centroid inside, their unique edges, the boundary edges among them.

    With the ``lazy_distance`` that follows ``points``, only cells near the
    boundary have their centroid evaluated; ``earlier`` and ``record`` as
    for :func:`_inside`.
    """
    inner_cells, edges, on_boundary = _flagged_mesh_edges(
        domain, triangulation, points, tolerance, lazy_distance, earlier, record
    )
    return inner_cells, edges, edges[on_boundary]


def _flagged_mesh_edges(domain, triangulation, points, tolerance, lazy_distance=None, earlier=None, record=None):
    """As :func:`_mesh_edges`, with a mask of the boundary edges instead of them."""
    if len(points) != triangulation.n_points:  # the own arrays tell ghost cells by the points' count
        raise GenerationError(f"{len(points)} points for a triangulation of {triangulation.n_points}")
    cells, neighbors, first = triangulation.cells_with_ghosts()
    bound = None if lazy_distance is None else lazy_distance.upper_bound(len(points))
    inside = _inside(domain, points, cells, tolerance, bound, first, earlier, record)
    return inner_cell_edges(cells, neighbors, inside, first)


def _spread(points, size):
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


def _spread_corners(corners, given, size):
    """The domain's corners, less those within ``CORNER_REACH`` local sizes of a given point or an earlier corner.

    A coastline resampled near the mesh size has sharp vertices a fraction of
    an element apart; fixing both would pin a sliver pair between them.
    """
    if len(corners) == 0:
        return corners
    keep = _spread(corners, size)
    if len(given):
        from scipy.spatial import cKDTree

        keep &= cKDTree(given).query(corners)[0] >= CORNER_REACH * size(corners)
    return corners[keep]


def _corners_in(domain, bbox):
    """The domain's corners within ``bbox`` (shape (2, dim)), those a rounding outside moved onto it; shape (k, dim).

    A grid's axes end a rounding past the values given (``linspace(-0.7,
    0, 71)`` at 1.1e-16): a gridded block cut by a box at z = 0 had its
    four top corners there, outside the combination's bbox, and lost them.
    """
    corners = np.asarray(domain.corners(), dtype=np.float64).reshape(-1, bbox.shape[1])
    rounding = 1e-9 * float(np.max(bbox[1] - bbox[0]))
    corners = corners[np.all((corners >= bbox[0] - rounding) & (corners <= bbox[1] + rounding), axis=1)]
    return np.clip(corners, bbox[0], bbox[1])


def _validated_fixed_points(fixed_points, domain, bbox, tolerance, size):
    """The user's fixed points, checked, and the domain's corners (spread out); 2D or 3D."""
    dim = bbox.shape[1]
    corners = _corners_in(domain, bbox)
    if fixed_points is None:
        return _spread_corners(corners, np.empty((0, dim)), size)
    fixed = checked_fixed_points(fixed_points, dim, GenerationError)
    distance = domain.distance(fixed)
    outside = distance > tolerance
    if outside.any():
        raise GenerationError(
            f"{int(outside.sum())} fixed points lie outside the domain, e.g. {fixed[outside][0].tolist()}"
        )
    _warn_if_fixed_points_crowd_the_boundary(domain, fixed, distance, corners, tolerance, size)
    fixed = np.unique(np.vstack([fixed, _spread_corners(corners, fixed, size)]), axis=0)
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


def _turns(domain, size, corners):
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


# warnings' words, by which meshing in strips mutes them for its cuts' points (and the third for its strips'
# boundary vertices on the cuts), and an anisotropic start the second for the corners of its metric
FIXED_NEAR_BOUNDARY = "fixed points lie less than half a size inside the boundary"
REACHED_MAX_ITER = "mesh generation reached max_iter"
SIZES_MISSED = "where its sizes ask for about"
CORNERS_DISPLACED = "of the domain's corners are no vertices, being within half a size of a fixed point"
OFF_BOUNDARY = "boundary vertices lie off the domain's boundary after"


def _warn_if_fixed_points_crowd_the_boundary(domain, fixed, distance, corners, tolerance, size):
    """Warn of ``fixed`` points less than ``CORNER_REACH`` sizes inside the boundary, and of the corners they displace.

    Neither the boundary nor the point can move: in a unit square at h 0.1
    a gauge 0.005 inside became a boundary vertex 0.005 off the boundary
    (the thin cells between went), one 0.01-0.03 inside left cells of q
    0.17-0.48; a corner within half a size of a fixed point is no vertex,
    and the cells cut across it, where the boundary turns there
    (:func:`_turns`: a model box's side nodes are on straight sides).
    """
    near = fixed_near_boundary(fixed, distance, size, tolerance)
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
    displaced = displaced[_turns(domain, size, displaced)]
    if len(displaced):
        warn_user(
            f"{len(displaced)} {CORNERS_DISPLACED}, e.g. {_at(displaced[0])}: the cells cut across them; move "
            "such points onto the corner or half a size from it"
        )


def fixed_near_boundary(fixed, distance, size, tolerance):
    """Words naming the ``fixed`` points (at ``distance``) less than ``CORNER_REACH`` sizes inside, or ``""``."""
    near = np.flatnonzero((distance < -tolerance) & (distance > -CORNER_REACH * size(fixed)))
    if len(near) == 0:
        return ""
    first = near[np.argmax(distance[near])]
    depth = -distance[first] / size(fixed[first : first + 1])[0]
    return f"{len(near)} {FIXED_NEAR_BOUNDARY}, e.g. {_at(fixed[first])}, {depth:.2g} sizes in"


def warn_if_fixed_points_crowd_the_boundary(domain, fixed_points, size, tolerance):
    """:func:`_warn_if_fixed_points_crowd_the_boundary` for the (checked) ``fixed_points`` alone, shape (k, dim).

    For a generator that adds fixed points of its own (an anisotropic start,
    the metric's corners) and mutes the check of its run.
    """
    fixed = np.asarray(fixed_points, dtype=np.float64).reshape(-1, domain.dim)
    if len(fixed) == 0:
        return
    corners = _corners_in(domain, np.asarray(domain.bbox, dtype=np.float64))
    _warn_if_fixed_points_crowd_the_boundary(domain, fixed, domain.distance(fixed), corners, tolerance, size)


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


def checked_max_iter(max_iter):
    """``max_iter`` as an int of at least 1 (a bool or 2.5 refused); else GenerationError."""
    iterations = checked_number(max_iter, "max_iter must be a whole number of at least 1", GenerationError, minimum=1)
    if not iterations.is_integer() or isinstance(max_iter, bool):
        raise GenerationError(f"max_iter must be a whole number of at least 1, got {max_iter!r}")
    return int(iterations)


def _options(domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance=1e-2, seed=0):
    """Both generators' options, checked.

    Returns ``(size, h0, tolerance, fixed points, whether h0 was estimated,
    the domain's sampled area or volume, the sizes' sample)`` (see
    :func:`_size_sample`).
    """
    dim = bbox.shape[1]
    if edge_length is None:
        if h0 is None:
            raise GenerationError("give edge_length (or at least h0, for a uniform mesh)")
        edge_length = h0
    size = as_size_function(edge_length)
    if isinstance(size, SizeGrid):
        if size.dim != dim:
            raise GenerationError(f"a {dim}D mesh needs a {dim}-axis SizeGrid, got {size.dim} axes")
        _check_grid_covers(size, bbox)
    sample = _size_sample(size, domain, bbox)  # one sample serves h0 and the vertex estimate
    h0_estimated = h0 is None and callable(edge_length) and not isinstance(edge_length, SizeGrid)
    if h0 is None:
        h0 = _smallest_size(size, domain, sample)
    h0 = checked_number(h0, "h0 must be positive and finite (a length)", GenerationError, minimum=0, strict=True)
    checked_max_iter(max_iter)
    checked_number(
        move_tolerance,
        "move_tolerance must be positive and finite (a fraction of the size)",
        GenerationError,
        minimum=0,
        strict=True,
    )
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise GenerationError(f"seed must be a non-negative integer, got {seed!r}")
    measure = _check_vertex_estimate(sample, dim)
    tolerance = BOUNDARY_TOLERANCE * h0
    fixed = _validated_fixed_points(fixed_points, domain, bbox, tolerance, size)
    return size, h0, tolerance, fixed, h0_estimated, measure, sample


GRID_COVERS = 0.5
"""Share of the domain's bbox (along each axis) below which a SizeGrid covering less of it warns."""


def _check_grid_covers(grid, bbox):
    """Refuse a SizeGrid apart from the domain, warn of one covering less than ``GRID_COVERS`` of it.

    Beyond its nodes a grid gives its edge's sizes: a grid of longitude and
    latitude given for a domain in UTM metres sized every point at its
    corner's 420 m, and nothing was said.
    """
    share = grid.covered(bbox[0], bbox[1])
    names = grid.axis_names
    extent = ", ".join(f"{name} {a:g}..{b:g}" for name, a, b in zip(names, *grid.bbox, strict=True))
    domain = ", ".join(f"{name} {a:g}..{b:g}" for name, a, b in zip(names, bbox[0], bbox[1], strict=True))
    if np.any(share < 0):
        raise SizingError(
            f"the SizeGrid ({extent}) and the domain ({domain}) do not overlap: is one in other units or another"
            " frame (degrees against metres)?"
        )
    if share.min() < GRID_COVERS:
        warn_user(
            f"the SizeGrid ({extent}) covers {100 * share.min():.0f} % of the domain ({domain}) along"
            f" {names[int(np.argmin(share))]}: beyond its nodes the sizes are its edge's"
        )


def _seeded(domain, size, h0, bbox, fixed, seed, seeder, tolerance, warn_below_h0, scale=1.0):
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
    return _with_fixed_first(points, fixed, 0.5 * scale * h0)


def _with_fixed_first(points, fixed, reach):
    """The ``fixed`` points followed by those of ``points`` farther than ``reach`` from all of them."""
    if len(fixed) == 0:
        return points
    return np.vstack([fixed, points[_beyond_fixed(points, fixed, reach)]])


def _beyond_fixed(points, fixed, reach):
    """Mask of the ``points`` farther than ``reach`` from every one of ``fixed``."""
    if len(fixed) == 0:
        return np.ones(len(points), dtype=bool)
    from scipy.spatial import cKDTree

    return cKDTree(fixed).query(points, distance_upper_bound=reach)[0] == np.inf


def generate_mesh(
    domain,
    edge_length=None,
    *,
    h0=None,
    bbox=None,
    fixed_points=None,
    max_iter=300,
    move_tolerance=1e-2,
    seed=0,
    levels=None,
):
    """Generate a triangle mesh of a domain with DistMesh's force equilibrium.

    Parameters
    ----------
    domain : Domain or callable
        Signed distance function (negative inside) with a ``bbox``; see
        :mod:`terramesh.geometry`. Units are the user's (metres, degrees...).
    edge_length : float, callable or SizeGrid, optional
        Target edge length: a number (uniform), a function of an ``(n, 2)``
        array, or a :class:`~terramesh.sizing.SizeGrid`. Defaults to ``h0``.
    h0 : float, optional
        Smallest edge length, the spacing of the initial lattice. Defaults to
        the number given as ``edge_length``, the grid's minimum, or the
        smallest value of the function on a 256 x 256 sample of the bbox.
    bbox : array_like, shape (2, 2), optional
        Region to mesh, ``[[xmin, ymin], [xmax, ymax]]``; defaults to the domain's.
    fixed_points : array_like, shape (k, 2), optional
        Points that must be vertices and never move. The domain's sharp
        corners (e.g. a rectangle's) are always added.
    max_iter : int, optional
        Most force iterations per level; reaching it at the last level
        without convergence warns.
    move_tolerance : float, optional
        Convergence: stop when no interior point moved more than this
        fraction of its local edge length in an iteration. Generation also
        stops, as "stalled", once the quality has gained less than
        0.01 in 20 iterations (10 at the coarsest of several levels, 5 at
        a refined level) in its best mean - 3 std of the quality (the
        OceanMesh2D guide's measure, §2.2).
        Afterwards the mesh is smoothed without lowering any vertex's worst
        cell (fixed points stay): boundary vertices slide along the
        boundary, three passes move interior vertices to the mean of their
        neighbours, and the vertices of cells below quality 0.8 move to
        where their worst cell is best.
    seed : int, optional
        Seed of the random thinning of the initial lattice; the same inputs
        and seed give the same mesh.
    levels : int, optional
        Coarse levels meshed first: level ``k`` meshes the domain at
        ``2**k`` times the size; each level's mesh, its edges split at their
        midpoints, starts the next, nearly in equilibrium already, so the
        fine levels need a few iterations where random initial points need
        tens. Where a coarse level misses a feature narrower than its size,
        the next level seeds it afresh. Default: at most 3, while the
        coarsest level keeps about 2,000 vertices and at most 12 % of
        them on the boundary (so none for a coastline, where a coarse
        level would miss most features); fewer where the coarsest would
        hold fewer than three points. ``0`` is classic DistMesh. 3D
        domains have their own default (see :func:`generate_mesh_3d`).

    Returns
    -------
    Mesh
        Valid mesh (counter-clockwise cells, no unused vertices, manifold
        boundary on the domain boundary, every cell's centroid inside).
        ``mesh.info`` holds, for the last level, ``iterations``,
        ``stop_reason`` (``"converged"``, ``"stalled"`` or ``"max_iter"``), ``max_move``,
        ``retriangulations`` and ``rebuilds`` (times the triangulation was
        built from scratch because flips, or a local insertion or removal
        of points, could not follow); ``levels``, one such record per level
        (coarsest first, with its ``seconds``, its number of ``points`` and,
        as ``filled``, the seeds added for features it missed when it was
        refined; a coarse level's ``rebuilds`` include its refinement's);
        ``seconds`` in all; and ``h0``, the smallest edge length used.

    Raises
    ------
    GenerationError
        For an empty domain, a bbox that misses it, or bad options; and,
        rather than an invalid mesh, where the boundary repair could not
        mend it (a part narrower than about an edge length: a boundary
        vertex left over half a size off the boundary, boundary edges that
        cross or hanging nodes), saying where.
    SizingError
        For non-positive, NaN or misshapen sizes, or a ``SizeGrid`` apart
        from the domain.

    Warns
    -----
    TerrameshWarning
        Among others, for a ``SizeGrid`` covering less than half the
        domain along an axis (:data:`GRID_COVERS`).

    References
    ----------
    P.-O. Persson and G. Strang, "A simple mesh generator in MATLAB",
    SIAM Review 46(2), 329-345, 2004. :doi:`10.1137/S0036144503429121`

    Examples
    --------
    >>> import terramesh as tm
    >>> mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2, seed=0)
    >>> 150 < mesh.n_cells < 200, mesh.info["stop_reason"] != "max_iter"
    (True, True)
    """
    started = time.perf_counter()
    domain = as_domain(domain, bbox)
    if domain.dim == 3:
        from .distmesh3d import generate_mesh_3d

        return generate_mesh_3d(
            domain,
            edge_length,
            h0=h0,
            bbox=bbox,
            fixed_points=fixed_points,
            max_iter=max_iter,
            move_tolerance=move_tolerance,
            seed=seed,
            levels=levels,
        )
    if domain.dim != 2:
        raise GenerationError(f"generate_mesh meshes 2D and 3D domains, got dim={domain.dim}")
    bbox = domain.bbox if bbox is None else as_bbox(bbox, dim=2)
    size, h0, tolerance, fixed, h0_estimated, measure, sample = _options(
        domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed
    )
    compile_ahead_on_first_run(["generation"])  # after the options' checks: a bad one said at once
    levels = coarse_levels(domain, size, bbox, sample) if levels is None else checked_levels(levels)
    finite_step = _finite_difference_step(h0, bbox)
    # a coarse level fixes only the fixed points half its size apart (the sides of a seismic
    # model box carry fixed nodes a fine edge apart); each finer level adds its own
    fixed_at = [np.ones(len(fixed), dtype=bool)]
    fixed_at += [_spread(fixed, scaled(size, 2.0**level)) for level in range(1, levels + 1)]
    points, levels = _coarsest_points(
        domain, size, h0, bbox, fixed, fixed_at, levels, seed, tolerance, not h0_estimated
    )
    n_fixed, records = int(fixed_at[levels].sum()), []
    if len(points) < 3:  # as the 3D generator says it; the triangulation's own message counted points only
        extent = " x ".join(f"{side:.4g}" for side in bbox[1] - bbox[0])
        raise GenerationError(
            f"only {len(points)} point{'s' if len(points) != 1 else ''} fit in the domain (its bbox {extent}): "
            f"h0={h0:g} is too large for it"
        )
    triangulation = Triangulation(points, frame=True)
    points = points[triangulation.sort_spatially(np.arange(len(points)) < n_fixed)]
    for level in range(levels, -1, -1):
        # sweeps only at the coarsest of several levels: on a coastline meshed at one level (mostly
        # boundary) they gained or lost 10-40 % by case, and left more low-valence vertices to clean
        sweep = level == levels and levels > 0
        stall_window = SWEPT_STALL_WINDOW if sweep else STALL_WINDOW if level == levels else REFINED_STALL_WINDOW
        if levels:
            logger.info(
                "level %d of %d (sizes x %g): %d points", levels - level + 1, levels + 1, 2.0**level, len(points)
            )
        with threads_for(len(points)):
            points, triangulation, record = _relax(
                domain,
                scaled(size, 2.0**level),
                tolerance,
                points,
                triangulation,
                n_fixed,
                max_iter,
                move_tolerance,
                stall_window,
                finite_step,
                sweep=sweep,
                # a coarse level only starts the next, whose own rounds mend what its refinement brings: on
                # jagged coasts, where each round finds a few hundred points to thin or add, five rounds cost
                # 20-25 %; with none, the few points thinned in a seismic model's middle level left BP2004's
                # worst cell at 0.801 instead of 0.814
                max_settle_rounds=MAX_SETTLE_ROUNDS if level == 0 else 1,
                settle_iterations=SETTLE_ITERATIONS if level == 0 else TOUCH_UP_ITERATIONS,
            )
        record.update(points=len(points), filled=0)
        records.append(record)
        if level:
            fine = 2.0 ** (level - 1)
            points, triangulation, n_fixed = _refined(
                domain,
                scaled(size, fine),
                fine * h0,
                points,
                n_fixed,
                fixed[fixed_at[level - 1] & ~fixed_at[level]],
                triangulation,
                record,
                bbox=bbox,
                seed=seed,
                tolerance=tolerance,
                finite_step=finite_step,
            )

    mesh = _finalize(domain, size, triangulation, points, n_fixed, tolerance, finite_step)
    triangulation = None
    mesh.info.update(
        {key: records[-1][key] for key in ("iterations", "stop_reason", "max_move", "retriangulations", "rebuilds")},
        levels=records,
        seconds=time.perf_counter() - started,
        h0=h0,
    )
    logger.info(
        "stopped after %d iterations (%s): %d vertices, %d cells in %.2f s",
        mesh.info["iterations"],
        mesh.info["stop_reason"],
        mesh.n_points,
        mesh.n_cells,
        mesh.info["seconds"],
    )
    _warn_if_unconverged(mesh.info, max_iter, move_tolerance)
    _warn_if_partly_covered(mesh, measure)
    _warn_if_rings_missed(mesh, domain, size, tolerance)
    _warn_if_sizes_missed(mesh, sample, h0)
    if fixed_points is not None:
        warn_if_fixed_points_dropped(mesh, checked_fixed_points(fixed_points, 2, GenerationError), tolerance)
    return mesh


FIXED_DROPPED = "fixed points are no vertices of the mesh"


def warn_if_fixed_points_dropped(mesh, fixed_points, tolerance):
    """Warn of the user's ``fixed_points`` that are no vertex of ``mesh`` (none within ``tolerance``), and where.

    A fixed point in a corner sharper than the cells can fill (6 degrees at
    a size of a fiftieth of its sides) kept its cell, but the slivers
    between it and the rest of the mesh went as flat, and the repair took
    the cell left hanging at the tip: the mesh came back without the vertex
    the user asked for, and said nothing. The generators that run
    :func:`generate_mesh` with fixed points of their own (a strip's cut, an
    anisotropic start's metric corners) mute its warning and ask this of
    their own result with the user's points.
    """
    from scipy.spatial import cKDTree

    if len(fixed_points) == 0:
        return
    distance, _ = cKDTree(mesh.points).query(fixed_points)
    dropped = np.flatnonzero(distance > tolerance)
    if len(dropped):
        warn_user(
            f"{len(dropped)} of the {len(fixed_points)} {FIXED_DROPPED}, the first at "
            f"{_at(fixed_points[dropped[0]])}: the cells there were dropped, as the domain is narrower than the "
            "size about it (a corner sharper than the cells can fill, a thin spit); a smaller size there keeps it"
        )


def _coarsest_points(domain, size, h0, bbox, fixed, fixed_at, levels, seed, tolerance, warn_below_h0):
    """The coarsest level's points (its fixed ones first) and the number of coarse levels.

    Fewer levels than ``levels`` where the coarsest would hold fewer than
    ``COARSEST_LEAST`` points: a domain (or a strip of one) not much larger
    than that level's size, whose refined handful keeps its structure (a
    unit square at 0.05 forced to 3 levels started from 16 points and stayed
    a grid of right triangles, mean q 0.943; 2 levels, from 46, 0.970; one
    level, from 150, 0.989, as without). ``fixed_at[level]`` masks the
    ``fixed`` points each level keeps.
    """
    for level in range(levels, -1, -1):
        try:
            points = _seeded(
                domain,
                size,
                h0,
                bbox,
                fixed[fixed_at[level]],
                seed,
                seed_points,
                tolerance,
                warn_below_h0,
                2.0**level,
            )
        except GenerationError:  # no lattice point inside at that spacing: a finer level may have some
            if level == 0:
                raise
            continue
        if len(points) >= COARSEST_LEAST or level == 0:
            return points, level


def _warn_if_unconverged(info, max_iter, move_tolerance):
    """Warn, at the user's line, when the iterations ran out (``info["stop_reason"]`` is ``"max_iter"``)."""
    if info["stop_reason"] == "max_iter":
        warn_user(
            f"{REACHED_MAX_ITER}={max_iter} before points stopped moving "
            f"(largest move {info['max_move']:.2e} of the local size, tolerance {move_tolerance:g})",
        )


def _doubled_midpoints(points, middle, on_boundary):
    """Midpoints (indices into ``middle``) projected exactly onto a point or onto an earlier midpoint's spot.

    Two boundary edges either side of a polygon's vertex project their
    midpoints onto that vertex; at refinement one of them would make the
    repair of the triangulation give up and rebuild it (0.1-0.2 s at
    50k-180k points), and every insertion and removal after it too.
    """
    if not on_boundary.any():
        return _NO_INDICES
    candidates = np.zeros(len(points) + len(middle), dtype=bool)
    candidates[: len(points)] = True  # a boundary vertex need not end a boundary edge of the kept cells
    candidates[len(points) + np.flatnonzero(on_boundary)] = True
    doubled = coincident_points(np.vstack([points, middle]), candidates)
    return doubled[doubled >= len(points)] - len(points)


def _refined(
    domain, size, h0, points, n_fixed, new_fixed, triangulation, record, *, bbox, seed, tolerance, finite_step
):
    """The next finer level's points: ``points``, the midpoints of their mesh's edges, seeds of missed features.

    ``size`` and ``h0`` are the finer level's; ``new_fixed`` are the fixed
    points it adds (they replace points within ``h0 / 2``). The new points
    are inserted into ``triangulation``, the fixed ones put first and the
    rest renumbered along a Hilbert curve; how many seeds filled missed
    features is recorded as ``filled`` in ``record``, and its ``rebuilds``
    count the refinement's too. Returns ``(points, triangulation, n_fixed)``.
    """
    rebuilds = triangulation.rebuilds
    cells, neighbors = triangulation.cells_and_neighbors()
    inside = _inside(domain, points, cells, tolerance)
    edges, on_boundary = triangulation.split_edges(inside)
    direct = edges is not None
    if not direct:
        _, edges, on_boundary = inner_cell_edges(cells, neighbors, inside, 0)
    cells = neighbors = inside = None
    middle = refined_points(
        domain, points, edges, on_boundary, lambda at, distance: _project_to_boundary(domain, at, distance, finite_step)
    )
    # fixed points a fine edge apart (a strip's cut) may all be fixed at the coarse level: the midpoints
    # between them crowded, and thinning them cost the finest level a settle round (16 iterations, not 6)
    short = row_norms(points[edges[:, 0]] - points[edges[:, 1]]) < SPLIT_RATIO * size(middle)
    doubled = _doubled_midpoints(points, middle, on_boundary)
    if direct:  # the midpoints are in at the exact middle: boundary ones move onto the boundary
        if len(doubled):  # one point on another's spot: the repair would give up and triangulate afresh
            triangulation.remove_points(len(points) + doubled)
            short, middle = np.delete(short, doubled), without_rows(middle, doubled)
        triangulation.move_points(np.vstack([points, middle]))
        if short.any():
            triangulation.remove_points(len(points) + np.flatnonzero(short))
    else:
        short[doubled] = True
        triangulation.add_points(middle[~short])
    middle = middle[~short]
    seeds = uncovered_seeds(domain, size, h0, bbox, seed, tolerance, triangulation.nearest_distances)
    triangulation.add_points(seeds)
    points = np.vstack([points, middle, seeds])
    if len(new_fixed):
        from scipy.spatial import cKDTree

        near = cKDTree(new_fixed).query(points[n_fixed:], distance_upper_bound=0.5 * h0)[0] < np.inf
        doomed = n_fixed + np.flatnonzero(near)
        triangulation.remove_points(doomed)
        triangulation.add_points(new_fixed)
        points = np.vstack([without_rows(points, doomed), new_fixed])
    front = np.arange(len(points)) < n_fixed
    front[len(points) - len(new_fixed) :] = True
    order = triangulation.sort_spatially(front)
    record.update(filled=len(seeds), rebuilds=record["rebuilds"] + triangulation.rebuilds - rebuilds)
    return points[order], triangulation, n_fixed + len(new_fixed)


def _relax(
    domain,
    size,
    tolerance,
    points,
    triangulation,
    n_fixed,
    max_iter,
    move_tolerance,
    stall_window,
    finite_step,
    sweep,
    max_settle_rounds=MAX_SETTLE_ROUNDS,
    settle_iterations=SETTLE_ITERATIONS,
):
    """Move ``points`` by truss forces until they stop (or the quality stalls); returns them with their triangulation.

    ``triangulation`` is Delaunay for some earlier positions of the same
    points. Returns ``(points, triangulation, record)``; the triangulation
    is Delaunay for the returned points and the record holds
    ``iterations``, ``stop_reason``, ``max_move``, ``retriangulations``,
    ``rebuilds`` (triangulations from scratch where local repair failed)
    and ``seconds``.

    With ``sweep`` (the coarsest level, started from thinned lattice
    points) the points move in Gauss-Seidel sweeps, each from its
    neighbours' new positions; otherwise all at once. ``max_settle_rounds``
    bounds the times crowded points and boundary gaps are mended before
    going on instead of stopping, each followed by ``settle_iterations``
    (or ``TOUCH_UP_ITERATIONS`` after a mend of at most ``TOUCH_UP`` points). A sweep anneals a
    disordered start in about a third of the iterations, but moves the
    points of a level refined from a settled one farther than they need,
    and each move of a tenth of a size costs a retriangulation.
    """
    started = time.perf_counter()
    points = np.ascontiguousarray(points)
    target = size(points)
    last_triangulated = np.full_like(points, np.inf)
    retriangulations, max_move, last_log, quality_score = 0, np.inf, started, []
    stop_reason, looked, touched_up = "max_iter", False, False
    lazy_distance = _LazyDistance(domain)
    settle_rounds, settled_at, settle_wait = 0, 0, 0
    rebuilds_at_start, rebuilds_seen = triangulation.rebuilds, 0  # one triangulation throughout: the points match it
    sweeps = _Sweeps(finite_step) if sweep else None
    # points projected onto another one's spot wait where they were, out of the forces, until the
    # points change anyway (removed at once, each cost passes over every array: 5 of a coast's 11 ms
    # per iteration)
    parked = _NO_INDICES
    # a sweep anneals from the topology it is given, and stale edges let an arrangement wander (at 3 %
    # the graded 10**4 disk took 35 sweeps, not 33, and 10-20 % longer). Simultaneous steps on a coastline
    # keep moving a few boundary points a tenth of a size: at 0.2 % the GSHHS coast at 0.1 degrees
    # triangulated in 117 of 125 iterations, at 3 % in 30 of 114, twice as fast, as good a mesh
    stale_allowed = STALE_ALLOWED if sweep else STALE_ALLOWED_STEPPED

    for iteration in range(1, int(max_iter) + 1):
        if count_far(points, last_triangulated, target, RETRIANGULATE_AFTER) > stale_allowed * len(points):
            cells = edges = boundary = None  # freed before their successors exist: lower peak memory
            points, target = _without_points(points, target, parked, triangulation, lazy_distance)
            parked = _NO_INDICES
            triangulation.move_points(points)
            sides = {}
            cells, edges, boundary = _mesh_edges(domain, triangulation, points, tolerance, lazy_distance, record=sides)
            gaps = _boundary_gaps(domain, points, boundary, target, finite_step, triangulation)
            if len(gaps):  # insertions only: the cells they leave alone keep their sides
                points = _changed_points(points, _NO_INDICES, gaps, triangulation, lazy_distance)
                target = np.concatenate([target, size(gaps)])  # the others did not move
                cells, edges, boundary = _mesh_edges(
                    domain, triangulation, points, tolerance, lazy_distance, earlier=sides
                )
            sides = None
            last_triangulated = triangulation.positions
            retriangulations += 1
        elif iteration % DENSITY_CONTROL_EVERY == 0:
            crowded = np.union1d(_crowded_points(points, edges, target, n_fixed), parked)
            parked = _NO_INDICES
            if len(crowded):
                points, target = _without_points(points, target, crowded, triangulation, lazy_distance)
                cells, edges, boundary = _mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
                last_triangulated = triangulation.positions
                retriangulations += 1
        if triangulation.rebuilds > rebuilds_seen:  # only a rebuild lets points coincide exactly
            n_points = len(points)
            points, target = _without_duplicates(points, target, triangulation, lazy_distance, n_fixed)
            if len(points) < n_points:
                cells, edges, boundary = _mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
                last_triangulated = triangulation.positions
            rebuilds_seen = triangulation.rebuilds
        previous = points
        if sweeps is None:
            scale = _rest_scale(points, edges, target)
            points, move = force_step(points, edges, target, scale, TIME_STEP, n_fixed, CHUNKS)
            on_boundary = False
        else:
            points, move, on_boundary = sweeps.step(points, edges, target, n_fixed)
        distance = lazy_distance.update(points, move, target)
        outside = (distance > 0) | on_boundary
        outside[:n_fixed] = False  # a fixed point a rounding outside (on a strip's side, say) stays to the bit
        outside = np.flatnonzero(outside)  # gathered and scattered by index: half the time by mask
        if len(outside):
            escaped = points[outside]
            points[outside] = _project_to_boundary(
                domain, escaped, distance[outside], finite_step, lazy_distance.nearest(outside, len(points))
            )
            if sweeps is not None:
                sweeps.projected(points, outside, escaped, distance[outside])
            near = distance > -tolerance
            doubled, twin = coincident_points(points, near, return_twins=True)
            if len(doubled):  # the Delaunay repair cannot follow two points onto one: one waits where it was
                park = _to_park(points, previous, doubled, twin, n_fixed)
                lazy_distance.moved(park, np.sqrt(np.sum((points[park] - previous[park]) ** 2, axis=1)))
                points[park], move[park] = previous[park], 0.0
                # detached from the forces and the quality as if removed: one pass over the edges, not all arrays
                cells, edges, boundary = _without_vertices(park, len(points), cells, edges, boundary, renumbered=False)
                parked = np.union1d(parked, park)  # with no edge, no step moves them
                near[parked] = True
                doubled = coincident_points(points, near)
            if len(doubled):  # still doubled (the spot a point went back to was taken): it goes, all parked too
                doubled, parked = np.union1d(doubled, parked), _NO_INDICES
                cells, edges, boundary = _without_vertices(doubled, len(points), cells, edges, boundary)
                points = _changed_points(points, doubled, _NO_POINTS, triangulation, lazy_distance)
                move, distance = np.delete(move, doubled), np.delete(distance, doubled)
                last_triangulated = without_rows(last_triangulated, doubled)
        target = size(points)
        max_move = largest_interior_move(move, target, distance, tolerance)
        mean, std = quality_mean_std(points, cells)
        quality_score.append(mean - 3.0 * std)
        if time.perf_counter() - last_log > 1.0:
            last_log = time.perf_counter()
            logger.info(
                "iteration %d of at most %d: %d points, largest move %.2e of the local size, %d triangulations, "
                "q mean-3std %.4f",
                iteration,
                max_iter,
                len(points),
                max_move,
                retriangulations,
                quality_score[-1],
            )
        stalled = len(quality_score) > stall_window and (
            max(quality_score[-stall_window:]) - max(quality_score[:-stall_window]) < STALL_GAIN
        )
        if (max_move < move_tolerance or stalled) and iteration >= settled_at + settle_wait:
            # before stopping, look with a fresh triangulation: points that crowd together
            # unseen (a stale point has no edge to its new neighbour) and boundary gaps that
            # opened late would stay as slivers; mend them and go on, a bounded number of times
            crowded, gaps = [], []
            if settle_rounds < max_settle_rounds:
                points, target = _without_points(points, target, parked, triangulation, lazy_distance)
                parked = _NO_INDICES
                triangulation.move_points(points)
                cells, edges, boundary = _mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
                last_triangulated = triangulation.positions
                crowded = _crowded_points(points, edges, target, n_fixed)
                gaps = _boundary_gaps(domain, points, boundary, target, finite_step, triangulation)
            if len(crowded) == 0 and len(gaps) == 0:
                stop_reason = "converged" if max_move < move_tolerance else "stalled"
                looked = settle_rounds < max_settle_rounds or touched_up
                break
            settle_rounds += 1
            points = _changed_points(points, crowded, gaps, triangulation, lazy_distance)
            target = size(points)
            cells, edges, boundary = _mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
            last_triangulated = triangulation.positions
            retriangulations += 1
            # the repairs are local: their neighbourhoods settle in a few iterations, while
            # waiting for a fresh stall window (5 to 20 iterations) cost a fifth of the run per round at 10**6 points
            settled_at, settle_wait = iteration, settle_iterations
            if len(crowded) + len(gaps) <= TOUCH_UP:
                # a boundary point or two shuffling along the boundary: the same one or two can
                # come back in every round (seen 5 rounds in a row at 10**5 points); mend once, stop
                settle_wait, settle_rounds, touched_up = TOUCH_UP_ITERATIONS, max_settle_rounds, True

    cells = edges = boundary = None  # the next step's peak memory is the run's: free what it does not use
    points, _ = _without_points(points, target, parked, triangulation, lazy_distance)
    triangulation.move_points(points)
    if not looked:
        # no fresh look before the stop (max_iter, or the settle rounds were spent; on coastlines
        # 8 to 300 points crowded since): they would leave near-flat cell pairs; one of each pair
        # goes. A touch-up's few iterations left none on disks of 10**4 to 10**6 points, where
        # this look cost 0.1 s at 10**6, so it counts as the look
        _, edges, _ = _mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
        crowded = _crowded_points(points, edges, size(points), n_fixed)
        if len(crowded):
            points = without_rows(points, crowded)
            triangulation.remove_points(crowded)
    record = dict(
        iterations=iteration,
        stop_reason=stop_reason,
        max_move=max_move,
        retriangulations=retriangulations,
        rebuilds=triangulation.rebuilds - rebuilds_at_start,
        seconds=time.perf_counter() - started,
    )
    return points, triangulation, record


def _finalize(domain, size, triangulation, points, n_fixed, tolerance, finite_step, n_held=None):
    """The final points' Delaunay cells inside the domain, made valid; the first ``n_fixed`` points stay.

    The smoothing leaves the first ``n_held`` points (default ``n_fixed``)
    where they are; those past ``n_fixed`` are still projected onto the
    boundary should they end on it off it (an adapted mesh's settled
    vertices).

    The triangulation's neighbour table gives the boundary in one pass; the
    general repair (the guide's deletion of cells at vertices with more
    than two boundary edges) runs only where that boundary is not manifold.
    Boundary vertices off the boundary are projected onto it; a cell that
    this folds, flattens along the boundary or takes across it (centroid
    outside) goes, and the repair and projection run again, until every
    boundary vertex is on the boundary, no two projected ones are closer
    than ``TWIN_REACH`` sizes along it, none hangs on another's edge and no
    two boundary edges cross.
    """
    cells, neighbors = triangulation.cells_and_neighbors()
    target = size(points)
    # exact where a decision needs the value (on the boundary, within NEAR_BOUNDARY sizes of it); farther
    # inside a bound serves: it proves cells inside and points interior
    limit = max(DISTANCE_REACH * float(np.min(target)), 2.0 * NEAR_BOUNDARY * float(np.max(target)))
    distance = _near_distance(domain, points, limit)
    keep = _inside(domain, points, cells, tolerance, distance if getattr(domain, "lipschitz", False) else None)
    on_boundary = np.abs(distance) <= NEAR_BOUNDARY * target
    keep &= ~_flat(domain, points, cells, on_boundary, n_fixed)
    # a triangulation's cells conform, and their neighbour table gives the boundary edges in one
    # pass where matching every edge took 43 ms a time at 660k cells (18 times on the guide's §5.3)
    cells, table = subset(cells, neighbors, keep)
    boundary = table_boundary_edges(cells, table)
    neighbors = None
    points = points.copy()
    projected = np.zeros(len(points), dtype=bool)  # in any pass so far
    for _ in range(MAX_REPAIR_PASSES):
        if not _manifold(boundary, len(points)):
            cells, table = _repaired(points, cells, table)
            boundary = _boundary(cells, table)
        _raise_if_no_cells(cells)
        vertices = sorted_unique(boundary)
        off = (np.abs(distance[vertices]) > tolerance) & (vertices >= n_fixed)
        # a boundary edge that a later pass's deletion leaves between two vertices projected close
        # together (0.16 sizes apart, q 0.19 on a coast jagged below the size): they merge, too
        ends, short = _short_boundary_edges(points, boundary, target)
        twins = sorted_unique(ends[short & projected[ends].any(axis=1)])
        twins = twins[twins >= n_fixed]
        if not off.any() and len(twins) == 0:
            # the last look, over the whole boundary: slits of no width (hanging nodes), closed, and
            # edges that a dropped cell laid open across others (where a projection had folded it, q -0.07;
            # across a cut 25 times thinner than the size), which the passes' look at moved vertices misses
            zipped = _zipped_slits(points, cells, boundary)
            if zipped is not cells:
                cells, table = zipped, None
                boundary = _boundary(cells, table)
                continue
            doomed = _crossing_cells(points, cells, boundary, vertices)
            if not doomed.any():
                break
            cells, table, boundary = _dropped(cells, table, doomed)
            continue
        moved = np.union1d(vertices[off], twins)
        projected[moved] = True
        deep = moved[distance[moved] <= -limit]  # a bound only: a boundary vertex that far in (a repair's)
        distance[deep] = domain.distance(points[deep])
        points[moved] = _project_to_boundary(domain, points[moved], distance[moved], finite_step)
        distance[moved] = domain.distance(points[moved])
        on_boundary[moved] = np.abs(distance[moved]) <= NEAR_BOUNDARY * target[moved]
        # a vertex projected onto another (a coastline's vertex, a fixed corner) becomes that one: its
        # cells follow, a cell of both goes as flat, and the repair mends the pinch this may leave
        merged = _merged_twins(points, cells, on_boundary, boundary, projected, target)
        touched = np.zeros(len(points), dtype=bool)
        touched[moved] = True
        touched = any_corner_in(touched, cells)
        if merged is not cells:
            table = None  # a merge can pinch an edge between more than two cells: no table from here on
            touched |= np.any(merged != cells, axis=1)  # a cell that a merge took onto land (q 0.91, centroid out)
            cells, boundary = merged, _boundary(merged, None)
        # a projection that folds a cell over its neighbour, lays one flat along the boundary
        # (three vertices onto one straight stretch of a coastline: q 1e-14 on the GSHHS coast)
        # or takes its centroid across the boundary (a cell over a headland): that cell goes,
        # and the loop repairs
        doomed = _flat(domain, points, cells, on_boundary, n_fixed)
        touched = np.flatnonzero(touched)
        doomed[touched] |= domain.distance(cell_centroids(points, cells, touched, 0)) > 0
        doomed[touched] |= _pushed_flat(points, cells[touched], moved, on_boundary)
        doomed |= _crossing_cells(points, cells, boundary, moved)
        if doomed.any():
            cells, table, boundary = _dropped(cells, table, doomed)
        # one Newton step may leave some off (a gridded distance bends between nodes): again; with all
        # on, the next pass looks for slits and ends
    else:
        _warn_if_off_boundary(points, sorted_unique(boundary), distance, tolerance, n_fixed, target, cells)
    points, cells, kept = remove_unused_points(points, cells)
    boundary = np.searchsorted(kept, boundary)  # boundary vertices are used: each is in ``kept`` (ascending)
    fixed = kept < (n_fixed if n_held is None else n_held)
    _check_repaired(points, cells, boundary)
    cells, recovered = recover_corners(points, cells, boundary, np.flatnonzero(kept < n_fixed), domain, size, tolerance)
    if recovered:  # a corner the cells had covered over is on the boundary again
        boundary = _boundary(cells, None)
        _check_repaired(points, cells, boundary)
    cells = _flipped_caps(domain, points, cells)  # interior edges: the boundary stays
    smoothed = Mesh(_smooth(domain, size, points, cells, boundary, fixed, tolerance, finite_step, limit), cells)
    return _check_boundary_edges(smoothed, boundary)


def _dropped(cells, table, doomed):
    """``(cells, table, boundary)`` without the ``doomed`` cells (a mask); ``table`` None where not conforming."""
    cells, table = (cells[~doomed], None) if table is None else subset(cells, table, ~doomed)
    return cells, table, _boundary(cells, table)


def _boundary(cells, table):
    """The boundary edges of ``cells``, from their neighbour ``table`` where known (None: not conforming)."""
    return boundary_edges(cells) if table is None else table_boundary_edges(cells, table)


def _repaired(points, cells, table):
    """``(cells, table)`` after the guide's deletion of cells at vertices with more than two boundary edges."""
    if table is None:
        return delete_interior_cells(points, cells), None
    return delete_interior_cells_with_table(points, cells, table)


def _short_boundary_edges(points, boundary, size):
    """``(ends, short)``: the ``boundary`` edges' ends in ascending order, and which are under ``TWIN_REACH`` sizes."""
    ends = np.sort(boundary, axis=1)
    length = np.sqrt(np.sum((points[ends[:, 0]] - points[ends[:, 1]]) ** 2, axis=1))
    return ends, length < TWIN_REACH * np.minimum(size[ends[:, 0]], size[ends[:, 1]])


def _merged_twins(points, cells, candidates, boundary, was_moved, size):
    """``cells`` with the vertices a projection put (next to) another one renumbered to that one.

    Each ``candidates`` vertex (a mask) at the exact spot of a lower-numbered
    one; and each vertex projected so far (``was_moved``, a mask) at the end
    of a ``boundary`` edge shorter than ``TWIN_REACH`` of its ``size`` (per
    vertex), merged into the other end (of two moved ends, into the
    lower-numbered). On a coast jagged below the size, a vertex beside an
    inlet projected 0.13 sizes from a fixed corner and left a cell of
    quality 0.17 between them.
    """
    numbering = lowest_twins(points, candidates)
    if len(boundary) and was_moved.any():
        ends, short = _short_boundary_edges(points, boundary, size)
        # the higher-numbered end goes where it moved; a lower-numbered one only if the other stayed
        goes_high = short & was_moved[ends[:, 1]]
        goes_low = short & ~goes_high & was_moved[ends[:, 0]]
        source = np.concatenate([ends[goes_high, 1], ends[goes_low, 0]])
        target = np.concatenate([ends[goes_high, 0], ends[goes_low, 1]])
        # one merge per vertex, and none into a vertex that goes itself (a chain along a jagged stretch)
        source, first = np.unique(source, return_index=True)
        target = target[first]
        keep = ~np.isin(target, source)
        numbering[source[keep]] = numbering[target[keep]]
    if np.array_equal(numbering, np.arange(len(points))):
        return cells
    return numbering[cells]


def _crossing_cells(points, cells, boundary, moved):
    """Mask of the cells to drop so that no boundary edge at a ``moved`` vertex crosses another.

    A vertex projected onto the coast next to another bank's vertex (0.02
    sizes apart where the Red Sea pinches, GSHHS at 10 km) left their
    boundary edges crossing and the cells beside them overlapping. Of each
    crossing pair, the smaller of the two cells on those edges goes; the
    repair mends the pinch this may leave.
    """
    doomed = np.zeros(len(cells), dtype=bool)
    touching = np.flatnonzero(np.isin(boundary, moved).any(axis=1))
    if len(touching) == 0:
        return doomed
    first, second = crossing_edges(points, boundary, touching)
    if len(first) == 0:
        return doomed
    owner_a, owner_b = cells_of_edges(cells, boundary[first]), cells_of_edges(cells, boundary[second])
    area = signed_areas(points, cells)
    doomed[np.where(area[owner_a] <= area[owner_b], owner_a, owner_b)] = True
    return doomed


def _zipped_slits(points, cells, boundary):
    """``cells`` with each slit of no width closed: the cell on an edge a boundary vertex hangs on, split there.

    A polygon corner at the tip of a spike of land thinner than rounding
    (a coast jagged below the size) left the boundary running out to it and
    back along the same line, the way back's vertex 1e-17 off the way out's
    edge: two cells on either side of a slit of no width, a hanging node
    (:func:`~terramesh.cleanup.validity.hanging_vertices`). The cell on the
    way out's edge ``(x, y)``, with third vertex ``z``, becomes ``(x, v, z)``
    and ``(v, y, z)`` at the hanging vertex ``v``: the two sides meet along
    ``(v, y)`` and the spike, narrower than rounding, is left out. (Dropping
    a cell instead laid an interior vertex open, whose projection onto the
    spike crossed edges and dropped the next cell, pass after pass.) Returns
    ``cells`` itself where nothing hangs.
    """
    vertex, host, _ = hanging_on_boundary(points, boundary)
    if len(vertex) == 0:
        return cells
    host, first = np.unique(host, return_index=True)  # one split per edge and per cell a pass
    vertex = vertex[first]
    owner, first = np.unique(cells_of_edges(cells, boundary[host]), return_index=True)
    host, vertex = host[first], vertex[first]
    corners = cells[owner]
    # the owner's corner where the edge starts: its cells run counter-clockwise, the edge with them
    start = np.argmax(corners == boundary[host, 0][:, None], axis=1)
    rows = np.arange(len(owner))
    x, y, z = (corners[rows, (start + k) % 3] for k in range(3))
    halves = np.concatenate([np.column_stack([x, vertex, z]), np.column_stack([vertex, y, z])])
    return np.concatenate([np.delete(cells, owner, axis=0), halves])


def _flat(domain, points, cells, on_boundary, n_fixed):
    """Mask of the cells to drop: flat (below ``FLAT_QUALITY``) with every vertex ``on_boundary``, or flat to rounding.

    Inverted cells count as flat to rounding. The flat cells of a fixed
    point (one of the first ``n_fixed``) whose cells are all flat and meet
    there at under ``ACUTE_CORNER`` degrees in all stay, where the domain's
    own corner there is that sharp too: they fill a corner of the domain
    sharper than about 10 degrees, whose cells are that thin (dropped, the
    corner vertex went with them, fixed or not, and the mesh stopped up to
    two sizes short of the tip). Slivers at a fixed point on a straighter
    boundary (a strip's cut point at a neck of a coast; a corner of 104
    degrees that one cell of q 0.01 reached along a coast jagged below the
    size) still go.
    """
    quality = triangle_qualities(points, cells)
    flat = (quality < FLAT_QUALITY) & all_corners_in(on_boundary, cells)
    if n_fixed and flat.any():
        every = np.bincount(cells.ravel(), minlength=n_fixed)[:n_fixed]
        flat_ones = np.bincount(cells[flat].ravel(), minlength=n_fixed)[:n_fixed]
        alone = np.zeros(len(points), dtype=bool)
        alone[:n_fixed] = (every > 0) & (flat_ones == every)
        at_alone = np.flatnonzero(flat & any_corner_in(alone, cells))
        if len(at_alone):
            corner = cells[at_alone]
            # the angle of each of these cells at each of its corners, summed per vertex
            a, b, c = (points[corner[:, k]] for k in range(3))
            angles = np.column_stack([_angle(a, b, c), _angle(b, c, a), _angle(c, a, b)])
            total = np.bincount(corner.ravel(), weights=angles.ravel(), minlength=len(points))
            acute = alone & (total < np.radians(ACUTE_CORNER))
            if acute.any():
                tips = np.flatnonzero(acute)
                shortest = np.full(len(points), np.inf)  # each tip's shortest edge, where it probes the domain
                for k in range(3):
                    at = corner[:, k]
                    for other in (corner[:, (k + 1) % 3], corner[:, (k + 2) % 3]):
                        np.minimum.at(shortest, at, np.sqrt(np.sum((points[other] - points[at]) ** 2, axis=1)))
                acute[tips] = _inside_angle(domain, points[tips], 0.25 * shortest[tips]) < ACUTE_CORNER
            flat[at_alone[any_corner_in(acute, corner)]] = False
    return (quality < DEGENERATE_QUALITY) | flat


def _pushed_flat(points, cells, moved, on_boundary):
    """Mask of ``cells`` flat (below ``FLAT_QUALITY``), widest at a ``moved`` vertex, and not all ``on_boundary``.

    A vertex projected onto a coast jagged below the size can land on the
    far edge of its own cell: the cell lies flat between two boundary
    vertices and an interior one beyond them (q 0.06). Smoothing cannot
    lift it, as the way out takes its centroid onto land; it goes, and the
    interior vertex joins the boundary. Flat cells with every vertex on the
    boundary are :func:`_flat`'s (a sharp corner's stay).
    """
    quality = triangle_qualities(points, cells)
    flat = np.flatnonzero((quality < FLAT_QUALITY) & ~all_corners_in(on_boundary, cells))
    if len(flat) == 0:
        return np.zeros(len(cells), dtype=bool)
    corners = cells[flat]
    widest = corners[np.arange(len(flat)), _widest_corner(points, corners)]
    pushed = np.zeros(len(cells), dtype=bool)
    pushed[flat[np.isin(widest, moved)]] = True
    return pushed


def _flipped_caps(domain, points, cells, passes=3):
    """``cells`` with the long edge of each cap (a cell below ``FLAT_QUALITY``) flipped, where that helps.

    A boundary vertex projected onto a coast jagged below the size can land
    on the far edge of its own cell, half a size from an interior vertex:
    a cap, flat with its widest angle at that vertex (q 0.02 and 0.15 on
    two such coasts), which smoothing cannot lift, as the way out takes a
    centroid onto land. The cap and its neighbour across the long edge
    become the two cells on the other diagonal of their quadrilateral
    where the worse of the two is better than before and both centroids
    are inside the domain. Of flips that share a cell, the one of the worst
    pair goes ahead (:func:`_worst_first`), and up to ``passes`` passes run
    (a flip can leave the next cap beside it). The boundary is
    unchanged: a long edge on it has no neighbour and stays. Returns
    ``cells`` itself where nothing flips.
    """
    for _ in range(passes):
        quality = triangle_qualities(points, cells)
        caps = np.flatnonzero(quality < FLAT_QUALITY)
        if len(caps) == 0:
            return cells
        corners = cells[caps]
        widest = _widest_corner(points, corners)
        apex, a, b = (corners[np.arange(len(caps)), (widest + k) % 3] for k in range(3))
        other = cells_of_edges(cells, np.column_stack([b, a]), missing=-1)
        inner = other >= 0
        caps, apex, a, b, other = caps[inner], apex[inner], a[inner], b[inner], other[inner]
        beyond = cells[other]
        far = np.max(np.where((beyond != a[:, None]) & (beyond != b[:, None]), beyond, -1), axis=1)
        first, second = np.column_stack([apex, a, far]), np.column_stack([apex, far, b])
        before = np.minimum(quality[caps], quality[other])
        better = np.minimum(triangle_qualities(points, first), triangle_qualities(points, second)) > before
        take = np.flatnonzero(better)
        # centroids inside as the smoothing judges them (strictly): else it would freeze these cells
        take = take[
            _inside(domain, points, np.concatenate([first[take], second[take]]), 0.0).reshape(2, -1).all(axis=0)
        ]
        take = _worst_first(take[np.argsort(before[take], kind="stable")], caps, other, len(cells))
        if len(take) == 0:
            return cells
        cells = cells.copy()
        cells[caps[take]] = first[take]
        cells[other[take]] = second[take]
    return cells


def _widest_corner(points, corners):
    """Which corner (0, 1, 2) of each triangle ``corners`` (rows of vertex indices) lies across its longest edge."""
    opposite = [
        np.sum((points[corners[:, (k + 1) % 3]] - points[corners[:, (k + 2) % 3]]) ** 2, axis=1) for k in range(3)
    ]
    return np.argmax(np.column_stack(opposite), axis=1)


def _worst_first(proposals, first, second, n_cells):
    """The ``proposals`` (flips of cells ``first[k]`` and ``second[k]``, worst pair first) that go ahead.

    Worst first, each cell in one flip: a flip goes ahead where it is the
    first of the proposals left that want either of its cells, and those
    that want a cell taken drop out; again, until none is left (two caps on
    one long edge are one flip). Taking only the first round's left a
    proposal waiting for a worse one that was itself refused.
    """
    taken = []
    while len(proposals):
        rank = np.arange(len(proposals))
        earliest = np.full(n_cells, len(proposals), dtype=np.int64)
        np.minimum.at(earliest, first[proposals], rank)
        np.minimum.at(earliest, second[proposals], rank)
        goes = (earliest[first[proposals]] == rank) & (earliest[second[proposals]] == rank)
        taken.append(proposals[goes])
        busy = np.zeros(n_cells, dtype=bool)
        busy[first[proposals[goes]]] = busy[second[proposals[goes]]] = True
        proposals = proposals[~(busy[first[proposals]] | busy[second[proposals]])]
    return np.sort(np.concatenate(taken)) if taken else proposals


def _inside_angle(domain, centres, radius, directions=64):
    """Degrees of the circle of ``radius`` around each of ``centres`` inside the domain (``directions`` probes)."""
    turn = (np.arange(directions) + 0.5) * (2 * np.pi / directions)
    probes = centres[:, None, :] + radius[:, None, None] * np.stack([np.cos(turn), np.sin(turn)], axis=-1)
    inside = domain.distance(probes.reshape(-1, 2)).reshape(len(centres), directions) < 0
    return 360.0 * inside.mean(axis=1)


def _angle(at, one, other):
    """The angle at ``at`` between the directions to ``one`` and ``other``, radians, per row."""
    u, v = one - at, other - at
    return np.arctan2(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]), np.einsum("ij,ij->i", u, v))


def _raise_if_no_cells(cells):
    """Raise a GenerationError where no cell is left (2D or 3D): the domain is too small or thin for the size."""
    if len(cells) == 0:
        raise GenerationError("no cell survived: the domain is too small or thin for the mesh size")


def _warn_if_off_boundary(points, vertices, distance, tolerance, n_fixed, target, cells):
    """Warn of the boundary ``vertices`` still off the boundary after the last repair pass, and where.

    A corner the domain does not report (two disks' union as one callable:
    its boundary vertex there stayed 0.043 sizes inside) draws the
    projections back and forth across it; the README promises boundary
    vertices on the boundary. One more than ``HOLE_OFF`` sizes off is a hole
    in the mesh or cells over a slot, and is refused (:func:`_check_repaired`).
    """
    off = vertices[(np.abs(distance[vertices]) > tolerance) & (vertices >= n_fixed)]
    if len(off):
        worst = off[np.argmax(np.abs(distance[off]) / target[off])]
        if abs(distance[worst]) > HOLE_OFF * target[worst]:
            _check_repaired(
                points,
                cells,
                boundary_edges(cells),
                [
                    f"a boundary vertex {abs(distance[worst]) / target[worst]:.2g} sizes off the domain's boundary at"
                    f" {_at(points[worst])} after {MAX_REPAIR_PASSES} repair passes (a hole in the mesh, or cells"
                    " across a slot)"
                ],
            )
        warn_user(
            f"{len(off)} {OFF_BOUNDARY} {MAX_REPAIR_PASSES} repair passes, "
            f"up to {abs(distance[worst]) / target[worst]:.2g} sizes at {_at(points[worst])}: a corner the domain "
            "does not report (give it as a fixed point, or combine the shapes with | & - so that it is found)"
        )


def _check_repaired(points, cells, boundary, problems=()):
    """Raise a GenerationError that says what and where, if the repaired mesh has a flat or inverted cell or a pinch.

    The cells are a subset of one triangulation whose points are distinct, so
    they are conforming with no duplicate cells or vertices by construction;
    what the repairs and projections could still break is checked here and,
    once smoothed, by :func:`_check_boundary_edges`
    (:func:`~terramesh.cleanup.mesh_problems` checks everything, slower).
    ``problems`` found before (a hole) are said too.
    """
    problems = list(problems)
    flat = np.flatnonzero(triangle_qualities(points, cells) <= 0)
    if len(flat):
        where = points[cells[flat[0]]].mean(axis=0)
        problems.append(f"{len(flat)} cells that are clockwise or flat (one at {_at(where)})")
    pinched = _pinched(boundary, len(points))
    if len(pinched):
        problems.append(
            f"{len(pinched)} boundary vertices without exactly two boundary edges (one at {_at(points[pinched[0]])})"
        )
    if problems:
        raise GenerationError(
            "mesh generation produced an invalid mesh: " + "; ".join(problems) + ". A part of the domain narrower "
            "than about an edge length (a neck, a channel, two coasts almost touching) cannot be meshed at this "
            "size: a smaller edge length there, or another seed, may help"
        )


def _check_boundary_edges(mesh, boundary):
    """Raise a GenerationError where the smoothed ``mesh``'s ``boundary`` edges cross or hang on each other.

    A slot narrower than the size left cells overlapping by 3e-6 of a 2 x 1
    rectangle, and a 3 mm slit at UTM coordinates its sides' vertices on
    each other's edges (hanging nodes); both were returned. Rounding where a
    neck pinches to nothing is forgiven, as :func:`~terramesh.cleanup.mesh_problems` forgives it.
    """
    problems = []
    if len(crossing_edges(mesh.points, boundary)[0]):
        problems += _overlap_problems(mesh.points, mesh.cells)
    hanging = hanging_on_boundary(mesh.points, boundary)[0]
    if len(hanging):
        problems.append(f"{len(hanging)} hanging nodes (one at {_at(mesh.points[hanging[0]])})")
    if problems:
        _check_repaired(mesh.points, mesh.cells, boundary, problems)
    return mesh


def _pinched(boundary, n_points):
    """The vertices with neither zero nor two of the ``boundary`` edges."""
    degree = np.bincount(boundary.ravel(), minlength=n_points)
    return np.flatnonzero((degree != 0) & (degree != 2))


def _manifold(boundary, n_points):
    """Whether every vertex has zero or two of the ``boundary`` edges."""
    return len(_pinched(boundary, n_points)) == 0


def _at(point):
    """``point`` for a message: its coordinates to six significant digits."""
    return "(" + ", ".join(f"{float(x):.6g}" for x in point) + ")"


def _smooth(domain, size, points, cells, boundary, fixed, tolerance, finite_step, limit):
    """Quality-safe smoothing: boundary vertices slide along the boundary, then ``POLISH_PASSES`` over the interior.

    A boundary vertex (not a fixed one) moves to the boundary point between
    its two boundary neighbours that splits their distance in the ratio of
    their sizes, or halfway to it, where that raises the worst quality of
    its cells. Interior vertices move to the mean of their neighbours
    where that keeps it. Neither knows the domain: next to a concave
    stretch of boundary a move can take a cell's centroid outside. The
    vertices of such cells are frozen and the smoothing runs again from the
    start (deterministic; one more run at most in practice); so are the
    ends of boundary edges a slide made cross another (onto the far bank of
    a strait narrower than a cell), and a vertex a slide left on another's
    boundary edge with the ends of both edges, that one and its own that
    runs back along it (a hanging node along a spike of land thinner than
    rounding). The points' distances bound the cells'
    only where they are within ``limit`` of it.
    """
    lipschitz = getattr(domain, "lipschitz", False)
    distance = domain.distance_within(points, limit) if lipschitz else None
    sliding, candidates = _boundary_candidates(domain, size, points, boundary, fixed, tolerance, finite_step)
    movable = ~fixed
    movable[boundary.ravel()] = False
    holes = _three_vertex_holes(boundary, len(points))
    for _ in range(3):
        smoothed = points.copy()
        move_where_better(smoothed, cells, sliding, candidates)
        smooth_interior(smoothed, cells, movable, POLISH_PASSES)
        raise_worst(smoothed, cells, movable, POOR_QUALITY, POLISH_PASSES)
        bound = distance + row_norms(smoothed - points) if lipschitz else None
        outside = ~_inside(domain, smoothed, cells, 0.0, bound)
        # a slide onto the other bank of a strait narrower than a cell (the nearest boundary point is
        # there) crossed two boundary edges: cells overlapped, every cell still counter-clockwise
        slid = np.flatnonzero(np.any(smoothed[boundary] != points[boundary], axis=(1, 2)))
        first, second = crossing_edges(smoothed, boundary, slid) if len(slid) else (_NO_INDICES, _NO_INDICES)
        # a hole of three vertices (a sliver of land between coast segments nearly touching) turns inside
        # out without any edges crossing when a vertex slides across the other two's edge: the cells round
        # it then lie over each other (the Chesapeake at 2 km, seed 1)
        turned = holes[np.sign(signed_areas(smoothed, holes)) != np.sign(signed_areas(points, holes))]
        # a slide along a spike of land thinner than rounding put a vertex on the edge that runs back
        # beside it: a slit of no width, a hanging node (a coast of roughness 1.07)
        hanging, host, back = hanging_on_boundary(smoothed, boundary) if len(slid) else (_NO_INDICES,) * 3
        if not outside.any() and len(first) == 0 and len(turned) == 0 and len(hanging) == 0:
            return smoothed
        frozen = np.zeros(len(points), dtype=bool)
        frozen[cells[outside].ravel()] = True
        frozen[turned.ravel()] = True
        frozen[boundary[np.concatenate([first, second])].ravel()] = True
        frozen[boundary[np.concatenate([host, back])].ravel()] = True  # the hanging vertex ends its edge back
        movable &= ~frozen
        keep = ~frozen[sliding]
        sliding, candidates = sliding[keep], candidates[keep]
    return points


def _three_vertex_holes(boundary, n_points):
    """The boundary loops of three vertices, shape (k, 3), each in its loop's (directed) order.

    Boundary vertices have one outgoing boundary edge each (the mesh is
    manifold by then), so a loop of three is an edge whose head's next but
    one is its tail; each loop is listed once, from its lowest vertex.
    """
    following = np.full(n_points, -1, dtype=np.int64)
    following[boundary[:, 0]] = boundary[:, 1]
    tail, head = boundary[:, 0], boundary[:, 1]
    third = following[head]
    closed = (third >= 0) & (following[np.maximum(third, 0)] == tail) & (tail < head) & (tail < third)
    return np.column_stack([tail[closed], head[closed], third[closed]])


def _boundary_candidates(domain, size, points, boundary, fixed, tolerance, finite_step):
    """The non-fixed boundary vertices and two places on the boundary to try for each, shape (k, 2, 2)."""
    from scipy.spatial import cKDTree

    after = np.full(len(points), -1, dtype=np.int64)
    before = np.full(len(points), -1, dtype=np.int64)
    after[boundary[:, 0]] = boundary[:, 1]
    before[boundary[:, 1]] = boundary[:, 0]
    sliding = np.flatnonzero((after >= 0) & ~fixed)
    here, last, following = points[sliding], points[before[sliding]], points[after[sliding]]
    size_last, size_next = size(last), size(following)
    between = last + (following - last) * (size_last / (size_last + size_next))[:, None]
    target = _project_to_boundary(domain, between, domain.distance(between), finite_step)
    halfway = 0.5 * (here + target)
    halfway = _project_to_boundary(domain, halfway, domain.distance(halfway), finite_step)
    candidates = np.stack([target, halfway], axis=1)
    # a candidate the projection left off the boundary (near a corner of it, say) is not tried, nor
    # one on another vertex or on another vertex's candidate (a fixed corner, a coastline's vertex
    # both sides project onto): two vertices could end there
    flat = candidates.reshape(-1, 2)
    off = np.abs(domain.distance(flat)).reshape(-1, 2) > tolerance
    occupied = cKDTree(points[sorted_unique(boundary)]).query(flat)[0].reshape(-1, 2) <= tolerance
    occupied &= np.any(candidates != here[:, None, :], axis=2)
    pairs = cKDTree(flat).query_pairs(tolerance, output_type="ndarray")
    pairs = pairs[pairs[:, 0] // 2 != pairs[:, 1] // 2]  # a vertex's own two candidates may coincide
    shared = np.zeros(len(flat), dtype=bool)
    shared[pairs.ravel()] = True
    skip = off | occupied | shared.reshape(-1, 2)
    candidates[skip] = np.repeat(here[:, None, :], 2, axis=1)[skip]
    return sliding, candidates
