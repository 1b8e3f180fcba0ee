"""The final 3D mesh: Delaunay cells inside the domain, slivers removed, then smoothed where no cell gets worse.

Interior points too close to the boundary and free points by a sharp edge
go; the boundary vertices are projected onto the boundary; flat cells of
boundary vertices alone are peeled off; the slivers are removed
(:mod:`terramesh.cleanup.slivers`), and a mesh with any cell still below
``MIN_DIHEDRAL`` is refused. Then the vertices are polished, the ends of
short edges moved apart, and the boundary surface checked.
"""

import time

import numpy as np

from .._kernels.delaunay3d import boundary_vertex_mask, duplicate_points
from .._kernels.smoothing import CUBE_DIRECTIONS, move_where_better, raise_worst
from .._kernels.smoothing3d import lengthen_short_edges, short_edge_vertices, smooth_interior_3d
from .._kernels.tetra import min_dihedral_all, radius_ratio_all, volumes_all
from ..cleanup.fix_mesh import remove_unused_points
from ..cleanup.slivers import MIN_DIHEDRAL, STEPS, feature_vertices, remove_slivers
from ..cleanup.validity import boundary_surface_problems, cells_outside
from ..errors import GenerationError, point_text, warn_user
from ..geometry.base import FunctionDomain, distance_gradient
from ..geometry.csg import known_by_distance_alone, leaf_solids
from ..mesh.columns import rows_any
from ..mesh.mesh import Mesh
from ..mesh.topology import all_corners_in, any_corner_in, kept_cells, table_boundary_faces
from .cells_inside import tetrahedralise
from .distances import project_to_boundary_3d
from .finalize import raise_if_no_cells
from .fixed_points import fixed_near_boundary_words
from .sharp_edges import encroaching_points

STUCK_DEPTH = 0.15  # interior points closer than this many local sizes to the boundary are dropped at the end
FINAL_NEWTON_STEPS = 6  # at most, for the boundary vertices of the final mesh
HULL_FACE_OUTSIDE = 0.25  # a final cell of boundary corners only with a face centroid this many sizes out goes...
HULL_FLAT_DEPTH = 0.1  # ...and one with a dihedral angle under MIN_DIHEDRAL and its centroid this close inside
ENCROACHED_ROUNDS = 3  # final tetrahedralisations at most, each after dropping points projected next to a sharp edge
POLISH_PASSES = 2  # passes of quality-safe smoothing of the interior vertices after sliver removal...
POLISH_ROUNDS = 3  # ...started again at most this many times, after freezing vertices it took outside
RAISE_BELOW = 0.3  # then the vertices of cells below this radius ratio go where their worst cell is best...
RAISE_PASSES = 3  # ...the interior ones in at most this many passes (the boundary ones in one, along it)
FACE_TURN = 90.0  # degrees between a boundary face's normal and the boundary's beyond which it cuts across
SHORT_EDGE = 0.45  # the ends of edges shorter than this many sizes move apart where their cells allow...
SHORT_EDGE_ROUNDS = 2  # ...in at most this many rounds
THIN_SIZES = 3.0  # a domain fewer sizes than this across its thinnest side is called thin when slivers remain


