"""The mesh container, its boundary node strings and its connectivity."""

from . import boundaries, topology
from .boundaries import Boundaries, LandBoundary, OpenBoundary
from .mesh import Mesh

__all__ = ["Mesh", "Boundaries", "OpenBoundary", "LandBoundary", "boundaries", "topology"]
