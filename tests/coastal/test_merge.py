"""Merging overlapping meshes (the guide's ``+``, §6.5): validity, the first mesh kept, a graded seam."""

import warnings

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.coastal.merge import merge, mesh_add
from terramesh.coastal.projection import to_mercator
from terramesh.errors import GeometryError, MeshValidityError, TerrameshWarning
from terramesh.mesh.topology import unique_edges

GRADE = 0.2


def plane(mesh):
    return np.column_stack(to_mercator(*mesh.points.T)) if mesh.geographic else mesh.points


def assert_merged(merged, a, b, *, min_seam_quality):
    """Valid, a kept bit for bit, b's kept cells unchanged, no overlap, a good and graded seam."""
    assert tm.cleanup.mesh_problems(merged) == []
    np.testing.assert_array_equal(merged.points[: a.n_points], a.points)
    np.testing.assert_array_equal(merged.cells[: a.n_cells], a.cells)
    info = merged.info["merge"]
    seam = np.zeros(merged.n_cells, dtype=bool)
    seam[info["seam_cells"]] = True
    assert seam.any() and not seam[: a.n_cells].any()
    # b's cells that are kept are b's cells, corner for corner
    from_b = ~seam
    from_b[: a.n_cells] = False
    b_keys = {tuple(c) for c in np.sort(b.points[b.cells].reshape(len(b.cells), -1), axis=1).tolist()}
    kept = np.sort(merged.points[merged.cells[from_b]].reshape(int(from_b.sum()), -1), axis=1)
    assert all(tuple(c) in b_keys for c in kept.tolist())
    # no overlap: the cells' areas add up to the area they cover
    xy = plane(merged)
    triangles = shapely.polygons(xy[merged.cells])
    covered = shapely.coverage_union_all(triangles).area
    assert shapely.area(triangles).sum() == pytest.approx(covered, rel=1e-9)
    # no near-duplicate vertices: no seam edge is much shorter than the shortest edge of a or b
    edges = unique_edges(merged.cells)
    length = np.linalg.norm(xy[edges[:, 0]] - xy[edges[:, 1]], axis=1)
    shortest = min(np.linalg.norm(np.diff(plane(m)[unique_edges(m.cells)], axis=1), axis=2).min() for m in (a, b))
    seam_edges = unique_edges(merged.cells[seam])
    span = np.linalg.norm(xy[seam_edges[:, 0]] - xy[seam_edges[:, 1]], axis=1)
    assert span.min() >= 0.5 * shortest
    # seam quality (ground quality for lon/lat) and grading: the vertex size changes at about the grade
    quality = tm.quality.triangle_quality(merged.points, merged.cells[seam], geographic=merged.geographic)
    assert quality.min() >= min_seam_quality
    assert quality.mean() >= 0.9
    assert info["seam_quality_min"] == pytest.approx(quality.min())
    size = np.zeros(merged.n_points)
    count = np.bincount(edges.ravel(), minlength=merged.n_points)
    np.add.at(size, edges.ravel(), np.repeat(length, 2))
    size /= np.maximum(count, 1)
    gradient = np.abs(size[seam_edges[:, 0]] - size[seam_edges[:, 1]]) / span
    assert np.median(gradient) <= info["grade"]
    # the tail is the vertex sizes' noise (a vertex's mean edge is some 10 % off its size): over the Gulf of
    # Maine seams' 129-188 edges the 95th percentile was 0.28-0.41 at g = 0.2, and 0.44-0.46 measured on a
    # local plane instead of Mercator; the meshes' own edges, 0.26
    assert np.percentile(gradient, 95) <= 2.5 * info["grade"]
    return quality


@pytest.fixture(scope="module")
def coarse_rectangle():
    return tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.15, seed=0)


@pytest.fixture(scope="module")
def fine_disk():
    return tm.generate_mesh(tm.geometry.Disk((1.0, 0.5), 0.3), 0.03, seed=0)


def test_fine_disk_inside_a_coarse_rectangle(fine_disk, coarse_rectangle):
    merged = merge(fine_disk, coarse_rectangle, g=GRADE)
    quality = assert_merged(merged, fine_disk, coarse_rectangle, min_seam_quality=0.55)
    # b's cells are dropped as far out as the size needs to relax from 0.03 to 0.15 at the grade
    seam_points = merged.points[np.unique(merged.cells[merged.info["merge"]["seam_cells"]])]
    reach = np.linalg.norm(seam_points - [1.0, 0.5], axis=1).max() - 0.3
    assert reach >= (0.15 - 0.03) / GRADE
    # the rectangle is still covered exactly
    assert tm.mesh.topology.signed_areas(merged.points, merged.cells).sum() == pytest.approx(2.0, rel=1e-9)
    assert quality.size > 50


