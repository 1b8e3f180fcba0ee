"""ADCIRC ``fort.13`` nodal attributes files.

Layout (ADCIRC documentation, "Nodal Attributes File (fort.13)"):

* ``AGRID`` title line; ``NumOfNodes``; ``NAttr``;
* per attribute: ``AttrName``, ``Units``, ``ValuesPerNode`` and the
  ``ValuesPerNode`` default values ``DefaultAttrVal``;
* per attribute again (any order): ``AttrName``, ``NumNodesNotDefaultVal``
  and that many lines ``n AttrVal(n, 1..ValuesPerNode)`` (1-based node
  numbers).

Attributes named in the ADCIRC documentation, with their values per node,
include ``primitive_weighting_in_continuity_equation`` (1, ``tau0``),
``mannings_n_at_sea_floor`` (1), ``internal_tide_friction`` (1, a scalar, or 3,
a tensor; "Internal Tide Energy Conversion" in the ADCIRC documentation) and
``surface_directional_effective_roughness_length`` (12); any other name is
read and written the same way. The reader takes text after the expected
values as a comment, and reals with Fortran's D exponent (``1.0D+01``) as
ADCIRC does; the writer lists only nodes whose values differ from the
default, with 15 significant digits, or 17 where 15 would not read back to
the same float.
"""

import numpy as np

from ..errors import MeshFormatError, warn_user
from ..mesh.nodal_attributes import NodalAttribute, NodalAttributes, one_line
from ._text import fortran_real, written_whole
from .fort14 import LineCursor

__all__ = ["NodalAttribute", "NodalAttributes", "KNOWN_VALUES_PER_NODE", "read_fort13", "write_fort13"]

KNOWN_VALUES_PER_NODE = {
    "primitive_weighting_in_continuity_equation": (1,),
    "mannings_n_at_sea_floor": (1,),
    "quadratic_friction_coefficient_at_sea_floor": (1,),
    "chezy_friction_coefficient_at_sea_floor": (1,),
    "bottom_roughness_length": (1,),
    "sea_surface_height_above_geoid": (1,),
    "surface_submergence_state": (1,),
    "surface_canopy_coefficient": (1,),
    "average_horizontal_eddy_viscosity_in_sea_water_wrt_depth": (1,),
    "elemental_slope_limiter": (1,),
    "advection_state": (1,),
    "wave_refraction_in_swan": (1,),
    # ADCIRC documentation, "Internal Tide Energy Conversion"
    # (https://adcirc.github.io/adcirc/user_guide/model_configuration/tides/internal_tide_energy_conversion.html):
    # "ADCIRC reads the internal_tide_friction attribute in as the IT_Fric variable, which can
    # have 1 (scalar) or 3 (tensor) dimensions". OceanMesh2D's Calc_IT_Fric and Make_IT_Fric.m
    # offer a scalar form besides the directional (tensor) one that
    # terramesh.coastal.internal_tide_friction computes.
    "internal_tide_friction": (1, 3),
    "surface_directional_effective_roughness_length": (12,),
}
"""``ValuesPerNode`` counts ADCIRC reads for the attributes it knows (a tuple per name);
:func:`write_fort13` refuses any other count for them and :func:`read_fort13` warns."""


def _counts(expected):
    """The counts of :data:`KNOWN_VALUES_PER_NODE` in words: ``3`` or ``1 or 3``."""
    return " or ".join(str(count) for count in expected)


def _next_line(lines, what):
    """The next line, stripped; a clear error when the file has ended."""
    if lines.position >= len(lines.lines):
        raise MeshFormatError(f"{lines.path}: file ends early, expected {what} at line {lines.position + 1}")
    lines.position += 1
    return lines.lines[lines.position - 1].strip()


def _next_floats(lines, count, what):
    """``count`` reals from the next line(s), as Fortran list-directed input; the rest of the last line is a comment."""
    values = []
    while len(values) < count:
        tokens = _next_line(lines, what).replace(",", " ").split()
        try:
            numbers = [fortran_real(token) for token in tokens[: count - len(values)]]
        except ValueError as error:
            raise MeshFormatError(f"{lines.path}: line {lines.position}: cannot read {what}: {error}") from error
        if not numbers:
            raise MeshFormatError(f"{lines.path}: line {lines.position}: {what} is missing")
        values.extend(numbers)
    return np.array(values)


