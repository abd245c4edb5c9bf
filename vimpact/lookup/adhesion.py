"""Adhesive impact tables: e_z and whether the sphere sticks, over (lam, Q1).

An adhesive table (docs/physics.md#adhesion, built by
:func:`vimpact.tablebuild.adhesion.build_adhesion_table`, ``vimpact table build``
on a spec with a ``lam`` axis) holds the normal impact of a sphere on an
adhesive Kelvin-Voigt half-space, whose restitution depends on the adhesion
number ``lam`` and the damping ``Q1`` alone (not on ``nu``). The sphere sticks
for ``lam >= lam_s(Q1)``, the sticking number, and ``e_z`` is not smooth there:
elastic, it falls to 0 like ``sqrt(1 - (lam / lam_s)^(10/3))``; damped, it jumps
from a finite value to 0 (the last elements are peeled only by a sphere still
moving), and just below ``lam_s`` it follows ``e_0 + c sqrt(log(lam_s / lam))``.
So the table stores

- one row per ``Q1`` node at ``lam = lam_s(Q1)`` (``s = 0``, status ``stuck``,
  ``e_z = 0``): the boundary, found by bisection;
- rows at ``lam = lam_s(Q1) exp(-s^2)`` for fixed nodes ``s > 0`` (status
  ``normal_only``) with their ``e_z``, which is smooth in ``(log Q1, s)``.

A lookup interpolates ``log lam_s`` cubically in ``log Q1``; a point with
``lam >= lam_s(Q1)`` is stuck (``e_z = 0``, ``stuck`` true); otherwise ``e_z`` is
interpolated cubically in ``(log Q1, s)``, ``s = sqrt(log(lam_s / lam))`` (linearly
extrapolated in the sliver between the first node and ``s = 0``). The metadata
holds the ranges and the error measured against direct simulation
(:func:`vimpact.tablebuild.adhesion.verify_adhesion_table`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from vimpact.lookup.interpolate import HermiteGrid
from vimpact.model.validation import InputError
from vimpact.tableformat.metadata import META_PREFIX, decode_value, read_metadata

__all__ = ["KIND", "AdhesionTable", "is_adhesion_table"]

#: ``vimpact.table_kind`` of an adhesive table.
KIND = "adhesion"
#: The outputs of a lookup.
OUTPUTS = ("e_z", "stuck", "lam_s")


def is_adhesion_table(path) -> bool:
    """Return True if the Parquet file at ``path`` is an adhesive table (its metadata says so)."""
    try:
        meta = read_metadata(path)
    except (InputError, OSError, ValueError):
        return False
    return meta.get("table_kind") == KIND or meta.get(META_PREFIX + "table_kind") == KIND


class AdhesionTable:
    """An adhesive impact table (module docstring): rows and ``vimpact.*`` metadata.

    Parameters
    ----------
    data : the rows: ``Q1``, ``nu``, ``lam``, ``s``, ``e_z``, ``status``
    metadata : ``vimpact.*`` key -> text
    path : where it was read from (messages)
    """

    def __init__(self, data: pd.DataFrame, metadata: dict[str, str], path=None):
        self.data = data.reset_index(drop=True)
        self.metadata = dict(metadata)
        self.path = None if path is None else Path(path)
        bound = self.data[self.data["status"] == "stuck"].sort_values("Q1")
        self.Q1 = bound["Q1"].to_numpy(float)
        self.lam_s_nodes = bound["lam"].to_numpy(float)
        inner = self.data[self.data["status"] != "stuck"]
        self.s = np.unique(inner["s"].to_numpy(float))
        e_z = inner.pivot(index="Q1", columns="s", values="e_z").reindex(index=self.Q1,
                                                                         columns=self.s)
        if e_z.isna().to_numpy().any():
            raise InputError(f"table = {str(self.path)!r} is not allowed: an adhesive table "
                             "needs e_z at every (Q1, s) node")
        self._boundary = HermiteGrid(["Q1"], [self.Q1], {"log_lam_s": np.log(self.lam_s_nodes)},
                                     log_axes=("Q1",))
        self._inner = HermiteGrid(["Q1", "s"], [self.Q1, self.s],
                                  {"e_z": e_z.to_numpy(float)}, log_axes=("Q1",))

    # ---- files ---------------------------------------------------------------
    @classmethod
    def open(cls, path) -> AdhesionTable:
        """Read an adhesive table, its integrity checked (page checksums, content hash)."""
        import pyarrow.parquet as pq

        from vimpact.tableformat.integrity import verify_table

        verify_table(path)
        arrow = pq.read_table(path)
        meta = {k.decode(): v.decode() for k, v in (arrow.schema.metadata or {}).items()
                if k.decode().startswith(META_PREFIX)}
        if meta.get(META_PREFIX + "table_kind") != KIND:
            raise InputError(f"table = {str(path)!r} is not allowed: not an adhesive table "
                             f"(no vimpact.table_kind = {KIND!r})")
        return cls(arrow.to_pandas(), meta, path)

    def save(self, path) -> Path:
        """Write the rows and metadata as Parquet (atomically, with checksums and hashes)."""
        from vimpact.tableformat.files import write_frame

        return write_frame(self.data, self.metadata, Path(path))

    def meta(self, key: str, default=None):
        """Return the metadata entry ``vimpact.<key>``, decoded by the table format's codec."""
        text = self.metadata.get(META_PREFIX + key)
        return default if text is None else decode_value(key, text)

    # ---- ranges ------------------------------------------------------------------
    @property
    def lam_range(self) -> tuple[float, float]:
        """The covered adhesion numbers ``(lam_min, lam_max)``."""
        lo, hi = self.meta("lam_range")
        return float(lo), float(hi)

    @property
    def Q1_range(self) -> tuple[float, float]:
        """The covered damping parameters ``(Q1_min, Q1_max)``."""
        return float(self.Q1[0]), float(self.Q1[-1])

    def error_bound(self) -> dict | None:
        """Return the largest errors measured against direct simulation (or None).

        From the metadata ``vimpact.interpolation_error``.
        """
        err = self.meta("interpolation_error")
        if not isinstance(err, dict):
            return None
        return {k: v["max"] for k, v in err.get("outputs", {}).items()}

    def info(self) -> dict:
        """Model, rows, ranges, nodes, build and measured error."""
        return {"kind": KIND, "model": self.meta("model"), "rows": len(self.data),
                "Q1": list(self.Q1_range), "lam": list(self.lam_range),
                "nodes": {"Q1": len(self.Q1), "s": len(self.s)},
                "lam_s": {"min": float(self.lam_s_nodes.min()),
                          "max": float(self.lam_s_nodes.max())},
                "build": self.meta("build"), "interpolation_error": self.meta(
                    "interpolation_error")}

    # ---- lookup ------------------------------------------------------------------
    def sticking_number(self, Q1) -> np.ndarray:
        """Return the sticking adhesion number ``lam_s(Q1)`` (cubic in log-log between nodes)."""
        Q1 = self._inside("Q1", Q1, self.Q1_range)
        return np.exp(self._boundary([Q1], False)["log_lam_s"])

    def _inside(self, name: str, x, rng: tuple[float, float]) -> np.ndarray:
        try:
            arr = np.asarray(x, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{name} = {x!r} is not allowed: must be a number or an array "
                             "of numbers") from None
        lo, hi = rng
        bad = ~(np.isfinite(arr) & (arr >= lo * (1.0 - 1e-12)) & (arr <= hi * (1.0 + 1e-12)))
        if np.any(bad):
            raise InputError(f"{name} = {float(arr[bad].flat[0])!r} is outside the table's "
                             f"range: it covers {name} in [{lo:.6g}, {hi:.6g}]")
        return np.clip(arr, lo, hi)

    def lookup(self, Q1, lam) -> dict:
        """Interpolate ``e_z`` and whether the sphere sticks at ``Q1``, ``lam``.

        Parameters
        ----------
        Q1 : damping parameter ``sqrt(15/32) (eta/G_inf)/T``, dimensionless
        lam : adhesion number ``sqrt(2 pi a_H dgamma / E*) / d``, dimensionless

        Returns
        -------
        dict
            ``Q1``, ``lam`` (broadcast), ``e_z`` (0 where stuck), ``stuck`` (bool),
            ``lam_s`` (the sticking number at ``Q1``), ``error_bound`` (the largest
            errors measured against direct simulation, or None); floats/bools for
            scalar inputs.

        Raises
        ------
        InputError
            a value outside the covered ranges (naming it and the range)
        """
        Q1 = self._inside("Q1", Q1, self.Q1_range)
        lam = self._inside("lam", lam, self.lam_range)
        Q1, lam = np.broadcast_arrays(Q1, lam)
        shape = Q1.shape
        q, lm = Q1.ravel(), lam.ravel()
        lam_s = np.exp(self._boundary([q], False)["log_lam_s"])
        stuck = lm >= lam_s
        e_z = np.zeros(q.shape)
        free = ~stuck
        if free.any():
            s = np.minimum(np.sqrt(np.log(lam_s[free] / lm[free])), self.s[-1])
            e_z[free] = np.clip(self._inner([q[free], s], True)["e_z"], 0.0, 1.0)
        out = {"Q1": Q1, "lam": lam, "e_z": e_z.reshape(shape), "stuck": stuck.reshape(shape),
               "lam_s": lam_s.reshape(shape)}
        if not shape:
            out = {k: (bool(v) if k == "stuck" else float(v)) for k, v in out.items()}
        out["error_bound"] = self.error_bound()
        return out


