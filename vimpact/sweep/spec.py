"""Sweeps: many impacts from one TOML specification into one Parquet table.

A specification (``sweeps/*.toml``, read with :mod:`tomllib`) describes one
table. Example (a Kelvin-Voigt lookup table on a grid of dimensionless
parameters)::

    description = "Kelvin-Voigt restitution table"
    model = "kelvin_voigt"        # elastic | kelvin_voigt | standard_solid | prony
    seed = 1                      # numpy default_rng(seed); required for [random]
    chunk_size = 128              # rows per part file (and per parallel batch)
    output = "tables/kv.parquet"      # relative to THIS FILE's directory
    tangential_memory = "incremental" # or "seed" (thesis eq. 4.16)

    [numerics]                    # optional; default: preset "default"
    preset = "default"            # default | fast | thesis
    steps = 1000                  # overrides: integrator, steps, elements,
                                  # row_width, max_time (see vimpact.Numerics)
    [grid]
    Q1 = { start = 1e-3, stop = 100, per_decade = 10 }
    nu = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]

Top-level keys: ``model`` (required), ``description``, ``seed``,
``chunk_size`` (default 64), ``output`` (default: the spec's name with
``.parquet`` beside it), ``tangential_memory``, ``numerics`` (a table, or a
preset name as a string) and exactly one of ``[random]`` or ``[grid]``.
Unknown keys and bad values are errors (``ValueError``) that name the file
and the key.

``[grid]``: parameter sets on a grid of the dimensionless parameters, built
with :meth:`vimpact.Scene.from_dimensionless` (the grid is the product of
all axes; ``Q1`` runs fastest, then ``Q2``, ``nu``, ``theta_ratio``). Keys:
``Q1`` (kelvin_voigt, standard_solid; >= 0), ``Q2`` (standard_solid; > 0),
``nu`` (required; in [0, 0.5]), ``theta_ratio`` (Theta / (m R^2), default
0.4). An axis is a number, a list of numbers, or a table
``{ start, stop, per_decade }`` (log-spaced, both ends included) or
``{ start, stop, num, log = true|false }`` (``num`` points; ``log`` defaults
to the rule below). With ``per_decade`` the number of intervals is
``round(per_decade * log10(stop / start))``, so both ends are exact. An elastic grid has ``nu`` and ``theta_ratio`` only
(``Q1 = 0``); a Prony series has no dimensionless grid.

``[random]``: physical parameter sets drawn at random, as the thesis does to
show that results collapse onto ``Q1`` (and ``Q2``). ``rows`` (required) is
the number of draws; every other key is a physical input named like its
column, with its unit as suffix:

- all models: ``nu``, ``R_m``, ``m_kg``, ``v_z0_m_s`` (required),
  ``v_x0_m_s`` (default 0), ``omega0_rad_s`` (default 0), ``theta_ratio``
  (default 0.4)
- elastic: ``E_Pa`` or ``G_Pa``; kelvin_voigt: ``E_Pa`` or ``G_Pa``, and
  ``eta_Pa_s``; standard_solid: ``G1_Pa``, ``G2_Pa``, ``eta_Pa_s``;
  prony: ``G_Pa`` (relaxed modulus), ``eta_Pa_s`` (parallel dashpot,
  default 0) and one ``[[random.arms]]`` table per Maxwell arm with
  ``G_Pa`` and ``tau_s``

Each value is a number (fixed), a range ``[lo, hi]`` or
``{ range = [lo, hi], log = true|false }``, or ``{ choice = [a, b, ...] }``
(one of the values, equally likely). A range is drawn **log-uniformly when
``lo > 0`` and ``hi / lo > 10``** (it spans more than a decade), uniformly
otherwise; ``log`` overrides that (``log = true`` needs ``lo > 0``).
Draws are not checked against the physics: a drawn combination that
:class:`vimpact.Scene` rejects becomes a row with status ``invalid`` and the
reason in the ``error`` column.

Output paths: ``output`` in the spec is relative to the spec file's
directory; ``out=`` / ``--out`` is relative to the current directory.

The table (:func:`run_sweep`): one row per parameter set, in the order
generated, with columns ``row`` (0-based index), the physical inputs (unit
suffixes: ``E_Pa``, ``G_Pa``, ``G1_Pa``, ``G2_Pa``, ``eta_Pa_s``, ``R_m``,
``m_kg``, ``v_z0_m_s``, ``v_x0_m_s``, ``omega0_rad_s``; for a grid those of
the reference scene that was simulated), the dimensionless parameters
``Q1``, ``Q2`` (``Q2 = 0`` for Kelvin-Voigt and elastic, the limit
``G2 -> inf``; neither for a Prony series), ``nu``, ``theta_ratio``, the
results (``e_z``, ``e_x``, ``beta_x``, ``energy_ratio``, ``t_contact_s``,
``u_max_m``, ``a_max_m``, the Hertz scales ``t_hertz_s``, ``d_hertz_m``,
``a_hertz_m``, their ratios ``t_contact_rel``, ``u_max_rel``, ``a_max_rel``,
end velocities ``v_z_end_m_s``, ``v_x_end_m_s``, ``omega_end_rad_s``),
``status`` (:data:`SWEEP_STATUSES`) and ``error`` (null unless the row
failed before the kernel). NaN appears only in a row whose status says why.
Units and descriptions of all columns, the numerics, model, seed, package
version and the spec text are in the Parquet key-value metadata
(:func:`read_metadata`).

Crash safety: every finished chunk goes atomically (temporary file, fsync,
``os.replace``) to ``<out>.parts/part-NNNNN.parquet``; at the end the parts
are combined, atomically, into ``<out>`` and the directory is removed.
``resume=True`` computes only the missing chunks; parts of another spec or
package version are refused (each part stores a SHA-256 of the spec text,
the resolved numerics and the package version: editing the spec, even a
comment, invalidates the parts). The result is byte for byte that of an
uninterrupted run. Two runs writing the same output at the same time are
not supported.

Python API::

    from vimpact.sweep.spec import run_sweep, load_spec, read_metadata
    path = run_sweep("sweeps/kelvin_voigt_table.toml", out=None, resume=False,
                     progress=None)            # -> Path of the table
    spec = load_spec("sweeps/kelvin_voigt_table.toml")   # validated SweepSpec
    params = spec.parameters()                 # every parameter set, up front
    meta = read_metadata(path)                 # model, numerics, units, spec, ...
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import shutil
import sys
import tomllib
from collections.abc import Callable
from typing import NamedTuple
from pathlib import Path

import numba
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vimpact import __version__
from vimpact.model.material import MODELS, Material, shear_modulus
from vimpact.model.numerics import PRESETS, Numerics
from vimpact.engine.routing import choose_path
from vimpact.engine.result import FINISHED, STATUSES
from vimpact.model.scene import TANGENTIAL_EFFECTS, TANGENTIAL_MEMORY, Scene
from vimpact.engine.simulate import simulate_batch

#: Version of the table layout (columns and metadata keys).
SCHEMA_VERSION = 2

#: Prefix of every key-value metadata key the sweep writes.
META_PREFIX = "vimpact."

#: Row statuses of a sweep table: those of :data:`vimpact.STATUSES` and two more.
SWEEP_STATUSES = {
    **STATUSES,
    "invalid": "the drawn parameters are not a valid scene (reason in the error column); "
               "outputs NaN",
    "failed": "the simulation raised an error (message in the error column); outputs NaN",
}

DEFAULT_CHUNK_SIZE = 64
MAX_ROWS = 10_000_000

# ---- columns ----------------------------------------------------------------

#: Unit and meaning of every column a sweep table can have.
COLUMNS = {
    "row": ("", "row index, 0-based, in the order the parameter sets were generated"),
    "E_Pa": ("Pa", "Young's modulus (relaxed) as drawn"),
    "G_Pa": ("Pa", "shear modulus (Kelvin-Voigt, elastic) or relaxed modulus G_inf (Prony)"),
    "G1_Pa": ("Pa", "standard solid: parallel spring G1 (relaxed modulus)"),
    "G2_Pa": ("Pa", "standard solid: spring G2 of the Maxwell arm"),
    "eta_Pa_s": ("Pa s", "viscosity: Kelvin-Voigt dashpot, standard-solid arm dashpot, "
                         "Prony parallel dashpot"),
    "R_m": ("m", "sphere radius"),
    "m_kg": ("kg", "sphere mass"),
    "v_z0_m_s": ("m/s", "normal impact speed (into the half-space)"),
    "v_x0_m_s": ("m/s", "tangential speed of the centre"),
    "omega0_rad_s": ("rad/s", "spin about the y axis"),
    "Q1": ("1", "damping parameter sqrt(15/32) (eta/G_inf) / T"),
    "Q2": ("1", "stiffness ratio G1/G2 (standard solid; 0 for Kelvin-Voigt and elastic)"),
    "nu": ("1", "Poisson ratio"),
    "theta_ratio": ("1", "moment of inertia Theta / (m R^2)"),
    "e_z": ("1", "normal restitution |v_z,end| / v_z0"),
    "e_x": ("1", "tangential restitution |v_c,end| / |v_c0|"),
    "beta_x": ("1", "signed tangential restitution -v_c,end / v_c0"),
    "energy_ratio": ("1", "kinetic energy after / before"),
    "t_contact_s": ("s", "contact time"),
    "u_max_m": ("m", "maximum indentation"),
    "a_max_m": ("m", "maximum contact half-width"),
    "t_hertz_s": ("s", "Hertz contact time of the relaxed modulus"),
    "d_hertz_m": ("m", "Hertz maximum indentation of the relaxed modulus"),
    "a_hertz_m": ("m", "Hertz contact radius of the relaxed modulus"),
    "t_contact_rel": ("1", "t_contact / t_hertz"),
    "u_max_rel": ("1", "u_max / d_hertz"),
    "a_max_rel": ("1", "a_max / a_hertz"),
    "v_z_end_m_s": ("m/s", "normal velocity at the end (negative: rebound)"),
    "v_x_end_m_s": ("m/s", "tangential velocity of the centre at the end"),
    "omega_end_rad_s": ("rad/s", "spin at the end"),
    "path": ("", "the kernel that ran the row (vimpact.engine.routing; why: the paths metadata)"),
    "status": ("", "outcome of the row, see the statuses metadata"),
    "error": ("", "why the row failed before or in the simulation (null otherwise)"),
}

#: Result columns: sweep name -> column of :func:`vimpact.simulate_batch`.
_RESULTS = {
    "e_z": "e_z", "e_x": "e_x", "beta_x": "beta_x", "energy_ratio": "energy_ratio",
    "t_contact_s": "t_contact", "u_max_m": "u_max", "a_max_m": "a_max",
    "t_hertz_s": "t_hertz", "d_hertz_m": "d_hertz", "a_hertz_m": "a_hertz",
    "v_z_end_m_s": "v_z_end", "v_x_end_m_s": "v_x_end", "omega_end_rad_s": "omega_end",
}
_RELATIVE = {"t_contact_rel": ("t_contact_s", "t_hertz_s"), "u_max_rel": ("u_max_m", "d_hertz_m"),
             "a_max_rel": ("a_max_m", "a_hertz_m")}
_OUTPUTS = ("e_z", "e_x", "beta_x", "energy_ratio", "t_contact_s", "u_max_m", "a_max_m",
            "t_hertz_s", "d_hertz_m", "a_hertz_m", "t_contact_rel", "u_max_rel", "a_max_rel",
            "v_z_end_m_s", "v_x_end_m_s", "omega_end_rad_s")
#: Outputs that are NaN when v_c0 = 0 (no tangential force).
_TANGENTIAL = ("e_x", "beta_x")
_SCALES = ("t_hertz_s", "d_hertz_m", "a_hertz_m")
#: String columns (null where not applicable: path of a row that never ran, error of a good row).
_LABELS = ("path", "status", "error")

# ---- spec keys --------------------------------------------------------------

_TOP_KEYS = ("model", "description", "seed", "chunk_size", "output", "tangential_memory",
             "tangential", "rotation", "numerics", "random", "grid")
_NUMERICS_KEYS = ("preset",) + tuple(f.name for f in dataclasses.fields(Numerics))

_MATERIAL_KEYS = {
    "elastic": ("E_Pa", "G_Pa"),
    "kelvin_voigt": ("E_Pa", "G_Pa", "eta_Pa_s"),
    "standard_solid": ("G1_Pa", "G2_Pa", "eta_Pa_s"),
    "prony": ("G_Pa", "eta_Pa_s"),
}
_SPHERE_KEYS = ("R_m", "m_kg", "v_z0_m_s", "v_x0_m_s", "omega0_rad_s")
_RANDOM_DEFAULTS = {"v_x0_m_s": 0.0, "omega0_rad_s": 0.0, "theta_ratio": 0.4}
_ARM_KEYS = ("G_Pa", "tau_s")

_GRID_KEYS = {
    "elastic": ("theta_ratio", "nu"),
    "kelvin_voigt": ("theta_ratio", "nu", "Q1"),
    "standard_solid": ("theta_ratio", "nu", "Q2", "Q1"),
}  # outermost axis first: the last one runs fastest
_GRID_CHECKS = {
    "Q1": (lambda x: x >= 0.0, "a finite number >= 0"),
    "Q2": (lambda x: x > 0.0, "a finite number > 0"),
    "nu": (lambda x: 0.0 <= x <= 0.5, "in [0, 0.5]"),
    "theta_ratio": (lambda x: x > 0.0, "a finite number > 0"),
}


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by Ctrl-C (or a progress callback); finished chunks stay on disk."""

    def __init__(self, message: str, parts_dir: Path, done: int, total: int):
        super().__init__(message)
        self.message, self.parts_dir, self.done, self.total = message, parts_dir, done, total

    def __str__(self) -> str:
        return self.message


