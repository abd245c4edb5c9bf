"""Element kernel of the MDR impact, in kernel units.

Unit-free numba kernels; nothing here imports the user-facing layer.

Kernel units (docs/physics.md#hertz-scales, docs/physics.md#method-of-dimensionality-reduction,
docs/physics.md#energy-and-passivity): indentation ``u`` and normal
surface displacements ``w`` in units of the Hertz indentation ``d``; element
positions ``xi`` in units of the Hertz radius ``a_H`` (so the MDR profile is
``g = xi^2``); time in units of ``T = d / v_z0``; normal velocity in units of
``v_z0``. The tangential problem is linear in ``v_c0`` (docs/physics.md#energy-and-passivity),
so tangential displacements and velocities are in units of ``v_c0 T`` and
``v_c0``: the contact point starts with ``v_c = 1``. Forces are in units of
``m v_z0 / T`` (normal) and ``m v_c0 / T`` (tangential); the element
stiffness per unit length is then ``15/16`` (normal) and ``kappa * 15/16``
(tangential) with ``kappa = c_t / c_n = 2 (1 - nu) / (2 - nu)``.

Material (docs/physics.md#rheologies), relative to the relaxed modulus ``G_inf``:
``tau0 = eta0 / (G_inf T)`` (parallel dashpot), arms ``g_i = G_i / G_inf``
with times ``tau_i / T``. Every arm is advanced with the exact exponential
update for a linear displacement path over the step; nothing divides by a
viscosity or a relaxation time.

Integrators (the value of ``integrator``):

``EULER``
    the thesis's explicit Euler: ``u += h v``, ``v -= h F`` with the force of
    the old state. First order; not symplectic (an elastic impact gains
    energy) and only conditionally stable with a dashpot.
``SYMPLECTIC_EULER``
    semi-implicit Euler (kick-drift): ``v+ = (v - h F_el) / (1 + h C)``,
    ``u += h v+``, elements follow the drift. First order, symplectic for
    the elastic part, dashpot implicit (unconditionally stable).
``VERLET``
    generalized Stormer-Verlet (kick-drift-kick) with the dashpot force
    implicit in the half-step velocity: ``v+ = (v - h/2 F_el) / (1 + h/2 C)``,
    drift ``u += h v+``, elements follow the linear path of the drift (for
    which the arm update is exact), then ``v = v+ - h/2 (F_el' + C' v+)``.
    Second order for smooth forces, unconditionally stable for the dashpot.
    Maxwell arms get the exact impulse of the drift path: the second half-kick
    takes their end stress, the first half the rest, whose damping part
    (``sum g_i tau_i (1 + E_i - 2 (1 - E_i) tau_i / h)``) is implicit in the
    half-step velocity like the dashpot (:func:`vimpact.kernels.arms.arm_implicit_coefficients`):
    an arm faster than the step stays second order and stable (it acts as
    the dashpot ``g_i tau_i``), where taking its stress explicitly was first
    order. An element entering within the step gets the arms' exact mean
    stress over its ramp; the force that decides whether an element still
    pushes at the step end takes the arms' damping part at the end velocity.

Compile-time specialization: the impact body :func:`_impact` reads the
effects (``TANGENTIAL``, ``MEMORY``, ``INTEGRATOR``, ``ARMS``, ``DASHPOT``,
``FRICTION``) as globals, and each kernel (:func:`impact_kernel`, and
:func:`batch_kernel` around it) is a copy of that body whose globals hold its
own values: numba reads them as constants and drops the branches they switch
off before typing, so a normal-only Kelvin-Voigt kernel carries no tangential
and no arm code at all. (Inlining one body into a wrapper per kernel instead
costs most of the compile: numba copies an inlined body's IR block by block,
each block with the whole scope.) Friction is read from the row instead where
the tangential problem has incremental memory (:func:`kernel_effects`; a stick
row carries ``mu = inf``), and takes the same statements as in a kernel
compiled for its value; vimpact/bench/specialization.py measures what each
effect costs as a run-time flag.
"""

from __future__ import annotations

import functools
import math
import types
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numba import prange

from vimpact.kernels.arms import (
    _arm_coefficient,
    _arm_start,
    _arm_stress,
    _follow,
    _follow_over,
    _follow_over_impulse,
    _follow_value,
    _free_rate,
    _relax,
    _to_stress,
    arm_coefficients,
    arm_implicit_coefficients,
)
from vimpact.kernels.jit import jit
from vimpact.kernels.layout import (  # noqa: F401 - re-exported: the kernels' common layout
    ELEMENT_STIFFNESS,
    EULER,
    N_OUT,
    N_REC,
    OUT_B_MAX,
    OUT_N_REC,
    OUT_STATUS,
    OUT_STEPS,
    OUT_T_CONTACT,
    OUT_T_GROSS_SLIP,
    OUT_U_MAX,
    OUT_VC_END,
    OUT_VZ_END,
    OUT_W_FRICTION,
    REC_B,
    REC_FX,
    REC_FZ,
    REC_SLIP,
    REC_T,
    REC_U,
    REC_V,
    REC_VC,
    STATUS_NON_FINITE,
    STATUS_OK,
    STATUS_ROW_EXCEEDED,
    STATUS_TIME_LIMIT,
    SYMPLECTIC_EULER,
    VERLET,
)
from vimpact.kernels.record import _record


