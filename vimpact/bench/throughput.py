"""Element-updates per second: batch kernel on 1 and 2 threads vs NumPy and pure Python.

Run: ``vimpact bench throughput [--quick] [--out DIR]``; the full-size run of
the repository is ``python -m benchmarks.throughput`` (``benchmarks/results/``).

One element-update is one element of the row advanced by one time step, so
an impact costs ``steps taken x ceil(row_width * elements)`` of them; the
rate is comparable across batch sizes and numerics. Measured on the same random
Kelvin-Voigt and standard-solid scenes (oblique, so the tangential problem
runs too) at the same ``Numerics``, continuum paths off (``continuum=False``:
the element kernel is what is measured):

- the batch kernel (``vimpact.simulate_batch``, Python packing and result
  rows included) on one and on two numba threads, alternated repeat by
  repeat in one process (the machine is shared and noisy: compare ratios;
  the process CPU time is stored too, and CPU / wall time of the 2-thread
  runs says how many cores they actually got);
- the NumPy reference :func:`vimpact.reference.numpy_elements.naive_impact` and
  the pure-Python baseline :func:`vimpact.bench.pure_python.pure_python_impact`, each on the
  first few of the same scenes (they are slow).

Each is credited with the time steps it took (the kernel's ``n_steps``
result column) times the elements in its half row, both refined by
:func:`vimpact.engine.routing.refinement` for stiff modes exactly as in the kernel.
The element count is nominal: the kernel skips elements the sphere has
never reached, the baselines do not. Compile time is excluded (warm-up call
first); the median of the repeats is reported. Nothing here asserts a time.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import TypeVar

import numba
import numpy as np
import pandas as pd

import vimpact as v
from vimpact.reference.numpy_elements import naive_impact

from .machine import (
    figure,
    load_average,
    machine_info,
    max_threads,
    progress,
    ratio_spread,
    save_figure,
    use_agg,
)
from .pure_python import kernel_refinement, pure_python_impact, refined_row

TITLE = "element-updates per second: batch kernel (1 and 2 threads) vs NumPy and pure Python"

T = TypeVar("T")

#: sizes: kernel batch, NumPy and pure-Python subsets, repeats, numerics
CONFIGS = {
    "full": dict(n_scenes=64, n_numpy=8, n_python=8, repeats=11, baseline_repeats=5,
                 numerics=v.Numerics(continuum=False)),
    "quick": dict(n_scenes=8, n_numpy=2, n_python=2, repeats=2, baseline_repeats=1,
                  numerics=v.Numerics(steps=60, elements=12, continuum=False)),
}


def timed(fn: Callable[[], T]) -> tuple[float, T]:
    """Wall time of one call of ``fn`` (s) and its return value."""
    t0 = time.perf_counter()
    result = fn()
    return time.perf_counter() - t0, result


def random_scenes(n: int, seed: int = 0) -> list[v.Scene]:
    """``n`` random scenes, alternately Kelvin-Voigt and standard solid.

    ``Q1`` log-uniform in [1e-3, 1], ``Q2`` log-uniform in [1e-2, 1e2]
    (standard solid), ``nu`` uniform in [0, 0.5]; all dimensionless, made
    by :meth:`vimpact.Scene.from_dimensionless` (oblique: ``v_c0 = 1 m/s``).
    Any prefix of the list is a balanced mix of the two materials.
    """
    rng = np.random.default_rng(seed)
    scenes = []
    for i in range(n):
        q1 = 10.0 ** rng.uniform(-3.0, 0.0)
        nu = rng.uniform(0.0, 0.5)
        q2 = 10.0 ** rng.uniform(-2.0, 2.0)
        scenes.append(v.Scene.from_dimensionless(q1, nu, None if i % 2 == 0 else q2))
    return scenes


def kernel_counts(table: pd.DataFrame, scenes: list[v.Scene], numerics: v.Numerics,
                  ) -> tuple[list[int], list[int]]:
    """Return the time steps and half-row elements of each scene.

    Time steps the kernel took (``n_steps`` column of
    :func:`vimpact.simulate_batch`) and elements in the half row of each scene.

    Raises
    ------
    ValueError
        if a scene did not run on the element kernel (its steps are then
        no element-updates).
    """
    other = sorted({p for p in table["path"] if not p.startswith("elements")})
    if other:
        raise ValueError(f"element-updates need the element kernel; scenes ran on {other}")
    elements = [_row(s, numerics) for s in scenes]
    return [int(k) for k in table["n_steps"]], elements


def _row(scene: v.Scene, numerics: v.Numerics) -> int:
    """Elements in the half row of ``scene`` at ``numerics`` (refined as in the kernel)."""
    return refined_row(scene, numerics.steps, numerics.elements, numerics.row_width)[2]


def _baseline(impact: Callable[..., dict], scene: v.Scene, numerics: v.Numerics) -> dict:
    """``impact(scene, steps, elements, row_width, max_time)`` at ``numerics``."""
    return impact(scene, numerics.steps, numerics.elements, numerics.row_width, numerics.max_time)


def _naive_as_kernel(scene: v.Scene, steps: int, elements: int, row_width: float,
                     max_time: float) -> dict:
    """Return the NumPy reference at the kernel's refinement of ``scene`` (the same work)."""
    return naive_impact(scene, steps, elements, row_width, max_time,
                        refinement=kernel_refinement(scene, steps, elements, row_width))


