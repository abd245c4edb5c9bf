"""LIGGGHTS: ``pair_style gran model hertz`` with per-type and per-type-pair properties.

LIGGGHTS builds the contact from ``fix property/global``: ``youngsModulus``
and ``poissonsRatio`` per atom type (it mixes them as
``1/Y* = (1-nu1^2)/Y1 + (1-nu2^2)/Y2``, the compliance sum of vimpact's pair
material, so the relaxed ``E`` and ``nu`` of each type are exported) and
``coefficientRestitution`` and ``coefficientFriction`` per type pair (a full
matrix, walls included as their own atom types). Its Hertz damping
``2 sqrt(5/6) beta sqrt(S_n m_eff)`` (``beta`` from ``e``,
``S_n = 2 Y* sqrt(R delta)``) gives a restitution that does not depend on the
speed; integrated here without ``limitForce`` it equals the input ``e``
(to 1e-10), so the export is the constant closest to vimpact's ``e_z(v)`` in
RMS and the residual is the speed dependence LIGGGHTS cannot follow. There is
no tangential restitution input: ``tangential history`` takes ``k_t = 8 G*
sqrt(R delta)`` and its damping from the same Young's moduli, Poisson ratios and
``beta``; the report gives the ``beta_x`` that law produces (:func:`tangential_beta`)
and its residual, and ``tangential_damping`` is switched off when that fits better.

Files: ``liggghts_settings.in`` (before ``create_box``: units, atom style,
communication) and ``liggghts.in`` (after it: ``hard_particles yes`` when a
Young's modulus exceeds the 1e9 Pa LIGGGHTS accepts by default in SI units,
the property matrices, the pair style, one ``fix wall/gran`` per wall and the
time step). Checked by running LIGGGHTS-PUBLIC 3.8.0 (tests/dem/test_liggghts.py).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from vimpact.dem import laws
from vimpact.dem.fit import ContactFit, Oblique, Residual, Targets, fit_constant
from vimpact.dem.problem import DemProblem, WallType

CODE = "liggghts"
TANGENTIAL = True
#: Young's modulus of a rigid wall relative to the stiffest particle type
RIGID_WALL_FACTOR = 1000.0
#: largest Young's modulus LIGGGHTS accepts in SI units without ``hard_particles yes``, Pa
SOFT_LIMIT = 1.0e9
#: default time steps per (shortest) contact in the exported ``timestep``
STEPS_PER_CONTACT = 100
#: the code's time-step error in e, about ``C / steps_per_contact``: ``(C, measurement)``,
#: the largest |e - predicted| over the round trip of sweeps/dem/two_rubbers.toml
TIME_STEP_ERROR = (0.05, "LIGGGHTS-PUBLIC 3.8.0 (Debian): "
                   "4.1e-4 at 100, 7.1e-5 at 800 steps")
#: the code's time-step error in beta_x, measured: the largest |beta - predicted| over the
#: oblique wall impacts of the round trip of sweeps/dem/two_rubbers.toml
BETA_TIME_STEP_ERROR = "LIGGGHTS-PUBLIC 3.8.0: 2.5e-2 at 100, 5.6e-3 at 800 steps"


def shear_ratio(Y: list[tuple[float, float]], i: int, j: int) -> tuple[float, float]:
    """Return the effective moduli ``(Y*, G*)``, Pa, LIGGGHTS mixes for types ``i``, ``j``.

    From the exported Young's moduli (Pa) and Poisson ratios ``Y``; ``i``, ``j``
    0-based: ``1/Y* = sum (1 - nu^2)/Y``, ``1/G* = sum 2 (2 - nu)(1 + nu)/Y``.
    """
    (E1, nu1), (E2, nu2) = Y[i], Y[j]
    return (1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2),
            1.0 / (2.0 * (2.0 - nu1) * (1.0 + nu1) / E1 + 2.0 * (2.0 - nu2) * (1.0 + nu2) / E2))


def tangential_beta(e_in: float, Ystar: float, Gstar: float, F: float, mu: float, w0,
                    damping: bool, steps: int | None = None, wall=None) -> np.ndarray:
    """Return LIGGGHTS' ``beta`` at ``w0 = v_c0 / v_z0`` (:func:`vimpact.dem.laws.liggghts_coulomb`).

    With ``tangential_damping`` on (``damping``) or off; ``Ystar``, ``Gstar`` in
    Pa. ``wall = (R, m, v)`` (m, kg, m/s; ``v`` like ``w0``): a wall contact, whose
    lever ``R - delta/2`` is included.
    """
    b = abs(laws.liggghts_beta(e_in))
    D = 2.0 * b * math.sqrt(4.0 * Gstar / Ystar) if damping else 0.0
    lever = None
    if wall is not None:
        R, m, v = wall
        lever = laws.hertz_overlap(Ystar, R, m, v) / (2.0 * R)
    return laws.liggghts_coulomb(e_in, 6.0 * Gstar / Ystar, D, F, mu, w0,
                                 steps or laws.FRICTION_STEPS, lever)[1]


def _tangential(problem: DemProblem, targets: dict[str, Targets], fits: list[ContactFit]) -> None:
    """Choose ``tangential_damping on|off`` and add the tangential predictions to ``fits``.

    LIGGGHTS' tangential constants follow from the exported Y, nu and
    restitution; the one free choice, ``tangential_damping on|off`` (one setting
    for the pair style and the walls), is the one with the smaller largest
    ``beta_x`` residual.
    """
    from vimpact.dem import linear

    Y = _youngs(problem)
    # per setting: the largest residual, the setting, and per fit (beta, target, the
    # oblique impacts it is over or None for full stick)
    candidates: list[tuple[float, bool, list[tuple[np.ndarray, np.ndarray, Oblique | None]]]] = []
    for damping in (True, False):
        res: list[tuple[np.ndarray, np.ndarray, Oblique | None]] = []
        for f in fits:
            c, t = f.contact, targets[f.contact.key]
            Ys, Gs = shear_ratio(Y, c.first.index - 1, c.second.index - 1)
            F = linear.mass_factor(c)
            e_in = f.params["coefficientRestitution"]
            ob = t.oblique
            if ob is not None:
                b = tangential_beta(e_in, Ys, Gs, F, ob.mu, ob.w0, damping, 1000,
                                    (ob.R, ob.m, ob.v) if c.is_wall else None)
                res.append((b, ob.beta_x, ob))
            elif t.beta_x is not None:
                b1 = tangential_beta(e_in, Ys, Gs, F, math.inf, np.ones(1), damping)[0]
                res.append((np.full_like(t.beta_x, b1), t.beta_x, None))
            else:
                return
        candidates.append((max(Residual.of(b, tg).max_abs for b, tg, _ in res), damping, res))
    # the smaller largest residual; on a tie the first (damping on)
    _, damping, res = min(candidates, key=lambda cand: cand[0])
    for f, (b, target, ob) in zip(fits, res):
        if ob is not None:  # the prediction at the reported step of the law
            c = f.contact
            Ys, Gs = shear_ratio(Y, c.first.index - 1, c.second.index - 1)
            b = tangential_beta(f.params["coefficientRestitution"], Ys, Gs,
                                linear.mass_factor(c), ob.mu, ob.w0, damping,
                                wall=(ob.R, ob.m, ob.v) if c.is_wall else None)
        f.params["tangential_damping"] = damping
        f.res_beta_x = Residual.of(b, target)
        if ob is not None:
            f.beta_oblique = b
        else:
            f.beta_x = b
        f.notes[1] = ("beta_x: LIGGGHTS derives k_t = 8 G* sqrt(R delta) and its tangential "
                      "damping from the exported Young's moduli, Poisson ratios and "
                      "coefficientRestitution; tangential_damping "
                      f"{'on' if damping else 'off'} (the better of the two) gives the residual "
                      + ("over the oblique impacts with the contact's friction"
                         if ob is not None else "in full stick"))


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    """Fit LIGGGHTS' ``coefficientRestitution`` per contact (the constant closest to ``e_z``).

    The Young's moduli (Pa) and Poisson ratios are the materials'; the tangential
    damping setting is chosen after (:func:`_tangential`).
    """
    fits = []
    Y = _youngs(problem)
    for c in problem.contacts:
        t = targets[c.key]
        e_in, _ = fit_constant(t.e_z, 1e-6, 1.0)
        e_code = laws.tsuji_hertz_e(e_in)  # what LIGGGHTS' law gives with that input
        e = np.full_like(t.e_z, e_code)
        notes = ["speed-independent restitution: the residual is vimpact's speed dependence",
                 "beta_x: not represented (no tangential restitution input)"]
        (E1, nu1), (E2, nu2) = Y[c.first.index - 1], Y[c.second.index - 1]
        E_code = 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)
        R, m = c.nominal()
        t_c = float(laws.hertz_contact_time(E_code, R, m, problem.speeds.max()))
        fits.append(ContactFit(c, {"coefficientRestitution": e_in, "mu": c.mu, "e_liggghts": e_code,
                                   "E_star_Pa": E_code, "t_contact_min": t_c},
                               e, None, Residual.of(e, t.e_z), None, notes))
    _tangential(problem, targets, fits)
    return fits


def _youngs(problem: DemProblem) -> list[tuple[float, float]]:
    out = [(2.0 * t.material.G_inf * (1.0 + t.material.nu), t.material.nu) for t in problem.types]
    stiffest = max(E for E, _ in out)
    for w in problem.walls:
        m = w.material
        out.append((RIGID_WALL_FACTOR * stiffest, 0.0) if m is None else
                   (2.0 * m.G_inf * (1.0 + m.nu), m.nu))
    return out


def time_step(fits: list[ContactFit], steps_per_contact: int = STEPS_PER_CONTACT) -> float:
    """Return LIGGGHTS' ``timestep``, s: the shortest Hertz contact time over ``steps_per_contact``.

    The shortest contact is that of the fastest impact.
    """
    return min(f.params["t_contact_min"] for f in fits) / steps_per_contact


def render(problem: DemProblem, fits: list[ContactFit],
           steps_per_contact: int = STEPS_PER_CONTACT) -> dict[str, str]:
    """Return the LIGGGHTS input files of the fits, by name.

    ``liggghts_settings.in`` (include before ``create_box`` / ``read_data``) and
    ``liggghts.in`` (after ``create_box``: material properties per type, pair
    style, walls, time step).
    """
    names = [t.name for t in problem.types] + [w.name for w in problem.walls]
    n = len(names)
    e = np.full((n, n), 0.5)  # wall-wall entries are never used
    mu = np.full((n, n), 0.5)
    for f in fits:
        i, j = f.contact.first.index - 1, f.contact.second.index - 1
        e[i, j] = e[j, i] = f.params["coefficientRestitution"]
        m = f.params["mu"]
        mu[i, j] = mu[j, i] = m if math.isfinite(m) else 1.0e6
    Y = _youngs(problem)
    damping = ("" if all(f.params.get("tangential_damping", True) for f in fits)
               else " tangential_damping off")
    settings = ["# LIGGGHTS settings written by `vimpact dem`: include BEFORE create_box / read_data",
                f"# from {problem.source}",
                "units si", "atom_style granular", "atom_modify map array", "newton off",
                "communicate single vel yes", ""]
    lines = ["# LIGGGHTS lines written by `vimpact dem` (units si): include AFTER create_box",
             f"# (create_box {n} ...: particle types and walls), before create_atoms / run",
             f"# from {problem.source}; speeds {problem.speeds.min():g}..{problem.speeds.max():g} m/s",
             "# atom types: " + ", ".join(f"{k + 1} = {nm}" for k, nm in enumerate(names)),
             "# wall-wall matrix entries are placeholders (never used)"]
    if any(w.material is None for w in problem.walls):
        lines.append(f"# rigid wall: Young's modulus {RIGID_WALL_FACTOR:g} x the stiffest particle type")
    if max(E for E, _ in Y) > SOFT_LIMIT:
        lines.append("hard_particles yes   # a Young's modulus above 1e9 Pa (LIGGGHTS refuses it otherwise)")
    lines += [
        "fix m1 all property/global youngsModulus peratomtype " + " ".join(f"{E:.8g}" for E, _ in Y),
        "fix m2 all property/global poissonsRatio peratomtype " + " ".join(f"{nu:.6g}" for _, nu in Y),
        f"fix m3 all property/global coefficientRestitution peratomtypepair {n} "
        + " ".join(f"{x:.8f}" for x in e.ravel()),
        f"fix m4 all property/global coefficientFriction peratomtypepair {n} "
        + " ".join(f"{x:.6g}" for x in mu.ravel()),
        f"pair_style gran model hertz tangential history{damping}",
        "pair_coeff * *"]
    for w in problem.walls:
        lines.append(f"fix wall_{w.name} all wall/gran model hertz tangential history{damping} "
                     f"primitive type {w.index} zplane 0.0   # replace 'zplane 0.0' by your "
                     "wall's geometry")
    lines += [f"timestep {time_step(fits, steps_per_contact):.8g}   # s: {steps_per_contact} steps "
              f"per shortest contact (v = {problem.speeds.max():g} m/s)", ""]
    return {"liggghts_settings.in": "\n".join(settings), "liggghts.in": "\n".join(lines)}


# ---- running LIGGGHTS itself (round trip) ----------------------------------

#: the LIGGGHTS executable (Debian package ``liggghts``)
LIGGGHTS = "liggghts"


def liggghts_available() -> str | None:
    """``None`` if the ``liggghts`` executable can be run, else why not."""
    import shutil

    if shutil.which(LIGGGHTS) is None:
        return "the 'liggghts' executable is not on PATH (Debian: apt-get install liggghts)"
    return None


def round_trip(problem: DemProblem, speeds, steps_per_contact: int = STEPS_PER_CONTACT,
               fits: list[ContactFit] | None = None, timeout: float = 600.0,
               angles_deg=None, contacts=None, head_on: bool | None = None) -> list[dict]:
    """Run LIGGGHTS once with the exported files on head-on collisions of every contact.

    The files are included unchanged; nominal sizes, ``speeds`` in m/s. One dict
    per collision with ``contact``, ``v``, ``e`` (LIGGGHTS', from its velocities) and
    ``predicted`` (the report's).

    With ``angles_deg``: oblique impacts of the wall contacts only at those angles from
    the normal (``v_c0 = v tan(angle)``, no spin); rows also have ``angle``, ``beta``
    (LIGGGHTS', the contact-point velocity from the tangential impulse with its
    solid-sphere inertia) and ``predicted_beta`` (:func:`tangential_beta`);
    ``head_on=True`` adds the head-on collisions of every contact to the same run (one
    LIGGGHTS start for both). ``contacts``: the keys of the contacts whose rows are
    returned (default: every contact). Several time steps in one LIGGGHTS start:
    :func:`round_trips`.
    """
    return round_trips(problem, speeds, [steps_per_contact], fits, timeout, angles_deg,
                       contacts, head_on)[steps_per_contact]


def round_trips(problem: DemProblem, speeds, steps_per_contact,
                fits: list[ContactFit] | None = None, timeout: float = 600.0,
                angles_deg=None, contacts=None, head_on: bool | None = None
                ) -> dict[int, list[dict]]:
    """Return :func:`round_trip`'s rows at each of the time steps ``steps_per_contact``.

    One LIGGGHTS start: each time step is a run of its own after ``clear``, with the
    files exported for it; a dict from steps per contact to rows.
    """
    import os
    import subprocess
    import tempfile

    from vimpact.dem import linear

    if fits is None:
        from vimpact.dem.export import export

        fits = export(problem, CODE).fits
    if head_on is None:
        head_on = angles_deg is None
    n_types = len(problem.types) + len(problem.walls)
    cases: list[dict[str, Any]] = []
    # per atom: type, position (m), radius (m), density (kg/m^3), velocity (m/s)
    atoms: list[tuple[int, tuple[float, float, float], float, float,
                      tuple[float, float, float]]] = []
    x, top = 0.0, 0.0
    r_max = max(max(t.radii) for t in problem.types)
    z_pairs = 20.0 * r_max  # far above any wall at z = 0; pairs collide along x
    Y = _youngs(problem)
    for f in fits:
        c = f.contact
        angles = list(angles_deg) if angles_deg is not None and c.is_wall else []
        for v, ang in [(v, a) for v in speeds for a in ([None] if head_on else []) + angles]:
            second = c.second
            R1 = c.first.radius
            R2 = R1 if isinstance(second, WallType) else second.radius
            vt = 0.0 if ang is None else float(v) * math.tan(math.radians(ang))
            x += 4.0 * (R1 + R2) + 8.0 * r_max * vt / float(v)
            gap = 1e-3 * R1
            case: dict[str, Any] = {"contact": c.key, "v": float(v),
                                    "predicted": float(f.params["e_liggghts"]), "ids": []}
            if ang is not None:
                case.update(angle=float(ang), vt=vt, F=linear.mass_factor(c))
            if isinstance(second, WallType):
                atoms.append((c.first.index, (x, 0.0, R1 + gap), R1, c.first.density,
                              (vt, 0.0, -float(v))))
                case["ids"] = [len(atoms)]
            else:
                m1, m2 = c.first.mass(R1), second.mass(R2)
                atoms.append((c.first.index, (x - R1 - gap / 2, 0.0, z_pairs), R1,
                              c.first.density, (v * m2 / (m1 + m2), 0.0, 0.0)))
                atoms.append((second.index, (x + R2 + gap / 2, 0.0, z_pairs), R2,
                              second.density, (-v * m1 / (m1 + m2), 0.0, 0.0)))
                case["ids"] = [len(atoms) - 1, len(atoms)]
            cases.append(case)
            top = x
        if angles:  # the report's beta of all this contact's oblique impacts in one call
            Ys, Gs = shear_ratio(Y, c.first.index - 1, c.second.index - 1)
            R_, m_ = c.nominal()
            mine = [cs for cs in cases if cs["contact"] == c.key and "angle" in cs]
            v_all = np.array([cs["v"] for cs in mine])
            beta = tangential_beta(f.params["coefficientRestitution"], Ys, Gs,
                                   linear.mass_factor(c), c.mu,
                                   np.array([cs["vt"] for cs in mine]) / v_all,
                                   f.params.get("tangential_damping", True),
                                   wall=(R_, m_, v_all))
            for cs, b in zip(mine, beta):
                cs["predicted_beta"] = float(b)
    t_end = max(1e-3 * f.contact.first.radius / min(speeds) for f in fits) + 3.0 * max(
        float(laws.hertz_contact_time(f.params["E_star_Pa"], *f.contact.nominal(), min(speeds)))
        for f in fits)
    steps_list = [int(n) for n in steps_per_contact]
    lines = []
    for part, n in enumerate(steps_list):
        dt = time_step(fits, n)
        lines += (["clear"] if part else []) + [
            f"include {n}/liggghts_settings.in", "boundary f f f",
            f"region box block {-r_max * 4:.6g} {top + 4 * r_max:.6g} {-4 * r_max:.6g} "
            f"{4 * r_max:.6g} {-4 * r_max:.6g} {z_pairs + 4 * r_max:.6g} units box",
            f"create_box {n_types} box", f"neighbor {0.5 * r_max:.6g} bin",
            f"include {n}/liggghts.in"]
        for k, (typ, (ax, ay, az), R, rho, (vx, vy, vz)) in enumerate(atoms, start=1):
            lines += [f"create_atoms {typ} single {ax:.12g} {ay:.12g} {az:.12g} units box",
                      f"set atom {k} diameter {2 * R:.12g} density {rho:.12g}",
                      f"group one id {k}",
                      f"velocity one set {vx:.12g} {vy:.12g} {vz:.12g} units box",
                      "group one delete"]
        lines += ["fix integrate all nve/sphere", "thermo 0",
                  f"run {int(math.ceil(t_end / dt))}"]
        for k in range(1, len(atoms) + 1):
            lines += [f"variable vx{k} equal vx[{k}]", f"variable vz{k} equal vz[{k}]",
                      f'print "VIMPACT {part} {k} ${{vx{k}}} ${{vz{k}}}"']
    with tempfile.TemporaryDirectory() as tmp:
        for n in steps_list:
            os.makedirs(os.path.join(tmp, str(n)), exist_ok=True)
            for name, text in render(problem, fits, n).items():
                with open(os.path.join(tmp, str(n), name), "w") as fh:
                    fh.write(text)
        with open(os.path.join(tmp, "in.drive"), "w") as fh:
            fh.write("\n".join(lines) + "\n")
        proc = subprocess.run([LIGGGHTS, "-in", "in.drive", "-log", "none"], cwd=tmp,
                              capture_output=True, text=True, timeout=timeout,
                              env=dict(os.environ, OMP_NUM_THREADS="1"))
    vel: dict[tuple[int, int], tuple[float, float]] = {}
    for ln in proc.stdout.splitlines():
        if ln.startswith("VIMPACT "):
            _, part_s, atom, vx_end, vz_end = ln.split()
            vel[int(part_s), int(atom)] = (float(vx_end), float(vz_end))
    if proc.returncode != 0 or len(vel) != len(atoms) * len(steps_list):
        raise RuntimeError(f"LIGGGHTS failed: {(proc.stdout + proc.stderr).strip()[-2000:]}")
    out = {}
    for part, n in enumerate(steps_list):
        rows = []
        for case in cases:
            row = {k: v for k, v in case.items() if k not in ("ids", "vt", "F")}
            ids, vt, F = case["ids"], case.get("vt", 0.0), case.get("F", 0.0)
            first = vel[part, ids[0]]
            if len(ids) == 1:
                row["e"] = first[1] / case["v"]
            else:
                row["e"] = (vel[part, ids[1]][0] - first[0]) / case["v"]
            if vt:
                # the tangential impulse changes the contact-point velocity F times the centre's
                row["beta"] = -(vt + F * (first[0] - vt)) / vt
            rows.append(row)
        out[n] = [r for r in rows if contacts is None or r["contact"] in contacts]
    return out


if __name__ == "__main__":  # python -m vimpact.dem.liggghts SETUP.toml [STEPS_PER_CONTACT]
    from vimpact.dem.report import round_trip_main

    round_trip_main("LIGGGHTS", liggghts_available, round_trip, STEPS_PER_CONTACT,
                    oblique=CODE)
