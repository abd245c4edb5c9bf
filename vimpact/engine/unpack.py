"""Kernel result rows to SI result columns, statuses and NaN guards, vectorized."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from vimpact.engine.columns import SceneColumns
from vimpact.engine.result import (
    FINISHED,
    RESULT_FIELDS,
    STATUS_CODE,
    STATUS_NAMES,
    STATUSES,
    Coded,
)
from vimpact.kernels import layout
from vimpact.kernels import status as status_table
from vimpact.model.numerics import MIN_CONTACT_STEPS
from vimpact.model.scene import HALF_SPACE_LIMIT, TANGENTIAL_EFFECTS, TANGENTIAL_MEMORY
from vimpact.model.validation import is_none, unexplained

#: kernel status code -> status name (the status table's codes)
KERNEL_STATUSES = {
    **status_table.BY_CODE,
    layout.STATUS_ASSUMPTION: "non_finite",  # only reached if a hand-over failed
}

#: kernel status code -> status code of the engine (index in ``STATUS_NAMES``)
_KERNEL_CODES = {k: STATUS_CODE[name] for k, name in KERNEL_STATUSES.items()}
#: status codes of the statuses the checks below set or test
_OK, _INVALID, _NON_FINITE = (STATUS_CODE[name] for name in ("ok", status_table.INVALID,
                                                              "non_finite"))
#: per status code: the status name (object, for the text column), finished, and kept
#: within the passive bounds (:func:`clip_round_off`)
_NAMES = np.array(STATUS_NAMES, dtype=object)
_FINISHED = np.array([name in FINISHED for name in STATUS_NAMES])
_CLIPPED = np.array([name in ("ok", "vc0_zero", "normal_only", "half_space")
                     for name in STATUS_NAMES])

#: Energy a passive impact may gain from rounding and integration error
#: (relative to the contact energy); more is status ``unstable`` (or
#: ``energy_gain`` for explicit Euler, which gains energy by construction).
PASSIVITY_SLACK = 1e-6

#: Outputs that are numbers only with a status in ``FINISHED``.
OUTPUTS = ("e_z", "e_x", "beta_x", "t_contact", "u_max", "a_max", "energy_ratio", "v_z_end",
           "v_x_end", "omega_end", "mu_eff", "rebound_angle", "gross_slip_fraction",
           "friction_energy", "F_tensile_max")
#: Outputs that are NaN (by definition) without a tangential problem.
TANGENTIAL_OUTPUTS = ("e_x", "beta_x", "mu_eff", "gross_slip_fraction")


def unpack(cols: SceneColumns, out: np.ndarray, paths: Coded,
           explicit_euler: np.ndarray, steps_per_T: np.ndarray, refused: np.ndarray,
           codes: bool = False) -> dict[str, Any]:
    """SI result columns (:data:`vimpact.engine.result.RESULT_FIELDS`) of kernel rows.

    Parameters
    ----------
    cols : the scenes
    out : ``(n, N_OUT)`` kernel rows (anything in invalid rows)
    paths : the path of each row (:class:`~vimpact.engine.result.Coded`, code ``-1``
        for invalid rows)
    explicit_euler : rows integrated by explicit Euler (energy gain expected)
    steps_per_T : time steps per time unit ``T`` of each element-path row (0 on
        continuum rows): with the contact time, how well the contact was resolved
    refused : object array, ``(status, reason)`` of a valid row that was not run
        (cost bounds, an unreachable tolerance), else ``None``
    codes : return ``status`` and ``path`` as :class:`~vimpact.engine.result.Coded`
        (status codes into :data:`~vimpact.engine.result.STATUS_NAMES`) instead of
        object arrays of ``str`` (the sweep stores them without a string per row)
    """
    n = len(cols)
    valid = cols.valid
    kstatus = out[:, layout.OUT_STATUS].astype(np.int64)
    # statuses as int8 codes (STATUS_NAMES): compared and masked without a str per row
    status = np.full(n, _INVALID, dtype=np.int8)
    ran = valid & is_none(refused)
    for kcode, code in _KERNEL_CODES.items():
        status[ran & (kstatus == kcode)] = code
    refused_rows = np.flatnonzero(valid & ~ran)
    for i in refused_rows:
        status[i] = STATUS_CODE[refused[i][0]]
    ok = status == _OK
    tangential = cols.computes_tangential
    v_z0, v_c0, mu_t = cols.v_z0, cols.v_c0, cols.contact_mass_factor
    vz_end = out[:, layout.OUT_VZ_END]
    vc_end = np.where(tangential, out[:, layout.OUT_VC_END], 1.0)  # / v_c0
    with np.errstate(all="ignore"):
        v_z_end = vz_end * v_z0
        impulse = (1.0 - vc_end) / mu_t * v_c0  # tangential impulse / m, m/s
        spin = np.where(cols.rotation, impulse * cols.m * cols.R / cols.Theta, 0.0)
        v_x_end = cols.v_x0 - impulse
        omega_end = cols.omega0 - spin
        # a held spin (rotation off) is a drive, not a store: its energy is left out and
        # the work of the torque that holds it, R omega0 times the tangential impulse,
        # is counted as energy put in (docs/physics.md#energy-and-passivity)
        held = ~cols.rotation
        spin0 = np.where(held, 0.0, cols.Theta * cols.omega0**2)
        spin1 = np.where(held, 0.0, cols.Theta * omega_end**2)
        drive = np.where(held, 2.0 * cols.m * cols.R * cols.omega0 * impulse, 0.0)
        energy0 = 0.5 * (cols.m * (v_z0**2 + cols.v_x0**2) + spin0 + drive)
        energy1 = 0.5 * (cols.m * (v_z_end**2 + v_x_end**2) + spin1)
        # passivity of what the contact can exchange: the normal energy and the contact
        # point's effective tangential energy m v_c^2 / (2 mu_t); a spin held fixed
        # (rotation off) is outside it, so its work on the sphere cannot count as a gain
        contact0 = v_z0**2 + v_c0**2 / mu_t
        contact1 = v_z_end**2 + (vc_end * v_c0) ** 2 / mu_t
        # a tangential output of a batch without a tangential row is its fill value
        # throughout (np.where picks none of it): not computed
        some = bool(tangential.any())
        values = {
            "e_z": np.abs(vz_end),
            "e_x": _tangential(some, tangential, lambda: np.abs(vc_end), np.nan),
            "beta_x": _tangential(some, tangential, lambda: -vc_end, np.nan),
            "t_contact": out[:, layout.OUT_T_CONTACT] * cols.T,
            "u_max": out[:, layout.OUT_U_MAX] * cols.d,
            "a_max": out[:, layout.OUT_B_MAX] * cols.a_H,
            "energy_ratio": energy1 / energy0,
            "v_z_end": v_z_end, "v_x_end": v_x_end, "omega_end": omega_end,
            "mu_eff": _tangential(some, tangential,
                                  lambda: np.abs(impulse) / (v_z0 - v_z_end), np.nan),
            "rebound_angle": np.degrees(np.arctan2(v_x_end, -v_z_end)),
            "gross_slip_fraction": _tangential(
                some, tangential,
                lambda: out[:, layout.OUT_T_GROSS_SLIP] / out[:, layout.OUT_T_CONTACT], np.nan),
            "friction_energy": _tangential(
                some, tangential, lambda: out[:, layout.OUT_W_FRICTION] * cols.m * v_c0**2,
                0.0),
            # without adhesion an element leaves before it would pull: no tensile force
            "F_tensile_max": np.zeros(n),
        }
        # the contact point's tangential speed cannot grow either (|beta_x| <= 1): the
        # normal energy is far larger when v_c0 << v_z0, so the sum above misses it
        gain = ((contact1 > contact0 * (1.0 + PASSIVITY_SLACK))
                | (np.abs(vz_end) > 1.0 + PASSIVITY_SLACK))
        if some:
            gain |= tangential & (np.abs(vc_end) > 1.0 + PASSIVITY_SLACK)
        contact_steps = out[:, layout.OUT_T_CONTACT] * steps_per_T
        unresolved = contact_steps < MIN_CONTACT_STEPS
        relative_gain = contact1 / contact0 - 1.0
    incremental = cols.memory == TANGENTIAL_MEMORY.index("incremental")
    gained = ok & gain
    status[gained & incremental & ~explicit_euler] = STATUS_CODE["unstable"]
    status[gained & incremental & explicit_euler] = STATUS_CODE["energy_gain"]
    status[gained & ~incremental] = STATUS_CODE["not_passive"]
    passive = incremental & ~explicit_euler
    status[ok & (steps_per_T > 0) & unresolved] = STATUS_CODE["unresolved"]
    ok = status == _OK
    status[ok & (values["a_max"] > HALF_SPACE_LIMIT * cols.R)] = STATUS_CODE["half_space"]
    ok = status == _OK
    status[ok & (cols.tangential == TANGENTIAL_EFFECTS.index("none"))] = \
        STATUS_CODE["normal_only"]
    ok = status == _OK
    status[ok & (v_c0 == 0.0)] = STATUS_CODE["vc0_zero"]
    clip_round_off(values, _CLIPPED[status], passive)
    dead = guard(values, status, tangential)
    error = cols.reasons.copy()  # (None on a valid row: cols.valid)
    for i in refused_rows:  # refused rows only
        error[i] = refused[i][1]
    for i in np.flatnonzero(status == _NON_FINITE):
        if error[i] is None:
            error[i] = "the integration produced a non-finite value"
    _explain(status, error, contact_steps, relative_gain, dead)
    with np.errstate(all="ignore"):
        result = {
            **values,
            "t_hertz": cols.t_H, "d_hertz": cols.d, "a_hertz": cols.a_H,
            "Q1": cols.Q1, "Q2": cols.Q2, "nu": cols.nu,
            "n_steps": out[:, layout.OUT_STEPS].astype(np.int64), "error": error,
        }
    if codes:
        result["status"], result["path"] = Coded(status, STATUS_NAMES), paths
    else:
        result["status"], result["path"] = _NAMES[status], paths.decode()
    if not valid.all():  # (every row valid, the usual case: nothing to blank)
        for name in ("t_hertz", "d_hertz", "a_hertz", "Q1", "Q2", "nu"):
            result[name] = np.where(valid, result[name], np.nan)
        result["n_steps"] = np.where(valid, result["n_steps"], 0)
    return {name: result[name] for name in RESULT_FIELDS}


def _tangential(some: bool, tangential: np.ndarray, value, fill: float) -> np.ndarray:
    """``np.where(tangential, value(), fill)``; ``fill`` throughout, uncomputed, if not ``some``."""
    if not some:
        return np.full(tangential.shape[0], fill)
    return np.where(tangential, value(), fill)


def unpack_row(cols: SceneColumns, out: np.ndarray, path_name: str | None, explicit_euler: bool,
               steps_per_T: float, refused: tuple[str, str] | None) -> dict[str, Any]:
    """:func:`unpack` of a one-row batch whose row is valid, as Python scalars.

    The same rules in the same order on NumPy scalars instead of one-element
    arrays (the same floating-point operations, so the same numbers), for
    :func:`vimpact.simulate`: about ten times cheaper than :func:`unpack` on one row.
    ``tests/engine/test_unpack.py`` checks the two agree on every status.

    Parameters
    ----------
    cols : SceneColumns
        One valid scene (``cols.reasons[0] is None``).
    out : numpy.ndarray
        Its kernel row, shape ``(N_OUT,)``, kernel units.
    path_name : str
        The path that ran it.
    explicit_euler : bool
        Integrated by explicit Euler (energy gain expected).
    steps_per_T : float
        Time steps per time unit ``T`` on the element path (0 on a continuum path).
    refused : tuple of str or None
        ``(status, reason)`` if the row was not run (:func:`unpack`), else ``None``.

    Returns
    -------
    dict
        :data:`vimpact.engine.result.RESULT_FIELDS` to Python scalars (SI units).
    """
    nan = math.nan
    d, a_H, T = cols.d[0], cols.a_H[0], cols.T[0]
    m, R, Theta, v_x0, omega0 = cols.m[0], cols.R[0], cols.Theta[0], cols.v_x0[0], cols.omega0[0]
    if refused is None:
        status = KERNEL_STATUSES.get(int(out[layout.OUT_STATUS].astype(np.int64)),
                                     status_table.INVALID)
    else:
        status = refused[0]
    ok = status == "ok"
    tangential = bool(cols.computes_tangential[0])
    rotation = bool(cols.rotation[0])
    v_z0, v_c0, mu_t = cols.v_z0[0], cols.v_c0[0], cols.contact_mass_factor[0]
    inputs = (out[layout.OUT_VZ_END], out[layout.OUT_VC_END] if tangential else 1.0,
              out[layout.OUT_T_CONTACT], out[layout.OUT_U_MAX], out[layout.OUT_B_MAX],
              out[layout.OUT_T_GROSS_SLIP], out[layout.OUT_W_FRICTION], v_z0, v_c0, mu_t, m,
              R, Theta, v_x0, omega0, d, a_H, T, steps_per_T)
    try:  # on Python floats: the same IEEE operations as on NumPy's, at a fraction of the cost
        values, gain, contact_steps, relative_gain = _row_values(
            tangential, rotation, *map(float, inputs))
    except (ZeroDivisionError, OverflowError):  # where NumPy gives inf or NaN instead
        with np.errstate(all="ignore"):
            values, gain, contact_steps, relative_gain = _row_values(
                tangential, rotation, *map(np.float64, inputs))
    Q1, Q2 = cols.Q_row()
    incremental = cols.memory[0] == TANGENTIAL_MEMORY.index("incremental")
    if ok and gain:
        status = (("energy_gain" if explicit_euler else "unstable") if incremental
                  else "not_passive")
    if ok and steps_per_T > 0 and contact_steps < MIN_CONTACT_STEPS:
        status = "unresolved"
    if status == "ok" and values["a_max"] > HALF_SPACE_LIMIT * R:
        status = "half_space"
    if status == "ok" and cols.tangential[0] == TANGENTIAL_EFFECTS.index("none"):
        status = "normal_only"
    if status == "ok" and v_c0 == 0.0:
        status = "vc0_zero"
    if (status in ("ok", "vc0_zero", "normal_only", "half_space") and incremental
            and not explicit_euler):  # clip_round_off
        for name in ("e_z", "e_x", "energy_ratio"):
            if values[name] > 1.0:
                values[name] = 1.0
        if abs(values["beta_x"]) > 1.0:
            values["beta_x"] = np.sign(values["beta_x"])
    # guard
    if status in FINISHED and not all(
            math.isfinite(v) or (not tangential and name in TANGENTIAL_OUTPUTS)
            for name, v in values.items()):
        status = "non_finite"
    if status not in FINISHED:
        values = dict.fromkeys(values, nan)
    error = None if refused is None else refused[1]
    if status == "non_finite" and error is None:
        error = "the integration produced a non-finite value"
    if error is None and (status not in FINISHED or status == "not_passive"):
        error = _reason(status, contact_steps, relative_gain)
    result = {
        **values,
        "t_hertz": cols.t_H[0], "d_hertz": d, "a_hertz": a_H, "Q1": Q1, "Q2": Q2,
        "nu": cols.nu[0], "status": status,
        "n_steps": int(out[layout.OUT_STEPS].astype(np.int64)), "path": path_name,
        "error": error,
    }
    # Python scalars (the numbers are NumPy float64, a subclass of float: float() is
    # exact; n_steps is an int and the strings are str already), in field order
    row = {}
    for name in RESULT_FIELDS:
        v = result[name]
        row[name] = float(v) if type(v) is np.float64 else (
            v.item() if isinstance(v, np.generic) else v)
    return row


def _row_values(tangential: bool, rotation: bool, vz_end, vc_end, t_contact, u_max, b_max,
                t_gross_slip, w_friction, v_z0, v_c0, mu_t, m, R, Theta, v_x0, omega0, d,
                a_H, T, steps_per_T) -> tuple[dict[str, Any], bool, Any, Any]:
    """Return the outputs of one kernel row in SI units, and its passivity figures.

    The rules of :func:`unpack` (for :func:`unpack_row`): the outputs, whether the
    contact gained energy, its contact steps and relative energy gain.
    """
    nan = math.nan
    v_z_end = vz_end * v_z0
    impulse = (1.0 - vc_end) / mu_t * v_c0
    spin = impulse * m * R / Theta if rotation else 0.0
    v_x_end = v_x0 - impulse
    omega_end = omega0 - spin
    # energies as in unpack (a held spin is a drive, not a store)
    spin0 = Theta * omega0**2 if rotation else 0.0
    spin1 = Theta * omega_end**2 if rotation else 0.0
    drive = 0.0 if rotation else 2.0 * m * R * omega0 * impulse
    energy0 = 0.5 * (m * (v_z0**2 + v_x0**2) + spin0 + drive)
    energy1 = 0.5 * (m * (v_z_end**2 + v_x_end**2) + spin1)
    contact0 = v_z0**2 + v_c0**2 / mu_t
    contact1 = v_z_end**2 + (vc_end * v_c0) ** 2 / mu_t
    values = {
        "e_z": abs(vz_end),
        "e_x": abs(vc_end) if tangential else nan,
        "beta_x": -vc_end if tangential else nan,
        "t_contact": t_contact * T,
        "u_max": u_max * d,
        "a_max": b_max * a_H,
        "energy_ratio": energy1 / energy0,
        "v_z_end": v_z_end, "v_x_end": v_x_end, "omega_end": omega_end,
        "mu_eff": abs(impulse) / (v_z0 - v_z_end) if tangential else nan,
        "rebound_angle": np.degrees(np.arctan2(v_x_end, -v_z_end)),
        "gross_slip_fraction": t_gross_slip / t_contact if tangential else nan,
        "friction_energy": w_friction * m * v_c0**2 if tangential else 0.0,
        "F_tensile_max": 0.0,
    }
    gain = bool((contact1 > contact0 * (1.0 + PASSIVITY_SLACK))
                or (abs(vz_end) > 1.0 + PASSIVITY_SLACK)
                or (tangential and abs(vc_end) > 1.0 + PASSIVITY_SLACK))
    return values, gain, t_contact * steps_per_T, contact1 / contact0 - 1.0


def clip_round_off(values: dict[str, np.ndarray], ok: np.ndarray, passive: np.ndarray) -> None:
    """Keep the physical bounds of a passive impact exactly.

    In a finished row (``ok`` and its finished variants, not ``energy_gain``,
    ``not_passive``; mask ``ok``) of a passive scene (incremental memory, not explicit
    Euler) ``e_z``, ``e_x``, ``|beta_x|`` and ``energy_ratio`` are at most 1. Rounding can
    put them above by up to :data:`PASSIVITY_SLACK` (a larger excess is status
    ``unstable``); such a value is set to the bound (``beta_x`` keeps its sign).
    """
    rows = ok & passive
    with np.errstate(invalid="ignore"):  # (a column with no value beyond its bound: kept)
        for name in ("e_z", "e_x", "energy_ratio"):
            over = rows & (values[name] > 1.0)
            if over.any():
                values[name] = np.where(over, 1.0, values[name])
        b = values["beta_x"]
        over = rows & (np.abs(b) > 1.0)
        if over.any():
            values["beta_x"] = np.where(over, np.sign(b), b)


def guard(values: dict[str, np.ndarray], status: np.ndarray,
          tangential: np.ndarray) -> np.ndarray:
    """NaN only with a status that says why.

    ``status``: codes into :data:`~vimpact.engine.result.STATUS_NAMES` (changed in
    place). Outputs of a row whose status is not finished become NaN; a finished row
    with an unexplained NaN or inf becomes ``non_finite`` (all outputs NaN). Returns the
    rows not finished now (bool).
    """
    finished = _FINISHED[status]
    bad = np.zeros(status.shape[0], dtype=bool)
    for name, v in values.items():
        unexplained = ~np.isfinite(v)
        if name in TANGENTIAL_OUTPUTS:
            unexplained &= tangential
        bad |= finished & unexplained
    status[bad] = _NON_FINITE
    dead = ~finished | bad  # (non_finite is not a finished status: no second pass)
    if dead.any():
        for v in values.values():
            v[dead] = np.nan
    return dead


def finished_codes(status: np.ndarray) -> np.ndarray:
    """Return elementwise ``name in FINISHED`` of status codes (:data:`STATUS_NAMES`)."""
    return _FINISHED[status]


def _explain(status: np.ndarray, error: np.ndarray, contact_steps: np.ndarray,
             relative_gain: np.ndarray, dead: np.ndarray) -> None:
    """Give a reason to every row whose status is not finished and has none yet.

    No row ends without numbers and without saying why. ``status``: codes;
    ``dead``: the rows not finished (:func:`guard`'s answer).
    """
    explain = dead | (status == STATUS_CODE["not_passive"])
    for i in unexplained(explain, error):
        error[i] = _reason(STATUS_NAMES[status[i]], contact_steps[i], relative_gain[i])


def _reason(status: str, contact_steps: float, relative_gain: float) -> str:
    """Why a row ended with ``status`` (not finished, or ``not_passive``), in words."""
    if status == "unresolved":
        return (f"the contact lasted {contact_steps:.3g} time steps on the element "
                f"path: at least {MIN_CONTACT_STEPS} are needed to resolve it (more "
                "steps per t_H, or the continuum path)")
    if status == "not_passive":
        return (f"the contact energy rose by {relative_gain:.2g} of its start, or "
                "|e_z| or |beta_x| exceeds 1: the seed tangential memory is not "
                "passive (numbers kept as its rule gives them; the incremental "
                "memory is passive)")
    if status == "unstable":
        return (f"the contact energy rose by {relative_gain:.2g} of its start, or the "
                f"contact point's tangential speed by more than {PASSIVITY_SLACK:g} "
                "(|beta_x| > 1), in a passive scene: the numerical solution is not "
                "converged (more steps or elements)")
    return STATUSES.get(status, status)
