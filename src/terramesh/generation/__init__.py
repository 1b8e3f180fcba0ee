"""Mesh generation: DistMesh's force equilibrium, seeding and triangulation."""

from .adapt import adapt_mesh
from .anisotropic import generate_anisotropic_mesh
from .distmesh import generate_mesh
from .distmesh3d import generate_mesh_3d
from .seeding import seed_points
from .triangulate import delaunay

__all__ = ["adapt_mesh", "generate_anisotropic_mesh", "generate_mesh", "generate_mesh_3d", "seed_points", "delaunay"]
