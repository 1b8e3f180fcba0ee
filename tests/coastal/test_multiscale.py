"""Multiscale meshing (guide §6.6): a 1 km regional box with a 100 m estuary box inside it."""

import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh.coastal.multiscale import CompositeSize, build_multiscale
from terramesh.coastal.projection import from_mercator, to_mercator
from terramesh.errors import GeometryError, MeshValidityError, TerrameshWarning
from terramesh.mesh.topology import unique_edges

GRADE = 0.2
ESTUARY = (-94.0, -93.8, 29.7, 29.9)


@pytest.fixture(scope="module")
def boxes(shared_data):
    """Gulf coast off Sabine Pass from GSHHS + ETOPO1 at 1 km; Sabine Pass from CUDEM (its 0 m contour) at 100 m."""
    return [
        {
            "bbox": (-94.6, -93.2, 29.3, 30.2),
            "shoreline": shared_data / "coast" / "GSHHS_l_L1.shp",
            "dem": shared_data / "dem" / "ETOPO1_0.1.grd",
            "min_el": 1000,
            "max_el": 5000,
            "fs": 3,
            "g": GRADE,
        },
        {
            "bbox": ESTUARY,
            "shoreline": None,
            "dem": shared_data / "dem" / "CUDEM_equal.nc",
            "min_el": 100,
            "max_el": 1000,
            "fs": 3,
            "g": GRADE,
        },
    ]


# CUDEM's 0 m contour and GSHHS disagree along the estuary box's edge (11.3 km, the longest piece 3.3 km)
WALLS = r"box 1's shoreline and the outer boxes' disagree at its edge: the coast runs along the edge for 1\d\.\d km"


@pytest.fixture(scope="module")
def multiscale(boxes):
    with pytest.warns(TerrameshWarning, match=WALLS):
        return build_multiscale(boxes)


@pytest.fixture(scope="module")
def single_grid(boxes):
    with pytest.warns(TerrameshWarning, match=WALLS):
        return build_multiscale(boxes, method="grid")


def edges_and_ratios(mesh):
    """Mercator points, unique edges, lengths, midpoints and length / requested size (the composite's)."""
    xy = np.column_stack(to_mercator(*mesh.points.T))
    edges = unique_edges(mesh.cells)
    length = np.linalg.norm(xy[edges[:, 0]] - xy[edges[:, 1]], axis=1)
    middle = 0.5 * (xy[edges[:, 0]] + xy[edges[:, 1]])
    return xy, edges, length, middle, length / mesh.info["size"](middle)


def transition_gradient(mesh):
    """|change of the vertex size| / edge length on the edges within 5 km outside the estuary box."""
    xy, edges, length, middle, _ = edges_and_ratios(mesh)
    size = np.bincount(edges.ravel(), weights=np.repeat(length, 2), minlength=len(xy))
    size /= np.bincount(edges.ravel(), minlength=len(xy))
    x0, x1, y0, y1 = mesh.info["size"].rectangles[1]
    outside = np.hypot(middle[:, 0] - np.clip(middle[:, 0], x0, x1), middle[:, 1] - np.clip(middle[:, 1], y0, y1))
    zone = (outside > 0) & (outside < 5000)
    assert zone.sum() > 200
    return np.abs(size[edges[zone, 0]] - size[edges[zone, 1]]) / length[zone]


