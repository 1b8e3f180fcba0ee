"""One-call coastal meshes on real data: validity, quality and conformity to the size function."""

import re
import sys
import warnings

import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh.coastal import to_mercator
from terramesh.coastal.projection import EARTH_RADIUS
from terramesh.errors import GeometryError, MeshValidityError, SizingError, TerrameshWarning
from terramesh.mesh.topology import boundary_loops, unique_edges
from terramesh.sizing.edge_shrink import EDGE_SHRINK


def edge_length_ratios(mesh):
    """Edge length over the requested size at the edge midpoint, both on the Mercator plane."""
    size = mesh.info["sizes"].size_grid()
    points = np.column_stack(to_mercator(*mesh.points.T))
    edges = unique_edges(mesh.cells)
    lengths = np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)
    return lengths / size(0.5 * (points[edges[:, 0]] + points[edges[:, 1]]))


def assert_solver_ready(mesh):
    assert tm.cleanup.mesh_problems(mesh) == []
    quality = tm.quality.summary(mesh)
    assert quality.mean >= 0.95
    assert quality.min >= 0.5
    assert 0.9 <= np.median(edge_length_ratios(mesh)) <= 1.15


@pytest.fixture(scope="module")
def sabine_pass(shared_data):
    """Sabine Pass, TX/LA: shoreline from the DEM's 0 m contour, the guide's fs + wl + grade + automatic dt."""
    with pytest.warns(TerrameshWarning, match="1 of 6 open boundaries are less than 1 m deep"):
        return tm.coastal.build(
            (-94.0, -93.8, 29.7, 29.9),
            dem=shared_data / "dem" / "CUDEM_equal.nc",
            min_el=80,
            max_el=1000,
            fs=3,
            wl=60,
            g=0.2,
            dt=0,
        )


def test_sabine_pass_is_solver_ready(sabine_pass):
    mesh = sabine_pass
    assert mesh.crs == "EPSG:4326" and mesh.geographic
    assert mesh.n_points > 2000
    assert_solver_ready(mesh)
    lon, lat = mesh.points.T
    slack = 1e-6  # degrees: boundary vertices lie within 1e-3 h0 (0.08 m) of the boundary
    assert lon.min() >= -94.0 - slack and lon.max() <= -93.8 + slack
    assert lat.min() >= 29.7 - slack and lat.max() <= 29.9 + slack
    # depth sampled from the DEM, positive down: water deeper than the 0 m shoreline almost everywhere
    assert np.isfinite(mesh.depth).all() and np.median(mesh.depth) > 0


def test_sabine_pass_time_step_keeps_the_coast(sabine_pass):
    """dt = 0 picks eq. 12's step: no size along the coast was raised by the CFL limit."""
    sizes = sabine_pass.info["sizes"]
    assert 0.5 < sizes.dt < 20
    courant = tm.coastal.sizes.courant_number(sizes.sizes, sizes.depth, dt=sizes.dt)
    assert courant[sizes.water].max() <= 0.5 * EDGE_SHRINK + 1e-9
    # and the mesh keeps it on its shortest edges, which the allowance is for
    assert np.nanmax(tm.coastal.courant_number(sabine_pass, sizes.dt)) <= 0.5
    assert sizes.check_timestep(sabine_pass) == sabine_pass.info["largest_courant"] <= 0.5
    assert sabine_pass.info["dt"] == sizes.dt  # where build_multiscale puts its step too


def test_a_mesh_built_for_a_long_time_step_keeps_it(shared_data):
    """dt = 60 s in the Gulf of Maine: the floor rises faster than the grade at the shelf break.

    With the bare floor of eq. 10 the mesh broke Courant 0.5 at 5,511 of its 9,734 vertices (up to
    1.29): its edges beside the jump in the sizes came out short, and all of them short of their size.
    """
    with pytest.warns(TerrameshWarning) as caught:
        mesh = tm.coastal.build(
            (-71.5, -66, 41, 45),
            shared_data / "coast" / "GSHHS_l_L1.shp",
            shared_data / "dem" / "ETOPO1_0.1.grd",
            min_el=1000,
            max_el=15e3,
            dis=0.2,
            g=0.25,
            dt=60,
        )
    said = [str(warning.message) for warning in caught]
    # the shelf's 4 km deep water needs 24 km at 60 s: past max_el, said so (nothing was, before)
    assert re.match(r"the CFL limit of dt = 60 s lifted the sizes past max_el = 15000 m over \d", said[0])
    assert len(said) == 2 and re.match(r"^(\d+) of the mesh's \d+ vertices break Courant 0.5 at dt = 60 s", said[1])
    courant = tm.coastal.courant_number(mesh, 60)
    over = courant > 0.5
    assert over.sum() == int(said[1].split()[0])
    assert over.mean() < 0.005 and courant.max() < 0.75  # vertices of the coast's own short edges
    assert "enforce_timestep(mesh, 60)" in said[1]
    assert tm.coastal.enforce_timestep(mesh, 60).info["timestep"]["max_courant_after"] <= 0.5
    assert_solver_ready(mesh)


