"""A DEM set-up: particle types, walls, friction and the impact speeds to cover.

Read from a TOML file (example: ``sweeps/dem/two_rubbers.toml``)::

    [speeds]                 # the normal impact speeds the DEM run will see, m/s
    min = 0.1
    max = 5.0
    n = 24                   # points (log-spaced); default 24

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
    [walls.floor]
    material = "rigid"       # or a material table as above

    [friction]               # Coulomb coefficients, by "type-type" or "type-wall"
    default = 0.5
    "soft-floor" = 0.6

Every pair of types (``i <= j``) and every type with every wall is a contact.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vimpact.model.material import Material, shear_modulus
from vimpact.model.pair import Body, Wall, pair_material
from vimpact.model.scene import DEFAULT_THETA_RATIO
from vimpact.model.validation import InputError, message, positive, require

#: speed points when ``[speeds] n`` is not given
DEFAULT_SPEED_POINTS = 24

_MATERIAL_KEYS = {
    "elastic": {"model", "nu", "E", "G"},
    "kelvin_voigt": {"model", "nu", "E", "G", "eta"},
    "standard_solid": {"model", "nu", "G1", "G2", "E1", "E2", "eta"},
    "prony": {"model", "nu", "G_inf", "E_inf", "arms", "eta0"},
}


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
        """A :class:`Body` of this type (nominal radius by default), at rest."""
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
    """A particle-particle or particle-wall contact and its friction coefficient."""

    first: ParticleType
    second: ParticleType | WallType
    mu: float

    @property
    def key(self) -> str:
        """``"first-second"``."""
        return f"{self.first.name}-{self.second.name}"

    @property
    def is_wall(self) -> bool:
        return isinstance(self.second, WallType)

    @property
    def material(self) -> Material:
        """The one half-space material of the pair (:func:`vimpact.model.pair.pair_material`)."""
        return pair_material(self.first.material, self.second.material)

    def levels(self) -> list[tuple[Body, Body | Wall]]:
        """The pair at each size level (min, nominal, max radius of both types; one
        level without a size range)."""
        n = max(len(self.first.radii), 1 if self.is_wall else len(self.second.radii))
        out = []
        for k in range(n):
            b1 = self.first.body(self.first.radii[min(k, len(self.first.radii) - 1)])
            if self.is_wall:
                out.append((b1, Wall(self.second.material)))
            else:
                r2 = self.second.radii[min(k, len(self.second.radii) - 1)]
                out.append((b1, self.second.body(r2)))
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

    def contact(self, a: str, b: str) -> Contact:
        """The contact of the named type/wall pair (either order)."""
        for c in self.contacts:
            if (c.first.name, c.second.name) in ((a, b), (b, a)):
                return c
        raise InputError(message("contact", f"{a}-{b}", "a pair of known type or wall names"))


def _err(source: str, what: str, value, allowed: str) -> InputError:
    return InputError(f"{source}: " + message(what, value, allowed))


def _num(source: str, where: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _err(source, where, value, "a number")
    return float(value)


def material_from_table(table, where: str = "material", source: str = "<string>") -> Material:
    """A :class:`vimpact.Material` from a TOML table (keys in the module doc)."""
    if not isinstance(table, dict):
        raise _err(source, where, table, 'a table with "model" and its moduli')
    model = table.get("model")
    require(f"{source}: {where}.model", model, model in _MATERIAL_KEYS,
            "one of " + ", ".join(map(repr, _MATERIAL_KEYS)))
    unknown = sorted(set(table) - _MATERIAL_KEYS[model])
    if unknown:
        raise _err(source, f"{where} key", unknown[0],
                   f"one of {sorted(_MATERIAL_KEYS[model])} for model {model!r}")
    v = {k: (_num(source, f"{where}.{k}", x) if k not in ("model", "arms") else x)
         for k, x in table.items()}
    if "nu" not in v:
        raise _err(source, f"{where}.nu", None, "given (Poisson ratio in [0, 0.5])")
    nu = v["nu"]
    try:
        if model == "elastic":
            return Material.elastic(nu=nu, G=v.get("G"), E=v.get("E"))
        if model == "kelvin_voigt":
            require(f"{where}.eta", None, "eta" in v, "given (Pa s)")
            return Material.kelvin_voigt(nu=nu, eta=v["eta"], G=v.get("G"), E=v.get("E"))
        if model == "standard_solid":
            G1 = v["G1"] if "G1" in v else shear_modulus(positive("E1", v.get("E1")), nu)
            G2 = v["G2"] if "G2" in v else shear_modulus(positive("E2", v.get("E2")), nu)
            require(f"{where}.eta", None, "eta" in v, "given (Pa s)")
            return Material.standard_solid(nu=nu, G1=G1, G2=G2, eta=v["eta"])
        G_inf = v["G_inf"] if "G_inf" in v else shear_modulus(positive("E_inf", v.get("E_inf")), nu)
        arms = v.get("arms", [])
        require(f"{where}.arms", arms, isinstance(arms, list) and all(
            isinstance(a, list) and len(a) == 2 for a in arms), "a list of [G_i (Pa), tau_i (s)]")
        arms = [(_num(source, f"{where}.arms", a[0]), _num(source, f"{where}.arms", a[1]))
                for a in arms]
        return Material.prony(nu=nu, G_inf=G_inf, arms=arms, eta0=v.get("eta0", 0.0))
    except InputError as exc:
        if str(exc).startswith(source):
            raise
        raise InputError(f"{source}: {where}: {exc}") from None


def problem_from_toml(text: str, source: str = "<string>") -> DemProblem:
    """Parse a DEM set-up (module doc) from TOML text."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{source}: not valid TOML: {exc}") from None
    unknown = sorted(set(data) - {"speeds", "types", "walls", "friction"})
    if unknown:
        raise _err(source, "top-level key", unknown[0], "one of speeds, types, walls, friction")
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
    types = []
    for i, (name, t) in enumerate(tables.items(), start=1):
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
            radii = (lo, math.sqrt(lo * hi), hi) if hi > lo else (lo,)
        else:
            R = _num(source, f"{where}.radius", r)
            if not (0.0 < R < math.inf):
                raise _err(source, f"{where}.radius", R, "a finite number > 0 (m)")
            radii = (R,)
        theta = _num(source, f"{where}.theta_ratio", t.get("theta_ratio", DEFAULT_THETA_RATIO))
        if not (0.0 < theta < math.inf):
            raise _err(source, f"{where}.theta_ratio", theta, "a finite number > 0")
        mat = material_from_table(t["material"], f"{where}.material", source)
        types.append(ParticleType(name, i, mat, radii, rho, theta))

    walls = []
    for k, (name, w) in enumerate((data.get("walls") or {}).items(), start=len(types) + 1):
        where = f"walls.{name}"
        if name in tables:
            raise _err(source, where, name, "a name different from every type name")
        if not isinstance(w, dict) or set(w) != {"material"}:
            raise _err(source, where, w, 'a table with only "material" ("rigid" or a material table)')
        m = w["material"]
        walls.append(WallType(name, k, None if m == "rigid" else
                              material_from_table(m, f"{where}.material", source)))

    fr = data.get("friction", {})
    if not isinstance(fr, dict):
        raise _err(source, "[friction]", fr, "a table of coefficients")
    names = [t.name for t in types] + [w.name for w in walls]
    for key in fr:
        if key != "default" and (key.count("-") < 1 or not any(
                key == f"{a}-{b}" for a in names for b in names)):
            raise _err(source, "friction key", key, '"default" or "NAME-NAME" of types/walls')
    for key, val in fr.items():
        mu = _num(source, f"friction.{key}", val)
        if not (mu >= 0.0):
            raise _err(source, f"friction.{key}", mu, "a number >= 0")

    def mu_of(a: str, b: str) -> float:
        for key in (f"{a}-{b}", f"{b}-{a}", "default"):
            if key in fr:
                return float(fr[key])
        return math.inf

    contacts = []
    for i, a in enumerate(types):
        for b in types[i:]:
            contacts.append(Contact(a, b, mu_of(a.name, b.name)))
        for w in walls:
            contacts.append(Contact(a, w, mu_of(a.name, w.name)))
    for c in contacts:  # refuse unmappable material pairs now, naming the contact
        try:
            c.material
        except InputError as exc:
            raise InputError(f"{source}: contact {c.key}: {exc}") from None
    return DemProblem(tuple(types), tuple(walls), tuple(contacts), speeds,
                      tuple(float(a) for a in angles), source)


def load_problem(path) -> DemProblem:
    """Read a DEM set-up TOML file (module doc)."""
    from vimpact.model.toml_input import read_text
    path = Path(path)
    return problem_from_toml(read_text(path, "DEM set-up"), str(path))