@jit(inline="always")
def _path_in_cone(L0, L1, C0, C1, alpha):
    """Return the integral of a sticking element's tangential force on its way out.

    Over ``t`` in ``[0, alpha]`` (in steps): its stick path ``L0 + t (L1 - L0)``, clipped
    to the cone ``|f_t| <= C0 + t (C1 - C0)``, which shrinks to 0 with the normal
    force at ``t = alpha``. ``|L| - C`` is convex, so the element sticks on
    ``[0, t*]`` and rides the cone (sign of ``L(alpha)``) down to 0 on
    ``[t*, alpha]``. Without the clip a linear path to the cone's end value,
    ``mu`` times a negative normal force, crosses it and, for ``mu v_z0 >> v_c0``,
    pushes far beyond anything the element holds.
    """
    if alpha <= 0.0:
        return 0.0
    dL = L1 - L0
    La = L0 + alpha * dL
    if La == 0.0:
        return alpha * L0 + 0.5 * alpha * alpha * dL
    sg = 1.0 if La > 0.0 else -1.0
    dC = C1 - C0
    if sg * L0 >= C0:
        ts = 0.0
    else:
        ts = (C0 - sg * L0) / (sg * dL - dC)
        ts = min(max(ts, 0.0), alpha)
    return ts * L0 + 0.5 * ts * ts * dL + sg * 0.5 * (C0 + ts * dC) * (alpha - ts)


