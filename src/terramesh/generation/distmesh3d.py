"""The force-equilibrium mesh generator (Persson & Strang 2004), 3D, with guaranteed sliver removal.

The loop of the 2D generator: seed points by the size function (a
body-centred cubic lattice, thinned), tetrahedralise, push points along truss
forces, project escaped points back onto the boundary, tetrahedralise again
when points have moved far enough (or every 20 iterations), stop when they stop
moving or the quality stalls. There is no density control (as in Persson's
n-D code): in 3D it removed far too many points. Sharp edges the domain
declares (a box's twelve; a CSG combination's, those it creates where one
operand's surface meets another's included, straight or curved) are
sampled by the size function and their points fixed, as the corners are:
the forces alone would push points off an edge onto one face or the other,
and the final cells would then cut across it. Before the final
tetrahedralisation, free points that came within the ball on a segment
between two edge points are dropped, so that the segment is an edge of
the cells (across a re-entrant edge, cells would otherwise bridge the
outside).

Then the final Delaunay mesh is cleaned and its slivers removed, in rounds:
flat cells with two or more faces on the boundary are peeled off, the best
edge removal (every triangulation of the ring, by dynamic programming) or
2-3 flip replaces poor cells, poor cells' vertices move to the best of a
deterministic set of nearby positions (on the boundary for boundary
vertices), and interior vertices that still hold slivers are contracted onto
a neighbour. Every change must raise the smallest dihedral angle of the cells
it touches and keep them positive. Cells below AIM_DIHEDRAL (15 degrees) are
worked on; a mesh with any cell below MIN_DIHEDRAL (10 degrees) left is not
returned: the call raises GenerationError with the count.

The Delaunay tetrahedralisation is an incremental Bowyer-Watson kernel
(numba, floating-point predicates, the cavity grown until the new point sees
all its faces, so the result is always a valid tetrahedralisation): 0.13 to
0.2 s for 25k points here, against 0.7 to 1 s for SciPy's Qhull, which a
25k-vertex ball needs about eight times. Qhull (:class:`scipy.spatial.Delaunay`)
remains the fallback should the kernel fail.
"""

import logging
import time
import warnings

import numba
import numpy as np

from .._kernels.forces import count_far, force_step, largest_interior_move
from ..errors import GenerationError, TerrameshWarning
from ..geometry.base import as_bbox, as_domain
from ..mesh.mesh import Mesh
from ..quality.tetra import _tet_largest_cosine
from .distmesh import _initial_points, _LazyDistance, _spread_corners

__all__ = ["generate_mesh_3d", "bcc_seed_points", "delaunay_3d"]

logger = logging.getLogger("terramesh.generation")

TIME_STEP = 0.2  # fraction of the net force a point moves per iteration
LENGTH_FACTOR = 1.1  # rest lengths exceed actual ones, so springs push (Persson's 1 + 0.4 / 2**(dim - 1))
LATTICE_FACTOR = 1.07  # cube side of the seed lattice over h: 2 points per cube, about the density of the final mesh
RETRIANGULATE_AFTER = 0.3  # move since the last tetrahedralisation, in local edge lengths, that makes a point stale
STALE_ALLOWED = 0.05  # fraction of stale points tolerated before tetrahedralising again
LONG_EDGE = 2.5  # edges longer than this many times the median length-to-size ratio carry no spring
MAX_STALE_ITERATIONS = 20  # iterations after which the points are tetrahedralised again anyway
STALL_WINDOW = 10  # iterations in which the mean - 3 std of the cell quality must improve...
STALL_GAIN = 1e-2  # ...by at least this much (on average), or generation stops as stalled
NEAR_BOUNDARY = 0.15  # interior points closer than this many local sizes to the boundary are dropped at the end
MIN_DIHEDRAL = 10.0  # degrees: every returned cell has a smallest dihedral angle at least this
AIM_DIHEDRAL = 15.0  # degrees: sliver removal works on every cell below this
SHARP_TURN = 35.0  # degrees between two boundary faces' outward normals above which their common edge is sharp
EDGE_SAMPLING = 8  # samples per h0 along a sharp edge when its size function is integrated
SLIVER_ROUNDS = 12  # rounds of flips, perturbation and boundary deletion
ENCLOSING_SCALE = 1.0e4  # the enclosing tetrahedron's size over the points' extent
LANDED = 4 * np.finfo(float).eps  # a projected point is on the boundary at this distance over its largest coordinate
FINAL_NEWTON_STEPS = 6  # at most, for the boundary vertices of the final mesh
ENCROACHED_ROUNDS = 3  # final tetrahedralisations at most, each after dropping points projected next to a sharp edge
EDGE_BALL = 1.25  # free points are kept this many half segment lengths from the middle of a sharp edge segment


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


