"""Mesh files for full-waveform-inversion codes, with boundary tags and velocities alongside.

========================  ==========  ==============================================================
file name                 format      what is in it
========================  ==========  ==============================================================
``*.msh``                 Gmsh 2.2    ASCII; cells (triangles, or tetrahedra in 3-D) tagged by
                                      region, boundary facets (lines, or triangles in 3-D) tagged by
                                      side and oriented outward, both named in ``$PhysicalNames``;
                                      velocity as ``$NodeData`` or ``$ElementData``: what Firedrake
                                      (and so spyro) reads
``*.vtu``                 VTU         the cells, ``region`` cell data, velocity (meshio)
``*.xdmf``                XDMF+HDF5   the same (meshio)
========================  ==========  ==============================================================

Boundary sides take the ids of Firedrake's ``RectangleMesh`` in 2-D and
``BoxMesh`` in 3-D; a boundary facet on none of the box's sides (a domain
that is not a box) gets the last id, "boundary":

==  ============================  =============================
id  2-D (:data:`BOUNDARY_IDS`)    3-D (:data:`BOUNDARY_IDS_3D`)
==  ============================  =============================
1   ``left``: x min               ``x_min``
2   ``right``: x max              ``x_max``
3   ``bottom``: z min             ``y_min``
4   ``top``: z max, free surface  ``y_max``
5   ``boundary``: any other       ``bottom``: z min
6                                 ``top``: z max, free surface
7                                 ``boundary``: any other
==  ============================  =============================

Cells get region 1, "model", or 2, "pad" where they lie in the padding
(sponge) layer of a padded velocity model (:data:`REGION_IDS`). Every file
says its coordinates are planar (``terramesh:crs`` null, see
:mod:`terramesh.io.meshio_formats`), so that :func:`terramesh.read_mesh`
does not take a model a few kilometres across, written in km, for
longitude and latitude.
"""

import itertools
import os

import numpy as np

from .._kernels.cleanup import facet_census
from ..cleanup.validity import census_facets, problems_and_lone_facets
from ..errors import MeshFormatError, MeshValidityError, checked_number
from ..mesh.topology import cell_centroids, checked_cells
from ..seismic.model import unit_mismatch
from ._text import write_rows, written_whole
from .fort14 import refuse_non_finite
from .gmsh import write_gmsh_view
from .meshio_formats import gmsh_crs_section, store_crs, writable_point_data

__all__ = [
    "BOUNDARY_IDS",
    "BOUNDARY_IDS_3D",
    "REGION_IDS",
    "BOX_SHARE",
    "boundary_sides",
    "write_fwi_mesh",
    "fwi_format_from_name",
]

BOUNDARY_IDS = {"left": 1, "right": 2, "bottom": 3, "top": 4, "boundary": 5}
"""Physical ids of a 2-D mesh's boundary lines by side (Firedrake's RectangleMesh numbering, 5 for any other)."""

BOUNDARY_IDS_3D = {"x_min": 1, "x_max": 2, "y_min": 3, "y_max": 4, "bottom": 5, "top": 6, "boundary": 7}
"""Physical ids of a 3-D mesh's boundary triangles by side (Firedrake's BoxMesh numbering, 7 for any other)."""

REGION_IDS = {"model": 1, "pad": 2}
"""Physical ids of the cells: inside the velocity model, or in its padding layer."""

# Side k lies on axis k // 2, at the box's lower end for even k and its upper end for odd k.
_SIDES = {2: ("left", "right", "bottom", "top"), 3: ("x_min", "x_max", "y_min", "y_max", "bottom", "top")}
_IDS = {2: BOUNDARY_IDS, 3: BOUNDARY_IDS_3D}
_AXES = {2: "xz", 3: "xyz"}
_ORDERS = {dim: tuple("".join(order) for order in itertools.permutations(axes)) for dim, axes in _AXES.items()}
_FORMATS = {".msh": "gmsh22", ".vtu": "vtu", ".xdmf": "xdmf"}
_UNITS = {"m": 1.0, "km": 1000.0}
_GMSH_TYPES = {2: (1, 2), 3: (2, 4)}  # (facet, cell) element types: line, triangle; triangle, tetrahedron
_MESHIO_TYPES = {2: "triangle", 3: "tetra"}


