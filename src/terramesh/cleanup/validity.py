"""Check the validity rules of a mesh (OceanMesh2D guide §2.2)."""

import numpy as np

from .._kernels.cleanup import edge_census
from ..errors import MeshValidityError
from ..mesh.topology import boundary_edges, coincident_points, signed_areas

__all__ = ["mesh_problems", "check_mesh"]


def mesh_problems(mesh, domain=None, boundary_tolerance=None):
    """List every validity rule the mesh breaks (an empty list means valid).

    The rules: counter-clockwise cells with positive area; no unused or
    duplicate vertices; no duplicate cells; every edge in at most two cells
    and, where in two, traversed in opposite directions (conformity); every
    boundary vertex on exactly two boundary edges. With ``domain`` also:
    every cell centroid inside the domain and, with ``boundary_tolerance``,
    every boundary vertex within that distance of the domain boundary.

    Parameters
    ----------
    mesh : terramesh.Mesh
        A triangle mesh.
    domain : Domain, optional
        The domain it should fill.
    boundary_tolerance : float or callable, optional
        Largest allowed ``|distance|`` of a boundary vertex, a number or a
        function of the vertex coordinates.

    Returns
    -------
    list of str
    """
    points, cells = mesh.points, mesh.cells
    problems = []
    if len(cells) == 0:
        return ["the mesh has no cells"]
    area = signed_areas(points, cells)
    if np.any(area <= 0):
        problems.append(f"{int(np.sum(area <= 0))} cells are clockwise or have zero area")
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    if not used.all():
        problems.append(f"{int(np.sum(~used))} vertices are not used by any cell")
    repeated = len(coincident_points(points))
    if repeated:
        problems.append(f"{repeated} duplicate vertices")
    if cells.shape[1] == 3:
        duplicate, n_repeated_edges, degree = edge_census(np.ascontiguousarray(cells, dtype=np.int64), len(points))
        if duplicate.any():
            problems.append("duplicate cells")
        if n_repeated_edges:
            problems.append("some edges are shared by cells of the same orientation or by more than two cells")
    else:
        degree = np.bincount(boundary_edges(cells).ravel(), minlength=len(points))
    if np.any((degree != 0) & (degree != 2)):
        problems.append(
            f"{int(np.sum((degree != 0) & (degree != 2)))} boundary vertices do not have exactly two boundary edges"
        )
    if domain is not None:
        centroids = points[cells].mean(axis=1)
        outside = domain.distance(centroids) > 0
        if outside.any():
            problems.append(f"{int(outside.sum())} cells have their centroid outside the domain")
        if boundary_tolerance is not None:
            on_boundary = degree > 0
            where = points[on_boundary]
            tolerance = boundary_tolerance(where) if callable(boundary_tolerance) else boundary_tolerance
            off = np.abs(domain.distance(where)) > tolerance
            if off.any():
                problems.append(f"{int(off.sum())} boundary vertices are off the domain boundary")
    return problems


def check_mesh(mesh, domain=None, boundary_tolerance=None):
    """Raise :class:`MeshValidityError` listing the broken rules, if any.

    See :func:`mesh_problems` for the rules and parameters.
    """
    problems = mesh_problems(mesh, domain, boundary_tolerance)
    if problems:
        raise MeshValidityError("invalid mesh: " + "; ".join(problems))
