"""VTU, Gmsh 2.2 ``.msh`` and XDMF through meshio.

VTU and XDMF files keep the mesh's reference system (``mesh.crs``, None for
planar coordinates) under the name ``terramesh:crs``, which meshio does not
write: in a VTU as VTK field data (a ``UInt8`` array of the JSON text, which
meshio reads back as ``field_data``), in an XDMF as an ``Information``
element of the grid whose ``Value`` is the JSON text, in a Gmsh file as a
line ``terramesh:crs <JSON text>`` in a ``$Comments`` section at its end
(Gmsh and meshio skip sections they do not know). A file without it (not
written by terramesh) gets a guess from its coordinates.
"""

import json
import os
import re
import shutil
import xml.etree.ElementTree as ET

import numpy as np

from ..errors import MeshFormatError, MeshValidityError, warn_user
from ..mesh.mesh import normalized_crs
from ._text import written_whole
from .fort14 import guess_crs
from .gmsh import GMSH_COMPONENTS, read_gmsh22, write_gmsh22, write_gmsh_view

__all__ = ["read_with_meshio", "write_with_meshio", "writable_point_data", "store_crs", "gmsh_crs_section"]

_CELL_TYPE = {3: "triangle", 4: "tetra"}
_GMSH_CELL_TYPE = {3: 2, 4: 4}  # Gmsh's element types by corners: triangle, tetrahedron
_CRS_NAME = "terramesh:crs"
_ABSENT = object()  # a file that keeps no reference system, unlike one that keeps None (planar)
_GMSH_TAIL = 4096  # bytes at the end of a Gmsh file searched for its reference system


def write_with_meshio(path, mesh, file_format):
    """Write ``mesh`` as ``"vtu"`` or ``"xdmf"`` with meshio, or as ``"gmsh22"`` (ASCII, :func:`.gmsh.write_gmsh22`).

    2D points get a zero z column, as VTU and Gmsh store 3D coordinates.
    Point data arrays are written alongside in VTU and XDMF (booleans as
    uint8 0 and 1; MeshFormatError for text or other non-numbers, naming
    the array), and so is ``mesh.crs`` (see the module). Gmsh files get physical and geometrical
    tag 1 on every cell and a ``$NodeData`` view of each point data array of 1, 3 or 9 values a
    node (others are left out with a warning). The file (and an XDMF's ``.h5``)
    is written under a temporary name and renamed when complete.
    """
    if file_format == "gmsh22":
        arrays = writable_point_data(mesh)
        left_out = [name for name, array in arrays.items() if array[0].size not in GMSH_COMPONENTS]
        if left_out:
            warn_user(
                f"point_data {left_out} left out of the Gmsh file {os.fspath(path)}: a Gmsh view holds 1, 3 or 9 "
                "values a node"
            )
        with written_whole(path) as temporary, open(temporary, "w", encoding="ascii", newline="\n") as handle:
            ones = np.ones(mesh.n_cells, dtype=np.int64)
            write_gmsh22(handle, mesh.points, [(_GMSH_CELL_TYPE[mesh.cells.shape[1]], mesh.cells, ones)])
            ids = np.arange(1, mesh.n_points + 1)
            for name, array in arrays.items():  # a depth written to .msh and read back was gone
                if name not in left_out:
                    write_gmsh_view(handle, "NodeData", name, ids, array)
            handle.write(gmsh_crs_section(mesh.crs))
        return
    import meshio

    points = mesh.points
    if mesh.dim == 2:
        points = np.column_stack([points, np.zeros(mesh.n_points)])
    output = meshio.Mesh(points, [(_CELL_TYPE[mesh.cells.shape[1]], mesh.cells)], point_data=writable_point_data(mesh))
    with written_whole(path) as temporary:
        getattr(meshio, file_format).write(temporary, output)
        store_crs(temporary, file_format, mesh.crs)


