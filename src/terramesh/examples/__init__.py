"""Bundled example data and the demo mesh."""

from .danish_straits import danish_straits_land, danish_straits_mesh

__all__ = ["danish_straits_land", "danish_straits_mesh"]
