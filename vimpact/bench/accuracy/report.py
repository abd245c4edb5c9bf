"""The accuracy benchmark's text summary and headline figures."""

from __future__ import annotations

from ..machine import figure


def _err(x: float | None, spec: str = ".1e") -> str:
    """Return an error as text, ``failed`` for ``None`` (no finite value: a row failed)."""
    return "failed" if x is None else format(x, spec)


def _cell(c) -> str:
    if isinstance(c, str):
        return c
    return (f"{c['steps']}/{c['elements']} ({c['error']:.1e}, "
            f"{c['seconds_per_impact'] * 1e3:.3g} ms)")


def _summary(data: dict) -> str:
    d = data["derived"]
    ref = data["reference"]
    kv = ref["kelvin_voigt_closed_form_e_z_difference_max"]
    lines = [f"reference: continuum kernel at rtol {ref['rtol']:g}; uncertainty (vs rtol "
             f"{ref['check_rtol']:g}) e_z {ref['e_z_uncertainty_max']:.1e}, e_x "
             f"{ref['e_x_uncertainty_max']:.1e}; Kelvin-Voigt e_z vs the closed form "
             + ("(no Kelvin-Voigt scene)" if kv is None else f"{kv:.1e}")]
    for name, g in data["integrators"].items():
        lines.append(f"{name} front: " + ", ".join(
            f"{r['steps']}/{r['elements']} {r['error']:.1e} @ "
            f"{r['seconds_per_impact'] * 1e3:.3g} ms"
            for r in g["front"]))
    for table in ("cheapest", "cheapest_by_time_model", "cheapest_e_z_only"):
        lines.append(f"{table}:")
        for tol, row in d[table].items():
            cells = [f"{n} {_cell(row[n])}" for n in data["integrators"]]
            if "continuum_normal_only" in row:
                c = row["continuum_normal_only"]
                cells.append("continuum " + (c if isinstance(c, str) else
                                             f"rtol {c['rtol']:g} "
                                             f"{c['seconds_per_impact'] * 1e6:.3g} us"))
            lines.append(f"  {tol}: " + "; ".join(cells)
                         + ("" if row.get("verifiable", True) else " (below the reference's uncertainty)"))
    for tol, r in d["euler_over_verlet_time"].items():
        m, t = r["measured"], r["time_model"]
        lines.append(f"euler/verlet time at {tol}: measured {m.get('ratio')}, "
                     f"time model {t.get('ratio')}" + (f" ({m['why']})" if "why" in m else ""))
    for pname, p in data["presets"].items():
        lines.append(f"preset {pname}: {p['integrator']} {p['steps']}/{p['elements']}: error "
                     f"{_err(p['error'], '.2e')} (e_z {_err(p['e_z_error_max'])}, "
                     f"e_x {_err(p['e_x_error_max'])})"
                     f" @ {p['seconds_per_impact'] * 1e3:.3g} ms")
    for pname, why in data.get("presets_not_on_elements", {}).items():
        lines.append(f"preset {pname}: not run on the element path ({why})")
    for pname, p in data.get("presets_as_routed", {}).items():
        paths = ", ".join(f"{k} x{c}" for k, c in p["rows_per_path"].items())
        lines.append(f"preset {pname} as routed ({paths}): error {_err(p['error'], '.2e')} "
                     f"(e_z {_err(p['e_z_error_max'])}, e_x {_err(p['e_x_error_max'])}) @ "
                     f"{p['seconds_per_impact'] * 1e3:.3g} ms")
    for r in data.get("for_tolerance", []):
        lines.append(f"for_tolerance({r['tolerance']:g}): {r['steps']}/{r['elements']} error "
                     f"{_err(r['error'])} (met: {r['met']}) @ "
                     f"{r['seconds_per_impact'] * 1e3:.3g} ms")
    scan = data.get("for_tolerance_scan")
    if scan:
        lines.append(f"for_tolerance scan ({len(scan['rows'])} tolerances "
                     f"{scan['rows'][0]['tolerance']:g}..{scan['rows'][-1]['tolerance']:g}, element "
                     f"path): {scan['missed']} missed; worst error/tol "
                     f"{scan['worst_error_over_tolerance']:.2f} at {scan['worst_tolerance']:.2e} "
                     f"(scene {scan['worst_scene']})")
    for c in d.get("model_checks", []):
        lines.append(f"model check {c['tolerance']:g} [{c['source']}]: {c['steps']}/{c['elements']}"
                     f" error {_err(c['error'])} (met: {c['met']}) @ "
                     f"{c['seconds_per_impact'] * 1e3:.3g} ms")
    for pname, p in d["suggested_presets"].items():
        lines.append(f"suggested {pname} (aim {p['aim']:g}, 2x margin reached: "
                     f"{p['reached_with_2x_margin']}): {p['integrator']} {p['steps']}/"
                     f"{p['elements']} error {p['error']:.1e} @ "
                     f"{p['seconds_per_impact'] * 1e3:.3g} ms")
    for n, m in d["error_models"].items():
        for q in ("e_z", "e_x"):
            f = m[q]
            if f.get("fitted"):
                lines.append(f"{n} {q}: {f['a']:.3g}/S^{f['p']:.2f} + {f['b']:.3g}/E^{f['q']:.2f}"
                             f" (rms log10 resid {f['rms_log10_residual']:.2f}, "
                             f"{f['points_used']} points)")
        f = m["envelope"]
        if f.get("fitted"):
            lines.append(f"{n} envelope (p=1, q=2) of max error: {f['a']:.3g}/S + "
                         f"{f['b']:.3g}/E^2 (LSQ {f['a_fit']:.3g}, {f['b_fit']:.3g}, "
                         f"x{f['scale']:.2f})")
        t = m["time"]
        lines.append(f"{n} time: {t['c0']:.2e} + {t['cs']:.2e} S + {t['c1']:.2e} S E s "
                     f"(rms rel resid {t['rms_relative_residual']:.2f})")
    lines.append(f"orders (elastic table 4.1): {d['orders']['elastic_table_4_1']}")
    lines.append(f"total {data['total_seconds']:.0f} s; load {data['load_average']}")
    return "\n".join(lines)


