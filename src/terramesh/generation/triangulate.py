"""Delaunay triangulation: terramesh's own exact incremental kernel (BSD, numba).

Chosen over SciPy's Qhull by measurement (4-10x faster at 10^5-10^6
points, see benchmarks/bench_delaunay.py) and for robustness: exact
predicates survive the cocircular lattices DistMesh seeds, and the
neighbour table the generator needs comes for free.

In 3D, :func:`delaunay_3d` wraps an incremental Bowyer-Watson kernel
(:mod:`terramesh._kernels.delaunay3d`, numba, floating-point predicates, the
cavity grown until the new point sees all its faces, so the result is always
a valid tetrahedralisation): about 0.12 s for 25k points, against 0.7 to 1 s
for SciPy's Qhull (:class:`scipy.spatial.Delaunay`), which remains the
fallback should the kernel fail.
"""

import math

import numpy as np

from .._kernels import delaunay as _kernel
from .._kernels.delaunay3d import STATUS_OK, bowyer_watson, bowyer_watson_workspace
from ..errors import GenerationError
from ..mesh.columns import bounds
from ..mesh.topology import without_rows

__all__ = ["delaunay", "delaunay_with_neighbors", "Triangulation", "delaunay_3d"]

# Hilbert grid for the insertion order: 2**20 cells a side (keys within int64);
# a cell holding more than _HILBERT_MAX_RUN points is ordered again on its own grid
_HILBERT_BITS = 20
_HILBERT_MAX_RUN = 16
# relative difference of the real cells' area and the hull's above which a repaired triangulation
# is folded (covers part of its hull twice) and is built again
_FOLDED = 1e-9


def delaunay(points):
    """Delaunay triangulation of a 2D point set, counter-clockwise cells.

    The cells of :func:`delaunay_with_neighbors` (exact predicates, every
    distinct point a vertex).

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)

    Returns
    -------
    numpy.ndarray, shape (m, 3), int64

    Raises
    ------
    GenerationError
        If the points do not span a plane (fewer than three, or all collinear).

    Examples
    --------
    >>> import numpy as np
    >>> delaunay(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])).shape
    (2, 3)
    """
    return delaunay_with_neighbors(points)[0]


def delaunay_with_neighbors(points, *, return_duplicates=False):
    """Delaunay triangulation of a 2D point set with its cell adjacency, by exact incremental insertion.

    Points are inserted in Hilbert-curve order with Lawson flips; the signs
    of the orientation and in-circle tests are exact (adaptive
    floating-point expansions, Shewchuk 1997), so the result is a valid
    triangulation of the convex hull for any input, including lattices with
    many cocircular and collinear points, and every point is a vertex
    except exact duplicates. Where four or more points are cocircular, one
    of the Delaunay triangulations is returned.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Point coordinates, any units; not modified. Coordinates are scaled
        by a power of two internally (an exact operation), so any finite
        magnitude works. Exactness additionally needs the nonzero coordinate
        differences to lie within about 10**70 of the largest coordinate
        (no underflow of fourth-degree products).
    return_duplicates : bool, optional
        Also return the map of points left out as exact duplicates.

    Returns
    -------
    cells : numpy.ndarray, shape (m, 3), int64
        Vertex indices into ``points``, counter-clockwise; they cover the
        convex hull of ``points`` exactly.
    neighbors : numpy.ndarray, shape (m, 3), int64
        ``neighbors[c, k]`` is the cell across the edge opposite corner
        ``k`` (the edge ``cells[c, k + 1], cells[c, k + 2]``), -1 on the
        hull.
    duplicate_of : numpy.ndarray, shape (n,), int64
        Only with ``return_duplicates``: the index of the vertex that point
        ``i`` coincides with exactly, -1 where point ``i`` is a vertex.

    Raises
    ------
    GenerationError
        If ``points`` is not an (n, 2) array of finite numbers, or the
        points do not span a plane (fewer than three distinct, or all
        collinear).

    See Also
    --------
    delaunay : The cells alone.

    Notes
    -----
    Unlike Qhull, which merges points closer than its rounding tolerance,
    every distinct point is kept: points a few ulps apart give cells whose
    area is positive exactly but may round to zero in floating point.
    Points are inserted along a Hilbert curve, refined inside crowded grid
    cells, so clustered (strongly graded) input stays fast. The first call
    compiles the kernel (cached on disk afterwards).

    References
    ----------
    .. [1] J. R. Shewchuk, "Adaptive precision floating-point arithmetic and
       fast robust geometric predicates", Discrete Comput. Geom. 18 (1997)
       305-363, doi:10.1007/PL00009321.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, 0.0]])
    >>> cells, neighbors, duplicate_of = delaunay_with_neighbors(square, return_duplicates=True)
    >>> cells.shape, neighbors.shape
    ((2, 3), (2, 3))
    >>> duplicate_of.tolist()
    [-1, -1, -1, -1, 1]
    """
    triangulation = Triangulation(points)
    cells, neighbors = triangulation.cells_and_neighbors()
    if not return_duplicates:
        return cells, neighbors
    return cells, neighbors, triangulation.duplicate_of


