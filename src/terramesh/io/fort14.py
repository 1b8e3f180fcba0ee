"""ADCIRC ``fort.14`` grid and boundary files.

Layout (ADCIRC documentation, "Grid and Boundary Information File"):

* ``AGRID`` title line; ``NE NP``;
* ``NP`` node lines ``JN X Y DP`` (depth positive down);
* ``NE`` element lines ``JE NHY NM1 NM2 NM3`` (NHY = 3);
* ``NOPE``; ``NETA``; per open boundary ``NVDLL [IBTYPEE]`` then ``NVDLL``
  node numbers;
* ``NBOU``; ``NVEL``; per land boundary ``NVELL IBTYPE`` then ``NVELL``
  lines whose columns depend on IBTYPE: the node only (0, 1, 2, 10, 11, 12,
  20, 21, 22, 30, 40, 41, 52, 102, 112, 122); node, barrier height and
  supercritical coefficient (3, 13, 23); node, paired back-face node,
  barrier height, sub- and supercritical coefficients (4, 24, 64); the same
  plus pipe height, coefficient and diameter (5, 25). ``NVEL`` counts the
  back-face nodes of paired barriers too.

The reader takes text after the expected values as comments, maps node
labels (which need not be 1..NP) to 0-based indices, and keeps every
boundary column, so a file read and written again is the same grid. Its
reals may carry Fortran's D exponent (``1.0D+01``) and its values may be
separated by commas (``1,0.0,0.0,1.0``), as ADCIRC's list-directed reads
take them.
"""

import numpy as np

from ..errors import MeshFormatError, MeshValidityError, checked_number, warn_user
from ..mesh.boundaries import (
    PAIRED_TYPES,
    Boundaries,
    LandBoundary,
    OpenBoundary,
    check_boundary_nodes,
    has_boundaries,
)
from ..mesh.columns import rows_all
from ..mesh.mesh import guess_crs
from ..mesh.nodal_attributes import one_line
from ._text import NULL_VALUE, fortran_list_directed, fortran_real, write_rows, written_whole

__all__ = ["OpenBoundary", "LandBoundary", "Boundaries", "has_boundaries", "read_fort14", "write_fort14", "guess_crs"]

# columns after the node number on a land boundary line, by IBTYPE (paired types include IBCONN)
_EXTRA_COLUMNS = {3: 2, 13: 2, 23: 2, 4: 4, 24: 4, 64: 4, 5: 7, 25: 7}


