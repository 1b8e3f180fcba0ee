"""The mesh container, its boundary node strings, its nodal attributes and its connectivity."""

from . import boundaries, nodal_attributes, topology
from .boundaries import Boundaries, LandBoundary, OpenBoundary
from .mesh import Mesh
from .nodal_attributes import NodalAttribute, NodalAttributes

__all__ = [
    "Mesh",
    "Boundaries",
    "OpenBoundary",
    "LandBoundary",
    "NodalAttribute",
    "NodalAttributes",
    "boundaries",
    "nodal_attributes",
    "topology",
]
