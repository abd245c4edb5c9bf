"""Continuum (``dx -> 0``) kernel of the full-stick impact for every rheology.

docs/physics.md#continuum-limit: with incremental tangential memory (Maw, Barber and
Fawcett) and full stick, the element row's continuum limit is a small ODE
system for any generalized Maxwell half-space with an optional parallel
dashpot (elastic, Kelvin-Voigt, standard solid, Prony series), any ``nu``
(through ``kappa = c_t / c_n = 2 (1 - nu) / (2 - nu)``) and any moment of
inertia (through ``mu_t = 1 + m R^2 / Theta``; 1 without rotation).

Units
-----
Kernel units of :mod:`vimpact.kernels.elements`: ``u`` / d, ``x`` / a_H (profile
``g = x^2``), ``t`` / T, ``v`` / v_z0, ``G_inf = 1``, dashpot time
``tau0 = eta0 / (G_inf T)``, arms ``g_i = G_i / G_inf`` with times ``tau_i / T``.
The tangential problem is linear in ``v_c0``: the contact-point displacement
``w_c`` and velocity ``v_c`` are in units of ``v_c0 T`` and ``v_c0``
(``v_c(0) = 1``). ``gn = 2 * 15/16`` (both halves of the element row).

Formulation
-----------
``A_i`` and ``B_i`` are the arm filters of ``u`` and ``w_c``
(``tau_i dA_i/dt = u - A_i``, ``tau_i dB_i/dt = w_c - B_i``). Loading
(``v >= 0``): the contact is ``[0, b]``, ``b = sqrt(u)``, and

    F_z = gn [ 2/3 b^3 + tau0 v b + sum_i g_i ((u - A_i) b + S_i) ]
    F_x = gn kappa [ w_c b - I + tau0 v_c b + sum_i g_i ((w_c - B_i) b + U_i) ]
    dS_i/dt = -S_i/tau_i + (A_i - u) db/dt,   dU_i/dt = -U_i/tau_i + (B_i - w_c) db/dt
    dI/dt = w_c db/dt,   dv/dt = -F_z,   dv_c/dt = -mu_t F_x

Unloading (``v < 0``): an element that entered at ``t_e`` carries the normal
force density ``f(t_e, t) = (u - u_e) + tau0 v + sum_i g_i [(u - A_i) + E_i
(A_i(t_e) - u_e)]`` with ``u_e = u(t_e)``, ``E_i = exp(-(t - t_e)/tau_i)``; the
edge ``b = sqrt(u_e*)`` is where it vanishes, and the integrals over ``[0, b]``
are the loading accumulators at ``t_e*``, decayed: ``E_i S_i(t_e*)``,
``E_i U_i(t_e*)``, ``I(t_e*)``. The edge is a state: differentiating
``f(t_e*, t) = 0`` along the loading history (``dA_i/dt_e = (u_e - A_i(t_e))/tau_i``
makes every history term cancel but one) gives ``df/du_e = -(1 + sum_i g_i E_i)``
and

    d(b^2)/dt = [v - tau0 F_z + sum_i g_i (v - (u - A_i)/tau_i - E_i (A_i(t_e*) - u_e)/tau_i)]
                / (1 + sum_i g_i E_i)

regular at the turning point and at the end of contact (for Kelvin-Voigt
it is section 5's ``d(u + tau0 v)/dt``). The history values at ``t_e*`` come
from the loading steps' Dormand-Prince dense output (fourth order, the same
order as the local error), inverted for ``b`` by safeguarded Newton.

Independent variable: as in :mod:`vimpact.kernels.continuum_kv`, the contact
half-width ``s = b`` is a state and time is advanced through a Sundman
variable ``sigma`` with ``dt = 2 s dsigma``. Loading (``s^2 = u``):
``ds/dsigma = v``; unloading: ``ds/dsigma = d(b^2)/dt``. Every right-hand
side is then smooth at the first touch (``s = 0``), and the end of contact
is ``s`` crossing zero with finite slope. (With a dashpot *and* arms the
unloading right-hand side has a weak ``(t - t_turn)^(3/2)`` term just after
the turning point, which the step control absorbs.)

Integrator: Dormand-Prince 5(4) on the whole state with PI step-size
control (the tableau of :mod:`vimpact.kernels.continuum_kv`), error norm RMS
over the active components with ``atol = rtol`` (``s``, ``v`` scaled for heavy
damping as there). The unloading restarts with ``UNLOAD_FIRST_STEP`` times
the proposed step: at the turning point the history is a square-root
function of the edge state (``t_e(b)``), the error estimate of a long first
step misses most of its error, and the small restart (3-4 extra steps) cut
the ``beta_x``/``t_contact`` errors from 10-100 ``rtol`` to 1-3 ``rtol``.
Measured against the scipy reference at ``rtol = 1e-12``: within 3e-11 on
``e_z``, ``beta_x``, ``t_contact`` (3.4e-10 with a dashpot *and* arms). Events
(``v = 0`` turning point, ``s = 0`` end of contact)
are located by re-taking the step with Newton on its length (derivative
from the FSAL stage), safeguarded by bisection, so the event state is an
ordinary Runge-Kutta step. Arms with ``tau_i = 0`` follow ``u`` at once and
carry no force (dropped); ``tau_i = inf`` is a spring in parallel. Arms with
``tau_i`` much shorter than ``T`` make the system stiff: the explicit method
then needs ``~ T / tau_i`` steps (``max_steps`` bounds them).

Cost: all work arrays are allocated once per impact; the step runs its
stages in one loop with the right-hand side and the edge lookup written out
in it (in numba every call with array arguments, inlined or not, costs
reference counting, measured at a third of the step's time), and the edge's
history step is searched from the previous one (the edge moves by about one
history step per step). The numbers are those of the straightforward
version to the bit. Most of the error of ``beta_x`` and ``t_contact`` with
arms comes from the unloading phase (measured for the 3-arm Prony benchmark
scene: a 10x tighter tolerance on unloading alone cuts it 10-60x, on loading
alone not at all).

Assumptions (checked while running)
-----------------------------------
- The contact stays one interval ``[0, b]``. This holds by itself: along the
  loading history ``df/dt_e = -v(t_e) (1 + sum_i g_i E_i) < 0`` (``v > 0`` while
  loading), so ``f`` falls monotonically from the centre to the outermost
  element and has one root (not checked; the force density at the edge, zero
  up to the integration error, is kept in ``e_val[n]`` of the right-hand side).
- No element re-enters: the edge never moves outward on unloading
  (``b`` grows by more than ``100 rtol b_max`` over an accepted step). At the
  edge ``d f/dt > 0`` means exactly that the free surface just outside rises
  faster than the sphere.
- After separation the free surface must not catch the sphere: the centre
  element (the last to leave, the deepest point) relaxes freely from its
  state at the end (exact exponential arm update, implicit surface), checked
  on 200 steps up to the time the sphere's lowest point is back at the
  original surface (``u = 0``) and then up to twice that.
A violation gives ``STATUS_ASSUMPTION`` (outputs of the last state, which
are not the impact's): the element row must take the scene. (A search over
4500 random scenes, 0-3 arms with ``g_i`` up to 1e4, ``tau_i`` 0.01-1000,
with and without dashpot, found none: for one arm the free surface provably
never catches the sphere, its recovery rate falls as it relaxes.)

Statuses and outputs
--------------------
``OUT_VZ_END`` (``-e_z``), ``OUT_VC_END`` (``v_c,end``; ``beta_x = -v_c,end``,
0 for normal-only rows), ``OUT_T_CONTACT``, ``OUT_U_MAX``, ``OUT_B_MAX``,
``OUT_STATUS``: ``STATUS_OK``; ``STATUS_TIME_LIMIT`` (``max_steps`` accepted
steps); ``STATUS_NON_FINITE`` (a non-finite state, a step-size underflow, or
invalid input: ``tau0 < 0``, ``g_i < 0``, ``tau_i < 0``, NaN, ``kappa`` or
``mu_t`` not positive; NaN outputs); ``STATUS_ASSUMPTION`` (above).
``OUT_STEPS`` counts accepted steps (loading and unloading), ``OUT_N_REC``
the trajectory rows.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vimpact.kernels.continuum_kv import (
    _A21,
    _A31,
    _A32,
    _A41,
    _A42,
    _A43,
    _A51,
    _A52,
    _A53,
    _A54,
    _A61,
    _A62,
    _A63,
    _A64,
    _A65,
    _B1,
    _B3,
    _B4,
    _B5,
    _B6,
    _E1,
    _E3,
    _E4,
    _E5,
    _E6,
    _E7,
    RTOL_MAX,
    RTOL_MIN,
    accepted_step_factor,
    rejected_step_factor,
)
from vimpact.kernels.jit import jit
from vimpact.kernels.layout import (
    ELEMENT_STIFFNESS,
    N_REC,
    OUT_B_MAX,
    OUT_N_REC,
    OUT_STATUS,
    OUT_STEPS,
    OUT_T_CONTACT,
    OUT_T_GROSS_SLIP,
    OUT_U_MAX,
    OUT_VC_END,
    OUT_VZ_END,
    OUT_W_FRICTION,
    STATUS_ASSUMPTION,
    STATUS_NON_FINITE,
    STATUS_OK,
    STATUS_TIME_LIMIT,
)
from vimpact.kernels.record import _record

__all__ = ["maxwell_stick_impact", "maxwell_stick_batch", "GN"]

#: Normal stiffness factor of the continuum force (both halves of the row).
GN = 2.0 * ELEMENT_STIFFNESS

_EPS = 2.220446049250313e-16

# Dormand-Prince continuous extension (Hairer, Norsett & Wanner, DOPRI5 ``contd5``)
_D1 = -12715105075.0 / 11282082432.0
_D3 = 87487479700.0 / 32700410799.0
_D4 = -10690763975.0 / 1880347072.0
_D5 = 701980252875.0 / 199316789632.0
_D6 = -1453857185.0 / 822651844.0
_D7 = 69997945.0 / 29380423.0

# state layout, loading: s, v, t, A[n], S[n], (w_c, v_c, I, B[n], U[n])
# state layout, unloading: s, v, t, u, A[n], (w_c, v_c, B[n])
_LS, _LV, _LT = 0, 1, 2
_US, _UV, _UT, _UU = 0, 1, 2, 3

_N_CHECK = 200  # steps of the post-separation surface check
#: first unloading step as a fraction of the step the loading phase proposed
UNLOAD_FIRST_STEP = 1e-3


@jit()
def _n_load(n, tang):
    return 3 + 2 * n + (3 + 2 * n if tang else 0)


@jit()
def _n_unload(n, tang):
    return 4 + n + (2 + n if tang else 0)


@jit(inline="always")
def _rhs_load(y, K, r, tau0, g, itau, n, kappa, mu_t, tang):
    """Loading right-hand side ``dy/dsigma`` into ``K[r]``; returns ``(F_z, F_x)``."""
    s = y[0]
    v = y[1]
    s2 = s * s
    acc = 2.0 / 3.0 * s2 * s + tau0 * v * s
    for i in range(n):
        a = y[3 + i]
        acc += g[i] * ((s2 - a) * s + y[3 + n + i])
        K[r, 3 + i] = 2.0 * s * (s2 - a) * itau[i]
        K[r, 3 + n + i] = -2.0 * s * y[3 + n + i] * itau[i] + (a - s2) * v
    Fz = GN * acc
    K[r, 0] = v
    K[r, 1] = -2.0 * s * Fz
    K[r, 2] = 2.0 * s
    Fx = 0.0
    if tang:
        o = 3 + 2 * n
        wc = y[o]
        vc = y[o + 1]
        accx = wc * s - y[o + 2] + tau0 * vc * s
        for i in range(n):
            bb = y[o + 3 + i]
            accx += g[i] * ((wc - bb) * s + y[o + 3 + n + i])
            K[r, o + 3 + i] = 2.0 * s * (wc - bb) * itau[i]
            K[r, o + 3 + n + i] = -2.0 * s * y[o + 3 + n + i] * itau[i] + (bb - wc) * v
        Fx = GN * kappa * accx
        K[r, o] = 2.0 * s * vc
        K[r, o + 1] = -2.0 * s * mu_t * Fx
        K[r, o + 2] = wc * v
    return Fz, Fx


@jit(inline="always")
def _dense(rc, k, th, c):
    """Dense-output value of component ``c`` of stored step ``k`` at ``theta = th``."""
    th1 = 1.0 - th
    return rc[k, 0, c] + th * (rc[k, 1, c] + th1 * (rc[k, 2, c] + th * (rc[k, 3, c]
                                                                       + th1 * rc[k, 4, c])))


@jit(inline="always")
def _dense_d(rc, k, th, c):
    """``d/dtheta`` of :func:`_dense`."""
    r1 = rc[k, 1, c]
    r2 = rc[k, 2, c]
    r3 = rc[k, 3, c]
    r4 = rc[k, 4, c]
    # p = r0 + th r1 + th (1-th) r2 + th^2 (1-th) r3 + th^2 (1-th)^2 r4
    return (r1 + (1.0 - 2.0 * th) * r2 + (2.0 * th - 3.0 * th * th) * r3
            + (2.0 * th - 6.0 * th * th + 4.0 * th * th * th) * r4)


@jit(inline="always")
def _edge(rc, hs, nh, s_t, kh):
    """Loading step ``k`` and ``theta`` with ``s(k, theta) = s_t``.

    ``hs`` holds ``s`` at the start of each stored step (increasing) and, at
    ``nh``, at the end of the last one. Below 0 the first step's polynomial is
    extended (``theta < 0``), above the turning point ``theta = 1``. The step
    is searched from ``kh[0]``, the previous call's (the edge moves little
    between calls), and stored there: the same step as a bisection over all
    steps, the last with ``hs[k] <= s_t``.
    """
    if s_t >= hs[nh]:
        return nh - 1, 1.0
    if s_t <= 0.0:
        k = 0
        lo = -1.0
        hi = 0.0
        th = s_t / (hs[1] - hs[0]) if hs[1] > hs[0] else 0.0
    else:
        k = min(max(kh[0], 0), nh - 1)
        while k > 0 and hs[k] > s_t:
            k -= 1
        while k < nh - 1 and hs[k + 1] <= s_t:
            k += 1
        kh[0] = k
        lo = 0.0
        hi = 1.0
        th = (s_t - hs[k]) / (hs[k + 1] - hs[k])
    for _ in range(60):
        if not (lo <= th <= hi):
            th = 0.5 * (lo + hi)
        p = _dense(rc, k, th, 0) - s_t
        if p == 0.0:
            return k, th
        if p < 0.0:
            lo = th
        else:
            hi = th
        dp = _dense_d(rc, k, th, 0)
        thn = th - p / dp if dp > 0.0 else 0.5 * (lo + hi)
        if not (lo < thn < hi):
            thn = 0.5 * (lo + hi)
        if abs(thn - th) <= 2.0 * _EPS or hi - lo <= 2.0 * _EPS:
            return k, thn
        th = thn
    return k, th


@jit(inline="always")
def _rhs_unload(z, K, r, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val, kh):
    """Unloading right-hand side ``dz/dsigma`` into ``K[r]``; returns ``(F_z, F_x)``.

    ``e_val`` receives the decay factors ``E_i`` at the edge and, at ``n``,
    the force density there (zero up to the integration error).
    """
    s = z[0]
    v = z[1]
    t = z[2]
    u = z[3]
    k, th = _edge(rc, hs, nh, s, kh)
    te = _dense(rc, k, th, _LT)
    ue = s * s
    acc = u * s - s * s * s / 3.0 + tau0 * v * s
    den = 1.0
    ft = 0.0
    fe = u - ue + tau0 * v
    for i in range(n):
        a = z[4 + i]
        ae = _dense(rc, k, th, 3 + i)
        se = _dense(rc, k, th, 3 + n + i)
        e = math.exp(-(t - te) * itau[i])
        e_val[i] = e
        acc += g[i] * ((u - a) * s + e * se)
        den += g[i] * e
        fe += g[i] * ((u - a) + e * (ae - ue))
        ft += g[i] * (v - ((u - a) + e * (ae - ue)) * itau[i])
        K[r, 4 + i] = 2.0 * s * (u - a) * itau[i]
    Fz = GN * acc
    e_val[n] = fe  # force density at the edge (0 up to the integration error)
    ft += v - tau0 * Fz
    K[r, 0] = ft / den
    K[r, 1] = -2.0 * s * Fz
    K[r, 2] = 2.0 * s
    K[r, 3] = 2.0 * s * v
    Fx = 0.0
    if tang:
        o = 4 + n
        lo = 3 + 2 * n
        wc = z[o]
        vc = z[o + 1]
        ie = _dense(rc, k, th, lo + 2)
        accx = wc * s - ie + tau0 * vc * s
        for i in range(n):
            bb = z[o + 2 + i]
            ue_i = _dense(rc, k, th, lo + 3 + n + i)
            accx += g[i] * ((wc - bb) * s + e_val[i] * ue_i)
            K[r, o + 2 + i] = 2.0 * s * (wc - bb) * itau[i]
        Fx = GN * kappa * accx
        K[r, o] = 2.0 * s * vc
        K[r, o + 1] = -2.0 * s * mu_t * Fx
    return Fz, Fx


@jit(inline="always")
def _rhs(phase, y, K, r, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val, kh):
    if phase == 0:
        return _rhs_load(y, K, r, tau0, g, itau, n, kappa, mu_t, tang)
    return _rhs_unload(y, K, r, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val, kh)


@jit()
def _rhs_once(phase, y, K, r, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val, kh):
    """:func:`_rhs` as a called function (not inlined) for the few evaluations
    outside the steps."""
    return _rhs(phase, y, K, r, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val, kh)


@jit()
def _step(phase, m, y, h, K, y1, tmp, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val,
          atol, rtol, kh):
    """One Dormand-Prince 5(4) step of length ``h`` from ``y`` (``K[0]`` its
    derivative); ``y1`` and ``K[1..6]`` receive the new state and stages
    (``K[6]`` the derivative at ``y1``). Returns the error norm.

    The stages run in one loop with the right-hand side (and the history
    lookup) written out once in it: it must stay the same as
    :func:`_rhs_load` / :func:`_rhs_unload` (which evaluate it outside the
    steps); tests/kernels/test_continuum_maxwell.py checks that both give
    the same derivatives."""
    for r in range(1, 7):
        if r == 1:
            for c in range(m):
                tmp[c] = y[c] + h * _A21 * K[0, c]
        elif r == 2:
            for c in range(m):
                tmp[c] = y[c] + h * (_A31 * K[0, c] + _A32 * K[1, c])
        elif r == 3:
            for c in range(m):
                tmp[c] = y[c] + h * (_A41 * K[0, c] + _A42 * K[1, c] + _A43 * K[2, c])
        elif r == 4:
            for c in range(m):
                tmp[c] = y[c] + h * (_A51 * K[0, c] + _A52 * K[1, c] + _A53 * K[2, c]
                                     + _A54 * K[3, c])
        elif r == 5:
            for c in range(m):
                tmp[c] = y[c] + h * (_A61 * K[0, c] + _A62 * K[1, c] + _A63 * K[2, c]
                                     + _A64 * K[3, c] + _A65 * K[4, c])
        else:
            for c in range(m):
                tmp[c] = y[c] + h * (_B1 * K[0, c] + _B3 * K[2, c] + _B4 * K[3, c]
                                     + _B5 * K[4, c] + _B6 * K[5, c])
        # the right-hand side at tmp into K[r]: the bodies of _rhs_load and
        # _rhs_unload (with _edge) written out, because every call (inlined or
        # not) with array arguments costs reference counting, a third of the
        # step's time when measured
        s = tmp[0]
        v = tmp[1]
        if phase == 0:
            s2 = s * s
            acc = 2.0 / 3.0 * s2 * s + tau0 * v * s
            for i in range(n):
                a = tmp[3 + i]
                acc += g[i] * ((s2 - a) * s + tmp[3 + n + i])
                K[r, 3 + i] = 2.0 * s * (s2 - a) * itau[i]
                K[r, 3 + n + i] = -2.0 * s * tmp[3 + n + i] * itau[i] + (a - s2) * v
            Fz = GN * acc
            K[r, 0] = v
            K[r, 1] = -2.0 * s * Fz
            K[r, 2] = 2.0 * s
            if tang:
                o = 3 + 2 * n
                wc = tmp[o]
                vc = tmp[o + 1]
                accx = wc * s - tmp[o + 2] + tau0 * vc * s
                for i in range(n):
                    bb = tmp[o + 3 + i]
                    accx += g[i] * ((wc - bb) * s + tmp[o + 3 + n + i])
                    K[r, o + 3 + i] = 2.0 * s * (wc - bb) * itau[i]
                    K[r, o + 3 + n + i] = -2.0 * s * tmp[o + 3 + n + i] * itau[i] + (bb - wc) * v
                Fx = GN * kappa * accx
                K[r, o] = 2.0 * s * vc
                K[r, o + 1] = -2.0 * s * mu_t * Fx
                K[r, o + 2] = wc * v
            continue
        t = tmp[2]
        u = tmp[3]
        # _edge(rc, hs, nh, s, kh)
        k = nh - 1
        th = 1.0
        if s < hs[nh]:
            if s <= 0.0:
                k = 0
                lo = -1.0
                hi = 0.0
                th = s / (hs[1] - hs[0]) if hs[1] > hs[0] else 0.0
            else:
                k = min(max(kh[0], 0), nh - 1)
                while k > 0 and hs[k] > s:
                    k -= 1
                while k < nh - 1 and hs[k + 1] <= s:
                    k += 1
                kh[0] = k
                lo = 0.0
                hi = 1.0
                th = (s - hs[k]) / (hs[k + 1] - hs[k])
            for _ in range(60):
                if not (lo <= th <= hi):
                    th = 0.5 * (lo + hi)
                p = _dense(rc, k, th, 0) - s
                if p == 0.0:
                    break
                if p < 0.0:
                    lo = th
                else:
                    hi = th
                dp = _dense_d(rc, k, th, 0)
                thn = th - p / dp if dp > 0.0 else 0.5 * (lo + hi)
                if not (lo < thn < hi):
                    thn = 0.5 * (lo + hi)
                if abs(thn - th) <= 2.0 * _EPS or hi - lo <= 2.0 * _EPS:
                    th = thn
                    break
                th = thn
        te = _dense(rc, k, th, _LT)
        ue = s * s
        acc = u * s - s * s * s / 3.0 + tau0 * v * s
        den = 1.0
        ft = 0.0
        fe = u - ue + tau0 * v
        for i in range(n):
            a = tmp[4 + i]
            ae = _dense(rc, k, th, 3 + i)
            se = _dense(rc, k, th, 3 + n + i)
            e = math.exp(-(t - te) * itau[i])
            e_val[i] = e
            acc += g[i] * ((u - a) * s + e * se)
            den += g[i] * e
            fe += g[i] * ((u - a) + e * (ae - ue))
            ft += g[i] * (v - ((u - a) + e * (ae - ue)) * itau[i])
            K[r, 4 + i] = 2.0 * s * (u - a) * itau[i]
        Fz = GN * acc
        e_val[n] = fe
        ft += v - tau0 * Fz
        K[r, 0] = ft / den
        K[r, 1] = -2.0 * s * Fz
        K[r, 2] = 2.0 * s
        K[r, 3] = 2.0 * s * v
        if tang:
            o = 4 + n
            ol = 3 + 2 * n
            wc = tmp[o]
            vc = tmp[o + 1]
            ie = _dense(rc, k, th, ol + 2)
            accx = wc * s - ie + tau0 * vc * s
            for i in range(n):
                bb = tmp[o + 2 + i]
                ue_i = _dense(rc, k, th, ol + 3 + n + i)
                accx += g[i] * ((wc - bb) * s + e_val[i] * ue_i)
                K[r, o + 2 + i] = 2.0 * s * (wc - bb) * itau[i]
            Fx = GN * kappa * accx
            K[r, o] = 2.0 * s * vc
            K[r, o + 1] = -2.0 * s * mu_t * Fx
    for c in range(m):
        y1[c] = tmp[c]
    acc = 0.0
    for c in range(m):
        e = h * (_E1 * K[0, c] + _E3 * K[2, c] + _E4 * K[3, c] + _E5 * K[4, c] + _E6 * K[5, c]
                 + _E7 * K[6, c])
        sc = atol[c] + rtol * max(abs(y[c]), abs(y1[c]))
        acc += (e / sc) ** 2
    return math.sqrt(acc / m)


@jit()
def _store(rc, hs, nh, y, y1, K, h, m):
    """Write the dense output of an accepted loading step into row ``nh``
    (Hairer, Norsett & Wanner's ``contd5`` coefficients) and its end ``s``."""
    for c in range(m):
        dif = y1[c] - y[c]
        bspl = h * K[0, c] - dif
        rc[nh, 0, c] = y[c]
        rc[nh, 1, c] = dif
        rc[nh, 2, c] = bspl
        rc[nh, 3, c] = dif - h * K[6, c] - bspl
        rc[nh, 4, c] = h * (_D1 * K[0, c] + _D3 * K[2, c] + _D4 * K[3, c] + _D5 * K[4, c]
                            + _D6 * K[5, c] + _D7 * K[6, c])
    hs[nh + 1] = y1[0]


@jit()
def _surface_catches(u_end, v_end, a_end, n, g, tau, tau0, tol):
    """Does the free centre element (``w = u_end``, arms ``a_end``) catch the
    sphere (``u = u_end + v_end (t - t_end)``) after separation?"""
    if not (v_end < 0.0):
        return True
    if n == 0:
        return False  # elastic: back at once; Kelvin-Voigt: w = u_end exp(-dt/tau0) >= u
    t_h = 2.0 * max(u_end, 0.0) / (-v_end)
    if t_h <= 0.0:
        return False
    h = t_h / _N_CHECK
    q = a_end[:n].copy()
    w = u_end
    G = 0.0
    E = np.empty(n)
    omE = np.empty(n)
    phi = np.empty(n)
    for i in range(n):
        G += g[i]
        x = h / tau[i] if tau[i] > 0.0 else np.inf
        omE[i] = -math.expm1(-x)
        E[i] = 1.0 - omE[i]
        phi[i] = x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0))) if x < 1e-3 \
            else 1.0 - omE[i] / x
    tau0_h = tau0 / h
    den = tau0_h + 1.0
    for i in range(n):
        den += g[i] * (1.0 - phi[i])
    for j in range(1, _N_CHECK + 1):
        num = tau0_h * w
        for i in range(n):
            num += g[i] * (E[i] * q[i] + (omE[i] - phi[i]) * w)
        w1 = num / den
        for i in range(n):
            q[i] = E[i] * q[i] + omE[i] * w + phi[i] * (w1 - w)
        w = w1
        if u_end + v_end * j * h > w + tol:
            return True
    return False