class LineCursor:
    """Cursor over the file's lines with errors that say where the file broke.

    Blank lines at the end of the file are dropped: they are no section (a
    file that ends after its elements has no boundaries), only what editors
    and other writers leave.
    """

    def __init__(self, text, path):
        self.lines = text.splitlines()
        end = len(self.lines)
        while end and not self.lines[end - 1].strip():
            end -= 1
        del self.lines[end:]
        self.position = 0
        self.path = path

    def next_numbers(self, count, what):
        """The first ``count`` integers of the next line; anything after them is a comment."""
        if self.position >= len(self.lines):
            raise MeshFormatError(f"{self.path}: file ends early, expected {what} at line {self.position + 1}")
        tokens = self.lines[self.position].replace(",", " ").split()[:count]
        self.position += 1
        if len(tokens) < count:
            raise MeshFormatError(
                f"{self.path}: line {self.position}: {what} needs {count} values, found {len(tokens)}"
            )
        try:
            return [int(token) for token in tokens]
        except ValueError as error:
            raise MeshFormatError(f"{self.path}: line {self.position}: cannot read {what}: {error}") from error

    def not_negative(self, count, what):
        """Refuse a negative count read from the previous line."""
        if count < 0:
            raise MeshFormatError(f"{self.path}: line {self.position}: negative {what} ({count})")

    def optional_int(self, index):
        """The ``index``-th token of the previous line as an int, or None when absent or not a number."""
        tokens = self.lines[self.position - 1].replace(",", " ").split()
        try:
            value = fortran_real(tokens[index])
        except (IndexError, ValueError):
            return None
        return int(value) if value == int(value) else None

    def block(self, count, columns, what, dtype=np.float64):
        """``count`` lines parsed as a ``dtype`` table (shape ``(count, columns)``) of their first ``columns`` numbers.

        An integer table whose file writes some numbers as ``3.0`` is read as
        floats and must hold whole numbers.
        """
        integers = columns if np.issubdtype(dtype, np.integer) else 0
        whole, real = self.table(count, columns, what, integers)
        return (whole if integers else real).astype(dtype, copy=False)

    def table(self, count, columns, what, integers=0):
        """The first ``columns`` numbers of the next ``count`` lines: ``(whole, real)``.

        ``whole`` (int64, shape ``(count, integers)``) holds the first
        ``integers`` columns (node and element numbers, exact up to the
        int64 range), ``real`` (float64, shape ``(count, columns -
        integers)``) the others. A file that writes a whole number as ``3.0``
        is read; one that writes ``3.5`` there is refused. A number may have
        a Fortran D exponent (``1.0D+01``), and values may be separated by
        commas. Any error names the file's line: a blank line, too few
        values, text that is no number, two commas with nothing between.
        """
        first = self.position  # 0-based index of the table's first line
        if first + count > len(self.lines):
            raise MeshFormatError(
                f"{self.path}: file ends early at line {len(self.lines)}: expected {count} lines of {what}, "
                f"found {len(self.lines) - first}"
            )
        self.position += count
        if count == 0:  # without the lines loadtxt would warn of "no data"
            return np.empty((0, integers), np.int64), np.empty((0, columns - integers))
        chunk = self.lines[first : first + count]
        if integers == columns:
            dtype = np.dtype(np.int64)
        elif integers == 0:
            dtype = np.dtype(np.float64)
        else:  # one pass, each column parsed as its type (as fast as all floats)
            dtype = np.dtype([("whole", np.int64, (integers,)), ("real", np.float64, (columns - integers,))])
        table = _loaded(chunk, columns, dtype)
        parsed = chunk
        if table is None:
            # Fortran D exponents and commas, which loadtxt does not read: looked for only after a failure,
            # so a file without them is read as fast as before (errors quote ``chunk`` as written)
            translated = fortran_list_directed(chunk)
            if translated is not None:
                parsed = translated
                table = _loaded(parsed, columns, dtype)
        if table is not None:
            if dtype.names is None:
                return (table, np.empty((count, 0))) if integers else (np.empty((count, 0), np.int64), table)
            return np.ascontiguousarray(table["whole"]), np.ascontiguousarray(table["real"])
        table = _loaded(parsed, columns, np.dtype(np.float64)) if integers else None
        if table is None:
            raise self._bad_line(chunk, first, columns, what)
        whole = table[:, :integers]
        # past 2**63 a float has no int64; ``3.5`` is no node number
        fractional = ~(np.isfinite(whole) & (whole == np.round(whole)) & (np.abs(whole) < 2.0**63)).all(axis=1)
        if np.any(fractional):
            row = np.flatnonzero(fractional)[0]
            where = "" if integers == columns else " in column 1" if integers == 1 else f" in columns 1-{integers}"
            raise MeshFormatError(
                f"{self.path}: line {first + row + 1}: {what} must hold whole numbers{where}, "
                f"found {chunk[row].strip()!r}"
            )
        return whole.astype(np.int64), table[:, integers:]

    def _bad_line(self, chunk, first, columns, what):
        """The MeshFormatError naming the first line of ``chunk`` that is not ``columns`` numbers (loadtxt failed)."""
        # only on failure: a Python loop over the lines would double the time of a good file
        for offset, line in enumerate(chunk):
            where = f"{self.path}: line {first + offset + 1}"
            if NULL_VALUE.search(line):
                return MeshFormatError(f"{where}: no value between commas among the {what}: {line.strip()!r}")
            tokens = line.replace(",", " ").split()[:columns]
            if not tokens:
                return MeshFormatError(f"{where}: blank line among the {what}")
            if len(tokens) < columns:
                return MeshFormatError(f"{where}: {what} need {columns} values, found {len(tokens)}: {line.strip()!r}")
            for token in tokens:
                try:
                    fortran_real(token)
                except ValueError:
                    return MeshFormatError(f"{where}: cannot read {what}: {token!r} is not a number")
        return MeshFormatError(f"{self.path}: lines {first + 1}-{first + len(chunk)}: cannot read {what}")


def _loaded(chunk, columns, dtype):
    """The lines ``chunk`` as a ``dtype`` table of their first ``columns`` numbers, or None when one is not."""
    try:
        table = np.loadtxt(
            chunk, usecols=range(columns), ndmin=2 if dtype.names is None else 1, dtype=dtype, comments=None
        )
    except (ValueError, OverflowError):
        return None
    # loadtxt skips blank lines: a table one short has a hole
    return table if len(table) == len(chunk) else None