def _impact(tau0, g, tau, kappa, mu_t, mu_k, h, n_elem, dxi, max_steps, rec, rec_every, out):
    """Advance one impact to its end and write the results into ``out``.

    The body of every element kernel, never compiled as it stands: :func:`_bind`
    gives each kernel a copy whose globals hold its effects (:func:`_effects`;
    ``TANGENTIAL``, ``MEMORY``, ``INTEGRATOR``, ``ARMS``, ``DASHPOT``,
    ``FRICTION`` and the derived ``IMPLICIT``, ``PARTIAL``, ``NCORR``). numba
    reads a global as a constant and drops the branches it switches off before
    typing, so a kernel carries no code of an effect it lacks. ``FRICTION``
    may be :data:`RUNTIME`: the row's ``mu_k`` decides (``inf``: full stick,
    the same statements as a kernel compiled without friction); so may
    ``DASHPOT`` (the row's ``tau0 > 0``, and ``NCORR`` with it). The arguments
    are kernel-unit inputs (module docstring).

    Parameters
    ----------
    tau0 : parallel dashpot time ``eta0 / (G_inf T)``
    g, tau : arm moduli ``G_i / G_inf`` and times ``tau_i / T`` (1-D, equal length)
    kappa : ``c_t / c_n``
    mu_t : inverse effective tangential mass times m: ``1 + m R^2 / Theta``
    mu_k : friction coefficient in kernel units, ``mu v_z0 / |v_c0|`` (``inf``
        sticks; read only by a kernel with friction)
    h : time step / T
    n_elem, dxi : elements in the half row and their spacing / a_H
    max_steps : time limit in steps
    rec : (n_rec, N_REC) trajectory buffer (may have zero rows)
    rec_every : record every this many steps (ignored without rows)
    out : (N_OUT,) result row
    """
    # Coulomb friction: every element in contact keeps |f_t| <= mu f_n
    # (docs/physics.md#coulomb-friction); a constant of the kernel, or the row's mu
    FRIC = FRICTION == 1 if FRICTION != RUNTIME else mu_k < math.inf
    # the parallel dashpot: a constant of the kernel, or the row's (tau0 > 0), and
    # with it NCOR, the partial-contact weighting of the normal force (NCORR below)
    DASH = DASHPOT == 1 if DASHPOT != RUNTIME else tau0 > 0.0
    NCOR = NCORR == 1 if NCORR != RUNTIME else DASH
    n_arms = g.shape[0] if ARMS else 0
    G = 0.0
    sum_gphi = 0.0
    ca = 0.0
    if ARMS:  # (a kernel without arms compiles none of the arm helpers)
        E, omE, phi = arm_coefficients(tau, h)
        for i in range(n_arms):
            G += g[i]
            sum_gphi += g[i] * phi[i]
        # Verlet: each arm's step impulse is exact for the drift path; its first half
        # takes the arm stresses weighted by kap and the damping ca implicitly in the
        # half-step velocity, like the dashpot (arm_implicit_coefficients), so arms
        # faster than the step stay second order and stable (IMPLICIT: Verlet with arms)
        kap, ca = arm_implicit_coefficients(g[:n_arms], tau[:n_arms], h)
    else:
        E = omE = phi = kap = tau[:0]
    c0 = tau0 if DASH else 0.0
    tau0_h = c0 / h
    den_free = tau0_h + 1.0 + G - sum_gphi
    decay0 = math.exp(-h / c0) if DASH else 0.0
    # the arms' end stress on the straight drift path misses the path's curvature:
    # on w0 + v t + a t^2 / 2 it is larger by sum g tau (1 + E - 2 (1 - E) / x) a h / 2,
    # which is ca (ve - v_test): the force that decides whether an element still
    # pushes at the step end (and the line of a partial step) takes it, as the
    # dashpot takes the end velocity (ca -> g tau for a fast arm, h x / 6 for a slow one)
    cae = ca if IMPLICIT else 0.0

    k_el = 2.0 * ELEMENT_STIFFNESS * dxi  # both halves of the symmetric row
    xi2 = np.empty(n_elem)
    for j in range(n_elem):
        xi = (j + 0.5) * dxi
        xi2[j] = xi * xi
    n_t = n_elem if TANGENTIAL else 0  # no tangential state at all without it
    w = np.zeros(n_elem)
    q = np.zeros((n_elem, n_arms))
    s = np.zeros(n_t)
    p = np.zeros((n_t, n_arms))
    contact = np.zeros(n_elem, dtype=np.bool_)
    # last normal force (Verlet: its spring part) of each element in contact / k_el
    f = np.zeros(n_elem)
    fs = np.zeros(n_elem if IMPLICIT else 0)  # ... its start-of-step form (IMPLICIT)
    n_af = n_arms if FRIC else 0
    p_save = np.empty(n_af)  # arms of a slip candidate before the stick trial
    E_e = np.empty(n_af)  # arm coefficients over the in-contact part of an entering step
    omE_e = np.empty(n_af)
    phi_e = np.empty(n_af)
    Cs = 0.0  # slipping elements: tangential force per unit normal velocity (mu f_n's dashpot)
    t_gross = 0.0
    # PARTIAL (Verlet): weigh partial contact within a step (see below); NCORR: ...
    # in the normal force only where it jumps at entry: the dashpot or an arm (else
    # the force is continuous at entry and exit, and the elastic Verlet impact stays
    # time reversible: e_z = 1 to rounding; an arm faster than the step acts as a dashpot)
    # last step's position part of each element's tangential force (/ k_el kappa)
    # and, with friction, its slip direction (0: sticking)
    ftp = np.zeros(n_t if PARTIAL else 0)
    ftps = np.zeros(n_t if IMPLICIT else 0)  # ... its start-of-step form (IMPLICIT)
    fsgn = np.zeros(n_t if PARTIAL and FRIC else 0)
    w_fric = 0.0
    slip_now = 0.0

    u = 0.0
    v = 1.0
    uc = 0.0
    vc = 1.0 if TANGENTIAL else 0.0
    F_el = 0.0  # position/history part of the normal force
    C = 0.0  # dashpot coefficient of the normal force
    Ft_el = 0.0
    Ct = 0.0
    F_s = 0.0  # IMPLICIT: the start-of-step forms of F_el, Ft_el and the arms' damping
    Ft_s = 0.0
    Ca = 0.0
    Cta = 0.0
    Css = 0.0
    active = 0  # elements [0, active) have ever been touched
    t_exit = 0.0  # time the last element left (impact starts touching at t = 0)
    u_max = 0.0
    j_outer_max = -1
    n_rec = rec.shape[0]
    # int64 from the start: a bare 0 (Literal[int](0)) compiled _record twice
    i_rec = np.int64(0)
    status = STATUS_TIME_LIMIT
    step = 0
    b_now = 0.0
    while step < max_steps:
        # ---- sphere: first half (or the whole kick) ----
        if INTEGRATOR == EULER:
            v_test = v - h * (F_el + C * v)
            u1 = u + h * v
        elif INTEGRATOR == SYMPLECTIC_EULER:
            v_test = (v - h * F_el) / (1.0 + h * C)
            u1 = u + h * v_test
        elif IMPLICIT:
            v_test = (v - 0.5 * h * F_s) / (1.0 + 0.5 * h * (C + Ca))
            u1 = u + h * v_test
        else:
            v_test = (v - 0.5 * h * F_el) / (1.0 + 0.5 * h * C)
            u1 = u + h * v_test
        vc_test = 0.0
        duc = 0.0
        if TANGENTIAL:
            Ft_pos = Ft_s if IMPLICIT else Ft_el
            if FRIC and IMPLICIT:  # slipping: mu times the normal force as the kick takes it
                Ft_pos = Ft_pos + Css * v_test
            elif FRIC and DASH:  # slipping elements: mu times their normal force, whose
                # dashpot part takes this step's normal velocity (as the normal kick)
                Ft_pos = Ft_pos + Cs * (v if INTEGRATOR == EULER else v_test)
            if INTEGRATOR == EULER:
                vc_test = vc - h * mu_t * (Ft_pos + Ct * vc)
                duc = h * vc
            elif INTEGRATOR == SYMPLECTIC_EULER:
                vc_test = (vc - h * mu_t * Ft_pos) / (1.0 + h * mu_t * Ct)
                duc = h * vc_test
            else:
                vc_test = (vc - 0.5 * h * mu_t * Ft_pos) / (1.0 + 0.5 * h * mu_t * (Ct + Cta))
                duc = h * vc_test
        uc1 = uc + duc
        # ---- elements ----
        while active < n_elem and xi2[active] <= u1:
            active += 1
        sum_r = 0.0
        sum_rt = 0.0
        sum_rs = 0.0  # IMPLICIT: start-of-step forms for the next step
        sum_rts = 0.0
        t_leave = 0.0
        n_c = 0
        n_stick = 0
        n_slip = 0
        sum_slip_r = 0.0  # sum of sign * (normal spring part) over slipping elements
        sum_slip_sign = 0.0
        sum_slip_rs = 0.0  # IMPLICIT: ... of the normal start-of-step forms
        # Verlet's step impulse is the trapezoid h/2 (F_start + F_end) of the forces
        # as the half-kicks apply them (dashpots at the half-step velocity). An
        # element in contact for only part of the step (leaving after a fraction
        # alpha, or entering for the last fraction theta) contributes instead the
        # integral of its force over that part, the force taken linear in time
        # between its values at the step ends (dashpots at the velocities of
        # those instants: v at the start, 2 v_test - v at the end); corr_n,
        # corr_t are what the second half-kick adds for them (/ k_el, / (k_el
        # kappa)). The zero crossing of that normal force gives alpha.
        corr_n = 0.0
        corr_t = 0.0
        ve = 2.0 * v_test - v
        vce = 2.0 * vc_test - vc
        j_outer = -1
        for j in range(active):
            w0 = w[j]
            w1 = u1 - xi2[j]
            was_in = contact[j]
            theta = 1.0
            f_entry = 0.0
            ft_entry = 0.0
            fol = 0.0
            fa_entry = 0.0
            fa_t = 0.0
            rs = 0.0
            r_end = 0.0
            arm_mean = 0.0
            arm_mean_t = 0.0
            if was_in:
                r = w1
                if ARMS:
                    r += _follow(w0, w1, q[j], g, E, omE, phi)
            else:
                if ARMS:
                    wf = _relax(w0, q[j], g, E, omE, phi, tau0_h, den_free, decay0)
                else:
                    wf = w0 * decay0
                if TANGENTIAL:
                    if ARMS:
                        s[j] = _relax(s[j], p[j], g, E, omE, phi, tau0_h, den_free, decay0)
                    else:
                        s[j] = s[j] * decay0
                if w1 < wf:
                    w[j] = wf
                    continue
                # (re-)entry: the sphere reached the relaxed surface at the
                # fraction 1 - theta of the step; the element follows it from
                # there (the arms see a ramp wf -> w1 over theta h, not a jump)
                theta = (w1 - wf) / (w1 - wf + w0 + xi2[j] - u)
                if PARTIAL:  # normal force at the moment of entry
                    f_entry = wf + c0 * (v + 2.0 * (1.0 - theta) * (v_test - v))
                    if ARMS:
                        f_entry += _arm_stress(wf, q[j], g)
                r = w1
                if IMPLICIT:  # the arms' exact mean stress over the entering part
                    fa_entry = _arm_stress(wf, q[j], g)
                    fo, arm_mean = _follow_over_impulse(wf, w1, q[j], g, tau, theta * h)
                    r += fo
                elif ARMS:
                    r += _follow_over(wf, w1, q[j], g, tau, theta * h)
            w[j] = w1
            fj = r + c0 * v_test
            if IMPLICIT:  # the arms' stress at the end velocity
                r_end = r + cae * (ve - v_test)
            else:
                r_end = r
            # the element leaves when its force would pull (Verlet: its force at the
            # step end, the dashpot at the end velocity 2 v_test - v)
            if (r_end + c0 * ve <= 0.0) if PARTIAL else (fj <= 0.0):
                if was_in:  # interpolate its force to zero within the step
                    if PARTIAL:
                        T0 = f[j] + c0 * v
                        T1 = r_end + c0 * ve
                        if T0 <= 0.0:
                            alpha = 0.0
                        elif T1 >= 0.0:
                            alpha = 1.0
                        else:
                            alpha = T0 / (T0 - T1)
                        if NCOR:  # minus what the first half-kick applied
                            if IMPLICIT:
                                corr_n += alpha * T0 - (fs[j] + (c0 + ca) * v_test)
                            else:
                                corr_n += alpha * T0 - (f[j] + c0 * v_test)
                        if TANGENTIAL:  # tangential force T0t -> trial T1t over the step
                            s0 = s[j]
                            s1 = uc1 if MEMORY == 1 else s0 + duc
                            T1t = s1 + c0 * vce
                            if ARMS:
                                T1t += _follow_value(s0, s1, p[j], g, E, omE, phi)
                            if IMPLICIT:
                                T1t += cae * (vce - vc_test)
                            sg = fsgn[j] if FRIC else 0.0
                            if sg != 0.0 and not NCOR:  # slipping: mu times the normal
                                T0t = 0.0  # force, which takes no correction here
                                A_t = 0.0
                                T1t = 0.0
                            elif sg != 0.0:  # slipping: mu times the normal force
                                T0t = ftp[j] + sg * mu_k / kappa * c0 * v
                                if IMPLICIT:  # what the first half-kick applied
                                    A_t = sg * mu_k / kappa * (fs[j] + (c0 + ca) * v_test)
                                else:
                                    A_t = ftp[j] + sg * mu_k / kappa * c0 * v_test
                                T1t = sg * mu_k / kappa * T1
                            else:
                                T0t = ftp[j] + c0 * vc
                                if IMPLICIT:
                                    A_t = ftps[j] + (c0 + ca) * vc_test
                                else:
                                    A_t = ftp[j] + c0 * vc_test
                            if FRIC and sg == 0.0 and mu_k < math.inf:  # sticking: its
                                # stick path inside the cone, which shrinks to 0 with
                                # the normal force
                                corr_t += 2.0 * _path_in_cone(
                                    T0t, T1t, mu_k / kappa * T0, mu_k / kappa * T1, alpha) - A_t
                            else:
                                corr_t += (2.0 * alpha * T0t + alpha * alpha * (T1t - T0t)
                                           - A_t)
                    else:
                        alpha = f[j] / (f[j] - fj)
                    t_leave = max(t_leave, (step + alpha) * h)
                contact[j] = False
                continue
            entry_n = 0.0  # what the normal force over the entering part adds
            if NCOR and not was_in:  # from f_entry to the end force over theta h
                if IMPLICIT:  # (the arms at their exact mean over it)
                    entry_n = (theta * (f_entry - fa_entry + w1 + c0 * ve + 2.0 * arm_mean)
                               - fj)
                else:
                    entry_n = theta * (f_entry + r + c0 * ve) - fj
                corr_n += entry_n
            contact[j] = True
            f[j] = r_end if PARTIAL else fj
            n_c += 1
            j_outer = j
            sum_r += r
            if IMPLICIT:
                rs = w1 + _arm_start(w1, q[j], g, kap)
                fs[j] = rs
                sum_rs += rs
            if TANGENTIAL and not FRIC:
                s0 = s[j]
                if MEMORY == 1:  # seed: total displacement of the contact point
                    s1 = uc1
                elif was_in:  # incremental: only displacement since entry loads it
                    s1 = s0 + duc
                else:  # incremental, entering: relaxed state plus the part of
                    # the step after the surface was reached
                    s1 = s0 + duc * theta
                if PARTIAL and not was_in:  # stress at entry: the relaxed state,
                    # dashpot at v_c then
                    ft_entry = s0 + c0 * (vc + 2.0 * (1.0 - theta) * (vc_test - vc))
                    if ARMS:
                        ft_entry += _arm_stress(s0, p[j], g)
                sum_rt += s1
                if ARMS:
                    if was_in:
                        fol = _follow(s0, s1, p[j], g, E, omE, phi)
                    elif IMPLICIT and MEMORY == 0:  # arms at their exact mean (as normal)
                        ft_entry -= _arm_stress(s0, p[j], g)
                        fol, arm_mean_t = _follow_over_impulse(s0, s1, p[j], g, tau, theta * h)
                        ft_entry += 2.0 * arm_mean_t - fol
                    else:
                        fol = _follow_over(s0, s1, p[j], g, tau, theta * h)
                    sum_rt += fol
                s[j] = s1
                if IMPLICIT:
                    P1s = s1 + _arm_start(s1, p[j], g, kap)
                    ftps[j] = P1s
                    sum_rts += P1s
                if PARTIAL:
                    P1 = s1 + fol
                    ftp[j] = P1 + cae * (vce - vc_test) if IMPLICIT else P1
                    if not was_in:
                        if MEMORY == 1:  # seed: the element jumps to the total displacement
                            ft_entry = P1 + c0 * vce
                        corr_t += theta * (ft_entry + P1 + c0 * vce) - (P1 + c0 * vc_test)
            if FRIC:  # stick trial, then return to the cone |f_t| <= mu f_n
                s0 = s[j]
                s1 = s0 + duc if was_in else s0 + duc * theta
                for i in range(n_af):
                    p_save[i] = p[j, i]
                if PARTIAL and not was_in:  # stress at entry (relaxed state, dashpot)
                    ft_entry = s0 + c0 * (vc + 2.0 * (1.0 - theta) * (vc_test - vc))
                    if ARMS:
                        ft_entry += _arm_stress(s0, p[j], g)
                    if mu_k < math.inf:  # inside the cone then
                        cone_e = mu_k * max(f_entry, 0.0) / kappa
                        ft_entry = min(max(ft_entry, -cone_e), cone_e)
                if ARMS:
                    if was_in:
                        fol = _follow(s0, s1, p[j], g, E, omE, phi)
                    elif IMPLICIT:  # the arms at their exact mean over the entering part
                        fa_t = _arm_stress(s0, p[j], g)
                        fol, arm_mean_t = _follow_over_impulse(s0, s1, p[j], g, tau, theta * h)
                        ft_entry += 2.0 * arm_mean_t - fol - fa_t
                    else:
                        fol = _follow_over(s0, s1, p[j], g, tau, theta * h)
                trial = s1 + fol
                if DASH:
                    trial += c0 * vc_test
                cone = mu_k * fj / kappa  # element stress at the cone, tangential units
                if mu_k == math.inf or abs(trial) <= cone:  # stick
                    sum_rt += s1
                    sum_rt += fol
                    n_stick += 1
                    s[j] = s1
                    if IMPLICIT:
                        P1s = s1 + _arm_start(s1, p[j], g, kap)
                        ftps[j] = P1s
                        sum_rts += P1s
                    if PARTIAL:
                        P1 = s1 + fol
                        ftp[j] = P1 + cae * (vce - vc_test) if IMPLICIT else P1
                        fsgn[j] = 0.0
                        if not was_in:
                            corr_t += theta * (ft_entry + P1 + c0 * vce) - (P1 + c0 * vc_test)
                else:  # slip: the element's own path s0 -> s_slip puts it on the cone
                    target = math.copysign(mu_k / kappa, trial) * fj
                    dt = h if was_in else max(theta, 1e-12) * h
                    if ARMS:
                        if was_in:
                            s_slip = _to_stress(target, s0, p_save, p[j], g, E, omE, phi, c0 / dt)
                        else:
                            for i in range(n_af):
                                E_e[i], omE_e[i], phi_e[i] = _arm_coefficient(tau[i], dt)
                            s_slip = _to_stress(target, s0, p_save, p[j], g, E_e, omE_e, phi_e,
                                                c0 / dt)
                    else:
                        s_slip = (target + c0 / dt * s0) / (1.0 + c0 / dt)
                    w_fric += k_el * kappa * target * (s1 - s_slip)
                    s[j] = s_slip
                    sgn = math.copysign(1.0, trial)
                    sum_slip_r += sgn * r
                    if IMPLICIT:
                        sum_slip_rs += sgn * rs
                    sum_slip_sign += sgn
                    n_slip += 1
                    if PARTIAL:  # mu times the normal force, entering or not
                        ftp[j] = sgn * mu_k / kappa * r_end
                        fsgn[j] = sgn
                        if NCOR and not was_in:
                            corr_t += sgn * mu_k / kappa * entry_n
        if n_c == 0 and t_leave > 0.0:
            t_exit = t_leave  # the last elements left within this step
        F_el1 = k_el * sum_r
        C1 = k_el * c0 * n_c
        Ft_el1 = k_el * kappa * sum_rt
        Ct1 = k_el * kappa * c0 * n_c
        Cs1 = 0.0
        Css1 = 0.0
        F_s1 = k_el * sum_rs
        Ft_s1 = k_el * kappa * sum_rts
        Ca1 = k_el * ca * n_c
        Cta1 = k_el * kappa * ca * n_c
        if FRIC:
            Ct1 = k_el * kappa * c0 * n_stick
            Cta1 = k_el * kappa * ca * n_stick
            if n_slip > 0:  # (mu_k may be inf: only slipping elements carry it)
                Ft_el1 += mu_k * k_el * sum_slip_r
                Ft_s1 += mu_k * k_el * sum_slip_rs  # slipping: mu times the normal force
                Cs1 = mu_k * k_el * c0 * sum_slip_sign  # as each half-kick takes it
                Css1 = mu_k * k_el * (c0 + ca) * sum_slip_sign
            if n_slip == n_c and n_c > 0:
                t_gross += h
            slip_now = n_slip * dxi
        # ---- sphere: second half ----
        if INTEGRATOR == VERLET:
            v = v_test - 0.5 * h * (F_el1 + C1 * v_test + k_el * corr_n)
            if FRIC and DASH:
                vc = vc_test - 0.5 * h * mu_t * (Ft_el1 + Ct1 * vc_test + Cs1 * v_test
                                                 + k_el * kappa * corr_t)
            elif TANGENTIAL:
                vc = vc_test - 0.5 * h * mu_t * (Ft_el1 + Ct1 * vc_test + k_el * kappa * corr_t)
        else:
            v = v_test
            vc = vc_test
        u = u1
        uc = uc1
        F_el, C, Ft_el, Ct, Cs = F_el1, C1, Ft_el1, Ct1, Cs1
        F_s, Ft_s, Ca, Cta, Css = F_s1, Ft_s1, Ca1, Cta1, Css1
        step += 1
        t = step * h
        if not (math.isfinite(u) and math.isfinite(v) and math.isfinite(vc)):
            status = STATUS_NON_FINITE
            break
        if u > u_max:
            u_max = u
        b_now = (j_outer + 1) * dxi if n_c > 0 else 0.0
        if j_outer > j_outer_max:
            j_outer_max = j_outer
        if n_rec > 0 and step % rec_every == 0:
            i_before = i_rec
            i_rec = _record(rec, i_rec, t, u, v, vc, F_el + C * v, Ft_el + Ct * vc + Cs * v, b_now)
            if i_rec > i_before:
                rec[i_before, REC_SLIP] = slip_now
        if j_outer_max >= n_elem - 1:
            status = STATUS_ROW_EXCEEDED
            break
        # ---- end of impact: no contact, moving away, no free surface can catch up ----
        if n_c == 0 and v < 0.0:
            caught = False
            if DASH or ARMS:  # an elastic surface is back at rest at once
                for j in range(active):
                    if _free_rate(w[j], q[j], g, tau, c0) < v * (1.0 + 1e-9):
                        caught = True
                        break
            if not caught:
                status = STATUS_OK
                break
    # a final record marks the end state (overwriting the last row if full)
    if n_rec > 0:
        i_last = min(i_rec, n_rec - 1)
        i_rec = _record(rec, i_last, step * h, u, v, vc, F_el + C * v, Ft_el + Ct * vc + Cs * v, b_now)
        rec[i_last, REC_SLIP] = slip_now
    out[OUT_VZ_END] = v
    out[OUT_VC_END] = vc  # stays 0 without tangential motion
    out[OUT_T_CONTACT] = t_exit
    out[OUT_U_MAX] = u_max
    out[OUT_B_MAX] = (j_outer_max + 1) * dxi
    out[OUT_STATUS] = status
    out[OUT_STEPS] = step
    out[OUT_N_REC] = i_rec
    out[OUT_T_GROSS_SLIP] = t_gross
    out[OUT_W_FRICTION] = w_fric


