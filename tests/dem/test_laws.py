"""The DEM codes' one-contact laws against closed forms (vimpact.dem.laws)."""

import math

import numpy as np
import pytest

from vimpact.dem import laws, linear
from vimpact.dem.mfix import _beta as mfix_beta
from vimpact.dem.yade import yade_law
from vimpact.reference.closed_forms import linear_model_zeta


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.3, 0.7, 0.999, 1.0, 1.5, 4.0])
def test_linear_law_ending_at_zero_force_is_the_closed_form(zeta):
    e, _, t = laws.linear_spring_dashpot(zeta, "force")
    ref = linear_model_zeta(zeta)
    assert e == pytest.approx(float(ref.e), rel=1e-8, abs=1e-12)
    assert t == pytest.approx(float(ref.t_star), rel=1e-8)


#: (zeta, w_t, zeta_t): the tangential oscillator below, at, just around and above critical
#: damping, without damping and without a spring, under normal contacts from undamped to
#: critically damped (Yade's range: zeta < 1)
CLOSED_FORM_CASES = [(0.0, 1.7, 0.0), (0.05, 0.5, 0.3), (0.3, 3.0, 0.8), (0.7, 1.0, 0.9999999),
                     (0.999, 1.0, 1.0), (0.9995, 1.7, 1.0000001), (1.0, 0.5, 3.0),
                     (0.3, 0.0, 0.0), (0.5, 5.0, 1.3)]


@pytest.mark.parametrize("zeta, w_t, zeta_t", CLOSED_FORM_CASES)
def test_linear_law_ending_at_zero_force_in_closed_form_is_the_ode(zeta, w_t, zeta_t):
    """The closed form Yade's fit uses is the ODE integrated by DOP853 (rtol 1e-11) to that
    integration's error, normal and tangential."""
    ode = laws.linear_spring_dashpot(zeta, "force", (w_t, zeta_t))
    e, beta, t = laws.linear_spring_dashpot_force_end(zeta, (w_t, zeta_t))
    assert e == pytest.approx(ode[0], abs=1e-8)
    assert beta == pytest.approx(ode[1], abs=1e-8)
    assert t == pytest.approx(ode[2], rel=1e-8)
    assert math.isnan(laws.linear_spring_dashpot_force_end(zeta)[1])


def test_linear_tangential_closed_form_under_strong_damping():
    """At zeta = 30 the ODE's end-of-contact event drifts (1e-5 with a fast tangential
    oscillator); the tangential velocity integrated tightly up to the closed-form contact
    time is the closed form's, in every damping regime of the oscillator."""
    from scipy.integrate import solve_ivp

    for w_t, zeta_t in ((10.0, 0.0), (3.0, 1.3), (1.0, 1.0), (10.0, 20.0)):
        _, beta, t = laws.linear_spring_dashpot_force_end(30.0, (w_t, zeta_t))
        sol = solve_ivp(lambda _, y: [y[1], -(w_t * w_t * y[0] + 2.0 * zeta_t * w_t * y[1])],
                        (0.0, t), [0.0, 1.0], method="DOP853", rtol=1e-13, atol=1e-16)
        assert beta == pytest.approx(-sol.y[1, -1], abs=1e-13)


@pytest.mark.parametrize("e_in", [0.1, 0.5, 0.9, 0.999])
def test_linear_law_ending_at_zero_overlap_restitutes_its_input(e_in):
    """The DEM formula zeta = |ln e| / sqrt(pi^2 + ln^2 e) with the contact ending at zero
    overlap gives e = exp(-zeta pi / sqrt(1 - zeta^2)) = e_in after t = pi / omega_d."""
    zeta = laws.zeta_of_restitution(e_in)
    e, _, t = laws.linear_spring_dashpot(zeta, "overlap")
    assert e == pytest.approx(e_in, rel=1e-9)
    assert t == pytest.approx(math.pi / math.sqrt(1 - zeta**2), rel=1e-9)


def test_elastic_hertz_law_is_hertz():
    e, t = laws.viscoelastic_hertz_e(0.0)
    assert e == pytest.approx(1.0, abs=1e-9)
    assert t == pytest.approx(2.9432751843, rel=1e-8)


def test_viscoelastic_hertz_small_damping_slope():
    """1 - e = 1.8917 alpha to first order (docs/physics.md#kelvin-voigt-continuum), with the second-order
    term visible as a linear trend of the slope in alpha."""
    alphas = np.array([1e-5, 2e-5, 4e-5])
    slopes = np.array([(1 - laws.viscoelastic_hertz_e(a)[0]) / a for a in alphas])
    intercept = np.polyfit(alphas, slopes, 1)[1]
    assert intercept == pytest.approx(1.8917, abs=2e-4)
    assert laws.SMALL_DAMPING_SLOPE == pytest.approx(1.8917, abs=1e-4)


