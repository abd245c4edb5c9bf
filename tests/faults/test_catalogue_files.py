"""The catalogue of bad scene files and sweep specifications, one case per id.

A bad file is a ``ValueError`` on one line that names the file and the key (as
written in the file) and shows the value; through the command line it is exit
code 2 with that line. A sweep row that is not a valid scene (``v_z0 = 1e-200``)
is a row with status ``invalid`` and its reason; the other rows are the
impacts they would be alone.
"""

from __future__ import annotations

import math

import pandas as pd
import pytest

import vimpact as v
from vimpact.cli.main import main
from vimpact.model.scene_file import load_scene, scene_from_toml
from vimpact.sweep import run_sweep
from vimpact.sweep.spec import load_spec

#: A scene file: top-level keys, then [numerics] and [scene] (a key set to None is left out).
SCENE_TOP = {"model": '"kelvin_voigt"'}
SCENE_NUMERICS = {"preset": '"fast"'}
SCENE = {"E_Pa": "1e9", "eta_Pa_s": "10.0", "nu": "0.3", "R_m": "0.01", "m_kg": "0.004",
         "v_z0_m_s": "1.0", "v_x0_m_s": "0.5", "omega0_rad_s": "0.0", "theta_ratio": "0.4"}


def toml(top: dict, tables: dict[str, dict]) -> str:
    lines = [f"{k} = {x}" for k, x in top.items() if x is not None]
    for name, table in tables.items():
        if table is not None:
            lines.append(f"[{name}]")
            lines += [f"{k} = {x}" for k, x in table.items() if x is not None]
    return "\n".join(lines) + "\n"


def scene_text(top=None, numerics=None, scene=None) -> str:
    return toml({**SCENE_TOP, **(top or {})},
                {"numerics": {**SCENE_NUMERICS, **(numerics or {})},
                 "scene": {**SCENE, **(scene or {})}})


#: Bad values typed into every [scene] key, and how the message shows them.
BAD_TOML_VALUES = {"nan": "nan", "inf": "inf", "-inf": "-inf", '"abc"': "'abc'", '""': "''",
                   "true": "True", "[1.0, 2.0]": "[1.0, 2.0]", "{ a = 1 }": "{'a': 1}"}

SCENE_KEY_CASES = [pytest.param(key, value, shown, id=f"scene.{key}={value}")
                   for key in SCENE for value, shown in BAD_TOML_VALUES.items()]


@pytest.mark.parametrize("key, value, shown", SCENE_KEY_CASES)
def test_bad_value_in_every_scene_key(key, value, shown):
    with pytest.raises(ValueError) as info:
        scene_from_toml(scene_text(scene={key: value}), "ball.toml")
    text = str(info.value)
    assert text.startswith("ball.toml: ") and f"scene.{key} = {shown}" in text, text
    assert "\n" not in text


