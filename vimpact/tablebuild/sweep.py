"""A sweep whose grid is refined to a tolerance.

The table-build workflow around :func:`vimpact.sweep.runner.run_sweep`.

``[grid] tolerance`` (:attr:`vimpact.sweep.spec.SweepSpec.grid_tolerance`): before
any chunk is made, :func:`refined_spec` refines the grid axes with
:func:`vimpact.tablebuild.refine.refine_grid` until the cubic lookup meets the
tolerance between the nodes (progress on stderr), so chunking, resume and shards
all see the final axes. The refined axes are deterministic and cached in the
parts directory (:data:`GRID_CACHE`), so ``--resume``, shards and ``--combine`` do
not refine again. A tolerance the refinement cannot reach within its node budget
(:data:`vimpact.tablebuild.refine.MAX_AXIS_NODES` per axis,
:data:`vimpact.tablebuild.refine.MAX_NODES` rows) is refused with an
:class:`~vimpact.model.validation.InputError` before anything is written. The
table's metadata then holds the refinement report as ``grid_refinement`` (JSON:
nodes inserted per round and axis, the cells they split and the error found
there, and the held-out check it reached) and, measured on the finished table as
``vimpact table verify --write`` does, ``interpolation_error``.

:func:`run_sweep` is :func:`vimpact.sweep.runner.run_sweep` with these stages
(:data:`STAGES`); ``vimpact sweep SPEC`` runs it. A spec without ``tolerance`` gives
the same table either way.

Python API::

    from vimpact.tablebuild.sweep import run_sweep
    path = run_sweep("sweeps/kelvin_voigt_table.toml", progress=False)
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from vimpact.lookup.table import RestitutionTable
from vimpact.model.scene import DEFAULT_THETA_RATIO
from vimpact.model.validation import InputError
from vimpact.sweep import runner
from vimpact.sweep.spec import SweepSpec
from vimpact.tablebuild import refine
from vimpact.tablebuild.verify import interpolation_error, write_interpolation_error
from vimpact.tableformat.files import atomic_file
from vimpact.tableformat.metadata import read_metadata

#: The refined axes of a sweep with ``[grid] tolerance``, in its parts directory (the
#: leading underscore keeps it out of a Parquet dataset's files).
GRID_CACHE = "_grid_refinement.json"
#: Models whose grids can be refined (their lookups are cubic in log Q1 (, log Q2), nu).
REFINABLE = ("kelvin_voigt", "standard_solid")


@dataclasses.dataclass(frozen=True)
class RefinedSweepSpec(SweepSpec):
    """A grid :class:`SweepSpec` whose axes were refined to its ``grid_tolerance``.

    ``grid_refinement`` (JSON text, the report of
    :func:`vimpact.tablebuild.refine.refine_grid`) goes into the parts' and the table's
    metadata.
    """

    grid_refinement: str = ""

    def metadata(self) -> dict:
        """Return the spec's metadata with the refinement report."""
        return {**super().metadata(), "grid_refinement": self.grid_refinement}


def _write_json_atomic(path: Path, value: dict) -> None:
    with atomic_file(path, str(path), mode="w") as f:  # never through a symlink
        json.dump(value, f)


