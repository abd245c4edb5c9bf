"""What one impact produces, with units."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING

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
    "status": "",
    "n_steps": "1",
    "path": "",
    "error": "",
}

#: Meaning of each status value.
STATUSES = {
    "ok": "finished; all outputs valid",
    "vc0_zero": "finished; v_c0 = 0, so no tangential force and e_x, beta_x are undefined (NaN)",
    "normal_only": "finished; the scene asked for the normal impact only (tangential = 'none'): "
                   "e_x, beta_x not computed (NaN)",
    "half_space": "finished, but the contact half-width exceeded 0.2 R: outside the half-space model",
    "time_limit": "the impact had not ended at the time limit (Numerics.max_time); outputs NaN",
    "row_exceeded": "the contact reached the end of the element row; outputs NaN",
    "non_finite": "the integration produced a non-finite value; outputs NaN",
    "unstable": "the numerical solution gained energy (the contact energy, normal plus the "
                "contact point's effective tangential energy, rose above 1 + 1e-6 of its start) "
                "although the material and the incremental tangential rule are passive: the "
                "step was too coarse for this scene; outputs NaN (refine: more steps or "
                "elements)",
    "energy_gain": "finished, but explicit Euler gained energy (more than 1e-6 of the contact "
                   "energy), as it does by construction: numbers kept as the thesis's integrator "
                   "gives them, not converged (use verlet)",
    "not_passive": "finished, but the seed tangential memory (not passive) gained energy or "
                   "gave |e_z| or |beta_x| above 1 + 1e-6: numbers kept as its rule gives "
                   "them, not physical (the incremental memory is passive)",
    "unresolved": "the contact lasted fewer time steps than the element path needs to resolve "
                  "it (numerics.MIN_CONTACT_STEPS); outputs NaN (more steps, or the continuum path)",
    "too_costly": "the element path would need more steps or elements than its cost bounds "
                  "(numerics.MAX_STEPS_PER_T_H, MAX_ELEMENTS_IN_ROW) for this scene; outputs NaN "
                  "(reason in the error column)",
    "tolerance_unreachable": "the numerics' tolerance is below what the element path this scene "
                             "needs can reach, or its error is not bounded there (the seed "
                             "memory); reason in the error column; outputs NaN",
    "invalid": "the row's inputs are not a valid scene (reason in the error column); outputs NaN",
}

#: Statuses whose numbers are results (the others carry NaN).
FINISHED = ("ok", "vc0_zero", "normal_only", "half_space", "energy_gain", "not_passive")


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
    error: str | None = None
    trajectory: "pd.DataFrame | None" = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict:
        """Outputs as a plain dict (NaN kept as float NaN; no trajectory)."""
        return {name: getattr(self, name) for name in RESULT_FIELDS}

    def to_json_dict(self) -> dict:
        """Outputs for JSON: NaN and inf become ``None`` (JSON null); units under ``"units"``."""
        d = {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
             for k, v in self.to_dict().items()}
        d["units"] = dict(UNITS)
        return d


#: Columns of :func:`vimpact.simulate_batch` (the fields of :class:`ImpactResult`
#: without the trajectory), in order.
RESULT_FIELDS = tuple(f.name for f in fields(ImpactResult) if f.name != "trajectory")
