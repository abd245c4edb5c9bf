"""One versus two numba threads for a short parallel launch, per threading layer, on a busy machine.

Run: ``vimpact bench threads [--quick] [--out DIR]``; the full-size run of
the repository is ``python -m benchmarks.threads`` (``benchmarks/results/``).

A sweep chunk on the Kelvin-Voigt continuum path is one parallel launch of
``kv_normal_batch`` over 64 rows (some 0.3 ms of work). Each configuration
runs in its own process (numba picks its threading layer once per process):
TBB, OpenMP with the package's ``OMP_WAIT_POLICY=PASSIVE``
(:mod:`vimpact.kernels.threads`), OpenMP with its own default wait policy
(threads spin after a region), the workqueue layer, and the package default
(what numba picks here with the package's settings). Each is timed with 1
and 2 threads (mean wall time of a launch: a spinning thread that lost its
core shows in the tail, which a sweep of many launches pays; medians and
90th percentiles are stored too), first on the machine as it is,
then with one busy-looping process per core started by the benchmark. The
figures are the ratios 2 threads / 1 thread (above 1: the second thread
costs time). A layer that numba cannot load here is reported as missing.
Nothing here asserts a time.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from .machine import figure, load_average, machine_info, max_threads, progress, save_figure, use_agg

TITLE = "1 vs 2 numba threads for a 64-row launch per threading layer, quiet and busy"

ROWS = 64
#: name -> environment of the probe process (None: remove the variable)
CONFIGS: dict[str, dict[str, str | None]] = {
    "package default": {},
    "tbb": {"NUMBA_THREADING_LAYER": "tbb"},
    "omp passive": {"NUMBA_THREADING_LAYER": "omp", "OMP_WAIT_POLICY": "PASSIVE"},
    "omp spinning (its default)": {"NUMBA_THREADING_LAYER": "omp", "OMP_WAIT_POLICY": None},
    "workqueue": {"NUMBA_THREADING_LAYER": "workqueue"},
}
REPEATS = {"full": 300, "quick": 60}

_PROBE = """
import json, os, sys, time
import vimpact  # sets the package's thread environment
if sys.argv[2] == "unset":
    os.environ.pop("OMP_WAIT_POLICY", None)  # before numba loads the layer
