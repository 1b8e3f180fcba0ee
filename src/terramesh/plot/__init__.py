"""Pictures of meshes (matplotlib, imported only when called)."""

from .mesh import plot_mesh

__all__ = ["plot_mesh"]
