"""REBOUND: a hard-sphere code; it takes a Python callback ``e(v)``.

The export is a module with vimpact's ``e_z`` at the fitted speeds of every
contact (nominal sizes) and a function ``coefficient_of_restitution(sim, v)``
to pass as ``sim.coefficient_of_restitution`` (with
``sim.collision_resolve = "hardsphere"``). It interpolates linearly in
``log v`` and holds the end values outside the fitted range. REBOUND calls it
with the impact speed only, so one curve serves every particle pair: the
module uses ``CONTACT`` (the first particle-particle contact unless changed)
and has one function per contact for a custom collision resolver. No walls,
no tangential restitution. The residual reported is the interpolation
error at the geometric midpoints between the fitted speeds.
"""

from __future__ import annotations

import numpy as np

from vimpact.dem.fit import ContactFit, Residual, Targets
from vimpact.dem.problem import DemProblem
from vimpact.engine.pairs import pair_restitution

CODE = "rebound"
TANGENTIAL = False


def interpolate(v_table: np.ndarray, e_table: np.ndarray, v) -> np.ndarray:
    """Return the callback's ``e`` at speeds ``v`` (m/s): linear in ``log v``, end values held."""
    return np.interp(np.log(np.asarray(v, dtype=float)), np.log(v_table), e_table)


def fit(problem: DemProblem, targets: dict[str, Targets], numerics=None) -> list[ContactFit]:
    """Tabulate vimpact's ``e_z`` at the fitted speeds per contact (nominal sizes).

    The residual is the interpolation error at the geometric midpoints between the
    speeds, against vimpact run there.
    """
    from vimpact.model.numerics import Numerics

    fits = []
    v = problem.speeds
    mid = np.sqrt(v[1:] * v[:-1]) if v.size > 1 else v
    for c in problem.contacts:
        t = targets[c.key]
        nom = t.nominal
        b1, b2 = c.levels()[len(c.levels()) // 2]
        check = pair_restitution(b1, b2, mid, numerics=numerics or Numerics.preset("fast"))
        e_mid = check["e_z"].to_numpy(dtype=float)
        pred = interpolate(t.v[nom], t.e_z[nom], mid)
        notes = ["REBOUND passes only the speed: one curve for all pairs (CONTACT in the module)",
                 "beta_x: not represented (hard spheres, normal restitution only)"]
        if c.is_wall:
            notes.append("walls: REBOUND has none; the curve is exported for a custom resolver")
        if len(set(t.level.tolist())) > 1:
            notes.append("size range: the curve is the nominal size's")
        f = ContactFit(c, {"v_m_s": t.v[nom].tolist(), "e_z": t.e_z[nom].tolist()},
                       interpolate(t.v[nom], t.e_z[nom], t.v), None,
                       Residual.of(pred, e_mid), None, notes)
        fits.append(f)
    return fits


def render(problem: DemProblem, fits: list[ContactFit]) -> dict[str, str]:
    """Return ``vimpact_restitution.py``, the module with REBOUND's callback ``e(v)``."""
    first = next((f for f in fits if not f.contact.is_wall), fits[0])
    lines = ['"""Coefficient of restitution for REBOUND, written by `vimpact dem`.',
             "",
             f"From {problem.source}. Use::",
             "",
             "    import vimpact_restitution as cor",
             '    sim.collision = "direct"',
             '    sim.collision_resolve = "hardsphere"',
             "    sim.coefficient_of_restitution = cor.coefficient_of_restitution",
             "",
             "Linear interpolation in log(v) of vimpact's e_z(v) (normal impact speed v, m/s),",
             "end values held outside the table. REBOUND passes only v, so CONTACT picks the",
             'one curve used for every pair."""',
             "", "import math", "", "TABLES = {"]
    for f in fits:
        lines.append(f"    {f.contact.key!r}: (")
        lines.append("        [" + ", ".join(f"{x:.10g}" for x in f.params["v_m_s"]) + "],")
        lines.append("        [" + ", ".join(f"{x:.10g}" for x in f.params["e_z"]) + "]),")
    lines += ["}", f"CONTACT = {first.contact.key!r}", "", "",
              "def restitution(v, contact=None):",
              '    """e_z at normal impact speed v (m/s) for a contact (default CONTACT)."""',
              "    vs, es = TABLES[contact or CONTACT]",
              "    v = abs(v)",
              "    if v <= vs[0]:",
              "        return es[0]",
              "    if v >= vs[-1]:",
              "        return es[-1]",
              "    x = math.log(v)",
              "    for k in range(1, len(vs)):",
              "        if v <= vs[k]:",
              "            a, b = math.log(vs[k - 1]), math.log(vs[k])",
              "            return es[k - 1] + (es[k] - es[k - 1]) * (x - a) / (b - a)",
              "    return es[-1]",
              "", "",
              "def coefficient_of_restitution(sim_pointer, v):",
              '    """The REBOUND callback: restitution at relative normal speed v."""',
              "    return restitution(v)", ""]
    return {"vimpact_restitution.py": "\n".join(lines)}
