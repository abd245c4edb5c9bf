"""Continuum full-stick kernel: time per impact and error versus rtol.

``python -m benchmarks.continuum_maxwell [--quick] [--out DIR]``

For oblique Kelvin-Voigt, standard-solid and 3-arm Prony impacts at
``nu = 0.3`` and ``0.5`` (rotation on, solid sphere), runs
:func:`vimpact.kernels.continuum_maxwell.maxwell_stick_batch` on one thread
(``numba.set_num_threads(1)``) over a batch of identical rows for every
``rtol`` in ``1e-6 .. 1e-12``, and measures

- the time per impact (median over repeats of the batch's process CPU time /
  rows; the wall time is stored too, it counts waiting on a shared machine),
- the error of ``e_z``, ``beta_x`` and ``t_contact`` against the independent
  scipy reference (``tests/oracles/maxwell_continuum_scipy.py``, DOP853 at
  rtol 1e-12 with brentq for the edge; its own error is about 1e-11, so the
  errors below ~1e-10 are partly the reference's),
- the time to reach 1e-6, 1e-8 and 1e-10 on all three outputs (the fastest
  rtol whose largest error is below the target).

Writes ``continuum_maxwell[_quick].json`` and a PNG of error versus time.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.machine import (bench_main, figure, load_average, machine_info,  # noqa: E402
                                save_figure, time_samples, use_agg)

RTOLS = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12]
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


def _cpu_samples(fn, repeats: int) -> list[float]:
    """CPU times of this process over ``repeats`` calls of ``fn()``, s: on a
    shared machine (other jobs running) the wall time also counts the time
    the thread waits for a core; the process CPU time (one numba thread) does not."""
    out = []
    for _ in range(repeats):
        t0 = time.process_time()
        fn()
        out.append(time.process_time() - t0)
    return out


def run(quick: bool) -> dict:
    import numba

    from tests.oracles.maxwell_continuum_scipy import maxwell_continuum_reference
    from vimpact.kernels.continuum_maxwell import maxwell_stick_batch
    from vimpact.kernels.layout import N_OUT, OUT_STATUS, OUT_T_CONTACT, OUT_VC_END, OUT_VZ_END

    numba.set_num_threads(1)
    rows = 20 if quick else 200
    repeats = 3 if quick else 7
    rtols = [1e-6, 1e-8, 1e-10, 1e-12] if quick else RTOLS
    mu_t = 1.0 + 1.0 / THETA_RATIO
    max_steps = 1_000_000
    scenes = []
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
                    np.full(rows, _kappa(nu)), np.full(rows, mu_t), np.ones(rows, dtype=np.bool_))
            out = np.zeros((rows, N_OUT))
            per = []
            for rtol in rtols:
                maxwell_stick_batch(*args, rtol, max_steps, out)  # compile / warm
                assert np.all(out[:, OUT_STATUS] == 0), (name, nu, rtol)
                got = np.array([-out[0, OUT_VZ_END], -out[0, OUT_VC_END], out[0, OUT_T_CONTACT]])
                err = np.abs(got - want)
                samples = time_samples(lambda: maxwell_stick_batch(*args, rtol, max_steps, out),
                                       repeats)
                cpu = _cpu_samples(lambda: maxwell_stick_batch(*args, rtol, max_steps, out),
                                   repeats)
                per.append({"rtol": rtol, "us_per_impact": 1e6 * float(np.median(cpu)) / rows,
                            "wall_us_per_impact": 1e6 * float(np.median(samples)) / rows,
                            "steps": int(out[0, 6]), "err_e_z": float(err[0]),
                            "err_beta_x": float(err[1]), "err_t_contact": float(err[2]),
                            "err_max": float(err.max())})
            reach = {}
            for target in TARGETS:
                ok = [p["us_per_impact"] for p in per if p["err_max"] <= target]
                reach[f"{target:g}"] = min(ok) if ok else None
            scenes.append({"material": name, "nu": nu, "tau0": tau0, "g": g, "tau": tau,
                           "mu_t": mu_t, "reference_seconds": t_ref,
                           "reference": {"e_z": ref.e_z, "beta_x": ref.beta_x,
                                         "t_contact": ref.t_contact},
                           "per_rtol": per, "us_to_reach": reach})
            print(f"{name:15s} nu={nu}: " + "  ".join(
                f"{t}: {'n/a' if v is None else f'{v:.1f} us'}" for t, v in reach.items()))
    figures = {}
    for s in scenes:
        for t, v in s["us_to_reach"].items():
            figures[f"{s['material']}_nu{s['nu']}_us_to_{t}"] = figure(v, "us/impact")
    return {"machine": machine_info(), "load_average": load_average(), "quick": quick,
            "rows_per_batch": rows, "time": "process CPU time, one numba thread (wall time as wall_us_per_impact)",
            "repeats": repeats, "threads": 1, "scenes": scenes, "figures": figures}


def plot(data: dict, path: Path) -> None:
    use_agg()
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for s in data["scenes"]:
        t = [p["us_per_impact"] for p in s["per_rtol"]]
        e = [max(p["err_max"], 1e-16) for p in s["per_rtol"]]
        ax.loglog(t, e, "o-", label=f"{s['material']}, nu={s['nu']}")
    for target in TARGETS:
        ax.axhline(target, color="0.8", lw=0.8)
    ax.set_xlabel("CPU time per impact, us (one thread)")
    ax.set_ylabel("largest error of e_z, beta_x, t_contact/T")
    ax.set_title("continuum full stick: error vs time (rtol 1e-6 .. 1e-12)")
    ax.legend(fontsize=7)
    save_figure(fig, path)


def main(argv: list[str] | None = None) -> dict:
    return bench_main(__doc__, run, plot, "continuum_maxwell", argv=argv)


if __name__ == "__main__":
    main()
