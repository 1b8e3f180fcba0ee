"""Adapt a tetrahedral mesh to a changed size function from its own vertices (a 3D model update during FWI).

The 2D strategy of :mod:`terramesh.generation.adapt` in 3D: the old
vertices in the domain are kept, the generator's seeds fill what the old
mesh does not reach, long edges are split in rounds where the size fell,
and the density is thinned or filled to the size asked; then the force
iterations of :func:`~terramesh.generation.distmesh3d.generate_mesh_3d`
run from there, as they do from a refined coarse level (nearly in
equilibrium: they stop at the first tetrahedralisation after 20
iterations), followed by its sliver removal and smoothing.

One difference from 2D: a 3D mesh is not the Delaunay tetrahedralisation
of its vertices (sliver removal flips and moves), so holding the old
vertices cannot give back the old cells. Where the size did not change
(given the old sizes), the old vertices stay where they were through the
force iterations and the clean-up, as fixed points do; where the clean-up
cannot mend the mesh so, it runs again with them free.
"""

import logging

import numpy as np

from .._kernels.delaunay3d import duplicate_points
from ..errors import GenerationError, warn_user
from ..mesh.topology import all_corners_in, any_corner_in, boundary_faces, edges_on_faces, table_boundary_faces
from ..quality.tetra import radius_ratio
from .adapt import BOUNDARY_SHIFT, FOOT_REACH, seeds_beyond_mesh, size_changed
from .cells_inside import tetrahedralise
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
from .distances import finite_difference_step, project_to_boundary_3d
from .finalize3d import RAISE_BELOW, finalize_3d, without_hull_cells
from .fixed_points import beyond_fixed
from .levels import refined_points
from .relax3d import SETTLE_AFTER, relax_3d
from .seeding3d import bcc_seed_points
from .sharp_edges import encroaching_points, sharp_edge_balls, sharp_edge_chains, sharp_edge_points_among
from .triangulate import morton_order

__all__ = ["restarted_3d"]

logger = logging.getLogger(__name__)

# the rounds stop at this share of the points in long edges: each is a tetrahedralisation (0.15 s at 20k
# points), and after the first two the long edges of a model update at 20k points were 20, 5, 3, 1 (47, 46 ... with
# the old sizes, ten rounds)
FEW_LONG = 2e-3
FILL_ROUNDS = 3  # thinning, then filling where the size fell, each a tetrahedralisation
DISORDERED_SHARE = 0.1  # more than this share of the points seeded, put in or taken out: iterate to equilibrium
# what the generator's own meshes' vertices stand for: 1.01-1.21 for bulky shapes, up to 1.93 for a tube's thin wall;
# beyond, a warning (an old mesh described by sizes half or twice its own stands for 8 or 1/8)
BIAS_RANGE = (0.5, 2.5)
ON_BOUNDARY = 0.1  # sizes: an old vertex outside the domain by no more than this is projected onto it, not dropped


