"""Clean a valid mesh: poor boundary cells, low-valence vertices, then smoothing."""

import numbers

import numpy as np

from .._kernels.cleanup import (
    centroids_surely_inside,
    peel_spikes,
    sharp_lone_vertices,
    shortest_edges,
    smooth_vertices,
)
from .._kernels.topology import cell_centroids, subset
from ..errors import MeshValidityError, warn_user
from ..mesh.topology import any_corner_in, boundary_edges, cell_neighbor_table, checked_fixed_points
from ..quality.triangle import triangle_quality
from .fix_mesh import (
    PEELED_AREA,
    RepairReport,
    as_triangle_arrays,
    at_their_place,
    default_merge_tolerance,
    finished_mesh,
    fix_arrays,
    nearest_used_vertex,
    repair_topology,
    resolved_disjoint_cutoff,
    total_signed_area,
    warn_if_area_lost,
)

__all__ = ["MOSTLY_POOR", "PEELED_AREA", "clean", "smooth_points", "low_valence_points"]

# relative error allowed to a domain's distance far from its boundary (a polygon's is within 1 %)
_DISTANCE_SLACK = 0.02
MOSTLY_POOR = 0.5
"""Share of the boundary cells below ``min_quality`` beyond which :func:`clean` deletes none of them.

Such a boundary is poor by design (an anisotropic boundary layer, one row
thick or many; a stretched grid, every cell q 0.21): each round of
deletions exposed another poor row and peeled it away (5.5 % of a disk with
a boundary layer, 790 cells; a one-row layer all of it). A raw Delaunay
triangulation's convex hull looks the same from the cells (slivers: 11 of
its 18 boundary cells) and is kept too, with the same one warning: no rule
on quality alone told them apart (within 3 layers of the boundary the poor
shares of one- and two-row layers, 0.72, fell among the hulls', 0.47-0.80).
"""
# vertices closer than this fraction of their shortest edge to the domain's boundary stay where they are
_NEAR_BOUNDARY = 0.01
# smoothing runs again with the vertices around the cells it took out of the domain held; one
# more run is the rule, and past this many the points stay where they were
_MAX_SMOOTHING_RUNS = 10


def low_valence_points(points, cells, *, spike_angle=80.0, geographic=False):
    """Vertices of too low valence: boundary spikes, and interior vertices joined to three others.

    * A *spike* is a boundary vertex used by one cell whose angle there is
      below ``spike_angle``: the cell juts out of the coastline on one edge,
      with all three vertices on the boundary. Wider single-cell corners
      (a rectangle's 90 degrees) are geometry and stay.
    * An interior vertex used by three cells sits inside the triangle of its
      three neighbours, with three cells that are necessarily poor.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3)
        A valid triangulation (counter-clockwise, manifold boundary).
    spike_angle : float, optional
        Degrees.
    geographic : bool, optional
        Points are longitude, latitude: measure angles on the ground.

    Returns
    -------
    spikes : numpy.ndarray, shape (a,)
        Boundary vertices used by one cell with an angle below ``spike_angle``.
    centres : numpy.ndarray, shape (b,)
        Interior vertices used by exactly three cells.

    Examples
    --------
    A triangle split at an interior vertex (3):

    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [0.5, 1], [0.5, 0.4]])
    >>> spikes, centres = low_valence_points(points, np.array([[0, 1, 3], [1, 2, 3], [2, 0, 3]]))
    >>> spikes.tolist(), centres.tolist()
    ([], [3])
    """
    _, points, cells = as_triangle_arrays(points, cells)
    spike_angle = _angle(spike_angle)
    on_boundary = np.zeros(len(points), dtype=bool)
    on_boundary[boundary_edges(cells).ravel()] = True
    in_cells = np.bincount(cells.ravel(), minlength=len(points))
    spikes = sharp_lone_vertices(points, cells, on_boundary & (in_cells == 1), spike_angle, bool(geographic))
    return spikes, np.flatnonzero(~on_boundary & (in_cells == 3))