def finalize_3d(domain, size, points, n_fixed, tolerance, finite_step, edge_balls=None):
    """The final points' Delaunay cells inside the domain, boundary vertices projected, slivers removed.

    ``edge_balls`` (see :func:`~.sharp_edges.sharp_edge_balls`): free points inside them are
    dropped, so that the sharp edges' segments are edges of the cells.
    """
    started = time.perf_counter()
    # a point stuck just inside the boundary makes flat cells with the boundary points above it
    distance = domain.distance(points)
    stuck = (distance < -tolerance) & (distance > -STUCK_DEPTH * size(points))
    stuck[:n_fixed] = False
    centres, radii = (np.empty((0, 3)), np.empty(0)) if edge_balls is None else edge_balls
    stuck |= encroaching_points(points, n_fixed, centres, radii)
    points = points[~stuck & ~duplicate_points(points)]
    for attempt in range(ENCROACHED_ROUNDS):
        cells, neighbors = tetrahedralise(domain, points, tolerance, neighbors=True)
        raise_if_no_cells(cells)
        points = points.copy()
        mask = boundary_vertex_mask(cells, neighbors, np.ones(len(cells), dtype=bool), len(points))
        on_boundary = np.flatnonzero(mask)
        on_boundary = on_boundary[on_boundary >= n_fixed]
        points[on_boundary] = project_to_boundary_3d(
            domain,
            points[on_boundary],
            domain.distance(points[on_boundary]),
            finite_step,
            newton_steps=FINAL_NEWTON_STEPS,
        )
        # an interior point that the cells left on the boundary may have been projected next to an edge
        encroaching = encroaching_points(points, n_fixed, centres, radii)
        if not encroaching.any() or attempt == ENCROACHED_ROUNDS - 1:
            break
        points = points[~encroaching]
    cells, neighbors = without_hull_cells(domain, size, points, cells, neighbors, tolerance)
    slivers_before = int(np.sum(min_dihedral_all(points, cells) < MIN_DIHEDRAL))

    def boundary_candidates(points, vertices):
        return _boundary_candidates(domain, points, vertices, size(points[vertices]), finite_step, tolerance)

    points, cells, neighbors, rounds = remove_slivers(domain, points, cells, neighbors, n_fixed, boundary_candidates)
    cells, neighbors = without_hull_cells(domain, size, points, cells, neighbors, tolerance)
    raise_if_no_cells(cells)  # the clean-up may take the last ones (a ball a few sizes across)
    points, cells, kept = remove_unused_points(points, cells)
    on_boundary = np.zeros(len(points), dtype=bool)
    on_boundary[table_boundary_faces(cells, neighbors).ravel()] = True
    free = kept >= n_fixed
    slidable = on_boundary & free & ~feature_vertices(points, cells, neighbors, len(points))
    movable = ~on_boundary & free
    points, outside = polished_3d(domain, points, cells, movable, on_boundary, slidable, boundary_candidates)
    if not outside.any():
        points = _lengthened(domain, size, points, cells, movable, on_boundary, slidable, boundary_candidates)
    angles = min_dihedral_all(points, cells)
    slivers = int(np.sum(angles < MIN_DIHEDRAL))
    if slivers:
        thin = (
            _too_thin(points, size)
            or _near_fixed(domain, size, points[~free], tolerance)
            or (
                "a feature of the domain thinner than the size there (a step, a gap, sharp edges closer than"
                " the size) cannot be held"
            )
        )
        worst = points[cells[np.argmin(angles)]].mean(axis=0)
        where = ", ".join(f"{value:.4g}" for value in worst)
        raise GenerationError(
            f"{slivers} slivers remain (cells with a dihedral angle below {MIN_DIHEDRAL:g} degrees, the smallest "
            f"{max(float(angles.min()), 0.0):.2f}, at ({where}) where the size is {float(size(worst[None])[0]):.4g}) "
            f"after {rounds} rounds of sliver removal; {thin}: try a smaller edge length there or another seed"
            + _unknown_edges(domain)
        )
    problems, place = _problems(points, cells, neighbors)
    if outside.any():
        problems.append(f"{int(outside.sum())} cells have their centroid outside the domain")
        place = points[cells[np.argmax(outside)]].mean(axis=0) if place is None else place
    across = _faces_across(domain, points, cells, neighbors, finite_step)
    if across:
        problems.append(f"{across} boundary faces cut across the domain instead of lying on its boundary")
    if problems:
        thin = _too_thin(points, size) or _near_fixed(domain, size, points[~free], tolerance)
        raise GenerationError(
            "mesh generation produced an invalid mesh: "
            + "; ".join(problems)
            + ("" if place is None else f" (the first near {point_text(place)})")
            + (
                f"; {thin}"
                if thin
                else ". A part of the domain thinner than about two edge lengths (a hole, a gap, a neck, solids "
                "touching along an edge or at a point) or a crease the generator does not know (surfaces meeting at a "
                "sharp angle, as lobes of a body from a mask do) cannot be meshed at this size"
            )
            + ": a smaller edge length there, or another seed, may help"
            + _unknown_edges(domain)
        )
    _warn_if_off_boundary(domain, size, points, np.flatnonzero(on_boundary & free), tolerance)
    info = {
        "min_dihedral": float(angles.min()),
        "slivers_before": slivers_before,
        "sliver_rounds": rounds,
        "sliver_seconds": time.perf_counter() - started,
    }
    return Mesh(points, cells, info=info)


