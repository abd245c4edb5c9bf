"""Slow, independent reference of the MDR impact in physical (SI) units.

This is the documentation-grade restatement of the element model of
docs/physics.md (method of dimensionality reduction to energy and passivity), written
directly in metres, seconds, kilograms and
pascals. It shares no code with :mod:`vimpact.kernels.elements` and does not
nondimensionalize anything: it only takes the discretization (``t_H`` and
``a_H`` for the step and the element spacing) from
:func:`vimpact.model.hertz.hertz_scales`; how much finer than that the kernel
resolves a scene is the caller's ``refinement`` (the engine's rule,
:func:`vimpact.engine.routing.refinement`, which the reference does not
import: it sits below the engine). In particular it

- uses the element stiffnesses ``c_n G`` and ``c_t G`` per unit length with
  ``c_n = 2 / (1 - nu)``, ``c_t = 4 / (2 - nu)`` and the material moduli in Pa,
- tracks the centre velocity ``v_x`` and the spin ``omega`` separately
  (``m dv_x/dt = -F_x``, ``Theta domega/dt = -R F_x``); the contact-point
  velocity ``v_c = v_x + R omega`` is only ever formed from them,
- runs the tangential problem at its true size (no scaling by ``v_c0``).

The time stepping is the same algorithm as the kernel's ``VERLET``
integrator, so for the same discretization both agree to rounding (about
1e-9 relative or better): the trapezoidal step impulse, with an element in
contact for only part of a step weighed by that part (its force taken
linear in time over it: from its last force to zero at the leave fraction
``alpha``, from its force at the moment of entry over the entering fraction
``theta``); the normal force only with a dashpot or Maxwell arms (without
them it is continuous at entry and exit). Maxwell arms enter the kick with
their exact impulse over the drift path: the second half-kick takes their
stress at the step end, the first half the rest, its damping part implicit in
the half-step velocity like ``eta0`` (:meth:`Rheology.kick_split`); an element
entering within the step gets the arms' exact mean stress over its ramp, and
the force that decides whether an element still pushes at the step end takes
the arms' damping part at the end velocity.

Coulomb friction (docs/physics.md#coulomb-friction), written here independently of the
kernel: every element in contact first takes the stick trial; if its
tangential force exceeds ``mu`` times its normal force it slips, its
displacement (and arms) solved so that the force sits on the cone (the
force is affine in the end displacement: two evaluations give the line).
A slipping element pushes with ``mu`` times its normal force, whose dashpot
part moves with the normal velocity of each half-kick. ``check_cone``
asserts ``|f_t| <= mu f_n (1 + 1e-12)`` for every element at every step. It is vectorized
over elements with NumPy and loops
over time steps in Python: slow on purpose, keep the sizes small.

Sign convention: ``v_z > 0`` into the half-space, indentation ``u > 0``
into the half-space, the normal surface displacement ``w`` of an element is
positive into the half-space, forces push the sphere back.
"""

from __future__ import annotations

import math

import numpy as np

from vimpact.model.hertz import hertz_scales

#: docs/physics.md#the-problem: the half-space model holds up to a = 0.2 R.
HALF_SPACE_LIMIT = 0.2


# --------------------------------------------------------------- rheology

def arm_update_coefficients(tau, dt):
    """Coefficients of the exact arm update over a time ``dt`` (docs/physics.md#rheologies).

    For ``tau dq/dt = w - q`` with ``w`` linear in time from ``w0`` to ``w1``::

        q(dt) = E q0 + (1 - E) w0 + phi (w1 - w0),
        E = exp(-dt/tau),  phi = 1 - (tau/dt)(1 - E)

    ``tau`` (s) and ``dt`` (s) broadcast against each other. Returns
    ``(E, 1 - E, phi)``. ``1 - E`` comes from ``expm1``; ``phi`` from its
    Taylor series where ``dt/tau`` is small (the closed form cancels there).
    """
    x = np.asarray(dt, dtype=float) / np.asarray(tau, dtype=float)
    one_minus_E = -np.expm1(-x)
    E = 1.0 - one_minus_E
    series = x * (1.0 / 2.0 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0)))
    safe_x = np.where(x > 0.0, x, 1.0)
    closed = 1.0 - one_minus_E / safe_x
    phi = np.where(x < 1e-3, series, closed)
    return E, one_minus_E, phi


