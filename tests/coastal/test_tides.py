import datetime as dt

import netCDF4
import numpy as np
import pytest

from terramesh.coastal.tides import (
    CONSTITUENTS,
    astronomical_arguments,
    atlas_elevation_constants,
    get_constituent,
    tidal_factors,
)
from terramesh.errors import ForcingError, MeshFormatError, TerrameshWarning

MAJOR8 = ["M2", "S2", "N2", "K2", "K1", "O1", "P1", "Q1"]

# AMIGT/AMIG (rad/s) as published in ADCIRC's tide_fac.f and fort.15 documentation (first eight), and in the
# NOAA-speed table of aquaveo/harmonica (tidal_constituents.py) for the others.
PUBLISHED_FREQUENCY = {
    "M2": 0.000140518902509,
    "S2": 0.000145444104333,
    "N2": 0.000137879699487,
    "K2": 0.000145842317201,
    "K1": 0.000072921158358,
    "O1": 0.000067597744151,
    "P1": 0.000072522945975,
    "Q1": 0.000064958541129,
    "2N2": 0.000135240496464,
    "Mf": 0.000005323414692,
    "Mm": 0.000002639203022,
    "M4": 0.000281037805017,
    "MS4": 0.000285963006842,
    "MN4": 0.000278398601995,
}

# Speeds (degrees per hour) from Schureman's Table 2 as tabulated in tide_fac.f (ACST).
SCHUREMAN_SPEED = {
    "M2": 28.9841042,
    "S2": 30.0,
    "N2": 28.4397295,
    "K2": 30.0821373,
    "K1": 15.0410686,
    "O1": 13.9430356,
    "P1": 14.9589314,
    "Q1": 13.3986609,
    "2N2": 27.8953548,
    "Mf": 1.0980331,
    "Mm": 0.5443747,
    "M4": 57.9682084,
    "MS4": 58.9841042,
    "MN4": 57.4238337,
}


@pytest.mark.parametrize("name", list(PUBLISHED_FREQUENCY))
def test_frequencies_are_the_doodson_values_adcirc_publishes(name):
    constituent = CONSTITUENTS[name]
    assert constituent.frequency == pytest.approx(PUBLISHED_FREQUENCY[name], rel=1e-7)
    assert constituent.speed == pytest.approx(SCHUREMAN_SPEED[name], abs=5e-7)


def test_the_major_constituents_carry_adcircs_potential_constants():
    # tide_fac.f / ADCIRC fort.15 documentation (Reid 1990): amplitude (m) and earth tide reduction factor
    published = {
        "M2": (0.242334, 0.693),
        "S2": (0.112841, 0.693),
        "N2": (0.046398, 0.693),
        "K2": (0.030704, 0.693),
        "K1": (0.141565, 0.736),
        "O1": (0.100514, 0.695),
        "P1": (0.046843, 0.706),
        "Q1": (0.019256, 0.695),
    }
    for name, (amplitude, reduction) in published.items():
        assert (CONSTITUENTS[name].potential_amplitude, CONSTITUENTS[name].earth_tide_reduction) == (
            amplitude,
            reduction,
        )
    for name in ("M4", "MS4", "MN4"):  # shallow-water constituents have no equilibrium potential
        assert CONSTITUENTS[name].potential_amplitude == 0


def test_mean_longitudes_match_the_published_j2000_elements():
    # Meeus, Astronomical Algorithms (1998), ch. 22 and 47 (Simon et al. 1994) at J2000.0 = 2000-01-01 12:00 TT,
    # i.e. 11:58:56 UT: Moon's mean longitude L', Sun's L0, lunar perigee L' - M', node Omega, solar perigee L0 - M.
    args = astronomical_arguments("2000-01-01T11:58:56")
    published = {"s": 218.3164477, "h": 280.46646, "p": 218.3164477 - 134.9633964, "N": 125.0445479}
    published["p1"] = (280.46646 - 357.5291092) % 360
    for key, value in published.items():
        assert abs((args[key] - value + 180) % 360 - 180) < 0.01, key
    assert args["I"] == pytest.approx(np.degrees(np.arccos(0.9136949 - 0.0356926 * np.cos(np.radians(args["N"])))))


