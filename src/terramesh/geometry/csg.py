"""Constructive solid geometry on signed distance functions.

Union, intersection and difference take the minimum or maximum of their
operands' distances (Persson & Strang 2004). The result is exact outside
the union and inside the intersection, and a bound elsewhere, which is all
the mesh generator needs: the sign everywhere and the value near the boundary.
The exception, a face two operands of a union share, where the minimum is
zero inside the union, is handled by the combinations' ``inside``.

In 3D a combination also reports its sharp edges (``sharp_edges()``), which
the generator samples and keeps fixed, and their ends among its
``corners()``. They include the edges the combination creates, where a
surface of one operand meets a surface of another (an L-shape's re-entrant
edge, the rim of a hole), not only the operands' own edges. Every pair of
the solids' surfaces (:meth:`Box._surfaces <.primitives3d.Box._surfaces>`
and the like) gives candidate curves: exact where the pair allows it (two
planes: a line; a plane and a sphere, two spheres: a circle; a plane and a
cylinder: an ellipse, or two lines along it; a quadric and a cylinder: the
cylinder's angle parametrises the curve, the other surface's quadratic
along the cylinder gives two branches, which join into closed loops where
its discriminant vanishes). The pieces of them kept are those on the
combination's boundary where that boundary turns there by at least
SHARP_ANGLE: the signed distance sampled on a small circle around the curve
shows the inside as one arc, whose angle is pi where the boundary is flat
(a face shared by two operands, tangent surfaces). Their ends (where another
surface crosses) lie on three surfaces and are solved for exactly.
"""

import functools

import numpy as np

from ..errors import GeometryError
from .base import Domain, as_domain, as_points, probe_directions

SHARP_ANGLE = 10.0  # degrees: surfaces meeting at a smaller turn of the boundary than this give no sharp edge
_PROBE = 1e-6  # radius of the circle around a curve point that probes the boundary, over the domain's extent
_PROBE_ANGLES = 48  # points on that circle
_SAMPLES = 256  # points tested along a closed curve; a line gets half as many, plus its crossings with every plane
_BISECTIONS = 24  # halvings of the parameter interval that holds a change between kept and not (then solved)
_PAD = 1e-3  # lines are clipped to the bbox grown by this much of its extent
_PAST = 1e-3  # of an interval: a change at a crossing is checked this far past it
_MOVED = 1e-5  # of the extent: Newton's method moving a corner farther from the change found than this is checked
_FLAT = 1e-12  # of the extent: a surface's value within this of zero along a curve is zero (rounding)

__all__ = ["Union", "Intersection", "Difference"]


