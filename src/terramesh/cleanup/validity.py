"""Check the validity rules of a mesh (OceanMesh2D guide §2.2; tetrahedral meshes too)."""

import numpy as np

from .._kernels.cleanup import edge_census
from .._kernels.delaunay3d import _link_components
from ..errors import MeshValidityError
from ..mesh.topology import checked_cells, checked_points, coincident_points, signed_areas
from ..quality.tetra import tetra_volumes

__all__ = ["mesh_problems", "check_mesh"]


def mesh_problems(mesh, domain=None, boundary_tolerance=None):
    """List every validity rule the mesh breaks (an empty list means valid).

    The rules, for triangles in 2D (the OceanMesh2D guide's §2.2) and
    tetrahedra in 3D: cells of positive area or volume (counter-clockwise
    triangles); no unused or duplicate vertices; no duplicate cells; every
    edge (face, in 3D) in at most two cells and, where in two, with the
    cells on its two sides (conformity); a manifold boundary (in 2D every
    boundary vertex on exactly two boundary edges; in 3D every boundary
    edge on exactly two boundary faces and the boundary faces around each
    vertex one fan). With ``domain`` also: every cell centroid inside the
    domain and, with ``boundary_tolerance``, every boundary vertex within
    that distance of the domain boundary.

    Parameters
    ----------
    mesh : terramesh.Mesh
        A triangle mesh with 2D points or a tetrahedral mesh.
    domain : Domain, optional
        The domain it should fill.
    boundary_tolerance : float or callable, optional
        Largest allowed ``|distance|`` of a boundary vertex, a number or a
        function of the vertex coordinates.

    Returns
    -------
    list of str

    Raises
    ------
    MeshValidityError
        For triangles with 3D points (a surface: the rules are for meshes
        that fill a domain).

    Examples
    --------
    >>> import numpy as np, terramesh as tm
    >>> corner = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> mesh_problems(tm.Mesh(corner, [[0, 1, 2, 3]])), mesh_problems(tm.Mesh(corner, [[0, 2, 1, 3]]))
    ([], ['1 cells are inverted or have zero volume'])
    """
    points, cells = mesh.points, mesh.cells
    if len(cells) == 0:
        return ["the mesh has no cells"]
    if cells.shape[1] == 4:
        problems, on_boundary = _tetrahedron_problems(points, cells)
    elif points.shape[1] == 2:
        problems, on_boundary = _triangle_problems(points, cells)
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
        centroids = points[cells].mean(axis=1)
        outside = domain.distance(centroids) > 0
        if outside.any():
            problems.append(f"{int(outside.sum())} cells have their centroid outside the domain")
        if boundary_tolerance is not None:
            where = points[on_boundary]
            tolerance = boundary_tolerance(where) if callable(boundary_tolerance) else boundary_tolerance
            off = np.abs(domain.distance(where)) > tolerance
            if off.any():
                problems.append(f"{int(off.sum())} boundary vertices are off the domain boundary")
    return problems


def _triangle_problems(points, cells):
    """The rules of a 2D triangle mesh's cells and boundary: ``(problems, boundary vertex mask)``."""
    problems = []
    area = signed_areas(points, cells)
    if np.any(area <= 0):
        problems.append(f"{int(np.sum(area <= 0))} cells are clockwise or have zero area")
    duplicate, n_repeated_edges, degree = edge_census(np.ascontiguousarray(cells, dtype=np.int64), len(points))
    if duplicate.any():
        problems.append("duplicate cells")
    if n_repeated_edges:
        problems.append("some edges are shared by cells of the same orientation or by more than two cells")
    if np.any((degree != 0) & (degree != 2)):
        problems.append(
            f"{int(np.sum((degree != 0) & (degree != 2)))} boundary vertices do not have exactly two boundary edges"
        )
    return problems, degree > 0


def _tetrahedron_problems(points, cells):
    """The rules of a tetrahedral mesh's cells and boundary: ``(problems, boundary vertex mask)``."""
    cells = checked_cells(cells, 4, len(points))
    points = checked_points(points, 3)
    problems = []
    volume = tetra_volumes(points, cells)
    if np.any(volume <= 0):
        problems.append(f"{int(np.sum(volume <= 0))} cells are inverted or have zero volume")
    if len(np.unique(np.sort(cells, axis=1), axis=0)) < len(cells):
        problems.append("duplicate cells")
    # the face opposite corner k of every cell, its vertices ascending, and that corner (the apex)
    faces = np.sort(np.concatenate([np.delete(cells, k, axis=1) for k in range(4)]), axis=1)
    apex = cells.T.ravel()
    order = np.lexsort(faces.T[::-1])
    faces, apex = faces[order], apex[order]
    first = np.ones(len(faces), dtype=bool)
    first[1:] = np.any(faces[1:] != faces[:-1], axis=1)
    starts = np.flatnonzero(first)
    counts = np.diff(np.append(starts, len(faces)))
    if np.any(counts > 2):
        problems.append(f"{int(np.sum(counts > 2))} faces are shared by more than two cells")
    shared = starts[counts == 2]
    a, b, c = (points[faces[shared, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    sides = np.einsum("ij,ij->i", points[apex[shared]] - a, normal) * np.einsum(
        "ij,ij->i", points[apex[shared + 1]] - a, normal
    )
    if np.any(sides >= 0):
        problems.append(f"{int(np.sum(sides >= 0))} faces have both their cells on one side (overlapping cells)")
    surface, fans = boundary_surface_problems(faces[starts[counts == 1]], len(points))
    return problems + surface, fans > 0


def boundary_surface_problems(faces, n_points):
    """What keeps the boundary faces (b, 3) of a tetrahedral mesh from a closed manifold surface.

    Returns ``(problems, fans)``: phrases (empty when every boundary edge
    is on exactly two boundary faces and the faces around each vertex form
    one fan), and the number of fans at each of the ``n_points`` vertices
    (0 off the boundary).
    """
    problems = []
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [0, 2]]]), axis=1)
    _, edge_counts = np.unique(edges[:, 0] * n_points + edges[:, 1], return_counts=True)
    if np.any(edge_counts != 2):
        problems.append(f"{int(np.sum(edge_counts != 2))} boundary edges are not on exactly two boundary faces")
    fans = _link_components(np.ascontiguousarray(faces, dtype=np.int64), n_points)
    if np.any(fans > 1):
        problems.append(f"{int(np.sum(fans > 1))} boundary vertices where the boundary is not manifold")
    return problems, fans


def check_mesh(mesh, domain=None, boundary_tolerance=None):
    """Raise :class:`MeshValidityError` listing the broken rules, if any.

    See :func:`mesh_problems` for the rules and parameters.
    """
    problems = mesh_problems(mesh, domain, boundary_tolerance)
    if problems:
        raise MeshValidityError("invalid mesh: " + "; ".join(problems))
