"""Mesh a 3D box in slabs side by side, on MPI ranks or one after the other, and merge them.

The seismic DistMesh talk's parallel scheme for a velocity model's box. The
box is cut across its longest side into slabs of about equal estimated
vertex counts. Each cut plane's section (a rectangle) is meshed first, in
2D, by the size on the plane, its sides holding the points the slabs place
along their edges there. Both slabs beside a cut hold that mesh's vertices
fixed, and clear the plane of all their other points before their final
tetrahedralisation (:data:`CUT_CLEAR`). The plane is then a face of the
hull of each slab's points, which a Delaunay tetrahedralisation covers with
the Delaunay triangles of the points on it: the same triangles on both
sides, so the slabs meet face for face and are joined by their shared
points. Where they do not (``info["remeshed"]``), every point is
tetrahedralised and cleaned up again as one.
"""

import logging
import numbers
import time
import warnings

import numpy as np

from .._kernels.tetra import min_dihedral_all
from ..errors import GenerationError, TerrameshError, muted_warnings, warn_user
from ..generation.distances import finite_difference_step
from ..generation.distmesh import generate_mesh
from ..generation.distmesh3d import generate_mesh_3d_clearing
from ..generation.finalize3d import finalize_3d, polished_3d
from ..generation.fixed_points import CORNERS_DISPLACED, FIXED_NEAR_BOUNDARY
from ..generation.options import checked_options
from ..generation.sharp_edges import sampled_curves, sharp_edge_balls, sharp_edge_chains
from ..geometry.primitives import Rectangle
from ..geometry.primitives3d import Box
from ..mesh.mesh import Mesh
from ..mesh.topology import boundary_faces, checked_fixed_points

__all__ = ["generate_mesh_slabs", "slab_cuts", "section_points"]

logger = logging.getLogger("terramesh.parallel")

SLAB_SAMPLES = (256, 24)  # size samples along the cut axis and along each axis across it (the vertex count estimate)
THINNEST_SLAB = 1.5  # sizes (a slab's median): more parts than leave every slab this thick are refused
# sizes: a slab's free points this near a cut plane go before its final tetrahedralisation (those found so were on
# it: boundary points of the coarse level and the midpoints of its faces' edges, which its start refined)
CUT_CLEAR = 0.25
FIXED_CLEARANCE = 0.5  # sizes: a cut keeps this clear of the user's fixed points off it...
SHIFT_WINDOWS = (0.1, 0.3)  # ...moving, if it must, within this share of the thinner slab beside it...
SHIFTS = 21  # ...to the nearest of this many places that is clear
ON_CUT = 2e-3  # of FIXED_CLEARANCE sizes: a place for a cut this near a fixed point inside the box goes onto it
CUT_POLISH = 3.0