def test_reproduces_a_published_tide_fac_output():
    # The bctides.in example of the SELFE/SCHISM "Tides" page (ccrm.vims.edu/w/index.php?title=Tides), written by
    # tide_fac. The page gives no date; its S2 (0.00) and P1 (110.04) arguments fix a 00:00 start with h = 160 deg,
    # and of every day from 1980 to 2030 and run length from 1 to 365 days only 1998-09-01 with 30 days reproduces
    # all eight constituents.
    published_f = [1.03272, 1.0, 1.03272, 0.77955, 0.90207, 0.83992, 1.0, 0.83992]
    published_argument = [129.18, 0.00, 243.40, 310.55, 244.87, 247.06, 110.04, 1.28]
    factors = tidal_factors(MAJOR8, dt.datetime(1998, 9, 1), run_days=30)
    np.testing.assert_allclose(factors.nodal_factor, published_f, atol=5e-5)
    difference = (factors.equilibrium_argument - published_argument + 180) % 360 - 180
    np.testing.assert_allclose(difference, 0, atol=0.01)


# Doodson (1928) / Pugh (1987, Table 4.3) series in the lunar node N: f = a0 + a1 cos N + a2 cos 2N,
# u = b1 sin N + b2 sin 2N + b3 sin 3N (degrees).
SERIES = {
    "M2": ((1.000, -0.037, 0.0), (-2.1, 0.0, 0.0)),
    "N2": ((1.000, -0.037, 0.0), (-2.1, 0.0, 0.0)),
    "K2": ((1.024, 0.286, 0.008), (-17.7, 0.7, 0.0)),
    "K1": ((1.006, 0.115, -0.009), (-8.9, 0.7, 0.0)),
    "O1": ((1.009, 0.187, -0.015), (10.8, -1.3, 0.2)),
    "Q1": ((1.009, 0.187, -0.015), (10.8, -1.3, 0.2)),
    "Mf": ((1.043, 0.414, 0.0), (-23.7, 2.7, -0.4)),
    "Mm": ((1.000, -0.130, 0.0), (0.0, 0.0, 0.0)),
}


def test_node_factors_follow_the_published_series_over_a_nodal_cycle():
    names = list(SERIES)
    for day in range(0, int(18.61 * 365.25), 20):
        time = dt.datetime(2000, 1, 1) + dt.timedelta(days=day)
        args = astronomical_arguments(time)
        node = np.radians(args["N"])
        factors = tidal_factors(names, time)
        for k, name in enumerate(names):
            c = CONSTITUENTS[name]
            v0 = np.dot(c.doodson, [args[key] for key in ("T", "s", "h", "p", "p1")]) + c.phase
            u = (factors.equilibrium_argument[k] - v0 + 180) % 360 - 180
            (a0, a1, a2), (b1, b2, b3) = SERIES[name]
            f = a0 + a1 * np.cos(node) + a2 * np.cos(2 * node)
            assert abs(factors.nodal_factor[k] - f) < 0.01, (name, time)
            # the series' coefficients are rounded to 0.1 degree
            assert abs(u - (b1 * np.sin(node) + b2 * np.sin(2 * node) + b3 * np.sin(3 * node))) < 0.15, (name, time)


def test_f_and_u_are_taken_at_the_middle_of_the_run_and_v0_at_its_start():
    start = dt.datetime(2015, 3, 10, 6, 30)
    run = tidal_factors(MAJOR8, start, run_days=40)
    middle = tidal_factors(MAJOR8, start + dt.timedelta(days=20))
    np.testing.assert_allclose(run.nodal_factor, middle.nodal_factor)
    # V0 advances by speed * 20 days between the two; u is the same
    speeds = np.array([CONSTITUENTS[n].speed for n in MAJOR8])
    shift = (middle.equilibrium_argument - run.equilibrium_argument - speeds * 480.0) % 360
    np.testing.assert_allclose((shift + 180) % 360 - 180, 0, atol=1e-6)


