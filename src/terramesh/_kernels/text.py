"""Whole numbers as ASCII text, for the element tables of the text mesh formats.

Python's ``%d`` formats about 15 million numbers a second; the element
table of a 10**6-vertex fort.14 holds 10 million of them (0.7 s). Here a
number costs a few divisions.
"""

import numba
import numpy as np

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
