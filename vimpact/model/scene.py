"""One impact: sphere, material, initial velocities and options (docs/physics.md#the-problem)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import cast

import numpy as np

from vimpact.model.hertz import Q1_PER_TAU, HertzScales, effective_modulus, hertz_scales
from vimpact.model.material import Material
from vimpact.model.validation import (
    InputError,
    finite,
    flag,
    friction_coefficient,
    one_of,
    poisson_ratio,
    positive,
    require,
)

TANGENTIAL_MEMORY = ("incremental", "seed")
#: What the work of adhesion may be on an oblique impact (the adhesive impact is normal only).
ADHESION_OBLIQUE = ("0 for an oblique impact (v_c0 != 0 with tangential 'auto' or 'stick'): "
                    "the adhesive impact is normal only (tangential='none')")
#: What a friction coefficient may be with the seed memory: the seed memory sets every
#: element to the total contact-point displacement, which slip cannot change, so
#: Coulomb friction needs the incremental memory.
SEED_FRICTION_ALLOWED = ("inf (full stick) with the seed tangential memory: Coulomb friction "
                         "needs the incremental memory")

#: What a scene asks of the tangential problem: ``auto`` (stick whenever
#: ``v_c0 != 0``), ``stick`` (full stick, docs/physics.md#full-stick) or ``none``
#: (normal impact only: no tangential state at all, e_x and beta_x NaN).
#: Slip is not modelled yet.
TANGENTIAL_EFFECTS = ("auto", "stick", "none")

#: ``Theta / (m R^2)`` of a solid sphere, the default moment of inertia.
DEFAULT_THETA_RATIO = 0.4
#: Hertz indentation (m) of the reference scene of :meth:`Scene.from_dimensionless`
#: (R = 1 m, m = 1 kg, v_z0 = 1 m/s): a_H = sqrt(R d) = 0.01 R.
REFERENCE_INDENTATION = 1e-4

#: The thesis's half-space limit: contact half-width at most this times R.
HALF_SPACE_LIMIT = 0.2

#: Largest parallel-dashpot time ``eta0 / G_inf`` in units of ``T`` (``Q1 <=
#: sqrt(15/32) 1e100``): the kernels multiply it by velocities and forces that
#: reach about its square, which overflows from about 1e150 (measured: the element
#: path gives non-finite values from ``Q1 = 1e160``, the continuum path from
#: ``1e190``). Nothing is lost: ``e_z ~ Q1^(-5/3) < 1e-160`` there.
MAX_DASHPOT_TIME = 1e100


class ScaleError(InputError):
    """A scene whose Hertz scales or kernel-unit inputs leave the floating-point range.

    Attributes
    ----------
    names : the inputs that set those scales, e.g. ``("G_inf", "R", "m", "v_z0", "Theta")``
    """

    def __init__(self, text: str, names: tuple[str, ...]):
        super().__init__(text)
        self.names = names


@dataclass(frozen=True)
class Scene:
    """A rigid sphere hitting a viscoelastic half-space.

    Attributes
    ----------
    material : the half-space
    R : sphere radius, m
    m : sphere mass, kg
    v_z0 : normal impact speed, m/s (> 0, into the half-space)
    v_x0 : tangential speed of the centre, m/s
    omega0 : spin about the y axis, rad/s (contact point moves with ``v_x + R omega``)
    Theta : moment of inertia, kg m^2 (default ``2/5 m R^2``, a solid sphere)
    tangential_memory : ``"incremental"`` (default, passive: elements enter
        unstrained) or ``"seed"`` (thesis eq. 4.16: total displacement; not passive)
    allow_large_contact : accept a contact half-width above ``0.2 R`` (the
        half-space model is then outside its range; the thesis stops there)
    tangential : ``"auto"`` (default: full stick whenever ``v_c0 != 0``),
        ``"stick"`` or ``"none"`` (normal impact only; ``TANGENTIAL_EFFECTS``)
    rotation : the sphere may spin (default). ``False`` is the limit
        ``Theta -> inf``: the tangential force changes ``v_x`` only and
        ``omega`` keeps ``omega0`` (``Theta`` is then not used)
    mu : Coulomb friction coefficient, dimensionless, >= 0 (default ``inf``:
        full stick, docs/physics.md#full-stick; finite: every element obeys
        ``|f_t| <= mu f_n``, docs/physics.md#coulomb-friction)
    adhesion : work of adhesion ``dgamma`` of the sphere-half-space pair, J/m^2,
        >= 0 (default 0: no adhesion, the impact exactly as without this field).
        ``> 0``: the adhesive normal impact of docs/physics.md#adhesion
        (JKR through the MDR with the rule of Hess; normal impact only)
    """

    material: Material
    R: float
    m: float
    v_z0: float
    v_x0: float = 0.0
    omega0: float = 0.0
    Theta: float | None = None
    tangential_memory: str = "incremental"
    allow_large_contact: bool = False
    tangential: str = "auto"
    rotation: bool = True
    mu: float = math.inf
    adhesion: float = 0.0
    hertz: HertzScales = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        require("material", self.material, isinstance(self.material, Material), "a vimpact.Material")
        object.__setattr__(self, "R", positive("R", self.R))
        object.__setattr__(self, "m", positive("m", self.m))
        object.__setattr__(self, "v_z0", positive("v_z0", self.v_z0))
        object.__setattr__(self, "v_x0", finite("v_x0", self.v_x0))
        object.__setattr__(self, "omega0", finite("omega0", self.omega0))
        if self.Theta is None:
            theta = DEFAULT_THETA_RATIO * self.m * self.R**2 if self.R < 1e150 else math.inf
            require("R", self.R, 0.0 < theta < math.inf,
                    f"large enough for the default Theta = {DEFAULT_THETA_RATIO} m R^2 to be a "
                    "finite number > 0 "
                    f"(with m = {self.m:g} kg; give Theta)")
            object.__setattr__(self, "Theta", theta)
        object.__setattr__(self, "Theta", positive("Theta", self.Theta))
        one_of("tangential_memory", self.tangential_memory, TANGENTIAL_MEMORY)
        one_of("tangential", self.tangential, TANGENTIAL_EFFECTS)
        flag("rotation", self.rotation)
        flag("allow_large_contact", self.allow_large_contact)
        object.__setattr__(self, "mu", friction_coefficient("mu", self.mu))
        object.__setattr__(self, "adhesion", finite("adhesion", self.adhesion))
        require("adhesion", self.adhesion, self.adhesion >= 0.0,
                ">= 0 (work of adhesion, J/m^2; 0: no adhesion)")
        require("adhesion", self.adhesion, self.adhesion == 0.0 or self.tangential == "none"
                or self.v_c0 == 0.0, ADHESION_OBLIQUE)
        require("mu", self.mu, self.tangential_memory != "seed" or math.isinf(self.mu),
                SEED_FRICTION_ALLOWED)
        mat = self.material
        with np.errstate(all="ignore"):
            hz = hertz_scales(mat.G_inf, mat.nu, self.R, self.m, self.v_z0)
            theta = float(self.Theta or 0.0)  # set above: positive, never None here
            ratio = theta / (self.m * self.R**2) if math.isfinite(self.R**2 * self.m) else 0.0
            m, v_z0, v_x0, omega0 = (np.float64(x) for x in (self.m, self.v_z0, self.v_x0,
                                                             self.omega0))  # inf, not OverflowError
            energy = m * (v_z0**2 + v_x0**2) + np.float64(self.Theta) * omega0**2
            energy += (v_x0 + np.float64(self.R) * omega0) ** 2  # v_c0^2 (kernel unit of F_x)
        if not (all(math.isfinite(x) and x > 0.0 for x in hz) and ratio > 0.0
                and math.isfinite(energy)
                and math.isfinite(1.0 / ratio) and math.isfinite(mat.dashpot_time / hz.T)
                and all(math.isfinite(tau / hz.T) and math.isfinite(G / mat.G_inf)
                        for G, tau in mat.arms)):
            raise ScaleError(
                f"the scene (G_inf = {mat.G_inf:.3g} Pa, R = {self.R:.3g} m, m = {self.m:.3g} kg, "
                f"v_z0 = {self.v_z0:.3g} m/s, v_x0 = {self.v_x0:.3g} m/s, omega0 = "
                f"{self.omega0:.3g} rad/s, Theta = {self.Theta:.3g} kg m^2) is not allowed: "
                "its Hertz scales, dimensionless inputs or kinetic energy leave the "
                "floating-point range",
                ("G_inf", "R", "m", "v_z0", "v_x0", "omega0", "Theta"))
        if mat.dashpot_time / hz.T > MAX_DASHPOT_TIME:
            raise ScaleError(
                f"eta0 = {mat.eta0:.3g} Pa s is not allowed with G_inf = {mat.G_inf:.3g} Pa, "
                f"R = {self.R:.3g} m, m = {self.m:.3g} kg, v_z0 = {self.v_z0:.3g} m/s: the "
                f"dashpot time eta0 / G_inf must be <= {MAX_DASHPOT_TIME:.0e} T = "
                f"{MAX_DASHPOT_TIME * hz.T:.3g} s (Q1 = {Q1_PER_TAU * mat.dashpot_time / hz.T:.3g}"
                f" > {Q1_PER_TAU * MAX_DASHPOT_TIME:.2g}: beyond it the kernels' arithmetic "
                "overflows, and the impact is fully damped, e_z < 1e-160)",
                ("eta0", "G_inf", "R", "m", "v_z0"))
        object.__setattr__(self, "hertz", hz)

    @classmethod
    def from_dimensionless(cls, Q1: float, nu: float, Q2: float | None = None, *,
                           theta_ratio: float = DEFAULT_THETA_RATIO,
                           tangential_memory: str = "incremental", tangential: str = "auto",
                           rotation: bool = True, mu: float = math.inf) -> Scene:
        """Return a physical scene with the given dimensionless parameters.

        Kelvin-Voigt for ``Q2 = None``, standard solid otherwise. Restitution
        depends only on ``Q1`` (``Q2``), ``nu`` and ``theta_ratio = Theta /
        (m R^2)`` (docs/physics.md#dimensionless-parameters), so any scene with these values gives
        the same ``e_z``, ``e_x``; this one has ``R = 1 m``, ``m = 1 kg``,
        ``v_z0 = v_x0 = 1 m/s``, ``omega0 = 0`` and a modulus chosen so that
        ``a_H = 0.01 R``.
        """
        Q1 = finite("Q1", Q1)
        require("Q1", Q1, Q1 >= 0.0, ">= 0")
        if Q2 is None:  # a parallel dashpot: its kernel-unit time is bounded
            require("Q1", Q1, Q1 <= Q1_PER_TAU * MAX_DASHPOT_TIME,
                    f"<= {Q1_PER_TAU * MAX_DASHPOT_TIME:.2g} for a Kelvin-Voigt body (beyond it "
                    "the kernels' arithmetic overflows; the impact is fully damped there, "
                    "e_z < 1e-160)")
        nu = poisson_ratio("nu", nu)  # a type check too: float("0.5") would take a string
        R, m, v_z0 = 1.0, 1.0, 1.0
        d = REFERENCE_INDENTATION  # a_H = sqrt(R d) = 0.01 R
        E_star = 15.0 * m * v_z0**2 / (16.0 * math.sqrt(R) * d**2.5)
        G = E_star * (1.0 - nu) / 2.0
        tau = Q1 / Q1_PER_TAU * d / v_z0  # eta / G_inf, s
        if Q2 is None:
            material = Material.kelvin_voigt(nu=nu, G=G, eta=tau * G)
        else:
            Q2 = positive("Q2", Q2)
            require("Q2", Q2, math.isfinite(G / Q2),
                    f"large enough for the arm modulus G2 = G1 / Q2 (G1 = {G:.3g} Pa) to be a "
                    "finite number")
            material = Material.standard_solid(nu=nu, G1=G, G2=G / Q2, eta=tau * G)
        return cls(material, R=R, m=m, v_z0=v_z0, v_x0=1.0, omega0=0.0,
                   Theta=positive("theta_ratio", theta_ratio) * m * R**2,
                   tangential_memory=tangential_memory, tangential=tangential, rotation=rotation,
                   mu=mu)

    # ---- derived quantities ------------------------------------------
    @property
    def v_c0(self) -> float:
        """Initial contact-point velocity ``v_x0 + R omega0``, m/s."""
        return self.v_x0 + self.R * self.omega0

    @property
    def theta_ratio(self) -> float:
        """``Theta / (m R^2)``, dimensionless."""
        return cast(float, self.Theta) / (self.m * self.R**2)

    @property
    def computes_tangential(self) -> bool:
        """The tangential problem is solved.

        Asked for (``tangential`` is not ``"none"``) and not trivially zero (``v_c0 !=
        0``, docs/physics.md#energy-and-passivity).
        """
        return self.tangential != "none" and self.v_c0 != 0.0

    @property
    def contact_mass_factor(self) -> float:
        """``1 + m R^2 / Theta`` (``1`` without rotation).

        The contact point accelerates this much faster than the centre under a tangential
        force (docs/physics.md#energy-and-passivity), dimensionless.
        """
        return 1.0 + 1.0 / self.theta_ratio if self.rotation else 1.0

    def tangential_end_state(self, vc_ratio):
        """Return the centre velocity (m/s) and spin (rad/s) at a contact-point velocity.

        Centre velocity (m/s) and spin (rad/s) when the contact-point velocity
        has become ``vc_ratio * v_c0`` (works on arrays).
        """
        impulse = (1.0 - vc_ratio) / self.contact_mass_factor * self.v_c0  # J / m, m/s
        spin = impulse * self.m * self.R / self.Theta if self.rotation else 0.0 * impulse
        return self.v_x0 - impulse, self.omega0 - spin

    @property
    def E_star(self) -> float:
        """Effective (relaxed) modulus ``2 G_inf / (1 - nu)``, Pa."""
        return float(effective_modulus(self.material.G_inf, self.material.nu))

    @property
    def Q1(self) -> float:
        """``Q1 = sqrt(15/32) (eta / G_inf) / T``, dimensionless (NaN for a general Prony series)."""
        return float(Q1_PER_TAU * self.material.viscous_time() / self.hertz.T)

    @property
    def Q2(self) -> float:
        """``Q2 = G1 / G2`` (standard solid; NaN otherwise)."""
        return self.material.q2

    @property
    def kinetic_energy(self) -> float:
        """Kinetic energy before the impact, J."""
        return 0.5 * (self.m * (self.v_z0**2 + self.v_x0**2)
                      + cast(float, self.Theta) * self.omega0**2)
