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


# STYLE.md's direction: kernels -> core -> domains (coastal, seismic) -> edges (io, parallel, plot, cli)
CORE = {
    "_kernels",
    "errors",
    "geometry",
    "readers",
    "sizing",
    "generation",
    "cleanup",
    "mesh",
    "quality",
    "postprocess",
}
DOMAINS = {"coastal", "seismic"}
EDGES = {"io", "parallel", "plot", "cli", "examples"}
# a Mesh's conveniences, which hand over to the stage that does the work (as meshio's Mesh.write does), and
# the coastal workflow's: tm.coastal.write_fort13/15, CoastalSizes.plot, build(parts=) meshing in strips
HANDED_OVER = {
    ("mesh/mesh.py", "io"),
    ("mesh/mesh.py", "coastal"),
    ("coastal/__init__.py", "io"),
    ("coastal/build.py", "plot"),
    ("coastal/build.py", "parallel"),
}


def _imported_packages(path, package_root):
    """``(line, top-level terramesh package)`` of every import in ``path``, in functions too."""
    import ast

    module = list(path.relative_to(package_root).with_suffix("").parts)
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = module[: len(module) - node.level]
            parts = base + (node.module.split(".") if node.module else [a.name for a in node.names])
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("terramesh."):
            parts = node.module.split(".")[1:]
        elif isinstance(node, ast.Import):
            parts = next((a.name.split(".")[1:] for a in node.names if a.name.startswith("terramesh.")), [])
        else:
            continue
        if parts:
            found.append((node.lineno, parts[0]))
    return found


def test_imports_flow_from_the_core_to_the_domains_to_the_edges():
    # the core had imported the fort.14 module for the ADCIRC boundary types a mesh carries (now mesh.boundaries)
    import pathlib

    import terramesh

    root = pathlib.Path(terramesh.__file__).parent
    wrong = []
    for path in sorted(root.rglob("*.py")):
        relative = path.relative_to(root)
        package = relative.parts[0] if len(relative.parts) > 1 else relative.stem
        for line, target in _imported_packages(path, root):
            core_reaches_out = package in CORE and target not in CORE
            domains_cross = package in DOMAINS and target in DOMAINS and target != package
            domains_reach_out = package in DOMAINS and target in EDGES
            allowed = (relative.as_posix(), target) in HANDED_OVER
            if (core_reaches_out or domains_cross or domains_reach_out) and not allowed:
                wrong.append(f"{relative}:{line} imports {target}")
    assert wrong == []


# modules of other libraries whose private names terramesh reads, each for a reason said where it is read
THIRD_PARTY_PRIVATE = {"meshio.gmsh.common", "segyio"}


def test_no_module_imports_another_modules_private_names():
    # 154 such imports had made the package's internal interfaces invisible: a name another module uses
    # is that module's interface and is named without the underscore
    import ast
    import pathlib

    import terramesh

    root = pathlib.Path(terramesh.__file__).parent
    private = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.level or node.module not in THIRD_PARTY_PRIVATE):
                names = [a.name for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
                private += [f"{path.relative_to(root)}:{node.lineno} imports {name}" for name in names]
    assert private == []
