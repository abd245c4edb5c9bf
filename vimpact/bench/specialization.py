"""What each compile-time effect of the element kernel buys (run time) and costs (compile time).

Run: ``vimpact bench specialization [--quick] [--out DIR]``; the full-size run
of the repository is ``python -m benchmarks.specialization`` (``benchmarks/results/``).

An element kernel (:func:`vimpact.kernels.elements.impact_kernel`) is a copy
of one impact body whose globals hold its effects (integrator, tangential
problem, memory, arms, dashpot, friction): numba reads them as constants and
drops the branches they switch off before typing. Each effect could instead be
a run-time flag: one kernel for both values, every branch kept. Per candidate
effect, the kernel with that one flag at run time (all others compiled in) is
timed against the kernel compiled for the rows' value, on the same packed rows
of two scene families (the effect on and off), in alternating rounds, one numba
thread, kernel time only (a serial loop over the rows, compiled once per
kernel); the ratio is that of the smallest times over the rounds (the least
disturbed by other load; the median of the per-round ratios is recorded too).
Both must give identical outputs. The full run also measures
the CPU time of compiling the one run-time-flag kernel against the two
specialized ones, each in a fresh process with an empty numba cache.

The impact body itself can read two effects from the row (``RUNTIME``):
friction (``mu``, ``inf`` sticks; the package does so where the tangential
memory is incremental) and the dashpot (``tau0 > 0``; the package does not: it
cost 3-13 % on a quiet machine); their candidates time that very body.
The other candidates are variants made here from the impact body's source,
with the named globals turned into locals read from a flag array. Nothing here
asserts a time.
"""

from __future__ import annotations

import ast
import functools
import inspect
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

from .machine import figure, load_average, machine_info, progress, save_figure, use_agg

TITLE = "element kernel: each effect at run time vs compiled in (run and compile time)"

CONFIGS = {"full": dict(rows=32, rounds=15, compile=True),
           "quick": dict(rows=3, rounds=1, compile=False)}

#: candidate effect -> (the global(s) made a run-time flag, the two scene families:
#: the effect on, then off)
CANDIDATES = {
    "friction": (("FRICTION",), ("kelvin_voigt oblique friction", "kelvin_voigt oblique stick")),
    "friction, arms": (("FRICTION",), ("prony oblique friction", "prony oblique stick")),
    "memory": (("MEMORY",), ("kelvin_voigt oblique seed", "kelvin_voigt oblique stick")),
    "arms": (("ARMS",), ("prony oblique stick", "kelvin_voigt oblique stick")),
    "dashpot": (("DASHPOT",), ("kelvin_voigt oblique stick", "elastic oblique stick")),
    "tangential": (("TANGENTIAL",), ("kelvin_voigt oblique stick", "kelvin_voigt normal")),
}
#: the candidates of the quick run (the package's own run-time flags)
QUICK = ("friction", "dashpot")
#: the effects the impact body can read from the row itself (its RUNTIME values)
PACKAGE_RUNTIME = ("FRICTION", "DASHPOT")
#: order of the flags in a variant's flag array
FLAGS = ("TANGENTIAL", "MEMORY", "INTEGRATOR", "ARMS", "DASHPOT", "FRICTION")