# ---- parsing ----------------------------------------------------------------

def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


class _Spec:
    """Error helper: messages that name the file and the key."""

    def __init__(self, path: Path):
        self.path = path

    def error(self, key: str, message: str) -> ValueError:
        return ValueError(f"{self.path}: {key}: {message}")

    def bad(self, key: str, value, allowed: str) -> ValueError:
        return ValueError(f"{self.path}: {key} = {value!r} is not allowed: must be {allowed}")

    def unknown(self, table: dict, allowed, where: str = "") -> None:
        for key in table:
            if key not in allowed:
                name = f"{where}.{key}" if where else key
                raise ValueError(f"{self.path}: unknown key {name!r} (allowed: "
                                 f"{', '.join(allowed)})")

    def number(self, key: str, value, check=None, allowed="a finite number") -> float:
        if not _is_number(value) or not math.isfinite(value) or (check and not check(value)):
            raise self.bad(key, value, allowed)
        return float(value)

    def integer(self, key: str, value, minimum: int) -> int:
        if not isinstance(value, int) or isinstance(value, bool) or value < minimum:
            raise self.bad(key, value, f"an integer >= {minimum}")
        return value

    def choice(self, data: dict, key: str, choices, default: str) -> str:
        value = data.get(key, default)
        if value not in choices:
            raise self.bad(key, value, "one of " + ", ".join(map(repr, choices)))
        return value

    def flag(self, data: dict, key: str, default: bool) -> bool:
        value = data.get(key, default)
        if not isinstance(value, bool):
            raise self.bad(key, value, "true or false")
        return value


