"""Mesh files for full-waveform-inversion codes, with boundary tags and velocities alongside.

========================  ==========  ==============================================================
file name                 format      what is in it
========================  ==========  ==============================================================
``*.msh``                 Gmsh 2.2    ASCII; triangles tagged by region, boundary lines tagged by
                                      side (``$PhysicalNames``), velocity as ``$NodeData`` or
                                      ``$ElementData``: what Firedrake (and so spyro) reads
``*.vtu``                 VTU         triangles, ``region`` cell data, velocity (meshio)
``*.xdmf``                XDMF+HDF5   the same (meshio)
========================  ==========  ==============================================================

Boundary sides take the ids of Firedrake's ``RectangleMesh`` (1: x min,
"left"; 2: x max, "right"; 3: z min, "bottom"; 4: z max, "top", the free
surface); a boundary edge on none of the four sides (a domain that is not a
box) gets 5, "boundary". Cells get region 1, "model", or 2, "pad" where
they lie in the padding (sponge) layer of a padded velocity model.
"""

import os

import numpy as np

from ..errors import MeshFormatError
from ..mesh.topology import boundary_edges

__all__ = ["BOUNDARY_IDS", "REGION_IDS", "boundary_sides", "write_fwi_mesh"]

BOUNDARY_IDS = {"left": 1, "right": 2, "bottom": 3, "top": 4, "boundary": 5}
"""Physical ids of the boundary lines by side (Firedrake's RectangleMesh numbering, plus 5 for any other)."""

REGION_IDS = {"model": 1, "pad": 2}
"""Physical ids of the cells: inside the velocity model, or in its padding layer."""

_FORMATS = {".msh": "gmsh22", ".vtu": "vtu", ".xdmf": "xdmf"}
_UNITS = {"m": 1.0, "km": 1000.0}


def _box(points, bbox):
    if bbox is None:
        return np.array([points.min(axis=0), points.max(axis=0)])
    box = np.asarray(bbox, dtype=np.float64)
    if box.shape != (2, 2) or not np.all(np.isfinite(box)) or np.any(box[1] <= box[0]):
        raise MeshFormatError(f"bbox must be [[xmin, zmin], [xmax, zmax]], got {np.asarray(bbox).tolist()}")
    return box


def boundary_sides(mesh, bbox=None, *, tolerance=None):
    """The boundary edges of a 2-D mesh and the side of the box each lies on.

    An edge lies on a side when both its vertices are within ``tolerance``
    of that side's line.

    Parameters
    ----------
    mesh : Mesh
        A valid 2-D triangle mesh, coordinates ``(x, z)``.
    bbox : array_like, shape (2, 2), optional
        The box ``[[xmin, zmin], [xmax, zmax]]``; the mesh's own extent by default.
    tolerance : float, optional
        Same units as the mesh; 1 % of the median boundary edge by default.

    Returns
    -------
    edges : ndarray, shape (b, 2), int64
        Vertex pairs, counter-clockwise around the domain.
    sides : ndarray, shape (b,), int64
        :data:`BOUNDARY_IDS` value of each edge.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.mesh import Mesh
    >>> square = Mesh(np.array([[0.0, -1], [1, -1], [1, 0], [0, 0]]), np.array([[0, 1, 2], [0, 2, 3]]))
    >>> edges, sides = boundary_sides(square)
    >>> sorted(sides.tolist())  # left, right, bottom, top
    [1, 2, 3, 4]
    """
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise MeshFormatError("boundary_sides needs a 2-D triangle mesh")
    edges = boundary_edges(mesh.cells)
    points = mesh.points
    box = _box(points, bbox)
    if tolerance is None:
        lengths = np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)
        tolerance = 0.01 * float(np.median(lengths)) if len(lengths) else 0.0
    sides = np.full(len(edges), BOUNDARY_IDS["boundary"], dtype=np.int64)
    ends = points[edges]  # (b, 2 ends, 2 coordinates)
    for name, axis, value in (
        ("left", 0, box[0, 0]),
        ("right", 0, box[1, 0]),
        ("bottom", 1, box[0, 1]),
        ("top", 1, box[1, 1]),
    ):
        on = np.all(np.abs(ends[:, :, axis] - value) <= tolerance, axis=1)
        sides[on] = BOUNDARY_IDS[name]
    return edges, sides


