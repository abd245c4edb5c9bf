"""The element kernel against closed forms, limits and conservation laws (docs/physics.md)."""

import math

import numpy as np
import pytest

import vimpact as v
from vimpact.model.hertz import Q1_PER_TAU
from vimpact.reference.closed_forms import (
    hertz_time_factor_quadrature,
    kelvin_voigt_continuum,
    kelvin_voigt_small_damping_slope,
)

RNG_SEED = 20261121


def _elastic_scene(nu=0.5, v_x0=0.0):
    return v.Scene(v.Material.elastic(nu=nu, E=1e9), R=0.05, m=0.2, v_z0=2.0, v_x0=v_x0)


# ---- elastic normal impact: Hertz ---------------------------------------------------

def test_elastic_normal_impact_matches_hertz():
    res = v.simulate(_elastic_scene())
    assert res.status == "vc0_zero"
    assert abs(res.e_z - 1.0) < 1e-4
    # Hertz contact time by quadrature (independent of the Beta-function constant)
    t_h = hertz_time_factor_quadrature() * res.d_hertz / 2.0
    assert abs(res.t_hertz / t_h - 1.0) < 1e-12
    assert abs(res.t_contact / t_h - 1.0) < 1e-3
    assert abs(res.u_max / res.d_hertz - 1.0) < 1e-3
    assert abs(res.a_max / res.a_hertz - 1.0) < 1e-2  # element spacing 1/200 of a_H
    assert abs(res.energy_ratio - 1.0) < 1e-4
    assert math.isnan(res.e_x) and math.isnan(res.beta_x)


def _observed_order(errors, steps) -> float:
    """Least-squares slope of -log(error) against log(steps)."""
    return -np.polyfit(np.log(steps), np.log(errors), 1)[0]


@pytest.mark.parametrize("integrator, observable, nominal", [
    ("euler", "e_z", 1.0),  # thesis table 4.1: |e_z - 1| halves when the steps double
    ("verlet", "t_contact", 2.0),  # e_z of verlet is exact up to rounding (time reversible)
])
def test_convergence_order_on_the_elastic_impact(integrator, observable, nominal):
    """Observed order of the integrator on the elastic impact against the Hertz
    closed forms (e_z = 1, t_contact = 2.94 t_H); elements fine enough that
    the time step dominates."""
    steps = (250, 500, 1000)
    numerics = v.Numerics(integrator=integrator, elements=1600, continuum=False)
    errors = []
    for n in steps:
        res = v.simulate(_elastic_scene(), numerics.with_(steps=n))
        exact = 1.0 if observable == "e_z" else res.t_hertz
        errors.append(abs(getattr(res, observable) - exact) / exact)
    assert nominal - 0.25 < _observed_order(errors, steps) < nominal + 0.35, errors


def test_symplectic_euler_order():
    """Semi-implicit Euler: on the elastic impact its positions are Verlet's
    (the force vanishes at the start and the end, so the staggered velocities
    coincide there): same e_z and t_contact to rounding. With a dashpot (which
    it treats implicitly over the whole step) it is first order against the
    Kelvin-Voigt continuum."""
    base = v.Numerics(elements=400, steps=500, continuum=False)
    sym = v.simulate(_elastic_scene(), base.with_(integrator="symplectic_euler"))
    ver = v.simulate(_elastic_scene(), base)
    assert sym.e_z == pytest.approx(ver.e_z, abs=1e-12)
    assert sym.t_contact == pytest.approx(ver.t_contact, rel=1e-12)
    q1 = 0.3
    exact = kelvin_voigt_continuum(q1).e_z
    # normal only: no other default test runs a semi-implicit Euler kernel with a
    # dashpot, and the normal-only one compiles in less time than the oblique one
    scene = v.Scene.from_dimensionless(q1, 0.5, tangential="none")
    steps = (250, 500, 1000)
    errors = [abs(v.simulate(scene, base.with_(integrator="symplectic_euler", steps=n,
                                               elements=1600)).e_z - exact) for n in steps]
    assert 0.75 < _observed_order(errors, steps) < 1.35, errors


