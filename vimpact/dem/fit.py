"""vimpact's restitution curves of each contact, and DEM constants fitted to them.

The targets are ``e_z(v)`` (normal impacts, every size level of the contact)
and, for codes with a tangential restitution, ``beta_x(v)`` (full stick,
``v_c0 = v_z0``; under stick ``beta_x`` does not depend on ``v_c0``) and, for a
contact with a finite friction coefficient, vimpact's oblique impacts with it
(:class:`Oblique`: ``beta_x`` over a few speeds times the set-up's impact angles),
which the tangential fits then use. A fit
runs the code's own law (:mod:`vimpact.dem.laws`) with the candidate
constants at the same points and minimizes the RMS difference; its residual
is reported as it is, never tuned away.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from vimpact.dem import laws
from vimpact.dem.problem import Contact, DemProblem
from vimpact.engine.pairs import pair_restitutions

#: impact angles (degrees from the normal, no spin) of the tangential targets when the
#: set-up gives no ``[speeds] angles_deg``
DEFAULT_ANGLES_DEG = (5.0, 15.0, 30.0, 45.0, 60.0, 75.0)
#: normal speeds (of the set-up's, log-spaced picks, nominal sizes) of the oblique targets
OBLIQUE_SPEEDS = 4


@dataclass
class Oblique:
    """vimpact's oblique impacts of one contact with its Coulomb friction (nominal sizes).

    Attributes
    ----------
    v : normal approach speed ``v_z0``, m/s; ``angle_deg`` : impact angle from the normal
        (``tan = v_c0 / v_z0``, no spin), degrees; one entry per point
    R, m : effective radius (m) and mass (kg)
    mu : the contact's friction coefficient
    e_z, beta_x : vimpact's restitutions at the points
    """

    v: np.ndarray
    angle_deg: np.ndarray
    R: float
    m: float
    mu: float
    e_z: np.ndarray
    beta_x: np.ndarray

    @property
    def w0(self) -> np.ndarray:
        """``v_c0 / v_z0`` of each point."""
        return np.tan(np.radians(self.angle_deg))


def oblique_targets(problem: DemProblem, contact: Contact, numerics=None) -> Oblique:
    """Run vimpact's oblique impacts of ``contact``, with its friction, at nominal sizes.

    At :data:`OBLIQUE_SPEEDS` of the set-up's speeds (m/s) times its impact angles
    (``[speeds] angles_deg``, else :data:`DEFAULT_ANGLES_DEG`, degrees from the
    normal), all in one engine batch.
    """
    from vimpact.model.numerics import Numerics

    curves = _oblique_curves(problem, contact)
    return _oblique_of(problem, contact, curves,
                       pair_restitutions(curves, numerics or Numerics.preset("fast")))


def _oblique_curves(problem: DemProblem, contact: Contact) -> list[tuple]:
    """Return the curves (:func:`vimpact.engine.pairs.pair_restitutions`) of :func:`oblique_targets`."""
    sp = problem.speeds
    pick = np.unique(np.linspace(0, sp.size - 1, min(OBLIQUE_SPEEDS, sp.size)).round().astype(int))
    speeds = sp[pick]
    b1, b2 = contact.levels()[len(contact.levels()) // 2]
    return [(b1, b2, speeds, {"tangential": True, "vc_ratio": math.tan(math.radians(a)),
                              "mu": contact.mu}) for a in _angles(problem)]


def _angles(problem: DemProblem) -> tuple:
    """Impact angles of the oblique targets, degrees from the normal."""
    return problem.angles_deg or DEFAULT_ANGLES_DEG


def _oblique_of(problem: DemProblem, contact: Contact, curves: list[tuple], frames: list
                ) -> Oblique:
    """Return :class:`Oblique` from the ``curves`` of :func:`_oblique_curves` and their results."""
    b1, b2 = curves[0][:2]
    R, m = contact.effective((b1, b2))
    vs, an, ez, bx = [], [], [], []
    for a, (_, _, speeds, _), df in zip(_angles(problem), curves, frames):
        # like the normal targets: a point counts if it has data (a contact wider than
        # 0.2 R, status half_space, is kept and noted in the report)
        done = np.isfinite(df["e_z"].to_numpy(dtype=float)) & np.isfinite(
            df["beta_x"].to_numpy(dtype=float))
        if not done.all():
            bad = sorted(set(df["status"].to_numpy(dtype=str)[~done]))
            raise ValueError(f"contact {contact.key}: vimpact's oblique impact at {a:g} degrees "
                             f"ended with status {bad}; narrow the speed range or the angles")
        vs.append(speeds)
        an.append(np.full(speeds.size, float(a)))
        ez.append(df["e_z"].to_numpy(dtype=float))
        bx.append(df["beta_x"].to_numpy(dtype=float))
    cat = np.concatenate
    return Oblique(cat(vs), cat(an), R, m, contact.mu, cat(ez), cat(bx))


@dataclass
class Targets:
    """vimpact's curves of one contact, flattened over (size level, speed).

    Attributes
    ----------
    contact : the contact
    v : approach speeds, m/s; ``level`` : size level index of each point
    R, m : effective radius (m) and mass (kg) at each point
    e_z : normal restitution; ``beta_x`` : tangential (full stick), or ``None``
    t_contact : contact time, s; ``status`` : engine status of each point
    oblique : vimpact's ``beta_x`` with the contact's friction over the impact angles
        (:class:`Oblique`), for a contact with a finite friction coefficient, else ``None``
    """

    contact: Contact
    v: np.ndarray
    level: np.ndarray
    R: np.ndarray
    m: np.ndarray
    e_z: np.ndarray
    beta_x: np.ndarray | None
    t_contact: np.ndarray
    status: np.ndarray
    oblique: Oblique | None = None

    def subset(self, mask: np.ndarray) -> Targets:
        """Return the points selected by ``mask``."""
        pick = lambda a: None if a is None else a[mask]  # noqa: E731
        return Targets(self.contact, self.v[mask], self.level[mask], self.R[mask], self.m[mask],
                       self.e_z[mask], pick(self.beta_x), self.t_contact[mask], self.status[mask],
                       self.oblique)

    @property
    def nominal(self) -> np.ndarray:
        """Mask of the points at the nominal size level."""
        return self.level == (int(self.level.max()) + 1) // 2 if self.level.size else self.level


def adhesive_scene(contact: Contact, level, v: float = 1.0):
    """Return the adhesive normal-impact scene of ``contact`` at a size level and speed.

    A :class:`vimpact.Scene` with the contact's ``adhesion``, at the size level
    ``level`` and approach speed ``v`` (m/s).
    """
    from vimpact.model.pair import Body, Wall, pair_scene
    from vimpact.model.scene import Scene

    b1, b2 = level
    base = pair_scene(Body(b1.material, b1.R, b1.m, b1.Theta, v_z=1.0),
                      b2 if isinstance(b2, Wall) else Body(b2.material, b2.R, b2.m, b2.Theta),
                      tangential="none", allow_large_contact=True)
    return Scene(base.material, R=base.R, m=base.m, v_z0=v, tangential="none",
                 allow_large_contact=True, adhesion=contact.adhesion)


def adhesive_restitution(contact: Contact, level, speeds, numerics):
    """Run vimpact's adhesive normal impacts of ``contact`` at ``level`` over ``speeds`` (m/s).

    Returns ``e_z`` (0 where the sphere sticks), contact time (s) and status
    (:func:`vimpact.engine.adhesion.simulate_adhesive`) as a DataFrame like
    :func:`vimpact.engine.pairs.pair_restitution`'s.
    """
    import pandas as pd

    from vimpact.engine.adhesion import simulate_adhesive

    rows = [simulate_adhesive(adhesive_scene(contact, level, float(v)), numerics)
            for v in speeds]
    return pd.DataFrame({"v_z0": speeds, "e_z": [r.e_z for r in rows],
                         "t_contact": [r.t_contact for r in rows],
                         "status": [r.status for r in rows]})


def compute_targets(problem: DemProblem, contact: Contact, *, tangential: bool = False,
                    numerics=None) -> Targets:
    """Run vimpact for ``contact`` at every size level and speed of ``problem``.

    Every impact of the contact (normal, full stick and the oblique ones of
    :func:`oblique_targets`) runs in one engine batch
    (:func:`vimpact.engine.pairs.pair_restitutions`); with adhesion, the normal impacts
    through :func:`adhesive_restitution` (``e_z`` 0 where the sphere sticks).
    """
    from vimpact.model.numerics import Numerics

    numerics = numerics or Numerics.preset("fast")
    levels = contact.levels()
    adhesive = contact.adhesion > 0.0
    oblique = tangential and math.isfinite(contact.mu)
    curves: list[tuple] = ([] if adhesive else [(b1, b2, problem.speeds, {}) for b1, b2 in levels])
    if tangential:
        curves += [(b1, b2, problem.speeds, {"tangential": True}) for b1, b2 in levels]
    slant = _oblique_curves(problem, contact) if oblique else []
    frames = pair_restitutions(curves + slant, numerics) if curves or slant else []
    nl = len(levels)
    normal = ([adhesive_restitution(contact, level, problem.speeds, numerics) for level in levels]
              if adhesive else frames[:nl])
    stick = frames[len(curves) - nl:len(curves)] if tangential else []
    parts = []
    for k, level in enumerate(levels):
        R, m = contact.effective(level)
        beta = stick[k]["beta_x"].to_numpy(dtype=float) if tangential else None
        parts.append((k, R, m, normal[k], beta))
    n = problem.speeds.size
    cat = np.concatenate
    e_z = cat([p[3]["e_z"].to_numpy(dtype=float) for p in parts])
    if not np.all(np.isfinite(e_z)):
        bad = cat([p[3]["status"].to_numpy(dtype=str) for p in parts])[~np.isfinite(e_z)]
        raise ValueError(f"contact {contact.key}: vimpact gave no e_z at some speeds "
                         f"(status {sorted(set(bad))}); narrow the speed range")
    return Targets(
        contact=contact,
        v=np.tile(problem.speeds, len(parts)),
        level=np.repeat(np.arange(len(parts)), n),
        R=np.repeat([p[1] for p in parts], n),
        m=np.repeat([p[2] for p in parts], n),
        e_z=e_z,
        beta_x=cat([p[4] for p in parts]) if tangential else None,
        t_contact=cat([p[3]["t_contact"].to_numpy(dtype=float) for p in parts]),
        status=cat([p[3]["status"].to_numpy(dtype=str) for p in parts]),
        oblique=(_oblique_of(problem, contact, slant, frames[len(curves):]) if oblique
                 else None),
    )


@dataclass
class Residual:
    """Difference ``code - vimpact`` over the fitted points (dimensionless)."""

    max_abs: float
    rms: float

    @classmethod
    def of(cls, predicted, target) -> Residual:
        """Return the residual of ``predicted`` against ``target`` (both dimensionless)."""
        d = np.asarray(predicted, dtype=float) - np.asarray(target, dtype=float)
        return cls(float(np.max(np.abs(d))), float(np.sqrt(np.mean(d * d))))

    def __str__(self) -> str:
        return f"max {self.max_abs:.2e}, RMS {self.rms:.2e}"


@dataclass
class ContactFit:
    """A code's constants for one contact and what the code will produce with them.

    Attributes
    ----------
    contact : the contact; ``params`` : the exported constants (name -> value, SI)
    e_z : restitution the code's law gives at the target points with ``params``
    beta_x : likewise for the tangential restitution, or ``None`` if not represented;
        constructed with a function instead of an array, it is computed when first read
        (a contact with friction is fitted and reported over its oblique impacts, so its
        full-stick curve is only worked out if someone asks for it)
    res_e_z : residual of ``e_z`` against vimpact
    res_beta_x : residual of ``beta_x`` against vimpact (``None`` if not represented): over
        the oblique impacts with friction when the contact has a finite friction
        coefficient (``beta_oblique``), else over the full-stick curve
    beta_oblique : the code's ``beta_x`` at the points of ``Targets.oblique``, or ``None``
    notes : what the code cannot represent, conventions applied
    """

    contact: Contact
    params: dict
    e_z: np.ndarray
    _beta_x: np.ndarray | Callable[[], np.ndarray] | None
    res_e_z: Residual
    res_beta_x: Residual | None = None
    notes: list[str] = field(default_factory=list)
    beta_oblique: np.ndarray | None = None

    @property
    def beta_x(self) -> np.ndarray | None:
        """The code's full-stick ``beta_x`` at the target points (computed on first read)."""
        if callable(self._beta_x):
            self._beta_x = np.asarray(self._beta_x(), dtype=float)
        return self._beta_x

    @beta_x.setter
    def beta_x(self, value: np.ndarray | None) -> None:
        self._beta_x = value

    @property
    def has_beta_x(self) -> bool:
        """Whether the code represents ``beta_x`` (without computing a deferred curve)."""
        return self._beta_x is not None