def _scale_exponent(points):
    """Power of two that brings the coordinates to magnitude at most 1 (an exact scaling)."""
    largest = float(np.abs(points).max())
    if largest == 0.0:
        raise GenerationError("the points to triangulate do not span a plane: all points coincide")
    return int(np.frexp(largest)[1])


def _checked_points(points):
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 2:
        raise GenerationError(f"points must have shape (n, 2), got {points.shape}")
    if not np.isfinite(points).all():
        raise GenerationError("points must be finite (found NaN or infinity)")
    if len(points) < 3:
        raise GenerationError(f"cannot triangulate {len(points)} points: the domain is too small for the mesh size")
    return points


class Triangulation:
    """A Delaunay triangulation that follows its points as they move, appear and go.

    Built by exact incremental insertion (see :func:`delaunay_with_neighbors`).
    :meth:`move_points` restores the Delaunay property for new positions by
    Lawson flips from the current connectivity; a point whose move would
    invert a cell is removed and inserted again. :meth:`add_points` inserts,
    :meth:`remove_points` removes. After the small moves of an iterative
    mesh generator this costs a small fraction of a rebuild; a rebuild is
    the fallback whenever the local repair cannot proceed.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Point coordinates, any units; not modified.
    frame : bool, optional
        Also triangulate four points far outside the points' box (never
        returned), so that every point is an interior vertex: points on the
        hull could not be moved or removed locally. The cells returned are
        then those of the points alone, less the flat ones along their hull.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> points = rng.random((100, 2))
    >>> triangulation = Triangulation(points)
    >>> moved = points + 1e-3 * rng.random((100, 2))
    >>> triangulation.move_points(moved)
    True
    >>> def triangles(cells):
    ...     return set(map(tuple, np.sort(cells, axis=1).tolist()))
    >>> triangles(triangulation.cells_and_neighbors()[0]) == triangles(delaunay(moved))
    True
    """

    def __init__(self, points, *, frame=False):
        points = _checked_points(points)
        if frame:
            low, high = bounds(points)
            reach = 4.0 * float(np.max(high - low)) + 1.0
            center = 0.5 * (low + high)
            corners = center + reach * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
            points = np.vstack([corners, points])
        self._offset = 4 if frame else 0
        self._build(points)
        self.rebuilds = 1
        self.flips = 0

    def _build(self, points):
        """Triangulate ``points`` (frame included) from scratch."""
        self._exponent = _scale_exponent(points)
        # a power-of-two scale is exact and keeps the predicates' products far from overflow
        scaled = np.ldexp(points, -self._exponent)
        order = _kernel.hilbert_order(scaled, _HILBERT_BITS, _HILBERT_MAX_RUN)
        status, cells, neighbors, duplicate_sorted = _kernel.triangulate(np.ascontiguousarray(scaled[order]))
        if status == _kernel.TOO_FEW_DISTINCT:
            raise GenerationError("the points to triangulate do not span a plane: fewer than three distinct points")
        if status == _kernel.COLLINEAR:
            raise GenerationError("the points to triangulate do not span a plane: all points are collinear")
        if status != _kernel.OK:
            raise GenerationError("Delaunay point location failed to converge")  # not expected with exact predicates
        n = len(points)
        self._held = scaled
        self._cells = np.append(order, n)[cells]
        self._neighbors = neighbors
        self._duplicate_of = np.full(n, -1, dtype=np.int64)
        skipped = duplicate_sorted >= 0
        self._duplicate_of[order[skipped]] = order[duplicate_sorted[skipped]]

    def _rebuild(self, points):
        self._build(np.vstack([self._held[: self._offset] * 2.0**self._exponent, points]))
        self.rebuilds += 1

    @property
    def n_points(self):
        """Number of points (the frame not counted)."""
        return len(self._held) - self._offset

    @property
    def duplicate_of(self):
        """Index of the point each point coincides with exactly, -1 for vertices; shape (n,)."""
        duplicate_of = self._duplicate_of[self._offset :]
        return np.where(duplicate_of >= 0, duplicate_of - self._offset, -1)

    def _scaled(self, points):
        """``points`` with the frame in front, scaled like the triangulation; None if they outgrow the scale."""
        # written in place, checked without a temporary: at 10**7 points each copy is 160 MB
        scaled = np.empty((self._offset + len(points), 2))
        scaled[: self._offset] = self._held[: self._offset]
        np.ldexp(points, -self._exponent, out=scaled[self._offset :])
        return scaled if scaled.max() < 2.0 and scaled.min() > -2.0 else None

    def move_points(self, points):
        """Follow new positions of the same points.

        Returns
        -------
        bool
            True when local repair (flips, and removing and inserting again
            points whose move would invert a cell) restored the Delaunay
            property, False when the triangulation was rebuilt.
        """
        points = _checked_points(points)
        if len(points) != self.n_points:
            raise GenerationError(f"move_points needs the same {self.n_points} points, got {len(points)}")
        moved = self._scaled(points)
        if moved is not None and not (self._duplicate_of >= 0).any():
            # on failure the state is rebuilt below, so repairing in place is safe
            infinite, marked = len(moved), np.empty(len(self._cells), dtype=np.uint8)
            inverted = _kernel.unsettled_edges(moved, self._cells, self._neighbors, infinite, marked)
            status, flips = _kernel.restore_delaunay(
                moved, self._held, self._cells, self._neighbors, infinite, 4 * len(self._cells), marked, inverted
            )
            self.flips += flips
            if status == _kernel.OK and _kernel.covered_area_mismatch(moved, self._cells, infinite) <= _FOLDED:
                return True
        self._rebuild(points)
        return False

    def add_points(self, points):
        """Insert new points, numbered after the current ones.

        Parameters
        ----------
        points : array_like, shape (k, 2)
            The new points.
        """
        points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        if not np.isfinite(points).all():
            raise GenerationError("points must be finite (found NaN or infinity)")
        if len(points) == 0:
            return
        n_old = len(self._held)
        added = np.ldexp(points, -self._exponent)
        if np.abs(added).max() < 2.0 and not (self._duplicate_of >= 0).any():
            # inserted in Hilbert order (each walk short), numbered in the caller's order by the kernel
            order = _kernel.hilbert_order(added, _HILBERT_BITS, _HILBERT_MAX_RUN)
            held = np.vstack([self._held, added])
            status, cells, neighbors, duplicate_of = _kernel.insert_points(
                held, self._cells, self._neighbors, n_old, n_old, order
            )
            if status == _kernel.OK and not (duplicate_of >= 0).any():
                self._cells, self._neighbors, self._held = cells, neighbors, held
                self._duplicate_of = np.full(len(self._held), -1, dtype=np.int64)
                return
        self._rebuild(np.vstack([self.positions, points]))

    def split_edges(self, keep):
        """Split every edge of the kept cells at its midpoint, each kept cell into four; the midpoints become points.

        Parameters
        ----------
        keep : numpy.ndarray of bool, shape (m,)
            Cells to split, in the order :meth:`cells_and_neighbors` lists them.

        Returns
        -------
        edges : numpy.ndarray, shape (e, 2), or None
            The split edges; the midpoint of ``edges[i]`` is point
            ``n_points + i`` (its exact middle: move it with
            :meth:`move_points`). None, with nothing changed, where the
            direct split cannot be used (duplicate points, a midpoint
            rounded off a nearly flat cell): insert the midpoints instead.
        outer : numpy.ndarray of bool, shape (e,)
            The edges with a kept cell on one side only.

        Raises
        ------
        GenerationError
            If ``keep`` does not have one flag per cell.
        """
        if (self._duplicate_of >= 0).any():
            return None, None
        status, held, cells, neighbors, edges, outer = _kernel.split_edges(
            self._held, self._cells, self._neighbors, len(self._held), self._offset, np.asarray(keep, dtype=bool)
        )
        if status == _kernel.WRONG_SIZE:
            n_cells = len(self.cells_and_neighbors()[0])
            raise GenerationError(f"keep needs one flag per cell ({n_cells}), got {np.size(keep)}")
        if status != _kernel.OK:
            return None, None
        self._held, self._cells, self._neighbors = held, cells, neighbors
        self._duplicate_of = np.full(len(held), -1, dtype=np.int64)
        return edges, outer

    def remove_points(self, indices):
        """Remove points; the rest keep their order (numbers above a removed one shift down).

        Parameters
        ----------
        indices : array_like of int
            Points to remove.
        """
        doomed = np.zeros(len(self._held), dtype=bool)
        doomed[self._offset + np.asarray(indices, dtype=np.int64)] = True
        if not doomed.any():
            return
        n = len(self._held)
        kept = ~doomed
        duplicate = self._duplicate_of >= 0
        if not (duplicate & kept).any():
            # a duplicate is in no cell: removing it needs no repair, and once every duplicate
            # goes the cells are a triangulation of the rest (a generator that drops the point
            # it found doubled after a rebuild needs no second rebuild)
            vertices = doomed & ~duplicate
            numbering = np.append(np.cumsum(kept) - 1, np.count_nonzero(kept))
            if vertices.any():
                status, cells, neighbors = _kernel.remove_points(
                    self._held, self._cells, self._neighbors, vertices, n, numbering
                )
            else:
                status, cells, neighbors = _kernel.OK, numbering[self._cells], self._neighbors
            if status == _kernel.OK:
                self._cells, self._neighbors = cells, neighbors
                self._held = without_rows(self._held, np.flatnonzero(doomed))
                self._duplicate_of = np.full(len(self._held), -1, dtype=np.int64)
                return
        self._rebuild(self.positions[kept[self._offset :]])

    def sort_spatially(self, front):
        """Renumber the points: those ``front`` marks first (in their order), the rest along a Hilbert curve.

        The cells are renumbered with them and sorted by their smallest
        vertex: neighbours in space become neighbours in memory, which every
        pass over points, edges or cells reads faster (about twice at 10**6
        points after refinement left them in edge order).

        Parameters
        ----------
        front : numpy.ndarray of bool, shape (n,)
            Points to keep in front (fixed points, say).

        Returns
        -------
        order : numpy.ndarray, shape (n,)
            The former number of each point: ``points[order]`` renumbers an
            array of the caller's.
        """
        n, offset = self.n_points, self._offset
        first, rest = np.flatnonzero(front), np.flatnonzero(~front)
        if len(rest) > 1:
            rest = rest[_kernel.hilbert_order(self._held[offset + rest], _HILBERT_BITS, _HILBERT_MAX_RUN)]
        order = np.concatenate([first, rest])
        if (self._duplicate_of >= 0).any():
            self._rebuild(self.positions[order])  # rare: the renumbering below assumes every point a vertex
            return order
        new_number = np.empty(len(self._held) + 1, dtype=np.int64)  # the ghost vertex is the last
        new_number[:offset] = np.arange(offset)
        new_number[offset + order] = offset + np.arange(n)
        new_number[-1] = len(self._held)
        self._cells, self._neighbors = _kernel.renumber(self._cells, self._neighbors, new_number)
        self._held = np.vstack([self._held[:offset], self._held[offset + order]])
        return order

    def nearest_distances(self, points):
        """Distance from each of ``points`` to the nearest point of the triangulation (frame corners included).

        Exact, by a greedy descent over the Delaunay neighbours; far cheaper
        than a k-d tree over all the points when the queries are few.

        Parameters
        ----------
        points : array_like, shape (k, 2)

        Returns
        -------
        numpy.ndarray, shape (k,)
        """
        queries = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        if not np.isfinite(queries).all():
            raise GenerationError("points must be finite (found NaN or infinity)")
        queries = np.ldexp(queries, -self._exponent)
        distances = np.empty(len(queries))
        if len(queries):
            order = _kernel.hilbert_order(queries, _HILBERT_BITS, _HILBERT_MAX_RUN)
            distances[order] = _kernel.nearest_vertex_distances(
                self._held, self._cells, self._neighbors, len(self._held), np.ascontiguousarray(queries[order])
            )
        return np.ldexp(distances, self._exponent)

    @property
    def positions(self):
        """Positions the triangulation is Delaunay for, shape (n, 2)."""
        return np.ldexp(self._held[self._offset :], self._exponent)

    def cells_and_neighbors(self):
        """Cells of the points (counter-clockwise) and their neighbour table, -1 where there is no cell across.

        See :func:`delaunay_with_neighbors`. With a frame, cells that touch
        it are left out.
        """
        return _kernel.drop_ghosts(self._cells, self._neighbors, len(self._held), self._offset)

    def cells_with_ghosts(self):
        """The triangulation's own cell and neighbour arrays, and ``first``: vertex ``v + first`` is point ``v``.

        Ghost cells (at the vertex at infinity) and frame cells are among
        them: the cells with a vertex outside ``[first, first + n_points)``.
        A pass that skips those (``classify_cells``, ``inner_cell_edges``)
        saves the ghost-free copy :meth:`cells_and_neighbors` makes, two
        arrays of 24 bytes a cell. The arrays are the triangulation's own:
        read them before it changes.
        """
        return self._cells, self._neighbors, self._offset


