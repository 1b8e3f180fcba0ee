"""``terramesh compile``: compile the kernels for this machine ahead of the first mesh."""

from .._kernels.precompile import compile_kernels, kernel_table
from ._options import whole_number_at_least_one

HELP = "compile terramesh's kernels for this machine now, in parallel (for images, clusters, before MPI jobs)"


def add_arguments(parser):
    """Declare the subcommand's arguments."""
    parser.add_argument(
        "--stages", nargs="+", choices=list(kernel_table()), help="only the kernels of these stages (default: all)"
    )
    parser.add_argument(
        "--processes",
        type=whole_number_at_least_one,
        metavar="N",
        help="worker processes, at least 1 (default: the CPU count)",
    )


def run(arguments):
    """Compile; returns 1 if a kernel failed to compile (it then compiles at its first use)."""
    report = compile_kernels(arguments.stages, arguments.processes)
    compiled = report["kernels"] - len(report["failed"])
    print(
        f"compiled {compiled} of {report['kernels']} kernels in {report['processes']} processes in "
        f"{report['seconds']:.0f} s"
    )
    for failure in report["failed"]:
        print(f"failed: {failure}")
    return 1 if report["failed"] else 0