from vimpact.bench.threads import probe
print(json.dumps(probe(int(sys.argv[1]))))
"""


def probe(repeats: int) -> dict:
    """Time a ``kv_normal_batch`` launch with 1 and with 2 threads.

    In this process: mean (what a sweep of many launches pays), median and
    90th percentile wall time (s) of a ``ROWS``-row ``kv_normal_batch`` launch
    with 1 and with 2 threads, and the layer numba took.
    """
    import numba

    from vimpact.kernels import layout
    from vimpact.kernels.continuum_kv import kv_normal_batch

    tau0 = np.linspace(0.01, 1.0, ROWS)
    out = np.zeros((ROWS, layout.N_OUT))
    kv_normal_batch(tau0, 1e-8, 100_000, out)  # compile or load, start the threads
    res: dict[str, Any] = {"layer": numba.threading_layer()}
    for nt in (1, 2):
        numba.set_num_threads(min(nt, max_threads()))
        kv_normal_batch(tau0, 1e-8, 100_000, out)
        ts = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            kv_normal_batch(tau0, 1e-8, 100_000, out)
            ts.append(time.perf_counter() - t0)
        res[f"threads_{nt}_s"] = float(np.mean(ts))
        res[f"threads_{nt}_median_s"] = float(np.median(ts))
        res[f"threads_{nt}_p90_s"] = float(np.percentile(ts, 90))
    res["ratio_2_to_1"] = res["threads_2_s"] / res["threads_1_s"]
    return res


def _run_config(env_changes: dict, repeats: int) -> dict:
    env = dict(os.environ)
    env["NUMBA_NUM_THREADS"] = "2"
    unset = "keep"
    for key, value in env_changes.items():
        if value is None:
            env.pop(key, None)
            unset = "unset"
        else:
            env[key] = value
    if "OMP_WAIT_POLICY" not in env_changes:
        env.pop("OMP_WAIT_POLICY", None)  # what the package sets, not the caller's shell
    r = subprocess.run([sys.executable, "-c", _PROBE, str(repeats), unset], env=env,
                       capture_output=True, text=True)
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["?"])[-1]
        return {"missing": last[:200]}
    return json.loads(r.stdout.strip().splitlines()[-1])


def _spinners(n: int) -> list[subprocess.Popen]:
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]


def run(quick: bool = False) -> dict:
    """Every configuration, on the machine as it is and with one spinning process per core."""
    repeats = REPEATS["quick" if quick else "full"]
    start = time.perf_counter()
    data: dict = {"machine": machine_info(), "rows": ROWS, "repeats": repeats,
                  "load_average": {"before": load_average()}, "as_is": {}, "busy": {}}
    for name, env in CONFIGS.items():
        progress(f"threads: {name}, machine as it is", start)
        data["as_is"][name] = _run_config(env, repeats)
    spin = _spinners(os.cpu_count() or 2)
    try:
        time.sleep(1.0)
        data["load_average"]["busy"] = load_average()
        for name, env in CONFIGS.items():
            progress(f"threads: {name}, busy machine", start)
            data["busy"][name] = _run_config(env, repeats)
    finally:
        for p in spin:
            p.kill()
            p.wait()
    data["load_average"]["after"] = load_average()
    return data


def figures(data: dict) -> dict:
    """2-thread / 1-thread time of a 64-row launch per configuration and load."""
    out = {}
    for load in ("as_is", "busy"):
        for name, d in data[load].items():
            if "ratio_2_to_1" in d:
                key = f"{load}_{name.split(' ')[0]}_{'_'.join(name.split(' ')[1:2])}".rstrip("_")
                out[f"{key}_2_over_1_threads"] = figure(d["ratio_2_to_1"], "-")
    return out


def report(data: dict) -> str:
    """Return the per-configuration launch times as a text table."""
    lines = [f"{ROWS}-row kv_normal_batch launch, mean of {data['repeats']} (median in brackets)"]
    lines.append(f"{'configuration':<28}{'load':<7}{'layer':<11}{'1 thread ms':>12}"
                 f"{'2 threads ms':>13}{'2/1':>8}")
    for load in ("as_is", "busy"):
        for name, d in data[load].items():
            if "missing" in d:
                lines.append(f"{name:<28}{load:<7}missing: {d['missing']}")
                continue
            lines.append(f"{name:<28}{load:<7}{d['layer']:<11}{1e3 * d['threads_1_s']:>12.3f}"
                         f"{1e3 * d['threads_2_s']:>13.3f}{d['ratio_2_to_1']:>8.2f}"
                         f"  ({1e3 * d['threads_1_median_s']:.3f} / "
                         f"{1e3 * d['threads_2_median_s']:.3f} ms)")
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    """Bars: 2-thread / 1-thread time per configuration, as is and busy."""
    use_agg()
    import matplotlib.pyplot as plt

    names = list(CONFIGS)
    fig, ax = plt.subplots(figsize=(8.0, 3.6))
    y = np.arange(len(names))
    for k, (load, color) in enumerate((("as_is", "tab:blue"), ("busy", "tab:red"))):
        vals = [data[load].get(n, {}).get("ratio_2_to_1", np.nan) for n in names]
        ax.barh(y + (0.2 if k == 0 else -0.2), vals, 0.4, color=color,
                label="machine as it is" if load == "as_is" else "one busy process per core")
    ax.axvline(1.0, color="k", lw=1, ls=":")
    ax.set_xscale("log")
    ax.set_yticks(y, names)
    ax.set_xlabel(f"wall time, 2 threads / 1 thread ({ROWS}-row launch)")
    ax.legend(fontsize=7)
    fig.suptitle(data["machine"]["cpu"], fontsize=8)
    save_figure(fig, path)