def test_regional_mesh_with_every_depth_function(shared_data):
    """Gulf of Maine from GSHHS and ETOPO1: feature size, wavelength, slope, grade and CFL together."""
    # Boston Harbor's entrance on the box's west edge, under 1 m on ETOPO1: an open boundary, said so
    with pytest.warns(TerrameshWarning, match="open boundaries are less than 1 m deep"):
        mesh = tm.coastal.build(
            (-71.0, -65.0, 41.0, 45.0),
            shared_data / "coast" / "GSHHS_l_L1.shp",
            shared_data / "dem" / "ETOPO1_0.1.grd",
            min_el=3000,
            max_el=30e3,
            fs=3,
            wl=40,
            slp=20,
            g=0.2,
            dt=0,
        )
    assert set(mesh.info["sizes"].fields) == {"fs", "wl", "slp"}
    assert_solver_ready(mesh)
    assert np.nanmedian(mesh.depth) > 20


def test_guide_names_and_long_names_agree(shared_data):
    land = shared_data / "coast" / "GSHHS_l_L1.shp"
    box = (-71.0, -69.0, 41.0, 43.0)
    short = tm.coastal.size_function(box, land, min_el=4000, max_el=20e3, dis=0.3, g=0.25)
    long = tm.coastal.size_function(
        box, land, min_edge_length=4000, max_edge_length=20e3, distance_rate=0.3, grade=0.25
    )
    np.testing.assert_array_equal(short.sizes, long.sizes)
    assert short.sizes.min() >= 4000 and short.sizes.max() <= 20e3


@pytest.mark.parametrize(
    ("options", "error", "message"),
    [
        (
            {"min_el": 4000, "fss": 3},
            TypeError,
            r"unknown option 'fss'.*\(and build's dj_cutoff, itmax, pfix\), besides terramesh's own",
        ),
        ({"min_el": 4000, "q": 0.2}, TypeError, r"unknown option 'q' \(the guide's New York .* option is g\)"),
        ({"min_el": 4000, "fs": 3, "feature_size": 3}, TypeError, "same option"),
        ({"fs": 3}, SizingError, "min_edge_length"),
        (
            {"min_el": 4000, "fs": 3, "dis": 0.2},
            SizingError,
            r"distance function \(dis, .*feature size \(fs, .*mutually exclusive",
        ),
        ({"min_el": 4000, "wl": 30}, SizingError, "wavelength needs a DEM"),
        ({"min_el": 4000, "wl": 30, "slp": 20}, SizingError, "wavelength, slope need a DEM"),
        ({"min_el": 4000, "fs": 3, "fl": [1e4, 5e4]}, SizingError, r"give slope \(slp\) or channels \(ch\)"),
        ({"min_el": 4000, "dis": 0.2, "itmax": 5}, TypeError, "'itmax' is an option of build"),
        ({"min_el": 4000, "dis": 0.2, "pfix": [[-70.3, 42.6]]}, TypeError, "'pfix' is an option of build"),
        ({"min_el": "4 km", "dis": 0.2}, SizingError, "min_edge_length must be a positive number"),
        # OceanMesh2D's per-depth rows were refused as "must be a positive number", with no word of depth_bounds
        (
            {"min_el": 4000, "dis": 0.2, "max_el": [[2e4, 0, -100]]},
            SizingError,
            r"max_edge_length \(max_el\) .*depth_bounds",
        ),
        ({"min_el": 4000, "dis": 0.2, "wl": [[30, -10, -1e4]]}, SizingError, r"wavelength \(wl\) takes one number"),
        ({"min_el": 4000, "max_el": "big", "dis": 0.2}, SizingError, "max_edge_length must be a positive number"),
        ({"min_el": 4000, "dis": 0.2, "g": "0.2"}, SizingError, "grade must be a positive number"),
        ({"min_el": 4000, "dis": 0.2, "dt": "10"}, SizingError, "dt must be a number of seconds"),  # was taken
    ],
)
def test_bad_options_are_named(shared_data, options, error, message):
    with pytest.raises(error, match=message):
        tm.coastal.size_function((-71.0, -69.0, 41.0, 43.0), shared_data / "coast" / "GSHHS_l_L1.shp", **options)


def test_a_dem_of_depths_is_named(shared_data):
    # ETOPO1 with its sign turned, as a depth grid (positive down) without a CF attribute would be read: 2 % of
    # the water below 0 m (98 % as it is); the wavelength and CFL functions took the sea for land, silently
    box = (-71.5, -66.0, 41.0, 45.0)
    land = shared_data / "coast" / "GSHHS_l_L1.shp"
    dem = tm.coastal.read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", box)
    depths = tm.coastal.DEM(dem.lon, dem.lat, -dem.elevation, source="ETOPO1 negated")
    with pytest.warns(TerrameshWarning, match=r"only \d+% of the shoreline's water lies below 0 m .* negate it"):
        tm.coastal.size_function(box, land, depths, min_el=5000, max_el=30e3, dis=0.3, wl=30)
    tm.coastal.size_function(box, land, dem, min_el=5000, max_el=30e3, dis=0.3, wl=30)  # no warning
    # all of it: a sea 20-120 m deep as depths, the land as negative depths; it said the DEM had no water at all
    lon = lat = np.linspace(-0.5, 0.5, 51)
    east = np.meshgrid(lon, lat, indexing="ij")[0]
    depths = tm.coastal.DEM(lon, lat, np.where(east < 0, -10.0, 20.0 + 200.0 * east), source="depths")
    with pytest.raises(SizingError, match=r"none of the shoreline's water lies below 0 m in the DEM \(depths\), only"):
        tm.coastal.size_function((-0.5, 0.5, -0.5, 0.5), shapely.box(-1, -1, 0, 1), depths, min_el=2000, wl=30)