def polished_3d(domain, points, cells, movable, on_boundary, slidable, boundary_candidates):
    """``points`` after quality-safe smoothing of the ``movable`` vertices, and the cells outside.

    In ``POLISH_PASSES`` each vertex moves to its neighbours' mean where
    neither the worst mean ratio nor the smallest dihedral angle of its
    cells falls (:func:`~terramesh._kernels.smoothing3d.smooth_interior_3d`):
    on the ball of ``bench_3d.py`` the cells of radius ratio below 0.3 go
    from 44 to 3. Then the vertices of cells below ``RAISE_BELOW`` move to
    the nearby place best for their worst cell, with no dihedral angle
    smaller than before (:func:`~terramesh._kernels.smoothing.raise_worst`):
    those 3 go, and on the ball at 64k vertices 68 (the worst 0.086), the
    mean unchanged. The ``slidable`` boundary vertices of cells still below
    it then move to the best of ``boundary_candidates(points, vertices)``,
    positions on the boundary (:func:`~terramesh._kernels.smoothing.move_where_better`).
    A move does not see the domain: next to a concave boundary it can take
    an interior vertex or a cell's centroid out. The vertices of such cells
    are frozen and the smoothing starts again from ``points`` (at most
    ``POLISH_ROUNDS`` times, then ``points`` as they were). Returns the
    points and the mask of their cells whose centroid is outside
    (:func:`~terramesh.cleanup.validity.cells_outside`).
    """
    movable, slidable = movable.copy(), slidable.copy()
    for _ in range(POLISH_ROUNDS):
        smoothed = points.copy()
        smooth_interior_3d(smoothed, cells, movable, POLISH_PASSES)
        raise_worst(smoothed, cells, movable, RAISE_BELOW, RAISE_PASSES)
        poor = np.unique(cells[radius_ratio_all(smoothed, cells) < RAISE_BELOW])
        sliding = poor[slidable[poor]]
        if len(sliding):
            move_where_better(smoothed, cells, sliding, boundary_candidates(smoothed, sliding))
        moved = np.flatnonzero(rows_any(smoothed != points) & ~on_boundary)
        escaped = moved[domain.distance(smoothed[moved]) >= 0]
        outside = cells_outside(domain, smoothed, cells, on_boundary)
        if len(escaped) == 0 and not outside.any():
            return smoothed, outside
        movable[cells[outside].ravel()] = slidable[cells[outside].ravel()] = False
        movable[escaped] = False
    return points, cells_outside(domain, points, cells, on_boundary)


