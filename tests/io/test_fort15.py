import datetime as dt
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh.coastal.tides import HarmonicConstants, tidal_factors
from terramesh.errors import ForcingError, GeometryError, TerrameshWarning
from terramesh.io import Boundaries, LandBoundary, NodalAttribute, NodalAttributes, OpenBoundary
from terramesh.io.fort15 import DEFAULT_CONSTITUENTS, check_fort15_options, write_fort15

from ..conftest import truth, write_atlas

MAJOR8 = ("M2", "S2", "N2", "K2", "K1", "O1", "P1", "Q1")
START = dt.datetime(2012, 6, 1, 0, 0)


def structured_mesh(nx=5, ny=4, flux=False):
    """A lon/lat grid off Florida: open boundaries along the south (west to east) and east (south to north) sides."""
    lon, lat = np.meshgrid(np.linspace(-80.0, -78.0, nx), np.linspace(30.0, 31.5, ny), indexing="xy")
    points = np.column_stack([lon.ravel(), lat.ravel()])
    index = np.arange(nx * ny).reshape(ny, nx)
    cells = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a, b, c, d = index[j, i], index[j, i + 1], index[j + 1, i + 1], index[j + 1, i]
            cells += [[a, b, c], [a, c, d]]
    south = index[0, :]
    east = index[1:, -1]
    land = np.concatenate([index[-1, ::-1][1:], index[::-1, 0][1:]])
    boundaries = Boundaries(
        open=[OpenBoundary(south.copy()), OpenBoundary(east.copy())],
        land=[LandBoundary(land, 22 if flux else 20)],
    )
    depth = 20.0 + 10.0 * (points[:, 0] + 80.0)
    return tm.Mesh(points, cells, point_data={"depth": depth}, boundaries=boundaries, crs="EPSG:4326", title="grid")


class Fort15:
    """A reader for the layout write_fort15 writes, following the ADCIRC documentation's conditionals."""

    def __init__(self, path, n_open_nodes, flux=False):
        self.raw = path.read_text().splitlines()
        self.position = 0
        r = {}
        r["RUNDES"], r["RUNID"] = self.text(32), self.text(24)
        for key in ("NFOVER", "NABOUT", "NSCREEN", "IHOT", "ICS", "IM", "NOLIBF", "NOLIFA", "NOLICA", "NOLICAT"):
            (r[key],) = self.ints(1)
        (r["NWP"],) = self.ints(1)
        r["AttrName"] = [self.whole() for _ in range(r["NWP"])]
        for key in ("NCOR", "NTIP", "NWS", "NRAMP"):
            (r[key],) = self.ints(1)
        for key in ("G", "TAU0", "DTDP", "STATIM", "REFTIM", "RNDAY"):
            (r[key],) = self.reals(1)
        assert r["NWS"] == 0 and r["IM"] == 0 and r["NOLIBF"] == 1  # no WTIMINC line, one ESLM, CF only
        (r["DRAMP"],) = self.reals(1)
        r["A00 B00 C00"] = self.reals(3)
        r["H0"] = self.reals(4 if r["NOLIFA"] == 2 else 1)
        r["SLAM0 SFEA0"] = self.reals(2)
        (r["CF"],) = self.reals(1)
        (r["ESLM"],) = self.reals(1)
        (r["CORI"],) = self.reals(1)
        (r["NTIF"],) = self.ints(1)
        r["potential"] = [(self.text(10).strip(), self.reals(5)) for _ in range(r["NTIF"])]
        (r["NBFR"],) = self.ints(1)
        r["boundary"] = [(self.text(10).strip(), self.reals(3)) for _ in range(r["NBFR"])]
        r["forcing"] = []
        for _ in range(r["NBFR"]):
            name = self.text(10).strip()
            r["forcing"].append((name, np.array([self.reals(2) for _ in range(n_open_nodes)]).reshape(-1, 2)))
        (r["ANGINN"],) = self.reals(1)
        if flux:
            (r["NFFR"],) = self.ints(1)
        for prefix, count in (("E", "NSTAE"), ("V", "NSTAV")):
            r[f"NOUT{prefix}"] = self.reals(4)
            (r[count],) = self.ints(1)
            r[count + " stations"] = np.array([self.reals(2) for _ in range(r[count])]).reshape(-1, 2)
        r["NOUTGE"] = self.reals(4)
        r["NOUTGV"] = self.reals(4)
        (r["NFREQ"],) = self.ints(1)
        r["analysis"] = [(self.text(10).strip(), self.reals(3)) for _ in range(r["NFREQ"])]
        r["THAS THAF NHAINC FMV"] = self.reals(4)
        r["NHASE NHASV NHAGE NHAGV"] = self.ints(4)
        r["NHSTAR NHSINC"] = self.ints(2)
        r["ITITER ISLDIA CONVCR ITMAX"] = self.reals(4)
        codes = [r["NOUTE"][0], r["NOUTV"][0], r["NOUTGE"][0], r["NOUTGV"][0], *r["NHASE NHASV NHAGE NHAGV"]]
        codes.append(r["NHSTAR NHSINC"][0])
        r["netcdf"] = [self.whole() for _ in range(10)] if any(abs(c) in (3, 5) for c in codes) else []
        assert self.position == len(self.raw), f"unread lines after line {self.position}: {self.raw[self.position :]}"
        self.values = r

    def line(self):
        assert self.position < len(self.raw), "the file ends early"
        self.position += 1
        return self.raw[self.position - 1]

    def text(self, width):
        """A fixed-width character field, as ADCIRC reads names (A32, A24, A10)."""
        line = self.line()
        assert "!" in line[width:], f"no comment after the field: {line!r}"
        return line[:width]

    def whole(self):
        """A line ADCIRC reads whole as text: no comment allowed."""
        line = self.line()
        assert "!" not in line, f"a comment would become part of the value: {line!r}"
        return line.strip()

    def numbers(self, count):
        """List-directed input: the first ``count`` values; the rest of the line must be the comment."""
        line = self.line()
        values, _, comment = line.partition("!")
        assert comment.strip(), f"no comment naming the variables: {line!r}"
        tokens = values.split()
        assert len(tokens) == count, f"expected {count} values on {line!r}"
        return tokens

    def ints(self, count):
        return [int(t) for t in self.numbers(count)]

    def reals(self, count):
        return [float(t) for t in self.numbers(count)]


