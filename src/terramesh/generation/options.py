"""The generators' options, checked, and the regular sample of the sizes they are checked on.

One sample of the bbox (256² in 2D, 64³ in 3D) gives the smallest size
(``h0`` where not given), the vertex count the sizes ask for (refused where
it exceeds the machine's memory), the domain's area and the sizes the mesh is
checked against afterwards (:mod:`.mesh_checks`).
"""

import numbers
from typing import NamedTuple

import numpy as np

from .._kernels import physical_memory
from ..errors import GenerationError, SizingError, checked_number, point_text, warn_user
from ..mesh.columns import bounds
from ..sizing.edge_length import ConstantSize, as_size_function
from ..sizing.grid import SizeGrid
from .distances import project_to_boundary
from .fixed_points import validated_fixed_points
from .levels import LEVEL_SAMPLES, regular_sample

BOUNDARY_TOLERANCE = 1e-3  # inside/outside and on-boundary tolerance, in units of h0
BYTES_PER_VERTEX = {2: 420, 3: 2000}  # peak memory per vertex: 6.0 GB at 14.5M (2D); 3D a bound, not measured
TIGHT_SAMPLE_SHARE = 1 / 16  # a domain on fewer of the bbox's sample points is sampled again over its own box
STEEP_SIZES = 3.0  # size change from one cell to the next above which sizes warn: a step, not a grading
SIZES_JUMP = "the sizes change faster than cells can follow"


class Options(NamedTuple):
    """The generators' options, checked (:func:`checked_options`)."""

    size: object  # the size function, a callable of (n, dim) points
    h0: float  # the smallest edge length, the seeds' lattice spacing
    tolerance: float  # inside/outside and on-boundary tolerance, BOUNDARY_TOLERANCE h0
    fixed: np.ndarray  # the fixed points: the user's, checked, and the domain's corners spread out, (k, dim)
    h0_estimated: bool  # h0 came from the sizes' sample, not from the user or a number
    measure: float  # the domain's area (or volume) as the sample measures it
    sample: "SizeSample"  # the sizes' sample (size_sample), for the checks of the mesh against its sizes


def checked_options(domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance=1e-2, seed=0):
    """Both generators' options, checked.

    Returns :class:`Options`.
    """
    dim = bbox.shape[1]
    if edge_length is None:
        if h0 is None:
            raise GenerationError("give edge_length (or at least h0, for a uniform mesh)")
        edge_length = h0
    size = as_size_function(edge_length)
    if isinstance(size, SizeGrid):
        if size.dim != dim:
            raise GenerationError(f"a {dim}D mesh needs a {dim}-axis SizeGrid, got {size.dim} axes")
        _check_grid_covers(size, bbox)
    sample = size_sample(size, domain, bbox)  # one sample serves h0 and the vertex estimate
    h0_estimated = h0 is None and callable(edge_length) and not isinstance(edge_length, SizeGrid)
    if h0 is None:
        h0 = smallest_size(size, domain, sample)
    h0 = checked_number(h0, "h0 must be positive and finite (a length)", GenerationError, minimum=0, strict=True)
    checked_max_iter(max_iter)
    checked_number(
        move_tolerance,
        "move_tolerance must be positive and finite (a fraction of the size)",
        GenerationError,
        minimum=0,
        strict=True,
    )
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise GenerationError(f"seed must be a non-negative integer, got {seed!r}")
    measure = _check_vertex_estimate(sample, dim)
    warn_if_sizes_jump(sample)
    tolerance = BOUNDARY_TOLERANCE * h0
    fixed = validated_fixed_points(fixed_points, domain, bbox, tolerance, size)
    return Options(size, h0, tolerance, fixed, h0_estimated, measure, sample)


def checked_max_iter(max_iter):
    """``max_iter`` as an int of at least 1 (a bool or 2.5 refused); else GenerationError."""
    iterations = checked_number(max_iter, "max_iter must be a whole number of at least 1", GenerationError, minimum=1)
    if not iterations.is_integer() or isinstance(max_iter, bool):
        raise GenerationError(f"max_iter must be a whole number of at least 1, got {max_iter!r}")
    return int(iterations)


class SizeSample(NamedTuple):
    """A regular sample of the sizes over the domain (:func:`size_sample`)."""

    inside: np.ndarray  # the sample points inside the domain, (k, dim)
    sizes: np.ndarray  # their sizes, (k,)
    share: float  # the area (or volume) each sample point stands for
    near: np.ndarray  # the sample points within a sample step of the boundary...
    near_distance: np.ndarray  # ...and their signed distances
    bbox_points: np.ndarray | None  # all the points of the bbox's own sample (2D: 256²), None if sampled again...
    bbox_distance: np.ndarray | None  # ...and their signed distances, exact within two sample steps
    steep: tuple | None  # neighbouring points inside whose sizes differ by a step (:func:`_steepest_change`), or None


