"""The mesh container: points, cells and what travels with them."""

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from ..errors import MeshFormatError, MeshValidityError
from .boundaries import check_boundary_nodes
from .columns import rows_all

__all__ = ["Mesh", "GEOGRAPHIC_CRS", "DEGREES_SLACK", "normalized_crs"]

GEOGRAPHIC_CRS = frozenset({"EPSG:4326", "OGC:CRS84", "CRS84", "WGS84", "LONLAT"})
"""Longitude-latitude names known without asking pyproj (upper case); any other CRS pyproj decides."""

DEGREES_SLACK = 1e-6
"""Degrees by which a geographic mesh's coordinates may pass longitude -360..360 and latitude -90..90.

Room for the rounding of reprojected coordinates (a pole at 90.0000000001);
metres labelled degrees miss the ranges by thousands.
"""


@lru_cache(maxsize=64)
def _pyproj_geographic(crs):
    """Whether pyproj reads the string ``crs`` as longitude, latitude; MeshValidityError if it cannot read it.

    Cached: a parse takes 0.2-8 ms, and ``Mesh.geographic`` is asked in
    every quality and time-step measure.
    """
    import pyproj

    try:
        return pyproj.CRS.from_user_input(crs).is_geographic
    except pyproj.exceptions.CRSError:
        raise MeshValidityError(
            f"crs {crs!r} is no coordinate reference system pyproj can read; give one such as "
            "'EPSG:4326' (longitude, latitude degrees) or 'EPSG:32633' (UTM metres), or None for planar coordinates"
        ) from None


def _check_degrees(points, crs):
    """Refuse coordinates that cannot be longitude, latitude degrees for a geographic ``crs``: MeshValidityError.

    UTM metres labelled ``"EPSG:4326"`` were taken (latitudes of 3.3e6), and
    every measure after was nonsense: 260 of 523 cells inverted, a Courant
    number 300 times too small, an hgrid.ll of metres. ``points`` are finite
    ``(n, dim)`` float64, x longitude and y latitude. The extremes of both
    columns at once (1.1 ms at 10**6 points) decide where every coordinate
    lies in -90..90 (most coasts from 90 W to 90 E); elsewhere the
    latitudes' own extremes are needed too (another 1.5 ms; the four
    column extremes took 4 ms).
    """
    if len(points) == 0 or crs is None or not (crs.upper() in GEOGRAPHIC_CRS or _pyproj_geographic(crs)):
        return
    both = points[:, :2]
    low, high = both.min(), both.max()
    if low >= -90.0 - DEGREES_SLACK and high <= 90.0 + DEGREES_SLACK:
        return
    y = points[:, 1]
    if low >= -360.0 - DEGREES_SLACK and high <= 360.0 + DEGREES_SLACK:
        if y.min() >= -90.0 - DEGREES_SLACK and y.max() <= 90.0 + DEGREES_SLACK:
            return
    x = points[:, 0]
    raise MeshValidityError(
        f"crs {crs!r} is longitude, latitude degrees, but the points span x {x.min():.7g}..{x.max():.7g}, "
        f"y {y.min():.7g}..{y.max():.7g}, outside longitude -360..360, latitude -90..90: coordinates in metres "
        "labelled degrees? give the mesh's own CRS (a UTM zone such as 'EPSG:32615', or the projection it was "
        "made in), or None for planar coordinates"
    )


def normalized_crs(crs):
    """``crs`` as a :class:`Mesh` keeps it: a string without surrounding blanks, or None.

    An EPSG code (``4326``) or a ``pyproj.CRS`` becomes its authority
    string (``"EPSG:4326"``); a string is kept as given, stripped.

    Raises
    ------
    MeshValidityError
        For an empty string, a string pyproj cannot read, or anything that is
        no reference system (a float, a bool, a list).

    Examples
    --------
    >>> normalized_crs(4326), normalized_crs(" EPSG:32633 "), normalized_crs(None)
    ('EPSG:4326', 'EPSG:32633', None)
    """
    if crs is None:
        return None
    if isinstance(crs, str):
        text = crs.strip()
        if not text:
            raise MeshValidityError("crs is an empty string: give None for planar coordinates")
        if text.upper() not in GEOGRAPHIC_CRS:
            _pyproj_geographic(text)  # refuses what pyproj cannot read, which would count as planar
        return text
    import pyproj

    # True is the EPSG code 1 to pyproj; a float code is a mistake too
    if not isinstance(crs, (bool, np.bool_, float, np.floating)):
        try:
            return pyproj.CRS.from_user_input(crs).to_string()
        except (pyproj.exceptions.CRSError, TypeError, ValueError):
            pass
    raise MeshValidityError(
        f"crs must be a string such as 'EPSG:4326', an EPSG code or a pyproj.CRS, or None; got {crs!r}"
    )


