"""Anisotropic triangle meshes: DistMesh's force equilibrium with every length measured in a metric.

The method (Persson & Strang 2004 with lengths and the Delaunay test taken
in a metric, as the seismic talk's "Anisotropy" slide asks):

1. Start from :func:`~terramesh.generation.generate_mesh`'s isotropic mesh
   at the size of the metric's point density, ``sqrt(major * minor)``: the
   right number of points, well spread, on the boundary where it bends.
2. Every ``DENSITY_EVERY`` iterations, Persson's density control in the
   metric: an edge shorter than ``SHORT`` loses an end, one longer than
   ``LONG`` gains its midpoint, and the points are triangulated again
   (Delaunay, repaired from the last triangulation; the cells whose
   centroid is inside), as they also are when a cell at the boundary has
   slid out of the domain.
3. Flip every inner edge that fails the metric Delaunay test (the angles
   facing it sum to more than pi in the metric).
4. Move every point by its springs, each of rest length 1 in the metric:
   they push when shorter and pull when longer (the density control sets
   the number of points, so no pressure is needed to fill the domain).
   Boundary vertices are projected back along the metric's normal; a point
   pushed across a boundary edge joins the boundary there; any other move
   that would turn a cell over is held back; fixed points stay.
5. Repeat from 2 until no interior point moves more than ``move_tolerance``
   (metric units) or the quality (mean - 3 std, measured in the metric)
   stops improving; the iterate with the best worst cell is returned, made
   valid (and checked).
6. Where no iterate can be made valid (a boundary more jagged than the
   cells are long), mesh again with the metric's cells rounder within two
   long sizes of the boundary, at most 3:1 and then 1:1, and warn.
"""

import logging
import time

import numpy as np
from scipy.spatial import cKDTree

from .._kernels import metric as _kernel
from .._kernels import threads_for
from .._kernels.topology import inner_cell_edges
from ..cleanup.fix_mesh import delete_interior_cells, delete_interior_cells_with_table, remove_unused_points
from ..cleanup.validity import cells_outside, mesh_problems
from ..errors import GenerationError, checked_number, muted_warnings, warn_user
from ..geometry.base import as_bbox, as_domain, distance_and_gradient
from ..mesh import Mesh
from ..mesh.columns import row_norms
from ..mesh.topology import (
    any_corner_in,
    boundary_edges,
    cell_centroids,
    cell_neighbor_table,
    checked_fixed_points,
    kept_cells,
)
from ..sizing.metric import as_metric_function, mean_size, metric_sizes, metric_tensor
from .distances import finite_difference_step, project_to_boundary
from .distmesh import generate_mesh
from .fixed_points import CORNERS_DISPLACED, FIXED_NEAR_BOUNDARY, warn_if_fixed_points_crowd_the_boundary
from .mesh_checks import FIXED_DROPPED, warn_if_fixed_points_dropped
from .options import BOUNDARY_TOLERANCE, checked_max_iter
from .triangulate import Triangulation, delaunay_with_neighbors

__all__ = ["generate_anisotropic_mesh"]

logger = logging.getLogger("terramesh.generation")

TIME_STEP = 0.2  # fraction of the net force a point moves per iteration (Persson & Strang)
STALL_WINDOW = 25  # iterations without a gain of STALL_GAIN in mean - 3 std of the metric quality: stalled
STALL_GAIN = 0.005
MAX_FLIP_PASSES = 500  # a metric varying from cell to cell can make a few quads flip back and forth
FLIP_SLACK = 1e-3  # sin(alpha + beta) below which an edge flips
MAX_SNAP_PASSES = 3  # last passes putting boundary vertices onto the boundary, cells that this spoils removed
NEWTON_STEP_LIMIT = 3.0  # a projection's Newton step is at most this many of the point's distances long
ON_BOUNDARY = 1e-3  # a projected point farther than this many tolerances from the boundary is projected again
MAX_HOLD_ROUNDS = 20  # rounds of joins and holding back; then no point joins (see _moved)
DENSITY_EVERY = 10  # iterations between Persson's density controls
CORNER_ANGLE = 120.0  # degrees, in the metric: polygon vertices sharper than this are fixed (the plane's default)
BOUNDARY_RATIOS = (3.0, 1.0)  # the longest over the shortest size tried at the boundary where the metric fails...
BOUNDARY_BAND = 2.0  # ...fading to the metric's own this many long sizes inside
SHORT, LONG = 0.7, 1.42  # metric edge lengths that lose an end or gain a midpoint: 1 / sqrt(2) and sqrt(2)


