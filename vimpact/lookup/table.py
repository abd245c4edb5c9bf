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
simulation (:func:`vimpact.tablebuild.verify.interpolation_error`), is stored as
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
from vimpact.kernels.status import INVALID
from vimpact.kernels.status import TABLE as STATUS_TABLE
from vimpact.lookup.interpolate import LOG_AXES, cluster_nodes, same_node
from vimpact.model.scene import DEFAULT_THETA_RATIO, HALF_SPACE_LIMIT, Scene
from vimpact.model.validation import InputError, positive, require
from vimpact.tableformat.metadata import COMMON_METADATA, META_PREFIX, decode_value, encode_value

__all__ = ["AXES", "DATA_STATUSES", "LOG_AXES", "LOOKUP_METHODS", "LOOKUP_MODELS",
           "MAX_CURVE_POINTS", "OUTPUTS", "SPEC_HINTS", "RestitutionTable", "format_info",
           "incidence", "validate_table"]

#: Interpolation methods of :meth:`RestitutionTable.lookup`.
LOOKUP_METHODS = ("cubic", "linear")

#: Statuses whose rows are data (all others are failures and are skipped).
DATA_STATUSES = tuple(s.name for s in STATUS_TABLE if s.has_data)

#: Models whose tables :meth:`RestitutionTable.lookup` can interpolate.
LOOKUP_MODELS = ("kelvin_voigt", "standard_solid")

#: Which sweep spec produces a grid table for lookup, by model.
SPEC_HINTS = {
    "kelvin_voigt": "sweeps/kelvin_voigt_table.toml",
    "standard_solid": "sweeps/standard_solid_table.toml",
}

#: Outputs interpolated by :meth:`RestitutionTable.lookup` (all dimensionless).
OUTPUTS = ("e_z", "e_x", "beta_x")

#: Interpolation axes of a lookup, in grid order: ``theta_ratio`` when the table holds
#: several values, ``psi`` when it has a ``psi`` column (friction incidence).
AXES = ("Q1", "Q2", "nu", "theta_ratio", "psi")


#: The most points of an e(v) curve (:meth:`RestitutionTable.restitution_curve`,
#: ``vimpact table export --n``).
MAX_CURVE_POINTS = 100_000

#: Largest allowed excess of ``e_z``, ``e_x``, ``|beta_x|`` over 1 in a data row
#: (round-off of an elastic impact).
BOUND_SLACK = 1e-6

_REQUIRED = ("Q1", "nu", "e_z", "e_x", "beta_x", "status")


def _axis_is_log(name: str) -> bool:
    return name in LOG_AXES


def _fmt(x: float) -> str:
    return f"{x:.6g}"


