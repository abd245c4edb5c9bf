"""The inputs of a lookup checked and broadcast, and its result put together.

Each query parameter is checked against what the table holds (its model, its
``psi`` and ``theta_ratio`` values) before any interpolation, and refused with
the parameter, the value and what is allowed. :func:`incidence` turns an impact
angle and a friction coefficient into the friction incidence ``psi`` a friction
table is looked up at.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from vimpact.lookup.columns import LOOKUP_METHODS, OUTPUTS, fmt
from vimpact.model.validation import InputError

__all__ = ["incidence", "lookup_result", "query_arrays"]


def incidence(angle_deg, mu, nu):
    """Maw, Barber and Fawcett's incidence ``psi`` of a non-spinning sphere.

    ``psi = 2 (1 - nu) / (mu (2 - nu)) * v_c0 / v_z0`` with ``v_c0 / v_z0 = tan(angle)``
    (no initial spin: the contact point moves with the centre).

    Parameters
    ----------
    angle_deg : float or array_like
        Impact angle from the surface normal, degrees, in [0, 90).
    mu : float
        Coulomb friction coefficient, dimensionless, > 0 (``inf``: full stick, ``psi = 0``).
    nu : float or array_like
        Poisson ratio, dimensionless, in [0, 0.5].

    Returns
    -------
    float or numpy.ndarray
        ``psi``, dimensionless (a float for scalar inputs).

    Raises
    ------
    InputError
        For an angle, ``mu`` or ``nu`` outside its range.
    """
    angle = np.asarray(angle_deg, dtype=float)
    if not np.all(np.isfinite(angle) & (angle >= 0.0) & (angle < 90.0)):
        bad = angle[~(np.isfinite(angle) & (angle >= 0.0) & (angle < 90.0))].flat[0]
        raise InputError(f"angle_deg = {float(bad)!r} is not allowed: the impact angle from the "
                         "normal must be in [0, 90) degrees")
    mu = float(mu)
    if not (mu > 0.0):  # NaN too
        raise InputError(f"mu = {mu!r} is not allowed: the friction coefficient must be > 0 "
                         "(inf for full stick)")
    nu = np.asarray(nu, dtype=float)
    if not np.all((nu >= 0.0) & (nu <= 0.5)):
        raise InputError(f"nu = {float(nu[~((nu >= 0) & (nu <= 0.5))].flat[0])!r} is not "
                         "allowed: must be in [0, 0.5]")
    from vimpact.tableformat.parameters import incidence as psi_of  # the one psi rule

    ratio = np.tan(np.radians(angle))
    psi = psi_of(mu, nu, ratio, np.ones_like(ratio))
    return float(psi) if np.ndim(psi) == 0 else psi


def query_arrays(model: str, method: str, Q1, nu, Q2, psi, theta_ratio, psis: np.ndarray,
                 thetas: np.ndarray, resolve_theta: Callable[[float | None], float | None],
                 ) -> tuple[dict[str, np.ndarray], tuple[np.ndarray, ...]]:
    """Check the inputs of a lookup and broadcast them together.

    Parameters
    ----------
    model : str
        The table's rheology (``Q2`` is required for ``standard_solid``, refused for
        ``kelvin_voigt``).
    method : str
        Interpolation method, one of :data:`~vimpact.lookup.columns.LOOKUP_METHODS`.
    Q1, nu, Q2, psi, theta_ratio : float, array_like or None
        As given to :meth:`vimpact.lookup.table.RestitutionTable.lookup` (dimensionless).
    psis : numpy.ndarray
        The table's friction incidences (empty: no psi axis).
    thetas : numpy.ndarray
        The table's ``theta_ratio`` values (an axis when there are several).
    resolve_theta : callable
        Refuses a ``theta_ratio`` the table does not hold
        (:meth:`vimpact.lookup.grid.TensorLookup.resolve_theta`).

    Returns
    -------
    arrays : dict
        Axis -> broadcast float array: ``Q1``, (``Q2``), ``nu``, (``theta_ratio`` when it
        is an axis), (``psi`` when the table has one; its only value if not given).
    bcast : tuple of numpy.ndarray
        The inputs as given, broadcast (0-d for scalars).

    Raises
    ------
    InputError
        Naming the parameter, the value and what is allowed.
    """
    if method not in LOOKUP_METHODS:
        raise InputError(f"method = {method!r} is not allowed: must be one of "
                         + ", ".join(LOOKUP_METHODS))
    if model == "kelvin_voigt" and Q2 is not None:
        raise InputError(f"Q2 = {Q2!r} is not allowed: this is a kelvin_voigt table "
                         "(e_z, e_x depend on Q1 and nu only); omit Q2 or use a "
                         "standard_solid table")
    if model == "standard_solid" and Q2 is None:
        raise InputError("Q2 is missing: this is a standard_solid table, lookup needs "
                         "Q2 = G1/G2 as well as Q1 and nu")
    if psi is not None and not len(psis):
        raise InputError(f"psi = {psi!r} is not allowed: the table has no psi column (it is "
                         "for full stick, mu = inf); omit psi or use a table swept over psi")
    if psi is None and len(psis) > 1:
        raise InputError("psi is missing: the table holds several friction incidences psi = "
                         + fmt(psis[0]) + " .. " + fmt(psis[-1]) + "; give psi (>= 0, "
                         "2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0)")
    theta_axis = len(thetas) > 1
    if not theta_axis:  # one value: only it (raises otherwise)
        for t in ([None] if theta_ratio is None else
                  np.unique(np.asarray(theta_ratio, dtype=float).ravel())):
            resolve_theta(None if t is None else float(t))
    elif theta_ratio is None:
        resolve_theta(None)  # raises: several values, give one
    named = {"Q1": Q1, "nu": nu} if Q2 is None else {"Q1": Q1, "Q2": Q2, "nu": nu}
    if theta_axis:
        named["theta_ratio"] = theta_ratio
    if len(psis):
        named["psi"] = psis[0] if psi is None else psi
    arrays = {}
    for name, value in named.items():
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{name} = {value!r} is not allowed: must be a number or "
                             "an array of numbers") from None
        if not np.all(np.isfinite(arr)):
            bad = float(arr[~np.isfinite(arr)].flat[0])
            raise InputError(f"{name} = {bad!r} is not allowed: must be finite")
        if name in ("psi", "theta_ratio") and np.any(arr < 0.0 if name == "psi" else arr <= 0.0):
            bad = float(arr[arr < 0.0 if name == "psi" else arr <= 0.0].flat[0])
            raise InputError(f"{name} = {bad!r} is not allowed: must be "
                             + (">= 0" if name == "psi" else "> 0"))
        arrays[name] = arr
    try:
        bcast = np.broadcast_arrays(*arrays.values())
    except ValueError:
        raise InputError(", ".join(arrays) + " have shapes "
                         + ", ".join(str(a.shape) for a in arrays.values())
                         + " that do not broadcast together") from None
    return dict(zip(arrays, bcast)), tuple(bcast)


def lookup_result(arrays: dict, out: dict, bcast: Sequence[np.ndarray],
                  bound: dict | None) -> dict:
    """Return the inputs and the outputs of a lookup, floats for scalar inputs.

    Parameters
    ----------
    arrays : dict
        Axis -> broadcast input array (:func:`query_arrays`).
    out : dict
        Output name -> interpolated array.
    bcast : sequence of numpy.ndarray
        The broadcast inputs (all 0-d: floats are returned).
    bound : dict or None
        The table's error bound for the method (stored as ``error_bound``).

    Returns
    -------
    dict
        ``arrays`` and the :data:`~vimpact.lookup.columns.OUTPUTS`, then ``error_bound``.
    """
    result = {**arrays, **{k: out[k] for k in OUTPUTS}}
    if all(a.ndim == 0 for a in bcast):
        result = {k: float(v) for k, v in result.items()}
    else:
        result = {k: np.asarray(v, dtype=float) for k, v in result.items()}
    result["error_bound"] = bound
    return result
