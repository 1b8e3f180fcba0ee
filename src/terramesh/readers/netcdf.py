"""Checks shared by the NetCDF readers (DEMs, velocity models)."""

import os

import numpy as np

from ..errors import MeshFormatError


def check_classic_size(dataset, path):
    """Refuse a classic-format (NetCDF-3) file shorter than its variables' data: it was truncated.

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
        If the file holds fewer bytes than its variables need, with both counts.
    """
    if not dataset.file_format.startswith("NETCDF3"):
        return
    records = max((len(dim) for dim in dataset.dimensions.values() if dim.isunlimited()), default=0)
    needed = 0
    for var in dataset.variables.values():
        sizes = [
            records if dataset.dimensions[dim].isunlimited() else len(dataset.dimensions[dim]) for dim in var.dimensions
        ]
        needed += int(np.prod(sizes, dtype=np.int64)) * var.dtype.itemsize
    size = os.path.getsize(path)
    if size < needed:
        raise MeshFormatError(f"{path} is truncated: {size:,} bytes, but its variables need at least {needed:,}")
