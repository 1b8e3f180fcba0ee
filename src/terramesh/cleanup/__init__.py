"""Validity checks and repairs of generated meshes."""

from .fix_mesh import orient_cells, remove_degenerate_cells, remove_unused_points, repair_boundary
from .validity import check_mesh, mesh_problems

__all__ = [
    "orient_cells",
    "remove_unused_points",
    "remove_degenerate_cells",
    "repair_boundary",
    "check_mesh",
    "mesh_problems",
]
