"""Adapt a 2D mesh to a changed size function from its own vertices (a model update during FWI).

The seismic DistMesh talk's strategy for a velocity model that full-waveform
inversion has updated: edit the size function, inject points where it fell
(take them out where it grew), and let the force iterations move the existing
points to the new equilibrium. Where the size did not change the vertices are
in equilibrium already, so they stay put, and the run converges in a fraction
of the iterations a fresh mesh needs.
"""

import logging
import time

import numpy as np

from .._kernels.precompile import compile_ahead_on_first_run
from ..errors import GenerationError
from ..geometry.base import as_domain
from ..geometry.segments import SegmentIndex
from ..mesh.columns import bounds, row_max, rows_all
from ..mesh.mesh import Mesh
from ..mesh.topology import (
    NO_INDICES,
    all_corners_in,
    any_corner_in,
    boundary_edges,
    boundary_faces,
)
from ..sizing.edge_length import as_size_function
from ..sizing.grid import SizeGrid
from .cells_inside import flagged_mesh_edges
from .density import (
    CHANGED_DENSITY,
    FILL_ABOVE,
    FREE_RINGS,
    MAX_DENSITY_ROUNDS,
    SIZE_CHANGE,
    SPLIT_RATIO,
    THIN_BELOW,
    diffused,
    edge_ratios,
    edges_of,
    longest_edges,
    vertices_stood_for,
    with_neighbours,
)
from .distances import LazyDistance, finite_difference_step, project_to_boundary
from .finalize import finalize
from .fixed_points import beyond_fixed
from .levels import COVERED, refined_points, scaled
from .mesh_checks import warn_if_unconverged
from .options import checked_options
from .relax import REFINED_STALL_WINDOW, STALL_WINDOW, changed_points, relax
from .seeding import seed_points
from .triangulate import Triangulation

__all__ = ["adapt_mesh"]

logger = logging.getLogger(__name__)

MISSED_BELOW = 0.1  # an old mesh whose bbox covers less of the domain's, or with fewer vertices in it, is refused
COARSE_CHECK = 4.0  # where the old mesh misses seeds of this many sizes apart, the domain is seeded where it does...
SEEDED_SHARE = 0.01  # ...and with more than this share of the points seeded, the iterations stall as a fresh run's
FILL_SEED = 0  # the seed of those seeds: the same inputs, the same mesh