def test_compound_constituents_combine_their_parents():
    factors = tidal_factors(["M2", "S2", "N2", "M4", "MS4", "MN4"], "2020-07-04T13:00", run_days=12)
    (f_m2, m2), (_, s2), (_, n2) = factors["M2"], factors["S2"], factors["N2"]
    assert factors["M4"][0] == pytest.approx(f_m2**2)
    assert factors["MN4"][0] == pytest.approx(f_m2**2)
    assert factors["MS4"][0] == pytest.approx(f_m2)
    for name, expected in (("M4", 2 * m2), ("MS4", m2 + s2), ("MN4", m2 + n2)):
        assert (factors[name][1] - expected + 180) % 360 - 180 == pytest.approx(0, abs=1e-9)


def test_s2_runs_with_the_clock_and_arguments_stay_in_range():
    assert tidal_factors(["S2"], "2001-05-05T06:00")["S2"] == (1.0, 180.0)
    factors = tidal_factors(list(CONSTITUENTS), "1850-02-28T23:59", run_days=3650)
    assert np.all((factors.equilibrium_argument >= 0) & (factors.equilibrium_argument < 360))
    assert np.all(factors.nodal_factor > 0)


def test_times_in_any_form_mean_the_same_utc_instant():
    expected = tidal_factors(MAJOR8, dt.datetime(2010, 1, 2, 3))
    eastern = dt.timezone(dt.timedelta(hours=-5))
    for start in (
        "2010-01-02T03:00",
        "2010-01-02T03:00Z",
        np.datetime64("2010-01-02T03:00"),
        dt.datetime(2010, 1, 1, 22, tzinfo=eastern),
    ):
        np.testing.assert_allclose(tidal_factors(MAJOR8, start).equilibrium_argument, expected.equilibrium_argument)
    midnight = tidal_factors(MAJOR8, dt.date(2010, 1, 2))
    assert midnight.start == dt.datetime(2010, 1, 2)


def test_bad_names_and_times_raise_value_errors():
    assert get_constituent("mn4").name == "MN4"
    with pytest.raises(ForcingError, match="unknown tidal constituent 'X9'"):
        tidal_factors(["M2", "X9"], "2010-01-01")
    with pytest.raises(ValueError, match="run_days"):
        tidal_factors(["M2"], "2010-01-01", run_days=-1)
    with pytest.raises(ValueError, match="ISO 8601"):
        tidal_factors(["M2"], "first of May")
    # OceanMesh2D's scripts give MATLAB's datestr: refused before
    np.testing.assert_array_equal(
        tidal_factors(["M2"], "01-Aug-2012 06:30").nodal_factor, tidal_factors(["M2"], "2012-08-01T06:30").nodal_factor
    )
    with pytest.raises(ForcingError, match="run_days must be a finite number >= 0, got 'thirty'"):
        tidal_factors(["M2"], "2010-01-01", run_days="thirty")


# ---------------------------------------------------------------------------------------------------------------------
# synthetic TPXO atlases


def linear_field(lon, lat, k):
    """A complex elevation (m) linear in lon and lat, different per constituent k: bilinear is exact."""
    return (0.3 + 0.01 * k + 0.02 * lon + 0.01 * lat) + 1j * (-0.2 + 0.03 * lon - 0.015 * lat - 0.01 * k)


def amplitude_phase(h):
    return np.abs(h), np.degrees(np.arctan2(-h.imag, h.real)) % 360


def write_constituent_file(path, lon, lat, h, *, order=("nx", "ny"), units="millimeter", dtype="i4"):
    """TPXO9-atlas layout: one file per constituent, hRe/hIm (integer mm) on (nx, ny), 1-D lon_z, lat_z."""
    scale = 1.0 if units in ("m", "meter") else 1000.0  # millimetres unless metres are said
    with netCDF4.Dataset(path, "w") as nc:
        nc.createDimension("nx", len(lon))
        nc.createDimension("ny", len(lat))
        nc.createVariable("lon_z", "f8", ("nx",))[:] = lon
        nc.createVariable("lat_z", "f8", ("ny",))[:] = lat
        for name, part in (("hRe", h.real), ("hIm", h.imag)):
            values = np.round(part * scale) if dtype.startswith("i") else part * scale
            variable = nc.createVariable(name, dtype, order)
            if units is not None:
                variable.units = units
            variable[:] = values if order == ("nx", "ny") else values.T