class KernelSpec(NamedTuple):
    """The effects of the rows an element kernel runs (routing groups rows by it).

    Attributes
    ----------
    integrator : ``EULER``, ``SYMPLECTIC_EULER`` or ``VERLET``
    tangential : the tangential problem is advanced
    memory : 0 incremental, 1 seed (meaningful only with ``tangential``)
    arms : the material has Maxwell arms
    dashpot : the material has a parallel dashpot; with ``arms`` it also selects how
        an element in contact for part of a step is weighted, so a kernel must only
        run rows whose dashpot and arms match its flags (routing groups rows that way)
    friction : Coulomb friction (finite ``mu``); ``False`` is full stick. Not a
        compile-time effect where the tangential problem has incremental memory:
        one kernel runs both, the stick rows with ``mu = inf`` (:func:`kernel_effects`)
    """

    integrator: int
    tangential: bool
    memory: int
    arms: bool
    dashpot: bool
    friction: bool = False


#: value of ``FRICTION`` (or ``DASHPOT``) in the compiled effects of a kernel that
#: reads the effect from the row (``mu_k < inf``, ``tau0 > 0``) instead of compiling
#: it in or out
RUNTIME = -1

# The effects the impact body reads as globals (:func:`_impact`). Each kernel runs a
# copy of the body whose globals hold its own values (:func:`_bind`); the module's
# values here are placeholders for the linters, never compiled.
TANGENTIAL = False
MEMORY = 0
INTEGRATOR = VERLET
ARMS = False
DASHPOT: int = 0
FRICTION: int = 0
IMPLICIT = False
PARTIAL = False
NCORR: int = 0


