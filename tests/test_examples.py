"""The gallery's quick examples run as a user runs them, and their files are what they say."""

import importlib.util
import re

import numpy as np
import pytest

import terramesh as tm
from terramesh.io import read_fort13

from .conftest import REPO


def _example(name):
    spec = importlib.util.spec_from_file_location(name, REPO / "examples" / "coastal" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_sabine_pass_writes_a_run_stable_at_its_time_step(shared_data, tmp_path, capsys):
    example = _example("sabine_pass")
    with pytest.warns(tm.errors.TerrameshWarning) as caught:  # the marsh's islets under the cells, the Courant number
        example.main(["--data", str(shared_data), "--output", str(tmp_path)])
    # the generator's lengths (Mercator metres) told as ground metres at the place it names
    islets = next(str(w.message) for w in caught if "disjoint part" in str(w.message))
    assert re.search(
        r"the longest [\d.]+ m long, near \(-93\.\d+, 29\.\d+\) \(lon, lat\), where the size is [\d.]+ m", islets
    )
    mesh = tm.read_mesh(tmp_path / "sabine_pass.14")
    assert mesh.n_points > 3000 and not tm.cleanup.mesh_problems(mesh)
    assert tm.quality.summary(mesh).mean > 0.95
    # what the §6.6 steps promise: depths of at least 1 m, every vertex within the Courant bound at 2 s,
    # numbered so that the bandwidth is small, ADCIRC's boundaries
    assert mesh.depth.min() >= 1.0
    assert tm.coastal.courant_number(mesh, example.DT).max() <= 0.5
    bandwidth = np.abs(mesh.cells - mesh.cells.min(axis=1, keepdims=True)).max()
    assert bandwidth < mesh.n_points / 10
    assert mesh.boundaries.open and mesh.boundaries.land and not tm.coastal.node_string_problems(mesh)
    attributes = read_fort13(tmp_path / "sabine_pass.13")
    assert attributes.n_nodes == mesh.n_points
    assert f"{mesh.n_points:,} vertices" in capsys.readouterr().out
    assert sorted(path.name for path in tmp_path.glob("*.png")) == [
        "sabine_pass.png",
        "sabine_pass_boundaries.png",
        "sabine_pass_courant.png",
    ]
