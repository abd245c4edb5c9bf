"""What LAMMPS' granular ``jkr`` normal model does with the same elastic adhesive impact.

A measurement for the (not yet written) ``jkr`` export: LAMMPS' elastic JKR contact
(no damping) against a wall loses the JKR work only down to the load-controlled
pull-off point (force minimum, ``a = (9 pi dgamma R^2 / (8 E*))^(1/3)``), about half
(0.494) of what the element row loses down to ``d_min`` (docs/physics.md#adhesion).
The work shares are scipy quadratures here; LAMMPS' ``cohesion`` is the surface
energy ``dgamma / 2`` (its pull-off force is ``3 pi cohesion R``), and its wall mixes
``E`` as a body of the same material (``E* = E / (2 (1 - nu^2))``, vimpact.dem.lammps).
"""

from __future__ import annotations

import math

import pytest
from scipy.integrate import quad

from vimpact.dem import lammps
from vimpact.dem.lammps import collision_script, run_lammps

E_STAR, NU, R, M, DGAMMA = 1.5e6, 0.5, 0.01, 4e-3, 0.5


def jkr_work(a_out: float) -> float:
    """-int F dd on the JKR curve from the jump into contact (a_J) out to ``a_out``, J."""
    def integrand(a):
        F = 4.0 * E_STAR * a**3 / (3.0 * R) - math.sqrt(8.0 * math.pi * DGAMMA * E_STAR * a**3)
        return F * (2.0 * a / R - 0.5 * math.sqrt(2.0 * math.pi * DGAMMA / (E_STAR * a)))
    a_jump = (2.0 * math.pi * DGAMMA * R**2 / E_STAR) ** (1.0 / 3.0)
    return -quad(integrand, a_out, a_jump)[0]


@pytest.mark.slow
def test_lammps_jkr_separates_at_the_force_minimum():
    why = lammps.lammps_available()
    if why is not None:
        pytest.skip(f"LAMMPS: {why}")
    a_pull = (9.0 * math.pi * DGAMMA * R**2 / (8.0 * E_STAR)) ** (1.0 / 3.0)
    a_min = (math.pi * DGAMMA * R**2 / (8.0 * E_STAR)) ** (1.0 / 3.0)
    assert jkr_work(a_pull) / jkr_work(a_min) == pytest.approx(0.4939, abs=1e-4)
    # LAMMPS' pull-off distance (cbrt(3 pi^2 / 16) (R cohesion^2 / E*^2)^(1/3)) is |d(a_pull)|
    d_pull = a_pull**2 / R - math.sqrt(2.0 * math.pi * a_pull * DGAMMA / E_STAR)
    lammps_pulloff = (3.0 * math.pi**2 / 16.0) ** (1.0 / 3.0) * (
        R * (DGAMMA / 2.0) ** 2 / E_STAR**2) ** (1.0 / 3.0)
    assert lammps_pulloff == pytest.approx(-d_pull, rel=1e-12)
    rho = M / (4.0 / 3.0 * math.pi * R**3)
    E = 2.0 * (1.0 - NU**2) * E_STAR
    coeffs = (f"jkr {E:.12g} 0 {NU} {DGAMMA / 2.0:.12g} damping viscoelastic "
              "tangential linear_nohistory 0 0")
    for v in (0.02, 0.05):
        (v1, _) = run_lammps(collision_script(coeffs, R, rho, v, 0.01, steps_per_contact=4000),
                             ["v1", "v2"])
        e_lammps = v1 / v
        assert e_lammps == pytest.approx(math.sqrt(1.0 - 2.0 * jkr_work(a_pull) / (M * v**2)),
                                         abs=2e-3)
        assert e_lammps > math.sqrt(1.0 - 2.0 * jkr_work(a_min) / (M * v**2)) + 0.01
