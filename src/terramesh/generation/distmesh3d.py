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
"""

import logging
import time

import numpy as np

from .._kernels.delaunay3d import (
    _boundary_vertex_mask,
    _duplicate_points,
    _quality_mean_std,
    _unique_edges,
)
from .._kernels.forces import count_far, edge_size_ratios, force_step, largest_interior_move, rest_length_scale
from .._kernels.precompile import compile_ahead_on_first_run
from .._kernels.smoothing import _CUBE_DIRECTIONS, move_where_better, raise_worst
from .._kernels.smoothing3d import lengthen_short_edges, short_edge_vertices, smooth_interior_3d
from .._kernels.tetra import _min_dihedral_all, _radius_ratio_all, _volumes_all
from ..cleanup.fix_mesh import remove_unused_points
from ..cleanup.slivers import _STEPS, MIN_DIHEDRAL, _feature_vertices, _remove_slivers
from ..cleanup.validity import boundary_surface_problems, cells_outside
from ..errors import GenerationError, warn_user
from ..geometry.base import FunctionDomain, as_bbox, as_domain, distance_gradient
from ..geometry.csg import _leaves, known_by_distance_alone
from ..mesh.columns import row_max, rows_all, rows_any, squared_row_norms
from ..mesh.mesh import Mesh
from ..mesh.topology import _sorted_cell_edges, all_corners_in, any_corner_in, checked_fixed_points, kept_cells
from .distmesh import (
    _at,
    _finite_difference_step,
    _inside,
    _LazyDistance,
    _options,
    _raise_if_no_cells,
    _seeded,
    _spread,
    _warn_if_partly_covered,
    _warn_if_unconverged,
    _with_fixed_first,
    fixed_near_boundary,
    warn_if_fixed_points_dropped,
)
from .flat_faces import with_face_seeds
from .levels import COVERED, checked_levels, coarse_levels, refined_points, scaled, uncovered_seeds
from .sharp_edges import _edge_balls, _encroaching, _sharp_edge_chains, _with_sharp_edges
from .triangulate import _morton_order, delaunay_3d

__all__ = ["generate_mesh_3d", "bcc_seed_points", "delaunay_3d"]

logger = logging.getLogger("terramesh.generation")

TIME_STEP = 0.2  # fraction of the net force a point moves per iteration
LENGTH_FACTOR = 1.1  # rest lengths exceed actual ones, so springs push (Persson's 1 + 0.4 / 2**(dim - 1))
LATTICE_FACTOR = 1.07  # cube side of the seed lattice over h: 2 points per cube, about the density of the final mesh
RETRIANGULATE_AFTER = 0.3  # move since the last tetrahedralisation, in local edge lengths, that makes a point stale
STALE_ALLOWED = 0.05  # fraction of stale points tolerated before tetrahedralising again
LONG_EDGE = 2.5  # edges longer than this many times the median length-to-size ratio carry no spring
MAX_STALE_ITERATIONS = 20  # iterations after which the points are tetrahedralised again anyway
SETTLE_AFTER = 20  # a refined start stops at its first tetrahedralisation after this many iterations
REFINED_JITTER = 0.005  # of its edge's length, at most, on each axis: a refined start's midpoints are moved
STALL_WINDOW = 10  # iterations in which the mean - 3 std of the cell quality must improve...
STALL_GAIN = 1e-2  # ...by at least this much (on average), or generation stops as stalled
NEAR_BOUNDARY = 0.15  # interior points closer than this many local sizes to the boundary are dropped at the end
LANDED = 4 * np.finfo(float).eps  # a projected point is on the boundary at this distance over its largest coordinate
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
CHORD = 2.0  # sizes: a flat cell of boundary points alone with an edge longer than this lies across a curved side
THIN_SIZES = 3.0  # a domain fewer sizes than this across its thinnest side is called thin when slivers remain


# --- seeding: nested body-centred cubic lattices ----------------------------------------------

# offsets, in half-steps of the parent level, that reach every child lattice site from some parent
_CHILDREN = np.array(
    [(i, j, k) for i in (-2, 0, 2) for j in (-2, 0, 2) for k in (-2, 0, 2)]
    + [(i, j, k) for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)],
    dtype=np.int64,
)
_COARSEST_POINTS = 100_000
_MAX_LATTICE_SITES = 10**13


def _hash_uniform(indices, salt):
    """A uniform number in [0, 1) per lattice site from its three indices and ``salt`` (SplitMix64)."""
    with np.errstate(over="ignore"):
        z = indices[:, 0].astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15)
        z ^= indices[:, 1].astype(np.uint64) * np.uint64(0xC2B2AE3D27D4EB4F)
        z ^= indices[:, 2].astype(np.uint64) * np.uint64(0x165667B19E3779F9)
        z ^= np.uint64(salt)
        z = z + np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    return (z >> np.uint64(11)).astype(np.float64) / float(1 << 53)


def bcc_seed_points(domain, size, h0, bbox, rng, inside_tolerance, band=None):
    """Initial 3D points with local density following ``1 / size**3``.

    A body-centred cubic (BCC) lattice of cube side ``LATTICE_FACTOR * h0`` (1.07 h0; two points
    per cube; its Delaunay cells are Sommerville tetrahedra, the best
    space-filling ones) is nested: the lattice of cube side ``2 s`` is a
    sublattice of the one of side ``s``. Where the requested size ``h``
    lies between ``2**k h0`` and ``2**(k+1) h0`` points come from level
    ``k`` and are kept with probability ``(2**k h0 / h)**3``, decided by a
    hash of the lattice site and the seed, so at most seven in eight are
    rejected and the result does not depend on the visiting order. Levels
    are refined top-down only near points that need it, so the work follows
    the number of points kept. Every point gets a small deterministic
    jitter (at most 1 % of the cube side) so that no five points are
    cospherical and no four coplanar.

    Parameters
    ----------
    domain : Domain
        A 3D domain.
    size : callable
        Target edge length, ``(n, 3) -> (n,)``, the domain's units.
    h0 : float
        Smallest edge length, sets the finest lattice.
    bbox : numpy.ndarray, shape (2, 3)
        Region to fill.
    rng : numpy.random.Generator
        Seeds the thinning and the jitter (through one draw).
    inside_tolerance : float
        Keep sites whose signed distance is below this.
    band : float, optional
        Keep only sites within this many local sizes of the boundary (and
        skip the lattice deeper inside): a refined coarse level's gaps.

    Returns
    -------
    points : numpy.ndarray, shape (n, 3)
    smallest_size : float
        Smallest size met at the lattice sites inside the domain.

    Raises
    ------
    GenerationError
        When ``h0`` is too small for the bbox, or (without ``band``) no site falls inside.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.geometry.primitives3d import Ball
    >>> ball = Ball((0, 0, 0), 1.0)
    >>> points, _ = bcc_seed_points(ball, lambda p: np.full(len(p), 0.2), 0.2, ball.bbox,
    ...                             np.random.default_rng(0), 1e-6)
    >>> expected = 2 / (1.07 * 0.2) ** 3 * (4 / 3 * np.pi)  # two points per lattice cube
    >>> round(len(points) / expected, 2), bool(np.all(ball.distance(points) < 1e-6))
    (1.0, True)
    """
    salt = int(rng.integers(0, 2**63))
    half = 0.5 * LATTICE_FACTOR * h0  # lattice coordinates count half cube sides: sites are all even or all odd
    extent = bbox[1] - bbox[0]
    c_max = np.floor(extent / half).astype(np.int64) + 1
    sites = float(np.prod(c_max.astype(np.float64) + 1.0)) / 4.0
    if sites > _MAX_LATTICE_SITES:
        raise GenerationError(f"h0={h0:g} is too small for this bbox ({sites:.3g} lattice sites); raise h0")
    top = max(0, int(np.ceil(np.log2(sites / _COARSEST_POINTS) / 3.0)))
    stride = 1 << top
    axes = [np.arange(0, c + 2 * stride, 2 * stride) for c in c_max]
    even = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    active = np.concatenate([even, even + stride])
    kept, smallest = [], np.inf
    reach = 0.5 * np.sqrt(3.0) * LATTICE_FACTOR * h0  # a site's descendants lie within reach * stride of it
    for level in range(top, -1, -1):
        stride = 1 << level
        points = bbox[0] + half * active
        inside_box = rows_all((points >= bbox[0] - 1e-9 * extent) & (points <= bbox[1] + 1e-9 * extent))
        distance = np.full(len(points), np.inf)
        distance[inside_box] = domain.distance(points[inside_box])
        near = distance < (reach * stride + 1e-9 * extent.max())
        active, points, distance = active[near], points[near], distance[near]
        if len(active) == 0:
            break
        target = size(points)
        inside = distance < inside_tolerance
        if inside.any():
            smallest = min(smallest, float(target[inside].min()))
        own_level = np.floor(np.log2(np.maximum(target / h0, 1.0))).astype(np.int64)
        at_level = (own_level == level) | ((level == top) & (own_level >= top))
        keep = at_level & inside & (_hash_uniform(active, salt) < (h0 * stride / target) ** 3)
        if band is not None:
            keep &= distance > -band * target
        kept.append(active[keep])
        if level == 0:
            break
        refine = target < 2.0 * stride * h0
        if band is not None:  # deep inside: no site of the band below it (sizes may halve on the way down)
            refine &= distance > -(2.0 * band * target + reach * stride)
        # the children within the bbox (and a stride around it), each once, in the order of their key; built one
        # axis at a time (NumPy reduces an (n, 35, 3) array over its last axis slowly), sorted by a merge sort,
        # which takes the runs of keys that the sorted parents give
        span = c_max + 2 * stride + 1
        x, y, z = (active[refine, axis, None] + (stride // 2) * _CHILDREN[:, axis] + stride for axis in range(3))
        within = (x >= 0) & (x < span[0]) & (y >= 0) & (y < span[1]) & (z >= 0) & (z < span[2])
        key = np.sort(((x * span[1] + y) * span[2] + z)[within], kind="stable")
        key = key[np.append(True, key[1:] != key[:-1])] if key.size else key  # none refined: the band is done
        active = np.column_stack([key // (span[1] * span[2]), key // span[2] % span[1], key % span[2]]) - stride
    sites = np.concatenate(kept) if kept else np.empty((0, 3), dtype=np.int64)
    if len(sites) == 0 and band is None:
        raise GenerationError("no lattice point falls inside the domain: the bbox misses it or h0 is too large")
    jitter = np.column_stack([_hash_uniform(sites, salt ^ (0x5BD1E995 * (axis + 1))) for axis in range(3)]) - 0.5
    points = bbox[0] + half * (sites + 0.02 * jitter)
    escaped = domain.distance(points) >= inside_tolerance  # jittered out of the domain: back on the lattice site
    points[escaped] = bbox[0] + half * sites[escaped]
    return points, smallest


def _lattice_seeds(domain, size, h0, bbox, rng, inside_tolerance):
    """:func:`bcc_seed_points` with hexagonal lattices on the domain's flat faces (:mod:`.flat_faces`)."""
    points, smallest = bcc_seed_points(domain, size, h0, bbox, rng, inside_tolerance)
    return with_face_seeds(points, domain, size, h0, bbox, rng, inside_tolerance), smallest


