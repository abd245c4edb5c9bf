"""Pure-Python baseline of the MDR impact: plain floats and lists, no NumPy.

The algorithm of ``naive_impact`` of :mod:`vimpact.reference.numpy_elements`
(generalized Stormer-Verlet with the dashpot implicit in the half-step
velocity, a row of elements that follow the sphere or relax freely, exact
exponential update of the Maxwell arm, an element in contact for part of a
step weighed by that part in the step impulse), restricted to what the
throughput benchmark needs: Kelvin-Voigt and one-arm standard-solid
materials (at most one arm, any parallel dashpot) and the default
``incremental`` tangential memory. It loops over every element of the row in
every step, like ``naive_impact``.

The partial-step weighing is the simpler first form (force linear over the
part of the step in contact, dashpots at the half-step velocity); the kernel
and ``naive_impact`` have since refined how the dashpot enters it. So the
baseline agrees with them to the discretization error (the difference
shrinks under refinement), not to rounding, and takes the same time steps:
the same work per element-update, which is what the throughput benchmark
compares.

The tangential problem (full stick) is included, so that the baseline does
the same work per element as the kernel on the oblique benchmark scenes; it
is skipped for ``v_c0 = 0``, as in the kernel. Only the contact-point
velocity ``v_c = v_x + R omega`` is tracked (``dv_c/dt = -F_x (1/m +
R^2/Theta)``, docs/physics.md#energy-and-passivity), which is what ``e_x`` needs;
``naive_impact`` splits it into ``v_x`` and ``omega``, which is the same to
rounding.

The discretization (time step and element spacing, refined for stiff modes)
follows the kernel's rule, :func:`vimpact.engine.routing.refinement`, as
``naive_impact`` does. Units: SI throughout (m, s, kg, Pa); see
``vimpact.reference.numpy_elements`` for the sign conventions.
"""

from __future__ import annotations

import math

from vimpact import Numerics, Scene
from vimpact.engine.routing import refinement

from .machine import element_spec


def _arm_coefficients(tau: float, dt: float) -> tuple[float, float, float]:
    """``(E, 1 - E, phi)`` of the exact arm update over ``dt`` (s) for arm time ``tau`` (s).

    ``q(dt) = E q0 + (1 - E) w0 + phi (w1 - w0)`` for ``w`` linear from ``w0``
    to ``w1`` (docs/physics.md#rheologies); ``tau = inf`` gives ``(1, 0, 0)``.
    """
    x = dt / tau
    one_minus_E = -math.expm1(-x)
    if x < 1e-3:  # series: the closed form cancels
        phi = x * (1.0 / 2.0 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0)))
    else:
        phi = 1.0 - one_minus_E / x
    return 1.0 - one_minus_E, one_minus_E, phi


def _advance(q: float, w0: float, w1: float, c: tuple[float, float, float]) -> float:
    """Arm variable (m) after the displacement went linearly ``w0 -> w1`` (m)."""
    E, one_minus_E, phi = c
    return E * q + one_minus_E * w0 + phi * (w1 - w0)


def kernel_refinement(scene: Scene, steps: int, elements: int, row_width: float = 1.05,
                      ) -> tuple[float, float]:
    """Return the element kernel's refinement factors for ``scene``.

    The element kernel's ``(time_factor, element_factor)`` for ``scene``
    (:func:`vimpact.engine.routing.refinement`), dimensionless, >= 1.
    """
    numerics = Numerics(steps=steps, elements=elements, row_width=row_width, continuum=False)
    return refinement(scene, numerics, element_spec(scene, numerics))


def refined_row(scene: Scene, steps: int, elements: int, row_width: float = 1.05,
                ) -> tuple[float, int, int]:
    """Return the discretization of ``scene`` as the kernel and ``naive_impact`` refine it.

    Returns the factor by which the time step is shorter than ``t_H /
    steps``, the elements per Hertz radius ``a_H`` and the elements in the
    half row (all dimensionless), from :func:`vimpact.engine.routing.refinement`
    (finer for a stiff tangential mode or a glassy contact).
    """
    time_factor, element_factor = kernel_refinement(scene, steps, elements, row_width)
    per_a_H = int(math.ceil(elements * element_factor))
    return time_factor, per_a_H, int(math.ceil(row_width * per_a_H))


