"""Checks shared by the NetCDF readers (DEMs, velocity models)."""

import os

import numpy as np

from ..errors import MeshFormatError

__all__ = ["check_classic_size", "classic_data_end"]

# the classic formats' header (NetCDF User Guide, "File Format Specifications"): tags and types
_ABSENT, _DIMENSION, _VARIABLE, _ATTRIBUTE = 0, 10, 11, 12
_TYPE_BYTES = {1: 1, 2: 1, 3: 2, 4: 4, 5: 4, 6: 8, 7: 1, 8: 2, 9: 4, 10: 8, 11: 8}


def check_classic_size(dataset, path):
    """Refuse a classic-format (NetCDF-3) file shorter than its header says its data are: it was truncated.

    netCDF-C reads zeros past the end of such a file, which a reader would
    report as zero elevations or velocities instead of a cut file.

    Parameters
    ----------
    dataset : netCDF4.Dataset
        The file, open.
    path : str or os.PathLike
        Its path, for its size and the message.

    Raises
    ------
    MeshFormatError
        If the file ends before its last variable's data do, with both
        sizes in bytes.

    Examples
    --------
    >>> import netCDF4, os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "dem.nc")
    >>> with netCDF4.Dataset(path, "w", format="NETCDF3_CLASSIC") as ds:
    ...     _ = ds.createDimension("x", 100)
    ...     ds.createVariable("z", "f8", ("x",))[:] = 1.0
    >>> os.truncate(path, os.path.getsize(path) - 1)
    >>> with netCDF4.Dataset(path) as ds:
    ...     check_classic_size(ds, path)
    Traceback (most recent call last):
    ...
    terramesh.errors.MeshFormatError: ...dem.nc is truncated: 879 bytes, but its data end at byte 880
    """
    if not dataset.file_format.startswith("NETCDF3"):
        return
    size = os.path.getsize(path)
    end = classic_data_end(path)
    if size < end:
        raise MeshFormatError(f"{path} is truncated: {size:,} bytes, but its data end at byte {end:,}")


def classic_data_end(path):
    """The byte at which a classic-format NetCDF file's data end, from the offsets in its header.

    The variables' sizes alone leave out the header: a file cut by less
    than the header's length held every variable's bytes' worth and still
    read zeros at its end.

    Parameters
    ----------
    path : str or os.PathLike
        A NetCDF-3 file: classic, 64-bit offset or CDF-5.

    Returns
    -------
    int
        One past the last byte of data the header places (of a file still
        being written, whose record count is unknown, the fixed-size
        variables' only).

    Raises
    ------
    MeshFormatError
        If the file is not one of those formats or ends inside its header.
    """
    with open(path, "rb") as file:
        header = _Header(file, path)
        version = header.magic()
        count_bytes = 8 if version == 5 else 4
        records = header.unsigned(count_bytes)
        dimensions = [
            length for _, length in header.items(_DIMENSION, count_bytes, lambda: header.unsigned(count_bytes))
        ]
        header.items(_ATTRIBUTE, count_bytes, lambda: header.attribute_values(count_bytes))
        variables = header.items(_VARIABLE, count_bytes, lambda: header.variable(count_bytes, version))
    ends, record_variables = [0], []
    for _, (dimension_ids, kind, begin) in variables:
        lengths = [dimensions[i] for i in dimension_ids]
        is_record = bool(lengths) and lengths[0] == 0
        data_bytes = int(np.prod(lengths[1:] if is_record else lengths, dtype=np.int64)) * _TYPE_BYTES[kind]
        if is_record:
            record_variables.append((begin, data_bytes))
        else:
            ends.append(begin + data_bytes)
    streaming = records == 2 ** (8 * count_bytes) - 1  # a file still being written: its readers count the records
    if record_variables and records and not streaming:
        # a record holds each record variable's slab padded to 4 bytes, but a lone variable's is not padded
        padded = [data_bytes + (-data_bytes) % 4 for _, data_bytes in record_variables]
        record_bytes = record_variables[0][1] if len(record_variables) == 1 else sum(padded)
        ends += [begin + (records - 1) * record_bytes + data_bytes for begin, data_bytes in record_variables]
    return max(ends)


class _Header:
    """Reads a classic NetCDF header from an open file, big-endian, as its specification lays it out."""

    def __init__(self, file, path):
        self.file, self.path = file, path

    def read(self, count):
        data = self.file.read(count)
        if len(data) < count:
            raise MeshFormatError(f"{self.path} is truncated: it ends inside its NetCDF header")
        return data

    def unsigned(self, count):
        return int.from_bytes(self.read(count), "big")

    def magic(self):
        magic = self.read(4)
        if magic[:3] != b"CDF" or magic[3] not in (1, 2, 5):
            raise MeshFormatError(f"{self.path} is no classic NetCDF file (it starts {magic!r})")
        return magic[3]

    def name(self, count_bytes):
        length = self.unsigned(count_bytes)
        return self.read(length + (-length) % 4)[:length]

    def items(self, tag, count_bytes, read_item):
        """``[(name, read_item()), ...]`` of a list tagged ``tag`` (or absent)."""
        found, count = self.unsigned(4), self.unsigned(count_bytes)
        if found not in (tag, _ABSENT) or (found == _ABSENT and count):
            raise MeshFormatError(f"{self.path}: its NetCDF header is malformed (a list tagged {found})")
        return [(self.name(count_bytes), read_item()) for _ in range(count)]

    def attribute_values(self, count_bytes):
        kind = self.type_code()
        values = self.unsigned(count_bytes) * _TYPE_BYTES[kind]
        self.read(values + (-values) % 4)

    def type_code(self):
        kind = self.unsigned(4)
        if kind not in _TYPE_BYTES:
            raise MeshFormatError(f"{self.path}: its NetCDF header is malformed (type {kind})")
        return kind

    def variable(self, count_bytes, version):
        dimension_ids = [self.unsigned(count_bytes) for _ in range(self.unsigned(count_bytes))]
        self.items(_ATTRIBUTE, count_bytes, lambda: self.attribute_values(count_bytes))
        kind = self.type_code()
        self.unsigned(count_bytes)  # vsize: capped for large variables, so the sizes are counted from the shape
        begin = self.unsigned(4 if version == 1 else 8)
        return dimension_ids, kind, begin
