"""Validity checks and repairs of meshes (OceanMesh2D guide §2.2 and §4.3).

:func:`fix_mesh` makes a mesh valid; :func:`clean` also removes poor boundary
cells and low-valence vertices and smooths; :func:`mesh_problems` lists the
rules a mesh breaks. The steps are plain functions on ``(points, cells)``
arrays that can be used on their own.
"""

from .clean import clean, low_valence_points, smooth_points
from .disjoint import cell_components, delete_disjoint_parts
from .fix_mesh import (
    RepairReport,
    delete_interior_cells,
    fix_mesh,
    merge_duplicate_points,
    orient_cells,
    remove_degenerate_cells,
    remove_duplicate_cells,
    remove_overlapping_cells,
    remove_unused_points,
)
from .validity import check_mesh, mesh_problems

__all__ = [
    "fix_mesh",
    "clean",
    "RepairReport",
    "merge_duplicate_points",
    "remove_unused_points",
    "remove_duplicate_cells",
    "orient_cells",
    "remove_degenerate_cells",
    "remove_overlapping_cells",
    "cell_components",
    "delete_disjoint_parts",
    "delete_interior_cells",
    "low_valence_points",
    "smooth_points",
    "check_mesh",
    "mesh_problems",
]
