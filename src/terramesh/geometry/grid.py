"""A domain known only on a regular grid: a sampled signed distance or a mask.

Shapes that come as rasters or volumes (a salt body picked in a velocity
model, a water mask, a level set from another code) have no formula for
their distance. :class:`GridDomain` interpolates a signed distance sampled
at the nodes of a regular 2-D or 3-D grid, and
:meth:`GridDomain.from_mask` builds that distance from a boolean mask with
a Euclidean distance transform. The interpolation is the one of
:class:`~terramesh.sizing.SizeGrid`.
"""

import numpy as np

from ..errors import GeometryError, checked_number
from ..sizing.grid import checked_axis, interpolate_on_grid
from .base import Domain, as_bbox

__all__ = ["GridDomain"]


def _grid_axes(axes):
    """The 2 or 3 validated axes of a grid, as a tuple of float64 arrays."""
    try:
        axes = list(axes)
    except TypeError as error:
        raise GeometryError(f"axes must be a sequence of 2 or 3 coordinate arrays (x, y[, z]), got {axes!r}") from error
    if len(axes) not in (2, 3):
        raise GeometryError(
            f"a GridDomain needs a 2-D or 3-D grid: 2 or 3 coordinate arrays (x, y[, z]), got {len(axes)} axes"
        )
    return tuple(checked_axis(axis, name, GeometryError) for axis, name in zip(axes, "xyz", strict=False))


def _box_edges(dim):
    """The box's edges as (axis along the edge, index of each other axis: 0 or -1), 4 in 2-D, 12 in 3-D."""
    edges = []
    for along in range(dim):
        others = [axis for axis in range(dim) if axis != along]
        for ends in np.ndindex(*(2,) * len(others)):
            edges.append((along, dict(zip(others, (-end for end in ends), strict=True))))
    return edges


def _zero_between(coordinate, step, line, i):
    """Where ``line``, values along an axis at ``coordinate`` (linear between nodes), crosses zero after node ``i``."""
    return coordinate[i] + step * line[i] / (line[i] - line[i + 1])