class _Combination(Domain):
    def __init__(self, domains):
        domains = [as_domain(domain) for domain in domains]
        if len(domains) < 2:
            raise GeometryError(f"{type(self).__name__} needs at least two domains, got {len(domains)}")
        dims = {domain.dim for domain in domains}
        if len(dims) != 1:
            raise GeometryError(f"{type(self).__name__} of domains with different dimensions {sorted(dims)}")
        self.domains = domains
        self.bbox = self._combined_bbox(np.array([domain.bbox for domain in domains]))
        # the minimum and maximum of 1-Lipschitz functions are 1-Lipschitz, and of others need not be
        self.lipschitz = all(getattr(domain, "lipschitz", False) for domain in domains)

    def _distance(self, points):
        return self._combine([domain.distance(points) for domain in self.domains])

    def distance_within(self, points, limit):
        """:meth:`Domain.distance_within` from the operands' own: a polygon's then skips its far distances.

        Exact: clipping to ``[-limit, limit]`` commutes with the minimum and
        maximum (and with the negation of a difference's operands).

        Examples
        --------
        >>> from terramesh.geometry import Disk
        >>> lens = Intersection([Disk((0, 0), 1), Disk((1, 0), 1)])
        >>> lens.distance_within([(0.5, 0.0), (5.0, 0.0)], 0.25).tolist()
        [-0.25, 0.25]
        """
        points = as_points(points, self.dim)
        return self._combine([domain.distance_within(points, limit) for domain in self.domains])

    def inside(self, points, tolerance=0.0):
        """Mask of the points inside by more than ``tolerance``, a face two operands of a union share counted inside.

        Where two operands of a union touch along a face (a block stacked on
        another, two boxes side by side) both their distances are zero, so
        the minimum is zero there too though the face lies inside the union
        (and stays zero in any combination holding that union). A point
        within ``tolerance`` of the zero level is inside when the points
        ``2 tolerance`` away from it in the ``3**dim - 1`` axis and diagonal
        directions are all inside or on the boundary; beside a true boundary,
        a re-entrant corner included, one of them is outside. Without it,
        cells of the mesh whose centroid fell on the shared face were
        dropped, leaving a crack (3D, stacked boxes: every seed tried).

        Examples
        --------
        >>> from terramesh.geometry import Rectangle
        >>> stacked = Rectangle((0, 0), (1, 0.5)) | Rectangle((0.2, 0.5), (0.8, 1))
        >>> stacked.distance([(0.5, 0.5)]).tolist(), stacked.inside([(0.5, 0.5), (0.1, 0.5)], 1e-6).tolist()
        ([0.0], [True, False])
        """
        points = as_points(points, self.dim)
        distance = self.distance(points)
        inside = distance < -tolerance
        near = np.flatnonzero(~inside & (distance <= tolerance))
        if len(near) and tolerance > 0:
            steps = 2.0 * tolerance * probe_directions(self.dim)
            probes = (points[near][:, None, :] + steps[None]).reshape(-1, self.dim)
            inside[near] = np.all(self.distance(probes).reshape(len(near), -1) <= 0, axis=1)
        return inside

    def corners(self):
        """Operands' corners that lie on this domain's boundary; in 3D the ends of its sharp edges.

        In 2D also the points where two operands' boundaries cross on it at
        an angle of at least SHARP_ANGLE (a union's re-entrant corners, where
        a hole's circle cuts a rectangle's side): found on a 256 x 256 grid
        where both distances change sign, then solved for by Newton's method
        on the two distances.

        In 3D the corners are the points where a sharp edge (see
        :meth:`sharp_edges`) ends: a solid's corner where it remains one,
        and the corners the combination creates, where a third surface
        crosses the curve two others meet in. Operands other than the
        solids of :mod:`.primitives3d` add their corners on the boundary.
        """
        scale = np.max(self.bbox[1] - self.bbox[0])
        on_boundary = max(1e-10 * scale, _rounding(self.bbox))
        if self.dim == 3:
            # a solid's corner is also an end of its edges where it is a corner here: elsewhere (inside a face
            # shared with another solid, say) it is none
            candidates = [leaf.corners() for leaf in leaf_solids(self) if known_by_distance_alone(leaf)]
            candidates = np.concatenate([np.empty((0, 3)), *candidates])
            candidates = candidates[np.abs(self.distance(candidates)) < on_boundary]
            ends = [piece.ends() for piece in self._edge_pieces()]
            return np.unique(np.concatenate([candidates, *ends]), axis=0)
        leaves = leaf_solids(self)
        own = [leaf.corners() for leaf in leaves]
        # a crossing on the bbox's side (a hole cutting a rectangle's edge) lands there exactly, not a rounding outside
        crossings = np.clip(_crossings(leaves, self.bbox), self.bbox[0], self.bbox[1])
        candidates = np.concatenate([np.empty((0, 2)), *own, crossings])
        candidates = candidates[np.abs(self.distance(candidates)) < on_boundary]
        # Newton's crossings along a side two operands share stop a thousand roundings short of an operand's corner
        # at UTM coordinates (3.4e-6 m at 5e6), and the corner itself, listed first, is kept
        return _distinct(candidates, max(1e-9 * scale, 1e3 * _rounding(self.bbox)))

    def sharp_edges(self):
        """The sharp edges of the combined boundary as parametric curves (3D; none in 2D).

        The operands' own edges where they remain on the boundary, and the
        curves where two operands' surfaces meet on it, both where the
        boundary turns by at least SHARP_ANGLE degrees across them (see the
        module's notes). Operands other than :class:`~.primitives3d.Box`,
        ``Ball``, ``Cylinder`` and combinations of them contribute their own
        ``sharp_edges()``, if any, where they lie on the boundary.

        Returns
        -------
        list of callable
            Each maps parameters ``t`` in [0, 1], shape ``(m,)``, to points
            on the edge, shape ``(m, 3)``, in the domain's units, the ends
            (at t = 0 and 1) among :meth:`corners`. A curve with
            ``closed = True`` (a whole circle, say) has none: its points at
            0 and 1 coincide. On a plane normal to a coordinate axis the
            points have that coordinate exactly (an edge of two such planes,
            two).

        Examples
        --------
        >>> from terramesh.geometry import Box
        >>> ell = Box((0, 0, 0), (2, 1, 1)) | Box((0, 0, 0), (1, 2, 1))
        >>> len(ell.sharp_edges())  # an L-shaped prism's: 6 + 6 + 6
        18
        >>> inner = [e for e in ell.sharp_edges() if np.all(e(np.array([0.5]))[0, :2] == 1.0)]
        >>> sorted(inner[0](np.array([0.0, 1.0])).tolist())  # the re-entrant edge x = y = 1
        [[1.0, 1.0, 0.0], [1.0, 1.0, 1.0]]
        """
        return list(self._edge_pieces()) if self.dim == 3 else []

    def _edge_pieces(self):
        cached = getattr(self, "_pieces_cache", None)
        if cached is None:
            cached = self._pieces_cache = sharp_edge_pieces(self)
        return cached


class Union(_Combination):
    """Points inside any operand.

    Examples
    --------
    >>> from terramesh.geometry import Disk
    >>> both = Union([Disk((0, 0), 1), Disk((1.5, 0), 1)])
    >>> both.distance([(2.0, 0.0)]).tolist()
    [-0.5]
    """

    @staticmethod
    def _combined_bbox(boxes):
        return np.array([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])

    @staticmethod
    def _combine(distances):
        return functools.reduce(np.minimum, distances)


class Intersection(_Combination):
    """Points inside every operand.

    Examples
    --------
    >>> from terramesh.geometry import Disk
    >>> lens = Intersection([Disk((0, 0), 1), Disk((1, 0), 1)])
    >>> lens.distance([(0.5, 0.0)]).tolist()
    [-0.5]
    """

    @staticmethod
    def _combined_bbox(boxes):
        box = np.array([boxes[:, 0].max(axis=0), boxes[:, 1].min(axis=0)])
        if np.any(box[1] <= box[0]):
            raise GeometryError("the intersection is empty: the operands' bounding boxes do not overlap")
        return box

    @staticmethod
    def _combine(distances):
        return functools.reduce(np.maximum, distances)