@dataclass(eq=False)
class Mesh:
    """An unstructured simplicial mesh.

    Parameters
    ----------
    points : numpy.ndarray, shape (n, dim)
        Vertex coordinates (float64), ``dim`` 2 or 3, in the units
        of the domain they were generated on (for geographic meshes:
        longitude, latitude in degrees).
    cells : numpy.ndarray, shape (m, dim + 1)
        Vertex indices (int64, 0 to ``n - 1``) of each cell: triangles
        ``(m, 3)``, counter-clockwise, for 2-D points; tetrahedra
        ``(m, 4)``, positively oriented, for 3-D points. Triangles with 3-D
        points (a surface, as read from a file) are accepted too, but most
        tools refuse them.
    point_data : dict of str to numpy.ndarray, optional
        Per-vertex arrays, e.g. ``"depth"`` (metres, positive down) for ADCIRC.
    boundaries : terramesh.io.fort14.Boundaries, optional
        ADCIRC-style open and land boundary node strings: 0-based vertex
        numbers, whole, ``0 .. n - 1``.
    title : str, optional
        Free text written to file headers (e.g. the fort.14 grid name).
    crs : str, int or pyproj.CRS, optional
        Coordinate reference system of ``points``, e.g. ``"EPSG:4326"`` for
        longitude-latitude degrees; None for plain planar units. Kept as a
        string (:func:`normalized_crs`): ``4326`` and
        ``pyproj.CRS("EPSG:4326")`` become ``"EPSG:4326"``, on assignment
        too. A longitude-latitude ``crs`` needs x in -360..360 and y in
        -90..90.
    info : dict, optional
        How the mesh was made: iterations, why generation stopped, timings;
        for a mesh read from a file, ``crs_guessed``: whether the reader
        guessed ``crs`` from the coordinates' ranges (the file keeps none).

    Raises
    ------
    MeshValidityError
        For arrays of the wrong shape (tetrahedra with 2-D points among
        them), NaN or infinite coordinates, cells or boundaries that refer
        to vertices that do not exist, ``point_data`` values that are not
        one value (or row) per point, a
        ``crs`` that is no reference system pyproj can read, or a
        longitude-latitude ``crs`` (given or assigned) for coordinates
        outside longitude -360..360 or latitude -90..90 (metres labelled
        degrees; :data:`DEGREES_SLACK` of rounding allowed).

    Examples
    --------
    >>> import numpy as np
    >>> mesh = Mesh(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), np.array([[0, 1, 2]]))
    >>> mesh.n_points, mesh.n_cells, mesh.dim
    (3, 1, 2)
    """

    points: np.ndarray
    cells: np.ndarray
    point_data: dict = field(default_factory=dict)
    boundaries: object = None
    title: str = "terramesh"
    crs: str | None = None
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        try:
            self.points = np.ascontiguousarray(self.points, dtype=np.float64)
        except (TypeError, ValueError):
            raise MeshValidityError("points must be numbers") from None
        cells = np.asarray(self.cells)
        if cells.size and cells.dtype.kind not in "iu":
            # cast, [0, 1, 2.9] became [0, 1, 2]: another cell than the one given
            whole = cells.dtype.kind == "f" and np.all(cells == np.round(cells))
            if not whole:
                raise MeshValidityError(f"cells must be integer vertex indices, got {cells.dtype} values")
        self.cells = np.ascontiguousarray(cells, dtype=np.int64)
        if self.points.ndim != 2 or self.points.shape[1] not in (2, 3):
            raise MeshValidityError(f"points must have shape (n, 2) or (n, 3), got {self.points.shape}")
        finite = np.isfinite(self.points)
        if not finite.all():
            finite = rows_all(finite)
            raise MeshValidityError(
                f"coordinates are NaN or infinite at {int(np.sum(~finite))} of {len(finite)} points "
                f"(index {int(np.argmin(finite))} first)"
            )
        _check_degrees(self.points, self.crs)
        if self.cells.ndim != 2 or self.cells.shape[1] not in (3, 4):
            raise MeshValidityError(f"cells must have shape (m, 3) or (m, 4), got {self.cells.shape}")
        if self.cells.shape[1] > self.dim + 1:
            raise MeshValidityError(
                f"cells of {self.cells.shape[1]} corners need {self.cells.shape[1] - 1}-D points, "
                f"got {self.dim}-D points: cells must have shape (m, dim + 1)"
            )
        if self.cells.size and (self.cells.min() < 0 or self.cells.max() >= len(self.points)):
            raise MeshValidityError("cells refer to vertices that do not exist")
        if not isinstance(self.point_data, Mapping):
            raise MeshValidityError(
                f"point_data must be a dict of name to per-point array, got a {type(self.point_data).__name__}"
            )
        for name, values in self.point_data.items():
            try:
                shape = np.shape(values)
            except ValueError:  # a ragged list
                shape = None
            if not shape or shape[0] != len(self.points):
                got = "a ragged sequence" if shape is None else f"shape {shape}"
                raise MeshValidityError(
                    f"point_data[{name!r}] must hold one value per point, shape ({len(self.points)},) or "
                    f"({len(self.points)}, k); got {got} (one value everywhere: numpy.full(n_points, value))"
                )
        check_boundaries(self.boundaries, len(self.points))
        self._built = True

    def __setattr__(self, name, value):
        # the crs is checked and normalised when assigned after construction too (coastal.build sets it);
        # while the constructor assigns it the points are not yet checked: __post_init__ measures them then
        if name == "crs":
            value = normalized_crs(value)
            if self.__dict__.get("_built"):
                _check_degrees(np.asarray(self.points, dtype=np.float64), value)
        super().__setattr__(name, value)

    def __add__(self, other):
        """``a + b``: :func:`terramesh.coastal.merge`, ``a`` keeping the overlap."""
        from ..coastal.merge import mesh_add

        return mesh_add(self, other)

    @property
    def depth(self):
        """Depth per vertex, metres, positive down (``point_data["depth"]``), or None."""
        return self.point_data.get("depth")

    @property
    def geographic(self):
        """True when the points are longitude, latitude in degrees: ``crs`` is geographic to pyproj (EPSG:4269 too)."""
        return self.crs is not None and (self.crs.upper() in GEOGRAPHIC_CRS or _pyproj_geographic(self.crs))

    @property
    def dim(self):
        """Number of space dimensions (2 or 3)."""
        return self.points.shape[1]

    @property
    def n_points(self):
        """Number of vertices."""
        return len(self.points)

    @property
    def n_cells(self):
        """Number of cells."""
        return len(self.cells)

    def write(self, path, file_format=None):
        """Write the mesh to ``path``; the format follows the file name unless given.

        See :func:`terramesh.io.write_mesh` for the formats.
        """
        from ..io import write_mesh

        write_mesh(path, self, file_format=file_format)

    def __repr__(self):
        return f"<terramesh.Mesh: {self.n_points} vertices, {self.n_cells} cells, {self.dim}D>"


