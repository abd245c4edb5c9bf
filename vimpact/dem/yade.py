"""Yade: ``ViscElMat(tc, en, et)`` with ``MatchMaker`` for type pairs.

``ViscElMat`` is a linear spring-dashpot. From the contact time ``tc`` and
the restitutions it sets, per contact of effective mass ``m``,
``kn = m (pi^2 + ln^2 en) / tc^2``, ``cn = -2 m ln(en) / tc`` and
``ks = 2/7 m (pi^2 + ln^2 et) / tc^2``, ``cs = -2 (2/7) m ln(et) / tc``
(the 2/7 is the contact-point mass of solid spheres). The contact ends
when the overlap does, so the normal restitution is ``en`` at every speed
(integrated here: to 1e-12) and the export is the constant closest to
vimpact's ``e_z(v)``. ``et`` is fitted by running the linear law in stick
(normal and tangential together, with the pair's real contact-point mass
factor) against vimpact's full-stick ``beta_x(v)``; a target ``beta_x <= 0``
(no reversal) cannot be reached (``et`` gives ``beta`` in ``(0, 1]``). ``tc`` is
the Hertz contact time at the geometric mean speed; it does not change
``en`` or ``et``. Pair values go through ``MatchMaker(matches=((id1, id2,
value), ...))`` on ``Ip2_ViscElMat_ViscElMat_ViscElPhys``; attribute names
as in current Yade, check against your version.
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.dem import linear
from vimpact.dem.fit import ContactFit, Residual, Targets, fit_constant, fit_scalar
from vimpact.dem.problem import DemProblem

CODE = "yade"
TANGENTIAL = True


def _beta(en: float, et: float, F: float) -> float:
    """Yade's tangential restitution in stick with contact-point mass factor ``F``:
    ``w_t^2 = ks F / m`` over ``omega0^2 = kn / m``, ``zeta_t = cs F / (2 m w_t)``."""
    w_t = math.sqrt(2.0 / 7.0 * F * (math.pi**2 + linear.ln2(et)) / (math.pi**2 + linear.ln2(en)))
    zeta_t = (math.sqrt(2.0 / 7.0 * F) * abs(math.log(et)) / math.sqrt(math.pi**2 + linear.ln2(et))
              if et < 1.0 else 0.0)
    return linear.tangential_beta(en, w_t, zeta_t)


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    fits = []
    for c in problem.contacts:
        t = targets[c.key]
        en, _ = fit_constant(t.e_z, 1e-6, 1.0)
        e = np.full_like(t.e_z, linear.laws.linear_spring_dashpot(
            linear.laws.zeta_of_restitution(en), "overlap")[0])
        F = linear.mass_factor(c)
        notes = ["speed-independent en: the residual is vimpact's speed dependence",
                 "tc = Hertz contact time at the geometric mean speed (does not change en, et)"]
        if abs(F - 3.5) > 1e-9:
            notes.append(f"contact-point mass factor {F:.4g} (not 3.5: not solid spheres); "
                         "et is fitted with it")
        b = None
        res_b = None
        et = math.nan
        if t.beta_x is not None:
            target = float(np.mean(t.beta_x))
            if target <= 0.0:
                notes.append(f"beta_x: vimpact's mean {target:.3g} <= 0 (no reversal) cannot be "
                             "represented by et; et = 1e-6 written")
                et = 1e-6
                b = np.full_like(t.beta_x, _beta(en, et, F))
            else:
                et, b = fit_scalar(lambda x: np.full_like(t.beta_x, _beta(en, x, F)),
                                   t.beta_x, 1e-6, 1.0)
            res_b = Residual.of(b, t.beta_x)
        fits.append(ContactFit(c, {"tc": linear.hertz_time(c, problem.speeds), "en": en, "et": et,
                                   "mu": c.mu}, e, b, Residual.of(e, t.e_z), res_b, notes))
    return fits


def render(problem: DemProblem, fits: list[ContactFit]) -> dict[str, str]:
    names = [t.name for t in problem.types] + [w.name for w in problem.walls]
    own = {f.contact.first.name: f for f in fits
           if not f.contact.is_wall and f.contact.first is f.contact.second}
    lines = ["# Yade snippet written by `vimpact dem` (SI units)",
             f"# from {problem.source}; speeds {problem.speeds.min():g}..{problem.speeds.max():g} m/s",
             "from yade import *", "ids = {}"]
    for nm in names:
        f = own.get(nm)
        if f is not None:
            p = f.params
            mu = p["mu"] if math.isfinite(p["mu"]) else 1.0e6
            rho = f.contact.first.density
            lines.append(f"ids[{nm!r}] = O.materials.append(ViscElMat(label={nm!r}, density={rho:.8g}, "
                         f"tc={p['tc']:.8g}, en={p['en']:.8g}, et={p['et']:.8g}, "
                         f"frictionAngle={math.atan(mu):.8g}))")
        else:  # a wall: its own values come only through the matches below
            lines.append(f"ids[{nm!r}] = O.materials.append(ViscElMat(label={nm!r}, density=1000.0))"
                         "  # wall")
    pairs = [f for f in fits if f.contact.first is not f.contact.second]
    for attr in ("tc", "en", "et"):
        m = ", ".join(f"(ids[{f.contact.first.name!r}], ids[{f.contact.second.name!r}], "
                      f"{f.params[attr]:.8g})" for f in pairs)
        lines.append(f"mm_{attr} = MatchMaker(matches=({m},))" if pairs else f"mm_{attr} = None")
    lines += ["ip2 = Ip2_ViscElMat_ViscElMat_ViscElPhys()",
              "if mm_tc is not None:",
              "    ip2.tc, ip2.en, ip2.et = mm_tc, mm_en, mm_et",
              "# use ip2 in InteractionLoop([...], [ip2], [Law2_ScGeom_ViscElPhys_Basic()])"]
    return {"yade_materials.py": "\n".join(lines) + "\n"}
