import io
import os
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from terramesh.io._text import fortran_list_directed, fortran_real, write_rows, written_whole


@settings(deadline=None, max_examples=80)
@given(
    arrays(np.float64, st.tuples(st.integers(0, 30), st.integers(1, 5)), elements=st.floats(-1e300, 1e300)),
    st.sampled_from(["%.17g", "%.9g", "%d"]),
    st.booleans(),
)
def test_write_rows_writes_what_savetxt_writes(table, fmt, one_dimensional):
    rows = table[:, 0] if one_dimensional else table
    if fmt == "%d":
        rows = np.round(rows / 1e290)
    expected, got = io.StringIO(), io.StringIO()
    np.savetxt(expected, rows, fmt=fmt)
    write_rows(got, rows, fmt)
    assert got.getvalue() == expected.getvalue()
    if not one_dimensional:
        formats = [fmt] * rows.shape[1]
        expected, got = io.StringIO(), io.StringIO()
        np.savetxt(expected, rows, fmt=formats)
        write_rows(got, rows, formats)
        assert got.getvalue() == expected.getvalue()


def test_write_rows_in_chunks():
    rows = np.column_stack([np.arange(250_001), np.linspace(0, 1, 250_001)])
    expected, got = io.StringIO(), io.StringIO()
    np.savetxt(expected, rows, fmt="%d %.17g")
    write_rows(got, rows, "%d %.17g")
    assert got.getvalue() == expected.getvalue()


@settings(deadline=None, max_examples=80)
@given(
    st.sampled_from([np.int64, np.int32, np.uint32, np.int8, np.uint8]).flatmap(
        lambda dtype: arrays(dtype, st.tuples(st.integers(0, 30), st.integers(1, 6)))
    ),
    st.booleans(),
)
def test_whole_numbers_are_written_as_percent_d_writes_them(table, one_dimensional):
    """Integer tables take the compiled path: the same text, extremes and signs included."""
    rows = table[:, 0] if one_dimensional else table
    expected, got = io.StringIO(), io.StringIO()
    np.savetxt(expected, rows, fmt="%d")
    write_rows(got, rows, "%d")
    assert got.getvalue() == expected.getvalue()


def test_whole_number_extremes_and_chunks():
    info = np.iinfo(np.int64)
    edges = np.array([[info.min, info.max, 0], [-1, 1, -10], [10**18, -(10**18), 9]], dtype=np.int64)
    rows = np.vstack([edges, np.arange(3 * 250_001, dtype=np.int64).reshape(-1, 3) - 10**6])
    expected, got = io.StringIO(), io.StringIO()
    np.savetxt(expected, rows, fmt="%d")
    write_rows(got, rows, ["%d", "%d", "%d"])
    assert got.getvalue() == expected.getvalue()
    beyond = np.array([[2**64 - 1]], dtype=np.uint64)  # past int64: % formatting, still exact
    got = io.StringIO()
    write_rows(got, beyond, "%d")
    assert got.getvalue() == f"{2**64 - 1}\n"


def test_written_whole_moves_sidecars_and_cleans_up(tmp_path):
    path = tmp_path / "mesh.xdmf"
    with written_whole(path) as temporary:
        assert os.path.dirname(temporary) != str(tmp_path) and os.path.basename(temporary) == "mesh.xdmf"
        with open(temporary, "w") as handle:
            handle.write("grid")
        with open(os.path.splitext(temporary)[0] + ".h5", "w") as handle:
            handle.write("data")
    assert sorted(entry.name for entry in tmp_path.iterdir()) == ["mesh.h5", "mesh.xdmf"]
    with pytest.raises(ValueError, match="half-way"), written_whole(path) as temporary:
        with open(temporary, "w") as handle:
            handle.write("gr")
        raise ValueError("half-way")
    assert path.read_text() == "grid"
    assert sorted(entry.name for entry in tmp_path.iterdir()) == ["mesh.h5", "mesh.xdmf"]


def test_written_whole_names_what_is_wrong_with_the_path(tmp_path):
    with (
        pytest.raises(FileNotFoundError, match="no such folder to write in.*missing"),
        written_whole(tmp_path / "missing" / "fort.14"),
    ):
        pass
    (tmp_path / "fort.14").mkdir()
    with pytest.raises(IsADirectoryError, match="fort.14"), written_whole(tmp_path / "fort.14"):
        pass


@settings(deadline=None, max_examples=200)
@given(st.floats(allow_nan=False, allow_infinity=False), st.sampled_from(["D", "d"]), st.booleans())
def test_fortran_real_reads_a_d_exponent_as_an_e_one(value, marker, plus):
    text = f"{value:.17e}"  # always an exponent: 1.00000000000000000e+17
    fortran = text.replace("e", marker).replace("+", "+" if plus else "")
    assert fortran_real(fortran) == fortran_real(text) == float(text)
    lines = [f"1 {fortran} ! sand", "2 0.5"]
    translated = fortran_list_directed(lines)
    assert translated == [lines[0].replace("D", "E").replace("d", "e"), "2 0.5"]
    assert np.loadtxt(translated, usecols=1, comments=None)[0] == value
    assert fortran_list_directed([f"1 {text}", "2 0.5"]) is None


@pytest.mark.parametrize("token", ["1.0X+01", "1.0D+0X", "D", "1.0D", "d5", "1.0DD1", "1.0D+01D", ""])
def test_fortran_real_refuses_what_is_no_number_quoting_it_as_written(token):
    with pytest.raises(ValueError, match=re.escape(f"could not convert string to float: {token!r}")):
        fortran_real(token)
