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

The friction laws stepped as the codes step them (LAMMPS, MercuryDPM, LIGGGHTS,
Yade) run in the numba kernel :mod:`vimpact.kernels.stepped`, one point after
another, in the same arithmetic as the codes' updates written here before.

All functions return plain floats / arrays; none imports vimpact's engine.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from vimpact.kernels.stepped import LAW_LAMMPS, LAW_LIGGGHTS, LAW_MERCURY, LAW_YADE, stepped_impacts
from vimpact.model.hertz import HERTZ_TIME_FACTOR

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


@lru_cache(maxsize=1)
def _master_curve():
    """Return ``log10 alpha -> e`` of the clipped viscoelastic Hertz law, a cubic spline.

    Through the 241 solved points of :mod:`vimpact.dem._hertz_table` (regenerated
    by :func:`write_table`, checked against direct solves by the tests); ``alpha``
    and ``e`` are dimensionless.
    """
    from vimpact.dem import _hertz_table as tab

    la = np.linspace(*tab.LOG_ALPHA, tab.N)
    return CubicSpline(la, np.array(tab.E_CLIPPED))


def write_table(path: str | None = None) -> str:
    """Solve the master curves again and write :mod:`vimpact.dem._hertz_table`."""
    from vimpact.dem import _hertz_table as tab

    la = np.linspace(*tab.LOG_ALPHA, tab.N)
    e = [viscoelastic_hertz_e(10.0**x)[0] for x in la]
    rows = "\n".join("    " + ", ".join(repr(x) for x in e[i:i + 4]) + ","
                     for i in range(0, len(e), 4))
    doc = tab.__doc__.strip()
    text = (f'"""{doc}\n"""\n\nLOG_ALPHA = {tab.LOG_ALPHA!r}\nN = {tab.N}\n\n'
            f"E_CLIPPED = (\n{rows}\n)\n")
    path = path or tab.__file__
    with open(path, "w") as fh:
        fh.write(text)
    return path


def viscoelastic_hertz_curve(alpha) -> np.ndarray:
    """``e(alpha)`` of the clipped viscoelastic Hertz law for many ``alpha`` (array).

    Interpolates the master curve solved with :func:`viscoelastic_hertz_e`
    (interpolation error below 1e-7); below ``alpha = 1e-7`` the law's
    first-order slope ``1 - e = 1.8917 alpha`` is used, above ``1e3`` it is an error.
    """
    alpha = np.asarray(alpha, dtype=float)
    if np.any(~np.isfinite(alpha)) or np.any(alpha < 0.0) or np.any(alpha > 1e3):
        raise ValueError(f"alpha must be finite, >= 0 and <= 1e3 (got {alpha!r})")
    tiny = alpha < 1e-7
    la = np.log10(np.where(tiny, 1e-7, alpha))
    e = _master_curve()(la)
    return np.where(tiny, 1.0 - SMALL_DAMPING_SLOPE * alpha, e)


#: ``1 - e = 1.5 B(3/5, 3/2) alpha`` to first order in the damping (docs/physics.md#kelvin-voigt-continuum)
SMALL_DAMPING_SLOPE = 1.5 * math.gamma(0.6) * math.gamma(1.5) / math.gamma(2.1)


def hertz_overlap(E_star: float, R, m, v0):
    """Return the elastic Hertz overlap ``d_H = (15 m v0^2 / (16 E* sqrt(R)))^(2/5)``, m.

    ``E_star`` in Pa, ``R`` in m, ``m`` in kg, ``v0`` in m/s: numbers or arrays.
    """
    v0 = np.asarray(v0, dtype=float)
    return (15.0 * np.asarray(m) * v0**2 / (16.0 * E_star * np.sqrt(R)))**0.4


def hertz_contact_time(E_star: float, R: float, m: float, v0):
    """Elastic Hertz contact time ``HERTZ_TIME_FACTOR d_H / v0`` (about 2.943 d_H / v0), s."""
    v0 = np.asarray(v0, dtype=float)
    return HERTZ_TIME_FACTOR * hertz_overlap(E_star, R, m, v0) / v0


