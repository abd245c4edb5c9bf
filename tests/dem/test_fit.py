"""Fits reproduce known constants from synthetic targets made by the law itself."""

import functools
import math

import numpy as np
import pytest

import vimpact as v
from vimpact.dem import laws
from vimpact.dem.fit import Targets, fit_constant, fit_scalar, fit_viscoelastic_hertz
from vimpact.dem.problem import problem_from_toml
from vimpact.dem.yade import yade_law

TOML = """
[speeds]
min = 0.05
max = 2.0
n = 12
[types.a]
density = 1200.0
radius = [0.004, 0.006]
[types.a.material]
model = "kelvin_voigt"
nu = 0.45
G = 3e7
eta = 600.0
[walls.floor]
material = "rigid"
"""


#: :data:`TOML` with 6 speeds over the same range: the synthetic targets solve the law directly
#: at every point (3 size levels), and recovering a known A needs no more
SYNTHETIC = TOML.replace("n = 12", "n = 6", 1)


def _synthetic(problem, contact, A, mass_factor=None, solve=True):
    """Targets ``e_z`` of the viscoelastic Hertz law with damping time ``A`` at every point:
    the law solved directly (``solve``), or its tabulated curve (the fit's)."""
    levels = contact.levels()
    n = problem.speeds.size
    R = np.repeat([contact.effective(l)[0] for l in levels], n)
    m = np.repeat([contact.effective(l)[1] for l in levels], n)
    vv = np.tile(problem.speeds, len(levels))
    f = np.ones_like(m) if mass_factor is None else mass_factor(m)
    alpha = A * f * vv / laws.hertz_overlap(contact.E_star, R, m, vv)
    # the law solved directly at every point (the fit uses the tabulated curve)
    e = (np.array([laws.viscoelastic_hertz_e(a)[0] for a in alpha]) if solve
         else laws.viscoelastic_hertz_curve(alpha))
    return Targets(contact, vv, np.repeat(np.arange(len(levels)), n), R, m, e, None,
                   np.zeros_like(vv), np.full(vv.shape, "ok"))


@pytest.mark.parametrize("A", [3e-7, 2e-5, 4e-4])
def test_viscoelastic_hertz_fit_recovers_A(A):
    p = problem_from_toml(SYNTHETIC)
    c = p.contacts[1]  # a-floor
    t = _synthetic(p, c, A)
    A_fit, e = fit_viscoelastic_hertz(t, c.E_star)
    assert A_fit == pytest.approx(A, rel=1e-5)
    assert np.max(np.abs(e - t.e_z)) < 1e-6


def test_viscoelastic_hertz_fit_with_lammps_mass_scaling_recovers_A():
    p = problem_from_toml(SYNTHETIC)
    c = p.contacts[0]  # a-a, polydisperse
    _, m_nom = c.nominal()
    t = _synthetic(p, c, 2e-5, mass_factor=lambda m: m / m_nom)
    A_fit, _ = fit_viscoelastic_hertz(t, c.E_star, mass_factor=t.m / m_nom)
    assert A_fit == pytest.approx(2e-5, rel=1e-5)


def test_constant_fit_is_the_mean_and_reports_the_spread():
    c, res = fit_constant(np.array([0.6, 0.7, 0.8]))
    assert c == pytest.approx(0.7)
    assert res.max_abs == pytest.approx(0.1) and res.rms == pytest.approx(np.sqrt(0.02 / 3))


def yade_beta(en, et, F, q=1.0):
    return yade_law(1e-4, en, et, q, F)[1]


def test_yade_et_fit_recovers_et():
    target = np.full(5, yade_beta(0.8, 0.35, 2.9))
    et, pred = fit_scalar(lambda x: np.full(5, yade_beta(0.8, x, 2.9)), target, 1e-6, 1.0)
    assert et == pytest.approx(0.35, rel=1e-5)


def test_yade_law_between_spheres_is_the_clipped_linear_law():
    """Yade's kn, cn from (tc, en) are the textbook spring-dashpot of damping ratio
    |ln en| / sqrt(pi^2 + ln^2 en) and period-based contact time; with the force clipped at
    zero the restitution is above en, and a wall (massR = m/2) damps by 1/sqrt(2) less."""
    from vimpact.dem import laws

    en = 0.8
    zeta = laws.zeta_of_restitution(en)
    e_pair, _, t_pair = yade_law(1e-4, en, 1.0, 1.0, 3.5)
    assert e_pair == pytest.approx(laws.linear_spring_dashpot(zeta, "force")[0], abs=1e-9)
    assert e_pair > en
    e_wall = yade_law(1e-4, en, 1.0, 0.5, 3.5)[0]
    assert e_wall == pytest.approx(laws.linear_spring_dashpot(zeta / np.sqrt(2), "force")[0],
                                   abs=1e-9)
    # the unclipped contact lasts tc exactly (half a damped period), the clipped one less
    assert t_pair < 1e-4


