"""Mesh size functions: what edge length the mesh should have where."""

from .edge_length import as_size_function
from .gradation import DEFAULT_GRADE, limit_gradient
from .grid import SizeGrid

__all__ = ["DEFAULT_GRADE", "SizeGrid", "as_size_function", "limit_gradient"]