BOX_SHARE = 0.5
"""Least share of their union that the mesh's extent and the box it is tagged against (the model's) must share.

A mesh in km written against a model in m shares a millionth of the
model's box: every vertex read the model's corner velocity, and the sides
away from the corner were tagged "boundary". A mesh of part of a model is
written with ``bbox``, its own box.
"""


def _dimension(mesh, who):
    """The mesh's dimension, checked: simplices of that dimension, at least one cell, finite coordinates."""
    if mesh.cells.shape[1] != mesh.dim + 1:
        raise MeshFormatError(
            f"{who} needs a 2-D triangle or a 3-D tetrahedral mesh, got {mesh.cells.shape[1]}-corner cells "
            f"in {mesh.dim}-D"
        )
    if mesh.n_cells == 0:
        raise MeshFormatError(f"{who} needs a mesh with at least one cell, got none")
    refuse_non_finite(mesh.points, f"{who}: the point coordinates are")
    return mesh.dim


def _box(points, bbox, dim):
    if bbox is None:
        return np.array([points.min(axis=0), points.max(axis=0)])
    box = np.asarray(bbox, dtype=np.float64)
    if box.shape != (2, dim) or not np.all(np.isfinite(box)) or np.any(box[1] <= box[0]):
        names = "[[xmin, zmin], [xmax, zmax]]" if dim == 2 else "[[xmin, ymin, zmin], [xmax, ymax, zmax]]"
        raise MeshFormatError(f"bbox of a {dim}-D mesh must be {names}, got {np.asarray(bbox).tolist()}")
    return box


def _boundary_facets(points, cells, lone=None):
    """Facets of exactly one cell, shape ``(b, dim)``, ordered so their normal points out of the domain.

    ``lone``: those facets as :func:`~terramesh._kernels.cleanup.facet_census` numbers them, where a
    check found them already. The orientation comes from the geometry rather than from the cells'
    vertex order, so cells of either orientation give outward facets.
    """
    corners = cells.shape[1]
    if lone is None:  # the kernel reads without bounds checks: a vertex number out of range is refused first
        lone = np.flatnonzero(facet_census(points, checked_cells(cells, corners, len(points)))[0])
    facets, owner, corner = census_facets(cells, lone)
    opposite = cells[owner, corner]
    # outward exactly when the simplex (opposite vertex, facet...) is positively oriented
    frames = points[facets] - points[opposite][:, None, :]
    inward = np.linalg.det(frames) < 0
    facets[inward, :2] = facets[inward, 1::-1]
    return facets


def _facet_length(points, facets):
    """Median edge length of the facets, the scale of the tolerances."""
    if not len(facets):
        return 0.0
    corners = points[facets]
    return float(np.median(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2)))


