"""The lookup of an adaptive table: its cells rebuilt from the rows, evaluated at query points.

An adaptive table (metadata ``vimpact.mode = adaptive``) stores the nodes of locally
refined cells instead of a grid (:mod:`vimpact.lookup.adaptive`). Its lookup is the
cells' cubic interpolant inside the covered range; linear interpolation and
extrapolation are refused, not silently replaced.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from vimpact.lookup.columns import where
from vimpact.model.validation import InputError

if TYPE_CHECKING:
    from vimpact.lookup.adaptive import AdaptiveGrid
    from vimpact.lookup.table import RestitutionTable

__all__ = ["adaptive_lookup", "adaptive_outputs", "build_adaptive_grid"]


def build_adaptive_grid(table: RestitutionTable) -> AdaptiveGrid:
    """Return the cells of an adaptive table, rebuilt from its node rows and metadata.

    Parameters
    ----------
    table : RestitutionTable
        A table with ``vimpact.mode = adaptive`` and its ``vimpact.adaptive`` entry.

    Returns
    -------
    AdaptiveGrid
        :meth:`vimpact.lookup.adaptive.AdaptiveGrid.from_rows` of the table.

    Raises
    ------
    InputError
        For a table that is not adaptive, or whose rows and structure disagree.
    """
    from vimpact.lookup.adaptive import AdaptiveGrid

    if not table.is_adaptive:
        raise InputError(f"the table{where(table.path)} is not adaptive "
                         "(vimpact.mode is not 'adaptive')")
    return AdaptiveGrid.from_rows(table.meta("adaptive"), table.data)


def adaptive_outputs(table: RestitutionTable, arrays: dict[str, np.ndarray], method: str,
                     extrapolate: bool) -> dict[str, np.ndarray]:
    """Interpolate ``e_z``, ``e_x``, ``beta_x`` of an adaptive table at query points.

    Parameters
    ----------
    table : RestitutionTable
        An adaptive table (its cells: :meth:`~RestitutionTable.adaptive_grid`, built
        once).
    arrays : dict
        Axis -> broadcast coordinates (:func:`vimpact.lookup.query.query_arrays`).
    method : str
        Must be ``"cubic"``.
    extrapolate : bool
        Must be False: the cells cover the table's range only.

    Returns
    -------
    dict
        Output name -> array; ``e_x`` is ``|beta_x|``.

    Raises
    ------
    InputError
        For another method, for extrapolation, or for a point outside the cells.
    """
    if method != "cubic" or extrapolate:
        raise InputError(f"method = {method!r}, extrapolate = {extrapolate!r} are not "
                         "allowed for an adaptive table: its lookup is cubic inside "
                         "its range")
    grid = table.adaptive_grid()
    out = grid({a: arrays[a] for a in grid.axes
                + ([grid.tensor_axis] if grid.tensor_axis else [])})
    out["e_x"] = np.abs(out["beta_x"])
    return out


def adaptive_lookup(table: RestitutionTable, arrays: dict[str, np.ndarray], method: str,
                    extrapolate: bool) -> tuple[dict[str, np.ndarray], dict | None]:
    """Interpolate an adaptive table at query points, with the error bound that holds.

    Points of a standard-solid table below its ``Q2`` range are answered by the
    table beside it that continues the range down to the Kelvin-Voigt limit
    (:func:`vimpact.lookup.band.below_range`), or refused naming the spec that
    builds it.

    Returns
    -------
    (outputs, bound)
        :func:`adaptive_outputs`'s result and the largest error bound of the tables
        used (the table's own :meth:`~RestitutionTable.error_bound` if only it).
    """
    from vimpact.lookup.band import below_range

    bound = table.error_bound(method)
    split = below_range(table, arrays, method, extrapolate, adaptive_outputs, bound)
    if split is not None:
        return split
    return adaptive_outputs(table, arrays, method, extrapolate), bound