def without_spikes(points, cells, table, spike_angle, geographic, is_fixed=None):
    """``cells`` and their neighbour ``table`` without boundary spikes, the ones their removal exposes included.

    A strip one cell wide (a channel or a spit the mesh does not resolve)
    loses one cell at its tip per removal, so removing spikes once per
    round of :func:`clean` took a round per cell (the Gulf of Maine
    reached the limit of 10 rounds). Vertices of the (n,) mask
    ``is_fixed`` are neither removed as spikes nor left in no cell.
    Returns ``(cells, table, number of spikes removed, interior valence-3
    vertices of the result)``, fixed vertices not among the latter.
    """
    mask = np.zeros(len(points), dtype=np.bool_) if is_fixed is None else is_fixed
    keep, removed, in_cells, on_boundary = peel_spikes(
        points, cells, table, len(points), spike_angle, bool(geographic), mask
    )
    if removed:
        cells, table = subset(cells, table, keep)
    return cells, table, removed, np.flatnonzero(~on_boundary & (in_cells == 3) & ~mask)


def _angle(spike_angle):
    """``spike_angle`` as degrees in (0, 180), or a MeshValidityError."""
    if not isinstance(spike_angle, numbers.Real) or isinstance(spike_angle, bool) or not 0 < spike_angle < 180:
        raise MeshValidityError(f"spike_angle must be a number of degrees in (0, 180), got {spike_angle!r}")
    return float(spike_angle)


def _remove_valence_three(cells, candidates):
    """Replace the three cells around each of an independent set of ``candidates`` by one.

    The three cells around an interior vertex ``v`` of valence 3 are
    ``(v, a, b), (v, b, c), (v, c, a)``; their union is the triangle
    ``(a, b, c)``, counter-clockwise, with the same outer edges, so the
    replacement keeps the mesh conforming. Candidates sharing a cell would
    conflict: only the smallest index of each cell goes in a round.
    Returns ``(cells, number of vertices removed)``.
    """
    n = int(cells.max()) + 1
    is_candidate = np.zeros(n, dtype=bool)
    is_candidate[candidates] = True
    flagged = np.where(is_candidate[cells], cells, n)
    smallest = flagged.min(axis=1)  # smallest candidate in each cell
    loses = is_candidate[cells] & (cells != smallest[:, None])
    is_candidate[cells[loses]] = False
    removed = np.flatnonzero(is_candidate)
    if len(removed) == 0:
        return cells, 0
    # the cells around each removed vertex, grouped by that vertex
    owner, corner = np.nonzero(is_candidate[cells])
    order = np.argsort(cells[owner, corner], kind="stable")
    owner, corner = owner[order].reshape(-1, 3), corner[order].reshape(-1, 3)
    first = cells[owner[:, 0]]
    # rotate the first cell so the removed vertex comes first: (v, x, y), x and y counter-clockwise
    k = corner[:, 0]
    rows = np.arange(len(k))
    x, y = first[rows, (k + 1) % 3], first[rows, (k + 2) % 3]
    v = first[rows, k]
    # each neighbour appears in two of the three cells: a + b + c = (sum of corners - 3 v) / 2
    total = cells[owner].sum(axis=(1, 2))
    z = (total - 3 * v) // 2 - x - y
    keep = np.ones(len(cells), dtype=bool)
    keep[owner.ravel()] = False
    return np.concatenate([cells[keep], np.column_stack([x, y, z])]), len(removed)


