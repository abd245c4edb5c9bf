"""Tensor-product cubic Hermite evaluation on a rectangular grid (numba kernel).

The interpolant is the one of :class:`vimpact.lookup.interpolate.HermiteGrid`
(which computes the node slopes and keeps a NumPy evaluation as the reference):
per axis ``k`` a cell ``[c_i, c_i+1]`` of the node coordinates (``log x`` on a
log axis, ``x`` otherwise), the parameter ``t = (u - c_i) / h`` and the four
cubic Hermite basis weights

- ``w0 = 2 t^3 - 3 t^2 + 1``, ``w1 = -2 t^3 + 3 t^2`` (values at the lower / upper node),
- ``g0 = (t^3 - 2 t^2 + t) h``, ``g1 = (t^3 - t^2) h`` (slopes at the lower / upper node),

and in ``d`` dimensions the sum over the ``2**d`` corner nodes and the ``2**d``
derivative masks (bit ``k`` set: differentiated along axis ``k``) of the
product of one weight per axis times the node's stored derivative. With
``extrapolate`` the end nodes' slopes continue the interpolant linearly.

Everything here is plain arrays; nothing imports the API side.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vimpact.kernels.jit import jit

#: Two coordinates closer than ``NODE_RTOL |node| + NODE_ATOL`` are the same node
#: (the point gets that node's values exactly).
NODE_RTOL = 1e-9
NODE_ATOL = 1e-12
#: Points per parallel work item (each item evaluates its own rows of ``out``).
CHUNK = 2048


@jit()
def _cell(c, raw, s0, n, x, is_log, extrapolate, w, k):
    """Cell index along one axis; writes the weights ``w0, w1, g0, g1`` into
    ``w[k, 0..3]`` (order: value lo, slope lo, value hi, slope hi)."""
    if n == 1:
        w[k, 0] = 1.0
        w[k, 1] = 0.0
        w[k, 2] = 0.0
        w[k, 3] = 0.0
        return 0
    lo = raw[s0]
    hi = raw[s0 + n - 1]
    if not extrapolate:
        if x < lo:
            x = lo
        elif x > hi:
            x = hi
    u = math.log(x) if is_log else x
    # i0 = searchsorted(c, u, side="right") - 1, clipped to [0, n - 2]
    left = 0
    right = n
    while left < right:
        mid = (left + right) // 2
        if c[s0 + mid] <= u:
            left = mid + 1
        else:
            right = mid
    i0 = left - 1
    if i0 < 0:
        i0 = 0
    elif i0 > n - 2:
        i0 = n - 2
    a = c[s0 + i0]
    b = c[s0 + i0 + 1]
    h = b - a
    t = (u - a) / h
    if t < 0.0:
        t = 0.0
    elif t > 1.0:
        t = 1.0
    r0 = raw[s0 + i0]
    if abs(x - r0) <= NODE_RTOL * abs(r0) + NODE_ATOL:
        t = 0.0
    r1 = raw[s0 + i0 + 1]
    if abs(x - r1) <= NODE_RTOL * abs(r1) + NODE_ATOL:
        t = 1.0
    t2 = t * t
    t3 = t2 * t
    w0 = 2.0 * t3 - 3.0 * t2 + 1.0
    w1 = -2.0 * t3 + 3.0 * t2
    g0 = (t3 - 2.0 * t2 + t) * h
    g1 = (t3 - t2) * h
    if extrapolate:
        g0 += min(u - c[s0], 0.0)
        g1 += max(u - c[s0 + n - 1], 0.0)
    w[k, 0] = w0
    w[k, 1] = g0
    w[k, 2] = w1
    w[k, 3] = g1
    return i0


@jit(parallel=True)
def hermite_eval(points, is_log, coords, raw, start, strides, corner_offset, pair_corner,
                 pair_mask, data, bad, extrapolate, out):
    """Evaluate the tensor-product cubic Hermite interpolant at ``N`` points.

    Parameters
    ----------
    points : float64 (N, d), the points' raw coordinates (inside the grid unless
        ``extrapolate``; > 0 on a log axis: the caller checks)
    is_log : bool (d,), axis interpolated in ``log x``
    coords : float64 (sum n_k,), the node coordinates of every axis one after the other,
        on the interpolation scale (``log x`` on a log axis)
    raw : float64 (sum n_k,), the same nodes as raw values
    start : int64 (d + 1,), axis ``k``'s nodes are ``coords[start[k]:start[k + 1]]``
    strides : int64 (d,), flat node index = sum_k i_k strides[k]
    corner_offset : int64 (2**d,), flat index offset of corner ``c`` (bit k: the upper
        node along axis k; 0 along an axis with one node)
    pair_corner, pair_mask : int64 (4**d,), corner and derivative mask of term ``q``
        (base-4 digit k of ``q`` = 2 * corner bit k + mask bit k)
    data : float64 (n_nodes, 2**d, n_out), per node and mask the derivative of each
        output (0 where unknown)
    bad : bool (n_nodes, 2**d), derivative unknown (a failed node): NaN where it carries weight
    extrapolate : bool, continue linearly beyond the end nodes
    out : float64 (N, n_out), written row by row
    """
    n_points = points.shape[0]
    d = points.shape[1]
    n_out = data.shape[2]
    n_terms = pair_corner.shape[0]
    n_chunks = (n_points + CHUNK - 1) // CHUNK
    for chunk in prange(n_chunks):
        w = np.empty((d, 4))
        W = np.empty(n_terms)
        acc = np.empty(n_out)
        stop = min((chunk + 1) * CHUNK, n_points)
        for p in range(chunk * CHUNK, stop):
            base = 0
            for k in range(d):
                s0 = start[k]
                i0 = _cell(coords, raw, s0, start[k + 1] - s0, points[p, k], is_log[k],
                           extrapolate, w, k)
                base += i0 * strides[k]
            # tensor product of the per-axis weights, axis 0 innermost
            W[0] = 1.0
            size = 1
            for k in range(d):
                for j in range(3, -1, -1):
                    wk = w[k, j]
                    for q in range(size):
                        W[j * size + q] = W[q] * wk
                size *= 4
            for j in range(n_out):
                acc[j] = 0.0
            failed = False
            for q in range(n_terms):
                wq = W[q]
                if wq == 0.0:
                    continue
                node = base + corner_offset[pair_corner[q]]
                m = pair_mask[q]
                if bad[node, m]:
                    failed = True
                for j in range(n_out):
                    acc[j] += wq * data[node, m, j]
            for j in range(n_out):
                out[p, j] = np.nan if failed else acc[j]


def term_tables(d: int) -> tuple[np.ndarray, np.ndarray]:
    """``(pair_corner, pair_mask)`` of the ``4**d`` terms of :func:`hermite_eval`."""
    q = np.arange(4 ** d, dtype=np.int64)
    corner = np.zeros_like(q)
    mask = np.zeros_like(q)
    for k in range(d):
        digit = (q // 4 ** k) % 4
        corner |= (digit >> 1) << k
        mask |= (digit & 1) << k
    return corner, mask
