"""Two spheres, and a sphere on a wall, mapped onto the rigid-sphere problem.

An impact of two bodies is the impact of one rigid sphere on one half-space
(:class:`vimpact.Scene`) when (docs/physics.md#pairs-and-walls in the project's words):

- the normal problem has the effective radius ``R = R1 R2 / (R1 + R2)`` and
  mass ``m = m1 m2 / (m1 + m2)`` and the two half-space compliances add;
- the contact point's relative tangential velocity is
  ``v_c = (v_x1 - v_x2) + R1 omega1 + R2 omega2`` and a tangential force
  ``F`` (on body 1, ``-F`` on body 2) slows it as
  ``dv_c/dt = -F (1/m + R1^2/Theta1 + R2^2/Theta2)``; the scene has the same
  law with ``R^2/Theta = R1^2/Theta1 + R2^2/Theta2``, so its moment of inertia
  is ``Theta = R^2 / (R1^2/Theta1 + R2^2/Theta2)``.

Sign convention: the normal axis ``z`` points from body 1 to body 2, so the
approach speed is ``v_z0 = v_z1 - v_z2 > 0``. ``x`` is the tangential axis
and both spins are about the same ``y`` axis, with the scene's sense (body
1's contact point moves with ``v_x1 + R1 omega1``; body 2's contact point,
on the far side of its centre, with ``v_x2 - R2 omega2``). A wall lies on the
``+z`` side of body 1 and does not move.

Which material pairs map exactly (the series combination of the two
relaxation operators, per unit of the common ``c_n`` or ``c_t`` factor, must
again be one generalized Maxwell material with one spectrum for normal and
tangential):

- a rigid partner (rigid wall, rigid sphere): the other body's material;
- proportional materials (body 2's ``G_inf``, arm moduli and dashpot are
  ``lambda`` times body 1's, same ``nu`` and relaxation times; the same
  material is ``lambda = 1``): body 1's material times ``lambda/(1+lambda)``
  (the same material: every modulus and viscosity halved);
- two elastic bodies: ``1/E* = 1/E*_1 + 1/E*_2`` and
  ``1/(c_t G) = 1/(c_t1 G_1) + 1/(c_t2 G_2)``, which fixes one elastic
  material (``G``, ``nu``) with both; the tangential MDR mapping stays the
  approximation it is for ``nu != 0.5`` (and ignores the Dundurs coupling of
  dissimilar bodies);
- equal ``nu``, any two generalized Maxwell materials: the series combination
  ``M_1 M_2 / (M_1 + M_2)`` of their operator moduli, which is again one
  (:func:`vimpact.model.series.series_material`: relaxed modulus
  ``G_inf1 G_inf2/(G_inf1 + G_inf2)``, a dashpot only if both have one, at most
  ``n_1 + n_2 + 1`` arms). Two Kelvin-Voigt bodies with different relaxation
  times, for example, are a spring, a dashpot and one Maxwell arm.

Unequal ``nu`` with a viscoelastic side is refused: a body's normal compliance
is ``(1 - nu)/(2 M(s))`` and its tangential one ``(2 - nu)/(4 M(s))``, so the
normal and tangential series combinations weight the two spectra differently
and have different relaxation times.
Two rigid bodies raise :class:`vimpact.InputError` too.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import cast

from vimpact.model.material import Material
from vimpact.model.scene import DEFAULT_THETA_RATIO, Scene
from vimpact.model.series import series_material
from vimpact.model.validation import InputError, finite, flag, positive, require

#: relative tolerance for "same nu", "same relaxation times", "proportional"
_SAME = 1e-12


@dataclass(frozen=True)
class Body:
    """A sphere taking part in a pair impact.

    Attributes
    ----------
    material : its material, or ``None`` for a rigid body
    R : radius, m
    m : mass, kg
    Theta : moment of inertia, kg m^2 (default ``2/5 m R^2``)
    v_z : velocity along the normal axis (from body 1 to body 2), m/s
    v_x : tangential velocity of the centre, m/s
    omega : spin about ``y``, rad/s (the scene's sense; see the module doc)
    rotation : the body may spin (``False``: ``Theta -> inf``)
    """

    material: Material | None
    R: float
    m: float
    Theta: float | None = None
    v_z: float = 0.0
    v_x: float = 0.0
    omega: float = 0.0
    rotation: bool = True

    def __post_init__(self):
        require("material", self.material, self.material is None or isinstance(self.material, Material),
                "a vimpact.Material or None (rigid)")
        object.__setattr__(self, "R", positive("R", self.R))
        object.__setattr__(self, "m", positive("m", self.m))
        if self.Theta is None:
            object.__setattr__(self, "Theta", DEFAULT_THETA_RATIO * self.m * self.R**2)
        object.__setattr__(self, "Theta", positive("Theta", self.Theta))
        for name in ("v_z", "v_x", "omega"):
            object.__setattr__(self, name, finite(name, getattr(self, name)))
        object.__setattr__(self, "rotation", flag("rotation", self.rotation))

    @property
    def spin_compliance(self) -> float:
        """``R^2 / Theta`` (0 without rotation), 1/kg."""
        return self.R**2 / cast(float, self.Theta) if self.rotation else 0.0


@dataclass(frozen=True)
class Wall:
    """A plane wall at rest (infinite radius and mass, no spin).

    Attributes
    ----------
    material : its material, or ``None`` for a rigid wall
    """

    material: Material | None = None

    def __post_init__(self):
        require("wall material", self.material,
                self.material is None or isinstance(self.material, Material),
                "a vimpact.Material or None (rigid)")


# ---- materials ----------------------------------------------------------

def _same(a: float, b: float) -> bool:
    return abs(a - b) <= _SAME * max(abs(a), abs(b), 1e-300)


def _scaled(mat: Material, factor: float) -> Material:
    """``mat`` with every modulus and viscosity times ``factor`` (same times and ``nu``)."""
    return dataclasses.replace(mat, G_inf=mat.G_inf * factor, eta0=mat.eta0 * factor,
                               arms=tuple((G * factor, tau) for G, tau in mat.arms))


def _proportion(m1: Material, m2: Material) -> float | None:
    """``lambda`` with ``m2 = lambda * m1`` (same ``nu`` and times), else ``None``."""
    if not _same(m1.nu, m2.nu) or len(m1.arms) != len(m2.arms):
        return None
    lam = m2.G_inf / m1.G_inf
    if not _same(m2.eta0, lam * m1.eta0):
        return None
    arms1, arms2 = sorted(m1.arms, key=lambda a: a[1]), sorted(m2.arms, key=lambda a: a[1])
    for (G1, t1), (G2, t2) in zip(arms1, arms2):
        if not (_same(t1, t2) and _same(G2, lam * G1)):
            return None
    return lam


def _is_elastic(mat: Material) -> bool:
    return not mat.arms and mat.eta0 == 0.0


def pair_material(mat1: Material | None, mat2: Material | None) -> Material:
    """Return the one half-space material equivalent to two bodies' materials in contact.

    Parameters
    ----------
    mat1, mat2 : the two materials; ``None`` is a rigid body (or wall)

    Returns
    -------
    Material
        whose relaxation operators (normal and tangential) are the series
        combination of the two (compliances add); see the module doc for the
        cases that map exactly.

    Raises
    ------
    InputError
        if both are rigid, or the series combination is not one generalized
        Maxwell material with one spectrum for normal and tangential.
    """
    if mat1 is None and mat2 is None:
        raise InputError("materials = (rigid, rigid) is not allowed: must be at least one "
                         "deformable body (two rigid bodies have no contact law)")
    if mat1 is None or mat2 is None:
        return cast(Material, mat2 if mat1 is None else mat1)  # not both: refused above
    lam = _proportion(mat1, mat2)
    if lam is not None:
        return _scaled(mat1, lam / (1.0 + lam))
    if _is_elastic(mat1) and _is_elastic(mat2):
        E1, E2 = 2 * mat1.G_inf / (1 - mat1.nu), 2 * mat2.G_inf / (1 - mat2.nu)
        K1, K2 = 4 * mat1.G_inf / (2 - mat1.nu), 4 * mat2.G_inf / (2 - mat2.nu)
        E_star = 1.0 / (1.0 / E1 + 1.0 / E2)
        K_t = 1.0 / (1.0 / K1 + 1.0 / K2)
        kappa = K_t / E_star  # c_t / c_n of the pair, in [2/3, 1]
        nu = min(max(2.0 * (1.0 - kappa) / (2.0 - kappa), 0.0), 0.5)
        return Material.elastic(nu=nu, G=E_star * (1.0 - nu) / 2.0)
    if not _same(mat1.nu, mat2.nu):
        raise InputError(
            f"materials with nu = {mat1.nu!r} and nu = {mat2.nu!r} are not allowed for a viscoelastic "
            "pair: must have equal nu (a body's normal compliance is (1 - nu)/(2 M(s)) and its "
            "tangential one (2 - nu)/(4 M(s)), so with unequal nu the normal and tangential series "
            "combinations weight the two relaxation spectra differently and have different poles: "
            "no one material of the generalized Maxwell form with one nu has both)")
    return series_material(mat1, mat2)


# ---- scenes -------------------------------------------------------------

def _partner(other: Body | Wall) -> tuple[Material | None, float, float, float, float, float]:
    """``material, 1/R, 1/m, R^2/Theta, v_z, v_c contribution`` of body 2 (or the wall)."""
    if isinstance(other, Wall):
        return other.material, 0.0, 0.0, 0.0, 0.0, 0.0
    require("body 2", other, isinstance(other, Body), "a vimpact.model.pair.Body or Wall")
    return (other.material, 1.0 / other.R, 1.0 / other.m, other.spin_compliance, other.v_z,
            -other.v_x + other.R * other.omega)


def pair_scene(body1: Body, other: Body | Wall, *, tangential: str = "auto",
               tangential_memory: str = "incremental", mu: float = math.inf,
               allow_large_contact: bool = False) -> Scene:
    """Return the rigid-sphere scene equivalent to ``body1`` hitting ``other``.

    Returns a :class:`vimpact.Scene` with the pair material
    (:func:`pair_material`), ``R``, ``m`` the effective radius and mass,
    ``v_z0`` the approach speed, ``v_x0`` the relative contact-point velocity
    ``v_c0`` (``omega0 = 0``) and ``Theta = R^2 / (R1^2/Theta1 + R2^2/Theta2)``
    (``rotation=False`` if neither body spins).

    Raises
    ------
    InputError
        if the bodies do not approach (``v_z1 - v_z2 <= 0``) or the materials
        do not map (:func:`pair_material`).
    """
    require("body 1", body1, isinstance(body1, Body), "a vimpact.model.pair.Body")
    mat2, inv_R2, inv_m2, spin2, v_z2, v_c2 = _partner(other)
    material = pair_material(body1.material, mat2)
    R = 1.0 / (1.0 / body1.R + inv_R2)
    m = 1.0 / (1.0 / body1.m + inv_m2)
    v_z0 = body1.v_z - v_z2
    require("approach speed v_z1 - v_z2", v_z0, v_z0 > 0.0,
            "> 0 (the z axis points from body 1 to body 2; the bodies must approach)")
    v_c0 = body1.v_x + body1.R * body1.omega + v_c2
    spin = body1.spin_compliance + spin2
    rotation = spin > 0.0
    Theta = R**2 / spin if rotation else None
    return Scene(material, R=R, m=m, v_z0=v_z0, v_x0=v_c0, omega0=0.0, Theta=Theta,
                 tangential=tangential, tangential_memory=tangential_memory, rotation=rotation,
                 mu=mu, allow_large_contact=allow_large_contact)


# ---- results ------------------------------------------------------------

@dataclass(frozen=True)
class PairResult:
    """End state of a pair impact.

    Attributes
    ----------
    e_z, beta_x : normal restitution and signed tangential restitution of the
        relative contact-point velocity (``beta_x`` NaN without tangential problem)
    body1, body2 : ``(v_z, v_x, omega)`` after the impact, m/s, m/s, rad/s
        (``body2`` is ``None`` for a wall)
    J_z, J_x : impulse on body 1 along ``z`` and ``x``, N s (body 2 gets the opposite)
    status : the status of the equivalent scene's result
    scene : the equivalent rigid-sphere scene
    result : the scene's :class:`vimpact.ImpactResult` (``None`` from the batch form)
    """

    e_z: float
    beta_x: float
    body1: tuple[float, float, float]
    body2: tuple[float, float, float] | None
    J_z: float
    J_x: float
    status: str
    scene: Scene = field(repr=False)
    result: object = field(default=None, repr=False)


def end_states(body1: Body, other: Body | Wall, scene: Scene, e_z: float, beta_x: float):
    """Both bodies' end states from the relative result (momentum exactly conserved).

    Returns ``(v_z, v_x, omega)`` of body 1 and of body 2 (``None`` for a wall;
    m/s, m/s, rad/s) and the impulses ``J_z, J_x`` on body 1 (N s), from the
    equivalent ``scene`` and its ``e_z``, ``beta_x`` (dimensionless).
    """
    v_z_end = -e_z * scene.v_z0  # relative normal velocity after (moving apart)
    J_z = scene.m * (v_z_end - scene.v_z0)  # on body 1, along z
    if scene.computes_tangential and math.isfinite(beta_x):
        v_c_end = -beta_x * scene.v_c0
        spin_total = scene.R**2 / cast(float, scene.Theta) if scene.rotation else 0.0
        P = (scene.v_c0 - v_c_end) / (1.0 / scene.m + spin_total)  # tangential impulse magnitude
    else:
        P = 0.0
    J_x = -P  # on body 1
    b1 = (body1.v_z + J_z / body1.m, body1.v_x + J_x / body1.m,
          body1.omega + (body1.R * J_x / cast(float, body1.Theta) if body1.rotation else 0.0))
    if isinstance(other, Wall):
        return b1, None, J_z, J_x
    # body 2 gets -J at its contact point (-R2 along z): torque_y = -R2 * (-J_x)
    b2 = (other.v_z - J_z / other.m, other.v_x - J_x / other.m,
          other.omega + (other.R * J_x / cast(float, other.Theta) if other.rotation else 0.0))
    return b1, b2, J_z, J_x
