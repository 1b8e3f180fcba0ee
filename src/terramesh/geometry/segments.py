"""Exact distance from many points to many line segments.

Long segments are first split (which leaves the polyline unchanged) so that
every piece is at most ``2 * half_length`` long. Near the segments, where the
mesh generator asks nearly all its questions, a bucket grid answers: cells
about a piece wide list the pieces meeting them, and the cells are searched
ring by ring around the point until no unsearched cell can hold anything
nearer (numba, exact). Farther out, a KD-tree holds the midpoints of the
pieces. A piece whose midpoint is ``r`` away from a point is at
least ``r - half_length`` away, so after testing the ``k`` nearest segments
the true distance lies between ``r_k - half_length`` and the best found.
Points where that gap exceeds ``relative_tolerance`` times the distance are
queried again with a larger ``k``: the result is within a relative error of
``relative_tolerance``, at ``O(log m)`` cost per point.
"""

import numpy as np
from scipy.spatial import cKDTree

from .._kernels.segments import (
    candidate_nearest_points,
    candidate_segment_distance,
    crossing_sides,
    grid_nearest,
    nearest_sides,
)
from ..errors import GeometryError

__all__ = ["SegmentIndex"]

_FIRST_K = 8
_CELLS_PER_SEGMENT = 4  # bucket grid cells per segment piece (the cells are never smaller than a piece)
_MAX_RING = 3  # rings of cells searched around a point before the KD-tree takes it
_MAX_CELLS_PER_SIDE = 2048  # bounds the grid's memory (4 million cells at most)
_PIECES_PER_SEGMENT = 64  # long segments are cut into pieces of about twice the median length, within this bound
# below this many points a KD query runs in this thread: starting threads cost 0.4-0.9 ms a query
# (2 cores), as much as 1,000 points' query, and a strip's cut placement makes hundreds of small ones
_THREADED_QUERY = 2000


def _bucket_grid(starts, ends, longest, other_ends):
    """A uniform grid over the segments with the pieces meeting each cell: the arguments of ``grid_nearest``.

    The cell side is at least the longest piece (so a piece meets at most
    2 x 2 cells), large enough for about ``_CELLS_PER_SEGMENT`` cells per
    piece, and at least the extent over ``_MAX_CELLS_PER_SIDE``. A piece
    is listed in the cells its box meets, the box also holding its
    ``other_ends`` (the same piece ending a rounding away).
    """
    lower = np.minimum(np.minimum(starts, ends), other_ends)  # each piece's box
    upper = np.maximum(np.maximum(starts, ends), other_ends)
    origin = lower.min(axis=0) if len(starts) else np.zeros(2)
    width = (upper.max(axis=0) - origin) if len(starts) else np.ones(2)
    extent = float(width.max())
    if not extent > np.finfo(float).tiny:  # every piece a point at one place (or subnormal distances apart)
        extent = 1.0
    area = float(np.prod(width))
    cell = max(longest, np.sqrt(area / max(_CELLS_PER_SEGMENT * len(starts), 1)), extent / _MAX_CELLS_PER_SIDE)
    nx, ny = (np.floor(width / cell).astype(np.int64) + 1).tolist()
    low = np.floor((lower - origin) / cell).astype(np.int64)
    high = np.minimum(np.floor((upper - origin) / cell).astype(np.int64), [nx - 1, ny - 1])
    piece, cell_id = [], []
    for di in (0, 1):
        for dj in (0, 1):
            meets = (low[:, 0] + di <= high[:, 0]) & (low[:, 1] + dj <= high[:, 1])
            piece.append(np.flatnonzero(meets))
            cell_id.append((low[meets, 0] + di) * ny + low[meets, 1] + dj)
    piece, cell_id = np.concatenate(piece), np.concatenate(cell_id)
    order = np.argsort(cell_id, kind="stable")
    cell_start = np.zeros(nx * ny + 1, dtype=np.int64)
    np.cumsum(np.bincount(cell_id, minlength=nx * ny), out=cell_start[1:])
    return origin.astype(np.float64), float(cell), nx, ny, cell_start, piece[order].astype(np.int64), _MAX_RING