def test_clipping_only_raises_restitution():
    for a in (0.01, 0.3, 3.0):
        assert laws.viscoelastic_hertz_e(a, True)[0] > laws.viscoelastic_hertz_e(a, False)[0]


def test_tabulated_master_curve_equals_direct_solves():
    alphas = np.geomspace(2e-7, 500.0, 23)
    direct = [laws.viscoelastic_hertz_e(a)[0] for a in alphas]
    np.testing.assert_allclose(laws.viscoelastic_hertz_curve(alphas), direct, atol=2e-7)


@pytest.mark.parametrize("et", [0.4, 0.9, 0.05])
def test_yade_tangential_restitution_is_et_for_solid_spheres(et):
    """Yade's ks, cs use the contact-point mass 2/7 m of solid spheres (mass factor 3.5):
    the tangential oscillator then completes half a damped period in tc, so beta = et when
    the normal contact lasts tc too (en = 1: no damping, the force ends with the overlap)."""
    e, beta, t = yade_law(1e-4, 1.0, et, 1.0, 3.5)
    assert e == pytest.approx(1.0, abs=1e-9) and t == pytest.approx(1e-4, rel=1e-8)
    assert beta == pytest.approx(et, rel=1e-8)


def test_linear_tangential_undamped_closed_form():
    """Undamped tangential oscillator w_t over a normal contact of pi / omega_d: beta = -cos(w_t t)."""
    en = 0.6
    zeta = laws.zeta_of_restitution(en)
    t = math.pi / math.sqrt(1 - zeta**2)
    for w_t in (0.5, 1.0, 1.7):
        assert linear.tangential_beta(en, w_t, 0.0) == pytest.approx(-math.cos(w_t * t), abs=1e-8)


def test_mfix_beta_is_monotonic_in_the_damping_factor():
    b = [mfix_beta(0.7, f, 3.5) for f in (0.0, 0.2, 0.5, 1.0)]
    assert b[0] == pytest.approx(-math.cos(math.sqrt(2 / 7 * 3.5) * math.pi /
                                           math.sqrt(1 - laws.zeta_of_restitution(0.7)**2)),
                                 abs=1e-8)
    assert all(x > y for x, y in zip(b, b[1:]))


# ---- the stepped oblique laws with Coulomb friction -------------------------

@pytest.mark.parametrize("alpha", [0.01, 0.1])
def test_stepped_lammps_law_in_stick_is_the_stick_ode_and_converges(alpha):
    """Without friction the stepped Hertz-Mindlin law (LAMMPS' velocity Verlet) is the
    stick ODE integrated by DOP853, to first order in the step."""
    e_ref, b_ref = laws.viscoelastic_hertz_mindlin(alpha, 0.7, 0.4, 3.5)
    err = []
    for steps in (500, laws.FRICTION_STEPS, 8000):
        e, b = laws.hertz_mindlin_coulomb(alpha, 0.7, 0.4, 3.5, math.inf, 1.0, steps)
        assert float(e) == pytest.approx(e_ref, abs=1e-5)
        err.append(abs(float(b) - b_ref))
    assert err[1] < 5e-4
    assert err[2] < err[1] or err[2] < 1e-5


def test_stepped_lammps_law_in_gross_slip_is_the_rigid_body_closed_form():
    """Sliding throughout (grazing impacts): F_x = mu F_z at every step, so
    v_c,end = v_c0 - mu F (1 + e) v_z0 (docs/physics.md#coulomb-friction)."""
    mu, F = 0.3, 3.5
    w0 = np.array([5.0, 10.0, 20.0])
    e, beta = laws.hertz_mindlin_coulomb(np.full(3, 0.05), 0.7, 0.4, F, mu, w0)
    assert beta == pytest.approx(mu * F * (1 + e) / w0 - 1, abs=1e-9)


