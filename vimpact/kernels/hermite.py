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
#: (the point gets that node's values exactly): the numbers of
#: ``vimpact.lookup.interpolate.NODE_RTOL`` / ``NODE_ATOL``, written out here because
#: kernels import numpy and numba only (``tests/lookup/test_node_tolerance.py``).
NODE_RTOL = 1e-9
NODE_ATOL = 1e-12
#: Points per parallel work item (each item evaluates its own rows of ``out``).
CHUNK = 2048


@jit()
def _cell(c, raw, s0, n, x, is_log, extrapolate, w, k):
    """Return the cell index of ``x`` along one axis; write its basis weights into ``w[k]``.

    The weights ``w0, w1, g0, g1`` go to ``w[k, 0..3]`` in the order value lo,
    slope lo, value hi, slope hi.
    """
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
def hermite_eval(points, is_log, coords, raw, start, strides, corner_offset, data, bad,
                 node_bad, n_out, extrapolate, out):
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
    data : float64 (n_nodes, 2**d, 4 * ceil(n_out / 4)), per node and derivative mask
        ``m`` (bit k: differentiated along axis k) the derivative of each output (0 where
        unknown, and in the padding columns)
    bad : bool (n_nodes, 2**d), derivative unknown (a failed node): NaN where it carries weight
    node_bad : bool (n_nodes,), some derivative of the node unknown
    n_out : number of outputs (columns of ``out``)
    extrapolate : bool, continue linearly beyond the end nodes
    out : float64 (N, n_out), written row by row

    The outputs are summed four at a time in scalars (the padding of ``data``), which
    the compiler keeps in registers: twice as fast as an accumulator array.
    """
    n_points = points.shape[0]
    d = points.shape[1]
    n_blocks = data.shape[2] // 4
    nc = corner_offset.shape[0]
    n_chunks = (n_points + CHUNK - 1) // CHUNK
    for chunk in prange(n_chunks):
        w = np.empty((d, 4))
        V = np.empty(nc)
        stop = min((chunk + 1) * CHUNK, n_points)
        for p in range(chunk * CHUNK, stop):
            base = 0
            for k in range(d):
                s0 = start[k]
                i0 = _cell(coords, raw, s0, start[k + 1] - s0, points[p, k], is_log[k],
                           extrapolate, w, k)
                base += i0 * strides[k]
            failed = False
            for block in range(n_blocks):
                j = 4 * block
                a0 = 0.0
                a1 = 0.0
                a2 = 0.0
                a3 = 0.0
                for c in range(nc):
                    # weights of the 2**d derivatives at corner c: tensor product over the
                    # axes of (value weight, slope weight) at its lower or upper node
                    V[0] = 1.0
                    size = 1
                    for k in range(d):
                        hi = 2 * ((c >> k) & 1)
                        wv = w[k, hi]
                        ws = w[k, hi + 1]
                        for q in range(size):
                            V[size + q] = V[q] * ws
                            V[q] = V[q] * wv
                        size *= 2
                    node = base + corner_offset[c]
                    if block == 0 and node_bad[node]:
                        for m in range(nc):
                            if bad[node, m] and V[m] != 0.0:
                                failed = True
                    for m in range(nc):
                        vm = V[m]
                        a0 += vm * data[node, m, j]
                        a1 += vm * data[node, m, j + 1]
                        a2 += vm * data[node, m, j + 2]
                        a3 += vm * data[node, m, j + 3]
                out[p, j] = a0
                if j + 1 < n_out:
                    out[p, j + 1] = a1
                if j + 2 < n_out:
                    out[p, j + 2] = a2
                if j + 3 < n_out:
                    out[p, j + 3] = a3
            if failed:
                for j in range(n_out):
                    out[p, j] = np.nan