def _family(name: str, rows: int):
    """Packed inputs of ``rows`` scenes of family ``name``: (compiled effects, args)."""
    import vimpact as v
    from vimpact.engine.columns import scene_columns
    from vimpact.engine.pack import element_arrays
    from vimpact.engine.routing import route
    from vimpact.kernels import layout
    from vimpact.kernels.elements import kernel_effects

    from .overhead import scene_columns as kv_columns

    cols = kv_columns(rows, seed=3, oblique="oblique" in name)
    if "prony" in name:  # one Maxwell arm beside the dashpot
        cols["G_arm1_Pa"] = 2.0 * cols["G_inf_Pa"]
        cols["tau_arm1_s"] = 3.0 * cols["eta0_Pa_s"] / cols["G_inf_Pa"]
    if "elastic" in name:
        cols["eta0_Pa_s"] = np.zeros(rows)
    if "friction" not in name:
        cols.pop("mu", None)
    if "seed" in name:
        cols["tangential_memory"] = np.full(rows, "seed", dtype=object)
    numerics = v.Numerics.preset("fast").with_(continuum=False)
    sc = scene_columns(cols)
    r = route(sc, numerics)
    if len(r.paths) != 1 or r.paths[0].spec is None:
        raise ValueError(f"family {name!r}: its rows take {len(r.paths)} paths, must take one "
                         "element kernel")
    spec = r.paths[0].spec
    a = element_arrays(sc, numerics, spec)
    args = (a["tau0"], a["g"], a["tau"], a["n_arms"], a["kappa"], a["mu_t"], a["mu"], a["h"],
            a["n_elem"], a["dxi"], a["max_steps"], np.zeros((rows, 0, layout.N_REC)), 1)
    key = list(kernel_effects(spec))  # the specialized kernel of the family:
    key[4] = int(spec.dashpot)
    if key[5]:
        key[5] = int(spec.friction)
    return tuple(key), args


def _variant_source(runtime: tuple[str, ...]) -> str:
    """Source of the impact body with the globals ``runtime`` read from a ``flags`` argument."""
    from vimpact.kernels import elements

    src = textwrap.dedent(inspect.getsource(elements._impact))
    fn = ast.parse(src).body[0]
    if not isinstance(fn, ast.FunctionDef):
        raise TypeError("the impact body must be a function definition")
    lines = src.splitlines()
    head = lines[fn.lineno - 1]
    if not head.endswith("rec_every, out):"):
        raise ValueError(f"unexpected impact signature: {head!r}")
    lines[fn.lineno - 1] = head[:-2] + ", flags):"
    set_flags = [f"    {name} = flags[{FLAGS.index(name)}]"
                 + (" != 0" if name in ("TANGENTIAL", "ARMS", "DASHPOT") else "")
                 for name in runtime]
    if {"INTEGRATOR", "ARMS", "DASHPOT"} & set(runtime):  # the derived flags too
        set_flags += ["    PARTIAL = INTEGRATOR == VERLET", "    IMPLICIT = PARTIAL and ARMS",
                      "    NCORR = PARTIAL and ((DASHPOT == 1 if DASHPOT != RUNTIME"
                      " else tau0 > 0.0) or ARMS)"]
    after_doc = fn.body[0].end_lineno
    return "\n".join(lines[:after_doc] + set_flags + lines[after_doc:]) + "\n"


@functools.cache
def variant(key: tuple, runtime: tuple[str, ...] = ()):
    """Return ``(serial kernel, loop)`` of the compiled effects ``key``, ``runtime`` at run time.

    The serial kernel takes the arguments of :func:`vimpact.kernels.elements.impact_kernel`'s
    kernels and a trailing int64 ``flags`` array (values in :data:`FLAGS` order, read only
    for the names in ``runtime``); ``loop`` runs it over packed rows (the batch
    kernel's arguments and ``flags``), serially. Compiled on first use, not cached on disk.
    ``TANGENTIAL``, ``ARMS``, ``DASHPOT`` are read as ``flags[i] != 0``.
    """
    import numba

    from vimpact.kernels import elements

    tag = elements._tag(key) + "".join(f"_{n.lower()}R" for n in runtime)
    namespace = {**vars(elements), **elements._effects(key)}
    exec(compile(_variant_source(runtime), elements.__file__, "exec"), namespace)
    body = namespace["_impact"]
    body.__qualname__ = body.__name__ = f"bench_impact_{tag}"
    # the package's numba options (vimpact.kernels.jit) but for the on-disk cache
    kernel = numba.njit(error_model="numpy")(body)

    def loop(tau0, g, tau, n_arms, kappa, mu_t, mu, h, n_elem, dxi, max_steps, rec, rec_every, out,
             flags):
        for i in range(tau0.shape[0]):
            k = n_arms[i]
            _kernel(tau0[i], g[i, :k], tau[i, :k], kappa[i], mu_t[i], mu[i],  # type: ignore[name-defined] # noqa: F821
                    h[i], n_elem[i], dxi[i], max_steps[i], rec[i], rec_every, out[i], flags)

    import types

    loop = types.FunctionType(loop.__code__, {"_kernel": kernel}, f"bench_loop_{tag}")
    loop.__qualname__ = loop.__name__
    return kernel, numba.njit(error_model="numpy")(loop)


