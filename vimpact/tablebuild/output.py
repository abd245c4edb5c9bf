"""Assemble and write a built table with its build record, and the line that says so.

Every table build (:mod:`vimpact.tablebuild.adaptive`, :mod:`~vimpact.tablebuild.friction`,
:mod:`~vimpact.tablebuild.adhesion`) ends the same way: the build's time and size go
into the table's metadata as ``vimpact.build``, the table is written to the output the
command names (or the spec's), and one line reports the file, its size, the time and
the held-out error.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pandas as pd

from vimpact.lookup.table import RestitutionTable


def adaptive_table(data: pd.DataFrame, spec: Any, grid_metadata: dict,
                   report: dict) -> RestitutionTable:
    """Return the adaptive restitution table of ``data`` with the spec's metadata.

    Parameters
    ----------
    data : pandas.DataFrame
        The node rows (axes, outputs, lattice coordinates, status).
    spec : SweepSpec
        The spec built; its metadata (units, numerics, spec text, ...) is stored.
    grid_metadata : dict
        The cell structure (``AdaptiveGrid.to_metadata()`` or the friction grid's).
    report : dict
        The refinement report, stored as ``vimpact.grid_refinement``.
    """
    meta = spec.metadata()
    meta.update(mode="adaptive", rows=int(len(data)), adaptive=grid_metadata,
                grid_refinement=report)
    meta.pop("layout", None)
    return RestitutionTable(data, {k: v if isinstance(v, str) else json.dumps(v)
                                   for k, v in meta.items() if v is not None})


def save_build(table: Any, build: dict, spec: Any, out) -> Path:
    """Store ``build`` in ``table``'s metadata and write the table, returning its path.

    Parameters
    ----------
    table : RestitutionTable or AdhesionTable
        The built table (anything with ``metadata`` and ``save(path)``).
    build : dict
        The build record (``seconds`` in s, ``tolerance``, ``met``, sizes), stored as
        JSON under ``vimpact.build``.
    spec : SweepSpec
        The spec the table was built from; its ``output`` is the default path.
    out : str or Path or None
        Where to write the table (None: ``spec.output``); folders are created.
    """
    table.metadata["vimpact.build"] = json.dumps(build)
    path = Path(out) if out is not None else spec.output
    path.parent.mkdir(parents=True, exist_ok=True)
    table.save(path)
    return path


def written(path: Path, seconds: float, result: dict) -> str:
    """Return the line that reports a written table: path, size (MB), time (s), held-out error.

    ``result`` is the table's interpolation error (``outputs`` -> name -> ``max``).
    """
    errs = ", ".join(f"{k} {v['max']:.2g}" for k, v in result["outputs"].items()
                     if v["max"] is not None)
    return (f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB) in {seconds:.0f} s; held-out "
            f"max error {errs}")
