"""Where gross slip throughout begins: the kink a friction table's psi nodes must sit on.

Above the incidence ``psi_s`` the contact slips throughout and ``beta_x`` is the
closed form of :mod:`vimpact.lookup.friction`; below it the contact sticks part of
the time. ``psi_s`` lies below ``psi_g = 2 chi (1 + e_z)`` (where the closed form
reaches ``beta_x = 0``), by an amount the tangential compliance sets, so it is found
by simulation (measured on a Kelvin-Voigt half-space: ``psi_g - psi_s`` = 0.997 at
``Q1 = 1e-3``, ``nu = 0.3``, near the elastic sphere's ``4 chi - (4 chi - 1) = 1``
of Maw, Barber and Fawcett; ``psi_s / psi_g`` = 0.85 at ``Q1 = 0.1``, 0.93 at
``Q1 = 1``, ``nu = 0.5``). :func:`gross_slip_start` bisects on the simulated fraction of the
contact time in gross slip (the same at every incidence past the start), all
points at once.
"""

from __future__ import annotations

import numpy as np

from vimpact.lookup.friction import gross_slip_onset
from vimpact.model.validation import InputError
from vimpact.tablebuild.verify import simulate_dimensionless

__all__ = ["gross_slip_start"]

#: Two gross-slip fractions this close are the same (the fraction of a contact that
#: slips throughout is a little below 1, the same at every psi past the start: the
#: first instants of contact count as stick).
SAME_FRACTION = 1e-9


def gross_slip_start(model: str, Q1, nu, Q2=None, *, theta_ratio: float = 0.4,
                     numerics=None, rel_tol: float = 1e-4, mu: float = 1.0,
                     simulate=None) -> dict:
    """Find the incidence ``psi_s`` above which the contact slips throughout, per point.

    Parameters
    ----------
    model : ``"kelvin_voigt"`` or ``"standard_solid"``
    Q1, nu, Q2 : arrays of one length (``Q2`` for a standard solid), dimensionless
    theta_ratio : ``Theta / (m R^2)``, dimensionless
    numerics : :class:`vimpact.Numerics` (default ``Numerics()``)
    rel_tol : bisection stops when the bracket is narrower than ``rel_tol psi_g``
    mu : friction coefficient of the simulated scenes (the result depends on psi only)
    simulate : the direct simulation (default
        :func:`vimpact.tablebuild.verify.simulate_dimensionless`)

    Returns
    -------
    dict of arrays: ``psi_s`` (the bracket's upper end: gross slip throughout there),
    ``psi_g`` (the closed form's zero), ``e_z``, and ``bracket`` (its width).

    Raises
    ------
    InputError
        if ``psi_g`` is not in gross slip throughout for some point (its gross-slip
        fraction differs from the one at ``1.5 psi_g``): the bracket ``[0, psi_g]``
        would not hold the start.
    """
    sim = simulate or simulate_dimensionless
    nu = np.atleast_1d(np.asarray(nu, dtype=float))
    Q1 = np.broadcast_to(np.asarray(Q1, dtype=float), nu.shape)
    Q2 = None if Q2 is None else np.broadcast_to(np.asarray(Q2, dtype=float), nu.shape)
    opts = dict(numerics=numerics, theta_ratio=theta_ratio)
    e_z = sim(model, Q1, nu, Q2, **opts)["e_z"].to_numpy(float)
    psi_g = gross_slip_onset(e_z, nu, theta_ratio)

    def fraction(psi):
        out = sim(model, Q1, nu, Q2, psi=psi, mu=mu, **opts)
        return out["gross_slip_fraction"].to_numpy(float)

    full = fraction(psi_g)  # the closed form holds at psi_g: this is "throughout"
    check = fraction(1.5 * psi_g)
    if not np.all(np.abs(check - full) <= SAME_FRACTION):
        bad = int(np.flatnonzero(np.abs(check - full) > SAME_FRACTION)[0])
        raise InputError(f"Q1 = {Q1[bad]:.6g}, nu = {nu[bad]:.6g} is not allowed: the "
                         f"gross-slip fraction at psi_g = {psi_g[bad]:.6g} and 1.5 psi_g "
                         "differ, so psi_g is not in gross slip throughout")

    def throughout(psi):
        return fraction(psi) >= full - SAME_FRACTION

    lo, hi = np.zeros_like(psi_g), psi_g.copy()
    while np.any(hi - lo > rel_tol * psi_g):
        mid = 0.5 * (lo + hi)
        ok = throughout(mid)
        hi = np.where(ok, mid, hi)
        lo = np.where(ok, lo, mid)
    return {"psi_s": hi, "psi_g": psi_g, "e_z": e_z, "bracket": hi - lo}
