"""The final mesh: the settled points' Delaunay cells inside the domain, made valid, then smoothed.

Boundary vertices off the boundary are projected onto it; the cells that
this folds, flattens or takes across the boundary go, and the guide's repair
mends the pinches this leaves, pass after pass until the boundary is
manifold and on the domain's. The smoothing after it never lowers a
vertex's worst cell.
"""

import numpy as np

from .._kernels.smoothing import move_where_better, raise_worst, smooth_interior
from .._kernels.topology import cell_centroids, subset, table_boundary_edges, triangle_qualities
from ..cleanup.fix_mesh import delete_interior_cells, delete_interior_cells_with_table, remove_unused_points
from ..cleanup.validity import cells_of_edges, crossing_edges, hanging_on_boundary, overlap_problems
from ..errors import GenerationError, point_text, warn_user
from ..mesh.columns import row_norms
from ..mesh.mesh import Mesh
from ..mesh.topology import (
    NO_INDICES,
    all_corners_in,
    any_corner_in,
    boundary_edges,
    lowest_twins,
    signed_areas,
    sorted_unique,
)
from .cells_inside import cells_inside
from .corners import recover_corners
from .distances import DISTANCE_REACH, near_distance, project_to_boundary

FLAT_QUALITY = 0.3  # a final cell below this quality hugging the boundary is dropped
NEAR_BOUNDARY = 0.1  # ...where all its vertices are this close to it, in local sizes
ACUTE_CORNER = 30.0  # degrees: a fixed point whose flat cells meet at less is a sharp corner of the domain, kept
DEGENERATE_QUALITY = 1e-6  # a final cell below this quality is flat to rounding and goes wherever it is
MAX_REPAIR_PASSES = 10  # rounds of boundary repair and projection in the final clean-up
HOLE_OFF = 0.5  # sizes off the boundary beyond which a boundary vertex left by the repair is a hole, refused
POLISH_PASSES = 3  # passes of quality-safe Laplacian smoothing of the interior vertices after generation...
POOR_QUALITY = 0.8  # ...then of moving the vertices of cells below this quality to where their worst cell is best
TWIN_REACH = 0.25  # a projected boundary vertex this many local sizes from its boundary neighbour merges into it
# a warning's words, by which meshing in strips mutes it for its strips' boundary vertices on the cuts
OFF_BOUNDARY = "boundary vertices lie off the domain's boundary after"


def finalize(domain, size, triangulation, points, n_fixed, tolerance, finite_step, n_held=None):
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
    distance = near_distance(domain, points, limit)
    keep = cells_inside(domain, points, cells, tolerance, distance if getattr(domain, "lipschitz", False) else None)
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
        raise_if_no_cells(cells)
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
        points[moved] = project_to_boundary(domain, points[moved], distance[moved], finite_step)
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
    smoothed = Mesh(_polished(domain, size, points, cells, boundary, fixed, tolerance, finite_step, limit), cells)
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
            cells_inside(domain, points, np.concatenate([first[take], second[take]]), 0.0).reshape(2, -1).all(axis=0)
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


def raise_if_no_cells(cells):
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
                    f" {point_text(points[worst])} after {MAX_REPAIR_PASSES} repair passes (a hole in the mesh, or"
                    " cells across a slot)"
                ],
            )
        warn_user(
            f"{len(off)} {OFF_BOUNDARY} {MAX_REPAIR_PASSES} repair passes, "
            f"up to {abs(distance[worst]) / target[worst]:.2g} sizes at {point_text(points[worst])}: a corner the "
            "domain does not report (give it as a fixed point, or combine the shapes with | & - so that it is found)"
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
        problems.append(f"{len(flat)} cells that are clockwise or flat (one at {point_text(where)})")
    pinched = _pinched(boundary, len(points))
    if len(pinched):
        problems.append(
            f"{len(pinched)} boundary vertices without exactly two boundary edges (one at "
            f"{point_text(points[pinched[0]])})"
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
        problems += overlap_problems(mesh.points, mesh.cells)
    hanging = hanging_on_boundary(mesh.points, boundary)[0]
    if len(hanging):
        problems.append(f"{len(hanging)} hanging nodes (one at {point_text(mesh.points[hanging[0]])})")
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


def _polished(domain, size, points, cells, boundary, fixed, tolerance, finite_step, limit):
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
        outside = ~cells_inside(domain, smoothed, cells, 0.0, bound)
        # a slide onto the other bank of a strait narrower than a cell (the nearest boundary point is
        # there) crossed two boundary edges: cells overlapped, every cell still counter-clockwise
        slid = np.flatnonzero(np.any(smoothed[boundary] != points[boundary], axis=(1, 2)))
        first, second = crossing_edges(smoothed, boundary, slid) if len(slid) else (NO_INDICES, NO_INDICES)
        # a hole of three vertices (a sliver of land between coast segments nearly touching) turns inside
        # out without any edges crossing when a vertex slides across the other two's edge: the cells round
        # it then lie over each other (the Chesapeake at 2 km, seed 1)
        turned = holes[np.sign(signed_areas(smoothed, holes)) != np.sign(signed_areas(points, holes))]
        # a slide along a spike of land thinner than rounding put a vertex on the edge that runs back
        # beside it: a slit of no width, a hanging node (a coast of roughness 1.07)
        hanging, host, back = hanging_on_boundary(smoothed, boundary) if len(slid) else (NO_INDICES,) * 3
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
    target = project_to_boundary(domain, between, domain.distance(between), finite_step)
    halfway = 0.5 * (here + target)
    halfway = project_to_boundary(domain, halfway, domain.distance(halfway), finite_step)
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
