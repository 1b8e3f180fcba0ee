"""Element quality: the radius-ratio-like measure of the OceanMesh2D guide, eq. (1)."""

from .summary import QualitySummary, summary
from .triangle import edge_length_ratio, triangle_quality

__all__ = ["triangle_quality", "edge_length_ratio", "summary", "QualitySummary"]
