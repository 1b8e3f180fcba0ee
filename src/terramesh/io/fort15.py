"""ADCIRC ``fort.15`` model parameter and periodic boundary condition file, for a tidal run.

Layout written (ADCIRC documentation, "Fort.15: Model Parameter and Periodic
Boundary Condition File"), one line per item, in this order:

* ``RUNDES``; ``RUNID``; ``NFOVER``; ``NABOUT``; ``NSCREEN``; ``IHOT`` (0,
  cold start); ``ICS`` (2, spherical); ``IM`` (0, 2DDI); ``NOLIBF`` (1,
  quadratic friction); ``NOLIFA`` (2 with wetting and drying, else 1);
  ``NOLICA``; ``NOLICAT``; ``NWP`` and its ``AttrName`` lines; ``NCOR`` (1,
  Coriolis from latitude); ``NTIP``; ``NWS`` (0); ``NRAMP``; ``G``;
  ``TAU0``; ``DTDP``; ``STATIM``; ``REFTIM``; ``RNDAY``; ``DRAMP``;
  ``A00 B00 C00``; ``H0 NODEDRYMIN NODEWETMIN VELMIN`` (or ``H0`` when
  ``NOLIFA`` is 1); ``SLAM0 SFEA0``; ``CF``; ``ESLM``; ``CORI``;
* ``NTIF`` and per potential constituent ``TIPOTAG`` and
  ``TPK AMIGT ETRF FFT FACET``;
* ``NBFR``, per boundary constituent ``BOUNTAG`` and ``AMIG FF FACE``, then
  per constituent ``ALPHAE`` and ``NETA`` lines ``EMO EFA``, one per
  open-boundary node in the order of ``mesh.boundaries.open``;
* ``ANGINN``; ``NFFR`` (0: flux from fort.20) only when the grid has
  flux-specified boundaries (IBTYPE 2, 12, 22, 32, 52);
* ``NOUTE TOUTSE TOUTFE NSPOOLE``, ``NSTAE`` and ``XEL YEL`` per station;
  ``NOUTV TOUTSV TOUTFV NSPOOLV``, ``NSTAV`` and ``XEV YEV``;
  ``NOUTGE TOUTSGE TOUTFGE NSPOOLGE``; ``NOUTGV TOUTSGV TOUTFGV NSPOOLGV``;
* ``NFREQ`` and per analysed constituent ``NAMEFR`` and
  ``HAFREQ HAFF HAFACE``; ``THAS THAF NHAINC FMV``;
  ``NHASE NHASV NHAGE NHAGV``; ``NHSTAR NHSINC``;
  ``ITITER ISLDIA CONVCR ITMAX``;
* with NetCDF output, the ten metadata lines ``NCPROJ`` ... ``NCDATE``.

Every line carries its ADCIRC variable names after ``!``, except the lines
ADCIRC reads whole as text (``AttrName`` and the NetCDF metadata), where a
comment would become part of the value. Names read with fixed widths
(``RUNDES`` A32, ``RUNID`` A24, constituent names A10) are padded so the
comment starts after the field.
"""

import inspect
import numbers
import warnings

import numpy as np

from ..coastal.tides import (
    CONSTITUENTS,
    HarmonicConstants,
    as_utc,
    atlas_elevation_constants,
    get_constituent,
    tidal_factors,
)
from ..errors import ForcingError, GeometryError, checked_number, warn_user
from ._text import written_whole

__all__ = ["write_fort15", "check_fort15_options", "DEFAULT_CONSTITUENTS", "FLUX_BOUNDARY_TYPES"]


DEFAULT_CONSTITUENTS = ("M2", "S2", "N2", "K2", "K1", "O1", "P1", "Q1")
FLUX_BOUNDARY_TYPES = frozenset({2, 12, 22, 32, 52})
_FORMATS = {"ascii": 1, "netcdf": 5}
_NETCDF_KEYS = ("NCPROJ", "NCINST", "NCSOUR", "NCHIST", "NCREF", "NCCOM", "NCHOST", "NCCONV", "NCCONT", "NCDATE")


