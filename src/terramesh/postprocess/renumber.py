"""Vertex renumbering by reverse Cuthill-McKee (the OceanMesh2D guide's ``msh.renum``, §6.3)."""

import numbers

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ..errors import MeshValidityError
from ..mesh.topology import checked_cells, unique_edges, with_fixed_points_renumbered

__all__ = ["bandwidth", "rcm_permutation", "renumber"]


def _cells(cells, n_points=None):
    """``cells`` checked as an integer ``(m, k)`` array, ``k >= 2``, of indices (below ``n_points`` if given)."""
    corners = np.shape(cells)[1] if np.ndim(cells) == 2 else 3
    return checked_cells(cells, max(corners, 2), n_points)


def bandwidth(cells):
    """Bandwidth of the mesh's vertex matrix: the largest ``|i - j|`` over the edges ``(i, j)``.

    The half-bandwidth of any matrix with a nonzero for each pair of vertices
    sharing a cell (mass or stiffness matrix of linear elements).

    Parameters
    ----------
    cells : numpy.ndarray, shape (m, k)
        Vertex indices of each cell.

    Returns
    -------
    int
        0 for an empty mesh.

    Raises
    ------
    MeshValidityError
        For cells that are not an integer ``(m, k)`` array (``k >= 2``), or
        negative indices.

    Examples
    --------
    >>> import numpy as np
    >>> bandwidth(np.array([[0, 1, 5], [1, 2, 5]]))
    5
    """
    cells = _cells(cells)
    if cells.size == 0:
        return 0
    corners = cells.shape[1]
    return int(max(np.abs(cells[:, i] - cells[:, j]).max() for i in range(corners) for j in range(i + 1, corners)))


def rcm_permutation(cells, n_points):
    """Reverse Cuthill-McKee order of the vertices of a mesh.

    Parameters
    ----------
    cells : numpy.ndarray, shape (m, k)
        Integer vertex indices of each cell, ``0 .. n_points - 1``.
    n_points : int
        Number of vertices (unused ones come out too).

    Returns
    -------
    numpy.ndarray, shape (n_points,)
        ``order[k]`` is the old index of the vertex numbered ``k``.

    Raises
    ------
    MeshValidityError
        For ``n_points`` that is not a non-negative integer, cells that are
        not an integer ``(m, k)`` array (``k >= 2``), or indices outside
        ``0 .. n_points - 1``.

    Examples
    --------
    >>> import numpy as np
    >>> order = rcm_permutation(np.array([[0, 5, 1], [5, 2, 1]]), 6)
    >>> sorted(order.tolist())
    [0, 1, 2, 3, 4, 5]
    """
    if not isinstance(n_points, numbers.Integral) or isinstance(n_points, bool) or n_points < 0:
        raise MeshValidityError(f"n_points must be a non-negative integer, got {n_points!r}")
    n_points = int(n_points)
    edges = unique_edges(_cells(cells, n_points))
    if n_points == 0:
        return np.zeros(0, dtype=np.int64)  # scipy refuses a 0 x 0 graph
    rows = np.concatenate([edges[:, 0], edges[:, 1]])
    columns = np.concatenate([edges[:, 1], edges[:, 0]])
    graph = csr_matrix((np.ones(len(rows), dtype=np.int8), (rows, columns)), shape=(n_points, n_points))
    return reverse_cuthill_mckee(graph, symmetric_mode=True).astype(np.int64)


def renumber(mesh):
    """Renumber the vertices by reverse Cuthill-McKee to shrink the matrix bandwidth.

    Cells keep their order; their vertex indices, the vertex coordinates,
    every ``point_data`` array and the boundaries (node strings, barrier
    pairs) follow the new numbering, so the mesh is the same one.

    RCM is a heuristic: on a mesh already in a good order (one renumbered
    before, or a structured grid) its order can have a larger bandwidth.
    The new order is taken only when it has a smaller bandwidth; otherwise
    the vertices keep their numbers (``info["renumber"]["reordered"]`` is
    False and ``new_index`` is ``0 .. n - 1``), so renumbering never makes
    the bandwidth worse.

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    Mesh
        A new mesh. ``info["renumber"]`` holds ``bandwidth_before`` and
        ``bandwidth_after`` (see :func:`bandwidth`; ``bandwidth_after <=
        bandwidth_before``), ``reordered`` (False where the RCM order was no
        better and the original one was kept) and ``new_index``, shape
        ``(n,)``: the new number of each old vertex, to carry other per-vertex
        data along (e.g. ``NodalAttributes.renumbered(new_index)``).

    Raises
    ------
    MeshValidityError
        For cells, or boundaries (assigned after the mesh was made), that
        refer to vertices that do not exist.

    References
    ----------
    E. Cuthill and J. McKee, "Reducing the bandwidth of sparse symmetric
    matrices", Proc. 24th ACM National Conference, 1969,
    https://doi.org/10.1145/800195.805928

    Examples
    --------
    >>> import numpy as np
    >>> import terramesh as tm
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (4, 1)), 0.2)
    >>> shuffled = tm.Mesh(mesh.points, np.random.default_rng(0).permutation(mesh.n_points)[mesh.cells])
    >>> report = renumber(shuffled).info["renumber"]
    >>> report["bandwidth_after"] < report["bandwidth_before"]
    True
    """
    from ..mesh.mesh import Mesh, check_boundaries

    n = mesh.n_points
    check_boundaries(mesh.boundaries, n)  # a node past the vertices was a bare IndexError below
    order = rcm_permutation(mesh.cells, n)
    new_index = np.empty(n, dtype=np.int64)
    new_index[order] = np.arange(n)
    cells = new_index[mesh.cells]
    before, after = bandwidth(mesh.cells), bandwidth(cells)
    reordered = after < before
    if not reordered:
        # RCM is a heuristic and can lose to the order the mesh already has: keep that one
        order = new_index = np.arange(n, dtype=np.int64)
        cells, after = np.array(mesh.cells, dtype=np.int64), before
    boundaries = None if mesh.boundaries is None else mesh.boundaries.renumbered(new_index)
    info = dict(
        mesh.info,
        renumber={
            "bandwidth_before": before,
            "bandwidth_after": after,
            "reordered": reordered,
            "new_index": new_index,
        },
    )
    info = with_fixed_points_renumbered(info, new_index)  # build's pfix vertices
    return Mesh(
        mesh.points[order],
        cells,
        point_data={name: np.asarray(values)[order] for name, values in mesh.point_data.items()},
        boundaries=boundaries,
        title=mesh.title,
        crs=mesh.crs,
        info=info,
    )
