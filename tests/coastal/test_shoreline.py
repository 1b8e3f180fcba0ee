"""Shoreline: reading, clipping, classification, resampling, DEM contours, failures."""

import numpy as np
import pyogrio
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from terramesh.coastal.dem import DEM, read_dem
from terramesh.coastal.projection import to_mercator
from terramesh.coastal.shoreline import Shoreline, read_shoreline, segment_lengths
from terramesh.errors import GeometryError, MeshFormatError, SizingError, TerrameshWarning
from terramesh.geometry import Polygon

NZ = (166.0, 176.0, -48.0, -40.0)
H0 = 1000.0


def _mercator(geometry):
    return shapely.transform(geometry, lambda xy: np.column_stack(to_mercator(xy[:, 0], xy[:, 1])))


def _segments_m(lines):
    """Ground lengths (m) of every segment of every line."""
    coords, index = shapely.get_coordinates(shapely.get_parts(lines), return_index=True)
    same = index[1:] == index[:-1]
    return segment_lengths(coords[:-1][same], coords[1:][same])


def _box(bbox):
    return shapely.box(bbox[0], bbox[2], bbox[1], bbox[3])


def _write(path, geometries, crs="EPSG:4326", geometry_type="Polygon"):
    pyogrio.raw.write(
        path, shapely.to_wkb(np.asarray(geometries, dtype=object)), [], [], geometry_type=geometry_type, crs=crs
    )
    return path


def assert_tiles_region(shore, rel=1e-9):
    """Land and water are valid, disjoint and cover the region, measured on the Mercator plane."""
    assert shore.land.is_valid and shore.water.is_valid
    region = _mercator(shore.region).area
    land, water = _mercator(shore.land), _mercator(shore.water)
    assert land.area + water.area == pytest.approx(region, rel=rel)
    assert shapely.intersection(land, water).area <= rel * region
    assert shapely.union_all([land, water]).area == pytest.approx(region, rel=rel)


def assert_classified(shore):
    """Mainland touches the region's edge, islands do not; the open boundary is on the edge, the coastline off it."""
    edge = shapely.boundary(shore.region)
    shapely.prepare(edge)
    assert shapely.dwithin(edge, np.asarray(shore.mainland.geoms), 1e-9).all()
    assert not shapely.intersects(edge, np.asarray(shore.islands.geoms)).any()
    coords, index = shapely.get_coordinates(shapely.get_parts(shore.open_boundary), return_index=True)
    same = index[1:] == index[:-1]
    middles = 0.5 * (coords[:-1][same] + coords[1:][same])
    assert shapely.dwithin(edge, shapely.points(np.vstack([coords, middles])), 1e-9).all()
    # the coastline leaves the edge only at its ends
    inner = np.concatenate([shapely.get_coordinates(line)[1:-1] for line in shore.coastline.geoms])
    assert not shapely.intersects(edge, shapely.points(inner)).any()


@pytest.fixture(scope="module")
def gshhs_nz(shared_data):
    return Shoreline.read(shared_data / "coast" / "GSHHS_l_L1.shp", NZ, H0)


@pytest.fixture(scope="module")
def ne10_nz(shared_data):
    return Shoreline.read(shared_data / "coast" / "ne_10m_land.shp", NZ, H0)


# ----------------------------------------------------------------------------------------------------------------
# real coastlines


@pytest.mark.parametrize("name", ["gshhs_nz", "ne10_nz"])
def test_new_zealand(request, name):
    shore = request.getfixturevalue(name)
    assert shore.bbox == NZ and shore.min_edge_length == H0
    assert_tiles_region(shore)
    assert_classified(shore)
    # The North Island reaches the box's north edge; the South Island and Stewart Island are inside.
    assert len(shore.mainland.geoms) >= 1
    north_island = shapely.Point(175.5, -40.5)
    assert any(part.contains(north_island) for part in shore.mainland.geoms)
    for town in [(169.5, -45.3), (172.0, -43.6), (167.8, -47.1)]:  # Otago, Canterbury, Stewart Island
        assert any(part.contains(shapely.Point(town)) for part in shore.islands.geoms)
    assert shore.water.contains(shapely.Point(174.5, -41.35))  # Cook Strait
    assert shore.water.contains(shapely.Point(168.0, -44.0))  # Tasman Sea
    # South Island is about 150,000 km**2
    south = max(shore.islands.geoms, key=lambda part: part.area)
    assert _mercator(south).area * np.cos(np.radians(43.8)) ** 2 == pytest.approx(150e9, rel=0.1)