def smooth_points(points, cells, *, passes=3, fixed=None, domain=None, geographic=False, boundary_quality=0.0):
    """Laplacian smoothing of interior vertices that never lowers the worst quality.

    Each pass moves the free interior vertices one after the other, in
    index order, to the mean of their neighbours (Gauss-Seidel: each move
    sees the ones before it). A move is kept only when the worst quality
    (guide eq. 1) of the vertex's cells is not lower than before and
    positive, so no cell inverts, the mesh's minimum quality cannot drop,
    and the connectivity is unchanged. Passes stop early when one moves
    nothing. With a ``domain``, vertices on its boundary stay too (a shore
    the mesh does not resolve, such as an island crossed by cells) and no
    cell whose centroid was inside it ends with its centroid outside: the
    vertices of such cells and of the cells around them are held and the
    smoothing runs again (one more run as a rule; after ten, no vertex
    moves). The same holds for a cell with a boundary edge that a run takes
    below ``boundary_quality``: keeping each vertex's worst quality does not
    keep every cell's (one went from above 0.25 to 0.129 beside a poorer
    one, and :func:`clean`, whose ``min_quality`` this is, deleted it the
    second time).

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
        Vertex coordinates, any units.
    cells : numpy.ndarray, shape (m, 3)
        A valid, counter-clockwise triangulation.
    passes : int, optional
        Most smoothing passes.
    fixed : array_like of bool, shape (n,), or of int, optional
        Vertices that must not move, besides the boundary vertices: a mask
        of all the vertices, or vertex numbers.
    domain : Domain, optional
        The meshed region; vertices within 1 % of their shortest edge of its
        boundary do not move. When ``domain.lipschitz`` is true (its distance
        changes no faster than a point moves, as for every built-in
        geometry), only the cells that may have come near its boundary have
        their centroid tested.
    geographic : bool, optional
        Points are longitude, latitude: measure quality on the ground.
    boundary_quality : float, optional
        No cell with a boundary edge that a run moves ends below this
        quality (0: no such limit).

    Returns
    -------
    points : numpy.ndarray, shape (n, 2)
        New coordinates (the input is not modified).
    moved : numpy.ndarray of bool, shape (n,)
        Vertices that moved.

    Raises
    ------
    MeshValidityError
        For malformed arrays, ``passes`` not a non-negative integer, or a
        ``fixed`` that is neither a mask of the ``n`` vertices nor numbers
        among them.

    Examples
    --------
    A square fan whose centre is off-centre moves back to the middle:

    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [0.8, 0.7]])
    >>> cells = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    >>> smoothed, moved = smooth_points(points, cells, passes=1)
    >>> smoothed[4].tolist(), moved.tolist()
    ([0.5, 0.5], [False, False, False, False, True])
    """
    _, points, cells = as_triangle_arrays(points, cells)
    points = points.copy()
    cells = np.ascontiguousarray(cells)
    n = len(points)
    if not isinstance(passes, numbers.Integral) or passes < 0:
        raise MeshValidityError(f"passes must be a non-negative integer, got {passes!r}")
    free = np.zeros(n, dtype=bool)
    free[cells.ravel()] = True
    free[boundary_edges(cells).ravel()] = False
    if fixed is not None:
        free[_fixed_vertices(fixed, n)] = False
    distance = None
    if domain is not None and free.any() and passes:
        distance, near = _domain_distance(domain, points, cells)
        free &= ~near
    if not free.any() or passes == 0:
        return points, np.zeros(n, dtype=bool)
    on_boundary = _boundary_cells(cells) if boundary_quality > 0 else np.zeros(0, dtype=np.int64)
    for _ in range(_MAX_SMOOTHING_RUNS):
        smoothed = points.copy()
        moved = smooth_vertices(smoothed, cells, free, int(passes), bool(geographic))
        left = (
            np.zeros(0, dtype=np.int64)
            if domain is None
            else _cells_that_left(domain, points, smoothed, cells, moved, distance)
        )
        touched = on_boundary[np.any(moved[cells[on_boundary]], axis=1)]
        sank = touched[triangle_quality(smoothed, cells[touched], geographic=geographic) < boundary_quality]
        if len(left) == 0 and len(sank) == 0:
            return smoothed, moved
        if len(sank):
            free[cells[sank].ravel()] = False
        if len(left) == 0:
            continue
        # their neighbours too: a run from the same start moves the vertices nearby a little differently
        held = np.zeros(n, dtype=bool)
        held[cells[left].ravel()] = True
        free[cells[any_corner_in(held, cells)].ravel()] = False
    return points, np.zeros(n, dtype=bool)


