"""The continuum (1-DOF) normal Kelvin-Voigt kernel, vimpact.kernels.continuum_kv.

Oracles: the scipy DOP853 solution of the same ODE (analytic.kelvin_voigt_continuum),
the Hertz contact time by quadrature, the first-order damping slope, the
kernel's own convergence in rtol, and the docs/physics.md#kelvin-voigt-continuum formulas for
force and contact half-width along a recorded trajectory.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vimpact.kernels import continuum_kv as C
from vimpact.kernels.continuum_kv import kv_normal_batch, kv_normal_impact
from vimpact.kernels.elements import (
    N_OUT,
    N_REC,
    OUT_B_MAX,
    OUT_N_REC,
    OUT_STATUS,
    OUT_STEPS,
    OUT_T_CONTACT,
    OUT_U_MAX,
    OUT_VC_END,
    OUT_VZ_END,
    REC_B,
    REC_FX,
    REC_FZ,
    REC_T,
    REC_U,
    REC_V,
    REC_VC,
    STATUS_NON_FINITE,
    STATUS_OK,
    STATUS_TIME_LIMIT,
)
from vimpact.model.hertz import HERTZ_TIME_FACTOR, Q1_PER_TAU
from vimpact.reference.closed_forms import (
    hertz_time_factor_quadrature,
    kelvin_voigt_continuum,
    kelvin_voigt_small_damping_slope,
)

MAX_STEPS = 100_000
NO_REC = np.zeros((0, N_REC))


def run(tau0, rtol, max_steps=MAX_STEPS):
    out = np.full(N_OUT, -99.0)
    n = kv_normal_impact(tau0, rtol, max_steps, NO_REC, 1, out)
    assert n == 0 == out[OUT_N_REC]
    return out


# ---- the scipy reference --------------------------------------------------------------

@pytest.mark.parametrize("q1", [1e-5, 1e-3, 0.03, 0.3, 1.0, 3.0, 10.0, 100.0])
def test_agrees_with_scipy_reference(q1):
    ref = kelvin_voigt_continuum(q1, rtol=1e-12)
    out = run(q1 / Q1_PER_TAU, 1e-12)
    assert out[OUT_STATUS] == STATUS_OK
    assert out[OUT_VZ_END] < 0.0
    assert abs(-out[OUT_VZ_END] - ref.e_z) < 1e-10 * max(ref.e_z, 1e-2)
    assert abs(out[OUT_T_CONTACT] - ref.t_contact_over_T) < 1e-10
    assert abs(out[OUT_U_MAX] - ref.u_max_over_d) < 1e-10
    assert out[OUT_B_MAX] == math.sqrt(out[OUT_U_MAX])
    assert out[OUT_VC_END] == 0.0


def test_elastic_is_hertz():
    out = run(0.0, 1e-12)
    assert out[OUT_STATUS] == STATUS_OK
    assert abs(out[OUT_VZ_END] + 1.0) < 1e-12
    assert abs(out[OUT_T_CONTACT] - hertz_time_factor_quadrature()) < 1e-10
    assert abs(out[OUT_T_CONTACT] - HERTZ_TIME_FACTOR) < 1e-10
    assert abs(out[OUT_U_MAX] - 1.0) < 1e-12
    assert abs(out[OUT_B_MAX] - 1.0) < 1e-12


def test_small_damping_slope():
    """(1 - e_z) / tau0 -> 1.5 B(3/5, 3/2) = 1.8917 (docs/physics.md#kelvin-voigt-continuum),
    linearly in tau0."""
    slope = kelvin_voigt_small_damping_slope()
    assert abs(slope - 1.8917) < 1e-4
    s = {tau: (1.0 + run(tau, 1e-13)[OUT_VZ_END]) / tau for tau in (1e-4, 2e-4)}
    for tau, si in s.items():
        assert abs(si - slope) < 4.0 * tau  # second-order term is about -2.93 tau0
    assert abs(2.0 * s[1e-4] - s[2e-4] - slope) < 1e-6  # Richardson: O(tau0^2)


@pytest.mark.parametrize("q1", [0.1, 10.0])
def test_error_proportional_to_rtol(q1):
    tau0 = q1 / Q1_PER_TAU
    ref = run(tau0, 1e-13)
    cols = [OUT_VZ_END, OUT_T_CONTACT, OUT_U_MAX]
    errs, steps = [], []
    for rtol in (1e-4, 1e-6, 1e-8):
        out = run(tau0, rtol)
        assert out[OUT_STATUS] == STATUS_OK
        err = max(abs(out[c] / ref[c] - 1.0) for c in cols)
        assert 1e-2 * rtol < err < 10.0 * rtol
        errs.append(err)
        steps.append(out[OUT_STEPS])
    assert errs[0] > 10.0 * errs[1] > 100.0 * errs[2]
    # fifth order: steps ~ rtol^(-1/5), about 2.5 per factor 100
    assert steps[0] < steps[1] < steps[2] < 8.0 * steps[0]


def test_steps_are_fifth_order():
    """Fixed steps on the loading branch: error of the step map ~ h^5 (global)."""
    tau0 = 0.5
    sig_end = 0.8

    def integrate(n):
        h = sig_end / n
        s, v, t = 0.0, 1.0, 0.0
        f = C._rhs(s, v, tau0, False)
        for _ in range(n):
            r = C._dp_step(s, v, t, *f, h, tau0, False)
            s, v, t = r[:3]
            f = r[3:6]
        return np.array([s, v, t])

    ref = integrate(4096)
    e = [np.max(np.abs(integrate(n) - ref)) for n in (8, 16, 32)]
    ratios = [e[0] / e[1], e[1] / e[2]]
    for r in ratios:
        assert 25.0 < r < 40.0  # 2^5 = 32


# ---- heavy damping, limits, status ---------------------------------------------------

@pytest.mark.parametrize("q1", [1e3, 1e5, 1e8])
@pytest.mark.parametrize("rtol", [1e-2, 1e-6, 1e-10])
def test_heavy_damping_finishes(q1, rtol):
    tau0 = q1 / Q1_PER_TAU
    out = run(tau0, rtol)
    assert out[OUT_STATUS] == STATUS_OK
    assert out[OUT_STEPS] < 2000
    # viscous limit: u_max -> (4 / (5 tau0))^(2/3), e_z -> u_max / tau0
    u_visc = (0.8 / tau0) ** (2.0 / 3.0)
    assert abs(out[OUT_U_MAX] / u_visc - 1.0) < 0.2
    assert abs(-out[OUT_VZ_END] * tau0 / out[OUT_U_MAX] - 1.0) < 0.2


def test_heavy_damping_against_scipy_reference():
    q1 = 1e4
    ref = kelvin_voigt_continuum(q1, rtol=1e-12)
    out = run(q1 / Q1_PER_TAU, 1e-12)
    assert abs(-out[OUT_VZ_END] / ref.e_z - 1.0) < 1e-9
    assert abs(out[OUT_U_MAX] / ref.u_max_over_d - 1.0) < 1e-10
    assert abs(out[OUT_T_CONTACT] - ref.t_contact_over_T) < 1e-6  # reference's own limit


def test_restitution_decreases_with_damping():
    q1 = np.logspace(-4, 4, 41)
    out = np.zeros((q1.size, N_OUT))
    kv_normal_batch(q1 / Q1_PER_TAU, 1e-8, MAX_STEPS, out)
    assert np.all(out[:, OUT_STATUS] == STATUS_OK)
    assert np.all(np.diff(-out[:, OUT_VZ_END]) < 0.0)
    assert np.all(np.diff(out[:, OUT_U_MAX]) < 0.0)


def test_time_limit():
    out = run(1.0, 1e-8, max_steps=5)
    assert out[OUT_STATUS] == STATUS_TIME_LIMIT
    assert out[OUT_STEPS] == 5


@pytest.mark.parametrize("tau0", [-1.0, math.nan, math.inf])
def test_invalid_tau0(tau0):
    out = run(tau0, 1e-8)
    assert out[OUT_STATUS] == STATUS_NON_FINITE
    assert math.isnan(out[OUT_VZ_END])


# ---- batch and trajectory ------------------------------------------------------------

def test_batch_equals_single_calls():
    tau0 = np.concatenate([[0.0], np.logspace(-6, 8, 57)])
    for rtol in (1e-4, 1e-11):
        out = np.zeros((tau0.size, N_OUT))
        kv_normal_batch(tau0, rtol, MAX_STEPS, out)
        single = np.array([run(t, rtol) for t in tau0])
        assert np.array_equal(out, single)


@pytest.mark.parametrize("q1, rec_every", [(0.0, 1), (0.3, 1), (30.0, 3)])
def test_trajectory_record(q1, rec_every):
    tau0 = q1 / Q1_PER_TAU
    rec = np.full((10_000, N_REC), np.nan)
    out = np.zeros(N_OUT)
    n = kv_normal_impact(tau0, 1e-10, MAX_STEPS, rec, rec_every, out)
    plain = run(tau0, 1e-10)
    assert np.array_equal(np.delete(out, OUT_N_REC), np.delete(plain, OUT_N_REC))
    steps = int(out[OUT_STEPS])
    assert n == (steps - 1) // rec_every + 1 == out[OUT_N_REC]  # last step: end row
    r = rec[:n]
    assert np.all(np.isnan(rec[n:]))
    # end state: end of contact
    assert r[-1, REC_T] == out[OUT_T_CONTACT]
    assert r[-1, REC_V] == out[OUT_VZ_END]
    assert r[-1, REC_FZ] == 0.0 and r[-1, REC_B] == 0.0
    assert abs(r[-1, REC_U] + tau0 * r[-1, REC_V]) < 1e-12
    assert np.all(r[:, REC_VC] == 0.0) and np.all(r[:, REC_FX] == 0.0)
    assert np.all(np.diff(r[:, REC_T]) > 0.0)
    assert np.max(r[:, REC_U]) <= out[OUT_U_MAX]
    assert np.max(r[:, REC_B]) <= out[OUT_B_MAX]
    # docs/physics.md#kelvin-voigt-continuum: b = sqrt(min(u, u + tau v)), F by branch
    u, v, b, F = r[:, REC_U], r[:, REC_V], r[:, REC_B], r[:, REC_FZ]
    w = np.minimum(u, u + tau0 * v)
    assert np.allclose(b * b, w, rtol=1e-12, atol=1e-14)
    F_ref = np.where(v >= 0.0, 1.25 * u**1.5 + 1.875 * tau0 * np.sqrt(u) * v,
                     1.25 * np.maximum(w, 0.0) ** 1.5)
    assert np.allclose(F, F_ref, rtol=1e-10, atol=1e-13)
    # the record follows the ODE: dv/dt = -F (trapezoid rule on the recorded rows)
    dv = np.diff(v)
    dv_ref = -0.5 * (F[1:] + F[:-1]) * np.diff(r[:, REC_T])
    assert np.max(np.abs(dv - dv_ref)) < 0.05 * np.max(np.abs(dv))


def test_full_record_buffer_keeps_the_end_state():
    rec = np.zeros((4, N_REC))
    out = np.zeros(N_OUT)
    n = kv_normal_impact(1.0, 1e-8, MAX_STEPS, rec, 1, out)
    assert n == 4 == out[OUT_N_REC]
    assert out[OUT_STEPS] > 4
    assert rec[3, REC_T] == out[OUT_T_CONTACT] and rec[3, REC_V] == out[OUT_VZ_END]
    assert np.all(np.diff(rec[:, REC_T]) > 0.0)


@pytest.mark.parametrize("tau0", [0.0, 0.1, 10.0, 1000.0])
@pytest.mark.parametrize("unloading", [False, True])
def test_event_located_to_rounding(tau0, unloading):
    """The re-taken step ends with the event component zero to a few ulp of its length."""
    comp = 0 if unloading else 1
    if unloading:  # an unloading state that reaches w = 0 soon
        s, v, t = (0.05, -1e-3, 1.0) if tau0 > 100.0 else (0.8, -0.1, 1.0)
    else:
        s, v, t = 0.0, 1.0, 0.0
    f = C._rhs(s, v, tau0, unloading)
    sig, h = 0.0, 0.02
    for _ in range(100_000):
        r = C._dp_step(s, v, t, *f, h, tau0, unloading)
        if r[comp] <= 0.0:
            break
        s, v, t = r[:3]
        f = r[3:6]
        sig += h
    else:
        pytest.fail("no event")
    hp, *y = C._locate(s, v, t, *f, sig, h, tau0, unloading, comp, *r[:6])
    assert 0.0 < hp <= h
    assert abs(y[comp]) <= 4.0 * abs(y[3 + comp]) * np.spacing(sig + hp) + 1e-300
    # the returned state is the Runge-Kutta step of that length
    assert tuple(y) == C._dp_step(s, v, t, *f, hp, tau0, unloading)[:6]
