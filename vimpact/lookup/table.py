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

:class:`RestitutionTable` reads, writes and describes the table; each further job
has its module in :mod:`vimpact.lookup`: :mod:`~vimpact.lookup.columns` (required
columns, data statuses, outputs, Kelvin-Voigt rows), :mod:`~vimpact.lookup.validation`
(refusing a table that cannot be trusted), :mod:`~vimpact.lookup.query` (the lookup's
inputs checked and its result put together, the friction incidence),
:mod:`~vimpact.lookup.grid` (tensor-grid lookup), :mod:`~vimpact.lookup.adaptive_table`
(adaptive-table lookup), :mod:`~vimpact.lookup.bounds` (the error bound returned),
:mod:`~vimpact.lookup.curve` (e(v) curves), :mod:`~vimpact.lookup.dataset` (xarray) and
:mod:`~vimpact.lookup.info` (summary and its text).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from vimpact.lookup import adaptive_table, bounds, curve, dataset, query
from vimpact.lookup.columns import (
    AXES,
    DATA_STATUSES,
    LOOKUP_METHODS,
    LOOKUP_MODELS,
    OUTPUTS,
    REQUIRED_COLUMNS,
    SPEC_HINTS,
    kelvin_voigt_rows,
    where,
)
from vimpact.lookup.curve import MAX_CURVE_POINTS
from vimpact.lookup.grid import TableGrid, TensorLookup
from vimpact.lookup.info import format_info, table_info
from vimpact.lookup.interpolate import LOG_AXES
from vimpact.lookup.query import incidence
from vimpact.lookup.validation import BOUND_SLACK, validate_table
from vimpact.model.validation import InputError, require
from vimpact.tableformat.metadata import COMMON_METADATA, META_PREFIX, decode_value, encode_value

if TYPE_CHECKING:
    from vimpact.lookup.adaptive import AdaptiveGrid
    from vimpact.lookup.interpolate import HermiteGrid

# the reader's public names, each defined in its module of vimpact.lookup, importable
# from here as well as from vimpact.lookup
__all__ = ["AXES", "BOUND_SLACK", "DATA_STATUSES", "LOG_AXES", "LOOKUP_METHODS",
           "LOOKUP_MODELS", "MAX_CURVE_POINTS", "OUTPUTS", "SPEC_HINTS", "RestitutionTable",
           "format_info", "incidence", "validate_table"]


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
        missing = [c for c in REQUIRED_COLUMNS if c not in data.columns]
        if missing:
            raise InputError(f"the table{where(path)} lacks the column(s) "
                             f"{', '.join(missing)}: a restitution table has "
                             f"{', '.join(REQUIRED_COLUMNS)} (and Q2 for a standard solid)")
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
            raise InputError(f"the standard_solid table{where(path)} lacks the column Q2")
        self.data = kelvin_voigt_rows(self.data, self.model)
        self._tensor = TensorLookup(self)
        self._adaptive: AdaptiveGrid | None = None

    @staticmethod
    def _where(path) -> str:
        return where(path)

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
        A file is read once for both; a file this process verified before and unchanged
        since is read with its page checksums and metadata hash checked but its content
        hash not recomputed (``verify_table(..., once=True)``).

        Raises
        ------
        InputError
            naming the file, the column and the offending value and row
        """
        import pyarrow as pa
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
        groups: list = []  # a file's row groups, read (and checked) once
        if validate:
            verify_table(p, keep=None if p.is_dir() else groups, once=True)
        try:
            arrow = pa.concat_tables(groups) if groups else pq.read_table(p)
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
        from vimpact.tableformat.files import write_frame

        # the model first, as open() requires it; the table's own entries may repeat it
        return write_frame(self.data, {META_PREFIX + "model": self.model, **self.metadata},
                           Path(path))

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
        (JSON-serializable; ``str(table)`` is the readable form,
        :func:`~vimpact.lookup.info.format_info`).
        """
        return table_info(self)

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

    def adaptive_grid(self) -> AdaptiveGrid:
        """Return the :class:`vimpact.lookup.adaptive.AdaptiveGrid` of an adaptive table.

        It is built once from its node rows and ``vimpact.adaptive``
        (:func:`vimpact.lookup.adaptive_table.build_adaptive_grid`).
        """
        if self._adaptive is None:
            self._adaptive = adaptive_table.build_adaptive_grid(self)
        return self._adaptive

    # ---- grid tables -----------------------------------------------------
    @property
    def tensor(self) -> TensorLookup:
        """The lookup of a grid table: its grids and cubic interpolants, built once.

        :class:`vimpact.lookup.grid.TensorLookup`.
        """
        return self._tensor

    def _theta_values(self) -> np.ndarray:
        return self._tensor.theta_values()

    def _resolve_theta(self, theta_ratio) -> float | None:
        return self._tensor.resolve_theta(theta_ratio)

    def _psi_values(self) -> np.ndarray:
        return self._tensor.psi_values()

    def _grid(self, theta: float | None) -> TableGrid:
        return self._tensor.grid(theta)

    def _lookup_grid(self) -> TableGrid:
        return self._tensor.lookup_grid()

    def _hermite_grid(self, theta, grid: TableGrid | None = None) -> HermiteGrid:
        return self._tensor.hermite(theta, grid)

    # ---- lookup ----------------------------------------------------------
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
        :data:`vimpact.tablebuild.verify.BOUND_FACTOR`), or None if not measured
        (:func:`vimpact.lookup.bounds.error_bound`).
        """
        return bounds.error_bound(self.interpolation_error, method)

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
        psis, thetas = self._tensor.psi_values(), self._tensor.theta_values()
        arrays, bcast = query.query_arrays(self.model, method, Q1, nu, Q2, psi, theta_ratio,
                                           psis, thetas, self._tensor.resolve_theta)
        if self.is_adaptive:  # below a standard solid's Q2 range: vimpact.lookup.band
            out, bound = adaptive_table.adaptive_lookup(self, arrays, method, extrapolate)
        else:
            out, bound = (self._tensor(arrays, thetas, theta_ratio, method, extrapolate),
                          self.error_bound(method))
        return query.lookup_result(arrays, out, bcast, bound)

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
        return dataset.to_xarray(self, theta_ratio)

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
        return curve.restitution_curve(self, material, R, m, v_z0, theta_ratio=theta_ratio,
                                       extrapolate=extrapolate,
                                       allow_large_contact=allow_large_contact,
                                       angle_deg=angle_deg, mu=mu)

    def export_curve(self, path, material, R: float, m: float, v_z0, **options) -> pd.DataFrame:
        """Write :meth:`restitution_curve` to a CSV file ``path`` (``.csv``); returns the curve.

        Columns ``v_z0_m_s`` (m/s), ``Q1``, (``Q2``), ``e_z``, ``e_x``,
        ``beta_x`` (dimensionless); ``options`` as for :meth:`restitution_curve`.
        """
        return curve.export_curve(self, path, material, R, m, v_z0, **options)