def test_a_dem_named_depth_that_holds_elevations_is_named(shared_data, tmp_path):
    # a NetCDF variable named "depth" without a positive attribute is read as depths; one that held elevations
    # turned the sea into land with only "negate it" as advice, wrong for a file: the warning now says how the
    # sign was chosen and how to choose the other
    import netCDF4

    box = (-71.5, -66.0, 41.0, 45.0)
    land = shared_data / "coast" / "GSHHS_l_L1.shp"
    dem = tm.coastal.read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", box)
    path = tmp_path / "named_depth.nc"
    with netCDF4.Dataset(path, "w") as out:
        out.createDimension("lat", dem.lat.size)
        out.createDimension("lon", dem.lon.size)
        out.createVariable("lat", "f8", ("lat",))[:] = dem.lat
        out.createVariable("lon", "f8", ("lon",))[:] = dem.lon
        out.createVariable("depth", "f4", ("lat", "lon"))[:] = dem.elevation.T
    named = tm.coastal.read_dem(path, box)
    expected = (
        r"only \d+% of the shoreline's water lies below 0 m in the DEM \(named_depth.nc\): named_depth.nc variable"
        r" 'depth' was read as depths \(positive down\) and negated: its name, as it has no positive attribute;"
        r" if that is wrong, read it with tm.coastal.read_dem\(path, bbox, positive='up'\) \(command line:"
        r" --dem-positive up\)"
    )
    with pytest.warns(TerrameshWarning, match=expected):
        tm.coastal.size_function(box, land, named, min_el=5000, max_el=30e3, dis=0.3, wl=30)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sizes = tm.coastal.size_function(
            box, land, tm.coastal.read_dem(path, box, positive="up"), min_el=5000, max_el=30e3, dis=0.3, wl=30
        )
    assert np.median(sizes.depth[sizes.water]) > 50
    # the other way round, the usual case: depths (positive down) under a name of elevations, no attribute
    with netCDF4.Dataset(path, "w") as out:
        out.createDimension("lat", dem.lat.size)
        out.createDimension("lon", dem.lon.size)
        out.createVariable("lat", "f8", ("lat",))[:] = dem.lat
        out.createVariable("lon", "f8", ("lon",))[:] = dem.lon
        out.createVariable("z", "f4", ("lat", "lon"))[:] = -dem.elevation.T
    with pytest.warns(
        TerrameshWarning, match=r"read as elevation .* positive='down'\) \(command line: --dem-positive down"
    ):
        tm.coastal.size_function(box, land, tm.coastal.read_dem(path, box), min_el=5000, max_el=30e3, dis=0.3, wl=30)


def test_depth_and_polygon_bounds_reach_the_size_function(shared_data):
    # listed in the README among the size function's pieces, they were bound_sizes' alone: size_function refused them
    box = (-71.0, -69.0, 41.0, 43.0)
    land = shared_data / "coast" / "GSHHS_l_L1.shp"
    dem = shared_data / "dem" / "ETOPO1_0.1.grd"
    plain = tm.coastal.size_function(box, land, dem, min_el=1000, max_el=20e3, dis=0.3)
    cape = shapely.box(-70.2, 41.5, -69.8, 42.1)
    bounded = tm.coastal.size_function(
        box,
        land,
        dem,
        min_el=1000,
        max_el=20e3,
        dis=0.3,
        depth_bounds=[(None, 3000, 0, 50)],
        polygon_bounds=[(cape, None, 1500)],
    )
    shallow = plain.water & (plain.depth >= 0) & (plain.depth < 50)
    assert plain.sizes[shallow].max() > 3000 and bounded.sizes[shallow].max() <= 3000 * (1 + 1e-9)
    lon, lat = np.meshgrid(bounded.grid.lon, bounded.grid.lat, indexing="ij")
    inside = (lon > -70.2) & (lon < -69.8) & (lat > 41.5) & (lat < 42.1)
    assert plain.sizes[inside].max() > 1500 and bounded.sizes[inside].max() <= 1500 * (1 + 1e-9)
    assert np.all(bounded.sizes <= plain.sizes * (1 + 1e-12))  # bounds, then grading: sizes only go down
    with pytest.raises(SizingError, match="depth_bounds needs a DEM"):
        tm.coastal.size_function(box, land, min_el=1000, dis=0.3, depth_bounds=[(None, 3000, 0, 50)])


def test_thalwegs_without_the_channel_function_are_refused(shared_data):
    # they were ignored without a word
    with pytest.raises(SizingError, match=r"thalwegs are the channel function's \(ch\)"):
        tm.coastal.size_function(
            (-71.0, -69.0, 41.0, 43.0),
            shared_data / "coast" / "GSHHS_l_L1.shp",
            min_el=4000,
            dis=0.3,
            thalwegs=[np.array([[-70.5, 42.0], [-70.4, 42.1]])],
        )


