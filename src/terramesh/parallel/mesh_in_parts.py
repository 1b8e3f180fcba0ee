"""Mesh a 2D domain in strips side by side, on MPI ranks or one after the other, and merge them."""

import contextlib
import logging
import time
import types
import warnings

import numpy as np

from .._kernels.smoothing import raise_worst, smooth_interior
from ..cleanup.disjoint import cell_components
from ..cleanup.fix_mesh import remove_unused_points
from ..errors import GenerationError, TerrameshWarning, warn_user
from ..generation.adapt import restarted
from ..generation.distmesh import generate_mesh
from ..generation.finalize import OFF_BOUNDARY, POLISH_PASSES, POOR_QUALITY
from ..generation.fixed_points import CORNER_REACH, CORNERS_DISPLACED, FIXED_NEAR_BOUNDARY, turning_mask
from ..generation.mesh_checks import FIXED_DROPPED, warn_if_fixed_points_dropped, warn_if_rings_missed
from ..generation.options import checked_options
from ..geometry.base import FunctionDomain, as_domain
from ..geometry.primitives import Rectangle
from ..mesh.mesh import Mesh
from ..mesh.topology import (
    any_corner_in,
    boundary_edges,
    boundary_vertex_degree,
    lowest_twins,
    signed_areas,
)
from ..quality.triangle import triangle_quality
from .decompose import separator_points, strip_cuts

__all__ = ["generate_mesh_parallel"]

logger = logging.getLogger("terramesh.parallel")

_STRIP_OPTIONS = {"max_iter", "move_tolerance", "levels"}  # generate_mesh's, besides those named
_ON_CUT = 1e-14  # relative: a point this near a cut is on it
_STRIP_MARGIN = 0.1  # a strip reaches this share of the bbox beyond it across the cuts, so it adds no corners there
CUT_POLISH = 3.0  # interior vertices this many local sizes from a cut are polished once the strips are merged
SEAM_REACH = 3.0  # where strips do not meet, the cells with a vertex within this many local sizes of the mismatch go...
HOLD_REACH = 3.5  # ...and are meshed anew among the kept vertices within this many sizes of theirs, which stay...
BEYOND_REACH = 1.5  # ...and no cell within this many sizes of a kept vertex farther out (0.75 took 5x the time)
PATCH_TRIES = 3  # times the patch may grow about the vertices where its new cells do not join the kept ones
LOCATE_AMONG = 12  # a point is looked for in the triangles with the nearest this many centroids
# a strip narrower than this many sizes squeezes its cells between the fixed points of its cuts. Meshing a disk
# and a 2 x 1 rectangle at h 0.1 and 0.05 in ever more strips: with the narrowest strip 1.5 to 4 sizes wide, min
# quality 0.76-0.84 and mean 0.94-0.97 (whole: 0.80-0.83 and 0.99); 1.1 to 1.3 sizes, min 0.65-0.71 and mean
# 0.89-0.92; 0.4 and 0.2 sizes, min 0.59 and 0.23, mean 0.72 and 0.57
NARROWEST_STRIP = 1.5
QUALITY_DROP = 0.5  # merged cells by a cut poorer than this share of the strips' worst are warned of
ISOLATED_CORNER = 1.0  # a corner by a cut with no other this many sizes away is kept in the strips (an anchor)


