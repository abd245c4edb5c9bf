"""What accuracy costs in time: error versus wall time per impact for every
integrator, its Pareto front, the presets, and an error model to pick numerics.

Run: ``vimpact bench accuracy [--quick] [--out DIR]`` (writes ``DIR/accuracy.json``
and ``accuracy.png``); the full-size run of the repository is
``python -m benchmarks.accuracy`` (``benchmarks/results/accuracy.json`` and
``accuracy_pareto.png``).

- Scenes: oblique impacts (``v_c0 != 0``, so ``e_x`` is computed), Kelvin-Voigt
  at ``nu = 0`` and ``0.5`` and the standard solid at ``Q2 = 0.1`` and ``10``
  (``nu = 0.5``), ``Q1`` log-spaced over ``[1e-3, 10]``.
- Reference: ``e_z`` and ``e_x`` of every scene from the exact full-stick
  continuum kernel (:func:`vimpact.kernels.continuum_maxwell.maxwell_stick_batch`,
  every rheology, the limit of the element row as steps and elements grow;
  docs/physics.md, continuum limit) at rtol 1e-12 (:func:`continuum_restitution`);
  its uncertainty per scene is ``|value(rtol 1e-12) - value(rtol 1e-10)|``
  (1e-13 to 3e-9: below it an error is not resolved, see the
  ``verifiable`` flags). Independent check: on the Kelvin-Voigt scenes its
  ``e_z`` against the closed form
  :func:`vimpact.reference.closed_forms.kelvin_voigt_continuum` (largest
  difference recorded in the JSON).
- Settings (element path, ``Numerics(continuum=False)``: the full-stick
  scenes would otherwise take a continuum path): for each integrator a
  coarse 2-D grid of (steps per ``t_H``,
  elements per ``a_H``). For each setting: max and median ``|e_z error|`` and
  ``|e_x error|`` over the scenes and the wall time per impact of
  ``vimpact.simulate_batch`` on all scenes at once (numba threads: 2; the
  kernels are compiled by a warm-up call first; cheap settings run on the
  scenes repeated to a batch of about 0.2 s; median of 3 samples taken in
  separate passes over all settings, see :class:`Timer`).
- Derived: Pareto front per integrator (error ``= max(max |e_z err|, max |e_x
  err|)`` versus time per impact), the cheapest setting per tolerance, the
  explicit-Euler / Verlet time ratio, observed orders, the thesis's table
  4.1 for all integrators, per integrator a fitted error model ``err = a /
  steps^p + b / elements^q`` (least squares in logs, for e_z, e_x and their
  max), an envelope of the same form with ``p = 1``, ``q = 2`` that bounds
  every grid point, and a time model ``t = c0 + cs steps + c1 steps
  elements``; the (steps, elements) the Verlet models pick per tolerance,
  run and measured; ``Numerics.for_tolerance`` and every preset in
  ``vimpact.PRESETS`` measured on the same scenes on the element path
  (``presets``, ``for_tolerance``; and, untimed, ``for_tolerance`` at 19
  tolerances from 1e-3 to 1e-6, ``for_tolerance_scan``), and the presets as routed
  (``presets_as_routed``: most of these full-stick scenes take the continuum
  path, a standard solid with a stiff arm the element path); suggested presets.
- Also: the continuum path (Kelvin-Voigt normal-only, ``tangential="none"``)
  at several ``rtol``, and the thesis's table 4.1 (elastic normal impact,
  element path) for all three integrators.

Explicit Euler gains energy; ``simulate`` flags such a passive impact as
``unstable`` with NaN outputs, so for those rows (table 4.1) the kernel's own
numbers are read (:func:`raw_restitution`).

The machine is shared: times carry the load average at start and end.
Nothing here asserts a time.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numba
import numpy as np

import vimpact as v
from vimpact.engine.result import FINISHED
from vimpact.reference.closed_forms import kelvin_voigt_continuum

from .machine import figure, load_average, machine_info, progress, save_figure, use_agg

TITLE = "what accuracy costs: error vs time per impact for every integrator, presets, continuum"

TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7)
INTEGRATORS = ("verlet", "symplectic_euler", "euler")
THESIS_TABLE_4_1 = {500: 1.1254, 1000: 0.5608, 5000: 0.1119, 10000: 0.0559}  # percent
THREADS = 2


def _pow2(start: int, stop: int) -> list[int]:
    out = [start]
    while out[-1] * 2 <= stop:
        out.append(out[-1] * 2)
    return out


def _sqrt2(start: int, stop: int) -> list[int]:
    """``start * 2^(k/2)`` up to ``stop``, rounded."""
    n = int(round(2 * math.log2(stop / start)))
    return [int(round(start * 2 ** (k / 2))) for k in range(n + 1)]


#: scenes, ladders, continuum tolerances, timing.
#: A ladder is the base grid ``steps x elements`` (factor 2, products capped)
#: and optionally a refinement: the factor-sqrt(2) grid in a band of
#: ``steps / elements`` where the front lies.
CONFIGS = {
    "full": dict(
        q1=[1e-3, 1e-2, 1e-1, 1.0, 10.0],
        kv_nu=[0.0, 0.5], sls_q2=[0.1, 10.0], sls_nu=0.5,
        ladders={
            "verlet": dict(steps=_pow2(125, 8000), elements=_pow2(25, 1600), cap=8000 * 1600,
                           refine=(_sqrt2(125, 8000), _sqrt2(25, 1600), (2.5, 40.0))),
            "symplectic_euler": dict(steps=_pow2(125, 32000), elements=_pow2(25, 1600),
                                     cap=16000 * 1600),
            "euler": dict(steps=_pow2(500, 128000), elements=_pow2(25, 1600), cap=32000 * 1600),
        },
        rtols=[1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
        table_steps=list(THESIS_TABLE_4_1), for_tolerance=[1e-3, 1e-4, 1e-5, 1e-6],
        for_tolerance_scan=(1e-3, 1e-6, 19),
        model_checks=[1e-3, 1e-4, 1e-5],
        repeats=3, target_batch_seconds=0.2, max_copies=256,
    ),
    "quick": dict(
        # Kelvin-Voigt only: a standard solid here would compile two element kernels
        # (explicit and semi-implicit Euler with arms, about 50 s on a fresh clone) that
        # nothing else in the default test run needs
        scenes=[(0.1, 0.5, None), (1.0, 0.0, None), (0.3, 0.25, None)],
        ladders={
            "verlet": dict(steps=[100, 200], elements=[20, 40], cap=200 * 40,
                           refine=([141], [28], (2.5, 40.0))),
            "symplectic_euler": dict(steps=[100, 200], elements=[20], cap=200 * 20),
            "euler": dict(steps=[200, 400], elements=[20], cap=400 * 20),
        },
        rtols=[1e-4, 1e-8],
        table_steps=[500, 1000], for_tolerance=[1e-3], for_tolerance_scan=(1e-3, 1e-4, 3),
        model_checks=[1e-3],
        repeats=1, target_batch_seconds=0.0, max_copies=1,
    ),
}


# ---------------------------------------------------------------- helpers
def _f(x) -> float | None:
    """JSON-safe float (None for NaN/inf)."""
    x = float(x)
    return x if math.isfinite(x) else None


class Timer:
    """Wall time per impact of ``simulate_batch``, robust on a shared machine.

    - A parallel launch waits for its second thread to be scheduled (several
      ms when another process holds the other core), which would swamp a
      small batch of cheap impacts. So a setting is timed on its scenes
      repeated ``copies`` times, enough for about ``target_batch_seconds``
      (as in a table sweep); its first call (whose results are used) also
      counts as a sample when no copies are needed.
    - A burst of load lasting a second would spoil every repeat taken in a
      row, so the repeats are taken in separate passes over all settings
      (:meth:`passes`), alternately forward and backward; the time of a
      setting is the median of its ``repeats`` samples.
    """

    def __init__(self, cfg):
        self.cfg = cfg
        self.jobs = []  # (row, scenes, numerics, copies)

    @staticmethod
    def _once(batch, numerics):
        t0, c0 = time.perf_counter(), time.process_time()
        df = v.simulate_batch(batch, numerics)
        return df, time.perf_counter() - t0, time.process_time() - c0

    def first(self, scenes, numerics, row: dict):
        """Run once (results returned), calibrate the batch, take one sample."""
        cfg = self.cfg
        df, wall, cpu = self._once(scenes, numerics)
        copies, t, c = 1, wall, cpu
        while t < cfg["target_batch_seconds"] and copies < cfg["max_copies"]:
            copies = min(cfg["max_copies"],
                         copies * max(2, math.ceil(cfg["target_batch_seconds"] / t)))
            _, t, c = self._once(scenes * copies, numerics)
        n = len(scenes) * copies
        row.update(timed_batch_size=n, first_call_seconds_per_impact=wall / len(scenes),
                   seconds_samples=[t / n], cpu_seconds_samples=[c / n])
        self._finish(row)
        self.jobs.append((row, scenes, numerics, copies))
        return df

    def more(self, row_job) -> None:
        row, scenes, numerics, copies = row_job
        _, t, c = self._once(scenes * copies, numerics)
        row["seconds_samples"].append(t / row["timed_batch_size"])
        row["cpu_seconds_samples"].append(c / row["timed_batch_size"])
        self._finish(row)

    def repeat_now(self, row: dict) -> None:
        """All repeats of the last setting at once (for late extras)."""
        job = next(j for j in reversed(self.jobs) if j[0] is row)
        while len(row["seconds_samples"]) < self.cfg["repeats"]:
            self.more(job)

    def passes(self) -> None:
        for k in range(self.cfg["repeats"] - 1):
            jobs = self.jobs if k % 2 else self.jobs[::-1]
            for job in jobs:
                if len(job[0]["seconds_samples"]) < self.cfg["repeats"]:
                    self.more(job)
            _log(f"timing pass {k + 2} of {self.cfg['repeats']} done")

    @staticmethod
    def _finish(row: dict) -> None:
        row["seconds_per_impact"] = float(np.median(row["seconds_samples"]))
        row["cpu_seconds_per_impact"] = float(np.median(row["cpu_seconds_samples"]))
        row["repeats"] = len(row["seconds_samples"])


def raw_restitution(scenes, numerics) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``e_z``, ``e_x`` and the energy ratio straight from the kernel rows.

    ``simulate_batch`` reports a passive impact that gained more than 1e-6 of
    its energy as status ``unstable`` with NaN outputs. Explicit Euler gains
    energy at every practical step on weakly damped scenes, and its
    accuracy is what this benchmark measures, so for those rows the kernel's
    own numbers are read here (internal :func:`vimpact.engine.pack.run_path`
    on the routed rows; the rows are counted as ``unstable_rows``)."""
    from vimpact.engine.columns import SceneColumns
    from vimpact.engine.pack import run_path
    from vimpact.engine.routing import route
    from vimpact.kernels import layout

    scenes = list(scenes)
    cols = SceneColumns.from_scenes(scenes)
    routes = route(cols, numerics)
    out = np.zeros((len(scenes), layout.N_OUT))
    out[:, layout.OUT_STATUS] = -1.0  # rows no kernel ran
    for k, path in enumerate(routes.paths):
        idx = np.flatnonzero(routes.group == k)
        sub = np.zeros((len(idx), layout.N_OUT))
        run_path(path, cols.take(idx), numerics, np.zeros((len(idx), 0, layout.N_REC)), 1, sub)
        out[idx] = sub
    ok = out[:, layout.OUT_STATUS] == layout.STATUS_OK
    vz = np.where(ok, np.abs(out[:, layout.OUT_VZ_END]), np.nan)
    vc = np.where(ok, out[:, layout.OUT_VC_END], np.nan)
    ez = vz
    ex = np.array([abs(c) if s.computes_tangential else np.nan for s, c in zip(scenes, vc)])
    energy = []
    for s, z, c in zip(scenes, vz, vc):
        vx, om = s.tangential_end_state(c if s.computes_tangential else 1.0)
        kin = 0.5 * (s.m * ((z * s.v_z0) ** 2 + vx**2) + s.Theta * om**2)
        energy.append(kin / s.kinetic_energy)
    return ez, ex, np.array(energy)


