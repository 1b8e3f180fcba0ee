"""Measures of single tetrahedra for the kernels that work on tetrahedral meshes (sliver removal, smoothing).

Private and unvalidated: ``points`` (n, 3) float64, corners as vertex
indices. :mod:`terramesh.quality.tetra` has the public, validated measures;
its tests check these against textbook references.
"""

import numba
import numpy as np


@numba.njit(cache=True, inline="always")
def _cross(ux, uy, uz, vx, vy, vz):
    return uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx


@numba.njit(cache=True, inline="always")
def face_normal(points, a, b, c):
    """The normal ``(b - a) x (c - a)`` of the face ``a, b, c`` of 3-D ``points``, twice the face's area long."""
    return _cross(
        points[b, 0] - points[a, 0],
        points[b, 1] - points[a, 1],
        points[b, 2] - points[a, 2],
        points[c, 0] - points[a, 0],
        points[c, 1] - points[a, 1],
        points[c, 2] - points[a, 2],
    )


@numba.njit(cache=True, inline="always")
def edges_and_normals(points, a, b, c, d):
    """The edges ``b - a``, ``c - a``, ``d - a`` and the inward area normals of the faces opposite b, c, d.

    Returned flat: the three edges' and then the three normals' components,
    18 numbers; each normal's length is twice its face's area. Six times
    the volume is ``(b - a) . n_b``; the normal of the face opposite ``a``
    is minus their sum.
    """
    ax, ay, az = points[a, 0], points[a, 1], points[a, 2]
    bx, by, bz = points[b, 0] - ax, points[b, 1] - ay, points[b, 2] - az
    cx, cy, cz = points[c, 0] - ax, points[c, 1] - ay, points[c, 2] - az
    dx, dy, dz = points[d, 0] - ax, points[d, 1] - ay, points[d, 2] - az
    n1x, n1y, n1z = _cross(cx, cy, cz, dx, dy, dz)
    n2x, n2y, n2z = _cross(dx, dy, dz, bx, by, bz)
    n3x, n3y, n3z = _cross(bx, by, bz, cx, cy, cz)
    return bx, by, bz, cx, cy, cz, dx, dy, dz, n1x, n1y, n1z, n2x, n2y, n2z, n3x, n3y, n3z


@numba.njit(cache=True)
def tet_largest_cosine(points, a, b, c, d):
    """Cosine of the smallest dihedral angle of the tetrahedron ``a, b, c, d``; 2.0 when it is not positive."""
    bx, by, bz, cx, cy, cz, dx, dy, dz, n1x, n1y, n1z, n2x, n2y, n2z, n3x, n3y, n3z = edges_and_normals(
        points, a, b, c, d
    )
    return largest_cosine_from_normals(dx, dy, dz, n1x, n1y, n1z, n2x, n2y, n2z, n3x, n3y, n3z)


@numba.njit(cache=True, inline="always")
def largest_cosine_from_normals(dx, dy, dz, n1x, n1y, n1z, n2x, n2y, n2z, n3x, n3y, n3z):
    """:func:`tet_largest_cosine` from the tetrahedron's :func:`edges_and_normals`."""
    # inward area normals of the faces opposite a, b, c, d (they sum to zero)
    volume = n3x * dx + n3y * dy + n3z * dz
    if not volume > 0.0:
        return 2.0
    n0x, n0y, n0z = -(n1x + n2x + n3x), -(n1y + n2y + n3y), -(n1z + n2z + n3z)
    l0 = np.sqrt(n0x * n0x + n0y * n0y + n0z * n0z)
    l1 = np.sqrt(n1x * n1x + n1y * n1y + n1z * n1z)
    l2 = np.sqrt(n2x * n2x + n2y * n2y + n2z * n2z)
    l3 = np.sqrt(n3x * n3x + n3y * n3y + n3z * n3z)
    if l0 == 0.0 or l1 == 0.0 or l2 == 0.0 or l3 == 0.0:
        return 1.0
    # the dihedral angle at the edge shared by the faces opposite k and l: cos = -n_k . n_l / (|n_k| |n_l|)
    largest = -(n0x * n1x + n0y * n1y + n0z * n1z) / (l0 * l1)
    largest = max(largest, -(n0x * n2x + n0y * n2y + n0z * n2z) / (l0 * l2))
    largest = max(largest, -(n0x * n3x + n0y * n3y + n0z * n3z) / (l0 * l3))
    largest = max(largest, -(n1x * n2x + n1y * n2y + n1z * n2z) / (l1 * l2))
    largest = max(largest, -(n1x * n3x + n1y * n3y + n1z * n3z) / (l1 * l3))
    largest = max(largest, -(n2x * n3x + n2y * n3y + n2z * n3z) / (l2 * l3))
    return min(largest, 1.0)


