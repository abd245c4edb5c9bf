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

# The per-point functions (_eval_point, hyman_eval, _hyman_slope) are compiled as
# functions of their own, not inlined into numba's IR at every call site: inlined,
# friction_eval took twice as long to compile (a first friction-table lookup 11.9 s of
# CPU against 5.9 s on an empty cache), and the lookups run as fast (1e6 points, one
# thread, alternating: the same CPU time within the run-to-run spread, bit for bit equal).


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


@jit()
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


@jit()
def _hyman_slope(x, y, i, first, last):
    """Return the slope at node ``i`` of the shape-preserving cubic through ``y(x)``.

    The cubic Hermite interpolant on the nodes ``first .. last`` (one segment between
    two kinks; nothing across them).

    The three-point (parabola) slope, third-order accurate; where the nodes are monotone
    over the two intervals on each side of ``i`` it is limited to ``3 min(|s_left|,
    |s_right|)`` with their sign (Hyman's filter, the Fritsch-Carlson condition), so the
    interpolant is monotone between monotone nodes and cannot swing past them (equal
    neighbours count as monotone either way: a flat stretch stays flat). Near a
    maximum or minimum of the nodes the slope is left free: the interpolant follows the
    curvature there instead of flattening at the largest node. Segment ends take the
    one-sided three-point slope, kept to the sign of the end interval and at most three
    times its secant.
    """
    if last - first == 1:
        return (y[last] - y[first]) / (x[last] - x[first])
    if i == first or i == last:
        j = first if i == first else last - 1  # the end interval
        k = first + 1 if i == first else last - 2  # its neighbour
        h = x[j + 1] - x[j]
        h2 = x[k + 1] - x[k]
        s = (y[j + 1] - y[j]) / h
        s2 = (y[k + 1] - y[k]) / h2
        d = ((2.0 * h + h2) * s - h * s2) / (h + h2)
        if d * s <= 0.0:
            return 0.0
        if abs(d) > 3.0 * abs(s):
            return 3.0 * s
        return d
    h0 = x[i] - x[i - 1]
    h1 = x[i + 1] - x[i]
    s0 = (y[i] - y[i - 1]) / h0
    s1 = (y[i + 1] - y[i]) / h1
    d = (s0 * h1 + s1 * h0) / (h0 + h1)
    a = i - 2 if i - 2 >= first else first
    b = i + 2 if i + 2 <= last else last
    up = True
    down = True
    for j in range(a, b):
        sj = y[j + 1] - y[j]
        if sj < 0.0:
            up = False
        if sj > 0.0:
            down = False
    if up or down:
        m = 3.0 * min(abs(s0), abs(s1))
        if d * s1 <= 0.0:
            return 0.0
        if abs(d) > m:
            return m if s1 > 0.0 else -m
    return d


@jit()
def hyman_eval(x, y, kinks, xq):
    """Return the shape-preserving cubic Hermite interpolant of ``y(x)`` at ``xq``.

    See :func:`_hyman_slope`. ``kinks`` are the node indices where the curve may have a
    kink (the first and last node included): each segment between two is interpolated
    on its own. ``xq`` is clamped to ``[x[0], x[-1]]``.
    """
    n = x.shape[0]
    if xq <= x[0]:
        return y[0]
    if xq >= x[n - 1]:
        return y[n - 1]
    i = 0
    while i < n - 2 and xq >= x[i + 1]:
        i += 1
    s = 0
    while s < kinks.shape[0] - 2 and i >= kinks[s + 1]:
        s += 1
    first = kinks[s]
    last = kinks[s + 1]
    h = x[i + 1] - x[i]
    t = (xq - x[i]) / h
    d0 = _hyman_slope(x, y, i, first, last)
    d1 = _hyman_slope(x, y, i + 1, first, last)
    return ((1.0 + 2.0 * t) * (1.0 - t) ** 2 * y[i] + t * (1.0 - t) ** 2 * h * d0
            + t * t * (3.0 - 2.0 * t) * y[i + 1] + t * t * (t - 1.0) * h * d1)


@jit(parallel=True)
def friction_eval(points, k, lo, hi, child, leaf_of, leaf_nodes, tnodes, values, chi,
                  unodes, kinks, psi_stick, out):
    """Interpolate a friction table (``e_z`` and ``beta_x`` over ``Q1``, ``nu``, ``psi``).

    The adaptive part (``Q1`` cells, ``nu`` tensor nodes) carries, per node, ``e_z``,
    the ratio ``r = psi_s / psi_g`` of the start of gross slip throughout to the
    closed form's zero, and ``beta_x`` at the incidence coordinates ``unodes``; it is
    interpolated to the point like :func:`adaptive_eval`. Then, with
    ``psi_g = 2 chi (1 + e_z)`` and ``psi_s = r psi_g``: at ``psi >= psi_s`` the contact
    slips throughout and ``beta_x = -1 + psi_g / psi`` (closed form); below, ``beta_x``
    is :func:`hyman_eval` over the coordinate ``u = psi / psi_stick`` (``psi <=
    psi_stick``) or ``u = 1 + (psi - psi_stick) / (psi_s - psi_stick)`` (up to
    ``u = 2`` at ``psi_s``), which puts both kinks at fixed ``u = 1`` and ``u = 2``.
    The value at ``u = 2`` is the closed form there, ``-1 + 1 / r`` (what the table's
    nodes hold, to rounding), so ``beta_x`` is continuous at ``psi_s``.

    Parameters
    ----------
    points : (n, 3) float64: ``Q1``, ``nu``, ``psi`` (inside the table: the caller checks)
    k, lo, hi, child, leaf_of, leaf_nodes, tnodes : as for :func:`adaptive_eval` (``k = 1``)
    values : (n_nodes, n_t, 2 + n_u) float64: ``e_z``, ``r``, ``beta_x`` at ``unodes``
    chi : (n,) float64, ``(1 - nu)(1 + m R^2 / Theta)/(2 - nu)`` of each point
    unodes : (n_u,) float64, increasing incidence coordinates from 0 to 2
    kinks : int64 indices into ``unodes`` of ``u = 0, 1, 2``
    psi_stick : the incidence of the first kink (where the contact starts to slip at the
        first instant: ``psi = 1``)
    out : (n, 2) float64, written: ``e_z``, ``beta_x``
    """
    n = points.shape[0]
    n_out = values.shape[2]
    n_chunks = (n + CHUNK - 1) // CHUNK
    for c in prange(n_chunks):
        u = np.empty(2)
        idx = np.zeros(2, dtype=np.int64)
        wa = np.empty((2, 4))
        wt = np.empty(4)
        row = np.empty(n_out)
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            _eval_point(points[i], k, lo, hi, child, leaf_of, leaf_nodes, tnodes, values,
                        row, u, idx, wa, wt)
            # at psi_s the contact slips throughout: the last node is the closed form there
            # (as simulated at the table's nodes), so the two parts meet without a step
            row[n_out - 1] = -1.0 + 1.0 / row[1]
            e_z = row[0]
            psi = points[i, 2]
            psi_g = 2.0 * chi[i] * (1.0 + e_z)
            psi_s = row[1] * psi_g
            out[i, 0] = e_z
            if psi >= psi_s:
                out[i, 1] = -1.0 + psi_g / psi
            else:
                if psi <= psi_stick:
                    x = psi / psi_stick
                else:
                    x = 1.0 + (psi - psi_stick) / (psi_s - psi_stick)
                out[i, 1] = hyman_eval(unodes, row[2:], kinks, x)
