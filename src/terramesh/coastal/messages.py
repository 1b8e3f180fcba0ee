"""Errors and warnings of a coastal build's meshing stages, their places in longitude, latitude.

A coastal mesh is generated and repaired on the spherical Mercator plane,
so the generator's and the clean-up's messages place things in its metres:
"cells overlap ... near (-8.50125e+06, 4.705e+06)" was the upper
Chesapeake (-76.37, 38.88), which no user could tell. :func:`lonlat_messages` rewrites the
points and the strips' coordinates in them as degrees, and the lengths said beside a point
as ground metres there (a Mercator metre is ``cos(lat)`` of one on the ground: at 60° a
"size" of 500 was 250 m).
"""

import contextlib
import re
import warnings

import numpy as np

from ..errors import TerrameshError, TerrameshWarning, warn_user
from .projection import from_mercator, scale_factor

__all__ = ["in_lonlat", "lonlat_messages"]

_NUMBER = r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?"
# a point, "(x, y)" or "[x, y]": a shape such as "(3, 2)" is none, and neither is a pair of whole numbers
# below a kilometre, which a point on the plane is only within a kilometre of (0, 0) and a whole metre
_POINT = re.compile(rf"([(\[])\s*({_NUMBER}),\s*({_NUMBER})\s*([)\]])")
_ON_THE_PLANE = 1000.0
# a strip's or a cut's place along one axis, as meshing in strips writes them: "(x 1.2e+06 to 1.3e+06)",
# "at y = 7.4e+06" (a "16 x 16 grid" is none)
_ALONG = re.compile(rf"\(([xy]) ({_NUMBER}) to ({_NUMBER})\)|\b([xy]) = ({_NUMBER})")
# the lengths the generator and the clean-up say beside a point: "the longest 206 long, near (x, y), where the
# size is 68.1", "at most 12.5 apart, near (x, y)"
_LENGTH = re.compile(rf"\b({_NUMBER})( long| apart| across)\b|\b(size is )({_NUMBER})")


def _degrees(value):
    return f"{value:.6g}"


def _on_the_plane(match):
    """The ``(x, y)`` of a point match, or None for a shape or a count."""
    x, y = match.group(2), match.group(3)
    if not any(c in x + y for c in ".eE") and max(abs(float(x)), abs(float(y))) < _ON_THE_PLANE:
        return None
    return float(x), float(y)


def _point(match):
    point = _on_the_plane(match)
    if point is None:
        return match.group(0)
    lon, lat = from_mercator(np.array([point[0]]), np.array([point[1]]))
    return f"{match.group(1)}{_degrees(lon[0])}, {_degrees(lat[0])}{match.group(4)} (lon, lat)"


def _ground(metres):
    """A length on the ground, to three significant digits, in m or km."""
    rounded = float(f"{metres:.3g}")  # 999.99 is 1 km, not 1e+03 m
    return f"{rounded:g} m" if rounded < 1000.0 else f"{rounded / 1000.0:g} km"


def _ground_lengths(text):
    """``text`` with the lengths beside its first point on the plane in ground metres at that point's latitude."""
    point = next((p for p in map(_on_the_plane, _POINT.finditer(text)) if p is not None), None)
    if point is None:
        return text
    per_ground_metre = float(scale_factor(from_mercator(np.array([point[0]]), np.array([point[1]]))[1][0]))

    def length(match):
        value, word, before, after = match.groups()
        if value is not None:
            return f"{_ground(float(value) / per_ground_metre)}{word}"
        return f"{before}{_ground(float(after) / per_ground_metre)}"

    return _LENGTH.sub(length, text)


def _along(match):
    strip_axis, start, end, cut_axis, at = match.groups()
    axis, values = (strip_axis, [start, end]) if strip_axis else (cut_axis, [at])
    values = np.array([float(value) for value in values])
    if axis == "x":
        degrees = from_mercator(values, np.zeros(len(values)))[0]
    else:
        degrees = from_mercator(np.zeros(len(values)), values)[1]
    name = "lon" if axis == "x" else "lat"
    if strip_axis:
        return f"({name} {_degrees(degrees[0])} to {_degrees(degrees[1])})"
    return f"{name} = {_degrees(degrees[0])}"


def in_lonlat(text):
    """``text`` with its points on the Mercator plane (metres) as longitude, latitude degrees.

    Parameters
    ----------
    text : str
        A message of the generator or the clean-up run on the plane.

    Returns
    -------
    str
        Points ``(x, y)`` and ``[x, y]`` (but pairs of whole numbers below
        a kilometre: shapes) become ``(lon, lat) (lon, lat)``; a strip's
        ``(x A to B)`` and a cut's ``y = A`` become ``(lon ... to ...)`` and
        ``lat = ...``; where there is a point, the lengths said ``N long``,
        ``N apart``, ``N across`` and ``size is N`` become ground metres at
        its latitude.

    Examples
    --------
    >>> in_lonlat("cells overlap (near (-8.50125e+06, 4.705e+06))")
    'cells overlap (near (-76.368, 38.8835) (lon, lat))'
    >>> in_lonlat("strip 1 (y 7.37987e+06 to 7.39762e+06), shape (3, 2), a 16 x 16 grid")
    'strip 1 (lat 55.0927 to 55.1838), shape (3, 2), a 16 x 16 grid'
    >>> in_lonlat("near (378486, 713931)")
    'near (3.4, 6.4) (lon, lat)'
    >>> in_lonlat("the longest 2000 long, near (0, 8.39974e+06), where the size is 500")
    'the longest 1 km long, near (0, 60) (lon, lat), where the size is 250 m'
    """
    return _ALONG.sub(_along, _POINT.sub(_point, _ground_lengths(text)))


@contextlib.contextmanager
def lonlat_messages():
    """Run a meshing stage on the Mercator plane, its errors and warnings told in longitude, latitude.

    A :class:`~terramesh.errors.TerrameshError` is raised again, of its
    type, with :func:`in_lonlat`'s text; the warnings are held and given
    again, terramesh's with that text, others as they were, under the
    caller's filters.
    """
    held = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")  # held here: the caller's filters decide when they are given again
            try:
                yield
            finally:
                held = list(caught)
    except TerrameshError as error:
        raise type(error)(in_lonlat(str(error))) from error
    finally:
        _given_again(held)  # also when the stage failed: they may say why (a MemoryError, an interrupt)


def _given_again(held):
    for warning in held:
        if issubclass(warning.category, TerrameshWarning):
            warn_user(in_lonlat(str(warning.message)), warning.category)
        else:
            warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
