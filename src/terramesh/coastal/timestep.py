"""Courant numbers of a finished mesh and decimation to a target time step (the guide's CalcCFL and CheckTimestep).

The Courant number at a vertex is eq. 10 of the guide,

``Cr = (|u| + sqrt(g H)) dt / dx``,

with the velocity estimate of eq. 11 and critical flow where the depth is
below ``eta`` (:func:`terramesh.coastal.sizes.wave_speed`), ``H`` the
vertex's depth and ``dx`` the length of the shortest edge at the vertex, in
ground metres (great-circle distance for longitude-latitude meshes). Why the
shortest edge rather than the guide's element size ``f_E`` (the diameter of
the inscribed circle, eq. 10): the size functions of §3-4 are edge lengths
and §4.2 sets ``f_h = f_E``, i.e. the guide's CFL limit is applied to the edge
length; the shortest edge at a vertex is the smallest distance information
travels between two coupled unknowns of the nodal (continuous Galerkin)
scheme ADCIRC uses; and it is what OceanMesh2D's ``CalcCFL`` computes
(shortest bar at each vertex), so numbers compare with the guide's
workflow. The inscribed diameter of an equilateral triangle is
``L / sqrt(3)``: with it every Courant number would be 1.73 times larger.
"""

import itertools
import numbers
from typing import NamedTuple

import numpy as np

from .._kernels.timestep import fill_stars
from .._kernels.topology import shortest_sides
from ..cleanup.fix_mesh import fix_mesh, remove_degenerate_cells
from ..cleanup.validity import crossing_edges, mesh_problems
from ..errors import MeshValidityError, SizingError, checked_number, warn_user
from ..mesh.mesh import guess_crs
from ..mesh.topology import (
    any_corner_in,
    boundary_edges,
    signed_areas,
    unique_edges,
    with_fixed_points_renumbered,
)
from ..quality.triangle import triangle_quality
from .projection import EARTH_RADIUS, to_mercator
from .sizes.cfl import COURANT, ETA, wave_speed
from .sizes.wavelength import GRAVITY

__all__ = ["courant_number", "enforce_timestep", "edge_lengths", "MIN_FILL_QUALITY", "MIN_KEPT_SHARE"]

MIN_FILL_QUALITY = 0.3
"""Worst triangle quality (guide eq. 1) accepted when re-triangulating the hole left by a removed vertex."""

MIN_KEPT_SHARE = 0.01
"""Share of the vertices below which meeting a Courant target is taken for a mistake, not a decimation.

Each vertex over the target needs edges ``Cr / courant`` times longer
around it, so about ``(courant / Cr)**2`` of the vertices there stay:
under 1 % overall is a mesh Courant numbers ten times the target
everywhere, which no decimation leaves usable. A mesh in degrees taken
as metres gave thousands (6,896 for 0.066), a step in minutes 60 times
too much (dt = 2000 s left 8 of 315 vertices); a mesh with a fine zone
too fine for ``dt`` stays far above (56 % for :func:`enforce_timestep`'s
example, 94 % for the tests' graded square).
"""

_REPAIR_MIN_QUALITY = 1e-6
"""``min_quality`` of the repair after a round: fill triangles of lower quality (in the mesh's coordinates) are flat."""


def checked_mesh(mesh, what):
    """``mesh`` if it is a 2D triangle :class:`~terramesh.Mesh`, else MeshValidityError naming the caller ``what``."""
    from ..mesh.mesh import Mesh

    if not isinstance(mesh, Mesh):
        raise MeshValidityError(f"{what} takes a terramesh.Mesh, got {type(mesh).__name__}")
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise MeshValidityError(f"{what} needs a 2D triangle mesh")
    return mesh


def is_geographic(mesh, geographic):
    """Whether ``mesh`` is taken as longitude-latitude: ``geographic`` where given, else what its CRS says."""
    return mesh.geographic if geographic is None else bool(geographic)


def _checked_cells(mesh, what):
    """Refuse degenerate cells: zero area or a zero-length edge, whose ``dx`` of 0 gives ``Cr = inf``.

    NumPy warned of a division by zero and the Courant number was ``inf``;
    :func:`enforce_timestep`'s repair dropped such a cell without a word.
    Degenerate as the repair has it: quality (guide eq. 1, either
    orientation) below :data:`_REPAIR_MIN_QUALITY`, fix_mesh's default.
    """
    degenerate = np.abs(triangle_quality(mesh.points, mesh.cells)) < _REPAIR_MIN_QUALITY  # 0 for one corner thrice
    if np.any(degenerate):
        first = int(np.argmax(degenerate))
        raise MeshValidityError(
            f"{what}: {int(np.sum(degenerate))} of {mesh.n_cells} cells are degenerate, of zero area, a zero-length"
            f" edge or quality below {_REPAIR_MIN_QUALITY:g} (the first, cell {first}, has corners"
            f" {mesh.cells[first].tolist()}): a zero-length edge makes the Courant number infinite, and the repair"
            " deletes such cells; repair the mesh first (terramesh.cleanup.fix_mesh)"
        )