def read_toml(path: Path, what: str) -> tuple[str, dict]:
    """Text and parsed content of the TOML file ``path`` (``what`` names it in errors)."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ValueError(f"{path}: {what} not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: cannot read the {what}: {exc}") from None
    return text, parse_toml(_Spec(path), text)


def parse_toml(spec: _Spec, text: str) -> dict:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{spec.path}: not valid TOML: {exc}") from None


class Header(NamedTuple):
    """The top-level keys a sweep spec and a scene file share."""

    model: str
    description: str
    tangential_memory: str
    tangential: str
    rotation: bool


def parse_header(spec: _Spec, data: dict) -> Header:
    """``model`` (required), ``description``, ``tangential_memory``, ``tangential``, ``rotation``."""
    model = data.get("model")
    if model is None:
        raise spec.error("model", f"missing (one of {', '.join(MODELS)})")
    if model not in MODELS:
        raise spec.bad("model", model, "one of " + ", ".join(map(repr, MODELS)))
    description = data.get("description", "")
    if not isinstance(description, str):
        raise spec.bad("description", description, "a string")
    return Header(model, description,
                  spec.choice(data, "tangential_memory", TANGENTIAL_MEMORY, "incremental"),
                  spec.choice(data, "tangential", TANGENTIAL_EFFECTS, "auto"),
                  spec.flag(data, "rotation", True))


@dataclasses.dataclass(frozen=True)
class Draw:
    """How one random input is drawn: ``kind`` is ``fixed``, ``uniform``,
    ``log_uniform`` or ``choice``; ``values`` the value, the range or the choices."""

    kind: str
    values: tuple[float, ...]

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        if self.kind == "fixed":
            return np.full(n, self.values[0])
        if self.kind == "uniform":
            return rng.uniform(self.values[0], self.values[1], n)
        if self.kind == "log_uniform":
            lo, hi = np.log(self.values[0]), np.log(self.values[1])
            return np.exp(rng.uniform(lo, hi, n))
        return rng.choice(np.asarray(self.values, dtype=float), n)


def _draw(spec: _Spec, key: str, value) -> Draw:
    if _is_number(value):
        return Draw("fixed", (spec.number(key, value),))
    log = None
    if isinstance(value, dict):
        if "choice" in value:
            spec.unknown(value, ("choice",), key)
            choices = value["choice"]
            if not isinstance(choices, list) or not choices:
                raise spec.bad(f"{key}.choice", choices, "a non-empty list of numbers")
            return Draw("choice", tuple(spec.number(f"{key}.choice", c) for c in choices))
        spec.unknown(value, ("range", "log"), key)
        if "range" not in value:
            raise spec.error(key, "a table needs 'range = [lo, hi]' (optional 'log') "
                                  "or 'choice = [...]'")
        log = value.get("log")
        if log is not None and not isinstance(log, bool):
            raise spec.bad(f"{key}.log", log, "true or false")
        key, value = f"{key}.range", value["range"]
    if not (isinstance(value, list) and len(value) == 2):
        raise spec.bad(key, value, "a number, a range [lo, hi], {range = [lo, hi], log = ...} "
                                   "or {choice = [...]}")
    lo, hi = (spec.number(key, x) for x in value)
    if lo > hi:
        raise spec.bad(key, value, "a range [lo, hi] with lo <= hi")
    if log is None:
        log = lo > 0.0 and hi > 10.0 * lo
    if log and lo <= 0.0:
        raise spec.bad(key, value, "a range with lo > 0 for log = true")
    return Draw("log_uniform" if log else "uniform", (lo, hi))


def _axis(spec: _Spec, key: str, value) -> np.ndarray:
    if _is_number(value):
        values = [value]
    elif isinstance(value, list):
        if not value:
            raise spec.bad(key, value, "a non-empty list")
        values = value
    elif isinstance(value, dict):
        spec.unknown(value, ("start", "stop", "per_decade", "num", "log"), key)
        for need in ("start", "stop"):
            if need not in value:
                raise spec.error(key, f"a range table needs '{need}'")
        start = spec.number(f"{key}.start", value["start"])
        stop = spec.number(f"{key}.stop", value["stop"])
        if stop < start:
            raise spec.bad(f"{key}.stop", value["stop"], f">= start = {start!r}")
        if ("per_decade" in value) == ("num" in value):
            raise spec.error(key, "give exactly one of 'per_decade' (log-spaced) or 'num'")
        if "per_decade" in value:
            if "log" in value and value["log"] is not True:
                raise spec.bad(f"{key}.log", value["log"], "true (or absent) with per_decade")
            per = spec.number(f"{key}.per_decade", value["per_decade"], lambda x: x > 0,
                              "a number > 0")
            if start <= 0.0:
                raise spec.bad(f"{key}.start", value["start"], "> 0 for a log-spaced axis")
            num = int(round(math.log10(stop / start) * per)) + 1
            log = True
        else:
            num = spec.integer(f"{key}.num", value["num"], 1)
            log = value.get("log")
            if log is None:
                log = start > 0.0 and stop > 10.0 * start
            elif not isinstance(log, bool):
                raise spec.bad(f"{key}.log", log, "true or false")
            if log and start <= 0.0:
                raise spec.bad(f"{key}.start", value["start"], "> 0 for a log-spaced axis")
        if num > MAX_ROWS:
            raise spec.bad(key, value, f"at most {MAX_ROWS} points")
        if num == 1:
            return np.array([start])
        if log:
            out = np.logspace(math.log10(start), math.log10(stop), num)
            out[0], out[-1] = start, stop  # exact ends
            return out
        return np.linspace(start, stop, num)
    else:
        raise spec.bad(key, value, "a number, a list of numbers or a range table "
                                   "{start, stop, per_decade | num}")
    return np.array([spec.number(key, x) for x in values], dtype=float)


@dataclasses.dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep specification (see the module docstring for the format).

    Attributes
    ----------
    path : the spec file
    text : its text (stored in the table's metadata)
    model : one of ``vimpact.MODELS``
    mode : ``"random"`` or ``"grid"``
    seed : seed of ``numpy.random.default_rng`` (recorded also for a grid)
    chunk_size : rows per chunk (one part file, one parallel batch)
    output : default output path (resolved against the spec's directory)
    numerics : the discretization of every impact
    tangential_memory : ``"incremental"`` or ``"seed"``
    description : free text
    rows : number of parameter sets
    draws : random mode: input name -> :class:`Draw`, in drawing order
    arms : random mode, Prony series: one ``{"G_Pa": Draw, "tau_s": Draw}`` per arm
    axes : grid mode: axis name -> values, outermost first
    tangential : ``"auto"``, ``"stick"`` or ``"none"`` (:class:`vimpact.Scene`)
    rotation : the sphere may spin
    """

    path: Path
    text: str
    model: str
    mode: str
    seed: int
    chunk_size: int
    output: Path
    numerics: Numerics
    tangential_memory: str
    description: str
    rows: int
    draws: dict = dataclasses.field(default_factory=dict)
    arms: tuple = ()
    axes: dict = dataclasses.field(default_factory=dict)
    tangential: str = "auto"
    rotation: bool = True

    @property
    def n_chunks(self) -> int:
        return -(-self.rows // self.chunk_size)

    @property
    def sweep_hash(self) -> str:
        """SHA-256 of the spec text, the resolved numerics and the package version:
        parts of a run can be resumed only by a run with the same hash."""
        h = hashlib.sha256()
        for piece in (self.text, json.dumps(dataclasses.asdict(self.numerics), sort_keys=True),
                      __version__, str(SCHEMA_VERSION)):
            h.update(piece.encode())
            h.update(b"\0")
        return h.hexdigest()

    # ---- parameter sets ---------------------------------------------------
    def parameters(self) -> dict[str, np.ndarray]:
        """All parameter sets, one array per input, generated from the seed.

        Random mode: the drawn physical inputs (each key drawn for all rows
        in a fixed order: material, sphere, ``nu``, ``theta_ratio``, arms).
        Grid mode: the axes expanded to their product (``Q1`` fastest).
        """
        if self.mode == "grid":
            names = list(self.axes)
            mesh = np.meshgrid(*(self.axes[k] for k in names), indexing="ij")
            return {k: m.ravel().copy() for k, m in zip(names, mesh)}
        rng = np.random.default_rng(self.seed)
        out = {key: draw.sample(rng, self.rows) for key, draw in self.draws.items()}
        for i, arm in enumerate(self.arms, start=1):
            out[f"G_arm{i}_Pa"] = arm["G_Pa"].sample(rng, self.rows)
            out[f"tau_arm{i}_s"] = arm["tau_s"].sample(rng, self.rows)
        return out

    def scene(self, params: dict, i: int) -> Scene:
        """The scene of row ``i`` of ``params`` (:meth:`parameters`); raises
        ``ValueError`` for an invalid combination."""
        p = {k: float(v[i]) for k, v in params.items()}
        if self.mode == "grid":
            Q1 = p.get("Q1", 0.0)
            scene = Scene.from_dimensionless(Q1, p["nu"], p.get("Q2"),
                                             theta_ratio=p["theta_ratio"],
                                             tangential_memory=self.tangential_memory,
                                             tangential=self.tangential, rotation=self.rotation)
            if self.model == "elastic":
                scene = dataclasses.replace(
                    scene, material=Material.elastic(nu=p["nu"], G=scene.material.G_inf))
            return dataclasses.replace(scene, allow_large_contact=True)
        nu = p["nu"]
        if self.model == "standard_solid":
            mat = Material.standard_solid(nu=nu, G1=p["G1_Pa"], G2=p["G2_Pa"], eta=p["eta_Pa_s"])
        elif self.model == "prony":
            arms = [(p[f"G_arm{k}_Pa"], p[f"tau_arm{k}_s"]) for k in range(1, len(self.arms) + 1)]
            mat = Material.prony(nu=nu, G_inf=p["G_Pa"], arms=arms, eta0=p["eta_Pa_s"])
        else:
            G, E = p.get("G_Pa"), p.get("E_Pa")
            if self.model == "kelvin_voigt":
                mat = Material.kelvin_voigt(nu=nu, eta=p["eta_Pa_s"], G=G, E=E)
            else:
                mat = Material.elastic(nu=nu, G=G, E=E)
        R, m = p["R_m"], p["m_kg"]
        return Scene(mat, R=R, m=m, v_z0=p["v_z0_m_s"], v_x0=p["v_x0_m_s"],
                     omega0=p["omega0_rad_s"], Theta=p["theta_ratio"] * m * R**2,
                     tangential_memory=self.tangential_memory, allow_large_contact=True,
                     tangential=self.tangential, rotation=self.rotation)

    # ---- table layout -------------------------------------------------------
    def input_columns(self) -> list[str]:
        """Physical input columns of the table, in order."""
        if self.mode == "grid":
            material = {"elastic": ["G_Pa"], "kelvin_voigt": ["G_Pa", "eta_Pa_s"],
                        "standard_solid": ["G1_Pa", "G2_Pa", "eta_Pa_s"]}[self.model]
        elif self.model in ("elastic", "kelvin_voigt"):
            material = [k for k in ("E_Pa", "G_Pa", "eta_Pa_s") if k in self.draws or k == "G_Pa"]
        else:
            material = [k for k in _MATERIAL_KEYS[self.model]]
            for i in range(1, len(self.arms) + 1):
                material += [f"G_arm{i}_Pa", f"tau_arm{i}_s"]
        return material + list(_SPHERE_KEYS)

    def columns(self) -> list[str]:
        """All columns of the table, in order."""
        dimensionless = ["nu", "theta_ratio"] if self.model == "prony" else \
            ["Q1", "Q2", "nu", "theta_ratio"]
        return (["row"] + self.input_columns() + dimensionless + list(_OUTPUTS)
                + ["path", "status", "error"])

    def units(self) -> dict[str, str]:
        """Unit of every column (``"1"`` dimensionless, ``""`` for labels)."""
        return {c: _unit(c) for c in self.columns()}

    def schema(self) -> pa.Schema:
        fields = []
        for c in self.columns():
            kind = pa.int64() if c == "row" else pa.string() if c in _LABELS else pa.float64()
            fields.append(pa.field(c, kind, nullable=(c in ("path", "error"))))
        return pa.schema(fields)

    def metadata(self) -> dict[str, str]:
        """Key-value metadata of the final table (without the ``vimpact.`` prefix)."""
        return {
            "schema_version": str(SCHEMA_VERSION),
            "version": __version__,
            "model": self.model,
            "mode": self.mode,
            "seed": str(self.seed),
            "rows": str(self.rows),
            "numerics": json.dumps(dataclasses.asdict(self.numerics)),
            "tangential_memory": self.tangential_memory,
            "tangential": self.tangential,
            "rotation": json.dumps(self.rotation),
            "units": json.dumps(self.units()),
            "columns": json.dumps({c: _describe(c) for c in self.columns()}),
            "statuses": json.dumps(SWEEP_STATUSES),
            "description": self.description,
            "spec": self.text,
            "spec_name": self.path.name,
            "sweep_hash": self.sweep_hash,
        }


def _unit(column: str) -> str:
    if column in COLUMNS:
        return COLUMNS[column][0]
    return "Pa" if column.endswith("_Pa") else "s"  # G_armK_Pa, tau_armK_s


def _describe(column: str) -> str:
    if column in COLUMNS:
        return COLUMNS[column][1]
    k = column.split("_arm")[1].split("_")[0]
    return f"Prony arm {k}: " + ("modulus G_i" if column.startswith("G_") else
                                 "relaxation time tau_i")


def load_spec(path) -> SweepSpec:
    """Read and validate a sweep specification (TOML).

    Raises ``ValueError`` naming the file and the key for a missing file,
    bad TOML, unknown keys and bad values.
    """
    path = Path(path)
    text, data = read_toml(path, "sweep specification")
    spec = _Spec(path)
    spec.unknown(data, _TOP_KEYS)
    header = parse_header(spec, data)
    model = header.model
    chunk_size = spec.integer("chunk_size", data.get("chunk_size", DEFAULT_CHUNK_SIZE), 1)
    output = data.get("output", path.with_suffix(".parquet").name)
    if not isinstance(output, str) or not output.strip():
        raise spec.bad("output", output, "a path (relative to the spec's directory)")
    output = (path.parent / output) if not Path(output).is_absolute() else Path(output)
    numerics = _numerics(spec, data.get("numerics", {}))

    if ("random" in data) == ("grid" in data):
        raise spec.error("random/grid", "give exactly one of the tables [random] or [grid]")
    if "random" in data:
        mode = "random"
        if "seed" not in data:
            raise spec.error("seed", "missing: random draws need a seed (an integer >= 0)")
        seed = spec.integer("seed", data["seed"], 0)
        draws, arms, rows = _random(spec, model, data["random"])
        axes = {}
    else:
        mode = "grid"
        seed = spec.integer("seed", data.get("seed", 0), 0)
        axes = _grid(spec, model, data["grid"])
        rows = int(np.prod([len(v) for v in axes.values()]))
        if rows > MAX_ROWS:
            raise spec.error("grid", f"{rows} rows; at most {MAX_ROWS} are allowed")
        draws, arms = {}, ()
    return SweepSpec(path=path, text=text, model=model, mode=mode, seed=seed,
                     chunk_size=chunk_size, output=output, numerics=numerics,
                     tangential_memory=header.tangential_memory,
                     description=header.description, rows=rows, draws=draws, arms=arms,
                     axes=axes, tangential=header.tangential, rotation=header.rotation)


def _numerics(spec: _Spec, table) -> Numerics:
    if isinstance(table, str):
        table = {"preset": table}
    if not isinstance(table, dict):
        raise spec.bad("numerics", table, "a table (or a preset name)")
    spec.unknown(table, _NUMERICS_KEYS, "numerics")
    preset = table.get("preset", "default")
    if preset not in PRESETS:
        raise spec.bad("numerics.preset", preset, "one of " + ", ".join(map(repr, PRESETS)))
    numerics = PRESETS[preset]
    for key, value in table.items():
        if key == "preset":
            continue
        try:
            numerics = numerics.with_(**{key: value})
        except ValueError as exc:
            raise ValueError(f"{spec.path}: numerics.{exc}") from None
    return numerics


def _random(spec: _Spec, model: str, table) -> tuple[dict, tuple, int]:
    if not isinstance(table, dict):
        raise spec.bad("random", table, "a table")
    material = _MATERIAL_KEYS[model]
    allowed = ("rows",) + material + _SPHERE_KEYS + ("nu", "theta_ratio") + \
        (("arms",) if model == "prony" else ())
    spec.unknown(table, allowed, "random")
    if "rows" not in table:
        raise spec.error("random.rows", "missing: the number of parameter sets to draw")
    rows = spec.integer("random.rows", table["rows"], 1)
    if rows > MAX_ROWS:
        raise spec.bad("random.rows", rows, f"at most {MAX_ROWS}")
    if model in ("elastic", "kelvin_voigt"):
        if ("E_Pa" in table) == ("G_Pa" in table):
            raise spec.error("random.E_Pa/G_Pa", "give exactly one of E_Pa or G_Pa")
    required = [k for k in material if k not in ("E_Pa", "G_Pa")] + ["R_m", "m_kg", "v_z0_m_s",
                                                                      "nu"]
    if model == "prony":
        required = ["G_Pa", "R_m", "m_kg", "v_z0_m_s", "nu"]
    for key in required:
        if key not in table:
            raise spec.error(f"random.{key}", "missing")
    draws = {}
    for key in material + _SPHERE_KEYS + ("nu", "theta_ratio"):
        if key in table:
            draws[key] = _draw(spec, f"random.{key}", table[key])
        elif key in _RANDOM_DEFAULTS or key == "eta_Pa_s":
            draws[key] = Draw("fixed", (_RANDOM_DEFAULTS.get(key, 0.0),))
    arms = ()
    if model == "prony":
        listed = table.get("arms", [])
        if not isinstance(listed, list) or not all(isinstance(a, dict) for a in listed):
            raise spec.bad("random.arms", listed, "a list of tables [[random.arms]]")
        parsed = []
        for i, arm in enumerate(listed, start=1):
            where = f"random.arms[{i}]"
            spec.unknown(arm, _ARM_KEYS, where)
            for key in _ARM_KEYS:
                if key not in arm:
                    raise spec.error(f"{where}.{key}", "missing")
            parsed.append({k: _draw(spec, f"{where}.{k}", arm[k]) for k in _ARM_KEYS})
        arms = tuple(parsed)
    return draws, arms, rows


def _grid(spec: _Spec, model: str, table) -> dict[str, np.ndarray]:
    if model not in _GRID_KEYS:
        raise spec.error("grid", f"model {model!r} has no dimensionless grid; use [random]")
    if not isinstance(table, dict):
        raise spec.bad("grid", table, "a table")
    keys = _GRID_KEYS[model]
    spec.unknown(table, keys, "grid")
    axes = {}
    for key in keys:
        if key not in table:
            if key == "theta_ratio":
                axes[key] = np.array([0.4])
                continue
            raise spec.error(f"grid.{key}", "missing")
        values = _axis(spec, f"grid.{key}", table[key])
        check, allowed = _GRID_CHECKS[key]
        for x in values:
            if not (math.isfinite(x) and check(x)):
                raise spec.bad(f"grid.{key}", float(x), allowed)
        axes[key] = values
    return axes


# ---- running ----------------------------------------------------------------

def _interleave(n: int, threads: int) -> np.ndarray:
    """An order that hands every thread of a static ``prange`` split a mix of the
    chunk's rows (neighbouring grid rows cost alike)."""
    return np.concatenate([np.arange(k, n, threads) for k in range(threads)])


def _threads() -> int:
    return max(1, numba.get_num_threads())


def compute_chunk(spec: SweepSpec, params: dict, start: int, stop: int) -> pa.Table:
    """Simulate rows ``start:stop`` of ``params`` and return them as a table.

    No row raises: an invalid scene gets status ``invalid``, a failing
    simulation ``failed``, each with NaN outputs and a message in ``error``.
    """
    n = stop - start
    cols: dict[str, np.ndarray | list] = {"row": np.arange(start, stop, dtype=np.int64)}
    for c in spec.columns():
        if c not in ("row",) + _LABELS:
            cols[c] = np.full(n, np.nan)
    status: list[str] = ["invalid"] * n
    error: list[str | None] = [None] * n
    path: list[str | None] = [None] * n

    scenes, index = [], []
    for k in range(n):
        try:
            scene = spec.scene(params, start + k)
        except ValueError as exc:
            error[k] = str(exc)
            continue
        scenes.append(scene)
        index.append(k)

    # inputs as given
    for key, values in params.items():
        if key in cols:
            cols[key][:] = values[start:stop]
    if spec.mode == "random" and "E_Pa" in params:
        cols["G_Pa"][:] = shear_modulus(params["E_Pa"][start:stop], params["nu"][start:stop])

    results = _simulate(scenes, spec.numerics)
    vc0_zero = np.zeros(n, dtype=bool)
    for (k, scene), (res, message) in zip(zip(index, scenes), results):
        vc0_zero[k] = scene.v_c0 == 0.0
        mat = scene.material
        if spec.mode == "grid":  # the physical inputs of the reference scene
            physical = {"R_m": scene.R, "m_kg": scene.m, "v_z0_m_s": scene.v_z0,
                        "v_x0_m_s": scene.v_x0, "omega0_rad_s": scene.omega0}
            if spec.model == "standard_solid":
                physical.update(G1_Pa=mat.G_inf, G2_Pa=mat.G_inf / params["Q2"][start + k],
                                eta_Pa_s=mat.G_inf * mat.viscous_time())
            else:
                physical["G_Pa"] = mat.G_inf
                if spec.model == "kelvin_voigt":
                    physical["eta_Pa_s"] = mat.eta0
            for key, value in physical.items():
                cols[key][k] = value
        if spec.model != "prony":
            if spec.mode == "random" or spec.model == "elastic":
                cols["Q1"][k] = scene.Q1
            if spec.model != "standard_solid":
                cols["Q2"][k] = 0.0  # the Kelvin-Voigt limit G2 -> inf
            elif spec.mode == "random":
                cols["Q2"][k] = scene.Q2
        if res is None:
            status[k], error[k] = "failed", message
            continue
        status[k], path[k] = res["status"], res["path"]
        for name, source in _RESULTS.items():
            cols[name][k] = res[source]
        for name, (num, den) in _RELATIVE.items():
            cols[name][k] = cols[num][k] / cols[den][k]

    _guard_nan(cols, status, error, vc0_zero)
    labels = {"path": path, "status": status, "error": error}
    arrays = [pa.array(labels[c] if c in labels else cols[c], type=f.type)
              for c, f in zip(spec.columns(), spec.schema())]
    return pa.Table.from_arrays(arrays, schema=spec.schema())


def _simulate(scenes: list[Scene], numerics: Numerics) -> list[tuple[dict | None, str | None]]:
    """Results (as dicts) of ``scenes`` in one parallel batch; if the batch raises,
    each scene alone, so that one bad scene cannot stop the others."""
    if not scenes:
        return []
    order = _interleave(len(scenes), _threads())
    try:
        df = simulate_batch([scenes[i] for i in order], numerics)
    except Exception:  # noqa: BLE001 - isolate the failing row below
        out = []
        for scene in scenes:
            try:
                out.append((simulate_batch([scene], numerics).iloc[0].to_dict(), None))
            except Exception as exc:  # noqa: BLE001 - recorded as the row's status
                out.append((None, f"{type(exc).__name__}: {exc}"))
        return out
    records = df.to_dict("records")
    out: list = [None] * len(scenes)
    for pos, i in enumerate(order):
        out[i] = (records[pos], None)
    return out


def _guard_nan(cols: dict, status: list, error: list, vc0_zero: np.ndarray) -> None:
    """NaN only with a status that explains it: a NaN that no status explains
    turns its row into ``non_finite`` (all outputs NaN) with a message."""
    for k, st in enumerate(status):
        if st not in FINISHED:
            continue
        bad = [c for c, v in cols.items()
               if c not in ("row",) + _LABELS and not isinstance(v, list)
               and np.isnan(v[k])
               and not (c in _TANGENTIAL and vc0_zero[k])]
        if bad:
            status[k] = "non_finite"
            error[k] = f"NaN in {', '.join(bad)} of a row with status {st!r}"
            for c in _OUTPUTS:
                cols[c][k] = np.nan


# ---- files ------------------------------------------------------------------

def _meta(values: dict[str, str]) -> dict[bytes, bytes]:
    return {(META_PREFIX + k).encode(): str(v).encode() for k, v in values.items()}


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # pragma: no cover - not possible on every platform
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


def _write_atomic(table: pa.Table, path: Path) -> None:
    """Write ``table`` to ``path``: a temporary file in the same directory,
    fsync, ``os.replace``, fsync of the directory."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            pq.write_table(table, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    _fsync_dir(path.parent)


def parts_dir(out) -> Path:
    """Directory of the finished chunks of a run writing ``out``."""
    out = Path(out)
    return out.with_name(out.name + ".parts")


def _part_path(parts: Path, chunk: int) -> Path:
    return parts / f"part-{chunk:05d}.parquet"


def _existing_parts(spec: SweepSpec, parts: Path) -> dict[int, Path]:
    """Finished chunks in ``parts``; refuses parts of another sweep."""
    found = {}
    for tmp in parts.glob(".*.tmp"):  # a write cut short (kill -9)
        tmp.unlink()
    for path in sorted(parts.glob("part-*.parquet")):
        try:
            meta = pq.read_schema(path).metadata or {}
        except Exception:  # noqa: BLE001 - an unreadable part is computed again
            print(f"vimpact sweep: {path} is unreadable; computing it again", file=sys.stderr)
            path.unlink()
            continue
        got = meta.get((META_PREFIX + "sweep_hash").encode(), b"").decode()
        if got != spec.sweep_hash:
            raise ValueError(
                f"{path} belongs to another sweep (a different spec, numerics or vimpact "
                f"version: hash {got[:12] or 'missing'} != {spec.sweep_hash[:12]}); "
                f"remove {parts} to start over")
        chunk = int(meta[(META_PREFIX + "chunk").encode()])
        if path != _part_path(parts, chunk) or chunk >= spec.n_chunks:
            raise ValueError(f"{path} does not fit this sweep (chunk {chunk}); "
                             f"remove {parts} to start over")
        found[chunk] = path
    return found


def run_sweep(spec_path, out=None, resume: bool = False,
              progress: Callable[[int, int], None] | None | bool = None) -> Path:
    """Run the sweep of a TOML specification and write its Parquet table.

    Parameters
    ----------
    spec_path : the specification (format: module docstring)
    out : output path (relative to the current directory); default the spec's
        ``output`` (relative to the spec's directory)
    resume : continue an interrupted run: compute only the chunks missing in
        ``<out>.parts/``. Without it, existing parts are an error.
    progress : ``None`` (default) shows a tqdm bar with rate and ETA on a
        terminal (quiet when stderr is not a TTY or ``CI`` is set); a callable
        is called as ``progress(rows_done, rows_total)`` after every chunk
        written instead; ``False`` shows nothing.

    Returns
    -------
    The path of the table.

    Raises
    ------
    ValueError
        for a bad spec, parts of another run, or parts without ``resume``.
    SweepInterrupted
        (a ``KeyboardInterrupt``) on Ctrl-C: finished chunks stay in
        ``<out>.parts/``; the message says how to resume.
    """
    spec = load_spec(spec_path)
    out = Path(out) if out is not None else spec.output
    parts = parts_dir(out)
    for stale in out.parent.glob(f".{out.name}.*.tmp"):  # a final write cut short
        stale.unlink()
    done: dict[int, Path] = {}
    if parts.exists():
        if not parts.is_dir():
            raise ValueError(f"{parts} is in the way: it should be the directory of the "
                             "finished chunks; remove it")
        done = _existing_parts(spec, parts)
        if done and not resume:
            raise ValueError(
                f"{parts} holds {len(done)} finished chunk(s) of an earlier run: use --resume "
                f"(resume=True) to continue it, or remove {parts} to start over")
    elif resume and out.exists() and _is_complete(spec, out):
        return out
    parts.mkdir(parents=True, exist_ok=True)

    params = spec.parameters()
    todo = [c for c in range(spec.n_chunks) if c not in done]
    total = spec.rows
    rows_done = sum(_chunk_rows(spec, c) for c in done)
    bar = _bar(spec, total, rows_done) if progress is None else None
    try:
        for chunk in todo:
            start, stop = chunk * spec.chunk_size, min(total, (chunk + 1) * spec.chunk_size)
            table = compute_chunk(spec, params, start, stop)
            meta = {**spec.metadata(), "chunk": str(chunk), "row_start": str(start),
                    "row_stop": str(stop), "n_chunks": str(spec.n_chunks)}
            _write_atomic(table.replace_schema_metadata(_meta(meta)), _part_path(parts, chunk))
            done[chunk] = _part_path(parts, chunk)
            rows_done += stop - start
            if bar is not None:
                bar.update(stop - start)
            elif callable(progress):
                progress(rows_done, total)
        if bar is not None:
            bar.close()
            bar = None
        _combine(spec, parts, out)
    except KeyboardInterrupt:
        if bar is not None:
            bar.close()
        hint = f"vimpact sweep {spec_path}" + (f" --out {out}" if out != spec.output else "")
        raise SweepInterrupted(
            f"interrupted: {len(done)} of {spec.n_chunks} chunks are saved in {parts}; "
            f"resume with: {hint} --resume", parts, len(done), spec.n_chunks) from None
    return out


def _chunk_rows(spec: SweepSpec, chunk: int) -> int:
    return min(spec.rows, (chunk + 1) * spec.chunk_size) - chunk * spec.chunk_size


def _is_complete(spec: SweepSpec, out: Path) -> bool:
    try:
        meta = pq.read_schema(out).metadata or {}
    except Exception:  # noqa: BLE001
        return False
    return meta.get((META_PREFIX + "sweep_hash").encode(), b"").decode() == spec.sweep_hash


def _combine(spec: SweepSpec, parts: Path, out: Path) -> None:
    tables = [pq.read_table(_part_path(parts, c)) for c in range(spec.n_chunks)]
    table = pa.concat_tables([t.replace_schema_metadata(None) for t in tables])
    rows = table.column("row").to_numpy()
    if len(rows) != spec.rows or not np.array_equal(rows, np.arange(spec.rows)):
        raise ValueError(f"{parts}: the parts do not add up to rows 0..{spec.rows - 1}; "
                         f"remove {parts} to start over")
    out.parent.mkdir(parents=True, exist_ok=True)
    meta = {**spec.metadata(), "paths": json.dumps(_paths_explained(spec, table))}
    _write_atomic(table.replace_schema_metadata(_meta(meta)), out)
    shutil.rmtree(parts)


def _paths_explained(spec: SweepSpec, table: pa.Table) -> dict:
    """Each kernel path of the table: its row count and why it ran (from its first row)."""
    names = table.column("path").to_pylist()
    params = spec.parameters()
    out: dict = {}
    for i, name in enumerate(names):
        if name is None:
            continue
        if name not in out:
            reasons = choose_path(spec.scene(params, i), spec.numerics).reasons
            out[name] = {"rows": 0, "first_row": i, "reasons": list(reasons)}
        out[name]["rows"] += 1
    return out


def _bar(spec: SweepSpec, total: int, initial: int):
    quiet = not sys.stderr.isatty() or bool(os.environ.get("CI"))
    if quiet:
        return None
    from tqdm import tqdm
    try:
        sized = os.get_terminal_size(sys.stderr.fileno()).columns > 0
    except (OSError, ValueError, AttributeError):
        sized = False
    # a terminal that reports no size (0 x 0) would get no bar at all
    return tqdm(total=total, initial=initial, unit="row", desc=spec.path.stem,
                file=sys.stderr, dynamic_ncols=sized, ncols=None if sized else 100,
                nrows=None if sized else 24, smoothing=0.1)


def read_metadata(path) -> dict:
    """The sweep metadata of a table (or part) at ``path``, keys without the
    ``vimpact.`` prefix; ``numerics``, ``units``, ``columns``, ``statuses``,
    ``paths`` (kernel path -> rows and reasons) and ``rotation`` decoded from JSON, ``schema_version``, ``seed`` and ``rows`` as ints."""
    raw = pq.read_schema(path).metadata or {}
    meta = {k.decode()[len(META_PREFIX):]: v.decode() for k, v in raw.items()
            if k.decode().startswith(META_PREFIX)}
    for key in ("numerics", "units", "columns", "statuses", "paths", "rotation"):
        if key in meta:
            meta[key] = json.loads(meta[key])
    for key in ("schema_version", "seed", "rows", "chunk", "row_start", "row_stop", "n_chunks"):
        if key in meta:
            meta[key] = int(meta[key])
    return meta


def summary(path) -> dict[str, int]:
    """Number of rows per status in the table at ``path``."""
    status = pq.read_table(path, columns=["status"]).column("status").to_pylist()
    counts: dict[str, int] = {}
    for s in status:
        counts[s] = counts.get(s, 0) + 1
    return counts


__all__ = ["COLUMNS", "Draw", "SCHEMA_VERSION", "SWEEP_STATUSES", "SweepInterrupted",
           "SweepSpec", "compute_chunk", "load_spec", "parts_dir", "read_metadata",
           "run_sweep", "summary"]
