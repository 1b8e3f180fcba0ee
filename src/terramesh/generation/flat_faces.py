"""Seeds on a box's faces: a hexagonal lattice in each face, in place of the cubic lattice's squares there.

A body-centred cubic lattice meets an axis-aligned face in squares, and the
force equilibrium keeps them: a square's diagonal is longer than the rest
length, so it carries no spring, and nothing turns the squares into
triangles. The face's triangles are then half-squares, one edge in three
about 1.5 times its size: on the unit box at h = 0.04, 90 % of the face
edges were below 1.52 h; on the 3-D BP2004 model's free surface, where the
sources and receivers of a seismic survey lie, the same, and 2.0 h at most.
So each face of the boxes a domain is made of (a box's six; of a
combination, where they bound it; of a 3D
:class:`~terramesh.geometry.GridDomain`, its grid box's, where the box cuts
the shape: a gridded velocity model's sides, 90 % of their edges below
1.52 h before, 1.11 h after, at h = 0.05 under a topography) is seeded with the 2-D seeder's nested
hexagonal lattices at the local size, and the cubic lattice's points less
than ``DEPTH`` sizes from it give way. The faces' edges then reach 1.16 h
at the 90th percentile on the unit box at h = 0.04 (1.19 h at h = 0.1) and
1.09 h on BP2004's surface. The price: the mean radius ratio of a uniform
box falls by 1-3 % (its interior was a perfect lattice; the more of its cells
at a face, the more), and a face gets seeds only where the domain reaches
``THICK`` sizes in from it: between the faces of a slab one to one and a half
sizes thick, hexagonal seeds left cells of radius ratio 0.23 (0.32 before).

A cylinder's ends are left to the cubic lattice: there a hexagonal lattice
meets the rim's fixed points badly, and of 200 random domains of the
validity sweep 7 more came out refused or with poorer cells.
"""

import numpy as np

from ..errors import GenerationError
from ..geometry.base import FunctionDomain
from ..geometry.csg import leaf_solids
from ..geometry.grid import GridDomain
from ..geometry.primitives3d import Box
from .seeding import seed_points

__all__ = ["flat_faces", "face_seeds", "with_face_seeds"]

DEPTH = 0.5  # lattice points nearer a seeded face than this many local sizes go (0.7: the interior's edges 4 % long)
THICK = 3.0  # a face gets seeds where the domain reaches this many sizes in from it (see the module's notes)


def flat_faces(domain, tolerance=0.0):
    """The planes of the faces of the boxes ``domain`` is made of, each once (coplanar faces of two boxes are one).

    Parameters
    ----------
    domain : Domain
        A 3D domain: a :class:`~terramesh.geometry.primitives3d.Box`, a
        :class:`~terramesh.geometry.GridDomain` (its grid box's faces) or a
        combination with them among its solids; other domains have none.
    tolerance : float, optional
        Planes along one axis closer than this are one, the first kept (a
        box's top at 0.3 and another's at 0.1 + 0.2 = 0.30000000000000004).

    Returns
    -------
    list
        The planes, each with ``axis`` (0, 1, 2: x, y, z), ``coordinate``
        (where along that axis), ``normal``, ``value(points)`` (signed
        distance to the plane) and ``snap(points)``. Whether a plane
        bounds the domain, and where, is for :func:`face_seeds` to find.

    Examples
    --------
    >>> from terramesh.geometry.primitives3d import Box
    >>> from terramesh.geometry.csg import Union
    >>> len(flat_faces(Union([Box((0, 0, 0), (1, 1, 1)), Box((1, 0, 0), (2, 1, 1))])))  # x = 1 twice; y, z shared
    7
    """
    planes = []
    for leaf in leaf_solids(domain):
        # a gridded shape's faces are those of its grid box where the box cuts it (a velocity model's sides)
        box = leaf if isinstance(leaf, Box) else _grid_box(leaf)
        if box is not None:
            for plane in box._surfaces():
                if not any(
                    kept.axis == plane.axis and abs(kept.coordinate - plane.coordinate) <= tolerance for kept in planes
                ):
                    planes.append(plane)
    return planes


def _grid_box(domain):
    """The grid box of a 3D :class:`~terramesh.geometry.GridDomain` as a Box, or None for another domain."""
    if isinstance(domain, GridDomain) and domain.dim == 3:
        return Box(*domain._box)
    return None