def report(data: dict) -> str:
    """Return the long text summary (fronts, cheapest settings, models, presets)."""
    return _summary(data)


def _spread_of(row: dict) -> list[float] | None:
    return row.get("seconds_samples")


def figures(data: dict) -> dict:
    """Return the headline numbers of an accuracy run.

    Headline numbers: per preset (element path and as routed) and
    ``for_tolerance`` target (element path) the time per impact and the error;
    per continuum ``rtol`` the time and the ``e_z`` error; the explicit-Euler
    error of the thesis's table 4.1.
    """
    out = {}
    for pname, p in data.get("presets", {}).items():
        out[f"preset_{pname}_seconds_per_impact"] = figure(
            p["seconds_per_impact"], "s", samples=_spread_of(p))
        out[f"preset_{pname}_error"] = figure(p["error"], "-", kind="accuracy")
    for pname, p in data.get("presets_as_routed", {}).items():
        out[f"preset_{pname}_as_routed_seconds_per_impact"] = figure(
            p["seconds_per_impact"], "s", samples=_spread_of(p))
        out[f"preset_{pname}_as_routed_error"] = figure(p["error"], "-", kind="accuracy")
    for r in data.get("for_tolerance", []):
        out[f"for_tolerance_{r['tolerance']:g}_seconds_per_impact"] = figure(
            r["seconds_per_impact"], "s", samples=_spread_of(r))
        out[f"for_tolerance_{r['tolerance']:g}_error"] = figure(r["error"], "-", kind="accuracy")
    for c in data.get("continuum", []):
        out[f"continuum_rtol_{c['rtol']:g}_seconds_per_impact"] = figure(
            c["seconds_per_impact"], "s", samples=_spread_of(c))
        out[f"continuum_rtol_{c['rtol']:g}_e_z_error"] = figure(
            c["e_z_error_max"], "-", kind="accuracy")
    t41 = data.get("table_4_1", {})
    for name in ("euler", "verlet"):
        for n, pct in t41.get(name, {}).get("percent", {}).items():
            out[f"table_4_1_{name}_{n}_steps_percent"] = figure(pct, "%", kind="accuracy")
    return out
