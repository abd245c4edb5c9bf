"""Tensor-grid lookup: a grid table's outputs on the full grid of its axes, interpolated.

A grid table holds one row at every combination of the distinct ``Q1``, (``Q2``),
``nu`` (, ``theta_ratio``, ``psi``) values. :class:`TableGrid` holds its outputs on
that grid (NaN where the impact failed) and interpolates them multilinearly;
:class:`TensorLookup` builds the grids of one table (one per ``theta_ratio`` slice,
or one over every axis) and their cubic Hermite interpolants
(:class:`vimpact.lookup.interpolate.HermiteGrid`) once, and evaluates the lookup
at query points.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from vimpact.lookup.columns import DATA_STATUSES, LOOKUP_MODELS, SPEC_HINTS, fmt
from vimpact.lookup.interpolate import LOG_AXES, cluster_nodes, outside_range, same_node
from vimpact.model.scene import DEFAULT_THETA_RATIO
from vimpact.model.validation import InputError

if TYPE_CHECKING:
    from vimpact.lookup.interpolate import HermiteGrid
    from vimpact.lookup.table import RestitutionTable

__all__ = ["ALL_AXES", "TableGrid", "TensorLookup", "node_values"]

#: Cache key of the grid over every lookup axis (the other keys are ``theta_ratio``
#: slices, None for a table's only one).
ALL_AXES = "all axes"


class TableGrid:
    """The table's outputs on a full rectangular grid of its parameters."""

    def __init__(self, axes: list[str], nodes: list[np.ndarray], values: dict[str, np.ndarray],
                 failed: int):
        self.axes = axes          # e.g. ["Q1", "nu"] or ["Q1", "Q2", "nu"]
        self.nodes = nodes        # sorted node values per axis
        self.values = values      # output name -> array of shape (len(nodes[0]), ...)
        self.failed = failed      # grid points without a data row (NaN)

    @property
    def shape(self) -> dict[str, int]:
        """Axis -> number of nodes."""
        return {a: len(n) for a, n in zip(self.axes, self.nodes)}

    def _weights(self, k: int, x: np.ndarray, extrapolate: bool):
        """Return the cell index ``i0``, ``i1`` and weight ``t`` of ``x`` on axis ``k``.

        ``value = (1 - t) f[i0] + t f[i1]``.
        """
        name, nodes = self.axes[k], self.nodes[k]
        lo, hi = nodes[0], nodes[-1]
        inside = ((x >= lo) | same_node(x, lo)) & ((x <= hi) | same_node(x, hi))
        if not extrapolate and not np.all(inside):
            raise outside_range(name, nodes, float(x[~inside].flat[0]), name in LOG_AXES)
        if not extrapolate:
            x = np.clip(x, lo, hi)  # values within round-off of an end node
        if len(nodes) == 1:  # a single value: constant along this axis
            zero = np.zeros(x.shape, dtype=np.int64)
            return zero, zero, np.zeros(x.shape)
        i0 = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, len(nodes) - 2)
        a, b = nodes[i0], nodes[i0 + 1]
        if name in LOG_AXES:
            if np.any(x <= 0.0) and lo > 0.0:
                bad = float(x[x <= 0.0].flat[0])
                raise InputError(
                    f"{name} = {bad:.6g} cannot be extrapolated on the table's log {name} axis: "
                    f"it covers {name} in [{fmt(lo)}, {fmt(hi)}]; give {name} > 0")
            log_cell = a > 0.0  # a cell starting at 0 (an elastic node) is linear in the value
            xs = np.where(log_cell, x, 1.0)
            as_ = np.where(log_cell, a, 1.0)
            t = np.where(log_cell, np.log(xs / as_) / np.log(b / as_), (x - a) / (b - a))
        else:
            t = (x - a) / (b - a)
        # a value within round-off (1e-9) of a node gives that node's row exactly
        t = np.where(same_node(x, a), 0.0, np.where(same_node(x, b), 1.0, t))
        return i0, i0 + 1, t

    def interpolate(self, coords: list[np.ndarray], extrapolate: bool) -> dict[str, np.ndarray]:
        """Return the multilinear interpolant of every output at ``coords``.

        Linear in the value along ``nu`` and ``psi``, in the logarithm along the
        :data:`~vimpact.lookup.interpolate.LOG_AXES`; a node within round-off of a
        coordinate gives that node's value exactly.

        Parameters
        ----------
        coords : list of numpy.ndarray
            One array of coordinates per axis (in :attr:`axes` order), all of one shape.
        extrapolate : bool
            Extrapolate linearly beyond the end nodes instead of raising.

        Returns
        -------
        dict
            Output name -> array of the coordinates' shape (NaN where a corner with
            weight > 0 failed).

        Raises
        ------
        InputError
            For a coordinate outside the covered range (without ``extrapolate``).
        """
        shape = coords[0].shape
        flat = [c.ravel() for c in coords]
        cells = [self._weights(k, x, extrapolate) for k, x in enumerate(flat)]
        out = {name: np.zeros(flat[0].shape) for name in self.values}
        for corner in range(2 ** len(self.axes)):
            weight = np.ones(flat[0].shape)
            index = []
            for k, (i0, i1, t) in enumerate(cells):
                if corner >> k & 1:
                    weight = weight * t
                    index.append(i1)
                else:
                    weight = weight * (1.0 - t)
                    index.append(i0)
            for name, table in self.values.items():
                f = table[tuple(index)]
                # a corner with weight 0 contributes nothing, even if it failed (NaN)
                out[name] += np.where(weight == 0.0, 0.0, weight * f)
        return {name: v.reshape(shape) for name, v in out.items()}



