"""Accuracy and cost of the default numerics; the thesis's table 4.1.

Run: ``python -m benchmarks.default_accuracy [--quick]``. Writes
``benchmarks/results/default_accuracy.json`` and ``default_accuracy.png``.

- e_z error of each preset against the Kelvin-Voigt continuum solution
  (PHYSICS.md section 5, solved to 1e-12), for Q1 from 1e-3 to 10, nu = 0.5;
- e_x error against a converged element run (8x the default steps and
  elements; its own distance to a 2x finer run is reported as ``ref_spread``);
- wall time per impact (single impact, median of repeats) and the batch
  kernel's time per impact on 1 and on all threads, measured side by side;
- explicit Euler on the elastic impact at 500 ... 10000 steps against the
  thesis's table 4.1.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numba
import numpy as np

import vimpact as v
from vimpact.analytic import kelvin_voigt_continuum

from .machine import machine_info

RESULTS = Path(__file__).parent / "results"
THESIS_TABLE_4_1 = {500: 1.1254, 1000: 0.5608, 5000: 0.1119, 10000: 0.0559}  # percent


def _median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def run(quick: bool = False) -> dict:
    q1s = np.geomspace(1e-3, 10.0, 4 if quick else 9)
    scenes = [v.Scene.from_dimensionless(float(q), 0.5) for q in q1s]
    exact = np.array([kelvin_voigt_continuum(float(q)).e_z for q in q1s])
    base = v.Numerics()
    ref_n = base.with_(steps=base.steps * (2 if quick else 8),
                       elements=base.elements * (2 if quick else 8))
    ref = v.simulate_batch(scenes, ref_n)
    finer = v.simulate_batch(scenes, ref_n.with_(steps=ref_n.steps * 2,
                                                 elements=ref_n.elements * 2))
    out = {"machine": machine_info(), "q1": q1s.tolist(), "nu": 0.5,
           "e_z_exact": exact.tolist(), "e_x_reference": ref.e_x.tolist(),
           "e_x_ref_spread": float(np.max(np.abs(ref.e_x - finer.e_x))), "presets": {}}
    for name in ("fast", "default"):
        n = v.Numerics.preset(name)
        df = v.simulate_batch(scenes, n)
        v.simulate(scenes[0], n)  # compile outside the timing
        t_single = [_median_time(lambda s=s: v.simulate(s, n), 2 if quick else 5) for s in scenes]
        out["presets"][name] = {
            "steps": n.steps, "elements": n.elements, "integrator": n.integrator,
            "e_z_error": np.abs(df.e_z - exact).tolist(),
            "e_x_error": np.abs(df.e_x - ref.e_x).tolist(),
            "seconds_per_impact": t_single,
        }
    # batch kernel, 1 thread vs all threads, side by side
    batch = [v.Scene.from_dimensionless(float(q), 0.5) for q in
             np.geomspace(1e-3, 10.0, 8 if quick else 64)]
    v.simulate_batch(batch[:2])
    threads = {}
    for nt in sorted({1, numba.config.NUMBA_NUM_THREADS}):
        numba.set_num_threads(nt)
        threads[str(nt)] = _median_time(lambda: v.simulate_batch(batch), 1 if quick else 3) / len(batch)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    out["batch_seconds_per_impact"] = threads
    # thesis table 4.1: explicit Euler, elastic impact, rebound-speed deviation in percent
    elastic = v.Scene(v.Material.elastic(nu=0.5, E=5e10), R=0.2, m=10.0, v_z0=10.0)
    out["table_4_1"] = {
        str(n): {"vimpact_percent": 100 * abs(v.simulate(
            elastic, v.Numerics(integrator="euler", steps=n, elements=500, continuum=False)).e_z - 1),
                 "thesis_percent": pct}
        for n, pct in THESIS_TABLE_4_1.items()}
    return out


def plot(data: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for name, p in data["presets"].items():
        ax.loglog(data["q1"], np.maximum(p["e_z_error"], 1e-12), "o-",
                  label=f"{name}: e_z vs continuum")
        ax.loglog(data["q1"], np.maximum(p["e_x_error"], 1e-12), "s--",
                  label=f"{name}: e_x vs converged run")
    ax.axhline(1e-4, color="grey", lw=0.8)
    ax.set_xlabel("Q1 (dimensionless)")
    ax.set_ylabel("absolute error (dimensionless)")
    ax.set_title("Kelvin-Voigt, nu = 0.5: accuracy of the presets")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny configuration (CI)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="results folder")
    args = parser.parse_args()
    data = run(args.quick)
    print(json.dumps(data["machine"]))
    args.out.mkdir(parents=True, exist_ok=True)
    stem = "default_accuracy_quick" if args.quick else "default_accuracy"
    (args.out / f"{stem}.json").write_text(json.dumps(data, indent=1))
    plot(data, args.out / f"{stem}.png")
    for name, p in data["presets"].items():
        print(f"{name}: max e_z error {max(p['e_z_error']):.2e}, max e_x error "
              f"{max(p['e_x_error']):.2e}, median s/impact {np.median(p['seconds_per_impact']):.4f}")
    print("batch s/impact by threads:", data["batch_seconds_per_impact"])
    print("table 4.1 (percent):", {k: round(x["vimpact_percent"], 4) for k, x in data["table_4_1"].items()})


if __name__ == "__main__":
    main()