class Difference(_Combination):
    """Points inside the first operand and outside all the others.

    Examples
    --------
    >>> from terramesh.geometry import Disk, Rectangle
    >>> plate = Difference([Rectangle((0, 0), (2, 1)), Disk((0.5, 0.5), 0.2)])
    >>> plate.distance([(0.5, 0.5), (1.5, 0.5)]).round(6).tolist()
    [0.2, -0.5]
    """

    @staticmethod
    def _combined_bbox(boxes):
        return boxes[0].copy()

    @staticmethod
    def _combine(distances):
        return functools.reduce(lambda kept, cut: np.maximum(kept, -cut), distances[1:], distances[0])


# --- corners where 2D operands' boundaries cross ------------------------------------------------

_CROSSING_GRID = 256  # grid points per axis searched for boundary crossings
_NEWTON_STEPS = 30


def _crossings(leaves, bbox):
    """Points where the boundaries of two of ``leaves`` (2D) cross at an angle of at least SHARP_ANGLE.

    Grid cells whose corners see both distances change sign hold a crossing
    (or come close); from their centres Newton's method on the pair of
    distances (central-difference Jacobian) converges to it. A start that
    leaves its cell's neighbourhood, meets boundaries nearly parallel, or
    does not converge to 1e-12 of the extent gives nothing.
    """
    scale = float(np.max(bbox[1] - bbox[0]))
    found = [np.empty((0, 2))]
    for i, first in enumerate(leaves):
        for second in leaves[i + 1 :]:
            low = np.maximum(np.maximum(first.bbox[0], second.bbox[0]), bbox[0])
            high = np.minimum(np.minimum(first.bbox[1], second.bbox[1]), bbox[1])
            spacing = (high - low) / (_CROSSING_GRID - 1)
            if np.any(spacing <= 0):
                continue
            low, high = low - spacing, high + spacing
            axes = [np.linspace(low[d], high[d], _CROSSING_GRID + 2) for d in range(2)]
            grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
            shape = (_CROSSING_GRID + 2, _CROSSING_GRID + 2)
            # only the signs: within a few cells of its boundary a polygon searches its segments, beyond
            # it takes point in polygon (a strip of a 1,000-vertex coast: 80 ms a grid with the full distance)
            near = 4.0 * float(spacing.max())
            changes = [_sign_change_cells(leaf.distance_within(grid, near).reshape(shape)) for leaf in (first, second)]
            i_cell, j_cell = np.nonzero(changes[0] & changes[1])
            if len(i_cell) == 0:
                continue
            start = np.column_stack([axes[0][i_cell], axes[1][j_cell]]) + 0.5 * spacing
            found.append(_newton_crossings(first, second, start, spacing, scale, _rounding(bbox)))
    return np.concatenate(found)


def _distinct(points, tolerance):
    """``points`` less each one within ``tolerance`` of an earlier one (one crossing found from two cells, say)."""
    if len(points) < 2:
        return points
    from scipy.spatial import cKDTree

    pairs = cKDTree(points).query_pairs(tolerance, output_type="ndarray")
    keep = np.ones(len(points), dtype=bool)
    keep[pairs.max(axis=1)] = False
    return points[keep]


def _sign_change_cells(values):
    """Grid cells whose four corner values include both signs (or a zero)."""
    corners = np.stack([values[:-1, :-1], values[1:, :-1], values[:-1, 1:], values[1:, 1:]])
    return (corners.min(axis=0) <= 0) & (corners.max(axis=0) >= 0)


def _residual(first, second, point, step):
    """Both distances at each of ``point`` (n, 2) and their central-difference gradients (the Jacobian's rows)."""
    value = np.column_stack([first.distance(point), second.distance(point)])
    shifts = np.eye(2) * step
    along, across = (
        np.column_stack([(leaf.distance(point + s) - leaf.distance(point - s)) / (2 * step) for s in shifts])
        for leaf in (first, second)
    )
    return value, along, across


def _rounding(bbox):
    """A few roundings of the coordinates in ``bbox``: distances nearer zero than this are zero.

    Far from the origin (UTM metres, 5e6) a corner's distances, rounded, are
    about 1e-9 however exact the corner: a tolerance of the extent's 1e-12
    missed both corners of two 30 m disks there.
    """
    return 64.0 * np.finfo(np.float64).eps * float(np.max(np.abs(bbox)))


def _newton_crossings(first, second, start, spacing, scale, rounding):
    """Solve ``first.distance = second.distance = 0`` from each ``start``; the converged, transversal roots.

    Converged is within 1e-12 of the extent ``scale`` or the coordinates'
    ``rounding``, whichever is larger.
    """
    point = start.copy()
    step = 1e-7 * scale
    for _ in range(_NEWTON_STEPS):
        value, along, across = _residual(first, second, point, step)
        determinant = along[:, 0] * across[:, 1] - along[:, 1] * across[:, 0]
        safe = np.where(np.abs(determinant) > 1e-12, determinant, 1.0)
        move = np.column_stack(
            [
                (across[:, 1] * value[:, 0] - along[:, 1] * value[:, 1]) / safe,
                (along[:, 0] * value[:, 1] - across[:, 0] * value[:, 0]) / safe,
            ]
        )
        point = point - move
    value, along, across = _residual(first, second, point, step)
    cross = np.abs(along[:, 0] * across[:, 1] - along[:, 1] * across[:, 0])
    sine = cross / np.maximum(np.linalg.norm(along, axis=1) * np.linalg.norm(across, axis=1), 1e-300)
    good = (
        np.all(np.abs(value) < max(1e-12 * scale, rounding), axis=1)
        & np.all(np.abs(point - start) <= 2.0 * spacing, axis=1)
        & (sine >= np.sin(np.radians(SHARP_ANGLE)))
    )
    return point[good]


