"""Exact arithmetic on floating-point expansions (Shewchuk 1997, doi:10.1007/PL00009321).

An expansion is a run of doubles, increasing in magnitude and non-overlapping,
whose exact sum is the value; its sign is the sign of its last component.
The exact geometric predicates of the 2D and 3D Delaunay kernels fall back on
these where a floating-point filter cannot decide a sign. Every function
writes into buffers its caller provides (allocating per call made lattices,
where such fallbacks are common, several times slower) and drops zero
components, so the work follows the lengths met, not the worst case the
buffers are sized for.
"""

import numba
import numpy as np

from .arrays import copy_head

EPSILON = 2.0**-53  # half an ulp of 1: the relative rounding error of one operation
_SPLITTER = 2.0**27 + 1.0


@numba.njit(cache=True, inline="always")
def two_sum(a, b):
    x = a + b
    bv = x - a
    av = x - bv
    return x, (a - av) + (b - bv)


@numba.njit(cache=True, inline="always")
def two_product(a, b):
    # Dekker's split: each half has at most 26 bits, so the partial products are exact
    x = a * b
    c = _SPLITTER * a
    ahi = c - (c - a)
    alo = a - ahi
    c = _SPLITTER * b
    bhi = c - (c - b)
    blo = b - bhi
    return x, alo * blo - (((x - ahi * bhi) - alo * bhi) - ahi * blo)


@numba.njit(cache=True, inline="always")
def product_difference(a, b, c, d, out):
    """Exact ``a b - c d`` into ``out`` (four components at most, zeros dropped); returns the length."""
    ab, ab_tail = two_product(a, b)
    cd, cd_tail = two_product(c, d)
    # Shewchuk's Two_Two_Diff: subtract the low part, then the high part, each by two-sums
    i, x0 = two_sum(ab_tail, -cd_tail)
    j, k = two_sum(ab, i)
    i, x1 = two_sum(k, -cd)
    x3, x2 = two_sum(j, i)
    n = 0
    for x in (x0, x1, x2, x3):
        if x != 0.0:
            out[n] = x
            n += 1
    if n == 0:
        out[0] = 0.0
        n = 1
    return n


@numba.njit(cache=True)
def expansion_sum(e, elen, f, flen, h):
    """Exact ``h = e + f`` with zero components dropped; returns the length of ``h``."""
    if elen == 0:
        copy_head(h, f, flen)
        return flen
    if flen == 0:
        copy_head(h, e, elen)
        return elen
    i = 0
    j = 0
    # merge by magnitude, accumulating with exact two-sums
    if abs(e[0]) < abs(f[0]):
        q = e[0]
        i = 1
    else:
        q = f[0]
        j = 1
    hlen = 0
    while i < elen or j < flen:
        if j >= flen or (i < elen and abs(e[i]) < abs(f[j])):
            g = e[i]
            i += 1
        else:
            g = f[j]
            j += 1
        q, t = two_sum(q, g)
        if t != 0.0:
            h[hlen] = t
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


@numba.njit(cache=True)
def scale_expansion(e, elen, b, h):
    """Exact ``h = e * b`` with zero components dropped; returns the length of ``h`` (at most ``2 elen``)."""
    hlen = 0
    q, t = two_product(e[0], b)
    if t != 0.0:
        h[hlen] = t
        hlen += 1
    for i in range(1, elen):
        p1, p0 = two_product(e[i], b)
        s, t = two_sum(q, p0)
        if t != 0.0:
            h[hlen] = t
            hlen += 1
        q, t = two_sum(p1, s)
        if t != 0.0:
            h[hlen] = t
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


@numba.njit(cache=True)
def multiply(e, elen, f, flen, out, spare, term):
    """Exact ``out = e * f``; ``out`` and ``spare`` hold ``2 elen flen``, ``term`` ``2 elen``; returns the length."""
    alen = np.int64(0)
    in_out = True  # which buffer holds the running sum
    for k in range(flen):
        tlen = scale_expansion(e, elen, f[k], term)
        if in_out:
            alen = expansion_sum(out, alen, term, tlen, spare)
        else:
            alen = expansion_sum(spare, alen, term, tlen, out)
        in_out = not in_out
    if not in_out:
        copy_head(out, spare, alen)
    return alen


@numba.njit(cache=True, inline="always")
def difference(a, b, out):
    """``a - b`` as an exact expansion of one or two components; returns the length."""
    x, y = two_sum(a, -b)
    if y != 0.0:
        out[0] = y
        out[1] = x
        return 2
    out[0] = x
    return 1


@numba.njit(cache=True)
def negate(e, elen):
    for i in range(elen):
        e[i] = -e[i]


@numba.njit(cache=True)
def minor(e, elen, f, flen, g, glen, h, hlen, out, work, subtract):
    """Exact ``e f - g h`` (``e f + g h`` unless ``subtract``) into ``out``; returns the length.

    At most 16 components for inputs of two.
    """
    p = work[0:8]
    q = work[8:16]
    spare = work[16:24]
    term = work[24:28]
    plen = multiply(e, elen, f, flen, p, spare, term)
    qlen = multiply(g, glen, h, hlen, q, spare, term)
    if subtract:
        negate(q, qlen)
    return expansion_sum(p, plen, q, qlen, out)


@numba.njit(cache=True)
def sum_of_products(x, xlen, p, plen, y, ylen, q, qlen, z, zlen, r, rlen, out, work):
    """Exact ``out = x p + y q + z r``; returns the length.

    ``out`` holds ``2 (xlen plen + ylen qlen + zlen rlen)`` components and
    ``work`` twice that plus ``4 max(xlen, ylen, zlen)``: the three
    products, two of them summed, a spare product and a scaled ``x``
    (:func:`multiply` scales the first factor by each component of the second).
    """
    a = 2 * xlen * plen
    b = 2 * ylen * qlen
    c = 2 * zlen * rlen
    first = work[0:a]
    second = work[a : a + b]
    third = work[a + b : a + b + c]
    partial = work[a + b + c : 2 * (a + b) + c]
    spare = work[2 * (a + b) + c : 2 * (a + b) + c + max(a, b, c)]
    term = work[2 * (a + b) + c + max(a, b, c) :]
    first_length = multiply(x, xlen, p, plen, first, spare, term)
    second_length = multiply(y, ylen, q, qlen, second, spare, term)
    third_length = multiply(z, zlen, r, rlen, third, spare, term)
    partial_length = expansion_sum(first, first_length, second, second_length, partial)
    return expansion_sum(partial, partial_length, third, third_length, out)
