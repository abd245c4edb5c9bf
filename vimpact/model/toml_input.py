"""TOML input rules shared by sweep specifications and scene files.

One place for what both formats accept, so that the two cannot drift apart:

- :class:`TomlSource`: error messages that name the file and the key (one line,
  ``ValueError``);
- :func:`read_toml`, :func:`parse_toml`: the file's text and content;
- :func:`parse_header`: the top-level keys both share (``model``,
  ``description``, ``tangential_memory``, ``tangential``, ``rotation``);
- :func:`parse_numerics`: a ``[numerics]`` table (or a preset name);
- the physical value keys (:data:`MATERIAL_KEYS`, :data:`SPHERE_KEYS`,
  :data:`PHYSICAL_DEFAULTS`, :data:`ARM_KEYS`), named like the table columns
  with their unit as suffix (``E_Pa``, ``eta_Pa_s``, ``R_m``, ``m_kg``,
  ``v_z0_m_s``, ``v_x0_m_s``, ``omega0_rad_s``, ``theta_ratio``, arms
  ``G_Pa`` and ``tau_s``);
- the friction keys (:data:`FRICTION_KEYS`): ``mu`` (Coulomb friction
  coefficient, >= 0, ``inf`` or ``"inf"`` for full stick, the default) and
  ``angle_deg`` (impact angle from the normal in degrees, in [0, 90): the
  tangential speed ``v_x0 = v_z0 tan(angle)``, an alternative to ``v_x0_m_s``,
  never both), read by :func:`friction_coefficient` and :func:`impact_angle`;
- :func:`scene_from_values`: one :class:`~vimpact.model.scene.Scene` from
  such named values (a scene file; one row of a sweep when it is explained).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path
from typing import NamedTuple

import numpy as np

from vimpact.model.material import MODELS, Material
from vimpact.model.numerics import PRESETS, Numerics
from vimpact.model.scene import DEFAULT_THETA_RATIO, TANGENTIAL_EFFECTS, TANGENTIAL_MEMORY, Scene
from vimpact.model.validation import InputError

#: Material keys per model (Pa, Pa s).
MATERIAL_KEYS = {
    "elastic": ("E_Pa", "G_Pa"),
    "kelvin_voigt": ("E_Pa", "G_Pa", "eta_Pa_s"),
    "standard_solid": ("G1_Pa", "G2_Pa", "eta_Pa_s"),
    "prony": ("G_Pa", "eta_Pa_s"),
}
#: Sphere and initial-velocity keys (m, kg, m/s, m/s, rad/s).
SPHERE_KEYS = ("R_m", "m_kg", "v_z0_m_s", "v_x0_m_s", "omega0_rad_s")
#: Defaults of the optional physical keys (``eta_Pa_s``: optional for Prony only).
PHYSICAL_DEFAULTS = {"v_x0_m_s": 0.0, "omega0_rad_s": 0.0, "theta_ratio": DEFAULT_THETA_RATIO}
#: Optional friction keys (after the physical keys, in this order): Coulomb friction
#: coefficient (1; default inf, full stick) and impact angle from the normal (degrees;
#: an alternative to ``v_x0_m_s``).
FRICTION_KEYS = ("mu", "angle_deg")
#: Allowed impact angles from the normal, degrees: [0, 90).
ANGLE_RANGE_DEG = (0.0, 90.0)
#: Keys of one Maxwell arm of a Prony series (Pa, s).
ARM_KEYS = ("G_Pa", "tau_s")
#: Top-level keys of a sweep specification.
SWEEP_TOP_KEYS = ("model", "description", "seed", "chunk_size", "output", "layout",
                  "tangential_memory", "tangential", "rotation", "numerics", "random", "grid")
#: Keys of a ``[numerics]`` table.
NUMERICS_KEYS = ("preset",) + tuple(f.name for f in dataclasses.fields(Numerics))


def physical_keys(model: str) -> tuple[str, ...]:
    """Physical value keys of ``model`` in their fixed order.

    Material, sphere, ``nu``, ``theta_ratio`` (arms separately).
    """
    return MATERIAL_KEYS[model] + SPHERE_KEYS + ("nu", "theta_ratio")


def required_keys(model: str) -> tuple[str, ...]:
    """Keys that must be given (besides one of ``E_Pa`` / ``G_Pa`` for elastic and Kelvin-Voigt)."""
    if model == "prony":
        return ("G_Pa", "R_m", "m_kg", "v_z0_m_s", "nu")
    return tuple(k for k in MATERIAL_KEYS[model] if k not in ("E_Pa", "G_Pa")) + \
        ("R_m", "m_kg", "v_z0_m_s", "nu")


def input_keys(model: str) -> tuple[str, ...]:
    """Every value key of ``model`` in its fixed order.

    :func:`physical_keys`, then :data:`FRICTION_KEYS` (arms separately).
    """
    return physical_keys(model) + FRICTION_KEYS


def tangential_speed(v_z0, angle_deg):
    """Tangential speed of the centre for an impact angle from the normal.

    ``v_x0 = v_z0 tan(angle)``, m/s (arrays or numbers; the same floating-point operations
    for a scene file and a sweep column).

    Parameters
    ----------
    v_z0 : normal impact speed, m/s
    angle_deg : impact angle measured from the normal, degrees, in [0, 90)
    """
    out = np.asarray(v_z0, dtype=float) * np.tan(np.radians(np.asarray(angle_deg, dtype=float)))
    return float(out) if out.ndim == 0 else out


def friction_coefficient(source: TomlSource, key: str, value) -> float:
    """Return a Coulomb friction coefficient.

    A number >= 0, or ``inf`` (TOML ``inf`` or the string ``"inf"``) for full stick.
    """
    if isinstance(value, str) and value.strip().lower() in ("inf", "+inf", "infinity"):
        return math.inf
    if not is_number(value) or math.isnan(value) or value < 0.0 or value == -math.inf:
        raise source.bad(key, value, 'a number >= 0 or inf (or "inf": full stick)')
    return float(value)


def impact_angle(source: TomlSource, key: str, value) -> float:
    """Return an impact angle from the normal, degrees, in [0, 90)."""
    lo, hi = ANGLE_RANGE_DEG
    return source.number(key, value, lambda x: lo <= x < hi,
                         f"a number of degrees in [{lo:g}, {hi:g}) from the normal")


def is_number(x) -> bool:
    """Return a TOML integer or float (not a bool)."""
    return isinstance(x, (int, float)) and not isinstance(x, bool)


class TomlSource:
    """A TOML input being read: error messages that name the file and the key."""

    def __init__(self, path):
        self.path = path

    def error(self, key: str, message: str) -> ValueError:
        """Return the error for ``key`` of this file, with ``message``."""
        return ValueError(f"{self.path}: {key}: {message}")

    def bad(self, key: str, value, allowed: str) -> ValueError:
        """Return the error for ``key = value``: not allowed, must be ``allowed``."""
        return ValueError(f"{self.path}: {key} = {value!r} is not allowed: must be {allowed}")

    def unknown(self, table: dict, allowed, where: str = "") -> None:
        """Raise for the first key of ``table`` (under ``where``) not in ``allowed``."""
        for key in table:
            if key not in allowed:
                name = f"{where}.{key}" if where else key
                raise ValueError(f"{self.path}: unknown key {name!r} (allowed: "
                                 f"{', '.join(allowed)})")

    def number(self, key: str, value, check=None, allowed="a finite number") -> float:
        """``value`` as a finite float that passes ``check``, else the error naming ``key``."""
        if not is_number(value) or not math.isfinite(value) or (check and not check(value)):
            raise self.bad(key, value, allowed)
        return float(value)

    def integer(self, key: str, value, minimum: int) -> int:
        """``value`` as an integer >= ``minimum`` (not a bool), else the error naming ``key``."""
        if not isinstance(value, int) or isinstance(value, bool) or value < minimum:
            raise self.bad(key, value, f"an integer >= {minimum}")
        return value

    def choice(self, data: dict, key: str, choices, default: str) -> str:
        """``data[key]`` (``default`` if absent), one of ``choices``."""
        value = data.get(key, default)
        if value not in choices:
            raise self.bad(key, value, "one of " + ", ".join(map(repr, choices)))
        return value

    def flag(self, data: dict, key: str, default: bool) -> bool:
        """``data[key]`` (``default`` if absent), a bool."""
        value = data.get(key, default)
        if not isinstance(value, bool):
            raise self.bad(key, value, "true or false")
        return value


def read_text(path: Path, what: str) -> str:
    """Return the UTF-8 text of the file ``path``.

    ``ValueError`` naming the file and ``what`` it should be when it is missing,
    unreadable or not UTF-8 text.
    """
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ValueError(f"{path}: {what} not found") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: cannot read the {what}: not UTF-8 text (byte "
                         f"{exc.object[exc.start:exc.start + 1]!r} at position {exc.start})") \
            from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None


def read_toml(path: Path, what: str) -> tuple[str, dict]:
    """Text and parsed content of the TOML file ``path`` (``what`` names it in errors)."""
    text = read_text(path, what)
    return text, parse_toml(TomlSource(path), text)


def parse_toml(source: TomlSource, text: str) -> dict:
    """Return the content of the TOML ``text``; ``ValueError`` naming ``source`` if it is not TOML."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{source.path}: not valid TOML: {exc}") from None


