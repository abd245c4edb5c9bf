"""Restitution of a polymer at several temperatures (time-temperature superposition).

:func:`fig_temperature` draws ``e_z(v_z0)`` of a sphere on a half-space of a
material file with a shift law (default: the example
``sweeps/materials/synthetic_rubber.toml``, a Prony series fitted to a
synthetic DMA master curve; docs/howto/dma.md) at several temperatures: the
same moduli, relaxation times scaled by the shift factor ``a_T``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vimpact.engine.simulate import simulate_batch
from vimpact.model.material import Material
from vimpact.model.numerics import Numerics
from vimpact.model.scene import Scene
from vimpact.plots.figures import _MARKERS, _drawing

#: The example material (relative to the repository root, where the figures are drawn).
EXAMPLE_MATERIAL = Path("sweeps/materials/synthetic_rubber.toml")
#: Temperatures of the curves, K.
TEMPERATURES_K = (240.0, 250.0, 260.0, 270.0, 300.0)
#: Normal impact speeds, m/s (contact half-width below 0.2 R at every temperature).
SPEEDS_M_S = tuple(np.geomspace(0.02, 0.5, 9))
#: The sphere: radius (m) and mass (kg): a 2 cm ball of density 955 kg/m^3.
SPHERE = (0.01, 0.004)
#: Numerics of the figure: about 1e-3 on e_z, so that it takes seconds.
FIGURE_NUMERICS = Numerics.preset("fast")


def restitution_curves(material: Material, temperatures=TEMPERATURES_K, speeds=SPEEDS_M_S,
                       numerics: Numerics = FIGURE_NUMERICS) -> dict[float, np.ndarray]:
    """Return ``e_z`` over the normal speed at each temperature.

    ``e_z`` at each normal speed (m/s) for each temperature (K) of ``material``
    (shifted by its shift law), sphere :data:`SPHERE`; temperature -> array.
    """
    R, m = SPHERE
    out = {}
    for T in temperatures:
        shifted = material.at_temperature(T)
        scenes = [Scene(shifted, R=R, m=m, v_z0=float(v)) for v in speeds]
        df = simulate_batch(scenes, numerics)
        if not df.status.isin(("ok", "vc0_zero")).all():
            bad = df[~df.status.isin(("ok", "vc0_zero"))].iloc[0]
            raise RuntimeError(f"temperature figure: a scene at {T:g} K ended with status "
                               f"{bad.status}: {bad.error}")
        out[float(T)] = df.e_z.to_numpy()
    return out


def fig_temperature(out, material: Material | str | Path | None = None) -> Path:
    """Draw ``e_z`` over the impact speed at several temperatures.

    ``e_z`` over the impact speed at :data:`TEMPERATURES_K` for ``material`` (a
    :class:`Material` with a shift law or a material file; default
    :data:`EXAMPLE_MATERIAL`, read relative to the current directory).
    """
    from vimpact.model.material_file import load_material

    if material is None:
        if not EXAMPLE_MATERIAL.is_file():
            raise ValueError(f"figure fig_temperature reads {EXAMPLE_MATERIAL}: draw it from "
                             "the repository root")
        material = EXAMPLE_MATERIAL
    name = "material"
    if not isinstance(material, Material):
        name = Path(material).stem.replace("_", " ")
        material = load_material(material)
    curves = restitution_curves(material)
    shift = material.shift
    assert shift is not None  # restitution_curves (at_temperature) needs a shift law
    R, m = SPHERE
    with _drawing(out, figsize=(8.4, 4.4)) as (fig, ax):
        for k, (T, e_z) in enumerate(curves.items()):
            ax.plot(SPEEDS_M_S, e_z, marker=_MARKERS[k % len(_MARKERS)],
                    label=f"T = {T:g} K (a_T = {shift.shift_factor(T):.2g})")
        ax.set_xscale("log")
        from matplotlib.ticker import NullFormatter
        ticks = [v for v in (0.02, 0.05, 0.1, 0.2, 0.5) if SPEEDS_M_S[0] <= v <= SPEEDS_M_S[-1]]
        ax.set_xticks(ticks, labels=[f"{v:g}" for v in ticks])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(r"normal impact speed $v_{z0}$ (m/s)")
        ax.set_ylabel(r"$e_z$ (dimensionless)")
        ax.set_title(f"sphere R = {R * 100:g} cm, m = {m * 1000:g} g on the {name}")
        ax.legend(title=shift.describe().replace(", T_ref", "\nT_ref"),
                  title_fontsize=9, loc="center left", bbox_to_anchor=(1.01, 0.5))
    return Path(out)


__all__ = ["EXAMPLE_MATERIAL", "SPEEDS_M_S", "SPHERE", "TEMPERATURES_K", "fig_temperature",
           "restitution_curves"]