def bcc_seed_points(domain, size, h0, bbox, rng, inside_tolerance):
    """Initial 3D points with local density following ``1 / size**3``.

    A body-centred cubic (BCC) lattice of cube side ``1.12 h0`` (two points
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

    Returns
    -------
    points : numpy.ndarray, shape (n, 3)
    smallest_size : float
        Smallest size met at the lattice sites inside the domain.

    Raises
    ------
    GenerationError
        When ``h0`` is too small for the bbox, or no site falls inside.

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
        inside_box = np.all((points >= bbox[0] - 1e-9 * extent) & (points <= bbox[1] + 1e-9 * extent), axis=1)
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
        kept.append(active[keep])
        if level == 0:
            break
        refine = target < 2.0 * stride * h0
        children = (active[refine][:, None, :] + (stride // 2) * _CHILDREN[None]).reshape(-1, 3)
        children = children[np.all((children >= -stride) & (children <= c_max + stride), axis=1)]
        span = c_max + 2 * stride + 1
        key = ((children[:, 0] + stride) * span[1] + children[:, 1] + stride) * span[2] + children[:, 2] + stride
        _, first = np.unique(key, return_index=True)
        active = children[first]
    sites = np.concatenate(kept) if kept else np.empty((0, 3), dtype=np.int64)
    if len(sites) == 0:
        raise GenerationError("no lattice point falls inside the domain: the bbox misses it or h0 is too large")
    jitter = np.column_stack([_hash_uniform(sites, salt ^ (0x5BD1E995 * (axis + 1))) for axis in range(3)]) - 0.5
    points = bbox[0] + half * (sites + 0.02 * jitter)
    escaped = domain.distance(points) >= inside_tolerance  # jittered out of the domain: back on the lattice site
    points[escaped] = bbox[0] + half * sites[escaped]
    return points, smallest


# --- Delaunay tetrahedralisation (Bowyer-Watson) -------------------------------------------------

_OK = 0
_WALK_FAILED = 1
_CAVITY_FAILED = 2


@numba.njit(cache=True, inline="always")
def _orient(points, a, b, c, d):
    """Six times the signed volume of ``(a, b, c, d)``: positive when ``d`` sees ``a, b, c`` counter-clockwise."""
    bx = points[b, 0] - points[a, 0]
    by = points[b, 1] - points[a, 1]
    bz = points[b, 2] - points[a, 2]
    cx = points[c, 0] - points[a, 0]
    cy = points[c, 1] - points[a, 1]
    cz = points[c, 2] - points[a, 2]
    dx = points[d, 0] - points[a, 0]
    dy = points[d, 1] - points[a, 1]
    dz = points[d, 2] - points[a, 2]
    return bx * (cy * dz - cz * dy) - by * (cx * dz - cz * dx) + bz * (cx * dy - cy * dx)


@numba.njit(cache=True, inline="always")
def _insphere(points, a, b, c, d, e):
    """Positive when ``e`` lies inside the circumsphere of the positively oriented ``(a, b, c, d)``."""
    ax = points[a, 0] - points[e, 0]
    ay = points[a, 1] - points[e, 1]
    az = points[a, 2] - points[e, 2]
    bx = points[b, 0] - points[e, 0]
    by = points[b, 1] - points[e, 1]
    bz = points[b, 2] - points[e, 2]
    cx = points[c, 0] - points[e, 0]
    cy = points[c, 1] - points[e, 1]
    cz = points[c, 2] - points[e, 2]
    dx = points[d, 0] - points[e, 0]
    dy = points[d, 1] - points[e, 1]
    dz = points[d, 2] - points[e, 2]
    ab = ax * by - bx * ay
    bc = bx * cy - cx * by
    cd = cx * dy - dx * cy
    da = dx * ay - ax * dy
    ac = ax * cy - cx * ay
    bd = bx * dy - dx * by
    abc = az * bc - bz * ac + cz * ab
    bcd = bz * cd - cz * bd + dz * bc
    cda = cz * da + dz * ac + az * cd
    dab = dz * ab + az * bd + bz * da
    alift = ax * ax + ay * ay + az * az
    blift = bx * bx + by * by + bz * bz
    clift = cx * cx + cy * cy + cz * cz
    dlift = dx * dx + dy * dy + dz * dz
    # Shewchuk's insphere determinant, whose orientation convention is the opposite of ours
    return (alift * bcd - blift * cda) + (clift * dab - dlift * abc)


@numba.njit(cache=True, inline="always")
def _orient_replaced(points, tets, t, k, p):
    """Orientation of cell ``t`` with its corner ``k`` replaced by point ``p``."""
    v0 = p if k == 0 else tets[t, 0]
    v1 = p if k == 1 else tets[t, 1]
    v2 = p if k == 2 else tets[t, 2]
    v3 = p if k == 3 else tets[t, 3]
    return _orient(points, v0, v1, v2, v3)


@numba.njit(cache=True)
def _grown(array, size, fill):
    out = np.full((size,) + array.shape[1:], fill, dtype=array.dtype)
    out[: array.shape[0]] = array
    return out


@numba.njit(cache=True)
def _bowyer_watson(points, order):
    """Delaunay tetrahedra of ``points[:-4]`` inserted in ``order``; ``points[-4:]`` enclose them all.

    Returns ``(status, cells, neighbors, duplicate_of)``: positively oriented
    cells of the real points (those touching the enclosing tetrahedron
    dropped), ``neighbors[c, k]`` the cell across the face opposite corner
    ``k`` (-1 where none is kept), and for each point the vertex it
    coincides with exactly (-1 for vertices).
    """
    n_all = points.shape[0]
    n = n_all - 4
    capacity = 7 * n + 64
    tets = np.empty((capacity, 4), dtype=np.int64)
    neighbors = np.full((capacity, 4), -1, dtype=np.int64)
    alive = np.zeros(capacity, dtype=np.bool_)
    stamp = np.full(capacity, -1, dtype=np.int64)
    free = np.empty(capacity, dtype=np.int64)
    n_free = 0
    n_used = 1
    tets[0, 0] = n
    tets[0, 1] = n + 1
    tets[0, 2] = n + 2
    tets[0, 3] = n + 3
    if _orient(points, n, n + 1, n + 2, n + 3) < 0:
        tets[0, 2] = n + 3
        tets[0, 3] = n + 2
    alive[0] = True
    cavity = np.empty(256, dtype=np.int64)
    stack = np.empty(256, dtype=np.int64)
    face_tet = np.empty(512, dtype=np.int64)
    face_corner = np.empty(512, dtype=np.int64)
    table_size = 4096
    table_key = np.full(table_size, -1, dtype=np.int64)
    table_value = np.empty(table_size, dtype=np.int64)
    table_stamp = np.full(table_size, -1, dtype=np.int64)
    duplicate_of = np.full(n, -1, dtype=np.int64)
    last = 0
    rotation = 0
    generator = 12345
    for step in range(order.shape[0]):
        p = order[step]
        # locate p by a visibility walk from the last new cell
        t = last
        walked = 0
        while True:
            moved = False
            for kk in range(4):
                k = (kk + rotation) & 3
                if _orient_replaced(points, tets, t, k, p) < 0.0:
                    t = neighbors[t, k]
                    moved = True
                    break
            # the face tried first follows a pseudo-random sequence, so that the walk cannot cycle
            generator = (generator * 1103515245 + 12345) & 0x7FFFFFFF
            rotation = (generator >> 16) & 3
            if not moved:
                break
            walked += 1
            if walked > 1000 or t < 0:
                # rounding made the walk cycle (nearly coplanar points): search every cell
                t = -1
                best = -np.inf
                for c in range(n_used):
                    if not alive[c]:
                        continue
                    worst = np.inf
                    for k in range(4):
                        worst = min(worst, _orient_replaced(points, tets, c, k, p))
                    if worst > best:
                        best = worst
                        t = c
                    if worst >= 0.0:
                        break
                if t < 0:
                    return _WALK_FAILED, tets[:0], neighbors[:0], duplicate_of
                break
        duplicate = -1
        for k in range(4):
            v = tets[t, k]
            if points[v, 0] == points[p, 0] and points[v, 1] == points[p, 1] and points[v, 2] == points[p, 2]:
                duplicate = v
        if duplicate >= 0:
            duplicate_of[p] = duplicate
            continue
        # the cavity: cells whose circumsphere holds p, connected to the one containing it
        n_cavity = 1
        cavity[0] = t
        stamp[t] = step
        n_stack = 1
        stack[0] = t
        while n_stack > 0:
            n_stack -= 1
            c = stack[n_stack]
            for k in range(4):
                o = neighbors[c, k]
                if o >= 0 and stamp[o] != step:
                    if _insphere(points, tets[o, 0], tets[o, 1], tets[o, 2], tets[o, 3], p) > 0.0:
                        stamp[o] = step
                        if n_cavity == cavity.shape[0]:
                            cavity = _grown(cavity, 2 * n_cavity, -1)
                            stack = _grown(stack, 2 * n_cavity, -1)
                        cavity[n_cavity] = o
                        n_cavity += 1
                        stack[n_stack] = o
                        n_stack += 1
        # p must see every cavity face from inside (rounding can break that): grow the cavity until it does
        while True:
            n_faces = 0
            grown = False
            for ci in range(n_cavity):
                c = cavity[ci]
                for k in range(4):
                    o = neighbors[c, k]
                    if o >= 0 and stamp[o] == step:
                        continue
                    if _orient_replaced(points, tets, c, k, p) <= 0.0:
                        if o < 0:
                            return _CAVITY_FAILED, tets[:0], neighbors[:0], duplicate_of
                        stamp[o] = step
                        if n_cavity == cavity.shape[0]:
                            cavity = _grown(cavity, 2 * n_cavity, -1)
                            stack = _grown(stack, 2 * n_cavity, -1)
                        cavity[n_cavity] = o
                        n_cavity += 1
                        grown = True
                        continue
                    if n_faces == face_tet.shape[0]:
                        face_tet = _grown(face_tet, 2 * n_faces, -1)
                        face_corner = _grown(face_corner, 2 * n_faces, -1)
                    face_tet[n_faces] = c
                    face_corner[n_faces] = k
                    n_faces += 1
            if not grown:
                break
        # new cells: p joined to every cavity face; faces through p are matched by their other edge
        if 6 * n_faces > table_size:
            while 6 * n_faces > table_size:
                table_size *= 2
            table_key = np.full(table_size, -1, dtype=np.int64)
            table_value = np.empty(table_size, dtype=np.int64)
            table_stamp = np.full(table_size, -1, dtype=np.int64)
        mask = table_size - 1
        for f in range(n_faces):
            if n_free > 0:
                n_free -= 1
                nt = free[n_free]
            else:
                if n_used == tets.shape[0]:
                    size = 2 * tets.shape[0]
                    tets = _grown(tets, size, -1)
                    neighbors = _grown(neighbors, size, -1)
                    alive = _grown(alive, size, False)
                    stamp = _grown(stamp, size, -1)
                    free = _grown(free, size, -1)
                nt = n_used
                n_used += 1
            c = face_tet[f]
            k = face_corner[f]
            for j in range(4):
                tets[nt, j] = tets[c, j]
            tets[nt, k] = p
            alive[nt] = True
            stamp[nt] = -1
            o = neighbors[c, k]
            neighbors[nt, k] = o
            if o >= 0:
                for j in range(4):
                    if neighbors[o, j] == c:
                        neighbors[o, j] = nt
            for i in range(4):
                if i == k:
                    continue
                u = -1
                w = -1
                for j in range(4):
                    if j != i and j != k:
                        if u < 0:
                            u = tets[nt, j]
                        else:
                            w = tets[nt, j]
                if u > w:
                    u, w = w, u
                key = u * n_all + w
                h = (key * 2654435761) & mask
                while True:
                    if table_stamp[h] != step:
                        table_stamp[h] = step
                        table_key[h] = key
                        table_value[h] = 4 * nt + i
                        break
                    if table_key[h] == key:
                        other = table_value[h] >> 2
                        slot = table_value[h] & 3
                        neighbors[nt, i] = other
                        neighbors[other, slot] = nt
                        break
                    h = (h + 1) & mask
            last = nt
        for ci in range(n_cavity):
            c = cavity[ci]
            alive[c] = False
            free[n_free] = c
            n_free += 1
    renumber = np.full(n_used, -1, dtype=np.int64)
    count = 0
    for t in range(n_used):
        if alive[t] and tets[t, 0] < n and tets[t, 1] < n and tets[t, 2] < n and tets[t, 3] < n:
            renumber[t] = count
            count += 1
    cells = np.empty((count, 4), dtype=np.int64)
    cell_neighbors = np.empty((count, 4), dtype=np.int64)
    for t in range(n_used):
        r = renumber[t]
        if r >= 0:
            for j in range(4):
                cells[r, j] = tets[t, j]
                o = neighbors[t, j]
                cell_neighbors[r, j] = renumber[o] if o >= 0 else -1
    return _OK, cells, cell_neighbors, duplicate_of


def _spread_bits(x):
    x = (x | (x << 16)) & 0x30000FF
    x = (x | (x << 8)) & 0x300F00F
    x = (x | (x << 4)) & 0x30C30C3
    return (x | (x << 2)) & 0x9249249


def _morton_order(points):
    """Permutation of ``points`` (n, 3) along a Z-order curve on a 1024**3 grid over their box."""
    low = points.min(axis=0)
    span = max(float((points.max(axis=0) - low).max()), 1e-300)
    q = np.minimum(((points - low) * (1024.0 / span)).astype(np.int64), 1023)
    key = _spread_bits(q[:, 0]) | (_spread_bits(q[:, 1]) << 1) | (_spread_bits(q[:, 2]) << 2)
    return np.argsort(key, kind="stable")


def _qhull(points):
    """Qhull's Delaunay cells and neighbours, reoriented positively (the fallback)."""
    from scipy.spatial import Delaunay

    triangulation = Delaunay(points)
    cells = triangulation.simplices.astype(np.int64)
    neighbors = triangulation.neighbors.astype(np.int64)
    a, b, c, d = (points[cells[:, k]] for k in range(4))
    negative = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) < 0
    cells[negative] = cells[negative][:, [0, 1, 3, 2]]
    neighbors[negative] = neighbors[negative][:, [0, 1, 3, 2]]
    return cells, neighbors