def test_the_two_coastlines_agree(gshhs_nz, ne10_nz):
    a, b = _mercator(gshhs_nz.land), _mercator(ne10_nz.land)
    assert shapely.symmetric_difference(a, b).area < 0.07 * a.area  # GSHHS-l is coarse (about 5 % here)


@pytest.mark.parametrize("name", ["gshhs_nz", "ne10_nz"])
def test_coastline_is_resampled_at_half_h0(request, name):
    """GSHHS-l is sparser than h0 / 2 (densified) and ne_10m denser (decimated): both come out at h0 / 2."""
    shore = request.getfixturevalue(name)
    length = _segments_m(shore.coastline)
    assert len(length) > 5000
    assert np.mean((length >= H0 / 4) & (length <= H0)) > 0.98
    assert np.median(length) == pytest.approx(H0 / 2, rel=0.02)
    assert length.max() <= 0.51 * H0
    assert _segments_m(shore.open_boundary).max() <= 0.501 * H0


def test_domain_is_the_water_on_the_mercator_plane(gshhs_nz):
    domain = gshhs_nz.domain()
    assert isinstance(domain, Polygon)
    assert domain.geometry.area == pytest.approx(_mercator(gshhs_nz.water).area, rel=1e-6)
    inside = np.column_stack(to_mercator([168.0, 169.5], [-44.0, -45.3]))  # Tasman Sea, Otago
    assert list(np.sign(domain.distance(inside))) == [-1.0, 1.0]


def test_domain_separates_rings_that_touch_at_a_point():
    """Shapely allows holes touching at a vertex; terramesh's Polygon does not: domain() erodes the water a little."""
    shore = Shoreline(shapely.box(-1.0, -1.0, 0.0, 1.0), (-0.5, 0.5, -0.5, 0.5), 5000.0)
    holes = [shapely.box(0.1, 0.1, 0.2, 0.2).exterior.coords, shapely.box(0.2, 0.2, 0.3, 0.3).exterior.coords]
    shore.water = shapely.Polygon(shapely.box(0.0, 0.0, 0.4, 0.4).exterior.coords, holes)
    domain = shore.domain()
    assert domain.geometry.area == pytest.approx(_mercator(shore.water).area, rel=1e-4)  # eroded by 1e-4 h0


def test_gshhs_atlantic_box(shared_data):
    shore = read_shoreline(shared_data / "coast" / "GSHHS_l_L1.shp", (-100, -50, 10, 60), 5000.0)
    assert_tiles_region(shore)
    assert shore.water.contains(shapely.Point(-90.0, 25.0))  # Gulf of Mexico
    assert shore.land.contains(shapely.Point(-98.0, 38.5))  # Kansas
    assert any(part.contains(shapely.Point(-77.3, 18.1)) for part in shore.islands.geoms)  # Jamaica


def test_box_in_0_360_and_across_the_antimeridian(shared_data):
    path = shared_data / "coast" / "GSHHS_l_L1.shp"
    same = Shoreline.read(path, (260, 310, 10, 60), 5000.0)
    assert same.bbox == (-100.0, -50.0, 10.0, 60.0)
    fiji = Shoreline.read(path, (170, 190, -20, -10), 2000.0)
    lon_min, _, lon_max, _ = fiji.land.bounds
    assert lon_min > 170 and lon_max > 180  # Fiji and Samoa, east of the antimeridian, at lon > 180
    assert fiji.land.contains(shapely.Point(178.0, -17.8))  # Viti Levu
    assert_tiles_region(fiji)


def test_file_in_0_360_with_a_minus_180_180_box(tmp_path):
    path = _write(tmp_path / "east.gpkg", [shapely.box(200.0, 0.0, 201.0, 1.0)])
    shore = Shoreline.read(path, (-160.5, -158.0, -1.0, 2.0), 2000.0)
    assert shore.islands.bounds == pytest.approx((-160.0, 0.0, -159.0, 1.0), abs=0.01)


# ----------------------------------------------------------------------------------------------------------------
# the synthetic oceanmesh files


def test_islands_in_the_irregular_ocean_polygon(shared_data):
    _, _, wkb, _ = pyogrio.raw.read(shared_data / "coast" / "ocean.shp")
    ocean = shapely.from_wkb(wkb)[0]
    shore = Shoreline.read(shared_data / "coast" / "islands.shp", ocean, 2000.0)
    assert shore.bbox == pytest.approx((ocean.bounds[0], ocean.bounds[2], ocean.bounds[1], ocean.bounds[3]))
    assert shore.region.area == pytest.approx(ocean.area, rel=1e-12)
    assert_tiles_region(shore)
    assert_classified(shore)
    assert len(shore.islands.geoms) >= 1 and len(shore.mainland.geoms) >= 1


