"""The numba kernels live in ``terramesh._kernels`` alone; the stages call them through their validating wrappers."""

import importlib
import pkgutil

import numba

import terramesh
from terramesh._kernels.precompile import kernel_table


def test_every_kernel_is_defined_in_the_kernels_folder():
    # a kernel elsewhere escapes the stale-cache check of the _kernels files' time stamps and the house style
    # (coastal/merge.py, coastal/timestep.py and cleanup/slivers.py held theirs until they moved to _kernels)
    outside = []
    for info in pkgutil.walk_packages(terramesh.__path__, "terramesh."):
        if info.name.endswith("__main__") or info.name.startswith("terramesh._kernels."):
            continue
        module = importlib.import_module(info.name)
        outside += [
            f"{info.name}.{name}"
            for name, value in vars(module).items()
            if isinstance(value, numba.core.dispatcher.Dispatcher) and value.py_func.__module__ == info.name
        ]
    assert outside == []


def test_the_table_names_each_kernel_by_its_kernel_module():
    rows = [row for rows in kernel_table().values() for row in rows]
    assert [f"{module}.{function}" for module, function, *_ in rows if not module.startswith("_kernels.")] == []