def _log(msg: str) -> None:
    progress(msg)


def _scene_list(cfg) -> list[dict]:
    if "scenes" in cfg:
        specs = [dict(Q1=q, nu=nu, Q2=q2) for q, nu, q2 in cfg["scenes"]]
    else:
        specs = [dict(Q1=q, nu=nu, Q2=None) for nu in cfg["kv_nu"] for q in cfg["q1"]]
        specs += [dict(Q1=q, nu=cfg["sls_nu"], Q2=q2) for q2 in cfg["sls_q2"] for q in cfg["q1"]]
    for s in specs:
        s["model"] = "kelvin_voigt" if s["Q2"] is None else "standard_solid"
    return specs


def _scenes(specs, **kw) -> list:
    return [v.Scene.from_dimensionless(s["Q1"], s["nu"], s["Q2"], **kw) for s in specs]


def pareto(times, errors) -> list[int]:
    """Indices of the non-dominated points (faster and more accurate than all
    others in one respect), sorted by time; non-finite errors never qualify."""
    order = sorted((i for i in range(len(times)) if math.isfinite(errors[i])),
                   key=lambda i: (times[i], errors[i]))
    front, best = [], math.inf
    for i in order:
        if errors[i] < best:
            front.append(i)
            best = errors[i]
    return front


