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

#: width and height of one contact's panel in the figure, inches
PANEL_IN = (3.2, 2.9)
#: fixed margins around and between the panels, inches: left (tick labels and
#: y label), right, top (the figure's two-line title and a panel's two-line title), bottom
#: (tick labels and x label), between columns, between rows (an x label and the
#: next row's title). A fixed layout, not matplotlib's constrained one, which
#: measured the text of every panel twice and cost a third of the figure's time.
MARGINS_IN = dict(left=0.75, right=0.15, top=0.9, bottom=0.5, column=0.75, row=0.85)


def _margins(n: int, rows: int) -> dict[str, float]:
    """Subplot parameters (figure fractions) of :data:`MARGINS_IN` for ``rows`` x ``n`` panels."""
    m = MARGINS_IN
    width, height = PANEL_IN[0] * n, PANEL_IN[1] * rows
    axes_w = (width - m["left"] - m["right"] - (n - 1) * m["column"]) / n
    axes_h = (height - m["top"] - m["bottom"] - (rows - 1) * m["row"]) / rows
    return dict(left=m["left"] / width, right=1.0 - m["right"] / width,
                bottom=m["bottom"] / height, top=1.0 - m["top"] / height,
                wspace=m["column"] / axes_w, hspace=m["row"] / axes_h)


def beta_row(fits: list[ContactFit]) -> bool:
    """Whether the figure has a ``beta_x`` row: some contact's ``beta_x`` is represented.

    Represented means it has a ``beta_x`` residual (over the oblique impacts with its
    friction, or over the full-stick curve), as the report's table says; a contact
    fitted over oblique impacts only has no full-stick curve, and is drawn all the same.
    """
    return any(f.res_beta_x is not None for f in fits)


