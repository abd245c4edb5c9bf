"""Coulomb friction in the element kernel (docs/physics.md#coulomb-friction).

Oracles, none produced by the kernel:
- gross slip throughout (large psi): ``F_x = mu F_z`` at every instant, so
  ``v_c,end = v_c0 - mu (1 + m R^2/Theta) (1 + e_z) v_z0`` for every rheology
  (kernel units: ``1 - mu_k mu_t (1 + e_z)``), with ``e_z`` of the same run;
- the limits ``mu -> inf`` (the stick kernel, bit for bit) and ``mu = 0``
  (``v_c`` unchanged);
- passivity: friction never adds tangential kinetic energy;
- the NumPy reference in SI units (friction written independently there);
- the flat punch (docs/physics.md#linear-model) as a 1-DOF stick-slip oscillator
  solved here with scipy (the kernel takes no profile: the reference does);
- convergence with friction (observed order).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.kernels.test_elements_accuracy import HERTZ_TIME, run_rows
from vimpact.kernels.elements import (
    OUT_T_CONTACT,
    OUT_T_GROSS_SLIP,
    OUT_VC_END,
    OUT_VZ_END,
    OUT_W_FRICTION,
    REC_SLIP,
    VERLET,
    KernelSpec,
    element_impact,
    element_kernel,
)

# kernel-unit rheologies: (tau0, g, tau); the default run compiles two friction
# kernels (elastic; arms and dashpot), the others are slow
RHEOLOGIES = {
    "elastic": (0.0, (), ()),
    "prony_dashpot": (0.05, (1.0, 0.5), (0.3, 3.0)),
    "kelvin_voigt": (0.2, (), ()),
    "standard_solid": (0.0, (2.0,), (0.5,)),
}
FAST = ("elastic", "prony_dashpot")
H, DXI = HERTZ_TIME / 400, 1.0 / 40  # coarse: the identities hold at any resolution


def spec_of(rheology, friction=True):
    tau0, g, _ = RHEOLOGIES[rheology]
    return KernelSpec(VERLET, True, 0, len(g) > 0, tau0 > 0.0, friction)


def run(rheology, friction=True, **kw):
    tau0, g, tau = RHEOLOGIES[rheology]
    kw.setdefault("h", H)
    kw.setdefault("dxi", DXI)
    return run_rows(spec_of(rheology, friction), tau0=tau0, g=g, tau=tau, **kw)


def slow_unless(rheology):
    return pytest.param(rheology, marks=() if rheology in FAST else pytest.mark.slow)


ALL = [slow_unless(r) for r in RHEOLOGIES]


@pytest.mark.parametrize("rheology", ALL)
def test_mu_inf_is_stick_bit_for_bit(rheology):
    # a stick spec and mu = inf run the one shared kernel: this checks the routing and that
    # mu = inf never slips; the kernel compiled without friction is compared with it in
    # tests/kernels/test_kernel_effects.py
    stick, rec_s = run(rheology, friction=False, n_rec=40, rec_every=10)
    fric, rec_f = run(rheology, mu=math.inf, n_rec=40, rec_every=10)
    assert np.array_equal(stick, fric)
    assert np.array_equal(rec_s, rec_f)
    assert fric[0, OUT_T_GROSS_SLIP] == 0.0 == fric[0, OUT_W_FRICTION]
    assert not rec_f[0, :, REC_SLIP].any()


@pytest.mark.parametrize("rheology", ALL)
def test_mu_zero_leaves_vc_unchanged(rheology):
    stick, _ = run(rheology, friction=False)
    out, rec = run(rheology, mu=0.0, n_rec=40, rec_every=10)
    assert out[0, OUT_VC_END] == 1.0
    assert out[0, OUT_W_FRICTION] == 0.0
    # the normal problem does not see the tangential one
    assert out[0, OUT_VZ_END] == stick[0, OUT_VZ_END]
    # the whole contact slips the whole time
    assert out[0, OUT_T_GROSS_SLIP] >= out[0, OUT_T_CONTACT] - H
    assert rec[0, :, REC_SLIP].max() > 0.5


@pytest.mark.parametrize("theta_ratio", [0.4, math.inf], ids=["rotation", "no_rotation"])
@pytest.mark.parametrize("rheology", ALL)
def test_gross_slip_closed_form(rheology, theta_ratio):
    """Large psi (mu_k = mu v_z0/|v_c0| small): gross slip throughout, and
    v_c,end = 1 - mu_k mu_t (1 + e_z) to rounding, for every rheology."""
    mu_k = np.array([0.01, 0.03, 0.05])
    mu_t = 1.0 + 1.0 / theta_ratio
    out, _ = run(rheology, mu=mu_k, theta_ratio=theta_ratio)
    e_z = -out[:, OUT_VZ_END]
    predicted = 1.0 - mu_k * mu_t * (1.0 + e_z)
    assert np.all(predicted > 0.0)  # still sliding forward at the end: gross slip
    np.testing.assert_allclose(out[:, OUT_VC_END], predicted, rtol=0.0, atol=1e-12)
    assert np.all(out[:, OUT_T_GROSS_SLIP] >= out[:, OUT_T_CONTACT] - H)
    if rheology == "elastic":  # Maw-Barber-Fawcett: psi2 = psi1 - 4 chi
        nu = 0.3
        kappa = 2.0 * (1.0 - nu) / (2.0 - nu)
        psi1 = kappa / mu_k
        chi = (1.0 - nu) * mu_t / (2.0 - nu)
        psi2 = kappa * out[:, OUT_VC_END] / mu_k
        np.testing.assert_allclose(psi2, psi1 - 4.0 * chi, rtol=1e-8)
    # dissipation: the tangential kinetic energy lost (1/2 m_eff (1 - vc^2), in
    # units m v_c0^2) goes into slip and the viscous parts; elastic: all to slip
    lost = 0.5 / mu_t * (1.0 - out[:, OUT_VC_END] ** 2)
    assert np.all(out[:, OUT_W_FRICTION] > 0.0)
    assert np.all(out[:, OUT_W_FRICTION] <= lost * (1.0 + 1e-2))
    if rheology == "elastic":
        np.testing.assert_allclose(out[:, OUT_W_FRICTION], lost, rtol=1e-2)


def test_seed_memory_with_friction_is_refused():
    with pytest.raises(ValueError, match="incremental"):
        element_kernel(KernelSpec(VERLET, True, 1, False, False, True))


def test_friction_never_adds_energy():
    """Random psi (through mu_k), rotation and arms: |v_c,end| <= v_c0 and the
    slip dissipation is not negative."""
    rng = np.random.default_rng(5)
    n = 24
    mu_k = 10.0 ** rng.uniform(-2.0, 1.5, n)
    theta = rng.uniform(0.1, 2.0)
    for rheology in FAST:
        out, _ = run(rheology, mu=mu_k, theta_ratio=theta)
        assert np.all(np.abs(out[:, OUT_VC_END]) <= 1.0 + 1e-9), out[:, OUT_VC_END]
        assert np.all(out[:, OUT_W_FRICTION] >= 0.0)
        assert np.all(np.isfinite(out))


@pytest.mark.parametrize("rheology", FAST)
def test_friction_converges_second_order_at_every_edge_position(rheology):
    """Near stick (psi = chi / 2), beta_x with friction under joint refinement
    of steps and elements: the largest error over 8 element counts per level
    (the largest contact radius at every position within an element; a single
    ladder samples one) falls at order >= 1.8 against a 4x finer run. Full
    stick with a dashpot does not: its edge stress jump makes the worst case
    about order 1.5 (benchmarks/element_orders.py); the cone removes the jump."""
    nu, theta = 0.3, 0.4
    kappa, mu_t = 2.0 * (1.0 - nu) / (2.0 - nu), 1.0 + 1.0 / theta
    chi = kappa * mu_t / 2.0
    mu_k = kappa / (0.5 * chi)  # psi = kappa / mu_k
    levels = np.array([25, 50, 100, 400])
    shifts = np.arange(8) / 8.0
    n = (levels[:, None] + shifts).ravel()
    out, _ = run(rheology, mu=mu_k,
                 h=HERTZ_TIME / np.repeat(6.0 * levels, shifts.size) / 1.87, dxi=1.0 / n,
                 nu=nu, theta_ratio=theta)
    beta = out[:, OUT_VC_END].reshape(levels.size, shifts.size)
    reference = beta[-1].mean()
    assert np.ptp(beta[-1]) < 2e-6, np.ptp(beta[-1])  # the reference's own spread
    worst = np.abs(beta[:-1] - reference).max(axis=1)
    order = -np.polyfit(np.log2(levels[:-1]), np.log2(worst), 1)[0]
    assert worst[-1] < 3e-5, worst
    assert order >= 1.8, (order, worst)


@pytest.mark.slow
def test_hypothesis_sweep_finite_and_passive():
    pytest.importorskip("hypothesis")
    from hypothesis import given, settings
    from hypothesis import strategies as st

    @settings(derandomize=True, max_examples=20, deadline=None)
    @given(psi=st.floats(0.1, 20.0), chi_ratio=st.floats(0.1, 2.0),
           Q1=st.floats(0.0, 1.0), Q2=st.floats(0.1, 10.0))
    def check(psi, chi_ratio, Q1, Q2):
        nu = 0.3
        kappa = 2.0 * (1.0 - nu) / (2.0 - nu)
        mu_t = 1.0 + chi_ratio
        tau_arm = Q1 / math.sqrt(15.0 / 32.0)
        out, _ = run_rows(KernelSpec(VERLET, True, 0, True, False, True), h=H, dxi=DXI,
                          g=(1.0 / Q2,), tau=(max(tau_arm, 1e-6),), nu=nu,
                          theta_ratio=1.0 / chi_ratio, mu=kappa / psi)
        assert np.all(np.isfinite(out))
        assert abs(out[0, OUT_VC_END]) <= 1.0 + 1e-9
        assert out[0, OUT_W_FRICTION] >= 0.0
        assert mu_t > 1.0

    check()


# ------------------------------------------------- the NumPy reference

def _scene(mu, material=None, v_x0=1.5):
    from vimpact import Material, Scene

    material = material or Material.prony(nu=0.3, G_inf=1e9, arms=[(1e9, 2e-6), (5e8, 2e-5)],
                                          eta0=300.0)
    return Scene(material, R=0.01, m=0.004, v_z0=1.0, v_x0=v_x0, omega0=0.0, mu=mu)


@pytest.mark.slow
@pytest.mark.parametrize("mu", [0.05, 0.3, 1.0])
def test_reference_with_friction_agrees_with_kernel(mu):
    """The engine (element kernel with friction) against the SI reference,
    which also checks |f_t| <= mu f_n per element at every step."""
    from tests.oracles.naive import naive_impact
    from vimpact import Numerics, simulate

    scene = _scene(mu)
    num = Numerics(steps=150, elements=30, continuum=False)
    res = simulate(scene, num)
    ref = naive_impact(scene, 150, 30)
    for key in ("e_z", "e_x", "beta_x", "t_contact"):
        assert math.isclose(getattr(res, key), ref[key], rel_tol=1e-8, abs_tol=1e-10), key


def test_reference_gross_slip_and_cone():
    """The SI reference alone: gross slip closed form and the cone check."""
    from tests.oracles.naive import naive_impact

    scene = _scene(0.02, v_x0=2.0)
    ref = naive_impact(scene, 120, 20)
    mu_t = 1.0 + scene.m * scene.R**2 / scene.Theta
    v_c_end = ref["v_x_end"] + scene.R * ref["omega_end"]
    predicted = scene.v_c0 - 0.02 * mu_t * (1.0 + ref["e_z"]) * scene.v_z0
    assert math.isclose(v_c_end, predicted, rel_tol=1e-10)
    assert ref["t_gross_slip"] >= ref["t_contact"] - scene.hertz.t_H / 100


# ---------------------------------------------- flat punch stick-slip

def flat_punch_oscillator(m, Theta, R, k_n, k_t, mu, v_z0, v_c0):
    """1-DOF normal oscillator ``m u'' = -k_n u`` (until ``u = 0``) carrying a
    tangential stick-slip oscillator: the contact spring ``s`` follows the
    contact point while ``|k_t s| <= mu k_n u`` and sits on the cone when
    slipping; ``v_c' = -k_t s / m_eff``. Solved with scipy, events at the
    switches. Returns ``v_c`` at the end of the contact."""
    from scipy.integrate import solve_ivp

    m_eff = 1.0 / (1.0 / m + R * R / Theta)
    w = math.sqrt(k_n / m)
    t_end = math.pi / w  # u = v_z0/w sin(w t)

    def u_of(t):
        return v_z0 / w * math.sin(w * t)

    def du_of(t):
        return v_z0 * math.cos(w * t)

    # state: stick (s, v_c) or slip (v_c, s = sign mu k_n u / k_t)
    # at first contact the cone is empty: slip unless the cone grows faster than
    # the spring is stretched (mu k_n v_z0 >= k_t |v_c0|)
    t, s, v_c = 0.0, 0.0, v_c0
    mode = "stick" if mu * k_n * v_z0 >= k_t * abs(v_c0) else "slip"
    sign = math.copysign(1.0, v_c0)
    while t < t_end * (1 - 1e-12):
        if mode == "stick":
            def rhs(t, y):
                return [y[1], -k_t * y[0] / m_eff]

            def ev(t, y):  # leaves the cone
                return mu * k_n * u_of(t) - abs(k_t * y[0])
            ev.terminal, ev.direction = True, -1
            sol = solve_ivp(rhs, (t, t_end), [s, v_c], events=ev, rtol=1e-12, atol=1e-14,
                            method="DOP853")
            t, (s, v_c) = sol.t[-1], sol.y[:, -1]
            if sol.status == 1:
                mode, sign = "slip", math.copysign(1.0, s)
        else:
            def rhs(t, y):
                return [-sign * mu * k_n * u_of(t) / m_eff]

            def ev(t, y):  # slip rate v_c - ds/dt changes sign: sticks again
                return sign * (y[0] - sign * mu * k_n * du_of(t) / k_t)
            ev.terminal, ev.direction = True, -1
            sol = solve_ivp(rhs, (t, t_end), [v_c], events=ev, rtol=1e-12, atol=1e-14,
                            method="DOP853")
            t, v_c = sol.t[-1], sol.y[0, -1]
            s = sign * mu * k_n * u_of(t) / k_t
            if sol.status == 1:
                mode = "stick"
    return v_c


@pytest.mark.slow
@pytest.mark.parametrize("mu", [0.1, 0.3, 3.0])
def test_flat_punch_is_a_stick_slip_oscillator(mu):
    """docs/physics.md#linear-model, docs/physics.md#coulomb-friction in the SI reference: a flat punch (every
    element enters at once and leaves together) with friction against the
    independent 1-DOF stick-slip oscillator."""
    from tests.oracles.naive import naive_impact
    from vimpact import Material, Scene

    G, nu, R, m = 1e9, 0.3, 0.01, 0.004
    scene = Scene(Material.elastic(nu=nu, G=G), R=R, m=m, v_z0=1.0, v_x0=0.8, omega0=0.0,
                  mu=mu)
    a0 = 0.5 * scene.hertz.a_H
    ref = naive_impact(scene, 1000, 200, flat_punch=a0)
    E_star = 2.0 * G / (1.0 - nu)
    k_n, k_t = 2.0 * a0 * E_star, 2.0 * a0 * 4.0 / (2.0 - nu) * G
    v_c = flat_punch_oscillator(m, scene.Theta, R, k_n, k_t, mu, 1.0, 0.8)
    assert math.isclose(ref["e_z"], 1.0, rel_tol=1e-6)
    v_c_ref = ref["v_x_end"] + R * ref["omega_end"]
    # measured at 1000 steps per t_H: 1e-14 (gross slip, mu = 0.1), 1e-7 (mu = 0.3),
    # 3.8e-6 (mu = 3: the contact slips out of stick in its last steps, and
    # without a dashpot the separation step is not weighted): relative to v_c0
    assert abs(v_c_ref - v_c) < 1e-5 * 0.8, (v_c_ref, v_c)


def test_single_scene_kernel_is_the_batch_row_bit_for_bit():
    """A single scene runs the serial impact kernel of its spec (no parallel launch);
    it must give exactly the batch kernel's row, trajectory included."""
    tau0, g, tau = RHEOLOGIES["prony_dashpot"]
    mu = np.array([0.05, 0.4, math.inf])
    out, rec = run("prony_dashpot", mu=mu, n_rec=50, rec_every=7)
    nu, theta_ratio = 0.3, 0.4  # run_rows' defaults
    kappa, mu_t = 2.0 * (1.0 - nu) / (2.0 - nu), 1.0 + 1.0 / theta_ratio
    n_elem = int(np.ceil(1.05 / DXI - 1e-9))
    max_steps = int(np.ceil(20.0 * HERTZ_TIME / H))
    impact = element_impact(spec_of("prony_dashpot"))
    for i in range(mu.size):
        o = np.zeros(out.shape[1])
        r = np.zeros(rec.shape[1:])
        impact(tau0, np.array(g), np.array(tau), kappa, mu_t, mu[i], H, n_elem, DXI, max_steps,
               r, 7, o)
        np.testing.assert_array_equal(o, out[i])
        np.testing.assert_array_equal(r, rec[i])
