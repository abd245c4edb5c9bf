"""Slow, plain reference of the full-stick continuum impact (docs/physics.md#continuum-limit).

Independent of :mod:`vimpact.kernels.continuum_maxwell` (no shared code, a
different unloading formulation): written with ``scipy.integrate.solve_ivp``
(DOP853) and ``scipy.optimize.brentq``.

Kernel units (``u`` / d, ``x`` / a_H, ``t`` / T, ``v`` / v_z0, ``G_inf = 1``,
tangential in ``v_c0``; ``gn = 15/8``):

- loading (``v >= 0``), integrated in ``sigma`` with ``dt = 2 b dsigma``,
  ``b = sqrt(u)`` a state (``db/dsigma = v``), with the accumulators
  ``A_i, S_i, w_c, v_c, I, B_i, U_i`` of section 11, until ``v = 0``
  (terminal event, dense output kept);
- unloading (``v < 0``), integrated in ``t`` on ``(u, v, A_i, w_c, v_c, B_i)``:
  at every right-hand-side call the edge is the root ``sigma_e`` of the force
  density ``f(t_e(sigma_e), t)`` over the loading history, found by
  ``brentq`` on the loading dense output (the whole row in contact if
  ``f >= 0`` at the turning point), and the end of contact is the terminal
  event ``f(0, t) = 0``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

GN = 15.0 / 8.0


@dataclass
class ContinuumReference:
    """Outputs of one reference impact: ``e_z``, ``beta_x`` (dimensionless), ``t_contact`` / T."""

    e_z: float
    beta_x: float
    t_contact: float
    u_max: float
    t_turn: float


class _Falling:
    """A terminal ``solve_ivp`` event: ``fn(t, y)`` crossing zero from above."""

    terminal = True
    direction = -1

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, t, y):
        return self.fn(t, y)


def maxwell_continuum_reference(tau0: float, g, tau, kappa: float, mu_t: float,
                                tangential: bool = True, rtol: float = 1e-12,
                                method: str = "DOP853") -> ContinuumReference:
    """Full-stick continuum impact of section 11 in kernel units (slow, ~seconds).

    ``tau0`` dashpot time, ``g``/``tau`` arm moduli and times (``tau > 0``),
    ``kappa = 2 (1 - nu) / (2 - nu)``, ``mu_t = 1 + m R^2 / Theta``.
    ``method`` is the scipy integrator of both phases: ``"DOP853"`` (explicit),
    or ``"Radau"`` / ``"BDF"`` / ``"LSODA"`` for arms much faster than the
    contact (stiff; their Jacobian by finite differences).
    Returns ``e_z``, ``beta_x = -v_c,end`` (NaN without ``tangential``),
    ``t_contact``, ``u_max``, ``t_turn``.
    """
    g = np.asarray(g, dtype=float)
    tau = np.asarray(tau, dtype=float)
    n = g.size
    atol = 1e-3 * rtol

    # ---------------- loading: y = [b, v, t, A(n), S(n), wc, vc, I, B(n), U(n)]
    def load(_sig, y):
        b, v = y[0], y[1]
        A = y[3:3 + n]
        S = y[3 + n:3 + 2 * n]
        wc, vc, I = y[3 + 2 * n:6 + 2 * n]
        B = y[6 + 2 * n:6 + 3 * n]
        U = y[6 + 3 * n:6 + 4 * n]
        u = b * b
        dt = 2.0 * b  # dt/dsigma
        Fz = GN * (u * b - b ** 3 / 3.0 + tau0 * v * b + np.sum(g * ((u - A) * b + S)))
        Fx = GN * kappa * (wc * b - I + tau0 * vc * b + np.sum(g * ((wc - B) * b + U)))
        dy = np.empty_like(y)
        dy[0] = v  # db/dsigma = db/dt dt/dsigma = v / (2b) * 2b
        dy[1] = -Fz * dt
        dy[2] = dt
        dy[3:3 + n] = (u - A) / tau * dt
        dy[3 + n:3 + 2 * n] = -S / tau * dt + (A - u) * v
        dy[3 + 2 * n] = vc * dt
        dy[4 + 2 * n] = -mu_t * Fx * dt if tangential else 0.0
        dy[5 + 2 * n] = wc * v
        dy[6 + 2 * n:6 + 3 * n] = (wc - B) / tau * dt
        dy[6 + 3 * n:6 + 4 * n] = -U / tau * dt + (B - wc) * v
        return dy

    turn = _Falling(lambda _sig, y: y[1])

    y0 = np.zeros(6 + 4 * n)
    y0[1] = 1.0
    y0[4 + 2 * n] = 1.0 if tangential else 0.0
    ld = solve_ivp(load, (0.0, 1e3), y0, method=method, rtol=rtol, atol=atol,
                   events=turn, dense_output=True)
    if ld.status != 1:
        raise RuntimeError("no turning point")
    sig_turn = ld.t_events[0][0]
    yt = ld.y_events[0][0]
    hist = ld.sol
    t_turn = yt[2]
    b_max = yt[0]

    def density(sig_e, t, u, v, A):
        """Return the normal force density of the element that entered at sigma_e."""
        h = hist(sig_e)
        ue = h[0] ** 2
        te = h[2]
        Ae = h[3:3 + n]
        return (u - ue) + tau0 * v + np.sum(g * ((u - A) + np.exp(-(t - te) / tau) * (Ae - ue)))

    def edge(t, u, v, A):
        if density(sig_turn, t, u, v, A) >= 0.0:
            return sig_turn
        if density(0.0, t, u, v, A) <= 0.0:
            return 0.0
        return brentq(density, 0.0, sig_turn, args=(t, u, v, A), xtol=1e-15, rtol=1e-15)

    # ---------------- unloading: z = [u, v, A(n), wc, vc, B(n)], independent t
    def unload(t, z):
        u, v = z[0], z[1]
        A = z[2:2 + n]
        wc, vc = z[2 + n], z[3 + n]
        B = z[4 + n:4 + 2 * n]
        se = edge(t, u, v, A)
        h = hist(se)
        b = h[0] if se > 0.0 else 0.0
        te = h[2]
        E = np.exp(-(t - te) / tau)
        Se = h[3 + n:3 + 2 * n]
        Ie = h[5 + 2 * n]
        Ue = h[6 + 3 * n:6 + 4 * n]
        Fz = GN * (u * b - b ** 3 / 3.0 + tau0 * v * b + np.sum(g * ((u - A) * b + E * Se)))
        Fx = GN * kappa * (wc * b - Ie + tau0 * vc * b + np.sum(g * ((wc - B) * b + E * Ue)))
        dz = np.empty_like(z)
        dz[0] = v
        dz[1] = -Fz
        dz[2:2 + n] = (u - A) / tau
        dz[2 + n] = vc
        dz[3 + n] = -mu_t * Fx if tangential else 0.0
        dz[4 + n:4 + 2 * n] = (wc - B) / tau
        return dz

    end = _Falling(lambda t, z: density(0.0, t, z[0], z[1], z[2:2 + n]))

    z0 = np.concatenate([[b_max ** 2, 0.0], yt[3:3 + n], [yt[3 + 2 * n], yt[4 + 2 * n]],
                         yt[6 + 2 * n:6 + 3 * n]])
    ul = solve_ivp(unload, (t_turn, t_turn + 1e3), z0, method=method, rtol=rtol, atol=atol,
                   events=end)
    if ul.status != 1:
        raise RuntimeError("no end of contact")
    ze = ul.y_events[0][0]
    return ContinuumReference(e_z=-ze[1], beta_x=-ze[3 + n] if tangential else np.nan,
                              t_contact=ul.t_events[0][0], u_max=b_max ** 2, t_turn=t_turn)
