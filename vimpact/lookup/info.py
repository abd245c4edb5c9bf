"""What a table holds, as a summary and as text (``vimpact table info``).

:func:`table_info` summarizes a table (model, rows, statuses, covered ranges, grid
or adaptive cells, numerics, measured interpolation error, version; JSON-serializable)
and :func:`format_info` writes that summary as readable lines.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from vimpact.engine.result import STATUSES
from vimpact.lookup.columns import fmt
from vimpact.lookup.interpolate import same_node

if TYPE_CHECKING:
    from vimpact.lookup.table import RestitutionTable

__all__ = ["format_info", "table_info"]


def table_info(table: RestitutionTable) -> dict:
    """Return a summary of ``table``.

    :meth:`vimpact.lookup.table.RestitutionTable.info` describes it.
    """
    ok = table.ok
    params = ["Q1"] + (["Q2"] if table.model == "standard_solid" else []) + ["nu"]
    params += [c for c in ("theta_ratio", "psi", "mu") if c in table.data.columns]
    ranges = {}
    for p in params:
        v = ok[p].to_numpy(float) if p in ok.columns else np.array([])
        v = v[~np.isnan(v)] if p == "mu" else v[np.isfinite(v)]  # mu = inf: full stick
        ranges[p] = [float(v.min()), float(v.max())] if len(v) else None
    adaptive = None
    if table.is_adaptive:
        grid_info, failed, note = None, None, "adaptive cells (see adaptive)"
        try:
            adaptive = table.adaptive_grid().info()
            adaptive["failed_nodes"] = int(len(table.data) - len(ok))
        except ValueError as exc:
            note = str(exc)
        build = table.meta("build")
        if isinstance(build, dict) and adaptive is not None:  # None: the cells did not read
            adaptive["build"] = build
    else:
        try:
            grid = table.tensor.lookup_grid()
            grid_info, failed, note = grid.shape, grid.failed, None
        except ValueError as exc:
            grid_info, failed, note = None, None, str(exc)
    spec = table.meta("spec")
    return {
        "below": _below(table),
        "path": None if table.path is None else str(table.path),
        "model": table.model,
        "rows": int(len(table.data)),
        "ok_rows": int(len(ok)),
        "statuses": {str(k): int(v) for k, v in table.data["status"].value_counts().items()},
        "ranges": ranges,
        "grid": grid_info,
        "failed_grid_points": failed,
        "grid_note": note,
        "adaptive": adaptive,
        "numerics": table.numerics,
        "version": table.version,
        "schema_version": table.meta("schema_version"),
        "spec": spec,
        "spec_name": table.meta("spec_name"),
        "description": table.meta("description"),
        "columns": [str(c) for c in table.data.columns],
        "interpolation_error": table.interpolation_error,
    }


def _below(table: RestitutionTable) -> dict | None:
    """Return which table beside ``table`` answers below its ``Q2`` range, or None.

    For an adaptive standard-solid table read from a file (:mod:`vimpact.lookup.band`):
    the neighbour's file name, the ``Q2`` where it takes over and its error bound; for
    the Kelvin-Voigt limit also the measured distance to it.
    """
    from vimpact.lookup.band import neighbour_below, q2_range

    try:
        found = neighbour_below(table)
    except (OSError, ValueError):
        return None
    if found is None or found.path is None:
        return None
    lo = q2_range(table)[0]
    limit = table.meta("kelvin_voigt_limit") if found.model == "kelvin_voigt" else None
    return {"file": found.path.name, "Q2": lo, "error_bound": found.error_bound(),
            "limit_distance": limit.get("max") if isinstance(limit, dict) else None}


def format_info(info: dict) -> str:
    """Return the readable form of :meth:`vimpact.lookup.table.RestitutionTable.info`.

    Parameters
    ----------
    info : dict
        The summary (:func:`table_info`).

    Returns
    -------
    str
        One line per item (model, rows, statuses, ranges, grid or adaptive cells,
        numerics, interpolation error, the table that answers below its ``Q2`` range,
        version, spec).
    """
    lines = [f"restitution table {info['path'] or '(in memory)'}"]
    if info.get("description"):
        lines.append(f"  description     {info['description']}")
    lines += [f"  model           {info['model']}",
             f"  rows            {info['rows']} ({info['ok_rows']} ok)"]
    statuses = ", ".join(f"{k} {v}" for k, v in info["statuses"].items())
    lines.append(f"  statuses        {statuses or 'none'}")
    unknown = [k for k in info["statuses"] if k not in STATUSES]
    if unknown:
        lines.append(f"                  (unknown status: {', '.join(unknown)})")
    for name, r in info["ranges"].items():
        one = r is not None and (r[0] == r[1] or (np.isfinite(r[1]) and same_node(r[0], r[1])))
        text = "no data" if r is None else (fmt(r[0]) if one else f"{fmt(r[0])} .. {fmt(r[1])}")
        lines.append(f"  {name:<15} {text}")
    ad = info.get("adaptive")
    if ad:
        tensor = f" x {ad['tensor_nodes']} {ad['tensor_axis']}" if ad["tensor_axis"] else ""
        if "psi_nodes" in ad:  # a friction table: psi nodes on the kinks of beta_x(psi)
            tensor += (f" x {ad['psi_nodes']} psi (nodes on the kinks of beta_x; gross slip "
                       "throughout by its closed form)")
        lines.append(f"  adaptive        {ad['leaves']} cells in log "
                     + " x log ".join(ad["axes"]) + f" (levels {ad['levels'][0]} .. "
                     f"{ad['levels'][1]}), {ad['adaptive_nodes']} nodes{tensor}")
        build = ad.get("build")
        if isinstance(build, dict):
            lines.append(f"  build           {build.get('seconds', '?')} s, "
                         f"{build.get('simulated', '?')} impacts simulated, tolerance "
                         f"{build.get('tolerance', '?')} (met at every cell's check points: "
                         f"{build.get('met', '?')})")
    elif info["grid"]:
        shape = " x ".join(f"{n} {a}" for a, n in info["grid"].items())
        failed = info["failed_grid_points"]
        lines.append(f"  grid            {shape}" + (f" ({failed} failed points)" if failed else ""))
    else:
        lines.append(f"  grid            none: {info['grid_note']}")
    numerics = info["numerics"]
    if isinstance(numerics, dict):
        numerics = ", ".join(f"{k}={v}" for k, v in numerics.items())
    lines.append(f"  numerics        {numerics or 'not recorded'}")
    err = info.get("interpolation_error")
    if isinstance(err, dict) and isinstance(err.get("outputs"), dict):
        parts = ", ".join(f"{k} {v['max']:.2g} (rms {v['rms']:.2g})"
                          for k, v in err["outputs"].items())
        lines.append(f"  interpolation   {err.get('method', 'cubic')}: max error {parts}")
        lines.append(f"                  measured at {err.get('points', '?')} held-out points "
                     "against direct simulation")
    else:
        lines.append("  interpolation   error not measured (`vimpact table verify TABLE --write`)")
    below = info.get("below")
    if below:
        bound = below["error_bound"] or {}
        text = ", ".join(f"{k} {bound[k]:.2g}" for k in ("e_z", "beta_x")
                         if bound.get(k) is not None)
        line = (f"  below           Q2 < {below['Q2']:.6g}: {below['file']} beside it answers"
                + (f" (error bound {text}" if text else ""))
        if below.get("limit_distance"):
            d = below["limit_distance"]
            line += f"; distance to that limit {d['e_z']:.2g} e_z, {d['beta_x']:.2g} beta_x"
        lines.append(line + (")" if text else ""))
    lines.append(f"  vimpact         {info['version'] or 'unknown'}"
                 f" (schema {info['schema_version'] or 'unknown'})")
    spec = info["spec"]
    if info.get("spec_name"):
        lines.append(f"  spec            {info['spec_name']}")
    elif spec:
        first = str(spec).strip().splitlines()[0] if str(spec).strip() else ""
        more = len(str(spec).strip().splitlines()) - 1
        lines.append(f"  spec            {first[:70]}" + (f" (+{more} lines)" if more > 0 else ""))
    return "\n".join(lines)
