"""Coastal-ocean meshes: shorelines, DEMs and the OceanMesh2D size functions, in WGS84 degrees."""

from ..cleanup.fix_mesh import fix_mesh
from ..io.fort13 import write_fort13
from ..io.fort15 import check_fort15_options, write_fort15
from ..postprocess.renumber import renumber
from . import sizes, tides
from .bathymetry import interpolate_bathymetry
from .boundaries import cut_region, make_boundaries, node_string_problems
from .build import ALIASES, CoastalSizes, build, size_function
from .dem import DEM, read_dem
from .grid import GeoGrid, as_lonlat_box
from .merge import merge
from .multiscale import CompositeSize, build_multiscale
from .nodal_attributes import internal_tide_friction, tau0
from .projection import from_mercator, metres_per_degree, scale_factor, to_mercator
from .shoreline import Shoreline, read_shoreline
from .timestep import courant_number, enforce_timestep

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
    "fix_mesh",
    "make_boundaries",
    "cut_region",
    "node_string_problems",
    "interpolate_bathymetry",
    "courant_number",
    "enforce_timestep",
    "renumber",
    "tau0",
    "internal_tide_friction",
    "write_fort13",
    "write_fort15",
    "check_fort15_options",
    "merge",
    "build_multiscale",
    "CompositeSize",
    "tides",
]
