"""A mesh's nodal attributes: values at every node with their units and defaults.

ADCIRC's ``fort.13`` holds them (:mod:`terramesh.io.fort13` reads and
writes it); :mod:`terramesh.coastal.nodal_attributes` computes two of them
from a mesh. They live in the core so that the computing needs no file
format, as a mesh's boundaries do (:mod:`terramesh.mesh.boundaries`).
"""

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..errors import MeshFormatError

__all__ = ["NodalAttribute", "NodalAttributes", "one_line"]


@dataclass(eq=False)
class NodalAttribute:
    """One nodal attribute: units, default values and the value at every node.

    Attributes
    ----------
    units : str
        Free text, e.g. ``"unitless"`` or ``"m"`` (the file's ``Units`` line);
        a line break in it becomes a space.
    default : numpy.ndarray, shape (k,)
        ``DefaultAttrVal``: the values of nodes not listed in the file.
    values : numpy.ndarray, shape (n, k)
        Values at every node (float64); a 1-D array is one value per node.

    Examples
    --------
    >>> import numpy as np
    >>> tau0 = NodalAttribute.from_values(np.array([0.03, 0.03, 0.005, 0.03]))
    >>> tau0.default.tolist(), int(tau0.non_default.sum()), tau0.values_per_node
    ([0.03], 1, 1)
    """

    units: str
    default: np.ndarray
    values: np.ndarray

    def __post_init__(self):
        self.units = one_line(self.units) or "unitless"
        self.default = np.atleast_1d(np.asarray(self.default, dtype=np.float64)).copy()
        values = np.array(self.values, dtype=np.float64)
        if values.ndim == 1:
            values = values[:, None]
        if self.default.ndim != 1 or values.ndim != 2 or values.shape[1] != len(self.default):
            raise MeshFormatError(
                f"a nodal attribute needs default values of shape (k,) and values of shape (n, k); "
                f"got {self.default.shape} and {np.shape(self.values)}"
            )
        self.values = values

    @classmethod
    def from_values(cls, values, *, units="unitless", default=None, prefer=None):
        """An attribute from its values at every node; by default the most frequent row is the default.

        Parameters
        ----------
        values : array_like, shape (n,) or (n, k)
        units : str, optional
        default : array_like, shape (k,), optional
        prefer : array_like, shape (k,), optional
            The default where it is one of the most frequent rows (or no
            node has values); other ties go to the smallest row.

        Returns
        -------
        NodalAttribute
        """
        values = np.asarray(values, dtype=np.float64)
        table = values[:, None] if values.ndim == 1 else values
        if default is None:
            preferred = None if prefer is None else np.atleast_1d(np.asarray(prefer, dtype=np.float64))
            if len(table) == 0:
                if preferred is None:
                    raise MeshFormatError("give the default of a nodal attribute with no nodes")
                return cls(units, preferred, table)
            rows, counts = np.unique(table, axis=0, return_counts=True)
            default = rows[np.argmax(counts)]
            if preferred is not None and np.count_nonzero(np.all(table == preferred, axis=1)) == counts.max():
                default = preferred
        return cls(units, default, table)

    @property
    def values_per_node(self):
        """``ValuesPerNode``: number of values at each node."""
        return len(self.default)

    @property
    def non_default(self):
        """Boolean mask of the nodes whose values differ from the default, shape ``(n,)``."""
        return np.any(self.values != self.default, axis=1)

    def renumbered(self, new_index):
        """Copy with node ``i`` moved to ``new_index[i]`` (see :func:`terramesh.postprocess.renumber`).

        Parameters
        ----------
        new_index : array_like of int, shape (n,)
            The new number of each node: a permutation of ``0 .. n - 1``.

        Returns
        -------
        NodalAttribute

        Raises
        ------
        MeshFormatError
            If ``new_index`` is not a permutation of ``0 .. n - 1`` (wrong
            length, repeated or missing numbers, non-integers).
        """
        n = len(self.values)
        index = np.asarray(new_index)
        if index.shape != (n,):
            raise MeshFormatError(f"new_index must have shape ({n},), one new number per node; got {index.shape}")
        if n and not np.issubdtype(index.dtype, np.integer):
            raise MeshFormatError(f"new_index must hold integers, got dtype {index.dtype}")
        # a repeated number would leave another row unset: uninitialised memory in the copy
        if n and not np.array_equal(np.sort(index), np.arange(n)):
            raise MeshFormatError(f"new_index must be a permutation of 0..{n - 1}, each node numbered once")
        values = np.empty_like(self.values)
        values[index] = self.values
        return NodalAttribute(self.units, self.default, values)


@dataclass(eq=False)
class NodalAttributes(Mapping):
    """The attributes of a fort.13 file, by name, in file order.

    A read-only mapping of attribute name to :class:`NodalAttribute`; build
    one from a dict. ``title`` is the file's ``AGRID`` line.

    Examples
    --------
    >>> import numpy as np
    >>> n = NodalAttribute("unitless", [0.02], np.full(3, 0.02))
    >>> attributes = NodalAttributes({"mannings_n_at_sea_floor": n}, title="demo")
    >>> list(attributes), attributes.n_nodes
    (['mannings_n_at_sea_floor'], 3)
    """

    attributes: dict = field(default_factory=dict)
    title: str = "terramesh"

    def __post_init__(self):
        self.attributes = dict(self.attributes)
        for name, attribute in self.attributes.items():
            if not isinstance(attribute, NodalAttribute):
                raise MeshFormatError(f"attribute {name!r} is a {type(attribute).__name__}, not a NodalAttribute")
            if not isinstance(name, str) or not name or len(name.split()) != 1:
                raise MeshFormatError(f"attribute names are one word without spaces, got {name!r}")
        sizes = {len(attribute.values) for attribute in self.attributes.values()}
        if len(sizes) > 1:
            raise MeshFormatError(f"the attributes have different numbers of nodes: {sorted(sizes)}")

    def __getitem__(self, name):
        return self.attributes[name]

    def __iter__(self):
        return iter(self.attributes)

    def __len__(self):
        return len(self.attributes)

    @property
    def n_nodes(self):
        """Number of nodes (None without attributes)."""
        return next((len(a.values) for a in self.attributes.values()), None)

    def renumbered(self, new_index):
        """Copy with node ``i`` moved to ``new_index[i]`` in every attribute."""
        return NodalAttributes({name: a.renumbered(new_index) for name, a in self.attributes.items()}, self.title)


def one_line(text):
    r"""``text`` (None: empty) on one line, stripped: each line break a space, its other blanks kept.

    Every break that the reader's ``str.splitlines`` splits at counts
    (``\r``, ``\x0c``, ``\u2028`` ...): a ``"\r"`` in a title or units,
    written as is, left a file that ``read_fort13`` could not read; a
    fort.14 title's double blanks were made single, and it read back otherwise.
    Other blanks stay, so that a title read and written again is the same.
    """
    return " ".join(str(text or "").splitlines()).strip()
