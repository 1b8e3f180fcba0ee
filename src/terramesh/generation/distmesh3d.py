"""The force-equilibrium mesh generator (Persson & Strang 2004), 3D, with guaranteed sliver removal.

The loop of the 2D generator: seed points by the size function (a
body-centred cubic lattice, thinned, and a hexagonal one in each of a box's
faces, see :mod:`terramesh.generation.flat_faces`), tetrahedralise, push points along truss
forces, project escaped points back onto the boundary, tetrahedralise again
when points have moved far enough (or every 20 iterations), stop when they stop
moving or the quality stalls. Meshes of 16,000 vertices and more start from a
coarse level, as in 2D: the domain meshed at twice the size (eight times fewer
points), whose vertices and edge midpoints settle in about 20 iterations where
random seeds take 70 to 100 (the ball of SeismicMesh's benchmark, 25k
vertices, in 1.0 s instead of 1.9 s). There is no density control (as in Persson's
n-D code): in 3D it removed far too many points. Sharp edges the domain
declares (a box's twelve, a cylinder's two rims; a CSG combination's, those
it creates where one operand's surface meets another's included, straight
or curved) are sampled by the size function and their points fixed, as the
corners are:
the forces alone would push points off an edge onto one face or the other,
and the final cells would then cut across it. Before the final
tetrahedralisation, free points that came within the ball on a segment
between two edge points (its diametral ball, enlarged 1.25 times) are dropped, so that the segment is an edge of
the cells (across a re-entrant edge, cells would otherwise bridge the
outside).

Then the final Delaunay mesh is cleaned and its slivers removed, in rounds
of flat boundary cells peeled off, edge removals and 2-3 flips, vertex moves
and contractions (see :mod:`terramesh.cleanup.slivers`). Cells below
AIM_DIHEDRAL (15 degrees) are worked on; a mesh with any cell below
MIN_DIHEDRAL (10 degrees) left is not returned: the call raises
GenerationError with the count. Then flips alone raise the cells below
FLIP_AIM (30 degrees) where they can (BP2004 3-D: the smallest angle 15.1
-> 20.1 degrees). Last, two passes of Laplacian smoothing
move each interior vertex to its neighbours' mean where neither the worst
mean ratio nor the smallest dihedral angle of its cells falls (the
25k-vertex ball: cells of radius ratio below 0.3 from 44 to 3), and the
vertices of cells still below radius ratio 0.3 (caps and needles, whose
angles the sliver bound does not see) go where their worst cell is best,
boundary vertices along the boundary (the 64k-vertex ball: its worst cell
from 0.086 to 0.300). Then the ends of edges shorter than SHORT_EDGE (0.45)
of their size move apart where their cells allow it, the same way: the
shortest edge sets an explicit solver's time step, and a few edges per
10**5 came out at 0.35-0.45 (on the 3-D BP2004 example made for a ``dt``,
0.975 of the step asked on one seed of six; after it, 1.15-1.34).

The tetrahedralisations are :func:`~terramesh.generation.triangulate.delaunay_3d`
(re-exported here): an incremental Bowyer-Watson kernel in numba
(:mod:`terramesh._kernels.delaunay3d`): about 0.12 s for 25k points, against
0.7 to 1 s for SciPy's Qhull, which a 25k-vertex ball needs about eight times.
Its floating-point predicates hand over to exact ones where a result is doubtful
(a flat cell, a point in no cell), Qhull being the last resort. Sharp-edge sampling
is in :mod:`terramesh.generation.sharp_edges`.

Here: the driver. :func:`generate_mesh_3d` checks the options and calls
:func:`generate_mesh_3d_clearing`, which calls ``_meshed`` (meshing again at one
level when the final mesh is refused), which settles the points in
``_relaxed``; that starts from ``_refined_start`` (the domain meshed at
twice the size by ``_relaxed`` again, one recursion per coarse level) or
from lattice seeds, and then :func:`~.finalize3d.finalize_3d` makes the
mesh. The seeding is in :mod:`.seeding3d`, the force iterations in
:mod:`.relax3d`, the final repair, sliver removal and smoothing in
:mod:`.finalize3d`.
"""