def delaunay_3d(points, *, return_duplicates=False):
    """Delaunay tetrahedralisation of a 3D point set, positively oriented, with the cell adjacency.

    Incremental Bowyer-Watson insertion along a Z-order curve with
    floating-point predicates; the cavity of each point is grown until the
    point sees all its faces, so the result is a valid tetrahedralisation
    even where rounding misjudges near-cospherical points (there it may be
    only nearly Delaunay). Points are first scaled to the unit box. Should
    the kernel fail, SciPy's Qhull is used instead.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Coordinates, any units; not modified. At least four, not coplanar.
    return_duplicates : bool, optional
        Also return, for each point, the index of the vertex it coincides
        with exactly (-1 for vertices); duplicates are left out of the cells.

    Returns
    -------
    cells : numpy.ndarray, shape (m, 4), int64
        Vertex indices with ``(b - a) . ((c - a) x (d - a)) > 0``.
    neighbors : numpy.ndarray, shape (m, 4), int64
        ``neighbors[c, k]``: the cell across the face opposite corner ``k``,
        -1 on the hull.
    duplicate_of : numpy.ndarray, shape (n,), int64
        Only with ``return_duplicates``.

    Raises
    ------
    GenerationError
        For fewer than four points, non-finite coordinates or coplanar points.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.spatial import ConvexHull
    >>> points = np.random.default_rng(0).random((100, 3))
    >>> cells, neighbors = delaunay_3d(points)
    >>> a, b, c, d = (points[cells[:, k]] for k in range(4))
    >>> volumes = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6
    >>> bool(np.all(volumes > 0)), bool(np.isclose(volumes.sum(), ConvexHull(points).volume))
    (True, True)
    """
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise GenerationError(f"points must have shape (n, 3), got {points.shape}")
    if not np.all(np.isfinite(points)):
        raise GenerationError("points must be finite (found NaN or infinity)")
    if len(points) < 4:
        raise GenerationError(f"cannot tetrahedralise {len(points)} points: the domain is too small for the mesh size")
    low, high = points.min(axis=0), points.max(axis=0)
    extent = float((high - low).max())
    if extent == 0.0:
        raise GenerationError("the points to tetrahedralise do not span a volume: all points coincide")
    center = 0.5 * (low + high)
    scaled = (points - center) / extent
    enclosing = ENCLOSING_SCALE * np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])
    status, cells, neighbors, duplicate_of = _bowyer_watson(np.vstack([scaled, enclosing]), _morton_order(scaled))
    if status != _OK or len(cells) == 0:
        try:
            cells, neighbors = _qhull(points)
        except Exception as error:  # Qhull raises its own QhullError for flat input
            raise GenerationError(f"the points to tetrahedralise do not span a volume: {error}") from error
        # Qhull keeps one point of each run of equal points (which one is its choice): the others map to it
        duplicate_of = np.full(len(points), -1, dtype=np.int64)
        used = np.zeros(len(points), dtype=bool)
        used[cells.ravel()] = True
        order = np.lexsort(points.T[::-1])
        run = np.cumsum(np.append(True, np.any(points[order[1:]] != points[order[:-1]], axis=1)))
        kept = np.full(run[-1] + 1, -1, dtype=np.int64)
        kept[run[used[order]]] = order[used[order]]
        duplicate_of[order] = np.where(used[order], -1, kept[run])
    if return_duplicates:
        return cells, neighbors, duplicate_of
    return cells, neighbors


# --- connectivity kernels ------------------------------------------------------------------------


@numba.njit(cache=True)
def _incidence(cells, n_points):
    """The cells (or faces) around each vertex, compressed: ``around[start[v]:start[v + 1]]``."""
    m, corners = cells.shape
    start = np.zeros(n_points + 1, dtype=np.int64)
    for t in range(m):
        for k in range(corners):
            start[cells[t, k] + 1] += 1
    for v in range(n_points):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    around = np.empty(corners * m, dtype=np.int64)
    for t in range(m):
        for k in range(corners):
            around[fill[cells[t, k]]] = t
            fill[cells[t, k]] += 1
    return start, around


@numba.njit(cache=True)
def _unique_edges(cells, n_points):
    """Every edge of the cells once, as (e, 2) vertex pairs ``(a, b)`` with ``a < b``, ordered by ``a``.

    Through the cells around each vertex, with a stamp per vertex instead
    of sorting.
    """
    m = cells.shape[0]
    start, around = _incidence(cells, n_points)
    stamp = np.full(n_points, -1, dtype=np.int64)
    edges = np.empty((3 * m + n_points, 2), dtype=np.int64)  # at most 6 m / 2 + ... edges; grown if not
    count = 0
    for v in range(n_points):
        for i in range(start[v], start[v + 1]):
            t = around[i]
            for k in range(4):
                u = cells[t, k]
                if u > v and stamp[u] != v:
                    stamp[u] = v
                    if count == edges.shape[0]:
                        edges = _grown(edges, 2 * count, -1)
                    edges[count, 0] = v
                    edges[count, 1] = u
                    count += 1
    return edges[:count].copy()


@numba.njit(cache=True)
def _tets_surely_inside(points, cells, distance_bound, tolerance):
    """Cells whose centroid is certainly deeper than ``tolerance``, from upper bounds of a 1-Lipschitz distance."""
    m = cells.shape[0]
    sure = np.zeros(m, dtype=np.bool_)
    for t in range(m):
        bound = -np.inf
        longest2 = 0.0
        for i in range(4):
            a = cells[t, i]
            if distance_bound[a] > bound:
                bound = distance_bound[a]
            for j in range(i + 1, 4):
                b = cells[t, j]
                length2 = 0.0
                for d in range(3):
                    delta = points[a, d] - points[b, d]
                    length2 += delta * delta
                if length2 > longest2:
                    longest2 = length2
        sure[t] = bound + np.sqrt(longest2) < -tolerance
    return sure


@numba.njit(cache=True)
def _quality_mean_std(points, cells):
    """Mean and standard deviation of ``6 sqrt(2) V / l_rms**3`` (1 for a regular tetrahedron)."""
    m = cells.shape[0]
    total = 0.0
    total2 = 0.0
    factor = 6.0 * np.sqrt(2.0) / 6.0
    for t in range(m):
        a = cells[t, 0]
        squares = 0.0
        for i in range(3):
            for j in range(i + 1, 4):
                for d in range(3):
                    delta = points[cells[t, i], d] - points[cells[t, j], d]
                    squares += delta * delta
        six_volume = _orient(points, a, cells[t, 1], cells[t, 2], cells[t, 3])
        rms = np.sqrt(squares / 6.0)
        q = factor * six_volume / (rms * rms * rms) if rms > 0.0 else 0.0
        total += q
        total2 += q * q
    mean = total / max(m, 1)
    return mean, np.sqrt(max(total2 / max(m, 1) - mean * mean, 0.0))


# --- sharp edges: sampled once and fixed -----------------------------------------------------------


def _sharp_edges(domain):
    """The domain's sharp edges as parametric curves (see ``Box.sharp_edges``, ``Union.sharp_edges``).

    A domain made of ``domains`` that reports none of its own: its operands'.
    """
    own = getattr(domain, "sharp_edges", None)
    if callable(own):
        return list(own())
    return [edge for operand in getattr(domain, "domains", ()) for edge in _sharp_edges(operand)]


def _sharp_edge_chains(domain, size, h0):
    """Points along each of the domain's sharp edges, spaced by the size function, ends included; a list of (m, 3).

    Each edge gets ``round(integral of ds / h)`` segments (at least one) of
    equal integral: the trapezoidal rule on EDGE_SAMPLING points per h0 of
    length. A curve marked ``closed`` (a circle) repeats its first point at
    the end; one of fewer than three segments is left out, as no three
    points can hold it.
    """
    edges = _sharp_edges(domain)
    if not edges:
        return []
    params, dense = [], []
    for curve in edges:
        coarse = curve(np.linspace(0.0, 1.0, 65))
        length = float(np.sum(np.sqrt(np.sum(np.diff(coarse, axis=0) ** 2, axis=1))))
        t = np.linspace(0.0, 1.0, int(np.clip(np.ceil(EDGE_SAMPLING * length / h0), 64, 1 << 16)) + 1)
        params.append(t)
        dense.append(curve(t))
    density = 1.0 / size(np.concatenate(dense))
    chains, start = [], 0
    for curve, t, points in zip(edges, params, dense, strict=True):
        w = density[start : start + len(t)]
        start += len(t)
        steps = np.sqrt(np.sum(np.diff(points, axis=0) ** 2, axis=1))
        cumulative = np.concatenate([[0.0], np.cumsum(steps * 0.5 * (w[1:] + w[:-1]))])
        total = cumulative[-1]
        segments = max(1, int(round(total)))
        closed = getattr(curve, "closed", False)
        if closed and segments < 3:
            continue
        chain = curve(np.interp(total * np.arange(segments + 1) / segments, cumulative, t))
        if closed:
            chain[-1] = chain[0]
        chains.append(chain)
    return chains


def _sharp_edge_points(domain, size, h0, bbox, tolerance, chains=None):
    """Points along the domain's sharp edges, spaced by the size function, their ends left out; shape (k, 3).

    See :func:`_sharp_edge_chains` (``chains``, if already made); a closed
    curve has no ends to leave out. Only the points on the domain's
    boundary are kept, and of points closer than half the local size to
    one another only the first.
    """
    if chains is None:
        chains = _sharp_edge_chains(domain, size, h0)
    samples = [chain[:-1] if np.array_equal(chain[0], chain[-1]) else chain[1:-1] for chain in chains]
    samples = [sample for sample in samples if len(sample)]
    if not samples:
        return np.empty((0, 3))
    samples = np.concatenate(samples)
    samples = samples[np.all((samples >= bbox[0]) & (samples <= bbox[1]), axis=1)]
    samples = samples[np.abs(domain.distance(samples)) <= tolerance]
    return _spread_corners(samples, np.empty((0, 3)), size)


def _edge_balls(domain, chains, tolerance):
    """Centres and radii of the balls on the segments of the chains that lie on the boundary; (k, 3), (k,).

    A segment between consecutive edge points is an edge of the Delaunay
    tetrahedralisation when no other point lies in the ball it is the
    diameter of. A free point there (a point pushed close to the edge)
    lets cells bridge the edge: across a re-entrant edge they then cover
    part of the outside with their centroid inside.
    """
    if not chains:
        return np.empty((0, 3)), np.empty(0)
    starts = np.concatenate([chain[:-1] for chain in chains])
    ends = np.concatenate([chain[1:] for chain in chains])
    on = (np.abs(domain.distance(starts)) <= tolerance) & (np.abs(domain.distance(ends)) <= tolerance)
    centres = 0.5 * (starts[on] + ends[on])
    return centres, 0.5 * np.sqrt(np.sum((ends[on] - starts[on]) ** 2, axis=1))