def test_every_field_reads_back_in_the_documented_order(tmp_path):
    mesh = structured_mesh()
    before = (mesh.points.copy(), mesh.cells.copy(), [b.nodes.copy() for b in mesh.boundaries.open])
    atlas = write_atlas(tmp_path, MAJOR8)
    stations = [[-79.3, 30.7], [-78.2, 31.4]]
    attributes = ["primitive_weighting_in_continuity_equation", "mannings_n_at_sea_floor"]
    path = tmp_path / "fort.15"
    write_fort15(
        path,
        mesh,
        start=START,
        run_days=30,
        dt=60.0,
        tidal_atlas=atlas,
        ramp_days=5,
        nodal_attributes=attributes,
        stations=stations,
        station_interval=360,
        global_interval=3600,
        harmonic_analysis=True,
        title="Florida tides",
        run_id="run01",
    )
    open_nodes = np.concatenate([b.nodes for b in mesh.boundaries.open])
    r = Fort15(path, len(open_nodes)).values
    assert r["RUNDES"].strip() == "Florida tides" and r["RUNID"].strip() == "run01"
    assert (r["IHOT"], r["ICS"], r["IM"], r["NOLIFA"], r["NCOR"], r["NTIP"], r["NRAMP"]) == (0, 2, 0, 2, 1, 1, 1)
    assert r["AttrName"] == attributes and r["NWP"] == 2
    assert r["TAU0"] == -3  # primitive weighting read from fort.13
    assert (r["DTDP"], r["RNDAY"], r["DRAMP"], r["STATIM"], r["REFTIM"]) == (60, 30, 5, 0, 0)
    np.testing.assert_allclose(r["SLAM0 SFEA0"], [-79.0, 30.75])
    np.testing.assert_allclose(r["A00 B00 C00"], [0.35, 0.30, 0.35])

    factors = tidal_factors(MAJOR8, START, run_days=30)
    assert [name for name, _ in r["potential"]] == list(MAJOR8)
    for (name, (tpk, amigt, etrf, fft, facet)), f, v in zip(
        r["potential"], factors.nodal_factor, factors.equilibrium_argument, strict=True
    ):
        c = tm.coastal.tides.CONSTITUENTS[name]
        assert (tpk, etrf) == (c.potential_amplitude, c.earth_tide_reduction)
        assert amigt == pytest.approx(c.frequency, rel=1e-12)
        assert fft == pytest.approx(f, abs=1e-6) and facet == pytest.approx(v, abs=1e-4)
    assert [name for name, _ in r["boundary"]] == list(MAJOR8)
    np.testing.assert_allclose([row for _, row in r["boundary"]], [[row[1], *row[3:]] for _, row in r["potential"]])

    # one EMO EFA line per open-boundary node per constituent, in the order of mesh.boundaries.open
    lon, lat = mesh.points[open_nodes, 0], mesh.points[open_nodes, 1]
    assert [name for name, _ in r["forcing"]] == list(MAJOR8)
    for k, (_, table) in enumerate(r["forcing"]):
        assert table.shape == (len(open_nodes), 2)
        h = truth(lon, lat, k)
        np.testing.assert_allclose(table[:, 0], np.abs(h), rtol=1e-6)
        np.testing.assert_allclose(table[:, 1], np.degrees(np.arctan2(-h.imag, h.real)) % 360, atol=1e-4)
    node_comments = [line for line in path.read_text().splitlines() if "EMO EFA" in line]
    assert [int(line.rsplit("node", 1)[1]) for line in node_comments[: len(open_nodes)]] == list(open_nodes + 1)

    assert r["NSTAE"] == 2 and r["NSTAV"] == 2
    np.testing.assert_allclose(r["NSTAE stations"], stations)
    assert r["NOUTE"] == [1, 0, 30, 6] and r["NOUTGE"] == [1, 0, 30, 60] and r["NOUTGV"] == [1, 0, 30, 60]
    assert [name for name, _ in r["analysis"]] == list(MAJOR8)
    assert r["THAS THAF NHAINC FMV"] == [5, 30, 6, 0]
    assert r["NHASE NHASV NHAGE NHAGV"] == [1, 1, 1, 1]
    assert r["netcdf"] == []
    # the caller's mesh is untouched
    np.testing.assert_array_equal(mesh.points, before[0])
    np.testing.assert_array_equal(mesh.cells, before[1])
    for boundary, nodes in zip(mesh.boundaries.open, before[2], strict=True):
        np.testing.assert_array_equal(boundary.nodes, nodes)


