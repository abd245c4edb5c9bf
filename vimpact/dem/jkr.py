"""LAMMPS' granular ``jkr`` normal model fitted to vimpact's adhesive ``e_z(v)``.

The law (LAMMPS ``pair_style granular`` / ``fix wall/gran`` with ``jkr E eta_n0 nu
cohesion damping viscoelastic``), as written here for a sphere on a wall
(effective radius ``R``, mass ``m``, effective modulus ``E*``, overlap ``delta``):

- contact forms at ``delta = 0`` and follows the JKR curve ``delta(a) = a^2/R -
  sqrt(2 pi a w / E*)`` with ``w = 2 cohesion`` (the surface energy is half the
  work of adhesion); the elastic force is ``4 E* a^3 / (3 R) - sqrt(8 pi w E* a^3)``;
- the damping is ``eta_n0 a m delta_dot`` (``damping viscoelastic``, ``a`` the JKR
  contact radius), opposing the overlap rate;
- the contact ends at ``delta = -(3 pi^2 / 16)^(1/3) (R cohesion^2 / E*^2)^(1/3)``,
  the indentation of the JKR force minimum (docs/physics.md#adhesion): earlier than
  the element row, which separates at the least indentation of the JKR curve.

A fit therefore chooses both ``cohesion`` and ``eta_n0`` (the cohesion of the
true work of adhesion would make LAMMPS' sphere stick below about 0.70 times our
elastic sticking velocity) to minimize the RMS difference to vimpact's ``e_z``
over the given speeds, sticking counted as ``e_z = 0``; the residual is
reported as it is. LAMMPS' wall mixes ``E`` as a body of the same material
(``E* = E / (2 (1 - nu^2))``, :mod:`vimpact.dem.lammps`), so the exported ``E`` is
``2 (1 - nu^2) E*``.

A pair (``pair_coeff i j jkr ...``) is the same law with the pair's effective
radius ``R1 R2 / (R1 + R2)`` and mass ``m1 m2 / (m1 + m2)`` in place of ``R``
and ``m`` (:meth:`JkrLaw.pair`): LAMMPS' ``jkr`` builds the contact radius, the
force, the pull-off distance and the damping ``eta_n0 a m_eff`` from ``R_eff``
and ``m_eff``, and mixes ``E`` of a ``pair_coeff`` line by the same
``E / (2 (1 - nu^2))`` as a wall; vimpact's pair is the sphere of ``R_eff``,
``m_eff`` on the halved half-space of the pair (:mod:`vimpact.model.pair`), the
target the pair line is fitted to.

Tangential: LAMMPS' ``jkr`` caps the tangential force at ``mu_s |F_ne + 2
F_pulloff|`` with ``F_ne`` the elastic JKR force (no damping) and ``F_pulloff =
3 pi cohesion R_eff``; its non-adhesive models cap at ``mu_s |F_n|`` with the
damping included. The exported tangential constants are fitted with the
non-adhesive cap (:mod:`vimpact.dem.lammps`), not with this one.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize

from vimpact.engine.adhesion import simulate_adhesive, sticking_velocity
from vimpact.model.scene import Scene
from vimpact.model.validation import InputError, positive

#: LAMMPS' pull-off distance prefactor, cbrt(3 pi^2 / 16)
PULLOFF_PREFIX = (3.0 * math.pi**2 / 16.0) ** (1.0 / 3.0)


@dataclass(frozen=True)
class JkrLaw:
    """LAMMPS' ``jkr`` law for one sphere on a wall (SI units); a pair: :meth:`pair`.

    Attributes
    ----------
    E_star : effective modulus of the contact, Pa
    R, m : sphere radius (m) and mass (kg)
    cohesion : LAMMPS' surface energy (half the work of adhesion), J/m^2
    eta_n0 : LAMMPS' viscoelastic damping coefficient, 1/(m s)
    """

    E_star: float
    R: float
    m: float
    cohesion: float
    eta_n0: float

    @classmethod
    def pair(cls, E_star: float, R1: float, m1: float, R2: float, m2: float, cohesion: float,
             eta_n0: float) -> JkrLaw:
        """Return the law of a ``pair_coeff`` contact of two spheres.

        Radii ``R1``, ``R2`` (m) and masses ``m1``, ``m2`` (kg) enter as the effective
        radius ``R1 R2 / (R1 + R2)`` and mass ``m1 m2 / (m1 + m2)``; ``E_star`` (Pa) is
        the pair's effective modulus, ``cohesion`` (J/m^2) and ``eta_n0`` (1/(m s)) as
        in the line.
        """
        return cls(E_star, R1 * R2 / (R1 + R2), m1 * m2 / (m1 + m2), cohesion, eta_n0)

    @property
    def pulloff(self) -> float:
        """Overlap at which LAMMPS ends the contact (negative), m."""
        return -PULLOFF_PREFIX * (self.R * self.cohesion**2 / self.E_star**2) ** (1.0 / 3.0)

    def radius(self, delta: float) -> float:
        """JKR contact radius at overlap ``delta`` (the stable root), m."""
        w = 2.0 * self.cohesion
        a_min = (math.pi * w * self.R**2 / (8.0 * self.E_star)) ** (1.0 / 3.0)

        def f(a):
            return a * a / self.R - math.sqrt(2.0 * math.pi * a * w / self.E_star) - delta
        hi = 2.0 * max(a_min, math.sqrt(self.R * max(delta, 0.0)), 1e-300)
        while f(hi) < 0.0:
            hi *= 2.0
        if f(a_min) >= 0.0:
            return a_min
        return brentq(f, a_min, hi, xtol=1e-15 * hi, rtol=1e-14)

    def force(self, delta: float, rate: float) -> float:
        """Return the normal force on the sphere (positive: pushes it out), N."""
        a = self.radius(delta)
        w = 2.0 * self.cohesion
        elastic = (4.0 * self.E_star * a**3 / (3.0 * self.R)
                   - math.sqrt(8.0 * math.pi * w * self.E_star * a**3))
        return elastic + self.eta_n0 * a * self.m * rate

    def restitution(self, v: float, rtol: float = 1e-9) -> float:
        """Return ``e_z`` at approach speed ``v`` (m/s); 0 if the sphere sticks.

        It sticks when it turns back towards the wall in contact after it had
        started to rebound.
        """
        def rhs(_, y):
            return [y[1], -self.force(y[0], y[1]) / self.m]

        def leave(_, y):
            return y[0] - self.pulloff
        leave.terminal, leave.direction = True, -1.0  # type: ignore[attr-defined]

        def turn(_, y):
            return y[1]
        turn.terminal = True  # type: ignore[attr-defined]
        t_scale = (self.m**2 / (self.E_star**2 * self.R * v)) ** 0.2  # Hertz time scale
        y0 = [0.0, v]
        rebounding = False
        for _ in range(4):
            sol = solve_ivp(rhs, (0.0, 1e4 * t_scale), y0, events=(leave, turn), rtol=rtol,
                            atol=[1e-14 * self.R, 1e-14 * v], max_step=0.05 * t_scale)
            if sol.t_events[0].size:
                return -float(sol.y_events[0][0][1]) / v
            if sol.t_events[1].size:
                if rebounding:
                    return 0.0
                rebounding = True
                y0 = [float(sol.y_events[1][0][0]), -1e-12 * v]
                continue
            break
        raise RuntimeError("the jkr law's impact did not end")


def law_sticking_velocity(law: JkrLaw, v_guess: float, rtol: float = 1e-3) -> float:
    """Return the speed (m/s) below which ``law``'s sphere sticks.

    By bisection to relative width ``rtol``; the bracket grows from ``v_guess``
    (m/s) by halving/doubling.
    """
    lo = hi = positive("v_guess", v_guess)
    while law.restitution(lo) > 0.0:
        lo *= 0.5
        if lo < 1e-12 * v_guess:
            return 0.0
    while law.restitution(hi) == 0.0:
        hi *= 2.0
    lo = max(lo, 0.5 * hi) if law.restitution(0.5 * hi) == 0.0 else lo
    while hi - lo > rtol * lo:
        mid = 0.5 * (lo + hi)
        if law.restitution(mid) == 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@dataclass(frozen=True)
class JkrFit:
    """LAMMPS ``jkr`` constants fitted to vimpact's adhesive restitution of one scene.

    Attributes
    ----------
    law : the fitted law (``cohesion``, ``eta_n0``)
    E_lammps : the ``E`` to give LAMMPS for a wall (``2 (1 - nu^2) E*``), Pa
    nu : Poisson ratio
    speeds, e_vimpact, e_law : the fitted points (m/s) and both restitutions there
    max_abs, rms : residual ``e_law - e_vimpact``
    v_stick_vimpact, v_stick_law : sticking velocities (m/s, relative width 1e-3)
    """

    law: JkrLaw
    E_lammps: float
    nu: float
    speeds: np.ndarray
    e_vimpact: np.ndarray
    e_law: np.ndarray
    max_abs: float
    rms: float
    v_stick_vimpact: float
    v_stick_law: float

    def coeffs(self) -> str:
        """Return the ``pair_coeff`` / ``fix wall/gran`` model text."""
        return (f"jkr {self.E_lammps:.12g} {self.law.eta_n0:.12g} {self.nu:.12g} "
                f"{self.law.cohesion:.12g} damping viscoelastic tangential linear_nohistory 0 0")


def fit_jkr(scene: Scene, speeds, numerics=None, target=None) -> JkrFit:
    """Fit LAMMPS' ``cohesion`` and ``eta_n0`` to vimpact's adhesive ``e_z`` of ``scene``.

    At ``speeds`` (m/s; ``scene.v_z0`` is replaced), least squares, starting from
    the true surface energy (J/m^2) times ``exp(0.4)`` and the damping
    ``2 E* tau / m`` (1/s; ``tau`` the material's viscous time, at least ``1e-3``
    Hertz times). ``target``: vimpact's ``e_z`` at ``speeds`` when already run (else
    it is run here).
    """
    speeds = np.asarray(speeds, dtype=float)
    if speeds.size < 2 or not np.all(np.isfinite(speeds) & (speeds > 0.0)):
        raise InputError(f"speeds = {speeds!r} is not allowed: must be at least two "
                         "finite speeds > 0 (m/s)")
    positive("adhesion", scene.adhesion)
    target = (np.array([simulate_adhesive(dataclasses.replace(scene, v_z0=float(v)),
                                          numerics).e_z for v in speeds])
              if target is None else np.asarray(target, dtype=float))
    E_star, R, m = scene.E_star, scene.R, scene.m
    tau = scene.material.viscous_time()
    t_H = float(scene.hertz.t_H)
    tau = tau if math.isfinite(tau) and tau > 1e-3 * t_H else 1e-3 * t_H
    c0, eta_scale = scene.adhesion / 2.0, 2.0 * E_star * tau / m

    def law(z) -> JkrLaw:
        return JkrLaw(E_star, R, m, c0 * math.exp(float(z[0])), eta_scale * float(z[1]) ** 2)

    def cost(z) -> float:
        L = law(z)
        return float(np.mean([(L.restitution(v, 1e-7) - t) ** 2 for v, t in zip(speeds, target)]))

    best = minimize(cost, [0.4, 1.0], method="Nelder-Mead",
                    options={"xatol": 1e-3, "fatol": 1e-8, "maxiter": 80})
    L = law(best.x)
    e_law = np.array([L.restitution(v) for v in speeds])
    d = e_law - target
    nu = scene.material.nu
    v_s = sticking_velocity(scene, numerics)
    return JkrFit(L, 2.0 * (1.0 - nu**2) * E_star, nu, speeds, target, e_law,
                  float(np.max(np.abs(d))), float(np.sqrt(np.mean(d * d))), v_s,
                  law_sticking_velocity(L, v_s))


def lammps_restitution(fit: JkrFit, v: float, steps_per_contact: int = 4000) -> float:
    """Return the ``e_z`` LAMMPS gives with ``fit``'s constants at ``v`` (m/s), sphere on a wall.

    0 if the sphere is still in contact at the end.
    """
    L = fit.law
    rho = L.m / (4.0 / 3.0 * math.pi * L.R**3)
    return lammps_jkr_restitution(fit.coeffs(), L, L.R, rho, v,
                                  steps_per_contact=steps_per_contact)


def lammps_jkr_restitution(coeffs: str, law: JkrLaw, R1: float, rho1: float, v: float, *,
                           R2: float | None = None, rho2: float | None = None,
                           steps_per_contact: int = 4000) -> float:
    """Run one head-on ``jkr`` collision in LAMMPS; return its ``e_z`` (0 if it stuck).

    Sphere 1 (radius ``R1``, m; density ``rho1``, kg/m^3) hits a wall (``R2`` None) or
    a second sphere (``R2``, ``rho2``; equal and opposite momenta) at approach speed
    ``v`` (m/s), with the model text ``coeffs`` (``jkr ...``) as the ``pair_coeff`` and
    the wall's. ``law`` (the contact's :class:`JkrLaw`, with the pair's effective
    radius and mass for a pair) sets the time step (``steps_per_contact`` per five
    Hertz time scales) and the pull-off distance: the collision stuck when the overlap
    at the end is above it.
    """
    return lammps_jkr_restitutions(coeffs, law, R1, rho1, [v], R2=R2, rho2=rho2,
                                   steps_per_contact=steps_per_contact)[0]


def lammps_jkr_restitutions(coeffs: str, law: JkrLaw, R1: float, rho1: float, speeds, *,
                            R2: float | None = None, rho2: float | None = None,
                            steps_per_contact: int = 4000) -> list[float]:
    """Return :func:`lammps_jkr_restitution` at each approach speed of ``speeds`` (m/s).

    Each collision is its own LAMMPS run, all in one process
    (:func:`vimpact.dem.lammps.run_lammps_many`).
    """
    from vimpact.dem.lammps import collision_script, run_lammps_many

    names = ["v1", "v2", "z1", "z2"]
    runs = []
    for v in speeds:
        t_c = 5.0 * (law.m**2 / (law.E_star**2 * law.R * v)) ** 0.2
        script = collision_script(coeffs, R1, rho1, v, t_c, R2=R2, rho2=rho2,
                                  steps_per_contact=steps_per_contact)
        script += ("variable z1 equal z[1]\n"
                   + ("variable z2 equal 0.0\n" if R2 is None else "variable z2 equal z[2]\n"))
        runs.append((script, names))
    out = []
    for v, (v1, v2, z1, z2) in zip(speeds, run_lammps_many(runs)):
        if R2 is None:
            overlap, e = R1 - z1, v1 / v
        else:
            overlap, e = R1 + R2 - (z2 - z1), (v2 - v1) / v
        out.append(0.0 if overlap > law.pulloff else e)
    return out


#: the caps of the tangential force :func:`oblique_wall_impact` can apply: LAMMPS' ``jkr``
#: one and the clipped normal force the non-adhesive models (and the tangential fit) use
TANGENTIAL_CAPS = ("jkr", "clipped")


def oblique_wall_impact(law: JkrLaw, k_t: float, x_gamma_t: float, mu_s: float, v: float,
                        angle_deg: float, *, cap: str = "jkr", steps_per_contact: int = 2000,
                        F: float = 3.5) -> tuple[float, float]:
    """Step LAMMPS' ``jkr ... tangential mindlin k_t x_gamma_t mu_s`` oblique wall impact.

    A sphere without spin arrives at normal speed ``v`` (m/s), ``angle_deg`` from the
    normal (tangential speed ``v tan(angle)``), stepped with velocity Verlet as ``fix
    nve/sphere`` steps it (``steps_per_contact`` per five Hertz time scales). Normal: the
    force of ``law`` (contact from overlap 0 to its pull-off overlap). Tangential (LAMMPS'
    ``mindlin``): the history ``s`` grows by the contact-point velocity ``w`` times the
    step, the force is ``k_t a s + x_gamma_t eta_n0 a m w`` (``a`` the JKR contact radius,
    ``k_t`` in Pa) and, above ``mu_s`` times the cap, is set to the cap and ``s`` to its
    elastic part. ``cap``: ``"jkr"``, LAMMPS' ``|F_ne + 2 F_pulloff|`` (``F_ne`` the
    elastic JKR force, ``F_pulloff = 3 pi cohesion R``), or ``"clipped"``, the normal force
    with its damping clipped at zero (the non-adhesive models' cap). ``F = 1 + m R^2 /
    Theta`` (3.5: a solid sphere) moves the contact point per unit tangential impulse.

    Returns
    -------
    (e, beta) : normal restitution and ``beta = -w_end / w_0``; ``e = 0`` (and ``beta``
    at the last step) if the sphere is still in contact after 50 contact lengths.
    """
    if cap not in TANGENTIAL_CAPS:
        raise InputError(f"cap = {cap!r} is not allowed: one of {', '.join(TANGENTIAL_CAPS)}")
    m, R = law.m, law.R
    t_c = 5.0 * (m**2 / (law.E_star**2 * R * v)) ** 0.2
    h = t_c / steps_per_contact
    f_pulloff = 3.0 * math.pi * law.cohesion * R
    w_coh = 2.0 * law.cohesion

    def forces(d: float, rate: float, s: float, w: float) -> tuple[float, float, float]:
        a = law.radius(d)
        f_e = (4.0 * law.E_star * a**3 / (3.0 * R)
               - math.sqrt(8.0 * math.pi * w_coh * law.E_star * a**3))
        damp_n = law.eta_n0 * a * m
        f_n = f_e + damp_n * rate
        limit = mu_s * (abs(f_e + 2.0 * f_pulloff) if cap == "jkr" else max(f_n, 0.0))
        k = k_t * a
        f_t = k * s + x_gamma_t * damp_n * w
        if abs(f_t) > limit:
            lim = math.copysign(limit, f_t)
            if s != 0.0 and k > 0.0:
                s = (lim - x_gamma_t * damp_n * w) / k
                f_t = lim
            else:
                f_t = 0.0
        return f_n / m, f_t / m, s

    w0 = v * math.tan(math.radians(angle_deg))
    d, rate, s, ux, om = 0.0, v, 0.0, w0, 0.0
    a_n, a_t = 0.0, 0.0
    for _ in range(50 * steps_per_contact):
        rate_h = rate - 0.5 * h * a_n
        ux_h = ux - 0.5 * h * a_t
        om_h = om + 0.5 * h * (F - 1.0) * a_t
        d += h * rate_h
        w_h = ux_h - om_h
        s += h * w_h
        a_n, a_t, s = forces(d, rate_h, s, w_h)
        rate = rate_h - 0.5 * h * a_n
        ux = ux_h - 0.5 * h * a_t
        om = om_h + 0.5 * h * (F - 1.0) * a_t
        if d < law.pulloff:
            return -rate / v, -(ux - om) / w0
    return 0.0, -(ux - om) / w0


def lammps_oblique_wall_impact(coeffs: str, law: JkrLaw, rho: float, v: float,
                               angle_deg: float, steps_per_contact: int = 4000
                               ) -> tuple[float, float]:
    """Run one oblique ``jkr`` wall impact in LAMMPS; return ``(e, beta)``.

    ``e`` and ``beta`` as :func:`oblique_wall_impact` defines them. The sphere of
    ``law`` (density ``rho``, kg/m^3; no spin) arrives at normal speed ``v`` (m/s),
    ``angle_deg`` from the normal, on ``fix wall/gran granular`` with the model text
    ``coeffs``. ``beta`` from the tangential impulse: the contact point's velocity
    changes ``1 + m R^2 / Theta = 3.5`` times the centre's (LAMMPS' solid sphere).
    """
    return lammps_oblique_wall_impacts(coeffs, law, rho, [v], angle_deg, steps_per_contact)[0]


def lammps_oblique_wall_impacts(coeffs: str, law: JkrLaw, rho: float, speeds, angle_deg: float,
                                steps_per_contact: int = 4000) -> list[tuple[float, float]]:
    """Return :func:`lammps_oblique_wall_impact` at each normal speed of ``speeds`` (m/s).

    Each impact is its own LAMMPS run, all in one process
    (:func:`vimpact.dem.lammps.run_lammps_many`).
    """
    from vimpact.dem.lammps import collision_script, run_lammps_many

    runs = []
    for v in speeds:
        v_t = v * math.tan(math.radians(angle_deg))
        t_c = 5.0 * (law.m**2 / (law.E_star**2 * law.R * v)) ** 0.2
        script = collision_script(coeffs, law.R, rho, v, t_c,
                                  steps_per_contact=steps_per_contact, v_t=v_t)
        runs.append((script + "variable z1 equal z[1]\n", ["v1", "vx1", "z1"]))
    out = []
    for v, (v1, vx1, z1) in zip(speeds, run_lammps_many(runs)):
        v_t = v * math.tan(math.radians(angle_deg))
        beta = -(v_t + 3.5 * (vx1 - v_t)) / v_t
        out.append((0.0, beta) if law.R - z1 > law.pulloff else (v1 / v, beta))
    return out
