"""Mesh size functions: what edge length the mesh should have where."""

from .edge_length import as_size_function
from .gradation import DEFAULT_GRADE, lift_to_floor, limit_gradient, limit_gradient_up
from .grid import SizeGrid
from .metric import MetricGrid, as_metric_function, metric_sizes, metric_tensor

__all__ = [
    "DEFAULT_GRADE",
    "SizeGrid",
    "as_size_function",
    "limit_gradient",
    "limit_gradient_up",
    "lift_to_floor",
    "metric_tensor",
    "metric_sizes",
    "as_metric_function",
    "MetricGrid",
]