# --- 3D: Delaunay tetrahedralisation (Bowyer-Watson) -------------------------------------------------

ENCLOSING_SCALE = 1.0e4  # the enclosing tetrahedron's size over the points' extent
_ENCLOSING = ENCLOSING_SCALE * np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])


def _spread_bits(x):
    x = (x | (x << 16)) & 0x30000FF
    x = (x | (x << 8)) & 0x300F00F
    x = (x | (x << 4)) & 0x30C30C3
    return (x | (x << 2)) & 0x9249249


def morton_order(points):
    """Permutation of ``points`` (n, 3) along a Z-order curve on a 1024**3 grid over their box."""
    if len(points) == 0:  # every point fixed (a domain a few sizes across, its sharp edges sampled)
        return np.empty(0, dtype=np.int64)
    low, high = bounds(points)
    span = max(float((high - low).max()), 1e-300)
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


def _flat_points_message(points, extent, error):
    """Why Qhull found ``points`` flat: how close to a plane they lie, and the first line of its own message."""
    centred = points - points.mean(axis=0)
    normal = np.linalg.svd(centred, full_matrices=False)[2][-1]  # the direction they vary least along
    across = centred @ normal
    thickness = float(across.max() - across.min())
    qhull = (str(error).strip().splitlines() or [type(error).__name__])[0]
    flat = "in one plane" if thickness <= 1e-9 * extent else f"within {thickness:.3g} of a plane"
    return (
        f"the points to tetrahedralise do not span a volume: they lie {flat}, {extent:.3g} across (Qhull: "
        f"{qhull}); a domain much thinner than the mesh size gives such points"
    )


