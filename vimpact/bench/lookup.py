"""Lookup: 1e6-point time of the numba kernel against the NumPy reference, and accuracy.

``vimpact bench lookup [--quick] [--out DIR]``; from a source checkout
``python -m benchmarks.lookup [--quick] [--out DIR]`` writes
``benchmarks/results/lookup[_quick].json`` and ``lookup[_quick].png``.

Time (always): on the shipped tables (``sweeps/tables/kelvin_voigt_table.parquet``:
Q1 x nu; ``standard_solid_table.parquet``: Q1 x Q2 x nu), 1e6 random in-range
lookups, side by side in one process on one numba thread: the cubic lookup through
the numba kernel (:func:`vimpact.kernels.hermite.hermite_eval`), the same through
the NumPy reference evaluation (``backend="numpy"``), and the multilinear lookup;
median CPU and wall time of the repeats (the machine may be shared), and the
largest difference between kernel and reference. The first call's time (kernel
loaded from numba's cache, or compiled) is reported apart. Where the shipped
tables are not at hand (the installed package), a small Kelvin-Voigt table
(:data:`BUILT_AXES`, ``fast`` numerics) is simulated in memory and timed instead.

Accuracy (full run, source checkout only): for each proposed table grid (``sweeps/proposed/*.toml``)
and the grid of the shipped Kelvin-Voigt spec, it simulates every node directly
(the spec's numerics), builds the table in memory, and measures the lookup error
against direct simulation at held-out points (mid-points of every cell edge along
each axis, cell centres, random interior points;
:func:`vimpact.tablebuild.verify.interpolation_error`), multilinear and cubic.
"""

from __future__ import annotations

import math
import time
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from .machine import load_average, machine_info, save_figure, use_agg

TITLE = "Lookup: 1e6 cubic lookups, numba kernel vs NumPy reference; error between nodes"
#: the source checkout (shipped tables and proposed specs; absent when installed)
ROOT = Path(__file__).resolve().parents[2]
#: nodes of the table built in memory when no shipped table is at hand
BUILT_AXES = {"Q1": np.logspace(-3.0, 2.0, 16), "nu": np.array([0.0, 0.25, 0.5])}
N_LOOKUPS = 1_000_000


