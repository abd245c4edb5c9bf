"""The standard solid below its main table: the band table and the Kelvin-Voigt limit.

The shipped standard-solid table covers ``Q2 = G1/G2 >= 1e-3``. Below, the arm's
relaxation time ``tau = Q2 eta/G1`` is short, yet at large ``Q1`` not short against
the impact: the ridge where the impact changes course crosses ``Q1 = 100`` near
``Q2 = 3e-5``, and e_z at ``Q2 = 1e-3``, ``Q1 = 100`` is 0.58 above its
Kelvin-Voigt value. Past the ridge ``e_z`` and ``beta_x`` approach the Kelvin-Voigt
limit linearly in ``Q2`` (docs/physics.md#standard-solid-limits).

So a lookup below a standard-solid table's ``Q2`` range is answered by its
neighbours in the same directory: the *band* table (:data:`BAND_FILE`, built from
:data:`BAND_SPEC`), an adaptive standard-solid table whose ``Q2`` range ends where
the table's begins; below the band, the Kelvin-Voigt table (:data:`KELVIN_VOIGT_FILE`),
when the band records the measured distance to that limit at its lower end
(metadata ``vimpact.kelvin_voigt_limit``, written by
:func:`vimpact.tablebuild.band.write_kelvin_voigt_limit`). Without the band the
lookup is refused with a message that names the spec which builds it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from vimpact.lookup.columns import OUTPUTS, where
from vimpact.model.validation import InputError

if TYPE_CHECKING:
    from vimpact.lookup.table import RestitutionTable

__all__ = ["BAND_FILE", "BAND_SPEC", "KELVIN_VOIGT_FILE", "KELVIN_VOIGT_Q2", "below_range",
           "neighbour_below", "q2_range", "reaches_kelvin_voigt"]

#: The band table's file name, looked for beside a standard-solid table.
BAND_FILE = "standard_solid_band.parquet"
#: The spec that builds the band table (``vimpact table build``).
BAND_SPEC = "sweeps/standard_solid_band.toml"
#: The Kelvin-Voigt table's file name, looked for beside the band table.
KELVIN_VOIGT_FILE = "kelvin_voigt_table.parquet"
#: A standard-solid table whose ``Q2`` range reaches down to this value (or below)
#: is continued by the Kelvin-Voigt table: there both outputs are within
#: ``0.17 Q2 <= 1.7e-6`` of their Kelvin-Voigt values at every ``Q1`` in 1e-3 ... 100
#: (measured by direct simulation; the table records its own measurement).
KELVIN_VOIGT_Q2 = 1e-5

_OPENED: dict[tuple[str, int], RestitutionTable] = {}


def _open(path: Path) -> RestitutionTable:
    """Open a neighbour table once per file version (its cells are built once)."""
    from vimpact.lookup.table import RestitutionTable

    key = (str(path.resolve()), path.stat().st_mtime_ns)
    if key not in _OPENED:
        _OPENED[key] = RestitutionTable.open(path)
    return _OPENED[key]


def q2_range(table: RestitutionTable) -> tuple[float, float]:
    """Return the ``Q2`` range ``(lo, hi)`` of an adaptive standard-solid table's cells."""
    grid = table.adaptive_grid()
    lo, hi = grid.bounds[grid.axes.index("Q2")]
    return float(lo), float(hi)


def reaches_kelvin_voigt(table: RestitutionTable) -> bool:
    """Whether an adaptive standard-solid table reaches down to :data:`KELVIN_VOIGT_Q2`."""
    return q2_range(table)[0] <= KELVIN_VOIGT_Q2 * (1.0 + 1e-9)


def neighbour_below(table: RestitutionTable) -> RestitutionTable | None:
    """Return the table that answers below ``table``'s ``Q2`` range, or None.

    Parameters
    ----------
    table : RestitutionTable
        An adaptive standard-solid table read from a file.

    Returns
    -------
    RestitutionTable or None
        The Kelvin-Voigt table beside ``table`` if ``table`` reaches down to
        :data:`KELVIN_VOIGT_Q2` and records its distance to the Kelvin-Voigt limit
        (``vimpact.kelvin_voigt_limit``); otherwise the band table beside it, if its
        ``Q2`` range ends where ``table``'s begins; None if there is none.
    """
    if table.path is None or table.model != "standard_solid" or not table.is_adaptive:
        return None
    folder = table.path.parent
    if reaches_kelvin_voigt(table):
        if table.meta("kelvin_voigt_limit") is None:
            return None
        kv = folder / KELVIN_VOIGT_FILE
        if kv.is_file():
            found = _open(kv)
            if found.model == "kelvin_voigt":
                return found
        return None
    band = folder / BAND_FILE
    if not band.is_file() or band.resolve() == table.path.resolve():
        return None
    found = _open(band)
    if found.model != "standard_solid" or not found.is_adaptive:
        return None
    if not np.isclose(q2_range(found)[1], q2_range(table)[0], rtol=1e-9):
        return None
    return found


