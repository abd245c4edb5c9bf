"""A table's grid refined until its lookups meet a tolerance between the nodes.

:func:`refine_grid` starts from a spec's axes, simulates the grid's nodes
directly (columnar, the table's numerics), measures the lookup error at the
mid-point of every cell edge along each axis (at the nodes of the other axes:
the error of that axis's interpolation alone), and inserts the mid-point of
every cell (along that axis) whose check fails, anywhere on the grid: the grid
stays a tensor product, so a node inserted on one axis is a new plane of
nodes. It repeats until every mid-point passes (or a round or node limit is
reached), then checks the result at cell centres and random interior points
it never refined on and reports all of it.

A sweep spec with ``[grid] tolerance = 1e-5`` calls it before making its chunks
(see :func:`refine_grid`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pandas as pd

from vimpact.lookup.interpolate import LOG_AXES
from vimpact.model.scene import DEFAULT_THETA_RATIO
from vimpact.model.validation import InputError

__all__ = ["grid_table", "refine_grid"]

#: Node budget of a refinement: grid points (rows of the table) at most ...
MAX_NODES = 200_000
#: ... and nodes per axis at most.
MAX_AXIS_NODES = 200


def grid_table(model: str, axes: dict[str, np.ndarray], numerics,
               theta_ratio: float = DEFAULT_THETA_RATIO,
               tangential: str = "auto", tangential_memory: str = "incremental",
               rotation: bool = True, simulate=None):
    """Simulate every node of the grid ``axes`` and return it as a restitution table.

    Parameters
    ----------
    model : ``"kelvin_voigt"`` (axes ``Q1``, ``nu``) or ``"standard_solid"``
        (``Q1``, ``Q2``, ``nu``)
    axes : axis name -> node values (dimensionless)
    numerics : :class:`vimpact.Numerics` of every impact
    theta_ratio, tangential, tangential_memory, rotation : as for :class:`vimpact.Scene`
    simulate : the direct simulation (default
        :func:`vimpact.tablebuild.verify.simulate_dimensionless`)

    Returns
    -------
    :class:`vimpact.lookup.table.RestitutionTable` with metadata ``model``,
    ``mode = grid``, ``numerics`` and the scene options.
    """
    from vimpact.lookup.table import RestitutionTable
    from vimpact.tablebuild.verify import simulate_dimensionless

    names = list(axes)
    mesh = np.meshgrid(*(np.asarray(axes[a], float) for a in names), indexing="ij")
    cols = {a: m.ravel() for a, m in zip(names, mesh)}
    sim = (simulate or simulate_dimensionless)(
        model, cols["Q1"], cols["nu"], cols.get("Q2"), numerics=numerics,
        theta_ratio=theta_ratio, tangential=tangential, tangential_memory=tangential_memory,
        rotation=rotation)
    data = pd.DataFrame({**cols, **{k: sim[k].to_numpy(float) for k in ("e_z", "e_x", "beta_x")},
                         "status": sim["status"].to_numpy(dtype=object)})
    meta = {"model": model, "mode": "grid", "numerics": dataclasses.asdict(numerics),
            "tangential": tangential, "tangential_memory": tangential_memory,
            "rotation": rotation}
    return RestitutionTable(data, meta)


class _SimulationMemory:
    """Direct simulation that remembers the points it simulated.

    :func:`vimpact.tablebuild.verify.simulate_dimensionless`, except that a point
    (the same ``Q1``, ``Q2``, ``nu`` to the bit) simulated before in this refinement is
    not simulated again. Rows are simulated independently of each other, so the
    result is the same as without the memory. One instance per refinement (its
    numerics and scene options do not change).
    """

    _COLUMNS = ("e_z", "beta_x", "e_x")

    def __init__(self):
        self.known: dict[tuple, tuple] = {}

    def __call__(self, model, Q1, nu, Q2=None, **options) -> pd.DataFrame:
        from vimpact.tablebuild.verify import simulate_dimensionless

        nu = np.asarray(nu, dtype=float)
        n = nu.size
        q1 = np.broadcast_to(np.asarray(Q1, dtype=float), (n,))
        q2 = np.full(n, -1.0) if Q2 is None else np.broadcast_to(np.asarray(Q2, dtype=float),
                                                                 (n,))
        keys = list(zip(q1.tolist(), q2.tolist(), nu.tolist()))
        new = np.array([i for i, k in enumerate(keys) if k not in self.known], dtype=int)
        if new.size:
            sim = simulate_dimensionless(model, q1[new], nu[new],
                                         None if Q2 is None else q2[new], **options)
            values = np.column_stack([sim[c].to_numpy(float) for c in self._COLUMNS])
            for i, row, status in zip(new, values, sim["status"].to_numpy(dtype=object)):
                self.known[keys[i]] = (*row, status)
        rows = [self.known[k] for k in keys]
        out = pd.DataFrame({c: np.array([r[j] for r in rows], dtype=float)
                            for j, c in enumerate(self._COLUMNS)})
        out["status"] = np.array([r[-1] for r in rows], dtype=object)
        return out


def _mid(a: np.ndarray, log: bool) -> np.ndarray:
    return np.sqrt(a[:-1] * a[1:]) if log else 0.5 * (a[:-1] + a[1:])


def refine_grid(model: str, axes: dict, tolerance: float, numerics=None, *,
                theta_ratio: float = DEFAULT_THETA_RATIO, tangential: str = "auto",
                tangential_memory: str = "incremental", rotation: bool = True,
                outputs=("e_z", "beta_x"), method: str = "cubic", max_rounds: int = 6,
                max_nodes: int = MAX_NODES, max_axis_nodes: int = MAX_AXIS_NODES,
                n_random: int = 500, seed: int = 0, progress=None):
    """Insert mid-points along the axes until the lookup meets ``tolerance`` between nodes.

    Parameters
    ----------
    model : ``"kelvin_voigt"`` or ``"standard_solid"``
    axes : axis name -> initial node values (``Q1``, ``nu``, and ``Q2`` for a standard
        solid; increasing, > 0 on the log axes ``Q1``, ``Q2``)
    tolerance : the largest absolute error of ``outputs`` allowed at the held-out
        points, dimensionless (> 0)
    numerics : :class:`vimpact.Numerics` of the sweep (default ``Numerics()``); its own
        error adds to the interpolation's, so it must be well below ``tolerance``
    theta_ratio, tangential, tangential_memory, rotation : the sweep's scene options
    outputs : outputs held to the tolerance (``e_x = |beta_x|`` follows ``beta_x``)
    method : the lookup method the table will be used with
    max_rounds : rounds of refinement at most
    max_nodes : grid points at most (a round that would exceed it is not done)
    max_axis_nodes : nodes per axis at most (likewise)
    n_random : random interior points of the final check
    seed : seed of those points
    progress : ``None`` or a callable given one line of text per round (a sweep
        prints it on stderr)

    Returns
    -------
    (axes, report)
        ``axes``: axis name -> refined node values (float arrays, a superset of the
        given ones); ``report`` (JSON-serializable): ``met`` (every held-out point of
        the last round and of the final check within tolerance), ``tolerance``,
        ``rounds`` (per round: nodes per axis, the tolerance each axis was held to
        (``tolerance / 2``, halved when the final check failed), the
        largest mid-point error per axis, the mid-points inserted per axis, each with
        the cell it splits and the error found there, and the final check's result
        when no axis needed a node), ``final`` (:func:`vimpact.tablebuild.verify.interpolation_error`
        of the refined grid: cell centres and random points included),
        ``stopped`` (why the loop ended), ``nodes`` (grid points).

    A sweep with ``[grid] tolerance`` calls it before its chunks are made
    (:func:`vimpact.tablebuild.sweep.refined_spec`, with the spec's numerics and scene
    options and this module's node budget :data:`MAX_NODES`, :data:`MAX_AXIS_NODES`),
    sweeps the refined axes, stores ``report`` as the metadata entry
    ``grid_refinement`` and measures the finished table's ``interpolation_error``.
    """
    from vimpact.model.numerics import Numerics
    from vimpact.tablebuild.verify import held_out_errors, interpolation_error

    numerics = numerics or Numerics()
    if not (isinstance(tolerance, (int, float)) and math.isfinite(tolerance) and tolerance > 0):
        raise InputError(f"tolerance = {tolerance!r} is not allowed: must be a number > 0 "
                         "(absolute error of e_z, beta_x)")
    need = ["Q1", "Q2", "nu"] if model == "standard_solid" else ["Q1", "nu"]
    if model not in ("kelvin_voigt", "standard_solid"):
        raise InputError(f"model = {model!r} is not allowed: kelvin_voigt or standard_solid")
    if sorted(axes) != sorted(need):
        raise InputError(f"axes = {sorted(axes)} is not allowed: a {model} grid has the axes "
                         + ", ".join(need))
    nodes = {}
    for a in need:
        v = np.unique(np.asarray(axes[a], dtype=float))
        if a in LOG_AXES and np.any(v <= 0):
            raise InputError(f"{a} = {v[v <= 0][0]!r} is not allowed: the {a} axis is "
                             f"logarithmic, give {a} > 0")
        nodes[a] = v
    memory = _SimulationMemory()  # points of earlier rounds are not simulated again
    opts: dict[str, Any] = dict(theta_ratio=theta_ratio, tangential=tangential,
                tangential_memory=tangential_memory, rotation=rotation, simulate=memory)
    rounds, stopped = [], "max_rounds"
    table = final = None
    # errors along the axes add up at points between nodes in every axis, but rarely
    # each at its worst: each axis is held to half the tolerance, halved again if the
    # final check (cell centres, random points) still fails. Measured on a standard
    # solid grid (Q2 >= 1) refined with each of 3 axes held to 3.3e-6: axis errors up to
    # 2.8e-6, cell centres and random points up to 3.0e-6, not the sum
    axis_tol = tolerance / 2.0
    while True:
        table = grid_table(model, nodes, numerics, **opts)
        err = held_out_errors(table, numerics, n=0, method=method, kinds=("axis",),
                              simulate=memory)
        worst = np.nanmax(np.column_stack([err[f"{k}_err"].to_numpy() for k in outputs]), axis=1)
        failed = ~np.isfinite(worst)
        worst = np.where(failed, np.inf, worst)  # a failed check is not a pass
        entry: dict[str, Any] = {"nodes": {a: int(len(nodes[a])) for a in need},
                                 "axis_tolerance": axis_tol,
                 "max_error": {}, "inserted": {}}
        new = {}
        for a in need:
            sel = (err["axis"] == a).to_numpy()
            if not sel.any():
                continue
            e = worst[sel]
            entry["max_error"][a] = float(np.max(e)) if np.isfinite(np.max(e)) else None
            bad = e > axis_tol
            if not bad.any():
                continue
            mids = err.loc[sel, a].to_numpy()[bad]
            # each failing mid-point splits the cell it sits in
            cell_mids = _mid(nodes[a], a in LOG_AXES)
            cell = np.unique(np.argmin(np.abs(cell_mids[None, :] - mids[:, None]), axis=1))
            new[a] = cell_mids[cell]
            entry["inserted"][a] = [
                {"between": [float(nodes[a][i]), float(nodes[a][i + 1])],
                 "max_error": float(np.max(e[bad][np.argmin(
                     np.abs(cell_mids[None, :] - mids[:, None]), axis=1) == i]))}
                for i in cell]
        rounds.append(entry)
        if progress is not None:
            progress(f"refinement round {len(rounds)}: nodes "
                     + " x ".join(f"{a} {len(nodes[a])}" for a in need)
                     + ", largest mid-point error "
                     + ", ".join(f"{a} {v:.2g}" if v is not None else f"{a} failed"
                                 for a, v in entry["max_error"].items())
                     + f" (each axis held to {axis_tol:.2g})"
                     + (", inserting " + ", ".join(f"{len(v)} {a}" for a, v in new.items())
                        if new else ", checking cell centres and random points"))
        if not new:
            final = interpolation_error(table, numerics, n=n_random, seed=seed, method=method,
                                        kinds=("centre", "random"), simulate=memory)
            entry["final_check"] = {k: final["outputs"][k]["max"] for k in outputs}
            if all(final["outputs"][k]["max"] is not None
                   and final["outputs"][k]["max"] <= tolerance for k in outputs):
                stopped = "met"
                break
            if len(rounds) > max_rounds:
                break
            axis_tol /= 2.0
            continue
        if len(rounds) > max_rounds:
            break
        size = math.prod(len(nodes[a]) + len(new.get(a, ())) for a in need)
        if size > max_nodes:
            stopped = f"max_nodes ({size} > {max_nodes})"
            break
        wide = [a for a in need if len(nodes[a]) + len(new.get(a, ())) > max_axis_nodes]
        if wide:
            stopped = (f"max_axis_nodes ({wide[0]}: {len(nodes[wide[0]]) + len(new[wide[0]])}"
                       f" > {max_axis_nodes})")
            break
        for a, v in new.items():
            nodes[a] = np.unique(np.concatenate([nodes[a], v]))
    if final is None or stopped != "met":
        final = interpolation_error(table, numerics, n=n_random, seed=seed, method=method,
                                    kinds=("centre", "random"), simulate=memory)
    final_ok = all(final["outputs"][k]["max"] is not None
                   and final["outputs"][k]["max"] <= tolerance for k in outputs)
    report = {"tolerance": float(tolerance), "outputs": list(outputs), "method": method,
              "met": stopped == "met" and final_ok, "stopped": stopped,
              "final_check_met": final_ok, "rounds": rounds, "final": final,
              "nodes": int(math.prod(len(v) for v in nodes.values()))}
    return {a: nodes[a] for a in need}, report