def test_islands_in_a_box_are_all_islands(shared_data):
    shore = Shoreline.read(shared_data / "coast" / "islands.shp", (-0.5, 3.0, -1.0, 1.0), 2000.0)
    assert len(shore.mainland.geoms) == 0 and len(shore.islands.geoms) == 3  # two of the four overlap
    assert_tiles_region(shore)
    assert shore.open_boundary.length == pytest.approx(_box(shore.bbox).length, rel=1e-9)


# ----------------------------------------------------------------------------------------------------------------
# the processing


def test_small_islands_and_lakes_are_dropped():
    h0 = 1000.0
    side = h0 / 111319.49  # degrees of latitude (and longitude, at the equator) per h0
    mainland = shapely.box(-1.0, -1.0, 0.0, 1.0).difference(shapely.box(-0.5, 0.1, -0.5 + 1.5 * side, 0.1 + side))
    islands = [shapely.box(0.1 * k, 0.0, 0.1 * k + k * side, k * side) for k in (0.7, 1.5, 3.0, 6.0)]  # 0.5..36 h0**2
    land = [mainland, *islands]
    shore = Shoreline(land, (-0.9, 0.9, -0.9, 0.9), h0)
    assert len(shore.islands.geoms) == 2  # the 9 and 36 h0**2 ones
    assert len(shore.mainland.geoms) == 1 and len(shore.mainland.geoms[0].interiors) == 0  # the 1.5 h0**2 lake filled
    everything = Shoreline(land, (-0.9, 0.9, -0.9, 0.9), h0, minimum_island_area=0.0)
    assert len(everything.islands.geoms) == 4 and len(everything.mainland.geoms[0].interiors) == 1
    assert shore.minimum_island_area == 4.0 * h0**2


def test_resampling_keeps_the_shape():
    """A disk of radius 20 h0 keeps its area to within 1 %; the smoothing does not shrink it noticeably."""
    h0 = 500.0
    radius = 20 * h0 / 111319.49
    disk = shapely.Point(0.0, 0.0).buffer(radius, quad_segs=64)
    shore = Shoreline(disk, (-1.0, 1.0, -1.0, 1.0), h0)
    assert shore.islands.area == pytest.approx(disk.area, rel=0.01)
    assert len(shapely.get_coordinates(shore.coastline)) == pytest.approx(2 * np.pi * 20 * 2, rel=0.05)
    smoother = Shoreline(disk, (-1.0, 1.0, -1.0, 1.0), h0, smooth=3)
    assert smoother.islands.area == pytest.approx(disk.area, rel=0.01)


def test_self_intersecting_polygons_are_repaired_with_a_warning():
    bow_tie = shapely.Polygon([(0.0, 0.0), (0.5, 0.5), (0.5, 0.0), (0.0, 0.5)])
    mainland = shapely.box(-1.0, -1.0, -0.5, 1.0)
    with pytest.warns(TerrameshWarning, match="1 invalid"):
        shore = Shoreline([mainland, bow_tie], (-0.7, 0.7, -0.2, 0.7), 2000.0)
    assert len(shore.islands.geoms) == 2
    assert_tiles_region(shore)


def test_closed_lines_are_land_and_nested_ones_lakes():
    outer = shapely.LineString(shapely.box(0.0, 0.0, 1.0, 1.0).exterior.coords)
    lake = shapely.box(0.3, 0.3, 0.6, 0.6).exterior  # a LinearRing
    half1 = shapely.LineString([(1.5, 0.2), (1.8, 0.2), (1.8, 0.6)])
    half2 = shapely.LineString([(1.8, 0.6), (1.5, 0.6), (1.5, 0.2)])  # joins half1 into a ring
    island_in_lake = shapely.box(0.4, 0.4, 0.5, 0.5).exterior
    shore = Shoreline([outer, lake, island_in_lake, half1, half2], (-0.5, 2.5, -0.5, 1.5), 2000.0)
    assert len(shore.islands.geoms) == 3
    assert sorted(len(part.interiors) for part in shore.islands.geoms) == [0, 0, 1]
    assert shore.land.contains(shapely.Point(0.45, 0.45)) and shore.water.contains(shapely.Point(0.35, 0.35))
    with pytest.raises(GeometryError, match="do not close"):
        Shoreline([outer, half1], (-0.5, 2.5, -0.5, 1.5), 2000.0)


def test_inputs_are_not_changed():
    land = np.array([shapely.box(0.0, 0.0, 1.0, 1.0), shapely.box(2.0, 0.0, 2.5, 0.5)], dtype=object)
    before = shapely.to_wkb(land)
    Shoreline(land, (0.5, 3.0, -0.5, 1.5), 2000.0)
    assert list(shapely.to_wkb(land)) == list(before)


