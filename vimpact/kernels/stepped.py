"""Oblique impacts stepped under the friction laws of DEM codes, several points side by side.

The kernel of :mod:`vimpact.dem.laws`' stepped laws (LAMMPS' Hertz-Mindlin,
MercuryDPM's Hertz-Mindlin species, LIGGGHTS' Hertz with history, Yade's
viscoelastic law): velocity Verlet in the law's own dimensionless units, the
normal overlap ``x`` (from 0, speed 1), the tangential history ``s``, the
centre's tangential speed ``u_x`` (from ``w0``) and the spin ``R omega`` (from
0), until the overlap is back to zero. The centre moves by ``-a_t``, the spin by
``arm (F - 1) a_t`` with the lever ``arm = 1 - lever x``, and the contact point
with ``w = u_x - arm R omega``. Which law is the integer ``law`` (``LAW_*``); its
constants per point are the columns of ``p`` (below). Every point is independent:
the arithmetic is that of the laws written with NumPy over all points at once, in
the same order, so the numbers are the same bit for bit (and the same whichever
points share the lanes of :func:`stepped_impacts`).

Constants ``p[:, 0..3]`` of each law (units of :mod:`vimpact.dem.laws`):

- ``LAW_LAMMPS``: ``kappa``, ``x_gamma`` (force ``1.5 kappa sqrt(x) s + 1.5 alpha
  x_gamma sqrt(x) w``, the history reset to the elastic part at the cap)
- ``LAW_MERCURY``: ``K``, ``D`` (elastic ``K sqrt(x) s``, dashpot ``D x^(1/4) w``
  below the cap)
- ``LAW_LIGGGHTS``: ``|beta|``, ``K``, ``D`` (normal force not clipped, the cap on its
  magnitude)
- ``LAW_YADE``: ``zeta``, ``k_t``, ``c_t`` (incremental elastic force, the dashpot
  only below the cap; normal force clipped)
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.kernels.jit import jit

LAW_LAMMPS = 0
LAW_MERCURY = 1
LAW_LIGGGHTS = 2
LAW_YADE = 3


@jit(internal=True, nrt=False)
def _sign(x):
    """``np.sign`` of a float: -1, 0 or 1 (NaN for NaN)."""
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    if x == 0.0:
        return 0.0
    return x


@jit(internal=True, nrt=False)
def _force(law, x, v, s, w, alpha, cap, p0, p1, p2):
    """Return ``(a_n, a_t, s)``: normal and tangential force per unit mass, history after the cap."""
    if law == LAW_LAMMPS:
        r = math.sqrt(max(x, 0.0))
        f = max(x * r + 1.5 * alpha * r * v, 0.0)
        ft = 1.5 * p0 * r * s + 1.5 * alpha * p1 * r * w
        if abs(ft) > cap * f:
            lim = _sign(ft) * cap * f
            k = 1.5 * p0 * r
            if s != 0.0 and k > 0.0:
                s = (lim - 1.5 * alpha * p1 * r * w) / k
            ft = lim if s != 0.0 else 0.0
        return 1.25 * f, 1.25 * ft, s
    if law == LAW_MERCURY:
        r = math.sqrt(max(x, 0.0))
        f = max(x * r + 1.5 * alpha * r * v, 0.0)
        el = p0 * r * s
        lim = _sign(el) * cap * f
        k = p0 * r
        if abs(el) > cap * f:
            s = lim / k if k > 0.0 else 0.0
            ft = lim
        else:
            ft = el + p1 * math.sqrt(r) * w
        return 1.25 * f, 1.25 * ft, s
    if law == LAW_LIGGGHTS:
        xp = max(x, 0.0)
        r = math.sqrt(xp)
        q = math.sqrt(r)
        f = xp * r + 2.0 * p0 * q * v
        el = p1 * r * s
        lim = _sign(el) * cap * abs(f)
        k = p1 * r
        if abs(el) > cap * abs(f):
            s = lim / k if k > 0.0 else 0.0
            ft = lim
        else:
            ft = el + p2 * q * w
        return 1.25 * f, 1.25 * ft, s
    # LAW_YADE
    f = max(x + 2.0 * p0 * v, 0.0)
    el = p1 * s
    if abs(el) > cap * f:
        el = _sign(el) * cap * f
        if p1 > 0.0:
            s = el / p1
        return f, el + 0.0, s
    return f, el + p2 * w, s


#: points stepped side by side (:func:`stepped_impacts`)
LANES = 8


def lanes_work() -> tuple[np.ndarray, np.ndarray]:
    """Return the work space ``(point, state)`` of :func:`stepped_impacts`' lanes."""
    return np.empty((2, LANES), dtype=np.int64), np.empty((7, LANES))


