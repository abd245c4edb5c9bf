"""Observed convergence orders of the element kernel and the e_x jitter, before/after.

Kernel level (own step ``h`` and spacing ``dxi``, no routing, no element-count
rule): Verlet, default solid sphere (Theta = 2/5 m R^2).

- jitter: e_x and e_z over step counts 1330..1470 per t_H at 200 elements
  per a_H (within +-5 % of the default 1400): their spread is the error that is
  not smooth in h;
- time-only orders (1/800 spacing, steps 150..1200 against 9600), space-only
  orders (9600 steps, 25..200 elements against 1600), joint refinement;
- Kelvin-Voigt e_z against the continuum closed form.

"before" is the kernel of commit ``BEFORE`` (read with ``git show``, compiled
from a temporary copy), when git is available.

    python -m benchmarks.element_orders [--quick]
"""

from __future__ import annotations

import importlib.util
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.machine import bench_main, machine_info, save_figure
from vimpact.kernels.elements import (N_OUT, N_REC, OUT_VC_END, OUT_VZ_END, VERLET, KernelSpec,
                                      element_kernel)

HERTZ_TIME = 2.9432751843
Q1_PER_TAU = math.sqrt(15.0 / 32.0)
BEFORE = "2733180"  # main before the partial-contact weighting
#: the default step refinement of a solid sphere's tangential problem (routing)
TANGENTIAL_FACTOR = math.sqrt(2.0 / 3.0 * 3.5)


def run_rows(spec, *, h, dxi, tau0=0.0, g=(), tau=(), nu=0.3, theta_ratio=0.4, mu=math.inf,
             row_width=1.05, max_time=20.0, kernel=None):
    """Kernel rows built here (kernel units); returns the OUT rows."""
    h, dxi, tau0, mu = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(x, dtype=float)) for x in (h, dxi, tau0, mu)))
    n = h.size
    g = np.tile(np.asarray(g, dtype=float), (n, 1))
    tau = np.tile(np.asarray(tau, dtype=float), (n, 1))
    out = np.zeros((n, N_OUT))
    (kernel or element_kernel)(spec)(
        tau0.copy(), g, tau, np.full(n, g.shape[1], dtype=np.int64),
        np.full(n, 2.0 * (1.0 - nu) / (2.0 - nu)), np.full(n, 1.0 + 1.0 / theta_ratio), mu.copy(),
        h.copy(), np.ceil(row_width / dxi - 1e-9).astype(np.int64), dxi.copy(),
        np.ceil(max_time * HERTZ_TIME / h).astype(np.int64), np.zeros((n, 0, N_REC)), 1, out)
    return out