def test_overlapping_rectangles_of_different_sizes():
    a = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1.2, 1)), 0.04, seed=0)
    b = tm.generate_mesh(tm.geometry.Rectangle((1, -0.3), (3, 1.3)), 0.15, seed=0)
    merged = merge(a, b)
    assert_merged(merged, a, b, min_seam_quality=0.55)
    # the union less the two re-entrant corners where the boundaries cross between vertices,
    # which the seam cuts with a chord of about one element (no vertex may be added on a's edges)
    union = shapely.union(shapely.box(0, 0, 1.2, 1), shapely.box(1, -0.3, 3, 1.3)).area
    area = tm.mesh.topology.signed_areas(merged.points, merged.cells).sum()
    assert union - 2 * 0.15**2 < area <= union + 1e-12


def covered_area_errors(merged, a, b):
    """Areas the merged mesh covers outside both meshes, and of the two it leaves out."""
    region = [shapely.coverage_union_all(shapely.polygons(plane(m)[m.cells])) for m in (merged, a, b)]
    union = shapely.union(region[1], region[2])
    return shapely.difference(region[0], union).area, shapely.difference(union, region[0]).area


@pytest.mark.parametrize(
    "a_domain, a_size, b_domain, b_size",
    [
        # b's straight edge runs within a cell of a's: the seam used to cut inside it (9.4 % of b lost)
        (((0.34, 0.3869), (0.6726, 0.6515)), 0.0285, ((0.288, 0.2207), (0.4997, 0.5398)), 0.1124),
        # a coarse b (a hexagon) all dropped: its whole outer boundary was too near a, b vanished (62 %)
        (((0.2291, 0.3029), (0.6698, 0.5016)), 0.0406, ((0.2978, 0.4028), 0.2355), 0.226),
        # b touches a at one corner, all of it dropped and re-meshed: the trimming cut it off (97 %)
        (((0.6701, 0.3034), 0.1962), 0.0492, ((0.1943, 0.3696), (0.4949, 0.7388)), 0.1403),
    ],
)
def test_the_merged_mesh_covers_both(a_domain, a_size, b_domain, b_size):
    def domain(shape):
        return tm.geometry.Disk(*shape) if np.isscalar(shape[1]) else tm.geometry.Rectangle(*shape)

    a = tm.generate_mesh(domain(a_domain), a_size, seed=1)
    b = tm.generate_mesh(domain(b_domain), b_size, seed=2)
    merged = merge(a, b)
    assert tm.cleanup.mesh_problems(merged) == []
    outside, left_out = covered_area_errors(merged, a, b)
    # only where the two boundaries cross between a's vertices (a's edges cannot be split) may the
    # seam cut a corner, by about one of a's elements at each of the two crossings (measured: outside
    # 0.11, 0, 0 and left out 0.07, 0.05, 1.38 sizes²; before: 1.16, 0, 0 and 7.9, 55, 46)
    assert outside < 0.5 * a_size**2
    assert left_out < 2.0 * a_size**2


def test_first_mesh_sticking_out_of_the_second():
    a = tm.generate_mesh(tm.geometry.Disk((2.0, 0.5), 0.4), 0.03, seed=0)
    b = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), 0.1, seed=0)
    merged = a + b if hasattr(tm.Mesh, "__add__") else mesh_add(a, b)
    assert_merged(merged, a, b, min_seam_quality=0.55)


def test_merge_is_not_commutative_and_keeps_holes(coarse_rectangle):
    domain = tm.geometry.Difference([tm.geometry.Rectangle((0.6, 0.2), (1.4, 0.8)), tm.geometry.Disk((1, 0.5), 0.15)])
    holed = tm.generate_mesh(domain, 0.04, seed=0)
    merged = merge(holed, coarse_rectangle)
    assert_merged(merged, holed, coarse_rectangle, min_seam_quality=0.55)
    # a owns its hole: nothing of b is kept inside it
    centroids = merged.points[merged.cells].mean(axis=1)
    assert not np.any(np.linalg.norm(centroids - [1.0, 0.5], axis=1) < 0.15 - 1e-9)
    # b + a: the rectangle keeps everything, the other mesh is dropped
    with pytest.warns(TerrameshWarning, match=r"b is \d.* times finer there .*merge\(inner, outer\)"):
        swapped = merge(coarse_rectangle, holed)
    assert swapped.n_cells == coarse_rectangle.n_cells and swapped.info["merge"]["seam_cells"].size == 0