def _lengthened(domain, size, points, cells, movable, on_boundary, slidable, boundary_candidates):
    """``points`` with the ends of edges shorter than ``SHORT_EDGE`` times their size moved apart where cells allow.

    The interior ends try the 26 cube directions at ``STEPS`` of their
    size, the ``slidable`` boundary ones ``boundary_candidates``; a move
    keeps every dihedral angle of the vertex's cells at least their smallest
    before and their worst radius ratio at least ``min(before, RAISE_BELOW)``
    (:func:`~terramesh._kernels.smoothing3d.lengthen_short_edges`). Where
    the moves take a cell's centroid out of the domain, its vertices are
    frozen and the lengthening starts again from ``points`` (at most
    ``POLISH_ROUNDS`` times, then ``points`` as they were). On the 3-D
    BP2004 example made for a time step, 2-7 edges of 360k were 0.37-0.44 of
    their size, and the shortest one set a time step 0.975 of the one asked.
    """
    movable, slidable = movable.copy(), slidable.copy()
    sizes = size(points)
    for _ in range(POLISH_ROUNDS):
        lengthened = points.copy()
        for _ in range(SHORT_EDGE_ROUNDS):
            short = np.flatnonzero(short_edge_vertices(lengthened, cells, sizes, SHORT_EDGE) & (movable | slidable))
            if len(short) == 0:
                break
            inside = movable[short]
            candidates = np.repeat(lengthened[short, None, :], len(STEPS) * len(CUBE_DIRECTIONS), axis=1)
            if inside.any():
                candidates[inside] = _around(domain, lengthened[short[inside]], sizes[short[inside]])
            if not inside.all():  # fewer along the boundary; the rest stay where the vertex is, never lengthening it
                along = boundary_candidates(lengthened, short[~inside])
                candidates[~inside, : along.shape[1]] = along
            if lengthen_short_edges(lengthened, cells, sizes, short, candidates, SHORT_EDGE, RAISE_BELOW) == 0:
                break
        changed = rows_any(lengthened != points)
        if not changed.any():
            return points
        stars = np.flatnonzero(any_corner_in(changed, cells))
        outside = cells[stars[cells_outside(domain, lengthened, cells[stars], on_boundary)]]
        if len(outside) == 0:
            return lengthened
        # each move was checked with the earlier ones made: undoing some alone could invert a cell
        movable[outside.ravel()] = slidable[outside.ravel()] = False
    return points


def _around(domain, where, scale):
    """Positions around each point: the 26 cube directions at ``STEPS`` of its ``scale``, the point where outside."""
    steps = STEPS[None, :, None, None] * scale[:, None, None, None]
    around = (where[:, None, None, :] + steps * CUBE_DIRECTIONS[None, None, :, :]).reshape(len(where), -1, 3)
    outside = domain.distance(around.reshape(-1, 3)).reshape(around.shape[:2]) >= 0
    around[outside] = np.repeat(where[:, None, :], around.shape[1], axis=1)[outside]
    return around


def _boundary_candidates(domain, points, vertices, scale, finite_step, tolerance):
    """Positions on the boundary around each vertex: 8 tangent directions times 5 steps, projected; (k, 40, 3)."""
    where = points[vertices]
    distance = domain.distance(where)
    normal = distance_gradient(domain, where, distance, finite_step)
    normal /= np.maximum(np.sqrt(np.einsum("ij,ij->i", normal, normal)), 1e-300)[:, None]
    helper = np.eye(3)[np.argmin(np.abs(normal), axis=1)]
    first = np.cross(normal, helper)
    first /= np.maximum(np.sqrt(np.einsum("ij,ij->i", first, first)), 1e-300)[:, None]
    second = np.cross(normal, first)
    angles = np.arange(8) * (np.pi / 4.0)
    directions = np.cos(angles)[None, :, None] * first[:, None, :] + np.sin(angles)[None, :, None] * second[:, None, :]
    steps = STEPS[None, :, None, None] * scale[:, None, None, None]
    candidates = (where[:, None, None, :] + steps * directions[:, None, :, :]).reshape(-1, 3)
    projected = project_to_boundary_3d(domain, candidates, domain.distance(candidates), finite_step, newton_steps=3)
    off = np.abs(domain.distance(projected)) > tolerance
    projected[off] = np.repeat(where, len(STEPS) * 8, axis=0)[off]
    return np.ascontiguousarray(projected.reshape(len(vertices), -1, 3))


