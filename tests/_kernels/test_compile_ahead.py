"""A fresh installation's first job compiles the kernels it uses side by side, from Python as from the command line."""

import logging

import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh._kernels import precompile
from terramesh.generation.distmesh3d import generate_mesh_3d

COMPILING = "first run of this installation: compiling the kernels for this machine"


def test_each_job_asks_for_its_stage_once_a_process(fresh_installation, caplog):
    caplog.set_level(logging.INFO, logger="terramesh")
    disk = tm.geometry.Disk((0, 0), 1)
    mesh = tm.generate_mesh(disk, 0.3, seed=0)
    assert mesh.n_cells > 0
    tm.generate_mesh(disk, 0.3, seed=0)
    assert fresh_installation.asked == [["generation"]]
    assert caplog.text.count(COMPILING) == 1 and "compiled 33 kernels in 41 s" in caplog.text
    fresh_installation.new_process()
    tm.adapt_mesh(mesh, disk, lambda p: 0.2 + 0.1 * np.abs(p[:, 0]), h0=0.2)
    fresh_installation.new_process()
    generate_mesh_3d(tm.geometry.Ball((0, 0, 0), 1), 0.5, seed=0)
    fresh_installation.new_process()
    land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    mesh = tm.coastal.build((0, 0.3, 0, 0.3), land, min_el=4000, max_el=8000, dis=0.3, g=0.3, max_iter=20)
    assert mesh.info["timings"]["compile ahead"] == 41.2  # the report's, before the stages that followed
    assert list(mesh.info["timings"])[:2] == ["compile ahead", "read"]
    fresh_installation.new_process()
    sizes = tm.coastal.size_function((0, 0.3, 0, 0.3), land, min_el=4000, max_el=8000, dis=0.3, g=0.3)
    tm.generate_mesh(sizes.shoreline.domain(), sizes.size_grid())
    fresh_installation.new_process()
    boxes = [{"bbox": (0, 0.3, 0, 0.3), "min_el": 4000, "max_el": 8000, "dis": 0.3, "g": 0.3}]
    mesh = tm.coastal.build_multiscale(boxes, land, max_iter=20)
    assert mesh.info["timings"]["compile ahead"] == 41.2
    fresh_installation.new_process()
    axes = [np.linspace(0, 2000, 21), np.linspace(-1000, 0, 11)]
    model = tm.seismic.VelocityModel(np.full((21, 11), 2000.0), axes)
    tm.seismic.size_function(model, frequency=2.0, hmin=100.0)
    # the coastal job's generation and the seismic size's later mesh would not ask again
    assert fresh_installation.asked == [
        ["generation"],
        ["generation"],
        ["generation-3d"],
        ["coastal"],
        ["coastal"],
        ["coastal"],
        ["seismic"],
    ]


def test_a_cache_that_holds_the_stages_heaviest_kernel_is_left_alone(fresh_installation, monkeypatch):
    heaviest = precompile.stage_tasks(["coastal"])[0]
    looked_at = []
    monkeypatch.setattr(precompile, "compiled_before", lambda kernel=None: looked_at.append(kernel) or True)
    assert precompile.compile_ahead_on_first_run(["coastal"]) is None
    assert fresh_installation.asked == []
    assert looked_at == [precompile._kernel(*heaviest[:2])]


@pytest.mark.parametrize("variable", ["PMI_SIZE", "OMPI_COMM_WORLD_SIZE"])
def test_ranks_started_by_mpiexec_compile_as_they_go(fresh_installation, monkeypatch, caplog, variable):
    caplog.set_level(logging.INFO, logger="terramesh")
    monkeypatch.setenv(variable, "2")
    assert precompile.processes_started_by_mpiexec() == 2
    tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.3, seed=0)
    assert fresh_installation.asked == []
    assert "each rank compiles the kernels (`terramesh compile` first)" in caplog.text
    monkeypatch.setenv(variable, "1")  # one process: it compiles ahead
    fresh_installation.new_process()
    precompile.compile_ahead_on_first_run(["generation"])
    assert fresh_installation.asked == [["generation"]]


def test_no_workers_leaves_the_kernels_to_compile_as_used(fresh_installation, caplog):
    fresh_installation.outcome = OSError("no processes")
    mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.3, seed=0)
    assert mesh.n_cells > 0
    assert "could not compile ahead (no processes): compiling as the kernels are used" in caplog.text
    assert [record.levelname for record in caplog.records if "compile" in record.message] == ["WARNING"]


def test_a_bad_option_is_refused_before_any_compiling(fresh_installation):
    with pytest.raises(tm.TerrameshError):
        tm.generate_mesh(tm.geometry.Disk((0, 0), 1), -0.1)
    model = tm.seismic.VelocityModel(np.full((21, 11), 2000.0), [np.linspace(0, 2000, 21), np.linspace(-1000, 0, 11)])
    with pytest.raises(tm.TerrameshError, match="peak source frequency"):
        tm.seismic.size_function(model, hmin=100.0)
    land = shapely.Polygon([(0.0, 0.0), (0.3, 0.0), (0.3, 0.25), (0.0, 0.1)])
    with pytest.raises(tm.TerrameshError, match="does not overlap the first"):
        tm.coastal.build_multiscale([{"bbox": (0, 0.3, 0, 0.3)}, {"bbox": (1, 2, 1, 2)}], land)
    assert fresh_installation.asked == []