def test_disjoint_meshes_are_put_side_by_side():
    a = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), 0.1, seed=0)
    b = tm.generate_mesh(tm.geometry.Rectangle((3, 0), (4, 1)), 0.1, seed=0)
    # the Gulf of Maine and Sabine Lake merged into a mesh of two parts, and nothing said so
    with pytest.warns(TerrameshWarning, match=r"neither overlap nor touch \(2 units apart\).*two parts"):
        merged = merge(a, b)
    assert tm.cleanup.mesh_problems(merged) == []
    assert merged.n_cells == a.n_cells + b.n_cells and merged.n_points == a.n_points + b.n_points
    touching = tm.generate_mesh(tm.geometry.Rectangle((1, 0), (2, 1)), 0.1, seed=0)
    merge(a, touching)  # sharing a side: no warning (they are errors here)


def test_point_data_follows_and_is_interpolated(fine_disk, coarse_rectangle):
    a, b = tm.Mesh(fine_disk.points, fine_disk.cells), tm.Mesh(coarse_rectangle.points, coarse_rectangle.cells)

    def depth(p):
        return 10.0 + 3.0 * p[:, 0] - 2.0 * p[:, 1] ** 2

    a.point_data["depth"], b.point_data["depth"] = depth(a.points), depth(b.points)
    b.point_data["only_in_b"] = np.ones(b.n_points)
    a_before, b_before = a.points.copy(), b.point_data["depth"].copy()
    with pytest.warns(TerrameshWarning, match="only_in_b"):
        merged = merge(a, b)
    assert set(merged.point_data) == {"depth"}
    # the inputs are not modified
    np.testing.assert_array_equal(a.points, a_before)
    np.testing.assert_array_equal(b.point_data["depth"], b_before)
    old = merged.n_points - merged.info["merge"]["new_points"]
    np.testing.assert_array_equal(merged.depth[:old], depth(merged.points[:old]))
    # new vertices: harmonic interpolation of the seam's boundary, close to the smooth field
    new = merged.depth[old:]
    assert np.isfinite(new).all()
    assert np.abs(new - depth(merged.points[old:])).max() < 0.05 * np.ptp(merged.depth)


def test_boundaries_are_dropped_with_a_warning(fine_disk, coarse_rectangle):
    a = tm.Mesh(fine_disk.points, fine_disk.cells, boundaries=object())
    with pytest.warns(TerrameshWarning, match="make_boundaries"):
        merged = merge(a, coarse_rectangle)
    assert merged.boundaries is None


