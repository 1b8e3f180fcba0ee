"""The column-by-column reductions give NumPy's own numbers, to the bit."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from terramesh.mesh.columns import bounds, row_max, row_norms, rows_all, rows_any, squared_row_norms
from terramesh.mesh.topology import all_corners_in, any_corner_in

finite = st.floats(min_value=-1e150, max_value=1e150, allow_nan=False, allow_subnormal=True)


@given(hnp.arrays(np.float64, st.tuples(st.integers(1, 40), st.integers(1, 3)), elements=finite))
@settings(max_examples=200, deadline=None)
def test_float_reductions_equal_numpys_along_the_short_axis(values):
    low, high = bounds(values)
    assert np.array_equal(low, values.min(axis=0)) and np.array_equal(high, values.max(axis=0))
    assert np.array_equal(squared_row_norms(values), np.sum(values**2, axis=1))
    assert np.array_equal(row_norms(values), np.linalg.norm(values, axis=1))
    assert np.array_equal(row_max(values), values.max(axis=1))


@given(hnp.arrays(np.bool_, st.tuples(st.integers(1, 40), st.integers(1, 4))))
def test_boolean_reductions_equal_numpys_along_the_short_axis(mask):
    assert np.array_equal(rows_all(mask), mask.all(axis=1))
    assert np.array_equal(rows_any(mask), mask.any(axis=1))


@given(st.data())
def test_corner_masks_equal_numpys(data):
    n = data.draw(st.integers(1, 12))
    cells = data.draw(
        hnp.arrays(np.int64, st.tuples(st.integers(0, 20), st.sampled_from([3, 4])), elements=st.integers(0, n - 1))
    )
    mask = data.draw(hnp.arrays(np.bool_, n))
    assert np.array_equal(all_corners_in(mask, cells), mask[cells].all(axis=1))
    assert np.array_equal(any_corner_in(mask, cells), mask[cells].any(axis=1))


def test_the_inputs_are_not_changed():
    values = np.array([[1.0, -2.0], [3.0, 4.0]])
    mask = values > 0
    kept, kept_mask = values.copy(), mask.copy()
    for reduce in (bounds, squared_row_norms, row_norms, row_max):
        reduce(values)
    rows_all(mask), rows_any(mask)
    assert np.array_equal(values, kept) and np.array_equal(mask, kept_mask)