SCENE_FILE_ERRORS = [
    # (id, top-level changes, [numerics] changes, [scene] changes, what the line names)
    ("model-missing", {"model": None}, {}, {}, ["model", "missing"]),
    ("model-unknown", {"model": '"maxwell"'}, {}, {}, ["model = 'maxwell'"]),
    ("model-number", {"model": "3"}, {}, {}, ["model = 3"]),
    ("tangential-unknown", {"tangential": '"slip"'}, {}, {}, ["tangential = 'slip'"]),
    ("rotation-string", {"rotation": '"yes"'}, {}, {}, ["rotation = 'yes'"]),
    ("large-contact-int", {"allow_large_contact": "1"}, {}, {}, ["allow_large_contact = 1"]),
    ("memory-nan", {"tangential_memory": "nan"}, {}, {}, ["tangential_memory = nan"]),
    ("description-number", {"description": "1"}, {}, {}, ["description = 1"]),
    ("unknown-top-key", {"speed": "1"}, {}, {}, ["unknown key 'speed'"]),
    ("sweep-key-seed", {"seed": "1"}, {}, {}, ["seed", "sweep key"]),
    ("unknown-scene-key", {}, {}, {"speed_m_s": "1"}, ["unknown key 'scene.speed_m_s'"]),
    ("E-and-G", {}, {}, {"G_Pa": "1e9"}, ["E_Pa/G_Pa"]),
    ("nu-missing", {}, {}, {"nu": None}, ["scene.nu", "missing"]),
    ("nu-0.7", {}, {}, {"nu": "0.7"}, ["scene.nu = 0.7"]),
    ("v_z0-zero", {}, {}, {"v_z0_m_s": "0"}, ["scene.v_z0_m_s = 0"]),
    ("v_z0-1e200", {}, {}, {"v_z0_m_s": "1e200"}, ["v_z0 = 1e+200", "floating-point"]),
    ("v_z0-1e-200", {}, {}, {"v_z0_m_s": "1e-200"}, ["v_z0 = 1e-200", "floating-point"]),
    ("eta-1e120", {}, {}, {"eta_Pa_s": "1e120"}, ["eta0 = 1e+120", "dashpot time"]),
    ("mu-nan", {}, {}, {"mu": "nan"}, ["scene.mu = nan"]),
    ("mu-negative", {}, {}, {"mu": "-1"}, ["scene.mu = -1"]),
    ("numerics-steps-1e9", {}, {"steps": "1e9"}, {}, ["numerics.steps = 1000000000.0"]),
    ("numerics-steps-huge-int", {}, {"steps": "1000000000"}, {},
     ["numerics.steps = 1000000000"]),
    ("numerics-steps-3", {}, {"steps": "3"}, {}, ["numerics.steps = 3"]),
    ("numerics-steps-nan", {}, {"steps": "nan"}, {}, ["numerics.steps = nan"]),
    ("numerics-elements-1e8", {}, {"elements": "100000000"}, {},
     ["numerics.elements = 100000000"]),
    ("numerics-rtol-string", {}, {"rtol": '"1e-8"'}, {}, ["numerics.rtol = '1e-8'"]),
    ("numerics-rtol-nan", {}, {"rtol": "nan"}, {}, ["numerics.rtol = nan"]),
    ("numerics-integrator", {}, {"integrator": '"rk4"'}, {}, ["numerics.integrator = 'rk4'"]),
    ("numerics-continuum-string", {}, {"continuum": '"yes"'}, {}, ["numerics.continuum"]),
    ("numerics-tolerance-inf", {}, {"tolerance": "inf"}, {}, ["numerics.tolerance = inf"]),
    ("numerics-row-width-inf", {}, {"row_width": "inf"}, {}, ["numerics.row_width = inf"]),
    ("numerics-max-time-nan", {}, {"max_time": "nan"}, {}, ["numerics.max_time = nan"]),
    ("numerics-max-time-zero", {}, {"max_time": "0"}, {}, ["numerics.max_time = 0"]),
    ("numerics-max-time-negative", {}, {"max_time": "-1"}, {}, ["numerics.max_time = -1"]),
    ("numerics-preset-unknown", {}, {"preset": '"turbo"'}, {}, ["numerics.preset = 'turbo'"]),
    ("numerics-unknown-key", {}, {"speed": "1"}, {}, ["unknown key 'numerics.speed'"]),
]


@pytest.mark.parametrize("top, numerics, scene, names",
                         [pytest.param(t, n, s, w, id=i) for i, t, n, s, w in SCENE_FILE_ERRORS])
def test_scene_file_refuses(top, numerics, scene, names):
    with pytest.raises(ValueError) as info:
        scene_from_toml(scene_text(top, numerics, scene), "ball.toml")
    text = str(info.value)
    assert text.startswith("ball.toml: ") and "\n" not in text, text
    for name in names:
        assert name in text, (name, text)


@pytest.mark.parametrize("text, names", [
    pytest.param("model = \n", ["not valid TOML"], id="not-toml"),
    pytest.param('model = "kelvin_voigt"\nnumerics = 3\n[scene]\nnu = 0.3\n',
                 ["numerics = 3"], id="numerics-number"),
    pytest.param('model = "kelvin_voigt"\nscene = 3\n', ["scene = 3"], id="scene-number"),
    pytest.param('model = "kelvin_voigt"\n', ["scene", "missing"], id="scene-missing"),
    pytest.param('model = "kelvin_voigt"\n[random]\nrows = 3\n', ["random"], id="random-table"),
    pytest.param('model = "prony"\n[scene]\nG_Pa = 1e6\nnu = 0.3\nR_m = 0.01\nm_kg = 0.004\n'
                 'v_z0_m_s = 1.0\narms = 3\n', ["scene.arms = 3"], id="prony-arms-number"),
    pytest.param('model = "prony"\n[scene]\nG_Pa = 1e6\nnu = 0.3\nR_m = 0.01\nm_kg = 0.004\n'
                 'v_z0_m_s = 1.0\n[[scene.arms]]\nG_Pa = 1e6\n', ["scene.arms[1].tau_s"],
                 id="prony-arm-without-time"),
    pytest.param('model = "prony"\n[scene]\nG_Pa = 1e6\nnu = 0.3\nR_m = 0.01\nm_kg = 0.004\n'
                 'v_z0_m_s = 1.0\n[[scene.arms]]\nG_Pa = 1e6\ntau_s = 1e-3\nbeta = 0.5\n',
                 ["scene.arms[1].beta"], id="prony-arm-third-field"),
    pytest.param('model = "prony"\n[scene]\nG_Pa = 1e6\nnu = 0.3\nR_m = 0.01\nm_kg = 0.004\n'
                 'v_z0_m_s = 1.0\n[[scene.arms]]\nG_Pa = 1e6\ntau_s = -1e-3\n',
                 ["scene.arms[1].tau_s = -0.001"], id="prony-arm-negative-time"),
])
def test_malformed_scene_file(text, names):
    with pytest.raises(ValueError) as info:
        scene_from_toml(text, "ball.toml")
    message = str(info.value)
    assert message.startswith("ball.toml: ") and "\n" not in message, message
    for name in names:
        assert name in message, (name, message)