def generate_mesh_parallel(
    domain, edge_length=None, *, parts=None, comm=None, h0=None, fixed_points=None, seed=0, **options
):
    """Mesh a 2D domain in strips (a 3D box in slabs), each as :func:`~terramesh.generate_mesh` would, and merge them.

    The seismic DistMesh talk's parallel scheme. A 3D domain (more than
    one part: a :class:`~terramesh.geometry.primitives3d.Box`, as a velocity
    model's sizes give) is cut into slabs across its longest side, each
    cut's section meshed first and held by the slabs on both sides, which
    then meet face for face (:mod:`~terramesh.parallel.mesh_in_slabs`); the
    merged mesh's interior vertices along the cuts are smoothed. In 2D the
    domain is cut into
    ``parts`` strips of about equal vertex counts, each cut moved a little to
    keep its points clear of the boundary (:func:`strip_cuts`); the
    points along each cut (:func:`separator_points`) are fixed in both
    strips beside it, so their meshes meet vertex for vertex there; each
    strip is meshed on its own (with seed ``seed + its index``), and the
    meshes are joined by those shared points. Where two strips do not meet
    vertex for vertex all the same (a cut crossing a coast at a shallow
    angle, or a feature narrower than the size: one strip's cells fall
    short of the cut, it puts a vertex of its own there, or the two touch
    at one point of the cut only), the cells with a vertex within
    ``SEAM_REACH`` (3) sizes of the mismatch are meshed anew, with the
    strips' vertices around them held where they are, and the new cells
    meet the kept ones vertex for vertex (more cells go where they would
    not, across the spikes of a jagged coast): every other cell stays
    exactly as its strip made it. Where even that fails, every point is
    meshed anew from where it is (``info["remeshed"]``, logged as a
    warning).
    With an MPI communicator the strips are shared out over its ranks (rank
    ``r`` meshes strips ``r``, ``r + size``, ...) and gathered on rank 0;
    without one they are meshed here one after the other, with the same
    result.

    Parameters
    ----------
    domain : Domain or callable
        A 2D domain (signed distance, negative inside, with a ``bbox``), or
        a 3D one (a ``Box`` in more than one part).
    edge_length : float, callable or SizeGrid, optional
        Target edge length, as for :func:`~terramesh.generate_mesh`.
    parts : int, optional
        Number of strips; defaults to the communicator's size (1 without
        one: then this is :func:`~terramesh.generate_mesh`).
    comm : mpi4py.MPI.Comm, optional
        Communicator whose ranks mesh the strips (every rank calls this
        function with the same arguments). mpi4py is the ``mpi`` extra:
        ``pip install "terramesh[mpi]"``, run with ``mpiexec -n 4 python ...``.
    h0, fixed_points, seed
        As for :func:`~terramesh.generate_mesh` (``h0`` is the same in
        every strip; fixed points go to the strips that hold them).
    **options
        Further options of :func:`~terramesh.generate_mesh` (``max_iter``,
        ``move_tolerance``, ``levels``).

    Returns
    -------
    Mesh or None
        The merged mesh on rank 0 (or without a communicator), valid as
        :func:`~terramesh.generate_mesh`'s; None on the other ranks.
        ``mesh.info`` holds ``parts`` (each strip's own info, with its
        ``rank``), ``axis`` and ``cuts`` (where the strips meet),
        ``remeshed`` (True where the stitching fell back to meshing every
        point anew), ``stitched`` (how many boundary vertices of the merged strips lay
        off the domain's boundary or on other than two boundary edges, and
        were meshed anew with their surroundings; usually 0), and
        ``seconds``. In 3D ``remeshed`` is True where the slabs did not
        meet face for face and all their points were tetrahedralised again
        as one (with a warning), and ``min_dihedral`` is the merged mesh's.

    Warns
    -----
    TerrameshWarning
        Where a strip is narrower than ``NARROWEST_STRIP`` (1.5) sizes: its
        cells are squeezed between its cuts' fixed points. Where the merged
        cells at a cut are poorer than ``QUALITY_DROP`` (0.5) times the
        strips' worst: the strips did not meet vertex for vertex there.
        What :func:`~terramesh.generate_mesh` warns of, said once (not once
        per strip or rank), and of the strips' runs only what still holds
        of the merged mesh. Under MPI, rank 0 alone warns; a warning of the
        user's options made an error (``python -W error``) is raised on
        every rank, before the strips are meshed.

    Raises
    ------
    GenerationError
        For a domain that is neither 2D nor 3D, a 3D domain in parts that is
        no box, bad ``parts`` or ``seed``, more parts than the domain can be
        cut into at the sizes (strips under half a size wide on average,
        slabs under 1.5 sizes thick: it names the most), fixed points that
        no place for a slab's cut nearby keeps half a size clear of, cuts so
        moved that a slab is too thin, a section, strip or slab that cannot
        be meshed (named, with its bounds: a piece too thin for the size),
        or strips that still do not meet once stitched (it names the cut).
        Under MPI a step that fails on some ranks only (placing the cuts, a
        section, a part) makes every rank raise, naming the step, the rank
        and the error (none is left waiting for it); an error every rank
        meets alike in placing the cuts (bad arguments) is raised as it is.

    Examples
    --------
    >>> import terramesh as tm
    >>> mesh = tm.parallel.generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=3)
    >>> tm.cleanup.mesh_problems(mesh), len(mesh.info["parts"])
    ([], 3)
    >>> box = tm.geometry.primitives3d.Box((0, 0, 0), (3, 1, 1))
    >>> mesh = tm.parallel.generate_mesh_parallel(box, 0.25, parts=2)
    >>> tm.cleanup.mesh_problems(mesh), round(mesh.info["cuts"][0], 6), mesh.info["remeshed"]
    ([], 1.5, False)
    """
    started = time.perf_counter()
    domain = as_domain(domain)
    unknown = sorted(set(options) - _STRIP_OPTIONS)
    if unknown:
        raise GenerationError(
            f"unknown option {unknown[0]!r}; generate_mesh_parallel passes on {sorted(_STRIP_OPTIONS)}"
        )
    if domain.dim == 3:
        from .mesh_in_slabs import generate_mesh_slabs

        return generate_mesh_slabs(domain, edge_length, parts, comm, h0, fixed_points, seed, options)
    if domain.dim != 2:
        raise GenerationError(f"generate_mesh_parallel meshes 2D and 3D domains, got dim={domain.dim}")
    given, parts = parts, (1 if comm is None else comm.Get_size()) if parts is None else parts
    bbox = domain.bbox
    max_iter, move_tolerance = options.get("max_iter", 300), options.get("move_tolerance", 1e-2)
    with failing_together(comm, "the cuts", alike=True):
        with warnings.catch_warnings(record=True) as caught:  # said once, below, by rank 0
            warnings.simplefilter("always")
            size, h0, tolerance, fixed, _, _, _ = checked_options(
                domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed
            )
        with parts_of_ranks(comm, given):
            axis, cuts = strip_cuts(domain, size, parts, h0, fixed_points)
        # the user's fixed points and the domain's corners by the cuts go to the strips that hold them, and a
        # cut's points give way to them: a corner that a cut's point came within CORNER_REACH of was dropped by
        # its strip, and its cells cut across it or reached past it (four combs in 2-7 strips, 24 runs: 48
        # corners lost, the area off by up to 0.2 %, mesh_problems silent); one the strips lose all the same is a
        # seam point
        user_fixed = (
            np.empty((0, 2)) if fixed_points is None else np.asarray(fixed_points, dtype=np.float64).reshape(-1, 2)
        )
        anchors = _anchors(domain, size, fixed, user_fixed, tolerance, axis, cuts)
        separators = [_beside_fixed(separator_points(domain, size, h0, axis, cut), anchors, size) for cut in cuts]
        bounds = np.concatenate([[bbox[0][axis]], cuts, [bbox[1][axis]]])
        said = [(str(warning.message), warning.category) for warning in caught]
        narrow = _narrow_strips(size, axis, bounds, separators)
    said_once(comm, said + ([(narrow, TerrameshWarning)] if narrow else []))
    mine = shared_out(
        comm,
        parts,
        lambda part: _mesh_strip(domain, size, h0, axis, bounds, separators, anchors, part, seed, options),
        lambda part: f"strip {part} of {parts} ({'xy'[axis]} {bounds[part]:g} to {bounds[part + 1]:g})",
    )
    if mine is None:
        return None
    mesh = _merged([strip[1] for strip in mine], [strip[2] for strip in mine], axis, cuts)
    mesh = _polished_near_cuts(domain, size, mesh, axis, cuts, anchors)
    lost = _lost_at_cuts(anchors, mesh, tolerance, axis, cuts, size)
    seam = np.vstack([mesh.points[_mismatched(domain, mesh, tolerance)], lost])
    stitched = len(seam)
    if stitched:
        # a strip's cells fell short of a cut, it put a vertex of its own there, or two strips touch at
        # a point of it only (the cut crosses a coast at a shallow angle, or a feature narrower than the
        # size), or a strip lost a corner (a cut along a tooth of the domain left a sliver of it, a fraction
        # of a size wide, to the strip): the cells about the mismatch are meshed anew, the rest staying as they are
        mesh = _stitched(domain, size, h0, tolerance, fixed, mesh, seam, max_iter, move_tolerance, lost)
        _check_strips_meet(domain, mesh, tolerance, axis, cuts, user_fixed, size)
    poorer = _poorer_at_cuts(mesh, [strip[1:3] for strip in mine], axis, cuts, size)
    if poorer:
        warn_user(poorer)
    if len(bounds) > 2:  # a strip is the domain cut by a rectangle, whose pieces it cannot tell: the whole is looked at
        warn_if_rings_missed(mesh, domain, size, tolerance)
    finish_merged(mesh, mine, user_fixed, tolerance, axis, cuts, started, h0, stitched=stitched)
    mesh.info["remeshed"] = bool(mesh.info.get("remeshed", False))
    return mesh