def read_fort14(path, crs="auto"):
    r"""Read an ADCIRC fort.14 file.

    Parameters
    ----------
    path : str or os.PathLike
    crs : str or None, optional
        The coordinates' reference system, which a fort.14 does not record
        (ADCIRC takes it from fort.15's ICS). ``"auto"`` (default):
        ``"EPSG:4326"`` (longitude, latitude degrees, as coastal meshes are
        written) when every x lies in [-180, 360] and every y in [-90, 90],
        else None (planar metres). Pass None for a planar mesh whose
        coordinates happen to lie in those ranges, or a CRS string: the
        time step, Courant number and quality measures depend on it.

    Returns
    -------
    Mesh
        ``points`` (longitude, latitude or x, y), ``cells`` (0-based,
        counter-clockwise as in the file), ``point_data["depth"]`` (metres,
        positive down), ``boundaries`` (:class:`Boundaries`), ``title`` and
        ``crs``.

    Raises
    ------
    MeshFormatError
        For truncated or malformed files (naming the file's line: a blank
        line or text inside a table, a node or element number that is not
        a whole number), nodes with NaN or infinite coordinates or depths
        (``nan`` in the depth column), or elements and boundaries that
        refer to unknown nodes. Blank lines at the end of the file are
        ignored.
    MeshValidityError
        For a longitude-latitude ``crs`` given for coordinates that are no
        degrees (see :class:`~terramesh.Mesh`).

    Examples
    --------
    A square of two triangles in metres, its nodes labelled 10 to 40, with
    one open boundary (nodes 20 and 30) and one land boundary (IBTYPE 20):

    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "fort.14"
    >>> _ = path.write_text(
    ...     "square\n2 4\n10 0 0 5.0\n20 1000 0 10.0\n30 1000 1000 10.0\n40 0 1000 5.0\n"
    ...     "1 3 10 20 30\n2 3 10 30 40\n"
    ...     "1\n2\n2\n20\n30\n1\n3\n3 20\n30\n40\n10\n"
    ... )
    >>> mesh = read_fort14(path)
    >>> mesh.n_points, mesh.cells.tolist(), mesh.point_data["depth"].tolist()
    (4, [[0, 1, 2], [0, 2, 3]], [5.0, 10.0, 10.0, 5.0])
    >>> len(mesh.boundaries.open), len(mesh.boundaries.land), mesh.boundaries.land[0].nodes.tolist(), mesh.crs
    (1, 1, [2, 3, 0], None)
    """
    from ..mesh.mesh import Mesh

    with open(path, encoding="utf-8", errors="replace") as handle:
        text = handle.read()
    lines = LineCursor(text, path)
    if not lines.lines:
        raise MeshFormatError(f"{path}: empty file")
    title = lines.lines[0].strip()
    lines.position = 1
    n_elements, n_nodes = lines.next_numbers(2, "NE NP")
    if n_elements < 0 or n_nodes < 0:
        raise MeshFormatError(f"{path}: negative NE or NP")
    # labels as integers, exact where floats are not (2**60 + 1 is 2**60 as a float)
    labels, nodes = lines.table(n_nodes, 4, "node lines (JN X Y DP)", integers=1)
    labels = labels[:, 0]
    refuse_non_finite(nodes[:, :2], f"{path}: coordinates are")
    _refuse_non_finite_depth(nodes[:, 2], labels, lines.position - n_nodes + 1, path)
    _warn_of_depths_off_the_earth(nodes[:, 2], labels, lines.position - n_nodes + 1, path)
    # as integers: five times faster than floats (1.55 -> 0.27 s for 1.8 million lines)
    elements, _ = lines.table(n_elements, 5, "element lines (JE NHY NM1 NM2 NM3)", integers=5)
    if n_elements and np.any(elements[:, 1] != 3):
        raise MeshFormatError(f"{path}: only triangles (NHY = 3) are supported")
    _refuse_more_elements(lines, elements, path)
    index_of = _label_lookup(labels, path)
    cells = index_of(elements[:, 2:5], "element", lines.position - n_elements + 1)
    boundaries = _read_boundaries(lines, index_of) if lines.position < len(lines.lines) else Boundaries()
    if not text.endswith(("\n", "\r")):  # cut inside its last number, it read: "985" as node 98
        warn_user(
            f"{path} does not end with a line break: it may have been cut short, and its last line, "
            f"{lines.lines[-1].strip()!r}, read as it is"
        )
    points = np.ascontiguousarray(nodes[:, :2])
    return Mesh(
        points,
        cells,
        point_data={"depth": np.ascontiguousarray(nodes[:, 2])},
        boundaries=boundaries,
        title=title,
        crs=guess_crs(points) if crs == "auto" else crs,
        info={"crs_guessed": crs == "auto"},
    )


