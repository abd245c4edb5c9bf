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


def test_yade_normal_law_and_its_closed_form_agree_far_within_the_screen():
    """``_en_for`` takes the closed form's side of ``target`` when it is more than
    ``EN_SCREEN`` away: that is the integrated law's side only if the two differ by less.
    They do, by far, at walls and between spheres over en in [1e-6, 1]."""
    import math

    import numpy as np

    from vimpact.dem import linear
    from vimpact.reference.closed_forms import linear_model_zeta

    worst = 0.0
    for q in (0.5, 1.0):
        for en in np.concatenate([np.geomspace(1e-6, 1.0, 16), [0.3, 0.9, 0.999999]]):
            zeta = -math.sqrt(q) * math.log(en) / math.sqrt(math.pi**2 + linear.ln2(en))
            e_law = yade.yade_law(1.0, float(en), 1.0, q, 3.5, tangential=False)[0]
            worst = max(worst, abs(e_law - float(linear_model_zeta(zeta).e)))
    assert worst < 0.1 * yade.EN_SCREEN, worst


def test_yade_en_search_takes_the_steps_of_the_plain_bisection():
    """The screened search ends on the very ``en`` of the bisection that solves the law at
    every step (at a wall: q = 1/2)."""
    target, q = 0.8123, 0.5

    def e_of(en):
        return yade.yade_law(1.0, en, 1.0, q, 3.5, tangential=False)[0]

    lo, hi = 1e-6, 1.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if e_of(mid) < target else (lo, mid)
    assert yade._en_for(target, q) == 0.5 * (lo + hi)
