"""How finely the element path resolves each scene: step, element row, time limit.

Vectorized over a batch (:class:`vimpact.engine.columns.SceneColumns`); the
one rule for the kernels, the NumPy reference and the benchmarks.
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.kernels.layout import EULER
from vimpact.model.hertz import HERTZ_TIME_FACTOR
from vimpact.model.numerics import Numerics

#: ``kappa mu_t`` of a solid sphere (Theta = 2/5 m R^2) at nu = 0.5: the
#: tangential stiffness the default numerics are calibrated on.
SOLID_SPHERE_STIFFNESS = 2.0 / 3.0 * 3.5

#: Longest creep-back stretch of the time limit, in units of the Hertz time factor.
MAX_TIME_STRETCH = 1e4


def stiffness_ratio(cols) -> np.ndarray:
    """Return how much stiffer than relaxed the half-space acts in contact, per row.

    How much stiffer than the relaxed modulus the half-space acts during the
    contact, ``1 + sum g_i tau_i / (tau_i + t_H)`` (``g_i = G_i / G_inf``):
    an arm whose time is long against the Hertz time is a spring, one whose
    time is short relaxes away. Dimensionless, >= 1, one value per row.
    """
    if not cols.G_arm.shape[1]:  # no arm column: 1 (what the sum of none gives)
        return np.ones(cols.G_inf.shape[0])
    g = cols.G_arm / cols.G_inf[:, None]
    tau = cols.tau_arm
    return 1.0 + _arm_sum(g * tau / (tau + cols.t_H[:, None]))


def refinement(cols, numerics: Numerics, tangential: np.ndarray | bool, integrator: int
               ) -> tuple[np.ndarray, np.ndarray]:
    """Return the factors (>= 1) refining the time step and the element spacing, per row.

    Factors (>= 1) by which the time step and the element spacing are made
    finer than ``t_H / steps`` and ``a_H / elements``, per row: the numerics
    resolve the stiffest mode as well as they resolve a relaxed elastic impact.

    - A glassy half-space (arms stiffer than the relaxed spring, with times
      long against the contact) makes a Hertz contact of ``r =``
      :func:`stiffness_ratio` times the modulus: ``r^(-2/5)`` times shorter
      and ``r^(-1/5)`` times narrower. Steps and elements scale with it.
    - Tangential problem (rows where ``tangential``): its oscillation is
      ``sqrt(kappa mu_t)`` times faster than the normal one (``kappa = c_t /
      c_n``, ``mu_t`` the contact-point mass factor), so the step resolves it
      as well (``Theta / (m R^2) = 1e-3`` gives about 26); it also feels each
      element entering the contact: elements finer by ``(kappa mu_t / 2.33)^(1/4)``
      (a heuristic exponent measured to bring ``Theta/(m R^2) = 1e-3`` within
      5e-4 of a twice finer run, not a derived one).
    - Viscous terms that are explicit in part of the step (the dashpot under
      explicit Euler; arms whose time is below the step, which act as
      dashpots ``G_i tau_i``, under every integrator) keep ``h C <= 1`` with
      the largest damping coefficient ``C`` the row can have.
    - Stability of the explicit kicks: ``h omega <= 1/2`` for the stiffest
      spring on the scale of one step (all arms slower than the step).
    """
    arms = cols.G_arm.shape[1] > 0  # (without an arm column its terms are 0: not computed)
    if arms:
        r = stiffness_ratio(cols)
        time_factor, element_factor = r ** 0.4, r ** 0.2
    else:  # r = 1 exactly, and 1 ** y = 1
        time_factor = element_factor = np.ones(cols.G_inf.shape[0])
    if isinstance(tangential, (bool, np.bool_)):  # one value for all rows (the element path)
        # the same numbers as the masks below, without the masks (where, factors of 1)
        stiff_t = cols.kappa * cols.contact_mass_factor if tangential else 0.0
        if tangential:
            time_factor = time_factor * np.maximum(1.0, np.sqrt(stiff_t))
            element_factor = element_factor * np.maximum(
                1.0, (stiff_t / SOLID_SPHERE_STIFFNESS) ** 0.25)
    else:
        stiff_t = np.where(tangential, cols.kappa * cols.contact_mass_factor, 0.0)
        time_factor = time_factor * np.where(tangential, np.maximum(1.0, np.sqrt(stiff_t)), 1.0)
        element_factor = element_factor * np.where(
            tangential, np.maximum(1.0, (stiff_t / SOLID_SPHERE_STIFFNESS) ** 0.25), 1.0)
    if arms:
        g = cols.G_arm / cols.G_inf[:, None]
        tau_T = cols.tau_arm / cols.T[:, None]
    h = HERTZ_TIME_FACTOR / numerics.steps / time_factor
    stiff_floor = np.maximum(1.0, stiff_t)
    # without arms and with an implicit dashpot no viscous term is explicit: h C = 0, a
    # factor of 1 (an infinite stiff_t gives NaN either way), not computed
    if arms or integrator == EULER:
        viscous = _arm_sum(np.where(tau_T < h[:, None], g * tau_T, 0.0)) if arms else 0.0
        if integrator == EULER:
            viscous = viscous + cols.dashpot_time / cols.T
        rate = 15.0 / 8.0 * viscous * numerics.row_width * stiff_floor
        time_factor = time_factor * np.maximum(1.0, h * rate)
        h = HERTZ_TIME_FACTOR / numerics.steps / time_factor
    springs = 1.0 + (_arm_sum(np.where(tau_T >= h[:, None], g, 0.0)) if arms else 0.0)
    omega = np.sqrt(15.0 / 8.0 * numerics.row_width * springs * stiff_floor)
    time_factor = time_factor * np.maximum(1.0, 2.0 * h * omega)
    return time_factor, element_factor


def time_limit(cols, numerics: Numerics) -> np.ndarray:
    """Time limit of each impact in units of ``T``.

    ``max_time`` Hertz times, stretched by the slow creep back of a viscous surface.
    """
    viscous = cols.dashpot_time  # s (+ the arms'; without an arm column a sum of none)
    if cols.G_arm.shape[1]:
        viscous = viscous + _arm_sum(cols.G_arm * cols.tau_arm) / cols.G_inf
    stretch = np.minimum(10.0 * viscous / cols.T, MAX_TIME_STRETCH)
    return numerics.max_time * HERTZ_TIME_FACTOR * (1.0 + stretch)


def element_row(cols, numerics: Numerics, tangential: np.ndarray | bool, integrator: int
                ) -> dict:
    """Return the element row and time step of each row, kernel units.

    Step ``h`` / T, element spacing ``dxi`` / a_H, elements in the half row
    ``n_elem`` and the time limit in steps ``max_steps``, per row.
    """
    if isinstance(tangential, bool) and cols.G_arm.shape == (1, 0):
        row = _element_row_one(cols, numerics, tangential, integrator)
        if row is not None:
            return row
    time_factor, element_factor = refinement(cols, numerics, tangential, integrator)
    h = HERTZ_TIME_FACTOR / numerics.steps / time_factor
    per_a_H = np.ceil(numerics.elements * element_factor)
    return {
        "h": h,
        "dxi": 1.0 / per_a_H,
        "n_elem": _count(numerics.row_width * per_a_H),
        "max_steps": _count(time_limit(cols, numerics) / h),
    }


def _element_row_one(cols, numerics: Numerics, tangential: bool, integrator: int
                     ) -> dict | None:
    """:func:`element_row` of one row without an arm column, on Python floats.

    :func:`refinement` and :func:`time_limit` with their terms of no arm (factors
    of 1, sums of none) left out and the rest in the same operations in the same
    order on the row's values (IEEE arithmetic and square roots: the same numbers;
    the one power stays a NumPy array operation, whose SIMD result can differ from
    the C library's in the last bit), for :func:`vimpact.simulate`, where the array
    operations cost more than the arithmetic. ``None`` if a value is not finite:
    the array form then decides (``tests/engine/test_columns.py`` checks the two agree).
    """
    stiff_t = float(cols.kappa[0]) * float(cols.contact_mass_factor[0]) if tangential else 0.0
    time_factor = element_factor = 1.0
    if tangential:
        time_factor = _at_least_1(math.sqrt(stiff_t))
        element_factor = _at_least_1(
            float((np.array([stiff_t / SOLID_SPHERE_STIFFNESS]) ** 0.25)[0]))
    h = HERTZ_TIME_FACTOR / numerics.steps / time_factor
    stiff_floor = _at_least_1(stiff_t)
    T = float(cols.T[0])
    dashpot_T = float(cols.dashpot_time[0]) / T
    if integrator == EULER:
        rate = 15.0 / 8.0 * (0.0 + dashpot_T) * numerics.row_width * stiff_floor
        time_factor = time_factor * _at_least_1(h * rate)
        h = HERTZ_TIME_FACTOR / numerics.steps / time_factor
    omega = math.sqrt(15.0 / 8.0 * numerics.row_width * 1.0 * stiff_floor)
    time_factor = time_factor * _at_least_1(2.0 * h * omega)
    h = HERTZ_TIME_FACTOR / numerics.steps / time_factor
    per_a_H = numerics.elements * element_factor
    stretch = 10.0 * float(cols.dashpot_time[0]) / T
    limit = numerics.max_time * HERTZ_TIME_FACTOR * (
        1.0 + (MAX_TIME_STRETCH if stretch > MAX_TIME_STRETCH else stretch))  # (NaN stays)
    if not all(map(math.isfinite, (h, per_a_H, limit, limit / h))):
        return None
    per_a_H = float(math.ceil(per_a_H))
    n_elem, max_steps = numerics.row_width * per_a_H, limit / h
    if n_elem > 2.0**62 or max_steps > 2.0**62:  # (saturated: _count)
        return None
    return {
        "h": np.array([h]),
        "dxi": np.array([1.0 / per_a_H]),
        "n_elem": np.array([math.ceil(n_elem)], dtype=np.int64),
        "max_steps": np.array([math.ceil(max_steps)], dtype=np.int64),
    }


def _at_least_1(x: float) -> float:
    """``np.maximum(1.0, x)`` of a float (NaN stays NaN)."""
    return 1.0 if x <= 1.0 else x


def _arm_sum(x: np.ndarray) -> np.ndarray:
    """Sum over the arms (axis 1) of ``(n, k)`` values; zeros without an arm column.

    The same numbers (a sum of none), without NumPy's reduction, which costs more than
    the one-row arithmetic around it (:func:`vimpact.simulate`).
    """
    return x.sum(axis=1) if x.shape[1] else np.zeros(x.shape[0])


def _count(x: np.ndarray) -> np.ndarray:
    """``ceil(x)`` as int64, saturated far below the int64 range (callers refuse such rows)."""
    return np.ceil(np.minimum(x, 2.0**62)).astype(np.int64)