def adapt_mesh(
    mesh, domain, edge_length, *, old_edge_length=None, h0=None, fixed_points=None, max_iter=300, move_tolerance=1e-2
):
    """Adapt a triangle or tetrahedral mesh to a new size function, starting from its own vertices.

    For a size function changed in places, typically by a velocity model
    update between full-waveform-inversion iterations (the seismic DistMesh
    talk's strategy): the vertices are kept; edges longer than
    ``SPLIT_RATIO`` (1.5) sizes get their midpoints, in rounds until none
    is left (where the size fell by half or more); then, by how many
    vertices of a mesh of the new size each vertex stands for, vertices
    standing for fewer than ``THIN_BELOW`` (0.6) are thinned (where the
    size grew) and those standing for more than ``FILL_ABOVE`` (1.5) get
    points in the middle of their longest edges (where it fell a little),
    both to the density asked; with the old sizes, wherever the size
    changed, already beyond ``CHANGED_DENSITY`` (10 %). Where the old mesh
    does not reach (it covers part of the domain only: a model extended, a
    padding added), the generator's seeds are put in at the new size's
    density first, as a fresh mesh starts. Then the force iterations of
    :func:`~terramesh.generate_mesh` run from there (all points at once),
    with its stop, clean-up, smoothing and validity. No randomness is
    involved: the same inputs give the same mesh.

    A tetrahedral mesh is adapted the same way (:mod:`terramesh.generation.adapt3d`)
    and finished by :func:`~terramesh.generation.distmesh3d.generate_mesh_3d`'s
    sliver removal. Its density is matched to within 10 % of what the old
    mesh's vertices stand for at the old sizes (with them; without, to
    0.6-1.5), since the 3D force iterations add and remove no points; a
    start with more than 10 % of its points new or taken out iterates to
    equilibrium (a fresh mesh's quality) instead of stopping after about 20
    iterations. In 3D, adapting is not faster than meshing afresh (a fresh
    mesh starts from a coarse level): what it gives is the old vertices,
    kept to the bit away from the change, given the old sizes. Where the
    old sizes show a change at more than ``FRESH_ABOVE`` (90 %) of the old
    vertices (a new frequency), there is nothing to keep, and the mesh is
    made afresh (``info["afresh"]``).

    Parameters
    ----------
    mesh : Mesh
        A 2D triangle or 3D tetrahedral mesh of ``domain``, in its units and frame (cells are
        made afresh, points outside the domain go, and parts of the domain
        it does not cover are seeded afresh). Its bbox must cover at least
        ``MISSED_BELOW`` (10 %) of the domain's, and that share of its
        vertices must lie in the domain.
    domain : Domain or callable
        Signed distance function (negative inside) with a ``bbox``.
    edge_length : float, callable or SizeGrid
        The new target edge length, in the mesh's units.
    old_edge_length : float, callable or SizeGrid, optional
        The edge length the mesh was made for. Given, the mesh's vertices
        where the size changed by no more than 2 % stay exactly where they
        are (bit for bit), as fixed points do, except those within two rings
        of neighbours of a vertex where it changed, of a point put in, or
        of an old vertex within 1.5 sizes of a fixed point that is new or of
        where the domain's boundary moved (a padding added or taken out);
        only there are long edges split. The domain's own nodes (a
        :class:`~terramesh.seismic.ModelBox`'s side nodes, which a size
        change anywhere along a side re-spaces) are taken from the old
        boundary vertices where the size did not change. Without it every
        vertex may move a little (in the BP2004 benchmark 13 % of them by
        more than 5 % of their size). In 3D the sharp edges' points are
        spaced along each whole edge by the sizes, so old vertices within
        about two sizes of an edge along which the size changed move too.
    h0 : float, optional
        Smallest edge length (the boundary tolerance is ``1e-3 h0``);
        defaults as in :func:`~terramesh.generate_mesh`.
    fixed_points : array_like, shape (k, 2) or (k, 3), optional
        Points that must be vertices and never move; the domain's corners
        are always added (with ``old_edge_length``, one within ``1e-3 h0``
        of an old boundary vertex is that vertex, and one where the size did
        not change on an edge of the old boundary is left out; 2D).
    max_iter : int, optional
        Most force iterations; reaching it warns.
    move_tolerance : float, optional
        Convergence: no interior point moved more than this fraction of its
        local size in an iteration (or the quality stalled for 5 iterations).

    Returns
    -------
    Mesh
        Valid mesh, as from :func:`~terramesh.generate_mesh`. ``mesh.info``
        holds ``iterations``, ``stop_reason``, ``max_move``,
        ``retriangulations``, ``rebuilds``, ``seconds``, ``h0``, and
        ``added`` and ``removed``: the points put in (``seeded`` of them
        seeds where the old mesh did not reach, the rest by the density
        matching) and taken out before the iterations; in 3D also ``held``,
        the old vertices held in place, and the sliver removal's
        ``min_dihedral``, ``slivers_before``, ``sliver_rounds`` and
        ``sliver_seconds`` (no ``rebuilds``).

    Raises
    ------
    GenerationError
        For a mesh that is neither a 2D triangle mesh nor a tetrahedral
        mesh of a domain of its dimension, one that misses the
        domain (its bbox covers less than 10 % of the domain's, or fewer
        than 10 % of its vertices lie in it: a mesh in km on a domain in
        metres, or about another origin; the message gives both extents),
        or bad options.
    SizingError
        For non-positive, NaN or misshapen sizes.

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> disk = tm.geometry.Disk((0, 0), 1)
    >>> coarse = tm.generate_mesh(disk, 0.2, seed=0)
    >>> finer_right = lambda p: np.where(p[:, 0] > 0.3, 0.1, 0.2)
    >>> adapted = tm.adapt_mesh(coarse, disk, finer_right, h0=0.1)
    >>> adapted.n_points > coarse.n_points, adapted.info["added"] > 0
    (True, True)
    """
    started = time.perf_counter()
    if not isinstance(mesh, Mesh):
        raise GenerationError(f"adapt_mesh adapts a terramesh Mesh, got {type(mesh).__name__}")
    domain = as_domain(domain)
    dim = mesh.dim
    if mesh.cells.shape[1] != dim + 1 or domain.dim != dim:
        raise GenerationError(
            f"adapt_mesh adapts 2D triangle meshes on 2D domains and tetrahedral meshes on 3D domains; got "
            f"{dim}D points, {mesh.cells.shape[1]}-corner cells and a {domain.dim}D domain"
        )
    size, h0, tolerance, fixed, _, _, _ = checked_options(
        domain, edge_length, h0, domain.bbox, fixed_points, max_iter, move_tolerance
    )
    _check_overlap(mesh.points, domain, tolerance)
    if len(mesh.cells) == 0:  # numpy's "zero-size array" (2D) or an IndexError (3D) from deep inside
        raise GenerationError("the mesh has vertices but no cells to adapt; mesh the domain afresh (generate_mesh)")
    compile_ahead_on_first_run(["generation"] if dim == 2 else ["generation-3d"])
    changed = old_size = None
    if old_edge_length is not None:
        old_size = as_size_function(old_edge_length, "old_edge_length")
        _check_old_sizes_cover(old_size, mesh.points)
        changed = size_changed(size, old_size)
        if dim == 2:
            fixed = _met_by_the_old_vertices(domain, fixed, fixed_points, mesh, changed, tolerance)
    share = None if dim != 3 or changed is None else float(np.mean(changed(mesh.points)))
    if share is not None and share > FRESH_ABOVE:
        from .adapt3d import density_bias
        from .distmesh3d import generate_mesh_3d

        density_bias(mesh, boundary_faces(mesh.cells), old_size)  # old sizes not the mesh's make any change total
        # nothing to keep: from its coarse levels a fresh mesh was 4 times faster (BP2004 3D, 0.8 -> 1 Hz:
        # 14.6 s against 55.7 s) and the sizes asked (adapted, 9 % more vertices)
        logger.info("the size changed at %.0f %% of the old vertices: meshing afresh", 100 * share)
        adapted = generate_mesh_3d(
            domain, size, h0=h0, fixed_points=fixed_points, max_iter=max_iter, move_tolerance=move_tolerance
        )
        adapted.info.update(afresh=True, added=adapted.n_points, removed=mesh.n_points, seeded=0, held=0)
    elif dim == 3:
        from .adapt3d import restarted_3d  # it builds on this module's helpers

        adapted = restarted_3d(domain, size, h0, tolerance, fixed, mesh, old_size, max_iter, move_tolerance)
    else:
        adapted = restarted(
            domain, size, h0, tolerance, fixed, mesh.points, changed, max_iter, move_tolerance, mesh.cells
        )
    adapted.crs = mesh.crs  # the same frame: a UTM mesh came back planar without a word
    adapted.info.update(seconds=time.perf_counter() - started)
    if not adapted.info.get("afresh"):  # the generator warned of its own
        warn_if_unconverged(adapted.info, max_iter, move_tolerance)
    logger.info(
        "adapted: %d points added, %d removed, %d iterations (%s), %d vertices in %.2f s",
        adapted.info["added"],
        adapted.info["removed"],
        adapted.info["iterations"],
        adapted.info["stop_reason"],
        adapted.n_points,
        adapted.info["seconds"],
    )
    return adapted