def generate_anisotropic_mesh(
    domain, metric, *, bbox=None, fixed_points=None, max_iter=300, move_tolerance=1e-3, seed=0, relax_boundary=True
):
    """Generate a triangle mesh whose cells follow a metric: long along one direction, short across it.

    Parameters
    ----------
    domain : Domain or callable
        Signed distance function (negative inside) of a 2D domain with a
        ``bbox``; see :mod:`terramesh.geometry`.
    metric : callable or array_like, shape (2, 2)
        The metric at an ``(n, 2)`` array of points, ``(n, 2, 2)``
        symmetric positive definite matrices (see
        :func:`~terramesh.sizing.metric_tensor`, which builds them from the
        sizes wanted along and across a direction), or one matrix for the
        whole domain. Edges come out of length 1 measured in it.
    bbox : array_like, shape (2, 2), optional
        Region to mesh; defaults to the domain's.
    fixed_points : array_like, shape (k, 2), optional
        Points that must be vertices and never move; the domain's sharp
        corners are always added.
    max_iter : int, optional
        Most anisotropic iterations (after the isotropic start).
    move_tolerance : float, optional
        Convergence: stop when no interior point moved more than this, in
        the metric's units (fractions of the local edge length), in an
        iteration. Generation also stops, as "stalled", when the quality
        measured in the metric (mean - 3 std) gained less than 0.005 in 25
        iterations.
    seed : int, optional
        Seed of the isotropic start; the same inputs and seed give the same mesh.
    relax_boundary : bool, optional
        Where the metric as given cannot make a valid mesh (a boundary
        more jagged than the cells are long: notches, spikes, a random
        coast), mesh again with cells at most 3 times as long as they are
        wide within two long sizes of the boundary, then round ones there
        (the short size kept, the metric unchanged farther in), and warn.
        False raises at once. In ``benchmarks/sweep_validity.py aniso`` 42
        of 240 runs needed it.

    Returns
    -------
    Mesh
        Valid mesh (counter-clockwise cells, no unused vertices, manifold
        boundary on the domain boundary). ``mesh.info`` holds
        ``iterations``, ``stop_reason`` (``"converged"``, ``"stalled"`` or
        ``"max_iter"``), ``kept_iteration`` (the iterate returned: the one
        with the best worst cell), ``max_move`` (metric units),
        ``retriangulations``, ``flips``, ``start`` (the isotropic start's
        info), ``boundary_ratio`` (the longest over shortest size allowed
        at the boundary where ``relax_boundary`` had to, else None) and
        ``seconds``.
        Measure the result with :func:`~terramesh.quality.metric_quality` and
        :func:`~terramesh.quality.metric_edge_lengths`.

    Raises
    ------
    GenerationError
        For a domain that is not 2D, bad options, or a mesh that could not
        be made valid (with ``relax_boundary``, not even with round cells
        at the boundary).
    SizingError
        For a metric that is not a field of symmetric positive definite
        matrices (NaN, wrong shape, a size of zero).

    See Also
    --------
    generate_mesh : The isotropic generator (one size, every direction).

    Examples
    --------
    >>> import numpy as np
    >>> import terramesh as tm
    >>> square = tm.geometry.Rectangle((0, 0), (1, 1))
    >>> metric = tm.sizing.metric_tensor(0.2, 0.05, 0.0)   # cells 0.2 along x, 0.05 along y
    >>> mesh = tm.generation.generate_anisotropic_mesh(square, metric, seed=0)
    >>> lengths = tm.quality.metric_edge_lengths(mesh.points, mesh.cells, metric)
    >>> bool(0.85 < np.median(lengths) < 1.15)
    True
    """
    started = time.perf_counter()
    domain = as_domain(domain, bbox)
    if domain.dim != 2:
        raise GenerationError(f"generate_anisotropic_mesh meshes 2D domains, got dim={domain.dim}")
    bbox = domain.bbox if bbox is None else as_bbox(bbox, dim=2)
    metric_at = as_metric_function(metric)
    max_iter = checked_max_iter(max_iter)
    checked_number(
        move_tolerance, "move_tolerance must be positive (metric units)", GenerationError, minimum=0, strict=True
    )
    if fixed_points is not None:
        fixed_points = checked_fixed_points(fixed_points, 2, GenerationError)
    if fixed_points is not None and len(fixed_points):
        # once, here: the start's runs mute it, the metric's corners being among their fixed points
        size = mean_size(metric_at(fixed_points))
        warn_if_fixed_points_crowd_the_boundary(
            domain, fixed_points, lambda p: mean_size(metric_at(p)), BOUNDARY_TOLERANCE * float(size.min())
        )
    options = dict(bbox=bbox, fixed_points=fixed_points, max_iter=max_iter, move_tolerance=move_tolerance, seed=seed)
    try:
        mesh, boundary_ratio = _generated(domain, metric_at, **options), None
    except _InvalidMesh as error:
        if not relax_boundary:
            raise GenerationError(str(error)) from None
        mesh, boundary_ratio = _with_relaxed_boundary(domain, metric_at, error, options)
    mesh.info.update(boundary_ratio=boundary_ratio, seconds=time.perf_counter() - started)
    if fixed_points is not None:
        warn_if_fixed_points_dropped(mesh, fixed_points, BOUNDARY_TOLERANCE * mesh.info["start"]["h0"])
    logger.info(
        "anisotropic mesh: %d iterations (%s), %d vertices, %d cells in %.2f s",
        mesh.info["iterations"],
        mesh.info["stop_reason"],
        mesh.n_points,
        mesh.n_cells,
        mesh.info["seconds"],
    )
    return mesh


