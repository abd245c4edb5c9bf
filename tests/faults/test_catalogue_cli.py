"""The command line's catalogue of bad inputs, one case per id.

Every bad input ends with exit code 2 and exactly one line on stderr that
names the option as the user typed it and the value (no traceback, nothing on
stdout). Extreme inputs that are admissible end with exit code 0 and a status
that says what happened, never a wrong number reported as ``ok``.

The cases run in-process (``vimpact.cli.main.main``) for speed; two run
through ``python -m vimpact`` and ``python -m vimpact.cli`` to prove the real entry points.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from vimpact.cli.main import main
from vimpact.reference.closed_forms import kelvin_voigt_continuum

#: A physical Kelvin-Voigt-capable scene (elastic without --eta).
PHYS = ["--E", "1e9", "--nu", "0.3", "--R", "0.01", "--m", "0.004", "--vz0", "1"]
#: A standard solid.
SLS = ["--G1", "1e7", "--G2", "3e7", "--eta", "600", "--nu", "0.49", "--R", "0.01",
       "--m", "0.004", "--vz0", "1"]
#: A dimensionless standard solid.
DIM = ["--Q1", "0.1", "--Q2", "1", "--nu", "0.5"]

#: Every numeric option, with a command line that uses it (its value is replaced).
FLAG_BASES = {
    "--E": PHYS,
    "--G": ["--G", "4e8"] + PHYS[2:],
    "--nu": PHYS,
    "--eta": PHYS + ["--eta", "10"],
    "--G1": SLS,
    "--G2": SLS,
    "--R": PHYS,
    "--m": PHYS,
    "--vz0": PHYS,
    "--Theta": PHYS + ["--Theta", "1.6e-7"],
    "--vx0": PHYS + ["--vx0", "0.5"],
    "--omega0": PHYS + ["--omega0", "10"],
    "--Q1": DIM,
    "--Q2": DIM,
    "--theta-ratio": DIM + ["--theta-ratio", "0.4"],
    "--mu": DIM + ["--mu", "0.3"],
    "--tolerance": DIM + ["--tolerance", "1e-4"],
    "--rtol": DIM + ["--rtol", "1e-8"],
    "--steps": DIM + ["--steps", "500"],
    "--elements": DIM + ["--elements", "70"],
}
#: Bad values typed into every option, and how the message shows them.
BAD_VALUES = {"nan": "nan", "inf": "inf", "-inf": "-inf", "abc": "abc", "": "''"}
#: Values that are admissible for an option although BAD_VALUES lists them.
ADMISSIBLE = {("--mu", "inf")}  # mu = inf: full stick


def with_value(argv: list[str], flag: str, value: str) -> list[str]:
    """``argv`` with ``flag``'s value replaced by ``value`` (appended if absent)."""
    out = list(argv)
    if flag in out:
        out[out.index(flag) + 1] = value
    else:
        out += [flag, value]
    return out


def run(argv: list[str], capsys) -> tuple[int, str, str]:
    """Exit code, stdout and stderr of ``vimpact ARGV`` run in-process."""
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own checks (types, choices, unknown options)
        code = exc.code
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def assert_one_line_error(code: int, out: str, err: str, *names: str) -> None:
    assert code == 2, (code, out, err)
    assert out == "", out
    assert err.count("\n") == 1 and err.endswith("\n"), err
    assert "Traceback" not in err, err
    for name in names:
        assert name in err, (name, err)


# ---- every numeric option x NaN, inf, -inf, a word, an empty value --------------

FLAG_CASES = [pytest.param(flag, value, shown, id=f"{flag}={value or 'empty'}")
              for flag in FLAG_BASES for value, shown in BAD_VALUES.items()
              if (flag, value) not in ADMISSIBLE]


@pytest.mark.parametrize("flag, value, shown", FLAG_CASES)
def test_bad_value_in_every_option(flag, value, shown, capsys):
    argv = ["simulate"] + with_value(FLAG_BASES[flag], flag, value)
    assert_one_line_error(*run(argv, capsys), flag, shown)


