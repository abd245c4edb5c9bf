"""Continuum (``dx -> 0``) kernel of the full-stick impact for every rheology.

docs/physics.md#continuum-limit: with incremental tangential memory (Maw, Barber and
Fawcett) and full stick, the element row's continuum limit is a small ODE
system for any generalized Maxwell half-space with an optional parallel
dashpot (elastic, Kelvin-Voigt, standard solid, Prony series), any ``nu``
(through ``kappa = c_t / c_n = 2 (1 - nu) / (2 - nu)``) and any moment of
inertia (through ``mu_t = 1 + m R^2 / Theta``; 1 without rotation), with arms
of any relaxation time (docs/physics.md#arms-of-any-relaxation-time).

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
Each arm is carried by its strain ``D_i = u - A_i`` (``A_i`` the arm filter of
``u``, ``tau_i dA_i/dt = u - A_i``) and, tangentially, ``E_i = w_c - B_i``.
Loading (``v >= 0``): the contact is ``[0, b]``, ``b = sqrt(u)``, and

    F_z = gn [ 2/3 b^3 + tau0 v b + sum_i g_i (D_i b + S_i) ]
    F_x = gn kappa [ w_c b - I + tau0 v_c b + sum_i g_i (E_i b + U_i) ]
    dD_i/dt = v - D_i/tau_i,      dS_i/dt = -S_i/tau_i - D_i db/dt
    dE_i/dt = v_c - E_i/tau_i,    dU_i/dt = -U_i/tau_i - E_i db/dt
    dI/dt = w_c db/dt,   dv/dt = -F_z,   dv_c/dt = -mu_t F_x

Unloading (``v < 0``): an element that entered at ``t_e`` carries the normal
force density ``f(t_e, t) = (u - u_e) + tau0 v + sum_i g_i [D_i - e_i D_i(t_e)]``
with ``u_e = u(t_e)``, ``e_i = exp(-(t - t_e)/tau_i)``; the edge ``b = sqrt(u_e*)``
is where it vanishes, and the integrals over ``[0, b]`` are the loading
accumulators at ``t_e*``, decayed: ``e_i S_i(t_e*)``, ``e_i U_i(t_e*)``,
``I(t_e*)``. The edge is a state: differentiating ``f(t_e*, t) = 0`` along the
loading history gives

    d(b^2)/dt = [v - tau0 F_z + sum_i g_i (v - (D_i - e_i D_i(t_e*))/tau_i)]
                / (1 + sum_i g_i e_i)

regular at the turning point and at the end of contact (for Kelvin-Voigt
it is section 5's ``d(u + tau0 v)/dt``).

Independent variable: as in :mod:`vimpact.kernels.continuum_kv`, the contact
half-width ``s = b`` is a state and time is advanced through a Sundman
variable ``sigma`` with ``dt = 2 s dsigma``. Loading (``s^2 = u``):
``ds/dsigma = v``; unloading: ``ds/dsigma = d(b^2)/dt``.

Arms of any relaxation time
---------------------------
The arm quantities ``X`` in ``(D_i, S_i, E_i, U_i)`` obey ``dX/dt = P - X/tau``
with a drive ``P`` that is bounded for every ``tau`` (``v``, ``-D db/dt``,
``v_c``, ``-E db/dt``); their stiffness ``1/tau`` is what limited the explicit
method to steps of about ``tau``. They are not Runge-Kutta components: at
every stage (and at the step's end) each is the exact solution of its filter
over ``[t_0, t_r]`` (``Delta = t_r - t_0``, ``z = Delta/tau``) for the cubic drive
with the step's start value ``P_0`` and slope ``P'_0``, the stage's end value
``P_r`` and the stage's integral ``J = int P dt``:

    X_r = exp(-z) X_0 + Delta (c_0 P_0 + c_1 Delta P'_0 + c_r P_r) + c_J J

(weights from ``phi_k(-z)``, :func:`_filter_weights`). ``J`` is the Runge-Kutta
stage increment of a non-stiff quantity: ``u`` for ``D``, ``w_c`` for ``E``, and
the integrals ``J_S = int -D v dsigma``, ``J_U = int -E v dsigma`` (Runge-Kutta
components, in the error norm); the slopes need the accelerations at the
step's start, kept in the state. So ``tau -> inf`` gives ``X_r = X_0 + J`` (a
spring: the Runge-Kutta update itself), ``tau -> 0`` gives ``X_r -> tau P_r``
(the arm is the dashpot ``g_i tau_i``, evaluated at the stage like ``tau0``),
continuously; a fast arm costs no extra steps and the cost per step is linear
in the number of arms. Unloading needs the strain rates ``dD_i/dt = v - D_i/tau_i``
in the edge equation: they are updated by the same filter (quadratic drive
``dv/dt``, integral the stage increment of ``v``) rather than formed as that
difference, which cancels to ``g_i tau_i dv/dt`` for a fast arm and magnified
the stage values' inconsistency (first order). The loading history keeps
the arm quantities at the start of every step; at any ``theta`` of a step
they follow from the same formula on the step's dense output.

The update's error enters the forces times the arm moduli: the steps are
controlled at ``rtol / (1 + sum_i g_i)`` (glassy over relaxed modulus).
Measured against the implicit scipy oracle on random scenes with arms down
to 1e-6 T and glassy/relaxed ratios up to 1e4: within about 30 ``rtol``
(tests/kernels/test_continuum_maxwell.py). Arms in transition (``tau`` of the
order of the step) with a large modulus cost the most steps: the update reads
the stages' ``u`` and ``v``, which the explicit method computes to low order.

Integrator: Dormand-Prince 5(4) on the Runge-Kutta components with PI
step-size control (the tableau of :mod:`vimpact.kernels.continuum_kv`),
error norm RMS over them with ``atol = rtol`` (``s``, ``v`` scaled for heavy
damping as there). The unloading restarts with ``UNLOAD_FIRST_STEP`` times
the proposed step: at the turning point the history is a square-root
function of the edge state (``t_e(b)``), and the error estimate of a long
first step misses most of its error. Events (``v = 0`` turning point, ``s = 0``
end of contact) are located by re-taking the step with Newton on its length
(derivative from the FSAL stage), safeguarded by bisection, so the event
state is an ordinary step. Arms with ``tau_i = 0`` follow ``u`` at once and
carry no force (dropped); ``tau_i = inf`` is a spring in parallel.

Assumptions (checked while running)
-----------------------------------
- The contact stays one interval ``[0, b]``. This holds by itself: along the
  loading history ``df/dt_e = -v(t_e) (1 + sum_i g_i e_i) < 0`` (``v > 0`` while
  loading), so ``f`` falls monotonically from the centre to the outermost
  element and has one root (not checked; the force density at the edge, zero
  up to the integration error, is kept in ``e_val[n]`` of the right-hand side).
- No element re-enters: the edge never moves outward on unloading
  (``b`` grows by more than ``100 rtol b_max`` over an accepted step).
- After separation the free surface must not catch the sphere: the centre
  element (the last to leave, the deepest point) relaxes freely from its
  state at the end (exact exponential arm update, implicit surface), checked
  on 200 steps up to the time the sphere's lowest point is back at the
  original surface (``u = 0``) and then up to twice that.
A violation gives ``STATUS_ASSUMPTION`` (outputs of the last state, which
are not the impact's): the element row must take the scene.

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

Compile time
------------
A fresh clone compiles this kernel on its first impact, so it is written to
compile little: the helpers are called functions (numba's IR inlining costs
more than a call), every call passes typed values (``np.int64``, ``np.bool_``:
a literal argument compiles the callee once more), the helpers that allocate
nothing compile without reference counting (``jit(nrt=False)``), all of it
without numba's rewrite passes (scalar code: ``jit(rewrites=False)``), the kernel
allocates arrays of two types only (1-D and 2-D float: numba compiles each
allocation type), and no array is reassigned inside the loop of steps (numba
versions it at every branch there, each copy with its reference counting).
numba links each callee's module into its caller's and optimizes it again
there, so the right-hand side is called from the step and the kernel only (the
trajectory recording takes the forces as arguments).
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
    _EPS,
    RTOL_MAX,
    RTOL_MIN,
    accepted_step_factor,
    rejected_step_factor,
    step_underflow,
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

# Dormand-Prince continuous extension (Hairer, Norsett & Wanner, DOPRI5 ``contd5``)
_D1 = -12715105075.0 / 11282082432.0
_D3 = 87487479700.0 / 32700410799.0
_D4 = -10690763975.0 / 1880347072.0
_D5 = 701980252875.0 / 199316789632.0
_D6 = -1453857185.0 / 822651844.0
_D7 = 69997945.0 / 29380423.0

# state layout, loading: s, v, t, D[n], S[n], J_S[n], (w_c, v_c, I, E[n], U[n], J_U[n]),
#   dv/dt, (dv_c/dt)
# state layout, unloading: s, v, t, u, D[n], (w_c, v_c, E[n]), dD/dt[n], dv/dt, (dv_c/dt)
# D, S, E, U, dD/dt (and dv/dt, kept for the next step) are the arm quantities
# (exact filter updates, not Runge-Kutta components)
_LS, _LV, _LT = 0, 1, 2
_US, _UV, _UT, _UU = 0, 1, 2, 3

_N_CHECK = 200  # steps of the post-separation surface check
#: first unloading step as a fraction of the step the loading phase proposed
UNLOAD_FIRST_STEP = 1e-3
#: below this ``z = Delta/tau`` the filter weights are evaluated by their series
_Z_SERIES = 0.2
_INV_FACT = np.array([1.0 / math.factorial(k) for k in range(16)])


@jit(internal=True, nrt=False, rewrites=False)
def _rk_mask(phase, n, tang, mask):
    """Write the Runge-Kutta mask of a phase's state into ``mask``; return its count.

    1 for the Runge-Kutta components, 0 for the arm quantities (and unused slots).
    """
    for c in range(mask.shape[0]):
        mask[c] = 0.0
    if phase == 0:
        for c in range(3):
            mask[c] = 1.0
        for i in range(n):
            mask[3 + 2 * n + i] = 1.0
        if tang:
            o = 3 + 3 * n
            for c in range(3):
                mask[o + c] = 1.0
            for i in range(n):
                mask[o + 3 + 2 * n + i] = 1.0
        return 3 + n + (3 + n if tang else 0)
    for c in range(4):
        mask[c] = 1.0
    if tang:
        mask[4 + n] = 1.0
        mask[5 + n] = 1.0
    return 4 + (2 if tang else 0)


@jit(internal=True, nrt=False, rewrites=False)
def _filter_weights(z):
    """Weights of the exact filter updates (module docstring) for ``z = Delta/tau``.

    Returns ``(exp(-z), w_0, w_r, w_J, c_0, c_1, c_r, c_J)``: the quadratic drive
    (``P_0``, ``P_r``, ``J``) gives ``X_r = exp(-z) X_0 + Delta (w_0 P_0 + w_r P_r)
    + w_J J`` with ``w_0 = phi_1 - 4 phi_2 + 6 phi_3``, ``w_r = 6 phi_3 - 2 phi_2``,
    ``w_J = 6 phi_2 - 12 phi_3``; the cubic drive (also ``P'_0``) gives
    ``exp(-z) X_0 + Delta (c_0 P_0 + c_1 Delta P'_0 + c_r P_r) + c_J J`` with
    ``c_0 = phi_1 - 18 phi_3 + 48 phi_4``, ``c_1 = phi_2 - 6 phi_3 + 12 phi_4``,
    ``c_r = 24 phi_4 - 6 phi_3``, ``c_J = 24 phi_3 - 72 phi_4``; all ``phi_k`` at
    ``-z`` (``z >= 0``; small negative ``z`` below the first loading step). By
    their series for ``|z| < _Z_SERIES``, else from ``expm1`` and the recurrence
    ``phi_(k+1)(x) = (phi_k(x) - 1/k!)/x``.
    """
    if abs(z) < _Z_SERIES:
        # phi_k(-z) = sum_m (-z)^m / (m + k)!, Horner, to m = 11 (|z|^12 / 12! < 1e-16)
        p1 = 1.0 / 479001600.0
        p2 = 1.0 / 6227020800.0
        p3 = 1.0 / 87178291200.0
        p4 = 1.0 / 1307674368000.0
        for m in range(10, -1, -1):
            p4 = p4 * (-z) + _INV_FACT[m + 4]
            p3 = p3 * (-z) + _INV_FACT[m + 3]
            p2 = p2 * (-z) + _INV_FACT[m + 2]
            p1 = p1 * (-z) + _INV_FACT[m + 1]
        ez = 1.0 - z * p1
    else:
        om = -math.expm1(-z)  # 1 - exp(-z)
        ez = 1.0 - om
        p1 = om / z
        p2 = (1.0 - p1) / z
        p3 = (0.5 - p2) / z
        p4 = (1.0 / 6.0 - p3) / z
    return (ez, p1 - 4.0 * p2 + 6.0 * p3, 6.0 * p3 - 2.0 * p2, 6.0 * p2 - 12.0 * p3,
            p1 - 18.0 * p3 + 48.0 * p4, p2 - 6.0 * p3 + 12.0 * p4, 24.0 * p4 - 6.0 * p3,
            24.0 * p3 - 72.0 * p4)


@jit(internal=True, nrt=False, rewrites=False)
def _arm(x0, ez, w0, wr, wj, dt, p0, pr, j):
    """Return the quadratic-drive filter update ``exp(-z) X_0 + Delta (w_0 P_0 + w_r P_r) + w_J J``."""
    return ez * x0 + dt * (w0 * p0 + wr * pr) + wj * j


@jit(internal=True, nrt=False, rewrites=False)
def _arm3(x0, ez, c0, c1, cr, cj, dt, p0, dp0, pr, j):
    """Return the cubic-drive filter update of an arm quantity.

    ``exp(-z) X_0 + Delta (c_0 P_0 + c_1 Delta P'_0 + c_r P_r) + c_J J``.
    """
    return ez * x0 + dt * (c0 * p0 + c1 * dt * dp0 + cr * pr) + cj * j


@jit(internal=True, nrt=False, rewrites=False)
def _rhs(phase, y0, x, K, r, advance, tau0, g, itau, n, kappa, mu_t, tang, rc, hs, nh, ah,
         e_val):
    """Right-hand side ``dx/dsigma`` into ``K[r]``; returns ``(F_z, F_x)``.

    With ``advance`` the arm quantities of ``x`` are first set by their exact
    filter update from the step's start ``y0`` (module docstring); without, ``x``
    holds them already. Their entries of ``K[r]`` are 0. Unloading reads the
    loading history (``rc``, ``hs``, ``nh``, ``ah``) at the edge; ``e_val``
    receives the decay factors there and, at ``n``, the force density at the
    edge (zero up to the integration error); ``e_val[n + 1:5 n + 1]`` keeps
    each arm's step weights between its strain and strain-rate updates, and
    ``e_val[5 n + 1]`` the loading step of the last edge (:func:`_edge`).
    """
    Kr = K[r]
    s = x[0]
    v = x[1]
    t = x[2]
    dt = t - y0[2]
    if phase == 0:
        s2 = s * s
        acc = 2.0 / 3.0 * s2 * s + tau0 * v * s
        o = 3 + 3 * n
        la = o + (3 + 3 * n if tang else 0)
        rate = 0.5 * v / s if s > 0.0 else 0.0  # db/dt
        rate0 = 0.5 * y0[1] / y0[0] if y0[0] > 0.0 else 0.0
        # d^2 b/dt^2 at the step's start (0 at the first touch, where the drives vanish)
        accel0 = (0.5 * y0[la] / y0[0] - 0.25 * y0[1] * y0[1] / (y0[0] * y0[0] * y0[0])
                  if y0[0] > 0.0 else 0.0)
        du = s2 - y0[0] * y0[0]
        wc = 0.0
        vc = 0.0
        accx = 0.0
        if tang:
            wc = x[o]
            vc = x[o + 1]
            accx = wc * s - x[o + 2] + tau0 * vc * s
        for i in range(n):
            # slots of arm i: D, S, J_S and (tangential) E, U, J_U
            iD = 3 + i
            iS = iD + n
            iJ = iS + n
            iE = o + iD
            iU = iE + n
            iJU = iU + n
            if advance:
                ez, w0, wr, wj, c0, c1, cr, cj = _filter_weights(dt * itau[i])
                d = _arm3(y0[iD], ez, c0, c1, cr, cj, dt, y0[1], y0[la], v, du)
                x[iD] = d
                d0 = y0[iD]
                x[iS] = _arm3(y0[iS], ez, c0, c1, cr, cj, dt, -d0 * rate0,
                              -(y0[1] - d0 * itau[i]) * rate0 - d0 * accel0, -d * rate,
                              x[iJ] - y0[iJ])
                if tang:
                    ee = _arm3(y0[iE], ez, c0, c1, cr, cj, dt, y0[o + 1], y0[la + 1], vc,
                               wc - y0[o])
                    x[iE] = ee
                    e0 = y0[iE]
                    x[iU] = _arm3(y0[iU], ez, c0, c1, cr, cj, dt, -e0 * rate0,
                                  -(y0[o + 1] - e0 * itau[i]) * rate0 - e0 * accel0, -ee * rate,
                                  x[iJU] - y0[iJU])
            d = x[iD]
            acc += g[i] * (d * s + x[iS])
            Kr[iD] = 0.0
            Kr[iS] = 0.0
            Kr[iJ] = -d * v
            if tang:
                ee = x[iE]
                accx += g[i] * (ee * s + x[iU])
                Kr[iE] = 0.0
                Kr[iU] = 0.0
                Kr[iJU] = -ee * v
        Fz = GN * acc
        Kr[0] = v
        Kr[1] = -2.0 * s * Fz
        Kr[2] = 2.0 * s
        x[la] = -Fz
        Kr[la] = 0.0
        Fx = 0.0
        if tang:
            Fx = GN * kappa * accx
            Kr[o] = 2.0 * s * vc
            Kr[o + 1] = -2.0 * s * mu_t * Fx
            Kr[o + 2] = wc * v
            x[la + 1] = -mu_t * Fx
            Kr[la + 1] = 0.0
        return Fz, Fx
    u = x[3]
    du = u - y0[3]
    o = 4 + n
    wc = 0.0
    vc = 0.0
    if tang:
        wc = x[o]
        vc = x[o + 1]
    k, th = _edge(rc, hs, nh, s, e_val, 5 * n + 1)
    te = _dense(rc, k, th, np.int64(_LT))
    ue = s * s
    # the loading step's dense output at the edge, for the arm quantities there
    rk = rc[5 * k]  # the state at the start of step k
    ahk = ah[k]  # its arm quantities
    sk = rk[_LS]
    vk = rk[_LV]
    dte = te - rk[_LT]
    ve = _dense(rc, k, th, np.int64(_LV)) if n > 0 else 0.0
    rate_e = 0.5 * ve / s if s > 0.0 else 0.0
    rate_k = 0.5 * vk / sk if sk > 0.0 else 0.0
    accel_k = 0.0
    due = ue - sk * sk
    ol = 3 + 3 * n
    la = ol + (3 + 3 * n if tang else 0)
    ou = o + (2 + n if tang else 0)
    if sk > 0.0:
        accel_k = 0.5 * rk[la] / sk - 0.25 * vk * vk / (sk * sk * sk)
    wce = 0.0
    vce = 0.0
    accx = 0.0
    if tang:
        if n > 0:
            wce = _dense(rc, k, th, ol)
            vce = _dense(rc, k, th, ol + 1)
        accx = wc * s - _dense(rc, k, th, ol + 2) + tau0 * vc * s
    acc = u * s - s * s * s / 3.0 + tau0 * v * s
    den = 1.0
    ft = 0.0
    fe = u - ue + tau0 * v
    for i in range(n):
        iD = 4 + i  # slots of arm i: D and (tangential) E
        iE = o + 2 + i
        iJ = 3 + 2 * n + i  # J_S and J_U of the loading layout
        iJU = ol + iJ
        if advance:
            ez, w0, wr, wj, c0, c1, cr, cj = _filter_weights(dt * itau[i])
            w = n + 1 + 4 * i  # the step's weights, kept for the strain rate below
            e_val[w] = ez
            e_val[w + 1] = w0
            e_val[w + 2] = wr
            e_val[w + 3] = wj
            x[iD] = _arm3(y0[iD], ez, c0, c1, cr, cj, dt, y0[1], y0[ou + n], v, du)
            if tang:
                x[iE] = _arm3(y0[iE], ez, c0, c1, cr, cj, dt, y0[o + 1], y0[ou + n + 1], vc,
                              wc - y0[o])
        d = x[iD]
        # arm quantities of the edge element at its entry (loading history)
        ez, w0, wr, wj, c0, c1, cr, cj = _filter_weights(dte * itau[i])
        dk = ahk[i]
        de = _arm3(dk, ez, c0, c1, cr, cj, dte, vk, rk[la], ve, due)
        se = _arm3(ahk[n + i], ez, c0, c1, cr, cj, dte, -dk * rate_k,
                   -(vk - dk * itau[i]) * rate_k - dk * accel_k, -de * rate_e,
                   _dense(rc, k, th, iJ) - rk[iJ])
        e = math.exp(-(t - te) * itau[i])
        e_val[i] = e
        acc += g[i] * (d * s + e * se)
        den += g[i] * e
        fe += g[i] * (d - e * de)
        ft += g[i] * e * de * itau[i]
        Kr[iD] = 0.0
        if tang:
            ee = x[iE]
            ek = ahk[2 * n + i]
            eee = _arm3(ek, ez, c0, c1, cr, cj, dte, rk[ol + 1], rk[la + 1], vce, wce - rk[ol])
            ue_i = _arm3(ahk[3 * n + i], ez, c0, c1, cr, cj, dte, -ek * rate_k,
                         -(rk[ol + 1] - ek * itau[i]) * rate_k - ek * accel_k, -eee * rate_e,
                         _dense(rc, k, th, iJU) - rk[iJU])
            accx += g[i] * (ee * s + e * ue_i)
            Kr[iE] = 0.0
    Fz = GN * acc
    e_val[n] = fe
    # the arm strain rates dD_i/dt = v - D_i/tau_i, by their own filter update
    # (drive dv/dt = -F_z): v - D_i/tau_i itself would cancel to g_i tau_i dv/dt
    # for a fast arm and carry the stage values' inconsistency (first order)
    for i in range(n):
        if advance:
            w = n + 1 + 4 * i
            x[ou + i] = _arm(y0[ou + i], e_val[w], e_val[w + 1], e_val[w + 2], e_val[w + 3], dt,
                             y0[ou + n], -Fz, v - y0[1])
        ft += g[i] * x[ou + i]
        Kr[ou + i] = 0.0
    x[ou + n] = -Fz
    Kr[ou + n] = 0.0
    ft += v - tau0 * Fz
    Kr[0] = ft / den
    Kr[1] = -2.0 * s * Fz
    Kr[2] = 2.0 * s
    Kr[3] = 2.0 * s * v
    Fx = 0.0
    if tang:
        Fx = GN * kappa * accx
        Kr[o] = 2.0 * s * vc
        Kr[o + 1] = -2.0 * s * mu_t * Fx
        x[ou + n + 1] = -mu_t * Fx
        Kr[ou + n + 1] = 0.0
    return Fz, Fx


@jit(internal=True, nrt=False, rewrites=False)
def _dense(rc, k, th, c):
    """Dense-output value of component ``c`` of stored step ``k`` at ``theta = th``.

    ``rc`` holds the five coefficient rows of step ``k`` at rows ``5 k .. 5 k + 4``
    (:func:`_store`; 2-D, so that the kernel allocates no 3-D array).
    """
    th1 = 1.0 - th
    b = 5 * k
    return rc[b, c] + th * (rc[b + 1, c] + th1 * (rc[b + 2, c] + th * (rc[b + 3, c]
                                                                      + th1 * rc[b + 4, c])))


@jit(internal=True, nrt=False, rewrites=False)
def _dense_d(rc, k, th, c):
    """``d/dtheta`` of :func:`_dense`."""
    b = 5 * k
    r1 = rc[b + 1, c]
    r2 = rc[b + 2, c]
    r3 = rc[b + 3, c]
    r4 = rc[b + 4, c]
    # p = r0 + th r1 + th (1-th) r2 + th^2 (1-th) r3 + th^2 (1-th)^2 r4
    return (r1 + (1.0 - 2.0 * th) * r2 + (2.0 * th - 3.0 * th * th) * r3
            + (2.0 * th - 6.0 * th * th + 4.0 * th * th * th) * r4)


@jit(internal=True, nrt=False, rewrites=False)
def _edge(rc, hs, nh, s_t, hint, ih):
    """Return the loading step ``k`` and ``theta`` with ``s(k, theta) = s_t``.

    ``hs`` holds ``s`` at the start of each stored step (increasing) and, at
    ``nh``, at the end of the last one. Below 0 the first step's polynomial is
    extended (``theta < 0``), above the turning point ``theta = 1``. The step
    is searched from ``hint[ih]``, the previous call's (the edge moves little
    between calls), and stored there: the same step as a bisection over all
    steps, the last with ``hs[k] <= s_t``. (The step is an integer kept in a
    float array: the kernel allocates no integer array.)
    """
    if s_t >= hs[nh]:
        return nh - 1, 1.0
    if s_t <= 0.0:
        k = 0
        lo = -1.0
        hi = 0.0
        th = s_t / (hs[1] - hs[0]) if hs[1] > hs[0] else 0.0
    else:
        k = int(hint[ih])
        if k < 0:
            k = 0
        if nh - 1 < k:
            k = nh - 1
        while k > 0 and hs[k] > s_t:
            k -= 1
        while k < nh - 1 and hs[k + 1] <= s_t:
            k += 1
        hint[ih] = k
        lo = 0.0
        hi = 1.0
        th = (s_t - hs[k]) / (hs[k + 1] - hs[k])
    for _ in range(60):
        if not (lo <= th <= hi):
            th = 0.5 * (lo + hi)
        p = _dense(rc, k, th, np.int64(0)) - s_t
        if p == 0.0:
            return k, th
        if p < 0.0:
            lo = th
        else:
            hi = th
        dp = _dense_d(rc, k, th, np.int64(0))
        thn = th - p / dp if dp > 0.0 else 0.5 * (lo + hi)
        if not (lo < thn < hi):
            thn = 0.5 * (lo + hi)
        if abs(thn - th) <= 2.0 * _EPS or hi - lo <= 2.0 * _EPS:
            return k, thn
        th = thn
    return k, th


@jit(internal=True, nrt=False, rewrites=False)
def _step(phase, m, y, h, K, y1, tmp, mask, n_rk, tau0, g, itau, n, kappa, mu_t, tang, rc, hs,
          nh, ah, e_val, atol, rtol):
    """Take one Dormand-Prince 5(4) step of length ``h`` (/ T) from ``y``; return its error norm.

    ``K[0]`` is the derivative at ``y``; ``y1`` and ``K[1..6]`` receive the new
    state and stages (``K[6]`` the derivative at ``y1``). The arm quantities of
    every stage and of ``y1`` are their exact filter updates (:func:`_rhs` with
    ``advance``). The error norm (dimensionless, 1 at the tolerance) is taken over
    the ``n_rk`` Runge-Kutta components.
    """
    K0 = K[0]
    K1 = K[1]
    K2 = K[2]
    K3 = K[3]
    K4 = K[4]
    K5 = K[5]
    K6 = K[6]
    for r in range(1, 7):
        if r == 1:
            for c in range(m):
                tmp[c] = y[c] + h * _A21 * K0[c]
        elif r == 2:
            for c in range(m):
                tmp[c] = y[c] + h * (_A31 * K0[c] + _A32 * K1[c])
        elif r == 3:
            for c in range(m):
                tmp[c] = y[c] + h * (_A41 * K0[c] + _A42 * K1[c] + _A43 * K2[c])
        elif r == 4:
            for c in range(m):
                tmp[c] = y[c] + h * (_A51 * K0[c] + _A52 * K1[c] + _A53 * K2[c]
                                     + _A54 * K3[c])
        elif r == 5:
            for c in range(m):
                tmp[c] = y[c] + h * (_A61 * K0[c] + _A62 * K1[c] + _A63 * K2[c]
                                     + _A64 * K3[c] + _A65 * K4[c])
        else:
            for c in range(m):
                tmp[c] = y[c] + h * (_B1 * K0[c] + _B3 * K2[c] + _B4 * K3[c]
                                     + _B5 * K4[c] + _B6 * K5[c])
        _rhs(phase, y, tmp, K, r, np.bool_(True), tau0, g, itau, n, kappa, mu_t, tang, rc, hs,
             nh, ah, e_val)
    for c in range(m):
        y1[c] = tmp[c]
    acc = 0.0
    for c in range(m):
        if mask[c] > 0.0:
            e = h * (_E1 * K0[c] + _E3 * K2[c] + _E4 * K3[c] + _E5 * K4[c]
                     + _E6 * K5[c] + _E7 * K6[c])
            sc = atol[c] + rtol * max(abs(y[c]), abs(y1[c]))
            acc += (e / sc) ** 2
    return math.sqrt(acc / n_rk)


@jit(internal=True, nrt=False, rewrites=False)
def _store(rc, hs, ah, nh, y, y1, K, h, m, n, tang):
    """Write the dense output of an accepted loading step ``nh``.

    Hairer, Norsett & Wanner's ``contd5`` coefficients into rows ``5 nh .. 5 nh + 4``
    of ``rc``, the step's end ``s`` into ``hs[nh + 1]`` and the arm quantities at
    its start into row ``nh`` of ``ah``.
    """
    b = 5 * nh
    R0 = rc[b]
    R1 = rc[b + 1]
    R2 = rc[b + 2]
    R3 = rc[b + 3]
    R4 = rc[b + 4]
    K0 = K[0]
    K2 = K[2]
    K3 = K[3]
    K4 = K[4]
    K5 = K[5]
    K6 = K[6]
    for c in range(m):
        dif = y1[c] - y[c]
        bspl = h * K0[c] - dif
        R0[c] = y[c]
        R1[c] = dif
        R2[c] = bspl
        R3[c] = dif - h * K6[c] - bspl
        R4[c] = h * (_D1 * K0[c] + _D3 * K2[c] + _D4 * K3[c] + _D5 * K4[c] + _D6 * K5[c]
                     + _D7 * K6[c])
    hs[nh + 1] = y1[0]
    for i in range(2 * n):
        ah[nh, i] = y[3 + i]
    if tang:
        o = 3 + 3 * n
        for i in range(2 * n):
            ah[nh, 2 * n + i] = y[o + 3 + i]


@jit(internal=True, rewrites=False)
def _grown_history(rc, hs, ah, nh):
    """Return the loading history with twice the rows, the first ``nh`` steps copied.

    Copied element by element (an array slice assignment compiles numba's
    shape-mismatch error message, about 25 string helpers; a flat view through
    ``reshape`` compiles numba's shape normalization).
    """
    cap = hs.shape[0] - 1
    rc2 = np.zeros((2 * rc.shape[0], rc.shape[1]))
    hs2 = np.zeros(2 * cap + 1)
    ah2 = np.zeros((2 * cap, ah.shape[1]))
    for j in range(5 * nh):
        for c in range(rc.shape[1]):
            rc2[j, c] = rc[j, c]
    for j in range(nh):
        for c in range(ah.shape[1]):
            ah2[j, c] = ah[j, c]
    for j in range(nh + 1):
        hs2[j] = hs[j]
    return rc2, hs2, ah2


@jit(internal=True, nrt=False, rewrites=False)
def _surface_catches(u_end, v_end, work, n, g, tau, tau0, tol):
    """Return whether the free centre element catches the sphere after separation.

    The element starts at ``w = u_end`` with arms ``work[0, :n]`` (overwritten);
    the sphere moves on as ``u = u_end + v_end (t - t_end)`` (kernel units).
    ``work`` is the caller's scratch, at least ``(4, n)``: rows 1-3 receive the
    arms' step factors.
    """
    if not (v_end < 0.0):
        return True
    if n == 0:
        return False  # elastic: back at once; Kelvin-Voigt: w = u_end exp(-dt/tau0) >= u
    t_h = 2.0 * max(u_end, 0.0) / (-v_end)
    if t_h <= 0.0:
        return False
    h = t_h / _N_CHECK
    q = work[0]
    E = work[1]
    omE = work[2]
    phi = work[3]
    w = u_end
    G = 0.0
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


@jit(rewrites=False)
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
    # counters and the phase are int64 from the start (np.int64, not a bare literal):
    # numba types a literal as its own type (Literal[int](0)) and compiles every
    # jitted callee once per argument type it sees while the types settle, which
    # compiled the right-hand side eight times
    i_rec = np.int64(0)
    out[OUT_T_GROSS_SLIP] = 0.0  # no friction on this path
    out[OUT_W_FRICTION] = 0.0
    nin = g.shape[0]
    ok_in = (tau0 >= 0.0 and math.isfinite(tau0) and kappa > 0.0 and math.isfinite(kappa)
             and mu_t > 0.0 and math.isfinite(mu_t) and tau.shape[0] == nin)
    n = np.int64(0)
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
    # every array of the kernel through np.zeros with int64 sizes: numba compiles
    # the allocation once per distinct shape type (a literal size is its own type)
    ga = np.zeros(n)
    ta = np.zeros(n)
    itau = np.zeros(n)
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
    # the arm quantities' update error enters the forces times their moduli:
    # the steps are controlled at rtol / (glassy / relaxed modulus) (module docstring)
    glassy = 1.0
    for i in range(n):
        glassy += ga[i]
    rtol = max(rtol / glassy, RTOL_MIN)
    m_l = 4 + 3 * n + (4 + 3 * n if tang else 0)  # state sizes: loading, unloading
    m_u = 5 + 2 * n + (3 + n if tang else 0)
    mm = m_l if m_l > m_u else m_u
    # absolute tolerances; heavy damping as in continuum_kv
    v_scale = 1.0
    s_scale = 1.0
    if tau0 > 0.8:
        s_scale = (0.8 / tau0) ** (1.0 / 3.0)
        v_scale = s_scale * s_scale / tau0
    atol = np.zeros(mm)
    for c in range(mm):
        atol[c] = rtol
    atol[0] = rtol * s_scale
    atol[1] = rtol * v_scale

    y = np.zeros(mm)
    y1 = np.zeros(mm)
    tmp = np.zeros(mm)
    mask = np.zeros(mm)
    K = np.zeros((np.int64(7), mm))
    # decay factors, edge force density, step weights; last: the history step of the
    # last edge (an integer kept as a float: no second allocation type to compile)
    e_val = np.zeros(5 * n + 2)
    cap = np.int64(64)
    rc = np.zeros((5 * cap, m_l))  # five dense-output rows per step (_store)
    hs = np.zeros(cap + 1)
    ah = np.zeros((cap, 4 * n))
    nh = np.int64(0)

    phase = np.int64(0)
    m = m_l
    n_rk = _rk_mask(phase, n, tang, mask)
    y[1] = 1.0
    if tang:
        y[3 + 3 * n + 1] = 1.0
    Fz, Fx = _rhs(phase, y, y, K, np.int64(0), np.bool_(False), tau0, ga, itau, n, kappa, mu_t,
                  tang, rc, hs, nh, ah, e_val)
    h = 0.05 * min(1.0, s_scale)
    sig = 0.0
    err_old = 1e-4
    rejected = False
    status = STATUS_TIME_LIMIT
    steps = 0
    u_max = 0.0
    s_max = 0.0
    t_turn = 0.0
    # the history grows (rare: doubling) outside the loop of steps, so that the
    # arrays are not reassigned in it: numba versions a variable reassigned in a
    # loop at every branch (SSA), and each copy of an array carries reference
    # counting (measured: a ninth of this function's lowered code)
    grow = False
    while True:
        if grow:
            rc, hs, ah = _grown_history(rc, hs, ah, nh)
            grow = False
        while steps < max_steps:
            if phase == 0 and nh + 1 >= hs.shape[0] - 1:
                grow = True
                break
            if step_underflow(h, sig):
                status = STATUS_NON_FINITE
                break
            err = _step(phase, m, y, h, K, y1, tmp, mask, n_rk, tau0, ga, itau, n, kappa, mu_t, tang,
                        rc, hs, nh, ah, e_val, atol, rtol)
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
                lo = 0.0
                hi = h
                g0 = y[comp]
                best_h = h
                best_g = y1[comp]
                last_h = h  # the step whose state y1 and stages K[1:] hold
                hp = h * g0 / (g0 - y1[comp])
                tiny = 4.0 * _EPS * (abs(sig) + h)
                for _ in range(40):
                    if not (lo < hp < hi):
                        hp = 0.5 * (lo + hi)
                    _step(phase, m, y, hp, K, y1, tmp, mask, n_rk, tau0, ga, itau, n, kappa, mu_t,
                          tang, rc, hs, nh, ah, e_val, atol, rtol)
                    last_h = hp
                    gv = y1[comp]
                    if abs(gv) <= abs(best_g):
                        best_h = hp
                        best_g = gv
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
                if last_h != best_h:
                    # take the best step again rather than keep copies of every candidate's
                    # state and stages: a step is a function of (y, K[0], h) alone, so this
                    # is the same state; the copy loops (unrolled over the seven stages and
                    # vectorized) were a third of this function's compiled code
                    _step(phase, m, y, h, K, y1, tmp, mask, n_rk, tau0, ga, itau, n, kappa, mu_t,
                          tang, rc, hs, nh, ah, e_val, atol, rtol)
            if phase == 0:
                _store(rc, hs, ah, nh, y, y1, K, h, m, n, tang)
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
                # the unloading state is built in y1 (free between steps), then copied
                z = y1
                for c in range(mm):
                    z[c] = 0.0
                z[0] = s_max
                z[1] = 0.0
                z[2] = t_turn
                z[3] = u_max
                for i in range(n):
                    z[4 + i] = y[3 + i]
                if tang:
                    o = 3 + 3 * n
                    z[4 + n] = y[o]
                    z[4 + n + 1] = y[o + 1]
                    for i in range(n):
                        z[4 + n + 2 + i] = y[o + 3 + i]
                ou = 4 + n + (2 + n if tang else 0)
                for i in range(n):
                    z[ou + i] = -z[4 + i] * itau[i]  # dD/dt = v - D/tau at v = 0
                for c in range(mm):
                    y[c] = z[c]
                phase = np.int64(1)
                m = m_u
                n_rk = _rk_mask(phase, n, tang, mask)
                e_val[5 * n + 1] = nh - 1
                for c in range(mm):
                    atol[c] = rtol
                atol[0] = rtol * s_scale
                atol[1] = rtol * v_scale
                atol[3] = rtol * (s_scale * s_scale)
                if tau0 > 0.0:
                    atol[0] = rtol * min(s_max, (v_scale / (1.25 * tau0)) ** (1.0 / 3.0))
                Fz, Fx = _rhs(phase, y, y, K, np.int64(0), np.bool_(False), tau0, ga, itau, n, kappa,
                              mu_t, tang, rc, hs, nh, ah, e_val)
                # restart small: the right-hand side is not smooth in the edge state
                # at the turning point, and there the error estimate of a long step
                # misses most of its error (measured: 10-20x the error otherwise)
                h = h_next * UNLOAD_FIRST_STEP
                err_old = 1e-4
            if phase == 0 and y[0] * y[0] > u_max:
                u_max = y[0] * y[0]
            if n_rec > 0 and steps % rec_every == 0:
                Fz, Fx = _rhs(phase, y, y, K, np.int64(6), np.bool_(False), tau0, ga, itau, n, kappa,
                              mu_t, tang, rc, hs, nh, ah, e_val)
                i_rec = _rec_state(rec, i_rec, phase, y, n, tang, Fz, Fx)
        if not grow:
            break
    if status == STATUS_OK and (n > 0 or tau0 > 0.0):
        # the stages K are free now: scratch of the check (no allocation here)
        for i in range(n):
            K[0, i] = y[3] - y[4 + i]  # A_i = u - D_i
        tol_c = 10.0 * rtol * max(u_max, 1e-300)
        if _surface_catches(y[3], y[1], K, n, ga, ta, tau0, tol_c):
            status = STATUS_ASSUMPTION
    if n_rec > 0:
        Fz, Fx = _rhs(phase, y, y, K, np.int64(6), np.bool_(False), tau0, ga, itau, n, kappa,
                      mu_t, tang, rc, hs, nh, ah, e_val)
        i_rec = _rec_state(rec, n_rec - 1 if n_rec - 1 < i_rec else i_rec, phase, y, n, tang,
                           Fz, Fx)
        if status == STATUS_OK:
            rec[i_rec - 1, 4] = 0.0
            rec[i_rec - 1, 5] = 0.0
            rec[i_rec - 1, 6] = 0.0
    out[OUT_VZ_END] = y[1]
    if tang:
        out[OUT_VC_END] = y[3 + 3 * n + 1] if phase == 0 else y[4 + n + 1]
    else:
        out[OUT_VC_END] = 0.0
    out[OUT_T_CONTACT] = y[2]
    out[OUT_U_MAX] = u_max
    out[OUT_B_MAX] = math.sqrt(u_max)
    out[OUT_STATUS] = status
    out[OUT_STEPS] = steps
    out[OUT_N_REC] = i_rec
    return i_rec


@jit(internal=True, nrt=False, rewrites=False)
def _rec_state(rec, i_rec, phase, y, n, tang, Fz, Fx):
    """Record the current state with its forces ``Fz``, ``Fx`` (:func:`_rhs` at it).

    The caller evaluates the forces: calling :func:`_rhs` from here linked and
    optimized all of it once more in this function's own module.
    """
    if phase == 0:
        u = y[0] * y[0]
        vc = y[3 + 3 * n + 1] if tang else 0.0
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
    # rec_every as int64, not the literal 1: a literal argument would compile the
    # impact kernel once more (for Literal[int](1)) instead of calling the one a
    # single-row run compiled
    for i in prange(nrow):
        k = n_arms[i]
        maxwell_stick_impact(tau0[i], g[i, :k], tau[i, :k], kappa[i], mu_t[i], tangential[i],
                             rtol, max_steps, no_rec, np.int64(1), out[i])