def write_fort15(
    path,
    mesh,
    *,
    start,
    run_days,
    dt,
    constituents=DEFAULT_CONSTITUENTS,
    potential_constituents=None,
    tidal_atlas=None,
    atlas_units=None,
    boundary_constants=None,
    ramp_days=2.0,
    nodal_attributes=(),
    tau0=None,
    stations=None,
    velocity_stations=None,
    station_interval=600.0,
    global_interval=3600.0,
    global_velocity=True,
    output_start_days=0.0,
    harmonic_analysis=None,
    harmonic_start_days=None,
    harmonic_interval=None,
    hotstart_interval_days=None,
    output_format="ascii",
    netcdf_metadata=None,
    title=None,
    run_id="tides",
    bottom_friction=0.0025,
    wetting_drying=True,
    minimum_depth=0.1,
    minimum_velocity=0.01,
    eddy_viscosity=5.0,
    gravity=9.81,
    advection=True,
    anginn=110.0,
    time_weights=(0.35, 0.30, 0.35),
    solver=(1, 0, 1.0e-10, 25),
    screen_interval=100,
):
    """Write an ADCIRC ``fort.15`` for a tidally forced, cold-started 2DDI run in lon/lat.

    Nodal factors and equilibrium arguments of the tidal potential, the
    boundary forcing and the harmonic analysis come from
    :func:`terramesh.coastal.tides.tidal_factors` (``V0`` at ``start``, ``f``
    and ``u`` at the middle of the run, as ADCIRC's tide_fac). Elevation
    amplitude and phase at the open-boundary nodes come from ``tidal_atlas``
    (a TPXO-format NetCDF atlas, see
    :func:`terramesh.coastal.tides.atlas_elevation_constants`) or from
    ``boundary_constants``. The mesh is not modified.

    Parameters
    ----------
    path : str or os.PathLike
    mesh : Mesh
        2D triangle mesh in longitude, latitude (degrees), with
        ``mesh.boundaries`` (:class:`terramesh.io.Boundaries`) when the
        boundaries are forced.
    start : datetime.datetime, datetime.date, numpy.datetime64 or str
        Cold-start time, UTC (an aware datetime is converted; a string in
        ISO 8601 or MATLAB's ``'01-Aug-2012 00:00'``).
    run_days : float
        ``RNDAY``: length of the run, days.
    dt : float
        ``DTDP``: time step, seconds.
    constituents : sequence of str, optional
        Constituents forced on the open boundaries (``NBFR``), by default the
        eight major ones (``"major8"``, as OceanMesh2D's Make_f15 names
        them); also the default tidal potential set and harmonic analysis
        set.
    potential_constituents : sequence of str, optional
        Constituents of the tidal potential (``NTIF``); by default those of
        ``constituents`` that have an equilibrium potential (shallow-water
        constituents such as M4 have none) and that ADCIRC forces it for:
        diurnal and semidiurnal ones (Mf and Mm it ignores; asked for, they
        are refused). An empty sequence turns the potential off
        (``NTIP = 0``).
    tidal_atlas : str, os.PathLike or mapping, optional
        TPXO atlas (folder of ``h_<con>_*.nc``, single ``h_tpxo*.nc``, or
        ``{constituent: file}``) sampled at the open-boundary nodes.
    atlas_units : {"mm", "cm", "m"}, optional
        Units of the atlas fields where the files do not say.
    boundary_constants : HarmonicConstants or mapping, optional
        Instead of an atlas: amplitude (m) and Greenwich phase (degrees) per
        open-boundary node, as a :class:`~terramesh.coastal.tides.HarmonicConstants`
        or ``{constituent: (amplitude, phase)}`` with ``NETA`` values each,
        in the order of ``mesh.boundaries.open``.
    ramp_days : float, optional
        ``DRAMP``: hyperbolic-tangent ramp of the forcing, days (0: no ramp,
        ``NRAMP = 0``).
    nodal_attributes : sequence of str or mapping, optional
        Names of the fort.13 attributes to use (``NWP`` and ``AttrName``),
        e.g. ``["primitive_weighting_in_continuity_equation",
        "mannings_n_at_sea_floor"]``; a :class:`~terramesh.io.NodalAttributes`
        gives its names.
    tau0 : float, optional
        ``TAU0``, the GWCE primitive weighting; by default -3 (read from
        fort.13) when ``primitive_weighting_in_continuity_equation`` is among
        the nodal attributes, else 0.005.
    stations : array_like, shape (n, 2), optional
        Elevation recording stations (``NSTAE``), longitude and latitude in
        degrees; each must lie inside the mesh.
    velocity_stations : array_like, shape (m, 2), optional
        Velocity recording stations (``NSTAV``); by default ``stations``.
    station_interval : float, optional
        Station output interval (``NSPOOLE``, ``NSPOOLV``), seconds; a
        whole number of time steps of ``dt``, or the nearest one (with a
    warning).
    global_interval : float or None, optional
        Global elevation/velocity output interval (``NSPOOLGE``,
        ``NSPOOLGV``), seconds; None writes no global output.
    global_velocity : bool, optional
        Write global velocity output (fort.64) besides elevation (fort.63).
    output_start_days : float, optional
        ``TOUTSE``, ``TOUTSV``, ``TOUTSGE``, ``TOUTSGV``: when output starts,
        days after the cold start; it ends at ``run_days``.
    harmonic_analysis : bool or sequence of str, optional
        Constituents to analyse (``NFREQ``); True means ``constituents``,
        None or False none.
    harmonic_start_days : float, optional
        ``THAS``, days; by default ``ramp_days``. ``THAF`` is ``run_days``.
    harmonic_interval : float, optional
        ``NHAINC`` as seconds; by default ``station_interval``.
    hotstart_interval_days : float, optional
        Write hot-start files every so many days (``NHSTAR``, ``NHSINC``).
    output_format : {"ascii", "netcdf"}, optional
        Output files as ASCII (``NOUT* = 1``) or NetCDF4 (5); NetCDF adds the
        metadata lines.
    netcdf_metadata : mapping, optional
        Values for ``NCPROJ``, ``NCINST``, ``NCSOUR``, ``NCHIST``, ``NCREF``,
        ``NCCOM``, ``NCHOST``, ``NCCONV``, ``NCCONT``, ``NCDATE``; the rest
        get defaults (``NCDATE`` is the start time).
    title : str, optional
        ``RUNDES`` (32 characters); by default the mesh title.
    run_id : str, optional
        ``RUNID`` (24 characters).
    bottom_friction : float, optional
        ``CF``, quadratic bottom friction coefficient (``NOLIBF = 1``); a
        Manning's n nodal attribute overrides it in ADCIRC.
    wetting_drying : bool, optional
        ``NOLIFA = 2`` (finite amplitude with wetting and drying) or 1.
    minimum_depth : float, optional
        ``H0``, metres.
    minimum_velocity : float, optional
        ``VELMIN``, m/s (wetting and drying only).
    eddy_viscosity : float, optional
        ``ESLM``, m^2/s; a negative value is a Smagorinsky coefficient.
    gravity : float, optional
        ``G``, m/s^2.
    advection : bool, optional
        ``NOLICA`` and ``NOLICAT``.
    anginn : float, optional
        ``ANGINN``, degrees.
    time_weights : tuple of float, optional
        ``A00 B00 C00``.
    solver : tuple, optional
        ``ITITER ISLDIA CONVCR ITMAX``.
    screen_interval : int, optional
        ``NSCREEN``; a whole number (2.5 is refused, not rounded).

    Raises
    ------
    ForcingError
        For options ADCIRC cannot take (non-positive ``dt``, an interval
        shorter than the time step, unknown constituents, a number
        that is NaN or infinite or not a number at all, a fraction for an
        integer option (``screen_interval``, ``solver``'s ITITER, ISLDIA,
        ITMAX), a non-geographic mesh, boundary forcing asked for on a mesh
        without open boundaries, boundary constants of the wrong size). No
        file is written then.
    MeshFormatError
        For unreadable atlas files.
    GeometryError
        If a station lies outside the mesh.

    Warns
    -----
    TerrameshWarning
        When the grid has open boundaries but no boundary forcing is given,
        when it has flux boundaries (ADCIRC then reads fort.20), when
        atlas values at some nodes come from the nearest ocean cell, and
        when an output interval is not a whole number of time steps (the
        nearest is written).

    Examples
    --------
    >>> import os, pathlib, tempfile, numpy as np
    >>> import terramesh as tm
    >>> from terramesh.io import Boundaries, OpenBoundary
    >>> points = np.array([[-80.0, 30.0], [-79.0, 30.0], [-79.0, 31.0], [-80.0, 31.0]])
    >>> mesh = tm.Mesh(points, [[0, 1, 2], [0, 2, 3]], point_data={"depth": np.full(4, 50.0)},
    ...                boundaries=Boundaries(open=[OpenBoundary(np.array([0, 1]))]), crs="EPSG:4326")
    >>> constants = {"M2": ([0.5, 0.6], [10.0, 12.0])}
    >>> path = os.path.join(tempfile.mkdtemp(), "fort.15")
    >>> write_fort15(path, mesh, start="2012-06-01", run_days=10, dt=30, constituents=["M2"],
    ...              boundary_constants=constants, stations=[[-79.5, 30.5]])
    >>> lines = pathlib.Path(path).read_text().splitlines()
    >>> lines[lines.index(next(l for l in lines if "! NBFR" in l)) + 4].split("!")[0].split()
    ['0.5', '10.0000']
    """
    settings = _Settings(locals())
    boundaries = getattr(mesh, "boundaries", None)
    open_nodes = [np.asarray(b.nodes, dtype=np.int64) for b in (boundaries.open if boundaries else [])]
    boundary_nodes = np.concatenate(open_nodes) if open_nodes else np.empty(0, dtype=np.int64)
    forced = tidal_atlas is not None or boundary_constants is not None
    if forced and len(boundary_nodes) == 0:
        raise ForcingError(
            "boundary forcing was asked for (tidal_atlas or boundary_constants) but the mesh has no open boundary "
            "(mesh.boundaries.open is empty); make the boundaries first or drop the forcing"
        )
    if tidal_atlas is not None and boundary_constants is not None:
        raise ForcingError("give tidal_atlas or boundary_constants, not both")
    if boundary_nodes.size and (boundary_nodes.min() < 0 or boundary_nodes.max() >= mesh.n_points):
        raise ForcingError("mesh.boundaries.open refers to nodes the mesh does not have")
    lonlat = _geographic_points(mesh)

    boundary = settings.constituents if forced else ()
    if tidal_atlas is not None:
        found = atlas_elevation_constants(
            tidal_atlas, lonlat[boundary_nodes, 0], lonlat[boundary_nodes, 1], constituents=boundary, units=atlas_units
        )
        amplitude, phase = found.amplitude, found.phase
    elif boundary_constants is not None:
        amplitude, phase = _given_constants(boundary_constants, boundary, len(boundary_nodes))
    else:
        amplitude = phase = np.empty((0, len(boundary_nodes)))

    stations_e = _stations(mesh, lonlat, stations, "stations")
    stations_v = stations_e if velocity_stations is None else _stations(mesh, lonlat, velocity_stations, "velocity")
    flux_types = sorted({b.ibtype for b in (boundaries.land if boundaries else []) if b.ibtype in FLUX_BOUNDARY_TYPES})
    # everything is checked: now say what the user should know
    if not forced and len(boundary_nodes):
        warn_user(
            f"the mesh has {len(boundary_nodes)} open-boundary nodes but no tidal_atlas or boundary_constants was "
            "given: NBFR = 0, so ADCIRC holds the open boundaries at zero elevation",
        )
    if flux_types:
        warn_user(
            f"the grid has flux-specified boundaries (IBTYPE {', '.join(map(str, flux_types))}): NFFR = 0 is "
            "written, so ADCIRC reads their normal flow from a fort.20 file you must supply",
        )

    lines = _Writer()
    settings.write_header(lines, lonlat)
    settings.write_tides(lines, boundary, amplitude, phase, boundary_nodes)
    lines.add(_num(settings.anginn), "ANGINN - minimum angle for tangential flow, degrees")
    if flux_types:
        lines.add("0", "NFFR - number of flux forcing frequencies; 0: non-periodic normal flow from fort.20")
    settings.write_output(lines, stations_e, stations_v)
    with written_whole(path) as temporary, open(temporary, "w", encoding="utf-8") as handle:
        handle.write(lines.text())