def node_values(data: pd.DataFrame, column: str) -> np.ndarray:
    """Return the distinct finite values of ``column``, clustered up to round-off.

    Parameters
    ----------
    data : pandas.DataFrame
        The table's rows.
    column : str
        An axis column such as ``theta_ratio`` or ``psi``.

    Returns
    -------
    numpy.ndarray
        Sorted nodes (:func:`vimpact.lookup.interpolate.cluster_nodes`); empty when the
        column is missing or holds no finite value.
    """
    if column not in data.columns:
        return np.array([])
    v = data[column].to_numpy(float)
    # distinct values first: clustering is a Python loop over its values, and a
    # table's rows (489360 in the adaptive standard-solid table) repeat a few values
    return cluster_nodes(np.unique(v[np.isfinite(v)]))[0] if np.isfinite(v).any() \
        else np.array([])


def build_grid(axes: list[str], rows: pd.DataFrame, model: str, mode) -> TableGrid:
    """Return the outputs of ``rows`` on the full grid of ``axes``.

    Parameters
    ----------
    axes : list of str
        The grid's axes, e.g. ``["Q1", "nu"]``.
    rows : pandas.DataFrame
        The rows to place (rows with a non-finite axis value are left out).
    model : str
        The table's rheology (names the sweep spec that makes a grid, in messages).
    mode : str or None
        The table's ``vimpact.mode`` (``random`` draws are refused).

    Returns
    -------
    TableGrid
        Data rows averaged per grid point (they must agree to 1e-9); NaN at grid points
        without a data row.

    Raises
    ------
    InputError
        For random draws, no rows, a grid point without any row, or two rows at one
        grid point with different outputs.
    """
    hint = SPEC_HINTS.get(model, "a grid sweep spec")
    if mode == "random":  # the sweep records how the rows were made
        raise InputError(
            "lookup needs a grid table (one row at every combination of the distinct "
            f"{', '.join(axes)} values): this one holds random draws (vimpact.mode = "
            f"random); make a grid with `vimpact sweep {hint}`")
    coords = np.column_stack([rows[a].to_numpy(float) for a in axes])
    keep = np.all(np.isfinite(coords), axis=1)
    rows, coords = rows[keep], coords[keep]
    if not len(rows):
        raise InputError("lookup needs a grid table, and this one has no rows with finite "
                         + ", ".join(axes))
    nodes, index = zip(*(cluster_nodes(coords[:, k]) for k in range(len(axes))))
    shape = tuple(len(n) for n in nodes)
    flat = np.ravel_multi_index(tuple(index), shape)
    covered = np.unique(flat).size
    if covered < math.prod(shape):
        raise InputError(
            f"lookup needs a grid table (one row at every combination of the distinct "
            f"{', '.join(axes)} values): this table has {len(rows)} rows at {covered} distinct "
            f"points but {' x '.join(f'{n} {a}' for a, n in zip(axes, shape))} distinct values "
            f"(random draws are not a grid); make one with `vimpact sweep {hint}`")
    data = rows["status"].isin(DATA_STATUSES).to_numpy()
    n_points = math.prod(shape)
    count = np.bincount(flat[data], minlength=n_points)
    values = {}
    for name in ("e_z", "beta_x", "e_x"):
        col = rows[name].to_numpy(float)
        total = np.bincount(flat[data], weights=col[data], minlength=n_points)
        lo = np.full(n_points, np.inf)
        hi = np.full(n_points, -np.inf)
        np.minimum.at(lo, flat[data], col[data])
        np.maximum.at(hi, flat[data], col[data])
        clash = (count > 1) & ~(hi - lo <= 1e-9 * np.maximum(1.0, np.abs(hi)))
        if np.any(clash):
            k = int(np.flatnonzero(clash)[0])
            where = ", ".join(f"{a} = {fmt(n[i])}" for a, n, i in
                              zip(axes, nodes, np.unravel_index(k, shape)))
            raise InputError(f"lookup needs one result per grid point, but the table has "
                             f"{count[k]} rows with different {name} at {where}")
        with np.errstate(invalid="ignore", divide="ignore"):
            values[name] = np.where(count > 0, total / np.maximum(count, 1), np.nan).reshape(shape)
    failed = int(np.sum(count == 0))
    return TableGrid(axes, list(nodes), values, failed)


