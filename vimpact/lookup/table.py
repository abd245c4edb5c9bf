"""Restitution tables: read, describe, interpolate, and turn into e(v) curves.

A restitution table is a Parquet file, or a partitioned Parquet dataset (a
directory of part files plus ``_common_metadata``), written by the sweep
driver (:mod:`vimpact.sweep`):
one row per impact with the columns ``Q1``, ``Q2`` (NaN for Kelvin-Voigt, see below),
``nu``, ``e_z``, ``e_x``, ``beta_x``, ``t_contact_s``, ``u_max_m``,
``a_max_m``, ``energy_ratio``, ``status`` (optionally ``theta_ratio`` and
physical inputs with unit suffixes), and key-value metadata
``vimpact.model``, ``vimpact.units`` (JSON), ``vimpact.numerics`` (JSON),
``vimpact.schema_version``, ``vimpact.version``, ``vimpact.spec``.

Only rows whose status is in :data:`DATA_STATUSES` are data; the others
record failures and are skipped.

Kelvin-Voigt rows: the Kelvin-Voigt solid is the standard solid's limit
``G2 -> inf``, i.e. ``Q2 = G1/G2 -> 0`` at the same ``Q1`` (``Q2 -> inf`` is
the elastic limit). ``Q2 = 0`` would also read as ``G1 = 0`` (a Maxwell fluid)
and meets ``log 0`` on a log ``Q2`` axis, so a Kelvin-Voigt row has ``Q2 = NaN``
(no ``Q2``), and every table read gets a text column ``model`` (the row's
rheology: ``kelvin_voigt`` or ``standard_solid``) that survives merging tables.
Old tables with ``Q2 = 0`` are translated on read.

Lookup (:meth:`RestitutionTable.lookup`) needs a *grid* table (every
combination of the distinct ``Q1`` [, ``Q2``], ``nu`` values present). By
default it interpolates with tensor-product cubic Hermite polynomials in
``log Q1`` (and ``log Q2``) and ``nu``, shape-preserving where the data is
monotone (:mod:`vimpact.lookup.interpolate`); ``method="linear"`` gives the
multilinear interpolant. The error between the nodes, measured against direct
simulation (:func:`vimpact.lookup.verify.interpolation_error`), is stored as
the metadata entry ``vimpact.interpolation_error`` and returned with every
lookup (``error_bound``). Since ``e_z``, ``e_x`` depend only on these parameters
(docs/physics.md#dimensionless-parameters), :meth:`RestitutionTable.restitution_curve` turns a
table into ``e_z(v_z0)``, ``e_x(v_z0)`` for one material and sphere, the form
a DEM code needs.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from vimpact.engine.result import STATUSES
from vimpact.model.scene import HALF_SPACE_LIMIT, Scene
from vimpact.model.validation import positive, require

__all__ = ["DATA_STATUSES", "LOOKUP_METHODS", "LOOKUP_MODELS", "OUTPUTS", "SPEC_HINTS",
           "RestitutionTable", "format_info"]

#: Interpolation methods of :meth:`RestitutionTable.lookup`.
LOOKUP_METHODS = ("cubic", "linear")

#: Statuses whose rows are data (all others are failures and are skipped).
DATA_STATUSES = ("ok",)

#: Models whose tables :meth:`RestitutionTable.lookup` can interpolate.
LOOKUP_MODELS = ("kelvin_voigt", "standard_solid")

#: Which sweep spec produces a grid table for lookup, by model.
SPEC_HINTS = {
    "kelvin_voigt": "sweeps/kelvin_voigt_table.toml",
    "standard_solid": "sweeps/standard_solid_table.toml",
}

#: Outputs interpolated by :meth:`RestitutionTable.lookup` (all dimensionless).
OUTPUTS = ("e_z", "e_x", "beta_x")

_REQUIRED = ("Q1", "nu", "e_z", "e_x", "beta_x", "status")
_META_PREFIX = "vimpact."  # the sweep's vimpact.sweep.store.META_PREFIX
#: Theta / (m R^2) of a table without a ``theta_ratio`` column (the solid sphere,
#: ``Scene``'s default).
DEFAULT_THETA_RATIO = 0.4
#: Two parameter values closer than this (relative) are the same grid node.
_NODE_RTOL = 1e-9
_NODE_ATOL = 1e-12


def _axis_is_log(name: str) -> bool:
    return name in ("Q1", "Q2")


def _fmt(x: float) -> str:
    return f"{x:.6g}"


# --------------------------------------------------------------------------
# grid helpers
# --------------------------------------------------------------------------

def _same(a, b) -> np.ndarray:
    """Elementwise: ``a`` and ``b`` are the same grid coordinate."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.abs(a - b) <= _NODE_RTOL * np.maximum(np.abs(a), np.abs(b)) + _NODE_ATOL