def kernel_effects(spec: KernelSpec) -> tuple[int, bool, int, bool, int, int]:
    """Return the compiled effects of the kernel that runs the rows of ``spec`` (checked).

    ``(integrator, tangential, memory, arms, dashpot, friction)`` as plain Python
    constants: ``memory`` 0 without a tangential problem, ``friction``
    :data:`RUNTIME` with incremental tangential memory (friction and full stick
    share that kernel: its friction rows run as fast as on a kernel compiled with
    friction, its stick rows 0-20 % slower than without, and those rows take the
    continuum kernel unless it is switched off). The others stay compiled in
    (vimpact/bench/specialization.py measures what each would cost at run time;
    the dashpot would cost 3-13 %).
    """
    integrator, tangential, memory = int(spec.integrator), bool(spec.tangential), int(spec.memory)
    arms, dashpot, friction = bool(spec.arms), bool(spec.dashpot), bool(spec.friction)
    if friction and tangential and memory != 0:
        raise ValueError(f"KernelSpec(memory={memory}, friction=True) is not supported: Coulomb "
                         "friction needs incremental memory (0); the seed memory sets every "
                         "element to the total contact-point displacement, which slip cannot "
                         "change")
    if not tangential:
        return integrator, False, 0, arms, int(dashpot), 0
    return integrator, True, memory, arms, int(dashpot), RUNTIME if memory == 0 else 0