def generate_mesh_slabs(domain, edge_length, parts, comm, h0, fixed_points, seed, options):
    """:func:`~terramesh.parallel.generate_mesh_parallel` for a 3D domain (a :class:`Box` in more than one part).

    See there for the arguments; ``options`` are ``max_iter``,
    ``move_tolerance`` and ``levels``. One part is
    :func:`~terramesh.generate_mesh` of any 3D domain.
    """
    started = time.perf_counter()
    ranks = 1 if comm is None else comm.Get_size()
    given, parts = parts, ranks if parts is None else parts
    if isinstance(parts, bool) or not isinstance(parts, numbers.Integral) or parts < 1:
        raise GenerationError(f"parts must be a positive integer, got {parts!r}")
    max_iter, move_tolerance, levels = (
        options.get(k, d) for k, d in (("max_iter", 300), ("move_tolerance", 1e-2), ("levels", None))
    )
    if parts > 1 and type(domain) is not Box:
        raise GenerationError(
            f"3D domains are meshed in parts when they are a box (a velocity model's: "
            f"tm.geometry.primitives3d.Box), not a {type(domain).__name__}; give parts=1"
        )
    if parts == 1:
        return _one_part(domain, edge_length, comm, h0, fixed_points, seed, max_iter, move_tolerance, levels)
    # meshing in parts is imported from here by the 2D module's entry point: its helpers come late, to no cycle
    from .mesh_in_parts import failing_together, finish_merged, parts_of_ranks, said_once, shared_out, still_holds

    with failing_together(comm, "the cuts", alike=True):
        with warnings.catch_warnings(record=True) as caught:  # said once, below, by rank 0
            warnings.simplefilter("always")
            size, h0, tolerance, _, _, _, _ = checked_options(
                domain, edge_length, h0, domain.bbox, fixed_points, max_iter, move_tolerance, seed
            )
        user_fixed = (
            np.empty((0, 3)) if fixed_points is None else checked_fixed_points(fixed_points, 3, GenerationError)
        )
        with parts_of_ranks(comm, given):
            axis, cuts = slab_cuts(domain, size, parts, user_fixed)
    said_once(comm, [(str(warning.message), warning.category) for warning in caught])
    sections = _sections(comm, domain, size, h0, axis, cuts, user_fixed, seed)
    bounds = np.concatenate([[domain.bbox[0][axis]], cuts, [domain.bbox[1][axis]]])
    on_cut = np.isin(user_fixed[:, axis], cuts) if len(cuts) else np.zeros(len(user_fixed), dtype=bool)
    slab_options = dict(max_iter=max_iter, move_tolerance=move_tolerance, levels=levels)

    def mesh_slab(part):
        return _mesh_slab(
            domain, size, h0, axis, bounds, sections, user_fixed[~on_cut], part, seed, slab_options, still_holds
        )

    slabs = shared_out(
        comm,
        parts,
        mesh_slab,
        lambda part: f"slab {part} of {parts} ({'xyz'[axis]} {bounds[part]:g} to {bounds[part + 1]:g})",
    )
    if slabs is None:
        return None
    points, cells = _merged([slab[1] for slab in slabs], [slab[2] for slab in slabs], axis, cuts)
    faces = boundary_faces(cells)
    unmatched = _faces_left_on_cuts(points, faces, axis, cuts)
    if unmatched:
        # the slabs did not meet face for face: every point is tetrahedralised and cleaned up again as one
        warn_user(
            f"{unmatched} faces on the cuts {'xyz'[axis]} = {', '.join(f'{c:g}' for c in cuts)} belong to one slab "
            "only: the slabs' points were tetrahedralised again as one mesh"
        )
        mesh = _remeshed(domain, size, h0, tolerance, points, axis, cuts, bounds, user_fixed)
    else:
        mesh = Mesh(_polished_near_cuts(domain, size, points, cells, faces, axis, cuts, user_fixed), cells)
    smallest = float(np.min(min_dihedral_all(mesh.points, mesh.cells)))
    finish_merged(
        mesh, slabs, user_fixed, tolerance, axis, cuts, started, h0, remeshed=bool(unmatched), min_dihedral=smallest
    )
    return mesh


def _one_part(domain, edge_length, comm, h0, fixed_points, seed, max_iter, move_tolerance, levels):
    """The whole domain meshed on rank 0 (None on the others), as :func:`~terramesh.generate_mesh` meshes it."""
    if comm is not None and comm.Get_rank() != 0:
        return None
    mesh = generate_mesh_3d_clearing(
        domain, edge_length, h0, None, fixed_points, max_iter, move_tolerance, seed, levels
    )
    mesh.info.update(parts=[dict(mesh.info, rank=0)], axis=None, cuts=[], remeshed=False)
    return mesh


