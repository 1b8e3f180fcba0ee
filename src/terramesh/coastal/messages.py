"""Errors and warnings of a coastal build's meshing stages, their places in longitude, latitude.

A coastal mesh is generated and repaired on the spherical Mercator plane,
so the generator's and the clean-up's messages place things in its metres:
"cells overlap ... near (-8.50125e+06, 4.705e+06)" was the upper
Chesapeake (-76.37, 38.88), which no user could tell. :func:`lonlat_messages` rewrites the
points and the strips' coordinates in them as degrees.
"""

import contextlib
import re
import warnings

import numpy as np

from ..errors import TerrameshError, TerrameshWarning, warn_user
from .projection import from_mercator

__all__ = ["in_lonlat", "lonlat_messages"]

_NUMBER = r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?"
# a point, "(x, y)" or "[x, y]": a shape such as "(3, 2)" is none, and neither is a pair of whole numbers
# below a kilometre, which a point on the plane is only within a kilometre of (0, 0) and a whole metre
_POINT = re.compile(rf"([(\[])\s*({_NUMBER}),\s*({_NUMBER})\s*([)\]])")
_ON_THE_PLANE = 1000.0
# a strip's or a cut's place along one axis, as meshing in strips writes them: "(x 1.2e+06 to 1.3e+06)",
# "at y = 7.4e+06" (a "16 x 16 grid" is none)
_ALONG = re.compile(rf"\(([xy]) ({_NUMBER}) to ({_NUMBER})\)|\b([xy]) = ({_NUMBER})")


def _degrees(value):
    return f"{value:.6g}"


def _point(match):
    x, y = match.group(2), match.group(3)
    if not any(c in x + y for c in ".eE") and max(abs(float(x)), abs(float(y))) < _ON_THE_PLANE:
        return match.group(0)
    lon, lat = from_mercator(np.array([float(x)]), np.array([float(y)]))
    return f"{match.group(1)}{_degrees(lon[0])}, {_degrees(lat[0])}{match.group(4)} (lon, lat)"


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
        ``lat = ...``.

    Examples
    --------
    >>> in_lonlat("cells overlap (near (-8.50125e+06, 4.705e+06))")
    'cells overlap (near (-76.368, 38.8835) (lon, lat))'
    >>> in_lonlat("strip 1 (y 7.37987e+06 to 7.39762e+06), shape (3, 2), a 16 x 16 grid")
    'strip 1 (lat 55.0927 to 55.1838), shape (3, 2), a 16 x 16 grid'
    >>> in_lonlat("near (378486, 713931)")
    'near (3.4, 6.4) (lon, lat)'
    """
    return _ALONG.sub(_along, _POINT.sub(_point, text))


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
