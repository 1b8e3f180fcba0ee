"""Compile the kernels ahead of their first use, in parallel processes.

numba compiles a kernel at its first call, one at a time (its compiler holds
a lock), and caches it on disk. A fresh installation's first mesh therefore
waits for every kernel it meets in turn (the demo: 80 s of compiling on 2
cores). The kernels each stage uses, with their argument types, are listed
in ``signatures.json`` (written by ``tools/record_kernel_signatures.py``);
here worker processes compile them side by side into the same on-disk
cache, heaviest first, but not two that share callees at the same time
(:func:`next_task`), and the job then loads them (the meshing jobs ask
for it first, :func:`compile_ahead_on_first_run`). A kernel missing from
the table, or one a worker fails on, still compiles at its first call: the
table only saves time (so does a race in numba's index of a kernel's cached
types, when two workers add types of one kernel at the same moment).

A worker (:func:`serve`) reads lines ``[module, function, types]`` (JSON)
on its standard input and answers each with ``ok`` or ``failed: REASON``
on its standard output.
"""

import contextlib
import functools
import importlib
import json
import logging
import os
import subprocess
import sys
import threading
import time
from importlib import resources
from types import CodeType

import numba

from . import compiled_before

logger = logging.getLogger("terramesh.kernels")

PROGRESS_EVERY = 10.0  # seconds between progress messages
# the command of a worker process (not ``-m``: runpy warns when the package has imported the module already)
WORKER = [sys.executable, "-c", f"from {__name__} import serve; serve()"]


def spelled_types(types):
    """Argument types as text that :func:`parsed_types` reads back, e.g. ``"Array(float64, 2, 'C'), int64"``."""
    return ", ".join(_spelled(t) for t in types)


def _spelled(t):
    if isinstance(t, numba.types.Array):
        readonly = ", readonly=True" if not t.mutable else ""
        return f"Array({_spelled(t.dtype)}, {t.ndim}, {t.layout!r}{readonly})"
    if isinstance(t, numba.types.UniTuple):
        return f"UniTuple({_spelled(t.dtype)}, {t.count})"
    if isinstance(t, numba.types.Tuple):
        return "Tuple((" + "".join(_spelled(item) + ", " for item in t.types) + "))"
    if isinstance(t, numba.types.Boolean):
        return "boolean"
    if isinstance(t, numba.types.Number | numba.types.NoneType) and not isinstance(t, numba.types.Literal):
        return str(t)
    raise ValueError(f"no spelling for the numba type {t!r}")


def parsed_types(text):
    """The tuple of numba types :func:`spelled_types` wrote as ``text``."""
    if not text:
        return ()
    return eval(f"({text},)", {"__builtins__": {}}, vars(numba.types))  # the table's own text, not user input


@functools.cache
def kernel_table():
    """Each stage's kernels: ``{stage: [[module, function, argument types, seconds], ...]}``.

    Seconds are None for a kernel compiled within another of the stage:
    compiling that one caches it too.
    """
    return json.loads(resources.files(__package__).joinpath("signatures.json").read_text())["stages"]


def stage_tasks(stages=None):
    """The kernels ``stages`` use (all by default), each once, as ``(module, function, types)``, slowest first."""
    table = kernel_table()
    if isinstance(stages, str):  # one stage by its name: list() took it letter by letter
        stages = [stages]
    stages = list(table) if stages is None else list(stages)
    unknown = sorted(set(stages) - set(table))
    if unknown:
        raise ValueError(f"unknown stage(s) {unknown}: the stages are {list(table)}")
    seconds = {}
    for stage in stages:
        for module, function, types, time_taken in table[stage]:
            if time_taken is not None:  # None: compiled (and cached) within another of the stage's kernels
                key = (module, function, types)
                seconds[key] = max(seconds.get(key, 0.0), time_taken)
    return sorted(seconds, key=lambda key: -seconds[key])


def _kernel(module, function):
    return getattr(importlib.import_module(f"terramesh.{module}"), function)


def _names(code):
    """The global names ``code`` (and the functions defined in it) refer to."""
    yield from code.co_names
    for constant in code.co_consts:
        if isinstance(constant, CodeType):
            yield from _names(constant)


