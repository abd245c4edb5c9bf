"""Gross slip in closed form: the part of a friction table's incidence axis not tabulated.

Under Coulomb friction the tangential restitution over the incidence
``psi = 2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0`` has kinks where the course of the
contact changes (docs/physics.md#coulomb-friction). Beyond the last one the contact
slips throughout: the tangential force is ``mu F_z`` at all times, so the contact
point's velocity changes by ``mu (1 + m R^2 / Theta) (1 + e_z) v_z0`` whatever the
rheology, and

    beta_x = -1 + 2 chi (1 + e_z) / psi,   chi = (1 - nu) (1 + m R^2 / Theta) / (2 - nu),

with ``e_z`` the normal restitution, which friction does not change. Since
``|F_x| <= mu F_z`` at all times, this is also an upper bound of ``beta_x`` at every
``psi``. It reaches ``beta_x = 0`` (the contact point just stops at the end) at
``psi_g = 2 chi (1 + e_z)`` (for the elastic sphere, ``e_z = 1``, Maw, Barber and
Fawcett's ``psi_1 = 4 chi``). Gross slip throughout holds at least from ``psi_g`` on;
the tangential compliance lets it begin somewhat below (measured on a Kelvin-Voigt
half-space, ``Q1 = 0.1``, ``nu = 0.3``: from about ``0.84 psi_g``, where ``beta_x``
is 0.19), so the kink where microslip meets gross slip is below ``psi_g`` and is
found by simulation, not by this closed form.
"""

from __future__ import annotations

import numpy as np

__all__ = ["chi", "gross_slip_beta_x", "gross_slip_onset"]


def chi(nu, theta_ratio=0.4, rotation: bool = True):
    """Mindlin ratio times the contact-point mass factor, ``(1 - nu)(1 + 1/theta_ratio)/(2 - nu)``.

    Parameters
    ----------
    nu : Poisson ratio, dimensionless, in [0, 0.5]
    theta_ratio : ``Theta / (m R^2)``, dimensionless, > 0
    rotation : the sphere may spin (without: mass factor 1)
    """
    nu = np.asarray(nu, dtype=float)
    factor = 1.0 + 1.0 / np.asarray(theta_ratio, dtype=float) if rotation else 1.0
    return (1.0 - nu) * factor / (2.0 - nu)


def gross_slip_onset(e_z, nu, theta_ratio=0.4, rotation: bool = True):
    """Return the incidence ``psi_g = 2 chi (1 + e_z)`` of the gross-slip onset.

    There the gross-slip closed form gives ``beta_x = 0``; the contact slips
    throughout at every ``psi >= psi_g``.

    Parameters
    ----------
    e_z : normal restitution, dimensionless, in [0, 1]
    nu, theta_ratio, rotation : as for :func:`chi`

    Returns
    -------
    psi_g, dimensionless (array or float)
    """
    return 2.0 * chi(nu, theta_ratio, rotation) * (1.0 + np.asarray(e_z, dtype=float))


def gross_slip_beta_x(psi, e_z, nu, theta_ratio=0.4, rotation: bool = True):
    """``beta_x = -1 + 2 chi (1 + e_z) / psi`` of gross slip throughout (``psi >= psi_g``).

    Parameters
    ----------
    psi : incidence, dimensionless, > 0
    e_z, nu, theta_ratio, rotation : as for :func:`gross_slip_onset`

    Returns
    -------
    beta_x, dimensionless; NaN where ``psi < psi_g`` (not gross slip throughout: a
    table or a simulation is needed there)
    """
    psi = np.asarray(psi, dtype=float)
    onset = gross_slip_onset(e_z, nu, theta_ratio, rotation)
    with np.errstate(divide="ignore", invalid="ignore"):
        beta = -1.0 + onset / psi
    return np.where(psi >= onset * (1.0 - 1e-12), beta, np.nan)