@contextlib.contextmanager
def parts_of_ranks(comm, given):
    """Say that the ranks set the count where ``given`` parts (None: one per rank of ``comm``) are too many.

    ``mpiexec -n 2`` on a box too small for two parts said "--parts 2 is more
    slabs than the box can be cut into" to a user who gave no ``--parts``.
    """
    try:
        yield
    except GenerationError as error:
        if given is not None or comm is None or not str(error).startswith("parts="):
            raise
        ranks = comm.Get_size()
        raise GenerationError(
            f"{ranks} MPI ranks mesh {ranks} parts unless parts is given: {error}; or run on fewer ranks (ranks "
            "beyond the parts wait)"
        ) from error


def shared_out(comm, parts, work, where):
    """``work(part)`` for each part, shared over ``comm``'s ranks: on rank 0 ``[(part, *result, rank), ...]`` in order.

    Rank ``r`` does parts ``r``, ``r + size``, ...; the results are gathered
    on rank 0, the other ranks get None. A part that raises makes every
    rank raise a :class:`GenerationError` naming it (``where(part)``) and
    its rank (:func:`failing_together`): each still reaches the gather, where
    the others would wait for it for ever. Without ``comm`` the parts run
    here in turn, and a :class:`GenerationError` of one of several parts is
    raised naming it.
    """
    rank, ranks = (0, 1) if comm is None else (comm.Get_rank(), comm.Get_size())
    mine = []
    with failing_together(comm, None) as step:
        for part in range(rank, parts, ranks):
            step.where = where(part)
            try:
                mine.append((part, *work(part), rank))
            except GenerationError as error:
                if comm is not None or parts == 1:
                    raise
                # the whole may mesh: say which part did not
                raise GenerationError(f"{step.where}: {error}; fewer parts may do") from error
    if comm is None:
        return mine
    gathered = comm.gather(mine, root=0)
    if rank != 0:
        return None
    return sorted((result for results in gathered for result in results), key=lambda result: result[0])


@contextlib.contextmanager
def failing_together(comm, where, alike=False):
    """Run the body on each rank of ``comm``; where it raises on any, raise on every rank, leaving none waiting.

    Each rank runs the body to its end or its first error, and then every
    rank learns what the others' did (``allgather``): a step before a
    collective call that fails on one rank only (the user's size function
    out of memory there) left the others waiting in that call for ever.
    Every rank then raises a :class:`GenerationError` naming each failure's
    place, rank and error. Without ``comm`` the body's error is raised as it
    is.

    Parameters
    ----------
    comm : mpi4py.MPI.Comm or None
        The ranks that run the body together.
    where : str or None
        The step the body is, as its errors name it: ``"the cuts"``. The
        body may name its place as it goes (``step.where``, below).
    alike : bool, optional
        Every rank runs the same body on the same arguments: where every
        rank failed with the same error (bad arguments), each raises its own
        as it is, as one process would, rather than the same words once per
        rank.

    Yields
    ------
    step : types.SimpleNamespace
        Its ``where`` is ``where``, or the place the body set last.

    Raises
    ------
    GenerationError
        Under MPI, where the body raised on a rank (and, ``alike``, not
        alike on all): ``"meshing in parts failed: {where} on rank {r}: {type}:
        {message}"``, each failure joined by ``"; "``.
    """
    step = types.SimpleNamespace(where=where)
    error = failure = None
    try:
        yield step
    except Exception as caught:
        if comm is None:
            raise
        error, failure = caught, (step.where, f"{type(caught).__name__}: {caught}")
    if comm is None:
        return
    failures = comm.allgather(failure)
    if alike and failure is not None and all(other == failure for other in failures):
        raise error
    named = [f"{other[0]} on rank {rank}: {other[1]}" for rank, other in enumerate(failures) if other is not None]
    if named:
        raise GenerationError("meshing in parts failed: " + "; ".join(named)) from error


