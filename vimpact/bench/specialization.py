"""What compile-time specialization of the element kernel costs (compile time) and buys (run time).

Run: ``vimpact bench specialization [--quick] [--out DIR]``; the full-size run
of the repository is ``python -m benchmarks.specialization`` (``benchmarks/results/``).

The element kernel (:func:`vimpact.kernels.elements.element_kernel`) is
compiled once per :class:`~vimpact.kernels.elements.KernelSpec`: the scene's
effects (integrator, tangential problem, memory, arms, dashpot, friction) are
closure constants, and numba prunes the branches they switch off before it
types the code. The alternative is one kernel that takes the same effects as
run-time arguments (:func:`runtime_flags_kernel`, built here from the same
impact body): compiled once for every scene, but every branch stays in the
code. Both are timed on the same packed inputs (one numba thread, kernel time
only, the smallest of the repeats) for four scene families; the outputs must
be identical. The full run also measures the CPU time of compiling each
kernel, in a fresh process with an empty numba cache. Nothing here asserts a
time.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .machine import figure, load_average, machine_info, progress, save_figure, use_agg

TITLE = "element kernel: compile-time specialization vs run-time effect flags (run and compile time)"

CONFIGS = {"full": dict(rows=64, repeats=5, compile=True),
           "quick": dict(rows=4, repeats=1, compile=False)}
CASES = ("kelvin_voigt normal", "kelvin_voigt oblique friction", "prony oblique friction",
         "prony oblique stick")

_KERNEL = None


def runtime_flags_kernel():
    """Return the batch element kernel with its effects as run-time flags.

    The batch element kernel with the effects as run-time arguments
    ``(integrator, tangential, memory, arms, dashpot, friction, ...)`` followed
    by the arguments of :func:`~vimpact.kernels.elements.element_kernel`'s kernels.
    """
    global _KERNEL
    if _KERNEL is None:
        from numba import prange

        from vimpact.kernels.elements import _impact
        from vimpact.kernels.jit import jit

        @jit(parallel=True)
        def run(integrator, tangential, memory, arms, dashpot, friction, tau0, g, tau, n_arms,
                kappa, mu_t, mu, h, n_elem, dxi, max_steps, rec, rec_every, out):
            for i in prange(tau0.shape[0]):
                k = n_arms[i]
                _impact(tangential, memory, integrator, arms, dashpot, friction, tau0[i],
                        g[i, :k], tau[i, :k], kappa[i], mu_t[i], mu[i], h[i], n_elem[i], dxi[i],
                        max_steps[i], rec[i], rec_every, out[i])

        _KERNEL = run
    return _KERNEL


def _case(name: str, rows: int):
    """Packed inputs of ``rows`` scenes of family ``name``: (spec, flags, args)."""
    import vimpact as v
    from vimpact.engine.columns import scene_columns
    from vimpact.engine.pack import element_arrays
    from vimpact.engine.routing import route
    from vimpact.kernels import layout

    from .overhead import scene_columns as kv_columns

    oblique = "oblique" in name
    cols = kv_columns(rows, seed=3, oblique=oblique)
    if "prony" in name:  # one Maxwell arm beside the dashpot
        cols["G_arm1_Pa"] = 2.0 * cols["G_inf_Pa"]
        cols["tau_arm1_s"] = 3.0 * cols["eta0_Pa_s"] / cols["G_inf_Pa"]
    if "stick" in name:
        cols.pop("mu")
    numerics = v.Numerics.preset("fast").with_(continuum=False)
    sc = scene_columns(cols)
    r = route(sc, numerics)
    k = max(range(len(r.paths)), key=lambda j: int((r.group == j).sum()))
    spec = r.paths[k].spec
    if spec is None:
        raise ValueError("the columns' largest group runs on a continuum kernel, must be an "
                         "element kernel (continuum=False)")
    sub = sc.take(np.flatnonzero(r.group == k))
    a = element_arrays(sub, numerics, spec)
    args = (a["tau0"], a["g"], a["tau"], a["n_arms"], a["kappa"], a["mu_t"], a["mu"], a["h"],
            a["n_elem"], a["dxi"], a["max_steps"], np.zeros((len(sub), 0, layout.N_REC)), 1)
    flags = (int(spec.integrator), bool(spec.tangential), int(spec.memory), bool(spec.arms),
             bool(spec.dashpot), bool(spec.friction))
    return spec, flags, args, len(sub)


def _compile_cpu(case: str, which: str) -> float:
    """In this process (fresh cache).

    CPU seconds of the first call of ``which`` (``specialized`` or ``runtime``) on
    ``case``.
    """
    from vimpact.kernels import layout
    from vimpact.kernels.elements import element_kernel

    spec, flags, args, n = _case(case, 2)
    out = np.zeros((n, layout.N_OUT))
    t0 = time.process_time()
    if which == "specialized":
        element_kernel(spec)(*args, out)
    else:
        runtime_flags_kernel()(*flags, *args, out)
    return time.process_time() - t0


_CHILD = """
import json, sys
from vimpact.bench.specialization import _compile_cpu
print(json.dumps({c: _compile_cpu(c, sys.argv[1]) for c in sys.argv[2:]}))
"""


def _compile_times() -> dict:
    """CPU seconds to compile.

    Each case's specialized kernel, and the run-time-flag kernel (its first case pays; the
    others find it compiled), each in a fresh process with an empty numba cache.
    """
    out = {}
    with tempfile.TemporaryDirectory(prefix="vimpact_spec_") as tmp:
        for which in ("specialized", "runtime"):
            env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / which)}
            r = subprocess.run([sys.executable, "-c", _CHILD, which, *CASES], env=env,
                               capture_output=True, text=True, check=True)
            out[which] = json.loads(r.stdout.strip().splitlines()[-1])
    return out


def run(quick: bool = False) -> dict:
    """Run time of both kernels per case (and, full, the compile times)."""
    import numba

    from vimpact.kernels import layout
    from vimpact.kernels.elements import element_kernel

    cfg = CONFIGS["quick" if quick else "full"]
    start = time.perf_counter()
    data: dict = {"machine": machine_info(), "config": {**cfg, "quick": quick},
                  "load_average": {"before": load_average()}, "cases": {}}
    all_threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        for name in CASES:
            progress(f"specialization: {name}", start)
            spec, flags, args, n = _case(name, cfg["rows"])
            o1, o2 = np.zeros((n, layout.N_OUT)), np.zeros((n, layout.N_OUT))
            special = element_kernel(spec)
            general = runtime_flags_kernel()
            special(*args, o1)
            general(*flags, *args, o2)
            ts, tg = [], []
            for _ in range(cfg["repeats"]):
                t0 = time.perf_counter()
                special(*args, o1)
                ts.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                general(*flags, *args, o2)
                tg.append(time.perf_counter() - t0)
            data["cases"][name] = {
                "spec": spec._asdict(), "rows": n,
                "specialized_us_per_impact": min(ts) / n * 1e6,
                "runtime_flags_us_per_impact": min(tg) / n * 1e6,
                "runtime_over_specialized": min(tg) / min(ts),
                "specialized_samples_s": ts, "runtime_flags_samples_s": tg,
                "identical_outputs": bool(np.array_equal(o1, o2, equal_nan=True)),
            }
    finally:
        numba.set_num_threads(all_threads)
    if cfg["compile"]:
        progress("specialization: compile times (fresh caches)", start)
        data["compile_cpu_s"] = _compile_times()
    data["load_average"]["after"] = load_average()
    return data


def figures(data: dict) -> dict:
    """Return the headline numbers of a specialization run."""
    out = {}
    for name, c in data["cases"].items():
        key = name.replace(" ", "_")
        out[f"{key}_runtime_over_specialized"] = figure(c["runtime_over_specialized"], "-")
    for which, d in data.get("compile_cpu_s", {}).items():
        out[f"compile_cpu_{which}_total_s"] = figure(sum(d.values()), "s")
    return out


def report(data: dict) -> str:
    """Return the specialized over run-time-flag times as a text table."""
    lines = [f"{'case':<32}{'spec us':>10}{'runtime us':>12}{'ratio':>8}  identical"]
    for name, c in data["cases"].items():
        lines.append(f"{name:<32}{c['specialized_us_per_impact']:>10.1f}"
                     f"{c['runtime_flags_us_per_impact']:>12.1f}"
                     f"{c['runtime_over_specialized']:>8.2f}  {c['identical_outputs']}")
    for which, d in data.get("compile_cpu_s", {}).items():
        lines.append(f"compile CPU s, {which}: " + ", ".join(f"{k} {v:.1f}" for k, v in d.items())
                     + f" (total {sum(d.values()):.1f})")
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    """Draw the time per row of both kernels to ``path``."""
    use_agg()
    import matplotlib.pyplot as plt

    names = list(data["cases"])
    fig, ax = plt.subplots(figsize=(8.0, 3.4))
    y = np.arange(len(names))
    ax.barh(y, [data["cases"][n]["runtime_over_specialized"] for n in names], color="tab:orange")
    ax.axvline(1.0, color="k", lw=1, ls=":")
    ax.set_yticks(y, names)
    ax.set_xlabel("kernel time, run-time effect flags / specialized kernel (1 thread)")
    fig.suptitle(data["machine"]["cpu"], fontsize=8)
    save_figure(fig, path)
