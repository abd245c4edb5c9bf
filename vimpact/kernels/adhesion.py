"""Adhesive normal impact on the MDR element row (docs/physics.md#adhesion), kernel units.

Kernel units as in :mod:`vimpact.kernels.elements`: indentation ``u`` and
surface displacements ``w`` in units of the Hertz indentation ``d``, element
positions ``xi`` in units of ``a_H`` (profile ``xi^2``), time in ``T = d / v_z0``,
velocity in ``v_z0``, force in ``m v_z0 / T``; the element stiffness per unit
length is ``15/16`` (relaxed modulus). Moduli relative to ``G_inf``: dashpot
time ``tau0``, arms ``g_i``, ``tau_i``.

Adhesion enters through one number, ``lam = sqrt(2 pi a_H dgamma / E*) / d``
(``E*`` the relaxed effective modulus): the critical stress of an edge element
at ``xi`` is ``-lam sqrt(xi)`` in units of ``E* d`` (the rule of Hess in stress
form). Contact is a block of elements ``[0, n_c)`` from the centre:

- first contact: the centre element touches the sphere; then the contact closes
  outwards (jump into contact) over every element whose gap to the sphere the
  instantaneous elastic stiffness ``1 + sum g_i`` closes with a stress below the
  critical one, ``(1 + sum g_i) gap < lam sqrt(xi)`` (an element that touches,
  ``gap <= 0``, always joins);
- the edge element ``n_c - 1`` detaches when its stress (spring, arms, dashpot at
  the step-end velocity) reaches ``-lam sqrt(xi)``, and the next one is then the
  edge; the cascade of the separation instability runs within the step.

With ``lam = 0`` these are the non-adhesive rules of the element kernel (enter on
touching, leave when the force would pull). Nothing here imports the user-facing
layer; the non-adhesive kernels are not touched by this module.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vimpact.kernels.arms import _arm_stress, _follow, _relax, arm_coefficients
from vimpact.kernels.jit import jit
from vimpact.kernels.layout import (
    ELEMENT_STIFFNESS,
    STATUS_NON_FINITE,
    STATUS_OK,
    STATUS_ROW_EXCEEDED,
    STATUS_TIME_LIMIT,
)

# columns of the adhesive kernel's output row (kernel units)
ADH_VZ_END = 0  # normal velocity at the end / v_z0 (negative: rebound; 0 when stuck)
ADH_T_CONTACT = 1  # contact time / T (stuck: time until sticking was detected)
ADH_U_MAX = 2  # maximum indentation / d
ADH_U_MIN = 3  # least indentation while in contact / d (negative: the sphere was pulled up)
ADH_A_MAX = 4  # maximum contact half-width / a_H
ADH_F_TENSILE = 5  # largest tensile (pulling) force on the sphere / (m v_z0 / T), >= 0
ADH_STUCK = 6  # 1.0: the sphere does not separate (turned back in contact, or certified)
ADH_STATUS = 7  # kernel status code (vimpact.kernels.status)
ADH_STEPS = 8  # time steps taken
ADH_CONTACTS = 9  # number of separate contact intervals
N_ADH_OUT = 10

# columns of the per-step record of :func:`adhesive_record` (kernel units)
REC_T = 0  # time at the end of the step / T
REC_U = 1  # indentation / d
REC_V = 2  # velocity / v_z0
REC_NC = 3  # elements in contact (half row)
REC_V_LYAP = 4  # energy of the fixed contact about its equilibrium (_contact_energy)
REC_E_GRIFFITH = 5  # kinetic + stored in every touched element - dgamma pi a^2
N_REC = 6

#: Steps between two evaluations of the sticking certificate (:func:`_cannot_separate`).
CERTIFY_EVERY = 32
#: Factor on the contact energy in the certificate: covers the step-to-step wobble of
#: the Verlet energy about its continuous-time value (relative ``(omega h)^2 / 4``, far
#: below 3 for any stable step), so the continuous-time bounds hold for the stepped motion.
ENERGY_MARGIN = 4.0


@jit()
def _row_geometry(n_elem, dxi):
    """``xi^2`` and ``sqrt(xi)`` at the element centres ``xi = (j + 1/2) dxi`` (units a_H)."""
    xi2 = np.empty(n_elem)
    sqrt_xi = np.empty(n_elem)
    for j in range(n_elem):
        xi = (j + 0.5) * dxi
        xi2[j] = xi * xi
        sqrt_xi[j] = math.sqrt(xi)
    return xi2, sqrt_xi


@jit(inline="always")
def _edge_stress(j, w, q, g, c0, ve, ARMS):
    """Stress of element ``j`` in contact (units of ``E* d``): spring, arms, dashpot."""
    s = w[j] + c0 * ve
    if ARMS:
        s += _arm_stress(w[j], q[j], g)
    return s


@jit(inline="always")
def _contact_update(u1, n_c, w, q, g, G, c0, ve, xi2, sqrt_xi, lam, ARMS):
    """Close the contact outwards, then open it from the edge; return the new ``n_c``.

    Closing (an element joins) needs the centre touching first; an element beyond
    the edge joins if it touches or if its gap ``w_j - (u1 - xi_j^2)`` closed by the
    instantaneous elastic stiffness ``1 + G`` takes a stress below ``lam sqrt(xi_j)``;
    it then snaps onto the sphere (``w_j = u1 - xi_j^2``, arm variables unchanged).
    Opening: the edge element leaves while its stress is at most ``-lam sqrt(xi)``.
    """
    n = w.shape[0]
    while n_c < n:
        gap = w[n_c] - (u1 - xi2[n_c])
        if gap > 0.0 and (n_c == 0 or (1.0 + G) * gap >= lam * sqrt_xi[n_c]):
            break
        w[n_c] = u1 - xi2[n_c]
        n_c += 1
    while n_c > 0:
        j = n_c - 1
        if _edge_stress(j, w, q, g, c0, ve, ARMS) > -lam * sqrt_xi[j]:
            break
        n_c -= 1
    return n_c


@jit(inline="always")
def _arm_energy(j, w, q, g):
    """``sum_i g_i (w_j - q_ji)^2`` of element ``j`` (twice its arm energy per stiffness)."""
    e = 0.0
    for i in range(g.shape[0]):
        y = w[j] - q[j, i]
        e += g[i] * y * y
    return e


@jit()
def _contact_energy(u, v, n_c, w, q, g, k_el, xi2, ARMS):
    """Energy of the contact ``[0, n_c)`` held fixed, about its equilibrium; and ``u_eq``.

    ``V = v^2 / 2 + K (u - u_eq)^2 / 2 + k_el / 2 sum_j sum_i g_i (w_j - q_ji)^2`` with
    ``K = k_el n_c`` and ``u_eq`` the mean of ``xi_j^2`` (where the springs of the
    relaxed modulus carry no net force). While the contact set does not change,
    ``dV/dt = -C v^2 - k_el sum g_i y_i^2 / tau_i <= 0`` (the dashpots and the arms'
    dampers only dissipate).
    """
    u_eq = 0.0
    arms = 0.0
    for j in range(n_c):
        u_eq += xi2[j]
        if ARMS:
            arms += _arm_energy(j, w, q, g)
    u_eq /= n_c
    K = k_el * n_c
    return 0.5 * v * v + 0.5 * K * (u - u_eq) ** 2 + 0.5 * k_el * arms, u_eq


@jit()
def _cannot_separate(u, v, n_c, touched, w, q, g, G, c0, k_el, xi2, sqrt_xi, lam, ARMS):
    """Return True if the contact ``[0, n_c)`` provably never changes again (the sphere sticks).

    Holding the contact set fixed, the motion is linear and passive, so its energy
    ``V`` (:func:`_contact_energy`) never grows: ``|u - u_eq| <= sqrt(2 V / K)``,
    ``|v| <= sqrt(2 V)`` and the edge element's arm stress
    ``|sum g_i y_i| <= sqrt(2 G V / k_el)`` (Cauchy-Schwarz) for all later times. A free
    element's own energy ``(w^2 + sum g_i y_i^2) / 2`` never grows either (it relaxes
    under zero force), so ``w >= -r`` for an element beyond the edge. If with these
    bounds (``V`` times :data:`ENERGY_MARGIN`) the edge element can never reach its
    detachment stress, and each element beyond it, outwards, either can never join
    (there the contact update stops) or, without arms, would on joining be stretched
    beyond its critical stress and leave in the same update (the edge of a creeping
    peel, whose next element joins and leaves at every step), then the contact set
    at the end of every later step is this one: the sphere comes to rest at ``u_eq``
    in contact and never separates. Sufficient, not necessary: a contact on the
    threshold, or an element with arms that may join, is not certified.
    """
    V, u_eq = _contact_energy(u, v, n_c, w, q, g, k_el, xi2, ARMS)
    Vb = ENERGY_MARGIN * V
    du = math.sqrt(2.0 * Vb / (k_el * n_c))
    e = n_c - 1
    stress_lo = u_eq - du - xi2[e] - c0 * math.sqrt(2.0 * Vb)
    if ARMS:
        stress_lo -= math.sqrt(2.0 * G * Vb / k_el)
    if not stress_lo > -lam * sqrt_xi[e]:
        return False
    u_hi = u_eq + du
    for j in range(n_c, w.shape[0]):
        r = 0.0
        if j < touched:
            r = w[j] * w[j]
            if ARMS:
                r += _arm_energy(j, w, q, g)
            r = math.sqrt(r)
        gap_lo = -r - (u_hi - xi2[j])
        if gap_lo > 0.0 and (1.0 + G) * gap_lo >= lam * sqrt_xi[j]:
            break  # element j never joins: the contact update stops here
        # element j may join; it must then leave in the same update (a spring-dashpot
        # element whose stress on the sphere is beyond its critical one at once)
        if ARMS or not u_hi - xi2[j] + c0 * math.sqrt(2.0 * Vb) <= -lam * sqrt_xi[j]:
            return False
    return True


@jit()
def adhesive_impact(tau0, g, tau, lam, h, n_elem, dxi, max_steps, out):
    """Advance one adhesive normal impact to its end; results into ``out`` (``ADH_*``).

    :func:`adhesive_record` without the record.
    """
    # np.int64: a bare constant would be typed Literal[int] and compile _impact a second
    # time, besides the int64 signature adhesive_record compiles it for
    _impact(tau0, g, tau, lam, h, n_elem, dxi, max_steps, out, np.zeros((0, N_REC)),
            np.int64(CERTIFY_EVERY))


@jit()
def adhesive_record(tau0, g, tau, lam, h, n_elem, dxi, max_steps, out, record, certify_every):
    """:func:`adhesive_impact` that also writes its first ``len(record)`` steps (``REC_*``).

    ``certify_every``: steps between two checks of the sticking certificate
    (:data:`CERTIFY_EVERY` in :func:`adhesive_impact`; 0: never, so only the turn back
    or the time limit end a sphere that does not separate). For the tests of the
    energy laws and of the end criterion; the record costs a pass over the row per step.
    """
    _impact(tau0, g, tau, lam, h, n_elem, dxi, max_steps, out, record, certify_every)


@jit()
def _impact(tau0, g, tau, lam, h, n_elem, dxi, max_steps, out, record, certify_every):
    """Advance one adhesive normal impact to its end; results into ``out`` (``ADH_*``).

    Velocity Verlet (kick-drift-kick) with the dashpot implicit in the
    half-step velocity, arms on their exact update for the drift path. The
    sphere starts touching (``u = 0``, ``v = 1``). The impact ends when the
    contact is lost with the sphere moving away above every point the relaxing
    surface can reach, or when the sphere sticks (``ADH_STUCK = 1``, end velocity
    0): in contact, it turns back towards the surface after it had started to
    rebound, or the contact provably never changes again (:func:`_cannot_separate`,
    checked every :data:`CERTIFY_EVERY` steps: an overdamped sphere creeps to rest
    in contact without ever turning back).

    Parameters
    ----------
    tau0 : parallel dashpot time ``eta0 / (G_inf T)`` (0: none)
    g, tau : arm moduli ``G_i / G_inf`` and times ``tau_i / T`` (1-D, equal length)
    lam : adhesion number ``sqrt(2 pi a_H dgamma / E*) / d`` (>= 0)
    h : time step / T
    n_elem, dxi : elements in the half row and their spacing / a_H
    max_steps : time limit in steps
    out : (N_ADH_OUT,) result row
    record : (n, N_REC) per-step record of the first ``n`` steps (``REC_*``; n = 0: none)
    certify_every : steps between two checks of :func:`_cannot_separate` (0: never)
    """
    n_arms = g.shape[0]
    ARMS = n_arms > 0
    E, omE, phi = arm_coefficients(tau, h)
    G = 0.0
    sum_gphi = 0.0
    for i in range(n_arms):
        G += g[i]
        sum_gphi += g[i] * phi[i]
    c0 = tau0
    tau0_h = c0 / h
    den_free = tau0_h + 1.0 + G - sum_gphi
    decay0 = math.exp(-h / c0) if c0 > 0.0 else 0.0
    k_el = 2.0 * ELEMENT_STIFFNESS * dxi  # both halves of the symmetric row
    xi2, sqrt_xi = _row_geometry(n_elem, dxi)
    w = np.zeros(n_elem)
    q = np.zeros((n_elem, n_arms))
    u = 0.0
    v = 1.0
    F_el = 0.0
    C = 0.0
    n_c = 0
    touched = 0  # elements [0, touched) have ever been in contact
    u_max = 0.0
    u_min = 0.0
    nc_max = 0
    f_tensile = 0.0
    t_first = -1.0
    t_end = 0.0
    contacts = 0
    rebounding = False
    stuck = False
    status = STATUS_TIME_LIMIT
    step = 0
    while step < max_steps:
        v_half = (v - 0.5 * h * F_el) / (1.0 + 0.5 * h * C)
        u1 = u + h * v_half
        ve = 2.0 * v_half - v
        for j in range(n_c):  # in contact: follow the sphere
            w1 = u1 - xi2[j]
            if ARMS:
                _follow(w[j], w1, q[j], g, E, omE, phi)
            w[j] = w1
        for j in range(n_c, touched):  # free: relax under zero force
            if ARMS:
                w[j] = _relax(w[j], q[j], g, E, omE, phi, tau0_h, den_free, decay0)
            else:
                w[j] = w[j] * decay0
        was = n_c
        n_c = _contact_update(u1, n_c, w, q, g, G, c0, ve, xi2, sqrt_xi, lam, ARMS)
        step += 1
        if n_c >= n_elem:
            status = STATUS_ROW_EXCEEDED
            break
        touched = max(touched, n_c)
        if n_c > 0 and was == 0:
            contacts += 1
            if t_first < 0.0:
                t_first = (step - 1) * h
        sum_r = 0.0
        for j in range(n_c):
            sum_r += w[j]
            if ARMS:
                sum_r += _arm_stress(w[j], q[j], g)
        F_el = k_el * sum_r
        C = k_el * c0 * n_c
        v_new = v_half - 0.5 * h * (F_el + C * v_half)
        u = u1
        if not (math.isfinite(u) and math.isfinite(v_new)):
            status = STATUS_NON_FINITE
            v = v_new
            break
        F_now = F_el + C * v_half
        if n_c > 0:
            f_tensile = max(f_tensile, -F_now)
            u_max = max(u_max, u)
            u_min = min(u_min, u)
            nc_max = max(nc_max, n_c)
            t_end = step * h
            if v_new < 0.0:
                rebounding = True
            elif rebounding:  # turned back towards the surface while in contact
                stuck = True
            if (not stuck and certify_every > 0 and step % certify_every == 0
                    and _cannot_separate(u, v_new, n_c, touched, w, q, g, G, c0, k_el, xi2,
                                         sqrt_xi, lam, ARMS)):
                stuck = True
        if step <= record.shape[0]:
            _record(record[step - 1], step * h, u, v_new, n_c, touched, w, q, g, k_el, xi2,
                    lam, dxi, ARMS)
        if stuck:
            v = v_new
            status = STATUS_OK
            break
        v = v_new
        if n_c == 0 and v < 0.0 and t_first >= 0.0:
            # free flight away: ends once no relaxing surface point can reach the sphere
            reach = True
            for j in range(touched):
                if u - xi2[j] >= min(w[j], 0.0):
                    reach = False
                    break
            if reach:
                status = STATUS_OK
                break
    out[ADH_VZ_END] = 0.0 if stuck else v
    out[ADH_T_CONTACT] = t_end - max(t_first, 0.0)
    out[ADH_U_MAX] = u_max
    out[ADH_U_MIN] = u_min
    out[ADH_A_MAX] = nc_max * dxi
    out[ADH_F_TENSILE] = f_tensile
    out[ADH_STUCK] = 1.0 if stuck else 0.0
    out[ADH_STATUS] = status
    out[ADH_STEPS] = step
    out[ADH_CONTACTS] = contacts


@jit()
def _record(row, t, u, v, n_c, touched, w, q, g, k_el, xi2, lam, dxi, ARMS):
    """One row of the per-step record: state, contact energy, Griffith energy."""
    row[REC_T] = t
    row[REC_U] = u
    row[REC_V] = v
    row[REC_NC] = n_c
    row[REC_V_LYAP] = _contact_energy(u, v, n_c, w, q, g, k_el, xi2, ARMS)[0] if n_c > 0 \
        else math.nan
    stored = 0.0
    for j in range(touched):
        stored += w[j] * w[j]
        if ARMS:
            stored += _arm_energy(j, w, q, g)
    # dgamma pi a^2 in kernel units: (15/32) lam^2 (n_c dxi)^2 (docs/physics.md#adhesion)
    row[REC_E_GRIFFITH] = (0.5 * v * v + 0.5 * k_el * stored
                           - 0.5 * ELEMENT_STIFFNESS * (lam * n_c * dxi) ** 2)


@jit(parallel=True)
def adhesive_batch(tau0, g, tau, n_arms, lam, h, n_elem, dxi, max_steps, out):
    """Run :func:`adhesive_impact` for every row, in parallel over the rows.

    Row ``i`` of each input is one scene, in the units of :func:`adhesive_impact`
    (``g[i, :n_arms[i]]``, ``tau[i, :n_arms[i]]`` its arms); its results go to
    ``out[i]`` (``(n, N_ADH_OUT)``), which only that row writes.
    """
    for i in prange(tau0.shape[0]):
        k = n_arms[i]
        adhesive_impact(tau0[i], g[i, :k], tau[i, :k], lam[i], h[i], n_elem[i], dxi[i],
                        max_steps[i], out[i])


@jit()
def quasi_static_row(u_path, lam, n_elem, dxi, F_out, a_out):
    """Elastic element row under a prescribed indentation path (no sphere dynamics).

    For each ``u_path[i]`` (units of ``d``) the contact is updated with the same
    rules as :func:`adhesive_impact` and the normal force
    and the contact half-width ``n_c dxi`` (units of ``a_H``) are written; the force
    is in the kernel unit ``m v_z0 / T`` of the scene whose Hertz scales are the units.
    Returns ``n_c`` at the end (``-1`` if the row was too short).
    """
    g = np.zeros(0)
    q = np.zeros((n_elem, 0))
    w = np.zeros(n_elem)
    k_el = 2.0 * ELEMENT_STIFFNESS * dxi
    xi2, sqrt_xi = _row_geometry(n_elem, dxi)
    n_c = 0
    for i in range(u_path.shape[0]):
        u1 = u_path[i]
        for j in range(n_c):
            w[j] = u1 - xi2[j]
        for j in range(n_c, n_elem):
            w[j] = 0.0
        n_c = _contact_update(u1, n_c, w, q, g, 0.0, 0.0, 0.0, xi2, sqrt_xi, lam, False)
        if n_c >= n_elem:
            return -1
        s = 0.0
        for j in range(n_c):
            s += w[j]
        F_out[i] = k_el * s
        a_out[i] = n_c * dxi
    return n_c