def old_kernel():
    """``element_kernel`` of commit BEFORE, or None without git."""
    root = Path(__file__).resolve().parent.parent
    try:
        src = subprocess.run(["git", "show", f"{BEFORE}:vimpact/kernels/elements.py"], cwd=root,
                             capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    path = Path(tempfile.mkdtemp()) / "elements_before.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("elements_before", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["elements_before"] = mod
    spec.loader.exec_module(mod)
    return mod.element_kernel


def orders(err):
    err = np.asarray(err, dtype=float)
    return (np.log(err[:-1] / err[1:]) / np.log(2.0)).tolist()


CASES = {  # name: (tau0, nu)
    "kelvin_voigt_Q1_0.3": (0.3 / Q1_PER_TAU, 0.3),
    "elastic_nu_0.5": (0.0, 0.5),
}


def run(quick: bool) -> dict:
    from vimpact.reference.closed_forms import kelvin_voigt_continuum

    before = old_kernel()
    kernels = {"after": element_kernel, **({"before": before} if before else {})}
    N_jit = np.arange(1330, 1471, 20 if quick else 5)
    steps = np.array([150, 300, 600] if quick else [150, 300, 600, 1200])
    fine_steps = 2400 if quick else 9600
    elems = np.array([25, 50, 100] if quick else [25, 50, 100, 200])
    fine_elems = 400 if quick else 1600
    data = {"machine": machine_info(), "before_commit": BEFORE, "cases": {}}
    for name, (tau0, nu) in CASES.items():
        spec = KernelSpec(VERLET, True, 0, False, tau0 > 0.0)
        case = {}
        for label, k in kernels.items():
            t0 = time.perf_counter()
            out = run_rows(spec, h=HERTZ_TIME / N_jit / TANGENTIAL_FACTOR, dxi=1 / 200,
                           tau0=tau0, nu=nu, kernel=k)
            e_x, e_z = np.abs(out[:, OUT_VC_END]), -out[:, OUT_VZ_END]
            r = {"jitter_steps": N_jit.tolist(), "e_x": e_x.tolist(), "e_z": e_z.tolist(),
                 "e_x_spread": float(np.ptp(e_x)), "e_z_spread": float(np.ptp(e_z))}
            # time only
            out = run_rows(spec, h=HERTZ_TIME / np.append(steps, fine_steps) / TANGENTIAL_FACTOR,
                           dxi=1 / (fine_elems // 2), tau0=tau0, nu=nu, kernel=k)
            for key, col, sgn in (("e_x", OUT_VC_END, 1.0), ("e_z", OUT_VZ_END, -1.0)):
                err = np.abs(sgn * out[:-1, col] - sgn * out[-1, col])
                r[f"time_{key}_error"] = err.tolist()
                r[f"time_{key}_order"] = orders(err)
            # space only
            out = run_rows(spec, h=HERTZ_TIME / fine_steps / TANGENTIAL_FACTOR,
                           dxi=1.0 / np.append(elems, fine_elems), tau0=tau0, nu=nu, kernel=k)
            for key, col, sgn in (("e_x", OUT_VC_END, 1.0), ("e_z", OUT_VZ_END, -1.0)):
                err = np.abs(sgn * out[:-1, col] - sgn * out[-1, col])
                r[f"space_{key}_error"] = err.tolist()
                r[f"space_{key}_order"] = orders(err)
            # joint: 1 element per a_H for every 6 steps per t_H
            joint = np.append(steps, fine_steps // 2)
            out = run_rows(spec, h=HERTZ_TIME / joint / TANGENTIAL_FACTOR, dxi=6.0 / joint,
                           tau0=tau0, nu=nu, kernel=k)
            for key, col, sgn in (("e_x", OUT_VC_END, 1.0), ("e_z", OUT_VZ_END, -1.0)):
                err = np.abs(sgn * out[:-1, col] - sgn * out[-1, col])
                r[f"joint_{key}_error"] = err.tolist()
                r[f"joint_{key}_order"] = orders(err)
            if tau0 > 0.0:  # against the continuum closed form
                exact = kelvin_voigt_continuum(tau0 * Q1_PER_TAU).e_z
                err = np.abs(-out[:-1, OUT_VZ_END] - exact)
                r["joint_e_z_vs_continuum_error"] = err.tolist()
                r["joint_e_z_vs_continuum_order"] = orders(err)
            r["seconds"] = time.perf_counter() - t0
            case[label] = r
        data["cases"][name] = case
    data["steps"], data["fine_steps"] = steps.tolist(), fine_steps
    data["elements"], data["fine_elements"] = elems.tolist(), fine_elems
    return data


def plot(data: dict, path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = data["cases"]
    fig, axes = plt.subplots(len(cases), 3, figsize=(13, 4 * len(cases)), squeeze=False)
    for row, (name, case) in zip(axes, cases.items()):
        for label, r in case.items():
            ls = "-" if label == "after" else "--"
            row[0].plot(r["jitter_steps"], np.array(r["e_x"]) - r["e_x"][len(r["e_x"]) // 2],
                        ls, label=f"{label}: spread {r['e_x_spread']:.1e}")
            for key, mk in (("e_x", "o"), ("e_z", "s")):
                row[1].loglog(data["steps"], r[f"time_{key}_error"], ls + mk,
                              label=f"{label} {key}")
                row[2].loglog(data["elements"], r[f"space_{key}_error"], ls + mk,
                              label=f"{label} {key}")
        row[0].set(title=f"{name}: e_x - middle value, 200 el/a_H", xlabel="steps per t_H")
        row[1].set(title="time only (vs finest)", xlabel="steps per t_H", ylabel="|error|")
        row[2].set(title="space only (vs finest)", xlabel="elements per a_H")
        for ax in row:
            ax.legend(fontsize=7)
    save_figure(fig, path)


def main(argv=None):
    return bench_main(__doc__, run, plot, "element_orders", argv=argv)


if __name__ == "__main__":
    main()
