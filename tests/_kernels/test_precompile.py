"""Compiling ahead: the table of each stage's kernels, the worker processes, and what a stage leaves to compile."""

import importlib
import json
import os
import pathlib
import pkgutil
import subprocess
import sys
import textwrap

import numba
import pytest
from hypothesis import given
from hypothesis import strategies as st

from terramesh._kernels.precompile import (
    compiled_callees,
    kernel_table,
    next_task,
    parsed_types,
    spelled_types,
    stage_tasks,
)

ROOT = pathlib.Path(__file__).resolve().parents[2]
STAGES = ["generation", "demo", "coastal", "seismic", "generation-3d", "3d"]


def run_python(code, **environment):
    """Run ``code`` in a fresh interpreter; its last line of output, read as JSON."""
    output = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        env=dict(os.environ, **environment),
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(output.stdout.strip().splitlines()[-1])


def test_every_row_names_a_kernel_and_types_it_reads_back():
    table = kernel_table()
    assert list(table) == STAGES
    for rows in table.values():
        assert any(seconds is not None for *_, seconds in rows)
        for module, function, types, _ in rows:
            kernel = getattr(importlib.import_module(f"terramesh.{module}"), function)
            assert isinstance(kernel, numba.core.registry.CPUDispatcher)
            assert spelled_types(parsed_types(types)) == types


def test_no_kernel_is_both_called_from_python_and_compiled_within_another():
    # a kernel compiled on its own lands in the cache, and a caller compiled later in another
    # process links that object code: the Delaunay kernels then ran 18-30 % slower (no inlining
    # across it), and with its parallel scan so linked, restore_delaunay crashed (numba issues 4807,
    # 8578; parallel kernels are now called from Python only, see the next test). The workers
    # compile only kernels called from Python; a helper called from both would need a second
    # dispatcher for Python
    outermost, within = set(), set()
    for rows in kernel_table().values():
        for module, function, _, seconds in rows:
            (within if seconds is None else outermost).add((module, function))
    assert not outermost & within


