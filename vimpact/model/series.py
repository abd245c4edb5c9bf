"""Series combination of two generalized Maxwell materials (compliances add).

A generalized Maxwell material has, in the Laplace variable ``s`` (1/s), the
operator modulus (Pa)

    M(s) = G_inf + eta0 s + sum_i G_i tau_i s / (1 + tau_i s).

Two bodies with the same Poisson ratio in contact act as one half-space with
``1/M*(s) = 1/M_1(s) + 1/M_2(s)``, i.e. ``M* = M_1 M_2 / (M_1 + M_2)``. For
passive materials (all moduli and times positive) ``M*`` is again of the
same form:

- its poles are the zeros of ``S = M_1 + M_2`` on the negative real axis. In
  the rate ``p = -s`` (1/s), ``S(-p)`` falls strictly between consecutive
  poles ``1/tau`` of ``S`` (``dS/dp = -eta0 - sum G tau / (tau p - 1)^2 < 0``),
  from ``G_inf > 0`` at ``p = 0`` to ``-inf`` below the first pole, from
  ``+inf`` to ``-inf`` between two poles and, after the last pole, to
  ``-inf`` only with a dashpot; so there is exactly one zero in each of
  these intervals and it is found by bisection in ``log p``;
- a relaxation time shared by both materials stays a pole of ``M*``;
- an arm of rate ``p_k`` has the modulus ``G_k = -Res_{s=-p_k} M* / p_k``
  (``G tau s/(1 + tau s) = G - (G/tau)/(s + 1/tau)``), with the residue
  ``M_1 M_2 / S'`` at a zero of ``S`` (non-negative by passivity; zero when
  ``M_1`` and ``M_2`` vanish there together, e.g. two Kelvin-Voigt bodies with
  the same relaxation time);
- the relaxed modulus is ``M*(0) = G_inf1 G_inf2 / (G_inf1 + G_inf2)`` and the
  parallel dashpot ``eta01 eta02 / (eta01 + eta02)`` if both have one (else none).

So ``M*`` has at most ``n_1 + n_2 + 1`` arms. Two Kelvin-Voigt bodies
``(G_1, eta_1)``, ``(G_2, eta_2)`` give the closed form: spring
``G_1 G_2/(G_1 + G_2)``, dashpot ``eta_1 eta_2/(eta_1 + eta_2)`` and one arm of
time ``(eta_1 + eta_2)/(G_1 + G_2)`` and modulus
``(G_1 eta_2 - G_2 eta_1)^2 / ((G_1 + G_2)(eta_1 + eta_2)^2)``.

Pure numpy; used by :func:`vimpact.model.pair.pair_material`.
"""

from __future__ import annotations

import numpy as np

from vimpact.model.material import Material

#: bisection steps in ``log p`` (the bracket shrinks by 2 per step: far below double precision)
_BISECTION_STEPS = 200
#: relative tolerance for merging equal relaxation times and for the frequency-domain self-check
_REL = 1e-10
#: arm moduli below this fraction of the glassy modulus are rounding of a vanishing residue
_DROP = 1e-12


def operator_modulus(mat: Material, s) -> np.ndarray:
    """Return the operator modulus ``M(s)`` of ``mat`` at ``s``, Pa.

    ``M(s) = G_inf + eta0 s + sum G_i tau_i s / (1 + tau_i s)`` of ``mat`` (Pa) at the
    Laplace variable ``s`` (1/s; real or complex, scalar or array).
    """
    s = np.asarray(s)
    out = mat.G_inf + mat.eta0 * s
    for G, tau in mat.arms:
        out = out + G * tau * s / (1.0 + tau * s)
    return out


