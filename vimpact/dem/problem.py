"""A DEM set-up: particle types, walls, friction and the impact speeds to cover.

Read from a TOML file (example: ``sweeps/dem/two_rubbers.toml``)::

    [speeds]                 # the normal impact speeds the DEM run will see, m/s
    min = 0.1
    max = 5.0
    n = 24                   # points (log-spaced); default 24
    angles_deg = [10, 30, 60] # optional: impact angles from the normal (no spin) of the
                             # tangential fits of contacts with friction; default
                             # 5, 15, 30, 45, 60, 75

    [types.soft]             # one table per particle type, in type order
    density = 1100.0         # kg/m^3
    radius = 0.005           # m, or [min, max] for a size range
    theta_ratio = 0.4        # Theta / (m R^2), optional (solid sphere)
    [types.soft.material]    # model = elastic | kelvin_voigt | standard_solid | prony
    model = "kelvin_voigt"
    nu = 0.45
    E = 5e6                  # Pa (or G); kelvin_voigt: eta (Pa s)
    eta = 20.0               # standard_solid: G1, G2 (or E1, E2), eta; prony: G_inf
                             # (or E_inf), arms = [[G_i, tau_i], ...], eta0
                             # optional [types.soft.material.shift]: temperature
                             # shift law (docs/howto/dma.md); or material = "FILE.toml",
                             # a material file (vimpact material fit), relative to this file
    [walls.floor]
    material = "rigid"       # or a material table as above, or a material file

    temperature_K = 296.0    # optional (top level): the temperature of the DEM run, K;
                             # every viscoelastic material then needs a shift law

    [friction]               # Coulomb coefficients, by "type-type" or "type-wall"
    default = 0.5
    "soft-floor" = 0.6

    [adhesion]               # optional: work of adhesion dgamma, J/m^2, by "type-type" or
    "soft-floor" = 0.05      # "type-wall" (or default); default 0 (no adhesion). Only
                             # LAMMPS' granular jkr model takes it (--for lammps)

Every pair of types (``i <= j``) and every type with every wall is a contact.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vimpact.model.material import Material
from vimpact.model.material_file import (
    at_temperature,
    material_from_table,  # noqa: F401 (its former home)
    resolve_material,
)
from vimpact.model.material_file import bad_value as _err
from vimpact.model.material_file import toml_number as _num
from vimpact.model.pair import Body, Wall, pair_material
from vimpact.model.scene import DEFAULT_THETA_RATIO
from vimpact.model.validation import InputError, message

#: top-level keys of a DEM set-up
_TOP_KEYS = ("speeds", "types", "walls", "friction", "adhesion", "temperature_K")
#: speed points when ``[speeds] n`` is not given
DEFAULT_SPEED_POINTS = 24



@dataclass(frozen=True)
class ParticleType:
    """One DEM particle type.

    Attributes
    ----------
    name : its name (the TOML table name); ``index`` : 1-based type number
    material : :class:`vimpact.Material`
    radii : ``(R,)`` or ``(R_min, R_nominal, R_max)`` with the geometric mean as nominal, m
    density : kg/m^3; ``theta_ratio`` : ``Theta / (m R^2)``
    """

    name: str
    index: int
    material: Material
    radii: tuple[float, ...]
    density: float
    theta_ratio: float = DEFAULT_THETA_RATIO

    @property
    def radius(self) -> float:
        """Nominal radius, m."""
        return self.radii[len(self.radii) // 2]

    def mass(self, R: float) -> float:
        """Mass of a sphere of radius ``R`` (m), kg."""
        return self.density * 4.0 / 3.0 * math.pi * R**3

    def body(self, R: float | None = None) -> Body:
        """Return a :class:`Body` of this type at rest, radius ``R`` (m; nominal by default)."""
        R = self.radius if R is None else R
        m = self.mass(R)
        return Body(self.material, R, m, Theta=self.theta_ratio * m * R**2)


@dataclass(frozen=True)
class WallType:
    """A wall: ``material`` ``None`` is rigid. ``index`` counts after the particle types."""

    name: str
    index: int
    material: Material | None


@dataclass(frozen=True)
class Contact:
    """A particle-particle or particle-wall contact.

    With its friction coefficient ``mu`` and its work of adhesion ``adhesion``
    (``dgamma``, J/m^2; 0: none).
    """

    first: ParticleType
    second: ParticleType | WallType
    mu: float
    adhesion: float = 0.0

    @property
    def key(self) -> str:
        """``"first-second"``."""
        return f"{self.first.name}-{self.second.name}"

    @property
    def is_wall(self) -> bool:
        """Whether the second partner is a wall."""
        return isinstance(self.second, WallType)

    @property
    def material(self) -> Material:
        """The one half-space material of the pair (:func:`vimpact.model.pair.pair_material`)."""
        return pair_material(self.first.material, self.second.material)

    def levels(self) -> list[tuple[Body, Body | Wall]]:
        """Return the pair at each size level.

        Min, nominal and max radius of both types; one level without a size range.
        """
        second = self.second
        n = max(len(self.first.radii), 1 if isinstance(second, WallType) else len(second.radii))
        out: list[tuple[Body, Body | Wall]] = []
        for k in range(n):
            b1 = self.first.body(self.first.radii[min(k, len(self.first.radii) - 1)])
            if isinstance(second, WallType):
                out.append((b1, Wall(second.material)))
            else:
                r2 = second.radii[min(k, len(second.radii) - 1)]
                out.append((b1, second.body(r2)))
        return out

    def effective(self, level: tuple[Body, Body | Wall]) -> tuple[float, float]:
        """Effective radius (m) and mass (kg) of one level."""
        b1, b2 = level
        if isinstance(b2, Wall):
            return b1.R, b1.m
        return b1.R * b2.R / (b1.R + b2.R), b1.m * b2.m / (b1.m + b2.m)

    def nominal(self) -> tuple[float, float]:
        """Effective radius (m) and mass (kg) at the nominal sizes."""
        levels = self.levels()
        return self.effective(levels[len(levels) // 2])

    @property
    def E_star(self) -> float:
        """Relaxed effective modulus ``2 G_inf / (1 - nu)`` of the pair material, Pa."""
        mat = self.material
        return 2.0 * mat.G_inf / (1.0 - mat.nu)


@dataclass(frozen=True)
class DemProblem:
    """Particle types, walls, their contacts and the impact speeds (m/s)."""

    types: tuple[ParticleType, ...]
    walls: tuple[WallType, ...]
    contacts: tuple[Contact, ...]
    speeds: np.ndarray = field(repr=False)
    angles_deg: tuple[float, ...] = ()
    source: str = "<string>"
    toml: str = field(default="", repr=False)
    size_classes: int = 1
    base: Path | None = field(default=None, repr=False)
    temperature: float | None = None

    @property
    def has_size_range(self) -> bool:
        """Some type has a radius range (it can be split into size classes)."""
        return any(len(t.radii) > 1 for t in self.types)

    def with_size_classes(self, k: int) -> DemProblem:
        """Return the same set-up with every size-range type split into ``k`` size classes.

        Types of equal radius ratio (``NAME_1`` .. ``NAME_k``, smallest first;
        friction as the type's).
        """
        return problem_from_toml(self.toml, self.source, base=self.base,
                                 temperature=self.temperature, size_classes=k)

    def contact(self, a: str, b: str) -> Contact:
        """Return the contact of the named type/wall pair (either order)."""
        for c in self.contacts:
            if (c.first.name, c.second.name) in ((a, b), (b, a)):
                return c
        raise InputError(message("contact", f"{a}-{b}", "a pair of known type or wall names"))


def problem_from_toml(text: str, source: str = "<string>", *, base: Path | None = None,
                      temperature: float | None = None, size_classes: int = 1) -> DemProblem:
    """Parse a DEM set-up (module doc) from TOML text.

    Parameters
    ----------
    text : the TOML text; ``source`` names it in error messages
    base : directory against which material file paths are resolved (default: the
        current directory)
    temperature : the temperature of the DEM run, K; overrides the file's
        ``temperature_K``; every viscoelastic material is shifted to it
    size_classes : > 1 splits every type with a radius range ``[min, max]``
        into that many types ``NAME_1`` .. ``NAME_k`` with the ranges
        ``min q^(i-1) .. min q^i``, ``q = (max/min)^(1/k)``, numbered in order
    """
    if isinstance(size_classes, bool) or not isinstance(size_classes, int) or size_classes < 1:
        raise InputError(message("size_classes", size_classes, "an integer >= 1"))
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{source}: not valid TOML: {exc}") from None
    unknown = sorted(set(data) - set(_TOP_KEYS))
    if unknown:
        raise _err(source, "top-level key", unknown[0], "one of " + ", ".join(_TOP_KEYS))
    where_T = "--temperature" if temperature is not None else "temperature_K"
    T = temperature if temperature is not None else data.get("temperature_K")
    if T is not None:
        T = _num(source, where_T, T)
        if not (0.0 < T < math.inf):
            raise _err(source, where_T, T, "an absolute temperature in kelvin, a finite number > 0")

    def material(value, where):
        mat = resolve_material(value, where, source, base)
        if T is None or (not mat.arms and mat.eta0 == 0.0):  # elastic: no times to shift
            return mat
        return at_temperature(mat, T, f"{where} at {where_T} = {T!r} K", source)
    sp = data.get("speeds")
    if not isinstance(sp, dict) or "min" not in sp or "max" not in sp:
        raise _err(source, "[speeds]", sp, "a table with min and max (m/s)")
    bad = sorted(set(sp) - {"min", "max", "n", "angles_deg"})
    if bad:
        raise _err(source, "[speeds] key", bad[0], "one of min, max, n, angles_deg")
    vmin, vmax = _num(source, "speeds.min", sp["min"]), _num(source, "speeds.max", sp["max"])
    if not (0.0 < vmin <= vmax < math.inf):
        raise _err(source, "speeds (min, max)", (vmin, vmax), "0 < min <= max, finite (m/s)")
    n = sp.get("n", DEFAULT_SPEED_POINTS)
    if isinstance(n, bool) or not isinstance(n, int) or not 2 <= n <= 200:
        raise _err(source, "speeds.n", n, "an integer in [2, 200]")
    speeds = np.geomspace(vmin, vmax, n) if vmax > vmin else np.full(1, vmin)
    angles = sp.get("angles_deg", [])
    if not isinstance(angles, list) or any(isinstance(a, bool) or not isinstance(a, (int, float))
                                           or not 0.0 <= a < 90.0 for a in angles):
        raise _err(source, "speeds.angles_deg", angles, "a list of angles in [0, 90) degrees")

    tables = data.get("types")
    if not isinstance(tables, dict) or not tables:
        raise _err(source, "[types]", tables, "at least one [types.NAME] table")
    types: list[ParticleType] = []
    base_of: dict[str, str] = {}  # type name -> its TOML table (differ for size classes)
    for name, t in tables.items():
        where = f"types.{name}"
        if not isinstance(t, dict):
            raise _err(source, where, t, "a table")
        bad = sorted(set(t) - {"density", "radius", "material", "theta_ratio"})
        if bad:
            raise _err(source, f"{where} key", bad[0], "one of density, radius, material, theta_ratio")
        for key in ("density", "radius", "material"):
            if key not in t:
                raise _err(source, f"{where}.{key}", None, "given")
        rho = _num(source, f"{where}.density", t["density"])
        if not (0.0 < rho < math.inf):
            raise _err(source, f"{where}.density", rho, "a finite number > 0 (kg/m^3)")
        r = t["radius"]
        if isinstance(r, list):
            if len(r) != 2:
                raise _err(source, f"{where}.radius", r, "a number or [min, max] (m)")
            lo, hi = (_num(source, f"{where}.radius", x) for x in r)
            if not (0.0 < lo <= hi < math.inf):
                raise _err(source, f"{where}.radius", r, "0 < min <= max (m)")
            ranges = [(lo, hi)] if size_classes == 1 or hi == lo else [
                (lo * (hi / lo) ** (k / size_classes), lo * (hi / lo) ** ((k + 1) / size_classes))
                for k in range(size_classes)]
        else:
            R = _num(source, f"{where}.radius", r)
            if not (0.0 < R < math.inf):
                raise _err(source, f"{where}.radius", R, "a finite number > 0 (m)")
            ranges = [(R, R)]
        theta = _num(source, f"{where}.theta_ratio", t.get("theta_ratio", DEFAULT_THETA_RATIO))
        if not (0.0 < theta < math.inf):
            raise _err(source, f"{where}.theta_ratio", theta, "a finite number > 0")
        mat = material(t["material"], f"{where}.material")
        for k, (lo, hi) in enumerate(ranges, start=1):
            radii = (lo, math.sqrt(lo * hi), hi) if hi > lo else (lo,)
            sub = name if len(ranges) == 1 else f"{name}_{k}"
            base_of[sub] = name
            types.append(ParticleType(sub, len(types) + 1, mat, radii, rho, theta))

    walls = []
    for k, (name, w) in enumerate((data.get("walls") or {}).items(), start=len(types) + 1):
        where = f"walls.{name}"
        if name in tables:
            raise _err(source, where, name, "a name different from every type name")
        if not isinstance(w, dict) or set(w) != {"material"}:
            raise _err(source, where, w, 'a table with only "material" ("rigid" or a material table)')
        m = w["material"]
        walls.append(WallType(name, k, None if m == "rigid" else
                              material(m, f"{where}.material")))

    names = [base_of[t.name] for t in types] + [w.name for w in walls]

    def per_contact(table: str, what: str, absent: float, finite: bool):
        """Return the coefficient of a ``[table]`` by contact (``NAME-NAME`` or ``default``)."""
        fr = data.get(table, {})
        if not isinstance(fr, dict):
            raise _err(source, f"[{table}]", fr, f"a table of {what}")
        for key in fr:
            if key != "default" and (key.count("-") < 1 or not any(
                    key == f"{a}-{b}" for a in names for b in names)):
                raise _err(source, f"{table} key", key, '"default" or "NAME-NAME" of types/walls')
        for key, val in fr.items():
            x = _num(source, f"{table}.{key}", val)
            if not (x >= 0.0 and (math.isfinite(x) or not finite)):
                raise _err(source, f"{table}.{key}", x,
                           "a finite number >= 0" if finite else "a number >= 0")

        def of(a: str, b: str) -> float:
            a, b = base_of.get(a, a), base_of.get(b, b)
            for key in (f"{a}-{b}", f"{b}-{a}", "default"):
                if key in fr:
                    return float(fr[key])
            return absent
        return of

    mu_of = per_contact("friction", "coefficients", math.inf, finite=False)
    adhesion_of = per_contact("adhesion", "works of adhesion (J/m^2)", 0.0, finite=True)

    contacts = []
    for i, a in enumerate(types):
        for b in types[i:]:
            contacts.append(Contact(a, b, mu_of(a.name, b.name), adhesion_of(a.name, b.name)))
        for w in walls:
            contacts.append(Contact(a, w, mu_of(a.name, w.name), adhesion_of(a.name, w.name)))
    for c in contacts:  # refuse unmappable material pairs now, naming the contact
        try:
            _ = c.material  # the property maps the pair (or raises)
        except InputError as exc:
            raise InputError(f"{source}: contact {c.key}: {exc}") from None
    return DemProblem(tuple(types), tuple(walls), tuple(contacts), speeds,
                      tuple(float(a) for a in angles), source, text, size_classes, base,
                      temperature)


def load_problem(path, temperature: float | None = None) -> DemProblem:
    """Read a DEM set-up TOML file (module doc).

    ``temperature`` (K) overrides its ``temperature_K``.
    """
    from vimpact.model.toml_input import read_text
    path = Path(path)
    return problem_from_toml(read_text(path, "DEM set-up"), str(path), base=path.parent,
                             temperature=temperature)
