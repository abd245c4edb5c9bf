"""Measured interpolation error of a restitution table against direct simulation.

A lookup between the nodes is only as good as its interpolant there. This
module simulates *held-out* points (never table nodes) directly, with the
table's own numerics, and compares them with :meth:`RestitutionTable.lookup`:

- ``axis`` points: the mid-point of every cell edge along one axis, at the
  nodes of the other axes (the error of the interpolation along that axis
  alone; :func:`vimpact.tablebuild.refine.refine_grid` uses them to decide where
  to insert nodes);
- ``centre`` points: the centre of every cell (mid-way along every axis);
- ``random`` points: uniform in ``log Q1``, ``log Q2`` and ``nu`` inside the
  covered range (seeded).

The summary (:func:`interpolation_error`) holds the max and RMS error per
output (``e_z``, ``beta_x``, ``e_x``) and is what ``vimpact table verify
--write`` stores as the metadata entry ``vimpact.interpolation_error``. The
error includes the table's own error at its nodes (the lookup is compared with
a fresh simulation, not with the table); ``node_error`` reports that part
separately on a sample of nodes re-simulated.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pandas as pd

from vimpact.lookup.interpolate import LOG_AXES
from vimpact.model.scene import DEFAULT_THETA_RATIO, REFERENCE_INDENTATION
from vimpact.model.validation import InputError

__all__ = ["KINDS", "adaptive_held_out_points", "held_out_errors", "held_out_points", "interpolation_error",
           "numerics_of", "simulate_dimensionless", "write_interpolation_error"]

#: ``bound = BOUND_FACTOR * max``: the held-out mid-points sit at the peak of the
#: cubic Hermite error's leading term (``t^2 (1 - t)^2`` in each cell); the next terms
#: move the peak by O(h). On the Kelvin-Voigt tables, fresh random points exceeded
#: the measured max by at most 1e-4 (relative): 1.5 leaves room for that.
BOUND_FACTOR = 1.5
#: Random held-out points of :func:`interpolation_error` at most (each is one direct
#: simulation; ``vimpact table verify --n``).
MAX_POINTS = 100_000
#: Held-out points of a friction table have ``psi`` uniform in ``[0, FRICTION_PSI_SPAN
#: psi_s]`` (``psi_s``: where gross slip throughout begins, the table's own).
FRICTION_PSI_SPAN = 1.25
#: Kinds of held-out points (see the module text).
KINDS = ("axis", "centre", "random")
_OUTPUTS = ("e_z", "beta_x", "e_x")


def numerics_of(table):
    """Return the table's numerics (metadata ``vimpact.numerics``) as a :class:`vimpact.Numerics`.

    Raises
    ------
    InputError
        if the table does not record its numerics (give ``numerics`` explicitly).
    """
    from vimpact.model.numerics import Numerics

    recorded = table.numerics
    if not isinstance(recorded, dict):
        raise InputError("numerics = None is not allowed for this table: it does not record "
                         "its numerics (metadata vimpact.numerics); give the numerics the table "
                         "was made with")
    fields = {f.name for f in dataclasses.fields(Numerics)}
    return Numerics(**{k: v for k, v in recorded.items() if k in fields})


def simulate_dimensionless(model: str, Q1, nu, Q2=None, *, numerics=None,
                           theta_ratio: float = DEFAULT_THETA_RATIO, tangential: str = "auto",
                           tangential_memory: str = "incremental",
                           rotation: bool = True, psi=None, mu: float = 1.0) -> pd.DataFrame:
    """Simulate impacts given by their dimensionless parameters, columnar.

    The scenes are those of :meth:`vimpact.Scene.from_dimensionless` (and of a grid
    sweep): ``R = 1 m``, ``m = 1 kg``, ``v_z0 = v_x0 = 1 m/s``, ``omega0 = 0``,
    Hertz indentation ``1e-4 m``; ``G_inf`` from ``nu``, ``eta / G_inf`` from ``Q1``,
    ``G2 = G1 / Q2`` for a standard solid.

    Parameters
    ----------
    model : ``"kelvin_voigt"`` or ``"standard_solid"``
    Q1, nu, Q2 : arrays of one length (``Q2`` for a standard solid), dimensionless
    numerics : :class:`vimpact.Numerics` (default: ``Numerics()``)
    theta_ratio : Theta / (m R^2)
    tangential, tangential_memory, rotation : as for :class:`vimpact.Scene`
    psi : friction incidence per point (dimensionless, >= 0; None: full stick); the
        scene is a psi grid sweep's (:func:`vimpact.tableformat.parameters.psi_reference`:
        friction coefficient ``mu``, ``v_x0`` from psi; psi = 0 is full stick)
    mu : friction coefficient of the points with ``psi > 0``, dimensionless

    Returns
    -------
    DataFrame: :func:`vimpact.simulate_batch`'s result (``e_z``, ``beta_x``, ``e_x``,
    ``status``, ...), one row per point.
    """
    from vimpact.engine.simulate import simulate_batch
    from vimpact.model.hertz import Q1_PER_TAU
    from vimpact.model.numerics import Numerics

    nu = np.asarray(nu, dtype=float)
    n = nu.size
    Q1 = np.broadcast_to(np.asarray(Q1, dtype=float), (n,))
    E_star = 15.0 / (16.0 * REFERENCE_INDENTATION**2.5)  # m = R = v_z0 = 1
    G = E_star * (1.0 - nu) / 2.0
    eta = Q1 / Q1_PER_TAU * REFERENCE_INDENTATION * G
    cols = {"nu": nu, "G_inf_Pa": G, "R_m": np.ones(n), "m_kg": np.ones(n),
            "v_z0_m_s": np.ones(n), "v_x0_m_s": np.ones(n), "omega0_rad_s": np.zeros(n),
            "theta_ratio": np.full(n, float(theta_ratio)),
            "tangential": np.full(n, tangential), "tangential_memory": np.full(n, tangential_memory),
            "rotation": np.full(n, bool(rotation))}
    if psi is not None:
        from vimpact.tableformat.parameters import psi_reference
        cols["v_x0_m_s"], cols["mu"] = psi_reference(np.broadcast_to(psi, (n,)), nu, mu)
    if model == "kelvin_voigt":
        cols["eta0_Pa_s"] = eta
    elif model == "standard_solid":
        Q2 = np.broadcast_to(np.asarray(Q2, dtype=float), (n,))
        G2 = G / Q2
        cols.update(G_arm1_Pa=G2, tau_arm1_s=eta / G2)
    else:
        raise InputError(f"model = {model!r} is not allowed: kelvin_voigt or standard_solid")
    return simulate_batch(cols, numerics or Numerics())


def held_out_points(axes: list[str], nodes: list[np.ndarray], n_random: int = 200,
                    seed: int = 0, kinds=KINDS) -> pd.DataFrame:
    """Points between the nodes (see the module text).

    Parameters
    ----------
    axes : axis names (those in :data:`~vimpact.lookup.interpolate.LOG_AXES` are log axes)
    nodes : increasing node values per axis
    n_random : number of random interior points
    seed : seed of the random points
    kinds : which kinds to make

    Returns
    -------
    DataFrame with one column per axis, ``kind`` and ``axis`` (the axis an
    ``axis`` point is mid-way along; empty otherwise).
    """
    log = [a in LOG_AXES for a in axes]
    mids = [np.sqrt(n[:-1] * n[1:]) if lg else 0.5 * (n[:-1] + n[1:])
            for n, lg in zip(nodes, log)]
    frames = []
    if "axis" in kinds:
        for k, a in enumerate(axes):
            if len(nodes[k]) < 2:
                continue
            lists = [mids[j] if j == k else nodes[j] for j in range(len(axes))]
            mesh = np.meshgrid(*lists, indexing="ij")
            frames.append(pd.DataFrame({b: m.ravel() for b, m in zip(axes, mesh)})
                          .assign(kind="axis", axis=a))
    if "centre" in kinds and all(len(n) >= 2 for n in nodes):
        mesh = np.meshgrid(*mids, indexing="ij")
        frames.append(pd.DataFrame({b: m.ravel() for b, m in zip(axes, mesh)})
                      .assign(kind="centre", axis=""))
    if "random" in kinds and n_random > 0:
        rng = np.random.default_rng(seed)
        cols = {}
        for a, n, lg in zip(axes, nodes, log):
            lo, hi = (np.log(n[0]), np.log(n[-1])) if lg else (n[0], n[-1])
            u = rng.uniform(lo, hi, n_random)
            cols[a] = np.exp(u) if lg else u
        frames.append(pd.DataFrame(cols).assign(kind="random", axis=""))
    if not frames:
        return pd.DataFrame({**{a: [] for a in axes}, "kind": [], "axis": []})
    return pd.concat(frames, ignore_index=True)


def adaptive_held_out_points(grid, n_random: int = 200, seed: int = 0,
                             kinds=KINDS) -> pd.DataFrame:
    """Held-out points of an adaptive table (:class:`vimpact.lookup.adaptive.AdaptiveGrid`).

    ``random``: ``n_random`` points uniform in the log of the adaptive axes and in the
    tensor axis. ``cell``: as many points again, each in a leaf drawn at random (so
    the small cells where the outputs change fast get their share), at a random
    position inside it; neither kind is a node or a check point of the refinement
    (``kinds`` with ``"centre"`` or ``"random"`` selects them; ``"axis"`` has no
    meaning here). The tensor axis (``nu``) is uniform between its end nodes.
    """
    friction = getattr(grid, "onset", None)  # a friction table: psi up to 1.25 psi_s
    grid = getattr(grid, "grid", grid)
    rng = np.random.default_rng(seed)
    frames = []
    lb = grid.log_bounds
    want_random = "random" in kinds
    want_cell = "centre" in kinds or "random" in kinds
    t_lo, t_hi = grid.tensor_nodes[0], grid.tensor_nodes[-1]
    if want_random and n_random > 0:
        cols = {a: np.exp(rng.uniform(lb[d, 0], lb[d, 1], n_random))
                for d, a in enumerate(grid.axes)}
        if grid.tensor_axis:
            cols[grid.tensor_axis] = rng.uniform(t_lo, t_hi, n_random)
        frames.append(pd.DataFrame(cols).assign(kind="random", axis=""))
    if want_cell and n_random > 0:
        lo, hi = grid.leaf_boxes()
        pick = rng.integers(0, len(lo), n_random)
        cols = {}
        for d, a in enumerate(grid.axes):
            t = rng.uniform(0.0, 1.0, n_random)
            cols[a] = np.exp(np.log(lo[pick, d]) + t * (np.log(hi[pick, d])
                                                        - np.log(lo[pick, d])))
        if grid.tensor_axis:
            cols[grid.tensor_axis] = rng.uniform(t_lo, t_hi, n_random)
        frames.append(pd.DataFrame(cols).assign(kind="cell", axis=""))
    if not frames:
        names = grid.axes + ([grid.tensor_axis] if grid.tensor_axis else [])
        return pd.DataFrame({**{a: [] for a in names}, "kind": [], "axis": []}
                            | ({"psi": []} if friction else {}))
    pts = pd.concat(frames, ignore_index=True)
    if friction is not None:
        psi_s = friction(pts["Q1"].to_numpy(), pts["nu"].to_numpy())["psi_s"]
        pts["psi"] = rng.uniform(0.0, FRICTION_PSI_SPAN, len(pts)) * psi_s
    return pts


def _scene_options(table) -> dict:
    return {"tangential": table.meta("tangential", "auto") or "auto",
            "tangential_memory": table.meta("tangential_memory", "incremental") or "incremental",
            "rotation": bool(table.meta("rotation", True))}


def _friction(table, psi) -> dict:
    """Return the keyword arguments of :func:`simulate_dimensionless` for a psi table.

    They are the points' psi and the one friction coefficient its rows with psi > 0 were made with.
    """
    if psi is None:
        return {}
    mu = table.data["mu"].to_numpy(float) if "mu" in table.data.columns else np.array([1.0])
    finite = np.unique(mu[np.isfinite(mu)])
    if finite.size > 1:
        raise InputError(f"the table{table._where(table.path)} holds psi rows made with several "
                         f"friction coefficients mu = {finite.tolist()}: not a psi grid")
    return {"psi": psi, "mu": float(finite[0]) if finite.size else 1.0}


def held_out_errors(table, numerics=None, n: int = 200, seed: int = 0, theta_ratio=None,
                    method: str = "cubic", kinds=KINDS, simulate=None) -> pd.DataFrame:
    """Lookup minus direct simulation at held-out points, one row per point.

    Parameters
    ----------
    table : :class:`vimpact.lookup.table.RestitutionTable` (a grid table)
    numerics : :class:`vimpact.Numerics` of the direct simulation (default: the table's)
    n : number of random interior points
    seed : seed of the random points
    theta_ratio : the table's theta_ratio slice, if it holds several
    method : lookup method compared (``"cubic"`` or ``"linear"``)
    kinds : kinds of held-out points
    simulate : the direct simulation (default :func:`simulate_dimensionless`; a
        refinement passes one that remembers the points it simulated before)

    Returns
    -------
    DataFrame: the point (one column per axis), ``kind``, ``axis``, ``status`` of the
    simulation, and per output ``<name>_sim``, ``<name>_table`` and
    ``<name>_err = |table - sim|`` (NaN where the simulation or the lookup failed).
    """
    numerics = numerics_of(table) if numerics is None else numerics
    theta = table._resolve_theta(theta_ratio)
    if table.is_adaptive:
        pts = adaptive_held_out_points(table.adaptive_grid(), n, seed, kinds)
    else:
        grid = table._grid(theta)
        pts = held_out_points(grid.axes, grid.nodes, n, seed, kinds)
    if theta is None:
        t = theta_ratio if theta_ratio is not None else (
            float(table._theta_values()[0]) if "theta_ratio" in table.data.columns
            and len(table._theta_values()) else DEFAULT_THETA_RATIO)
    else:
        t = theta
    psi = pts["psi"].to_numpy() if "psi" in pts else None
    sim = (simulate or simulate_dimensionless)(
        table.model, pts["Q1"].to_numpy(), pts["nu"].to_numpy(),
        pts["Q2"].to_numpy() if "Q2" in pts else None,
        numerics=numerics, theta_ratio=t, **_scene_options(table), **_friction(table, psi))
    look = table.lookup(*(pts[a].to_numpy() for a in ("Q1", "nu")),
                        Q2=pts["Q2"].to_numpy() if "Q2" in pts else None,
                        theta_ratio=theta_ratio, method=method, psi=psi)
    ok = (sim["status"] == "ok").to_numpy()
    out = pts.copy()
    out["status"] = sim["status"].to_numpy()
    for name in _OUTPUTS:
        s = np.where(ok, sim[name].to_numpy(float), np.nan)
        out[f"{name}_sim"] = s
        out[f"{name}_table"] = look[name]
        out[f"{name}_err"] = np.abs(look[name] - s)
    return out


def _node_error(table, numerics, theta_ratio, n_nodes: int, seed: int, simulate=None) -> dict:
    """Max |table - fresh simulation| on a sample of the table's own nodes."""
    rows = table.ok
    if "theta_ratio" in rows.columns and theta_ratio is not None:
        rows = rows[np.isclose(rows["theta_ratio"].to_numpy(float), theta_ratio)]
    if not len(rows):
        return {}
    pick = np.random.default_rng(seed).choice(len(rows), min(n_nodes, len(rows)), replace=False)
    rows = rows.iloc[np.sort(pick)]
    t = (float(rows["theta_ratio"].iloc[0]) if "theta_ratio" in rows.columns
         else DEFAULT_THETA_RATIO)
    Q2 = rows["Q2"].to_numpy(float) if table.model == "standard_solid" else None
    psi = rows["psi"].to_numpy(float) if "psi" in rows.columns else None
    sim = (simulate or simulate_dimensionless)(
        table.model, rows["Q1"].to_numpy(float), rows["nu"].to_numpy(float), Q2,
        numerics=numerics, theta_ratio=t, **_scene_options(table), **_friction(table, psi))
    ok = (sim["status"] == "ok").to_numpy()
    return {name: float(np.nanmax(np.abs(sim[name].to_numpy(float)[ok]
                                         - rows[name].to_numpy(float)[ok]), initial=0.0))
            for name in _OUTPUTS}


def interpolation_error(table, numerics=None, n: int = 200, seed: int = 0, theta_ratio=None,
                        method: str = "cubic", kinds=KINDS, node_sample: int = 50,
                        simulate=None) -> dict:
    """Max and RMS error of :meth:`RestitutionTable.lookup` between the nodes.

    Simulates the held-out points (:func:`held_out_errors`) with the table's
    numerics and compares with the lookup.

    Parameters
    ----------
    table : a grid :class:`vimpact.lookup.table.RestitutionTable`
    numerics : :class:`vimpact.Numerics` of the direct simulation (default: the
        table's own, from its metadata)
    n : number of random interior points (besides the mid-points)
    seed : seed of the random points and of the node sample
    theta_ratio : the table's theta_ratio slice, if it holds several
    method : ``"cubic"`` (default) or ``"linear"``
    kinds : kinds of held-out points (default all: axis mid-points, cell centres, random)
    node_sample : table nodes re-simulated to report the table's own error there
    simulate : the direct simulation (default :func:`simulate_dimensionless`)

    Returns
    -------
    dict (JSON-serializable): ``method``, ``points`` (held-out points simulated),
    ``failed`` (points whose simulation or lookup failed, left out), ``kinds``,
    ``seed``, ``numerics``, ``outputs`` (name -> ``max``, ``rms``, ``bound`` =
    :data:`BOUND_FACTOR` x ``max``, dimensionless, and ``at``: the point of the max),
    ``per_axis`` (axis -> name -> max over
    that axis's mid-points), ``node_error`` (name -> max over the node sample),
    ``vimpact_version``.
    """
    from vimpact import __version__

    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 0 <= n <= MAX_POINTS:
        raise InputError(f"n = {n!r} is not allowed: must be an integer from 0 to {MAX_POINTS} "
                         "(random held-out points, each one direct simulation)")
    numerics = numerics_of(table) if numerics is None else numerics
    err = held_out_errors(table, numerics, n, seed, theta_ratio, method, kinds, simulate)
    axes = [a for a in ("Q1", "Q2", "nu") if a in err.columns]
    good = np.all(np.isfinite(err[[f"{k}_err" for k in _OUTPUTS if k != "e_x"]].to_numpy()),
                  axis=1)
    outputs: dict[str, dict] = {}
    for name in _OUTPUTS:
        e = err[f"{name}_err"].to_numpy()
        fin = np.isfinite(e)
        if not fin.any():
            outputs[name] = {"max": None, "rms": None, "bound": None, "at": None}
            continue
        i = int(np.nanargmax(np.where(fin, e, -1.0)))
        outputs[name] = {"max": float(e[i]), "rms": float(math.sqrt(np.mean(e[fin] ** 2))),
                         "bound": BOUND_FACTOR * float(e[i]),
                         "at": {a: float(err[a].iloc[i]) for a in axes}}
    per_axis = {}
    for a in axes:
        sel = (err["axis"] == a).to_numpy()
        if sel.any():
            per_axis[a] = {name: float(np.nanmax(err.loc[sel, f"{name}_err"].to_numpy(),
                                                 initial=0.0)) for name in _OUTPUTS}
    return {
        "method": method,
        "points": int(len(err)),
        "failed": int(np.sum(~good)),
        "kinds": {k: int(np.sum(err["kind"] == k)) for k in sorted(set(err["kind"]))},
        "seed": int(seed),
        "numerics": dataclasses.asdict(numerics),
        "outputs": outputs,
        "per_axis": per_axis,
        "node_error": _node_error(table, numerics, theta_ratio, node_sample, seed, simulate)
        if node_sample else {},
        "vimpact_version": __version__,
    }


def write_interpolation_error(table, result: dict, path=None):
    """Store ``result`` as the metadata entry ``vimpact.interpolation_error`` and write.

    The entry goes into ``table``, which is written to ``path`` (default: where the
    table was read).

    A table read from a Parquet file is rewritten from that file's own data (read with
    ``pyarrow``, not through pandas), atomically, so its rows, columns and types stay
    exactly as the sweep wrote them and its content hash (``vimpact.content_sha256``)
    stays true; for a partitioned dataset only its ``_common_metadata`` is rewritten. A
    table held in memory is saved with :meth:`RestitutionTable.save` (without a content
    hash of other data).
    """
    from pathlib import Path

    import pyarrow.parquet as pq

    from vimpact.tableformat.files import write_atomic
    from vimpact.tableformat.metadata import COMMON_METADATA

    text = json.dumps(result)
    key = "vimpact.interpolation_error"
    table.metadata[key] = text
    target = Path(path) if path is not None else table.path
    if target is None:
        raise InputError("path = None is not allowed for a table held in memory: give the "
                         "file to write")
    if target.is_dir():
        schema = pq.read_schema(target / COMMON_METADATA)
        meta = dict(schema.metadata or {})
        meta[key.encode()] = text.encode()
        write_atomic(schema.empty_table().replace_schema_metadata(meta),
                           target / COMMON_METADATA, schema_only=True)
        return target
    source = table.path
    if source is not None and source.is_file():
        arrow = pq.read_table(source)
        meta = dict(arrow.schema.metadata or {})
        meta[key.encode()] = text.encode()
        target.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(arrow.replace_schema_metadata(meta), target)
        return target
    table.metadata.pop("vimpact.content_sha256", None)  # not a hash of this data
    return table.save(target)
