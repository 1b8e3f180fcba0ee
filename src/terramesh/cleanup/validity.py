"""Check the validity rules of a mesh (OceanMesh2D guide §2.2; tetrahedral meshes too)."""

import numpy as np

from .._kernels.cleanup import edge_census, facet_census, flat_cells
from .._kernels.delaunay3d import link_components
from .._kernels.segments import meeting_edges, vertices_on_edges
from ..errors import MeshValidityError
from ..geometry.base import distance_gradient
from ..mesh.topology import (
    any_corner_in,
    boundary_edges,
    cell_centroids,
    checked_cells,
    checked_points,
    coincident_points,
    loops_along,
    sorted_cell_edges,
    sorted_unique,
    unique_edges,
)
from ..quality.tetra import tetra_volumes

__all__ = [
    "mesh_problems",
    "check_mesh",
    "cells_outside",
    "near_seam_vertices",
    "hanging_vertices",
    "hanging_on_boundary",
    "NEAR_SEAM",
]


def mesh_problems(mesh, domain=None, boundary_tolerance=None, overlaps=True, *, hanging_nodes=True):
    """List every validity rule the mesh breaks (an empty list means valid).

    The rules, for triangles in 2D (the OceanMesh2D guide's §2.2) and
    tetrahedra in 3D: cells of positive area or volume (counter-clockwise
    triangles); no unused or duplicate vertices; no duplicate cells; every
    edge (face, in 3D) in at most two cells and, where in two, with the
    cells on its two sides (conformity); a manifold boundary (in 2D every
    boundary vertex on exactly two boundary edges; in 3D every boundary
    edge on exactly two boundary faces and the boundary faces around each
    vertex one fan). With ``domain`` also: every cell centroid inside the
    domain (or no farther out than the chord of a curved boundary takes it,
    see :func:`cells_outside`) and, with ``boundary_tolerance``, every boundary vertex within
    that distance of the domain boundary. Unless ``overlaps`` is False,
    also no ground (space, in 3D) covered twice by cells that fit edge to
    edge (face to face): two parts laid across each other, one lying inside
    another, or in 2D a fold within one part (a vertex dragged past its
    neighbour, its turned-over cells dropped or turned back).

    Parameters
    ----------
    mesh : terramesh.Mesh
        A triangle mesh with 2D points or a tetrahedral mesh.
    domain : Domain, optional
        The domain it should fill.
    boundary_tolerance : float or callable, optional
        Largest allowed ``|distance|`` of a boundary vertex, a number or a
        function of the vertex coordinates.
    overlaps : bool, optional
        Look for cells lying over each other. 2D: shapely, 0.4 s at 10**6
        vertices; boundary edges that cross by rounding where the domain
        pinches to nothing (1e-6 of an edge on the guide's §5.3 coast) are
        not an overlap: the area covered twice near them is what counts.
        3D: boundary edges through boundary faces, and a point just inside
        each boundary face inside another cell (KD-trees, 0.2 s at 10**5
        tetrahedra); an edge through a face by less than ``OVERLAP_DEPTH``
        of the face's longest edge is rounding, not an overlap.
    hanging_nodes : bool, optional
        Look for hanging nodes in a 2D mesh (:func:`hanging_vertices`; a
        KD-tree over the boundary vertices). :func:`~terramesh.cleanup.fix_mesh`, which cannot
        join such parts, looks without them and warns of them instead.

    Returns
    -------
    list of str

    Raises
    ------
    MeshValidityError
        For triangles with 3D points (a surface: the rules are for meshes
        that fill a domain), or a ``boundary_tolerance`` without a
        ``domain``.

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> corner = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> mesh_problems(tm.Mesh(corner, [[0, 1, 2, 3]])), mesh_problems(tm.Mesh(corner, [[0, 2, 1, 3]]))
    ([], ['1 cells are inverted or have zero volume'])

    A square of two cells beside a rectangle whose corner lies halfway up the square's side:

    >>> points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [1, 0.5], [2, 0.5], [2, 1.5], [1, 1.5]])
    >>> mesh_problems(tm.Mesh(points, [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]))[0][:52]
    '2 hanging nodes: boundary vertices on another bounda'
    """
    return problems_and_lone_facets(mesh, domain, boundary_tolerance, overlaps, hanging_nodes)[0]


