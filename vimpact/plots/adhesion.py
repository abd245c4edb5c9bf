"""Figure of the adhesive normal impact (docs/physics.md#adhesion), computed on the fly.

:func:`fig_adhesion`: ``e_z`` over the impact speed for a sphere on an elastic and
on a Kelvin-Voigt half-space with the same relaxed modulus and work of adhesion,
with each one's sticking velocity (vertical line) and the non-adhesive
Kelvin-Voigt restitution for comparison.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from vimpact.engine.adhesion import simulate_adhesive, sticking_velocity
from vimpact.model.material import Material
from vimpact.model.numerics import Numerics
from vimpact.model.scene import Scene
from vimpact.plots.style import drawing

#: The example: a 1 cm, 4 g sphere on a soft rubber (E* = 1.5 MPa, nu = 0.5) with a
#: work of adhesion 0.5 J/m^2; Kelvin-Voigt with eta = 30 Pa s.
EXAMPLE = {"E_Pa": 1.125e6, "nu": 0.5, "R_m": 0.01, "m_kg": 4e-3, "dgamma_J_m2": 0.5,
           "eta_Pa_s": 30.0}
#: Numerics of the figure (about 1e-3 on e_z, so that it takes seconds).
FIGURE_NUMERICS = Numerics.preset("fast")


def example_scenes() -> dict[str, Scene]:
    """Return the elastic and the Kelvin-Voigt example scene (at 0.1 m/s)."""
    p = EXAMPLE
    elastic = Material.elastic(nu=p["nu"], E=p["E_Pa"])
    kv = Material.kelvin_voigt(nu=p["nu"], E=p["E_Pa"], eta=p["eta_Pa_s"])
    return {name: Scene(mat, R=p["R_m"], m=p["m_kg"], v_z0=0.1, adhesion=p["dgamma_J_m2"],
                        tangential="none", allow_large_contact=True)
            for name, mat in (("elastic", elastic), ("Kelvin-Voigt", kv))}


def restitution_curve(scene: Scene, speeds) -> np.ndarray:
    """``e_z`` of ``scene`` at each speed (m/s); 0 where the sphere sticks."""
    return np.array([simulate_adhesive(dataclasses.replace(scene, v_z0=float(v)),
                                       FIGURE_NUMERICS).e_z for v in speeds])


def fig_adhesion(out) -> Path:
    """``e_z`` over ``v_z0`` with the sticking velocities, elastic and Kelvin-Voigt."""
    scenes = example_scenes()
    with drawing(out) as (fig, ax):
        for (name, scene), color in zip(scenes.items(), ("C0", "C1")):
            v_s = sticking_velocity(scene, FIGURE_NUMERICS, rtol=1e-3)
            speeds = np.concatenate([np.linspace(0.6, 1.0, 5)[:-1] * v_s,
                                     v_s * np.geomspace(1.0005, 100.0, 28)])
            ez = restitution_curve(scene, speeds)
            ax.semilogx(speeds, ez, marker="o", ms=3, color=color,
                        label=f"{name}, adhesive (sticks below {v_s * 1e3:.3g} mm/s)")
            ax.axvline(v_s, color=color, ls=":", lw=1.0)
            if name != "elastic":
                plain = restitution_curve(dataclasses.replace(scene, adhesion=0.0), speeds)
                ax.semilogx(speeds, plain, color=color, ls="--", lw=1.0,
                            label=f"{name}, no adhesion")
        p = EXAMPLE
        ax.set_xlabel(r"impact speed $v_{z0}$ (m/s)")
        ax.set_ylabel(r"$e_z$")
        ax.set_ylim(-0.02, 1.02)
        ax.set_title(rf"adhesive impact: $R$ = {p['R_m'] * 1e3:g} mm, $m$ = {p['m_kg'] * 1e3:g} g, "
                     rf"$E^*$ = {p['E_Pa'] / 0.75 / 1e6:g} MPa, $\Delta\gamma$ = "
                     rf"{p['dgamma_J_m2']:g} J/m$^2$, $\eta$ = {p['eta_Pa_s']:g} Pa s", fontsize=9)
        ax.legend(loc="lower right", fontsize=8)
    return Path(out)
