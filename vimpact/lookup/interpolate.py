"""Tensor-product cubic Hermite interpolation on a restitution table's grid.

Along each axis (``log Q1``, ``log Q2``, ``nu``, ``theta_ratio``: the log of
the damping parameters, the others as they are) the interpolant is a cubic
Hermite polynomial per cell, fixed by the node values and the node slopes.
In several dimensions it is the tensor product: each node carries the value,
the slope along every axis and the mixed derivatives (``2**d`` numbers per
node and output), computed once per table.

Slopes
------
Per axis, the slope at a node is the derivative of the polynomial through
(up to) five neighbouring nodes (fourth order on a smooth output, exact for
polynomials of degree <= 4, so the interpolant reproduces cubics exactly and
converges at order 4 on smooth data). Then, where the data is monotone around
a node (the two secants adjacent to it and the next ones out, all of one sign),
the slope is limited to
``[0, 3 min(|secants|)]`` with that sign (Fritsch-Carlson's sufficient
condition, Hyman's filter): a monotone run of data stays monotone between its
nodes, and no overshoot appears at steep changes. Where the data has a local
extremum at the node or in a cell beside it, the slope is left alone, which
keeps the order there (limiting the slopes beside a smooth maximum costs an
order of magnitude in accuracy: measured on beta_x(Q1) of the Kelvin-Voigt
table, 4e-4 with, 4e-6 without). Mixed derivatives are the slope operators of the other axes
applied to the limited slopes.

Evaluation: by default the numba kernel :func:`vimpact.kernels.hermite.hermite_eval`
(one pass per point: per axis a binary search and four basis weights, then the
``4**d`` terms of the tensor product; parallel over blocks of points). The
NumPy evaluation (``backend="numpy"``: per axis one ``searchsorted`` and four
basis weights, then one gather of the ``2**d`` corner nodes and a weighted sum,
in chunks of points) is kept as the reference the kernel is tested against.
"""

from __future__ import annotations

import numpy as np

from vimpact.model.validation import InputError

__all__ = ["BACKENDS", "HermiteGrid", "LOG_AXES", "NODE_ATOL", "NODE_RTOL", "cluster_nodes",
           "derivative_matrix", "hermite_slopes", "same_node"]

#: Axes interpolated in the logarithm of the value (> 0 required; the one list for
#: tables, their verification and refinement: held-out mid-points and inserted nodes
#: are geometric means there): the damping parameters, which span decades, and
#: ``theta_ratio = Theta / (m R^2)``, which enters the tangential dynamics through the
#: effective mass factor ``1 + m R^2 / Theta``, smoother in ``log theta_ratio`` than in
#: ``theta_ratio`` on nodes spaced by ratios. ``nu`` and ``psi`` (which is 0 at normal
#: incidence) are interpolated as they are.
LOG_AXES = ("Q1", "Q2", "theta_ratio")
#: Evaluations of :meth:`HermiteGrid.__call__`: the numba kernel, the NumPy reference.
BACKENDS = ("numba", "numpy")
#: Points evaluated per block (bounds the temporary memory).
_BLOCK = 1 << 16
#: Nodes of a slope stencil (the degree of the local polynomial + 1).
_STENCIL = 5
#: Two coordinates closer than ``NODE_RTOL |x| + NODE_ATOL`` are the same node (the
#: one rule for tables, grids and the interpolation kernel: ``vimpact.kernels.hermite``
#: writes the same numbers out, as kernels import no other folder; a test checks them).
NODE_RTOL = 1e-9
NODE_ATOL = 1e-12


