"""Real meshes through the whole post-processing chain to ADCIRC files, and the fort.14 read back identical.

Sabine Pass (CUDEM, 30 m) and the Gulf of Maine (GSHHS low + ETOPO1 0.1 degree): repair, cell-averaged
bathymetry, boundaries, a Courant check at a time step the mesh does not meet and its enforcement,
renumbering, fort.14 and fort.13.
"""

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import TerrameshWarning
from terramesh.mesh.topology import boundary_edges


@pytest.fixture(scope="module")
def sabine_pass(shared_data):
    dem = shared_data / "dem" / "CUDEM_equal.nc"
    # the box's west edge crosses a marsh channel 3 nodes wide, nowhere 1 m deep: an open boundary, said so
    with pytest.warns(TerrameshWarning, match="1 of 6 open boundaries are less than 1 m deep"):
        mesh = tm.coastal.build((-94.0, -93.8, 29.7, 29.9), dem=dem, min_el=80, max_el=1000, fs=3, wl=60, g=0.2)
    return mesh, dem, {"dt": 3.0, "min_depth": None, "buoyancy": None, "dry_depth": 1.0}


@pytest.fixture(scope="module")
def gulf_of_maine(shared_data):
    dem = shared_data / "dem" / "ETOPO1_0.1.grd"
    mesh = tm.coastal.build(
        (-71.0, -65.0, 41.0, 45.0),
        shared_data / "coast" / "GSHHS_l_L1.shp",
        dem,
        min_el=3000,
        max_el=30e3,
        fs=3,
        wl=40,
        slp=20,
        g=0.2,
        dt=0,
        itmax=50,
        boundaries={"dry_depth": 1.0},  # Boston Harbor's entrance, 0.25 m on ETOPO1, is land
    )
    # a synthetic stratification for the internal tide friction: N = 2e-3 rad/s over the box
    buoyancy = (np.array([-72.0, -64.0]), np.array([40.0, 46.0]), np.full((2, 2), 2e-3))
    # the mesh was CFL-limited for its automatic dt (about 52 s); ask for more
    return mesh, dem, {"dt": 60.0, "min_depth": 1.0, "buoyancy": buoyancy}


def check_adcirc_boundaries(mesh):
    """Segments tile the boundary in the mesh's direction (domain on the left); islands closed and clockwise."""
    b = mesh.boundaries
    used = sorted(
        (int(p), int(q))
        for segment in b.open + b.land
        for p, q in zip(segment.nodes[:-1], segment.nodes[1:], strict=True)
    )
    assert used == sorted(map(tuple, boundary_edges(mesh.cells).tolist()))
    for island in (land for land in b.land if land.ibtype == 21):
        ring = mesh.points[island.nodes]
        assert island.nodes[0] == island.nodes[-1]
        assert np.sum(ring[:-1, 0] * ring[1:, 1] - ring[1:, 0] * ring[:-1, 1]) < 0


@pytest.mark.parametrize("case", ["sabine_pass", "gulf_of_maine"])
def test_chain_to_adcirc_files(case, request, tmp_path):
    built, dem, options = request.getfixturevalue(case)
    dt = options["dt"]
    # 1. repair (generation already did; nothing left to do)
    mesh = tm.coastal.fix_mesh(built)
    assert mesh.n_points == built.n_points and tm.cleanup.mesh_problems(mesh) == []
    # 2. bathymetry, cell averaged
    mesh = tm.coastal.interpolate_bathymetry(mesh, dem, min_depth=options["min_depth"])
    assert np.all(np.isfinite(mesh.depth)) and mesh.info["bathymetry"]["averaged"] > 0
    if options["min_depth"] is not None:
        assert mesh.depth.min() >= options["min_depth"]
    # 3. boundaries: open where the box edge is water, mainland between, the islands
    mesh = tm.coastal.make_boundaries(mesh, dry_depth=options.get("dry_depth", 0.0))
    counts = mesh.info["boundaries"]
    assert counts["open"] >= 1 and counts["mainland"] >= 1 and counts["islands"] >= 1
    check_adcirc_boundaries(mesh)
    # 4. the Courant check fails at dt, enforcement fixes it
    before = tm.coastal.courant_number(mesh, dt)
    assert before.max() > 0.5
    mesh = tm.coastal.enforce_timestep(mesh, dt)
    report = mesh.info["timestep"]
    assert report["violations_before"] > 0 and report["removed"] > 0
    assert tm.coastal.courant_number(mesh, dt).max() <= 0.5
    assert report["removed"] < 0.15 * built.n_points
    assert tm.cleanup.mesh_problems(mesh) == []
    assert tm.quality.triangle_quality(mesh.points, mesh.cells, geographic=True).min() >= 0.3
    check_adcirc_boundaries(mesh)  # made again after the decimation
    # 5. renumbering shrinks the bandwidth; boundaries follow
    mesh = tm.coastal.renumber(mesh)
    bandwidth = mesh.info["renumber"]
    assert bandwidth["bandwidth_after"] < 0.1 * bandwidth["bandwidth_before"]
    check_adcirc_boundaries(mesh)
    # 6. nodal attributes
    attributes = {"primitive_weighting_in_continuity_equation": tm.coastal.tau0(mesh)}
    if options["buoyancy"] is not None:
        attributes["internal_tide_friction"] = tm.coastal.internal_tide_friction(mesh, options["buoyancy"])
        assert attributes["internal_tide_friction"].non_default.any()
    # 7. files, read back identical
    mesh.write(tmp_path / "fort.14")
    tm.coastal.write_fort13(tmp_path / "fort.13", attributes, mesh.n_points)
    back = tm.read_mesh(tmp_path / "fort.14")
    assert np.array_equal(back.points, mesh.points)
    assert np.array_equal(back.cells, mesh.cells)
    assert np.array_equal(back.depth, mesh.depth)
    written, read = mesh.boundaries, back.boundaries
    assert [len(b.nodes) for b in read.open] == [len(b.nodes) for b in written.open]
    assert [(len(b.nodes), b.ibtype) for b in read.land] == [(len(b.nodes), b.ibtype) for b in written.land]
    for r, w in zip(read.open + read.land, written.open + written.land, strict=True):
        assert np.array_equal(r.nodes, w.nodes) and r.ibtype == w.ibtype
    nodal = tm.io.read_fort13(tmp_path / "fort.13")
    for name, attribute in attributes.items():
        assert np.array_equal(nodal[name].values, attribute.values)
    # 8. the control file for a tidal run forced on every open-boundary node (constants made up here:
    # the user brings a TPXO atlas, tested with synthetic atlases in tests/coastal/test_tides.py)
    neta = sum(len(b.nodes) for b in mesh.boundaries.open)
    constants = {"M2": (np.full(neta, 0.5), np.full(neta, 10.0)), "K1": (np.full(neta, 0.1), np.full(neta, 200.0))}
    tm.coastal.write_fort15(
        tmp_path / "fort.15", mesh, start="2024-01-01", run_days=5, dt=dt, constituents=["M2", "K1"],
        boundary_constants=constants, nodal_attributes=list(attributes),
    )  # fmt: skip
    lines = (tmp_path / "fort.15").read_text().splitlines()
    nbfr = next(i for i, line in enumerate(lines) if "! NBFR" in line)
    assert int(lines[nbfr].split()[0]) == 2
    forcing = [line for line in lines[nbfr + 1 :] if len(line.split("!")[0].split()) == 2]
    assert len(forcing) >= 2 * neta  # amplitude and phase per open-boundary node and constituent