def _effects(key: tuple) -> dict:
    """Return the globals of the impact body for the compiled effects ``key``.

    ``key`` as :func:`kernel_effects` returns it; ``dashpot`` and ``friction`` 0, 1
    or :data:`RUNTIME`.
    """
    integrator, tangential, memory, arms, dashpot, friction = key
    if friction != 0 and not (tangential and memory == 0):
        raise ValueError(f"compiled effects {key}: friction needs the tangential problem with "
                         "incremental memory")
    partial = integrator == VERLET  # Verlet weighs partial contact within a step
    # ... in the normal force with a dashpot or arms (the row's dashpot decides only
    # for a Verlet kernel without arms)
    ncorr = (RUNTIME if dashpot == RUNTIME and partial and not arms
             else int(partial and (arms or dashpot == 1)))
    return {"TANGENTIAL": tangential, "MEMORY": memory, "INTEGRATOR": integrator, "ARMS": arms,
            "DASHPOT": int(dashpot), "FRICTION": int(friction), "IMPLICIT": partial and arms,
            "PARTIAL": partial, "NCORR": ncorr}


def _tag(key: tuple) -> str:
    """Name the compiled effects ``key`` (part of a kernel's qualified name)."""
    integrator, tangential, memory, arms, dashpot, friction = key
    dash, fric = ("R" if x == RUNTIME else str(int(x)) for x in (dashpot, friction))
    return (f"integrator{integrator}_tangential{int(tangential)}_memory{memory}"
            f"_arms{int(arms)}_dashpot{dash}_friction{fric}")


