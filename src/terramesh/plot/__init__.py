"""Pictures of meshes, shorelines and size fields (matplotlib, imported only when called)."""

from .coastal import plot_shoreline
from .mesh import plot_mesh

__all__ = ["plot_mesh", "plot_shoreline"]
