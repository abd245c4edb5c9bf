"""Tests of vimpact.reference.closed_forms against independent oracles.

Oracles: the docs/physics.md#linear-model closed forms (atan2 / log forms, velocity
from the explicit solution), direct numerical integration of the ODEs written
here, quadrature, and the numbers docs/physics.md quotes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad, solve_ivp

from vimpact.model.hertz import HERTZ_TIME_FACTOR, Q1_PER_TAU
from vimpact.reference import closed_forms as analytic
from vimpact.reference.closed_forms import (
    hertz_time_factor_quadrature,
    kelvin_voigt_continuum,
    kelvin_voigt_small_damping_slope,
    linear_model,
    linear_model_zeta,
    linear_tangential_frequency,
)

PHYSICS_HERTZ_TIME = 2.9432751843   # docs/physics.md#hertz-scales
PHYSICS_KV_SLOPE = 1.8917            # docs/physics.md#kelvin-voigt-continuum, per tau/T
PHYSICS_KV_SLOPE_Q1 = 2.7630         # docs/physics.md#kelvin-voigt-continuum, per Q1


# ---------------------------------------------------------------- oracles

def physics_closed_form(zeta: float) -> tuple[float, float]:
    """docs/physics.md#linear-model formulas with omega0 = 1, as written there."""
    d = zeta
    if zeta < 1.0:
        wd = math.sqrt(1.0 - zeta**2)
        th = math.atan2(2.0 * d * wd, 2.0 * d**2 - 1.0)
        t = th / wd
        e = math.exp(-d * t) * abs(math.cos(th) - d / wd * math.sin(th))
    elif zeta == 1.0:
        t, e = 2.0, math.exp(-2.0)
    else:
        g = math.sqrt(zeta**2 - 1.0)
        l1, l2 = -d + g, -d - g
        a = 2.0 * d**2 - 1.0
        t = math.log((a + 2.0 * d * g) / (a - 2.0 * d * g)) / (2.0 * g)
        e = abs(l1 * math.exp(l1 * t) - l2 * math.exp(l2 * t)) / (2.0 * g)
    return t, e


def integrate_linear(zeta: float) -> tuple[float, float]:
    """u'' + 2 zeta u' + u = 0, u(0)=0, u'(0)=1, until u + 2 zeta u' = 0."""

    def rhs(t, y):
        return [y[1], -2.0 * zeta * y[1] - y[0]]

    def force(t, y):
        return y[0] + 2.0 * zeta * y[1]

    force.terminal = True
    force.direction = -1
    sol = solve_ivp(rhs, (0.0, 50.0), [0.0, 1.0], method="DOP853",
                    rtol=1e-13, atol=1e-15, events=force)
    assert sol.status == 1
    return float(sol.t_events[0][0]), abs(float(sol.y_events[0][0][1]))


def integrate_kelvin_voigt(q1: float) -> tuple[float, float, float]:
    """Section-5 ODE written directly: one right-hand side for both branches
    (it is C^1 across v = 0), started at u = 0, plain (u, v) variables."""
    th = q1 / Q1_PER_TAU

    def rhs(t, y):
        u, v = y
        if v >= 0.0:
            f = 1.25 * max(u, 0.0) ** 1.5 + 1.875 * th * math.sqrt(max(u, 0.0)) * v
        else:
            f = 1.25 * max(u + th * v, 0.0) ** 1.5
        return [v, -f]

    def end(t, y):
        return y[0] + th * y[1] if y[1] < 0.0 else 1.0

    def turn(t, y):
        return y[1]

    end.terminal = True
    end.direction = -1
    sol = solve_ivp(rhs, (0.0, 10.0), [0.0, 1.0], method="DOP853",
                    rtol=1e-13, atol=1e-16, events=[end, turn])
    assert sol.status == 1
    return (abs(float(sol.y_events[0][0][1])), float(sol.t_events[0][0]),
            float(sol.y_events[1][0][0]))


# ---------------------------------------------------------------- linear model

ZETAS = [0.05, 0.3, 0.7, 0.9, 0.999, 1.0, 1.001, 1.2, 2.0, 5.0]


@pytest.mark.parametrize("zeta", ZETAS)
def test_linear_model_against_direct_integration(zeta):
    t_ode, e_ode = integrate_linear(zeta)
    t, e = linear_model_zeta(zeta)
    assert t == pytest.approx(t_ode, abs=1e-8)
    assert e == pytest.approx(e_ode, abs=1e-8)