def _slope(x, err, floor) -> dict:
    """Observed order: minus the least-squares slope of log err over log x,
    on the points with err above 5x the reference's uncertainty ``floor``."""
    x, err = np.asarray(x, float), np.asarray(err, float)
    use = np.isfinite(err) & (err > 5.0 * floor)
    local = [_f(-math.log(err[i + 1] / err[i]) / math.log(x[i + 1] / x[i]))
             for i in range(len(x) - 1) if err[i] > 0 and err[i + 1] > 0]
    order = None
    if use.sum() >= 2:
        order = _f(-np.polyfit(np.log(x[use]), np.log(err[use]), 1)[0])
    return {"order": order, "points_used": int(use.sum()),
            "x": x.tolist(), "error": [_f(e) for e in err], "local_orders": local}


def fit_error_model(steps, elements, err, floor, p0: float) -> dict:
    """Least squares in logs of ``err = a / steps^p + b / elements^q`` on the
    points with err above 3x the reference's uncertainty ``floor``."""
    from scipy.optimize import least_squares

    S, E, y = (np.asarray(a, float) for a in (steps, elements, err))
    use = np.isfinite(y) & (y > 3.0 * floor)
    S, E, y = S[use], E[use], y[use]
    if len(y) < 5:
        return {"fitted": False, "points_used": int(len(y))}

    def model(x, S, E):
        return np.exp(x[0]) * S ** -x[1] + np.exp(x[2]) * E ** -x[3]

    def resid(x):
        return np.log(model(x, S, E)) - np.log(y)

    best = None
    for p in (p0, 1.0, 2.0):
        for q in (1.0, 2.0, 3.0):
            la = np.log(np.median(y * S ** p))
            lb = np.log(np.median(y * E ** q)) - 2.0
            for x0 in ([la, p, lb, q], [la - 2.0, p, lb + 2.0, q]):
                r = least_squares(resid, x0, bounds=([-60, 0.2, -60, 0.2], [60, 5, 60, 5]))
                if best is None or r.cost < best.cost:
                    best = r
    res = resid(best.x) / math.log(10.0)
    ts, te = np.exp(best.x[0]) * S ** -best.x[1], np.exp(best.x[2]) * E ** -best.x[3]
    share_s, share_e = float(np.max(ts / (ts + te))), float(np.max(te / (ts + te)))
    return {"fitted": True,
            "steps_term_share_max": share_s, "elements_term_share_max": share_e,
            "steps_term_resolved": share_s > 0.2, "elements_term_resolved": share_e > 0.2,
            "exponent_at_bound": bool(min(best.x[1], best.x[3]) < 0.21 or
                                      max(best.x[1], best.x[3]) > 4.95),
            "a": _f(math.exp(best.x[0])), "p": _f(best.x[1]),
            "b": _f(math.exp(best.x[2])), "q": _f(best.x[3]),
            "points_used": int(len(y)), "rms_log10_residual": _f(np.sqrt(np.mean(res**2))),
            "max_log10_residual": _f(np.max(np.abs(res))),
            "formula": "err = a / steps**p + b / elements**q"}