def _fixed_vertices(fixed, n):
    """The vertex numbers of ``fixed``, a mask of the ``n`` vertices or vertex numbers; else MeshValidityError.

    A mask must have one entry per vertex (else it would read as the vertex
    numbers of its True entries), and numbers must be whole and name vertices.
    """
    fixed = np.asarray(fixed)
    if fixed.dtype == bool:
        if fixed.shape != (n,):
            raise MeshValidityError(f"fixed must be a mask of the {n} vertices, got shape {fixed.shape}")
        return np.flatnonzero(fixed)
    if fixed.size and not np.issubdtype(fixed.dtype, np.integer):
        raise MeshValidityError(f"fixed must be a mask of the vertices or vertex numbers, got dtype {fixed.dtype}")
    fixed = fixed.astype(np.int64).ravel()
    if fixed.size and (fixed.min() < 0 or fixed.max() >= n):
        raise MeshValidityError(
            f"fixed has vertex numbers from {fixed.min()} to {fixed.max()}; the vertices are 0 to {n - 1}"
        )
    return fixed


def _domain_distance(domain, points, cells):
    """The domain's distance at each vertex (0 where unused), and which are closer than 1 % of their shortest edge.

    A domain that bounds far distances (a polygon's ``distance_and_nearest``)
    searches its boundary only as far as that test needs and gives a bound
    nearer zero beyond, as good for proving centroids inside: on the guide's
    §5.3 mesh the exact far distances took 0.17 s of 0.28 s.
    """
    shortest = shortest_edges(points, cells)
    used = np.isfinite(shortest)
    distance = np.zeros(len(points))
    bounded = getattr(domain, "distance_and_nearest", None)
    if bounded is None or not used.any():
        distance[used] = domain.distance(points[used])
    else:
        distance[used] = bounded(points[used], _NEAR_BOUNDARY * float(shortest[used].max()))[0]
    return distance, used & (np.abs(distance) <= _NEAR_BOUNDARY * shortest)


def _cells_that_left(domain, before, after, cells, moved, distance):
    """Cells whose centroid was inside ``domain`` at ``before`` and is not at ``after``.

    Only cells with a moved vertex can have left. With a 1-Lipschitz
    distance, known at the vertices ``before``, a centroid closer to one of
    them than that vertex's depth is inside and is not evaluated.
    """
    candidates = np.flatnonzero(any_corner_in(moved, cells))
    if not getattr(domain, "lipschitz", False):
        candidates = candidates[domain.inside(cell_centroids(before, cells, candidates, 0))]
        return candidates[~domain.inside(cell_centroids(after, cells, candidates, 0))]
    upper = distance + _DISTANCE_SLACK * np.abs(distance)
    candidates = candidates[~centroids_surely_inside(after, np.ascontiguousarray(cells[candidates]), before, upper)]
    unsure = np.flatnonzero(~centroids_surely_inside(before, np.ascontiguousarray(cells[candidates]), before, upper))
    was_inside = np.ones(len(candidates), dtype=bool)
    was_inside[unsure] = domain.inside(cell_centroids(before, cells, candidates[unsure], 0))
    candidates = candidates[was_inside]
    return candidates[~domain.inside(cell_centroids(after, cells, candidates, 0))]


