"""The one-row route (simulate()'s) picks the path the batch route picks for that row,
and a single impact gives the same numbers on one thread and on two."""

import math

import numba
import numpy as np
import pytest

import vimpact as v
from vimpact.engine.columns import SceneColumns
from vimpact.engine.routing import route


def _random_columns(n: int, seed: int) -> dict:
    """Rows that reach every routing key: arms or not, dashpot or not, tangential
    problem or not (v_c0 = 0 included), both memories, finite and infinite mu (some
    below the incidence at which friction counts), and invalid rows."""
    rng = np.random.default_rng(seed)
    R = 10.0 ** rng.uniform(-3.0, -1.0, n)
    m = 7800.0 * 4.0 / 3.0 * math.pi * R**3
    v_z0 = 10.0 ** rng.uniform(-1.0, 1.0, n)
    G = 10.0 ** rng.uniform(7.0, 10.0, n)
    arm = rng.random(n) < 0.4
    memory = np.where(rng.random(n) < 0.3, "seed", "incremental").astype(object)
    mu = np.where(rng.random(n) < 0.5, np.inf, rng.uniform(0.1, 0.5, n))
    mu = np.where(memory == "seed", np.inf, mu)  # seed memory takes full stick only
    v_x0 = v_z0 * rng.choice([0.0, 1e-14, 0.5, -1.0], n)
    nu = rng.uniform(0.0, 0.5, n)
    nu[rng.random(n) < 0.05] = 0.7  # invalid
    return {
        "nu": nu, "G_inf_Pa": G, "R_m": R, "m_kg": m, "v_z0_m_s": v_z0, "v_x0_m_s": v_x0,
        "omega0_rad_s": np.where(rng.random(n) < 0.1, -v_x0 / R, 0.0),  # v_c0 = 0
        "eta0_Pa_s": np.where(rng.random(n) < 0.6, G * 1e-6, 0.0),
        "G_arm1_Pa": np.where(arm, G * 2.0, 0.0), "tau_arm1_s": np.full(n, 1e-5),
        "tangential": rng.choice(["auto", "stick", "none"], n).astype(object),
        "tangential_memory": memory, "mu": mu,
        "rotation": rng.random(n) < 0.7,
    }


@pytest.mark.parametrize("numerics", [v.Numerics(), v.Numerics(continuum=False)])
def test_one_row_route_is_the_batch_route(numerics):
    cols = SceneColumns.from_columns(_random_columns(400, seed=3))
    batch = route(cols, numerics)
    assert len({p.name for p in batch.paths}) >= 6  # the rows reach many kernels
    for i in range(len(cols)):
        one = route(cols.take(np.array([i])), numerics)
        assert one.group.shape == (1,)
        if batch.group[i] < 0:
            assert one.group[0] == -1 and one.paths == ()
        else:
            assert one.group[0] == 0
            assert one.paths == (batch.paths[batch.group[i]],)


def _scenes():
    kv = v.Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5)
    return [(v.Scene(kv, R=0.2, m=10.0, v_z0=10.0, tangential="none"), v.Numerics()),
            (v.Scene(kv, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0), v.Numerics()),
            (v.Scene(kv, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0, mu=0.3), "fast")]


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="numba has one thread here")
def test_one_impact_same_on_one_and_two_threads(monkeypatch):
    """One row runs on a serial kernel: the thread count changes nothing, and
    simulate() leaves numba's thread count alone (no set per impact)."""
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = [v.simulate(s, n).to_dict() for s, n in _scenes()]
        numba.set_num_threads(2)
        calls = []
        monkeypatch.setattr(numba, "set_num_threads", lambda k: calls.append(k))
        two = [v.simulate(s, n).to_dict() for s, n in _scenes()]
    finally:
        monkeypatch.undo()
        numba.set_num_threads(before)
    assert calls == []
    assert [repr(r) for r in one] == [repr(r) for r in two]


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="numba has one thread here")
def test_batch_same_on_one_and_two_threads():
    """On the two continuum batch kernels (normal only; oblique full stick)."""
    cols = _random_columns(300, seed=5)
    keep = ["nu", "G_inf_Pa", "R_m", "m_kg", "v_z0_m_s", "v_x0_m_s", "eta0_Pa_s", "tangential"]
    cols = {k: cols[k] for k in keep}
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = v.simulate_batch(cols)
        numba.set_num_threads(2)
        two = v.simulate_batch(cols)
    finally:
        numba.set_num_threads(before)
    assert set(one["path"].dropna()) == {"continuum[kelvin_voigt,normal]", "continuum[stick]"}
    assert one.equals(two)
