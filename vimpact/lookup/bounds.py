"""The error bound a lookup returns with its values.

A verified table stores the interpolation error measured against direct simulation
at held-out points between its nodes (metadata ``vimpact.interpolation_error``,
written by :func:`vimpact.tablebuild.verify.interpolation_error`). Each lookup
returns the bound stored there for its method, per output.
"""

from __future__ import annotations

__all__ = ["error_bound"]


def error_bound(err: dict | None, method: str = "cubic") -> dict | None:
    """Return the error bound measured between the nodes for ``method``, per output.

    Parameters
    ----------
    err : dict or None
        The table's ``vimpact.interpolation_error`` entry (None: not measured).
    method : str
        The lookup's interpolation method; a bound measured for another method is
        no bound for this one.

    Returns
    -------
    dict or None
        ``{"e_z": ..., "beta_x": ..., "e_x": ...}``, dimensionless (the stored
        ``bound``, 1.5 times the largest error found at the held-out points, see
        :data:`vimpact.tablebuild.verify.BOUND_FACTOR`; the largest error itself in
        entries written before bounds were stored), or None if not measured for
        ``method``.
    """
    if not err or err.get("method", "cubic") != method:
        return None
    out = {}
    for k, v in err.get("outputs", {}).items():
        value = v.get("bound", v.get("max")) if isinstance(v, dict) else None
        out[k] = None if value is None else float(value)
    return out