def size_sample(size, domain, bbox):
    """A regular sample of the bbox (256² or 64³): the points inside the domain and their sizes.

    A domain that fills little of a generous bbox (the unit disk in a bbox
    of +-100: 5 sample points inside, an area of 2.44) is sampled again
    over the box around its points, so that its area, its smallest size
    and the checks of the mesh against its sizes stand on as many points
    as a snug bbox gives. Otherwise the bbox's sample is kept, for the
    choice of coarse levels (:func:`~terramesh.generation.levels.coarse_levels`).
    """
    inside, distance, sample, share, step = _sampled(domain, bbox)
    bbox_points, bbox_distance = sample, distance
    if 0 < len(inside) < TIGHT_SAMPLE_SHARE * len(sample):
        low, high = bounds(inside)
        low, high = np.maximum(low - 2.0 * step, bbox[0]), np.minimum(high + 2.0 * step, bbox[1])
        inside, distance, sample, share, step = _sampled(domain, np.array([low, high]), check_cut=False)
        bbox_points = bbox_distance = None
    near = np.abs(distance) < step
    sizes = np.asarray(size(inside), dtype=np.float64)
    steep = _steepest_change(sample, distance < 0, sizes)
    return SizeSample(inside, sizes, share, sample[near], distance[near], bbox_points, bbox_distance, steep)


def _steepest_change(sample, inside, sizes):
    """``(point, neighbour, size, neighbour's size)`` of a steep step between neighbours inside, or None.

    The steepest along the first axis that has one. Steep: a change of the
    sizes over the larger of the sample step and the smaller size above
    ``STEEP_SIZES`` (their gradient where the sample resolves it, the
    change from one cell to the next where they jump); a size doubling
    between cells 0.05 and 0.1 across, 6.4 per unit length over the
    sample's step of 0.0078, is a change of 1. ``sample`` is the regular
    sample (``regular_sample``'s order), ``inside`` its mask of points in
    the domain and ``sizes`` theirs.
    """
    dim = sample.shape[1]
    per_axis = round(len(sample) ** (1 / dim))
    shape = (per_axis,) * dim
    if per_axis < 2 or sizes.shape != (int(inside.sum()),) or not np.all(np.isfinite(sizes)):
        return None  # the size checks name what is wrong
    grid = np.full(len(sample), np.nan, dtype=np.float32)  # half the pages: 0.3 ms of a 256² sample, not 1.5
    grid[inside] = sizes
    grid = grid.reshape(shape)
    for axis in range(dim):
        step = np.float32((sample[-1, axis] - sample[0, axis]) / (per_axis - 1))  # first and last: the bbox's corners
        if step == 0.0:
            continue
        low = grid[(slice(None),) * axis + (slice(None, -1),)]
        high = grid[(slice(None),) * axis + (slice(1, None),)]
        change = np.subtract(high, low)
        np.abs(change, out=change)
        allowed = np.minimum(low, high)
        np.maximum(allowed, step, out=allowed)
        allowed *= np.float32(STEEP_SIZES)
        steep = change > allowed  # False where either point is outside (NaN)
        if steep.any():
            change /= allowed
            change[~steep] = 0.0
            at = np.unravel_index(int(np.argmax(change)), change.shape)
            beyond = tuple(k + (1 if a == axis else 0) for a, k in enumerate(at))
            points = sample.reshape(shape + (dim,))
            return points[at], points[beyond], float(grid[at]), float(grid[beyond])
    return None


def warn_if_sizes_jump(sample):
    """Warn where the sizes change from one cell to the next by more than ``STEEP_SIZES`` times the smaller.

    DistMesh grades its cells by their sizes, and neighbouring cells can
    differ by some 20-50 %: a square sized 0.001 for x < 0.05 and 0.1
    beyond came out with cells of q 0.057, without a word, and 0.001 against
    1 failed, blamed on a narrow part the square does not have.
    """
    if sample.steep is None:
        return
    point, neighbour, size, beyond = sample.steep
    warn_user(
        f"{SIZES_JUMP}: from {size:.3g} to {beyond:.3g} within {float(np.linalg.norm(neighbour - point)):.3g} near "
        f"{point_text(0.5 * (point + neighbour))}: a step, where neighbouring cells differ by 20-50 % at most, so "
        "expect poor or missing cells there; limit the gradient first "
        "(tm.sizing.limit_gradient on a SizeGrid; the size functions' grade or g)"
    )


