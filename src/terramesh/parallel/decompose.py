"""Cutting a 2D domain into strips of equal work, and the points the strips share along each cut.

The seismic DistMesh talk's parallel scheme: the domain is split into
subdomains whose separators are fixed in space, each subdomain is meshed as
if on its own, and the meshes are merged by their shared separator points.
Here the subdomains are strips across the longer side of the bbox, cut where
the estimated vertex count (the integral of ``1 / (sqrt(3)/2 h**2)``) is
shared equally, and each cut's pieces inside the domain are sampled by the
size function; both strips beside a cut keep those points fixed.
"""

import numbers

import numpy as np

from ..errors import GenerationError
from ..generation.fixed_points import CORNER_REACH
from ..generation.sharp_edges import sampled_curves

__all__ = ["strip_cuts", "separator_points", "cut_clearance"]

_WORK_SAMPLES = 256  # points per axis of the sample that estimates the vertex count
THINNEST_STRIP = 0.5  # sizes: more parts than make strips this wide on average (or with...
FEWEST_VERTICES = 3  # ...fewer vertices than this each, by the estimate) are refused
SEPARATOR_SAMPLES = 4097  # points along a cut that find its pieces inside the domain (ends then bisected)
_BISECTIONS = 60
FACE_PROBE = 1e-9  # of the bbox's extent: a cut's points this near the zero level are probed on both sides
LONGEST_SEGMENT = 1.2  # sizes, at most, between two points of a cut
SHORTEST_PIECE = 0.5  # sizes: a piece of a cut inside the domain shorter than this gets no points
CLEARANCE = 0.75  # a cut's inner points nearer the boundary than this many sizes count against it...
SHIFT_WINDOWS = (0.1, 0.3)  # ...when cuts are shifted, within this share of the strips' mean width, to have
SHIFTS = 21  # fewer (positions tried in a window; the wider only where the narrower found no clean place)
SHIFT_SHARE = 0.2  # a cut moves at most this share of a strip's vertex count: each strip keeps 0.6 to 1.4 shares