class _Writer:
    """Lines with their trailing ``! NAMES - description`` comments."""

    def __init__(self):
        self.lines = []

    def add(self, values, comment=None, width=40):
        text = str(values)
        if comment is None:
            self.lines.append(text)
        else:
            self.lines.append(f"{text:<{width}} ! {comment}")

    def text(self):
        return "\n".join(self.lines) + "\n"


def _num(value):
    """Shortest decimal that reads back to the same float."""
    value = float(value)
    if value == int(value) and abs(value) < 1e15:
        return str(int(value))
    return repr(float(value))


def _deg(angle):
    """Degrees in [0, 360) with four decimals (never "360.0000")."""
    return f"{round(float(angle) % 360.0, 4) % 360.0:.4f}"


def _name(name):
    """Constituent name padded to ADCIRC's A10 field."""
    return f"{name:<10}"


def _positive(value, what, allow_zero=False):
    requirement = f"{what} must be a finite number {'>=' if allow_zero else '>'} 0"
    return checked_number(value, requirement, ForcingError, minimum=0, strict=not allow_zero)


def _finite(value, what):
    """``value`` as a finite float; a ForcingError naming ``what`` otherwise."""
    return checked_number(value, f"{what} must be a finite number", ForcingError)


def _integer(value, what):
    """``value`` as an int; a ForcingError naming ``what`` for anything that is not a finite whole number.

    ``int()`` alone would write 2.5 as 2: a fraction is refused, not rounded.
    """
    if isinstance(value, numbers.Integral):
        return int(value)
    number = checked_number(value, f"{what} must be a finite whole number", ForcingError)
    if number != round(number):
        raise ForcingError(f"{what} must be a finite whole number, got {value!r}")
    return int(number)