def _faces_across(domain, points, cells, neighbors, step):
    """How many boundary faces turn more than ``FACE_TURN`` degrees from the boundary under them.

    A face of the mesh's surface lies on the domain's boundary, its outward
    normal near the gradient of the distance at its centroid (cosines of
    0.92 and above on balls meshed three sizes across, boxes, CSG, masks).
    A face bevelling a sharp edge the mesh does not follow turns by half the
    edge's angle, less than 90 degrees (cosines of 0.53-0.62 where a
    topography meets a box's side at 50 degrees). In a slab thinner than the
    size the faces run across it instead, facing against the boundary
    (cosines below -0.5): a slab 0.05 thick meshed at 0.1 came back with its
    edges bevelled off, 75-82 % of its volume, and no error.
    """
    faces, opposite = table_boundary_faces(cells, neighbors, opposite=True)
    a, b, c = (points[faces[:, k]] for k in range(3))
    centroid = (a + b + c) / 3.0
    normal = np.cross(b - a, c - a)
    normal *= np.where(np.einsum("ij,ij->i", normal, points[opposite] - centroid) > 0, -1.0, 1.0)[:, None]
    gradient = np.stack(
        [domain.distance(centroid + step * unit) - domain.distance(centroid - step * unit) for unit in np.eye(3)],
        axis=1,
    )
    cosine = np.einsum("ij,ij->i", normal, gradient) / np.maximum(
        np.linalg.norm(normal, axis=1) * np.linalg.norm(gradient, axis=1), np.finfo(np.float64).tiny
    )
    return int(np.sum(cosine < np.cos(np.radians(FACE_TURN))))


def _too_thin(points, size):
    """Why a domain fewer than THIN_SIZES sizes across its thinnest side cannot be meshed, or ``""``."""
    thinnest = float((points.max(axis=0) - points.min(axis=0)).min())
    median = float(np.median(size(points)))
    across = thinnest / median
    if across >= THIN_SIZES:
        return ""
    # the median size named: "1 across its thinnest side, 2.9 sizes" read as a contradiction (a graded domain)
    return (
        f"the domain is {thinnest:.4g} across its thinnest side, {across:.2g} sizes (its median size {median:.4g}): "
        "too thin for tetrahedra of that size"
    )


def _near_fixed(domain, size, fixed, tolerance):
    """Why ``fixed`` points less than half a size inside the boundary may have failed the mesh, or ``""``.

    A box at h 0.17 with one 0.09 sizes in by a corner: a face across the
    domain, which the message called too thin.
    """
    near = fixed_near_boundary_words(fixed, domain.distance(fixed), size, tolerance) if len(fixed) else ""
    if not near:
        return ""
    return f"{near}: no good cells fit between them and the boundary; move them onto it or half a size in"


def _unknown_edges(domain):
    """Words on sharp edges the generator may not know, or ``""``.

    A :class:`~terramesh.geometry.FunctionDomain` says none unless given
    (``sharp_edges``), and in a combination the edges where the surface of
    an operand known by its distance alone (a user's function, a grid)
    meets another operand's are known to no one.
    """
    leaves = leaf_solids(domain)
    words = []
    if any(isinstance(leaf, FunctionDomain) and not leaf.sharp_edges_given for leaf in leaves):
        words.append(
            "if the domain's distance function (a FunctionDomain) turns sharply anywhere, give the edges there "
            "(FunctionDomain(..., sharp_edges=[...])): the generator cannot find them in a distance function"
        )
    if len(leaves) > 1 and any(known_by_distance_alone(leaf) for leaf in leaves):
        words.append(
            "if it is where the surface of an operand known by its distance alone (a distance function, a grid) "
            "meets another operand's, the edge there is known to no one: a smaller size there, or the combination "
            "as one FunctionDomain with all its sharp_edges, may do"
        )
    return "".join(f"; {phrase}" for phrase in words)