@st.composite
def blobs(draw):
    """A few star-shaped polygons around the unit box (degrees)."""
    parts = []
    # no subnormal coordinates (a centre at y = 5e-324): GEOS's own symmetric difference, in the check below,
    # then warns of a division by zero
    coordinate = st.floats(-0.3, 1.3, allow_subnormal=False)
    for _ in range(draw(st.integers(1, 4))):
        cx, cy = draw(coordinate), draw(coordinate)
        radius = draw(st.floats(0.05, 0.6))
        k = draw(st.integers(3, 10))
        factors = np.array(draw(st.lists(st.floats(0.3, 1.0), min_size=k, max_size=k)))
        angle = np.linspace(0.0, 2 * np.pi, k, endpoint=False)
        parts.append(
            shapely.Polygon(
                np.column_stack([cx + radius * factors * np.cos(angle), cy + radius * factors * np.sin(angle)])
            )
        )
    return parts


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(blobs())
def test_land_and_water_tile_the_box(parts):
    h0 = 3000.0
    bbox = (0.0, 1.0, 0.0, 1.0)
    try:
        shore = Shoreline(parts, bbox, h0)
    except GeometryError as error:  # no land left in the box, or no water
        assert "no land polygon" in str(error) or "all land" in str(error)
        if "no land polygon" in str(error):
            assert_open_water(Shoreline(parts, bbox, h0, require_land=False))
        return
    assert_tiles_region(shore)
    assert_classified(shore)
    # close to the input: the boundary moves by a fraction of h0, features under 4 h0**2 go
    h0_deg = h0 / 111319.49
    given_land = shapely.intersection(shapely.union_all(parts), _box(bbox))
    moved = shapely.symmetric_difference(given_land, shore.land).area
    corners = sum(len(part.exterior.coords) for part in parts)
    assert moved <= 0.25 * h0_deg * given_land.boundary.length + 8 * h0_deg**2 * (corners + 4)


# ----------------------------------------------------------------------------------------------------------------
# DEM contours


def test_from_dem_keeps_the_sabine_pass_ship_channel(shared_data):
    dem = read_dem(shared_data / "dem" / "CUDEM_equal.nc")
    shore = Shoreline.from_dem(dem, min_edge_length=60.0)
    assert_tiles_region(shore)
    parts = shapely.get_parts(shore.water)
    sea = parts[np.argmax(shapely.area(parts))]
    channel = shapely.points(
        [(-93.8613, 29.72), (-93.9002, 29.76), (-93.9524, 29.80), (-93.953, 29.84), (-93.922, 29.88)]
    )
    assert dem.sample(*shapely.get_coordinates(channel).T).max() < -10.0
    assert sea.contains(channel).all()  # one connected water body from the Gulf up the channel
    # land is where the DEM is above 0 (away from the smoothed shore)
    rng = np.random.default_rng(3)
    lon = rng.uniform(dem.bbox[0], dem.bbox[1], 4000)
    lat = rng.uniform(dem.bbox[2], dem.bbox[3], 4000)
    z = dem.sample(lon, lat)
    clear = np.abs(z) > 1.0
    on_land = shapely.contains_xy(shore.land, lon, lat)
    assert np.mean(on_land[clear] == (z[clear] > 0)) > 0.97
    # the file itself, as build takes it (an AttributeError on the path's 'lon' before)
    from_file = Shoreline.from_dem(shared_data / "dem" / "CUDEM_equal.nc", min_edge_length=60.0)
    assert shapely.equals(from_file.water, shore.water) and from_file.bbox == shore.bbox
    with pytest.raises(GeometryError, match="dem must be a terramesh.coastal.DEM or a path to a NetCDF/GeoTIFF file"):
        Shoreline.from_dem(dem.elevation, min_edge_length=60.0)


def test_from_dem_with_a_box_and_level():
    lon, lat = np.linspace(0.0, 1.0, 101), np.linspace(0.0, 1.0, 101)
    x, y = np.meshgrid(lon, lat, indexing="ij")
    dem = DEM(lon + 360.0 - 180.0, lat, 100.0 * (x - 0.5))  # land east of 180.5
    shore = Shoreline.from_dem(dem, (180.2, 180.8, 0.2, 0.8), 2000.0, level=10.0)
    assert shore.bbox == pytest.approx((-179.8, -179.2, 0.2, 0.8))  # as_lonlat_box prefers -180..180
    assert shore.land.bounds[0] == pytest.approx(-179.4, abs=0.005)  # 100 (x - 0.5) >= 10
    # "read the DEM over the whole box": build had read it for the box itself, the file ends short of it
    with pytest.raises(
        GeometryError,
        match=r"reaches beyond the DEM \(lon 180\.\.181, lat 0\.\.1\) by more than a cell.*shrink the bbox to the "
        r"DEM's extent, or give the land from a shoreline file \(shoreline=PATH\)$",
    ):
        Shoreline.from_dem(dem, (179.0, 180.5, 0.2, 0.8), 2000.0)


