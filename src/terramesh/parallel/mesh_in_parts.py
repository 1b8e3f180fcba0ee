"""Mesh a 2D domain in strips side by side, on MPI ranks or one after the other, and merge them."""

import logging
import time

import numpy as np

from ..errors import GenerationError, warn_user
from ..generation.adapt import restarted
from ..generation.distmesh import _options, generate_mesh
from ..geometry.base import as_domain
from ..geometry.primitives import Rectangle
from ..mesh.mesh import Mesh
from ..mesh.topology import boundary_edges, lowest_twins
from .decompose import separator_points, strip_cuts

__all__ = ["generate_mesh_parallel"]

logger = logging.getLogger("terramesh.parallel")

_STRIP_OPTIONS = {"max_iter", "move_tolerance", "levels"}  # generate_mesh's, besides those named
_ON_CUT = 1e-14  # relative: a point this near a cut is on it
_STRIP_MARGIN = 0.1  # a strip reaches this share of the bbox beyond it across the cuts, so it adds no corners there
SEAM_REACH = 3.0  # where strips do not meet, the points within this many local sizes of the mismatch are meshed anew
# a strip narrower than this many sizes squeezes its cells between the fixed points of its cuts. Meshing a disk
# and a 2 x 1 rectangle at h 0.1 and 0.05 in ever more strips: with the narrowest strip 1.5 to 4 sizes wide, min
# quality 0.76-0.84 and mean 0.94-0.97 (whole: 0.80-0.83 and 0.99); 1.1 to 1.3 sizes, min 0.65-0.71 and mean
# 0.89-0.92; 0.4 and 0.2 sizes, min 0.59 and 0.23, mean 0.72 and 0.57
NARROWEST_STRIP = 1.5


