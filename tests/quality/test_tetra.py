import numpy as np
import pytest

import terramesh as tm
from terramesh._kernels.tetra import min_dihedral_all
from terramesh.quality.tetra import (
    dihedral_angles,
    min_max_dihedral,
    radius_ratio,
    tetra_summary,
    tetra_volumes,
)

REGULAR = np.array([[1.0, 1, 1], [-1, 1, -1], [1, -1, -1], [-1, -1, 1]])  # positively oriented
CORNER = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
ONE = np.array([[0, 1, 2, 3]])


def reference_dihedral(points, cell):
    """Dihedral angles by the textbook route: angle between the two faces' normals seen along the edge."""
    angles = []
    for i, j in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]:
        k, m = (c for c in range(4) if c not in (i, j))
        a, b = points[cell[i]], points[cell[j]]
        axis = (b - a) / np.linalg.norm(b - a)
        u = points[cell[k]] - a
        v = points[cell[m]] - a
        u -= axis * (u @ axis)  # components across the edge
        v -= axis * (v @ axis)
        angles.append(np.degrees(np.arccos(np.clip(u @ v / np.linalg.norm(u) / np.linalg.norm(v), -1, 1))))
    return np.array(angles)


def test_regular_tetrahedron():
    np.testing.assert_allclose(dihedral_angles(REGULAR, ONE), np.degrees(np.arccos(1 / 3)), rtol=1e-12)
    np.testing.assert_allclose(radius_ratio(REGULAR, ONE), 1.0, rtol=1e-12)
    np.testing.assert_allclose(tetra_volumes(REGULAR, ONE), 8 / 3)


def test_corner_tetrahedron():
    smallest, largest = min_max_dihedral(CORNER, ONE)
    np.testing.assert_allclose(smallest, np.degrees(np.arccos(1 / np.sqrt(3))))
    np.testing.assert_allclose(largest, 90.0)
    # r_in = 1 / (3 + sqrt 3), r_circ = sqrt(3) / 2
    np.testing.assert_allclose(radius_ratio(CORNER, ONE), 3 / (3 + np.sqrt(3)) / (np.sqrt(3) / 2))


def test_angles_agree_with_a_textbook_reference_on_random_cells():
    rng = np.random.default_rng(1)
    points = rng.random((60, 3))
    cells = np.array([rng.choice(60, 4, replace=False) for _ in range(300)])
    angles = dihedral_angles(points, cells)
    expected = np.array([reference_dihedral(points, cell) for cell in cells])
    np.testing.assert_allclose(angles, expected, atol=1e-7)


def reference_radius_ratio(points, cell):
    """3 r_in / r_circ by the textbook route: the circumcentre from a linear system, r_in = 3 V / area."""
    a, b, c, d = points[cell]
    edges = np.array([b - a, c - a, d - a])
    centre = np.linalg.solve(2 * edges, np.sum(edges**2, axis=1))  # relative to a
    volume = np.linalg.det(edges) / 6
    faces = [(b, c, d), (a, c, d), (a, b, d), (a, b, c)]
    area = sum(0.5 * np.linalg.norm(np.cross(q - p, r - p)) for p, q, r in faces)
    return 3 * (3 * volume / area) / np.linalg.norm(centre)


def test_radius_ratio_agrees_with_a_textbook_reference_on_random_cells():
    rng = np.random.default_rng(3)
    points = rng.random((60, 3))
    cells = np.array([rng.choice(60, 4, replace=False) for _ in range(300)])
    expected = np.array([reference_radius_ratio(points, cell) for cell in cells])
    np.testing.assert_allclose(radius_ratio(points, cells), expected, rtol=1e-7, atol=1e-12)
    assert np.any(expected < 0)  # inverted cells among them: negative, the same magnitude


def test_numba_kernel_agrees_with_numpy():
    rng = np.random.default_rng(2)
    points = rng.random((80, 3))
    cells = np.array([rng.choice(80, 4, replace=False) for _ in range(500)])
    positive = tetra_volumes(points, cells) > 0
    kernel = min_dihedral_all(points, cells)
    np.testing.assert_allclose(kernel[positive], min_max_dihedral(points, cells[positive])[0], atol=1e-8)
    assert np.all(kernel[~positive] == -1.0)  # the kernel flags cells that are not positive


def test_slivers_and_inverted_cells():
    flat = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 1e-4]])  # four nearly coplanar points
    assert min_max_dihedral(flat, ONE)[0][0] < 0.1
    assert 0 < radius_ratio(flat, ONE)[0] < 1e-3
    mirrored = ONE[:, [0, 2, 1, 3]]
    np.testing.assert_allclose(dihedral_angles(CORNER, mirrored), dihedral_angles(CORNER, ONE)[:, [1, 0, 2, 3, 5, 4]])
    assert tetra_volumes(CORNER, mirrored)[0] < 0
    np.testing.assert_allclose(radius_ratio(CORNER, mirrored), -radius_ratio(CORNER, ONE))


