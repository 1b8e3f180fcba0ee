"""Seismic meshes for full-waveform inversion: velocity models, wavelength/CFL sizing, padding.

Coordinates are ``(x, z)`` in 2-D and ``(x, y, z)`` in 3-D, metres, with
``z`` negative downward and the free surface on top (see
:mod:`terramesh.seismic.model`); velocities are m/s.

The modules: :mod:`~terramesh.seismic.model` (the velocity model and its
frame), :mod:`~terramesh.seismic.velocity` (:func:`read_velocity`, with the
NetCDF, ``.npy`` and array readers), :mod:`~terramesh.seismic.segy` and
:mod:`~terramesh.seismic.binary` (the SEG-Y and raw binary readers),
:mod:`~terramesh.seismic.sizing` (mesh sizes) and
:mod:`~terramesh.seismic.anisotropic` (cells that follow the layers).

>>> import numpy as np
>>> from terramesh import seismic
>>> model = seismic.read_velocity(np.full((5, 9), 2000.0), spacing=50.0, axis_order="zx")
>>> size = seismic.size_function(model, frequency=4, hmin=40, grade=0.2, pad=100)
>>> size.bbox.tolist()
[[-100.0, -300.0], [500.0, 0.0]]
"""

from .anisotropic import layer_metric
from .model import UNITS, VelocityModel
from .segy import read_segy_header
from .sizing import (
    ALIASES,
    CELLS_PER_WAVELENGTH,
    CELLS_PER_WAVELENGTH_3D,
    COURANT,
    EDGE_SHRINK,
    EDGE_SHRINK_3D,
    EDGE_SHRINK_SEISMIC,
    PAD_STYLES,
    ModelBox,
    SeismicSize,
    cfl_size,
    gradient_size,
    pad_model,
    size_function,
    stable_timestep,
    wavelength_size,
)
from .velocity import read_velocity

__all__ = [
    "layer_metric",
    "VelocityModel",
    "read_velocity",
    "read_segy_header",
    "UNITS",
    "SeismicSize",
    "ModelBox",
    "size_function",
    "wavelength_size",
    "gradient_size",
    "cfl_size",
    "stable_timestep",
    "pad_model",
    "CELLS_PER_WAVELENGTH",
    "CELLS_PER_WAVELENGTH_3D",
    "COURANT",
    "EDGE_SHRINK",
    "EDGE_SHRINK_3D",
    "EDGE_SHRINK_SEISMIC",
    "PAD_STYLES",
    "ALIASES",
]