def _refuse_more_elements(lines, elements, path):
    """Refuse a file whose line after NE elements is the next element: its NE is short of the elements it holds.

    The element was read as NOPE and the error came from the open boundaries
    ("file ends early at line 3027: expected 817 lines of open boundary nodes").
    """
    if lines.position >= len(lines.lines) or not len(elements):
        return
    tokens = lines.lines[lines.position].replace(",", " ").split()
    following = str(int(elements[-1, 0]) + 1)
    if len(tokens) >= 5 and tokens[0] == following and tokens[1] == "3" and all(t.isdigit() for t in tokens[2:5]):
        raise MeshFormatError(
            f"{path}: line {lines.position + 1} is element {following} (JE NHY NM1 NM2 NM3), after the "
            f"{len(elements)} elements the header's NE declares: NE is short of the elements the file holds"
        )


EARTH_DEPTHS = (-9000.0, 11100.0)
"""Depths (metres, positive down) a node on Earth can have: from above Everest's 8,849 m to below the Challenger Deep.

Beyond them a depth is a fill value (-99999) or in other units, which
:func:`read_fort14` warns of: ADCIRC would take -99999 as land 100 km high.
"""


def _warn_of_depths_off_the_earth(depth, labels, first_line, path, shown=3):
    """Warn of depths outside :data:`EARTH_DEPTHS`, naming the first ``shown`` nodes (file numbers and lines)."""
    low, high = EARTH_DEPTHS
    off = np.flatnonzero((depth < low) | (depth > high))
    if off.size:
        named = ", ".join(f"node {labels[row]} (line {first_line + row}: {depth[row]:g} m)" for row in off[:shown])
        warn_user(
            f"{path}: {off.size} of {len(depth)} nodes have a depth no place on Earth has (more than {-low:g} m "
            f"above the datum or {high:g} m below it): {named}{', ...' if off.size > shown else ''}; fill values "
            "for no data? give them depths (terramesh post --dem, terramesh.coastal.interpolate_bathymetry)"
        )


def _refuse_non_finite_depth(depth, labels, first_line, path, shown=5):
    """Raise a MeshFormatError naming the first ``shown`` nodes (file numbers and lines) whose depth is NaN or infinite.

    ``nan`` reads as a number, and such a file was read without a word (and
    ``terramesh info`` called it valid), where the reader refuses NaN
    coordinates and text among the numbers, :func:`~terramesh.io.read_fort13`
    NaN attribute values, and the writers NaN depths: ADCIRC and SCHISM run
    no such node. ``first_line`` is the file's line of the first node.
    """
    finite = np.isfinite(depth)
    if finite.all():
        return
    bad = np.flatnonzero(~finite)
    named = ", ".join(f"node {labels[row]} (line {first_line + row})" for row in bad[:shown])
    raise MeshFormatError(
        f"{path}: depth is NaN or infinite at {len(bad)} of {len(depth)} nodes: {named}"
        f"{', ...' if len(bad) > shown else ''}. ADCIRC and SCHISM read no such depth: give those nodes a depth in "
        "the file (any number, e.g. 0, where the bathymetry is to be interpolated again with "
        "terramesh.coastal.interpolate_bathymetry or terramesh post --dem)"
    )


def _label_lookup(labels, path):
    """``index_of(values, what, line)``: the rows of the nodes numbered ``values``; MeshFormatError for one missing.

    ``values`` (int64, one row a file line) were read from the file's lines
    ``line`` on, so the error names the line of the missing node.

    Nodes numbered one after another (as most files number them) are looked
    up by subtraction; others by a search in their sorted numbers. Either
    way no hash of the numbers is needed (``np.unique`` took 0.7 of the 2.7 s
    that 917k nodes took to read).
    """

    def missing(values, found, what, line):
        values, found = values.reshape(len(values), -1), found.reshape(len(values), -1)
        row = np.flatnonzero(~found.all(axis=1))[0]
        return MeshFormatError(
            f"{path}: line {line + row}: {what} refers to node {values[row][~found[row]][0]} that does not exist"
        )

    n_nodes = len(labels)
    # the span in Python integers: in int64 it wraps for labels near both ends of the range
    if n_nodes and int(labels[-1]) - int(labels[0]) == n_nodes - 1 and np.all(np.diff(labels) == 1):

        def index_of(values, what, line):
            index = values - labels[0]
            found = (index >= 0) & (index < n_nodes)
            if not np.all(found):
                raise missing(values, found, what, line)
            return index

        return index_of
    order = np.argsort(labels, kind="stable")
    sorted_labels = labels[order]
    if np.any(sorted_labels[1:] == sorted_labels[:-1]):
        raise MeshFormatError(f"{path}: node numbers are not unique")

    def index_of(values, what, line):
        position = np.minimum(np.searchsorted(sorted_labels, values), n_nodes - 1)
        found = sorted_labels[position] == values if n_nodes else np.zeros(values.shape, bool)
        if not np.all(found):
            raise missing(values, found, what, line)
        return order[position]

    return index_of