# --- sharp edges of 3D combinations ----------------------------------------------------------------


def leaf_solids(domain):
    """The solids a combination is made of, at any depth, in order."""
    if isinstance(domain, _Combination):
        return [leaf for operand in domain.domains for leaf in leaf_solids(operand)]
    return [domain]


class _Curve:
    """A curve ``t -> points`` for ``t`` in [0, 1] (periodic if ``closed``) on the two ``surfaces`` it came from.

    ``line`` holds the ends of a straight one, whose crossings with planes
    are then known exactly. Points are snapped onto axis-aligned planes.
    """

    def __init__(self, function, surfaces, *, closed, line=None):
        self._function, self.surfaces, self.closed, self.line = function, tuple(surfaces), closed, line

    def __call__(self, t):
        t = np.asarray(t, dtype=np.float64)
        points = np.array(self._function(t % 1.0 if self.closed else t), dtype=np.float64).reshape(-1, 3)
        for surface in self.surfaces:
            surface.snap(points)
        return points


class _Piece:
    """The part of a curve from parameter ``t0`` to ``t1`` (t1 may pass 1 on a closed one), as ``t`` in [0, 1].

    ``start`` and ``end`` are returned exactly at 0 and 1 (solved-for
    corners); a piece without them is a whole closed curve.
    """

    def __init__(self, curve, t0, t1, start=None, end=None):
        self.curve, self.t0, self.t1, self.start, self.end = curve, t0, t1, start, end
        self.closed = start is None

    def __call__(self, t):
        t = np.asarray(t, dtype=np.float64)
        points = self.curve(self.t0 + t * (self.t1 - self.t0))
        if not self.closed:
            points[t == 0.0] = self.start
            points[t == 1.0] = self.end
        return points

    def ends(self):
        return np.empty((0, 3)) if self.closed else np.array([self.start, self.end])


def _line(point, direction, surfaces, box):
    """The line through ``point`` along unit ``direction``, clipped to ``box``, as a list of at most one curve."""
    low, high = -np.inf, np.inf
    for axis in range(3):
        if direction[axis] == 0.0:
            if not box[0, axis] <= point[axis] <= box[1, axis]:
                return []
            continue
        ends = (box[:, axis] - point[axis]) / direction[axis]
        low, high = max(low, ends.min()), min(high, ends.max())
    if not high > low:
        return []
    start, end = point + low * direction, point + high * direction

    def function(t):
        points = start + t[:, None] * (end - start)
        points[t == 1.0] = end
        return points

    return [_Curve(function, surfaces, closed=False, line=(start, end))]


def _circle(center, normal, radius, surfaces):
    from .primitives3d import perpendicular_pair

    u, v = perpendicular_pair(normal)

    def function(t):
        angle = 2.0 * np.pi * t
        return center + radius * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)

    return [_Curve(function, surfaces, closed=True)]


def _plane_plane(a, b, box):
    direction = np.cross(a.normal, b.normal)
    norm = np.sqrt(np.sum(direction**2))
    if norm < 1e-9:
        return []  # parallel: coplanar faces make no edge, others never meet
    direction /= norm
    matrix = np.array([a.normal, b.normal, direction])
    point = np.linalg.solve(matrix, [a.offset, b.offset, direction @ box.mean(axis=0)])
    point = b.snap(a.snap(point[None]))[0]
    return _line(point, direction, (a, b), box)


def _plane_sphere(plane, sphere):
    offset = plane.value(sphere.center[None])[0]
    if abs(offset) >= sphere.radius * (1.0 - 1e-12):
        return []  # apart or touching: no curve
    center = sphere.center - offset * plane.normal
    return _circle(center, plane.normal, np.sqrt(sphere.radius**2 - offset**2), (plane, sphere))


def _sphere_sphere(a, b):
    gap = b.center - a.center
    d = np.sqrt(np.sum(gap**2))
    if d == 0.0 or d >= (a.radius + b.radius) * (1 - 1e-12) or d <= abs(a.radius - b.radius) * (1 + 1e-12):
        return []
    along = (d**2 + a.radius**2 - b.radius**2) / (2.0 * d)
    return _circle(a.center + along * gap / d, gap / d, np.sqrt(a.radius**2 - along**2), (a, b))


def _circles_across(cylinder, center, radius, box, surfaces):
    """Lines along ``cylinder`` where its cross-section meets the circle (centre, radius) of a parallel one."""
    a = cylinder.direction
    relative = center - cylinder.center
    relative = relative - (relative @ a) * a
    d = np.sqrt(np.sum(relative**2))
    if d == 0.0 or d >= (cylinder.radius + radius) * (1 - 1e-12) or d <= abs(cylinder.radius - radius) * (1 + 1e-12):
        return []
    e = relative / d
    along = (d**2 + cylinder.radius**2 - radius**2) / (2.0 * d)
    across = np.sqrt(cylinder.radius**2 - along**2) * np.cross(a, e)
    foot = cylinder.center + along * e
    return _line(foot + across, a, surfaces, box) + _line(foot - across, a, surfaces, box)


