"""Materials written as TOML: a material table, a material file, and its temperature shift.

One grammar for a material wherever a TOML input gives one: a DEM set-up's
``[types.NAME.material]``, a material file (``vimpact material fit --out``),
which scene files, sweep specifications and DEM set-ups name by path. Keys
(moduli in Pa, viscosities in Pa s, times in s)::

    model = "prony"          # elastic | kelvin_voigt | standard_solid | prony
    nu = 0.49                # Poisson ratio, in [0, 0.5]
    G_inf = 1.0e6            # prony: relaxed shear modulus (or E_inf, Young's)
    eta0 = 0.0               # prony: parallel dashpot (default 0)
    arms = [[3.2e8, 1e-8], [1.1e8, 1e-7]]   # prony: [G_i, tau_i] pairs
    # elastic: E or G; kelvin_voigt: E or G, eta; standard_solid: G1, G2 (or E1, E2), eta

    [shift]                  # optional: how the times shift with temperature
    law = "wlf"              # wlf | arrhenius
    T_ref_K = 220.0          # reference temperature of the times above, K
    C1 = 17.44               # WLF: log10 a_T = -C1 (T - T_ref) / (C2 + T - T_ref)
    C2_K = 51.6              # WLF, K
    # arrhenius: E_a_J_mol = 1.5e5, ln a_T = (E_a / R) (1/T - 1/T_ref)

A material file has these keys at its top level, and may have a
``description`` (a string). Wherever a material is expected, a string other
than ``"rigid"`` names a material file, relative to the directory of the file
that names it. Temperatures are absolute, in kelvin.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from vimpact.model.material import Material, shear_modulus
from vimpact.model.temperature import LAWS, ShiftLaw
from vimpact.model.toml_input import MATERIAL_KEYS, read_toml
from vimpact.model.validation import InputError, message, positive, require

#: Keys of a material table, per model.
MATERIAL_TABLE_KEYS = {
    "elastic": ("model", "nu", "E", "G", "shift"),
    "kelvin_voigt": ("model", "nu", "E", "G", "eta", "shift"),
    "standard_solid": ("model", "nu", "G1", "G2", "E1", "E2", "eta", "shift"),
    "prony": ("model", "nu", "G_inf", "E_inf", "arms", "eta0", "shift"),
}
#: Keys of a ``[shift]`` table, per law (temperatures in K, E_a in J/mol).
SHIFT_KEYS = {"wlf": ("law", "T_ref_K", "C1", "C2_K"),
              "arrhenius": ("law", "T_ref_K", "E_a_J_mol")}


def bad_value(source: str, what: str, value, allowed: str) -> InputError:
    """Return the error of a bad TOML value: ``SOURCE: what = value is not allowed: must be ...``."""
    return InputError(f"{source}: " + message(what, value, allowed))


def toml_number(source: str, where: str, value) -> float:
    """Return a TOML integer or float (not a bool) as a float; else :func:`bad_value`."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise bad_value(source, where, value, "a number")
    return float(value)


_err, _num = bad_value, toml_number


def shift_from_table(table, where: str = "shift", source: str = "<string>") -> ShiftLaw:
    """Return a :class:`~vimpact.model.temperature.ShiftLaw` from a ``[shift]`` table (module doc)."""
    if not isinstance(table, dict):
        raise _err(source, where, table, 'a table with "law" and "T_ref_K"')
    law = table.get("law")
    if law not in SHIFT_KEYS:
        raise _err(source, f"{where}.law", law, "one of " + ", ".join(map(repr, LAWS)))
    unknown = sorted(set(table) - set(SHIFT_KEYS[law]))
    if unknown:
        raise _err(source, f"{where} key", unknown[0],
                   f"one of {list(SHIFT_KEYS[law])} for law {law!r}")
    for key in SHIFT_KEYS[law][1:]:
        if key not in table:
            raise _err(source, f"{where}.{key}", None, "given")
    v = {k: _num(source, f"{where}.{k}", x) for k, x in table.items() if k != "law"}
    try:
        if law == "wlf":
            return ShiftLaw.wlf(v["T_ref_K"], v["C1"], v["C2_K"])
        return ShiftLaw.arrhenius(v["T_ref_K"], v["E_a_J_mol"])
    except InputError as exc:
        raise InputError(f"{source}: {where}: {exc}") from None