def pure_python_impact(scene: Scene, steps: int, elements: int, row_width: float = 1.05,
                       max_time: float = 100.0) -> dict:
    """Simulate ``scene`` like ``naive_impact`` with plain Python floats and lists.

    Parameters
    ----------
    scene : the impact; its material has at most one Maxwell arm and its
        ``tangential_memory`` is ``"incremental"``
    steps : time steps per Hertz contact time ``t_H`` (of ``G_inf``), before
        refinement (:func:`refined_row`)
    elements : elements per Hertz radius ``a_H`` on the half row, before refinement
    row_width : half-row length in units of ``a_H``
    max_time : time limit in units of ``t_H + 10 eta0 / G_inf``

    Returns
    -------
    dict with ``e_z`` and ``e_x`` (1; ``e_x`` NaN if ``v_c0 = 0``),
    ``status`` (``ok``, ``time_limit``, ``row_exceeded``, ``non_finite``;
    the half-space limit is not checked), ``steps`` (time steps taken) and
    ``n_elements`` (elements in the half row, refined).
    """
    mat = scene.material
    if len(mat.arms) > 1 or scene.tangential_memory != "incremental":
        raise ValueError("pure_python_impact: at most one Maxwell arm and "
                         "tangential_memory='incremental' only")
    G_inf, eta0, nu = float(mat.G_inf), float(mat.eta0), float(mat.nu)
    G1, tau1 = mat.arms[0] if mat.arms else (0.0, math.inf)  # Pa, s
    has_arm = bool(mat.arms)
    R, m = float(scene.R), float(scene.m)
    k_n = 2.0 / (1.0 - nu)  # normal stiffness per length / G
    k_t = 4.0 / (2.0 - nu)  # tangential stiffness per length / G
    mu = scene.contact_mass_factor / m  # 1/m + R^2/Theta: dv_c/dt = -mu F_x, 1/kg

    hz = scene.hertz
    time_factor, per_a_H, n = refined_row(scene, steps, elements, row_width)
    h = float(hz.t_H) / steps / time_factor  # s
    dx = float(hz.a_H) / per_a_H  # m
    gap = [((j + 0.5) * dx) ** 2 / R for j in range(n)]  # MDR profile x^2 / R, m
    weight = 2.0 * dx  # each element stands for itself and its mirror image, m
    max_steps = int(math.ceil(max_time * (float(hz.t_H) + 10.0 * eta0 / G_inf) / h))
    c_h = _arm_coefficients(tau1, h)
    decay = math.exp(-h * G_inf / eta0) if eta0 > 0.0 else 0.0  # free KV element over h

    def relax(w0: float, q0: float) -> tuple[float, float]:
        """Free element under zero force over one step (as ``Rheology.relax``)."""
        if not has_arm:
            return w0 * decay, q0
        E, one_minus_E, phi = c_h
        w1 = ((eta0 / h * w0 + G1 * (E * q0 + (one_minus_E - phi) * w0))
              / (eta0 / h + G_inf + G1 * (1.0 - phi)))
        return w1, _advance(q0, w0, w1, c_h)

    def free_rate(w: float, q: float) -> float:
        """``dw/dt`` (m/s) of a free element (as ``Rheology.free_rate``)."""
        if eta0 > 0.0:
            return -(G_inf * w + G1 * (w - q)) / eta0
        return G1 * (w - q) / tau1 / (G_inf + G1) if has_arm else 0.0

    tangential = scene.v_c0 != 0.0
    w, q, s, p = [0.0] * n, [0.0] * n, [0.0] * n, [0.0] * n  # m
    f_last, ft_last = [0.0] * n, [0.0] * n  # last normal / tangential force in contact, N
    contact = [False] * n
    u, v_z, v_c = 0.0, float(scene.v_z0), float(scene.v_c0)  # m, m/s
    Fz_spring = Cz = Fx_spring = Cx = 0.0  # N, N s/m
    j_outer_max = -1
    status = "time_limit"
    step = 0
    while step < max_steps:
        # half kick, dashpot implicit in the half-step velocities; drift
        v_z_half = (m * v_z - 0.5 * h * Fz_spring) / (m + 0.5 * h * Cz)
        v_c_half = (v_c - 0.5 * h * mu * Fx_spring) / (1.0 + 0.5 * h * mu * Cx)
        u_new = u + h * v_z_half
        du_c = h * v_c_half
        Fz_spring = Fx_spring = 0.0
        # partial contact within the step: the trapezoid h/2 (F_start + F_end) gets,
        # per such element, the end force that makes it the integral of the element's
        # force taken linear in time over its part of the step
        corr_z = corr_x = 0.0
        n_c, j_outer = 0, -1
        for j in range(n):
            w0, w1 = w[j], u_new - gap[j]
            was_in = contact[j]
            if was_in:  # follows the sphere, arm on the linear path
                theta, c = 1.0, c_h
                q[j] = _advance(q[j], w0, w1, c)
            else:  # relaxes over the step; enters if the sphere reaches it
                w_rel, q[j] = relax(w0, q[j])
                if tangential:
                    s[j], p[j] = relax(s[j], p[j])
                if w1 < w_rel:
                    w[j] = w_rel
                    continue
                # theta: fraction of the step after the sphere reached the surface
                theta = (w1 - w_rel) / (w1 - w_rel + w0 - (u - gap[j]))
                c = _arm_coefficients(tau1, theta * h)
                f_entry = k_n * weight * (G_inf * w_rel + G1 * (w_rel - q[j]) + eta0 * v_z_half)
                q[j] = _advance(q[j], w_rel, w1, c)
            w[j] = w1
            spring = G_inf * w1 + G1 * (w1 - q[j])  # Pa
            force = k_n * weight * (spring + eta0 * v_z_half)  # N
            if force <= 0.0:  # no adhesion: leaves contact
                contact[j] = False
                if was_in:  # left after the fraction alpha: force f_last -> 0
                    alpha = f_last[j] / (f_last[j] - force)
                    corr_z += alpha * force
                    if tangential:  # trial tangential end force (not kept)
                        s_l = s[j] + du_c
                        p_l = _advance(p[j], s[j], s_l, c_h)
                        ft1 = k_t * weight * (G_inf * s_l + G1 * (s_l - p_l) + eta0 * v_c_half)
                        corr_x += alpha**2 * ft1 - (1.0 - alpha) ** 2 * ft_last[j]
                continue
            contact[j] = True
            f_last[j] = force
            n_c, j_outer = n_c + 1, j
            Fz_spring += k_n * weight * spring
            if not was_in:  # entered for the last theta h: from the force at entry
                corr_z += theta * (f_entry + force) - force
            if tangential:  # incremental memory: displacement since entering
                s0, s1 = s[j], s[j] + du_c * theta
                ft_entry = k_t * weight * (G_inf * s0 + G1 * (s0 - p[j]) + eta0 * v_c_half)
                p[j] = _advance(p[j], s0, s1, c)
                s[j] = s1
                f_spring = k_t * weight * (G_inf * s1 + G1 * (s1 - p[j]))
                Fx_spring += f_spring
                ft_last[j] = f_spring + k_t * weight * eta0 * v_c_half
                if not was_in:
                    corr_x += theta * (ft_entry + ft_last[j]) - ft_last[j]
        Cz = k_n * weight * eta0 * n_c
        Cx = k_t * weight * eta0 * n_c
        # second half kick
        v_z = v_z_half - 0.5 * h * (Fz_spring + Cz * v_z_half + corr_z) / m
        v_c = v_c_half - 0.5 * h * mu * (Fx_spring + Cx * v_c_half + corr_x)
        u = u_new
        step += 1
        if not (math.isfinite(u) and math.isfinite(v_z) and math.isfinite(v_c)):
            status = "non_finite"
            break
        j_outer_max = max(j_outer_max, j_outer)
        if j_outer_max >= n - 1:
            status = "row_exceeded"
            break
        # end: no contact, moving away, and no free surface catches up
        if n_c == 0 and v_z < 0.0 and not any(
                free_rate(w[j], q[j]) < v_z * (1.0 + 1e-9) for j in range(n)):
            status = "ok"
            break
    return {
        "e_z": abs(v_z) / float(scene.v_z0),
        "e_x": abs(v_c) / abs(float(scene.v_c0)) if tangential else math.nan,
        "status": status, "steps": step, "n_elements": n,
    }
