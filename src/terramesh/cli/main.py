"""Entry point of the ``terramesh`` command."""

import argparse
import logging
import sys

from .. import __version__
from .._kernels import compiled_before
from ..errors import TerrameshError
from . import coastal, demo, info, seismic

_SUBCOMMANDS = {"demo": demo, "info": info, "coastal": coastal, "seismic": seismic}
_MESHING = ("demo", "coastal", "seismic")


def _parser():
    parser = argparse.ArgumentParser(
        prog="terramesh", description="Unstructured meshes for coastal-ocean and seismic models."
    )
    parser.add_argument("--version", action="version", version=f"terramesh {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module in _SUBCOMMANDS.items():
        sub = commands.add_parser(name, help=module.HELP, description=module.HELP)
        sub.add_argument("-q", "--quiet", action="store_true", help="no progress messages on stderr")
        module.add_arguments(sub)
    return parser


def main(argv=None):
    """Run the command line; returns the exit status (0 on success).

    Examples
    --------
    >>> main(["--version"])  # doctest: +SKIP
    terramesh 0.1.0
    """
    arguments = _parser().parse_args(argv)
    logger = logging.getLogger("terramesh")
    handler = None
    if not arguments.quiet:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("terramesh: %(message)s"))
        logger.addHandler(handler)
        logger.setLevel(logging.INFO)
        if arguments.command in _MESHING and not compiled_before():
            logger.info(
                "first run of this installation: compiling the kernels for this machine (a minute or two, once)"
            )
    try:
        return _SUBCOMMANDS[arguments.command].run(arguments)
    except (TerrameshError, OSError) as error:  # OSError: a missing file, a directory, no permission
        print(f"terramesh {arguments.command}: error: {error}", file=sys.stderr)
        return 1
    finally:
        if handler is not None:
            logger.removeHandler(handler)