def _read_boundaries(lines, index_of):
    boundaries = Boundaries()
    (n_open,) = lines.next_numbers(1, "NOPE")
    lines.not_negative(n_open, "NOPE")
    (declared_open,) = lines.next_numbers(1, "NETA")
    neta_line = lines.position
    for _ in range(n_open):
        (count,) = lines.next_numbers(1, "NVDLL")
        lines.not_negative(count, "NVDLL")
        ibtype = lines.optional_int(1)
        nodes, _ = lines.table(count, 1, "open boundary nodes", integers=1)
        boundaries.open.append(OpenBoundary(index_of(nodes[:, 0], "open boundary", lines.position - count + 1), ibtype))
    _check_total(lines.path, neta_line, "NETA", declared_open, [sum(len(b.nodes) for b in boundaries.open)])
    if lines.position >= len(lines.lines):
        # ADCIRC reads NBOU and NVEL after the open boundaries: a file that ends before them was cut short
        warn_user(
            f"{lines.path}: the file ends after the open boundaries, without NBOU and NVEL (cut short?): read "
            "with no land boundaries"
        )
        return boundaries
    (n_land,) = lines.next_numbers(1, "NBOU")
    lines.not_negative(n_land, "NBOU")
    (declared_land,) = lines.next_numbers(1, "NVEL")
    nvel_line = lines.position
    for _ in range(n_land):
        count, ibtype = lines.next_numbers(2, "NVELL IBTYPE")
        lines.not_negative(count, "NVELL")
        extra = _EXTRA_COLUMNS.get(ibtype, 0)
        paired = ibtype in PAIRED_TYPES
        numbers, values = lines.table(
            count, 1 + extra, f"land boundary nodes (IBTYPE {ibtype})", integers=2 if paired else 1
        )
        line = lines.position - count + 1
        nodes = index_of(numbers[:, 0], "land boundary", line)
        paired_nodes = index_of(numbers[:, 1], "barrier pair", line) if paired else None
        boundaries.land.append(LandBoundary(nodes, ibtype, paired_nodes, values if extra else None))
    # ADCIRC's documentation counts both faces of a paired barrier in NVEL; some tools count one
    faces = sum(len(b.nodes) for b in boundaries.land)
    paired_faces = sum(len(b.nodes) for b in boundaries.land if b.ibtype in PAIRED_TYPES)
    _check_total(lines.path, nvel_line, "NVEL", declared_land, [faces + paired_faces, faces])
    if lines.position < len(lines.lines):
        warn_user(
            f"{lines.path}: {len(lines.lines) - lines.position} lines after the last land boundary (from line "
            f"{lines.position + 1}) were not read: is NBOU or an NVELL too small?"
        )
    return boundaries


def _check_total(path, line, name, declared, found):
    """Warn when a declared total of boundary nodes (NETA, NVEL) is none of the totals the strings give."""
    if declared not in found:
        warn_user(
            f"{path}: line {line}: {name} is {declared}, but the boundary strings hold {found[0]} nodes; "
            "read as the strings give them (ADCIRC may refuse the file)"
        )


def writable_nodes(mesh):
    """The node depths (zeros without any) and boundaries of ``mesh``, checked for a fort.14-style file.

    Raises a MeshFormatError before anything is written for a NaN or
    infinite coordinate or depth, or a boundary node the mesh does not have.
    """
    refuse_non_finite(mesh.points, "the point coordinates are")
    depth = np.asarray(mesh.point_data.get("depth", np.zeros(mesh.n_points)))
    if depth.shape != (mesh.n_points,) or depth.dtype.kind not in "biuf":
        raise MeshFormatError(
            f"point_data['depth'] must be one number per node, shape ({mesh.n_points},); "
            f"got shape {depth.shape} of dtype {depth.dtype}"
        )
    depth = depth.astype(np.float64, copy=False)
    refuse_non_finite(
        depth,
        "depth is",
        hint="no DEM? interpolate one (terramesh.coastal.interpolate_bathymetry) or fill them, e.g. "
        "mesh.point_data['depth'] = numpy.nan_to_num(mesh.depth, nan=0.0)",
    )
    boundaries = mesh.boundaries or Boundaries()
    check_boundary_nodes(boundaries, mesh.n_points)
    return depth, boundaries


