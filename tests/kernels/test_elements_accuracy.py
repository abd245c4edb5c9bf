"""Accuracy of the element kernel at kernel level (own ``h``, ``dxi``, ``n_elem``).

Oracles, none produced by the kernel run under test:
- convergence trends: the error against a much finer run falls with the
  observed order asked for under joint refinement of steps and elements;
- the Kelvin-Voigt continuum closed form (docs/physics.md#kelvin-voigt-continuum) for e_z;
- the e_x jitter: a converged method gives nearly the same e_x for step
  counts a few per cent apart (the spread measures the error that is not
  smooth in ``h``; docs/physics.md#energy-and-passivity makes e_x independent of ``v_c0``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vimpact.kernels.elements import (
    N_OUT,
    N_REC,
    OUT_STATUS,
    OUT_VC_END,
    OUT_VZ_END,
    STATUS_OK,
    VERLET,
    KernelSpec,
    element_kernel,
)

HERTZ_TIME = 2.9432751843  # t_H / T, docs/physics.md#hertz-scales
Q1_PER_TAU = math.sqrt(15.0 / 32.0)  # docs/physics.md#dimensionless-parameters


def run_rows(spec: KernelSpec, *, h, dxi, tau0=0.0, g=(), tau=(), nu=0.3, theta_ratio=0.4,
             mu=math.inf, row_width=1.05, max_time=20.0, n_rec=0, rec_every=1):
    """Run the kernel ``spec`` on rows built here (kernel units of
    :mod:`vimpact.kernels.elements`); ``h``, ``dxi``, ``tau0``, ``mu`` broadcast
    over rows, ``g``, ``tau`` are the arms shared by all rows. ``theta_ratio =
    inf`` is a sphere without rotation. Returns ``(out, rec)``."""
    h, dxi, tau0, mu = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(x, dtype=float)) for x in (h, dxi, tau0, mu)))
    n = h.size
    g = np.tile(np.asarray(g, dtype=float), (n, 1))
    tau = np.tile(np.asarray(tau, dtype=float), (n, 1))
    kappa = np.full(n, 2.0 * (1.0 - nu) / (2.0 - nu))
    mu_t = np.full(n, 1.0 + 1.0 / theta_ratio)
    n_elem = np.ceil(row_width / dxi - 1e-9).astype(np.int64)
    max_steps = np.ceil(max_time * HERTZ_TIME / h).astype(np.int64)
    out = np.zeros((n, N_OUT))
    rec = np.zeros((n, n_rec, N_REC))
    element_kernel(spec)(tau0.copy(), g, tau, np.full(n, g.shape[1], dtype=np.int64), kappa, mu_t,
                         mu.copy(), h.copy(), n_elem, dxi.copy(), max_steps, rec, rec_every, out)
    assert (out[:, OUT_STATUS] == STATUS_OK).all(), out[:, OUT_STATUS]
    return out, rec


def observed_order(values, ref, ratio=2.0):
    """Orders between successive refinements of the error against ``ref``."""
    err = np.abs(np.asarray(values) - ref)
    return np.log(err[:-1] / err[1:]) / np.log(ratio), err


def fitted_order(values, ref, ratio=2.0):
    """Least-squares slope of ``-log(error)`` over the refinement levels: the
    observed order of a ladder whose error is not smooth level by level (the
    element spacing moves entry and exit events across steps)."""
    err = np.abs(np.asarray(values) - ref)
    levels = np.arange(err.size) * math.log(ratio)
    return -np.polyfit(levels, np.log(err), 1)[0], err


KV = KernelSpec(VERLET, True, 0, False, True)
ELASTIC = KernelSpec(VERLET, True, 0, False, False)


def test_ex_jitter_is_gone():
    """Step counts within +-5 % of 1400 per t_H (200 elements per a_H): the
    spread of e_x is far below the smooth error it used to exceed (3e-5 on
    main before the partial-contact weighting, measured by
    benchmarks/element_orders.py)."""
    N = np.arange(1330, 1471, 10)
    tau0 = 0.3 / Q1_PER_TAU
    out, _ = run_rows(KV, h=HERTZ_TIME / N / 1.87, dxi=1.0 / 200, tau0=tau0)
    e_x, e_z = np.abs(out[:, OUT_VC_END]), -out[:, OUT_VZ_END]
    assert np.ptp(e_x) < 2e-6, np.ptp(e_x)
    assert np.ptp(e_z) < 1e-7, np.ptp(e_z)


def test_kelvin_voigt_ez_against_the_continuum():
    """e_z on elements converges to the closed-form continuum (docs/physics.md#kelvin-voigt-continuum)
    at second order under joint refinement.

    On the oblique kernel: in full stick the normal problem does not see the
    tangential one (the same e_z as the normal-only kernel), and that kernel is the
    one the rest of the suite compiles (a normal-only Kelvin-Voigt element kernel
    would be compiled for this test alone)."""
    from vimpact.reference.closed_forms import kelvin_voigt_continuum

    Q1 = 0.3
    tau0 = Q1 / Q1_PER_TAU
    exact = kelvin_voigt_continuum(Q1).e_z
    N = np.array([100, 200, 400, 800])
    out, _ = run_rows(KV, h=HERTZ_TIME / N, dxi=1.0 / (N / 4), tau0=tau0)
    order, err = fitted_order(-out[:, OUT_VZ_END], float(exact))
    assert err[-1] < 2e-6, err
    assert order >= 1.8, (order, err)


def test_ex_second_order_joint_refinement_elastic():
    """Elastic e_x against a 4x finer run: observed order >= 1.8 with steps
    and elements refined together (1 element per a_H for 6 steps per t_H)."""
    N = np.array([150, 300, 600, 2400])
    out, _ = run_rows(ELASTIC, h=HERTZ_TIME / N / 1.87, dxi=6.0 / N, nu=0.5)
    e_x = out[:, OUT_VC_END]
    order, err = fitted_order(e_x[:3], e_x[3])
    assert order >= 1.8, (order, err)


def test_kelvin_voigt_ex_second_order_in_time():
    """Kelvin-Voigt e_x at a fixed fine spacing: second order in the step
    (first order before the dashpots of partially-in-contact elements were
    taken at the step-end velocities). Its spacing error is not smooth level
    by level (benchmarks/element_orders.py), so joint ladders are noisy."""
    # the spacing fine enough that its (non-smooth) error stays below the step's
    N = np.array([100, 200, 400, 3200])
    out, _ = run_rows(KV, h=HERTZ_TIME / N / 1.87, dxi=1.0 / 800, tau0=0.3 / Q1_PER_TAU, nu=0.5)
    e_x = out[:, OUT_VC_END]
    order, err = fitted_order(e_x[:3], e_x[3])
    assert order >= 1.8, (order, err)


def continuum_reference(g, tau, nu=0.3, theta_ratio=0.4, tangential=True):
    """``(e_z, e_x)`` of the full-stick continuum kernel at rtol 1e-12 (an
    independent discretization of the same equations, itself checked against
    scipy in tests/kernels/test_continuum_maxwell.py), kernel units."""
    from vimpact.kernels import continuum_maxwell

    out = np.zeros((1, N_OUT))
    continuum_maxwell.maxwell_stick_batch(
        np.zeros(1), np.array([list(g)]), np.array([list(tau)]),
        np.array([len(g)], dtype=np.int64), np.full(1, 2.0 * (1.0 - nu) / (2.0 - nu)),
        np.full(1, 1.0 + 1.0 / theta_ratio), np.array([tangential]), 1e-12, 10_000_000, out)
    assert out[0, OUT_STATUS] == STATUS_OK
    return -out[0, OUT_VZ_END], abs(out[0, OUT_VC_END])


STANDARD_SOLID_NORMAL = KernelSpec(VERLET, False, 0, True, False)
STANDARD_SOLID = KernelSpec(VERLET, True, 0, True, False)


@pytest.mark.parametrize("Q2", [1e-3, 1e-4])
def test_fast_stiff_arm_second_order_in_time(Q2):
    """A standard solid whose arm is far faster than the step (Q1 = 0.3, Q2 =
    1e-3: tau_arm = 4.4e-4 T, 30 times below the step at 200 steps per t_H):
    e_z converges to the continuum kernel at second order in the step (first
    order, 2e-3 at 200 steps, while the arm was explicit in the kick), and
    is within 1e-5 already at 200 steps per t_H."""
    g, tau = (1.0 / Q2,), (0.3 / Q1_PER_TAU * Q2,)
    exact, _ = continuum_reference(g, tau, tangential=False)
    N = np.array([200, 400, 800])
    out, _ = run_rows(STANDARD_SOLID_NORMAL, h=HERTZ_TIME / N, dxi=1.0 / 800, g=g, tau=tau)
    order, err = fitted_order(-out[:, OUT_VZ_END], exact)
    assert order >= 1.8, (order, err)
    assert err[0] < 1e-5, err


def test_fast_stiff_arm_oblique():
    """The same arm in an oblique impact (Q2 = 1e-3, 400 elements per a_H):
    e_z and e_x within 1e-5 of the continuum at 200 steps per t_H (both were
    about 4e-4 while the arm was explicit), e_z falling at second order."""
    g, tau = (1e3,), (0.3 / Q1_PER_TAU * 1e-3,)
    ez_exact, ex_exact = continuum_reference(g, tau)
    N = np.array([200, 400, 800])
    out, _ = run_rows(STANDARD_SOLID, h=HERTZ_TIME / N / 1.87, dxi=1.0 / 400, g=g, tau=tau)
    order, err = fitted_order(-out[:, OUT_VZ_END], ez_exact)
    assert order >= 1.8, (order, err)
    err_x = np.abs(np.abs(out[:, OUT_VC_END]) - ex_exact)
    assert max(err[0], err_x.max()) < 1e-5, (err, err_x)