def boundary_sides(mesh, bbox=None, *, tolerance=None):
    """The boundary facets of a mesh and the side of the box each lies on.

    Facets are the edges of a 2-D triangle mesh and the triangular faces of
    a 3-D tetrahedral mesh that belong to exactly one cell. A facet lies on
    a side when all its vertices are within ``tolerance`` of that side's
    line (plane).

    Parameters
    ----------
    mesh : Mesh
        A valid 2-D triangle mesh, coordinates ``(x, z)``, or a 3-D
        tetrahedral mesh, ``(x, y, z)``; z up.
    bbox : array_like, shape (2, dim), optional
        The box ``[[xmin, zmin], [xmax, zmax]]`` (3-D: ``[[xmin, ymin, zmin],
        [xmax, ymax, zmax]]``), mesh units; the mesh's own extent by default.
    tolerance : float, optional
        Mesh units, finite and >= 0; 1 % of the median boundary facet edge
        by default.

    Returns
    -------
    facets : ndarray, shape (b, dim), int64
        Vertex indices of each facet, oriented outward: edges run
        counter-clockwise around the domain (clockwise around holes), and
        triangles are counter-clockwise seen from outside.
    sides : ndarray, shape (b,), int64
        :data:`BOUNDARY_IDS` (2-D) or :data:`BOUNDARY_IDS_3D` (3-D) value of each facet.

    Raises
    ------
    MeshFormatError
        For a mesh that is neither, has no cells or a NaN or infinite
        coordinate, a bad ``bbox`` or a bad ``tolerance``.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.mesh import Mesh
    >>> square = Mesh(np.array([[0.0, -1], [1, -1], [1, 0], [0, 0]]), np.array([[0, 1, 2], [0, 2, 3]]))
    >>> edges, sides = boundary_sides(square)
    >>> sorted(sides.tolist())  # left, right, bottom, top
    [1, 2, 3, 4]
    >>> tetrahedron = Mesh(np.array([[0.0, 0, -1], [1, 0, -1], [0, 1, -1], [0, 0, 0]]), np.array([[0, 1, 2, 3]]))
    >>> faces, sides = boundary_sides(tetrahedron)
    >>> sorted(sides.tolist())  # x min, y min, bottom, and the slanted face
    [1, 3, 5, 7]
    """
    dim = _dimension(mesh, "boundary_sides")
    if tolerance is not None:
        tolerance = checked_number(tolerance, "tolerance must be a finite number >= 0", MeshFormatError, minimum=0)
    points = mesh.points
    facets = _boundary_facets(points, mesh.cells)
    box = _box(points, bbox, dim)
    if tolerance is None:
        tolerance = 0.01 * _facet_length(points, facets)
    return facets, _sides(points, facets, box, tolerance)


def _sides(points, facets, box, tolerance):
    """The side id of each facet: the side of ``box`` all its corners are within ``tolerance`` of, else "boundary"."""
    dim = points.shape[1]
    ids = _IDS[dim]
    sides = np.full(len(facets), ids["boundary"], dtype=np.int64)
    corners = points[facets]  # (b, dim corners, dim coordinates)
    for k, name in enumerate(_SIDES[dim]):
        axis, end = divmod(k, 2)
        on = np.all(np.abs(corners[:, :, axis] - box[end, axis]) <= tolerance, axis=1)
        sides[on] = ids[name]
    return sides


def _regions(mesh, velocity_model, tolerance):
    """Region id of each cell: "pad" where the centroid lies outside the model's interior box."""
    regions = np.full(mesh.n_cells, REGION_IDS["model"], dtype=np.int64)
    if velocity_model is None or not any(velocity_model.pad):
        return regions
    inner = velocity_model.interior_bbox
    centroids = cell_centroids(mesh.points, mesh.cells)
    outside = np.any((centroids < inner[0] - tolerance) | (centroids > inner[1] + tolerance), axis=1)
    regions[outside] = REGION_IDS["pad"]
    return regions


def _extent(box):
    """``"x 0..2400, z -1600..0"``: a box ``(2, dim)`` as a message names it."""
    return ", ".join(f"{axis} {low:.6g}..{high:.6g}" for axis, low, high in zip(_AXES[box.shape[1]], *box, strict=True))


def _units_hint(mesh_box, box, what):
    """Why the mesh's extent is about 1000 times ``box``'s (or a thousandth) on every axis, or ``""``."""
    mismatch = unit_mismatch(mesh_box, box)
    if mismatch == "km":
        return (
            f"; the mesh is about 1/1000 of {what}: a mesh in km with a model in m? give the mesh in metres "
            "(tm.Mesh(mesh.points * 1000, mesh.cells)); units='km' writes the file in km"
        )
    if mismatch == "m":
        return (
            f"; the mesh is about 1000 times {what}: a model in km (its spacing) with a mesh in m? read the model "
            "with its spacing in metres"
        )
    return ""