def slab_cuts(domain, size, parts, fixed_points=None):
    """Where to cut a 3D box into ``parts`` slabs of about equal vertex counts: ``(axis, positions)``.

    The slabs lie across the bbox's longest side (``axis``); the vertex
    count is estimated by the integral of ``sqrt(2) / h**3`` on a sample of
    ``SLAB_SAMPLES`` sizes. A cut that comes within ``FIXED_CLEARANCE``
    (0.5) sizes of one of ``fixed_points`` moves to the nearest place
    clear of them, within a tenth of the thinner slab beside it (three
    tenths where that finds none: ``SHIFT_WINDOWS``). A fixed point half a
    size or more inside the box's faces stays on a cut within ``1e-3`` of
    its size of it, the cut moved onto it to the bit (a vertex of the cut's
    section).

    Parameters
    ----------
    domain : Domain
        A 3D domain with a ``bbox``.
    size : callable
        Edge length, ``(n, 3) -> (n,)``.
    parts : int
        Number of slabs: at most as many as leave each ``THINNEST_SLAB``
        (1.5) of its sizes thick (the median of the sample in it).
    fixed_points : array_like, shape (m, 3), optional
        The user's fixed points.

    Returns
    -------
    axis : int
        0, 1 or 2: the cuts are at constant ``'xyz'[axis]``.
    positions : numpy.ndarray, shape (parts - 1,)
        The cuts' coordinates, ascending, in the domain's units.

    Raises
    ------
    GenerationError
        For more parts than the box takes (the message names the most),
        fixed points that no place near a cut keeps clear of, or cuts so
        moved that a slab is too thin.

    Examples
    --------
    >>> import numpy as np
    >>> from terramesh.geometry.primitives3d import Box
    >>> axis, cuts = slab_cuts(Box((0, 0, 0), (4, 1, 1)), lambda p: np.full(len(p), 0.1), 4)
    >>> axis, np.round(cuts, 6).tolist()
    (0, [1.0, 2.0, 3.0])
    """
    bbox = np.asarray(domain.bbox, dtype=np.float64)
    axis = int(np.argmax(bbox[1] - bbox[0]))
    across = [a for a in range(3) if a != axis]
    along_samples, across_samples = SLAB_SAMPLES
    fractions = [(np.arange(n) + 0.5) / n for n in (along_samples, across_samples, across_samples)]
    grid = np.stack(np.meshgrid(*fractions, indexing="ij"), axis=-1).reshape(-1, 3)
    sample = np.empty_like(grid)
    for column, a in zip(range(3), [axis, *across], strict=True):
        sample[:, a] = bbox[0, a] + grid[:, column] * (bbox[1, a] - bbox[0, a])
    sizes = np.asarray(size(sample), dtype=np.float64).reshape(along_samples, -1)
    work = np.concatenate([[0.0], np.cumsum(np.mean(np.sqrt(2.0) / sizes**3, axis=1))])
    positions = bbox[0, axis] + np.linspace(0.0, 1.0, along_samples + 1) * (bbox[1, axis] - bbox[0, axis])

    def balanced(count):
        return np.interp(np.arange(1, count) / count * work[-1], work, positions)

    def thick_enough(cuts):
        bounds = np.concatenate([[positions[0]], cuts, [positions[-1]]])
        slice_of = np.clip(np.searchsorted(positions, bounds) - 1, 0, along_samples - 1)
        return all(
            bounds[k + 1] - bounds[k]
            >= THINNEST_SLAB * np.median(sizes[slice_of[k] : max(slice_of[k + 1], slice_of[k] + 1)])
            for k in range(len(bounds) - 1)
        )

    cuts = balanced(parts)
    if not thick_enough(cuts):
        most = next((count for count in range(parts - 1, 0, -1) if thick_enough(balanced(count))), 1)
        raise GenerationError(
            f"parts={parts} is more slabs than the box can be cut into at these sizes: at most {most} (slabs at "
            f"least {THINNEST_SLAB:g} sizes thick); give fewer parts"
        )
    fixed = np.empty((0, 3)) if fixed_points is None else np.asarray(fixed_points, dtype=np.float64).reshape(-1, 3)
    if len(fixed) == 0:
        return axis, cuts
    reach = FIXED_CLEARANCE * np.asarray(size(fixed), dtype=np.float64)
    # a fixed point on a cut is a vertex of its section, but not one within reach of the box's faces: on them it
    # would lie on a sharp edge of both slabs beside their own points (two such 0.15 sizes apart, a slab refused),
    # and nearer than 1e-3 h the section merged it into a point of its rim
    inside = np.all((fixed - bbox[0] >= reach[:, None]) & (bbox[1] - fixed >= reach[:, None]), axis=1)
    balanced_bounds = np.concatenate([[positions[0]], cuts, [positions[-1]]])
    for k, cut in enumerate(balanced_bounds[1:-1]):
        # within a share of the thinner slab beside it: two cuts moving toward each other keep the slab between
        # them in order and 40 % of its thickness (a share of the slabs' mean put a cut past its neighbour)
        room = min(np.diff(balanced_bounds[k : k + 3]))
        for share in SHIFT_WINDOWS:
            offsets = share * room * np.linspace(-1.0, 1.0, SHIFTS)
            places = cut + offsets[np.argsort(np.abs(offsets), kind="stable")]  # the balanced place first
            gaps = np.abs(fixed[:, axis, None] - places[None, :])
            # a place within ON_CUT sizes of a fixed point inside goes onto it, to the bit (a point at x = 1.0 by a
            # cut the vertex counts put at 0.99999999999999520 was otherwise a point to keep clear of)
            onto = np.where(inside[:, None] & (gaps <= ON_CUT * reach[:, None]), gaps, np.inf)
            snapped = np.isfinite(onto).any(axis=0)
            places[snapped] = fixed[np.argmin(onto[:, snapped], axis=0), axis]
            gaps = np.abs(fixed[:, axis, None] - places[None, :])
            clear = np.all((gaps >= reach[:, None]) | ((gaps == 0.0) & inside[:, None]), axis=0)
            if clear.any():
                cuts[k] = places[np.argmax(clear)]
                break
        else:
            near = fixed[np.argmin(np.abs(fixed[:, axis] - cut) / reach)]
            raise GenerationError(
                f"no place for the cut near {'xyz'[axis]} = {cut:g} (within {SHIFT_WINDOWS[-1]:g} of the thinner slab "
                f"beside it) keeps {FIXED_CLEARANCE:g} sizes clear of the fixed points, e.g. {near.tolist()}: with "
                f"fixed points this close together along {'xyz'[axis]}, mesh in fewer parts or in one"
            )
    if not thick_enough(cuts):
        raise GenerationError(
            f"the cuts moved to keep clear of the fixed points left a slab thinner than {THINNEST_SLAB:g} sizes: "
            "give fewer parts"
        )
    return axis, cuts