def test_a_grade_given_in_percent_is_named(shared_data):
    with pytest.warns(TerrameshWarning, match=r"g = 20 lets the size grow by 20 m per metre.* give g = 0.2"):
        tm.coastal.size_function(
            (-71.0, -69.0, 41.0, 43.0), shared_data / "coast" / "GSHHS_l_L1.shp", min_el=4000, dis=0.3, g=20
        )


def test_bbox_outside_the_dem_is_refused(shared_data):
    with pytest.raises((GeometryError, SizingError, ValueError), match="overlap|outside|cover"):
        tm.coastal.size_function((10.0, 11.0, 50.0, 51.0), dem=shared_data / "dem" / "CUDEM_equal.nc", min_el=100, fs=3)


def test_a_dem_read_elsewhere_is_checked_against_the_bbox(shared_data):
    # a DEM object was sampled as it came: Sabine Lake's DEM gave Massachusetts Bay 2.3 m everywhere
    massachusetts_bay = (-71.0, -69.5, 41.2, 42.5)
    sabine_lake = tm.coastal.read_dem(shared_data / "dem" / "CUDEM_equal.nc")
    with pytest.raises(GeometryError, match=r"bbox \(-71.0, -69.5, 41.2, 42.5\) does not overlap the DEM CUDEM_equal"):
        tm.coastal.build(massachusetts_bay, shared_data / "coast" / "GSHHS_l_L1.shp", sabine_lake, min_el=3000, fs=3)
    etopo1 = shared_data / "dem" / "ETOPO1_0.1.grd"
    part = tm.coastal.read_dem(etopo1, (-70.5, -69.0, 41.0, 43.0))
    gshhs = shared_data / "coast" / "GSHHS_l_L1.shp"
    with pytest.warns(TerrameshWarning, match=r"DEM ETOPO1_0.1.grd covers lon -70.8..-68.7, .* less than the bbox"):
        tm.coastal.size_function(massachusetts_bay, gshhs, part, min_el=3000, wl=30)
    whole = tm.coastal.read_dem(etopo1)  # 0..360: the bbox's longitudes a turn apart, over it all the same
    assert whole.bbox[:2] == (0.0, 360.0)
    sizes = tm.coastal.size_function(massachusetts_bay, gshhs, whole, min_el=3000, wl=30)
    read_for_the_box = tm.coastal.size_function(massachusetts_bay, gshhs, etopo1, min_el=3000, wl=30)
    assert np.allclose(sizes.depth, read_for_the_box.depth)


def test_a_shoreline_cut_to_another_box_is_refused(shared_data):
    # the mesh is the shoreline's water: one cut to a larger box was meshed over it, sized beyond the size grid
    gshhs = shared_data / "coast" / "GSHHS_l_L1.shp"
    box, larger = (-71.0, -69.5, 41.2, 42.5), (-71.5, -69.0, 41.0, 43.0)
    sizes = tm.coastal.size_function(box, tm.coastal.read_shoreline(gshhs, box, 3000), min_el=3000, fs=3)
    assert sizes.shoreline.bbox == box
    with pytest.raises(GeometryError, match=r"cut to the bbox \(-71.5, -69.0, 41.0, 43.0\), not \(-71.0, -69.5, 41.2"):
        tm.coastal.size_function(box, tm.coastal.read_shoreline(gshhs, larger, 3000), min_el=3000, fs=3)
    circle = shapely.Point(-70.3, 41.9).buffer(0.6, 64)
    tm.coastal.size_function(circle, tm.coastal.read_shoreline(gshhs, circle, 3000), min_el=3000, fs=3)
    square = shapely.box(*circle.bounds)
    with pytest.raises(GeometryError, match="cut to another region than the one asked for"):
        tm.coastal.size_function(square, tm.coastal.read_shoreline(gshhs, circle, 3000), min_el=3000, fs=3)


def test_dem_without_water_is_refused(shared_data):
    dem = tm.coastal.DEM(np.linspace(0, 0.2, 30), np.linspace(0, 0.2, 30), np.full((30, 30), 5.0))
    water = __import__("shapely").box(0.05, 0.05, 0.1, 0.1)
    land = __import__("shapely").box(-1, -1, 1, 1).difference(water)
    with pytest.raises(SizingError, match="no water"):
        tm.coastal.size_function((0, 0.2, 0, 0.2), land, dem, min_el=500, wl=30)


def test_size_below_the_dem_resolution_warns(shared_data):
    with pytest.warns(TerrameshWarning, match="finer than the DEM"):
        tm.coastal.size_function(
            (-94.0, -93.95, 29.75, 29.8), dem=shared_data / "dem" / "CUDEM_equal.nc", min_el=10, max_el=200, wl=60
        )


@pytest.fixture(scope="module")
def shallow_channel():
    """Land west of 0° E; sea 5 m deep at the coast deepening eastward, a V channel 40 m deep along the equator."""
    lon = lat = np.linspace(-0.5, 0.5, 101)
    east, north = np.meshgrid(lon, lat, indexing="ij")
    elevation = -(5 + 100 * east.clip(0)) - 40 * np.maximum(0, 1 - np.abs(north) / 0.05)
    dem = tm.coastal.DEM(lon, lat, np.where(east < 0, 10.0, elevation))
    thalwegs = [np.column_stack([np.linspace(0.02, 0.28, 30), np.zeros(30)])]
    return shapely.box(-1.0, -1.0, 0.0, 1.0), dem, thalwegs


