"""Lookup on an adaptive (non-tensor) table: a 2**k-tree of cells (numba kernel).

The table's adaptive axes (``k`` = 1 or 2, the logarithms of the damping
parameters) are mapped onto the unit square, ``u = (log x - lo) / (hi - lo)``.
The root cell is the whole square; a cell of level ``L`` with integer index
``(i_0, ..., i_k-1)`` covers ``[i_d / 2**L, (i_d + 1) / 2**L]`` along axis ``d``
and is either a leaf or split into its ``2**k`` halves (child number: bit ``d``
set = upper half along axis ``d``). A leaf carries its own ``4**k`` nodes at
``t = 0, 1/3, 2/3, 1`` of the cell along every axis (node ``a_0 + 4 a_1``)
and is interpolated by the tensor-product cubic Lagrange polynomial through
them; across the optional tensor axis (``nu``: the same node values at every
point) the four nodes around the point give a cubic Lagrange polynomial too
(all nodes when there are fewer than four).

Everything here is plain arrays; nothing imports the API side.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from vimpact.kernels.jit import jit

#: Points per parallel work item.
CHUNK = 2048


@jit(inline="always")
def _lagrange_thirds(t, w):
    """Cubic Lagrange weights of the nodes ``0, 1/3, 2/3, 1`` at ``t`` into ``w[0:4]``."""
    a = t - 1.0 / 3.0
    b = t - 2.0 / 3.0
    c = t - 1.0
    w[0] = -4.5 * a * b * c
    w[1] = 13.5 * t * b * c
    w[2] = -13.5 * t * a * c
    w[3] = 4.5 * t * a * b


@jit(inline="always")
def _tensor_weights(nodes, x, w):
    """Return ``(first, count)`` of the local stencil on the tensor axis; its weights go to ``w``.

    ``first`` is the stencil's first node, ``w`` receives its Lagrange weights; a
    single node has weight 1.
    """
    n = nodes.shape[0]
    if n == 1:
        w[0] = 1.0
        return 0, 1
    m = 4 if n >= 4 else n
    i = 0
    while i < n - 2 and x >= nodes[i + 1]:
        i += 1
    s = i - 1
    if s < 0:
        s = 0
    if s > n - m:
        s = n - m
    for j in range(m):
        p = 1.0
        for q in range(m):
            if q != j:
                p *= (x - nodes[s + q]) / (nodes[s + j] - nodes[s + q])
        w[j] = p
    return s, m


@jit(inline="always")
def _eval_point(p, k, lo, hi, child, leaf_of, leaf_nodes, tnodes, values, out_row,
                u, idx, wa, wt):
    """Write the interpolated outputs at one point ``p`` into ``out_row``.

    ``p`` holds the adaptive coordinates, then the tensor one; ``u``, ``idx``,
    ``wa``, ``wt`` are scratch arrays of the work item.
    """
    n_out = values.shape[2]
    for d in range(k):
        idx[d] = 0
        v = (np.log(p[d]) - lo[d]) / (hi[d] - lo[d])
        if v < 0.0:
            v = 0.0
        if v > 1.0:
            v = 1.0
        u[d] = v
    cell = 0
    scale = 1.0  # 2**level
    while leaf_of[cell] < 0:
        c = 0
        for d in range(k):
            upper = u[d] * (2.0 * scale) >= 2 * idx[d] + 1
            idx[d] = 2 * idx[d] + (1 if upper else 0)
            if upper:
                c |= 1 << d
        cell = child[cell, c]
        scale *= 2.0
    leaf = leaf_of[cell]
    for d in range(k):
        t = u[d] * scale - idx[d]
        if t < 0.0:
            t = 0.0
        if t > 1.0:
            t = 1.0
        _lagrange_thirds(t, wa[d])
    x_t = p[k] if p.shape[0] > k else 0.0
    s, m = _tensor_weights(tnodes, x_t, wt)
    for j in range(n_out):
        out_row[j] = 0.0
    n_local = 4 ** k
    for a in range(n_local):
        w = wa[0, a % 4]
        if k == 2:
            w *= wa[1, a // 4]
        row = leaf_nodes[leaf, a]
        for q in range(m):
            ww = w * wt[q]
            for j in range(n_out):
                out_row[j] += ww * values[row, s + q, j]


@jit(parallel=True)
def adaptive_eval(points, k, lo, hi, child, leaf_of, leaf_nodes, tnodes, values, out):
    """Interpolate an adaptive table at many points.

    Parameters
    ----------
    points : (n, k + t) float64, raw coordinates (``Q1``, ``Q2``, then ``nu``), inside
        the table (the caller checks the range; outside, the point is clamped)
    k : number of adaptive (log) axes, 1 or 2
    lo, hi : (k,) natural logarithms of the adaptive axes' ends
    child : (n_cells, 2**k) int64, the children of each cell (-1: none)
    leaf_of : (n_cells,) int64, leaf number of a cell, -1 for a split cell
    leaf_nodes : (n_leaves, 4**k) int64, the node (row of ``values``) of each leaf node
    tnodes : (n_t,) float64, the increasing nodes of the tensor axis (one node: none)
    values : (n_nodes, n_t, n_out) float64, outputs at the nodes (NaN: a failed impact,
        which makes every lookup using it NaN)
    out : (n, n_out) float64, written
    """
    n = points.shape[0]
    n_chunks = (n + CHUNK - 1) // CHUNK
    for c in prange(n_chunks):
        u = np.empty(2)
        idx = np.zeros(2, dtype=np.int64)
        wa = np.empty((2, 4))
        wt = np.empty(4)
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            _eval_point(points[i], k, lo, hi, child, leaf_of, leaf_nodes, tnodes, values,
                        out[i], u, idx, wa, wt)
