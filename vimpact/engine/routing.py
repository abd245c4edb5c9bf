"""Which kernel runs a scene, and why: simulate only the effects a scene calls for.

A scene names its effects (tangential problem or not, rotation, rheology);
:func:`choose_path` maps them to one of

- ``continuum``: the Kelvin-Voigt (or elastic) normal-only impact as a
  one-degree-of-freedom ODE with the closed-form continuum force
  (PHYSICS.md section 5), adaptive Dormand-Prince 5(4) with event location;
- ``elements``: the MDR element kernel, compiled for exactly the scene's
  effects (:class:`vimpact.kernels.elements.KernelSpec`): no tangential state
  without a tangential problem, no arm variables without Maxwell arms, no
  dashpot term without a dashpot.

``Path.reasons`` says why, in words (``vimpact simulate --explain``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from vimpact.kernels.elements import EULER, KernelSpec
from vimpact.model.hertz import HERTZ_TIME_FACTOR
from vimpact.model.numerics import INTEGRATORS, Numerics
from vimpact.model.scene import TANGENTIAL_MEMORY, Scene

CONTINUUM = "continuum"
ELEMENTS = "elements"


@dataclass(frozen=True)
class Path:
    """The kernel chosen for a scene.

    Attributes
    ----------
    kind : ``"continuum"`` or ``"elements"``
    spec : compile-time effects of the element kernel (``None`` for the continuum path)
    reasons : why, one sentence each
    """

    kind: str
    spec: KernelSpec | None
    reasons: tuple[str, ...]

    @property
    def name(self) -> str:
        """Short label, e.g. ``elements[verlet,tangential:incremental,dashpot]``."""
        if self.spec is None:
            return "continuum[kelvin_voigt,normal]"
        sp = self.spec
        parts = [_INTEGRATOR_NAMES[sp.integrator]]
        if sp.tangential:
            parts.append("tangential:" + TANGENTIAL_MEMORY[sp.memory])
        if sp.arms:
            parts.append("arms")
        if sp.dashpot:
            parts.append("dashpot")
        return f"elements[{','.join(parts)}]"

    def explain(self) -> str:
        """Multi-line explanation: the path and the reasons."""
        return "\n".join([f"path: {self.name}"] + [f"  - {r}" for r in self.reasons])


_INTEGRATOR_NAMES = {code: name for name, code in INTEGRATORS.items()}


def choose_path(scene: Scene, numerics: Numerics) -> Path:
    """The cheapest kernel that computes everything ``scene`` asks for."""
    mat = scene.material
    arms = any(G > 0.0 for G, _ in mat.arms)
    dashpot = mat.eta0 > 0.0
    tangential = scene.computes_tangential
    reasons = []
    if scene.tangential == "none":
        reasons.append("normal impact only (tangential = 'none'): no tangential state")
    elif scene.v_c0 == 0.0:
        reasons.append("v_c0 = v_x0 + R omega0 = 0: no tangential force (PHYSICS.md 7), "
                       "tangential work skipped")
    else:
        rot = (f"with rotation (Theta/(m R^2) = {scene.theta_ratio:.4g}, contact-point mass "
               f"factor {scene.contact_mass_factor:.4g})" if scene.rotation
               else "without rotation (Theta -> inf)")
        reasons.append(f"tangential full stick, {scene.tangential_memory} memory, {rot}")
    what = [("Maxwell arms" if arms else "no arm variables"),
            ("a parallel dashpot" if dashpot else "no dashpot term")]
    reasons.append(f"material {mat.model}: {what[0]}, {what[1]}")
    if not arms and not tangential and numerics.continuum:
        reasons.append("Kelvin-Voigt/elastic normal impact: closed-form continuum force "
                       "(PHYSICS.md 5), 1-DOF ODE, adaptive Dormand-Prince 5(4) with event "
                       f"location, rtol = {numerics.rtol:g}")
        return Path(CONTINUUM, None, tuple(reasons))
    if not arms and not tangential:
        reasons.append("continuum path switched off (Numerics.continuum = False)")
    else:
        need = [n for n, on in (("the tangential problem", tangential), ("Maxwell arms", arms)) if on]
        reasons.append(f"elements needed for {' and '.join(need)}")
    spec = KernelSpec(numerics.integrator_code, tangential,
                      TANGENTIAL_MEMORY.index(scene.tangential_memory) if tangential else 0,
                      arms, dashpot)
    ft, fe = refinement(scene, numerics, spec)
    finer = f" (refined {ft:.3g}x for the stiffest mode)" if ft > 1.0 else ""
    finer_e = f" (refined {fe:.3g}x: glassy contact is narrower)" if fe > 1.0 else ""
    reasons.append(f"element kernel: {numerics.integrator}, {numerics.steps} steps per "
                   f"t_H{finer}, {numerics.elements} elements per a_H{finer_e}")
    return Path(ELEMENTS, spec, tuple(reasons))


#: ``kappa mu_t`` of a solid sphere (Theta = 2/5 m R^2) at nu = 0.5: the
#: tangential stiffness the default numerics are calibrated on.
SOLID_SPHERE_STIFFNESS = 2.0 / 3.0 * 3.5


def stiffness_ratio(scene: Scene) -> float:
    """How much stiffer than the relaxed modulus the half-space acts during the
    contact, ``1 + sum g_i tau_i / (tau_i + t_H)`` (``g_i = G_i / G_inf``):
    an arm whose time is long against the Hertz time is a spring, one whose
    time is short relaxes away. Dimensionless, >= 1."""
    mat, t_H = scene.material, scene.hertz.t_H
    return 1.0 + sum(G / mat.G_inf * tau / (tau + t_H) for G, tau in mat.arms if G > 0.0)


def refinement(scene: Scene, numerics: Numerics, spec: KernelSpec) -> tuple[float, float]:
    """Factors (>= 1) by which the time step and the element spacing are made
    finer than ``t_H / steps`` and ``a_H / elements``: the numerics resolve
    the stiffest mode as well as they resolve a relaxed elastic impact.

    - A glassy half-space (arms stiffer than the relaxed spring, with times
      long against the contact) makes a Hertz contact of ``r =``
      :func:`stiffness_ratio` times the modulus: ``r^(-2/5)`` times shorter
      and ``r^(-1/5)`` times narrower. Steps and elements scale with it.
    - Tangential problem: its oscillation is ``sqrt(kappa mu_t)`` times faster
      than the normal one (``kappa = c_t / c_n``, ``mu_t`` the contact-point
      mass factor), so the step resolves it as well (``Theta / (m R^2) =
      1e-3`` gives about 26).
    - Viscous terms that are explicit in part of the step (the dashpot under
      explicit Euler; arms whose time is below the step, which act as
      dashpots ``G_i tau_i``, under every integrator) keep ``h C <= 1`` with
      the largest damping coefficient ``C`` the row can have.
    - Stability of the explicit kicks: ``h omega <= 1/2`` for the stiffest
      spring on the scale of one step (all arms slower than the step).
    """
    r = stiffness_ratio(scene)
    time_factor, element_factor = r ** 0.4, r ** 0.2
    mat, T = scene.material, scene.hertz.T
    stiff_t = mat.kappa * scene.contact_mass_factor if spec.tangential else 0.0
    if spec.tangential:
        time_factor *= max(1.0, math.sqrt(stiff_t))
        # a fast tangential oscillation also feels each element entering the
        # contact: finer elements, measured to bring Theta/(m R^2) = 1e-3 within
        # 5e-4 of a twice finer run (a heuristic exponent, not a derived one)
        element_factor *= max(1.0, (stiff_t / SOLID_SPHERE_STIFFNESS) ** 0.25)
    h = HERTZ_TIME_FACTOR / numerics.steps / time_factor  # / T
    viscous = sum(G / mat.G_inf * tau / T for G, tau in mat.arms if tau / T < h)
    if spec.integrator == EULER:
        viscous += mat.dashpot_time / T
    rate = 15.0 / 8.0 * viscous * numerics.row_width * max(1.0, stiff_t)  # / T
    time_factor *= max(1.0, h * rate)
    # stability margin of the explicit kicks: h omega <= 1/2 for the stiffest
    # spring on the scale of one step (arms slower than the step are springs)
    h = HERTZ_TIME_FACTOR / numerics.steps / time_factor
    springs = 1.0 + sum(G / mat.G_inf for G, tau in mat.arms if tau / T >= h)
    omega = math.sqrt(15.0 / 8.0 * numerics.row_width * springs * max(1.0, stiff_t))  # / T
    time_factor *= max(1.0, 2.0 * h * omega)
    return time_factor, element_factor