def _sequence(value, what):
    """``value`` as a tuple; a ForcingError naming ``what`` for a number, string or anything not iterable."""
    if isinstance(value, (str, bytes)):
        raise ForcingError(f"{what} must be a sequence of numbers, got {value!r}")
    try:
        return tuple(value)
    except TypeError:
        raise ForcingError(f"{what} must be a sequence of numbers, got {value!r}") from None


def _steps(interval, dt, what):
    """A whole number of time steps from an interval in seconds: the nearest, warning where it is not exact.

    ADCIRC counts its output intervals in time steps and takes any ``DTDP``:
    the step ``dt = 0`` picks (20.9 s) was refused against the default 600 s.
    """
    interval = _positive(interval, what)
    steps = interval / dt
    if steps < 1 - 1e-9:
        raise ForcingError(f"{what} ({interval:g} s) is shorter than the time step dt = {dt:g} s")
    whole = int(round(steps))
    if abs(steps - whole) > 1e-6 * steps:
        warn_user(
            f"{what} ({interval:g} s) is not a whole number of time steps of dt = {dt:g} s: written as {whole} "
            f"steps ({whole * dt:g} s)"
        )
    return whole


_GROUPS = {"MAJOR8": DEFAULT_CONSTITUENTS}
"""Names of constituent groups OceanMesh2D's Make_f15 takes (``'major8'``: the eight major ones)."""


def check_fort15_options(**options):
    """Refuse, before there is a mesh, options :func:`write_fort15` would refuse.

    A long job (meshing, a merge, depths from a DEM) that ends in a fort.15
    checks its options first, so an unknown or repeated constituent, a bad
    date or an output interval shorter than the time step is named before
    the work, not after it. The options are ``write_fort15``'s, less ``path`` and
    ``mesh``; what needs the mesh (open boundaries, stations, the atlas at
    its nodes) is checked when the file is written. Warnings wait for the
    writing too.

    Raises
    ------
    ForcingError
        As :func:`write_fort15` would for these options; ``TypeError`` for a
        name it does not take.

    Examples
    --------
    >>> from terramesh.io.fort15 import check_fort15_options
    >>> check_fort15_options(start="2012-06-01", run_days=10, dt=30)
    >>> check_fort15_options(start="2012-06-01", run_days=10, dt=30, constituents=["M2", "M2"])
    Traceback (most recent call last):
    ...
    terramesh.errors.ForcingError: constituents lists a constituent twice: M2, M2
    """
    # bound as write_fort15 binds them: a missing start, run_days or dt, or a name it does not take, is a TypeError
    bound = inspect.signature(write_fort15).bind(None, None, **options)
    bound.apply_defaults()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _Settings(bound.arguments)