class GridDomain(Domain):
    """Domain whose signed distance is given at the nodes of a regular 2-D or 3-D grid.

    Parameters
    ----------
    axes : sequence of array_like
        Two or three evenly spaced, strictly increasing coordinate arrays
        ``(x, y[, z])``, each of at least two nodes, in the domain's units
        (metres, say; for seismic volumes z is negative downward).
    distance_values : array_like, shape (len(x), len(y)[, len(z)])
        Signed distance to the boundary at each node, negative inside, in
        the units of the coordinates, indexed ``[ix, iy(, iz)]`` (NumPy's
        ``indexing="ij"``). Finite, with at least one negative node. Copied.

    Attributes
    ----------
    axes : tuple of numpy.ndarray
        The node coordinates per axis, float64.
    values : numpy.ndarray
        The node distances, float64, read-only.
    spacing : numpy.ndarray, shape (dim,)
        Node spacing per axis.

    Raises
    ------
    GeometryError
        If the grid has fewer than 2 or more than 3 axes, an axis is not
        evenly spaced and increasing, the values do not match the axes'
        shape, are NaN or infinite, or no node is inside.

    See Also
    --------
    GridDomain.from_mask : the same from a boolean inside/outside mask.
    terramesh.sizing.SizeGrid : edge lengths on a grid, interpolated the same way.

    Notes
    -----
    Inside the grid box the distance is the (bi/tri)linear interpolation of
    the node values. Near the boundary, that of an exact distance sampled at
    spacing ``s`` is within ``s**2 / 8`` times the sum of the boundary's
    principal curvatures of it (``1 / R`` on a circle, ``2 / R`` on a
    sphere of radius ``R``). A level-set function that is not a distance
    still defines the shape, but the generator's tolerances assume
    distances: ``GridDomain.from_mask(axes, level < 0)`` turns it into one.
    The domain is the part of the grid box where it is negative: the
    grid says nothing about what lies beyond it, so a shape that reaches the
    grid's edge (a water mask touching the raster border) is cut there,
    with the box faces as boundary and the points where the cut meets the
    box's edges and corners as :meth:`corners`. In formulas, with ``f`` the
    interpolation, ``c`` the nearest point of the box and ``b`` the box's
    own signed distance, ``distance(p) = max(f(c) + |p - c|, b(p))``. For a
    shape that stays off the grid's edge (``f >= 0`` there) this is ``f`` in
    the box and, beyond it, the value at the nearest box point plus the
    distance to the box, which is positive and grows outward.

    The interpolation of even an exact distance changes a little faster
    than 1 per unit length between nodes, so ``lipschitz`` is False and the
    generator evaluates every point.

    ``bbox`` is the bounding box of the inside nodes padded by one node
    spacing (an interpolated value is negative only in a cell with a
    negative corner), clipped to the grid box: tighter than the grid for a
    small shape in a large model, which saves the generator seeding empty
    space.

    Examples
    --------
    A unit disk from its exact distance, sampled every 0.1:

    >>> import numpy as np
    >>> x = np.linspace(-2, 2, 41)
    >>> X, Y = np.meshgrid(x, x, indexing="ij")
    >>> disk = GridDomain((x, x), np.hypot(X, Y) - 1.0)
    >>> disk.distance([(0.0, 0.0), (0.5, 0.0), (0.0, 3.0)]).round(3).tolist()
    [-1.0, -0.5, 2.0]
    >>> disk.bbox.round(3).tolist()
    [[-1.0, -1.0], [1.0, 1.0]]
    """

    lipschitz = False

    def __init__(self, axes, distance_values):
        self.axes = _grid_axes(axes)
        try:
            values = np.array(distance_values, dtype=np.float64, order="C")
        except (TypeError, ValueError) as error:
            raise GeometryError("GridDomain distance values must be an array of numbers") from error
        shape = tuple(axis.size for axis in self.axes)
        if values.shape != shape:
            raise GeometryError(f"distance values have shape {values.shape}, the grid axes need {shape}")
        bad = ~np.isfinite(values)
        if bad.any():
            raise GeometryError(f"the distance grid has {int(bad.sum())} NaN or infinite values")
        inside = values < 0
        if not inside.any():
            raise GeometryError("no grid node has a negative distance: the domain would be empty")
        values.flags.writeable = False
        self.values = values
        self._origin = np.array([axis[0] for axis in self.axes])
        self.spacing = np.array([axis[1] - axis[0] for axis in self.axes])
        self._box = np.array([self._origin, [axis[-1] for axis in self.axes]])
        # per-axis reductions: the indices of every inside node of a large volume would not fit in memory
        first, last = np.empty(values.ndim), np.empty(values.ndim)
        for axis in range(values.ndim):
            used = np.flatnonzero(inside.any(axis=tuple(other for other in range(values.ndim) if other != axis)))
            first[axis], last[axis] = used[0], used[-1]
        low = self._origin + (first - 1) * self.spacing
        high = self._origin + (last + 1) * self.spacing
        self.bbox = as_bbox([np.maximum(low, self._box[0]), np.minimum(high, self._box[1])], dim=len(self.axes))

    @classmethod
    def from_mask(cls, axes, inside, *, smoothing=1.0):
        """Build the domain from a boolean mask of the nodes inside the shape.

        The signed distance at a node is its Euclidean distance to the
        nearest node of the other kind (``scipy.ndimage.distance_transform_edt``
        with the grid spacing as sampling) less half a node spacing, negated
        inside. The zero level then runs halfway between neighbouring inside
        and outside nodes, so the boundary lies within half a cell of the
        shape the mask was drawn from. That level is a staircase, though, and
        a mesh with edges of a few cells follows its steps with slivers; a
        Gaussian filter of the distance (``smoothing``) rounds them off.

        Parameters
        ----------
        axes : sequence of array_like
            Two or three evenly spaced, increasing coordinate arrays
            ``(x, y[, z])``, in the domain's units.
        inside : array_like of bool, shape (len(x), len(y)[, len(z)])
            True at the nodes inside the shape, indexed ``[ix, iy(, iz)]``;
            integers 0 and 1 are accepted too. At least one node must be inside.
        smoothing : float, optional
            Standard deviation of the Gaussian filter applied to the signed
            distance, in node spacings along each axis; 0 keeps the
            staircase. With the default, 1, meshes with edges of 2.5 cells
            or longer come out as good as from the exact distance (measured
            on a disk and a ball); without the filter they have slivers.

        Returns
        -------
        GridDomain

        Raises
        ------
        GeometryError
            For bad axes, a mask of the wrong shape or with values other
            than True/False (0/1), a negative or non-finite ``smoothing``, or
            a mask with no node inside (before or after smoothing).

        Notes
        -----
        With unequal spacings, half the smallest one is subtracted, which
        overstates distances by at most half the difference of the spacings;
        the zero level stays halfway between nodes either way, as both sides
        of a boundary lose the same amount.

        The filter leaves a flat boundary where it is, but moves a curved one
        by ``sigma**2 / 2`` times the Laplacian of the distance (inward by
        ``sigma**2 / R`` on a ball of radius ``R``, ``sigma`` the filter's
        width in length units). That leading term is subtracted, with the
        Laplacian of the field filtered twice (a second-order difference of
        the once-filtered field brings back part of the steps). On a ball of
        radius 10 cells the mean radial error of the boundary is then
        -0.07 cells instead of -0.17 (-0.05 without the filter); the largest
        stays under half a cell. Parts of the shape thinner than about two
        cells fade away under the filter: keep them with ``smoothing=0``.

        A mask with every node inside is the grid box itself. The transform
        and the filter cost a few float64 arrays of the mask's size.

        Examples
        --------
        >>> import numpy as np
        >>> x = np.linspace(-2, 2, 41)
        >>> X, Y = np.meshgrid(x, x, indexing="ij")
        >>> disk = GridDomain.from_mask((x, x), X**2 + Y**2 < 1.0)
        >>> disk.distance([(0.5, 0.0), (1.5, 0.0)]).round(3).tolist()
        [-0.457, 0.55]
        >>> raw = GridDomain.from_mask((x, x), X**2 + Y**2 < 1.0, smoothing=0)
        >>> bool(np.abs(raw.distance([(0.95, 0.0), (0.0, -0.95)])).max() < 1e-12)  # halfway between nodes
        True
        """
        from scipy.ndimage import distance_transform_edt, gaussian_filter, laplace

        axes = _grid_axes(axes)
        smoothing = checked_number(
            smoothing, "smoothing must be a zero or positive finite number of node spacings", GeometryError, minimum=0
        )
        mask = np.asarray(inside)
        shape = tuple(axis.size for axis in axes)
        if mask.shape != shape:
            raise GeometryError(f"the mask has shape {mask.shape}, the grid axes need {shape}")
        if mask.dtype != np.bool_:
            if not (np.issubdtype(mask.dtype, np.number) and np.all((mask == 0) | (mask == 1))):
                raise GeometryError(
                    "the mask must be boolean (True inside) or hold only 0 and 1; "
                    "for a signed distance use GridDomain(axes, distance_values)"
                )
            mask = mask != 0
        if not mask.any():
            raise GeometryError("the mask has no node inside: the domain would be empty")
        spacing = np.array([axis[1] - axis[0] for axis in axes])
        if mask.all():
            # nothing outside to measure from: the domain is the box, whose own distance takes over
            extent = np.array([axis[-1] - axis[0] for axis in axes])
            values = np.full(shape, -float(np.sqrt(np.sum(extent**2))))
        else:
            half = 0.5 * spacing.min()
            depth = distance_transform_edt(mask, sampling=spacing)
            reach = distance_transform_edt(~mask, sampling=spacing)
            values = np.where(mask, half - depth, reach - half)
            if smoothing > 0:
                # point-reflected padding continues a linear field linearly, so a flat boundary reaching the
                # grid's edge stays where it is there too
                pad = 2 * int(np.ceil(4.0 * smoothing)) + 1
                values = np.pad(values, pad, mode="reflect", reflect_type="odd")
                values = gaussian_filter(values, smoothing, mode="nearest")
                # the filter moves a curved level by (sigma**2 / 2) times the Laplacian: take that back, from a
                # field filtered twice so that the correction does not bring the steps back
                again = gaussian_filter(values, smoothing, mode="nearest")
                values -= 0.5 * smoothing**2 * laplace(again, mode="nearest")
                values = values[(slice(pad, -pad),) * mask.ndim]
                if not np.any(values < 0):
                    raise GeometryError(
                        f"no node is inside after smoothing: the mask's inside parts are thinner than the filter "
                        f"(smoothing={smoothing:g} node spacings); pass a smaller smoothing, or 0"
                    )
        return cls(axes, values)

    def _distance(self, points):
        low, high = self._box
        nearest = np.clip(points, low, high)
        gap = np.sqrt(np.sum((points - nearest) ** 2, axis=1))
        field = interpolate_on_grid(self.values, self._origin, self.spacing, nearest) + gap
        depth = np.min(np.minimum(points - low, high - points), axis=1)
        box = gap - np.maximum(depth, 0.0)
        return np.maximum(field, box)

    def sharp_edges(self):
        """Where the grid box cuts the shape: its edges inside, and contours on its faces (3-D; none in 2-D).

        Where the shape reaches the grid's edge, the box's faces cut it and
        the box's edges, where inside, are sharp edges of the domain: the
        3D generator fixes points along them (a box's own edges left
        unheld made slivers of 5 degrees). Each run of inside nodes along
        an edge gives one segment, ending at the box's corners or where the
        (linear) interpolation along the edge crosses zero, the ends among
        :meth:`corners`. Where the shape's own surface meets a box face (a
        topography reaching the model's sides) there is one as well: the
        zero contours of each face's values (marching squares), their points
        moved onto the interpolated zero level within the face.

        Returns
        -------
        list of callable
            Each maps parameters ``t`` in [0, 1], shape ``(m,)``, to points
            on the edge, shape ``(m, 3)``, with the two coordinates of the
            box faces it lies on exactly.

        Examples
        --------
        >>> import numpy as np
        >>> x = np.linspace(0, 1, 11)
        >>> block = GridDomain((x, x, x), -np.ones((11, 11, 11)))  # the whole grid box
        >>> edges = block.sharp_edges()
        >>> len(edges), edges[0](np.array([0.0, 1.0])).tolist()
        (12, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
        """
        from .primitives3d import segment_curve

        if self.dim != 3:
            return []
        curves = []
        for along, fixed in _box_edges(3):
            line = self.values[tuple(fixed.get(axis, slice(None)) for axis in range(3))]
            inside = np.concatenate([[False], line < 0, [False]])
            first = np.flatnonzero(inside[1:-1] & ~inside[:-2])  # a run's first and last inside nodes
            last = np.flatnonzero(inside[1:-1] & ~inside[2:])
            step = self.spacing[along]
            coordinate = self.axes[along]
            corner = np.array([self.axes[axis][fixed[axis]] if axis in fixed else 0.0 for axis in range(3)])
            for i, j in zip(first, last, strict=True):
                low = coordinate[0] if i == 0 else _zero_between(coordinate, step, line, i - 1)
                high = coordinate[-1] if j == len(line) - 1 else _zero_between(coordinate, step, line, j)
                if high > low:
                    start, end = corner.copy(), corner.copy()
                    start[along], end[along] = low, high
                    curves.append(segment_curve(start, end, along))
        return curves + self._face_contours()

    def _face_contours(self):
        """The zero contours of the values on the grid box's six faces, as :class:`_FaceContour` curves."""
        from contourpy import contour_generator

        contours = []
        for axis in range(3):
            u, v = (other for other in range(3) if other != axis)
            for end in (0, -1):
                face = np.take(self.values, end, axis=axis)  # (len(axes[u]), len(axes[v]))
                if face.min() >= 0 or face.max() < 0:
                    continue
                lines = contour_generator(x=self.axes[u], y=self.axes[v], z=face.T, line_type="Separate").lines(0.0)
                for line in lines:
                    if len(line) >= 2:
                        contours.append(_FaceContour(self, axis, self.axes[axis][end], (u, v), line))
        return contours

    def corners(self):
        """Where a shape cut by the grid's edge has corners, shape ``(k, dim)``.

        The grid box's corners that are inside, and the points where the
        zero level crosses the box's edges (4 sides in 2-D, 12 edges in 3-D),
        found by linear interpolation along them. Empty for a shape that
        stays off the grid's edge.
        """
        found = []
        for corner in np.ndindex(*(2,) * self.dim):
            if self.values[tuple(-bit for bit in corner)] < 0:
                found.append(self._box[list(corner), range(self.dim)])
        for along, fixed in _box_edges(self.dim):
            index = tuple(fixed.get(axis, slice(None)) for axis in range(self.dim))
            line = self.values[index]
            start = np.flatnonzero((line[:-1] < 0) != (line[1:] < 0))
            if len(start) == 0:
                continue
            points = np.empty((len(start), self.dim))
            for axis, end in fixed.items():
                points[:, axis] = self.axes[axis][end]
            points[:, along] = _zero_between(self.axes[along], self.spacing[along], line, start)
            found.append(points)
        if not found:
            return np.empty((0, self.dim))
        return np.unique(np.vstack(found), axis=0)


