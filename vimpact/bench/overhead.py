"""Python time per row outside the kernels, and the Kelvin-Voigt batch throughput.

Run: ``vimpact bench overhead [--quick] [--out DIR]``; the full-size run of
the repository is ``python -m benchmarks.overhead`` (``benchmarks/results/``).

``vimpact.simulate_batch(columns, numerics, timings=t)`` on scene columns (a
mapping of arrays: no per-row Python objects) fills ``t["kernel_s"]`` (time
inside the numba kernels) and ``t["total_s"]`` (the whole call). The Python
overhead per row is ``(total_s - kernel_s) / rows``: validation, routing,
packing, unpacking and the ``DataFrame``. Measured on

- the continuum path: ``1e5`` random Kelvin-Voigt normal-only rows
  (``tangential = "none"``, default numerics);
- an element path: random oblique Kelvin-Voigt rows (``v_x0 = v_z0``,
  rotation) with Coulomb friction (``mu`` uniform in [0.1, 0.5]; friction
  needs the element kernel, full stick would take a continuum path) at the
  ``fast`` preset, fewer rows (the kernel is some ten times dearer per row);

both on 2 numba threads (or 1 where numba has only one), after a warm-up
call that compiles or loads the kernels; median over the repeats. Also the
Kelvin-Voigt normal-only throughput, rows / ``total_s``. Targets:
overhead <= 5 microseconds per row, throughput >= 50,000 rows/s on 2 threads.

Rows: ``nu`` uniform in [0, 0.5], ``R`` log-uniform in [1 mm, 10 cm], steel
density (``m = 7800 kg/m^3 * 4/3 pi R^3``), ``v_z0`` log-uniform in [0.1,
10] m/s, the modulus chosen for ``a_H / R`` log-uniform in [0.003, 0.03]
and the dashpot for ``Q1`` log-uniform in [1e-3, 1]. Nothing here asserts
a time.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numba
import numpy as np

from .machine import figure, load_average, machine_info, progress, save_figure, use_agg

TITLE = "Python overhead per row outside the kernels (columnar simulate_batch) and KV rows/s"

#: targets: Python time per row outside the kernels, s; Kelvin-Voigt normal-only rows/s
TARGET_OVERHEAD_US_PER_ROW = 5.0
TARGET_KV_ROWS_PER_SECOND = 50_000.0
THREADS = 2

#: rows and repeats of each measurement
CONFIGS = {
    "full": dict(kv_rows=100_000, kv_repeats=7, element_rows=10_000, element_repeats=5),
    "quick": dict(kv_rows=100_000, kv_repeats=3, element_rows=1_000, element_repeats=3),
}


def scene_columns(n: int, seed: int = 0, oblique: bool = False) -> dict[str, np.ndarray]:
    """``n`` random Kelvin-Voigt rows as scene columns (SI units, see the module).

    Normal-only (``tangential = "none"``) unless ``oblique``, in which case
    ``v_x0 = v_z0`` and the tangential problem runs with Coulomb friction
    (``mu`` uniform in [0.1, 0.5]) and rotation.
    """
    from vimpact.model.hertz import Q1_PER_TAU

    rng = np.random.default_rng(seed)
    nu = rng.uniform(0.0, 0.5, n)
    R = 10.0 ** rng.uniform(-3.0, -1.0, n)  # m
    m = 7800.0 * 4.0 / 3.0 * math.pi * R**3  # kg, steel
    v_z0 = 10.0 ** rng.uniform(-1.0, 1.0, n)  # m/s
    a_over_R = 10.0 ** rng.uniform(math.log10(0.003), math.log10(0.03), n)
    d = a_over_R**2 * R  # Hertz indentation, a_H = sqrt(R d), m
    E_star = 15.0 * m * v_z0**2 / (16.0 * np.sqrt(R) * d**2.5)  # Pa
    G = E_star * (1.0 - nu) / 2.0  # Pa
    Q1 = 10.0 ** rng.uniform(-3.0, 0.0, n)
    eta0 = Q1 / Q1_PER_TAU * d / v_z0 * G  # Pa s
    cols = {"nu": nu, "G_inf_Pa": G, "eta0_Pa_s": eta0, "R_m": R, "m_kg": m,
            "v_z0_m_s": v_z0}
    if oblique:
        cols["v_x0_m_s"] = v_z0.copy()
        cols["mu"] = rng.uniform(0.1, 0.5, n)
    else:
        cols["tangential"] = np.full(n, "none", dtype=object)
    return cols


def _measure(columns: dict, numerics, repeats: int) -> dict:
    """``repeats`` calls of ``simulate_batch(columns, numerics, timings=t)``:
    per call ``total_s``, ``kernel_s``, overhead per row (us) and rows/s."""
    import vimpact as v

    rows = len(columns["nu"])
    total, kernel = [], []
    frame = None
    for _ in range(repeats):
        t: dict = {}
        frame = v.simulate_batch(columns, numerics, timings=t)
        total.append(t["total_s"])
        kernel.append(t["kernel_s"])
    over = [(a - b) / rows * 1e6 for a, b in zip(total, kernel)]
    rate = [rows / a for a in total]
    statuses = frame["status"].value_counts().to_dict()
    if "invalid" in statuses:
        bad = frame.loc[frame["status"] == "invalid", "error"].iloc[0]
        raise RuntimeError(f"overhead benchmark made an invalid row: {bad}")
    return {
        "rows": rows, "repeats": repeats,
        "total_s": total, "kernel_s": kernel,
        "overhead_us_per_row": over, "rows_per_second": rate,
        "median_overhead_us_per_row": float(np.median(over)),
        "median_kernel_us_per_row": float(np.median(kernel)) / rows * 1e6,
        "median_total_us_per_row": float(np.median(total)) / rows * 1e6,
        "median_rows_per_second": float(np.median(rate)),
        "overhead_share": float(np.median([1.0 - b / a for a, b in zip(total, kernel)])),
        "paths": {str(k): int(x) for k, x in frame["path"].value_counts().items()},
        "statuses": {str(k): int(x) for k, x in statuses.items()},
    }


def run(quick: bool = False) -> dict:
    """Measure both paths; returns the JSON-ready record (``continuum``,
    ``elements``: see :func:`_measure`; ``targets`` and whether they are met)."""
    import vimpact as v

    cfg = CONFIGS["quick" if quick else "full"]
    all_threads = numba.config.NUMBA_NUM_THREADS
    threads = min(THREADS, all_threads)
    load_before = load_average()
    start = time.perf_counter()
    kv_cols = scene_columns(cfg["kv_rows"], seed=1)
    el_cols = scene_columns(cfg["element_rows"], seed=2, oblique=True)
    fast = v.Numerics.preset("fast")
    numba.set_num_threads(threads)
    try:
        progress("overhead: compiling / loading the kernels", start)
        v.simulate_batch({k: x[:64] for k, x in kv_cols.items()})
        v.simulate_batch({k: x[:64] for k, x in el_cols.items()}, fast)
        progress(f"overhead: continuum path, {cfg['kv_rows']} rows", start)
        kv = _measure(kv_cols, None, cfg["kv_repeats"])
        progress(f"overhead: element path, {cfg['element_rows']} rows", start)
        el = _measure(el_cols, fast, cfg["element_repeats"])
    finally:
        numba.set_num_threads(all_threads)
    return {
        "machine": machine_info(),
        "load_average": {"before": load_before, "after": load_average()},
        "threads": threads,
        "config": {**cfg, "quick": quick, "continuum_numerics": "Numerics()",
                   "element_numerics": "fast"},
        "continuum": kv,
        "elements": el,
        "targets": {
            "overhead_us_per_row_max": TARGET_OVERHEAD_US_PER_ROW,
            "kv_rows_per_second_min": TARGET_KV_ROWS_PER_SECOND,
            "continuum_overhead_met": kv["median_overhead_us_per_row"]
            <= TARGET_OVERHEAD_US_PER_ROW,
            "element_overhead_met": el["median_overhead_us_per_row"]
            <= TARGET_OVERHEAD_US_PER_ROW,
            "kv_rows_per_second_met": kv["median_rows_per_second"]
            >= TARGET_KV_ROWS_PER_SECOND,
        },
    }


def figures(data: dict) -> dict:
    """Overhead per row of each path, kernel time per row and the KV rows/s."""
    out = {}
    for key in ("continuum", "elements"):
        d = data[key]
        out[f"{key}_overhead_us_per_row"] = figure(
            d["median_overhead_us_per_row"], "us/row", samples=d["overhead_us_per_row"])
        out[f"{key}_kernel_us_per_row"] = figure(
            d["median_kernel_us_per_row"], "us/row", samples=d["kernel_s"])
    kv = data["continuum"]
    out["continuum_rows_per_second"] = figure(kv["median_rows_per_second"], "rows/s",
                                              better="higher", samples=kv["rows_per_second"])
    return out


def report(data: dict) -> str:
    """Per path: rows, total, kernel and overhead time per row; the targets."""
    lines = [f"{'path':<10}{'rows':>8}{'total us/row':>14}{'kernel us/row':>15}"
             f"{'overhead us/row':>17}{'rows/s':>11}"]
    for key in ("continuum", "elements"):
        d = data[key]
        lines.append(f"{key:<10}{d['rows']:>8}{d['median_total_us_per_row']:>14.2f}"
                     f"{d['median_kernel_us_per_row']:>15.2f}"
                     f"{d['median_overhead_us_per_row']:>17.2f}"
                     f"{d['median_rows_per_second']:>11.4g}")
    t = data["targets"]
    lines.append(f"targets ({data['threads']} threads): overhead <= "
                 f"{t['overhead_us_per_row_max']:g} us/row: continuum "
                 f"{'met' if t['continuum_overhead_met'] else 'NOT met'}, elements "
                 f"{'met' if t['element_overhead_met'] else 'NOT met'}; Kelvin-Voigt >= "
                 f"{t['kv_rows_per_second_min']:g} rows/s: "
                 f"{'met' if t['kv_rows_per_second_met'] else 'NOT met'}")
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    """Left: time per row split into kernel and Python overhead, per path, with
    the overhead target; right: Kelvin-Voigt rows/s per repeat with the target."""
    use_agg()
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10.0, 4.0),
                                 gridspec_kw={"width_ratios": [1.6, 1.0]})
    names = ["continuum", "elements"]
    labels = [f"{n}\n({data[n]['rows']} rows)" for n in names]
    kern = [data[n]["median_kernel_us_per_row"] for n in names]
    over = [data[n]["median_overhead_us_per_row"] for n in names]
    y = np.arange(len(names))
    ax.barh(y + 0.2, kern, 0.4, color="tab:blue", label="inside the kernels")
    ax.barh(y - 0.2, over, 0.4, color="tab:orange", label="Python outside the kernels")
    for yi, k, o in zip(y, kern, over):
        ax.annotate(f"{k:.3g} us/row", (k, yi + 0.2), xytext=(4, 0),
                    textcoords="offset points", va="center", fontsize=8)
        ax.annotate(f"{o:.3g} us/row", (o, yi - 0.2), xytext=(4, 0),
                    textcoords="offset points", va="center", fontsize=8)
    ax.axvline(data["targets"]["overhead_us_per_row_max"], color="k", ls=":", lw=1,
               label="overhead target (5 us/row)")
    ax.set_xscale("log")
    ax.set_xlim(min(kern + over) / 3, max(kern + over) * 8)
    ax.set_yticks(y, labels)
    ax.set_xlabel("wall time per row, microseconds (simulate_batch on columns)")
    ax.set_title(f"Where the time goes ({data['threads']} numba threads)", fontsize=10)
    ax.legend(fontsize=7, loc="lower right")
    kv = data["continuum"]
    bx.plot(range(1, len(kv["rows_per_second"]) + 1), kv["rows_per_second"], "o",
            color="tab:blue", label="repeats")
    bx.axhline(kv["median_rows_per_second"], color="tab:blue", lw=1.2,
               label=f"median {kv['median_rows_per_second']:.3g} rows/s")
    bx.axhline(data["targets"]["kv_rows_per_second_min"], color="k", ls=":", lw=1,
               label="target 50,000 rows/s")
    bx.set_ylim(0, max(max(kv["rows_per_second"]), data["targets"]["kv_rows_per_second_min"])
                * 1.3)
    bx.set_xticks(range(1, len(kv["rows_per_second"]) + 1))
    bx.set_xlabel("repeat")
    bx.set_ylabel("rows per second")
    bx.set_title("Kelvin-Voigt normal-only batch", fontsize=10)
    bx.legend(fontsize=7, loc="lower right")
    fig.suptitle(data["machine"]["cpu"], fontsize=8)
    save_figure(fig, path)
