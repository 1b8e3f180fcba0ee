"""Compiled (numba) kernels.

Private: every function takes contiguous arrays of the documented dtype and
does no validation; the public wrappers elsewhere in the package do that.

Numba compiles a kernel once per argument type, and a read-only array (a
memory map, a broadcast) is another type than a writable one; a wrapper
whose input may be either passes :func:`read_only` so that one compilation
serves both. Likewise a compiled caller passes ``np.int64(0)`` rather than
``0`` where a plain constant would be typed as that literal value and
compiled into a specialization of its own.
"""


def read_only(array):
    """A read-only view of ``array`` (no copy)."""
    view = array.view()
    view.flags.writeable = False
    return view
