import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import terramesh as tm
from terramesh.quality import triangle_quality

equilateral = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]])


def test_reference_values():
    assert triangle_quality(equilateral, np.array([[0, 1, 2]]))[0] == pytest.approx(1.0)
    right = np.array([[0.0, 0], [1, 0], [0, 1]])
    # 4 sqrt(3) * 0.5 / (1 + 1 + 2)
    assert triangle_quality(right, np.array([[0, 1, 2]]))[0] == pytest.approx(np.sqrt(3) / 2)
    assert triangle_quality(right, np.array([[0, 2, 1]]))[0] == pytest.approx(-np.sqrt(3) / 2)
    flat = np.array([[0.0, 0], [1, 0], [2, 0]])
    assert triangle_quality(flat, np.array([[0, 1, 2]]))[0] == 0


@given(st.floats(1e-6, 1e6), st.floats(-1e3, 1e3), st.floats(-1e3, 1e3))
def test_quality_is_invariant_to_scale_and_shift(scale, dx, dy):
    points = equilateral * scale + np.array([dx, dy])
    assert triangle_quality(points, np.array([[0, 1, 2]]))[0] == pytest.approx(1.0, rel=1e-6)


def test_geographic_quality_measures_on_the_ground():
    latitude = 60.0
    ground = equilateral * 0.01
    degrees = ground / np.array([np.cos(np.radians(latitude)), 1.0]) + np.array([10.0, latitude])
    cells = np.array([[0, 1, 2]])
    assert triangle_quality(degrees, cells)[0] < 0.8
    assert triangle_quality(degrees, cells, geographic=True)[0] == pytest.approx(1.0, abs=1e-3)


def test_summary_counts_and_statistics():
    points = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    mesh = tm.Mesh(points, np.array([[0, 1, 2], [0, 2, 3]]))
    result = tm.quality.summary(mesh)
    assert (result.n_vertices, result.n_cells, result.n_boundary_edges) == (4, 2, 4)
    assert result.mean == pytest.approx(np.sqrt(3) / 2)
    assert result.mean_minus_3std == pytest.approx(np.sqrt(3) / 2)
    assert result.n_below_0_5 == 0 and result.n_inverted == 0
    assert "mean 0.8660" in str(result)
