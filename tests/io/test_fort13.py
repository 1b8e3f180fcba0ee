import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from terramesh.errors import MeshFormatError, TerrameshWarning
from terramesh.io import NodalAttribute, NodalAttributes, read_fort13, write_fort13
from terramesh.io.fort13 import KNOWN_VALUES_PER_NODE

# the ADCIRC documentation's layout, with comments after values as real files have them
SAMPLE = """\
Sabine Pass test grid nodal attributes   ! AGRID
5            ! NumOfNodes
4            ! NAttr
primitive_weighting_in_continuity_equation
unitless
1
0.03         ! default tau0
mannings_n_at_sea_floor
s/m^(1/3)
1
0.025
internal_tide_friction
1/s
3
0.0 0.0 0.0
surface_directional_effective_roughness_length
m
12
0 0 0 0 0 0
0 0 0 0 0 0
mannings_n_at_sea_floor
2
2 0.02   ! marsh
5 0.1
primitive_weighting_in_continuity_equation
1
4 0.005
internal_tide_friction
0
surface_directional_effective_roughness_length
1
3 0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8 0.9 1.0 1.1 1.2   ! a forest
"""


def write(tmp_path, text=SAMPLE):
    path = tmp_path / "fort.13"
    path.write_text(text)
    return path


def test_reads_the_documented_layout(tmp_path):
    attributes = read_fort13(write(tmp_path))
    assert attributes.title.startswith("Sabine Pass")
    assert list(attributes) == [
        "primitive_weighting_in_continuity_equation",
        "mannings_n_at_sea_floor",
        "internal_tide_friction",
        "surface_directional_effective_roughness_length",
    ]
    assert attributes.n_nodes == 5
    tau0 = attributes["primitive_weighting_in_continuity_equation"]
    assert tau0.units == "unitless"
    np.testing.assert_array_equal(tau0.values[:, 0], [0.03, 0.03, 0.03, 0.005, 0.03])
    manning = attributes["mannings_n_at_sea_floor"]
    assert manning.units == "s/m^(1/3)"
    np.testing.assert_array_equal(manning.values[:, 0], [0.025, 0.02, 0.025, 0.025, 0.1])
    friction = attributes["internal_tide_friction"]
    assert friction.values.shape == (5, 3) and not friction.non_default.any()
    roughness = attributes["surface_directional_effective_roughness_length"]
    assert roughness.values_per_node == 12  # defaults spread over two lines, as Fortran list-directed input reads
    np.testing.assert_allclose(roughness.values[2], np.arange(1, 13) / 10)
    assert np.all(roughness.values[[0, 1, 3, 4]] == 0)


def test_writer_lists_only_non_default_nodes_and_reads_back(tmp_path):
    attributes = read_fort13(write(tmp_path))
    out = tmp_path / "again.13"
    write_fort13(out, attributes, 5)
    lines = out.read_text().splitlines()
    assert lines[:3] == ["Sabine Pass test grid nodal attributes   ! AGRID", "5", "4"]
    manning = lines.index("mannings_n_at_sea_floor", 10)
    assert lines[manning + 1 : manning + 4] == ["2", "2 0.02", "5 0.1"]
    assert_same(attributes, read_fort13(out))


def assert_same(a, b):
    assert a.title == b.title
    assert list(a) == list(b)
    for name in a:
        assert a[name].units == b[name].units
        np.testing.assert_array_equal(a[name].default, b[name].default)
        np.testing.assert_array_equal(a[name].values, b[name].values)


reals = st.floats(allow_nan=False, allow_infinity=False, width=64)
names = st.one_of(
    st.sampled_from(
        [
            "primitive_weighting_in_continuity_equation",
            "mannings_n_at_sea_floor",
            "internal_tide_friction",
            "surface_directional_effective_roughness_length",
        ]
    ),
    st.from_regex(r"[a-z][a-z_0-9]{0,30}", fullmatch=True),
)


