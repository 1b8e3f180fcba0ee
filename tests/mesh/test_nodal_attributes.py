import numpy as np
import pytest

from terramesh.errors import MeshFormatError
from terramesh.mesh import NodalAttribute, NodalAttributes


@pytest.mark.parametrize(
    "new_index, message",
    [
        (np.array([0, 0, 1, 2]), r"permutation of 0\.\.3"),  # was: node 3's row left uninitialised
        (np.array([0, 1, 2, 4]), r"permutation of 0\.\.3"),
        (np.array([0, 1, 2]), r"shape \(4,\).*got \(3,\)"),  # was: numpy's shape-mismatch ValueError
        (np.array([[0, 1], [2, 3]]), r"shape \(4,\)"),
        (np.array([0.0, 1.0, 2.0, 3.0]), "integers"),
    ],
)
def test_renumbered_refuses_what_is_not_a_permutation(new_index, message):
    attribute = NodalAttribute.from_values(np.array([1.0, 2.0, 3.0, 4.0]))
    with pytest.raises(MeshFormatError, match=message):
        attribute.renumbered(new_index)
    with pytest.raises(MeshFormatError, match=message):
        NodalAttributes({"a": attribute}).renumbered(new_index)
    moved = attribute.renumbered(np.array([3, 0, 2, 1]))  # node i becomes new_index[i]
    np.testing.assert_array_equal(moved.values.ravel(), [2.0, 4.0, 3.0, 1.0])
    assert NodalAttribute("m", [0.0], np.zeros(0)).renumbered(np.array([], dtype=int)).values.shape == (0, 1)


def test_from_values_prefers_a_given_row_among_the_most_frequent():
    values = np.array([0.02, 0.03, 0.02, 0.03, 0.005])
    assert NodalAttribute.from_values(values).default.tolist() == [0.02]  # a tie goes to the smallest row
    assert NodalAttribute.from_values(values, prefer=0.03).default.tolist() == [0.03]
    assert NodalAttribute.from_values(values, prefer=0.005).default.tolist() == [0.02]  # not among the most frequent
    assert NodalAttribute.from_values(np.empty((0, 3)), prefer=np.zeros(3)).default.tolist() == [0.0, 0.0, 0.0]