def same_node(a, b) -> np.ndarray:
    """Elementwise: ``a`` and ``b`` are the same grid coordinate."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.abs(a - b) <= NODE_RTOL * np.maximum(np.abs(a), np.abs(b)) + NODE_ATOL


def cluster_nodes(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distinct values up to round-off: ``(nodes, index of each value)``.

    Values that are :func:`same_node` as a cluster's first member join it;
    the node is the cluster's median member (a value that occurs in the data).
    """
    order = np.argsort(values, kind="stable")
    s = values[order]
    start = np.ones(len(s), dtype=bool)  # s[i] begins a cluster
    if len(s) and s[0] >= 0.0:
        # non-negative values: one that is not the same node as its lower neighbour is not
        # the same node as any smaller value (their distance is larger, the tolerance the
        # same), so a cluster begins there, and an exact repeat never begins one; the
        # comparison with the cluster's first member is left for the other values only
        start[1:] = ~same_node(s[:-1], s[1:])
        open_ = np.flatnonzero(~start & np.r_[False, s[1:] != s[:-1]])
    else:
        start[1:] = False
        open_ = np.arange(1, len(s))
    # the last cluster start at or before each value among those already decided
    fixed = np.maximum.accumulate(np.where(start, np.arange(len(s)), 0)) if len(s) else start
    last = 0
    for i in open_.tolist():
        first = max(int(fixed[i - 1]), last)
        start[i] = not same_node(s[first], s[i])
        if start[i]:
            last = i
    starts = np.flatnonzero(start)
    bounds = np.append(starts, len(s))
    nodes = s[(bounds[:-1] + bounds[1:] - 1) // 2]
    index = np.empty(len(values), dtype=np.int64)
    index[order] = np.cumsum(start) - 1
    return nodes, index


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def outside_range(name: str, nodes: np.ndarray, bad: float, log_axis: bool) -> InputError:
    """Return the refusal of a lookup at ``name = bad``, outside the axis' ``nodes``.

    The one wording of the tensor lookups (multilinear and cubic): the range covered
    and how to extrapolate (linearly, in log ``name`` on a ``log_axis``).
    """
    lo, hi = nodes[0], nodes[-1]
    covered = (f"{name} = {_fmt(lo)} only (a single grid value)" if len(nodes) == 1
               else f"{name} in [{_fmt(lo)}, {_fmt(hi)}]")
    return InputError(f"{name} = {bad:.6g} is outside the table's range: it covers {covered}; "
                      "extrapolate=True (--extrapolate) extrapolates linearly"
                      + (f" in log {name}" if log_axis else ""))


def derivative_matrix(x: np.ndarray, stencil: int = _STENCIL) -> np.ndarray:
    """Return the derivative matrix ``D`` of the nodes ``x``.

    ``(D @ f)[i]`` is the derivative at ``x[i]`` of the polynomial through
    ``stencil`` nodes around ``i`` (centred where possible; all nodes if fewer).

    Parameters
    ----------
    x : increasing node coordinates (on the axis's own scale, e.g. log Q1)
    stencil : nodes per stencil (5: fourth-order slopes)

    Returns
    -------
    ndarray of shape ``(len(x), len(x))``, zero for a single node.
    """
    x = np.asarray(x, dtype=float)
    n = len(x)
    D = np.zeros((n, n))
    if n < 2:
        return D
    k = min(stencil, n)
    for i in range(n):
        lo = min(max(i - k // 2, 0), n - k)
        idx = np.arange(lo, lo + k)
        xs = x[idx]
        # derivative at x[i] of the Lagrange basis polynomials of the stencil
        for j_local, j in enumerate(idx):
            others = np.delete(xs, j_local)
            denom = np.prod(xs[j_local] - others)
            if j == i:
                D[i, j] = np.sum(1.0 / (x[i] - others))
            else:
                rest = np.delete(others, np.flatnonzero(others == x[i]))
                D[i, j] = np.prod(x[i] - rest) / denom
    return D


def _limit(x: np.ndarray, f: np.ndarray, s: np.ndarray, axis: int) -> np.ndarray:
    """Apply Hyman's monotonicity filter along ``axis``.

    Where both secants adjacent to a node have one sign, clip the slope into
    ``[0, 3 min(|secants|)]`` with that sign; a zero secant on either side gives
    slope 0; the end nodes use their one secant.
    """
    f = np.moveaxis(f, axis, -1)
    s = np.moveaxis(s, axis, -1).copy()
    n = f.shape[-1]
    if n < 2:
        return np.moveaxis(s, -1, axis)
    d = np.diff(f, axis=-1) / np.diff(x)  # secants, shape (..., n-1)
    left = np.concatenate([d[..., :1], d], axis=-1)
    right = np.concatenate([d, d[..., -1:]], axis=-1)
    # monotone across the node and across the cells on either side: a node next to a
    # cell holding an extremum keeps its accurate slope (the extremum is real data)
    far_left = np.concatenate([d[..., :1], d[..., :1], d[..., :-1]], axis=-1)
    far_right = np.concatenate([d[..., 1:], d[..., -1:], d[..., -1:]], axis=-1)
    monotone = ((left * right >= 0.0) & (far_left * left >= 0.0) & (right * far_right >= 0.0)
                & (far_left * right >= 0.0) & (left * far_right >= 0.0))
    sign = np.where(left + right >= 0.0, 1.0, -1.0)
    bound = 3.0 * np.minimum(np.abs(left), np.abs(right))
    clipped = sign * np.clip(sign * s, 0.0, bound)
    with np.errstate(invalid="ignore"):
        s = np.where(monotone, clipped, s)
    return np.moveaxis(s, -1, axis)


def _derivative(x: np.ndarray, f: np.ndarray, axis: int, D: np.ndarray) -> np.ndarray:
    """Apply ``D`` along ``axis``.

    Where a stencil meets a failed (NaN) node but the node itself is finite, the
    mean of its finite adjacent secants instead (so a failed impact spoils only the
    cells that touch it).
    """
    s = np.moveaxis(np.tensordot(D, np.moveaxis(f, axis, 0), axes=(1, 0)), 0, axis)
    patch = np.isnan(s) & np.isfinite(f)
    if np.any(patch) and f.shape[axis] > 1:
        g = np.moveaxis(f, axis, -1)
        d = np.diff(g, axis=-1) / np.diff(x)
        pad = np.full(g.shape[:-1] + (1,), np.nan)
        left = np.concatenate([pad, d], axis=-1)
        right = np.concatenate([d, pad], axis=-1)
        mean = np.where(np.isnan(left), right, np.where(np.isnan(right), left, 0.5 * (left + right)))
        s = np.where(patch, np.moveaxis(mean, -1, axis), s)
    return s


def hermite_slopes(x: np.ndarray, f: np.ndarray, axis: int = 0, monotone: bool = True,
                   D: np.ndarray | None = None) -> np.ndarray:
    """Node slopes ``df/dx`` of ``f`` along ``axis`` (see the module text).

    Parameters
    ----------
    x : increasing node coordinates along ``axis``
    f : node values
    axis : the axis of ``f`` that ``x`` labels
    monotone : apply the monotonicity filter where the data is monotone
    D : the derivative matrix of ``x`` (:func:`derivative_matrix`), if already made
    """
    D = derivative_matrix(x) if D is None else D
    s = _derivative(np.asarray(x, float), f, axis, D)
    return _limit(np.asarray(x, float), f, s, axis) if monotone else s


class HermiteGrid:
    """Cubic Hermite tensor-product interpolant of several outputs on one grid.

    Parameters
    ----------
    axes : axis names, e.g. ``["Q1", "nu"]`` (``Q1``, ``Q2`` are interpolated in log)
    nodes : increasing node values per axis (raw, not logged)
    values : output name -> node values, shape ``tuple(len(n) for n in nodes)``
        (NaN at a node whose impact failed: lookups that need it give NaN)
    monotone : limit the slopes where the data is monotone (default True)
    log_axes : names of the axes interpolated in ``log x`` (default :data:`LOG_AXES`)
    """

    def __init__(self, axes: list[str], nodes: list[np.ndarray], values: dict[str, np.ndarray],
                 monotone: bool = True, log_axes: tuple[str, ...] = LOG_AXES):
        self.axes = list(axes)
        self.nodes = [np.asarray(n, dtype=float) for n in nodes]
        self.log_axes = tuple(log_axes)
        for name, n in zip(self.axes, self.nodes):
            if name in self.log_axes and np.any(n <= 0.0):
                raise InputError(f"{name} nodes = {n[n <= 0.0][:3].tolist()} are not allowed on "
                                 f"the log {name} axis of a cubic lookup: give {name} > 0 (a "
                                 "Kelvin-Voigt row is Q2 = NaN, not 0)")
        self.coords = [np.log(n) if a in self.log_axes else n for a, n in zip(self.axes, self.nodes)]
        self.names = list(values)
        self.shape = tuple(len(n) for n in self.nodes)
        d = len(self.axes)
        mats = [derivative_matrix(c) for c in self.coords]
        stacks = []
        for name in self.names:
            f = np.asarray(values[name], dtype=float)
            # derivative arrays by bit mask m: bit k set = differentiated along axis k
            deriv = {0: f}
            for k in range(d):
                for m in range(1 << k):  # masks without bit k, built so far
                    base = deriv[m]
                    if m == 0:
                        deriv[m | 1 << k] = hermite_slopes(self.coords[k], f, k, monotone, mats[k])
                    else:
                        deriv[m | 1 << k] = _derivative(self.coords[k], base, k, mats[k])
            stacks.append(np.stack([deriv[m] for m in range(1 << d)], axis=-1))
        data = np.stack(stacks, axis=-1)  # shape + (2**d, n_out)
        # (node, derivative mask) pairs with a NaN in some output
        self.bad = ~np.all(np.isfinite(data.reshape(-1, 1 << d, len(self.names))), axis=2)
        self.data = np.nan_to_num(data.reshape(-1, 1 << d, len(self.names)))
        self._rows = self.data.reshape(len(self.data), -1)  # one row of numbers per node
        self.strides = np.array([int(np.prod(self.shape[k + 1:])) for k in range(d)], dtype=np.int64)
        self._kernel_args: tuple | None = None

    def _kernel_arrays(self) -> tuple:
        """Return the grid as the arrays :func:`vimpact.kernels.hermite.hermite_eval` takes.

        Everything but the points, ``extrapolate`` and ``out``.
        """
        if self._kernel_args is None:
            d = len(self.axes)
            is_log = np.array([a in self.log_axes for a in self.axes], dtype=np.bool_)
            coords = np.ascontiguousarray(np.concatenate(self.coords), dtype=np.float64)
            raw = np.ascontiguousarray(np.concatenate(self.nodes), dtype=np.float64)
            start = np.concatenate([[0], np.cumsum(self.shape)]).astype(np.int64)
            offset = np.array([sum(int(self.strides[k]) for k in range(d)
                                   if c >> k & 1 and self.shape[k] > 1)
                               for c in range(1 << d)], dtype=np.int64)
            n_out = self.data.shape[2]
            pad = np.zeros(self.data.shape[:2] + ((-n_out) % 4,))  # outputs in fours
            data = np.ascontiguousarray(np.concatenate([self.data, pad], axis=2), dtype=np.float64)
            bad = np.ascontiguousarray(self.bad, dtype=np.bool_)
            self._kernel_args = (is_log, coords, raw, start, self.strides.astype(np.int64),
                                 offset, data, bad, np.ascontiguousarray(bad.any(axis=1)), n_out)
        return self._kernel_args

    # ---- range checks ---------------------------------------------------------
    def _check(self, k: int, x: np.ndarray, extrapolate: bool) -> None:
        """Raise :class:`InputError` for a point outside axis ``k`` or at ``x <= 0`` on a log axis.

        A point outside the axis is allowed with ``extrapolate``.
        """
        if x.size == 0:
            return
        name, nodes = self.axes[k], self.nodes[k]
        lo, hi = nodes[0], nodes[-1]
        tol_lo = NODE_RTOL * abs(lo) + NODE_ATOL
        tol_hi = NODE_RTOL * abs(hi) + NODE_ATOL
        if not extrapolate and (x.min() < lo - tol_lo or x.max() > hi + tol_hi):
            inside = (x >= lo - tol_lo) & (x <= hi + tol_hi)
            raise outside_range(name, nodes, float(x[~inside].flat[0]), name in self.log_axes)
        if extrapolate and name in self.log_axes and len(nodes) > 1 and x.min() <= 0.0:
            bad = float(x[x <= 0.0].flat[0])
            raise InputError(
                f"{name} = {bad:.6g} cannot be extrapolated on the table's log {name} axis: "
                f"it covers {name} in [{_fmt(lo)}, {_fmt(hi)}]; give {name} > 0")

    # ---- per-axis weights ---------------------------------------------------------
    def _axis(self, k: int, x: np.ndarray, extrapolate: bool):
        """Cell index and the four 1-D weights ``(value lo, value hi, slope lo, slope hi)``."""
        name, nodes, c = self.axes[k], self.nodes[k], self.coords[k]
        lo, hi = nodes[0], nodes[-1]
        self._check(k, x, extrapolate)
        if not extrapolate:
            x = np.clip(x, lo, hi)
        n = len(nodes)
        if n == 1:
            zero = np.zeros(x.shape)
            return np.zeros(x.shape, dtype=np.int64), (np.ones(x.shape), zero, zero, zero)
        if name in self.log_axes:
            u = np.log(x)
        else:
            u = x
        i0 = np.clip(np.searchsorted(c, u, side="right") - 1, 0, n - 2)
        a, b = c[i0], c[i0 + 1]
        h = b - a
        t = np.clip((u - a) / h, 0.0, 1.0)
        # a value within round-off of a node gives that node's row exactly
        near = np.abs(x - nodes[i0]) <= NODE_RTOL * np.abs(nodes[i0]) + NODE_ATOL
        t = np.where(near, 0.0, t)
        near = np.abs(x - nodes[i0 + 1]) <= NODE_RTOL * np.abs(nodes[i0 + 1]) + NODE_ATOL
        t = np.where(near, 1.0, t)
        t2, t3 = t * t, t * t * t
        w0 = 2 * t3 - 3 * t2 + 1
        w1 = -2 * t3 + 3 * t2
        g0 = (t3 - 2 * t2 + t) * h
        g1 = (t3 - t2) * h
        if extrapolate:  # linear beyond the end nodes, with the end node's slope
            g0 = g0 + np.minimum(u - c[0], 0.0)
            g1 = g1 + np.maximum(u - c[-1], 0.0)
        return i0, (w0, w1, g0, g1)

    def __call__(self, coords: list[np.ndarray], extrapolate: bool = False,
                 backend: str = "numba") -> dict[str, np.ndarray]:
        """Interpolated outputs at the points ``coords`` (one array per axis, same shape).

        Parameters
        ----------
        coords : one array of raw coordinates per axis (``Q1``, not ``log Q1``), one shape
        extrapolate : continue linearly beyond the end nodes (with the end slopes)
            instead of raising :class:`InputError` for a point outside
        backend : ``"numba"`` (default, :func:`vimpact.kernels.hermite.hermite_eval`) or
            ``"numpy"`` (the vectorized reference)

        Returns
        -------
        dict output name -> array of ``coords``' shape (NaN where a failed node's
        value or derivative carries weight)
        """
        if backend not in BACKENDS:
            raise InputError(f"backend = {backend!r} is not allowed: must be one of "
                             + ", ".join(BACKENDS))
        shape = np.shape(coords[0])
        flat = [np.asarray(c, dtype=float).ravel() for c in coords]
        if backend == "numba":
            return self._call_kernel(flat, shape, extrapolate)
        n = flat[0].size
        d = len(self.axes)
        nc = 1 << d
        n_out = len(self.names)
        # corner offsets in the flat node index; corner bit k = the hi node along axis k
        offsets = np.array([sum(self.strides[k] for k in range(d)
                                if c >> k & 1 and self.shape[k] > 1)
                            for c in range(nc)], dtype=np.int64)
        out = np.empty((n, n_out))
        for start in range(0, n, _BLOCK):
            stop = min(start + _BLOCK, n)
            B = stop - start
            base = np.zeros(B, dtype=np.int64)
            weights = []
            for k, x in enumerate(flat):
                i0, w = self._axis(k, x[start:stop], extrapolate)
                base += i0 * self.strides[k]
                weights.append(w)
            idx = base[:, None] + offsets[None, :]
            # W[b, corner bits d-1..0, mask bits d-1..0] = prod_k w_k[b, bit_k, mask_k]
            W = np.ones((B,) + (1,) * (2 * d))
            for k, (w0, w1, g0, g1) in enumerate(weights):
                wk = np.stack([np.stack([w0, g0], -1), np.stack([w1, g1], -1)], 1)  # (B, 2, 2)
                bshape = [B] + [1] * (2 * d)
                bshape[d - k] = 2
                bshape[2 * d - k] = 2
                W = W * wk.reshape(bshape)
            W = W.reshape(B, nc * nc)
            G = np.take(self._rows, idx, axis=0).reshape(B, nc * nc, n_out)
            acc = np.empty((B, n_out))
            for j in range(n_out):
                acc[:, j] = np.einsum("bj,bj->b", W, G[:, :, j])
            if self.bad.any():
                # NaN where a failed node's value or derivative carries weight
                nz = [[(w0 != 0.0, g0 != 0.0), (w1 != 0.0, g1 != 0.0)]
                      for (w0, w1, g0, g1) in weights]
                bad = np.zeros(B, dtype=bool)
                for c in range(nc):
                    node_bad = self.bad[idx[:, c]]
                    if not node_bad.any():
                        continue
                    for m in range(nc):
                        used = node_bad[:, m].copy()
                        for k in range(d):
                            used &= nz[k][c >> k & 1][m >> k & 1]
                        bad |= used
                acc[bad] = np.nan
            out[start:stop] = acc
        return {name: out[:, j].reshape(shape) for j, name in enumerate(self.names)}

    def _call_kernel(self, flat: list[np.ndarray], shape: tuple, extrapolate: bool) -> dict:
        from vimpact.kernels.hermite import hermite_eval

        for k, x in enumerate(flat):
            self._check(k, x, extrapolate)
        n = flat[0].size
        points = np.empty((n, len(self.axes)))
        for k, x in enumerate(flat):
            points[:, k] = x
        out = np.empty((n, len(self.names)))
        hermite_eval(points, *self._kernel_arrays(), bool(extrapolate), out)
        return {name: out[:, j].reshape(shape) for j, name in enumerate(self.names)}