def _read_grid_cache(path: Path, spec: SweepSpec):
    """Return the cached ``(axes, report)`` of this sweep (same sweep hash), or None."""
    try:
        cached = json.loads(path.read_text())
        if cached.get("sweep_hash") != spec.sweep_hash:
            return None
        return ({a: np.asarray(v, dtype=float) for a, v in cached["axes"].items()},
                cached["report"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def _reached(report: dict) -> str:
    final = report.get("final", {}).get("outputs", {})
    parts = [f"{k} {final[k]['max']:.3g}" for k in report.get("outputs", ())
             if isinstance(final.get(k), dict) and final[k].get("max") is not None]
    return ", ".join(parts) or "none measured (every held-out simulation failed)"


def refined_spec(spec: SweepSpec, parts: Path, log: Callable[[str], None] | None = None
                 ) -> SweepSpec:
    """Return ``spec`` with its grid axes refined to ``spec.grid_tolerance``.

    ``spec`` itself when it has none.

    The refinement (:func:`vimpact.tablebuild.refine.refine_grid`, with the spec's
    numerics and scene options, cubic lookup, outputs ``e_z`` and ``beta_x``) is read
    from ``parts/GRID_CACHE`` when a run of the same sweep (same sweep hash) made it,
    and written there otherwise.

    Parameters
    ----------
    spec : a grid spec
    parts : the sweep's parts directory (created if needed)
    log : called with one line of progress per refinement round (or None)

    Raises
    ------
    InputError
        ``grid.tolerance`` on a grid that cannot be refined (elastic, several
        ``theta_ratio`` values), or a tolerance the refinement did not reach within
        its node budget: the message gives the smallest error it reached.
    """
    tol = getattr(spec, "grid_tolerance", None)
    if tol is None or spec.mode != "grid":
        return spec
    if spec.model not in REFINABLE:
        raise InputError(f"grid.tolerance = {tol!r} is not allowed for a {spec.model} grid: "
                         f"only {' and '.join(REFINABLE)} grids are refined (remove it)")
    theta = np.asarray(spec.axes.get("theta_ratio", [DEFAULT_THETA_RATIO]), dtype=float)
    if theta.size != 1:
        raise InputError(f"grid.tolerance = {tol!r} is not allowed with {theta.size} "
                         "theta_ratio values: a refined grid has one theta_ratio (one "
                         "spec per value)")
    if "psi" in spec.axes:
        raise InputError(f"grid.tolerance = {tol!r} is not allowed with a psi axis: the "
                         "refinement covers Q1, Q2 and nu of stick grids (check a psi grid "
                         "with vimpact table verify instead)")
    cache = Path(parts) / GRID_CACHE
    cached = _read_grid_cache(cache, spec)
    if cached is not None:
        axes, report = cached
        if log is not None:
            log(f"refined grid read from {cache}")
    else:
        start = {a: spec.axes[a] for a in ("Q1", "Q2", "nu") if a in spec.axes}
        if log is not None:
            log(f"refining the grid to tolerance {tol:g} ("
                + " x ".join(f"{a} {len(v)}" for a, v in start.items()) + " nodes)")
        axes, report = refine.refine_grid(
            spec.model, start, float(tol), spec.numerics, theta_ratio=float(theta[0]),
            tangential=spec.tangential, tangential_memory=spec.tangential_memory,
            rotation=spec.rotation, max_nodes=refine.MAX_NODES,
            max_axis_nodes=refine.MAX_AXIS_NODES, progress=log)
        if not report["met"]:
            raise InputError(
                f"grid.tolerance = {tol:g} is not allowed for this grid: the refinement "
                f"did not reach it within its budget ({refine.MAX_AXIS_NODES} nodes per "
                f"axis, {refine.MAX_NODES} rows; stopped: {report['stopped']}); the "
                f"smallest error it reached, at held-out points of its finest grid: "
                f"{_reached(report)}. Nothing was written: loosen grid.tolerance or "
                "narrow the axes")
        Path(parts).mkdir(parents=True, exist_ok=True)
        _write_json_atomic(cache, {"sweep_hash": spec.sweep_hash,
                                   "axes": {a: [float(x) for x in v] for a, v in axes.items()},
                                   "report": report})
        if log is not None:
            log("refined grid: " + " x ".join(f"{a} {len(v)}" for a, v in axes.items())
                + f" nodes, held-out error {_reached(report)}")
    new_axes = {k: (np.asarray(axes[k], dtype=float) if k in axes else v)
                for k, v in spec.axes.items()}
    fields = {f.name: getattr(spec, f.name) for f in dataclasses.fields(spec)
              if f.name != "grid_refinement"}
    fields.update(axes=new_axes, rows=math.prod(len(v) for v in new_axes.values()))
    return RefinedSweepSpec(**fields, grid_refinement=json.dumps(report))


def measure_interpolation_error(spec: SweepSpec, out: Path, log=None) -> dict | None:
    """Measure the finished table's interpolation error and store it in its metadata.

    As ``vimpact table verify TABLE --write`` does (:func:`vimpact.tablebuild.verify.
    interpolation_error` with its defaults, :func:`vimpact.tablebuild.verify.
    write_interpolation_error`). Only for a refined grid (``grid_tolerance`` set).
    """
    if getattr(spec, "grid_tolerance", None) is None or spec.mode != "grid":
        return None
    table = RestitutionTable.open(out)
    if log is not None:
        log("measuring the interpolation error at held-out points (table verify)")
    result = interpolation_error(table)
    write_interpolation_error(table, result)
    worst = {k: v["max"] for k, v in result["outputs"].items() if k in ("e_z", "beta_x")}
    if log is not None:
        log("interpolation error stored: " + ", ".join(
            f"{k} max {v:.3g}" if v is not None else f"{k} not measured"
            for k, v in worst.items()))
        if any(v is None or v > spec.grid_tolerance for v in worst.values()):
            log(f"warning: the measured error exceeds grid.tolerance = "
                f"{spec.grid_tolerance:g} at some held-out point; the table stores the "
                "measurement as it is")
    return result


def _needs_measurement(spec: SweepSpec, out: Path) -> bool:
    if getattr(spec, "grid_tolerance", None) is None or spec.mode != "grid":
        return False
    return "interpolation_error" not in read_metadata(out)


def _finish(spec: SweepSpec, out: Path, log: Callable[[str], None] | None,
            again: bool) -> None:
    """Measure a refined grid's table's interpolation error.

    After the table is written, and when a run finds it complete without one (cut
    short after the write).
    """
    if again and not _needs_measurement(spec, out):
        return
    measure_interpolation_error(spec, out, log)


#: The stages of a sweep with ``[grid] tolerance`` (:class:`vimpact.sweep.runner.SweepStages`).
STAGES = runner.SweepStages(prepare=refined_spec, finish=_finish, kept=(GRID_CACHE,))


def run_sweep(spec_path, out=None, resume: bool = False, progress=None, **options) -> Path:
    """Run the sweep of a spec, its grid refined to ``[grid] tolerance`` where it has one.

    :func:`vimpact.sweep.runner.run_sweep` (same arguments and result) with
    :data:`STAGES`: the refinement before the chunks, the measured interpolation
    error after the table.
    """
    return runner.run_sweep(spec_path, out, resume, progress, stages=STAGES, **options)


__all__ = ["GRID_CACHE", "REFINABLE", "STAGES", "RefinedSweepSpec",
           "measure_interpolation_error", "refined_spec", "run_sweep"]
