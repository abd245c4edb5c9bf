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
- equal ``nu``, one elastic side ``G_e`` and one Kelvin-Voigt side ``(G, eta)``:
  ``G_e (G + eta s) / (G_e + G + eta s)`` is a standard solid with
  ``G_inf = G_e G/(G_e + G)``, arm ``G_e^2/(G_e + G)`` and time
  ``eta/(G_e + G)``;
- equal ``nu``, one elastic side and one standard-solid side ``(G1, G2, tau)``:
  a standard solid with ``G_inf = G_e G1/(G_e + G1)``, glassy modulus
  ``G_e (G1 + G2)/(G_e + G1 + G2)`` and time ``tau (G_e + G1 + G2)/(G_e + G1)``.

Everything else raises :class:`vimpact.InputError` saying why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from collections.abc import Sequence

import numpy as np

from vimpact.model.material import Material
from vimpact.model.scene import DEFAULT_THETA_RATIO, Scene
from vimpact.model.validation import InputError, finite, flag, message, positive, require

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
        return self.R**2 / self.Theta if self.rotation else 0.0


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
    return Material(mat.model, mat.nu, mat.G_inf * factor,
                    tuple((G * factor, tau) for G, tau in mat.arms), mat.eta0 * factor)


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


def _elastic_with_viscoelastic(G_e: float, mat: Material) -> Material:
    """Series of an elastic ``G_e`` with a Kelvin-Voigt or one-arm body (same ``nu``)."""
    nu = mat.nu
    if not mat.arms:  # Kelvin-Voigt: G + eta s
        G, eta = mat.G_inf, mat.eta0
        return Material.standard_solid(nu=nu, G1=G_e * G / (G_e + G), G2=G_e**2 / (G_e + G),
                                       eta=G_e**2 / (G_e + G) * eta / (G_e + G))
    (G2, tau), G1 = mat.arms[0], mat.G_inf
    G_inf = G_e * G1 / (G_e + G1)
    G_glassy = G_e * (G1 + G2) / (G_e + G1 + G2)
    tau_p = tau * (G_e + G1 + G2) / (G_e + G1)
    arm = G_glassy - G_inf
    return Material.standard_solid(nu=nu, G1=G_inf, G2=arm, eta=arm * tau_p)


def pair_material(mat1: Material | None, mat2: Material | None) -> Material:
    """The one half-space material equivalent to two bodies' materials in contact.

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
        return mat2 if mat1 is None else mat1
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
            "pair: must have equal nu (with unequal nu the series combination has different "
            "relaxation spectra in the normal and the tangential direction, which no single "
            "half-space material reproduces)")
    for elastic, other in ((mat1, mat2), (mat2, mat1)):
        if _is_elastic(elastic):
            if len(other.arms) + (other.eta0 > 0) == 1 and not (other.arms and other.eta0 > 0):
                return _elastic_with_viscoelastic(elastic.G_inf, other)
            raise InputError(
                f"material pair (elastic, {other.model} with {len(other.arms)} arms and "
                f"eta0 = {other.eta0!r}) is not allowed: must be an elastic body against a "
                "Kelvin-Voigt or a one-arm standard solid (the series combination is only derived "
                "for those; a general Prony series is not mapped)")
    raise InputError(
        f"material pair ({mat1.model}, {mat2.model}) is not allowed: two different viscoelastic "
        "materials map onto one half-space only when one is a multiple of the other (same nu and "
        "relaxation times); their series combination is not one generalized Maxwell material "
        "of the supported form")


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
    """The rigid-sphere scene equivalent to ``body1`` hitting ``other``.

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


def _reconstruct(body1: Body, other: Body | Wall, scene: Scene, e_z: float, beta_x: float):
    """Both bodies' end states from the relative result (momentum exactly conserved)."""
    v_z_end = -e_z * scene.v_z0  # relative normal velocity after (moving apart)
    J_z = scene.m * (v_z_end - scene.v_z0)  # on body 1, along z
    if scene.computes_tangential and math.isfinite(beta_x):
        v_c_end = -beta_x * scene.v_c0
        spin_total = scene.R**2 / scene.Theta if scene.rotation else 0.0
        P = (scene.v_c0 - v_c_end) / (1.0 / scene.m + spin_total)  # tangential impulse magnitude
    else:
        P = 0.0
    J_x = -P  # on body 1
    b1 = (body1.v_z + J_z / body1.m, body1.v_x + J_x / body1.m,
          body1.omega + (body1.R * J_x / body1.Theta if body1.rotation else 0.0))
    if isinstance(other, Wall):
        return b1, None, J_z, J_x
    # body 2 gets -J at its contact point (-R2 along z): torque_y = -R2 * (-J_x)
    b2 = (other.v_z - J_z / other.m, other.v_x - J_x / other.m,
          other.omega + (other.R * J_x / other.Theta if other.rotation else 0.0))
    return b1, b2, J_z, J_x


def simulate_pair(body1: Body, other: Body | Wall, numerics=None, **scene_options) -> PairResult:
    """Simulate body 1 hitting body 2 (or a wall).

    Parameters
    ----------
    body1 : the first body; ``other`` : the second body or a :class:`Wall`
    numerics : :class:`vimpact.Numerics` (default: the engine's default)
    scene_options : ``tangential``, ``tangential_memory``, ``mu``,
        ``allow_large_contact`` of the equivalent scene (:func:`pair_scene`)

    Returns
    -------
    PairResult
    """
    from vimpact.engine.simulate import simulate

    scene = pair_scene(body1, other, **scene_options)
    res = simulate(scene, numerics)
    b1, b2, J_z, J_x = _reconstruct(body1, other, scene, res.e_z, res.beta_x)
    return PairResult(res.e_z, res.beta_x, b1, b2, J_z, J_x, res.status, scene, res)