def _runtime_key(key: tuple, runtime: tuple[str, ...]) -> tuple:
    """Return the compiled effects of the kernel with ``runtime`` at run time (values ignored)."""
    k = list(key)
    if "FRICTION" in runtime:  # the package's own run-time friction (the row's mu)
        k[5] = -1
    if "DASHPOT" in runtime:  # ... and dashpot (the row's tau0)
        k[4] = -1
    if "MEMORY" in runtime:  # (a kernel with run-time memory has no friction code)
        k[1], k[2], k[5] = True, 0, 0
    if "TANGENTIAL" in runtime:
        k[1] = True
    if "ARMS" in runtime:
        k[3] = True
    return tuple(k)


def _source_flags(runtime: tuple[str, ...]) -> tuple[str, ...]:
    """Return the names of ``runtime`` that a variant reads from its flag array.

    The others are the package's own run-time effects (:data:`PACKAGE_RUNTIME`).
    """
    return tuple(n for n in runtime if n not in PACKAGE_RUNTIME)


def _flags(key: tuple) -> np.ndarray:
    """Return the flag array of a family's compiled effects (:data:`FLAGS` order)."""
    integrator, tangential, memory, arms, dashpot, friction = key
    return np.array([tangential, memory, integrator, arms, dashpot, friction], dtype=np.int64)


def _compile_cpu(candidate: str) -> dict:
    """In this process (fresh cache): CPU seconds to compile the candidate's kernels.

    The two specialized serial kernels of its families, and the one with the flag at run time.
    """
    from vimpact.kernels import layout

    runtime, families = CANDIDATES[candidate]
    out: dict = {}
    for which in ("specialized", "runtime"):
        total = 0.0
        for fam in families:
            key, args = _family(fam, 1)
            k = _runtime_key(key, runtime) if which == "runtime" else key
            kernel, _ = variant(k, _source_flags(runtime) if which == "runtime" else ())
            row = [a[0] for a in args[:11]]
            row[1], row[2] = row[1][:args[3][0]], row[2][:args[3][0]]
            t0 = time.process_time()
            kernel(*row[:3], *row[4:], np.zeros((0, layout.N_REC)), np.int64(1),
                   np.zeros(layout.N_OUT), _flags(key))
            total += time.process_time() - t0
        out[which] = total
    return out


_CHILD = """
import json, sys
from vimpact.bench.specialization import _compile_cpu
print(json.dumps(_compile_cpu(sys.argv[1])))
"""


def _compile_times(candidates) -> dict:
    """Compile CPU seconds per candidate, each in a fresh process with an empty numba cache."""
    out = {}
    with tempfile.TemporaryDirectory(prefix="vimpact_spec_") as tmp:
        for i, c in enumerate(candidates):
            env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / str(i))}
            r = subprocess.run([sys.executable, "-c", _CHILD, c], env=env, capture_output=True,
                               text=True, check=True)
            out[c] = json.loads(r.stdout.strip().splitlines()[-1])
    return out