def test_multiscale_mesh_is_valid_and_follows_each_box(multiscale):
    mesh = multiscale
    assert mesh.crs == "EPSG:4326" and mesh.info["method"] == "once"
    assert tm.cleanup.mesh_problems(mesh) == []
    quality = tm.quality.summary(mesh)
    assert quality.mean >= 0.95 and quality.min >= 0.5
    _, _, length, middle, ratio = edges_and_ratios(mesh)
    inner = mesh.info["size"].owner(middle) == 1
    assert inner.sum() > 3000  # the estuary is resolved at its own 100 m scale
    assert 0.9 <= np.median(ratio[inner]) <= 1.15
    assert 0.9 <= np.median(ratio[~inner]) <= 1.15
    # the estuary's size reaches down to its min_el; the shelf's stays km-scale
    assert np.percentile(length[inner], 5) < 180 and np.median(length[~inner]) > 1000
    # graded transition: the element size changes at about the grade outside the estuary box
    gradient = transition_gradient(mesh)
    assert np.median(gradient) <= GRADE and np.percentile(gradient, 95) <= 2 * GRADE
    # depth from each box's DEM, positive down
    assert np.isfinite(mesh.depth).all() and np.median(mesh.depth) > 0
    lon, lat = mesh.points.T
    assert lon.min() >= -94.6 - 1e-6 and lon.max() <= -93.2 + 1e-6 and lat.min() >= 29.3 - 1e-6
    # ADCIRC boundaries, open on the outer box's edge (or deep), as build makes them: there were none
    assert len(mesh.boundaries.open) >= 1 and len(mesh.boundaries.land) >= 1
    assert mesh.info["boundaries"]["options"]["bbox"] == (-94.6, -93.2, 29.3, 30.2)


@pytest.mark.slow
def test_against_one_mesh_on_a_single_combined_grid(multiscale, single_grid):
    """Same mesh from a 25x smaller size grid: vertices within 5%, the same quality."""
    assert tm.cleanup.mesh_problems(single_grid) == []
    assert single_grid.info["grid_nodes"] > 20 * multiscale.info["grid_nodes"]
    assert single_grid.n_points == pytest.approx(multiscale.n_points, rel=0.05)
    one, many = tm.quality.summary(single_grid), tm.quality.summary(multiscale)
    assert abs(one.mean - many.mean) < 0.01 and many.min >= 0.5 and one.min >= 0.5
    inner = single_grid.info["size"].owner(edges_and_ratios(single_grid)[3]) == 1
    assert 0.9 <= np.median(edges_and_ratios(single_grid)[4][inner]) <= 1.15
    for mesh in (multiscale, single_grid):
        assert mesh.info["timings"]["total"] > 0


@pytest.mark.slow
def test_boxes_meshed_apart_and_merged(boxes):
    with pytest.warns(TerrameshWarning, match=WALLS):  # the same walls as meshed at once, which merge did not say
        mesh = build_multiscale(boxes, method="merge")
    assert tm.cleanup.mesh_problems(mesh) == []
    quality = tm.quality.summary(mesh)
    assert quality.mean >= 0.95 and quality.min >= 0.3
    _, _, _, middle, ratio = edges_and_ratios(mesh)
    inner = mesh.info["size"].owner(middle) == 1
    assert 0.9 <= np.median(ratio[inner]) <= 1.15
    gradient = transition_gradient(mesh)
    assert np.median(gradient) <= GRADE and np.percentile(gradient, 95) <= 2 * GRADE
    # every vertex's depth is its box's DEM's, the seam's new vertices too (a merge interpolates them)
    lon, lat = mesh.points.T
    in_estuary = (lon >= ESTUARY[0]) & (lon <= ESTUARY[1]) & (lat >= ESTUARY[2]) & (lat <= ESTUARY[3])
    expected = np.where(
        in_estuary,
        -tm.coastal.read_dem(boxes[1]["dem"]).sample(lon, lat),
        -tm.coastal.read_dem(boxes[0]["dem"]).sample(lon, lat),
    )
    assert len(mesh.info["merge"]["seam_cells"]) > 50
    assert np.allclose(mesh.depth, expected)