# ---- the cases of the user's report and their neighbours -------------------------

def _tmp_spec(tmp_path) -> str:
    spec = tmp_path / "kv.toml"
    spec.write_text('model = "kelvin_voigt"\nseed = 1\nchunk_size = 4\nnumerics = "fast"\n'
                    "[random]\nrows = 4\nE_Pa = 1e9\neta_Pa_s = 10.0\nnu = 0.3\nR_m = 0.01\n"
                    "m_kg = 0.004\nv_z0_m_s = 1.0\n")
    return str(spec)


SIMULATE_ERRORS = [
    # (id, arguments after "simulate", what the one line must name)
    ("vz0-1e200", with_value(PHYS, "--vz0", "1e200"), ["--vz0 = 1e+200", "floating-point"]),
    ("vz0-1e-200", with_value(PHYS, "--vz0", "1e-200"), ["--vz0 = 1e-200", "floating-point"]),
    ("vz0-zero", with_value(PHYS, "--vz0", "0"), ["--vz0 = 0"]),
    ("vz0-negative", with_value(PHYS, "--vz0", "-2"), ["--vz0 = -2"]),
    ("omega0-1e300", PHYS + ["--omega0", "1e300"], ["--omega0 = 1e+300", "kinetic energy"]),
    ("E-negative", with_value(PHYS, "--E", "-1e9"), ["--E = -1"]),
    ("E-and-G", PHYS + ["--G", "1e9"], ["--E", "--G"]),
    ("nu-0.7", with_value(PHYS, "--nu", "0.7"), ["--nu = 0.7"]),
    ("nu-negative", with_value(PHYS, "--nu", "-0.1"), ["--nu = -0.1"]),
    ("R-1e-300", with_value(PHYS, "--R", "1e-300"), ["--R = 1e-300"]),
    ("R-1e-30-half-space", with_value(PHYS, "--R", "1e-30"), ["--R = 1e-30", "a_max",
                                                               "--allow-large-contact"]),
    # a 1e300 kg sphere sinks 1e57 m deep: its scales are finite, its contact not a half-space's
    ("m-1e300-half-space", with_value(PHYS, "--m", "1e300"), ["a_max", "--allow-large-contact"]),
    ("Theta-zero", PHYS + ["--Theta", "0"], ["--Theta = 0"]),
    ("Theta-and-theta-ratio", PHYS + ["--Theta", "1e-6", "--theta-ratio", "0.4"],
     ["--Theta", "--theta-ratio"]),
    ("theta-ratio-physical-nan", PHYS + ["--theta-ratio", "nan"], ["--theta-ratio = nan"]),
    ("eta-1e120", PHYS + ["--eta", "1e120"], ["--eta = 1e+120", "dashpot time"]),
    ("Q1-1e300-oblique", ["--Q1", "1e300", "--nu", "0.5"], ["--Q1 = 1e+300"]),
    ("Q1-negative", ["--Q1", "-1", "--nu", "0.5"], ["--Q1 = -1"]),
    ("Q2-1e-300", ["--Q1", "0.1", "--Q2", "1e-300", "--nu", "0.5"], ["--Q2 = 1e-300"]),
    ("Q2-without-Q1", ["--Q2", "1", "--nu", "0.5"], ["--Q1"]),
    ("Q1-with-physical", ["--Q1", "0.1", "--nu", "0.5", "--E", "1e9"], ["--E", "--Q1"]),
    ("Q1-without-nu", ["--Q1", "0.1"], ["--nu"]),
    ("Q1-with-Theta", ["--Q1", "0.1", "--nu", "0.5", "--Theta", "1"], ["--Theta"]),
    ("nu-missing", PHYS[:2] + PHYS[4:], ["--nu"]),
    ("vz0-missing", PHYS[:-2], ["--vz0"]),
    ("modulus-missing", PHYS[2:], ["--E"]),
    ("G1-without-G2", ["--G1", "1e6"] + PHYS[2:], ["--G2"]),
    ("G1-with-E", SLS + ["--E", "1e9"], ["--E"]),
    ("eta-with-model-elastic", PHYS + ["--eta", "1", "--model", "elastic"], ["--eta"]),
    ("model-unknown", PHYS + ["--model", "maxwell"], ["--model", "maxwell"]),
    ("prony-three-fields", ["--G", "1e6", "--prony", "1e6:1e-3:5"] + PHYS[2:],
     ["--prony = '1e6:1e-3:5'"]),
    ("prony-nan-time", ["--G", "1e6", "--prony", "1e6:nan"] + PHYS[2:],
     ["--prony = '1e6:nan'", "relaxation time"]),
    ("prony-negative-modulus", ["--G", "1e6", "--prony", "-1e6:1e-3"] + PHYS[2:],
     ["--prony = '-1e6:1e-3'", "modulus"]),
    ("prony-empty", ["--G", "1e6", "--prony", ""] + PHYS[2:], ["--prony = ''"]),
    ("prony-without-G", ["--prony", "1e6:1e-3"] + PHYS[2:], ["--G"]),
    ("prony-with-model-kv", ["--G", "1e6", "--eta", "1", "--prony", "1e6:1e-3",
                             "--model", "kelvin_voigt"] + PHYS[2:], ["--prony"]),
    ("steps-1e9", DIM + ["--steps", "1e9"], ["--steps = 1000000000"]),
    ("steps-3", DIM + ["--steps", "3"], ["--steps = 3"]),
    ("steps-2.5", DIM + ["--steps", "2.5"], ["--steps", "2.5"]),
    ("elements-1e8", DIM + ["--elements", "1e8"], ["--elements = 100000000"]),
    ("rtol-1", DIM + ["--rtol", "1"], ["--rtol = 1"]),
    ("tolerance-0.5", DIM + ["--tolerance", "0.5"], ["--tolerance = 0.5"]),
    ("tolerance-with-numerics", DIM + ["--tolerance", "1e-4", "--numerics", "fast"],
     ["--tolerance", "--numerics"]),
    ("tolerance-unreachable-on-elements", DIM + ["--mu", "0.3", "--tolerance", "1e-9"],
     ["--tolerance = 1e-09", "element path"]),
    ("mu-negative", DIM + ["--mu", "-1"], ["--mu = -1"]),
    ("integrator-unknown", DIM + ["--integrator", "rk4"], ["--integrator", "rk4"]),
    ("numerics-unknown", DIM + ["--numerics", "turbo"], ["--numerics", "turbo"]),
    ("tangential-unknown", DIM + ["--tangential", "slip"], ["--tangential", "slip"]),
    ("memory-unknown", DIM + ["--tangential-memory", "total"], ["--tangential-memory"]),
    ("unknown-option", DIM + ["--speed", "3"], ["--speed"]),
    ("trajectory-txt", DIM + ["--trajectory", "table.txt"], ["--trajectory = 'table.txt'"]),
    ("trajectory-no-folder", DIM + ["--trajectory", "no/such/folder/t.csv"],
     ["--trajectory", "does not exist"]),
    ("scene-file-missing", ["--scene", "no/such/scene.toml"], ["no/such/scene.toml"]),
    ("scene-file-with-option", ["--scene", "sweeps/scenes/rubber_ball.toml", "--vz0", "2"],
     ["--vz0", "--scene"]),
]


