"""Lookup accuracy between the nodes (linear vs cubic) and 1e6-point lookup time.

``python -m benchmarks.lookup [--quick] [--out DIR]`` writes
``benchmarks/results/lookup.json`` and ``lookup.png``.

For each proposed table grid (``sweeps/proposed/*.toml``; ``--quick``: the
Kelvin-Voigt one only) and, for comparison, the grid of the shipped
Kelvin-Voigt spec, it simulates every node directly (columnar, the spec's
numerics), builds the table in memory, and measures the lookup error against
direct simulation at held-out points (mid-points of every cell edge along each
axis, cell centres, random interior points;
:func:`vimpact.lookup.verify.interpolation_error`), for the multilinear and the
cubic lookup. Then it times 1e6 random lookups (cubic and linear side by side,
wall and CPU time of this process: the machine may be shared).
"""

from __future__ import annotations

import math
import time
import tomllib
from pathlib import Path

import numpy as np

from .machine import bench_main, load_average, machine_info, save_figure, use_agg

ROOT = Path(__file__).resolve().parents[1]
N_LOOKUPS = 1_000_000


def grid_axes(spec_path: Path) -> tuple[str, dict, float | None, str]:
    """``(model, axes, tolerance, numerics preset)`` of a grid spec, its axes made as the
    sweep makes them (``per_decade``: ``round(log10(stop/start) * per) + 1`` log-spaced
    values with exact ends; a list as given)."""
    data = tomllib.loads(spec_path.read_text())
    axes = {}
    for key in ("Q1", "Q2", "nu"):
        if key not in data["grid"]:
            continue
        v = data["grid"][key]
        if isinstance(v, dict):
            num = int(round(math.log10(v["stop"] / v["start"]) * v["per_decade"])) + 1
            out = np.logspace(math.log10(v["start"]), math.log10(v["stop"]), num)
            out[0], out[-1] = v["start"], v["stop"]
            axes[key] = out
        else:
            axes[key] = np.asarray(v if isinstance(v, list) else [v], dtype=float)
    numerics = data.get("numerics", {})
    preset = numerics if isinstance(numerics, str) else numerics.get("preset", "default")
    return data["model"], axes, data["grid"].get("tolerance"), preset


def measure_grid(name: str, spec_path: Path, n_random: int) -> tuple[dict, object]:
    from vimpact.lookup.refine import grid_table
    from vimpact.lookup.verify import interpolation_error
    from vimpact.model.numerics import Numerics

    model, axes, tolerance, preset = grid_axes(spec_path)
    numerics = Numerics.preset(preset)
    t0 = time.perf_counter()
    table = grid_table(model, axes, numerics)
    t_nodes = time.perf_counter() - t0
    out = {"spec": str(spec_path.relative_to(ROOT)), "model": model,
           "nodes": {a: len(v) for a, v in axes.items()}, "rows": len(table),
           "failed_nodes": int((table.data["status"] != "ok").sum()),
           "tolerance": tolerance, "numerics_preset": preset, "node_simulation_s": t_nodes}
    for method in ("linear", "cubic"):
        t0 = time.perf_counter()
        res = interpolation_error(table, numerics, n=n_random, seed=0, method=method,
                                  node_sample=0 if method == "linear" else 50)
        res["wall_s"] = time.perf_counter() - t0
        out[method] = res
    cubic = out["cubic"]["outputs"]
    out["meets_tolerance"] = (None if tolerance is None else
                              all(cubic[k]["max"] is not None and cubic[k]["max"] <= tolerance
                                  for k in ("e_z", "beta_x")))
    print(f"{name}: {out['rows']} nodes; max error e_z / beta_x: linear "
          f"{out['linear']['outputs']['e_z']['max']:.2g} / "
          f"{out['linear']['outputs']['beta_x']['max']:.2g}, cubic "
          f"{cubic['e_z']['max']:.2g} / {cubic['beta_x']['max']:.2g} "
          f"({out['cubic']['points']} held-out points)", flush=True)
    return out, table


