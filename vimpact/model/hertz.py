"""Hertz scales of the elastic impact of a rigid sphere on a half-space.

docs/physics.md#hertz-scales. All lengths in m, times in s, moduli in Pa, masses in kg.
The kernels work in the units defined here: indentation in units of ``d``,
element positions in units of ``a_H``, time in units of ``T = d / v_z0``,
velocities in units of ``v_z0``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

#: ``t_H / T = 2 * int_0^1 dxi / sqrt(1 - xi^(5/2)) = (4/5) B(2/5, 1/2)``
#: (substitute ``s = xi^(5/2)``); docs/physics.md quotes 2.9432751843.
HERTZ_TIME_FACTOR: float = 0.8 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)

#: ``Q1 = sqrt(15/32) * (eta / G_inf) / T`` (docs/physics.md#dimensionless-parameters).
Q1_PER_TAU: float = math.sqrt(15.0 / 32.0)

#: Element stiffness per unit length in kernel units: ``E* a_H d^2 / (m v_z0^2) = 15/16``.
ELEMENT_STIFFNESS: float = 15.0 / 16.0


def effective_modulus(G, nu):
    """Effective modulus ``E* = 2 G / (1 - nu)`` of a half-space under a rigid sphere, Pa."""
    return 2.0 * np.asarray(G, dtype=float) / (1.0 - np.asarray(nu, dtype=float))


class HertzScales(NamedTuple):
    """Hertz reference values of an elastic impact (docs/physics.md#hertz-scales).

    Attributes
    ----------
    d : maximum elastic indentation, m
    a_H : Hertz contact radius at maximum indentation, m
    T : time unit ``d / v_z0``, s
    t_H : elastic contact time, s
    """

    d: float | np.ndarray
    a_H: float | np.ndarray
    T: float | np.ndarray
    t_H: float | np.ndarray


def hertz_scales(G, nu, R, m, v_z0) -> HertzScales:
    """Return the Hertz scales of an elastic impact (works on arrays).

    Works elementwise on arrays. For a viscoelastic material pass the relaxed
    (long-time) modulus ``G_inf``.

    Parameters
    ----------
    G : float or array_like
        Shear modulus, Pa.
    nu : float or array_like
        Poisson ratio, dimensionless.
    R : float or array_like
        Sphere radius, m.
    m : float or array_like
        Sphere mass, kg.
    v_z0 : float or array_like
        Normal impact speed, m/s.

    Returns
    -------
    HertzScales
        ``d`` (m), ``a_H`` (m), ``T`` (s) and ``t_H`` (s); floats for scalar inputs.
    """
    E_star = effective_modulus(G, nu)
    R = np.asarray(R, dtype=float)
    m = np.asarray(m, dtype=float)
    v_z0 = np.asarray(v_z0, dtype=float)
    d = (15.0 * m * v_z0**2 / (16.0 * E_star * np.sqrt(R))) ** 0.4
    a_H = np.sqrt(R * d)
    T = d / v_z0
    out = HertzScales(d, a_H, T, HERTZ_TIME_FACTOR * T)
    if np.ndim(out.d) == 0:
        out = HertzScales(*(float(x) for x in out))
    return out