def _encroaching(points, n_fixed, centres, radii):
    """Mask of the points after the first ``n_fixed`` strictly inside one of the balls (see :func:`_edge_balls`)."""
    mask = np.zeros(len(points), dtype=bool)
    if len(centres) == 0 or len(points) == n_fixed:
        return mask
    from scipy.spatial import cKDTree

    inside = cKDTree(points[n_fixed:]).query_ball_point(centres, radii * (EDGE_BALL - 1e-9))
    hits = [index for ball in inside for index in ball]
    mask[n_fixed + np.asarray(hits, dtype=np.int64)] = True
    return mask


def _with_sharp_edges(domain, size, h0, bbox, tolerance, points, n_fixed, chains=None):
    """``points`` with fixed points along the domain's sharp edges after the first ``n_fixed``; the new count.

    Force equilibrium has no hold on a sharp edge: a point there that any
    force pushes into one face's side is projected onto the other face, so
    edges lose their points and the final cells cut across them. Fixed
    points spaced by the size, as the corners are, keep the edges in the mesh.
    Edge points within half the local size of a fixed point, and lattice
    points within half the local size of an edge point, are left out.
    """
    from scipy.spatial import cKDTree

    edge = _sharp_edge_points(domain, size, h0, bbox, tolerance, chains)
    if n_fixed and len(edge):
        edge = edge[cKDTree(points[:n_fixed]).query(edge)[0] >= 0.5 * size(edge)]
    if len(edge) == 0:
        return points, n_fixed
    reach = 0.5 * size(edge)
    free = points[n_fixed:]
    distance, nearest = cKDTree(edge).query(free, distance_upper_bound=float(reach.max()))
    near = distance < np.append(reach, 0.0)[nearest]  # nearest == len(edge) where none is within the bound
    return np.vstack([points[:n_fixed], edge, free[~near]]), n_fixed + len(edge)


# --- the driver ------------------------------------------------------------------------------------


def _distance_gradient(domain, points, distance, step):
    """Forward-difference gradient of the signed distance, shape (n, 3); ``step`` a number or one per point."""
    gradient = np.empty_like(points)
    for axis in range(3):
        shifted = points.copy()
        shifted[:, axis] += step
        gradient[:, axis] = (domain.distance(shifted) - distance) / step
    return gradient


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
    landed = LANDED * np.max(np.abs(points), axis=1)
    active = np.flatnonzero(np.abs(distance) > landed)
    for _ in range(newton_steps):
        if len(active) == 0:
            break
        where, off = points[active], distance[active]
        local_step = np.clip(0.25 * np.abs(off), 4.0 * landed[active], step)
        gradient = _distance_gradient(domain, where, off, local_step)
        norm2 = np.sum(gradient**2, axis=1)
        norm2[norm2 == 0] = 1.0
        points[active] = where - (off / norm2)[:, None] * gradient
        distance[active] = domain.distance(points[active])
        active = active[np.abs(distance[active]) > landed[active]]
    return points


def _inside_cells(domain, points, cells, tolerance, distance_bound=None):
    """Mask of the cells whose centroid lies inside the domain by more than ``tolerance``."""
    inside = (
        np.zeros(len(cells), dtype=bool)
        if distance_bound is None
        else _tets_surely_inside(points, cells, distance_bound, tolerance)
    )
    unsure = np.flatnonzero(~inside)
    centroids = points[cells[unsure]].mean(axis=1)
    inside[unsure] = domain.distance(centroids) < -tolerance
    return inside


def _duplicates(points):
    """Points that coincide exactly with a point of lower index (kept), as a boolean mask."""
    order = np.lexsort(points.T[::-1])
    same = np.all(points[order[1:]] == points[order[:-1]], axis=1)
    doomed = np.zeros(len(points), dtype=bool)
    doomed[np.maximum(order[1:], order[:-1])[same]] = True
    return doomed


def _tetrahedralise(domain, points, tolerance, distance_bound=None, *, edges=True):
    """Delaunay cells with their centroid inside, their neighbours (renumbered), and their unique edges.

    The points must be distinct (see :func:`_duplicates`).
    """
    cells, neighbors = delaunay_3d(points)
    inside = _inside_cells(domain, points, cells, tolerance, distance_bound)
    renumber = np.append(np.where(inside, np.cumsum(inside) - 1, -1), -1)
    cells, neighbors = cells[inside], renumber[neighbors[inside]]
    return cells, neighbors, _unique_edges(cells, len(points)) if edges else None


def _without_long_edges(points, edges, target):
    """The edges not longer than LONG_EDGE times the median length-to-size ratio.

    Nearly coplanar boundary points (a flat face of the domain) give
    Delaunay cells that reach across the domain. Their long edges exert no
    force (springs only push), but they would inflate the sum of squared
    lengths that scales every rest length, and so the pressure on all points.
    """
    lengths = np.sqrt(np.sum((points[edges[:, 0]] - points[edges[:, 1]]) ** 2, axis=1))
    ratio = lengths / (0.5 * (target[edges[:, 0]] + target[edges[:, 1]]))
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


def _finite_difference_step(h0, bbox):
    """Step of the finite differences of the distance function for the Newton projections.

    The distance carries a rounding error of eps times the coordinates
    (large in UTM or Mercator metres) and a truncation error of the step over
    the boundary's curvature radius (about h0 or more); this step balances
    the two.
    """
    return float(np.sqrt(np.finfo(float).eps * h0 * max(h0, float(np.abs(bbox).max()))))


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
        edges (a box's twelve; of a CSG combination, the operands' edges
        where they stay on its boundary and the edges it creates where
        operands meet, see ``Union.sharp_edges``), spaced by the size.
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

    Returns
    -------
    Mesh
        Valid tetrahedral mesh: positively oriented cells
        (``(b - a) . ((c - a) x (d - a)) > 0``), no unused vertices, a
        manifold boundary whose vertices lie within ``1e-3 h0`` of the domain
        boundary (on it to rounding where the domain has an exact
        ``project``, as a box has: its edges are followed by mesh edges, its
        faces by boundary faces), and every cell's smallest dihedral angle
        at least 10 degrees (sliver removal aims at 15). ``mesh.info`` holds
        ``iterations``, ``stop_reason`` (``"converged"``, ``"stalled"`` or
        ``"max_iter"``), ``max_move``, ``retriangulations``, ``seconds``,
        ``h0``, ``force_seconds``, and for the final clean-up
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
    started = time.perf_counter()
    domain = as_domain(domain, bbox)
    if domain.dim != 3:
        raise GenerationError(f"generate_mesh_3d needs a 3D domain, got dim={domain.dim}")
    bbox = domain.bbox if bbox is None else as_bbox(bbox, dim=3)
    size, h0, tolerance, points, n_fixed = _initial_points(
        domain, edge_length, h0, bbox, fixed_points, max_iter, seed, bcc_seed_points
    )
    chains = _sharp_edge_chains(domain, size, h0)
    points, n_fixed = _with_sharp_edges(domain, size, h0, bbox, tolerance, points, n_fixed, chains)
    edge_balls = _edge_balls(domain, chains, tolerance)
    # Z-order numbering: neighbours in space are near in memory (every kernel below walks neighbours)
    points = np.vstack([points[:n_fixed], points[n_fixed:][_morton_order(points[n_fixed:])]])
    if len(points) < 4:
        raise GenerationError(f"only {len(points)} points fit in the domain: h0={h0:g} is too large for it")
    points = np.ascontiguousarray(points)
    target = size(points)
    last_triangulated = np.full_like(points, np.inf)
    finite_step = _finite_difference_step(h0, bbox)
    retriangulations, max_move, last_log, scores, last_fresh = 0, np.inf, started, [], 0
    stop_reason = "max_iter"
    lazy_distance = _LazyDistance(domain)

    for iteration in range(1, int(max_iter) + 1):
        fresh = iteration - last_fresh >= MAX_STALE_ITERATIONS or count_far(
            points, last_triangulated, target, RETRIANGULATE_AFTER
        ) > STALE_ALLOWED * len(points)
        if fresh:
            doomed = _duplicates(points)  # two points projected onto the same corner, say
            if doomed.any():
                points, target, last_triangulated = points[~doomed], target[~doomed], last_triangulated[~doomed]
            bound = lazy_distance.upper_bound(len(points))
            cells, _, edges = _tetrahedralise(domain, points, tolerance, bound)
            edges = _without_long_edges(points, edges, target)
            last_triangulated = points.copy()
            last_fresh = iteration
            retriangulations += 1
        points, move = force_step(points, edges, target, LENGTH_FACTOR, TIME_STEP, n_fixed)
        distance = lazy_distance.update(points, move, target)
        outside = distance > 0
        if outside.any():
            points[outside] = _project_to_boundary(
                domain, points[outside], distance[outside], finite_step, newton_steps=1
            )
        target = size(points)
        max_move = largest_interior_move(move, target, distance, tolerance)
        if fresh:
            # cells with all four corners on the boundary (flat ones along a cylinder's side) are peeled at the end
            on_boundary = distance >= -tolerance
            mean, std = _quality_mean_std(points, cells[~np.all(on_boundary[cells], axis=1)])
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

    forces_done = time.perf_counter()
    mesh = _finalize(domain, size, points, n_fixed, tolerance, finite_step, edge_balls)
    mesh.info.update(
        iterations=iteration,
        stop_reason=stop_reason,
        max_move=max_move,
        retriangulations=retriangulations,
        seconds=time.perf_counter() - started,
        h0=h0,
        force_seconds=forces_done - started,
    )
    logger.info(
        "stopped after %d iterations (%s): %d vertices, %d cells, min dihedral %.1f degrees in %.2f s",
        iteration,
        stop_reason,
        mesh.n_points,
        mesh.n_cells,
        mesh.info["min_dihedral"],
        mesh.info["seconds"],
    )
    if stop_reason == "max_iter":
        warnings.warn(
            f"mesh generation reached max_iter={max_iter} before points stopped moving "
            f"(largest move {max_move:.2e} of the local size, tolerance {move_tolerance:g})",
            TerrameshWarning,
            stacklevel=2,
        )
    return mesh


