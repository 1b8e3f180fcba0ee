"""Vertex renumbering by reverse Cuthill-McKee (the OceanMesh2D guide's ``msh.renum``, §6.3)."""

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ..mesh.topology import unique_edges

__all__ = ["bandwidth", "rcm_permutation", "renumber"]


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

    Examples
    --------
    >>> import numpy as np
    >>> bandwidth(np.array([[0, 1, 5], [1, 2, 5]]))
    5
    """
    cells = np.asarray(cells, dtype=np.int64)
    if cells.size == 0:
        return 0
    corners = cells.shape[1]
    return int(max(np.abs(cells[:, i] - cells[:, j]).max() for i in range(corners) for j in range(i + 1, corners)))


def rcm_permutation(cells, n_points):
    """Reverse Cuthill-McKee order of the vertices of a mesh.

    Parameters
    ----------
    cells : numpy.ndarray, shape (m, k)
    n_points : int
        Number of vertices (unused ones come out too).

    Returns
    -------
    numpy.ndarray, shape (n_points,)
        ``order[k]`` is the old index of the vertex numbered ``k``.

    Examples
    --------
    >>> import numpy as np
    >>> order = rcm_permutation(np.array([[0, 5, 1], [5, 2, 1]]), 6)
    >>> sorted(order.tolist())
    [0, 1, 2, 3, 4, 5]
    """
    edges = unique_edges(np.asarray(cells, dtype=np.int64))
    rows = np.concatenate([edges[:, 0], edges[:, 1]])
    columns = np.concatenate([edges[:, 1], edges[:, 0]])
    graph = csr_matrix((np.ones(len(rows), dtype=np.int8), (rows, columns)), shape=(n_points, n_points))
    return reverse_cuthill_mckee(graph, symmetric_mode=True).astype(np.int64)


def renumber(mesh):
    """Renumber the vertices by reverse Cuthill-McKee to shrink the matrix bandwidth.

    Cells keep their order; their vertex indices, the vertex coordinates,
    every ``point_data`` array and the boundaries (node strings, barrier
    pairs) follow the new numbering, so the mesh is the same one.

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    Mesh
        A new mesh. ``info["renumber"]`` holds ``bandwidth_before`` and
        ``bandwidth_after`` (see :func:`bandwidth`) and ``new_index``, shape
        ``(n,)``: the new number of each old vertex, to carry other per-vertex
        data along (e.g. ``NodalAttributes.renumbered(new_index)``).

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
    from ..mesh.mesh import Mesh

    n = mesh.n_points
    order = rcm_permutation(mesh.cells, n)
    new_index = np.empty(n, dtype=np.int64)
    new_index[order] = np.arange(n)
    cells = new_index[mesh.cells]
    boundaries = None if mesh.boundaries is None else mesh.boundaries.renumbered(new_index)
    info = dict(
        mesh.info,
        renumber={
            "bandwidth_before": bandwidth(mesh.cells),
            "bandwidth_after": bandwidth(cells),
            "new_index": new_index,
        },
    )
    return Mesh(
        mesh.points[order],
        cells,
        point_data={name: np.asarray(values)[order] for name, values in mesh.point_data.items()},
        boundaries=boundaries,
        title=mesh.title,
        crs=mesh.crs,
        info=info,
    )
