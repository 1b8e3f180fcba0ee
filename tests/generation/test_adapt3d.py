"""adapt_mesh in 3D: tetrahedral meshes adapted to a changed size function, against fresh meshes of it."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

import terramesh as tm
from terramesh.errors import GenerationError
from terramesh.quality import radius_ratio

H = 0.12
BOX = tm.geometry.Box((0.0, 0.0, 0.0), (2.0, 1.0, 1.0))


def uniform(points):
    return np.full(len(points), H)


def anomaly(centre, factor, radius=0.35):
    """H, times ``factor`` within ``radius`` of ``centre``, graded back to H over as far again."""

    def size(points):
        r = np.linalg.norm(points - np.asarray(centre), axis=1)
        return H * (1.0 + (factor - 1.0) * np.clip(1.5 - r / radius, 0.0, 1.0))

    return size


def edge_ratios(mesh, size):
    """Each edge's length over the size at its midpoint, and the midpoints."""
    pairs = [[a, b] for a in range(4) for b in range(a + 1, 4)]
    edges = np.unique(np.sort(np.concatenate([mesh.cells[:, pair] for pair in pairs]), axis=1), axis=0)
    ends = mesh.points[edges]
    middle = ends.mean(axis=1)
    return np.linalg.norm(ends[:, 0] - ends[:, 1], axis=1) / size(middle), middle


def assert_like_fresh(adapted, fresh, domain, size, count=0.12, quality=0.01):
    """Valid, sliver-free, as many vertices as a fresh mesh (within ``count``), as good (within ``quality``)."""
    assert tm.cleanup.mesh_problems(adapted, domain, boundary_tolerance=1e-3 * 0.6 * H) == []
    assert adapted.info["min_dihedral"] >= 10.0
    assert abs(adapted.n_points / fresh.n_points - 1.0) < count
    assert radius_ratio(adapted.points, adapted.cells).mean() > radius_ratio(fresh.points, fresh.cells).mean() - quality
    assert 0.95 < np.median(edge_ratios(adapted, size)[0]) < 1.07


@pytest.fixture(scope="module")
def old_box():
    return tm.generate_mesh(BOX, uniform, h0=H, seed=0)


@pytest.mark.parametrize(("factor", "old_sizes"), [(0.6, False), (0.6, True), (1.8, False), (1.8, True)])
def test_a_local_change_on_a_box_gives_a_mesh_as_a_fresh_one(old_box, factor, old_sizes):
    # fresh: 2,644 / 1,973 vertices, mean radius ratio 0.891 / 0.888; adapted 2,796-2,857 / 2,066-2,120, 0.880-0.894
    size = anomaly((1.2, 0.7, 0.7), factor)
    fresh = tm.generate_mesh(BOX, size, h0=0.6 * H, seed=0)
    adapted = tm.adapt_mesh(old_box, BOX, size, h0=0.6 * H, old_edge_length=uniform if old_sizes else None)
    assert_like_fresh(adapted, fresh, BOX, size)
    assert (adapted.info["added"] > adapted.info["removed"]) == (factor < 1)
    if old_sizes:
        # the old vertices far from the change stay where they were, to the bit, but for those near the box's
        # edges: an edge's points are spaced along all of it by the sizes, so a change anywhere along it moves
        # them (92 of the 521 far vertices, all within 1.9 sizes of an edge)
        points = old_box.points
        far = np.linalg.norm(points - [1.2, 0.7, 0.7], axis=1) > 0.35 * 1.5 + 4 * H
        from_edges = np.sort(np.minimum(points, [2.0, 1.0, 1.0] - points), axis=1)[:, 1]
        kept = far & (from_edges > 2 * H)
        assert kept.sum() > 100
        assert cKDTree(adapted.points).query(points[kept])[0].max() == 0.0
        assert adapted.info["held"] > 0.4 * old_box.n_points
    else:
        assert adapted.info["held"] == 0


def test_a_size_changed_almost_everywhere_iterates_to_equilibrium(old_box):
    """Most points new: from a start far from equilibrium, 31 iterations left mean radius ratio 0.86."""
    coarser = lambda points: np.where(points[:, 0] > 0.4, 1.5 * H, H)  # noqa: E731
    fresh = tm.generate_mesh(BOX, coarser, h0=H, seed=0)
    adapted = tm.adapt_mesh(old_box, BOX, coarser, h0=H, old_edge_length=uniform)
    assert "afresh" not in adapted.info and adapted.info["removed"] > 0.3 * old_box.n_points
    assert adapted.info["stop_reason"] != "settled"
    assert_like_fresh(adapted, fresh, BOX, coarser, count=0.15, quality=0.01)


