"""Coastal-ocean meshes: shorelines, DEMs and the OceanMesh2D size functions, in WGS84 degrees."""

from . import sizes
from .build import ALIASES, CoastalSizes, build, size_function
from .dem import DEM, read_dem
from .grid import GeoGrid, as_lonlat_box
from .projection import from_mercator, metres_per_degree, scale_factor, to_mercator
from .shoreline import Shoreline, read_shoreline

__all__ = [
    "build",
    "size_function",
    "CoastalSizes",
    "ALIASES",
    "sizes",
    "DEM",
    "read_dem",
    "Shoreline",
    "read_shoreline",
    "GeoGrid",
    "as_lonlat_box",
    "to_mercator",
    "from_mercator",
    "scale_factor",
    "metres_per_degree",
]