def figure(code: str, problem: DemProblem, targets: dict[str, Targets],
           fits: list[ContactFit], out: Path) -> Path:
    """Write the comparison figure to ``out`` (PNG)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = len(fits)
    rows = 2 if beta_row(fits) else 1
    fig = Figure(figsize=(PANEL_IN[0] * n, PANEL_IN[1] * rows))
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, n, squeeze=False, gridspec_kw=_margins(n, rows))
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
            ob = t.oblique
            if f.beta_oblique is not None and ob is not None and f.res_beta_x is not None:
                for j, v in enumerate(sorted(set(ob.v.tolist()))):
                    sel = ob.v == v
                    ax.plot(ob.angle_deg[sel], ob.beta_x[sel], "-", color=f"C{j}", lw=1,
                            label=f"v_z0 {v:.2g} m/s")
                    ax.plot(ob.angle_deg[sel], f.beta_oblique[sel], "o", ms=3, mfc="none",
                            color=f"C{j}")
                ax.legend(fontsize=5)
                ax.set_title(f"beta_x, mu = {ob.mu:g}: max {f.res_beta_x.max_abs:.1e}",
                             fontsize=8)
                ax.set_xlabel("impact angle [deg]")
                if k == 0:
                    ax.set_ylabel("beta_x")
                continue
            if f.beta_x is not None and t.beta_x is not None and f.res_beta_x is not None:
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
    # two lines: one line is wider than a figure of one or two panels
    fig.suptitle(f"vimpact (lines) vs {code} with the exported constants (markers)\n"
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
             fits: list[ContactFit], files: list[str], png: str | None,
             steps_per_contact: int | None = None, step_error=None,
             beta_step_error: str | None = None) -> str:
    """Return the report text (Markdown).

    ``steps_per_contact`` and ``step_error`` (the code module's
    ``TIME_STEP_ERROR``) add the exported time step and the code's error at it,
    ``beta_step_error`` (``BETA_TIME_STEP_ERROR``) its measured error in ``beta_x``.
    ``png``: the figure's file name, or ``None`` when no figure was drawn (the report
    says so).
    """
    lines = [f"# vimpact dem: {code}", "",
             f"Input: `{problem.source}`; normal impact speeds {problem.speeds.min():g} to "
             f"{problem.speeds.max():g} m/s ({problem.speeds.size} points, log-spaced)"
             + ("; size levels min/nominal/max where a radius range is given" if any(
                 len(t.radii) > 1 for t in problem.types) else "") + ".",
             f"Written: {', '.join(f'`{x}`' for x in files)}.", "",
             "Residual = code minus vimpact over all points (max |.|, RMS). The beta_x "
             "residual of a contact with friction is over oblique impacts with that friction "
             "at the impact angles (nominal sizes, speeds as listed in its note); without "
             "friction, over the full-stick curve.", "",
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
        if beta_step_error is not None and any(f.beta_oblique is not None for f in fits):
            lines.append(f"Its time-step error in beta_x is larger (measured on oblique wall "
                         f"impacts: {beta_step_error}); add it to the beta_x residual, or "
                         "raise `--steps-per-contact`.")
    lines += ["", "## Notes", ""]
    for f in fits:
        for note in f.notes:
            lines.append(f"- {f.contact.key}: {note}")
    half = {k: int(np.sum(t.status == "half_space")) for k, t in targets.items()}
    for k, nbad in half.items():
        if nbad:
            lines.append(f"- {k}: {nbad} point(s) have a contact wider than 0.2 R "
                         "(half-space model stretched; status half_space)")
    for k, t in targets.items():
        ob = t.oblique
        if ob is not None and any(f.beta_oblique is not None for f in fits
                                  if f.contact.key == k):
            lines.append(f"- {k}: beta_x targets: vimpact with mu = {ob.mu:g} at v_z0 = "
                         + ", ".join(f"{v:.3g}" for v in sorted(set(ob.v.tolist())))
                         + " m/s and impact angles "
                         + ", ".join(f"{a:g}" for a in sorted(set(ob.angle_deg.tolist())))
                         + " deg (from the normal, no spin)")
    lines += ["", f"![vimpact vs {code}]({png})" if png is not None else
              "No figure was drawn (`--no-figure`).", ""]
    return "\n".join(lines)


def oblique_round_trip(code: str, round_trip, problem: DemProblem,
                       steps_per_contact: int) -> list[dict]:
    """Export for ``code``, then run the code on oblique impacts of the wall contacts.

    Every wall contact with friction, at the speeds (m/s) and angles (degrees from
    the normal) of the report's ``beta_x`` targets.

    ``round_trip(problem, speeds, steps, fits=, angles_deg=, contacts=)`` is the code's
    round trip; its rows get ``vimpact_beta`` (vimpact's ``beta_x`` there) and ``stated``
    (the report's ``beta_x`` residual, max). Pair contacts are left out: in an oblique
    sphere-sphere impact the line of centres turns during the contact, which no
    one-contact law follows.
    """
    from vimpact.dem.export import export

    ex = export(problem, code)
    obl = {k: t.oblique for k, t in ex.targets.items() if t.oblique is not None}
    walls = {f.contact.key for f in ex.fits if f.contact.is_wall and f.contact.key in obl}
    if not walls:
        return []
    first = obl[sorted(walls)[0]]
    speeds, angles = sorted(set(first.v.tolist())), sorted(set(first.angle_deg.tolist()))
    rows = round_trip(problem, speeds, steps_per_contact, fits=ex.fits, angles_deg=angles,
                      contacts=walls)
    stated = {f.contact.key: f.res_beta_x.max_abs for f in ex.fits
              if f.contact.key in walls and f.res_beta_x is not None}
    for r in rows:
        ob = obl[r["contact"]]
        k = int(np.flatnonzero(np.isclose(ob.v, r["v"], rtol=1e-12)
                               & (ob.angle_deg == r["angle"]))[0])
        r["vimpact_beta"] = float(ob.beta_x[k])
        r["stated"] = stated[r["contact"]]
    return rows


def round_trip_main(code: str, available, round_trip, steps_per_contact: int,
                    oblique: str | None = None) -> None:
    """Run ``python -m vimpact.dem.CODE SETUP.toml [STEPS_PER_CONTACT]``: a round trip.

    Runs the DEM code on the exported files at five speeds over the set-up's range
    and prints the
    restitution it gives next to the report's prediction (one row per collision;
    ``round_trip(problem, speeds, steps)`` returns rows with ``contact``, ``v``
    (m/s), ``predicted``, ``e`` and optionally ``level``), then the largest difference.

    ``oblique``, the export code of a code with a tangential fit: also the rows of
    :func:`oblique_round_trip` (oblique wall impacts with the set-up's friction at the
    report's speeds and angles), with ``angle``,
    ``beta``, ``predicted_beta``, ``vimpact_beta`` and ``stated`` (the report's beta_x
    residual of that contact); printed likewise, with the largest
    ``|beta - vimpact_beta|`` against the stated residual.
    """
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
    rows = round_trip(prob, speeds, steps)
    for r in rows:
        print(f"{r['contact']:12s} {r.get('level', 0):5d} {r['v']:8.3g} {r['predicted']:12.8f} "
              f"{r['e']:12.8f} {r['e'] - r['predicted']:10.2e}")
    print(f"head-on: {len(rows)} collisions at {steps} steps per contact, largest "
          f"|e - predicted| = {max(abs(r['e'] - r['predicted']) for r in rows):.2e}")
    if oblique is None:
        return
    rows = oblique_round_trip(oblique, round_trip, prob, steps)
    if not rows:
        print("oblique: no wall contact with friction in this set-up")
        return
    print(f"\n{'contact':12s} {'v [m/s]':>8s} {'angle':>6s} {'predicted':>10s} {code + ' beta':>12s} "
          f"{'diff':>10s} {'vimpact':>10s}")
    for r in rows:
        print(f"{r['contact']:12s} {r['v']:8.3g} {r['angle']:6g} {r['predicted_beta']:10.6f} "
              f"{r['beta']:12.6f} {r['beta'] - r['predicted_beta']:10.2e} {r['vimpact_beta']:10.6f}")
    worst = max(abs(r["beta"] - r["vimpact_beta"]) for r in rows)
    stated = max(r["stated"] for r in rows)
    print(f"oblique: {len(rows)} wall impacts at {steps} steps per contact, largest "
          f"|beta - predicted| = {max(abs(r['beta'] - r['predicted_beta']) for r in rows):.2e}, "
          f"|e - predicted| = {max(abs(r['e'] - r['predicted']) for r in rows):.2e}; "
          f"largest |beta - vimpact| = {worst:.2e} (stated beta_x residual {stated:.2e})")