# --- sliver removal: flips, vertex perturbation, flat boundary cells ----------------------------------
#
# The mesh is held as ``tets`` (capacity, 4) positively oriented, ``neighbors`` (capacity, 4) with the
# cell across the face opposite each corner (-1 on the boundary), ``alive`` flags, a free list, and
# ``vertex_tet``: one live cell at each vertex (-1 for an unused vertex). Every change goes through
# ``_replace_cells`` or ``_delete_cell``, which keep all of it consistent.

_MAX_RING = 7  # largest number of cells around an edge that edge removal tries
_MAX_STAR = 512


_INVALID = -3.0  # the quality of a cell that is not positively oriented
# boundary faces whose normals are this close to opposite are folded onto each other, not two sides of an edge
_FOLDED = -np.cos(np.radians(MIN_DIHEDRAL))


@numba.njit(cache=True)
def _quality(points, a, b, c, d):
    """Minus the cosine of the smallest dihedral angle (rises with the angle, -1 to 0.5); _INVALID if not positive."""
    cosine = _tet_largest_cosine(points, a, b, c, d)
    return _INVALID if cosine > 1.0 else -cosine


def _aim(degrees):
    return -np.cos(np.radians(degrees))


@numba.njit(cache=True)
def _sorted3(a, b, c):
    if a > b:
        a, b = b, a
    if b > c:
        b, c = c, b
    if a > b:
        a, b = b, a
    return a, b, c


@numba.njit(cache=True)
def _face_of(tets, t, k):
    """Sorted vertices of the face of cell ``t`` opposite corner ``k``."""
    a = tets[t, (k + 1) & 3]
    b = tets[t, (k + 2) & 3]
    c = tets[t, (k + 3) & 3]
    return _sorted3(a, b, c)


@numba.njit(cache=True)
def _allocate(tets, alive, free, state):
    """A free cell slot (state[0]: slots used, state[1]: free-list length); -1 when full."""
    if state[1] > 0:
        state[1] -= 1
        return free[state[1]]
    if state[0] < tets.shape[0]:
        state[0] += 1
        return state[0] - 1
    return -1


@numba.njit(cache=True)
def _replace_cells(tets, neighbors, alive, vertex_tet, free, state, old, n_old, new, n_new):
    """Replace cells ``old[:n_old]`` by ``new[:n_new]`` (vertex quadruples) filling the same region.

    Faces of the new cells are linked to each other and to the cells around
    the old ones by their vertex sets. Returns False (nothing changed) when
    the slots run out or a new face has no partner or more than one (the
    new cells would not fill the region as a manifold).
    """
    n_outer = 0
    outer_face = np.empty((4 * n_old, 3), dtype=np.int64)
    outer_cell = np.empty(4 * n_old, dtype=np.int64)
    for i in range(n_old):
        t = old[i]
        for k in range(4):
            o = neighbors[t, k]
            internal = False
            for j in range(n_old):
                if old[j] == o:
                    internal = True
            if not internal:
                x, y, z = _face_of(tets, t, k)
                outer_face[n_outer, 0] = x
                outer_face[n_outer, 1] = y
                outer_face[n_outer, 2] = z
                outer_cell[n_outer] = o
                n_outer += 1
    ids = np.empty(n_new, dtype=np.int64)
    for j in range(n_new):
        if j < n_old:
            ids[j] = old[j]
        else:
            ids[j] = _allocate(tets, alive, free, state)
            if ids[j] < 0:
                for i in range(n_old, j):  # give back what was taken
                    free[state[1]] = ids[i]
                    state[1] += 1
                return False
    # check every new face has a partner before writing anything
    partner = np.full((n_new, 4), -2, dtype=np.int64)  # >= 0: new cell index j2 * 4 + k2; -1 - i: outer face i
    for j in range(n_new):
        for k in range(4):
            x, y, z = _sorted3(new[j, (k + 1) & 3], new[j, (k + 2) & 3], new[j, (k + 3) & 3])
            found = 0
            for j2 in range(n_new):
                if j2 == j:
                    continue
                for k2 in range(4):
                    x2, y2, z2 = _sorted3(new[j2, (k2 + 1) & 3], new[j2, (k2 + 2) & 3], new[j2, (k2 + 3) & 3])
                    if x == x2 and y == y2 and z == z2:
                        partner[j, k] = 4 * j2 + k2
                        found += 1
            for i in range(n_outer):
                if outer_face[i, 0] == x and outer_face[i, 1] == y and outer_face[i, 2] == z:
                    partner[j, k] = -1 - i
                    found += 1
            if found != 1:  # no partner, or a face in three cells: not a valid replacement
                for i in range(n_new - n_old):
                    free[state[1]] = ids[n_old + i]
                    state[1] += 1
                return False
    for j in range(n_new):
        t = ids[j]
        for k in range(4):
            tets[t, k] = new[j, k]
        alive[t] = True
    for j in range(n_new):
        t = ids[j]
        for k in range(4):
            p = partner[j, k]
            if p >= 0:
                neighbors[t, k] = ids[p >> 2]
            else:
                o = outer_cell[-1 - p]
                neighbors[t, k] = o
                if o >= 0:
                    x, y, z = _sorted3(tets[t, (k + 1) & 3], tets[t, (k + 2) & 3], tets[t, (k + 3) & 3])
                    for k2 in range(4):
                        x2, y2, z2 = _face_of(tets, o, k2)
                        if x == x2 and y == y2 and z == z2:
                            neighbors[o, k2] = t
        for k in range(4):
            vertex_tet[tets[t, k]] = t
    for i in range(n_new, n_old):
        t = old[i]
        alive[t] = False
        free[state[1]] = t
        state[1] += 1
    return True


@numba.njit(cache=True)
def _edge_ring(tets, neighbors, t0, a, b, ring_cells, ring_vertices):
    """Cells and vertices around the edge ``a b`` of cell ``t0``, in order; -1 for a boundary or crowded edge.

    ``ring_cells[i]`` holds ``a, b, ring_vertices[i], ring_vertices[i + 1]`` (cyclically).
    """
    x = -1
    y = -1
    for k in range(4):
        v = tets[t0, k]
        if v != a and v != b:
            if x < 0:
                x = v
            else:
                y = v
    previous = x
    following = y
    current = t0
    count = 0
    while True:
        if count == ring_cells.shape[0]:
            return -1
        ring_cells[count] = current
        ring_vertices[count] = previous
        count += 1
        k = 0
        while tets[current, k] != previous:
            k += 1
        nxt = neighbors[current, k]
        if nxt < 0:
            return -1
        if nxt == t0:
            return count
        z = -1
        for k in range(4):
            v = tets[nxt, k]
            if v != a and v != b and v != following:
                z = v
        previous = following
        following = z
        current = nxt


@numba.njit(cache=True)
def _pair_quality(points, a, b, r0, r1, r2, sense):
    """Smaller quality of the cells joining triangle ``r0 r1 r2`` (in ring order) to ``a`` and to ``b``.

    ``sense`` is the sign of ``orient(a, b, r_i, r_i+1)`` along the ring: for
    -1, ``a`` lies on the positive side of the triangle taken in ring order
    and ``b`` on the negative side; for +1 the reverse. _INVALID when a
    cell is not positive.
    """
    if sense < 0:
        qa = _quality(points, r0, r1, r2, a)
        qb = _quality(points, r1, r0, r2, b)
    else:
        qa = _quality(points, r1, r0, r2, a)
        qb = _quality(points, r0, r1, r2, b)
    if qa == _INVALID or qb == _INVALID:
        return _INVALID
    return min(qa, qb)


@numba.njit(cache=True)
def _try_edge_removal(points, tets, neighbors, t0, a, b, ring_cells, ring_vertices, new, best, choice, stack):
    """Best retriangulation of the cells around edge ``a b`` (dynamic programming over the ring's triangulations).

    Returns ``(quality, n_ring, n_new)``: the new cells' smallest quality
    and how many old and new cells, with the new cells in ``new``;
    quality _INVALID when impossible.
    """
    n = _edge_ring(tets, neighbors, t0, a, b, ring_cells, ring_vertices)
    if n < 3:
        return _INVALID, 0, 0
    sense = 1.0 if _orient(points, a, b, ring_vertices[0], ring_vertices[1]) > 0.0 else -1.0
    for i in range(n):
        if _orient(points, a, b, ring_vertices[i], ring_vertices[(i + 1) % n]) * sense <= 0.0:
            return _INVALID, n, 0  # the ring is not consistently oriented (an inverted cell): no removal
    for i in range(n):
        for j in range(n):
            best[i, j] = _INVALID
            choice[i, j] = -1
    for i in range(n - 1):
        best[i, i + 1] = 1e300
    for length in range(2, n):
        for i in range(n - length):
            j = i + length
            for k in range(i + 1, j):
                value = min(best[i, k], best[k, j])
                if value <= best[i, j]:
                    continue
                value = min(
                    value, _pair_quality(points, a, b, ring_vertices[i], ring_vertices[k], ring_vertices[j], sense)
                )
                if value > best[i, j]:
                    best[i, j] = value
                    choice[i, j] = k
    quality = best[0, n - 1]
    if quality == _INVALID:
        return _INVALID, n, 0
    n_new = 0
    top = 1
    stack[0, 0] = 0
    stack[0, 1] = n - 1
    while top > 0:
        top -= 1
        i = stack[top, 0]
        j = stack[top, 1]
        if j - i < 2:
            continue
        k = choice[i, j]
        r0 = ring_vertices[i]
        r1 = ring_vertices[k]
        r2 = ring_vertices[j]
        if sense < 0:
            new[n_new, 0], new[n_new, 1], new[n_new, 2], new[n_new, 3] = r0, r1, r2, a
            new[n_new + 1, 0], new[n_new + 1, 1], new[n_new + 1, 2], new[n_new + 1, 3] = r1, r0, r2, b
        else:
            new[n_new, 0], new[n_new, 1], new[n_new, 2], new[n_new, 3] = r1, r0, r2, a
            new[n_new + 1, 0], new[n_new + 1, 1], new[n_new + 1, 2], new[n_new + 1, 3] = r0, r1, r2, b
        n_new += 2
        stack[top, 0] = i
        stack[top, 1] = k
        stack[top + 1, 0] = k
        stack[top + 1, 1] = j
        top += 2
    return quality, n, n_new