def _kept_share(cr, target):
    """About what share of the vertices meeting ``target`` leaves: ``(target / Cr)**2`` where ``Cr > target``."""
    return float(np.mean(np.where(cr > target, (target / np.maximum(cr, target)) ** 2, 1.0))) if len(cr) else 1.0


def _degrees_taken_for_metres(mesh, geographic, distance):
    """The largest Courant number read as degrees, when ``mesh`` may be lon/lat taken for metres; else None.

    That is, no ``crs`` and no ``geographic`` said, and every point within
    longitude-latitude ranges. ``distance`` is each vertex's wave speed
    times ``dt``, metres.
    """
    if geographic is not None or mesh.crs is not None or guess_crs(mesh.points) is None:
        return None
    return float(np.max(distance / _shortest_edge(mesh.points, mesh.cells, True)))


def _degrees_advice(largest):
    """What to do about a mesh in degrees taken for metres, whose Courant number read as degrees is ``largest``."""
    return (
        "the mesh has no crs, so its coordinates were taken as metres, and every one lies within longitude-latitude"
        f' ranges: if they are degrees, give the mesh crs="EPSG:4326" or pass geographic=True (read as degrees the'
        f" largest Courant number is {largest:.3g})"
    )


def edge_lengths(points, edges, *, geographic):
    """Length of each edge, ground metres: great-circle on the sphere of radius 6378137 m, or Euclidean.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
        Longitude, latitude (degrees) when ``geographic``, else metres.
    edges : numpy.ndarray, shape (e, 2)
    geographic : bool

    Returns
    -------
    numpy.ndarray, shape (e,)

    Examples
    --------
    >>> import numpy as np
    >>> lengths = edge_lengths(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0, 1]]), geographic=True)
    >>> round(float(lengths[0]), 1)
    111319.5
    """
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    if not geographic:
        return np.hypot(b[:, 0] - a[:, 0], b[:, 1] - a[:, 1])
    lon1, lat1, lon2, lat2 = (np.radians(v) for v in (a[:, 0], a[:, 1], b[:, 0], b[:, 1]))
    h = np.sin(0.5 * (lat2 - lat1)) ** 2 + np.cos(lat1) * np.cos(lat2) * np.sin(0.5 * (lon2 - lon1)) ** 2
    return 2.0 * EARTH_RADIUS * np.arcsin(np.sqrt(np.clip(h, 0.0, 1.0)))


def _shortest_edge(points, cells, geographic):
    """Shortest edge at each vertex, ground metres (inf for a vertex without edges).

    Every side of every cell, measured from its lower vertex so that an edge
    measures the same from either cell (:func:`edge_lengths`' formulas):
    measuring interior edges twice took half the time of finding each edge
    once (``unique_edges``).
    """
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    if geographic:
        x, y = np.radians(points[:, 0]), np.radians(points[:, 1])
        return shortest_sides(cells, x, y, np.cos(y), EARTH_RADIUS, True)
    x, y = np.ascontiguousarray(points[:, 0], dtype=np.float64), np.ascontiguousarray(points[:, 1], dtype=np.float64)
    return shortest_sides(cells, x, y, y, 1.0, False)


def depth_of(mesh):
    """The mesh's depth (positive down, metres) as float64; MeshValidityError where it is missing or not finite."""
    depth = mesh.depth
    if depth is None:
        raise MeshValidityError("the mesh has no depth (point_data['depth']): run interpolate_bathymetry first")
    depth = np.asarray(depth, dtype=np.float64)
    if not np.all(np.isfinite(depth)):
        raise MeshValidityError(
            f"{int(np.sum(~np.isfinite(depth)))} vertices have no depth (NaN): run interpolate_bathymetry first"
        )
    return depth


def _positive(name, value):
    return checked_number(value, f"{name} must be a positive finite number", SizingError, minimum=0, strict=True)


