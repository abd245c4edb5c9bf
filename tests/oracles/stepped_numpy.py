"""The stepped friction laws of the DEM codes as NumPy loops over steps (all points at once).

The implementation ``vimpact.dem.laws`` had before its stepping moved into a numba
kernel (:mod:`vimpact.kernels.stepped`): kept as the oracle the kernel is compared
with bit for bit (``tests/dem/test_stepped_kernel.py``).
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.dem.laws import FRICTION_STEPS, _record_ended, _stepped_result, liggghts_beta
from vimpact.model.hertz import HERTZ_TIME_FACTOR


def hertz_mindlin_coulomb(alpha, kappa, x_gamma, F, mu, w0,
                          steps: int = FRICTION_STEPS) -> tuple[np.ndarray, np.ndarray]:
    """As ``vimpact.dem.laws.hertz_mindlin_coulomb`` was: the NumPy loop over all points."""
    alpha, w0, kappa, x_gamma = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (alpha, w0, kappa, x_gamma)))
    return _stepped(alpha, w0, mu if np.ndim(mu) else float(mu), steps,
                    _mindlin_force(kappa.ravel(), x_gamma.ravel()),
                    F if np.ndim(F) else float(F))


def _mindlin_force(kappa: np.ndarray, x_gamma: np.ndarray):
    def force(x, v, s, w, alpha, cap):
        r = np.sqrt(np.maximum(x, 0.0))
        f = np.maximum(x * r + 1.5 * alpha * r * v, 0.0)
        ft = 1.5 * kappa * r * s + 1.5 * alpha * x_gamma * r * w
        over = np.abs(ft) > cap * f
        if np.any(over):
            lim = np.sign(ft) * cap * f
            k = 1.5 * kappa * r
            s = np.where(over & (s != 0.0) & (k > 0.0),
                         (lim - 1.5 * alpha * x_gamma * r * w) / np.where(k > 0.0, k, 1.0), s)
            ft = np.where(over, np.where(s != 0.0, lim, 0.0), ft)
        return 1.25 * f, 1.25 * ft, s
    return force


def mercury_mindlin_coulomb(alpha, K, D, F, mu, w0,
                            steps: int = FRICTION_STEPS) -> tuple[np.ndarray, np.ndarray]:
    """As ``vimpact.dem.laws.mercury_mindlin_coulomb`` was: the NumPy loop over all points."""
    alpha, D, w0, Kb = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (alpha, D, w0, K)))
    Dflat = D.ravel()
    K = Kb.ravel()

    def force(x, v, s, w, a, cap):
        r = np.sqrt(np.maximum(x, 0.0))
        f = np.maximum(x * r + 1.5 * a * r * v, 0.0)
        el = K * r * s
        over = np.abs(el) > cap * f
        lim = np.sign(el) * cap * f
        k = K * r
        s = np.where(over, np.where(k > 0.0, lim / np.where(k > 0.0, k, 1.0), 0.0), s)
        ft = np.where(over, lim, el + Dflat * np.sqrt(r) * w)
        return 1.25 * f, 1.25 * ft, s
    return _stepped(alpha, w0, mu, steps, force, F)


def liggghts_coulomb(e_in: float, K: float, D: float, F: float, mu: float, w0,
                     steps: int = FRICTION_STEPS, lever=None) -> tuple[np.ndarray, np.ndarray]:
    """As ``vimpact.dem.laws.liggghts_coulomb`` was: the NumPy loop over all points."""
    b = abs(liggghts_beta(e_in))
    w0 = np.asarray(w0, dtype=float)

    def force(x, v, s, w, _a, cap):
        xp = np.maximum(x, 0.0)
        r = np.sqrt(xp)
        q = np.sqrt(r)
        f = xp * r + 2.0 * b * q * v
        el = K * r * s
        over = np.abs(el) > cap * np.abs(f)
        lim = np.sign(el) * cap * np.abs(f)
        k = K * r
        s = np.where(over, np.where(k > 0.0, lim / np.where(k > 0.0, k, 1.0), 0.0), s)
        ft = np.where(over, lim, el + D * q * w)
        return 1.25 * f, 1.25 * ft, s
    return _stepped(np.zeros(w0.shape), w0, mu, steps, force, F, lever)


def yade_coulomb(zeta, w_t, zeta_t, F, mu, w0, steps: int = FRICTION_STEPS,
                 rho=None) -> tuple[np.ndarray, np.ndarray]:
    """As ``vimpact.dem.laws.yade_coulomb`` was: the NumPy loop over all points."""
    w0 = np.asarray(w0, dtype=float)
    lever = None if rho is None else 1.0 / np.broadcast_to(np.asarray(rho, dtype=float),
                                                         w0.shape)
    per_point = any(np.ndim(a) for a in (zeta, w_t, zeta_t, F))
    if per_point:  # one contact per point: flat arrays like _stepped's state
        zeta, w_t, zeta_t, F = (np.broadcast_to(np.asarray(a, dtype=float), w0.shape).ravel()
                                for a in (zeta, w_t, zeta_t, F))
    k_t = w_t * w_t / F  # tangential stiffness per unit mass (contact-point mass m / F)
    c_t = 2.0 * zeta_t * w_t / F
    stiff = k_t > 0.0
    k_safe = np.where(stiff, k_t, 1.0) if per_point else k_t

    def force(x, v, s, w, alpha, cap):
        f = np.maximum(x + 2.0 * zeta * v, 0.0)
        el = k_t * s  # the incremental elastic force: the sum of k_t w dt
        over = np.abs(el) > cap * f
        el = np.where(over, np.sign(el) * cap * f, el)
        if per_point:
            s = np.where(over & stiff, el / k_safe, s)
        elif k_t > 0.0:
            s = np.where(over, el / k_t, s)
        return f, el + np.where(over, 0.0, c_t * w), s
    return _stepped(np.zeros(w0.shape), w0, mu, steps, force,
                    np.reshape(F, w0.shape) if per_point else F, lever, contact_time=math.pi)


def _stepped(alpha: np.ndarray, w0: np.ndarray, mu, steps: int, force, F,
             lever=None, contact_time: float = HERTZ_TIME_FACTOR) -> tuple[np.ndarray, np.ndarray]:
    """As ``vimpact.dem.laws._stepped`` was: the NumPy loop over all points."""
    alpha, w0 = np.broadcast_arrays(alpha, w0)
    shape = alpha.shape
    alpha, w0 = alpha.ravel().copy(), w0.ravel().copy()
    lev = (np.zeros_like(w0) if lever is None
           else np.broadcast_to(np.asarray(lever, dtype=float), shape).ravel())
    spin = (np.broadcast_to(np.asarray(F, dtype=float), shape).ravel() - 1.0 if np.ndim(F)
            else F - 1.0)
    h = contact_time / steps
    # stick: the tangential force still ends with the normal one
    cap = (np.minimum(np.broadcast_to(np.asarray(mu, dtype=float), shape).ravel(), 1e300)
           if np.ndim(mu) else min(float(mu), 1e300))
    x = np.zeros_like(alpha)
    v = np.ones_like(alpha)
    s = np.zeros_like(alpha)
    ux = w0.copy()
    om = np.zeros_like(alpha)
    an = np.zeros_like(alpha)
    at = np.zeros_like(alpha)
    live = np.ones(alpha.shape, dtype=bool)
    e = np.full_like(alpha, np.nan)
    wend = np.full_like(alpha, np.nan)
    for _ in range(50 * steps):
        arm = 1.0 - lev * x
        v_half = v - 0.5 * h * an
        ux_half = ux - 0.5 * h * at
        om_half = om + 0.5 * h * arm * spin * at
        x = x + h * v_half
        arm = 1.0 - lev * x
        w_half = ux_half - arm * om_half
        s = s + h * w_half  # the tangential displacement (history) in stick
        an, at, s = force(x, v_half, s, w_half, alpha, cap)
        v = v_half - 0.5 * h * an
        ux = ux_half - 0.5 * h * at
        om = om_half + 0.5 * h * arm * spin * at
        if _record_ended(live, x, v, ux, om, e, wend):
            break
    return _stepped_result(live, e, wend, w0, shape)