def advance_arms(q, w0, w1, coefficients):
    """Arm variables ``q`` (elements x arms, m) after ``w`` went linearly ``w0 -> w1``."""
    E, one_minus_E, phi = coefficients
    return E * q + one_minus_E * w0[:, None] + phi * (w1 - w0)[:, None]


class Rheology:
    """The general element of the rheologies.

    The general element of docs/physics.md#rheologies, per unit length and per
    unit of the geometric factor ``c`` (``c_n`` or ``c_t``)::

        stress(w, q, dw/dt) = G_inf w + eta0 dw/dt + sum_i G_i (w - q_i)

    Moduli in Pa, ``eta0`` in Pa s, ``tau_i`` in s.
    """

    def __init__(self, material):
        self.G_inf = float(material.G_inf)
        self.eta0 = float(material.eta0)
        self.G = np.array([G for G, _ in material.arms], dtype=float)
        self.tau = np.array([tau for _, tau in material.arms], dtype=float)
        self.n_arms = len(self.G)

    def spring_stress(self, w, q):
        """``G_inf w + sum_i G_i (w - q_i)`` (Pa), the part without the dashpot."""
        return self.G_inf * w + (self.G * (w[:, None] - q)).sum(axis=1)

    def relax(self, w0, q0, h, coefficients):
        """Free surface under zero force over one step ``h`` (docs/physics.md#kelvin-voigt-continuum).

        Solves ``eta0 dw/dt + G_inf w + sum G_i (w - q_i) = 0``:
        without arms exactly (``w0 exp(-h G_inf/eta0)``, or 0 for an elastic
        element); with arms implicitly in the end value ``w1``, the arms on
        the exact linear-path update ``w0 -> w1``:
        ``eta0 (w1 - w0)/h + G_inf w1 + sum G_i (w1 - q_i(w1)) = 0``.
        Returns ``(w1, q1)``.
        """
        if self.n_arms == 0:
            if self.eta0 > 0.0:
                return w0 * math.exp(-h * self.G_inf / self.eta0), q0
            return np.zeros_like(w0), q0
        E, one_minus_E, phi = coefficients
        # q_i(w1) = E q0 + (1-E) w0 + phi (w1 - w0): collect the terms in w1
        lhs = self.eta0 / h + self.G_inf + (self.G * (1.0 - phi)).sum()
        rhs = self.eta0 / h * w0 + (self.G * (E * q0 + (one_minus_E - phi) * w0[:, None])).sum(axis=1)
        w1 = rhs / lhs
        return w1, advance_arms(q0, w0, w1, coefficients)

    def kick_split(self, h, coefficients):
        """How the Verlet kick splits each arm's exact step impulse (fast arms implicit).

        On a step ``h`` where an element's ``w`` moves linearly at the drift
        velocity ``v``, the arm stress ``G_i (w - q_i)`` has the exact impulse
        ``h G_i [(1 - phi_i)(w0 - q0_i) + tau_i phi_i v]`` and the end value
        ``G_i [E_i (w0 - q0_i) + tau_i (1 - E_i) v]``. With the end value in the
        second half-kick, the first half must carry ``G_i [kap_i (w0 - q0_i) +
        c_i v]``: ``kap_i = 2 (1 - phi_i) - E_i`` and the damping
        ``c_i = tau_i (1 + E_i - 2 (1 - E_i) tau_i / h) >= 0`` taken implicitly
        like ``eta0``. Returns ``(kap, sum G_i c_i, sum G_i tau_i (1 - E_i))``
        (1, Pa s, Pa s).
        """
        E, one_minus_E, phi = coefficients
        x = h / self.tau
        c = np.where(x < 1e-3, h * x * (1.0 / 6.0 - x * (1.0 / 12.0 - x / 40.0)),
                     self.tau * (1.0 + E - 2.0 * one_minus_E / np.where(x > 0.0, x, 1.0)))
        return 2.0 * (1.0 - phi) - E, float((self.G * c).sum()), float((self.G * h * (1.0 - phi)).sum())

    def start_stress(self, w, q, kap):
        """``G_inf w + sum_i G_i kap_i (w - q_i)`` (Pa): the first half-kick's stress."""
        return self.G_inf * w + (self.G * kap * (w[:, None] - q)).sum(axis=1)

    def arm_mean_stress(self, w0, w1, q0, dt):
        """Return the arms' stress averaged over ``dt``, Pa per element.

        The arms' stress averaged over ``dt`` (Pa, per element) on the linear path
        ``w0 -> w1`` from ``q0``: ``sum G_i [(1 - phi_i)(w0 - q0_i) + (tau_i phi_i /
        dt)(w1 - w0)]``; ``dt`` per element.
        """
        _, _, phi = arm_update_coefficients(self.tau[None, :], dt[:, None])
        x = dt[:, None] / self.tau[None, :]
        phi_x = np.where(x < 1e-3, 0.5 - x * (1.0 / 6.0 - x / 24.0),
                         phi / np.where(x > 0.0, x, 1.0))
        return (self.G * ((1.0 - phi) * (w0[:, None] - q0)
                          + phi_x * (w1 - w0)[:, None])).sum(axis=1)

    def free_rate(self, w, q):
        """``dw/dt`` (m/s) of free surface elements under zero force."""
        spring = self.spring_stress(w, q)
        if self.eta0 > 0.0:
            return -spring / self.eta0
        if self.n_arms == 0:
            return np.zeros_like(w)  # elastic: already at rest at w = 0
        # d/dt [G_inf w + sum G_i (w - q_i)] = 0 with tau_i dq_i/dt = w - q_i
        arm_rates = (self.G * (w[:, None] - q) / self.tau).sum(axis=1)
        return arm_rates / (self.G_inf + self.G.sum())