def test_composite_size_is_continuous_and_graded(multiscale):
    size = multiscale.info["size"]
    x0, x1, y0, y1 = size.rectangles[1]
    # across the estuary box's edges the size does not jump
    y = np.linspace(y0 + 1, y1 - 1, 50)
    for x, outward in ((x0, -1.0), (x1, 1.0)):
        inside = size(np.column_stack([np.full_like(y, x - outward * 1e-3), y]))
        outside = size(np.column_stack([np.full_like(y, x + outward * 1e-3), y]))
        np.testing.assert_allclose(outside, inside, rtol=1e-5)
    # walking away from the box, the size grows by at most the grade per metre
    walk = np.column_stack([np.linspace(x1, x1 + 30e3, 301), np.full(301, 0.5 * (y0 + y1))])
    h = size(walk)
    assert np.all(np.diff(h) <= GRADE * np.diff(walk[:, 0]) + 1e-6)
    # 4.5 times: the walk starts on land, 1152 m since Shoreline.from_dem takes CUDEM's 2,574 nodes at exactly
    # 0 m as land (ponds near this edge were water, and the size there 482 m)
    assert h[-1] > 4 * h[0]


def test_bad_boxes_are_refused(shared_data):
    land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    outer = {"bbox": (0, 0.3, 0, 0.3), "min_el": 2500, "max_el": 6000, "dis": 0.3}
    with pytest.raises(GeometryError, match="method"):
        build_multiscale([outer], land, method="best")
    with pytest.raises(GeometryError, match="list of dicts"):
        build_multiscale(outer, land)
    with pytest.raises(GeometryError, match="bbox"):
        build_multiscale([outer, {"min_el": 100}], land)
    with pytest.raises(GeometryError, match="does not overlap"):
        build_multiscale([outer, {"bbox": (1, 1.1, 1, 1.1), "min_el": 1000, "max_el": 2000}], land)
    with pytest.raises(TypeError, match="unknown option"):
        build_multiscale([{**outer, "fss": 3}], land)
    ashore = {"bbox": (0.2, 0.3, 0.0, 0.05), "min_el": 1500, "max_el": 3000, "dis": 0.3}
    with pytest.raises(GeometryError, match=r"^box 1: the bbox \(0\.2, 0\.3, 0\.0, 0\.05\) is all land"):
        build_multiscale([outer, ashore], land)
    reaching = {"bbox": (0.2, 0.4, 0.05, 0.15), "min_el": 1500, "max_el": 3000, "dis": 0.3}
    with pytest.warns(TerrameshWarning, match="reaches out"):
        mesh = build_multiscale([outer, reaching], land)
    assert tm.cleanup.mesh_problems(mesh) == [] and mesh.points[:, 0].max() <= 0.3 + 1e-9


@pytest.mark.parametrize("method", ["once", "merge", "grid"])
def test_a_box_reaching_out_is_cut_and_takes_the_outer_boxs_dem(method):
    # merging meshed such a box whole, its edge out at sea a mainland wall, and its depths were NaN without a DEM
    land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    lon = lat = np.linspace(-0.1, 0.5, 61)
    dem = tm.coastal.DEM(lon, lat, np.full((61, 61), -40.0))
    outer = {"bbox": (0, 0.3, 0, 0.3), "min_el": 2500, "max_el": 6000, "dis": 0.3, "dem": dem}
    reaching = {"bbox": (0.2, 0.4, 0.2, 0.3), "min_el": 1000, "max_el": 3000, "dis": 0.3, "dem": None}
    with pytest.warns(TerrameshWarning, match="reaches out"):
        mesh = build_multiscale([outer, reaching], land, method=method)
    assert tm.cleanup.mesh_problems(mesh) == [] and mesh.points[:, 0].max() <= 0.3 + 1e-9
    assert np.allclose(mesh.depth, 40.0)
    east = np.flatnonzero((np.abs(mesh.points[:, 0] - 0.3) < 1e-9) & (mesh.points[:, 1] > 0.25 + 1e-6))
    assert len(east) >= 3 and np.isin(east, np.concatenate([b.nodes for b in mesh.boundaries.open])).all()
    inner = (mesh.points[:, 0] > 0.2) & (mesh.points[:, 1] > 0.2)
    assert inner.sum() > 40  # refined there (1 km against 2.5 km)


