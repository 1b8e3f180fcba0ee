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


def test_muted_warnings_mutes_the_words_given_and_nothing_else():
    import warnings

    import pytest

    # the words are literal text, not a pattern: "(k)" once read as a regex group
    with errors.muted_warnings("dropped (k) of them"):
        errors.warn_user("3 vertices dropped (k) of them")
        with pytest.warns(errors.TerrameshWarning, match="another"):
            errors.warn_user("another warning")
        with pytest.warns(UserWarning, match="dropped"):
            warnings.warn("dropped (k) of them, from elsewhere", UserWarning, stacklevel=1)  # another category
    with pytest.warns(errors.TerrameshWarning, match="dropped"):
        errors.warn_user("dropped (k) of them, after the block")


def test_every_muted_warning_is_raised_with_its_words():
    # each caller mutes a warning by the constant of the module that raises it, which the message must contain
    import ast
    import pathlib

    source = pathlib.Path(errors.__file__).parent
    constants = {}
    for path in source.rglob("*.py"):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant):
                for target in node.targets:
                    if isinstance(target, ast.Name) and target.id.isupper():
                        constants[target.id] = (path, node.value.value)
    muted = set()
    for path in source.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "muted_warnings":
                names = (name for arg in node.args for name in ast.walk(arg) if isinstance(name, ast.Name))
                muted |= {name.id for name in names if name.id.isupper()}
    assert {"REACHED_MAX_ITER", "SIZES_MISSED", "BREAK_COURANT", "SHORT_OF_THE_BBOX"} <= muted
    for name in muted:
        path, words = constants[name]
        text = path.read_text()
        assert "{" + name + "}" in text, f"{name} ({words!r}) is muted but no message of {path.name} uses it"


def test_a_warning_held_by_a_context_manager_points_at_the_users_line():
    # the coastal stages hold their warnings to give them again in longitude, latitude: they pointed at
    # contextlib.py:144, where the with block's exit gave them
    import pytest

    from terramesh.coastal.messages import lonlat_messages

    with pytest.warns(errors.TerrameshWarning) as caught:
        with lonlat_messages():
            errors.warn_user("held and given again")
    assert [warning.filename for warning in caught] == [__file__]
