"""``vimpact material``: fit a Prony material to measurements; show a material file.

- ``vimpact material fit DATA.csv --nu NU --out material.toml``: a DMA master
  curve (``frequency_Hz, storage_Pa, loss_Pa``) or a relaxation modulus
  (``time_s, modulus_Pa``) to a material file (:mod:`vimpact.model.material_file`)
  that ``simulate --material``, scene files, sweep specifications and DEM
  set-ups read; with ``--T-ref`` and ``--wlf`` or ``--arrhenius`` it carries
  its temperature shift law.
- ``vimpact material show FILE [--temperature K]``: the material (at ``K``).

Guide: docs/howto/dma.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["add_parser"]


def add_parser(sub) -> None:
    """Register ``vimpact material`` on ``sub`` (the object of ``add_subparsers``)."""
    p = sub.add_parser("material", help="fit a Prony material to DMA or relaxation data",
                       description="Fit a Prony series to measured shear moduli and write a "
                                   "material file; show a material file at a temperature. "
                                   "Guide: docs/howto/dma.md.")
    actions = p.add_subparsers(dest="action", required=True, metavar="ACTION")

    fit = actions.add_parser(
        "fit", help="fit a Prony material to a CSV of measurements",
        description=("Fit G_inf and the moduli G_i of a Prony series with fixed log-spaced "
                     "relaxation times (non-negative least squares, relative misfit) to a CSV "
                     "file with the header frequency_Hz,storage_Pa,loss_Pa (a DMA master curve) "
                     "or time_s,modulus_Pa (a relaxation modulus); shear moduli unless "
                     "--tensile. Lines starting with # are comments."),
        epilog="Example: vimpact material fit sweeps/materials/synthetic_rubber_dma.csv "
               "--nu 0.49 --T-ref 220 --wlf 17.44 51.6 --out rubber.toml")
    fit.add_argument("data", metavar="DATA.csv", help="the measurements (CSV)")
    fit.add_argument("--nu", type=float, required=True, metavar="NU",
                     help="Poisson ratio, dimensionless, in [0, 0.5] (required)")
    fit.add_argument("--out", required=True, metavar="FILE.toml",
                     help="the material file to write (TOML)")
    fit.add_argument("--per-decade", type=float, default=None, metavar="N",
                     help="relaxation times per decade of the data's span (default 2)")
    fit.add_argument("--dashpot", action="store_true",
                     help="DMA data: also fit a parallel dashpot eta0 (a loss growing like "
                          "eta0 omega)")
    fit.add_argument("--tensile", action="store_true",
                     help="the data are Young's (tensile) moduli E', E'' or E(t): converted to "
                          "shear moduli G = E / (2 (1 + nu))")
    fit.add_argument("--T-ref", dest="T_ref", type=float, metavar="K",
                     help="reference temperature of the data (master curve), kelvin (> 0)")
    law = fit.add_mutually_exclusive_group()
    law.add_argument("--wlf", nargs=2, type=float, metavar=("C1", "C2_K"),
                     help="WLF shift law log10 a_T = -C1 (T - T_ref) / (C2 + T - T_ref); "
                          "C2 in kelvin (needs --T-ref)")
    law.add_argument("--arrhenius", type=float, metavar="EA_J_MOL",
                     help="Arrhenius shift law ln a_T = (E_a / R) (1/T - 1/T_ref), E_a in "
                          "J/mol (needs --T-ref)")
    fit.set_defaults(func=run_fit)

    show = actions.add_parser("show", help="print a material file (at a temperature)",
                              description="Print a material file's moduli, relaxation times "
                                          "and shift law; with --temperature, the material "
                                          "shifted to that temperature.")
    show.add_argument("file", metavar="FILE.toml", help="a material file")
    show.add_argument("--temperature", type=float, metavar="K",
                      help="temperature, kelvin (> 0): times shifted by the material's a_T")
    show.set_defaults(func=run_show)


def _shift(a):
    from vimpact.model.temperature import ShiftLaw

    if a.wlf is None and a.arrhenius is None:
        if a.T_ref is not None:
            raise ValueError(f"--T-ref = {a.T_ref:g} needs a shift law: give --wlf C1 C2_K "
                             "or --arrhenius EA_J_MOL")
        return None
    flag = "--wlf" if a.wlf is not None else "--arrhenius"
    if a.T_ref is None:
        raise ValueError(f"{flag} needs the reference temperature --T-ref K")
    try:
        if a.wlf is not None:
            return ShiftLaw.wlf(a.T_ref, *a.wlf)
        return ShiftLaw.arrhenius(a.T_ref, a.arrhenius)
    except ValueError as exc:
        text = str(exc)
        for name, opt in (("T_ref (reference temperature, K)", "--T-ref"),
                          ("C1 (WLF constant)", "--wlf C1"), ("C2 (WLF constant, K)", "--wlf C2_K"),
                          ("E_a (activation energy, J/mol)", "--arrhenius")):
            text = text.replace(name + " =", opt + " =")
        raise ValueError(text) from None


def run_fit(a: argparse.Namespace) -> int:
    """Run ``vimpact material fit`` and return the exit code."""
    from vimpact.model.fit import DEFAULT_PER_DECADE, load_measurements
    from vimpact.model.material import Material, shear_modulus
    from vimpact.model.material_file import material_toml
    from vimpact.model.validation import poisson_ratio

    out = Path(a.out)
    if out.suffix.lower() != ".toml":
        raise ValueError(f"--out = {a.out!r} is not allowed: must end in .toml")
    if not (out.parent if str(out.parent) else Path(".")).is_dir():
        raise ValueError(f"--out = {a.out!r} is not allowed: the folder {str(out.parent)!r} "
                         "does not exist")
    try:
        nu = poisson_ratio("--nu", a.nu)
    except ValueError as exc:
        raise ValueError(str(exc)) from None
    shift = _shift(a)
    if a.per_decade is None:
        a.per_decade = DEFAULT_PER_DECADE
    kind, cols = load_measurements(a.data)
    scale = shear_modulus(1.0, nu) if a.tensile else 1.0
    if kind == "dma":
        fitted, residual = _named(a.data, Material.from_dma, cols["frequency_Hz"],
                                  scale * cols["storage_Pa"], scale * cols["loss_Pa"], nu,
                                  per_decade=a.per_decade, dashpot=a.dashpot, shift=shift)
        what = f"DMA master curve, {len(cols['frequency_Hz'])} frequencies"
    else:
        if a.dashpot:
            raise ValueError("--dashpot is for DMA data (a relaxation modulus has no "
                             "dashpot term after t = 0)")
        fitted, residual = _named(a.data, Material.from_relaxation, cols["time_s"],
                                  scale * cols["modulus_Pa"], nu, per_decade=a.per_decade,
                                  shift=shift)
        what = f"relaxation modulus, {len(cols['time_s'])} times"
    n = len(fitted.arms)
    taus = [tau for _, tau in fitted.arms]
    comment = (f"Prony material fitted by vimpact material fit to {Path(a.data).name}\n"
               f"({what}{', tensile data converted to shear' if a.tensile else ''}): "
               f"{n} arms, {a.per_decade:g} relaxation times per decade;\n"
               f"RMS relative residual {residual:.3g}. Moduli in Pa, times in s, "
               "temperatures in K.")
    out.write_text(material_toml(fitted, comment), encoding="utf-8")
    print(f"fitted {n} Prony arms (tau {min(taus):.3g} .. {max(taus):.3g} s) and "
          f"G_inf = {fitted.G_inf:.4g} Pa to the {what}" if n else
          f"fitted G_inf = {fitted.G_inf:.4g} Pa (no arm) to the {what}")
    print(f"RMS relative residual {residual:.3g}")
    print(f"wrote {a.out}")
    return 0


def _named(data: str, fit, *args, **kwargs):
    """``fit(*args)`` with errors that name the data file and the option."""
    try:
        return fit(*args, **kwargs)
    except ValueError as exc:
        text = str(exc).replace("per_decade =", "--per-decade =")
        raise ValueError(text if text.startswith("--per-decade") else f"{data}: {text}") \
            from None


def run_show(a: argparse.Namespace) -> int:
    """Run ``vimpact material show`` and return the exit code."""
    from vimpact.model.material_file import load_material

    mat = load_material(a.file)
    lines = []
    if a.temperature is not None:
        try:
            shifted = mat.at_temperature(a.temperature)
        except ValueError as exc:
            raise ValueError(str(exc).replace("temperature (K) =", "--temperature =", 1)) \
                from None
        shift = mat.shift
        assert shift is not None  # at_temperature refused a material without a shift law
        a_T = shift.shift_factor(a.temperature)
        lines.append(f"at {a.temperature:g} K: shift factor a_T = {a_T:.4g} "
                     f"(log10 a_T = {shift.log10_shift(a.temperature):.4g})")
        mat = shifted
    lines.append(f"{mat.model}, nu = {mat.nu:g}")
    lines.append(f"  G_inf    {mat.G_inf:.4g} Pa (relaxed)")
    lines.append(f"  G_glassy {mat.glassy_modulus:.4g} Pa (instantaneous)")
    if mat.arms:
        taus = [tau for _, tau in mat.arms]
        lines.append(f"  arms     {len(mat.arms)}, tau {min(taus):.4g} .. {max(taus):.4g} s")
    if mat.eta0:
        lines.append(f"  eta0     {mat.eta0:.4g} Pa s")
    if mat.shift is not None:
        lines.append(f"  shift    {mat.shift.describe()}")
    print("\n".join(lines))
    return 0
