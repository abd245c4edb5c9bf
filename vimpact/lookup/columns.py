"""The rows of a restitution table as the reader sees them.

The columns a table needs, which statuses are data, which outputs a lookup
interpolates over which axes, and how a Kelvin-Voigt row is told apart from a
standard-solid one (``Q2 = NaN`` and a ``model`` column).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from vimpact.kernels.status import TABLE as STATUS_TABLE

__all__ = ["AXES", "DATA_STATUSES", "LOOKUP_METHODS", "LOOKUP_MODELS", "OUTPUTS",
           "REQUIRED_COLUMNS", "SPEC_HINTS", "fmt", "kelvin_voigt_rows", "where"]

#: Interpolation methods of :meth:`vimpact.lookup.table.RestitutionTable.lookup`.
LOOKUP_METHODS = ("cubic", "linear")

#: Statuses whose rows are data (all others are failures and are skipped).
DATA_STATUSES = tuple(s.name for s in STATUS_TABLE if s.has_data)

#: Models whose tables :meth:`vimpact.lookup.table.RestitutionTable.lookup` can
#: interpolate.
LOOKUP_MODELS = ("kelvin_voigt", "standard_solid")

#: Which sweep spec produces a grid table for lookup, by model.
SPEC_HINTS = {
    "kelvin_voigt": "sweeps/kelvin_voigt_table.toml",
    "standard_solid": "sweeps/standard_solid_table.toml",
}

#: Outputs interpolated by :meth:`vimpact.lookup.table.RestitutionTable.lookup` (all
#: dimensionless).
OUTPUTS = ("e_z", "e_x", "beta_x")

#: Interpolation axes of a lookup, in grid order: ``theta_ratio`` when the table holds
#: several values, ``psi`` when it has a ``psi`` column (friction incidence).
AXES = ("Q1", "Q2", "nu", "theta_ratio", "psi")

#: Columns every restitution table has (``Q2`` too for a standard solid).
REQUIRED_COLUMNS = ("Q1", "nu", "e_z", "e_x", "beta_x", "status")


def fmt(x: float) -> str:
    """Return ``x`` with six significant digits, as the reader's messages print values."""
    return f"{x:.6g}"


def where(path) -> str:
    """Return `` 'path'`` for a message about the table at ``path`` (empty: in memory)."""
    return f" {str(path)!r}" if path is not None else ""


def kelvin_voigt_rows(data: pd.DataFrame, model: str) -> pd.DataFrame:
    """Make Kelvin-Voigt rows unambiguous: ``Q2 = NaN`` (not 0) and a ``model`` column.

    The Kelvin-Voigt solid is the limit ``G2 -> inf`` (``Q2 -> 0``) of the standard
    solid; old tables wrote it as ``Q2 = 0``, which also reads as a Maxwell fluid
    (``G1 = 0``) and is ``log 0`` on a log ``Q2`` axis. Rows of a Kelvin-Voigt table,
    and rows of a standard-solid table with ``Q2 = 0``, become ``Q2 = NaN`` with
    ``model = "kelvin_voigt"``; an existing ``model`` column is kept.

    Parameters
    ----------
    data : pandas.DataFrame
        The table's rows.
    model : str
        The table's rheology (metadata ``vimpact.model``); rows of a model outside
        :data:`LOOKUP_MODELS` are returned unchanged.

    Returns
    -------
    pandas.DataFrame
        ``data`` itself when nothing changes, else a changed copy.
    """
    if model not in LOOKUP_MODELS:
        return data
    q2 = data["Q2"].to_numpy(float) if "Q2" in data.columns else None
    if "model" in data.columns:
        kv = (data["model"] == "kelvin_voigt").to_numpy()
    elif model == "kelvin_voigt":
        kv = np.ones(len(data), dtype=bool)
    else:
        kv = q2 == 0.0
    if "model" in data.columns and (q2 is None or not np.any(kv & (q2 == 0.0))):
        return data
    data = data.copy()
    if "model" not in data.columns:
        data["model"] = np.where(kv, "kelvin_voigt", model)
    if q2 is not None:
        data["Q2"] = np.where(kv, np.nan, q2)
    return data