def _entry(threads: int, steps: list[int], elements: list[int], seconds: list[float],
           cpu_seconds: list[float] | None = None) -> dict:
    """One implementation's record.

    Per-scene steps and row elements, raw, median and least wall times (s), process CPU
    times (s, all threads) if measured, and the rate (1/s) from the median.
    """
    updates = sum(k * n for k, n in zip(steps, elements))
    median = float(np.median(seconds))
    return {"threads": threads, "n_scenes": len(steps), "steps": steps, "elements": elements,
            "element_updates": updates, "seconds": seconds, "median_seconds": median,
            "min_seconds": min(seconds), "cpu_seconds": cpu_seconds,
            "element_updates_per_second": updates / median}


def run(quick: bool = False) -> dict:
    """Measure the element-update rates; returns the JSON-ready record.

    Keys: ``machine``, ``load_average`` (before and after), ``config``
    (sizes and numerics), ``kernel_paths`` (the kernels that ran),
    ``implementations`` (``kernel_1_thread``, ``kernel_2_threads`` if numba
    has two threads, ``numpy``, ``pure_python``: see :func:`_entry`) and
    ``ratios`` of the rates (``kernel_over_numpy`` and
    ``kernel_over_pure_python`` with the kernel on one thread,
    ``kernel_2_threads_over_numpy``, ``two_threads_over_one``,
    ``numpy_over_pure_python``; ``None`` where a rate is missing).
    """
    cfg = CONFIGS["quick" if quick else "full"]
    load_before = load_average()
    numerics: v.Numerics = cfg["numerics"]
    scenes = random_scenes(cfg["n_scenes"])
    all_threads = max_threads()
    thread_counts = [1, 2] if all_threads >= 2 else [1]

    # kernel: warm up (compile / load the cache), then 1 and 2 threads alternately
    t_start = time.perf_counter()
    progress("throughput: compiling / loading the kernels", t_start)
    table = v.simulate_batch(scenes, numerics)
    steps, elements = kernel_counts(table, scenes, numerics)
    seconds: dict[int, list[float]] = {nt: [] for nt in thread_counts}
    cpu: dict[int, list[float]] = {nt: [] for nt in thread_counts}
    try:
        for nt in thread_counts:  # start each thread pool size once
            numba.set_num_threads(nt)
            v.simulate_batch(scenes[:2 * nt], numerics)
        for _ in range(cfg["repeats"]):
            for nt in thread_counts:
                numba.set_num_threads(nt)
                cpu0 = time.process_time()
                seconds[nt].append(timed(lambda: v.simulate_batch(scenes, numerics))[0])
                cpu[nt].append(time.process_time() - cpu0)
    finally:
        numba.set_num_threads(all_threads)
    impls = {f"kernel_{nt}_thread{'s' if nt > 1 else ''}":
             _entry(nt, steps, elements, seconds[nt], cpu[nt]) for nt in thread_counts}

    # baselines: the first few of the same scenes, single-threaded, same numerics
    progress("throughput: kernel timed; NumPy and pure-Python baselines", t_start)
    for name, impact, n in (("numpy", _naive_as_kernel, cfg["n_numpy"]),
                            ("pure_python", pure_python_impact, cfg["n_python"])):
        times, counts = [], []
        for _ in range(cfg["baseline_repeats"]):
            t, results = timed(lambda: [_baseline(impact, s, numerics) for s in scenes[:n]])
            times.append(t)
            counts = [r["steps"] for r in results]
        impls[name] = _entry(1, counts, [_row(s, numerics) for s in scenes[:n]], times)

    rate = {k: x["element_updates_per_second"] for k, x in impls.items()}

    def ratio(a: str, b: str) -> float | None:
        return rate[a] / rate[b] if a in rate and b in rate else None

    return {
        "machine": machine_info(),
        "load_average": {"before": load_before, "after": load_average()},
        "config": {**{k: x for k, x in cfg.items() if k != "numerics"},
                   "numerics": asdict(numerics), "quick": quick},
        "kernel_paths": sorted(set(table["path"])),
        "implementations": impls,
        "ratios": {
            "kernel_over_numpy": ratio("kernel_1_thread", "numpy"),
            "kernel_over_pure_python": ratio("kernel_1_thread", "pure_python"),
            "kernel_2_threads_over_numpy": ratio("kernel_2_threads", "numpy"),
            "two_threads_over_one": ratio("kernel_2_threads", "kernel_1_thread"),
            "numpy_over_pure_python": ratio("numpy", "pure_python"),
        },
    }


