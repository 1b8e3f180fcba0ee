"""The BP2004 velocity model, read once for the seismic tests."""

import pytest

from terramesh import seismic


@pytest.fixture(scope="session")
def bp2004_path(shared_data):
    return shared_data / "seismic" / "vel_z6.25m_x12.5m_exact.segy"


@pytest.fixture(scope="session")
def bp2004(bp2004_path):
    return seismic.read_velocity(bp2004_path)