def compiled_callees(kernel):
    """The kernels compiled (and cached) on their own when ``kernel`` compiles: what it calls, at any depth.

    Callees inlined into their callers (``inline="always"``) are not among
    them, but what they call is.
    """
    return {callee for callee in kernels_reached(kernel) if callee.targetoptions.get("inline", "never") != "always"}


def kernels_reached(kernel):
    """The kernels that ``kernel`` calls or inlines, at any depth (by the global names its code reads)."""
    found, stack = set(), [kernel]
    while stack:
        caller = stack.pop()
        for name in _names(caller.py_func.__code__):
            callee = caller.py_func.__globals__.get(name)
            if isinstance(callee, numba.core.registry.CPUDispatcher) and callee is not caller and callee not in found:
                found.add(callee)
                stack.append(callee)
    return found


def _callee_names(module, function):
    try:
        kernel = _kernel(module, function)
    except (ImportError, AttributeError):  # the worker reports it
        return frozenset()
    return frozenset(callee.py_func.__qualname__ for callee in compiled_callees(kernel))


def next_task(pending, running):
    """Index in ``pending`` (each ``(task, callees)``) of the task to compile next, beside ``running`` (callee sets).

    The first (heaviest) that shares no callee with a task being compiled:
    two workers compiling the same callee do the work twice (the Delaunay
    repair and the triangulation share 8 s of insertion code, which the
    later of the two then loads from the cache); the first where all do.
    """
    busy = set().union(*running)
    return next((i for i, (_, callees) in enumerate(pending) if not callees & busy), 0)


def compile_kernel(module, function, types):
    """Compile (or load from the cache) ``terramesh.<module>.<function>`` for the argument ``types`` (text)."""
    _kernel(module, function).compile(parsed_types(types))


def compile_kernels(stages=None, processes=None):
    """Compile terramesh's kernels for this machine now, in parallel, so that later runs start at once.

    numba compiles each kernel at its first call and caches it beside the
    installed package (or in ``NUMBA_CACHE_DIR``). Here ``processes``
    worker processes (the CPU count by default) compile them side by side
    into that cache; the kernels already there only load. Useful after
    installing into an image or on a cluster's shared file system, before
    many processes (MPI ranks) would each compile the same kernels. Progress
    goes to the ``terramesh`` logger; the outcome is the returned report.

    Parameters
    ----------
    stages : str or list of str, optional
        Which kernels: ``"generation"`` (2D meshing), ``"demo"`` (the
        bundled example), ``"coastal"`` (with a DEM and the solver
        files), ``"seismic"``, ``"generation-3d"`` (3D meshing), ``"3d"``
        (a 3D seismic model's mesh and files); all by default.
    processes : int, optional
        Worker processes; the CPU count by default.

    Returns
    -------
    dict
        ``kernels`` (how many were asked for), ``failed``
        (``"module.function: reason"`` for each kernel not compiled; it
        compiles at its first use instead), ``processes`` and ``seconds``.

    Raises
    ------
    ValueError
        For an unknown stage or fewer than one process.
    OSError
        Where no worker process can start.

    Examples
    --------
    >>> import terramesh as tm
    >>> report = tm.compile_kernels(["generation"])  # doctest: +SKIP
    >>> report["failed"]  # doctest: +SKIP
    []
    """
    if processes is not None and int(processes) < 1:
        raise ValueError(f"processes must be at least 1, got {processes}")
    tasks = stage_tasks(stages)
    if not WORKER[0]:
        raise OSError("no Python interpreter to start worker processes with (sys.executable is empty)")
    processes = max(1, min(int(processes or os.cpu_count() or 1), len(tasks)))  # no idle workers
    started = time.perf_counter()
    pending = [(task, _callee_names(*task[:2])) for task in tasks]
    running, done, failed, lock = {}, [0], [], threading.Lock()

    def feed(worker):
        try:
            while True:
                with lock:
                    if not pending:
                        return
                    task, running[worker.pid] = pending.pop(next_task(pending, running.values()))
                try:
                    worker.stdin.write(json.dumps(task) + "\n")
                    worker.stdin.flush()
                    answer = worker.stdout.readline().strip()
                except OSError:  # the worker is gone
                    answer = ""
                with lock:
                    del running[worker.pid]
                    done[0] += 1
                    if answer != "ok":
                        failed.append(f"{task[0]}.{task[1]}: {answer.removeprefix('failed: ') or 'the worker stopped'}")
                if not answer:
                    return  # the other workers take the rest
        finally:
            with contextlib.suppress(OSError):
                worker.stdin.close()

    with contextlib.ExitStack() as stack:  # on leaving, each worker's pipes close and it is waited for
        workers = [
            stack.enter_context(subprocess.Popen(WORKER, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True))
            for _ in range(processes)
        ]
        threads = [threading.Thread(target=feed, args=(worker,), daemon=True) for worker in workers]
        for thread in threads:
            thread.start()
        logger.info("compiling %d kernels in %d processes", len(tasks), processes)
        last = started
        while any(thread.is_alive() for thread in threads):
            for thread in threads:
                thread.join(timeout=0.5)
            if time.perf_counter() - last > PROGRESS_EVERY:
                last = time.perf_counter()
                logger.info("compiled %d of %d kernels (%.0f s)", done[0], len(tasks), last - started)
    for (module, function, _types), _callees in pending:  # every worker stopped before these
        failed.append(f"{module}.{function}: not compiled, no worker left")
    return dict(kernels=len(tasks), failed=failed, processes=processes, seconds=time.perf_counter() - started)


