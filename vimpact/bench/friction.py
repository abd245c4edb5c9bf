"""Cost of Coulomb friction in the element kernel, and beta_x error versus time.

Kernel level (Verlet, elastic nu = 0.3 and a standard solid Q2 = 0.5, solid
sphere): the friction kernel (``KernelSpec.friction``) against the stick
kernel at equal numerics (equal steps and elements, hence equal accuracy for
``mu = inf``, where both give the same numbers bit for bit), with ``mu`` at
infinity, in microslip (psi = 3 chi) and in gross slip (psi = 10 chi);
then beta_x with friction (psi = 3 chi) over a joint steps x elements ladder
against a 2x finer run, error versus seconds per impact, beside the stick
problem's.

    python -m benchmarks.friction [--quick]
"""

from __future__ import annotations

import math
import time
from typing import Any

import numba
import numpy as np

from vimpact.kernels.elements import OUT_T_CONTACT, OUT_T_GROSS_SLIP, OUT_VC_END, VERLET, KernelSpec
from vimpact.model.hertz import HERTZ_TIME_FACTOR

from .element_orders import TANGENTIAL_FACTOR, mu_for, run_rows
from .machine import figure, machine_info, median_time, save_figure

TITLE = "Coulomb friction: friction kernel against stick kernel, beta_x error vs time"


def interleaved_medians(fns: dict, repeats: int) -> dict:
    """Return the median wall time of each function, timed in turns, s.

    Median wall time of each ``fns`` entry, timed in turn within every
    repeat (so a busy machine slows all of them alike), s.
    """
    times: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            times[k].append(time.perf_counter() - t0)
    return {k: float(np.median(v)) for k, v in times.items()}


NU, THETA = 0.3, 0.4
MATERIALS = {"elastic": (0.0, (), ()), "standard_solid_Q2_0.5": (0.0, (2.0,), (0.5,))}


def run(quick: bool) -> dict:
    """Measure the cost and the beta_x ladder of each case; return the JSON-ready record."""
    steps, elements = (300, 50) if quick else (1400, 200)
    rows = 4 if quick else 8
    repeats = 5 if quick else 9
    threads = numba.get_num_threads()
    numba.set_num_threads(1)  # one thread: the ratio, not the parallel speed-up
    data: dict[str, Any] = {"machine": machine_info(), "steps": steps, "elements": elements, "rows": rows,
            "threads_used": 1, "cost": {}, "ladder": {}}
    h = HERTZ_TIME_FACTOR / steps / TANGENTIAL_FACTOR
    for name, (tau0, g, tau) in MATERIALS.items():
        stick = KernelSpec(VERLET, True, 0, len(g) > 0, tau0 > 0.0)
        fric = stick._replace(friction=True)
        kw = dict(h=np.full(rows, h), dxi=1.0 / elements, tau0=tau0, g=g, tau=tau, nu=NU,
                  theta_ratio=THETA)
        cases = {"stick": (stick, math.inf), "friction_mu_inf": (fric, math.inf),
                 "friction_psi_3chi": (fric, mu_for(3.0)),
                 "friction_psi_10chi": (fric, mu_for(10.0))}
        cost = {}
        fns = {label: (lambda spec=spec, mu=mu: run_rows(spec, mu=mu, **kw))
               for label, (spec, mu) in cases.items()}
        for fn in fns.values():
            fn()  # compile / load
        seconds = interleaved_medians(fns, repeats)
        for label, (spec, mu) in cases.items():
            t = seconds[label] / rows
            out = run_rows(spec, mu=mu, **kw)
            cost[label] = {"seconds_per_impact": t, "beta_x": float(-out[0, OUT_VC_END]),
                           "gross_slip_fraction": float(out[0, OUT_T_GROSS_SLIP]
                                                        / out[0, OUT_T_CONTACT])}
        base = cost["stick"]["seconds_per_impact"]
        for c in cost.values():
            c["ratio_to_stick"] = c["seconds_per_impact"] / base
        data["cost"][name] = cost

        ladder_steps = np.array([100, 200, 400, 800] if quick else [100, 200, 400, 800, 1600, 3200])
        ladder = {}
        for label, (spec, mu) in (("friction_psi_3chi", (fric, mu_for(3.0))),
                                  ("stick", (stick, math.inf))):
            hs = HERTZ_TIME_FACTOR / ladder_steps / TANGENTIAL_FACTOR
            dx = 1.0 / np.maximum(ladder_steps // 7, 10)
            fine = run_rows(spec, mu=mu, h=hs[-1] / 2, dxi=dx[-1] / 2, tau0=tau0, g=g, tau=tau,
                            nu=NU, theta_ratio=THETA)
            beta_fine = float(-fine[0, OUT_VC_END])
            pts = []
            for hi, di in zip(hs, dx):
                kwi = dict(mu=mu, h=np.full(2, hi), dxi=di, tau0=tau0, g=g, tau=tau, nu=NU,
                           theta_ratio=THETA)
                t = median_time(lambda: run_rows(spec, **kwi), repeats) / 2
                out = run_rows(spec, **kwi)
                pts.append({"steps": int(round(HERTZ_TIME_FACTOR / hi / TANGENTIAL_FACTOR)),
                            "elements": int(round(1 / di)), "seconds_per_impact": t,
                            "beta_x_error": abs(float(-out[0, OUT_VC_END]) - beta_fine)})
            err = np.array([p["beta_x_error"] for p in pts])
            ladder[label] = {"points": pts, "beta_x_reference": beta_fine,
                             "orders": (np.log(err[:-1] / err[1:]) / np.log(2.0)).tolist()}
        data["ladder"][name] = ladder
    numba.set_num_threads(threads)
    return data


def plot(data: dict, path) -> None:
    """Draw the time ratios and the beta_x ladder to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(data["cost"])
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    labels = list(data["cost"][names[0]])
    x = np.arange(len(labels))
    for k, name in enumerate(names):
        axes[0].bar(x + 0.4 * k, [data["cost"][name][l]["ratio_to_stick"] for l in labels], 0.4,
                    label=name)
        for label, lad in data["ladder"][name].items():
            pts = lad["points"]
            axes[1].loglog([p["seconds_per_impact"] for p in pts],
                           [max(p["beta_x_error"], 1e-16) for p in pts], "o-",
                           label=f"{name} {label}")
    axes[0].set_xticks(x + 0.2, labels, rotation=15, fontsize=8)
    axes[0].set(ylabel="time / stick kernel", title=f"cost at {data['steps']} steps, "
                f"{data['elements']} elements")
    axes[1].set(xlabel="seconds per impact", ylabel="|beta_x - finer run|",
                title="beta_x error vs time (psi = 3 chi)")
    for ax in axes:
        ax.legend(fontsize=7)
    save_figure(fig, path)


def figures(data: dict) -> dict:
    """Return the headline numbers of a friction run.

    Time ratio friction / stick kernel per material and case, and the
    finest beta_x error of the friction ladder.
    """
    out = {}
    for name, cost in data["cost"].items():
        for label, c in cost.items():
            if label != "stick":
                out[f"{name}_{label}_over_stick"] = figure(c["ratio_to_stick"], "-")
        pts = data["ladder"][name]["friction_psi_3chi"]["points"]
        out[f"{name}_friction_finest_beta_x_error"] = figure(pts[-1]["beta_x_error"], "-",
                                                             kind="accuracy")
    return out
