import netCDF4
import numpy as np
import pytest

from terramesh.errors import MeshFormatError
from terramesh.readers import check_classic_size


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
    # 1200 floats of 4 bytes, and 8-byte levels along each record
    needed = 1200 * 4 + records * 40 * 8
    assert len(data) >= needed
    path.write_bytes(data[: needed - 1])
    with netCDF4.Dataset(path) as ds:
        with pytest.raises(
            MeshFormatError, match=rf"dem.nc is truncated: {needed - 1:,} bytes, .* at least {needed:,}"
        ):
            check_classic_size(ds, path)


def test_netcdf4_files_are_left_to_hdf5s_own_checks(tmp_path):
    path = _write(tmp_path / "dem.nc", "NETCDF4")
    with netCDF4.Dataset(path) as ds:
        assert check_classic_size(ds, path) is None
