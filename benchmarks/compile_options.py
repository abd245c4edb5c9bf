"""LLVM optimisation level (``NUMBA_OPT``) against cold compile and run time of the kernels.

``python -m benchmarks.compile_options [--quick] [--out DIR]`` writes
``benchmarks/results/compile_options.json`` and ``compile_options.png``.

Each level runs in a fresh process with a new empty ``NUMBA_CACHE_DIR`` (numba
reads ``NUMBA_OPT`` when it loads): the CPU seconds (user + system of that
process) of the first call of the continuum impact kernel
(:func:`vimpact.kernels.continuum_maxwell.maxwell_stick_impact`: compile) and
of the first friction ``simulate()`` (element kernel, Kelvin-Voigt, ``mu =
0.3``: compile), then the CPU time per impact on one thread, best of
``REPEATS``: Kelvin-Voigt normal and oblique (full stick), a standard solid,
20 Prony arms (continuum kernel, called from Python per impact), and the
friction scene (``simulate()``, element kernel). The outputs of every level
are compared with those of the default level (3). CPU time, not wall: the
machine is shared. Nothing here asserts a time.
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

from .machine import bench_main, load_average, machine_info, progress, save_figure, use_agg

LEVELS = {"full": (3, 2, 1, 0), "quick": (3,)}
REPEATS = 9
SCENES = ("kv_normal", "kv_oblique", "sls", "prony20")


def _child() -> dict:
    """One level (this process's ``NUMBA_OPT``): compile and run CPU times."""
    import numba

    from vimpact.engine.simulate import simulate
    from vimpact.kernels.continuum_maxwell import maxwell_stick_impact
    from vimpact.kernels.layout import N_OUT, N_REC
    from vimpact.model.scene import Scene

    numba.set_num_threads(1)
    rng = np.random.default_rng(1)
    scenes = {
        "kv_normal": (0.1, np.zeros(0), np.zeros(0), False),
        "kv_oblique": (0.1, np.zeros(0), np.zeros(0), True),
        "sls": (0.0, np.array([1.5]), np.array([0.5]), True),
        "prony20": (0.0, rng.uniform(0.05, 0.3, 20), 10.0 ** rng.uniform(-3.0, 2.0, 20), True),
    }
    kappa, mu_t, rtol = 0.8, 3.5, 1e-6
    no_rec = np.zeros((0, N_REC))
    out = np.zeros(N_OUT)
    res: dict = {"outputs": {}}
    c0 = time.process_time()
    maxwell_stick_impact(0.1, np.zeros(0), np.zeros(0), kappa, mu_t, True, rtol, 100_000, no_rec,
                         1, out)
    res["compile_continuum_cpu_s"] = time.process_time() - c0
    for name, (tau0, g, tau, tang) in scenes.items():
        n = 20 if name == "prony20" else 200
        best = np.inf
        for _ in range(REPEATS):
            t0 = time.process_time()
            for _ in range(n):
                maxwell_stick_impact(tau0, g, tau, kappa, mu_t, tang, rtol, 1_000_000, no_rec, 1,
                                     out)
            best = min(best, (time.process_time() - t0) / n)
        res[f"{name}_us"] = 1e6 * best
        res["outputs"][name] = out[:3].tolist()  # -e_z, v_c,end, t_contact
    scene = Scene.from_dimensionless(0.1, 0.5, mu=0.3)
    c0 = time.process_time()
    r = simulate(scene)
    res["compile_friction_cpu_s"] = time.process_time() - c0
    best = np.inf
    for _ in range(max(3, REPEATS // 2)):
        t0 = time.process_time()
        simulate(scene)
        best = min(best, time.process_time() - t0)
    res["friction_us"] = 1e6 * best
    res["outputs"]["friction"] = [r.e_z, r.beta_x, r.t_contact]
    return res


def _start(level: int, tmp: str) -> subprocess.Popen:
    cache = tempfile.mkdtemp(prefix=f"opt{level}_", dir=tmp)
    env = {**os.environ, "NUMBA_OPT": str(level), "NUMBA_CACHE_DIR": cache}
    return subprocess.Popen([sys.executable, "-m", "benchmarks.compile_options", "--child"],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            cwd=Path(__file__).parent.parent)


def run(quick: bool = False) -> dict:
    """Every level in its own fresh process, two at a time."""
    levels = LEVELS["quick" if quick else "full"]
    start = time.perf_counter()
    data: dict = {"machine": machine_info(), "config": {"levels": list(levels),
                                                        "repeats": REPEATS, "quick": quick},
                  "load_average": {"before": load_average()}, "levels": {}}
    with tempfile.TemporaryDirectory(prefix="vimpact_opt_") as tmp:
        for k in range(0, len(levels), 2):
            pair = levels[k:k + 2]
            progress(f"compile_options: NUMBA_OPT={pair}", start)
            procs = {lv: _start(lv, tmp) for lv in pair}
            for lv, p in procs.items():
                stdout, _ = p.communicate()
                data["levels"][str(lv)] = json.loads(stdout.strip().splitlines()[-1])
    data["load_average"]["after"] = load_average()
    ref = data["levels"].get("3")
    if ref is not None:
        for rec in data["levels"].values():
            rec["run_ratio_to_opt3"] = {s: rec[f"{s}_us"] / ref[f"{s}_us"]
                                        for s in (*SCENES, "friction")}
            rec["outputs_identical_to_opt3"] = rec["outputs"] == ref["outputs"]
    return data


def report(data: dict) -> str:
    cols = "".join(f"{s:>12}" for s in (*SCENES, "friction"))
    lines = [f"{'NUMBA_OPT':<10}{'compile s':>10}{'friction':>10}{cols}   (run: us per impact)"]
    for lv, rec in data["levels"].items():
        runs = "".join(f"{rec[f'{s}_us']:>12.1f}" for s in (*SCENES, "friction"))
        lines.append(f"{lv:<10}{rec['compile_continuum_cpu_s']:>10.1f}"
                     f"{rec['compile_friction_cpu_s']:>10.1f}{runs}")
    lines.append(f"load average before/after: {data['load_average']['before']} / "
                 f"{data['load_average']['after']}")
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    """Compile CPU seconds and run time relative to level 3, per level."""
    use_agg()
    import matplotlib.pyplot as plt

    levels = list(data["levels"])
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9.0, 3.4))
    x = np.arange(len(levels))
    a1.bar(x - 0.2, [data["levels"][lv]["compile_continuum_cpu_s"] for lv in levels], 0.4,
           label="continuum impact")
    a1.bar(x + 0.2, [data["levels"][lv]["compile_friction_cpu_s"] for lv in levels], 0.4,
           label="friction (element)")
    a1.set_xticks(x, levels)
    a1.set_xlabel("NUMBA_OPT")
    a1.set_ylabel("cold compile, CPU s")
    a1.legend(fontsize=7)
    for s in (*SCENES, "friction"):
        a2.plot(x, [data["levels"][lv].get("run_ratio_to_opt3", {}).get(s, np.nan)
                    for lv in levels], "o-", label=s)
    a2.set_xticks(x, levels)
    a2.set_yscale("log")
    a2.set_xlabel("NUMBA_OPT")
    a2.set_ylabel("run time / run time at 3")
    a2.legend(fontsize=7)
    fig.suptitle(data["machine"]["cpu"], fontsize=8)
    save_figure(fig, path)


def main(argv: list[str] | None = None) -> dict:
    data = bench_main(__doc__, run, plot, "compile_options", argv=argv)
    print(report(data))
    return data


if __name__ == "__main__":
    if sys.argv[1:] == ["--child"]:
        print(json.dumps(_child()))
    else:
        main()
