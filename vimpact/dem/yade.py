"""Yade: ``ViscElMat(tc, en, et)`` with a ``MatchMaker`` for every pair of materials.

Yade's ``Ip2_ViscElMat_ViscElMat_ViscElPhys`` turns ``(tc, en, et)`` into a
linear spring-dashpot, with ``massR = m1 m2 / (m1 + m2)`` from the bodies'
masses (a body of mass 0, such as a ``wall`` or a fixed facet, takes the
other body's mass, so at a wall ``massR = m / 2``, not the effective mass
``m``):

``kn = massR (pi^2 + ln^2 en) / tc^2``, ``cn = -2 massR ln(en) / tc``,
``ks = 2/7 massR (pi^2 + ln^2 et) / tc^2``, ``cs = -4/7 massR ln(et) / tc``.

``Law2_ScGeom_ViscElPhys_Basic`` clips the normal force at zero (the contact
ends when the force does, while the spheres still overlap) and, in stick,
adds the tangential spring (incremental) and dashpot; with the normal force
at zero the Coulomb limit is zero, so the tangential force ends with it. So
Yade does *not* restitute its input ``en``: between spheres it gives the
clipped linear law's ``e(zeta)``, at a wall that of ``zeta / sqrt(2)``. The
fit runs that law (:func:`yade_law`) and chooses ``en`` (and ``et``) so that
what Yade produces is the constant closest to vimpact's curve; ``tc`` is set
so that the contact lasts the Hertz contact time at the geometric mean speed
(at a wall ``tc`` is ``1/sqrt(2)`` of it). ``et`` is fitted to vimpact's
``beta_x`` with the pair's contact-point mass factor: for a contact with friction,
to vimpact's oblique impacts with it over the set-up's impact angles, by stepping
Yade's law with its Coulomb cap (:func:`yade_oblique`; at walls with Yade's lever
``R - delta``); without friction, in full stick. Checked by running Yade 2023.02 on
head-on and oblique impacts (tests/dem/test_yade.py).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from vimpact.dem import laws, linear
from vimpact.dem.fit import (
    ContactFit,
    Residual,
    Targets,
    fit_constant,
    fit_scalar,
    fit_scalar_many,
)
from vimpact.dem.problem import Contact, DemProblem, WallType

CODE = "yade"
TANGENTIAL = True
#: default time steps per (shortest) contact in the exported ``vimpact_dt``
STEPS_PER_CONTACT = 400
#: the code's time-step error in e, about ``C / steps_per_contact``: ``(C, measurement)``,
#: the largest |e - predicted| over the round trip of sweeps/dem/two_rubbers.toml
TIME_STEP_ERROR = (0.23, "Yade 2023.02 (Debian): "
                   "2.2e-3 at 100, 5.8e-4 at 400, 1.1e-4 at 1600 steps")
#: friction angle written for a contact without friction (stick)
STICK_MU = 1.0e6
#: the code's time-step error in beta_x, measured: the largest |beta - predicted| over the
#: oblique wall impacts of the round trip of sweeps/dem/two_rubbers.toml
BETA_TIME_STEP_ERROR = "Yade 2023.02: 6.2e-3 at 400, 1.3e-3 at 1600 steps"


def mass_ratio(contact: Contact) -> float:
    """Yade's ``massR`` over the true effective mass: 1/2 at a wall (mass 0), else 1."""
    return 0.5 if contact.is_wall else 1.0


def yade_law(tc: float, en: float, et: float, q: float, F: float, m: float = 1.0,
             tangential: bool = True) -> tuple[float, float, float]:
    """Return what Yade's linear law restitutes: ``(e, beta, contact time)``, contact time in s.

    In closed form (:func:`vimpact.dem.laws.linear_spring_dashpot_force_end`: the
    normal force clipped at zero, the tangential spring and dashpot in stick).

    Parameters
    ----------
    tc : s; en, et : Yade's inputs, in (0, 1]
    q : ``massR / m_eff`` (:func:`mass_ratio`); F : contact-point mass factor
    m : effective mass, kg (cancels out)
    """
    mR = q * m
    L2n, L2t = linear.ln2(en), linear.ln2(et)
    kn = mR * (math.pi**2 + L2n) / tc**2
    cn = -2.0 * mR * math.log(en) / tc
    ks = 2.0 / 7.0 * mR * (math.pi**2 + L2t) / tc**2
    cs = -4.0 / 7.0 * mR * math.log(et) / tc
    w0 = math.sqrt(kn / m)
    zeta = cn / (2.0 * math.sqrt(kn * m))
    tan = None
    if tangential:
        w_t = math.sqrt(ks * F / m)
        tan = (w_t / w0, cs * F / (2.0 * m * w_t))
    e, beta, t = laws.linear_spring_dashpot_force_end(zeta, tan)
    return e, beta, t / w0