def test_a_size_changed_everywhere_is_meshed_afresh(old_box):
    # a new frequency: adapting BP2004 3D from 0.8 to 1 Hz took 55.7 s for 9 % more vertices than a fresh mesh's
    # 14.6 s; nothing of the old mesh is kept anyway
    coarser = lambda points: np.full(len(points), 1.5 * H)  # noqa: E731
    adapted = tm.adapt_mesh(old_box, BOX, coarser, old_edge_length=uniform)
    fresh = tm.generate_mesh(BOX, coarser)
    assert adapted.info["afresh"] and adapted.info["held"] == 0
    assert np.array_equal(adapted.points, fresh.points) and np.array_equal(adapted.cells, fresh.cells)
    # without the old sizes nothing tells: adapted from the old vertices
    assert "afresh" not in tm.adapt_mesh(old_box, BOX, coarser).info


def test_an_unchanged_size_leaves_a_cylinder_as_it_was():
    """Flat cells across a cylinder's side (boundary points alone) have edges of up to 13 sizes: not split.

    Split in rounds, 1,740 vertices became 2,483 where the size had not changed.
    """
    cylinder = tm.geometry.Cylinder((0.0, 0.0, 0.0), 0.6, 1.6, axis=(0, 0, 1))
    old = tm.generate_mesh(cylinder, uniform, h0=H, seed=0)
    adapted = tm.adapt_mesh(old, cylinder, uniform, h0=H)
    assert abs(adapted.n_points / old.n_points - 1.0) < 0.05
    assert tm.cleanup.mesh_problems(adapted, cylinder, boundary_tolerance=1e-3 * H) == []
    held = tm.adapt_mesh(old, cylinder, uniform, h0=H, old_edge_length=uniform)
    assert held.info["added"] == held.info["removed"] == 0 and held.info["iterations"] == 1


def test_a_mesh_of_part_of_the_domain_is_seeded_where_it_does_not_reach():
    """A model extended by half its length: the old mesh covers two thirds, seeds fill the rest."""
    short = tm.geometry.Box((0.0, 0.0, 0.0), (1.2, 1.0, 1.0))
    old = tm.generate_mesh(short, uniform, h0=H, seed=0)
    fresh = tm.generate_mesh(BOX, uniform, h0=H, seed=0)
    adapted = tm.adapt_mesh(old, BOX, uniform, h0=H, old_edge_length=uniform)
    assert adapted.info["seeded"] > 0.3 * old.n_points
    assert_like_fresh(adapted, fresh, BOX, uniform)
    # the old mesh's far end (its face at x = 1.2, a layer at the boundary's density) is inside now: thinned
    ratios, middle = edge_ratios(adapted, uniform)
    assert 0.93 < np.median(ratios[np.abs(middle[:, 0] - 1.2) < 0.5 * H]) < 1.07


@pytest.fixture(scope="module")
def bp2004_3d(shared_data):
    """A BP2004 window (x 26-34 km, the top 4 km) on a 200 m grid, extruded 4 km along y."""
    section = tm.seismic.read_velocity(shared_data / "seismic" / "vel_z6.25m_x12.5m_exact.segy")
    x, z = section.axes
    columns, rows = (x >= 26000) & (x <= 34000), z >= -4000
    values = section.values[np.ix_(columns, rows)][::16, ::32]
    y = np.arange(0.0, 4001.0, 200.0)
    return tm.seismic.VelocityModel(np.repeat(values[:, None, :], len(y), axis=1), (x[columns][::16], y, z[rows][::32]))