def courant_number(mesh, dt, *, eta=ETA, gravity=GRAVITY, geographic=None):
    """Courant number at every vertex for time step ``dt`` (the guide's ``CalcCFL``, eq. 10-11).

    ``Cr = (|u| + sqrt(g H)) dt / dx``, where

    * ``|u| + sqrt(g H)`` is :func:`terramesh.coastal.sizes.wave_speed` of
      the vertex's depth ``h``: ``H = h`` and the linear long-wave velocity
      ``|u| = eta sqrt(g / h)`` (eq. 11) where ``h >= eta``; critical flow,
      ``H = eta`` and ``|u| = sqrt(g eta)``, where ``h < eta`` (land included);
    * ``dx`` is the length of the shortest edge at the vertex, ground metres
      (great-circle distance on the 6378137 m sphere for longitude-latitude
      meshes); see the module's notes for why this and not the inscribed
      circle's diameter.

    Parameters
    ----------
    mesh : Mesh
        A 2D triangle mesh with ``mesh.depth`` (metres, positive down).
    dt : float
        Time step, seconds.
    eta : float, optional
        Free-surface amplitude, metres (2 m, as the guide).
    gravity : float, optional
        m/s^2.
    geographic : bool, optional
        Points are longitude, latitude degrees; by default from ``mesh.crs``
        (planar points are taken to be metres).

    Returns
    -------
    numpy.ndarray, shape (n,)
        Dimensionless; 0 at a vertex with no edge.

    Raises
    ------
    MeshValidityError
        If the mesh has no depth or NaN depths, or cells of zero area or
        with a zero-length edge (repair it with :func:`terramesh.cleanup.fix_mesh`).
    SizingError
        If ``dt``, ``eta`` or ``gravity`` is not a positive number.

    Warns
    -----
    TerrameshWarning
        When the mesh has no ``crs``, ``geographic`` is not given, every
        point lies within longitude-latitude ranges and the Courant numbers
        are absurd (meeting ``Cr <= 0.5`` would leave under
        :data:`MIN_KEPT_SHARE` of the vertices): degrees taken for metres.

    Examples
    --------
    Two triangles with 100 m edges in 100 m of water, ``dt = 2 s``: the
    speed is 31.95 m/s and the Courant number 0.64.

    >>> import numpy as np, terramesh as tm
    >>> points = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]])
    >>> mesh = tm.Mesh(points, [[0, 1, 2], [0, 2, 3]], point_data={"depth": np.full(4, 100.0)})
    >>> courant_number(mesh, 2.0).round(4).tolist()
    [0.6389, 0.6389, 0.6389, 0.6389]
    """
    mesh = checked_mesh(mesh, "courant_number")
    dt = _positive("dt", dt)
    _checked_cells(mesh, "courant_number")
    cr = _courant_numbers(mesh, dt, eta, gravity, geographic)
    # a mesh in degrees without a crs was measured in metres: 6,896 where the Courant number was 0.066
    if _kept_share(cr, COURANT) < MIN_KEPT_SHARE:
        largest = _degrees_taken_for_metres(mesh, geographic, wave_speed(mesh.depth, eta=eta, gravity=gravity) * dt)
        if largest is not None:
            warn_user(
                f"courant_number: at dt = {dt:g} s the Courant numbers reach {float(cr.max()):.3g} (median"
                f" {float(np.median(cr)):.3g}): {_degrees_advice(largest)}; if they are metres, pass geographic=False"
            )
    return cr


def _courant_numbers(mesh, dt, eta, gravity, geographic):
    """:func:`courant_number` of a mesh already checked (its cells not degenerate), without its warning."""
    distance = wave_speed(depth_of(mesh), eta=eta, gravity=gravity) * dt
    return distance / _shortest_edge(mesh.points, mesh.cells, is_geographic(mesh, geographic))


def _select(bad, priority, edges):
    """Local maxima of ``priority`` among ``bad`` vertices over ``edges``: an independent set (no shared cell)."""
    both = bad[edges[:, 0]] & bad[edges[:, 1]]
    e = edges[both]
    first_wins = (priority[e[:, 0]] > priority[e[:, 1]]) | (
        (priority[e[:, 0]] == priority[e[:, 1]]) & (e[:, 0] < e[:, 1])
    )
    loser = np.zeros(len(bad), dtype=bool)
    loser[e[~first_wins, 0]] = True
    loser[e[first_wins, 1]] = True
    return bad & ~loser


def _corner_free(xy, tree, alive, vertices, previous, following):
    """For boundary ``vertices``: no other living point in the triangle ``(previous, vertex, following)``, closed.

    ``previous[i] -> vertices[i] -> following[i]`` are consecutive on the
    boundary. Any mesh edge entering that triangle (other than at its
    corners) must end inside it, since two of its sides are mesh edges: an
    empty triangle means removing the vertex and closing the hole with the
    chord ``previous - following`` overlaps nothing. ``tree`` is a KD-tree
    over ``xy``, every vertex of the numbering; only those ``alive`` count.
    """
    from scipy.spatial import cKDTree

    free = np.ones(len(vertices), dtype=bool)
    if len(vertices) == 0:
        return free
    v, p, f = xy[vertices], xy[previous], xy[following]
    radius = np.maximum(np.hypot(*(p - v).T), np.hypot(*(f - v).T))
    pairs = cKDTree(v).sparse_distance_matrix(tree, float(radius.max()) * (1 + 1e-9), output_type="ndarray")
    i, j = pairs["i"], pairs["j"]
    near = (pairs["v"] <= radius[i] * (1 + 1e-9)) & alive[j]
    near &= (j != vertices[i]) & (j != previous[i]) & (j != following[i])
    i, j = i[near], j[near]
    q = xy[j]

    def side(a, b):
        return (b[i, 0] - a[i, 0]) * (q[:, 1] - a[i, 1]) - (b[i, 1] - a[i, 1]) * (q[:, 0] - a[i, 0])

    eps = 1e-12 * radius[i] ** 2
    s1, s2, s3 = side(p, v), side(v, f), side(f, p)
    inside = ((s1 >= -eps) & (s2 >= -eps) & (s3 >= -eps)) | ((s1 <= eps) & (s2 <= eps) & (s3 <= eps))
    free[i[inside]] = False
    return free