def _plane_cylinder(plane, cylinder, box):
    n, a = plane.normal, cylinder.direction
    slope = n @ a
    if abs(slope) < 1e-9:
        # parallel to the axis: the plane's trace in the cross-section is a line, a circle of infinite radius; solve
        # it as the chord of the cylinder's circle at the plane's distance from the axis
        level = plane.offset - n @ cylinder.center
        if abs(level) >= cylinder.radius * (1 - 1e-12):
            return []
        across = n - slope * a
        across /= np.sqrt(np.sum(across**2))
        foot = cylinder.center + level * across
        half = np.sqrt(cylinder.radius**2 - level**2) * np.cross(a, across)
        surfaces = (plane, cylinder)
        return _line(foot + half, a, surfaces, box) + _line(foot - half, a, surfaces, box)
    c, r, u, v = cylinder.center, cylinder.radius, cylinder.u, cylinder.v

    def function(t):
        angle = 2.0 * np.pi * t
        rim = c + r * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)
        return rim + ((plane.offset - rim @ n) / slope)[:, None] * a

    return [_Curve(function, (plane, cylinder), closed=True)]


def _on_cylinder(cylinder, other, box):
    """The curves where ``cylinder`` meets a sphere or another cylinder, by the angle around its axis.

    At angle phi the line ``q(phi) + s a`` on the cylinder meets the other
    surface where ``A s**2 + 2 B s + C = 0``; the two roots are two branches,
    which join where the discriminant ``B**2 - A C`` changes sign. Where it
    is positive all round, the branches are two closed curves; else each
    arc of positive discriminant makes one closed loop, out along one branch
    and back along the other (the angle spaced as a cosine, so that points
    do not thin out where the branches meet and the curve turns along s).
    """
    c, a, r, u, v = cylinder.center, cylinder.direction, cylinder.radius, cylinder.u, cylinder.v
    if other.kind == "cylinder":
        b = other.direction
        across = a - (a @ b) * b
        quadratic = across @ across
        if quadratic < 1e-12:  # parallel axes: lines along them
            return _circles_across(cylinder, other.center, other.radius, box, (cylinder, other))

    def coefficients(angle):
        rim = c + r * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)
        relative = rim - other.center
        if other.kind == "sphere":
            return rim, np.ones(len(angle)), relative @ a, np.sum(relative**2, axis=1) - other.radius**2
        relative = relative - np.outer(relative @ b, b)
        return rim, np.full(len(angle), quadratic), relative @ across, np.sum(relative**2, axis=1) - other.radius**2

    def branch(angle, sign):
        rim, qa, qb, qc = coefficients(angle)
        root = np.sqrt(np.maximum(qb**2 - qa * qc, 0.0))
        return rim + ((-qb + sign * root) / qa)[:, None] * a

    def discriminant(angle):
        _, qa, qb, qc = coefficients(angle)
        return qb**2 - qa * qc

    surfaces = (cylinder, other)
    angles = 2.0 * np.pi * np.arange(_SAMPLES * 2) / (_SAMPLES * 2)
    positive = discriminant(angles) > 0.0
    if positive.all():
        return [
            _Curve(lambda t, sign=sign: branch(2.0 * np.pi * t, sign), surfaces, closed=True) for sign in (1.0, -1.0)
        ]
    if not positive.any():
        return []
    step = angles[1]
    first = int(np.argmin(positive))  # a negative sample: arcs are then whole after rotating to it
    curves = []
    order = (first + np.arange(len(angles) + 1)) % len(angles)
    unwrapped = angles[0] + step * (first + np.arange(len(angles) + 1))
    flags = positive[order]
    starts = np.flatnonzero(~flags[:-1] & flags[1:]) + 1
    stops = np.flatnonzero(flags[:-1] & ~flags[1:])
    for begin, finish in zip(starts, stops, strict=True):
        ends = []
        for low, high in ((unwrapped[begin - 1], unwrapped[begin]), (unwrapped[finish + 1], unwrapped[finish])):
            for _ in range(_BISECTIONS):
                middle = 0.5 * (low + high)
                if discriminant(np.array([middle]))[0] > 0.0:
                    high = middle
                else:
                    low = middle
            ends.append(high)  # the side where the branches exist

        def loop(t, start=ends[0], stop=ends[1]):
            out = t <= 0.5
            s = np.where(out, 2.0 * t, 2.0 - 2.0 * t)
            angle = start + (stop - start) * 0.5 * (1.0 - np.cos(np.pi * s))
            return np.where(out[:, None], branch(angle, 1.0), branch(angle, -1.0))

        curves.append(_Curve(loop, surfaces, closed=True))
    return curves


def _intersections(a, b, box):
    """Candidate curves where surfaces ``a`` and ``b`` meet, within ``box`` for lines."""
    kinds = (a.kind, b.kind)
    if kinds == ("plane", "plane"):
        return _plane_plane(a, b, box)
    if kinds in {("plane", "sphere"), ("sphere", "plane")}:
        return _plane_sphere(*((a, b) if a.kind == "plane" else (b, a)))
    if kinds in {("plane", "cylinder"), ("cylinder", "plane")}:
        return _plane_cylinder(*((a, b) if a.kind == "plane" else (b, a)), box)
    if kinds == ("sphere", "sphere"):
        return _sphere_sphere(a, b)
    if "cylinder" in kinds:
        return _on_cylinder(*((a, b) if a.kind == "cylinder" else (b, a)), box)
    return []


