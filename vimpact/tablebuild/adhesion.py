"""Build and verify an adhesive impact table (:mod:`vimpact.lookup.adhesion`).

``vimpact table build SPEC`` on a grid spec with a ``lam`` axis (model
``kelvin_voigt``, ``[grid] tolerance``) runs :func:`build_adhesion_table`:

1. the ``Q1`` axis of the spec gives the first ``Q1`` nodes; at each the sticking
   number ``lam_s(Q1)`` is found by bisection in ``log lam`` to the relative width
   :data:`STICKING_RTOL` (all nodes at once, one batch per halving);
2. at each ``Q1`` node, rows at ``lam = lam_s exp(-s^2)`` for fixed nodes ``s > 0``
   (from :data:`S_FIRST` up to ``sqrt(log(max lam_s / lam_min))``, geometric up to
   :data:`S_GEOMETRIC`, then spaced by the spec's ``lam`` axis) give ``e_z``;
3. the lookup is checked against direct simulation half-way between the nodes
   along ``Q1`` and along ``s``; where the largest ``e_z`` error exceeds half the
   tolerance, every interval of that axis is halved (new ``Q1`` nodes get their own
   bisection), for at most :data:`MAX_ROUNDS` rounds;
4. the finished table is verified (:func:`verify_adhesion_table`) at held-out
   points it never used, uniform in ``log lam x log Q1`` and in a band around the
   sticking boundary, and written with that error and the build's time.

``vimpact table verify TABLE`` on an adhesive table repeats step 4 with the stored
seed and number of points, so it reproduces the stored errors.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from vimpact.engine.adhesion import adhesion_for_number, run_kernel
from vimpact.engine.columns import SceneColumns
from vimpact.kernels import adhesion as kernel
from vimpact.kernels.status import BY_CODE
from vimpact.lookup.adhesion import KIND, AdhesionTable
from vimpact.model.numerics import Numerics
from vimpact.model.scene import Scene
from vimpact.model.validation import InputError
from vimpact.sweep.spec import ADHESION_AXIS, SweepSpec, load_spec
from vimpact.tablebuild.output import save_build

__all__ = ["build_adhesion_table", "simulate", "sticking_numbers", "verify_adhesion_table"]

#: Relative width of the bisection bracket of the sticking number.
STICKING_RTOL = 1e-7
#: The first ``s`` node (``lam = lam_s exp(-s^2)``, here ``lam_s (1 - 1e-4)``); between it
#: and the boundary ``s = 0`` the lookup extrapolates ``e_z`` linearly in ``s``.
S_FIRST = 0.01
#: ``s`` nodes are geometric from :data:`S_FIRST` up to here (:data:`S_NEAR` of them).
S_GEOMETRIC = 0.2
S_NEAR = 6
#: Refinement rounds at most.
MAX_ROUNDS = 3
#: Half-width in ``log lam`` of the band around the boundary that the verification samples.
BAND = 0.1
#: The sliver next to the boundary, ``s < S_SLIVER`` (``lam`` within 0.25 % below
#: ``lam_s``), where ``e_z`` is not smooth (it jumps there when damped) and the stuck
#: flag rests on the interpolated ``lam_s``: the refinement does not check it, the
#: verification reports it apart (``e_z_sliver``, ``stuck_misread``).
S_SLIVER = 0.05
#: Poisson ratio of the simulated scenes (the normal impact does not depend on it).
NU = 0.5


def simulate(Q1, lam, numerics: Numerics) -> tuple[np.ndarray, np.ndarray]:
    """Simulate the adhesive normal impacts at ``(Q1, lam)`` (arrays); return ``(e_z, stuck)``.

    Kelvin-Voigt, dimensionless scenes (:meth:`Scene.from_dimensionless`), in parallel
    over the rows. Raises :class:`InputError` if an impact did not finish.
    """
    Q1, lam = np.broadcast_arrays(np.asarray(Q1, dtype=float), np.asarray(lam, dtype=float))
    scenes = []
    for q, lm in zip(Q1.ravel(), lam.ravel()):
        s = Scene.from_dimensionless(float(q), NU, tangential="none")
        scenes.append(dataclasses.replace(s, adhesion=adhesion_for_number(s, float(lm)),
                                          allow_large_contact=True))
    out = run_kernel(SceneColumns.from_scenes(scenes), numerics)
    status = out[:, kernel.ADH_STATUS].astype(int)
    if np.any(status != 0):
        i = int(np.flatnonzero(status != 0)[0])
        raise InputError(f"the adhesive impact at Q1 = {Q1.ravel()[i]:.6g}, lam = "
                         f"{lam.ravel()[i]:.6g} ended with status {BY_CODE[status[i]]!r}; a "
                         "table needs finished impacts")
    stuck = out[:, kernel.ADH_STUCK] > 0.5
    e_z = np.where(stuck, 0.0, np.abs(out[:, kernel.ADH_VZ_END]))
    return e_z.reshape(Q1.shape), stuck.reshape(Q1.shape)


def sticking_numbers(Q1, numerics: Numerics, rtol: float = STICKING_RTOL,
                     lo: float = 1e-5, hi: float = 2.0) -> np.ndarray:
    """Return the sticking number ``lam_s`` at each ``Q1``: bisection in ``log lam``.

    The bracket ``[lo, hi]`` is widened (by factors 10) until ``lo`` separates and
    ``hi`` sticks at every row, then halved until ``hi / lo - 1 <= rtol``; returns the
    geometric mid-point (assumes one crossing: sticks above ``lam_s``, separates below).
    """
    Q1 = np.asarray(Q1, dtype=float)
    lo_a = np.full(Q1.shape, lo)
    hi_a = np.full(Q1.shape, hi)
    for _ in range(6):
        s_lo = simulate(Q1, lo_a, numerics)[1]
        s_hi = simulate(Q1, hi_a, numerics)[1]
        if not s_lo.any() and s_hi.all():
            break
        lo_a = np.where(s_lo, lo_a / 10.0, lo_a)
        hi_a = np.where(s_hi, hi_a, hi_a * 10.0)
    else:
        raise InputError("no bracket of the sticking number found for Q1 = "
                         f"{Q1.min():.4g} .. {Q1.max():.4g}")
    while np.any(hi_a / lo_a - 1.0 > rtol):
        todo = hi_a / lo_a - 1.0 > rtol
        mid = np.sqrt(lo_a[todo] * hi_a[todo])
        s = simulate(Q1[todo], mid, numerics)[1]
        hi_a[todo] = np.where(s, mid, hi_a[todo])
        lo_a[todo] = np.where(s, lo_a[todo], mid)
    return np.sqrt(lo_a * hi_a)


def _s_nodes(s_max: float, per_decade: float) -> np.ndarray:
    """Return the nodes ``s`` below the boundary.

    :data:`S_NEAR` geometric from :data:`S_FIRST` to :data:`S_GEOMETRIC`, then evenly
    spaced to ``s_max``, about ``per_decade`` per decade of ``lam`` at ``s = 1``.
    """
    near = np.geomspace(S_FIRST, S_GEOMETRIC, S_NEAR)
    step = 0.5 * np.log(10.0) / per_decade  # ds = dy / (2 s) at s = 1
    n = max(2, int(np.ceil((s_max - S_GEOMETRIC) / step)) + 1)
    return np.concatenate([near, np.linspace(S_GEOMETRIC, s_max, n)[1:]])


def _lam(lam_s, s) -> np.ndarray:
    return lam_s[:, None] * np.exp(-np.asarray(s)[None, :] ** 2)


def _table(Q1, lam_s, s, e_z, meta: dict) -> AdhesionTable:
    nq, ns = len(Q1), len(s)
    inner = pd.DataFrame({"Q1": np.repeat(Q1, ns), "lam": _lam(lam_s, s).ravel(),
                          "s": np.tile(s, nq), "e_z": e_z.ravel(), "status": "normal_only"})
    bound = pd.DataFrame({"Q1": Q1, "lam": lam_s, "s": 0.0, "e_z": 0.0, "status": "stuck"})
    data = pd.concat([bound, inner], ignore_index=True)
    data.insert(2, "nu", NU)
    return AdhesionTable(data, {f"vimpact.{k}": v if isinstance(v, str) else json.dumps(v)
                                for k, v in meta.items()})


def _nodes(Q1, s, numerics, known: dict) -> tuple[np.ndarray, np.ndarray]:
    new = np.array([q for q in Q1.tolist() if q not in known])
    if len(new):
        known.update(zip(new.tolist(), sticking_numbers(new, numerics).tolist()))
    lam_s = np.array([known[q] for q in Q1.tolist()])
    lam = _lam(lam_s, s)
    e_z, stuck = simulate(np.broadcast_to(Q1[:, None], lam.shape), lam, numerics)
    for i, j in np.argwhere(stuck):  # below the boundary yet stuck: kept (e_z = 0), reported
        known.setdefault("not_monotone", []).append([float(Q1[i]), float(lam[i, j])])
    return lam_s, e_z


def _midpoints(x: np.ndarray, log: bool) -> np.ndarray:
    return np.sqrt(x[1:] * x[:-1]) if log else 0.5 * (x[1:] + x[:-1])


def _lookup_error(table: AdhesionTable, Q1, lam, numerics) -> float:
    e_z, _ = simulate(Q1, lam, numerics)
    err = np.abs(table.lookup(Q1, lam)["e_z"] - e_z)
    return float(err.max()) if err.size else 0.0


def build_adhesion_table(spec_path, out=None, *, n_verify: int = 2000, seed: int = 0,
                         log: Callable[[str], None] | None = None
                         ) -> tuple[AdhesionTable, Path]:
    """Build, verify and write the adhesive table of a spec (module docstring).

    Parameters
    ----------
    spec_path : grid spec (TOML or :class:`SweepSpec`), model ``kelvin_voigt``, axes
        ``lam`` (range ends, and ``per_decade``-like node spacing) and ``Q1`` (first
        nodes), ``[grid] tolerance`` (the largest ``e_z`` error aimed at)
    out : the Parquet file (default: the spec's ``output``)
    n_verify : held-out points of the verification (as many again in the band
        around the sticking boundary)
    seed : their seed
    log : called with one line of progress per stage

    Returns
    -------
    (table, path)
    """
    spec = spec_path if isinstance(spec_path, SweepSpec) else load_spec(spec_path)
    if spec.mode != "grid" or ADHESION_AXIS not in spec.axes or spec.model != "kelvin_voigt":
        raise InputError(f"spec = {str(spec.path)!r} is not allowed: an adhesive table needs "
                         "a [grid] spec, model kelvin_voigt, with lam and Q1 axes")
    if spec.grid_tolerance is None:
        raise InputError(f"spec = {str(spec.path)!r} is not allowed: an adhesive table needs "
                         "[grid] tolerance (the e_z error aimed at)")
    say = log or (lambda line: None)
    start = time.perf_counter()
    numerics = spec.numerics
    tol = float(spec.grid_tolerance)
    lam_axis = np.asarray(spec.axes[ADHESION_AXIS], dtype=float)
    lam_min, lam_max = float(lam_axis.min()), float(lam_axis.max())
    if not lam_min > 0.0:
        raise InputError(f"grid.lam = {lam_min} is not allowed in an adhesive table: its lam "
                         "axis is logarithmic, give lam > 0")
    per_decade = (len(lam_axis) - 1) / np.log10(lam_max / lam_min) if len(lam_axis) > 1 else 4
    Q1 = np.unique(np.asarray(spec.axes["Q1"], dtype=float))
    if len(Q1) < 2 or not Q1[0] > 0.0:
        raise InputError("grid.Q1 is not allowed: an adhesive table needs at least two Q1 "
                         "values, all > 0")
    known: dict = {}
    lam_s = _nodes(Q1, np.zeros(0), numerics, known)[0]
    s = _s_nodes(np.sqrt(max(np.log(lam_s.max() / lam_min), 1.0)), per_decade)
    say(f"sticking numbers at {len(Q1)} Q1 nodes: lam_s = {lam_s.min():.4g} .. "
        f"{lam_s.max():.4g}; {len(s)} s nodes")
    rounds = []
    met = False
    for r in range(MAX_ROUNDS + 1):
        lam_s, e_z = _nodes(Q1, s, numerics, known)
        table = _table(Q1, lam_s, s, e_z, {"table_kind": KIND, "model": "kelvin_voigt",
                                           "lam_range": [lam_min, lam_max]})
        # half-way along s at the Q1 nodes, and along Q1 at the s nodes, inside the range
        sm = _midpoints(s, False)
        lam_sm = _lam(lam_s, sm)
        keep = (lam_sm >= lam_min) & (lam_sm <= lam_max) & (sm >= S_SLIVER)[None, :]
        err_s = _lookup_error(table, np.broadcast_to(Q1[:, None], lam_sm.shape)[keep],
                              lam_sm[keep], numerics)
        qm = _midpoints(Q1, True)
        lam_qm = _lam(table.sticking_number(qm), s)
        keep = (lam_qm >= lam_min) & (lam_qm <= lam_max) & (s >= S_SLIVER)[None, :]
        err_q = _lookup_error(table, np.broadcast_to(qm[:, None], lam_qm.shape)[keep],
                              lam_qm[keep], numerics)
        rounds.append({"Q1_nodes": len(Q1), "s_nodes": len(s), "error_mid_s": err_s,
                       "error_mid_Q1": err_q, "seconds": round(time.perf_counter() - start, 1)})
        say(f"round {r}: {len(Q1)} Q1 x {len(s)} s nodes; e_z error half-way along s "
            f"{err_s:.3g}, along Q1 {err_q:.3g} ({time.perf_counter() - start:.0f} s)")
        if max(err_s, err_q) <= 0.5 * tol:
            met = True
            break
        if r == MAX_ROUNDS:
            break
        if err_q > 0.5 * tol:
            Q1 = np.sort(np.concatenate([Q1, qm]))
        if err_s > 0.5 * tol:
            s = np.sort(np.concatenate([s, sm]))
    seconds_refine = time.perf_counter() - start
    meta = spec.metadata()
    meta.update(table_kind=KIND, mode="adhesion", lam_range=[lam_min, lam_max],
                grid_refinement={"rounds": rounds, "met": met, "table_tolerance": tol,
                                 "stuck_below_boundary": known.get("not_monotone", [])})
    meta.pop("layout", None)
    table = _table(Q1, lam_s, s, e_z, {k: v for k, v in meta.items() if v is not None})
    say(f"verifying at {2 * n_verify} held-out points")
    result = verify_adhesion_table(table, n=n_verify, seed=seed, numerics=numerics)
    table.metadata["vimpact.interpolation_error"] = json.dumps(result)
    seconds = time.perf_counter() - start
    path = save_build(table, {
        "seconds": round(seconds, 1), "refine_seconds": round(seconds_refine, 1),
        "tolerance": tol, "met": met, "nodes": {"Q1": len(Q1), "s": len(s)},
        "rows": len(table.data)}, spec, out)
    say(f"wrote {path} ({path.stat().st_size / 1e3:.0f} kB) in {seconds:.0f} s; held-out max "
        f"error e_z {result['outputs']['e_z']['max']:.3g}, stuck misread at "
        f"{result['stuck_misread']} of {result['points']} points")
    return AdhesionTable.open(path), path


def verify_adhesion_table(table: AdhesionTable, n: int = 2000, seed: int = 0,
                          numerics: Numerics | None = None) -> dict:
    """Measure the lookup against direct simulation at held-out points.

    ``n`` points uniform in ``log lam x log Q1`` over the table's ranges and ``n``
    in the band ``|log(lam / lam_s(Q1))| <= BAND`` around the sticking boundary
    (where ``e_z`` changes fastest), from ``seed``. Returns the JSON-able result:
    ``points``, ``seed``, ``n``, ``outputs`` (``max``, ``rms``, ``at`` of the ``e_z``
    error on the points not stuck in both: ``e_z`` outside the sliver
    ``s < S_SLIVER`` next to the boundary, ``e_z_sliver`` inside it),
    ``stuck_misread`` (points where the lookup's stuck flag differs from the
    simulation's), the largest ``|log(lam / lam_s)|`` of those, and ``stuck_points``.
    """
    if numerics is None:
        numerics = Numerics(**{k: v for k, v in (table.meta("numerics") or {}).items()
                               if k in {f.name for f in dataclasses.fields(Numerics)}})
    rng = np.random.default_rng(seed)
    (q_lo, q_hi), (l_lo, l_hi) = table.Q1_range, table.lam_range
    Q1 = np.exp(rng.uniform(np.log(q_lo), np.log(q_hi), 2 * n))
    lam = np.exp(rng.uniform(np.log(l_lo), np.log(l_hi), n))
    lam_s = table.sticking_number(Q1[n:])
    band = np.clip(lam_s * np.exp(rng.uniform(-BAND, BAND, n)), l_lo, l_hi)
    lam = np.concatenate([lam, band])
    e_z, stuck = simulate(Q1, lam, numerics)
    res = table.lookup(Q1, lam)
    misread = res["stuck"] != stuck
    both_free = ~stuck & ~res["stuck"]
    err = np.abs(res["e_z"] - e_z)
    outputs: dict[str, dict] = {}
    with np.errstate(invalid="ignore"):
        s = np.sqrt(np.log(res["lam_s"] / lam))
    sliver = s < S_SLIVER
    for name, sel in (("e_z", both_free & ~sliver), ("e_z_sliver", both_free & sliver)):
        if not sel.any():
            outputs[name] = {"max": None, "rms": None, "at": {}}
            continue
        i = int(np.flatnonzero(sel)[np.argmax(err[sel])])
        outputs[name] = {"max": float(err[i]), "rms": float(np.sqrt(np.mean(err[sel] ** 2))),
                         "at": {"Q1": float(Q1[i]), "lam": float(lam[i])}}
    dist = np.abs(np.log(lam / res["lam_s"]))[misread]
    return {"points": int(2 * n), "n": int(n), "seed": int(seed), "outputs": outputs,
            "stuck_misread": int(misread.sum()),
            "misread_max_log_distance": float(dist.max()) if dist.size else None,
            "stuck_points": int(stuck.sum())}