def grid(lon0=-90.0, lon1=-70.0, lat0=20.0, lat1=40.0, step=0.5):
    lon = np.arange(lon0, lon1 + step / 2, step)
    lat = np.arange(lat0, lat1 + step / 2, step)
    return lon, lat, *np.meshgrid(lon, lat, indexing="ij")


def test_per_constituent_atlas_is_interpolated_bilinearly(tmp_path):
    lon, lat, glon, glat = grid()
    for k, name in enumerate(["m2", "k1"]):
        write_constituent_file(tmp_path / f"h_{name}_tpxo9_atlas_30_v5.nc", lon, lat, linear_field(glon, glat, k))
    rng = np.random.default_rng(5)
    px, py = rng.uniform(-88, -72, 50), rng.uniform(22, 38, 50)
    out = atlas_elevation_constants(tmp_path, px, py, constituents=["M2", "K1"])
    assert out.constituents == ("M2", "K1")
    for k in range(2):
        amplitude, phase = amplitude_phase(linear_field(px, py, k))
        np.testing.assert_allclose(out.amplitude[k], amplitude, atol=2e-3)  # the file holds whole millimetres
        np.testing.assert_allclose((out.phase[k] - phase + 180) % 360 - 180, 0, atol=0.5)
    assert not out.nearest.any()


def test_single_file_atlas_with_amplitude_and_phase(tmp_path):
    lon, lat, glon, glat = grid()
    names = ["m2  ", "s2  ", "k1  "]
    path = tmp_path / "h_tpxo7.2.nc"
    with netCDF4.Dataset(path, "w") as nc:
        for dim, size in (("nc", 3), ("nct", 4), ("nx", len(lon)), ("ny", len(lat))):
            nc.createDimension(dim, size)
        nc.createVariable("con", "S1", ("nc", "nct"))[:] = netCDF4.stringtochar(np.array(names, dtype="S4"))
        nc.createVariable("lon_z", "f8", ("nx", "ny"))[:] = glon
        nc.createVariable("lat_z", "f8", ("nx", "ny"))[:] = glat
        amplitude, phase = zip(*(amplitude_phase(linear_field(glon, glat, k)) for k in range(3)), strict=True)
        ha = nc.createVariable("ha", "f4", ("nc", "nx", "ny"))
        ha.units = "meter"
        ha[:] = np.array(amplitude)
        nc.createVariable("hp", "f4", ("nc", "nx", "ny"))[:] = np.array(phase)
    px, py = np.array([-85.2, -74.9]), np.array([25.3, 33.3])
    out = atlas_elevation_constants(path, px, py, constituents=["K1", "m2"])
    for row, k in ((0, 2), (1, 0)):
        amplitude, phase = amplitude_phase(linear_field(px, py, k))
        np.testing.assert_allclose(out.amplitude[row], amplitude, rtol=1e-5)
        np.testing.assert_allclose(out.phase[row], phase, atol=1e-3)
    # the folder form finds the single file when there are no per-constituent files
    np.testing.assert_allclose(
        atlas_elevation_constants(tmp_path, px, py, constituents=["K1"]).amplitude[0], out.amplitude[0]
    )
    with pytest.raises(ForcingError, match="has no MN4"):
        atlas_elevation_constants(path, px, py, constituents=["MN4"])


def test_lat_lon_axis_order_and_float_metres(tmp_path):
    lon, lat, glon, glat = grid()
    write_constituent_file(
        tmp_path / "m2.nc", lon, lat, linear_field(glon, glat, 0), order=("ny", "nx"), units="m", dtype="f8"
    )
    px, py = np.array([-80.25, -71.1]), np.array([30.6, 21.4])
    out = atlas_elevation_constants({"M2": tmp_path / "m2.nc"}, px, py, constituents=["M2"])
    amplitude, phase = amplitude_phase(linear_field(px, py, 0))
    np.testing.assert_allclose(out.amplitude[0], amplitude, rtol=1e-10)
    np.testing.assert_allclose(out.phase[0], phase, atol=1e-8)


