"""``vimpact simulate``: one impact from physical or dimensionless input, or a scene file."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
from pathlib import Path
from typing import Any

from vimpact import __version__
from vimpact.cli.material_args import add_material_arguments, as_flags, material_from_args, missing
from vimpact.engine.result import STATUSES, UNITS
from vimpact.model.material import MODELS
from vimpact.model.numerics import INTEGRATORS, PRESETS, Numerics, preset_summary
from vimpact.model.scene import (
    DEFAULT_THETA_RATIO,
    TANGENTIAL_EFFECTS,
    TANGENTIAL_MEMORY,
    ScaleError,
    Scene,
)
from vimpact.model.validation import InputError, positive


def add_parser(sub) -> argparse.ArgumentParser:
    """Register ``vimpact simulate`` on ``sub`` (the object of ``add_subparsers``)."""
    sim = sub.add_parser(
        "simulate", help="simulate one impact",
        description=(
            "Simulate one impact. Give either a physical scene (material, sphere, "
            "velocities) or a dimensionless one (--Q1 [--Q2] --nu). The model is "
            "inferred from the material options unless --model is given: --eta alone "
            "-> kelvin_voigt, --G1 --G2 --eta -> standard_solid, --prony -> prony, "
            "neither -> elastic. Or read the whole scene from a TOML file (--scene)."),
        epilog="Examples: vimpact simulate --Q1 0.1 --nu 0.5 --json; "
               "vimpact simulate --scene sweeps/scenes/rubber_ball.toml --explain")
    sim.add_argument("--scene", metavar="FILE",
                     help="read the scene (and optionally [numerics]) from a TOML file, the "
                          "format of a sweep's fixed part; other scene options are then refused")
    g = sim.add_argument_group("material (physical input)")
    g.add_argument("--model", choices=MODELS, help="rheology (default: inferred)")
    add_material_arguments(g, prony=True)
    g.add_argument("--material", metavar="FILE",
                   help="read the material from a material file (TOML, e.g. written by "
                        "vimpact material fit) instead of the options above")
    g.add_argument("--temperature", type=float, metavar="K",
                   help="temperature, kelvin (> 0): the relaxation times of --material are "
                        "shifted by its shift law's a_T (a scene file: temperature_K)")
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
    g.add_argument("--theta-ratio", type=float, default=None, metavar="RATIO",
                   help=f"Theta / (m R^2), dimensionless (default {DEFAULT_THETA_RATIO}, solid sphere; "
                        "instead of --Theta)")
    g = sim.add_argument_group("effects")
    g.add_argument("--tangential", choices=TANGENTIAL_EFFECTS, default=None,
                   help="tangential problem: auto (default: full stick when v_c0 != 0), "
                        "stick, or none (normal impact only; e_x not computed)")
    g.add_argument("--no-rotation", action="store_true",
                   help="the sphere does not spin (Theta -> infinity)")
    g.add_argument("--mu", type=float, default=None, metavar="MU",
                   help="Coulomb friction coefficient, dimensionless, >= 0 (default: inf, "
                        "full stick)")
    g.add_argument("--adhesion", type=float, default=None, metavar="J_M2",
                   help="work of adhesion, J/m^2, >= 0 (default 0: none); the adhesive impact "
                        "is normal only (--tangential none or no tangential speed)")
    g.add_argument("--sticking-velocity", action="store_true",
                   help="also find the impact speed below which the sphere sticks (bisection "
                        "on --vz0 to 1e-3 relative; needs --adhesion)")
    g.add_argument("--tangential-memory", choices=TANGENTIAL_MEMORY, default=None,
                   help="tangential element rule: incremental (default, passive) or seed "
                        "(thesis eq. 4.16, total displacement)")
    g = sim.add_argument_group("numerics")
    g.add_argument("--numerics", choices=tuple(PRESETS), default=None,
                   help="numerics preset: " + ", ".join(preset_summary(p) for p in PRESETS))
    g.add_argument("--tolerance", type=float, metavar="TOL",
                   help="numerics for this absolute accuracy on e_z and beta_x on the path "
                        "that runs (instead of a preset; between 1e-9 and 1e-2); refused where "
                        "the element path cannot reach it")
    g.add_argument("--integrator", choices=tuple(INTEGRATORS), help="override the integrator")
    g.add_argument("--steps", type=_count, help="override: time steps per Hertz contact time")
    g.add_argument("--elements", type=_count, help="override: elements per Hertz contact radius")
    g.add_argument("--rtol", type=float, help="override: tolerance of the continuum path")
    g.add_argument("--no-continuum", action="store_true",
                   help="always use the element kernel (no Kelvin-Voigt continuum path)")
    g.add_argument("--explain", action="store_true",
                   help="say which kernel runs and why, then simulate")
    g = sim.add_argument_group("output")
    g.add_argument("--allow-large-contact", action="store_true",
                   help="accept a contact half-width above 0.2 R (outside the half-space model)")
    g.add_argument("--trajectory", metavar="FILE",
                   help="write the time series (t, u_z, v_z, v_x, omega, F_z, F_x, a, slip width) to "
                        "FILE, CSV or Parquet by extension (.csv, .parquet)")
    g.add_argument("--json", action="store_true", help="print one JSON object")
    sim.set_defaults(func=run)
    return sim


def _count(text: str) -> int:
    """Read an integer option.

    Return an integer option; an integral float such as ``1e3`` is read as that integer (its
    range is checked by :class:`Numerics`, with a message that names the option).
    """
    try:
        return int(text)
    except ValueError:
        pass
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value.is_integer():  # NaN, inf, 2.5, words: argparse names the option
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: must be an integer")
    return int(value)


_PHYSICAL = ("E", "G", "eta", "G1", "G2", "prony", "R", "m", "Theta", "vz0", "model")
_EFFECTS = {"tangential": "auto", "tangential_memory": "incremental"}
#: Scene and Material parameter names -> the flag a user typed
_FLAGS = {"v_z0": "--vz0", "v_x0": "--vx0", "omega0": "--omega0", "theta_ratio": "--theta-ratio",
          "tangential_memory": "--tangential-memory", "G_inf": "--G", "eta0": "--eta",
          "R": "--R", "m": "--m", "Theta": "--Theta", "mu": "--mu", "nu": "--nu", "Q1": "--Q1",
          "Q2": "--Q2", "E": "--E", "G": "--G", "eta": "--eta", "G1": "--G1", "G2": "--G2",
          "steps": "--steps", "elements": "--elements", "rtol": "--rtol",
          "tolerance": "--tolerance", "integrator": "--integrator", "adhesion": "--adhesion",
          "rtol_sticking": "--sticking-velocity"}
#: Options that set a scene's Hertz scales (named when those leave the float range).
_SCALE_OPTIONS = ("E", "G", "G1", "G2", "eta", "prony", "R", "m", "Theta", "vz0", "theta_ratio")


def _as_flags(exc: ValueError) -> InputError:
    """Return the error of a Scene/Material/Numerics parameter, named by its command-line flag."""
    return InputError(str(as_flags(exc, _FLAGS)))


def scene_from_args(a) -> Scene:
    """Return the scene described by parsed ``simulate`` options (errors name the flags)."""
    try:
        return _scene_from_args(a)
    except ScaleError as exc:  # no one input is at fault: name the options that set the scales
        typed = [f"--{n.replace('_', '-')} = {getattr(a, n)}" for n in _SCALE_OPTIONS
                 if getattr(a, n, None) is not None]
        typed += [f"--{n} = {getattr(a, n)}" for n in ("vx0", "omega0") if getattr(a, n) != 0.0]
        if a.Q1 is not None or not typed:
            raise _as_flags(exc) from None
        reason = str(exc).split(" is not allowed: ", 1)[-1]
        raise InputError(f"the scene {', '.join(typed)} is not allowed: {reason}") from None
    except InputError as exc:
        raise _as_flags(exc) from None


def _scene_from_args(a) -> Scene:
    effects: dict[str, Any] = {k: getattr(a, k) if getattr(a, k) is not None else default
               for k, default in _EFFECTS.items()}
    effects["rotation"] = not a.no_rotation
    if a.mu is not None:
        effects["mu"] = a.mu
    if a.Theta is not None and a.theta_ratio is not None:
        raise InputError(f"--Theta = {a.Theta:g} cannot be combined with --theta-ratio = "
                         f"{a.theta_ratio:g}: give one of them")
    ratio = a.theta_ratio if a.theta_ratio is not None else DEFAULT_THETA_RATIO
    if a.Q1 is not None:
        given = [f"--{n}" for n in _PHYSICAL + ("material", "temperature")
                 if getattr(a, n) is not None]
        given += [f"--{n}" for n in ("vx0", "omega0") if getattr(a, n) != 0.0]
        if given:
            raise ValueError(f"{', '.join(given)} cannot be combined with --Q1: give either "
                             "a dimensionless scene (--Q1 [--Q2] --nu) or a physical one")
        if a.nu is None:
            raise missing("nu", "the Poisson ratio in [0, 0.5] is required")
        if a.Theta is not None:
            raise InputError("--Theta cannot be combined with --Q1: the dimensionless scene "
                             "takes --theta-ratio")
        scene = Scene.from_dimensionless(a.Q1, a.nu, a.Q2, theta_ratio=ratio, **effects)
        if a.adhesion is not None:
            scene = dataclasses.replace(scene, adhesion=a.adhesion)
        return scene
    if a.Q2 is not None:
        raise missing("Q1", "--Q2 is part of the dimensionless input --Q1 --Q2 --nu")
    if a.temperature is not None and a.material is None:
        raise ValueError(f"--temperature = {a.temperature:g} needs --material FILE: a material "
                         "file with a temperature shift law (vimpact material fit)")
    material = _material_file(a) if a.material is not None else material_from_args(a)
    for name, what in (("R", "sphere radius, m"), ("m", "sphere mass, kg"),
                       ("vz0", "normal impact speed, m/s")):
        if getattr(a, name) is None:
            raise missing(name, f"the {what} is required (or use --Q1 --nu)")
    theta = a.Theta
    if theta is None and a.theta_ratio is not None:
        theta = positive("theta_ratio", a.theta_ratio) * a.m * a.R**2
    if a.adhesion is not None:
        effects["adhesion"] = a.adhesion
    return Scene(material, R=a.R, m=a.m, v_z0=a.vz0, v_x0=a.vx0, omega0=a.omega0, Theta=theta,
                 allow_large_contact=a.allow_large_contact, **effects)


def _material_file(a):
    """Return the material of ``--material FILE`` (at ``--temperature``).

    Material options beside it are refused.
    """
    from vimpact.model.material_file import load_material  # TOML reading: only when asked

    given = [f"--{n}" for n in ("model", "E", "G", "eta", "G1", "G2", "prony", "nu")
             if getattr(a, n) is not None]
    if given:
        raise ValueError(f"{', '.join(given)} cannot be combined with --material: the file "
                         "describes the whole material")
    return _at_temperature(load_material(a.material), a.temperature)


def _at_temperature(material, T):
    """``material`` at ``--temperature`` (unchanged without the option)."""
    if T is None:
        return material
    try:
        return material.at_temperature(T)
    except InputError as exc:
        raise InputError(str(exc).replace("temperature (K) =", "--temperature =", 1)) from None


def _scene_file(a) -> tuple[Scene, Numerics | None]:
    """Scene and numerics of ``--scene FILE``; scene options beside it are refused."""
    from vimpact.model.scene_file import load_scene  # TOML reading: only when asked

    given = [f"--{n.replace('_', '-')}" for n in _PHYSICAL + ("Q1", "Q2", "nu", "material")
             + tuple(_EFFECTS) if getattr(a, n) is not None]
    given += [f"--{n.replace('_', '-')}" for n, default in
              (("vx0", 0.0), ("omega0", 0.0), ("theta_ratio", None), ("mu", None),
               ("adhesion", None),
               ("no_rotation", False))
              if getattr(a, n) != default]
    if given:
        raise ValueError(f"{', '.join(given)} cannot be combined with --scene: the file "
                         "describes the whole scene")
    if a.temperature is not None:
        raise ValueError(f"--temperature = {a.temperature:g} cannot be combined with --scene: "
                         "give temperature_K (kelvin) in the scene file's [scene] table, "
                         "beside its material file")
    scene, numerics = load_scene(a.scene)
    if a.allow_large_contact:
        scene = dataclasses.replace(scene, allow_large_contact=True)
    return scene, numerics


def _numerics(a, base: Numerics | None = None) -> Numerics:
    """Return the numerics of the options: a preset, a tolerance or the file's, then overrides."""
    if a.tolerance is not None and a.numerics is not None:
        raise ValueError(f"--tolerance = {a.tolerance:g} cannot be combined with "
                         f"--numerics = {a.numerics}: give one of them")
    if a.tolerance is not None:
        numerics = Numerics.for_tolerance(a.tolerance)
    elif a.numerics is not None or base is None:
        numerics = Numerics.preset(a.numerics or "default")
    else:
        numerics = base
    changes = {k: getattr(a, k) for k in ("integrator", "steps", "elements", "rtol")
               if getattr(a, k) is not None}
    if a.no_continuum:
        changes["continuum"] = False
    return numerics.with_(**changes)