class _InvalidMesh(GenerationError):
    """The mesh could not be made valid: what :func:`generate_anisotropic_mesh` meets again with a relaxed metric.

    ``points`` are the last candidate's: where the metric is sampled to
    tell whether relaxing it would change anything.
    """

    def __init__(self, message, points):
        super().__init__(message)
        self.points = points


def _with_relaxed_boundary(domain, metric_at, error, options):
    """The mesh of ``metric_at`` made rounder near the boundary, at the first of ``BOUNDARY_RATIOS`` that is valid.

    Returns the mesh and the ratio. A ratio the metric does not exceed
    near the boundary (at the failed candidate's points) is skipped: the
    same metric would fail the same way. Raises a GenerationError with
    ``error``'s message, and the ratios tried, when none gives a valid mesh.
    """
    major, minor, _ = metric_sizes(metric_at(error.points))
    near = domain.distance(error.points) > -BOUNDARY_BAND * major
    stretch = float((major / minor)[near].max(initial=1.0))
    tried = []
    for ratio in (ratio for ratio in BOUNDARY_RATIOS if ratio < stretch):
        logger.info("anisotropic mesh: again, with %s at the boundary (%s)", _cells_at_most(ratio), error)
        try:
            mesh = _generated(domain, _relaxed_near(domain, metric_at, ratio), **options)
        except _InvalidMesh:
            tried.append(_cells_at_most(ratio))
            continue
        warn_user(
            f"{error}; meshed with {_cells_at_most(ratio)} within {BOUNDARY_BAND:g} long sizes of the boundary "
            "instead (relax_boundary=False raises)"
        )
        return mesh, ratio
    nor = f"; nor with {' or '.join(tried)} within {BOUNDARY_BAND:g} long sizes of the boundary" if tried else ""
    raise GenerationError(f"{error}{nor}") from None


def _cells_at_most(ratio):
    """How the warning and the error name a boundary ratio."""
    return "round cells" if ratio == 1 else f"cells at most {ratio:g}:1"


def _relaxed_near(domain, metric_at, ratio):
    """``metric_at`` with its long size at most ``ratio`` times its short one at the boundary.

    The limit fades linearly to none ``BOUNDARY_BAND`` long sizes inside;
    the short size and the direction stay.
    """

    def relaxed(points):
        metric = metric_at(points)
        major, minor, angle = metric_sizes(metric)
        inside = np.clip(-domain.distance(points) / (BOUNDARY_BAND * major), 0.0, 1.0)
        limit = np.minimum(major, ratio * minor)
        return metric_tensor(limit + inside * (major - limit), minor, angle)

    return relaxed