def _names(values, what):
    if values is None:
        return ()
    if isinstance(values, str):
        values = _GROUPS.get(values.strip().upper(), [values])
    names = tuple(get_constituent(v).name for v in values)
    if len(set(names)) != len(names):
        raise ForcingError(f"{what} lists a constituent twice: {', '.join(names)}")
    return names


class _Settings:
    """The validated options of one write_fort15 call."""

    def __init__(self, options):
        self.start = as_utc(options["start"], "start")
        self.run_days = _positive(options["run_days"], "run_days")
        self.dt = _positive(options["dt"], "dt")
        self.ramp_days = _positive(options["ramp_days"], "ramp_days", allow_zero=True)
        if self.ramp_days > self.run_days:
            warn_user(
                f"ramp_days ({self.ramp_days:g}) is longer than the run ({self.run_days:g} days): the forcing never "
                "reaches full strength",
            )
        self.constituents = _names(options["constituents"], "constituents")
        potential = options["potential_constituents"]
        # ADCIRC forces the potential of diurnal and semidiurnal constituents only (its NA = NINT(0.00014 /
        # AMIGT) is 1 or 2): an Mf or Mm line in NTIF is read and then ignored, without a word
        if potential is None:
            self.potential = tuple(
                n for n in self.constituents if CONSTITUENTS[n].potential_amplitude > 0 and CONSTITUENTS[n].species
            )
        else:
            self.potential = _names(potential, "potential_constituents")
            without = [n for n in self.potential if CONSTITUENTS[n].potential_amplitude == 0]
            if without:
                raise ForcingError(f"{', '.join(without)} have no equilibrium tidal potential; leave them out")
            long_period = [n for n in self.potential if CONSTITUENTS[n].species == 0]
            if long_period:
                raise ForcingError(
                    f"ADCIRC forces the tidal potential of diurnal and semidiurnal constituents only: "
                    f"{', '.join(long_period)} would be listed in NTIF and ignored; leave them out"
                )
        analysis = options["harmonic_analysis"]
        if analysis is True:
            self.analysis = self.constituents
        elif analysis is None or analysis is False:
            self.analysis = ()
        else:
            self.analysis = _names(analysis, "harmonic_analysis")
        self.attributes = self._attributes(options["nodal_attributes"])
        tau0 = options["tau0"]
        if tau0 is None:
            tau0 = -3.0 if "primitive_weighting_in_continuity_equation" in self.attributes else 0.005
        self.tau0 = _finite(tau0, "tau0")
        if options["output_format"] not in _FORMATS:
            raise ForcingError(f"output_format must be one of {', '.join(_FORMATS)}, got {options['output_format']!r}")
        self.format_code = _FORMATS[options["output_format"]]
        self.station_steps = _steps(options["station_interval"], self.dt, "station_interval")
        interval = options["global_interval"]
        self.global_steps = None if interval is None else _steps(interval, self.dt, "global_interval")
        self.global_velocity = bool(options["global_velocity"])
        self.output_start = _positive(options["output_start_days"], "output_start_days", allow_zero=True)
        if self.output_start >= self.run_days:
            raise ForcingError(f"output_start_days ({self.output_start:g}) must be before the end of the run")
        harmonic_start = options["harmonic_start_days"]
        self.harmonic_start = (
            self.ramp_days if harmonic_start is None else _finite(harmonic_start, "harmonic_start_days")
        )
        if self.analysis and not 0 <= self.harmonic_start < self.run_days:
            raise ForcingError(
                f"harmonic_start_days ({self.harmonic_start:g}) must lie in [0, run_days = {self.run_days:g}); "
                "shorten the ramp or pass harmonic_start_days"
            )
        harmonic_interval = options["harmonic_interval"]
        self.harmonic_steps = (
            self.station_steps if harmonic_interval is None else _steps(harmonic_interval, self.dt, "harmonic_interval")
        )
        hotstart = options["hotstart_interval_days"]
        self.hotstart_steps = None
        if hotstart is not None:
            # days checked as given, so a bad value is named as the user wrote it, not in seconds
            seconds = _positive(hotstart, "hotstart_interval_days") * 86400.0
            self.hotstart_steps = _steps(seconds, self.dt, "hotstart_interval_days")
        self.metadata = self._metadata(options["netcdf_metadata"])
        title = options["title"]
        if title is None:
            title = getattr(options["mesh"], "title", None) or "terramesh tidal run"
        self.title = " ".join(str(title).split())
        self.run_id = " ".join(str(options["run_id"]).split())
        for what, text, width in (("title (RUNDES)", self.title, 32), ("run_id (RUNID)", self.run_id, 24)):
            if len(text) > width:
                warn_user(
                    f"{what} is cut to the {width} characters ADCIRC reads: {text[:width]!r}",
                )
        self.friction = _positive(options["bottom_friction"], "bottom_friction", allow_zero=True)
        self.wetting_drying = bool(options["wetting_drying"])
        self.minimum_depth = _positive(options["minimum_depth"], "minimum_depth")
        self.minimum_velocity = _positive(options["minimum_velocity"], "minimum_velocity", allow_zero=True)
        self.eddy_viscosity = _finite(options["eddy_viscosity"], "eddy_viscosity")
        self.gravity = _positive(options["gravity"], "gravity")
        self.advection = bool(options["advection"])
        self.anginn = _finite(options["anginn"], "anginn")
        weights = tuple(
            _finite(w, "time_weights (A00, B00, C00)")
            for w in _sequence(options["time_weights"], "time_weights (A00, B00, C00)")
        )
        if len(weights) != 3 or abs(sum(weights) - 1.0) > 1e-9:
            raise ForcingError(f"time_weights (A00, B00, C00) must be three numbers adding to 1, got {weights}")
        self.time_weights = weights
        solver = _sequence(options["solver"], "solver (ITITER, ISLDIA, CONVCR, ITMAX)")
        if len(solver) != 4:
            raise ForcingError(f"solver must be (ITITER, ISLDIA, CONVCR, ITMAX), got {solver}")
        self.solver = (
            _integer(solver[0], "solver ITITER"),
            _integer(solver[1], "solver ISLDIA"),
            _finite(solver[2], "solver CONVCR"),
            _integer(solver[3], "solver ITMAX"),
        )
        self.screen_interval = _integer(options["screen_interval"], "screen_interval")
        self.tides = tidal_factors(
            tuple(dict.fromkeys(self.potential + self.constituents + self.analysis)) or ("M2",),
            self.start,
            run_days=self.run_days,
        )

    @staticmethod
    def _attributes(values):
        if values is None:
            return ()
        if isinstance(values, str):
            values = [values]
        names = tuple(str(v).strip() for v in (values.keys() if hasattr(values, "keys") else values))
        for name in names:
            if not name or len(name.split()) != 1:
                raise ForcingError(f"nodal attribute names are one word, got {name!r}")
        if len(set(names)) != len(names):
            raise ForcingError(f"nodal_attributes lists a name twice: {', '.join(names)}")
        return names

    def _metadata(self, given):
        defaults = {
            "NCPROJ": "terramesh tidal run",
            "NCINST": "unknown",
            "NCSOUR": "terramesh",
            "NCHIST": "fort.15 written by terramesh",
            "NCREF": "none",
            "NCCOM": "tidal run",
            "NCHOST": "unknown",
            "NCCONV": "CF",
            "NCCONT": "unknown",
            "NCDATE": self.start.strftime("%Y-%m-%d %H:%M:%S"),
        }
        for key, value in (given or {}).items():
            if key.upper() not in defaults:
                raise ForcingError(f"unknown netcdf_metadata key {key!r}; known: {', '.join(_NETCDF_KEYS)}")
            text = str(value).replace("\n", " ").strip()
            defaults[key.upper()] = text or "none"
        return defaults

    def factors(self, name):
        return self.tides[name]

    def write_header(self, lines, lonlat):
        lines.add(f"{self.title[:32]:<32}", "RUNDES - run description (32 characters)")
        lines.add(f"{self.run_id[:24]:<24}", "RUNID - run identification (24 characters)")
        lines.add("1", "NFOVER - 1: correct nonfatal input errors")
        lines.add("1", "NABOUT - 1: abbreviated output to fort.16")
        lines.add(str(self.screen_interval), "NSCREEN - screen output every NSCREEN time steps")
        lines.add("0", "IHOT - 0: cold start")
        lines.add("2", "ICS - 2: spherical coordinates (longitude, latitude in degrees)")
        lines.add("0", "IM - 0: 2DDI barotropic model")
        lines.add("1", "NOLIBF - 1: quadratic bottom friction")
        lines.add("2" if self.wetting_drying else "1", "NOLIFA - 2: finite amplitude with wetting and drying")
        lines.add("1" if self.advection else "0", "NOLICA - advective terms")
        lines.add("1" if self.advection else "0", "NOLICAT - time derivative part of the advective terms")
        lines.add(str(len(self.attributes)), "NWP - number of nodal attributes read from fort.13")
        for name in self.attributes:
            lines.add(name)  # AttrName: read whole, so no comment
        lines.add("1", "NCOR - 1: Coriolis parameter from latitude")
        lines.add("1" if self.potential else "0", "NTIP - 1: tidal potential forcing")
        lines.add("0", "NWS - 0: no meteorological forcing")
        lines.add("1" if self.ramp_days > 0 else "0", "NRAMP - 1: hyperbolic tangent ramp")
        lines.add(_num(self.gravity), "G - gravitational acceleration, m/s^2")
        lines.add(_num(self.tau0), "TAU0 - GWCE primitive weighting (-3: from fort.13)")
        lines.add(_num(self.dt), "DTDP - time step, s")
        lines.add("0", "STATIM - start time, days")
        lines.add("0", "REFTIM - reference time of the nodal factors and equilibrium arguments, days")
        lines.add(_num(self.run_days), "RNDAY - length of the run, days")
        lines.add(_num(self.ramp_days), "DRAMP - ramp duration, days")
        lines.add(" ".join(_num(w) for w in self.time_weights), "A00 B00 C00 - GWCE time weighting factors")
        if self.wetting_drying:
            lines.add(
                f"{_num(self.minimum_depth)} 0 0 {_num(self.minimum_velocity)}",
                "H0 NODEDRYMIN NODEWETMIN VELMIN - minimum depth (m), wet/dry time steps, velocity (m/s)",
            )
        else:
            lines.add(_num(self.minimum_depth), "H0 - minimum depth, m")
        centre = 0.5 * (lonlat.min(axis=0) + lonlat.max(axis=0))
        lines.add(f"{_num(centre[0])} {_num(centre[1])}", "SLAM0 SFEA0 - centre of the CPP projection, degrees")
        lines.add(_num(self.friction), "CF - quadratic bottom friction coefficient")
        lines.add(_num(self.eddy_viscosity), "ESLM - horizontal eddy viscosity, m^2/s (negative: Smagorinsky)")
        lines.add("0", "CORI - constant Coriolis parameter (unused with NCOR = 1)")

    def write_tides(self, lines, boundary, amplitude, phase, boundary_nodes):
        start = self.start.strftime("%Y-%m-%d %H:%M UTC")
        lines.add(
            str(len(self.potential)),
            f"NTIF - tidal potential constituents; f, V0+u for a {self.run_days:g}-day run from {start}",
        )
        for name in self.potential:
            c = CONSTITUENTS[name]
            f, argument = self.factors(name)
            lines.add(_name(name), "TIPOTAG - tidal potential constituent")
            tpk, etrf = _num(c.potential_amplitude), _num(c.earth_tide_reduction)
            lines.add(
                f"{tpk} {c.frequency:.15g} {etrf} {f:.6f} {_deg(argument)}",
                "TPK AMIGT ETRF FFT FACET - amplitude (m), frequency (rad/s), reduction, f, V0+u (deg)",
            )
        lines.add(str(len(boundary)), "NBFR - elevation boundary forcing frequencies")
        for name in boundary:
            f, argument = self.factors(name)
            lines.add(_name(name), "BOUNTAG - boundary forcing constituent")
            lines.add(
                f"{CONSTITUENTS[name].frequency:.15g} {f:.6f} {_deg(argument)}",
                "AMIG FF FACE - frequency (rad/s), nodal factor, equilibrium argument (deg)",
            )
        for k, name in enumerate(boundary):
            lines.add(_name(name), "ALPHAE - boundary forcing constituent")
            for node, a, p in zip(boundary_nodes, amplitude[k], phase[k], strict=True):
                lines.add(
                    f"{float(a):.8g} {_deg(p)}",
                    f"EMO EFA - amplitude (m), phase (deg), node {node + 1}",
                    28,
                )

    def write_output(self, lines, stations_e, stations_v):
        code = self.format_code
        end = _num(self.run_days)
        begin = _num(self.output_start)
        n_e, n_v = len(stations_e), len(stations_v)
        lines.add(
            f"{code if n_e else 0} {begin} {end} {self.station_steps}",
            "NOUTE TOUTSE TOUTFE NSPOOLE - elevation station output (fort.61)",
        )
        lines.add(str(n_e), "NSTAE - elevation recording stations")
        for lon, lat in stations_e:
            lines.add(f"{_num(lon)} {_num(lat)}", "XEL YEL - longitude, latitude (degrees)")
        lines.add(
            f"{code if n_v else 0} {begin} {end} {self.station_steps}",
            "NOUTV TOUTSV TOUTFV NSPOOLV - velocity station output (fort.62)",
        )
        lines.add(str(n_v), "NSTAV - velocity recording stations")
        for lon, lat in stations_v:
            lines.add(f"{_num(lon)} {_num(lat)}", "XEV YEV - longitude, latitude (degrees)")
        steps = self.global_steps
        lines.add(
            f"{code if steps else 0} {begin} {end} {steps or 0}",
            "NOUTGE TOUTSGE TOUTFGE NSPOOLGE - global elevation output (fort.63)",
        )
        velocity = steps if self.global_velocity else None
        lines.add(
            f"{code if velocity else 0} {begin} {end} {velocity or 0}",
            "NOUTGV TOUTSGV TOUTFGV NSPOOLGV - global velocity output (fort.64)",
        )
        lines.add(str(len(self.analysis)), "NFREQ - constituents in the harmonic analysis")
        for name in self.analysis:
            f, argument = self.factors(name)
            lines.add(_name(name), "NAMEFR - harmonic analysis constituent")
            lines.add(
                f"{CONSTITUENTS[name].frequency:.15g} {f:.6f} {_deg(argument)}",
                "HAFREQ HAFF HAFACE - frequency (rad/s), nodal factor, equilibrium argument (deg)",
            )
        analysis = bool(self.analysis)
        lines.add(
            f"{_num(self.harmonic_start) if analysis else 0} {end if analysis else 0} "
            f"{self.harmonic_steps if analysis else 0} 0",
            "THAS THAF NHAINC FMV - harmonic analysis start, end (days), every NHAINC steps, FMV",
        )
        flags = (
            code if analysis and n_e else 0,
            code if analysis and n_v else 0,
            code if analysis else 0,
            code if analysis and self.global_velocity else 0,
        )
        lines.add(" ".join(map(str, flags)), "NHASE NHASV NHAGE NHAGV - harmonic analysis output (fort.51-54)")
        if self.hotstart_steps:
            lines.add(f"{code} {self.hotstart_steps}", "NHSTAR NHSINC - hot start file every NHSINC steps")
        else:
            lines.add("0 0", "NHSTAR NHSINC - no hot start files")
        ititer, isldia, convcr, itmax = self.solver
        lines.add(f"{ititer} {isldia} {_num(convcr)} {itmax}", "ITITER ISLDIA CONVCR ITMAX - GWCE solver")
        written = [code if n_e else 0, code if n_v else 0, code if steps else 0, code if velocity else 0, *flags]
        if self.hotstart_steps:
            written.append(code)
        if any(abs(v) in (3, 5) for v in written):
            for key in _NETCDF_KEYS:
                lines.add(self.metadata[key])  # read whole, so no comment