def generate_mesh_parallel(
    domain, edge_length=None, *, parts=None, comm=None, h0=None, fixed_points=None, seed=0, **options
):
    """Mesh a 2D domain in strips, each as :func:`~terramesh.generate_mesh` would, and merge them.

    The seismic DistMesh talk's parallel scheme: the domain is cut into
    ``parts`` strips of about equal vertex counts, each cut moved a little to
    keep its points clear of the boundary (:func:`strip_cuts`); the
    points along each cut (:func:`separator_points`) are fixed in both
    strips beside it, so their meshes meet vertex for vertex there; each
    strip is meshed on its own (with seed ``seed + its index``), and the
    meshes are joined by those shared points. Where two strips do not meet
    vertex for vertex all the same (a cut crossing a coast at a shallow
    angle, or a feature narrower than the size: one strip's cells fall
    short of the cut, or it puts a vertex of its own there), the points
    within ``SEAM_REACH`` (3) sizes of the mismatch are meshed anew from
    both strips' points, the others staying where they are. With an MPI
    communicator the strips are shared out over its ranks (rank ``r``
    meshes strips ``r``, ``r + size``, ...) and gathered on rank 0; without
    one they are meshed here one after the other, with the same result.

    Parameters
    ----------
    domain : Domain or callable
        A 2D domain (signed distance, negative inside, with a ``bbox``).
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
        ``stitched`` (how many boundary vertices of the merged strips lay
        off the domain's boundary and were meshed anew, usually 0), and
        ``seconds``.

    Warns
    -----
    TerrameshWarning
        Where a strip is narrower than ``NARROWEST_STRIP`` (1.5) sizes: its
        cells are squeezed between its cuts' fixed points.

    Raises
    ------
    GenerationError
        For a domain that is not 2D, bad ``parts`` or ``seed``, a strip that
        cannot be meshed (named, with its bounds: a piece too thin for the
        size), or strips that still do not meet once stitched (it names the
        cut).
        Under MPI a strip that fails on one rank makes every rank raise,
        naming the strip and the error (none is left waiting for it).

    Examples
    --------
    >>> import terramesh as tm
    >>> mesh = tm.parallel.generate_mesh_parallel(tm.geometry.Disk((0, 0), 1), 0.1, parts=3)
    >>> tm.cleanup.mesh_problems(mesh), len(mesh.info["parts"])
    ([], 3)
    """
    started = time.perf_counter()
    domain = as_domain(domain)
    if domain.dim != 2:
        raise GenerationError(f"generate_mesh_parallel meshes 2D domains, got dim={domain.dim}")
    unknown = sorted(set(options) - _STRIP_OPTIONS)
    if unknown:
        raise GenerationError(
            f"unknown option {unknown[0]!r}; generate_mesh_parallel passes on {sorted(_STRIP_OPTIONS)}"
        )
    rank, ranks = (0, 1) if comm is None else (comm.Get_rank(), comm.Get_size())
    parts = ranks if parts is None else parts
    bbox = domain.bbox
    max_iter, move_tolerance = options.get("max_iter", 300), options.get("move_tolerance", 1e-2)
    size, h0, tolerance, fixed, _, _, _ = _options(
        domain, edge_length, h0, bbox, fixed_points, max_iter, move_tolerance, seed
    )
    axis, cuts = strip_cuts(domain, size, parts, h0, fixed_points)
    separators = [separator_points(domain, size, h0, axis, cut) for cut in cuts]
    bounds = np.concatenate([[bbox[0][axis]], cuts, [bbox[1][axis]]])
    if rank == 0:  # once, not once per rank
        _warn_of_narrow_strips(size, axis, bounds, separators)
    user_fixed = np.empty((0, 2)) if fixed_points is None else np.asarray(fixed_points, dtype=np.float64).reshape(-1, 2)
    mine, failure = [], None
    for part in range(rank, parts, ranks):
        try:
            mine.append(
                (part, *_mesh_strip(domain, size, h0, axis, bounds, separators, user_fixed, part, seed, options))
            )
        except Exception as error:
            where = f"strip {part} of {parts} ({'xy'[axis]} {bounds[part]:g} to {bounds[part + 1]:g})"
            if comm is None:
                if isinstance(error, GenerationError) and parts > 1:  # the whole may mesh: say which strip did not
                    raise GenerationError(f"{where}: {error}; fewer parts may do") from error
                raise
            # every rank must reach the gather, or the others would wait for this one for ever
            failure = f"{where} on rank {rank}: {type(error).__name__}: {error}"
            break
    if comm is not None:
        gathered = comm.gather((mine, failure, rank), root=0)
        failures = comm.bcast(None if rank else [f for _, f, _ in gathered if f], root=0)
        if failures:
            raise GenerationError("meshing in parts failed: " + "; ".join(failures))
        if rank != 0:
            return None
        mine = sorted(
            ((*strip, sender) for strips, _, sender in gathered for strip in strips), key=lambda strip: strip[0]
        )
    else:
        mine = [(*strip, 0) for strip in mine]
    mesh = _merged([strip[1] for strip in mine], [strip[2] for strip in mine], axis, cuts)
    off = _off_boundary(domain, mesh, tolerance)
    stitched = len(off)
    if stitched:
        # a strip's cells fell short of a cut, or it put a vertex of its own there (the cut crosses a
        # coast at a shallow angle, or a feature narrower than the size): the crack between the strips
        # is meshed anew from both strips' points, the rest staying where it is
        mesh = _stitched(domain, size, h0, tolerance, fixed, mesh, mesh.points[off], max_iter, move_tolerance)
        _check_strips_meet(domain, mesh, tolerance, axis, cuts)
    mesh.info.update(
        parts=[dict(strip[3], rank=strip[4]) for strip in mine],
        axis=axis,
        cuts=cuts.tolist(),
        stitched=stitched,
        seconds=time.perf_counter() - started,
        h0=h0,
    )
    return mesh


