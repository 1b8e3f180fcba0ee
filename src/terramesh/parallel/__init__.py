"""Meshing a domain in parts side by side (MPI ranks or one after the other) and merging them."""

from .decompose import separator_points, strip_cuts
from .mesh_in_parts import generate_mesh_parallel
from .mesh_in_slabs import section_points, slab_cuts

__all__ = ["generate_mesh_parallel", "strip_cuts", "separator_points", "slab_cuts", "section_points"]
