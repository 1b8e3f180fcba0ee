import netCDF4
import numpy as np
import pytest

from terramesh.errors import MeshFormatError
from terramesh.readers import check_classic_size
from terramesh.readers.netcdf import classic_data_end


def _write(path, file_format, records=0):
    with netCDF4.Dataset(path, "w", format=file_format) as ds:
        ds.createDimension("y", 30)
        ds.createDimension("x", 40)
        ds.createVariable("z", "f4", ("y", "x"))[:] = np.arange(1200.0).reshape(30, 40)
        if records:
            ds.createDimension("time", None)
            ds.createVariable("level", "f8", ("time", "x"))[:] = np.ones((records, 40))
    return path


@pytest.mark.parametrize("records", [0, 3])
def test_a_cut_classic_file_is_named_with_both_sizes(tmp_path, records):
    path = _write(tmp_path / "dem.nc", "NETCDF3_CLASSIC", records)
    with netCDF4.Dataset(path) as ds:
        check_classic_size(ds, path)  # whole: nothing to say
    data = path.read_bytes()
    assert classic_data_end(path) == len(data)
    # 1200 floats of 4 bytes and 8-byte levels along each record fill all but the header; a file cut by less
    # than the header held all the variables' bytes and read zeros at its end
    header = len(data) - 1200 * 4 - records * 40 * 8
    assert header > 50
    cut = len(data) - header // 2
    path.write_bytes(data[:cut])
    message = rf"dem.nc is truncated: {cut:,} bytes, but its data end at byte {len(data):,}"
    with netCDF4.Dataset(path) as ds, pytest.raises(MeshFormatError, match=message):
        check_classic_size(ds, path)


@pytest.mark.parametrize("file_format", ["NETCDF3_64BIT_OFFSET", "NETCDF3_64BIT_DATA"])
def test_the_other_classic_formats_are_read_to_their_end(tmp_path, file_format):
    path = _write(tmp_path / "dem.nc", file_format, records=2)
    assert classic_data_end(path) == path.stat().st_size


def test_a_header_cut_short_or_no_netcdf_is_named(tmp_path):
    path = _write(tmp_path / "dem.nc", "NETCDF3_CLASSIC")
    path.write_bytes(path.read_bytes()[:40])
    with pytest.raises(MeshFormatError, match="dem.nc is truncated: it ends inside its NetCDF header"):
        classic_data_end(path)
    path.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(100))
    with pytest.raises(MeshFormatError, match="dem.nc is no classic NetCDF file"):
        classic_data_end(path)


def test_netcdf4_files_are_left_to_hdf5s_own_checks(tmp_path):
    path = _write(tmp_path / "dem.nc", "NETCDF4")
    with netCDF4.Dataset(path) as ds:
        assert check_classic_size(ds, path) is None