def viscoelastic_hertz_restitution(A: float, E_star: float, R, m, v0) -> np.ndarray:
    """Return ``e(v0)`` of the clipped viscoelastic Hertz law, ``v0`` in m/s.

    With dissipation time ``A`` (s), effective modulus ``E*`` (Pa), radius ``R``
    (m) and mass ``m`` (kg).
    """
    v0 = np.asarray(v0, dtype=float)
    return viscoelastic_hertz_curve(A * v0 / hertz_overlap(E_star, R, m, v0))


def viscoelastic_hertz_mindlin(alpha: float, kappa: float, x_gamma: float, F: float,
                               rtol: float = RTOL) -> tuple[float, float]:
    """Return the normal and tangential restitution of the viscoelastic Hertz-Mindlin law in stick.

    The clipped viscoelastic Hertz law with a Mindlin tangential spring and dashpot
    in stick (LAMMPS ``hertz ... damping viscoelastic tangential mindlin k_t
    x_gamma_t mu limit_damping``).

    In the units of :func:`viscoelastic_hertz_e` (overlap ``x``, tangential
    displacement ``s`` in ``d_H``, contact-point velocity ``w`` in ``v0``):
    ``w' = -(5/4) F sqrt(x) (1.5 kappa s + 1.5 alpha x_gamma w)``, ``s' = w``, from
    ``F_t = -(k_t a s + x_gamma eta_n v_t)`` with ``k_t = 8 G*`` = ``1.5 kappa`` times
    ``k_n = 4/3 E*`` and ``eta_n = 2 E* A a``. The tangential force ends with the
    normal one (its Coulomb limit is then zero).

    Parameters
    ----------
    alpha : ``A v0 / d_H``; kappa : ``k_t / (2 E*)`` (Mindlin over Hertz tangent
        stiffness, ``2 (1 - nu)/(2 - nu)`` for one material); x_gamma : tangential
        over normal damping; F : contact-point mass factor ``1 + m R^2/Theta``
    rtol : integrator tolerance (relative; absolute ``rtol / 100``)

    Returns
    -------
    (e, beta) : ``beta = -w_end / w_0`` with ``w_0 = 1`` (the contact point slides
        initially at the normal approach speed)
    """
    a, k, g = float(alpha), float(kappa), float(x_gamma)

    def rhs(_, y):
        x, v, s, w = y
        r = math.sqrt(max(x, 0.0))
        f = x * r + 1.5 * a * r * v
        ft = 1.5 * k * s * r + 1.5 * a * g * r * w
        if f < 0.0:
            f, ft = 0.0, 0.0
        return [v, -1.25 * f, w, -1.25 * F * ft]

    def overlap(_, y):
        return y[0]

    def force(_, y):
        return y[0] + 1.5 * a * y[1]

    events = [_terminal(overlap)] + ([_terminal(force)] if a > 0.0 else [])
    s0 = 1e-9
    sol = solve_ivp(rhs, (s0, 50.0 + 50.0 * a), [s0, 1.0, s0, 1.0], method="DOP853", rtol=rtol,
                    atol=rtol / 100.0, events=events)
    for ev_t, ev_y in zip(sol.t_events, sol.y_events):
        if len(ev_t):
            return abs(float(ev_y[0][1])), -float(ev_y[0][3])
    raise RuntimeError(f"viscoelastic Hertz-Mindlin law with alpha = {a} did not end its contact")


# ---- oblique impacts with Coulomb friction (time-stepped, as the codes do) --

#: time steps per elastic Hertz contact time of the stepped friction laws; their
#: discretization error in ``beta`` is below 5e-4 at this step (against the stick ODE,
#: tests/dem/test_laws.py)
FRICTION_STEPS = 2000


