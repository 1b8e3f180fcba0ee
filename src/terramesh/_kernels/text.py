"""Numbers as ASCII text, written (element tables of the text mesh formats) and read (Gmsh tables).

Python's ``%d`` formats about 15 million numbers a second; the element
table of a 10**6-vertex fort.14 holds 10 million of them (0.7 s). Here a
number costs a few divisions.

Read, a real is rounded as ``strtod`` rounds it (the nearest double), by
the Eisel-Lemire algorithm; the rare tokens it does not take (20 or more
significant digits, subnormal or overflowing values, ``nan``, ``inf``,
text that is no number) are handed back to the caller, for Python's
``float``: the 2.8 million coordinates of 917k nodes in 0.25 s (meshio
took 15 s for the whole Gmsh file).
"""

import math

import numba
import numpy as np

from .arrays import grown

_SPACE, _NEWLINE, _MINUS, _ZERO = 32, 10, 45, 48
_WIDEST = 21  # characters of an int64 with its sign and the separator after it


@numba.njit(cache=True)
def int_rows_text(values):
    """ASCII bytes of a 2D int64 array as ``"%d"`` writes it: numbers one space apart, each row a line."""
    rows, columns = values.shape
    text = np.empty(rows * columns * _WIDEST, dtype=np.uint8)
    digits = np.empty(_WIDEST, dtype=np.uint8)
    at = 0
    for i in range(rows):
        for j in range(columns):
            value = values[i, j]
            if value < 0:
                text[at] = _MINUS
                at += 1
                magnitude = np.uint64(-(value + 1)) + np.uint64(1)  # -value overflows at the smallest int64
            else:
                magnitude = np.uint64(value)
            count = 0
            while True:
                digits[count] = _ZERO + magnitude % np.uint64(10)
                count += 1
                magnitude //= np.uint64(10)
                if magnitude == 0:
                    break
            for k in range(count - 1, -1, -1):
                text[at] = digits[k]
                at += 1
            text[at] = _SPACE if j < columns - 1 else _NEWLINE
            at += 1
    return text[:at]


# reading: numbers parsed where they lie in a file's bytes, one row of a table a line


def _powers_of_five():
    """128-bit truncations of 5**q, q = -342..308, with the top bit set: high and low words (Eisel-Lemire).

    The table of fast_float (Lemire, "Number parsing at a gigabyte per second",
    Software: Practice and Experience 51, 2021, doi:10.1002/spe.2984), made
    here from exact integers.
    """
    words = []
    for q in range(_SMALLEST_POWER, _LARGEST_POWER + 1):
        if q >= 0:
            power = 5**q
            power <<= max(128 - power.bit_length(), 0)
            power >>= max(power.bit_length() - 128, 0)
        else:
            divisor = 5**-q
            bits = (divisor - 1).bit_length()  # the least z with 2**z >= 5**-q
            power = 2 ** (bits + 127 if q >= -27 else 2 * bits + 128) // divisor + 1
            power >>= max(power.bit_length() - 128, 0)
        words.append((power >> 64, power & (2**64 - 1)))
    return np.array(words, dtype=np.uint64)


_SMALLEST_POWER, _LARGEST_POWER = -342, 308
_POWERS_OF_FIVE = _powers_of_five()
_TAB, _CARRIAGE_RETURN, _DOLLAR, _PLUS, _DOT, _NINE = 9, 13, 36, 43, 46, 57
_LOW_32 = np.uint64(0xFFFFFFFF)
_MANTISSA_BITS = 52

# the statuses of the row readers: what stopped them at ``where``
ROWS_READ = 0
SECTION_ENDS = 1  # the file or the section ended before the rows the header counts
FEW_NUMBERS = 2  # a line ended before its row did
MANY_NUMBERS = 3  # a line holds more numbers than its row
NOT_WHOLE = 4  # a token that is no whole number (or none within int64)
UNKNOWN_TYPE = 5  # an element type with no node count
NEGATIVE_COUNT = 6  # an element's tag count below zero


@numba.njit(cache=True)
def _blank(byte):
    return byte == _SPACE or byte == _TAB or byte == _CARRIAGE_RETURN


@numba.njit(cache=True)
def _token_end(text, at):
    while at < len(text) and not _blank(text[at]) and text[at] != _NEWLINE:
        at += 1
    return at


@numba.njit(cache=True)
def _next_token(text, at):
    """The start and end of the next number on this line; start == end where the line has no more."""
    while at < len(text) and _blank(text[at]):
        at += 1
    if at == len(text) or text[at] == _NEWLINE:
        return at, at
    return at, _token_end(text, at)


@numba.njit(cache=True)
def _next_row(text, at):
    """Where the next row starts (blank lines skipped) and whether the file or the section ends there instead."""
    while at < len(text) and (_blank(text[at]) or text[at] == _NEWLINE):
        at += 1
    return at, at == len(text) or text[at] == _DOLLAR