def _generated(domain, metric_at, *, bbox, fixed_points, max_iter, move_tolerance, seed):
    """The anisotropic mesh of the checked options (see :func:`generate_anisotropic_mesh`), its info but ``seconds``."""
    logger.info("anisotropic mesh: isotropic start at the metric's density")
    fixed = _metric_corners(domain, metric_at, bbox)
    if fixed_points is not None:
        fixed = np.vstack([fixed_points, fixed])
    # the metric's corners (sharp in the metric, not always in the plane) take the place of others nearby
    with muted_warnings(CORNERS_DISPLACED, FIXED_NEAR_BOUNDARY, FIXED_DROPPED):
        start = generate_mesh(domain, lambda p: mean_size(metric_at(p)), bbox=bbox, fixed_points=fixed, seed=seed)
    tolerance = BOUNDARY_TOLERANCE * start.info["h0"]
    finite_step = finite_difference_step(start.info["h0"], bbox)
    points, cells, n_fixed = _fixed_first(start, np.vstack([domain.corners(), fixed]), tolerance)
    neighbors = cell_neighbor_table(cells)
    project = _Projection(domain, metric_at, finite_step, tolerance)
    current = metric_at(points)
    flips = _kernel.metric_delaunay_flips(points, cells, neighbors, current, MAX_FLIP_PASSES, FLIP_SLACK)
    best, best_at, retriangulations, stop_reason, max_move = -np.inf, 0, 0, "max_iter", np.inf
    best_state = (-np.inf, points, cells, 0)
    triangulation = None  # the Delaunay triangulation each retriangulation repairs (the first builds it)
    for iteration in range(1, max_iter + 1):
        edges, outer = _edges(cells, neighbors)
        controlled = None
        if iteration % DENSITY_EVERY == 1:
            lengths = _kernel.edge_lengths(points, edges, current)
            controlled = _density_controlled(project, points, edges, outer, lengths, n_fixed)
        if controlled is not None or _any_outside(domain, points, cells, edges[outer], tolerance):
            triangulation, points = _followed(triangulation, points, controlled)
            points, cells, neighbors, current, flipped = _triangulated(
                project, points, n_fixed, triangulation.cells_and_neighbors()
            )
            flips += flipped
            edges, outer = _edges(cells, neighbors)
            retriangulations += 1
        quality = _kernel.cell_qualities(points, cells, current)
        if quality.min() > best_state[0]:  # the density control's rounds shake the worst cell: keep the best
            best_state = (float(quality.min()), points, cells.copy(), iteration)
        measure = float(quality.mean() - 3.0 * quality.std())
        if measure > best + STALL_GAIN:
            best, best_at = measure, iteration
        if iteration - best_at >= STALL_WINDOW:
            stop_reason = "stalled"
            break
        if iteration % 25 == 0:
            logger.info(
                "iteration %d of at most %d: max move %.3g, quality %.3f", iteration, max_iter, max_move, measure
            )
        moves, travelled = _kernel.force_moves(points, edges, current, 1.0, TIME_STEP, n_fixed)
        moved = points + moves
        on_boundary = _touched(len(points), edges[outer])
        interior = ~on_boundary
        interior[:n_fixed] = on_boundary[:n_fixed] = False
        moved[on_boundary] = project(moved[on_boundary])
        points, cells, neighbors = _moved(project, points, moved, cells, neighbors, n_fixed)
        max_move = float(travelled[interior].max()) if interior.any() else 0.0
        current = metric_at(points)
        flips += _kernel.metric_delaunay_flips(points, cells, neighbors, current, MAX_FLIP_PASSES, FLIP_SLACK)
        if max_move < move_tolerance:
            stop_reason = "converged"
            break

    mesh, kept = _valid_mesh(domain, project, [best_state[1:], (points, cells, iteration)], n_fixed)
    mesh.info.update(
        iterations=iteration,
        kept_iteration=kept,
        stop_reason=stop_reason,
        max_move=max_move,
        retriangulations=retriangulations,
        flips=int(flips),
        start=start.info,
    )
    return mesh