def read_fort13(path):
    """Read an ADCIRC fort.13 nodal attributes file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    NodalAttributes
        Every attribute with its dense ``(NumOfNodes, ValuesPerNode)``
        values, default where the file lists no value; ``title`` is AGRID.

    Raises
    ------
    MeshFormatError
        For truncated or malformed files (the message names the attribute
        and line), node numbers outside ``1..NumOfNodes`` or listed twice
        for one attribute, NaN or infinite values, lines left after the
        last attribute's values, or attributes listed in one section and
        missing from the other.

    Warns
    -----
    TerrameshWarning
        For an attribute of :data:`KNOWN_VALUES_PER_NODE` with another
        number of values per node (read as written; ADCIRC would misread it).

    Examples
    --------
    >>> import numpy as np, os, tempfile
    >>> tau0 = NodalAttribute.from_values(np.array([0.03, 0.005, 0.03]))
    >>> path = os.path.join(tempfile.mkdtemp(), "fort.13")
    >>> write_fort13(path, {"primitive_weighting_in_continuity_equation": tau0}, 3)
    >>> read_fort13(path)["primitive_weighting_in_continuity_equation"].values.ravel().tolist()
    [0.03, 0.005, 0.03]
    """
    with open(path, encoding="utf-8", errors="replace") as handle:
        lines = LineCursor(handle.read(), path)
    if not lines.lines:
        raise MeshFormatError(f"{path}: empty file")
    title = lines.lines[0].strip()
    lines.position = 1
    (n_nodes,) = lines.next_numbers(1, "NumOfNodes")
    (n_attributes,) = lines.next_numbers(1, "NAttr")
    if n_nodes < 0 or n_attributes < 0:
        raise MeshFormatError(f"{path}: negative NumOfNodes or NAttr")
    headers = {}
    for number in range(1, n_attributes + 1):
        name = _next_line(lines, f"AttrName of attribute {number} of {n_attributes}").split()
        if not name:
            raise MeshFormatError(f"{path}: line {lines.position}: AttrName of attribute {number} is blank")
        name = name[0]
        units = _next_line(lines, f"Units of {name}")
        (count,) = lines.next_numbers(1, f"ValuesPerNode of {name}")
        if count < 1:
            raise MeshFormatError(f"{path}: line {lines.position}: ValuesPerNode of {name} must be at least 1")
        expected = KNOWN_VALUES_PER_NODE.get(name)
        if expected is not None and count not in expected:
            # read as written (the file may come from a model that differs), but ADCIRC would misread it
            warn_user(
                f"{path}: line {lines.position}: {name} has {count} values per node; ADCIRC reads {_counts(expected)}"
            )
        default = _next_floats(lines, count, f"{count} DefaultAttrVal of {name}")
        if not np.all(np.isfinite(default)):
            raise MeshFormatError(f"{path}: line {lines.position}: DefaultAttrVal of {name} is not finite: {default}")
        headers[name] = (units, default)
    attributes = {}
    for _ in range(n_attributes):
        missing = [name for name in headers if name not in attributes]
        name = _next_line(lines, f"AttrName of the values of {', '.join(missing)}").split()
        name = name[0] if name else ""
        if name not in headers:
            raise MeshFormatError(f"{path}: line {lines.position}: attribute {name!r} was not declared in the header")
        if name in attributes:
            raise MeshFormatError(f"{path}: line {lines.position}: values of {name} given twice")
        units, default = headers[name]
        (count,) = lines.next_numbers(1, f"NumNodesNotDefaultVal of {name}")
        if count < 0:
            raise MeshFormatError(f"{path}: line {lines.position}: negative NumNodesNotDefaultVal of {name}")
        what = f"non-default values of {name} (node and {len(default)} values)"
        table = lines.block(count, 1 + len(default), what) if count else np.empty((0, 1 + len(default)))
        nodes = table[:, 0]
        if np.any((nodes < 1) | (nodes > n_nodes) | (nodes != np.round(nodes))):
            bad = nodes[(nodes < 1) | (nodes > n_nodes) | (nodes != np.round(nodes))][0]
            raise MeshFormatError(f"{path}: {name} gives a value at node {bad:g}, outside 1..{n_nodes}")
        first = lines.position - count + 1
        unique, where, repeats = np.unique(nodes, return_index=True, return_counts=True)
        if np.any(repeats > 1):
            node = unique[repeats > 1][0]
            raise MeshFormatError(
                f"{path}: {name} lists node {node:g} twice (first at line {first + where[repeats > 1][0]})"
            )
        not_finite = ~np.isfinite(table[:, 1:]).all(axis=1)
        if np.any(not_finite):
            row = np.flatnonzero(not_finite)[0]
            raise MeshFormatError(f"{path}: line {first + row}: a value of {name} at node {nodes[row]:g} is not finite")
        values = np.tile(default, (n_nodes, 1))
        values[nodes.astype(np.int64) - 1] = table[:, 1:]
        attributes[name] = NodalAttribute(units, default, values)
    if lines.position < len(lines.lines):
        raise MeshFormatError(
            f"{path}: line {lines.position + 1}: {len(lines.lines) - lines.position} lines after the values of the "
            f"last attribute: is a NumNodesNotDefaultVal too small?"
        )
    return NodalAttributes({name: attributes[name] for name in headers}, title=title)


