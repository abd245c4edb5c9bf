"""The stepped friction laws of the DEM codes as NumPy loops over steps (all points at once).

The implementation ``vimpact.dem.laws`` had before its stepping moved into a numba
kernel (:mod:`vimpact.kernels.stepped`): kept as the oracle the kernel is compared
with bit for bit (``tests/dem/test_stepped_kernel.py``).
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.dem.laws import FRICTION_STEPS, liggghts_beta
from vimpact.model.hertz import HERTZ_TIME_FACTOR


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


def _stepped(alpha: np.ndarray, w0: np.ndarray, mu, steps: int, force, F,
             lever=None, contact_time: float = HERTZ_TIME_FACTOR) -> tuple[np.ndarray, np.ndarray]:
    """Step many oblique impacts with velocity Verlet until each contact ends; return ``(e, beta)``.

    ``steps`` per ``contact_time`` (the elastic Hertz contact time in the time unit ``T
    = d_H / v0`` by default, ``pi`` for a linear law in ``1/omega0``), until the overlap
    is back to zero. ``force(x, v, s, w, alpha, mu) -> (a_n, a_t, s)`` gives the normal
    acceleration and the tangential force per unit mass (positive decelerates) and the
    history after the friction cap. The centre moves by ``-a_t``, the spin (``R omega``)
    by ``arm (F - 1) a_t`` with the lever ``arm = 1 - lever x`` (``lever`` per point, or
    0), and the contact point with ``w = u_x - arm R omega``. ``mu`` and ``F``: numbers, or
    arrays that broadcast with ``alpha`` (per point; the force then gets ``mu`` per point).
    """
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