def test_a_mesh_with_hanging_nodes_is_not_sent_to_fix_mesh(coarse_rectangle):
    # a square beside a rectangle whose corners lie on the square's side: "repair it first (fix_mesh)", which
    # warns of them and leaves them as they are
    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1], [1, 0.25], [2, 0.25], [2, 0.75], [1, 0.75]])
    hanging = tm.Mesh(points, [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    with pytest.raises(MeshValidityError) as error:
        merge(hanging, coarse_rectangle)
    message = str(error.value)
    assert message.startswith("a is not a valid mesh (2 hanging nodes: boundary vertices on another boundary edge")
    assert message.endswith(": give the parts matching nodes along where they meet, which fix_mesh cannot mend")
    turned = tm.Mesh(points, [[0, 2, 1], [0, 2, 3], [4, 5, 6], [4, 6, 7]])  # fix_mesh first: it turns the cell
    with pytest.raises(MeshValidityError, match=r"clockwise .*: repair it first \(fix_mesh\)$"):
        merge(coarse_rectangle, turned)


def test_grade_alias_and_bad_input(fine_disk, coarse_rectangle):
    same = merge(fine_disk, coarse_rectangle, grade=0.3)
    alias = merge(fine_disk, coarse_rectangle, g=0.3)
    np.testing.assert_array_equal(same.cells, alias.cells)
    with pytest.raises(TypeError, match="same option"):
        merge(fine_disk, coarse_rectangle, g=0.3, grade=0.3)
    with pytest.raises(TypeError, match="unknown option"):
        merge(fine_disk, coarse_rectangle, fs=3)
    with pytest.raises(GeometryError, match="grade"):
        merge(fine_disk, coarse_rectangle, grade=0)
    with pytest.raises(GeometryError, match="crs"):
        merge(tm.Mesh(fine_disk.points, fine_disk.cells, crs="EPSG:4326"), coarse_rectangle)
    with pytest.raises(TypeError, match="Mesh"):
        merge(fine_disk, "mesh.14")
    with pytest.raises(GeometryError, match="region"):
        merge(fine_disk, coarse_rectangle, region=(0, 0, 1, 1))
    with pytest.raises(GeometryError, match="buffer"):
        merge(fine_disk, coarse_rectangle, buffer=-1)
    with pytest.raises(GeometryError, match="smoothing"):
        merge(fine_disk, coarse_rectangle, smoothing=-1)
    assert mesh_add(fine_disk, 3) is NotImplemented
    broken = tm.Mesh(fine_disk.points, fine_disk.cells[:, ::-1])
    with pytest.raises(MeshValidityError, match="repair"):
        merge(broken, coarse_rectangle)


@settings(max_examples=12, deadline=None, derandomize=True)
@example(centre=(0.75, 0.0), radius=0.1875, fine=0.021484375, coarse=0.125, disk_first=False, grade=0.15)
@given(
    centre=st.tuples(st.floats(0.2, 1.8), st.floats(0.0, 1.0)),
    radius=st.floats(0.15, 0.6),
    fine=st.floats(0.02, 0.08),
    coarse=st.floats(0.08, 0.2),
    disk_first=st.booleans(),
    grade=st.sampled_from([0.15, 0.2, 0.3]),
)
def test_any_overlap_merges_into_a_valid_mesh(centre, radius, fine, coarse, disk_first, grade):
    disk = tm.generate_mesh(tm.geometry.Disk(centre, radius), fine * radius / 0.3, seed=1)
    rectangle = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (2, 1)), coarse, seed=2)
    a, b = (disk, rectangle) if disk_first else (rectangle, disk)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"merge\(a, b\) keeps a .* finer", category=TerrameshWarning)
        merged = merge(a, b, grade=grade)
    assert tm.cleanup.mesh_problems(merged) == []
    np.testing.assert_array_equal(merged.cells[: a.n_cells], a.cells)
    triangles = shapely.polygons(merged.points[merged.cells])
    assert shapely.area(triangles).sum() == pytest.approx(shapely.coverage_union_all(triangles).area, rel=1e-9)
    # measured over 400 random cases with the fine disk first: >= 0.31; a coarse first mesh over a thin
    # fine remainder (its locked coarse edges next to fine ones, no room to grade) went down to 0.27,
    # and one random draw in CI to 0.163 (pinned as an example above)
    if merged.info["merge"]["seam_cells"].size:
        assert merged.info["merge"]["seam_quality_min"] >= (0.3 if disk_first else 0.15)


# --- real coastal meshes ------------------------------------------------------------------------


@pytest.fixture(scope="module")
def gulf_of_maine(shared_data):
    """Two overlapping boxes of the Gulf of Maine from GSHHS, 3 km and 5 km at the coast."""
    land = shared_data / "coast" / "GSHHS_l_L1.shp"
    # without boundaries: merge drops them, with a warning (tested above)
    west = tm.coastal.build((-70.5, -68.0, 41.5, 43.8), land, min_el=3000, max_el=15e3, fs=3, g=GRADE, boundaries=False)
    east = tm.coastal.build((-69.0, -66.0, 42.5, 45.0), land, min_el=5000, max_el=25e3, fs=3, g=GRADE, boundaries=False)
    return west, east


@pytest.mark.parametrize("order", ["west first", "east first"])
def test_gulf_of_maine_boxes(gulf_of_maine, order):
    a, b = gulf_of_maine if order == "west first" else gulf_of_maine[::-1]
    merged = merge(a, b)
    assert merged.geographic and merged.crs == a.crs
    assert_merged(merged, a, b, min_seam_quality=0.6)
    assert tm.quality.summary(merged).mean >= 0.95
    # the merged mesh covers both boxes' water: about the two areas less the overlap
    area = {m: np.abs(tm.mesh.topology.signed_areas(plane(m), m.cells)).sum() for m in (a, b, merged)}
    assert max(area[a], area[b]) < area[merged] < area[a] + area[b]


