"""Error and time models of the accuracy benchmark.

Pareto fronts, fitted error laws ``err = a / steps^p + b / elements^q``, their envelope,
the time model, observed orders and the cheapest setting per tolerance.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .config import TOLERANCES


def _f(x) -> float | None:
    """JSON-safe float (None for NaN/inf)."""
    x = float(x)
    return x if math.isfinite(x) else None



def _num(x) -> float:
    return math.inf if x is None else x


def _orders(rows, floors) -> dict:
    """Return the observed orders on the base grid.

    Observed orders on the base grid along the diagonal (steps = 5
    elements), in steps at the largest elements present for every steps
    value, in elements at the largest steps present for every elements value.
    """
    rows = [r for r in rows if r["grid"] == "base"]
    steps = sorted({r["steps"] for r in rows})
    elements = sorted({r["elements"] for r in rows})
    have = {(r["steps"], r["elements"]): r for r in rows}
    e_fix = max((e for e in elements if all((s, e) in have for s in steps)), default=None)
    s_fix = max((s for s in steps if all((s, e) in have for e in elements)), default=None)
    lines = {
        "diagonal_steps_eq_5_elements": sorted(k for k in have if k[0] == 5 * k[1]),
        f"steps_at_elements_{e_fix}": [(s, e_fix) for s in steps] if e_fix else [],
        f"elements_at_steps_{s_fix}": [(s_fix, e) for e in elements] if s_fix else [],
    }
    out = {}
    for label, keys in lines.items():
        if len(keys) < 2:
            continue
        axis = 1 if label.startswith("elements_at") else 0
        x = [k[axis] for k in keys]
        out[label] = {
            "axis": "elements" if axis else "steps",
            "e_z": _slope(x, [_num(have[k]["e_z_error_max"]) for k in keys], floors["z"]),
            "e_x": _slope(x, [_num(have[k]["e_x_error_max"]) for k in keys], floors["x"]),
            "error": _slope(x, [_num(have[k]["error"]) for k in keys], floors["both"]),
        }
    return out


def _cheapest(rows, tol, key, by="seconds_per_impact") -> dict | str:
    """Return the setting with ``row[key] <= tol`` and the least ``row[by]``."""
    ok = [r for r in rows if r[key] is not None and r[key] <= tol]
    if not ok:
        return "not reached"
    r = min(ok, key=lambda r: r[by])
    return {"steps": r["steps"], "elements": r["elements"],
            "seconds_per_impact": r["seconds_per_impact"],
            "model_seconds_per_impact": r.get("model_seconds_per_impact"), "error": r[key]}



def pareto(times, errors) -> list[int]:
    """Return the Pareto front of (time, error) points.

    Indices of the non-dominated points (faster and more accurate than all
    others in one respect), sorted by time; non-finite errors never qualify.
    """
    order = sorted((i for i in range(len(times)) if math.isfinite(errors[i])),
                   key=lambda i: (times[i], errors[i]))
    front, best = [], math.inf
    for i in order:
        if errors[i] < best:
            front.append(i)
            best = errors[i]
    return front


def _slope(x, err, floor) -> dict:
    """Return an observed order: minus the slope of log err over log x.

    Observed order: minus the least-squares slope of log err over log x,
    on the points with err above 5x the reference's uncertainty ``floor``.
    """
    x, err = np.asarray(x, float), np.asarray(err, float)
    use = np.isfinite(err) & (err > 5.0 * floor)
    local = [_f(-math.log(err[i + 1] / err[i]) / math.log(x[i + 1] / x[i]))
             for i in range(len(x) - 1) if err[i] > 0 and err[i + 1] > 0]
    order = None
    if use.sum() >= 2:
        order = _f(-np.polyfit(np.log(x[use]), np.log(err[use]), 1)[0])
    return {"order": order, "points_used": int(use.sum()),
            "x": x.tolist(), "error": [_f(e) for e in err], "local_orders": local}


def fit_error_model(steps, elements, err, floor, p0: float) -> dict:
    """Fit the error model ``err = a / steps^p + b / elements^q``.

    Least squares in logs of ``err = a / steps^p + b / elements^q`` on the
    points with err above 3x the reference's uncertainty ``floor``.
    """
    from scipy.optimize import least_squares

    S, E, y = (np.asarray(a, float) for a in (steps, elements, err))
    use = np.isfinite(y) & (y > 3.0 * floor)
    S, E, y = S[use], E[use], y[use]
    if len(y) < 5:
        return {"fitted": False, "points_used": int(len(y))}

    def model(x, S, E):
        return np.exp(x[0]) * S ** -x[1] + np.exp(x[2]) * E ** -x[3]

    def resid(x):
        return np.log(model(x, S, E)) - np.log(y)

    log_s, log_e = np.log(S), np.log(E)

    def jac(x):  # d resid / d (log a, p, log b, q): the 18 fits need no finite differences
        ts, te = np.exp(x[0]) * S ** -x[1], np.exp(x[2]) * E ** -x[3]
        m = ts + te
        return np.column_stack([ts / m, -log_s * ts / m, te / m, -log_e * te / m])

    best = None
    for p in (p0, 1.0, 2.0):
        for q in (1.0, 2.0, 3.0):
            la = np.log(np.median(y * S ** p))
            lb = np.log(np.median(y * E ** q)) - 2.0
            for x0 in ([la, p, lb, q], [la - 2.0, p, lb + 2.0, q]):
                r = least_squares(resid, x0, jac=jac,
                                  bounds=([-60, 0.2, -60, 0.2], [60, 5, 60, 5]))
                if best is None or r.cost < best.cost:
                    best = r
    assert best is not None  # the loops above ran
    res = resid(best.x) / math.log(10.0)
    ts, te = np.exp(best.x[0]) * S ** -best.x[1], np.exp(best.x[2]) * E ** -best.x[3]
    share_s, share_e = float(np.max(ts / (ts + te))), float(np.max(te / (ts + te)))
    return {"fitted": True,
            "steps_term_share_max": share_s, "elements_term_share_max": share_e,
            "steps_term_resolved": share_s > 0.2, "elements_term_resolved": share_e > 0.2,
            "exponent_at_bound": bool(min(best.x[1], best.x[3]) < 0.21 or
                                      max(best.x[1], best.x[3]) > 4.95),
            "a": _f(math.exp(best.x[0])), "p": _f(best.x[1]),
            "b": _f(math.exp(best.x[2])), "q": _f(best.x[3]),
            "points_used": int(len(y)), "rms_log10_residual": _f(np.sqrt(np.mean(res**2))),
            "max_log10_residual": _f(np.max(np.abs(res))),
            "formula": "err = a / steps**p + b / elements**q"}


def fit_envelope(steps, elements, err, floor, p: float, q: float) -> dict:
    """``err <= a / steps^p + b / elements^q`` at fixed exponents.

    Least squares in logs for ``a``, ``b``, then both scaled up until the model bounds
    every point above 3x ``floor`` (the form ``Numerics.for_tolerance`` uses).
    """
    from scipy.optimize import least_squares

    S, E, y = (np.asarray(a, float) for a in (steps, elements, err))
    use = np.isfinite(y) & (y > 3.0 * floor)
    S, E, y = S[use], E[use], y[use]
    if len(y) < 3:
        return {"fitted": False, "points_used": int(len(y))}

    def model(x):
        return np.exp(x[0]) * S**-p + np.exp(x[1]) * E**-q

    r = least_squares(lambda x: np.log(model(x)) - np.log(y),
                      [np.log(np.median(y * S**p)), np.log(np.median(y * E**q))])
    scale = float(np.max(y / model(r.x)))
    a, b = math.exp(r.x[0]), math.exp(r.x[1])
    out: dict[str, Any] = {
        "fitted": True, "p": p, "q": q, "a_fit": a, "b_fit": b, "scale": scale,
        "a": a * scale, "b": b * scale, "points_used": int(len(y)),
        "formula": "err <= a / steps**p + b / elements**q on every grid point"}
    out["for_tolerance_rule"] = {
        f"{tol:g}": {"steps": math.ceil((2 * a * scale / tol) ** (1 / p)),
                     "elements": math.ceil((2 * b * scale / tol) ** (1 / q))}
        for tol in TOLERANCES}
    return out


def fit_time_model(steps, elements, seconds) -> dict:
    """``t = c0 + cs steps + c1 steps elements`` (non-negative, relative least squares)."""
    from scipy.optimize import nnls

    S, E, t = (np.asarray(a, float) for a in (steps, elements, seconds))
    A = np.column_stack([np.ones_like(t), S, S * E]) / t[:, None]
    c, _ = nnls(A, np.ones_like(t))
    rel = (c[0] + c[1] * S + c[2] * S * E) / t - 1.0
    return {"c0": _f(c[0]), "cs": _f(c[1]), "c1": _f(c[2]),
            "rms_relative_residual": _f(np.sqrt(np.mean(rel**2))),
            "max_relative_residual": _f(np.max(np.abs(rel))),
            "formula": "seconds_per_impact = c0 + cs * steps + c1 * steps * elements"}


def _model_time(m: dict, S, E):
    return m["c0"] + m["cs"] * S + m["c1"] * S * E


def _model_err(m: dict, S, E):
    return m["a"] * S ** -m["p"] + m["b"] * E ** -m["q"]


def model_pick(mz: dict, mx: dict, tmodel: dict, tol: float, grid_max: tuple[int, int],
               floor: float) -> dict:
    """Cheapest (steps, elements) by the fitted models with both errors <= tol."""
    if not (mz.get("fitted") and mx.get("fitted")):
        return {"pick": None, "why": "no model"}
    S = np.unique(np.round(np.geomspace(16, 4e6, 700)))[:, None]
    E = np.unique(np.round(np.geomspace(8, 1e6, 700)))[None, :]
    ok = np.maximum(_model_err(mz, S, E), _model_err(mx, S, E)) <= tol
    if not ok.any():
        return {"pick": None, "why": "beyond 4e6 steps / 1e6 elements"}
    cost = np.where(ok, _model_time(tmodel, S, E), np.inf)
    i, j = np.unravel_index(np.argmin(cost), cost.shape)
    s, e = int(S[i, 0]), int(E[0, j])
    return {"steps": s, "elements": e,
            "predicted_e_z_error": _f(_model_err(mz, s, e)),
            "predicted_e_x_error": _f(_model_err(mx, s, e)),
            "predicted_seconds_per_impact": _f(_model_time(tmodel, s, e)),
            "extrapolated": bool(s > grid_max[0] or e > grid_max[1]),
            "below_reference_uncertainty": bool(tol < floor)}