def finish_merged(mesh, results, fixed, tolerance, axis, cuts, started, h0, **info):
    """Say what the parts' runs warned of and the user's ``fixed`` points ``mesh`` lacks; fill in its ``info``.

    Each part's warnings (each result's fifth item) once, not once per part
    or rank, and after the collectives: raised as errors, they strand no
    rank. ``info`` gets ``parts`` (each part's own info with its ``rank``),
    ``axis``, ``cuts``, ``seconds`` (since ``started``), ``h0`` and the
    items given.
    """
    for message, category in dict.fromkeys(warning for result in results for warning in result[4]):
        warn_user(message, category)
    warn_if_fixed_points_dropped(mesh, fixed, tolerance)
    mesh.info.update(
        parts=[dict(result[3], rank=result[5]) for result in results],
        axis=axis,
        cuts=cuts.tolist(),
        seconds=time.perf_counter() - started,
        h0=h0,
        **info,
    )


def said_once(comm, said):
    """Issue the ``said`` warnings (``(message, category)`` pairs) on rank 0 alone; one raised there, every rank raises.

    Every rank finds the same warnings before the strips are meshed (the
    same arguments), but says none: the user reads each once. One that the
    user's filters make an error (``python -W error``) is sent to every
    rank, which raises it too: raised on rank 0 alone, before the gather,
    it left the others waiting there for ever.
    """
    rank = 0 if comm is None else comm.Get_rank()
    raised = None
    if rank == 0:
        try:
            for message, category in said:
                warn_user(message, category)
        except Warning as error:
            raised = error
    if comm is not None:
        raised = comm.bcast(raised, root=0)
    if raised is not None:
        raise raised


def _poorer_at_cuts(mesh, strips, axis, cuts, size):
    """The warning where the merged cells within ``CUT_POLISH`` sizes of a cut are far poorer than the strips' own.

    Those below ``QUALITY_DROP`` times the worst cell of the ``strips``
    (their ``(points, cells)``) were made where the strips met: a cut along
    a face the domain's distance reads as boundary (a union's inner face
    taken as a callable) had each strip put its own vertices along it, and
    the merge joined them with slivers that no other check sees. None
    where there are none.
    """
    if len(cuts) == 0:
        return None
    own = min(float(np.min(triangle_quality(points, cells))) for points, cells in strips)
    points, cells = mesh.points, mesh.cells
    near = np.min(np.abs(points[:, axis, None] - cuts[None, :]), axis=1) < CUT_POLISH * size(points)
    at_cuts = np.flatnonzero(near[cells].any(axis=1))
    quality = triangle_quality(points, cells[at_cuts])
    if len(quality) == 0 or quality.min() >= QUALITY_DROP * own:
        return None
    worst = points[cells[at_cuts[np.argmin(quality)]]].mean(axis=0)
    cut = cuts[np.argmin(np.abs(cuts - worst[axis]))]
    return (
        f"cells where the strips meet at the cut {'xy'[axis]} = {cut:g} reach quality {quality.min():.2g} "
        f"(e.g. at ({worst[0]:.6g}, {worst[1]:.6g})), the strips' own {own:.2g}: they did not meet vertex for "
        "vertex there; try another number of parts"
    )


def _anchors(domain, size, fixed, user_fixed, tolerance, axis, cuts):
    """The ``fixed`` points the strips keep: the user's (``user_fixed``), and corners by a cut where the boundary turns.

    A corner farther than a size from the cuts is a corner of its strip's
    domain, which its run keeps as the whole domain's would. A node on a
    straight side (a model box's nodes along its sides, there to start an
    even row of cells) gives way to a cut's point near it, as in a strip's
    own run: the boundary runs straight through it
    (:func:`~terramesh.generation.fixed_points.turning_mask`). So does
    a corner with another where the boundary turns within
    ``ISOLATED_CORNER`` sizes: a jagged coast's sharp vertices, a fraction
    of a size apart, which the whole domain's run thins too (there the
    stitch about each made poor cells: min q 0.07-0.36 where 0.37-0.50
    without).
    """
    from scipy.spatial import cKDTree

    given = cKDTree(user_fixed).query(fixed)[0] <= tolerance if len(user_fixed) else np.zeros(len(fixed), dtype=bool)
    if len(cuts) == 0 or len(fixed) == 0:
        return fixed[given]
    corners = np.asarray(domain.corners(), dtype=np.float64).reshape(-1, 2)
    corners = corners[np.min(np.abs(corners[:, axis, None] - cuts[None, :]), axis=1) < 2.0 * size(corners)]
    corners = corners[turning_mask(domain, size, corners)]
    near = np.min(np.abs(fixed[:, axis, None] - cuts[None, :]), axis=1) < size(fixed)
    if len(corners) == 0:
        return fixed[given]
    gaps = cKDTree(corners).query(fixed, [1, 2])[0]  # the first is the point itself, where it is a turning corner
    isolated = (gaps[:, 0] <= tolerance) & (gaps[:, 1] >= ISOLATED_CORNER * size(fixed))
    return fixed[given | (near & isolated)]