def delaunay_3d(points, *, return_duplicates=False):
    """Delaunay tetrahedralisation of a 3D point set, positively oriented, with the cell adjacency.

    Incremental Bowyer-Watson insertion along a Z-order curve, first with
    floating-point predicates on the points scaled to the unit box: the
    cavity of each point is grown until the point sees all its faces, so
    the result is a valid tetrahedralisation of the points in general
    position the generator makes. Where it is not (a flat cell, a point in
    no cell: cospherical points, as on a lattice), the points are
    tetrahedralised again with exact predicates (Shewchuk's error bounds,
    then exact arithmetic), scaled by a power of two so that no sign
    changes: every distinct point is then a vertex and every cell has a
    positive volume, also on an exact cubic lattice. Where lattice points
    are not exactly on their lattice (tenths, which no double holds), the
    Delaunay cells of the points as given may include slivers flat to
    rounding. SciPy's Qhull is the last resort, should the exact kernel
    fail (a point the enclosing tetrahedron hides from every cell).

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
        Vertex indices with ``(b - a) . ((c - a) x (d - a)) > 0`` (should
        Qhull, the last resort, be needed, some of its cells may be flat).
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
    low, high = bounds(points)
    extent = float((high - low).max())
    if extent == 0.0:
        raise GenerationError("the points to tetrahedralise do not span a volume: all points coincide")
    center = 0.5 * (low + high)
    scaled = (points - center) / extent
    order = morton_order(scaled)
    status, cells, neighbors, duplicate_of = bowyer_watson(np.vstack([scaled, _ENCLOSING]), order, None)
    if status != STATUS_OK or len(cells) == 0:
        # exactly: scaled by a power of two, which changes no sign (centring would round)
        scale = math.ldexp(1.0, -math.frexp(extent)[1])
        enclosed = np.vstack([points * scale, center * scale + _ENCLOSING])
        status, cells, neighbors, duplicate_of = bowyer_watson(enclosed, order, bowyer_watson_workspace(enclosed))
    if status != STATUS_OK or len(cells) == 0:
        try:
            cells, neighbors = _qhull(points)
        except Exception as error:  # Qhull raises its own QhullError for flat input
            raise GenerationError(_flat_points_message(points, extent, error)) from error
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