def restarted_3d(domain, size, h0, tolerance, fixed, mesh, old_size, max_iter, move_tolerance):
    """A tetrahedral mesh of ``domain`` for ``size`` generated from the old ``mesh``'s vertices.

    ``fixed`` (the user's fixed points and the domain's corners) come
    first, then the domain's sharp edges sampled by the new size (old
    vertices within half a size of an edge's line give way to its points).
    ``old_size`` is the size function the old mesh was made for, or None.
    Given, the density is matched only about the points where the size
    changed (:func:`~terramesh.generation.adapt.size_changed`), and the old
    vertices away from them (``FREE_RINGS`` rings of neighbours), from new
    points and from where the boundary or the sharp edges' points moved
    stay where they are, as fixed points do. Without it every vertex may
    move and the density is matched everywhere. The force iterations stop
    at the first tetrahedralisation after ``SETTLE_AFTER`` unless more than
    ``DISORDERED_SHARE`` of the points were seeded, put in or taken out (a
    start far from equilibrium: a size changed everywhere by 20 % came out
    at mean radius ratio 0.86 after 31 iterations, and at 0.895, as a fresh
    mesh, after 91). Returns the mesh;
    ``info`` holds the force iterations' record, ``added``, ``removed``,
    ``seeded``, ``held`` (old vertices held in place) and ``h0``.
    """
    changed = None if old_size is None else size_changed(size, old_size)
    bbox = np.asarray(domain.bbox, dtype=np.float64)
    finite_step = finite_difference_step(h0, bbox)
    old_points, old_cells = mesh.points, mesh.cells
    distance, target = domain.distance(old_points), size(old_points)
    # vertices outside go, but those less than ``ON_BOUNDARY`` sizes out are projected (an old boundary vertex a
    # rounding out, which a smaller new h0 finds outside its tolerance; one the boundary moved past by a little);
    # the seeds fill where the others were
    old_faces = boundary_faces(old_cells)
    on_old = np.zeros(len(old_points), dtype=bool)
    on_old[old_faces.ravel()] = True
    # an old boundary vertex now inside (the domain grew there: a model extended, a bump added) goes, and seeds
    # fill its place: kept, a face's vertices in one plane inside a bump gave flat cells that no move mended
    near = (distance <= ON_BOUNDARY * target) & ~(on_old & (distance < -BOUNDARY_SHIFT * target))
    own = ~_where_the_boundary_moved(old_points, old_cells, on_old, distance, target, tolerance)[near]
    points, distance = old_points[near], distance[near]
    outside = distance > tolerance
    points[outside] = project_to_boundary_3d(domain, points[outside], distance[outside], finite_step, newton_steps=3)
    seeded = seeds_beyond_mesh(
        domain, size, h0, tolerance, points, _kept_cells(old_cells, near), seeder=bcc_seed_points
    )
    free = np.vstack([points, seeded])
    own = np.concatenate([own, np.zeros(len(seeded), dtype=bool)])
    fresh = np.arange(len(free)) >= len(points)
    kept = beyond_fixed(free, fixed, 0.5 * h0)
    free, own, fresh = free[kept], own[kept], fresh[kept]
    chains = sharp_edge_chains(domain, size, h0)
    edge, displaced = sharp_edge_points_among(domain, size, h0, bbox, tolerance, fixed, free, chains)
    # and so does any point within half a size of an edge's line: an old face's vertices beside an edge that a new
    # operand made (a bump added to a box's face) left cells across it, where the generator's seeds, within half
    # a size of an edge point only, are moved by the forces first
    displaced |= _near_lines(free, chains, size)
    free, own, fresh = free[~displaced], own[~displaced], fresh[~displaced]
    held = np.vstack([fixed, edge])
    # a held point that is no old vertex (a new fixed point, an edge point spaced by a changed size) stands
    # where the old vertices were spaced otherwise: those about it move; so do those in a new edge's balls, which
    # the final clean-up drops (held, they stayed: a bump added to a box's face gave cells across its new edge)
    own &= _far_from_new(held, old_points, free, size, tolerance)
    edge_balls = sharp_edge_balls(domain, chains, tolerance)
    own &= ~encroaching_points(np.vstack([held, free]), len(held), *edge_balls)[len(held) :]
    order = morton_order(free)
    free, own, fresh = free[order], own[order], fresh[order]
    if len(held) + len(free) < 4:
        raise GenerationError(f"{len(held) + len(free)} points lie in the domain: too few to adapt")
    bias = 1.0 if old_size is None else density_bias(mesh, old_faces, old_size)
    fell = None if old_size is None else (lambda points: size(points) < (1.0 - SIZE_CHANGE) * old_size(points))
    free, settled, added, removed = _match_density(
        domain, size, changed, fell, tolerance, held, free, own, fresh, finite_step, bias
    )
    # the settled old vertices go just after the held points and stay, as they do, through the force iterations
    points = np.vstack([held, free[settled], free[~settled]])
    n_settled = int(settled.sum())
    settle = 0 if len(seeded) + added + removed > DISORDERED_SHARE * len(points) else SETTLE_AFTER
    points, record = relax_3d(
        domain,
        size,
        np.ascontiguousarray(points),
        len(held) + n_settled,
        tolerance,
        finite_step,
        max_iter,
        move_tolerance,
        settle,
    )
    try:
        adapted = finalize_3d(domain, size, points, len(held) + n_settled, tolerance, finite_step, edge_balls)
    except GenerationError as error:
        if not n_settled:
            raise
        # held vertices never cost a mesh: the clean-up may move them, as the generator's own
        logger.info("the clean-up refused the mesh with its old vertices held (%s): freeing them", error)
        adapted, n_settled = finalize_3d(domain, size, points, len(held), tolerance, finite_step, edge_balls), 0
    else:
        worst = float(radius_ratio(adapted.points, adapted.cells).min())
        if n_settled and worst < RAISE_BELOW:
            # nor a cell the polish would have raised: a held vertex kept one at radius ratio 0.19 (fresh: 0.30)
            freed = finalize_3d(domain, size, points, len(held), tolerance, finite_step, edge_balls)
            if radius_ratio(freed.points, freed.cells).min() > worst:
                logger.info("a cell of radius ratio %.3f with the old vertices held: freed them", worst)
                adapted, n_settled = freed, 0
    del record["seconds"]
    adapted.info.update(record, added=added + len(seeded), removed=removed, seeded=len(seeded), held=n_settled, h0=h0)
    return adapted