def problems_and_lone_facets(mesh, domain, boundary_tolerance, overlaps, hanging_nodes):
    """:func:`mesh_problems`, and the boundary of a tetrahedral mesh its rules found (None for triangles).

    The boundary is the facets of :func:`~terramesh._kernels.cleanup.facet_census` in no other cell,
    ascending: :func:`terramesh.io.write_fwi_mesh` writes them without a second census.
    """
    from ..mesh.mesh import Mesh

    if not isinstance(mesh, Mesh):
        raise MeshValidityError(f"give a terramesh Mesh, tm.Mesh(points, cells), not a {type(mesh).__name__}")
    points, cells = mesh.points, mesh.cells
    if boundary_tolerance is not None and domain is None:  # else no vertex was measured and the mesh passed
        raise MeshValidityError("boundary_tolerance measures the boundary vertices against a domain: give the domain")
    if len(cells) == 0:
        return ["the mesh has no cells"], None
    lone = None
    if cells.shape[1] == 4:
        problems, on_boundary, surface, lone = _tetrahedron_problems(points, cells)
        if overlaps and not problems:  # the cells fit face to face: they may still lie in each other
            problems += _tetrahedron_overlap_problems(points, cells, *surface)
    elif points.shape[1] == 2:
        problems, on_boundary = _triangle_problems(points, cells)
        if not problems and (overlaps or hanging_nodes):  # cells that fit edge to edge may lie on each other
            edges = boundary_edges(cells)
            hanging = _hanging_problems(points, edges) if hanging_nodes else []
            problems += (overlap_problems(points, cells, edges) if overlaps else []) + hanging
    else:
        raise MeshValidityError(
            "mesh_problems checks triangles in 2D and tetrahedra in 3D; this mesh has triangles with 3D points"
        )
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    if not used.all():
        problems.append(f"{int(np.sum(~used))} vertices are not used by any cell")
    repeated = len(coincident_points(points))
    if repeated:
        problems.append(f"{repeated} duplicate vertices")
    if domain is not None:
        outside = cells_outside(domain, points, cells, on_boundary)
        if outside.any():
            problems.append(f"{int(outside.sum())} cells have their centroid outside the domain")
        if boundary_tolerance is not None:
            where = points[on_boundary]
            tolerance = boundary_tolerance(where) if callable(boundary_tolerance) else boundary_tolerance
            off = np.abs(domain.distance(where)) > tolerance
            if off.any():
                problems.append(f"{int(off.sum())} boundary vertices are off the domain boundary")
    return problems, lone


def cells_outside(domain, points, cells, on_boundary):
    """Mask of the cells whose centroid lies outside the domain, chords of a curved boundary excused.

    A boundary facet (edge, triangle) is flat while the boundary through its
    corners curves: against a boundary curving away from the domain (a
    void, the underside of a salt body) the facet cuts across the outside
    by its sag, and the centroid of a cell on it can follow (a sphere of
    1.25 edge lengths: cells of three corners on it and a fourth 0.44
    edge lengths inside have their centroid 0.03-0.05 edge lengths out).
    Such a cell is excused when its corners are one facet's on the
    boundary (``dim`` of them in ``on_boundary``) and one not outside, its centroid lies no farther out
    than the facet's own centroid, and the boundary's outward normals at
    the facet's corners agree (pairwise less than 90 degrees apart). A
    cell bridging a gap narrower than itself has corners on the gap's two
    walls, whose normals are opposite: it stays outside.

    Parameters
    ----------
    domain : Domain or callable
        Signed distance function (negative inside).
    points : numpy.ndarray, shape (n, dim)
    cells : numpy.ndarray, shape (m, dim + 1)
    on_boundary : numpy.ndarray of bool, shape (n,)
        The mesh's boundary vertices.

    Returns
    -------
    numpy.ndarray of bool, shape (m,)

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> water = tm.geometry.Rectangle((-3, -3), (3, 3)) - tm.geometry.Disk((0, 0), 1)
    >>> arc = np.array([[np.cos(0.5), np.sin(0.5)], [np.cos(0.5), -np.sin(0.5)], [1.1, 0.0]])
    >>> cells_outside(water, arc, np.array([[1, 2, 0]]), np.array([True, True, False]))
    array([False])
    """
    dim = points.shape[1]
    distance = domain.distance(cell_centroids(points, cells))
    outside = distance > 0
    candidates = np.flatnonzero(outside)
    corners_on = on_boundary[cells[candidates]]
    chord = np.flatnonzero(corners_on.sum(axis=1) == dim)
    if len(chord) == 0:
        return outside
    apex = cells[candidates[chord]][~corners_on[chord]]
    chord = chord[domain.distance(points[apex]) <= 0]
    candidates = candidates[chord]
    facets = cells[candidates][corners_on[chord]].reshape(-1, dim)  # the boundary corners, in cell order
    corners = points[facets]
    sag = domain.distance(corners.mean(axis=1))
    span = np.max(np.abs(corners - corners.mean(axis=1, keepdims=True)), axis=(1, 2))
    flat = corners.reshape(-1, dim)
    normal = distance_gradient(domain, flat, domain.distance(flat), np.repeat(1e-6 * span, dim)).reshape(-1, dim, dim)
    normal /= np.maximum(np.linalg.norm(normal, axis=2, keepdims=True), 1e-300)
    agree = np.ones(len(candidates), dtype=bool)
    for first in range(dim):
        for second in range(first + 1, dim):
            agree &= np.einsum("ij,ij->i", normal[:, first], normal[:, second]) > 0
    outside[candidates[agree & (distance[candidates] <= sag)]] = False
    return outside


FLAT = 1e-10
"""Area of a cell over the sum of its squared edges (its quality over 4 sqrt 3) at or below which it is flat.

A cell 1,000 times longer than wide has about 3e-4; three boundary vertices
a rounding off one line (an anisotropic mesh at 1,000:1) had 1e-18, a
positive area, and the mesh passed.
"""


def _triangle_problems(points, cells):
    """The rules of a 2D triangle mesh's cells and boundary: ``(problems, boundary vertex mask)``."""
    problems = []
    points = checked_points(points, 2)
    cells = checked_cells(cells, 3, len(points))  # the kernels read without bounds checks
    flat = flat_cells(points, cells, FLAT)
    if np.any(flat):
        problems.append(f"{int(np.sum(flat))} cells are clockwise or have zero area")
    duplicate, n_repeated_edges, degree = edge_census(cells, len(points))
    if duplicate.any():
        problems.append("duplicate cells")
    if n_repeated_edges:
        problems.append("some edges are shared by cells of the same orientation or by more than two cells")
    if np.any((degree != 0) & (degree != 2)):
        problems.append(
            f"{int(np.sum((degree != 0) & (degree != 2)))} boundary vertices do not have exactly two boundary edges"
        )
    return problems, degree > 0