def _beside_fixed(points, anchors, size):
    """A cut's ``points`` but those within ``CORNER_REACH`` sizes of an anchor (:func:`_anchors`), standing for them.

    Both fixed, they made edges of a fraction of a size (0.31 of it from a
    receiver line 0.61 sizes apart across a cut: half the explicit time
    step); the strips then do not meet there, and the stitch meshes it.
    """
    if not len(anchors) or not len(points):
        return points
    from scipy.spatial import cKDTree

    gap = cKDTree(anchors).query(points)[0]
    return points[gap >= CORNER_REACH * size(points)]


def _narrow_strips(size, axis, bounds, separators):
    """The warning for strips narrower than ``NARROWEST_STRIP`` times the largest size on their cuts' points."""
    widths, largest = np.diff(bounds), np.zeros(len(bounds) - 1)
    for k, points in enumerate(separators):
        if len(points):
            largest[k : k + 2] = np.maximum(largest[k : k + 2], np.max(size(points)))  # the strips on both sides
    narrow = np.flatnonzero(widths < NARROWEST_STRIP * largest)
    if len(narrow):
        k = narrow[np.argmin(widths[narrow] / largest[narrow])]
        return (
            f"{len(narrow)} of {len(widths)} strips are narrower than {NARROWEST_STRIP:g} sizes, e.g. strip {k} "
            f"({'xy'[axis]} {bounds[k]:g} to {bounds[k + 1]:g}): {widths[k]:.3g} wide, sizes up to {largest[k]:.3g} "
            "along its cuts; its cells are squeezed between the cuts' fixed points (lower quality): "
            "fewer parts may do"
        )
    return None


def _mesh_strip(domain, size, h0, axis, bounds, separators, anchors, part, seed, options):
    """Mesh strip ``part`` (between ``bounds[part]`` and the next along ``axis``): ``(points, cells, info, said)``.

    ``said`` holds its run's warnings (``(message, category)`` pairs) that
    still hold once the strips are merged (:func:`still_holds`), to be said then.

    The ``anchors`` (:func:`_anchors`) it holds are fixed points of its run.
    """
    low, high = domain.bbox
    margin = _STRIP_MARGIN * (high - low)
    strip_low, strip_high = low - margin, high + margin
    strip_low[axis], strip_high[axis] = bounds[part], bounds[part + 1]
    beside = [separators[k] for k in (part - 1, part) if 0 <= k < len(separators)]
    holds = (anchors[:, axis] >= bounds[part]) & (anchors[:, axis] <= bounds[part + 1])
    fixed = np.concatenate([*beside, anchors[holds], np.empty((0, 2))])
    # one part is the whole domain, meshed as generate_mesh meshes it: intersected with the strip's
    # rectangle, sweep run 40122's random-walk coast was refused for a pinch that it meshes without
    strip = domain if len(bounds) == 2 else domain & Rectangle(strip_low, strip_high)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = generate_mesh(
            strip, size, h0=h0, fixed_points=fixed if len(fixed) else None, seed=seed + part, **options
        )
    said = [(str(warning.message), warning.category) for warning in caught if still_holds(str(warning.message))]
    return mesh.points, mesh.cells, mesh.info, said


def still_holds(message):
    """Whether a strip's warning ``message`` still holds of the merged mesh, to be said once it is merged.

    A cut's points and the corners by it are fixed near the boundary on
    purpose (the user's were warned of once, by generate_mesh_parallel),
    and the user's fixed points that the merged mesh lacks are warned of
    once, of it.
    A strip's boundary vertices off the boundary are mostly on its cuts,
    inside the merged mesh; those of the merged mesh are checked with the
    same tolerance (:func:`_mismatched`), stitched, and refused with an
    error where they stay: the strip's warning, with its advice to report
    a corner, misled (a slot 0.4 sizes wide by a cut, whose merged mesh
    lay within 2e-9 of the boundary).
    """
    return not any(words in message for words in (FIXED_NEAR_BOUNDARY, CORNERS_DISPLACED, OFF_BOUNDARY, FIXED_DROPPED))


def _merged(points, cells, axis, cuts):
    """One mesh of the strips' ``points`` and ``cells``, the points they share (to the bit) made one.

    A point within a few roundings of a cut is put on it exactly first: one
    that each strip projected onto the cut on its own lands there within an
    ulp of the other's.
    """
    offsets = np.cumsum([0] + [len(p) for p in points])
    points = np.concatenate(points)
    if len(cuts):
        along = points[:, axis]
        index = np.searchsorted(cuts, along)
        below, above = cuts[np.clip(index - 1, 0, len(cuts) - 1)], cuts[np.clip(index, 0, len(cuts) - 1)]
        for cut in (below, above):
            on = np.abs(along - cut) <= _ON_CUT * np.maximum(np.abs(cut), 1.0)
            points[on, axis] = cut[on]
    # only points on a cut can be shared: the rest keep their strip's (spatial) order
    representative = lowest_twins(points, np.isin(points[:, axis], cuts))
    kept = representative == np.arange(len(points))
    numbering = (np.cumsum(kept) - 1)[representative]
    cells = np.concatenate([numbering[c + offset] for c, offset in zip(cells, offsets, strict=False)])
    return Mesh(points[kept], cells)