def test_from_dem_takes_land_at_exactly_the_level_as_land():
    """Pinned: a bathymetric DEM's land at 0 m exactly was water ("no land polygon in the bbox")."""
    lon = np.linspace(-0.5, 1.5, 81)
    x, _ = np.meshgrid(lon, lon, indexing="ij")
    land_at_zero = x < 0.31  # nodes 0.025 apart: the last land column is at 0.3
    shore = Shoreline.from_dem(DEM(lon, lon, np.where(land_at_zero, 0.0, -100.0)), (0, 1, 0, 1), 2000.0)
    assert shore.land.bounds == pytest.approx((0.0, 0.0, 0.3, 1.0), abs=1e-9)
    # above the level it still starts where the DEM crosses it: 1 / 101 of a cell east of the last land node
    above = Shoreline.from_dem(DEM(lon, lon, np.where(land_at_zero, 1.0, -100.0)), (0, 1, 0, 1), 2000.0)
    assert above.land.bounds[2] == pytest.approx(0.3 + 0.025 / 101, abs=1e-9)


# ----------------------------------------------------------------------------------------------------------------
# projections


def test_projected_file_is_read_in_lon_lat(tmp_path):
    import pyproj

    to_utm = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:32615", always_xy=True)
    x0, y0 = to_utm.transform(-93.9, 29.8)
    island = shapely.box(x0 - 2000.0, y0 - 1000.0, x0 + 2000.0, y0 + 1000.0)
    path = _write(tmp_path / "utm.shp", [island], crs="EPSG:32615")
    shore = Shoreline.read(path, (-94.0, -93.8, 29.7, 29.9), 200.0)
    lon_min, lat_min, lon_max, lat_max = shore.land.bounds
    assert (lon_min + lon_max) / 2 == pytest.approx(-93.9, abs=1e-3)
    assert (lat_min + lat_max) / 2 == pytest.approx(29.8, abs=1e-3)
    assert (lon_max - lon_min) * 111319.49 * np.cos(np.radians(29.8)) == pytest.approx(4000.0, rel=0.05)
    # the same coordinates in a file without a CRS, told with crs=
    bare = tmp_path / "bare.gpkg"
    with pytest.warns(UserWarning, match="crs"):
        pyogrio.raw.write(bare, shapely.to_wkb([island]), [], [], geometry_type="Polygon")
    with pytest.raises(GeometryError, match="no CRS"):
        Shoreline.read(bare, (-94.0, -93.8, 29.7, 29.9), 200.0)
    told = Shoreline.read(bare, (-94.0, -93.8, 29.7, 29.9), 200.0, crs="EPSG:32615")
    assert told.land.equals_exact(shore.land, 1e-9)


def test_projected_file_across_the_antimeridian_keeps_land_near_180(tmp_path):
    # the window was transformed whole: in EPSG:3857 it reached only x of lon -179.9..179.8, and islands within
    # 0.1-0.2 degrees of 180 were dropped silently (Fiji: 11 islands of 12)
    import pyproj

    islands = [shapely.box(179.93, -17.05, 179.98, -17.0), shapely.box(-179.97, -17.55, -179.92, -17.5)]
    to_mercator_file = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:3857", always_xy=True)
    projected = [
        shapely.transform(island, lambda xy: np.column_stack(to_mercator_file.transform(*xy.T))) for island in islands
    ]
    bbox = (176.0, 182.0, -20.0, -15.0)
    lonlat = Shoreline.read(_write(tmp_path / "lonlat.shp", islands), bbox, H0)
    mercator = Shoreline.read(_write(tmp_path / "mercator.shp", projected, crs="EPSG:3857"), bbox, H0)
    assert len(lonlat.islands.geoms) == len(mercator.islands.geoms) == 2
    assert mercator.land.area == pytest.approx(lonlat.land.area, rel=1e-6)
    assert mercator.land.bounds[0] < 180.0 < mercator.land.bounds[2]


# ----------------------------------------------------------------------------------------------------------------
# failures


def assert_open_water(shore):
    """No land: the water is the whole region, there is no coastline and all of the region's edge is open."""
    assert_tiles_region(shore)
    assert shore.land.is_empty and shore.mainland.is_empty and shore.islands.is_empty
    assert shore.coastline.is_empty and shore.mainland_coastline.is_empty
    assert shore.water.equals(shore.region)
    assert shore.open_boundary.length == pytest.approx(shore.region.boundary.length, rel=1e-12)


