"""Numba's on-disk caches of kernels built on other files' kernels, dropped when those files change.

Numba keys a cached kernel on its own file's time stamp and size alone. A
kernel that inlines or calls a kernel of another file, or reads another
file's constant, keeps the machine code of that file's old version when
only that file changes: after an edit of ``smoothing.star_corners``,
``cleanup.smooth_vertices`` ran the old one until its cache was deleted.
A new installation rewrites every file and so renews every cache; a
``git pull`` into an editable installation rewrites only the changed files.

At import the package compares the time stamps and sizes of the
``_kernels`` files with those recorded in their cache folder (about 0.3
ms); where one changed, it deletes the caches of every module that
imports it, directly or through other kernel files, and records the new
stamps. Should numba's internals differ from those read here, or the
cache folder be read-only, nothing is done.
"""

import ast
import json
import os
import tempfile

STAMPS = "terramesh-kernel-sources.json"
"""File in the ``_kernels`` cache folder: each kernel file's ``[mtime_ns, size]`` at the last check."""


def drop_stale_caches(kernels=None, package=None, cache_folder=None):
    """Delete the cached kernels of modules that import a kernel file changed since the last check.

    Parameters
    ----------
    kernels : str, optional
        The folder of the kernel files (default: this one).
    package : str, optional
        The package's root folder, whose modules may import the kernel
        files (default: this folder's parent).
    cache_folder : callable, optional
        Maps a source file's path to the folder numba caches its kernels in
        (default: numba's own rule, :func:`numba_cache_folder`).

    Returns
    -------
    list of str
        The deleted cache files, sorted.

    Examples
    --------
    >>> drop_stale_caches()  # right after the import did the same
    []
    """
    kernels = kernels or os.path.dirname(os.path.abspath(__file__))
    package = package or os.path.dirname(kernels)
    cache_folder = cache_folder or numba_cache_folder
    try:
        stamps = _stamps(kernels)
        record = os.path.join(cache_folder(os.path.join(kernels, "__init__.py")), STAMPS)
        try:
            with open(record) as file:
                recorded = json.load(file)
        except (FileNotFoundError, ValueError):
            recorded = {}  # no record: any cache there may be stale
        except OSError:
            return []  # another user's record in a shared installation: theirs to keep
        changed = {name for name in stamps.keys() | recorded.keys() if stamps.get(name) != recorded.get(name)}
        if not changed:
            return []
        deleted = []
        for path in _importers(kernels, package, {name[: -len(".py")] for name in changed}):
            # numba's rule needs the file; a kernel file removed (a pull) has its folder's, which is the same
            source = path if os.path.exists(path) else os.path.join(kernels, "__init__.py")
            deleted += _delete_caches(path, cache_folder(source))
        _write_atomically(record, json.dumps(stamps, sort_keys=True))
        return sorted(deleted)
    except (OSError, ValueError, SyntaxError, ImportError, AttributeError, TypeError, RuntimeError):
        return []


def numba_cache_folder(path):
    """The folder numba caches the kernels of source file ``path`` in (its locators' rule; they create it)."""
    from numba.core.caching import CompileResultCacheImpl

    namespace = {}
    exec(compile("def stand_in():\n    pass\n", path, "exec"), namespace)
    return CompileResultCacheImpl(namespace["stand_in"])._locator.get_cache_path()


def _stamps(kernels):
    """``{file name: [mtime_ns, size]}`` of the kernel files."""
    stamps = {}
    for entry in os.scandir(kernels):
        if entry.name.endswith(".py"):
            status = entry.stat()
            stamps[entry.name] = [status.st_mtime_ns, status.st_size]
    return stamps


def _importers(kernels, package, changed):
    """Paths of the kernel files ``changed`` (module names) and of every module that imports one, at any depth."""
    package_name = os.path.basename(package)
    kernels_name = ".".join([package_name, *os.path.relpath(kernels, package).split(os.sep)])
    imports = {}
    for folder, subfolders, names in os.walk(package):
        subfolders[:] = [name for name in subfolders if name != "__pycache__"]
        for name in names:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8") as file:
                    source = file.read()
                if "_kernels" in source or folder == kernels:
                    imports[path] = _kernel_modules_imported(source, path, package, kernels_name)
    stale = set(changed)
    grown = True
    while grown:  # a kernel file that imports a stale one is stale too
        grown = False
        for path, modules in imports.items():
            module = os.path.splitext(os.path.basename(path))[0]
            if os.path.dirname(path) == kernels and module not in stale and modules & stale:
                stale.add(module)
                grown = True
    found = {os.path.join(kernels, module + ".py") for module in stale}
    return sorted(found | {path for path, modules in imports.items() if modules & stale})


def _kernel_modules_imported(source, path, package, kernels_name):
    """Names of the kernel modules that ``source`` (of ``path``) imports, relatively or absolutely."""
    parts = [os.path.basename(package), *os.path.relpath(os.path.dirname(path), package).split(os.sep)]
    parts = [part for part in parts if part != "."]
    modules = set()
    for node in ast.walk(ast.parse(source, path)):
        if isinstance(node, ast.ImportFrom):
            base = parts[: len(parts) - node.level + 1] if node.level else []
            full = ".".join(base + ([node.module] if node.module else []))
            if full == kernels_name:
                modules |= {alias.name for alias in node.names}
            elif full.startswith(kernels_name + "."):
                modules.add(full[len(kernels_name) + 1 :].split(".")[0])
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith(kernels_name + "."):
                    modules.add(alias.name[len(kernels_name) + 1 :].split(".")[0])
    return modules


def _delete_caches(path, folder):
    """Delete numba's index and data files of ``path``'s kernels in ``folder``; their paths."""
    prefix = os.path.splitext(os.path.basename(path))[0] + "."
    deleted = []
    try:
        entries = list(os.scandir(folder))
    except FileNotFoundError:
        return deleted
    for entry in entries:
        if entry.name.startswith(prefix) and entry.name.endswith((".nbi", ".nbc")):
            try:
                os.remove(entry.path)
                deleted.append(entry.path)
            except FileNotFoundError:  # another process (an MPI rank) deleted it first
                pass
    return deleted


def _write_atomically(path, text):
    """Write ``text`` to ``path`` by renaming a finished file over it, so that no reader sees half of it."""
    handle, temporary = tempfile.mkstemp(dir=os.path.dirname(path), suffix=".tmp")
    try:
        with os.fdopen(handle, "w") as file:
            file.write(text)
        os.chmod(temporary, 0o644)  # mkstemp's 0600 would leave the record unreadable to the other users
        os.replace(temporary, path)
    except BaseException:
        os.unlink(temporary)
        raise
