"""Adaptive (non-tensor) restitution tables: cells refined where the lookup needs them.

A tensor grid puts a plane of nodes across the whole table for every feature
it resolves; the restitution of a standard solid changes course along narrow
ridges in the (``Q1``, ``Q2``) plane, so a tensor grid that resolves them is far
too large. An adaptive table refines only where it must:

- The **adaptive axes** (the damping parameters ``Q1`` and, for a standard
  solid, ``Q2``; interpolated in their logarithm) are mapped onto the unit
  square. The root cell is the whole square, and every cell is either a
  *leaf* or split into its ``2**k`` halves (a binary tree in ``Q1`` alone, a
  quadtree in ``log Q1 x log Q2``).
- A leaf holds ``4**k`` nodes at ``0, 1/3, 2/3, 1`` of its width along every
  axis and is interpolated by the tensor-product cubic Lagrange polynomial
  through them (fourth order; the nodes of a cell's halves include all of the
  cell's own nodes, so a split reuses them).
- The **tensor axis** (``nu``) is the same short list of nodes at every
  adaptive node: ``beta_x`` is smooth in ``nu`` and ``e_z`` does not depend on it.
  Along it the lookup is the cubic Lagrange polynomial through the four nodes
  around the point.

**Refinement** (:func:`refine_cells`): starting from a uniform level, every cell
is checked at ``3**k`` held-out points (``1/6, 1/2, 5/6`` of its width along
every axis: the cell centre, its edge mid-points, and the points where the
error of a four-node cubic peaks), at every tensor node; a cell whose largest
error there exceeds the cell tolerance is split. A cell's check points become
nodes of its halves, so nothing simulated is wasted. Neighbouring leaves of
different levels agree at their common edge only to within the tolerance (no
hanging-node constraint): the lookup is continuous to that accuracy.

Storage (:class:`AdaptiveGrid`, :meth:`AdaptiveGrid.to_metadata`): the table's rows
are the leaves' nodes, one row per adaptive node and tensor node, with the
integer lattice coordinates ``lattice_Q1`` (``lattice_Q2``) of the node; the
metadata entry ``vimpact.adaptive`` holds the axes, their ends, the lattice
and the leaves (level and index per leaf). Evaluation:
:func:`vimpact.kernels.adaptive_lookup.adaptive_eval` (numba, parallel over
blocks of points).
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable

import numpy as np

from vimpact.lookup.interpolate import LOG_AXES
from vimpact.model.validation import InputError

__all__ = ["ADAPTIVE_FORMAT", "AdaptiveGrid", "LATTICE_LEVEL", "check_points",
           "lattice_coordinates", "refine_cells"]

#: Version of the ``vimpact.adaptive`` metadata layout.
ADAPTIVE_FORMAT = 1
#: Node coordinates are integers on a lattice of ``3 * 2**LATTICE_LEVEL`` steps per
#: adaptive axis (exact, shared by neighbouring cells); cells are at most of level
#: ``LATTICE_LEVEL - 1`` (their check points need half a node step).
LATTICE_LEVEL = 30
_TICKS = 3 * 2**LATTICE_LEVEL
#: Fractions of a leaf's width at its nodes and at its held-out check points.
NODE_FRACTIONS = (0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0)
CHECK_FRACTIONS = (1.0 / 6.0, 0.5, 5.0 / 6.0)


def _lagrange_thirds(t: np.ndarray) -> np.ndarray:
    """Cubic Lagrange weights of the nodes 0, 1/3, 2/3, 1 at ``t``: shape ``t.shape + (4,)``."""
    t = np.asarray(t, dtype=float)
    a, b, c = t - 1.0 / 3.0, t - 2.0 / 3.0, t - 1.0
    return np.stack([-4.5 * a * b * c, 13.5 * t * b * c, -13.5 * t * a * c, 4.5 * t * a * b],
                    axis=-1)


def _local(k: int, fractions_index: list[int]) -> np.ndarray:
    """Multi-indices (``k`` columns) of a cell's local points, axis 0 fastest."""
    grid = list(itertools.product(fractions_index, repeat=k))
    return np.array([g[::-1] for g in grid], dtype=np.int64).reshape(-1, k)


