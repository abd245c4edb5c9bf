"""Material options shared by the subcommands (``simulate``, ``table export``)."""

from __future__ import annotations

import math
import re

from vimpact.model.material import Material


def add_material_arguments(g, *, prony: bool) -> None:
    """Add ``--E --G --nu --eta --G1 --G2`` (and ``--prony``) to an argparse group."""
    g.add_argument("--E", type=float, metavar="PA", help="Young's modulus, Pa (or --G)")
    g.add_argument("--G", type=float, metavar="PA",
                   help="shear modulus, Pa (relaxed modulus G_inf for --prony)")
    g.add_argument("--nu", type=float, metavar="NU",
                   help="Poisson ratio, dimensionless, in [0, 0.5] (required)")
    g.add_argument("--eta", type=float, metavar="PA_S",
                   help="viscosity, Pa s: Kelvin-Voigt dashpot, the standard solid's "
                        "arm dashpot, or the parallel dashpot of --prony")
    g.add_argument("--G1", type=float, metavar="PA", help="standard solid: parallel spring, Pa")
    g.add_argument("--G2", type=float, metavar="PA", help="standard solid: arm spring, Pa")
    if prony:
        g.add_argument("--prony", action="append", metavar="G_I:TAU_I",
                       help="Prony arm 'modulus Pa:relaxation time s' (repeat for more arms)")


def missing(name: str, why: str) -> ValueError:
    """Return the error for a missing option ``--name``, saying ``why`` it is needed."""
    return ValueError(f"--{name} is missing: {why}")


def material_from_args(a) -> Material:
    """Return the material described by parsed options (model inferred unless ``a.model``)."""
    if a.nu is None:
        raise missing("nu", "the Poisson ratio in [0, 0.5] is required")
    prony = getattr(a, "prony", None)
    model = getattr(a, "model", None) or (
        "prony" if prony else
        "standard_solid" if a.G1 is not None or a.G2 is not None else
        "kelvin_voigt" if a.eta is not None else "elastic")
    if model == "standard_solid":
        for name in ("G1", "G2", "eta"):
            if getattr(a, name) is None:
                raise missing(name, "the standard solid needs --G1, --G2 (Pa) and --eta (Pa s)")
        if a.E is not None or a.G is not None:
            raise ValueError("--E/--G are not used by the standard solid: give --G1 and --G2")
        return Material.standard_solid(nu=a.nu, G1=a.G1, G2=a.G2, eta=a.eta)
    if a.G1 is not None or a.G2 is not None:
        raise ValueError(f"--G1/--G2 belong to the standard solid, not --model {model}")
    if a.E is None and a.G is None:
        raise missing("E", "give the modulus as --E or --G (Pa)")
    if a.E is not None and a.G is not None and model != "prony":
        raise ValueError(f"--E = {a.E:g} cannot be combined with --G = {a.G:g}: give the "
                         "modulus once (Pa)")
    if model == "prony":
        if not prony:
            raise missing("prony", "a Prony series needs at least one --prony G_I:TAU_I")
        if a.G is None:
            raise missing("G", "the Prony series needs its relaxed modulus --G (Pa)")
        arms = []
        for text in prony:
            try:
                G_i, tau_i = (float(x) for x in text.split(":"))
            except ValueError:
                raise ValueError(f"--prony = {text!r} is not allowed: must be "
                                 "'modulus:time' in Pa:s, e.g. 1e6:1e-3") from None
            for value, what in ((G_i, "the modulus (Pa)"), (tau_i, "the relaxation time (s)")):
                if not (math.isfinite(value) and value > 0.0):
                    raise ValueError(f"--prony = {text!r} is not allowed: {what} must be a "
                                     "finite number > 0")
            arms.append((G_i, tau_i))
        return Material.prony(nu=a.nu, G_inf=a.G, arms=arms, eta0=a.eta or 0.0)
    if prony:
        raise ValueError(f"--prony needs --model prony, not --model {model}")
    if model == "kelvin_voigt":
        if a.eta is None:
            raise missing("eta", "the Kelvin-Voigt body needs its viscosity (Pa s)")
        return Material.kelvin_voigt(nu=a.nu, eta=a.eta, G=a.G, E=a.E)
    if a.eta is not None:
        raise ValueError("--eta is not used by --model elastic")
    return Material.elastic(nu=a.nu, G=a.G, E=a.E)


def as_flags(exc: ValueError, flags: dict[str, str]) -> ValueError:
    """Return the error of an API parameter named by its command-line flag.

    Every ``name = `` (or ``name missing``) of ``flags`` (parameter -> flag) at the
    message's start or after ``(``, ``, `` or ``; `` becomes ``flag = `` (``flag is
    missing``); the value stays as it is.
    """
    named = re.compile(r"(^|\(|, |; )(" + "|".join(sorted(map(re.escape, flags), key=len,
                                                           reverse=True))
                       + r")( = | is missing| missing)")
    return type(exc)(named.sub(lambda m: f"{m[1]}{flags[m[2]]}"
                               + (" is missing" if "missing" in m[3] else m[3]), str(exc))) \
        if isinstance(exc, ValueError) else exc
