"""Pairs and walls mapped onto the rigid-sphere problem (vimpact.model.pair, run by
vimpact.engine.pairs)."""

import math

import numpy as np
import pytest

import vimpact as v
from vimpact.engine.pairs import simulate_pair, simulate_pair_batch
from vimpact.model.pair import Body, Wall, pair_material, pair_scene

FAST = v.Numerics.preset("fast")
KV = v.Material.kelvin_voigt(nu=0.4, E=1e9, eta=2000.0)


def _hertz_time_textbook(E1, nu1, E2, nu2, R1, R2, m1, m2, v0):
    """Elastic contact time of two spheres from the textbook effective modulus
    ``1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2`` (not from shear moduli as the code does)."""
    E = 1.0 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)
    R, m = R1 * R2 / (R1 + R2), m1 * m2 / (m1 + m2)
    d = (15 * m * v0**2 / (16 * E * math.sqrt(R)))**0.4
    return 2.9432751843 * d / v0


@pytest.mark.parametrize("E2, nu2", [(2e9, 0.3), (5e10, 0.25)])
def test_elastic_pair_contact_time_is_textbook_hertz(E2, nu2):
    E1, nu1 = 2e9, 0.3
    b1 = Body(v.Material.elastic(nu=nu1, E=E1), R=0.01, m=0.004, v_z=0.7)
    b2 = Body(v.Material.elastic(nu=nu2, E=E2), R=0.03, m=0.1, v_z=-0.3)
    res = simulate_pair(b1, b2, FAST, tangential="none")
    assert res.e_z == pytest.approx(1.0, abs=2e-3)
    t_ref = _hertz_time_textbook(E1, nu1, E2, nu2, 0.01, 0.03, 0.004, 0.1, 1.0)
    assert res.result.t_contact == pytest.approx(t_ref, rel=2e-3)


def test_same_material_is_halved_half_space():
    b1 = Body(KV, R=0.01, m=0.004, Theta=0.0000002, v_z=1.0, v_x=0.3, omega=10.0)
    b2 = Body(KV, R=0.02, m=0.03, v_z=-0.5, v_x=-0.2, omega=-5.0)
    pair = simulate_pair(b1, b2, FAST)
    half = v.Material.kelvin_voigt(nu=0.4, G=KV.G_inf / 2, eta=KV.eta0 / 2)
    R, m = 0.01 * 0.02 / 0.03, 0.004 * 0.03 / 0.034
    Theta = R**2 / (0.01**2 / 0.0000002 + 0.02**2 / b2.Theta)
    v_c0 = (0.3 + 0.2) + 0.01 * 10.0 + 0.02 * (-5.0)
    ref = v.simulate(v.Scene(half, R=R, m=m, v_z0=1.5, v_x0=v_c0, Theta=Theta), FAST)
    assert pair.e_z == pytest.approx(ref.e_z, rel=1e-12)
    assert pair.beta_x == pytest.approx(ref.beta_x, rel=1e-12)


def _swap(b: Body) -> Body:
    """The same body seen with z and x reversed (y kept): v_z, v_x flip, omega stays."""
    return Body(b.material, b.R, b.m, b.Theta, -b.v_z, -b.v_x, b.omega, b.rotation)


def test_pair_is_symmetric_in_its_bodies():
    b1 = Body(KV, R=0.01, m=0.004, v_z=1.0, v_x=0.3, omega=10.0)
    b2 = Body(KV, R=0.02, m=0.03, v_z=-0.5, v_x=-0.2, omega=-5.0)
    a = simulate_pair(b1, b2, FAST)
    b = simulate_pair(_swap(b2), _swap(b1), FAST)
    assert b.e_z == pytest.approx(a.e_z, rel=1e-12)
    assert b.beta_x == pytest.approx(a.beta_x, rel=1e-12)
    np.testing.assert_allclose([-b.body2[0], -b.body2[1], b.body2[2]], a.body1, rtol=1e-12)
    np.testing.assert_allclose([-b.body1[0], -b.body1[1], b.body1[2]], a.body2, rtol=1e-12)


def test_momentum_linear_and_angular_about_the_contact_point():
    b1 = Body(KV, R=0.01, m=0.004, v_z=1.0, v_x=0.3, omega=10.0)
    b2 = Body(KV, R=0.02, m=0.03, Theta=3e-6, v_z=-0.5, v_x=-0.2, omega=-5.0)
    r = simulate_pair(b1, b2, FAST)
    assert r.status == "ok" and abs(r.J_x) > 0
    (z1, x1, w1), (z2, x2, w2) = r.body1, r.body2
    assert b1.m * z1 + b2.m * z2 == pytest.approx(b1.m * b1.v_z + b2.m * b2.v_z, rel=1e-13)
    assert b1.m * x1 + b2.m * x2 == pytest.approx(b1.m * b1.v_x + b2.m * b2.v_x, rel=1e-13)

    def L(w1, x1, w2, x2):  # body 1 centre at z = -R1, body 2 at +R2; L_y = Theta w + z m v_x
        return b1.Theta * w1 - b1.R * b1.m * x1 + b2.Theta * w2 + b2.R * b2.m * x2

    assert L(w1, x1, w2, x2) == pytest.approx(L(b1.omega, b1.v_x, b2.omega, b2.v_x), rel=1e-12)
    # the relative contact-point velocity after is -beta_x times the one before
    vc0 = (b1.v_x - b2.v_x) + b1.R * b1.omega + b2.R * b2.omega
    vc1 = (x1 - x2) + b1.R * w1 + b2.R * w2
    assert vc1 == pytest.approx(-r.beta_x * vc0, rel=1e-12)