def test_no_land_in_the_bbox(shared_data):
    path, bbox = shared_data / "coast" / "GSHHS_l_L1.shp", (-150, -140, -40, -35)
    refused = r"GSHHS_l_L1.shp has no land polygon in the bbox \(-150.0, -140.0, .*require_land=False"
    with pytest.raises(GeometryError, match=refused):
        Shoreline.read(path, bbox, 5000.0)
    # asked for, the South Pacific there is open water: a box to mesh with no coast
    shore = Shoreline.read(path, bbox, 5000.0, require_land=False)
    assert_open_water(shore)
    assert read_shoreline(path, bbox, 5000.0, require_land=False).water.equals(shore.water)
    domain = shore.domain()
    x, y = to_mercator(np.array([-145.0, -139.0]), np.array([-37.5, -37.5]))
    inside, outside = domain.distance(np.column_stack([x, y]))
    assert inside < -200e3 and outside > 0  # the box's middle lies 2.5 degrees of latitude from its edge
    # land that shrinks away under minimum_island_area leaves open water too
    speck = shapely.box(-145.0, -37.5, -144.99, -37.49)
    with pytest.raises(GeometryError, match="minimum_island_area"):
        Shoreline(speck, bbox, 5000.0)
    assert_open_water(Shoreline(speck, bbox, 5000.0, require_land=False))


def test_box_beyond_a_regional_file_is_open_water_when_asked(tmp_path):
    """A regional coastline ends short of an offshore box: refused by default, open water when asked."""
    path = _write(tmp_path / "coast.gpkg", [shapely.box(10.0, 0.0, 11.0, 1.0)])
    offshore = (12.0, 13.0, 0.0, 1.0)
    with pytest.raises(GeometryError, match=r"does not overlap the shoreline file coast.gpkg .*require_land=False"):
        Shoreline.read(path, offshore, 5000.0)
    assert_open_water(Shoreline.read(path, offshore, 5000.0, require_land=False))


def test_open_water_from_a_dem(shared_data):
    dem = read_dem(shared_data / "dem" / "ETOPO1_0.1.grd", (-72.5, -70.5, 36.5, 38.5))
    bbox = (-72.0, -71.0, 37.0, 38.0)  # 200 km off the US East Coast: the whole box is below sea level
    assert dem.sample(np.array([-71.5]), np.array([37.5]))[0] < -2000.0
    with pytest.raises(GeometryError, match="has no land polygon"):
        Shoreline.from_dem(dem, bbox, 2000.0)
    assert_open_water(Shoreline.from_dem(dem, bbox, 2000.0, require_land=False))


def test_bbox_outside_the_file(shared_data):
    with pytest.raises(GeometryError, match=r"bbox \(50.0, 60.0, 10.0, 20.0\) does not overlap .*islands.shp \(x 0.09"):
        Shoreline.read(shared_data / "coast" / "islands.shp", (50, 60, 10, 20), 2000.0)


def test_all_land():
    with pytest.raises(GeometryError, match="all land"):
        Shoreline(shapely.box(-2.0, -2.0, 2.0, 2.0), (-1, 1, -1, 1), 2000.0)


def test_bad_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere.shp"):
        Shoreline.read(tmp_path / "nowhere.shp", NZ, H0)
    junk = tmp_path / "junk.shp"
    junk.write_bytes(b"\x00\x00\x27\x0a" + b"not a shapefile" * 10)
    with pytest.raises(MeshFormatError, match="junk.shp"):
        Shoreline.read(junk, NZ, H0)
    empty = tmp_path / "empty.gpkg"
    pyogrio.raw.write(empty, np.array([], dtype=object), [], [], geometry_type="Polygon", crs="EPSG:4326")
    with pytest.raises(GeometryError, match="has no features"):
        Shoreline.read(empty, NZ, H0)
    points = _write(tmp_path / "points.gpkg", [shapely.Point(170.0, -44.0)], geometry_type="Point")
    with pytest.raises(GeometryError, match="no polygons or lines"):
        Shoreline.read(points, NZ, H0)
    # a folder: GDAL read whichever file it found first; a .prj it cannot parse: taken as degrees, silently
    with pytest.raises(GeometryError, match=r"is a folder: give the file itself \(shapefiles in it: \['junk.shp'\]"):
        Shoreline.read(tmp_path, NZ, H0)
    garbled = _write(tmp_path / "garbled.shp", [shapely.box(170.0, -44.0, 171.0, -43.0)], crs="EPSG:4326")
    garbled.with_suffix(".prj").write_text("not a projection")
    with pytest.raises(MeshFormatError, match="cannot read the CRS in .*garbled.prj"):
        Shoreline.read(garbled, NZ, H0)
    assert Shoreline.read(garbled, NZ, H0, crs="EPSG:4326").land.area > 0