def plot(data: dict, path: Path) -> None:
    """Bar plot of the element-update rates (1/s, log scale) to ``path``."""
    use_agg()
    import matplotlib.pyplot as plt

    impls = data["implementations"]
    names = list(impls)
    rates = [impls[k]["element_updates_per_second"] for k in names]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    bars = ax.bar([k.replace("_", " ") for k in names], rates,
                  color=[f"C{i}" for i in range(len(names))])
    ax.set_yscale("log")
    numpy_rate = impls["numpy"]["element_updates_per_second"]
    for bar, r in zip(bars, rates):
        ax.annotate(f"{r:.3g}/s\n{r / numpy_rate:.3g}x NumPy",
                    (bar.get_x() + bar.get_width() / 2, r), ha="center", va="bottom", fontsize=8)
    ax.set_ylim(min(rates) / 3, max(rates) * 5)
    n = data["config"]["numerics"]
    ax.set_ylabel("element-updates per second (1/s)")
    ax.set_title(f"{n['steps']} steps / t_H, {n['elements']} elements / a_H; "
                 f"{data['machine']['cpu']}", fontsize=9)
    save_figure(fig, path)


def figures(data: dict) -> dict:
    """Element-updates per second of each implementation and the ratios."""
    impls = data["implementations"]
    out = {}
    sp = {}
    for name, x in impls.items():
        f = figure(x["element_updates_per_second"], "1/s", better="higher", samples=x["seconds"])
        sp[name] = f["spread"]
        out[f"{name}_element_updates_per_second"] = f
    pairs = {"kernel_over_numpy": ("kernel_1_thread", "numpy"),
             "kernel_over_pure_python": ("kernel_1_thread", "pure_python"),
             "two_threads_over_one": ("kernel_2_threads", "kernel_1_thread")}
    for key, (a, b) in pairs.items():
        if data["ratios"].get(key) is not None:
            out[key] = figure(data["ratios"][key], "-", better="higher",
                              rel_spread=ratio_spread(sp.get(a), sp.get(b)))
    return out


def report(data: dict) -> str:
    """Return the rates as a text table, the ratios and the cores the 2 threads got."""
    lines = ["kernels: " + ", ".join(data["kernel_paths"]),
             f"{'implementation':<18}{'threads':>8}{'scenes':>8}{'updates':>12}"
             f"{'median s':>10}{'updates/s':>11}"]
    for name, x in data["implementations"].items():
        lines.append(f"{name:<18}{x['threads']:>8}{x['n_scenes']:>8}{x['element_updates']:>12.3g}"
                     f"{x['median_seconds']:>10.4f}{x['element_updates_per_second']:>11.3g}")
    lines.append("ratios: " + str({k: None if x is None else round(x, 2)
                                   for k, x in data["ratios"].items()}))
    two = data["implementations"].get("kernel_2_threads")
    if two and two.get("cpu_seconds"):  # CPU / wall time: how many cores the 2 threads got
        cores = np.median(two["cpu_seconds"]) / two["median_seconds"]
        lines.append(f"2 threads kept {cores:.2f} cores busy; load average "
                     f"{data['load_average']}")
    return "\n".join(lines)