class Header(NamedTuple):
    """The top-level keys a sweep spec and a scene file share."""

    model: str
    description: str
    tangential_memory: str
    tangential: str
    rotation: bool


def parse_header(source: TomlSource, data: dict) -> Header:
    """``model`` (required), ``description``, ``tangential_memory``, ``tangential``, ``rotation``."""
    model = data.get("model")
    if model is None:
        raise source.error("model", f"missing (one of {', '.join(MODELS)})")
    if model not in MODELS:
        raise source.bad("model", model, "one of " + ", ".join(map(repr, MODELS)))
    description = data.get("description", "")
    if not isinstance(description, str):
        raise source.bad("description", description, "a string")
    return Header(model, description,
                  source.choice(data, "tangential_memory", TANGENTIAL_MEMORY, "incremental"),
                  source.choice(data, "tangential", TANGENTIAL_EFFECTS, "auto"),
                  source.flag(data, "rotation", True))


def parse_numerics(source: TomlSource, table) -> Numerics:
    """Return a ``[numerics]`` table.

    ``preset`` (default ``"default"``) then overrides of any field of
    :class:`~vimpact.model.numerics.Numerics`; a string is a preset name.
    """
    if isinstance(table, str):
        table = {"preset": table}
    if not isinstance(table, dict):
        raise source.bad("numerics", table, "a table (or a preset name)")
    source.unknown(table, NUMERICS_KEYS, "numerics")
    preset = table.get("preset", "default")
    if preset not in PRESETS:
        raise source.bad("numerics.preset", preset, "one of " + ", ".join(map(repr, PRESETS)))
    numerics = PRESETS[preset]
    for key, value in table.items():
        if key == "preset":
            continue
        try:
            numerics = numerics.with_(**{key: value})
        except ValueError as exc:
            raise ValueError(f"{source.path}: numerics.{exc}") from None
    return numerics