def package_kernels():
    """Every numba kernel defined in terramesh, by its dispatcher."""
    import terramesh

    kernels = {}
    for info in pkgutil.walk_packages(terramesh.__path__, "terramesh."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if isinstance(value, numba.core.registry.CPUDispatcher) and value.py_func.__module__ == info.name:
                kernels[value] = f"{info.name}.{name}"
    return kernels


def test_no_kernel_calls_a_parallel_kernel():
    # numba starts its threads when a parallel kernel compiles or loads. A kernel that holds a parallel
    # callee cached by another process (the workers compile side by side) loads without them: "LLVM
    # ERROR: Symbol not found: allocate_sched" in a worker, and a segmentation fault at the first call
    # when it was the process's first parallel code (forces.short_edge_ends, which held
    # rest_length_scale). Parallel kernels are called from Python only
    kernels = package_kernels()
    assert len(kernels) > 100
    calls = [
        f"{name} calls {kernels.get(callee, callee.py_func.__qualname__)}"
        for kernel, name in kernels.items()
        for callee in compiled_callees(kernel)
        if callee.targetoptions.get("parallel")
    ]
    assert calls == []


def test_the_triangulation_and_its_repair_share_their_insertion_not_their_inlined_predicates():
    from terramesh._kernels import delaunay, expansions

    shared = compiled_callees(delaunay.triangulate) & compiled_callees(delaunay.restore_delaunay)
    assert {delaunay._insert, delaunay._locate, delaunay._incircle_exact} <= shared
    assert delaunay.orient not in shared  # inline="always": compiled into each caller, nothing to share
    assert compiled_callees(expansions.two_sum) == set()


def test_a_worker_takes_the_heaviest_task_that_shares_no_callee_with_those_being_compiled():
    pending = [("triangulate", {"_insert", "_locate"}), ("smooth", {"_star"}), ("classify", set())]
    assert next_task(pending, []) == 0
    assert next_task(pending, [{"_insert", "_remove"}]) == 1  # not the triangulation, while the repair compiles
    assert next_task(pending, [{"_insert"}, {"_star"}]) == 2
    assert next_task(pending[:2], [{"_insert"}, {"_star"}]) == 0  # all share: the heaviest, rather than wait


def test_tasks_list_each_compiled_kernel_once_slowest_first():
    table = kernel_table()
    tasks = stage_tasks()
    assert len(tasks) == len(set(tasks))
    outermost = {}  # the longest a kernel took in any stage's recording
    for rows in table.values():
        for module, function, types, seconds in rows:
            if seconds is not None:
                outermost[module, function, types] = max(seconds, outermost.get((module, function, types), 0.0))
    assert set(tasks) == set(outermost)
    assert [outermost[task] for task in tasks] == sorted(outermost.values(), reverse=True)
    demo = stage_tasks(["demo"])
    assert set(demo) < set(tasks) and ("_kernels.delaunay", "triangulate") in {task[:2] for task in demo}
    with pytest.raises(ValueError, match=r"unknown stage\(s\) \['meshing'\]"):
        stage_tasks(["meshing"])
    assert stage_tasks("demo") == demo  # one name: it was taken letter by letter, "unknown stage(s) ['d', 'e', ...]"


_DTYPES = [numba.types.float64, numba.types.float32, numba.types.int64, numba.types.int32, numba.types.uint64]
_SCALARS = st.sampled_from([*_DTYPES, numba.types.uint8, numba.types.boolean, numba.types.none])
_ARRAYS = st.builds(
    lambda dtype, ndim, layout, readonly: numba.types.Array(dtype, ndim, layout, readonly=readonly),
    st.sampled_from([*_DTYPES, numba.types.boolean]),
    st.integers(1, 4),
    st.sampled_from("CFA"),
    st.booleans(),
)
_TYPES = st.recursive(
    st.one_of(_SCALARS, _ARRAYS),
    lambda items: st.one_of(
        st.builds(numba.types.UniTuple, items, st.integers(1, 3)),
        st.builds(lambda members: numba.types.Tuple(members), st.lists(items, min_size=2, max_size=3)),
    ),
    max_leaves=4,
)


@given(st.lists(_TYPES, max_size=6))
def test_spelled_types_read_back(types):
    assert parsed_types(spelled_types(types)) == tuple(types)


def test_a_literal_constant_has_no_spelling():
    with pytest.raises(ValueError, match="no spelling for the numba type"):
        spelled_types([numba.types.IntegerLiteral(3)])


def test_workers_fill_an_empty_cache_that_a_later_process_loads(tmp_path):
    # three small kernels of the table and one row no worker can compile, in two processes
    report = run_python(
        """
        import json
        import terramesh._kernels.precompile as precompile
        rows = [row for row in precompile.kernel_table()["generation"]
                if row[1] in ("triangle_qualities", "count_far", "largest_interior_move")]
        assert len(rows) == 3
        rows.append(["_kernels.topology", "no_such_kernel", "int64", 9.0])
        precompile.kernel_table = lambda: {"small": rows}
        print(json.dumps(precompile.compile_kernels(["small"], processes=2)))
        """,
        NUMBA_CACHE_DIR=str(tmp_path),
    )
    assert report["kernels"] == 4 and report["processes"] == 2
    (failure,) = report["failed"]
    assert failure == (
        "_kernels.topology.no_such_kernel: AttributeError: module 'terramesh._kernels.topology' has no attribute "
        "'no_such_kernel'"
    )
    loaded = run_python(
        """
        import json
        import numpy as np
        from numba.core import event
        from terramesh._kernels import forces, topology
        compiled = []

        class Listener(event.Listener):
            def on_start(self, ev):
                compiled.append(ev.data["dispatcher"].py_func.__name__)

            def on_end(self, ev):
                pass

        event.register("numba:compile", Listener())
        points, cells = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), np.array([[0, 1, 2]])
        quality = topology.triangle_qualities(points, cells)
        forces.count_far(points, points + 0.5, np.ones(3), 0.1)
        print(json.dumps(dict(compiled=compiled, quality=float(quality[0]))))
        """,
        NUMBA_CACHE_DIR=str(tmp_path),
    )
    assert loaded["compiled"] == []  # loaded from what the workers left
    assert loaded["quality"] == pytest.approx(0.866, abs=1e-3)


def test_workers_that_stop_leave_their_kernels_reported(monkeypatch):
    # in this process: pytest fails a test that leaves a worker's pipe unclosed (an unraisable ResourceWarning)
    import terramesh._kernels.precompile as precompile

    rows = precompile.kernel_table()["generation"][:3]
    monkeypatch.setattr(precompile, "kernel_table", lambda: {"small": rows})
    monkeypatch.setattr(precompile, "WORKER", [sys.executable, "-c", "import sys; sys.stdin.readline()"])  # no answer
    report = precompile.compile_kernels(["small"], processes=2)
    assert report["kernels"] == 3
    reasons = sorted(failure.split(": ", 1)[1] for failure in report["failed"])
    assert reasons == ["not compiled, no worker left", "the worker stopped", "the worker stopped"]


def test_bad_requests_are_refused_by_name():
    from terramesh._kernels.precompile import compile_kernels

    with pytest.raises(ValueError, match="processes must be at least 1, got 0"):
        compile_kernels(["demo"], processes=0)
    with pytest.raises(ValueError, match=r"unknown stage\(s\) \['2d'\]: the stages are \['generation', 'demo'"):
        compile_kernels(["2d"])


def test_no_interpreter_no_workers(monkeypatch):
    import terramesh._kernels.precompile as precompile

    monkeypatch.setattr(precompile, "WORKER", ["", *precompile.WORKER[1:]])  # an embedded Python, say
    with pytest.raises(OSError, match="no Python interpreter to start worker processes with"):
        precompile.compile_kernels(["demo"])


# each stage's job, as the table was recorded from it (tools/record_kernel_signatures.py)
_RECORDER = importlib.util.spec_from_file_location("recorder", ROOT / "tools" / "record_kernel_signatures.py")


@pytest.mark.parametrize("stage", STAGES)
def test_a_stages_job_calls_only_kernels_its_row_lists(stage, shared_data, tmp_path):
    recorder = importlib.util.module_from_spec(_RECORDER)
    _RECORDER.loader.exec_module(recorder)
    used = run_python(
        f"""
        import json, pathlib, warnings
        import numpy as np
        warnings.simplefilter("ignore")
        import terramesh as tm
        from numba.core.registry import CPUDispatcher
        from terramesh._kernels.precompile import spelled_types
        data, scratch = pathlib.Path({str(shared_data)!r}), pathlib.Path({str(tmp_path)!r})
        exec({recorder.STAGES[stage]!r})
        import sys
        used = []
        for module in list(sys.modules.values()):
            for kernel in vars(module).values() if getattr(module, "__name__", "").startswith("terramesh.") else ():
                if isinstance(kernel, CPUDispatcher) and kernel.py_func.__module__ == module.__name__:
                    for types in kernel.signatures:
                        try:
                            used.append([module.__name__.removeprefix("terramesh."), kernel.py_func.__name__,
                                         spelled_types(types)])
                        except ValueError:  # a literal constant: compiled within another kernel, not called
                            pass
        print(json.dumps(used))
        """
    )
    listed = {tuple(row[:3]) for row in kernel_table()[stage]}
    assert used and {tuple(row) for row in used} <= listed  # else: run the recorder again
