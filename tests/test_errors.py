"""The error hierarchy: what ``except`` clauses written against plain Python conventions catch."""

import terramesh.errors as errors


def test_every_specific_error_is_a_value_error():
    """Errors of bad input (including a bad mesh or a bad option to a mesh operation) are ValueErrors too."""
    specific = [getattr(errors, name) for name in errors.__all__ if name not in ("TerrameshError", "TerrameshWarning")]
    assert specific
    for error in specific:
        assert issubclass(error, errors.TerrameshError) and issubclass(error, ValueError), error.__name__
