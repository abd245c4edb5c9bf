"""Run impacts: validated scenes in, kernel arrays through, results out.

Data flow (DESIGN.md): ``Scene`` -> dimensionless structure of arrays
(:func:`pack`) -> :func:`vimpact.core.impact.run_batch` -> result rows ->
:class:`ImpactResult` / ``DataFrame``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from .core import impact as kernel
from .hertz import HERTZ_TIME_FACTOR
from .numerics import Numerics
from .result import FINISHED, ImpactResult
from .scene import HALF_SPACE_LIMIT, TANGENTIAL_MEMORY, Scene
from .validation import require

_STATUS_NAMES = {
    kernel.STATUS_OK: "ok",
    kernel.STATUS_TIME_LIMIT: "time_limit",
    kernel.STATUS_ROW_EXCEEDED: "row_exceeded",
    kernel.STATUS_NON_FINITE: "non_finite",
}


class HalfSpaceError(ValueError):
    """The contact grew beyond the half-space limit ``a_max > 0.2 R``."""


def pack(scenes: Sequence[Scene], numerics: Numerics) -> dict[str, np.ndarray]:
    """Dimensionless kernel inputs of ``scenes`` as a structure of arrays.

    Times are in units of ``T``, moduli relative to ``G_inf`` (see
    :mod:`vimpact.core.impact`). ``max_steps`` is the per-impact time limit.
    """
    n = len(scenes)
    max_arms = max((len(s.material.arms) for s in scenes), default=0)
    a = {
        "tau0": np.zeros(n),
        "g": np.zeros((n, max_arms)),
        "tau": np.zeros((n, max_arms)),
        "n_arms": np.zeros(n, dtype=np.int64),
        "kappa": np.zeros(n),
        "mu_t": np.zeros(n),
        "tangential": np.zeros(n, dtype=np.bool_),
        "memory": np.zeros(n, dtype=np.int64),
        "max_steps": np.zeros(n, dtype=np.int64),
    }
    h = HERTZ_TIME_FACTOR / numerics.steps
    for i, s in enumerate(scenes):
        mat, T = s.material, s.hertz.T
        a["tau0"][i] = mat.dashpot_time / T
        for k, (G_k, tau_k) in enumerate(mat.arms):
            a["g"][i, k] = G_k / mat.G_inf
            a["tau"][i, k] = tau_k / T
        a["n_arms"][i] = len(mat.arms)
        a["kappa"][i] = 2.0 * (1.0 - mat.nu) / (2.0 - mat.nu)
        a["mu_t"][i] = s.contact_mass_factor
        a["tangential"][i] = s.v_c0 != 0.0
        a["memory"][i] = TANGENTIAL_MEMORY.index(s.tangential_memory)
        # slow creep back: the dashpot time, or the viscous time g tau of the arms
        viscous = a["tau0"][i] + float(np.dot(a["g"][i], a["tau"][i]))
        limit = numerics.max_time * HERTZ_TIME_FACTOR * (1.0 + min(10.0 * viscous, 1e4))
        a["max_steps"][i] = int(math.ceil(limit / h))
    return a


def _grid(numerics: Numerics) -> tuple[float, int, float]:
    """Time step / T, number of elements on the half row, spacing / a_H."""
    dxi = 1.0 / numerics.elements
    n_elem = int(math.ceil(numerics.row_width * numerics.elements))
    return HERTZ_TIME_FACTOR / numerics.steps, n_elem, dxi


def _result(s: Scene, row: np.ndarray, trajectory: pd.DataFrame | None = None) -> ImpactResult:
    """Physical outputs of one kernel result row."""
    hz = s.hertz
    status = _STATUS_NAMES[int(row[kernel.OUT_STATUS])]
    nan = float("nan")
    if status == "ok":
        v_z_end = row[kernel.OUT_VZ_END] * s.v_z0
        vc_end = row[kernel.OUT_VC_END]  # / v_c0
        v_x_end, omega_end = s.tangential_end_state(vc_end)
        energy = 0.5 * (s.m * (v_z_end**2 + v_x_end**2) + s.Theta * omega_end**2)
        e_x = abs(vc_end) if s.v_c0 != 0.0 else nan
        beta_x = -vc_end if s.v_c0 != 0.0 else nan
        values = dict(
            e_z=abs(v_z_end) / s.v_z0, e_x=e_x, beta_x=beta_x,
            t_contact=row[kernel.OUT_T_CONTACT] * hz.T,
            u_max=row[kernel.OUT_U_MAX] * hz.d,
            a_max=row[kernel.OUT_B_MAX] * hz.a_H,
            energy_ratio=energy / s.kinetic_energy,
            v_z_end=v_z_end, v_x_end=v_x_end, omega_end=omega_end,
        )
        values = {k: float(x) for k, x in values.items()}
        if values["a_max"] > HALF_SPACE_LIMIT * s.R:
            status = "half_space"
        elif s.v_c0 == 0.0:
            status = "vc0_zero"
    else:
        values = dict(e_z=nan, e_x=nan, beta_x=nan, t_contact=nan, u_max=nan, a_max=nan,
                      energy_ratio=nan, v_z_end=nan, v_x_end=nan, omega_end=nan)
    assert status in FINISHED or math.isnan(values["e_z"])
    return ImpactResult(t_hertz=hz.t_H, d_hertz=hz.d, a_hertz=hz.a_H, Q1=s.Q1, Q2=s.Q2,
                        nu=s.material.nu, status=status, trajectory=trajectory, **values)


def simulate(scene: Scene, numerics: Numerics | None = None, *,
             trajectory: bool = False) -> ImpactResult:
    """Simulate one impact.

    Parameters
    ----------
    scene : the impact
    numerics : discretization (default ``Numerics()``: about 1e-4 on e_z, e_x)
    trajectory : also record the time series (``ImpactResult.trajectory``,
        a DataFrame with columns ``t_s, u_z_m, v_z_m_s, v_x_m_s, omega_rad_s,
        F_z_N, F_x_N, a_m``; about 500 rows per Hertz time)

    Raises
    ------
    HalfSpaceError
        if the contact half-width exceeds ``0.2 R`` and the scene does not
        allow it (``Scene.allow_large_contact``).
    """
    numerics = numerics or Numerics()
    require("scene", scene, isinstance(scene, Scene), "a vimpact.Scene")
    a = pack([scene], numerics)
    h, n_elem, dxi = _grid(numerics)
    out = np.zeros(kernel.N_OUT)
    rec_every = max(1, numerics.steps // 500)
    n_rec = int(a["max_steps"][0] // rec_every + 2) if trajectory else 0
    rec = np.zeros((n_rec, kernel.N_REC))
    k = a["n_arms"][0]
    n_used = kernel.run_impact(
        a["tau0"][0], a["g"][0, :k], a["tau"][0, :k], a["kappa"][0], a["mu_t"][0],
        a["tangential"][0], a["memory"][0], numerics.integrator_code, h, n_elem, dxi,
        a["max_steps"][0], rec, rec_every, out)
    traj = _trajectory(scene, rec[:n_used]) if trajectory else None
    res = _result(scene, out, traj)
    if res.status == "half_space" and not scene.allow_large_contact:
        raise HalfSpaceError(
            f"a_max = {res.a_max:.4g} m is not allowed: must be <= 0.2 R = "
            f"{HALF_SPACE_LIMIT * scene.R:.4g} m (half-space model; allow_large_contact=True "
            "or --allow-large-contact accepts it)")
    return res


def _trajectory(s: Scene, rec: np.ndarray) -> pd.DataFrame:
    """Physical time series from kernel records."""
    hz = s.hertz
    vc = rec[:, kernel.REC_VC]
    v_x, omega = s.tangential_end_state(vc)
    force_n = s.m * s.v_z0 / hz.T
    force_t = s.m * s.v_c0 / hz.T
    return pd.DataFrame({
        "t_s": rec[:, kernel.REC_T] * hz.T,
        "u_z_m": rec[:, kernel.REC_U] * hz.d,
        "v_z_m_s": rec[:, kernel.REC_V] * s.v_z0,
        "v_x_m_s": v_x,
        "omega_rad_s": omega,
        "F_z_N": rec[:, kernel.REC_FZ] * force_n,
        "F_x_N": rec[:, kernel.REC_FX] * force_t,
        "a_m": rec[:, kernel.REC_B] * hz.a_H,
    })


def simulate_batch(scenes: Sequence[Scene], numerics: Numerics | None = None) -> pd.DataFrame:
    """Simulate many impacts in parallel (numba ``prange`` over scenes).

    Returns one row per scene with the columns of :class:`ImpactResult`
    (units in :data:`vimpact.result.UNITS`). A row that fails (half-space
    exceeded, time limit, ...) gets a status and NaN outputs; the others
    are unaffected. Nothing is raised for a single bad row.
    """
    numerics = numerics or Numerics()
    scenes = list(scenes)
    if not scenes:
        return pd.DataFrame(columns=list(ImpactResult.__dataclass_fields__)[:-1])
    a = pack(scenes, numerics)
    h, n_elem, dxi = _grid(numerics)
    out = np.zeros((len(scenes), kernel.N_OUT))
    kernel.run_batch(a["tau0"], a["g"], a["tau"], a["n_arms"], a["kappa"], a["mu_t"],
                     a["tangential"], a["memory"], numerics.integrator_code, h, n_elem, dxi,
                     a["max_steps"], out)
    return pd.DataFrame([_result(s, row).to_dict() for s, row in zip(scenes, out)])