def test_channels_are_resolved_in_shallow_water(shallow_channel):
    """§3.4 over eq. 7 without its 100 m cut-off: a channel 45-73 m deep gets sizes (it got none)."""
    land, dem, thalwegs = shallow_channel
    sizes = tm.coastal.size_function((-0.2, 0.3, -0.2, 0.2), land, dem, min_el=1000, slp=20, ch=50, thalwegs=thalwegs)
    assert sizes.depth.max() < 100
    slope = tm.coastal.sizes.slope_size(sizes.grid, sizes.depth, elements_per_slope=20, min_depth=0)
    expected = tm.coastal.sizes.channel_size(sizes.grid, sizes.depth, slope, percentile=50, thalwegs=thalwegs)
    np.testing.assert_array_equal(sizes.fields["ch"], expected.astype(np.float32))
    assert np.isfinite(sizes.fields["ch"]).sum() >= 20
    assert np.isinf(sizes.fields["slp"]).all()  # the slope function itself keeps its cut-off


def test_zero_elements_per_slope_is_refused(shallow_channel):
    land, dem, _ = shallow_channel
    with pytest.raises(SizingError, match="elements_per_slope"):
        tm.coastal.size_function((-0.2, 0.3, -0.2, 0.2), land, dem, min_el=1000, slp=0)


def test_open_water_box_takes_its_sizes_from_max_el_and_the_dem(shared_data):
    """A box over the shelf break off New Jersey holds no land: refused unless asked for, then meshed as open sea."""
    box, land, dem = (-73.0, -72.0, 38.5, 39.5), shared_data / "coast" / "GSHHS_l_L1.shp", shared_data / "dem"
    with pytest.raises(GeometryError, match=r"no land polygon in the bbox .*require_land=False"):
        tm.coastal.size_function(box, land, min_el=3000, max_el=6000, dis=0.3)
    # no coast: dis has nothing to act on, and max_el is the size everywhere
    sizes = tm.coastal.size_function(box, land, min_el=3000, max_el=6000, dis=0.3, g=0.2, require_land=False)
    assert sizes.fields == {} and np.all(sizes.sizes == 6000.0)
    # the DEM's functions still act: the slope refines the shelf break (60 to 3,000 m deep here) down to min_el
    options = dict(min_el=3000, max_el=20e3, slp=20, wl=30, require_land=False)
    sloped = tm.coastal.size_function(box, land, dem / "ETOPO1_0.1.grd", g=np.inf, **options)  # not graded
    assert set(sloped.fields) == {"slp", "wl"}
    expected = np.clip(np.minimum(sloped.fields["slp"], sloped.fields["wl"]), 3000.0, 20e3)
    np.testing.assert_allclose(sloped.sizes, expected)
    assert sloped.sizes.min() == 3000.0 and sloped.sizes.max() == 20e3
    # graded by default at g = 0.2 (OceanMesh2D's default): never coarser, finer where the slope jumps
    graded = tm.coastal.size_function(box, land, dem / "ETOPO1_0.1.grd", **options)
    assert np.all(graded.sizes <= sloped.sizes * (1 + 1e-12)) and (graded.sizes < 0.9 * sloped.sizes).any()
    with pytest.raises(SizingError, match=r"open water, where dis and fs have no coast to act on: give max_el"):
        tm.coastal.size_function(box, land, min_el=3000, dis=0.3, require_land=False)
    with pytest.raises(SizingError, match=r"dt = 0 .* the box \(-73.0, -72.0, 38.5, 39.5\) is open water"):
        tm.coastal.size_function(box, land, dem / "ETOPO1_0.1.grd", dis=0.3, dt=0, **options)
    mesh = tm.coastal.build(box, land, dem / "ETOPO1_0.1.grd", g=0.2, **options)
    assert_solver_ready(mesh)
    assert np.all(mesh.depth > 0)
    boundaries = tm.coastal.make_boundaries(mesh).boundaries
    assert len(boundaries.open) == 1 and boundaries.land == []  # the whole rim is open sea
    (rim,), _ = boundary_loops(mesh.points, mesh.cells)
    assert set(boundaries.open[0].nodes) == set(rim)


def test_the_sizes_are_the_minimum_of_the_fields_in_double_precision_kept_in_single(shared_data):
    """Each field is folded into the sizes as it is made and kept as float32 (3.40 GB at the peak of the guide's
    §5.3 box at 1 km when all were kept whole, 2.27 GB now): the sizes are still the double-precision minimum."""
    box, land, dem = (-73.0, -72.0, 38.5, 39.5), shared_data / "coast" / "GSHHS_l_L1.shp", shared_data / "dem"
    sizes = tm.coastal.size_function(
        box, land, dem / "ETOPO1_0.1.grd", min_el=3000, max_el=20e3, slp=20, wl=30, g=np.inf, require_land=False
    )
    slope = tm.coastal.sizes.slope_size(sizes.grid, sizes.depth, elements_per_slope=20)
    wavelength = tm.coastal.sizes.wavelength_size(sizes.depth, elements_per_wavelength=30)
    assert {name: values.dtype for name, values in sizes.fields.items()} == {"slp": np.float32, "wl": np.float32}
    np.testing.assert_array_equal(sizes.fields["slp"], slope.astype(np.float32))
    np.testing.assert_array_equal(sizes.fields["wl"], wavelength.astype(np.float32))
    np.testing.assert_array_equal(sizes.sizes, np.clip(np.minimum(slope, wavelength), 3000.0, 20e3))
    assert sizes.sizes.dtype == np.float64 and np.isfinite(slope).any()