def _turns(domain, points, tangents, radius):
    """Whether the boundary of ``domain`` turns by at least SHARP_ANGLE across the curve through each point.

    The signed distance on a circle of ``radius`` about each point, normal to
    its ``tangents``: a point off the boundary sees one sign only; a flat
    boundary splits the circle into two half circles; an edge into an
    inside arc of another angle (or into several arcs, where solids touch
    along it).
    """
    sharp = np.zeros(len(points), dtype=bool)
    near = np.flatnonzero(np.abs(domain.distance(points)) <= radius)
    if len(near) == 0:
        return sharp
    tangent = tangents[near] / np.maximum(np.sqrt(np.sum(tangents[near] ** 2, axis=1)), 1e-300)[:, None]
    helper = np.eye(3)[np.argmin(np.abs(tangent), axis=1)]
    first = np.cross(tangent, helper)
    first /= np.sqrt(np.sum(first**2, axis=1))[:, None]
    second = np.cross(tangent, first)
    step = 2.0 * np.pi / _PROBE_ANGLES
    # half a step off the frame's axes: on a face two operands share, inside, the distance bound is zero, not negative
    angle = step * (np.arange(_PROBE_ANGLES) + 0.5)
    offsets = np.cos(angle)[None, :, None] * first[:, None, :] + np.sin(angle)[None, :, None] * second[:, None, :]
    probes = points[near][:, None, :] + radius * offsets
    d = domain.distance(probes.reshape(-1, 3)).reshape(len(near), _PROBE_ANGLES)
    inside = d < 0.0
    following = np.roll(d, -1, axis=1)
    entering = ~inside & (following < 0.0)
    leaving = inside & (following >= 0.0)
    count = entering.sum(axis=1)
    at = step * (np.arange(_PROBE_ANGLES) + 0.5 + d / np.where(d != following, d - following, 1.0))
    arc = np.full(len(near), np.pi)
    one = count == 1
    arc[one] = (np.max(np.where(leaving, at, 0.0), axis=1) - np.max(np.where(entering, at, 0.0), axis=1))[one]
    arc %= 2.0 * np.pi
    sharp[near] = (count > 1) | (np.abs(arc - np.pi) >= np.radians(SHARP_ANGLE))
    return sharp


def _kept(domain, curve, t, radius):
    """Whether the curve's points at ``t`` lie on a sharp edge of the boundary (see :func:`_turns`)."""
    delta = 1e-6
    ahead, behind = t + delta, t - delta
    if not curve.closed:
        ahead, behind = np.minimum(ahead, 1.0), np.maximum(behind, 0.0)
    return _turns(domain, curve(t), curve(ahead) - curve(behind), radius)


def _corner(domain, curve, t, surfaces, scale, third=None, implicit=()):
    """The point at ``t`` where the curve ends, solved onto the nearest third surface (or ``third``) when close.

    A change found by bisection is only as good as the probe radius; the
    corner proper lies on three surfaces, and Newton's method on the three
    of them gets there (in one step for three planes). A curve ended by no
    surface known so (an operand known by its distance alone, ``implicit``:
    a user's function, a grid), or with no surfaces of its own, is followed
    onto the surface that ends it (:func:`_along_onto`).
    """
    point = curve(np.array([t]))
    if not curve.surfaces:
        return _or_point(_along_onto(domain, curve, t, point, [*surfaces, *implicit], scale), point)
    if third is None:
        others = [s for s in surfaces if all(s is not own for own in curve.surfaces)]
        gaps = [abs(s.value(point)[0]) for s in others]
        if not others or min(gaps) > 1e3 * _PROBE * scale:
            return _or_point(_along_onto(domain, curve, t, point, list(implicit), scale), point)
        third = others[int(np.argmin(gaps))]
    three = (*curve.surfaces, third)
    solved = point.copy()
    for _ in range(8):
        values = np.array([s.value(solved)[0] for s in three])
        if np.max(np.abs(values)) <= 1e-15 * scale:
            break
        jacobian = np.array([s.gradient(solved)[0] for s in three])
        if abs(np.linalg.det(jacobian)) < 1e-6:
            return point[0]  # the three surfaces do not meet at a point here
        solved = solved - np.linalg.solve(jacobian, values)[None]
    for s in three:
        s.snap(solved)
    if np.sqrt(np.sum((solved - point) ** 2)) > 1e3 * _PROBE * scale:
        return point[0]
    moved = np.sqrt(np.sum((solved - point) ** 2))
    off = abs(float(domain.distance(solved)[0])) > 1e-9 * scale if implicit else False
    if implicit and (moved > _MOVED * scale or off):
        # a plane passing by (a box's face 1.1 away, 3e-4 above or below a corner that a grid's surface makes)
        # took the corner, off the domain or along the edge: the surface that ends the curve may be one known by
        # its distance alone, whose root along it is nearer the change found
        other = _along_onto(domain, curve, t, point, list(implicit), scale)
        if other is not None and (off or np.sqrt(np.sum((other - point[0]) ** 2)) < moved):
            return other
    return solved[0]


def _or_point(solved, point):
    """``solved`` (shape (3,)), or the curve's ``point`` (shape (1, 3)) where it is None."""
    return point[0] if solved is None else solved


def known_by_distance_alone(operand):
    """Whether ``operand`` has no surfaces a combination can solve on (a user's distance function, a grid)."""
    return not callable(getattr(operand, "_surfaces", None))


class _Implicit:
    """An operand known by its distance alone (a user's function, a grid), as a surface that may end a curve."""

    axis = None

    def __init__(self, operand):
        self.operand = operand

    def value(self, points):
        return self.operand.distance(points)

    def snap(self, points):
        return points