def _geographic_points(mesh):
    """Points as (lon, lat) degrees, checked."""
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise ForcingError("fort.15 is written for 2D triangle meshes only")
    if mesh.crs is not None and not mesh.geographic:
        raise ForcingError(f"fort.15 uses ICS = 2 (longitude, latitude); the mesh is in {mesh.crs}, reproject it first")
    points = np.asarray(mesh.points, dtype=np.float64)
    if not np.all(np.isfinite(points)) or np.abs(points[:, 1]).max() > 90 or np.abs(points[:, 0]).max() > 360:
        raise ForcingError("the mesh points are not longitude, latitude in degrees; ICS = 2 needs them")
    return points


def _given_constants(given, names, count):
    """Amplitude and phase arrays, shape (k, count), from HarmonicConstants or a mapping."""
    if isinstance(given, HarmonicConstants):
        index = {get_constituent(n).name: k for k, n in enumerate(given.constituents)}
        missing = [n for n in names if n not in index]
        if missing:
            raise ForcingError(f"boundary_constants has no {', '.join(missing)}")
        amplitude = np.asarray(given.amplitude, dtype=np.float64)[[index[n] for n in names]]
        phase = np.asarray(given.phase, dtype=np.float64)[[index[n] for n in names]]
    else:
        table = {get_constituent(key).name: value for key, value in given.items()}
        missing = [n for n in names if n not in table]
        if missing:
            raise ForcingError(f"boundary_constants has no {', '.join(missing)}")
        pairs = [tuple(table[n]) for n in names]
        if any(len(pair) != 2 for pair in pairs):
            raise ForcingError("boundary_constants values must be (amplitude, phase) pairs")
        amplitude = np.array([np.asarray(a, dtype=np.float64).ravel() for a, _ in pairs]).reshape(len(names), -1)
        phase = np.array([np.asarray(p, dtype=np.float64).ravel() for _, p in pairs]).reshape(len(names), -1)
    if amplitude.shape != (len(names), count) or phase.shape != (len(names), count):
        raise ForcingError(
            f"boundary_constants need {count} values per constituent (one per open-boundary node), "
            f"got amplitude {amplitude.shape} and phase {phase.shape}"
        )
    if not (np.all(np.isfinite(amplitude)) and np.all(np.isfinite(phase))) or np.any(amplitude < 0):
        raise ForcingError("boundary_constants must be finite, with amplitudes >= 0")
    return amplitude, phase


