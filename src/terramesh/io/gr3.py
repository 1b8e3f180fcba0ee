"""SCHISM ``hgrid.gr3`` grids: the fort.14 layout with SCHISM's land boundaries.

Layout (SCHISM manual, "hgrid.gr3"): a title line; ``NE NP``; ``NP`` node
lines ``id x y depth``; ``NE`` element lines ``id 3 n1 n2 n3``; then the
open boundaries exactly as in fort.14, and the land boundaries with one
flag per segment instead of ADCIRC's IBTYPE: ``count 0`` for a land
(exterior) segment, ``count 1`` for an island, whose ring does *not* repeat
its first node at the end (an ADCIRC island does).

In memory a mesh always holds ADCIRC boundaries (:class:`Boundaries`), so
the file is converted on the way in and out:

* reading, the flag becomes the IBTYPE of the same meaning (ADCIRC's 0,
  external no-flux, and 1, island) and an island ring gets its closing node;
* writing, IBTYPE 1, 11 and 21 (islands) become flag 1 with the closing node
  dropped, every other type flag 0. SCHISM has no levees or weirs: a paired
  barrier (IBTYPE 4, 24, 64, 5, 25) becomes two land segments (front and
  back faces) and an external barrier (3, 13, 23) a land segment, dropping
  their heights and coefficients, with a warning.
* writing, a specified-flux (river) boundary (:data:`RIVER_TYPES`: IBTYPE 2,
  12, 22, 32, 52, 102, 112, 122) becomes an *open* boundary, after the
  mesh's own open boundaries, with a warning that names its number: SCHISM
  takes water through open boundaries only (a land segment is a wall), and
  sets a river's flux for that open boundary in ``bctides.in`` (``ifltype``).
  Read back, it is an open boundary: the gr3 keeps no IBTYPE.
* writing, an open boundary that is a closed ring (a box round islands,
  open all the way round) becomes two segments that share their ends:
  SCHISM stops at one that ends where it starts ("Looped open bnd").

Nodes and elements are read and written by the fort.14 code, so both
dialects share it (labels, comments after values, triangles only).
"""

import dataclasses

import numpy as np

from ..errors import MeshFormatError, warn_user
from ..mesh.boundaries import ISLAND_TYPES, PAIRED_TYPES, Boundaries, LandBoundary, OpenBoundary
from .fort14 import (
    checked_ibtypes,
    read_fort14,
    refuse_invalid_cells,
    writable_nodes,
    write_grid,
)

__all__ = ["ISLAND_TYPES", "RIVER_TYPES", "read_gr3", "write_gr3"]

# ADCIRC's specified normal flux (inflow) boundaries: 2, 12, 22 barotropic, 102, 112, 122 the same baroclinic,
# 32 and 52 with radiation; written as open boundaries, as SCHISM forces rivers there
RIVER_TYPES = frozenset({2, 12, 22, 32, 52, 102, 112, 122})


def _is_ring(nodes):
    return len(nodes) > 1 and nodes[0] == nodes[-1]


def _from_gr3(boundaries):
    """ADCIRC boundaries from the gr3 ones: islands (flag 1) closed by repeating their first node."""
    land = []
    for boundary in boundaries.land:
        nodes = boundary.nodes
        if boundary.ibtype == 1 and len(nodes) > 1 and not _is_ring(nodes):
            nodes = np.append(nodes, nodes[0])
        land.append(LandBoundary(nodes, boundary.ibtype, boundary.paired_nodes, boundary.values))
    return Boundaries(open=list(boundaries.open), land=land)