def _cluster(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distinct values up to round-off: ``(nodes, index of each value)``.

    Values within ``1e-9`` (relative) of a cluster's first member join it;
    the node is the cluster's median member (a value that occurs in the data).
    """
    order = np.argsort(values, kind="stable")
    s = values[order]
    starts = [0]
    for i in range(1, len(s)):
        if not _same(s[starts[-1]], s[i]):
            starts.append(i)
    bounds = starts + [len(s)]
    nodes = np.array([s[(bounds[k] + bounds[k + 1] - 1) // 2] for k in range(len(starts))])
    labels = np.empty(len(s), dtype=np.int64)
    for k in range(len(starts)):
        labels[bounds[k]:bounds[k + 1]] = k
    index = np.empty(len(values), dtype=np.int64)
    index[order] = labels
    return nodes, index


class _Grid:
    """The table's outputs on a full rectangular grid of its parameters."""

    def __init__(self, axes: list[str], nodes: list[np.ndarray], values: dict[str, np.ndarray],
                 failed: int):
        self.axes = axes          # e.g. ["Q1", "nu"] or ["Q1", "Q2", "nu"]
        self.nodes = nodes        # sorted node values per axis
        self.values = values      # output name -> array of shape (len(nodes[0]), ...)
        self.failed = failed      # grid points without a data row (NaN)

    @property
    def shape(self) -> dict[str, int]:
        return {a: len(n) for a, n in zip(self.axes, self.nodes)}

    def _weights(self, k: int, x: np.ndarray, extrapolate: bool):
        """Cell index ``i0``, ``i1`` and weight ``t`` of ``x`` on axis ``k``:
        ``value = (1 - t) f[i0] + t f[i1]``."""
        name, nodes = self.axes[k], self.nodes[k]
        lo, hi = nodes[0], nodes[-1]
        inside = ((x >= lo) | _same(x, lo)) & ((x <= hi) | _same(x, hi))
        if not extrapolate and not np.all(inside):
            bad = float(x[~inside].flat[0])
            covered = (f"{name} = {_fmt(lo)} only (a single grid value)" if len(nodes) == 1
                       else f"{name} in [{_fmt(lo)}, {_fmt(hi)}]")
            raise ValueError(
                f"{name} = {bad:.6g} is outside the table's range: it covers {covered}; "
                "extrapolate=True (--extrapolate) extrapolates linearly"
                + (f" in log {name}" if _axis_is_log(name) else ""))
        if not extrapolate:
            x = np.clip(x, lo, hi)  # values within round-off of an end node
        if len(nodes) == 1:  # a single value: constant along this axis
            zero = np.zeros(x.shape, dtype=np.int64)
            return zero, zero, np.zeros(x.shape)
        i0 = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, len(nodes) - 2)
        a, b = nodes[i0], nodes[i0 + 1]
        if _axis_is_log(name):
            if np.any(x <= 0.0) and lo > 0.0:
                bad = float(x[x <= 0.0].flat[0])
                raise ValueError(
                    f"{name} = {bad:.6g} cannot be extrapolated on the table's log {name} axis: "
                    f"it covers {name} in [{_fmt(lo)}, {_fmt(hi)}]; give {name} > 0")
            log_cell = a > 0.0  # a cell starting at 0 (an elastic node) is linear in the value
            xs = np.where(log_cell, x, 1.0)
            as_ = np.where(log_cell, a, 1.0)
            t = np.where(log_cell, np.log(xs / as_) / np.log(b / as_), (x - a) / (b - a))
        else:
            t = (x - a) / (b - a)
        # a value within round-off (1e-9) of a node gives that node's row exactly
        t = np.where(_same(x, a), 0.0, np.where(_same(x, b), 1.0, t))
        return i0, i0 + 1, t

    def interpolate(self, coords: list[np.ndarray], extrapolate: bool) -> dict[str, np.ndarray]:
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


