"""Join two overlapping meshes into one, the first keeping the overlap (the guide's ``+`` operator, §6.5).

:func:`merge` (also ``a + b``) keeps every cell of ``a`` as it is, drops
the cells of ``b`` that lie in ``a``'s region or too close to it, and fills
the gap between the two with new cells that share exactly the boundary
vertices and edges of both sides: no hanging node, no overlap, no vertex
moved. The seam is graded: ``b``'s cells are dropped as far from ``a`` as
their size needs to relax from ``a``'s at the grade limit, and the gap is
meshed for a size that grows from each side at that grade.

How the gap is meshed (every step keeps a conforming triangulation, so the
result is valid by construction; it is checked once more at the end):

1. ``b``'s cells are dropped where a vertex lies inside ``a``'s region or
   nearer to it than ``max(buffer * h, (h_b - h_a) / g)`` (``h`` the local
   element sizes), or where the cell crosses the region.
2. The boundary vertices of ``a``, of ``b``'s kept cells and of ``b``'s
   outer boundary where it is clear of ``a`` (half a seam cell away, the
   seam's size growing from ``a``'s; an edge that comes nearer is cut back
   to its clear stretches, which end at new points) are triangulated (exact
   Delaunay, :func:`~terramesh.generation.triangulate.delaunay_with_neighbors`) and
   all those boundary edges are recovered by edge flips (Sloan 1993): a
   constrained Delaunay triangulation in which no cell crosses a boundary.
   Its cells inside ``b``'s region, outside ``a``'s region and outside
   ``b``'s kept cells form the gap.
3. The gap is refined pass after pass: its boundary edges that belong to
   no kept cell (``b``'s dropped outer boundary, chords where the two
   boundaries cross) are split at their midpoints where longer than the
   graded size, and the centroid of each cell larger than it is inserted,
   each followed by Lawson flips that never cross the gap's boundary. The
   graded size is ``min_i (h_i + g |x - p_i|)`` over the gap's boundary
   vertices ``p_i`` with their own meshes' sizes ``h_i``.
4. The new interior points are smoothed (density-weighted centroidal
   smoothing; a move that would invert a cell is undone) and flipped back
   to Delaunay.
5. Seam cells on the merged boundary below quality 0.5 (as
   :func:`~terramesh.cleanup.clean` would remove) and seam cells that make
   a vertex have more than two boundary edges are deleted, and so are
   small parts of the seam left apart from both meshes.

Everything runs on the plane the meshes were made on: the Mercator plane
for longitude-latitude meshes (so the cells of ``a`` and ``b``, straight
there, are met exactly), the points' own plane otherwise. Vertices of
``a`` and ``b`` keep their coordinates bit for bit; only new vertices are
projected back.
"""

import logging
import numbers
import time

import numpy as np
import shapely
from scipy import sparse
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import spsolve
from scipy.spatial import cKDTree

from .._kernels.merge import insert_points, make_delaunay, recover_edges, split_boundary_edges
from ..cleanup.disjoint import cell_components
from ..cleanup.fix_mesh import remove_unused_points
from ..cleanup.validity import mesh_problems
from ..errors import GeometryError, MeshValidityError, warn_user
from ..generation.triangulate import delaunay_with_neighbors
from ..mesh.mesh import Mesh
from ..mesh.topology import (
    boundary_edges,
    boundary_loops,
    cell_centroids,
    cell_neighbor_table,
    signed_areas,
    unique_edges,
)
from ..quality.triangle import triangle_quality
from ..sizing.gradation import DEFAULT_GRADE
from .boundaries import cut_region
from .projection import from_mercator, to_mercator

__all__ = ["merge", "mesh_add", "DEFAULT_GRADE"]

logger = logging.getLogger("terramesh.coastal")


BOUNDARIES_DROPPED = "merge drops the open and land boundaries"  # the warning's words, by which a caller mutes it
_NEIGHBOURS = 24  # boundary vertices whose cones bound the gap's size at a point
_SPLIT_RATIO = 1.35  # a gap cell whose circumradius * sqrt(3) exceeds this many target sizes is split
_MAX_REFINE_PASSES = 60
_MIN_INSERT_DISTANCE = 0.45  # no point is inserted nearer than this many target sizes to a vertex of its cell
_PEEL_QUALITY = 0.5  # a seam cell on the merged boundary below this quality goes (as in clean())
_LEAST_PART = 8  # a part of the seam cut off from both meshes with fewer cells than this goes
_FLAT = 1e-3  # a triangulated cell of the gap below this quality is a sliver along a straight boundary


# --- geometry of a mesh ---------------------------------------------------------------------------


def _region(points, cells, *, holes=True):
    """The area a valid mesh covers, as a shapely (Multi)Polygon (with its holes unless ``holes=False``)."""
    loops, area = boundary_loops(points, cells)
    rings = [points[loop] for loop in loops]
    shells = [shapely.Polygon(r) for r, s in zip(rings, area, strict=True) if s > 0]
    inner = [r for r, s in zip(rings, area, strict=True) if s < 0]
    if not holes or not inner:
        return shapely.MultiPolygon(shells) if len(shells) > 1 else shells[0]
    shell_area = shapely.area(shells)
    tree = shapely.STRtree(shells)
    probe = shapely.points([r[0] for r in inner])
    hole_index, shell_index = tree.query(probe, predicate="within")
    # the smallest shell around each hole is the one it belongs to
    order = np.lexsort((shell_area[shell_index], hole_index))
    hole_index, shell_index = hole_index[order], shell_index[order]
    first = np.ones(len(hole_index), dtype=bool)
    first[1:] = hole_index[1:] != hole_index[:-1]
    owned = [[] for _ in shells]
    for h, s in zip(hole_index[first], shell_index[first], strict=True):
        owned[s].append(inner[h])
    polygons = [shapely.Polygon(shell.exterior.coords, owned[i]) for i, shell in enumerate(shells)]
    return shapely.MultiPolygon(polygons) if len(polygons) > 1 else polygons[0]