def _warn_of_narrow_strips(size, axis, bounds, separators):
    """Warn where a strip is narrower than ``NARROWEST_STRIP`` times the largest size on its cuts' points."""
    widths, largest = np.diff(bounds), np.zeros(len(bounds) - 1)
    for k, points in enumerate(separators):
        if len(points):
            largest[k : k + 2] = np.maximum(largest[k : k + 2], np.max(size(points)))  # the strips on both sides
    narrow = np.flatnonzero(widths < NARROWEST_STRIP * largest)
    if len(narrow):
        k = narrow[np.argmin(widths[narrow] / largest[narrow])]
        warn_user(
            f"{len(narrow)} of {len(widths)} strips are narrower than {NARROWEST_STRIP:g} sizes, e.g. strip {k} "
            f"({'xy'[axis]} {bounds[k]:g} to {bounds[k + 1]:g}): {widths[k]:.3g} wide, sizes up to {largest[k]:.3g} "
            "along its cuts; its cells are squeezed between the cuts' fixed points (lower quality): "
            "fewer parts may do"
        )


def _mesh_strip(domain, size, h0, axis, bounds, separators, user_fixed, part, seed, options):
    """Mesh strip ``part`` (between ``bounds[part]`` and the next along ``axis``): ``(points, cells, info)``."""
    low, high = domain.bbox
    margin = _STRIP_MARGIN * (high - low)
    strip_low, strip_high = low - margin, high + margin
    strip_low[axis], strip_high[axis] = bounds[part], bounds[part + 1]
    beside = [separators[k] for k in (part - 1, part) if 0 <= k < len(separators)]
    holds = (user_fixed[:, axis] >= bounds[part]) & (user_fixed[:, axis] <= bounds[part + 1])
    fixed = np.concatenate([*beside, user_fixed[holds], np.empty((0, 2))])
    # one part is the whole domain, meshed as generate_mesh meshes it: intersected with the strip's
    # rectangle, sweep run 40122's random-walk coast was refused for a pinch that it meshes without
    strip = domain if len(bounds) == 2 else domain & Rectangle(strip_low, strip_high)
    mesh = generate_mesh(strip, size, h0=h0, fixed_points=fixed if len(fixed) else None, seed=seed + part, **options)
    return mesh.points, mesh.cells, mesh.info


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


def _off_boundary(domain, mesh, tolerance):
    """The boundary vertices of the merged mesh off the domain's boundary: where two strips do not meet."""
    vertices = np.unique(boundary_edges(mesh.cells))
    return vertices[np.abs(domain.distance(mesh.points[vertices])) > tolerance]


def _stitched(domain, size, h0, tolerance, fixed, mesh, seam, max_iter, move_tolerance):
    """The merged ``mesh`` of the strips meshed anew within ``SEAM_REACH`` sizes of the ``seam`` points.

    The strips' vertices farther away stay exactly where they are
    (:func:`~terramesh.generation.adapt.restarted`); the domain's corners and
    the user's ``fixed`` points stay fixed, while the cut's own points, fixed
    only so that the strips would meet, may move.
    """
    from scipy.spatial import cKDTree

    tree = cKDTree(seam)

    def changed(at):
        return tree.query(at)[0] < SEAM_REACH * size(at)

    mesh = restarted(domain, size, h0, tolerance, fixed, mesh.points, changed, max_iter, move_tolerance)
    logger.info(
        "strips stitched: %d points added, %d removed near %d seam vertices",
        mesh.info["added"],
        mesh.info["removed"],
        len(seam),
    )
    return Mesh(mesh.points, mesh.cells)


def _check_strips_meet(domain, mesh, tolerance, axis, cuts):
    """Raise a GenerationError where a boundary vertex of the merged mesh lies off the domain's boundary (a cut)."""
    off = _off_boundary(domain, mesh, tolerance)
    if len(off):
        where = mesh.points[off[0], axis]
        cut = cuts[np.argmin(np.abs(cuts - where))] if len(cuts) else where
        raise GenerationError(
            f"the strips do not meet vertex for vertex along the cut at {'xy'[axis]} = {cut:g} "
            f"({len(off)} boundary vertices off the domain's boundary, e.g. {mesh.points[off[0]].tolist()}); "
            "the cut runs along the boundary or across a channel too narrow for its points: try another number of parts"
        )
