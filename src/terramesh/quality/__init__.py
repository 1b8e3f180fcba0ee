"""Element quality: triangles by the guide's eq. (1), also in a metric; tetrahedra by dihedral angle, radius ratio.

Every measure refuses points with a NaN or infinite coordinate
(MeshValidityError, as :class:`~terramesh.Mesh` does) rather than score
their cells: a quality of 0 called such a cell flat, NaN spoiled every mean.
"""

from .metric import metric_edge_lengths, metric_quality
from .summary import QualitySummary, summary
from .tetra import TetraQualitySummary, dihedral_angles, min_max_dihedral, radius_ratio, tetra_summary, tetra_volumes
from .triangle import edge_length_ratio, triangle_quality

__all__ = [
    "triangle_quality",
    "edge_length_ratio",
    "summary",
    "QualitySummary",
    "tetra_summary",
    "TetraQualitySummary",
    "dihedral_angles",
    "min_max_dihedral",
    "radius_ratio",
    "tetra_volumes",
    "metric_quality",
    "metric_edge_lengths",
]