def _polished_near_cuts(domain, size, mesh, axis, cuts, anchors):
    """The merged mesh with its interior vertices within ``CUT_POLISH`` sizes of a cut smoothed, quality-safe.

    A strip holds its cut's points fixed, and with sizes that change
    along the cut its cells there settle against points they cannot move:
    Persson's two circles in 3-5 strips had min q 0.68, 0.52 and 0.44 at
    the cuts, whole 0.80. Merged, those points are interior vertices like
    any other: the generator's last polish (moves to the mean of the
    neighbours that keep the star's worst cell, then of the vertices of
    cells below 0.8 to where their worst cell is best) runs on the
    vertices near the cuts, the boundary's and the user's fixed points
    staying. A cell whose centroid a move takes outside the domain (next
    to a concave boundary) freezes its vertices, and the polish runs again.
    """
    if len(cuts) == 0:
        return mesh
    points, cells = mesh.points, mesh.cells
    along = points[:, axis]
    near = np.min(np.abs(along[:, None] - cuts[None, :]), axis=1) < CUT_POLISH * size(points)
    # the cells of the vertices near the cuts hold their whole stars, and so every edge at them: the
    # polish and the boundary they need, on them alone (the whole mesh's boundary took 0.1 s at 920k vertices)
    star = cells[near[cells].any(axis=1)]
    movable = near.copy()
    movable[boundary_edges(star).ravel()] = False
    if len(anchors):
        from scipy.spatial import cKDTree

        movable[cKDTree(points).query(anchors)[1]] = False
    for _ in range(3):
        polished = points.copy()
        smooth_interior(polished, star, movable, POLISH_PASSES)
        raise_worst(polished, star, movable, POOR_QUALITY, POLISH_PASSES)
        touched = np.flatnonzero(np.any(polished != points, axis=1)[star].any(axis=1))
        outside = touched[domain.distance(polished[star[touched]].mean(axis=1)) > 0]
        if len(outside) == 0:
            return Mesh(polished, cells)
        movable[star[outside].ravel()] = False
    return mesh


def _mismatched(domain, mesh, tolerance):
    """The merged mesh's boundary vertices where two strips do not meet.

    Those off the domain's boundary (a strip's cells fell short of a cut)
    and those on other than two boundary edges (two strips touching at a
    cut's point only, where the cut crosses a neck of the domain).
    """
    degree = boundary_vertex_degree(mesh.cells, len(mesh.points))
    vertices = np.flatnonzero(degree)
    off = np.abs(domain.distance(mesh.points[vertices])) > tolerance
    return vertices[off | (degree[vertices] != 2)]


def _lost_at_cuts(anchors, mesh, tolerance, axis, cuts, size):
    """The ``anchors`` within a size of a cut that are no vertices of the merged ``mesh``, shape (k, 2).

    Farther from the cuts a strip loses a corner where the whole domain's
    run would (the clean-up takes poor cells at a jagged coast's corners:
    13 of 205 on a random walk of 1,000 vertices): those are not sought.
    """
    if len(anchors) == 0 or len(cuts) == 0:
        return np.empty((0, 2))
    from scipy.spatial import cKDTree

    near = np.min(np.abs(anchors[:, axis, None] - cuts[None, :]), axis=1) < size(anchors)
    return anchors[near & (cKDTree(mesh.points).query(anchors)[0] > tolerance)]


def _stitched(domain, size, h0, tolerance, fixed, mesh, seam, max_iter, move_tolerance, lost):
    """The merged ``mesh`` of the strips with its cells near the ``seam`` points meshed anew, the others kept.

    The cells with a vertex within ``SEAM_REACH`` sizes of the seam (the
    patch) go; their vertices are meshed anew (:func:`_patch_mesh`) among
    the kept vertices around, which stay, and the new cells fill the patch,
    meeting the kept ones vertex for vertex (:func:`_joined`). The cells
    beyond stay exactly as they are, to the bit. The domain's corners and
    the user's ``fixed`` points stay fixed, those the strips ``lost`` are
    put back (shape (k, 2), each a seam point), while the cut's own points,
    fixed only so that the strips would meet, may move. Where the new cells
    do not join the kept ones (a jagged coast's spikes of water between
    them), the patch grows about the vertices where they do not, up to
    ``PATCH_TRIES`` times; then the whole mesh is made again from its
    points, all of them free to move
    (:func:`~terramesh.generation.adapt.restarted`), and its ``info`` says
    ``remeshed``.
    """
    from scipy.spatial import cKDTree

    for _ in range(PATCH_TRIES):
        tree = cKDTree(seam)
        patch = any_corner_in(tree.query(mesh.points)[0] < SEAM_REACH * size(mesh.points), mesh.cells)
        local, held = _patch_mesh(domain, size, h0, tolerance, fixed, lost, mesh, patch, max_iter, move_tolerance)
        joined, apart = _joined(domain, tolerance, mesh, patch, held, local, tree, size)
        if joined is not None:
            logger.info("strips stitched: %d cells near %d seam vertices meshed anew", int(patch.sum()), len(seam))
            return joined
        seam = np.vstack([seam, apart])
    logger.warning(
        "strips stitched: the patch near %d seam vertices did not join; every point is meshed anew", len(seam)
    )
    # every point free: held where they were, the far points' Delaunay cells about a jagged coast were not the
    # strips' (the Danish straits in 6 strips kept a cap of q 0.09 at the coast, 3 sizes from a cut; 0.57 free)
    mesh = restarted(domain, size, h0, tolerance, np.vstack([fixed, lost]), mesh.points, None, max_iter, move_tolerance)
    return Mesh(mesh.points, mesh.cells, info={"remeshed": True})


