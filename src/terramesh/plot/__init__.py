"""Pictures of meshes, their quality, boundaries, shorelines and size fields (matplotlib, imported only when called)."""

from .boundaries import plot_boundaries
from .coastal import plot_shoreline
from .mesh import plot_mesh
from .quality import plot_quality
from .sizes import plot_size_field

__all__ = ["plot_mesh", "plot_boundaries", "plot_quality", "plot_shoreline", "plot_size_field"]