def fit_envelope(steps, elements, err, floor, p: float, q: float) -> dict:
    """``err <= a / steps^p + b / elements^q`` at fixed exponents: least squares
    in logs for ``a``, ``b``, then both scaled up until the model bounds every
    point above 3x ``floor`` (the form ``Numerics.for_tolerance`` uses)."""
    from scipy.optimize import least_squares

    S, E, y = (np.asarray(a, float) for a in (steps, elements, err))
    use = np.isfinite(y) & (y > 3.0 * floor)
    S, E, y = S[use], E[use], y[use]
    if len(y) < 3:
        return {"fitted": False, "points_used": int(len(y))}

    def model(x):
        return np.exp(x[0]) * S**-p + np.exp(x[1]) * E**-q

    r = least_squares(lambda x: np.log(model(x)) - np.log(y),
                      [np.log(np.median(y * S**p)), np.log(np.median(y * E**q))])
    scale = float(np.max(y / model(r.x)))
    a, b = math.exp(r.x[0]), math.exp(r.x[1])
    out = {"fitted": True, "p": p, "q": q, "a_fit": a, "b_fit": b, "scale": scale,
           "a": a * scale, "b": b * scale, "points_used": int(len(y)),
           "formula": "err <= a / steps**p + b / elements**q on every grid point"}
    out["for_tolerance_rule"] = {
        f"{tol:g}": {"steps": math.ceil((2 * out["a"] / tol) ** (1 / p)),
                     "elements": math.ceil((2 * out["b"] / tol) ** (1 / q))}
        for tol in TOLERANCES}
    return out


def fit_time_model(steps, elements, seconds) -> dict:
    """``t = c0 + cs steps + c1 steps elements`` (non-negative, relative least squares)."""
    from scipy.optimize import nnls

    S, E, t = (np.asarray(a, float) for a in (steps, elements, seconds))
    A = np.column_stack([np.ones_like(t), S, S * E]) / t[:, None]
    c, _ = nnls(A, np.ones_like(t))
    rel = (c[0] + c[1] * S + c[2] * S * E) / t - 1.0
    return {"c0": _f(c[0]), "cs": _f(c[1]), "c1": _f(c[2]),
            "rms_relative_residual": _f(np.sqrt(np.mean(rel**2))),
            "max_relative_residual": _f(np.max(np.abs(rel))),
            "formula": "seconds_per_impact = c0 + cs * steps + c1 * steps * elements"}


def _model_time(m: dict, S, E):
    return m["c0"] + m["cs"] * S + m["c1"] * S * E


def _model_err(m: dict, S, E):
    return m["a"] * S ** -m["p"] + m["b"] * E ** -m["q"]


def model_pick(mz: dict, mx: dict, tmodel: dict, tol: float, grid_max: tuple[int, int],
               floor: float) -> dict:
    """Cheapest (steps, elements) by the fitted models with both errors <= tol."""
    if not (mz.get("fitted") and mx.get("fitted")):
        return {"pick": None, "why": "no model"}
    S = np.unique(np.round(np.geomspace(16, 4e6, 700)))[:, None]
    E = np.unique(np.round(np.geomspace(8, 1e6, 700)))[None, :]
    ok = np.maximum(_model_err(mz, S, E), _model_err(mx, S, E)) <= tol
    if not ok.any():
        return {"pick": None, "why": "beyond 4e6 steps / 1e6 elements"}
    cost = np.where(ok, _model_time(tmodel, S, E), np.inf)
    i, j = np.unravel_index(np.argmin(cost), cost.shape)
    s, e = int(S[i, 0]), int(E[0, j])
    return {"steps": s, "elements": e,
            "predicted_e_z_error": _f(_model_err(mz, s, e)),
            "predicted_e_x_error": _f(_model_err(mx, s, e)),
            "predicted_seconds_per_impact": _f(_model_time(tmodel, s, e)),
            "extrapolated": bool(s > grid_max[0] or e > grid_max[1]),
            "below_reference_uncertainty": bool(tol < floor)}


# ---------------------------------------------------------------- measurement
#: The reference: the full-stick continuum kernel at this rtol (about 1e-10 on e_z, e_x) ...
REFERENCE_RTOL = 1e-12
#: ... and its uncertainty per scene: the distance to a run at this looser rtol.
REFERENCE_CHECK_RTOL = 1e-10
REFERENCE_MAX_STEPS = 10_000_000