def size_changed(size, old_size):
    """``changed(points)``: the mask of ``points`` where ``size`` and ``old_size`` differ by over ``SIZE_CHANGE``."""

    def changed(points):
        return np.abs(size(points) / old_size(points) - 1.0) > SIZE_CHANGE

    return changed


FRESH_ABOVE = 0.9
"""Share of a tetrahedral mesh's old vertices where the size changed above which :func:`adapt_mesh` meshes afresh."""


OLD_SIZES_COVER = 0.9
"""Share of the old mesh's bbox (along each axis) that a gridded ``old_edge_length`` must cover."""


def _check_old_sizes_cover(old_size, points):
    """Refuse gridded old sizes that miss much of the old mesh: read on another grid, their values were clamped.

    The command line read an old model on a 50 m grid with the new one's 25 m
    spacing: its sizes covered half the old mesh, each vertex beyond took
    the edge's, and 6 of 9,744 old vertices were kept where the sizes held.
    """
    if not isinstance(old_size, SizeGrid) or len(points) == 0:  # a function's sizes reach everywhere
        return
    low, high = bounds(points)
    covered = old_size.covered(low, high)
    if covered.min() < OLD_SIZES_COVER:
        extent = " .. ".join("(" + ", ".join(f"{value:g}" for value in corner) + ")" for corner in old_size.bbox)
        raise GenerationError(
            f"old_edge_length's grid spans {extent}, {100 * max(min(covered), 0.0):.3g} % of the old mesh "
            f"({_extent(low, high)}) along an axis: was the old model read with another spacing or origin than "
            "its own (the command line's --old-model takes --spacing unless --old-spacing is given)?"
        )