def _node_keys(level: np.ndarray, index: np.ndarray) -> np.ndarray:
    """Lattice keys of the ``4**k`` nodes of cells ``(level, index)``: ``(n, 4**k, k)``."""
    k = index.shape[1]
    local = _local(k, [0, 1, 2, 3])  # in thirds of the cell
    step = (2 ** (LATTICE_LEVEL - level)).astype(np.int64)  # a third of the cell
    return (3 * index[:, None, :] + local[None, :, :]) * step[:, None, None]


def _check_keys(level: np.ndarray, index: np.ndarray) -> np.ndarray:
    """Lattice keys of the ``3**k`` check points of cells ``(level, index)``."""
    k = index.shape[1]
    local = _local(k, [1, 3, 5])  # in sixths of the cell
    half = (2 ** (LATTICE_LEVEL - 1 - level)).astype(np.int64)
    return (6 * index[:, None, :] + local[None, :, :]) * half[:, None, None]


def check_points(k: int) -> tuple[np.ndarray, np.ndarray]:
    """Return the check fractions and the matrix of the cubic interpolant at them.

    The fractions are ``3**k`` x ``k``, the matrix ``W`` is ``3**k`` x ``4**k``, with
    ``W @ node values`` = the leaf's cubic interpolant at them.
    """
    frac = np.array(CHECK_FRACTIONS)[_local(k, [0, 1, 2])]
    w = np.ones((len(frac), 4**k))
    nodes = _local(k, [0, 1, 2, 3])
    for d in range(k):
        lw = _lagrange_thirds(frac[:, d])  # (3**k, 4)
        w *= lw[:, nodes[:, d]]
    return frac, w


def lattice_coordinates(keys: np.ndarray, bounds) -> np.ndarray:
    """Return the raw axis values of lattice keys ``(n, k)``.

    The axes have raw ends ``bounds`` ``(k, 2)`` and are log-spaced: the one rule for
    the build, the stored rows and the lookup.
    """
    lb = np.log(np.asarray(bounds, dtype=float))
    u = np.asarray(keys, dtype=float) / _TICKS
    return np.exp(lb[:, 0] + u * (lb[:, 1] - lb[:, 0]))


def _packed(keys: np.ndarray) -> np.ndarray | None:
    """One ``uint64`` per row of lattice keys ``(n, k)``, ordered as the rows are.

    ``key_0 (T + 1)**(k-1) + ... + key_(k-1)`` with ``T`` = :data:`_TICKS` (``k <= 2``:
    below ``2**64``), so sorting the packed keys sorts the rows lexicographically, as
    ``np.unique(keys, axis=0)`` does. None if a key lies off the lattice (``< 0`` or
    ``> T``) or ``k > 2``.
    """
    keys = np.asarray(keys, dtype=np.int64)
    k = keys.shape[1]
    if k > 2 or (keys.size and (keys.min() < 0 or keys.max() > _TICKS)):
        return None
    packed = np.zeros(len(keys), dtype=np.uint64)
    for d in range(k):
        packed = packed * np.uint64(_TICKS + 1) + keys[:, d].astype(np.uint64)
    return packed