OVERLAP_SHARE = 1e-6
_NEAR_BLOCK = 64  # crossing edges whose neighbourhoods are looked up at once
"""Share of the area near crossing boundary edges that may be covered twice (rounding at a pinch)."""


def overlap_problems(points, cells, edges=None):
    """Where counter-clockwise cells that fit edge to edge cover some ground twice, say so.

    The number of cells over a point is the winding number of the boundary
    loops around it. So the cells overlap exactly when two boundary edges
    cross (two parts of a merge laid across each other) or when, next to a
    loop, the loops wind around more than once (a part lying wholly inside
    another, or a fold within one part: a vertex dragged past its
    neighbour and the cells between them turned over leave a loop that runs
    counter-clockwise inside the mesh). Both are looked at with shapely;
    14 % of two stacked squares' area passed every other rule.

    The winding number changes only across boundary edges, so when no two
    cross, it is the same all along the left of a loop, and every region
    of the plane lies on one side of some loop: it is enough to know it at
    one point beside each loop. That point is the midpoint of one of the
    loop's edges (one that crosses nothing, where there is one): on the
    left of it the loop itself counts 1 if it runs counter-clockwise (the
    inside is on its left) and 0 if clockwise (a hole), and every other
    loop counts its sign if the midpoint lies inside it. (The centroid of
    the cell on the edge, used before, can lie beyond another loop: the
    thin dart a fold leaves was missed.) ``edges``: the cells'
    :func:`~terramesh.mesh.topology.boundary_edges`, if known.
    """
    import shapely

    edges = boundary_edges(cells) if edges is None else edges
    first, second = crossing_edges(points, edges)
    crossing = np.zeros(len(points), dtype=bool)  # the tails of crossing edges: one boundary edge leaves a vertex
    if len(first):
        overlap, near = _overlap_near(points, cells, edges[np.concatenate([first, second])])
        if overlap > OVERLAP_SHARE * near:
            pair = shapely.linestrings(points[edges[[first[0], second[0]]]])
            where = shapely.get_coordinates(shapely.intersection(pair[0], pair[1]))
            return [
                f"{len(first)} pairs of boundary edges cross: cells overlap by {overlap:.3g} "
                f"(near ({where[0, 0]:.6g}, {where[0, 1]:.6g}))"
            ]
        crossing[edges[np.concatenate([first, second]), 0]] = True
    loops, areas = loops_along(points, edges)
    if not loops:
        return []
    rings = np.array([shapely.Polygon(points[loop]) for loop in loops], dtype=object)
    # in each loop the first edge that crosses nothing (the first edge if every one does)
    order = np.concatenate(loops)
    starts = np.cumsum([0] + [len(loop) for loop in loops])
    free = np.flatnonzero(~crossing[order])
    at = np.searchsorted(free, starts[:-1])
    pick = np.where(at < len(free), free[np.minimum(at, len(free) - 1)], starts[:-1])
    pick = np.where(pick < starts[1:], pick, starts[:-1])
    following = np.where(pick + 1 < starts[1:], pick + 1, starts[:-1])
    middle = 0.5 * (points[order[pick]] + points[order[following]])
    probe, ring = shapely.STRtree(rings).query(shapely.points(middle), predicate="within")
    other = ring != probe
    winding = (areas > 0) + np.bincount(probe[other], weights=np.sign(areas[ring[other]]), minlength=len(loops))
    over = np.flatnonzero(winding > 1)
    if len(over):
        where = middle[over[0]]
        return [
            f"cells overlap: next to {len(over)} boundary loops the mesh lies over itself "
            f"(near ({where[0]:.6g}, {where[1]:.6g}))"
        ]
    return []


NEAR_SEAM = 1e-3
"""Share of their shortest boundary edge within which boundary vertices of two loops count as one spot."""


def near_seam_vertices(points, cells, share=NEAR_SEAM):
    """Boundary vertices with a vertex of another boundary loop nearer than ``share`` of their shortest boundary edge.

    Two meshes joined by hand along a seam whose nodes differ by rounding
    (one file written to the millimetre) are valid but do not connect: two
    parts with a wall between them. Their seam vertices lie far closer to
    each other than to anything else. Such a pair is reported when the
    distance is below ``share`` times the shorter of the two vertices'
    shortest boundary edges; only the nearest few boundary vertices of each
    are looked at (a KD-tree over the boundary vertices).

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3)
        A valid mesh: counter-clockwise cells, simple boundary loops.
    share : float, optional
        Scale-free threshold.

    Returns
    -------
    first, second : numpy.ndarray of int
        Vertex numbers, each pair once (``first < second``).
    distance : numpy.ndarray
        Their distance, units of ``points``.

    Examples
    --------
    Two unit squares side by side, the right one's seam 1e-6 off:

    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [1 + 1e-6, 0], [2, 0], [2, 1], [1 + 1e-6, 1]])
    >>> first, second, _ = near_seam_vertices(points, np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]))
    >>> first.tolist(), second.tolist()
    ([1, 2], [4, 7])
    """
    return near_seam_pairs(points, boundary_edges(cells), share)