@st.composite
def attribute_sets(draw):
    n_nodes = draw(st.integers(1, 25))
    chosen = draw(st.lists(names, min_size=0, max_size=4, unique=True))
    attributes = {}
    for name in chosen:
        # ADCIRC's counts for the names it knows
        k = (
            draw(st.sampled_from(KNOWN_VALUES_PER_NODE[name]))
            if name in KNOWN_VALUES_PER_NODE
            else draw(st.integers(1, 4))
        )
        default = np.array(draw(st.lists(reals, min_size=k, max_size=k)))
        values = np.tile(default, (n_nodes, 1))
        where = draw(st.lists(st.integers(0, n_nodes - 1), max_size=n_nodes, unique=True))
        for node in where:
            values[node] = draw(st.lists(reals, min_size=k, max_size=k))
        units = draw(st.sampled_from(["unitless", "m", "1/s", "s/m^(1/3)", "metres above geoid"]))
        attributes[name] = NodalAttribute(units, default, values)
    title = draw(st.text(st.characters(codec="ascii", exclude_categories=["Cc"]), max_size=30)).strip()
    return n_nodes, NodalAttributes(attributes, title=title or "terramesh")


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(attribute_sets())
def test_hypothesis_round_trip_is_lossless(tmp_path, case):
    n_nodes, attributes = case
    before = {name: a.values.copy() for name, a in attributes.items()}
    path = tmp_path / "random.13"
    write_fort13(path, attributes, n_nodes)
    for name, attribute in attributes.items():  # the writer does not mutate
        np.testing.assert_array_equal(attribute.values, before[name])
    assert_same(attributes, read_fort13(path))


@pytest.mark.parametrize(
    "lines, message",
    [
        (1, "expected NumOfNodes at line 2"),
        (3, "expected AttrName of attribute 1 of 4 at line 4"),
        (4, "expected Units of primitive_weighting_in_continuity_equation"),
        (18, "expected 12 DefaultAttrVal of surface_directional_effective_roughness_length at line 19"),
        (19, "expected 12 DefaultAttrVal of surface_directional_effective_roughness_length at line 20"),
        (20, "AttrName of the values of primitive_weighting_in_continuity_equation, mannings_n_at_sea_floor"),
        (23, r"expected 2 lines of non-default values of mannings_n_at_sea_floor \(node and 1 values\), found 1"),
        (28, "expected NumNodesNotDefaultVal of internal_tide_friction at line 29"),
        (30, "NumNodesNotDefaultVal of surface_directional_effective_roughness_length"),
    ],
)
def test_truncated_files_say_what_is_missing(tmp_path, lines, message):
    text = "\n".join(SAMPLE.splitlines()[:lines]) + "\n"
    with pytest.raises(MeshFormatError, match=message):
        read_fort13(write(tmp_path, text))


def test_malformed_files_are_refused(tmp_path):
    with pytest.raises(MeshFormatError, match="outside 1..5"):
        read_fort13(write(tmp_path, SAMPLE.replace("5 0.1\n", "6 0.1\n")))
    with pytest.raises(MeshFormatError, match="'bogus' was not declared"):
        read_fort13(write(tmp_path, SAMPLE.replace("internal_tide_friction\n0\n", "bogus\n0\n")))
    with pytest.raises(MeshFormatError, match="cannot read 1 DefaultAttrVal of mannings"):
        read_fort13(write(tmp_path, SAMPLE.replace("0.025\n", "n/a\n")))
    with pytest.raises(MeshFormatError, match="empty file"):
        read_fort13(write(tmp_path, ""))
    # each was read without a word: NaN Manning's n, the last value of a node listed twice, lines ignored
    with pytest.raises(MeshFormatError, match="DefaultAttrVal of mannings_n_at_sea_floor is not finite"):
        read_fort13(write(tmp_path, SAMPLE.replace("0.025\n", "nan\n")))
    with pytest.raises(MeshFormatError, match="line 24: a value of mannings_n_at_sea_floor at node 5 is not finite"):
        read_fort13(write(tmp_path, SAMPLE.replace("5 0.1\n", "5 inf\n")))
    with pytest.raises(MeshFormatError, match="mannings_n_at_sea_floor lists node 2 twice"):
        read_fort13(write(tmp_path, SAMPLE.replace("5 0.1\n", "2 0.1\n")))
    surplus = SAMPLE.replace(
        "surface_directional_effective_roughness_length\n1\n", "surface_directional_effective_roughness_length\n0\n"
    )
    with pytest.raises(MeshFormatError, match="line 32: 1 lines after the values of the last attribute"):
        read_fort13(write(tmp_path, surplus))