def _arms_by_rate(mats: tuple[Material, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Arms of the sum of ``mats`` with equal times merged.

    Rates ``1/tau`` (ascending, 1/s) and moduli (Pa).
    """
    arms = sorted((1.0 / tau, G) for m in mats for G, tau in m.arms)
    rates: list[float] = []
    moduli: list[float] = []
    for p, G in arms:
        if rates and p - rates[-1] <= _REL * p:
            moduli[-1] += G
        else:
            rates.append(p)
            moduli.append(G)
    return np.array(rates), np.array(moduli)


def _sum_on_axis(G_inf: float, eta0: float, rates: np.ndarray, moduli: np.ndarray, p: float
                 ) -> float:
    """``S(-p)`` of the summed operator, strictly decreasing in ``p`` between its poles."""
    return float(G_inf - eta0 * p + np.sum(moduli * p / (p - rates)))


def _zeros(G_inf: float, eta0: float, rates: np.ndarray, moduli: np.ndarray) -> np.ndarray:
    """Return the rates ``p > 0`` (1/s) where ``S(-p) = 0``.

    One below the first pole, one between each two poles, one above the last with a
    dashpot.
    """
    edges = [0.0, *rates.tolist()]
    intervals = list(zip(edges[:-1], edges[1:]))
    if eta0 > 0.0:
        intervals.append((edges[-1], np.inf))
    f = lambda p: _sum_on_axis(G_inf, eta0, rates, moduli, p)  # noqa: E731
    out = []
    for lo, hi in intervals:
        if hi == np.inf:  # widen until the dashpot wins
            hi = max(2.0 * lo, (G_inf + moduli.sum()) / eta0, 1e-300)
            while f(hi) >= 0.0:
                hi *= 10.0
        if lo == 0.0:
            lo = hi * 1e-300
        a, b = np.log(lo), np.log(hi)
        for _ in range(_BISECTION_STEPS):
            mid = 0.5 * (a + b)
            if mid in (a, b):
                break
            if f(np.exp(mid)) > 0.0:
                a = mid
            else:
                b = mid
        out.append(np.exp(0.5 * (a + b)))
    return np.array(out)


def _model_name(arms: list, eta0: float) -> str:
    if not arms:
        return "kelvin_voigt" if eta0 > 0.0 else "elastic"
    return "standard_solid" if len(arms) == 1 and eta0 == 0.0 else "prony"


def series_material(mat1: Material, mat2: Material) -> Material:
    """Return the one material whose operator modulus is ``M_1 M_2 / (M_1 + M_2)`` (module doc).

    Parameters
    ----------
    mat1, mat2 : generalized Maxwell materials with the same ``nu``

    Returns
    -------
    Material
        ``elastic``, ``kelvin_voigt``, ``standard_solid`` or ``prony`` (by the
        number of arms and the dashpot), ``nu`` of the inputs.

    Raises
    ------
    ValueError
        if the two ``nu`` differ (the caller decides what that means), or if
        the partial fractions do not reproduce ``M_1 M_2 / (M_1 + M_2)`` to
        1e-8 on the imaginary axis (not expected for passive materials).
    """
    if abs(mat1.nu - mat2.nu) > 1e-12 * max(mat1.nu, mat2.nu, 1e-300):
        raise ValueError(f"series_material needs equal nu (got {mat1.nu!r} and {mat2.nu!r})")
    G_inf = mat1.G_inf * mat2.G_inf / (mat1.G_inf + mat2.G_inf)
    eta0 = (mat1.eta0 * mat2.eta0 / (mat1.eta0 + mat2.eta0)
            if mat1.eta0 > 0.0 and mat2.eta0 > 0.0 else 0.0)
    rates, moduli = _arms_by_rate((mat1, mat2))
    S_inf, S_eta = mat1.G_inf + mat2.G_inf, mat1.eta0 + mat2.eta0
    arms: list[tuple[float, float]] = []
    # zeros of S: residue M1 M2 / S'(s), S'(s) = eta0 + sum G tau / (1 + tau s)^2
    for p in _zeros(S_inf, S_eta, rates, moduli):
        s = -p
        dS = S_eta + float(np.sum(moduli / rates / (1.0 - p / rates) ** 2))
        res = float(operator_modulus(mat1, s) * operator_modulus(mat2, s)) / dS
        arms.append((-res / p, 1.0 / p))
    # shared relaxation times: both operators have a pole there, M* keeps one
    for G1, tau1 in mat1.arms:
        for G2, tau2 in mat2.arms:
            if abs(tau1 - tau2) <= _REL * tau1:
                a, b = G1 / tau1, G2 / tau2  # minus the residues of the two arms
                arms.append((a * b / (a + b) * tau1, tau1))
    glassy = G_inf + sum(max(G, 0.0) for G, _ in arms)
    arms = sorted(((G, tau) for G, tau in arms if G > _DROP * glassy), key=lambda a: a[1])
    out = Material(_model_name(arms, eta0), mat1.nu, G_inf, tuple(arms), eta0)
    # self-check on the imaginary axis around every time scale
    taus = [tau for m in (mat1, mat2, out) for _, tau in m.arms]
    for m in (mat1, mat2):
        if m.eta0 > 0.0:
            taus.append(m.eta0 / m.G_inf)
    w = np.geomspace(1e-3 / max(taus), 1e3 / min(taus), 200) if taus else np.array([1.0])
    s = 1j * w
    M1, M2 = operator_modulus(mat1, s), operator_modulus(mat2, s)
    want, got = M1 * M2 / (M1 + M2), operator_modulus(out, s)
    err = float(np.max(np.abs(got - want) / np.abs(want)))
    if not err <= 1e-8:
        raise ValueError(f"series combination failed its frequency-domain check "
                         f"(relative error {err:.2e})")
    return out
