"""The library's option names in an error message, as the command line's flags."""

import re

from ..coastal.build import ALIASES as COASTAL_ALIASES
from ..seismic.sizing import ALIASES as SEISMIC_ALIASES

# a Python option name with the value given with it ("units='m/s'", "coarsen_pad=False"), or bare in a list
# ("give them (sources=, receivers=)"), or alone where it is words joined by underscores ("min_edge_length"): a
# plain word alone is English as often as not; never in a path or a file's name ("missing/old_model.npy" and
# "velocity_window/model.npy" are the user's)
_GIVEN = re.compile(
    r"(?<![-\w/\\.'\"])([a-z][a-z0-9]*(?:_[a-z0-9]+)*)=(?:(\([^()]*\)|'[^']*'|\"[^\"]*\"|[^\s,;:)]+)|(?=[,)]))"
)
_SAID_TWICE = re.compile(r" \([^()]* on the command line\)")
_NAMED = re.compile(r"(?<![-\w/\\.'\"])([a-z][a-z0-9]*(?:_[a-z0-9]+)+)(?![-\w/\\.'\"])")
# "filter_lengths (fl)": a long name with the guide's short one, the same flag
_WITH_SHORT = re.compile(r"(?<![-\w/\\.'\"])([a-z][a-z0-9_]*) \(([a-z][a-z0-9_]*)\)")
# a word that a message opens with and says something of ("grade must be ...", "thalwegs are ..."): the subject
# of a check, an option's name however plain; words inside the message are left alone
_SUBJECT = re.compile(r"^([a-z][a-z0-9_]*)(?= (?:must|are) )")
_WORD = re.compile(r"(?<![-\w/\\.'\"])([a-z][a-z0-9]+)(?![-\w/\\.'\"])")

# Switches that say one thing both ways: geographic=False is --planar, and geographic=True, where a command
# has no --geographic, is leaving --planar out
_OPPOSITES = {"geographic": "planar", "planar": "geographic"}

# The size functions' own names for options that build passes them under another name (fs as
# shoreline_size's elements_per_feature): their checks name these
_PASSED_AS = {
    "rate": "distance_rate",
    "elements_per_feature": "feature_size",
    "elements_per_wavelength": "wavelength",
    "elements_per_slope": "slope",
    "percentile": "channels",
}


def in_flags(message, parser):
    """``message`` with the library's option names that ``parser`` takes as flags written as those flags.

    The size functions name their options as Python does (``min_edge_length
    2000 exceeds max_edge_length 1000``, ``pass units='m/s'``,
    ``elements_per_feature must be ...``); on the command line they are
    ``--min-el``, ``--units m/s`` and ``--fs``. Rewritten are: names of
    words joined by underscores, each to the flag of its own name, of its
    guide's short name (:data:`terramesh.coastal.ALIASES`) or of the option
    build passes on under it (``elements_per_feature``: ``fs``); a name with
    ``=``; a name that opens the message as the subject of a check
    (``grade must be``, ``thalwegs are``); a long name followed by its short
    one in brackets (``slope (slp)``); and the guide's short names of more
    than one letter (``dis``, ``fs``). Plain words elsewhere are English as
    often as not, and stay.

    Examples
    --------
    >>> import argparse
    >>> parser = argparse.ArgumentParser()
    >>> _ = parser.add_argument("--min-el"), parser.add_argument("--units")
    >>> _ = parser.add_argument("--no-coarsen-pad", dest="coarsen_pad", action="store_false")
    >>> _ = parser.add_argument("--g"), parser.add_argument("--slp"), parser.add_argument("--fs")
    >>> in_flags("min_edge_length 2000 exceeds max_edge_length 1000", parser)
    '--min-el 2000 exceeds max_edge_length 1000'
    >>> in_flags("pass units='m/s', or leave coarsen_pad=False out", parser)
    'pass --units m/s, or leave --no-coarsen-pad out'
    >>> in_flags("read it with units='km/s' (read_velocity; --units km/s on the command line)", parser)
    'read it with --units km/s'
    >>> in_flags("no such file: 'models/min_el.npy', min_el_run/a.npy", parser)
    "no such file: 'models/min_el.npy', min_el_run/a.npy"
    >>> in_flags("grade must be a positive number, got 0.0; the grade limits growth", parser)
    '--g must be a positive number, got 0.0; the grade limits growth'
    >>> in_flags("elements_per_feature must be positive: give slope (slp), or fs", parser)
    '--fs must be positive: give --slp, or --fs'
    >>> _ = parser.add_argument("--line-bytes", nargs=2)
    >>> in_flags("pass line_bytes=(9, 21) to read it", parser)
    'pass --line-bytes 9 21 to read it'
    >>> _ = parser.add_argument("--planar", action="store_true")
    >>> in_flags("if they are degrees, pass geographic=True; if metres, pass geographic=False", parser)
    'if they are degrees, leave out --planar; if metres, pass --planar'
    """
    flags, negated = {}, set()
    for action in parser._actions:
        flag = next((option for option in action.option_strings if option.startswith("--")), None)
        if flag is None or action.dest in flags:
            continue
        flags[action.dest] = flag
        if action.const is False:  # store_false: the flag says False
            negated.add(action.dest)
    short_names = set()
    for aliases in (COASTAL_ALIASES, SEISMIC_ALIASES):
        for short, long in aliases.items():
            if short in flags:
                short_names.add(short)
                flags.setdefault(long, flags[short])
    for name, option in _PASSED_AS.items():
        if option in flags:
            flags.setdefault(name, flags[option])

    def given(match):
        name, value = match.groups()
        if name in _OPPOSITES and value in ("True", "False"):  # geographic=False: --planar; True without it
            yes, no = (name, _OPPOSITES[name]) if value == "True" else (_OPPOSITES[name], name)
            if yes in flags:
                return flags[yes]
            if no in flags:
                return f"no {flags[no]}"  # "pass no --planar", said below as "leave out --planar"
        if name not in flags:
            return match.group(0)
        if value is None or (name in negated and value == "False"):
            return flags[name]
        if value.startswith("("):  # a tuple ("line_bytes=(9, 21)"): the flag takes its items one by one
            return f"{flags[name]} {' '.join(item.strip() for item in value[1:-1].split(','))}"
        return f"{flags[name]} {value.strip(chr(39) + chr(34))}"

    def with_short(match):
        long, short = match.groups()
        flag = flags.get(long)
        return flag if flag is not None and flags.get(short) == flag else match.group(0)

    def named(match):
        return flags.get(match.group(1), match.group(0))

    def short(match):
        return flags[match.group(1)] if match.group(1) in short_names else match.group(0)

    message = _WITH_SHORT.sub(with_short, message)
    message = _SUBJECT.sub(named, _NAMED.sub(named, _GIVEN.sub(given, message)))
    # "with axis_order (--axis-order on the command line)": now said in the flags themselves
    return _SAID_TWICE.sub("", _WORD.sub(short, message)).replace("pass no --", "leave out --")
