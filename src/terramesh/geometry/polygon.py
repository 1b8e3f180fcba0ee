"""Polygons (with holes and many parts) as signed distance functions."""

import numpy as np
import shapely

from ..errors import GeometryError
from .base import Domain, as_points
from .segments import SegmentIndex

__all__ = ["Polygon"]

GENTLE_REFLEX = 160.0  # reflex vertices whose edges meet at less than this, and more than 120, are gentle corners
BRIDGED_ARC = 5.0
"""Edge lengths of boundary between an edge's two crossings beyond which :meth:`Polygon.bridged_edges` reports it."""


def _rings_of(geometry):
    """Every ring (exterior and interior) of a shapely (multi)polygon, as arrays."""
    rings = []
    for part in shapely.get_parts(geometry):
        rings.append(shapely.get_coordinates(part.exterior))
        rings.extend(shapely.get_coordinates(hole) for hole in part.interiors)
    return rings


def _nesting(rings):
    """Each ring's nesting depth (the rings around it) and the (inner, outer) pairs of rings, one inside the other.

    Tested with each ring's first vertex, enough since rings do not touch.
    Each filled ring queries a tree of those points (``contains_properly``,
    the ring prepared once): the points querying a tree of rings tested
    each point against the whole largest ring, 3.7-4.4 s for Natural
    Earth's 3,128 rings at 2 km (319k vertices in the largest), now 0.1 s.
    """
    lengths = np.array([len(ring) for ring in rings])
    coordinates = np.concatenate(rings)
    filled = shapely.polygons(shapely.linearrings(coordinates, indices=np.repeat(np.arange(len(rings)), lengths)))
    firsts = shapely.points(coordinates[np.cumsum(lengths) - lengths])
    outer, inner = shapely.STRtree(firsts).query(filled, predicate="contains_properly")
    order = np.lexsort((outer, inner))
    inner, outer = inner[order], outer[order]
    return np.bincount(inner, minlength=len(rings)), inner, outer


def _a_crossing(rings):
    """A point where a ring crosses or touches itself or another ring, or None if none is found.

    Every test at once on prepared rings: the pairs of rings whose boxes meet,
    queried one ring at a time, took 6.3 s to find the pair of Natural
    Earth's 10m land (6,838 rings) that touch; now 0.1 s.
    """
    lengths = np.array([len(ring) for ring in rings])
    lines = shapely.linearrings(np.concatenate(rings), indices=np.repeat(np.arange(len(rings)), lengths))
    reasons = np.asarray(shapely.is_valid_reason(shapely.polygons(lines)), dtype=str)
    located = np.flatnonzero(np.char.find(reasons, "[") >= 0)  # "Self-intersection[x y]", "Ring Self-intersection[x y]"
    if len(located):
        return [float(value) for value in reasons[located[0]].split("[", 1)[1].rstrip("]").split()[:2]]
    shapely.prepare(lines)
    first, second = shapely.STRtree(lines).query(lines)
    first, second = first[first < second], second[first < second]
    meet = np.flatnonzero(shapely.intersects(lines[first], lines[second]))
    if len(meet) == 0:
        return None
    pair = meet[0]
    return shapely.get_coordinates(shapely.intersection(lines[first[pair]], lines[second[pair]]))[0].tolist()


def signed_ring_area(ring):
    """Signed area of a closed ring, shape (n, 2) (counter-clockwise positive), by the shoelace formula.

    Summed about the ring's first vertex: with raw coordinates far from the
    origin (UTM, 5e6 m) the products cancel to rounding, and a small ring's
    area came out 0 or of the wrong sign.

    Examples
    --------
    >>> import numpy as np
    >>> float(signed_ring_area(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]) + 5e6))
    0.5
    """
    x, y = (ring - ring[0]).T
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def _region_on_the_left(rings, depth):
    """The rings turned so that the region (inside an odd number of them) lies on the left of each.

    A ring at even depth is a shell (the region is its interior: turn it
    counter-clockwise), one at odd depth a hole (clockwise).
    """
    turned = []
    for ring, level in zip(rings, depth, strict=True):
        counter_clockwise = signed_ring_area(ring) > 0
        turned.append(ring if counter_clockwise == (level % 2 == 0) else ring[::-1])
    return turned