@pytest.mark.parametrize("material", [None, KV])
def test_wall_is_the_limit_of_a_huge_body(material):
    b1 = Body(KV, R=0.01, m=0.004, v_z=1.0, v_x=0.5)
    wall = simulate_pair(b1, Wall(material), FAST)
    big = simulate_pair(b1, Body(material, R=1e7, m=1e13), FAST)
    assert big.e_z == pytest.approx(wall.e_z, rel=1e-5)
    assert big.beta_x == pytest.approx(wall.beta_x, rel=1e-4, abs=1e-6)
    if material is None:  # rigid wall: today's problem
        ref = v.simulate(v.Scene(KV, R=0.01, m=0.004, v_z0=1.0, v_x0=0.5), FAST)
        assert wall.e_z == ref.e_z and wall.beta_x == ref.beta_x
    assert wall.body2 is None


def _G_of_s(mat, s):
    """Laplace-domain modulus s G(s) of a generalized Maxwell material."""
    return mat.G_inf + mat.eta0 * s + sum(G * tau * s / (1 + tau * s) for G, tau in mat.arms)


@pytest.mark.parametrize("visco", [
    v.Material.kelvin_voigt(nu=0.45, G=2e6, eta=30.0),
    v.Material.standard_solid(nu=0.45, G1=2e6, G2=5e6, eta=10.0),
])
def test_elastic_with_viscoelastic_is_the_series_combination(visco):
    elastic = v.Material.elastic(nu=0.45, G=7e6)
    for a, b in ((elastic, visco), (visco, elastic)):
        mat = pair_material(a, b)
        assert mat.model == "standard_solid" and mat.nu == 0.45
        for s in (0.0, 1e3, 1e5, 1e6, 1e8):
            Ge, Gv = _G_of_s(elastic, s), _G_of_s(visco, s)
            assert _G_of_s(mat, s) == pytest.approx(Ge * Gv / (Ge + Gv), rel=1e-12)


def test_proportional_materials_add_compliances():
    hard = v.Material.kelvin_voigt(nu=0.4, G=3 * KV.G_inf, eta=3 * KV.eta0)
    mat = pair_material(KV, hard)
    for s in (0.0, 1e4, 1e6):
        G1, G2 = _G_of_s(KV, s), _G_of_s(hard, s)
        assert _G_of_s(mat, s) == pytest.approx(G1 * G2 / (G1 + G2), rel=1e-12)


def test_elastic_pair_compliances_add():
    m1, m2 = v.Material.elastic(nu=0.2, E=70e9), v.Material.elastic(nu=0.45, E=3e9)
    mat = pair_material(m1, m2)
    E = lambda m: 2 * m.G_inf / (1 - m.nu)  # noqa: E731
    K = lambda m: 4 * m.G_inf / (2 - m.nu)  # noqa: E731
    assert 1 / E(mat) == pytest.approx(1 / E(m1) + 1 / E(m2), rel=1e-12)
    assert 1 / K(mat) == pytest.approx(1 / K(m1) + 1 / K(m2), rel=1e-12)


@pytest.mark.parametrize("a, b, words", [
    (KV, v.Material.kelvin_voigt(nu=0.3, E=1e9, eta=2000.0), "equal nu"),
    (v.Material.elastic(nu=0.3, E=1e9), KV, "equal nu"),
    (None, None, "rigid"),
])
def test_refusals_say_why(a, b, words):
    with pytest.raises(v.InputError, match=words):
        pair_material(a, b)


def test_bodies_must_approach():
    with pytest.raises(v.InputError, match="approach"):
        pair_scene(Body(KV, 0.01, 0.004, v_z=0.1), Body(KV, 0.01, 0.004, v_z=0.2))


def test_batch_matches_single_and_marks_wall_nan():
    b1 = Body(KV, R=0.01, m=0.004, v_z=1.0, v_x=0.3)
    b2 = Body(KV, R=0.02, m=0.03, v_z=-0.5)
    df = simulate_pair_batch([(b1, b2), (b1, Wall())], FAST)
    one = simulate_pair(b1, b2, FAST)
    assert df.loc[0, "e_z"] == one.e_z and df.loc[0, "v_x2"] == one.body2[1]
    assert math.isnan(df.loc[1, "v_z2"]) and np.isfinite(df.loc[1, "v_z1"])


def test_pair_restitutions_in_one_batch_equal_the_curves_one_by_one():
    """Several pairs' curves (normal, full stick, oblique with friction) in one engine batch
    give each curve bit for bit what :func:`pair_restitution` gives it alone; an unknown
    option is refused by name."""
    from vimpact.engine.pairs import pair_restitution, pair_restitutions

    b1 = Body(KV, R=0.01, m=0.004)
    b2 = Body(v.Material.kelvin_voigt(nu=0.4, G=3e7, eta=600.0), R=0.005, m=6e-4)
    speeds = np.array([0.1, 0.5, 1.3])
    curves = [(b1, Wall(), speeds, {}), (b1, b2, speeds[:2], {"tangential": True}),
              (b2, Wall(), speeds, {"tangential": True, "vc_ratio": 0.6, "mu": 0.3})]
    together = pair_restitutions(curves, FAST)
    for (a, b, s, options), df in zip(curves, together):
        alone = pair_restitution(a, b, s, numerics=FAST, **options)
        assert list(df.columns) == list(alone.columns)
        for col in df.columns:
            np.testing.assert_array_equal(df[col].to_numpy(), alone[col].to_numpy())
    with pytest.raises(ValueError, match="options"):
        pair_restitutions([(b1, Wall(), speeds, {"angle": 3.0})], FAST)