def test_kelvin_voigt_fit_is_close_to_tau_and_residual_is_second_order():
    """For a Kelvin-Voigt wall contact the viscoelastic Hertz law's loading branch is ours
    with A = tau (docs/physics.md#kelvin-voigt-continuum): the fitted A is near tau, and the residual of the
    fit is small compared with 1 - e (the laws differ at second order in the damping)."""
    from vimpact.dem.fit import compute_targets

    p = problem_from_toml(TOML)
    c = p.contacts[1]
    t = compute_targets(p, c, numerics=v.Numerics.preset("fast"))
    A, e = fit_viscoelastic_hertz(t, c.E_star)
    tau = 600.0 / 3e7
    assert A == pytest.approx(tau, rel=0.1)
    assert np.max(np.abs(e - t.e_z)) < 0.1 * np.max(1 - t.e_z)


#: the stepped law's points of the tangential search tests: A v0 / d_H at four speeds, and
#: the start of the stiffness ratio
ALPHA, KAPPA0 = np.array([1e-4, 3e-4, 1e-3, 3e-3]), 0.6
#: a solid sphere at 45 degrees with mu = 0.5: (F, mu, w0)
SOLID_45 = (3.5, 0.5, (1.0, 1.0, 1.0, 1.0))


def stepped_beta(F, mu, w0, ln_kappa, ln_gamma):
    """LAMMPS' stepped Hertz-Mindlin-Coulomb beta at :data:`ALPHA` (its fit's step count)."""
    from vimpact.dem.lammps import FIT_STEPS

    return laws.hertz_mindlin_coulomb(ALPHA, KAPPA0 * np.exp(ln_kappa), np.exp(ln_gamma),
                                      F, mu, np.asarray(w0, dtype=float), FIT_STEPS)[1]


def search_bounds():
    import math

    return (-5.0, math.log(1e-6)), (5.0, math.log(1e12))


@functools.lru_cache
def search_alone(F: float, mu: float, w0: tuple, known: tuple) -> np.ndarray:
    """The LAMMPS tangential fit's search (:func:`grid_search` from its start) on beta targets
    made by the stepped law at ``known = (ln k_t / k_0, ln x_gamma_t)``. Cached: the
    lockstep test compares with the very search the recovery test runs for the solid
    sphere at 45 degrees."""
    from vimpact.dem.fit import grid_search
    from vimpact.dem.lammps import SEARCH_HALF_WIDTH, SEARCH_START

    target = stepped_beta(F, mu, w0, *known)
    return grid_search(lambda z: np.mean((stepped_beta(F, mu, w0, z[:, :1], z[:, 1:])
                                          - target) ** 2, axis=1),
                       SEARCH_START, SEARCH_HALF_WIDTH, *search_bounds())


@pytest.mark.parametrize("ln_k, ln_x", [(-0.18, 7.27), (-0.2, -0.58), (0.5, 2.0), (-1.0, 4.0)])
def test_tangential_grid_search_recovers_known_lammps_constants(ln_k, ln_x):
    """The shrinking-grid search of the LAMMPS tangential fit, on beta targets made by the
    stepped Hertz-Mindlin-Coulomb law itself at known ``(ln k_t / k_0, ln x_gamma_t)``,
    finds those constants from the fit's own start (the cost has curved valleys: a search
    that shrinks after every move stopped in the wrong one in three of these four)."""
    z = search_alone(*SOLID_45, (ln_k, ln_x))  # 45 degrees, a solid sphere
    assert z == pytest.approx([ln_k, ln_x], abs=0.01)


def test_grid_search_reusing_costs_ends_where_evaluating_every_candidate_ends():
    """A candidate two grids share takes the cost it got before instead of being stepped
    again: the search (:func:`search_alone`) takes the same steps and ends on the same point,
    bit for bit, as the one that evaluates every candidate. (That it never asks for a
    candidate twice: test_lockstep_tangential_searches_equal_the_searches_one_by_one.)"""
    from vimpact.dem.fit import grid_search
    from vimpact.dem.lammps import SEARCH_HALF_WIDTH, SEARCH_START

    F, mu, w0 = SOLID_45
    target = stepped_beta(F, mu, w0, 0.5, 2.0)
    every = grid_search(lambda z: np.mean((stepped_beta(F, mu, w0, z[:, :1], z[:, 1:])
                                           - target) ** 2, axis=1),
                        SEARCH_START, SEARCH_HALF_WIDTH, *search_bounds(), reuse=False)
    np.testing.assert_array_equal(search_alone(F, mu, w0, (0.5, 2.0)), every)