def _even_odd_region(rings, depth, inner, outer):
    """The region inside an odd number of the (disjoint, simple) rings, as a shapely geometry.

    ``depth``, ``inner``, ``outer`` as :func:`_nesting` gives them: even
    depths are shells, odd ones holes of the ring around them at depth one
    less.
    """
    holes = {}
    is_parent = (depth[outer] == depth[inner] - 1) & (depth[inner] % 2 == 1)
    for hole, shell in zip(inner[is_parent], outer[is_parent], strict=True):
        holes.setdefault(int(shell), []).append(rings[hole])
    parts = [shapely.Polygon(rings[i], holes.get(i, [])) for i in np.flatnonzero(depth % 2 == 0)]
    return parts[0] if len(parts) == 1 else shapely.MultiPolygon(parts)


class Polygon(Domain):
    """A planar region bounded by closed rings, with exact signed distance.

    The region is given by the even-odd rule: a point is inside when an odd
    number of rings enclose it. Holes, islands in holes and disjoint parts
    therefore need no labels. Rings must be simple and must not touch each
    other.

    Parameters
    ----------
    rings : array_like, shape (k, 2), or sequence of such arrays
        Ring vertices (x, y), any units; closing the ring by repeating the
        first vertex is optional.

    Raises
    ------
    GeometryError
        If there is no ring, a ring has fewer than three distinct vertices
        or non-finite coordinates, or rings self-intersect or cross.

    Notes
    -----
    The distance is exact near the boundary (a bucket grid of the segments)
    and within 1 % farther out (a KD-tree, ``O(log m)`` per point for ``m``
    segments). The sign near the boundary is the side of the nearest
    segment (the rings turned so that the region is on their left; at a
    vertex, the side of the bisector of its two segments' normals); farther
    out it comes from shapely's prepared point-in-polygon test.

    Examples
    --------
    >>> square = [(0, 0), (4, 0), (4, 4), (0, 4)]
    >>> hole = [(1, 1), (3, 1), (3, 3), (1, 3)]
    >>> frame = Polygon([square, hole])
    >>> frame.distance([(0.5, 2.0), (2.0, 2.0)]).tolist()
    [-0.5, 1.0]
    """

    lipschitz = True

    def __init__(self, rings):
        rings = self._validated_rings(rings)
        self.rings = rings
        lines = shapely.multilinestrings([shapely.linearrings(ring) for ring in rings])
        if not shapely.is_simple(lines):
            where = _a_crossing(rings)
            raise GeometryError(
                "polygon rings self-intersect or touch each other"
                + (f" (near ({where[0]:.6g}, {where[1]:.6g}))" if where is not None else "")
                + "; fix the geometry first: rings that cross with shapely.make_valid, rings that touch at a point "
                "(which shapely accepts, but a mesh would be pinched there) by parting them, e.g. with "
                "shapely.buffer(polygon, -d) for a d far below the mesh size"
            )
        depth, inner, outer = _nesting(rings)
        self.geometry = _even_odd_region(rings, depth, inner, outer)
        self._depth = depth
        self._parent = np.full(len(rings), -1)  # the ring just around each, -1 for none
        is_parent = depth[outer] == depth[inner] - 1
        self._parent[inner[is_parent]] = outer[is_parent]
        shapely.prepare(self.geometry)
        # the region on the left of every segment: the side of the nearest one is the sign
        turned = _region_on_the_left(rings, depth)
        starts = np.concatenate(turned)
        ends = np.concatenate([np.roll(ring, -1, axis=0) for ring in turned])
        first = np.cumsum([0] + [len(ring) for ring in turned])[:-1]
        following = np.arange(len(starts)) + 1
        following[first + np.array([len(ring) for ring in turned]) - 1] = first
        self._segments = SegmentIndex(starts, ends, following=following)
        self._centres_inside = None  # found at the first inside test
        everything = np.concatenate(rings)
        self.bbox = np.array([everything.min(axis=0), everything.max(axis=0)])

    @classmethod
    def from_shapely(cls, geometry):
        """Build from a shapely ``Polygon`` or ``MultiPolygon`` (holes kept).

        Raises
        ------
        GeometryError
            If the geometry is empty, not polygonal or invalid.

        Examples
        --------
        >>> import shapely
        >>> Polygon.from_shapely(shapely.box(0, 0, 2, 1)).bbox.tolist()
        [[0.0, 0.0], [2.0, 1.0]]
        """
        if not isinstance(geometry, (shapely.Polygon, shapely.MultiPolygon)):
            raise GeometryError(f"expected a shapely Polygon or MultiPolygon, got {type(geometry).__name__}")
        if geometry.is_empty:
            raise GeometryError("the polygon is empty")
        if not shapely.is_valid(geometry):
            raise GeometryError(f"invalid polygon: {shapely.is_valid_reason(geometry)}")
        return cls(_rings_of(geometry))

    @staticmethod
    def _validated_rings(rings):
        if isinstance(rings, np.ndarray) and rings.ndim == 2:
            rings = [rings]
        try:
            rings = [np.asarray(ring, dtype=np.float64) for ring in rings]
        except (TypeError, ValueError) as error:
            raise GeometryError(f"polygon rings must be arrays of (x, y) vertices: {error}") from error
        if len(rings) and all(ring.ndim == 1 for ring in rings):
            rings = [np.asarray(rings, dtype=np.float64)]
        if not rings:
            raise GeometryError("the polygon is empty: no rings given")
        cleaned = []
        for number, ring in enumerate(rings):
            if ring.ndim != 2 or ring.shape[1] != 2:
                raise GeometryError(f"ring {number} must have shape (k, 2), got {ring.shape}")
            if not np.all(np.isfinite(ring)):
                raise GeometryError(f"ring {number} has non-finite coordinates")
            if len(ring) > 1 and np.array_equal(ring[0], ring[-1]):
                ring = ring[:-1]
            keep = np.ones(len(ring), dtype=bool)
            keep[1:] = np.any(ring[1:] != ring[:-1], axis=1)
            ring = ring[keep]
            if len(ring) > 1 and np.array_equal(ring[0], ring[-1]):
                # the closing vertex repeated ([A, B, ..., A, A]): its last copy had stayed, an edge of no length
                # whose corner angle divided by zero
                ring = ring[:-1]
            if len(ring) < 3:
                raise GeometryError(f"ring {number} has fewer than three distinct vertices")
            cleaned.append(np.ascontiguousarray(ring))
        return cleaned

    def _distance(self, points):
        return self.distance_and_nearest(points)[0]

    def rings_missed(self, points, tolerance):
        """The rings that none of ``points`` lies on (within ``tolerance``), as ``(holes, parts)`` ring indices.

        A mesh's boundary vertices lie on the rings it keeps: a ring none of
        them is on is a hole that the cells cover or a part with no cells,
        both smaller than the mesh there. A hole of a part that is missed
        itself is not listed.

        Examples
        --------
        >>> frame = Polygon([[(0, 0), (4, 0), (4, 4), (0, 4)], [(1, 1), (3, 1), (3, 3), (1, 3)]])
        >>> frame.rings_missed([(0.0, 0.0), (4.0, 4.0), (0.0, 2.0)], 1e-9)
        ([1], [])
        """
        segment = self._segments.nearest_segments(as_points(points, 2), tolerance)
        # the segments are the rings' in order, ring after ring
        first = np.cumsum([0] + [len(ring) for ring in self.rings])[:-1]
        reached = np.zeros(len(self.rings), dtype=bool)
        reached[np.searchsorted(first, segment[segment >= 0], side="right") - 1] = True
        part = self._depth % 2 == 0
        parent_missed = np.zeros(len(self.rings), dtype=bool)
        has_parent = self._parent >= 0
        parent_missed[has_parent] = ~reached[self._parent[has_parent]]
        missed = ~reached & ~parent_missed  # within a missed ring, a ring's region went with it
        holes, parts = np.flatnonzero(missed & ~part), np.flatnonzero(missed & part)
        return holes.tolist(), parts.tolist()

    def distance_and_nearest(self, points, limit=None):
        """Signed distance and the nearest boundary point, NaN where far from the boundary.

        The nearest points come with the distances near the boundary, where
        the generator projects the points that went outside: the same as
        :meth:`project` there, without searching the segments again. With
        ``limit``, the segments are searched only about that far: a point
        farther from them gets a bound, ``-b`` inside and ``b`` outside
        (point in polygon) with ``limit <= b <=`` its distance (``b`` from
        the empty cells of the segment grid around it), where
        :meth:`distance_within` clips to ``limit`` (the distances the search
        found stay exact).

        Examples
        --------
        >>> distance, nearest = Polygon([(0, 0), (4, 0), (4, 4), (0, 4)]).distance_and_nearest([(2.0, -1.0)])
        >>> distance.tolist(), nearest.tolist()
        ([1.0], [[2.0, 0.0]])
        >>> Polygon([(0, 0), (4, 0), (4, 4), (0, 4)]).distance_and_nearest([(2.0, 2.0), (40.0, 2.0)], 0.5)[0].tolist()
        [-2.0, 0.5]
        """
        points = as_points(points, 2)
        distance, side, settled, nearest = self._segments.distance_and_side(points, limit, return_nearest=True)
        folded = np.flatnonzero(settled & (side == 0) & (distance > 0))  # a ring folding back onto itself
        if len(folded):
            side[folded] = self._sides(points[folded])
        far = np.flatnonzero(~settled)  # beyond the bucket grid's rings (within ``limit`` when given)
        if len(far):
            if limit is None:  # the grid's rings searched in vain: the KD-tree at once
                distance[far] = self._segments.distance(points[far], searched=True)
            else:  # a bound: the grid's empty cells around a point often tell far more than the search radius
                distance[far] = np.maximum(limit, self._segments.clearance(points[far]))
            side[far] = self._sides(points[far])
            nearest[far] = np.nan
        return np.where(side > 0, -distance, distance), nearest

    def distance_within(self, points, limit):
        """:meth:`Domain.distance_within`: segments searched only within ``limit``, point in polygon beyond.

        Examples
        --------
        >>> square = Polygon([(0, 0), (4, 0), (4, 4), (0, 4)])
        >>> square.distance_within([(2.0, 1.0), (2.0, 2.0), (9.0, 2.0)], 1.5).tolist()
        [-1.0, -1.5, 1.5]
        """
        return np.clip(self.distance_and_nearest(points, limit)[0], -limit, limit)

    def bridged_edges(self, points, edges, tolerance=0.0):
        """The edges that cross a part of the outside thinner than they are long, and where each first does.

        An edge that leaves the region and comes back in across the same
        ring cuts off the stretch of ring between the two crossings. Where
        that stretch is longer than :data:`BRIDGED_ARC` times the edge's
        own length across it, the edge joins what a thin feature separates
        (a breakwater, a barrier island, a cut or crack); a shorter stretch
        is a boundary wiggling below the mesh size, which the edge smooths
        (up to 4.1 lengths on random-walk coasts of 2,000 vertices meshed at
        0.03 and on GSHHS meshed at 2-20 km).

        DistMesh meshes across such features, as every generator that keeps
        the cells whose centroid is inside does: a cut 0.002 wide in a 2 x 1
        rectangle meshed at 0.05 is crossed by 16 edges, the area covered
        within 0.1 % of the domain's. Not checked by the generator (110-170 ms
        on coasts of 30-180 thousand vertices); call it where it matters.

        Parameters
        ----------
        points : array_like, shape (n, 2)
        edges : array_like of int, shape (e, 2)
        tolerance : float, optional
            Crossings nearer an edge's end than this are its end on the
            boundary, not a crossing.

        Returns
        -------
        indices : numpy.ndarray of int, shape (k,)
            The bridging edges, increasing.
        where : numpy.ndarray, shape (k, 2)
            The first crossing of each.

        Examples
        --------
        A 3 x 2 rectangle with a cut 0.02 wide down from its top side to 0.2:

        >>> cut = Polygon([(0, 0), (3, 0), (3, 2), (1.51, 2), (1.51, 0.2), (1.49, 0.2), (1.49, 2), (0, 2)])
        >>> indices, where = cut.bridged_edges([(1.3, 1.5), (1.7, 1.5), (1.3, 0.1)], [(0, 1), (0, 2)])
        >>> indices.tolist(), where.round(2).tolist()
        ([0], [[1.49, 1.5]])
        """
        points = as_points(points, 2)
        edges = np.asarray(edges)
        if edges.size == 0:
            return np.empty(0, dtype=np.int64), np.empty((0, 2))
        if edges.ndim != 2 or edges.shape[1] != 2 or edges.dtype.kind not in "iu":
            raise GeometryError(f"edges must be an (e, 2) array of vertex indices, got {edges.dtype} {edges.shape}")
        if edges.min() < 0 or edges.max() >= len(points):
            raise GeometryError(f"edges refer to vertices {edges.min()}..{edges.max()}, of {len(points)} points")
        a, b = points[edges[:, 0]], points[edges[:, 1]]
        length = np.hypot(*(b - a).T)
        # an edge can only cross where both its ends lie within its length of the boundary
        near = np.abs(self.distance_within(points, float(length.max(initial=0.0))))
        candidates = np.flatnonzero((near[edges[:, 0]] <= length) & (near[edges[:, 1]] <= length))
        starts = np.concatenate(self.rings)
        ends = np.concatenate([np.roll(ring, -1, axis=0) for ring in self.rings])
        ring_of = np.repeat(np.arange(len(self.rings)), [len(ring) for ring in self.rings])
        side = np.hypot(*(ends - starts).T)
        position = np.concatenate(
            [np.cumsum(piece) - piece for piece in np.split(side, np.cumsum([len(r) for r in self.rings])[:-1])]
        )
        perimeter = np.bincount(ring_of, weights=side)
        tree = shapely.STRtree(shapely.linestrings(np.stack([starts, ends], axis=1)))
        lines = shapely.linestrings(np.stack([a[candidates], b[candidates]], axis=1))
        edge, segment = tree.query(lines, predicate="intersects")
        edge = candidates[edge]
        # where each crossing lies, as fractions t along the edge and u along the side
        r, q = b[edge] - a[edge], ends[segment] - starts[segment]
        w = starts[segment] - a[edge]
        denominator = r[:, 0] * q[:, 1] - r[:, 1] * q[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[:, 0] * q[:, 1] - w[:, 1] * q[:, 0]) / denominator
            u = (w[:, 0] * r[:, 1] - w[:, 1] * r[:, 0]) / denominator
        inner = np.isfinite(t) & (t * length[edge] > tolerance) & ((1.0 - t) * length[edge] > tolerance)
        edge, segment, t, u = edge[inner], segment[inner], t[inner], u[inner]
        order = np.lexsort((t, edge))
        edge, segment, t, u = edge[order], segment[order], t[order], u[order]
        arc = position[segment] + u * side[segment]
        # consecutive crossings of one edge on one ring: the stretch between them, the shorter way round
        pair = (edge[1:] == edge[:-1]) & (ring_of[segment[1:]] == ring_of[segment[:-1]])
        # out and back in, not in and back out (an edge clipping both banks of a narrow channel)
        between = a[edge[1:]] + (0.5 * (t[1:] + t[:-1]))[:, None] * (b - a)[edge[1:]]
        pair[pair] = self.distance(between[pair]) > 0.0
        stretch = np.abs(arc[1:] - arc[:-1])
        stretch = np.minimum(stretch, perimeter[ring_of[segment[1:]]] - stretch)
        bridged = pair & (stretch > BRIDGED_ARC * length[edge[1:]])
        first = np.flatnonzero(bridged)  # the pair's first crossing
        indices, at = np.unique(edge[first], return_index=True)
        crossing = first[at]
        return indices, a[edge[crossing]] + t[crossing, None] * (b - a)[edge[crossing]]

    def project(self, points):
        """The nearest point of the boundary to each point, shape ``(n, 2)``.

        Exact near the boundary (where the generator projects); farther
        out, a boundary point within 1 % of the nearest distance.

        Examples
        --------
        >>> Polygon([(0, 0), (4, 0), (4, 4), (0, 4)]).project([(2.0, 1.0), (5.0, 5.0)]).tolist()
        [[2.0, 0.0], [4.0, 4.0]]
        """
        return self._segments.nearest_points(as_points(points, 2))

    def inside(self, points, tolerance=0.0):
        """Mask of the points inside by more than ``tolerance``: point in polygon, distances only near the edge.

        Examples
        --------
        >>> Polygon([(0, 0), (4, 0), (4, 4), (0, 4)]).inside([(2.0, 2.0), (2.0, 0.001), (5.0, 1.0)], 0.01).tolist()
        [True, False, False]
        """
        points = as_points(points, 2)
        side = self._segments.sides(points, self._centre_inside(), tolerance)
        inside = side > 0
        unsure = np.flatnonzero(side == 0)  # on the boundary, or in line with a segment and a cell's centre
        if len(unsure):
            near = points[unsure]
            distance, side, settled = self._segments.distance_and_side(near, tolerance)
            decided = settled & ((side != 0) | (distance <= tolerance))
            inside[unsure] = np.where(decided, (side > 0) & (distance > tolerance), self._contains(near))
        return inside

    def _centre_inside(self):
        """Which centres of the segment index's cells are inside (what :meth:`SegmentIndex.sides` starts from)."""
        if self._centres_inside is None:
            self._centres_inside = self._contains(self._segments.cell_centres())
        return self._centres_inside

    def _contains(self, points):
        return shapely.contains_xy(self.geometry, points[:, 0], points[:, 1])

    def _sides(self, points):
        """1 inside, -1 outside: the segment index's crossing count, point in polygon where it cannot tell."""
        side = self._segments.sides(points, self._centre_inside())
        unsure = np.flatnonzero(side == 0)
        side[unsure] = np.where(self._contains(points[unsure]), 1, -1)
        return side

    def gentle_reflex_corners(self, angle=GENTLE_REFLEX):
        """Reflex ring vertices that :meth:`corners` leaves out, turning by more than ``180 - angle`` degrees.

        Where the domain's boundary turns into it by 20-60 degrees (an inner
        angle of 200-240), the mesh's boundary cuts across the corner unless
        a vertex is fixed there: cells 19-31 % outside at 224-239 degrees in
        a square at h 0.02-0.1. On a coastline such vertices are its wiggles,
        spaced below the mesh size, across which cutting is meant: the
        generator fixes only those whose edges are both longer than the
        local size.

        Returns
        -------
        points : ndarray, shape (k, 2)
        shorter_edge : ndarray, shape (k,)
            The shorter of each vertex's two edges.

        Examples
        --------
        >>> notch = Polygon([(0, 0), (1, 0), (1, 1), (0.5, 0.72), (0, 1)])
        >>> points, shorter_edge = notch.gentle_reflex_corners()
        >>> points.tolist(), shorter_edge.round(3).tolist()
        ([[0.5, 0.72]], [0.573])
        """
        points, shorter = [], []
        for ring in self.rings:
            before = ring - np.roll(ring, 1, axis=0)
            after = np.roll(ring, -1, axis=0) - ring
            length_before, length_after = np.hypot(*before.T), np.hypot(*after.T)
            vertex_angle = _angle_between(before, after)
            # the domain is on each ring's left (outer rings counter-clockwise, holes clockwise): a right turn is reflex
            reflex = before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0] < 0
            gentle = reflex & (vertex_angle >= 120.0) & (vertex_angle < angle)
            points.append(ring[gentle])
            shorter.append(np.minimum(length_before, length_after)[gentle])
        return np.concatenate(points), np.concatenate(shorter)

    def corners(self, angle=120.0, metric=None):
        """Ring vertices where the two edges meet at less than ``angle`` degrees.

        Convex and reflex corners alike: the angle is the unsigned one
        between the two edges, 180 for a straight run. With ``metric`` (a
        function of ``(n, 2)`` points returning ``(n, 2, 2)`` symmetric
        positive definite matrices), the angle is measured in it at each
        vertex: a corner of 100 degrees is one of 10 in a metric 12 times as
        fine across it.
        """
        found = []
        for ring in self.rings:
            before = ring - np.roll(ring, 1, axis=0)
            after = np.roll(ring, -1, axis=0) - ring
            if metric is not None:  # M = L L^T: a vector's length in M is that of L^T x in the plane
                factor = np.linalg.cholesky(metric(ring))
                before, after = np.einsum("nji,nj->ni", factor, before), np.einsum("nji,nj->ni", factor, after)
            vertex_angle = _angle_between(before, after)
            found.append(ring[vertex_angle < angle])
        return np.concatenate(found)


def _angle_between(before, after):
    """Degrees between each vertex's two edges, the edge vectors into it and out of it: 180 on a straight run."""
    cosine = np.einsum("ij,ij->i", -before, after) / (np.hypot(*before.T) * np.hypot(*after.T))
    return np.degrees(np.arccos(np.clip(cosine, -1, 1)))
