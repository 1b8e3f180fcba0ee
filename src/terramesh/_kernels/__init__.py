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

import contextlib
import os

import numba
import numpy as np

# GNU OpenMP, numba's threading layer on Linux, keeps an idle thread spinning for milliseconds
# after each parallel loop (5 ms and more on the development machine). Where the cores are
# shared (MPI ranks on one node, other jobs) the spinning threads take the time the working
# ones need: two MPI ranks on 2 cores took 3.4-5.4 s for the disk at h = 0.002 against 2.0-2.2 s
# with about ten microseconds of spinning, which keeps the loops of one iteration nearly as
# quick alone (benchmarks/README, "Idle threads that spin"). Set before the first parallel loop loads
# libgomp; an OMP_WAIT_POLICY or GOMP_SPINCOUNT of the user's wins.
if "GOMP_SPINCOUNT" not in os.environ and "OMP_WAIT_POLICY" not in os.environ:
    os.environ["GOMP_SPINCOUNT"] = "1000"

# With NUMBA_DISABLE_JIT=1 (to step through a kernel in a debugger) the kernels run on NumPy
# scalars, which warn where compiled integer arithmetic wraps by design (the hashes, the
# random walks, the radix sort's keys), and the tests turn warnings into errors. NumPy's error state is the
# process's: in this debugging mode alone the user's own integer overflows go unwarned too.
if numba.config.DISABLE_JIT:
    np.seterr(over="ignore")


SERIAL_BELOW = 3000
"""Items under which :func:`threads_for` runs the parallel kernels on the calling thread alone."""


@contextlib.contextmanager
def threads_for(count):
    """Run the parallel kernels within on one thread when ``count`` (points, cells) is under :data:`SERIAL_BELOW`.

    A parallel loop wakes the idle threads, about 60 microseconds on the
    development machine once they stopped spinning (see above), where a
    kernel on a few points takes 5-10: the anisotropic generator's
    projections of the few points that join the boundary, a thousand calls
    a mesh, spent most of their time waking threads, and a coarse level of
    a few thousand points, a dozen loops an iteration, ran 10 % faster on
    one thread (benchmarks/README, "Waking threads for a few points").
    """
    previous = numba.get_num_threads()
    if count >= SERIAL_BELOW or previous == 1:
        yield
        return
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(previous)


def physical_memory():
    """The machine's memory, bytes, or None where the system does not say (no ``sysconf``: Windows)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None


def read_only(array):
    """A read-only view of ``array`` (no copy)."""
    view = array.view()
    view.flags.writeable = False
    return view


def compiled_before(kernel=None):
    """Whether numba's on-disk cache holds ``kernel`` (a compiled function; the triangulation's by default).

    False on a fresh installation: the kernels must first compile for this
    machine (the meshing jobs then compile theirs side by side,
    :func:`.precompile.compile_ahead_on_first_run`); later runs load them
    from the cache. True where numba's internals differ from those this
    reads (nothing is then done ahead).
    """
    if kernel is None:
        from .delaunay import triangulate as kernel

    try:
        return os.path.exists(kernel._cache._cache_file._index_path)
    except AttributeError:
        return True


# before any kernel loads from numba's cache: a kernel file changed in place (a git pull into an
# editable installation) leaves the cached kernels of the files that use it stale (see the module)
from .stale_caches import drop_stale_caches  # noqa: E402

drop_stale_caches()