def hertz_mindlin_coulomb(alpha, kappa, x_gamma, F, mu, w0,
                          steps: int = FRICTION_STEPS) -> tuple[np.ndarray, np.ndarray]:
    """Return the normal and tangential restitution of LAMMPS' Hertz-Mindlin law with friction.

    LAMMPS' ``hertz ... damping viscoelastic tangential mindlin k_t x_gamma_t mu
    limit_damping`` in an oblique impact, with Coulomb friction, stepped as LAMMPS
    steps it.

    Units and the stick law are those of :func:`viscoelastic_hertz_mindlin`; the
    contact point arrives sliding at ``w0 = v_c0 / v_z0`` (``tan`` of the impact angle
    for a sphere without spin). Each step is LAMMPS' velocity Verlet (``fix
    nve/sphere``): half-step velocities, the history ``s`` incremented by ``w dt``, the
    force ``ft = 1.5 kappa sqrt(x) s + 1.5 alpha x_gamma sqrt(x) w`` and, when ``|ft|``
    exceeds ``mu f`` (``f`` the normal force clipped at zero, LAMMPS' ``Fncrit``), the
    force set to ``mu f`` and the history to the elastic part of it
    (``GranSubModTangentialMindlin::calculate_forces``). Many points at once.

    Parameters
    ----------
    alpha, w0 : arrays (or numbers) of the same shape: ``A v0 / d_H`` and ``v_c0 / v_z0``
    kappa, x_gamma : as in :func:`viscoelastic_hertz_mindlin`; numbers, or arrays that
        broadcast with ``alpha`` (one candidate per point: a fit runs many at once)
    F : as in :func:`viscoelastic_hertz_mindlin`; mu : Coulomb coefficient (``inf``: stick);
        numbers, or arrays that broadcast with ``alpha`` (points of several contacts at once)
    steps : steps per elastic Hertz contact time (``2.943 T``)

    Returns
    -------
    (e, beta) : arrays of the broadcast shape; ``beta = -w_end / w0``
    """
    alpha, w0, kappa, x_gamma = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (alpha, w0, kappa, x_gamma)))
    return _stepped(LAW_LAMMPS, alpha, w0, mu, steps, (kappa, x_gamma), F)


def mercury_mindlin_coulomb(alpha, K, D, F, mu, w0,
                            steps: int = FRICTION_STEPS) -> tuple[np.ndarray, np.ndarray]:
    """Return the normal and tangential restitution of MercuryDPM's Hertz-Mindlin species.

    MercuryDPM's ``HertzianBSHPViscoelasticMindlinSpecies`` in an oblique impact with
    Coulomb friction, stepped with velocity Verlet.

    Normal: the clipped viscoelastic Hertz law of :func:`viscoelastic_hertz_e` (units
    ``d_H``, ``T = d_H / v0``). Tangential (``MindlinInteraction::computeFrictionForce``):
    the spring ``-(2/3) K_t0 xi`` with ``K_t0 = 8 G a`` and, while that elastic force is
    below ``mu`` times the normal force, the dashpot ``-c sqrt(m_eff K_t0) v_t``; above it
    the force is ``mu`` times the normal force and the spring is reset to it. In units of
    ``k_n d_H^1.5``: elastic ``K sqrt(x) s`` with ``K = 4 G / E*``, viscous
    ``D x^(1/4) w`` (``D`` per point: it carries the mass and the speed).

    Parameters
    ----------
    alpha, D, w0 : arrays (or numbers) that broadcast; K : number or array like them (one
        candidate per point: a fit runs many at once); F, mu : numbers, or arrays that
        broadcast with ``alpha`` (points of several contacts at once)

    Returns
    -------
    (e, beta) : arrays of the broadcast shape; ``beta = -w_end / w0``
    """
    alpha, D, w0, K = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (alpha, D, w0, K)))
    return _stepped(LAW_MERCURY, alpha, w0, mu, steps, (K, D), F)


