"""Layouts shared by every kernel: integrator codes, status codes, the columns
of the per-impact output row and of a trajectory record, and the record writer.

Kernel units are described in :mod:`vimpact.kernels.elements`. Everything here
is plain numbers and one ``@jit`` helper; nothing imports the API side.
"""

from __future__ import annotations

from vimpact.kernels.jit import jit

EULER = 0
SYMPLECTIC_EULER = 1
VERLET = 2

# status codes written to OUT_STATUS
STATUS_OK = 0
STATUS_TIME_LIMIT = 1
STATUS_ROW_EXCEEDED = 2
STATUS_NON_FINITE = 3
# a continuum kernel met a scene outside its assumptions (the element path takes it over)
STATUS_ASSUMPTION = 4

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


@jit()
def _record(rec, i, t, u, v, vc, Fz, Fx, b):
    """Write one trajectory row if there is room; return the next row index."""
    if i >= rec.shape[0]:
        return i
    rec[i, REC_T] = t
    rec[i, REC_U] = u
    rec[i, REC_V] = v
    rec[i, REC_VC] = vc
    rec[i, REC_FZ] = Fz
    rec[i, REC_FX] = Fx
    rec[i, REC_B] = b
    return i + 1


