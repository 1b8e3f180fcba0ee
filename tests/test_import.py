"""What ``import terramesh`` loads: the readers, plotting and the solvers' libraries wait until used."""

import subprocess
import sys

# each costs from 0.05 s (netCDF4) to 0.4 s (matplotlib.pyplot) at every start of the command line
# or of an MPI rank, and only some jobs use them
DEFERRED = ("scipy.ndimage", "matplotlib", "meshio", "netCDF4", "segyio", "mpi4py", "pyproj", "rasterio")


def test_import_leaves_the_heavy_modules_unloaded():
    probe = f"import sys, terramesh; print(' '.join(m for m in {DEFERRED!r} if m in sys.modules))"
    loaded = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout.split()
    assert loaded == []


def test_a_coastline_search_loads_the_distance_transform_when_it_needs_it():
    probe = (
        "import sys, numpy as np, terramesh as tm\n"
        "square = tm.geometry.Polygon([(0, 0), (4, 0), (4, 4), (0, 4)])\n"
        "before = 'scipy.ndimage' in sys.modules\n"
        "distance, _ = square.distance_and_nearest(np.array([[2.0, 2.0], [40.0, 2.0]]), 0.5)\n"
        "print(before, 'scipy.ndimage' in sys.modules, distance.tolist())"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout.split()
    assert out[:2] == ["False", "True"]
