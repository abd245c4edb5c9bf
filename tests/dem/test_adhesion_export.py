"""`vimpact dem` with an ``[adhesion]`` table: LAMMPS' ``jkr`` lines that LAMMPS runs, and
refusal where a code has no adhesive law."""

from __future__ import annotations

import json
import math
import re

import pytest

from vimpact.cli.main import main
from vimpact.dem import lammps
from vimpact.dem.jkr import JkrLaw
from vimpact.dem.problem import problem_from_toml

#: a Kelvin-Voigt sphere (E* = 1.5 MPa on the rigid floor, R = 1 cm, m = 4 g) with
#: dgamma = 0.5 J/m^2 on the floor: it sticks below a few cm/s
TOML = """
[speeds]
min = 0.03
max = 0.4
n = 4
angles_deg = [45.0]
[types.a]
density = 955.0
radius = 0.01
[types.a.material]
model = "kelvin_voigt"
nu = 0.5
E = 1.125e6
eta = 30.0
[walls.floor]
material = "rigid"
[friction]
default = 0.5
[adhesion]
"a-floor" = 0.5
"""


def test_adhesion_table_sets_each_contact_default_zero():
    p = problem_from_toml(TOML)
    assert p.contact("a", "floor").adhesion == 0.5 and p.contact("a", "a").adhesion == 0.0
    p = problem_from_toml(TOML.replace('"a-floor" = 0.5', "default = 0.1"))
    assert {c.adhesion for c in p.contacts} == {0.1}


@pytest.mark.parametrize("edit, words", [
    (('"a-floor" = 0.5', '"a-floor" = -0.5'), "adhesion.a-floor"),
    (('"a-floor" = 0.5', '"a-wall" = 0.5'), "adhesion key"),
])
def test_bad_adhesion_is_one_line_and_exit_2(edit, words, tmp_path, capsys):
    src = tmp_path / "bad.toml"
    src.write_text(TOML.replace(*edit, 1))
    assert main(["dem", str(src), "--for", "lammps", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err


def test_codes_without_an_adhesive_law_refuse_it(tmp_path, capsys):
    src = tmp_path / "setup.toml"
    src.write_text(TOML)
    assert main(["dem", str(src), "--for", "yade", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a-floor" in err and "--for lammps" in err


@pytest.mark.slow
def test_jkr_lines_run_in_lammps_as_the_report_predicts(tmp_path, capsys):
    """The wall line the CLI writes, run in LAMMPS head on: it rebounds as the report's
    law says above the law's sticking velocity and sticks below it."""
    src = tmp_path / "setup.toml"
    src.write_text(TOML)
    assert main(["dem", str(src), "--for", "lammps", "--out", str(tmp_path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    p = next(c["params"] for c in data["contacts"] if c["contact"] == "a-floor")
    wall = next(c for c in data["contacts"] if c["contact"] == "a-floor")
    assert wall["residual_e_z"]["max_abs"] < 0.03  # measured 7.7e-3 on these 4 speeds
    v_stick = p["v_stick_lammps_m_s"]
    assert 0.5 < v_stick / p["v_stick_vimpact_m_s"] < 1.5
    text = (tmp_path / "lammps_walls.in").read_text()
    coeffs = re.search(r"wall/gran granular (jkr .*?) zplane", text).group(1)
    assert "limit_damping" not in coeffs and "tangential mindlin" in coeffs
    assert "pair_coeff 1 1 hertz" in (tmp_path / "lammps_pair.in").read_text()  # a-a: none
    why = lammps.lammps_available()
    if why is not None:
        pytest.skip(f"LAMMPS: {why}")
    R, m = 0.01, 955.0 * 4.0 / 3.0 * math.pi * 0.01**3
    E_star = p["E_jkr_Pa"] / (2.0 * (1.0 - p["nu"] ** 2))
    law = JkrLaw(E_star, R, m, p["cohesion"], p["eta_n0"])
    for v, sticks in ((2.0 * v_stick, False), (0.7 * v_stick, True)):
        t_c = 5.0 * (m**2 / (E_star**2 * R * v)) ** 0.2
        script = lammps.collision_script(coeffs, R, 955.0, v, t_c, steps_per_contact=4000)
        v1, z1 = lammps.run_lammps(script.replace("variable v2 equal 0.0",
                                                  "variable v2 equal z[1]"), ["v1", "v2"])
        if sticks:
            assert R - z1 > law.pulloff  # still in contact
        else:
            assert v1 / v == pytest.approx(law.restitution(v), abs=2e-3)


@pytest.mark.slow
def test_jkr_pair_line_runs_in_lammps_as_the_report_predicts(tmp_path):
    """The pair line written for an adhesive sphere pair (``"a-a"``), run in LAMMPS head on
    with two equal spheres: the e_z of the law with the pair's effective radius R/2 and mass
    m/2 above its sticking velocity, sticking below it, and vimpact's pair e_z to the
    report's residual."""
    from vimpact.dem.export import export
    from vimpact.dem.jkr import lammps_jkr_restitution

    problem = problem_from_toml(TOML.replace('"a-floor" = 0.5', '"a-a" = 0.5'), "pair")
    ex = export(problem, "lammps", out_dir=tmp_path)
    f = next(f for f in ex.fits if f.contact.key == "a-a")
    t = ex.targets["a-a"]
    p = f.params
    assert f.res_e_z.max_abs < 0.03  # measured 7.5e-3 on these 4 speeds
    text = (tmp_path / "lammps_pair.in").read_text()
    coeffs = re.search(r"pair_coeff 1 1 (jkr .*?)   #", text).group(1)
    why = lammps.lammps_available()
    if why is not None:
        pytest.skip(f"LAMMPS: {why}")
    R, rho = 0.01, 955.0
    m = rho * 4.0 / 3.0 * math.pi * R**3
    E_star = p["E_jkr_Pa"] / (2.0 * (1.0 - p["nu"] ** 2))
    assert E_star == pytest.approx(f.contact.E_star, rel=1e-9)  # the pair's, half the wall's
    law = JkrLaw.pair(E_star, R, m, R, m, p["cohesion"], p["eta_n0"])
    for v, e_vimpact in zip(t.v, t.e_z):
        e = lammps_jkr_restitution(coeffs, law, R, rho, float(v), R2=R, rho2=rho)
        # measured: LAMMPS - law at most 2.8e-4, LAMMPS - vimpact at most 7.5e-3
        assert e == pytest.approx(law.restitution(float(v)), abs=2e-3)
        assert e == pytest.approx(e_vimpact, abs=0.03)
    v_stick = p["v_stick_lammps_m_s"]
    assert 0.5 < v_stick / p["v_stick_vimpact_m_s"] < 1.5
    assert lammps_jkr_restitution(coeffs, law, R, rho, 0.7 * v_stick, R2=R, rho2=rho) == 0.0
    e = lammps_jkr_restitution(coeffs, law, R, rho, 1.3 * v_stick, R2=R, rho2=rho)
    assert e == pytest.approx(law.restitution(1.3 * v_stick), abs=2e-3) and e > 0.3