def liggghts_coulomb(e_in: float, K: float, D: float, F: float, mu: float, w0,
                     steps: int = FRICTION_STEPS, lever=None) -> tuple[np.ndarray, np.ndarray]:
    """Return the normal and tangential restitution of LIGGGHTS' Hertz law with friction.

    LIGGGHTS' ``model hertz tangential history`` in an oblique impact with Coulomb
    friction, stepped with velocity Verlet.

    In the units of :func:`viscoelastic_hertz_e` (``d_H`` of LIGGGHTS' ``Y*``): normal
    force ``x^1.5 + 2 |beta| x^(1/4) x'`` (not clipped, :func:`tsuji_hertz_e`);
    tangential (``tangential_model_history.h``): the spring ``K sqrt(x) s`` with
    ``K = 6 G*/Y*`` (``k_t = 8 G* sqrt(R delta)``) capped at ``mu |F_n|`` (the spring
    reset to the cap), and below the cap the dashpot ``D x^(1/4) w`` with
    ``D = 2 |beta| sqrt(4 G*/Y*)`` (``tangential_damping on``) or 0 (``off``);
    ``beta`` from the input restitution ``e_in`` (:func:`liggghts_beta`). The law does
    not depend on the speed: ``beta`` depends on the angle only, unless ``lever``
    (``d_H / (2 R)`` per point, like ``w0``) is given: LIGGGHTS' contact point is at
    ``R - delta/2`` from the centre (``cri``), the lever of the spin in the contact-point
    velocity and of the torque, which shifts ``beta`` by about ``delta/R``.

    Returns
    -------
    (e, beta) : arrays; ``beta = -w_end / w0``
    """
    b = abs(liggghts_beta(e_in))
    w0 = np.asarray(w0, dtype=float)
    return _stepped(LAW_LIGGGHTS, np.zeros(w0.shape), w0, mu, steps, (b, K, D), F, lever)


def yade_coulomb(zeta, w_t, zeta_t, F, mu, w0, steps: int = FRICTION_STEPS,
                 rho=None) -> tuple[np.ndarray, np.ndarray]:
    """Return the normal and tangential restitution of Yade's viscoelastic law with friction.

    Yade's ``Law2_ScGeom_ViscElPhys_Basic`` in an oblique impact with Coulomb
    friction, stepped as Yade steps it.

    In the units of :func:`linear_spring_dashpot` (time ``1/omega0``, lengths
    ``v0/omega0``): normal force ``u + 2 zeta u'`` clipped at zero; tangential, the
    elastic force is incremental (``fs -= ks w dt``) and capped at ``mu`` times the
    normal force, the viscous one ``cs w`` is added only while the elastic one is below
    the cap (``ViscoelasticPM.cpp``). ``(w_t, zeta_t)`` are the tangential oscillator of
    the contact point (angular frequency over ``omega0``, damping ratio; contact-point
    mass ``m / F``), ``w0 = v_c0 / v_z0`` (array). Leapfrog steps as Yade's
    ``NewtonIntegrator``.

    ``rho`` (array like ``w0``, or ``None``): the sphere radius in units of ``v0/omega0``.
    Given, the lever arm of the contact point is ``R - delta`` (Yade's
    ``Ig2_Wall_Sphere_ScGeom`` puts the contact point where the sphere's centre projects
    onto the wall): the contact point moves with ``v_x - (R - delta) omega`` and the
    torque has that arm. ``None``: arm ``R`` (the one-contact law).

    ``zeta``, ``w_t``, ``zeta_t``, ``F``, ``mu`` may also be arrays of the shape of ``w0``
    (one contact per point, e.g. several contacts' candidates of a fit in one call: each
    point then gets what it gets alone); ``rho`` ``inf`` at a point is the arm ``R``.

    Returns
    -------
    (e, beta) : arrays; ``beta = -w_end / w0``
    """
    w0 = np.asarray(w0, dtype=float)
    lever = None if rho is None else 1.0 / np.broadcast_to(np.asarray(rho, dtype=float),
                                                         w0.shape)
    w_t, zeta_t, F = (np.asarray(a, dtype=float) for a in (w_t, zeta_t, F))
    k_t = w_t * w_t / F  # tangential stiffness per unit mass (contact-point mass m / F)
    c_t = 2.0 * zeta_t * w_t / F
    return _stepped(LAW_YADE, np.zeros(w0.shape), w0, mu, steps, (zeta, k_t, c_t), F, lever,
                    contact_time=math.pi)


