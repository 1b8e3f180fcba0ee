"""Cutting a 2D domain into strips of equal work, and the points the strips share along each cut.

The seismic DistMesh talk's parallel scheme: the domain is split into
subdomains whose separators are fixed in space, each subdomain is meshed as
if on its own, and the meshes are merged by their shared separator points.
Here the subdomains are strips across the longer side of the bbox, cut where
the estimated vertex count (the integral of ``1 / (sqrt(3)/2 h**2)``) is
shared equally, and each cut's pieces inside the domain are sampled by the
size function; both strips beside a cut keep those points fixed.
"""

import numpy as np

from ..errors import GenerationError
from ..generation.sharp_edges import sampled_curves

__all__ = ["strip_cuts", "separator_points"]

_WORK_SAMPLES = 256  # points per axis of the sample that estimates the vertex count
SEPARATOR_SAMPLES = 4097  # points along a cut that find its pieces inside the domain (ends then bisected)
_BISECTIONS = 60


def strip_cuts(domain, size, parts):
    """Where to cut ``domain`` into ``parts`` strips of about equal vertex counts: ``(axis, positions)``.

    Parameters
    ----------
    domain : Domain
        A 2D domain (signed distance, ``bbox``).
    size : callable
        Edge length, ``(n, 2) -> (n,)``.
    parts : int
        Number of strips, at least 1.

    Returns
    -------
    axis : int
        0 (cuts at constant x) where the bbox is wider than tall, else 1.
    positions : numpy.ndarray, shape (parts - 1,)
        The cuts' coordinates along ``axis``, ascending, in the domain's units.

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> disk = tm.geometry.Disk((0, 0), 1)
    >>> axis, cuts = strip_cuts(disk, lambda p: np.full(len(p), 0.1), 2)
    >>> axis, abs(float(cuts[0])) < 0.01
    (0, True)
    """
    if int(parts) != parts or parts < 1:
        raise GenerationError(f"parts must be a positive integer, got {parts!r}")
    bbox = np.asarray(domain.bbox, dtype=np.float64)
    axis = 0 if bbox[1, 0] - bbox[0, 0] >= bbox[1, 1] - bbox[0, 1] else 1
    axes = [np.linspace(low, high, _WORK_SAMPLES) for low, high in bbox.T]
    sample = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
    work = np.zeros(len(sample))
    inside = domain.distance(sample) < 0
    work[inside] = 1.0 / size(sample[inside]) ** 2
    along = work.reshape(_WORK_SAMPLES, _WORK_SAMPLES).sum(axis=1 - axis)
    if not along.sum() > 0:
        raise GenerationError("the domain has no point inside on a 256 x 256 sample of its bbox: nothing to cut")
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (along[1:] + along[:-1]))])
    return axis, np.interp(np.arange(1, int(parts)) / parts * cumulative[-1], cumulative, axes[axis])


class _Segment:
    def __init__(self, start, end):
        self.start, self.end = start, end

    def __call__(self, t):
        return self.start + np.asarray(t, dtype=np.float64)[:, None] * (self.end - self.start)


def separator_points(domain, size, h0, axis, position):
    """Points along the cut ``{x[axis] = position}`` inside ``domain``, spaced by the size, ends on the boundary.

    The cut's pieces inside the domain are found on ``SEPARATOR_SAMPLES``
    points across the bbox, their ends (where the cut meets the boundary)
    by bisection on the distance; each piece is sampled like a sharp edge
    (about one point per size, ends included). A piece shorter than the
    sample spacing is missed: the merge then finds the strips do not match
    there and says so.

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
    other = 1 - axis
    low, high = domain.bbox[0][other], domain.bbox[1][other]
    along = np.linspace(low, high, SEPARATOR_SAMPLES)

    def at(values):
        points = np.empty((len(values), 2))
        points[:, axis] = position
        points[:, other] = values
        return points

    inside = domain.distance(at(along)) < 0
    starts = np.flatnonzero(inside & ~np.concatenate([[False], inside[:-1]]))
    ends = np.flatnonzero(inside & ~np.concatenate([inside[1:], [False]]))
    pieces = []
    for first, last in zip(starts, ends, strict=True):
        start = along[0] if first == 0 else _boundary_between(domain, at, along[first - 1], along[first])
        end = along[-1] if last == len(along) - 1 else _boundary_between(domain, at, along[last + 1], along[last])
        pieces.append(_Segment(at(np.array([start]))[0], at(np.array([end]))[0]))
    chains = sampled_curves(pieces, size, h0)
    points = np.concatenate(chains) if chains else np.empty((0, 2))
    points[:, axis] = position  # exactly, whatever the interpolation rounded
    return points


def _boundary_between(domain, at, outside, inside):
    """The boundary point between coordinates ``outside`` and ``inside`` along the cut, by bisection."""
    for _ in range(_BISECTIONS):
        middle = 0.5 * (outside + inside)
        if domain.distance(at(np.array([middle])))[0] < 0:
            inside = middle
        else:
            outside = middle
    return 0.5 * (outside + inside)
