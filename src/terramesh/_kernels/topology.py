"""Connectivity kernels on triangulations stored with a neighbour table.

``cells`` (m, 3) int64 counter-clockwise; ``neighbors`` (m, 3) int64,
``neighbors[c, k]`` the cell across the edge opposite corner ``k`` (the edge
``cells[c, k+1], cells[c, k+2]``), -1 on the boundary.
"""

import numba
import numpy as np


@numba.njit(cache=True)
def cell_edges(cells, neighbors):
    """Every edge once as (e, 2) vertex pairs, and a flag marking boundary edges.

    An edge is emitted by the cell with the larger index of the two that
    share it (or its only cell), so no sorting is needed.
    """
    m = cells.shape[0]
    count = 0
    for c in range(m):
        for k in range(3):
            if neighbors[c, k] < c:
                count += 1
    edges = np.empty((count, 2), dtype=np.int64)
    boundary = np.empty(count, dtype=np.bool_)
    i = 0
    for c in range(m):
        for k in range(3):
            n = neighbors[c, k]
            if n < c:
                edges[i, 0] = cells[c, (k + 1) % 3]
                edges[i, 1] = cells[c, (k + 2) % 3]
                boundary[i] = n < 0
                i += 1
    return edges, boundary