def _check_extents(mesh, velocity_model, bbox, tolerance):
    """Refuse a mesh that is not on the box its sides are tagged against, or not within its velocity model.

    With a model: the mesh must lie within the model's box (outside it the
    velocity is the edge's, and the padding gets no region) and, unless
    ``bbox`` gives its own box, share :data:`BOX_SHARE` of their union with
    it; extents 1000 times apart (km against m) are refused with or without
    ``bbox``. With ``bbox``: the mesh's extent must be that box, to
    ``tolerance``, or its sides are tagged against lines the boundary is
    not on (the free surface of a mesh in metres tagged "bottom" against
    ``[[0, 0], [1, 1]]``).
    """
    mesh_box = np.array([mesh.points.min(axis=0), mesh.points.max(axis=0)])
    if velocity_model is not None:
        box = velocity_model.bbox
        what = f"the velocity model's box ({_extent(box)}, metres)"
        hint = _units_hint(mesh_box, box, "the model's extent")
        beyond = float(np.max(np.maximum(box[0] - mesh_box[0], mesh_box[1] - box[1])))
        if beyond > 1e-6 * float(np.max(box[1] - box[0])):
            padded = " (the padding of a size function)" if not any(velocity_model.pad) else ""
            raise MeshFormatError(
                f"the mesh reaches {beyond:.4g} m beyond the velocity model's box{padded}: the mesh spans "
                f"{_extent(mesh_box)}, {what}"
                + (
                    hint
                    or "; pass the size function (size_function's result), whose model is padded, or the model the "
                    "mesh was made for"
                )
            )
        overlap = np.prod(np.minimum(box[1], mesh_box[1]) - np.maximum(box[0], mesh_box[0]))
        union = np.prod(np.maximum(box[1], mesh_box[1]) - np.minimum(box[0], mesh_box[0]))
        if overlap < BOX_SHARE * union and (bbox is None or hint):
            raise MeshFormatError(
                f"the mesh ({_extent(mesh_box)}) and {what} share {100 * overlap / union:.3g} % of their union, "
                f'less than {100 * BOX_SHARE:g} %: its sides off the model\'s box would be tagged "boundary"'
                + (
                    hint
                    or "; pass the model (or size function) the mesh was made for, or, for a mesh of part of the "
                    "model, bbox= the mesh's own box"
                )
            )
    if bbox is not None:
        # the mesh within the box, spanning most of it on every axis: a top that follows topography is below the
        # model's top (the default box), so its own box is not asked for
        beyond = float(np.max(np.maximum(bbox[0] - mesh_box[0], mesh_box[1] - bbox[1])))
        spans = float(np.min((mesh_box[1] - mesh_box[0]) / np.maximum(bbox[1] - bbox[0], np.finfo(float).tiny)))
        if beyond > tolerance or spans < BOX_SHARE:
            off = f"beyond it by up to {beyond:.4g}" if beyond > tolerance else f"{100 * spans:.3g} % of it on an axis"
            raise MeshFormatError(
                f"bbox ({_extent(bbox)}) is not the box of the mesh, which spans {_extent(mesh_box)} ({off}"
                "): its sides would be tagged against lines the boundary is not on; give the mesh's own box, "
                "in the mesh's units, or leave bbox out"
            )


def _velocity_model(model):
    from ..seismic.velocity import KM_PER_S_BELOW, VelocityModel

    if model is not None and not isinstance(model, VelocityModel):
        model = getattr(model, "model", model)  # a SeismicSize carries its (padded) velocity model
        if not isinstance(model, VelocityModel):
            raise MeshFormatError(f"model must be a VelocityModel or a SeismicSize, got {type(model).__name__}")
    if model is not None and model.vmax < KM_PER_S_BELOW:  # the file's velocity would be 1000 times too slow
        raise MeshFormatError(
            f"the model's velocities are {model.vmin:g}..{model.vmax:g}, which look like km/s; a model holds m/s "
            "(units='km' converts the file): read it with units='km/s' (read_velocity) or multiply the values by 1000"
        )
    return model


