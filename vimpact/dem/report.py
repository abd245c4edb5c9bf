"""Report of a DEM export: vimpact's curves beside what the code will produce.

A Markdown file (constants, residuals, what is not represented) and one PNG
with a panel per contact: ``e_z(v)`` (and ``beta_x(v)`` where the code has a
tangential restitution), vimpact as lines, the code's law with the exported
constants as markers.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from vimpact.dem.fit import ContactFit, Targets
from vimpact.dem.problem import DemProblem


def figure(code: str, problem: DemProblem, targets: dict[str, Targets],
           fits: list[ContactFit], out: Path) -> Path:
    """Write the comparison figure to ``out`` (PNG)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = len(fits)
    rows = 2 if any(f.beta_x is not None for f in fits) else 1
    fig = Figure(figsize=(3.2 * n, 2.9 * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, n, squeeze=False)
    for k, f in enumerate(fits):
        t = targets[f.contact.key]
        ax = axes[0, k]
        levels = np.unique(t.level)
        sizes = {0: "R min", 1: "R nominal", 2: "R max"} if len(levels) == 3 else {0: ""}
        for lvl in levels:
            sel = t.level == lvl
            size = sizes.get(int(lvl), "")
            style = {"R min": ":", "R max": "--"}.get(size, "-")
            ax.plot(t.v[sel], t.e_z[sel], style, color="C0",
                    label=f"vimpact {size}".strip())
            ax.plot(t.v[sel], f.e_z[sel], "o" if style == "-" else ("v" if size == "R min" else "^"),
                    ms=3, mfc="none", color="C3", label=f"{code} {size}".strip())
        if len(levels) > 1 or k == 0:
            ax.legend(fontsize=6)
        ax.set_xscale("log")
        ax.set_title(f"{f.contact.key}\nRMS {f.res_e_z.rms:.1e}", fontsize=8)
        ax.set_xlabel("v_z0 [m/s]")
        if k == 0:
            ax.set_ylabel("e_z")
        if rows == 2:
            ax = axes[1, k]
            if f.beta_x is not None and t.beta_x is not None:
                ax.plot(t.v, t.beta_x, ".", color="C0", ms=3)
                ax.plot(t.v, f.beta_x, "o", ms=3, mfc="none", color="C3")
                ax.set_title(f"beta_x RMS {f.res_beta_x.rms:.1e}", fontsize=8)
            else:
                ax.text(0.5, 0.5, "beta_x not\nrepresented", ha="center", va="center",
                        transform=ax.transAxes)
            ax.set_xscale("log")
            ax.set_xlabel("v_z0 [m/s]")
            if k == 0:
                ax.set_ylabel("beta_x")
    fig.suptitle(f"vimpact (lines) vs {code} with the exported constants (markers); "
                 "size ranges: R min dotted, R max dashed", fontsize=9)
    fig.savefig(out, dpi=110)
    return out


def _fmt(x) -> str:
    if isinstance(x, float):
        return f"{x:.6g}" if math.isfinite(x) else str(x)
    if isinstance(x, list):
        return f"[{len(x)} values]"
    return str(x)


def markdown(code: str, problem: DemProblem, targets: dict[str, Targets],
             fits: list[ContactFit], files: list[str], png: str,
             steps_per_contact: int | None = None, step_error=None) -> str:
    """The report text; ``steps_per_contact`` and ``step_error`` (the code module's
    ``TIME_STEP_ERROR``) add the exported time step and the code's error at it."""
    lines = [f"# vimpact dem: {code}", "",
             f"Input: `{problem.source}`; normal impact speeds {problem.speeds.min():g} to "
             f"{problem.speeds.max():g} m/s ({problem.speeds.size} points, log-spaced)"
             + ("; size levels min/nominal/max where a radius range is given" if any(
                 len(t.radii) > 1 for t in problem.types) else "") + ".",
             f"Written: {', '.join(f'`{x}`' for x in files)}.", "",
             "Residual = code minus vimpact over all points (max |.|, RMS).", "",
             "| contact | pair material | exported constants | e_z residual | beta_x residual |",
             "|---|---|---|---|---|"]
    for f in fits:
        c = f.contact
        mat = c.material
        params = ", ".join(f"{k} = {_fmt(v)}" for k, v in f.params.items())
        rb = str(f.res_beta_x) if f.res_beta_x is not None else "not represented"
        lines.append(f"| {c.key} | {mat.model}, G_inf {mat.G_inf:.4g} Pa, nu {mat.nu:.3g} | "
                     f"{params} | {f.res_e_z} | {rb} |")
    if steps_per_contact is not None:
        lines += ["", "## Time step", "",
                  f"The exported time step is the shortest contact / {steps_per_contact}."]
        if step_error is not None:
            C, measured = step_error
            lines.append(f"The code's own time-step error in e at that step is about "
                         f"{C / steps_per_contact:.1e} (first order in the step, "
                         f"{C:g} / steps; measured, largest over the round trip collisions: "
                         f"{measured}). Change it with `--steps-per-contact`.")
    lines += ["", "## Notes", ""]
    for f in fits:
        for note in f.notes:
            lines.append(f"- {f.contact.key}: {note}")
    half = {k: int(np.sum(t.status == "half_space")) for k, t in targets.items()}
    for k, nbad in half.items():
        if nbad:
            lines.append(f"- {k}: {nbad} point(s) have a contact wider than 0.2 R "
                         "(half-space model stretched; status half_space)")
    if problem.angles_deg:
        lines.append("- angles: under full stick beta_x does not depend on the impact angle; "
                     "the DEM code's Coulomb limit (exported mu) takes over at grazing angles")
    lines += ["", f"![vimpact vs {code}]({png})", ""]
    return "\n".join(lines)


def round_trip_main(code: str, available, round_trip, steps_per_contact: int) -> None:
    """``python -m vimpact.dem.CODE SETUP.toml [STEPS_PER_CONTACT]``: run the DEM code
    on the exported files at five speeds over the set-up's range and print the
    restitution it gives next to the report's prediction (one row per collision;
    ``round_trip(problem, speeds, steps)`` returns rows with ``contact``, ``v``
    (m/s), ``predicted``, ``e`` and optionally ``level``)."""
    import sys

    from vimpact.dem.problem import load_problem

    why = available()
    if why:
        sys.exit(f"cannot run {code}: {why}")
    prob = load_problem(sys.argv[1])
    steps = int(sys.argv[2]) if len(sys.argv) > 2 else steps_per_contact
    speeds = np.geomspace(prob.speeds.min(), prob.speeds.max(), 5)
    print(f"{'contact':12s} {'level':>5s} {'v [m/s]':>8s} {'predicted e':>12s} "
          f"{code + ' e':>12s} {'diff':>10s}")
    for r in round_trip(prob, speeds, steps):
        print(f"{r['contact']:12s} {r.get('level', 0):5d} {r['v']:8.3g} {r['predicted']:12.8f} "
              f"{r['e']:12.8f} {r['e'] - r['predicted']:10.2e}")