MPIEXEC_VARIABLES = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "MPI_LOCALNRANKS", "PMIX_SIZE")
"""What MPICH's, Open MPI's and PMIx's launchers tell each process of how many they started."""


def processes_started_by_mpiexec():
    """How many processes the MPI launcher that started this one started (1 without a launcher)."""
    return next((int(os.environ[name]) for name in MPIEXEC_VARIABLES if os.environ.get(name, "").isdigit()), 1)


_ahead = {"tried": False}  # compiling ahead is a fresh installation's first job's, once a process


def compile_ahead_on_first_run(stages, *, mpi=False):
    """On a fresh installation, compile the kernels of ``stages`` side by side before the job meets them one by one.

    The meshing jobs (the command line's, :func:`terramesh.generate_mesh`,
    :func:`terramesh.adapt_mesh`, :func:`terramesh.coastal.build`, the size
    functions, ...) call it first: with an empty cache a job otherwise
    compiles each kernel at its first call, one at a time (the OceanMesh2D
    guide's §5.3 example took 187 s so on 2 cores, 136 s compiling ahead).
    Only a process's first job looks: nothing is done where the cache holds
    the stages' heaviest kernel, or under ``mpi`` or in one of several
    processes started by mpiexec, where each rank would start its own
    workers (``terramesh compile`` first). Progress goes to the
    ``terramesh`` logger; where no worker can start, the kernels compile
    as they are used.

    Parameters
    ----------
    stages : list of str
        The stages of :func:`compile_kernels` the job uses.
    mpi : bool, optional
        Whether the job runs on MPI ranks.

    Returns
    -------
    dict or None
        The report of :func:`compile_kernels`, or None where nothing was compiled ahead.
    """
    if _ahead["tried"]:
        return None
    _ahead["tried"] = True
    tasks = stage_tasks(stages)
    if not tasks or compiled_before(_kernel(*tasks[0][:2])):
        return None
    if mpi or processes_started_by_mpiexec() > 1:
        logger.info("first run of this installation: each rank compiles the kernels (`terramesh compile` first)")
        return None
    logger.info("first run of this installation: compiling the kernels for this machine (a minute or so, once)")
    try:
        report = compile_kernels(stages)
    except OSError as error:  # no worker process could start: the kernels compile as they are used
        logger.warning("could not compile ahead (%s): compiling as the kernels are used", error)
        return None
    logger.info("compiled %d kernels in %.0f s", report["kernels"] - len(report["failed"]), report["seconds"])
    if report["failed"]:
        logger.warning("%d kernels did not compile ahead; they compile as they are used", len(report["failed"]))
    return report


def serve():
    """Be a worker: compile the kernels named on standard input, one answer line each."""
    for line in sys.stdin:
        try:
            compile_kernel(*json.loads(line))
            answer = "ok"
        except Exception as error:  # reported to the parent, which lets the kernel compile at first use
            answer = "failed: " + " ".join(f"{type(error).__name__}: {error}".split())
        print(answer, flush=True)
