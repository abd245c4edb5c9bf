"""Every status a result row can have: the one table.

Plain data (no numba, no other folder of vimpact), so that the kernels take
their status codes from it and the engine, the sweep, the lookup and the
command line take their names, texts and lists from it:

- ``code``: the number a kernel writes to ``OUT_STATUS`` (``None``: the status
  is set after the kernel, by the engine's checks or by the sweep);
- ``finished``: the impact ran to its end and its numbers are results (the
  other statuses carry NaN outputs);
- ``has_data``: a restitution table uses the row as data (interpolates it);
- ``sweep_only``: only a sweep table has it (the impact itself never does).
"""

from __future__ import annotations

from typing import NamedTuple


class Status(NamedTuple):
    """One status: its name, kernel code, meaning, and what a row with it holds."""

    name: str
    code: int | None
    message: str
    finished: bool
    has_data: bool
    sweep_only: bool = False


#: The statuses, in the order they are documented and listed.
TABLE: tuple[Status, ...] = (
    Status("ok", 0, "finished; all outputs valid", True, True),
    Status("vc0_zero", None, "finished; v_c0 = 0, so no tangential force and e_x, beta_x are "
           "undefined (NaN)", True, False),
    Status("normal_only", None, "finished; the scene asked for the normal impact only "
           "(tangential = 'none'): e_x, beta_x not computed (NaN)", True, False),
    Status("stuck", None, "finished; adhesion held the sphere: it turned back towards the "
           "surface while in contact, or creeps to rest in a contact that provably never "
           "changes, and does not separate, e_z = 0 (an adhesive impact, normal only: e_x, "
           "beta_x NaN)", True, False),
    Status("half_space", None, "finished, but the contact half-width exceeded 0.2 R: outside "
           "the half-space model", True, False),
    Status("time_limit", 1, "the impact had not ended at the time limit (Numerics.max_time); "
           "outputs NaN", False, False),
    Status("row_exceeded", 2, "the contact reached the end of the element row; outputs NaN",
           False, False),
    Status("non_finite", 3, "the integration produced a non-finite value; outputs NaN",
           False, False),
    Status("unstable", None, "the numerical solution gained energy (the contact energy, normal "
           "plus the contact point's effective tangential energy, rose above 1 + 1e-6 of its "
           "start) although the material and the incremental tangential rule are passive: the "
           "step was too coarse for this scene; outputs NaN (refine: more steps or elements)",
           False, False),
    Status("energy_gain", None, "finished, but explicit Euler gained energy (more than 1e-6 of "
           "the contact energy), as it does by construction: numbers kept as the thesis's "
           "integrator gives them, not converged (use verlet)", True, False),
    Status("not_passive", None, "finished, but the seed tangential memory (not passive) gained "
           "energy or gave |e_z| or |beta_x| above 1 + 1e-6: numbers kept as its rule gives "
           "them, not physical (the incremental memory is passive)", True, False),
    Status("unresolved", None, "the contact lasted fewer time steps than the element path needs "
           "to resolve it (numerics.MIN_CONTACT_STEPS); outputs NaN (more steps, or the "
           "continuum path)", False, False),
    Status("too_costly", None, "the element path would need more steps or elements than its "
           "cost bounds (numerics.MAX_STEPS_PER_T_H, MAX_ELEMENTS_IN_ROW) for this scene; "
           "outputs NaN (reason in the error column)", False, False),
    Status("tolerance_unreachable", None, "the numerics' tolerance is below what the element "
           "path this scene needs can reach, or its error is not bounded there (the seed "
           "memory); reason in the error column; outputs NaN", False, False),
    Status("invalid", None, "the row's inputs are not a valid scene (reason in the error "
           "column); outputs NaN", False, False),
    Status("failed", None, "the simulation raised an error (message in the error column); "
           "outputs NaN", False, False, sweep_only=True),
)

#: name -> Status
BY_NAME: dict[str, Status] = {s.name: s for s in TABLE}
#: kernel code -> name, for the statuses a kernel writes
BY_CODE: dict[int, str] = {s.code: s.name for s in TABLE if s.code is not None}
#: status of a row whose inputs are not a valid scene (it never ran)
INVALID = "invalid"


def code(name: str) -> int:
    """Return the kernel code of status ``name`` (``KeyError`` if it has none)."""
    value = BY_NAME[name].code
    if value is None:
        raise KeyError(f"status {name!r} is not written by a kernel")
    return value