def test_attribute_construction_and_writer_checks(tmp_path):
    tau0 = NodalAttribute.from_values([0.03, 0.005, 0.03, 0.03])
    assert tau0.default.tolist() == [0.03] and tau0.non_default.tolist() == [False, True, False, False]
    with pytest.raises(MeshFormatError, match="shape"):
        NodalAttribute("m", [0.0, 0.0], np.zeros((3, 3)))
    with pytest.raises(MeshFormatError, match="4 rows for 5 nodes"):
        write_fort13(tmp_path / "x.13", {"tau0": tau0}, 5)
    with pytest.raises(MeshFormatError, match="without spaces"):
        NodalAttributes({"two words": tau0})
    with pytest.raises(MeshFormatError, match="different numbers of nodes"):
        NodalAttributes({"a": tau0, "b": NodalAttribute.from_values(np.zeros(3))})


@pytest.mark.parametrize(
    "name, attribute, expected",
    [
        ("internal_tide_friction", NodalAttribute("1/s", [0.0, 0.0], np.zeros((4, 2))), "1 or 3"),
        ("primitive_weighting_in_continuity_equation", NodalAttribute("unitless", [0, 0, 0], np.zeros((4, 3))), 1),
        ("surface_directional_effective_roughness_length", NodalAttribute("m", [0.0], np.zeros(4)), 12),
    ],
)
def test_writer_refuses_a_known_attribute_with_the_wrong_values_per_node(tmp_path, name, attribute, expected):
    """Was written without complaint; ADCIRC reads its own count and misreads the file."""
    path = tmp_path / "fort.13"
    with pytest.raises(
        MeshFormatError,
        match=rf"attribute {name} has {attribute.values_per_node} values per node; "
        rf"ADCIRC reads {expected}",
    ):
        write_fort13(path, {name: attribute}, 4)
    assert not path.exists()
    # names ADCIRC does not know take any count
    write_fort13(path, {"my_attribute": attribute}, 4)
    assert read_fort13(path)["my_attribute"].values_per_node == attribute.values_per_node
    # such a file from elsewhere is read as written, with a warning
    path.write_text(path.read_text().replace("my_attribute", name))
    with pytest.warns(TerrameshWarning, match=rf"{name} has {attribute.values_per_node} values per node; ADCIRC reads"):
        assert read_fort13(path)[name].values_per_node == attribute.values_per_node