def writable_point_data(mesh):
    """``mesh.point_data`` as arrays of the types VTU, XDMF and Gmsh hold; MeshFormatError naming one they cannot.

    meshio knows 8- to 64-bit integers and 32- and 64-bit floats only: a
    boolean array stopped it with a bare ``KeyError: dtype('bool')``.
    Booleans are written as 0 and 1 (uint8, read back as such), other floats
    as float64; text, objects, complex numbers and dates are refused.
    """
    arrays = {}
    for name, values in mesh.point_data.items():
        array = np.asarray(values)
        if array.dtype.kind == "b":
            array = array.astype(np.uint8)
        elif array.dtype.kind == "f" and array.dtype.itemsize not in (4, 8):  # float16, longdouble
            array = array.astype(np.float64)
        elif array.dtype.kind not in "iuf":
            raise MeshFormatError(
                f"point_data[{name!r}] holds {array.dtype} values; VTU, XDMF and Gmsh files hold integers and reals "
                "only: convert it (e.g. .astype(float)) or leave it out of point_data"
            )
        # checked here too: point_data may have changed since the mesh was made
        if array.shape[:1] != (mesh.n_points,):
            raise MeshFormatError(
                f"point_data[{name!r}] has shape {array.shape}; it needs one value or row per point, "
                f"shape ({mesh.n_points},) or ({mesh.n_points}, k)"
            )
        arrays[name] = array
    return arrays


def store_crs(path, file_format, crs):
    """Keep ``crs`` (a string, or None: planar) in the ``"vtu"``, ``"xdmf"`` or ``"gmsh22"`` file ``path``.

    See the module for where each format keeps it; :func:`read_with_meshio`
    reads it back.
    """
    text = json.dumps(None if crs is None else str(crs))
    if file_format == "vtu":
        _store_crs_vtu(path, text)
    elif file_format == "xdmf":
        _store_crs_xdmf(path, text)
    elif file_format == "gmsh22":
        with open(path, "a", encoding="utf-8", newline="\n") as handle:
            handle.write(gmsh_crs_section(crs))


def gmsh_crs_section(crs):
    """The ``$Comments`` section that keeps ``crs`` at the end of a Gmsh file (see the module)."""
    return f"$Comments\n{_CRS_NAME} {json.dumps(None if crs is None else str(crs))}\n$EndComments\n"


def _store_crs_vtu(path, crs):
    """Add ``crs`` (JSON text) to the VTU file ``path`` as the field data array ``terramesh:crs``."""
    data = " ".join(map(str, crs.encode("utf-8")))
    field = (
        f'<FieldData>\n<DataArray type="UInt8" Name="{_CRS_NAME}" NumberOfTuples="{len(crs.encode())}" '
        f'format="ascii">\n{data}\n</DataArray>\n</FieldData>\n'
    ).encode("ascii")
    marker = b"<UnstructuredGrid>\n"
    # streamed: the file may hold gigabytes of base64 data after its header
    with open(path, "rb") as source:
        head = source.read(4096)
        at = head.find(marker)
        if at < 0:
            raise MeshFormatError(f"{path}: meshio wrote no <UnstructuredGrid> header to add the reference system to")
        at += len(marker)
        with open(path + ".crs", "wb") as target:
            target.write(head[:at] + field + head[at:])
            shutil.copyfileobj(source, target)
    os.replace(path + ".crs", path)


def _store_crs_xdmf(path, crs):
    """Add ``crs`` (JSON text) to the XDMF file ``path`` as the grid's ``Information Name="terramesh:crs"``."""
    tree = ET.parse(path)
    grid = tree.getroot().find("Domain/Grid")
    if grid is None:
        raise MeshFormatError(f"{path}: meshio wrote no Domain/Grid to add the reference system to")
    information = ET.SubElement(grid, "Information", Name=_CRS_NAME, Value=crs)
    # meshio reads an Information's text as XML of Gmsh tags and refuses one without text: an empty element
    information.text = "<terramesh/>"
    tree.write(path)