def _layers(path, *layers):
    """A GeoPackage of ``(name, geometries, geometry type)`` layers; geometries None: an attribute table."""
    for name, geometries, kind in layers:
        wkb = None if geometries is None else shapely.to_wkb(np.asarray(geometries, dtype=object))
        fields = [np.array(["a"] * (1 if geometries is None else len(geometries)), dtype=object)]
        pyogrio.raw.write(path, wkb, fields, ["name"], geometry_type=kind, crs="EPSG:4326", layer=name, driver="GPKG")
    return path


LAND = shapely.box(165.0, -50.0, 170.0, -38.0)
RIVER = shapely.LineString([(168.0, -44.0), (172.0, -43.0)])


def test_the_land_layer_of_a_file_of_several_is_found(tmp_path):
    # land with rivers beside it was refused (several layers: name one); before that, GDAL took the first layer,
    # and the stations read as the land failed as open water. The land is the one polygon layer.
    stations = ("stations", [shapely.Point(170.5, -44.0)], "Point")
    path = _layers(tmp_path / "coast.gpkg", stations, ("land", [LAND], "Polygon"), ("rivers", [RIVER], "LineString"))
    _layers(path, ("notes", None, None))
    assert [kind for _, kind in pyogrio.list_layers(path)] == ["Point", "Polygon", "LineString", None]
    shore = Shoreline.read(path, NZ, H0)  # pyogrio's 'more than one layer' warning is an error here too
    assert shore.land.bounds[2] == pytest.approx(170.0, abs=0.01) and len(shore.mainland.geoms) == 1
    # no polygon layer: the coastline's closed lines are the land, the stations never
    ring = shapely.box(171.0, -45.0, 172.0, -44.0).exterior
    lines = _layers(tmp_path / "lines.gpkg", stations, ("coast", [ring], "LineString"), ("notes", None, None))
    assert Shoreline.read(lines, NZ, H0).land.area == pytest.approx(1.0, rel=0.02)


@pytest.mark.parametrize(
    ("layers", "match"),
    [
        (
            [
                ("land", [LAND], "Polygon"),
                ("lakes", [shapely.box(168, -45, 169, -44)], "Polygon"),
                ("r", [RIVER], "LineString"),
            ],
            r"coast.gpkg has 2 polygon layers: land \(Polygon\), lakes \(Polygon\); choose the land's with "
            r"layer='land'",
        ),
        (
            [
                ("stations", [shapely.Point(170.5, -44.0)], "Point"),
                ("a", [RIVER], "LineString"),
                ("b", [RIVER], "LineString"),
            ],
            r"coast.gpkg has 2 line layers: a \(LineString\), b \(LineString\); choose the land's with layer='a'",
        ),
        (
            [("stations", [shapely.Point(170.5, -44.0)], "Point"), ("notes", None, None)],
            r"coast.gpkg has no layer of land polygons or coastline lines: stations \(Point\), notes \(no geometry\)",
        ),
    ],
)
def test_a_file_of_several_land_layers_needs_the_layer(tmp_path, layers, match):
    path = _layers(tmp_path / "coast.gpkg", *layers)
    with pytest.raises(GeometryError, match=match):
        Shoreline.read(path, NZ, H0)
    if "polygon layers" in match:
        for layer in ("land", 0):
            shore = Shoreline.read(path, NZ, H0, layer=layer)
            assert shore.land.bounds[2] == pytest.approx(170.0, abs=0.01) and len(shore.mainland.geoms) == 1