def near_seam_pairs(points, edges, share=NEAR_SEAM):
    """:func:`near_seam_vertices` on the directed boundary ``edges`` (as :func:`boundary_edges` lists them)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    nothing = np.zeros(0, dtype=np.int64)
    if len(edges) == 0:
        return nothing, nothing, np.zeros(0)
    n = len(points)
    length = np.sqrt(np.sum((points[edges[:, 1]] - points[edges[:, 0]]) ** 2, axis=1))
    shortest = np.full(n, np.inf)
    shortest[edges[:, 0]] = length  # each boundary vertex has one edge out and one in
    shortest[edges[:, 1]] = np.minimum(shortest[edges[:, 1]], length)
    vertices = sorted_unique(edges)
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    loop = connected_components(graph, directed=False)[1]
    k = min(4, len(vertices))
    distance, nearest = cKDTree(points[vertices]).query(points[vertices], k=k)
    first = np.repeat(vertices, k - 1)
    second = vertices[nearest[:, 1:].ravel()]
    distance = distance[:, 1:].ravel()
    close = (loop[first] != loop[second]) & (distance < share * np.minimum(shortest[first], shortest[second]))
    pairs, index = np.unique(
        np.column_stack([np.minimum(first[close], second[close]), np.maximum(first[close], second[close])]),
        axis=0,
        return_index=True,
    )
    return pairs[:, 0], pairs[:, 1], distance[close][index]


def hanging_vertices(points, cells, share=NEAR_SEAM):
    """Hanging nodes: boundary vertices on the inside of another boundary edge, with a boundary edge back along it.

    Two blocks meshed apart and put side by side, with nodes that do not
    match along the line where they meet (T-junctions), pass every rule of
    cells and boundary: they are two parts with a wall of zero width
    between them. Their seam vertices lie on the other part's boundary
    edges, and the boundary edges there run back along each other. A
    vertex counts when it is within ``share`` of the edge's length of the
    edge, inside it by as much (nearer an end it is a near seam vertex,
    see :func:`near_seam_vertices`), and one of its own two boundary edges
    runs the other way along the same line (the sine of the angle between
    them below ``share``). Two parts that touch at a point (a strait that
    pinches to nothing, its banks crossing by rounding) leave each other
    at an angle and do not count. Each boundary edge looks only at the
    boundary vertices near it (a bucket grid of the edges).

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    cells : numpy.ndarray, shape (m, 3)
        Counter-clockwise cells, every boundary vertex on two boundary edges.
    share : float, optional
        Scale-free threshold.

    Returns
    -------
    vertex, edge : numpy.ndarray of int
        Each hanging vertex (ascending, once) and a boundary edge it lies on
        (a row of :func:`~terramesh.mesh.topology.boundary_edges`).

    Examples
    --------
    A square of two cells and, beside it, a rectangle whose corners lie on the square's side:

    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [1, 0.25], [2, 0.25], [2, 0.75], [1, 0.75]])
    >>> vertex, _ = hanging_vertices(points, np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]))
    >>> vertex.tolist()
    [4, 7]
    """
    vertex, host, _ = hanging_on_boundary(points, boundary_edges(cells), share)
    return vertex, host


def hanging_on_boundary(points, edges, share=NEAR_SEAM):
    """:func:`hanging_vertices` on given boundary ``edges``, with the edge of each vertex that runs back.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    edges : numpy.ndarray of int, shape (k, 2)
        The directed boundary edges (:func:`~terramesh.mesh.topology.boundary_edges`).
    share : float, optional
        Scale-free threshold.

    Returns
    -------
    vertex, host, back : numpy.ndarray of int
        Each hanging vertex (ascending, once), the row of ``edges`` it lies
        on, and the row of its own boundary edge that runs back along that one.

    Examples
    --------
    A slit: the boundary runs along y = 0 out to vertex 2 at x = 2, then
    back (row 3) to vertex 3 at x = 1.5, on the way out's edge 1 -> 2 (row 2).

    >>> import numpy as np
    >>> points = np.array([[0.0, 0], [1, 0], [2, 0], [1.5, 0], [1.5, -1], [0.5, 1]])
    >>> edges = np.array([[5, 0], [0, 1], [1, 2], [2, 3], [3, 4], [4, 5]])
    >>> [found.tolist() for found in hanging_on_boundary(points, edges)]
    [[3], [2], [3]]
    """
    nothing = np.zeros(0, dtype=np.int64)
    if len(edges) == 0:
        return nothing, nothing, nothing
    edge, vertex = vertices_on_other_edges(points, edges, share)
    start = points[edges[:, 0]]
    along = points[edges[:, 1]] - start
    length = np.sqrt(np.sum(along**2, axis=1))
    leaving = np.full(len(points), -1, dtype=np.int64)  # each boundary vertex's boundary edges, out and in
    arriving = np.full(len(points), -1, dtype=np.int64)
    leaving[edges[:, 0]] = np.arange(len(edges))
    arriving[edges[:, 1]] = np.arange(len(edges))
    back = np.full(len(edge), -1, dtype=np.int64)
    for own in (arriving[vertex], leaving[vertex]):
        first, second = along[edge], along[own]
        scale = length[edge] * length[own]
        runs_back = (own >= 0) & (np.einsum("ij,ij->i", first, second) < 0)  # -1: no such edge (an open chain)
        runs_back &= np.abs(first[:, 0] * second[:, 1] - first[:, 1] * second[:, 0]) <= share * scale
        back[runs_back] = own[runs_back]
    found = back >= 0
    vertex, index = np.unique(vertex[found], return_index=True)
    return vertex, edge[found][index], back[found][index]


def _hanging_problems(points, edges):
    """The hanging-node rule's phrase (:func:`hanging_vertices`) on the boundary ``edges``, or none."""
    vertex, _, _ = hanging_on_boundary(points, edges)
    if len(vertex) == 0:
        return []
    x, y = points[vertex[0]]
    return [
        f"{len(vertex)} hanging nodes: boundary vertices on another boundary edge, the first at ({x:.6g}, {y:.6g})"
        " (parts that meet along a line with nodes that do not match are not joined there: give them matching"
        " nodes along it)"
    ]