@settings(max_examples=200, deadline=None, database=None)
@given(st.one_of(st.floats(0.0, 0.999), st.floats(1.001, 10.0)))
def test_linear_model_against_physics_formulas(zeta):
    t_ref, e_ref = physics_closed_form(zeta)
    t, e = linear_model_zeta(zeta)
    assert t == pytest.approx(t_ref, rel=1e-10)
    assert e == pytest.approx(e_ref, rel=1e-10)
    # in every regime the force bracket is 1 at t*, so e = exp(-delta t*)
    assert e == pytest.approx(math.exp(-zeta * t_ref), rel=1e-10)


def test_linear_model_critical_value():
    t, e = linear_model_zeta(1.0)
    assert t == pytest.approx(2.0, abs=1e-15)
    assert e == pytest.approx(math.exp(-2.0), abs=1e-15)
    t, e = linear_model(3.0, 3.0)
    assert t == pytest.approx(2.0 / 3.0, abs=1e-15)


@pytest.mark.parametrize("zeta0", [1.0 / math.sqrt(2.0), 1.0, 1.0 - 1e-3, 1.0 + 1e-3])
def test_linear_model_continuous(zeta0):
    # zeta0 = 1: regimes meet; 1/sqrt(2): where the thesis's atan branch
    # switches; 1 +- 1e-3: edges of the near-critical series band.
    gaps = [1e-2, 1e-4, 1e-6, 1e-8]
    jumps = []
    for eps in gaps:
        below = np.array(linear_model_zeta(zeta0 - eps))
        above = np.array(linear_model_zeta(zeta0 + eps))
        jumps.append(np.abs(above - below).max())
    for eps, jump in zip(gaps, jumps):
        assert jump < 5.0 * eps  # |d/dzeta| of t* and e is below 2.5 here
    assert jumps[-1] < 1e-7
    assert jumps == sorted(jumps, reverse=True)


def test_linear_model_small_damping_limit():
    zetas = np.array([1e-2, 1e-4, 1e-6, 1e-9])
    t, e = linear_model_zeta(zetas)
    assert np.all(np.abs(t - math.pi) < 3.0 * zetas)
    assert np.all(np.abs(e - 1.0) < 4.0 * zetas)   # e = 1 - pi zeta + ...
    t, e = linear_model_zeta(0.0)
    assert t == pytest.approx(math.pi, abs=1e-15) and e == 1.0


def test_linear_model_units_and_vectorization():
    omega0 = np.array([[1.0], [10.0]])
    delta = np.array([0.5, 7.0, 10.0])  # zeta from 0.05 to 10, incl. 1
    t, e = linear_model(omega0, delta)
    assert t.shape == e.shape == (2, 3)
    for i in range(2):
        for j in range(3):
            tz, ez = physics_closed_form(delta[j] / omega0[i, 0])
            assert t[i, j] == pytest.approx(tz / omega0[i, 0], rel=1e-10)
            assert e[i, j] == pytest.approx(ez, rel=1e-10)
    t, e = linear_model(2.0, 1.0)
    assert type(t) is float and type(e) is float


def test_linear_tangential_frequency():
    m, R, k = 2.0, 0.1, 800.0
    Theta = 0.4 * m * R**2
    # solid sphere: effective mass 1/(1/m + R^2/Theta) = 2/7 m
    assert linear_tangential_frequency(k, m, R, Theta) == pytest.approx(
        math.sqrt(k / (2.0 / 7.0 * m)), rel=1e-14)
    assert linear_tangential_frequency(k, m, R, 1e30) == pytest.approx(math.sqrt(k / m), rel=1e-14)


# ---------------------------------------------------------------- Hertz time

def test_hertz_time_factor_quadrature():
    value = hertz_time_factor_quadrature()
    assert value == pytest.approx(HERTZ_TIME_FACTOR, abs=1e-10)
    assert value == pytest.approx(PHYSICS_HERTZ_TIME, abs=1e-10)


# ---------------------------------------------------------------- Kelvin-Voigt

def test_kelvin_voigt_elastic_limit():
    e_z, t_c, u_max = kelvin_voigt_continuum(0.0)
    assert e_z == pytest.approx(1.0, abs=1e-9)
    assert t_c == pytest.approx(PHYSICS_HERTZ_TIME, abs=1e-9)
    assert u_max == pytest.approx(1.0, abs=1e-9)
    # energy, kernel units: kinetic v^2/2, Hertz potential u^(5/2)/2
    assert 0.5 * u_max**2.5 == pytest.approx(0.5, abs=1e-9)      # at the turning point
    assert 0.5 * e_z**2 == pytest.approx(0.5, abs=1e-9)          # after the impact


