"""Kernels of the mesh clean-up: neighbour tables, connected parts, quality-safe smoothing.

Private: ``points`` (n, 2) float64, ``cells`` (m, 3) int64, ``table`` (m, 3)
int64 with ``table[c, k]`` the cell across the edge opposite corner ``k``
(the edge ``cells[c, k+1], cells[c, k+2]``), -1 on the boundary; unvalidated.
"""

import numba
import numpy as np

from .smoothing import moved_corners, star_corners
from .tetra import face_normal
from .topology import cross_and_squares, edges_by_lower_vertex, vertex_cells

_QUALITY_FACTOR = 2.0 * np.sqrt(3.0)  # 4 sqrt(3) A / sum(l^2) with A = cross / 2


@numba.njit(cache=True)
def neighbor_table(cells, n_points):
    """The cell across each edge, shape (m, 3); -1 on the boundary.

    Equal edges meet in one group of :func:`edges_by_lower_vertex`: linear
    time, where sorting the 3 m edges (NumPy's argsort) took 0.34 s at
    587k cells and this 0.07 s. An edge in more than two cells (not
    conforming) is read in the order of its slots ``s = k m + c`` (cell
    ``c``'s edge opposite corner ``k``): the first lists the second's
    cell, each other the cell before it, as pairing neighbours in a
    stable sort of the edges would.
    """
    m = cells.shape[0]
    start, index, upper = edges_by_lower_vertex(cells, n_points)
    table = np.full((m, 3), -1, dtype=np.int64)
    taken = np.zeros(3 * m, dtype=np.bool_)  # an edge already read with an earlier one of its group
    for v in range(n_points):
        for i in range(start[v], start[v + 1]):
            if taken[i]:
                continue
            count = 0
            other = -1
            for j in range(i + 1, start[v + 1]):
                if upper[j] == upper[i]:
                    taken[j] = True
                    count += 1
                    other = j
            if count == 1:
                # edge k of a cell runs from corner k to k + 1: it is opposite corner k + 2
                a = index[i] // 3
                b = index[other] // 3
                table[a, (index[i] % 3 + 2) % 3] = b
                table[b, (index[other] % 3 + 2) % 3] = a
            elif count > 1:
                slots = np.empty(count + 1, dtype=np.int64)
                slots[0] = (index[i] % 3 + 2) % 3 * m + index[i] // 3
                n = 1
                for j in range(i + 1, start[v + 1]):
                    if upper[j] == upper[i]:
                        slots[n] = (index[j] % 3 + 2) % 3 * m + index[j] // 3
                        n += 1
                slots.sort()
                table[slots[0] % m, slots[0] // m] = slots[1] % m
                for t in range(1, n):
                    table[slots[t] % m, slots[t] // m] = slots[t - 1] % m
    return table


@numba.njit(cache=True, inline="always")
def _root(parent, c):
    while parent[c] != c:
        parent[c] = parent[parent[c]]
        c = parent[c]
    return c


@numba.njit(cache=True)
def _labels_in_order(parent):
    """Number the union-find sets ``0, 1, ...`` in the order of their smallest member: ``(n_parts, labels)``."""
    m = parent.shape[0]
    labels = np.full(m, -1, dtype=np.int64)
    n_parts = 0
    for c in range(m):
        r = _root(parent, c)
        if labels[r] < 0:
            labels[r] = n_parts
            n_parts += 1
        labels[c] = labels[r]
    return n_parts, labels


@numba.njit(cache=True)
def edge_components(cells, n_points):
    """Parts of cells joined through shared edges (any number of cells per edge): ``(n_parts, labels (m,))``.

    Parts are numbered in the order of their first cell, as
    :func:`scipy.sparse.csgraph.connected_components` numbers them.
    """
    m = cells.shape[0]
    start, index, upper = edges_by_lower_vertex(cells, n_points)
    parent = np.arange(m)
    for v in range(n_points):
        for i in range(start[v], start[v + 1]):
            for j in range(i + 1, start[v + 1]):
                if upper[i] == upper[j]:
                    a = _root(parent, index[i] // 3)
                    b = _root(parent, index[j] // 3)
                    if a != b:
                        parent[max(a, b)] = min(a, b)
    return _labels_in_order(parent)


@numba.njit(cache=True)
def table_components(table):
    """Parts of cells joined through the neighbour ``table``: ``(n_parts, labels (m,))``, numbered by first cell."""
    m = table.shape[0]
    parent = np.arange(m)
    for c in range(m):
        for k in range(3):
            n = table[c, k]
            if n > c:
                a = _root(parent, c)
                b = _root(parent, n)
                if a != b:
                    parent[max(a, b)] = min(a, b)
    return _labels_in_order(parent)


@numba.njit(cache=True)
def shortest_edges(points, cells):
    """Length of the shortest edge at each vertex, shape (n,); inf at vertices no cell uses."""
    shortest = np.full(points.shape[0], np.inf)
    for c in range(cells.shape[0]):
        for k in range(3):
            a = cells[c, k]
            b = cells[c, (k + 1) % 3]
            dx = points[a, 0] - points[b, 0]
            dy = points[a, 1] - points[b, 1]
            squared = dx * dx + dy * dy
            if squared < shortest[a]:
                shortest[a] = squared
            if squared < shortest[b]:
                shortest[b] = squared
    return np.sqrt(shortest)


@numba.njit(cache=True, inline="always")
def _cell_quality(ax, ay, bx, by, cx, cy, geographic):
    """Quality of the triangle ``a, b, c``.

    Geographic quality scales the cell's longitudes by the cosine of its
    centroid's latitude, as :func:`terramesh.quality.triangle_quality` does.
    """
    shrink = np.cos(np.radians((ay + by + cy) / 3.0)) if geographic else 1.0
    abx = (bx - ax) * shrink
    aby = by - ay
    acx = (cx - ax) * shrink
    acy = cy - ay
    bcx = (cx - bx) * shrink
    bcy = cy - by
    squares = abx * abx + aby * aby + acx * acx + acy * acy + bcx * bcx + bcy * bcy
    if squares > 0.0:
        return _QUALITY_FACTOR * (abx * acy - aby * acx) / squares
    return 0.0


@numba.njit(cache=True)
def smooth_vertices(points, cells, movable, passes, geographic):
    """Move each ``movable`` vertex to the mean of its neighbours where its cells' worst quality does not drop.

    Gauss-Seidel order (vertex by vertex in index order, each seeing the
    moves before it), in place; a move is kept when the worst quality of the
    vertex's cells is positive and not lower than before, so no cell
    inverts and the mesh's worst quality cannot drop. The mean over the
    vertex's cells of their other two corners is the mean of its neighbours
    for an interior vertex (each neighbour is in two of its cells). The
    cells' qualities are kept up to date, so a vertex costs one evaluation
    of its cells. Stops after ``passes`` passes or a pass without a move.
    Returns the (n,) mask of the vertices moved.
    """
    n = points.shape[0]
    start, index = vertex_cells(cells, n)
    quality = np.empty(cells.shape[0])
    for c in range(cells.shape[0]):
        a, b, d = cells[c, 0], cells[c, 1], cells[c, 2]
        quality[c] = _cell_quality(
            points[a, 0], points[a, 1], points[b, 0], points[b, 1], points[d, 0], points[d, 1], geographic
        )
    largest_star = np.max(start[1:] - start[:-1]) if n else 0
    trial = np.empty(largest_star)
    corners = np.empty((largest_star, 4))
    where = np.empty(largest_star, dtype=np.int64)
    moved = np.zeros(n, dtype=np.bool_)
    for _ in range(passes):
        moves = 0
        for v in range(n):
            if not movable[v] or start[v + 1] == start[v]:
                continue
            star = index[start[v] : start[v + 1]]
            x, y = star_corners(points, cells, star, v, corners, where)
            if x == points[v, 0] and y == points[v, 1]:
                continue
            before = np.inf
            after = np.inf
            for s in range(star.shape[0]):
                before = min(before, quality[star[s]])
                ax, ay, bx, by, cx, cy = moved_corners(corners, where, s, x, y)
                trial[s] = _cell_quality(ax, ay, bx, by, cx, cy, geographic)
                after = min(after, trial[s])
            if after >= before and after > 0.0:
                points[v, 0] = x
                points[v, 1] = y
                for s in range(star.shape[0]):
                    quality[star[s]] = trial[s]
                moved[v] = True
                moves += 1
        if moves == 0:
            break
    return moved


@numba.njit(cache=True)
def boundary_degree(cells, table, n_points):
    """Number of boundary edges (``table`` -1) at each vertex, shape (n,)."""
    degree = np.zeros(n_points, dtype=np.int64)
    for c in range(cells.shape[0]):
        for k in range(3):
            if table[c, k] < 0:
                degree[cells[c, (k + 1) % 3]] += 1
                degree[cells[c, (k + 2) % 3]] += 1
    return degree


@numba.njit(cache=True, inline="always")
def _sharp_corner(points, cells, c, v, spike_angle, geographic):
    """Whether cell ``c``'s angle at its corner ``v`` is below ``spike_angle`` degrees (on the ground if geographic)."""
    k = 0 if cells[c, 0] == v else (1 if cells[c, 1] == v else 2)
    a, b, d = cells[c, k], cells[c, (k + 1) % 3], cells[c, (k + 2) % 3]
    shrink = 1.0
    if geographic:  # ground angles: longitudes shrunk by the cosine of the cell's mean latitude
        shrink = np.cos(np.radians((points[cells[c, 0], 1] + points[cells[c, 1], 1] + points[cells[c, 2], 1]) / 3.0))
    after_x = points[b, 0] * shrink - points[a, 0] * shrink
    after_y = points[b, 1] - points[a, 1]
    before_x = points[d, 0] * shrink - points[a, 0] * shrink
    before_y = points[d, 1] - points[a, 1]
    cross = after_x * before_y - after_y * before_x
    dot = after_x * before_x + after_y * before_y
    return np.degrees(np.arctan2(np.abs(cross), dot)) < spike_angle


@numba.njit(cache=True)
def sharp_lone_vertices(points, cells, lone, spike_angle, geographic):
    """The vertices marked ``lone`` (in one cell) whose cell's angle there is below ``spike_angle``, ascending."""
    sharp = np.zeros(lone.shape[0], dtype=np.bool_)
    for c in range(cells.shape[0]):
        for k in range(3):
            v = cells[c, k]
            if lone[v] and _sharp_corner(points, cells, c, v, spike_angle, geographic):
                sharp[v] = True
    return np.flatnonzero(sharp)


@numba.njit(cache=True)
def peel_spikes(points, cells, table, n_points, spike_angle, geographic, is_fixed):
    """Boundary spikes taken out round by round, the ones each round exposes in the next.

    A spike is a boundary vertex in one cell whose angle there is below
    ``spike_angle`` degrees; a round removes the cells of all the spikes
    found at its start. A vertex of the (n,) mask ``is_fixed`` is no spike,
    and a spike's cell stays when such a vertex is in it alone (it would be
    left in no cell). Only the corners of removed cells can turn into
    spikes, so after the first round only they are looked at: a strip one
    cell wide loses a cell per round, and a full pass per round took 26
    passes (0.5 s) on the guide's §5.3 mesh. A spike's cell has all three
    corners on the boundary already (its two edges at the spike are), so
    no vertex joins the boundary. Returns ``(keep, n_spikes, in_cells,
    on_boundary)``: the cells left (m,), the spikes removed, and per vertex
    (n,) the cells left around it and whether it is on the boundary.
    """
    m = cells.shape[0]
    keep = np.ones(m, dtype=np.bool_)
    in_cells = np.zeros(n_points, dtype=np.int64)
    cell_xor = np.zeros(n_points, dtype=np.int64)  # the XOR of a vertex's cells: its cell, when it has one
    on_boundary = np.zeros(n_points, dtype=np.bool_)
    for c in range(m):
        for k in range(3):
            in_cells[cells[c, k]] += 1
            cell_xor[cells[c, k]] ^= c
            if table[c, k] < 0:
                on_boundary[cells[c, (k + 1) % 3]] = True
                on_boundary[cells[c, (k + 2) % 3]] = True
    work = np.empty(n_points, dtype=np.int64)
    n_work = 0
    for v in range(n_points):
        if in_cells[v] == 1 and on_boundary[v]:
            work[n_work] = v
            n_work += 1
    spike_cells = np.empty(n_points, dtype=np.int64)
    seen = np.full(n_points, -1, dtype=np.int64)
    n_spikes = 0
    rounds = 0
    while n_work > 0:
        found = 0
        for i in range(n_work):
            v = work[i]
            lone = in_cells[v] == 1 and on_boundary[v] and not is_fixed[v]
            if lone and _sharp_corner(points, cells, cell_xor[v], v, spike_angle, geographic):
                c = cell_xor[v]
                stranded = False
                for k in range(3):
                    stranded = stranded or (is_fixed[cells[c, k]] and in_cells[cells[c, k]] == 1)
                if not stranded:
                    spike_cells[found] = c
                    found += 1
        n_spikes += found
        rounds += 1
        n_work = 0
        for i in range(found):
            c = spike_cells[i]
            if not keep[c]:  # two spikes of one cell
                continue
            keep[c] = False
            for k in range(3):
                v = cells[c, k]
                in_cells[v] -= 1
                cell_xor[v] ^= c
                if seen[v] != rounds:
                    seen[v] = rounds
                    work[n_work] = v
                    n_work += 1
    return keep, n_spikes, in_cells, on_boundary


@numba.njit(cache=True, inline="always")
def sorted3(a, b, c):
    """Three numbers in increasing order."""
    if a > b:
        a, b = b, a
    if b > c:
        b, c = c, b
    if a > b:
        a, b = b, a
    return a, b, c


@numba.njit(cache=True)
def edge_census(cells, n_points):
    """What repeats among the cells and their edges, from one grouping of the edges.

    Returns ``(repeated, n_repeated_edges, degree)``: the (m,) mask of the
    cells with the same three vertices (in any order) as a cell of smaller
    index; the number of directed edges ``(cells[c, k], cells[c, k + 1])``
    that another edge of any cell repeats; and the (n,) number of boundary
    edges (edges no other edge repeats as an unordered pair) at each vertex.
    Cells with the same vertices share every edge, so only the cells of a
    group of equal edges are compared.
    """
    m = cells.shape[0]
    start, index, upper = edges_by_lower_vertex(cells, n_points)
    repeated = np.zeros(m, dtype=np.bool_)
    repeated_edge = np.zeros(3 * m, dtype=np.bool_)
    shared = np.zeros(3 * m, dtype=np.bool_)
    for v in range(n_points):
        for i in range(start[v], start[v + 1]):
            for j in range(i + 1, start[v + 1]):
                if upper[i] != upper[j]:
                    continue
                shared[index[i]] = True
                shared[index[j]] = True
                a = index[i] // 3
                b = index[j] // 3
                # equal ends and the same first vertex: the same direction
                if cells[a, index[i] % 3] == cells[b, index[j] % 3]:
                    repeated_edge[index[i]] = True
                    repeated_edge[index[j]] = True
                same = sorted3(cells[a, 0], cells[a, 1], cells[a, 2]) == sorted3(cells[b, 0], cells[b, 1], cells[b, 2])
                if a != b and same:
                    repeated[max(a, b)] = True
    degree = np.zeros(n_points, dtype=np.int64)
    for e in range(3 * m):
        if not shared[e]:
            c = e // 3
            k = e % 3
            degree[cells[c, k]] += 1
            degree[cells[c, (k + 1) % 3]] += 1
    return repeated, np.count_nonzero(repeated_edge), degree


@numba.njit(cache=True, inline="always")
def _facet(cells, c, k, n_points):
    """Cell ``c`` without its corner ``k``: the facet's lowest vertex and its other vertices as one key."""
    if cells.shape[1] == 3:
        u = cells[c, (k + 1) % 3]
        w = cells[c, (k + 2) % 3]
        return min(u, w), max(u, w)
    low, middle, high = sorted3(cells[c, (k + 1) % 4], cells[c, (k + 2) % 4], cells[c, (k + 3) % 4])
    return low, middle * n_points + high


@numba.njit(cache=True)
def facets_by_lower_vertex(cells, n_points):
    """The facets of triangles or tetrahedra grouped by their lowest vertex, as a compressed table ``(start, table)``.

    The facet ``4 c + k`` is cell ``c`` without its corner ``k`` (an edge
    of a triangle, a face of a tetrahedron). The rows
    ``table[start[v]:start[v + 1]]`` are the facets whose lowest vertex is
    ``v``: ``(4 c + k, key)``, ``key`` encoding the other vertices
    (ascending ``b``, or ``b * n_points + c`` for ``b < c``). Equal facets
    share a group of a few dozen and their key, as in
    :func:`~terramesh._kernels.topology.edges_by_lower_vertex`. Cell by
    cell, the facet and its key side by side: half the time of filling
    two arrays facet by facet (0.05 s for 750k tetrahedra).
    """
    m, corners = cells.shape
    start = np.zeros(n_points + 1, dtype=np.int64)
    for c in range(m):
        for k in range(corners):
            start[_facet(cells, c, k, n_points)[0] + 1] += 1
    for v in range(n_points):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    table = np.empty((corners * m, 2), dtype=np.int64)
    for c in range(m):
        for k in range(corners):
            v, key = _facet(cells, c, k, n_points)
            table[fill[v], 0] = 4 * c + k
            table[fill[v], 1] = key
            fill[v] += 1
    return start, table


@numba.njit(cache=True, inline="always")
def _far_side(points, a, b, c, p):
    """Which side of facet ``a, b`` (2-D; ``a, b, c`` in 3-D) point ``p`` lies on: a signed multiple of its distance."""
    if points.shape[1] == 2:
        return (points[b, 0] - points[a, 0]) * (points[p, 1] - points[a, 1]) - (points[b, 1] - points[a, 1]) * (
            points[p, 0] - points[a, 0]
        )
    # the normal (b - a) x (c - a), and the dot product term by term in order, as NumPy's cross and einsum
    nx, ny, nz = face_normal(points, a, b, c)
    return (points[p, 0] - points[a, 0]) * nx + (points[p, 1] - points[a, 1]) * ny + (points[p, 2] - points[a, 2]) * nz


@numba.njit(cache=True)
def facet_census(points, cells):
    """What repeats among the facets of triangles or tetrahedra (edges, faces), from one grouping of them.

    Returns ``(lone, n_crowded, n_one_sided, repeated)``: the (corners m,)
    mask of the facets no other facet repeats (the boundary), facet
    ``k m + c`` being cell ``c`` without its corner ``k`` (the order of
    ``np.concatenate([np.delete(cells, k, axis=1) for k in range(corners)])``);
    the number of distinct facets in more than two cells; the number in
    exactly two whose far corners do not lie strictly on opposite sides of
    it (the facet's vertices ascending ``a, b, c``, the product of
    ``((b - a) x (c - a)) . (p - a)`` over the two far corners ``p`` at
    least 0; in 2-D the cross product of ``b - a`` and ``p - a``); and
    whether two cells have the same vertices (in any order): two such
    cells share every facet, with the same far corner. One grouping
    (:func:`facets_by_lower_vertex`) instead of sorting the facets: the 3
    million faces of 750k tetrahedra took 1.5-2 s to lexsort.
    """
    m, corners = cells.shape
    n_points = points.shape[0]
    start, table = facets_by_lower_vertex(cells, n_points)
    lone = np.zeros(corners * m, dtype=np.bool_)
    grouped = np.zeros(corners * m, dtype=np.bool_)  # by row of ``table``: already in a group of equal facets
    largest = 0
    for v in range(n_points):
        largest = max(largest, start[v + 1] - start[v])
    cell = np.empty(largest, dtype=np.int64)  # the cells of a group of equal facets, and their far corners
    far = np.empty(largest, dtype=np.int64)
    n_crowded = 0
    n_one_sided = 0
    repeated = False
    for v in range(n_points):
        for i in range(start[v], start[v + 1]):
            if grouped[i]:
                continue
            count = 0
            for j in range(i, start[v + 1]):
                if table[j, 1] == table[i, 1]:
                    grouped[j] = True
                    cell[count] = table[j, 0] >> 2
                    far[count] = cells[cell[count], table[j, 0] & 3]
                    count += 1
            if count == 1:
                lone[(table[i, 0] & 3) * m + cell[0]] = True
                continue
            if count > 2:
                n_crowded += 1
            for s in range(count):
                for t in range(s + 1, count):
                    repeated = repeated or (cell[s] != cell[t] and far[s] == far[t])
            if count == 2:
                key = table[i, 1]
                b = key if corners == 3 else key // n_points
                c = key % n_points
                if _far_side(points, v, b, c, far[0]) * _far_side(points, v, b, c, far[1]) >= 0.0:
                    n_one_sided += 1
    return lone, n_crowded, n_one_sided, repeated


@numba.njit(cache=True)
def signed_areas(points, cells):
    """Signed area of each triangle (positive counter-clockwise), shape (m,): one pass, no (m, 2) temporaries."""
    out = np.empty(cells.shape[0])
    for c in range(cells.shape[0]):
        a = cells[c, 0]
        b = cells[c, 1]
        d = cells[c, 2]
        out[c] = 0.5 * (
            (points[b, 0] - points[a, 0]) * (points[d, 1] - points[a, 1])
            - (points[b, 1] - points[a, 1]) * (points[d, 0] - points[a, 0])
        )
    return out


@numba.njit(cache=True)
def flat_cells(points, cells, flat):
    """Mask (m,) of the triangles whose signed area is at most ``flat`` times the sum of their squared sides.

    Clockwise and flat cells, in one pass (NumPy's corners, differences and
    sums took 0.13 s for 587k cells).
    """
    out = np.empty(cells.shape[0], dtype=np.bool_)
    for c in range(cells.shape[0]):
        cross, squares = cross_and_squares(points, cells, c)
        out[c] = 0.5 * cross <= flat * squares
    return out


@numba.njit(cache=True)
def centroids_surely_inside(points, cells, anchors, upper):
    """Cells whose centroid at ``points`` is certainly inside a domain with a 1-Lipschitz distance.

    ``upper`` (n,) bounds the distance at ``anchors`` (n, 2) from above;
    the distance at the centroid is at most, for every corner ``v``,
    ``upper[v]`` plus the centroid's distance to ``anchors[v]``, so a cell
    where the least of these is negative is inside. Returns a boolean (m,)
    mask; False means "evaluate it".
    """
    m = cells.shape[0]
    sure = np.zeros(m, dtype=np.bool_)
    for c in range(m):
        x = (points[cells[c, 0], 0] + points[cells[c, 1], 0] + points[cells[c, 2], 0]) / 3.0
        y = (points[cells[c, 0], 1] + points[cells[c, 1], 1] + points[cells[c, 2], 1]) / 3.0
        bound = np.inf
        for k in range(3):
            v = cells[c, k]
            bound = min(bound, upper[v] + np.hypot(x - anchors[v, 0], y - anchors[v, 1]))
        sure[c] = bound < 0.0
    return sure