def strip_cuts(domain, size, parts, h0=None, fixed_points=None):
    """Where to cut ``domain`` into ``parts`` strips of about equal vertex counts: ``(axis, positions)``.

    With ``h0``, each cut then moves, within a tenth of the strips' mean
    width (three tenths where that finds no clean place), to the place of
    ``SHIFTS`` tried where the fewest of its points come near the boundary,
    a fixed point or a corner of the domain (:func:`cut_clearance`; the
    nearest to the balanced place among equals). No cut moves by more than
    ``SHIFT_SHARE`` (0.2) of a strip's estimated vertex count, so every
    strip keeps between 0.6 and 1.4 times its share.

    Parameters
    ----------
    domain : Domain
        A 2D domain (signed distance, ``bbox``).
    size : callable
        Edge length, ``(n, 2) -> (n,)``.
    parts : int
        Number of strips, at least 1, and at most as many as leave them
        ``THINNEST_STRIP`` (0.5) sizes wide on average and of
        ``FEWEST_VERTICES`` (3) estimated vertices each.
    h0 : float, optional
        The smallest edge length; without it the cuts stay where the
        vertex count is shared equally.
    fixed_points : array_like, shape (m, 2), optional
        The user's fixed points, which a cut keeps clear of.

    Returns
    -------
    axis : int
        0 (cuts at constant x) where the bbox is wider than tall, else 1.
    positions : numpy.ndarray, shape (parts - 1,)
        The cuts' coordinates along ``axis``, ascending, in the domain's units.

    Raises
    ------
    GenerationError
        For ``parts`` not a positive integer, or more than the domain can
        be cut into (the message names the most).

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> disk = tm.geometry.Disk((0, 0), 1)
    >>> axis, cuts = strip_cuts(disk, lambda p: np.full(len(p), 0.1), 2)
    >>> axis, abs(float(cuts[0])) < 0.01
    (0, True)
    """
    # 2.0 passed an int(parts) == parts check and broke range() later; True is no number of parts
    if isinstance(parts, bool) or not isinstance(parts, numbers.Integral) or parts < 1:
        raise GenerationError(f"parts must be a positive integer, got {parts!r}")
    bbox = np.asarray(domain.bbox, dtype=np.float64)
    axis = 0 if bbox[1, 0] - bbox[0, 0] >= bbox[1, 1] - bbox[0, 1] else 1
    axes = [np.linspace(low, high, _WORK_SAMPLES) for low, high in bbox.T]
    sample = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
    work = np.zeros(len(sample))
    inside = domain.distance_within(sample, float(np.max(bbox[1] - bbox[0])) / _WORK_SAMPLES) < 0  # the sign only
    work[inside] = 1.0 / size(sample[inside]) ** 2
    along = work.reshape(_WORK_SAMPLES, _WORK_SAMPLES).sum(axis=1 - axis)
    if not along.sum() > 0:
        raise GenerationError("the domain has no point inside on a 256 x 256 sample of its bbox: nothing to cut")
    most = _most_parts(bbox, axis, inside.reshape(_WORK_SAMPLES, _WORK_SAMPLES), along)
    if parts > most:  # before the arrays of its size: 1e9 parts ran out of memory, 500 ran a minute and failed
        raise GenerationError(
            f"parts={parts} is more strips than the domain can be cut into at these sizes: at most {most} "
            f"(strips at least {THINNEST_STRIP:g} sizes wide on average and of {FEWEST_VERTICES} vertices each, "
            "as the sizes estimate them); give fewer parts"
        )
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (along[1:] + along[:-1]))])
    targets = np.arange(1, parts) / parts * cumulative[-1]
    cuts = np.interp(targets, cumulative, axes[axis])
    if h0 is None or len(cuts) == 0:
        return axis, cuts
    fixed = None if fixed_points is None else np.asarray(fixed_points, dtype=np.float64).reshape(-1, 2)
    corners = np.asarray(domain.corners(), dtype=np.float64).reshape(-1, 2)
    width = (bbox[1, axis] - bbox[0, axis]) / parts
    # each cut stays within SHIFT_SHARE strips' work of its balanced place, whatever its neighbours do: bounded
    # by the way to its neighbours instead, two cuts of a graded size moved toward each other and left a strip
    # of 54 vertices among four of about 300. The bands do not overlap, so the cuts stay in order in the bbox
    reach = SHIFT_SHARE * cumulative[-1] / parts
    for k, (cut, target) in enumerate(zip(cuts, targets, strict=True)):
        for window in SHIFT_WINDOWS:  # wider only where the narrow one found no clean place
            offsets = window * width * np.linspace(-1.0, 1.0, SHIFTS)
            offsets = offsets[np.argsort(np.abs(offsets), kind="stable")]  # the balanced place first: it wins ties
            offsets = offsets[np.abs(np.interp(cut + offsets, axes[axis], cumulative) - target) <= reach]
            scores = _clearances(domain, size, h0, axis, cut + offsets, fixed, corners)
            cuts[k] = cut + offsets[int(np.argmin(scores))]
            if min(scores) == 0:
                break
    return axis, cuts


def _most_parts(bbox, axis, inside, along):
    """The most strips that ``strip_cuts`` makes: ``THINNEST_STRIP`` sizes wide and ``FEWEST_VERTICES`` each.

    From the work sample: ``inside`` (shape (n, n), the samples inside)
    and ``along`` (the sum of ``1 / h**2`` over each column across
    ``axis``). A column's mean of ``1 / h**2`` gives its size, so the
    domain is ``sum(step / h)`` sizes wide along ``axis``; the vertex
    count is the integral of ``1 / (sqrt(3)/2 h**2)``.
    """
    steps = (bbox[1] - bbox[0]) / (_WORK_SAMPLES - 1)
    counts = inside.sum(axis=1 - axis)
    sizes_wide = steps[axis] * float(np.sum(np.sqrt(along[counts > 0] / counts[counts > 0])))
    vertices = float(np.sum(along)) * steps[0] * steps[1] / (np.sqrt(3.0) / 2.0)
    return max(1, int(min(sizes_wide / THINNEST_STRIP, vertices / FEWEST_VERTICES)))


class _Segment:
    def __init__(self, start, end):
        self.start, self.end = start, end

    def __call__(self, t):
        return self.start + np.asarray(t, dtype=np.float64)[:, None] * (self.end - self.start)


