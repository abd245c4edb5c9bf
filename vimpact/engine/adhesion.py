"""Adhesive normal impacts (docs/physics.md#adhesion): one scene in, SI results out.

A scene with a work of adhesion ``Scene.adhesion > 0`` runs on the adhesive
element kernel (:mod:`vimpact.kernels.adhesion`), normal impact only. This
module makes its inputs (the adhesion number ``lam``, step and element row of
:mod:`vimpact.engine.discretization`), runs it, and gives

- :func:`simulate_adhesive`: an :class:`AdhesiveResult` (e_z, whether the
  sphere stuck, the largest tensile force, ...);
- :func:`sticking_velocity`: the impact speed below which the sphere sticks,
  by bisection;
- :func:`jkr_quasi_static`: the elastic element row under a prescribed
  indentation (the JKR curves ``F(d)``, ``a(d)`` as the row gives them);
- :func:`result_columns`: the adhesive rows of :func:`vimpact.simulate_batch`,
  run in parallel over the rows (:func:`run_kernel`), as its result columns.

Single scene and batch build their kernel inputs with one function
(:func:`kernel_inputs`), so a batch row equals :func:`vimpact.simulate` of its scene.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from vimpact.engine import discretization
from vimpact.engine.columns import SceneColumns
from vimpact.engine.pack import arm_arrays
from vimpact.engine.result import FINISHED, RESULT_FIELDS, STATUSES, ImpactResult
from vimpact.kernels import adhesion as kernel
from vimpact.kernels.layout import STATUS_ROW_EXCEEDED, VERLET
from vimpact.kernels.status import BY_CODE
from vimpact.model.hertz import effective_modulus, hertz_scales
from vimpact.model.numerics import Numerics
from vimpact.model.scene import HALF_SPACE_LIMIT, TANGENTIAL_EFFECTS, Scene
from vimpact.model.validation import InputError, message, positive, require

#: Path name of the adhesive kernel (``ImpactResult.path``, ``vimpact simulate --explain``).
PATH_NAME = "adhesion[verlet,normal]"
#: Times the half row is widened when the contact reaches its end, at most.
MAX_ROW_WIDENINGS = 6
#: Default relative tolerance of :func:`sticking_velocity` on the speed.
STICKING_RTOL = 1e-3


@dataclass(frozen=True)
class AdhesiveResult:
    """Outcome of one adhesive normal impact (SI units).

    Attributes
    ----------
    e_z : normal restitution ``|v_z,end| / v_z0`` (0 when the sphere stuck)
    stuck : the sphere did not separate (it turned back towards the surface while in
        contact, or creeps to rest in a contact that provably never changes)
    status : ``"ok"``, ``"stuck"``, ``"half_space"`` (finished, contact above 0.2 R), or
        a status of the table that says why the numbers are NaN (``time_limit``,
        ``row_exceeded``, ``non_finite``)
    F_tensile_max : largest pulling force on the sphere, N (>= 0)
    t_contact : contact time, s (stuck: time from first contact until sticking was seen)
    u_max : maximum indentation, m
    u_min : least indentation in contact, m (negative: the surface was pulled up)
    a_max : maximum contact radius, m
    v_z_end : normal velocity at the end, m/s (negative: away from the surface)
    adhesion_number : ``lam = sqrt(2 pi a_H dgamma / E*) / d`` (Hertz scales of the
        relaxed modulus at this impact speed), dimensionless
    contacts : separate contact intervals (1 unless the sphere bounced and was caught)
    n_steps : time steps taken
    path : the kernel that ran
    """

    e_z: float
    stuck: bool
    status: str
    F_tensile_max: float
    t_contact: float
    u_max: float
    u_min: float
    a_max: float
    v_z_end: float
    adhesion_number: float
    contacts: int
    n_steps: int
    path: str = PATH_NAME

    @property
    def energy_ratio(self) -> float:
        """Kinetic energy after / before, ``e_z^2``."""
        return self.e_z**2


def adhesion_number(scene: Scene) -> float:
    """Return the adhesion number ``lam = sqrt(2 pi a_H dgamma / E*) / d``, dimensionless.

    The critical elongation of the rule of Hess at the Hertz radius in units of the
    Hertz indentation (relaxed modulus); 0 without adhesion.
    """
    hz = scene.hertz
    return math.sqrt(2.0 * math.pi * float(hz.a_H) * scene.adhesion / scene.E_star) / float(hz.d)


def adhesion_for_number(scene: Scene, lam: float) -> float:
    """Return the work of adhesion (J/m^2) that gives ``scene`` the adhesion number ``lam``.

    The inverse of :func:`adhesion_number`: ``dgamma = lam^2 d^2 E* / (2 pi a_H)``.
    """
    lam = positive("lam", lam)
    hz = scene.hertz
    return lam**2 * float(hz.d) ** 2 * scene.E_star / (2.0 * math.pi * float(hz.a_H))


def adhesion_numbers(cols: SceneColumns) -> np.ndarray:
    """Return :func:`adhesion_number` of every row of ``cols``, dimensionless."""
    E_star = 2.0 * cols.G_inf / (1.0 - cols.nu)
    with np.errstate(all="ignore"):  # nu = 1 cannot occur in a valid row
        return np.sqrt(2.0 * np.pi * cols.a_H * cols.adhesion / E_star) / cols.d


def work_of_adhesion(lam, G_inf, nu, R, m, v_z0) -> np.ndarray:
    """Return the work of adhesion (J/m^2) that gives each row the adhesion number ``lam``.

    :func:`adhesion_for_number` on arrays (relaxed shear modulus ``G_inf``, Pa;
    Poisson ratio ``nu``; sphere radius ``R``, m, and mass ``m``, kg; impact speed
    ``v_z0``, m/s): ``dgamma = lam^2 d^2 E* / (2 pi a_H)``.
    """
    hz = hertz_scales(G_inf, nu, R, m, v_z0)
    E_star = effective_modulus(G_inf, nu)
    return np.asarray(lam, dtype=float) ** 2 * hz.d**2 * E_star / (2.0 * np.pi * hz.a_H)


def adhesion_number_of(dgamma, G_inf, nu, R, m, v_z0) -> np.ndarray:
    """Return the adhesion number ``lam`` of each row (inputs as :func:`work_of_adhesion`).

    :func:`adhesion_number` on arrays; ``dgamma`` the work of adhesion, J/m^2.
    """
    hz = hertz_scales(G_inf, nu, R, m, v_z0)
    E_star = effective_modulus(G_inf, nu)
    with np.errstate(all="ignore"):  # a bad row gives NaN, marked by the engine
        return np.sqrt(2.0 * np.pi * hz.a_H * np.asarray(dgamma, dtype=float) / E_star) / hz.d


def kernel_inputs(cols: SceneColumns, numerics: Numerics, widen: float = 1.0
                  ) -> dict[str, np.ndarray]:
    """Return the inputs of :func:`vimpact.kernels.adhesion.adhesive_batch`, one per row.

    The element row and step of :mod:`vimpact.engine.discretization` (Verlet, no
    tangential problem) with the half row ``widen`` times as wide, refined for a
    strong adhesion: the contact radius at zero load is ``lam^(2/3) a_H``, so the row
    grows by ``max(1, lam)^(2/3)`` and the stiffness with it, the step shrinking by
    ``max(1, lam)^(1/3)``.
    """
    num = numerics.with_(row_width=numerics.row_width * widen)
    row = discretization.element_row(cols, num, np.zeros(len(cols), dtype=bool), VERLET)
    g, tau, n_arms = arm_arrays(cols)
    lam = adhesion_numbers(cols)
    stiffer = np.maximum(1.0, lam) ** (1.0 / 3.0)
    return {"tau0": cols.dashpot_time / cols.T, "g": g, "tau": tau, "n_arms": n_arms,
            "lam": lam, "h": row["h"] / stiffer,
            "n_elem": (row["n_elem"] * np.maximum(1.0, lam) ** (2.0 / 3.0)).astype(np.int64) + 1,
            "dxi": np.asarray(row["dxi"], dtype=float) * np.ones(len(cols)),
            "max_steps": (row["max_steps"] * stiffer).astype(np.int64)}


def run_kernel(cols: SceneColumns, numerics: Numerics) -> np.ndarray:
    """Run every row of ``cols`` on the adhesive kernel; return ``(n, N_ADH_OUT)`` rows.

    Rows whose contact reached the end of the half row run again on a row twice as
    wide, up to :data:`MAX_ROW_WIDENINGS` times.
    """
    out = np.zeros((len(cols), kernel.N_ADH_OUT))
    todo = np.arange(len(cols))
    for k in range(MAX_ROW_WIDENINGS + 1):
        a = kernel_inputs(cols if k == 0 else cols.take(todo), numerics, 2.0**k)
        sub = np.zeros((len(todo), kernel.N_ADH_OUT))
        kernel.adhesive_batch(a["tau0"], a["g"], a["tau"], a["n_arms"], a["lam"], a["h"],
                              a["n_elem"], a["dxi"], a["max_steps"], sub)
        out[todo] = sub
        todo = todo[sub[:, kernel.ADH_STATUS] == STATUS_ROW_EXCEEDED]
        if len(todo) == 0:
            break
    return out


def simulate_adhesive(scene: Scene, numerics: Numerics | None = None) -> AdhesiveResult:
    """Simulate the adhesive normal impact of ``scene`` (``scene.adhesion >= 0``).

    The half row is widened (up to :data:`MAX_ROW_WIDENINGS` doublings) when the
    contact reaches its end. ``scene.adhesion = 0`` runs this kernel without
    adhesion (the non-adhesive element rules; :func:`vimpact.simulate` does not
    route such a scene here).

    Raises
    ------
    InputError
        if ``scene`` is not a :class:`Scene` or ``numerics`` not a :class:`Numerics`.
    """
    if not isinstance(scene, Scene):
        raise InputError(message("scene", scene, "a vimpact.Scene"))
    numerics = Numerics() if numerics is None else numerics
    require("numerics", numerics, isinstance(numerics, Numerics), "a vimpact.Numerics")
    out = np.zeros(kernel.N_ADH_OUT)
    cols = SceneColumns.from_scenes([scene])
    for k in range(MAX_ROW_WIDENINGS + 1):
        a = kernel_inputs(cols, numerics, 2.0**k)
        n = int(a["n_arms"][0])
        kernel.adhesive_impact(float(a["tau0"][0]), a["g"][0, :n].copy(),
                               a["tau"][0, :n].copy(), float(a["lam"][0]), float(a["h"][0]),
                               int(a["n_elem"][0]), float(a["dxi"][0]),
                               int(a["max_steps"][0]), out)
        if BY_CODE[int(out[kernel.ADH_STATUS])] != "row_exceeded":
            break
    return _result(scene, out, float(a["lam"][0]))


def _result(scene: Scene, out: np.ndarray, lam: float) -> AdhesiveResult:
    hz = scene.hertz
    status = BY_CODE[int(out[kernel.ADH_STATUS])]
    stuck = bool(out[kernel.ADH_STUCK] > 0.5)
    v_end = float(out[kernel.ADH_VZ_END]) * scene.v_z0
    vals: dict[str, float] = {"e_z": abs(v_end) / scene.v_z0, "F_tensile_max":
            float(out[kernel.ADH_F_TENSILE] * scene.m * scene.v_z0 / hz.T),
            "t_contact": float(out[kernel.ADH_T_CONTACT] * hz.T),
            "u_max": float(out[kernel.ADH_U_MAX] * hz.d),
            "u_min": float(out[kernel.ADH_U_MIN] * hz.d),
            "a_max": float(out[kernel.ADH_A_MAX] * hz.a_H), "v_z_end": v_end}
    if status == "ok":
        if stuck:
            status = "stuck"
        if vals["a_max"] > HALF_SPACE_LIMIT * scene.R and not scene.allow_large_contact:
            status = "half_space"
        if not all(math.isfinite(x) for x in vals.values()):
            status = "non_finite"
    if status not in ("ok", "stuck", "half_space"):
        vals = {k: math.nan for k in vals}
    return AdhesiveResult(e_z=vals["e_z"], stuck=stuck, status=status,
                          F_tensile_max=vals["F_tensile_max"], t_contact=vals["t_contact"],
                          u_max=vals["u_max"], u_min=vals["u_min"], a_max=vals["a_max"],
                          v_z_end=vals["v_z_end"], adhesion_number=lam,
                          contacts=int(out[kernel.ADH_CONTACTS]),
                          n_steps=int(out[kernel.ADH_STEPS]))


def sticking_velocity(scene: Scene, numerics: Numerics | None = None, *,
                      rtol: float = STICKING_RTOL, v_max: float | None = None) -> float:
    """Return the impact speed (m/s) below which the sphere of ``scene`` sticks.

    Bisection on ``v_z0`` (the other inputs of ``scene`` kept) between a speed at
    which the sphere sticks and one at which it separates, to the relative
    width ``rtol``; returns the midpoint of the final bracket (so within
    ``rtol / 2`` of the threshold the kernel resolves). The bracket is found by
    halving/doubling from ``scene.v_z0``. ``0.0`` if the sphere separates at every
    speed down to ``1e-12`` times ``scene.v_z0`` (no adhesion).

    Raises
    ------
    InputError
        if ``rtol`` is not in (0, 0.5), or no speed up to ``v_max`` (default
        ``1e6 scene.v_z0``) separates, or an impact fails (status not ok/stuck).
    """
    rtol = positive("rtol", rtol)
    require("rtol", rtol, rtol < 0.5, "in (0, 0.5)")
    v_top = 1e6 * scene.v_z0 if v_max is None else positive("v_max", v_max)

    def sticks(v: float) -> bool:
        res = simulate_adhesive(dataclasses.replace(scene, v_z0=v), numerics)
        if res.status not in ("ok", "stuck"):
            raise InputError(f"v_z0 = {v:.6g} m/s: the adhesive impact ended with status "
                             f"{res.status!r}; the sticking velocity needs finished impacts")
        return res.stuck

    v = scene.v_z0
    if sticks(v):
        lo = v
        hi = 2.0 * v
        while sticks(hi):
            lo = hi
            hi *= 2.0
            if hi > v_top:
                raise InputError(f"v_max = {v_top:.6g} m/s is too small: the sphere sticks "
                                 "at every speed up to it")
    else:
        hi = v
        lo = 0.5 * v
        while not sticks(lo):
            hi = lo
            lo *= 0.5
            if lo < 1e-12 * scene.v_z0:
                return 0.0
    while hi - lo > rtol * lo:
        mid = 0.5 * (lo + hi)
        if sticks(mid):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def jkr_quasi_static(E_star: float, R: float, dgamma: float, d_path: np.ndarray,
                     elements_per_unit: float = 200.0, length: float | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Run the elastic adhesive element row under a prescribed indentation path.

    Parameters
    ----------
    E_star : effective modulus, Pa
    R : sphere radius, m
    dgamma : work of adhesion, J/m^2
    d_path : indentations in the order they are imposed, m (negative: pulled up)
    elements_per_unit : elements per unit ``length`` on the half row
    length : length unit of the element spacing, m (default: the JKR contact
        radius at zero load ``a_0 = (9 pi dgamma R^2 / (2 E*))^(1/3)``); the half row
        is 4 ``a_0`` or the Hertz radius of the deepest indentation (twice), the larger

    Returns
    -------
    F : normal force on the sphere at each indentation, N (negative: tensile)
    a : contact radius, m
    """
    E_star, R, dgamma = (positive(n, x) for n, x in (("E_star", E_star), ("R", R),
                                                     ("dgamma", dgamma)))
    d_path = np.asarray(d_path, dtype=float)
    a0 = (9.0 * math.pi * dgamma * R**2 / (2.0 * E_star)) ** (1.0 / 3.0)
    unit = a0 if length is None else positive("length", length)
    # kernel units: lengths in a_H = unit, indentations in d = unit^2 / R
    d = unit**2 / R
    lam = math.sqrt(2.0 * math.pi * unit * dgamma / E_star) / d
    width = max(4.0 * a0, 2.0 * math.sqrt(R * max(float(d_path.max()), 0.0))) / unit
    dxi = 1.0 / elements_per_unit
    n_elem = int(math.ceil(width / dxi))
    F = np.zeros(len(d_path))
    a = np.zeros(len(d_path))
    if kernel.quasi_static_row(d_path / d, lam, n_elem, dxi, F, a) < 0:
        raise InputError(f"d_path max = {d_path.max():.4g} m is too deep for the row")
    # kernel force unit: element stiffness 15/16 per unit length is E* (a_H d per unit)
    return F * 16.0 / 15.0 * E_star * unit * d, a * unit



