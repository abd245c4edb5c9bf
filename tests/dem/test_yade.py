"""Yade round trip: Yade 2023.02 (Debian package), running the exported
``yade_materials.py`` unchanged on head-on collisions, restitutes what the
report predicts, and its time-step error shrinks with the step."""

import numpy as np
import pytest

from tests.dem.codes import need
from tests.dem.test_round_trip import TOML
from vimpact.dem import yade
from vimpact.dem.export import export
from vimpact.dem.problem import problem_from_toml


@pytest.fixture(scope="module")
def yade_export():
    problem = problem_from_toml(TOML, "round-trip")
    return problem, export(problem, "yade")


@pytest.fixture(scope="module")
def exported(yade_export):
    problem, ex = yade_export
    return problem, ex.fits


def test_yade_runs_the_exported_file_and_restitutes_the_prediction(exported):
    need(yade.yade_available(), "Yade")
    problem, fits = exported
    speeds = np.geomspace(problem.speeds.min(), problem.speeds.max(), 5)
    diff = {}
    for steps in (400, 1600):
        rows = yade.round_trip(problem, speeds, steps, fits=fits)
        assert {r["contact"] for r in rows} == {f.contact.key for f in fits}  # pairs, same type, wall
        diff[steps] = max(abs(r["e"] - r["predicted"]) for r in rows)
    assert diff[400] < 1e-3          # the exported default step
    assert diff[1600] < diff[400] / 2  # Yade's time-step error, shrinking with the step


def test_yade_oblique_wall_impacts_give_the_reported_beta(yade_export):
    """Yade on the exported file, oblique wall impacts with the set-up's friction at the
    report's speeds and angles: its beta is the report's prediction (which includes
    Yade's wall lever arm R - delta) to its time-step error, shrinking with the step, and
    within the stated beta_x residual (plus that error) of vimpact's."""
    need(yade.yade_available(), "Yade")
    from tests.dem.test_round_trip import oblique_rows_against_vimpact

    problem, ex = yade_export
    f = next(x for x in ex.fits if x.contact.key == "a-floor")
    ob = ex.targets["a-floor"].oblique
    speeds, angles = sorted(set(ob.v.tolist())), sorted(set(ob.angle_deg.tolist()))
    diff, rows = {}, {}
    for steps in (400, 1600):
        rows[steps] = [r for r in yade.round_trip(problem, speeds, steps, fits=ex.fits,
                                                  angles_deg=angles) if r["contact"] == "a-floor"]
        assert len(rows[steps]) == len(speeds) * len(angles)
        diff[steps] = max(abs(r["beta"] - r["predicted_beta"]) for r in rows[steps])
    assert diff[1600] < 3e-3
    assert diff[1600] < diff[400] / 2
    for r, beta_vimpact in oblique_rows_against_vimpact(rows[1600], ob):
        assert abs(r["beta"] - beta_vimpact) <= f.res_beta_x.max_abs + diff[1600]


def test_exported_yade_file_defines_every_pair_and_one_variable_set(exported):
    problem, fits = exported
    text = yade.render(problem, fits)["yade_materials.py"]
    n_contacts = len(problem.contacts)
    for attr in ("tc", "en", "et", "frictAngle"):
        line = next(ln for ln in text.splitlines() if ln.strip().startswith(f"{attr}=MatchMaker"))
        assert line.count("(_m[") == n_contacts
    for ln in text.splitlines():
        if "ViscElMat(label=" in ln:
            assert all(f"{k}=" in ln for k in ("tc", "en", "et", "frictionAngle"))