def _ground_grades(sizes):
    """The largest |change of size| per ground metre between neighbours along a row (east) and a column (north)."""
    grid, h = sizes.grid, sizes.sizes
    north = np.abs(np.diff(h, axis=1)) / np.diff(EARTH_RADIUS * np.radians(grid.lat))[None, :]
    east = np.abs(np.diff(h, axis=0)) / grid.ground_step[None, :]
    return float(north.max()), float(east.max())


@pytest.mark.parametrize(
    ("bbox", "land", "max_el"),
    [
        ((0, 10, 78, 84), shapely.box(-1, 83.7, 11, 86), 50e3),  # 0.254 north before
        ((0, 20, 70, 78), shapely.box(-1, 77.5, 21, 86), 300e3),
        ((0, 10, -66, -58), shapely.box(-1, -70, 11, -65.5), 50e3),
        ((0, 10, 40, 48), shapely.box(-1, 47.5, 11, 50), 50e3),
    ],
    ids=["82 N", "75 N, 300 km", "62 S", "45 N"],
)
def test_the_grade_holds_on_the_ground_along_the_parallels_and_the_meridians(bbox, land, max_el):
    """g on the ground both ways: graded on the Mercator plane at g, the grade along the meridians was up to
    h |tan(lat)| / R more where sizes grow equatorward, 0.254 for 0.2 at 82 N with sizes to 50 km."""
    sizes = tm.coastal.size_function(bbox, land, min_el=2000.0, dis=1.0, max_el=max_el, g=0.2)
    north, east = _ground_grades(sizes)
    assert east <= 0.2 * 1.01  # the grid's own rounding
    assert north <= 0.2 * 1.01
    assert north >= 0.19  # not finer than asked (the coast runs east-west: the sizes grow north or south)


def test_a_straight_coast_takes_the_feature_size_from_the_distance(shared_data):
    """Pinned: fs on a coast with no medial axis was inf everywhere ("no size function was asked for")."""
    land = shapely.box(-1, -1, 0.2, 2)  # a straight coast, open sea to the east
    with pytest.warns(TerrameshWarning, match=r"no node is on the approximate medial axis .* h0 \+ 0.3 d"):
        sizes = tm.coastal.size_function((0, 1, 0, 1), land, min_el=1000.0, fs=3, g=0.3)
    distance = tm.coastal.sizes.distance_to_coastline(sizes.grid, sizes.shoreline.coastline)
    np.testing.assert_allclose(sizes.fields["fs"], 1000.0 + 0.3 * distance)  # OceanMesh2D's featfx: h0 + g |d|
    assert sizes.sizes[distance < 2000].max() <= 1000.0 + 0.3 * 2000.0
    lon = np.linspace(-0.5, 1.5, 41)
    flat = tm.coastal.DEM(lon, lon, np.full((41, 41), -500.0))
    with pytest.warns(TerrameshWarning, match="medial axis"):
        timed = tm.coastal.size_function((0, 1, 0, 1), land, flat, min_el=1000.0, fs=3, dt=0)  # eq. 12 has f_hd
    assert 0 < timed.dt < np.inf
    with pytest.raises(SizingError, match=r"^slp is inf everywhere: the slope function is off where the water is"):
        tm.coastal.size_function((0, 1, 0, 1), land, flat, min_el=1000.0, slp=20)


@pytest.mark.parametrize("min_el", [8e3, 10e3, 12e3])
def test_islands_nearly_touching_are_meshed_without_overlap(shared_data, min_el):
    """The Bahamas at 8-12 km (Natural Earth 1:50m): a vertex projected onto one island beside another's left
    their boundary edges crossing (2 to 6 pairs, 1.7e5 m² covered twice), and the build raised."""
    land = shared_data / "coast" / "ne_50m_land.shp"
    mesh = tm.coastal.build((-85, -65, 15, 30), land, min_el=min_el, max_el=100e3, fs=3, g=0.2)
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.quality.triangle_quality(mesh.points, mesh.cells, geographic=True).min() >= 0.5


def test_each_stage_of_a_build_says_so_with_its_time(caplog, shared_data):
    import logging

    # the size functions and the clean-up of §5.3 ran 19 s and 6 s without a line
    with caplog.at_level(logging.INFO, logger="terramesh"):
        tm.coastal.build((-71.0, -69.0, 41.0, 43.0), shared_data / "coast" / "GSHHS_l_L1.shp", min_el=4000, fs=3)
    for line in ("read the shoreline in", "size functions fs in", "sizes bounded and graded in", "repairing and"):
        assert line in caplog.text