def _regions(mesh, velocity_model, tolerance):
    """Region id of each cell: "pad" where the centroid lies outside the model's interior box."""
    regions = np.full(mesh.n_cells, REGION_IDS["model"], dtype=np.int64)
    if velocity_model is None or not any(velocity_model.pad):
        return regions
    inner = velocity_model.interior_bbox
    centroids = mesh.points[mesh.cells].mean(axis=1)
    outside = np.any((centroids < inner[0] - tolerance) | (centroids > inner[1] + tolerance), axis=1)
    regions[outside] = REGION_IDS["pad"]
    return regions


def _velocity_model(model):
    from ..seismic.velocity import VelocityModel

    if model is None or isinstance(model, VelocityModel):
        return model
    inner = getattr(model, "model", None)  # a SeismicSize carries its (padded) velocity model
    if isinstance(inner, VelocityModel):
        return inner
    raise MeshFormatError(f"model must be a VelocityModel or a SeismicSize, got {type(model).__name__}")


def _write_msh(path, points, cells, edges, sides, regions, velocity, velocity_on, velocity_name):
    n_points, n_edges, n_cells = len(points), len(edges), len(cells)
    names = [(1, sid, name) for name, sid in BOUNDARY_IDS.items() if np.any(sides == sid)]
    names += [(2, rid, name) for name, rid in REGION_IDS.items() if np.any(regions == rid)]
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
        f.write(f"$PhysicalNames\n{len(names)}\n")
        f.writelines(f'{dim} {tag} "{name}"\n' for dim, tag, name in names)
        f.write("$EndPhysicalNames\n")
        f.write(f"$Nodes\n{n_points}\n")
        table = np.column_stack([np.arange(1, n_points + 1), points, np.zeros(n_points)])
        np.savetxt(f, table, fmt=["%d", "%.17g", "%.17g", "%d"])
        f.write("$EndNodes\n")
        f.write(f"$Elements\n{n_edges + n_cells}\n")
        # elm-number elm-type(1 line, 2 triangle) number-of-tags physical elementary node-numbers...
        lines = np.column_stack(
            [np.arange(1, n_edges + 1), np.full(n_edges, 1), np.full(n_edges, 2), sides, sides, edges + 1]
        )
        np.savetxt(f, lines, fmt="%d")
        triangles = np.column_stack(
            [
                np.arange(n_edges + 1, n_edges + n_cells + 1),
                np.full(n_cells, 2),
                np.full(n_cells, 2),
                regions,
                regions,
                cells + 1,
            ]
        )
        np.savetxt(f, triangles, fmt="%d")
        f.write("$EndElements\n")
        if velocity is not None:
            section = "NodeData" if velocity_on == "vertices" else "ElementData"
            first, last = (1, n_points) if velocity_on == "vertices" else (n_edges + 1, n_edges + n_cells)
            ids = np.arange(first, last + 1)
            f.write(f'${section}\n1\n"{velocity_name}"\n1\n0.0\n3\n0\n1\n{len(ids)}\n')
            np.savetxt(f, np.column_stack([ids, velocity]), fmt=["%d", "%.9g"])
            f.write(f"$End{section}\n")


def _write_meshio(path, file_format, mesh, points, regions, velocity, velocity_on, velocity_name):
    import meshio

    if file_format == "vtu":
        points = np.column_stack([points, np.zeros(len(points))])
    point_data = {name: np.asarray(values).copy() for name, values in mesh.point_data.items()}
    cell_data = {"region": [regions.astype(np.int32)]}
    if velocity is not None:
        if velocity_on == "vertices":
            point_data[velocity_name] = velocity
        else:
            cell_data[velocity_name] = [velocity]
    output = meshio.Mesh(points, [("triangle", mesh.cells.copy())], point_data=point_data, cell_data=cell_data)
    getattr(meshio, file_format).write(os.fspath(path), output)


