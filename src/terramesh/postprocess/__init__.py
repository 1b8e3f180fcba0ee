"""Post-processing of finished meshes (the OceanMesh2D guide's §6 ``msh`` methods)."""

from .renumber import bandwidth, rcm_permutation, renumber

__all__ = ["renumber", "bandwidth", "rcm_permutation"]