def fit_constant(target: np.ndarray, lo: float = 0.0, hi: float = 1.0) -> tuple[float, Residual]:
    """Return the constant closest to ``target`` in RMS (its mean), clipped to ``[lo, hi]``."""
    c = float(np.clip(np.mean(target), lo, hi))
    return c, Residual.of(np.full_like(target, c), target)


def fit_viscoelastic_hertz(t: Targets, E_star: float, mass_factor: np.ndarray | None = None
                           ) -> tuple[float, np.ndarray]:
    """Dissipation time ``A`` (s) of the clipped viscoelastic Hertz law closest to ``t.e_z`` in RMS.

    Parameters
    ----------
    t : the targets; ``E_star`` : the law's effective modulus, Pa
    mass_factor : per point, the factor by which the code's effective ``A``
        differs from the fitted one (LAMMPS scales its damping with ``m_eff``,
        so a polydisperse contact has ``A m_eff / m_eff,nominal``); default 1

    Returns
    -------
    (A, e) : the constant and the law's restitution at the target points
    """
    f = np.ones_like(t.v) if mass_factor is None else np.asarray(mass_factor, dtype=float)
    d = laws.hertz_overlap(E_star, t.R, t.m, t.v)
    unit = f * t.v / d  # alpha per unit A, 1/s

    def predict(A: float) -> np.ndarray:
        return laws.viscoelastic_hertz_curve(np.minimum(A * unit, 1e3))

    # first-order guess from the small-damping slope, then a bounded search in log A
    guess = float(np.median(np.maximum(1.0 - t.e_z, 1e-9) / laws.SMALL_DAMPING_SLOPE / unit))
    lo, hi = math.log10(guess) - 3.0, min(math.log10(guess) + 3.0, math.log10(1e3 / unit.max()))

    # Brent's bounded search of scipy's minimize_scalar (without importing scipy.optimize)
    logA = fit_scalar_many(lambda jobs: [predict(10.0**x) for _, x in jobs], [t.e_z], [lo],
                           [hi], xatol=1e-9, maxiter=500)[0]
    A = 10.0**logA
    return A, predict(A)