def test_netcdf_output_adds_the_metadata_lines_and_shallow_water_constituents_stay_out_of_the_potential(tmp_path):
    mesh = structured_mesh()
    n_open = sum(len(b.nodes) for b in mesh.boundaries.open)
    constants = HarmonicConstants(
        ("M2", "M4"), np.full((2, n_open), 0.25), np.tile(np.arange(n_open, dtype=float), (2, 1)), np.zeros((2, n_open))
    )
    path = tmp_path / "fort.15"
    write_fort15(
        path,
        mesh,
        start="2020-01-01T06:00",
        run_days=3,
        dt=10,
        constituents=["M2", "M4"],
        boundary_constants=constants,
        ramp_days=0,
        wetting_drying=False,
        output_format="netcdf",
        global_velocity=False,
        hotstart_interval_days=1,
        netcdf_metadata={"ncinst": "Example Institute", "NCCONT": "someone@example.org"},
    )
    r = Fort15(path, n_open).values
    assert r["NTIF"] == 1 and r["potential"][0][0] == "M2"  # M4 has no equilibrium potential
    assert [name for name, _ in r["boundary"]] == ["M2", "M4"]
    np.testing.assert_allclose(r["forcing"][1][1][:, 1], np.arange(n_open))
    assert r["NRAMP"] == 0 and r["NOLIFA"] == 1 and len(r["H0"]) == 1
    assert r["NOUTGE"][0] == 5 and r["NOUTGV"][0] == 0 and r["NHSTAR NHSINC"] == [5, 8640]
    assert r["NOUTE"][0] == 0 and r["NSTAE"] == 0
    assert len(r["netcdf"]) == 10
    assert r["netcdf"][1] == "Example Institute" and r["netcdf"][8] == "someone@example.org"
    assert r["netcdf"][9] == "2020-01-01 06:00:00"


def test_flux_boundaries_get_nfrr_and_a_warning(tmp_path):
    mesh = structured_mesh(flux=True)
    n_open = sum(len(b.nodes) for b in mesh.boundaries.open)
    with pytest.warns(TerrameshWarning, match="fort.20"):
        write_fort15(
            tmp_path / "fort.15",
            mesh,
            start=START,
            run_days=2,
            dt=30,
            constituents=["M2"],
            boundary_constants={"M2": (np.full(n_open, 0.3), np.zeros(n_open))},
            ramp_days=1,
        )
    assert Fort15(tmp_path / "fort.15", n_open, flux=True).values["NFFR"] == 0


