"""Mesh generation: DistMesh's force equilibrium, seeding and triangulation."""

from .distmesh import generate_mesh
from .seeding import seed_points
from .triangulate import delaunay

__all__ = ["generate_mesh", "seed_points", "delaunay"]