@pytest.mark.parametrize("method", ["once", "merge", "grid"])
def test_boxes_listed_inner_first_are_refused_before_meshing(monkeypatch, method):
    """Was: a MeshValidityError from clean ("left no cell") after the outer box was cut down to the inner one."""
    import terramesh.coastal.multiscale as multiscale

    def no_sizes(*args, **kwargs):
        pytest.fail("size_function was called: the order of the boxes must be checked first")

    monkeypatch.setattr(multiscale, "size_function", no_sizes)
    land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    outer = {"bbox": (0, 0.3, 0, 0.3), "min_el": 2500, "max_el": 6000, "dis": 0.3, "g": 0.3}
    inner = {"bbox": (0.05, 0.15, 0.05, 0.15), "min_el": 1000, "max_el": 2000, "dis": 0.3, "g": 0.3}
    message = (
        r"^box 1 \(0\.0, 0\.3, 0\.0, 0\.3\) contains the first box \(0\.05, 0\.15, 0\.05, 0\.15\): "
        "list the boxes outermost first"
    )
    with pytest.raises(GeometryError, match=message):
        build_multiscale([inner, outer], land, method=method)
    estuary = {"bbox": (0.08, 0.12, 0.08, 0.12), "min_el": 500, "max_el": 1000}
    with pytest.raises(GeometryError, match="^box 2 .* contains the first box"):
        build_multiscale([inner, estuary, outer], land, method=method)


@pytest.mark.parametrize(
    ("boundaries", "message"),
    [
        ("yes", r"^build_multiscale: boundaries must be True, False or a dict .* got 'yes'"),
        ({"island_ibtyp": 20}, r"'island_ibtyp' \(did you mean 'island_ibtype'\?\)"),
        ({"dry_depth": np.nan}, r"^build_multiscale: boundaries: dry_depth must be a finite number of metres"),
    ],
)
def test_a_bad_boundaries_argument_is_refused_before_meshing(monkeypatch, boundaries, message):
    # "yes" failed after the meshing, with a ValueError from a dict update
    import terramesh.coastal.multiscale as multiscale

    def no_sizes(*args, **kwargs):
        pytest.fail("size_function was called: boundaries must be checked first")

    monkeypatch.setattr(multiscale, "size_function", no_sizes)
    box = {"bbox": (0, 0.3, 0, 0.3), "min_el": 2500, "max_el": 6000}
    with pytest.raises(MeshValidityError, match=message):
        build_multiscale([box], shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25)]), boundaries=boundaries)


@pytest.mark.parametrize("method", ["once", "merge"])
def test_offshore_box_refines_open_water(shared_data, method):
    """A refinement box 200 km off the US East Coast, with no land in it (GSHHS), inside a 3-30 km shelf mesh."""
    boxes = [
        {"bbox": (-76, -70, 36, 41), "min_el": 3000, "max_el": 30e3, "dis": 0.3, "g": GRADE},
        {"bbox": (-72, -71, 37, 38), "min_el": 1000, "max_el": 1500, "dis": 0.3, "g": GRADE},
    ]
    mesh = build_multiscale(boxes, shared_data / "coast" / "GSHHS_l_L1.shp", method=method)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.quality.summary(mesh).min >= 0.5
    offshore = mesh.info["sizes"][1]
    assert offshore.shoreline.coastline.is_empty and np.all(offshore.sizes == 1500.0)  # max_el: no coast to grade
    _, _, length, middle, ratio = edges_and_ratios(mesh)
    inner = mesh.info["size"].owner(middle) == 1
    assert inner.sum() > 10_000  # 1 degree square at 1.5 km
    ground = length * np.cos(np.radians(from_mercator(*middle.T)[1]))  # Mercator to ground metres
    assert 0.9 <= np.median(ratio[inner]) <= 1.15 and 1350 <= np.median(ground[inner]) <= 1650
    assert 0.9 <= np.median(ratio[~inner]) <= 1.15 and np.median(ground[~inner]) > 2 * np.median(ground[inner])
    gradient = transition_gradient(mesh)
    assert np.median(gradient) <= GRADE and np.percentile(gradient, 95) <= 2 * GRADE