def test_potential_only_run_on_a_mesh_without_boundaries(tmp_path):
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    attributes = NodalAttributes({"mannings_n_at_sea_floor": NodalAttribute("s/m^(1/3)", [0.02], np.full(20, 0.02))})
    write_fort15(tmp_path / "fort.15", mesh, start=START, run_days=1, dt=30, ramp_days=0.5, nodal_attributes=attributes)
    r = Fort15(tmp_path / "fort.15", 0).values
    assert r["NTIF"] == 8 and r["NBFR"] == 0 and r["forcing"] == []
    assert r["AttrName"] == ["mannings_n_at_sea_floor"] and r["TAU0"] == 0.005
    assert r["RUNDES"].strip() == "grid"  # the mesh title


def test_open_boundaries_without_forcing_warn(tmp_path):
    with pytest.warns(TerrameshWarning, match="zero elevation"):
        write_fort15(tmp_path / "fort.15", structured_mesh(), start=START, run_days=1, dt=30, ramp_days=0.5)


def test_forcing_needs_an_open_boundary(tmp_path):
    mesh = structured_mesh()
    mesh.boundaries = Boundaries(land=mesh.boundaries.land)
    with pytest.raises(ForcingError, match="no open boundary"):
        write_fort15(tmp_path / "fort.15", mesh, start=START, run_days=1, dt=30, ramp_days=0.5, tidal_atlas=tmp_path)


def test_bad_options_raise(tmp_path):
    mesh = structured_mesh()
    path = tmp_path / "fort.15"
    n_open = sum(len(b.nodes) for b in mesh.boundaries.open)
    common = {"start": START, "run_days": 2, "ramp_days": 1}
    with pytest.raises(GeometryError, match="1 stations lie outside the mesh"):
        write_fort15(path, mesh, dt=30, stations=[[-79.5, 30.5], [-70.0, 30.5]], **common)
    with pytest.raises(ForcingError, match=r"station_interval \(5 s\) is shorter than the time step dt = 7 s"):
        write_fort15(path, mesh, dt=7, station_interval=5, **common)
    with pytest.raises(ForcingError, match="dt must be"):
        write_fort15(path, mesh, dt=0, **common)
    with pytest.raises(ForcingError, match="one per open-boundary node"):
        write_fort15(path, mesh, dt=30, constituents=["M2"], boundary_constants={"M2": ([0.1], [0.0])}, **common)
    with pytest.raises(ForcingError, match="no equilibrium tidal potential"):
        write_fort15(path, mesh, dt=30, potential_constituents=["M4"], **common)
    with pytest.raises(ForcingError, match="unknown tidal constituent"):
        write_fort15(path, mesh, dt=30, constituents=["M2", "Z0"], **common)
    projected = tm.Mesh(mesh.points * 1e5, mesh.cells, boundaries=mesh.boundaries, crs="EPSG:32617")
    with pytest.raises(ForcingError, match="reproject"):
        write_fort15(path, projected, dt=30, **common)
    with pytest.raises(ForcingError, match="not both"):
        write_fort15(
            path,
            mesh,
            dt=30,
            constituents=["M2"],
            tidal_atlas=tmp_path,
            boundary_constants={"M2": (np.zeros(n_open), np.zeros(n_open))},
            **common,
        )
    assert not path.exists()


def test_raises_section_documents_forcing_error_for_bad_options():
    raises = write_fort15.__doc__.split("Raises\n    ------\n")[1].split("Warns\n")[0]
    forcing = raises.split("ForcingError\n")[1].split("MeshFormatError\n")[0]
    assert "interval\n        shorter than the time step" in forcing and "unknown constituents" in forcing
    assert "non-geographic mesh" in forcing and "without" in forcing and "wrong size" in forcing
    assert raises.split("MeshFormatError\n")[1].split("GeometryError\n")[0].strip() == "For unreadable atlas files."