def _vertex_sizes(points, cells):
    """Mean length of the edges at each vertex, shape (n,)."""
    edges = unique_edges(cells)
    length = np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)
    total = np.bincount(edges.ravel(), weights=np.repeat(length, 2), minlength=len(points))
    count = np.bincount(edges.ravel(), minlength=len(points))
    return total / np.maximum(count, 1)


def _circumradius(points, cells):
    a, b, c = (points[cells[:, i]] for i in range(3))
    la = np.linalg.norm(b - c, axis=1)
    lb = np.linalg.norm(c - a, axis=1)
    lc = np.linalg.norm(a - b, axis=1)
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    return la * lb * lc / np.maximum(4.0 * area, np.finfo(float).tiny)


class _ConeSize:
    """``h(x) = min_i (h_i + g |x - p_i|)`` over the nearest sites: sizes growing at the grade ``g`` from each site."""

    def __init__(self, sites, sizes, grade):
        self.tree = cKDTree(sites)
        self.sizes = np.asarray(sizes, dtype=np.float64)
        self.grade = grade
        self.k = min(_NEIGHBOURS, len(sites))

    def __call__(self, points):
        if len(points) == 0:  # a pass with no edge left to split
            return np.zeros(0)
        distance, index = self.tree.query(points, k=self.k)
        distance, index = distance.reshape(len(points), -1), index.reshape(len(points), -1)
        return np.min(self.sizes[index] + self.grade * distance, axis=1)


# --- the gap ---------------------------------------------------------------------------------------


class _Held:
    """A triangulation with room to grow: points (capacity, 2), cells and neighbours (capacity, 3)."""

    def __init__(self, points, cells, neighbors):
        self.points, self.cells, self.neighbors = points, cells, neighbors
        self.n_points, self.n_cells = len(points), len(cells)

    def reserve(self, more_points, more_cells):
        if self.n_points + more_points > len(self.points):
            size = max(2 * len(self.points), self.n_points + more_points)
            self.points = np.concatenate([self.points[: self.n_points], np.empty((size - self.n_points, 2))])
        if self.n_cells + more_cells > len(self.cells):
            size = max(2 * len(self.cells), self.n_cells + more_cells)
            extra = np.empty((size - self.n_cells, 3), dtype=np.int64)
            self.cells = np.concatenate([self.cells[: self.n_cells], extra])
            self.neighbors = np.concatenate([self.neighbors[: self.n_cells], extra])


def _refine(points, cells, neighbors, size, locked, smoothing):
    """Refine the seam to ``size``; returns its points (the given ones first, unmoved) and cells.

    Each pass splits the boundary edges that are not ``locked`` (sorted
    vertex pairs, as keys ``min * n + max`` with ``n = len(points)``) and
    are longer than the size, at their midpoints, then the cells larger
    than the size, at their centroids. Then the new interior points are
    smoothed.
    """
    n_given = len(points)
    held = _Held(points.copy(), cells.copy(), neighbors.copy())
    on_boundary = []
    for _ in range(_MAX_REFINE_PASSES):
        p, c, nb = held.points[: held.n_points], held.cells[: held.n_cells], held.neighbors[: held.n_cells]
        cell, corner = np.nonzero(nb < 0)
        u, v = c[cell, (corner + 1) % 3], c[cell, (corner + 2) % 3]
        free = ~np.isin(np.minimum(u, v) * n_given + np.maximum(u, v), locked) | (np.maximum(u, v) >= n_given)
        cell, corner, u, v = cell[free], corner[free], u[free], v[free]
        middle = 0.5 * (p[u] + p[v])
        target = size(middle)
        long = (np.linalg.norm(p[u] - p[v], axis=1) > _SPLIT_RATIO * target) & (
            np.linalg.norm(p[c[cell, corner]] - middle, axis=1) > _MIN_INSERT_DISTANCE * target
        )
        before = held.n_points
        if long.any():
            held.reserve(int(long.sum()), int(long.sum()))
            held.n_points, held.n_cells = split_boundary_edges(
                held.points,
                held.n_points,
                held.cells,
                held.n_cells,
                held.neighbors,
                np.column_stack([cell, corner, u, v])[long],
                np.ascontiguousarray(middle[long]),
            )
            on_boundary.append(np.arange(before, held.n_points))
        p, c = held.points[: held.n_points], held.cells[: held.n_cells]
        centroid = p[c].mean(axis=1)
        target = size(centroid)
        split = np.flatnonzero(np.sqrt(3.0) * _circumradius(p, c) > _SPLIT_RATIO * target)
        if len(split):
            nearest = np.min(np.linalg.norm(p[c[split]] - centroid[split, None, :], axis=2), axis=1)
            split = split[nearest > _MIN_INSERT_DISTANCE * target[split]]
        if len(split):
            held.reserve(len(split), 2 * len(split))
            held.n_points, held.n_cells = insert_points(
                held.points,
                held.n_points,
                held.cells,
                held.n_cells,
                held.neighbors,
                split,
                np.ascontiguousarray(centroid[split]),
            )
        if held.n_points == before:
            break
    points = held.points[: held.n_points].copy()
    cells = held.cells[: held.n_cells].copy()
    neighbors = held.neighbors[: held.n_cells].copy()
    movable = np.arange(len(points)) >= n_given
    if on_boundary:
        movable[np.concatenate(on_boundary)] = False
    if movable.any() and smoothing:
        points = _smooth(points, cells, neighbors, size, movable, smoothing)
    return points, cells