def viscoelastic_hertz_prediction(t: Targets, E_star: float, A: float,
                                  mass_factor: np.ndarray | None = None) -> np.ndarray:
    """Return the viscoelastic Hertz law's restitution at the points of ``t``.

    With the damping constant ``A`` (s), times ``mass_factor`` per point as in
    :func:`fit_viscoelastic_hertz`; ``E_star`` the effective modulus, Pa.
    """
    f = np.ones_like(t.v) if mass_factor is None else np.asarray(mass_factor, dtype=float)
    return laws.viscoelastic_hertz_curve(np.minimum(A * f * t.v / laws.hertz_overlap(
        E_star, t.R, t.m, t.v), 1e3))


def linear_tangential_beta(en: float, et_like: tuple[float, float]) -> float:
    """Return the tangential restitution ``beta`` of a linear spring-dashpot contact.

    The contact ends at zero overlap, with normal restitution ``en`` and the
    tangential oscillator ``(w_t/omega0, zeta_t)`` (both dimensionless).
    """
    return laws.linear_spring_dashpot(laws.zeta_of_restitution(en), "overlap", et_like)[1]


def fit_scalar(predict, target: np.ndarray, lo: float, hi: float) -> tuple[float, np.ndarray]:
    """One constant ``p`` in ``[lo, hi]`` minimizing ``RMS(predict(p) - target)``.

    The one-search case of :func:`fit_scalar_many`; returns ``p`` and ``predict(p)``.
    """
    p = fit_scalar_many(lambda jobs: [predict(x) for _, x in jobs], [target], [lo], [hi])[0]
    return p, np.asarray(predict(p), dtype=float)


