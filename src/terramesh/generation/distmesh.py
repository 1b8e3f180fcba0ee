"""The force-equilibrium mesh generator (Persson & Strang 2004), 2D: the driver.

One screen: seed points by the size function, triangulate, push points along
truss forces, project escaped points back onto the boundary, retriangulate
when points have moved far enough, stop when they stop moving (or the
quality stops improving); then triangulate once more, make the result valid
and smooth it without lowering any cell's worst quality.

The stages live beside it: the options and the sizes' sample
(:mod:`.options`), fixed points and corners (:mod:`.fixed_points`), the
force iterations (:mod:`.relax`), the distances they need
(:mod:`.distances`), the triangulation's cells inside the domain
(:mod:`.cells_inside`), the final repair and smoothing (:mod:`.finalize`)
and the warnings about the result (:mod:`.mesh_checks`). Here: the coarse
levels, each refined into the next, and the order of the stages.
"""

import logging
import time

import numpy as np

from .._kernels import threads_for
from .._kernels.precompile import compile_ahead_on_first_run
from .._kernels.topology import inner_cell_edges
from ..errors import GenerationError
from ..geometry.base import as_bbox, as_domain
from ..mesh.columns import row_norms
from ..mesh.topology import NO_INDICES, checked_fixed_points, coincident_points, without_rows
from .cells_inside import cells_inside
from .distances import finite_difference_step, project_to_boundary
from .finalize import finalize
from .fixed_points import spread_mask
from .levels import checked_levels, coarse_levels, level_start_points, refined_points, scaled, uncovered_seeds
from .mesh_checks import (
    warn_if_fixed_points_dropped,
    warn_if_partly_covered,
    warn_if_rings_missed,
    warn_if_sizes_missed,
    warn_if_unconverged,
)
from .options import checked_options
from .relax import (
    MAX_SETTLE_ROUNDS,
    REFINED_STALL_WINDOW,
    SETTLE_ITERATIONS,
    STALL_WINDOW,
    SWEPT_STALL_WINDOW,
    TOUCH_UP_ITERATIONS,
    relax,
)
from .seeding import seed_points
from .triangulate import Triangulation

__all__ = ["generate_mesh"]


logger = logging.getLogger("terramesh.generation")


SPLIT_RATIO = 1.3  # an edge shorter than this many of the finer level's sizes gets no midpoint at refinement
COARSEST_LEAST = 100  # a coarse level is meshed only with at least this many points (see _coarsest_points)


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
        domains have their own default (see :func:`~.distmesh3d.generate_mesh_3d`).

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
        domain along an axis (:data:`~terramesh.generation.options.GRID_COVERS`).

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
    size, h0, tolerance, fixed, h0_estimated, measure, sample = checked_options(
        domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed
    )
    compile_ahead_on_first_run(["generation"])  # after the options' checks: a bad one said at once
    levels = coarse_levels(domain, size, bbox, sample) if levels is None else checked_levels(levels)
    finite_step = finite_difference_step(h0, bbox)
    # a coarse level fixes only the fixed points half its size apart (the sides of a seismic
    # model box carry fixed nodes a fine edge apart); each finer level adds its own
    fixed_at = [np.ones(len(fixed), dtype=bool)]
    fixed_at += [spread_mask(fixed, scaled(size, 2.0**level)) for level in range(1, levels + 1)]
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
        if levels:
            logger.info(
                "level %d of %d (sizes x %g): %d points", levels - level + 1, levels + 1, 2.0**level, len(points)
            )
        with threads_for(len(points)):
            points, triangulation, record = relax(
                domain,
                scaled(size, 2.0**level),
                tolerance,
                points,
                triangulation,
                n_fixed,
                max_iter,
                move_tolerance,
                finite_step=finite_step,
                **_level_settings(level, levels),
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

    mesh = finalize(domain, size, triangulation, points, n_fixed, tolerance, finite_step)
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
    warn_if_unconverged(mesh.info, max_iter, move_tolerance)
    warn_if_partly_covered(mesh, measure)
    warn_if_rings_missed(mesh, domain, size, tolerance)
    warn_if_sizes_missed(mesh, sample, h0)
    if fixed_points is not None:
        warn_if_fixed_points_dropped(mesh, checked_fixed_points(fixed_points, 2, GenerationError), tolerance)
    return mesh


def _level_settings(level, levels):
    """How the force iterations run at ``level`` (0 the finest) of ``levels`` coarse ones: ``relax``'s options."""
    # sweeps only at the coarsest of several levels: on a coastline meshed at one level (mostly
    # boundary) they gained or lost 10-40 % by case, and left more low-valence vertices to clean
    sweep = level == levels and levels > 0
    return dict(
        sweep=sweep,
        stall_window=SWEPT_STALL_WINDOW if sweep else STALL_WINDOW if level == levels else REFINED_STALL_WINDOW,
        # a coarse level only starts the next, whose own rounds mend what its refinement brings: on
        # jagged coasts, where each round finds a few hundred points to thin or add, five rounds cost
        # 20-25 %; with none, the few points thinned in a seismic model's middle level left BP2004's
        # worst cell at 0.801 instead of 0.814
        max_settle_rounds=MAX_SETTLE_ROUNDS if level == 0 else 1,
        settle_iterations=SETTLE_ITERATIONS if level == 0 else TOUCH_UP_ITERATIONS,
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
            points = level_start_points(
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


def _doubled_midpoints(points, middle, on_boundary):
    """Midpoints (indices into ``middle``) projected exactly onto a point or onto an earlier midpoint's spot.

    Two boundary edges either side of a polygon's vertex project their
    midpoints onto that vertex; at refinement one of them would make the
    repair of the triangulation give up and rebuild it (0.1-0.2 s at
    50k-180k points), and every insertion and removal after it too.
    """
    if not on_boundary.any():
        return NO_INDICES
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
    inside = cells_inside(domain, points, cells, tolerance)
    edges, on_boundary = triangulation.split_edges(inside)
    direct = edges is not None
    if not direct:
        _, edges, on_boundary = inner_cell_edges(cells, neighbors, inside, 0)
    cells = neighbors = inside = None
    middle = refined_points(
        domain, points, edges, on_boundary, lambda at, distance: project_to_boundary(domain, at, distance, finite_step)
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
