"""The guide's edge-length (size) functions on a :class:`~terramesh.coastal.GeoGrid`.

Each function takes arrays sampled on the grid, ``(nx, ny)`` indexed
``[ix, iy]``, and returns sizes in ground metres, ``inf`` where it does not
constrain the mesh. The final size function is the minimum of those in use
(§3), bounded (:func:`bound_sizes`), graded
(:func:`terramesh.sizing.limit_gradient`, eq. 9) and CFL-limited
(:func:`cfl_floor` graded upward, eq. 10-12).

========================  ==========================  =====================
guide                     function                    equation
========================  ==========================  =====================
``dis`` (§3.1)            :func:`distance_size`       2
``fs`` (§3.1)             :func:`feature_size`        3-4
``dis`` xor ``fs``        :func:`shoreline_size`      2 or 3-4
``wl`` (§3.2)             :func:`wavelength_size`     5-6
``slp``, ``fl`` (§3.3)    :func:`slope_size`          7-8
``ch`` (§3.4)             :func:`channel_size`        --
``dt`` (§4.2)             :func:`cfl_floor`           10-11, 12 (``dt=0``)
``max_el``, ``max_el_ns`` :func:`bound_sizes`         --
========================  ==========================  =====================
"""

from .bounds import NEARSHORE_WIDTH, bound_sizes, nearshore_mask
from .cfl import COURANT, ETA, cfl_floor, cfl_limit, cfl_timestep, courant_number, wave_speed
from .channels import ANGLE_OF_REPOSE, channel_size, find_channels, read_thalwegs
from .distance import (
    MEDIAL_AXIS_GRADIENT,
    approximate_medial_axis,
    distance_size,
    distance_to_coastline,
    feature_size,
    polygon_mask,
    shoreline_size,
    water_mask,
)
from .slope import (
    LEAST_OVERLAND_DEPTH,
    SLOPE_CUTOFF_DEPTH,
    auto_filter_length,
    filter_bathymetry,
    gaussian_lowpass,
    slope_size,
)
from .wavelength import GRAVITY, M2_PERIOD, m2_wavelength, wavelength_size

__all__ = [
    "ANGLE_OF_REPOSE",
    "LEAST_OVERLAND_DEPTH",
    "COURANT",
    "ETA",
    "GRAVITY",
    "M2_PERIOD",
    "MEDIAL_AXIS_GRADIENT",
    "NEARSHORE_WIDTH",
    "SLOPE_CUTOFF_DEPTH",
    "approximate_medial_axis",
    "auto_filter_length",
    "bound_sizes",
    "cfl_floor",
    "cfl_limit",
    "cfl_timestep",
    "channel_size",
    "courant_number",
    "distance_size",
    "distance_to_coastline",
    "feature_size",
    "filter_bathymetry",
    "find_channels",
    "gaussian_lowpass",
    "m2_wavelength",
    "nearshore_mask",
    "polygon_mask",
    "read_thalwegs",
    "shoreline_size",
    "slope_size",
    "water_mask",
    "wave_speed",
    "wavelength_size",
]
