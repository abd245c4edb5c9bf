"""Build an adaptive restitution table from a sweep spec (``vimpact table build``).

The spec is a grid spec (:mod:`vimpact.sweep.spec`) with ``[grid] refine =
"adaptive"`` and a ``tolerance``: the ends of its ``Q1`` (and ``Q2``) axes are
the table's range, its ``nu`` values the tensor nodes, ``min_level`` /
``max_level`` the coarsest and finest cells. Every cell is refined until its
cubic lookup is within half the tolerance of direct simulation at its check
points (:func:`vimpact.lookup.adaptive.refine_cells`; the other half is left for
the interpolation along ``nu`` and between check points), on ``e_z`` and
``beta_x``. The finished table is then verified at held-out points it never
used (random points, and random points inside randomly drawn cells:
:func:`vimpact.tablebuild.verify.interpolation_error`), which is stored as
``vimpact.interpolation_error``; the refinement report is ``vimpact.grid_refinement``
and the build's time and size ``vimpact.build``. A standard-solid table that reaches
down to the Kelvin-Voigt limit (:data:`vimpact.lookup.band.KELVIN_VOIGT_Q2`) also
records its measured distance to it (``vimpact.kelvin_voigt_limit``,
:func:`vimpact.tablebuild.band.kelvin_voigt_limit`).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from vimpact.lookup.adaptive import AdaptiveGrid, lattice_coordinates, refine_cells
from vimpact.lookup.table import RestitutionTable
from vimpact.model.validation import InputError
from vimpact.sweep.spec import SweepSpec, load_spec
from vimpact.tablebuild.output import adaptive_table, save_build, written
from vimpact.tablebuild.verify import interpolation_error, simulate_dimensionless

__all__ = ["MAX_POINTS", "build_adaptive", "simulate_nodes"]

#: Adaptive points (each simulated at every ``nu`` node) of one build at most.
MAX_POINTS = 400_000
#: Outputs interpolated and held to the tolerance (``e_x = |beta_x|``).
NAMES = ("e_z", "beta_x")
#: Share of the tolerance a cell's check points are held to.
CELL_SHARE = 0.5


def simulate_nodes(spec: SweepSpec, keys: np.ndarray, bounds, simulate=None) -> tuple:
    """Simulate the adaptive points ``keys`` at every ``nu`` node of ``spec``.

    Returns ``(values, status)``: ``values`` ``(m, n_nu, 3)`` = ``e_z``, ``beta_x``,
    ``e_x`` (NaN where the impact failed), ``status`` ``(m, n_nu)``.
    """
    nu = np.asarray(spec.axes["nu"], dtype=float)
    xy = lattice_coordinates(keys, bounds)
    m, nt = len(xy), len(nu)
    Q1 = np.repeat(xy[:, 0], nt)
    Q2 = np.repeat(xy[:, 1], nt) if spec.model == "standard_solid" else None
    theta = float(np.asarray(spec.axes.get("theta_ratio", [0.4]))[0])
    sim = (simulate or simulate_dimensionless)(
        spec.model, Q1, np.tile(nu, m), Q2, numerics=spec.numerics, theta_ratio=theta,
        tangential=spec.tangential, tangential_memory=spec.tangential_memory,
        rotation=spec.rotation)
    status = sim["status"].to_numpy(dtype=object)
    ok = status == "ok"
    values = np.stack([np.where(ok, sim[c].to_numpy(float), np.nan)
                       for c in ("e_z", "beta_x", "e_x")], axis=-1)
    return values.reshape(m, nt, 3), status.reshape(m, nt)


def build_adaptive(spec_path, out=None, *, n_verify: int = 2000, seed: int = 0,
                   max_points: int = MAX_POINTS, max_seconds: float | None = None,
                   log: Callable[[str], None] | None = None,
                   simulate=None) -> tuple[RestitutionTable, Path]:
    """Refine, verify and write the adaptive table of a spec.

    Parameters
    ----------
    spec_path : the sweep spec (TOML) with ``[grid] refine = "adaptive"``
    out : the Parquet file to write (default: the spec's ``output``)
    n_verify : random held-out points of the verification (and as many inside random
        cells), each one direct simulation at a random ``nu``
    seed : seed of the held-out points
    max_points : adaptive points at most (each simulated at every ``nu`` node)
    max_seconds : time budget of the refinement, s (None: none); the levels after it
        are left unrefined and reported (``met`` false)
    log : called with one line of progress per level
    simulate : the direct simulation (default
        :func:`vimpact.tablebuild.verify.simulate_dimensionless`)

    Returns
    -------
    (table, path) : the written :class:`RestitutionTable` and its path
    """
    spec = spec_path if isinstance(spec_path, SweepSpec) else load_spec(spec_path)
    if spec.mode != "grid" or spec.grid_refine != "adaptive":
        raise InputError(f"spec = {str(spec.path)!r} is not allowed: `table build` needs a "
                         '[grid] spec with refine = "adaptive" and a tolerance')
    if spec.grid_psi_nodes is not None:
        from vimpact.tablebuild.friction import build_friction

        return build_friction(spec, out, n_verify=n_verify, seed=seed,
                              max_seconds=max_seconds, log=log, simulate=simulate)
    start = time.perf_counter()
    axes = ["Q1"] + (["Q2"] if spec.model == "standard_solid" else [])
    bounds = np.array([[spec.axes[a][0], spec.axes[a][-1]] for a in axes], dtype=float)
    nu = np.asarray(spec.axes["nu"], dtype=float)
    statuses: dict[tuple, np.ndarray] = {}
    simulated = [0]

    def evaluate(keys: np.ndarray) -> np.ndarray:
        values, status = simulate_nodes(spec, keys, bounds, simulate)
        simulated[0] += status.size
        for key, st in zip(map(tuple, keys.tolist()), status):
            statuses[key] = st
        return values[..., :2]

    if spec.grid_tolerance is None:  # a SweepSpec made by hand (load_spec requires one)
        raise InputError(f"spec = {str(spec.path)!r} is not allowed: `table build` needs a "
                         "[grid] tolerance")
    tol = float(spec.grid_tolerance)
    leaves, keys, values, report = refine_cells(
        evaluate, len(axes), len(nu), CELL_SHARE * tol, check=(0, 1),
        min_level=spec.grid_levels[0], max_level=spec.grid_levels[1], max_nodes=max_points,
        max_seconds=max_seconds, progress=log)
    report["table_tolerance"] = tol
    grid = AdaptiveGrid(axes, bounds, leaves, keys, "nu", nu,
                        {"e_z": values[..., 0], "beta_x": values[..., 1]})
    cols = grid.rows()
    status = np.concatenate([statuses[k] for k in map(tuple, keys.tolist())])
    data = pd.DataFrame({a: cols[a] for a in axes})
    if spec.model == "standard_solid":
        data = data[["Q1", "Q2"]]
    data["nu"] = cols["nu"]
    data["theta_ratio"] = float(np.asarray(spec.axes.get("theta_ratio", [0.4]))[0])
    for c in NAMES:
        data[c] = np.where(status == "ok", cols[c], np.nan)
    data["e_x"] = np.abs(data["beta_x"].to_numpy())
    for a in axes:
        data[f"lattice_{a}"] = cols[f"lattice_{a}"]
    data["status"] = status.astype(str)
    seconds_refine = time.perf_counter() - start
    table = adaptive_table(data, spec, grid.to_metadata(), report)
    if log is not None:
        log(f"refined: {len(leaves)} cells, {len(keys)} nodes x {len(nu)} nu = {len(data)} "
            f"rows in {seconds_refine:.0f} s; verifying at {2 * n_verify} held-out points")
    result = interpolation_error(table, spec.numerics, n=n_verify, seed=seed,
                                 simulate=simulate)
    table.metadata["vimpact.interpolation_error"] = json.dumps(result)
    seconds = time.perf_counter() - start
    build = {"seconds": round(seconds, 1), "refine_seconds": round(seconds_refine, 1),
             "simulated": int(simulated[0] + result["points"]), "tolerance": tol,
             "met": bool(report["met"]), "cells": int(len(leaves))}
    if spec.model == "standard_solid":  # continued by the Kelvin-Voigt table below it?
        from vimpact.lookup.band import reaches_kelvin_voigt
        from vimpact.tablebuild.band import kelvin_voigt_limit

        if reaches_kelvin_voigt(table):
            limit = kelvin_voigt_limit(table, seed=seed, simulate=simulate)
            table.metadata["vimpact.kelvin_voigt_limit"] = json.dumps(limit)
            build["seconds"] = round(time.perf_counter() - start, 1)
    path = save_build(table, build, spec, out)
    if log is not None:
        log(written(path, seconds, result))
    return RestitutionTable.open(path), path