def _moved(project, points, moved, cells, neighbors, n_fixed):
    """Points at ``moved`` where no cell turns over, and the cells and neighbours that go with them.

    An interior point pushed across a boundary edge joins the boundary
    there, as in DistMesh (whose triangulation then leaves it on the hull):
    the cell between goes and the point is projected onto the boundary.
    Any other point that would turn a cell over (one past a neighbour in
    a thin cell) is held back where it was, waiting for the density
    control to give it room. Holding some back can turn over a cell of the
    others, so this repeats, for at most ``MAX_HOLD_ROUNDS`` rounds: the
    cells left are some of the given ones, none turned over. A point that
    joined the boundary and is then held back lies on the mesh's boundary
    off the domain's (a notch, in about one join in 25): the next
    iteration projects it, as every boundary vertex, and the final mesh is
    checked. Where the rounds do not settle, no point joins: the given
    cells stay, and the moves that turn one over are held back.
    """
    proposed = moved
    moved = moved.copy()
    flat_before = _kernel.inverted_cell_mask(points, cells)  # rounding can leave a Delaunay cell at area 0
    given = cells, neighbors, flat_before
    for round_ in range(MAX_HOLD_ROUNDS + 1):
        inverted = _kernel.inverted_cell_mask(moved, cells) & ~flat_before
        if not inverted.any():
            return moved, cells, neighbors
        if round_ == MAX_HOLD_ROUNDS:
            break
        crossing, joining = _kernel.crossed_boundary_edges(cells, neighbors, inverted, len(points), n_fixed)
        if len(joining):
            cells, neighbors = kept_cells(cells, neighbors, ~crossing)
            flat_before = flat_before[~crossing]
            moved[joining] = project(moved[joining])
            continue
        back = cells[inverted].reshape(-1)
        moved[back] = points[back]
    # The joins ran away (on a jagged coast each projected point turns over the next cell, and the same
    # rounds came back every iteration): undo them and hold back the moves that turn cells over, so that the
    # rest of the mesh moves on. Each round puts back at least one moved point, so this ends.
    cells, neighbors, flat_before = given
    moved = proposed.copy()
    while True:
        inverted = _kernel.inverted_cell_mask(moved, cells) & ~flat_before
        if not inverted.any():
            return moved, cells, neighbors
        back = cells[inverted].reshape(-1)
        moved[back] = points[back]


def _on_boundary(project, points, cells, neighbors, n_fixed):
    """``points`` with the mesh's boundary vertices off the domain boundary projected onto it, where no cell turns over.

    After a density control a point inside can end on the mesh's boundary
    (a boundary point removed next to it, a split boundary edge's midpoint).
    """
    edges, outer = _edges(cells, neighbors)
    vertices = np.flatnonzero(_touched(len(points), edges[outer])[n_fixed:]) + n_fixed
    off = np.abs(project.domain.distance(points[vertices])) > project.tolerance
    if not off.any():
        return points, cells, neighbors
    moved = points.copy()
    moved[vertices[off]] = project(points[vertices[off]])
    return _moved(project, points, moved, cells, neighbors, n_fixed)


class _Projection:
    """Moves points onto the domain's boundary along the metric's normal: to the boundary point nearest in the metric.

    Two Newton steps ``p - d M^-1 g / (g . M^-1 g)`` (``g`` the distance's
    gradient), each at most ``NEWTON_STEP_LIMIT`` times the point's
    distance long: along the plane's normal, a boundary vertex of cells a
    twentieth as high as wide slides sideways by many of their heights
    and turns them over. Where that leaves a point off the boundary (the
    normal turns at a polygon's vertex), the plane's projection follows.
    """

    def __init__(self, domain, metric_at, finite_step, tolerance):
        self.domain, self.metric_at, self.finite_step, self.tolerance = domain, metric_at, finite_step, tolerance

    def __call__(self, points):
        with threads_for(len(points)):  # a few points a call, a thousand calls a mesh: waking threads cost more
            return self._projected(points)

    def _projected(self, points):
        for _ in range(2):
            distance, gradient = distance_and_gradient(self.domain, points, self.finite_step)
            towards = np.linalg.solve(self.metric_at(points), gradient[:, :, None])[:, :, 0]
            along = gradient[:, 0] * towards[:, 0] + gradient[:, 1] * towards[:, 1]
            along[along <= 0] = 1.0
            step = (distance / along)[:, None] * towards
            # near a jagged coast the metric's normal can run along the boundary: uncapped, one point in ten
            # went more than 4 of its distances (48 at worst) and its far distances needed searches of their own
            length = np.maximum(row_norms(step), np.finfo(float).tiny)
            step *= np.minimum(1.0, NEWTON_STEP_LIMIT * np.abs(distance) / length)[:, None]
            points = points - step
        distance = self.domain.distance(points)
        # a capped step can leave a point near the boundary but not on it, where an uncapped one converged; the
        # plane's projection moves one within the tolerance by less than that
        off = np.abs(distance) > ON_BOUNDARY * self.tolerance
        if off.any():
            points[off] = project_to_boundary(self.domain, points[off], distance[off], self.finite_step)
        return points


