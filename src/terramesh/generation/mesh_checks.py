"""Warnings about a generated mesh: iterations run out, area not covered, rings, sizes or fixed points missed.

Each check compares the finished mesh with what was asked (the domain's
sampled area, its polygon's rings, the sizes' vertex counts) and warns at the
user's line, saying where and what would help. Each warning's words are a
constant beside its message, here or in the module that raises it, so that
the callers that say their own (the coastal pipeline, meshing in strips, an
anisotropic start) mute it by those words.
"""

import numpy as np

from ..errors import point_text, warn_user
from ..mesh.columns import bounds
from ..mesh.topology import boundary_edges, signed_areas, sorted_unique
from ..quality.tetra import tetra_volumes

# warnings' words, by which a caller that says its own mutes them (tm.errors.muted_warnings): the coastal
# pipeline the first two; generators that add fixed points of their own (meshing in strips, an anisotropic
# start) the third, and ask it of the user's points alone (the words of the warnings raised elsewhere live
# with their messages: fixed_points.FIXED_NEAR_BOUNDARY and CORNERS_DISPLACED, finalize.OFF_BOUNDARY)
REACHED_MAX_ITER = "mesh generation reached max_iter"
SIZES_MISSED = "where its sizes ask for about"
FIXED_DROPPED = "fixed points are no vertices of the mesh"
# fractions of the domain's sampled area the cells may cover without a warning: 1,090 meshes of the tests covered
# 0.83-1.13 but for those made to warn; a wedge of 2 degrees meshed in four pieces covering 0.72 had said nothing
AREA_COVERED = (0.8, 1.25)


def warn_if_partly_covered(mesh, measure):
    """Warn when the cells cover much less or much more than the domain's sampled area (or volume) ``measure``.

    Features thinner than the sizes are not meshed as they are: a polygon
    thin in most places (a needle 57 wide meshed at 50) came out as 5
    vertices over 21 % of its area, "converged"; a hole 17 wide in a strip
    meshed at 50 was bridged by cells covering 133 % of the area; a wedge of
    2 degrees meshed at 0.02 fell into four pieces over 72 % of its area.
    """
    volumes = signed_areas(mesh.points, mesh.cells) if mesh.dim == 2 else tetra_volumes(mesh.points, mesh.cells)
    ratio = float(volumes.sum()) / measure if measure > 0 else 1.0
    if not AREA_COVERED[0] <= ratio <= AREA_COVERED[1]:
        why = "parts thinner than the mesh size were left out" if ratio < 1 else "cells bridge gaps or holes"
        warn_user(
            f"the mesh covers {100 * ratio:.0f} % of the domain's {'area' if mesh.dim == 2 else 'volume'} (about "
            f"{measure:.4g}): {why}{'' if ratio < 1 else ' thinner than the mesh size'}; give smaller sizes there",
        )


def warn_if_rings_missed(mesh, domain, size, tolerance):
    """Warn of the rings of a polygon ``domain`` that no boundary vertex of the 2D ``mesh`` lies on.

    DistMesh keeps the cells whose centroid is inside: a hole smaller than
    the cells around it is covered, a part smaller than them gets none (a
    hole 0.04 across in a unit square meshed at 0.1, a part 0.03 square
    beside it: both gone, the area covered within 0.2 % of the domain's; a
    barrier island 0.7 degrees long in GSHHS's Gulf of Mexico, narrower than
    the 0.1 degree cells, covered). Domains other than :class:`~terramesh.geometry.Polygon` have no list of
    their boundary's pieces and are not checked.
    """
    if not hasattr(domain, "rings_missed") or mesh.n_cells == 0:
        return
    holes, parts = domain.rings_missed(mesh.points[sorted_unique(boundary_edges(mesh.cells))], tolerance)
    if not holes and not parts:
        return
    missed = holes + parts
    extent = np.array([np.ptp(domain.rings[ring], axis=0).max() for ring in missed])
    largest = missed[int(np.argmax(extent))]
    where = domain.rings[largest].mean(axis=0)
    said = [
        f"{len(rings)} {word}{'s' if len(rings) > 1 else ''} {fate}"
        for rings, word, fate in ((holes, "hole", "covered by cells"), (parts, "disjoint part", "with no cells"))
        if rings
    ]
    warn_user(
        f"the domain's boundary has pieces smaller or narrower than the cells there that are not in the mesh: "
        f"{' and '.join(said)} (the longest {_plain(extent.max())} long, near ({where[0]:.6g}, {where[1]:.6g}), "
        f"where the size is {_plain(float(size(where[None])[0]))}); give smaller sizes there to keep them",
    )


def _plain(length):
    """``length`` to three significant digits, without an exponent between 1e-4 and 1e9 (11600 m, not 1.16e+04)."""
    if 1e-4 <= abs(length) < 1e9:
        return np.format_float_positional(length, precision=3, unique=False, fractional=False, trim="-")
    return f"{length:.3g}"


SIZE_BLOCKS = 16  # the 2D check of the mesh against its sizes counts vertices in this many blocks a side of the bbox
FEWEST_EXPECTED = 10  # ...in the blocks where the sizes ask for this many vertices or more...
LEAST_SHARE = 0.5  # ...and warns where the mesh has fewer than this share of them