def _along_onto(domain, curve, t, point, surfaces, scale):
    """The end ``point`` (at ``t``) of a curve moved along it onto one of ``surfaces`` that ends it, or None.

    A user's sharp edge (:class:`~terramesh.geometry.FunctionDomain`) or a
    grid's knows no surfaces, and bisection leaves its end about a probe
    radius off the surface that cuts it: where that surface is a plane of
    the combination's bbox (a box's face across the edge), the corner fell
    outside the bbox and was dropped, 0.04-0.08 from the nearest vertex.
    The surfaces within reach are tried nearest first, but one the curve
    lies in (a box's face under a user's edge): the root of its value along
    the curve, bracketed about ``t``, is bisected and the point snapped onto
    an axis-aligned plane. The first root at least as near the domain's
    boundary as ``point`` is taken; a plane passing near an end that another
    operand's face makes would move the corner off the domain.
    """
    gaps = np.array([abs(s.value(point)[0]) for s in surfaces])
    reach = 1e3 * _PROBE * scale
    off = abs(float(domain.distance(point)[0]))
    for k in np.argsort(gaps, kind="stable"):
        if gaps[k] > reach:
            break
        solved = _root_along(curve, t, surfaces[k], scale)
        if solved is not None and np.sqrt(np.sum((solved - point) ** 2)) <= reach:
            if abs(float(domain.distance(solved)[0])) <= off + _FLAT * scale:  # at least as near, to rounding
                return solved[0]
    return None


def _root_along(curve, t, surface, scale):
    """Where the curve leaves ``surface`` about ``t`` (within 0.01 in ``t``), snapped: shape (1, 3), or None.

    Leaves: the surface's value rises past a rounding (``_FLAT`` of the
    extent) there, from below it (a crossing) or from zero (a curve along a
    face of an operand known by its distance alone, where that face ends).
    None where the curve lies in the surface there, or no change is
    bracketed.
    """
    flat = _FLAT * scale
    level = flat  # where the value rises from zero; from below it, where it crosses zero (set below)

    def beyond(u):
        return surface.value(curve(np.asarray(u, dtype=np.float64))) > level

    step, bracket = 1e-9, None
    while bracket is None and step <= 1e-2:
        around = np.array([t - step, t, t + step])
        if not curve.closed:
            around = np.clip(around, 0.0, 1.0)
        values = surface.value(curve(around))
        if not np.all(np.isfinite(values)) or np.all(np.abs(values) <= flat):
            return None
        side = values > flat
        if side[0] != side[1]:
            bracket = [around[0], around[1]]
        elif side[1] != side[2]:
            bracket = [around[1], around[2]]
        step *= 4.0
    if bracket is None:
        return None
    low, high = bracket
    if np.min(surface.value(curve(np.array(bracket)))) < -flat:
        level = 0.0
    low_side = beyond([low])[0]
    for _ in range(2 * _BISECTIONS):
        middle = 0.5 * (low + high)
        if beyond([middle])[0] == low_side:
            low = middle
        else:
            high = middle
    return surface.snap(curve(np.array([0.5 * (low + high)])))


