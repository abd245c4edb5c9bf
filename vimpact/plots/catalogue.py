"""The thesis figures that ``vimpact plot`` draws.

Names, titles and the sweep spec of each figure's table, without loading the drawing code
(numpy only; the command line's parser reads it). The drawings are in
:mod:`vimpact.plots.figures`.
"""

from __future__ import annotations

#: name -> (title, sweep spec of its table or ``None`` when computed on the fly)
CATALOGUE: dict[str, tuple[str, str | None]] = {
    "fig3_2": ("linear model: e and omega0 t* over zeta", None),
    "fig4_2": ("v_z, v_x, omega during one impact", None),
    "fig4_4": ("explicit Euler phase plane vs. exact elastic curve", None),
    "fig5_1": ("e_z, e_x over Q1, random physical draws", "sweeps/fig5_1_kelvin_voigt_random.toml"),
    "fig5_2": ("e_z over Q1, Kelvin-Voigt, with linear model and continuum",
               "sweeps/fig5_2_3_kelvin_voigt_nu.toml"),
    "fig5_3": ("e_x over Q1, Kelvin-Voigt, nu = 0, 0.25, 0.5",
               "sweeps/fig5_2_3_kelvin_voigt_nu.toml"),
    "fig5_4": ("e_z over Q1, standard solid, family of Q2",
               "sweeps/fig5_4_5_standard_solid_q2.toml (+ sweeps/fig5_4_5_kelvin_voigt.toml)"),
    "fig5_5": ("e_x over Q1, standard solid, family of Q2",
               "sweeps/fig5_4_5_standard_solid_q2.toml (+ sweeps/fig5_4_5_kelvin_voigt.toml)"),
    "fig_mbf": ("friction: exit psi2 over incidence psi1, elastic sphere, several chi (Maw, "
                "Barber and Fawcett)", None),
    "fig_beta_psi": ("friction: beta_x over psi for several Q1", None),
    "fig_chung_ooi": ("friction: rebound angle and spin over the impact angle (Chung and Ooi "
                      "2011, test 4)", None),
    "fig_temperature": ("e_z over the impact speed at several temperatures, the example "
                        "polymer sweeps/materials/synthetic_rubber.toml (run from the "
                        "repository root)", None),
    "fig_adhesion": ("adhesion: e_z over the impact speed with the sticking velocity, elastic "
                     "and Kelvin-Voigt half-space", None),
}

#: Names accepted by :func:`vimpact.plots.figures.plot_figure` (also ``"5.2"``,
#: ``"fig5.2"``, ``"fig5_2"``).
FIGURE_NAMES = tuple(CATALOGUE)


def figure_name(name: str) -> str:
    """Canonical figure name: ``"5.2"``, ``"fig5.2"``, ``"Fig 5-2"`` -> ``"fig5_2"``."""
    key = str(name).strip().lower().replace(" ", "")
    for prefix in ("figure", "fig"):
        if key.startswith(prefix):
            key = key[len(prefix):]
            break
    key = "fig" + key.replace(".", "_").replace("-", "_")
    if key not in CATALOGUE:
        raise ValueError(f"figure = {name!r} is not allowed: must be one of "
                         + ", ".join(FIGURE_NAMES))
    return key
