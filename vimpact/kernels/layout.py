"""Layouts shared by every kernel: integrator and status codes, output and record columns.

The columns are those of the per-impact output row and of a trajectory record.

Kernel units are described in :mod:`vimpact.kernels.elements`. Everything here
is plain numbers (no numba: the command line's parser and the value objects
read these codes without loading numba); the record writer is
:func:`vimpact.kernels.record._record`, which imports this module (not the
other way round). Nothing imports the API side.
"""

from __future__ import annotations

from vimpact.kernels.status import BY_CODE, code

EULER = 0
SYMPLECTIC_EULER = 1
VERLET = 2

# status codes written to OUT_STATUS: those of the status table
STATUS_OK = code("ok")
STATUS_TIME_LIMIT = code("time_limit")
STATUS_ROW_EXCEEDED = code("row_exceeded")
STATUS_NON_FINITE = code("non_finite")
# not a status of a result: a continuum kernel met a scene outside its assumptions (the
# engine hands the row to the element path); a code of its own, after the table's
STATUS_ASSUMPTION = max(BY_CODE) + 1

# columns of the per-impact output row
OUT_VZ_END = 0  # normal velocity at the end / v_z0 (negative: rebound)
OUT_VC_END = 1  # contact-point velocity at the end / v_c0
OUT_T_CONTACT = 2  # contact time / T
OUT_U_MAX = 3  # maximum indentation / d
OUT_B_MAX = 4  # maximum contact half-width / a_H
OUT_STATUS = 5
OUT_STEPS = 6  # time steps taken
OUT_N_REC = 7  # trajectory rows written
# Coulomb friction (element kernels with KernelSpec.friction; 0 in every other kernel):
OUT_T_GROSS_SLIP = 8  # time with gross slip (contact non-empty, every element in it slipping) / T
# energy dissipated by slip, sum over slipping elements of f_t * (slip increment),
# in units of m v_c0^2 (m the sphere's mass, v_c0 the initial contact-point speed);
# the tangential kinetic energy at the start is 1/2 m v_c0^2 / mu_t (mu_t = 1 + m R^2/Theta)
OUT_W_FRICTION = 9
N_OUT = 10

# columns of a trajectory record
REC_T, REC_U, REC_V, REC_VC, REC_FZ, REC_FX, REC_B = range(7)
# slip-zone width / a_H: slipping elements of the half row times their spacing
# (the annulus b - c of a stick core c); written by the element kernels after
# _record (0 without friction), left untouched by the continuum kernels
REC_SLIP = 7
N_REC = 8

#: Element stiffness per unit length in kernel units (both halves of the row counted by the caller).
ELEMENT_STIFFNESS = 15.0 / 16.0

