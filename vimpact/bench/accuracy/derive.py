"""What the accuracy benchmark derives from its measurements."""

from __future__ import annotations

from typing import Any

import numba

import vimpact as v

from .config import INTEGRATORS, TOLERANCES
from .measure import REFERENCE_RTOL, Timer, _log, evaluate
from .models import (
    _cheapest,
    _f,
    _model_time,
    _num,
    _orders,
    fit_envelope,
    fit_error_model,
    fit_time_model,
    model_pick,
)


def derive(out: dict, floors: dict, cfg: dict, scenes: list, ref: dict, timer: Timer) -> dict:
    """Return the derived numbers of a run (``out["derived"]``).

    Error and time models per integrator, the cheapest setting per tolerance, the
    explicit-Euler / Verlet time ratio, observed orders, the models' picks run and
    measured, suggested presets. Adds ``model_seconds_per_impact`` to every setting and
    preset of ``out``.
    """
    derived: dict[str, Any] = {}
    models: dict[str, dict[str, Any]] = {}
    names = tuple(out["integrators"])  # this run's integrators (Verlet among them)
    for n in names:
        rows = out["integrators"][n]["settings"]
        S = [r["steps"] for r in rows]
        E = [r["elements"] for r in rows]
        p0 = 2.0 if n == "verlet" else 1.0
        models[n] = {
            "e_z": fit_error_model(S, E, [_num(r["e_z_error_max"]) for r in rows],
                                   floors["z"], p0),
            "e_x": fit_error_model(S, E, [_num(r["e_x_error_max"]) for r in rows],
                                   floors["x"], p0),
            "error": fit_error_model(S, E, [_num(r["error"]) for r in rows],
                                     floors["both"], p0),
            "envelope": fit_envelope(S, E, [_num(r["error"]) for r in rows], floors["both"],
                                     1.0, 2.0),
            "time": fit_time_model(S, E, [r["seconds_per_impact"] for r in rows]),
            "grid_max": [max(S), max(E)],
        }
        models[n]["picks"] = {
            f"{tol:g}": model_pick(models[n]["e_z"], models[n]["e_x"], models[n]["time"], tol,
                                   (max(S), max(E)), floors["both"]) for tol in TOLERANCES}
        for r in rows:
            r["model_seconds_per_impact"] = _f(_model_time(models[n]["time"], r["steps"],
                                                           r["elements"]))
    for r in out["presets"].values():
        r["model_seconds_per_impact"] = _f(_model_time(models[r["integrator"]]["time"],
                                                       r["steps"], r["elements"]))

    for table, key, floor in (("cheapest", "error", floors["both"]),
                              ("cheapest_e_z_only", "e_z_error_max", floors["z"]),
                              ("cheapest_e_x_only", "e_x_error_max", floors["x"])):
        derived[table] = {}
        for tol in TOLERANCES:
            derived[table][f"{tol:g}"] = {
                "verifiable": tol >= floor,
                **{n: _cheapest(out["integrators"][n]["settings"], tol, key)
                   for n in names}}
    for tol in TOLERANCES:
        cont = [c for c in out["continuum"] if c["e_z_error_max"] is not None
                and c["e_z_error_max"] <= tol]
        derived["cheapest_e_z_only"][f"{tol:g}"]["continuum_normal_only"] = (
            min(cont, key=lambda c: c["seconds_per_impact"]) if cont else "not reached")
    # the same ranked by the fitted time model (measured errors): robust to timing noise
    derived["cheapest_by_time_model"] = {
        f"{tol:g}": {n: _cheapest(out["integrators"][n]["settings"], tol, "error",
                                  by="model_seconds_per_impact") for n in names}
        for tol in TOLERANCES}

    def _ratio(tol, by, slow="euler", fast="verlet"):
        if slow not in out["integrators"]:
            return {"ratio": None, "why": f"{slow} is not among this run's integrators"}
        a = _cheapest(out["integrators"][slow]["settings"], tol, "error", by=by)
        b = _cheapest(out["integrators"][fast]["settings"], tol, "error", by=by)
        if isinstance(b, str):
            return {"ratio": None, "why": f"{fast} does not reach {tol:g}"}
        if isinstance(a, str):
            t_max = max(r[by] for r in out["integrators"][slow]["settings"])
            return {"ratio": None, "lower_bound": t_max / b[by],
                    "why": f"{slow} does not reach {tol:g} on its ladder"}
        return {"ratio": a[by] / b[by], slow: a, fast: b}

    derived["euler_over_verlet_time"] = {
        f"{tol:g}": {"measured": _ratio(tol, "seconds_per_impact"),
                     "time_model": _ratio(tol, "model_seconds_per_impact")}
        for tol in (1e-3, 1e-4)}
    if "default" in out["presets"] and "euler" in out["integrators"]:
        d = out["presets"]["default"]
        e = _cheapest(out["integrators"]["euler"]["settings"], d["error"], "error")
        derived["default_vs_euler_same_error"] = {
            "default_error": d["error"], "default_seconds_per_impact": d["seconds_per_impact"],
            "euler_cheapest_reaching_it": e,
            "euler_over_default_time": (None if isinstance(e, str)
                                        else e["seconds_per_impact"] / d["seconds_per_impact"]),
            "target": "default at <= 1/10 of explicit Euler's time for the same error"}
    derived["orders"] = {n: _orders(out["integrators"][n]["settings"], floors) for n in names}
    derived["orders"]["elastic_table_4_1"] = {n: out["table_4_1"][n]["order"]
                                              for n in INTEGRATORS if n in out["table_4_1"]}
    derived["error_models"] = models

    # the fitted models' choices for verlet, run and measured
    checks = []
    vm = models["verlet"]
    for tol in cfg["model_checks"]:
        rule = vm["envelope"].get("for_tolerance_rule", {}).get(f"{tol:g}")
        for source, pick in (("free-exponent fit, cheapest by time model",
                              vm["picks"].get(f"{tol:g}")),
                             ("envelope (p=1, q=2), half the tolerance to each knob", rule)):
            if not pick or "steps" not in pick:
                continue
            num = v.Numerics(continuum=False, steps=max(int(pick["steps"]), 4),
                             elements=max(int(pick["elements"]), 4))
            r = evaluate(scenes, num, ref, timer)
            timer.repeat_now(r)
            checks.append({"tolerance": tol, "source": source, "steps": num.steps,
                           "elements": num.elements, "error": r["error"],
                           "e_z_error_max": r["e_z_error_max"], "e_x_error_max": r["e_x_error_max"],
                           "met": r["error"] is not None and r["error"] <= tol,
                           "seconds_per_impact": r["seconds_per_impact"]})
            _log(f"model check {tol:g} ({source}): {num.steps}/{num.elements} -> {r['error']}")
    derived["model_checks"] = checks

    # suggested presets: cheapest measured setting (by the time model) with a 2x margin
    every = [r for n in names for r in out["integrators"][n]["settings"]
             if r["error"] is not None]
    suggest = {}
    for pname, tol in (("fast", 1e-3), ("default", 1e-4), ("precise", 1e-7)):
        ok = [r for r in every if r["error"] <= tol / 2]
        pick = (min(ok, key=lambda r: r["model_seconds_per_impact"]) if ok
                else min(every, key=lambda r: r["error"]))
        suggest[pname] = {"aim": tol, "reached_with_2x_margin": bool(ok),
                          **{k: pick[k] for k in ("integrator", "steps", "elements", "error",
                                                  "e_z_error_max", "e_x_error_max",
                                                  "seconds_per_impact",
                                                  "model_seconds_per_impact")}}
    derived["suggested_presets"] = suggest
    derived["note"] = ("error = max(max over scenes |e_z - ref|, max over scenes |e_x - ref|); "
                       "time = wall time of simulate_batch over all scenes / scenes, on "
                       f"{numba.get_num_threads()} numba threads; reference: the continuum kernel "
                       f"(rtol {REFERENCE_RTOL:g}); a tolerance is 'verifiable' when it is "
                       "above the reference's own uncertainty (reference.e_z_floor, "
                       "e_x_floor: |ref(rtol 1e-12) - ref(rtol 1e-10)|).")
    return derived
