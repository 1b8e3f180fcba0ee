"""The library's option names in an error message, as the command line's flags."""

import re

from ..coastal.build import ALIASES as COASTAL_ALIASES
from ..seismic.sizing import ALIASES as SEISMIC_ALIASES

# a Python option name with the value given with it ("units='m/s'", "coarsen_pad=False"), or alone where
# it is words joined by underscores ("min_edge_length"): a plain word alone is English as often as not; never
# in a path or a file's name ("missing/old_model.npy" and "velocity_window/model.npy" are the user's)
_GIVEN = re.compile(r"(?<![-\w/.'\"])([a-z][a-z0-9]*(?:_[a-z0-9]+)*)=('[^']*'|\"[^\"]*\"|[^\s,;:)]+)")
_SAID_TWICE = re.compile(r" \([^()]* on the command line\)")
_NAMED = re.compile(r"(?<![-\w/.'\"])([a-z][a-z0-9]*(?:_[a-z0-9]+)+)(?![-\w/.'\"])")


def in_flags(message, parser):
    """``message`` with the library's option names that ``parser`` takes as flags written as those flags.

    The size functions name their options as Python does (``min_edge_length
    2000 exceeds max_edge_length 1000``, ``pass units='m/s'``); on the
    command line they are ``--min-el`` and ``--units m/s``. Names of words
    joined by underscores are rewritten, each to the flag of its own name or
    of its guide's short name (:data:`terramesh.coastal.ALIASES`).

    Examples
    --------
    >>> import argparse
    >>> parser = argparse.ArgumentParser()
    >>> _ = parser.add_argument("--min-el"), parser.add_argument("--units")
    >>> _ = parser.add_argument("--no-coarsen-pad", dest="coarsen_pad", action="store_false")
    >>> in_flags("min_edge_length 2000 exceeds max_edge_length 1000", parser)
    '--min-el 2000 exceeds max_edge_length 1000'
    >>> in_flags("pass units='m/s', or leave coarsen_pad=False out", parser)
    'pass --units m/s, or leave --no-coarsen-pad out'
    >>> in_flags("read it with units='km/s' (read_velocity; --units km/s on the command line)", parser)
    'read it with --units km/s'
    >>> in_flags("no such file: 'models/min_el.npy', min_el_run/a.npy", parser)
    "no such file: 'models/min_el.npy', min_el_run/a.npy"
    """
    flags, negated = {}, set()
    for action in parser._actions:
        flag = next((option for option in action.option_strings if option.startswith("--")), None)
        if flag is None or action.dest in flags:
            continue
        flags[action.dest] = flag
        if action.const is False:  # store_false: the flag says False
            negated.add(action.dest)
    for aliases in (COASTAL_ALIASES, SEISMIC_ALIASES):
        for short, long in aliases.items():
            if short in flags and long not in flags:
                flags[long] = flags[short]

    def given(match):
        name, value = match.groups()
        if name not in flags:
            return match.group(0)
        if name in negated and value == "False":
            return flags[name]
        return f"{flags[name]} {value.strip(chr(39) + chr(34))}"

    def named(match):
        return flags.get(match.group(1), match.group(0))

    # "with axis_order (--axis-order on the command line)": now said in the flags themselves
    return _SAID_TWICE.sub("", _NAMED.sub(named, _GIVEN.sub(given, message)))