@pytest.mark.parametrize("method", ["once", "merge"])
@pytest.mark.parametrize("inner_lon", [(182.8, 184.2), (-177.2, -175.8)])
def test_inner_box_east_of_180_in_a_box_across_the_antimeridian(shared_data, method, inner_lon):
    """The Chatham Islands (183.5 E) in 178-186 E: the inner box, kept in -180..180, was refused as not overlapping."""
    boxes = [
        {"bbox": (178, 186, -46, -42), "min_el": 4000, "max_el": 40e3, "fs": 3, "g": 0.3},
        {"bbox": (*inner_lon, -44.5, -43.5), "min_el": 1000, "max_el": 8e3, "fs": 3, "g": 0.3},
    ]
    mesh = build_multiscale(
        boxes, shared_data / "coast" / "GSHHS_l_L1.shp", shared_data / "dem" / "ETOPO1_0.1.grd", method=method
    )
    assert tm.cleanup.mesh_problems(mesh) == []
    lon, lat = mesh.points.T
    assert 178 - 1e-6 <= lon.min() and lon.max() <= 186 + 1e-6  # the first box's longitudes
    assert np.isfinite(mesh.depth).all()
    inner = (lon >= 182.8) & (lon <= 184.2) & (lat >= -44.5) & (lat <= -43.5)
    edges = unique_edges(mesh.cells)
    length = tm.coastal.timestep.edge_lengths(mesh.points, edges, geographic=True)
    refined = np.median(length[inner[edges].all(axis=1)])
    assert refined <= 8000 and refined < 0.4 * np.median(length[~inner[edges].any(axis=1)])


def test_the_smallest_of_the_boxes_time_steps_is_kept_and_checked(shared_data):
    boxes = [
        {
            "bbox": (-71.5, -66, 41, 45),
            "min_el": 3000,
            "max_el": 30e3,
            "max_el_ns": 6e3,
            "fs": 3,
            "wl": 30,
            "g": 0.25,
            "dt": 0,
        },
        {"bbox": (-70.9, -69.8, 41.9, 42.8), "min_el": 600, "max_el": 5e3, "fs": 3, "wl": 30, "g": 0.25, "dt": 0},
    ]
    mesh = build_multiscale(boxes, shared_data / "coast" / "GSHHS_l_L1.shp", shared_data / "dem" / "ETOPO1_0.1.grd")
    steps = [sizes.dt for sizes in mesh.info["sizes"]]
    assert steps[1] < 0.5 * steps[0] and mesh.info["dt"] == min(steps)
    assert np.nanmax(tm.coastal.courant_number(mesh, mesh.info["dt"])) <= 0.5  # checked: no warning either


def test_a_box_without_dt_is_named_instead_of_the_courant_remedy(shared_data):
    # the check's remedy, enforce_timestep at the outer box's 19.5 s, took a review's inner box from 11,194 to
    # 4,404 vertices and still left Courant 1.36
    boxes = [
        {"bbox": (-71.5, -66, 41, 45), "min_el": 3000, "max_el": 30e3, "fs": 3, "wl": 30, "g": 0.25, "dt": 0},
        {"bbox": (-70.9, -69.8, 41.9, 42.8), "min_el": 600, "max_el": 5e3, "fs": 3, "g": 0.25},
    ]
    with pytest.warns(TerrameshWarning, match=r"box 1 has no dt: its sizes are not limited for the dt") as record:
        mesh = build_multiscale(boxes, shared_data / "coast" / "GSHHS_l_L1.shp", shared_data / "dem" / "ETOPO1_0.1.grd")
    assert not any("enforce_timestep(" in str(w.message) for w in record)
    assert mesh.info["dt"] == mesh.info["sizes"][0].dt and mesh.info["largest_courant"] > 0.5


