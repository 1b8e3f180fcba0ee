"""Compiled (numba) kernels.

Private: every function takes contiguous arrays of the documented dtype and
does no validation; the public wrappers elsewhere in the package do that.
"""