def _check_overlap(points, domain, tolerance):
    """Refuse an old mesh that misses the domain: one in other units (km for m) or about another origin.

    Such a mesh kept only the few of its vertices that fell in the domain
    (or none, the domain's own nodes standing alone): a BP2004 mesh written
    in km and read back came out as 30 vertices and 18 cells, edges of up
    to 100 sizes, "converged", with no word of the mistake. Refused when its
    bbox covers less than ``MISSED_BELOW`` (10 %) of the domain's (a mesh in
    km on a domain in metres), or fewer than that share of its vertices lie
    in the domain, within ``tolerance`` (a mesh in metres on a domain in km,
    or about another origin). A mesh of no vertices is refused too.
    """
    if len(points) == 0:
        raise GenerationError("the mesh has no vertices to adapt; mesh the domain afresh (generate_mesh)")
    box = np.asarray(domain.bbox, dtype=np.float64)
    low, high = bounds(points)
    overlap = np.clip(np.minimum(high, box[1]) - np.maximum(low, box[0]), 0.0, None)
    covered = float(np.prod(overlap / (box[1] - box[0])))
    # compared with the tolerance only: a polygon skips the far distances (120 ms at 80k vertices of a coast)
    inside = float(np.mean(domain.distance_within(points, 2.0 * tolerance) <= tolerance))
    if covered >= MISSED_BELOW and inside >= MISSED_BELOW:
        return
    raise GenerationError(
        f"the mesh misses the domain: its vertices span {_extent(low, high)}, the domain {_extent(*box)}; "
        f"its bbox covers {100 * covered:.3g} % of the domain's and {100 * inside:.3g} % of its vertices lie "
        f"in the domain (adapting needs {100 * MISSED_BELOW:g} % of each). Is the mesh in other units than the "
        "domain (km against metres: a mesh written with units='km' reads back in km) or about another origin? "
        "Scale or shift its points to the domain's, or mesh the domain afresh (generate_mesh)"
    )


def _extent(low, high):
    """``(x0, y0) .. (x1, y1)`` with the sides' lengths, for a message."""
    corners = " .. ".join("(" + ", ".join(f"{value:g}" for value in corner) + ")" for corner in (low, high))
    return f"{corners} ({' x '.join(f'{side:g}' for side in high - low)})"


BOUNDARY_SHIFT = 0.25
"""Sizes by which a point's distance to the new boundary may differ from that to the old one, the boundary unmoved."""

FOOT_REACH = 1.5
"""Sizes from a new fixed point within which the old points are freed (an old vertex is about a size away)."""


