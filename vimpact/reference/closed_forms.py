"""Closed forms and high-accuracy reference solutions (oracles for the kernels).

- :func:`linear_model`: the simplified linear spring-dashpot model
  (docs/physics.md#linear-model), all damping regimes in real arithmetic.
- :func:`hertz_time_factor_quadrature`: the Hertz contact time ``t_H / T`` by
  quadrature, an independent check of :data:`vimpact.model.hertz.HERTZ_TIME_FACTOR`.
- :func:`kelvin_voigt_continuum`: the normal Kelvin-Voigt impact in the
  continuum limit (docs/physics.md#kelvin-voigt-continuum), a one-degree-of-freedom ODE solved
  to about 1e-12.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np
from scipy.integrate import quad, solve_ivp
from scipy.special import beta

from vimpact.model.hertz import HERTZ_TIME_FACTOR, Q1_PER_TAU

__all__ = [
    "LinearModelResult",
    "KelvinVoigtResult",
    "linear_model",
    "linear_model_zeta",
    "linear_tangential_frequency",
    "hertz_time_factor_quadrature",
    "kelvin_voigt_continuum",
    "kelvin_voigt_small_damping_slope",
]


# --------------------------------------------------------------------------
# input checks
# --------------------------------------------------------------------------

def _as_float_array(name: str, value) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number or array of real numbers, got {value!r}") from None
    return arr


def _check(name: str, arr: np.ndarray, ok: np.ndarray, allowed: str) -> None:
    """Raise ``ValueError`` naming ``name`` and its first offending value."""
    bad = ~(ok & np.isfinite(arr))
    if np.any(bad):
        first = float(arr[bad].flat[0])
        raise ValueError(f"{name} must be finite and {allowed}, got {name} = {first!r}")


def _scalar_or_array(x: np.ndarray) -> float | np.ndarray:
    return float(x) if x.ndim == 0 else x


# --------------------------------------------------------------------------
# 1. the simplified linear model (docs/physics.md#linear-model)
# --------------------------------------------------------------------------

class LinearModelResult(NamedTuple):
    """Result of the linear spring-dashpot impact.

    Attributes
    ----------
    t_star : contact time, s (or in units of ``1/omega0`` from
        :func:`linear_model_zeta`)
    e : coefficient of restitution ``|du/dt(t*)| / v0``, -
    """

    t_star: float | np.ndarray
    e: float | np.ndarray


#: Half-width of the band ``|zeta - 1| < _CRITICAL_BAND`` in which the
#: contact time is taken from its Taylor series about ``zeta = 1``.
_CRITICAL_BAND = 1e-3

#: Taylor coefficients ``c_k`` of ``asin(s)/s = sum_k c_k s^(2k)``,
#: ``c_k = (2k)! / (4^k (k!)^2 (2k+1))``.
_ASIN_SERIES = tuple(
    math.comb(2 * k, k) / (4**k * (2 * k + 1)) for k in range(7)
)


def _scaled_contact_time(zeta: np.ndarray) -> np.ndarray:
    """``omega0 * t*`` of the linear model as a function of ``zeta >= 0``.

    One real-analytic function covers all regimes:
    ``omega0 t* = 2 arccos(zeta) / sqrt(1 - zeta^2)``  (``zeta < 1``),
    ``2`` (``zeta = 1``), ``2 arccosh(zeta) / sqrt(zeta^2 - 1)`` (``zeta > 1``).
    Near ``zeta = 1`` both quotients are ``0/0``-like, so within
    ``|zeta - 1| < 1e-3`` the common Taylor series
    ``2 sum_k c_k w^k`` in ``w = 1 - zeta^2`` is used (truncation error
    below 1e-17, so the function is smooth to rounding through the band edges).
    """
    z = zeta
    near = np.abs(z - 1.0) < _CRITICAL_BAND
    under = (z < 1.0) & ~near
    over = (z > 1.0) & ~near

    # Safe placeholder arguments where a branch is not used (no warnings).
    zu = np.where(under, z, 0.0)
    zo = np.where(over, z, 2.0)
    zn = np.where(near, z, 1.0)

    t_under = 2.0 * np.arccos(zu) / np.sqrt((1.0 - zu) * (1.0 + zu))
    # sqrt(zo-1)*sqrt(zo+1) instead of sqrt(zo**2-1): no overflow, no cancellation
    t_over = 2.0 * np.arccosh(zo) / (np.sqrt(zo - 1.0) * np.sqrt(zo + 1.0))
    w = (1.0 - zn) * (1.0 + zn)
    series = np.zeros_like(w)
    for c in reversed(_ASIN_SERIES):
        series = series * w + c
    t_near = 2.0 * series

    return np.where(under, t_under, np.where(over, t_over, t_near))


def linear_model(omega0, delta) -> LinearModelResult:
    """Contact time and restitution of the linear spring-dashpot impact.

    A mass on a spring and dashpot in parallel (``omega0^2 = k/m``,
    ``2 delta = c/m``), ``m u'' + c u' + k u = 0``, ``u(0) = 0``,
    ``u'(0) = v0``; contact ends at the first ``t* > 0`` where the force
    ``k u + c u'`` returns to zero (docs/physics.md#linear-model).

    With ``zeta = delta / omega0`` the docs/physics.md closed forms reduce to

    - ``zeta < 1``: ``omega0 t* = 2 arccos(zeta) / sqrt(1 - zeta^2)``
      (i.e. ``omega_d t* = atan2(2 delta omega_d, 2 delta^2 - omega0^2)``)
    - ``zeta = 1``: ``omega0 t* = 2``
    - ``zeta > 1``: ``omega0 t* = 2 arccosh(zeta) / sqrt(zeta^2 - 1)``
      (i.e. ``t* = ln((2delta^2 - omega0^2 + 2 delta g)/(2delta^2 - omega0^2 - 2 delta g)) / (2g)``)

    and in every regime ``e = exp(-delta t*)``. Only real arithmetic is used.
    Within ``|zeta - 1| < 1e-3`` the contact time comes from its Taylor series
    about ``zeta = 1`` (error below 1e-17), so the result is continuous and
    smooth through ``zeta = 1`` to rounding.

    Parameters
    ----------
    omega0 : float or array_like
        Undamped angular frequency ``sqrt(k/m)``, 1/s; finite and > 0.
    delta : float or array_like
        Decay rate ``c / (2m)``, 1/s; finite and >= 0. Broadcast with ``omega0``.

    Returns
    -------
    LinearModelResult
        ``t_star`` (s) and ``e`` (-); floats for scalar input, arrays otherwise.

    Raises
    ------
    ValueError
        If ``omega0`` is not finite and positive or ``delta`` not finite and
        non-negative.
    """
    w0 = _as_float_array("omega0", omega0)
    d = _as_float_array("delta", delta)
    _check("omega0", w0, w0 > 0.0, "> 0 (1/s)")
    _check("delta", d, d >= 0.0, ">= 0 (1/s)")
    w0, d = np.broadcast_arrays(w0, d)
    zeta = d / w0
    tau = _scaled_contact_time(zeta)
    t_star = tau / w0
    e = np.exp(-zeta * tau)
    return LinearModelResult(_scalar_or_array(t_star), _scalar_or_array(e))


def linear_model_zeta(zeta) -> LinearModelResult:
    """Linear model in units of ``1/omega0``: returns ``(omega0 t*, e)``.

    Parameters
    ----------
    zeta : float or array_like
        Damping ratio ``delta / omega0``, -; finite and >= 0.

    Returns
    -------
    LinearModelResult
        ``t_star`` = ``omega0 t*`` (-) and ``e`` (-).
    """
    z = _as_float_array("zeta", zeta)
    _check("zeta", z, z >= 0.0, ">= 0")
    return linear_model(1.0, z)


def linear_tangential_frequency(k_x, m, R, Theta):
    """Angular frequency of the tangential linear model (docs/physics.md#linear-model).

    ``omega_x = sqrt((1 + m R^2 / Theta) k_x / m)``: a tangential spring acting
    at the contact point of a sphere that can both slide and roll.

    Parameters
    ----------
    k_x : float or array_like
        Tangential spring stiffness, N/m; > 0.
    m : float or array_like
        Sphere mass, kg; > 0.
    R : float or array_like
        Sphere radius, m; > 0.
    Theta : float or array_like
        Moment of inertia about the centre, kg m^2; > 0.

    Returns
    -------
    float or numpy.ndarray
        ``omega_x`` in 1/s.
    """
    args = {}
    for name, value, unit in (("k_x", k_x, "N/m"), ("m", m, "kg"), ("R", R, "m"), ("Theta", Theta, "kg m^2")):
        arr = _as_float_array(name, value)
        _check(name, arr, arr > 0.0, f"> 0 ({unit})")
        args[name] = arr
    k_x, m, R, Theta = args["k_x"], args["m"], args["R"], args["Theta"]
    return _scalar_or_array(np.sqrt((1.0 + m * R**2 / Theta) * k_x / m))


# --------------------------------------------------------------------------
# 2. Hertz contact time by quadrature
# --------------------------------------------------------------------------

def hertz_time_factor_quadrature() -> float:
    """``t_H / T = 2 int_0^1 dxi / sqrt(1 - xi^(5/2))`` by numerical quadrature.

    The integrand has an inverse-square-root singularity at ``xi = 1``;
    substituting ``xi = 1 - s^2`` gives the smooth integrand
    ``2 s / sqrt(1 - (1 - s^2)^(5/2))`` (limit ``2 / sqrt(5/2)`` at ``s = 0``),
    whose denominator is evaluated as ``-expm1(2.5 log1p(-s^2))`` to avoid
    cancellation. Independent of the Beta-function closed form in
    :data:`vimpact.model.hertz.HERTZ_TIME_FACTOR`; docs/physics.md quotes 2.9432751843.

    Returns
    -------
    float
        ``t_H / T``, - (about 2.9432751843).
    """

    def integrand(s: float) -> float:
        if s == 0.0:
            return 2.0 / math.sqrt(2.5)
        return 2.0 * s / math.sqrt(-math.expm1(2.5 * math.log1p(-s * s)))

    value, _ = quad(integrand, 0.0, 1.0, epsabs=1e-14, epsrel=1e-13, limit=200)
    return 2.0 * value


# --------------------------------------------------------------------------
# 3. Kelvin-Voigt continuum normal impact (docs/physics.md#kelvin-voigt-continuum)
# --------------------------------------------------------------------------

class KelvinVoigtResult(NamedTuple):
    """Normal Kelvin-Voigt impact in the continuum limit, kernel units.

    Attributes
    ----------
    e_z : normal coefficient of restitution ``|v_z,end| / v_z0``, -
    t_contact_over_T : contact time in units of ``T = d / v_z0``, -
    u_max_over_d : maximum indentation in units of the elastic ``d``, -
    """

    e_z: float | np.ndarray
    t_contact_over_T: float | np.ndarray
    u_max_over_d: float | np.ndarray


def kelvin_voigt_small_damping_slope() -> float:
    """First-order slope ``(1 - e_z) / (tau/T) = 1.5 B(3/5, 3/2) = 1.8917...``, -.

    docs/physics.md#kelvin-voigt-continuum; in terms of ``Q1``: ``1 - e_z = slope / Q1_PER_TAU * Q1``.
    """
    return 1.5 * float(beta(0.6, 1.5))


class _Event:
    """A terminal event of :func:`scipy.integrate.solve_ivp`.

    ``fn(t, y)`` crossing zero in ``direction`` (-1: from above) stops the integration.
    """

    terminal = True

    def __init__(self, fn, direction: int):
        self.fn, self.direction = fn, direction

    def __call__(self, t, y):
        return self.fn(t, y)


@functools.lru_cache(maxsize=512)
def _kv_single(tau_hat: float, rtol: float) -> tuple[float, float, float]:
    """One Kelvin-Voigt continuum impact; see :func:`kelvin_voigt_continuum`.

    Deterministic in its two floats and 10-70 ms of CPU a call: kept for the
    process (a few hundred bytes each), so the tests that ask for the same
    ``q1`` and ``rtol`` again get the same numbers without solving again.
    """
    a = 1.25                # Hertz force coefficient, 5/4
    c = 1.875 * tau_hat     # viscous coefficient, 15/8 tau_hat
    atol = 1e-4 * rtol
    t_end_max = 10.0 * HERTZ_TIME_FACTOR   # contact time is below the elastic one
    opts = dict(method="DOP853", rtol=rtol, atol=atol)

    # Start: u = t + alpha t^(5/2) + beta t^(7/2) + gamma t^4 + O(t^5) solves the
    # loading equation near t = 0, where sqrt(u) is not smooth. t0 keeps the
    # neglected terms (relative size (tau_hat t0^(3/2))^3, t0^4) below 1e-15.
    t0 = 1e-4 if tau_hat == 0.0 else min(1e-4, (1e-5 / tau_hat) ** (2.0 / 3.0))
    alpha, beta_, gamma = -0.5 * tau_hat, -1.0 / 7.0, 15.0 * tau_hat**2 / 64.0
    u0 = t0 + alpha * t0**2.5 + beta_ * t0**3.5 + gamma * t0**4
    v0 = 1.0 + 2.5 * alpha * t0**1.5 + 3.5 * beta_ * t0**2.5 + 4.0 * gamma * t0**3

    def loading(t, y):
        u, v = y
        return [v, -(a * u + c * v) * math.sqrt(max(u, 0.0))]

    turning = _Event(lambda t, y: y[1], direction=-1)  # v = 0 from above
    s1 = solve_ivp(loading, (t0, t_end_max), [u0, v0], events=turning, **opts)
    if s1.status != 1:
        raise RuntimeError(f"Kelvin-Voigt reference: no turning point (tau_hat={tau_hat!r}): {s1.message}")
    t1 = float(s1.t_events[0][0])
    u_max = float(s1.y_events[0][0][0])

    # Unloading in the variables (w, v), w = u + tau_hat v: the end event w = 0
    # is then a state crossing zero instead of a cancelling sum, which keeps
    # the contact time accurate when v_end is tiny (large tau_hat).
    def unloading(t, y):
        w, v = y
        f = a * max(w, 0.0) ** 1.5
        return [v - tau_hat * f, -f]

    separation = _Event(lambda t, y: y[0], direction=-1)  # w = 0 from above
    s2 = solve_ivp(unloading, (t1, t1 + t_end_max), [u_max, 0.0], events=separation, **opts)
    if s2.status != 1:
        raise RuntimeError(f"Kelvin-Voigt reference: no separation (tau_hat={tau_hat!r}): {s2.message}")
    t2 = float(s2.t_events[0][0])
    v_end = float(s2.y_events[0][0][1])
    return abs(v_end), t2, u_max


def kelvin_voigt_continuum(q1, rtol: float = 1e-12) -> KelvinVoigtResult:
    """Solve the normal impact of a rigid sphere on a Kelvin-Voigt half-space, continuum limit.

    Kernel units (docs/physics.md#hertz-scales, docs/physics.md#kelvin-voigt-continuum,
    docs/physics.md#dimensionless-parameters): indentation ``u`` in units of
    ``d``, velocity in ``v_z0``, time in ``T = d / v_z0``, force in
    ``m v_z0^2 / d``; ``tau_hat = tau / T = q1 / Q1_PER_TAU``. The ODE

    - loading (``v >= 0``):  ``F = 5/4 u^(3/2) + 15/8 tau_hat sqrt(u) v``
    - unloading (``v < 0``): ``F = 5/4 (u + tau_hat v)^(3/2)``

    ``du/dt = v``, ``dv/dt = -F``, ``u(0) = 0``, ``v(0) = 1`` is integrated
    until ``u + tau_hat v = 0``, where the contact ends and ``e_z = |v|``.

    Numerics: ``scipy.integrate.solve_ivp`` with DOP853, ``atol = 1e-4 rtol``,
    an event at ``v = 0`` (switch of branch, gives ``u_max``) and an event at
    ``w = u + tau_hat v = 0``; the unloading branch is integrated in
    ``(w, v)``. The start at ``u = 0`` (where ``sqrt(u)`` is not smooth) uses the
    series ``u = t - tau_hat/2 t^(5/2) - t^(7/2)/7 + 15/64 tau_hat^2 t^4`` up to
    a small ``t0 <= 1e-4``. The problem is not stiff enough to need an implicit
    method: DOP853 needs about 1000-2500 right-hand-side evaluations for every
    ``q1`` from 0 to 1e7, while Radau needs 10-40 times more for no gain.
    Accuracy at the default ``rtol = 1e-12``: about 1e-12 in ``e_z`` and
    ``u_max``; ``t_contact`` about 1e-11 for ``q1 <= 100``, degrading for
    larger ``q1`` (about 1e-7 at 1e4), where the contact ends in a long
    force-free-like tail with a tiny rebound speed.

    Parameters
    ----------
    q1 : float or array_like
        Damping parameter ``Q1 = sqrt(15/32) (eta/G) / T``, -; finite and
        >= 0 (0 gives the elastic impact). Arrays are handled element by
        element (a reference solution, not a kernel).
    rtol : float, optional
        Relative tolerance of the integrator, in [1e-13, 1e-6].

    Returns
    -------
    KelvinVoigtResult
        ``(e_z, t_contact_over_T, u_max_over_d)``; floats for scalar ``q1``,
        arrays of the shape of ``q1`` otherwise.

    Raises
    ------
    ValueError
        If ``q1`` is negative or not finite, or ``rtol`` is out of range.
    """
    q = _as_float_array("q1", q1)
    _check("q1", q, q >= 0.0, ">= 0")
    if not (isinstance(rtol, (int, float, np.floating)) and 1e-13 <= rtol <= 1e-6):
        raise ValueError(f"rtol must be a float in [1e-13, 1e-6], got rtol = {rtol!r}")

    out = np.empty((3,) + q.shape)
    for idx in np.ndindex(q.shape):
        out[(slice(None),) + idx] = _kv_single(float(q[idx]) / Q1_PER_TAU, float(rtol))
    return KelvinVoigtResult(*(_scalar_or_array(x) for x in out))