@jit()
def maxwell_stick_impact(tau0, g, tau, kappa, mu_t, tangential, rtol, max_steps, rec, rec_every,
                         out):
    """One full-stick impact in the continuum limit; results into ``out``.

    Parameters (kernel units, module docstring)
    ----------
    tau0 : parallel dashpot time ``eta0 / (G_inf T)``, >= 0
    g, tau : arm moduli ``G_i / G_inf`` (>= 0) and times ``tau_i / T`` (>= 0, inf
        allowed), 1-D of equal length (may be empty)
    kappa : ``c_t / c_n = 2 (1 - nu) / (2 - nu)`` (> 0)
    mu_t : ``1 + m R^2 / Theta`` (1 without rotation; > 0)
    tangential : advance the tangential problem (``v_c(0) = 1``); False:
        normal only, ``OUT_VC_END = 0``
    rtol : relative tolerance of the steps, clamped to ``[RTOL_MIN, RTOL_MAX]``
        of :mod:`vimpact.kernels.continuum_kv`; the outputs' global error is a
        small multiple of it
    max_steps : limit on accepted steps (``STATUS_TIME_LIMIT``)
    rec : ``(n_rec, N_REC)`` trajectory buffer (may have zero rows): rows
        ``t, u, v, v_c, F_z, F_x, b`` (``F_x`` in units of ``m v_c0 / T``: the
        tangential acceleration is ``-mu_t F_x``) after every ``rec_every``-th
        accepted step and one at the end (overwriting the last row if full)
    rec_every : record every this many accepted steps
    out : ``(N_OUT,)`` result row (module docstring)

    Returns the number of trajectory rows written.
    """
    n_rec = rec.shape[0]
    i_rec = 0
    out[OUT_T_GROSS_SLIP] = 0.0  # no friction on this path
    out[OUT_W_FRICTION] = 0.0
    nin = g.shape[0]
    ok_in = (tau0 >= 0.0 and math.isfinite(tau0) and kappa > 0.0 and math.isfinite(kappa)
             and mu_t > 0.0 and math.isfinite(mu_t) and tau.shape[0] == nin)
    n = 0
    for i in range(nin):
        if not (g[i] >= 0.0 and math.isfinite(g[i]) and tau[i] >= 0.0):
            ok_in = False
        elif g[i] > 0.0 and tau[i] > 0.0:
            n += 1
    if not ok_in:
        out[OUT_VZ_END] = np.nan
        out[OUT_VC_END] = np.nan
        out[OUT_T_CONTACT] = np.nan
        out[OUT_U_MAX] = np.nan
        out[OUT_B_MAX] = np.nan
        out[OUT_STATUS] = STATUS_NON_FINITE
        out[OUT_STEPS] = 0
        out[OUT_N_REC] = 0
        return 0
    ga = np.empty(n)
    ta = np.empty(n)
    itau = np.empty(n)
    j = 0
    for i in range(nin):
        if g[i] > 0.0 and tau[i] > 0.0:
            ga[j] = g[i]
            ta[j] = tau[i]
            itau[j] = 1.0 / tau[i]
            j += 1
    tang = tangential
    if not (rtol >= RTOL_MIN):
        rtol = RTOL_MIN
    if rtol > RTOL_MAX:
        rtol = RTOL_MAX
    m_l = _n_load(n, tang)
    m_u = _n_unload(n, tang)
    mm = max(m_l, m_u)
    # absolute tolerances; heavy damping as in continuum_kv
    v_scale = 1.0
    s_scale = 1.0
    if tau0 > 0.8:
        s_scale = (0.8 / tau0) ** (1.0 / 3.0)
        v_scale = s_scale * s_scale / tau0
    atol = np.full(mm, rtol)
    atol[0] = rtol * s_scale
    atol[1] = rtol * v_scale

    y = np.zeros(mm)
    y1 = np.zeros(mm)
    tmp = np.zeros(mm)
    K = np.zeros((7, mm))
    Ks = np.zeros((7, mm))
    ys = np.zeros(mm)
    e_val = np.zeros(n + 1)
    kh = np.zeros(1, dtype=np.int64)  # the history step of the last edge
    cap = 64
    rc = np.zeros((cap, 5, m_l))
    hs = np.zeros(cap + 1)
    nh = 0

    phase = 0
    m = m_l
    y[1] = 1.0
    if tang:
        y[3 + 2 * n + 1] = 1.0
    Fz, Fx = _rhs_once(phase, y, K, 0, tau0, ga, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val,
                       kh)
    h = 0.05 * min(1.0, s_scale)
    sig = 0.0
    err_old = 1e-4
    rejected = False
    status = STATUS_TIME_LIMIT
    steps = 0
    u_max = 0.0
    s_max = 0.0
    t_turn = 0.0
    while steps < max_steps:
        if h <= 4.0 * _EPS * abs(sig) or not (h > 0.0):
            status = STATUS_NON_FINITE
            break
        err = _step(phase, m, y, h, K, y1, tmp, tau0, ga, itau, n, kappa, mu_t, tang, rc, hs, nh,
                    e_val, atol, rtol, kh)
        if not (err <= 1.0):
            h *= rejected_step_factor(err)
            rejected = True
            continue
        steps += 1
        h_next = h * accepted_step_factor(err, err_old, rejected)
        err_old = max(err, 1e-4)
        rejected = False
        comp = 1 if phase == 0 else 0
        event = y1[comp] <= 0.0
        if event and y1[comp] < 0.0:
            # re-take the step so that component comp is zero at its end
            for c in range(m):
                Ks[0, c] = K[0, c]
            lo = 0.0
            hi = h
            g0 = y[comp]
            best_h = h
            best_g = y1[comp]
            for c in range(m):
                ys[c] = y1[c]
            for r in range(7):
                for c in range(m):
                    Ks[r, c] = K[r, c]
            hp = h * g0 / (g0 - y1[comp])
            tiny = 4.0 * _EPS * (abs(sig) + h)
            for _ in range(40):
                if not (lo < hp < hi):
                    hp = 0.5 * (lo + hi)
                _step(phase, m, y, hp, K, y1, tmp, tau0, ga, itau, n, kappa, mu_t, tang, rc,
                      hs, nh, e_val, atol, rtol, kh)
                gv = y1[comp]
                if abs(gv) <= abs(best_g):
                    best_h = hp
                    best_g = gv
                    for c in range(m):
                        ys[c] = y1[c]
                    for r in range(1, 7):
                        for c in range(m):
                            Ks[r, c] = K[r, c]
                if gv == 0.0:
                    break
                if gv > 0.0:
                    lo = hp
                else:
                    hi = hp
                dg = K[6, comp]
                hn = hp - gv / dg if dg != 0.0 else 0.5 * (lo + hi)
                if not (lo < hn < hi):
                    hn = 0.5 * (lo + hi)
                if abs(hn - hp) <= tiny or hi - lo <= tiny:
                    break
                hp = hn
            h = best_h
            for c in range(m):
                y1[c] = ys[c]
            for r in range(1, 7):
                for c in range(m):
                    K[r, c] = Ks[r, c]
        if phase == 0:
            if nh + 1 >= rc.shape[0]:  # grow the history (rare: doubling)
                rc2 = np.empty((2 * rc.shape[0], 5, m_l))
                rc2[:nh] = rc[:nh]
                hs2 = np.empty(2 * rc.shape[0] + 1)
                hs2[:nh + 1] = hs[:nh + 1]
                rc = rc2
                hs = hs2
            _store(rc, hs, nh, y, y1, K, h, m)
            nh += 1
        elif y1[0] > y[0] + 100.0 * rtol * s_max:  # edge moving outward: re-entry
            status = STATUS_ASSUMPTION
            for c in range(m):
                y[c] = y1[c]
            break
        sig += h
        for c in range(m):
            y[c] = y1[c]
            K[0, c] = K[6, c]
        h = h_next
        finite = True
        for c in range(m):
            if not math.isfinite(y[c]):
                finite = False
        if not finite:
            status = STATUS_NON_FINITE
            break
        if event and phase == 1:
            y[0] = 0.0
            status = STATUS_OK
            break
        if event:  # turning point: switch to the unloading state
            y[1] = 0.0
            s_max = y[0]
            u_max = s_max * s_max
            t_turn = y[2]
            hs[nh] = s_max
            z = np.zeros(mm)
            z[0] = s_max
            z[1] = 0.0
            z[2] = t_turn
            z[3] = u_max
            for i in range(n):
                z[4 + i] = y[3 + i]
            if tang:
                o = 3 + 2 * n
                z[4 + n] = y[o]
                z[4 + n + 1] = y[o + 1]
                for i in range(n):
                    z[4 + n + 2 + i] = y[o + 3 + i]
            for c in range(mm):
                y[c] = z[c]
            phase = 1
            m = m_u
            kh[0] = nh - 1
            atol[3] = rtol * (s_scale * s_scale)
            if tau0 > 0.0:
                atol[0] = rtol * min(s_max, (v_scale / (1.25 * tau0)) ** (1.0 / 3.0))
            Fz, Fx = _rhs_once(phase, y, K, 0, tau0, ga, itau, n, kappa, mu_t, tang, rc, hs, nh,
                               e_val, kh)
            # restart small: the right-hand side is not smooth in the edge state
            # at the turning point, and there the error estimate of a long step
            # misses most of its error (measured: 10-20x the error otherwise)
            h = h_next * UNLOAD_FIRST_STEP
            err_old = 1e-4
            if n_rec > 0 and steps % rec_every == 0:
                i_rec = _rec_state(rec, i_rec, phase, y, K, tau0, ga, itau, n, kappa, mu_t,
                                   tang, rc, hs, nh, e_val, kh)
            continue
        if phase == 0 and y[0] * y[0] > u_max:
            u_max = y[0] * y[0]
        if n_rec > 0 and steps % rec_every == 0:
            i_rec = _rec_state(rec, i_rec, phase, y, K, tau0, ga, itau, n, kappa, mu_t, tang, rc,
                               hs, nh, e_val, kh)
    if status == STATUS_OK and (n > 0 or tau0 > 0.0):
        a_end = np.empty(max(n, 1))
        for i in range(n):
            a_end[i] = y[4 + i]
        tol_c = 10.0 * rtol * max(u_max, 1e-300)
        if _surface_catches(y[3], y[1], a_end, n, ga, ta, tau0, tol_c):
            status = STATUS_ASSUMPTION
    if n_rec > 0:
        i_rec = _rec_state(rec, min(i_rec, n_rec - 1), phase, y, K, tau0, ga, itau, n, kappa,
                           mu_t, tang, rc, hs, nh, e_val, kh)
        if status == STATUS_OK:
            rec[i_rec - 1, 4] = 0.0
            rec[i_rec - 1, 5] = 0.0
            rec[i_rec - 1, 6] = 0.0
    out[OUT_VZ_END] = y[1]
    if tang:
        out[OUT_VC_END] = y[3 + 2 * n + 1] if phase == 0 else y[4 + n + 1]
    else:
        out[OUT_VC_END] = 0.0
    out[OUT_T_CONTACT] = y[2]
    out[OUT_U_MAX] = u_max
    out[OUT_B_MAX] = math.sqrt(u_max)
    out[OUT_STATUS] = status
    out[OUT_STEPS] = steps
    out[OUT_N_REC] = i_rec
    return i_rec