@numba.njit(cache=True)
def _try_face_flip(points, tets, neighbors, t, k, new):
    """The 2-3 flip of the face of ``t`` opposite corner ``k``: the three new cells' smallest quality, or _INVALID.

    The new cells are ``t`` with one corner of that face replaced by the
    apex ``e`` of the cell across; all three are positive exactly when the
    segment from ``t``'s apex to ``e`` crosses the face.
    """
    o = neighbors[t, k]
    if o < 0:
        return _INVALID
    e = -1
    for j in range(4):
        v = tets[o, j]
        if v != tets[t, 0] and v != tets[t, 1] and v != tets[t, 2] and v != tets[t, 3]:
            e = v
    quality = 1e300
    row = 0
    for j in range(4):
        if j == k:
            continue
        for i in range(4):
            new[row, i] = tets[t, i]
        new[row, j] = e
        quality = min(quality, _quality(points, new[row, 0], new[row, 1], new[row, 2], new[row, 3]))
        row += 1
    return quality


@numba.njit(cache=True)
def _flip_slivers(points, tets, neighbors, alive, vertex_tet, free, state, order, aim):
    """Improve each cell of ``order`` below quality ``aim`` by the best of edge removals and 2-3 flips around it.

    A change is made only when the smallest quality of the new cells exceeds
    that of the cells they replace. Returns the number of changes.
    """
    ring_cells = np.empty(_MAX_RING, dtype=np.int64)
    ring_vertices = np.empty(_MAX_RING, dtype=np.int64)
    best = np.empty((_MAX_RING, _MAX_RING))
    choice = np.empty((_MAX_RING, _MAX_RING), dtype=np.int64)
    stack = np.empty((2 * _MAX_RING, 2), dtype=np.int64)
    candidate = np.empty((2 * _MAX_RING, 4), dtype=np.int64)
    chosen = np.empty((2 * _MAX_RING, 4), dtype=np.int64)
    chosen_old = np.empty(_MAX_RING, dtype=np.int64)
    changes = 0
    for index in range(order.shape[0]):
        t = order[index]
        if not alive[t]:
            continue
        current = _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3])
        if current >= aim:
            continue
        best_gain = 0.0
        chosen_old_count = 0
        chosen_new_count = 0
        for i in range(3):
            for j in range(i + 1, 4):
                a = tets[t, i]
                b = tets[t, j]
                q, n_ring, n_new = _try_edge_removal(
                    points, tets, neighbors, t, a, b, ring_cells, ring_vertices, candidate, best, choice, stack
                )
                if q == _INVALID:
                    continue
                before = 1e300
                for r in range(n_ring):
                    c = ring_cells[r]
                    before = min(before, _quality(points, tets[c, 0], tets[c, 1], tets[c, 2], tets[c, 3]))
                if q - before > best_gain:
                    best_gain = q - before
                    chosen_old_count = n_ring
                    chosen_new_count = n_new
                    chosen_old[:n_ring] = ring_cells[:n_ring]
                    chosen[:n_new] = candidate[:n_new]
        for k in range(4):
            q = _try_face_flip(points, tets, neighbors, t, k, candidate)
            if q == _INVALID:
                continue
            o = neighbors[t, k]
            before = min(current, _quality(points, tets[o, 0], tets[o, 1], tets[o, 2], tets[o, 3]))
            if q - before > best_gain:
                best_gain = q - before
                chosen_old_count = 2
                chosen_new_count = 3
                chosen_old[0] = t
                chosen_old[1] = o
                chosen[:3] = candidate[:3]
        if chosen_new_count > 0:
            if _replace_cells(
                tets, neighbors, alive, vertex_tet, free, state, chosen_old, chosen_old_count, chosen, chosen_new_count
            ):
                changes += 1
    return changes


@numba.njit(cache=True, inline="always")
def _face_normal(points, tets, t, k):
    """First corner ``a`` of the face opposite corner ``k`` of ``t``, its normal (b - a) x (c - a) and its length."""
    a = tets[t, (k + 1) & 3]
    b = tets[t, (k + 2) & 3]
    c = tets[t, (k + 3) & 3]
    ux = points[b, 0] - points[a, 0]
    uy = points[b, 1] - points[a, 1]
    uz = points[b, 2] - points[a, 2]
    wx = points[c, 0] - points[a, 0]
    wy = points[c, 1] - points[a, 1]
    wz = points[c, 2] - points[a, 2]
    nx = uy * wz - uz * wy
    ny = uz * wx - ux * wz
    nz = ux * wy - uy * wx
    return a, nx, ny, nz, np.sqrt(nx * nx + ny * ny + nz * nz)


@numba.njit(cache=True)
def _star(tets, neighbors, vertex_tet, v, out, mark, stamp):
    """The cells around vertex ``v`` (breadth-first across the faces through ``v``); their count, -1 if too many."""
    t0 = vertex_tet[v]
    if t0 < 0:
        return 0
    count = 1
    out[0] = t0
    mark[t0] = stamp
    head = 0
    while head < count:
        t = out[head]
        head += 1
        for k in range(4):
            if tets[t, k] == v:
                continue
            o = neighbors[t, k]
            if o >= 0 and mark[o] != stamp:
                if count == out.shape[0]:
                    return -1
                mark[o] = stamp
                out[count] = o
                count += 1
    return count


@numba.njit(cache=True)
def _star_quality(points, tets, star, n_star, floor):
    """Smallest quality over the star; stops early (returning it) once at or below ``floor``."""
    worst = 1e300
    for s in range(n_star):
        t = star[s]
        q = _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3])
        if q < worst:
            worst = q
            if worst <= floor:
                return worst
    return worst


_DIRECTIONS = np.array(
    [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1) if (i, j, k) != (0, 0, 0)], dtype=np.float64
)
_DIRECTIONS /= np.sqrt(np.sum(_DIRECTIONS**2, axis=1))[:, None]
_STEPS = np.array([0.3, 0.15, 0.08, 0.04, 0.02])


@numba.njit(cache=True)
def _perturb_vertices(points, tets, neighbors, vertex_tet, vertices, movable, mark, state, directions, steps, aim):
    """Move each movable vertex to the candidate that most raises the smallest quality of its star.

    Vertices whose star is at ``aim`` already are skipped. Candidates: the
    vertex pushed away from the opposite face of each poor cell of its
    star, and along 26 fixed directions, at
    steps shrinking from 0.3 to 0.02 of the mean edge length at the vertex
    (a deterministic pattern search). A move is kept only if every cell
    stays positive and the star's smallest quality rises. Returns the
    number of vertices moved.
    """
    star = np.empty(_MAX_STAR, dtype=np.int64)
    star_quality = np.empty(_MAX_STAR)
    extra = np.empty((_MAX_STAR, 3))
    moved = 0
    for index in range(vertices.shape[0]):
        v = vertices[index]
        if not movable[v]:
            continue
        state[2] += 1
        n_star = _star(tets, neighbors, vertex_tet, v, star, mark, state[2])
        if n_star <= 0:
            continue
        # worst cells first, so that candidates are refused after few evaluations
        for s in range(n_star):
            star_quality[s] = _quality(points, tets[star[s], 0], tets[star[s], 1], tets[star[s], 2], tets[star[s], 3])
        for i in range(1, n_star):
            j = i
            while j > 0 and star_quality[j - 1] > star_quality[j]:
                star_quality[j - 1], star_quality[j] = star_quality[j], star_quality[j - 1]
                star[j - 1], star[j] = star[j], star[j - 1]
                j -= 1
        current = star_quality[0]
        if current >= aim:
            continue  # fixed already, by the move of another vertex of its slivers
        # mean edge length at v and the directions away from poor cells' opposite faces
        total = 0.0
        n_edges = 0
        n_extra = 0
        for s in range(n_star):
            t = star[s]
            k = 0
            while tets[t, k] != v:
                k += 1
            for j in range(4):
                if j != k:
                    u = tets[t, j]
                    total += np.sqrt(
                        (points[u, 0] - points[v, 0]) ** 2
                        + (points[u, 1] - points[v, 1]) ** 2
                        + (points[u, 2] - points[v, 2]) ** 2
                    )
                    n_edges += 1
            q = _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3])
            if q < current + 0.05:
                a, nx, ny, nz, norm = _face_normal(points, tets, t, k)
                if norm > 0.0:
                    # the face normal pointing at v
                    side = nx * (points[v, 0] - points[a, 0]) + ny * (points[v, 1] - points[a, 1])
                    side += nz * (points[v, 2] - points[a, 2])
                    sign = 1.0 if side >= 0.0 else -1.0
                    extra[n_extra, 0] = sign * nx / norm
                    extra[n_extra, 1] = sign * ny / norm
                    extra[n_extra, 2] = sign * nz / norm
                    n_extra += 1
        scale = total / max(n_edges, 1)
        x0 = points[v, 0]
        y0 = points[v, 1]
        z0 = points[v, 2]
        improved = False
        for step in steps:
            length = step * scale
            bx = points[v, 0]
            by = points[v, 1]
            bz = points[v, 2]
            best = current
            cx = bx
            cy = by
            cz = bz
            for d in range(n_extra + directions.shape[0]):
                if d < n_extra:
                    dx, dy, dz = extra[d, 0], extra[d, 1], extra[d, 2]
                else:
                    dx = directions[d - n_extra, 0]
                    dy = directions[d - n_extra, 1]
                    dz = directions[d - n_extra, 2]
                points[v, 0] = cx + length * dx
                points[v, 1] = cy + length * dy
                points[v, 2] = cz + length * dz
                q = _star_quality(points, tets, star, n_star, best)
                if q > best:
                    best = q
                    bx = points[v, 0]
                    by = points[v, 1]
                    bz = points[v, 2]
            points[v, 0] = bx
            points[v, 1] = by
            points[v, 2] = bz
            if best > current:
                current = best
                improved = True
        if improved:
            moved += 1
        else:
            points[v, 0] = x0
            points[v, 1] = y0
            points[v, 2] = z0
    return moved


