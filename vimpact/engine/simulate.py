"""Run impacts: validated scenes in, kernel arrays through, results out.

Data flow (DESIGN.md): ``Scene`` -> dimensionless structure of arrays
(:func:`pack`) -> :func:`vimpact.kernels.elements.run_batch` -> result rows ->
:class:`ImpactResult` / ``DataFrame``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from vimpact.kernels import continuum_kv as continuum
from vimpact.kernels import elements as kernel
from vimpact.kernels.elements import KernelSpec, element_kernel
from vimpact.model.hertz import HERTZ_TIME_FACTOR
from vimpact.model.numerics import Numerics
from vimpact.engine.routing import Path, choose_path, refinement
from vimpact.engine.result import FINISHED, ImpactResult
from vimpact.model.scene import HALF_SPACE_LIMIT, TANGENTIAL_MEMORY, Scene
from vimpact.model.validation import require

_STATUS_NAMES = {
    kernel.STATUS_OK: "ok",
    kernel.STATUS_TIME_LIMIT: "time_limit",
    kernel.STATUS_ROW_EXCEEDED: "row_exceeded",
    kernel.STATUS_NON_FINITE: "non_finite",
}


#: Energy a passive impact may gain from rounding and integration error
#: (relative); more is reported as status ``unstable``, never as a result.
#: Not applied to explicit Euler, which gains energy by construction (the
#: thesis's table 4.1 is that gain) and is kept only to reproduce the thesis.
PASSIVITY_SLACK = 1e-6

#: Accepted steps of the adaptive continuum path at most (it needs tens to hundreds).
CONTINUUM_MAX_STEPS = 1_000_000

#: Rows of a recorded trajectory at most (the last row always holds the end state).
MAX_TRAJECTORY_ROWS = 1_000_000


class HalfSpaceError(ValueError):
    """The contact grew beyond the half-space limit ``a_max > 0.2 R``."""


def pack(scenes: Sequence[Scene], numerics: Numerics, spec: KernelSpec) -> dict[str, np.ndarray]:
    """Dimensionless kernel inputs of ``scenes`` (all on the element kernel
    ``spec``) as a structure of arrays.

    Times are in units of ``T``, moduli relative to ``G_inf`` (see
    :mod:`vimpact.kernels.elements`). ``h`` is the time step of each scene and
    ``max_steps`` its time limit in steps; ``n_elem`` and ``dxi`` its half row
    (elements, spacing / a_H), refined for a glassy contact.
    """
    n = len(scenes)
    max_arms = max((len(s.material.arms) for s in scenes), default=0) if spec.arms else 0
    a = {
        "tau0": np.zeros(n),
        "g": np.zeros((n, max_arms)),
        "tau": np.zeros((n, max_arms)),
        "n_arms": np.zeros(n, dtype=np.int64),
        "kappa": np.zeros(n),
        "mu_t": np.zeros(n),
        "mu": np.full(n, np.inf),
        "h": np.zeros(n),
        "n_elem": np.zeros(n, dtype=np.int64),
        "dxi": np.zeros(n),
        "max_steps": np.zeros(n, dtype=np.int64),
    }
    for i, s in enumerate(scenes):
        mat, T = s.material, s.hertz.T
        a["tau0"][i] = mat.dashpot_time / T
        if spec.arms:
            for k, (G_k, tau_k) in enumerate(mat.arms):
                a["g"][i, k] = G_k / mat.G_inf
                a["tau"][i, k] = tau_k / T
            a["n_arms"][i] = len(mat.arms)
        a["kappa"][i] = mat.kappa
        a["mu_t"][i] = s.contact_mass_factor
        time_factor, element_factor = refinement(s, numerics, spec)
        a["h"][i] = HERTZ_TIME_FACTOR / numerics.steps / time_factor
        per_a_H = int(math.ceil(numerics.elements * element_factor))
        a["dxi"][i] = 1.0 / per_a_H
        a["n_elem"][i] = int(math.ceil(numerics.row_width * per_a_H))
        a["max_steps"][i] = int(math.ceil(_time_limit(s, numerics) / a["h"][i]))
    return a


def _time_limit(s: Scene, numerics: Numerics) -> float:
    """Time limit of an impact in units of ``T``: ``max_time`` Hertz times,
    stretched by the slow creep back of a viscous surface."""
    mat = s.material
    viscous = mat.dashpot_time + sum(G * tau for G, tau in mat.arms) / mat.G_inf  # s
    return numerics.max_time * HERTZ_TIME_FACTOR * (1.0 + min(10.0 * viscous / s.hertz.T, 1e4))


def run_kernels(scenes: Sequence[Scene], numerics: Numerics, n_rec: int = 0, rec_every: int = 1
                ) -> tuple[np.ndarray, np.ndarray, list[Path]]:
    """Run every scene on its path; rows grouped by kernel, one parallel call per group.

    Returns the kernel result rows ``(n, N_OUT)``, the trajectory buffer
    ``(n, n_rec, N_REC)`` and the :class:`Path` of each scene.
    """
    paths = [choose_path(s, numerics) for s in scenes]
    out = np.zeros((len(scenes), kernel.N_OUT))
    rec = np.zeros((len(scenes), n_rec, kernel.N_REC))
    groups: dict[KernelSpec | None, list[int]] = {}
    for i, p in enumerate(paths):
        groups.setdefault(p.spec, []).append(i)
    for spec, idx in groups.items():
        group = [scenes[i] for i in idx]
        sub_out = np.zeros((len(idx), kernel.N_OUT))
        sub_rec = np.zeros((len(idx), n_rec, kernel.N_REC))
        if spec is None:
            _run_continuum(group, numerics, sub_rec, rec_every, sub_out)
        else:
            a = pack(group, numerics, spec)
            element_kernel(spec)(a["tau0"], a["g"], a["tau"], a["n_arms"], a["kappa"], a["mu_t"],
                                 a["mu"], a["h"], a["n_elem"], a["dxi"], a["max_steps"], sub_rec,
                                 rec_every, sub_out)
        out[idx] = sub_out
        rec[idx] = sub_rec
    return out, rec, paths


def _run_continuum(scenes: Sequence[Scene], numerics: Numerics, rec: np.ndarray,
                   rec_every: int, out: np.ndarray) -> None:
    """The Kelvin-Voigt/elastic normal-only scenes on the continuum 1-DOF path."""
    tau0 = np.array([s.material.dashpot_time / s.hertz.T for s in scenes])
    if rec.shape[1] == 0:
        continuum.kv_normal_batch(tau0, numerics.rtol, CONTINUUM_MAX_STEPS, out)
        return
    for i in range(len(scenes)):
        out[i, kernel.OUT_N_REC] = continuum.kv_normal_impact(
            tau0[i], numerics.rtol, CONTINUUM_MAX_STEPS, rec[i], rec_every, out[i])


def _result(s: Scene, row: np.ndarray, path: Path,
            trajectory: pd.DataFrame | None = None) -> ImpactResult:
    """Physical outputs of one kernel result row."""
    hz = s.hertz
    status = _STATUS_NAMES[int(row[kernel.OUT_STATUS])]
    nan = float("nan")
    if status == "ok":
        v_z_end = row[kernel.OUT_VZ_END] * s.v_z0
        vc_end = row[kernel.OUT_VC_END] if s.computes_tangential else 1.0  # / v_c0
        v_x_end, omega_end = s.tangential_end_state(vc_end)
        energy = 0.5 * (s.m * (v_z_end**2 + v_x_end**2) + s.Theta * omega_end**2)
        e_x = abs(vc_end) if s.computes_tangential else nan
        beta_x = -vc_end if s.computes_tangential else nan
        values = dict(
            e_z=abs(v_z_end) / s.v_z0, e_x=e_x, beta_x=beta_x,
            t_contact=row[kernel.OUT_T_CONTACT] * hz.T,
            u_max=row[kernel.OUT_U_MAX] * hz.d,
            a_max=row[kernel.OUT_B_MAX] * hz.a_H,
            energy_ratio=energy / s.kinetic_energy,
            v_z_end=v_z_end, v_x_end=v_x_end, omega_end=omega_end,
        )
        values = {k: float(x) for k, x in values.items()}
        if (values["energy_ratio"] > 1.0 + PASSIVITY_SLACK and s.tangential_memory == "incremental"
                and (path.spec is None or path.spec.integrator != kernel.EULER)):
            status = "unstable"  # a passive model cannot gain energy: numerical garbage
            values = dict.fromkeys(values, nan)
        elif values["a_max"] > HALF_SPACE_LIMIT * s.R:
            status = "half_space"
        elif s.tangential == "none":
            status = "normal_only"
        elif s.v_c0 == 0.0:
            status = "vc0_zero"
    else:
        values = dict(e_z=nan, e_x=nan, beta_x=nan, t_contact=nan, u_max=nan, a_max=nan,
                      energy_ratio=nan, v_z_end=nan, v_x_end=nan, omega_end=nan)
    assert status in FINISHED or math.isnan(values["e_z"])
    return ImpactResult(t_hertz=hz.t_H, d_hertz=hz.d, a_hertz=hz.a_H, Q1=s.Q1, Q2=s.Q2,
                        nu=s.material.nu, status=status, n_steps=int(row[kernel.OUT_STEPS]),
                        path=path.name, trajectory=trajectory, **values)


def simulate(scene: Scene, numerics: Numerics | None = None, *,
             trajectory: bool = False) -> ImpactResult:
    """Simulate one impact.

    Parameters
    ----------
    scene : the impact
    numerics : discretization (default ``Numerics()``: about 1e-4 on e_z, e_x)
    trajectory : also record the time series (``ImpactResult.trajectory``,
        a DataFrame with columns ``t_s, u_z_m, v_z_m_s, v_x_m_s, omega_rad_s,
        F_z_N, F_x_N, a_m``; about 500 rows per Hertz time on the element
        path, one row per accepted step on the continuum path)

    Raises
    ------
    HalfSpaceError
        if the contact half-width exceeds ``0.2 R`` and the scene does not
        allow it (``Scene.allow_large_contact``).
    """
    numerics = numerics or Numerics()
    require("scene", scene, isinstance(scene, Scene), "a vimpact.Scene")
    n_rec, rec_every = 0, 1
    if trajectory:  # about 500 rows per Hertz time, at most MAX_TRAJECTORY_ROWS
        path = choose_path(scene, numerics)
        if path.spec is None:
            n_rec = 100_000  # one row per accepted ODE step
        else:
            per_t_H = numerics.steps * refinement(scene, numerics, path.spec)[0]
            rec_every = max(1, int(per_t_H) // 500)
            max_steps = _time_limit(scene, numerics) / HERTZ_TIME_FACTOR * per_t_H
            n_rec = int(max_steps // rec_every) + 2
        n_rec = min(n_rec, MAX_TRAJECTORY_ROWS)
    out, rec, paths = run_kernels([scene], numerics, n_rec, rec_every)
    traj = _trajectory(scene, rec[0, :int(out[0, kernel.OUT_N_REC])]) if trajectory else None
    res = _result(scene, out[0], paths[0], traj)
    if res.status == "half_space" and not scene.allow_large_contact:
        raise HalfSpaceError(
            f"a_max = {res.a_max:.4g} m is not allowed: must be <= 0.2 R = "
            f"{HALF_SPACE_LIMIT * scene.R:.4g} m (half-space model; allow_large_contact=True "
            "or --allow-large-contact accepts it)")
    return res


def explain(scene: Scene, numerics: Numerics | None = None) -> str:
    """Which kernel :func:`simulate` runs for ``scene`` and why (text, several lines)."""
    return choose_path(scene, numerics or Numerics()).explain()


def _trajectory(s: Scene, rec: np.ndarray) -> pd.DataFrame:
    """Physical time series from kernel records."""
    hz = s.hertz
    vc = rec[:, kernel.REC_VC] if s.computes_tangential else np.ones(len(rec))
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

    Scenes are grouped by the kernel their effects call for
    (:func:`vimpact.engine.routing.choose_path`), one parallel call per group.
    Returns one row per scene, in order, with the columns of
    :class:`ImpactResult` (units in :data:`vimpact.engine.result.UNITS`). A row that
    fails (half-space exceeded, time limit, ...) gets a status and NaN
    outputs; the others are unaffected. Nothing is raised for a single bad row.
    """
    numerics = numerics or Numerics()
    scenes = list(scenes)
    if not scenes:
        return pd.DataFrame(columns=list(ImpactResult.__dataclass_fields__)[:-1])
    out, _, paths = run_kernels(scenes, numerics)
    return pd.DataFrame([_result(s, row, p).to_dict() for s, row, p in zip(scenes, out, paths)])