def _to_gr3(boundaries):
    """gr3 boundaries (flags 0 and 1, open rings in two, rivers open) from ADCIRC ones; warns about what changed."""
    land, dropped, rivers = [], set(), []
    opens = []
    for boundary in boundaries.open:
        nodes = np.asarray(boundary.nodes)
        if _is_ring(nodes) and len(nodes) > 3:
            # a box round islands is open all the way round: SCHISM aborts on a segment that ends where it starts
            # ("Looped open bnd"), and its manual asks for two that meet
            half = len(nodes) // 2
            opens += [OpenBoundary(nodes[: half + 1].copy(), boundary.ibtype), OpenBoundary(nodes[half:].copy())]
        else:
            opens.append(OpenBoundary(nodes.copy(), boundary.ibtype))
    for number, boundary in enumerate(boundaries.land, start=1):
        nodes = np.asarray(boundary.nodes)
        if boundary.ibtype in RIVER_TYPES:
            rivers.append(f"land boundary {number} (IBTYPE {boundary.ibtype}) as open boundary {len(opens) + 1}")
            opens.append(OpenBoundary(nodes.copy()))
        elif boundary.ibtype in PAIRED_TYPES or boundary.values is not None:
            dropped.add(boundary.ibtype)
            land.append(LandBoundary(nodes.copy(), 0))
            if boundary.paired_nodes is not None:
                land.append(LandBoundary(np.asarray(boundary.paired_nodes).copy(), 0))
        elif boundary.ibtype in ISLAND_TYPES:
            land.append(LandBoundary(nodes[:-1].copy() if _is_ring(nodes) else nodes.copy(), 1))
        else:
            land.append(LandBoundary(nodes.copy(), 0))
    if dropped:
        warn_user(
            f"hgrid.gr3 has no barrier boundaries: IBTYPE {', '.join(map(str, sorted(dropped)))} written as "
            "land segments (both faces of paired barriers), without their heights and coefficients",
        )
    if rivers:
        warn_user(
            f"hgrid.gr3 takes rivers through open boundaries: wrote {', '.join(rivers)}; "
            "set their flux in bctides.in (ifltype)",
        )
    return Boundaries(open=opens, land=land)


def read_gr3(path, crs="auto"):
    """Read a SCHISM hgrid.gr3 (or any .gr3) file.

    Parameters
    ----------
    path : str or os.PathLike
    crs : str or None, optional
        As :func:`~terramesh.io.read_fort14`: by default longitude,
        latitude when the coordinates fit, else planar.

    Returns
    -------
    Mesh
        ``points``, ``cells`` (0-based), ``point_data["depth"]`` (the gr3's
        fourth column: depth positive down for hgrid.gr3) and
        ``boundaries`` in ADCIRC form: land flag 0 as IBTYPE 0, island flag 1
        as IBTYPE 1 with the ring closed by its first node.

    Raises
    ------
    MeshFormatError
        For truncated or malformed files, land boundaries without a flag,
        elements that are not triangles, or NaN or infinite coordinates or
        values (the fourth column), as :func:`~terramesh.io.read_fort14`.

    Examples
    --------
    >>> import os, tempfile
    >>> import terramesh as tm
    >>> mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.5)
    >>> mesh.point_data["depth"] = 10.0 + mesh.points[:, 0]
    >>> path = os.path.join(tempfile.mkdtemp(), "hgrid.gr3")
    >>> mesh.write(path)
    >>> tm.read_mesh(path).n_cells == mesh.n_cells
    True
    """
    mesh = read_fort14(path, crs)
    return dataclasses.replace(mesh, boundaries=_from_gr3(mesh.boundaries))


