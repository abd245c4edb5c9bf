"""Figures of the oblique impact with Coulomb friction, computed on the fly.

- :func:`fig_mbf`: Maw, Barber and Fawcett's exit against incidence, ``psi2``
  over ``psi1`` for an elastic sphere at several ``chi``, with the rigid-body
  sliding line ``psi2 = psi1 - 4 chi`` (Wear 38, 1976; Int. J. Mech. Sci. 23, 1981);
- :func:`fig_beta_psi`: ``beta_x`` over ``psi`` for several ``Q1`` (Kelvin-Voigt);
- :func:`fig_chung_ooi`: rebound angle and spin over the impact angle in the
  standard oblique DEM benchmark geometry (Chung and Ooi, Granular Matter 13,
  2011, test 4: alumina sphere on a rigid wall).

Definitions (docs/physics.md): ``psi = 2 (1 - nu) / (mu (2 - nu)) v_c / v_z0``
with ``v_c`` the contact-point velocity (``psi1`` before, ``psi2`` after the
impact, same sign convention), ``chi = (1 - nu)(1 + m R^2/Theta) / (2 - nu)``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vimpact.engine.simulate import simulate_batch
from vimpact.lookup.friction import chi as mindlin_chi
from vimpact.model.numerics import Numerics
from vimpact.model.scene import REFERENCE_INDENTATION
from vimpact.plots.style import drawing

#: Numerics of these figures: about 1e-3 on beta_x, so that a figure takes seconds.
FIGURE_NUMERICS = Numerics.preset("fast")


def _columns(nu, G, eta, R, m, v_z0, v_x0, theta_ratio, mu) -> dict:
    n = np.broadcast(v_z0, v_x0).shape[0]
    full = lambda x: np.broadcast_to(np.asarray(x, dtype=float), (n,)).copy()  # noqa: E731
    return {"nu": full(nu), "G_inf_Pa": full(G), "eta0_Pa_s": full(eta), "R_m": full(R),
            "m_kg": full(m), "v_z0_m_s": full(v_z0), "v_x0_m_s": full(v_x0),
            "theta_ratio": full(theta_ratio), "mu": full(mu)}


def _exit_incidence(nu, theta_ratio, Q1, psi1, mu=0.3) -> np.ndarray:
    """Return the exit incidences ``psi2`` for incidences ``psi1``.

    ``psi2`` for incidences ``psi1`` (a dimensionless scene: v_z0 = 1 m/s, R = 1 m,
    m = 1 kg, a_H = 0.01 R).
    """
    d = REFERENCE_INDENTATION  # m
    G = 15.0 / (16.0 * d**2.5) * (1.0 - nu) / 2.0  # E* from d at 1 m/s
    T = d / 1.0
    eta = Q1 / np.sqrt(15.0 / 32.0) * T * G
    v_c = psi1 * mu * (2.0 - nu) / (2.0 * (1.0 - nu))
    df = simulate_batch(_columns(nu, G, eta, 1.0, 1.0, 1.0, v_c, theta_ratio, mu),
                        FIGURE_NUMERICS)
    if not df.status.eq("ok").all():
        bad = df[df.status != "ok"].iloc[0]
        raise RuntimeError(f"friction figure: a scene ended with status {bad.status}: {bad.error}")
    return psi1 * -df.beta_x.to_numpy()


def fig_mbf(out) -> Path:
    """``psi2`` over ``psi1`` for an elastic sphere (nu = 0.3) at three ``chi``."""
    nu = 0.3
    psi1 = np.linspace(0.05, 8.0, 40)
    with drawing(out) as (fig, ax):
        for theta_ratio in (0.4, 1.0, 4.0):
            chi = mindlin_chi(nu, theta_ratio)
            psi2 = _exit_incidence(nu, theta_ratio, 0.0, psi1)
            line, = ax.plot(psi1, psi2, marker="o", ms=3,
                            label=rf"$\chi$ = {chi:.3g} ($\Theta/mR^2$ = {theta_ratio:g})")
            ax.plot(psi1, psi1 - 4.0 * chi, color=line.get_color(), ls=":", lw=1.0)
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_xlabel(r"incidence $\psi_1$")
        ax.set_ylabel(r"exit $\psi_2$")
        ax.set_title("elastic sphere with friction (dotted: gross slip, $\\psi_1 - 4\\chi$)")
        ax.legend()
    return Path(out)


def fig_beta_psi(out) -> Path:
    """``beta_x`` over ``psi`` for several ``Q1`` (Kelvin-Voigt, nu = 0.5, solid sphere)."""
    nu, theta_ratio = 0.5, 0.4
    psi1 = np.geomspace(0.05, 30.0, 40)
    with drawing(out) as (fig, ax):
        for Q1 in (0.0, 0.01, 0.1, 0.5):
            beta = -_exit_incidence(nu, theta_ratio, Q1, psi1) / psi1
            ax.semilogx(psi1, beta, marker="o", ms=3, label=f"Q1 = {Q1:g}")
        ax.axvline(4.0 * mindlin_chi(nu, theta_ratio), color="0.6", ls=":", lw=1.0)
        ax.set_xlabel(r"incidence $\psi$")
        ax.set_ylabel(r"$\beta_x$")
        ax.set_title(r"tangential restitution with friction ($\nu$ = 0.5; dotted: $4\chi$)")
        ax.legend()
    return Path(out)


#: Chung and Ooi (2011), test 4: alumina sphere on a rigid wall
CHUNG_OOI = {"E_Pa": 380e9, "nu": 0.23, "density_kg_m3": 4000.0, "R_m": 2.5e-3,
             "speed_m_s": 3.9, "mu": 0.092}


def chung_ooi_angles(angles_deg) -> dict:
    """Return the rebound angle and spin of the Chung-Ooi test 4 sphere.

    Rebound angle (deg) and spin (rad/s) of the Chung-Ooi test 4 sphere at the
    given impact angles (degrees from the normal), elastic, rigid wall.
    """
    p = CHUNG_OOI
    angles = np.radians(np.asarray(angles_deg, dtype=float))
    m = 4.0 / 3.0 * np.pi * p["R_m"] ** 3 * p["density_kg_m3"]
    G = p["E_Pa"] / (2.0 * (1.0 + p["nu"]))
    df = simulate_batch(_columns(p["nu"], G, 0.0, p["R_m"], m, p["speed_m_s"] * np.cos(angles),
                                 p["speed_m_s"] * np.sin(angles), 0.4, p["mu"]), FIGURE_NUMERICS)
    return {"rebound_angle_deg": df.rebound_angle.to_numpy(),
            "omega_end_rad_s": df.omega_end.to_numpy(), "status": df.status.to_numpy()}


def fig_chung_ooi(out) -> Path:
    """Rebound angle and spin over the impact angle, Chung-Ooi test 4 geometry."""
    angles = np.linspace(5.0, 85.0, 33)
    res = chung_ooi_angles(angles)
    with drawing(out, 1, 2, figsize=(10.0, 4.2)) as (fig, (ax1, ax2)):
        ax1.plot(angles, res["rebound_angle_deg"], marker="o", ms=3, label="vimpact")
        ax1.plot(angles, angles, color="0.6", ls=":", lw=1.0, label="mirror (no friction)")
        ax1.set_xlabel("impact angle from the normal, deg")
        ax1.set_ylabel("rebound angle of the centre, deg")
        ax1.legend()
        ax2.plot(angles, res["omega_end_rad_s"], marker="o", ms=3)
        ax2.set_xlabel("impact angle from the normal, deg")
        ax2.set_ylabel(r"spin after the impact $\omega$, rad/s")
        fig.suptitle("Chung-Ooi test 4: alumina sphere R = 2.5 mm, 3.9 m/s, mu = 0.092, "
                     "rigid wall")
    return Path(out)
