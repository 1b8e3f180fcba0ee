"""The force iterations: points moved by truss forces until they stop, triangulated again as they go.

:func:`relax` is DistMesh's loop (Persson & Strang 2004): each iteration
moves the points along the net force of their edges' springs (all at once,
or in Gauss-Seidel sweeps), projects the points that left the domain back
onto its boundary, and retriangulates when enough points moved a tenth of a
size. Crowded points are thinned and boundary gaps filled as it goes, and
once more before it stops.
"""

import logging
import time
import weakref

import numpy as np

from .._kernels.chunks import CHUNKS
from .._kernels.forces import (
    count_far,
    force_step,
    largest_interior_move,
    neighbor_lists,
    rest_length_scale,
    short_edge_ends,
    sweep_step,
)
from .._kernels.topology import quality_mean_std, rows_renumbered
from ..mesh.topology import NO_INDICES, coincident_points, without_rows
from .cells_inside import mesh_edges
from .distances import LazyDistance, project_to_boundary

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
STALE_ALLOWED_STEPPED = 0.03  # ...and in simultaneous steps (one level, refined levels), see relax
GAP_RATIO = 1.3  # a boundary edge longer than this many local sizes gets a point in its middle
STALL_WINDOW = 20  # iterations in which the best mean - 3 std of the quality must improve...
SWEPT_STALL_WINDOW = 10  # ...or this many where Gauss-Seidel sweeps move the points (they anneal sooner)...
REFINED_STALL_WINDOW = 5  # ...or this many at a level started from a refined coarser mesh (nearly in equilibrium)
STALL_GAIN = 1e-2  # ...by at least this much, or generation stops as stalled (the final smoothing does the rest)
DENSITY_CONTROL_EVERY = 10  # iterations between removals of crowded points (Persson 2005)


NO_POINTS = np.empty((0, 2))  # an empty result, one rather than one per call


def relax(
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
    lazy_distance = LazyDistance(domain)
    settle_rounds, settled_at, settle_wait = 0, 0, 0
    rebuilds_at_start, rebuilds_seen = triangulation.rebuilds, 0  # one triangulation throughout: the points match it
    sweeps = _Sweeps(finite_step) if sweep else None
    # points projected onto another one's spot wait where they were, out of the forces, until the
    # points change anyway (removed at once, each cost passes over every array: 5 of a coast's 11 ms
    # per iteration)
    parked = NO_INDICES
    # a sweep anneals from the topology it is given, and stale edges let an arrangement wander (at 3 %
    # the graded 10**4 disk took 35 sweeps, not 33, and 10-20 % longer). Simultaneous steps on a coastline
    # keep moving a few boundary points a tenth of a size: at 0.2 % the GSHHS coast at 0.1 degrees
    # triangulated in 117 of 125 iterations, at 3 % in 30 of 114, twice as fast, as good a mesh
    stale_allowed = STALE_ALLOWED if sweep else STALE_ALLOWED_STEPPED

    for iteration in range(1, int(max_iter) + 1):
        if count_far(points, last_triangulated, target, RETRIANGULATE_AFTER) > stale_allowed * len(points):
            cells = edges = boundary = None  # freed before their successors exist: lower peak memory
            points, target = _without_points(points, target, parked, triangulation, lazy_distance)
            parked = NO_INDICES
            triangulation.move_points(points)
            sides = {}
            cells, edges, boundary = mesh_edges(domain, triangulation, points, tolerance, lazy_distance, record=sides)
            gaps = _boundary_gaps(domain, points, boundary, target, finite_step, triangulation)
            if len(gaps):  # insertions only: the cells they leave alone keep their sides
                points = changed_points(points, NO_INDICES, gaps, triangulation, lazy_distance)
                target = np.concatenate([target, size(gaps)])  # the others did not move
                cells, edges, boundary = mesh_edges(
                    domain, triangulation, points, tolerance, lazy_distance, earlier=sides
                )
            sides = None
            last_triangulated = triangulation.positions
            retriangulations += 1
        elif iteration % DENSITY_CONTROL_EVERY == 0:
            crowded = np.union1d(_crowded_points(points, edges, target, n_fixed), parked)
            parked = NO_INDICES
            if len(crowded):
                points, target = _without_points(points, target, crowded, triangulation, lazy_distance)
                cells, edges, boundary = mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
                last_triangulated = triangulation.positions
                retriangulations += 1
        if triangulation.rebuilds > rebuilds_seen:  # only a rebuild lets points coincide exactly
            n_points = len(points)
            points, target = _without_duplicates(points, target, triangulation, lazy_distance, n_fixed)
            if len(points) < n_points:
                cells, edges, boundary = mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
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
            points[outside] = project_to_boundary(
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
                doubled, parked = np.union1d(doubled, parked), NO_INDICES
                cells, edges, boundary = _without_vertices(doubled, len(points), cells, edges, boundary)
                points = changed_points(points, doubled, NO_POINTS, triangulation, lazy_distance)
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
                parked = NO_INDICES
                triangulation.move_points(points)
                cells, edges, boundary = mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
                last_triangulated = triangulation.positions
                crowded = _crowded_points(points, edges, target, n_fixed)
                gaps = _boundary_gaps(domain, points, boundary, target, finite_step, triangulation)
            if len(crowded) == 0 and len(gaps) == 0:
                stop_reason = "converged" if max_move < move_tolerance else "stalled"
                looked = settle_rounds < max_settle_rounds or touched_up
                break
            settle_rounds += 1
            points = changed_points(points, crowded, gaps, triangulation, lazy_distance)
            target = size(points)
            cells, edges, boundary = mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
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
        _, edges, _ = mesh_edges(domain, triangulation, points, tolerance, lazy_distance)
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
        return NO_POINTS
    middle = 0.5 * (start[gap] + end[gap])
    middle = project_to_boundary(domain, middle, domain.distance(middle), finite_step)
    middle = without_rows(middle, coincident_points(middle))
    return middle[triangulation.nearest_distances(middle) > 0]


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


def changed_points(points, removed, added, triangulation, lazy_distance):
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
    return changed_points(points, removed, NO_POINTS, triangulation, lazy_distance), np.delete(target, removed)
