"""The command line's parsing and help: unknown options named first, under their command, and the defaults said."""

import inspect
import sys

import numpy as np
import pytest

from terramesh.cli import main
from terramesh.cli.main import _SUBCOMMANDS, _parser

BBOX = ["--bbox", "-98", "-80", "18", "31"]  # negative numbers as values


def refused(arguments, capsys):
    """The stderr of ``main(arguments)``, refused by argparse (exit status 2)."""
    with pytest.raises(SystemExit) as exit_:
        main(arguments)
    assert exit_.value.code == 2
    return capsys.readouterr().err


def helps(command):
    """``{option: help}`` of a subcommand, each help on one line as written."""
    parser = _parser().commands[command]
    return {option: action.help for action in parser._actions for option in action.option_strings}


def test_a_mistyped_option_is_named_under_the_commands_usage_with_the_one_meant(capsys):
    # printed the top-level usage ("usage: terramesh [-h] [--version] [-q] COMMAND ...") and
    # "unrecognized arguments: --maxel 20000"
    err = refused(["coastal", *BBOX, "--min-el", "250", "--maxel", "20000"], capsys)
    assert err.startswith("usage: terramesh coastal [-h]") and "usage: terramesh [-h]" not in err
    assert err.rstrip().endswith("terramesh coastal: error: unrecognized option --maxel: did you mean --max-el?")
    err = refused(["seismic", "model.npy", "--frequency", "2", "--hmin", "50", "--elem-order", "2"], capsys)
    assert err.startswith("usage: terramesh seismic") and "--elem-order: did you mean --element-order?" in err


@pytest.mark.parametrize(
    ("arguments", "named"),
    [
        (["coastal", *BBOX, "--min_el", "250"], "--min_el: did you mean --min-el?"),
        (["coastal", *BBOX, "--min_el=250", "--dis", "0.3"], "--min_el: did you mean --min-el?"),
        (["coastal", *BBOX, "--Min-El", "250"], "--Min-El: did you mean --min-el?"),
        (["coastal", "--min_el", "250", "--max_el", "-5"], "--min_el: did you mean --min-el?; unrecognized option"),
        (["seismic", "--hmn", "50", "model.npy"], "--hmn: did you mean --hmin?"),
        (["post", "mesh.14", "--dme", "dem.nc"], "--dme: did you mean --dem?"),
        (["-q", "info", "--plannar"], "--plannar: did you mean --planar?"),
    ],
)
def test_unknown_options_are_named_before_the_missing_required_ones(capsys, arguments, named):
    # --min_el 250 was refused as "the following arguments are required: --min-el/--h0", --min_el never named
    err = refused(arguments, capsys)
    assert f"error: unrecognized option {named}" in err and "required" not in err
    assert "--max_el: did you mean --max-el?" in err or "--max_el" not in arguments  # each one, not the first only
    assert "-5" not in err.splitlines()[-1]  # a negative number is the value given, not an option


@pytest.mark.parametrize("command", sorted(_SUBCOMMANDS))
def test_every_command_names_an_unknown_option_under_its_own_usage(capsys, command):
    err = refused([command, "--no-such-option"], capsys)
    assert err.startswith(f"usage: terramesh {command}")
    assert f"terramesh {command}: error: unrecognized option --no-such-option: terramesh {command} --help lists" in err
    assert "required" not in err


def test_options_before_the_command_are_said_to_belong_after_it(capsys):
    err = refused(["--quite", "demo"], capsys)
    assert err.startswith("usage: terramesh [-h]") and "--quite: did you mean --quiet?" in err
    err = refused(["--max_el", "coastal", *BBOX], capsys)
    assert "--max_el: did you mean --max-el, an option of terramesh coastal, given after the command's name?" in err
    err = refused(["--dis", "coastal"], capsys)  # coastal's own required options are not what is said
    assert "--dis: an option of terramesh coastal: give it after the command's name" in err and "required" not in err


def test_what_argparse_takes_is_still_taken(capsys):
    # a unique abbreviation, --opt=value, negative numbers as values, a positional after the options
    arguments = _parser().parse_args(["coastal", *BBOX, "--min", "250", "--max-el=2e4", "--dis", "-0.5", "--h0=300"])
    assert arguments.bbox == [-98.0, -80.0, 18.0, 31.0] and arguments.min_el == 300.0
    assert arguments.max_el == 2e4 and arguments.dis == -0.5
    arguments = _parser().parse_args(["seismic", "--hmin", "50", "--frequency", "2", "model.npy", "--hma", "900"])
    assert arguments.model == "model.npy" and arguments.hmax == 900.0
    # an abbreviation of more than one option is argparse's own error, under the command's usage
    err = refused(["coastal", *BBOX, "--min-el", "250", "--max", "5000"], capsys)
    assert (
        err.startswith("usage: terramesh coastal")
        and "ambiguous option: --max could match --max-el, --max-el-ns" in err
    )
    # words no argument takes: argparse's message, under the command's usage
    err = refused(["coastal", *BBOX, "--min-el", "250", "stray"], capsys)
    assert err.startswith("usage: terramesh coastal") and "error: unrecognized arguments: stray" in err


