"""LIGGGHTS round trip: LIGGGHTS-PUBLIC 3.8.0 (Debian package), including the exported
``liggghts_settings.in`` and ``liggghts.in`` unchanged, restitutes what the report
predicts on head-on pair and wall collisions, and its time-step error shrinks with the step."""

import numpy as np
import pytest

from tests.dem.codes import need
from tests.dem.test_round_trip import TOML
from vimpact.dem import liggghts
from vimpact.dem.export import export
from vimpact.dem.problem import problem_from_toml


@pytest.fixture(scope="module")
def exported():
    problem = problem_from_toml(TOML, "round-trip")
    return problem, export(problem, "liggghts").fits


def test_liggghts_runs_the_exported_files_and_restitutes_the_prediction(exported):
    need(liggghts.liggghts_available(), "LIGGGHTS")
    problem, fits = exported
    speeds = np.geomspace(problem.speeds.min(), problem.speeds.max(), 5)
    diff = {}
    for steps in (100, 800):
        rows = liggghts.round_trip(problem, speeds, steps, fits=fits)
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
