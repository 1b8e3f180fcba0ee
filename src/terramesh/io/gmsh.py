"""Gmsh 2.2 ASCII ``.msh`` files, read by a compiled parser and written in tables.

meshio's Gmsh reader parses each element line in Python: 16.8 s for a
801k-vertex seismic mesh, against 0.9 s for the same mesh as VTU. Here the
``$Nodes``, ``$Elements`` and ``$NodeData`` tables are parsed where they
lie in the file's bytes (:mod:`terramesh._kernels.text`), with the same
result as meshio's reader for the geometry, the element blocks and the
node data; every other section (``$PhysicalNames``, ``$ElementData``,
``$Comments``...) is skipped. Gmsh 4 and binary files are left to meshio.
Written (:func:`write_gmsh22`), the node and element tables go out a chunk
of rows at a time (meshio's writer took 12.9 s for 917k vertices).

Reference: Gmsh reference manual, "MSH file format version 2 (legacy)",
https://gmsh.info/doc/texinfo/gmsh.html#MSH-file-format-version-2-_0028Legacy_0029
"""

import re

import numpy as np

from .._kernels import text as kernels
from ..errors import MeshFormatError
from ._text import write_rows

__all__ = ["read_gmsh22", "write_gmsh22"]

_NEWLINE = b"\n"
_BLANKS = re.compile(rb"\s*")
_PROBLEMS = {
    kernels.FEW_NUMBERS: "too few numbers for one of its {what}",
    kernels.MANY_NUMBERS: "more numbers than one of its {what} holds",
}


class _File:
    """A Gmsh file's bytes with a cursor, and errors that name the file and the line."""

    def __init__(self, path, data):
        self.path = path
        self.data = data
        self.bytes = np.frombuffer(data, dtype=np.uint8)
        self.at = 0

    def error(self, problem, at=None):
        """The MeshFormatError for ``problem``, at the line of offset ``at`` (none: no line)."""
        where = "" if at is None else f"line {self.data.count(_NEWLINE, 0, at) + 1}: "
        return MeshFormatError(
            f"{self.path}: cannot read as gmsh: the file is truncated or malformed ({where}{problem})"
        )

    def line(self, what):
        """The next line that is not blank, stripped, and its offset; MeshFormatError where the file ends."""
        while True:
            end = self.data.find(b"\n", self.at)
            end = len(self.data) if end < 0 else end
            start, self.at = self.at, end + 1
            text = self.data[start:end].strip()
            if text:
                return text.decode("utf-8", errors="replace"), start
            if end == len(self.data):
                raise self.error(f"the file ends where {what} should be")

    def at_end(self):
        """Whether only blanks are left."""
        return _BLANKS.match(self.data, self.at).end() == len(self.data)  # matched in place: no copy of the rest

    def whole(self, what):
        """The next line as a whole number of at least zero."""
        text, start = self.line(what)
        try:
            value = int(text)
        except ValueError:
            raise self.error(f"{text!r} is no {what}", start) from None
        if value < 0:
            raise self.error(f"{what} {value} is negative", start)
        return value

    def close(self, name, count, what):
        """Step over ``$End<name>`` after a table of ``count`` rows."""
        text, start = self.line(f"$End{name}")
        if text == f"$End{name}":
            return
        if text.startswith("$"):
            raise self.error(f"{text} where $End{name} should be", start)
        raise self.error(f"${name} holds more {what} than the {count:,} its header counts", start)

    def skip(self, name):
        """Step over a section this reader does not keep."""
        found = self.data.find(f"\n$End{name}".encode(), self.at - 1)
        if found < 0:
            raise self.error(f"the file ends inside its ${name} section (no $End{name})")
        self.at = found + 1
        self.line(f"$End{name}")

    def check(self, status, where, done, count, name, what):
        """Raise for a row reader's ``status`` (see :mod:`terramesh._kernels.text`)."""
        if status == kernels.ROWS_READ:
            return
        if status == kernels.SECTION_ENDS:
            if where == len(self.data):
                raise self.error(f"the file ends after {done:,} of the {count:,} {what} its ${name} header counts")
            raise self.error(f"${name} holds {done:,} {what} where its header counts {count:,}", where)
        if status in _PROBLEMS:
            end = self.data.find(b"\n", where)
            line = self.data[where : len(self.data) if end < 0 else end].strip().decode("utf-8", errors="replace")
            raise self.error(f"{_PROBLEMS[status].format(what=what)}: {line!r}", where)
        token = self.data[where : where + 40].split(None, 1)[0].decode("utf-8", errors="replace")
        if status == kernels.NOT_WHOLE:
            raise self.error(f"{token!r} is not a whole number", where)
        if status == kernels.UNKNOWN_TYPE:
            raise self.error(f"element type {token} is none Gmsh 2.2 knows", where)
        raise self.error(f"negative tag count {token}", where)

    def reals(self, count, columns, name, what):
        """``count`` rows of a whole number and ``columns`` reals: ``(numbers, values)``."""
        numbers, values, deferred, done, status, where = kernels.real_rows(self.bytes, self.at, count, columns)
        self.check(status, where, done, count, name, what)
        self.at = where
        flat = values.reshape(-1)
        # the few tokens the kernel leaves (nan, inf, subnormals, 20+ digits): Python reads them, as strtod would
        for index, start, end in deferred.tolist():
            token = self.data[start:end]
            try:
                if b"_" in token:  # Python's float reads "1_0"; strtod (meshio, Gmsh) does not
                    raise ValueError
                flat[index] = float(token)
            except ValueError:
                raise self.error(f"{token.decode('utf-8', errors='replace')!r} is not a number", start) from None
        self.close(name, count, what)
        return numbers, values