def _refusal(table: RestitutionTable, q2: float) -> InputError:
    lo, hi = q2_range(table)
    if reaches_kelvin_voigt(table) and table.meta("kelvin_voigt_limit") is None:
        return InputError(
            f"Q2 = {q2:.6g} is outside the table's range: it covers Q2 in [{lo:.6g}, "
            f"{hi:.6g}]; below, the Kelvin-Voigt table answers once this table records "
            "its distance to that limit (`python -m vimpact.tablebuild.band TABLE`; "
            "`vimpact table build` records it)")
    if reaches_kelvin_voigt(table):
        return InputError(
            f"Q2 = {q2:.6g} is outside the table's range: it covers Q2 in [{lo:.6g}, "
            f"{hi:.6g}]; below, the Kelvin-Voigt table {KELVIN_VOIGT_FILE} beside "
            f"{where(table.path).strip() or 'the table'} answers (the limit Q2 -> 0), "
            "and it is missing")
    return InputError(
        f"Q2 = {q2:.6g} is outside the table's range: it covers Q2 in [{lo:.6g}, {hi:.6g}]. "
        f"Below it the band table {BAND_FILE} (Q2 down to the Kelvin-Voigt limit) answers "
        f"when it lies beside this table; build it with `vimpact table build {BAND_SPEC}`")


def _max_bound(bounds: list[dict | None]) -> dict | None:
    if any(b is None for b in bounds):
        return None
    out: dict = {}
    for k in OUTPUTS:
        values = [b.get(k) for b in bounds if b is not None]
        known = [float(v) for v in values if v is not None]
        out[k] = float(max(known)) if len(known) == len(values) else None
    return out


def below_range(table: RestitutionTable, arrays: dict[str, np.ndarray], method: str,
                extrapolate: bool, outputs, bound: dict | None,
                ) -> tuple[dict[str, np.ndarray], dict | None] | None:
    """Answer a standard-solid lookup whose points lie partly below the table's ``Q2``.

    Parameters
    ----------
    table : RestitutionTable
        An adaptive standard-solid table.
    arrays : dict
        Axis -> broadcast coordinates (``Q1``, ``Q2``, ``nu``; dimensionless).
    method, extrapolate : as for :meth:`RestitutionTable.lookup`
    outputs : callable
        ``outputs(table, arrays, method, extrapolate)`` -> output name -> array: the
        table's own lookup (:func:`vimpact.lookup.adaptive_table.adaptive_outputs`).
    bound : dict or None
        The table's own error bound.

    Returns
    -------
    (outputs, bound) or None
        None when no point lies below the range (or the table has no ``Q2``
        range); else the outputs with the points below answered by the neighbour
        (:func:`neighbour_below`), and the largest bound of the tables used (for the
        Kelvin-Voigt table: its bound plus the measured distance to the limit).

    Raises
    ------
    InputError
        Below the range without a neighbour, naming the spec that builds the band.
    """
    if (table.model != "standard_solid" or not table.is_adaptive or "Q2" not in arrays
            or method != "cubic" or extrapolate):  # the table's own lookup refuses these
        return None
    lo, _ = q2_range(table)
    Q2 = np.asarray(arrays["Q2"], dtype=float)
    below = Q2 < lo * (1.0 - 1e-9)
    if not below.any():
        return None
    neighbour = neighbour_below(table)
    if neighbour is None:
        raise _refusal(table, float(Q2[below].flat[0]))
    shape = Q2.shape
    flat = {a: np.asarray(v, dtype=float).ravel() for a, v in arrays.items()}
    mask = below.ravel()
    result = {k: np.full(mask.size, np.nan) for k in OUTPUTS}
    bounds = []
    if (~mask).any():
        own = outputs(table, {a: v[~mask] for a, v in flat.items()}, method, extrapolate)
        for k in OUTPUTS:
            result[k][~mask] = own[k]
        bounds.append(bound)
    sub = {a: v[mask] for a, v in flat.items()}
    if neighbour.model == "kelvin_voigt":
        res = neighbour.lookup(sub["Q1"], sub["nu"], method=method, extrapolate=extrapolate)
        limit = table.meta("kelvin_voigt_limit") or {}
        gap = limit.get("gap", {})
        kv_bound = res["error_bound"]
        if kv_bound is not None:
            kv_bound = {k: (None if kv_bound.get(k) is None or gap.get(k) is None
                            else float(kv_bound[k]) + float(gap[k])) for k in OUTPUTS}
        bounds.append(kv_bound)
    else:
        res = neighbour.lookup(sub["Q1"], sub["nu"], Q2=sub["Q2"], method=method,
                               extrapolate=extrapolate)
        bounds.append(res["error_bound"])
    for k in OUTPUTS:
        result[k][mask] = res[k]
    return {k: v.reshape(shape) for k, v in result.items()}, _max_bound(bounds)