def test_layers_named_by_number_are_read_by_name(tmp_path):
    # layer=2019 (--layer 2019 on the command line) was taken as the 2020th layer, and the error blamed the file
    # ("not a vector file, or corrupt?")
    earlier = shapely.box(171.0, -45.0, 172.0, -44.0)
    path = _layers(tmp_path / "years.gpkg", ("2020", [LAND], "Polygon"), ("2019", [earlier], "Polygon"))
    assert Shoreline.read(path, NZ, H0, layer=2019).land.area == pytest.approx(1.0, rel=0.02)
    assert Shoreline.read(path, NZ, H0, layer="2019").land.area == pytest.approx(1.0, rel=0.02)
    assert Shoreline.read(path, NZ, H0, layer=1).land.area == pytest.approx(1.0, rel=0.02)  # no layer is named '1'
    assert Shoreline.read(path, NZ, H0, layer=0).land.bounds[2] == pytest.approx(170.0, abs=0.01)
    for layer in (2, "2021"):
        with pytest.raises(
            GeometryError,
            match=rf"years.gpkg has no layer {layer!r}; choose one of its 2 layers by "
            r"name or 0-based number: 2020 \(Polygon\), 2019 \(Polygon\)",
        ):
            Shoreline.read(path, NZ, H0, layer=layer)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"bbox": (1, 0, 0, 1)}, GeometryError, "min < max"),
        ({"bbox": shapely.Point(0, 0)}, GeometryError, "Polygon"),
        ({"min_edge_length": -1.0}, SizingError, "positive"),
        ({"min_edge_length": "big"}, SizingError, "number"),
        ({"minimum_island_area": -1.0}, SizingError, ">= 0"),
        ({"smooth": -1}, GeometryError, "smooth"),
        # min_edge_length in degrees: 9e8 vertices, and the process was killed for memory with no message
        ({"min_edge_length": 0.001}, GeometryError, r"would make 6.\d+e\+08 vertices.*min_edge_length is in metres"),
    ],
)
def test_bad_arguments(kwargs, error, match):
    arguments = {"land": shapely.box(0.0, 0.0, 1.0, 1.0), "bbox": (0.5, 1.5, 0.0, 1.0), "min_edge_length": 1000.0}
    arguments.update(kwargs)
    with pytest.raises(error, match=match):
        Shoreline(**arguments)


def test_land_with_nan_coordinates_is_named():
    # a raw GEOSException from make_valid before
    with np.errstate(invalid="ignore"):  # shapely's own warning, making the polygon
        land = shapely.polygons(np.array([(0, 0), (1, np.nan), (1, 1), (0, 0)]))
    with pytest.raises(GeometryError, match="1 land polygon vertices have NaN or infinite coordinates"):
        Shoreline(land, (0.5, 1.5, 0.0, 1.0), 1000.0)


def test_the_guides_nan_delimited_polygon_vector_is_land():
    # §2.5's polygons, one array with NaN rows between them: a TypeError came from inside os.fspath
    mainland = [[0.0, 0.0], [0.4, 0.0], [0.4, 1.0], [0.0, 1.0]]
    island = [[0.6, 0.4], [0.7, 0.4], [0.7, 0.5], [0.6, 0.5], [0.6, 0.4]]  # closed or not, both read
    vector = np.array([*mainland, [np.nan, np.nan], *island, [np.nan, np.nan]])
    expected = Shoreline(shapely.MultiPolygon([shapely.Polygon(mainland), shapely.Polygon(island)]), (0, 1, 0, 1), 2000)
    for land in (vector, [np.array(mainland), np.array(island)]):
        shore = Shoreline.read(land, (0, 1, 0, 1), 2000)
        assert shore.land.symmetric_difference(expected.land).area < 1e-4 * expected.land.area  # resampled alike
        assert len(shore.islands.geoms) == 1
    with pytest.raises(GeometryError, match=r"polygon array 1 must be \(k, 2\) lon/lat, got shape \(4, 3\)"):
        Shoreline.read(np.zeros((4, 3)), (0, 1, 0, 1), 2000)
    with pytest.raises(GeometryError, match="fewer than 3 distinct vertices"):
        Shoreline.read(np.array([[0.0, 0.0], [0.4, 0.0], [np.nan, np.nan]]), (0, 1, 0, 1), 2000)


def test_a_corrupt_record_is_refused_not_left_out(tmp_path):
    # bytes damaged in a record left a ring unclosed: GDAL passed the shape, shapely could not read it, and the
    # feature was dropped without a word, its land meshed as water (2 of ne_50m_land's 1,420 features)
    import struct

    path = _write(tmp_path / "land.shp", [shapely.box(0, 0, 1, 1), shapely.box(2, 0, 3, 1)])
    data = bytearray(path.read_bytes())
    # the first record: a 100-byte file header, an 8-byte record header, then type, box, 1 part, 5 points
    last_point = 100 + 8 + 4 + 32 + 4 + 4 + 4 + 4 * 16
    assert struct.unpack("<2d", data[last_point : last_point + 16]) == (1.0, 0.0)
    data[last_point : last_point + 8] = struct.pack("<d", 0.5)
    path.write_bytes(bytes(data))
    with (
        pytest.warns(RuntimeWarning, match="Non closed ring"),  # GDAL's own
        pytest.raises(
            MeshFormatError, match=r"land.shp: 1 of the 2 features near the box are corrupt \(feature ids \[0\]\)"
        ),
    ):
        read_shoreline(path, (-1, 4, -1, 2), 1000.0)