# --------------------------------------------------------------------------
# grid helpers
# --------------------------------------------------------------------------


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
        """Return the cell index ``i0``, ``i1`` and weight ``t`` of ``x`` on axis ``k``.

        ``value = (1 - t) f[i0] + t f[i1]``.
        """
        name, nodes = self.axes[k], self.nodes[k]
        lo, hi = nodes[0], nodes[-1]
        inside = ((x >= lo) | same_node(x, lo)) & ((x <= hi) | same_node(x, hi))
        if not extrapolate and not np.all(inside):
            bad = float(x[~inside].flat[0])
            covered = (f"{name} = {_fmt(lo)} only (a single grid value)" if len(nodes) == 1
                       else f"{name} in [{_fmt(lo)}, {_fmt(hi)}]")
            raise InputError(
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
                raise InputError(
                    f"{name} = {bad:.6g} cannot be extrapolated on the table's log {name} axis: "
                    f"it covers {name} in [{_fmt(lo)}, {_fmt(hi)}]; give {name} > 0")
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


def incidence(angle_deg, mu, nu):
    """Maw, Barber and Fawcett's incidence ``psi`` of a non-spinning sphere.

    ``psi = 2 (1 - nu) / (mu (2 - nu)) * v_c0 / v_z0`` with ``v_c0 / v_z0 = tan(angle)``
    (no initial spin: the contact point moves with the centre).

    Parameters
    ----------
    angle_deg : impact angle from the surface normal, degrees, in [0, 90)
    mu : Coulomb friction coefficient, > 0 (``inf``: full stick, ``psi = 0``)
    nu : Poisson ratio, in [0, 0.5]

    Returns
    -------
    float or ndarray, dimensionless
    """
    angle = np.asarray(angle_deg, dtype=float)
    if not np.all(np.isfinite(angle) & (angle >= 0.0) & (angle < 90.0)):
        bad = angle[~(np.isfinite(angle) & (angle >= 0.0) & (angle < 90.0))].flat[0]
        raise InputError(f"angle_deg = {float(bad)!r} is not allowed: the impact angle from the "
                         "normal must be in [0, 90) degrees")
    mu = float(mu)
    if not (mu > 0.0):  # NaN too
        raise InputError(f"mu = {mu!r} is not allowed: the friction coefficient must be > 0 "
                         "(inf for full stick)")
    nu = np.asarray(nu, dtype=float)
    if not np.all((nu >= 0.0) & (nu <= 0.5)):
        raise InputError(f"nu = {float(nu[~((nu >= 0) & (nu <= 0.5))].flat[0])!r} is not "
                         "allowed: must be in [0, 0.5]")
    from vimpact.tableformat.parameters import incidence as psi_of  # the one psi rule

    ratio = np.tan(np.radians(angle))
    psi = psi_of(mu, nu, ratio, np.ones_like(ratio))
    return float(psi) if np.ndim(psi) == 0 else psi


def _rows_text(rows: np.ndarray, limit: int = 3) -> str:
    rows = [int(r) for r in rows[:limit]]
    return ("row " if len(rows) == 1 else "rows ") + ", ".join(str(r) for r in rows)


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
    data : the rows, Kelvin-Voigt rows already as ``Q2 = NaN`` (:class:`RestitutionTable`)
    metadata : ``vimpact.*`` key -> text
    path : the file, for the messages
    """
    where = f"table = {str(path)!r}" if path is not None else "the table"
    if META_PREFIX + "model" not in metadata:
        raise InputError(f"{where} is not allowed: it has no vimpact metadata (no key "
                         "vimpact.model): not a restitution table written by `vimpact sweep`")
    status = data["status"].astype(str).to_numpy()
    unknown = ~np.isin(status, list(STATUSES))
    if unknown.any():
        i = np.flatnonzero(unknown)
        raise InputError(f"{where} is not allowed: column status = {status[i[0]]!r} at "
                         f"{_rows_text(i)} is not a vimpact status (known: "
                         + ", ".join(STATUSES) + ")")
    ok = np.isin(status, DATA_STATUSES)
    ran = status != INVALID  # every other row is an impact at its inputs
    bounds = {"e_z": (0.0, 1.0 + BOUND_SLACK, "in [0, 1 + 1e-6]"),
              "e_x": (0.0, 1.0 + BOUND_SLACK, "in [0, 1 + 1e-6]"),
              "beta_x": (-1.0 - BOUND_SLACK, 1.0 + BOUND_SLACK, "|beta_x| <= 1 + 1e-6")}
    for name, (lo, hi, allowed) in bounds.items():
        v = pd.to_numeric(data[name], errors="coerce").to_numpy(float)
        bad = ok & ~np.isfinite(v)
        if bad.any():
            i = np.flatnonzero(bad)
            raise InputError(f"{where} is not allowed: column {name} = {_fmt(v[i[0]])} at "
                             f"{_rows_text(i)} with status ok (a data row needs a finite "
                             f"{name})")
        bad = ok & ((v < lo) | (v > hi))
        if bad.any():
            i = np.flatnonzero(bad)
            raise InputError(f"{where} is not allowed: column {name} = {_fmt(v[i[0]])} at "
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
            raise InputError(f"{where} is not allowed: column {name} = {_fmt(v[i[0]])} at "
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
            raise InputError(f"the table{self._where(path)} lacks the column(s) "
                             f"{', '.join(missing)}: a restitution table has "
                             f"{', '.join(_REQUIRED)} (and Q2 for a standard solid)")
        self.data = data.reset_index(drop=True)
        self.path = None if path is None else Path(path)
        self.metadata: dict[str, str] = {}
        for key, value in (metadata or {}).items():
            key = key.decode() if isinstance(key, bytes) else str(key)
            if not key.startswith(META_PREFIX):
                key = META_PREFIX + key
            if isinstance(value, bytes):
                value = value.decode()
            elif not isinstance(value, str):  # stored as the writer stores it
                value = encode_value(key[len(META_PREFIX):], value)
            self.metadata[key] = value
        if self.model == "standard_solid" and "Q2" not in self.data.columns:
            raise InputError(f"the standard_solid table{self._where(path)} lacks the column Q2")
        self.data = _kelvin_voigt_rows(self.data, self.model)
        self._grids: dict = {}
        self._hermite: dict = {}
        self._adaptive = None

    @staticmethod
    def _where(path) -> str:
        return f" {str(path)!r}" if path is not None else ""

    # ---- reading and writing -------------------------------------------
    @classmethod
    def open(cls, path, validate: bool = True) -> RestitutionTable:
        """Read a restitution table and its ``vimpact.*`` metadata.

        The table is one Parquet file, or a partitioned dataset written by a large
        sweep (a directory of part files plus ``_common_metadata``, which holds the
        metadata).

        The table is checked before use: the file's integrity (page checksums and the
        content hash, :func:`vimpact.tableformat.integrity.verify_table`, where available), then
        its rows (:func:`validate_table`: vimpact metadata, known statuses, finite
        outputs within their physical bounds in data rows, axes in their domains, no
        duplicated node). ``validate=False`` skips both (to inspect a damaged file).

        Raises
        ------
        InputError
            naming the file, the column and the offending value and row
        """
        import pyarrow.parquet as pq

        from vimpact.tableformat.integrity import verify_table

        p = Path(path)
        if p.is_dir():
            if not (p / COMMON_METADATA).is_file():
                raise InputError(
                    f"table = {str(path)!r} is not allowed: a directory without "
                    f"{COMMON_METADATA} (an unfinished sweep dataset: finish it with "
                    "`vimpact sweep SPEC --resume`, or --combine after shards)")
        elif not p.is_file():
            raise InputError(f"table = {str(path)!r} is not allowed: no such file "
                             "(a Parquet restitution table written by `vimpact sweep`)")
        if validate:
            verify_table(p)
        try:
            arrow = pq.read_table(p)
            raw = (pq.read_schema(p / COMMON_METADATA) if p.is_dir() else arrow.schema).metadata
        except Exception as exc:  # pyarrow raises several types for a bad file
            why = (str(exc).splitlines() or [""])[0]
            raise InputError(f"table = {str(path)!r} is not allowed: not a readable Parquet "
                             f"file ({type(exc).__name__}: {why})") from None
        meta = {k.decode(): v.decode() for k, v in (raw or {}).items()
                if k.decode().startswith(META_PREFIX)}
        if p.is_dir():  # the parts' schemas carry per-chunk bookkeeping
            arrow = arrow.replace_schema_metadata(None)
        if validate and META_PREFIX + "model" not in meta:
            validate_table(arrow.slice(0, 0).to_pandas(), meta, p)  # foreign: before the columns
        table = cls(arrow.to_pandas(), meta, path=p)
        if validate:
            table.validate()
        return table

    def validate(self) -> RestitutionTable:
        """Check the rows and metadata (:func:`validate_table`); return the table.

        Raises
        ------
        InputError
            naming the file, the column and the offending value and row
        """
        validate_table(self.data, self.metadata, self.path)
        return self

    def save(self, path) -> Path:
        """Write the table as Parquet with its ``vimpact.*`` metadata (what :meth:`open` reads)."""
        import pyarrow as pa

        from vimpact.tableformat.files import write_atomic

        arrow = pa.Table.from_pandas(self.data, preserve_index=False)
        meta = dict(arrow.schema.metadata or {})
        meta[(META_PREFIX + "model").encode()] = self.model.encode()  # what open() requires
        meta.update({k.encode(): v.encode() for k, v in self.metadata.items()})
        # atomically, with page checksums and fresh content/metadata hashes (the stored
        # ones describe the file this table was read from, not these columns)
        write_atomic(arrow.replace_schema_metadata(meta), Path(path))
        return Path(path)

    # ---- metadata --------------------------------------------------------
    def meta(self, key: str, default=None):
        """Return the metadata value ``vimpact.<key>``, decoded.

        Decoded by the table format's metadata codec
        (:func:`vimpact.tableformat.metadata.decode_value`: JSON keys such as
        ``units``, ``numerics``, ``paths`` parsed, integer keys such as ``rows`` as
        ints).
        """
        value = self.metadata.get(META_PREFIX + key)
        if value is None:
            return default
        return decode_value(key, value)

    @property
    def model(self) -> str:
        """Rheology of the table (``vimpact.model``; inferred from ``Q2`` if missing)."""
        model = self.metadata.get(META_PREFIX + "model")
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
        """Vimpact version that wrote the table."""
        return self.meta("version")

    # ---- rows ------------------------------------------------------------
    @property
    def ok(self) -> pd.DataFrame:
        """The data rows (status in :data:`DATA_STATUSES`)."""
        return self.data[self.data["status"].isin(DATA_STATUSES)]

    def __len__(self) -> int:
        return len(self.data)

    def info(self) -> dict:
        """Return a summary of the table.

        Model, rows, ok rows, status counts, covered ranges, grid, numerics, version
        (JSON-serializable; ``str(table)`` is the readable form).
        """
        ok = self.ok
        params = ["Q1"] + (["Q2"] if self.model == "standard_solid" else []) + ["nu"]
        params += [c for c in ("theta_ratio", "psi", "mu") if c in self.data.columns]
        ranges = {}
        for p in params:
            v = ok[p].to_numpy(float) if p in ok.columns else np.array([])
            v = v[~np.isnan(v)] if p == "mu" else v[np.isfinite(v)]  # mu = inf: full stick
            ranges[p] = [float(v.min()), float(v.max())] if len(v) else None
        adaptive = None
        if self.is_adaptive:
            grid_info, failed, note = None, None, "adaptive cells (see adaptive)"
            try:
                adaptive = self.adaptive_grid().info()
                adaptive["failed_nodes"] = int(len(self.data) - len(ok))
            except ValueError as exc:
                note = str(exc)
            build = self.meta("build")
            if isinstance(build, dict):
                adaptive["build"] = build
        else:
            try:
                grid = self._lookup_grid()
                grid_info, failed, note = grid.shape, grid.failed, None
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
            "adaptive": adaptive,
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

    # ---- adaptive tables --------------------------------------------------
    @property
    def is_adaptive(self) -> bool:
        """Whether the table is adaptive, not a grid.

        ``vimpact.mode = adaptive``: cells refined locally, its structure in
        ``vimpact.adaptive`` (:mod:`vimpact.lookup.adaptive`).
        """
        return self.meta("mode") == "adaptive"

    def adaptive_grid(self):
        """Return the :class:`vimpact.lookup.adaptive.AdaptiveGrid` of an adaptive table.

        It is built once from its node rows and ``vimpact.adaptive``.
        """
        if self._adaptive is None:
            from vimpact.lookup.adaptive import AdaptiveGrid

            if not self.is_adaptive:
                raise InputError(f"the table{self._where(self.path)} is not adaptive "
                                 "(vimpact.mode is not 'adaptive')")
            self._adaptive = AdaptiveGrid.from_rows(self.meta("adaptive"), self.data)
        return self._adaptive

    # ---- lookup ----------------------------------------------------------
    def _theta_values(self) -> np.ndarray:
        v = self.data["theta_ratio"].to_numpy(float)
        # distinct values first: clustering is a Python loop over its values, and a
        # table's rows (489360 in the adaptive standard-solid table) repeat a few values
        return cluster_nodes(np.unique(v[np.isfinite(v)]))[0] if np.isfinite(v).any() \
            else np.array([])

    def _resolve_theta(self, theta_ratio) -> float | None:
        """Return the theta_ratio slice to use (None: the table has one value / no column)."""
        if "theta_ratio" not in self.data.columns:
            if theta_ratio is not None and not same_node(theta_ratio, DEFAULT_THETA_RATIO):
                raise InputError(
                    f"theta_ratio = {theta_ratio!r} is not allowed: the table has no theta_ratio "
                    f"column, so it is for Theta / (m R^2) = {DEFAULT_THETA_RATIO} (a solid sphere)")
            return None
        values = self._theta_values()
        if theta_ratio is None:
            if len(values) > 1:
                raise InputError(
                    "theta_ratio is missing: the table holds several Theta / (m R^2) = "
                    + ", ".join(_fmt(v) for v in values) + "; give one of them")
            return None
        match = values[same_node(values, theta_ratio)]
        if not len(match):
            raise InputError(
                f"theta_ratio = {theta_ratio!r} is not allowed: the table holds Theta / (m R^2) = "
                + ", ".join(_fmt(v) for v in values) + " only (a table with several values "
                "interpolates between them)")
        return None if len(values) == 1 else float(match[0])

    def _psi_values(self) -> np.ndarray:
        """Return the distinct friction incidences ``psi`` of the table (empty: no psi column)."""
        if "psi" not in self.data.columns:
            return np.array([])
        v = self.data["psi"].to_numpy(float)
        return cluster_nodes(np.unique(v[np.isfinite(v)]))[0] if np.isfinite(v).any() \
            else np.array([])

    def _base_axes(self) -> list[str]:
        model = self.model
        if model not in LOOKUP_MODELS:
            raise InputError(f"lookup needs a kelvin_voigt or standard_solid table, "
                             f"this one is {model!r}")
        return ["Q1", "Q2", "nu"] if model == "standard_solid" else ["Q1", "nu"]

    def _grid(self, theta: float | None) -> _Grid:
        """Return the grid at one ``theta_ratio`` (None: the table's only one).

        Axes ``Q1``, (``Q2``), ``nu`` and ``psi`` if the table has a psi column.
        """
        if theta in self._grids:
            return self._grids[theta]
        axes = self._base_axes() + (["psi"] if len(self._psi_values()) else [])
        rows = self.data
        if theta is not None:
            rows = rows[same_node(rows["theta_ratio"].to_numpy(float), theta)]
        grid = self._build_grid(axes, rows)
        self._grids[theta] = grid
        return grid

    def _lookup_grid(self) -> _Grid:
        """Return the grid over every lookup axis.

        ``Q1``, (``Q2``), ``nu``, ``theta_ratio`` (when the table holds several
        values), ``psi`` (when it has a psi column).
        """
        key = "all axes"
        if key in self._grids:
            return self._grids[key]
        thetas = self._theta_values() if "theta_ratio" in self.data.columns else np.array([])
        axes = (self._base_axes() + (["theta_ratio"] if len(thetas) > 1 else [])
                + (["psi"] if len(self._psi_values()) else []))
        grid = self._build_grid(axes, self.data)
        self._grids[key] = grid
        return grid

    def _build_grid(self, axes: list[str], rows: pd.DataFrame) -> _Grid:
        model = self.model
        hint = SPEC_HINTS.get(model, "a grid sweep spec")
        if self.meta("mode") == "random":  # the sweep records how the rows were made
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
                where = ", ".join(f"{a} = {_fmt(n[i])}" for a, n, i in
                                  zip(axes, nodes, np.unravel_index(k, shape)))
                raise InputError(f"lookup needs one result per grid point, but the table has "
                                 f"{count[k]} rows with different {name} at {where}")
            with np.errstate(invalid="ignore", divide="ignore"):
                values[name] = np.where(count > 0, total / np.maximum(count, 1), np.nan).reshape(shape)
        failed = int(np.sum(count == 0))
        return _Grid(axes, list(nodes), values, failed)

    def _hermite_grid(self, theta: float | None, grid: _Grid | None = None):
        """Return the cubic interpolant of the grid for ``theta``.

        Or of ``grid``, cached under ``theta``; slopes computed once.
        """
        if theta not in self._hermite:
            from vimpact.lookup.interpolate import HermiteGrid

            grid = self._grid(theta) if grid is None else grid
            self._hermite[theta] = HermiteGrid(grid.axes, grid.nodes, grid.values,
                                               log_axes=LOG_AXES)
        return self._hermite[theta]

    @property
    def interpolation_error(self) -> dict | None:
        """The measured interpolation error, or None if not measured.

        Metadata ``vimpact.interpolation_error``, written by
        :func:`vimpact.tablebuild.verify.interpolation_error` / ``vimpact table verify
        --write``.
        """
        value = self.meta("interpolation_error")
        return value if isinstance(value, dict) else None

    def error_bound(self, method: str = "cubic") -> dict | None:
        """Return the error bound measured between the nodes for ``method``, per output.

        ``{"e_z": ..., "beta_x": ..., "e_x": ...}`` (the stored ``bound``, 1.5 times
        the largest error found at the held-out points, see
        :data:`vimpact.tablebuild.verify.BOUND_FACTOR`), or None if not measured.
        """
        err = self.interpolation_error
        if not err or err.get("method", "cubic") != method:
            return None
        out = {}
        for k, v in err.get("outputs", {}).items():
            value = v.get("bound", v.get("max")) if isinstance(v, dict) else None
            out[k] = None if value is None else float(value)
        return out

    def lookup(self, Q1, nu, Q2=None, extrapolate: bool = False, theta_ratio=None,
               method: str = "cubic", psi=None) -> dict:
        """Interpolate ``e_z``, ``e_x``, ``beta_x`` at ``Q1``, ``nu`` (``Q2``, ``theta_ratio``, ``psi``).

        ``method="cubic"`` (default): tensor-product cubic Hermite in ``log Q1``,
        ``log Q2``, ``nu``, ``log theta_ratio`` and ``psi`` (the axes the table has),
        shape-preserving where the data is monotone (:mod:`vimpact.lookup.interpolate`,
        evaluated by the numba kernel :func:`vimpact.kernels.hermite.hermite_eval`);
        ``"linear"``: multilinear on the same scales. At a grid point either returns
        that row's values. ``e_x`` is ``|beta_x|`` of the interpolated ``beta_x``
        (exact at grid points and right where ``beta_x`` changes sign between them).
        Slopes are computed once per table; 1e6 points take a fraction of a second of
        one core (``python -m benchmarks.lookup`` measures it).

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
            (cubic: with the end node's slope; results clipped to the physical bounds
            ``0 <= e_z, e_x <= 1``, ``|beta_x| <= 1``) instead of raising
        theta_ratio : float or array_like, optional
            ``Theta / (m R^2)``, dimensionless, > 0: needed when the table holds several
            values, and then interpolated (cubic in ``log theta_ratio``, see
            :data:`LOG_AXES`); with one value (or no column: 0.4) only that value
        method : ``"cubic"`` (default) or ``"linear"``
        psi : float or array_like, optional
            friction incidence ``2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0``, dimensionless,
            >= 0 (:func:`incidence`): an axis of a table with a ``psi`` column (needed
            when it holds several values), interpolated linearly in ``psi``; not allowed
            for a table without one (full stick)

        Returns
        -------
        dict
            ``Q1``, (``Q2``), ``nu``, (``theta_ratio``, ``psi`` when they are axes)
            (broadcast inputs) and ``e_z``, ``e_x``, ``beta_x`` (dimensionless): floats
            for scalar inputs, arrays of the broadcast shape otherwise. NaN where the
            interpolation needs a grid point whose impact failed. ``error_bound``:
            output -> the largest interpolation error measured between the nodes for
            this method (:attr:`interpolation_error`), None if the table was not
            verified; it holds inside the covered range, not for extrapolated values.

        Raises
        ------
        InputError
            outside the covered range (naming the parameter, value and range),
            for a table that is not a grid, or for ``Q2`` given to a
            Kelvin-Voigt table / missing for a standard-solid one, ``psi`` given to a
            table without a psi axis / missing for one with several.
        """
        model = self.model
        if method not in LOOKUP_METHODS:
            raise InputError(f"method = {method!r} is not allowed: must be one of "
                             + ", ".join(LOOKUP_METHODS))
        if model == "kelvin_voigt" and Q2 is not None:
            raise InputError(f"Q2 = {Q2!r} is not allowed: this is a kelvin_voigt table "
                             "(e_z, e_x depend on Q1 and nu only); omit Q2 or use a "
                             "standard_solid table")
        if model == "standard_solid" and Q2 is None:
            raise InputError("Q2 is missing: this is a standard_solid table, lookup needs "
                             "Q2 = G1/G2 as well as Q1 and nu")
        psis = self._psi_values()
        if psi is not None and not len(psis):
            raise InputError(f"psi = {psi!r} is not allowed: the table has no psi column (it is "
                             "for full stick, mu = inf); omit psi or use a table swept over psi")
        if psi is None and len(psis) > 1:
            raise InputError("psi is missing: the table holds several friction incidences psi = "
                             + _fmt(psis[0]) + " .. " + _fmt(psis[-1]) + "; give psi (>= 0, "
                             "2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0)")
        thetas = self._theta_values() if "theta_ratio" in self.data.columns else np.array([])
        theta_axis = len(thetas) > 1
        if not theta_axis:  # one value: only it (raises otherwise)
            for t in ([None] if theta_ratio is None else
                      np.unique(np.asarray(theta_ratio, dtype=float).ravel())):
                self._resolve_theta(None if t is None else float(t))
        elif theta_ratio is None:
            self._resolve_theta(None)  # raises: several values, give one
        named = {"Q1": Q1, "nu": nu} if Q2 is None else {"Q1": Q1, "Q2": Q2, "nu": nu}
        if theta_axis:
            named["theta_ratio"] = theta_ratio
        if len(psis):
            named["psi"] = psis[0] if psi is None else psi
        arrays = {}
        for name, value in named.items():
            try:
                arr = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                raise InputError(f"{name} = {value!r} is not allowed: must be a number or "
                                 "an array of numbers") from None
            if not np.all(np.isfinite(arr)):
                bad = float(arr[~np.isfinite(arr)].flat[0])
                raise InputError(f"{name} = {bad!r} is not allowed: must be finite")
            if name in ("psi", "theta_ratio") and np.any(arr < 0.0 if name == "psi" else arr <= 0.0):
                bad = float(arr[arr < 0.0 if name == "psi" else arr <= 0.0].flat[0])
                raise InputError(f"{name} = {bad!r} is not allowed: must be "
                                 + (">= 0" if name == "psi" else "> 0"))
            arrays[name] = arr
        try:
            bcast = np.broadcast_arrays(*arrays.values())
        except ValueError:
            raise InputError(", ".join(arrays) + " have shapes "
                             + ", ".join(str(a.shape) for a in arrays.values())
                             + " that do not broadcast together") from None
        arrays = dict(zip(arrays, bcast))
        if self.is_adaptive:
            if method != "cubic" or extrapolate:
                raise InputError(f"method = {method!r}, extrapolate = {extrapolate!r} are not "
                                 "allowed for an adaptive table: its lookup is cubic inside "
                                 "its range")
            grid_a = self.adaptive_grid()
            out = grid_a({a: arrays[a] for a in grid_a.axes
                          + ([grid_a.tensor_axis] if grid_a.tensor_axis else [])})
            out["e_x"] = np.abs(out["beta_x"])
            return self._result(arrays, out, bcast, method)
        # one theta_ratio node: the slice at it (a table need not be a grid across thetas)
        theta = None
        if theta_axis and np.ndim(theta_ratio) == 0 and same_node(thetas, theta_ratio).any():
            theta = float(thetas[same_node(thetas, theta_ratio)][0])
        if theta_axis and theta is None:
            grid, key = self._lookup_grid(), "all axes"
        else:
            grid, key = self._grid(theta), theta
        if method == "cubic":
            out = self._hermite_grid(key, grid)([arrays[a] for a in grid.axes], extrapolate)
        else:
            out = grid.interpolate([arrays[a] for a in grid.axes], extrapolate)
        if extrapolate:
            out["e_z"] = np.clip(out["e_z"], 0.0, 1.0)
            out["beta_x"] = np.clip(out["beta_x"], -1.0, 1.0)
        # |beta_x| where beta_x is known; the interpolated e_x where only it is
        out["e_x"] = np.where(np.isfinite(out["beta_x"]), np.abs(out["beta_x"]), out["e_x"])
        if extrapolate:
            out["e_x"] = np.clip(out["e_x"], 0.0, 1.0)
        return self._result(arrays, out, bcast, method)

    def _result(self, arrays: dict, out: dict, bcast: list, method: str) -> dict:
        """Return the inputs and the outputs of a lookup, floats for scalar inputs.

        With the table's ``error_bound`` for ``method``.
        """
        result = {**arrays, **{k: out[k] for k in OUTPUTS}}
        if all(a.ndim == 0 for a in bcast):
            result = {k: float(v) for k, v in result.items()}
        else:
            result = {k: np.asarray(v, dtype=float) for k, v in result.items()}
        result["error_bound"] = self.error_bound(method)
        return result

    def to_xarray(self, theta_ratio=None):
        """Return the grid as an :class:`xarray.Dataset`.

        Data variables ``e_z``, ``e_x``, ``beta_x`` (dimensionless) over the labelled
        axes ``Q1``, (``Q2``), ``nu``, (``theta_ratio`` when the table holds several,
        ``psi`` when it has a psi column); ``theta_ratio`` (one of the table's values) selects that slice.

        Units and descriptions are attributes of each variable and axis; the
        dataset's attributes hold the model, numerics, interpolation error and
        version (JSON text where structured). xarray is optional: it is imported
        here, and its absence is an :class:`~vimpact.model.validation.InputError`.
        """
        try:
            import xarray as xr
        except ImportError:
            raise InputError("to_xarray = xarray is not allowed here: xarray is not installed "
                             "(pip install xarray); RestitutionTable.data is the same table "
                             "as a pandas DataFrame") from None
        if self.is_adaptive:
            raise InputError(f"to_xarray is not allowed for the adaptive table"
                             f"{self._where(self.path)}: its nodes are cells of different "
                             "sizes, not a grid; evaluate lookup() on the grid you need")
        theta = self._resolve_theta(theta_ratio)
        grid = self._lookup_grid() if theta is None else self._grid(theta)
        units = self.units
        described = {"Q1": "damping parameter sqrt(15/32) (eta/G_inf)/T",
                     "Q2": "G1/G2 of the standard solid", "nu": "Poisson ratio",
                     "theta_ratio": "moment of inertia ratio Theta / (m R^2)",
                     "psi": "friction incidence 2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0",
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
        if "mu" in self.data.columns:  # psi tables: the mu the rows were simulated with
            attrs["mu"] = json.dumps(sorted({float(x) for x in self.data["mu"].dropna()}))
        return xr.Dataset(data_vars, coords=coords, attrs=attrs)

    # ---- physical curves -------------------------------------------------
    def restitution_curve(self, material, R: float, m: float, v_z0, theta_ratio=None,
                          extrapolate: bool = False, allow_large_contact: bool = False,
                          angle_deg: float | None = None,
                          mu: float | None = None) -> pd.DataFrame:
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
        angle_deg : impact angle from the normal, degrees, in [0, 90): with ``mu``,
            required for a table with a ``psi`` axis (friction), which it looks up at
            ``psi = 2 (1 - nu) / (mu (2 - nu)) tan(angle)`` (:func:`incidence`, no
            initial spin); the same at every speed
        mu : Coulomb friction coefficient, > 0 (``inf``: full stick, ``psi = 0``); only for
            a table with a ``psi`` axis (a table without one is for full stick)

        Returns
        -------
        DataFrame with columns ``v_z0_m_s``, ``Q1``, (``Q2``), (``psi``), ``e_z``,
        ``e_x``, ``beta_x`` (at most :data:`MAX_CURVE_POINTS` speeds); ``attrs`` holds
        the units and the inputs.
        """
        from vimpact.model.material import Material

        require("material", material, isinstance(material, Material), "a vimpact.Material")
        if material.model != self.model:
            raise InputError(f"material model {material.model!r} does not match the table's "
                             f"model {self.model!r}")
        R, m = positive("R", R), positive("m", m)
        speeds = np.atleast_1d(np.asarray(v_z0, dtype=float)).ravel()
        require("v_z0", v_z0, speeds.size > 0, "at least one speed (m/s)")
        if speeds.size > MAX_CURVE_POINTS:
            raise InputError(f"v_z0 = {speeds.size} speeds is not allowed: at most "
                             f"{MAX_CURVE_POINTS} points per curve")
        psi = None
        if len(self._psi_values()):
            if angle_deg is None or mu is None:
                missing = " and ".join(n for n, x in (("angle_deg", angle_deg), ("mu", mu))
                                       if x is None)
                raise InputError(f"{missing} missing: the table has a friction incidence axis "
                                 "psi, so the curve needs the impact angle from the normal "
                                 "(degrees) and the friction coefficient mu")
            psi = incidence(angle_deg, mu, material.nu)
        else:
            if mu is not None and not math.isinf(float(mu)):
                raise InputError(f"mu = {mu!r} is not allowed: the table has no psi column (it "
                                 "is for full stick, mu = inf); use a table swept over psi")
            if angle_deg is not None:
                incidence(angle_deg, math.inf, material.nu)  # range check only: under full
                # stick beta_x does not depend on the angle
        scenes = [Scene(material, R=R, m=m, v_z0=float(v), allow_large_contact=True) for v in speeds]
        if not allow_large_contact:
            big = [s for s in scenes if s.hertz.a_H > HALF_SPACE_LIMIT * R]
            if big:
                s = big[0]
                raise InputError(
                    f"v_z0 = {s.v_z0:.6g} m/s is not allowed: its Hertz contact radius "
                    f"{s.hertz.a_H:.4g} m exceeds 0.2 R = {HALF_SPACE_LIMIT * R:.4g} m (outside "
                    "the half-space model; allow_large_contact=True / --allow-large-contact "
                    "accepts it)")
        q1 = np.array([s.Q1 for s in scenes])
        q2 = np.array([s.Q2 for s in scenes]) if self.model == "standard_solid" else None
        res = self.lookup(q1, material.nu, q2, extrapolate=extrapolate, theta_ratio=theta_ratio,
                          psi=None if psi is None else np.full(len(q1), psi))
        columns = {"v_z0_m_s": speeds, "Q1": q1}
        if q2 is not None:
            columns["Q2"] = q2
        if psi is not None:
            columns["psi"] = np.full(len(q1), psi)
        columns.update({k: res[k] for k in OUTPUTS})
        df = pd.DataFrame(columns)
        df.attrs.update({
            "units": {"v_z0_m_s": "m/s", **{k: "1" for k in columns if k != "v_z0_m_s"}},
            "model": material.model, "nu": material.nu, "R_m": R, "m_kg": m,
            "angle_deg": None if angle_deg is None else float(angle_deg),
            "mu": None if mu is None else float(mu),
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
        from vimpact.tableformat.files import atomic_file, refuse_symlink
        refuse_symlink(p, "out")  # before the work
        df = self.restitution_curve(material, R, m, v_z0, **options)
        with atomic_file(p, "out", mode="w") as f:  # never through a symbolic link
            df.to_csv(f, index=False, float_format="%.10g")
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
        one = r is not None and (r[0] == r[1] or (np.isfinite(r[1]) and same_node(r[0], r[1])))
        text = "no data" if r is None else (_fmt(r[0]) if one else f"{_fmt(r[0])} .. {_fmt(r[1])}")
        lines.append(f"  {name:<15} {text}")
    ad = info.get("adaptive")
    if ad:
        tensor = f" x {ad['tensor_nodes']} {ad['tensor_axis']}" if ad["tensor_axis"] else ""
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