def restarted(domain, size, h0, tolerance, fixed, points, changed, max_iter, move_tolerance, cells=None):
    """A mesh generated from ``points`` (an old mesh's vertices) for ``size``, fixed points ``fixed`` first.

    ``changed(points)`` masks the points whose surroundings must be meshed
    anew (where the size changed, along a seam between strips), and so do
    the points where the domain's boundary moved, given the old mesh's
    ``cells`` (:func:`_where_the_boundary_moved`). Points
    away from them (``FREE_RINGS`` rings of neighbours) stay exactly where
    they are, and the density is matched where they are (beyond
    ``CHANGED_DENSITY``). With ``changed`` None every point may move and the
    density is matched everywhere (to within ``THIN_BELOW`` and
    ``FILL_ABOVE``). Given the old ``cells``, the parts of the domain the
    old mesh does not reach get the generator's seeds first
    (:func:`seeds_beyond_mesh`). Does not warn; ``info`` holds the last level's record
    of :func:`~terramesh.generate_mesh`, ``added``, ``removed``, ``seeded`` and ``h0``.
    """
    finite_step = finite_difference_step(h0, np.vstack(bounds(points)))
    # vertices outside go; those just outside (a boundary vertex within the old mesh's tolerance, which
    # a smaller new h0 makes stricter) are projected, not dropped: dropping left holes to refill
    old_points = points
    distance, target = domain.distance(points), size(points)
    near = distance <= 0.5 * target
    moved = _where_the_boundary_moved(points, distance, target, tolerance, fixed, cells)
    points, distance, moved = points[near], distance[near], moved[near]
    outside = distance > tolerance
    points[outside] = project_to_boundary(domain, points[outside], distance[outside], finite_step)
    seeded = np.empty((0, 2)) if cells is None else seeds_beyond_mesh(domain, size, h0, tolerance, old_points, cells)
    seeded = seeded[beyond_fixed(seeded, fixed, 0.5 * h0)]
    kept = beyond_fixed(points, fixed, 0.5 * h0)
    n_fixed = len(fixed)
    points = np.vstack([fixed, points[kept], seeded])
    own = np.concatenate([np.ones(n_fixed, dtype=bool), ~moved[kept], np.zeros(len(seeded), dtype=bool)])
    fresh = np.arange(len(points)) >= len(points) - len(seeded)
    if len(points) < 3:
        raise GenerationError(f"{len(points)} of the mesh's vertices lie in the domain: too few to adapt")
    triangulation = Triangulation(points, frame=True)
    order = triangulation.sort_spatially(np.arange(len(points)) < n_fixed)
    points, own, fresh = points[order], own[order], fresh[order]
    points, settled, added, removed = _match_density(
        domain, size, changed, tolerance, points, triangulation, n_fixed, finite_step, own, fresh
    )
    # the settled points go first and stay as fixed ones do, through the iterations and the smoothing:
    # where the size did not change the mesh is the old one
    points = points[triangulation.sort_spatially(settled)]
    n_settled = int(settled.sum())
    points, triangulation, record = relax(
        domain,
        size,
        tolerance,
        points,
        triangulation,
        n_settled,
        max_iter,
        move_tolerance,
        # seeds start at random, far from the equilibrium: the generator's window for its random start where they
        # are many (with 5, BP2004 with 6 % of the points seeded stalled with edges of up to 1.89 sizes, a half of
        # it with 1.73; 0.1 % seeded in a coast's crannies converge with 5 as the rest)
        STALL_WINDOW if len(seeded) > SEEDED_SHARE * len(points) else REFINED_STALL_WINDOW,
        finite_step,
        sweep=False,
    )
    adapted = finalize(domain, size, triangulation, points, n_fixed, tolerance, finite_step, n_held=n_settled)
    del record["seconds"]
    adapted.info.update(record, added=added + len(seeded), removed=removed, seeded=len(seeded), h0=h0)
    return adapted