# ------------------------------------------------------------------ impact

def stick_path_in_cone(L0, L1, C0, C1, alpha):
    """Integrate a leaving element's tangential force over part of a step.

    Integral over ``t`` in ``[0, alpha]`` (fractions of the step) of a sticking
    element's tangential force as it leaves: the stick path ``L0 + t (L1 - L0)``
    clipped to the cone ``|f_t| <= C0 + t (C1 - C0)``, which reaches 0 with the
    normal force at ``t = alpha``. ``|L| - C`` is convex: the element sticks up to
    ``t*`` (where ``|L| = C``) and then follows the cone, with the sign of
    ``L(alpha)``, down to 0. Arrays of one length; N s / h.
    """
    L0, L1, C0, C1, alpha = np.broadcast_arrays(*(np.asarray(x, dtype=float)
                                                  for x in (L0, L1, C0, C1, alpha)))
    dL, dC = L1 - L0, C1 - C0
    La = L0 + alpha * dL
    sg = np.sign(La)
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = np.where(sg * L0 >= C0, 0.0, (C0 - sg * L0) / (sg * dL - dC))
    ts = np.where(sg == 0.0, alpha, np.clip(np.nan_to_num(ts, nan=0.0), 0.0, alpha))
    out = ts * L0 + 0.5 * ts**2 * dL + sg * 0.5 * (C0 + ts * dC) * (alpha - ts)
    return np.where(alpha > 0.0, out, 0.0)