def test_offshore_box_beyond_a_regional_coastline(tmp_path):
    """The inner box lies beyond the extent of the (regional) shoreline file: open water, meshed."""
    import pyogrio

    path = tmp_path / "coast.gpkg"
    land = shapely.box(9.0, -1.0, 10.2, 2.0)
    pyogrio.raw.write(path, shapely.to_wkb([land]), [], [], geometry_type="Polygon", crs="EPSG:4326")
    boxes = [
        {"bbox": (9.8, 11.2, 0.0, 1.0), "min_el": 3000, "max_el": 8000, "dis": 0.3, "g": GRADE},
        {"bbox": (10.6, 11.0, 0.3, 0.7), "min_el": 1500, "max_el": 2000, "g": GRADE},
    ]
    mesh = build_multiscale(boxes, path)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert mesh.info["sizes"][1].shoreline.land.is_empty
    _, _, _, middle, ratio = edges_and_ratios(mesh)
    inner = mesh.info["size"].owner(middle) == 1
    assert inner.sum() > 300 and 0.9 <= np.median(ratio[inner]) <= 1.15


def test_composite_size_of_nested_boxes():
    land = shapely.box(-1.0, -1.0, 0.0, 1.0)
    outer = tm.coastal.size_function((-0.5, 0.5, -0.5, 0.5), land, min_el=4000, max_el=8000, dis=0.5)
    inner = tm.coastal.size_function((-0.05, 0.1, -0.05, 0.05), land, min_el=1000, max_el=1000)
    size = CompositeSize([outer, inner], [0.25, 0.25])
    x, y = to_mercator(np.array([0.05, 0.2, 0.35, -0.2]), np.zeros(4))
    h = size(np.column_stack([x, y]))
    assert h[0] == pytest.approx(1000.0, rel=1e-3)  # Mercator metres at the equator are ground metres
    assert h[0] < h[1] < h[2] <= outer.size_grid()(np.column_stack([x, y]))[2] + 1e-9
    np.testing.assert_array_equal(size.owner(np.column_stack([x, y])), [1, 0, 0, 0])
    flat = CompositeSize([outer, inner], [0.25, 0.25], nested=False)
    assert flat(np.column_stack([x, y]))[0] == pytest.approx(outer.size_grid()(np.column_stack([x, y]))[0])


@pytest.mark.parametrize("method", ["grid", "once"])
def test_the_sizes_are_graded_on_the_ground_at_high_latitude(monkeypatch, method):
    """Graded on Mercator lengths, the sizes grew up to h tan(lat) / R faster than g along the meridians: the grid
    method's combined grid, and the default's transition out of a fine box (0.251 for g 0.2 at 82 N)."""
    import terramesh.coastal.multiscale as multiscale
    from terramesh.coastal.projection import EARTH_RADIUS

    class Captured(Exception):
        pass

    def capture(domain, size, h0, **options):
        raise Captured(size)

    monkeypatch.setattr(multiscale, "mesh_water", capture)
    land = shapely.box(-1.0, 83.7, 11.0, 86.0)  # the coast to the north: sizes grow toward the equator
    outer = {"bbox": (0, 10, 78, 84), "min_el": 2000, "max_el": 50e3, "dis": 1.0, "g": 0.2}
    inner = {"bbox": (4, 6, 83, 83.6), "min_el": 1000, "max_el": 5000, "dis": 1.0, "g": 0.2}
    with pytest.raises(Captured) as caught:
        build_multiscale([outer, inner], land, method=method)
    size = caught.value.args[0]  # on the Mercator plane
    lat = np.linspace(78.5, 82.99, 4000)  # the meridian at 5 E, south of the inner box
    ground = size(np.column_stack(to_mercator(np.full(lat.size, 5.0), lat))) * np.cos(np.radians(lat))
    north = np.abs(np.diff(ground)) / np.diff(EARTH_RADIUS * np.radians(lat))
    assert 0.19 <= north.max() <= 0.2 * 1.01