import logging
import time

import numpy as np

from .._kernels.precompile import compile_ahead_on_first_run
from ..errors import GenerationError
from ..geometry.base import as_bbox, as_domain
from ..mesh.topology import checked_fixed_points, edges_on_faces, table_boundary_faces
from .cells_inside import tetrahedralise
from .distances import finite_difference_step, project_to_boundary_3d
from .finalize3d import STUCK_DEPTH, finalize_3d
from .fixed_points import spread_mask, with_fixed_first
from .levels import COVERED, checked_levels, coarse_levels, level_start_points, refined_points, scaled, uncovered_seeds
from .mesh_checks import warn_if_fixed_points_dropped, warn_if_partly_covered, warn_if_unconverged
from .options import checked_options
from .relax3d import SETTLE_AFTER, relax_3d
from .seeding3d import bcc_seed_points, lattice_seeds
from .sharp_edges import sharp_edge_balls, sharp_edge_chains, with_sharp_edges
from .triangulate import delaunay_3d, morton_order

__all__ = ["generate_mesh_3d", "bcc_seed_points", "delaunay_3d"]


logger = logging.getLogger("terramesh.generation")


REFINED_JITTER = 0.005  # of its edge's length, at most, on each axis: a refined start's midpoints are moved


def generate_mesh_3d(
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
    """Generate a tetrahedral mesh of a 3D domain with DistMesh's force equilibrium, free of slivers.

    Parameters
    ----------
    domain : Domain or callable
        Signed distance function (negative inside) of ``(n, 3)`` points with
        a ``bbox`` of shape ``(2, 3)``; see :mod:`terramesh.geometry`
        (:class:`~terramesh.geometry.primitives3d.Box`, ``Ball``,
        ``Cylinder`` and their unions, intersections and differences).
        Coordinates are ``(x, y, z)`` in the user's units.
    edge_length : float, callable or SizeGrid, optional
        Target edge length: a number (uniform), a function of an ``(n, 3)``
        array, or a 3-axis :class:`~terramesh.sizing.SizeGrid` (trilinear).
        Defaults to ``h0``.
    h0 : float, optional
        Smallest edge length, the spacing of the initial lattice. Defaults to
        the number given as ``edge_length``, the grid's minimum, or the
        smallest value of the function on a 64**3 sample of the bbox.
    bbox : array_like, shape (2, 3), optional
        Region to mesh, ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]``; defaults
        to the domain's.
    fixed_points : array_like, shape (k, 3), optional
        Points that must be vertices and never move. The domain's corners
        (e.g. a box's) are always added, and so are points along its sharp
        edges (a box's twelve, a cylinder's two rims; of a CSG combination,
        the operands' edges where they stay on its boundary and the edges it
        creates where operands meet, see ``Union.sharp_edges``), spaced by
        the size.
    max_iter : int, optional
        Most force iterations; reaching it without convergence warns.
    move_tolerance : float, optional
        Convergence: stop when no interior point moved more than this
        fraction of its local edge length in an iteration. Generation also
        stops, as "stalled", once the mean - 3 std of the cell quality
        ``6 sqrt(2) V / l_rms**3`` of fresh tetrahedralisations gains less
        than 0.01 per 10 iterations (flat cells along the boundary, which
        are removed at the end, not counted).
    seed : int, optional
        Seed of the lattice thinning and jitter; the same inputs and seed
        give the same mesh.
    levels : int, optional
        Coarse levels meshed first: level ``k`` meshes the domain at
        ``2**k`` times the size, and its vertices with its edges' midpoints
        start the level below (eight times the points, nearly in
        equilibrium: about 20 iterations and two tetrahedralisations where
        random seeds take 70 to 100 and six to nine). By default one where
        the coarse level keeps 2,000 vertices or more and at most 40 % of
        them on the boundary (none below about 16,000 vertices); 0 meshes at
        one level (1.4-1.9 times slower; its mean radius ratio was about 1 %
        higher on meshes of 100k-200k vertices), 2 or more refine twice
        (worse cells).

    Returns
    -------
    Mesh
        Valid tetrahedral mesh: positively oriented cells
        (``(b - a) . ((c - a) x (d - a)) > 0``), no unused vertices, a
        manifold boundary whose vertices lie within ``1e-3 h0`` of the domain
        boundary (on it to rounding where the domain has an exact
        ``project``, as a box has: its edges are followed by mesh edges, its
        faces by boundary faces), and every cell's smallest dihedral angle
        at least 10 degrees (sliver removal aims at 15, then flips raise
        the cells below 30 where they can). ``mesh.info`` holds
        ``iterations``, ``stop_reason`` (``"converged"``, ``"stalled"``,
        ``"settled"``: a refined level's 20 iterations done, or
        ``"max_iter"``), ``max_move``, ``retriangulations``, ``seconds``,
        ``h0``, ``force_seconds``, ``levels`` (one record per level, the
        coarsest first: ``iterations``, ``stop_reason``, ``max_move``,
        ``retriangulations``, ``points``, ``seconds``), and for the final clean-up
        ``min_dihedral`` (degrees), ``slivers_before`` (cells below 10
        degrees in the final Delaunay mesh), ``sliver_rounds`` and
        ``sliver_seconds`` (final tetrahedralisation included).

    Raises
    ------
    GenerationError
        For a domain that is not 3D, an empty domain, a bbox that misses it,
        bad options, or when slivers (cells with a dihedral angle below 10
        degrees) remain after sliver removal; the message says how many.
        That happens where the domain is thinner than the mesh size (a slab
        thinner than ``h`` cannot be filled with good tetrahedra).
    SizingError
        For non-positive, NaN or misshapen sizes.

    References
    ----------
    P.-O. Persson and G. Strang, "A simple mesh generator in MATLAB",
    SIAM Review 46(2), 329-345, 2004. :doi:`10.1137/S0036144503429121`

    L. A. Freitag and C. Ollivier-Gooch, "Tetrahedral mesh improvement using
    swapping and smoothing", Int. J. Numer. Meth. Eng. 40(21), 3979-4002,
    1997. :doi:`10.1002/(SICI)1097-0207(19971115)40:21<3979::AID-NME251>3.0.CO;2-9`

    B. M. Klingner and J. R. Shewchuk, "Aggressive tetrahedral mesh
    improvement", Proceedings of the 16th International Meshing Roundtable,
    3-23, 2007 (edge removal by dynamic programming).

    Examples
    --------
    >>> from terramesh.geometry.primitives3d import Ball
    >>> mesh = generate_mesh_3d(Ball((0, 0, 0), 1.0), 0.3, seed=0)
    >>> mesh.cells.shape[1], mesh.info["min_dihedral"] >= 10
    (4, True)
    """
    return generate_mesh_3d_clearing(
        domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed, levels
    )


def generate_mesh_3d_clearing(
    domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed, levels, clear=None
):
    """:func:`generate_mesh_3d`; ``clear`` (or None) maps relaxed free points and the size to a mask of those to drop.

    The mask's free points go before the final tetrahedralisation (a slab
    of :func:`~terramesh.parallel.generate_mesh_parallel` clears its cut
    faces of all but their fixed points, which the slab beside holds too).
    """
    started = time.perf_counter()
    domain = as_domain(domain, bbox)
    if domain.dim != 3:
        raise GenerationError(f"generate_mesh_3d needs a 3D domain, got dim={domain.dim}")
    bbox = domain.bbox if bbox is None else as_bbox(bbox, dim=3)
    size, h0, tolerance, fixed, h0_estimated, measure, _ = checked_options(
        domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed
    )
    compile_ahead_on_first_run(["generation-3d"])  # after the options' checks: a bad one said at once
    levels = coarse_levels(domain, size, bbox) if levels is None else checked_levels(levels)
    mesh, records, forces_done = _meshed(
        domain, size, h0, bbox, tolerance, fixed, levels, seed, max_iter, move_tolerance, not h0_estimated, clear
    )
    final = records[-1]
    mesh.info.update(
        {key: final[key] for key in ("iterations", "stop_reason", "max_move", "retriangulations")},
        levels=records,
        seconds=time.perf_counter() - started,
        h0=h0,
        force_seconds=forces_done - started,
    )
    logger.info(
        "stopped after %d iterations (%s): %d vertices, %d cells, min dihedral %.1f degrees in %.2f s",
        mesh.info["iterations"],
        mesh.info["stop_reason"],
        mesh.n_points,
        mesh.n_cells,
        mesh.info["min_dihedral"],
        mesh.info["seconds"],
    )
    warn_if_unconverged(final, max_iter, move_tolerance)
    warn_if_partly_covered(mesh, measure)
    if fixed_points is not None:
        warn_if_fixed_points_dropped(mesh, checked_fixed_points(fixed_points, 3, GenerationError), tolerance)
    return mesh


def _meshed(
    domain, size, h0, bbox, tolerance, fixed, levels, seed, max_iter, move_tolerance, warn_below_h0, clear=None
):
    """The final mesh with ``levels`` coarse levels first: ``(mesh, the levels' records, when the forces ended)``.

    A refined start can leave what the clean-up cannot mend where seeds
    would not (slivers at a CSG edge: 3 of 84 sweep runs with forced
    levels), so when the clean-up refuses it the points are seeded and
    relaxed again at one level: coarse levels never cost a mesh. ``clear``:
    see :func:`generate_mesh_3d_clearing`.
    """
    records = []
    points, n_fixed, edge_balls = _relaxed(
        domain, size, h0, bbox, tolerance, fixed, levels, seed, max_iter, move_tolerance, warn_below_h0, records
    )
    if clear is not None:
        points = np.vstack([points[:n_fixed], points[n_fixed:][~clear(points[n_fixed:], size)]])
    forces_done = time.perf_counter()
    try:
        mesh = finalize_3d(domain, size, points, n_fixed, tolerance, finite_difference_step(h0, bbox), edge_balls)
    except GenerationError as error:
        if len(records) == 1:  # one level (asked for, or the coarse one failed): the refusal stands
            raise
        logger.info("the mesh from a coarse level failed its clean-up (%s): meshing at one level", error)
        return _meshed(
            domain, size, h0, bbox, tolerance, fixed, 0, seed, max_iter, move_tolerance, warn_below_h0, clear
        )
    return mesh, records, forces_done


def _relaxed(domain, size, h0, bbox, tolerance, fixed, levels, seed, max_iter, move_tolerance, warn_below_h0, records):
    """Points in force equilibrium for ``size``, with ``levels`` coarse levels first: ``(points, n_fixed, edge balls)``.

    The ``fixed`` points come first, then the sharp edges' points (fixed
    too, ``n_fixed`` in all), then the free ones. Appends each level's
    record (coarsest first) to ``records``: ``iterations``,
    ``stop_reason``, ``max_move``, ``retriangulations``, ``seconds`` (of
    the force iterations) and ``points``.
    """
    points = None
    if levels:
        points = _refined_start(
            domain, size, h0, bbox, tolerance, fixed, levels, seed, max_iter, move_tolerance, records
        )
    settle = SETTLE_AFTER if points is not None else 0
    if points is None:
        points = level_start_points(domain, size, h0, bbox, fixed, seed, lattice_seeds, tolerance, warn_below_h0)
    chains = sharp_edge_chains(domain, size, h0)
    points, n_fixed = with_sharp_edges(domain, size, h0, bbox, tolerance, points, len(fixed), chains)
    edge_balls = sharp_edge_balls(domain, chains, tolerance)
    # Z-order numbering: neighbours in space are near in memory (every kernel below walks neighbours)
    points = np.vstack([points[:n_fixed], points[n_fixed:][morton_order(points[n_fixed:])]])
    if len(points) < 4:
        extent = " x ".join(f"{side:.4g}" for side in bbox[1] - bbox[0])
        raise GenerationError(
            f"only {len(points)} point{'s' if len(points) != 1 else ''} fit in the domain (its bbox {extent}): "
            f"h0={h0:g} is too large for it"
        )
    points, record = relax_3d(
        domain,
        size,
        np.ascontiguousarray(points),
        n_fixed,
        tolerance,
        finite_difference_step(h0, bbox),
        max_iter,
        move_tolerance,
        settle,
    )
    record["points"] = len(points)
    records.append(record)
    return points, n_fixed, edge_balls


def _refined_start(domain, size, h0, bbox, tolerance, fixed, levels, seed, max_iter, move_tolerance, records):
    """The free points a mesh at twice the size gives, refined (its vertices and edge midpoints); ``fixed`` first.

    Eight times fewer points settle at the coarse level; its vertices with
    the midpoints of its edges (on the boundary, projected onto it) are a
    start for the asked size that is nearly in equilibrium, so the fine
    level stops after about 20 iterations and two tetrahedralisations
    where random seeds take 70 to 100 and six to nine. Points within half
    ``h0`` of a fixed point are left out; lattice points near the boundary
    that no point covers (a part thinner than the coarse size) are added.
    None when the coarse level fails (a part too thin for it): the caller
    seeds the fine level afresh.
    """
    coarse_size = scaled(size, 2.0)
    coarse_fixed = fixed[spread_mask(fixed, coarse_size)]
    try:
        points, n_fixed, _ = _relaxed(
            domain,
            coarse_size,
            2.0 * h0,
            bbox,
            tolerance,
            coarse_fixed,
            levels - 1,
            seed,
            max_iter,
            move_tolerance,
            False,
            records,
        )
        cells, neighbors = tetrahedralise(domain, points, tolerance, neighbors=True)
    except GenerationError as error:
        logger.info("no coarse level (%s): seeding the level of h0 = %g afresh", error, h0)
        del records[:]
        return None
    edges, on_boundary_edge = edges_on_faces(cells, table_boundary_faces(cells, neighbors), len(points))
    step = finite_difference_step(h0, bbox)

    def project(middle, distance):
        return project_to_boundary_3d(domain, middle, distance, step, newton_steps=3)

    # the midpoints of a settled mesh are nearly cospherical in many places (and cocircular on a flat face), so
    # the tetrahedralisation's exact predicates decide often: a 68k-point refined start took 0.91 s, jittered 0.45
    jitter = REFINED_JITTER * np.random.default_rng(seed).uniform(-1.0, 1.0, (len(edges), 3))
    middle = refined_points(domain, points, edges, on_boundary_edge, project, jitter)
    # a flat cell with four corners on the boundary (across a cylinder's side) has a diagonal that is no boundary
    # edge, its midpoint a sag inside, where the forces push it out: a cylinder's side came out with 78 % more
    # vertices than one level gives, 376 edges under half their size among them
    inner = np.flatnonzero(~on_boundary_edge)
    distance = domain.distance(middle[inner])
    near = distance > -STUCK_DEPTH * size(middle[inner])
    sagging = inner[near]
    start = np.vstack([points[n_fixed:], np.delete(middle, sagging, axis=0)])
    if len(start) == 0:
        return None
    from scipy.spatial import cKDTree

    tree = cKDTree(start)
    # ...but where the coarse side's triangles were long, those midpoints filled it (left out, 90 side edges came
    # out over 1.6 sizes, one level 8): those farther than COVERED sizes from every point go onto the boundary
    # (of two closer than COVERED times the smallest of these sizes, the first)
    gap = project(middle[sagging], distance[near])
    gap = gap[tree.query(gap)[0] > COVERED * size(gap)]
    if len(gap):
        pairs = cKDTree(gap).query_pairs(COVERED * float(size(gap).min()), output_type="ndarray")
        gap = np.delete(gap, np.unique(pairs[:, 1]), axis=0)
        start = np.vstack([start, gap])
        tree = cKDTree(start)
    fill = uncovered_seeds(
        domain, size, h0, bbox, seed, tolerance, lambda seeds: tree.query(seeds)[0], seeder=bcc_seed_points
    )
    return with_fixed_first(np.vstack([start, fill]), fixed, 0.5 * h0)
