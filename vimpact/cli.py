"""The ``vimpact`` command line.

Bad input gives one line on stderr naming the parameter and what is allowed,
and exit code 2; never a traceback.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from . import __version__
from ._cli_material import add_material_arguments, material_from_args, missing
from .material import MODELS
from .numerics import INTEGRATORS, PRESETS, Numerics
from .result import STATUSES, UNITS
from .scene import TANGENTIAL_MEMORY, Scene
from .simulate import simulate
from .sweep_cli import add_sweep_parser
from .table_cli import add_plot_parser, add_table_parser


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit code 2
        self.exit(2, f"{self.prog}: error: {message}\n")


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="vimpact", description=(
        "Coefficients of restitution of a rigid sphere hitting a viscoelastic "
        "half-space (method of dimensionality reduction)."))
    parser.add_argument("--version", action="version", version=f"vimpact {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    sim = sub.add_parser(
        "simulate", help="simulate one impact",
        description=(
            "Simulate one impact. Give either a physical scene (material, sphere, "
            "velocities) or a dimensionless one (--Q1 [--Q2] --nu). The model is "
            "inferred from the material options unless --model is given: --eta alone "
            "-> kelvin_voigt, --G1 --G2 --eta -> standard_solid, --prony -> prony, "
            "neither -> elastic."),
        epilog="Example: vimpact simulate --Q1 0.1 --nu 0.5 --json")
    g = sim.add_argument_group("material (physical input)")
    g.add_argument("--model", choices=MODELS, help="rheology (default: inferred)")
    add_material_arguments(g, prony=True)
    g = sim.add_argument_group("sphere and impact (physical input)")
    g.add_argument("--R", type=float, metavar="M", help="sphere radius, m")
    g.add_argument("--m", type=float, metavar="KG", help="sphere mass, kg")
    g.add_argument("--Theta", type=float, metavar="KG_M2",
                   help="moment of inertia, kg m^2 (default 2/5 m R^2)")
    g.add_argument("--vz0", type=float, metavar="M_S", help="normal impact speed, m/s (> 0)")
    g.add_argument("--vx0", type=float, default=0.0, metavar="M_S",
                   help="tangential speed of the centre, m/s (default 0)")
    g.add_argument("--omega0", type=float, default=0.0, metavar="RAD_S",
                   help="spin about y, rad/s (default 0); contact point moves with vx0 + R omega0")
    g = sim.add_argument_group("dimensionless input (instead of the physical one)")
    g.add_argument("--Q1", type=float, metavar="Q1",
                   help="damping parameter sqrt(15/32) (eta/G_inf)/T, dimensionless, >= 0")
    g.add_argument("--Q2", type=float, metavar="Q2",
                   help="stiffness ratio G1/G2 of the standard solid, dimensionless, > 0 "
                        "(omit for Kelvin-Voigt)")
    g.add_argument("--theta-ratio", type=float, default=0.4, metavar="RATIO",
                   help="Theta / (m R^2), dimensionless (default 0.4, solid sphere)")
    g = sim.add_argument_group("options")
    g.add_argument("--tangential-memory", choices=TANGENTIAL_MEMORY, default="incremental",
                   help="tangential element rule: incremental (default, passive) or seed "
                        "(thesis eq. 4.16, total displacement)")
    g.add_argument("--numerics", choices=tuple(PRESETS), default="default",
                   help="numerics preset (default: about 1e-4 on e_z, e_x)")
    g.add_argument("--integrator", choices=tuple(INTEGRATORS), help="override the integrator")
    g.add_argument("--steps", type=int, help="override: time steps per Hertz contact time")
    g.add_argument("--elements", type=int, help="override: elements per Hertz contact radius")
    g.add_argument("--allow-large-contact", action="store_true",
                   help="accept a contact half-width above 0.2 R (outside the half-space model)")
    g.add_argument("--trajectory", metavar="FILE",
                   help="write the time series (t, u_z, v_z, v_x, omega, F_z, F_x, a) to "
                        "FILE, CSV or Parquet by extension (.csv, .parquet)")
    g.add_argument("--json", action="store_true", help="print one JSON object")
    sim.set_defaults(func=_cmd_simulate)
    add_sweep_parser(sub)
    add_table_parser(sub)
    add_plot_parser(sub)
    return parser


_PHYSICAL = ("E", "G", "eta", "G1", "G2", "prony", "R", "m", "Theta", "vz0", "model")


def scene_from_args(a) -> Scene:
    """The scene described by parsed ``simulate`` options."""
    if a.Q1 is not None:
        given = [f"--{n}" for n in _PHYSICAL if getattr(a, n) is not None]
        given += [f"--{n}" for n in ("vx0", "omega0") if getattr(a, n) != 0.0]
        if given:
            raise ValueError(f"{', '.join(given)} cannot be combined with --Q1: give either "
                             "a dimensionless scene (--Q1 [--Q2] --nu) or a physical one")
        if a.nu is None:
            raise missing("nu", "the Poisson ratio in [0, 0.5] is required")
        return Scene.from_dimensionless(a.Q1, a.nu, a.Q2, theta_ratio=a.theta_ratio,
                                        tangential_memory=a.tangential_memory)
    if a.Q2 is not None:
        raise missing("Q1", "--Q2 is part of the dimensionless input --Q1 --Q2 --nu")
    material = material_from_args(a)
    for name, what in (("R", "sphere radius, m"), ("m", "sphere mass, kg"),
                       ("vz0", "normal impact speed, m/s")):
        if getattr(a, name) is None:
            raise missing(name, f"the {what} is required (or use --Q1 --nu)")
    theta = a.Theta
    if theta is None and a.theta_ratio != 0.4:
        theta = a.theta_ratio * a.m * a.R**2
    return Scene(material, R=a.R, m=a.m, v_z0=a.vz0, v_x0=a.vx0, omega0=a.omega0, Theta=theta,
                 tangential_memory=a.tangential_memory,
                 allow_large_contact=a.allow_large_contact)


def _numerics(a) -> Numerics:
    changes = {k: getattr(a, k) for k in ("integrator", "steps", "elements")
               if getattr(a, k) is not None}
    return Numerics.preset(a.numerics).with_(**changes)


def _cmd_simulate(a) -> int:
    if a.trajectory and Path(a.trajectory).suffix.lower() not in (".csv", ".parquet"):
        raise ValueError(f"--trajectory = {a.trajectory!r} is not allowed: "
                         "must end in .csv or .parquet")
    scene = scene_from_args(a)
    res = simulate(scene, _numerics(a), trajectory=bool(a.trajectory))
    if a.trajectory:
        path = Path(a.trajectory)
        if path.suffix.lower() == ".csv":
            res.trajectory.to_csv(path, index=False)
        else:
            res.trajectory.to_parquet(path, index=False)
    if a.json:
        print(json.dumps(res.to_json_dict()))
    else:
        print(_summary(scene, res))
    return 0


def _summary(scene: Scene, res) -> str:
    mat = scene.material
    lines = [f"vimpact {__version__}: {mat.model} half-space, nu = {mat.nu:g}, "
             f"tangential memory {scene.tangential_memory}"]
    for key in ("e_z", "e_x", "beta_x", "energy_ratio", "Q1", "Q2", "t_contact", "t_hertz",
                "u_max", "d_hertz", "a_max", "a_hertz", "v_z_end", "v_x_end", "omega_end"):
        value = getattr(res, key)
        unit = UNITS[key] if UNITS[key] != "1" else ""
        text = "undefined" if math.isnan(value) else f"{value:.6g}"
        lines.append(f"  {key:<13} {text:>12} {unit}")
    lines.append(f"  status        {res.status}: {STATUSES[res.status]}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = _build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except ValueError as exc:
        print(f"vimpact {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("vimpact: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
