"""Extreme but admissible inputs end in a converged answer or a status.

Hypothesis draws batches of scenes whose physical inputs span about 30 decades
(``G_inf``, ``R``, ``v_z0`` each log-uniform over [1e-15, 1e15] in its SI
unit; ``m`` mostly the mass whose Hertz indentation is 1e-24 ... 0.03 times ``R``, so
that most rows stay inside the half-space model, else also over 30 decades; ``v_x0`` and
``R omega0`` up to 1e15 ``v_z0`` of either sign, ``nu``
anywhere in [0, 0.5] with both ends) for every model, and runs each batch with
one :func:`vimpact.simulate_batch` call. The viscous inputs are drawn as raw
SI numbers too (``eta`` over 30 decades around the scene's own ``G_inf T``), so
``Q1`` itself spans dozens of decades; the arm moduli of the standard solid and
the Prony series are drawn relative to ``G_inf`` over [1e-3, 1e3] and their times
relative to ``T`` over [1.3e-3, 1e4] in the default run (the full-stick continuum
path) and over [1e-4, 1e4] in the ``slow`` run (with Coulomb friction ``mu`` in
[1e-3, 10] besides full stick, which takes the element path; further
out it is refused as too costly or runs for minutes: cost, not correctness, which
the catalogues cover with single extreme rows).

Every row must be one of

- status ``ok`` (or the finished ``vc0_zero``, ``normal_only``, ``half_space``)
  with finite outputs in their physical ranges, exactly (rounding above a bound
  is set to it, docs/physics.md#energy-and-passivity): ``0 <= e_z <= 1``,
  ``|beta_x| <= 1`` and ``e_x = |beta_x|`` where a tangential problem is
  solved, ``t_contact, u_max, a_max > 0``, and ``energy_ratio <= 1`` (every
  scene here is passive: incremental memory; a held spin, ``rotation = False``
  with ``omega0 != 0``, counts the work that holds it);
- or a status that is not ``ok`` with a reason in the ``error`` column, all
  outputs NaN;

and ``simulate_batch`` never raises. ``derandomize=True``: the examples are a
function of the test alone.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import vimpact as v
from vimpact.engine.result import FINISHED
from vimpact.engine.unpack import OUTPUTS, TANGENTIAL_OUTPUTS
from vimpact.model.hertz import hertz_scales

SETTINGS = dict(deadline=None, derandomize=True, database=None, print_blob=False,
                phases=(Phase.explicit, Phase.reuse, Phase.generate),
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

#: Rows per example (one simulate_batch call each).
ROWS = 6
FAST = v.Numerics.preset("fast")


# Each strategy is built once (functools.cache and the constants below): building it
# inside the composite on every draw (and Hypothesis validating it again) cost more than
# the simulations. The draws are the same (the examples are a function of the choices).
@functools.cache
def _decades(lo: float, hi: float):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False).map(lambda x: 10.0 ** x)


@functools.cache
def _signed(lo: float, hi: float):
    return st.one_of(st.just(0.0), st.tuples(st.sampled_from((-1.0, 1.0)), _decades(lo, hi))
                     .map(lambda p: p[0] * p[1]))


MODEL = st.sampled_from(v.MODELS)
NU = st.one_of(st.sampled_from((0.0, 0.5)), st.floats(0.0, 0.5))
ONE_IN_FIVE = st.integers(0, 4)
THETA_RATIO = st.one_of(st.just(0.4), _decades(-3.0, 0.0))
TANGENTIAL = st.sampled_from(("auto", "stick", "none"))
MU = st.one_of(st.just(math.inf), _decades(-3.0, 1.0))
ARM_COUNT = st.integers(1, 3)
ETA0_PER_G_T = st.one_of(st.just(0.0), _decades(-6.0, 2.0))


@st.composite
def rows(draw, fast_arms: bool = False) -> dict:
    """One scene as a dict of input columns (SI units); arm times from 1e-4 T with
    ``fast_arms`` (with friction: the element path), else from 1.3e-3 T (full stick
    only: no element kernel to compile in the default run)."""
    tau_lo = -4.0 if fast_arms else -2.9
    model = draw(MODEL)
    nu = draw(NU)
    G = draw(_decades(-15.0, 15.0))
    R = draw(_decades(-15.0, 15.0))
    v_z0 = draw(_decades(-15.0, 15.0))
    # the mass: mostly the one that puts the Hertz indentation d at 1e-24 ... 0.03 R (a_H
    # <= 0.18 R: most rows stay inside the half-space model and reach the kernels), else free
    depth = draw(_decades(-24.0, -1.5)) if draw(ONE_IN_FIVE) < 4 else None
    E_star = 2.0 * G / (1.0 - nu)
    m = 16.0 * E_star * math.sqrt(R) * (depth * R) ** 2.5 / (15.0 * v_z0**2) if depth else 0.0
    if not (math.isfinite(m) and 0.0 < m < 1e300):
        m = draw(_decades(-15.0, 15.0))
    row = {"model": model, "nu": nu, "G_inf_Pa": G, "R_m": R, "m_kg": m, "v_z0_m_s": v_z0,
           "v_x0_m_s": draw(_signed(-15.0, 15.0)) * v_z0,
           "omega0_rad_s": draw(_signed(-15.0, 15.0)) * v_z0 / R,
           "theta_ratio": draw(THETA_RATIO),
           "rotation": draw(st.booleans()),
           "tangential": draw(TANGENTIAL),
           "mu": draw(MU) if fast_arms else math.inf}
    with np.errstate(all="ignore"):
        T = hertz_scales(G, nu, R, m, v_z0).T
    T = T if math.isfinite(T) and T > 0.0 else 1.0
    arms = []
    if model == "kelvin_voigt":
        row["eta0_Pa_s"] = draw(_decades(-15.0, 15.0)) * G * T
    elif model == "standard_solid":
        arms = [(draw(_decades(-3.0, 3.0)) * G, draw(_decades(tau_lo, 4.0)) * T)]
    elif model == "prony":
        n = draw(ARM_COUNT)
        arms = [(draw(_decades(-3.0, 3.0)) * G, draw(_decades(tau_lo, 4.0)) * T)
                for _ in range(n)]
        row["eta0_Pa_s"] = draw(ETA0_PER_G_T) * G * T
    row["arms"] = arms
    return row


def _columns(batch: list[dict]) -> pd.DataFrame:
    k = max(len(r["arms"]) for r in batch)
    data = {key: [r.get(key, 0.0) for r in batch] for key in
            ("model", "nu", "G_inf_Pa", "eta0_Pa_s", "R_m", "m_kg", "v_z0_m_s", "v_x0_m_s",
             "omega0_rad_s", "theta_ratio", "rotation", "tangential", "mu")}
    for i in range(k):  # G = 0: no such arm in this row
        data[f"G_arm{i + 1}_Pa"] = [r["arms"][i][0] if i < len(r["arms"]) else 0.0 for r in batch]
        data[f"tau_arm{i + 1}_s"] = [r["arms"][i][1] if i < len(r["arms"]) else 1.0 for r in batch]
    return pd.DataFrame(data)


def violations(inputs: pd.DataFrame, out: pd.DataFrame) -> list[str]:
    """What is wrong with each row of ``out`` (empty if nothing)."""
    bad = []
    for i, (row, res) in enumerate(zip(inputs.to_dict("records"), out.to_dict("records"))):
        why = []
        status = res["status"]
        if status not in v.STATUSES:
            why.append(f"unknown status {status!r}")
        elif status in FINISHED:
            tangential = (row["tangential"] != "none"
                          and row["v_x0_m_s"] + row["R_m"] * row["omega0_rad_s"] != 0.0)
            for name in OUTPUTS:
                if name in TANGENTIAL_OUTPUTS and not tangential:
                    continue
                if not math.isfinite(res[name]):
                    why.append(f"{name} = {res[name]} with status {status}")
            if not -0.0 <= res["e_z"] <= 1.0:
                why.append(f"e_z = {res['e_z']}")
            if tangential and not (abs(res["beta_x"]) <= 1.0
                                   and res["e_x"] == abs(res["beta_x"])):
                why.append(f"beta_x = {res['beta_x']}, e_x = {res['e_x']}")
            for name in ("t_contact", "u_max", "a_max"):
                if not res[name] > 0.0:
                    why.append(f"{name} = {res[name]}")
            if not res["energy_ratio"] <= 1.0:
                why.append(f"energy_ratio = {res['energy_ratio']} in a passive scene")
        else:
            if not isinstance(res["error"], str) or not res["error"]:
                why.append(f"status {status} without a reason")
            finite = [n for n in OUTPUTS if math.isfinite(res[n])]
            if finite:
                why.append(f"status {status} with numbers in {finite}")
        if why:
            bad.append(f"row {i} {row} -> {status} ({res['error']}): {'; '.join(why)}")
    return bad


def check(batch: list[dict]) -> None:
    inputs = _columns(batch)
    out = v.simulate_batch(inputs, FAST)
    assert len(out) == len(inputs)
    problems = violations(inputs, out)
    assert not problems, "\n".join(problems)


@settings(max_examples=40, **SETTINGS)
@given(st.lists(rows(), min_size=ROWS, max_size=ROWS))
def test_extreme_admissible_inputs_end_in_a_valid_number_or_a_status(batch):
    check(batch)


@pytest.mark.slow  # compiles the element kernel for four sets of effects (minutes when cold)
@settings(max_examples=40, **SETTINGS)
@given(st.lists(rows(fast_arms=True), min_size=ROWS, max_size=ROWS))
def test_extreme_inputs_with_fast_arms_and_friction(batch):
    check(batch)