# --- the driver ------------------------------------------------------------------------------------


def _project_to_boundary(domain, points, distance, step, *, newton_steps=2):
    """Move points onto the zero level set: exactly where the domain can (``domain.project``), else by Newton.

    Up to ``newton_steps`` steps along the forward-difference gradient, each
    only for the points whose distance is still above rounding (LANDED times
    their largest coordinate): a step leaves the error of that gradient
    (rounding over the difference step) times the distance, which the next
    step multiplies by it again. The difference step shrinks with the
    distance, to a quarter of it (but not below 4 LANDED times the
    coordinates), so that a point landing near an edge of the boundary,
    where the gradient jumps, does not difference across the edge.
    """
    project = getattr(domain, "project", None)
    if callable(project):
        return project(points)
    points = points.copy()
    distance = np.array(distance, dtype=np.float64)
    landed = LANDED * row_max(np.abs(points))
    active = np.flatnonzero(np.abs(distance) > landed)
    for _ in range(newton_steps):
        if len(active) == 0:
            break
        where, off = points[active], distance[active]
        local_step = np.clip(0.25 * np.abs(off), 4.0 * landed[active], step)
        gradient = distance_gradient(domain, where, off, local_step)
        norm2 = squared_row_norms(gradient)
        norm2[norm2 == 0] = 1.0
        points[active] = where - (off / norm2)[:, None] * gradient
        distance[active] = domain.distance(points[active])
        active = active[np.abs(distance[active]) > landed[active]]
    return points