def scene_from_values(model: str, values: dict, arms=(), *, tangential_memory="incremental",
                      tangential="auto", rotation=True, allow_large_contact=False) -> Scene:
    """Return the scene of one set of named physical values.

    Parameters
    ----------
    model : one of ``vimpact.MODELS``
    values : key -> number, keys of :func:`input_keys` (missing optional keys take
        :data:`PHYSICAL_DEFAULTS`; ``eta_Pa_s`` defaults to 0 for Prony; ``mu`` to
        ``inf``; ``angle_deg`` sets ``v_x0 = v_z0 tan(angle)`` and excludes ``v_x0_m_s``)
    arms : Prony series: ``[(G_Pa, tau_s), ...]``

    Raises ``ValueError`` (``InputError``) for an invalid combination.
    """
    if "angle_deg" in values and "v_x0_m_s" in values:
        raise InputError(f"angle_deg = {values['angle_deg']!r} is not allowed together with "
                         f"v_x0_m_s = {values['v_x0_m_s']!r}: give one of them")
    p = {**PHYSICAL_DEFAULTS, **{k: float(v) for k, v in values.items()}}
    if "angle_deg" in p:
        p["v_x0_m_s"] = tangential_speed(p["v_z0_m_s"], p["angle_deg"])
    nu = p["nu"]
    if model == "standard_solid":
        mat = Material.standard_solid(nu=nu, G1=p["G1_Pa"], G2=p["G2_Pa"], eta=p["eta_Pa_s"])
    elif model == "prony":
        mat = Material.prony(nu=nu, G_inf=p["G_Pa"], arms=list(arms),
                             eta0=p.get("eta_Pa_s", 0.0))
    elif model == "kelvin_voigt":
        mat = Material.kelvin_voigt(nu=nu, eta=p["eta_Pa_s"], G=p.get("G_Pa"), E=p.get("E_Pa"))
    else:
        mat = Material.elastic(nu=nu, G=p.get("G_Pa"), E=p.get("E_Pa"))
    R, m = p["R_m"], p["m_kg"]
    return Scene(mat, R=R, m=m, v_z0=p["v_z0_m_s"], v_x0=p["v_x0_m_s"], omega0=p["omega0_rad_s"],
                 Theta=p["theta_ratio"] * m * R**2, tangential_memory=tangential_memory,
                 allow_large_contact=allow_large_contact, tangential=tangential,
                 rotation=rotation, mu=p.get("mu", math.inf))


__all__ = ["ANGLE_RANGE_DEG", "ARM_KEYS", "FRICTION_KEYS", "Header", "MATERIAL_KEYS",
           "NUMERICS_KEYS", "PHYSICAL_DEFAULTS", "SPHERE_KEYS", "SWEEP_TOP_KEYS", "TomlSource",
           "friction_coefficient", "impact_angle", "input_keys", "is_number", "parse_header",
           "parse_numerics", "parse_toml", "physical_keys", "read_toml", "required_keys",
           "scene_from_values", "tangential_speed"]
