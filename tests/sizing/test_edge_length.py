"""What a user passes as ``edge_length`` becomes one validated size function (``sizing/edge_length.py``)."""

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import SizingError
from terramesh.sizing import as_size_function


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ([0.1, -0.2, 0.3], r"1 values that are zero or negative, e\.g\. -0\.2 at \(1, 1\)"),
        ([0.1, 0.2, np.nan], r"1 NaN or infinite values, e\.g\. nan at \(2, 2\)"),
    ],
)
def test_bad_sizes_are_refused_saying_where(values, message):
    size = as_size_function(lambda points: np.array(values))
    with pytest.raises(SizingError, match=message):
        size(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]))


def test_a_size_negative_outside_the_domain_is_named_as_such():
    # Persson and Strang's example (b) as written, 0.05 + 0.3 d_circle, is negative deep in the hole: the seeding
    # asks for sizes a little outside the domain, and the error said only "9 values that are zero or negative"
    hole = tm.geometry.Disk((0, 0), 0.5)
    domain = tm.geometry.Difference([tm.geometry.Rectangle((-1, -1), (1, 1)), hole])
    with pytest.raises(SizingError, match=r"e\.g\. -[\d.e-]+ at \(.*\): .* outside the domain") as error:
        tm.generate_mesh(domain, lambda p: 0.05 + 0.3 * hole.distance(p), h0=0.05, seed=0)
    where = np.array(str(error.value).split(" at (")[1].split(")")[0].split(", "), dtype=float)
    assert domain.distance(where[None])[0] > 0  # the point named is outside


@pytest.mark.parametrize("returned", [np.array([0.1 + 0.2j, 0.1]), np.array(["0.1", "0.2"]), np.array([True, True])])
def test_sizes_that_are_not_real_numbers_are_refused(returned):
    # complex sizes lost their imaginary part with a NumPy warning at every call
    size = as_size_function(lambda points: returned)
    with pytest.raises(SizingError, match="edge_length must return real numbers"):
        size(np.zeros((2, 2)))
