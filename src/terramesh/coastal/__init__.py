"""Coastal-ocean meshes: shorelines, DEMs and the OceanMesh2D size functions, in WGS84 degrees."""

from .grid import GeoGrid, as_lonlat_box
from .projection import from_mercator, metres_per_degree, scale_factor, to_mercator

__all__ = ["GeoGrid", "as_lonlat_box", "to_mercator", "from_mercator", "scale_factor", "metres_per_degree"]