def simulate_pair_batch(pairs: Sequence[tuple[Body, Body | Wall]], numerics=None,
                        **scene_options):
    """Simulate many pair impacts in one batch.

    Parameters
    ----------
    pairs : sequence of ``(body1, body2_or_wall)``
    numerics, scene_options : as :func:`simulate_pair`

    Returns
    -------
    pandas.DataFrame
        one row per pair: ``e_z, beta_x, status, t_contact_s`` and the end
        states ``v_z1, v_x1, omega1, v_z2, v_x2, omega2`` (m/s, rad/s; NaN for a
        wall) and the impulses on body 1 ``J_z, J_x`` (N s), and ``error``. A pair
        that is not a valid ``(body, body or wall)`` approaching along ``z`` gets
        status ``invalid``, its reason in ``error`` and NaN numbers; the other pairs
        are unaffected (nothing is raised for a bad pair).
    """
    import pandas as pd

    from vimpact.engine.simulate import simulate_batch

    pairs = list(pairs)
    n = len(pairs)
    scenes: list = [None] * n
    reasons: list = [None] * n
    for i, pair in enumerate(pairs):
        try:
            b1, b2 = pair
            require(f"pairs[{i}]", pair, isinstance(b1, Body) and isinstance(b2, (Body, Wall)),
                    "a (vimpact.Body, vimpact.Body or vimpact.Wall) pair")
            scenes[i] = pair_scene(b1, b2, **scene_options)
        except (ValueError, TypeError) as exc:
            reasons[i] = (f"pairs[{i}]: {exc}" if isinstance(exc, ValueError) else
                          message(f"pairs[{i}]", pair, "a (vimpact.Body, vimpact.Body or "
                                                       "vimpact.Wall) pair"))
    good = [i for i in range(n) if scenes[i] is not None]
    df = simulate_batch([scenes[i] for i in good], numerics)
    columns = ["e_z", "beta_x", "status", "t_contact", "v_z1", "v_x1", "omega1", "v_z2", "v_x2",
               "omega2", "J_z", "J_x", "error"]
    rows = [dict(e_z=np.nan, beta_x=np.nan, status="invalid", t_contact=np.nan, v_z1=np.nan,
                 v_x1=np.nan, omega1=np.nan, v_z2=np.nan, v_x2=np.nan, omega2=np.nan,
                 J_z=np.nan, J_x=np.nan, error=reasons[i]) for i in range(n)]
    for k, i in enumerate(good):
        row = df.iloc[k]
        e_z, beta_x = float(row["e_z"]), float(row["beta_x"])
        rows[i].update(e_z=e_z, beta_x=beta_x, status=row["status"],
                       t_contact=float(row["t_contact"]), error=row.get("error"))
        if math.isfinite(e_z):
            b1, b2 = pairs[i]
            end1, end2, J_z, J_x = _reconstruct(b1, b2, scenes[i], e_z, beta_x)
            end2 = end2 or (np.nan, np.nan, np.nan)
            rows[i].update(zip(("v_z1", "v_x1", "omega1", "v_z2", "v_x2", "omega2", "J_z",
                                "J_x"), (*end1, *end2, J_z, J_x)))
    out = pd.DataFrame(rows, columns=columns)
    return out.rename(columns={"t_contact": "t_contact_s"})


def pair_restitution(body1: Body, other: Body | Wall, speeds, *, tangential: bool = False,
                     vc_ratio: float = 1.0, numerics=None, mu: float = math.inf):
    """``e_z`` (and ``beta_x``) of a pair over approach speeds: the curves DEM fits need.

    Parameters
    ----------
    body1, other : the pair (their velocities are ignored)
    speeds : approach speeds ``v_z0``, m/s (array)
    tangential : also solve the tangential problem (full stick unless ``mu``)
        with ``v_c0 = vc_ratio * v_z0``; otherwise normal only (fast)
    numerics : :class:`vimpact.Numerics`

    Returns
    -------
    pandas.DataFrame with columns ``v_z0, e_z, beta_x, t_contact, a_max, status``.
    """
    from vimpact.engine.simulate import simulate_batch

    speeds = np.asarray(speeds, dtype=float)
    require("speeds", speeds, speeds.ndim == 1 and speeds.size > 0 and bool(np.all(speeds > 0))
            and bool(np.all(np.isfinite(speeds))), "a non-empty 1-D array of finite speeds > 0")
    base = pair_scene(Body(body1.material, body1.R, body1.m, body1.Theta, v_z=1.0,
                           rotation=body1.rotation),
                      other if isinstance(other, Wall) else
                      Body(other.material, other.R, other.m, other.Theta, rotation=other.rotation),
                      tangential="stick" if tangential else "none", mu=mu,
                      allow_large_contact=True)
    scenes = [Scene(base.material, R=base.R, m=base.m, v_z0=v, v_x0=vc_ratio * v if tangential
                    else 0.0, Theta=base.Theta if base.rotation else None,
                    rotation=base.rotation, tangential=base.tangential, mu=mu,
                    allow_large_contact=True) for v in speeds]
    df = simulate_batch(scenes, numerics)
    out = df[["e_z", "beta_x", "t_contact", "a_max", "status"]].reset_index(drop=True)
    out.insert(0, "v_z0", speeds)
    return out