def section_points(domain, size, h0, axis, cut, fixed_points=None, seed=0):
    """The vertices of a 2D mesh of the box's section at ``'xyz'[axis] = cut``, as 3D points on the plane; (k, 3).

    The section is meshed by ``size`` on the plane (:func:`~terramesh.generate_mesh`),
    its sides holding the points a slab of the box places along its edges
    there (its sharp edges sampled by ``size`` and ``h0``), so that both
    slabs beside the cut hold the same points. ``fixed_points`` (3D, on the
    plane) are vertices too.
    """
    low, high = (np.array(corner, dtype=np.float64) for corner in domain.bbox)
    below = high.copy()
    below[axis] = cut
    on_plane = [
        edge for edge in Box(low, below).sharp_edges() if edge(np.array([0.0, 1.0]))[:, axis].tolist() == [cut, cut]
    ]
    rim = np.concatenate(sampled_curves(on_plane, size, h0))
    across = [a for a in range(3) if a != axis]

    def embedded(plane_points):
        points = np.empty((len(plane_points), 3))
        points[:, axis], points[:, across] = cut, plane_points
        return points

    given = np.empty((0, 3)) if fixed_points is None else np.asarray(fixed_points, dtype=np.float64).reshape(-1, 3)
    held = np.unique(np.vstack([rim, given])[:, across], axis=0)
    # the rim's points are fixed on the boundary on purpose, where they displace the rectangle's corners
    with muted_warnings(FIXED_NEAR_BOUNDARY, CORNERS_DISPLACED):
        section = generate_mesh(
            Rectangle(low[across], high[across]), lambda q: size(embedded(q)), h0=h0, fixed_points=held, seed=seed
        )
    return embedded(section.points)


def _sections(comm, domain, size, h0, axis, cuts, fixed, seed):
    """Each cut's :func:`section_points`, shared out over ``comm``'s ranks and gathered on all of them.

    A section that raises makes every rank raise, naming it and its rank
    (:func:`~terramesh.parallel.mesh_in_parts.failing_together`).
    """
    from .mesh_in_parts import failing_together

    rank, ranks = (0, 1) if comm is None else (comm.Get_rank(), comm.Get_size())
    mine = {}
    with failing_together(comm, None) as step:
        for k in range(rank, len(cuts), ranks):
            step.where = f"the section at {'xyz'[axis]} = {cuts[k]:g}"
            try:
                mine[k] = section_points(domain, size, h0, axis, cuts[k], fixed[fixed[:, axis] == cuts[k]], seed)
            except TerrameshError as error:  # a sizing error, say: named as it is
                if comm is not None:
                    raise
                raise type(error)(f"{step.where}: {error}") from error
    if comm is not None:
        mine = {k: points for gathered in comm.allgather(mine) for k, points in gathered.items()}
    return [mine[k] for k in range(len(cuts))]


