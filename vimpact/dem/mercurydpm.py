"""MercuryDPM: Hertzian BSHP viscoelastic species (Brilliantov's law) with mixed species.

The normal law is the viscoelastic Hertz law ``F = k_n d^1.5 + 1.5 A k_n
d^0.5 dd/dt`` with ``k_n = 4/3 E*``; each species takes the effective modulus
``E*`` and the dissipation ``A`` (s) of contacts between its own particles,
and ``speciesHandler.getMixedObject(a, b)`` those of a type pair (walls are
species too), so a full pair matrix is represented, and ``A`` does not carry
the mass (exact over a size range, unlike LAMMPS' ``eta_n0``). The fit
assumes the force is clipped at zero (no attraction); if your build lets it
pull, the restitution is lower (MercuryDPM's
``HertzianBSHPViscoelasticInteraction::computeNormalForce`` clips it).

Species: ``HertzianBSHPViscoelasticMindlinSpecies`` (header
``Species/HertzianBSHPViscoelasticMindlinSpecies.h``; the normal species with
``MindlinSpecies``). Tangential (``MindlinInteraction::computeFrictionForce``):
a spring ``(2/3) K_t0 xi`` with ``K_t0 = 8 G a`` (``G`` from
``setEffectiveShearModulus``) and, while the spring force is below the Coulomb
limit, a dashpot ``c sqrt(m_eff K_t0)`` (``c`` from ``setSlidingDissipation``);
at the limit the force is ``mu`` times the normal force and the spring is reset.
``G`` and ``c`` are fitted to vimpact's ``beta_x``: with the contact's friction
(``setSlidingFrictionCoefficient``) over the set-up's impact angles, or in full
stick without friction, by stepping that law
(:func:`vimpact.dem.laws.mercury_mindlin_coulomb`). Not run here (no Debian or
PyPI build of MercuryDPM): the class, header, setter names and the force law
were read from MercuryDPM's sources (``Kernel/Species``,
``Kernel/Interactions``), not compiled.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from vimpact.dem import laws, linear
from vimpact.dem.fit import (
    ContactFit,
    Residual,
    Targets,
    fit_viscoelastic_hertz,
    grid_search_many,
    lockstep_costs,
)
from vimpact.dem.problem import Contact, DemProblem

CODE = "mercurydpm"
TANGENTIAL = True
#: nominal speeds of the full-stick tangential fit (contacts without friction)
TANGENTIAL_FIT_POINTS = 4
#: steps per contact of the stepped law inside the tangential search (the reported
#: prediction uses :data:`vimpact.dem.laws.FRICTION_STEPS`)
FIT_STEPS = 1000
#: start and half-widths of the tangential grid search, ``(ln(G / G_relaxed), ln c_t)``
SEARCH_START, SEARCH_HALF_WIDTH = (0.0, math.log(0.3)), (1.0, 1.5)
#: friction written for a contact without one (stick)
STICK_MU = 1.0e6
SPECIES = "HertzianBSHPViscoelasticMindlinSpecies"
HEADER = "Species/HertzianBSHPViscoelasticMindlinSpecies.h"


def mercury_beta(c: Contact, A: float, G, c_t, mu: float, v, R, m, w0,
                 steps: int | None = None) -> np.ndarray:
    """Return MercuryDPM's ``beta`` for the contact ``c`` (:func:`vimpact.dem.laws.mercury_mindlin_coulomb`).

    With dissipation time ``A`` (s), effective shear modulus ``G`` (Pa),
    sliding dissipation ``c_t`` and friction ``mu``, at normal speeds ``v`` (m/s),
    effective radius ``R`` (m) and mass ``m`` (kg), and ``w0 = v_c0 / v_z0`` (arrays;
    ``G`` and ``c_t`` numbers, or arrays of candidates that broadcast with them).
    """
    alpha, K, D, F, mu_, w0_ = _mercury_law(c, A, G, c_t, mu, v, R, m, w0)
    return laws.mercury_mindlin_coulomb(alpha, K, D, F, mu_, w0_,
                                        steps or laws.FRICTION_STEPS)[1]


def _mercury_law(c: Contact, A: float, G, c_t, mu: float, v, R, m, w0) -> tuple:
    """Return the arguments ``(alpha, K, D, F, mu, w0)`` of :func:`vimpact.dem.laws.mercury_mindlin_coulomb`.

    For :func:`mercury_beta` (same parameters and units).
    """
    E = c.E_star
    d = laws.hertz_overlap(E, R, m, v)
    D = c_t * np.sqrt(8.0 * G * m) * (R * d)**0.25 * v / (4.0 / 3.0 * E * np.sqrt(R) * d**1.5)
    return A * v / d, 4.0 * G / E, D, linear.mass_factor(c), mu, w0


def _tangential_points(c: Contact, t: Targets) -> tuple:
    """Return the points of the tangential fit of ``c``: ``(v, R, m, w0, target, mu)``.

    The oblique impacts with the contact's friction (``t.oblique``), else full stick
    at a few nominal speeds (``mu`` infinite); speeds in m/s, ``R`` in m, ``m`` in kg.
    """
    ob = t.oblique
    if ob is not None:
        v, R, m, w0, target, mu = ob.v, ob.R, ob.m, ob.w0, ob.beta_x, ob.mu
    elif t.beta_x is None:
        raise ValueError(f"contact {c.key}: no beta_x targets to fit (neither full stick nor "
                         "oblique); compute the targets with tangential=True")
    else:
        nominal = np.flatnonzero(t.nominal)
        pick = nominal[np.unique(np.linspace(0, nominal.size - 1, TANGENTIAL_FIT_POINTS)
                                 .round().astype(int))]
        v, R, m, target, mu = t.v[pick], t.R[pick], t.m[pick], t.beta_x[pick], math.inf
        w0 = np.ones_like(v)
    return v, R, m, w0, target, mu


def _search_tangential(items: list[tuple[Contact, Targets, float, float]]) -> list[np.ndarray]:
    """Search ``(ln(G / G0), ln c_t)`` of several contacts in lockstep.

    ``items``: ``(contact, targets, A, G0)`` per contact (``A`` in s, ``G0`` the
    relaxed shear modulus, Pa). Every round of :func:`vimpact.dem.fit.grid_search_many`
    steps the candidates of every running search at all their points in one call of
    :func:`vimpact.dem.laws.mercury_mindlin_coulomb` (per-point ``F`` and ``mu``); the
    stepped law is elementwise, so each search's costs are those of its own search alone.
    Returns the best point of each search.
    """
    points = [_tangential_points(c, t) for c, t, _, _ in items]

    def arguments(i: int, z: np.ndarray) -> tuple:
        c, _, A, G0 = items[i]
        v, R, m, w0, _, mu = points[i]
        return _mercury_law(c, A, G0 * np.exp(z[:, :1]), np.exp(z[:, 1:]), mu, v, R, m, w0)

    costs = lockstep_costs(functools.partial(laws.mercury_mindlin_coulomb, steps=FIT_STEPS),
                           arguments, [p[4] for p in points])
    n = len(items)
    return grid_search_many(costs, [SEARCH_START] * n, [SEARCH_HALF_WIDTH] * n,
                            [(-5.0, math.log(1e-6))] * n, [(5.0, math.log(1e6))] * n)


def _fit_tangential(c: Contact, t: Targets, A: float, G0: float, z: np.ndarray | None = None):
    """Fit MercuryDPM's effective shear modulus (Pa) and sliding dissipation to ``beta_x``.

    Closest to vimpact's ``beta_x`` in RMS, over the oblique impacts with the
    contact's friction (``t.oblique``), else in full stick at a few nominal
    speeds (:func:`_search_tangential`; ``z`` its result when already searched).
    Returns ``(G, c_t, beta at the fit points, target, basis)``.
    """
    v, R, m, w0, target, mu = _tangential_points(c, t)
    if z is None:
        z = _search_tangential([(c, t, A, G0)])[0]
    G, c_t = G0 * math.exp(float(z[0])), math.exp(float(z[1]))
    return G, c_t, mercury_beta(c, A, G, c_t, mu, v, R, m, w0), target, t.oblique is not None


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    """Fit each contact's species: dissipation ``A`` (s) to ``e_z``, Mindlin constants to ``beta_x``.

    The effective modulus is the pair's ``E*`` (Pa); the effective shear modulus
    (Pa) and sliding dissipation are fitted when vimpact's ``beta_x`` is among the
    targets. In phases: the normal law of every contact; the tangential searches in
    lockstep (:func:`_search_tangential`); the rest per contact.
    """
    normal = []
    for c in problem.contacts:
        t = targets[c.key]
        A, e = fit_viscoelastic_hertz(t, c.E_star)
        mat = c.material
        G0 = mat.G_inf / (2.0 - mat.nu)  # Mindlin: 8 G* a with G* of the pair's half-space
        normal.append((c, t, A, e, G0))
    tangential = [(c, t, A, G0) for c, t, A, _, G0 in normal
                  if t.beta_x is not None or t.oblique is not None]
    searched = {c.key: z for (c, *_), z in zip(tangential, _search_tangential(tangential))}
    fits = []
    for c, t, A, e, G0 in normal:
        params = {"effectiveElasticModulus": c.E_star, "dissipation": A,
                  "effectiveShearModulus": G0, "slidingDissipation": 0.0, "mu": c.mu}
        notes = []
        b = res_b = b_ob = None
        if t.beta_x is not None or t.oblique is not None:
            G, c_t, b_fit, target, oblique = _fit_tangential(c, t, A, G0, searched.get(c.key))
            params["effectiveShearModulus"], params["slidingDissipation"] = G, c_t
            res_b = Residual.of(b_fit, target)
            if oblique:
                b_ob = b_fit
            elif t.beta_x is not None:
                R_, m_ = t.R, t.m
                b = mercury_beta(c, A, G, c_t, math.inf, t.v, R_, m_, np.ones_like(t.v))
                res_b = Residual.of(b, t.beta_x)
            notes.append(
                f"beta_x: effective shear modulus {G:.4g} Pa ({G / G0:.3g} x G/(2 - nu) of the "
                f"pair) and sliding dissipation {c_t:.4g} fitted "
                + (f"with the contact's friction mu = {c.mu:g} over the impact angles "
                   "(residual over those oblique impacts)" if oblique else "in full stick")
                + "; MercuryDPM's Mindlin law as read from its sources "
                  "(spring (2/3) 8 G a, dashpot c sqrt(m_eff 8 G a) below the Coulomb "
                  "limit), not run")
        fits.append(ContactFit(c, params, e, b, Residual.of(e, t.e_z), res_b, notes, b_ob))
    return fits


def render(problem: DemProblem, fits: list[ContactFit]) -> dict[str, str]:
    """Return ``mercurydpm_species.cpp``: the species and mixed species of the fits (SI units).

    To be pasted into a driver's ``setupInitialConditions()`` before particles and
    walls are created.
    """
    ident = {t.index: f"s_{t.name}" for t in problem.types}
    ident.update({w.index: f"s_{w.name}" for w in problem.walls})
    lines = ["// MercuryDPM species written by `vimpact dem` (SI units)",
             f"// from {problem.source}; speeds {problem.speeds.min():g}..{problem.speeds.max():g} m/s",
             "// Put the #include at the top of your driver and the rest inside setupInitialConditions()",
             "// (or your constructor), before particles and walls are created.",
             f"#include \"{HEADER}\""]
    for t in problem.types:
        lines.append(f"auto {ident[t.index]} = speciesHandler.copyAndAddObject({SPECIES}());")
        lines.append(f"{ident[t.index]}->setDensity({t.density:.8g});  // kg/m^3")
    for w in problem.walls:
        lines.append(f"auto {ident[w.index]} = speciesHandler.copyAndAddObject({SPECIES}());"
                     f"  // wall {'(rigid)' if w.material is None else ''}; wall->setSpecies(...)")
        lines.append(f"{ident[w.index]}->setDensity(1.0);  // not used by a fixed wall")
    for f in fits:
        a, b = ident[f.contact.first.index], ident[f.contact.second.index]
        target = a if a == b else f"speciesHandler.getMixedObject({a}, {b})"
        p = f.params
        mu = p["mu"] if math.isfinite(p["mu"]) else STICK_MU
        lines.append(f"// {f.contact.key}")
        lines.append(f"{target}->setEffectiveElasticModulus({p['effectiveElasticModulus']:.10g});  // Pa")
        lines.append(f"{target}->setDissipation({p['dissipation']:.10g});  // A, s")
        lines.append(f"{target}->setEffectiveShearModulus({p['effectiveShearModulus']:.10g});"
                     "  // Pa, Mindlin")
        lines.append(f"{target}->setSlidingDissipation({p['slidingDissipation']:.10g});"
                     "  // c in c sqrt(m_eff K_t0)")
        lines.append(f"{target}->setSlidingFrictionCoefficient({mu:.6g});")
    return {"mercurydpm_species.cpp": "\n".join(lines) + "\n"}
