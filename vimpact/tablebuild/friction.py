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

import json
import time
from collections.abc import Callable

import numpy as np
import pandas as pd

from vimpact.lookup.adaptive import AdaptiveGrid, lattice_coordinates, refine_cells
from vimpact.lookup.friction import (
    PSI_STICK,
    FrictionGrid,
    coordinate_nodes,
    gross_slip_onset,
    psi_of_coordinate,
)
from vimpact.model.validation import InputError
from vimpact.tablebuild.output import adaptive_table, save_build, written
from vimpact.tablebuild.verify import interpolation_error, simulate_dimensionless

__all__ = ["build_friction", "gross_slip_start"]

#: Bisection bracket of ``psi_s`` of a friction table, relative to ``psi_g``: a
#: misplaced kink by ``delta psi_g`` moves ``beta_x`` by about ``(delta)^1.25`` times
#: a number of order 1 (its measured approach to the closed form), 6e-7 here.
ONSET_REL_TOL = 1e-5
#: Share of the tolerance a cell's check points are held to (as for the other
#: adaptive tables; the rest is left for the interpolation along nu and psi).
CELL_SHARE = 0.5
#: Friction coefficient of the simulated rows with psi > 0 (the result depends on psi).
MU = 1.0

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


def _simulate_friction(spec, Q1, nu, unodes, theta, simulate) -> dict:
    """Simulate the incidence nodes of the points ``(Q1, nu)`` (flat arrays).

    Returns arrays ``(n, n_u)``: ``psi``, ``e_z``, ``beta_x``, ``status``, and ``psi_s``
    ``(n,)``; NaN outputs where an impact failed.
    """
    sim = simulate or simulate_dimensionless
    found = gross_slip_start("kelvin_voigt", Q1, nu, theta_ratio=theta, numerics=spec.numerics,
                             rel_tol=ONSET_REL_TOL, mu=MU, simulate=simulate)
    psi_s = found["psi_s"]
    if np.any(psi_s <= PSI_STICK):
        bad = int(np.flatnonzero(psi_s <= PSI_STICK)[0])
        raise InputError(f"Q1 = {Q1[bad]:.6g}, nu = {nu[bad]:.6g} is not allowed in a friction "
                         f"table: gross slip begins at psi_s = {psi_s[bad]:.6g}, not above "
                         f"the first kink psi = {PSI_STICK:g}")
    n, nu_n = len(Q1), len(unodes)
    psi = psi_of_coordinate(unodes[None, :], psi_s[:, None])
    out = sim("kelvin_voigt", np.repeat(Q1, nu_n), np.repeat(nu, nu_n), None,
              numerics=spec.numerics, theta_ratio=theta, tangential=spec.tangential,
              tangential_memory=spec.tangential_memory, rotation=spec.rotation,
              psi=psi.ravel(), mu=MU)
    status = out["status"].to_numpy(dtype=object).reshape(n, nu_n)
    ok = status == "ok"
    cols = {c: np.where(ok, out[c].to_numpy(float).reshape(n, nu_n), np.nan)
            for c in ("e_z", "beta_x")}
    return {"psi": psi, "status": status, "psi_s": psi_s, **cols}


