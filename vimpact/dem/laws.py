"""One-contact force laws of DEM codes, integrated independently of vimpact's engine.

Each law is run by a small ODE integrator (``scipy.integrate.solve_ivp``,
DOP853 with events at the end of contact) in the law's own dimensionless
form, so that its restitution is a function of one or two numbers:

- viscoelastic Hertz (Brilliantov et al.; LAMMPS ``hertz`` + ``damping
  viscoelastic``, MercuryDPM BSHP): ``F = k_n d^1.5 + 1.5 A k_n d^0.5 dd/dt``
  with ``k_n = 4/3 E* sqrt(R)``. In units of the Hertz overlap ``d_H`` and
  ``T = d_H / v0``: ``x'' = -(5/4) (x^1.5 + 1.5 alpha x^0.5 x')`` with
  ``alpha = A v0 / d_H``, so ``e = e(alpha)``. Clipped: the contact ends when
  the force reaches zero (LAMMPS ``limit_damping``); unclipped: when the
  overlap does (the force may pull).
- Tsuji-type Hertz (LIGGGHTS ``model hertz`` with ``coefficientRestitution``):
  damping ``2 sqrt(5/6) |beta| sqrt(S_n m)`` with ``S_n = 2 E* sqrt(R d)``,
  ``beta = ln e_in / sqrt(ln^2 e_in + pi^2)``; dimensionless
  ``x'' = -(5/4) x^1.5 - 2.5 |beta| x^0.25 x'``: a restitution that does not
  depend on the speed but is not ``e_in`` either.
- linear spring-dashpot (Yade ``ViscElMat``, MFiX ``LSD``): ``m u'' + c u' + k u = 0``,
  in units of ``1/omega0`` with the damping ratio ``zeta``; with a tangential
  spring-dashpot at the contact point, in stick, of the same contact duration.

All functions return plain floats / arrays; none imports vimpact's engine.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

#: integrator tolerances of every law (relative, absolute)
RTOL, ATOL = 1e-11, 1e-13


def _terminal(fun, direction=-1.0):
    fun.terminal = True
    fun.direction = direction
    return fun


# ---- viscoelastic Hertz --------------------------------------------------

def viscoelastic_hertz_e(alpha: float, clipped: bool = True) -> tuple[float, float]:
    """Restitution and contact time of the viscoelastic Hertz law.

    Parameters
    ----------
    alpha : ``A v0 / d_H`` (``A`` the dissipation time, s; ``d_H`` the elastic
        Hertz overlap at impact speed ``v0``), dimensionless, >= 0
    clipped : the force never pulls (contact ends at zero force); ``False``:
        the contact ends at zero overlap

    Returns
    -------
    (e, t_contact / T) : restitution and contact time in units of ``T = d_H / v0``
    """
    a = float(alpha)

    def rhs(_, y):
        x, v = y
        s = math.sqrt(max(x, 0.0))
        f = x * s + 1.5 * a * s * v
        if clipped and f < 0.0:
            f = 0.0
        return [v, -1.25 * f]

    def overlap(_, y):
        return y[0]

    def force(_, y):  # the bracket of F / sqrt(x): starts at 1.5 alpha > 0
        return y[0] + 1.5 * a * y[1]

    events = [_terminal(overlap)]
    if clipped and a > 0.0:
        events.append(_terminal(force))
    # start slightly inside (x ~ s for s -> 0) so that the overlap event does not fire at t = 0
    s0 = 1e-9
    sol = solve_ivp(rhs, (s0, 50.0 + 50.0 * a), [s0, 1.0], method="DOP853", rtol=RTOL,
                    atol=ATOL, events=events)
    for ev_t, ev_y in zip(sol.t_events, sol.y_events):
        if len(ev_t):
            return abs(float(ev_y[0][1])), float(ev_t[0])
    raise RuntimeError(f"viscoelastic Hertz law with alpha = {a} did not end its contact")


#: the master curve is tabulated on this range of log10(alpha)
_LOG_ALPHA = (-7.0, 3.0)


@lru_cache(maxsize=2)
def _master_curve(clipped: bool):
    """``log10 alpha -> e`` of the viscoelastic Hertz law (cubic spline through 241 solved points)."""
    la = np.linspace(*_LOG_ALPHA, 241)
    e = np.array([viscoelastic_hertz_e(10.0**x, clipped)[0] for x in la])
    return CubicSpline(la, e)


def viscoelastic_hertz_curve(alpha, clipped: bool = True) -> np.ndarray:
    """``e(alpha)`` of the viscoelastic Hertz law for many ``alpha`` (array).

    Interpolates a master curve solved once with :func:`viscoelastic_hertz_e`
    (interpolation error below 1e-7); below ``alpha = 1e-7`` the law's
    first-order slope ``1 - e = 1.8917 alpha`` is used, above ``1e3`` it is an error.
    """
    alpha = np.asarray(alpha, dtype=float)
    if np.any(~np.isfinite(alpha)) or np.any(alpha < 0.0) or np.any(alpha > 10.0**_LOG_ALPHA[1]):
        raise ValueError(f"alpha must be finite, >= 0 and <= 1e3 (got {alpha!r})")
    tiny = alpha < 10.0**_LOG_ALPHA[0]
    la = np.log10(np.where(tiny, 10.0**_LOG_ALPHA[0], alpha))
    e = _master_curve(bool(clipped))(la)
    return np.where(tiny, 1.0 - SMALL_DAMPING_SLOPE * alpha, e)


#: ``1 - e = 1.5 B(3/5, 3/2) alpha`` to first order in the damping (PHYSICS.md section 5)
SMALL_DAMPING_SLOPE = 1.5 * math.gamma(0.6) * math.gamma(1.5) / math.gamma(2.1)


def hertz_overlap(E_star: float, R, m, v0):
    """Elastic Hertz overlap ``d_H = (15 m v0^2 / (16 E* sqrt(R)))^(2/5)``, m
    (``R`` m, ``m`` kg, ``v0`` m/s: numbers or arrays)."""
    v0 = np.asarray(v0, dtype=float)
    return (15.0 * np.asarray(m) * v0**2 / (16.0 * E_star * np.sqrt(R)))**0.4


def hertz_contact_time(E_star: float, R: float, m: float, v0):
    """Elastic Hertz contact time ``2.9432751843 d_H / v0``, s."""
    v0 = np.asarray(v0, dtype=float)
    return 2.9432751843 * hertz_overlap(E_star, R, m, v0) / v0


def viscoelastic_hertz_restitution(A: float, E_star: float, R, m, v0,
                                   clipped: bool = True) -> np.ndarray:
    """``e(v0)`` of the viscoelastic Hertz law with dissipation time ``A`` (s),
    effective modulus ``E*`` (Pa), radius ``R`` (m) and mass ``m`` (kg)."""
    v0 = np.asarray(v0, dtype=float)
    return viscoelastic_hertz_curve(A * v0 / hertz_overlap(E_star, R, m, v0), clipped)


# ---- Tsuji-type Hertz (LIGGGHTS) ----------------------------------------

def liggghts_beta(e_in: float) -> float:
    """LIGGGHTS' ``beta = ln e / sqrt(ln^2 e + pi^2)`` of an input restitution ``e_in`` in (0, 1]."""
    if e_in >= 1.0:
        return 0.0
    le = math.log(e_in)
    return le / math.sqrt(le * le + math.pi**2)