def seeds_beyond_mesh(domain, size, h0, tolerance, points, cells, seeder=seed_points):
    """The generator's seeds where the old mesh does not reach.

    ``seeder`` places them: :func:`~terramesh.generation.seeding.seed_points`,
    or the 3D ``bcc_seed_points``. The old mesh is ``points`` and ``cells`` (all of it, in the domain or
    not). A seed is covered when the nearest old vertex is within
    ``COVERED`` (0.8) of the larger of the seed's size and the longest edge
    of that vertex's cells (:func:`_longest_edges_about`): an old mesh
    coarser than the new size covers its cells too, and the splitting of
    its long edges refines them. Beyond, where the domain grew past the old
    mesh (a model extended, a padding added), the seeds stand at the size's
    density; the splitting alone filled a half of BP2004 with edges of up to
    3.2 sizes. A lattice ``COARSE_CHECK`` times coarser is tried first, and
    where the old mesh covers all of it none is seeded: the fine seeds and
    their distances cost 60 ms at 50k vertices, a sixth of an adaptation. A
    gap narrower than that lattice is left to the splitting, which fills it
    well. Seeded with ``FILL_SEED``, so the same inputs give the same mesh.
    """
    from scipy.spatial import cKDTree

    tree = cKDTree(points)

    def uncovered(seeds):
        distance, nearest = tree.query(seeds)
        far = distance > COVERED * size(seeds)  # most seeds stop here, the cells' edges wanted for the rest
        far[far] = distance[far] > COVERED * _longest_edges_about(points, cells, nearest[far])
        return far

    def seeds(scale):
        try:
            return seeder(
                domain, scaled(size, scale), scale * h0, domain.bbox, np.random.default_rng(FILL_SEED), tolerance
            )[0]
        except GenerationError:  # no lattice point in the domain (one about a size across): none to add
            return np.empty((0, points.shape[1]))

    if not uncovered(seeds(COARSE_CHECK)).any():
        return np.empty((0, points.shape[1]))
    fine = seeds(1.0)
    return fine[uncovered(fine)]


def _longest_edges_about(points, cells, vertices):
    """Length of the longest edge of the ``cells`` about each of ``vertices`` (0 for a vertex of none).

    Every point of a cell lies within its circumradius of a corner, below
    the longest edge for all but flat cells: how far the old mesh reaches
    about a vertex, coarse or fine.
    """
    wanted = np.zeros(len(points), dtype=bool)
    wanted[vertices] = True
    about = cells[any_corner_in(wanted, cells)]
    corners = points[about]
    first, second = np.triu_indices(about.shape[1], 1)  # every pair of corners: a triangle's three, a tetrahedron's six
    sides = corners[:, first] - corners[:, second]  # (cells, pairs, dim)
    longest = np.sqrt(row_max(np.sum(sides**2, axis=2)))
    reach = np.zeros(len(points))
    np.maximum.at(reach, about.ravel(), np.repeat(longest, about.shape[1]))
    return reach[vertices]


def _met_by_the_old_vertices(domain, fixed, fixed_points, mesh, changed, tolerance):
    """``fixed`` with the domain's nodes replaced by the old ``mesh``'s vertices where it has them.

    The domain's nodes (its ``corners()``, less the user's ``fixed_points``)
    may follow the sizes: a :class:`~terramesh.seismic.ModelBox` spaces its
    side nodes by integrating ``1 / size`` along each side, so a size change
    anywhere along a side re-spaces all of that side's nodes (up to half a
    size, BP2004: 1,018 old vertices far from the change moved, by up to
    95 m), and one anywhere in the box shifts them all by up to 3 mm (the
    integration's step follows the smallest size). Fixed, the shifted nodes
    took the old boundary vertices' places and freed their neighbours. So a
    node within ``tolerance`` of an old vertex on the boundary is that vertex,
    and one where the size did not change that lies (within ``tolerance``)
    on an old boundary edge with both ends on the boundary is left out: the
    old boundary vertices about it, spaced for the same sizes, stay. The
    user's fixed points are kept as given.
    """
    from scipy.spatial import cKDTree

    if len(fixed) == 0:
        return fixed
    nodes = np.asarray(domain.corners(), dtype=np.float64).reshape(-1, 2)
    node = cKDTree(nodes).query(fixed)[0] == 0.0 if len(nodes) else np.zeros(len(fixed), dtype=bool)
    if fixed_points is not None:
        given = np.asarray(fixed_points, dtype=np.float64).reshape(-1, 2)
        node &= cKDTree(given).query(fixed)[0] > 0.0 if len(given) else True
    node = np.flatnonzero(node)
    if len(node) == 0:
        return fixed
    points = mesh.points
    near, vertex = cKDTree(points).query(fixed[node])
    on_boundary = np.abs(domain.distance(points[vertex])) <= tolerance
    snapped = (near <= tolerance) & on_boundary
    # one old vertex stands for one node only (nodes are more than the tolerance apart, as fixed points)
    snapped &= np.bincount(vertex[snapped], minlength=len(points))[vertex] == 1
    fixed = fixed.copy()
    fixed[node[snapped]] = points[vertex[snapped]]
    rest = node[~snapped]
    if len(rest):
        rest = rest[~changed(fixed[rest])]
    if len(rest) == 0:
        return fixed
    edges = boundary_edges(mesh.cells)
    ends = np.abs(domain.distance(points[edges.ravel()])).reshape(-1, 2) <= tolerance
    edges = edges[rows_all(ends)]
    if len(edges) == 0:
        return fixed
    covered = SegmentIndex(points[edges[:, 0]], points[edges[:, 1]]).distance(fixed[rest]) <= tolerance
    return np.delete(fixed, rest[covered], axis=0)


