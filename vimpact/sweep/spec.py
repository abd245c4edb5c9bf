"""Sweep specifications: a TOML file -> a validated :class:`SweepSpec`.

A specification (``sweeps/*.toml``, read with :mod:`tomllib`) describes one
table. Example (a Kelvin-Voigt lookup table on a grid of dimensionless
parameters)::

    description = "Kelvin-Voigt restitution table"
    model = "kelvin_voigt"        # elastic | kelvin_voigt | standard_solid | prony
    seed = 1                      # root of the random draws; required for [random]
    chunk_size = 128              # rows per chunk: one part file, one parallel batch, one task
    output = "tables/kv.parquet"      # relative to THIS FILE's directory
    layout = "auto"               # file | dataset | auto (file up to 1e6 rows)
    tangential_memory = "incremental" # or "seed" (thesis eq. 4.16)

    [numerics]                    # optional; default: preset "default"
    preset = "default"            # default | fast | precise | thesis
    steps = 1000                  # overrides: any field of vimpact.Numerics
    [grid]
    Q1 = { start = 1e-3, stop = 100, per_decade = 10 }
    nu = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]

Top-level keys: ``model`` (required), ``description``, ``seed``,
``chunk_size`` (at most :data:`MAX_CHUNK_SIZE` rows, and at most
:data:`MAX_CHUNKS` chunks per sweep; default below), ``output`` (default: the spec's name with
``.parquet`` beside it), ``layout``, ``tangential_memory``, ``tangential``,
``rotation``, ``numerics`` (a table, or a preset name as a string) and exactly
one of ``[random]`` or ``[grid]``. Unknown keys and bad values are errors
(``ValueError``) that name the file and the key. The key rules shared with
scene files live in :mod:`vimpact.model.toml_input`.

``[grid]``: parameter sets on a grid of the dimensionless parameters, simulated
on the reference scene of :meth:`vimpact.Scene.from_dimensionless` (the grid is
the product of all axes; ``Q1`` runs fastest, then ``Q2``, ``nu``,
``theta_ratio``, ``psi``). Keys: ``tolerance`` (optional, not an axis: the
interpolation error the grid should meet between its nodes, a number in [1e-9,
1e-1]; stored as :attr:`SweepSpec.grid_tolerance` and in the metadata as
``grid_tolerance``, for a refinement of the grid to read), ``Q1``
(kelvin_voigt, standard_solid; >= 0), ``Q2`` (standard_solid; > 0), ``nu``
(required; in [0, 0.5]), ``theta_ratio`` (Theta / (m R^2), default 0.4),
``lam`` (optional, >= 0, not with ``psi``: the adhesion number
``sqrt(2 pi a_H dgamma / E*) / d`` of docs/physics.md#adhesion; a row is the
reference scene with ``v_x0 = 0`` and the work of adhesion that gives it this
number; the outermost axis), ``psi`` (optional, >= 0: the incidence ``2 (1 - nu) / (mu (2 - nu)) v_c0 /
v_z0`` of docs/physics.md#coulomb-friction) with ``mu`` (not an axis: the
friction coefficient, a number > 0, default 1; only with ``psi``). With
friction the results depend on ``psi`` (with ``nu`` and ``theta_ratio``) and
not on ``mu`` and ``v_c0`` apart, so a row with ``psi > 0`` is the reference
scene with this ``mu`` and ``v_x0 = psi mu (2 - nu) / (2 (1 - nu)) v_z0``; a
row with ``psi = 0`` is the full-stick limit (``mu = inf``, ``v_x0 = v_z0``),
the row of the same grid without ``psi``. Without ``psi`` the grid is full
stick and has no ``mu`` and ``psi`` columns. ``psi_nodes = [n_stick, n_slip]``
(``refine = "adaptive"``, kelvin_voigt, no ``psi`` axis) makes the spec a friction
table's: ``vimpact table build`` places its ``psi`` nodes on the kinks of
``beta_x(psi)`` (:mod:`vimpact.tablebuild.friction`). An axis is a number, a list of
numbers, or a table ``{ start, stop, per_decade }`` (log-spaced, both ends
included) or ``{ start, stop, num, log = true|false }`` (``num`` points;
``log`` defaults to the rule below). With ``per_decade`` the number of
intervals is ``round(per_decade * log10(stop / start))``, so both ends are
exact. An elastic grid has ``nu``, ``theta_ratio`` (and ``psi``) only (``Q1 = 0``); a
Prony series has no dimensionless grid.

``[random]``: physical parameter sets drawn at random, as the thesis does to
show that results collapse onto ``Q1`` (and ``Q2``). ``rows`` (required) is
the number of draws; every other key is a physical input named like its
column, with its unit as suffix:

- all models: ``nu``, ``R_m``, ``m_kg``, ``v_z0_m_s`` (required),
  ``v_x0_m_s`` (default 0), ``omega0_rad_s`` (default 0), ``theta_ratio``
  (default 0.4)
- friction, all models: ``mu`` (Coulomb friction coefficient, >= 0; default
  ``inf``, full stick; a fixed value or a choice may be ``inf`` or ``"inf"``)
  and ``angle_deg`` (impact angle from the normal, degrees, in [0, 90):
  ``v_x0 = v_z0 tan(angle)``, instead of ``v_x0_m_s``, never both). A spec
  with ``mu`` has the columns ``mu`` and ``psi`` (the incidence of its row: 0
  for ``mu = inf`` or ``v_c0 = 0``, ``inf`` for ``mu = 0``); one with
  ``angle_deg`` the column ``angle_deg`` beside ``v_x0_m_s``
- elastic: ``E_Pa`` or ``G_Pa``; kelvin_voigt: ``E_Pa`` or ``G_Pa``, and
  ``eta_Pa_s``; standard_solid: ``G1_Pa``, ``G2_Pa``, ``eta_Pa_s``;
  prony: ``G_Pa`` (relaxed modulus), ``eta_Pa_s`` (parallel dashpot,
  default 0) and one ``[[random.arms]]`` table per Maxwell arm with
  ``G_Pa`` and ``tau_s``
- adhesion, all models: ``adhesion_J_m2`` (work of adhesion, J/m^2, >= 0; drawn
  after every other key, so a spec without it draws as before). A row with
  ``v_c0 != 0`` and a tangential problem is ``invalid`` (the adhesive impact is
  normal only: give ``tangential = "none"``)
- or, instead of the material keys and ``nu``, a material file
  (:mod:`vimpact.model.material_file`, e.g. written by ``vimpact material
  fit``): ``material = "rubber.toml"`` (relative to the spec's directory) and
  optionally ``temperature_K`` (kelvin; the file's shift law moves its times
  there). Its values are fixed for every row; ``model`` may be left out

Each value is a number (fixed), a range ``[lo, hi]`` or
``{ range = [lo, hi], log = true|false }``, or ``{ choice = [a, b, ...] }``
(one of the values, equally likely). A range is drawn **log-uniformly when
``lo > 0`` and ``hi / lo > 10``** (it spans more than a decade), uniformly
otherwise; ``log`` overrides that (``log = true`` needs ``lo > 0``).
Draws are not checked against the physics: a drawn combination that is not a
valid scene becomes a row with status ``invalid`` and the reason in the
``error`` column.

Chunk size when the spec sets none: a grid's rows do not depend on the chunking, so
the runner chooses it from the measured cost of the rows
(:func:`vimpact.sweep.runner.choose_chunk_size`: about :data:`AUTO_CHUNK_SECONDS` of
work per chunk, :data:`AUTO_CHUNK_ROWS` rows at least and at most, one chunk for a
sweep of at most :data:`ONE_CHUNK_SECONDS` of work), once per sweep,
before the first chunk, and records it in the parts directory
(:data:`CHUNK_SIZE_FILE`) so that ``--resume``, shards and ``--combine`` use the same
chunks; the table's metadata ``chunk_size`` holds it. Random draws are made per chunk
(below), so a random spec without ``chunk_size`` keeps :data:`DEFAULT_CHUNK_SIZE` (64)
and its rows stay those of earlier versions; set ``chunk_size`` (e.g. 10000) for a
faster random sweep, knowing it draws other rows.

Random draws per chunk (schema version 3): the rows of chunk ``c`` are drawn
from ``numpy.random.default_rng(SeedSequence(seed, spawn_key=(c,)))``, each key
for all rows of the chunk in a fixed order (material, sphere, ``nu``,
``theta_ratio``, arms), so any chunk can be computed anywhere and in any order
with the same rows (:mod:`vimpact.sweep.parameters`); ``mu`` and ``angle_deg``
are drawn after ``theta_ratio`` (a fixed value draws nothing, so a spec without
them draws as before). The draws therefore depend on ``seed`` and
``chunk_size``; tables of schema version 2 drew all rows from one
``default_rng(seed)`` and have other draws.

Columns (:data:`vimpact.tableformat.schema.COLUMNS` has the unit and meaning of each; the table's metadata
``units`` and ``columns`` too): ``row``, the physical inputs, ``Q1``, ``Q2``
(``NaN`` on Kelvin-Voigt and elastic grid rows: no ``G2``, the limit
``G2 -> inf``, never ``0``; random rows of these models still get ``0`` from the
runner), ``nu``, ``theta_ratio`` (``psi`` with friction), the outputs
(:data:`OUTPUTS`, in every table, the friction outputs ``mu_eff``,
``rebound_angle_deg``, ``gross_slip_fraction``, ``friction_energy_J``
included: in full stick they are the impulse ratio, the rebound angle, 0 and 0),
then ``path``, ``status``, ``error``. A spec with adhesion (a ``lam`` axis, or
``adhesion_J_m2`` drawn) has the input ``adhesion_J_m2``, the dimensionless
``lam`` and the output ``F_tensile_max_N`` (after the other outputs) too.

Output paths: ``output`` in the spec is relative to the spec file's
directory and stays inside it (no ``..``, not absolute: a spec someone sends
cannot make the sweep write elsewhere); ``out=`` / ``--out`` is relative to the
current directory. The
table layout and the runners are described in :mod:`vimpact.sweep.store` and
:mod:`vimpact.sweep.runner`.

Python API::

    from vimpact.sweep import load_spec
    spec = load_spec("sweeps/kelvin_voigt_table.toml")   # validated SweepSpec
    params = spec.chunk_parameters(0)          # the parameter sets of chunk 0
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from pathlib import Path

import numpy as np

from vimpact import __version__
from vimpact.model.material_file import inline_material
from vimpact.model.numerics import Numerics
from vimpact.model.scene import DEFAULT_THETA_RATIO, Scene
from vimpact.model.toml_input import (
    ANGLE_RANGE_DEG,
    ARM_KEYS,
    FRICTION_KEYS,
    MATERIAL_KEYS,
    PHYSICAL_DEFAULTS,
    SPHERE_KEYS,
    SWEEP_TOP_KEYS,
    TomlSource,
    friction_coefficient,
    input_keys,
    is_number,
    parse_header,
    parse_numerics,
    read_toml,
    required_keys,
    scene_from_values,
)
from vimpact.tableformat.schema import (
    ADHESION_OUTPUTS,
    COLUMNS,
    LABELS,
    OUTPUTS,
    SCHEMA_VERSION,
    SWEEP_STATUSES,
)

#: Rows per chunk of a random spec without ``chunk_size`` (its draws are made per chunk),
#: and of a grid spec until the runner has chosen its size.
DEFAULT_CHUNK_SIZE = 64
#: Work per chunk the runner aims at when a grid spec sets no ``chunk_size``, s (a
#: chunk's fixed costs, a parallel launch and a part file, are then a few percent).
AUTO_CHUNK_SECONDS = 1.0
#: Rows per chunk the runner chooses at least and at most (memory: about a kilobyte a row).
AUTO_CHUNK_ROWS = (16, 100_000)
#: Work of a whole sweep, s, up to which the runner makes it one chunk when it chooses
#: (one process, at most ``AUTO_CHUNK_ROWS[1]`` rows): in chunks a file-layout table's rows
#: are written twice, a part and then the table (about 1 us a row, 10-20 % of a
#: Kelvin-Voigt row's kernel time), which would only save this much work on an interrupt.
ONE_CHUNK_SECONDS = 2 * AUTO_CHUNK_SECONDS
#: File in the parts directory that records the chunk size the runner chose (JSON).
CHUNK_SIZE_FILE = "_chunk_size.json"
#: Rows of one sweep at most (a grid axis has at most as many points).
MAX_ROWS = 10**12
#: Chunks (part files) of one sweep at most: the runners list the chunks to do and the
#: parts directory holds one file each; more rows need a larger ``chunk_size``.
MAX_CHUNKS = 10**6
#: Rows of one chunk at most: a chunk is held in memory (its inputs, outputs and the
#: kernels' arrays, about a kilobyte a row).
MAX_CHUNK_SIZE = 10**6
#: Table layouts: one Parquet file, or a partitioned dataset (a directory).
LAYOUTS = ("auto", "file", "dataset")
#: ``layout = "auto"`` writes one file up to this many rows, a dataset above.
FILE_LAYOUT_MAX_ROWS = 1_000_000
#: Allowed ``[grid] tolerance`` (interpolation error between nodes, dimensionless).
GRID_TOLERANCE_RANGE = (1e-9, 1e-1)
#: ``[grid] refine``: how a grid with ``tolerance`` is refined.
GRID_REFINE = ("tensor", "adaptive")
#: ``[grid] min_level`` and ``max_level`` defaults of an adaptive grid, and the largest
#: level allowed (a cell of level L spans 1/2**L of an axis's log range).
ADAPTIVE_LEVELS = (2, 16, 24)
#: Points of one grid axis at most (the axes are held in memory, the grid is not).
MAX_AXIS_POINTS = 10**7


# ---- spec keys -------------------------------------------------------------

_GRID_KEYS = {
    "elastic": ("psi", "theta_ratio", "nu"),
    "kelvin_voigt": ("psi", "theta_ratio", "nu", "Q1"),
    "standard_solid": ("psi", "theta_ratio", "nu", "Q2", "Q1"),
}  # outermost axis first: the last one runs fastest; psi only when given
#: ``[grid] mu`` when a ``psi`` axis is given without it.
DEFAULT_GRID_MU = 1.0
_GRID_CHECKS = {
    "psi": (lambda x: x >= 0.0, "a finite number >= 0"),
    "Q1": (lambda x: x >= 0.0, "a finite number >= 0"),
    "Q2": (lambda x: x > 0.0, "a finite number > 0"),
    "nu": (lambda x: 0.0 <= x <= 0.5, "in [0, 0.5]"),
    "theta_ratio": (lambda x: x > 0.0, "a finite number > 0"),
    "lam": (lambda x: x >= 0.0, "a finite number >= 0"),
}
#: The adhesion axis of a grid (optional, outermost): the adhesion number, on which
#: (with Q1, Q2, nu) the normal impact alone depends (docs/physics.md#adhesion).
ADHESION_AXIS = "lam"
#: The drawn input of a random spec with adhesion, J/m^2.
ADHESION_KEY = "adhesion_J_m2"


@dataclasses.dataclass(frozen=True)
class Draw:
    """How one random input is drawn.

    ``kind`` is ``fixed``, ``uniform``, ``log_uniform`` or ``choice``; ``values`` the
    value, the range or the choices.
    """

    kind: str
    values: tuple[float, ...]

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """Draw ``n`` values with ``rng``."""
        if self.kind == "fixed":
            return np.full(n, self.values[0])
        if self.kind == "uniform":
            return rng.uniform(self.values[0], self.values[1], n)
        if self.kind == "log_uniform":
            lo, hi = np.log(self.values[0]), np.log(self.values[1])
            return np.exp(rng.uniform(lo, hi, n))
        return rng.choice(np.asarray(self.values, dtype=float), n)


def _draw(spec: TomlSource, key: str, value) -> Draw:
    if is_number(value):
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


def _draw_mu(spec: TomlSource, key: str, value) -> Draw:
    """Parse how a friction coefficient is drawn.

    Like :func:`_draw`, every value >= 0; a fixed value or a choice may be ``inf``
    (TOML ``inf`` or ``"inf"``: full stick), a range is finite.
    """
    if isinstance(value, str) or (is_number(value) and math.isinf(value)):
        return Draw("fixed", (friction_coefficient(spec, key, value),))
    if isinstance(value, dict) and "choice" in value and isinstance(value["choice"], list) \
            and value["choice"]:
        spec.unknown(value, ("choice",), key)
        return Draw("choice", tuple(friction_coefficient(spec, f"{key}.choice", c)
                                    for c in value["choice"]))
    draw = _draw(spec, key, value)
    if any(x < 0.0 for x in draw.values):
        raise spec.bad(key, value, 'friction coefficients >= 0 (or "inf")')
    return draw


def _axis(spec: TomlSource, key: str, value) -> np.ndarray:
    if is_number(value):
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
            log: bool | None = True
        else:
            num = spec.integer(f"{key}.num", value["num"], 1)
            log = value.get("log")
            if log is None:
                log = start > 0.0 and stop > 10.0 * start
            elif not isinstance(log, bool):
                raise spec.bad(f"{key}.log", log, "true or false")
            if log and start <= 0.0:
                raise spec.bad(f"{key}.start", value["start"], "> 0 for a log-spaced axis")
        if num > MAX_AXIS_POINTS:
            raise spec.bad(key, value, f"at most {MAX_AXIS_POINTS} points")
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
    seed : root of the per-chunk random draws (recorded also for a grid)
    chunk_size : rows per chunk (one part file, one parallel batch, one task)
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
    layout : ``"auto"``, ``"file"`` or ``"dataset"`` as written (:attr:`table_layout`
        resolves ``"auto"``)
    grid_tolerance : grid mode: ``[grid] tolerance``, the interpolation error the grid
        should meet between its nodes (dimensionless, in [1e-9, 1e-1]; ``None``: not
        asked). Not an axis: a refinement of the grid reads it
    grid_mu : grid mode with a ``psi`` axis: the friction coefficient of the rows with
        ``psi > 0`` (``[grid] mu``, default 1); ``None`` without ``psi``
    material_text : the text of the material file ``[random] material`` names ("" without
        one); part of :attr:`sweep_hash`
    grid_refine : grid mode: ``[grid] refine``, ``"tensor"`` (default: planes of nodes
        inserted across the grid, :func:`vimpact.tablebuild.refine.refine_grid`) or
        ``"adaptive"`` (cells of ``log Q1`` (x ``log Q2``) split where they fail the
        tolerance, :mod:`vimpact.lookup.adaptive`; built by ``vimpact table build``)
    grid_psi_nodes : grid mode, adaptive Kelvin-Voigt: ``[grid] psi_nodes = [n_stick,
        n_slip]``, the incidence nodes of a friction table
        (:func:`vimpact.lookup.friction.coordinate_nodes`; built by ``vimpact table
        build``), or None
    grid_levels : grid mode, adaptive: ``([grid] min_level, [grid] max_level)``, the
        level of the uniform start and of the finest cell (a cell of level ``L`` spans
        ``1 / 2**L`` of each adaptive axis's range in log)
    chunk_size_given : the spec sets ``chunk_size``; if not, a grid's runner chooses it
        (module docstring) and ``chunk_size`` is :data:`DEFAULT_CHUNK_SIZE` until then
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
    layout: str = "auto"
    grid_tolerance: float | None = None
    grid_mu: float | None = None
    material_text: str = ""
    grid_refine: str = "tensor"
    grid_levels: tuple[int, int] = (ADAPTIVE_LEVELS[0], ADAPTIVE_LEVELS[1])
    grid_psi_nodes: tuple[int, int] | None = None
    chunk_size_given: bool = True

    @property
    def chooses_chunk_size(self) -> bool:
        """Whether the runner chooses the chunk size (a grid spec without ``chunk_size``)."""
        return not self.chunk_size_given and self.mode == "grid"

    @property
    def n_chunks(self) -> int:
        """Number of chunks (part files) of the sweep."""
        return -(-self.rows // self.chunk_size)

    @property
    def has_friction(self) -> bool:
        """Whether the spec sets a friction coefficient.

        A grid with a ``psi`` axis, or a random spec with ``mu``; its table has the
        columns ``mu`` and ``psi``.
        """
        return "psi" in self.axes or "mu" in self.draws

    @property
    def has_adhesion(self) -> bool:
        """Whether the spec has adhesion.

        A grid with a ``lam`` axis or a random spec drawing ``adhesion_J_m2``: its table
        has the columns ``adhesion_J_m2``, ``lam`` and ``F_tensile_max_N``.
        """
        return ADHESION_AXIS in self.axes or ADHESION_KEY in self.draws

    @property
    def table_layout(self) -> str:
        """``"file"`` (one Parquet file) or ``"dataset"`` (a directory of part files)."""
        if self.layout != "auto":
            return self.layout
        return "file" if self.rows <= FILE_LAYOUT_MAX_ROWS else "dataset"

    def chunk_rows(self, chunk: int) -> tuple[int, int]:
        """First row and one past the last row of ``chunk``."""
        start = chunk * self.chunk_size
        return start, min(self.rows, start + self.chunk_size)

    @property
    def sweep_hash(self) -> str:
        """SHA-256 of the spec text, the resolved numerics, the package and schema version.

        The material file's text too; parts of a run can be resumed only by a
        run with the same hash.
        """
        h = hashlib.sha256()
        pieces = [self.text, json.dumps(dataclasses.asdict(self.numerics), sort_keys=True),
                  __version__, str(SCHEMA_VERSION)]
        if self.material_text:  # a spec without a material file keeps its hash
            pieces.append(self.material_text)
        for piece in pieces:
            h.update(piece.encode())
            h.update(b"\0")
        return h.hexdigest()

    # ---- parameter sets ---------------------------------------------------
    def chunk_parameters(self, chunk: int, part: tuple[int, int] | None = None
                         ) -> dict[str, np.ndarray]:
        """Return the parameter sets of ``chunk`` (:func:`vimpact.sweep.parameters.chunk_parameters`)."""
        from vimpact.sweep.parameters import chunk_parameters
        return chunk_parameters(self, chunk, part)

    def parameters(self) -> dict[str, np.ndarray]:
        """Return all parameter sets, chunk after chunk.

        Memory grows with ``rows``: for small sweeps and tests; the runners use
        :meth:`chunk_parameters`.
        """
        chunks = [self.chunk_parameters(c) for c in range(self.n_chunks)]
        return {k: np.concatenate([c[k] for c in chunks]) for k in chunks[0]}

    def scene(self, params: dict, i: int) -> Scene:
        """Return the scene of row ``i`` of ``params``.

        One Python object: to explain a row, not to run a sweep; raises
        ``ValueError`` for an invalid combination.
        """
        p = {k: float(v[i]) for k, v in params.items()}
        if self.mode == "grid":
            scene = Scene.from_dimensionless(p.get("Q1", 0.0), p["nu"], p.get("Q2"),
                                             theta_ratio=p["theta_ratio"],
                                             tangential_memory=self.tangential_memory,
                                             tangential=self.tangential, rotation=self.rotation)
            if self.model == "elastic":
                from vimpact.model.material import Material
                scene = dataclasses.replace(
                    scene, material=Material.elastic(nu=p["nu"], G=scene.material.G_inf))
            if ADHESION_AXIS in p:
                from vimpact.engine.adhesion import adhesion_for_number
                scene = dataclasses.replace(scene, v_x0=0.0)  # normal impact
                if p[ADHESION_AXIS] > 0.0:
                    scene = dataclasses.replace(
                        scene, adhesion=adhesion_for_number(scene, p[ADHESION_AXIS]))
            if "psi" in p:
                from vimpact.tableformat.parameters import psi_reference
                assert self.grid_mu is not None  # load_spec sets it with a psi axis
                v_x0, mu = psi_reference(np.array([p["psi"]]), np.array([p["nu"]]),
                                         self.grid_mu, scene.v_z0)
                scene = dataclasses.replace(scene, v_x0=float(v_x0[0]), mu=float(mu[0]))
            return dataclasses.replace(scene, allow_large_contact=True)
        arms = [(p[f"G_arm{k}_Pa"], p[f"tau_arm{k}_s"]) for k in range(1, len(self.arms) + 1)]
        values = {k: v for k, v in p.items() if "_arm" not in k}
        if "angle_deg" in values:
            values.pop("v_x0_m_s", None)  # made from the angle (chunk_parameters)
        adhesion = values.pop(ADHESION_KEY, 0.0)
        scene = scene_from_values(self.model, values, arms,
                                  tangential_memory=self.tangential_memory,
                                  tangential=self.tangential, rotation=self.rotation,
                                  allow_large_contact=True)
        return dataclasses.replace(scene, adhesion=adhesion) if adhesion else scene

    # ---- table layout -------------------------------------------------------
    def input_columns(self) -> list[str]:
        """Physical input columns of the table, in order."""
        if self.mode == "grid":
            material = {"elastic": ["G_Pa"], "kelvin_voigt": ["G_Pa", "eta_Pa_s"],
                        "standard_solid": ["G1_Pa", "G2_Pa", "eta_Pa_s"]}[self.model]
        elif self.model in ("elastic", "kelvin_voigt"):
            material = [k for k in ("E_Pa", "G_Pa", "eta_Pa_s") if k in self.draws or k == "G_Pa"]
        else:
            material = list(MATERIAL_KEYS[self.model])
            for i in range(1, len(self.arms) + 1):
                material += [f"G_arm{i}_Pa", f"tau_arm{i}_s"]
        extra = ["angle_deg"] if "angle_deg" in self.draws else []
        return (material + list(SPHERE_KEYS) + extra + (["mu"] if self.has_friction else [])
                + ([ADHESION_KEY] if self.has_adhesion else []))

    def columns(self) -> list[str]:
        """All columns of the table, in order."""
        dimensionless = ["nu", "theta_ratio"] if self.model == "prony" else \
            ["Q1", "Q2", "nu", "theta_ratio"]
        if self.has_friction:
            dimensionless.append("psi")
        adhesion = list(ADHESION_OUTPUTS) if self.has_adhesion else []
        if self.has_adhesion:
            dimensionless.append(ADHESION_AXIS)
        return (["row"] + self.input_columns() + dimensionless + list(OUTPUTS) + adhesion
                + list(LABELS))

    def units(self) -> dict[str, str]:
        """Return the unit of every column (``"1"`` dimensionless, ``""`` for labels)."""
        return {c: _unit(c) for c in self.columns()}

    def schema(self):
        """Return the ``pyarrow`` schema of the table (``row`` int64, labels string, else float64)."""
        import pyarrow as pa
        fields = []
        for c in self.columns():
            kind = pa.int64() if c == "row" else pa.string() if c in LABELS else pa.float64()
            fields.append(pa.field(c, kind, nullable=(c in ("path", "error"))))
        return pa.schema(fields)

    def metadata(self) -> dict:
        """Return the metadata of the table.

        Keys without the ``vimpact.`` prefix; values as Python objects, encoded by
        :func:`vimpact.tableformat.metadata.encode_metadata`.
        """
        return {
            "schema_version": SCHEMA_VERSION,
            "version": __version__,
            "model": self.model,
            "mode": self.mode,
            "seed": self.seed,
            "rows": self.rows,
            "chunk_size": self.chunk_size,
            "layout": self.table_layout,
            "numerics": dataclasses.asdict(self.numerics),
            "tangential_memory": self.tangential_memory,
            "tangential": self.tangential,
            "rotation": self.rotation,
            "grid_tolerance": self.grid_tolerance,
            **({"grid_refine": self.grid_refine, "grid_levels": list(self.grid_levels)}
               if self.grid_refine != "tensor" else {}),
            **({"grid_psi_nodes": list(self.grid_psi_nodes)} if self.grid_psi_nodes else {}),
            "units": self.units(),
            "columns": {c: _describe(c) for c in self.columns()},
            "statuses": SWEEP_STATUSES,
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
    spec = TomlSource(path)
    spec.unknown(data, SWEEP_TOP_KEYS)
    # [random] material = "FILE.toml" (and temperature_K): the file's values, fixed
    data, material_text = inline_material(str(path), data, "random", path.parent)
    header = parse_header(spec, data)
    model = header.model
    chunk_size = spec.integer("chunk_size", data.get("chunk_size", DEFAULT_CHUNK_SIZE), 1)
    output = data.get("output", path.with_suffix(".parquet").name)
    if not isinstance(output, str) or not output.strip():
        raise spec.bad("output", output, "a path (relative to the spec's directory)")
    if Path(output).is_absolute() or ".." in Path(output).parts:
        raise spec.bad("output", output, "a relative path inside the spec's directory "
                       "(no '..', not absolute): a spec writes only beside itself; give "
                       "--out to write elsewhere")
    output = path.parent / output
    numerics = parse_numerics(spec, data.get("numerics", {}))
    layout = spec.choice(data, "layout", LAYOUTS, "auto")

    if ("random" in data) == ("grid" in data):
        raise spec.error("random/grid", "give exactly one of the tables [random] or [grid]")
    if "random" in data:
        mode = "random"
        if "seed" not in data:
            raise spec.error("seed", "missing: random draws need a seed (an integer >= 0)")
        seed = spec.integer("seed", data["seed"], 0)
        draws, arms, rows = _random(spec, model, data["random"])
        axes: dict[str, np.ndarray] = {}
    else:
        mode = "grid"
        seed = spec.integer("seed", data.get("seed", 0), 0)
        axes, grid_tolerance, grid_mu = _grid(spec, model, data["grid"])
        grid_refine, grid_levels = _adaptive(spec, model, data["grid"], axes, grid_tolerance)
        psi_nodes = _psi_nodes(spec, model, data["grid"], axes, grid_refine)
        rows = math.prod(len(v) for v in axes.values())
        if rows > MAX_ROWS:
            raise spec.error("grid", f"{rows} rows; at most {MAX_ROWS} are allowed")
        draws, arms = {}, ()
    if mode == "random":
        grid_tolerance = grid_mu = psi_nodes = None
        grid_refine, grid_levels = "tensor", ADAPTIVE_LEVELS[:2]
    if chunk_size > MAX_CHUNK_SIZE:
        raise spec.bad("chunk_size", chunk_size, f"at most {MAX_CHUNK_SIZE} rows (a chunk is "
                       "held in memory)")
    if -(-rows // chunk_size) > MAX_CHUNKS:
        raise spec.bad("chunk_size", chunk_size,
                       f"at least {-(-rows // MAX_CHUNKS)} for {rows} rows: at most "
                       f"{MAX_CHUNKS} chunks (part files) per sweep")
    if ADHESION_AXIS in axes and "psi" in axes:
        raise spec.error(f"grid.{ADHESION_AXIS}", "is not allowed with a psi axis: the "
                         "adhesive impact is normal only (a lam grid has v_x0 = 0)")
    finite_mu = "mu" in draws and any(math.isfinite(x) for x in draws["mu"].values)
    if header.tangential_memory == "seed" and ("psi" in axes or finite_mu):
        key = "grid.psi" if "psi" in axes else "random.mu"
        raise spec.error(key, "is not allowed with tangential_memory = \"seed\": the seed "
                         "memory sets every element to the total contact-point displacement, "
                         "which slip cannot change, so friction needs tangential_memory = "
                         "\"incremental\"")
    return SweepSpec(path=path, text=text, model=model, mode=mode, seed=seed,
                     chunk_size=chunk_size, output=output, numerics=numerics,
                     tangential_memory=header.tangential_memory,
                     description=header.description, rows=rows, draws=draws, arms=arms,
                     axes=axes, tangential=header.tangential, rotation=header.rotation,
                     layout=layout, grid_tolerance=grid_tolerance,
                     grid_mu=grid_mu, material_text=material_text,
                     grid_refine=grid_refine, grid_levels=(grid_levels[0], grid_levels[1]),
                     grid_psi_nodes=psi_nodes, chunk_size_given="chunk_size" in data)


def _random(spec: TomlSource, model: str, table) -> tuple[dict, tuple, int]:
    if not isinstance(table, dict):
        raise spec.bad("random", table, "a table")
    material = MATERIAL_KEYS[model]
    allowed = ("rows",) + material + SPHERE_KEYS + ("nu", "theta_ratio") + FRICTION_KEYS + \
        (("arms",) if model == "prony" else ()) + (ADHESION_KEY,)
    spec.unknown(table, allowed, "random")
    if "rows" not in table:
        raise spec.error("random.rows", "missing: the number of parameter sets to draw")
    rows = spec.integer("random.rows", table["rows"], 1)
    if rows > MAX_ROWS:
        raise spec.bad("random.rows", rows, f"at most {MAX_ROWS}")
    if model in ("elastic", "kelvin_voigt"):
        if ("E_Pa" in table) == ("G_Pa" in table):
            raise spec.error("random.E_Pa/G_Pa", "give exactly one of E_Pa or G_Pa")
    for key in required_keys(model):
        if key not in table:
            raise spec.error(f"random.{key}", "missing")
    if "angle_deg" in table and "v_x0_m_s" in table:
        raise spec.error("random.angle_deg/v_x0_m_s", "give at most one of angle_deg (impact "
                         "angle from the normal, degrees) or v_x0_m_s (tangential speed, m/s)")
    draws = {}
    for key in input_keys(model):
        if key == "mu" and key in table:
            draws[key] = _draw_mu(spec, "random.mu", table[key])
        elif key == "angle_deg" and key in table:
            draws[key] = _draw(spec, "random.angle_deg", table[key])
            lo, hi = ANGLE_RANGE_DEG
            if not all(lo <= x < hi for x in draws[key].values):
                raise spec.bad("random.angle_deg", table[key],
                               f"degrees from the normal in [{lo:g}, {hi:g})")
        elif key in table:
            draws[key] = _draw(spec, f"random.{key}", table[key])
        elif key == "v_x0_m_s" and "angle_deg" in table:
            continue  # v_x0 = v_z0 tan(angle), made per chunk
        elif key in PHYSICAL_DEFAULTS or key == "eta_Pa_s":
            draws[key] = Draw("fixed", (PHYSICAL_DEFAULTS.get(key, 0.0),))
    if ADHESION_KEY in table:  # drawn last: a spec without it draws as before
        draws[ADHESION_KEY] = _draw(spec, f"random.{ADHESION_KEY}", table[ADHESION_KEY])
        if any(not x >= 0.0 for x in draws[ADHESION_KEY].values):
            raise spec.bad(f"random.{ADHESION_KEY}", table[ADHESION_KEY],
                           "works of adhesion >= 0, J/m^2")
    arms: tuple[dict[str, Draw], ...] = ()
    if model == "prony":
        listed = table.get("arms", [])
        if not isinstance(listed, list) or not all(isinstance(a, dict) for a in listed):
            raise spec.bad("random.arms", listed, "a list of tables [[random.arms]]")
        parsed = []
        for i, arm in enumerate(listed, start=1):
            where = f"random.arms[{i}]"
            spec.unknown(arm, ARM_KEYS, where)
            for key in ARM_KEYS:
                if key not in arm:
                    raise spec.error(f"{where}.{key}", "missing")
            parsed.append({k: _draw(spec, f"{where}.{k}", arm[k]) for k in ARM_KEYS})
        arms = tuple(parsed)
    return draws, arms, rows


def _adaptive(spec: TomlSource, model: str, table: dict, axes: dict,
              tolerance: float | None) -> tuple[str, tuple[int, int]]:
    """``[grid] refine`` and the adaptive levels (``min_level``, ``max_level``)."""
    refine = table.get("refine", "tensor")
    if refine not in GRID_REFINE:
        raise spec.bad("grid.refine", refine, " or ".join(repr(r) for r in GRID_REFINE))
    lo, hi, top = ADAPTIVE_LEVELS
    if refine == "tensor":
        for key in ("min_level", "max_level"):
            if key in table:
                raise spec.error(f"grid.{key}", 'needs refine = "adaptive"')
        return refine, (lo, hi)
    if tolerance is None:
        raise spec.error("grid.tolerance", 'missing: refine = "adaptive" refines cells until '
                         "their lookup meets it")
    if model not in ("kelvin_voigt", "standard_solid"):
        raise spec.error("grid.refine", f'"adaptive" needs a kelvin_voigt or standard_solid '
                         f"grid, not {model}")
    if ADHESION_AXIS in axes:
        raise spec.error(f"grid.{ADHESION_AXIS}", 'is not allowed with refine = "adaptive" '
                         "(the adaptive axes are Q1 (and Q2), the tensor axis nu)")
    for key in ("psi", "theta_ratio"):
        if key in axes and len(axes[key]) > 1:
            raise spec.error(f"grid.{key}", 'one value only with refine = "adaptive" (the '
                             "adaptive axes are Q1 (and Q2), the tensor axis nu)")
    for key in ("Q1", "Q2"):
        if key in axes and (len(axes[key]) < 2 or axes[key][0] <= 0.0):
            raise spec.bad(f"grid.{key}", axes[key].tolist()[:3], 'a range with start > 0 '
                           'and stop > start for refine = "adaptive" (its ends are the '
                           "table's range)")
    min_level = spec.integer("grid.min_level", table.get("min_level", lo), 0)
    max_level = spec.integer("grid.max_level", table.get("max_level", hi), 0)
    if not min_level <= max_level <= top:
        raise spec.bad("grid.max_level", max_level, f"an integer from min_level = {min_level} "
                       f"to {top}")
    return refine, (min_level, max_level)


def _psi_nodes(spec: TomlSource, model: str, table: dict, axes: dict,
               refine: str) -> tuple[int, int] | None:
    """``[grid] psi_nodes = [n_stick, n_slip]``: a Kelvin-Voigt friction table.

    The incidence nodes of an adaptive friction table
    (:func:`vimpact.lookup.friction.coordinate_nodes`), placed on the kinks of
    ``beta_x(psi)``; None without the key.
    """
    if "psi_nodes" not in table:
        return None
    value = table["psi_nodes"]
    if refine != "adaptive" or model != "kelvin_voigt" or "psi" in axes:
        raise spec.error("grid.psi_nodes", 'needs model = "kelvin_voigt", refine = "adaptive" '
                         "and no psi axis (the friction table places its psi nodes itself)")
    if not (isinstance(value, list) and len(value) == 2):
        raise spec.bad("grid.psi_nodes", value, "two integers >= 2 (nodes below psi = 1 "
                       "and from there to the start of gross slip)")
    n_stick = spec.integer("grid.psi_nodes", value[0], 2)
    n_slip = spec.integer("grid.psi_nodes", value[1], 2)
    return (n_stick, n_slip)


def _grid(spec: TomlSource, model: str, table) -> tuple[dict[str, np.ndarray], float | None,
                                                       float | None]:
    """Parse a ``[grid]`` table: its axes, tolerance and friction coefficient.

    The axes (outermost first), the optional ``tolerance`` and the friction coefficient
    ``mu`` (``None`` without a ``psi`` axis) of a ``[grid]`` table.
    """
    if model not in _GRID_KEYS:
        raise spec.error("grid", f"model {model!r} has no dimensionless grid; use [random]")
    if not isinstance(table, dict):
        raise spec.bad("grid", table, "a table")
    keys = ((ADHESION_AXIS,) if ADHESION_AXIS in table else ()) + _GRID_KEYS[model]
    spec.unknown(table, keys + ("tolerance", "mu", "refine", "min_level", "max_level",
                                "psi_nodes"), "grid")
    tolerance = None
    if "tolerance" in table:
        tolerance = spec.number("grid.tolerance", table["tolerance"],
                                lambda x: GRID_TOLERANCE_RANGE[0] <= x <= GRID_TOLERANCE_RANGE[1],
                                f"a number in [{GRID_TOLERANCE_RANGE[0]:g}, "
                                f"{GRID_TOLERANCE_RANGE[1]:g}]")
    mu = None
    if "psi" in table:
        mu = spec.number("grid.mu", table.get("mu", DEFAULT_GRID_MU), lambda x: x > 0.0,
                         "a finite number > 0 (the friction coefficient of the rows with "
                         "psi > 0)")
    elif "mu" in table:
        raise spec.error("grid.mu", "needs a psi axis (the grid's friction is given by psi "
                         "and mu; without psi the grid is full stick)")
    axes = {}
    for key in keys:
        if key == "psi" and key not in table:
            continue
        if key not in table:
            if key == "theta_ratio":
                axes[key] = np.array([DEFAULT_THETA_RATIO])
                continue
            raise spec.error(f"grid.{key}", "missing")
        values = _axis(spec, f"grid.{key}", table[key])
        check, allowed = _GRID_CHECKS[key]
        for x in values:
            if not (math.isfinite(x) and check(x)):
                raise spec.bad(f"grid.{key}", float(x), allowed)
            if key == "Q2":  # the grid's rows are Scene.from_dimensionless scenes: its own
                # rule on Q2 (G2 = G1 / Q2 finite; nu = 0 has the largest G1), at load time
                try:
                    Scene.from_dimensionless(0.0, 0.0, float(x))
                except ValueError as e:
                    raise spec.bad(f"grid.{key}", float(x),
                                   str(e).split("must be ", 1)[-1]) from None
        axes[key] = values
    return axes, tolerance, mu


__all__ = ["Draw", "FILE_LAYOUT_MAX_ROWS", "LAYOUTS", "MAX_ROWS", "SweepSpec", "load_spec"]