def _tetrahedralise(domain, points, tolerance, distance_bound=None, *, neighbors=False):
    """Delaunay cells with their centroid inside; with ``neighbors`` their neighbours (renumbered), else None.

    The force loop needs no neighbours (renumbering them takes 8 ms at
    25k points, 7 % of the tetrahedralisation).

    The points must be distinct (see :func:`~terramesh._kernels.delaunay3d._duplicate_points`).
    """
    cells, across = delaunay_3d(points)
    inside = _inside(domain, points, cells, tolerance, distance_bound)
    if not neighbors:
        return cells[inside], None
    return kept_cells(cells, across, inside)


def _without_long_edges(points, edges, target):
    """The edges not longer than LONG_EDGE times the median length-to-size ratio.

    Nearly coplanar boundary points (a flat face of the domain) give
    Delaunay cells that reach across the domain. Their long edges exert no
    force (springs only push), but they would inflate the sum of squared
    lengths that scales every rest length, and so the pressure on all points.
    """
    if len(edges) == 0:  # no cell inside (yet): the clean-up says the domain is too thin for the size
        return edges
    ratio = edge_size_ratios(points, edges, target)
    return edges[ratio <= LONG_EDGE * np.median(ratio[::7])]  # every 7th: the median needs no more


def _stalled(scores):
    """Whether the quality of fresh tetrahedralisations now gains less than STALL_GAIN per STALL_WINDOW iterations.

    ``scores`` holds (iteration, mean - 3 std of the cell quality) pairs; the
    last is compared with the best at least STALL_WINDOW iterations older.
    """
    if not scores:
        return False
    last, score = scores[-1]
    older = [(value, iteration) for iteration, value in scores if iteration <= last - STALL_WINDOW]
    if not older:
        return False
    best, when = max(older)
    return (score - best) * STALL_WINDOW / (last - when) < STALL_GAIN


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
    return _generate_mesh_3d(domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed, levels)


