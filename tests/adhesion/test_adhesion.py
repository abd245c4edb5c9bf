"""Adhesive normal impact (docs/physics.md#adhesion) against what the code does not produce.

- quasi-static elastic JKR closed forms (both branches of F(d) and a(d), pull-off force,
  contact radius at zero load, jump into contact at d = 0), with the element spacing's
  first-order convergence;
- an elastic adhesive impact against the energy balance over the JKR curve (a scipy
  quadrature here, not the kernel), and the sticking velocity it implies;
- the limit dgamma -> 0 against the non-adhesive element kernel;
- convergence under joint refinement of steps and elements; passivity.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad

import vimpact as v
from vimpact.engine.adhesion import (
    adhesion_for_number,
    adhesion_number,
    jkr_quasi_static,
    simulate_adhesive,
    sticking_velocity,
)

E_STAR, R, M, DGAMMA = 1.5e6, 0.01, 4e-3, 0.5  # Pa, m, kg, J/m^2 (a rubber-like contact)
ELASTIC = v.Material.elastic(nu=0.5, E=E_STAR * 0.75)  # E* = E / (1 - nu^2)


def scene(v_z0: float, material=ELASTIC, dgamma: float = DGAMMA) -> v.Scene:
    return v.Scene(material, R=R, m=M, v_z0=v_z0, adhesion=dgamma, tangential="none")


# ---- JKR closed forms (rigid sphere, parabolic profile) ----------------------------
def jkr_d(a):
    return a**2 / R - np.sqrt(2.0 * math.pi * a * DGAMMA / E_STAR)


def jkr_F(a):
    return 4.0 * E_STAR * a**3 / (3.0 * R) - np.sqrt(8.0 * math.pi * DGAMMA * E_STAR * a**3)


A0 = (9.0 * math.pi * DGAMMA * R**2 / (2.0 * E_STAR)) ** (1.0 / 3.0)  # zero load
A_JUMP = (2.0 * math.pi * DGAMMA * R**2 / E_STAR) ** (1.0 / 3.0)  # d = 0 on the stable branch
A_MIN = (math.pi * DGAMMA * R**2 / (8.0 * E_STAR)) ** (1.0 / 3.0)  # d minimal: separation
F_PULL = -1.5 * math.pi * DGAMMA * R
D_UNIT = A0**2 / R


def separation_work() -> float:
    """Work the sphere loses on the JKR curve from d = 0 (after the jump into contact)
    out to the separation at d_min: -int F dd over a in [a_min, a_jump], J."""
    def dd_da(a):
        return 2.0 * a / R - 0.5 * math.sqrt(2.0 * math.pi * DGAMMA / (E_STAR * a))
    return -quad(lambda a: float(jkr_F(a)) * dd_da(a), A_MIN, A_JUMP)[0]


def test_scene_adhesion_validation_and_routing():
    assert v.Scene(ELASTIC, R=R, m=M, v_z0=1.0).adhesion == 0.0
    with pytest.raises(ValueError, match="adhesion"):
        v.Scene(ELASTIC, R=R, m=M, v_z0=1.0, adhesion=-1.0)
    with pytest.raises(ValueError, match="adhesion"):
        v.Scene(ELASTIC, R=R, m=M, v_z0=1.0, adhesion=math.nan)
    with pytest.raises(ValueError, match="normal only"):
        v.Scene(ELASTIC, R=R, m=M, v_z0=1.0, v_x0=0.5, adhesion=0.1)
    assert v.choose_path(scene(0.05), v.Numerics()).name == "adhesion[verlet,normal]"
    assert "adhesion" not in v.choose_path(scene(0.05, dgamma=0.0), v.Numerics()).name
    batch = v.simulate_batch([scene(0.05)])  # never run as if without adhesion
    assert batch.path[0] == "adhesion[verlet,normal]"


def test_quasi_static_row_is_jkr_on_both_branches():
    """Load to 2 d_unit, unload to -2 d_unit: the row's (d, a) lie on the JKR curve
    d(a) past the pull-off force (force-controlled unstable branch) down to a_min."""
    d_in = np.linspace(0.0, 2.0 * D_UNIT, 401)
    d_out = np.linspace(2.0 * D_UNIT, -2.0 * D_UNIT, 2001)
    errors = []
    for n in (100, 200, 400):
        F, a = jkr_quasi_static(E_STAR, R, DGAMMA, np.concatenate([d_in, d_out]), n)
        Fo, ao, do = F[401:], a[401:], d_out
        on = ao > 0
        dx = A0 / n
        # both branches are visited: contact radii above and below the pull-off radius
        a_pull = (9.0 * math.pi * DGAMMA * R**2 / (8.0 * E_STAR)) ** (1.0 / 3.0)
        assert ao[on].max() > 1.5 * a_pull and ao[on].min() < 0.8 * a_pull
        # a(d): the row's edge lies within one spacing of the JKR radius
        err_d = np.abs(do[on] - jkr_d(ao[on])) / D_UNIT
        # F(d) along the unloading path against JKR at the row's own contact radius
        err_F = np.abs(Fo[on] - jkr_F(ao[on])) / abs(F_PULL)
        assert err_F.max() < 20.0 / n
        # separation at the minimum of d(a): no contact below d_min (+ one spacing)
        assert not np.any(on & (do < jkr_d(A_MIN) - 2.0 * dx * A0 / R))
        assert np.all(on[do > jkr_d(A_MIN) + 0.05 * D_UNIT])
        # pull-off force -3/2 pi dgamma R and zero-load radius a_0
        assert Fo.min() == pytest.approx(F_PULL, rel=3.0 / n)
        k = np.flatnonzero((Fo[:-1] > 0.0) & (Fo[1:] <= 0.0))[0]
        assert ao[k] == pytest.approx(A0, abs=3.0 * dx)
        # jump into contact at d = 0: the first contact (once the centre element at
        # dx/2 touches) is at once the JKR radius a_jump of d = 0, not a point
        k0 = np.flatnonzero(a[:401] > 0.0)[0]
        assert d_in[k0] <= (0.5 * dx) ** 2 / R + d_in[1]
        assert a[k0] == pytest.approx(A_JUMP, abs=2.0 * dx)
        # loading branch is the same JKR curve (reversible elastic adhesion)
        err_load = np.abs(d_in[a[:401] > 0] - jkr_d(a[:401][a[:401] > 0])) / D_UNIT
        assert err_load.max() < 10.0 / n
        errors.append(err_d.max())
    order = math.log2(errors[0] / errors[2]) / 2.0
    assert 0.8 < order < 1.3, errors


def test_elastic_impact_energy_balance_and_pull_off():
    """e_z^2 = 1 - 2 W / (m v^2), W the work over the JKR curve from the jump into
    contact to the separation instability; the largest pull is the pull-off force."""
    W = separation_work()
    for vz in (0.02, 0.05):
        res = simulate_adhesive(scene(vz))
        assert res.status == "ok" and not res.stuck
        assert res.e_z == pytest.approx(math.sqrt(1.0 - 2.0 * W / (M * vz**2)), abs=2e-3)
        assert res.F_tensile_max == pytest.approx(-F_PULL, rel=2e-2)
        assert res.u_min == pytest.approx(float(jkr_d(A_MIN)), rel=5e-2)


def test_elastic_sticking_velocity_and_stuck_status():
    v_s = math.sqrt(2.0 * separation_work() / M)
    got = sticking_velocity(scene(0.02), rtol=1e-3)
    assert got == pytest.approx(v_s, rel=5e-3)
    below = v.simulate(scene(0.9 * v_s))
    assert below.status == "stuck" and below.e_z == 0.0 and below.energy_ratio == 0.0
    above = v.simulate(scene(1.2 * v_s))
    assert above.status == "normal_only" and 0.0 < above.e_z < 1.0


def test_joint_refinement_converges_first_order():
    vz = 0.03
    exact = math.sqrt(1.0 - 2.0 * separation_work() / (M * vz**2))
    err = [abs(simulate_adhesive(scene(vz), v.Numerics(steps=175 * 2**k, elements=25 * 2**k)).e_z
               - exact) for k in range(4)]
    for coarse, fine in zip(err, err[1:]):
        assert fine < 0.7 * coarse, err


@pytest.mark.parametrize("material", [
    v.Material.kelvin_voigt(nu=0.5, E=E_STAR * 0.75, eta=30.0),
    v.Material.standard_solid(nu=0.4, G1=3e5, G2=1e6, eta=30.0),
], ids=["kelvin_voigt", "standard_solid"])
def test_no_adhesion_limit_is_the_element_kernel(material):
    """dgamma -> 0: the adhesive kernel's rules become the non-adhesive ones.

    The element kernel's e_z of an oblique full-stick impact: its normal problem does
    not see the tangential one (it differs from the normal-only run by the element
    row's refinement, about 1e-7 here), and it is the kernel the rest of the suite
    compiles (a normal-only one would be compiled for this test alone)."""
    for vz in (0.05, 0.5):
        ref = v.simulate(v.Scene(material, R=R, m=M, v_z0=vz, v_x0=0.3 * vz,
                                 allow_large_contact=True),
                         v.Numerics(continuum=False)).e_z
        tiny = simulate_adhesive(scene(vz, material, dgamma=1e-12)).e_z
        zero = simulate_adhesive(scene(vz, material, dgamma=0.0)).e_z
        assert zero == pytest.approx(ref, abs=2e-4)
        assert tiny == pytest.approx(ref, abs=2e-4)


@pytest.mark.parametrize("material", [
    v.Material.kelvin_voigt(nu=0.5, E=E_STAR * 0.75, eta=30.0),
    v.Material.standard_solid(nu=0.5, G1=5e5, G2=2e6, eta=20.0),
    v.Material.prony(nu=0.5, G_inf=5e5, arms=[(1e6, 1e-4), (3e6, 3e-3)], eta0=5.0),
], ids=["kelvin_voigt", "standard_solid", "prony"])
def test_viscoelastic_adhesive_impacts_are_passive(material):
    """Energy is never created: the kinetic energy after is at most the one before
    (e_z <= 1) for Kelvin-Voigt, standard-solid and Prony half-spaces from sticking to
    fast impacts; results finite, a stuck sphere has e_z = 0 (not NaN)."""
    for vz in (0.01, 0.03, 0.1, 0.3):
        res = simulate_adhesive(scene(vz, material))
        assert res.status in ("ok", "stuck")
        assert 0.0 <= res.e_z <= 1.0
        assert math.isfinite(res.F_tensile_max) and res.F_tensile_max > 0.0
        if res.stuck:
            assert res.e_z == 0.0


def test_viscoelastic_sticks_at_a_higher_speed_than_elastic():
    """Damping only adds losses to the adhesive ones: the sticking velocity of a
    Kelvin-Voigt half-space is above the elastic one (same relaxed modulus)."""
    kv = v.Material.kelvin_voigt(nu=0.5, E=E_STAR * 0.75, eta=30.0)
    v_el = sticking_velocity(scene(0.02), rtol=1e-2)
    v_kv = sticking_velocity(scene(0.02, kv), rtol=1e-2)
    assert v_kv > 1.05 * v_el


def test_adhesion_number_scaling():
    """lam = sqrt(2 pi a_H dgamma / E*) / d falls as v^(-3/5) (d ~ v^(4/5), a_H ~ v^(2/5))."""
    l1, l2 = adhesion_number(scene(0.1)), adhesion_number(scene(1.0))
    assert l1 / l2 == pytest.approx(10.0**0.6, rel=1e-12)


def test_sticking_velocity_input_errors():
    with pytest.raises(ValueError, match="rtol"):
        sticking_velocity(scene(0.02), rtol=0.0)
    assert sticking_velocity(dataclasses.replace(scene(0.02), adhesion=0.0)) == 0.0


def test_elastic_sticking_velocity_closed_form_and_collapse():
    """Elastic: e_z depends on lam alone, and the sticking velocity is
    v_s = C (dgamma^5 R^4 / (E*^2 m^3))^(1/6) with C from the JKR work in JKR units
    (a scipy quadrature here): lam_s = (1 / (2 w0))^(3/10), C = sqrt(16/15) (2 pi / lam_s^2)^(5/6)."""
    w0 = -quad(lambda s: (1.25 * s**3 - 15.0 / 8.0 * s**1.5) * (2.0 * s - 0.5 * s**-0.5),
               4.0 ** (-2.0 / 3.0), 1.0)[0]
    lam_s = (1.0 / (2.0 * w0)) ** 0.3
    C = math.sqrt(16.0 / 15.0) * (2.0 * math.pi / lam_s**2) ** (5.0 / 6.0)
    assert C == pytest.approx(3.766, abs=1e-3)
    other = v.Scene(v.Material.elastic(nu=0.3, E=7e7), R=0.05, m=0.3, v_z0=0.1, adhesion=2.0,
                    tangential="none")
    for s in (scene(0.02), other):
        scale = (s.adhesion**5 * s.R**4 / (s.E_star**2 * s.m**3)) ** (1.0 / 6.0)
        assert sticking_velocity(s, rtol=1e-3) == pytest.approx(C * scale, rel=3e-3)
    # same lam, different physics: the same e_z to rounding
    for lam in (0.3, 1.0):
        a = scene(0.05)
        b = dataclasses.replace(other, v_z0=0.7)
        a = dataclasses.replace(a, adhesion=adhesion_for_number(a, lam))
        b = dataclasses.replace(b, adhesion=adhesion_for_number(b, lam))
        assert adhesion_number(a) == pytest.approx(lam, rel=1e-12)
        assert simulate_adhesive(a).e_z == pytest.approx(simulate_adhesive(b).e_z, abs=1e-12)


def test_kelvin_voigt_collapses_on_lam_and_q1():
    """Kelvin-Voigt: e_z depends on (lam, Q1) only (measured on two physical scenes)."""
    q1, lam = 0.05, 0.8
    a = v.Scene.from_dimensionless(q1, 0.5, tangential="none")
    mat_b = v.Material.kelvin_voigt(nu=0.2, G=4e6, eta=1.0)
    b = v.Scene(mat_b, R=0.003, m=2e-4, v_z0=0.4, tangential="none")
    b = dataclasses.replace(b, material=v.Material.kelvin_voigt(
        nu=0.2, G=4e6, eta=1.0 * q1 / b.Q1))
    assert b.Q1 == pytest.approx(q1, rel=1e-12)
    a = dataclasses.replace(a, adhesion=adhesion_for_number(a, lam), allow_large_contact=True)
    b = dataclasses.replace(b, adhesion=adhesion_for_number(b, lam), allow_large_contact=True)
    ra, rb = simulate_adhesive(a), simulate_adhesive(b)
    assert ra.e_z == pytest.approx(rb.e_z, abs=1e-9) and 0.0 < ra.e_z < 1.0
