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
``MindlinSpecies``): friction needs a tangential stiffness, so the Mindlin
part gets ``setEffectiveShearModulus(G/(2 - nu))`` of the pair material (the
Mindlin stiffness ``8 G* a`` of a rigid sphere on the pair's half-space) and
``setSlidingFrictionCoefficient(mu)``; its tangential dissipation is left at
MercuryDPM's default and ``beta_x`` is not fitted. Not run here (no Debian or
PyPI build of MercuryDPM): the class, header and setter names were read from
MercuryDPM's sources (``Kernel/Species``), not compiled.
"""

from __future__ import annotations

import math

from vimpact.dem.fit import ContactFit, Residual, Targets, fit_viscoelastic_hertz
from vimpact.dem.problem import DemProblem

CODE = "mercurydpm"
TANGENTIAL = False
SPECIES = "HertzianBSHPViscoelasticMindlinSpecies"
HEADER = "Species/HertzianBSHPViscoelasticMindlinSpecies.h"


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    fits = []
    for c in problem.contacts:
        t = targets[c.key]
        A, e = fit_viscoelastic_hertz(t, c.E_star)
        mat = c.material
        fits.append(ContactFit(c, {"effectiveElasticModulus": c.E_star, "dissipation": A,
                                   "effectiveShearModulus": mat.G_inf / (2.0 - mat.nu),
                                   "mu": c.mu}, e, None, Residual.of(e, t.e_z), None,
                               ["beta_x: not fitted (Mindlin tangential stiffness of the relaxed "
                                "pair material, MercuryDPM's default tangential dissipation)"]))
    return fits


def render(problem: DemProblem, fits: list[ContactFit]) -> dict[str, str]:
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
        mu = p["mu"] if math.isfinite(p["mu"]) else 1.0e6
        lines.append(f"// {f.contact.key}")
        lines.append(f"{target}->setEffectiveElasticModulus({p['effectiveElasticModulus']:.10g});  // Pa")
        lines.append(f"{target}->setDissipation({p['dissipation']:.10g});  // A, s")
        lines.append(f"{target}->setEffectiveShearModulus({p['effectiveShearModulus']:.10g});"
                     "  // Pa, Mindlin")
        lines.append(f"{target}->setSlidingFrictionCoefficient({mu:.6g});")
    return {"mercurydpm_species.cpp": "\n".join(lines) + "\n"}
