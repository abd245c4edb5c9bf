"""MFiX-DEM: the linear spring-dashpot model (``DES_COLL_MODEL = 'LSD'``).

MFiX takes the normal restitution as ``DES_EN_INPUT``, the upper triangle
over solids phases (``e11 e12 ... e1N e22 ... eNN``), and
``DES_EN_WALL_INPUT`` per phase, and derives the damping
``eta_n = 2 sqrt(k_n m_eff) |ln e| / sqrt(pi^2 + ln^2 e)``; the contact ends
at zero overlap, so the restitution is ``e`` at every speed (integrated here)
and the export is the constant closest to vimpact's ``e_z(v)``. The
stiffness ``KN`` (particle-particle) and ``KN_W`` (wall) are single values:
they set the contact time only (chosen as the Hertz contact time at the
geometric mean speed of the first contact of each kind), not ``e``.

Tangential: with LSD, MFiX takes ``DES_ETAT_FAC`` (tangential over normal
damping, one value for all particle pairs, in [0, 1]: MFiX refuses others)
and ``DES_ETAT_W_FAC`` (walls), with ``KT_FAC = KT_W_FAC = 2/7`` (tangential
over normal stiffness); ``DES_ET_INPUT`` belongs to the
Hertzian model and is not used here. Each contact's ``DES_ETAT_FAC`` is
fitted to vimpact's oblique impacts with the contact's friction over the set-up's
impact angles (MFiX's law with its Coulomb cap stepped as MFiX steps it,
:func:`vimpact.dem.laws.mfix_coulomb`), or without friction to the full-stick
``beta_x(v)``; the exported single value is their mean, and the report's ``beta_x``
residual is that of the exported value. Friction is likewise one ``MEW`` and one ``MEW_W``: per-pair
friction is not represented. Not run here (no Debian or PyPI build of MFiX):
the keywords and their ranges were read from MFiX's documentation, not run.
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.dem import laws, linear
from vimpact.dem.fit import ContactFit, Residual, Targets, fit_constant, fit_scalar
from vimpact.dem.problem import DemProblem

CODE = "mfix"
TANGENTIAL = True
KT_FAC = 2.0 / 7.0
#: MFiX's allowed range of DES_ETAT_FAC and DES_ETAT_W_FAC
ETAT_FAC_RANGE = (0.0, 1.0)


def _beta(en: float, etat_fac: float, F: float) -> float:
    """Return MFiX's tangential restitution in stick.

    ``k_t = KT_FAC k_n``, ``eta_t = etat_fac eta_n``, contact-point mass
    ``m_eff / F``; normal restitution ``en``.
    """
    w_t = math.sqrt(KT_FAC * F)  # / omega0
    zeta_t = etat_fac * laws.zeta_of_restitution(en) * math.sqrt(F / KT_FAC)
    return linear.tangential_beta(en, w_t, zeta_t)


#: steps per contact of the stepped law inside the fit (the reported prediction uses
#: :data:`vimpact.dem.laws.FRICTION_STEPS`)
FIT_STEPS = 1000


def _oblique_beta(en: float, etat_fac, F: float, mu: float, w0,
                  steps: int = laws.FRICTION_STEPS) -> np.ndarray:
    """Return MFiX's ``beta`` in oblique impacts with friction ``mu`` at ``w0 = v_c0 / v_z0``.

    :func:`vimpact.dem.laws.mfix_coulomb`; the law scales with the speed, so
    ``beta`` depends on the angle only. ``etat_fac`` is a number or an array of
    candidates that broadcasts with ``w0``.
    """
    zeta = laws.zeta_of_restitution(en)
    return laws.mfix_coulomb(zeta, math.sqrt(KT_FAC * F),
                             etat_fac * zeta * math.sqrt(F / KT_FAC), F, mu, w0, steps)[1]


def _fit_oblique(en: float, F: float, mu: float, w0: np.ndarray, target: np.ndarray,
                 xatol: float = 5e-4) -> float:
    """Return the ``DES_ETAT_FAC`` in :data:`ETAT_FAC_RANGE` closest (RMS) to ``target`` at ``w0``.

    Grids of 21 values, each stepped in one run, shrunk around the best to one
    spacing until the spacing is below ``xatol``.
    """
    lo, hi = ETAT_FAC_RANGE
    best = 0.5 * (lo + hi)
    while True:
        x = np.linspace(lo, hi, 21)
        b = _oblique_beta(en, x[:, None], F, mu, w0[None, :], FIT_STEPS)
        best = float(x[int(np.argmin(np.mean((b - target) ** 2, axis=1)))])
        step = x[1] - x[0]
        if step < xatol:
            return best
        lo, hi = (max(best - step, ETAT_FAC_RANGE[0]), min(best + step, ETAT_FAC_RANGE[1]))


def fit(problem: DemProblem, targets: dict[str, Targets]) -> list[ContactFit]:
    """Fit MFiX's restitution ``en`` per contact and its one tangential damping factor.

    ``en`` is the constant closest to vimpact's ``e_z``; the stiffness (N/m) gives
    the Hertz contact time. ``DES_ETAT_FAC`` (``DES_ETAT_W_FAC``) is fitted per
    contact and exported as the mean over particle pairs (walls).
    """
    fits = []
    # MFiX takes one friction for particle pairs and one for walls: the first contact's
    written_mu: dict[bool, float] = {}
    for c in problem.contacts:
        written_mu.setdefault(c.is_wall, c.mu)
    for c in problem.contacts:
        t = targets[c.key]
        en, _ = fit_constant(t.e_z, 1e-6, 1.0)
        e = np.full_like(t.e_z, laws.linear_spring_dashpot(laws.zeta_of_restitution(en),
                                                           "overlap")[0])
        F = linear.mass_factor(c)
        R_nom, m_nom = c.nominal()
        tc = linear.hertz_time(c, problem.speeds)
        zeta = laws.zeta_of_restitution(en)
        kn = m_nom * (math.pi / tc)**2 / (1.0 - zeta**2)  # N/m: contact time tc at overlap end
        fits.append(ContactFit(c, {"en": en, "etat_fac": math.nan, "kn": kn, "F": F, "mu": c.mu},
                               e, None, Residual.of(e, t.e_z), None,
                               ["speed-independent en: the residual is vimpact's speed dependence"]))
        if t.oblique is not None:
            ob = t.oblique
            mu = written_mu[c.is_wall]  # MFiX's one MEW (MEW_W), as written
            fits[-1].params["etat_fac"] = _fit_oblique(en, F, mu, ob.w0, ob.beta_x)
        elif t.beta_x is not None:
            etat, _ = fit_scalar(lambda x: np.full_like(t.beta_x, _beta(en, x, F)),
                                 t.beta_x, *ETAT_FAC_RANGE)
            fits[-1].params["etat_fac"] = etat
    # one DES_ETAT_FAC for particle pairs, one DES_ETAT_W_FAC for walls: export the means
    for wall in (False, True):
        group = [f for f in fits if f.contact.is_wall == wall]
        vals = [f.params["etat_fac"] for f in group if math.isfinite(f.params["etat_fac"])]
        if not vals:
            continue
        mean = float(np.mean(vals))
        for f in group:
            t = targets[f.contact.key]
            f.params["etat_fac_fitted"] = f.params["etat_fac"]
            f.params["etat_fac"] = mean
            if t.beta_x is not None:
                f.beta_x = np.full_like(t.beta_x, _beta(f.params["en"], mean, f.params["F"]))
                f.res_beta_x = Residual.of(f.beta_x, t.beta_x)
            basis = "in full stick"
            if t.oblique is not None:
                ob = t.oblique
                f.beta_oblique = _oblique_beta(f.params["en"], mean, f.params["F"],
                                               written_mu[wall], ob.w0)
                f.res_beta_x = Residual.of(f.beta_oblique, ob.beta_x)
                basis = (f"to vimpact's oblique impacts with the contact's friction mu = "
                         f"{ob.mu:g} over the impact angles, MFiX running with the written "
                         f"{'MEW_W' if wall else 'MEW'} = {written_mu[wall]:g} (residual over "
                         "those oblique impacts; MFiX's LSD law with its Coulomb cap as read "
                         "from its sources, not run)")
            f.notes.append(f"{'DES_ETAT_W_FAC' if wall else 'DES_ETAT_FAC'} is one value: "
                           f"exported mean {mean:.4g}, this contact alone would take "
                           f"{f.params['etat_fac_fitted']:.4g}, fitted {basis}")
    return fits


def render(problem: DemProblem, fits: list[ContactFit]) -> dict[str, str]:
    """Return ``mfix.dat``: the MFiX-DEM keywords of the fits (SI units)."""
    N = len(problem.types)
    e = {}
    for f in fits:
        if not f.contact.is_wall:
            i, j = sorted((f.contact.first.index, f.contact.second.index))
            e[(i, j)] = f.params["en"]
    upper = [e[(i, j)] for i in range(1, N + 1) for j in range(i, N + 1)]
    pp = [f for f in fits if not f.contact.is_wall]
    pw = [f for f in fits if f.contact.is_wall]
    lines = ["! MFiX-DEM keywords written by `vimpact dem` (SI units), linear spring-dashpot",
             f"! from {problem.source}; speeds {problem.speeds.min():g}..{problem.speeds.max():g} m/s",
             "! solids phases: " + ", ".join(f"{t.index} = {t.name}" for t in problem.types),
             "DES_COLL_MODEL = 'LSD'",
             "DES_EN_INPUT = " + " ".join(f"{x:.6f}" for x in upper)]
    if pp:
        lines.append(f"KN = {pp[0].params['kn']:.6g}   ! N/m, contact time of {pp[0].contact.key}")
        lines.append(f"KT_FAC = {KT_FAC:.8g}")
        if math.isfinite(pp[0].params["etat_fac"]):
            lines.append(f"DES_ETAT_FAC = {pp[0].params['etat_fac']:.6g}")
        mus = {f.params["mu"] for f in pp}
        mu = pp[0].params["mu"]
        lines.append(f"MEW = {mu if math.isfinite(mu) else 1.0e6:.6g}" +
                     ("   ! per-pair friction differs; MFiX takes one value" if len(mus) > 1 else ""))
    if pw:
        walls = {f.contact.second.name for f in pw}
        if len(walls) > 1:
            lines.append("! several walls: MFiX has one wall restitution per phase; the first wall is used")
        first = [f for f in pw if f.contact.second.name == pw[0].contact.second.name]
        first.sort(key=lambda f: f.contact.first.index)
        lines.append("DES_EN_WALL_INPUT = " + " ".join(f"{f.params['en']:.6f}" for f in first))
        lines.append(f"KN_W = {first[0].params['kn']:.6g}   ! N/m, contact time of {first[0].contact.key}")
        lines.append(f"KT_W_FAC = {KT_FAC:.8g}")
        if math.isfinite(first[0].params["etat_fac"]):
            lines.append(f"DES_ETAT_W_FAC = {first[0].params['etat_fac']:.6g}")
        mu = first[0].params["mu"]
        lines.append(f"MEW_W = {mu if math.isfinite(mu) else 1.0e6:.6g}")
    return {"mfix.dat": "\n".join(lines) + "\n"}