def grid_axes(spec_path: Path) -> tuple[str, dict, float | None, str]:
    """Return the model, axes, tolerance and numerics preset of a grid spec.

    ``(model, axes, tolerance, numerics preset)`` of a grid spec, its axes made as the
    sweep makes them (``per_decade``: ``round(log10(stop/start) * per) + 1`` log-spaced
    values with exact ends; a list as given).
    """
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
    """Build the table of grid ``name`` and measure its interpolation error."""
    from vimpact.model.numerics import Numerics
    from vimpact.tablebuild.refine import grid_table
    from vimpact.tablebuild.verify import interpolation_error

    model, axes, tolerance, preset = grid_axes(spec_path)
    numerics = Numerics.preset(preset)
    t0 = time.perf_counter()
    table = grid_table(model, axes, numerics)
    t_nodes = time.perf_counter() - t0
    out: dict[str, Any] = {"spec": str(spec_path.relative_to(ROOT)), "model": model,
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


#: Shipped tables timed, by the number of lookup axes.
SHIPPED = {"kelvin_voigt_2_axes": ROOT / "sweeps/tables/kelvin_voigt_table.parquet",
           "standard_solid_3_axes": ROOT / "sweeps/tables/standard_solid_table.parquet"}
#: The evaluations timed side by side: (name, method, HermiteGrid backend or None for
#: the whole :meth:`RestitutionTable.lookup`, input checks and all).
VARIANTS = (("cubic_lookup", "cubic", None), ("cubic_numba", "cubic", "numba"),
            ("cubic_numpy", "cubic", "numpy"), ("linear_lookup", "linear", None))


def _open_shipped(path: Path):
    """Open a shipped table.

    Return a shipped table, its rows validated (the file's integrity is the store's
    concern and its own tests'; it does not change the lookup time).
    """
    from vimpact.lookup.table import RestitutionTable

    return RestitutionTable.open(path, validate=False).validate()


def _lookup(table, pts: dict, variant: tuple) -> dict:
    name, method, backend = variant
    if backend is None:
        return table.lookup(pts["Q1"], pts["nu"], pts.get("Q2"), method=method)
    grid = table._lookup_grid()
    hermite = table._hermite_grid("all axes", grid)
    return hermite([pts[a] for a in grid.axes], False, backend=backend)


def time_lookups(table, repeats: int, n_points: int = N_LOOKUPS) -> dict:
    """Time random in-range lookups per variant.

    ``n_points`` random in-range lookups per variant (:data:`VARIANTS`), alternated,
    wall and CPU s; the kernel's first call timed apart.
    """
    rng = np.random.default_rng(1)
    grid = table._lookup_grid()
    pts = {}
    for a, n in zip(grid.axes, grid.nodes):
        pts[a] = (np.exp(rng.uniform(np.log(n[0]), np.log(n[-1]), n_points))
                  if a in ("Q1", "Q2") else rng.uniform(n[0], n[-1], n_points))
    res = {"points": n_points, "axes": grid.axes, "nodes": [len(n) for n in grid.nodes]}
    small = {a: v[:10] for a, v in pts.items()}
    w0 = time.perf_counter()
    _lookup(table, small, VARIANTS[1])  # slopes, and the kernel loaded (or compiled)
    res["first_call_s"] = time.perf_counter() - w0
    for variant in VARIANTS:
        _lookup(table, small, variant)
    for name, *_ in VARIANTS:
        res[name] = {"wall_s": [], "cpu_s": []}
    outs = {}
    for _ in range(repeats):
        for variant in VARIANTS:
            name = variant[0]
            w0, c0 = time.perf_counter(), time.process_time()
            outs[name] = _lookup(table, pts, variant)
            res[name]["wall_s"].append(time.perf_counter() - w0)
            res[name]["cpu_s"].append(time.process_time() - c0)
    for name, *_ in VARIANTS:
        res[name]["cpu_s_median"] = float(np.median(res[name]["cpu_s"]))
        res[name]["wall_s_median"] = float(np.median(res[name]["wall_s"]))
    res["numpy_over_numba_cpu"] = (res["cubic_numpy"]["cpu_s_median"]
                                   / res["cubic_numba"]["cpu_s_median"])
    res["max_abs_numba_minus_numpy"] = float(max(
        np.nanmax(np.abs(outs["cubic_numba"][k] - outs["cubic_numpy"][k]))
        for k in ("e_z", "beta_x")))
    print(f"  {n_points:.0e} lookups ({'x'.join(grid.axes)}), CPU s: "
          + ", ".join(f"{v[0]} {res[v[0]]['cpu_s_median']:.3f}" for v in VARIANTS)
          + f" (numpy / numba kernel {res['numpy_over_numba_cpu']:.1f}x); max |numba - numpy| "
          f"{res['max_abs_numba_minus_numpy']:.1e}; first call {res['first_call_s']:.2f} s",
          flush=True)
    return res


def run(quick: bool) -> dict:
    """Time the lookups of the shipped tables (and measure a grid); return the record."""
    import numba

    numba.set_num_threads(1)  # one core
    data: dict[str, Any] = {"benchmark": "lookup", "machine": machine_info(),
                            "load_before": load_average(),
            "grids": {}, "timing": {}}
    for name, path in SHIPPED.items():
        if path.is_file():
            table = _open_shipped(path)
            if table.is_adaptive:  # not a tensor grid: timed by the adaptive_lookup benchmark
                print(f"{name}: {path.relative_to(ROOT)} is adaptive (bench adaptive_lookup)",
                      flush=True)
                continue
            print(f"{name}: {path.relative_to(ROOT)}", flush=True)
            data["timing"][name] = time_lookups(table, 1 if quick else 3)
    if not data["timing"]:  # installed: no shipped table here, build a small one
        from vimpact.model.numerics import Numerics
        from vimpact.tablebuild.refine import grid_table

        table = grid_table("kelvin_voigt", BUILT_AXES, Numerics.preset("fast"))
        print(f"kelvin_voigt_2_axes_built: {len(table)} nodes simulated", flush=True)
        data["timing"]["kelvin_voigt_2_axes_built"] = time_lookups(table, 1 if quick else 3)
    if not quick:
        grids = {"kelvin_voigt_proposed": ROOT / "sweeps/proposed/kelvin_voigt_table.toml",
                 "kelvin_voigt_shipped_spec": ROOT / "sweeps/kelvin_voigt_table.toml",
                 "standard_solid_proposed": ROOT / "sweeps/proposed/standard_solid_table.toml"}
        for name, path in grids.items():
            if path.is_file():
                data["grids"][name] = measure_grid(name, path, 2000)[0]
    data["load_after"] = load_average()
    data["figures"] = figures(data)
    return data


def figures(data: dict) -> dict:
    """Return the headline numbers of a lookup run.

    Headline numbers: cubic lookup CPU time per 1e6 points (numba kernel and NumPy
    reference) per shipped table; with the accuracy part, the max errors per grid.
    """
    from vimpact.bench.machine import figure

    out = {}
    for name, t in data["timing"].items():
        scale = N_LOOKUPS / t["points"]
        for variant in ("cubic_lookup", "cubic_numba", "cubic_numpy"):
            out[f"{name}.lookup_1e6_{variant}_cpu"] = figure(
                t[variant]["cpu_s_median"] * scale, "s", "lower", "time",
                samples=[x * scale for x in t[variant]["cpu_s"]])
    for name, g in data["grids"].items():
        for method in ("linear", "cubic"):
            for k in ("e_z", "beta_x"):
                out[f"{name}.{method}.{k}_max"] = figure(g[method]["outputs"][k]["max"], "1",
                                                          "lower", "accuracy")
    return out


def report(data: dict) -> str:
    """One line per shipped table: the three evaluations' CPU time side by side."""
    lines = []
    for name, t in data["timing"].items():
        lines.append(f"{name} ({' x '.join(f'{n} {a}' for a, n in zip(t['axes'], t['nodes']))}): "
                     f"{t['points']:.0e} lookups, CPU s: "
                     + ", ".join(f"{v[0]} {t[v[0]]['cpu_s_median']:.3f}" for v in VARIANTS)
                     + f" (numpy / numba kernel {t['numpy_over_numba_cpu']:.1f}x)")
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    """Draw the lookup times (and grid errors) to ``path``."""
    use_agg()
    import matplotlib.pyplot as plt

    names = list(data["grids"])
    fig, axes = plt.subplots(1, 2 if names else 1, figsize=(11 if names else 6, 4))
    axes = np.atleast_1d(axes)
    tn = list(data["timing"])
    for j, (variant, *_) in enumerate(VARIANTS):
        axes[0].bar(np.arange(len(tn)) + (j - 1.5) * 0.2,
                    [data["timing"][n][variant]["cpu_s_median"] * N_LOOKUPS
                     / data["timing"][n]["points"] for n in tn], 0.2,
                    label=variant.replace("_", " "))
    axes[0].axhline(1.0, color="k", lw=0.8, ls="--", label="target 1 s")
    axes[0].set_xticks(np.arange(len(tn)), [n.replace("_", " ") for n in tn], fontsize=8)
    axes[0].set_ylabel("CPU s per 1e6 lookups (one core)")
    axes[0].set_title("shipped tables", fontsize=9)
    axes[0].legend(fontsize=7)
    if names:
        x = np.arange(len(names))
        for j, (method, k) in enumerate([(m, k) for m in ("linear", "cubic")
                                         for k in ("e_z", "beta_x")]):
            vals = [data["grids"][n][method]["outputs"][k]["max"] or np.nan for n in names]
            axes[1].bar(x + (j - 1.5) * 0.2, vals, 0.2, label=f"{method} {k}")
        axes[1].axhline(1e-5, color="k", lw=0.8, ls="--", label="1e-5")
        axes[1].set_yscale("log")
        axes[1].set_xticks(x, [n.replace("_", "\n") for n in names], fontsize=7)
        axes[1].set_ylabel("max |lookup - simulation| between nodes")
        axes[1].legend(fontsize=7)
    save_figure(fig, path)
