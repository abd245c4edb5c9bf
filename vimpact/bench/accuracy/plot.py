"""The accuracy benchmark's chart."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..machine import save_figure, use_agg

COLOURS = {"verlet": "tab:blue", "symplectic_euler": "tab:green", "euler": "tab:red"}


def plot(data: dict, path: Path) -> None:
    """Draw the accuracy benchmark's chart to ``path``.

    The Pareto fronts (left), convergence and table 4.1 (top right) and the
    continuum path (bottom right) to ``path``.
    """
    use_agg()
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(14, 7.2))
    gs = fig.add_gridspec(2, 2, width_ratios=[1.55, 1])
    ax, bx, cx = fig.add_subplot(gs[:, 0]), fig.add_subplot(gs[0, 1]), fig.add_subplot(gs[1, 1])
    ref = data["reference"]
    fx, fz = ref["e_x_floor"], ref["e_z_floor"]
    errs = []
    for name, d in data["integrators"].items():
        rows = [r for r in d["settings"] if r["error"] is not None]
        errs += [r["error"] for r in rows]
        c = COLOURS.get(name, "k")
        ax.loglog([r["seconds_per_impact"] for r in rows], [r["error"] for r in rows], ".",
                  color=c, alpha=0.25, ms=5)
        fr = d["front"]
        ax.loglog([r["seconds_per_impact"] for r in fr], [r["error"] for r in fr], "o-",
                  color=c, ms=4.5, lw=1.6, label=f"{name}: Pareto front (all settings: dots)")
        for r in fr:
            ax.annotate(f"{r['steps']}/{r['elements']}", (r["seconds_per_impact"], r["error"]),
                        fontsize=5.5, color=c, xytext=(3, 2), textcoords="offset points")
    max_t = max(r["seconds_per_impact"] for d in data["integrators"].values()
                for r in d["settings"])
    for pname, p in data["presets"].items():
        if p["error"] is None:
            continue
        errs.append(p["error"])
        ax.loglog([p["seconds_per_impact"]], [p["error"]], "*", ms=16,
                  color=COLOURS.get(p["integrator"], "k"), mec="k", zorder=5)
        right = p["seconds_per_impact"] > 0.3 * max_t  # label left of the star
        ax.annotate(f"{pname} ({p['integrator']} {p['steps']}/{p['elements']})",
                    (p["seconds_per_impact"], p["error"]), fontsize=8, weight="bold",
                    xytext=(-9 if right else 7, -11), textcoords="offset points",
                    ha="right" if right else "left")
    lo = min(min(errs) / 3, 3e-8)
    for tol in (1e-3, 1e-4, 1e-7):
        ax.axhline(tol, color="grey", lw=0.8, ls=":")
        ax.annotate(f"{tol:g}", (1.0, tol), xycoords=("axes fraction", "data"), fontsize=8,
                    color="grey", ha="right", va="bottom")
    floor = max(fx, fz)
    if floor > lo:  # errors below the reference's uncertainty are not resolved
        ax.axhspan(lo, floor, color="grey", alpha=0.12,
                   label=f"not resolved: below the reference's uncertainty ({floor:.1e})")
    else:
        ax.plot([], [], " ", label=f"reference: continuum kernel, rtol {ref['rtol']:g} "
                                   f"(uncertainty {floor:.0e}, below the axis)")
    ax.set_ylim(lo, max(errs) * 2)
    ax.set_xlabel(f"wall time per impact, s (simulate_batch, {data['threads']} numba threads)")
    ax.set_ylabel("max over scenes of max(|e_z error|, |e_x error|)")
    ax.set_title(f"Element path against the exact continuum kernel, {len(data['scenes'])} "
                 "oblique scenes (labels: steps per t_H / elements per a_H)", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(True, which="major", alpha=0.3)

    # right top: convergence along the diagonal and the elastic table 4.1
    ys = []
    for name, o in data["derived"]["orders"].items():
        line = o.get("diagonal_steps_eq_5_elements") if name != "elastic_table_4_1" else None
        if not line:
            continue
        c = COLOURS.get(name, "k")
        for q, ls, mk in (("e_z", "-", "o"), ("e_x", "--", "s")):
            y = [e if e is not None else np.nan for e in line[q]["error"]]
            ys += y
            order = line[q]["order"]
            lab = f"{name} {q}" + (f" (order {order:.2f})" if order is not None else "")
            bx.loglog(line[q]["x"], y, ls, marker=mk, color=c, ms=3.5, label=lab)
    t41 = data["table_4_1"]
    xs = [int(k) for k in t41["thesis_percent"]]
    bx.loglog(xs, [x / 100 for x in t41["thesis_percent"].values()], "k^", ms=7,
              mfc="none", label="thesis table 4.1 (euler, elastic, normal)")
    bx.loglog(xs, [t41["euler"]["percent"][str(n)] / 100 for n in xs], "r:",
              label="ours: euler, elastic, normal (table 4.1)")
    y_lo = max(np.nanmin(ys) / 3, 1e-9)
    shown = [f for f in (fx, fz) if f > y_lo]
    for f in shown:
        bx.axhline(f, color="grey", lw=0.8, ls="--")
    bx.set_ylim(y_lo, 0.05)
    bx.set_xlabel("steps per t_H (elements per a_H = steps / 5)")
    bx.set_ylabel("max error over scenes")
    bx.set_title("Convergence along the diagonal"
                 + (" (grey dashes: reference uncertainty)" if shown else ""), fontsize=10)
    bx.legend(fontsize=6, ncol=2)
    bx.grid(True, which="major", alpha=0.3)

    # right bottom: the continuum path
    cont = [c for c in data["continuum"] if c["e_z_error_max"] is not None]
    if cont:
        cx.loglog([c["seconds_per_impact"] * 1e6 for c in cont],
                  [max(c["e_z_error_max"], 1e-14) for c in cont], "kx-",
                  label="continuum path: max |e_z error|")
        for c in cont:
            cx.annotate(f"rtol {c['rtol']:g}", (c["seconds_per_impact"] * 1e6,
                                                 max(c["e_z_error_max"], 1e-14)),
                        fontsize=7, xytext=(4, 0), textcoords="offset points")
        for tol in (1e-3, 1e-4, 1e-7):
            cx.axhline(tol, color="grey", lw=0.8, ls=":")
        cx.set_xlabel("wall time per impact, microseconds (simulate_batch)")
        cx.set_ylabel("max |e_z error| (exact continuum)")
        cx.set_title("Continuum path: Kelvin-Voigt normal-only impacts", fontsize=10)
        cx.grid(True, which="major", alpha=0.3)
        cx.legend(fontsize=7)
    save_figure(fig, path)