def material_from_table(table, where: str = "material", source: str = "<string>") -> Material:
    """Return a :class:`vimpact.Material` from a material table (keys in the module doc)."""
    if not isinstance(table, dict):
        raise _err(source, where, table, 'a table with "model" and its moduli')
    model = str(table.get("model"))
    require(f"{source}: {where}.model", table.get("model"), model in MATERIAL_TABLE_KEYS,
            "one of " + ", ".join(map(repr, MATERIAL_TABLE_KEYS)))
    unknown = sorted(set(table) - set(MATERIAL_TABLE_KEYS[model]))
    if unknown:
        raise _err(source, f"{where} key", unknown[0],
                   f"one of {sorted(MATERIAL_TABLE_KEYS[model])} for model {model!r}")
    v = {k: (_num(source, f"{where}.{k}", x) if k not in ("model", "arms", "shift") else x)
         for k, x in table.items()}
    if "nu" not in v:
        raise _err(source, f"{where}.nu", None, "given (Poisson ratio in [0, 0.5])")
    shift = shift_from_table(v["shift"], f"{where}.shift", source) if "shift" in v else None
    nu = v["nu"]
    try:
        if model == "elastic":
            mat = Material.elastic(nu=nu, G=v.get("G"), E=v.get("E"))
        elif model == "kelvin_voigt":
            require(f"{where}.eta", None, "eta" in v, "given (Pa s)")
            mat = Material.kelvin_voigt(nu=nu, eta=v["eta"], G=v.get("G"), E=v.get("E"))
        elif model == "standard_solid":
            G1 = v["G1"] if "G1" in v else shear_modulus(positive("E1", v.get("E1")), nu)
            G2 = v["G2"] if "G2" in v else shear_modulus(positive("E2", v.get("E2")), nu)
            require(f"{where}.eta", None, "eta" in v, "given (Pa s)")
            mat = Material.standard_solid(nu=nu, G1=G1, G2=G2, eta=v["eta"])
        else:
            G_inf = v["G_inf"] if "G_inf" in v else shear_modulus(positive("E_inf", v.get("E_inf")),
                                                                  nu)
            arms: Any = v.get("arms", [])
            require(f"{where}.arms", arms, isinstance(arms, list) and all(
                isinstance(a, list) and len(a) == 2 for a in arms),
                "a list of [G_i (Pa), tau_i (s)]")
            arms = [(_num(source, f"{where}.arms", a[0]), _num(source, f"{where}.arms", a[1]))
                    for a in arms]
            mat = Material.prony(nu=nu, G_inf=G_inf, arms=arms, eta0=v.get("eta0", 0.0))
    except InputError as exc:
        if str(exc).startswith(source):
            raise
        raise InputError(f"{source}: {where}: {exc}") from None
    return mat.with_shift(shift) if shift is not None else mat


def load_material(path) -> Material:
    """Read a material file (TOML, module doc); errors name the file and the key."""
    path = Path(path)
    _, data = read_toml(path, "material file")
    description = data.pop("description", "")
    if not isinstance(description, str):
        raise _err(str(path), "description", description, "a string")
    return material_from_table(data, "material", str(path))


def resolve_material(value, where: str, source: str, base: Path | None = None) -> Material:
    """Return the material a TOML key gives.

    A material table, or a string naming a material file relative to ``base`` (the
    directory of the file being read).
    """
    if isinstance(value, str):
        path = Path(value)
        if not path.is_absolute() and base is not None:
            path = base / path
        if not path.is_file():
            raise _err(source, where, value, "a material table or the path of a material file "
                       "(relative to this file's directory)")
        return load_material(path)
    return material_from_table(value, where, source)


def at_temperature(material: Material, T, where: str, source: str) -> Material:
    """``material`` at the temperature ``T`` (K) given by the key ``where`` of ``source``."""
    try:
        return material.at_temperature(T)
    except InputError as exc:
        raise InputError(f"{source}: {where}: {exc}") from None


#: Keys a scene file's ``[scene]`` or a sweep's ``[random]`` table takes for a material
#: file: its path and the temperature (K) to shift it to.
MATERIAL_FILE_KEYS = ("material", "temperature_K")


def table_values(material: Material) -> tuple[dict, list]:
    """Return the value keys of a scene file that give ``material``.

    The value keys of a scene file's ``[scene]`` (a sweep's ``[random]``) that give
    ``material``: ``(values, arms)`` with ``nu``, the material keys of its model
    (``G_Pa``, ``eta_Pa_s``, ``G1_Pa``, ``G2_Pa``) and the arms as ``{G_Pa, tau_s}``.
    """
    values = {"nu": material.nu}
    if material.model == "standard_solid":
        G2, tau = material.arms[0] if material.arms else (material.G_inf, 0.0)
        values.update(G1_Pa=material.G_inf, G2_Pa=G2, eta_Pa_s=G2 * tau)
        return values, []
    values["G_Pa"] = material.G_inf
    if material.model in ("kelvin_voigt", "prony"):
        values["eta_Pa_s"] = material.eta0
    arms = [{"G_Pa": G, "tau_s": tau} for G, tau in material.arms]
    return values, arms