def mfix_coulomb(zeta: float, w_t: float, zeta_t, F: float, mu: float, w0,
                 steps: int = FRICTION_STEPS) -> tuple[np.ndarray, np.ndarray]:
    """Return the normal and tangential restitution of MFiX's linear spring-dashpot with friction.

    MFiX's ``LSD`` law in an oblique impact with Coulomb friction, stepped as MFiX
    steps it.

    In the units of :func:`linear_spring_dashpot` (time ``1/omega0``, lengths
    ``v0/omega0``): normal force ``u + 2 zeta u'`` (not clipped; the contact ends at
    zero overlap); tangential (``calc_force_dem.f``, ``cfslide.f``): the history ``s``
    grows by ``w dt``, the trial force is ``(w_t^2 s + 2 zeta_t w_t w) / F`` and, when it
    exceeds ``mu`` times the magnitude of the normal force, the force is ``mu |f|``
    against the sliding velocity and the history is set to its elastic part. Forces
    from the current state, then velocities, then positions (MFiX's explicit Euler
    with the new velocity). ``(w_t, zeta_t)`` as in :func:`yade_coulomb`; ``zeta_t``
    may be an array broadcasting with ``w0`` (candidates of a fit).

    Returns
    -------
    (e, beta) : arrays of the broadcast shape; ``beta = -w_end / w0``
    """
    w0, zt = np.broadcast_arrays(np.asarray(w0, dtype=float), np.asarray(zeta_t, dtype=float))
    shape = w0.shape
    w0, zt = w0.ravel(), zt.ravel()
    h = math.pi / steps
    cap = min(float(mu), 1e300)
    spin = F - 1.0
    k, c = w_t * w_t / F, 2.0 * zt * w_t / F
    x = np.zeros_like(w0)
    v = np.ones_like(w0)
    s = np.zeros_like(w0)
    ux = w0.copy()
    om = np.zeros_like(w0)
    live = np.ones(w0.shape, dtype=bool)
    e = np.full_like(w0, np.nan)
    wend = np.full_like(w0, np.nan)
    first = True
    for _ in range(50 * steps):
        w = ux - om
        f = x + 2.0 * zeta * v
        s = s + h * w
        ft = k * s + c * w
        over = np.abs(ft) > cap * np.abs(f)
        if np.any(over):
            lim = cap * np.abs(f) * np.sign(w)
            ft = np.where(over, lim, ft)
            s = np.where(over, (ft - c * w) / k, s) if k > 0.0 else s
        if first:  # the first step starts at contact: no force yet
            f, ft, first = np.zeros_like(f), np.zeros_like(ft), False
        v = v - h * f
        ux = ux - h * ft
        om = om + h * spin * ft
        x = x + h * v
        if _record_ended(live, x, v, ux, om, e, wend):
            break
    return _stepped_result(live, e, wend, w0, shape)


def _record_ended(live: np.ndarray, x: np.ndarray, v: np.ndarray, ux: np.ndarray,
                  om: np.ndarray, e: np.ndarray, wend: np.ndarray) -> bool:
    """Record the contacts whose overlap ``x`` is back to zero; return True when none is live.

    Their normal restitution ``e = -v`` and contact-point velocity ``ux - om`` are
    written into ``e`` and ``wend``, and they leave ``live`` (all updated in place).
    """
    ended = live & (x <= 0.0)
    e[ended] = -v[ended]
    wend[ended] = (ux - om)[ended]
    live &= ~ended
    return not live.any()