@pytest.mark.parametrize("args, names", [pytest.param(a, n, id=i) for i, a, n in SIMULATE_ERRORS])
def test_simulate_refuses(args, names, capsys, repo_root, monkeypatch):
    monkeypatch.chdir(repo_root)  # the shipped scene file is named relative to the repository
    assert_one_line_error(*run(["simulate"] + args, capsys), *names)


def test_trajectory_into_a_directory_is_refused(tmp_path, capsys):
    folder = tmp_path / "out.csv"
    folder.mkdir()
    assert_one_line_error(*run(["simulate"] + DIM + ["--trajectory", str(folder)], capsys),
                          "--trajectory", "directory")


SWEEP_ERRORS = [
    ("out-csv", ["--out", "table.csv"], ["--out = 'table.csv'", ".parquet"]),
    ("shard-words", ["--shard", "a/b"], ["--shard", "'a/b'"]),
    ("shard-three-parts", ["--shard", "1/2/3"], ["--shard", "'1/2/3'"]),
    ("shard-index-too-large", ["--shard", "4/4"], ["--shard = 4/4"]),
    ("shard-negative", ["--shard", "-1/4"], ["--shard = -1/4"]),
    ("shard-zero-count", ["--shard", "1/0"], ["--shard = 1/0"]),
    ("workers-zero", ["--workers", "0"], ["--workers = 0"]),
    ("workers-negative", ["--workers", "-2"], ["--workers = -2"]),
    ("workers-word", ["--workers", "many"], ["--workers", "many"]),
    ("workers-and-scheduler", ["--workers", "2", "--scheduler", "tcp://x:1"],
     ["--workers", "--scheduler"]),
    ("shard-and-combine", ["--shard", "0/2", "--combine"], ["--shard", "--combine"]),
    ("combine-without-parts", ["--combine"], ["missing", "--resume"]),
]


