"""The error hierarchy: what ``except`` clauses written against plain Python conventions catch."""

import terramesh.errors as errors


def test_every_specific_error_is_a_value_error():
    """Errors of bad input (including a bad mesh or a bad option to a mesh operation) are ValueErrors too."""
    specific = [getattr(errors, name) for name in errors.__all__ if name not in ("TerrameshError", "TerrameshWarning")]
    assert specific
    for error in specific:
        assert issubclass(error, errors.TerrameshError) and issubclass(error, ValueError), error.__name__


def test_checked_number_takes_numbers_only():
    import numpy as np
    import pytest

    assert errors.checked_number(np.float32(0.5), "x must be a number", errors.SizingError) == 0.5
    assert errors.checked_number(np.array(3), "x must be a number", errors.SizingError) == 3.0
    assert errors.checked_number("0.1", "x must be a number", errors.SizingError) == 0.1  # the command line's text
    # float() reads the flags as 1 and 0; none of these is a number an option means
    for value in [True, np.bool_(False), None, "nan", "ten", [1.0]]:
        with pytest.raises(errors.SizingError, match=r"x must be a number, got"):
            errors.checked_number(value, "x must be a number", errors.SizingError)
    with pytest.raises(errors.SizingError, match=r"at least 1"):
        errors.checked_number(0.5, "x must be at least 1", errors.SizingError, minimum=1)
