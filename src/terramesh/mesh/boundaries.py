"""A mesh's boundary node strings: open (elevation) and land (flux) boundaries, as ADCIRC and SCHISM number them.

These are the mesh's own data (``Mesh.boundaries``), made by
:func:`~terramesh.coastal.make_boundaries`, kept through repairs and
renumbering, and written by the fort.14 and gr3 writers; so they live with
the mesh, not with a file format.
"""

from dataclasses import dataclass, field

import numpy as np

from ..errors import MeshFormatError

__all__ = [
    "OpenBoundary",
    "LandBoundary",
    "Boundaries",
    "has_boundaries",
    "check_boundary_nodes",
    "PAIRED_TYPES",
    "ISLAND_TYPES",
]

PAIRED_TYPES = frozenset({4, 24, 64, 5, 25})
"""IBTYPEs of barriers with a back face: each node comes with its paired node (IBCONN)."""

ISLAND_TYPES = frozenset({1, 11, 21})
"""IBTYPEs of closed land boundaries (islands)."""


@dataclass(eq=False)
class OpenBoundary:
    """An open (elevation-specified) boundary: 0-based node indices in order.

    ``ibtype`` is the optional IBTYPEE flag of the NVDLL line (None when absent).
    """

    nodes: np.ndarray
    ibtype: int | None = None


@dataclass(eq=False)
class LandBoundary:
    """A flux-specified (land, island, barrier) boundary.

    Attributes
    ----------
    nodes : numpy.ndarray, shape (k,)
        0-based node indices in traversal order.
    ibtype : int
        ADCIRC IBTYPE (e.g. 20 mainland, 21 island, 24 weir pair).
    paired_nodes : numpy.ndarray, shape (k,), optional
        Back-face node of each node for IBTYPE 4, 24, 64, 5, 25 (0-based).
    values : numpy.ndarray, shape (k, c), optional
        The per-node real columns in file order: barrier height and
        coefficients, pipe height, coefficient and diameter.
    """

    nodes: np.ndarray
    ibtype: int
    paired_nodes: np.ndarray | None = None
    values: np.ndarray | None = None


@dataclass(eq=False)
class Boundaries:
    """Open and land boundaries of an ADCIRC grid."""

    open: list = field(default_factory=list)
    land: list = field(default_factory=list)

    def renumbered(self, new_index):
        """Copy with every node index ``i`` replaced by ``new_index[i]``."""
        return Boundaries(
            open=[OpenBoundary(new_index[b.nodes], b.ibtype) for b in self.open],
            land=[
                LandBoundary(
                    new_index[b.nodes],
                    b.ibtype,
                    None if b.paired_nodes is None else new_index[b.paired_nodes],
                    None if b.values is None else b.values.copy(),
                )
                for b in self.land
            ],
        )


def has_boundaries(boundaries):
    """Whether ``boundaries`` (a :class:`Boundaries` or None) holds any open or land boundary.

    Examples
    --------
    >>> has_boundaries(None), has_boundaries(Boundaries()), has_boundaries(Boundaries(open=[OpenBoundary([0, 1])]))
    (False, False, True)
    """
    return boundaries is not None and bool(boundaries.open or boundaries.land)


def check_boundary_nodes(boundaries, n_points):
    """Raise a MeshFormatError when a boundary refers to a node outside ``0 .. n_points - 1`` or not a whole number.

    Examples
    --------
    >>> check_boundary_nodes(Boundaries(open=[OpenBoundary([0, 1])]), 2)
    >>> check_boundary_nodes(Boundaries(open=[OpenBoundary([0, 5])]), 2)
    Traceback (most recent call last):
    ...
    terramesh.errors.MeshFormatError: an open boundary refers to node 5 (0-based) of a mesh with 2 nodes (indices 0..1)
    """
    strings = [("an open boundary", b.nodes) for b in boundaries.open]
    strings += [("a land boundary", b.nodes) for b in boundaries.land]
    strings += [("a barrier pair", b.paired_nodes) for b in boundaries.land if b.paired_nodes is not None]
    for what, nodes in strings:
        nodes = np.asarray(nodes).ravel()
        if nodes.dtype.kind not in "iu":
            # written as integers, 1.9 would become node 1 without a word
            fractional = nodes[~((nodes == np.round(nodes)) if nodes.dtype.kind == "f" else np.zeros(len(nodes), bool))]
            if len(fractional):
                raise MeshFormatError(
                    f"{what} refers to node {fractional[0].item()!r}: node indices must be whole numbers"
                )
        outside = nodes[~((nodes >= 0) & (nodes < n_points))]
        if len(outside):
            raise MeshFormatError(
                f"{what} refers to node {outside[0]} (0-based) of a mesh with {n_points} nodes "
                f"(indices 0..{n_points - 1})"
            )