def _is_ascii_2(source):
    """Whether ``$MeshFormat`` says Gmsh 2 ASCII (version ``2`` or ``2.x``, file type 0), the cursor after it.

    False where the file does not start as a Gmsh file does, for meshio to
    say what it makes of it.
    """
    try:
        text, _ = source.line("$MeshFormat")
        while text == "$Comments":  # meshio and Gmsh skip comments before the format
            source.skip("Comments")
            text, _ = source.line("$MeshFormat")
        if text != "$MeshFormat":
            return False
        fields = source.line("the format")[0].split()
    except MeshFormatError:
        return False
    if len(fields) < 2 or fields[0].split(".")[0] != "2" or fields[1] != "0":
        return False
    source.skip("MeshFormat")
    return True


def _node_lookup(source, numbers):
    """``index_of(values)``: the rows of the nodes numbered ``values`` (int64), -1 for a number none has."""
    n_nodes = len(numbers)
    # the span in Python integers: in int64 it wraps for numbers near both ends of the range
    if n_nodes and int(numbers[-1]) - int(numbers[0]) == n_nodes - 1 and np.all(np.diff(numbers) == 1):
        # numbered one after another, as writers number them: a subtraction, no search

        def index_of(values):
            index = values - numbers[0]
            return np.where((index >= 0) & (index < n_nodes), index, -1)

        return index_of
    order = np.argsort(numbers, kind="stable")
    ordered = numbers[order]
    repeated = np.flatnonzero(ordered[1:] == ordered[:-1])
    if len(repeated):
        raise source.error(f"node number {ordered[repeated[0]]} appears twice in $Nodes")

    def index_of(values):
        if not n_nodes:
            return np.full(values.shape, -1, dtype=np.int64)
        position = np.minimum(np.searchsorted(ordered, values), n_nodes - 1)
        return np.where(ordered[position] == values, order[position], -1)

    return index_of


def _node_data(source, index_of, n_nodes, name, numbers, values):
    """``values`` (one row per number in ``numbers``) as one row per node; MeshFormatError where they do not fit."""
    index = index_of(numbers)
    if np.any(index < 0):
        missing = numbers[np.flatnonzero(index < 0)[0]]
        raise source.error(f"$NodeData {name!r} gives a value for node {missing}, which $Nodes does not hold")
    covered = np.zeros(n_nodes, dtype=bool)
    covered[index] = True
    if len(numbers) != n_nodes or not covered.all():
        raise source.error(f"$NodeData {name!r} holds {len(numbers):,} values for {n_nodes:,} nodes")
    data = np.empty_like(values)
    data[index] = values
    return data[:, 0] if data.shape[1] == 1 else data


def _cell_blocks(source, types, numbers, starts, nodes, index_of):
    """One meshio ``(type, cells)`` pair per element type, in the order the types first appear."""
    # private in meshio, with no public form: the Gmsh type and node-order tables its own reader uses
    from meshio.gmsh.common import _gmsh_to_meshio_order, _gmsh_to_meshio_type

    index = index_of(nodes)
    if np.any(index < 0):
        at = np.flatnonzero(index < 0)[0]
        element = numbers[np.searchsorted(starts, at, side="right") - 1]
        raise source.error(f"element {element} refers to node {nodes[at]}, which $Nodes does not hold")
    # types are small numbers: counted, not sorted (np.unique sorted 1.8 million in 0.1 s)
    kinds = np.flatnonzero(np.bincount(types))
    blocks = []
    for kind in sorted(kinds, key=lambda kind: np.argmax(types == kind)):
        rows = np.flatnonzero(types == kind)
        width = starts[rows[0] + 1] - starts[rows[0]]
        if rows[-1] - rows[0] == len(rows) - 1:  # one run of rows, as writers group them: a view, no gather
            cells = index[starts[rows[0]] : starts[rows[-1] + 1]].reshape(len(rows), width)
        else:
            cells = index[starts[rows][:, None] + np.arange(width)]
        name = _gmsh_to_meshio_type[int(kind)]
        blocks.append((name, _gmsh_to_meshio_order(name, cells)))
    return blocks