def _stations(mesh, lonlat, stations, what):
    """Stations as an (n, 2) array, each checked to lie in a cell of the mesh."""
    if stations is None:
        return np.empty((0, 2))
    points = np.asarray(stations, dtype=np.float64)
    if points.size == 0:
        return np.empty((0, 2))
    points = np.atleast_2d(points)
    if points.ndim != 2 or points.shape[1] != 2 or not np.all(np.isfinite(points)):
        raise ForcingError(f"{what} must be finite (longitude, latitude) pairs of shape (n, 2), got {points.shape}")
    inside = _inside_mesh(lonlat, mesh.cells, points)
    points = points.copy()
    for shift in (-360.0, 360.0):  # a station given in the other longitude convention is written in the mesh's
        if not inside.all():
            outside = np.flatnonzero(~inside)
            moved = _inside_mesh(lonlat, mesh.cells, points[outside] + [shift, 0.0])
            points[outside[moved], 0] += shift
            inside[outside] = moved
    if not inside.all():
        outside = np.flatnonzero(~inside)
        listed = ", ".join(f"#{i} ({points[i, 0]:g}, {points[i, 1]:g})" for i in outside[:5])
        raise GeometryError(f"{len(outside)} {what} lie outside the mesh: {listed}")
    return points


def _inside_mesh(points, cells, query, candidates=16):
    """Whether each query point lies in (or on) a triangle: nearest cells by centroid first, then all cells."""
    inside = np.zeros(len(query), dtype=bool)
    if len(query) == 0 or len(cells) == 0:
        return inside
    from scipy.spatial import cKDTree

    corners = points[cells]
    k = min(candidates, len(cells))
    _, near = cKDTree(corners.mean(axis=1)).query(query, k=k)
    near = near.reshape(len(query), k)
    inside = _in_triangles(corners[near], query[:, None, :]).any(axis=1)
    for i in np.flatnonzero(~inside):
        inside[i] = _in_triangles(corners, query[i][None, :]).any()
    return inside


def _in_triangles(corners, point):
    """Barycentric containment test of points in triangles, tolerant of points on edges."""
    a, b, c = corners[..., 0, :], corners[..., 1, :], corners[..., 2, :]
    v0, v1, v2 = b - a, c - a, point - a
    det = v0[..., 0] * v1[..., 1] - v0[..., 1] * v1[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (v2[..., 0] * v1[..., 1] - v2[..., 1] * v1[..., 0]) / det
        t = (v0[..., 0] * v2[..., 1] - v0[..., 1] * v2[..., 0]) / det
    tol = 1e-10
    return (det != 0) & (s >= -tol) & (t >= -tol) & (s + t <= 1 + tol)