def _plane(points, geographic):
    """Conformal plane coordinates for the fill's geometry: Mercator metres for lon/lat, else the points."""
    if geographic:
        return np.ascontiguousarray(np.column_stack(to_mercator(points[:, 0], points[:, 1])))
    return np.ascontiguousarray(points)


def _edges_at(cells, mask):
    """The edges of the cells with a corner in ``mask``, in :func:`unique_edges` order: every edge at those vertices."""
    return unique_edges(cells[any_corner_in(mask, cells)])


def _shortest_edge_ends(edges, xy, which, cr):
    """For each vertex ``which`` marks: the other end of its shortest edge, and the vertex's Courant number."""
    lengths = np.hypot(*(xy[edges[:, 0]] - xy[edges[:, 1]]).T)
    vertex = np.concatenate([edges[:, 0], edges[:, 1]])
    other = np.concatenate([edges[:, 1], edges[:, 0]])
    lengths = np.concatenate([lengths, lengths])
    mine = which[vertex]
    vertex, other, lengths = vertex[mine], other[mine], lengths[mine]
    order = np.lexsort((lengths, vertex))
    first = np.ones(len(order), dtype=bool)
    first[1:] = vertex[order][1:] != vertex[order][:-1]
    shortest = order[first]
    return other[shortest], cr[vertex[shortest]]


LONG_EDGE = 4.0  # medians: a boundary edge longer is looked at by every chord crossing test, not found near it


def _chords_cross(xy, tree, edges, starts, ends):
    """Which chords ``starts -> ends`` (a boundary vertex's hole closed) cross a boundary edge or another chord.

    Across a narrow inlet the chord met the far bank: the refilled hole lay
    over cells there (7e-6 square degrees in the Gulf of Maine at 3 km).
    ``tree`` is a KD-tree over ``xy``.
    """
    chords = np.column_stack([starts, ends])
    if len(chords) == 0:
        return np.zeros(0, dtype=bool)
    # a boundary edge that meets a chord has an end within its own length of the chord, so within the
    # longest edge plus half the chord of the chord's middle: only the edges at the vertices the tree finds
    # there are looked at (a tree of every boundary edge's middle, made twice a round, took 15 ms at 50k edges).
    # The few edges longer than LONG_EDGE medians (241 km across open water where the median is 1.6 km) are
    # looked at wherever they are: sized by them, each chord's reach took in 5,000 vertices
    along = xy[edges[:, 1]] - xy[edges[:, 0]]
    squared = np.einsum("ij,ij->i", along, along)
    long = squared > LONG_EDGE**2 * np.median(squared)
    longest = np.sqrt(np.max(squared[~long], initial=0.0))
    reach = (0.5 * np.hypot(*(xy[ends] - xy[starts]).T) + longest) * (1 + 1e-9)
    near = tree.query_ball_point(0.5 * (xy[starts] + xy[ends]), reach)
    flagged = np.zeros(len(xy), dtype=bool)
    flagged[np.fromiter(itertools.chain.from_iterable(near), dtype=np.int64)] = True
    edges = edges[flagged[edges].any(axis=1) | long]
    first, _ = crossing_edges(xy, np.concatenate([edges, chords]), len(edges) + np.arange(len(chords)))
    crossing = np.zeros(len(chords), dtype=bool)
    crossing[first - len(edges)] = True
    return crossing


class _Round(NamedTuple):
    """What one round of :func:`_remove_round` did, in the numbering it was given."""

    cells: np.ndarray  # the mesh's cells after the round
    stuck: np.ndarray  # vertices whose hole could not be filled, not to be tried again until their star changes
    removed: np.ndarray  # the vertices removed
    new_cells: np.ndarray  # (k, 3): the cells filling their holes
    ring: np.ndarray  # the vertices around the removed ones: their stars changed
    corners: tuple  # (previous, vertex, following) of each boundary vertex removed
    boundary: np.ndarray  # the boundary edges before the round