def test_lockstep_tangential_searches_equal_the_searches_one_by_one():
    """Two contacts with different mass factors ``F``, friction ``mu`` and known constants,
    searched in lockstep (:func:`grid_search_many`, one stepped call per round over both
    contacts' candidates, per-point ``F`` and ``mu``) end exactly where :func:`grid_search`
    ends for each alone (scalar ``F``, ``mu``): the stepped law is elementwise, and a search
    that has stopped drops out without moving the other. (The solid sphere's search alone
    is the one of test_tangential_grid_search_recovers_known_lammps_constants[-0.2--0.58].)"""
    from vimpact.dem.fit import grid_search_many
    from vimpact.dem.lammps import FIT_STEPS, SEARCH_HALF_WIDTH, SEARCH_START

    contacts = [  # (F, mu, w0, known (ln k, ln x)): a solid sphere at 45 deg; a hollow one
        (*SOLID_45, (-0.2, -0.58)),
        (2.5, 0.3, tuple(np.tan(np.radians([15.0, 30.0, 45.0, 60.0]))), (0.5, 2.0)),
    ]
    targets = [stepped_beta(F, mu, w0, *known) for F, mu, w0, known in contacts]
    bounds = search_bounds()
    alone = [search_alone(*contacts[k]) for k in range(2)]

    rounds, asked = [0, 0], [[], []]

    def costs(grids):
        args = []
        for k, z in grids:
            rounds[k] += 1
            asked[k].append(z)
            F, mu, w0, _ = contacts[k]
            args.append(np.broadcast_arrays(ALPHA, KAPPA0 * np.exp(z[:, :1]), np.exp(z[:, 1:]),
                                            F, mu, np.asarray(w0, dtype=float)))
        b = laws.hertz_mindlin_coulomb(*(np.concatenate([a[i].ravel() for a in args])
                                         for i in range(6)), steps=FIT_STEPS)[1]
        out, start = [], 0
        for (k, _), a in zip(grids, args):
            out.append(np.mean((b[start:start + a[0].size].reshape(a[0].shape) - targets[k]) ** 2,
                               axis=1))
            start += a[0].size
        return out

    together = grid_search_many(costs, [SEARCH_START] * 2, [SEARCH_HALF_WIDTH] * 2,
                                [bounds[0]] * 2, [bounds[1]] * 2)
    for k in range(2):
        np.testing.assert_array_equal(together[k], alone[k])
        assert alone[k] == pytest.approx(contacts[k][3], abs=0.01)
    assert rounds[0] != rounds[1]  # one search dropped out while the other ran on
    for k in range(2):  # no candidate asked for twice: a grid's known points take their costs
        fresh = np.concatenate(asked[k])
        assert len(np.unique(fresh, axis=0)) == len(fresh) < 0.8 * 49 * rounds[k]


@pytest.mark.parametrize("lo, hi", [(1e-6, 1.0), (-2.0, 0.5), (0.3, 0.30001)])
def test_scalar_search_takes_the_steps_of_scipys_bounded_brent(lo, hi):
    """:func:`fit_scalar` (the one-search case of :func:`fit_scalar_many`) ends exactly where
    scipy's ``minimize_scalar(method="bounded")`` ends with the same tolerance, on a cost
    with several minima (parabolic and golden-section steps both occur)."""
    from scipy.optimize import minimize_scalar

    k = np.arange(1.0, 6.0)
    target = np.array([0.3, -0.2, 0.5, 0.1, -0.4])

    def predict(p):
        return np.sin(3.0 * k * p) + 0.7 * p * p + 0.2 * np.abs(p - 0.31)

    def cost(p):
        r = predict(p) - target
        return float(np.mean(r * r))

    ref = minimize_scalar(cost, bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-10, "maxiter": 500})
    p, pred = fit_scalar(predict, target, lo, hi)
    assert p == float(ref.x)
    np.testing.assert_array_equal(pred, predict(ref.x))


#: steps per contact of the stepped Yade law in the lockstep test (the export's search uses
#: more; equality and recovery hold at any fixed step count, the law is the same in both)
YADE_TEST_STEPS = 300