def _pieces(domain, curve, planes, surfaces, scale, implicit=()):
    """The pieces of ``curve`` on sharp edges of ``domain``, their ends solved for (see :func:`_corner`)."""
    radius = _PROBE * scale
    crossings = {}
    if curve.line is not None:
        start, end = curve.line
        for plane in planes:
            if any(plane is own for own in curve.surfaces):
                continue
            slope = plane.normal @ (end - start)
            if abs(slope) > 1e-12 * scale:
                t = (plane.offset - plane.normal @ start) / slope
                if 0.0 < t < 1.0:
                    crossings.setdefault(t, plane)
        # where the line leaves the bbox, so that a piece ending at the bbox (on no plane) ends by bisection there
        slope = end - start
        moving = np.abs(slope) > 1e-12 * scale
        leaves = ((domain.bbox - start)[:, moving] / slope[moving]).ravel()
        uniform = np.concatenate([np.linspace(0.0, 1.0, _SAMPLES // 2 + 1), leaves[(leaves > 0.0) & (leaves < 1.0)]])
        known = np.array(sorted(crossings))
        if len(known):
            uniform = uniform[np.min(np.abs(uniform[:, None] - known[None, :]), axis=1) > 1e-4]
        grid = np.unique(np.concatenate([[0.0, 1.0], uniform, known]))
    else:
        grid = np.linspace(0.0, 1.0, _SAMPLES + 1)
    middle = 0.5 * (grid[1:] + grid[:-1])
    keep = _kept(domain, curve, middle, radius)
    if not keep.any():
        return []
    if curve.closed and keep.all():
        return [_Piece(curve, 0.0, 1.0)]
    low, high = grid[:-1], grid[1:]
    if curve.closed:
        # rotate to start at a dropped interval, and end with it again, so that every kept run has two ends inside
        first = int(np.argmin(keep))
        order = (first + np.arange(len(keep) + 1)) % len(keep)
        shift = np.where(np.arange(len(keep) + 1) + first >= len(keep), 1.0, 0.0)
        shift[-1] = 1.0
        low, high, middle, keep = low[order] + shift, high[order] + shift, middle[order] + shift, keep[order]
    begins = np.flatnonzero(keep & ~np.concatenate([[False], keep[:-1]]))
    finishes = np.flatnonzero(keep & ~np.concatenate([keep[1:], [False]]))

    # the changes between kept and not: at a plane's crossing exactly, else found by bisection (all at once)
    changes = [(begin - 1, begin) for begin in begins if begin > 0]
    changes += [(finish, finish + 1) for finish in finishes if finish < len(keep) - 1]
    at = {}
    # (interval before the change, where the bisection starts and ends, whether its start is kept)
    searched = [
        (before, middle[before], middle[after], keep[before])
        for before, after in changes
        if high[before] not in crossings
    ]
    # a change at a crossing is the crossing's only where the curve is kept just before it and not just past it: a
    # box's face passing 3e-4 above or below a corner that a grid's surface makes took the piece's end, one sample
    # interval holding both. Looked at where an operand known by its distance alone may end the curve (among the
    # solids alone a crossing ends it, but in 4 of 90 random combinations it changed corners by a rounding or one)
    at_crossing = [(before, after) for before, after in changes if implicit and high[before] in crossings]
    if at_crossing:
        kept_side = np.array([before if keep[before] else after for before, after in at_crossing])
        other_side = np.array([after if keep[before] else before for before, after in at_crossing])
        crossing = np.array([high[before] for before, _ in at_crossing])
        inside = crossing + _PAST * (middle[kept_side] - crossing)
        outside = crossing + _PAST * (middle[other_side] - crossing)
        kept_inside, kept_outside = np.split(_kept(domain, curve, np.concatenate([inside, outside]), radius), 2)
        for k, (before, _) in enumerate(at_crossing):
            if kept_outside[k]:  # the change is past the crossing
                start, end = outside[k], middle[other_side[k]]
            elif not kept_inside[k]:  # before it
                start, end = middle[kept_side[k]], inside[k]
            else:
                continue
            searched.append((before, start, end, True))
    if searched:
        lo = np.array([start for _, start, _, _ in searched])
        hi = np.array([end for _, _, end, _ in searched])
        lo_kept = np.array([kept for _, _, _, kept in searched])
        for _ in range(_BISECTIONS):
            mid = 0.5 * (lo + hi)
            same = _kept(domain, curve, mid, radius) == lo_kept
            lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        for (before, _, _, _), t in zip(searched, 0.5 * (lo + hi), strict=True):
            at[before] = (float(t), _corner(domain, curve, float(t), surfaces, scale, implicit=implicit))
    for before, _ in changes:
        if before not in at:
            shared = high[before]
            at[before] = (shared, _corner(domain, curve, shared, surfaces, scale, crossings[shared], implicit))

    pieces = []
    for begin, finish in zip(begins, finishes, strict=True):
        t0, start = (0.0, curve(np.array([0.0]))[0]) if begin == 0 else at[begin - 1]
        t1, end = (1.0, curve(np.array([1.0]))[0]) if finish == len(keep) - 1 else at[finish]
        if np.sqrt(np.sum((end - start) ** 2)) > 1e-9 * scale:
            pieces.append(_Piece(curve, t0, t1, start, end))
    return pieces


def sharp_edge_pieces(domain):
    """The sharp edges of a 3D combination as :class:`_Piece` curves, each once."""
    leaves = leaf_solids(domain)
    scale = float(np.max(domain.bbox[1] - domain.bbox[0]))
    box = domain.bbox + _PAD * scale * np.array([[-1.0], [1.0]])
    surfaces, curves, implicit = [], [], []
    for leaf in leaves:
        if not known_by_distance_alone(leaf):
            surfaces.extend(leaf._surfaces())
            continue
        implicit.append(_Implicit(leaf))
        if callable(getattr(leaf, "sharp_edges", None)):
            # an operand of another kind: its own edges, of which only the pieces on the boundary are kept
            curves.extend(_Curve(edge, (), closed=getattr(edge, "closed", False)) for edge in leaf.sharp_edges())
    for i, a in enumerate(surfaces):
        for b in surfaces[i + 1 :]:
            curves.extend(_intersections(a, b, box))
    planes = [s for s in surfaces if s.kind == "plane"]
    pieces, seen = [], set()
    quantum = 1e-9 * scale
    found = [piece for curve in curves for piece in _pieces(domain, curve, planes, surfaces, scale, implicit)]
    _merge_ends(found, quantum)
    for piece in found:
        # the same edge comes from a solid's own faces and from a face of another on the same planes
        probe = piece(np.array([0.0, 0.5, 1.0]) if not piece.closed else np.array([0.0, 0.25, 0.5, 0.75]))
        key = tuple(sorted(tuple(np.round(p / quantum).astype(np.int64)) for p in probe))
        if key not in seen:
            seen.add(key)
            pieces.append(piece)
    return pieces


def _merge_ends(pieces, quantum):
    """Make ends of pieces closer than ``quantum`` one point: the first found, snapped onto the most planes.

    The same corner, solved from different curves, differs in the last bits;
    as two fixed points a rounding apart it would spoil the cells there.
    """
    open_pieces = [piece for piece in pieces if not piece.closed]
    if not open_pieces:
        return
    from scipy.spatial import cKDTree

    ends = np.concatenate([piece.ends() for piece in open_pieces])
    groups = cKDTree(ends).query_ball_point(ends, quantum)
    chosen = np.arange(len(ends))
    for index, group in enumerate(groups):
        chosen[index] = min(group)
    merged = ends[chosen]
    for number, piece in enumerate(open_pieces):
        piece.start, piece.end = merged[2 * number], merged[2 * number + 1]
