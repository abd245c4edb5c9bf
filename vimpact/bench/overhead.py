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

One impact (:func:`one_impact`; target: at most 100 us of Python outside the
kernel): the CPU time of one ``vimpact.simulate(scene)`` call on one thread,
minus the kernel's (wall) time, for an oblique and a normal-only Kelvin-Voigt
scene (continuum paths) and an oblique one with friction (element path), with
the engine as of :data:`BEFORE_COMMIT` timed in turns with the current one in
the same run (from a source checkout, which has that code in git) and its
results compared.

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
from typing import Any

import numba
import numpy as np

from .machine import (
    figure,
    load_average,
    machine_info,
    max_threads,
    package_at_commit,
    progress,
    save_figure,
    use_agg,
)

TITLE = "Python overhead per row outside the kernels (columnar simulate_batch) and KV rows/s"

#: targets: Python time per row outside the kernels, s; Kelvin-Voigt normal-only rows/s
TARGET_OVERHEAD_US_PER_ROW = 5.0
TARGET_KV_ROWS_PER_SECOND = 50_000.0
THREADS = 2

#: rows and repeats of each measurement; calls per sample and samples of one impact
CONFIGS = {
    "full": dict(kv_rows=100_000, kv_repeats=7, element_rows=10_000, element_repeats=5,
                 one_impact_calls=1000, one_impact_repeats=7),
    "quick": dict(kv_rows=100_000, kv_repeats=3, element_rows=1_000, element_repeats=3,
                  one_impact_calls=200, one_impact_repeats=3),
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
    """``repeats`` calls of ``simulate_batch(columns, numerics, timings=t)``.

    Per call ``total_s``, ``kernel_s``, overhead per row (us) and rows/s.
    """
    import vimpact as v

    rows = len(columns["nu"])
    total: list[float] = []
    kernel: list[float] = []
    frame = None
    for _ in range(repeats):
        t: dict = {}
        frame = v.simulate_batch(columns, numerics, timings=t)
        total.append(t["total_s"])
        kernel.append(t["kernel_s"])
    if frame is None:
        raise ValueError(f"repeats = {repeats!r} is not allowed: must be >= 1")
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


#: main before the one-row route of :func:`vimpact.simulate` (Python scalars instead of
#: one-element array arithmetic, no thread count set per impact, no reduction over an
#: empty arm column); 7dbf0d8 was the commit before the scalar unpack of the one row.
#: Its engine is timed side by side with the current one where the source is at hand
BEFORE_COMMIT = "c993144"
#: Python CPU time outside the kernel of one ``simulate()`` call, us
TARGET_ONE_IMPACT_US = 100.0


def _cpu_us(fn, calls: int) -> float:
    """Return the CPU time per call of ``fn()``, us.

    CPU time per call of ``fn()`` over ``calls`` calls, us (CPU time: robust
    against other processes on the machine).
    """
    t0 = time.process_time()
    for _ in range(calls):
        fn()
    return (time.process_time() - t0) / calls * 1e6


def _side_by_side(fns: dict, calls: int, repeats: int) -> dict[str, list[float]]:
    """Time functions in turns, CPU time per call in us.

    CPU time per call (us) of each function of ``fns``, ``repeats`` rounds of
    ``calls`` calls each, the functions taking turns within a round (so a change
    of load hits all alike); after one warm-up call each.
    """
    for fn in fns.values():
        fn()
    samples: dict[str, list[float]] = {name: [] for name in fns}
    for _ in range(repeats):
        for name, fn in fns.items():
            samples[name].append(_cpu_us(fn, calls))
    return samples


class _KernelsReplaced:
    """Replace every kernel by a copy of its output row.

    While active, every kernel the engines call (the continuum batch and
    single-impact kernels and each element batch and single-impact kernel, in
    the current and the :data:`BEFORE_COMMIT` engine's ``pack``) only copies
    ``row`` into its output: what is left of a ``simulate()`` call is the Python
    around the kernel. With ``row=None`` the real kernel runs once and its output
    row (and return value: the recorded rows of a single-impact kernel) is kept.
    """

    def __init__(self, packs: list, row: np.ndarray | None = None, returned=None):
        self.packs, self.row, self.returned = packs, row, returned
        self.saved: list = []

    def _wrap(self, real):
        def kernel(*args):
            if self.row is None:
                self.returned = real(*args)
                self.row = args[-1].copy()
            else:
                args[-1][:] = self.row  # every kernel takes ``out`` (its rows) last
            return self.returned
        return kernel

    def __enter__(self):
        from vimpact.kernels import continuum_kv, continuum_maxwell

        factories = ("element_kernel", "element_impact")  # one kernel per KernelSpec
        targets = ([(continuum_kv, name) for name in ("kv_normal_batch", "kv_normal_impact")]
                   + [(continuum_maxwell, name)
                      for name in ("maxwell_stick_batch", "maxwell_stick_impact")]
                   + [(pack, name) for pack in self.packs for name in factories
                      if hasattr(pack, name)])  # the older engine has no element_impact
        for owner, name in targets:
            real = getattr(owner, name)
            self.saved.append((owner, name, real))
            setattr(owner, name, (lambda spec, real=real: self._wrap(real(spec)))
                    if name in factories else self._wrap(real))
        return self

    def __exit__(self, *exc):
        for owner, name, value in reversed(self.saved):
            setattr(owner, name, value)
        self.saved.clear()




def one_impact(quick: bool = False) -> dict:
    """Measure the Python outside the kernel of one ``simulate()`` call.

    CPU time of one ``simulate()`` call on 1 numba thread, the kernel's share
    (``run_columns`` timings: wall time inside the kernel) and the Python outside
    it, for the README's oblique Kelvin-Voigt scene (full-stick continuum path), a
    normal-only one (Kelvin-Voigt continuum path) and an oblique one with friction
    (element path); with the engine as of :data:`BEFORE_COMMIT` side by side where
    available, whose results must be the same.
    """
    import vimpact as v
    from vimpact.engine import pack
    from vimpact.engine.columns import SceneColumns
    from vimpact.engine.routing import route
    from vimpact.engine.simulate import run_columns

    cfg = CONFIGS["quick" if quick else "full"]
    calls, repeats = cfg["one_impact_calls"], cfg["one_impact_repeats"]
    # the engine as of BEFORE_COMMIT (current kernels and model), if at hand
    old_engine = package_at_commit(BEFORE_COMMIT, "vimpact.engine")
    before = None if old_engine is None else old_engine.simulate.simulate
    packs = [pack] if old_engine is None else [pack, old_engine.pack]
    mat = v.Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5)
    scenes = {"oblique (README)": v.Scene(mat, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0),
              "normal only": v.Scene(mat, R=0.2, m=10.0, v_z0=10.0, tangential="none"),
              "friction (elements, fast)": v.Scene(mat, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0,
                                                   mu=0.3)}
    numerics = {"friction (elements, fast)": v.Numerics.preset("fast")}
    unavailable = None if old_engine is not None else "no source checkout with git at hand"
    if before is not None:
        try:  # the old engine on today's kernels and model: it may no longer fit them
            for name, scene in scenes.items():
                before(scene, numerics.get(name, v.Numerics()))
        except Exception as exc:  # any failure means: no side-by-side timing
            before, packs = None, [pack]
            unavailable = f"the engine as of {BEFORE_COMMIT} fails here: {exc!r}"
    all_threads = numba.get_num_threads()
    numba.set_num_threads(1)
    out: dict[str, Any] = {"before_commit": BEFORE_COMMIT if before else None,
                           "before_unavailable": unavailable, "calls": calls,
                           "repeats": repeats, "scenes": {}}
    try:
        for name, scene in scenes.items():
            num = numerics.get(name, v.Numerics())
            cols = SceneColumns.from_scenes([scene])
            run_columns(cols, num)  # load the kernel
            kernel = []
            for _ in range(repeats):
                t: dict = {}
                for _ in range(calls):
                    run_columns(cols, num, timings=t)
                kernel.append(t["kernel_s"] / calls * 1e6)
            kernel_us = min(kernel)
            result = v.simulate(scene, num)
            rec = {"path": result.path, "kernel_us": kernel_us}
            fns = {"now": lambda: v.simulate(scene, num)}
            if before is not None:
                fns["before"] = lambda: before(scene, num)
                old = before(scene, num)
                # on the fields both engines give (outputs added since are not compared)
                then, now = old.to_dict(), result.to_dict()
                rec["same_result_as_before"] = all(repr(then[k]) == repr(now[k])
                                                   for k in then if k in now)
                rec["fields_new_since_before"] = sorted(set(now) - set(then))
            samples = _side_by_side(fns, calls, repeats)  # with the kernel
            rec["simulate_us"], rec["simulate_us_samples"] = min(samples["now"]), samples["now"]
            with _KernelsReplaced(packs) as recorder:  # the real kernel's row
                v.simulate(scene, num)
            with _KernelsReplaced(packs, recorder.row, recorder.returned):
                outside = _side_by_side(fns, calls, repeats)
            rec["outside_kernel_us"] = min(outside["now"])
            rec["outside_kernel_us_samples"] = outside["now"]
            rec["from_scenes_us"] = min(_side_by_side(
                {"x": lambda: SceneColumns.from_scenes([scene])}, calls, repeats)["x"])
            rec["route_us"] = min(_side_by_side({"x": lambda: route(cols, num)}, calls,
                                                repeats)["x"])
            if before is not None:
                rec["before_simulate_us"] = min(samples["before"])
                rec["before_simulate_us_samples"] = samples["before"]
                rec["before_outside_kernel_us"] = min(outside["before"])
                rec["before_outside_kernel_us_samples"] = outside["before"]
                rec["before_over_now"] = rec["before_simulate_us"] / rec["simulate_us"]
                rec["outside_before_over_now"] = (rec["before_outside_kernel_us"]
                                                  / rec["outside_kernel_us"])
            out["scenes"][name] = rec
    finally:
        numba.set_num_threads(all_threads)
    out["target_outside_kernel_us"] = TARGET_ONE_IMPACT_US
    return out


