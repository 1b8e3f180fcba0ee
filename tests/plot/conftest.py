"""The plotting tests draw off screen (Agg), wherever they run."""

import matplotlib
import numpy as np
import pytest

import terramesh as tm

matplotlib.use("Agg")


@pytest.fixture
def squashed_mesh():
    """A 10 by 6 grid of squares, two triangles each, its first row of points moved up to y = 0.09: 20 poor cells."""
    x, y = np.meshgrid(np.linspace(0, 1, 11), np.linspace(0, 0.6, 7))
    points = np.c_[x.ravel(), y.ravel()]
    points[:11, 1] = 0.09
    index = np.arange(77).reshape(7, 11)
    a, b, c, d = index[:-1, :-1].ravel(), index[:-1, 1:].ravel(), index[1:, 1:].ravel(), index[1:, :-1].ravel()
    return tm.Mesh(points, np.concatenate([np.c_[a, b, c], np.c_[a, c, d]]))