def test_land_in_the_stencil_falls_back_to_the_nearest_ocean_cell(tmp_path):
    lon, lat, glon, glat = grid(step=1.0)
    h = linear_field(glon, glat, 0)
    land = (glon >= -80) & (glat >= 30)  # a continent in the north-east
    h[land] = 0
    write_constituent_file(tmp_path / "h_m2_test.nc", lon, lat, h, units="m", dtype="f8")
    # a coastal point whose stencil touches land, one deep inland (nearest ocean 6 cells away), one at sea
    px, py = np.array([-80.5, -74.0, -85.5]), np.array([30.5, 36.0, 25.5])
    with pytest.warns(TerrameshWarning, match="nearest ocean cell") as record:
        out = atlas_elevation_constants(tmp_path, px, py, constituents=["M2"])
    np.testing.assert_array_equal(out.nearest[0], [True, True, False])
    # the warning gives the largest distance to the cell used: the inland point's, to -81 E (7 degrees at 36 N)
    inland = great_circle_km(-74.0, 36.0, -81.0, 36.0)
    assert 600 < inland < 650
    assert f"the largest distance to the cell used is {inland:.1f} km (M2 at lon -74.0000, lat 36.0000)" in str(
        record[0].message
    )
    ocean = ~land
    for k in (0, 1):
        # the nearest ocean cell centre by great-circle distance
        d = np.arccos(
            np.clip(
                np.sin(np.radians(py[k])) * np.sin(np.radians(glat))
                + np.cos(np.radians(py[k])) * np.cos(np.radians(glat)) * np.cos(np.radians(glon - px[k])),
                -1,
                1,
            )
        )
        d[~ocean] = np.inf
        expected = h.ravel()[np.argmin(d)]
        assert out.amplitude[0, k] == pytest.approx(abs(expected))
    assert out.amplitude[0, 2] == pytest.approx(abs(linear_field(px[2], py[2], 0)))


def great_circle_km(lon0, lat0, lon1, lat1, radius_km=6378.137):
    """Haversine distance on terramesh's sphere (the Mercator one, 6378.137 km)."""
    lon0, lat0, lon1, lat1 = np.radians([lon0, lat0, lon1, lat1])
    a = np.sin((lat1 - lat0) / 2) ** 2 + np.cos(lat0) * np.cos(lat1) * np.sin((lon1 - lon0) / 2) ** 2
    return float(2 * radius_km * np.arcsin(np.sqrt(a)))


def test_an_atlas_that_does_not_cover_the_points_is_refused(tmp_path):
    """Points 600-2700 km outside a regional atlas took its edge value, with only the generic warning."""
    lon, lat, glon, glat = grid(-80.0, -75.0, 30.0, 35.0, step=0.5)
    write_constituent_file(tmp_path / "h_m2_regional.nc", lon, lat, linear_field(glon, glat, 0), units="m", dtype="f8")
    px, py = np.array([-77.0, -70.0, -60.0]), np.array([32.0, 42.0, 10.0])
    farthest = great_circle_km(-60.0, 10.0, -75.0, 30.0)  # to the atlas's nearest corner
    assert 2600 < farthest < 2800
    with pytest.raises(
        ForcingError,
        match=rf"2 of 3 points lie more than 2 atlas cells outside the tidal atlas .*h_m2_regional\.nc "
        rf"\(M2: cell centres lon -80\.\.-75, lat 30\.\.35, cells 0\.5 x 0\.5 degrees\); "
        rf"the farthest, lon -60\.0000, lat 10\.0000, is {farthest:.0f} km outside",
    ):
        atlas_elevation_constants(tmp_path, px, py, constituents=["M2"])
    # the same atlas written in 0..360 refuses the same points
    write_constituent_file(tmp_path / "h_m2_regional.nc", lon + 360, lat, linear_field(glon, glat, 0), units="m")
    with pytest.raises(ForcingError, match=rf"2 of 3 points .* lon 280\.\.285, .* is {farthest:.0f} km outside"):
        atlas_elevation_constants(tmp_path, px, py, constituents=["M2"])


