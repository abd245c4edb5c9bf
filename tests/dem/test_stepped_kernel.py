"""The stepped friction laws' numba kernel gives the NumPy loops' numbers bit for bit.

The oracle (``tests/oracles/stepped_numpy.py``) is the implementation the laws had
before the kernel: every point at once, one NumPy operation per step and quantity.
Random points of every law: sticking and sliding impacts, per-point constants, levers,
friction from 0.05 to stick.
"""

import numpy as np
import pytest

from tests.oracles import stepped_numpy as oracle
from vimpact.dem import laws

STEPS = 400  # per contact time: the same arithmetic at any count, fewer steps run faster


def _points(seed, n=40):
    rng = np.random.default_rng(seed)
    w0 = np.tan(np.radians(rng.uniform(2.0, 85.0, n)))
    mu = rng.choice([0.05, 0.3, 1.0, np.inf], n)
    return rng, w0, mu


def _equal(got, want):
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)


@pytest.mark.parametrize("seed", [1, 2])
def test_lammps_law(seed):
    rng, w0, mu = _points(seed)
    args = (rng.uniform(0.0, 0.6, w0.size), rng.uniform(0.5, 3.0, w0.size),
            rng.uniform(0.0, 5.0, w0.size), rng.uniform(2.5, 3.5, w0.size), mu, w0)
    _equal(laws.hertz_mindlin_coulomb(*args, steps=STEPS),
           oracle.hertz_mindlin_coulomb(*args, steps=STEPS))
    # scalar constants and friction, one alpha per point
    args = (args[0], 1.2, 0.7, 3.5, 0.4, w0)
    _equal(laws.hertz_mindlin_coulomb(*args, steps=STEPS),
           oracle.hertz_mindlin_coulomb(*args, steps=STEPS))


@pytest.mark.parametrize("seed", [3, 4])
def test_mercurydpm_law(seed):
    rng, w0, mu = _points(seed)
    args = (rng.uniform(0.0, 0.6, w0.size), rng.uniform(0.5, 3.0, w0.size),
            rng.uniform(0.0, 2.0, w0.size), rng.uniform(2.5, 3.5, w0.size), mu, w0)
    _equal(laws.mercury_mindlin_coulomb(*args, steps=STEPS),
           oracle.mercury_mindlin_coulomb(*args, steps=STEPS))


@pytest.mark.parametrize("seed", [5, 6])
def test_liggghts_law(seed):
    rng, w0, _ = _points(seed)
    lever = rng.uniform(0.0, 0.05, w0.size)
    for e_in, mu, lev in ((0.6, 0.3, None), (0.9, 1.0, lever), (1.0, np.inf, None)):
        args = (e_in, 2.4, 0.8, 3.5, mu, w0)
        _equal(laws.liggghts_coulomb(*args, steps=STEPS, lever=lev),
               oracle.liggghts_coulomb(*args, steps=STEPS, lever=lev))


@pytest.mark.parametrize("seed", [7, 8])
def test_yade_law(seed):
    rng, w0, mu = _points(seed)
    rho = rng.choice([20.0, 300.0, np.inf], w0.size)
    per_point = (rng.uniform(0.0, 0.4, w0.size), rng.uniform(0.5, 1.2, w0.size),
                 rng.uniform(0.0, 0.4, w0.size), rng.uniform(2.5, 3.5, w0.size), mu, w0)
    _equal(laws.yade_coulomb(*per_point, steps=STEPS, rho=rho),
           oracle.yade_coulomb(*per_point, steps=STEPS, rho=rho))
    scalar = (0.2, 0.9, 0.1, 3.5, 0.3, w0)
    _equal(laws.yade_coulomb(*scalar, steps=STEPS), oracle.yade_coulomb(*scalar, steps=STEPS))


def test_a_contact_that_never_ends_is_refused():
    with pytest.raises(RuntimeError, match="did not end"):
        laws.hertz_mindlin_coulomb(np.array([np.nan]), 1.0, 1.0, 3.5, 0.3, np.array([1.0]),
                                   steps=STEPS)


def test_points_sharing_the_kernels_lanes_get_what_they_get_alone():
    """The kernel steps :data:`~vimpact.kernels.stepped.LANES` points side by side and
    hands a finished point's lane to the next one: fewer points than lanes, more, and points
    that do not end within ``max_steps`` (NaN, counted) give each point bit for bit what it
    gives stepped alone."""
    from vimpact.kernels.stepped import LANES, LAW_LAMMPS, lanes_work, stepped_impacts

    rng, w0, mu = _points(5, 3 * LANES + 3)
    n = w0.size
    alpha = 10.0 ** rng.uniform(-3.0, 0.5, n)
    p = np.column_stack([rng.uniform(0.3, 1.0, n), rng.uniform(0.1, 2.0, n), np.zeros(n)])
    lever, spin, cap = rng.uniform(0.0, 0.3, n), np.full(n, 2.5), np.minimum(mu, 1e300)
    h = laws.HERTZ_TIME_FACTOR / STEPS
    for max_steps in (50 * STEPS, STEPS + 4):  # the second: about half the points do not end
        for m in (2, n):
            e, w = np.empty(m), np.empty(m)
            left = stepped_impacts(np.int64(LAW_LAMMPS), alpha[:m], w0[:m], lever[:m], spin[:m],
                                   cap[:m], p[:m], h, np.int64(max_steps), e, w, *lanes_work())
            alone = np.empty((m, 2))
            count = 0
            for i in range(m):
                sl = slice(i, i + 1)
                count += stepped_impacts(np.int64(LAW_LAMMPS), alpha[sl], w0[sl], lever[sl],
                                         spin[sl], cap[sl], p[sl], h, np.int64(max_steps),
                                         alone[i, :1], alone[i, 1:], *lanes_work())
            np.testing.assert_array_equal(e, alone[:, 0])
            np.testing.assert_array_equal(w, alone[:, 1])
            assert left == count
        assert max_steps == 50 * STEPS or 0 < left < n
