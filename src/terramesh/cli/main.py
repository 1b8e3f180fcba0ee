"""Entry point of the ``terramesh`` command."""

import argparse
import contextlib
import logging
import os
import sys
import warnings

from .. import __version__
from .._kernels.precompile import compile_ahead_on_first_run
from ..errors import TerrameshError
from . import coastal, demo, info, multiscale, post, precompile, seismic
from ._flags import in_flags
from ._options import mpi_rank
from ._parser import Parser

_SUBCOMMANDS = {
    "demo": demo,
    "info": info,
    "coastal": coastal,
    "multiscale": multiscale,
    "seismic": seismic,
    "post": post,
    "compile": precompile,
}
_FIRST_RUN_STAGES = {
    "demo": ["demo"],
    "coastal": ["coastal"],
    "multiscale": ["coastal"],
    "seismic": ["seismic"],
    "post": ["coastal"],
}  # what each meshing job uses


def _parser():
    """The ``terramesh`` parser; ``parser.commands`` holds each subcommand's own."""
    parser = Parser(  # the subcommands' parsers are of its class: an unknown option is named before all else
        prog="terramesh", description="Unstructured meshes for coastal-ocean and seismic models."
    )
    parser.add_argument("--version", action="version", version=f"terramesh {__version__}")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress messages on stderr")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    parser.commands = {}
    for name, module in _SUBCOMMANDS.items():
        sub = parser.commands[name] = commands.add_parser(name, help=module.HELP, description=module.HELP)
        # SUPPRESS: not given after the subcommand, the subparser leaves a -q given before it alone
        sub.add_argument(
            "-q", "--quiet", action="store_true", default=argparse.SUPPRESS, help="no progress messages on stderr"
        )
        module.add_arguments(sub)
    return parser


def main(argv=None):
    """Run the command line; returns the exit status (0 on success).

    Examples
    --------
    >>> main(["--version"])  # doctest: +SKIP
    terramesh 0.1.0
    """
    parser = _parser()
    arguments = parser.parse_args(argv)
    logger = logging.getLogger("terramesh")
    handler = None
    if not arguments.quiet:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("terramesh: %(message)s"))
        logger.addHandler(handler)
        logger.setLevel(logging.INFO)
    if arguments.command in _FIRST_RUN_STAGES:
        compile_ahead_on_first_run(_FIRST_RUN_STAGES[arguments.command], mpi=getattr(arguments, "mpi", False))
    # under --mpi every rank reads and sizes the same input: rank 0 says each warning once for all. Errors are
    # said by every rank that meets one: a rank's own (a file it alone cannot read) would be lost otherwise
    speaks = mpi_rank(getattr(arguments, "mpi", False)) == 0
    try:
        with _plain_warnings(arguments.command, parser.commands[arguments.command], shown=speaks):
            return _SUBCOMMANDS[arguments.command].run(arguments)
    except BrokenPipeError:
        # the reader went away (``terramesh info mesh.14 | head``): the rest of the output has nowhere to go,
        # and Python's flush at exit would fail on the same pipe again
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except (TerrameshError, OSError) as error:  # OSError: a missing file, a directory, no permission
        message = in_flags(str(error), parser.commands[arguments.command])
        print(f"terramesh {arguments.command}: error: {message}", file=sys.stderr)
        return 1
    finally:
        if handler is not None:
            logger.removeHandler(handler)


@contextlib.contextmanager
def _plain_warnings(command, parser, *, shown=True):
    """Show warnings as ``terramesh COMMAND: warning: ...`` lines, not as ``<frozen runpy>:88: TerrameshWarning: ...``.

    Only how a printed warning reads changes (the library's option names as
    the ``parser``'s flags, :func:`in_flags`), or, not ``shown`` (an MPI
    rank other than 0), that it is printed at all: the filters (``-W
    error`` raises on every rank), and code that records warnings
    (``pytest.warns``, ``catch_warnings(record=True)``), see them as before.
    """
    formatting, showing = warnings.formatwarning, warnings.showwarning

    def plain(message, category, filename, lineno, line=None):
        return f"terramesh {command}: warning: {in_flags(str(message), parser)}\n"

    warnings.formatwarning = plain
    if not shown:
        warnings.showwarning = lambda *args, **kwargs: None
    try:
        yield
    finally:
        warnings.formatwarning, warnings.showwarning = formatting, showing