def test_points_just_outside_the_atlas_take_the_nearest_ocean_cell(tmp_path):
    """Within two cells of the outer centres (an atlas's edge cells, a coast masked as land) the fallback stays."""
    lon, lat, glon, glat = grid(-80.0, -75.0, 30.0, 35.0, step=0.5)
    h = linear_field(glon, glat, 0)
    write_constituent_file(tmp_path / "h_m2_regional.nc", lon, lat, h, units="m", dtype="f8")
    # 1.9 cells east of the last column, 2 cells south of the first row, and one inside
    px, py = np.array([-74.05, -77.0, -77.2]), np.array([32.0, 29.0, 32.1])
    with pytest.warns(TerrameshWarning, match="nearest ocean cell was used") as record:
        out = atlas_elevation_constants(tmp_path, px, py, constituents=["M2"])
    np.testing.assert_array_equal(out.nearest[0], [True, True, False])
    assert out.amplitude[0, 0] == pytest.approx(abs(linear_field(-75.0, 32.0, 0)))
    assert out.amplitude[0, 1] == pytest.approx(abs(linear_field(-77.0, 30.0, 0)))
    east, south = great_circle_km(-74.05, 32.0, -75.0, 32.0), great_circle_km(-77.0, 29.0, -77.0, 30.0)
    assert south > east
    assert f"the largest distance to the cell used is {south:.1f} km (M2 at lon -77.0000, lat 29.0000)" in str(
        record[0].message
    )
    with pytest.raises(ForcingError, match="1 of 1 points lie more than 2 atlas cells outside"):
        atlas_elevation_constants(tmp_path, [-77.0], [28.9], constituents=["M2"])


def test_global_atlas_wraps_across_the_seam(tmp_path):
    lon = np.arange(0.0, 360.0, 1.0)  # 0..359, global
    lat = np.arange(-80.0, 80.5, 1.0)
    glon, glat = np.meshgrid(lon, lat, indexing="ij")
    distance = np.abs((glon + 180) % 360 - 180)  # degrees from the Greenwich meridian
    h = (0.5 + 0.01 * distance + 0.001 * glat) + 0.1j
    write_constituent_file(tmp_path / "h_k1_global.nc", lon, lat, h, units="m", dtype="f8")
    px, py = np.array([-0.5, 359.5, 0.25, -179.7]), np.array([10.0, 10.0, -5.0, 3.0])
    out = atlas_elevation_constants(tmp_path, px, py, constituents=["K1"])
    expected = 0.5 + 0.01 * np.abs((px + 180) % 360 - 180) + 0.001 * py + 0.1j
    np.testing.assert_allclose(out.amplitude[0], np.abs(expected), rtol=1e-12)
    assert not out.nearest.any()


@pytest.mark.parametrize(
    "px",
    [
        [-0.1, 0.1],  # a cluster across the seam
        [359.8, 0.2, 180.0],  # points all round, with the seam between two of them
        np.append(np.arange(-179.9, 180.0, 0.7), [359.9, 0.1, -0.05]),  # a window of the whole turn
    ],
    ids=["cluster", "spread", "whole-turn"],
)
def test_global_cell_centred_atlas_interpolates_between_the_last_and_first_centres(tmp_path, px):
    """0.5 degree cell centres 0.25..359.75: points within a quarter degree of 0 are bilinear, not the nearest cell."""
    lon = np.arange(0.25, 360.0, 0.5)
    lat = np.arange(-89.75, 90.0, 0.5)
    glon, glat = np.meshgrid(lon, lat, indexing="ij")
    h = (1.0 + 0.003 * glat + 0.002 * np.cos(np.radians(glon))) + 1j * (
        0.5 + 0.001 * glat + 0.005 * np.sin(np.radians(glon))
    )
    write_constituent_file(tmp_path / "h_m2_global.nc", lon, lat, h, dtype="f8")  # millimetres
    px = np.asarray(px, dtype=float)
    py = np.full(px.shape, 50.0)
    out = atlas_elevation_constants(tmp_path, px, py, constituents=["M2"])  # warnings are errors: no "touched land"
    # bilinear on the centres: linear in latitude, and linear in longitude between centres round the circle
    expected = (1.0 + 0.003 * py + 0.002 * np.interp(px, lon, np.cos(np.radians(lon)), period=360.0)) + 1j * (
        0.5 + 0.001 * py + 0.005 * np.interp(px, lon, np.sin(np.radians(lon)), period=360.0)
    )
    amplitude, phase = amplitude_phase(expected)
    assert not out.nearest.any()
    np.testing.assert_allclose(out.amplitude[0], amplitude, rtol=1e-9)
    np.testing.assert_allclose((out.phase[0] - phase + 180) % 360 - 180, 0, atol=1e-7)