def test_lockstep_yade_et_searches_equal_the_searches_one_by_one_and_recover_et():
    """Two contacts with different ``tc``, ``en``, ``q``, ``F``, ``mu`` (a pair, arm ``R``;
    a wall contact, lever ``R - delta``) and targets made by the stepped Yade law itself at
    known ``et``: searched in lockstep (:func:`fit_scalar_many`, one stepped call per round
    over both contacts' candidates, per-point constants) each ends exactly where
    :func:`fit_scalar` ends alone (scalar constants), and finds its ``et``."""
    from vimpact.dem.fit import fit_scalar_many
    from vimpact.dem.yade import yade_oblique, yade_oblique_many

    w0 = np.tan(np.radians([10.0, 30.0, 45.0, 70.0]))
    contacts = [  # yade_oblique's arguments, and the known et
        (dict(tc=1e-4, en=0.7, q=1.0, F=3.5, mu=0.5, w0=w0), 0.35),
        (dict(tc=3e-5, en=0.9, q=0.5, F=2.5, mu=0.3, w0=np.repeat(w0[1:], 2),
              R=0.004, v=np.tile([0.2, 2.0], 3)), 0.6),
    ]
    targets = [yade_oblique(**dict(a, et=et), steps=YADE_TEST_STEPS) for a, et in contacts]
    alone = [fit_scalar(lambda x, a=a: yade_oblique(**dict(a, et=x), steps=YADE_TEST_STEPS),
                        tg, 1e-6, 1.0)[0] for (a, _), tg in zip(contacts, targets)]
    calls = []

    def predict(jobs):
        calls.append([s for s, _ in jobs])
        return yade_oblique_many([dict(contacts[s][0], et=x) for s, x in jobs], YADE_TEST_STEPS)

    together = fit_scalar_many(predict, targets, [1e-6] * 2, [1.0] * 2)
    assert together == alone
    for et, (_, known) in zip(together, contacts):
        assert et == pytest.approx(known, rel=1e-4)
    assert [0, 1] in calls  # one stepped call for both contacts' candidates
    # and the law at the end: each contact's beta exactly as alone
    for b, (a, _), et in zip(yade_oblique_many([dict(a, et=et) for (a, _), et in
                                                zip(contacts, together)]), contacts, together):
        np.testing.assert_array_equal(b, yade_oblique(**dict(a, et=et)))


@pytest.mark.parametrize("A", [3e-7, 2e-5])
def test_viscoelastic_hertz_fit_ends_where_scipys_bounded_search_ends(A):
    """The fit of ``A`` drives :func:`fit_scalar_many` (not scipy, which the LAMMPS export
    no longer imports); it ends exactly where ``minimize_scalar(method="bounded")`` ends on
    the same cost, with the same bracket and tolerance. Any targets do: these are the
    tabulated curve with a mass scaling other than the fit's (a residual is left at the
    minimum, as with real targets), not the law solved at every point."""
    from scipy.optimize import minimize_scalar

    p = problem_from_toml(SYNTHETIC)
    c = p.contacts[0]
    _, m_nom = c.nominal()
    t = _synthetic(p, c, A, mass_factor=lambda m: (m / m_nom) ** 0.5, solve=False)
    f = t.m / m_nom
    unit = f * t.v / laws.hertz_overlap(c.E_star, t.R, t.m, t.v)
    guess = float(np.median(np.maximum(1.0 - t.e_z, 1e-9) / laws.SMALL_DAMPING_SLOPE / unit))
    lo = math.log10(guess) - 3.0
    hi = min(math.log10(guess) + 3.0, math.log10(1e3 / unit.max()))

    def cost(logA):
        r = laws.viscoelastic_hertz_curve(np.minimum(10.0**logA * unit, 1e3)) - t.e_z
        return float(np.mean(r * r))

    ref = minimize_scalar(cost, bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-9, "maxiter": 500})
    A_fit, _ = fit_viscoelastic_hertz(t, c.E_star, mass_factor=f)
    assert A_fit == 10.0**ref.x


def test_a_deferred_beta_x_is_computed_once_when_read():
    """``ContactFit`` given a function for ``beta_x`` calls it on the first read only (not
    to say whether the code represents ``beta_x``); an array or ``None`` is kept as is."""
    from vimpact.dem.fit import ContactFit, Residual

    calls = []

    def curve():
        calls.append(1)
        return [0.25, -0.5]

    c = problem_from_toml(SYNTHETIC).contacts[0]
    res = Residual(0.0, 0.0)
    f = ContactFit(c, {}, np.ones(2), curve, res)
    assert f.has_beta_x and not calls
    np.testing.assert_array_equal(f.beta_x, [0.25, -0.5])
    np.testing.assert_array_equal(f.beta_x, [0.25, -0.5])
    assert len(calls) == 1
    f.beta_x = np.zeros(2)
    np.testing.assert_array_equal(f.beta_x, np.zeros(2))
    none = ContactFit(c, {}, np.ones(2), None, res)
    assert not none.has_beta_x and none.beta_x is None