def time_lookups(table, repeats: int) -> dict:
    """1e6 random in-range lookups, cubic and linear alternated, wall and CPU s."""
    rng = np.random.default_rng(1)
    grid = table._grid(None)
    pts = {}
    for a, n in zip(grid.axes, grid.nodes):
        pts[a] = (np.exp(rng.uniform(np.log(n[0]), np.log(n[-1]), N_LOOKUPS)) if a in ("Q1", "Q2")
                  else rng.uniform(n[0], n[-1], N_LOOKUPS))
    res = {"points": N_LOOKUPS, "axes": grid.axes}
    for method in ("cubic", "linear"):
        table.lookup(pts["Q1"][:10], pts["nu"][:10], pts.get("Q2", [None])[:10]
                     if "Q2" in pts else None, method=method)  # slopes made once per table
    for method in ("cubic", "linear"):
        res[method] = {"wall_s": [], "cpu_s": []}
    for _ in range(repeats):
        for method in ("cubic", "linear"):
            w0, c0 = time.perf_counter(), time.process_time()
            table.lookup(pts["Q1"], pts["nu"], pts.get("Q2"), method=method)
            res[method]["wall_s"].append(time.perf_counter() - w0)
            res[method]["cpu_s"].append(time.process_time() - c0)
    for method in ("cubic", "linear"):
        res[method]["cpu_s_median"] = float(np.median(res[method]["cpu_s"]))
        res[method]["wall_s_median"] = float(np.median(res[method]["wall_s"]))
    res["cubic_over_linear_cpu"] = res["cubic"]["cpu_s_median"] / res["linear"]["cpu_s_median"]
    print(f"  1e6 lookups ({'x'.join(grid.axes)}): cubic {res['cubic']['cpu_s_median']:.2f} s CPU, "
          f"linear {res['linear']['cpu_s_median']:.2f} s CPU", flush=True)
    return res


def run(quick: bool) -> dict:
    import numba

    numba.set_num_threads(1)  # one core
    grids = {"kelvin_voigt_proposed": ROOT / "sweeps/proposed/kelvin_voigt_table.toml",
             "kelvin_voigt_shipped_spec": ROOT / "sweeps/kelvin_voigt_table.toml"}
    if not quick:
        grids["standard_solid_proposed"] = ROOT / "sweeps/proposed/standard_solid_table.toml"
    data = {"benchmark": "lookup", "machine": machine_info(), "load_before": load_average(),
            "grids": {}, "timing": {}}
    for name, path in grids.items():
        if not path.is_file():
            continue
        result, table = measure_grid(name, path, 200 if quick else 2000)
        data["grids"][name] = result
        if name.endswith("proposed"):
            data["timing"][name] = time_lookups(table, 1 if quick else 3)
    data["load_after"] = load_average()
    figures = {}
    for name, g in data["grids"].items():
        for method in ("linear", "cubic"):
            for k in ("e_z", "beta_x"):
                figures[f"{name}.{method}.{k}_max"] = {
                    "value": g[method]["outputs"][k]["max"], "unit": "1", "better": "lower",
                    "kind": "accuracy"}
    for name, t in data["timing"].items():
        figures[f"{name}.lookup_1e6_cubic_cpu"] = {"value": t["cubic"]["cpu_s_median"],
                                                   "unit": "s", "better": "lower", "kind": "time"}
    data["figures"] = figures
    return data


def plot(data: dict, path: Path) -> None:
    use_agg()
    import matplotlib.pyplot as plt

    names = list(data["grids"])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    x = np.arange(len(names))
    for j, (method, k) in enumerate([(m, k) for m in ("linear", "cubic") for k in ("e_z", "beta_x")]):
        vals = [data["grids"][n][method]["outputs"][k]["max"] or np.nan for n in names]
        axes[0].bar(x + (j - 1.5) * 0.2, vals, 0.2, label=f"{method} {k}")
    axes[0].axhline(1e-5, color="k", lw=0.8, ls="--", label="1e-5")
    axes[0].set_yscale("log")
    axes[0].set_xticks(x, [n.replace("_", "\n") for n in names], fontsize=7)
    axes[0].set_ylabel("max |lookup - simulation| between nodes")
    axes[0].legend(fontsize=7)
    tn = list(data["timing"])
    for j, method in enumerate(("linear", "cubic")):
        axes[1].bar(np.arange(len(tn)) + (j - 0.5) * 0.35,
                    [data["timing"][n][method]["cpu_s_median"] for n in tn], 0.35, label=method)
    axes[1].set_xticks(np.arange(len(tn)), [n.replace("_", "\n") for n in tn], fontsize=7)
    axes[1].set_ylabel("CPU s per 1e6 lookups (one core)")
    axes[1].legend(fontsize=7)
    save_figure(fig, path)


def main(argv: list[str] | None = None) -> dict:
    return bench_main(__doc__, run, plot, "lookup", argv=argv)


if __name__ == "__main__":
    main()