def run(quick: bool = False) -> dict:
    """Measure both paths and one impact.

    Measure both paths; returns the JSON-ready record (``continuum``,
    ``elements``: see :func:`_measure`; ``targets`` and whether they are met).
    """
    import vimpact as v

    cfg = CONFIGS["quick" if quick else "full"]
    all_threads = max_threads()
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
    progress("overhead: one simulate() call", start)
    single = one_impact(quick)
    return {
        "machine": machine_info(),
        "load_average": {"before": load_before, "after": load_average()},
        "threads": threads,
        "config": {**cfg, "quick": quick, "continuum_numerics": "Numerics()",
                   "element_numerics": "fast"},
        "continuum": kv,
        "elements": el,
        "one_impact": single,
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
    for name, rec in data.get("one_impact", {}).get("scenes", {}).items():
        key = "one_impact_" + name.split(" ")[0]
        out[f"{key}_simulate_cpu_us"] = figure(rec["simulate_us"], "us",
                                               samples=rec["simulate_us_samples"])
        out[f"{key}_outside_kernel_us"] = figure(rec["outside_kernel_us"], "us")
        if "before_over_now" in rec:
            out[f"{key}_before_over_now"] = figure(rec["before_over_now"], "-", better="higher")
            out[f"{key}_outside_before_over_now"] = figure(rec["outside_before_over_now"], "-",
                                                           better="higher")
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
    one = data.get("one_impact", {})
    for name, rec in one.get("scenes", {}).items():
        line = (f"one simulate(), {name} [{rec['path']}]: {rec['simulate_us']:.0f} us CPU, "
                f"kernel {rec['kernel_us']:.0f} us, Python outside it "
                f"{rec['outside_kernel_us']:.0f} us (target "
                f"{one['target_outside_kernel_us']:.0f}; from_scenes "
                f"{rec['from_scenes_us']:.0f}, route {rec['route_us']:.0f})")
        if "before_over_now" in rec:
            line += (f"; at {one['before_commit']}, same run: {rec['before_simulate_us']:.0f} us,"
                     f" outside the kernel {rec['before_outside_kernel_us']:.0f} us "
                     f"({rec['outside_before_over_now']:.2f}x now; results "
                     f"{'identical' if rec['same_result_as_before'] else 'DIFFERENT'})")
        lines.append(line)
    t = data["targets"]
    lines.append(f"targets ({data['threads']} threads): overhead <= "
                 f"{t['overhead_us_per_row_max']:g} us/row: continuum "
                 f"{'met' if t['continuum_overhead_met'] else 'NOT met'}, elements "
                 f"{'met' if t['element_overhead_met'] else 'NOT met'}; Kelvin-Voigt >= "
                 f"{t['kv_rows_per_second_min']:g} rows/s: "
                 f"{'met' if t['kv_rows_per_second_met'] else 'NOT met'}")
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    """Draw the kernel and Python time per row and the throughput to ``path``.

    Left: time per row split into kernel and Python overhead, per path, with
    the overhead target; right: Kelvin-Voigt rows/s per repeat with the target.
    """
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