def _overlap_near(points, cells, crossing):
    """The area the cells near the ``crossing`` boundary edges cover twice, and the area they cover.

    Where a strait or neck pinches to nothing, two banks' boundary edges can
    cross by rounding (1e-6 of an edge, the guide's §5.3 coast): no ground
    is covered twice that matters. Laid across each other, two meshes'
    boundary edges cross at vertices as often as not: only the area tells.
    """
    import shapely
    from scipy.spatial import cKDTree

    ends = points[crossing]  # (k, 2, 2)
    reach = 2.0 * np.sqrt(np.sum((ends[:, 1] - ends[:, 0]) ** 2, axis=1))
    near, tree, centres = np.zeros(len(points), dtype=bool), cKDTree(points), ends.mean(axis=1)
    # in blocks: thousands of long crossing edges (a mesh laid over itself) each reach most points, and their
    # index lists all at once took over 6 GB
    for start in range(0, len(centres), _NEAR_BLOCK):
        found = tree.query_ball_point(centres[start : start + _NEAR_BLOCK], reach[start : start + _NEAR_BLOCK])
        near[np.concatenate([np.asarray(indices, dtype=np.int64) for indices in found])] = True
    local = cells[near[cells].any(axis=1)]
    triangles = shapely.polygons(points[local])
    covered = float(np.sum(shapely.area(triangles)))
    return covered - float(shapely.area(shapely.union_all(triangles))), covered


def vertices_on_other_edges(points, edges, share):
    """``(edge, vertex)``: each end of one of ``edges`` lying on another, within ``share`` of its length.

    On a bucket grid of the edges
    (:func:`~terramesh._kernels.segments.vertices_on_edges`: 2 ms for a
    coast's 7,000 boundary edges where KD-trees of the vertices and of the
    edges' midpoints by length took 7); where the grid would not serve,
    KD-trees answer. Either way the pairs come sorted by edge, then vertex.
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    edges = np.ascontiguousarray(edges, dtype=np.int64).reshape(-1, 2)
    # the kernel reads and writes without bounds checks: an index out of range is refused here, as NumPy would
    if edges.size and (edges.min() < 0 or edges.max() >= len(points)):
        raise IndexError(f"edges name vertices outside 0 .. {len(points) - 1} (of {len(points)} points)")
    edge, vertex, done = vertices_on_edges(points, edges, float(share))
    if not done:
        start = points[edges[:, 0]]
        along = points[edges[:, 1]] - start
        squared = np.sum(along**2, axis=1)  # as the kernel sums them: the same pairs at the thresholds
        vertices = sorted_unique(edges)
        edge, found = near_pairs(
            start + 0.5 * along, (0.5 + share) * np.sqrt(squared), points[vertices], np.zeros(len(vertices))
        )
        vertex = vertices[found]
        apart = (vertex != edges[edge, 0]) & (vertex != edges[edge, 1])
        edge, vertex = edge[apart], vertex[apart]
        offset = points[vertex] - start[edge]
        squared = np.maximum(squared[edge], np.finfo(np.float64).tiny)
        position = (offset[:, 0] * along[edge, 0] + offset[:, 1] * along[edge, 1]) / squared
        side = np.abs(along[edge, 0] * offset[:, 1] - along[edge, 1] * offset[:, 0]) / squared
        on = (position > share) & (position < 1 - share) & (side <= share)
        edge, vertex = edge[on], vertex[on]
    order = np.lexsort((vertex, edge))
    return edge[order], vertex[order]


def crossing_edges(points, edges, among=None):
    """The pairs of ``edges`` (2D segments, vertex index pairs) that cross or touch away from a shared vertex.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, 2)
    edges : numpy.ndarray, shape (e, 2)
    among : numpy.ndarray of int, optional
        Look only at the pairs with at least one of these edges.

    Returns
    -------
    first, second : numpy.ndarray of int
        Indices into ``edges``: each pair once with ``first < second`` when
        ``among`` is None; else ``first`` the edge of ``among`` (a pair of
        two of them comes twice, once from each). Ordered by ``first`` (in
        the order of ``among``).

    Notes
    -----
    Closed segments meet where they cross, where an end of one lies on the
    other, or where they overlap along a line, decided with exact
    orientation predicates (the answer of shapely's ``intersects``); the
    segments are bucketed on a grid of cells about their mean length.
    Where that grid would not serve (tiny edges crowding a few cells
    beside edges thousands of times longer, or coordinates beyond the
    floats' range), shapely's ``intersects`` on a tree of the segments
    answers.

    Raises
    ------
    IndexError
        For ``edges`` naming a vertex outside ``points``, or ``among`` an
        edge outside ``edges``.

    Examples
    --------
    >>> import numpy as np
    >>> points = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0], [2.0, 2.0]])
    >>> first, second = crossing_edges(points, np.array([[0, 1], [2, 3], [1, 4]]))
    >>> first.tolist(), second.tolist()
    ([0], [1])
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    edges = np.ascontiguousarray(edges, dtype=np.int64).reshape(-1, 2)
    queries = np.arange(len(edges)) if among is None else np.ascontiguousarray(among, dtype=np.int64).reshape(-1)
    # the kernel reads without bounds checks: an index out of range is refused here, as NumPy would
    if edges.size and (edges.min() < 0 or edges.max() >= len(points)):
        raise IndexError(f"edges name vertices outside 0 .. {len(points) - 1} (of {len(points)} points)")
    if queries.size and (queries.min() < -len(edges) or queries.max() >= len(edges)):
        raise IndexError(f"among names edges outside -{len(edges)} .. {len(edges) - 1}")
    # exact turns on a bucket grid: shapely's segments and tree took 0.15 s for a 587k-cell mesh's 50k boundary
    # edges, most of it making the segments; where the grid does not serve, shapely's tree does
    first, second, done = meeting_edges(points, edges, queries, among is None)
    if done:
        return first, second
    return _crossing_edges_by_tree(points, edges, queries, among is None)