def separator_points(domain, size, h0, axis, position):
    """Points along the cut ``{x[axis] = position}`` inside ``domain``, spaced by the size, ends on the boundary.

    The cut's pieces inside the domain are found on ``SEPARATOR_SAMPLES``
    points across the bbox, their ends (where the cut meets the boundary)
    by bisection on the distance (a face inside the domain where the
    distance reads zero, as a union's shared face, counted inside: see
    :func:`_inside`); each piece is sampled like a sharp edge
    (about one point per size, ends included). A piece shorter than
    ``SHORTEST_PIECE`` (half a size at its middle) gets no points: a jagged
    coast crossing a cut three times within a quarter of a size held its
    crossings in both strips, and the cells fanning out to them were
    needles (q 0.174; 0.570 without them, the strips meeting all the same).
    A piece shorter than the sample spacing is missed; wherever the strips
    then do not match, the merge meshes the place anew, or says so.

    Returns
    -------
    numpy.ndarray, shape (k, 2)
        The points have coordinate ``axis`` exactly ``position``.

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> points = separator_points(tm.geometry.Disk((0, 0), 1), lambda p: np.full(len(p), 0.25), 0.25, 0, 0.0)
    >>> len(points), points[:, 0].tolist() == [0.0] * 9, np.round(points[[0, -1], 1], 12).tolist()
    (9, True, [-1.0, 1.0])
    """
    chains = _separator_chains(domain, size, h0, axis, position)
    if not chains:
        return np.empty((0, 2))
    ends = np.array([chain[[0, -1]] for chain in chains])  # (pieces, 2, 2)
    long_enough = np.abs(ends[:, 1, 1 - axis] - ends[:, 0, 1 - axis]) >= SHORTEST_PIECE * size(ends.mean(axis=1))
    held = [chain for chain, keep in zip(chains, long_enough, strict=True) if keep]
    return np.concatenate(held) if held else np.empty((0, 2))


def _separator_chains(domain, size, h0, axis, position):
    """The points of :func:`separator_points`, one array per piece of the cut inside the domain."""
    return _chains_along(domain, size, h0, axis, np.array([float(position)]))[0]


def _chains_along(domain, size, h0, axis, positions):
    """:func:`_separator_chains` of the cuts at each of ``positions`` (a list of lists of arrays).

    All cuts at once: the distance functions are called a few dozen times
    in all, not per cut (placing four cuts on a 1,000-vertex coast tried
    84 positions at about 5 ms each, mostly the calls' own cost).
    """
    other = 1 - axis
    low, high = domain.bbox[0][other], domain.bbox[1][other]
    along = np.linspace(low, high, SEPARATOR_SAMPLES)
    # only the sign matters here and in the bisection: within one sample spacing, a polygon's
    # distance searches its segments that near and takes the sign of the rest from point in polygon
    spacing = (high - low) / (SEPARATOR_SAMPLES - 1)
    samples = _on_cuts(axis, np.repeat(positions, len(along)), np.tile(along, len(positions)))
    inside = _inside(domain, axis, samples, spacing).reshape(len(positions), len(along))
    outside_before = np.pad(~inside[:, :-1], ((0, 0), (1, 0)), constant_values=True)
    outside_after = np.pad(~inside[:, 1:], ((0, 0), (0, 1)), constant_values=True)
    cut_of, first = np.nonzero(inside & outside_before)  # row by row, ascending: the k-th start pairs with the k-th end
    _, last = np.nonzero(inside & outside_after)
    starts, ends = along[first], along[last]
    opens, closes = first > 0, last < len(along) - 1
    ends_found = _boundary_between(
        domain,
        axis,
        np.concatenate([positions[cut_of[opens]], positions[cut_of[closes]]]),
        np.concatenate([along[first[opens] - 1], along[last[closes] + 1]]),
        np.concatenate([along[first[opens]], along[last[closes]]]),
        spacing,
    )
    starts[opens], ends[closes] = ends_found[: opens.sum()], ends_found[opens.sum() :]
    pieces = [
        _Segment(*_on_cuts(axis, positions[[cut, cut]], np.array([start, end])))
        for cut, start, end in zip(cut_of, starts, ends, strict=True)
    ]
    # no segment so long that a strip's generator would put a point in its middle (GAP_RATIO, 1.3 sizes):
    # each strip would project its own, an ulp apart
    chains = sampled_curves(pieces, size, h0, longest=LONGEST_SEGMENT)
    for cut, chain in zip(cut_of, chains, strict=True):
        chain[:, axis] = positions[cut]  # exactly, whatever the interpolation rounded
    return [[chain for cut, chain in zip(cut_of, chains, strict=True) if cut == k] for k in range(len(positions))]


