"""The dimensionless friction parameter of a table row: the incidence ``psi``.

One rule for the writer and the reader: a grid row at incidence ``psi`` is the
reference scene with the ``v_x0`` and ``mu`` of :func:`psi_reference`; a physical
row (or a lookup by impact angle) gets its ``psi`` from :func:`incidence`
(docs/physics.md#coulomb-friction).
"""

from __future__ import annotations

import numpy as np


def psi_reference(psi: np.ndarray, nu: np.ndarray, mu: float,
                  v_z0: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Tangential speed and friction coefficient of the reference scene at incidence ``psi``.

    With friction the result depends on ``psi = 2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0``
    (and ``chi``, fixed by ``nu`` and ``theta_ratio``), not on ``mu`` and ``v_c0``
    apart, so a grid row with ``psi > 0`` takes the given ``mu`` and
    ``v_x0 = psi mu (2 - nu) / (2 (1 - nu)) v_z0`` (``nu <= 0.5``: no division by 0).
    ``psi = 0`` is the limit ``mu -> inf`` at ``v_c0 != 0``: full stick, the stick
    grid's row (``v_x0 = v_z0``, ``mu = inf``), not a normal impact.

    Parameters
    ----------
    psi : incidence, dimensionless, >= 0
    nu : Poisson ratio, dimensionless, in [0, 0.5]
    mu : friction coefficient of the rows with ``psi > 0``, dimensionless, > 0
    v_z0 : normal impact speed of the reference scene, m/s

    Returns
    -------
    ``(v_x0, mu)``: m/s and dimensionless, one value per row.
    """
    psi = np.asarray(psi, dtype=float)
    stick = psi == 0.0
    v_x0 = np.where(stick, v_z0, psi * mu * (2.0 - nu) / (2.0 * (1.0 - nu)) * v_z0)
    return v_x0, np.where(stick, np.inf, mu)


def incidence(mu: np.ndarray, nu: np.ndarray, v_c0: np.ndarray, v_z0: np.ndarray) -> np.ndarray:
    """Return the incidence ``psi = 2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0`` of rows.

    Dimensionless: 0 for full stick (``mu = inf``) and for ``v_c0 = 0``; ``inf`` (signed) for ``mu = 0``
    with ``v_c0 != 0`` (frictionless).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        psi = 2.0 * (1.0 - nu) / (mu * (2.0 - nu)) * v_c0 / v_z0
        frictionless = np.sign(v_c0) * np.inf
    return np.where(v_c0 == 0.0, 0.0, np.where(mu == 0.0, frictionless, psi))


__all__ = ["incidence", "psi_reference"]
