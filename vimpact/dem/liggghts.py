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
no tangential restitution input.
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.dem import laws
from vimpact.dem.fit import ContactFit, Residual, Targets, fit_constant
from vimpact.dem.problem import DemProblem

CODE = "liggghts"
TANGENTIAL = False
#: Young's modulus of a rigid wall relative to the stiffest particle type
RIGID_WALL_FACTOR = 1000.0


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    fits = []
    for c in problem.contacts:
        t = targets[c.key]
        e_in, _ = fit_constant(t.e_z, 1e-6, 1.0)
        e_code = laws.tsuji_hertz_e(e_in)  # what LIGGGHTS' law gives with that input
        e = np.full_like(t.e_z, e_code)
        notes = ["speed-independent restitution: the residual is vimpact's speed dependence",
                 "beta_x: not represented (no tangential restitution input)"]
        fits.append(ContactFit(c, {"coefficientRestitution": e_in, "mu": c.mu}, e, None,
                               Residual.of(e, t.e_z), None, notes))
    return fits


def _youngs(problem: DemProblem) -> list[tuple[float, float]]:
    out = [(2.0 * t.material.G_inf * (1.0 + t.material.nu), t.material.nu) for t in problem.types]
    stiffest = max(E for E, _ in out)
    for w in problem.walls:
        m = w.material
        out.append((RIGID_WALL_FACTOR * stiffest, 0.0) if m is None else
                   (2.0 * m.G_inf * (1.0 + m.nu), m.nu))
    return out


def render(problem: DemProblem, fits: list[ContactFit]) -> dict[str, str]:
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
    lines = ["# LIGGGHTS lines written by `vimpact dem` (units si)",
             f"# from {problem.source}; speeds {problem.speeds.min():g}..{problem.speeds.max():g} m/s",
             "# atom types: " + ", ".join(f"{k + 1} = {nm}" for k, nm in enumerate(names)),
             "# walls are atom types of their own (fix mesh/surface ... type N)",
             "# wall-wall matrix entries are placeholders (never used)"]
    if any(w.material is None for w in problem.walls):
        lines.append(f"# rigid wall: Young's modulus {RIGID_WALL_FACTOR:g} x the stiffest particle type")
    lines += [
        "fix m1 all property/global youngsModulus peratomtype " + " ".join(f"{E:.8g}" for E, _ in Y),
        "fix m2 all property/global poissonsRatio peratomtype " + " ".join(f"{nu:.6g}" for _, nu in Y),
        f"fix m3 all property/global coefficientRestitution peratomtypepair {n} "
        + " ".join(f"{x:.6f}" for x in e.ravel()),
        f"fix m4 all property/global coefficientFriction peratomtypepair {n} "
        + " ".join(f"{x:.6g}" for x in mu.ravel()),
        "pair_style gran model hertz tangential history",
        "pair_coeff * *",
    ]
    return {"liggghts.in": "\n".join(lines) + "\n"}
