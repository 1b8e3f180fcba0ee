"""The domain protocol: a signed distance function with a bounding box.

A *domain* is anything with a ``distance(points)`` method returning the signed
distance of each point to the domain boundary (negative inside, positive
outside) and a ``bbox`` attribute, an array of shape ``(2, dim)`` holding the
lower and upper corners. The classes here share that protocol, and plain
callables are wrapped by :func:`as_domain`.
"""

import numpy as np

from ..errors import GeometryError

__all__ = [
    "Domain",
    "FunctionDomain",
    "as_domain",
    "as_bbox",
    "as_points",
    "distance_gradient",
    "distance_and_gradient",
    "probe_directions",
]

ONE_CALL_COORDINATES = 2**16
"""Point coordinates (n * dim) up to which :func:`distance_and_gradient` evaluates in one call."""


def as_points(points, dim):
    """Return ``points`` as a C-contiguous float64 array of shape ``(n, dim)``.

    Raises
    ------
    GeometryError
        If the array does not have shape ``(n, dim)``, or has NaN or
        infinite coordinates.
    """
    array = np.ascontiguousarray(points, dtype=np.float64)
    if array.ndim == 1 and array.shape[0] == dim:
        array = array.reshape(1, dim)
    if array.ndim != 2 or array.shape[1] != dim:
        raise GeometryError(f"points must have shape (n, {dim}), got {np.shape(points)}")
    # one sum is the quick look (0.4 ms at 10**6 points); only a non-finite one (or an overflow) looks closer
    if not np.isfinite(array.sum()) and not np.isfinite(array).all():
        bad = ~np.isfinite(array).all(axis=1)
        raise GeometryError(
            f"points must be finite: {int(bad.sum())} of {len(array)} have NaN or infinite coordinates "
            f"(index {int(np.argmax(bad))} first)"
        )
    return array


def distance_gradient(domain, points, distance, step):
    """Forward-difference gradient of a domain's signed distance at ``points`` (the outward normal on the boundary).

    Parameters
    ----------
    domain : Domain or callable
        Signed distance function of ``(n, dim)`` points.
    points : numpy.ndarray, shape (n, dim)
    distance : numpy.ndarray, shape (n,)
        The signed distance at ``points`` (evaluated once by the caller).
    step : float or numpy.ndarray, shape (n,)
        Difference step, in the points' units: one for all or one per point.

    Returns
    -------
    numpy.ndarray, shape (n, dim)
        Unit length to the step's accuracy where the distance is exact.

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> disk = tm.geometry.Disk((0, 0), 1)
    >>> at = np.array([[0.0, 1.0]])
    >>> np.round(distance_gradient(disk, at, disk.distance(at), 1e-6), 4)
    array([[0., 1.]])
    """
    return _forward_differences(domain, points, step, distance)[1]


def distance_and_gradient(domain, points, step):
    """A domain's signed distance at ``points`` and its forward-difference gradient, from one call of the distance.

    As ``distance_gradient(domain, points, domain.distance(points), step)``,
    for callers that need both: a few points (a Newton projection's) cost
    the distance function's fixed overhead once, not ``dim + 1`` times.

    Returns
    -------
    distance : numpy.ndarray, shape (n,)
    gradient : numpy.ndarray, shape (n, dim)

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> distance, gradient = distance_and_gradient(tm.geometry.Disk((0, 0), 1), np.array([[0.0, 2.0]]), 1e-6)
    >>> distance.round(6).tolist(), gradient.round(4).tolist()
    ([1.0], [[0.0, 1.0]])
    """
    return _forward_differences(domain, points, step)