def test_help_shows_the_required_options_as_required(capsys):
    # the unknown options are looked for with nothing required: -h is answered then, and said so
    with pytest.raises(SystemExit):
        main(["coastal", "--help"])
    usage = " ".join(capsys.readouterr().out.split())
    assert "--bbox LON_MIN LON_MAX LAT_MIN LAT_MAX" in usage and "[--bbox" not in usage
    assert "--min-el MIN_EL" in usage and "[--min-el" not in usage
    err = refused(["seismic", "model.npy"], capsys)
    assert "the following arguments are required: --frequency, --hmin" in err and "[--hmin" not in err


def test_coastal_help_says_the_defaults_and_what_sets_the_sizes(capsys):
    said = helps("coastal")
    assert "default: unbounded" in said["--max-el"]
    for option in ("--max-el-ns", "--dis", "--fs", "--wl", "--slp", "--ch"):
        assert "default: off" in said[option], option
    assert "default 0.2" in said["--g"]
    with pytest.raises(SystemExit):
        main(["coastal", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "Give at least one size function (--dis, --fs, --wl, --slp, --ch) or a bounded --max-el" in out


@pytest.mark.parametrize("max_el", [[], ["--max-el", "inf"]])
def test_coastal_without_a_size_function_is_refused_before_any_file_is_read(tmp_path, capsys, monkeypatch, max_el):
    # was said by build after reading the shoreline and the DEM (2 s on the guide's example)
    coastal = sys.modules["terramesh.cli.coastal"]

    def not_to_be_called(*args, **kwargs):
        raise AssertionError("read or meshed although the command was to be refused first")

    for name in ("build", "read_dem"):
        monkeypatch.setattr(coastal, name, not_to_be_called)
    monkeypatch.setattr(coastal.Shoreline, "read", not_to_be_called)
    missing = str(tmp_path / "missing.nc")  # read first, it was "no such file"
    arguments = ["coastal", *BBOX, "--min-el", "250", "--dem", missing, "--dem-positive", "up", *max_el]
    assert main([*arguments, "-q", "-o", str(tmp_path / "c.14")]) == 1
    assert capsys.readouterr().err == (
        "terramesh coastal: error: no size function was asked for (--dis, --fs, --wl, --slp, --ch) and --max-el is"
        " unbounded\n"
    )


def test_coastal_with_a_size_function_or_a_bounded_max_el_goes_on(tmp_path, monkeypatch):
    coastal = sys.modules["terramesh.cli.coastal"]
    built = []

    def build(*args, **kwargs):
        built.append(kwargs)
        raise coastal.SizingError("stopped here")

    monkeypatch.setattr(coastal, "build", build)
    for sizes in (["--max-el", "5000"], ["--fs", "3"], ["--ch", "50"]):
        assert main(["coastal", *BBOX, "--min-el", "250", *sizes, "-q", "-o", str(tmp_path / "c.14")]) == 1
    assert [kwargs.get("max_el") for kwargs in built] == [5000.0, None, None]


def test_seismic_help_says_the_defaults_the_sizes_use(capsys):
    from terramesh.seismic import read_velocity
    from terramesh.seismic.sizing import CELLS_PER_WAVELENGTH, CELLS_PER_WAVELENGTH_3D, COURANT, size_function

    said = helps("seismic")
    assert "(default 1)" in said["--element-order"]
    assert "default: unbounded" in said["--hmax"]
    assert "default: off, no grading" in said["--grade"]
    assert f"(default {COURANT:g})" in said["--courant"]
    in_2d = ", ".join(f"{n:g}" for n in CELLS_PER_WAVELENGTH.values())
    in_3d = ", ".join(f"{n:g}" for n in CELLS_PER_WAVELENGTH_3D.values())
    assert f"{in_2d} for orders 1-5 in 2-D, {in_3d} for orders 1-3 in 3-D" in said["--cells-per-wavelength"]
    # what the help says is what the sizes do: order 1, its cells per wavelength, no largest size, no grading
    defaults = inspect.signature(size_function).parameters
    assert defaults["hmax"].default is None and defaults["grade"].default is None
    v = np.where(np.arange(21)[:, None] < 10, 1500.0, 3000.0) * np.ones((21, 41))
    sizes = size_function(read_velocity(v, spacing=25.0, axis_order="zx"), frequency=5, hmin=30)
    assert sizes.settings["element_order"] == 1 and sizes.settings["courant"] == COURANT
    assert float(sizes([(500.0, -400.0)])[0]) == pytest.approx(3000.0 / (5 * CELLS_PER_WAVELENGTH[1]))


def test_demo_grade_is_the_dimensionless_size_gradient_as_coastal_says_it(capsys):
    from terramesh.examples.danish_straits import danish_straits_mesh

    said = helps("demo")
    # was "edge growth per km from the coast (0.25)", where coastal's --g is the dimensionless largest size gradient
    grade = said["--grade"]
    assert grade.startswith("grade: ") and helps("coastal")["--g"].startswith("grade: ")
    assert "dimensionless" in grade and "km per km of distance from the coast" in grade
    assert "largest size gradient" in grade and "largest size gradient" in helps("coastal")["--g"]
    signature = inspect.signature(danish_straits_mesh).parameters
    for option, name in (("--grade", "grade"), ("--min-edge-km", "min_edge_km"), ("--max-edge-km", "max_edge_km")):
        assert f"(default {signature[name].default:g})" in said[option], option
    assert "km" in said["--min-edge-km"] and "km" in said["--max-edge-km"]