def numerics_from_args(a, base: Numerics | None = None) -> Numerics:
    """:func:`_numerics` with errors that name the options (``--steps``, ``--rtol``, ...)."""
    try:
        return _numerics(a, base)
    except InputError as exc:
        raise _as_flags(exc) from None


def _check_output(flag: str, path: str, suffixes: tuple[str, ...]) -> Path:
    """Refuse an output path before any work.

    Wrong extension, a directory, a missing or unwritable folder.
    """
    from vimpact.tableformat.files import refuse_symlink  # the one rule for files vimpact writes

    out = Path(path)
    if out.suffix.lower() not in suffixes:
        raise InputError(f"{flag} = {path!r} is not allowed: must end in {' or '.join(suffixes)}")
    refuse_symlink(out, flag)
    if out.is_dir():
        raise InputError(f"{flag} = {path!r} is not allowed: it is a directory")
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"{flag} = {path!r} is not allowed: the folder {str(folder)!r} "
                         "does not exist")
    if not os.access(folder, os.W_OK) or (out.exists() and not os.access(out, os.W_OK)):
        raise InputError(f"{flag} = {path!r} is not allowed: not writable")
    return out


def run(a) -> int:
    """Run ``vimpact simulate`` and return the exit code."""
    if a.trajectory:
        _check_output("--trajectory", a.trajectory, (".csv", ".parquet"))
    if a.scene is not None:
        scene, file_numerics = _scene_file(a)
    else:
        scene, file_numerics = scene_from_args(a), None
    numerics = numerics_from_args(a, file_numerics)
    # the engine loads numba and pandas (about 2.5 s): only once the inputs are valid
    from vimpact.engine.routing import choose_path
    from vimpact.engine.simulate import simulate

    if a.sticking_velocity and scene.adhesion <= 0.0:
        raise InputError("--sticking-velocity needs a work of adhesion > 0 (--adhesion J_M2, "
                         "or adhesion_J_m2 in the scene file): without adhesion the sphere "
                         "never sticks")
    path = choose_path(scene, numerics)
    if a.explain and not a.json:
        print(path.explain())
    try:
        res = simulate(scene, numerics, trajectory=bool(a.trajectory))
    except InputError as exc:  # half-space exceeded, tolerance unreachable
        raise _as_flags(exc) from None
    if a.trajectory:
        from vimpact.tableformat.files import atomic_file

        out = Path(a.trajectory)
        csv = out.suffix.lower() == ".csv"
        trajectory = res.trajectory
        assert trajectory is not None  # simulate(..., trajectory=True) recorded it
        with atomic_file(out, "--trajectory", mode="w" if csv else "wb") as f:
            if csv:
                trajectory.to_csv(f, index=False)
            else:
                trajectory.to_parquet(f, index=False)
    extra = _adhesion_outputs(scene, numerics, a.sticking_velocity)
    if a.json:
        d = res.to_json_dict()
        if a.explain:
            d["explain"] = list(path.reasons)
        if extra:
            d["adhesion"] = extra
        print(json.dumps(d))
    else:
        print(_summary(scene, res))
        for key, value in extra.items():
            print(f"  {key:<21} {value:.6g}" if isinstance(value, float) else
                  f"  {key:<21} {value}")
    return 0