class _FaceContour:
    """A zero contour of a :class:`GridDomain`'s values on a face of its box, as a curve ``t -> points``.

    ``line`` (k, 2) is the marching-squares polyline in the face's two
    coordinates ``axes``; its vertices lie on grid lines, where the
    interpolation is linear and they are exact. Between them the polyline
    cuts the (bilinear) contour by up to ``spacing**2`` times its curvature,
    so each point is moved onto the zero level along the face's gradient
    (two Newton steps). Parameter ``t`` runs along the polyline by arc
    length; a closed one (first vertex repeated) is periodic (``closed``).
    """

    def __init__(self, domain, axis, coordinate, axes, line):
        self._domain, self._axis, self._coordinate, self._axes = domain, axis, float(coordinate), axes
        self.closed = bool(np.array_equal(line[0], line[-1]))
        self._line = np.asarray(line, dtype=np.float64)
        length = np.concatenate([[0.0], np.cumsum(np.sqrt(np.sum(np.diff(self._line, axis=0) ** 2, axis=1)))])
        self._arc = length / length[-1] if length[-1] > 0 else np.linspace(0.0, 1.0, len(length))

    def __call__(self, t):
        t = np.asarray(t, dtype=np.float64)
        t = t % 1.0 if self.closed else np.clip(t, 0.0, 1.0)
        u, v = self._axes
        points = np.empty((len(t), 3))
        points[:, self._axis] = self._coordinate
        points[:, u] = np.interp(t, self._arc, self._line[:, 0])
        points[:, v] = np.interp(t, self._arc, self._line[:, 1])
        domain = self._domain
        low, high = domain._box
        for _ in range(2):
            value = interpolate_on_grid(domain.values, domain._origin, domain.spacing, points)
            gradient = np.zeros((len(points), 2))
            for k, along in enumerate((u, v)):
                step = 1e-6 * domain.spacing[along]
                shifted = points.copy()
                shifted[:, along] += step
                gradient[:, k] = (
                    interpolate_on_grid(domain.values, domain._origin, domain.spacing, shifted) - value
                ) / step
            norm2 = np.maximum(np.sum(gradient**2, axis=1), 1e-300)
            for k, along in enumerate((u, v)):
                points[:, along] = np.clip(points[:, along] - value * gradient[:, k] / norm2, low[along], high[along])
        return points
