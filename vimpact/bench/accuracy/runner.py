"""One run of the accuracy benchmark: measure every setting, then derive."""

from __future__ import annotations

import time
from typing import Any

import numba

import vimpact as v

from ..machine import load_average, machine_info, max_threads
from .config import CONFIGS, INTEGRATORS, THREADS, TOLERANCES, _ladder
from .derive import derive
from .measure import (
    Timer,
    _log,
    _scene_list,
    _scenes,
    continuum_ladder,
    evaluate,
    for_tolerance_scan,
    reference,
    table_4_1,
)
from .models import _num, pareto


def run(quick: bool = False, integrators: tuple[str, ...] | None = None) -> dict:
    """Measure every setting, preset and path on the scenes; return the JSON-ready record.

    Parameters
    ----------
    quick : the small configuration (``CONFIGS["quick"]``) instead of the full one
    integrators : whose ladders to run (names from :data:`INTEGRATORS`, ``"verlet"``
        among them: the error models' checks and the Euler / Verlet ratio use it);
        default: the configuration's ``integrators`` (the quick one: Verlet only)

    Raises
    ------
    ValueError
        if ``integrators`` names an unknown integrator or lacks ``"verlet"``.
    """
    cfg = dict(CONFIGS["quick" if quick else "full"])
    if integrators is not None:
        unknown = [n for n in integrators if n not in INTEGRATORS]
        if unknown or "verlet" not in integrators:
            raise ValueError(f"integrators={tuple(integrators)!r}: allowed are names from "
                             f"{INTEGRATORS}, 'verlet' among them")
        cfg["integrators"] = tuple(n for n in INTEGRATORS if n in integrators)
    numba.set_num_threads(min(THREADS, max_threads()))
    load_start = load_average()
    t_start = time.perf_counter()
    specs = _scene_list(cfg)
    scenes = _scenes(specs)
    if any(s.v_c0 == 0.0 for s in scenes):
        raise RuntimeError("every scene must be oblique (v_c0 != 0) so that e_x is defined")
    ref = reference(specs, scenes)
    _log(f"reference done: uncertainty e_z {ref['json']['e_z_floor']:.1e}, "
         f"e_x {ref['json']['e_x_floor']:.1e}; Kelvin-Voigt closed form vs reference "
         f"{ref['json']['kelvin_voigt_closed_form_e_z_difference_max']}")
    floors = {"z": ref["json"]["e_z_floor"], "x": ref["json"]["e_x_floor"]}
    floors["both"] = max(floors.values())
    for spec, ez, ex, uz, ux in zip(specs, ref["e_z"], ref["e_x"], ref["u_z"], ref["u_x"]):
        spec.update(e_z_ref=float(ez), e_x_ref=float(ex), e_z_uncertainty=float(uz),
                 e_x_uncertainty=float(ux))

    timer = Timer(cfg)
    out: dict[str, Any] = {"machine": machine_info(), "threads": numba.get_num_threads(), "quick": quick,
           "scenes": specs, "theta_ratio": 0.4, "reference": ref["json"],
           "tolerances": list(TOLERANCES), "integrators": {}}

    for name in cfg["integrators"]:
        # compile every kernel the scenes need outside the timing
        v.simulate_batch(scenes, v.Numerics(integrator=name, steps=16, elements=8,
                                            continuum=False))
        rows: list[dict] = []
        for s, e, grid in _ladder(cfg, name):
            r = evaluate(scenes, v.Numerics(integrator=name, steps=s, elements=e,
                                            continuum=False), ref, timer)
            r["grid"] = grid
            rows.append(r)
            _log(f"{name} {s}/{e}: e_z {r['e_z_error_max']:.2e} e_x {r['e_x_error_max']:.2e} "
                 f"{r['seconds_per_impact'] * 1e3:.3g} ms/impact (batch {r['timed_batch_size']})"
                 if r["error"] is not None else f"{name} {s}/{e}: failed")
        out["integrators"][name] = {
            "settings": rows,
            "paths": sorted({p for r in rows for p in r["paths"]}),
            "failed_settings": sum(r["failed"] > 0 for r in rows),
        }

    # presets on the same scenes: on the element path (what numerics.py states for
    # them; those of this run's integrators), and as routed (most of these full-stick
    # scenes take the continuum path)
    out["presets"], out["presets_as_routed"], out["presets_not_on_elements"] = {}, {}, {}
    for pname, num in v.PRESETS.items():
        if num.integrator in cfg["integrators"]:
            elements = num.with_(continuum=False)
            v.simulate_batch(scenes, elements.with_(steps=16, elements=8))
            out["presets"][pname] = evaluate(scenes, elements, ref, timer)
        else:
            out["presets_not_on_elements"][pname] = (
                f"integrator {num.integrator!r} is not among this run's {cfg['integrators']}")
        out["presets_as_routed"][pname] = evaluate(scenes, num, ref, timer)

    # Numerics.for_tolerance (if the package has it): measured against its target
    out["for_tolerance"] = []
    if hasattr(v.Numerics, "for_tolerance"):
        for tol in cfg["for_tolerance"]:
            num = v.Numerics.for_tolerance(tol).with_(continuum=False)
            r = evaluate(scenes, num, ref, timer)
            r["tolerance"] = tol
            r["met"] = r["error"] is not None and r["error"] <= tol
            out["for_tolerance"].append(r)
            _log(f"for_tolerance({tol:g}) -> {num.steps}/{num.elements}: error {r['error']}")
        out["for_tolerance_scan"] = for_tolerance_scan(scenes, ref, *cfg["for_tolerance_scan"])
        em = getattr(getattr(v, "numerics", None), "ERROR_MODEL", None)
        out["package_error_model"] = em

    # continuum path, table 4.1
    out["continuum"] = continuum_ladder(specs, cfg, timer)
    out["table_4_1"] = table_4_1(cfg["table_steps"])

    timer.passes()
    for g in out["integrators"].values():
        rows = g["settings"]
        front = pareto([r["seconds_per_impact"] for r in rows], [_num(r["error"]) for r in rows])
        for i, r in enumerate(rows):
            r["on_front"] = i in front
        g["front"] = [{k: rows[i][k] for k in ("steps", "elements", "seconds_per_impact",
                                               "error", "e_z_error_max", "e_x_error_max")}
                      for i in front]

    out["derived"] = derive(out, floors, cfg, scenes, ref, timer)
    out["load_average"] = {"start": load_start, "end": load_average()}
    out["total_seconds"] = time.perf_counter() - t_start
    return out

