"""Make ``synthetic_rubber_dma.csv``: a SYNTHETIC DMA master curve with the shape of a rubber.

The data are not a measurement. They are the shear storage and loss moduli of
a stated Prony series (below), evaluated with the closed forms

    G'(omega)  = G_inf + sum_i G_i omega^2 tau_i^2 / (1 + omega^2 tau_i^2)
    G''(omega) = sum_i G_i omega tau_i / (1 + omega^2 tau_i^2),   omega = 2 pi f,

at 49 frequencies from 1e-5 Hz to 1e7 Hz (4 per decade), each value multiplied
by exp(0.01 z) with z standard normal (seeded): 1 % scatter, as if measured.
The generating series, chosen for the shape of a rubber's master curve (not
fitted to any real material):

- relaxed (rubbery) modulus G_inf = 1.0e6 Pa, glassy modulus G_inf + sum G_i =
  1.0e9 Pa (ratio 1e3);
- 25 arms, tau_i = 10^(k/2) s for k = -16 .. 8 (1e-8 s .. 1e4 s, twelve
  decades, two per decade), G_i proportional to tau_i^(-1/4) (a power-law
  transition zone, G(t) ~ t^(-1/4)).

Its reference temperature is taken as its glass transition, T_ref = T_g =
220 K, and its temperature shift as the WLF law with the "universal"
constants C1 = 17.44, C2 = 51.6 K (Williams, Landel and Ferry, 1955), valid
above about T_g. Run from the repository root to remake the file:

    python sweeps/materials/synthetic_rubber.py
"""

from pathlib import Path

import numpy as np

from vimpact.model.fit import storage_loss
from vimpact.model.material import Material

#: reference temperature (the synthetic rubber's glass transition), K; WLF C1, C2 (K)
T_REF_K, WLF_C1, WLF_C2_K = 220.0, 17.44, 51.6
#: Poisson ratio used with the data (not part of a DMA shear measurement)
NU = 0.49


def generating_material() -> Material:
    """The stated Prony series the data are made from (module doc)."""
    taus = 10.0 ** (np.arange(-16, 9) / 2.0)
    G = taus ** -0.25
    G *= 999.0e6 / G.sum()
    return Material.prony(nu=NU, G_inf=1.0e6, arms=[(float(g), float(t)) for g, t in zip(G, taus)])


def main() -> None:
    f = np.geomspace(1e-5, 1e7, 49)
    storage, loss = storage_loss(generating_material(), f)
    rng = np.random.default_rng(22)
    storage = storage * np.exp(0.01 * rng.standard_normal(f.size))
    loss = loss * np.exp(0.01 * rng.standard_normal(f.size))
    lines = ["# SYNTHETIC master curve with the shape of a rubber, not a measurement:",
             "# made by sweeps/materials/synthetic_rubber.py from a stated Prony series",
             "# (G_inf = 1e6 Pa, 25 arms, tau 1e-8..1e4 s, glassy modulus 1e9 Pa), 1 % scatter.",
             f"# Shear moduli at the reference temperature T_ref = {T_REF_K:g} K (its T_g);",
             f"# shift law: WLF, C1 = {WLF_C1:g}, C2 = {WLF_C2_K:g} K (the universal constants).",
             "frequency_Hz,storage_Pa,loss_Pa"]
    lines += [f"{a:.6g},{b:.6g},{c:.6g}" for a, b, c in zip(f, storage, loss)]
    out = Path(__file__).with_name("synthetic_rubber_dma.csv")
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
