"""LAMMPS' ``jkr`` model run in LAMMPS: the pair contact (``pair_coeff``) against
:class:`vimpact.dem.jkr.JkrLaw` of the pair's effective radius and mass, and the tangential
force's cap in an oblique wall impact against :func:`vimpact.dem.jkr.oblique_wall_impact`."""

from __future__ import annotations

import math

import pytest

from tests.dem.codes import need
from vimpact.dem import lammps
from vimpact.dem.jkr import (
    JkrLaw,
    lammps_jkr_restitutions,
    lammps_oblique_wall_impacts,
    law_sticking_velocity,
    oblique_wall_impact,
)

#: a jkr line near the one fitted to tests/dem/test_adhesion_export.py's sphere pair
#: (E* = 0.75 MPa for the pair, cohesion and eta_n0 of that fit); two unequal spheres
E, NU, COHESION, ETA_N0 = 1.125e6, 0.5, 0.3075, 49110.0
R1, R2, RHO = 0.01, 0.015, 955.0
COEFFS = (f"jkr {E} {ETA_N0} {NU} {COHESION} damping viscoelastic "
          "tangential linear_nohistory 0 0")


def _mass(R: float) -> float:
    return RHO * 4.0 / 3.0 * math.pi * R**3


def test_pair_law_is_the_wall_law_of_the_effective_sphere():
    E_star = E / (2.0 * (1.0 - NU**2))
    law = JkrLaw.pair(E_star, R1, _mass(R1), R2, _mass(R2), COHESION, ETA_N0)
    assert law.R == pytest.approx(R1 * R2 / (R1 + R2), rel=1e-15)
    assert law.m == pytest.approx(_mass(R1) * _mass(R2) / (_mass(R1) + _mass(R2)), rel=1e-15)
    # equal spheres: half the radius and half the mass
    equal = JkrLaw.pair(E_star, R1, _mass(R1), R1, _mass(R1), COHESION, ETA_N0)
    assert (equal.R, equal.m) == pytest.approx((R1 / 2.0, _mass(R1) / 2.0), rel=1e-15)


def test_lammps_pair_collision_follows_the_effective_law(one_lammps_process):
    """Two unequal spheres head on in LAMMPS (pair_coeff jkr): they stick below the law's
    sticking velocity and rebound with the law's e_z above it; sphere 1 alone on a
    wall (its own radius and mass) would not (e_z off by about 0.06 at 0.1 m/s)."""
    need(lammps.lammps_available(), "LAMMPS")
    E_star = E / (2.0 * (1.0 - NU**2))  # how LAMMPS mixes the E, nu of a pair line
    law = JkrLaw.pair(E_star, R1, _mass(R1), R2, _mass(R2), COHESION, ETA_N0)
    v_stick = law_sticking_velocity(law, 0.02)
    wall = JkrLaw(E_star, R1, _mass(R1), COHESION, ETA_N0)
    speeds = (0.7 * v_stick, 1.3 * v_stick, 0.1)
    for v, e in zip(speeds, lammps_jkr_restitutions(COEFFS, law, R1, RHO, speeds, R2=R2,
                                                    rho2=RHO)):
        expected = law.restitution(v)
        if v < v_stick:
            assert e == 0.0 and expected == 0.0
        else:
            # measured 3.4e-4 just above sticking, 1.5e-5 at 0.1 m/s (4000 steps per contact)
            assert e == pytest.approx(expected, abs=2e-3)
            assert abs(wall.restitution(v) - e) > 0.02


#: the wall line fitted to tests/dem/test_adhesion_export.py's set-up (E* = 1.5 MPa, R = 1 cm,
#: cohesion 0.295 J/m^2; k_t, x_gamma_t fitted with the non-adhesive cap, mu_s = 0.5)
WALL = dict(E=2.25e6, eta_n0=49757.3, nu=0.5, cohesion=0.29492, k_t=1.65772e6, x_gamma_t=0.4102,
            mu_s=0.5)


def test_lammps_caps_the_jkr_tangential_force_at_the_raised_limit(one_lammps_process):
    """An oblique (45 deg) jkr wall impact in LAMMPS gives the beta_x of the stepped law with
    LAMMPS' cap mu_s |F_ne + 2 F_pulloff|, not of the cap the tangential constants were fitted
    with (the normal force clipped at zero): beta_x -0.43 instead of 0.24 at 0.03 m/s."""
    need(lammps.lammps_available(), "LAMMPS")
    w = WALL
    coeffs = (f"jkr {w['E']} {w['eta_n0']} {w['nu']} {w['cohesion']} damping viscoelastic "
              f"tangential mindlin {w['k_t']} {w['x_gamma_t']} {w['mu_s']}")
    law = JkrLaw(w["E"] / (2.0 * (1.0 - w["nu"] ** 2)), R1, _mass(R1), w["cohesion"], w["eta_n0"])
    speeds = (0.03, 0.4)
    for v, (e, beta) in zip(speeds, lammps_oblique_wall_impacts(coeffs, law, RHO, speeds, 45.0)):
        e_jkr, beta_jkr = oblique_wall_impact(law, w["k_t"], w["x_gamma_t"], w["mu_s"], v, 45.0,
                                              steps_per_contact=4000)
        _, beta_clipped = oblique_wall_impact(law, w["k_t"], w["x_gamma_t"], w["mu_s"], v, 45.0,
                                              cap="clipped", steps_per_contact=4000)
        # measured: beta 3.8e-4 and 1.5e-5 apart, e 7e-4 and 1e-5 (0.03, 0.4 m/s)
        assert beta == pytest.approx(beta_jkr, abs=3e-3)
        assert e == pytest.approx(e_jkr, abs=3e-3)
        assert abs(beta - beta_clipped) > 0.05  # measured 0.67 and 0.09


def test_oblique_wall_impact_refuses_an_unknown_cap():
    law = JkrLaw(1.5e6, R1, _mass(R1), 0.3, 5e4)
    with pytest.raises(ValueError, match="cap = 'hertz'"):
        oblique_wall_impact(law, 1e6, 0.4, 0.5, 0.1, 45.0, cap="hertz")