def _bounded_brent(lo: float, hi: float, xatol: float, maxiter: int):
    """Brent's minimization of one scalar on ``[lo, hi]`` as a generator.

    Each ``yield`` hands out the next candidate and receives its cost; the
    generator returns the best candidate. The method (Brent 1973): ``x`` is the
    best point so far, ``w`` the second best, ``v`` the one before it; a step is
    the minimum of the parabola through the three if it falls inside the bracket
    ``[a, b]`` and is less than half the step before last, else a golden-section
    step into the larger part of the bracket; no candidate lies closer than
    ``tol`` to ``x``. It stops when the bracket is within ``xatol`` of ``x`` (plus
    the relative ``sqrt(eps) |x|``) or after ``maxiter`` evaluations. Its
    decisions and arithmetic are those of :func:`scipy.optimize.minimize_scalar`
    with ``method="bounded"`` (``tests/dem/test_fit.py`` checks it ends where that
    ends), so :func:`fit_scalar` gives what it gave with scipy's search.
    """
    sqrt_eps = math.sqrt(2.2e-16)
    section = 0.5 * (3.0 - math.sqrt(5.0))  # the golden-section fraction
    a, b = lo, hi
    x = w = v = a + section * (b - a)
    step = before_last = 0.0
    fx = yield x
    fw = fv = fx
    evaluations = 1
    while True:
        middle = 0.5 * (a + b)
        tol = sqrt_eps * abs(x) + xatol / 3.0
        if abs(x - middle) <= 2.0 * tol - 0.5 * (b - a):
            break
        parabolic = False
        if abs(before_last) > tol:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            limit, before_last = before_last, step
            if abs(p) < abs(0.5 * q * limit) and q * (a - x) < p < q * (b - x):
                parabolic = True
                step = p / q
                if (x + step) - a < 2.0 * tol or b - (x + step) < 2.0 * tol:
                    step = tol if middle >= x else -tol  # not onto the bracket's ends
        if not parabolic:
            before_last = (a - x) if x >= middle else (b - x)
            step = section * before_last
        u = x + (1.0 if step >= 0.0 else -1.0) * max(abs(step), tol)
        fu = yield u
        evaluations += 1
        if fu <= fx:  # u is the new best; the bracket shrinks to its side of x
            if u >= x:
                a = x
            else:
                b = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
        if evaluations >= maxiter:
            break
    return x


