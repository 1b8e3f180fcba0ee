"""Pictures of meshes, shorelines and size fields (matplotlib, imported only when called)."""

from .coastal import plot_shoreline
from .mesh import plot_mesh
from .sizes import plot_size_field

__all__ = ["plot_mesh", "plot_shoreline", "plot_size_field"]