def format_info(info: dict) -> str:
    """Return the text of ``vimpact table info`` for an adhesive table."""
    lines = [f"adhesive impact table ({info['model']}, normal impact): e_z and stuck over "
             f"lam x Q1, {info['rows']} rows",
             f"  Q1              {info['Q1'][0]:.6g} .. {info['Q1'][1]:.6g} "
             f"({info['nodes']['Q1']} nodes)",
             f"  lam             {info['lam'][0]:.6g} .. {info['lam'][1]:.6g} "
             f"({info['nodes']['s']} nodes below the sticking number)",
             f"  sticking lam_s  {info['lam_s']['min']:.6g} .. {info['lam_s']['max']:.6g}"]
    build = info.get("build")
    if isinstance(build, dict):
        lines.append(f"  build           {build.get('seconds')} s, tolerance "
                     f"{build.get('tolerance')}, met {build.get('met')}")
    err = info.get("interpolation_error")
    if isinstance(err, dict):
        parts = [f"{k} max {v['max']:.3g}" for k, v in err.get("outputs", {}).items()
                 if v.get("max") is not None]
        lines.append(f"  measured error  {', '.join(parts)} at {err.get('points')} held-out "
                     f"points; stuck misread at {err.get('stuck_misread')}")
    return "\n".join(lines)