def write_gr3(path, mesh):
    """Write a SCHISM hgrid.gr3 file (1-based node and element numbers).

    The fourth node column is ``mesh.point_data["depth"]`` (metres, positive
    down), zero where the mesh has none; boundaries are converted from
    ADCIRC form as the module describes. The mesh is not modified.

    Parameters
    ----------
    path : str or os.PathLike
    mesh : Mesh
        A 2D triangle mesh.

    Raises
    ------
    MeshFormatError
        If the mesh is not a 2D triangle mesh, a coordinate or a depth is
        NaN or infinite, a boundary refers to a node the mesh does not
        have or its IBTYPE is not a whole number (no file is written then).
    MeshValidityError
        If cells are clockwise, have zero area or repeat another cell, or
        nodes are in no cell (SCHISM fails on them): repair the mesh with
        :func:`terramesh.cleanup.fix_mesh`. No file is written then.

    Warns
    -----
    TerrameshWarning
        When barrier boundaries lose their heights and coefficients, and when
        river (specified-flux) boundaries are written as open boundaries,
        naming their numbers for ``bctides.in``.

    Examples
    --------
    A square of two triangles (metres) ringed by an ADCIRC island boundary
    (IBTYPE 21, its ring closed by its first node) is written as a SCHISM
    island (flag 1, without the closing node) and read back closed:

    >>> import pathlib, tempfile
    >>> import numpy as np, terramesh as tm
    >>> from terramesh.mesh.boundaries import Boundaries, LandBoundary
    >>> mesh = tm.Mesh(np.array([[0.0, 0.0], [1e3, 0.0], [1e3, 1e3], [0.0, 1e3]]), [[0, 1, 2], [0, 2, 3]])
    >>> mesh.point_data["depth"] = np.array([5.0, 10.0, 10.0, 5.0])
    >>> mesh.boundaries = Boundaries(land=[LandBoundary(np.array([0, 1, 2, 3, 0]), 21)])
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "hgrid.gr3"
    >>> write_gr3(path, mesh)
    >>> path.read_text().splitlines()[-5]
    '4 1 = Number of nodes for land boundary 1'
    >>> back = read_gr3(path)
    >>> back.n_points, back.boundaries.land[0].ibtype, back.boundaries.land[0].nodes.tolist()
    (4, 1, [0, 1, 2, 3, 0])
    """
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise MeshFormatError("hgrid.gr3 holds 2D triangle meshes only")
    # refused before the boundaries' conversion warns of anything
    depth, boundaries = writable_nodes(mesh)
    refuse_invalid_cells(mesh, "hgrid.gr3")
    write_grid(path, mesh, depth, _to_gr3(checked_ibtypes(boundaries)))


def write_ll(path, mesh):
    """Write a SCHISM hgrid.ll file: hgrid.gr3 with the nodes in longitude, latitude degrees.

    A mesh in a projected CRS (``mesh.crs``, UTM metres say) is converted
    (pyproj, to EPSG:4326); a longitude-latitude mesh is written as it is.

    Parameters
    ----------
    path : str or os.PathLike
    mesh : Mesh
        A 2D triangle mesh with a ``crs``, or without one in degrees.

    Raises
    ------
    MeshFormatError
        As :func:`write_gr3`, and for a mesh without a ``crs`` whose
        coordinates are no longitudes and latitudes (the file would hold
        metres where SCHISM reads degrees).

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np, terramesh as tm
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((500e3, 4.6e6), (510e3, 4.61e6)), 2e3)
    >>> mesh.point_data["depth"] = np.full(mesh.n_points, 20.0)
    >>> mesh.crs = "EPSG:32618"  # UTM zone 18 N, metres
    >>> path = os.path.join(tempfile.mkdtemp(), "hgrid.ll")
    >>> write_ll(path, mesh)
    >>> lon, lat = tm.read_mesh(path).points.mean(axis=0)
    >>> bool(-75.1 < lon < -74.9 and 41.5 < lat < 41.7)
    True
    """
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise MeshFormatError("hgrid.ll holds 2D triangle meshes only")
    if not mesh.geographic:
        if mesh.crs is None:
            x, y = mesh.points[:, 0], mesh.points[:, 1]
            if len(x) and (np.abs(x).max() > 360 or np.abs(y).max() > 90):
                raise MeshFormatError(
                    f"hgrid.ll holds longitude, latitude degrees; the mesh spans x {x.min():g}..{x.max():g}, y"
                    f" {y.min():g}..{y.max():g} and has no crs to convert them from: set mesh.crs (e.g. 'EPSG:32618')"
                )
        else:
            from pyproj import Transformer

            to_lonlat = Transformer.from_crs(mesh.crs, "EPSG:4326", always_xy=True)
            lon, lat = to_lonlat.transform(mesh.points[:, 0], mesh.points[:, 1])
            mesh = dataclasses.replace(mesh, points=np.column_stack([lon, lat]), crs="EPSG:4326")
    write_gr3(path, mesh)