def guess_crs(points):
    """``"EPSG:4326"`` when every point lies in longitude [-180, 360], latitude [-90, 90]; else None.

    Examples
    --------
    >>> import numpy as np
    >>> guess_crs(np.array([[-75.5, 38.0], [300.0, -60.0]])), guess_crs(np.array([[5e5, 4.3e6]]))
    ('EPSG:4326', None)
    """
    if len(points) == 0:
        return None
    x, y = points[:, 0], points[:, 1]
    inside = x.min() >= -180.0 and x.max() <= 360.0 and y.min() >= -90.0 and y.max() <= 90.0
    return "EPSG:4326" if inside else None


def check_boundaries(boundaries, n_points):
    """Refuse ADCIRC boundaries whose node strings name vertices the mesh lacks (the fort.14 writer's check).

    Node 99 on a mesh of 25 vertices was taken, and ``renumber`` failed with a
    bare IndexError. Objects that are no boundaries (without ``open`` and
    ``land`` lists) are not looked into.
    """
    if not (hasattr(boundaries, "open") and hasattr(boundaries, "land")):
        return
    try:
        check_boundary_nodes(boundaries, n_points)
    except MeshFormatError as error:
        raise MeshValidityError(
            f"boundaries do not fit the mesh: {error}; boundary nodes are 0-based vertex numbers of this mesh"
        ) from None