def refuse_invalid_cells(mesh, what):
    """Raise a MeshValidityError naming the cells and nodes that ADCIRC and SCHISM cannot take; nothing is written.

    Clockwise (inverted) cells, flat ones (area at most
    :data:`~terramesh.cleanup.validity.FLAT` times the sum of their squared
    edges, as :func:`~terramesh.cleanup.mesh_problems` counts them), cells
    with the vertices of an earlier one, and nodes in no cell: each was
    written without a word, and the model failed or misbehaved on the file.
    ``what`` names the file (``"fort.14"``). One compiled pass each for the
    quality and the repeated cells, one scatter for the used nodes: about
    0.1 s at 10**6 cells, a tenth of the write.
    """
    from .._kernels.cleanup import edge_census
    from ..cleanup.validity import FLAT
    from ..quality.triangle import triangle_quality

    cells = np.ascontiguousarray(mesh.cells, dtype=np.int64)  # the kernel's layout (a Mesh's, unless reassigned)
    # orientation in longitude, latitude degrees has the sign it has on the ground (x scaled by cos(lat) > 0)
    quality = triangle_quality(mesh.points, cells)
    if mesh.geographic:
        # a global mesh's cells across 180 have corners at 179.5 and -179.5: measured with their longitudes
        # within half a turn of the first corner's, as on the ground (counted clockwise, fix_mesh flipped them)
        longitude = mesh.points[cells, 0]
        seam = np.flatnonzero(np.ptp(longitude, axis=1) > 180.0)
        if len(seam):
            corners = mesh.points[cells[seam]].copy()
            turned = corners[:, :, 0] - corners[:, :1, 0]
            corners[:, :, 0] -= 360.0 * np.round(turned / 360.0)
            quality[seam] = triangle_quality(corners.reshape(-1, 2), np.arange(3 * len(seam)).reshape(-1, 3))
    flat_quality = 4.0 * np.sqrt(3.0) * FLAT  # quality is 4 sqrt(3) area over the squared edges
    found = [
        ("are clockwise, inverted", quality < -flat_quality),
        ("have zero area", np.abs(quality) <= flat_quality),
        ("repeat the vertices of an earlier cell", edge_census(cells, mesh.n_points)[0]),
    ]
    problems = [
        f"{int(np.count_nonzero(mask))} of {len(cells)} cells {says} (first: cell {int(np.argmax(mask)) + 1})"
        for says, mask in found
        if mask.any()
    ]
    used = np.zeros(mesh.n_points, dtype=bool)
    used[cells.ravel()] = True
    if not used.all():
        unused = int(np.count_nonzero(~used))
        problems.append(f"{unused} of {mesh.n_points} nodes are in no cell (first: node {int(np.argmin(used)) + 1})")
    if problems:
        raise MeshValidityError(
            f"cannot write {what}: {'; '.join(problems)}; numbered from 1, as in the file. ADCIRC and SCHISM need "
            "counter-clockwise cells of positive area, each once, and every node in a cell: repair the mesh "
            "first with terramesh.cleanup.fix_mesh(mesh)"
        )


def refuse_non_finite(values, what, item="node", hint=None):
    """Raise a MeshFormatError when a row of ``values`` holds a NaN or infinity, naming the count and the first.

    The first is given by its 1-based number (as in the files) and its
    0-based index in the arrays; ``hint`` says what to do about it.
    """
    values = np.atleast_1d(np.asarray(values, dtype=np.float64))  # a 0-d value is one row
    if values.size == 0:
        return
    finite = np.isfinite(values.reshape(len(values), -1))
    if finite.all():  # one pass over all entries; NumPy's all(axis=1) over short rows is 15 ns a row
        return
    rows = np.flatnonzero(~rows_all(finite))
    if len(rows):
        raise MeshFormatError(
            f"{what} NaN or infinite at {len(rows)} of {len(values)} {item}s "
            f"({item} {rows[0] + 1} first, index {rows[0]})" + ("" if hint is None else f"; {hint}")
        )


