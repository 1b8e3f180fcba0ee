"""Argument types and output checks shared by the subcommands, all made before any work.

The types raise :class:`argparse.ArgumentTypeError`, so argparse names the
flag: ``argument --dj-cutoff: a fraction between 0 and 1, got '2'``.
"""

import argparse
import os

from .._kernels.precompile import processes_started_by_mpiexec
from ..errors import TerrameshError, checked_number, warn_user

__all__ = [
    "finite_number",
    "positive_number",
    "non_negative_number",
    "fraction",
    "time_step",
    "whole_number_at_least_one",
    "check_output_folder",
    "check_output_file",
]


def finite_number(text):
    """A finite number, of any sign."""
    return checked_number(text, "a finite number", argparse.ArgumentTypeError)


def positive_number(text):
    """A finite number above 0."""
    return checked_number(text, "a number above 0", argparse.ArgumentTypeError, minimum=0.0, strict=True)


def non_negative_number(text):
    """A finite number of at least 0."""
    return checked_number(text, "a number of at least 0", argparse.ArgumentTypeError, minimum=0.0)


def fraction(text):
    """A number in [0, 1]."""
    number = checked_number(text, "a fraction between 0 and 1", argparse.ArgumentTypeError, minimum=0.0)
    if number > 1:
        raise argparse.ArgumentTypeError(f"a fraction between 0 and 1, got {text!r}")
    return number


def time_step(text):
    """A time step in seconds, finite, of at least 0: 0 asks for one to be chosen."""
    return checked_number(text, "a time step of at least 0 s (0 chooses one)", argparse.ArgumentTypeError, minimum=0.0)


def whole_number_at_least_one(text):
    """A whole number of at least 1."""
    try:
        number = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a whole number of at least 1, got {text!r}") from None
    if number < 1:
        raise argparse.ArgumentTypeError(f"a whole number of at least 1, got {number}")
    return number


def check_output_folder(folder, flag):
    """Raise OSError, naming ``flag``, unless ``folder`` is a writable folder or one that can be created there.

    Nothing is created: the folder is made when the results are written, so a
    command refused later (bad input) leaves no empty folder behind.
    """
    folder = os.path.abspath(os.fspath(folder))
    existing = folder
    while not os.path.exists(existing):
        existing = os.path.dirname(existing)
    if not os.path.isdir(existing):
        beyond = "" if existing == folder else f": cannot make {folder!r} in it"
        raise NotADirectoryError(f"{flag}: {existing!r} is a file, not a folder{beyond}")
    if not os.access(existing, os.W_OK | os.X_OK):
        what = "write into" if existing == folder else f"create {folder!r} in"
        raise PermissionError(f"{flag}: no permission to {what} the folder {existing!r}")


def check_output_file(path, flag):
    """Raise OSError, naming ``flag``, unless a file can be written at ``path`` (its folder made if missing)."""
    if os.path.isdir(path):
        raise IsADirectoryError(f"{flag}: {os.fspath(path)!r} is a folder; give a file name")
    if os.path.exists(path) and not os.access(path, os.W_OK):
        raise PermissionError(f"{flag}: no permission to overwrite {os.fspath(path)!r}")
    check_output_folder(os.path.dirname(os.path.abspath(os.fspath(path))), flag)


def mpi_world(mpi):
    """``--mpi``'s ``MPI.COMM_WORLD``, None without ``--mpi``; refused without mpi4py, warned of in one process.

    Run without ``mpiexec``, ``--mpi`` meshed the parts one after another in
    the one process, without a word; and without mpi4py it was Python's
    ModuleNotFoundError.
    """
    if not mpi:
        return None
    try:
        from mpi4py import MPI
    except ImportError:
        raise TerrameshError("--mpi needs mpi4py and an MPI library: pip install 'terramesh[mpi]'") from None
    comm = MPI.COMM_WORLD
    if comm.Get_size() == 1:
        warn_user(
            "--mpi in a single process: its parts are meshed here one after another; start the command with "
            "mpiexec -n N to share them among N processes"
        )
    return comm


def mpi_rank(mpi):
    """The process's rank in the MPI job of ``--mpi``: 0 without ``--mpi``, or without mpi4py (the command says so)."""
    if not mpi:
        return 0
    try:
        from mpi4py import MPI
    except ImportError:
        return 0
    return MPI.COMM_WORLD.Get_rank()


def check_launched_with_mpi(mpi):
    """Warn of a job started by mpiexec in several processes without ``--mpi``: each does it all, and writes.

    The launcher's environment says how many it started; MPI itself is not
    started here. A warning, not an error: a driver started by mpiexec may
    run the command in its own processes (one box per rank), which inherit
    that environment; and the files are written whole under a temporary
    name, so the copies do not corrupt one another.
    """
    launched = processes_started_by_mpiexec()
    if launched > 1 and not mpi:
        warn_user(
            f"this is one of {launched} processes started by mpiexec, but without --mpi each meshes the whole job "
            "and writes the file: add --mpi to share the strips, or run it without mpiexec"
        )