def continuum_restitution(scenes, rtol: float) -> tuple[np.ndarray, np.ndarray]:
    """``e_z`` and ``e_x`` of full-stick impacts from the exact continuum kernel.

    Calls :func:`vimpact.kernels.continuum_maxwell.maxwell_stick_batch` directly
    (every rheology; no routing, no element row), with the kernel inputs built
    from :class:`vimpact.engine.columns.SceneColumns` as the engine builds them.
    The reference of ``benchmarks/element_orders.py`` and of the tolerance tests
    too: routing sends scenes with an arm faster than 1e-3 T to elements, but the
    kernel itself is exact for them (tests/kernels/test_continuum_maxwell.py checks
    it against scipy).

    Parameters
    ----------
    scenes : full-stick scenes (``mu = inf``)
    rtol : relative tolerance of the adaptive Dormand-Prince 5(4) solver, -

    Returns
    -------
    e_z, e_x : per scene, dimensionless (``e_x`` is ``NaN`` where the scene
        computes no tangential problem)

    Raises
    ------
    RuntimeError
        if a row does not finish with status ok.
    """
    from vimpact.engine.columns import SceneColumns
    from vimpact.engine.pack import arm_arrays
    from vimpact.kernels import layout
    from vimpact.kernels.continuum_maxwell import maxwell_stick_batch

    cols = SceneColumns.from_scenes(list(scenes))
    g, tau, n_arms = arm_arrays(cols)
    out = np.zeros((len(cols), layout.N_OUT))
    maxwell_stick_batch(cols.dashpot_time / cols.T, g, tau, n_arms, cols.kappa,
                        cols.contact_mass_factor, cols.computes_tangential, rtol,
                        REFERENCE_MAX_STEPS, out)
    bad = out[:, layout.OUT_STATUS] != layout.STATUS_OK
    if bad.any():
        raise RuntimeError(f"continuum reference (rtol {rtol:g}) failed on rows "
                           f"{np.flatnonzero(bad).tolist()}: status "
                           f"{sorted(set(out[bad, layout.OUT_STATUS].tolist()))}")
    e_z = -out[:, layout.OUT_VZ_END]
    e_x = np.where(cols.computes_tangential, np.abs(out[:, layout.OUT_VC_END]), np.nan)
    return e_z, e_x


def reference(specs, scenes) -> dict:
    """``e_z`` and ``e_x`` of every scene from the continuum kernel at
    :data:`REFERENCE_RTOL`; uncertainty per scene ``|ref(1e-12) - ref(1e-10)|``;
    on the Kelvin-Voigt scenes ``e_z`` is checked against the closed form."""
    t0 = time.perf_counter()
    ez, ex = continuum_restitution(scenes, REFERENCE_RTOL)
    t1 = time.perf_counter()
    ez_check, ex_check = continuum_restitution(scenes, REFERENCE_CHECK_RTOL)
    uz, ux = np.abs(ez - ez_check), np.abs(ex - ex_check)
    kv = np.array([s["model"] == "kelvin_voigt" for s in specs])
    closed = np.array([kelvin_voigt_continuum(s["Q1"]).e_z if s["model"] == "kelvin_voigt"
                       else np.nan for s in specs])
    kv_diff = np.abs(ez - closed)[kv]
    floor_x, floor_z = float(ux.max()), float(uz.max())
    rtols = f"rtol {REFERENCE_RTOL:g}"
    return {
        "e_z": ez, "e_x": ex, "u_z": uz, "u_x": ux,
        "json": {
            "kernel": "vimpact.kernels.continuum_maxwell.maxwell_stick_batch (full stick)",
            "rtol": REFERENCE_RTOL, "check_rtol": REFERENCE_CHECK_RTOL,
            "seconds_per_impact": (t1 - t0) / len(scenes),
            "e_z_source": f"continuum kernel ({rtols}), every scene",
            "e_x_source": f"continuum kernel ({rtols}), every scene",
            "e_x_uncertainty_max": floor_x,
            "e_x_uncertainty_median": float(np.median(ux)),
            "e_z_uncertainty_max": floor_z,
            "e_z_uncertainty_median": float(np.median(uz)),
            "kelvin_voigt_closed_form_e_z_difference_max":
                _f(kv_diff.max()) if kv.any() else None,
            "kelvin_voigt_scenes": int(kv.sum()),
            "e_x_floor": floor_x, "e_z_floor": floor_z,
            "note": (f"reference = the exact full-stick continuum kernel (the limit of the "
                     f"element row as steps and elements grow) at {rtols}; uncertainty per "
                     f"scene = |value(rtol {REFERENCE_RTOL:g}) - value(rtol "
                     f"{REFERENCE_CHECK_RTOL:g})|, an upper estimate of the reference's "
                     "own error. Floors (errors below them are not resolved here): "
                     "e_x_floor, e_z_floor = the largest of these over the scenes. "
                     "Independent check: on the Kelvin-Voigt scenes the reference's e_z "
                     "against the closed form kelvin_voigt_continuum(Q1).e_z "
                     "(kelvin_voigt_closed_form_e_z_difference_max)."),
        },
    }