def _mesh_slab(domain, size, h0, axis, bounds, sections, fixed, part, seed, options, kept):
    """Mesh slab ``part`` (between ``bounds[part]`` and the next): ``(points, cells, info, said)``.

    It holds its cuts' sections and the user's ``fixed`` points in it (none
    on a cut: those are in the sections), and its free points within
    ``CUT_CLEAR`` sizes of a cut go before its final tetrahedralisation.
    ``said`` holds its warnings that ``kept`` says still hold once merged.
    """
    low, high = (np.array(corner, dtype=np.float64) for corner in domain.bbox)
    low[axis], high[axis] = bounds[part], bounds[part + 1]
    planes = [bounds[k] for k in (part, part + 1) if 0 < k < len(bounds) - 1]
    holds = fixed[(fixed[:, axis] >= low[axis]) & (fixed[:, axis] <= high[axis])]
    held = np.vstack([*(sections[k] for k in (part - 1, part) if 0 <= k < len(sections)), holds])

    def clear(points, level_size):
        gaps = np.abs(points[:, axis, None] - np.asarray(planes)[None, :])
        return np.any(gaps < CUT_CLEAR * level_size(points)[:, None], axis=1)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = generate_mesh_3d_clearing(
            Box(low, high),
            size,
            h0,
            None,
            held,
            options["max_iter"],
            options["move_tolerance"],
            seed + part,
            options["levels"],
            clear,
        )
    said = [(str(warning.message), warning.category) for warning in caught if kept(str(warning.message))]
    return mesh.points, mesh.cells, mesh.info, said


def _merged(points, cells, axis, cuts):
    """The slabs' ``points`` and ``cells`` as one mesh, the points two slabs share on a cut (to the bit) made one."""
    offsets = np.cumsum([0] + [len(p) for p in points])
    every = np.vstack(points)
    joined = np.vstack([c + offset for c, offset in zip(cells, offsets, strict=False)])
    shared = np.flatnonzero(np.isin(every[:, axis], cuts))
    index = np.arange(len(every))
    _, first, inverse = np.unique(every[shared], axis=0, return_index=True, return_inverse=True)
    index[shared] = shared[first][inverse.ravel()]
    kept = np.ones(len(every), dtype=bool)
    kept[shared] = False
    kept[shared[first]] = True
    renumber = np.cumsum(kept) - 1
    return every[kept], renumber[index][joined]


def _faces_left_on_cuts(points, faces, axis, cuts):
    """How many of the merged mesh's boundary ``faces`` lie on a cut: faces one slab has and the other lacks."""
    along = points[faces, axis]
    on = np.isin(along[:, 0], cuts) & (along[:, 0] == along[:, 1]) & (along[:, 0] == along[:, 2])
    return int(np.count_nonzero(on))


def _polished_near_cuts(domain, size, points, cells, faces, axis, cuts, fixed):
    """``points`` with the interior vertices within ``CUT_POLISH`` sizes of a cut smoothed where no cell gets worse.

    Each slab's cells settled against the fixed points of its cuts, which
    the merged mesh frees (:func:`~terramesh.generation.finalize3d.polished_3d`;
    ``faces`` are its boundary faces); the user's ``fixed`` points stay.
    """
    on_boundary = np.zeros(len(points), dtype=bool)
    on_boundary[faces.ravel()] = True
    gaps = np.min(np.abs(points[:, axis, None] - np.asarray(cuts)[None, :]), axis=1)
    movable = ~on_boundary & (gaps < CUT_POLISH * size(points)) & ~_at(points, fixed)
    return polished_3d(domain, points, cells, movable, on_boundary, np.zeros(len(points), dtype=bool), None)[0]


def _at(points, fixed):
    """Mask of the ``points`` that are one of the ``fixed`` points (the nearest to each, where within 1e-12 of it)."""
    from scipy.spatial import cKDTree

    mask = np.zeros(len(points), dtype=bool)
    if len(fixed) and len(points):
        distance, nearest = cKDTree(points).query(fixed)
        mask[nearest[distance <= 1e-12 * max(1.0, float(np.max(np.abs(points))))]] = True
    return mask


def _remeshed(domain, size, h0, tolerance, points, axis, cuts, bounds, fixed):
    """All the slabs' ``points`` tetrahedralised and cleaned up as one mesh, their fixed ones held.

    Held: the points on the cuts, on the box's edges (the slabs' sharp
    edges' points) and the user's fixed points.
    """
    low, high = (np.asarray(corner, dtype=np.float64) for corner in domain.bbox)
    on_edges = np.sum((points == low) | (points == high), axis=1) >= 2
    held = on_edges | np.isin(points[:, axis], cuts) | _at(points, fixed)
    chains = []
    for k in range(len(bounds) - 1):
        slab_low, slab_high = low.copy(), high.copy()
        slab_low[axis], slab_high[axis] = bounds[k], bounds[k + 1]
        chains += sharp_edge_chains(Box(slab_low, slab_high), size, h0)
    ordered = np.vstack([points[held], points[~held]])
    return finalize_3d(
        domain,
        size,
        ordered,
        int(held.sum()),
        tolerance,
        finite_difference_step(h0, domain.bbox),
        sharp_edge_balls(domain, chains, tolerance),
    )