def naive_impact(scene, steps, elements, row_width=1.05, max_time=100.0, mu=None,
                 check_cone=True, flat_punch=None, refinement=(1.0, 1.0)):
    """Simulate ``scene`` with the NumPy reference of the element kernel.

    Simulate ``scene`` (a :class:`vimpact.Scene`) in SI units with the
    Stormer-Verlet scheme of the kernel.

    Parameters
    ----------
    scene : the impact
    steps : time steps per Hertz contact time ``t_H`` (of ``G_inf``)
    elements : elements per Hertz radius ``a_H`` on the half row
    row_width : half-row length in units of ``a_H``
    max_time : time limit in units of ``t_H + 10 eta0 / G_inf``
    mu : Coulomb friction coefficient (default ``scene.mu`` if the scene has
        one, else ``inf``: full stick); needs incremental memory
    check_cone : raise ``AssertionError`` if an element in contact ends a
        step with ``|f_t| > mu f_n (1 + 1e-12)``
    flat_punch : radius ``a0`` (m) of a flat punch instead of the sphere's
        MDR profile (docs/physics.md#linear-model): ``g = 0`` on ``|x| < a0``, no
        element outside; every element enters at once and leaves together
    refinement : ``(time_factor, element_factor)``, both >= 1 (dimensionless):
        the step is ``t_H / steps / time_factor``, the spacing ``a_H /
        ceil(elements element_factor)``; the kernel's own factors for this
        scene come from :func:`vimpact.engine.routing.refinement` (a stiff
        tangential mode or a glassy contact is resolved more finely)

    Returns
    -------
    dict with ``e_z, e_x, beta_x`` (1; ``e_x, beta_x`` NaN if ``v_c0 = 0``),
    ``v_z_end, v_x_end`` (m/s), ``omega_end`` (rad/s), ``t_contact`` (s),
    ``u_max``, ``a_max`` (m), ``energy_ratio`` (1), ``status``
    (``ok``, ``vc0_zero``, ``half_space``, ``time_limit``, ``row_exceeded``,
    ``non_finite``), ``steps`` (time steps taken), ``t_gross_slip`` (s with
    every element in contact slipping), ``w_friction`` (J dissipated by slip)
    and ``slip_width_max`` (m, widest slip zone on the half row).
    """
    mat = scene.material
    rheo = Rheology(mat)
    nu = float(mat.nu)
    c_n = 2.0 / (1.0 - nu)  # normal stiffness per length / G
    c_t = 4.0 / (2.0 - nu)  # tangential stiffness per length / G
    R, m, Theta = float(scene.R), float(scene.m), float(scene.Theta)

    hz = hertz_scales(mat.G_inf, nu, R, m, scene.v_z0)
    # the caller's refinement (the kernel's rule: finer steps and elements for a
    # stiffer tangential mode or a glassy contact): taken, not re-derived
    time_factor, element_factor = (float(f) for f in refinement)
    h = hz.t_H / steps / time_factor  # s
    elements = int(math.ceil(elements * element_factor))
    dx = hz.a_H / elements  # m
    n = int(math.ceil(row_width * elements))
    if flat_punch is not None:  # the same spacing, as many elements as fit in a0
        n = max(1, round(flat_punch / dx))
        dx = flat_punch / n
    x = (np.arange(n) + 0.5) * dx  # element positions, m
    gap = x * x / R if flat_punch is None else np.zeros(n)  # MDR profile g(x) = x^2 / R, m
    weight = 2.0 * dx  # symmetric row: each element stands for itself and its mirror image
    max_steps = int(math.ceil(max_time * (hz.t_H + 10.0 * rheo.eta0 / rheo.G_inf) / h))

    arms_h = arm_update_coefficients(rheo.tau, h)  # full-step coefficients, per arm
    # arms in the kick: exact step impulse, damping part implicit (Rheology.kick_split)
    implicit = rheo.n_arms > 0
    kap, arm_damping, _ = rheo.kick_split(h, arms_h) if implicit else (None, 0.0, 0.0)
    # the arms' end stress on the straight drift path misses its curvature a: on
    # w0 + v t + a t^2/2 the stress is larger by arm_damping * a h / 2 = arm_damping
    # (v_end - v_half), which the force at the step end takes (as eta0 takes v_end)
    arm_end = arm_damping
    weighted = rheo.eta0 > 0.0 or implicit  # force can jump at entry: weigh partial steps

    # element state
    w = np.zeros(n)  # normal surface displacement, m
    q = np.zeros((n, rheo.n_arms))  # normal arm variables, m
    s = np.zeros(n)  # tangential surface displacement, m
    p = np.zeros((n, rheo.n_arms))  # tangential arm variables, m
    contact = np.zeros(n, dtype=bool)
    f_last = np.zeros(n)  # last normal spring force of each element in contact, N
    f_start = np.zeros(n)  # ... as the first half-kick takes it (start_stress), N

    # sphere state
    u, v_z = 0.0, float(scene.v_z0)  # indentation (m), normal velocity (m/s)
    v_x, omega = float(scene.v_x0), float(scene.omega0)
    u_c = 0.0  # tangential displacement of the contact point, m
    # forces of the current state: spring part and dashpot coefficient (N, N s/m)
    Fz_spring, Cz = 0.0, 0.0
    Fx_spring, Cx = 0.0, 0.0
    Fz_start, Fx_start, Cz_arm, Cx_arm = 0.0, 0.0, 0.0, 0.0  # first half-kick: arms split
    Fx_slip_start, Cx_slip_start = 0.0, 0.0  # ... slipping: mu times the normal force so

    memory = scene.tangential_memory
    if mu is None:
        mu = float(getattr(scene, "mu", math.inf))
    friction = mu < math.inf
    if friction and memory != "incremental":
        raise ValueError(f"friction (mu = {mu}) needs incremental tangential memory, "
                         f"not {memory!r}")
    # last step's tangential force of each element in contact without its
    # dashpot part (N) and its slip direction (0: sticking)
    ft_pos = np.zeros(n)
    ft_start = np.zeros(n)  # sticking: as the first half-kick takes it, N
    slip_sign = np.zeros(n)
    Fx_slip, Cx_slip = 0.0, 0.0  # slipping elements: mu F_n, spring part (N), per v_z (N s/m)
    t_gross, w_friction, slip_width_max = 0.0, 0.0, 0.0
    t_contact = 0.0
    u_max = 0.0
    j_outer_max = -1
    status = "time_limit"
    step = 0
    while step < max_steps:
        # ---- first half kick, dashpot implicit in the half-step velocities ----
        # m v+ = m v - h/2 (Fz_spring + Cz v+)
        v_z_half = (m * v_z - 0.5 * h * Fz_start) / (m + 0.5 * h * (Cz + Cz_arm))
        # m v_x+ = m v_x - h/2 F_x,  Theta omega+ = Theta omega - h/2 R F_x,
        # F_x = Fx_spring + Cx (v_x+ + R omega+): a 2x2 linear system
        k = 0.5 * h * (Cx + Cx_arm)
        A = np.array([[m + k, k * R], [k * R, Theta + k * R * R]])
        Fx_known = Fx_start + (Fx_slip_start + Cx_slip_start * v_z_half if implicit
                               else Fx_slip + Cx_slip * v_z_half)
        b = np.array([m * v_x - 0.5 * h * Fx_known, Theta * omega - 0.5 * h * R * Fx_known])
        v_x_half, omega_half = np.linalg.solve(A, b)
        v_c_half = v_x_half + R * omega_half
        # velocities at the step ends (the end one extrapolated through the half
        # step): the dashpots of the force path of an element in partial contact
        v_z_start, v_c_start = v_z, v_x + R * omega
        v_z_end, v_c_end_step = 2.0 * v_z_half - v_z_start, 2.0 * v_c_half - v_c_start

        # ---- drift ----
        u_new = u + h * v_z_half
        u_c_new = u_c + h * v_c_half
        du_c = u_c_new - u_c
        w_sphere_old = u - gap  # where the sphere surface was above each element
        w_sphere = u_new - gap  # ... and is now

        # ---- elements ----
        was_in = contact.copy()
        free = ~was_in
        w0 = w.copy()
        s0 = s.copy()

        # in contact: follow the sphere, arms on the exact linear path
        q[was_in] = advance_arms(q[was_in], w0[was_in], w_sphere[was_in], arms_h)
        # free: relax under zero force over the whole step (normal and tangential)
        w_free, q[free] = rheo.relax(w0[free], q[free], h, arms_h)
        s_free, p[free] = rheo.relax(s0[free], p[free], h, arms_h)
        w_relaxed = w0.copy()
        w_relaxed[free] = w_free
        s[free] = s_free
        # a free element enters when the sphere reaches its relaxed surface
        entering = free & (w_sphere >= w_relaxed)
        staying_free = free & ~entering
        w[staying_free] = w_relaxed[staying_free]
        # theta: fraction of the step after the sphere reached the surface
        # (linear interpolation of the gap sphere - surface over the step)
        theta = np.ones(n)
        gain = w_sphere - w_relaxed
        theta[entering] = gain[entering] / (gain[entering] + (w0 - w_sphere_old)[entering])
        # entering elements ramp from the relaxed surface to the sphere over theta h
        # normal force at the moment of entry (relaxed surface, dashpot at v_z then)
        f_entry = np.zeros(n)
        # with arms: the force over the entering part is the relaxed spring and the
        # dashpot on a line, plus the arms' exact mean stress on the ramp
        f_entry_lin = np.zeros(n)
        arm_mean = np.zeros(n)
        if entering.any():  # (on most steps no element enters)
            arms_theta = arm_update_coefficients(rheo.tau[None, :],
                                                 (theta[entering] * h)[:, None])
            v_entry = v_z_start + 2.0 * (1.0 - theta) * (v_z_half - v_z_start)
            f_entry[entering] = c_n * weight * (rheo.spring_stress(w_relaxed[entering],
                                                                   q[entering])
                                                + rheo.eta0 * v_entry[entering])
            if implicit:
                f_entry_lin[entering] = c_n * weight * (rheo.G_inf * w_relaxed[entering]
                                                        + rheo.eta0 * v_entry[entering])
                arm_mean[entering] = c_n * weight * rheo.arm_mean_stress(
                    w_relaxed[entering], w_sphere[entering], q[entering], theta[entering] * h)
            q[entering] = advance_arms(q[entering], w_relaxed[entering], w_sphere[entering],
                                       arms_theta)

        touching = was_in | entering
        w[touching] = w_sphere[touching]
        spring = np.zeros(n)
        spring[touching] = c_n * weight * rheo.spring_stress(w[touching], q[touching])  # N
        force = spring + c_n * weight * rheo.eta0 * v_z_half  # N, element and mirror image
        # at the step end: the arms' damping part at the end velocity, as the dashpot
        spring_end = spring + c_n * weight * arm_end * (v_z_end - v_z_half) * touching
        force_end = spring_end + c_n * weight * rheo.eta0 * v_z_end
        # no adhesion: an element whose force would pull at the step end leaves
        leaving = touching & (force_end <= 0.0)
        now_in = touching & ~leaving
        left = leaving & was_in

        # Partial contact within the step. The kick's trapezoid h/2 (F_start + F_end)
        # of the applied forces (dashpots at the half-step velocities) gets, per
        # element in contact for part of the step, what makes it the integral of
        # the element's force over that part, the force linear in time between
        # its values at the step ends (dashpots at v_start and v_end).
        corr_z, corr_x = 0.0, 0.0
        if left.any():
            dash_z = c_n * weight * rheo.eta0
            T0 = f_last[left] + dash_z * v_z_start
            T1 = force_end[left]
            alpha = np.where(T0 <= 0.0, 0.0, np.where(T1 >= 0.0, 1.0, T0 / np.where(
                T0 - T1 > 0.0, T0 - T1, 1.0)))
            t_leave = ((step + alpha) * h).max()
            if weighted:  # the normal force jumps at entry only with a dashpot (or a fast arm)
                applied = (f_start[left] + (dash_z + c_n * weight * arm_damping) * v_z_half
                           if implicit else f_last[left] + dash_z * v_z_half)
                corr_z += float((alpha * T0 - applied).sum())
            # tangential: from T0t at the start to the stick trial T1t at the end
            s_l = np.full(int(left.sum()), u_c_new) if memory == "seed" else s[left] + du_c
            p_l = advance_arms(p[left], s[left], s_l, arms_h)  # trial only, not kept
            T1t = c_t * weight * (rheo.spring_stress(s_l, p_l) + rheo.eta0 * v_c_end_step
                                  + arm_end * (v_c_end_step - v_c_half))
            trial_t = T1t
            sg = slip_sign[left]
            dash_t = c_t * weight * rheo.eta0
            T0t = ft_pos[left] + np.where(sg != 0.0, sg * mu * dash_z * v_z_start if friction
                                          else 0.0, dash_t * v_c_start)
            A_t = ft_pos[left] + np.where(sg != 0.0, sg * mu * dash_z * v_z_half if friction
                                          else 0.0, dash_t * v_c_half)
            if implicit:  # what the first half-kick applied
                A_t = np.where(sg != 0.0, sg * mu * (f_start[left] + (
                    dash_z + c_n * weight * arm_damping) * v_z_half) if friction else 0.0,
                               ft_start[left] + (dash_t + c_t * weight * arm_damping) * v_c_half)
            if friction:
                T1t = np.where(sg != 0.0, sg * mu * T1, T1t)
            path = 2.0 * alpha * T0t + alpha**2 * (T1t - T0t) - A_t
            if friction:  # sticking: the stick path inside the cone, which shrinks to 0
                path = np.where(sg == 0.0, 2.0 * stick_path_in_cone(  # with the normal force
                    T0t, trial_t, mu * T0, mu * T1, alpha) - A_t, path)
            if not weighted:  # slipping: mu times the normal force, not corrected
                path = np.where(sg != 0.0, 0.0, path)
            corr_x += float(path.sum())
        contact = now_in
        f_last[now_in] = spring_end[now_in]
        if implicit:
            f_start[now_in] = c_n * weight * rheo.start_stress(w[now_in], q[now_in], kap)
        new = now_in & entering
        # entering for the last theta h: from the force at entry to the end force
        entry_z = np.zeros(n)  # what the normal force over the entering part adds
        if implicit:  # (the arms at their exact mean)
            lin_end = c_n * weight * (rheo.G_inf * w[new] + rheo.eta0 * v_z_end)
            entry_z[new] = (theta[new] * (f_entry_lin[new] + lin_end + 2.0 * arm_mean[new])
                            - force[new])
        elif weighted:
            entry_z[new] = theta[new] * (f_entry[new] + force_end[new]) - force[new]
        corr_z += float(entry_z[new].sum())

        # tangential state of the elements in contact (docs/physics.md#full-stick)
        s_start, p_start = s.copy(), p.copy()  # relaxed state for the entering ones
        if memory == "seed":  # thesis eq. 4.16: total contact-point displacement
            s_new = np.full(n, u_c_new)
        else:  # incremental: only the displacement since entering loads an element
            s_new = s + du_c * theta  # theta = 1 for elements that were in contact
        stay = now_in & was_in
        entered = new.any()
        arm_mean_t = np.zeros(n)
        if entered and implicit and memory != "seed":  # entering: the arms' exact mean
            arm_mean_t[new] = c_t * weight * rheo.arm_mean_stress(
                s_start[new], s_new[new], p_start[new], theta[new] * h)
        p[stay] = advance_arms(p_start[stay], s_start[stay], s_new[stay], arms_h)
        if entered:
            arms_new = arm_update_coefficients(rheo.tau[None, :], (theta[new] * h)[:, None])
            p[new] = advance_arms(p_start[new], s_start[new], s_new[new], arms_new)
        s[now_in] = s_new[now_in]
        t_spring = np.zeros(n)  # tangential force without the dashpot, N
        t_spring[now_in] = c_t * weight * rheo.spring_stress(s[now_in], p[now_in])
        f_t = t_spring + c_t * weight * rheo.eta0 * v_c_half  # stick trial as applied, N
        v_c_entry = v_c_start + 2.0 * (1.0 - theta) * (v_c_half - v_c_start)
        ft_entry = np.zeros(n)
        if entered:
            ft_entry[new] = c_t * weight * (rheo.spring_stress(s_start[new], p_start[new])
                                            + rheo.eta0 * v_c_entry[new])
        ft_end = t_spring + c_t * weight * rheo.eta0 * v_c_end_step
        if memory == "seed":  # the element jumps to the total displacement at entry
            ft_entry[new] = ft_end[new]
        slip = np.zeros(n, dtype=bool)
        if friction:
            slip = now_in & (np.abs(f_t) > mu * force)
            cone_entry = mu * np.maximum(f_entry[new], 0.0)
            ft_entry[new] = np.clip(ft_entry[new], -cone_entry, cone_entry)
        if entered and implicit and memory != "seed":  # the arms' exact mean over entering
            arms_entry = rheo.spring_stress(s_start[new], p_start[new]) - rheo.G_inf * s_start[new]
            arms_end = rheo.spring_stress(s[new], p[new]) - rheo.G_inf * s[new]
            ft_entry[new] += 2.0 * arm_mean_t[new] - c_t * weight * (arms_entry + arms_end)
        stick_new = new & ~slip
        corr_x += float((theta[stick_new] * (ft_entry[stick_new] + ft_end[stick_new])
                         - f_t[stick_new]).sum())
        ft_pos[now_in] = t_spring[now_in] + c_t * weight * arm_end * (v_c_end_step - v_c_half)
        if implicit:
            ft_start[now_in] = c_t * weight * rheo.start_stress(s[now_in], p[now_in], kap)
        slip_sign[now_in] = 0.0
        if slip.any():
            # the element's own path s_start -> s1 over dt (h, or theta h when
            # entering) with its force on the cone: the force is affine in s1
            idx = np.flatnonzero(slip)
            dt = np.where(was_in[idx], h, np.maximum(theta[idx], 1e-12) * h)
            coeff = arm_update_coefficients(rheo.tau[None, :], dt[:, None])
            s_a = s_start[idx]

            def path_force(s1):
                q1 = advance_arms(p_start[idx], s_a, s1, coeff)
                return c_t * weight * (rheo.spring_stress(s1, q1) + rheo.eta0 * (s1 - s_a) / dt), q1

            f_a, _ = path_force(s_a)
            s_b = np.where(s_new[idx] != s_a, s_new[idx], s_a + dx)
            f_b, _ = path_force(s_b)
            sg = np.copysign(1.0, f_t[idx])
            target = sg * mu * force[idx]
            s_slip = s_a + (target - f_a) * (s_b - s_a) / (f_b - f_a)
            _, p[idx] = path_force(s_slip)
            w_friction += float((target * (s_new[idx] - s_slip)).sum())
            s[idx] = s_slip
            f_t[idx] = target
            ft_pos[idx] = sg * mu * spring_end[idx]
            slip_sign[idx] = sg
            # entering slipping: mu times the normal force over the whole part
            ent = ~was_in[idx] & weighted
            corr_x += float((sg[ent] * mu * entry_z[idx][ent]).sum())
            slip_width_max = max(slip_width_max, idx.size * dx)
        if check_cone and friction and now_in.any():
            # slipping elements sit on the cone by construction (f_t = mu f_n
            # sign, f_n may be slightly negative in an element's last step: its
            # dashpot at the half-step velocity), sticking ones inside it
            excess = np.abs(f_t[now_in]) - mu * np.abs(force[now_in]) * (1.0 + 1e-12)
            if excess.max() > 0.0:
                raise AssertionError(f"step {step}: |f_t| > mu f_n by {excess.max():.3e} N")

        # forces of the new state
        n_c = int(now_in.sum())
        stick = now_in & ~slip
        Fz_spring = spring[now_in].sum()
        Cz = c_n * weight * rheo.eta0 * n_c
        Fx_spring = c_t * weight * rheo.spring_stress(s[stick], p[stick]).sum()
        Cx = c_t * weight * rheo.eta0 * int(stick.sum())
        Fz_start, Fx_start = Fz_spring, Fx_spring
        if implicit:
            Fz_start = float(f_start[now_in].sum())
            Fx_start = float(ft_start[stick].sum())
            Cz_arm = c_n * weight * arm_damping * n_c
            Cx_arm = c_t * weight * arm_damping * int(stick.sum())
        Fx_slip = float((slip_sign[slip] * mu * spring[slip]).sum()) if slip.any() else 0.0
        if implicit and slip.any():
            Fx_slip_start = float((slip_sign[slip] * mu * f_start[slip]).sum())
            Cx_slip_start = float((slip_sign[slip] * mu * c_n * weight
                                   * (rheo.eta0 + arm_damping)).sum())
        else:
            Fx_slip_start, Cx_slip_start = 0.0, 0.0
        Cx_slip = float((slip_sign[slip] * mu * c_n * weight * rheo.eta0).sum()) if slip.any() else 0.0
        if n_c > 0 and int(slip.sum()) == n_c:
            t_gross += h
        if n_c == 0 and left.any():
            t_contact = t_leave

        # ---- second half kick (dashpot with the half-step velocities) ----
        F_z = Fz_spring + Cz * v_z_half + corr_z
        F_x = Fx_spring + Cx * v_c_half + Fx_slip + Cx_slip * v_z_half + corr_x
        v_z = v_z_half - 0.5 * h * F_z / m
        v_x = v_x_half - 0.5 * h * F_x / m
        omega = omega_half - 0.5 * h * R * F_x / Theta
        u, u_c = u_new, u_c_new
        step += 1

        if not all(map(math.isfinite, (u, v_z, v_x, omega))):
            status = "non_finite"
            break
        u_max = max(u_max, u)
        if n_c > 0:
            j_outer_max = max(j_outer_max, int(np.flatnonzero(now_in)[-1]))
        if j_outer_max >= n - 1 and flat_punch is None:
            status = "row_exceeded"
            break
        # ---- end: no contact, moving away, and no free surface catches up ----
        if n_c == 0 and v_z < 0.0:
            rate = rheo.free_rate(w, q)
            if not (rate < v_z * (1.0 + 1e-9)).any():
                status = "ok"
                break

    v_c0 = scene.v_x0 + R * scene.omega0
    v_c_end = v_x + R * omega
    energy0 = 0.5 * (m * (scene.v_z0**2 + scene.v_x0**2) + Theta * scene.omega0**2)
    energy1 = 0.5 * (m * (v_z**2 + v_x**2) + Theta * omega**2)
    a_max = (j_outer_max + 1) * dx
    if status == "ok":
        if a_max > HALF_SPACE_LIMIT * R:
            status = "half_space"
        elif v_c0 == 0.0:
            status = "vc0_zero"
    nan = float("nan")
    return dict(
        e_z=abs(v_z) / scene.v_z0,
        e_x=abs(v_c_end) / abs(v_c0) if v_c0 != 0.0 else nan,
        beta_x=-v_c_end / v_c0 if v_c0 != 0.0 else nan,
        v_z_end=v_z, v_x_end=v_x, omega_end=omega,
        t_contact=t_contact, u_max=u_max, a_max=a_max,
        energy_ratio=energy1 / energy0, status=status, steps=step,
        t_gross_slip=t_gross, w_friction=w_friction, slip_width_max=slip_width_max,
    )