def _whole_ibtype(value, requirement):
    """``value`` as an int; MeshFormatError with ``requirement`` unless a whole number (``21.0``, ``"21"`` are)."""
    number = checked_number(value, requirement, MeshFormatError)
    if number != round(number):
        raise MeshFormatError(f"{requirement}, got {value!r}")
    return int(number)


def checked_ibtypes(boundaries):
    """A copy of ``boundaries`` (sharing its node arrays) whose IBTYPEs are ints, for writing.

    A flag is written as the text of its value: ``20.0``, ``None`` or ``"x"``
    in a land boundary's IBTYPE gave a file that ADCIRC and :func:`read_fort14`
    refuse. An open boundary's IBTYPEE may be None (no flag written).

    Raises
    ------
    MeshFormatError
        Naming the boundary whose IBTYPE or IBTYPEE is not a whole number.
    """
    opens = [
        OpenBoundary(
            boundary.nodes,
            None
            if boundary.ibtype is None
            else _whole_ibtype(
                boundary.ibtype, f"open boundary {number}: IBTYPEE must be a whole number or None (no flag)"
            ),
        )
        for number, boundary in enumerate(boundaries.open, start=1)
    ]
    land = [
        LandBoundary(
            boundary.nodes,
            _whole_ibtype(
                boundary.ibtype, f"land boundary {number}: IBTYPE must be a whole number (e.g. 20 mainland, 21 island)"
            ),
            boundary.paired_nodes,
            boundary.values,
        )
        for number, boundary in enumerate(boundaries.land, start=1)
    ]
    return Boundaries(open=opens, land=land)


def _check_land_columns(boundaries):
    """Raise a MeshFormatError when a land boundary lacks the columns its IBTYPE needs in the file."""
    for number, boundary in enumerate(boundaries.land, start=1):
        count = len(boundary.nodes)
        paired = boundary.ibtype in PAIRED_TYPES
        where = f"land boundary {number} (IBTYPE {boundary.ibtype})"
        if paired and (boundary.paired_nodes is None or np.shape(boundary.paired_nodes) != (count,)):
            got = "none" if boundary.paired_nodes is None else f"shape {np.shape(boundary.paired_nodes)}"
            raise MeshFormatError(f"{where} needs paired_nodes, one back-face node per node ({count}), got {got}")
        if not paired and boundary.ibtype in _EXTRA_COLUMNS and boundary.paired_nodes is not None:
            raise MeshFormatError(f"{where} is not a paired barrier but has paired_nodes")
        width = _EXTRA_COLUMNS.get(boundary.ibtype, 0) - (1 if paired else 0)
        if width > 0 or boundary.values is not None:
            shape = None if boundary.values is None else np.shape(boundary.values)
            if width > 0 and shape != (count, width):
                raise MeshFormatError(
                    f"{where} needs values of shape ({count}, {width}) (barrier height and coefficients), "
                    f"got {'none' if shape is None else shape}"
                )
            if shape is not None and (len(shape) != 2 or shape[0] != count):
                raise MeshFormatError(f"{where} needs values of shape ({count}, k), got {shape}")
            refuse_non_finite(boundary.values, f"the values of {where} are", item="row")


def write_fort14(path, mesh):
    """Write an ADCIRC fort.14 file (1-based node and element numbers).

    Depth comes from ``mesh.point_data["depth"]`` (metres, positive down),
    zero where the mesh has none; boundaries from ``mesh.boundaries``.
    The mesh is not modified.

    Parameters
    ----------
    path : str or os.PathLike
    mesh : Mesh
        A 2D triangle mesh.

    Raises
    ------
    MeshFormatError
        If the mesh is not a 2D triangle mesh, a coordinate or a depth is
        NaN or infinite (a coastal mesh built without a DEM has NaN depths):
        ADCIRC and SCHISM read no such value; or if a boundary refers to a
        node the mesh does not have, an IBTYPE (or an open boundary's
        IBTYPEE) is not a whole number, or a barrier lacks the paired nodes or
        values its IBTYPE needs. No file is written then.
    MeshValidityError
        If cells are clockwise, have zero area or repeat another cell, or
        nodes are in no cell (:func:`refuse_invalid_cells`): repair the mesh
        with :func:`terramesh.cleanup.fix_mesh`. No file is written then.

    Examples
    --------
    A round trip of a square of two triangles (metres) with depths, an
    open boundary on its right side and a land boundary (IBTYPE 20) on
    the others:

    >>> import pathlib, tempfile
    >>> import numpy as np, terramesh as tm
    >>> from terramesh.mesh.boundaries import Boundaries, LandBoundary, OpenBoundary
    >>> mesh = tm.Mesh(np.array([[0.0, 0.0], [1e3, 0.0], [1e3, 1e3], [0.0, 1e3]]), [[0, 1, 2], [0, 2, 3]])
    >>> mesh.point_data["depth"] = np.array([5.0, 10.0, 10.0, 5.0])
    >>> mesh.boundaries = Boundaries(
    ...     open=[OpenBoundary(np.array([1, 2]))], land=[LandBoundary(np.array([2, 3, 0, 1]), 20)]
    ... )
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "fort.14"
    >>> write_fort14(path, mesh)
    >>> back = read_fort14(path)
    >>> back.n_points, len(back.boundaries.open), len(back.boundaries.land)
    (4, 1, 1)
    >>> bool(np.array_equal(back.points, mesh.points)), back.boundaries.land[0].nodes.tolist()
    (True, [2, 3, 0, 1])
    """
    if mesh.dim != 2 or mesh.cells.shape[1] != 3:
        raise MeshFormatError("fort.14 holds 2D triangle meshes only")
    depth, boundaries = writable_nodes(mesh)
    refuse_invalid_cells(mesh, "fort.14")
    boundaries = checked_ibtypes(boundaries)
    _check_land_columns(boundaries)
    write_grid(path, mesh, depth, boundaries)