def _near_lines(points, chains, size, steps=8):
    """Mask of the ``points`` within half their size of a chain's polyline (sampled ``steps`` times a segment)."""
    near = np.zeros(len(points), dtype=bool)
    if not chains or len(points) == 0:
        return near
    from scipy.spatial import cKDTree

    fractions = np.arange(steps)[:, None, None] / steps
    lines = np.concatenate(
        [(chain[:-1] + fractions * (chain[1:] - chain[:-1])).reshape(-1, 3) for chain in chains]
        + [chain[-1:] for chain in chains]
    )
    reach = 0.5 * size(points)
    distance = cKDTree(lines).query(points, distance_upper_bound=float(reach.max()))[0]
    return distance < reach


def _kept_cells(cells, kept):
    """``cells`` among the ``kept`` points only, renumbered (an old mesh's cells about the vertices kept)."""
    index = np.cumsum(kept) - 1
    return index[cells[all_corners_in(kept, cells)]]


def _where_the_boundary_moved(points, cells, on_old, distance, target, tolerance):
    """Mask of the old vertices the domain's boundary moved near: freed, they find the new boundary.

    An old boundary vertex now off the boundary (beyond ``tolerance``: held
    a rounding inside a face moved out by a hundredth of a size, 332 of a
    ball's boundary vertices were left off it), and an old interior vertex
    within that of it or beyond with no old boundary vertex within
    ``FOOT_REACH`` sizes (the boundary came to it from afar; one a fifth of
    a size inside an unmoved face is common, and freeing it with its
    neighbours moved old vertices three rings into a model whose boundary
    had not changed), with their neighbours. ``on_old`` marks the old
    boundary vertices.
    """
    from scipy.spatial import cKDTree

    reach = BOUNDARY_SHIFT * target
    shifted = on_old & (np.abs(distance) > tolerance)
    near_new = np.flatnonzero(~on_old & (distance > -reach))
    if len(near_new) and on_old.any():
        beyond = cKDTree(points[on_old]).query(points[near_new])[0] > FOOT_REACH * target[near_new]
        shifted[near_new[beyond]] = True
    return with_neighbours(shifted, cells, 1)


def _far_from_new(held, old_points, free, size, tolerance):
    """Mask of the ``free`` points farther than ``FOOT_REACH`` sizes from every held point that is no old vertex."""
    from scipy.spatial import cKDTree

    if len(held) == 0 or len(free) == 0:
        return np.ones(len(free), dtype=bool)
    new = held[cKDTree(old_points).query(held)[0] > tolerance]
    if len(new) == 0:
        return np.ones(len(free), dtype=bool)
    return cKDTree(new).query(free)[0] >= FOOT_REACH * size(free)


