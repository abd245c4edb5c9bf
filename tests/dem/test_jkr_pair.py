"""LAMMPS' ``jkr`` pair contact (``pair_coeff``) against :class:`vimpact.dem.jkr.JkrLaw` of the
pair's effective radius and mass."""

from __future__ import annotations

import math

import pytest

from tests.dem.codes import need
from vimpact.dem import lammps
from vimpact.dem.jkr import JkrLaw, lammps_jkr_restitution, law_sticking_velocity

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


def test_lammps_pair_collision_follows_the_effective_law():
    """Two unequal spheres head on in LAMMPS (pair_coeff jkr): they stick below the law's
    sticking velocity and rebound with the law's e_z above it; sphere 1 alone on a
    wall (its own radius and mass) would not (e_z off by about 0.06 at 0.1 m/s)."""
    need(lammps.lammps_available(), "LAMMPS")
    E_star = E / (2.0 * (1.0 - NU**2))  # how LAMMPS mixes the E, nu of a pair line
    law = JkrLaw.pair(E_star, R1, _mass(R1), R2, _mass(R2), COHESION, ETA_N0)
    v_stick = law_sticking_velocity(law, 0.02)
    wall = JkrLaw(E_star, R1, _mass(R1), COHESION, ETA_N0)
    for v in (0.7 * v_stick, 1.3 * v_stick, 0.1):
        e = lammps_jkr_restitution(COEFFS, law, R1, RHO, v, R2=R2, rho2=RHO)
        expected = law.restitution(v)
        if v < v_stick:
            assert e == 0.0 and expected == 0.0
        else:
            # measured 3.4e-4 just above sticking, 1.5e-5 at 0.1 m/s (4000 steps per contact)
            assert e == pytest.approx(expected, abs=2e-3)
            assert abs(wall.restitution(v) - e) > 0.02