def _kelvin_voigt_rows(data: pd.DataFrame, model: str) -> pd.DataFrame:
    """Kelvin-Voigt rows unambiguous: ``Q2 = NaN`` (not 0) and a ``model`` column.

    The Kelvin-Voigt solid is the limit ``G2 -> inf`` (``Q2 -> 0``) of the standard
    solid; old tables wrote it as ``Q2 = 0``, which also reads as a Maxwell fluid
    (``G1 = 0``) and is ``log 0`` on a log ``Q2`` axis. Rows of a Kelvin-Voigt table,
    and rows of a standard-solid table with ``Q2 = 0``, become ``Q2 = NaN`` with
    ``model = "kelvin_voigt"``; an existing ``model`` column is kept.
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


# --------------------------------------------------------------------------
# the table
# --------------------------------------------------------------------------

class RestitutionTable:
    """A restitution table: rows of impacts plus the sweep's metadata.

    Parameters
    ----------
    data : DataFrame
        One row per impact with at least the columns ``Q1``, ``nu``, ``e_z``,
        ``e_x``, ``beta_x``, ``status`` (and ``Q2`` for a standard solid).
    metadata : dict, optional
        Key-value metadata. Keys with or without the ``vimpact.`` prefix,
        str or bytes; dict values are stored as JSON. ``model`` is inferred
        from ``Q2`` (all NaN -> ``kelvin_voigt``) when missing.
    path : where the table was read from (for messages), optional
    """

    def __init__(self, data: pd.DataFrame, metadata: dict | None = None, path=None):
        require("data", type(data).__name__, isinstance(data, pd.DataFrame), "a pandas DataFrame")
        missing = [c for c in _REQUIRED if c not in data.columns]
        if missing:
            raise ValueError(f"the table{self._where(path)} lacks the column(s) "
                             f"{', '.join(missing)}: a restitution table has "
                             f"{', '.join(_REQUIRED)} (and Q2 for a standard solid)")
        self.data = data.reset_index(drop=True)
        self.path = None if path is None else Path(path)
        self.metadata: dict[str, str] = {}
        for key, value in (metadata or {}).items():
            key = key.decode() if isinstance(key, bytes) else str(key)
            if isinstance(value, bytes):
                value = value.decode()
            elif not isinstance(value, str):
                value = json.dumps(value)
            if not key.startswith(_META_PREFIX):
                key = _META_PREFIX + key
            self.metadata[key] = value
        if self.model == "standard_solid" and "Q2" not in self.data.columns:
            raise ValueError(f"the standard_solid table{self._where(path)} lacks the column Q2")
        self.data = _kelvin_voigt_rows(self.data, self.model)
        self._grids: dict = {}
        self._hermite: dict = {}

    @staticmethod
    def _where(path) -> str:
        return f" {str(path)!r}" if path is not None else ""

    # ---- reading and writing -------------------------------------------
    @classmethod
    def open(cls, path) -> "RestitutionTable":
        """Read a restitution table and its ``vimpact.*`` metadata: one Parquet file, or a
        partitioned dataset written by a large sweep (a directory of part files plus
        ``_common_metadata``, which holds the metadata)."""
        import pyarrow.parquet as pq

        from vimpact.sweep.store import COMMON_METADATA

        p = Path(path)
        if p.is_dir():
            if not (p / COMMON_METADATA).is_file():
                raise ValueError(
                    f"table = {str(path)!r} is not allowed: a directory without "
                    f"{COMMON_METADATA} (an unfinished sweep dataset: finish it with "
                    "`vimpact sweep SPEC --resume`, or --combine after shards)")
        elif not p.is_file():
            raise ValueError(f"table = {str(path)!r} is not allowed: no such file "
                             "(a Parquet restitution table written by `vimpact sweep`)")
        try:
            arrow = pq.read_table(p)
            raw = (pq.read_schema(p / COMMON_METADATA) if p.is_dir() else arrow.schema).metadata
        except Exception as exc:  # pyarrow raises several types for a bad file
            why = (str(exc).splitlines() or [""])[0]
            raise ValueError(f"table = {str(path)!r} is not allowed: not a readable Parquet "
                             f"file ({type(exc).__name__}: {why})") from None
        meta = {k.decode(): v.decode() for k, v in (raw or {}).items()
                if k.decode().startswith(_META_PREFIX)}
        if p.is_dir():  # the parts' schemas carry per-chunk bookkeeping
            arrow = arrow.replace_schema_metadata(None)
        return cls(arrow.to_pandas(), meta, path=p)

    def save(self, path) -> Path:
        """Write the table as Parquet with its ``vimpact.*`` metadata (what :meth:`open` reads)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        arrow = pa.Table.from_pandas(self.data, preserve_index=False)
        meta = dict(arrow.schema.metadata or {})
        meta.update({k.encode(): v.encode() for k, v in self.metadata.items()})
        pq.write_table(arrow.replace_schema_metadata(meta), path)
        return Path(path)

    # ---- metadata --------------------------------------------------------
    def meta(self, key: str, default=None):
        """Metadata value ``vimpact.<key>``, decoded by the sweep's metadata codec
        (:func:`vimpact.sweep.store.decode_value`: JSON keys such as ``units``,
        ``numerics``, ``paths`` parsed, integer keys such as ``rows`` as ints)."""
        from vimpact.sweep.store import decode_value

        value = self.metadata.get(_META_PREFIX + key)
        if value is None:
            return default
        return decode_value(key, value)

    @property
    def model(self) -> str:
        """Rheology of the table (``vimpact.model``; inferred from ``Q2`` if missing)."""
        model = self.metadata.get(_META_PREFIX + "model")
        if model:
            return model
        if "Q2" in self.data.columns and (self.data["Q2"].to_numpy(float) > 0).any():
            return "standard_solid"  # Q2 = 0 or NaN: Kelvin-Voigt (the limit G2 -> inf)
        return "kelvin_voigt"

    @property
    def units(self) -> dict:
        """Column -> unit (``vimpact.units``), empty if not recorded."""
        units = self.meta("units", {})
        return units if isinstance(units, dict) else {}

    @property
    def numerics(self):
        """The sweep's numerics as recorded (a dict from JSON, or None)."""
        return self.meta("numerics")

    @property
    def version(self) -> str | None:
        """vimpact version that wrote the table."""
        return self.meta("version")

    # ---- rows ------------------------------------------------------------
    @property
    def ok(self) -> pd.DataFrame:
        """The data rows (status in :data:`DATA_STATUSES`)."""
        return self.data[self.data["status"].isin(DATA_STATUSES)]

    def __len__(self) -> int:
        return len(self.data)

    def info(self) -> dict:
        """Summary: model, rows, ok rows, status counts, covered ranges, grid,
        numerics, version (JSON-serializable; ``str(table)`` is the readable form)."""
        ok = self.ok
        params = ["Q1"] + (["Q2"] if self.model == "standard_solid" else []) + ["nu"]
        if "theta_ratio" in self.data.columns:
            params.append("theta_ratio")
        ranges = {}
        for p in params:
            v = ok[p].to_numpy(float) if p in ok.columns else np.array([])
            v = v[np.isfinite(v)]
            ranges[p] = [float(v.min()), float(v.max())] if len(v) else None
        thetas = self._theta_values() if "theta_ratio" in self.data.columns else np.array([])
        try:
            grid = self._grid(float(thetas[0]) if len(thetas) > 1 else None)
            grid_info, failed = grid.shape, grid.failed
            note = (f"per theta_ratio ({len(thetas)} values; lookup takes one of them)"
                    if len(thetas) > 1 else None)
        except ValueError as exc:
            grid_info, failed, note = None, None, str(exc)
        spec = self.meta("spec")
        return {
            "path": None if self.path is None else str(self.path),
            "model": self.model,
            "rows": int(len(self.data)),
            "ok_rows": int(len(ok)),
            "statuses": {str(k): int(v) for k, v in self.data["status"].value_counts().items()},
            "ranges": ranges,
            "grid": grid_info,
            "failed_grid_points": failed,
            "grid_note": note,
            "numerics": self.numerics,
            "version": self.version,
            "schema_version": self.meta("schema_version"),
            "spec": spec,
            "spec_name": self.meta("spec_name"),
            "description": self.meta("description"),
            "columns": [str(c) for c in self.data.columns],
            "interpolation_error": self.interpolation_error,
        }

    def __str__(self) -> str:
        return format_info(self.info())

    def __repr__(self) -> str:
        where = f" {str(self.path)!r}" if self.path else ""
        return f"<RestitutionTable{where}: {self.model}, {len(self.data)} rows, {len(self.ok)} ok>"

    # ---- lookup ----------------------------------------------------------
    def _theta_values(self) -> np.ndarray:
        v = self.data["theta_ratio"].to_numpy(float)
        return _cluster(v[np.isfinite(v)])[0] if np.isfinite(v).any() else np.array([])

    def _resolve_theta(self, theta_ratio) -> float | None:
        """The theta_ratio slice to use (None: the table has one value / no column)."""
        if "theta_ratio" not in self.data.columns:
            if theta_ratio is not None and not _same(theta_ratio, DEFAULT_THETA_RATIO):
                raise ValueError(
                    f"theta_ratio = {theta_ratio!r} is not allowed: the table has no theta_ratio "
                    f"column, so it is for Theta / (m R^2) = {DEFAULT_THETA_RATIO} (a solid sphere)")
            return None
        values = self._theta_values()
        if theta_ratio is None:
            if len(values) > 1:
                raise ValueError(
                    "theta_ratio is missing: the table holds several Theta / (m R^2) = "
                    + ", ".join(_fmt(v) for v in values) + "; give one of them")
            return None
        match = values[_same(values, theta_ratio)]
        if not len(match):
            raise ValueError(
                f"theta_ratio = {theta_ratio!r} is not allowed: the table holds Theta / (m R^2) = "
                + ", ".join(_fmt(v) for v in values) + " (no interpolation in theta_ratio)")
        return None if len(values) == 1 else float(match[0])

    def _grid(self, theta: float | None) -> _Grid:
        if theta in self._grids:
            return self._grids[theta]
        model = self.model
        if model not in LOOKUP_MODELS:
            raise ValueError(f"lookup needs a kelvin_voigt or standard_solid table, "
                             f"this one is {model!r}")
        axes = ["Q1", "Q2", "nu"] if model == "standard_solid" else ["Q1", "nu"]
        hint = SPEC_HINTS.get(model, "a grid sweep spec")
        if self.meta("mode") == "random":  # the sweep records how the rows were made
            raise ValueError(
                "lookup needs a grid table (one row at every combination of the distinct "
                f"{', '.join(axes)} values): this one holds random draws (vimpact.mode = "
                f"random); make a grid with `vimpact sweep {hint}`")
        rows = self.data
        if theta is not None:
            rows = rows[_same(rows["theta_ratio"].to_numpy(float), theta)]
        coords = np.column_stack([rows[a].to_numpy(float) for a in axes])
        keep = np.all(np.isfinite(coords), axis=1)
        rows, coords = rows[keep], coords[keep]
        if not len(rows):
            raise ValueError("lookup needs a grid table, and this one has no rows with finite "
                             + ", ".join(axes))
        nodes, index = zip(*(_cluster(coords[:, k]) for k in range(len(axes))))
        shape = tuple(len(n) for n in nodes)
        flat = np.ravel_multi_index(tuple(index), shape)
        covered = np.unique(flat).size
        if covered < math.prod(shape):
            raise ValueError(
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
                where = ", ".join(f"{a} = {_fmt(n[i])}" for a, n, i in
                                  zip(axes, nodes, np.unravel_index(k, shape)))
                raise ValueError(f"lookup needs one result per grid point, but the table has "
                                 f"{count[k]} rows with different {name} at {where}")
            with np.errstate(invalid="ignore", divide="ignore"):
                values[name] = np.where(count > 0, total / np.maximum(count, 1), np.nan).reshape(shape)
        failed = int(np.sum(count == 0))
        grid = _Grid(axes, list(nodes), values, failed)
        self._grids[theta] = grid
        return grid

    def _hermite_grid(self, theta: float | None):
        """The cubic interpolant of the grid for ``theta`` (slopes computed once)."""
        if theta not in self._hermite:
            from vimpact.lookup.interpolate import HermiteGrid

            grid = self._grid(theta)
            self._hermite[theta] = HermiteGrid(grid.axes, grid.nodes, grid.values)
        return self._hermite[theta]

    @property
    def interpolation_error(self) -> dict | None:
        """The measured interpolation error (metadata ``vimpact.interpolation_error``,
        written by :func:`vimpact.lookup.verify.interpolation_error` /
        ``vimpact table verify --write``), or None if not measured."""
        raw = self.metadata.get(_META_PREFIX + "interpolation_error")
        if raw is None:
            return None
        try:
            value = json.loads(raw)
        except ValueError:
            return None
        return value if isinstance(value, dict) else None

    def error_bound(self, method: str = "cubic") -> dict | None:
        """Output -> the error bound measured between the nodes for ``method``
        (``{"e_z": ..., "beta_x": ..., "e_x": ...}``: the stored ``bound``, 1.5 times
        the largest error found at the held-out points, see
        :data:`vimpact.lookup.verify.BOUND_FACTOR`), or None if not measured."""
        err = self.interpolation_error
        if not err or err.get("method", "cubic") != method:
            return None
        out = {}
        for k, v in err.get("outputs", {}).items():
            value = v.get("bound", v.get("max")) if isinstance(v, dict) else None
            out[k] = None if value is None else float(value)
        return out

    def lookup(self, Q1, nu, Q2=None, extrapolate: bool = False, theta_ratio=None,
               method: str = "cubic") -> dict:
        """Interpolate ``e_z``, ``e_x``, ``beta_x`` at ``Q1``, ``nu`` (and ``Q2``).

        ``method="cubic"`` (default): tensor-product cubic Hermite in ``log Q1``,
        ``log Q2`` and ``nu``, shape-preserving where the data is monotone
        (:mod:`vimpact.lookup.interpolate`); ``"linear"``: multilinear (linear in
        ``log Q1``, ``log Q2`` and ``nu``). At a grid point either returns that
        row's values. ``e_x`` is ``|beta_x|`` of the interpolated ``beta_x``
        (exact at grid points and right where ``beta_x`` changes sign between
        them). Vectorized, slopes computed once per table: 1e6 points take about
        0.5 s (Q1 x nu) and 2 s (Q1 x Q2 x nu) of one core, measured by
        ``python -m benchmarks.lookup``.

        Parameters
        ----------
        Q1 : float or array_like
            damping parameter ``sqrt(15/32) (eta/G_inf)/T``, dimensionless, > 0
        nu : float or array_like
            Poisson ratio, dimensionless
        Q2 : float or array_like, optional
            ``G1/G2``, dimensionless: required for a standard-solid table,
            not allowed for a Kelvin-Voigt one
        extrapolate : bool
            outside the covered range extrapolate linearly from the edge
            (cubic: with the end node's slope; results clipped to the physical bounds ``0 <= e_z, e_x <= 1``,
            ``|beta_x| <= 1``) instead of raising
        theta_ratio : float, optional
            ``Theta / (m R^2)``; needed only when the table holds several
        method : ``"cubic"`` (default) or ``"linear"``

        Returns
        -------
        dict
            ``Q1``, (``Q2``), ``nu`` (broadcast inputs) and ``e_z``, ``e_x``,
            ``beta_x`` (dimensionless): floats for scalar inputs, arrays of the
            broadcast shape otherwise. NaN where the interpolation needs a grid
            point whose impact failed. ``error_bound``: output -> the largest
            interpolation error measured between the nodes for this method
            (:attr:`interpolation_error`), None if the table was not verified;
            it holds inside the covered range, not for extrapolated values.

        Raises
        ------
        ValueError
            outside the covered range (naming the parameter, value and range),
            for a table that is not a grid, or for ``Q2`` given to a
            Kelvin-Voigt table / missing for a standard-solid one.
        """
        model = self.model
        if method not in LOOKUP_METHODS:
            raise ValueError(f"method = {method!r} is not allowed: must be one of "
                             + ", ".join(LOOKUP_METHODS))
        if model == "kelvin_voigt" and Q2 is not None:
            raise ValueError(f"Q2 = {Q2!r} is not allowed: this is a kelvin_voigt table "
                             "(e_z, e_x depend on Q1 and nu only); omit Q2 or use a "
                             "standard_solid table")
        if model == "standard_solid" and Q2 is None:
            raise ValueError("Q2 is missing: this is a standard_solid table, lookup needs "
                             "Q2 = G1/G2 as well as Q1 and nu")
        named = {"Q1": Q1, "nu": nu} if Q2 is None else {"Q1": Q1, "Q2": Q2, "nu": nu}
        arrays = {}
        for name, value in named.items():
            try:
                arr = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                raise ValueError(f"{name} = {value!r} is not allowed: must be a number or "
                                 "an array of numbers") from None
            if not np.all(np.isfinite(arr)):
                bad = float(arr[~np.isfinite(arr)].flat[0])
                raise ValueError(f"{name} = {bad!r} is not allowed: must be finite")
            arrays[name] = arr
        try:
            bcast = np.broadcast_arrays(*arrays.values())
        except ValueError:
            raise ValueError("Q1, nu" + (", Q2" if Q2 is not None else "") + " have shapes "
                             + ", ".join(str(a.shape) for a in arrays.values())
                             + " that do not broadcast together") from None
        arrays = dict(zip(arrays, bcast))
        theta = self._resolve_theta(theta_ratio)
        grid = self._grid(theta)
        if method == "cubic":
            out = self._hermite_grid(theta)([arrays[a] for a in grid.axes], extrapolate)
        else:
            out = grid.interpolate([arrays[a] for a in grid.axes], extrapolate)
        if extrapolate:
            out["e_z"] = np.clip(out["e_z"], 0.0, 1.0)
            out["beta_x"] = np.clip(out["beta_x"], -1.0, 1.0)
        # |beta_x| where beta_x is known; the interpolated e_x where only it is
        out["e_x"] = np.where(np.isfinite(out["beta_x"]), np.abs(out["beta_x"]), out["e_x"])
        if extrapolate:
            out["e_x"] = np.clip(out["e_x"], 0.0, 1.0)
        result = {**arrays, **{k: out[k] for k in OUTPUTS}}
        if all(a.ndim == 0 for a in bcast):
            result = {k: float(v) for k, v in result.items()}
        else:
            result = {k: np.asarray(v, dtype=float) for k, v in result.items()}
        result["error_bound"] = self.error_bound(method)
        return result

    def to_xarray(self, theta_ratio=None):
        """The grid as an :class:`xarray.Dataset`: data variables ``e_z``, ``e_x``,
        ``beta_x`` (dimensionless) over the labelled axes ``Q1``, (``Q2``), ``nu``.

        Units and descriptions are attributes of each variable and axis; the
        dataset's attributes hold the model, numerics, interpolation error and
        version (JSON text where structured). xarray is optional: it is imported
        here, and its absence is an :class:`~vimpact.model.validation.InputError`.
        """
        try:
            import xarray as xr
        except ImportError:
            from vimpact.model.validation import InputError

            raise InputError("to_xarray = xarray is not allowed here: xarray is not installed "
                             "(pip install xarray); RestitutionTable.data is the same table "
                             "as a pandas DataFrame") from None
        grid = self._grid(self._resolve_theta(theta_ratio))
        units = self.units
        described = {"Q1": "damping parameter sqrt(15/32) (eta/G_inf)/T",
                     "Q2": "G1/G2 of the standard solid", "nu": "Poisson ratio",
                     "e_z": "normal coefficient of restitution",
                     "e_x": "tangential coefficient of restitution |beta_x|",
                     "beta_x": "tangential coefficient of restitution (signed)"}
        coords = {a: (a, n, {"units": units.get(a, "1"), "long_name": described.get(a, a)})
                  for a, n in zip(grid.axes, grid.nodes)}
        data_vars = {k: (grid.axes, grid.values[k], {"units": units.get(k, "1"),
                                                     "long_name": described[k]})
                     for k in OUTPUTS}
        attrs = {"model": self.model,
                 "numerics": json.dumps(self.numerics),
                 "interpolation_error": json.dumps(self.interpolation_error),
                 "vimpact_version": str(self.version),
                 "source": "" if self.path is None else str(self.path)}
        return xr.Dataset(data_vars, coords=coords, attrs=attrs)

    # ---- physical curves -------------------------------------------------
    def restitution_curve(self, material, R: float, m: float, v_z0, theta_ratio=None,
                          extrapolate: bool = False,
                          allow_large_contact: bool = False) -> pd.DataFrame:
        """``e_z``, ``e_x``, ``beta_x`` against impact speed for one material and sphere.

        ``Q1`` depends on the speed through the Hertz time ``T`` (``Q1`` grows
        as ``v_z0^(1/5)``); each speed is turned into a :class:`vimpact.Scene`
        for its ``Q1`` (``Q2``) and looked up in the table.

        Parameters
        ----------
        material : vimpact.Material whose model is the table's
        R : sphere radius, m
        m : sphere mass, kg
        v_z0 : normal impact speeds, m/s (> 0)
        theta_ratio : ``Theta / (m R^2)`` (default: the table's)
        extrapolate : see :meth:`lookup`
        allow_large_contact : accept speeds whose Hertz contact radius (an
            upper bound of the contact half-width) exceeds ``0.2 R``

        Returns
        -------
        DataFrame with columns ``v_z0_m_s``, ``Q1``, (``Q2``), ``e_z``,
        ``e_x``, ``beta_x``; ``attrs`` holds the units and the inputs.
        """
        from vimpact.model.material import Material

        require("material", material, isinstance(material, Material), "a vimpact.Material")
        if material.model != self.model:
            raise ValueError(f"material model {material.model!r} does not match the table's "
                             f"model {self.model!r}")
        R, m = positive("R", R), positive("m", m)
        speeds = np.atleast_1d(np.asarray(v_z0, dtype=float)).ravel()
        require("v_z0", v_z0, speeds.size > 0, "at least one speed (m/s)")
        scenes = [Scene(material, R=R, m=m, v_z0=float(v), allow_large_contact=True) for v in speeds]
        if not allow_large_contact:
            big = [s for s in scenes if s.hertz.a_H > HALF_SPACE_LIMIT * R]
            if big:
                s = big[0]
                raise ValueError(
                    f"v_z0 = {s.v_z0:.6g} m/s is not allowed: its Hertz contact radius "
                    f"{s.hertz.a_H:.4g} m exceeds 0.2 R = {HALF_SPACE_LIMIT * R:.4g} m (outside "
                    "the half-space model; allow_large_contact=True / --allow-large-contact "
                    "accepts it)")
        q1 = np.array([s.Q1 for s in scenes])
        q2 = np.array([s.Q2 for s in scenes]) if self.model == "standard_solid" else None
        res = self.lookup(q1, material.nu, q2, extrapolate=extrapolate, theta_ratio=theta_ratio)
        columns = {"v_z0_m_s": speeds, "Q1": q1}
        if q2 is not None:
            columns["Q2"] = q2
        columns.update({k: res[k] for k in OUTPUTS})
        df = pd.DataFrame(columns)
        df.attrs.update({
            "units": {"v_z0_m_s": "m/s", **{k: "1" for k in columns if k != "v_z0_m_s"}},
            "model": material.model, "nu": material.nu, "R_m": R, "m_kg": m,
            "table": None if self.path is None else str(self.path),
        })
        return df

    def export_curve(self, path, material, R: float, m: float, v_z0, **options) -> pd.DataFrame:
        """Write :meth:`restitution_curve` to a CSV file ``path`` (``.csv``); returns the curve.

        Columns ``v_z0_m_s`` (m/s), ``Q1``, (``Q2``), ``e_z``, ``e_x``,
        ``beta_x`` (dimensionless); ``options`` as for :meth:`restitution_curve`.
        """
        p = Path(path)
        require("out", str(path), p.suffix.lower() == ".csv", "a file name ending in .csv")
        require("out", str(path), p.parent.is_dir(), "in an existing directory")
        df = self.restitution_curve(material, R, m, v_z0, **options)
        df.to_csv(p, index=False, float_format="%.10g")
        return df


# --------------------------------------------------------------------------
# text
# --------------------------------------------------------------------------

def format_info(info: dict) -> str:
    """Readable form of :meth:`RestitutionTable.info`."""
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
        text = "no data" if r is None else (_fmt(r[0]) if _same(r[0], r[1])
                                            else f"{_fmt(r[0])} .. {_fmt(r[1])}")
        lines.append(f"  {name:<15} {text}")
    if info["grid"]:
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
