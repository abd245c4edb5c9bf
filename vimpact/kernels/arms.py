"""Maxwell-arm helpers of the element kernels (docs/physics.md#rheologies, exact update).

Every arm is advanced with the exact exponential update for a linear
displacement path over the step; nothing divides by a viscosity or a
relaxation time. Kernel units as in :mod:`vimpact.kernels.elements`.
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.kernels.jit import jit


@jit()
def _arm_coefficient(tau, h):
    """``(E, 1 - E, phi)`` of the exact arm update over a step ``h``.

    For ``tau dq/dt = w - q`` with ``w`` linear from ``w0`` to ``w1``:
    ``q1 = E q0 + (1 - E) w0 + phi (w1 - w0)`` with ``E = exp(-h/tau)`` and
    ``phi = 1 - (tau/h)(1 - E)`` (docs/physics.md#rheologies). Valid for ``tau = 0``
    (the arm follows ``w``) and ``tau = inf`` (the arm is frozen).
    """
    x = h / tau if tau > 0.0 else np.inf
    omE = -math.expm1(-x)
    if x < 1e-3:  # series: the closed form cancels
        phi = x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0)))
    else:
        phi = 1.0 - omE / x
    return 1.0 - omE, omE, phi


@jit()
def arm_coefficients(tau, h):
    """Arrays ``(E, 1 - E, phi)`` of :func:`_arm_coefficient` for every arm."""
    n = tau.shape[0]
    E = np.empty(n)
    omE = np.empty(n)
    phi = np.empty(n)
    for i in range(n):
        E[i], omE[i], phi[i] = _arm_coefficient(tau[i], h)
    return E, omE, phi


@jit(inline="always")
def _follow_over(w0, w1, qrow, g, tau, dt):
    """Advance the arms like :func:`_follow`, over a part ``dt`` (/ T) of a step.

    For an element entering contact within the step; the coefficients are computed
    here, as entries are rare.
    """
    acc = 0.0
    for i in range(g.shape[0]):
        E, omE, phi = _arm_coefficient(tau[i], dt)
        qi = E * qrow[i] + omE * w0 + phi * (w1 - w0)
        qrow[i] = qi
        acc += g[i] * (w1 - qi)
    return acc


@jit(inline="always")
def _follow(w0, w1, qrow, g, E, omE, phi):
    """Advance the arms of one element along ``w0 -> w1``; return ``sum g_i (w1 - q_i)``."""
    acc = 0.0
    for i in range(g.shape[0]):
        qi = E[i] * qrow[i] + omE[i] * w0 + phi[i] * (w1 - w0)
        qrow[i] = qi
        acc += g[i] * (w1 - qi)
    return acc


@jit(inline="always")
def _relax(w0, qrow, g, E, omE, phi, tau0_h, den_free, decay0):
    """Free surface relaxation under zero force over one step; returns the new ``w``.

    Solves ``tau0 dw/dt + G_inf w + sum g_i (w - q_i) = 0`` (docs/physics.md
    section 5) for an element with arms, implicit in the end value (L-stable),
    the arms on the exact linear-path update. (Without arms the kernel uses
    the exact ``w decay0`` instead, 0 for an elastic element.)
    """
    n = g.shape[0]
    num = tau0_h * w0
    for i in range(n):
        num += g[i] * (E[i] * qrow[i] + (omE[i] - phi[i]) * w0)
    w1 = num / den_free
    for i in range(n):
        qrow[i] = E[i] * qrow[i] + omE[i] * w0 + phi[i] * (w1 - w0)
    return w1


@jit()
def _free_rate(w, qrow, g, tau, tau0):
    """Return the current ``dw/dt`` of a free surface element, in units of ``v_z0``."""
    n = g.shape[0]
    r = w
    for i in range(n):
        r += g[i] * (w - qrow[i])
    if tau0 > 0.0:
        return -r / tau0
    G = 0.0
    rate = 0.0
    for i in range(n):
        G += g[i]
        if tau[i] > 0.0:
            rate += g[i] * (w - qrow[i]) / tau[i]
    return rate / (1.0 + G)



@jit(inline="always")
def _to_stress(target, s0, p0, prow, g, E, omE, phi, tau0_dt):
    """Return the end value ``s1`` of the linear path ``s0 -> s1`` with element stress ``target``.

    The path is linear over a time ``dt`` (/ T); Coulomb slip
    (docs/physics.md#coulomb-friction). Solves
    ``s1 + sum g_i (s1 - p_i(s1)) + tau0 (s1 - s0) / dt = target`` with the arms on
    the exact linear-path update from ``p0`` (``E``, ``omE``, ``phi`` the
    coefficients for ``dt``, ``tau0_dt = tau0 / dt``); writes the arms to ``prow``
    and returns ``s1``. Like :func:`_relax`, with a target stress instead of zero.
    """
    num = target + tau0_dt * s0
    den = tau0_dt + 1.0
    for i in range(g.shape[0]):
        num += g[i] * (E[i] * p0[i] + (omE[i] - phi[i]) * s0)
        den += g[i] * (1.0 - phi[i])
    s1 = num / den
    for i in range(g.shape[0]):
        prow[i] = E[i] * p0[i] + omE[i] * s0 + phi[i] * (s1 - s0)
    return s1


@jit(inline="always")
def _follow_value(w0, w1, qrow, g, E, omE, phi):
    """Return the arms' stress ``sum g_i (w1 - q_i)`` after the path ``w0 -> w1``.

    The arms are not changed: the trial force of an element that leaves contact
    within the step.
    """
    acc = 0.0
    for i in range(g.shape[0]):
        acc += g[i] * (w1 - (E[i] * qrow[i] + omE[i] * w0 + phi[i] * (w1 - w0)))
    return acc


@jit(inline="always")
def _arm_stress(w, qrow, g):
    """``sum g_i (w - q_i)``: the arms' part of the spring stress at ``w``."""
    acc = 0.0
    for i in range(g.shape[0]):
        acc += g[i] * (w - qrow[i])
    return acc


@jit()
def arm_implicit_coefficients(g, tau, h):
    """Split of each arm's step impulse for the Verlet kick (fast arms implicit).

    Over a step ``h`` on which the element's displacement is linear with the
    drift velocity ``v`` (from ``w0``, arm ``q0``), the exact arm force
    ``g (w - q)`` has the impulse ``h g [(1 - phi)(w0 - q0) + tau phi v]``; its
    end value is ``g [E (w0 - q0) + tau (1 - E) v]``. The kick takes the end
    value in its second half, so its first half must carry
    ``g [kap (w0 - q0) + c v]`` with ``kap = 2 (1 - phi) - E`` and
    ``c = tau (1 + E - 2 (1 - E) x^-1)``, ``x = h / tau``: ``c >= 0`` is a
    damping taken implicitly in the half-step velocity like the dashpot (an
    arm much faster than the step acts as the dashpot ``g tau``; a slow one
    as its spring, ``c -> h x / 6``).

    Returns
    -------
    kap : (n_arms,) weights of the arms' stresses ``g_i (w0 - q_i)`` at the step start
    c : ``sum_i g_i c_i``, the arms' damping per unit element stiffness (units of ``T``)
    """
    n = tau.shape[0]
    kap = np.empty(n)
    c = 0.0
    for i in range(n):
        E, omE, phi = _arm_coefficient(tau[i], h)
        kap[i] = 2.0 * (1.0 - phi) - E
        x = h / tau[i] if tau[i] > 0.0 else np.inf
        if x < 1e-3:  # series: 1 + E - 2 (1 - E) / x = x^2/6 - x^3/12 + x^4/40
            ci = h * x * (1.0 / 6.0 - x * (1.0 / 12.0 - x / 40.0))
        else:
            ci = h / x * (1.0 + E - 2.0 * omE / x)
        c += g[i] * ci
    return kap, c


@jit(inline="always")
def _arm_start(w, qrow, g, kap):
    """Return ``sum g_i kap_i (w - q_i)``, the arms' start-of-step stress in the Verlet kick.

    ``kap_i`` from :func:`arm_implicit_coefficients`.
    """
    acc = 0.0
    for i in range(g.shape[0]):
        acc += g[i] * kap[i] * (w - qrow[i])
    return acc


@jit(inline="always")
def _follow_over_impulse(w0, w1, qrow, g, tau, dt):
    """Advance the arms like :func:`_follow_over` and return their end and mean stress.

    The arms follow ``w0 -> w1`` over ``dt`` (/ T), written to ``qrow``; returns
    ``(sum g_i (w1 - q_i), mean)``, ``mean`` the arms' stress averaged over ``dt``,
    exact for the linear path:
    ``sum g_i [(1 - phi_i)(w0 - q0_i) + (tau_i phi_i / dt)(w1 - w0)]``. For an element
    entering contact within a step: an arm faster than that part jumps to its
    dashpot-like stress at once, which a straight line from the entry stress misses.
    """
    acc = 0.0
    mean = 0.0
    for i in range(g.shape[0]):
        E, omE, phi = _arm_coefficient(tau[i], dt)
        x = dt / tau[i] if tau[i] > 0.0 else np.inf
        if x < 1e-3:  # phi / x = 1/2 - x/6 + x^2/24
            phi_x = 0.5 - x * (1.0 / 6.0 - x / 24.0)
        else:
            phi_x = phi / x
        q0 = qrow[i]
        qi = E * q0 + omE * w0 + phi * (w1 - w0)
        qrow[i] = qi
        acc += g[i] * (w1 - qi)
        mean += g[i] * ((1.0 - phi) * (w0 - q0) + phi_x * (w1 - w0))
    return acc, mean