def clean(
    mesh_or_points,
    cells=None,
    *,
    min_quality=0.25,
    spike_angle=80.0,
    smoothing_passes=3,
    domain=None,
    disjoint_cutoff=None,
    dj_cutoff=None,
    max_rounds=10,
    geographic=None,
    fixed_points=None,
):
    """Remove poor boundary cells and low-valence vertices, then smooth; the result stays valid.

    First :func:`~terramesh.cleanup.fix_mesh` (with ``disjoint_cutoff``).
    Then, in rounds until nothing changes (at most ``max_rounds``):

    1. delete the cells below ``min_quality`` (guide eq. 1) that have a
       boundary edge. Poor interior cells are kept, since deleting them would
       punch holes (false islands) in the water; smoothing improves them.
       When more than :data:`MOSTLY_POOR` (half) of the boundary cells are
       poor, none is deleted, with one warning: such a boundary is poor by
       design (an anisotropic boundary layer, a stretched grid), and each
       round would peel another row; a raw triangulation's hull slivers are
       kept the same way;
    2. delete low-valence vertices (:func:`low_valence_points`): a boundary
       spike (a vertex in one cell, sharper than ``spike_angle``) goes with
       its cell, and so do the spikes that exposes (a strip one cell wide
       goes in one round). A domain's own corners sharper than
       ``spike_angle`` in one cell go too (a triangle's 60 degrees): lower
       ``spike_angle`` to keep them. Then an interior vertex of valence 3 goes and
       its three cells become one (no hole, same outer edges);
    3. repair what the deletions broke: small disconnected parts and
       vertices with more than two boundary edges (as in ``fix_mesh``).

    Last, :func:`smooth_points` moves interior vertices (never inverting a
    cell nor lowering the worst quality, nor taking a boundary cell below
    ``min_quality``; vertices on the ``domain`` boundary stay, when a
    domain is given) and unused vertices are dropped.

    Vertices at ``fixed_points`` (the guide's ``pfix``: gauges, river
    inflow nodes) stay exactly where they are: smoothing does not move
    them, they are not removed as spikes or valence-3 vertices, and a poor
    boundary cell whose deletion would leave one in no cell is kept (as is
    a spike's cell). The repairs of ``fix_mesh`` can still remove one, with
    a warning: a duplicate merged into another vertex, or a vertex of a
    small disconnected part that is deleted.

    Parameters
    ----------
    mesh_or_points : Mesh or numpy.ndarray, shape (n, 2)
        A mesh, or vertex coordinates with ``cells``.
    cells : numpy.ndarray, shape (m, 3), optional
    min_quality : float, optional
        Boundary cells of lower quality are deleted; 0 deletes none.
    spike_angle : float, optional
        Degrees; see :func:`low_valence_points`.
    smoothing_passes : int, optional
        Laplacian passes; 0 turns smoothing off.
    domain : Domain, optional
        The meshed region: smoothing keeps vertices on its boundary and cell
        centroids inside it (see :func:`smooth_points`), so coastline
        features the mesh does not resolve (an island thinner than one
        element, crossed by cells) keep their vertices on the shore.
    disjoint_cutoff, dj_cutoff : float, optional
        Fraction of cells below which a disconnected part is deleted (see
        :func:`~terramesh.cleanup.fix_mesh`); 0.01 by default.
    max_rounds : int, optional
        Most rounds of steps 1 to 3; reaching it while rounds still change
        the mesh warns.
    geographic : bool, optional
        Points are longitude, latitude; by default from the mesh's ``crs``.
    fixed_points : array_like, shape (k, 2), optional
        Coordinates, in the units of the points (metres on a projected
        plane, degrees for longitude/latitude), of vertices that must stay:
        each must be a vertex of the mesh (used by a cell), equal to it or
        within ``1024 * eps`` times the larger side of the points' bounding
        box.

    Returns
    -------
    Mesh
        A new valid mesh; ``info["repair"]`` is a
        :class:`~terramesh.cleanup.RepairReport` with the counts of the
        fix and of this cleaning (``low_quality_cells``,
        ``low_valence_points``, ``smoothed_points``). Point data follow the
        vertices kept (values are not re-interpolated at moved vertices);
        boundaries are dropped, with a warning, if anything was deleted.
        With ``fixed_points``, ``info["fixed_points"]`` is the (k,) array of
        the vertex index of each (-1 for one the repairs removed); without,
        an ``info["fixed_points"]`` of the input is dropped (the vertices
        are numbered anew).

    Raises
    ------
    MeshValidityError
        For malformed arrays or options, a fixed point that is no vertex of
        the mesh, or if nothing valid remains.

    Warns
    -----
    TerrameshWarning
        If the repairs removed fixed points (how many, and the first).

    Examples
    --------
    >>> import terramesh as tm
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.2)
    >>> cleaned = clean(mesh)
    >>> tm.cleanup.mesh_problems(cleaned)
    []
    """
    mesh, points, cells = as_triangle_arrays(mesh_or_points, cells, "clean")
    if not isinstance(min_quality, numbers.Real) or not 0 <= min_quality < 1:
        raise MeshValidityError(f"min_quality must be in [0, 1), got {min_quality!r}")
    spike_angle = _angle(spike_angle)
    if not isinstance(max_rounds, numbers.Integral) or max_rounds < 0:
        raise MeshValidityError(f"max_rounds must be a non-negative integer, got {max_rounds!r}")
    if geographic is None:
        geographic = mesh is not None and mesh.geographic
    cutoff = resolved_disjoint_cutoff(disjoint_cutoff, dj_cutoff)
    fixed = None if fixed_points is None else _FixedPoints(fixed_points, points, cells)
    n_points, n_cells = len(points), len(cells)
    # the cells' neighbour table is followed through the deletions and made again after other changes
    points, cells, source, report, table, _ = fix_arrays(
        points,
        cells,
        cutoff=cutoff,
        by="cells",
        merge_tolerance=None,
        min_quality=1e-6,
        geographic=geographic,
        point_data=None if mesh is None else mesh.point_data,
        what="clean",
    )
    is_fixed = None if fixed is None else fixed.follow(points, cells, source)
    low_quality = low_valence = 0
    area_before = total_signed_area(points, cells)
    if table is None and len(cells):
        table = cell_neighbor_table(cells)
    # judged once, on the mesh as given: a boundary layer partly peeled would look like hull slivers
    poor_all_through = (
        max_rounds > 0 and min_quality > 0 and _warn_if_poor_all_through(points, cells, table, min_quality, geographic)
    )
    for _ in range(max_rounds):
        if len(cells) == 0:
            break
        start = len(cells), low_valence
        if table is None:
            table = cell_neighbor_table(cells)
        on_boundary_edge = np.flatnonzero((table[:, 0] < 0) | (table[:, 1] < 0) | (table[:, 2] < 0))
        if poor_all_through:
            poor = on_boundary_edge[:0]
        else:
            poor = on_boundary_edge[
                triangle_quality(points, cells[on_boundary_edge], geographic=geographic) < min_quality
            ]
        if is_fixed is not None and len(poor):
            poor = _sparing(cells, poor, is_fixed)
        if len(poor):
            keep = np.ones(len(cells), dtype=bool)
            keep[poor] = False
            cells, table = subset(cells, table, keep)
            low_quality += len(poor)
        if len(cells):
            cells, table, spikes, centres = without_spikes(points, cells, table, spike_angle, geographic, is_fixed)
            low_valence += spikes
            if len(centres):
                cells, removed = _remove_valence_three(cells, centres)
                low_valence += removed
                table = None
        cells, topology, table = repair_topology(
            points, cells, cutoff=cutoff, by="cells", geographic=geographic, table=table
        )
        report = report + topology
        if (len(cells), low_valence) == start:
            break
    else:
        if max_rounds:
            warn_user(
                f"clean reached max_rounds={max_rounds} while rounds still removed cells; the mesh is valid "
                "but may have poor boundary cells or low-valence vertices left",
            )
    warn_if_area_lost(
        area_before,
        total_signed_area(points, cells),
        "clean",
        f"{low_quality} poor boundary cells, {low_valence} low-valence vertices, and the cells their removal exposed",
        "sharp headlands and spikes go; lower spike_angle or min_quality, or max_rounds=1, to keep more",
    )
    points, moved = smooth_points(
        points,
        cells,
        passes=smoothing_passes,
        fixed=is_fixed,
        domain=domain,
        geographic=geographic,
        boundary_quality=min_quality,
    )
    report = report + RepairReport(
        low_quality_cells=low_quality, low_valence_points=low_valence, smoothed_points=int(moved.sum())
    )
    result = finished_mesh(
        mesh, points, cells, source, report, n_points=n_points, n_cells=n_cells, what="clean", keep_fixed=False
    )
    if fixed is not None:
        result.info["fixed_points"] = fixed.final(cells, len(points))
    return result