@numba.njit(cache=True)
def _try_positions(points, tets, neighbors, vertex_tet, vertices, candidates, mark, state, aim):
    """Move each vertex to the best of its candidate positions (k, 3) if that raises its star's smallest quality.

    Vertices whose star is at ``aim`` already are skipped.
    """
    star = np.empty(_MAX_STAR, dtype=np.int64)
    moved = 0
    for index in range(vertices.shape[0]):
        v = vertices[index]
        state[2] += 1
        n_star = _star(tets, neighbors, vertex_tet, v, star, mark, state[2])
        if n_star <= 0:
            continue
        current = _star_quality(points, tets, star, n_star, -1e300)
        if current >= aim:
            continue
        x0 = points[v, 0]
        y0 = points[v, 1]
        z0 = points[v, 2]
        best = current
        bx, by, bz = x0, y0, z0
        for c in range(candidates.shape[1]):
            points[v, 0] = candidates[index, c, 0]
            points[v, 1] = candidates[index, c, 1]
            points[v, 2] = candidates[index, c, 2]
            q = _star_quality(points, tets, star, n_star, best)
            if q > best:
                best = q
                bx = points[v, 0]
                by = points[v, 1]
                bz = points[v, 2]
        points[v, 0] = bx
        points[v, 1] = by
        points[v, 2] = bz
        if best > current:
            moved += 1
    return moved


@numba.njit(cache=True)
def _collapse_vertices(points, tets, neighbors, alive, vertex_tet, free, state, vertices, movable, mark, aim):
    """Remove each movable vertex whose star is below ``aim`` by contracting it onto its best neighbour.

    Every cell of the star that holds the neighbour disappears and the others
    get the neighbour in place of the vertex; the neighbour chosen gives the
    largest smallest quality, and the contraction is made only if that beats
    the star's, with every new cell positive and the result a manifold.
    Returns the number of vertices removed.
    """
    star = np.empty(_MAX_STAR, dtype=np.int64)
    new = np.empty((_MAX_STAR, 4), dtype=np.int64)
    best_new = np.empty((_MAX_STAR, 4), dtype=np.int64)
    candidates = np.empty(_MAX_STAR, dtype=np.int64)
    removed = 0
    for index in range(vertices.shape[0]):
        v = vertices[index]
        if not movable[v] or vertex_tet[v] < 0:
            continue
        state[2] += 1
        n_star = _star(tets, neighbors, vertex_tet, v, star, mark, state[2])
        if n_star <= 0:
            continue
        current = _star_quality(points, tets, star, n_star, -1e300)
        if current >= aim:
            continue
        n_candidates = 0
        for s in range(n_star):
            for j in range(4):
                u = tets[star[s], j]
                if u == v:
                    continue
                seen = False
                for c in range(n_candidates):
                    if candidates[c] == u:
                        seen = True
                if not seen:
                    candidates[n_candidates] = u
                    n_candidates += 1
        best = current
        best_count = 0
        for c in range(n_candidates):
            u = candidates[c]
            worst = 1e300
            count = 0
            for s in range(n_star):
                t = star[s]
                holds_u = False
                for j in range(4):
                    if tets[t, j] == u:
                        holds_u = True
                if holds_u:
                    continue
                for j in range(4):
                    new[count, j] = u if tets[t, j] == v else tets[t, j]
                worst = min(worst, _quality(points, new[count, 0], new[count, 1], new[count, 2], new[count, 3]))
                count += 1
                if worst <= best:
                    break
            if count > 0 and worst > best:
                best = worst
                best_count = count
                best_new[:count] = new[:count]
        if best_count > 0:
            if _replace_cells(tets, neighbors, alive, vertex_tet, free, state, star, n_star, best_new, best_count):
                vertex_tet[v] = -1
                removed += 1
    return removed


@numba.njit(cache=True)
def _edge_on_boundary(tets, neighbors, t0, a, b):
    """Whether the edge ``a b`` of cell ``t0`` lies on the boundary (its ring of cells is open)."""
    ring_cells = np.empty(64, dtype=np.int64)
    ring_vertices = np.empty(64, dtype=np.int64)
    return _edge_ring(tets, neighbors, t0, a, b, ring_cells, ring_vertices) < 0


@numba.njit(cache=True)
def _boundary_turns_sharply(points, tets, neighbors, t, sharp, normals):
    """Whether two boundary faces of cell ``t`` have outward unit normals whose cosine is below ``sharp``.

    The normals are oriented by the vertex order of the positively oriented
    cell, not by the side of its fourth corner, which a flat cell leaves
    undecided. Faces folded onto each other (normals within MIN_DIHEDRAL of
    opposite) do not count: that is a flat cell lying in the boundary (a
    small face over a large one), not a chord of a domain edge, which would
    be a wedge too thin for any cell to pass the sliver bound. ``normals``
    is scratch space, shape (4, 3).
    """
    count = 0
    for k in range(4):
        if neighbors[t, k] >= 0:
            continue
        a, nx, ny, nz, norm = _face_normal(points, tets, t, k)
        if norm == 0.0:
            continue
        # corners k + 1, k + 2, k + 3 turn counter-clockwise seen from outside for even k (an odd cyclic shift)
        scale = (1.0 if k % 2 == 0 else -1.0) / norm
        normals[count, 0] = nx * scale
        normals[count, 1] = ny * scale
        normals[count, 2] = nz * scale
        for j in range(count):
            cosine = normals[j, 0] * normals[count, 0] + normals[j, 1] * normals[count, 1]
            cosine += normals[j, 2] * normals[count, 2]
            if _FOLDED < cosine < sharp:
                return True
        count += 1
    return False


@numba.njit(cache=True)
def _delete_flat_boundary_cells(points, tets, neighbors, alive, vertex_tet, free, state, order, aim, fixed, sharp):
    """Delete cells of ``order`` below quality ``aim`` with two or three boundary faces, where that keeps it manifold.

    Two boundary faces: the two other faces become boundary, allowed when
    the edge they share is not on the boundary already, nor joins two fixed
    points where the faces' outward normals have a cosine below ``sharp``:
    that is a piece of a sharp edge of the domain (a box's, sampled with
    fixed points), which the new boundary faces would cut across, losing
    volume. Three: the vertex shared by the three boundary faces (no other
    cell reaches it across a face) must not be fixed; it becomes unused.
    Four: a cell apart from the rest goes unless it holds a fixed point.
    Returns the number deleted.
    """
    normals = np.empty((4, 3))
    deleted = 0
    for index in range(order.shape[0]):
        t = order[index]
        if not alive[t]:
            continue
        if _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3]) >= aim:
            continue
        n_boundary = 0
        for k in range(4):
            if neighbors[t, k] < 0:
                n_boundary += 1
        if n_boundary == 2:
            a = -1
            b = -1
            for k in range(4):
                if neighbors[t, k] < 0:
                    if a < 0:
                        a = tets[t, k]
                    else:
                        b = tets[t, k]
            # the exposed faces share the edge a b (a, b: the corners opposite the boundary faces)
            if _edge_on_boundary(tets, neighbors, t, a, b):
                continue
            pinned = True
            for k in range(4):
                v = tets[t, k]
                if v != a and v != b and not fixed[v]:
                    pinned = False
            if pinned and _boundary_turns_sharply(points, tets, neighbors, t, sharp, normals):
                continue
        elif n_boundary == 3:
            # the tip, on all three boundary faces, is the corner opposite the fourth face
            tip = -1
            for k in range(4):
                if neighbors[t, k] >= 0:
                    tip = tets[t, k]
            if fixed[tip]:
                continue
        elif n_boundary < 4:
            continue
        elif fixed[tets[t, 0]] or fixed[tets[t, 1]] or fixed[tets[t, 2]] or fixed[tets[t, 3]]:
            continue  # a cell on its own, but holding a fixed point
        alive[t] = False
        free[state[1]] = t
        state[1] += 1
        for k in range(4):
            o = neighbors[t, k]
            if o >= 0:
                for j in range(4):
                    if neighbors[o, j] == t:
                        neighbors[o, j] = -1
        for k in range(4):
            v = tets[t, k]
            if vertex_tet[v] == t:
                vertex_tet[v] = -1
                for j in range(4):
                    o = neighbors[t, j]
                    if o >= 0 and j != k:
                        vertex_tet[v] = o
        deleted += 1
    return deleted


@numba.njit(cache=True)
def _boundary_vertex_mask(tets, neighbors, alive, n_points):
    """Vertices on a boundary face of a live cell."""
    mask = np.zeros(n_points, dtype=np.bool_)
    for t in range(tets.shape[0]):
        if alive[t]:
            for k in range(4):
                if neighbors[t, k] < 0:
                    for j in range(4):
                        if j != k:
                            mask[tets[t, j]] = True
    return mask


@numba.njit(cache=True)
def _link_components(faces, n_points):
    """Per vertex, the number of fans its boundary faces form: 1 where the surface is manifold, 0 off it.

    Faces around a vertex belong to one fan when a chain of them shares
    edges through the vertex (union-find over the faces at each vertex).
    """
    n = faces.shape[0]
    start, around = _incidence(faces, n_points)
    root = np.arange(n)
    components = np.zeros(n_points, dtype=np.int64)
    for v in range(n_points):
        low = start[v]
        high = start[v + 1]
        for i in range(low, high):
            root[around[i]] = around[i]
        for i in range(low, high):
            fi = around[i]
            for j in range(i + 1, high):
                fj = around[j]
                shared = False
                for a in range(3):
                    for b in range(3):
                        if faces[fi, a] == faces[fj, b] and faces[fi, a] != v:
                            shared = True
                if shared:
                    x = fi
                    while root[x] != x:
                        x = root[x]
                    y = fj
                    while root[y] != y:
                        y = root[y]
                    if x != y:
                        root[x] = y
        for i in range(low, high):
            if root[around[i]] == around[i]:
                components[v] += 1
    return components