def write_fwi_mesh(
    path,
    mesh,
    model=None,
    velocity_on="vertices",
    *,
    file_format=None,
    units="m",
    coordinate_order="xz",
    velocity_name="velocity",
    bbox=None,
):
    """Write a 2-D mesh for a full-waveform-inversion code, with boundary tags and the velocity alongside.

    Gmsh 2.2 files (``.msh``) carry the boundary as line elements tagged by
    side, ids as in :data:`BOUNDARY_IDS` and named in ``$PhysicalNames``
    (Firedrake reads them as the markers of ``ds(id)``), and the triangles
    tagged by region (:data:`REGION_IDS`: 2 marks the padding layer of a
    padded model, e.g. for a damping term). The velocity goes in a
    ``$NodeData`` view, or an ``$ElementData`` view of the triangles
    (meshio 5.3 cannot read the latter back, a bug in its reader; Gmsh
    does). VTU and XDMF files get the
    triangles, a ``region`` cell array and the velocity (point or cell
    data), plus the mesh's own point data.

    Parameters
    ----------
    path : str or os.PathLike
        ``.msh``, ``.vtu`` or ``.xdmf`` (or give ``file_format``).
    mesh : Mesh
        A 2-D triangle mesh in the ``(x, z)`` frame, metres, z negative downward.
    model : VelocityModel or SeismicSize, optional
        The velocity (m/s) to sample at the vertices or cell centroids
        (linear interpolation on its grid); a SeismicSize gives its padded
        model, so the layer's velocities follow the pad style. Without it
        no velocity is written.
    velocity_on : {"vertices", "cells"}, optional
        One value per vertex, or per cell (at its centroid).
    file_format : {"gmsh22", "vtu", "xdmf"}, optional
        By default from the file name.
    units : {"m", "km"}, optional
        ``"km"`` writes coordinates in km and velocities in km/s (spyro's
        examples use these); metres and m/s by default.
    coordinate_order : {"xz", "zx"}, optional
        The order of the coordinates in the file; ``"zx"`` is the layout
        of spyro and SeismicMesh. Boundary ids keep their meaning (side
        names) either way.
    velocity_name : str, optional
        Name of the velocity field.
    bbox : array_like, shape (2, 2), optional
        The box whose sides tag the boundary, ``[[xmin, zmin], [xmax,
        zmax]]`` metres; by default the model's box, else the mesh's extent.

    Raises
    ------
    MeshFormatError
        For an unknown format, units or ordering, a 3-D mesh, or a bad model.

    Examples
    --------
    >>> import os, tempfile, numpy as np, terramesh as tm
    >>> from terramesh.seismic import read_velocity
    >>> model = read_velocity(np.full((3, 5), 1500.0), spacing=(100.0, 50.0), axis_order="zx")
    >>> mesh = tm.generate_mesh(model.domain, 60.0)
    >>> path = os.path.join(tempfile.mkdtemp(), "model.msh")
    >>> write_fwi_mesh(path, mesh, model)
    >>> import pathlib
    >>> '1 4 "top"' in pathlib.Path(path).read_text()
    True
    """
    path = os.fspath(path)
    if file_format is None:
        extension = os.path.splitext(path)[1].lower()
        if extension not in _FORMATS:
            raise MeshFormatError(f"cannot tell the format of {path!r}; use one of {sorted(_FORMATS)} or file_format")
        file_format = _FORMATS[extension]
    if file_format not in _FORMATS.values():
        raise MeshFormatError(f"unknown FWI mesh format {file_format!r}; known: {sorted(_FORMATS.values())}")
    if velocity_on not in ("vertices", "cells"):
        raise MeshFormatError(f"velocity_on must be 'vertices' or 'cells', got {velocity_on!r}")
    if units not in _UNITS:
        raise MeshFormatError(f"units must be 'm' or 'km', got {units!r}")
    if coordinate_order not in ("xz", "zx"):
        raise MeshFormatError(f"coordinate_order must be 'xz' or 'zx', got {coordinate_order!r}")
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise MeshFormatError("write_fwi_mesh writes 2-D triangle meshes for now")
    velocity_model = _velocity_model(model)
    if velocity_model is not None and velocity_model.dim != 2:
        raise MeshFormatError("the velocity model of a 2-D mesh must be 2-D")
    box = velocity_model.bbox if bbox is None and velocity_model is not None else bbox
    edges, sides = boundary_sides(mesh, box)
    lengths = np.linalg.norm(mesh.points[edges[:, 0]] - mesh.points[edges[:, 1]], axis=1)
    regions = _regions(mesh, velocity_model, 0.01 * float(np.median(lengths)))
    velocity = None
    if velocity_model is not None:
        where = mesh.points if velocity_on == "vertices" else mesh.points[mesh.cells].mean(axis=1)
        velocity = velocity_model(where) / _UNITS[units]
    points = mesh.points / _UNITS[units]
    if coordinate_order == "zx":
        points = points[:, ::-1]
    points = np.ascontiguousarray(points)
    if file_format == "gmsh22":
        _write_msh(path, points, mesh.cells, edges, sides, regions, velocity, velocity_on, velocity_name)
    else:
        _write_meshio(path, file_format, mesh, points, regions, velocity, velocity_on, velocity_name)