def test_unreadable_scene_files(tmp_path):
    with pytest.raises(ValueError, match="none.toml: scene file not found"):
        load_scene(tmp_path / "none.toml")
    latin = tmp_path / "latin.toml"
    latin.write_bytes(b'model = "kelvin_voigt"\ndescription = "caf\xe9"\n')
    with pytest.raises(ValueError, match="latin.toml: cannot read the scene file"):
        load_scene(latin)


@pytest.mark.parametrize("numerics, scene, names", [
    pytest.param({"steps": "1e9"}, {}, ["numerics.steps"], id="steps-1e9"),
    pytest.param({}, {"v_z0_m_s": '""'}, ["scene.v_z0_m_s = ''"], id="v_z0-empty"),
    pytest.param({}, {"v_z0_m_s": "1e200"}, ["v_z0 = 1e+200"], id="v_z0-1e200"),
])
def test_scene_file_through_the_command_line(numerics, scene, names, tmp_path, capsys):
    path = tmp_path / "ball.toml"
    path.write_text(scene_text(None, numerics, scene))
    assert main(["simulate", "--scene", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1, captured.err
    assert str(path) in captured.err and "Traceback" not in captured.err
    for name in names:
        assert name in captured.err, (name, captured.err)


def test_max_time_1e300_is_admissible_and_changes_nothing_that_ended():
    """``max_time = 1e300`` only moves the time limit (capped, in steps, below the int64
    range); an impact that ends on its own gives the same numbers."""
    far, _ = scene_from_toml(scene_text(), "ball.toml")
    _, numerics = scene_from_toml(scene_text(numerics={"max_time": "1e300"}), "ball.toml")
    assert numerics.max_time == 1e300
    a = v.simulate(far, numerics.with_(continuum=False))
    b = v.simulate(far, numerics.with_(continuum=False, max_time=100.0))
    assert a.status == b.status == "ok" and a.e_z == b.e_z and a.beta_x == b.beta_x


# ---- sweep specifications -----------------------------------------------------

RANDOM_SPEC = {"model": '"kelvin_voigt"', "seed": "1", "chunk_size": "4", "numerics": '"fast"'}
RANDOM = {"rows": "4", "E_Pa": "1e9", "eta_Pa_s": "10.0", "nu": "0.3", "R_m": "0.01",
          "m_kg": "0.004", "v_z0_m_s": "1.0"}
GRID_SPEC = {"model": '"standard_solid"'}
GRID = {"Q1": "[0.1, 1.0]", "Q2": "1.0", "nu": "0.5"}

SPEC_ERRORS = [
    # (id, top-level changes, [random] or [grid] changes, grid?, what the line names)
    ("rows-zero", {}, {"rows": "0"}, False, ["random.rows = 0"]),
    ("rows-float", {}, {"rows": "1.5"}, False, ["random.rows = 1.5"]),
    ("rows-word", {}, {"rows": '"many"'}, False, ["random.rows = 'many'"]),
    ("rows-1e13", {}, {"rows": "10000000000000"}, False, ["random.rows = 10000000000000"]),
    ("chunk-size-zero", {"chunk_size": "0"}, {}, False, ["chunk_size = 0"]),
    ("seed-negative", {"seed": "-1"}, {}, False, ["seed = -1"]),
    ("layout-unknown", {"layout": '"zip"'}, {}, False, ["layout = 'zip'"]),
    ("unknown-top-key", {"speed": "1"}, {}, False, ["unknown key 'speed'"]),
    ("unknown-random-key", {}, {"speed": "1"}, False, ["unknown key 'random.speed'"]),
    ("range-with-nan", {}, {"v_x0_m_s": "[0, nan]"}, False, ["random.v_x0_m_s = nan"]),
    ("range-with-inf", {}, {"v_x0_m_s": "[inf, 1]"}, False, ["random.v_x0_m_s = inf"]),
    ("range-reversed", {}, {"v_x0_m_s": "[1, 0]"}, False, ["random.v_x0_m_s = [1, 0]"]),
    ("range-three", {}, {"v_x0_m_s": "[1, 2, 3]"}, False, ["random.v_x0_m_s = [1, 2, 3]"]),
    ("choice-empty", {}, {"v_x0_m_s": "{ choice = [] }"}, False, ["random.v_x0_m_s.choice"]),
    ("choice-nan", {}, {"v_x0_m_s": "{ choice = [nan] }"}, False, ["random.v_x0_m_s.choice"]),
    ("log-range-negative", {}, {"v_x0_m_s": "{ range = [-1, 1], log = true }"}, False,
     ["random.v_x0_m_s.range"]),
    ("value-word", {}, {"v_x0_m_s": '"fast"'}, False, ["random.v_x0_m_s = 'fast'"]),
    ("mu-negative", {}, {"mu": "-1"}, False, ["random.mu = -1"]),
    ("grid-Q1-negative", {}, {"Q1": "[-1, 1]"}, True, ["grid.Q1 = -1"]),
    ("grid-Q1-nan", {}, {"Q1": "nan"}, True, ["grid.Q1 = nan"]),
    ("grid-Q1-empty", {}, {"Q1": "[]"}, True, ["grid.Q1 = []"]),
    ("grid-Q1-reversed", {}, {"Q1": "{ start = 1, stop = 0.1, per_decade = 10 }"}, True,
     ["grid.Q1.stop = 0.1"]),
    ("grid-Q1-per-decade-zero", {}, {"Q1": "{ start = 0.1, stop = 1, per_decade = 0 }"}, True,
     ["grid.Q1.per_decade = 0"]),
    ("grid-Q1-too-many-points", {}, {"Q1": "{ start = 0.1, stop = 1e300, per_decade = 1e6 }"},
     True, ["grid.Q1", "points"]),
    ("grid-Q2-zero", {}, {"Q2": "0"}, True, ["grid.Q2 = 0"]),
    # G2 = G1 / Q2 overflows: refused at load time, not as rows with G2 = inf
    ("grid-Q2-1e-300", {}, {"Q2": "[1.0, 1e-300]"}, True, ["grid.Q2 = 1e-300", "G2"]),
    ("grid-nu-0.7", {}, {"nu": "0.7"}, True, ["grid.nu = 0.7"]),
    ("grid-tolerance-1", {}, {"tolerance": "1"}, True, ["grid.tolerance = 1"]),
]


def spec_text(top: dict, table: dict, grid: bool) -> str:
    if grid:
        return toml({**GRID_SPEC, **top}, {"grid": {**GRID, **table}})
    return toml({**RANDOM_SPEC, **top}, {"random": {**RANDOM, **table}})


@pytest.mark.parametrize("top, table, grid, names",
                         [pytest.param(t, x, g, w, id=i) for i, t, x, g, w in SPEC_ERRORS])
def test_sweep_spec_refuses(top, table, grid, names, tmp_path):
    path = tmp_path / "spec.toml"
    path.write_text(spec_text(top, table, grid))
    with pytest.raises(ValueError) as info:
        load_spec(path)
    text = str(info.value)
    assert text.startswith(f"{path}: ") and "\n" not in text, text
    for name in names:
        assert name in text, (name, text)


def test_sweep_spec_through_the_command_line(tmp_path, capsys):
    path = tmp_path / "spec.toml"
    path.write_text(spec_text({}, {"v_x0_m_s": "[0, nan]"}, False))
    assert main(["sweep", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "random.v_x0_m_s = nan" in err and str(path) in err


def test_a_sweep_row_with_v_z0_1e_200_is_invalid_and_the_rest_goes_on(tmp_path):
    path = tmp_path / "spec.toml"
    path.write_text(spec_text({}, {"rows": "8", "v_z0_m_s": "{ choice = [1e-200, 1.0, 2.0] }",
                                   "v_x0_m_s": "[0.1, 1.0]"}, False))
    table = pd.read_parquet(run_sweep(path, progress=False))
    bad = table.v_z0_m_s == 1e-200
    assert bad.any() and (~bad).any()
    assert (table.status[bad] == "invalid").all()
    assert table.error[bad].str.contains("floating-point").all()
    assert table.e_z[bad].isna().all()
    good = table[~bad].reset_index(drop=True)
    alone = v.simulate_batch(pd.DataFrame({
        "nu": good.nu, "G_inf_Pa": good.E_Pa / (2.0 * (1.0 + good.nu)), "eta0_Pa_s": good.eta_Pa_s,
        "R_m": good.R_m, "m_kg": good.m_kg, "v_z0_m_s": good.v_z0_m_s, "v_x0_m_s": good.v_x0_m_s,
        "model": "kelvin_voigt"}), "fast")
    assert list(good.status) == list(alone.status) == ["ok"] * len(good)
    for name in ("e_z", "beta_x"):
        assert good[name].to_numpy() == pytest.approx(alone[name].to_numpy(), rel=1e-12), name
    assert all(math.isfinite(x) for x in good.e_z)
