"""What one impact produces, with units."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from vimpact.kernels.status import TABLE as STATUS_TABLE

if TYPE_CHECKING:  # the trajectory is a DataFrame; pandas is loaded only where one is made
    import pandas as pd

#: Units of every output (``"1"`` = dimensionless).
UNITS = {
    "e_z": "1",
    "e_x": "1",
    "beta_x": "1",
    "t_contact": "s",
    "u_max": "m",
    "a_max": "m",
    "t_hertz": "s",
    "d_hertz": "m",
    "a_hertz": "m",
    "energy_ratio": "1",
    "Q1": "1",
    "Q2": "1",
    "nu": "1",
    "v_z_end": "m/s",
    "v_x_end": "m/s",
    "omega_end": "rad/s",
    "mu_eff": "1",
    "rebound_angle": "deg",
    "gross_slip_fraction": "1",
    "friction_energy": "J",
    "F_tensile_max": "N",
    "status": "",
    "n_steps": "1",
    "path": "",
    "error": "",
}

#: Meaning of each status value an impact can have (from the status table,
#: :mod:`vimpact.kernels.status`).
STATUSES = {s.name: s.message for s in STATUS_TABLE if not s.sweep_only}

#: Statuses whose numbers are results (the others carry NaN).
FINISHED = tuple(s.name for s in STATUS_TABLE if s.finished and not s.sweep_only)

#: Every status name (the sweep's ``failed`` too), in the status table's order: inside
#: the engine and the sweep a row's status is its index here (an ``int8`` code), made
#: text only where text is shown or stored (:class:`Coded`).
STATUS_NAMES: tuple[str, ...] = tuple(s.name for s in STATUS_TABLE)
#: status name -> its code (index in :data:`STATUS_NAMES`)
STATUS_CODE: dict[str, int] = {name: i for i, name in enumerate(STATUS_NAMES)}


class Coded(NamedTuple):
    """A text column as integer codes into a tuple of names (``-1``: no value, ``None``).

    The engine's statuses and kernel paths take one of a few names; a code per row is
    compared, masked and stored without a Python string per row.
    """

    codes: np.ndarray
    names: tuple[str, ...]

    def decode(self) -> np.ndarray:
        """Return the column as an object array of ``str`` (``None`` for code ``-1``)."""
        lookup = np.empty(len(self.names) + 1, dtype=object)  # the last entry: None
        lookup[:-1] = self.names
        return lookup[self.codes]

    def codes_in(self, names: list[str]) -> np.ndarray:
        """Return the codes into ``names`` (``-1`` stays ``-1``), appending names it lacks.

        For joining columns coded with their own names into one list of names.
        """
        lookup = np.full(len(self.names) + 1, -1, dtype=np.int16)  # the last entry: -1
        for j, name in enumerate(self.names):
            if name not in names:
                names.append(name)
            lookup[j] = names.index(name)
        return lookup[self.codes]

    @classmethod
    def encode(cls, values: np.ndarray, names: tuple[str, ...] | None = None) -> Coded:
        """Return the object array ``values`` (``str`` or ``None``) as codes into ``names``.

        ``names`` default: the distinct values in order of first appearance.
        """
        if names is None:
            names = tuple(dict.fromkeys(v for v in values.tolist() if v is not None))
        index = {name: i for i, name in enumerate(names)}
        codes = np.fromiter((index[v] if v is not None else -1 for v in values.tolist()),
                            dtype=np.int16, count=len(values))
        return cls(codes, names)


@dataclass(frozen=True)
class ImpactResult:
    """Outcome of one impact. Units in ``UNITS``; NaN only with a status that says why.

    Attributes
    ----------
    e_z : normal restitution ``|v_z,end| / v_z0``
    e_x : tangential restitution ``|v_c,end| / |v_c0|``
    beta_x : signed tangential restitution ``-v_c,end / v_c0``
    t_contact : contact time, s
    u_max : maximum indentation, m
    a_max : maximum contact half-width, m
    t_hertz, d_hertz, a_hertz : Hertz contact time (s), indentation (m) and
        radius (m) of the elastic impact with the relaxed modulus
    energy_ratio : kinetic energy after / before (translation and rotation; with a held
        spin, ``rotation=False``, the spin's energy is left out and the work of the
        torque holding it counted as energy put in: docs/physics.md#energy-and-passivity)
    Q1, Q2, nu : dimensionless parameters (Q1 NaN for a general Prony series,
        Q2 NaN unless a standard solid)
    v_z_end, v_x_end, omega_end : end velocities, m/s, m/s, rad/s (v_z > 0 into the half-space)
    status : see ``STATUSES``
    mu_eff : impulse ratio ``|int F_x dt| / int F_z dt`` (NaN without tangential problem)
    rebound_angle : angle of the centre's rebound velocity to the normal,
        ``atan2(v_x_end, -v_z_end)``, degrees
    gross_slip_fraction : fraction of the contact time in which every element in
        contact slips (Coulomb friction; 0 in full stick, NaN without tangential problem)
    friction_energy : energy dissipated by slip, J (0 in full stick)
    F_tensile_max : largest pulling (tensile) normal force on the sphere, N, >= 0
        (docs/physics.md#adhesion); 0 without adhesion, where the contact never pulls
    n_steps : time steps taken (element path) or accepted ODE steps (continuum path)
    path : the kernel that ran (:mod:`vimpact.engine.routing`), e.g. ``elements[verlet,dashpot]``
    trajectory : time series of the impact if asked for (``None`` otherwise)
    """

    e_z: float
    e_x: float
    beta_x: float
    t_contact: float
    u_max: float
    a_max: float
    t_hertz: float
    d_hertz: float
    a_hertz: float
    energy_ratio: float
    Q1: float
    Q2: float
    nu: float
    v_z_end: float
    v_x_end: float
    omega_end: float
    status: str
    n_steps: int = 0
    path: str = ""
    mu_eff: float = math.nan
    rebound_angle: float = math.nan
    gross_slip_fraction: float = math.nan
    friction_energy: float = math.nan
    F_tensile_max: float = math.nan
    error: str | None = None
    trajectory: pd.DataFrame | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict:
        """Return the outputs as a plain dict (NaN kept as float NaN; no trajectory)."""
        return {name: getattr(self, name) for name in RESULT_FIELDS}

    def to_json_dict(self) -> dict:
        """Return the outputs for JSON: NaN and inf become ``None`` (JSON null); units under ``"units"``."""
        d = {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
             for k, v in self.to_dict().items()}
        d["units"] = dict(UNITS)
        return d


#: Columns of :func:`vimpact.simulate_batch` (the fields of :class:`ImpactResult`
#: without the trajectory), in order.
RESULT_FIELDS = tuple(f.name for f in fields(ImpactResult) if f.name != "trajectory")
