"""Yade round trip: Yade 2023.02 (Debian package), running the exported
``yade_materials.py`` unchanged on head-on collisions, restitutes what the
report predicts, and its time-step error shrinks with the step."""

import pytest

from tests.dem.codes import need, round_trips_at_report_points
from vimpact.dem import yade


@pytest.fixture(scope="module")
def yade_export(code_run):
    """The set-up and the export that ``vimpact dem --for yade`` made of the round trips'
    set-up (the CLI test's run)."""
    run = code_run("yade")
    assert run.status == 0
    return run.export.problem, run.export


@pytest.fixture(scope="module")
def exported(yade_export):
    problem, ex = yade_export
    return problem, ex.fits


@pytest.fixture(scope="module")
def yade_rows(yade_export):
    """Yade on the exported file at the default step (400 per contact) and at 1600 (one
    Yade start): at each step the head-on collisions of every contact and the oblique wall
    impacts, at the report's oblique speeds (its lowest and highest among them) and angles."""
    need(yade.yade_available(), "Yade")
    return round_trips_at_report_points(yade, yade_export, (400, 1600))


def test_yade_runs_the_exported_file_and_restitutes_the_prediction(exported, yade_rows):
    _, fits = exported
    diff = {}
    for steps in (400, 1600):
        rows = [r for r in yade_rows[steps] if "angle" not in r]
        assert {r["contact"] for r in rows} == {f.contact.key for f in fits}  # pairs, same type, wall
        diff[steps] = max(abs(r["e"] - r["predicted"]) for r in rows)
    assert diff[400] < 1e-3          # the exported default step
    assert diff[1600] < diff[400] / 2  # Yade's time-step error, shrinking with the step


def test_yade_oblique_wall_impacts_give_the_reported_beta(yade_export, yade_rows):
    """Yade on the exported file, oblique wall impacts with the set-up's friction at the
    report's speeds and angles: its beta is the report's prediction (which includes
    Yade's wall lever arm R - delta) to its time-step error, shrinking with the step, and
    within the stated beta_x residual (plus that error) of vimpact's."""
    from tests.dem.test_round_trip import oblique_rows_against_vimpact

    _, ex = yade_export
    f = next(x for x in ex.fits if x.contact.key == "a-floor")
    ob = ex.targets["a-floor"].oblique
    speeds, angles = sorted(set(ob.v.tolist())), sorted(set(ob.angle_deg.tolist()))
    diff, rows = {}, {}
    for steps in (400, 1600):
        rows[steps] = [r for r in yade_rows[steps] if r["contact"] == "a-floor" and "angle" in r]
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


@pytest.mark.parametrize("target, q", [(0.8123, 0.5), (0.3, 1.0), (0.999, 0.5)])
def test_yade_en_search_ends_where_the_integrated_law_restitutes_the_target(target, q):
    """The bisection (on Yade's law in closed form) ends on neighbouring numbers around the
    ``en`` whose restitution is ``target``, at a wall (q = 1/2) and between spheres; the
    law integrated as an ODE (:func:`vimpact.dem.laws.linear_spring_dashpot`, clipped at
    zero force) restitutes ``target`` there to its integration error."""
    import math

    from vimpact.dem import laws, linear

    en = yade._en_for(target, q)
    assert yade.yade_law(1.0, en, 1.0, q, 3.5, tangential=False)[0] == pytest.approx(
        target, abs=1e-13)
    zeta = -math.sqrt(q) * math.log(en) / math.sqrt(math.pi**2 + linear.ln2(en))
    assert laws.linear_spring_dashpot(zeta, "force")[0] == pytest.approx(target, abs=1e-8)