def _dimension(cell_type):
    """The topological dimension of a meshio cell type; unknown ones count as volumes (a warning too many)."""
    if cell_type == "vertex":
        return 0
    if cell_type.startswith(("line", "VTK_LAGRANGE_CURVE")):
        return 1
    if cell_type.startswith(("triangle", "quad", "polygon", "VTK_LAGRANGE_TRIANGLE", "VTK_LAGRANGE_QUADRILATERAL")):
        return 2
    return 3


def _stored_crs(path, file_format, data):
    """The reference system a file keeps (None: planar), or ``_ABSENT`` where it keeps none."""
    try:
        if file_format == "gmsh":
            # the section is the file's last: its tail, not gigabytes of nodes, is read
            with open(path, "rb") as handle:
                handle.seek(max(os.path.getsize(path) - _GMSH_TAIL, 0))
                tail = handle.read().decode("utf-8", errors="replace")
            found = re.findall(rf"^\$Comments\s*\n{re.escape(_CRS_NAME)} (.*)\n\$EndComments", tail, flags=re.M)
            if not found:
                return _ABSENT
            text = found[-1]
        elif file_format == "vtu":
            if _CRS_NAME not in data.field_data:
                return _ABSENT
            text = np.asarray(data.field_data[_CRS_NAME]).astype(np.uint8).tobytes().decode("utf-8")
        elif file_format == "xdmf":
            found = [
                element.get("Value")
                for element in ET.parse(path).getroot().iter("Information")
                if element.get("Name") == _CRS_NAME
            ]
            if not found:
                return _ABSENT
            text = found[0]
        else:
            return _ABSENT
        crs = json.loads(text)
    except (ValueError, TypeError, ET.ParseError) as error:
        raise MeshFormatError(f"{path}: unreadable {_CRS_NAME} (the mesh's reference system): {error}") from error
    if crs is not None and not isinstance(crs, str):
        raise MeshFormatError(f"{path}: {_CRS_NAME} must be a string or null, found {crs!r}")
    if crs is not None:
        # terramesh before 2026-11-30 kept any text ("local grid", "UTM33N"): such a file still reads, planar
        try:
            crs = normalized_crs(crs)
        except MeshValidityError:
            warn_user(
                f"{path}: its reference system {crs!r} is none pyproj can read: the mesh is read as planar "
                "(crs None); give read_mesh(path, crs=...) the system it is in"
            )
            crs = None
    return crs