def _warn_if_off_boundary(domain, size, points, vertices, tolerance):
    """Warn of the boundary ``vertices`` farther than ``tolerance`` from the boundary, and where (3D).

    Every boundary vertex is projected onto the boundary, but one that an
    edge the generator does not know (a crease of a user's distance function
    with another operand) pulls both ways stays off: a ball cut from a wedge
    prism left one 0.024-0.029 sizes off, and said nothing.
    """
    distance = np.abs(domain.distance(points[vertices]))
    off = np.flatnonzero(distance > tolerance)
    if len(off) == 0:
        return
    sizes_off = distance[off] / size(points[vertices[off]])
    worst = vertices[off[np.argmax(sizes_off)]]
    warn_user(
        f"{len(off)} boundary vertices lie off the domain's boundary, up to {float(sizes_off.max()):.2g} sizes at "
        f"{point_text(points[worst])}: an edge of the domain the generator does not know{_unknown_edges(domain)}"
    )


def _problems(points, cells, neighbors):
    """What makes the final mesh invalid: a list of phrases (empty when valid) and the first place, or None.

    The place is the first inverted or flat cell's centroid, else the first
    vertex where the boundary is not manifold (the creases of a body built
    from a mask, where three lobes meet, were refused with no place).
    """
    problems, places = [], []
    volume = volumes_all(points, cells)
    if np.any(volume <= 0):
        problems.append(f"{int(np.sum(volume <= 0))} cells are inverted or flat")
        places.append(points[cells[np.argmax(volume <= 0)]].mean(axis=0))
    if np.any(np.bincount(cells.ravel(), minlength=len(points)) == 0):
        problems.append("unused vertices")
    surface, fans = boundary_surface_problems(table_boundary_faces(cells, neighbors), len(points))
    if np.any(fans > 1):
        places.append(points[np.argmax(fans > 1)])
    return problems + surface, (places[0] if places else None)


def without_hull_cells(domain, size, points, cells, neighbors, tolerance):
    """The cells less those with every corner on the boundary (within ``HULL_FLAT_DEPTH`` sizes) lying across or flat.

    Across: a face's centroid more than ``HULL_FACE_OUTSIDE`` local sizes
    outside (a chord of a curved boundary sags out by far less). Flat: a
    dihedral angle below MIN_DIHEDRAL with the centroid within
    ``HULL_FLAT_DEPTH`` sizes of the boundary. Delaunay makes such cells
    from boundary points alone where the boundary is concave or straight:
    two crossing cylinders gave a flat cell 20 sizes wide in their common
    tangent plane (its centroid a rounding inside), and four points on one
    straight line of a cylinder a needle; no vertex of them may move, so
    sliver removal cannot mend them (half the seeds raised). Run again
    after sliver removal, it takes the flat cells that removal leaves
    against a voxel body's boundary (a salt body: 10 of 16 runs raised).
    Returns ``(cells, neighbors)``, the neighbours renumbered (-1 for none).
    """
    on_boundary = np.abs(domain.distance(points)) <= np.maximum(tolerance, HULL_FLAT_DEPTH * size(points))
    candidates = np.flatnonzero(all_corners_in(on_boundary, cells))
    if len(candidates) == 0:
        return cells, neighbors
    corners = cells[candidates]
    faces = points[corners[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]]]  # (k, 4 faces, 3 corners, 3)
    face_centroids = faces.mean(axis=2).reshape(-1, 3)
    across = domain.distance(face_centroids) > HULL_FACE_OUTSIDE * size(face_centroids)
    centroids = points[corners].mean(axis=1)
    flat = (min_dihedral_all(points, corners) < MIN_DIHEDRAL) & (
        domain.distance(centroids) > -HULL_FLAT_DEPTH * size(centroids)
    )
    drop = np.zeros(len(cells), dtype=bool)
    drop[candidates[across.reshape(-1, 4).any(axis=1) | flat]] = True
    if not drop.any():
        return cells, neighbors
    return kept_cells(cells, neighbors, ~drop)