def tsuji_hertz_e(e_in: float, clipped: bool = False) -> float:
    """Restitution the LIGGGHTS Hertz law produces from its input ``coefficientRestitution``
    ``e_in`` (speed-independent): ``x'' = -(5/4) x^1.5 - 2.5 |beta| x^0.25 x'``."""
    b = abs(liggghts_beta(e_in))

    def rhs(_, y):
        x, v = y
        xp = max(x, 0.0)
        f = 1.25 * xp**1.5 + 2.5 * b * xp**0.25 * v
        if clipped and f < 0.0:
            f = 0.0
        return [v, -f]

    def overlap(_, y):
        return y[0]

    def force(_, y):
        xp = max(y[0], 0.0)
        return 1.25 * xp**1.25 + 2.5 * b * y[1]

    events = [_terminal(overlap)] + ([_terminal(force)] if clipped and b > 0 else [])
    s0 = 1e-9
    sol = solve_ivp(rhs, (s0, 100.0), [s0, 1.0], method="DOP853", rtol=RTOL, atol=ATOL,
                    events=events)
    for ev_t, ev_y in zip(sol.t_events, sol.y_events):
        if len(ev_t):
            return abs(float(ev_y[0][1]))
    raise RuntimeError(f"Tsuji-type Hertz law with e_in = {e_in} did not end its contact")