def _read_gmsh(path):
    """Read a Gmsh file: 2.2 ASCII with :func:`~terramesh.io.gmsh.read_gmsh22`, others with meshio.

    The files terramesh writes are 2.2 ASCII, which meshio parses line by
    line in Python (16.8 s for 801k vertices). For the others, meshio is
    asked again without the file's element data where it cannot split that:
    meshio 5 splits ``$ElementData`` among the cell blocks by the length of
    each ``(type, array)`` pair, always 2, so a file with element data and
    more than one block (an FWI mesh's boundary lines and its triangles,
    :func:`~terramesh.io.write_fwi_mesh` with ``velocity_on="cells"``) cannot
    be read. Element data is not kept here anyway.
    """
    import tempfile

    import meshio

    data = read_gmsh22(path)
    if data is not None:
        return data
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
    ``crs`` (a string, or None for planar coordinates) is the mesh's;
    ``"auto"``: the one the file keeps (VTU, XDMF and Gmsh files terramesh
    wrote, None included), else for a 2D mesh longitude, latitude where the
    coordinates fit those ranges (:func:`~terramesh.io.fort14.guess_crs`),
    else none.

    Cells of lower dimension than those kept (boundary lines beside
    triangles, faces beside tetrahedra) are left out without a word; others
    (quadrilaterals beside triangles, hexahedra) with a TerrameshWarning.
    Cell data (a velocity per cell, regions) is not kept either, as a mesh
    holds point data only; its names are in
    ``mesh.info["cell_data_left_out"]``.
    A file meshio cannot parse (truncated or malformed, the reason
    meshio gave after), or whose cells refer to vertices it does not
    have, raises MeshFormatError; a longitude-latitude ``crs`` given for
    coordinates that are no degrees, MeshValidityError (the same kept in
    the file: a TerrameshWarning, and the mesh is read as planar).
    """
    import meshio

    from ..mesh.mesh import Mesh

    try:
        # the per-format readers raise; meshio.read would call sys.exit on failure
        data = _read_gmsh(path) if file_format == "gmsh" else getattr(meshio, file_format).read(path)
    except MeshFormatError:  # the Gmsh 2.2 reader's, which say what is wrong
        raise
    except OSError as error:  # no permission, a missing XDMF .h5: the file may be whole
        raise MeshFormatError(f"{path}: cannot read as {file_format}: {type(error).__name__}: {error}") from error
    except Exception as error:  # meshio raises many types for malformed files
        # some carry no message (meshio's ReadError for an empty or cut-off XML file), others NumPy's words on
        # meshio's arrays ("cannot reshape array of size 2 into shape (315,4)" for a cut-off Gmsh file): say what
        # kind of failure it was, the reason after
        detail = str(error).strip()
        reason = f"{type(error).__name__}: {detail}" if detail else type(error).__name__
        raise MeshFormatError(
            f"{path}: cannot read as {file_format}: the file is truncated or malformed ({reason})"
        ) from error
    for cell_type in ("tetra", "triangle"):
        blocks = [block.data for block in data.cells if block.type == cell_type]
        if blocks:
            break
    else:
        raise MeshFormatError(f"{path}: no triangle or tetrahedron cells")
    dropped = {}
    for block in data.cells:
        if block.type != cell_type and _dimension(block.type) >= (3 if cell_type == "tetra" else 2):
            dropped[block.type] = dropped.get(block.type, 0) + len(block.data)
    cells = np.concatenate(blocks)
    if dropped:
        left_out = ", ".join(f"{count:,} {name}" for name, count in dropped.items())
        warn_user(
            f"{path}: read its {len(cells):,} {cell_type} cells only and left out {left_out} cells: "
            "a terramesh mesh holds triangles or tetrahedra"
        )
    points = data.points
    if cell_type == "triangle" and points.shape[1] == 3 and np.all(points[:, 2] == 0):
        points = points[:, :2]
    point_data = {name: np.asarray(values) for name, values in data.point_data.items() if not name.startswith("gmsh:")}
    # a velocity per cell (write_fwi_mesh's velocity_on="cells"), regions: named in the mesh's info, not warned
    # of, as every FWI file has regions
    cell_data = [name for name in data.cell_data if not name.startswith("gmsh:")]
    cell_data += (data.info or {}).get("element_data", []) if isinstance(data.info, dict) else []
    guessed = stored = False
    if crs == "auto":
        crs = _stored_crs(path, file_format, data)
        stored = crs is not _ABSENT
        if crs is _ABSENT:  # as a fort.14's: no reference system kept, a guess from the coordinates
            crs, guessed = (guess_crs(points), True) if points.shape[1] == 2 else (None, False)
    try:
        info = {"crs_guessed": guessed, "cell_data_left_out": list(dict.fromkeys(cell_data))}
        mesh = Mesh(points, cells, point_data=point_data, info=info)
    except MeshValidityError as error:  # e.g. cells that refer to vertices past the last: the file is malformed
        raise MeshFormatError(f"{path}: malformed {file_format} file: {error}") from error
    # apart: a crs the caller gave that does not fit is the caller's mistake, not a malformed file
    try:
        mesh.crs = crs
    except MeshValidityError as error:
        if not stored:
            raise
        # metres that terramesh before 2026-12 let through as "EPSG:4326": read as a stored crs pyproj cannot read
        warn_user(
            f"{path}: the reference system it keeps does not fit its points ({error}): the mesh is read as "
            "planar (crs None); give read_mesh(path, crs=...) the system it is in"
        )
    return mesh
