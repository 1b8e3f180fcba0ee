"""What the data readers share.

The readers themselves live with the data they read: coastlines and DEMs in
:mod:`terramesh.coastal` (``shoreline``, ``dem``), velocity models in
:mod:`terramesh.seismic` (``velocity``, ``segy``, ``binary``). The checks
both domains need are here, in the core, so that neither imports the other
or a file-format module for them.
"""

from .netcdf import check_classic_size

__all__ = ["check_classic_size"]