# ---- Kelvin-Voigt normal impact: continuum closed form -----------------------------

def test_kelvin_voigt_converges_to_continuum():
    q1 = [0.01, 0.03, 0.1, 0.3, 1.0, 3.0]
    exact = np.array([kelvin_voigt_continuum(q).e_z for q in q1])
    scenes = [v.Scene.from_dimensionless(q, 0.5) for q in q1]
    mean_err = []
    for steps, elements in [(120, 24), (500, 100), (2000, 400)]:
        df = v.simulate_batch(scenes, v.Numerics(steps=steps, elements=elements,
                                                 continuum=False))
        assert (df.status == "ok").all()
        mean_err.append(np.mean(np.abs(df.e_z.to_numpy() - exact)))
    for coarse, fine in zip(mean_err, mean_err[1:]):
        assert fine < coarse / 4.0
    assert mean_err[-1] < 1e-5


@pytest.mark.parametrize("q1", [1e-3, 0.02, 0.2, 2.0, 10.0])
def test_default_numerics_reach_1e4_on_kelvin_voigt(q1):
    exact = kelvin_voigt_continuum(q1)
    res = v.simulate(v.Scene.from_dimensionless(q1, 0.5))
    assert abs(res.e_z - exact.e_z) < 1e-4
    assert abs(res.t_contact / (res.d_hertz / 1.0) - exact.t_contact_over_T) < 1e-2
    assert abs(res.u_max / res.d_hertz - exact.u_max_over_d) < 1e-3


def test_kelvin_voigt_small_damping_slope():
    """1 - e_z = 1.8917 tau/T to first order (docs/physics.md#kelvin-voigt-continuum)."""
    slope = kelvin_voigt_small_damping_slope()
    assert abs(slope - 1.8917) < 1e-4
    for q1 in (1e-3, 3e-4):
        res = v.simulate(v.Scene.from_dimensionless(q1, 0.5), v.Numerics(steps=2000, elements=400))
        measured = (1.0 - res.e_z) / (q1 / Q1_PER_TAU)
        assert abs(measured / slope - 1.0) < 3e-3  # second-order term ~ 2.3 q1


def test_restitution_decreases_with_damping():
    df = v.simulate_batch([v.Scene.from_dimensionless(q, 0.5) for q in np.geomspace(1e-3, 10, 9)])
    assert (np.diff(df.e_z.to_numpy()) < 0).all()
    assert ((df.e_z > 0) & (df.e_z < 1)).all()


# ---- standard solid limits ----------------------------------------------------------

def test_standard_solid_tends_to_elastic_for_large_q2():
    """Q2 -> inf: the arm vanishes. The e_z gap falls like 1/Q2 (1 - e_z is
    first order in the arm's weight); e_x, which an elastic impact already
    has, comes within the default numerics' e_x accuracy (about 1e-4) and
    no further, so it is checked against that band, not for monotony."""
    elastic = v.simulate(v.Scene.from_dimensionless(0.0, 0.5))
    gaps_z, gaps_x = [], []
    for q2 in (1e2, 1e3, 1e4):
        r = v.simulate(v.Scene.from_dimensionless(0.3, 0.5, Q2=q2))
        gaps_z.append(abs(r.e_z - elastic.e_z))
        gaps_x.append(abs(r.e_x - elastic.e_x))
    assert gaps_z[0] > 30 * gaps_z[1] > 900 * gaps_z[2]
    assert gaps_z[2] < 1e-6
    assert max(gaps_x) < 3e-4, gaps_x


def test_standard_solid_tends_to_kelvin_voigt_for_small_q2():
    kv = v.simulate(v.Scene.from_dimensionless(0.3, 0.5))
    gaps = [abs(v.simulate(v.Scene.from_dimensionless(0.3, 0.5, Q2=q2)).e_z - kv.e_z)
            for q2 in (1e-1, 1e-2, 1e-3)]
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 2e-4
    # arm times far below the step: no artefact of the thesis's fig. 5.4
    for q2 in (1e-4, 1e-6):
        r = v.simulate(v.Scene.from_dimensionless(0.3, 0.5, Q2=q2))
        assert abs(r.e_z - kv.e_z) < 5e-4 and abs(r.e_x - kv.e_x) < 1e-3