#: time steps per contact of the stepped law in the search of ``et`` (the reported beta: the
#: law's default, :data:`vimpact.dem.laws.FRICTION_STEPS`)
FIT_STEPS = 1000


def _tangential_law(tc: float, en: float, et: float, q: float, F: float
                    ) -> tuple[float, float, float, float]:
    """Yade's law in the units of :func:`vimpact.dem.laws.yade_coulomb`, per unit ``massR / q``.

    Returns ``(zeta, w_t, zeta_t, omega0)``: the normal damping ratio, the tangential
    oscillator of the contact point (angular frequency over ``omega0``, damping ratio)
    and ``omega0`` (1/s) for an effective mass of 1 kg; ``tc`` in s, the rest as in
    :func:`yade_law`.
    """
    mR = q
    kn = mR * (math.pi**2 + linear.ln2(en)) / tc**2
    cn = -2.0 * mR * math.log(en) / tc
    ks = 2.0 / 7.0 * mR * (math.pi**2 + linear.ln2(et)) / tc**2
    cs = -4.0 / 7.0 * mR * math.log(et) / tc
    w0n = math.sqrt(kn)
    w_t = math.sqrt(ks * F)
    return cn / (2.0 * math.sqrt(kn)), w_t / w0n, cs * F / (2.0 * w_t), w0n


def yade_oblique(tc: float, en: float, et: float, q: float, F: float, mu: float, w0,
                 steps: int | None = None, R: float | None = None, v=None) -> np.ndarray:
    """Return Yade's ``beta`` in oblique impacts with Coulomb friction ``mu`` at ``w0 = v_c0 / v_z0``.

    ``w0`` an array; the law stepped as Yade steps it (:func:`vimpact.dem.laws.yade_coulomb`).
    Without ``R``, the one-contact law: it scales with the speed, so ``beta`` depends on
    the angle only. With the sphere radius ``R`` (m) and the normal speeds ``v`` (m/s,
    like ``w0``): Yade's wall contact, whose contact point is on the wall plane (lever
    ``R - delta``), so that ``beta`` shifts by about ``delta/R`` with the speed.
    """
    case = dict(tc=tc, en=en, et=et, q=q, F=F, mu=mu, w0=w0, R=R, v=v)
    return yade_oblique_many([case], steps)[0].reshape(np.shape(w0))


def yade_oblique_many(cases: list[dict[str, Any]], steps: int | None = None) -> list[np.ndarray]:
    """:func:`yade_oblique` of several contacts (or candidates) in one stepped call.

    One case is :func:`yade_oblique` itself. ``cases``: one dict of :func:`yade_oblique`'s
    arguments per case (``tc``, ``en``, ``et``, ``q``, ``F``, ``mu``, ``w0``, and ``R``,
    ``v`` for Yade's wall contact); every point of every case is stepped at once with its
    own constants (the law is elementwise), so each case gets exactly what it gets alone.
    """
    cols: dict[str, list[np.ndarray]] = {k: [] for k in ("zeta", "w_t", "zeta_t", "F", "mu",
                                                          "w0", "rho")}
    for cs in cases:
        w0 = np.asarray(cs["w0"], dtype=float).ravel()
        zeta, w_t, zeta_t, w0n = _tangential_law(cs["tc"], cs["en"], cs["et"], cs["q"], cs["F"])
        for k, val in (("zeta", zeta), ("w_t", w_t), ("zeta_t", zeta_t), ("F", cs["F"]),
                       ("mu", cs["mu"])):
            cols[k].append(np.full(w0.size, float(val)))
        cols["w0"].append(w0)
        # an infinite radius (in v0/omega0) is the arm R of the one-contact law
        cols["rho"].append(np.full(w0.size, math.inf) if cs.get("R") is None else
                           np.broadcast_to(cs["R"] * w0n / np.asarray(cs["v"], dtype=float),
                                           w0.shape))
    flat = {k: np.concatenate(v) for k, v in cols.items()}
    beta = laws.yade_coulomb(flat["zeta"], flat["w_t"], flat["zeta_t"], flat["F"], flat["mu"],
                             flat["w0"], steps or laws.FRICTION_STEPS, flat["rho"])[1]
    return np.split(beta, np.cumsum([np.size(cs["w0"]) for cs in cases])[:-1])


