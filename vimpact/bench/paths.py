"""Cost per impact of each kernel path against the general element kernel.

Run: ``vimpact bench paths [--quick] [--out DIR]``; the full-size run of the
repository is ``python -m benchmarks.paths`` (``benchmarks/results/``).

- Kelvin-Voigt normal-only at equal accuracy (1e-6 on e_z against the
  closed-form continuum solution): the continuum 1-DOF path
  against the element kernel (target: >= 50x);
- specialization at equal numerics: each scene's specialized element kernel
  against the general kernel compiled with the tangential problem and the
  arms on (and the rows' own dashpot flag, :func:`general_spec`) run on the
  same inputs; the normal results must agree.

Kernel time only (inputs packed once, median of repeats, one numba thread).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

import vimpact as v
from vimpact.engine.columns import SceneColumns
from vimpact.engine.pack import CONTINUUM_MAX_STEPS, element_arrays
from vimpact.engine.routing import choose_path
from vimpact.kernels import continuum_kv as continuum
from vimpact.kernels import elements as kernel
from vimpact.kernels import layout
from vimpact.reference.closed_forms import kelvin_voigt_continuum

from .machine import (
    element_spec,
    figure,
    machine_info,
    ratio_spread,
    save_figure,
    time_samples,
    use_agg,
)

TITLE = "cost per impact of each kernel path vs the general element kernel"

def general_spec(spec: kernel.KernelSpec) -> kernel.KernelSpec:
    """Return the general element kernel for ``spec``.

    The element kernel with the tangential problem and the arms on (full
    stick), and the dashpot flag of ``spec``: the dashpot flag also decides
    how an element in contact for part of a step is weighed (only with a
    dashpot is the normal force discontinuous at entry and exit), so it is
    not only a folded branch and must match the rows.
    """
    return kernel.KernelSpec(layout.VERLET, True, 0, True, spec.dashpot, False)


def _timed(call, repeats: int, per: float) -> tuple[float, list[float]]:
    """Median of ``repeats`` wall times of ``call()`` divided by ``per``, and the samples."""
    samples = [t / per for t in time_samples(call, repeats)]
    return float(np.median(samples)), samples


def _kv_normal(quick: bool) -> dict:
    """Kernel time only (inputs packed once).

    The Python layer around a batch is the same for both paths and would hide the kernels'
    ratio.
    """
    q1 = np.geomspace(1e-3, 10.0, 4 if quick else 16)
    scenes = [v.Scene.from_dimensionless(q, 0.5, tangential="none") for q in q1]
    repeat = 1 if quick else 64  # the continuum batch is microseconds: amortize the launch
    exact = np.array([kelvin_voigt_continuum(q).e_z for q in q1])
    elements = v.Numerics(continuum=False, **({"steps": 400, "elements": 80} if quick else
                                              {"steps": 8000, "elements": 1600}))
    settings = {"continuum rtol=1e-7": (v.Numerics(rtol=1e-7), _continuum_call, repeat),
                f"elements {elements.steps}/{elements.elements}": (elements, _element_call, 1)}
    out: dict[str, dict[str, Any]] = {}
    for name, (numerics, make, k) in settings.items():
        call, result = make(scenes * k, numerics)
        call()  # compile / load
        e_z = np.abs(result()[:len(scenes), layout.OUT_VZ_END])
        t, samples = _timed(call, 1 if quick else 3, k * len(scenes) / 1e6)
        out[name] = {"path": choose_path(scenes[0], numerics).name,
                     "max_e_z_error": float(np.max(np.abs(e_z - exact))),
                     "us_per_impact": t, "us_per_impact_samples": samples}
    a, b = (x["us_per_impact"] for x in out.values())
    return {"settings": out, "speedup": b / a}


def _continuum_call(scenes, numerics: v.Numerics):
    tau0 = np.array([s.material.dashpot_time / s.hertz.T for s in scenes])
    out = np.zeros((len(scenes), layout.N_OUT))
    return ((lambda: continuum.kv_normal_batch(tau0, numerics.rtol, CONTINUUM_MAX_STEPS, out)),
            (lambda: out))


def _element_call(scenes, numerics: v.Numerics, spec=None):
    """Return a call of an element kernel and its output rows.

    The element kernel ``spec`` (default: the scenes' own) on inputs packed
    for the scenes' own kernel: a call and the output rows.
    """
    own = element_spec(scenes[0], numerics)
    a = element_arrays(SceneColumns.from_scenes(scenes), numerics, own)
    n = len(scenes)
    out = np.zeros((n, layout.N_OUT))
    rec = np.zeros((n, 0, layout.N_REC))
    run = kernel.element_kernel(spec or own)

    def call():
        run(a["tau0"], a["g"], a["tau"], a["n_arms"], a["kappa"], a["mu_t"], a["mu"], a["h"],
            a["n_elem"], a["dxi"], a["max_steps"], rec, 1, out)
    return call, (lambda: out)


def _specialization(quick: bool) -> dict:
    numerics = v.Numerics(continuum=False, **({"steps": 200, "elements": 40} if quick else {}))
    n = 4 if quick else 32
    q1 = np.geomspace(1e-2, 3.0, n)
    cases = {
        "kelvin_voigt normal": [v.Scene.from_dimensionless(q, 0.5, tangential="none") for q in q1],
        "kelvin_voigt oblique": [v.Scene.from_dimensionless(q, 0.5) for q in q1],
        "standard_solid normal": [v.Scene.from_dimensionless(q, 0.5, 1.0, tangential="none")
                                  for q in q1],
        "standard_solid oblique": [v.Scene.from_dimensionless(q, 0.5, 1.0) for q in q1],
    }
    out = {}
    for name, scenes in cases.items():
        special, special_out = _element_call(scenes, numerics)
        general, general_out = _element_call(
            scenes, numerics, general_spec(element_spec(scenes[0], numerics)))
        special()
        general()
        diff = float(np.max(np.abs(special_out()[:, layout.OUT_VZ_END]
                                   - general_out()[:, layout.OUT_VZ_END])))
        t_spec, s_spec = _timed(special, 1 if quick else 3, n / 1e6)
        t_gen, s_gen = _timed(general, 1 if quick else 3, n / 1e6)
        out[name] = {"path": choose_path(scenes[0], numerics).name,
                     "us_per_impact": t_spec, "us_per_impact_samples": s_spec,
                     "general_us_per_impact": t_gen, "general_us_per_impact_samples": s_gen,
                     "speedup": t_gen / t_spec, "max_e_z_difference": diff}
    return out


def run(quick: bool = False) -> dict:
    """Measure the continuum and element paths and the specialization; return the record."""
    threads = numba.get_num_threads()
    numba.set_num_threads(1)  # per-core cost; the machine is shared
    try:
        return {"machine": machine_info(), "threads": 1,
                "kelvin_voigt_normal_equal_accuracy": _kv_normal(quick),
                "specialization_equal_numerics": _specialization(quick)}
    finally:
        numba.set_num_threads(threads)


def plot(data: dict, path) -> None:
    """Horizontal bars: time per impact of each path and of the general kernel (log scale)."""
    use_agg()
    import matplotlib.pyplot as plt

    spec = data["specialization_equal_numerics"]
    kv = data["kelvin_voigt_normal_equal_accuracy"]["settings"]
    labels = list(spec) + list(kv)
    general = [d["general_us_per_impact"] for d in spec.values()] + [np.nan] * len(kv)
    special = [d["us_per_impact"] for d in spec.values()] + [d["us_per_impact"] for d in kv.values()]
    fig, ax = plt.subplots(figsize=(8, 4))
    y = np.arange(len(labels))
    ax.barh(y + 0.2, general, 0.4, label="general element kernel (tangential and arms on)")
    ax.barh(y - 0.2, special, 0.4, label="specialized path")
    ax.set_yticks(y, labels)
    ax.set_xscale("log")
    ax.set_xlabel("time per impact, µs")
    ax.set_title("Cost per impact by path (KV normal rows: equal accuracy 1e-6 on e_z)")
    ax.legend(fontsize=8)
    save_figure(fig, path)


def figures(data: dict) -> dict:
    """Time per impact of each path, the continuum's speedup at equal accuracy and its e_z error."""
    out = {}
    kv = data["kelvin_voigt_normal_equal_accuracy"]
    spreads = []
    for name, d in kv["settings"].items():
        key = "kv_normal_" + name.replace(" ", "_").replace("/", "_").replace("=", "_")
        f = figure(d["us_per_impact"], "us", samples=d.get("us_per_impact_samples"))
        spreads.append(f["spread"])
        out[f"{key}_us_per_impact"] = f
        out[f"{key}_e_z_error"] = figure(d["max_e_z_error"], "-", kind="accuracy")
    out["kv_normal_continuum_speedup"] = figure(kv["speedup"], "-", better="higher",
                                                rel_spread=ratio_spread(*spreads))
    for name, d in data["specialization_equal_numerics"].items():
        out[name.replace(" ", "_") + "_us_per_impact"] = figure(
            d["us_per_impact"], "us", samples=d.get("us_per_impact_samples"))
    return out


def report(data: dict) -> str:
    """Time per impact and error of each path; the speedups."""
    kv = data["kelvin_voigt_normal_equal_accuracy"]
    lines = [f"{name:24s} {d['us_per_impact']:10.1f} us/impact  max e_z error "
             f"{d['max_e_z_error']:.1e}" for name, d in kv["settings"].items()]
    lines.append(f"continuum speedup at equal accuracy: {kv['speedup']:.0f}x")
    for name, d in data["specialization_equal_numerics"].items():
        lines.append(f"{name:24s} {d['path']:45s} {d['speedup']:.2f}x vs general "
                     f"(e_z difference {d['max_e_z_difference']:.1e})")
    return "\n".join(lines)
