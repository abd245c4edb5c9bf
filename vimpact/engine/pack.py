"""Scene columns to kernel arrays (kernel units), and the kernel calls.

Units (:mod:`vimpact.kernels.elements`): times in units of ``T = d / v_z0``,
moduli relative to ``G_inf``, lengths in ``d`` (normal) and ``a_H``
(positions); tangential quantities in units of ``v_c0``.
"""

from __future__ import annotations

import numpy as np

from vimpact.engine import discretization
from vimpact.engine.columns import SceneColumns
from vimpact.engine.routing import CONTINUUM_STICK, Path
from vimpact.kernels import continuum_kv, continuum_maxwell, layout
from vimpact.kernels.elements import KernelSpec, element_impact, element_kernel
from vimpact.model.numerics import Numerics

#: Accepted steps of the adaptive continuum path at most (it needs tens to hundreds).
CONTINUUM_MAX_STEPS = 1_000_000
#: Accepted steps of the full-stick continuum kernel at most (tens to thousands;
#: beyond, the element path takes the row).
CONTINUUM_STICK_MAX_STEPS = 200_000
#: Rows of the full-stick continuum path up to which a batch runs the serial impact
#: kernel row by row instead of the parallel batch kernel: continuum rows take tens to
#: hundreds of microseconds, so a parallel launch gains at most a few ms there, and a
#: small run (a first command, a small sweep) does not compile the batch kernel, about
#: 10 s of CPU on an empty cache (its parallel loop optimizes the whole impact kernel
#: once more). The same kernel computes every row either way: the same numbers.
CONTINUUM_STICK_SERIAL_ROWS = 16


def arm_arrays(cols: SceneColumns, keep: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the arms in kernel units, the real arms of a row first, and their count.

    ``g = G_i / G_inf``, ``tau = tau_i / T`` as ``(n, max_arms)`` with the real arms of
    a row first, and their count ``n_arms`` (``keep=False``: no arms at all).
    """
    n = len(cols)
    if not keep or not cols.G_arm.shape[1]:  # (no arm column: no reduction to pay for)
        return np.zeros((n, 0)), np.zeros((n, 0)), np.zeros(n, dtype=np.int64)
    real = cols.G_arm > 0.0
    n_arms = real.sum(axis=1).astype(np.int64)
    width = int(n_arms.max(initial=0))
    if not width:
        return np.zeros((n, 0)), np.zeros((n, 0)), np.zeros(n, dtype=np.int64)
    order = np.argsort(~real, axis=1, kind="stable")[:, :width]  # real arms first
    g = np.take_along_axis(cols.G_arm, order, axis=1) / cols.G_inf[:, None]
    tau = np.take_along_axis(cols.tau_arm, order, axis=1) / cols.T[:, None]
    tau = np.where(np.take_along_axis(real, order, axis=1), tau, 1.0)
    return np.ascontiguousarray(g), np.ascontiguousarray(tau), n_arms


def element_arrays(cols: SceneColumns, numerics: Numerics, spec: KernelSpec) -> dict[str, np.ndarray]:
    """Kernel inputs of ``cols`` (all rows on the element kernel ``spec``) as arrays.

    ``tau0`` dashpot time, ``g``/``tau`` the arms (``(n, max_arms)``, the real
    arms of a row first, ``n_arms`` of them), ``kappa``, ``mu_t`` contact-point
    mass factor, ``mu`` friction in tangential units (``mu v_z0 / |v_c0|``; ``inf``
    for a spec without friction),
    ``h`` step, ``n_elem``/``dxi`` the half row, ``max_steps`` the time limit.
    """
    g, tau, n_arms = arm_arrays(cols, spec.arms)
    if spec.friction:
        with np.errstate(divide="ignore"):
            mu = np.where(np.isfinite(cols.mu), cols.mu * cols.v_z0 / np.abs(cols.v_c0), np.inf)
    else:  # full stick (a finite mu of these rows is below rounding: routing.friction_rows);
        mu = np.full(len(cols), np.inf)  # a kernel that takes friction from the row sticks
    a = {
        "tau0": cols.dashpot_time / cols.T,
        "g": g,
        "tau": tau,
        "n_arms": n_arms,
        "kappa": cols.kappa,
        "mu_t": cols.contact_mass_factor,
        "mu": mu,
    }
    a.update(discretization.element_row(cols, numerics, bool(spec.tangential), spec.integrator))
    return a


def run_path(path: Path, cols: SceneColumns, numerics: Numerics, rec: np.ndarray,
             rec_every: int, out: np.ndarray, arrays: dict | None = None) -> None:
    """Run the rows ``cols`` on the kernel of ``path``.

    Run the rows ``cols`` on ``path``, results into ``out`` (``(n, N_OUT)``) and
    the trajectory buffer ``rec`` (``(n, n_rec, N_REC)``; ``n_rec`` may be 0).
    ``arrays``: the element-kernel inputs if already made (:func:`element_arrays`).
    """
    if path.kind == CONTINUUM_STICK:
        g, tau, n_arms = arm_arrays(cols)
        args = (cols.dashpot_time / cols.T, g, tau, n_arms, cols.kappa, cols.contact_mass_factor,
                cols.computes_tangential)
        # few rows (a single simulate()): the impact kernel itself, whose cold compile
        # is about half that of the parallel batch kernel
        if rec.shape[1] == 0 and len(cols) > CONTINUUM_STICK_SERIAL_ROWS:
            continuum_maxwell.maxwell_stick_batch(*args, numerics.rtol, CONTINUUM_STICK_MAX_STEPS,
                                                  out)
            return
        for i in range(len(cols)):
            k = n_arms[i]
            out[i, layout.OUT_N_REC] = continuum_maxwell.maxwell_stick_impact(
                args[0][i], g[i, :k], tau[i, :k], args[4][i], args[5][i], args[6][i],
                numerics.rtol, CONTINUUM_STICK_MAX_STEPS, rec[i], rec_every, out[i])
        return
    if path.spec is None:
        tau0 = cols.dashpot_time / cols.T
        if rec.shape[1] == 0 and len(cols) > 1:  # one row: the impact kernel (as above)
            continuum_kv.kv_normal_batch(tau0, numerics.rtol, CONTINUUM_MAX_STEPS, out)
            return
        for i in range(len(cols)):
            out[i, layout.OUT_N_REC] = continuum_kv.kv_normal_impact(
                tau0[i], numerics.rtol, CONTINUUM_MAX_STEPS, rec[i], rec_every, out[i])
        return
    a = arrays if arrays is not None else element_arrays(cols, numerics, path.spec)
    if len(cols) == 1:  # one row: the serial impact kernel (no parallel launch to compile)
        k = a["n_arms"][0]
        element_impact(path.spec)(a["tau0"][0], a["g"][0, :k], a["tau"][0, :k], a["kappa"][0],
                                  a["mu_t"][0], a["mu"][0], a["h"][0], a["n_elem"][0],
                                  a["dxi"][0], a["max_steps"][0], rec[0], rec_every, out[0])
        return
    element_kernel(path.spec)(a["tau0"], a["g"], a["tau"], a["n_arms"], a["kappa"], a["mu_t"],
                              a["mu"], a["h"], a["n_elem"], a["dxi"], a["max_steps"], rec,
                              rec_every, out)


def interleave(n: int, threads: int) -> np.ndarray:
    """Return a row order that gives every thread a mix of the rows.

    An order that hands every thread of a static ``prange`` split a mix of the
    rows (neighbouring rows of a grid cost alike).
    """
    return np.concatenate([np.arange(k, n, threads) for k in range(threads)])