def impact_result(scene: Scene, numerics: Numerics | None = None) -> ImpactResult:
    """Return :func:`simulate_adhesive` as the :class:`~vimpact.ImpactResult` of simulate.

    Normal impact only: e_x, beta_x, mu_eff, gross_slip_fraction NaN, friction_energy
    0 (no slip); status ``stuck`` when the sphere did not separate, else
    ``normal_only``/``vc0_zero``.
    """
    res = simulate_adhesive(scene, numerics)
    hz = scene.hertz
    status = res.status
    if status == "ok":
        status = "normal_only" if scene.tangential == "none" else "vc0_zero"
    return ImpactResult(
        e_z=res.e_z, e_x=math.nan, beta_x=math.nan, t_contact=res.t_contact, u_max=res.u_max,
        a_max=res.a_max, t_hertz=float(hz.t_H), d_hertz=float(hz.d), a_hertz=float(hz.a_H),
        energy_ratio=res.energy_ratio, Q1=scene.Q1, Q2=scene.Q2, nu=scene.material.nu,
        v_z_end=res.v_z_end, v_x_end=scene.v_x0, omega_end=scene.omega0, status=status,
        n_steps=res.n_steps, path=PATH_NAME, F_tensile_max=res.F_tensile_max,
        rebound_angle=float(rebound_angle(np.float64(scene.v_x0), np.float64(res.v_z_end))),
        friction_energy=0.0 if math.isfinite(res.e_z) else math.nan,
        error=None if status in FINISHED else STATUSES.get(status, status))