def build_friction(spec, out=None, *, n_verify: int = 2000, seed: int = 0,
                   max_points: int = 100_000, max_seconds: float | None = None,
                   log: Callable[[str], None] | None = None,
                   simulate=None) -> tuple:
    """Refine, verify and write a Kelvin-Voigt friction table (``[grid] psi_nodes``).

    Adaptive cells in ``log Q1`` (tensor axis ``nu``) as for
    :func:`vimpact.tablebuild.adaptive.build_adaptive`; at every adaptive point and
    ``nu`` node: the start of gross slip throughout ``psi_s`` (:func:`gross_slip_start`,
    to :data:`ONSET_REL_TOL` of ``psi_g``), then ``beta_x`` at the incidence nodes of
    :func:`vimpact.lookup.friction.coordinate_nodes` (``psi = 0 .. 1`` and ``1 ..
    psi_s``). A cell is split until ``e_z``, ``psi_s / psi_g`` and ``beta_x`` at every
    incidence node meet half the tolerance at its check points. The table is then
    verified at held-out points (random ``Q1``, ``nu`` and ``psi`` up to ``1.25
    psi_s``, direct simulation) and written with that error. Arguments as for
    ``build_adaptive``; returns ``(table, path)``.
    """
    from vimpact.lookup.table import RestitutionTable

    start = time.perf_counter()
    theta = float(np.asarray(spec.axes.get("theta_ratio", [0.4]))[0])
    bounds = np.array([[spec.axes["Q1"][0], spec.axes["Q1"][-1]]], dtype=float)
    nu = np.asarray(spec.axes["nu"], dtype=float)
    unodes = coordinate_nodes(*spec.grid_psi_nodes)
    nt, nn = len(nu), len(unodes)
    done: dict[tuple, dict] = {}
    simulated = [0]

    def counted(*args, **kwargs):
        result = (simulate or simulate_dimensionless)(*args, **kwargs)
        simulated[0] += len(result)
        return result

    def evaluate(keys: np.ndarray) -> np.ndarray:
        q1 = lattice_coordinates(keys, bounds)[:, 0]
        res = _simulate_friction(spec, np.repeat(q1, nt), np.tile(nu, len(q1)), unodes, theta,
                                 counted)
        values = np.empty((len(q1), nt, 2 + nn))
        e_z = res["e_z"][:, -1]  # at psi_s: the element path's e_z, the closed form's
        ratio = res["psi_s"] / gross_slip_onset(e_z, np.tile(nu, len(q1)), theta, spec.rotation)
        values[..., 0] = e_z.reshape(len(q1), nt)
        values[..., 1] = ratio.reshape(len(q1), nt)
        values[..., 2:] = res["beta_x"].reshape(len(q1), nt, nn)
        for i, key in enumerate(map(tuple, keys.tolist())):
            done[key] = {c: res[c][i * nt:(i + 1) * nt] for c in ("psi", "status", "e_z",
                                                                   "beta_x")}
        return values

    tol = float(spec.grid_tolerance)
    leaves, keys, values, report = refine_cells(
        evaluate, 1, nt, CELL_SHARE * tol, min_level=spec.grid_levels[0],
        max_level=spec.grid_levels[1], max_nodes=max_points, max_seconds=max_seconds,
        progress=log)
    report["table_tolerance"] = tol
    names = ["e_z", "onset_ratio"] + [f"beta_x_{j}" for j in range(nn)]
    grid = AdaptiveGrid(["Q1"], bounds, leaves, keys, "nu", nu,
                        {n: values[..., j] for j, n in enumerate(names)})
    fgrid = FrictionGrid(grid, unodes, theta, spec.rotation)
    q1 = lattice_coordinates(keys, bounds)[:, 0]
    shape = (len(keys), nt, nn)
    rows = {c: np.stack([done[k][c] for k in map(tuple, keys.tolist())])
            for c in ("psi", "status", "e_z", "beta_x")}
    psi = rows["psi"].ravel()
    data = pd.DataFrame({
        "Q1": np.broadcast_to(q1[:, None, None], shape).ravel(),
        "nu": np.broadcast_to(nu[None, :, None], shape).ravel(),
        "theta_ratio": theta,
        "psi": psi,
        "mu": np.where(psi == 0.0, np.inf, MU),
        "e_z": rows["e_z"].ravel(),
        "beta_x": rows["beta_x"].ravel(),
    })
    data["e_x"] = np.abs(data["beta_x"].to_numpy())
    data["lattice_Q1"] = np.broadcast_to(keys[:, 0][:, None, None], shape).ravel()
    data["lattice_psi"] = np.broadcast_to(np.arange(nn)[None, None, :], shape).ravel()
    data["status"] = rows["status"].ravel().astype(str)
    seconds_refine = time.perf_counter() - start
    table = adaptive_table(data, spec, fgrid.to_metadata(), report)
    if log is not None:
        log(f"refined: {len(leaves)} cells, {len(keys)} Q1 nodes x {nt} nu x {nn} psi = "
            f"{len(data)} rows in {seconds_refine:.0f} s; verifying at {2 * n_verify} "
            "held-out points")
    result = interpolation_error(table, spec.numerics, n=n_verify, seed=seed,
                                 simulate=counted)
    table.metadata["vimpact.interpolation_error"] = json.dumps(result)
    seconds = time.perf_counter() - start
    build = {"seconds": round(seconds, 1), "refine_seconds": round(seconds_refine, 1),
             "simulated": int(simulated[0]), "tolerance": tol,
             "met": bool(report["met"]), "cells": int(len(leaves))}
    path = save_build(table, build, spec, out)
    if log is not None:
        log(written(path, seconds, result))
    return RestitutionTable.open(path), path