def _unique_keys(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(keys, axis=0, return_inverse=True)`` of lattice keys ``(n, k)``.

    The same arrays, sorted as one ``uint64`` per row (:func:`_packed`): 0.03 s for the
    489,360 rows of the shipped standard-solid table, against 0.5 s for the sort of
    rows that ``np.unique(axis=0)`` does.
    """
    packed = _packed(keys)
    if packed is None:
        unique, inverse = np.unique(keys, axis=0, return_inverse=True)
        return unique, inverse.ravel()
    _, first, inverse = np.unique(packed, return_index=True, return_inverse=True)
    return np.asarray(keys, dtype=np.int64)[first], inverse.ravel()


def _rows_of(keys: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Return the row of ``keys`` ``(n, k)`` that holds each lattice key of ``wanted`` ``(m, k)``.

    The last such row where a key appears twice. Raises :class:`InputError` naming the
    first key of ``wanted`` that no row holds.
    """
    probe = _packed(wanted)
    stored = _packed(keys)
    if stored is None:  # rows off the lattice hold no node: never a match
        inside = np.all((keys >= 0) & (keys <= _TICKS), axis=1)
        stored = np.full(len(keys), np.iinfo(np.uint64).max, dtype=np.uint64)
        stored[inside] = _packed(keys[inside])
    if probe is None:
        raise InputError(f"adaptive table: a leaf node at lattice {wanted.tolist()[:1]} lies "
                         "off the lattice")
    order = np.argsort(stored, kind="stable")
    ranked = stored[order]
    at = np.searchsorted(ranked, probe, side="right") - 1
    found = (at >= 0) & (ranked[np.maximum(at, 0)] == probe)
    if not found.all():
        key = tuple(int(x) for x in wanted[np.flatnonzero(~found)[0]])
        raise InputError(f"adaptive table: the leaf node at lattice {key} has no row")
    return order[at].astype(np.int64)


def _cell_tree(leaves: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Return the cell tree of the kernel: ``child`` ``(n_cells, 2**k)`` and ``leaf_of``.

    Cells are numbered as they are first met going through the leaves in order, each
    from the root (cell 0) down to itself; ``child[c, b]`` is the child of cell ``c``
    whose index has bit ``d`` of ``b`` set where it is the upper half along axis ``d``
    (-1: none), ``leaf_of[c]`` the leaf that cell ``c`` is (-1: a split cell).

    Raises :class:`InputError` for a leaf that overlaps an earlier one (the first such
    leaf in order: one that lies inside, covers, or repeats an earlier leaf), a level
    outside ``0 ... LATTICE_LEVEL - 1`` or an index outside its level, and for leaves
    that do not tile the square (a split cell lacks a child).
    """
    n = len(leaves)
    level = leaves[:, 0].astype(np.int64)
    index = leaves[:, 1:].astype(np.int64)
    if n and (level.min() < 0 or level.max() > LATTICE_LEVEL - 1):
        bad = int(np.flatnonzero((level < 0) | (level > LATTICE_LEVEL - 1))[0])
        raise InputError(f"adaptive leaves: leaf {bad} at level {int(level[bad])} is not "
                         f"allowed: levels 0 ... {LATTICE_LEVEL - 1}")
    outside = np.any((index < 0) | (index >= (np.int64(1) << level)[:, None]), axis=1)
    if outside.any():
        bad = int(np.flatnonzero(outside)[0])
        raise InputError(f"adaptive leaves: leaf {bad} at level {int(level[bad])}, index "
                         f"{index[bad].tolist()} lies outside the square (0 <= index < "
                         f"2**level)")
    if n == 0:
        raise InputError("adaptive leaves do not cover the table: a split cell lacks a child")
    # every leaf's path from the root (level 0) down to itself, leaf by leaf
    steps = level + 1
    owner = np.repeat(np.arange(n), steps)
    depth = np.arange(int(steps.sum())) - np.repeat(np.cumsum(steps) - steps, steps)
    sub = index[owner] >> (level[owner] - depth)[:, None]
    code = np.zeros(len(owner), dtype=np.int64)  # one integer per cell: level and index
    for d in range(k):  # sub + 2**depth: its leading bit gives the level (30 bits each)
        code = (code << 31) | (sub[:, d] + (np.int64(1) << depth))
    own = np.cumsum(steps) - 1  # the entry of each leaf itself
    # overlaps: a leaf n that is (or lies inside) an earlier leaf, or covers one
    leaf_code = code[own]
    unique_leaf, first_leaf = np.unique(leaf_code, return_index=True)
    clash = np.full(n, n, dtype=np.int64)
    twice = np.ones(n, dtype=bool)
    twice[first_leaf] = False
    clash[twice] = np.flatnonzero(twice)  # a leaf repeated: the second is the clash
    at = np.minimum(np.searchsorted(unique_leaf, code), len(unique_leaf) - 1)
    hit = unique_leaf[at] == code
    other = first_leaf[at[hit]]  # the leaf whose cell is on this path
    mine = owner[hit]
    pair = other != mine
    if pair.any() or twice.any():
        worst = np.maximum(other[pair], mine[pair])
        bad = int(min(worst.min() if worst.size else n, clash.min()))
        raise InputError(f"adaptive leaves: leaf {bad} at level {int(level[bad])}, index "
                         f"{index[bad].tolist()} overlaps another leaf")
    # cells numbered in the order they are first met
    _, first, inverse = np.unique(code, return_index=True, return_inverse=True)
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(first))
    cell = rank[inverse.ravel()]
    child = np.full((len(first), 1 << k), -1, dtype=np.int64)
    below = depth > 0
    which = np.zeros(len(owner), dtype=np.int64)
    for d in range(k):
        which |= (sub[:, d] & 1) << d
    child[cell[np.flatnonzero(below) - 1], which[below]] = cell[below]
    leaf = np.full(len(first), -1, dtype=np.int64)
    leaf[cell[own]] = np.arange(n)
    if np.any(child[leaf < 0] < 0):  # every split cell has all its children
        raise InputError("adaptive leaves do not cover the table: a split cell lacks "
                         "a child")
    return child, leaf


class AdaptiveGrid:
    """An adaptive table's cells, nodes and values, and its lookup.

    Parameters
    ----------
    axes : adaptive axis names (``["Q1"]`` or ``["Q1", "Q2"]``; interpolated in log)
    bounds : ``(k, 2)`` raw ends of the adaptive axes (> 0)
    leaves : ``(n_leaves, 1 + k)`` int: level, then the index along each axis
    keys : ``(n_nodes, k)`` int lattice coordinates of the nodes (every leaf node among them)
    tensor_axis : name of the tensor axis (``"nu"``) or None
    tensor_nodes : its increasing nodes (one value: no tensor axis to interpolate)
    values : output name -> ``(n_nodes, n_tensor)`` node values (NaN: a failed impact)
    """

    def __init__(self, axes: list[str], bounds, leaves, keys, tensor_axis: str | None,
                 tensor_nodes, values: dict[str, np.ndarray]):
        self.axes = list(axes)
        self.k = len(self.axes)
        if self.k not in (1, 2):
            raise InputError(f"adaptive axes = {self.axes} are not allowed: one or two "
                             "(Q1, and Q2 for a standard solid)")
        bad = [a for a in self.axes if a not in LOG_AXES]
        if bad:
            raise InputError(f"adaptive axis {bad[0]!r} is not allowed: the adaptive axes are "
                             "log axes (" + ", ".join(LOG_AXES) + ")")
        self.bounds = np.asarray(bounds, dtype=float).reshape(self.k, 2)
        if not np.all(self.bounds > 0) or not np.all(self.bounds[:, 1] > self.bounds[:, 0]):
            raise InputError(f"adaptive bounds = {self.bounds.tolist()} are not allowed: each "
                             "axis needs 0 < lo < hi")
        self.leaves = np.asarray(leaves, dtype=np.int64).reshape(-1, 1 + self.k)
        self.keys = np.asarray(keys, dtype=np.int64).reshape(-1, self.k)
        self.tensor_axis = tensor_axis
        self.tensor_nodes = np.atleast_1d(np.asarray(tensor_nodes, dtype=float))
        self.names = list(values)
        self.values = np.stack([np.asarray(values[n], dtype=float).reshape(
            len(self.keys), len(self.tensor_nodes)) for n in self.names], axis=-1)
        self._kernel: tuple | None = None  # the kernel's arrays, made once

    # ---- geometry ---------------------------------------------------------
    @property
    def log_bounds(self) -> np.ndarray:
        """Natural logarithms of the axes' ends, ``(k, 2)``."""
        return np.log(self.bounds)

    def coordinates(self, keys: np.ndarray) -> np.ndarray:
        """Raw axis values (``Q1``, ``Q2``) of lattice keys ``(n, k)``."""
        return lattice_coordinates(keys, self.bounds)

    def leaf_boxes(self) -> tuple[np.ndarray, np.ndarray]:
        """Raw lower and upper corners of every leaf, each ``(n_leaves, k)``."""
        level = self.leaves[:, 0]
        idx = self.leaves[:, 1:]
        lo = idx * (3 * 2 ** (LATTICE_LEVEL - level))[:, None]
        hi = (idx + 1) * (3 * 2 ** (LATTICE_LEVEL - level))[:, None]
        return self.coordinates(lo), self.coordinates(hi)

    def info(self) -> dict:
        """Leaves, levels and nodes (JSON-serializable)."""
        levels = self.leaves[:, 0]
        return {"axes": self.axes, "tensor_axis": self.tensor_axis,
                "tensor_nodes": len(self.tensor_nodes), "leaves": int(len(self.leaves)),
                "levels": [int(levels.min()), int(levels.max())] if len(levels) else None,
                "adaptive_nodes": int(len(self.keys)),
                "rows": int(len(self.keys) * len(self.tensor_nodes))}

    # ---- kernel arrays ----------------------------------------------------
    def _kernel_arrays(self) -> tuple:
        if self._kernel is None:
            child, leaf = _cell_tree(self.leaves, self.k)
            nk = _node_keys(self.leaves[:, 0], self.leaves[:, 1:]).reshape(-1, self.k)
            leaf_nodes = _rows_of(self.keys, nk).reshape(-1, 4**self.k)
            lb = self.log_bounds
            self._kernel = (self.k, np.ascontiguousarray(lb[:, 0]),
                            np.ascontiguousarray(lb[:, 1]), child, leaf, leaf_nodes,
                            np.ascontiguousarray(self.tensor_nodes),
                            np.ascontiguousarray(self.values))
        return self._kernel

    def check_range(self, coords: dict[str, np.ndarray]) -> None:
        """Raise :class:`InputError` for a point outside the covered box."""
        for d, a in enumerate(self.axes):
            x = coords[a]
            lo, hi = self.bounds[d]
            tol_lo, tol_hi = 1e-9 * lo, 1e-9 * hi
            if x.size and (x.min() < lo - tol_lo or x.max() > hi + tol_hi):
                bad = float(x[(x < lo - tol_lo) | (x > hi + tol_hi)].flat[0])
                raise InputError(f"{a} = {bad:.6g} is outside the table's range: it covers "
                                 f"{a} in [{lo:.6g}, {hi:.6g}] (an adaptive table does not "
                                 "extrapolate)")
        if self.tensor_axis is not None and len(self.tensor_nodes) > 1:
            x = coords[self.tensor_axis]
            lo, hi = self.tensor_nodes[0], self.tensor_nodes[-1]
            if x.size and (x.min() < lo - 1e-12 or x.max() > hi + 1e-12):
                bad = float(x[(x < lo - 1e-12) | (x > hi + 1e-12)].flat[0])
                raise InputError(f"{self.tensor_axis} = {bad:.6g} is outside the table's "
                                 f"range: it covers {self.tensor_axis} in [{lo:.6g}, {hi:.6g}]")

    def __call__(self, coords: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Interpolated outputs at the points ``coords`` (axis name -> raw values, one shape).

        Raises :class:`InputError` outside the covered range.
        """
        from vimpact.kernels.adaptive_lookup import adaptive_eval

        arrays = {a: np.asarray(v, dtype=float) for a, v in coords.items()}
        shape = np.broadcast_shapes(*(v.shape for v in arrays.values()))
        arrays = {a: np.broadcast_to(v, shape).ravel() for a, v in arrays.items()}
        self.check_range(arrays)
        names = self.axes + ([self.tensor_axis] if self.tensor_axis else [])
        points = np.empty((math.prod(shape), len(names)))
        for j, a in enumerate(names):
            points[:, j] = arrays[a]
        out = np.empty((len(points), len(self.names)))
        adaptive_eval(points, *self._kernel_arrays(), out)
        return {n: out[:, j].reshape(shape) for j, n in enumerate(self.names)}

    # ---- storage ------------------------------------------------------------
    def to_metadata(self) -> dict:
        """Return the ``vimpact.adaptive`` metadata entry (JSON-serializable)."""
        return {"format": ADAPTIVE_FORMAT, "axes": self.axes,
                "bounds": self.bounds.tolist(), "lattice_level": LATTICE_LEVEL,
                "tensor_axis": self.tensor_axis, "tensor_nodes": self.tensor_nodes.tolist(),
                "leaves": {"level": self.leaves[:, 0].tolist(),
                           **{f"index_{a}": self.leaves[:, 1 + d].tolist()
                              for d, a in enumerate(self.axes)}}}

    def rows(self) -> dict[str, np.ndarray]:
        """Return the node rows: the axes (raw), the lattice keys and the outputs.

        One row per adaptive node and tensor node (tensor axis fastest).
        """
        nt = len(self.tensor_nodes)
        xy = self.coordinates(self.keys)
        cols: dict[str, np.ndarray] = {}
        for d, a in enumerate(self.axes):
            cols[a] = np.repeat(xy[:, d], nt)
        if self.tensor_axis is not None:
            cols[self.tensor_axis] = np.tile(self.tensor_nodes, len(self.keys))
        for d, a in enumerate(self.axes):
            cols[f"lattice_{a}"] = np.repeat(self.keys[:, d], nt)
        for j, n in enumerate(self.names):
            cols[n] = self.values[:, :, j].ravel()
        return cols

    @classmethod
    def from_rows(cls, meta: dict, data, names=("e_z", "beta_x")) -> AdaptiveGrid:
        """Rebuild from the ``vimpact.adaptive`` entry and the node rows (a DataFrame).

        Raises :class:`InputError` for an inconsistent table. A friction table (the entry
        has ``friction``) gives a :class:`vimpact.lookup.friction.FrictionGrid`.
        """
        if isinstance(meta, dict) and "friction" in meta:
            from vimpact.lookup.friction import FrictionGrid

            return FrictionGrid.from_rows(meta, data)  # type: ignore[return-value]
        if not isinstance(meta, dict) or meta.get("format") != ADAPTIVE_FORMAT:
            raise InputError(f"vimpact.adaptive = {str(meta)[:80]!r} is not allowed: an "
                             f"adaptive table's structure of format {ADAPTIVE_FORMAT}")
        if meta.get("lattice_level") != LATTICE_LEVEL:
            raise InputError(f"vimpact.adaptive lattice_level = {meta.get('lattice_level')!r} "
                             f"is not allowed: {LATTICE_LEVEL}")
        axes = list(meta["axes"])
        tensor_axis = meta.get("tensor_axis")
        tnodes = np.asarray(meta["tensor_nodes"], dtype=float)
        lv = meta["leaves"]
        leaves = np.column_stack([np.asarray(lv["level"], dtype=np.int64)]
                                 + [np.asarray(lv[f"index_{a}"], dtype=np.int64) for a in axes])
        keys_all = np.column_stack([data[f"lattice_{a}"].to_numpy(np.int64) for a in axes])
        if tensor_axis is not None:
            t = data[tensor_axis].to_numpy(float)
            ti = np.searchsorted(tnodes, t)
            ti = np.clip(ti, 0, len(tnodes) - 1)
            if not np.allclose(tnodes[ti], t, rtol=0, atol=1e-12):
                raise InputError(f"adaptive table: a row's {tensor_axis} is not one of the "
                                 f"tensor nodes {tnodes.tolist()}")
        else:
            ti = np.zeros(len(data), dtype=np.int64)
        keys, inverse = _unique_keys(keys_all)
        ok = data["status"].astype(str).isin(["ok"]).to_numpy()
        values = {}
        count = np.zeros((len(keys), len(tnodes)), dtype=np.int64)
        np.add.at(count, (inverse, ti), 1)
        if np.any(count != 1):
            raise InputError("adaptive table: every adaptive node needs exactly one row per "
                             f"{tensor_axis or 'node'} (found "
                             f"{int(count.min())} .. {int(count.max())})")
        for n in names:
            v = np.full((len(keys), len(tnodes)), np.nan)
            v[inverse, ti] = np.where(ok, data[n].to_numpy(float), np.nan)
            values[n] = v
        return cls(axes, meta["bounds"], leaves, keys, tensor_axis, tnodes, values)


def refine_cells(evaluate: Callable[[np.ndarray], np.ndarray], k: int, n_tensor: int,
                 tolerance: float, *, check: tuple[int, ...] | None = None,
                 min_level: int = 2, max_level: int = 16, max_nodes: int = 200_000,
                 max_seconds: float | None = None,
                 progress: Callable[[str], None] | None = None):
    """Split cells until each leaf's cubic lookup meets ``tolerance`` at its check points.

    Parameters
    ----------
    evaluate : lattice keys ``(m, k)`` int -> values ``(m, n_tensor, n_out)`` (the true
        outputs at those adaptive points, at every tensor node; NaN: failed)
    k : adaptive axes (1 or 2)
    n_tensor : tensor nodes
    tolerance : largest absolute error allowed at a leaf's check points (dimensionless, > 0)
    check : the outputs (indices of the last axis) held to the tolerance (default all)
    min_level : level of the uniform start (``2**(k min_level)`` cells)
    max_level : cells of this level are not split (a failing one is reported)
    max_nodes : adaptive points evaluated at most (a level that would exceed it is not
        refined: its cells stay leaves and are reported)
    max_seconds : wall-clock budget; a level that starts after it is not checked (its
        cells stay leaves and are reported, like ``max_nodes``)
    progress : called with one line per level

    Returns
    -------
    (leaves, keys, values, report)
        ``leaves`` ``(n, 1 + k)`` int (level, index); ``keys`` ``(m, k)`` and ``values``
        ``(m, n_tensor, n_out)`` of every leaf node; ``report`` (JSON-serializable):
        ``tolerance``, ``met`` (every leaf within tolerance at its check points),
        ``levels`` (per level: cells checked, split, new points, largest check error),
        ``unmet`` (leaves over tolerance: level, index, error, at most 200),
        ``max_leaf_error`` (largest check error of a leaf), ``points`` (adaptive points
        evaluated), ``seconds``.
    """
    if k not in (1, 2):
        raise InputError(f"k = {k!r} is not allowed: 1 or 2 adaptive axes")
    if not (isinstance(tolerance, (int, float)) and math.isfinite(tolerance) and tolerance > 0):
        raise InputError(f"tolerance = {tolerance!r} is not allowed: must be a number > 0")
    if not 0 <= min_level <= max_level <= LATTICE_LEVEL - 1:
        raise InputError(f"min_level = {min_level}, max_level = {max_level} are not allowed: "
                         f"0 <= min_level <= max_level <= {LATTICE_LEVEL - 1}")
    start = time.perf_counter()
    _, W = check_points(k)
    # the points evaluated so far: packed lattice keys (:func:`_packed`), sorted, and
    # the row of each in the blocks of values
    known_keys = np.zeros(0, dtype=np.uint64)
    known_rows = np.zeros(0, dtype=np.int64)
    blocks: list[np.ndarray] = []

    def lookup(keys: np.ndarray):
        """Return the unique packed keys of ``keys`` and where they are.

        With ``first`` (first appearance of each), ``inverse`` (back to every key)
        and the row of each in the values (``-1``: not yet evaluated).
        """
        flat = keys.reshape(-1, k)
        packed = _packed(flat)
        assert packed is not None  # k <= 2 and a cell's points lie on the lattice
        unique, first, inverse = np.unique(packed, return_index=True, return_inverse=True)
        rows = np.full(len(unique), -1, dtype=np.int64)
        if len(known_keys):
            at = np.minimum(np.searchsorted(known_keys, unique), len(known_keys) - 1)
            hit = known_keys[at] == unique
            rows[hit] = known_rows[at[hit]]
        return flat, unique, first, inverse.ravel(), rows

    def fetch(keys: np.ndarray) -> np.ndarray:
        nonlocal known_keys, known_rows
        flat, unique, first, inverse, rows = lookup(keys)
        new = np.flatnonzero(rows < 0)
        if len(new):
            new = new[np.argsort(first[new], kind="stable")]  # in order of first appearance
            vals = np.asarray(evaluate(flat[first[new]]), float)
            base = sum(len(b) for b in blocks)
            blocks.append(vals)
            rows[new] = base + np.arange(len(new))
            merged = np.concatenate([known_keys, unique[new]])
            order = np.argsort(merged, kind="stable")
            known_keys = merged[order]
            known_rows = np.concatenate([known_rows, rows[new]])[order]
        allv = np.concatenate(blocks) if len(blocks) > 1 else blocks[0]
        if len(blocks) > 1:
            blocks[:] = [allv]
        return allv[rows[inverse]].reshape(keys.shape[:-1] + allv.shape[1:])

    def count_new(keys: np.ndarray) -> int:
        return int(np.sum(lookup(keys)[4] < 0))

    active = _local(k, list(range(2**min_level)))  # index along axis 0 fastest
    level = min_level
    leaves: list = []
    unmet: list[dict] = []
    levels: list[dict] = []
    max_leaf = 0.0
    stopped = "met"
    while len(active):
        lv = np.full(len(active), level, dtype=np.int64)
        nk, ck = _node_keys(lv, active), _check_keys(lv, active)
        n_new = count_new(np.concatenate([nk.reshape(-1, k), ck.reshape(-1, k)]))
        late = max_seconds is not None and time.perf_counter() - start > max_seconds
        if late or len(known_keys) + n_new > max_nodes:
            stopped = (f"max_seconds ({max_seconds:g} s) at level {level}" if late else
                       f"max_nodes ({len(known_keys) + n_new} > {max_nodes}) at level {level}")
            # no room to check these cells: they stay leaves with unknown error
            fetch(nk)
            for idx in active:
                leaves.append([level, *idx])
                if len(unmet) < 200:
                    unmet.append({"level": int(level), "index": idx.tolist(), "error": None})
            levels.append({"level": int(level), "cells": int(len(active)), "split": 0,
                           "new_points": 0, "max_error": None, "unchecked": int(len(active))})
            break
        vn, vc = fetch(nk), fetch(ck)  # (c, 4**k, nt, no), (c, 3**k, nt, no)
        est = np.einsum("pn,cnto->cpto", W, vn)
        err = np.abs(est - vc)
        if check is not None:
            err = err[..., list(check)]
        err = np.where(np.isnan(err), np.inf, err).reshape(len(active), -1).max(axis=1)
        bad = err > tolerance
        final = level >= max_level
        for idx, e in zip(active[~bad], err[~bad]):
            leaves.append([level, *idx])
            max_leaf = max(max_leaf, float(e))
        if final and bad.any():
            stopped = f"max_level ({max_level})"
            for idx, e in zip(active[bad], err[bad]):
                leaves.append([level, *idx])
                max_leaf = max(max_leaf, float(e))
                if len(unmet) < 200:
                    unmet.append({"level": int(level), "index": idx.tolist(),
                                  "error": float(e) if math.isfinite(e) else None})
        finite = err[np.isfinite(err)]
        entry = {"level": int(level), "cells": int(len(active)),
                 "split": 0 if final else int(bad.sum()), "new_points": int(n_new),
                 "max_error": float(finite.max()) if finite.size else None,
                 "failed_checks": int(np.sum(~np.isfinite(err)))}
        levels.append(entry)
        if progress is not None:
            progress(f"level {level}: {len(active)} cells, {n_new} new points "
                     f"({len(known_keys)} in all), {entry['split']} split, largest check error "
                     + (f"{entry['max_error']:.2g}" if entry["max_error"] is not None else "-")
                     + f", {time.perf_counter() - start:.0f} s")
        if final:
            break
        parents = active[bad]
        if not len(parents):
            break
        kids = []
        for c in range(1 << k):
            bits = np.array([(c >> d) & 1 for d in range(k)], dtype=np.int64)
            kids.append(2 * parents + bits)
        active = np.concatenate(kids)
        level += 1
    leaves_arr = np.array(leaves, dtype=np.int64).reshape(-1, 1 + k)
    leaf_keys = _unique_keys(_node_keys(leaves_arr[:, 0], leaves_arr[:, 1:]).reshape(-1, k))[0]
    values = fetch(leaf_keys)
    over = [u for u in unmet if u["error"] is None or u["error"] > tolerance]
    report = {"tolerance": float(tolerance), "met": not over and stopped == "met",
              "stopped": stopped, "levels": levels, "unmet": over,
              "max_leaf_error": max_leaf if math.isfinite(max_leaf) else None,
              "leaves": int(len(leaves_arr)), "points": int(len(known_keys)),
              "seconds": round(time.perf_counter() - start, 1)}
    return leaves_arr, leaf_keys, values, report
