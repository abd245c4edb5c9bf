"""One impact written as a TOML file (``vimpact simulate --scene FILE``).

A scene file is a sweep specification's fixed part: the same top-level keys
where they make sense for one impact, a ``[numerics]`` table exactly like a
sweep's, and a ``[scene]`` table that is a sweep's ``[random]`` table with one
number per key (and no ``rows``). Example (a standard solid, oblique impact
with backspin)::

    description = "plastic ball on a rubber floor"
    model = "standard_solid"        # elastic | kelvin_voigt | standard_solid | prony
    tangential = "auto"             # auto | stick | none   (default auto)
    rotation = true                 # the sphere may spin   (default true)
    tangential_memory = "incremental"  # or "seed"          (default incremental)
    allow_large_contact = false     # accept a contact above 0.2 R (default false)

    [numerics]                      # optional; absent: the caller's default
    preset = "default"              # default | fast | thesis, then overrides:
    steps = 2000                    # any field of vimpact.Numerics

    [scene]
    G1_Pa = 1e7                     # material keys of the model, see below
    G2_Pa = 3e7
    eta_Pa_s = 600.0
    nu = 0.49
    R_m = 0.01                      # sphere radius, m
    m_kg = 0.004                    # sphere mass, kg
    v_z0_m_s = 1.0                  # normal impact speed, m/s (> 0)
    v_x0_m_s = 0.8                  # tangential speed of the centre, m/s (default 0)
    omega0_rad_s = -40.0            # spin about y, rad/s (default 0)
    theta_ratio = 0.4               # Theta / (m R^2) (default 0.4, a solid sphere)
    mu = 0.3                        # Coulomb friction coefficient (default inf: full stick)
    # adhesion_J_m2 = 0.05          # work of adhesion (default 0; normal impacts only)

Top-level keys: ``model`` (required), ``description``, ``tangential_memory``,
``tangential``, ``rotation``, ``allow_large_contact``, ``numerics`` (a table,
or a preset name as a string) and ``scene`` (required).

``[scene]`` keys, named as a sweep's ``[random]`` keys and its table columns:

- all models: ``nu``, ``R_m``, ``m_kg``, ``v_z0_m_s`` (required),
  ``v_x0_m_s`` (default 0), ``omega0_rad_s`` (default 0), ``theta_ratio``
  (default 0.4)
- adhesion, all models: ``adhesion_J_m2`` (work of adhesion, J/m^2, >= 0, default
  0; a scene file only, docs/physics.md#adhesion; the impact must be normal)
- friction, all models: ``mu`` (Coulomb friction coefficient, static =
  kinetic, a number >= 0; ``inf`` (TOML) or ``"inf"`` is full stick, the
  default) and ``angle_deg`` (impact angle from the normal, degrees, in
  [0, 90): ``v_x0 = v_z0 tan(angle)``; an alternative to ``v_x0_m_s``, giving
  both is an error)
- elastic: ``E_Pa`` or ``G_Pa``; kelvin_voigt: ``E_Pa`` or ``G_Pa``, and
  ``eta_Pa_s``; standard_solid: ``G1_Pa``, ``G2_Pa``, ``eta_Pa_s``;
  prony: ``G_Pa`` (relaxed modulus), ``eta_Pa_s`` (parallel dashpot,
  default 0) and one ``[[scene.arms]]`` table per Maxwell arm with ``G_Pa``
  and ``tau_s`` (or ``arms = [{G_Pa = ..., tau_s = ...}, ...]``)

Instead of the material keys and ``nu``, ``[scene]`` may name a material file
(:mod:`vimpact.model.material_file`, e.g. written by ``vimpact material fit``):
``material = "rubber.toml"`` (relative to the scene file's directory) and,
optionally, ``temperature_K`` (the temperature in kelvin to which the file's
shift law moves its relaxation times; docs/howto/dma.md). ``model`` may then
be left out (it is the file's).

Every value is one number: a range or a choice (which a sweep's ``[random]``
takes) is an error. Unknown keys, missing keys and bad values are
``ValueError`` naming the file and the key, on one line. The key rules and the
construction of the scene (:func:`vimpact.model.toml_input.scene_from_values`)
are those of a sweep specification (:mod:`vimpact.model.toml_input`), so a
scene file and a sweep whose ``[random]`` values are all fixed give the same
:class:`~vimpact.Scene` (except ``allow_large_contact``, which a sweep always
sets).

Python API::

    from vimpact.model.scene_file import load_scene, scene_from_toml
    scene, numerics = load_scene("sweeps/scenes/rubber_ball.toml")
    # numerics is None when the file has no [numerics]
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from vimpact.model.material_file import inline_material
from vimpact.model.numerics import Numerics
from vimpact.model.scene import ScaleError, Scene
from vimpact.model.toml_input import (
    ARM_KEYS,
    PHYSICAL_DEFAULTS,
    SWEEP_TOP_KEYS,
    TomlSource,
    friction_coefficient,
    impact_angle,
    input_keys,
    parse_header,
    parse_numerics,
    parse_toml,
    read_toml,
    required_keys,
    scene_from_values,
)

#: ``[scene]`` key of the work of adhesion, J/m^2 (default 0; docs/physics.md#adhesion).
ADHESION_KEY = "adhesion_J_m2"

#: Top-level keys of a scene file.
TOP_KEYS = ("model", "description", "tangential_memory", "tangential", "rotation",
            "allow_large_contact", "numerics", "scene")

#: Defaults of the ``[scene]`` table (those of a sweep's ``[random]``).
DEFAULTS = {**PHYSICAL_DEFAULTS, "eta_Pa_s": 0.0}  # eta_Pa_s: prony only (optional there)

_ONE_NUMBER = ("one number (a scene is one impact: ranges and choices belong in a "
               "sweep's [random] table)")

# What each value must be (besides a finite number); Scene and Material check
# the same again, these only make the message name the file's key.
_POSITIVE = (lambda x: x > 0.0, "a finite number > 0")
_NON_NEGATIVE = (lambda x: x >= 0.0, "a finite number >= 0")
_CHECKS = {
    "nu": (lambda x: 0.0 <= x <= 0.5, "in [0, 0.5]"),
    "E_Pa": _POSITIVE, "G_Pa": _POSITIVE, "G1_Pa": _POSITIVE, "G2_Pa": _POSITIVE,
    "eta_Pa_s": _NON_NEGATIVE, "tau_s": _POSITIVE,
    "R_m": _POSITIVE, "m_kg": _POSITIVE, "v_z0_m_s": _POSITIVE, "theta_ratio": _POSITIVE,
    "adhesion_J_m2": _NON_NEGATIVE,
}


def allowed_scene_keys(model: str) -> tuple[str, ...]:
    """Return the keys the ``[scene]`` table may have for ``model``.

    Keys of the ``[scene]`` table for ``model`` (those of a sweep's ``[random]``
    without ``rows``).
    """
    return input_keys(model) + (("arms",) if model == "prony" else ())


def required_scene_keys(model: str) -> tuple[str, ...]:
    """Return the keys the ``[scene]`` table must have for ``model``.

    Keys that ``[scene]`` must have (besides one of ``E_Pa`` / ``G_Pa`` for
    elastic and Kelvin-Voigt).
    """
    return required_keys(model)


def load_scene(path) -> tuple[Scene, Numerics | None]:
    """Read a scene file (TOML, format: module docstring).

    Returns the scene and its numerics (``None`` when the file has no
    ``[numerics]``: the caller's default applies). Raises ``ValueError``
    naming the file (and the key) for a missing file, bad TOML, unknown or
    missing keys and bad values.
    """
    path = Path(path)
    text, data = read_toml(path, "scene file")
    return _scene(TomlSource(path), text, data, path.parent)


def scene_from_toml(text: str, source="<string>") -> tuple[Scene, Numerics | None]:
    """:func:`load_scene` of the TOML ``text``; ``source`` names it in error messages."""
    spec = TomlSource(source)
    return _scene(spec, text, parse_toml(spec, text))


def _scene(spec: TomlSource, text: str, data: dict,
           base: Path | None = None) -> tuple[Scene, Numerics | None]:
    source = spec.path
    _top_keys(spec, data)
    # [scene] material = "FILE.toml" (and temperature_K): the file's values, written out
    data, _ = inline_material(str(source), data, "scene", base)
    header = parse_header(spec, data)
    allow_large = spec.flag(data, "allow_large_contact", False)
    numerics = parse_numerics(spec, data["numerics"]) if "numerics" in data else None

    if "scene" not in data:
        raise spec.error("scene", "missing: a [scene] table with the physical values ("
                         + ", ".join(allowed_scene_keys(header.model)) + ")")
    table = data["scene"]
    adhesion = 0.0  # a scene-file key only (docs/physics.md#adhesion; sweeps have no adhesion)
    if isinstance(table, dict) and ADHESION_KEY in table:
        table = dict(table)
        adhesion = _number(spec, f"scene.{ADHESION_KEY}", table.pop(ADHESION_KEY), ADHESION_KEY)
    values, arms = _scene_table(spec, header.model, table)

    # The same key names, defaults and construction as a sweep row
    # (vimpact.model.toml_input), so the two formats cannot drift apart.
    try:
        scene = scene_from_values(header.model, values, arms,
                                  tangential_memory=header.tangential_memory,
                                  tangential=header.tangential, rotation=header.rotation,
                                  allow_large_contact=allow_large)
        if adhesion:
            scene = dataclasses.replace(scene, adhesion=adhesion)
    except ScaleError as exc:  # name the keys of this file that set the scales
        keys = [k for name in exc.names for k in _SCALE_KEYS.get(name, (name,))
                if k in values or name not in _SCALE_KEYS]
        raise ValueError(f"{source}: scene: {exc} (keys here: {', '.join(keys)})") from None
    except ValueError as exc:
        raise ValueError(f"{source}: scene: {exc}") from None
    return scene, numerics


#: Scene attributes that set the Hertz scales (ScaleError.names) -> the [scene] keys giving them.
_SCALE_KEYS = {"G_inf": ("E_Pa", "G_Pa", "G1_Pa"), "R": ("R_m",), "m": ("m_kg",),
               "v_z0": ("v_z0_m_s",), "v_x0": ("v_x0_m_s", "angle_deg"),
               "omega0": ("omega0_rad_s",), "Theta": ("theta_ratio",), "eta0": ("eta_Pa_s",)}


def _top_keys(spec: TomlSource, data: dict) -> None:
    for key in data:
        if key in TOP_KEYS:
            continue
        if key == "random":
            raise spec.error("random", "a scene file takes its values in [scene]: a sweep's "
                             "[random] table with one number per key and without 'rows'")
        if key in SWEEP_TOP_KEYS:
            raise spec.error(key, "a sweep key, not a scene key (allowed: "
                             + ", ".join(TOP_KEYS) + ")")
        spec.unknown({key: None}, TOP_KEYS)


def _number(spec: TomlSource, key: str, value, name: str) -> float:
    if isinstance(value, (list, dict)):
        raise spec.bad(key, value, _ONE_NUMBER)
    if name == "mu":
        return friction_coefficient(spec, key, value)
    if name == "angle_deg":
        return impact_angle(spec, key, value)
    check, allowed = _CHECKS.get(name, (None, "a finite number"))
    return spec.number(key, value, check, allowed)


def _scene_table(spec: TomlSource, model: str, table) -> tuple[dict, tuple]:
    """Return the ``[scene]`` values (key -> number) and the arms ``((G_Pa, tau_s), ...)``."""
    if not isinstance(table, dict):
        raise spec.bad("scene", table, "a table [scene]")
    spec.unknown(table, allowed_scene_keys(model), "scene")
    missing = [f"scene.{k}" for k in required_scene_keys(model) if k not in table]
    if missing:
        raise spec.error(", ".join(missing), "missing (required for model "
                         f"{model!r}: {', '.join(required_scene_keys(model))})")
    if model in ("elastic", "kelvin_voigt") and ("E_Pa" in table) == ("G_Pa" in table):
        raise spec.error("scene.E_Pa/G_Pa", "give exactly one of E_Pa or G_Pa")
    if "angle_deg" in table and "v_x0_m_s" in table:
        raise spec.error("scene.angle_deg/v_x0_m_s", "give at most one of angle_deg (impact "
                         "angle from the normal, degrees) or v_x0_m_s (tangential speed, m/s)")
    draws = {}
    for key in input_keys(model):
        if key in table:
            value = _number(spec, f"scene.{key}", table[key], key)
        elif key == "v_x0_m_s" and "angle_deg" in table:
            continue  # v_x0 = v_z0 tan(angle)
        elif key in DEFAULTS:
            value = DEFAULTS[key]
        else:  # the other of E_Pa / G_Pa
            continue
        draws[key] = value
    arms = []
    if model == "prony":
        listed = table.get("arms", [])
        if not isinstance(listed, list) or not all(isinstance(a, dict) for a in listed):
            raise spec.bad("scene.arms", listed, "a list of tables [[scene.arms]]")
        for i, arm in enumerate(listed, start=1):
            where = f"scene.arms[{i}]"
            spec.unknown(arm, ARM_KEYS, where)
            absent = [f"{where}.{k}" for k in ARM_KEYS if k not in arm]
            if absent:
                raise spec.error(", ".join(absent), "missing")
            arms.append(tuple(_number(spec, f"{where}.{k}", arm[k], k) for k in ARM_KEYS))
    return draws, tuple(arms)


__all__ = ["DEFAULTS", "TOP_KEYS", "allowed_scene_keys", "load_scene", "required_scene_keys",
           "scene_from_toml"]
