"""Mesh files: one ``read_mesh``/``write_mesh`` pair, one module per format.

Formats, chosen by file name:

========================  ==========  ====================================
file name                 format      notes
========================  ==========  ====================================
``*.14``, ``*.grd``       fort14      ADCIRC grid with boundaries (native)
``*.gr3``                 gr3         SCHISM hgrid.gr3 (native)
``*.ll``                  ll          SCHISM hgrid.ll: degrees (native)
``*.vtu``                 vtu         ParaView (meshio), keeps the CRS
``*.msh``                 gmsh22      Gmsh 2.2 ASCII (read by .gmsh, written by meshio)
``*.xdmf``                xdmf        XDMF + HDF5 (meshio), keeps the CRS
========================  ==========  ====================================

ADCIRC nodal attributes (fort.13) travel beside the grid, not in it: see
:func:`read_fort13` and :func:`write_fort13`.
"""

import os

from ..errors import MeshFormatError
from .fort13 import NodalAttribute, NodalAttributes, read_fort13, write_fort13
from .fort14 import Boundaries, LandBoundary, OpenBoundary, read_fort14, write_fort14
from .fwi import BOUNDARY_IDS, BOUNDARY_IDS_3D, REGION_IDS, boundary_sides, write_fwi_mesh
from .gr3 import read_gr3, write_gr3, write_ll
from .meshio_formats import read_with_meshio, write_with_meshio

__all__ = [
    "read_mesh",
    "write_mesh",
    "format_from_name",
    "FORMATS",
    "Boundaries",
    "OpenBoundary",
    "LandBoundary",
    "read_fort14",
    "write_fort14",
    "read_gr3",
    "write_gr3",
    "write_ll",
    "NodalAttribute",
    "NodalAttributes",
    "read_fort13",
    "write_fort13",
    "write_fwi_mesh",
    "boundary_sides",
    "BOUNDARY_IDS",
    "BOUNDARY_IDS_3D",
    "REGION_IDS",
]

FORMATS = {
    "fort14": (read_fort14, write_fort14),
    "gr3": (read_gr3, write_gr3),
    "ll": (read_gr3, write_ll),
    "vtu": (
        lambda path, crs: read_with_meshio(path, "vtu", crs),
        lambda path, mesh: write_with_meshio(path, mesh, "vtu"),
    ),
    "gmsh22": (
        lambda path, crs: read_with_meshio(path, "gmsh", crs),
        lambda path, mesh: write_with_meshio(path, mesh, "gmsh22"),
    ),
    "xdmf": (
        lambda path, crs: read_with_meshio(path, "xdmf", crs),
        lambda path, mesh: write_with_meshio(path, mesh, "xdmf"),
    ),
}

FORMAT_BY_EXTENSION = {
    ".14": "fort14",
    ".grd": "fort14",
    ".gr3": "gr3",
    ".ll": "ll",
    ".vtu": "vtu",
    ".msh": "gmsh22",
    ".xdmf": "xdmf",
}
"""The format (a key of ``FORMATS``) of each file extension (lower case) that :func:`format_from_name` knows."""


def format_from_name(path):
    """The format (a key of ``FORMATS``) that a file name's extension says; MeshFormatError if none.

    Examples
    --------
    >>> format_from_name("fort.14"), format_from_name("hgrid.gr3"), format_from_name("model.msh")
    ('fort14', 'gr3', 'gmsh22')
    """
    extension = os.path.splitext(os.fspath(path))[1].lower()
    if extension not in FORMAT_BY_EXTENSION:
        known = ", ".join(sorted(FORMAT_BY_EXTENSION))
        raise MeshFormatError(f"cannot tell the mesh format of {os.fspath(path)!r} from its name; use one of {known}")
    return FORMAT_BY_EXTENSION[extension]


def _format_of(path, file_format):
    if file_format is not None:
        if file_format not in FORMATS:
            raise MeshFormatError(f"unknown mesh format {file_format!r}; known: {', '.join(FORMATS)}")
        return file_format
    try:
        return format_from_name(path)
    except MeshFormatError as error:
        raise MeshFormatError(f"{error} or pass file_format") from None


def read_mesh(path, file_format=None, crs="auto"):
    """Read a mesh file.

    Parameters
    ----------
    path : str or os.PathLike
    file_format : str, optional
        One of ``FORMATS``; by default taken from the file name.
    crs : str or None, optional
        The points' reference system (``mesh.crs``; None: planar).
        ``"auto"`` (default): the one a ``.vtu`` or ``.xdmf`` file that
        terramesh wrote keeps (None included); for other files, which keep
        none, for a 2D mesh longitude, latitude (``"EPSG:4326"``) when the
        coordinates fit those ranges (:func:`read_fort14`), else None.
        Give None or a CRS string to say, whatever the file keeps.

    Returns
    -------
    Mesh

    Raises
    ------
    MeshFormatError
        Unknown format, a folder, or a malformed or truncated file.
    FileNotFoundError
        If there is no such file.

    Examples
    --------
    >>> import terramesh as tm, tempfile, os
    >>> mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.25)
    >>> mesh.point_data["depth"] = 5.0 + mesh.points[:, 1]  # metres, positive down
    >>> path = os.path.join(tempfile.mkdtemp(), "disk.14")
    >>> mesh.write(path)
    >>> tm.read_mesh(path).n_cells == mesh.n_cells
    True
    """
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such mesh file: {os.fspath(path)!r}")
    if os.path.isdir(path):  # each reader's open() said only "[Errno 21] Is a directory"
        raise MeshFormatError(f"{os.fspath(path)} is a folder, not a mesh file")
    return FORMATS[_format_of(path, file_format)][0](path, crs)


def write_mesh(path, mesh, file_format=None):
    """Write a mesh file; the format follows the file name unless given.

    Parameters
    ----------
    path : str or os.PathLike
    mesh : Mesh
    file_format : str, optional
        One of ``FORMATS``.

    Notes
    -----
    The file is written under a temporary name beside ``path`` and renamed
    when complete: a write that fails leaves any earlier file as it was and
    no truncated one. ``.vtu`` and ``.xdmf`` files keep ``mesh.crs``.
    """
    FORMATS[_format_of(path, file_format)][1](path, mesh)