def _inside(domain, axis, points, spacing):
    """Mask of the ``points`` of cuts across ``axis`` inside ``domain``, a face inside it (a union's) counted inside.

    A union's distance reads zero on a face its operands share (so does a
    callable's minimum of two shapes): a cut along it found no piece
    inside, was scored clear of the boundary and stayed there, and the
    strips each put vertices of their own along the face, which the merge
    joined with slivers (q 0.011 where the whole mesh had 0.80). A point
    within ``FACE_PROBE`` of the bbox's extent of the zero level is inside
    where the points that far from it on both sides of the cut are.
    """
    distance = domain.distance_within(points, spacing)
    inside = distance < 0
    probe = FACE_PROBE * float(np.max(np.ptp(np.asarray(domain.bbox, dtype=np.float64), axis=0)))
    zero = np.flatnonzero(~inside & (distance <= probe))
    if len(zero):
        step = np.zeros(points.shape[1])
        step[axis] = probe
        sides = domain.distance_within(np.concatenate([points[zero] - step, points[zero] + step]), spacing) < 0
        inside[zero] = sides[: len(zero)] & sides[len(zero) :]
    return inside


def _on_cuts(axis, positions, values):
    """Points with coordinate ``axis`` at ``positions`` and the other at ``values``."""
    points = np.empty((len(values), 2))
    points[:, axis] = positions
    points[:, 1 - axis] = values
    return points


def _boundary_between(domain, axis, positions, outside, inside, spacing):
    """The boundary points between ``outside`` and ``inside`` (at most ``spacing`` apart) on the cuts, by bisection."""
    outside, inside = np.array(outside, dtype=np.float64), np.array(inside, dtype=np.float64)
    for _ in range(_BISECTIONS):
        middle = 0.5 * (outside + inside)
        now_inside = _inside(domain, axis, _on_cuts(axis, positions, middle), spacing)
        inside = np.where(now_inside, middle, inside)
        outside = np.where(now_inside, outside, middle)
    return 0.5 * (outside + inside)


def cut_clearance(domain, size, h0, axis, position, fixed_points=None, corners=None):
    """How many points of the cut at ``position`` come closer to the boundary than ``CLEARANCE`` sizes.

    The points along a cut other than its pieces' ends (which lie on the
    boundary) are fixed in both strips: one close to the boundary (the cut
    running along a coast at a shallow angle) makes a sliver of a cell with
    the boundary vertices beside it, or leaves a strip's cells short of it.
    A fixed point of the user's within ``CLEARANCE`` sizes of the cut, and
    two ends of pieces that close (land or water across the cut narrower
    than that), count too, and so does each of the domain's ``corners``
    (a model box's side nodes, say) that a cut point leaves fixed (one
    ``CORNER_REACH`` sizes away or more) but closer than ``CLEARANCE``
    sizes: with a side node 0.55 sizes from a cut's end, BP2004 in four
    strips had a cell of quality 0.73. Fewer is better.
    """
    return int(_clearances(domain, size, h0, axis, np.array([float(position)]), fixed_points, corners)[0])


def _clearances(domain, size, h0, axis, positions, fixed_points=None, corners=None):
    """:func:`cut_clearance` of the cut at each of ``positions``, an integer array."""
    return np.array(
        [
            _clearance(domain, size, axis, position, chains, fixed_points, corners)
            for position, chains in zip(positions, _chains_along(domain, size, h0, axis, positions), strict=True)
        ],
        dtype=np.int64,
    )


def _clearance(domain, size, axis, position, chains, fixed_points, corners):
    inner = np.concatenate([chain[1:-1] for chain in chains] + [np.empty((0, 2))])
    count = int(np.sum(np.abs(domain.distance(inner)) < CLEARANCE * size(inner))) if len(inner) else 0
    # a strip of land (or a piece of water) across the cut narrower than that: two ends close together
    ends = np.concatenate([chain[[0, -1]] for chain in chains] + [np.empty((0, 2))])
    if len(ends) > 2:
        ends = ends[np.argsort(ends[:, 1 - axis], kind="stable")]
        gaps = np.diff(ends[:, 1 - axis])
        count += int(np.sum(gaps < CLEARANCE * np.minimum(size(ends[1:]), size(ends[:-1]))))
    if fixed_points is not None and len(fixed_points):
        count += int(np.sum(np.abs(fixed_points[:, axis] - position) < CLEARANCE * size(fixed_points)))
    if corners is not None and len(corners) and len(ends):
        near = corners[np.abs(corners[:, axis] - position) < CLEARANCE * size(corners)]
        if len(near):
            from scipy.spatial import cKDTree

            gap = cKDTree(np.concatenate(chains)).query(near)[0] / size(near)
            count += int(np.sum((gap >= CORNER_REACH) & (gap < CLEARANCE)))
    return count