def test_internal_tide_friction_takes_one_or_three_values_per_node(tmp_path):
    """A scalar IT_Fric was refused by the writer and warned on by the reader.

    ADCIRC's "Internal Tide Energy Conversion" page: IT_Fric "can have 1 (scalar) or 3 (tensor)
    dimensions"; OceanMesh2D's scalar options write the 1-value form.
    """
    scalar = NodalAttribute("1/s", [0.0], np.array([0.0, 1e-5, 0.0, 2.5e-5]))
    path = tmp_path / "scalar.13"
    write_fort13(path, {"internal_tide_friction": scalar}, 4)
    back = read_fort13(path)["internal_tide_friction"]  # no warning: warnings are errors
    assert back.values_per_node == 1
    np.testing.assert_array_equal(back.values, scalar.values)
    # a file as OceanMesh2D writes it
    text = "Spatial attributes description\n3\n1\ninternal_tide_friction\n1/time\n1\n0.0\n"
    text += "internal_tide_friction\n2\n1 1.0e-5\n3 2.0e-5\n"
    np.testing.assert_array_equal(
        read_fort13(write(tmp_path, text))["internal_tide_friction"].values.ravel(), [1e-5, 0.0, 2e-5]
    )
    tensor = NodalAttribute("1/s", [0.0, 0.0, 0.0], np.arange(12.0).reshape(4, 3) * 1e-6)
    write_fort13(path, {"internal_tide_friction": tensor}, 4)
    np.testing.assert_array_equal(read_fort13(path)["internal_tide_friction"].values, tensor.values)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(attribute_sets(), st.sampled_from([np.nan, np.inf, -np.inf]), st.booleans(), st.data())
def test_hypothesis_non_finite_values_and_defaults_are_refused(tmp_path, case, bad, in_default, data):
    n_nodes, attributes = case
    if not len(attributes):
        attributes = NodalAttributes(
            {"mannings_n_at_sea_floor": NodalAttribute("s/m^(1/3)", [0.02], np.full(n_nodes, 0.02))}
        )
    name = data.draw(st.sampled_from(list(attributes)))
    attribute = attributes[name]
    if in_default:
        attribute.default[data.draw(st.integers(0, attribute.values_per_node - 1))] = bad
        message = f"attribute {name}: the default .* is NaN or infinite"
    else:
        node = data.draw(st.integers(0, n_nodes - 1))
        attribute.values[node, data.draw(st.integers(0, attribute.values_per_node - 1))] = bad
        message = f"attribute {name}: values NaN or infinite at 1 of {n_nodes} nodes \\(node {node + 1} first\\)"
    path = tmp_path / "non_finite.13"
    with pytest.raises(MeshFormatError, match=message):
        write_fort13(path, attributes, n_nodes)
    assert not path.exists()


def test_a_failed_write_leaves_the_previous_file(tmp_path, monkeypatch):
    """The file was opened in place: a failure half-way left a truncated fort.13."""
    from terramesh.io import fort13

    path = tmp_path / "fort.13"
    attribute = NodalAttribute("unitless", [0.03], np.array([[0.03], [0.05], [0.03], [0.07]]))
    write_fort13(path, {"primitive_weighting_in_continuity_equation": attribute}, 4)
    before = path.read_bytes()

    def disk_full(values):
        raise OSError("No space left on device")

    monkeypatch.setattr(fort13, "format_columns", disk_full)
    with pytest.raises(OSError, match="No space left"):
        write_fort13(path, {"primitive_weighting_in_continuity_equation": attribute}, 4)
    assert path.read_bytes() == before
    assert [entry.name for entry in tmp_path.iterdir()] == ["fort.13"]


# SAMPLE with D exponents (all three spellings) in defaults, node numbers and values; "D" in the title
SAMPLE_D = (
    SAMPLE.replace("Sabine Pass test grid nodal attributes", "Sabine Pass DEM 1.0D+01 nodal attributes")
    .replace("0.03         ! default tau0", "3.0D-2       ! default tau0, D exponent")
    .replace("0.025\n", "2.5d-2\n")
    .replace("0.0 0.0 0.0\n", "0.0D0 0.0d+00 0D1\n")
    .replace("2 0.02   ! marsh", "2 2.0D-2   ! marsh: dredged")
    .replace("5 0.1\n", "5.0D0 1.0d-1\n")
    .replace("3 0.1 0.2 0.3", "3 1.0D-1 2.0d-1 0.3D0")
)