def _remove_round(xy, tree, cells, cr, target, stuck, alive, boundary=None):
    """One round: the chosen vertices removed and their holes filled.

    ``xy`` (plane coordinates, see :func:`_plane`), ``cr`` and ``stuck``
    cover every vertex of the numbering, ``alive`` marking those the cells
    still use; ``tree`` is a KD-tree over ``xy``; ``boundary`` the cells'
    boundary edges where known (:func:`_boundary_after` a round). Only the
    vertices and cells around those over ``target`` are looked at, besides
    the boundary edges. Returns a :class:`_Round`.
    """
    edges = boundary_edges(cells) if boundary is None else boundary
    n = len(xy)
    is_boundary = np.zeros(n, dtype=bool)
    is_boundary[edges.ravel()] = True
    following = np.full(n, -1, dtype=np.int64)
    previous = np.full(n, -1, dtype=np.int64)
    following[edges[:, 0]], previous[edges[:, 1]] = edges[:, 1], edges[:, 0]
    bad = (cr > target) & ~stuck
    # interior vertices first: removing one never moves the shoreline
    priority = np.where(is_boundary, 0.5, 1.0) * cr
    blocked = (cr > target) & stuck
    if blocked.any():
        # a vertex that cannot go (its hole fills badly, or it is a reflex corner) has its
        # shortest edge, the dx of its Courant number, lengthened: the edge's other end goes
        far_end, courant_of = _shortest_edge_ends(_edges_at(cells, blocked), xy, blocked, cr)
        far_end_free = ~stuck[far_end]
        far_end, courant_of = far_end[far_end_free], courant_of[far_end_free]
        bad[far_end] = True
        np.maximum.at(priority, far_end, courant_of)
    chosen = _select(bad, priority, _edges_at(cells, bad))
    flat = cells.ravel()
    entry = np.flatnonzero(chosen[flat])
    cell, corner = entry // 3, entry % 3
    vertex = flat[entry]
    order = np.argsort(vertex, kind="stable")
    cell, corner, vertex = cell[order], corner[order], vertex[order]
    vertices, starts = np.unique(vertex, return_index=True)
    starts = np.append(starts, len(vertex)).astype(np.int64)
    a = cells[cell, (corner + 1) % 3]
    b = cells[cell, (corner + 2) % 3]
    corner_free = np.ones(len(vertices), dtype=bool)
    on_boundary = is_boundary[vertices]
    ends = previous[vertices[on_boundary]], following[vertices[on_boundary]]
    corner_free[on_boundary] = _corner_free(xy, tree, alive, vertices[on_boundary], *ends) & ~_chords_cross(
        xy, tree, edges, *ends
    )
    accepted, new_cells = fill_stars(vertices, starts, a, b, is_boundary, corner_free, xy, MIN_FILL_QUALITY)
    removed = vertices[accepted]
    stuck = stuck.copy()
    stuck[vertices[~accepted]] = True
    in_removed = np.zeros(n, dtype=bool)
    in_removed[removed] = True
    around = np.repeat(accepted, np.diff(starts))
    ring = np.union1d(a[around], b[around])
    stuck[ring] = False  # their stars changed: worth another try
    cells = np.concatenate([cells[~any_corner_in(in_removed, cells)], new_cells.reshape(-1, 3)])
    gone = removed[is_boundary[removed]]
    return _Round(cells, stuck, removed, new_cells, ring, (previous[gone], gone, following[gone]), edges)


def _boundary_after(step):
    """The boundary edges after a round that needs no repair, from those before it.

    Holes of interior vertices are filled inside their stars; that of a
    boundary vertex is closed by the chord from the vertex before it to the
    one after it, which takes the place of its two boundary edges. A chord
    along a boundary edge or another chord the other way (an island of three
    vertices closing up, or of four from two sides) makes both interior.
    Finding the boundary among the whole mesh's edges took 8-26 ms a round
    at 587k cells.
    """
    previous, gone, following = step.corners
    if len(gone) == 0:
        return step.boundary
    # every vertex has one boundary edge in and one out (the first round's repair deletes the cells at a
    # pinch, and _fills_need_no_repair refuses a round that leaves one), so a vertex ends one chord at most
    n = int(step.boundary.max()) + 1
    going = np.zeros(n, dtype=bool)
    going[gone] = True
    edges = step.boundary[~going[step.boundary].any(axis=1)]
    # an edge or chord back along a chord runs from its end to its start
    start_of = np.full(n, -1, dtype=np.int64)
    start_of[following] = previous
    back = start_of[edges[:, 0]] == edges[:, 1]
    closed = (start_of[previous] == following) | np.isin(following, edges[back, 0])
    return np.concatenate([edges[~back], np.column_stack([previous[~closed], following[~closed]])])


def _fills_need_no_repair(points, tree, alive, step, geographic):
    """Whether the mesh after ``step`` is valid wherever the round changed it, the mesh before it being valid.

    Then the repair (:func:`~terramesh.cleanup.fix_mesh`) would change
    nothing but drop the removed vertices, and is skipped: the fill cells
    are counter-clockwise and not flat in the mesh's own coordinates (the
    fill was made on the Mercator plane), every edge around the ring of
    removed vertices has at most two cells, on its two sides, every vertex
    of the ring left on the boundary has two boundary edges, and (on the
    sphere) the triangles closed by the chords of removed boundary vertices
    are empty and the chords cross nothing in longitude-latitude as well.
    A fill is a triangulation of the hole's polygon, so these leave no cell
    over another.
    """
    if len(step.cells) == 0:
        return False
    if len(step.new_cells) and (
        np.any(signed_areas(points, step.new_cells) <= 0)
        or np.any(triangle_quality(points, step.new_cells) < _REPAIR_MIN_QUALITY)
    ):
        return False
    n = len(points)
    in_ring = np.zeros(n, dtype=bool)
    in_ring[step.ring] = True
    local = step.cells[any_corner_in(in_ring, step.cells)]
    directed = (local * n + local[:, [1, 2, 0]]).ravel()
    pairs = (np.minimum(local, local[:, [1, 2, 0]]) * n + np.maximum(local, local[:, [1, 2, 0]])).ravel()
    if len(np.unique(directed)) < len(directed) or np.unique(pairs, return_counts=True)[1].max(initial=0) > 2:
        return False
    degree = np.bincount(boundary_edges(local).ravel(), minlength=n)[step.ring]
    if np.any((degree != 0) & (degree != 2)):
        return False
    previous, gone, following = step.corners
    if geographic and len(gone):
        free = _corner_free(points, tree, alive, gone, previous, following)
        return bool(np.all(free) and not np.any(_chords_cross(points, tree, step.boundary, previous, following)))
    return True