def fit_scalar_many(predict, targets, lows, highs, xatol: float = 1e-10,
                    maxiter: int = 500) -> list[float]:
    """Run several :func:`fit_scalar` searches in lockstep, every round's candidates in one call.

    Each search is Brent's bounded search of one constant (:func:`_bounded_brent`)
    minimizing the mean square of its prediction minus its target; its steps depend
    only on its own costs, so it finds what it would find alone. A search that has
    stopped drops out of the later rounds.

    Parameters
    ----------
    predict : list of ``(search index, candidate)`` of the searches still running ->
        list of their predictions (arrays like their targets), in the same order
    targets : one array per search (dimensionless)
    lows, highs : the bounds of each search's constant (its units)
    xatol : width of the bracket at which a search stops; maxiter : evaluations at most

    Returns
    -------
    the best constant of each search
    """
    searches = [_bounded_brent(lo, hi, xatol, maxiter) for lo, hi in zip(lows, highs)]
    best: list[float] = [math.nan] * len(searches)
    pending = {s: next(g) for s, g in enumerate(searches)}
    while pending:
        jobs = list(pending.items())
        running = {}
        for (s, _), pred in zip(jobs, predict(jobs)):
            r = np.asarray(pred) - targets[s]
            try:
                running[s] = searches[s].send(float(np.mean(r * r)))
            except StopIteration as stop:
                best[s] = float(stop.value)
        pending = running
    return best


