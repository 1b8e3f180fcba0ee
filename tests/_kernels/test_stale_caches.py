"""Numba's caches of kernels built on another file's kernels: dropped when that file changes."""

import json
import os
import pathlib
import subprocess
import sys

from terramesh._kernels import stale_caches
from terramesh._kernels.precompile import kernels_reached
from terramesh._kernels.stale_caches import STAMPS, drop_stale_caches

from .test_precompile import package_kernels

SOURCES = {
    "_kernels/__init__.py": "",
    "_kernels/base.py": "LIMIT = 1\n",
    "_kernels/middle.py": "from .base import LIMIT\n",
    "_kernels/alone.py": "VALUE = 2\n",
    "stage/__init__.py": "",
    "stage/user.py": "from .._kernels.middle import LIMIT\n",
    "stage/other.py": "from .._kernels import alone\n",
    "stage/plain.py": "import os\n",
}


def write_package(root):
    for name, text in SOURCES.items():
        path = root / "package" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root / "package"


def in_tree(path):
    return os.path.join(os.path.dirname(path), "__pycache__")


def cache_files(package):
    """Fake cache files, one index and one data file per module, as numba names them."""
    made = []
    for name in SOURCES:
        path = package / name
        cache = pathlib.Path(in_tree(path))
        cache.mkdir(exist_ok=True)
        for suffix in (".nbi", ".1.nbc"):
            made.append(cache / f"{path.stem}.kernel-3.py311{suffix}")
            made[-1].write_text("")
    return made


def drop(package):
    deleted = drop_stale_caches(str(package / "_kernels"), str(package), in_tree)
    return sorted(
        {
            os.path.relpath(os.path.dirname(os.path.dirname(path)), package)
            + "/"
            + os.path.basename(path).split(".")[0]
            for path in deleted
        }
    )


def test_a_changed_kernel_file_drops_the_caches_of_its_importers_at_any_depth(tmp_path):
    package = write_package(tmp_path)
    cache_files(package)
    # no record yet: any cache may be stale, so every kernel file and importer is dropped
    assert drop(package) == [
        "_kernels/__init__",
        "_kernels/alone",
        "_kernels/base",
        "_kernels/middle",
        "stage/other",
        "stage/user",
    ]
    record = json.loads((package / "_kernels" / "__pycache__" / STAMPS).read_text())
    assert sorted(record) == ["__init__.py", "alone.py", "base.py", "middle.py"]
    made = cache_files(package)
    assert drop(package) == []  # nothing changed
    assert all(path.exists() for path in made)
    (package / "_kernels" / "base.py").write_text("LIMIT = 10\n")  # a size of its own: a change whatever the clock
    assert drop(package) == ["_kernels/base", "_kernels/middle", "stage/user"]
    assert (package / "stage" / "__pycache__" / "other.kernel-3.py311.nbi").exists()
    assert drop(package) == []
    (package / "_kernels" / "alone.py").unlink()  # a file gone counts as changed, its caches go too
    assert drop(package) == ["_kernels/alone", "stage/other"]


def test_a_removed_kernel_file_drops_its_importers_caches_by_numbas_own_rule(tmp_path):
    # numba's locator refuses a file that is gone: the check failed that way on every later import
    package = write_package(tmp_path)
    drop_stale_caches(str(package / "_kernels"), str(package))
    made = cache_files(package)
    (package / "_kernels" / "alone.py").unlink()
    deleted = drop_stale_caches(str(package / "_kernels"), str(package))
    assert sorted(pathlib.Path(path).name for path in deleted) == [
        "alone.kernel-3.py311.1.nbc",
        "alone.kernel-3.py311.nbi",
        "other.kernel-3.py311.1.nbc",
        "other.kernel-3.py311.nbi",
    ]
    record = package / "_kernels" / "__pycache__" / STAMPS
    assert "alone.py" not in json.loads(record.read_text())
    assert oct(record.stat().st_mode & 0o777) == "0o644"  # readable by the other users of an installation
    assert drop_stale_caches(str(package / "_kernels"), str(package)) == []
    assert sum(path.exists() for path in made) == len(made) - 4


def test_an_unreadable_record_or_cache_folder_is_no_error(tmp_path):
    package = write_package(tmp_path)
    cache_files(package)
    (package / "_kernels" / "__pycache__" / STAMPS).write_text("{not json")
    assert "stage/user" in drop(package)

    def nowhere(path):
        raise OSError("read-only file system")

    assert drop_stale_caches(str(package / "_kernels"), str(package), nowhere) == []


def test_imports_are_resolved_relatively_and_absolutely():
    package = "/somewhere/terramesh"
    found = stale_caches._kernel_modules_imported(
        "from .._kernels.topology import x\nfrom .._kernels import delaunay as exact, threads_for\n"
        "import terramesh._kernels.raster\nfrom ..mesh import topology\nfrom . import segments\n",
        f"{package}/coastal/merge.py",
        package,
        "terramesh._kernels",
    )
    assert found == {"topology", "delaunay", "threads_for", "raster"}
    inside = stale_caches._kernel_modules_imported(
        "from .arrays import grown\nfrom . import expansions\n",
        f"{package}/_kernels/delaunay.py",
        package,
        "terramesh._kernels",
    )
    assert inside == {"arrays", "expansions"}


def test_the_cache_folder_is_numbas_own_for_the_file():
    from terramesh._kernels import delaunay

    assert stale_caches.numba_cache_folder(delaunay.__file__) == delaunay.triangulate._cache._cache_path


def test_a_kernel_that_inlines_another_files_kernel_runs_its_new_version_after_a_change(tmp_path):
    # the hazard itself, with numba's real cache: an edit of the helper's file alone (a git pull into an
    # editable installation) left the caller's cached machine code running the old helper
    root = tmp_path / "site"
    kernels = root / "toy" / "_kernels"
    kernels.mkdir(parents=True)
    (root / "toy" / "__init__.py").write_text("")
    (kernels / "__init__.py").write_text(
        "from terramesh._kernels.stale_caches import drop_stale_caches\n"
        "import os\n"
        "if os.environ.get('TOY_DROP') == '1':\n"
        "    drop_stale_caches(os.path.dirname(__file__))\n"
    )
    helper = kernels / "helper.py"
    helper.write_text("from numba import njit\n\n\n@njit(inline='always')\ndef helper():\n    return 1\n")
    (kernels / "user.py").write_text(
        "from numba import njit\n\nfrom .helper import helper\n\n\n"
        "@njit(cache=True)\ndef user():\n    return helper()\n"
    )

    def run(drop):
        code = "from toy._kernels.user import user; print(user())"
        environment = dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), *sys.path]), TOY_DROP=drop)
        environment.pop("NUMBA_CACHE_DIR", None)
        result = subprocess.run(
            [sys.executable, "-c", code], env=environment, capture_output=True, text=True, check=True
        )
        return int(result.stdout.split()[-1])

    assert run("1") == 1
    helper.write_text(helper.read_text().replace("return 1", "return 22"))
    assert run("0") == 1  # numba alone: stale
    assert run("1") == 22


def test_kernels_that_other_files_kernels_use_live_in_the_kernels_folder():
    # what keeps the check above to the _kernels files' time stamps
    outside = [
        f"{name} uses {callee.py_func.__module__}.{callee.py_func.__qualname__}"
        for kernel, name in package_kernels().items()
        for callee in kernels_reached(kernel)
        if callee.py_func.__module__ != kernel.py_func.__module__
        and not callee.py_func.__module__.startswith("terramesh._kernels.")
    ]
    assert outside == []