def _en_for(target: float, q: float) -> float:
    """Yade's ``en`` input for which it restitutes ``target`` (normal law only).

    Bisection on ``en`` with Yade's law (:func:`yade_law`, in closed form) down to
    neighbouring numbers.
    """
    def e_of(en: float) -> float:
        return yade_law(1.0, en, 1.0, q, 3.5, tangential=False)[0]

    lo, hi = 1e-6, 1.0
    if target >= 1.0:
        return 1.0
    if target <= e_of(lo):
        return lo
    for _ in range(80):  # e_of increases with en
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):  # lo and hi are neighbouring numbers: no step changes them
            break
        lo, hi = (mid, hi) if e_of(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    """Fit Yade's ``en``, ``et`` and contact time ``tc`` (s) per contact.

    ``en`` gives the constant closest to vimpact's ``e_z`` (Yade clips the normal
    force at zero), ``tc`` makes the contact last the Hertz contact time, ``et`` is
    fitted to vimpact's ``beta_x`` (oblique impacts with the contact's friction,
    else full stick); the oblique fits of all contacts run in lockstep
    (:func:`vimpact.dem.fit.fit_scalar_many`), every round's candidates in one stepped
    call (:func:`yade_oblique_many`).
    """
    fits = []
    oblique: dict[int, dict[str, Any]] = {}  # contact index -> its yade_oblique arguments
    for i, c in enumerate(problem.contacts):
        t = targets[c.key]
        q, F = mass_ratio(c), linear.mass_factor(c)
        e_const, _ = fit_constant(t.e_z, 1e-6, 1.0)
        en = _en_for(e_const, q)
        t_h = linear.hertz_time(c, problem.speeds)
        # tc such that Yade's contact lasts t_h: the contact time scales with tc
        tc = t_h / yade_law(1.0, en, 1.0, q, F, tangential=False)[2]
        e_code = yade_law(tc, en, 1.0, q, F, tangential=False)[0]
        e = np.full_like(t.e_z, e_code)
        notes = ["speed-independent restitution: the residual is vimpact's speed dependence",
                 f"Yade clips the normal force at zero{' and gives a wall mass 0' if c.is_wall else ''}:"
                 f" its input en = {en:.6g} restitutes {e_code:.6g}",
                 "tc: Yade's contact lasts the Hertz contact time at the geometric mean speed"]
        if abs(F - 3.5) > 1e-9:
            notes.append(f"contact-point mass factor {F:.4g} (not 3.5: not solid spheres); "
                         "et is fitted with it")
        b = res_b = None
        et = 1.0
        ob = t.oblique
        if ob is not None:  # et: below, all contacts' searches in lockstep
            # Yade's wall contact point: on the wall plane, lever R - delta
            oblique[i] = dict(tc=tc, en=en, q=q, F=F, mu=c.mu, w0=ob.w0,
                              R=ob.R if c.is_wall else None, v=ob.v if c.is_wall else None)
        elif t.beta_x is not None:
            def beta(x: float) -> np.ndarray:
                return np.full_like(t.beta_x, yade_law(tc, en, x, q, F)[1])

            et, b = fit_scalar(beta, t.beta_x, 1e-6, 1.0)
            res_b = Residual.of(b, t.beta_x)
            if float(np.mean(t.beta_x)) <= 0.0:
                notes.append("beta_x: vimpact's mean <= 0 (no reversal): et cannot reach it")
        mu = c.mu if math.isfinite(c.mu) else STICK_MU
        fits.append(ContactFit(c, {"tc": tc, "en": en, "et": et, "frictAngle": math.atan(mu),
                                   "mu": c.mu, "e_yade": e_code, "t_contact": t_h},
                               e, b, Residual.of(e, t.e_z), res_b, notes))
    if oblique:
        _fit_oblique_et(problem, targets, fits, oblique)
    return fits


def _fit_oblique_et(problem: DemProblem, targets: dict[str, Targets], fits: list[ContactFit],
                    oblique: dict[int, dict[str, Any]]) -> None:
    """Fit ``et`` of the contacts ``oblique`` (index -> :func:`yade_oblique`'s arguments).

    One ``et`` per contact closest to vimpact's oblique impacts with the contact's
    friction, all contacts' searches in lockstep; completes their fits in place.
    """
    keys = list(oblique)
    obs = [ob for i in keys if (ob := targets[problem.contacts[i].key].oblique) is not None]

    def predict(jobs: list[tuple[int, float]]) -> list[np.ndarray]:
        return yade_oblique_many([dict(oblique[keys[s]], et=x) for s, x in jobs], FIT_STEPS)

    ets = fit_scalar_many(predict, [ob.beta_x for ob in obs], [1e-6] * len(keys),
                          [1.0] * len(keys))
    betas = yade_oblique_many([dict(oblique[i], et=et) for i, et in zip(keys, ets)])
    for i, ob, et, b_ob in zip(keys, obs, ets, betas):
        f, a = fits[i], oblique[i]
        c, t = f.contact, targets[f.contact.key]
        f.params["et"] = et
        f.beta_oblique = b_ob
        f.res_beta_x = Residual.of(b_ob, ob.beta_x)
        if t.beta_x is not None:
            f.beta_x = np.full_like(t.beta_x, yade_law(a["tc"], a["en"], et, a["q"], a["F"])[1])
        f.notes.append(f"et = {et:.4g} fitted to vimpact's oblique impacts with mu = {c.mu:g} "
                       "over the impact angles" + (
                           " (at a wall Yade's contact point is on the wall plane, lever "
                           "R - delta: its beta shifts with the speed by about delta/R; "
                           "included)" if c.is_wall
                           else " (Yade's linear law: beta depends on the angle only)"))


def time_step(fits: list[ContactFit], steps_per_contact: int = STEPS_PER_CONTACT) -> float:
    """``O.dt`` (s): the shortest contact time over ``steps_per_contact``."""
    return min(f.params["t_contact"] for f in fits) / steps_per_contact


def render(problem: DemProblem, fits: list[ContactFit],
           steps_per_contact: int = STEPS_PER_CONTACT) -> dict[str, str]:
    """``yade_materials.py``: run it with ``exec`` in your Yade script before creating bodies."""
    names = [t.name for t in problem.types] + [w.name for w in problem.walls]
    density = {t.name: t.density for t in problem.types}
    # each material's own values: those of its first contact (Yade checks that all materials
    # define the same variables; the MatchMakers decide the values)
    first: dict[str, dict] = {}
    for f in fits:
        for nm in (f.contact.first.name, f.contact.second.name):
            first.setdefault(nm, f.params)
    dt = time_step(fits, steps_per_contact)
    lines = [
        "# Yade input written by `vimpact dem` (SI units: m, kg, s)",
        f"# from {problem.source}; speeds {problem.speeds.min():g}..{problem.speeds.max():g} m/s",
        "# Use: exec(open('yade_materials.py').read()) in your script BEFORE creating bodies; then",
        "#   spheres: sphere(..., material=vimpact_mat['TYPE']);"
        " walls: wall(..., material=vimpact_mat['WALL'])",
        "#   O.engines = [ForceResetter(), InsertionSortCollider([...]),",
        "#                InteractionLoop([...geometry functors...], [vimpact_ip2], [vimpact_law]),",
        "#                NewtonIntegrator(damping=0.0)]   # Yade's default damping 0.2 changes e",
        f"#   O.dt = vimpact_dt   # {steps_per_contact} steps per shortest contact",
        "# Walls must have mass 0 (Yade's wall() default): en at walls is fitted for that.",
        "from yade import *",
        "vimpact_mat = {}",
    ]
    for nm in names:
        p = first[nm]
        rho = density.get(nm, 1000.0)
        kind = "" if nm in density else "  # wall (density unused)"
        lines.append(f"vimpact_mat[{nm!r}] = O.materials.append(ViscElMat(label={nm!r}, "
                     f"density={rho:.8g}, tc={p['tc']:.10g}, en={p['en']:.10g}, "
                     f"et={p['et']:.10g}, frictionAngle={p['frictAngle']:.10g})){kind}")
    lines.append("_m = vimpact_mat")
    lines.append("vimpact_ip2 = Ip2_ViscElMat_ViscElMat_ViscElPhys(")
    for attr in ("tc", "en", "et", "frictAngle"):
        rows = ", ".join(f"(_m[{f.contact.first.name!r}], _m[{f.contact.second.name!r}], "
                         f"{f.params[attr]:.10g})" for f in fits)
        lines.append(f"    {attr}=MatchMaker(matches=({rows},)),")
    lines += [")", "vimpact_law = Law2_ScGeom_ViscElPhys_Basic()",
              f"vimpact_dt = {dt:.10g}  # s", ""]
    return {"yade_materials.py": "\n".join(lines)}


# ---- running Yade itself (round trip) -------------------------------------

#: the Yade executable (Debian package ``yade``)
YADE = "yade"

_DRIVER = r"""
import json
results = []
for part in {parts!r}:
    O.reset()
    exec(open(part["materials"]).read())
    cases = part["cases"]
    walls_needed = sorted({{c["wall"] for c in cases if c["wall"]}})
    for w in walls_needed:
        O.bodies.append(wall(0.0, axis=2, material=vimpact_mat[w]))
    runs = []
    x = 0.0
    for c in cases:
        R1, R2, v = c["R1"], c["R2"], c["v"]
        x += 4.0 * (R1 + (R2 or R1)) + 0.01
        gap = 1e-3 * R1
        if c["wall"]:
            b1 = O.bodies.append(sphere((x, 0.0, R1 + gap), R1, material=vimpact_mat[c["first"]]))
            O.bodies[b1].state.vel = Vector3(c.get("vt", 0.0), 0.0, -v)
            runs.append((b1, None))
        else:
            z = 1.0  # far above any wall; the pair collides along x
            b1 = O.bodies.append(sphere((x - R1 - gap / 2, 0.0, z), R1, material=vimpact_mat[c["first"]]))
            b2 = O.bodies.append(sphere((x + R2 + gap / 2, 0.0, z), R2, material=vimpact_mat[c["second"]]))
            m1, m2 = O.bodies[b1].state.mass, O.bodies[b2].state.mass
            O.bodies[b1].state.vel = Vector3(v * m2 / (m1 + m2), 0.0, 0.0)
            O.bodies[b2].state.vel = Vector3(-v * m1 / (m1 + m2), 0.0, 0.0)
            runs.append((b1, b2))
    O.engines = [ForceResetter(),
                 InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                                 [vimpact_ip2], [vimpact_law]),
                 NewtonIntegrator(damping=0.0)]
    O.dt = part["dt"]
    O.run(part["steps"], True)
    out = []
    for c, (b1, b2) in zip(cases, runs):
        if b2 is None:
            e = O.bodies[b1].state.vel[2] / c["v"]
        else:
            e = (O.bodies[b2].state.vel[0] - O.bodies[b1].state.vel[0]) / c["v"]
        out.append(dict(c, e=float(e), vx_end=float(O.bodies[b1].state.vel[0]),
                        spin=float(O.bodies[b1].state.angVel[1])))
    results.append({{"rows": out, "open": O.interactions.countReal()}})
json.dump(results, open({result!r}, "w"))
"""


def yade_available() -> str | None:
    """``None`` if the ``yade`` executable can be run, else why not."""
    import shutil

    if shutil.which(YADE) is None:
        return "the 'yade' executable is not on PATH (Debian: apt-get install yade)"
    return None


def round_trip(problem: DemProblem, speeds, steps_per_contact: int = STEPS_PER_CONTACT,
               fits: list[ContactFit] | None = None, timeout: float = 600.0,
               angles_deg=None, contacts=None, head_on: bool | None = None) -> list[dict]:
    """Run Yade once with the exported ``yade_materials.py`` on head-on collisions of every contact.

    The file is used unchanged; nominal sizes, ``speeds`` in m/s. One dict per
    collision with ``contact``, ``v``, ``e`` (Yade's, from its velocities) and
    ``predicted`` (the report's).

    With ``angles_deg``: oblique impacts of the wall contacts only, at those angles from
    the normal (``v_c0 = v tan(angle)``, no spin); each row also has ``angle``, ``beta``
    (Yade's ``-v_c,end / v_c0``, ``v_c = v_x - R omega_y`` from its velocity and spin)
    and ``predicted_beta`` (the report's law, :func:`yade_oblique`); ``head_on=True``
    adds the head-on collisions of every contact to the same run (one Yade start for
    both). ``contacts``: the keys of the contacts whose rows are returned (default: every
    contact). Several time steps in one Yade start: :func:`round_trips`.
    """
    return round_trips(problem, speeds, [steps_per_contact], fits, timeout, angles_deg,
                       contacts, head_on)[steps_per_contact]


def round_trips(problem: DemProblem, speeds, steps_per_contact, fits: list[ContactFit] | None = None,
                timeout: float = 600.0, angles_deg=None, contacts=None,
                head_on: bool | None = None) -> dict[int, list[dict]]:
    """Return :func:`round_trip`'s rows at each of the time steps ``steps_per_contact``.

    One Yade start: each time step is a scene of its own (``O.reset()``, the file it
    was exported with run again), one after another; a dict from steps per contact to
    rows.
    """
    import json
    import os
    import subprocess
    import tempfile

    if fits is None:
        from vimpact.dem.export import export

        fits = export(problem, CODE).fits
    if head_on is None:
        head_on = angles_deg is None
    cases = []
    for f in fits:
        c = f.contact
        angles = list(angles_deg) if angles_deg is not None and c.is_wall else []
        second = c.second
        R2 = None if isinstance(second, WallType) else second.radius
        for v in speeds:
            for ang in ([None] if head_on else []) + angles:
                case: dict[str, Any] = {
                    "contact": c.key, "first": c.first.name, "second": second.name,
                    "wall": second.name if c.is_wall else None, "v": float(v),
                    "R1": c.first.radius, "R2": R2, "predicted": float(f.params["e_yade"])}
                if ang is not None:
                    case.update(angle=float(ang), vt=float(v) * math.tan(math.radians(ang)))
                cases.append(case)
        if angles:  # the report's beta of all this contact's oblique impacts in one call
            p = f.params
            mine = [cs for cs in cases if cs["contact"] == c.key and "angle" in cs]
            v_all = np.array([cs["v"] for cs in mine])
            beta = yade_oblique(p["tc"], p["en"], p["et"], mass_ratio(c), linear.mass_factor(c),
                                p["mu"], np.array([math.tan(math.radians(cs["angle"]))
                                                   for cs in mine]),
                                R=c.first.radius, v=v_all)
            for cs, b in zip(mine, beta):
                cs["predicted_beta"] = float(b)
    t_end = max(1e-3 * cs["R1"] / cs["v"] for cs in cases) + 3.0 * max(
        f.params["t_contact"] for f in fits)
    steps_list = [int(n) for n in steps_per_contact]
    with tempfile.TemporaryDirectory() as tmp:
        parts = []
        for n in steps_list:
            mats = os.path.join(tmp, f"{n}", "yade_materials.py")
            os.makedirs(os.path.dirname(mats), exist_ok=True)
            with open(mats, "w") as fh:
                fh.write(render(problem, fits, n)["yade_materials.py"])
            dt = time_step(fits, n)
            parts.append({"materials": mats, "cases": cases, "dt": dt,
                          "steps": int(math.ceil(t_end / dt))})
        drv, res = os.path.join(tmp, "drive.py"), os.path.join(tmp, "out.json")
        with open(drv, "w") as fh:
            fh.write(_DRIVER.format(parts=parts, result=res))
        proc = subprocess.run([YADE, "-n", "-x", drv], cwd=tmp, capture_output=True, text=True,
                              timeout=timeout, env=dict(os.environ, OMP_NUM_THREADS="1"))
        if not os.path.exists(res):
            raise RuntimeError(f"Yade failed: {(proc.stdout + proc.stderr).strip()[-2000:]}")
        with open(res) as fh:
            results = json.load(fh)
    out = {}
    for n, data in zip(steps_list, results):
        if data["open"]:
            raise RuntimeError(f"Yade round trip: {data['open']} contacts still open at the end "
                               f"({n} steps per contact)")
        rows = data["rows"]
        for r in rows:
            if "vt" in r:
                r["beta"] = -(r["vx_end"] - r["R1"] * r["spin"]) / r["vt"]
        out[n] = [r for r in rows if contacts is None or r["contact"] in contacts]
    return out


if __name__ == "__main__":  # python -m vimpact.dem.yade SETUP.toml [STEPS_PER_CONTACT]
    from vimpact.dem.report import round_trip_main

    round_trip_main("Yade", yade_available, round_trip, STEPS_PER_CONTACT,
                    oblique=CODE)
