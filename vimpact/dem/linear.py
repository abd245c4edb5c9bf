"""What the linear spring-dashpot codes (Yade, MFiX) share.

The contact-point mass factor, the Hertz-equivalent contact time and the
tangential restitution of a linear contact in stick.
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.dem import laws
from vimpact.dem.problem import Contact
from vimpact.model.pair import Wall


def mass_factor(contact: Contact) -> float:
    """Return the contact-point mass factor ``F = 1 + m_eff (R1^2/Theta1 + R2^2/Theta2)``.

    At the nominal sizes; dimensionless. The contact point moves ``F`` times
    faster than the centres under a tangential force (3.5 for solid spheres).
    """
    b1, b2 = contact.levels()[len(contact.levels()) // 2]
    _, m = contact.nominal()
    spin = b1.spin_compliance + (0.0 if isinstance(b2, Wall) else b2.spin_compliance)
    return 1.0 + m * spin


def hertz_time(contact: Contact, speeds) -> float:
    """Return the elastic Hertz contact time of the pair, s.

    At the nominal sizes and the geometric mean of ``speeds`` (m/s): the linear
    codes' (speed-independent) contact time.
    """
    R, m = contact.nominal()
    v = float(np.exp(np.mean(np.log(speeds))))
    return float(laws.hertz_contact_time(contact.E_star, R, m, v))


def tangential_beta(en: float, w_t: float, zeta_t: float) -> float:
    """Return ``beta`` of a linear contact in stick that ends at zero overlap.

    Normal restitution ``en``; the tangential oscillator has angular frequency
    ``w_t / omega0`` and damping ratio ``zeta_t`` (all dimensionless).
    """
    return laws.linear_spring_dashpot(laws.zeta_of_restitution(en), "overlap",
                                      (w_t, zeta_t))[1]


def ln2(e: float) -> float:
    """Return ``(ln e)^2`` (``inf`` for ``e = 0``), as in the linear law's damping."""
    return math.log(e)**2 if e > 0 else math.inf