@numba.njit(cache=True, inline="always")
def tet_radius_ratio(points, a, b, c, d):
    """:func:`radius_ratio` of the tetrahedron ``a, b, c, d``: negative when inverted, 0 when flat."""
    bx, by, bz, cx, cy, cz, dx, dy, dz, n1x, n1y, n1z, n2x, n2y, n2z, n3x, n3y, n3z = edges_and_normals(
        points, a, b, c, d
    )
    six_volume = bx * n1x + by * n1y + bz * n1z
    n0x, n0y, n0z = n1x + n2x + n3x, n1y + n2y + n3y, n1z + n2z + n3z
    areas = 0.5 * (
        np.sqrt(n0x * n0x + n0y * n0y + n0z * n0z)
        + np.sqrt(n1x * n1x + n1y * n1y + n1z * n1z)
        + np.sqrt(n2x * n2x + n2y * n2y + n2z * n2z)
        + np.sqrt(n3x * n3x + n3y * n3y + n3z * n3z)
    )
    bb = bx * bx + by * by + bz * bz
    cc = cx * cx + cy * cy + cz * cz
    dd = dx * dx + dy * dy + dz * dz
    lx = bb * n1x + cc * n2x + dd * n3x
    ly = bb * n1y + cc * n2y + dd * n3y
    lz = bb * n1z + cc * n2z + dd * n3z
    lifted = np.sqrt(lx * lx + ly * ly + lz * lz)
    if not (areas > 0.0 and lifted > 0.0):
        return 0.0
    # 3 r_in / r_circ = 3 (3 V / A) (12 V / |lifted|) = 108 V^2 / (A |lifted|), V = six_volume / 6
    return 3.0 * six_volume * abs(six_volume) / (areas * lifted)


@numba.njit(cache=True)
def radius_ratio_all(points, cells):
    """:func:`tet_radius_ratio` of every cell, shape (m,)."""
    out = np.empty(cells.shape[0])
    for t in range(cells.shape[0]):
        out[t] = tet_radius_ratio(points, cells[t, 0], cells[t, 1], cells[t, 2], cells[t, 3])
    return out


@numba.njit(cache=True)
def _tet_min_dihedral(points, a, b, c, d):
    """Smallest dihedral angle (degrees) of the tetrahedron ``a, b, c, d``; -1 when it is not positively oriented."""
    cosine = tet_largest_cosine(points, a, b, c, d)
    if cosine > 1.0:
        return -1.0
    return np.degrees(np.arccos(cosine))


@numba.njit(cache=True)
def min_dihedral_all(points, cells):
    """:func:`_tet_min_dihedral` of every cell, shape (m,)."""
    out = np.empty(cells.shape[0])
    for t in range(cells.shape[0]):
        out[t] = _tet_min_dihedral(points, cells[t, 0], cells[t, 1], cells[t, 2], cells[t, 3])
    return out


@numba.njit(cache=True)
def volumes_all(points, cells):
    """Signed volume of every cell, ``(b - a) . ((c - a) x (d - a)) / 6``, shape (m,).

    One pass: NumPy's gathers, ``cross`` and ``einsum`` took 65 ms for a
    378k-cell mesh, this 4 ms (the sums may round differently, by 1e-17 of
    a unit cube's volume).
    """
    out = np.empty(cells.shape[0])
    for t in range(cells.shape[0]):
        bx, by, bz, _, _, _, _, _, _, n1x, n1y, n1z, _, _, _, _, _, _ = edges_and_normals(
            points, cells[t, 0], cells[t, 1], cells[t, 2], cells[t, 3]
        )
        out[t] = (bx * n1x + by * n1y + bz * n1z) / 6.0
    return out
