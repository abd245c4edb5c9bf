"""Scenes as columns: validated, vectorized inputs of the batch path.

Data flow: inputs -> :class:`SceneColumns` (this module) -> kernel
arrays (:mod:`vimpact.engine.pack`) -> kernels -> SI result columns
(:mod:`vimpact.engine.unpack`). One scene is one row; nothing here builds a
Python object per row.

Input columns (a ``pandas.DataFrame`` or a mapping of equal-length arrays;
units in the names):

=====================  ========  ==============================================
column                 default   meaning
=====================  ========  ==============================================
``nu``                 required  Poisson ratio, in [0, 0.5]
``G_inf_Pa``           required  relaxed (long-time) shear modulus, Pa
``eta0_Pa_s``          0         parallel dashpot viscosity, Pa s
``G_arm<i>_Pa``        (none)    modulus of Maxwell arm ``i = 1, 2, ...``, Pa
``tau_arm<i>_s``       (none)    relaxation time of arm ``i``, s
``R_m``                required  sphere radius, m
``m_kg``               required  sphere mass, kg
``v_z0_m_s``           required  normal impact speed, m/s (> 0)
``v_x0_m_s``           0         tangential speed of the centre, m/s
``omega0_rad_s``       0         spin about y, rad/s
``Theta_kg_m2``        0.4 m R^2 moment of inertia (or ``theta_ratio`` = Theta/(m R^2))
``tangential``         "auto"    "auto", "stick" or "none"
``tangential_memory``  "incr."   "incremental" or "seed"
``rotation``           True      the sphere may spin
``mu``                 inf       Coulomb friction coefficient (inf: full stick)
``adhesion_J_m2``      0         work of adhesion, J/m^2, >= 0 (> 0: the adhesive
                                 normal impact, docs/physics.md#adhesion)
``model``              inferred  "elastic", "kelvin_voigt", "standard_solid",
                                 "prony": only how Q1, Q2 are reported
=====================  ========  ==============================================

A row that breaks a rule is not an error for the batch: it is marked invalid
with the reason (``SceneColumns.reasons``), its values are replaced by
harmless ones, and the other rows go on.
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from vimpact.model.hertz import Q1_PER_TAU, hertz_scales
from vimpact.model.material import MODELS
from vimpact.model.scene import (
    ADHESION_OBLIQUE,
    DEFAULT_THETA_RATIO,
    MAX_DASHPOT_TIME,
    SEED_FRICTION_ALLOWED,
    TANGENTIAL_EFFECTS,
    TANGENTIAL_MEMORY,
    Scene,
)
from vimpact.model.validation import InputError, check_column, is_none, message, unexplained

#: numeric input columns: name -> (validation rule, default or None if required)
NUMERIC = {
    "nu": ("poisson_ratio", None),
    "G_inf_Pa": ("positive", None),
    "eta0_Pa_s": ("non_negative", 0.0),
    "R_m": ("positive", None),
    "m_kg": ("positive", None),
    "v_z0_m_s": ("positive", None),
    "v_x0_m_s": ("finite", 0.0),
    "omega0_rad_s": ("finite", 0.0),
    "mu": ("friction", math.inf),
    "adhesion_J_m2": ("non_negative", 0.0),
}
#: text input columns: name -> (choices, default)
CHOICES = {
    "tangential": (TANGENTIAL_EFFECTS, "auto"),
    "tangential_memory": (TANGENTIAL_MEMORY, "incremental"),
}
_ARM = re.compile(r"^(G|tau)_arm(\d+)_(Pa|s)$")
_OTHER = ("Theta_kg_m2", "theta_ratio", "rotation", "model")

MODEL_ELASTIC, MODEL_KELVIN_VOIGT, MODEL_STANDARD_SOLID, MODEL_PRONY = range(4)


class _once:  # noqa: N801 - used as a decorator, like property
    """Decorate a derived column: computed on first access, then kept.

    A derived column computed on first access and then kept in the instance
    (``functools.cached_property`` without its lock, which costs more than the
    one-row arithmetic it saves).
    """

    def __init__(self, fn):
        self.fn, self.__doc__ = fn, fn.__doc__

    def __set_name__(self, owner, name: str) -> None:
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        value = obj.__dict__[self.name] = self.fn(obj)
        return value


@dataclass
class SceneColumns:
    """A batch of scenes as arrays (SI units), validated, with derived Hertz scales.

    Attributes
    ----------
    nu, G_inf, eta0 : Poisson ratio (-), relaxed modulus (Pa), dashpot (Pa s)
    G_arm, tau_arm : ``(n, k)`` arm moduli (Pa) and times (s); unused slots have ``G = 0``
    R, m, v_z0, v_x0, omega0, Theta, mu : sphere and impact (m, kg, m/s, m/s, rad/s, kg m^2, -)
    tangential, memory, model : codes (indices into ``TANGENTIAL_EFFECTS``,
        ``TANGENTIAL_MEMORY``, ``MODELS``)
    rotation, allow_large_contact : flags
    reasons : object array, ``None`` for a valid row, else why it is invalid
    adhesion : work of adhesion, J/m^2 (0: none; > 0 runs the adhesive kernel)
    d, a_H, T, t_H : Hertz scales of the relaxed modulus (m, m, s, s)
    """

    nu: np.ndarray
    G_inf: np.ndarray
    eta0: np.ndarray
    G_arm: np.ndarray
    tau_arm: np.ndarray
    R: np.ndarray
    m: np.ndarray
    v_z0: np.ndarray
    v_x0: np.ndarray
    omega0: np.ndarray
    Theta: np.ndarray
    mu: np.ndarray
    tangential: np.ndarray
    memory: np.ndarray
    model: np.ndarray
    rotation: np.ndarray
    allow_large_contact: np.ndarray
    reasons: np.ndarray
    adhesion: np.ndarray = None  # type: ignore[assignment]  # zeros if not given
    d: np.ndarray = None  # type: ignore[assignment]  # set by __post_init__
    a_H: np.ndarray = None  # type: ignore[assignment]  # set by __post_init__
    T: np.ndarray = None  # type: ignore[assignment]  # set by __post_init__
    t_H: np.ndarray = None  # type: ignore[assignment]  # set by __post_init__

    def __post_init__(self):
        if self.adhesion is None:
            self.adhesion = np.zeros(self.nu.shape[0])
        with np.errstate(all="ignore"):  # out-of-range rows are marked by check_scales
            self.d, self.a_H, self.T, self.t_H = (np.asarray(x, dtype=float) for x in hertz_scales(
                self.G_inf, self.nu, self.R, self.m, self.v_z0))

    def __len__(self) -> int:
        return self.nu.shape[0]

    # ---- derived, vectorized (docs/physics.md#method-of-dimensionality-reduction,
    # docs/physics.md#energy-and-passivity, docs/physics.md#dimensionless-parameters);
    # the ones routing, packing and unpacking all read are computed once per batch
    # (:data:`_DERIVED`; :meth:`check_scales` forgets them when it rewrites rows) ----
    @_once
    def valid(self) -> np.ndarray:
        """Rows without a reason to refuse them, bool.

        Rows without a reason to refuse them (valid scenes), bool (kept until
        :meth:`check_scales` gives a row a reason).
        """
        return is_none(self.reasons)

    @_once
    def adhesive(self) -> np.ndarray:
        """Valid rows with a work of adhesion > 0 (the adhesive kernel runs them), bool."""
        return self.valid & (self.adhesion > 0.0)

    @_once
    def v_c0(self) -> np.ndarray:
        """Initial contact-point velocity ``v_x0 + R omega0``, m/s."""
        return self.v_x0 + self.R * self.omega0

    @_once
    def theta_ratio(self) -> np.ndarray:
        """``Theta / (m R^2)``, dimensionless."""
        return self.Theta / (self.m * self.R**2)

    @_once
    def contact_mass_factor(self) -> np.ndarray:
        """``1 + m R^2 / Theta`` (1 without rotation), dimensionless."""
        return np.where(self.rotation, 1.0 + 1.0 / self.theta_ratio, 1.0)

    @_once
    def kappa(self) -> np.ndarray:
        """``c_t / c_n = 2 (1 - nu) / (2 - nu)``, dimensionless."""
        return 2.0 * (1.0 - self.nu) / (2.0 - self.nu)

    @_once
    def computes_tangential(self) -> np.ndarray:
        """The tangential problem is solved: asked for and ``v_c0 != 0``."""
        return (self.tangential != TANGENTIAL_EFFECTS.index("none")) & (self.v_c0 != 0.0)

    @_once
    def has_arms(self) -> np.ndarray:
        """Rows with at least one Maxwell arm, bool."""
        if self.G_arm.shape[1] == 0:  # (np.any over no column costs more than this)
            return np.zeros(len(self), dtype=bool)
        return np.any(self.G_arm > 0.0, axis=1)

    @_once
    def dashpot_time(self) -> np.ndarray:
        """``eta0 / G_inf``, s."""
        return self.eta0 / self.G_inf

    @property
    def Q1(self) -> np.ndarray:
        """``sqrt(15/32) (eta / G_inf) / T`` (NaN for a Prony series), dimensionless."""
        arm_viscous = ((self.G_arm * self.tau_arm).sum(axis=1) / self.G_inf if self.G_arm.shape[1]
                       else 0.0)  # no arm column: a sum of none
        viscous = np.where(self.model == MODEL_STANDARD_SOLID, arm_viscous, self.dashpot_time)
        return np.where(self.model == MODEL_PRONY, np.nan, Q1_PER_TAU * viscous / self.T)

    @property
    def Q2(self) -> np.ndarray:
        """``G1 / G2`` for a standard solid (inf without arm), NaN otherwise."""
        if not self.G_arm.shape[1]:  # no arm column: inf for a standard solid (none), else NaN
            return np.where(self.model == MODEL_STANDARD_SOLID, np.inf, np.nan)
        G2 = self.G_arm.sum(axis=1)
        with np.errstate(divide="ignore"):
            q2 = np.where(G2 > 0.0, self.G_inf / np.where(G2 > 0.0, G2, 1.0), np.inf)
        return np.where(self.model == MODEL_STANDARD_SOLID, q2, np.nan)

    def Q_row(self) -> tuple[float, float]:
        """:attr:`Q1` and :attr:`Q2` of a one-row batch (row 0), as NumPy scalars.

        The same rules on scalars (the same floating-point operations, so the same
        numbers) for :func:`vimpact.simulate`, where the array forms cost more than the
        arithmetic; with an arm column the array forms themselves.
        """
        if self.G_arm.shape[1]:
            return self.Q1[0], self.Q2[0]
        model = self.model[0]
        if model == MODEL_PRONY:
            q1 = np.float64(np.nan)
        else:  # no arm column: a standard solid's arm viscosity is a sum of none
            viscous = np.float64(0.0) if model == MODEL_STANDARD_SOLID else self.dashpot_time[0]
            q1 = Q1_PER_TAU * viscous / self.T[0]
        return q1, np.float64(np.inf if model == MODEL_STANDARD_SOLID else np.nan)

    def take(self, index) -> SceneColumns:
        """Return the rows ``index`` (an integer array or a mask) as a new batch."""
        fields = {k: getattr(self, k)[index] for k in _FIELDS}
        return SceneColumns(**fields)

    # ---- constructors ---------------------------------------------------------
    @classmethod
    def from_scenes(cls, scenes: Sequence[Scene]) -> SceneColumns:
        """Columns of validated :class:`Scene` objects (one Python pass over them)."""
        n = len(scenes)
        k = max((len(s.material.arms) for s in scenes if isinstance(s, Scene)), default=0)
        G_arm, tau_arm = np.zeros((n, k)), np.zeros((n, k))
        reasons = np.empty(n, dtype=object)  # (NumPy fills an object array with None)
        numbers, codes, flags = [], [], []  # a tuple per row, one array each at the end
        bad = False
        for i, s in enumerate(scenes):
            if not isinstance(s, Scene):  # a bad entry is a bad row, not a lost batch
                bad = True
                reasons[i] = message(f"scenes[{i}]", s, "a vimpact.Scene")
                numbers.append(_NEUTRAL_ROW)
                codes.append((0, 0, 0))
                flags.append((True, False))
                continue
            mat = s.material
            numbers.append((mat.nu, mat.G_inf, mat.eta0, s.R, s.m, s.v_z0, s.v_x0, s.omega0,
                            s.Theta, s.mu, s.adhesion))
            for j, (G, tau) in enumerate(mat.arms):
                G_arm[i, j], tau_arm[i, j] = G, tau
            codes.append((TANGENTIAL_EFFECTS.index(s.tangential),
                          TANGENTIAL_MEMORY.index(s.tangential_memory), MODELS.index(mat.model)))
            flags.append((s.rotation, s.allow_large_contact))
        # (fields, n) copies: every column a contiguous row of one array
        number = np.array(numbers, dtype=float).reshape(n, len(_SCENE_NUMBERS)).T.copy()
        code = np.array(codes, dtype=np.int8).reshape(n, 3).T.copy()
        flag = np.array(flags, dtype=bool).reshape(n, 2).T.copy()
        cols = dict(zip(_SCENE_NUMBERS, number), G_arm=G_arm, tau_arm=tau_arm,
                    tangential=code[0], memory=code[1], model=code[2], rotation=flag[0],
                    allow_large_contact=flag[1], reasons=reasons)
        if bad:
            _neutralize(cols)
        # no check_scales: a Scene checked the same ranges when it was made
        # (ScaleError), and a row that is not a Scene is already marked
        return cls(**cols)

    @classmethod
    def from_columns(cls, data) -> SceneColumns:
        """Validate scene columns (module docstring); bad rows get a reason, never an exception.

        Raises :class:`InputError` only for a malformed batch: not a mapping, columns of
        different lengths, a required column missing, an unknown column.
        """
        if not isinstance(data, Mapping) and not hasattr(data, "columns"):
            raise InputError(message("scenes", type(data).__name__,
                                     "a sequence of vimpact.Scene, a DataFrame or a mapping of "
                                     "columns"))
        names = list(data.keys()) if isinstance(data, Mapping) else list(data.columns)
        arrays = {name: _as_array(data[name]) for name in names}
        lengths = {a.shape[0] if a.ndim else -1 for a in arrays.values()}
        if len(lengths) != 1 or -1 in lengths:
            raise InputError(message("scene columns", {k: np.shape(v) for k, v in arrays.items()},
                                     "one-dimensional arrays of one length"))
        n = lengths.pop()
        arms: dict[int, dict[str, np.ndarray]] = {}
        for name in names:
            if name in NUMERIC or name in CHOICES or name in _OTHER:
                continue
            match = _ARM.match(name)
            if match is None or (match[1] == "G") != (match[3] == "Pa"):
                raise InputError(f"unknown scene column {name!r} (allowed: "
                                 f"{', '.join(list(NUMERIC) + list(CHOICES) + list(_OTHER))}, "
                                 "G_arm<i>_Pa, tau_arm<i>_s)")
            arms.setdefault(int(match[2]), {})[match[1]] = arrays[name]
        missing = [k for k, (_, default) in NUMERIC.items() if default is None and k not in arrays]
        if missing:
            raise InputError(f"scene columns {', '.join(missing)} are required "
                             f"(given: {', '.join(names) or 'none'})")
        reasons = np.empty(n, dtype=object)  # (NumPy fills an object array with None)
        num = {}
        for name, (rule, default) in NUMERIC.items():
            # (a default: one value viewed in every row, checked once by check_column)
            values = arrays[name] if name in arrays else np.broadcast_to(np.asarray(default),
                                                                         (n,))
            num[name] = check_column(name, values, rule, reasons)
        k = max(arms, default=0)
        G_arm, tau_arm = np.zeros((n, k)), np.zeros((n, k))
        for i in range(1, k + 1):
            pair = arms.get(i, {})
            if set(pair) != {"G", "tau"}:
                raise InputError(f"arm {i} needs both G_arm{i}_Pa and tau_arm{i}_s")
            # 0 = no such arm in this row (rows of one batch may have fewer arms)
            G_arm[:, i - 1] = check_column(f"G_arm{i}_Pa", pair["G"], "non_negative", reasons)
            tau_arm[:, i - 1] = check_column(f"tau_arm{i}_s", pair["tau"], "positive", reasons)
        codes = {}
        for name, (choices, choice) in CHOICES.items():
            codes[name] = _codes(name, arrays.get(name), choices, choice, n, reasons)
        rotation = _flags("rotation", arrays.get("rotation"), True, n, reasons)
        if "Theta_kg_m2" in arrays and "theta_ratio" in arrays:
            raise InputError("give Theta_kg_m2 or theta_ratio, not both")
        R, m = num["R_m"], num["m_kg"]
        if "Theta_kg_m2" in arrays:
            Theta = check_column("Theta_kg_m2", arrays["Theta_kg_m2"], "positive", reasons)
        else:
            ratio = arrays.get("theta_ratio",
                               np.broadcast_to(np.asarray(DEFAULT_THETA_RATIO), (n,)))
            Theta = check_column("theta_ratio", ratio, "positive", reasons) * m * R**2
        model = _model(arrays.get("model"), G_arm, num["eta0_Pa_s"], n, reasons)
        seeded = ((codes["tangential_memory"] == TANGENTIAL_MEMORY.index("seed"))
                  & np.isfinite(num["mu"]))
        for row in unexplained(seeded, reasons):
            reasons[row] = message("mu", float(num["mu"][row]), SEED_FRICTION_ALLOWED)
        cols = dict(nu=num["nu"], G_inf=num["G_inf_Pa"], eta0=num["eta0_Pa_s"], G_arm=G_arm,
                    tau_arm=tau_arm, R=R, m=m, v_z0=num["v_z0_m_s"], v_x0=num["v_x0_m_s"],
                    omega0=num["omega0_rad_s"], Theta=Theta, mu=num["mu"],
                    tangential=codes["tangential"], memory=codes["tangential_memory"],
                    model=model, rotation=rotation, allow_large_contact=np.ones(n, dtype=bool),
                    reasons=reasons, adhesion=num["adhesion_J_m2"])
        # the adhesive impact is normal only (the rule of vimpact.Scene)
        oblique = ((num["adhesion_J_m2"] > 0.0) & (codes["tangential"] != TANGENTIAL_EFFECTS.index(
            "none")) & (num["v_x0_m_s"] + R * num["omega0_rad_s"] != 0.0))
        for row in unexplained(oblique, reasons):
            reasons[row] = message("adhesion_J_m2", float(num["adhesion_J_m2"][row]),
                                   ADHESION_OBLIQUE)
        _neutralize(cols)
        out = cls(**cols)
        out.check_scales()
        return out

    def check_scales(self) -> None:
        """Mark rows whose Hertz scales (or kernel-unit inputs) are not finite numbers.

        Inputs whose arithmetic leaves the float range (e.g. ``v_z0 = 1e200``).
        """
        with np.errstate(all="ignore"):
            tau0 = self.dashpot_time / self.T
            ok = (np.isfinite(self.d) & (self.d > 0) & np.isfinite(self.T) & (self.T > 0)
                  & np.isfinite(self.a_H) & (self.a_H > 0) & np.isfinite(tau0)
                  & np.isfinite(self.G_arm / self.G_inf[:, None]).all(axis=1)
                  & np.isfinite(self.tau_arm / self.T[:, None]).all(axis=1)
                  & np.isfinite(self.contact_mass_factor) & np.isfinite(self.v_c0)
                  # the energies the results are checked with (passivity, energy_ratio)
                  & np.isfinite(self.m * (self.v_z0**2 + self.v_x0**2)
                                + self.Theta * self.omega0**2)
                  & np.isfinite(self.v_c0**2 / self.contact_mass_factor))
        for i in np.flatnonzero(~ok & self.valid):
            self.__dict__.pop("valid", None)
            self.reasons[i] = (
                f"the inputs of this row (G_inf = {self.G_inf[i]:.3g} Pa, R = {self.R[i]:.3g} m, "
                f"m = {self.m[i]:.3g} kg, v_z0 = {self.v_z0[i]:.3g} m/s, v_x0 = "
                f"{self.v_x0[i]:.3g} m/s, omega0 = {self.omega0[i]:.3g} rad/s) give Hertz "
                "scales, kernel inputs or a kinetic energy outside the floating-point range: "
                "not allowed")
        with np.errstate(all="ignore"):
            damped = ok & (tau0 > MAX_DASHPOT_TIME)
        for i in np.flatnonzero(damped & self.valid):
            self.__dict__.pop("valid", None)
            self.reasons[i] = (
                f"eta0_Pa_s = {self.eta0[i]:.3g} is not allowed in this row: the dashpot time "
                f"eta0 / G_inf must be <= {MAX_DASHPOT_TIME:.0e} T = "
                f"{MAX_DASHPOT_TIME * self.T[i]:.3g} s (Q1 <= "
                f"{Q1_PER_TAU * MAX_DASHPOT_TIME:.2g}: beyond it the kernels' arithmetic "
                "overflows, and the impact is fully damped, e_z < 1e-160)")
        bad = ~self.valid
        if bad.any():
            fields = {k: getattr(self, k) for k in _FIELDS}
            _neutralize(fields)
            self.__post_init__()
            for name in _DERIVED:  # computed from the rows before they were neutralized
                self.__dict__.pop(name, None)


_FIELDS = ("nu", "G_inf", "eta0", "G_arm", "tau_arm", "R", "m", "v_z0", "v_x0", "omega0",
           "Theta", "mu", "tangential", "memory", "model", "rotation", "allow_large_contact",
           "reasons", "adhesion")
#: the numeric fields of :meth:`SceneColumns.from_scenes`, in the order it reads them
_SCENE_NUMBERS = ("nu", "G_inf", "eta0", "R", "m", "v_z0", "v_x0", "omega0", "Theta", "mu",
                  "adhesion")
#: derived columns computed once per batch (:class:`_once`)
_DERIVED = ("valid", "adhesive", "v_c0", "theta_ratio", "contact_mass_factor", "kappa", "computes_tangential",
            "has_arms", "dashpot_time")
#: harmless values written into invalid rows, so that no arithmetic on them warns
_NEUTRAL = {"nu": 0.5, "G_inf": 1.0, "eta0": 0.0, "R": 1.0, "m": 1.0, "v_z0": 1.0, "v_x0": 0.0,
            "omega0": 0.0, "Theta": 0.4, "mu": math.inf, "adhesion": 0.0}

#: a row that is not a Scene, in the order of :data:`_SCENE_NUMBERS`
_NEUTRAL_ROW = tuple(_NEUTRAL[name] for name in _SCENE_NUMBERS)


def _as_array(values) -> np.ndarray:
    """Return a column as an array without NumPy's coercion of mixed lists to strings."""
    if isinstance(values, np.ndarray) or hasattr(values, "dtype"):
        return np.asarray(values)
    if np.ndim(values) == 0 or isinstance(values, (str, bytes)):
        return np.asarray(values)
    obj = np.empty(len(values), dtype=object)
    obj[:] = list(values)
    kinds = {type(v) for v in obj}
    if kinds <= {float, int} or all(isinstance(v, numbers.Real) and not isinstance(v, bool)
                                    for v in obj):
        return obj.astype(np.float64)
    if kinds <= {str}:
        return obj.astype(str)
    return obj