@numba.njit(cache=True)
def _whole(text, start, end):
    """``(value, ok)`` for the token ``text[start:end]``: an optionally signed int64 of at most 18 digits."""
    negative = text[start] == _MINUS
    if text[start] == _MINUS or text[start] == _PLUS:
        start += 1
    if start == end or end - start > 18:
        return 0, False
    value = 0
    for at in range(start, end):
        digit = np.int64(text[at]) - _ZERO
        if digit < 0 or digit > 9:
            return 0, False
        value = 10 * value + digit
    return -value if negative else value, True


@numba.njit(cache=True)
def _product_128(a, b):
    """The high and low words of the 128-bit product of two uint64."""
    a_low, a_high, b_low, b_high = a & _LOW_32, a >> np.uint64(32), b & _LOW_32, b >> np.uint64(32)
    low_low, low_high, high_low = a_low * b_low, a_low * b_high, a_high * b_low
    middle = (low_low >> np.uint64(32)) + (low_high & _LOW_32) + (high_low & _LOW_32)
    high = a_high * b_high + (low_high >> np.uint64(32)) + (high_low >> np.uint64(32)) + (middle >> np.uint64(32))
    return high, (low_low & _LOW_32) | (middle << np.uint64(32))


@numba.njit(cache=True)
def _decimal(significand, exponent):
    """``(value, ok)``: significand * 10**exponent correctly rounded (Eisel-Lemire), for normal doubles.

    ``significand`` (uint64) is not zero; ok is False where the result
    would be subnormal or overflow.
    """
    if exponent < _SMALLEST_POWER or exponent > _LARGEST_POWER:
        return 0.0, False
    shift = 0
    for step in (32, 16, 8, 4, 2, 1):
        if significand < np.uint64(1) << np.uint64(64 - step):
            significand <<= np.uint64(step)
            shift += step
    index = exponent - _SMALLEST_POWER
    high, low = _product_128(significand, _POWERS_OF_FIVE[index, 0])
    precision_mask = np.uint64(0xFFFFFFFFFFFFFFFF) >> np.uint64(_MANTISSA_BITS + 3)
    if high & precision_mask == precision_mask:
        second_high, _ = _product_128(significand, _POWERS_OF_FIVE[index, 1])
        low += second_high
        if second_high > low:
            high += np.uint64(1)
    upper = np.int64(high >> np.uint64(63))
    drop = np.uint64(upper + 64 - _MANTISSA_BITS - 3)
    mantissa = high >> drop
    power = (((152170 + 65536) * exponent) >> 16) + 63 + upper - shift + 1023
    if power <= 0:
        return 0.0, False
    if low <= np.uint64(1) and -4 <= exponent <= 23 and mantissa & np.uint64(3) == np.uint64(1):
        if mantissa << drop == high:  # halfway between two doubles: round to even
            mantissa &= ~np.uint64(1)
    mantissa += mantissa & np.uint64(1)
    mantissa >>= np.uint64(1)
    if mantissa >= np.uint64(2) << np.uint64(_MANTISSA_BITS):
        mantissa = np.uint64(1) << np.uint64(_MANTISSA_BITS)
        power += 1
    if power >= 2047:
        return 0.0, False
    return math.ldexp(float(mantissa), power - 1023 - _MANTISSA_BITS), True


@numba.njit(cache=True)
def _real(text, start, end):
    """``(value, ok)`` for the token ``text[start:end]``; ok is False where it is no decimal number this reads.

    Those are 20 or more significant digits, subnormal or overflowing
    values, ``nan`` and ``inf`` and text that is no number: the caller
    tells them apart.
    """
    negative = text[start] == _MINUS
    at = start + 1 if text[start] == _MINUS or text[start] == _PLUS else start
    significand, digits, exponent, seen = np.uint64(0), 0, 0, False
    fraction = False
    while at < end:
        byte = text[at]
        if byte == _DOT and not fraction:
            fraction = True
        elif _ZERO <= byte <= _NINE:
            seen = True
            if significand != 0 or byte != _ZERO:
                if digits == 19:
                    return 0.0, False
                significand = np.uint64(10) * significand + np.uint64(byte - _ZERO)
                digits += 1
            if fraction:
                exponent -= 1
        else:
            break
        at += 1
    if not seen:
        return 0.0, False
    if at < end:
        if text[at] != 69 and text[at] != 101:  # E, e
            return 0.0, False
        power, ok = _whole(text, at + 1, end)
        if not ok or abs(power) > 100_000:
            return 0.0, False
        exponent += power
    if significand == 0:
        return -0.0 if negative else 0.0, True
    value, ok = _decimal(significand, exponent)
    return -value if negative else value, ok