@jit(nrt=False)
def stepped_impacts(law, alpha, w0, lever, spin, cap, p, h, max_steps, e, w_end, point, state):
    """Step every point's impact until its overlap is back to zero.

    :data:`LANES` points are stepped side by side, one step of each in turn, and a
    point that ends hands its lane to the next point not yet started: the steps of
    different points do not wait for each other (one point's steps form a chain of
    dependent operations, which alone leaves the processor idle most of the time).
    Each point's arithmetic is its own, in the order of the laws (bit for bit what it
    gives stepped alone).

    Parameters
    ----------
    law : ``LAW_*``
    alpha, w0, lever, spin, cap : 1-D, one per point: the law's damping parameter
        (``alpha = A v0 / d_H`` for LAMMPS and MercuryDPM, else unused), ``v_c0 /
        v_z0``, the lever coefficient (0: arm ``R``), ``F - 1`` (``F`` the contact-point
        mass factor) and the Coulomb cap ``min(mu, 1e300)``
    p : ``(n, 3)`` the law's constants per point (module docstring)
    h : time step in the law's time unit; max_steps : steps at most
    e, w_end : 1-D outputs: ``-v`` and ``u_x - R omega`` where the overlap ended
        (NaN where it did not within ``max_steps``)
    point, state : work space of the lanes, ``(2, LANES)`` int64 and ``(7, LANES)`` float
        (the kernel allocates nothing: it compiles without reference counting)

    Returns the number of points whose overlap did not end within ``max_steps``.
    """
    n = w0.shape[0]
    for i in range(n):
        e[i] = np.nan
        w_end[i] = np.nan
    # per lane: its point (-1: none left), steps taken and the state of the point
    taken = point[1]
    point = point[0]
    x = state[0]
    v = state[1]
    s = state[2]
    ux = state[3]
    om = state[4]
    an = state[5]
    at = state[6]
    started = 0
    for k in range(LANES):
        point[k] = -1
        taken[k] = 0
        x[k], v[k], s[k], ux[k], om[k], an[k], at[k] = 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
        if k < n:
            point[k] = k
            ux[k] = w0[k]
            started += 1
    live = started
    unfinished = 0
    while live > 0:
        for k in range(LANES):
            i = point[k]
            if i < 0:
                continue
            lev = lever[i]
            sp = spin[i]
            arm = 1.0 - lev * x[k]
            v_half = v[k] - 0.5 * h * an[k]
            ux_half = ux[k] - 0.5 * h * at[k]
            om_half = om[k] + 0.5 * h * arm * sp * at[k]
            xk = x[k] + h * v_half
            arm = 1.0 - lev * xk
            w_half = ux_half - arm * om_half
            sk = s[k] + h * w_half
            ank, atk, sk = _force(law, xk, v_half, sk, w_half, alpha[i], cap[i], p[i, 0],
                                  p[i, 1], p[i, 2])
            vk = v_half - 0.5 * h * ank
            uxk = ux_half - 0.5 * h * atk
            omk = om_half + 0.5 * h * arm * sp * atk
            taken[k] += 1
            if xk <= 0.0 or taken[k] >= max_steps:
                if xk <= 0.0:
                    e[i] = -vk
                    w_end[i] = uxk - omk
                else:
                    unfinished += 1
                if started < n:  # the lane takes the next point, from contact
                    point[k] = started
                    taken[k] = 0
                    x[k], v[k], s[k], ux[k], om[k], an[k], at[k] = (
                        0.0, 1.0, 0.0, w0[started], 0.0, 0.0, 0.0)
                    started += 1
                else:
                    point[k] = -1
                    live -= 1
                continue
            x[k], v[k], s[k], ux[k], om[k], an[k], at[k] = xk, vk, sk, uxk, omk, ank, atk
    return unfinished