def _smooth(points, cells, neighbors, size, movable, passes):
    """Density-weighted centroidal smoothing of the ``movable`` points, with flips; no cell inverts."""
    empty = np.zeros(0, dtype=np.int64)
    for _ in range(passes):
        corner = points[cells]
        centroid = corner.mean(axis=1)
        area = np.abs(signed_areas(points, cells))
        weight = np.repeat(area / size(centroid) ** 2, 3)
        flat = cells.ravel()
        total = np.bincount(flat, weights=weight, minlength=len(points))
        target = (
            np.column_stack(
                [
                    np.bincount(flat, weights=weight * np.repeat(centroid[:, axis], 3), minlength=len(points))
                    for axis in (0, 1)
                ]
            )
            / np.maximum(total, np.finfo(float).tiny)[:, None]
        )
        moved = points.copy()
        moved[movable] = target[movable]
        for _ in range(20):
            inverted = signed_areas(moved, cells) <= 0
            if not inverted.any():
                break
            back = np.zeros(len(points), dtype=bool)
            back[cells[inverted].ravel()] = True
            moved[back] = points[back]
        else:
            break
        points = moved
        make_delaunay(points, cells, neighbors, empty)
    return points


def _harmonic(values, known, cells):
    """Fill the vertices not ``known`` with the discrete harmonic extension of the known values.

    Each unknown vertex becomes the average of its neighbours (graph
    Laplacian over the edges of ``cells``); unknown vertices with no known
    vertex in their part of the graph get NaN. ``values`` is (n,) or (n, k)
    float; returns a filled copy.
    """
    n = len(values)
    flat = values.reshape(n, -1).copy()
    edges = unique_edges(cells)
    rows = np.concatenate([edges[:, 0], edges[:, 1]])
    columns = np.concatenate([edges[:, 1], edges[:, 0]])
    adjacency = sparse.csr_matrix((np.ones(len(rows)), (rows, columns)), shape=(n, n))
    _, part = connected_components(adjacency, directed=False)
    anchored = np.zeros(part.max() + 1, dtype=bool)
    anchored[part[known]] = True
    solve = ~known & anchored[part]
    flat[~known & ~solve] = np.nan
    if solve.any():
        laplacian = (sparse.diags(np.asarray(adjacency.sum(axis=1)).ravel()) - adjacency).tocsr()
        unknown, given = np.flatnonzero(solve), np.flatnonzero(known)
        rhs = -(laplacian[unknown][:, given] @ flat[given])
        solution = spsolve(laplacian[unknown][:, unknown].tocsc(), rhs)
        flat[unknown] = np.asarray(solution).reshape(len(unknown), -1)
    return flat.reshape(values.shape)


def _same_crs(a, b):
    if a.geographic or b.geographic:
        return a.geographic and b.geographic
    return (a.crs or "").upper() == (b.crs or "").upper()


def _checked(mesh, name):
    if not isinstance(mesh, Mesh):
        raise TypeError(f"merge joins two terramesh.Mesh objects; {name} is a {type(mesh).__name__}")
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise GeometryError(
            f"merge joins 2D triangle meshes; {name} has {mesh.dim}D points and {mesh.cells.shape[1]}-corner cells"
        )
    problems = mesh_problems(mesh)
    if problems:
        # hanging nodes are looked for in a mesh with no other problem, and fix_mesh cannot join such parts
        advice = (
            "repair it first (fix_mesh)"
            if mesh_problems(mesh, hanging_nodes=False)
            else "give the parts matching nodes along where they meet, which fix_mesh cannot mend"
        )
        raise MeshValidityError(f"{name} is not a valid mesh ({'; '.join(problems)}): {advice}")


def _plane(points, geographic):
    """Coordinates on the plane the mesh was made on: Mercator metres for longitude-latitude, else as given."""
    if not geographic:
        return np.ascontiguousarray(points, dtype=np.float64)
    return np.column_stack(to_mercator(points[:, 0], points[:, 1]))


def _from_plane(points, geographic):
    if not geographic:
        return points
    return np.column_stack(from_mercator(points[:, 0], points[:, 1]))


