"""Validation of a restitution table's rows and metadata before any use.

:func:`validate_table` refuses a table that cannot be trusted for lookup, plots or
exports (foreign file, unknown status, outputs outside their physical bounds, axes
outside their domains, one node recorded twice), naming the file, the column, the
first offending value and its row.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from vimpact.engine.result import STATUSES
from vimpact.kernels.status import INVALID
from vimpact.lookup.columns import DATA_STATUSES, fmt
from vimpact.model.validation import InputError
from vimpact.tableformat.metadata import META_PREFIX

__all__ = ["BOUND_SLACK", "validate_table"]

#: Largest allowed excess of ``e_z``, ``e_x``, ``|beta_x|`` over 1 in a data row
#: (round-off of an elastic impact).
BOUND_SLACK = 1e-6


def _rows_text(rows: np.ndarray, limit: int = 3) -> str:
    first = [int(r) for r in rows[:limit]]
    return ("row " if len(first) == 1 else "rows ") + ", ".join(str(r) for r in first)


def validate_table(data: pd.DataFrame, metadata: dict, path=None) -> None:
    """Refuse a table that cannot be trusted for lookup, plots or exports.

    Raises :class:`~vimpact.model.validation.InputError` naming the file, the column
    (or metadata key), the first offending value and its row (0-based) for:

    - no ``vimpact.model`` metadata (a Parquet file not written by vimpact: foreign);
    - a ``status`` not among :data:`vimpact.engine.result.STATUSES`;
    - an output ``e_z``, ``e_x``, ``beta_x`` that is NaN or infinite in a data row
      (status ``ok``), ``e_z`` or ``e_x`` outside ``[0, 1 + 1e-6]``, ``|beta_x| > 1 + 1e-6``;
    - an axis value that is NaN in a data row (``Q1``, ``nu``, ``theta_ratio``, ``psi``,
      ``mu``; ``Q2`` except on Kelvin-Voigt rows, where it is NaN), or out of its domain in
      any row: ``Q1 >= 0``, ``Q2 > 0``, ``0 <= nu <= 0.5``, ``theta_ratio > 0``,
      ``psi >= 0``, ``mu > 0`` (``inf`` allowed);
    - two rows at the same node (equal ``Q1``, ``Q2``, ``nu``, ``theta_ratio``, ``psi``,
      ``mu``, ``model``: one impact recorded twice).

    Parameters
    ----------
    data : the rows, Kelvin-Voigt rows already as ``Q2 = NaN``
        (:class:`~vimpact.lookup.table.RestitutionTable`)
    metadata : ``vimpact.*`` key -> text
    path : the file, for the messages
    """
    where = f"table = {str(path)!r}" if path is not None else "the table"
    if META_PREFIX + "model" not in metadata:
        raise InputError(f"{where} is not allowed: it has no vimpact metadata (no key "
                         "vimpact.model): not a restitution table written by `vimpact sweep`")
    # each distinct status checked once (a table has a few among its rows)
    codes, kinds = pd.factorize(data["status"].astype(str), use_na_sentinel=False)
    kinds = np.asarray(kinds, dtype=object)
    unknown = ~np.isin(kinds, list(STATUSES))[codes]
    if unknown.any():
        i = np.flatnonzero(unknown)
        raise InputError(f"{where} is not allowed: column status = {kinds[codes[i[0]]]!r} at "
                         f"{_rows_text(i)} is not a vimpact status (known: "
                         + ", ".join(STATUSES) + ")")
    ok = np.isin(kinds, DATA_STATUSES)[codes]
    ran = (kinds != INVALID)[codes]  # every other row is an impact at its inputs
    bounds = {"e_z": (0.0, 1.0 + BOUND_SLACK, "in [0, 1 + 1e-6]"),
              "e_x": (0.0, 1.0 + BOUND_SLACK, "in [0, 1 + 1e-6]"),
              "beta_x": (-1.0 - BOUND_SLACK, 1.0 + BOUND_SLACK, "|beta_x| <= 1 + 1e-6")}
    for name, (lo, hi, allowed) in bounds.items():
        v = pd.to_numeric(data[name], errors="coerce").to_numpy(float)
        bad = ok & ~np.isfinite(v)
        if bad.any():
            i = np.flatnonzero(bad)
            raise InputError(f"{where} is not allowed: column {name} = {fmt(v[i[0]])} at "
                             f"{_rows_text(i)} with status ok (a data row needs a finite "
                             f"{name})")
        bad = ok & ((v < lo) | (v > hi))
        if bad.any():
            i = np.flatnonzero(bad)
            raise InputError(f"{where} is not allowed: column {name} = {fmt(v[i[0]])} at "
                             f"{_rows_text(i)} is outside its physical range ({allowed})")
    kv = (data["model"] == "kelvin_voigt").to_numpy() if "model" in data.columns else \
        np.zeros(len(data), dtype=bool)
    domains = {"Q1": (lambda x: x >= 0.0, ">= 0"), "Q2": (lambda x: x > 0.0, "> 0"),
               "nu": (lambda x: (x >= 0.0) & (x <= 0.5), "in [0, 0.5]"),
               "theta_ratio": (lambda x: x > 0.0, "> 0"), "psi": (lambda x: x >= 0.0, ">= 0"),
               "mu": (lambda x: x > 0.0, "> 0 (inf: full stick)")}
    for name, (inside, allowed) in domains.items():
        if name not in data.columns:
            continue
        v = pd.to_numeric(data[name], errors="coerce").to_numpy(float)
        missing = ok & np.isnan(v) & (~kv if name == "Q2" else True)
        if name == "Q2" and not kv.any() and np.isnan(v).all():
            missing = np.zeros(len(v), dtype=bool)  # a Kelvin-Voigt table without model column
        if missing.any():
            i = np.flatnonzero(missing)
            raise InputError(f"{where} is not allowed: column {name} = nan at {_rows_text(i)} "
                             f"with status ok (a data row needs {name} {allowed})")
        with np.errstate(invalid="ignore"):
            # a row that never ran (status invalid: e.g. nu = 0.7 asked for) keeps its inputs
            bad = ran & ((~np.isnan(v) & ~inside(v)) | (np.isinf(v) & (name != "mu")))
        if bad.any():
            i = np.flatnonzero(bad)
            raise InputError(f"{where} is not allowed: column {name} = {fmt(v[i[0]])} at "
                             f"{_rows_text(i)} is outside its domain ({name} {allowed})")
    keys = [c for c in ("Q1", "Q2", "nu", "theta_ratio", "psi", "mu", "model")
            if c in data.columns]
    dup = ran & data.duplicated(subset=keys, keep=False).to_numpy()
    if dup.any():
        i = np.flatnonzero(dup)
        first = data.iloc[i[0]]
        hashed = pd.util.hash_pandas_object(data.iloc[i][keys], index=False).to_numpy()
        same = i[hashed == hashed[0]]
        at = ", ".join(f"{k} = {first[k]:.6g}" if isinstance(first[k], (float, np.floating))
                       else f"{k} = {first[k]}" for k in keys)
        raise InputError(f"{where} is not allowed: duplicated node in columns "
                         f"{', '.join(keys)}: {_rows_text(same, 4)} are all at {at} "
                         "(one impact per node)")

