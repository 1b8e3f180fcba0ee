"""Pictures of meshes, their quality, shorelines and size fields (matplotlib, imported only when called)."""

from .coastal import plot_shoreline
from .mesh import plot_mesh
from .quality import plot_quality
from .sizes import plot_size_field

__all__ = ["plot_mesh", "plot_quality", "plot_shoreline", "plot_size_field"]
