"""Constructive solid geometry on signed distance functions.

Union, intersection and difference take the minimum or maximum of their
operands' distances (Persson & Strang 2004). The result is exact outside
the union and inside the intersection, and a bound elsewhere, which is all
the mesh generator needs: the sign everywhere and the value near the boundary.
"""

import numpy as np

from ..errors import GeometryError
from .base import Domain, as_domain

__all__ = ["Union", "Intersection", "Difference"]


class _Combination(Domain):
    def __init__(self, domains):
        domains = [as_domain(domain) for domain in domains]
        if len(domains) < 2:
            raise GeometryError(f"{type(self).__name__} needs at least two domains, got {len(domains)}")
        dims = {domain.dim for domain in domains}
        if len(dims) != 1:
            raise GeometryError(f"{type(self).__name__} of domains with different dimensions {sorted(dims)}")
        self.domains = domains
        self.bbox = self._combined_bbox(np.array([domain.bbox for domain in domains]))

    def corners(self):
        """Operands' corners that lie on this domain's boundary."""
        candidates = [domain.corners() for domain in self.domains]
        candidates = np.concatenate(candidates) if candidates else np.empty((0, self.dim))
        if len(candidates) == 0:
            return candidates
        scale = np.max(self.bbox[1] - self.bbox[0])
        return candidates[np.abs(self.distance(candidates)) < 1e-10 * scale]


class Union(_Combination):
    """Points inside any operand.

    Examples
    --------
    >>> from terramesh.geometry import Disk
    >>> both = Union([Disk((0, 0), 1), Disk((1.5, 0), 1)])
    >>> both.distance([(2.0, 0.0)]).tolist()
    [-0.5]
    """

    @staticmethod
    def _combined_bbox(boxes):
        return np.array([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])

    def _distance(self, points):
        return np.min([domain.distance(points) for domain in self.domains], axis=0)


class Intersection(_Combination):
    """Points inside every operand.

    Examples
    --------
    >>> from terramesh.geometry import Disk
    >>> lens = Intersection([Disk((0, 0), 1), Disk((1, 0), 1)])
    >>> lens.distance([(0.5, 0.0)]).tolist()
    [-0.5]
    """

    @staticmethod
    def _combined_bbox(boxes):
        box = np.array([boxes[:, 0].max(axis=0), boxes[:, 1].min(axis=0)])
        if np.any(box[1] <= box[0]):
            raise GeometryError("the intersection is empty: the operands' bounding boxes do not overlap")
        return box

    def _distance(self, points):
        return np.max([domain.distance(points) for domain in self.domains], axis=0)


class Difference(_Combination):
    """Points inside the first operand and outside all the others.

    Examples
    --------
    >>> from terramesh.geometry import Disk, Rectangle
    >>> plate = Difference([Rectangle((0, 0), (2, 1)), Disk((0.5, 0.5), 0.2)])
    >>> plate.distance([(0.5, 0.5), (1.5, 0.5)]).round(6).tolist()
    [0.2, -0.5]
    """

    @staticmethod
    def _combined_bbox(boxes):
        return boxes[0].copy()

    def _distance(self, points):
        distance = self.domains[0].distance(points)
        for domain in self.domains[1:]:
            distance = np.maximum(distance, -domain.distance(points))
        return distance