def _forward_differences(domain, points, step, distance=None):
    """``(distance, gradient)`` by forward differences; the distance evaluated with the shifted points where not given.

    Up to ``ONE_CALL_COORDINATES`` coordinates (points times ``dim``) go in one call
    of the distance (its fixed cost, a polygon's 20-200 us, was most of a
    projection of a few points); beyond, one call per axis bounds the memory.
    """
    n, dim = points.shape
    step = np.asarray(step, dtype=np.float64)
    if n * dim > ONE_CALL_COORDINATES:
        if distance is None:
            distance = domain.distance(points)
        gradient = np.empty_like(points)
        for axis in range(dim):
            shifted = points.copy()
            shifted[:, axis] += step
            gradient[:, axis] = (domain.distance(shifted) - distance) / step
        return distance, gradient
    given = distance is not None
    stacked = np.repeat(points[None], dim + (not given), axis=0)  # (dim [+ 1], n, dim): the shifted, then the points
    for axis in range(dim):
        stacked[axis, :, axis] += step
    values = np.asarray(domain.distance(stacked.reshape(-1, dim)), dtype=np.float64).reshape(len(stacked), n)
    if not given:
        distance = values[dim]
    return distance, ((values[:dim] - distance) / step).T


def probe_directions(dim):
    """The ``3**dim - 1`` unit directions from a cube's centre to its faces, edges and corners, shape (k, dim).

    Points a small step away in all of them tell a point inside a domain
    whose distance reads zero (a face two operands of a union share) from a
    point on its boundary, a re-entrant corner included: beside the
    boundary one of them is outside.

    Examples
    --------
    >>> probe_directions(2).shape, probe_directions(3).shape
    ((8, 2), (26, 3))
    """
    grid = np.stack(np.meshgrid(*[[-1.0, 0.0, 1.0]] * dim, indexing="ij"), axis=-1).reshape(-1, dim)
    grid = grid[np.any(grid != 0, axis=1)]
    return grid / np.linalg.norm(grid, axis=1, keepdims=True)