NON_FINITE_OPTIONS = {
    "eddy_viscosity": lambda x: x,
    "tau0": lambda x: x,
    "anginn": lambda x: x,
    "harmonic_start_days": lambda x: x,
    "screen_interval": lambda x: x,
    "time_weights": lambda x: (x, 0.3, 0.35),
    "solver": lambda x: (1, 0, x, 25),
}


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.sampled_from(sorted(NON_FINITE_OPTIONS)), st.sampled_from([np.nan, np.inf, -np.inf]))
def test_hypothesis_non_finite_numbers_are_refused_before_writing(tmp_path, option, value):
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    path = tmp_path / "fort.15"
    with pytest.raises(ForcingError, match=option):
        write_fort15(
            path, mesh, start=START, run_days=2, dt=30, ramp_days=1, **{option: NON_FINITE_OPTIONS[option](value)}
        )
    assert not path.exists()


@pytest.mark.parametrize(
    "option, value, message",
    [
        ("screen_interval", 2.5, r"screen_interval must be a finite whole number, got 2\.5"),  # was written as 2
        ("screen_interval", "abc", "screen_interval must be a finite whole number"),
        ("solver", (1.5, 0, 1e-10, 25), r"solver ITITER must be a finite whole number, got 1\.5"),  # was 1
        ("solver", (1, 0, 1e-10, 25.5), r"solver ITMAX must be a finite whole number, got 25\.5"),  # was 25
        ("solver", 5, r"solver \(ITITER, ISLDIA, CONVCR, ITMAX\) must be a sequence"),  # was a TypeError
        ("time_weights", 1.0, r"time_weights \(A00, B00, C00\) must be a sequence"),  # was a TypeError
        ("hotstart_interval_days", "abc", "hotstart_interval_days must be a finite number > 0, got 'abc'"),
        ("hotstart_interval_days", -1, "hotstart_interval_days must be a finite number > 0, got -1"),
        ("hotstart_interval_days", 1e-4, r"hotstart_interval_days \(8\.64 s\) is shorter than the time step"),
    ],
)
def test_options_refused_with_their_name(tmp_path, option, value, message):
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    path = tmp_path / "fort.15"
    with pytest.raises(ForcingError, match=message):
        write_fort15(path, mesh, start=START, run_days=2, dt=30, ramp_days=1, **{option: value})
    assert not path.exists()
    with pytest.raises(ForcingError, match=message):  # and so, before there is a mesh
        check_fort15_options(start=START, run_days=2, dt=30, ramp_days=1, **{option: value})


def test_intervals_are_rounded_to_whole_time_steps_with_a_warning(tmp_path):
    # ADCIRC counts output intervals in steps and takes any DTDP: dt = 20.9 s (as dt = 0 picks) was refused
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    path = tmp_path / "fort.15"
    with pytest.warns(TerrameshWarning) as caught:
        write_fort15(
            path, mesh, start=START, run_days=2, dt=20.9, ramp_days=1, harmonic_analysis=True, harmonic_interval=900
        )
    said = sorted(str(w.message) for w in caught)
    assert said == [
        "global_interval (3600 s) is not a whole number of time steps of dt = 20.9 s: written as 172 steps (3594.8 s)",
        "harmonic_interval (900 s) is not a whole number of time steps of dt = 20.9 s: written as 43 steps (898.7 s)",
        "station_interval (600 s) is not a whole number of time steps of dt = 20.9 s: written as 29 steps (606.1 s)",
    ]
    values = {
        line.split("!")[1].split(" - ")[0].strip(): line.split("!")[0].split()
        for line in path.read_text().splitlines()
        if "!" in line
    }
    assert values["NOUTE TOUTSE TOUTFE NSPOOLE"][-1] == "29"
    assert values["NOUTGE TOUTSGE TOUTFGE NSPOOLGE"][-1] == "172"
    assert values["THAS THAF NHAINC FMV"][2] == "43"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # whole numbers of steps: nothing to say
        write_fort15(path, mesh, start=START, run_days=2, dt=30, ramp_days=1)


def test_options_are_checked_without_a_mesh_and_without_warning_twice():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_fort15_options(start=START, run_days=1, dt=30, title="x" * 40)  # warned when written, not here
    with pytest.raises(ForcingError, match="constituents lists a constituent twice: M2, M2"):
        check_fort15_options(start=START, run_days=5, dt=30, constituents=["M2", "M2"])
    with pytest.raises(TypeError, match="missing a required argument: 'dt'"):
        check_fort15_options(start=START, run_days=5)
    with pytest.raises(TypeError, match="unexpected keyword argument 'stride'"):
        check_fort15_options(start=START, run_days=5, dt=30, stride=2)


