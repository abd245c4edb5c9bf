"""Scene builders and invariant checks shared by ``test_hard_cases.py`` and
``test_properties.py`` (hard cases stay numerically stable).

Every scene is built on the dimensionless base of
``Scene.from_dimensionless`` (``R = 1 m``, ``m = 1 kg``, ``v_z0 = 1 m/s``,
``a_H = 0.01 R``), so moduli are given relative to the relaxed modulus
``G_inf`` and relaxation times relative to the Hertz time unit ``T = d / v_z0``
(docs/physics.md#hertz-scales); ``h = t_H / steps = 2.94e-3 T`` at the default
numerics. Only the public API is used.
"""

from __future__ import annotations

import math

import numpy as np

import vimpact as v

#: the time step of the default numerics in units of T (t_H / 1000)
H_DEFAULT = v.HERTZ_TIME_FACTOR / v.Numerics().steps

#: invariant tolerances: energy passivity and |beta_x| <= 1
ENERGY_TOL = 1e-6
BETA_TOL = 1e-9
#: an elastic impact returns the normal speed (e_z = 1 within 1e-6)
ELASTIC_EZ_TOL = 1e-6
#: ``e_z <= 1`` with that tolerance: the time discretization of an (almost)
#: elastic impact returns the normal speed to about 1e-10 above 1 (default
#: numerics, elastic); more than 1e-6 above 1 is energy made by the numerics
EZ_MAX = 1.0 + ELASTIC_EZ_TOL

#: statuses whose numbers are results (``vimpact.engine.result.FINISHED``)
FINISHED = ("ok", "vc0_zero", "half_space")

OUTPUTS = ("e_z", "e_x", "beta_x", "t_contact", "u_max", "a_max", "energy_ratio",
           "v_z_end", "v_x_end", "omega_end")


def base(nu: float = 0.5) -> v.Scene:
    """The elastic dimensionless base scene (Q1 = 0) for Poisson ratio ``nu``."""
    return v.Scene.from_dimensionless(0.0, nu)


def hertz_unit(nu: float = 0.5) -> tuple[float, float]:
    """``(G_inf [Pa], T [s])`` of the base scene: moduli and times are given relative to these."""
    b = base(nu)
    return b.material.G_inf, b.hertz.T


def tau_of_q1(q1: float) -> float:
    """``eta / G_inf`` in units of T for damping ``Q1`` (docs/physics.md#dimensionless-parameters)."""
    return q1 / math.sqrt(15.0 / 32.0)


def material(kind: str, nu: float = 0.5, *, q1: float = 0.0, q2: float | None = None,
             arms=(), eta0: float = 0.0) -> v.Material:
    """A material on the base scale.

    ``kind``: ``elastic``; ``kelvin_voigt`` (``q1``); ``standard_solid``
    (``q1``, ``q2``); ``prony`` (``arms = [(G_i / G_inf, tau_i / T), ...]``,
    ``eta0`` = parallel dashpot time ``eta0 / G_inf`` in units of T).
    """
    G, T = hertz_unit(nu)
    if kind == "elastic":
        return v.Material.elastic(nu=nu, G=G)
    if kind == "kelvin_voigt":
        return v.Material.kelvin_voigt(nu=nu, G=G, eta=tau_of_q1(q1) * T * G)
    if kind == "standard_solid":
        return v.Material.standard_solid(nu=nu, G1=G, G2=G / q2, eta=tau_of_q1(q1) * T * G)
    if kind == "prony":
        return v.Material.prony(nu=nu, G_inf=G, arms=[(g * G, t * T) for g, t in arms],
                                eta0=eta0 * T * G)
    raise ValueError(kind)


def scene(mat: v.Material, *, theta: float = 0.4, v_x0: float = 1.0,
          omega0: float = 0.0) -> v.Scene:
    """The base sphere (``R = 1 m``, ``m = 1 kg``, ``v_z0 = 1 m/s``) on ``mat``.

    ``v_x0`` in m/s and ``omega0`` in rad/s are in units of ``v_z0`` and
    ``v_z0 / R``, so ``v_c0 / v_z0 = v_x0 + omega0``; ``theta = Theta / (m R^2)``.
    """
    return v.Scene(mat, R=1.0, m=1.0, v_z0=1.0, v_x0=v_x0, omega0=omega0, Theta=theta)


def tighter(numerics: v.Numerics | None = None) -> v.Numerics:
    """The convergence reference: twice the steps and twice the elements."""
    n = numerics or v.Numerics()
    return n.with_(steps=2 * n.steps, elements=2 * n.elements)


def fmt(x: float) -> str:
    """Compact number for test ids: 1e-05 -> 1e-5, 0.25 -> 0.25, 1000.0 -> 1e3."""
    if x == 0:
        return "0"
    if x == 2.0 / 3.0:
        return "2/3"
    if abs(x) >= 1e3 or abs(x) < 1e-2:
        mant, exp = f"{x:.0e}".split("e")
        return f"{mant}e{int(exp)}"
    return f"{x:g}"


def invariant_violations(row, scene_: v.Scene, allowed=("ok", "vc0_zero")) -> list[str]:
    """Every invariant that result ``row`` (dict-like) of ``scene_`` breaks.

    - status in ``allowed`` (never a silent failure status);
    - finite outputs (NaN only for e_x, beta_x with ``vc0_zero``);
    - ``0 <= e_z <= 1 + 1e-6`` (``EZ_MAX``), ``energy_ratio <= 1 + 1e-6`` (passive material,
      incremental memory), ``|beta_x| <= 1 + 1e-9`` and ``e_x = |beta_x|``.
    """
    bad = []
    status = row["status"]
    if status not in allowed:
        return [f"status {status!r} not in {allowed}"]
    vc0_zero = scene_.v_c0 == 0.0
    if (status == "vc0_zero") != vc0_zero:
        bad.append(f"status {status!r} but v_c0 = {scene_.v_c0!r}")
    for key in OUTPUTS:
        x = float(row[key])
        if key in ("e_x", "beta_x") and vc0_zero:
            if not math.isnan(x):
                bad.append(f"{key} = {x!r} should be NaN for v_c0 = 0")
        elif not math.isfinite(x):
            bad.append(f"{key} = {x!r} not finite")
    e_z = float(row["e_z"])
    if not 0.0 <= e_z <= EZ_MAX:
        bad.append(f"e_z = {e_z!r} outside [0, 1 + {ELASTIC_EZ_TOL:g}]")
    if not float(row["energy_ratio"]) <= 1.0 + ENERGY_TOL:
        bad.append(f"energy_ratio = {float(row['energy_ratio'])!r} > 1 + {ENERGY_TOL:g}")
    if not vc0_zero:
        beta = float(row["beta_x"])
        if not abs(beta) <= 1.0 + BETA_TOL:
            bad.append(f"|beta_x| = {abs(beta)!r} > 1 + {BETA_TOL:g}")
        if not float(row["e_x"]) == abs(beta):
            bad.append(f"e_x = {float(row['e_x'])!r} != |beta_x| = {abs(beta)!r}")
    if not float(row["u_max"]) > 0.0 or not float(row["t_contact"]) > 0.0:
        bad.append(f"u_max = {float(row['u_max'])!r}, t_contact = {float(row['t_contact'])!r} "
                   "should be > 0")
    return bad


def log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(10.0 ** rng.uniform(math.log10(lo), math.log10(hi)))