def _crossing_edges_by_tree(points, edges, queries, each_pair_once):
    """:func:`crossing_edges` by shapely's ``intersects`` on a tree of segments (any coordinates, any lengths)."""
    import shapely

    segments = shapely.linestrings(points[edges])
    found, second = shapely.STRtree(segments).query(segments[queries], predicate="intersects")
    first = queries[found]
    apart = ~np.any(edges[first][:, :, None] == edges[second][:, None, :], axis=(1, 2))
    apart &= (first < second) if each_pair_once else (first != second)
    return first[apart], second[apart]


def cells_of_edges(cells, edges, missing=None):
    """The cell holding each directed edge ``edges[i, 0] -> edges[i, 1]``.

    Each must be in one, unless ``missing`` (an int) is given: then the
    value for an edge in none (the far side of a boundary edge).

    Examples
    --------
    >>> import numpy as np
    >>> cells = np.array([[0, 1, 2], [2, 1, 3]])
    >>> cells_of_edges(cells, np.array([[1, 3], [2, 0]])).tolist()
    [1, 0]
    >>> cells_of_edges(cells, np.array([[2, 1], [3, 1]]), missing=-1).tolist()
    [1, -1]
    """
    n = np.int64(max(cells.max(initial=0), edges.max(initial=0))) + 1
    # an edge's cell has its first vertex: only those cells are sorted (the whole mesh's 3 m keys took
    # 70 ms at 587k cells for the few boundary edges a generator asks about)
    first_vertex = np.zeros(n, dtype=bool)
    first_vertex[edges[:, 0]] = True
    candidates = np.flatnonzero(any_corner_in(first_vertex, cells))
    local = np.take(cells, candidates, axis=0)
    keys = (local * n + np.roll(local, -1, axis=1)).ravel()
    order = np.argsort(keys, kind="stable")
    wanted = edges[:, 0] * n + edges[:, 1]
    at = np.searchsorted(keys[order], wanted)
    if missing is None:
        return candidates[order[at] // cells.shape[1]]
    if len(keys) == 0:
        return np.full(len(edges), missing, dtype=np.int64)
    at = np.minimum(at, len(keys) - 1)
    return np.where(keys[order[at]] == wanted, candidates[order[at] // cells.shape[1]], missing)


def _tetrahedron_problems(points, cells):
    """The rules of a tetrahedral mesh's cells and boundary.

    Returns ``(problems, boundary vertex mask, (boundary faces (b, 3),
    vertices ascending, in lexicographic order, the cell of each),
    the boundary as facets of :func:`~terramesh._kernels.cleanup.facet_census`)``.
    """
    cells = checked_cells(cells, 4, len(points))
    points = checked_points(points, 3)
    problems = []
    volume = tetra_volumes(points, cells)
    if np.any(volume <= 0):
        problems.append(f"{int(np.sum(volume <= 0))} cells are inverted or have zero volume")
    lone, n_crowded, n_one_sided, repeated = facet_census(points, cells)
    if repeated:
        problems.append("duplicate cells")
    if n_crowded:
        problems.append(f"{n_crowded} faces are shared by more than two cells")
    if n_one_sided:
        problems.append(f"{n_one_sided} faces have both their cells on one side (overlapping cells)")
    lone = np.flatnonzero(lone)
    faces, owner, _ = census_facets(cells, lone)
    faces.sort(axis=1)
    order = np.lexsort(faces.T[::-1])
    faces, owner = faces[order], owner[order]
    surface, fans = boundary_surface_problems(faces, len(points))
    return problems + surface, fans > 0, (faces, owner), lone


def census_facets(cells, facets):
    """The ``facets`` of :func:`~terramesh._kernels.cleanup.facet_census` (its numbers ``k m + c``) as vertices.

    Returns ``(vertices (b, corners - 1), cell, corner)``: each facet's
    vertices in its cell's order without the corner (what ``np.delete``
    leaves), its cell, and the corner of the cell it leaves out.
    """
    corners = cells.shape[1]
    cell, corner = facets % len(cells), facets // len(cells)
    others = np.arange(corners - 1) + (np.arange(corners - 1) >= corner[:, None])
    return cells[cell[:, None], others], cell, corner


def boundary_surface_problems(faces, n_points):
    """What keeps the boundary faces (b, 3) of a tetrahedral mesh from a closed manifold surface.

    Returns ``(problems, fans)``: phrases (empty when every boundary edge
    is on exactly two boundary faces and the faces around each vertex form
    one fan), and the number of fans at each of the ``n_points`` vertices
    (0 off the boundary).
    """
    problems = []
    edges = sorted_cell_edges(faces)
    _, edge_counts = np.unique(edges[:, 0] * n_points + edges[:, 1], return_counts=True)
    if np.any(edge_counts != 2):
        problems.append(f"{int(np.sum(edge_counts != 2))} boundary edges are not on exactly two boundary faces")
    fans = link_components(np.ascontiguousarray(faces, dtype=np.int64), n_points)
    if np.any(fans > 1):
        problems.append(f"{int(np.sum(fans > 1))} boundary vertices where the boundary is not manifold")
    return problems, fans


OVERLAP_DEPTH = 1e-6
"""Share of a cell's longest edge by which cells of a mesh may pass into each other (rounding, not an overlap)."""

# how far from a boundary face towards its cell's far corner the point that tests the space inside it lies
_PROBE_STEP = 0.1


def _tetrahedron_overlap_problems(points, cells, faces, owner):
    """Where positive tetrahedra that fit face to face fill some space twice, say so.

    The number of cells around a point is the winding number of the
    boundary surface around it (the interior faces cancel in pairs), so the
    cells overlap exactly when two boundary sheets pass through each other
    (an edge of a boundary face through another boundary face) or when,
    inside a boundary sheet, the surface winds around more than once (a
    part lying wholly inside another). The second is seen at a point just
    inside each boundary face (``faces``, the face of cell ``owner``): it
    lies in another cell too. Each test looks only at the cells whose
    bounding sphere reaches it (:func:`near_pairs`).
    """
    corner = points[faces]  # (b, 3, 3)
    middle = corner.mean(axis=1)
    edges = unique_edges(faces)
    ends = points[edges]
    face_reach = np.sqrt(np.max(np.sum((corner - middle[:, None]) ** 2, axis=2), axis=1))
    half = 0.5 * np.sqrt(np.sum((ends[:, 1] - ends[:, 0]) ** 2, axis=1))
    edge, face = near_pairs(ends.mean(axis=1), half, middle, face_reach)
    apart = ~np.any(edges[edge][:, :, None] == faces[face][:, None, :], axis=(1, 2))
    edge, face = edge[apart], face[apart]
    through, where = _edges_through_faces(ends[edge], corner[face])
    if through.any():
        x, y, z = where[np.argmax(through)]
        return [
            f"{len(np.unique(edge[through]))} boundary edges pass through boundary faces: cells overlap "
            f"(near ({x:.6g}, {y:.6g}, {z:.6g}))"
        ]
    tets = points[cells]
    centre = tets.mean(axis=1)
    reach = np.sqrt(np.max(np.sum((tets - centre[:, None]) ** 2, axis=2), axis=1))
    far_corner = np.sum(cells[owner], axis=1) - np.sum(faces, axis=1)
    probes = middle + _PROBE_STEP * (points[far_corner] - middle)
    probe, cell = near_pairs(probes, np.zeros(len(probes)), centre, reach)
    other = cell != owner[probe]
    probe, cell = probe[other], cell[other]
    inside = probe[_strictly_inside(tets[cell], probes[probe])]
    if len(inside):
        x, y, z = probes[inside[0]]
        return [
            f"cells overlap: next to {len(np.unique(inside))} boundary faces the mesh lies in itself "
            f"(near ({x:.6g}, {y:.6g}, {z:.6g}))"
        ]
    return []


def _edges_through_faces(ends, corners):
    """Whether each segment ``ends`` (k, 2, 3) passes through triangle ``corners`` (k, 3, 3), and where.

    Through means from one side of the triangle's plane to the other, both
    ends farther from it than ``OVERLAP_DEPTH`` of the triangle's longest
    edge, at a point inside the triangle by ``OVERLAP_DEPTH`` (barycentric):
    two parts that touch, a boundary edge of one along a boundary face or
    across the rim of a face of the other, do not overlap.
    """
    p, q = ends[:, 0], ends[:, 1]
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    normal = np.cross(b - a, c - a)
    size = np.einsum("ij,ij->i", normal, normal)
    side_p = np.einsum("ij,ij->i", p - a, normal) / np.sqrt(size)
    side_q = np.einsum("ij,ij->i", q - a, normal) / np.sqrt(size)
    longest = np.sqrt(np.max(np.sum((corners - np.roll(corners, 1, axis=1)) ** 2, axis=2), axis=1))
    crosses = (side_p * side_q < 0) & (np.minimum(np.abs(side_p), np.abs(side_q)) > OVERLAP_DEPTH * longest)
    where = p + (side_p / np.where(crosses, side_p - side_q, 1.0))[:, None] * (q - p)
    weight_a = np.einsum("ij,ij->i", normal, np.cross(b - where, c - where)) / size
    weight_b = np.einsum("ij,ij->i", normal, np.cross(c - where, a - where)) / size
    inside = np.minimum(np.minimum(weight_a, weight_b), 1.0 - weight_a - weight_b) > OVERLAP_DEPTH
    return crosses & inside, where


def _strictly_inside(tets, at):
    """Whether each point ``at`` (k, 3) lies inside tetrahedron ``tets`` (k, 4, 3) by ``OVERLAP_DEPTH`` of it.

    All four barycentric coordinates above ``OVERLAP_DEPTH``; in chunks,
    since the pairs of a large mesh number millions.
    """
    inside = np.zeros(len(at), dtype=bool)
    step = 1 << 17
    for start in range(0, len(at), step):
        chunk = slice(start, start + step)
        origin = tets[chunk, 0]
        frame = np.transpose(tets[chunk, 1:] - origin[:, None], (0, 2, 1))
        weight = np.linalg.solve(frame, (at[chunk] - origin)[..., None])[..., 0]
        inside[chunk] = np.minimum(weight.min(axis=1), 1.0 - weight.sum(axis=1)) > OVERLAP_DEPTH
    return inside


def near_pairs(first, first_reach, second, second_reach):
    """The pairs of balls, one from each set, that meet: ``|first[i] - second[j]| <= reach_i + reach_j``.

    Each set is split by its radii into powers of two, with a KD-tree each,
    so that a few large cells do not make every small one search far.

    Parameters
    ----------
    first, second : numpy.ndarray, shape (a, dim) and (b, dim)
        Centres, any units.
    first_reach, second_reach : numpy.ndarray, shape (a,) and (b,)
        Radii (0 for points), units of the centres.

    Returns
    -------
    i, j : numpy.ndarray of int
        Indices into ``first`` and ``second``.

    Examples
    --------
    >>> import numpy as np
    >>> i, j = near_pairs(np.array([[0.0, 0], [5, 0]]), np.zeros(2), np.array([[1.0, 0], [8, 0]]), np.array([1.0, 3]))
    >>> i.tolist(), j.tolist()
    ([0, 1], [0, 1])
    """
    found_first, found_second = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=np.int64)]
    their_trees = _trees_by_radius(second, second_reach)
    for mine, my_tree in _trees_by_radius(first, first_reach):
        for theirs, their_tree in their_trees:
            reach = first_reach[mine].max() + second_reach[theirs].max()
            found = my_tree.sparse_distance_matrix(their_tree, reach, output_type="ndarray")
            i, j = mine[found["i"]], theirs[found["j"]]
            meet = found["v"] <= first_reach[i] + second_reach[j]
            found_first.append(i[meet])
            found_second.append(j[meet])
    return np.concatenate(found_first), np.concatenate(found_second)


def _trees_by_radius(centres, reach):
    """``(indices, KD-tree of their centres)`` for each power of two of ``reach``.

    Radii below 2**-40 of the largest (points among cells) share one tree.
    """
    from scipy.spatial import cKDTree

    if len(reach) == 0:
        return []
    level = np.floor(np.log2(np.maximum(reach, np.finfo(np.float64).tiny)))
    level = np.maximum(level, level.max() - 40)
    order = np.argsort(level, kind="stable")
    groups = np.split(order, np.flatnonzero(np.diff(level[order])) + 1)
    return [(group, cKDTree(centres[group])) for group in groups]


def check_mesh(mesh, domain=None, boundary_tolerance=None):
    """Raise :class:`MeshValidityError` listing the broken rules, if any.

    See :func:`mesh_problems` for the rules.

    Parameters
    ----------
    mesh : terramesh.Mesh
        A triangle mesh with 2D points (``points`` shape ``(n, 2)``,
        ``cells`` shape ``(m, 3)``) or a tetrahedral mesh (``(n, 3)`` and
        ``(m, 4)``), coordinates in any one unit.
    domain : Domain, optional
        The domain it should fill: every cell centroid must lie inside it
        (see :func:`cells_outside`).
    boundary_tolerance : float or callable, optional
        Largest allowed ``|distance|`` of a boundary vertex from the
        ``domain`` boundary, in the points' units: a number, or a function
        of the boundary vertices' coordinates ``(k, dim) -> (k,)``. Needs
        ``domain``.

    Raises
    ------
    MeshValidityError
        If the mesh breaks any rule (the message lists them, as
        :func:`mesh_problems` words them), or for the inputs
        :func:`mesh_problems` refuses (triangles with 3D points, a
        ``boundary_tolerance`` without a ``domain``).

    Notes
    -----
    ``check_mesh`` takes neither ``overlaps`` nor ``hanging_nodes``: it
    calls :func:`mesh_problems` with their defaults, so it always looks for
    overlapping cells and, in 2D, hanging nodes. A mesh that
    :func:`~terramesh.cleanup.fix_mesh` returns with only a warning of
    hanging nodes fails it; call :func:`mesh_problems` with
    ``hanging_nodes=False`` (or ``overlaps=False``) to leave those rules out.

    Examples
    --------
    A valid square of two cells passes silently:

    >>> import numpy as np, terramesh as tm
    >>> points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [1, 0.5], [2, 0.5], [2, 1.5], [1, 1.5]])
    >>> check_mesh(tm.Mesh(points[:4], [[0, 1, 2], [0, 2, 3]]))

    The square beside a rectangle whose corner lies halfway up its side
    has hanging nodes, which ``check_mesh`` cannot be told to pass:

    >>> touching = tm.Mesh(points, [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    >>> check_mesh(touching)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    terramesh.errors.MeshValidityError: invalid mesh: 2 hanging nodes: boundary vertices on another boundary edge, ...
    >>> mesh_problems(touching, hanging_nodes=False)
    []
    """
    problems = mesh_problems(mesh, domain, boundary_tolerance)
    if problems:
        raise MeshValidityError("invalid mesh: " + "; ".join(problems))