def _node_counts():
    """Nodes per element, indexed by Gmsh element type (0: no type)."""
    # private in meshio, with no public form (as in _cell_blocks): the cell sizes and Gmsh types its reader uses
    from meshio._common import num_nodes_per_cell
    from meshio.gmsh.common import _gmsh_to_meshio_type

    counts = np.zeros(max(_gmsh_to_meshio_type) + 1, dtype=np.int64)
    for kind, name in _gmsh_to_meshio_type.items():
        counts[kind] = num_nodes_per_cell[name]
    return counts


def read_gmsh22(path):
    r"""Read a Gmsh 2.2 ASCII ``.msh`` file as meshio's reader does, or None for another Gmsh file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    meshio.Mesh or None
        ``points`` (float64, ``(n, 3)``, in the file's node order), one cell
        block per element type in the order the types first appear (cells
        as 0-based int64 rows into ``points``, in file order, node order as
        meshio's), and ``point_data``: each ``$NodeData`` section's values
        by its name (float64, ``(n,)`` for one component, else ``(n, k)``),
        the last section of a name kept. No cell data: physical and
        geometrical tags and ``$ElementData`` are skipped, the names of the
        latter listed in ``info["element_data"]``. None for a file
        of another version (Gmsh 4) or a binary one, for meshio to read.

    Raises
    ------
    MeshFormatError
        For a truncated or malformed file, saying what is wrong and on
        which line: a section that ends early or holds more rows than its
        header counts, a line with too few or too many numbers, text that is
        no number, an unknown element type, an element or ``$NodeData``
        that refers to a node ``$Nodes`` does not hold, node numbers that
        repeat.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "one.msh")
    >>> with open(path, "w") as handle:
    ...     _ = handle.write(
    ...         "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n10 0 0 0\n20 1 0 0\n30 0 1 0\n$EndNodes\n"
    ...         "$Elements\n2\n1 15 2 0 1 10\n2 2 2 0 1 10 20 30\n$EndElements\n"
    ...     )
    >>> mesh = read_gmsh22(path)
    >>> mesh.points.shape, [(block.type, block.data.tolist()) for block in mesh.cells]
    ((3, 3), [('vertex', [[0]]), ('triangle', [[0, 1, 2]])])
    """
    import meshio

    with open(path, "rb") as handle:
        source = _File(path, handle.read())
    if not _is_ascii_2(source):
        return None
    numbers = points = elements = None
    raw_data, element_data = {}, []
    while not source.at_end():
        section, start = source.line("a section")
        if not section.startswith("$"):
            raise source.error(f"{section[:40]!r} where a section ($Name) should start", start)
        name = section[1:]
        if name == "Nodes":
            count = source.whole("node count")
            numbers, points = source.reals(count, 3, name, "nodes")
        elif name == "Elements":
            count = source.whole("element count")
            types, element_numbers, starts, nodes, done, status, where = kernels.element_rows(
                source.bytes, source.at, count, _node_counts()
            )
            source.check(status, where, done, count, name, "elements")
            source.at = where
            source.close(name, count, "elements")
            elements = types, element_numbers, starts, nodes
        elif name == "NodeData":
            data_name, components, count = _data_header(source)
            raw_data[data_name] = source.reals(count, components, name, "values")
        elif name == "ElementData":  # not kept, but named: the caller says what it left out
            if source.whole("string tag count") > 0:
                element_data.append(source.line("an $ElementData name")[0].replace('"', ""))
            source.skip(name)
        else:
            source.skip(name)
    if points is None:
        if elements is not None or raw_data:
            raise source.error("the file has no $Nodes section")
        return meshio.Mesh(np.empty((0, 3)), [])
    index_of = _node_lookup(source, numbers)
    blocks = [] if elements is None else _cell_blocks(source, *elements, index_of)
    point_data = {
        data_name: _node_data(source, index_of, len(points), data_name, *values)
        for data_name, values in raw_data.items()
    }
    return meshio.Mesh(points, blocks, point_data=point_data, info={"element_data": element_data})


