"""ADCIRC nodal attributes from a mesh: OceanMesh2D's ``Calc_tau0`` and ``Calc_IT_Fric`` (guide §6.6).

Both functions return a :class:`~terramesh.mesh.NodalAttribute` ready
for :func:`~terramesh.io.fort13.write_fort13` under its ADCIRC name, its
default (the fort.13 ``DefaultAttrVal``) the value most nodes take, so that
the file lists the fewest nodes, e.g.
``write_fort13("fort.13", {"primitive_weighting_in_continuity_equation":
tau0(mesh)}, mesh.n_points)``. Renumbering the mesh afterwards? Carry the
attributes along with ``attribute.renumbered(mesh.info["renumber"]["new_index"])``,
or compute them after :func:`~terramesh.coastal.renumber`.
"""

import numbers

import numpy as np

from ..errors import GeometryError, MeshValidityError
from ..mesh.nodal_attributes import NodalAttribute
from ..mesh.topology import unique_edges
from .bathymetry import check_outside
from .projection import EARTH_RADIUS
from .timestep import checked_mesh, depth_of, edge_lengths, is_geographic

__all__ = ["tau0", "internal_tide_friction", "M2_FREQUENCY", "EARTH_ROTATION"]

M2_FREQUENCY = 2.0 * np.pi / (12.4206012 * 3600.0)
"""Angular frequency of the M2 tide, rad/s."""

EARTH_ROTATION = 7.29212e-5
"""Angular velocity of the Earth, rad/s (the Coriolis parameter is ``2 Omega sin(lat)``)."""


def _number(name, value, *, positive=False):
    if not isinstance(value, numbers.Real) or isinstance(value, bool) or not np.isfinite(value):
        raise MeshValidityError(f"{name} must be a finite number, got {value!r}")
    if positive and value <= 0:
        raise MeshValidityError(f"{name} must be positive, got {value!r}")
    return float(value)


def _negative_tau0(values):
    """The one negative value of ``tau0`` (ADCIRC's flag), the fort.13 default whatever its count; else None.

    ADCIRC (``InitNodalAttr`` in ``nodalattr.F``) sets every node whose
    ``tau0`` is negative from its hard-coded depth scheme numbered by the
    default when the default is negative, and leaves negative values as they
    are otherwise: a negative value means "ADCIRC's scheme" only as the
    default, and only one scheme can be the default.
    """
    negative = np.unique(values[values < 0])
    if len(negative) > 1:
        raise MeshValidityError(
            f"tau0 takes negative values {negative.tolist()}: ADCIRC reads a negative tau0 as the flag of one of its"
            " depth schemes, and only the default's scheme applies; give at most one negative value"
        )
    return negative if len(negative) else None