def test_boxes_side_by_side_are_open_along_their_union(gulf_of_maine):
    # the guide's §6.6 partition: the union of two boxes is no rectangle, and the extent's rule made walls of
    # its re-entrant sides (24 wet vertices in a review's Gulf of Maine pair)
    west, east = gulf_of_maine
    merged = merge(west, east)
    union = shapely.union(*(tm.coastal.cut_region(m) for m in gulf_of_maine))
    assert shapely.equals(merged.info["region"], union)
    outline = shapely.boundary(union)

    def open_nodes(**options):
        result = tm.coastal.make_boundaries(merged, open_by="bbox", **options)
        return np.unique(np.concatenate([o.nodes for o in result.boundaries.open]))

    kept, given, extent = open_nodes(), open_nodes(bbox=union), open_nodes(bbox=(-70.5, -66.0, 41.5, 45.0))
    assert np.array_equal(kept, given)
    assert shapely.dwithin(outline, shapely.points(merged.points[kept]), 1e-9).all()
    # the re-entrant sides (x = -68 south of 42.5, y = 42.5 east of -68) are open, the extent's box left them walls
    re_entrant = np.abs(merged.points[kept, 0] + 68.0) < 1e-9
    re_entrant |= np.abs(merged.points[kept, 1] - 42.5) < 1e-9
    assert re_entrant.sum() >= 10
    assert len(extent) <= len(kept) - re_entrant.sum() + 2


@pytest.fixture(scope="module")
def sabine_pass_and_region(shared_data):
    """Sabine Pass at 80 m (CUDEM) and a 1 km regional mesh around it (GSHHS + ETOPO1)."""
    fine = tm.coastal.build(
        (-94.0, -93.8, 29.7, 29.9),
        dem=shared_data / "dem" / "CUDEM_equal.nc",
        min_el=80,
        max_el=1000,
        fs=3,
        g=GRADE,
        boundaries=False,
    )
    regional = tm.coastal.build(
        (-94.6, -93.2, 29.3, 30.2),
        shared_data / "coast" / "GSHHS_l_L1.shp",
        shared_data / "dem" / "ETOPO1_0.1.grd",
        min_el=1000,
        max_el=5000,
        fs=3,
        g=GRADE,
        boundaries=False,
    )
    return fine, regional


def test_sabine_pass_into_a_regional_mesh(sabine_pass_and_region):
    fine, regional = sabine_pass_and_region
    box = shapely.box(-94.0, 29.7, -93.8, 29.9)
    merged = merge(fine, regional, region=box)
    quality = assert_merged(merged, fine, regional, min_seam_quality=0.45)
    # with the box as a's region, nothing of the regional mesh is kept inside it
    from_regional = np.setdiff1d(np.arange(fine.n_cells, merged.n_cells), merged.info["merge"]["seam_cells"])
    centroids = merged.points[merged.cells[from_regional]].mean(axis=1)
    assert not shapely.contains_xy(box, centroids[:, 0], centroids[:, 1]).any()
    # 80 m to 1 km at g = 0.2: a seam kilometres wide, many new cells, all of them good on average
    assert merged.info["merge"]["new_points"] > 100 and quality.mean() >= 0.92
    depth = merged.depth
    assert np.isfinite(depth).all()
    seam_depth = depth[np.unique(merged.cells[merged.info["merge"]["seam_cells"]])]
    assert seam_depth.min() >= min(fine.depth.min(), regional.depth.min())
    assert seam_depth.max() <= max(fine.depth.max(), regional.depth.max())


def test_the_merged_mesh_keeps_the_gauges_fixed(shared_data):
    # the merge dropped info["fixed_points"]: enforce_timestep then removed the inner mesh's gauge
    coast, dem = shared_data / "coast" / "GSHHS_l_L1.shp", shared_data / "dem" / "ETOPO1_0.1.grd"
    gauge = (-70.2, 42.6)
    inner = tm.coastal.build(
        (-70.5, -69.5, 42, 43), coast, dem, min_el=1500, max_el=3000, fs=3, g=0.25, pfix=[gauge], boundaries=False
    )
    outer = tm.coastal.build((-71, -68, 41.5, 44), coast, dem, min_el=5000, max_el=30e3, fs=3, g=0.25, boundaries=False)
    merged = tm.coastal.make_boundaries(merge(inner, outer), dry_depth=1.0)  # Boston Harbor's 0.25 m: land
    index = merged.info["fixed_points"]
    assert index.shape == (1,) and np.array_equal(merged.points[index[0]], gauge)
    with pytest.warns(TerrameshWarning, match="1 of them are fixed points"):  # 60 s is too long for 1.5 km
        enforced = tm.coastal.enforce_timestep(merged, 60.0)
    assert np.all(enforced.points == gauge, axis=1).any()