def test_whole_numbers_given_as_floats_or_strings_are_taken(tmp_path):
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    path = tmp_path / "fort.15"
    options = dict(start=START, run_days=2, dt=30, ramp_days=1, screen_interval=np.float64(50.0))
    write_fort15(path, mesh, solver=(1.0, 0, 1e-10, "30"), hotstart_interval_days="0.5", **options)
    r = Fort15(path, 0).values
    assert r["NSCREEN"] == 50 and r["ITITER ISLDIA CONVCR ITMAX"] == [1, 0, 1e-10, 30]
    assert r["NHSTAR NHSINC"] == [1, 1440]


def test_long_title_is_cut_with_a_warning_and_velocity_stations_can_differ(tmp_path):
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    with pytest.warns(TerrameshWarning, match="cut to the 32 characters"):
        write_fort15(
            tmp_path / "fort.15",
            mesh,
            start=START,
            run_days=1,
            dt=30,
            ramp_days=0.5,
            title="a description much longer than thirty-two characters",
            stations=[[-79.0, 31.0]],
            velocity_stations=[[-79.9, 30.1], [-78.1, 31.4], [-79.0, 30.75]],
        )
    r = Fort15(tmp_path / "fort.15", 0).values
    assert r["RUNDES"] == "a description much longer than t"
    assert r["NSTAE"] == 1 and r["NSTAV"] == 3
    np.testing.assert_allclose(r["NSTAV stations"][2], [-79.0, 30.75])


def test_stations_in_the_other_longitude_convention_are_written_in_the_mesh_s(tmp_path):
    # they were accepted (inside after a 360 shift) but written at 281 E, where ADCIRC finds no cell
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    write_fort15(
        tmp_path / "fort.15",
        mesh,
        start=START,
        run_days=1,
        dt=30,
        ramp_days=0.5,
        stations=[[-79.0 + 360.0, 31.0], [-79.5, 30.5]],
    )
    r = Fort15(tmp_path / "fort.15", 0).values
    np.testing.assert_allclose(r["NSTAE stations"], [[-79.0, 31.0], [-79.5, 30.5]])


def test_the_guides_major8_and_matlab_dates_are_read(tmp_path):
    # Make_f15's 'major8' and MATLAB's datestr were refused
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    common = dict(run_days=1, dt=30, ramp_days=0.5)
    write_fort15(tmp_path / "guide.15", mesh, start="01-Jun-2012 00:00", constituents="major8", **common)
    write_fort15(tmp_path / "plain.15", mesh, start="2012-06-01", constituents=DEFAULT_CONSTITUENTS, **common)
    assert (tmp_path / "guide.15").read_text() == (tmp_path / "plain.15").read_text()


@pytest.mark.parametrize("crs", ["EPSG:4269", "+proj=longlat +datum=WGS84", 4326])
def test_any_longitude_latitude_crs_is_written_with_ics_2(tmp_path, crs):
    """NAD83 (EPSG:4269) and PROJ strings were taken for planar: "reproject it first"."""
    mesh = structured_mesh()
    mesh.boundaries = Boundaries()
    mesh.crs = crs
    write_fort15(tmp_path / "fort.15", mesh, start=START, run_days=1, dt=30, ramp_days=0.5)
    assert Fort15(tmp_path / "fort.15", 0).values["ICS"] == 2


def test_long_period_constituents_stay_out_of_the_tidal_potential(tmp_path):
    # ADCIRC forces the potential of species 1 and 2 only (NA = NINT(0.00014 / AMIGT)): Mf and Mm lines in NTIF
    # were read and ignored
    mesh = structured_mesh()
    n_open = sum(len(b.nodes) for b in mesh.boundaries.open)
    constants = HarmonicConstants(
        ("M2", "K1", "MF", "MM"), np.full((4, n_open), 0.1), np.zeros((4, n_open)), np.zeros((4, n_open))
    )
    options = dict(start=START, run_days=60, dt=30, constituents=["M2", "K1", "Mf", "Mm"], ramp_days=1)
    write_fort15(tmp_path / "fort.15", mesh, boundary_constants=constants, **options)
    r = Fort15(tmp_path / "fort.15", n_open).values
    assert [name for name, _ in r["potential"]] == ["M2", "K1"]
    with pytest.raises(ForcingError, match="Mf, Mm would be listed in NTIF and ignored"):
        write_fort15(
            tmp_path / "f.15", mesh, boundary_constants=constants, potential_constituents=["M2", "Mf", "Mm"], **options
        )