def tau0(
    mesh,
    *,
    depth_cutoff=10.0,
    distance_cutoff=2000.0,
    default=0.03,
    shallow=0.02,
    deep=0.005,
    geographic=None,
):
    """Primitive weighting in the continuity equation (ADCIRC's ``tau0``) from depth and spacing.

    OceanMesh2D's ``Calc_tau0`` rule (its default ``-3`` option): ``tau0``
    is ``default`` (0.03) where the mesh is fine, and where the mean length
    of the edges at a vertex exceeds ``distance_cutoff`` (2 km) it is
    ``shallow`` (0.02) in water up to ``depth_cutoff`` (10 m) deep and
    ``deep`` (0.005) in deeper water. Edge lengths are in ground metres
    (great-circle for longitude-latitude meshes).

    The attribute's default value (the fort.13 ``DefaultAttrVal``) is the
    value most nodes take, so that the file lists the fewest nodes: on a
    mesh coarser than ``distance_cutoff`` almost everywhere that is
    ``deep``, not ``default`` (OceanMesh2D's name for the fine-mesh value).
    A negative value is ADCIRC's flag for its hard-coded depth schemes
    (``TAU0 = -1``, ``-2``), which ADCIRC applies to the nodes left
    negative only when the default is negative: the negative value, if
    any, is then the default, whatever its count. Ties go to ``default``.

    Parameters
    ----------
    mesh : Mesh
        A 2D triangle mesh with ``mesh.depth`` (metres, positive down).
    depth_cutoff : float, optional
        Metres.
    distance_cutoff : float, optional
        Metres.
    default, shallow, deep : float, optional
        The three values of ``tau0`` (1/s as ADCIRC reads them; the file
        says ``unitless``, as ADCIRC's documentation does); at most one of
        the values taken may be negative (see above).
    geographic : bool, optional
        Points are longitude, latitude degrees; by default from ``mesh.crs``.

    Returns
    -------
    NodalAttribute
        One value per node, for ``primitive_weighting_in_continuity_equation``.

    Raises
    ------
    MeshValidityError
        For a mesh without depth, bad options, or two different negative
        values taken.

    References
    ----------
    OceanMesh2D, ``utilities/Calc_tau0.m`` (W. Pringle, 2018),
    https://github.com/CHLNDDEV/OceanMesh2D; ADCIRC fort.13 documentation,
    ``primitive_weighting_in_continuity_equation``; ADCIRC's ``TAU0``
    documentation and ``src/nodalattr.F`` (``InitNodalAttr``) for the
    negative default.

    Examples
    --------
    A strip of 3 km cells, 5 m deep on its western fifth and 50 m beyond:
    every node is coarse, most are deep, and the default is ``deep``.

    >>> import numpy as np, terramesh as tm
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (30e3, 6e3)), 3e3)
    >>> mesh.point_data["depth"] = np.where(mesh.points[:, 0] < 6e3, 5.0, 50.0)
    >>> attribute = tau0(mesh)
    >>> attribute.default.tolist(), sorted(set(attribute.values.ravel().tolist()))
    ([0.005], [0.005, 0.02])
    >>> int(attribute.non_default.sum()) == int(np.sum(attribute.values == 0.02))
    True
    """
    mesh = checked_mesh(mesh, "tau0")
    depth = depth_of(mesh)
    depth_cutoff = _number("depth_cutoff", depth_cutoff)
    distance_cutoff = _number("distance_cutoff", distance_cutoff, positive=True)
    default, shallow, deep = (_number(n, v) for n, v in (("default", default), ("shallow", shallow), ("deep", deep)))
    edges = unique_edges(mesh.cells)
    lengths = edge_lengths(mesh.points, edges, geographic=is_geographic(mesh, geographic))
    total = np.bincount(edges.ravel(), weights=np.repeat(lengths, 2), minlength=mesh.n_points)
    count = np.bincount(edges.ravel(), minlength=mesh.n_points)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, total / count, 0.0)
    values = np.full(mesh.n_points, default)
    coarse = mean > distance_cutoff
    values[coarse & (depth <= depth_cutoff)] = shallow
    values[coarse & (depth > depth_cutoff)] = deep
    return NodalAttribute.from_values(values, default=_negative_tau0(values), prefer=default)


def _buoyancy_grid(grid):
    """``(lon, lat, seabed, mean)`` checked: axes increasing, values (nx, ny) non-negative or NaN."""
    try:
        parts = tuple(grid)
    except TypeError:
        raise GeometryError("buoyancy_grid must be (lon, lat, N) or (lon, lat, N_seabed, N_mean)") from None
    if len(parts) not in (3, 4):
        raise GeometryError(f"buoyancy_grid must have 3 or 4 parts (lon, lat, N[, N_mean]), got {len(parts)}")
    lon, lat = (np.asarray(axis, dtype=np.float64) for axis in parts[:2])
    for name, axis in (("longitudes", lon), ("latitudes", lat)):
        if axis.ndim != 1 or len(axis) < 2 or not np.all(np.isfinite(axis)) or np.any(np.diff(axis) <= 0):
            raise GeometryError(f"buoyancy_grid {name} must be a strictly increasing 1-D array of 2 or more values")
    fields = []
    for name, values in zip(("N", "N_mean"), parts[2:], strict=False):
        values = np.asarray(values, dtype=np.float64)
        if values.shape != (len(lon), len(lat)):
            raise GeometryError(
                f"buoyancy_grid {name} has shape {values.shape}, expected (nx, ny) = ({len(lon)}, {len(lat)})"
            )
        if np.any(values[np.isfinite(values)] < 0):
            raise GeometryError(f"buoyancy_grid {name} must be >= 0 (rad/s)")
        if not np.isfinite(values).any():
            raise GeometryError(f"buoyancy_grid {name} has no finite value")
        fields.append(values)
    return lon, lat, fields[0], fields[1] if len(fields) == 2 else fields[0]


def _on_grid(lon, lat, values, x, y):
    """Bilinear interpolation of ``values[ix, iy]`` at ``(x, y)``; where that is NaN, the nearest finite node."""
    from scipy.interpolate import RegularGridInterpolator
    from scipy.spatial import cKDTree

    inside_x, inside_y = np.clip(x, lon[0], lon[-1]), np.clip(y, lat[0], lat[-1])
    result = RegularGridInterpolator((lon, lat), values, bounds_error=False)(np.column_stack([inside_x, inside_y]))
    missing = ~np.isfinite(result)
    if missing.any():
        gx, gy = np.meshgrid(lon, lat, indexing="ij")
        valid = np.isfinite(values)
        _, nearest = cKDTree(np.column_stack([gx[valid], gy[valid]])).query(
            np.column_stack([inside_x[missing], inside_y[missing]])
        )
        result[missing] = values[valid][nearest]
    return result


