"""Continuum full-stick kernel: time per impact to a target error, before and after.

``vimpact bench continuum_maxwell [--quick] [--out DIR]``; from a source checkout
``python -m benchmarks.continuum_maxwell [--quick] [--out DIR]`` writes ``benchmarks/results/``

For oblique Kelvin-Voigt, standard-solid and 3-arm Prony impacts at
``nu = 0.3`` and ``0.5`` (rotation on, solid sphere), runs
:func:`vimpact.kernels.continuum_maxwell.maxwell_stick_batch` on one thread
(``numba.set_num_threads(1)``) over a batch of identical rows for every
``rtol`` of a half-decade ladder ``1e-6 .. 1e-12``, and measures

- the time per impact (median over repeats of the batch's process CPU time /
  rows; the wall time is stored too, it counts waiting on a shared machine),
- the error of ``e_z``, ``beta_x`` and ``t_contact`` against the independent
  scipy reference (:mod:`vimpact.reference.continuum_scipy`, DOP853 at
  rtol 1e-12 with brentq for the edge; its own error is about 1e-11, so the
  errors below ~1e-10 are partly the reference's),
- the time to reach 1e-6, 1e-8 and 1e-10 on all three outputs (the fastest
  rtol of the ladder whose largest error is below the target).

Before and after, side by side: the full run also builds the kernel as it was
at commit :data:`BEFORE_COMMIT` (``git show`` into a module under the
temporary folder, compiled once and cached there) and times both kernels in
turn within every repeat, so that a busy machine slows both alike; the ratio
``before / after`` is reported per rtol (the cost at equal rtol; the two kernels'
errors differ, the current one controls its steps at ``rtol / (1 + sum g_i)``)
and, the fair comparison, the time of each to reach every target. ``--quick`` times the current
kernel only (the old one would have to be compiled first, minutes); so does an
installed package (no repository to take the old kernel from).

Writes ``continuum_maxwell[_quick].json`` and a PNG of error versus time.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from vimpact.bench.machine import (
    figure,
    load_average,
    machine_info,
    module_at_commit,
    save_figure,
    use_agg,
)

TITLE = "Continuum full-stick kernel: time per impact to 1e-6/1e-8/1e-10, before vs after"

#: the continuum kernel before arms of any relaxation time (it integrated the arms
#: as Runge-Kutta components, which limited its steps to the fastest arm's time)
BEFORE_COMMIT = "54d8eb1"
KERNEL_PATH = "vimpact/kernels/continuum_maxwell.py"

RTOLS = [10.0 ** (-k / 2.0) for k in range(12, 25)]  # 1e-6 .. 1e-12, half decades
RTOLS_QUICK = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]
TARGETS = [1e-6, 1e-8, 1e-10]
THETA_RATIO = 0.4  # solid sphere
Q1_PER_TAU = (15.0 / 32.0) ** 0.5

# (name, tau0, g, tau): Q1 = 0.3 throughout (tau_v = Q1 / sqrt(15/32))
_TV = 0.3 / Q1_PER_TAU
MATERIALS = [
    ("kelvin_voigt", _TV, [], []),
    ("standard_solid", 0.0, [1.0], [_TV]),  # Q2 = 1
    ("prony3", 0.0, [2.0, 0.5, 0.3], [0.05, 0.5, 3.0]),
]
NUS = [0.3, 0.5]


def _kappa(nu):
    return 2.0 * (1.0 - nu) / (2.0 - nu)


def kernel_before():
    """Return the batch kernel as of :data:`BEFORE_COMMIT`.

    ``None`` without git or outside a source checkout.
    """
    module = module_at_commit(BEFORE_COMMIT, KERNEL_PATH)
    return None if module is None else module.maxwell_stick_batch


def _reach(per: list[dict], key: str) -> dict:
    """Fastest time (``key``) over the rtols whose largest error meets each target."""
    out = {}
    for target in TARGETS:
        ok = [(p[key], p["rtol"]) for p in per if p["err_max"] <= target]
        best = min(ok) if ok else None
        out[f"{target:g}"] = None if best is None else {"us": best[0], "rtol": best[1]}
    return out


def run(quick: bool) -> dict:
    """Measure time per impact and error against the scipy reference per rtol (module docstring)."""
    import numba

    from vimpact.kernels.continuum_maxwell import maxwell_stick_batch
    from vimpact.kernels.layout import (
        N_OUT,
        OUT_STATUS,
        OUT_STEPS,
        OUT_T_CONTACT,
        OUT_VC_END,
        OUT_VZ_END,
    )
    from vimpact.reference.continuum_scipy import maxwell_continuum_reference

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    rows = 10 if quick else 200
    repeats = 3 if quick else 7
    rtols = RTOLS_QUICK if quick else RTOLS
    before = None if quick else kernel_before()
    kernels = {"after": maxwell_stick_batch}
    if before is not None:
        kernels["before"] = before
    mu_t = 1.0 + 1.0 / THETA_RATIO
    max_steps = 1_000_000
    scenes = []
    try:
        for name, tau0, g, tau in MATERIALS:
            for nu in NUS:
                t0 = time.perf_counter()
                ref = maxwell_continuum_reference(tau0, g, tau, _kappa(nu), mu_t)
                t_ref = time.perf_counter() - t0
                want = np.array([ref.e_z, ref.beta_x, ref.t_contact])
                k = max(len(g), 1)
                ga = np.zeros((rows, k))
                ta = np.zeros((rows, k))
                ga[:, :len(g)] = g
                ta[:, :len(tau)] = tau
                args = (np.full(rows, tau0), ga, ta, np.full(rows, len(g), dtype=np.int64),
                        np.full(rows, _kappa(nu)), np.full(rows, mu_t),
                        np.ones(rows, dtype=np.bool_))
                outs = {kn: np.zeros((rows, N_OUT)) for kn in kernels}
                per: dict[str, list[dict]] = {kn: [] for kn in kernels}
                for rtol in rtols:
                    cpu: dict[str, list[float]] = {kn: [] for kn in kernels}
                    wall: dict[str, list[float]] = {kn: [] for kn in kernels}
                    for kn, fn in kernels.items():  # compile / warm
                        fn(*args, rtol, max_steps, outs[kn])
                        assert np.all(outs[kn][:, OUT_STATUS] == 0), (kn, name, nu, rtol)
                    for _ in range(repeats):
                        for kn, fn in kernels.items():  # in turn: load hits both alike
                            w0 = time.perf_counter()
                            c0 = time.process_time()
                            fn(*args, rtol, max_steps, outs[kn])
                            cpu[kn].append(time.process_time() - c0)
                            wall[kn].append(time.perf_counter() - w0)
                    for kn in kernels:
                        o = outs[kn][0]
                        got = np.array([-o[OUT_VZ_END], -o[OUT_VC_END], o[OUT_T_CONTACT]])
                        err = np.abs(got - want)
                        us = 1e6 * float(np.median(cpu[kn])) / rows
                        per[kn].append({
                            "rtol": rtol, "us_per_impact": us,
                            "wall_us_per_impact": 1e6 * float(np.median(wall[kn])) / rows,
                            "steps": int(o[OUT_STEPS]), "us_per_step": us / o[OUT_STEPS],
                            "err_e_z": float(err[0]), "err_beta_x": float(err[1]),
                            "err_t_contact": float(err[2]), "err_max": float(err.max())})
                scene = {"material": name, "nu": nu, "tau0": tau0, "g": g, "tau": tau,
                         "mu_t": mu_t, "reference_seconds": t_ref,
                         "reference": {"e_z": ref.e_z, "beta_x": ref.beta_x,
                                       "t_contact": ref.t_contact},
                         "per_rtol": per["after"], "us_to_reach": _reach(per["after"],
                                                                          "us_per_impact")}
                if "before" in kernels:
                    pb = per["before"]
                    scene["before"] = {"per_rtol": pb,
                                       "us_to_reach": _reach(pb, "us_per_impact")}
                    scene["same_outputs"] = bool(all(
                        a["err_max"] == b["err_max"] and a["steps"] == b["steps"]
                        for a, b in zip(per["after"], pb)))
                    scene["ratio_per_rtol"] = [b["us_per_impact"] / a["us_per_impact"]
                                               for a, b in zip(per["after"], pb)]
                scenes.append(scene)
                print(_scene_line(scene), flush=True)
    finally:
        numba.set_num_threads(threads)
    data = {"machine": machine_info(), "load_average": load_average(), "quick": quick,
            "rows_per_batch": rows, "repeats": repeats, "threads": 1,
            "time": "process CPU time, one numba thread, kernels timed in turn "
                    "(wall time as wall_us_per_impact)",
            "before_commit": BEFORE_COMMIT if "before" in kernels else None,
            "rtols": rtols, "scenes": scenes}
    data["figures"] = figures(data)
    return data


def _fmt(r):
    return "n/a" if r is None else f"{r['us']:.1f} us (rtol {r['rtol']:.0e})"


def _scene_line(s: dict) -> str:
    line = f"{s['material']:15s} nu={s['nu']}: " + "  ".join(
        f"{t}: {_fmt(r)}" for t, r in s["us_to_reach"].items())
    if "before" in s:
        line += "\n" + " " * 17 + "before: " + "  ".join(
            f"{t}: {_fmt(r)}" for t, r in s["before"]["us_to_reach"].items())
        line += f"\n{'':17s}before/after at equal rtol: median {np.median(s['ratio_per_rtol']):.2f}x"
    return line


def report(data: dict) -> str:
    """Return one block of text per scene: the time to reach each target."""
    return "\n".join(_scene_line(s) for s in data["scenes"])


def figures(data: dict) -> dict:
    """Return the headline figures.

    Time per impact to reach each target (after), and before/after ratios
    (median over the rtol ladder, at equal rtol).
    """
    out = {}
    for s in data["scenes"]:
        key = f"{s['material']}_nu{s['nu']}"
        for t, r in s["us_to_reach"].items():
            out[f"{key}_us_to_{t}"] = figure(None if r is None else r["us"], "us/impact")
            if "before" in s:
                rb = s["before"]["us_to_reach"].get(t)
                out[f"{key}_before_us_to_{t}"] = figure(None if rb is None else rb["us"],
                                                        "us/impact")
        if "ratio_per_rtol" in s:
            out[f"{key}_before_over_after"] = figure(float(np.median(s["ratio_per_rtol"])), "-",
                                                     better="higher")
    return out


def plot(data: dict, path: Path) -> None:
    """Write the chart of error against CPU time per impact to ``path``."""
    use_agg()
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, s in enumerate(data["scenes"]):
        c = colors[i % len(colors)]
        t = [p["us_per_impact"] for p in s["per_rtol"]]
        e = [max(p["err_max"], 1e-16) for p in s["per_rtol"]]
        ax.loglog(t, e, "o-", color=c, ms=3, label=f"{s['material']}, nu={s['nu']}")
        if "before" in s:
            tb = [p["us_per_impact"] for p in s["before"]["per_rtol"]]
            eb = [max(p["err_max"], 1e-16) for p in s["before"]["per_rtol"]]
            ax.loglog(tb, eb, "x:", color=c, ms=3, lw=0.8)
    for target in TARGETS:
        ax.axhline(target, color="0.8", lw=0.8)
    ax.set_xlabel("CPU time per impact, us (one thread)")
    ax.set_ylabel("largest error of e_z, beta_x, t_contact/T")
    title = "continuum full stick: error vs time (rtol 1e-6 .. 1e-12)"
    if data.get("before_commit"):
        title += f"\nsolid: now, dotted: before ({data['before_commit'][:7]})"
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    save_figure(fig, path)

