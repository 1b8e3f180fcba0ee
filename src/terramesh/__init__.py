"""terramesh: unstructured triangle meshes for coastal-ocean and seismic models.

>>> import terramesh as tm
>>> mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2)
>>> mesh.dim
2
"""

from . import cleanup, coastal, geometry, parallel, plot, postprocess, quality, seismic, sizing
from ._kernels.precompile import compile_kernels
from .errors import TerrameshError, TerrameshWarning
from .generation import adapt_mesh, generate_anisotropic_mesh, generate_mesh
from .io import read_mesh, write_mesh
from .mesh import Mesh

__version__ = "0.1.0"

__all__ = [
    "Mesh",
    "generate_mesh",
    "generate_anisotropic_mesh",
    "adapt_mesh",
    "read_mesh",
    "write_mesh",
    "geometry",
    "sizing",
    "quality",
    "cleanup",
    "coastal",
    "postprocess",
    "parallel",
    "plot",
    "seismic",
    "compile_kernels",
    "TerrameshError",
    "TerrameshWarning",
    "__version__",
]