def test_a_build_in_strips_is_valid_and_like_the_whole(shared_data):
    # build had no way to mesh in parts: a coastal user had to assemble the size function, the domain and
    # generate_mesh_parallel by hand, losing the repair, the clean-up, the depths and the lon/lat points
    box, shoreline = (-71.0, -69.0, 41.0, 43.0), shared_data / "coast" / "GSHHS_l_L1.shp"
    whole = tm.coastal.build(box, shoreline, min_el=2000, fs=3)
    strips = tm.coastal.build(box, shoreline, min_el=2000, fs=3, parts=3)
    assert len(strips.info["parts"]) == 3 and strips.crs == "EPSG:4326"
    assert tm.cleanup.mesh_problems(strips) == []
    assert abs(strips.n_points - whole.n_points) < 0.05 * whole.n_points
    worst = tm.quality.summary(strips).min
    assert worst > min(0.5, tm.quality.summary(whole).min - 0.1)


def test_a_build_carries_the_adcirc_boundaries_a_solver_needs(shared_data, tmp_path):
    # the fort.14 of build (as the README's first snippet writes it) had no open boundary: the CLI alone made them
    box, shoreline = (-71.0, -69.0, 41.0, 43.0), shared_data / "coast" / "GSHHS_l_L1.shp"
    mesh = tm.coastal.build(box, shoreline, min_el=4000, fs=3)
    mesh.point_data["depth"] = np.nan_to_num(mesh.depth, nan=0.0)
    mesh.write(tmp_path / "fort.14")
    written = tm.read_mesh(tmp_path / "fort.14")
    assert len(written.boundaries.open) >= 1 and len(written.boundaries.land) >= 1
    for boundary in written.boundaries.open:  # no DEM: open on the box's edge alone
        lon, lat = written.points[boundary.nodes].T
        assert np.all(np.isclose(lon, -71) | np.isclose(lon, -69) | np.isclose(lat, 41) | np.isclose(lat, 43))
    assert mesh.info["boundaries"]["options"]["open_by"] == "bbox" and "boundaries" in mesh.info["timings"]
    assert tm.coastal.build(box, shoreline, min_el=4000, fs=3, boundaries=False).boundaries is None
    islands_as_20 = tm.coastal.build(box, shoreline, min_el=4000, fs=3, boundaries={"island_ibtype": 20})
    assert {land.ibtype for land in islands_as_20.boundaries.land} == {20}


BAD_BOUNDARIES = [
    ("yes", r"build: boundaries must be True, False or a dict of make_boundaries options .* got 'yes'"),
    (None, r"boundaries must be True, False or a dict .* got None"),
    ({"dry_dpeth": 1.0}, r"make_boundaries does not take: 'dry_dpeth' \(did you mean 'dry_depth'\?\); its options"),
    ({"depth_threshold": "100"}, r"build: boundaries: depth_threshold must be a number of metres"),
    ({"open_by": "depth", "depth_threshold": np.inf}, r"build: boundaries: open_by=\"depth\" with depth_threshold=inf"),
]


@pytest.mark.parametrize(("boundaries", "message"), BAD_BOUNDARIES)
def test_a_bad_boundaries_argument_is_refused_before_meshing(monkeypatch, boundaries, message):
    # "yes" failed after the meshing, with a ValueError from a dict update ("dictionary update sequence element")
    build_module = sys.modules["terramesh.coastal.build"]  # the package's name build is the function

    def no_sizes(*args, **kwargs):
        pytest.fail("size_function was called: boundaries must be checked first")

    monkeypatch.setattr(build_module, "size_function", no_sizes)
    with pytest.raises(MeshValidityError, match=message):
        tm.coastal.build((0, 0.3, 0, 0.3), None, min_el=2000, boundaries=boundaries)


GAUGES = np.array([[-70.3, 42.6], [-69.5, 42.2]])
"""Two points in the water of the Gulf of Maine box (-71, -69, 41, 43), lon/lat."""


def test_fixed_points_are_vertices_at_exactly_the_given_coordinates(shared_data):
    # build had no pfix, and the clean-up it runs moved fixed points by up to 2.5 km
    box, shoreline = (-71.0, -69.0, 41.0, 43.0), shared_data / "coast" / "GSHHS_l_L1.shp"
    x, y = to_mercator(*GAUGES.T)
    assert not np.array_equal(np.column_stack(tm.coastal.from_mercator(x, y)), GAUGES)  # the round trip is off

    mesh = tm.coastal.build(box, shoreline, min_el=4000, fs=3, fixed_points=GAUGES)

    index = mesh.info["fixed_points"]
    np.testing.assert_array_equal(mesh.points[index], GAUGES)
    assert np.all(np.isin(index, mesh.cells))
    assert tm.cleanup.mesh_problems(mesh) == []
    assert mesh.info["repair"].smoothed_points > 0  # the clean-up ran
    alias = tm.coastal.build(box, shoreline, min_el=4000, fs=3, pfix=GAUGES)  # the guide's name
    np.testing.assert_array_equal(alias.points, mesh.points)
    np.testing.assert_array_equal(alias.cells, mesh.cells)
    for options in ({"parts": 2}, {"clean_quality": None}):  # meshed in strips; repaired but not cleaned
        other = tm.coastal.build(box, shoreline, min_el=4000, fs=3, pfix=GAUGES, **options)
        np.testing.assert_array_equal(other.points[other.info["fixed_points"]], GAUGES)
        assert tm.cleanup.mesh_problems(other) == []
    # renumbering kept the old indices, and a time step's removals took gauges away without a word
    renumbered = tm.coastal.renumber(mesh)
    np.testing.assert_array_equal(renumbered.points[renumbered.info["fixed_points"]], GAUGES)
    mesh.point_data["depth"] = np.full(mesh.n_points, 50.0)
    stepped = tm.coastal.enforce_timestep(mesh, 100.0)
    assert stepped.info["timestep"]["removed"] > 0.2 * mesh.n_points
    np.testing.assert_array_equal(stepped.points[stepped.info["fixed_points"]], GAUGES)
    assert tm.cleanup.mesh_problems(stepped) == []