def _stepped_result(live: np.ndarray, e: np.ndarray, wend: np.ndarray, w0: np.ndarray,
                    shape: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(e, beta = -w_end / w0)`` in ``shape``; refuse a contact that never ended."""
    if live.any():
        raise RuntimeError("stepped contact law did not end its contact")
    return e.reshape(shape), (-wend / w0).reshape(shape)


def _stepped(law: int, alpha: np.ndarray, w0: np.ndarray, mu, steps: int, constants, F,
             lever=None, contact_time: float = HERTZ_TIME_FACTOR) -> tuple[np.ndarray, np.ndarray]:
    """Step many oblique impacts with velocity Verlet until each contact ends; return ``(e, beta)``.

    ``steps`` per ``contact_time`` (the elastic Hertz contact time in the time unit ``T
    = d_H / v0`` by default, ``pi`` for a linear law in ``1/omega0``), until the overlap
    is back to zero, under the law ``law`` (``LAW_*`` of :mod:`vimpact.kernels.stepped`,
    which steps them) with its ``constants``. The centre moves by ``-a_t``, the spin (``R
    omega``) by ``arm (F - 1) a_t`` with the lever ``arm = 1 - lever x`` (``lever`` per
    point, or 0), and the contact point with ``w = u_x - arm R omega``. ``mu``, ``F`` and
    each constant: numbers, or arrays that broadcast with ``alpha`` (per point).
    """
    alpha, w0 = np.broadcast_arrays(alpha, w0)
    shape = alpha.shape

    def column(a) -> np.ndarray:
        return np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=float), shape).ravel())

    n = alpha.size
    p = np.zeros((n, 3))
    for k, c in enumerate(constants):
        p[:, k] = column(c)
    e, wend = np.empty(n), np.empty(n)
    w0 = column(w0)
    # stick: the tangential force still ends with the normal one
    unfinished = stepped_impacts(
        np.int64(law), column(alpha), w0,
        np.zeros(n) if lever is None else column(lever), column(F) - 1.0,
        np.minimum(column(mu), 1e300), p, contact_time / steps, np.int64(50 * steps), e, wend)
    if unfinished:
        raise RuntimeError("stepped contact law did not end its contact")
    return e.reshape(shape), (-wend / w0).reshape(shape)


# ---- Tsuji-type Hertz (LIGGGHTS) ----------------------------------------

def liggghts_beta(e_in: float) -> float:
    """LIGGGHTS' ``beta = ln e / sqrt(ln^2 e + pi^2)`` of an input restitution ``e_in`` in (0, 1]."""
    if e_in >= 1.0:
        return 0.0
    le = math.log(e_in)
    return le / math.sqrt(le * le + math.pi**2)


def tsuji_hertz_e(e_in: float, clipped: bool = False) -> float:
    """Return the restitution the LIGGGHTS Hertz law produces from its input restitution.

    The input is ``coefficientRestitution`` ``e_in``; the law is speed-independent:
    ``x'' = -(5/4) x^1.5 - 2.5 |beta| x^0.25 x'`` (overlap in ``d_H``, time in
    ``d_H / v0``).
    """
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
    """Return the normal (and tangential) restitution of a linear spring-dashpot contact.

    Parameters
    ----------
    zeta : normal damping ratio ``c / (2 sqrt(k m))``, >= 0; time unit ``1/omega0``
    ends : ``"overlap"`` (contact ends when the overlap returns to zero: Yade,
        MFiX) or ``"force"`` (when the force does; docs/physics.md#linear-model)
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
    """Return the damping ratio for which a linear spring-dashpot restitutes ``e``.

    The contact ends at zero overlap: ``|ln e| / sqrt(pi^2 + ln^2 e)`` (the usual
    DEM formula).
    """
    if e >= 1.0:
        return 0.0
    le = math.log(e)
    return -le / math.sqrt(math.pi**2 + le * le)


if __name__ == "__main__":
    print("wrote", write_table())