def _patch_mesh(domain, size, h0, tolerance, fixed, lost, mesh, patch, max_iter, move_tolerance):
    """The ``patch`` cells' vertices meshed anew among the kept vertices around them, which stay: ``(mesh, held)``.

    The ``fixed`` points among those vertices stay where they are, and the
    ``lost`` ones within ``SEAM_REACH`` sizes of them are put back.

    ``held`` (indices into ``mesh.points``) are the kept cells' vertices
    within ``HOLD_REACH`` sizes of the patch's own: fixed points of the
    run, so that the patch's points feel the forces of their true
    neighbours and the run's cells around the patch are the kept ones
    wherever those are Delaunay. The run's domain leaves out what lies
    within ``BEYOND_REACH`` sizes of a kept vertex farther out: no cell
    spans the kept cells there, whose vertices are not in the run.
    """
    from scipy.spatial import cKDTree

    points, cells = mesh.points, mesh.cells
    on_kept = np.zeros(len(points), dtype=bool)
    on_kept[cells[~patch].ravel()] = True
    free = np.zeros(len(points), dtype=bool)
    free[cells[patch].ravel()] = True
    free = np.flatnonzero(free & ~on_kept)
    # the domain's corners and the user's fixed points among the patch's vertices stay where they are
    fixed = fixed[cKDTree(points[free]).query(fixed)[0] <= tolerance] if len(fixed) else fixed
    if len(lost):
        fixed = np.vstack([fixed, lost[cKDTree(points[free]).query(lost)[0] < SEAM_REACH * size(lost)]])
    # a kept vertex farther than this from the patch's vertices is held by none of them; its disk of
    # BEYOND_REACH sizes, by none of the patch's cells (sizes grade slowly over a few sizes)
    reach = 2.0 * (HOLD_REACH + BEYOND_REACH) * float(np.max(size(points[free])))
    low, high = points[free].min(axis=0) - reach, points[free].max(axis=0) + reach
    near = np.flatnonzero(on_kept & np.all((points >= low) & (points <= high), axis=1))
    close = cKDTree(points[free]).query(points[near])[0] < HOLD_REACH * size(points[near])
    held, beyond = near[close], near[~close]
    region = domain
    if len(beyond):
        anchors = points[beyond]
        radius = BEYOND_REACH * size(anchors)
        anchor_tree, nearest = cKDTree(anchors), list(range(1, min(8, len(anchors)) + 1))

        def away(at):
            # minus the distance to the union of the disks about the anchors: the sizes vary little
            # between neighbours, so one of the nearest few is the disk nearest
            distance, index = anchor_tree.query(at, nearest)
            return np.max(radius[index] - distance, axis=1)

        region = domain & FunctionDomain(away, (low, high))
    local = restarted(
        region, size, h0, tolerance, np.vstack([points[held], fixed]), points[free], None, max_iter, move_tolerance
    )
    return local, held


def _joined(domain, tolerance, mesh, patch, held, local, seam_tree, size):
    """The merged ``mesh`` with the ``local`` mesh's cells in the ``patch`` instead of its own: ``(mesh, apart)``.

    The local mesh's cells that are kept cells (the same three ``held``
    vertices, found by their exact coordinates) stay behind; the rest, from
    its cells near the seam (``seam_tree``) across the others, fill the
    patch. Where the run's Delaunay cells are not the kept ones next to the
    patch (a kept pair of cells not Delaunay, smoothed so), those kept cells
    go too, with the patch's. The mesh is None where the new cells do not
    join the kept ones (:func:`_unjoined`), or reach the edge of the run;
    ``apart`` holds the vertices where (shape (k, 2); none where they join).
    """
    points, cells = mesh.points, mesh.cells
    # the local mesh's vertices by their number in ``mesh``: the held ones are there to the bit, the others new
    twins = lowest_twins(np.vstack([points[held], local.points]), None)[len(held) :]
    number = np.full(len(local.points), -1, dtype=np.int64)
    number[twins < len(held)] = held[twins[twins < len(held)]]
    is_held = np.zeros(len(points), dtype=bool)
    is_held[held] = True
    around = np.flatnonzero(~patch & is_held[cells].all(axis=1))  # kept cells the local mesh may hold
    local_cells = number[local.cells]
    same = _rows_in(np.sort(local_cells, axis=1), np.sort(cells[around], axis=1))
    same &= np.all(local_cells >= 0, axis=1)
    known = _rows_in(np.sort(cells[around], axis=1), np.sort(local_cells[same], axis=1))
    # the new cells: those connected to a new vertex near the seam by cells that are no kept ones (the
    # run's points put in where its domain was cut short, far from the seam, are new too)
    new_vertex = (number < 0) & (seam_tree.query(local.points)[0] < (SEAM_REACH + 1.0) * size(local.points))
    seeds = any_corner_in(new_vertex, local.cells)
    filling = _reached(local.cells, ~same, seeds)
    # the local mesh's boundary off the domain's is where its run was cut short: the filling keeps clear of it
    rim = boundary_edges(local.cells).ravel()
    rim = rim[np.abs(domain.distance(local.points[rim])) > tolerance]
    reached = np.intersect1d(local.cells[filling], rim)
    if len(reached):
        return None, local.points[reached]
    # the merged cells they replace: the patch's, and the kept ones the local mesh does not hold under them
    # (found by their centroids: a kept cell may touch the patch at a vertex only, across a coast's inlet
    # that the local mesh spans)
    replaced = patch.copy()
    unheld = around[~known]
    replaced[unheld] = _located(points[cells[unheld]].mean(axis=1), local.points, local.cells[filling])
    new = np.flatnonzero(number < 0)
    number[new] = len(points) + np.arange(len(new))
    joined_points = np.vstack([points, local.points[new]])
    joined_cells = np.vstack([cells[~replaced], number[local.cells[filling]]])
    joined_points, joined_cells, _ = remove_unused_points(joined_points, joined_cells)
    touched = np.zeros(len(joined_points), dtype=bool)
    touched[joined_cells[len(cells) - int(replaced.sum()) :].ravel()] = True
    apart = _unjoined(domain, tolerance, joined_points, joined_cells, touched)
    if len(apart):
        return None, joined_points[apart]
    return Mesh(joined_points, joined_cells), joined_points[apart]


