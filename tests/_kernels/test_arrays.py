import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from terramesh._kernels import arrays

finite = st.floats(-1e12, 1e12, allow_nan=False, allow_infinity=False)


@settings(deadline=None, max_examples=60)
@given(hnp.arrays(np.float64, st.integers(0, 300), elements=finite), st.integers(0, 300))
def test_sort_in_place_is_numpys_sort_of_the_head(values, count):
    count = min(count, len(values))
    expected = np.concatenate([np.sort(values[:count]), values[count:]])
    arrays.sort_in_place(values, count)
    np.testing.assert_array_equal(values, expected)


@settings(deadline=None, max_examples=60)
@given(hnp.arrays(np.int64, st.integers(0, 200), elements=st.integers(-50, 50)), st.integers(-60, 60))
def test_count_below_is_searchsorted(values, value):
    ascending = np.sort(values)
    assert arrays.count_below(ascending, value) == np.searchsorted(ascending, value)


def test_copies_and_growing():
    source = np.arange(12.0).reshape(6, 2)
    rows = np.full((8, 2), -1.0)
    arrays.copy_rows(rows, source, 4)
    np.testing.assert_array_equal(rows[:4], source[:4])
    assert np.all(rows[4:] == -1.0)
    head = np.zeros(5, dtype=np.int64)
    arrays.copy_head(head, np.arange(10, 20), 3)
    np.testing.assert_array_equal(head, [10, 11, 12, 0, 0])
    grown = arrays.grown(source.astype(np.int64), 9, -7)
    assert grown.shape == (9, 2) and grown.dtype == np.int64
    np.testing.assert_array_equal(grown[:6], source)
    assert np.all(grown[6:] == -7)
    flat = arrays.grown(np.array([True, False]), 4, False)
    np.testing.assert_array_equal(flat, [True, False, False, False])