class SegmentIndex:
    """Nearest-segment queries on a fixed set of 2D segments.

    Parameters
    ----------
    starts, ends : numpy.ndarray, shape (m, 2)
        Segment end points, float64.
    relative_tolerance : float, optional
        Largest relative error of a returned distance.
    following : numpy.ndarray of int, shape (m,), optional
        For closed rings: the segment that starts where each one ends.
        Needed for :meth:`distance_and_side`.

    Examples
    --------
    >>> import numpy as np
    >>> index = SegmentIndex(np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]))
    >>> index.distance(np.array([[0.5, 2.0], [2.0, 0.0]])).tolist()
    [2.0, 1.0]
    """

    def __init__(self, starts, ends, *, relative_tolerance=1e-2, following=None):
        self.relative_tolerance = float(relative_tolerance)
        lengths = np.hypot(*(ends - starts).T)
        extent = float(np.ptp(np.vstack([starts, ends]))) if len(starts) else 0.0
        usable = lengths[lengths > 1e-9 * extent]
        piece = 2.0 * float(np.median(usable)) if usable.size else max(extent, 1.0)
        # a few long segments among many tiny ones (1e-7 and 20 long: 10**8 pieces, out of memory) cut
        # into at most _PIECES_PER_SEGMENT times as many pieces as there are segments
        piece = max(piece, float(lengths.sum()) / (_PIECES_PER_SEGMENT * max(len(lengths), 1)))
        counts = np.maximum(np.ceil(lengths / piece).astype(np.int64), 1)
        owner = np.repeat(np.arange(len(lengths)), counts)
        first = np.cumsum(counts) - counts
        step = np.arange(owner.size) - first[owner]
        fraction = (ends - starts)[owner] / counts[owner, None]
        self.starts = starts[owner] + step[:, None] * fraction
        self.ends = self.starts + fraction
        self.half_length = 0.5 * float(np.max(np.hypot(*fraction.T)))
        self._owner = owner  # the segment each piece is of
        # the pieces again, each ending exactly where the next begins (start + fraction may miss it by
        # a rounding): a crossing count on them has no gap to slip through
        last = first + counts - 1
        self._chained_ends = np.empty_like(self.starts)
        self._chained_ends[:-1] = self.starts[1:]
        self._chained_ends[last] = ends
        self._tree = cKDTree(0.5 * (self.starts + self.ends))
        self._grid = _bucket_grid(self.starts, self.ends, 2.0 * self.half_length, self._chained_ends)
        self._neighbours = None
        self._clearances = None
        if following is not None:
            # pieces of a segment follow each other; the last one is followed by the next segment's first
            after = np.arange(owner.size) + 1
            after[last] = first[np.asarray(following)]
            before = np.empty_like(after)
            before[after] = np.arange(owner.size)
            length = np.hypot(*fraction.T)
            normal = np.column_stack([-fraction[:, 1], fraction[:, 0]]) / np.where(length > 0, length, 1.0)[:, None]
            self._neighbours = (before, after, normal)

    def distance_and_side(self, points, radius=None, return_nearest=False):
        """Exact distance and side of the nearest segment, for the points near the segments.

        Needs ``following`` (closed rings). A point whose nearest point is
        inside a segment is on the side of that segment; one nearest to a
        vertex is on the side of the sum of the two segments' normals there
        (the bisector), which is right for a closed ring that does not cross
        itself. At a needle's tip, where the normals nearly cancel, the
        vertex's exact turn decides, also for points the two segments tie
        for (a crack or spike as thin as a rounding); a ring folding back
        exactly there leaves them 0.

        Parameters
        ----------
        points : numpy.ndarray, shape (n, 2)
        radius : float, optional
            Settle only the points within ``radius`` of a segment (fewer grid
            cells searched); by default the grid's reach.
        return_nearest : bool, optional
            Also return the nearest point of the segments, shape (n, 2),
            exact where settled (what :meth:`nearest_points` gives there).

        Returns
        -------
        distance : numpy.ndarray, shape (n,)
            Exact where settled, infinite elsewhere.
        side : numpy.ndarray of int8, shape (n,)
            1 left, -1 right, 0 on a segment, not settled or at an exact fold.
        settled : numpy.ndarray of bool, shape (n,)
            Every point within ``radius`` (or the grid's reach) is settled.

        Raises
        ------
        GeometryError
            If the index was built without ``following``.

        Examples
        --------
        >>> import numpy as np
        >>> square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
        >>> index = SegmentIndex(square, np.roll(square, -1, axis=0), following=np.array([1, 2, 3, 0]))
        >>> distance, side, settled = index.distance_and_side(np.array([[0.5, 0.1], [1.5, 1.5]]))
        >>> distance.round(6).tolist(), side.tolist()
        ([0.1, 0.707107], [1, -1])
        """
        if self._neighbours is None:
            raise GeometryError("distance_and_side needs the segments' order: build the index with following=")
        points = np.ascontiguousarray(points, dtype=np.float64)
        origin, cell, nx, ny, cell_start, cell_items, rings = self._grid
        if radius is not None:
            rings = int(np.ceil(radius / cell)) + 1
        distance, nearest, settled, segment, parameter = grid_nearest(
            points, self.starts, self.ends, origin, cell, nx, ny, cell_start, cell_items, rings
        )
        before, after, normal = self._neighbours
        side = nearest_sides(
            points, settled, segment, parameter, normal, before, after, self.starts, self.ends, self._chained_ends
        )
        if return_nearest:
            return distance, side, settled, nearest
        return distance, side, settled

    def nearest_segments(self, points, radius):
        """The segment nearest each of ``points`` (n, 2) within ``radius``, -1 for a point farther from all.

        Examples
        --------
        >>> import numpy as np
        >>> index = SegmentIndex(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[1.0, 0.0], [1.0, 1.0]]))
        >>> index.nearest_segments(np.array([[0.5, 0.0], [1.0, 0.7], [5.0, 5.0]]), 1e-9).tolist()
        [0, 1, -1]
        """
        points = np.ascontiguousarray(points, dtype=np.float64)
        origin, cell, nx, ny, cell_start, cell_items, _ = self._grid
        rings = int(min(np.ceil(radius / cell) + 1, max(nx, ny) + 1))  # the whole grid at most (cells of 1e-150)
        distance, _, settled, piece, _ = grid_nearest(
            points, self.starts, self.ends, origin, cell, nx, ny, cell_start, cell_items, rings
        )
        found = settled & (distance <= radius)
        return np.where(found, self._owner[np.where(found, piece, 0)], -1)

    def clearance(self, points):
        """A lower bound of each point's distance to the segments, from the empty cells of the bucket grid around it.

        A point in a cell whose centre is ``D`` cells from the centre of the
        nearest cell holding a piece is at least ``D - sqrt(2)`` cells from
        every piece (each point lies within half a diagonal of its cell's
        centre). Free after a distance transform of the grid, made once;
        where the grid search stops at a radius, this bounds the points far
        from the segments far better than that radius does. 0 outside the
        grid.

        Examples
        --------
        >>> import numpy as np
        >>> index = SegmentIndex(np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]))
        >>> bool(index.clearance(np.array([[0.5, 0.0]]))[0] == 0.0)
        True
        """
        points = np.ascontiguousarray(points, dtype=np.float64)
        origin, cell, nx, ny, cell_start = self._grid[:5]
        if self._clearances is None:
            from scipy.ndimage import distance_transform_edt  # 0.16 s to import, and only a coastline's search needs it

            empty = (np.diff(cell_start) == 0).reshape(nx, ny)
            if empty.all():
                self._clearances = np.zeros((nx, ny))
            else:
                self._clearances = np.maximum(distance_transform_edt(empty) - np.sqrt(2.0), 0.0) * cell
        index = np.floor((points - origin) / cell)
        on_grid = np.all((index >= 0) & (index < [nx, ny]), axis=1)
        out = np.zeros(len(points))
        i, j = index[on_grid].astype(np.int64).T
        out[on_grid] = self._clearances[i, j]
        return out

    def cell_centres(self):
        """Centres of the bucket grid's cells, shape ``(cells, 2)``: the order :meth:`sides` takes their sides in."""
        x, y = self._centre_coordinates()
        return np.column_stack([np.repeat(x, len(y)), np.tile(y, len(x))])

    def _centre_coordinates(self):
        origin, cell, nx, ny = self._grid[:4]
        return origin[0] + (np.arange(nx) + 0.5) * cell, origin[1] + (np.arange(ny) + 0.5) * cell

    def sides(self, points, centre_inside, tolerance=None):
        """Inside or outside closed rings, from the cell centres' sides and the crossings on the way to each point.

        Needs the segments to form closed rings that chain exactly (each
        ends where the next begins). Costs about one cell's pieces per
        point, where a search for the nearest segment's side looks through
        nine cells or more.

        Parameters
        ----------
        points : numpy.ndarray, shape (n, 2)
        centre_inside : numpy.ndarray of bool, shape (cells,)
            Which of the :meth:`cell_centres` are inside.
        tolerance : float, optional
            A point inside but within ``tolerance`` of a segment counts as outside.

        Returns
        -------
        numpy.ndarray of int8, shape (n,)
            1 inside, -1 outside, 0 undecided: a point on a segment or in
            line with one and its cell's centre, where rounding could
            change the answer.

        Examples
        --------
        >>> import numpy as np
        >>> square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
        >>> index = SegmentIndex(square, np.roll(square, -1, axis=0))
        >>> centres = index.cell_centres()
        >>> centre_inside = ((centres > 0) & (centres < 1)).all(axis=1)
        >>> index.sides(np.array([[0.5, 0.1], [1.5, 0.5]]), centre_inside).tolist()
        [1, -1]
        >>> index.sides(np.array([[0.5, 0.1]]), centre_inside, tolerance=0.2).tolist()
        [-1]
        """
        points = np.ascontiguousarray(points, dtype=np.float64)
        centre_inside = np.asarray(centre_inside, dtype=np.bool_)
        tolerance = -1.0 if tolerance is None else float(tolerance)
        pieces = (self.starts, self.ends, self._chained_ends)
        grid = self._grid[:6]  # origin, cell, nx, ny, cell_start, cell_items
        return crossing_sides(points, *pieces, *grid, *self._centre_coordinates(), centre_inside, tolerance)

    def distance(self, points, *, searched=False):
        """Unsigned distance from each point to the nearest segment, shape ``(n,)``.

        ``searched``: the bucket grid has not settled these points already
        (a caller's :meth:`distance_and_side`), so the KD-tree takes them
        at once.
        """
        return self._nearest(points, candidate_segment_distance, searched=searched)

    def nearest_points(self, points):
        """The nearest point on the segments to each point, shape ``(n, 2)``.

        Exact where the distance is (near the segments); elsewhere a point
        of a segment within ``relative_tolerance`` of the nearest distance.

        Examples
        --------
        >>> import numpy as np
        >>> index = SegmentIndex(np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]))
        >>> index.nearest_points(np.array([[0.5, 2.0], [2.0, 1.0]])).tolist()
        [[0.5, 0.0], [1.0, 0.0]]
        """
        nearest = np.empty((len(points), 2))
        self._nearest(points, candidate_nearest_points, nearest)
        return nearest

    def _nearest(self, points, kernel, nearest=None, searched=False):
        """Distances (and ``nearest`` points): exact from the bucket grid near the segments, else from the KD-tree.

        Points the grid's rings do not settle (all with ``searched``) get ``kernel(points, starts,
        ends, candidates)`` (distances, or ``(distances, nearest points)``)
        over ever more KD candidates until each is within the tolerance.
        """
        points = np.ascontiguousarray(points, dtype=np.float64)
        if searched:
            distance, pending = np.full(len(points), np.inf), np.arange(len(points))
        else:
            distance, grid_points, settled, _, _ = grid_nearest(points, self.starts, self.ends, *self._grid)
            if nearest is not None:
                nearest[settled] = grid_points[settled]
            pending = np.flatnonzero(~settled)
        k = _FIRST_K
        total = len(self.starts)
        while pending.size:
            k = min(k, total)
            workers = -1 if len(pending) >= _THREADED_QUERY else 1
            mid_distance, candidates = self._tree.query(points[pending], k=k, workers=workers)
            mid_distance = mid_distance.reshape(len(pending), k)
            candidates = candidates.reshape(len(pending), k).astype(np.int64, copy=False)
            result = kernel(points[pending], self.starts, self.ends, candidates)
            best, located = result if isinstance(result, tuple) else (result, None)
            lower_bound = mid_distance[:, -1] - self.half_length
            done = (k == total) | (best - lower_bound <= self.relative_tolerance * best)
            distance[pending[done]] = best[done]
            if nearest is not None:
                nearest[pending[done]] = located[done]
            pending = pending[~done]
            k *= 4
        return distance
