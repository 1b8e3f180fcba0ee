"""The command line's parser: an unknown option is named, with the option meant, before anything else is said.

argparse lets a subcommand hand the options it does not know back to the
top-level parser, which printed its own usage (``usage: terramesh [-h]
...``) and ``unrecognized arguments: --maxel 20000``; and a required option
missing was said first, so ``--min_el 250`` read as ``the following
arguments are required: --min-el/--h0`` and ``--min_el`` was never named.
Python 3.14's ``suggest_on_error`` suggests for choices and command names, not options; this works
from Python 3.10 on.
"""

import argparse
import contextlib
import copy
import difflib
import sys

__all__ = ["Parser"]

_CLOSE = 0.7
"""How alike a misspelling and the option meant are, at least (difflib's ratio): --maxel and --max-el 0.93,
--dem-var and --dem-variable 0.78; --maxel and --help, 0.62, are not."""


class Parser(argparse.ArgumentParser):
    """An :class:`argparse.ArgumentParser` that refuses unknown options first, by name, saying the nearest one.

    The arguments are parsed twice: once with no argument required, to find
    what no option of this parser takes (argparse's own rules: abbreviations
    of a single option, ``--opt=value``, negative numbers as values), then,
    when nothing is left over, as usual. The subcommands' parsers are of
    this class too (``add_subparsers`` makes them of their parent's), so
    each is checked where it is parsed and its own usage is printed.

    Examples
    --------
    >>> parser = Parser(prog="terramesh coastal")
    >>> _ = parser.add_argument("--min-el", "--h0", type=float, required=True)
    >>> _ = parser.add_argument("--max-el", type=float)
    >>> parser.unrecognized(["--maxel", "20000"])
    'unrecognized option --maxel: did you mean --max-el?'
    >>> parser.unrecognized(["--min_el=250", "-98.5"])
    'unrecognized option --min_el: did you mean --min-el?'
    """

    def parse_known_args(self, args=None, namespace=None):
        """Parse as argparse does, after refusing (``error``, exit status 2) any argument this parser does not take."""
        args = sys.argv[1:] if args is None else list(args)
        with self._nothing_required():
            _, extras = super().parse_known_args(args, copy.copy(namespace))
        if extras:
            self.error(self.unrecognized(extras))
        return super().parse_known_args(args, namespace)

    def format_usage(self):
        """The usage, with the required options as declared (not bracketed), also while checking for unknown ones."""
        with self._as_declared():
            return super().format_usage()

    def format_help(self):
        """The help, with the required options as declared, also while checking for unknown ones (``-h`` is then)."""
        with self._as_declared():
            return super().format_help()

    @contextlib.contextmanager
    def _nothing_required(self):
        """Nothing required of this parser, nor of its subcommands' (``terramesh --dis coastal``: --dis first)."""
        relaxed = []
        for parser in _with_subcommands(self):
            items = [item for item in (*parser._actions, *parser._mutually_exclusive_groups) if item.required]
            relaxed.append((parser, getattr(parser, "_relaxed", [])))
            parser._relaxed = [*getattr(parser, "_relaxed", []), *items]
            for item in items:
                item.required = False
        try:
            yield
        finally:
            for parser, before in relaxed:
                for item in parser._relaxed[len(before) :]:
                    item.required = True
                parser._relaxed = before

    @contextlib.contextmanager
    def _as_declared(self):
        relaxed = getattr(self, "_relaxed", [])
        for item in relaxed:
            item.required = True
        try:
            yield
        finally:
            for item in relaxed:
                item.required = False

    def unrecognized(self, extras):
        """The error message for ``extras``, the arguments no option took: each unknown option with the one meant."""
        options = [_option_name(text) for text in extras if _is_option(text, self.prefix_chars)]
        if not options:  # words alone: argparse's own message, under this parser's usage
            return f"unrecognized arguments: {' '.join(extras)}"
        return "; ".join(f"unrecognized option {name}: {self._meant(name)}" for name in dict.fromkeys(options))

    def _meant(self, name):
        """What ``name`` may have been meant as: this parser's nearest option, or a subcommand's (given before it)."""
        known = [option for action in self._actions for option in action.option_strings]
        spelled = "--" + name.lstrip(self.prefix_chars).replace("_", "-").lower()  # --min_el, -min-el, --Min-El
        if spelled in known:
            return f"did you mean {spelled}?"
        # terramesh --max-el 5000 coastal ...: a command's options come after its name
        theirs = {}
        for parser in list(_with_subcommands(self))[1:]:
            for option in {option for action in parser._actions for option in action.option_strings}:
                theirs.setdefault(option, []).append(parser.prog)
        if name in theirs:
            return f"an option of {' and '.join(theirs[name])}: give it after the command's name"
        close = [spelled] if spelled in theirs else []
        close = close or difflib.get_close_matches(name, known, n=1, cutoff=_CLOSE)
        if close and close[0] in known:
            return f"did you mean {close[0]}?"
        close = close or difflib.get_close_matches(name, list(theirs), n=1, cutoff=_CLOSE)
        if close:
            where = " and ".join(theirs[close[0]])
            return f"did you mean {close[0]}, an option of {where}, given after the command's name?"
        return f"{self.prog} --help lists the options"


def _with_subcommands(parser):
    """``parser`` and its subcommands' parsers, theirs, and so on."""
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for command in dict.fromkeys(action.choices.values()):  # an alias's parser is its command's
                yield from _with_subcommands(command)


def _is_option(text, prefix_chars):
    """Whether ``text`` reads as an option, as argparse reads it: a prefix, not a number, not a lone ``-``, no space."""
    if len(text) < 2 or text[0] not in prefix_chars or " " in text:
        return False
    try:
        float(text)
    except ValueError:
        return True
    return False  # -98, -1e5, -inf: a value, given to an option argparse did not know (its own was named)


def _option_name(text):
    """The option of ``--opt=value``."""
    return text.split("=", 1)[0]