def _where_the_boundary_moved(points, distance, target, tolerance, fixed, cells):
    """Mask of the old points the domain's boundary moved near (none without the old mesh's ``cells``).

    A point within a size of the old or the new boundary whose distances to
    the two differ by more than ``BOUNDARY_SHIFT`` sizes, and one nearer
    than ``FOOT_REACH`` sizes to a fixed point that is no old vertex within
    ``tolerance`` (a box's fixed points, spread along a side the new box made
    shorter or longer, fall between the old ones). Held where they were (a
    model adapted without its padding), such points left cells of quality
    0.2 against the new boundary's points.
    """
    moved = np.zeros(len(points), dtype=bool)
    if cells is None:
        return moved
    from scipy.spatial import cKDTree

    boundary = boundary_edges(cells)
    on_old = np.zeros(len(points), dtype=bool)
    on_old[boundary.ravel()] = True
    # only points near either boundary can have moved: all distances to the old one cost 0.07 s at 50k points
    reach = FOOT_REACH * target
    candidates = (np.abs(distance) < reach) | with_neighbours(on_old, cells, 2)  # a cell's corners: neighbours
    candidates = np.flatnonzero(candidates)
    at, size = points[candidates], target[candidates]
    old_distance = SegmentIndex(points[boundary[:, 0]], points[boundary[:, 1]]).distance(at)
    new_distance = np.abs(distance[candidates])
    shifted = (np.minimum(old_distance, new_distance) < size) & (
        np.abs(new_distance - old_distance) > BOUNDARY_SHIFT * size
    )
    if len(fixed):
        new_fixed = fixed[cKDTree(at).query(fixed)[0] > tolerance]
        if len(new_fixed):
            shifted |= cKDTree(new_fixed).query(at)[0] < FOOT_REACH * size
    moved[candidates] = shifted
    return moved