def _errors(ez, ex, finished, ref) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``|e_z - ref|``, ``|e_x - ref|`` per scene, ``inf`` where a row did not
    finish (``finished`` false) or gave no finite value; and the rows that count."""
    ok = finished & np.isfinite(ez) & np.isfinite(ex)
    dz = np.where(ok, np.abs(ez - ref["e_z"]), np.inf)
    dx = np.where(ok, np.abs(ex - ref["e_x"]), np.inf)
    return dz, dx, ok


def evaluate(scenes, numerics, ref, timer: Timer) -> dict:
    """Errors over the scenes and (first sample of the) wall time per impact."""
    row = {"integrator": numerics.integrator, "steps": numerics.steps,
           "elements": numerics.elements}
    df = timer.first(scenes, numerics, row)
    ez, ex = df.e_z.to_numpy(), df.e_x.to_numpy()
    unstable = (df.status == "unstable").to_numpy()
    gain = None
    if unstable.any():
        idx = np.flatnonzero(unstable)
        rz, rx, energy = raw_restitution([scenes[i] for i in idx], numerics)
        ez, ex = ez.copy(), ex.copy()
        ez[idx], ex[idx] = rz, rx
        gain = _f(np.nanmax(energy) - 1.0)
    dz, dx, ok = _errors(ez, ex, df.status.isin(FINISHED).to_numpy() | unstable, ref)
    row.update({
        "e_z_error_max": _f(dz.max()), "e_z_error_median": _f(np.median(dz)),
        "e_x_error_max": _f(dx.max()), "e_x_error_median": _f(np.median(dx)),
        "error": _f(max(dz.max(), dx.max())),
        "worst_scene_e_z": int(np.argmax(dz)), "worst_scene_e_x": int(np.argmax(dx)),
        "n_steps_median": float(np.median(df.n_steps)),
        "failed": int((~ok).sum()),
        "unstable_rows": int(unstable.sum()),
        "max_energy_gain_of_unstable_rows": gain,
        "paths": sorted(set(df.path)),
        "rows_per_path": {str(k): int(c) for k, c in df.path.value_counts().sort_index().items()},
        "error_by_path": {str(k): _f(np.maximum(dz, dx)[(df.path == k).to_numpy()].max())
                          for k in sorted(set(df.path))},
    })
    return row


def for_tolerance_scan(scenes, ref, tol_max: float, tol_min: float, n: int) -> dict:
    """``Numerics.for_tolerance(tol)`` on the element path at ``n`` tolerances
    log-spaced over ``[tol_min, tol_max]`` (untimed): the largest error over the
    scenes per tolerance and the worst ``error / tol`` (above 1: missed)."""
    rows = []
    for tol in np.geomspace(tol_max, tol_min, n):
        num = v.Numerics.for_tolerance(float(tol)).with_(continuum=False)
        df = v.simulate_batch(scenes, num)
        dz, dx, _ = _errors(df.e_z.to_numpy(), df.e_x.to_numpy(),
                            df.status.isin(FINISHED).to_numpy(), ref)
        err = float(max(dz.max(), dx.max()))
        rows.append({"tolerance": float(tol), "steps": num.steps, "elements": num.elements,
                     "error": _f(err), "e_z_error_max": _f(dz.max()),
                     "e_x_error_max": _f(dx.max()),
                     "worst_scene": int(np.argmax(np.maximum(dz, dx))),
                     "error_over_tolerance": _f(err / tol), "met": bool(err <= tol)})
    worst = max(rows, key=lambda r: _num(r["error_over_tolerance"]))
    return {"rows": rows, "missed": sum(not r["met"] for r in rows),
            "worst_error_over_tolerance": worst["error_over_tolerance"],
            "worst_tolerance": worst["tolerance"], "worst_scene": worst["worst_scene"],
            "note": "element path (continuum=False), untimed; error = max(max |e_z err|, "
                    "max |e_x err|) over the scenes against the continuum reference"}


def continuum_ladder(specs, cfg, timer: Timer) -> list[dict]:
    """The continuum path on the Kelvin-Voigt scenes made normal-only."""
    kv = [s for s in specs if s["model"] == "kelvin_voigt"]
    if not kv:
        return []
    scenes = _scenes(kv, tangential="none")
    exact = np.array([kelvin_voigt_continuum(s["Q1"]).e_z for s in kv])
    v.simulate_batch(scenes[:2], v.Numerics())  # compile
    out = []
    for rtol in cfg["rtols"]:
        n = v.Numerics(rtol=rtol)
        row = {"rtol": rtol}
        df = timer.first(scenes, n, row)
        err = np.abs(df.e_z.to_numpy() - exact)
        row.update({"e_z_error_max": _f(err.max()), "e_z_error_median": _f(np.median(err)),
                    "n_steps_median": float(np.median(df.n_steps)),
                    "paths": sorted(set(df.path)),
                    "failed": int((~df.status.isin(FINISHED)).sum())})
        out.append(row)
    return out


def table_4_1(steps_list) -> dict:
    """Elastic normal-only impact on the element path (continuum off), elements
    500 per a_H (thesis): |e_z - 1| in percent per integrator; thesis 4.1."""
    elastic = v.Scene(v.Material.elastic(nu=0.5, E=5e10), R=0.2, m=10.0, v_z0=10.0)
    out = {"scene": "elastic, nu = 0.5 (Q1 = 0), normal only, Numerics(continuum=False, "
                    "elements=500)",
           "thesis_percent": {str(n): THESIS_TABLE_4_1[n] for n in steps_list}}
    for name in INTEGRATORS:
        pct, paths, status = [], set(), []
        for n in steps_list:
            num = v.Numerics(integrator=name, steps=n, elements=500, continuum=False)
            r = v.simulate(elastic, num)
            e_z = raw_restitution([elastic], num)[0][0] if r.status == "unstable" else r.e_z
            pct.append(100.0 * abs(e_z - 1.0))
            paths.add(r.path)
            status.append(r.status)
        out[name] = {"percent": dict(zip(map(str, steps_list), pct)),
                     "vimpact_status": dict(zip(map(str, steps_list), status)),
                     "order": _f(-np.polyfit(np.log(steps_list), np.log(np.maximum(pct, 1e-300)),
                                             1)[0]) if len(steps_list) > 1 else None,
                     "paths": sorted(paths)}
    return out


def _ladder(cfg, name) -> list[tuple[int, int, str]]:
    """(steps, elements, "base" or "refined") of one integrator, by steps."""
    lad = cfg["ladders"][name]
    base = {(s, e) for s in lad["steps"] for e in lad["elements"] if s * e <= lad["cap"]}
    out = {k: "base" for k in base}
    if "refine" in lad:
        steps, elements, (lo, hi) = lad["refine"]
        for s in steps:
            for e in elements:
                if lo <= s / e <= hi and s * e <= lad["cap"] and (s, e) not in out:
                    out[(s, e)] = "refined"
    return sorted((s, e, g) for (s, e), g in out.items())


def _num(x) -> float:
    return math.inf if x is None else x


def _orders(rows, floors) -> dict:
    """Observed orders on the base grid along the diagonal (steps = 5
    elements), in steps at the largest elements present for every steps
    value, in elements at the largest steps present for every elements value."""
    rows = [r for r in rows if r["grid"] == "base"]
    steps = sorted({r["steps"] for r in rows})
    elements = sorted({r["elements"] for r in rows})
    have = {(r["steps"], r["elements"]): r for r in rows}
    e_fix = max((e for e in elements if all((s, e) in have for s in steps)), default=None)
    s_fix = max((s for s in steps if all((s, e) in have for e in elements)), default=None)
    lines = {
        "diagonal_steps_eq_5_elements": sorted(k for k in have if k[0] == 5 * k[1]),
        f"steps_at_elements_{e_fix}": [(s, e_fix) for s in steps] if e_fix else [],
        f"elements_at_steps_{s_fix}": [(s_fix, e) for e in elements] if s_fix else [],
    }
    out = {}
    for label, keys in lines.items():
        if len(keys) < 2:
            continue
        axis = 1 if label.startswith("elements_at") else 0
        x = [k[axis] for k in keys]
        out[label] = {
            "axis": "elements" if axis else "steps",
            "e_z": _slope(x, [_num(have[k]["e_z_error_max"]) for k in keys], floors["z"]),
            "e_x": _slope(x, [_num(have[k]["e_x_error_max"]) for k in keys], floors["x"]),
            "error": _slope(x, [_num(have[k]["error"]) for k in keys], floors["both"]),
        }
    return out


def _cheapest(rows, tol, key, by="seconds_per_impact") -> dict | str:
    """The setting with ``row[key] <= tol`` and the least ``row[by]``."""
    ok = [r for r in rows if r[key] is not None and r[key] <= tol]
    if not ok:
        return "not reached"
    r = min(ok, key=lambda r: r[by])
    return {"steps": r["steps"], "elements": r["elements"],
            "seconds_per_impact": r["seconds_per_impact"],
            "model_seconds_per_impact": r.get("model_seconds_per_impact"), "error": r[key]}


def run(quick: bool = False) -> dict:
    cfg = CONFIGS["quick" if quick else "full"]
    numba.set_num_threads(min(THREADS, numba.config.NUMBA_NUM_THREADS))
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
    for s, ez, ex, uz, ux in zip(specs, ref["e_z"], ref["e_x"], ref["u_z"], ref["u_x"]):
        s.update(e_z_ref=float(ez), e_x_ref=float(ex), e_z_uncertainty=float(uz),
                 e_x_uncertainty=float(ux))

    timer = Timer(cfg)
    out = {"machine": machine_info(), "threads": numba.get_num_threads(), "quick": quick,
           "scenes": specs, "theta_ratio": 0.4, "reference": ref["json"],
           "tolerances": list(TOLERANCES), "integrators": {}}

    for name in INTEGRATORS:
        # compile every kernel the scenes need outside the timing
        v.simulate_batch(scenes, v.Numerics(integrator=name, steps=16, elements=8,
                                            continuum=False))
        rows = []
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
    # them), and as routed (most of these full-stick scenes take the continuum path)
    out["presets"], out["presets_as_routed"] = {}, {}
    for pname, num in v.PRESETS.items():
        elements = num.with_(continuum=False)
        v.simulate_batch(scenes, elements.with_(steps=16, elements=8))
        out["presets"][pname] = evaluate(scenes, elements, ref, timer)
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

    # derived numbers
    derived = {}
    models = {}
    for n in INTEGRATORS:
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
                   for n in INTEGRATORS}}
    for tol in TOLERANCES:
        cont = [c for c in out["continuum"] if c["e_z_error_max"] is not None
                and c["e_z_error_max"] <= tol]
        derived["cheapest_e_z_only"][f"{tol:g}"]["continuum_normal_only"] = (
            min(cont, key=lambda c: c["seconds_per_impact"]) if cont else "not reached")
    # the same ranked by the fitted time model (measured errors): robust to timing noise
    derived["cheapest_by_time_model"] = {
        f"{tol:g}": {n: _cheapest(out["integrators"][n]["settings"], tol, "error",
                                  by="model_seconds_per_impact") for n in INTEGRATORS}
        for tol in TOLERANCES}

    def _ratio(tol, by, slow="euler", fast="verlet"):
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
    if "default" in out["presets"]:
        d = out["presets"]["default"]
        e = _cheapest(out["integrators"]["euler"]["settings"], d["error"], "error")
        derived["default_vs_euler_same_error"] = {
            "default_error": d["error"], "default_seconds_per_impact": d["seconds_per_impact"],
            "euler_cheapest_reaching_it": e,
            "euler_over_default_time": (None if isinstance(e, str)
                                        else e["seconds_per_impact"] / d["seconds_per_impact"]),
            "target": "default at <= 1/10 of explicit Euler's time for the same error"}
    derived["orders"] = {n: _orders(out["integrators"][n]["settings"], floors)
                         for n in INTEGRATORS}
    derived["orders"]["elastic_table_4_1"] = {n: out["table_4_1"][n]["order"] for n in INTEGRATORS}
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
    every = [r for n in INTEGRATORS for r in out["integrators"][n]["settings"]
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
    out["derived"] = derived
    out["load_average"] = {"start": load_start, "end": load_average()}
    out["total_seconds"] = time.perf_counter() - t_start
    return out


# ---------------------------------------------------------------- plot
COLOURS = {"verlet": "tab:blue", "symplectic_euler": "tab:green", "euler": "tab:red"}


def plot(data: dict, path: Path) -> None:
    """The Pareto fronts (left), convergence and table 4.1 (top right) and the
    continuum path (bottom right) to ``path``."""
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


# ---------------------------------------------------------------- CLI
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
            cells = [f"{n} {_cell(row[n])}" for n in INTEGRATORS]
            if "continuum_normal_only" in row:
                c = row["continuum_normal_only"]
                cells.append("continuum " + (c if isinstance(c, str) else
                                             f"rtol {c['rtol']:g} "
                                             f"{c['seconds_per_impact'] * 1e6:.3g} us"))
            lines.append(f"  {tol}: " + "; ".join(cells)
                         + ("" if row.get("verifiable", True) else " (below the reference's uncertainty)"))
    for tol, r in d["euler_over_verlet_time"].items():
        lines.append(f"euler/verlet time at {tol}: measured {r['measured'].get('ratio')}, "
                     f"time model {r['time_model'].get('ratio')}")
    for pname, p in data["presets"].items():
        lines.append(f"preset {pname}: {p['integrator']} {p['steps']}/{p['elements']}: error "
                     f"{p['error']:.2e} (e_z {p['e_z_error_max']:.1e}, "
                     f"e_x {p['e_x_error_max']:.1e})"
                     f" @ {p['seconds_per_impact'] * 1e3:.3g} ms")
    for pname, p in data.get("presets_as_routed", {}).items():
        paths = ", ".join(f"{k} x{c}" for k, c in p["rows_per_path"].items())
        lines.append(f"preset {pname} as routed ({paths}): error {p['error']:.2e} "
                     f"(e_z {p['e_z_error_max']:.1e}, e_x {p['e_x_error_max']:.1e}) @ "
                     f"{p['seconds_per_impact'] * 1e3:.3g} ms")
    for r in data.get("for_tolerance", []):
        lines.append(f"for_tolerance({r['tolerance']:g}): {r['steps']}/{r['elements']} error "
                     f"{r['error']:.1e} (met: {r['met']}) @ {r['seconds_per_impact'] * 1e3:.3g} ms")
    scan = data.get("for_tolerance_scan")
    if scan:
        lines.append(f"for_tolerance scan ({len(scan['rows'])} tolerances "
                     f"{scan['rows'][0]['tolerance']:g}..{scan['rows'][-1]['tolerance']:g}, element "
                     f"path): {scan['missed']} missed; worst error/tol "
                     f"{scan['worst_error_over_tolerance']:.2f} at {scan['worst_tolerance']:.2e} "
                     f"(scene {scan['worst_scene']})")
    for c in d.get("model_checks", []):
        lines.append(f"model check {c['tolerance']:g} [{c['source']}]: {c['steps']}/{c['elements']}"
                     f" error {c['error']:.1e} (met: {c['met']}) @ "
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
    """The long text summary (fronts, cheapest settings, models, presets)."""
    return _summary(data)


def _spread_of(row: dict) -> list[float] | None:
    return row.get("seconds_samples")


def figures(data: dict) -> dict:
    """Headline numbers: per preset (element path and as routed) and
    ``for_tolerance`` target (element path) the time per impact and the error;
    per continuum ``rtol`` the time and the ``e_z`` error; the explicit-Euler
    error of the thesis's table 4.1."""
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