@pytest.mark.parametrize("args, names", [pytest.param(a, n, id=i) for i, a, n in SWEEP_ERRORS])
def test_sweep_refuses(args, names, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert_one_line_error(*run(["sweep", _tmp_spec(tmp_path)] + args, capsys), *names)


def test_sweep_spec_missing(tmp_path, capsys):
    assert_one_line_error(*run(["sweep", str(tmp_path / "none.toml")], capsys),
                          "none.toml", "not found")


#: Other subcommands (table validation is tests/lookup's): what the line must name.
OTHER_ERRORS = [
    ("plot-unknown-figure", ["plot", "fig9", "--out", "x.png"], ["'fig9'"]),
    ("plot-out-txt", ["plot", "fig3_2", "--out", "x.txt"], ["--out = 'x.txt'", ".png"]),
    ("plot-out-no-folder", ["plot", "fig3_2", "--out", "no/such/x.png"],
     ["--out = 'no/such/x.png'"]),
    ("plot-table-needed", ["plot", "fig5_1", "--out", "x.png"], ["--table"]),
    ("plot-table-missing", ["plot", "fig5_1", "--out", "x.png", "--table", "none.parquet"],
     ["--table = 'none.parquet'"]),
    ("dem-file-missing", ["dem", "none.toml", "--for", "lammps"], ["none.toml"]),
    ("dem-code-unknown", ["dem", "none.toml", "--for", "gromacs"], ["--for", "gromacs"]),
    ("bench-unknown", ["bench", "nosuch"], ["'nosuch'"]),
    ("bench-compare-missing", ["bench", "compare", "a.json", "b.json"], ["a.json"]),
    ("command-unknown", ["simulat"], ["simulat"]),
]


@pytest.mark.parametrize("argv, names", [pytest.param(a, n, id=i) for i, a, n in OTHER_ERRORS])
def test_other_subcommands_refuse(argv, names, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert_one_line_error(*run(argv, capsys), *names)


# ---- extreme admissible inputs: exit 0 and a status that says what happened -------

def _json(argv: list[str], capsys) -> dict:
    code, out, err = run(["simulate"] + argv + ["--json"], capsys)
    assert code == 0 and err == "", (code, err)
    return json.loads(out)


def test_thesis_euler_with_4_steps_on_the_continuum_path_is_the_closed_form(capsys):
    """The oblique Kelvin-Voigt scene takes the full-stick continuum path, which has no
    time step: its e_z is the continuum's whatever --steps says."""
    out = _json(["--Q1", "0.1", "--nu", "0.5", "--numerics", "thesis", "--steps", "4"], capsys)
    assert out["status"] == "ok" and out["path"].startswith("continuum")
    assert out["e_z"] == pytest.approx(kelvin_voigt_continuum(0.1).e_z, abs=1e-6)


def test_thesis_euler_with_4_steps_on_elements_is_unresolved_not_a_number(capsys):
    out = _json(["--Q1", "0.1", "--nu", "0.5", "--numerics", "thesis", "--steps", "4",
                 "--elements", "4", "--no-continuum"], capsys)
    assert out["status"] == "unresolved" and out["path"].startswith("elements[euler")
    assert out["e_z"] is None and out["beta_x"] is None and "time steps" in out["error"]


def test_held_spin_without_rotation_is_the_same_contact_as_its_contact_point_speed(capsys):
    """``--no-rotation --omega0 -1000``: omega stays -1000 rad/s, only v_c0 = v_x0 + R
    omega0 = -10 m/s enters the contact, so e_z and beta_x equal those of v_x0 = -10 m/s
    without spin; the held spin drives the sphere, and the energy ratio counts the work
    that holds it (docs/physics.md#energy-and-passivity), so it stays <= 1."""
    spun = _json(PHYS + ["--no-rotation", "--omega0", "-1000"], capsys)
    plain = _json(PHYS + ["--no-rotation", "--vx0", "-10"], capsys)
    assert spun["status"] == plain["status"] == "ok"
    assert spun["e_z"] == pytest.approx(plain["e_z"], abs=1e-12)
    assert spun["beta_x"] == pytest.approx(plain["beta_x"], abs=1e-9)
    assert spun["omega_end"] == -1000.0
    assert spun["energy_ratio"] <= 1.0 and plain["energy_ratio"] <= 1.0


def test_arm_modulus_1e300_is_the_glassy_elastic_limit(capsys):
    """An arm of modulus 1e300 Pa relaxing in 1 ms: the contact (glassy modulus) lasts
    about 1e-121 s, so the arm never relaxes and the impact is elastic, e_z = 1."""
    out = _json(["--G", "1e6", "--prony", "1e300:1e-3"] + PHYS[2:] + ["--vx0", "1"], capsys)
    assert out["status"] == "ok"
    assert out["e_z"] == pytest.approx(1.0, abs=1e-6) and abs(out["beta_x"]) <= 1.0 + 1e-6


def test_theta_1e_300_is_too_costly_with_a_reason(capsys):
    """Theta / (m R^2) = 2.5e-294: the contact point's tangential mode is 1e147 times
    stiffer than the normal one; the element path would need ~1e149 steps per t_H."""
    out = _json(PHYS + ["--Theta", "1e-300", "--vx0", "1"], capsys)
    assert out["status"] == "too_costly" and "steps per Hertz time" in out["error"]
    assert out["e_z"] is None


def test_largest_admissible_dashpot_is_fully_damped(capsys):
    """Q1 = 6e99, normal impact: e_z ~ Q1^(-5/3) (the sphere stops within a depth
    ~Q1^(-2/3) d); it must come out as a tiny number, not as 0 or NaN."""
    out = _json(["--Q1", "6e99", "--nu", "0.5", "--tangential", "none"], capsys)
    assert out["status"] == "normal_only"
    assert 0.0 < out["e_z"] < 1e-160


# ---- the real entry point ------------------------------------------------------

# the two ways a bad input leaves: a refusal that main returns, after arithmetic that overflows
# (a warning would be a second line in a real process), and argparse's own exit inside main
# (the catalogue above runs steps-1e9 and every other case in-process); one through each of
# the two ``__main__`` modules (``python -m vimpact.cli`` with an exit code that main returns:
# tests/cli/test_main_module.py)
@pytest.mark.parametrize("module, args, names", [
    pytest.param("vimpact", with_value(PHYS, "--vz0", "1e200"), ["--vz0 = 1e+200"],
                 id="vz0-1e200"),
    pytest.param("vimpact.cli", with_value(PHYS, "--E", ""), ["--E", "''"], id="E-empty"),
])
def test_installed_entry_point(module, args, names):
    proc = subprocess.run([sys.executable, "-m", module, "simulate", *args],
                          capture_output=True, text=True, timeout=600)
    assert_one_line_error(proc.returncode, proc.stdout, proc.stderr, *names)