def _neutralize(cols: dict) -> None:
    bad = ~is_none(cols["reasons"])
    if not bad.any():
        return
    for name, value in _NEUTRAL.items():
        cols[name][bad] = value
    cols["G_arm"][bad] = 0.0
    cols["tau_arm"][bad] = 1.0
    cols["tangential"][bad] = TANGENTIAL_EFFECTS.index("none")


def _codes(name: str, values, choices, default: str, n: int, reasons) -> np.ndarray:
    if values is None:
        return np.full(n, choices.index(default), dtype=np.int8)
    values = np.asarray(values)
    if values.ndim == 1 and n > 1 and values.strides[0] == 0 and isinstance(values[0], str) \
            and values[0] in choices:
        # one value in every row (a view of one element): compared once
        return np.full(n, choices.index(values[0]), dtype=np.int8)
    text = values.dtype.kind == "U"  # compared as it is (as objects: a str per row, 5 ms/1e5)
    if not text:
        values = values.astype(object)
    out = np.zeros(n, dtype=np.int8)
    known = np.zeros(n, dtype=bool)
    for code, choice in enumerate(choices):
        hit = values == choice
        out[hit] = code
        known |= hit
    for i in unexplained(~known, reasons):
        reasons[i] = message(name, values[i].item() if text else values[i],
                             "one of " + ", ".join(map(repr, choices)))
    return out