def _match_density(domain, size, changed, fell, tolerance, held, free, own, fresh, step, bias):
    """The ``free`` points with midpoints of long edges added in rounds, then thinned or filled to the density asked.

    As the 2D :func:`~terramesh.generation.adapt._match_density`, on
    tetrahedralisations made afresh each round (a few, against the force
    iterations' tens), the ``held`` points among them. ``own`` marks the
    old vertices where they were, ``fresh`` the seeds where the old mesh did
    not reach (at the density asked already: neither thinned nor filled, an
    edge between two of them not split). With ``changed``, the density is
    matched to within ``CHANGED_DENSITY`` of ``bias`` (what the old mesh's
    vertices stand for at the old sizes, :func:`density_bias`), and then,
    in up to ``FILL_ROUNDS - 1`` more rounds, filled to ``bias`` where the
    size ``fell`` (a mask of points, or None). Returns
    ``(free points, settled mask, added, removed)``.
    """
    n_held = len(held)
    padded = lambda mask, value: np.concatenate([np.full(n_held, value), mask])  # noqa: E731  (held, then free)

    def mesh_edges(free):
        points = np.vstack([held, free])
        cells, neighbors = tetrahedralise(domain, points, tolerance, neighbors=True)
        # boundary points alone make flat cells across a curved side, their edges chords of many sizes (a
        # cylinder's: up to 13 sizes; split in rounds, 1,740 vertices became 2,500 where the size had not changed)
        cells, neighbors = without_hull_cells(domain, size, points, cells, neighbors, tolerance)
        edges, on_boundary = edges_on_faces(cells, table_boundary_faces(cells, neighbors), len(points))
        return points, size(points), cells, edges, on_boundary

    def midpoints(points, edges, on_boundary, chosen):
        def project(at, distance):
            return project_to_boundary_3d(domain, at, distance, step, newton_steps=3)

        middle = refined_points(domain, points, edges[chosen], on_boundary[chosen], project)
        return middle[~duplicate_points(np.vstack([points, middle]))[len(points) :]]

    changes = None if changed is None else changed(free)
    added = 0
    for _ in range(MAX_DENSITY_ROUNDS):
        points, target, cells, edges, on_boundary = mesh_edges(free)
        long = (edge_ratios(points, edges, target) > SPLIT_RATIO) & ~all_corners_in(padded(fresh, False), edges)
        if changes is not None:  # the old mesh stands where nothing changed, its few long edges too
            long &= any_corner_in(with_neighbours(padded(changes | ~own, False), edges, 1), edges)
        if np.count_nonzero(long) <= FEW_LONG * len(points):
            break
        middle = midpoints(points, edges, on_boundary, long)
        free = np.vstack([free, middle])
        none = np.zeros(len(middle), dtype=bool)
        own, fresh = np.append(own, none), np.append(fresh, none)
        changes = None if changes is None else np.append(changes, changed(middle))
        added += len(middle)
    else:
        points, target, cells, edges, on_boundary = mesh_edges(free)
    # thinning and filling last: the gaps thinning leaves close in the force iterations
    removed = 0
    for fill_round in range(FILL_ROUNDS if fell is not None else 1):
        if fill_round:
            points, target, cells, edges, on_boundary = mesh_edges(free)
        stands_for = vertices_stood_for(points, cells, edges, on_boundary, target)
        if changes is None:
            matched, few, many = padded(~fresh, False), THIN_BELOW, FILL_ABOVE
        elif not fill_round:
            # and where old vertices were freed: an old boundary face inside now (the model extended) is a layer
            # of the boundary's density (a box extended by half its length came out with 15 % more vertices)
            matched = with_neighbours(padded(changes | ~own, False), edges, 1) & padded(~fresh, False)
            few, many = bias * (1.0 - CHANGED_DENSITY), bias * (1.0 + CHANGED_DENSITY)
        else:
            # a vertex gets at most one midpoint a round: where the size fell everywhere by 1.4 (2.7 vertices for
            # one) one round left BP2004 3D 4 % short of a fresh mesh's vertices (edges 1.03 of their size); the
            # later rounds fill, where the size fell only (filling elsewhere undid the thinning), to the bias
            matched = with_neighbours(padded(fell(free), False), edges, 1) & padded(~fresh, False)
            few, many = 0.0, bias
        excess = np.where(matched & (stands_for < few), 1.0 - stands_for / bias, 0.0)
        shortfall = np.where(matched & (stands_for > many), stands_for / bias - 1.0, 0.0)
        if fill_round and np.sum(shortfall) < FEW_LONG * len(points):
            break
        thinned = diffused(excess)  # all past the held points, whose excess is 0
        longest = longest_edges(points, edges, target)[diffused(shortfall)]
        longest = np.unique(longest[(longest >= 0) & ~np.isin(longest, edges_of(edges, thinned))])
        middle = midpoints(points, edges, on_boundary, longest)
        keep = np.ones(len(free), dtype=bool)
        keep[thinned - n_held] = False
        free = np.vstack([free[keep], middle])
        own = np.append(own[keep], np.zeros(len(middle), dtype=bool))
        fresh = np.append(fresh[keep], np.zeros(len(middle), dtype=bool))
        added += len(middle)
        removed += len(thinned)
        if changes is not None:
            changes = np.append(changes[keep], changed(middle))
    if changes is None:
        return free, np.zeros(len(free), dtype=bool), added, removed
    _, _, _, edges, _ = mesh_edges(free)
    moving = with_neighbours(padded(changes | ~own, False), edges, FREE_RINGS)
    return free, ~moving[n_held:], added, removed


def density_bias(mesh, faces, old_size):
    """The median of what the old ``mesh``'s vertices stand for (:func:`vertices_stood_for`) at its own sizes.

    The measure is biased by the mesh's arrangement and its boundary: 1.01
    on a box's generated mesh, 1.15 on a ball's. Matched to 1 within
    ``CHANGED_DENSITY``, a ball's vertices where the size changed were
    filled 13 % above a fresh mesh's count; matched to this, as the old
    mesh stands. ``faces`` are the mesh's boundary faces.
    """
    cells = mesh.cells
    edges, on_boundary = edges_on_faces(cells, faces, mesh.n_points)
    used = np.unique(cells)
    bias = float(np.median(vertices_stood_for(mesh.points, cells, edges, on_boundary, old_size(mesh.points))[used]))
    if not BIAS_RANGE[0] <= bias <= BIAS_RANGE[1]:
        warn_user(
            f"the old mesh's vertices stand for {bias:.2f} vertices each at old_edge_length (a mesh made for those"
            f" sizes: {BIAS_RANGE[0]:g}-{BIAS_RANGE[1]:g}): is old_edge_length the size the mesh was made for? An"
            " adapted mesh keeps that density where the size did not change, and a change everywhere is meshed afresh"
        )
    return bias