def _write_msh(path, points, cells, facets, sides, regions, velocity, velocity_on, velocity_name):
    dim = points.shape[1]
    n_points, n_facets, n_cells = len(points), len(facets), len(cells)
    facet_type, cell_type = _GMSH_TYPES[dim]
    names = [(dim - 1, sid, name) for name, sid in _IDS[dim].items() if np.any(sides == sid)]
    names += [(dim, rid, name) for name, rid in REGION_IDS.items() if np.any(regions == rid)]
    with written_whole(path) as temporary, open(temporary, "w", encoding="ascii", newline="\n") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
        f.write(f"$PhysicalNames\n{len(names)}\n")
        f.writelines(f'{tag_dim} {tag} "{name}"\n' for tag_dim, tag, name in names)
        f.write("$EndPhysicalNames\n")
        f.write(f"$Nodes\n{n_points}\n")
        table = np.column_stack([np.arange(1, n_points + 1), points, np.zeros((n_points, 3 - dim))])
        write_rows(f, table, fmt=["%d"] + ["%.17g"] * 3)
        f.write("$EndNodes\n")
        f.write(f"$Elements\n{n_facets + n_cells}\n")
        # elm-number elm-type number-of-tags physical elementary node-numbers...
        boundary = np.column_stack(
            [np.arange(1, n_facets + 1), np.full(n_facets, facet_type), np.full(n_facets, 2), sides, sides, facets + 1]
        )
        write_rows(f, boundary, fmt="%d")
        interior = np.column_stack(
            [
                np.arange(n_facets + 1, n_facets + n_cells + 1),
                np.full(n_cells, cell_type),
                np.full(n_cells, 2),
                regions,
                regions,
                cells + 1,
            ]
        )
        write_rows(f, interior, fmt="%d")
        f.write("$EndElements\n")
        if velocity is not None:
            section = "NodeData" if velocity_on == "vertices" else "ElementData"
            first, last = (1, n_points) if velocity_on == "vertices" else (n_facets + 1, n_facets + n_cells)
            write_gmsh_view(f, section, velocity_name, np.arange(first, last + 1), velocity, fmt="%.9g")
        f.write(gmsh_crs_section(None))  # planar: not longitude, latitude, whatever the coordinates' range


def _write_meshio(path, file_format, mesh, points, cells, regions, velocity, velocity_on, velocity_name):
    import meshio

    if points.shape[1] == 2 and file_format == "vtu":
        points = np.column_stack([points, np.zeros(len(points))])
    point_data = writable_point_data(mesh)
    cell_data = {"region": [regions.astype(np.int32)]}
    if velocity is not None:
        if velocity_on == "vertices":
            point_data[velocity_name] = velocity
        else:
            cell_data[velocity_name] = [velocity]
    output = meshio.Mesh(points, [(_MESHIO_TYPES[mesh.dim], cells)], point_data=point_data, cell_data=cell_data)
    with written_whole(path) as temporary:
        getattr(meshio, file_format).write(temporary, output)
        store_crs(temporary, file_format, None)  # planar: not longitude, latitude, whatever the coordinates' range


def fwi_format_from_name(path):
    """The FWI file format (``"gmsh22"``, ``"vtu"`` or ``"xdmf"``) a file name says; MeshFormatError if none.

    Examples
    --------
    >>> fwi_format_from_name("marmousi.msh"), fwi_format_from_name("model.vtu")
    ('gmsh22', 'vtu')
    """
    path = os.fspath(path)
    extension = os.path.splitext(path)[1].lower()
    if extension not in _FORMATS:
        raise MeshFormatError(
            f"cannot tell the FWI format of {path!r}: FWI meshes are written as {', '.join(sorted(_FORMATS))}"
        )
    return _FORMATS[extension]