def _flags(name: str, values, default: bool, n: int, reasons) -> np.ndarray:
    if values is None:
        return np.full(n, default, dtype=bool)
    values = np.asarray(values)
    if values.dtype == bool:
        return values.copy()
    obj = values.astype(object)
    ok = np.array([isinstance(v, (bool, np.bool_)) for v in obj], dtype=bool)
    for i in unexplained(~ok, reasons):
        reasons[i] = message(name, obj[i], "True or False")
    return np.where(ok, obj == True, default)  # noqa: E712 - elementwise


def _model(values, G_arm: np.ndarray, eta0: np.ndarray, n: int, reasons) -> np.ndarray:
    """Model codes: given, or inferred from the rheology; a given model must fit it."""
    # (a sum over no arm column costs some 5 ms per 1e5 rows)
    n_arms = (G_arm > 0.0).sum(axis=1) if G_arm.shape[1] else np.zeros(n, dtype=np.int64)
    inferred = np.where(n_arms == 0, np.where(eta0 > 0.0, MODEL_KELVIN_VOIGT, MODEL_ELASTIC),
                        np.where((n_arms == 1) & (eta0 == 0.0), MODEL_STANDARD_SOLID, MODEL_PRONY))
    if values is None:
        return inferred.astype(np.int8)
    codes = _codes("model", values, MODELS, "prony", n, reasons)
    fits = {MODEL_ELASTIC: ((n_arms == 0) & (eta0 == 0.0), "no arms and eta0 = 0"),
            MODEL_KELVIN_VOIGT: (n_arms == 0, "no Maxwell arms"),
            MODEL_STANDARD_SOLID: ((n_arms <= 1) & (eta0 == 0.0),
                                   "at most one Maxwell arm and eta0 = 0"),
            MODEL_PRONY: (np.ones(n, dtype=bool), "")}
    for code, (ok, what) in fits.items():
        for i in unexplained((codes == code) & ~ok, reasons):
            reasons[i] = (f"model = {MODELS[code]!r} is not allowed for this row: it needs "
                          f"{what} (the row has {n_arms[i]} arms, eta0 = {eta0[i]:g} Pa s)")
    return codes


def scene_columns(scenes) -> SceneColumns:
    """:class:`SceneColumns` of a sequence of :class:`Scene` or of input columns."""
    if isinstance(scenes, SceneColumns):
        return scenes
    if isinstance(scenes, Mapping) or hasattr(scenes, "columns"):
        return SceneColumns.from_columns(scenes)
    if isinstance(scenes, (str, bytes)) or not isinstance(scenes, Sequence):
        scenes = list(scenes) if hasattr(scenes, "__iter__") and not isinstance(
            scenes, (str, bytes)) else scenes
        if not isinstance(scenes, list):
            raise InputError(message("scenes", scenes, "a sequence of vimpact.Scene, a DataFrame "
                                                       "or a mapping of columns"))
    return SceneColumns.from_scenes(scenes)
