"""Meshing a domain in parts side by side (MPI ranks or one after the other) and merging them."""

from .decompose import separator_points, strip_cuts
from .mesh_in_parts import generate_mesh_parallel

__all__ = ["generate_mesh_parallel", "strip_cuts", "separator_points"]
