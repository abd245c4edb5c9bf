"""LIGGGHTS round trip: LIGGGHTS-PUBLIC 3.8.0 (Debian package), including the exported
``liggghts_settings.in`` and ``liggghts.in`` unchanged, restitutes what the report
predicts on head-on pair and wall collisions, and its time-step error shrinks with the step."""

import pytest

from tests.dem.codes import need, round_trips_at_report_points
from vimpact.dem import liggghts


@pytest.fixture(scope="module")
def liggghts_export(code_run):
    """The set-up and the export that ``vimpact dem --for liggghts`` made of the round trips'
    set-up (the CLI test's run)."""
    run = code_run("liggghts")
    assert run.status == 0
    return run.export.problem, run.export


@pytest.fixture(scope="module")
def exported(liggghts_export):
    problem, ex = liggghts_export
    return problem, ex.fits


@pytest.fixture(scope="module")
def liggghts_rows(liggghts_export):
    """LIGGGHTS on the exported files at the default step (100 per contact) and at 800 (one
    LIGGGHTS start): at each step the head-on collisions of every contact and the oblique
    wall impacts, at the report's oblique speeds (its lowest and highest among them) and
    angles."""
    need(liggghts.liggghts_available(), "LIGGGHTS")
    return round_trips_at_report_points(liggghts, liggghts_export, (100, 800))


def test_liggghts_runs_the_exported_files_and_restitutes_the_prediction(exported, liggghts_rows):
    _, fits = exported
    diff = {}
    for steps in (100, 800):
        rows = [r for r in liggghts_rows[steps] if "angle" not in r]
        assert {r["contact"] for r in rows} == {f.contact.key for f in fits}
        diff[steps] = max(abs(r["e"] - r["predicted"]) for r in rows)
    assert diff[100] < 1e-3          # the exported default step
    assert diff[800] < diff[100] / 2  # LIGGGHTS' time-step error, shrinking with the step


def test_rigid_wall_gets_hard_particles(exported):
    problem, fits = exported
    text = liggghts.render(problem, fits)["liggghts.in"]
    young = next(ln for ln in text.splitlines() if "youngsModulus" in ln)
    assert max(float(x) for x in young.split()[6:]) > liggghts.SOFT_LIMIT
    assert text.index("hard_particles yes") < text.index("youngsModulus")


def test_liggghts_oblique_wall_impacts_give_the_reported_beta(liggghts_export, liggghts_rows):
    """LIGGGHTS on the exported files, oblique wall impacts with the set-up's friction at
    the report's speeds and angles: its beta is the report's prediction (its Hertz-Mindlin
    history law with the lever R - delta/2 at walls) to its time-step error, shrinking with
    the step, and within the stated beta_x residual (plus that error) of vimpact's."""
    from tests.dem.test_round_trip import oblique_rows_against_vimpact

    _, ex = liggghts_export
    f = next(x for x in ex.fits if x.contact.key == "a-floor")
    ob = ex.targets["a-floor"].oblique
    speeds, angles = sorted(set(ob.v.tolist())), sorted(set(ob.angle_deg.tolist()))
    diff, rows = {}, {}
    for steps in (100, 800):
        rows[steps] = [r for r in liggghts_rows[steps]
                       if r["contact"] == "a-floor" and "angle" in r]
        assert len(rows[steps]) == len(speeds) * len(angles)
        diff[steps] = max(abs(r["beta"] - r["predicted_beta"]) for r in rows[steps])
    assert diff[800] < 1e-2
    assert diff[800] < diff[100]
    for r, beta_vimpact in oblique_rows_against_vimpact(rows[800], ob):
        assert abs(r["beta"] - beta_vimpact) <= f.res_beta_x.max_abs + diff[800]