def _boundary_faces(cells, neighbors):
    """Faces of the cells with no cell across, shape (b, 3)."""
    faces = [np.delete(cells, k, axis=1)[neighbors[:, k] < 0] for k in range(4)]
    return np.concatenate(faces) if faces else np.empty((0, 3), dtype=np.int64)


def _feature_vertices(points, cells, neighbors, n_points, angle=25.0):
    """Boundary vertices on a sharp edge or corner, which stay put during sliver removal.

    A vertex is one when some boundary face around it turns more than
    ``angle`` degrees away from the mean normal there.
    """
    faces, normals = [], []
    for k in range(4):
        on = neighbors[:, k] < 0
        face = np.delete(cells[on], k, axis=1)
        a, b, c = (points[face[:, i]] for i in range(3))
        normal = np.cross(b - a, c - a)
        toward = points[cells[on, k]] - a
        normal *= -np.sign(np.einsum("ij,ij->i", normal, toward))[:, None]  # outward
        faces.append(face)
        normals.append(normal)
    faces, normals = np.concatenate(faces), np.concatenate(normals)
    length = np.sqrt(np.einsum("ij,ij->i", normals, normals))
    unit = normals / np.where(length > 0, length, 1.0)[:, None]
    mean = np.zeros((n_points, 3))
    for i in range(3):
        np.add.at(mean, faces[:, i], normals)
    mean /= np.maximum(np.sqrt(np.einsum("ij,ij->i", mean, mean)), 1e-300)[:, None]
    cosine = np.ones(n_points)
    for i in range(3):
        np.minimum.at(cosine, faces[:, i], np.einsum("ij,ij->i", unit, mean[faces[:, i]]))
    return cosine < np.cos(np.radians(angle))


def _boundary_candidates(domain, points, vertices, scale, finite_step, tolerance):
    """Positions on the boundary around each vertex: 8 tangent directions times 5 steps, projected; (k, 40, 3)."""
    where = points[vertices]
    distance = domain.distance(where)
    normal = _distance_gradient(domain, where, distance, finite_step)
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


@numba.njit(cache=True)
def _qualities(points, tets, which):
    out = np.empty(which.shape[0])
    for i in range(which.shape[0]):
        t = which[i]
        out[i] = _quality(points, tets[t, 0], tets[t, 1], tets[t, 2], tets[t, 3])
    return out


def _remove_slivers(domain, size, points, cells, neighbors, n_fixed, tolerance, finite_step):
    """Raise every cell's smallest dihedral angle towards AIM_DIHEDRAL; returns points, cells, neighbours, rounds."""
    n = len(points)
    m = len(cells)
    capacity = m + m // 4 + 1024
    tets = np.full((capacity, 4), -1, dtype=np.int64)
    tets[:m] = cells
    adjacent = np.full((capacity, 4), -1, dtype=np.int64)
    adjacent[:m] = neighbors
    alive = np.zeros(capacity, dtype=bool)
    alive[:m] = True
    free = np.empty(capacity, dtype=np.int64)
    state = np.array([m, 0, 0], dtype=np.int64)  # slots used, free-list length, visit stamp
    vertex_tet = np.full(n, -1, dtype=np.int64)
    for k in range(4):
        vertex_tet[cells[:, k]] = np.arange(m)
    fixed = np.zeros(n, dtype=bool)
    fixed[:n_fixed] = True
    mark = np.full(capacity, -1, dtype=np.int64)
    feature = _feature_vertices(points, cells, neighbors, n)
    aim = _aim(AIM_DIHEDRAL)
    sharp = np.cos(np.radians(SHARP_TURN))

    def peel_outside():
        """Delete boundary cells whose centroid lies outside (a bridge over a concave edge, say), sharp or not."""
        while True:
            live = np.flatnonzero(alive[: state[0]])
            outside = live[domain.distance(points[tets[live]].mean(axis=1)) > 0]
            if len(outside) == 0 or not _delete_flat_boundary_cells(
                points, tets, adjacent, alive, vertex_tet, free, state, outside, np.inf, fixed, -2.0
            ):
                return

    peel_outside()
    rounds = 0
    for rounds in range(1, SLIVER_ROUNDS + 1):
        live = np.flatnonzero(alive[: state[0]])
        quality = _qualities(points, tets, live)
        poor = quality < aim
        if not poor.any():
            rounds -= 1
            break
        order = live[poor][np.argsort(quality[poor], kind="stable")]
        # flat cells on the boundary go first (peeled layer by layer), then flips, then vertex moves
        changes = 0
        while True:
            deleted = _delete_flat_boundary_cells(
                points, tets, adjacent, alive, vertex_tet, free, state, order, aim, fixed, sharp
            )
            changes += deleted
            if deleted == 0:
                break
        order = order[alive[order]]
        changes += _flip_slivers(points, tets, adjacent, alive, vertex_tet, free, state, order, aim)
        order = order[alive[order]]
        vertices = np.unique(tets[order])
        boundary = _boundary_vertex_mask(tets, adjacent, alive, n)
        movable = ~fixed & ~boundary
        changes += _perturb_vertices(
            points, tets, adjacent, vertex_tet, vertices, movable, mark, state, _DIRECTIONS, _STEPS, aim
        )
        sliding = vertices[boundary[vertices] & ~fixed[vertices] & ~feature[vertices]]
        if len(sliding):
            candidates = _boundary_candidates(domain, points, sliding, size(points[sliding]), finite_step, tolerance)
            changes += _try_positions(points, tets, adjacent, vertex_tet, sliding, candidates, mark, state, aim)
        if rounds >= 2:  # what flips and moves could not mend: contract interior vertices of the slivers left
            live = np.flatnonzero(alive[: state[0]])
            stubborn = live[_qualities(points, tets, live) < aim]
            changes += _collapse_vertices(
                points, tets, adjacent, alive, vertex_tet, free, state, np.unique(tets[stubborn]), movable, mark, aim
            )
        logger.debug("sliver round %d: %d cells below the aim, %d changes", rounds, len(order), changes)
        if changes == 0:
            break
    peel_outside()
    live = np.flatnonzero(alive[: state[0]])
    return points, tets[live], adjacent[live], rounds


def _problems(points, cells, neighbors):
    """What makes the final mesh invalid, as a list of phrases (empty when valid)."""
    problems = []
    a, b, c, d = (points[cells[:, k]] for k in range(4))
    volume = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))
    if np.any(volume <= 0):
        problems.append(f"{int(np.sum(volume <= 0))} cells are inverted or flat")
    if np.any(np.bincount(cells.ravel(), minlength=len(points)) == 0):
        problems.append("unused vertices")
    faces = _boundary_faces(cells, neighbors)
    fans = _link_components(faces, len(points))
    if np.any(fans > 1):
        problems.append(f"{int(np.sum(fans > 1))} boundary vertices where the boundary is not manifold")
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges[:, 0] * len(points) + edges[:, 1], return_counts=True)
    if np.any(counts != 2):
        problems.append(f"{int(np.sum(counts != 2))} boundary edges not on exactly two boundary faces")
    return problems


def _finalize(domain, size, points, n_fixed, tolerance, finite_step, edge_balls=None):
    """The final points' Delaunay cells inside the domain, boundary vertices projected, slivers removed.

    ``edge_balls`` (see :func:`_edge_balls`): free points inside them are
    dropped, so that the sharp edges' segments are edges of the cells.
    """
    from ..quality.tetra import _min_dihedral_all

    started = time.perf_counter()
    # a point stuck just inside the boundary makes flat cells with the boundary points above it
    distance = domain.distance(points)
    stuck = (distance < -tolerance) & (distance > -NEAR_BOUNDARY * size(points))
    stuck[:n_fixed] = False
    centres, radii = (np.empty((0, 3)), np.empty(0)) if edge_balls is None else edge_balls
    stuck |= _encroaching(points, n_fixed, centres, radii)
    points = points[~stuck & ~_duplicates(points)]
    for attempt in range(ENCROACHED_ROUNDS):
        cells, neighbors, _ = _tetrahedralise(domain, points, tolerance, edges=False)
        if len(cells) == 0:
            raise GenerationError("no cell survived: the domain is too small or thin for the mesh size")
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
    slivers_before = int(np.sum(_min_dihedral_all(points, cells) < MIN_DIHEDRAL))
    points, cells, neighbors, rounds = _remove_slivers(
        domain, size, points, cells, neighbors, n_fixed, tolerance, finite_step
    )
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    renumber = np.cumsum(used) - 1
    points, cells = points[used], renumber[cells]
    angles = _min_dihedral_all(points, cells)
    slivers = int(np.sum(angles < MIN_DIHEDRAL))
    if slivers:
        raise GenerationError(
            f"{slivers} slivers remain (cells with a dihedral angle below {MIN_DIHEDRAL:g} degrees, the smallest "
            f"{max(float(angles.min()), 0.0):.2f}) after {rounds} rounds of sliver removal; try another seed or a "
            "smaller edge length"
        )
    problems = _problems(points, cells, neighbors)
    outside = domain.distance(points[cells].mean(axis=1)) > 0
    if outside.any():
        problems.append(f"{int(outside.sum())} cells have their centroid outside the domain")
    if problems:
        raise GenerationError("mesh generation produced an invalid mesh: " + "; ".join(problems))
    info = {
        "min_dihedral": float(angles.min()),
        "slivers_before": slivers_before,
        "sliver_rounds": rounds,
        "sliver_seconds": time.perf_counter() - started,
    }
    return Mesh(points, cells, info=info)