def test_one_arm_prony_equals_standard_solid():
    G1, G2, eta, nu = 2e7, 5e7, 400.0, 0.3
    sls = v.Material.standard_solid(nu=nu, G1=G1, G2=G2, eta=eta)
    prony = v.Material.prony(nu=nu, G_inf=G1, arms=[(G2, eta / G2)])
    a, b = (v.simulate(v.Scene(mat, R=0.02, m=0.01, v_z0=1.5, v_x0=0.7, omega0=-20.0))
            for mat in (sls, prony))
    for key in ("e_z", "e_x", "beta_x", "t_contact", "u_max", "energy_ratio"):
        assert getattr(a, key) == pytest.approx(getattr(b, key), rel=1e-12)
    assert a.Q2 == pytest.approx(G1 / G2) and math.isnan(b.Q2)


# ---- passivity ----------------------------------------------------------------------

def _random_material(rng, model):
    nu = rng.uniform(0.0, 0.5)
    G = 10 ** rng.uniform(5, 9)
    if model == "elastic":
        return v.Material.elastic(nu=nu, G=G)
    if model == "kelvin_voigt":
        return v.Material.kelvin_voigt(nu=nu, G=G, eta=G * 10 ** rng.uniform(-7, -3))
    if model == "standard_solid":
        return v.Material.standard_solid(nu=nu, G1=G, G2=G * 10 ** rng.uniform(-2, 2),
                                         eta=G * 10 ** rng.uniform(-7, -3))
    arms = [(G * 10 ** rng.uniform(-1, 2), 10 ** rng.uniform(-8, -2)) for _ in range(3)]
    return v.Material.prony(nu=nu, G_inf=G, arms=arms, eta0=G * 10 ** rng.uniform(-8, -5))


@pytest.mark.parametrize("model", v.MODELS)
def test_incremental_memory_is_passive(model):
    rng = np.random.default_rng(RNG_SEED + v.MODELS.index(model))
    scenes = []
    for _ in range(12):
        R = 10 ** rng.uniform(-3, -1)
        scenes.append(v.Scene(_random_material(rng, model), R=R, m=10 ** rng.uniform(-4, 0) * R,
                              v_z0=10 ** rng.uniform(-2, 0.5), v_x0=rng.normal(),
                              omega0=rng.normal() / R, allow_large_contact=True))
    df = v.simulate_batch(scenes, v.Numerics.preset("fast"))
    assert df.status.isin(["ok", "half_space"]).all()
    assert (df.energy_ratio <= 1.0 + 1e-6).all()
    assert ((df.e_z >= 0) & (df.e_z <= 1 + 1e-6)).all()


def test_seed_memory_is_not_passive_for_elastic_nu0():
    """docs/physics.md#full-stick: the thesis's total-displacement rule returns energy."""
    mat = v.Material.elastic(nu=0.0, E=1e8)
    seed = v.simulate(v.Scene(mat, R=0.05, m=0.05, v_z0=1.0, v_x0=1.0, tangential_memory="seed"))
    incr = v.simulate(v.Scene(mat, R=0.05, m=0.05, v_z0=1.0, v_x0=1.0))
    assert seed.energy_ratio > 1.0 + 1e-3
    assert incr.energy_ratio < 1.0


def test_thesis_table_4_1_explicit_euler():
    """docs/physics.md#elastic-impact: explicit Euler, elastic, 1.1254 % (500 steps), 0.5608 % (1000)."""
    scene = v.Scene(v.Material.elastic(nu=0.5, E=5e10), R=0.2, m=10.0, v_z0=10.0)
    for steps, percent in ((500, 1.1254), (1000, 0.5608)):
        res = v.simulate(scene, v.Numerics(integrator="euler", steps=steps, elements=100, continuum=False))
        assert 100 * abs(res.e_z - 1) == pytest.approx(percent, rel=0.02)