def format_columns(values):
    """The shortest decimal strings that read back exactly (Python's ``repr`` of a float), a list per column.

    ``np.char.mod("%.15g")``, read back to find the values that needed
    ``%.17g``, and joined column by column with ``np.char.add``, took 0.91 s
    for 149k nodes of two attributes (``benchmarks/bench_io.py``).
    """
    return [
        list(map(repr, column)) for column in np.asarray(values, dtype=np.float64).reshape(len(values), -1).T.tolist()
    ]


def write_fort13(path, attributes, n_nodes, *, title=None):
    """Write an ADCIRC fort.13 nodal attributes file.

    Parameters
    ----------
    path : str or os.PathLike
    attributes : NodalAttributes or mapping of str to NodalAttribute
        Attributes in the order to write; each with ``n_nodes`` rows.
    n_nodes : int
        ``NumOfNodes``: the number of nodes of the fort.14 grid.
    title : str, optional
        The AGRID line (a line break in it becomes a space); by default the
        attributes' title or "terramesh".

    Raises
    ------
    MeshFormatError
        If ``attributes`` is not a mapping of names to attributes (one
        :class:`NodalAttribute` alone has no name), if an attribute's number of rows is not ``n_nodes``, one of its
        values or defaults is NaN or infinite (ADCIRC reads no such value),
        or an attribute of :data:`KNOWN_VALUES_PER_NODE` has another number
        of values per node (ADCIRC reads the count it expects, not the one in
        the file). No file is written then.

    Examples
    --------
    Only the nodes whose values differ from the default are listed, with
    1-based node numbers:

    >>> import pathlib, tempfile
    >>> import numpy as np
    >>> tau0 = NodalAttribute.from_values(np.array([0.03, 0.005, 0.03]))
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "fort.13"
    >>> write_fort13(path, {"primitive_weighting_in_continuity_equation": tau0}, 3, title="demo")
    >>> print(path.read_text(), end="")
    demo
    3
    1
    primitive_weighting_in_continuity_equation
    unitless
    1
    0.03
    primitive_weighting_in_continuity_equation
    1
    2 0.005
    """
    if isinstance(attributes, NodalAttribute):
        raise MeshFormatError(
            "write_fort13 takes attributes by their ADCIRC names, a mapping such as "
            '{"primitive_weighting_in_continuity_equation": tau0(mesh)}, not one NodalAttribute'
        )
    if not isinstance(attributes, NodalAttributes):
        try:
            attributes = NodalAttributes(dict(attributes))
        except (TypeError, ValueError) as error:
            raise MeshFormatError(
                f"attributes must map ADCIRC attribute names to NodalAttribute, got {type(attributes).__name__}"
            ) from error
    for name, attribute in attributes.items():
        expected = KNOWN_VALUES_PER_NODE.get(name)
        if expected is not None and attribute.values_per_node not in expected:
            raise MeshFormatError(
                f"attribute {name} has {attribute.values_per_node} values per node; "
                f"ADCIRC reads {_counts(expected)} (ValuesPerNode = {_counts(expected)})"
            )
        if len(attribute.values) != n_nodes:
            raise MeshFormatError(f"attribute {name} has {len(attribute.values)} rows for {n_nodes} nodes")
        if not np.all(np.isfinite(attribute.default)):
            raise MeshFormatError(f"attribute {name}: the default {attribute.default.tolist()} is NaN or infinite")
        bad = np.flatnonzero(~np.isfinite(attribute.values).all(axis=1))
        if len(bad):
            raise MeshFormatError(
                f"attribute {name}: values NaN or infinite at {len(bad)} of {n_nodes} nodes (node {bad[0] + 1} first)"
            )
    title = one_line(title if title is not None else attributes.title) or "terramesh"
    with written_whole(path) as temporary, open(temporary, "w", encoding="utf-8") as handle:
        handle.write(f"{title}\n{n_nodes}\n{len(attributes)}\n")
        for name, attribute in attributes.items():
            default = " ".join(repr(value) for value in attribute.default.tolist())
            handle.write(f"{name}\n{attribute.units}\n{attribute.values_per_node}\n{default}\n")
        for name, attribute in attributes.items():
            nodes = np.flatnonzero(attribute.non_default)
            handle.write(f"{name}\n{len(nodes)}\n")
            if len(nodes):
                columns = format_columns(attribute.values[nodes])
                handle.write(
                    "\n".join(map(" ".join, zip(map(str, (nodes + 1).tolist()), *columns, strict=True))) + "\n"
                )