def test_a_3d_velocity_update_is_followed_where_it_happened(bp2004_3d):
    # the velocity falls by 40 % in an ellipsoid 3 x 2.4 x 1.6 km: 6,034 old vertices, 7,116 fresh
    options = dict(frequency=0.5, hmin=100.0, grade=0.15)
    old_size = tm.seismic.size_function(bp2004_3d, **options)
    old = tm.generate_mesh(old_size.domain, old_size, seed=0)
    grid = np.stack(np.meshgrid(*bp2004_3d.axes, indexing="ij"), axis=-1)
    centre, axes = np.array([31000.0, 2000.0, -2500.0]), np.array([1500.0, 1200.0, 800.0])
    values = bp2004_3d.values.copy()
    values[np.sum(((grid - centre) / axes) ** 2, axis=-1) <= 1] *= 0.6
    size = tm.seismic.size_function(tm.seismic.VelocityModel(values, bp2004_3d.axes), **options)
    fresh = tm.generate_mesh(size.domain, size, seed=0)
    adapted = tm.adapt_mesh(old, size.domain, size, old_edge_length=old_size)
    assert tm.cleanup.mesh_problems(adapted, size.domain, boundary_tolerance=1e-3 * 100.0) == []
    assert adapted.info["min_dihedral"] >= 10.0
    assert abs(adapted.n_points / fresh.n_points - 1.0) < 0.08
    assert radius_ratio(adapted.points, adapted.cells).mean() > radius_ratio(fresh.points, fresh.cells).mean() - 0.01
    inside = np.sum(((adapted.points - centre) / axes) ** 2, axis=1) <= 0.5
    ratios, _ = edge_ratios(tm.Mesh(adapted.points, adapted.cells[np.all(inside[adapted.cells], axis=1)]), size)
    assert 0.9 < np.median(ratios) < 1.1  # the new sizes where the velocity fell
    # the old vertices far from where the size changed (the grading spreads it over 6 km of the 8) and from the
    # model box's edges (whose points a change anywhere along them spaces anew) stay, to the bit
    points, (low, high) = old.points, size.domain.bbox
    changed = np.abs(size(points) / old_size(points) - 1.0) > 0.02
    from_changes = cKDTree(points[changed]).query(points)[0] / old_size(points)
    from_edges = np.sort(np.minimum(points - low, high - points), axis=1)[:, 1] / old_size(points)
    far = (from_changes > 4) & (from_edges > 4)
    assert far.sum() > 300
    assert cKDTree(adapted.points).query(points[far])[0].max() == 0.0
    assert adapted.info["held"] > 0.4 * old.n_points
    again = tm.adapt_mesh(old, size.domain, size, old_edge_length=old_size)
    np.testing.assert_array_equal(again.points, adapted.points)
    np.testing.assert_array_equal(again.cells, adapted.cells)


@pytest.mark.parametrize(
    ("mesh", "domain", "message"),
    [
        (tm.Mesh(np.eye(4)[:, :3], [[0, 1, 2, 3]]), tm.geometry.Disk((0, 0), 1), "tetrahedral meshes on 3D domains"),
        (None, tm.geometry.Box((10.0, 10.0, 10.0), (12.0, 11.0, 11.0)), "the mesh misses the domain"),
        (None, tm.geometry.Box((0.0, 0.0, 0.0), (2000.0, 1000.0, 1000.0)), "in other units"),
    ],
)
def test_bad_3d_inputs(old_box, mesh, domain, message):
    with pytest.raises(GenerationError, match=message):
        tm.adapt_mesh(old_box if mesh is None else mesh, domain, 100.0 if domain.bbox[1, 0] > 100 else H)


@pytest.mark.parametrize("radius", [1.005, 1.03])
def test_a_boundary_moved_out_by_a_fraction_of_a_size_is_followed(radius):
    """Held a rounding inside the new sphere, all 332 boundary vertices were left off it, without a word."""
    old = tm.generate_mesh(tm.geometry.Ball((0, 0, 0), 1.0), 0.2, seed=0)
    ball = tm.geometry.Ball((0, 0, 0), radius)
    adapted = tm.adapt_mesh(old, ball, 0.2, old_edge_length=0.2)
    assert tm.cleanup.mesh_problems(adapted, ball, boundary_tolerance=1e-3 * 0.2) == []


@pytest.mark.parametrize("radius", [0.2, 0.3, 0.4])
def test_a_bump_added_to_a_face_is_meshed(old_box, radius):
    """The old face's vertices beside the bump's new edge left cells across it, and those inside it flat cells."""
    domain = BOX | tm.geometry.Ball((2.0, 0.5, 0.5), radius)
    for old_size in (None, uniform):
        adapted = tm.adapt_mesh(old_box, domain, H, old_edge_length=old_size)
        assert tm.cleanup.mesh_problems(adapted, domain, boundary_tolerance=1e-3 * H) == []
        assert adapted.info["min_dihedral"] >= 10.0


def test_a_mesh_without_cells_and_a_wrong_old_size_are_told(old_box):
    with pytest.raises(GenerationError, match="no cells to adapt"):
        tm.adapt_mesh(tm.Mesh(old_box.points, np.empty((0, 4), dtype=int)), BOX, H)
    # the mesh was made for H, not 0.6 H: each vertex stands for 4.7 at 0.6 H
    with pytest.warns(tm.TerrameshWarning, match="is old_edge_length the size the mesh was made for"):
        tm.adapt_mesh(old_box, BOX, H, old_edge_length=0.6 * H)
