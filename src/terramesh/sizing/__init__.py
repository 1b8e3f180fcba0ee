"""Mesh size functions: what edge length the mesh should have where."""

from .edge_length import as_size_function
from .gradation import limit_gradient
from .grid import SizeGrid

__all__ = ["SizeGrid", "as_size_function", "limit_gradient"]