def _depth_gradient(mesh, depth):
    """Gradient of the depth at each vertex, ``(dh/dx, dh/dy)`` per ground metre (east, north), shape (n, 2).

    The gradient of the linear interpolant on each cell, in local ground
    metres (east ``R cos(lat) dlon``, north ``R dlat`` at the cell's
    centroid), averaged over the cells around the vertex, weighted by area.
    """
    cells = mesh.cells
    lon, lat = np.radians(mesh.points[:, 0]), np.radians(mesh.points[:, 1])
    shrink = np.cos(lat[cells].mean(axis=1))
    x = EARTH_RADIUS * (lon[cells] - lon[cells[:, :1]]) * shrink[:, None]
    y = EARTH_RADIUS * (lat[cells] - lat[cells[:, :1]])
    h = depth[cells]
    det = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
    dx = ((h[:, 1] - h[:, 0]) * (y[:, 2] - y[:, 0]) - (h[:, 2] - h[:, 0]) * (y[:, 1] - y[:, 0])) / det
    dy = ((x[:, 1] - x[:, 0]) * (h[:, 2] - h[:, 0]) - (x[:, 2] - x[:, 0]) * (h[:, 1] - h[:, 0])) / det
    area = 0.5 * np.abs(det)
    weight = np.bincount(cells.ravel(), weights=np.repeat(area, 3), minlength=mesh.n_points)
    gradient = np.column_stack(
        [
            np.bincount(cells.ravel(), weights=np.repeat(area * dx, 3), minlength=mesh.n_points),
            np.bincount(cells.ravel(), weights=np.repeat(area * dy, 3), minlength=mesh.n_points),
        ]
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(weight[:, None] > 0, gradient / weight[:, None], 0.0)


def internal_tide_friction(
    mesh,
    buoyancy_grid,
    *,
    coefficient=0.2,
    cutoff_depth=100.0,
    frequency=M2_FREQUENCY,
    criticality=True,
):
    """Internal tide friction tensor from a buoyancy-frequency grid, OceanMesh2D's ``Calc_IT_Fric`` (local_dir).

    For each vertex (Pringle et al. 2018's local, directional scheme):

    * ``N_b`` (sea bed) and ``N_m`` (depth mean) buoyancy frequencies are
      interpolated from the grid (bilinear; where the grid has NaN, the
      nearest finite node);
    * ``F = C sqrt((N_b^2 - w^2)(N_m^2 - w^2)) / w`` with ``C`` the
      ``coefficient`` and ``w`` the tidal ``frequency`` (0 where the product
      is negative);
    * with ``criticality``, ``F`` is divided by ``max(|grad h|^2 / a^2, 1)``,
      ``a^2 = (w^2 - f^2) / (N_b^2 - w^2)`` (``f = 2 Omega sin(lat)``), and set
      to 0 where ``a^2 < 0``;
    * ``F = 0`` where the depth is below ``cutoff_depth`` or the bed is flat.

    The three values per node are ``F h_x^2, F h_y^2, F h_x h_y`` (1/s),
    ``h_x, h_y`` the depth gradient (east, north, per ground metre) of the
    mesh's depth: the area-weighted mean of the gradients of the cells
    around the vertex (OceanMesh2D takes it from the DEM, averaged over the
    vertex's cell; the mesh's depth, from :func:`interpolate_bathymetry`, is
    that average already).

    Parameters
    ----------
    mesh : Mesh
        A 2D triangle mesh in longitude, latitude with ``mesh.depth``
        (metres, positive down).
    buoyancy_grid : tuple
        ``(lon, lat, N)`` or ``(lon, lat, N_seabed, N_mean)``: increasing
        axes (degrees, shapes (nx,), (ny,)) and buoyancy frequencies, rad/s,
        shape ``(nx, ny)`` indexed ``[ix, iy]``; NaN where unknown (land).
        With one field it is used for both ``N_b`` and ``N_m``.
    coefficient : float, optional
        ``C_it`` (0.2, OceanMesh2D's default).
    cutoff_depth : float, optional
        Metres: no internal tide friction in shallower water (100 m).
    frequency : float, optional
        Tidal frequency, rad/s (M2).
    criticality : bool, optional
        Normalise by the slope criticality (OceanMesh2D's ``'crit','Nb'``).

    Returns
    -------
    NodalAttribute
        Three values per node, units ``1/s``, for ``internal_tide_friction``;
        the default is the row most nodes take, ``(0, 0, 0)`` (shallow or
        flat) where no other row is taken by more nodes.

    Raises
    ------
    GeometryError
        For a malformed grid.
    MeshValidityError
        For a mesh without depth, not in degrees, or bad options.

    References
    ----------
    W. J. Pringle, D. Wirasaet, A. Suhardjo, J. Meixner, J. J. Westerink,
    A. B. Kennedy and S. Nong, "Finite-element barotropic model for the
    Indian and Western Pacific Oceans: Tidal model-data comparisons and
    sensitivities", Ocean Modelling 129, 2018,
    https://doi.org/10.1016/j.ocemod.2018.07.003; OceanMesh2D,
    ``utilities/Calc_IT_Fric.m``; ADCIRC fort.13 documentation,
    ``internal_tide_friction``.

    Examples
    --------
    A sloping shelf (200 m to 2200 m over 2 degrees) under uniform
    stratification ``N = 2e-3`` rad/s:

    >>> import numpy as np, terramesh as tm
    >>> mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 40), (2, 41)), 0.25)
    >>> mesh.crs = "EPSG:4326"
    >>> mesh.point_data["depth"] = 200.0 + 1000.0 * mesh.points[:, 0]
    >>> grid = (np.array([-1.0, 3.0]), np.array([39.0, 42.0]), np.full((2, 2), 2e-3))
    >>> friction = internal_tide_friction(mesh, grid)
    >>> friction.values.shape[1], friction.units
    (3, '1/s')
    >>> bool(np.all(friction.values[:, 0] > 0)), bool(np.allclose(friction.values[:, 1:], 0, atol=1e-12))
    (True, True)
    """
    mesh = checked_mesh(mesh, "internal_tide_friction")
    if mesh.crs is not None and not mesh.geographic:
        raise MeshValidityError(f"the mesh is in {mesh.crs}; internal_tide_friction needs longitude, latitude")
    (x_min, y_min), (x_max, y_max) = mesh.points.min(axis=0), mesh.points.max(axis=0)
    if y_min < -90.0 or y_max > 90.0 or x_min < -360.0 or x_max > 720.0:
        raise MeshValidityError(
            f"the mesh's points (x {x_min:g}..{x_max:g}, y {y_min:g}..{y_max:g}) are not longitude, latitude"
            " degrees, which internal_tide_friction needs"
        )
    depth = depth_of(mesh)
    coefficient = _number("coefficient", coefficient)
    cutoff_depth = _number("cutoff_depth", cutoff_depth)
    frequency = _number("frequency", frequency, positive=True)
    lon, lat, seabed, mean = _buoyancy_grid(buoyancy_grid)
    x = mesh.points[:, 0].copy()
    # the mesh's longitudes moved by a whole turn when that puts them on the grid
    for turn in (-360.0, 360.0):
        move = ((x < lon[0]) | (x > lon[-1])) & (x + turn >= lon[0]) & (x + turn <= lon[-1])
        x[move] += turn
    y = mesh.points[:, 1]
    # beyond the outermost nodes by more than a cell, as for a DEM
    dx, dy = lon[1] - lon[0], lat[1] - lat[0]
    outside = (x < lon[0] - dx) | (x > lon[-1] + dx) | (y < lat[0] - dy) | (y > lat[-1] + dy)
    extent = (lon[0], lon[-1], lat[0], lat[-1])
    check_outside(
        outside, mesh.points, "vertices", "the buoyancy grid", extent, "take its frequencies at its nearest edge"
    )
    n_b = _on_grid(lon, lat, seabed, x, y)
    n_m = n_b if mean is seabed else _on_grid(lon, lat, mean, x, y)
    w2 = frequency**2
    friction = coefficient * np.sqrt(np.maximum((n_b**2 - w2) * (n_m**2 - w2), 0.0)) / frequency
    gradient = _depth_gradient(mesh, depth)
    slope2 = np.sum(gradient**2, axis=1)
    if criticality:
        f2 = (2.0 * EARTH_ROTATION * np.sin(np.radians(y))) ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            alpha2 = (w2 - f2) / (n_b**2 - w2)
            gamma2 = np.maximum(np.where(alpha2 > 0, slope2 / alpha2, 0.0), 1.0)
        friction = np.where(alpha2 < 0, 0.0, friction / gamma2)
    friction = np.where((depth < cutoff_depth) | (slope2 == 0), 0.0, friction)
    hx, hy = gradient[:, 0], gradient[:, 1]
    # + 0.0 turns the -0.0 of a zero friction times a negative hx hy into 0.0: one zero row, written "0"
    values = np.column_stack([friction * hx**2, friction * hy**2, friction * hx * hy]) + 0.0
    return NodalAttribute.from_values(values, units="1/s", prefer=np.zeros(3))