def test_fortran_d_exponents_read_as_e_and_a_title_with_d_is_kept(tmp_path):
    """ADCIRC's list-directed READ takes 1.0D+01; "could not convert string to float: '3.0D-2'" was raised."""
    attributes = read_fort13(write(tmp_path, SAMPLE_D))
    assert attributes.title == "Sabine Pass DEM 1.0D+01 nodal attributes   ! AGRID"
    plain = read_fort13(write(tmp_path))
    plain.title = attributes.title
    assert_same(attributes, plain)
    out = tmp_path / "again.13"
    write_fort13(out, attributes, 5)
    assert_same(attributes, read_fort13(out))


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("2.5d-2\n", "2.5X-2\n", r"line 11: cannot read 1 DefaultAttrVal of mannings_n_at_sea_floor: .*'2\.5X-2'"),
        ("0.0D0 0.0d+00 0D1\n", "0.0D0 0.0d+0x 0D1\n", r"line 15: cannot read 3 DefaultAttrVal .*'0\.0d\+0x'"),
        ("5.0D0 1.0d-1\n", "5.0D0 1.0d-\n", r"line 24: cannot read non-default values of mannings.*'1\.0d-'"),
    ],
)
def test_bad_numbers_among_fortran_exponents_are_named_as_written(tmp_path, old, new, message):
    assert old in SAMPLE_D
    with pytest.raises(MeshFormatError, match=message):
        read_fort13(write(tmp_path, SAMPLE_D.replace(old, new)))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(attribute_sets(), st.sampled_from(["D", "d"]), st.booleans())
def test_hypothesis_fortran_d_exponents_read_as_written_with_e(tmp_path, case, marker, plus):
    """Every number written with D or d (``1D+300``, ``1d-05``, ``1D300``) reads as the float written with e."""
    n_nodes, attributes = case
    path = tmp_path / "random.13"
    write_fort13(path, attributes, n_nodes)
    title, _, rest = path.read_text().partition("\n")
    sign = {"+": "+" if plus else "", "-": "-"}
    path.write_text(title + "\n" + re.sub(r"(?<=[0-9])e([+-])(?=[0-9])", lambda m: marker + sign[m[1]], rest))
    assert_same(attributes, read_fort13(path))


@pytest.mark.parametrize("brk", ["\r", "\r\n", "\x0c", "\x1c", "\u2028", "\x85"])
def test_line_breaks_in_the_title_and_units_become_spaces(tmp_path, brk):
    """A ``\\r`` or form feed (any break str.splitlines splits at) was written as is: a file read_fort13 refused."""
    n = NodalAttribute(f"s/m{brk}^(1/3)", [0.02], np.array([0.02, 0.03, 0.02]))
    path = tmp_path / "fort.13"
    write_fort13(path, {"mannings_n_at_sea_floor": n}, 3, title=f"Sabine{brk}Pass   grid")
    back = read_fort13(path)
    assert back.title == "Sabine Pass   grid"  # blanks other than breaks kept: a title reads back as written
    assert back["mannings_n_at_sea_floor"].units == "s/m ^(1/3)"
    np.testing.assert_array_equal(back["mannings_n_at_sea_floor"].values, n.values)


@pytest.mark.parametrize(
    ("attributes", "message"),
    [
        (NodalAttribute.from_values(np.full(4, 0.03)), "by their ADCIRC names.*not one NodalAttribute"),
        ([1, 2], "must map ADCIRC attribute names to NodalAttribute, got list"),
        ({"surface_canopy_coefficient": 3.0}, "must map ADCIRC attribute names to NodalAttribute, got dict"),
    ],
)
def test_attributes_not_a_mapping_of_names_are_refused_clearly(tmp_path, attributes, message):
    # what tau0 returns, passed as it is, raised "'NodalAttribute' object is not iterable"
    with pytest.raises(MeshFormatError, match=message):
        write_fort13(tmp_path / "fort.13", attributes, 4)
    assert not (tmp_path / "fort.13").exists()
