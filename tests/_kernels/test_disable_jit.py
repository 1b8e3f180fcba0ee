"""With ``NUMBA_DISABLE_JIT=1`` the kernels run as Python and give the compiled meshes (``_kernels/__init__``)."""

import os
import subprocess
import sys
import textwrap

_MESHES = """
    import hashlib, warnings
    import numpy as np
    import terramesh as tm
    warnings.simplefilter("error")
    for domain, size in [(tm.geometry.Disk((0, 0), 1), 0.1), (tm.geometry.Ball((0, 0, 0), 1), 0.35)]:
        mesh = tm.generate_mesh(domain, size, seed=3)
        print(hashlib.sha256(mesh.points.tobytes() + mesh.cells.tobytes()).hexdigest())
    print(np.geterr()["over"])
"""


def _run(**environment):
    env = dict(os.environ, **environment)
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(_MESHES)], env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return result.stdout.split()


def test_python_kernels_wrap_integers_as_compiled_ones_do():
    # the hashes and random walks overflow uint64/int64 by design; NumPy's scalars warned, which the
    # warnings filter made an error in the lattice seeding and the point location
    *compiled, compiled_errors = _run(NUMBA_DISABLE_JIT="0")
    *python, python_errors = _run(NUMBA_DISABLE_JIT="1")
    assert python == compiled
    assert (compiled_errors, python_errors) == ("warn", "ignore")
