"""VTU, Gmsh 2.2 ``.msh`` and XDMF through meshio."""

import numpy as np

from ..errors import MeshFormatError, MeshValidityError
from .fort14 import guess_crs

__all__ = ["read_with_meshio", "write_with_meshio"]

_CELL_TYPE = {3: "triangle", 4: "tetra"}


def write_with_meshio(path, mesh, file_format):
    """Write ``mesh`` with meshio as ``"vtu"``, ``"gmsh22"`` (ASCII) or ``"xdmf"``.

    2D points get a zero z column, as VTU and Gmsh store 3D coordinates.
    Point data arrays are written alongside in VTU and XDMF. Gmsh files get
    physical and geometrical tag 1 on every cell and no point data.
    """
    import meshio

    points = mesh.points
    if mesh.dim == 2:
        points = np.column_stack([points, np.zeros(mesh.n_points)])
    cell_type = _CELL_TYPE[mesh.cells.shape[1]]
    cell_data = {}
    if file_format.startswith("gmsh"):
        ones = np.ones(mesh.n_cells, dtype=np.int32)
        cell_data = {"gmsh:physical": [ones], "gmsh:geometrical": [ones]}
    # meshio cannot read back the NodeData of ASCII Gmsh files, so Gmsh gets geometry only
    point_data = {} if file_format.startswith("gmsh") else dict(mesh.point_data)
    output = meshio.Mesh(points, [(cell_type, mesh.cells)], point_data=point_data, cell_data=cell_data)
    if file_format == "gmsh22":
        meshio.gmsh.write(path, output, fmt_version="2.2", binary=False)
    else:
        getattr(meshio, file_format).write(path, output)


def _read_gmsh(path):
    """Read a Gmsh file with meshio; again without its element data where meshio cannot split that.

    meshio 5 splits ``$ElementData`` among the cell blocks by the length of
    each ``(type, array)`` pair, always 2, so a file with element data and
    more than one block (an FWI mesh's boundary lines and its triangles,
    :func:`~terramesh.io.write_fwi_mesh` with ``velocity_on="cells"``) cannot
    be read. Element data is not kept here anyway.
    """
    import os
    import re
    import tempfile

    import meshio

    try:
        return meshio.gmsh.read(path)
    except ValueError as error:
        if "Incompatible cell data" not in str(error):
            raise
    with open(path, "rb") as handle:
        text = re.sub(rb"\$ElementData\b.*?\$EndElementData[^\n]*\n?", b"", handle.read(), flags=re.S)
    handle, stripped = tempfile.mkstemp(suffix=".msh")
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(text)
        return meshio.gmsh.read(stripped)
    finally:
        os.remove(stripped)


def read_with_meshio(path, file_format, crs="auto"):
    """Read the tetrahedra or else the triangles of a ``"vtu"``, ``"gmsh"`` or ``"xdmf"`` file.

    A third coordinate that is zero everywhere is dropped, giving a 2D mesh.
    These files record no reference system: ``crs`` (a string, or None) is
    the mesh's; ``"auto"``, for a 2D mesh, longitude, latitude where the
    coordinates fit those ranges (:func:`~terramesh.io.fort14.guess_crs`),
    else none.
    A file meshio cannot parse, or whose cells refer to vertices it does not
    have, raises MeshFormatError.
    """
    import meshio

    from ..mesh.mesh import Mesh

    try:
        # the per-format readers raise; meshio.read would call sys.exit on failure
        data = _read_gmsh(path) if file_format == "gmsh" else getattr(meshio, file_format).read(path)
    except Exception as error:  # meshio raises many types for malformed files
        # some carry no message (meshio's ReadError for an empty or cut-off XML file): say what kind of failure it was
        detail = str(error).strip() or f"truncated or not a {file_format} file"
        raise MeshFormatError(f"{path}: cannot read as {file_format}: {type(error).__name__}: {detail}") from error
    for cell_type in ("tetra", "triangle"):
        blocks = [block.data for block in data.cells if block.type == cell_type]
        if blocks:
            break
    else:
        raise MeshFormatError(f"{path}: no triangle or tetrahedron cells")
    cells = np.concatenate(blocks)
    points = data.points
    if cell_type == "triangle" and points.shape[1] == 3 and np.all(points[:, 2] == 0):
        points = points[:, :2]
    point_data = {name: np.asarray(values) for name, values in data.point_data.items() if not name.startswith("gmsh:")}
    try:
        if crs == "auto":  # as a fort.14's: these files keep no reference system either
            crs = guess_crs(points) if points.shape[1] == 2 else None
        return Mesh(points, cells, point_data=point_data, crs=crs)
    except MeshValidityError as error:  # e.g. cells that refer to vertices past the last: the file is malformed
        raise MeshFormatError(f"{path}: malformed {file_format} file: {error}") from error