def _rows_in(rows, table):
    """Mask of the ``rows`` (integer, shape (n, k)) that are rows of ``table``."""
    if len(rows) == 0 or len(table) == 0:
        return np.zeros(len(rows), dtype=bool)
    _, inverse = np.unique(np.vstack([table, rows]), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    return np.isin(inverse[len(table) :], inverse[: len(table)])


def _located(at, points, cells):
    """Mask of the points ``at`` that lie in one of the triangles ``cells`` (each tried among the nearest few).

    A point in a triangle farther out than its ``LOCATE_AMONG`` nearest
    centroids (a large cell among small ones) is missed: its kept cell then
    stays under the new ones, which :func:`_unjoined` finds, and the patch grows.
    """
    from scipy.spatial import cKDTree

    if len(at) == 0 or len(cells) == 0:
        return np.zeros(len(at), dtype=bool)
    corners = points[cells]
    nearest = cKDTree(corners.mean(axis=1)).query(at, list(range(1, min(LOCATE_AMONG, len(cells)) + 1)))[1]
    a, b, c = (corners[nearest, k] for k in range(3))  # shape (len(at), k, 2) each
    here = at[:, None, :]

    def side(start, end):
        return (end[..., 0] - start[..., 0]) * (here[..., 1] - start[..., 1]) - (end[..., 1] - start[..., 1]) * (
            here[..., 0] - start[..., 0]
        )

    return np.any((side(a, b) >= 0) & (side(b, c) >= 0) & (side(c, a) >= 0), axis=1)


def _reached(cells, allowed, seeds):
    """Mask of the ``allowed`` cells connected to an allowed ``seeds`` cell through allowed cells sharing edges."""
    index = np.flatnonzero(allowed)
    _, component = cell_components(cells[index])
    reached = np.zeros(len(cells), dtype=bool)
    reached[index[np.isin(component, component[seeds[index]])]] = True
    return reached


def _unjoined(domain, tolerance, points, cells, touched):
    """The ``touched`` vertices (a mask) where the cells do not make a valid mesh, ascending.

    Those of a cell not counter-clockwise or of an edge in two cells on the
    same side (or in three), and those on other than none or two boundary
    edges or on two off the domain's boundary (beyond ``tolerance``).
    """
    rows = cells[any_corner_in(touched, cells)]
    bad = np.zeros(len(points), dtype=bool)
    bad[rows[signed_areas(points, rows) <= 0].ravel()] = True
    directed = np.concatenate([rows[:, [0, 1]], rows[:, [1, 2]], rows[:, [2, 0]]])
    edges, counts = np.unique(directed, axis=0, return_counts=True)
    bad[edges[counts > 1].ravel()] = True
    degree = boundary_vertex_degree(rows, len(points))
    on_rim = np.flatnonzero(touched & (degree > 0))
    bad[on_rim[(degree[on_rim] != 2) | (np.abs(domain.distance(points[on_rim])) > tolerance)]] = True
    return np.flatnonzero(bad & touched)


def _check_strips_meet(domain, mesh, tolerance, axis, cuts, user_fixed, size):
    """Raise a GenerationError where the strips still do not meet (:func:`_mismatched`), naming the cut.

    Or naming the user's fixed point that is such a vertex: one a fraction of
    a size inside the boundary becomes a boundary vertex off it (a notch),
    which no stitch can mend, and the cut was blamed.
    """
    off = _mismatched(domain, mesh, tolerance)
    if len(off) and len(user_fixed):
        from scipy.spatial import cKDTree

        gap, _ = cKDTree(user_fixed).query(mesh.points[off])
        if np.any(gap <= tolerance):
            point = mesh.points[off[np.argmin(gap)]][None]
            inside = -float(domain.distance(point)[0] / size(point)[0])
            raise GenerationError(
                f"the fixed point {point[0].tolist()} lies {inside:.2g} sizes inside the boundary, too close to "
                "keep cells between them: move it onto the boundary or half a size in"
            )
    if len(off):
        where = mesh.points[off[0], axis]
        cut = cuts[np.argmin(np.abs(cuts - where))] if len(cuts) else where
        raise GenerationError(
            f"the strips do not meet vertex for vertex along the cut at {'xy'[axis]} = {cut:g} "
            f"({len(off)} boundary vertices off the domain's boundary or pinched, "
            f"e.g. {mesh.points[off[0]].tolist()}); "
            "the cut runs along the boundary or across a channel too narrow for its points: try another number of parts"
        )