def _bind(key: tuple):
    """Return a copy of the impact body (:func:`_impact`) with the effects ``key`` as globals."""
    body = types.FunctionType(_impact.__code__, {**globals(), **_effects(key)}, "element_impact")
    body.__qualname__ = body.__name__
    return _named(body, key)


@functools.cache
def impact_kernel(key: tuple):
    """Return the serial one-impact kernel of the compiled effects ``key`` (compiled on first use).

    ``key`` as :func:`kernel_effects` returns it, or with ``friction`` fixed at 0 or 1
    (the specialized kernels vimpact/bench/specialization.py compares with).
    """
    return jit()(_bind(key))


def element_impact(spec: KernelSpec):
    """Return the serial one-impact kernel for the rows of ``spec`` (compiled on first use, cached).

    Signature: ``impact(tau0, g, tau, kappa, mu_t, mu, h, n_elem, dxi, max_steps,
    rec, rec_every, out)``, the scalars and arrays of one row of
    :func:`element_kernel` (``g``, ``tau`` only the row's real arms, ``rec``
    ``(n_rec, N_REC)``, ``out`` ``(N_OUT,)``; ``mu`` ``inf`` for a row of a
    spec without friction); writes exactly what the batch kernel writes for
    that row. A single scene runs it instead of the parallel batch kernel,
    whose cold compile costs more (the parallel launch around the same impact).
    """
    return impact_kernel(kernel_effects(spec))