def test_stepped_yade_law_in_stick_is_yade_law_and_slides_as_a_rigid_body():
    en, et, F = 0.7, 0.5, 3.5
    e_ref, b_ref, _ = yade_law(1.0, en, et, 1.0, F)
    kn = math.pi**2 + math.log(en)**2
    ks = 2 / 7 * (math.pi**2 + math.log(et)**2)
    zeta = -2 * math.log(en) / (2 * math.sqrt(kn))
    w_t = math.sqrt(ks * F)
    zeta_t = -4 / 7 * math.log(et) * F / (2 * w_t)
    e, b = laws.yade_coulomb(zeta, w_t / math.sqrt(kn), zeta_t, F, math.inf, np.array([1.0]))
    assert float(e[0]) == pytest.approx(e_ref, abs=5e-4)
    assert float(b[0]) == pytest.approx(b_ref, abs=5e-4)
    # no damping: the force is mu F_z throughout when sliding (Yade's viscous tangential
    # force acts only below the cap, so the closed form needs zeta = zeta_t = 0)
    w0 = np.array([5.0, 10.0, 20.0])
    e, b = laws.yade_coulomb(0.0, w_t / math.sqrt(kn), 0.0, F, 0.3, w0)
    assert b == pytest.approx(0.3 * F * (1 + e) / w0 - 1, abs=1e-9)


def test_stepped_liggghts_and_mercurydpm_laws_slide_as_rigid_bodies():
    """Gross slip without damping: v_c,end = v_c0 - mu F (1 + e) v_z0 for both laws
    (with damping neither is exact: LIGGGHTS caps with |F_n|, which pulls at the end of a
    damped contact, and both add their tangential dashpot uncapped while the spring is
    below the cap, as Yade does)."""
    F, mu = 3.5, 0.2
    w0 = np.array([5.0, 10.0])
    e, b = laws.liggghts_coulomb(1.0, 1.0, 0.0, F, mu, w0)
    assert e == pytest.approx(1.0, abs=1e-6)
    assert b == pytest.approx(mu * F * (1 + e) / w0 - 1, abs=1e-9)
    e, b = laws.mercury_mindlin_coulomb(0.0, 1.0, 0.0, F, mu, w0)
    assert b == pytest.approx(mu * F * (1 + e) / w0 - 1, abs=1e-9)


def test_stepped_liggghts_normal_law_is_tsuji_hertz():
    e, _ = laws.liggghts_coulomb(0.7, 1.0, 0.5, 3.5, math.inf, np.array([1.0]))
    assert float(e[0]) == pytest.approx(laws.tsuji_hertz_e(0.7), abs=1e-5)


def test_mfix_law_sticks_like_the_ode_and_slides_like_coulomb():
    """MFiX's stepped LSD law with friction: in stick it converges to the linear
    spring-dashpot ODE (an independent integrator); sliding through the whole contact of
    an undamped normal law it gives Coulomb's ``beta = -1 + 2 mu F / w0``."""
    F, kt = 3.5, 2.0 / 7.0
    zeta = laws.zeta_of_restitution(0.6)
    w_t, zeta_t = math.sqrt(kt * F), 0.5 * zeta * math.sqrt(F / kt)
    ref = laws.linear_spring_dashpot(zeta, "overlap", (w_t, zeta_t))
    e, b = laws.mfix_coulomb(zeta, w_t, zeta_t, F, math.inf, np.array([0.3, 2.0]))
    assert e == pytest.approx(ref[0], abs=5e-4) and b == pytest.approx(ref[1], abs=5e-4)
    mu, w0 = 0.3, np.tan(np.radians([75.0, 85.0]))
    _, b = laws.mfix_coulomb(0.0, w_t, zeta_t, F, mu, w0)
    assert b == pytest.approx(-1.0 + 2.0 * mu * F / w0, abs=2e-3)


def test_master_curve_is_scipys_cubic_spline_bit_for_bit():
    """The stored spline coefficients are those of scipy's not-a-knot ``CubicSpline``
    through the tabulated points, and their evaluation (without scipy) gives scipy's
    numbers bit for bit: at random points, the breakpoints, the ends and just outside."""
    from scipy.interpolate import CubicSpline

    from vimpact.dem import _hertz_table as tab

    breaks, c = laws._master_curve()
    ref = CubicSpline(np.linspace(*tab.LOG_ALPHA, tab.N), np.array(tab.E_CLIPPED))
    np.testing.assert_array_equal(breaks, ref.x)
    np.testing.assert_array_equal(c, ref.c)
    x = np.concatenate([np.random.default_rng(7).uniform(-7.0, 3.0, 20000), breaks,
                        np.nextafter(breaks, -np.inf), [-7.0 - 1e-12, 3.0 + 1e-12],
                        np.log10(np.geomspace(1e-7, 1e3, 5001))])
    np.testing.assert_array_equal(laws._spline_at(breaks, c, x), ref(x))
    alphas = np.geomspace(1e-7, 1e3, 301)
    np.testing.assert_array_equal(laws.viscoelastic_hertz_curve(alphas), ref(np.log10(alphas)))