def warn_if_sizes_missed(mesh, sample, h0):
    """Warn where the 2D mesh has far fewer vertices than its sizes ask for (a spot the sizes change too fast for).

    The sizes' ``sample`` (:func:`~.options.size_sample`) gives each square block of
    a grid over the domain (``SIZE_BLOCKS`` along its longer side) the vertex count its sizes (not
    below ``h0``) ask for, ``1 / (sqrt(3)/2 h**2)`` over its area; where that
    is ``FEWEST_EXPECTED`` or more and the mesh has under ``LEAST_SHARE`` of
    it, the sizes fell faster than the mesh could follow: the seeding's
    lattices, refined only around sites whose own size is small, stepped
    over a spot of small sizes between their coarse sites (a spot 0.04
    across at 1e-3 in a unit square at 0.2 had none of its 1,450 vertices,
    silently with h0 given or a SizeGrid), or the forces of the coarse
    cells around a spot that was seeded squeezed it to its middle and
    thinned it (0.012 across: from 131 vertices to none).
    """
    inside, sizes, share = sample.inside, sample.sizes, sample.share
    if len(inside) == 0 or len(mesh.points) == 0:
        return
    # square blocks, SIZE_BLOCKS along the longer side: on a strip 30 x 1 blocks 1/16 high fell between
    # the mesh's rows and missed every vertex
    low, high = bounds(inside)
    side = max(float(np.max(high - low)) / SIZE_BLOCKS, np.finfo(float).tiny)
    counts = np.maximum(np.ceil((high - low) / side).astype(np.int64), 1)

    def block(points):
        # column by column: NumPy 2.4 took twice as long over the (n, 2) array
        index = 0
        for axis in range(2):
            cell = ((points[:, axis] - low[axis]) / side).astype(np.int64)
            np.clip(cell, 0, counts[axis] - 1, out=cell)
            index = index * counts[axis] + cell
        return index

    blocks = block(inside)
    asked = np.bincount(
        blocks, weights=share / (np.sqrt(3.0) / 2.0 * np.maximum(sizes, h0) ** 2), minlength=int(np.prod(counts))
    )
    found = np.bincount(block(mesh.points), minlength=int(np.prod(counts)))
    # and short in the block's 3 x 3 neighbourhood too: a row of vertices just past a block's edge left a
    # bar 0.2 wide (a block's share of it asked for 10) with 5, at the size asked everywhere
    around = [_neighbourhood_sums(values.reshape(counts)).ravel() for values in (asked, found)]
    short = np.flatnonzero(
        (asked >= FEWEST_EXPECTED) & (found < LEAST_SHARE * asked) & (around[1] < LEAST_SHARE * around[0])
    )
    if len(short) == 0:
        return
    worst = short[np.argmin(found[short] / asked[short])]
    in_worst = blocks == worst
    where = inside[in_worst][np.argmin(sizes[in_worst])]
    warn_user(
        f"the mesh has {int(found[worst])} vertices {SIZES_MISSED} {asked[worst]:.0f} (near "
        f"({where[0]:.6g}, {where[1]:.6g}), sizes down to {sizes[in_worst].min():.3g}; {len(short)} such "
        f"blocks of a {counts[0]} x {counts[1]} grid over the domain): the sizes change faster than a mesh "
        "can follow; grade them (tm.sizing.limit_gradient) so that the region of small sizes is wider",
    )


def _neighbourhood_sums(grid):
    """Each value of the 2D ``grid`` summed with its (up to) eight neighbours'."""
    padded = np.pad(grid.astype(np.float64), 1)
    rows, columns = grid.shape
    return sum(padded[i : i + rows, j : j + columns] for i in range(3) for j in range(3))


def warn_if_unconverged(info, max_iter, move_tolerance):
    """Warn, at the user's line, when the iterations ran out (``info["stop_reason"]`` is ``"max_iter"``)."""
    if info["stop_reason"] == "max_iter":
        warn_user(
            f"{REACHED_MAX_ITER}={max_iter} before points stopped moving "
            f"(largest move {info['max_move']:.2e} of the local size, tolerance {move_tolerance:g})",
        )


def warn_if_fixed_points_dropped(mesh, fixed_points, tolerance):
    """Warn of the user's ``fixed_points`` that are no vertex of ``mesh`` (none within ``tolerance``), and where.

    A fixed point in a corner sharper than the cells can fill (6 degrees at
    a size of a fiftieth of its sides) kept its cell, but the slivers
    between it and the rest of the mesh went as flat, and the repair took
    the cell left hanging at the tip: the mesh came back without the vertex
    the user asked for, and said nothing. The generators that run
    :func:`~terramesh.generate_mesh` with fixed points of their own (a strip's cut, an
    anisotropic start's metric corners) mute its warning and ask this of
    their own result with the user's points.
    """
    from scipy.spatial import cKDTree

    if len(fixed_points) == 0:
        return
    distance, nearest = cKDTree(mesh.points).query(fixed_points)
    dropped = np.flatnonzero(distance > tolerance)
    if len(dropped) == 0:
        return
    first = dropped[0]
    # the vertex nearest the point is another of the user's: the two were too close for a cell between them (a
    # ball's pole and a point 0.001 below it was blamed on "a corner sharper than the cells" the ball does not have)
    crowded = np.flatnonzero(np.linalg.norm(fixed_points - mesh.points[nearest[first]], axis=1) <= tolerance)
    if len(crowded):
        why = (
            f"another fixed point, {point_text(fixed_points[crowded[0]])}, is {distance[first]:.3g} from it, too "
            "close for a cell between them; give fixed points further apart than the sizes there"
        )
    else:
        why = (
            "the cells there were dropped, as the domain is narrower than the size about it (a corner sharper than "
            "the cells can fill, a thin spit); a smaller size there keeps it"
        )
    where = point_text(fixed_points[first])
    warn_user(f"{len(dropped)} of the {len(fixed_points)} {FIXED_DROPPED}, the first at {where}: {why}")