def grid_search(cost, start, half_width, lower, upper, xatol: float = 5e-4, n: int = 7,
                max_rounds: int = 40, reuse: bool = True) -> np.ndarray:
    """Minimize ``cost`` over two parameters by a pattern search of grids, each evaluated in one call.

    Each round evaluates an ``n x n`` grid of half-widths ``half_width`` around the
    centre (clipped to ``[lower, upper]``) in one call of ``cost`` (so that a stepped
    law runs every candidate at once) and moves the centre to the best point. The grid
    shrinks to one grid spacing only when the centre stays the best (the minimum is
    bracketed); a move keeps it, and a move to an edge doubles the half-width of that
    parameter (up to 4 times the first: the minimum lies further out). Shrinking after
    every move instead crawls along a curved valley of the cost by ever smaller steps
    and stops far from its bottom. Stops when the spacing is below ``xatol`` in both
    parameters, or after ``max_rounds`` rounds. A move keeps most of the grid's points
    (4 in 10 of all candidates of the LAMMPS fit's searches): a candidate within
    :data:`SAME_CANDIDATE` of one evaluated before takes its cost instead of being
    evaluated again (``reuse=False``: every candidate is evaluated). The one-search case
    of :func:`grid_search_many`.

    Parameters
    ----------
    cost : ``(k, 2)`` candidates -> ``(k,)`` costs
    start, half_width, lower, upper : pairs of numbers (the parameters' units)
    xatol : spacing at which the search stops, in the parameters' units
    n : grid points per parameter (odd)

    Returns
    -------
    the best candidate, shape ``(2,)``
    """
    return grid_search_many(lambda grids: [cost(grids[0][1])], [start], [half_width], [lower],
                            [upper], xatol, n, max_rounds, reuse)[0]


#: candidates of a grid search this close in every parameter (absolute, in the parameters'
#: units, plus as much relative) are the same point: the grid arithmetic leaves a point that
#: two grids share up to 3.3e-16 apart in the LAMMPS fit's searches (ln k_t, ln x_gamma_t)
SAME_CANDIDATE = 1e-13


