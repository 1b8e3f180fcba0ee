"""Domains as signed distance functions: primitives, polygons and CSG.

Every domain has ``distance(points)`` (negative inside) and ``bbox``
(shape ``(2, dim)``); any callable with a bbox works as a domain too.
Shapes known only as rasters or volumes are a :class:`GridDomain`.
"""

from .base import Domain, FunctionDomain, as_bbox, as_domain
from .csg import Difference, Intersection, Union
from .grid import GridDomain
from .polygon import Polygon
from .primitives import Disk, Rectangle
from .primitives3d import Ball, Box, Cylinder
from .segments import SegmentIndex

__all__ = [
    "Domain",
    "FunctionDomain",
    "as_bbox",
    "as_domain",
    "Rectangle",
    "Disk",
    "Box",
    "Ball",
    "Cylinder",
    "Polygon",
    "GridDomain",
    "Union",
    "Intersection",
    "Difference",
    "SegmentIndex",
]
