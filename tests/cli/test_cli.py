"""The command line: JSON output, summaries, trajectories, and exit code 2 on bad input."""

import json
import subprocess
import sys

import pandas as pd
import pytest

from vimpact.cli.main import main
from vimpact.reference.closed_forms import kelvin_voigt_continuum

KEYS = {"e_z", "e_x", "beta_x", "t_contact", "u_max", "a_max", "t_hertz", "d_hertz", "a_hertz",
        "energy_ratio", "Q1", "Q2", "nu", "status"}


def test_dimensionless_json(capsys):
    assert main(["simulate", "--Q1", "0.1", "--nu", "0.5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert KEYS <= set(out)
    assert out["status"] == "ok" and out["Q2"] is None
    assert out["e_z"] == pytest.approx(kelvin_voigt_continuum(0.1).e_z, abs=1e-4)
    assert out["units"]["t_contact"] == "s"


def test_physical_summary_and_trajectory(tmp_path, capsys):
    path = tmp_path / "traj.parquet"
    args = ["simulate", "--E", "5e10", "--nu", "0.5", "--eta", "1e5", "--R", "0.2", "--m", "10",
            "--vz0", "10", "--vx0", "5", "--omega0", "-10", "--trajectory", str(path)]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "kelvin_voigt" in text and "e_z" in text and "status        ok" in text
    traj = pd.read_parquet(path)
    assert list(traj.columns) == ["t_s", "u_z_m", "v_z_m_s", "v_x_m_s", "omega_rad_s",
                                  "F_z_N", "F_x_N", "a_m", "slip_width_m"]
    assert traj.t_s.is_monotonic_increasing and (traj.F_z_N >= 0).all()
    # the sphere is released with the velocities it had when the force vanished
    assert traj.v_z_m_s.iloc[-1] < 0 < traj.v_z_m_s.iloc[0]


@pytest.mark.parametrize("args, name", [
    (["--m", "-1", "--nu", "0.5", "--E", "1e9", "--R", "0.1", "--vz0", "1"], "m"),
    (["--Q1", "0.1", "--nu", "0.7"], "nu"),
    (["--Q1", "-1", "--nu", "0.3"], "Q1"),
    (["--E", "1e9", "--G", "1e9", "--nu", "0.3", "--R", "1", "--m", "1", "--vz0", "1"], "E"),
    (["--E", "1e9", "--nu", "0.3", "--R", "1", "--vz0", "1"], "--m"),
    (["--E", "1e9", "--nu", "0.3", "--R", "1", "--m", "1", "--vz0", "-2"], "--vz0"),
    (["--G1", "1e6", "--nu", "0.3", "--R", "1", "--m", "1", "--vz0", "1"], "--G2"),
    (["--Q1", "0.1", "--nu", "0.5", "--R", "1"], "--R"),
    (["--Q1", "0.1"], "--nu"),
    (["--E", "1e5", "--nu", "0.5", "--R", "0.01", "--m", "1", "--vz0", "10"], "a_max"),
    (["--Q1", "0.1", "--nu", "0.5", "--steps", "2"], "steps"),
    (["--Q1", "0.1", "--nu", "0.5", "--trajectory", "x.txt"], "trajectory"),
    (["--Q1", "abc", "--nu", "0.5"], "Q1"),
])
def test_bad_input_exits_2_with_one_line(args, name, capsys):
    try:
        code = main(["simulate", *args])
    except SystemExit as exc:  # argparse's own checks (types, choices)
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and name in err and "Traceback" not in err


def test_help_names_every_option_with_its_unit(capsys):
    """``vimpact simulate --help`` (the real entry point's exit codes: tests/cli/test_main_module.py
    and tests/faults/test_catalogue_cli.py::test_installed_entry_point)."""
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "--help"])
    assert exc.value.code == 0
    helptext = capsys.readouterr().out
    for option in ("--E", "--G1", "--vz0", "--omega0", "--Q1", "--tangential-memory", "Pa s",
                   "m/s", "rad/s"):
        assert option in helptext