def as_bbox(bbox, dim=None):
    """Validate a bounding box given as ``[[xmin, ymin, ...], [xmax, ymax, ...]]``.

    Parameters
    ----------
    bbox : array_like, shape (2, dim)
        Lower corner then upper corner, in the domain's units.
    dim : int, optional
        Expected number of dimensions.

    Returns
    -------
    numpy.ndarray, shape (2, dim), float64

    Raises
    ------
    GeometryError
        If the box has the wrong shape, non-finite values, or zero or negative extent.

    Examples
    --------
    >>> as_bbox([(0, 0), (2, 1)]).tolist()
    [[0.0, 0.0], [2.0, 1.0]]
    """
    try:
        box = np.array(bbox, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise GeometryError(f"bbox must be numbers [[xmin, ymin], [xmax, ymax]], got {bbox!r}") from error
    if box.ndim != 2 or box.shape[0] != 2 or (dim is not None and box.shape[1] != dim):
        expected = f"(2, {dim})" if dim is not None else "(2, dim)"
        raise GeometryError(
            f"bbox must have shape {expected}: the lower corner then the upper corner, "
            f"e.g. [[xmin, ymin], [xmax, ymax]]; got shape {box.shape}"
        )
    if not np.all(np.isfinite(box)):
        raise GeometryError(f"bbox has non-finite values: {box.tolist()}")
    if np.any(box[1] <= box[0]):
        raise GeometryError(f"bbox upper corner must exceed the lower corner on every axis: {box.tolist()}")
    return box


class Domain:
    """Base class of the geometry objects: signed distance plus bounding box.

    Subclasses set ``self.bbox`` (shape ``(2, dim)``) and implement
    ``_distance(points)`` on a validated ``(n, dim)`` float64 array.
    The operators ``|``, ``&`` and ``-`` build unions, intersections and
    differences.
    """

    bbox: np.ndarray
    #: the distance changes no faster than the point moves, so the generator may skip far interior
    #: points. The primitives and polygons say so, a combination where all its operands do; a
    #: subclass claims it only when true (a distance scaled by 100 claimed it: meshes with boundary
    #: edges 3.3 sizes long, and a 100x ellipse cut to a box lost 29 % of its area)
    lipschitz = False

    @property
    def dim(self):
        """Number of space dimensions."""
        return self.bbox.shape[1]

    def distance(self, points):
        """Signed distance from each point to the boundary (negative inside).

        Parameters
        ----------
        points : array_like, shape (n, dim)
            Coordinates in the domain's units.

        Returns
        -------
        numpy.ndarray, shape (n,)
            Signed distance in the same units.
        """
        return self._distance(as_points(points, self.dim))

    def distance_within(self, points, limit):
        """The signed distance where it is below ``limit`` in magnitude, ``-limit`` or ``limit`` elsewhere.

        For callers that only compare distances with thresholds up to
        ``limit`` (the seeding's lattice levels): geometries whose far
        distances are costly (a polygon's) override it to skip them.

        Examples
        --------
        >>> from terramesh.geometry import Disk
        >>> Disk((0, 0), 1).distance_within([(0.0, 0.5), (0.0, 3.0)], 1.0).tolist()
        [-0.5, 1.0]
        """
        return np.clip(self.distance(points), -limit, limit)

    def inside(self, points, tolerance=0.0):
        """Mask of the points inside by more than ``tolerance`` (``distance < -tolerance``).

        Geometries with a cheaper inside test than a full distance override it.

        Examples
        --------
        >>> from terramesh.geometry import Disk
        >>> Disk((0, 0), 1).inside([(0.0, 0.5), (0.0, 0.999), (2.0, 0.0)], 0.01).tolist()
        [True, False, False]
        """
        return self.distance(points) < -tolerance

    def __call__(self, points):
        """Same as :meth:`distance`, so a domain is a plain distance function too."""
        return self.distance(points)

    def corners(self):
        """Sharp boundary points a mesh should keep as vertices, shape ``(k, dim)``."""
        return np.empty((0, self.dim))

    def __or__(self, other):
        from .csg import Union

        return Union([self, other])

    def __and__(self, other):
        from .csg import Intersection

        return Intersection([self, other])

    def __sub__(self, other):
        from .csg import Difference

        return Difference([self, other])


class FunctionDomain(Domain):
    """Wrap a user's signed distance callable and its bounding box.

    Parameters
    ----------
    function : callable
        Maps an ``(n, dim)`` array to ``n`` signed distances (negative inside).
    bbox : array_like, shape (2, dim)
        Box that contains the domain.
    corners : array_like, shape (k, dim), optional
        Points of the boundary the mesh must keep as vertices (where it
        turns sharply). The distance function cannot tell the generator
        where they are; a corner left out is rounded off.
    sharp_edges : list, optional
        3D only: the curves along which the boundary turns sharply (where
        two faces meet), each an ``(m, 3)`` polyline or a callable mapping
        parameters ``t`` in [0, 1], shape ``(m,)``, to points on the edge,
        shape ``(m, 3)``. A curve whose two ends coincide is a loop. The 3D
        generator spaces points along them by the size and holds them; a
        sharp edge it is not told of is rounded, and slivers or faces across
        the boundary make it raise (a wedge prism of 20-60 degrees at two
        sizes did in 8 of 8 without its edges, and in none with them). Their
        ends are corners too (``sharp_edges=[]`` says there are none). In
        a combination (``|``, ``&``, ``-``) the pieces of them on its
        boundary are kept, but the curves where the function's faces meet
        another operand are known to no one: the mesh rounds them, with a
        warning where boundary vertices stay off the boundary (a ball cut
        from a wedge prism at h = 0.05: up to 0.03 sizes), or the generator
        raises (a box on a wedge prism at h = 0.04-0.06); give such a
        combination as one FunctionDomain with all its edges.

    Raises
    ------
    GeometryError
        For a function that is not callable, corners or an edge off the
        boundary (farther than ``1e-6`` of the bbox's largest side), or
        sharp edges of a 2D domain.

    Examples
    --------
    >>> import numpy as np
    >>> ring = FunctionDomain(lambda p: np.abs(np.hypot(p[:, 0], p[:, 1]) - 1.0) - 0.2,
    ...                       bbox=[(-1.2, -1.2), (1.2, 1.2)])
    >>> ring.distance([[1.0, 0.0]]).round(3).tolist()
    [-0.2]

    A prism whose edges the generator is told of:

    >>> slab = FunctionDomain(
    ...     lambda p: np.max(np.abs(p) - (1.0, 1.0, 0.1), axis=1), [(-1, -1, -0.1), (1, 1, 0.1)],
    ...     sharp_edges=[[(x, y, z) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))] for z in (-0.1, 0.1)]
    ...     + [[(x, y, -0.1), (x, y, 0.1)] for x in (-1, 1) for y in (-1, 1)],
    ... )
    >>> len(slab.sharp_edges()), len(slab.corners())
    (6, 8)
    """

    lipschitz = False

    def __init__(self, function, bbox, *, corners=None, sharp_edges=None):
        from .curves import checked_curves, checked_on_boundary, curve_ends

        if not callable(function):
            raise GeometryError(f"a domain must be callable, got {type(function).__name__}")
        self.function = function
        self.bbox = as_bbox(bbox)
        self._sharp_edges = checked_curves(sharp_edges, self.dim, self.distance, self.bbox)
        #: whether the sharp edges were given (an empty list says there are none), which the 3D generator's errors use
        self.sharp_edges_given = sharp_edges is not None
        given = np.empty((0, self.dim)) if corners is None or np.size(corners) == 0 else as_points(corners, self.dim)
        checked_on_boundary(given, self.distance, self.bbox, "the corners")
        self._corners = np.unique(np.concatenate([given, *map(curve_ends, self._sharp_edges)]), axis=0)

    def corners(self):
        """The corners given, and the ends of the sharp edges given, shape ``(k, dim)``."""
        return self._corners.copy()

    def sharp_edges(self):
        """The sharp edges given, as callables ``t -> points`` (see the class's ``sharp_edges``)."""
        return list(self._sharp_edges)

    def _distance(self, points):
        values = np.asarray(self.function(points))
        if values.dtype.kind not in "iuf":  # complex parts were dropped with a NumPy warning
            raise GeometryError(f"the distance function must return real numbers, got an array of {values.dtype}")
        values = values.astype(np.float64, copy=False).reshape(-1)
        if values.shape[0] != points.shape[0]:
            raise GeometryError(f"the distance function returned {values.shape[0]} values for {points.shape[0]} points")
        bad = ~np.isfinite(values)
        if bad.any():  # else "points must be finite" came later, from the triangulation
            first = points[np.argmax(bad)]
            raise GeometryError(
                f"the distance function returned NaN or infinite values at {int(bad.sum())} of {len(values)} points "
                f"(the first at ({first[0]:.6g}, {first[1]:.6g}{'' if len(first) == 2 else f', {first[2]:.6g}'}))"
            )
        return values


def as_domain(domain, bbox=None):
    """Return ``domain`` as a :class:`Domain`.

    Parameters
    ----------
    domain : Domain or callable
        A terramesh geometry, or a callable signed distance function. A
        callable needs a ``bbox`` attribute or the ``bbox`` argument.
    bbox : array_like, shape (2, dim), optional
        Bounding box for a plain callable.

    Raises
    ------
    GeometryError
        If ``domain`` is neither, or a callable comes without a bbox.

    Examples
    --------
    A signed distance function of the unit disk (negative inside), with
    its bbox; a terramesh geometry is returned as it is:

    >>> import numpy as np, terramesh as tm
    >>> disk = tm.geometry.as_domain(lambda p: np.hypot(p[:, 0], p[:, 1]) - 1.0, bbox=[[-1, -1], [1, 1]])
    >>> type(disk).__name__, disk.distance(np.array([[0.0, 0.0], [2.0, 0.0]])).tolist()
    ('FunctionDomain', [-1.0, 1.0])
    >>> square = tm.geometry.Rectangle((0, 0), (1, 1))
    >>> tm.geometry.as_domain(square) is square
    True
    """
    if isinstance(domain, Domain):
        return domain
    if callable(domain):
        box = bbox if bbox is not None else getattr(domain, "bbox", None)
        if box is None:
            raise GeometryError("a distance function needs a bbox: pass bbox=[[xmin, ymin], [xmax, ymax]]")
        return FunctionDomain(domain, box)
    raise GeometryError(f"expected a terramesh domain or a callable distance function, got {type(domain).__name__}")