def write_fwi_mesh(
    path,
    mesh,
    model=None,
    velocity_on="vertices",
    *,
    file_format=None,
    units="m",
    coordinate_order=None,
    velocity_name="velocity",
    bbox=None,
):
    """Write a 2-D or 3-D mesh for a full-waveform-inversion code, with boundary tags and the velocity alongside.

    Gmsh 2.2 files (``.msh``) carry the boundary as facet elements (lines in
    2-D, triangles in 3-D, oriented outward) tagged by side, ids as in
    :data:`BOUNDARY_IDS` (2-D, Firedrake's ``RectangleMesh``) or
    :data:`BOUNDARY_IDS_3D` (3-D, Firedrake's ``BoxMesh``) and named in
    ``$PhysicalNames`` (Firedrake reads them as the markers of ``ds(id)``),
    and the cells (triangles, tetrahedra) tagged by region
    (:data:`REGION_IDS`: 2 marks the padding layer of a padded model, e.g.
    for a damping term). The velocity goes in a ``$NodeData`` view, or an
    ``$ElementData`` view of the cells (meshio 5.3 cannot read the latter
    back, a bug in its reader; Gmsh does). VTU and XDMF files get the
    cells, a ``region`` cell array and the velocity (point or cell data),
    plus the mesh's own point data. The cells, positively oriented (a
    valid mesh, :func:`~terramesh.cleanup.mesh_problems`), stay so, and
    boundary facets point outward, in the file's own coordinate order
    (a mirroring order such as ``"zx"`` swaps two corners of each). The
    inputs are not modified.

    Parameters
    ----------
    path : str or os.PathLike
        ``.msh``, ``.vtu`` or ``.xdmf`` (or give ``file_format``).
    mesh : Mesh
        A valid 2-D triangle mesh in the ``(x, z)`` frame or a 3-D
        tetrahedral mesh in ``(x, y, z)``; metres, z negative downward.
    model : VelocityModel or SeismicSize, optional
        The velocity (m/s) to sample at the vertices or cell centroids
        (bi- or trilinear interpolation on its grid), of the mesh's
        dimension; a SeismicSize gives its padded model, so the layer's
        velocities follow the pad style. Without it no velocity is written.
        The mesh must lie within the model's box and, without ``bbox``,
        cover :data:`BOX_SHARE` of it (the model the mesh was made for).
    velocity_on : {"vertices", "cells"}, optional
        One value per vertex, or per cell (at its centroid).
    file_format : {"gmsh22", "vtu", "xdmf"}, optional
        By default from the file name.
    units : {"m", "km"}, optional
        ``"km"`` writes coordinates in km and velocities in km/s (spyro's
        examples use these); metres and m/s by default.
    coordinate_order : str, optional
        The order of the coordinates in the file: ``"xz"`` (the default in
        2-D) or ``"zx"``; in 3-D ``"xyz"`` (the default) or any other order
        of the three letters, e.g. ``"zxy"``. ``"zx"`` and ``"zxy"`` are the
        layouts of spyro and SeismicMesh. Boundary ids keep their meaning
        (side names) in any order.
    velocity_name : str, optional
        Name of the velocity field.
    bbox : array_like, shape (2, dim), optional
        The box whose sides tag the boundary, ``[[xmin, zmin], [xmax,
        zmax]]`` (3-D: ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]``) metres;
        by default the model's box, else the mesh's extent. Given (for a
        mesh of part of a model, its own box), it must hold the mesh (to 1 %
        of a boundary facet) and the mesh must span at least
        :data:`BOX_SHARE` of it on every axis.

    Raises
    ------
    MeshFormatError
        For an unknown format, units or ordering, a mesh that is neither
        2-D triangles nor 3-D tetrahedra or has no cells, a model that is
        not a velocity model, one whose dimension is not the mesh's or
        whose velocities look like km/s (all below 20); a mesh reaching beyond the model's box, or (without ``bbox``)
        covering less than :data:`BOX_SHARE` of it, or about 1/1000 of it
        (km against m); a ``bbox`` that is not the mesh's extent; and for a
        NaN or infinite coordinate or (VTU, XDMF) point data value. No file
        is written then.
    MeshValidityError
        For a mesh :func:`~terramesh.cleanup.mesh_problems` finds invalid
        (overlaps and hanging nodes are not looked for): clockwise
        (inverted) or flat cells, a repeated corner, cells that do not fit
        edge to edge (face to face), unused or duplicate vertices. Repair a
        2-D mesh with :func:`~terramesh.cleanup.fix_mesh`.

    Examples
    --------
    >>> import os, pathlib, tempfile, numpy as np, terramesh as tm
    >>> from terramesh.seismic import VelocityModel, read_velocity
    >>> folder = tempfile.mkdtemp()
    >>> model = read_velocity(np.full((3, 5), 1500.0), spacing=(100.0, 50.0), axis_order="zx")
    >>> mesh = tm.generate_mesh(model.domain, 60.0)
    >>> write_fwi_mesh(os.path.join(folder, "model.msh"), mesh, model)
    >>> '1 4 "top"' in pathlib.Path(folder, "model.msh").read_text()
    True

    A 3-D model in SeismicMesh's layout, (z, x, y), in km with velocities in km/s:

    >>> model = VelocityModel(np.full((3, 3, 3), 2000.0), ([0.0, 200, 400], [0.0, 150, 300], [-300.0, -150, 0]))
    >>> box = tm.generate_mesh(tm.geometry.Box(*model.bbox), 150.0)
    >>> write_fwi_mesh(os.path.join(folder, "box.msh"), box, model, units="km", coordinate_order="zxy")
    >>> '2 6 "top"' in pathlib.Path(folder, "box.msh").read_text()
    True
    """
    path = os.fspath(path)
    if file_format is None:
        try:
            file_format = fwi_format_from_name(path)
        except MeshFormatError as error:
            raise MeshFormatError(f"{error} or file_format") from None
    if file_format not in _FORMATS.values():
        raise MeshFormatError(f"unknown FWI mesh format {file_format!r}; known: {sorted(_FORMATS.values())}")
    if velocity_on not in ("vertices", "cells"):
        raise MeshFormatError(f"velocity_on must be 'vertices' or 'cells', got {velocity_on!r}")
    if units not in _UNITS:
        raise MeshFormatError(f"units must be 'm' or 'km', got {units!r}")
    dim = _dimension(mesh, "write_fwi_mesh")
    if file_format != "gmsh22":  # the mesh's own point data goes in VTU and XDMF files
        for name, values in mesh.point_data.items():
            values = np.asarray(values)
            if values.dtype.kind == "f":
                refuse_non_finite(values, f"point_data[{name!r}] is")
    order = _AXES[dim] if coordinate_order is None else coordinate_order
    if order not in _ORDERS[dim]:
        raise MeshFormatError(
            f"coordinate_order of a {dim}-D mesh must be one of {', '.join(_ORDERS[dim])}; got {coordinate_order!r}"
        )
    velocity_model = _velocity_model(model)
    if velocity_model is not None and velocity_model.dim != dim:
        raise MeshFormatError(f"a {dim}-D mesh needs a {dim}-D velocity model, got a {velocity_model.dim}-D one")
    if bbox is not None:
        bbox = _box(mesh.points, bbox, dim)
    problems, lone = problems_and_lone_facets(mesh, None, None, overlaps=False, hanging_nodes=False)
    if problems:
        repair = (
            "repair it first with terramesh.cleanup.fix_mesh(mesh)"
            if dim == 2
            else "generate it again, or turn inverted tetrahedra positive (swap two corners of each) and drop flat ones"
        )
        # FWI codes take the cells as given: a clockwise cell's Jacobian is negative, a flat cell's singular
        raise MeshValidityError(f"write_fwi_mesh needs a valid mesh: {'; '.join(problems)}; {repair}")
    facets = _boundary_facets(mesh.points, mesh.cells, lone)
    tolerance = 0.01 * _facet_length(mesh.points, facets)
    _check_extents(mesh, velocity_model, bbox, tolerance)
    if bbox is None:
        bbox = _box(mesh.points, None, dim) if velocity_model is None else velocity_model.bbox
    sides = _sides(mesh.points, facets, bbox, tolerance)
    regions = _regions(mesh, velocity_model, tolerance)
    velocity = None
    if velocity_model is not None:
        where = mesh.points if velocity_on == "vertices" else cell_centroids(mesh.points, mesh.cells)
        velocity = velocity_model(where) / _UNITS[units]
    permutation = [_AXES[dim].index(axis) for axis in order]
    points = np.ascontiguousarray(mesh.points[:, permutation] / _UNITS[units])
    cells = mesh.cells.copy()
    inversions = sum(a > b for a, b in itertools.combinations(permutation, 2))
    if inversions % 2:
        # an odd permutation of the axes mirrors the mesh; swapping two corners keeps cells positive and facets outward
        cells[:, :2] = cells[:, 1::-1]
        facets[:, :2] = facets[:, 1::-1]
    if file_format == "gmsh22":
        _write_msh(path, points, cells, facets, sides, regions, velocity, velocity_on, velocity_name)
    else:
        _write_meshio(path, file_format, mesh, points, cells, regions, velocity, velocity_on, velocity_name)