def test_explain_normal_only_takes_the_continuum_path(capsys):
    assert main(["simulate", "--Q1", "0.3", "--nu", "0.5", "--tangential", "none",
                 "--explain", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["path"].startswith("continuum") and out["status"] == "normal_only"
    assert any("normal impact only" in r for r in out["explain"])
    assert out["e_z"] == pytest.approx(kelvin_voigt_continuum(0.3).e_z, abs=1e-8)
    assert out["e_x"] is None


def test_explain_standard_solid_names_its_effects(capsys):
    assert main(["simulate", "--Q1", "0.3", "--Q2", "1", "--nu", "0.5", "--explain"]) == 0
    text = capsys.readouterr().out
    assert "path: continuum[stick]" in text
    assert "Maxwell arms" in text and "no dashpot term" in text
    assert main(["simulate", "--Q1", "0.3", "--Q2", "1", "--nu", "0.5", "--explain",
                 "--no-continuum"]) == 0
    assert "path: elements[verlet,tangential:incremental,arms]" in capsys.readouterr().out


def test_scene_file_and_tolerance(capsys):
    assert main(["simulate", "--scene", "sweeps/scenes/normal_kelvin_voigt.toml",
                 "--tolerance", "1e-6", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["path"].startswith("continuum") and out["status"] == "normal_only"


@pytest.mark.parametrize("args, names", [
    (["--scene", "sweeps/scenes/rubber_ball.toml", "--Q1", "0.1"], "--Q1"),
    (["--Q1", "0.1", "--nu", "0.5", "--tolerance", "1e-4", "--numerics", "fast"], "--tolerance"),
    (["--Q1", "0.1", "--nu", "0.5", "--tolerance", "0.5"], "tolerance = 0.5"),
    (["--scene", "no/such/file.toml"], "file.toml"),
])
def test_scene_and_numerics_errors(args, names, capsys):
    assert main(["simulate"] + args) == 2
    err = capsys.readouterr().err
    assert names in err and len(err.strip().splitlines()) == 1


def test_a_negative_value_is_read_as_a_value_and_refused_by_name(capsys):
    code = main(["simulate", "--E", "-1e9", "--nu", "0.5", "--R", "0.01", "--m", "0.004",
                 "--vz0", "1"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and err.startswith("vimpact simulate: error: --E = ")


#: Run in a fresh interpreter: build the parser, then refuse each bad command line; after
#: each step print the exit code and which of the heavy packages are loaded.
_FRESH = """
import json, sys
from vimpact.cli.main import build_parser, main
heavy = {'numba', 'pandas', 'pyarrow', 'matplotlib', 'scipy', 'dask'}
def loaded():
    return sorted({m.split('.')[0] for m in sys.modules} & heavy)
build_parser()
steps = [['parser', None, loaded()]]
for argv in json.loads(sys.argv[1]):
    steps.append([argv, main(argv), loaded()])
print(json.dumps(steps))
"""


def test_building_the_parser_and_refusing_bad_input_load_neither_numba_nor_pandas():
    """``vimpact --help`` and every bad-flag exit only build the parser: they must not
    pay for numba (about 0.9 s) or pandas (about 1.5 s), which the subcommands load
    when they run. A bad value exits 2 before the engine loads (2.5-4 s before).
    One fresh process checks the three steps in turn (the modules loaded only grow)."""
    bad = [["simulate", "--Q1", "-1", "--nu", "0.3"], ["plot", "nosuch", "--out", "x.png"]]
    out = subprocess.run([sys.executable, "-c", _FRESH, json.dumps(bad)], capture_output=True,
                         text=True, check=True).stdout
    steps = json.loads(out)
    assert steps == [["parser", None, []], [bad[0], 2, []], [bad[1], 2, []]], steps


def _subcommand_parsers(parser):
    """``{name: parser}`` of the subcommands registered on ``parser``."""
    import argparse

    (action,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return action.choices


def test_a_command_builds_the_same_subcommand_parser_as_the_full_parser():
    """A command builds only its subcommand, and builds it as the full parser does."""
    from vimpact.cli.main import SUBCOMMANDS, build_parser

    full = _subcommand_parsers(build_parser())
    assert sorted(full) == sorted(SUBCOMMANDS)
    for name in SUBCOMMANDS:
        own = _subcommand_parsers(build_parser([name, "--anything"]))
        assert list(own) == [name]
        assert own[name].format_help() == full[name].format_help()
    # no subcommand first: all of them (top-level help lists each with its help line)
    for argv in ([], ["--help"], ["--version"], ["bogus"], ["-h", "simulate"]):
        assert sorted(_subcommand_parsers(build_parser(argv))) == sorted(SUBCOMMANDS)
