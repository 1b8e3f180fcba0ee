"""Points along sharp edges (terramesh.generation.sharp_edges)."""

import numpy as np
import pytest

from terramesh.generation.sharp_edges import sampled_curves
from terramesh.geometry.primitives3d import segment_curve


@pytest.mark.parametrize("h", [153.0, 163.0, 167.0, 261.0, 293.0])
def test_an_edges_samples_end_on_its_corners_exactly(h):
    # total * k / k missed total by a rounding: the last sample of a box's edge lay 5e-13 short of its corner, and
    # a slab's section held both that point and the corner from the edge beside it (a 3D model meshed in slabs
    # warned "1 fixed points lie within 0.15 of another one, e.g. [3300.0, 0.0]" of points it had placed itself)
    start, end = np.array([3300.0, -300.0, 0.0]), np.array([3300.0, 3300.0, 0.0])
    chain = sampled_curves([segment_curve(start, end, 1)], lambda p: h * (1 + 0.3 * np.sin(p[:, 1] / 500)), 100.0)[0]
    assert chain[0].tolist() == start.tolist() and chain[-1].tolist() == end.tolist()
    spacing = np.diff(chain[:, 1])
    assert np.all(spacing > 0) and spacing.max() < 2 * h