@numba.njit(cache=True, inline="always")
def _room(array, size):
    """``array`` with room for ``size`` values: twice as long (:func:`~.arrays.grown`) when it has less."""
    return array if size <= len(array) else grown(array, max(size, 2 * len(array)), 0)


@numba.njit(cache=True)
def real_rows(text, at, rows, columns):
    """Parse ``rows`` lines from ``text[at:]``, each a whole number and ``columns`` reals (Gmsh nodes, node data).

    ``text`` is a file's bytes (uint8). Blank lines between rows are
    skipped. Returns ``(numbers, values, deferred, done, status, where)``:
    the first column (int64, ``(rows,)``), the others (float64, ``(rows,
    columns)``), the tokens this does not read (int64 ``(k, 3)``: the
    flat index into ``values``, the token's start and end; their values
    are the caller's to parse, see :func:`_real`), the rows read, a status
    (``ROWS_READ`` and the others above) and the offset it concerns: after
    the last row, or the line or token that stopped the reading.
    """
    numbers = np.empty(rows, dtype=np.int64)
    values = np.empty((rows, columns), dtype=np.float64)
    deferred = np.empty(48, dtype=np.int64)
    held = 0
    for row in range(rows):
        at, ended = _next_row(text, at)
        if ended:
            return numbers, values, deferred[:held].reshape(-1, 3), row, SECTION_ENDS, at
        line = at
        start, at = _next_token(text, at)
        numbers[row], ok = _whole(text, start, at)
        if not ok:
            return numbers, values, deferred[:held].reshape(-1, 3), row, NOT_WHOLE, start
        for column in range(columns):
            start, at = _next_token(text, at)
            if start == at:
                return numbers, values, deferred[:held].reshape(-1, 3), row, FEW_NUMBERS, line
            values[row, column], ok = _real(text, start, at)
            if not ok:
                deferred = _room(deferred, held + 3)
                deferred[held], deferred[held + 1], deferred[held + 2] = row * columns + column, start, at
                held += 3
        start, at = _next_token(text, at)
        if start != at:
            return numbers, values, deferred[:held].reshape(-1, 3), row, MANY_NUMBERS, line
    return numbers, values, deferred[:held].reshape(-1, 3), rows, ROWS_READ, at


@numba.njit(cache=True)
def element_rows(text, at, rows, node_counts):
    """Parse ``rows`` Gmsh 2.2 element lines from ``text[at:]``: number, type, tag count, tags, nodes.

    ``node_counts[t]`` is the number of nodes of an element of type ``t``
    (0 or less: no type). Blank lines between rows are skipped. Returns
    ``(types, numbers, starts, nodes, done, status, where)``: each row's
    type and element number (int64, ``(rows,)``), where its nodes start in ``nodes`` (int64,
    ``(rows + 1,)``, the last the total), the node numbers of all rows one
    after another (int64), the rows read, a status (``ROWS_READ`` and the
    others above) and the offset it concerns: after the last row, or the
    line or token that stopped the reading.
    """
    types = np.empty(rows, dtype=np.int64)
    numbers = np.empty(rows, dtype=np.int64)
    starts = np.zeros(rows + 1, dtype=np.int64)
    nodes = np.empty(4 * rows, dtype=np.int64)
    for row in range(rows):
        at, ended = _next_row(text, at)
        if ended:
            return types, numbers, starts, nodes[: starts[row]], row, SECTION_ENDS, at
        line = at
        tags, count = 0, 0
        for item in range(3):
            start, at = _next_token(text, at)
            if start == at:
                return types, numbers, starts, nodes[: starts[row]], row, FEW_NUMBERS, line
            value, ok = _whole(text, start, at)
            if not ok:
                return types, numbers, starts, nodes[: starts[row]], row, NOT_WHOLE, start
            if item == 0:
                numbers[row] = value
            elif item == 1:
                if value < 0 or value >= len(node_counts) or node_counts[value] <= 0:
                    return types, numbers, starts, nodes[: starts[row]], row, UNKNOWN_TYPE, start
                types[row], count = value, node_counts[value]
            elif item == 2:
                if value < 0:
                    return types, numbers, starts, nodes[: starts[row]], row, NEGATIVE_COUNT, start
                tags = value
        nodes = _room(nodes, starts[row] + count)
        for item in range(tags + count):
            start, at = _next_token(text, at)
            if start == at:
                return types, numbers, starts, nodes[: starts[row]], row, FEW_NUMBERS, line
            value, ok = _whole(text, start, at)
            if not ok:
                return types, numbers, starts, nodes[: starts[row]], row, NOT_WHOLE, start
            if item >= tags:
                nodes[starts[row] + item - tags] = value
        starts[row + 1] = starts[row] + count
        start, at = _next_token(text, at)
        if start != at:
            return types, numbers, starts, nodes[: starts[row]], row, MANY_NUMBERS, line
    return types, numbers, starts, nodes[: starts[rows]], rows, ROWS_READ, at
