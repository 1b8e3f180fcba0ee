"""Fixtures of the kernel tests."""

import contextlib

import numba
import pytest


@pytest.fixture
def one_thread():
    """A context in which numba's parallel kernels run on one thread (to compare with all of them)."""

    @contextlib.contextmanager
    def context():
        threads = numba.get_num_threads()
        numba.set_num_threads(1)
        try:
            yield
        finally:
            numba.set_num_threads(threads)

    return context