def rebound_angle(v_x_end, v_z_end):
    """Angle of the end velocity to the normal, ``atan2(v_x_end, -v_z_end)``, degrees.

    A sphere that stuck (``v_z_end = 0``) has 0 (90 if it slides on with ``v_x0``), not
    the 180 of the signed zero ``-0.0``.
    """
    return np.degrees(np.arctan2(v_x_end, -v_z_end + 0.0))


def result_columns(cols: SceneColumns, numerics: Numerics) -> dict[str, np.ndarray]:
    """Run the adhesive rows ``cols`` (all valid, ``adhesion > 0``); return their result columns.

    The columns of :func:`vimpact.simulate_batch` (:data:`RESULT_FIELDS`), row by row
    what :func:`impact_result` gives for the same scene: normal impact only (``e_x``,
    ``beta_x`` and the friction outputs NaN), status ``stuck`` when the sphere did
    not separate, ``F_tensile_max`` the largest pulling force, N.
    """
    n = len(cols)
    out = run_kernel(cols, numerics)
    status = np.array([BY_CODE[int(c)] for c in out[:, kernel.ADH_STATUS]], dtype=object)
    stuck = out[:, kernel.ADH_STUCK] > 0.5
    with np.errstate(all="ignore"):
        v_end = out[:, kernel.ADH_VZ_END] * cols.v_z0
        vals = {"e_z": np.abs(v_end) / cols.v_z0,
                "F_tensile_max": out[:, kernel.ADH_F_TENSILE] * cols.m * cols.v_z0 / cols.T,
                "t_contact": out[:, kernel.ADH_T_CONTACT] * cols.T,
                "u_max": out[:, kernel.ADH_U_MAX] * cols.d,
                "a_max": out[:, kernel.ADH_A_MAX] * cols.a_H, "v_z_end": v_end}
    ok = status == "ok"
    status[ok & stuck] = "stuck"
    status[ok & (vals["a_max"] > HALF_SPACE_LIMIT * cols.R) & ~cols.allow_large_contact] = \
        "half_space"
    finite = np.all([np.isfinite(v) for v in vals.values()], axis=0)
    status[ok & ~finite] = "non_finite"
    dead = ~np.isin(status, ("ok", "stuck", "half_space"))
    for v in vals.values():
        v[dead] = np.nan
    status[status == "ok"] = np.where(
        cols.tangential[status == "ok"] == TANGENTIAL_EFFECTS.index("none"),
        "normal_only", "vc0_zero")
    error = np.array([None if s in FINISHED else STATUSES.get(s, s) for s in status],
                     dtype=object)
    nan = np.full(n, np.nan)
    result = {**vals, "e_x": nan, "beta_x": nan.copy(), "t_hertz": cols.t_H,
              "d_hertz": cols.d, "a_hertz": cols.a_H, "energy_ratio": vals["e_z"] ** 2,
              "Q1": cols.Q1, "Q2": cols.Q2, "nu": cols.nu, "v_x_end": cols.v_x0,
              "omega_end": cols.omega0, "status": status,
              "n_steps": out[:, kernel.ADH_STEPS].astype(np.int64),
              "path": np.full(n, PATH_NAME, dtype=object), "mu_eff": nan.copy(),
              "rebound_angle": rebound_angle(cols.v_x0, vals["v_z_end"]),
              "gross_slip_fraction": nan.copy(),
              "friction_energy": np.where(np.isfinite(vals["e_z"]), 0.0, np.nan),
              "error": error}
    return {name: result[name] for name in RESULT_FIELDS}