def _reuse_costs(z: np.ndarray, seen_z: np.ndarray, seen_f: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Return the costs of the candidates ``z`` evaluated before, and the mask of the new ones.

    A candidate within :data:`SAME_CANDIDATE` of one in ``seen_z`` gets its cost from
    ``seen_f``; the others get NaN and are the mask's ``True`` entries.
    """
    f = np.full(len(z), np.nan)
    if not len(seen_z):
        return f, np.ones(len(z), dtype=bool)
    same = np.all(np.abs(z[:, None, :] - seen_z[None, :, :])
                  <= SAME_CANDIDATE * (1.0 + np.abs(seen_z[None, :, :])), axis=2)
    found = same.any(axis=1)
    f[found] = seen_f[same.argmax(axis=1)[found]]
    return f, ~found


def grid_search_many(costs, starts, half_widths, lowers, uppers, xatol: float = 5e-4,
                     n: int = 7, max_rounds: int = 40, reuse: bool = True) -> list[np.ndarray]:
    """Run several :func:`grid_search` searches in lockstep, every round's grids in one call.

    Each search follows :func:`grid_search`'s rule on its own (its decisions depend
    only on its own costs); a search that has stopped drops out of the later rounds.

    Parameters
    ----------
    costs : list of ``(search index, (k_i, 2) candidates)`` of the searches still
        running -> list of their ``(k_i,)`` costs, in the same order
    starts, half_widths, lowers, uppers : one pair of numbers per search (the
        parameters' units)
    xatol, n, max_rounds, reuse : as in :func:`grid_search` (``costs`` gets only the
        candidates not evaluated before, and no call for a search without any)

    Returns
    -------
    the best candidate of each search, shape ``(2,)`` each
    """
    c = [np.asarray(a, dtype=float) for a in starts]
    h = [np.asarray(a, dtype=float) for a in half_widths]
    lo = [np.asarray(a, dtype=float) for a in lowers]
    hi = [np.asarray(a, dtype=float) for a in uppers]
    u = np.linspace(-1.0, 1.0, n)
    h_max = [4.0 * a for a in h]
    running = list(range(len(c)))
    seen_z = [np.empty((0, 2)) for _ in c]  # the candidates evaluated so far, and their costs
    seen_f = [np.empty(0) for _ in c]
    for _ in range(max_rounds):
        if not running:
            break
        axes = {s: [np.unique(np.clip(c[s][i] + h[s][i] * u, lo[s][i], hi[s][i]))
                    for i in range(2)] for s in running}
        z = {s: np.stack([g.ravel() for g in np.meshgrid(*axes[s], indexing="ij")], axis=1)
             for s in running}
        f, new = {}, {}
        for s in running:
            f[s], new[s] = _reuse_costs(z[s], seen_z[s], seen_f[s]) if reuse else (
                np.full(len(z[s]), np.nan), np.ones(len(z[s]), dtype=bool))
        asked = [s for s in running if new[s].any()]
        for s, fs in zip(asked, costs([(s, z[s][new[s]]) for s in asked]) if asked else []):
            f[s][new[s]] = fs
            seen_z[s] = np.concatenate([seen_z[s], z[s][new[s]]])
            seen_f[s] = np.concatenate([seen_f[s], fs])
        for s in list(running):
            centre = int(np.argmin(np.abs(z[s] - c[s]).sum(axis=1)))  # the grid point at the centre
            j = int(np.argmin(f[s]))
            if f[s][j] >= f[s][centre] * (1.0 - 1e-12):  # ties keep the centre: shrink around it
                h[s] = h[s] * 2.0 / (n - 1)
                if np.all(h[s] < xatol):
                    running.remove(s)
                continue
            for i in range(2):  # an edge inside the bounds: the minimum lies further out
                ax = axes[s][i]
                if ax.size > 1 and z[s][j, i] in (ax[0], ax[-1]) and lo[s][i] < z[s][j, i] < hi[s][i]:
                    h[s][i] = min(2.0 * h[s][i], h_max[s][i])
            c[s] = z[s][j]
    return c


def lockstep_costs(law, arguments, targets):
    """Return the ``costs`` of :func:`grid_search_many` for searches that fit a stepped law.

    Every running search's candidates at all its points go through one call of ``law``
    (a stepped law of :mod:`vimpact.dem.laws`, elementwise, so each search's costs are
    those it would get alone): ``arguments(i, z)`` gives the law's arguments of search
    ``i`` for its ``(k, 2)`` candidates ``z``, arrays that broadcast to ``(k, points)``;
    ``law(*flat_arguments)`` returns ``(e, beta)``; the cost of a candidate is the mean
    square of ``beta`` minus ``targets[i]`` over the search's points.
    """
    def costs(grids: list[tuple[int, np.ndarray]]) -> list[np.ndarray]:
        parts = [np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in arguments(i, z)))
                 for i, z in grids]
        flat = [np.concatenate([args[k].ravel() for args in parts]) for k in range(len(parts[0]))]
        beta = law(*flat)[1]
        out, start = [], 0
        for (i, _), args in zip(grids, parts):  # back to each search's (k, points)
            piece = beta[start:start + args[0].size].reshape(args[0].shape)
            start += args[0].size
            out.append(np.mean((piece - targets[i]) ** 2, axis=1))
        return out

    return costs