def _left_as_it_is_by_repair(mesh):
    """Whether the repair of :func:`enforce_timestep`'s rounds would return ``mesh`` as it is: a valid mesh.

    That is :func:`~terramesh.cleanup.mesh_problems` empty (hanging nodes
    count: the repair warns of them) and no cell flatter than the repair's
    ``min_quality``. On the guide's US East Coast mesh (318,567 vertices)
    the check takes 0.45 s where the repair took 1.2 s.
    """
    flat = len(remove_degenerate_cells(mesh.points, mesh.cells, _REPAIR_MIN_QUALITY)) < mesh.n_cells
    return not flat and not mesh_problems(mesh)


def _courant_around(cr, distance, points, cells, ring, alive, geographic):
    """``cr`` after a round that kept the numbering: 0 where a vertex went, measured again on the ``ring`` left.

    Only the vertices around the removed ones have other edges than
    before; ``distance`` is each vertex's wave speed times ``dt``, metres.
    """
    changed = np.zeros(len(cr), dtype=bool)
    changed[ring] = True
    changed &= alive
    cr = np.where(alive, cr, 0.0)
    cr[changed] = distance[changed] / _shortest_edge(points, cells[any_corner_in(changed, cells)], geographic)[changed]
    return cr


def _check_not_absurd(mesh, dt, target, cr, geographic, *, eta, gravity):
    """Refuse Courant numbers ``cr`` whose target would leave under :data:`MIN_KEPT_SHARE` of the vertices.

    A mesh in degrees taken for metres lost 299 of its 315 vertices at
    dt = 2 s, and one stepped at 2000 s all but 8, each with only a
    warning that a few vertices still broke the target. ``geographic`` is
    the caller's argument (None: from the crs).
    """
    share = _kept_share(cr, target)
    if share >= MIN_KEPT_SHARE:
        return
    largest = _degrees_taken_for_metres(mesh, geographic, wave_speed(mesh.depth, eta=eta, gravity=gravity) * dt)
    causes = [] if largest is None else [_degrees_advice(largest)]
    causes.append("dt is not in seconds (a step in minutes is 60 times too long)")
    raise SizingError(
        f"enforce_timestep: at dt = {dt:g} s the Courant numbers reach {float(cr.max()):.3g} (median"
        f" {float(np.median(cr)):.3g}) against a target of {target:g}: meeting it would leave"
        f" {'under 0.01' if share < 1e-4 else f'about {100.0 * share:.2g}'} % of the {len(cr)} vertices, so none was"
        " removed. Likely causes: "
        + "; or ".join(causes)
        + ". A mesh really this much finer than dt allows is better made again for it (coastal.build's dt; "
        "terramesh coastal --dt)"
    )