def face_seeds(domain, size, h0, bbox, rng, tolerance, plane):
    """Seeds of ``plane`` where it bounds ``domain``: the 2-D seeder's nested hexagonal lattices, in 3D.

    Parameters
    ----------
    domain : Domain
        A 3D domain.
    size : callable
        Target edge length, ``(n, 3) -> (n,)``, the domain's units.
    h0 : float
        Smallest edge length, the finest lattice's spacing.
    bbox : numpy.ndarray, shape (2, 3)
        Region meshed; the plane is seeded over its section.
    rng : numpy.random.Generator
        Seeds the thinning (one draw).
    tolerance : float
        A point of the plane is on the boundary where the domain's distance
        there is below this in magnitude.
    plane
        One of :func:`flat_faces`.

    Returns
    -------
    numpy.ndarray, shape (m, 3)
        Only where the plane bounds the domain and the domain reaches
        ``THICK`` sizes in from it; empty where the plane lies inside the
        domain or apart from it.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.geometry.primitives3d import Box
    >>> box = Box((0, 0, 0), (1, 1, 1))
    >>> top = [p for p in flat_faces(box) if p.axis == 2 and p.coordinate == 1.0][0]
    >>> seeds = face_seeds(box, lambda p: np.full(len(p), 0.1), 0.1, box.bbox, np.random.default_rng(0), 1e-4, top)
    >>> bool(np.all(seeds[:, 2] == 1.0)), 100 < len(seeds) < 140  # 1 / (sqrt(3) / 2 0.1**2) = 115 per unit area
    (True, True)
    """
    across = [axis for axis in range(3) if axis != plane.axis]
    section = np.ascontiguousarray(bbox[:, across])

    def lift(flat):
        points = np.empty((len(flat), 3))
        points[:, across] = flat
        points[:, plane.axis] = plane.coordinate
        return points

    def off_boundary(flat):  # zero where the plane bounds the domain, growing away from there, either side
        points = lift(np.asarray(flat, dtype=np.float64))
        distance = np.abs(domain.distance(points))
        # kept off the seeds (but not from the search) where the plane lies inside: a union's shared face reads 0
        return np.where(
            _bounds(domain, points, plane.normal, distance, tolerance), distance, np.maximum(distance, 2 * tolerance)
        )

    try:
        flat, _ = seed_points(
            FunctionDomain(off_boundary, section), lambda flat: size(lift(flat)), h0, section, rng, tolerance
        )
    except GenerationError:  # no lattice point of the plane is on the boundary
        return np.empty((0, 3))
    seeds = lift(flat)
    return seeds[_thick(domain, seeds, plane.normal, size(seeds), tolerance)]


def with_face_seeds(points, domain, size, h0, bbox, rng, tolerance):
    """``points`` (a cubic lattice's) less those within ``DEPTH`` sizes of a box's face, with the faces' seeds.

    A point gives way to a face when it is nearer the face's plane than
    ``DEPTH`` times its size and its foot on the plane is on the boundary
    (within ``tolerance``) where that face got seeds, that is where the
    domain reaches ``THICK`` sizes in from it: a slab thinner than that keeps
    its lattice. A face's seeds give way in the same way to the faces across
    their own, so that none lies on or beside a box's edge, whose points the
    edge's own sampling places. Domains without boxes get ``points`` back.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 3)
        Seeds inside the domain.
    domain, size, h0, bbox, rng, tolerance
        As for :func:`face_seeds`.

    Returns
    -------
    numpy.ndarray, shape (k, 3)
        The points kept, then the faces' seeds, plane by plane.
    """
    faces = [
        (plane, face_seeds(domain, size, h0, bbox, rng, tolerance, plane)) for plane in flat_faces(domain, tolerance)
    ]
    faces = [(plane, seeds) for plane, seeds in faces if len(seeds)]
    if not faces:
        return points
    every = np.vstack([points, *(seeds for _, seeds in faces)])
    axis_of = np.concatenate([np.full(len(points), -1), *(np.full(len(seeds), plane.axis) for plane, seeds in faces)])
    target = size(every)
    # every (point, plane) pair within reach, then the domain's distances at all their feet at once (a union of
    # 40 boxes has 240 planes: one distance call per pair took a minute)
    near, feet, normals = [], [], []
    for plane, _ in faces:
        close = np.flatnonzero((np.abs(plane.value(every)) < DEPTH * target) & (axis_of != plane.axis))
        near.append(close)
        feet.append(plane.snap(every[close]))
        normals.append(np.broadcast_to(plane.normal, (len(close), 3)))
    near, feet, normals = np.concatenate(near), np.vstack(feet), np.vstack(normals)
    bounded = _bounds(domain, feet, normals, np.abs(domain.distance(feet)), tolerance)
    # a lattice point gives way only where the face got seeds: not where the part is thin
    lattice = np.flatnonzero(bounded & (axis_of[near] < 0))
    bounded[lattice] = _thick(domain, feet[lattice], normals[lattice], target[near[lattice]], tolerance)
    beside = np.zeros(len(every), dtype=bool)
    beside[near[bounded]] = True
    return every[~beside]


def _thick(domain, points, normals, target, tolerance):
    """Mask of the boundary ``points`` where the domain reaches ``THICK`` sizes (``target``) in along the normal.

    The point that far in may lie on the boundary (within ``tolerance``):
    from a box's edge the way in runs along the next face.
    """
    if len(points) == 0:
        return np.zeros(0, dtype=bool)
    reach = (THICK * target)[:, None] * np.broadcast_to(normals, points.shape)
    return (domain.distance(points + reach) < tolerance) | (domain.distance(points - reach) < tolerance)


def _bounds(domain, points, normals, distance, tolerance):
    """Mask of the ``points`` (``distance`` from the boundary) where their plane (of normal ``normals``) bounds it.

    On the boundary (within ``tolerance``) with the outside on one side: a
    step of ``10 tolerance`` along the normal, one way or the other, leaves
    the domain.
    """
    on = np.flatnonzero(distance < tolerance)
    bounds = np.zeros(len(points), dtype=bool)
    if len(on):
        at, step = points[on], 10 * tolerance * np.broadcast_to(normals, points.shape)[on]
        bounds[on] = (domain.distance(at + step) > 0) | (domain.distance(at - step) > 0)
    return bounds