def _data_header(source):
    """A ``$NodeData`` header: the view's name (quotes removed, as meshio does), components, values."""
    names = [source.line("a $NodeData name")[0].replace('"', "") for _ in range(source.whole("string tag count"))]
    for _ in range(source.whole("real tag count")):
        source.line("a $NodeData real tag")
    integers = [source.whole("$NodeData integer tag") for _ in range(source.whole("integer tag count"))]
    if not names or len(integers) < 3 or integers[1] < 1:
        raise source.error("$NodeData needs a name and 3 integer tags (time step, components, values)", source.at)
    return names[0], integers[1], integers[2]


GMSH_COMPONENTS = (1, 3, 9)
"""Values per node or element a Gmsh view holds: a scalar, a vector, a tensor."""


def write_gmsh_view(handle, section, name, ids, values, fmt="%.17g"):
    """Write a ``$NodeData`` or ``$ElementData`` view: ``values`` (k,) or (k, 1|3|9) of the nodes or elements ``ids``.

    Gmsh 2.2's layout: one string tag (the name), one real tag (the time,
    0), three integer tags (time step 0, the components, the count), then
    ``id value...`` rows. Reals to 17 significant digits by default: read
    back bit for bit.

    Examples
    --------
    >>> import io, numpy as np
    >>> out = io.StringIO()
    >>> write_gmsh_view(out, "NodeData", "depth", np.arange(1, 3), np.array([5.0, 7.5]))
    >>> print(out.getvalue(), end="")
    $NodeData
    1
    "depth"
    1
    0.0
    3
    0
    1
    2
    1 5
    2 7.5
    $EndNodeData
    """
    table = np.asarray(values, dtype=np.float64).reshape(len(ids), -1)
    handle.write(f'${section}\n1\n"{name}"\n1\n0.0\n3\n0\n{table.shape[1]}\n{len(ids)}\n')
    write_rows(handle, np.column_stack([ids, table]), fmt=["%d"] + [fmt] * table.shape[1])
    handle.write(f"$End{section}\n")


def write_gmsh22(handle, points, blocks, names=()):
    """Write the ``$MeshFormat``, ``$PhysicalNames``, ``$Nodes`` and ``$Elements`` of a Gmsh 2.2 ASCII file.

    Parameters
    ----------
    handle : text file
        Open for writing; the caller adds any further sections (``$NodeData``, ``$Comments``).
    points : ndarray, shape (n, 2) or (n, 3)
        Coordinates (2D gets a zero z, as Gmsh stores three), written to 17
        significant digits: read back bit for bit.
    blocks : sequence of (int, ndarray, ndarray)
        ``(gmsh_type, cells, tags)`` in file order: the Gmsh element type
        (1 line, 2 triangle, 4 tetrahedron), 0-based node rows (k, corners)
        and each element's physical tag (k,), written as its geometrical
        tag too. Elements are numbered from 1 through the blocks.
    names : sequence of (int, int, str), optional
        ``(dimension, tag, name)`` of the physical groups; none: no ``$PhysicalNames``.

    Examples
    --------
    >>> import io, numpy as np
    >>> out = io.StringIO()
    >>> write_gmsh22(out, np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), [(2, np.array([[0, 1, 2]]), np.array([1]))])
    >>> print(out.getvalue(), end="")
    $MeshFormat
    2.2 0 8
    $EndMeshFormat
    $Nodes
    3
    1 0 0 0
    2 1 0 0
    3 0 1 0
    $EndNodes
    $Elements
    1
    1 2 2 1 1 1 2 3
    $EndElements
    """
    n_points = len(points)
    handle.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
    if names:
        handle.write(f"$PhysicalNames\n{len(names)}\n")
        handle.writelines(f'{dimension} {tag} "{name}"\n' for dimension, tag, name in names)
        handle.write("$EndPhysicalNames\n")
    handle.write(f"$Nodes\n{n_points}\n")
    table = np.column_stack([np.arange(1, n_points + 1), points, np.zeros((n_points, 3 - points.shape[1]))])
    write_rows(handle, table, fmt=["%d"] + ["%.17g"] * 3)
    handle.write("$EndNodes\n")
    handle.write(f"$Elements\n{sum(len(cells) for _, cells, _ in blocks)}\n")
    first = 1
    for gmsh_type, cells, tags in blocks:
        count = len(cells)
        # elm-number elm-type number-of-tags physical elementary node-numbers...
        rows = np.column_stack(
            [np.arange(first, first + count), np.full(count, gmsh_type), np.full(count, 2), tags, tags, cells + 1]
        )
        write_rows(handle, rows, fmt="%d")
        first += count
    handle.write("$EndElements\n")