def _generate_mesh_3d(domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed, levels, clear=None):
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
    size, h0, tolerance, fixed, h0_estimated, measure, _ = _options(
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
    _warn_if_unconverged(final, max_iter, move_tolerance)
    _warn_if_partly_covered(mesh, measure)
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
    see :func:`_generate_mesh_3d`.
    """
    records = []
    points, n_fixed, edge_balls = _relaxed(
        domain, size, h0, bbox, tolerance, fixed, levels, seed, max_iter, move_tolerance, warn_below_h0, records
    )
    if clear is not None:
        points = np.vstack([points[:n_fixed], points[n_fixed:][~clear(points[n_fixed:], size)]])
    forces_done = time.perf_counter()
    try:
        mesh = _finalize(domain, size, points, n_fixed, tolerance, _finite_difference_step(h0, bbox), edge_balls)
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
        points = _seeded(domain, size, h0, bbox, fixed, seed, _lattice_seeds, tolerance, warn_below_h0)
    chains = _sharp_edge_chains(domain, size, h0)
    points, n_fixed = _with_sharp_edges(domain, size, h0, bbox, tolerance, points, len(fixed), chains)
    edge_balls = _edge_balls(domain, chains, tolerance)
    # Z-order numbering: neighbours in space are near in memory (every kernel below walks neighbours)
    points = np.vstack([points[:n_fixed], points[n_fixed:][_morton_order(points[n_fixed:])]])
    if len(points) < 4:
        extent = " x ".join(f"{side:.4g}" for side in bbox[1] - bbox[0])
        raise GenerationError(
            f"only {len(points)} point{'s' if len(points) != 1 else ''} fit in the domain (its bbox {extent}): "
            f"h0={h0:g} is too large for it"
        )
    points, record = _force_equilibrium(
        domain,
        size,
        np.ascontiguousarray(points),
        n_fixed,
        tolerance,
        _finite_difference_step(h0, bbox),
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
    coarse_fixed = fixed[_spread(fixed, coarse_size)]
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
        cells, neighbors = _tetrahedralise(domain, points, tolerance, neighbors=True)
    except GenerationError as error:
        logger.info("no coarse level (%s): seeding the level of h0 = %g afresh", error, h0)
        del records[:]
        return None
    edges, on_boundary_edge = edges_on_faces(cells, _boundary_faces(cells, neighbors), len(points))
    step = _finite_difference_step(h0, bbox)

    def project(middle, distance):
        return _project_to_boundary(domain, middle, distance, step, newton_steps=3)

    # the midpoints of a settled mesh are nearly cospherical in many places (and cocircular on a flat face), so
    # the tetrahedralisation's exact predicates decide often: a 68k-point refined start took 0.91 s, jittered 0.45
    jitter = REFINED_JITTER * np.random.default_rng(seed).uniform(-1.0, 1.0, (len(edges), 3))
    middle = refined_points(domain, points, edges, on_boundary_edge, project, jitter)
    # a flat cell with four corners on the boundary (across a cylinder's side) has a diagonal that is no boundary
    # edge, its midpoint a sag inside, where the forces push it out: a cylinder's side came out with 78 % more
    # vertices than one level gives, 376 edges under half their size among them
    inner = np.flatnonzero(~on_boundary_edge)
    distance = domain.distance(middle[inner])
    near = distance > -NEAR_BOUNDARY * size(middle[inner])
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
    return _with_fixed_first(np.vstack([start, fill]), fixed, 0.5 * h0)


def edges_on_faces(cells, faces, n_points):
    """The cells' unique edges (``a < b`` in each) and the mask of those on any of ``faces`` (boundary faces)."""
    edges = _unique_edges(np.ascontiguousarray(cells, dtype=np.int64), n_points)
    on = _sorted_cell_edges(faces)
    return edges, np.isin(edges[:, 0] * n_points + edges[:, 1], on[:, 0] * n_points + on[:, 1])


def _force_equilibrium(domain, size, points, n_fixed, tolerance, finite_step, max_iter, move_tolerance, settle=0):
    """Move the free points (past the first ``n_fixed``) by truss forces until they stop or the quality stalls.

    With ``settle`` (a refined start, nearly in equilibrium) they also stop,
    as "settled", after the first iteration on a fresh tetrahedralisation
    past iteration ``settle``: the final tetrahedralisation follows, and
    twenty more iterations and a tetrahedralisation won little (mean radius
    ratio 0.9067 against 0.9038 on a graded box of 68k vertices) for a fifth
    of the generation's time (BP2004 3D: 3.4-3.6 s against 2.8-2.9 s).

    Returns ``(points, record)``, the record holding ``iterations``,
    ``stop_reason``, ``max_move``, ``retriangulations`` and ``seconds``.
    """
    started = time.perf_counter()
    target = size(points)
    last_triangulated = np.full_like(points, np.inf)
    retriangulations, max_move, last_log, scores, last_fresh = 0, np.inf, started, [], 0
    stop_reason = "max_iter"
    lazy_distance = _LazyDistance(domain)
    on_boundary = np.zeros(len(points), dtype=bool)  # as of the last iteration (the seeds: none counted)

    for iteration in range(1, int(max_iter) + 1):
        fresh = iteration - last_fresh >= MAX_STALE_ITERATIONS or count_far(
            points, last_triangulated, target, RETRIANGULATE_AFTER
        ) > STALE_ALLOWED * len(points)
        if fresh:
            doomed = _duplicate_points(points)  # two points projected onto the same corner, say
            if doomed.any():
                points, target, last_triangulated = points[~doomed], target[~doomed], last_triangulated[~doomed]
                on_boundary = on_boundary[~doomed]
            bound = lazy_distance.upper_bound(len(points))
            cells, _ = _tetrahedralise(domain, points, tolerance, bound)
            edges = _without_long_edges(points, _unique_edges(np.ascontiguousarray(cells), len(points)), target)
            scaling = _scaling_cells(points, cells, on_boundary, target)
            scaled_by = (
                edges if scaling is None else _without_long_edges(points, _unique_edges(scaling, len(points)), target)
            )
            last_triangulated = points.copy()
            last_fresh = iteration
            retriangulations += 1
        # the edges' forces summed in order: 3D meshes of thin parts hang on their last bits (two of the tests'
        # failed with the 2D generator's chunked sums), and the tetrahedralisation, not the forces, is 3D's cost
        scale = rest_length_scale(points, scaled_by, target, LENGTH_FACTOR, 1)
        points, move = force_step(points, edges, target, scale, TIME_STEP, n_fixed, 1)
        distance = lazy_distance.update(points, move, target)
        outside = distance > 0
        if outside.any():
            points[outside] = _project_to_boundary(
                domain, points[outside], distance[outside], finite_step, newton_steps=1
            )
        target = size(points)
        max_move = largest_interior_move(move, target, distance, tolerance)
        on_boundary = distance >= -tolerance
        if fresh:
            # cells with all four corners on the boundary (flat ones along a cylinder's side) are peeled at the end
            mean, std = _quality_mean_std(points, cells, on_boundary)
            scores.append((iteration, mean - 3.0 * std))
        if time.perf_counter() - last_log > 1.0:
            last_log = time.perf_counter()
            logger.info(
                "iteration %d: %d points, largest move %.2e of the local size, %d tetrahedralisations, "
                "q mean-3std %.4f",
                iteration,
                len(points),
                max_move,
                retriangulations,
                scores[-1][1],
            )
        if max_move < move_tolerance:
            stop_reason = "converged"
            break
        if _stalled(scores):
            stop_reason = "stalled"
            break
        if settle and fresh and iteration > settle:
            stop_reason = "settled"
            break
    record = dict(
        iterations=iteration,
        stop_reason=stop_reason,
        max_move=max_move,
        retriangulations=retriangulations,
        seconds=time.perf_counter() - started,
    )
    return points, record


def _scaling_cells(points, cells, on_boundary, target):
    """The ``cells`` whose edges set the rest lengths' scale: all but the flat ones of boundary points alone.

    The scale is Persson's, the root mean square of the edges over the
    sizes. Delaunay makes flat cells of boundary points across a
    cylinder's side, their edges chords of many sizes, which raised the
    scale, and the pressure jammed the interior: a cylinder graded along
    its axis had 3.3 % of its cells below radius ratio 0.5 (mean 0.827),
    a box or a ball 0.8-0.9 %. Their edges stay springs: left out of the
    forces too, a tube's wall 1.2 sizes thick lost 7 % of its vertices and
    a voxel salt body refused in 15 of 16 seeds, not 6. Left out: a
    dihedral angle below ``MIN_DIHEDRAL`` and an edge longer than
    ``CHORD`` sizes (a box's cells along its edges have four boundary
    corners too, and a thin wall's flat cells span it). None when none is.
    """
    candidates = np.flatnonzero(all_corners_in(on_boundary, cells))
    if len(candidates) == 0:
        return None
    corners = np.ascontiguousarray(cells[candidates])
    ends = points[corners]
    longest = np.max([squared_row_norms(ends[:, a] - ends[:, b]) for a in range(4) for b in range(a + 1, 4)], axis=0)
    chord = longest > (CHORD * row_max(target[corners])) ** 2
    chord[chord] = _min_dihedral_all(points, corners[chord]) < MIN_DIHEDRAL
    if not chord.any():
        return None
    return np.ascontiguousarray(np.delete(cells, candidates[chord], axis=0))


def _polished(domain, points, cells, movable, on_boundary, slidable, boundary_candidates):
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
        poor = np.unique(cells[_radius_ratio_all(smoothed, cells) < RAISE_BELOW])
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

    The interior ends try the 26 cube directions at ``_STEPS`` of their
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
            candidates = np.repeat(lengthened[short, None, :], len(_STEPS) * len(_CUBE_DIRECTIONS), axis=1)
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
    """Positions around each point: the 26 cube directions at ``_STEPS`` of its ``scale``, the point where outside."""
    steps = _STEPS[None, :, None, None] * scale[:, None, None, None]
    around = (where[:, None, None, :] + steps * _CUBE_DIRECTIONS[None, None, :, :]).reshape(len(where), -1, 3)
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
    steps = _STEPS[None, :, None, None] * scale[:, None, None, None]
    candidates = (where[:, None, None, :] + steps * directions[:, None, :, :]).reshape(-1, 3)
    projected = _project_to_boundary(domain, candidates, domain.distance(candidates), finite_step, newton_steps=3)
    off = np.abs(domain.distance(projected)) > tolerance
    projected[off] = np.repeat(where, len(_STEPS) * 8, axis=0)[off]
    return np.ascontiguousarray(projected.reshape(len(vertices), -1, 3))


def _boundary_faces(cells, neighbors, opposite=False):
    """Faces of the cells with no cell across, shape (b, 3); with ``opposite``, also each cell's corner across it."""
    free = [neighbors[:, k] < 0 for k in range(4)]
    faces = np.concatenate([np.delete(cells, k, axis=1)[free[k]] for k in range(4)])
    if not opposite:
        return faces
    return faces, np.concatenate([cells[free[k], k] for k in range(4)])


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
    faces, opposite = _boundary_faces(cells, neighbors, opposite=True)
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
    across = thinnest / float(np.median(size(points)))
    if across >= THIN_SIZES:
        return ""
    return (
        f"the domain is {thinnest:.4g} across its thinnest side, {across:.2g} sizes: "
        "too thin for tetrahedra of that size"
    )


def _near_fixed(domain, size, fixed, tolerance):
    """Why ``fixed`` points less than half a size inside the boundary may have failed the mesh, or ``""``.

    A box at h 0.17 with one 0.09 sizes in by a corner: a face across the
    domain, which the message called too thin.
    """
    near = fixed_near_boundary(fixed, domain.distance(fixed), size, tolerance) if len(fixed) else ""
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
    leaves = _leaves(domain)
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
        f"{_at(points[worst])}: an edge of the domain the generator does not know{_unknown_edges(domain)}"
    )