def _adhesion_outputs(scene: Scene, numerics: Numerics, sticking: bool) -> dict:
    """Return the adhesive impact's own outputs (empty without adhesion), SI units in names."""
    if scene.adhesion <= 0.0:
        return {}
    from vimpact.engine.adhesion import STICKING_RTOL, simulate_adhesive, sticking_velocity

    adh = simulate_adhesive(scene, numerics)
    out: dict = {"adhesion_J_m2": scene.adhesion, "stuck": adh.stuck,
                 "F_tensile_max_N": adh.F_tensile_max, "u_min_m": adh.u_min,
                 "adhesion_number": adh.adhesion_number}
    if sticking:
        try:
            out["sticking_velocity_m_s"] = sticking_velocity(scene, numerics)
        except InputError as exc:
            raise InputError(f"--sticking-velocity: {exc}") from None
        out["sticking_velocity_rtol"] = STICKING_RTOL
    return out


def _summary(scene: Scene, res) -> str:
    mat = scene.material
    lines = [f"vimpact {__version__}: {mat.model} half-space, nu = {mat.nu:g}, "
             f"tangential memory {scene.tangential_memory}"]
    for key in ("e_z", "beta_x", "e_x", "mu_eff", "energy_ratio", "Q1", "Q2", "t_contact",
                "t_hertz", "u_max", "d_hertz", "a_max", "a_hertz", "v_z_end", "v_x_end",
                "omega_end", "rebound_angle", "gross_slip_fraction", "friction_energy"):
        value = getattr(res, key)
        unit = UNITS[key] if UNITS[key] != "1" else ""
        text = "undefined" if math.isnan(value) else f"{value:.6g}"
        lines.append(f"  {key:<13} {text:>12} {unit}")
    lines.append(f"  status        {res.status}: {STATUSES[res.status]}")
    lines.append(f"  path          {res.path} ({res.n_steps} steps)")
    if res.error:
        lines.append(f"  reason        {res.error}")
    if scene.computes_tangential and mat.nu != 0.5:
        lines.append("  note          the tangential MDR mapping is exact only at nu = 0.5 for a "
                     "rigid sphere; at this nu beta_x is the thesis's approximation")
    return "\n".join(lines)