def write_grid(path, mesh, depth, boundaries):
    """Write the fort.14 layout of ``mesh`` with ``depth`` and ``boundaries`` (already checked) to ``path``.

    The part of :func:`write_fort14` that :func:`~terramesh.io.write_gr3`
    shares, after its own checks and conversion of the boundaries; a mesh
    without depths is written at 0 m with a warning.
    """
    if "depth" not in mesh.point_data and mesh.n_points:  # a .vtu of another tool's: written as 0 m without a word
        warn_user(
            f"the mesh has no depths (point_data['depth']): all {mesh.n_points} nodes are written at 0 m; put the "
            "DEM's on first (terramesh.coastal.interpolate_bathymetry, terramesh post --dem) for a model run"
        )
    numbers = np.arange(1, mesh.n_points + 1)
    # one line: a form feed or U+2028 in a title breaks the line for the reader (str.splitlines) too
    title = one_line(mesh.title) or "terramesh"
    with written_whole(path) as temporary, open(temporary, "w", encoding="utf-8") as handle:
        handle.write(f"{title}\n{mesh.n_cells} {mesh.n_points}\n")
        write_rows(handle, np.column_stack([numbers, mesh.points, depth]), fmt="%d %.17g %.17g %.17g")
        write_rows(
            handle,
            np.column_stack([np.arange(1, mesh.n_cells + 1), np.full(mesh.n_cells, 3), mesh.cells + 1]),
            fmt="%d",
        )
        write_boundaries(handle, boundaries)


def write_boundaries(handle, boundaries):
    """Write the open and land boundary sections of a fort.14 to the text ``handle``, node numbers from 1."""
    # node lists may be any sequence (lists included), as check_boundary_nodes accepts them
    handle.write(f"{len(boundaries.open)} = Number of open boundaries\n")
    handle.write(f"{sum(len(b.nodes) for b in boundaries.open)} = Total number of open boundary nodes\n")
    for number, boundary in enumerate(boundaries.open, start=1):
        flag = "" if boundary.ibtype is None else f" {boundary.ibtype}"
        handle.write(f"{len(boundary.nodes)}{flag} = Number of nodes for open boundary {number}\n")
        write_rows(handle, np.asarray(boundary.nodes, dtype=np.int64) + 1, fmt="%d")
    total = sum(len(b.nodes) * (2 if b.ibtype in PAIRED_TYPES else 1) for b in boundaries.land)
    handle.write(f"{len(boundaries.land)} = Number of land boundaries\n")
    handle.write(f"{total} = Total number of land boundary nodes\n")
    for number, boundary in enumerate(boundaries.land, start=1):
        handle.write(f"{len(boundary.nodes)} {boundary.ibtype} = Number of nodes for land boundary {number}\n")
        columns = [np.asarray(boundary.nodes, dtype=np.int64) + 1]
        formats = ["%d"]
        if boundary.paired_nodes is not None:
            columns.append(np.asarray(boundary.paired_nodes, dtype=np.int64) + 1)
            formats.append("%d")
        if boundary.values is not None:
            values = np.asarray(boundary.values, dtype=np.float64)
            columns.extend(values.T)
            formats.extend(["%.17g"] * values.shape[1])
        write_rows(handle, np.column_stack(columns), fmt=" ".join(formats))