def _edges(cells, neighbors):
    """Every edge once (one pass over the neighbour table) and whether it is on the boundary."""
    _, edges, outer = inner_cell_edges(cells, neighbors, np.ones(len(cells), dtype=bool), 0)
    return edges, outer


def _density_controlled(project, points, edges, outer, lengths, n_fixed):
    """Which points go (one end of each edge too short) and the points that come (midpoints of those too long).

    Returns ``(doomed, midpoints)``, a mask over ``points`` and an (k, 2)
    array, or None where every edge is of a length to keep.

    Edges under ``SHORT`` or over ``LONG`` (metric units: 1 is right) lose
    their later end (never a fixed point; a point losing its edge's
    partner keeps its own) or gain their midpoint, projected onto the
    boundary where the edge is a boundary edge.
    """
    short = lengths < SHORT
    long = lengths > LONG
    if not (short.any() or long.any()):
        return None
    doomed = _kernel.thinned_ends(edges[short], len(points), n_fixed)
    long &= ~any_corner_in(doomed, edges)
    split, on_boundary = edges[long], outer[long]
    midpoints = 0.5 * (points[split[:, 0]] + points[split[:, 1]])
    if on_boundary.any():
        midpoints[on_boundary] = project(midpoints[on_boundary])
    return doomed, midpoints


def _followed(triangulation, points, controlled):
    """A Delaunay ``Triangulation`` of ``points`` less the doomed plus the midpoints in ``controlled``; those points.

    ``triangulation`` (of the same points at earlier positions) is
    repaired: flips from its connectivity, the doomed removed and the
    midpoints inserted locally (on BP2004 a build of 56k points cost 46 ms
    a retriangulation); None builds one.
    """
    doomed, midpoints = (None, np.empty((0, 2))) if controlled is None else controlled
    if triangulation is not None:
        triangulation.move_points(points)
    if doomed is not None:
        points = points[~doomed]
        if triangulation is not None:
            triangulation.remove_points(np.flatnonzero(doomed))
    points = np.vstack([points, midpoints])
    if triangulation is None:
        return Triangulation(points, frame=True), points
    triangulation.add_points(midpoints)
    return triangulation, points


def _metric_corners(domain, metric_at, bbox):
    """A polygon's vertices sharper than ``CORNER_ANGLE`` measured in the metric (in the bbox), shape (k, 2).

    Unless such a corner is a vertex, boundary vertices slide round it and
    their cells fold. Other domains: none beyond their own corners.
    """
    if not hasattr(domain, "rings"):
        return np.empty((0, 2))
    corners = domain.corners(CORNER_ANGLE, metric=metric_at)
    return corners[np.all((corners >= bbox[0]) & (corners <= bbox[1]), axis=1)]


def _fixed_first(start, wanted, tolerance):
    """The start's points with the ``wanted`` fixed points (vertices of the start) first."""
    points, cells = start.points, start.cells
    wanted = np.asarray(wanted, dtype=np.float64).reshape(-1, 2)
    distance, index = cKDTree(points).query(wanted) if len(wanted) else (np.empty(0), np.empty(0, dtype=int))
    fixed = np.unique(index[distance <= tolerance])
    order = np.concatenate([fixed, np.setdiff1d(np.arange(len(points)), fixed)])
    renumber = np.empty(len(points), dtype=np.int64)
    renumber[order] = np.arange(len(points))
    return points[order].copy(), renumber[cells], len(fixed)


