"""Truss forces of the force-equilibrium mesh generator."""

import numba
import numpy as np


@numba.njit(cache=True)
def spring_forces(points, edges, target, length_factor):
    """Net repulsive spring force on every point.

    Each edge ``(a, b)`` is a spring with rest length proportional to
    ``0.5 * (target[a] + target[b])``, scaled so that the rest lengths' sum
    of squares is ``length_factor**2`` times that of the current lengths
    (Persson & Strang 2004). Springs only push (no attraction).

    ``points`` (n, dim) float64, ``edges`` (e, 2) int64, ``target`` (n,) float64.
    Returns the (n, dim) force array.
    """
    n, dim = points.shape
    n_edges = edges.shape[0]
    lengths = np.empty(n_edges)
    rest = np.empty(n_edges)
    sum_length2 = 0.0
    sum_rest2 = 0.0
    for e in range(n_edges):
        a = edges[e, 0]
        b = edges[e, 1]
        length2 = 0.0
        for d in range(dim):
            delta = points[a, d] - points[b, d]
            length2 += delta * delta
        lengths[e] = np.sqrt(length2)
        rest[e] = 0.5 * (target[a] + target[b])
        sum_length2 += length2
        sum_rest2 += rest[e] * rest[e]
    scale = length_factor * np.sqrt(sum_length2 / sum_rest2)
    force = np.zeros((n, dim))
    for e in range(n_edges):
        push = rest[e] * scale - lengths[e]
        if push > 0.0 and lengths[e] > 0.0:
            a = edges[e, 0]
            b = edges[e, 1]
            ratio = push / lengths[e]
            for d in range(dim):
                component = ratio * (points[a, d] - points[b, d])
                force[a, d] += component
                force[b, d] -= component
    return force