@jit()
def _rec_state(rec, i_rec, phase, y, K, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val,
               kh):
    """Record the current state (forces recomputed at it)."""
    Fz, Fx = _rhs_once(phase, y, K, 6, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, e_val,
                       kh)
    if phase == 0:
        u = y[0] * y[0]
        vc = y[3 + 2 * n + 1] if tang else 0.0
    else:
        u = y[3]
        vc = y[4 + n + 1] if tang else 0.0
    return _record(rec, i_rec, y[2], u, y[1], vc, Fz, Fx, max(y[0], 0.0))


@jit(parallel=True)
def maxwell_stick_batch(tau0, g, tau, n_arms, kappa, mu_t, tangential, rtol, max_steps, out):
    """Many continuum full-stick impacts in parallel.

    ``tau0``, ``n_arms``, ``kappa``, ``mu_t``, ``tangential`` are ``(n,)``;
    ``g``, ``tau`` are ``(n, max_arms)`` (row ``i`` uses its first ``n_arms[i]``
    entries); ``out`` is ``(n, N_OUT)``. ``rtol`` and ``max_steps`` are shared.
    Each row is what :func:`maxwell_stick_impact` writes for the same arguments.
    """
    nrow = tau0.shape[0]
    no_rec = np.zeros((0, N_REC))
    for i in prange(nrow):
        k = n_arms[i]
        maxwell_stick_impact(tau0[i], g[i, :k], tau[i, :k], kappa[i], mu_t[i], tangential[i],
                             rtol, max_steps, no_rec, 1, out[i])
