"""How the batch kernel's wall time scales with batch size, elements and steps.

Run: ``vimpact bench scaling [--quick] [--out DIR]``; the full-size run of
the repository is ``python -m benchmarks.scaling`` (``benchmarks/results/``).

Wall time of ``vimpact.simulate_batch`` on the element kernel
(``Numerics(continuum=False)``; all numba threads, Python packing
and result rows included) on the random Kelvin-Voigt / standard-solid scenes
of :func:`vimpact.bench.throughput.random_scenes`, against

- ``scenes``: the number of parameter sets, at fixed numerics;
- ``elements``: elements per Hertz radius ``a_H``, at fixed steps per ``t_H``;
- ``steps``: time steps per Hertz time ``t_H``, at fixed elements per ``a_H``.

Each sweep gets a power law ``t = c x^p`` fitted by least squares in log-log
(``p`` about 1 is linear scaling). The repeats go round all points in turn
(the machine is shared and noisy) and the median is fitted. Nothing here
asserts a time.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numba
import numpy as np

import vimpact as v

from .machine import figure, load_average, machine_info, progress, save_figure, use_agg
from .throughput import random_scenes, timed

TITLE = "how the batch wall time scales with batch size, elements and steps (power-law fits)"


#: sweep values, scenes per point of the numerics sweeps, base numerics, repeats
CONFIGS = {
    "full": dict(scenes=[8, 16, 32, 64, 128, 256], elements=[50, 100, 200, 400, 800],
                 steps=[250, 500, 1000, 2000, 4000], n_scenes=64,
                 numerics=v.Numerics(continuum=False),
                 repeats=9),
    "quick": dict(scenes=[2, 4, 8], elements=[8, 16, 32], steps=[25, 50, 100], n_scenes=4,
                  numerics=v.Numerics(steps=50, elements=16, continuum=False),
                  repeats=1),
}


def fit_power_law(x: list[float], t: list[float]) -> dict:
    """Least-squares fit of ``log t = log c + p log x``.

    Returns ``{"exponent": p, "prefactor": c}`` (``c`` in the units of ``t`` per unit of
    ``x**p``).
    """
    p, log_c = np.polyfit(np.log(x), np.log(t), 1)
    return {"exponent": float(p), "prefactor": float(np.exp(log_c))}


def run(quick: bool = False) -> dict:
    """Time the three sweeps; returns the JSON-ready record.

    Keys: ``machine``, ``load_average`` (before and after), ``threads``,
    ``config`` (sweep values and the base numerics) and ``sweeps``: for each
    of ``scenes``, ``elements``, ``steps`` the values ``x``, the ``fixed``
    settings, raw ``seconds`` (one list per point), ``median_seconds``, the
    ``fit`` (:func:`fit_power_law`) and the ``local_exponents`` between
    neighbouring points (a fixed cost per call or per scene shows as
    exponents below 1 at the small end).
    """
    cfg = CONFIGS["quick" if quick else "full"]
    load_before = load_average()
    base: v.Numerics = cfg["numerics"]
    scenes = random_scenes(max(max(cfg["scenes"]), cfg["n_scenes"]))
    fixed = scenes[:cfg["n_scenes"]]
    # every point as (sweep, x, scenes, numerics)
    points = ([("scenes", n, scenes[:n], base) for n in cfg["scenes"]]
              + [("elements", e, fixed, base.with_(elements=e)) for e in cfg["elements"]]
              + [("steps", k, fixed, base.with_(steps=k)) for k in cfg["steps"]])
    v.simulate_batch(scenes[:2], base)  # compile / load the cache outside the timing
    seconds: list[list[float]] = [[] for _ in points]
    for r in range(cfg["repeats"]):
        progress(f"scaling: repeat {r + 1} of {cfg['repeats']}")
        for i, (_, _, batch, numerics) in enumerate(points):
            seconds[i].append(timed(lambda: v.simulate_batch(batch, numerics))[0])

    fixed_settings = {
        "scenes": {"steps": base.steps, "elements": base.elements},
        "elements": {"n_scenes": cfg["n_scenes"], "steps": base.steps},
        "steps": {"n_scenes": cfg["n_scenes"], "elements": base.elements},
    }
    sweeps = {}
    for name, fixed_at in fixed_settings.items():
        idx = [i for i, pt in enumerate(points) if pt[0] == name]
        x = [points[i][1] for i in idx]
        median = [float(np.median(seconds[i])) for i in idx]
        local = np.diff(np.log(median)) / np.diff(np.log(x))
        sweeps[name] = {"x": x, "fixed": fixed_at, "seconds": [seconds[i] for i in idx],
                        "median_seconds": median, "fit": fit_power_law(x, median),
                        "local_exponents": local.tolist()}
    return {
        "machine": machine_info(),
        "load_average": {"before": load_before, "after": load_average()},
        "threads": numba.get_num_threads(),
        "config": {**{k: x for k, x in cfg.items() if k != "numerics"},
                   "numerics": asdict(base), "quick": quick},
        "sweeps": sweeps,
    }


LABELS = {"scenes": "parameter sets in the batch", "elements": "elements per a_H",
          "steps": "time steps per t_H"}


def plot(data: dict, path: Path) -> None:
    """Three log-log panels (wall time in s against each swept quantity) with the fits."""
    use_agg()
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullLocator

    fig, axes = plt.subplots(1, 3, figsize=(11.0, 3.6))
    for ax, (name, sweep) in zip(axes, data["sweeps"].items()):
        x = np.asarray(sweep["x"], dtype=float)
        ax.loglog(x, sweep["median_seconds"], "o", label="median")
        for xi, ts in zip(x, sweep["seconds"]):
            ax.loglog([xi] * len(ts), ts, ".", color="grey", ms=3)
        fit = sweep["fit"]
        ax.loglog(x, fit["prefactor"] * x ** fit["exponent"], "-",
                  label=f"fit: exponent {fit['exponent']:.2f}")
        ax.set_xticks(x, [f"{xi:g}" for xi in x])
        ax.xaxis.set_minor_locator(NullLocator())
        ax.set_xlabel(LABELS[name])
        ax.set_title(", ".join(f"{k} = {x}" for k, x in sweep["fixed"].items()), fontsize=9)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("wall time of simulate_batch (s)")
    fig.suptitle(f"{data['threads']} numba threads; {data['machine']['cpu']}", fontsize=9)
    save_figure(fig, path)


def figures(data: dict) -> dict:
    """Wall time at the largest point of each sweep and the fitted exponents."""
    out = {}
    for name, sweep in data["sweeps"].items():
        out[f"{name}_{sweep['x'][-1]}_seconds"] = figure(sweep["median_seconds"][-1], "s",
                                                         samples=sweep["seconds"][-1])
    return out


def report(data: dict) -> str:
    """Per sweep: the fitted and local exponents and the median times."""
    lines = []
    for name, sweep in data["sweeps"].items():
        times = ", ".join(f"{x}: {t:.3g} s" for x, t in zip(sweep["x"], sweep["median_seconds"]))
        local = ", ".join(f"{p:.2f}" for p in sweep["local_exponents"])
        lines.append(f"{name:<9} exponent {sweep['fit']['exponent']:.3f} (local {local})   "
                     f"({times})")
    return "\n".join(lines)