def inline_material(source: str, data: dict, table: str,
                    base: Path | None) -> tuple[dict, str]:
    """Return ``data`` with its material file written out as value keys.

    ``data`` (a parsed scene file or sweep spec) with the material file named by
    ``[table] material`` (shifted to ``[table] temperature_K``) written out as the
    table's value keys, and ``model`` set to the file's; unchanged without ``material``.

    Returns the new data and the text of the material file read ("" without one).
    The material keys of every model (:data:`~vimpact.model.toml_input.MATERIAL_KEYS`),
    ``nu`` and ``arms`` beside ``material`` are an error: the file gives them.
    """
    values = data.get(table)
    if not isinstance(values, dict) or ("material" not in values
                                        and "temperature_K" not in values):
        return data, ""
    if "material" not in values:
        raise InputError(f"{source}: {table}.temperature_K = {values['temperature_K']!r} is "
                         "not allowed: must come with a material file ({table}.material), "
                         "whose shift law it applies")
    replaced = {k for keys in MATERIAL_KEYS.values() for k in keys} | {"nu", "arms"}
    given = sorted(k for k in values if k in replaced)
    if given:
        raise InputError(f"{source}: {table}.{given[0]} cannot be combined with "
                         f"{table}.material: the material file gives the whole material")
    name = values["material"]
    if not isinstance(name, str):
        raise _err(source, f"{table}.material", name, "the path of a material file (relative "
                   "to this file's directory)")
    path = Path(name) if Path(name).is_absolute() or base is None else base / name
    mat = resolve_material(name, f"{table}.material", source, base)
    if "temperature_K" in values:
        T = values["temperature_K"]
        ok = isinstance(T, (int, float)) and not isinstance(T, bool) and 0.0 < T < math.inf
        if not ok:
            raise _err(source, f"{table}.temperature_K", T,
                       "an absolute temperature in kelvin, one finite number > 0")
        mat = at_temperature(mat, float(T), f"{table}.temperature_K", source)
    model = data.get("model", mat.model)
    if model != mat.model:
        raise _err(source, "model", model, f"{mat.model!r}, the model of the material file "
                   f"{name!r} (or left out)")
    numbers, arms = table_values(mat)
    new_table = {k: v for k, v in values.items() if k not in MATERIAL_FILE_KEYS}
    new_table.update(numbers)
    if mat.model == "prony":
        new_table["arms"] = arms
    return {**data, "model": mat.model, table: new_table}, path.read_text(encoding="utf-8")


def material_toml(material: Material, comment: str = "") -> str:
    """Return the text of a material file for ``material``.

    The text of a material file for ``material`` (``comment`` lines go on top, as
    TOML comments); :func:`load_material` of it gives ``material`` back exactly.
    """
    lines = [f"# {line}".rstrip() for line in comment.splitlines()]
    lines += [f'model = "{material.model}"', f"nu = {material.nu!r}"]
    if material.model == "prony":
        lines += ["# relaxed shear modulus G_inf (Pa), parallel dashpot eta0 (Pa s),",
                  "# Maxwell arms [G_i (Pa), tau_i (s)]",
                  f"G_inf = {material.G_inf!r}", f"eta0 = {material.eta0!r}", "arms = ["]
        lines += [f"    [{G!r}, {tau!r}]," for G, tau in material.arms]
        lines.append("]")
    elif material.model == "standard_solid":
        G2, tau = material.arms[0] if material.arms else (material.G_inf, 0.0)
        lines += [f"G1 = {material.G_inf!r}", f"G2 = {G2!r}", f"eta = {G2 * tau!r}"]
    else:
        lines.append(f"G = {material.G_inf!r}")
        if material.model == "kelvin_voigt":
            lines.append(f"eta = {material.eta0!r}")
    s = material.shift
    if s is not None:
        lines += ["", "# time-temperature superposition: tau_i(T) = a_T tau_i(T_ref)",
                  "[shift]",
                  f'law = "{s.law}"', f"T_ref_K = {s.T_ref!r}"]
        lines += ([f"C1 = {s.C1!r}", f"C2_K = {s.C2!r}"] if s.law == "wlf"
                  else [f"E_a_J_mol = {s.E_a!r}"])
    return "\n".join(lines) + "\n"


__all__ = ["MATERIAL_FILE_KEYS", "MATERIAL_TABLE_KEYS", "SHIFT_KEYS", "at_temperature",
           "bad_value", "inline_material", "load_material", "material_from_table", "material_toml",
           "resolve_material", "shift_from_table", "table_values", "toml_number"]