def _sampled(domain, bbox, check_cut=True):
    """The regular sample of ``bbox``: its points inside, the distances and points, each point's share and the step."""
    dim = bbox.shape[1]
    samples = LEVEL_SAMPLES if dim == 2 else 64
    shape = (samples,) * dim
    sample = regular_sample(bbox, samples)
    share = float(np.prod(bbox[1] - bbox[0])) / len(sample)
    step = float(max(np.linspace(low, high, samples)[1] - low for low, high in bbox.T))  # the sample's own step
    # only the sign and the distances near the boundary are wanted: a coastline's exact distances took
    # 0.13 s here, the bounded ones a tenth
    distance = domain.distance_within(sample, 2.0 * step)
    # DistMesh meshes a domain inside its bbox; one cut by it was meshed past the bbox, cells bridging
    on_faces = np.zeros(shape, dtype=bool)
    for axis in range(dim):
        on_faces[(slice(None),) * axis + (0,)] = on_faces[(slice(None),) * axis + (-1,)] = True
    cut = on_faces.ravel() & (distance < -step)
    if check_cut and cut.any():
        where = ", ".join(f"{v:.6g}" for v in sample[np.flatnonzero(cut)[0]])
        raise GenerationError(
            f"the domain reaches out of the bbox {bbox.tolist()} (inside at ({where}) on its side): give a bbox"
            " that contains the domain, or intersect the domain with a box (tm.geometry.Intersection)"
        )
    # np.compress, not a boolean index: NumPy 2.4 indexes the rows of an (n, 2) array 10x slower
    return np.compress(distance < 0, sample, axis=0), distance, sample, share, step


def smallest_size(size, domain, sample):
    """Smallest edge length requested in the domain, from ``sample`` (:func:`size_sample`) for a callable.

    The sample's points near the boundary are projected onto it and their
    sizes taken too: a size graded from the boundary is smallest there,
    where the inside points miss it by up to a sample step times its
    gradient (64³ on a 2-unit box graded at 0.5: h0 0.056 for 0.04, and the
    boundary's edges 1.5 sizes long).
    """
    if isinstance(size, SizeGrid):
        return float(size.values.min())
    if isinstance(size, ConstantSize):
        return float(size.value)
    inside, sizes, share = sample.inside, sample.sizes, sample.share
    near, near_distance = sample.near, sample.near_distance
    if len(inside) == 0:
        raise GenerationError(
            "no sample point of the bbox is inside the domain: the bbox misses it, or the domain is empty or "
            "thinner than the sample; give h0"
        )
    smallest = float(sizes.min())
    if len(near):
        step = 1e-3 * share ** (1.0 / inside.shape[1])
        on_boundary = project_to_boundary(domain, near, near_distance, step)
        with np.errstate(invalid="ignore"):
            boundary_sizes = np.asarray(size(on_boundary), dtype=np.float64)
        usable = boundary_sizes[np.isfinite(boundary_sizes) & (boundary_sizes > 0)]
        if len(usable):
            smallest = min(smallest, float(usable.min()))
    return smallest


def _check_vertex_estimate(sample, dim):
    """Refuse sizes that ask for more vertices than this machine's memory holds (a unit mistake, most often).

    Returns the domain's area (or volume) as the sample measures it.

    The count is the sizes' vertex density (equilateral cells: 2 / (√3 h²)
    per unit area; regular tetrahedra: √2 / h³ per unit volume) summed over
    a regular sample of the domain. A square of 100 km meshed at 0.5 (metres
    taken for kilometres) ran 67 s and then ran out of memory deep in the
    seeding.
    """
    inside, sizes, share = sample.inside, sample.sizes, sample.share
    memory = physical_memory()
    if memory is None:  # no limit known
        return share * len(inside)
    with np.errstate(divide="ignore", over="ignore"):
        density = 2.0 / (np.sqrt(3.0) * sizes**2) if dim == 2 else np.sqrt(2.0) / sizes**3
        estimate = float(np.sum(density) * share)
    most = memory / BYTES_PER_VERTEX[dim]
    if estimate > most:
        raise GenerationError(
            f"the sizes ask for about {estimate:.3g} vertices (the domain's {'area' if dim == 2 else 'volume'} over "
            f"each size's share), more than this machine's {memory / 2**30:.0f} GiB of memory holds (about "
            f"{most:.2g}): are the sizes and the domain in the same units?"
        )
    return share * len(inside)


GRID_COVERS = 0.5
"""Share of the domain's bbox (along each axis) below which a SizeGrid covering less of it warns."""


def _check_grid_covers(grid, bbox):
    """Refuse a SizeGrid apart from the domain, warn of one covering less than ``GRID_COVERS`` of it.

    Beyond its nodes a grid gives its edge's sizes: a grid of longitude and
    latitude given for a domain in UTM metres sized every point at its
    corner's 420 m, and nothing was said.
    """
    share = grid.covered(bbox[0], bbox[1])
    names = grid.axis_names
    extent = ", ".join(f"{name} {a:g}..{b:g}" for name, a, b in zip(names, *grid.bbox, strict=True))
    domain = ", ".join(f"{name} {a:g}..{b:g}" for name, a, b in zip(names, bbox[0], bbox[1], strict=True))
    if np.any(share < 0):
        raise SizingError(
            f"the SizeGrid ({extent}) and the domain ({domain}) do not overlap: is one in other units or another"
            " frame (degrees against metres)?"
        )
    if share.min() < GRID_COVERS:
        warn_user(
            f"the SizeGrid ({extent}) covers {100 * share.min():.0f} % of the domain ({domain}) along"
            f" {names[int(np.argmin(share))]}: beyond its nodes the sizes are its edge's"
        )