def test_kelvin_voigt_slope_value():
    # independent of scipy.special.beta: B(3/5, 3/2) by quadrature
    b, _ = quad(lambda s: 1.0, 0.0, 1.0, weight="alg", wvar=(-0.4, 0.5))
    slope = kelvin_voigt_small_damping_slope()
    assert slope == pytest.approx(1.5 * b, rel=1e-12)
    assert slope == pytest.approx(PHYSICS_KV_SLOPE, abs=6e-5)
    assert slope / Q1_PER_TAU == pytest.approx(PHYSICS_KV_SLOPE_Q1, abs=6e-5)


def test_kelvin_voigt_small_damping():
    slope = 1.5 * math.gamma(0.6) * math.gamma(1.5) / math.gamma(2.1)
    q1 = np.array([1e-4, 1e-3])
    e_z = kelvin_voigt_continuum(q1).e_z
    rel_err = np.abs((1.0 - e_z) / (q1 / Q1_PER_TAU) / slope - 1.0)
    assert rel_err[1] < 5e-3
    # second-order term: error shrinks linearly with q1
    assert 8.0 < rel_err[1] / rel_err[0] < 12.0


def test_kelvin_voigt_monotone_and_bounded():
    q1 = np.geomspace(1e-3, 10.0, 9)
    e_z, t_c, u_max = kelvin_voigt_continuum(q1)
    assert e_z.shape == q1.shape
    assert np.all((e_z > 0.0) & (e_z < 1.0))
    assert np.all(np.diff(e_z) < 0.0)
    assert np.all(np.diff(u_max) < 0.0) and np.all(u_max < 1.0)
    assert np.all(t_c < HERTZ_TIME_FACTOR)


@pytest.mark.parametrize("q1", [0.05, 1.0, 5.0])
def test_kelvin_voigt_against_direct_integration(q1):
    ref = integrate_kelvin_voigt(q1)
    got = kelvin_voigt_continuum(q1)
    assert got.e_z == pytest.approx(ref[0], abs=1e-9)
    assert got.t_contact_over_T == pytest.approx(ref[1], abs=1e-8)
    assert got.u_max_over_d == pytest.approx(ref[2], abs=1e-9)


def test_kelvin_voigt_tolerance_convergence():
    q1 = np.array([1e-3, 0.1, 1.0, 10.0])
    fine = kelvin_voigt_continuum(q1, rtol=1e-12)
    coarse = kelvin_voigt_continuum(q1, rtol=1e-10)
    assert np.abs(fine.e_z - coarse.e_z).max() < 1e-9
    assert np.abs(fine.u_max_over_d - coarse.u_max_over_d).max() < 1e-9
    assert np.abs(fine.t_contact_over_T - coarse.t_contact_over_T).max() < 1e-8


def test_kelvin_voigt_scalar_returns_floats():
    res = kelvin_voigt_continuum(0.5)
    assert all(type(x) is float for x in res)


# ---------------------------------------------------------------- bad input

@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: linear_model(0.0, 1.0), "omega0"),
        (lambda: linear_model(-1.0, 1.0), "omega0"),
        (lambda: linear_model(np.inf, 1.0), "omega0"),
        (lambda: linear_model(1.0, -0.1), "delta"),
        (lambda: linear_model(1.0, [0.1, np.nan]), "delta"),
        (lambda: linear_model_zeta(-1.0), "zeta"),
        (lambda: linear_tangential_frequency(1.0, 0.0, 1.0, 1.0), "m"),
        (lambda: linear_tangential_frequency(1.0, 1.0, 1.0, -1.0), "Theta"),
        (lambda: kelvin_voigt_continuum(-1e-3), "q1"),
        (lambda: kelvin_voigt_continuum([0.1, np.nan]), "q1"),
        (lambda: kelvin_voigt_continuum("x"), "q1"),
        (lambda: kelvin_voigt_continuum(1.0, rtol=1e-2), "rtol"),
    ],
)
def test_bad_input_names_parameter(call, name):
    with pytest.raises(ValueError, match=rf"^{name} must"):
        call()


def test_public_api():
    for name in analytic.__all__:
        assert hasattr(analytic, name)