# ---- linear spring-dashpot ------------------------------------------------

def linear_spring_dashpot(zeta: float, ends: str = "overlap", tangential=None
                          ) -> tuple[float, float, float]:
    """Normal (and tangential) restitution of a linear spring-dashpot contact.

    Parameters
    ----------
    zeta : normal damping ratio ``c / (2 sqrt(k m))``, >= 0; time unit ``1/omega0``
    ends : ``"overlap"`` (contact ends when the overlap returns to zero: Yade,
        MFiX) or ``"force"`` (when the force does; PHYSICS.md section 9)
    tangential : ``(w_t, zeta_t)`` of a tangential spring-dashpot acting on the
        contact-point velocity in stick: angular frequency ``w_t / omega0`` and
        damping ratio ``zeta_t`` of the tangential oscillator (with the
        contact-point mass ``m / (1 + m R^2/Theta)``); ``None``: normal only

    Returns
    -------
    (e, beta, omega0 t_contact) : ``beta = -v_c,end / v_c0`` (NaN without tangential)
    """
    z = float(zeta)
    wt, zt = tangential if tangential is not None else (0.0, 0.0)

    def rhs(_, y):
        u, v, s, w = y
        f = u + 2.0 * z * v
        if ends == "force" and f < 0.0:
            f = 0.0
        return [v, -f, w, -(wt * wt * s + 2.0 * zt * wt * w)]

    def overlap(_, y):
        return y[0]

    def force(_, y):
        return y[0] + 2.0 * z * y[1]

    if ends == "force":
        ev = _terminal(force)
        t0, y0 = 0.0, [0.0, 1.0, 0.0, 1.0]  # force starts at 2 zeta > 0
        if z == 0.0:
            ev = _terminal(overlap)
            t0, y0 = 1e-12, [1e-12, 1.0, 1e-12, 1.0]
    elif ends == "overlap":
        ev = _terminal(overlap)
        t0, y0 = 1e-12, [1e-12, 1.0, 1e-12, 1.0]
    else:
        raise ValueError(f"ends = {ends!r} is not allowed: must be 'overlap' or 'force'")
    sol = solve_ivp(rhs, (t0, 1e3), y0, method="DOP853", rtol=RTOL, atol=ATOL, events=[ev])
    if not len(sol.t_events[0]):
        raise RuntimeError(f"linear spring-dashpot with zeta = {z} did not end its contact")
    y = sol.y_events[0][0]
    beta = -float(y[3]) if tangential is not None else math.nan
    return abs(float(y[1])), beta, float(sol.t_events[0][0])


def zeta_of_restitution(e: float) -> float:
    """Damping ratio for which a linear spring-dashpot ending at zero overlap
    restitutes ``e``: ``|ln e| / sqrt(pi^2 + ln^2 e)`` (the usual DEM formula)."""
    if e >= 1.0:
        return 0.0
    le = math.log(e)
    return -le / math.sqrt(math.pi**2 + le * le)
