"""The trajectory record writer shared by every kernel (columns: :mod:`vimpact.kernels.layout`)."""

from __future__ import annotations

from vimpact.kernels.jit import jit
from vimpact.kernels.layout import REC_B, REC_FX, REC_FZ, REC_T, REC_U, REC_V, REC_VC


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