def _triangulated(project, points, n_fixed, delaunay=None):
    """``points`` triangulated again: the points, cells, neighbours, metric at the points and the flips made.

    The Delaunay cells (built afresh, or ``delaunay``, cells and neighbours
    of the caller's repaired :class:`Triangulation`, which leaves out the
    nearly flat cells along the hull) whose centroid lies inside the domain; where that
    leaves a vertex with more than two boundary edges (cells meeting at a
    point across a narrow gap), cells go until none has (the guide's
    repair, :func:`~terramesh.cleanup.delete_interior_cells`); boundary
    vertices off the boundary are projected onto it where no cell turns
    over (see :func:`_on_boundary`); and the edges flip to the metric's
    Delaunay test.
    """
    cells, neighbors = delaunay_with_neighbors(points) if delaunay is None else delaunay
    inside = project.domain.inside(cell_centroids(points, cells), project.tolerance)
    cells, neighbors = delete_interior_cells_with_table(points, *kept_cells(cells, neighbors, inside))
    points, cells, neighbors = _on_boundary(project, points, cells, neighbors, n_fixed)
    metric = project.metric_at(points)
    flips = _kernel.metric_delaunay_flips(points, cells, neighbors, metric, MAX_FLIP_PASSES, FLIP_SLACK)
    return points, cells, neighbors, metric, flips


def _snapped(project, points, cells, n_fixed):
    """Boundary vertices still off the boundary put onto it, and the cells this turns over or takes outside gone.

    What the holding back of :func:`_on_boundary` left (a jagged coast's
    vertex whose nearest boundary point lies past a neighbour's cells), done
    as the isotropic generator's last step does it: a vertex goes onto the
    boundary, a cell turned over, flat or across the outside (a notch
    narrower than the cells, its three corners on the boundary) goes, and
    the guide's repair leaves every boundary vertex two boundary edges; a
    few passes, as a removal can leave a vertex of the boundary off it.
    """
    for _ in range(MAX_SNAP_PASSES):
        on_boundary = _touched(len(points), boundary_edges(cells))
        off = np.flatnonzero(on_boundary[n_fixed:]) + n_fixed
        off = off[np.abs(project.domain.distance(points[off])) > project.tolerance]
        if len(off):
            points = points.copy()
            points[off] = project(points[off])
        doomed = _kernel.inverted_cell_mask(points, cells) | cells_outside(project.domain, points, cells, on_boundary)
        if not (len(off) or doomed.any()):
            break
        cells = delete_interior_cells(points, cells[~doomed])
    return points, cells


def _candidates(project, states, n_fixed):
    """``states``, then a fresh triangulation of the last one's points, flipped to the metric's Delaunay test."""
    yield from states
    points, cells, *_ = _triangulated(project, states[-1][0], n_fixed)
    yield points, cells, states[-1][2]


def _touched(n_points, edges):
    """Which of ``n_points`` vertices the ``edges`` (k, 2) touch, shape (n_points,)."""
    touched = np.zeros(n_points, dtype=bool)
    touched[edges] = True
    return touched


def _any_outside(domain, points, cells, boundary_edges, tolerance):
    """Whether a boundary cell's centroid is outside the domain (boundary vertices slid past a concave corner)."""
    near = cells[any_corner_in(_touched(len(points), boundary_edges), cells)]
    # clipped at any limit above the tolerance, the comparison stays exact; a polygon's distances far from its
    # boundary (centroids of long cells) would need a search of their own
    return bool((domain.distance_within(cell_centroids(points, near), 2.0 * tolerance) > tolerance).any())


def _valid_mesh(domain, project, states, n_fixed):
    """The first of ``states`` (points, cells, iteration) that makes a valid mesh, its boundary vertices projected.

    The best state can be one a density control left with a cell across a
    concave corner; the last, one whose worst cell a round has just
    shaken; a fresh triangulation of the last one's points comes third. A
    mesh that is not valid is an error, never a result.
    """
    for points, cells, iteration in _candidates(project, states, n_fixed):
        points, cells, _ = _on_boundary(project, points, cells, cell_neighbor_table(cells), n_fixed)
        points, cells = _snapped(project, points, cells, n_fixed)
        points, cells, _ = remove_unused_points(points, cells)
        mesh = Mesh(points, cells)
        tolerance = max(project.tolerance, 1e-9)
        # the cheap rules first: a candidate laid over itself by thousands of edges broke them all, and the
        # search for its overlaps took a minute
        problems = mesh_problems(mesh, domain, boundary_tolerance=tolerance, overlaps=False)
        problems = problems or mesh_problems(mesh, domain, boundary_tolerance=tolerance)
        if not problems:
            return mesh, iteration
    raise _InvalidMesh(
        "the anisotropic mesh came out invalid (" + "; ".join(map(str, problems[:3])) + "): try a metric "
        "that varies less from one cell to the next, or a finer one near the boundary",
        states[-1][0],
    )