def test_units_are_guessed_with_a_warning_or_taken_from_the_caller(tmp_path):
    lon, lat, glon, glat = grid()
    write_constituent_file(tmp_path / "h_m2_x.nc", lon, lat, linear_field(glon, glat, 0), units=None)
    px, py = np.array([-80.0]), np.array([30.0])
    with pytest.warns(TerrameshWarning, match="no units attribute"):
        guessed = atlas_elevation_constants(tmp_path, px, py, constituents=["M2"])
    given = atlas_elevation_constants(tmp_path, px, py, constituents=["M2"], units="mm")
    np.testing.assert_allclose(guessed.amplitude, given.amplitude)
    np.testing.assert_allclose(given.amplitude[0], amplitude_phase(linear_field(px, py, 0))[0], atol=2e-3)


def test_atlas_errors_name_the_problem(tmp_path):
    lon, lat, glon, glat = grid()
    write_constituent_file(tmp_path / "h_m2_x.nc", lon, lat, linear_field(glon, glat, 0))
    with pytest.raises(ForcingError, match="no h_<con>_\\*.nc file for S2"):
        atlas_elevation_constants(tmp_path, [-80.0], [30.0], constituents=["M2", "S2"])
    with pytest.raises(ForcingError, match="not empty"):
        atlas_elevation_constants(tmp_path, [], [], constituents=["M2"])
    with pytest.raises(MeshFormatError, match="not found"):
        atlas_elevation_constants(tmp_path / "missing.nc", [-80.0], [30.0], constituents=["M2"])
    bad = tmp_path / "bad"
    bad.mkdir()
    with netCDF4.Dataset(bad / "h_m2_bad.nc", "w") as nc:
        nc.createDimension("nx", 2)
        nc.createVariable("depth", "f8", ("nx",))[:] = [1, 2]
    with pytest.raises(MeshFormatError, match="no hRe/hIm or ha/hp"):
        atlas_elevation_constants(bad, [-80.0], [30.0], constituents=["M2"])
    dry = tmp_path / "dry"
    dry.mkdir()
    write_constituent_file(dry / "h_m2_dry.nc", lon, lat, np.zeros_like(glon, dtype=complex))
    with pytest.raises(MeshFormatError, match="no ocean"):
        atlas_elevation_constants(dry, [-80.0], [30.0], constituents=["M2"])


def test_one_tpxo9_atlas_file_of_one_constituent_names_it_in_con(tmp_path):
    # h_m2_tpxo9_atlas_30.nc names its constituent in a 1-D 'con' of characters over 2-D fields: it was taken
    # for a file of several, split into letters and refused ("has no M2; it holds M, 2, , ")
    path = tmp_path / "h_m2_tpxo9_atlas_30_v5.nc"
    lon, lat = np.arange(0.0, 360.0, 1.0) + 0.5, np.arange(-89.5, 90.0, 1.0)
    with netCDF4.Dataset(path, "w") as nc:
        nc.createDimension("nx", len(lon))
        nc.createDimension("ny", len(lat))
        nc.createDimension("nct", 4)
        nc.createVariable("con", "S1", ("nct",))[:] = netCDF4.stringtochar(np.array(["m2  "], dtype="S4"))[0]
        nc.createVariable("lon_z", "f8", ("nx",))[:] = lon
        nc.createVariable("lat_z", "f8", ("ny",))[:] = lat
        for name, value in (("hRe", 300), ("hIm", -400)):
            field = nc.createVariable(name, "i4", ("nx", "ny"))
            field.units = "millimeter"
            field[:] = value
    constants = atlas_elevation_constants(path, [-70.0], [42.0], constituents=["M2"])
    np.testing.assert_allclose(constants.amplitude, [[0.5]])
    with pytest.raises(ForcingError, match="has no K1; it holds M2"):
        atlas_elevation_constants(path, [-70.0], [42.0], constituents=["K1"])
