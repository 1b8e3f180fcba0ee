"""Element quality: triangles by the OceanMesh2D guide's eq. (1), tetrahedra by dihedral angles and radius ratio."""

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
]