def test_measures_are_scale_and_translation_invariant():
    moved = 1e4 * CORNER + np.array([5e5, -3e5, 2e3])
    np.testing.assert_allclose(dihedral_angles(moved, ONE), dihedral_angles(CORNER, ONE), rtol=1e-9)
    np.testing.assert_allclose(radius_ratio(moved, ONE), radius_ratio(CORNER, ONE), rtol=1e-9)


def test_tetra_summary_of_a_cube_split_in_six():
    cube = np.array([[x, y, z] for x in (0.0, 1) for y in (0.0, 1) for z in (0.0, 1)])
    # Kuhn triangulation along the diagonal 0 -> 7, every cell oriented positively
    cells = np.array([[0, 1, 3, 7], [0, 3, 2, 7], [0, 2, 6, 7], [0, 6, 4, 7], [0, 4, 5, 7], [0, 5, 1, 7]])
    volumes = tetra_volumes(cube, cells)
    cells[volumes < 0] = cells[volumes < 0][:, [1, 0, 2, 3]]
    stats = tetra_summary(tm.Mesh(cube, cells))
    assert stats.n_cells == 6 and stats.n_vertices == 8
    assert stats.n_boundary_faces == 12  # two triangles per cube face
    assert stats.n_inverted == 0 and stats.n_below_10_degrees == 0
    assert stats.min_dihedral == pytest.approx(45.0) and stats.max_dihedral == pytest.approx(90.0)
    assert 0 < stats.min_radius_ratio <= stats.mean_radius_ratio < 1
    assert set(stats.as_dict()) >= {"min_dihedral", "mean_min_dihedral", "mean_radius_ratio"}
    assert "dihedral angles" in str(stats)


def test_tetra_summary_refuses_triangles_and_handles_no_cells():
    triangles = tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="tetrahedra"):
        tetra_summary(triangles)
    empty = tetra_summary(tm.Mesh(CORNER, np.empty((0, 4), dtype=np.int64)))
    assert empty.n_cells == 0 and np.isnan(empty.min_dihedral)


def test_bad_shapes_and_indices_raise_terramesh_errors():
    for call in (tetra_volumes, dihedral_angles, radius_ratio):
        with pytest.raises(tm.errors.MeshValidityError, match=r"\(n, 3\)"):
            call(CORNER[:, :2], ONE)
        with pytest.raises(tm.errors.MeshValidityError, match=r"\(m, 4\)"):
            call(CORNER, ONE[:, :3])
        with pytest.raises(tm.errors.MeshValidityError, match="do not exist"):  # -1 picked the last point
            call(CORNER, np.array([[0, 1, 2, -1]]))
    with pytest.raises(tm.errors.MeshValidityError, match="tetrahedra"):
        tetra_summary(tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([[0, 1, 2]])))


def test_bad_shapes_raise():
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        dihedral_angles(CORNER[:, :2], ONE)
    with pytest.raises(ValueError, match=r"\(m, 4\)"):
        radius_ratio(CORNER, ONE[:, :3])


def test_volumes_agree_with_the_triple_product_and_check_their_input():
    rng = np.random.default_rng(3)
    points = rng.normal(size=(200, 3)) * 1e3
    cells = rng.integers(0, 200, size=(500, 4))
    a, b, c, d = (points[cells[:, k]] for k in range(4))
    reference = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6.0
    volumes = tetra_volumes(points, cells)
    np.testing.assert_allclose(volumes, reference, rtol=1e-12, atol=1e-6)  # 1e-12 of the 1e9 m^3 cells
    assert np.array_equal(volumes > 0, reference > 0)
    with pytest.raises(tm.errors.MeshValidityError, match="do not exist"):
        tetra_volumes(points, np.array([[0, 1, 2, 200]]))


@pytest.mark.parametrize("measure", [tetra_volumes, dihedral_angles, min_max_dihedral, radius_ratio])
def test_a_corner_that_is_nan_or_infinite_is_refused_not_scored(measure):
    """A NaN corner gave a volume of NaN but angles and a radius ratio of 0, as for a flat cell."""
    for bad in (np.nan, np.inf):
        points = CORNER.copy()
        points[2, 1] = bad
        with pytest.raises(tm.errors.MeshValidityError, match=r"NaN or infinite at 1 of 4 points \(index 2 first\)"):
            measure(points, ONE)
