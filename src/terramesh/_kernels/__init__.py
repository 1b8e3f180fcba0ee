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

import os


def read_only(array):
    """A read-only view of ``array`` (no copy)."""
    view = array.view()
    view.flags.writeable = False
    return view


def compiled_before():
    """Whether numba's on-disk cache holds the triangulation kernel.

    False on a fresh installation: the kernels must first compile for this
    machine (the command line then compiles its job's side by side,
    :func:`.precompile.compile_kernels`); later runs load them from the
    cache. True where numba's internals differ from those this reads
    (nothing is then done ahead).
    """
    from .delaunay import triangulate

    try:
        return os.path.exists(triangulate._cache._cache_file._index_path)
    except AttributeError:
        return True
