"""terramesh.seismic.binary: raw binary velocity files, their shape, dtype and byte order."""

import warnings

import numpy as np
import pytest

from terramesh.errors import MeshFormatError, SizingError
from terramesh.seismic import read_velocity

from .test_velocity import SECTION_ZX, check_section


def test_a_raw_binary_model_with_a_few_nan_samples_is_told_to_fill_them(tmp_path):
    # they were blamed on the byte order, though every other value was a plausible velocity
    values = SECTION_ZX.astype("<f4")
    values[0, :2] = np.nan
    path = tmp_path / "holes.bin"
    values.tofile(path)
    with pytest.raises(
        SizingError, match=r"2 NaN or infinite velocities \(the first at index \(0, 0\) \(z, x\)\); fill"
    ):
        read_velocity(path, shape=(3, 4), axis_order="zx", spacing=1.0)


@pytest.mark.parametrize("byte_order, code", [("little", "<"), ("big", ">")])
@pytest.mark.parametrize("axis_order", ["zx", "xz"])
def test_raw_binary(tmp_path, byte_order, code, axis_order):
    array = SECTION_ZX if axis_order == "zx" else SECTION_ZX.T
    path = tmp_path / "vel.bin"
    array.astype(code + "f4").tofile(path)
    model = read_velocity(path, shape=array.shape, axis_order=axis_order, byte_order=byte_order, spacing=(10.0, 5.0))
    check_section(model)


def test_raw_binary_float64_and_3d(tmp_path):
    values = np.arange(1, 25, dtype=np.float64).reshape(2, 3, 4) * 100  # (z, x, y)
    path = tmp_path / "Saltf@@"
    values.astype(">f8").tofile(path)
    model = read_velocity(path, shape=(2, 3, 4), axis_order="zxy", dtype="float64", byte_order="big", spacing=10.0)
    assert model.shape == (3, 4, 2)
    assert model([(0.0, 0.0, 0.0)])[0] == 100.0  # the first value is the top of the first trace
    assert model([(0.0, 0.0, -10.0)])[0] == 1300.0


def test_raw_binary_of_the_wrong_size_names_both_byte_counts(tmp_path):
    path = tmp_path / "vel.bin"
    SECTION_ZX.astype("<f4").tofile(path)  # 12 values, 48 bytes
    with pytest.raises(MeshFormatError, match=r"48 bytes.*\(4, 4\).*needs 64 bytes"):
        read_velocity(path, shape=(4, 4), axis_order="zx", spacing=1.0)
    with pytest.raises(MeshFormatError, match="needs 96 bytes"):
        read_velocity(path, shape=(3, 4), axis_order="zx", dtype="float64", spacing=1.0)
    with pytest.raises(SizingError, match="shape"):
        read_velocity(path, axis_order="zx", spacing=1.0)
    with pytest.raises(SizingError, match="axis_order"):
        read_velocity(path, shape=(3, 4), spacing=1.0)
    with pytest.raises(SizingError, match="byte_order"):
        read_velocity(path, shape=(3, 4), axis_order="zx", spacing=1.0, byte_order="middle")


def test_raw_binary_byte_order_named_by_the_dtype(tmp_path):
    # dtype=">f4" was read little-endian (the default byte_order) and refused as misread bytes
    path = tmp_path / "vel.bin"
    SECTION_ZX.astype(">f4").tofile(path)
    options = dict(shape=(3, 4), axis_order="zx", spacing=1.0)
    expected = read_velocity(SECTION_ZX, axis_order="zx", spacing=1.0).values
    np.testing.assert_array_equal(read_velocity(path, dtype=">f4", **options).values, expected)
    np.testing.assert_array_equal(read_velocity(path, dtype=np.dtype(">f4"), **options).values, expected)
    np.testing.assert_array_equal(read_velocity(path, dtype=">f4", byte_order="big", **options).values, expected)
    with pytest.raises(SizingError, match="dtype '>f4' is big-endian but byte_order='little'"):
        read_velocity(path, dtype=">f4", byte_order="little", **options)
    SECTION_ZX.astype("<f4").tofile(path)
    np.testing.assert_array_equal(read_velocity(path, dtype="<f4", **options).values, expected)
    with pytest.raises(SizingError, match="little-endian but byte_order='big'"):
        read_velocity(path, dtype="<f4", byte_order="big", **options)


def test_raw_binary_read_in_the_wrong_order_or_type_is_refused(tmp_path):
    # misread, 1500 m/s became 1.2e-38 (which warned "looks like km/s") or 1e23, and random bits NaN
    path = tmp_path / "vel.bin"
    SECTION_ZX.astype(">f4").tofile(path)
    options = dict(shape=(3, 4), axis_order="zx", spacing=1.0)
    with pytest.raises(
        MeshFormatError, match=r"largest magnitude 1.*e-3\d.*check byte_order \(now 'little'; try 'big'\)"
    ):
        read_velocity(path, **options)
    SECTION_ZX.astype("<f4").tofile(path)
    with pytest.raises(MeshFormatError, match=r"e\+\d\d, which no velocity model has.*dtype \(now 'float64'\)"):
        read_velocity(path, **dict(options, shape=(2, 3)), dtype="float64")
    np.random.default_rng(0).random((50, 80)).astype(">f4").tofile(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no NumPy warning on the way
        with pytest.raises(MeshFormatError, match="NaN or infinite values and largest magnitude"):
            read_velocity(path, shape=(50, 80), axis_order="zx", spacing=1.0)


@pytest.mark.parametrize("shape", [(12,), (3, 2, 2, 1), "3x4", (3.5, 4)])
def test_raw_binary_shape_is_named_before_the_spacing(tmp_path, shape):
    path = tmp_path / "vel.bin"
    SECTION_ZX.astype("<f4").tofile(path)
    with pytest.raises(SizingError, match="shape must be 2 or 3 whole numbers"):
        read_velocity(path, shape=shape, axis_order="zx", spacing=(10.0, 5.0))