def element_kernel(spec: KernelSpec):
    """Return the batch kernel for the rows of ``spec`` (compiled on first use, cached on disk).

    Signature: ``run(tau0, g, tau, n_arms, kappa, mu_t, mu, h, n_elem, dxi,
    max_steps, rec, rec_every, out)`` with per-set arrays of length ``n``
    (``g``, ``tau`` padded to ``(n, max_arms)``; ``h``, ``n_elem``, ``dxi``
    per set; ``mu`` the friction coefficient in tangential kernel units,
    ``mu v_z0 / |v_c0|``, ``inf`` for a spec without friction), shared ``rec_every``,
    a trajectory buffer ``rec`` of shape
    ``(n, n_rec, N_REC)`` (``n_rec`` may be 0) and ``out`` of shape
    ``(n, N_OUT)``. ``prange`` runs over the parameter sets; each writes its
    own row.
    """
    return batch_kernel(kernel_effects(spec))


@functools.cache
def batch_kernel(key: tuple):
    """Return the parallel batch kernel of the compiled effects ``key`` (:func:`element_kernel`)."""
    # the prange body calls the serial kernel of the same effects (compiled once, shared
    # with single scenes) instead of inlining the impact a second time. It is a global
    # of this copy of the batch function, not a closure cell: numba keys a closure's
    # cache entry on its pickled cells, and a dispatcher pickles with a random id per
    # process (the batch would never load from the cache); the effects are
    # the one cell, so each has its own cache entry.
    template = _batch_template(key)
    run = types.FunctionType(template.__code__, {**globals(), "_spec_impact": impact_kernel(key)},
                             template.__name__, None, template.__closure__)
    return jit(parallel=True)(_named(run, key))


def _named(function, key: tuple):
    """Return ``function`` with a qualified name that names the compiled effects ``key``.

    numba names a compiled function's machine-code symbol after its qualified name
    and a counter that restarts in every process, and keys its on-disk cache on
    the qualified name (not on the globals that hold a kernel's effects). Every
    kernel made from one body shares one qualified name, so a kernel compiled now
    and a batch loaded from the on-disk cache (compiled in another process, where
    its callee got the same count) could define the same symbol with different
    code, and the batch would run the wrong kernel's impact. A name per key keeps
    the symbols and cache entries of different kernels apart.
    """
    tag = _tag(key)
    function.__qualname__ = f"{function.__qualname__}_{tag}"
    function.__name__ = f"{function.__name__}_{tag}"
    return function


#: the impact a batch loop calls: not bound here (a declaration for the type checker);
#: :func:`batch_kernel` binds it per kernel in the loop's globals
_spec_impact: Callable[..., None]


def _batch_template(key: tuple):
    """Return the batch loop over ``_spec_impact`` (bound by :func:`batch_kernel`), keyed by ``key``."""

    def run(tau0, g, tau, n_arms, kappa, mu_t, mu, h, n_elem, dxi, max_steps, rec, rec_every, out):
        if False:  # noqa: SIM108 - keeps key a cell of the function (its cache key), never run
            key  # noqa: B018
        for i in prange(tau0.shape[0]):
            k = n_arms[i]
            _spec_impact(tau0[i], g[i, :k], tau[i, :k], kappa[i], mu_t[i], mu[i],  # noqa: F821
                         h[i], n_elem[i], dxi[i], max_steps[i], rec[i], rec_every, out[i])

    return run
