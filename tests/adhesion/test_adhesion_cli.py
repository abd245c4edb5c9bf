"""``vimpact simulate --adhesion`` / ``--sticking-velocity`` and the scene-file key."""

from __future__ import annotations

import json

import pytest

from vimpact.cli.main import main
from vimpact.model.scene_file import scene_from_toml

SCENE = ["simulate", "--E", "1.125e6", "--nu", "0.5", "--R", "0.01", "--m", "0.004",
         "--tangential", "none"]


def test_adhesion_json_and_sticking_velocity(capsys):
    assert main([*SCENE, "--vz0", "0.03", "--adhesion", "0.5", "--sticking-velocity",
                 "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["path"] == "adhesion[verlet,normal]" and d["status"] == "normal_only"
    adh = d["adhesion"]
    assert adh["stuck"] is False and 0.0 < d["e_z"] < 1.0
    # the sphere at 0.9 v_s sticks: status stuck and e_z = 0, never NaN
    assert main([*SCENE, "--vz0", str(0.9 * adh["sticking_velocity_m_s"]), "--adhesion", "0.5",
                 "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["status"] == "stuck" and d["e_z"] == 0.0 and d["adhesion"]["stuck"] is True


@pytest.mark.parametrize("args, text", [
    (["--vz0", "0.03", "--adhesion", "-1"], "--adhesion = -1.0 is not allowed"),
    (["--vz0", "0.03", "--adhesion", "nan"], "--adhesion"),
    (["--vz0", "0.03", "--sticking-velocity"], "--sticking-velocity needs"),
])
def test_bad_adhesion_input_exits_2_with_one_line(args, text, capsys):
    assert _code([*SCENE, *args]) == 2
    err = capsys.readouterr().err.strip()
    assert text in err and "\n" not in err


def test_oblique_adhesion_is_refused(capsys):
    assert _code(["simulate", "--E", "1e6", "--nu", "0.5", "--R", "0.01", "--m", "0.004",
                  "--vz0", "0.03", "--vx0", "0.01", "--adhesion", "0.5"]) == 2
    assert "normal only" in capsys.readouterr().err


def _code(args: list[str]) -> int:
    try:
        return main(args)
    except SystemExit as exc:  # argparse's own checks
        return int(exc.code or 0)


def test_scene_file_key():
    text = """model = "elastic"
tangential = "none"
[scene]
E_Pa = 1.125e6
nu = 0.5
R_m = 0.01
m_kg = 0.004
v_z0_m_s = 0.03
adhesion_J_m2 = 0.5
"""
    scene, _ = scene_from_toml(text)
    assert scene.adhesion == 0.5
    with pytest.raises(ValueError, match="adhesion_J_m2"):
        scene_from_toml(text.replace("0.5\n", "-0.5\n").replace("nu = -0.5", "nu = 0.5"))
    assert scene_from_toml(text.replace("adhesion_J_m2 = 0.5\n", ""))[0].adhesion == 0.0


def test_adhesion_figure(tmp_path, capsys):
    out = tmp_path / "fig_adhesion.png"
    assert main(["plot", "fig_adhesion", "--out", str(out)]) == 0
    assert out.stat().st_size > 10_000
