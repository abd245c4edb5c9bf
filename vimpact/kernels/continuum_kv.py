"""Continuum (1-DOF) kernel of the normal Kelvin-Voigt impact.

docs/physics.md#kelvin-voigt-continuum: for a Kelvin-Voigt half-space with normal motion only,
the element row has a closed-form force, and the impact is the ODE (kernel
units of :mod:`vimpact.kernels.elements`: ``u`` / d, ``t`` / T, ``v`` / v_z0, unit
mass, ``tau0 = eta / (G T)``)

    u(0) = 0, v(0) = 1, du/dt = v, dv/dt = -F
    loading   (v >= 0):  F = 5/4 u^(3/2) + 15/8 tau0 sqrt(u) v
    unloading (v <  0):  F = 5/4 w^(3/2),  w = u + tau0 v,  until w = 0

After ``w = 0`` no element is in contact and none re-enters (the free
Kelvin-Voigt surface recedes faster than the sphere), so the end of contact
is the end of the impact.

Formulation
-----------
In ``t`` the right-hand side is not smooth where the contact is small:
``F ~ sqrt(t)`` at the start (loading) and ``F ~ (t_end - t)^(3/2)`` at the
end (unloading), which costs any Runge-Kutta method its order there. This
kernel integrates instead in the contact half-width ``s = b / a_H`` and a
Sundman-type independent variable ``sigma`` with ``dt = 2 s dsigma``:

    loading   (s^2 = u):  ds/dsigma = v,
                          dv/dsigma = -(5/2 s^4 + 15/4 tau0 s^2 v)
    unloading (s^2 = w):  ds/dsigma = v - 5/4 tau0 s^3,
                          dv/dsigma = -5/2 s^4
    both:                 dt/dsigma = 2 s

(``ds/dsigma = du/dt`` resp. ``dw/dt``; ``dv/dsigma = -2 s F``). Both right-hand
sides are polynomials, so the solution is analytic in ``sigma`` from the first
touch ``s = 0, v = 1, t = 0`` through the end of contact, where ``s`` crosses
zero with slope ``v_end`` (the polynomial extends smoothly past it). ``s`` is
continuous at the turning point (``w = u`` when ``v = 0``), ``ds/dsigma`` jumps
there (the contact radius starts to shrink at once), which is why the
integration restarts on the new branch at that event. ``u = s^2`` (loading),
``u = s^2 - tau0 v`` (unloading); the contact half-width is ``b = s`` in both.

Integrator
----------
Dormand-Prince 5(4) (FSAL, local extrapolation) on the state ``(s, v, t)``
with PI step-size control. Error norm: RMS over the three components of
``err_i / (atol_i + rtol max(|y_i|, |y_i,new|))`` with ``atol_i = ATOL_PER_RTOL
* rtol * scale_i``: ``scale_t = 1``; ``scale_s, scale_v = 1`` for ``tau0 <= 0.8``
and otherwise the sizes that ``s = b`` and ``v`` have near the turning point
and on unloading for heavy damping, where the loading is viscous
(``v ~ 1 - 5/4 tau0 u^(3/2)``): ``u_max ~ (4 / (5 tau0))^(2/3)``, ``|v| ~ e_z ~
u_max / tau0``, and on unloading ``s`` ends in a tail where ``5/4 tau0 s^3 ~
|v|``. Without this (plain ``atol = rtol``) an absolute error in ``v`` larger
than ``e_z`` lets the numerical ``v`` hover just above zero near the turning
point (measured with ``atol = rtol``: ``Q1 = 1e4`` at ``rtol = 1e-6``): no
turning point, ``STATUS_TIME_LIMIT``. Supported: ``0 <= tau0 <~ 1e100`` (beyond,
``v_end`` underflows); the step count grows like ``log(tau0)`` for heavy damping.

Events are state components crossing zero: ``v`` on loading (turning point),
``s`` on unloading (end of contact). An accepted step that crosses is
replaced by a re-taken step of length ``h'`` with the component zero at its
end: a guess from the cubic Hermite interpolant of the step, then Newton on
the Runge-Kutta map ``h' -> y(h')`` (derivative from the FSAL stage, which is
``f(y(h'))``), safeguarded by bisection on the bracket, to a step length
change of a few ulp. The event state is thus an ordinary Runge-Kutta step
(no interpolation error), and the branch restarts exactly there (``v = 0``
set exactly at the turning point).

Units of the outputs as in :mod:`vimpact.kernels.elements`. ``OUT_STEPS`` is the
number of accepted Runge-Kutta steps (each event's re-taken step counts as
one); ``max_steps`` bounds them (``STATUS_TIME_LIMIT``). Rejected steps do not
count; they cannot loop forever because each rejection shrinks the step by a
factor of at least 0.9 and a step below the rounding level of ``sigma``
stops the impact with ``STATUS_NON_FINITE`` (also the status of a ``tau0``
that is negative or not finite, with NaN outputs).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vimpact.kernels.jit import jit
from vimpact.kernels.layout import (
    N_REC,
    OUT_B_MAX,
    OUT_N_REC,
    OUT_STATUS,
    OUT_STEPS,
    OUT_T_CONTACT,
    OUT_U_MAX,
    OUT_VZ_END,
    STATUS_NON_FINITE,
    STATUS_OK,
    STATUS_TIME_LIMIT,
)
from vimpact.kernels.record import _record

__all__ = [
    "ATOL_PER_RTOL",
    "RTOL_MIN",
    "RTOL_MAX",
    "kv_normal_impact",
    "kv_normal_batch",
]

#: Absolute tolerance per unit of ``rtol`` and of the scale of each state
#: component (see the module docstring).
ATOL_PER_RTOL = 1.0
#: ``rtol`` is clamped to ``[RTOL_MIN, RTOL_MAX]``.
RTOL_MIN = 1e-14
RTOL_MAX = 1e-2

_EPS = 2.220446049250313e-16

# ---- Dormand-Prince 5(4) tableau (Dormand & Prince 1980) ----
_C2 = 1.0 / 5.0
_C3 = 3.0 / 10.0
_C4 = 4.0 / 5.0
_C5 = 8.0 / 9.0
_A21 = 1.0 / 5.0
_A31 = 3.0 / 40.0
_A32 = 9.0 / 40.0
_A41 = 44.0 / 45.0
_A42 = -56.0 / 15.0
_A43 = 32.0 / 9.0
_A51 = 19372.0 / 6561.0
_A52 = -25360.0 / 2187.0
_A53 = 64448.0 / 6561.0
_A54 = -212.0 / 729.0
_A61 = 9017.0 / 3168.0
_A62 = -355.0 / 33.0
_A63 = 46732.0 / 5247.0
_A64 = 49.0 / 176.0
_A65 = -5103.0 / 18656.0
# fifth-order weights (= last row, FSAL)
_B1 = 35.0 / 384.0
_B3 = 500.0 / 1113.0
_B4 = 125.0 / 192.0
_B5 = -2187.0 / 6784.0
_B6 = 11.0 / 84.0
# error weights: fifth minus fourth order
_E1 = 71.0 / 57600.0
_E3 = -71.0 / 16695.0
_E4 = 71.0 / 1920.0
_E5 = -17253.0 / 339200.0
_E6 = 22.0 / 525.0
_E7 = -1.0 / 40.0

# PI step-size control (Hairer, Norsett & Wanner, DOPRI5 defaults)
_SAFETY = 0.9
_BETA = 0.04
_ALPHA = 0.2 - 0.75 * _BETA
_FAC_MIN = 0.2
_FAC_MAX = 10.0


@jit()
def _rhs(s, v, tau0, unloading):
    """``d(s, v, t)/dsigma`` on the loading or unloading branch."""
    s2 = s * s
    if unloading:
        return v - 1.25 * tau0 * s2 * s, -2.5 * s2 * s2, 2.0 * s
    return v, -(2.5 * s2 * s2 + 3.75 * tau0 * s2 * v), 2.0 * s


@jit()
def _dp_step(s, v, t, fs, fv, ft, h, tau0, unloading):
    """Take one Dormand-Prince 5(4) step of length ``h`` (/ T) from ``(s, v, t)``.

    ``(fs, fv, ft)`` is the derivative at the start (first same as last). Returns the
    new state, its derivative and the error estimate (fifth minus fourth order
    solution): ``(s1, v1, t1, fs1, fv1, ft1, es, ev, et)``.
    """
    k2s, k2v, k2t = _rhs(s + h * _A21 * fs, v + h * _A21 * fv, tau0, unloading)
    k3s, k3v, k3t = _rhs(s + h * (_A31 * fs + _A32 * k2s),
                         v + h * (_A31 * fv + _A32 * k2v), tau0, unloading)
    k4s, k4v, k4t = _rhs(s + h * (_A41 * fs + _A42 * k2s + _A43 * k3s),
                         v + h * (_A41 * fv + _A42 * k2v + _A43 * k3v), tau0, unloading)
    k5s, k5v, k5t = _rhs(s + h * (_A51 * fs + _A52 * k2s + _A53 * k3s + _A54 * k4s),
                         v + h * (_A51 * fv + _A52 * k2v + _A53 * k3v + _A54 * k4v),
                         tau0, unloading)
    k6s, k6v, k6t = _rhs(s + h * (_A61 * fs + _A62 * k2s + _A63 * k3s + _A64 * k4s + _A65 * k5s),
                         v + h * (_A61 * fv + _A62 * k2v + _A63 * k3v + _A64 * k4v + _A65 * k5v),
                         tau0, unloading)
    s1 = s + h * (_B1 * fs + _B3 * k3s + _B4 * k4s + _B5 * k5s + _B6 * k6s)
    v1 = v + h * (_B1 * fv + _B3 * k3v + _B4 * k4v + _B5 * k5v + _B6 * k6v)
    t1 = t + h * (_B1 * ft + _B3 * k3t + _B4 * k4t + _B5 * k5t + _B6 * k6t)
    k7s, k7v, k7t = _rhs(s1, v1, tau0, unloading)
    es = h * (_E1 * fs + _E3 * k3s + _E4 * k4s + _E5 * k5s + _E6 * k6s + _E7 * k7s)
    ev = h * (_E1 * fv + _E3 * k3v + _E4 * k4v + _E5 * k5v + _E6 * k6v + _E7 * k7v)
    et = h * (_E1 * ft + _E3 * k3t + _E4 * k4t + _E5 * k5t + _E6 * k6t + _E7 * k7t)
    return s1, v1, t1, k7s, k7v, k7t, es, ev, et


@jit()
def _err_norm(es, ev, et, s0, v0, t0, s1, v1, t1, rtol, atol_s, atol_v, atol_t):
    """RMS of the scaled error estimate (NaN stays NaN)."""
    a = es / (atol_s + rtol * max(abs(s0), abs(s1)))
    b = ev / (atol_v + rtol * max(abs(v0), abs(v1)))
    c = et / (atol_t + rtol * max(abs(t0), abs(t1)))
    return math.sqrt((a * a + b * b + c * c) / 3.0)


@jit()
def _hermite_root(y0, d0, y1, d1):
    """Return the root in ``[0, 1]`` of the cubic Hermite interpolant of one step.

    End values ``y0, y1`` (opposite signs or ``y1 = 0``) and end slopes ``d0, d1``
    (per unit ``theta``, the fraction of the step); safeguarded Newton on the cubic
    from the linear guess.
    """
    lo = 0.0
    hi = 1.0
    x = y0 / (y0 - y1)
    for _ in range(30):
        x2 = x * x
        x3 = x2 * x
        h00 = 2.0 * x3 - 3.0 * x2 + 1.0
        h10 = x3 - 2.0 * x2 + x
        h01 = -2.0 * x3 + 3.0 * x2
        h11 = x3 - x2
        p = h00 * y0 + h10 * d0 + h01 * y1 + h11 * d1
        if p == 0.0:
            return x
        if (p > 0.0) == (y0 > 0.0):
            lo = x
        else:
            hi = x
        dp = ((6.0 * x2 - 6.0 * x) * y0 + (3.0 * x2 - 4.0 * x + 1.0) * d0
              + (-6.0 * x2 + 6.0 * x) * y1 + (3.0 * x2 - 2.0 * x) * d1)
        xn = x - p / dp if dp != 0.0 else 0.5 * (lo + hi)
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 4.0 * _EPS:
            return xn
        x = xn
    return x


@jit()
def _locate(s, v, t, fs, fv, ft, sig, h, tau0, unloading, comp, s1, v1, t1, fs1, fv1, ft1):
    """Re-take the step from ``(s, v, t)`` so that state component ``comp`` is zero at its end.

    ``comp`` is 0 for ``s``, 1 for ``v``; the step is taken at ``sigma = sig``.
    ``(s1, ..., ft1)`` is the accepted full step of length ``h`` in which it
    changed sign (or became zero). Returns the step length and the state and
    derivative at its end.
    """
    if comp == 0:
        g0, d0, g1, d1 = s, fs, s1, fs1
    else:
        g0, d0, g1, d1 = v, fv, v1, fv1
    if g1 == 0.0:
        return h, s1, v1, t1, fs1, fv1, ft1
    pos0 = g0 > 0.0
    lo = 0.0
    hi = h
    best_h, best_g = h, g1
    bs, bv, bt, bfs, bfv, bft = s1, v1, t1, fs1, fv1, ft1
    hp = h * _hermite_root(g0, d0 * h, g1, d1 * h)
    tiny = 4.0 * _EPS * (abs(sig) + h)
    for _ in range(40):
        if not (lo < hp < hi):
            hp = 0.5 * (lo + hi)
        ys, yv, yt, gs, gv, gt, _es, _ev, _et = _dp_step(s, v, t, fs, fv, ft, hp, tau0, unloading)
        g = ys if comp == 0 else yv
        dg = gs if comp == 0 else gv
        if abs(g) <= abs(best_g):
            best_h, best_g = hp, g
            bs, bv, bt, bfs, bfv, bft = ys, yv, yt, gs, gv, gt
        if g == 0.0:
            break
        if (g > 0.0) == pos0:
            lo = hp
        else:
            hi = hp
        if dg != 0.0:
            dh = -g / dg
        else:
            dh = 0.5 * (lo + hi) - hp
        hn = hp + dh
        if not (lo < hn < hi):
            hn = 0.5 * (lo + hi)
        if abs(hn - hp) <= tiny or hi - lo <= tiny:
            if abs(hn - hp) <= tiny and lo < hn < hi and hn != hp:
                ys, yv, yt, gs, gv, gt, _es, _ev, _et = _dp_step(s, v, t, fs, fv, ft, hn,
                                                                 tau0, unloading)
                g = ys if comp == 0 else yv
                if abs(g) <= abs(best_g):
                    best_h, best_g = hn, g
                    bs, bv, bt, bfs, bfv, bft = ys, yv, yt, gs, gv, gt
            break
        hp = hn
    return best_h, bs, bv, bt, bfs, bfv, bft


@jit()
def _force(s, v, tau0, unloading):
    """Return the normal force ``F`` at ``(s, v)``, in units of ``m v_z0 / T``."""
    if unloading:
        sp = max(s, 0.0)
        return 1.25 * sp * sp * sp
    return 1.25 * s * s * s + 1.875 * tau0 * s * v


@jit(internal=True)
def rejected_step_factor(err):
    """Factor (< 1) for the step after a rejected one with error norm ``err`` (NaN: the smallest)."""
    if math.isfinite(err):
        return min(max(_FAC_MIN, _SAFETY * err ** (-_ALPHA)), _SAFETY)
    return _FAC_MIN


@jit(internal=True)
def step_underflow(h, sig):
    """Whether the step ``h`` is too small to move the time ``sig`` (or not positive, or NaN)."""
    return h <= 4.0 * _EPS * abs(sig) or not (h > 0.0)


@jit(internal=True)
def accepted_step_factor(err, err_old, rejected):
    """Return the PI step-size factor after an accepted step (Hairer, Norsett & Wanner).

    ``err`` and ``err_old`` are the error norms of this step and the previous one
    (dimensionless, 1 at the tolerance); the factor is not above 1 right after a
    rejection.
    """
    fac = _SAFETY * err ** (-_ALPHA) * err_old ** _BETA if err > 0.0 else _FAC_MAX
    fac = min(_FAC_MAX, max(_FAC_MIN, fac))
    return min(fac, 1.0) if rejected else fac


@jit()
def kv_normal_impact(tau0, rtol, max_steps, rec, rec_every, out):
    """One normal Kelvin-Voigt impact, continuum limit; results into ``out``.

    Parameters (kernel units, see module docstring)
    ----------
    tau0 : Kelvin-Voigt time ``eta / (G T)``, >= 0 (0: elastic Hertz impact);
        ``Q1 = Q1_PER_TAU * tau0``
    rtol : relative tolerance of the Runge-Kutta steps, clamped to
        ``[RTOL_MIN, RTOL_MAX]``; absolute tolerances tied to it (module
        docstring). The global relative error of the outputs is about
        0.1-5 ``rtol``.
    max_steps : limit on accepted steps (``STATUS_TIME_LIMIT`` when reached)
    rec : ``(n_rec, N_REC)`` trajectory buffer (may have zero rows); a row
        ``t, u, v, 0, F_z, 0, b`` after every ``rec_every``-th accepted step and
        one for the end state (``F_z = 0``, ``b = 0`` at the end of contact),
        which overwrites the last row if the buffer is full
    rec_every : record every this many accepted steps (ignored without rows)
    out : ``(N_OUT,)`` result row: ``OUT_VZ_END`` (``-e_z``), ``OUT_VC_END = 0``,
        ``OUT_T_CONTACT``, ``OUT_U_MAX``, ``OUT_B_MAX = sqrt(u_max)``,
        ``OUT_STATUS``, ``OUT_STEPS`` (accepted steps), ``OUT_N_REC`` (rows
        written)

    Returns the number of trajectory rows written. On ``STATUS_TIME_LIMIT`` or
    ``STATUS_NON_FINITE`` the outputs are those of the last accepted state
    (``OUT_T_CONTACT`` its ``t``).
    """
    n_rec = rec.shape[0]
    # the counter and the phase flag are int64 and bool from the start, not bare
    # literals: numba would compile every callee once more per literal type
    i_rec = np.int64(0)
    out[:] = 0.0  # every column of the row is written (those it does not compute stay 0)
    if not (tau0 >= 0.0 and math.isfinite(tau0)):
        out[OUT_VZ_END] = np.nan
        out[OUT_T_CONTACT] = np.nan
        out[OUT_U_MAX] = np.nan
        out[OUT_B_MAX] = np.nan
        out[OUT_STATUS] = STATUS_NON_FINITE
        out[OUT_STEPS] = 0
        out[OUT_N_REC] = 0
        return 0
    if not (rtol >= RTOL_MIN):  # also NaN
        rtol = RTOL_MIN
    if rtol > RTOL_MAX:
        rtol = RTOL_MAX
    atol = ATOL_PER_RTOL * rtol
    # Absolute tolerances at the scale each component has where it matters
    # (module docstring): for heavy damping u_max ~ (4 / (5 tau0))^(2/3) and
    # |v| ~ e_z ~ u_max / tau0 near the turning point and on unloading.
    v_scale = 1.0
    s_scale = 1.0
    if tau0 > 0.8:
        s_scale = (0.8 / tau0) ** (1.0 / 3.0)
        v_scale = s_scale * s_scale / tau0
    atol_s = atol * s_scale
    atol_v = atol * v_scale

    unloading: np.bool_ = np.bool_(False)
    s = 0.0
    v = 1.0
    t = 0.0
    sig = 0.0
    fs, fv, ft = _rhs(s, v, tau0, unloading)

    # ---- initial step (Hairer, Norsett & Wanner, sec. II.4) ----
    sc_s = atol_s + rtol * abs(s)
    sc_v = atol_v + rtol * abs(v)
    sc_t = atol + rtol * abs(t)
    d0 = math.sqrt(((s / sc_s) ** 2 + (v / sc_v) ** 2 + (t / sc_t) ** 2) / 3.0)
    d1 = math.sqrt(((fs / sc_s) ** 2 + (fv / sc_v) ** 2 + (ft / sc_t) ** 2) / 3.0)
    h0 = 0.01 * d0 / d1 if (d0 > 1e-5 and d1 > 1e-5) else 1e-6
    gs, gv, gt = _rhs(s + h0 * fs, v + h0 * fv, tau0, unloading)
    d2 = math.sqrt((((gs - fs) / sc_s) ** 2 + ((gv - fv) / sc_v) ** 2
                    + ((gt - ft) / sc_t) ** 2) / 3.0) / h0
    dm = max(d1, d2)
    h1 = (0.01 / dm) ** 0.2 if dm > 1e-15 else max(1e-6, 1e-3 * h0)
    h = min(100.0 * h0, h1)

    err_old = 1e-4
    rejected = False
    status = STATUS_TIME_LIMIT
    steps = 0
    u_max = 0.0
    while steps < max_steps:
        if step_underflow(h, sig):
            status = STATUS_NON_FINITE
            break
        s1, v1, t1, fs1, fv1, ft1, es, ev, et = _dp_step(s, v, t, fs, fv, ft, h, tau0, unloading)
        err = _err_norm(es, ev, et, s, v, t, s1, v1, t1, rtol, atol_s, atol_v, atol)
        if not (err <= 1.0):  # rejected (also NaN)
            h *= rejected_step_factor(err)
            rejected = True
            continue
        # ---- accepted ----
        steps += 1
        h_next = h * accepted_step_factor(err, err_old, rejected)
        err_old = max(err, 1e-4)
        rejected = False

        event = (v1 <= 0.0) if not unloading else (s1 <= 0.0)
        if event:
            comp = 0 if unloading else 1
            h, s1, v1, t1, fs1, fv1, ft1 = _locate(s, v, t, fs, fv, ft, sig, h, tau0, unloading,
                                                   comp, s1, v1, t1, fs1, fv1, ft1)
        sig += h
        s, v, t = s1, v1, t1
        fs, fv, ft = fs1, fv1, ft1
        h = h_next
        if not (math.isfinite(s) and math.isfinite(v) and math.isfinite(t)):
            status = STATUS_NON_FINITE
            break
        if event and unloading:  # end of contact: w = s^2 = 0
            s = 0.0
            status = STATUS_OK
            break
        if event:  # turning point: restart on the unloading branch
            v = 0.0
            u_max = s * s
            unloading = np.bool_(True)
            fs, fv, ft = _rhs(s, v, tau0, unloading)
            # s ends in a tail where 5/4 tau0 s^3 ~ |v| ~ v_scale
            if tau0 > 0.0:
                atol_s = atol * min(s, (v_scale / (1.25 * tau0)) ** (1.0 / 3.0))
            if n_rec > 0 and steps % rec_every == 0:
                i_rec = _record(rec, i_rec, t, u_max, 0.0, 0.0, _force(s, v, tau0, unloading),
                                0.0, s)
            continue
        if not unloading and s * s > u_max:
            u_max = s * s
        if n_rec > 0 and steps % rec_every == 0:
            u = s * s - tau0 * v if unloading else s * s
            i_rec = _record(rec, i_rec, t, u, v, 0.0, _force(s, v, tau0, unloading), 0.0,
                            max(s, 0.0))
    if n_rec > 0:  # the end state (overwriting the last row if full)
        u = s * s - tau0 * v if unloading else s * s
        i_rec = _record(rec, min(i_rec, n_rec - 1), t, u, v, 0.0, _force(s, v, tau0, unloading),
                        0.0, max(s, 0.0))
    out[OUT_VZ_END] = v
    out[OUT_T_CONTACT] = t
    out[OUT_U_MAX] = u_max
    out[OUT_B_MAX] = math.sqrt(u_max)
    out[OUT_STATUS] = status
    out[OUT_STEPS] = steps
    out[OUT_N_REC] = i_rec
    return i_rec


@jit(parallel=True)
def kv_normal_batch(tau0, rtol, max_steps, out):
    """Many normal Kelvin-Voigt continuum impacts in parallel.

    ``tau0`` is ``(n,)``, ``out`` is ``(n, N_OUT)`` (row ``i`` for ``tau0[i]``);
    ``rtol`` (float) and ``max_steps`` (int) are shared. Each row is exactly
    what :func:`kv_normal_impact` writes for the same arguments.
    """
    n = tau0.shape[0]
    no_rec = np.zeros((0, N_REC))
    # rec_every as int64, not the literal 1 (which would compile the impact once more)
    for i in prange(n):
        kv_normal_impact(tau0[i], rtol, max_steps, no_rec, np.int64(1), out[i])