def _match_density(domain, size, changed, tolerance, points, triangulation, n_fixed, finite_step, own, fresh):
    """``points`` with midpoints of long edges added in rounds, then thinned or filled to the density asked.

    ``own`` marks the points that are the old mesh's vertices where they
    were, ``fresh`` the seeds where the old mesh did not reach
    (:func:`seeds_beyond_mesh`): at the density asked already, they are
    neither thinned nor filled, and an edge between two of them is not
    split. ``triangulation`` (Delaunay for ``points``) follows. Returns ``(points,
    settled, added, removed)``: the points, a mask of those that need not
    move (:func:`_settled`) and the counts.
    """
    lazy_distance = LazyDistance(domain)  # the points' distances bound the cells': fewer centroids evaluated

    def mesh_edges(points):
        target = size(points)
        lazy_distance.update(points, np.zeros(len(points)), target)
        return target, flagged_mesh_edges(domain, triangulation, points, tolerance, lazy_distance)

    # no point moves here, points are only added and removed: where the size changed is known once for each
    changes = None if changed is None else changed(points)

    def with_changes(kept, middle):
        return None if changed is None else np.concatenate([kept, changed(middle)])

    added = 0
    for _ in range(MAX_DENSITY_ROUNDS):
        target, (cells, edges, on_boundary) = mesh_edges(points)
        # seeds are a lattice thinned at random, whose Delaunay edges reach 2 sizes before the forces even
        # them out: split, a half of BP2004 seeded afresh came out with 11 % more vertices than a fresh mesh
        long = (edge_ratios(points, edges, target) > SPLIT_RATIO) & ~all_corners_in(fresh, edges)
        if changed is not None:
            # with the old sizes the old mesh stands where nothing changed, its long edges too (a fresh mesh
            # that stalled has a few, up to 1.55 sizes): split, one moved 16 vertices far from the change
            long &= any_corner_in(with_neighbours(changes | ~own, edges, 1), edges)
        if not long.any():
            break
        middle = _midpoints(domain, points, edges, on_boundary, long, finite_step)
        points = changed_points(points, NO_INDICES, middle, triangulation, lazy_distance)
        own = np.concatenate([own, np.zeros(len(middle), dtype=bool)])
        fresh = np.concatenate([fresh, np.zeros(len(middle), dtype=bool)])
        changes = with_changes(changes, middle)
        added += len(middle)
    else:
        target, (cells, edges, on_boundary) = mesh_edges(points)
    # thinning and filling last: the gaps thinning leaves (up to twice the size) close in the force
    # iterations, where splitting them filled the thinned region up again
    stands_for = vertices_stood_for(points, cells, edges, on_boundary, target)
    matched = np.ones(len(points), dtype=bool) if changed is None else with_neighbours(changes, edges, 1)
    matched &= ~fresh
    few, many = (THIN_BELOW, FILL_ABOVE) if changed is None else (1.0 - CHANGED_DENSITY, 1.0 + CHANGED_DENSITY)
    excess = np.where(matched & (stands_for < few), 1.0 - stands_for, 0.0)
    shortfall = np.where(matched & (stands_for > many), stands_for - 1.0, 0.0)
    excess[:n_fixed] = 0.0
    thinned = diffused(excess)
    # a point is added in the middle of the longest edge of each vertex the diffusion picks
    longest = longest_edges(points, edges, target)[diffused(shortfall)]
    longest = np.unique(longest[(longest >= 0) & ~np.isin(longest, edges_of(edges, thinned))])
    middle = _midpoints(domain, points, edges, on_boundary, longest, finite_step)
    points = changed_points(points, thinned, middle, triangulation, lazy_distance)
    own = np.concatenate([np.delete(own, thinned), np.zeros(len(middle), dtype=bool)])
    changes = with_changes(None if changes is None else np.delete(changes, thinned), middle)
    added += len(middle)
    _, (_, edges, _) = mesh_edges(points)
    return points, _settled(edges, changes, own, n_fixed), added, len(thinned)


def _settled(edges, changed, own, n_fixed):
    """Mask of the points that need not move: the mesh's own vertices where nothing ``changed`` (a mask).

    A point is settled when it was a vertex of the mesh and did not
    change; points within ``FREE_RINGS`` rings of neighbours of one that
    did (or of a new point) are free to move too, so that the changes find
    their equilibrium among them. Fixed points count as settled; with
    ``changed`` None no other point does.
    """
    if changed is None:
        settled = np.zeros(len(own), dtype=bool)
        settled[:n_fixed] = True
        return settled
    free = with_neighbours(~own | changed, edges, FREE_RINGS)
    free[:n_fixed] = False
    return ~free


def _midpoints(domain, points, edges, on_boundary, chosen, finite_step):
    """Midpoints of the ``chosen`` edges, those of boundary edges projected onto the boundary."""
    return refined_points(
        domain,
        points,
        edges[chosen],
        on_boundary[chosen],
        lambda at, distance: project_to_boundary(domain, at, distance, finite_step),
    )