def _problems(points, cells, neighbors):
    """What makes the final mesh invalid, as a list of phrases (empty when valid)."""
    problems = []
    volume = _volumes_all(points, cells)
    if np.any(volume <= 0):
        problems.append(f"{int(np.sum(volume <= 0))} cells are inverted or flat")
    if np.any(np.bincount(cells.ravel(), minlength=len(points)) == 0):
        problems.append("unused vertices")
    return problems + boundary_surface_problems(_boundary_faces(cells, neighbors), len(points))[0]


def _without_hull_cells(domain, size, points, cells, neighbors, tolerance):
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
    flat = (_min_dihedral_all(points, corners) < MIN_DIHEDRAL) & (
        domain.distance(centroids) > -HULL_FLAT_DEPTH * size(centroids)
    )
    drop = np.zeros(len(cells), dtype=bool)
    drop[candidates[across.reshape(-1, 4).any(axis=1) | flat]] = True
    if not drop.any():
        return cells, neighbors
    return kept_cells(cells, neighbors, ~drop)


def _finalize(domain, size, points, n_fixed, tolerance, finite_step, edge_balls=None):
    """The final points' Delaunay cells inside the domain, boundary vertices projected, slivers removed.

    ``edge_balls`` (see :func:`_edge_balls`): free points inside them are
    dropped, so that the sharp edges' segments are edges of the cells.
    """
    started = time.perf_counter()
    # a point stuck just inside the boundary makes flat cells with the boundary points above it
    distance = domain.distance(points)
    stuck = (distance < -tolerance) & (distance > -NEAR_BOUNDARY * size(points))
    stuck[:n_fixed] = False
    centres, radii = (np.empty((0, 3)), np.empty(0)) if edge_balls is None else edge_balls
    stuck |= _encroaching(points, n_fixed, centres, radii)
    points = points[~stuck & ~_duplicate_points(points)]
    for attempt in range(ENCROACHED_ROUNDS):
        cells, neighbors = _tetrahedralise(domain, points, tolerance, neighbors=True)
        _raise_if_no_cells(cells)
        points = points.copy()
        mask = _boundary_vertex_mask(cells, neighbors, np.ones(len(cells), dtype=bool), len(points))
        on_boundary = np.flatnonzero(mask)
        on_boundary = on_boundary[on_boundary >= n_fixed]
        points[on_boundary] = _project_to_boundary(
            domain,
            points[on_boundary],
            domain.distance(points[on_boundary]),
            finite_step,
            newton_steps=FINAL_NEWTON_STEPS,
        )
        # an interior point that the cells left on the boundary may have been projected next to an edge
        encroaching = _encroaching(points, n_fixed, centres, radii)
        if not encroaching.any() or attempt == ENCROACHED_ROUNDS - 1:
            break
        points = points[~encroaching]
    cells, neighbors = _without_hull_cells(domain, size, points, cells, neighbors, tolerance)
    slivers_before = int(np.sum(_min_dihedral_all(points, cells) < MIN_DIHEDRAL))

    def boundary_candidates(points, vertices):
        return _boundary_candidates(domain, points, vertices, size(points[vertices]), finite_step, tolerance)

    points, cells, neighbors, rounds = _remove_slivers(domain, points, cells, neighbors, n_fixed, boundary_candidates)
    cells, neighbors = _without_hull_cells(domain, size, points, cells, neighbors, tolerance)
    _raise_if_no_cells(cells)  # the clean-up may take the last ones (a ball a few sizes across)
    points, cells, kept = remove_unused_points(points, cells)
    on_boundary = np.zeros(len(points), dtype=bool)
    on_boundary[_boundary_faces(cells, neighbors).ravel()] = True
    free = kept >= n_fixed
    slidable = on_boundary & free & ~_feature_vertices(points, cells, neighbors, len(points))
    movable = ~on_boundary & free
    points, outside = _polished(domain, points, cells, movable, on_boundary, slidable, boundary_candidates)
    if not outside.any():
        points = _lengthened(domain, size, points, cells, movable, on_boundary, slidable, boundary_candidates)
    angles = _min_dihedral_all(points, cells)
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
    problems = _problems(points, cells, neighbors)
    if outside.any():
        problems.append(f"{int(outside.sum())} cells have their centroid outside the domain")
    across = _faces_across(domain, points, cells, neighbors, finite_step)
    if across:
        problems.append(f"{across} boundary faces cut across the domain instead of lying on its boundary")
    if problems:
        thin = _too_thin(points, size) or _near_fixed(domain, size, points[~free], tolerance)
        raise GenerationError(
            "mesh generation produced an invalid mesh: "
            + "; ".join(problems)
            + (
                f"; {thin}"
                if thin
                else ". A part of the domain thinner than about two edge lengths (a hole, a gap, a neck, solids "
                "touching along an edge or at a point) cannot be meshed at this size"
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