@pytest.mark.parametrize(
    ("points", "error", "message"),
    [
        (
            [[-70.3, 42.6], [-70.9, 42.5]],
            GeometryError,
            r"1 of the 2 fixed points lie on land.*fixed point 1\) at lon -70.9",
        ),
        ([[-68.5, 42.0]], GeometryError, r"outside the box.*fixed point 0\) at lon -68.5, lat 42.0"),
        ([[-70.3, 42.6], [-70.3, 42.6]], GeometryError, "fixed points 0 and 1 .* are closer than"),
        ([[-70.3, 42.6, 0.0]], GeometryError, r"shape \(k, 2\)"),
    ],
)
def test_fixed_points_on_land_or_outside_the_box_are_refused(shared_data, points, error, message):
    with pytest.raises(error, match=message):
        tm.coastal.build(
            (-71.0, -69.0, 41.0, 43.0), shared_data / "coast" / "GSHHS_l_L1.shp", min_el=4000, fs=3, pfix=points
        )


def test_pfix_and_fixed_points_together_are_refused(shared_data):
    with pytest.raises(TypeError, match="'pfix' and 'fixed_points' are the same option"):
        tm.coastal.build(
            (-71.0, -69.0, 41.0, 43.0),
            shared_data / "coast" / "GSHHS_l_L1.shp",
            min_el=4000,
            fs=3,
            pfix=GAUGES,
            fixed_points=GAUGES,
        )


def test_a_min_el_in_kilometres_is_refused_before_the_shoreline_is_read(monkeypatch, shared_data):
    # 0.25 for 250 m: the coast was resampled at 0.125 m first (100 s and 8 GB, or a MemoryError traceback)
    # and the grid's node count refused it only then
    build_module = sys.modules["terramesh.coastal.build"]

    def unread(*args, **kwargs):
        raise AssertionError("the shoreline was read")

    monkeypatch.setattr(build_module, "as_shoreline", unread)
    with pytest.raises(SizingError, match=r"a 0.25 m grid over this bbox has .* nodes, more than 200,000,000"):
        tm.coastal.build((166, 176, -48, -40), shared_data / "coast" / "ne_10m_land.shp", min_el=0.25, max_el=20, fs=3)
    # and min_el above max_el, which the bounds refused after the shoreline was read
    with pytest.raises(SizingError, match="min_edge_length 2000 exceeds max_edge_length 1000"):
        tm.coastal.build(
            (166, 176, -48, -40), shared_data / "coast" / "ne_10m_land.shp", min_el=2000, max_el=1000, fs=3
        )


def test_a_sliver_hole_does_not_turn_inside_out_in_the_last_smoothing(shared_data):
    # upper Chesapeake at 2 km, seed 1: a hole of three vertices (land between coast segments nearly
    # touching, 18 m2 across 2 km) turned inside out when one vertex slid across the other two's edge, no
    # edges crossing; the cells round it lay over each other and clean could not mend it (an error)
    coast, dem = shared_data / "coast" / "GSHHS_l_L1.shp", shared_data / "dem" / "ETOPO1_0.1.grd"
    mesh = tm.coastal.build((-77, -74, 35, 39), coast, dem, min_el=2000, max_el=20000, fs=3, slp=10, seed=1)
    assert tm.cleanup.mesh_problems(mesh) == []


def test_sizes_large_of_themselves_are_not_blamed_on_dt(shared_data):
    # offshore, wl without max_el: 246 km sizes with or without dt=1, which was refused as "Is dt in seconds?"
    box, land = (-48, -42, 30, 36), shared_data / "coast" / "GSHHS_l_L1.shp"
    dem = shared_data / "dem" / "ETOPO1_0.1.grd"
    plain = tm.coastal.size_function(box, land, dem, min_el=5e3, wl=30, require_land=False)
    stepped = tm.coastal.size_function(box, land, dem, min_el=5e3, wl=30, dt=1.0, require_land=False)
    np.testing.assert_array_equal(stepped.sizes, plain.sizes)


@pytest.mark.parametrize("dt", [300, 600])
def test_a_time_step_that_leaves_the_box_no_mesh_is_named(shared_data, dt):
    # dt=600 (minutes meant?) failed in the clean-up as "clean left no cell"; dt=300 gave a mesh of 26 vertices
    with pytest.raises(SizingError, match=rf"dt = {dt} s asks for elements of \d+ km .* Is dt in seconds"):
        tm.coastal.size_function(
            (-71, -65, 41, 45.5),
            shared_data / "coast" / "GSHHS_l_L1.shp",
            shared_data / "dem" / "ETOPO1_0.1.grd",
            min_el=2000,
            max_el=20e3,
            fs=3,
            dt=dt,
        )
