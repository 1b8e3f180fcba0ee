"""Shared fixtures: the real data in ../shared/data and canonical domains."""

import pathlib
import warnings

import netCDF4
import numpy as np
import pytest

import terramesh as tm
from terramesh._kernels import compiled_before

REPO = pathlib.Path(__file__).resolve().parents[1]
SHARED_DATA = REPO.parent / "shared" / "data"


def pytest_sessionstart(session):
    """On a fresh installation, compile the kernels side by side first, as the command line does."""
    if not compiled_before():
        report = tm.compile_kernels()
        seconds, processes = report["seconds"], report["processes"]
        print(f"\ncompiled {report['kernels']} kernels ahead in {processes} processes, {seconds:.0f} s")


@pytest.fixture
def fresh_installation(monkeypatch):
    """As on a fresh installation, each job the first of its process: what is asked of ``compile_kernels``.

    ``asked`` lists the stages of each call; ``outcome`` is the report it
    returns, or an exception it raises; ``new_process()`` forgets the jobs run.
    """
    from types import SimpleNamespace

    from terramesh._kernels import precompile

    fresh = SimpleNamespace(asked=[], outcome=dict(kernels=33, failed=[], processes=2, seconds=41.2))

    def compile_kernels(stages):
        fresh.asked.append(stages)
        if isinstance(fresh.outcome, Exception):
            raise fresh.outcome
        return fresh.outcome

    fresh.new_process = lambda: monkeypatch.setattr(precompile, "_ahead", {"tried": False})
    fresh.new_process()
    monkeypatch.setattr(precompile, "compiled_before", lambda kernel=None: False)
    monkeypatch.setattr(precompile, "compile_kernels", compile_kernels)
    return fresh


@pytest.fixture(scope="session")
def shared_data():
    """Folder of the real data sets; the suite needs it (CI has it beside the clone)."""
    if not SHARED_DATA.is_dir():
        pytest.fail(f"real test data not found at {SHARED_DATA}; the tests read ../shared/data")
    return SHARED_DATA


@pytest.fixture(scope="session")
def plate_with_hole():
    """The issue's graded example: a 2 x 1 rectangle minus a disk."""
    domain = tm.geometry.Difference([tm.geometry.Rectangle((0, 0), (2, 1)), tm.geometry.Disk((0.5, 0.5), 0.2)])
    return domain, (lambda p: 0.01 + 0.1 * np.abs(domain.distance(p)))


def boundary_ring(mesh, on):
    """The boundary vertices where ``on`` (a mask over ``boundary_edges``) holds, in traversal order (domain left)."""
    from terramesh.mesh.topology import boundary_edges

    following = dict(boundary_edges(mesh.cells)[on].tolist())
    ring = [next(iter(following))]
    while following[ring[-1]] != ring[0]:
        ring.append(following[ring[-1]])
    return np.array(ring)


def hole_ring(mesh):
    """The ring of :func:`plate_with_hole`'s hole (clockwise: the domain on the left)."""
    from terramesh.mesh.topology import boundary_edges

    ends = mesh.points[boundary_edges(mesh.cells)]
    return boundary_ring(mesh, np.all(np.hypot(*(ends - [0.5, 0.5]).transpose(2, 0, 1)) < 0.21, axis=1))


def random_walk_coast(n, seed, roughness=0.6, smallest_radius=None):
    """A closed polygon of ``n`` vertices whose radius follows a random walk: a coast jagged below the mesh size."""
    rng = np.random.default_rng(seed)
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    radius = 1 + roughness * np.cumsum(rng.normal(size=n)) / np.sqrt(n)
    radius -= np.linspace(0, 1, n) * (radius[-1] - radius[0])  # closed: the walk ends where it began
    if smallest_radius is not None:
        radius = np.maximum(radius, smallest_radius)
    return tm.geometry.Polygon(np.column_stack([radius * np.cos(angle), radius * np.sin(angle)]))


def assert_valid(mesh, domain, h_min):
    """Every rule of a valid mesh, with boundary vertices within 1e-3 h of the boundary."""
    problems = tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * h_min)
    assert problems == []


def wedge_with_its_tip_fixed(generate, degrees):
    """``generate(wedge, fixed points)`` on a wedge of ``degrees``, sides 1: the mesh, the dropped-point warnings."""
    angle = np.radians(degrees)
    wedge = tm.geometry.Polygon([[(0, 0), (1, 0), (np.cos(angle), np.sin(angle))]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = generate(wedge, [(0.0, 0.0), (0.5, 0.0)])
    assert tm.cleanup.mesh_problems(mesh, wedge) == []
    return mesh, [str(w.message) for w in caught if "fixed points are no vertices" in str(w.message)]


def wedge_prism(degrees, told):
    """A prism 0.3 high on a right triangle with a ``degrees`` corner at the origin, as a user's distance function."""
    angle = np.radians(degrees)
    normals = np.array([(0.0, -1.0), (-np.sin(angle), np.cos(angle))])

    def distance(p):
        sides = p[:, :2] @ normals.T
        return np.max(np.column_stack([sides, p[:, 0] - 1.0, -p[:, 2], p[:, 2] - 0.3]), axis=1)

    triangle = [(0, 0), (1, 0), (1, np.tan(angle)), (0, 0)]
    edges = [[(x, y, z) for x, y in triangle] for z in (0.0, 0.3)]
    edges += [[(x, y, 0.0), (x, y, 0.3)] for x, y in triangle[:3]]
    bbox = [(0, 0, 0), (1, np.tan(angle), 0.3)]
    return tm.geometry.FunctionDomain(distance, bbox, sharp_edges=edges if told else None)


def truth(lon, lat, k):
    """Complex elevation (m) of constituent ``k``, linear in lon and lat so that an atlas's interpolation is exact."""
    return (0.4 + 0.02 * k + 0.05 * (lon + 80)) + 1j * (0.1 - 0.03 * (lat - 30) - 0.01 * k)


def write_atlas(folder, names, lon=(-82.0, -76.0), lat=(28.0, 34.0)):
    """A TPXO9-format atlas in ``folder``, a file per constituent of ``names``, of :func:`truth` on a 0.25° grid."""
    lon = np.arange(lon[0], lon[1] + 0.1, 0.25)
    lat = np.arange(lat[0], lat[1] + 0.1, 0.25)
    glon, glat = np.meshgrid(lon, lat, indexing="ij")
    for k, name in enumerate(names):
        h = truth(glon, glat, k)
        with netCDF4.Dataset(folder / f"h_{name.lower()}_tpxo9_atlas_30_v5.nc", "w") as nc:
            nc.createDimension("nx", len(lon))
            nc.createDimension("ny", len(lat))
            nc.createVariable("lon_z", "f8", ("nx",))[:] = lon
            nc.createVariable("lat_z", "f8", ("ny",))[:] = lat
            for var, part in (("hRe", h.real), ("hIm", h.imag)):
                v = nc.createVariable(var, "f8", ("nx", "ny"))
                v.units = "m"
                v[:] = part
    return folder