def _distance_to_boundary(tree, boundary_points, starts, ends, queries):
    """Distance from ``queries`` to the boundary segments at the nearest boundary vertex, and that vertex."""
    distance, nearest = tree.query(queries)
    best = distance.copy()
    for other in (starts, ends):
        a, b = boundary_points[nearest], boundary_points[other[nearest]]
        ab = b - a
        t = np.clip(np.sum((queries - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
        np.minimum(best, np.linalg.norm(queries - a - t[:, None] * ab, axis=1), out=best)
    return best, nearest


class _NearA:
    """Distance from points to the region ``a`` owns, and ``a``'s element size on its boundary nearest to them."""

    def __init__(self, xa, a_cells, owned, region):
        self.size_a = _vertex_sizes(xa, a_cells)
        edges = boundary_edges(a_cells)
        self.on_boundary, position = np.unique(edges, return_inverse=True)
        position = position.reshape(edges.shape)
        # each boundary vertex's two boundary neighbours, as positions in on_boundary
        self.following = np.empty(len(self.on_boundary), dtype=np.int64)
        self.preceding = np.empty(len(self.on_boundary), dtype=np.int64)
        self.following[position[:, 0]] = position[:, 1]
        self.preceding[position[:, 1]] = position[:, 0]
        self.boundary_points = xa[self.on_boundary]
        self.tree = cKDTree(self.boundary_points)
        self.owned, self.region = owned, region

    def __call__(self, points):
        distance, nearest = _distance_to_boundary(
            self.tree, self.boundary_points, self.preceding, self.following, points
        )
        if self.region is not None:
            np.minimum(distance, shapely.distance(self.region, shapely.points(points)), out=distance)
        distance[shapely.contains_xy(self.owned, points[:, 0], points[:, 1])] = 0.0
        return distance, self.size_a[self.on_boundary[nearest]]


def _clearance(distance, size_near, size_b, grade, buffer):
    """Distance to ``a`` less half the seam's least width; where positive, ``b``'s outer boundary can bound the seam.

    The seam's size at a point grows from ``a``'s at the grade, so a coarse
    ``b``'s outer boundary bounds the seam wherever half a seam cell fits
    between it and ``a``, not half one of ``b``'s cells.
    """
    seam_size = np.maximum(size_near, np.minimum(size_b, size_near + grade * distance))
    return distance - 0.5 * buffer * seam_size, seam_size


def _dropped_cells(near, xb, b_cells, size_b, distance, size_near, grade, buffer):
    """Mask of ``b``'s cells in ``a``'s owned region or nearer to it than the seam needs.

    ``distance`` and ``size_near`` are ``near(xb)``.
    """
    needed = np.maximum(buffer * np.maximum(size_b, size_near), (size_b - size_near) / grade)
    drop = np.any(distance[b_cells] < needed[b_cells], axis=1)
    # a cell whose corners are all far enough may still straddle a thin part of the region
    longest = np.max(np.linalg.norm(xb[b_cells] - xb[np.roll(b_cells, 1, axis=1)], axis=2), axis=1)
    unsure = np.flatnonzero(~drop & (np.min(distance[b_cells], axis=1) < 2.0 * longest))
    if len(unsure):
        drop[unsure] = shapely.intersects(near.owned, shapely.polygons(xb[b_cells[unsure]]))
    return drop


def _without_pinches(cells, n_points):
    """Drop cells at vertices with more than two boundary edges until there are none."""
    while len(cells):
        degree = np.bincount(boundary_edges(cells).ravel(), minlength=n_points)
        bad = degree > 2
        if not bad.any():
            break
        cells = cells[~np.any(bad[cells], axis=1)]
    return cells


def _outer_constraints(xb, b_cells, b_kept, size_b, near, distance, size_near, grade, buffer):
    """``b``'s outer boundary where it is clear of ``a``: the seam's outer edge.

    The outer boundary edges of ``b``'s dropped cells are kept whole where
    the whole edge is clear of ``a`` (:func:`_clearance`); the others are
    cut back to their clear stretches,
    sampled at a fifth of the seam's size, which end at new points on the
    edge. Returns the edges (indices into ``xb`` followed by the new points),
    the new points and the seam's size at them.
    """
    outer = boundary_edges(b_cells)
    n = len(xb)
    kept = boundary_edges(b_kept) if len(b_kept) else np.zeros((0, 2), dtype=np.int64)
    outer = outer[~np.isin(outer[:, 0] * n + outer[:, 1], kept[:, 0] * n + kept[:, 1])]
    clear, seam_size = _clearance(distance, size_near, size_b, grade, buffer)
    # an edge is clear all along when its ends are clear by more than half its length (the clearance
    # changes by at most 1 + buffer * grade / 2 per unit length); the others are sampled
    length = np.linalg.norm(xb[outer[:, 1]] - xb[outer[:, 0]], axis=1)
    whole = np.min(clear[outer], axis=1) > (0.5 + 0.25 * buffer * grade) * length
    if whole.any():
        whole[whole] = ~shapely.intersects(near.owned, shapely.linestrings(xb[outer[whole]]))
    cut, outer = outer[~whole], outer[whole]
    nothing = (outer, np.zeros((0, 2)), np.zeros(0))
    if not len(cut):
        return nothing
    u, v = cut[:, 0], cut[:, 1]
    length = np.linalg.norm(xb[v] - xb[u], axis=1)
    least = np.minimum(seam_size[u], seam_size[v])
    pieces = np.clip(np.ceil(length / (0.2 * least)), 1, 1000).astype(np.int64)
    edge = np.repeat(np.arange(len(cut)), pieces + 1)
    first = np.concatenate([[0], np.cumsum(pieces + 1)[:-1]])
    t = (np.arange(len(edge)) - first[edge]) / pieces[edge]
    samples = xb[u][edge] + t[:, None] * (xb[v] - xb[u])[edge]
    sample_clearance, sample_size = _clearance(
        *near(samples), (1 - t) * size_b[u][edge] + t * size_b[v][edge], grade, buffer
    )
    sample_clear = sample_clearance > 0
    # runs of clear samples along each edge; a run of more than one sample is a stretch of the seam's edge
    opens = sample_clear & ((t == 0) | ~np.roll(sample_clear, 1))
    closes = sample_clear & ((t == 1) | ~np.roll(sample_clear, -1))
    starts, ends = np.flatnonzero(opens), np.flatnonzero(closes)
    run_length = (t[ends] - t[starts]) * length[edge[starts]]
    long = run_length >= 0.5 * least[edge[starts]]
    starts, ends = starts[long], ends[long]
    if len(starts):
        clear_of_a = ~shapely.intersects(near.owned, shapely.linestrings(np.stack([samples[starts], samples[ends]], 1)))
        starts, ends = starts[clear_of_a], ends[clear_of_a]
    ends_of_runs = np.stack([starts, ends], axis=1)
    at_vertex = np.where(t[ends_of_runs] == 0, u[edge[ends_of_runs]], v[edge[ends_of_runs]])
    new = (t[ends_of_runs] > 0) & (t[ends_of_runs] < 1)
    index = np.where(new, n + np.cumsum(new.ravel()).reshape(new.shape) - 1, at_vertex)
    where = ends_of_runs[new]
    return np.concatenate([outer, index]), samples[where], sample_size[where]


def _gap_triangulation(x, constraints, owned, b_region, b_kept_region):
    """Constrained Delaunay triangulation of the ``constraints`` (edges, global indices); its cells in the gap."""
    vertices, local = np.unique(constraints, return_inverse=True)
    local = local.reshape(constraints.shape)
    points = np.ascontiguousarray(x[vertices])
    cells, neighbors = delaunay_with_neighbors(points)
    cells, neighbors = np.ascontiguousarray(cells), np.ascontiguousarray(neighbors)
    failed = recover_edges(points, cells, neighbors, np.ascontiguousarray(local))
    if failed:
        raise MeshValidityError(
            f"{failed} boundary edges of the two meshes could not be kept in the seam's triangulation"
            " (a vertex of one lies on an edge of the other?)"
        )
    keys = np.unique(np.sort(local, axis=1) @ np.array([len(points), 1]))
    make_delaunay(points, cells, neighbors, keys)
    centroid = cell_centroids(points, cells)
    # flat cells lie along straight stretches of the hull, where rounding put collinear points a hair apart
    gap = (
        (triangle_quality(points, cells) > _FLAT)
        & shapely.contains_xy(b_region, centroid[:, 0], centroid[:, 1])
        & ~shapely.contains_xy(owned, centroid[:, 0], centroid[:, 1])
        & ~shapely.contains_xy(b_kept_region, centroid[:, 0], centroid[:, 1])
    )
    return vertices[cells[gap]]


def _trim(points, cells, removable, anchors):
    """Delete removable cells until the boundary is manifold and has no poor removable cell on it.

    A removable cell on the boundary below quality :data:`_PEEL_QUALITY`
    (a sliver between the seam's outer edge and a mesh's boundary) goes;
    at each vertex with more than two boundary edges, the removable cell
    there with the most boundary edges (the lowest quality among equals)
    goes; repeated until neither is left. Parts of removable cells alone
    then go unless they have :data:`_LEAST_PART` cells or more and one of
    the ``anchors`` (a mask of vertices). Returns the mask of cells kept.
    """
    n = len(points)
    keep = np.ones(len(cells), dtype=bool)
    quality = triangle_quality(points, cells)
    for _ in range(100):
        index = np.flatnonzero(keep)
        edges = boundary_edges(cells[index])
        degree = np.bincount(edges.ravel(), minlength=n)
        bad = degree > 2
        edge_keys = edges[:, 0] * n + edges[:, 1]
        candidates = index[removable[index]]
        directed = np.stack(
            [cells[candidates][:, [0, 1]], cells[candidates][:, [1, 2]], cells[candidates][:, [2, 0]]], 1
        )
        on_boundary = np.isin(directed[..., 0] * n + directed[..., 1], edge_keys).sum(axis=1)
        poor = candidates[(on_boundary > 0) & (quality[candidates] < _PEEL_QUALITY)]
        at_bad = np.any(bad[cells[candidates]], axis=1)
        if len(poor) == 0 and not at_bad.any():
            break
        keep[poor] = False
        if at_bad.any():
            rank = np.repeat(np.flatnonzero(at_bad), 3)
            corner = cells[candidates][at_bad].ravel()
            touching = candidates[rank]
            chosen = bad[corner]
            touching, corner, rank = touching[chosen], corner[chosen], rank[chosen]
            order = np.lexsort((quality[touching], -on_boundary[rank], corner))
            first = np.ones(len(order), dtype=bool)
            first[1:] = corner[order][1:] != corner[order][:-1]
            keep[touching[order][first]] = False
    # parts made of removable cells alone (left over by the deletions) go too, unless large and on
    # b's outer boundary: b's area, re-meshed, that the deletions cut off from a at a thin place
    index = np.flatnonzero(keep)
    _, part = cell_components(cells[index])
    on_b = np.zeros(part.max() + 1, dtype=bool)
    on_b[np.repeat(part, 3)[anchors[cells[index].ravel()]]] = True
    kept_part = on_b & (np.bincount(part) >= _LEAST_PART)
    kept_part[part[~removable[index]]] = True
    keep[index[~kept_part[part]]] = False
    return keep


def _merged_point_data(a, b, b_vertices, gap_cells, n_old, n_new):
    """Per-vertex data: both meshes' values; new vertices get the harmonic interpolation of the seam's boundary."""
    shared = [name for name in a.point_data if name in b.point_data]
    left_out = sorted(set(a.point_data) ^ set(b.point_data))
    if left_out:
        warn_user(
            f"point_data {left_out} is in only one of the meshes and was left out of the merged mesh",
        )
    data = {}
    known = np.arange(n_old + n_new) < n_old
    for name in shared:
        va, vb = np.asarray(a.point_data[name]), np.asarray(b.point_data[name])
        old = np.concatenate([va, vb[b_vertices]])
        if n_new == 0:
            data[name] = old
            continue
        dtype = np.result_type(old.dtype, np.float64)
        gap_vertices, local = np.unique(gap_cells, return_inverse=True)
        local = local.reshape(gap_cells.shape)
        values = np.full((len(gap_vertices),) + old.shape[1:], np.nan, dtype=dtype)
        is_old = known[gap_vertices]
        values[is_old] = old[gap_vertices[is_old]]
        finite = np.all(np.isfinite(values.reshape(len(values), -1)), axis=1)
        values = _harmonic(values, finite, local)
        new = np.full((n_new,) + old.shape[1:], np.nan, dtype=dtype)
        new[gap_vertices[~is_old] - n_old] = values[~is_old]
        data[name] = np.concatenate([old.astype(dtype), new])
    return data


def _fixed_points_followed(a, b, number, kept):
    """``a``'s then ``b``'s ``info["fixed_points"]`` as vertices of the merged mesh (-1 for those it left out).

    ``number`` maps ``a``'s vertices, then ``b``'s, to the merged numbering
    before the unused vertices went (-1 for ``b``'s dropped ones); ``kept``
    the vertices that stayed, ascending.
    """
    old = []
    for mesh, offset in ((a, 0), (b, len(a.points))):
        index = np.asarray(mesh.info.get("fixed_points", []), dtype=np.int64).reshape(-1)
        old.append(np.where(index >= 0, number[offset + np.maximum(index, 0)], -1))
    old = np.concatenate(old)
    position = np.minimum(np.searchsorted(kept, np.maximum(old, 0)), max(len(kept) - 1, 0))
    return np.where((old >= 0) & (kept[position] == old), position, -1)


FINER_DROPPED = 0.5
"""Ratio of ``b``'s median element size in the overlap to ``a``'s there under which :func:`merge` warns."""


def _warn_if_finer_dropped(xa, xb, owned, b_region, size_a, size_b):
    """Warn where ``b`` is much finer than ``a`` where they overlap: ``a`` keeps the overlap, ``b``'s detail goes.

    ``outer + inner`` (the order reversed) dropped 7,330 of an estuary's
    10,812 fine cells for the regional mesh's coarse ones, with no word.
    """
    b_over = shapely.contains_xy(owned, xb[:, 0], xb[:, 1])
    a_over = shapely.contains_xy(b_region, xa[:, 0], xa[:, 1])
    if b_over.sum() < 10 or a_over.sum() < 3:
        return
    fine, coarse = float(np.median(size_b[b_over])), float(np.median(size_a[a_over]))
    if fine < FINER_DROPPED * coarse:
        warn_user(
            f"merge(a, b) keeps a where they overlap, and b is {coarse / fine:.3g} times finer there (median"
            f" element {fine:.4g} against {coarse:.4g}): {int(b_over.sum())} of b's vertices go; to keep a fine"
            " inner mesh in a coarse outer one, merge(inner, outer)"
        )


def merge(a, b, *, grade=None, buffer=1.0, region=None, smoothing=12, **guide_names):
    """Join two overlapping meshes into one valid mesh, ``a`` keeping the overlap (the guide's ``a + b``, §6.5).

    Every cell and vertex of ``a`` is kept unchanged (they come first, in
    their order). Cells of ``b`` in ``a``'s region, or nearer to it than a
    graded seam needs, are dropped; the gap between ``a``'s boundary and
    ``b``'s remaining cells is filled with new cells (and new interior
    vertices) sharing exactly the boundary vertices and edges of both
    sides. The seam's size grows from each side's local element size at
    the grade ``g``. See the module notes for the algorithm.

    Parameters
    ----------
    a, b : Mesh
        Valid 2D triangle meshes with the same ``crs``: longitude, latitude
        in degrees (geographic; merged on the Mercator plane, where coastal
        meshes are made), or planar coordinates in any one unit.
    grade : float, optional
        ``g``: largest growth of the element size per unit distance across
        the seam (default :data:`~terramesh.sizing.DEFAULT_GRADE`, 0.2). ``b``'s cells of size
        ``h_b`` are dropped within ``(h_b - h_a) / g`` of ``a``, where
        ``h_a`` is ``a``'s element size on its nearest boundary.
    buffer : float, optional
        Least width of the seam, in local element sizes (the larger of the
        two sides'); ``b``'s cells nearer than that to ``a`` are dropped.
    region : shapely geometry, optional
        Area ``a`` owns beyond its own cells, in ``a``'s coordinates (e.g.
        the box ``a`` was meshed in, so that ``b``'s water is not kept where
        ``a`` has land). By default ``a`` owns the area inside its outer
        boundary (its holes, islands, included).
    smoothing : int, optional
        Smoothing passes of the seam's new vertices (0: none).
    **guide_names
        ``g`` for ``grade``.

    Returns
    -------
    Mesh
        Points: ``a``'s, then ``b``'s kept vertices, then the seam's new
        ones; cells: ``a``'s, ``b``'s kept cells, the seam's. ``point_data``
        present in both meshes follows the vertices (new vertices get the
        harmonic interpolation of the seam's boundary values).
        ``boundaries`` is None: the open and land boundaries must be made
        again (:func:`~terramesh.coastal.make_boundaries`); where both
        meshes know the region they were cut from
        (:func:`~terramesh.coastal.cut_region`), ``info["region"]`` is
        the union of the two, whose edge ``make_boundaries`` opens.
        ``info["merge"]`` has ``seam_cells`` (indices of the new cells),
        ``seam_quality_min``/``_mean``, ``dropped_cells`` (of ``b``),
        ``new_points``, ``grade`` and ``seconds``. Where ``a`` or ``b``
        has ``info["fixed_points"]``, so does the merged mesh: ``a``'s
        then ``b``'s, as its vertices (-1 for one of ``b``'s the merge
        dropped), which :func:`enforce_timestep` keeps.

    Raises
    ------
    TypeError
        If ``a`` or ``b`` is not a :class:`~terramesh.Mesh`, or for an unknown option.
    GeometryError
        If they have different CRS or are not 2D triangle meshes.
    MeshValidityError
        If either input is invalid (see :func:`~terramesh.cleanup.mesh_problems`).

    Warns
    -----
    TerrameshWarning
        When boundaries are dropped, ``point_data`` is only in one mesh, the
        meshes are apart, or ``b`` is much finer than ``a`` where they
        overlap (:data:`FINER_DROPPED`: the order reversed?).

    Notes
    -----
    Not commutative: ``a + b`` keeps ``a`` in the overlap, ``b + a`` keeps ``b``.

    References
    ----------
    S. W. Sloan, "A fast algorithm for generating constrained Delaunay
    triangulations", Computers & Structures 47(3), 441-450, 1993.
    :doi:`10.1016/0045-7949(93)90239-A`

    Examples
    --------
    >>> import terramesh as tm
    >>> coarse = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.2, seed=0)
    >>> fine = tm.generate_mesh(tm.geometry.Disk((1.0, 0.5), 0.3), 0.06, seed=0)
    >>> merged = merge(fine, coarse)
    >>> tm.cleanup.mesh_problems(merged), bool((merged.cells[: fine.n_cells] == fine.cells).all())
    ([], True)
    """
    started = time.perf_counter()
    if guide_names:
        unknown = sorted(set(guide_names) - {"g"})
        if unknown:
            raise TypeError(
                f"unknown option(s) {unknown}; merge takes grade (the guide's g), buffer, region, smoothing"
            )
        if grade is not None:
            raise TypeError("'g' and 'grade' are the same option; give one")
        grade = guide_names["g"]
    grade = DEFAULT_GRADE if grade is None else float(grade)
    if not (np.isfinite(grade) and grade > 0):
        raise GeometryError(f"grade must be a positive number, got {grade!r}")
    if not isinstance(smoothing, numbers.Integral) or isinstance(smoothing, bool) or smoothing < 0:
        raise GeometryError(f"smoothing must be a non-negative integer of passes, got {smoothing!r}")
    buffer = float(buffer)
    if not (np.isfinite(buffer) and buffer >= 0):
        raise GeometryError(f"buffer must be a non-negative number of element sizes, got {buffer!r}")
    _checked(a, "a")
    _checked(b, "b")
    if not _same_crs(a, b):
        raise GeometryError(f"the meshes must have the same crs to merge, got {a.crs!r} and {b.crs!r}")
    if a.boundaries is not None or b.boundaries is not None:
        warn_user(
            f"{BOUNDARIES_DROPPED}: make them again on the merged mesh (make_boundaries)",
        )
    geographic = a.geographic
    xa, xb = _plane(a.points, geographic), _plane(b.points, geographic)
    na = len(xa)
    owned = _region(xa, a.cells, holes=False)
    region_plane = None
    if region is not None:
        if not isinstance(region, shapely.Geometry) or region.is_empty:
            raise GeometryError(f"region must be a non-empty shapely geometry, got {region!r}")
        region_plane = (
            shapely.transform(region, lambda xy: np.column_stack(to_mercator(xy[:, 0], xy[:, 1])))
            if geographic
            else region
        )
        owned = shapely.union(owned, region_plane)
    shapely.prepare(owned)
    near = _NearA(xa, a.cells, owned, region_plane)
    size_b = _vertex_sizes(xb, b.cells)
    distance, size_near = near(xb)  # b's vertices: which cells go, and where b's outer boundary is clear
    drop = _dropped_cells(near, xb, b.cells, size_b, distance, size_near, grade, buffer)
    b_kept = _without_pinches(b.cells[~drop], len(xb))
    nb = len(xb)
    outer, extra, extra_size = _outer_constraints(xb, b.cells, b_kept, size_b, near, distance, size_near, grade, buffer)
    x = np.concatenate([xa, xb, extra])
    b_region = _region(xb, b.cells)
    _warn_if_finer_dropped(xa, xb, owned, b_region, near.size_a, size_b)
    apart = float(shapely.distance(_region(xa, a.cells), b_region))
    if apart > 0:
        warn_user(
            f"the meshes neither overlap nor touch ({apart:.4g} {'Mercator metres' if geographic else 'units'}"
            " apart): the merged mesh is in two parts, joined by no seam"
        )
    b_kept_region = _region(xb, b_kept) if len(b_kept) else shapely.Polygon()
    for polygon in (b_region, b_kept_region):
        shapely.prepare(polygon)
    # a's boundary and the kept part of b's are locked; b's outer boundary in the seam may be split
    locked = [boundary_edges(a.cells)]
    if len(b_kept):
        locked.append(boundary_edges(b_kept) + na)
    locked = np.concatenate(locked)
    gap = _gap_triangulation(x, np.concatenate([locked, outer + na]), owned, b_region, b_kept_region)
    sizes = np.concatenate([near.size_a, size_b, extra_size])
    # the seam alone: its own numbering, its boundary vertices first (fixed)
    seam_vertices, local = np.unique(gap, return_inverse=True) if len(gap) else (np.zeros(0, np.int64), gap)
    local = local.reshape(gap.shape)
    new_plane = np.zeros((0, 2))
    if len(gap):
        size = _ConeSize(x[seam_vertices], sizes[seam_vertices], grade)
        position = np.searchsorted(seam_vertices, locked)
        position = np.minimum(position, len(seam_vertices) - 1)
        in_seam = np.all(seam_vertices[position] == locked, axis=1)
        ends = np.sort(position[in_seam], axis=1)
        seam_points, local = _refine(
            np.ascontiguousarray(x[seam_vertices]),
            np.ascontiguousarray(local),
            cell_neighbor_table(local),
            size,
            np.unique(ends[:, 0] * len(seam_vertices) + ends[:, 1]),
            smoothing,
        )
        new_plane = seam_points[len(seam_vertices) :]
    # numbering of the merged mesh: a's vertices, b's kept ones, the seam's new ones (on b's outer edge first)
    new_plane = np.concatenate([extra, new_plane])
    n_new = len(new_plane)
    used_b = np.zeros(nb, dtype=bool)
    used_b[b_kept.ravel()] = True
    used_b[gap[(gap >= na) & (gap < na + nb)] - na] = True
    b_vertices = np.flatnonzero(used_b)
    number = np.full(na + nb + len(extra), -1, dtype=np.int64)
    number[:na] = np.arange(na)
    number[na + b_vertices] = na + np.arange(len(b_vertices))
    n_old = na + len(b_vertices)
    number[na + nb :] = n_old + np.arange(len(extra))
    seam_number = np.concatenate([number[seam_vertices], n_old + np.arange(len(extra), n_new)])
    seam_cells = seam_number[local] if len(gap) else np.zeros((0, 3), dtype=np.int64)
    points = np.concatenate([a.points, b.points[b_vertices], _from_plane(new_plane, geographic)])
    cells = np.concatenate([a.cells, number[na + b_kept], seam_cells])
    is_seam = np.arange(len(cells)) >= len(a.cells) + len(b_kept)
    plane_points = np.concatenate([xa, xb[b_vertices], new_plane])
    keep = _trim(
        plane_points, cells, is_seam, (np.arange(len(plane_points)) >= na) & (np.arange(len(plane_points)) < n_old)
    )
    cells, is_seam = cells[keep], is_seam[keep]
    point_data = _merged_point_data(a, b, b_vertices, cells[is_seam], n_old, n_new)
    # vertices of b and new ones left unused by the deletions go (a's are all used: a is valid)
    points, cells, kept = remove_unused_points(points, cells)
    n_new = int(np.sum(kept >= n_old))
    point_data = {name: values[kept] for name, values in point_data.items()}
    merged = Mesh(points, cells, point_data=point_data, title=a.title, crs=a.crs)
    regions = [cut_region(a), cut_region(b)]
    if all(region is not None for region in regions):
        # open boundaries lie on the parts' outline: two boxes side by side are no rectangle
        merged.info["region"] = shapely.union(*regions)
    if "fixed_points" in a.info or "fixed_points" in b.info:
        # gauges and inflow nodes (pfix) stay fixed: enforce_timestep removed them once the merge had dropped this
        merged.info["fixed_points"] = _fixed_points_followed(a, b, number, kept)
    problems = mesh_problems(merged)
    if problems:
        raise MeshValidityError("merging produced an invalid mesh: " + "; ".join(problems))
    quality = triangle_quality(points, cells[is_seam], geographic=geographic)
    merged.info["merge"] = dict(
        seam_cells=np.flatnonzero(is_seam),
        seam_quality_min=float(quality.min()) if len(quality) else float("nan"),
        seam_quality_mean=float(quality.mean()) if len(quality) else float("nan"),
        dropped_cells=int(len(b.cells) - len(b_kept)),
        new_points=n_new,
        grade=grade,
        seconds=time.perf_counter() - started,
    )
    logger.info(
        "merged: %d + %d cells of b kept + %d seam cells%s, %.2f s",
        a.n_cells,
        len(b_kept),
        int(is_seam.sum()),
        f" (q min {quality.min():.3f})" if len(quality) else "",
        merged.info["merge"]["seconds"],
    )
    return merged


def mesh_add(a, b):
    """``a + b`` for meshes: :func:`merge` with its defaults (``NotImplemented`` when ``b`` is no mesh).

    Parameters
    ----------
    a : Mesh
        The mesh that keeps the overlap: a valid 2D triangle mesh, points
        ``(n, 2)`` in longitude, latitude degrees or in planar coordinates
        of any one unit, as :func:`merge` takes it.
    b : Mesh or object
        The mesh joined to ``a``, with the same ``crs``; anything that is
        no :class:`~terramesh.Mesh` gives ``NotImplemented``, so that Python
        tries ``b.__radd__`` and then raises ``TypeError``.

    Returns
    -------
    Mesh or NotImplemented
        :func:`merge`'s mesh (``a``'s vertices and cells first), with
        ``grade``, ``buffer``, ``region`` and ``smoothing`` at their
        defaults.

    Raises
    ------
    TypeError
        If ``a`` is no :class:`~terramesh.Mesh` (``b`` is).
    GeometryError, MeshValidityError
        As :func:`merge`: different CRS, no 2D triangle meshes, an invalid input.

    Examples
    --------
    >>> import terramesh as tm
    >>> left = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1.2, 1)), 0.1, seed=0)
    >>> right = tm.generate_mesh(tm.geometry.Rectangle((1, 0), (2, 1)), 0.1, seed=0)
    >>> tm.cleanup.mesh_problems(mesh_add(left, right))
    []
    """
    if not isinstance(b, Mesh):
        return NotImplemented
    return merge(a, b)