def enforce_timestep(
    mesh, dt, *, courant=COURANT, max_rounds=50, eta=ETA, gravity=GRAVITY, geographic=None, boundary_options=None
):
    """Remove the vertices that break the CFL condition at ``dt`` until none does (the guide's ``CheckTimestep``).

    Each round computes the Courant number at every vertex
    (:func:`courant_number`), picks among the vertices above ``courant`` an
    independent set (no two share a cell: each is the largest Courant
    number among its offending neighbours, interior vertices preferred to
    boundary ones), deletes each of them with its star of cells and fills
    the hole with triangles between the vertex's neighbours (the
    triangulation of the hole whose worst triangle is best, by dynamic
    programming; each round handles all the chosen vertices in one
    compiled pass). The hole of a boundary vertex is closed by the chord
    between its two boundary neighbours: at a convex corner the mesh loses
    the sliver between the chord and the old boundary, at a reflex one it
    gains the sliver (the triangle of the vertex and its two neighbours),
    which is allowed only when no other vertex lies in it, so that nothing
    overlaps. An island too small for ``dt`` (its own edges break the
    condition) shrinks and, at three vertices, closes up: the mesh then
    covers it (``info["boundaries"]["islands"]`` tells). A fill that would make a triangle of
    quality below :data:`MIN_FILL_QUALITY` is refused and the vertex left
    for a later round; in the meantime the other end of its shortest edge
    (its ``dx``) is removed in its place where that one can go.
    The mesh is repaired after each round
    (:func:`terramesh.cleanup.fix_mesh`, keeping every part). Depths and
    other ``point_data`` follow the vertices kept; no vertex moves.

    Only the first round repairs the whole mesh, and only when the mesh
    it is given is not valid (:func:`~terramesh.cleanup.mesh_problems`
    lists something, or a cell is flat): after it, a
    round looks at the cells it changed, repairs the whole mesh only if
    they break a validity rule there (the repair would change nothing
    else), and computes the Courant numbers again only at the vertices
    whose star changed, and carries the boundary over from the round
    before. The result is the mesh that repairing and measuring everything
    each round gives; on the guide's US East Coast mesh (318,000 vertices,
    8 rounds) it took 3 s instead of 26, and 2.2 s since the boundary is
    carried over.

    Parameters
    ----------
    mesh : Mesh
        A valid 2D triangle mesh with ``mesh.depth`` (metres, positive down).
    dt : float
        Target time step, seconds.
    courant : float, optional
        Largest Courant number allowed (0.5, OceanMesh2D's ``CheckTimestep``
        default; the guide suggests staying below 0.8).
    max_rounds : int, optional
        Most rounds; a warning says when they did not suffice.
    eta, gravity : float, optional
        Metres and m/s^2, as in :func:`courant_number`.
    geographic : bool, optional
        Points are longitude, latitude degrees; by default from ``mesh.crs``.
    boundary_options : dict, optional
        Options of :func:`~terramesh.coastal.make_boundaries` for rebuilding
        the boundaries; by default those the mesh's boundaries were made
        with (``mesh.info["boundaries"]["options"]``), while they are as
        :func:`~terramesh.coastal.make_boundaries` made them. Otherwise
        (edited since, or read from a file) they are carried over (see
        Returns).

    Returns
    -------
    Mesh
        A new mesh. When vertices were removed and the input's boundaries
        are as :func:`make_boundaries` made them (or ``boundary_options`` is
        given), they are made again with those options. Other boundaries
        (read from a fort.14 or edited, say) are carried over: renumbered, each string
        keeping its IBTYPE, order and extra columns, a removed node dropped
        with its row (a closed string is closed again). The first and last
        nodes of the strings that are not closed, where strings meet, and
        the nodes of paired barriers (IBTYPE 4, 24, 64, 5, 25) are never
        removed; the other end of their shortest edge may go instead.
        Neither are the fixed points of :func:`build` (``pfix``, whose
        vertices ``info["fixed_points"]`` lists, renumbered here).
        ``info["timestep"]`` holds ``dt``, ``courant``, ``rounds``,
        ``removed`` (vertices), ``max_courant_before``/``after`` and
        ``violations_before``/``after``.

    Raises
    ------
    MeshValidityError
        If the mesh has no depth, is not a 2D triangle mesh, or has cells
        of zero area or with a zero-length edge (its validity is not
        otherwise checked: see :func:`~terramesh.cleanup.mesh_problems`).
    SizingError
        For a non-positive ``dt`` or ``courant``; and, before anything is
        removed, when meeting ``courant`` would leave under
        :data:`MIN_KEPT_SHARE` of the vertices: a mesh in degrees without
        a ``crs`` taken for metres, or ``dt`` not in seconds.

    Warns
    -----
    TerrameshWarning
        When the target is not met after ``max_rounds``, or no offending
        vertex can be removed (e.g. at reflex boundary corners or boundary
        string ends); and when carried-over boundaries lose a string (an
        island that closed up) or a barrier loses node pairs.

    Examples
    --------
    A square of 200 m with 10 m cells at its centre grading to 40 m, 20 m
    deep: at ``dt = 1 s`` the smallest cells break ``Cr <= 0.5``.

    >>> import numpy as np, terramesh as tm
    >>> size = lambda p: 10.0 + 0.3 * np.hypot(p[:, 0] - 100.0, p[:, 1] - 100.0)
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (200, 200)), size, h0=10.0)
    >>> mesh.point_data["depth"] = np.full(mesh.n_points, 20.0)
    >>> bool(courant_number(mesh, 1.0).max() > 0.5)
    True
    >>> result = enforce_timestep(mesh, 1.0)
    >>> bool(courant_number(result, 1.0).max() <= 0.5), result.info["timestep"]["removed"] > 0
    (True, True)
    """
    from .boundaries import boundaries_fingerprint, carried_over, make_boundaries, string_ends

    mesh = checked_mesh(mesh, "enforce_timestep")
    dt = _positive("dt", dt)
    target = _positive("courant", courant)
    if not isinstance(max_rounds, numbers.Integral) or isinstance(max_rounds, bool) or max_rounds < 0:
        raise SizingError(f"max_rounds must be a non-negative integer, got {max_rounds!r}")
    given_geographic, geographic = geographic, is_geographic(mesh, geographic)
    depth_of(mesh)
    from scipy.spatial import cKDTree

    from ..mesh.mesh import Mesh

    _checked_cells(mesh, "enforce_timestep")
    before = _courant_numbers(mesh, dt, eta, gravity, geographic)
    _check_not_absurd(mesh, dt, target, before, given_geographic, eta=eta, gravity=gravity)
    options = boundary_options
    made = mesh.info.get("boundaries") or {}
    if options is None and mesh.boundaries is not None and made.get("made") == boundaries_fingerprint(mesh.boundaries):
        options = made.get("options")  # made by make_boundaries and not edited since: made again
    # boundaries carried over rather than made again: the ends of their strings and barrier nodes stay
    carried = mesh.boundaries is not None and options is None
    pinned = string_ends(mesh.boundaries, mesh.n_points) if carried else np.zeros(mesh.n_points, dtype=bool)
    fixed = np.asarray(mesh.info.get("fixed_points", ()), dtype=np.int64)
    pinned[fixed[fixed >= 0]] = True  # gauges and river inflow nodes (build's pfix) stay vertices
    # the rounds keep the numbering of the last repair (``repaired``); removed vertices stay in it, not alive
    repaired, cells, cr = mesh, mesh.cells, before
    origin = np.arange(mesh.n_points)  # each vertex's number in the input, carried through the repairs
    stuck = np.zeros(mesh.n_points, dtype=bool)
    alive = np.ones(mesh.n_points, dtype=bool)
    rounds = removed = 0
    xy = boundary = None
    while rounds < max_rounds and np.any((cr > target) & ~(stuck | pinned)):
        if xy is None:
            xy = _plane(repaired.points, geographic)
            plane_tree = cKDTree(xy)
            mesh_tree = cKDTree(repaired.points) if geographic else plane_tree
            speed = wave_speed(depth_of(repaired), eta=eta, gravity=gravity)
        step = _remove_round(xy, plane_tree, cells, cr, target, stuck | pinned, alive, boundary)
        rounds += 1
        removed += len(step.removed)
        # after a repair (or for an input the repair would leave as it is) only the cells a round changed can
        # be wrong: the first round repairs the input as it comes unless it is valid
        if rounds == 1:
            valid = _left_as_it_is_by_repair(mesh)
        if valid and _fills_need_no_repair(repaired.points, mesh_tree, alive, step, geographic):
            cells, stuck, boundary = step.cells, step.stuck, _boundary_after(step)
            alive = np.zeros(len(alive), dtype=bool)
            alive[cells.ravel()] = True
            cr = _courant_around(cr, speed * dt, repaired.points, cells, step.ring, alive, geographic)
        else:
            point_data = dict(repaired.point_data, _stuck=step.stuck, _pinned=pinned, _origin=origin)
            changed = Mesh(repaired.points, step.cells, point_data=point_data, title=mesh.title, crs=mesh.crs)
            repaired = fix_mesh(changed, disjoint_cutoff=0.0, min_quality=_REPAIR_MIN_QUALITY, geographic=geographic)
            cells, stuck, pinned = repaired.cells, repaired.point_data["_stuck"], repaired.point_data["_pinned"]
            origin = repaired.point_data["_origin"]
            alive = np.ones(repaired.n_points, dtype=bool)
            cr = _courant_numbers(repaired, dt, eta, gravity, geographic)  # repaired: no degenerate cell
            xy = boundary = None
            valid = True
    # the vertices still used, in their order: what the repair makes of the numbering
    new_index = np.cumsum(alive) - 1
    cr = cr[alive]
    point_data = {
        name: np.asarray(values)[alive] for name, values in repaired.point_data.items() if name not in _WORK_DATA
    }
    violations = int(np.sum(cr > target))
    if violations:
        why = f"after {rounds} rounds (max_rounds)" if rounds >= max_rounds else "where no vertex can be removed"
        kept = int(np.sum((cr > target) & pinned[alive]))
        if kept:
            why += f"; {kept} of them are fixed points, end a boundary string or belong to a barrier, and were kept"
        warn_user(
            f"enforce_timestep: {violations} vertices still have a Courant number above {target:g} at dt = {dt:g} s"
            f" (largest {float(cr.max()):.3g}) {why}",
        )
    report = {
        "dt": dt,
        "courant": target,
        "rounds": rounds,
        "removed": removed,
        "max_courant_before": float(before.max()) if len(before) else 0.0,
        "max_courant_after": float(cr.max()) if len(cr) else 0.0,
        "violations_before": int(np.sum(before > target)),
        "violations_after": violations,
    }
    vertex_map = np.full(mesh.n_points, -1)  # each input vertex's number in the result, -1 if removed
    vertex_map[origin[alive]] = np.arange(np.count_nonzero(alive))
    info = with_fixed_points_renumbered(dict(mesh.info, timestep=report), vertex_map)
    result = Mesh(
        repaired.points[alive], new_index[cells], point_data=point_data, title=mesh.title, crs=mesh.crs, info=info
    )
    if mesh.boundaries is None:
        return result
    if removed and not carried:
        return make_boundaries(result, **options)
    result.boundaries, lost = carried_over(mesh.boundaries, vertex_map, mesh.cells, result.cells, result.n_points)
    if lost:
        warn_user(f"enforce_timestep removed {removed} vertices: " + "; ".join(lost))
    return result


_WORK_DATA = ("_stuck", "_pinned", "_origin")
"""The ``point_data`` that :func:`enforce_timestep` carries through its repairs for itself."""