def run(quick: bool = False) -> dict:
    """Run time of each candidate's kernels per family (and, full, the compile times)."""
    import numba

    from vimpact.kernels import layout

    cfg = CONFIGS["quick" if quick else "full"]
    candidates = QUICK if quick else tuple(CANDIDATES)
    start = time.perf_counter()
    data: dict = {"machine": machine_info(), "config": {**cfg, "quick": quick},
                  "load_average": {"before": load_average()}, "candidates": {}}
    all_threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        for cand in candidates:
            runtime, families = CANDIDATES[cand]
            data["candidates"][cand] = {"runtime_flags": list(runtime), "families": {}}
            for fam in families:
                progress(f"specialization: {cand}: {fam}", start)
                key, args = _family(fam, cfg["rows"])
                n = args[0].shape[0]
                flags = _flags(key)
                _, special = variant(key)
                rkey = _runtime_key(key, runtime)
                _, general = variant(rkey, _source_flags(runtime))
                o1, o2 = np.zeros((n, layout.N_OUT)), np.zeros((n, layout.N_OUT))
                special(*args, o1, flags)
                general(*args, o2, flags)
                ts, tg = [], []
                for _ in range(cfg["rounds"]):  # alternating, one round each
                    t0 = time.perf_counter()
                    special(*args, o1, flags)
                    ts.append(time.perf_counter() - t0)
                    t0 = time.perf_counter()
                    general(*args, o2, flags)
                    tg.append(time.perf_counter() - t0)
                ratios = [g / s for g, s in zip(tg, ts)]  # per round
                data["candidates"][cand]["families"][fam] = {
                    "specialized_effects": list(key), "runtime_effects": list(rkey), "rows": n,
                    "specialized_us_per_impact": min(ts) / n * 1e6,
                    "runtime_flag_us_per_impact": min(tg) / n * 1e6,
                    "runtime_over_specialized": min(tg) / min(ts),
                    "median_round_ratio": float(np.median(ratios)),
                    "round_ratio_min_max": [min(ratios), max(ratios)],
                    "specialized_samples_s": ts, "runtime_flag_samples_s": tg,
                    "identical_outputs": bool(np.array_equal(o1, o2, equal_nan=True)),
                }
    finally:
        numba.set_num_threads(all_threads)
    if cfg["compile"]:
        progress("specialization: compile times (fresh caches)", start)
        for cand, times in _compile_times(candidates).items():
            data["candidates"][cand]["compile_cpu_s"] = times
    data["load_average"]["after"] = load_average()
    return data


def figures(data: dict) -> dict:
    """Return the headline numbers of a specialization run."""
    out = {}
    for cand, c in data["candidates"].items():
        key = cand.replace(", ", "_").replace(" ", "_")
        for fam, f in c["families"].items():
            out[f"{key}__{fam.replace(' ', '_')}_runtime_over_specialized"] = figure(
                f["runtime_over_specialized"], "-")
        if "compile_cpu_s" in c:
            out[f"{key}__compile_cpu_runtime_over_two_specialized"] = figure(
                c["compile_cpu_s"]["runtime"] / c["compile_cpu_s"]["specialized"], "-")
    return out


def report(data: dict) -> str:
    """Return the run-time-flag over specialized times as a text table."""
    lines = [f"{'candidate':<16}{'family':<34}{'spec us':>10}{'flag us':>10}{'ratio':>8}"
             f"  identical"]
    for cand, c in data["candidates"].items():
        for fam, f in c["families"].items():
            lines.append(f"{cand:<16}{fam:<34}{f['specialized_us_per_impact']:>10.1f}"
                         f"{f['runtime_flag_us_per_impact']:>10.1f}"
                         f"{f['runtime_over_specialized']:>8.3f}  {f['identical_outputs']}")
        if "compile_cpu_s" in c:
            t = c["compile_cpu_s"]
            lines.append(f"{'':<16}compile CPU: two specialized {t['specialized']:.1f} s, "
                         f"one with the flag {t['runtime']:.1f} s")
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    """Draw the run-time-flag over specialized time of every candidate and family to ``path``."""
    use_agg()
    import matplotlib.pyplot as plt

    labels, ratios = [], []
    for cand, c in data["candidates"].items():
        for fam, f in c["families"].items():
            labels.append(f"{cand}: {fam}")
            ratios.append(f["runtime_over_specialized"])
    fig, ax = plt.subplots(figsize=(8.0, 0.4 * len(labels) + 1.2))
    y = np.arange(len(labels))
    ax.barh(y, ratios, color="tab:orange")
    ax.axvline(1.0, color="k", lw=1, ls=":")
    ax.set_yticks(y, labels, fontsize=7)
    ax.set_xlabel("kernel time, effect as a run-time flag / compiled in (1 thread)")
    fig.suptitle(data["machine"]["cpu"], fontsize=8)
    save_figure(fig, path)
