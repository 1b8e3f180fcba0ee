"""The 3D generator's initial points: nested body-centred cubic lattices thinned to the size function.

A BCC lattice of cube side ``LATTICE_FACTOR * h0`` (two points per cube;
its Delaunay cells are Sommerville tetrahedra) is nested: the lattice of
side ``2 s`` is a sublattice of the one of side ``s``, so each site keeps or
drops its children by the size there, from the coarsest level down, and
the density follows ``1 / size**3`` without a random thinning of all sites.

:func:`lattice_seeds` adds hexagonal lattices on the domain's flat faces
(:mod:`.flat_faces`): the generator's seeds.
"""

import numpy as np

from ..errors import GenerationError
from ..mesh.columns import rows_all
from .flat_faces import with_face_seeds

LATTICE_FACTOR = 1.07  # cube side of the seed lattice over h: 2 points per cube, about the density of the final mesh


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
        raise GenerationError(
            "no lattice point falls inside the domain: it is empty, the bbox misses it or h0 is too large"
        )
    jitter = np.column_stack([_hash_uniform(sites, salt ^ (0x5BD1E995 * (axis + 1))) for axis in range(3)]) - 0.5
    points = bbox[0] + half * (sites + 0.02 * jitter)
    escaped = domain.distance(points) >= inside_tolerance  # jittered out of the domain: back on the lattice site
    points[escaped] = bbox[0] + half * sites[escaped]
    return points, smallest


def lattice_seeds(domain, size, h0, bbox, rng, inside_tolerance):
    """:func:`bcc_seed_points` with hexagonal lattices on the domain's flat faces (:mod:`.flat_faces`)."""
    points, smallest = bcc_seed_points(domain, size, h0, bbox, rng, inside_tolerance)
    return with_face_seeds(points, domain, size, h0, bbox, rng, inside_tolerance), smallest