def _warn_if_poor_all_through(points, cells, table, min_quality, geographic):
    """Whether more than :data:`MOSTLY_POOR` of the boundary cells are below ``min_quality``, warning once if so."""
    if len(cells) == 0:
        return False
    on_boundary_edge = np.flatnonzero(np.any(table < 0, axis=1))
    poor = int(np.count_nonzero(triangle_quality(points, cells[on_boundary_edge], geographic=geographic) < min_quality))
    if poor <= MOSTLY_POOR * len(on_boundary_edge):
        return False
    warn_user(
        f"{poor:,} of the {len(on_boundary_edge):,} boundary cells are below min_quality={min_quality:g}: a boundary"
        " poor by design (an anisotropic boundary layer, a stretched grid) or a raw triangulation's hull, so none is"
        " deleted (each round would expose and peel another poor row); lower min_quality to keep them quietly",
    )
    return True


class _FixedPoints:
    """The vertices at the ``fixed_points`` of :func:`clean`, followed through its renumbering.

    ``given`` are the points (k, 2); ``tolerance`` how far one may be from
    its vertex (:func:`~terramesh.cleanup.fix_mesh.merge_duplicate_points`'s
    default, ``1024 * eps`` times the larger bbox side); ``index`` the
    vertex of each (-1 once removed).
    """

    def __init__(self, fixed_points, points, cells):
        given = checked_fixed_points(fixed_points, 2, MeshValidityError)
        self.given = given
        self.tolerance = default_merge_tolerance(points) if len(points) else 0.0
        self.index, distance = nearest_used_vertex(given, points, cells)
        far = np.flatnonzero(distance > self.tolerance)
        if len(far):
            first = far[0]
            x, y = given[first].tolist()
            raise MeshValidityError(
                f"{len(far)} of the {len(given)} fixed points are no vertex of the mesh, the first (fixed point"
                f" {first}) ({x!r}, {y!r}): its nearest vertex is {distance[first]:.6g} away (allowed"
                f" {self.tolerance:.3g}); fixed points must be vertices (generate the mesh with them as fixed_points)"
            )

    def follow(self, points, cells, source):
        """The (n,) mask of the fixed vertices among ``points`` (input vertex ``source[i]`` became vertex ``i``).

        A vertex merged into another (a duplicate) is followed to the vertex
        at its place; one no cell uses any more is removed (-1).
        """
        new = np.full(int(source.max(initial=-1)) + 1, -1, dtype=np.int64)
        new[source] = np.arange(len(source))
        index = np.where(self.index < len(new), new[np.minimum(self.index, len(new) - 1)], -1)
        index = at_their_place(index, self.given, points, cells, self.tolerance)
        moved = np.flatnonzero(index >= 0)
        moved = moved[np.linalg.norm(points[index[moved]] - self.given[moved], axis=1) > self.tolerance]
        if len(moved):
            x, y = self.given[moved[0]]
            warn_user(
                f"fix_mesh's repairs in clean moved {len(moved)} fixed vertices, the first from ({x:.9g}, {y:.9g}),"
                " to untangle a fold of their cells; they stay there",
            )
        self.index = index
        return self.mask(len(points))

    def mask(self, n):
        """The (n,) mask of the fixed vertices."""
        is_fixed = np.zeros(n, dtype=bool)
        is_fixed[self.index[self.index >= 0]] = True
        return is_fixed

    def final(self, cells, n):
        """Each fixed point's vertex once the vertices no cell uses are dropped (-1: removed), warning of those removed.

        ``cells`` use vertices ``0 .. n - 1``, as given to ``finished_mesh``.
        """
        used = np.zeros(n, dtype=bool)
        used[cells.ravel()] = True
        renumbered = np.cumsum(used) - 1
        index = np.where((self.index >= 0) & used[np.maximum(self.index, 0)], renumbered[self.index], -1)
        lost = np.flatnonzero(index < 0)
        if len(lost):
            x, y = self.given[lost[0]]
            warn_user(
                f"clean removed {len(lost)} of the {len(index)} fixed points, the first ({x:.9g}, {y:.9g}): the"
                " repairs deleted their vertices (in a small disconnected part, below disjoint_cutoff, a merged"
                " duplicate, or cells deleted at a pinched boundary vertex); info['fixed_points'] is -1 for them",
            )
        return index


def _sparing(cells, doomed, is_fixed):
    """The ``doomed`` cells less those whose deletion would leave a fixed vertex (``is_fixed``, (n,)) in no cell."""
    n = len(is_fixed)
    left = np.bincount(cells.ravel(), minlength=n) - np.bincount(cells[doomed].ravel(), minlength=n)
    orphaned = is_fixed & (left == 0)
    if not orphaned.any():
        return doomed
    return doomed[~any_corner_in(orphaned, cells[doomed])]


def _boundary_cells(cells):
    """Indices of the cells with a boundary edge."""
    return np.flatnonzero(np.any(cell_neighbor_table(cells) < 0, axis=1)) if len(cells) else np.zeros(0, np.int64)