class TensorLookup:
    """The tensor-grid lookup of one table: its grids and interpolants, built once.

    Reads the table's rows and metadata when a grid is first needed (a table whose
    ``data`` is replaced before its first lookup is looked up in the new rows).

    Parameters
    ----------
    table : RestitutionTable
        The grid table looked up.
    """

    def __init__(self, table: RestitutionTable):
        self.table = table
        self._grids: dict = {}
        self._hermite: dict = {}
        self._nodes: dict[str, tuple[pd.DataFrame, np.ndarray]] = {}

    def _node_values(self, column: str) -> np.ndarray:
        """Return :func:`node_values` of ``column``, computed once per ``table.data`` object."""
        data = self.table.data
        cached = self._nodes.get(column)
        if cached is None or cached[0] is not data:
            cached = self._nodes[column] = (data, node_values(data, column))
        return cached[1]

    def theta_values(self) -> np.ndarray:
        """Return the table's distinct ``theta_ratio`` values (empty: no such column)."""
        return self._node_values("theta_ratio")

    def psi_values(self) -> np.ndarray:
        """Return the distinct friction incidences ``psi`` of the table (empty: no psi column)."""
        return self._node_values("psi")

    def resolve_theta(self, theta_ratio) -> float | None:
        """Return the theta_ratio slice to use (None: the table has one value / no column).

        Parameters
        ----------
        theta_ratio : float or None
            ``Theta / (m R^2)`` asked for, dimensionless (None: the table's only one).

        Raises
        ------
        InputError
            For a value the table does not hold, or None when it holds several.
        """
        if "theta_ratio" not in self.table.data.columns:
            if theta_ratio is not None and not same_node(theta_ratio, DEFAULT_THETA_RATIO):
                raise InputError(
                    f"theta_ratio = {theta_ratio!r} is not allowed: the table has no theta_ratio "
                    f"column, so it is for Theta / (m R^2) = {DEFAULT_THETA_RATIO} (a solid sphere)")
            return None
        values = self.theta_values()
        if theta_ratio is None:
            if len(values) > 1:
                raise InputError(
                    "theta_ratio is missing: the table holds several Theta / (m R^2) = "
                    + ", ".join(fmt(v) for v in values) + "; give one of them")
            return None
        match = values[same_node(values, theta_ratio)]
        if not len(match):
            raise InputError(
                f"theta_ratio = {theta_ratio!r} is not allowed: the table holds Theta / (m R^2) = "
                + ", ".join(fmt(v) for v in values) + " only (a table with several values "
                "interpolates between them)")
        return None if len(values) == 1 else float(match[0])

    def base_axes(self) -> list[str]:
        """Return the material axes of the lookup: ``Q1``, (``Q2``), ``nu``.

        Raises
        ------
        InputError
            For a table of a model that cannot be looked up.
        """
        model = self.table.model
        if model not in LOOKUP_MODELS:
            raise InputError(f"lookup needs a kelvin_voigt or standard_solid table, "
                             f"this one is {model!r}")
        return ["Q1", "Q2", "nu"] if model == "standard_solid" else ["Q1", "nu"]

    def _build(self, axes: list[str], rows: pd.DataFrame) -> TableGrid:
        return build_grid(axes, rows, self.table.model, self.table.meta("mode"))

    def grid(self, theta: float | None) -> TableGrid:
        """Return the grid at one ``theta_ratio`` (None: the table's only one).

        Axes ``Q1``, (``Q2``), ``nu`` and ``psi`` if the table has a psi column.
        """
        if theta in self._grids:
            return self._grids[theta]
        axes = self.base_axes() + (["psi"] if len(self.psi_values()) else [])
        rows = self.table.data
        if theta is not None:
            rows = rows[same_node(rows["theta_ratio"].to_numpy(float), theta)]
        grid = self._build(axes, rows)
        self._grids[theta] = grid
        return grid

    def lookup_grid(self) -> TableGrid:
        """Return the grid over every lookup axis.

        ``Q1``, (``Q2``), ``nu``, ``theta_ratio`` (when the table holds several
        values), ``psi`` (when it has a psi column).
        """
        if ALL_AXES in self._grids:
            return self._grids[ALL_AXES]
        thetas = self.theta_values()
        axes = (self.base_axes() + (["theta_ratio"] if len(thetas) > 1 else [])
                + (["psi"] if len(self.psi_values()) else []))
        grid = self._build(axes, self.table.data)
        self._grids[ALL_AXES] = grid
        return grid

    def hermite(self, key, grid: TableGrid | None = None) -> HermiteGrid:
        """Return the cubic interpolant of the grid for ``key``.

        ``key`` is a ``theta_ratio`` slice (:meth:`grid`) or :data:`ALL_AXES`; the
        interpolant of ``grid`` when given, cached under ``key``; slopes computed once.
        """
        if key not in self._hermite:
            from vimpact.lookup.interpolate import HermiteGrid

            grid = self.grid(key) if grid is None else grid
            self._hermite[key] = HermiteGrid(grid.axes, grid.nodes, grid.values,
                                             log_axes=LOG_AXES)
        return self._hermite[key]

    def __call__(self, arrays: dict[str, np.ndarray], thetas: np.ndarray, theta_ratio,
                 method: str, extrapolate: bool) -> dict[str, np.ndarray]:
        """Interpolate ``e_z``, ``e_x``, ``beta_x`` at checked, broadcast query points.

        Parameters
        ----------
        arrays : dict
            Axis -> coordinates (:func:`vimpact.lookup.query.query_arrays`).
        thetas : numpy.ndarray
            The table's ``theta_ratio`` values (:meth:`theta_values`).
        theta_ratio : float, array_like or None
            As given to the lookup: a scalar at one of several tabulated values looks
            up that slice's grid; otherwise the grid over every axis.
        method : str
            ``"cubic"`` or ``"linear"``.
        extrapolate : bool
            Extrapolate linearly beyond the covered range; results clipped to
            ``0 <= e_z, e_x <= 1``, ``|beta_x| <= 1``.

        Returns
        -------
        dict
            Output name -> array; ``e_x`` is ``|beta_x|`` where ``beta_x`` is known.
        """
        theta_axis = len(thetas) > 1
        # one theta_ratio node: the slice at it (a table need not be a grid across thetas)
        theta = None
        if theta_axis and np.ndim(theta_ratio) == 0 and same_node(thetas, theta_ratio).any():
            theta = float(thetas[same_node(thetas, theta_ratio)][0])
        key: float | str | None
        if theta_axis and theta is None:
            grid, key = self.lookup_grid(), ALL_AXES
        else:
            grid, key = self.grid(theta), theta
        if method == "cubic":
            out = self.hermite(key, grid)([arrays[a] for a in grid.axes], extrapolate)
        else:
            out = grid.interpolate([arrays[a] for a in grid.axes], extrapolate)
        if extrapolate:
            out["e_z"] = np.clip(out["e_z"], 0.0, 1.0)
            out["beta_x"] = np.clip(out["beta_x"], -1.0, 1.0)
        # |beta_x| where beta_x is known; the interpolated e_x where only it is
        out["e_x"] = np.where(np.isfinite(out["beta_x"]), np.abs(out["beta_x"]), out["e_x"])
        if extrapolate:
            out["e_x"] = np.clip(out["e_x"], 0.0, 1.0)
        return out
