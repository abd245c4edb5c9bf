"""Adaptive-table lookup: 1e6 cubic lookups against the tensor-grid lookup in one run.

``vimpact bench adaptive_lookup [--quick] [--out DIR]``; from a source checkout
``python -m benchmarks.adaptive_lookup [--quick]`` writes
``benchmarks/results/adaptive_lookup[_quick].json`` and ``.png``.

Side by side in one process on one numba thread, alternated, 1e6 random in-range
points each (uniform in ``log Q1``, ``log Q2`` and ``nu``): the cubic lookup of the
shipped adaptive standard-solid table (``sweeps/tables/standard_solid_table.parquet``,
:func:`vimpact.kernels.adaptive_lookup.adaptive_eval`) and the cubic lookup of a
tensor-grid table (the shipped Kelvin-Voigt figure tables' standard-solid grid,
``sweeps/tables/fig5_4_5_standard_solid_q2.parquet``, Q1 x Q2 x nu, through
:func:`vimpact.kernels.hermite.hermite_eval`), both through
:meth:`vimpact.lookup.table.RestitutionTable.lookup`. Median CPU and wall time over
the repeats; the ratio adaptive / tensor is the figure that survives a shared machine.
Where the shipped tables are not at hand (installed package), an adaptive table of a
smooth analytic function is built in memory instead (same kernel, same tree depth
range), against a tensor table of the same function.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from .machine import load_average, machine_info, save_figure, use_agg

TITLE = "Adaptive lookup: 1e6 cubic lookups, adaptive table vs tensor grid (one core)"
ROOT = Path(__file__).resolve().parents[2]
ADAPTIVE = ROOT / "sweeps" / "tables" / "standard_solid_table.parquet"
TENSOR = ROOT / "sweeps" / "tables" / "fig5_4_5_standard_solid_q2.parquet"
N_LOOKUPS = 1_000_000


def _points(table, n: int, seed: int) -> dict:
    """Random in-range points of ``table`` (log-uniform in Q1, Q2; uniform in nu)."""
    rng = np.random.default_rng(seed)
    ranges = table.info()["ranges"]
    out = {}
    for a in ("Q1", "Q2", "nu"):
        lo, hi = ranges[a]
        out[a] = (np.exp(rng.uniform(np.log(lo), np.log(hi), n)) if a != "nu"
                  else rng.uniform(lo, hi, n))
    return out


def _tables():
    from vimpact.lookup.table import RestitutionTable

    if ADAPTIVE.is_file() and TENSOR.is_file():
        a = RestitutionTable.open(ADAPTIVE, validate=False)
        t = RestitutionTable.open(TENSOR, validate=False)
        if a.is_adaptive:
            return a, t, "shipped"
    return (*_built(), "built")


def _built():
    """Build an adaptive and a tensor table of an analytic function (installed package)."""
    import json

    import pandas as pd

    from vimpact.lookup.adaptive import AdaptiveGrid, lattice_coordinates, refine_cells
    from vimpact.lookup.table import RestitutionTable

    bounds = np.array([[1e-3, 100.0], [1e-3, 100.0]])
    nu = np.linspace(0.0, 0.5, 12)

    def f(lq1, lq2, n):
        lq1, lq2, n = np.broadcast_arrays(lq1, lq2, n)
        return np.stack([0.3 * np.tanh(lq1 + 0.5 * lq2 - 1.0) + 0.5,
                         0.1 * np.sin(lq1) * np.cos(lq2) * (1 + n**2)], axis=-1)

    def ev(keys):
        lx = np.log(lattice_coordinates(keys, bounds))
        return f(lx[:, None, 0], lx[:, None, 1], nu[None, :])

    leaves, keys, v, rep = refine_cells(ev, 2, len(nu), 1e-6, max_level=10)
    g = AdaptiveGrid(["Q1", "Q2"], bounds, leaves, keys, "nu", nu,
                     {"e_z": v[..., 0], "beta_x": v[..., 1]})
    cols = g.rows()
    data = pd.DataFrame({"Q1": cols["Q1"], "Q2": cols["Q2"], "nu": cols["nu"], "e_z": cols["e_z"],
                         "beta_x": cols["beta_x"], "e_x": np.abs(cols["beta_x"]),
                         "lattice_Q1": cols["lattice_Q1"], "lattice_Q2": cols["lattice_Q2"],
                         "status": "ok"})
    adaptive = RestitutionTable(data, {"model": "standard_solid", "mode": "adaptive",
                                       "adaptive": json.dumps(g.to_metadata())})
    q = np.logspace(-3, 2, 41)
    m = np.meshgrid(q, q, nu, indexing="ij")
    vals = f(np.log(m[0]), np.log(m[1]), m[2])
    tensor = RestitutionTable(pd.DataFrame({
        "Q1": m[0].ravel(), "Q2": m[1].ravel(), "nu": m[2].ravel(), "e_z": vals[..., 0].ravel(),
        "beta_x": vals[..., 1].ravel(), "e_x": np.abs(vals[..., 1]).ravel(), "status": "ok"}),
        {"model": "standard_solid", "mode": "grid"})
    return adaptive, tensor


def run(quick: bool) -> dict:
    """Time 1e6 cubic lookups (1e5 when ``quick``) on both tables, one core, in one run."""
    import numba

    numba.set_num_threads(1)  # one core
    adaptive, tensor, source = _tables()
    n = 100_000 if quick else N_LOOKUPS
    repeats = 2 if quick else 5
    data = {"benchmark": "adaptive_lookup", "machine": machine_info(),
            "load_before": load_average(), "source": source, "points": n,
            "adaptive": adaptive.info().get("adaptive"),
            "tensor_grid": tensor.info().get("grid")}
    pts = {"adaptive": _points(adaptive, n, 1), "tensor": _points(tensor, n, 2)}
    tables = {"adaptive": adaptive, "tensor": tensor}
    w0 = time.perf_counter()
    for k, t in tables.items():  # kernels loaded (or compiled), tensor slopes made
        t.lookup(pts[k]["Q1"][:10], pts[k]["nu"][:10], Q2=pts[k]["Q2"][:10])
    data["first_calls_s"] = time.perf_counter() - w0
    times: dict[str, dict[str, Any]] = {k: {"wall_s": [], "cpu_s": []} for k in tables}
    for _ in range(repeats):
        for k, t in tables.items():
            w, c = time.perf_counter(), time.process_time()
            t.lookup(pts[k]["Q1"], pts[k]["nu"], Q2=pts[k]["Q2"])
            times[k]["wall_s"].append(time.perf_counter() - w)
            times[k]["cpu_s"].append(time.process_time() - c)
    for k in tables:
        times[k]["cpu_s_median"] = float(np.median(times[k]["cpu_s"]))
        times[k]["wall_s_median"] = float(np.median(times[k]["wall_s"]))
    data["timing"] = times
    data["adaptive_over_tensor_cpu"] = (times["adaptive"]["cpu_s_median"]
                                        / times["tensor"]["cpu_s_median"])
    data["load_after"] = load_average()
    data["figures"] = figures(data)
    return data


def figures(data: dict) -> dict:
    """CPU s per 1e6 cubic lookups (adaptive, tensor) and their ratio."""
    from vimpact.bench.machine import figure

    scale = N_LOOKUPS / data["points"]
    out = {}
    for k in ("adaptive", "tensor"):
        t = data["timing"][k]
        out[f"{k}.lookup_1e6_cpu"] = figure(t["cpu_s_median"] * scale, "s", "lower", "time",
                                            samples=[x * scale for x in t["cpu_s"]])
    out["adaptive_over_tensor_cpu"] = figure(data["adaptive_over_tensor_cpu"], "-", "lower",
                                             "time")
    return out


def report(data: dict) -> str:
    """One line: both times and the ratio."""
    t = data["timing"]
    scale = N_LOOKUPS / data["points"]
    return (f"{data['points']:.0e} cubic lookups ({data['source']} tables), CPU s per 1e6: "
            f"adaptive {t['adaptive']['cpu_s_median'] * scale:.3f}, tensor grid "
            f"{t['tensor']['cpu_s_median'] * scale:.3f}; adaptive / tensor "
            f"{data['adaptive_over_tensor_cpu']:.2f}")


def plot(data: dict, path: Path) -> None:
    """Draw the lookup times of :func:`run` (seconds per 1e6 lookups) to ``path``."""
    use_agg()
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.5))
    scale = N_LOOKUPS / data["points"]
    names = ["adaptive", "tensor"]
    ax.bar(names, [data["timing"][k]["cpu_s_median"] * scale for k in names])
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="target 1 s")
    ax.set_ylabel("CPU s per 1e6 cubic lookups (one core)")
    ax.set_title(f"adaptive / tensor = {data['adaptive_over_tensor_cpu']:.2f}", fontsize=9)
    ax.legend(fontsize=7)
    save_figure(fig, path)
