"""The mesh container and its connectivity."""

from . import topology
from .mesh import Mesh

__all__ = ["Mesh", "topology"]
