"""Shared fixtures: the real data in ../shared/data and canonical domains."""

import pathlib

import numpy as np
import pytest

import terramesh as tm

REPO = pathlib.Path(__file__).resolve().parents[1]
SHARED_DATA = REPO.parent / "shared" / "data"


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


def assert_valid(mesh, domain, h_min):
    """Every rule of a valid mesh, with boundary vertices within 1e-3 h of the boundary."""
    problems = tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * h_min)
    assert problems == []
