"""Validation messages, statuses and the batch contract of the Python API."""

import math

import numpy as np
import pytest

import vimpact as v


@pytest.mark.parametrize("make, name", [
    (lambda: v.Material.elastic(nu=0.6, E=1e9), "nu"),
    (lambda: v.Material.kelvin_voigt(nu=0.3, G=-1.0, eta=1.0), "G"),
    (lambda: v.Material.kelvin_voigt(nu=0.3, G=1e6, eta=-1.0), "eta"),
    (lambda: v.Material.standard_solid(nu=0.3, G1=1e6, G2=0.0, eta=1.0), "G2"),
    (lambda: v.Material.prony(nu=0.3, G_inf=1e6, arms=[(1e6, -1e-3)]), "tau_1"),
    (lambda: v.Scene(v.Material.elastic(nu=0.3, E=1e9), R=0.1, m=0.0, v_z0=1.0), "m"),
    (lambda: v.Scene(v.Material.elastic(nu=0.3, E=1e9), R=0.1, m=1.0, v_z0=float("nan")), "v_z0"),
    (lambda: v.Scene(v.Material.elastic(nu=0.3, E=1e9), R=0.1, m=1.0, v_z0=1.0,
                     tangential_memory="total"), "tangential_memory"),
    (lambda: v.Numerics(integrator="rk4"), "integrator"),
    (lambda: v.Numerics(steps=3), "steps"),
    (lambda: v.Numerics.preset("slow"), "preset"),
])
def test_bad_input_names_parameter(make, name):
    with pytest.raises(ValueError, match=name):
        make()


def test_single_impact_half_space_is_an_error_batch_is_a_status():
    soft = v.Scene(v.Material.elastic(nu=0.5, E=1e5), R=0.01, m=1.0, v_z0=10.0)
    with pytest.raises(v.HalfSpaceError, match="0.2 R"):
        v.simulate(soft)
    allowed = v.simulate(v.Scene(soft.material, R=0.01, m=1.0, v_z0=10.0, allow_large_contact=True))
    assert allowed.status == "half_space" and allowed.a_max > 0.2 * 0.01
    ok = v.Scene.from_dimensionless(0.1, 0.5)
    df = v.simulate_batch([ok, soft, ok], v.Numerics.preset("fast"))
    assert list(df.status) == ["ok", "half_space", "ok"]
    assert df.e_z[0] == df.e_z[2]


def test_error_column_has_one_dtype_whether_or_not_a_row_failed():
    def batch(G_inf):
        return v.simulate_batch({"G_inf_Pa": G_inf, "nu": [0.3, 0.3], "eta0_Pa_s": [10.0, 10.0],
                                 "R_m": [0.01, 0.01], "m_kg": [0.01, 0.01],
                                 "v_z0_m_s": [1.0, 1.0]}, v.Numerics.preset("fast"))

    clean, mixed = batch([1e6, 2e6]), batch([1e6, -1.0])
    assert clean["error"].dtype == mixed["error"].dtype == "str"
    assert clean["error"].isna().all()
    assert mixed["error"].isna().tolist() == [True, False] and "G_inf" in mixed["error"][1]


def test_time_limit_is_a_status_not_a_hang():
    # the time limit is the element path's (the continuum paths bound their steps)
    df = v.simulate_batch([v.Scene.from_dimensionless(0.1, 0.5)],
                          v.Numerics(steps=100, elements=20, max_time=0.3, continuum=False))
    assert df.status[0] == "time_limit"
    assert math.isnan(df.e_z[0])
    res = v.simulate(v.Scene.from_dimensionless(0.1, 0.5), v.Numerics(max_time=0.3,
                                                                       continuum=False))
    assert res.status == "time_limit" and math.isnan(res.e_z)


def test_batch_equals_single_runs():
    scenes = [v.Scene.from_dimensionless(q, nu, q2) for q, nu, q2 in
              [(0.05, 0.5, None), (1.0, 0.0, 3.0), (0.2, 0.25, 0.1)]]
    n = v.Numerics.preset("fast")
    df = v.simulate_batch(scenes, n)
    for i, s in enumerate(scenes):
        single = v.simulate(s, n)
        assert df.e_z[i] == single.e_z and df.e_x[i] == single.e_x


def test_dimensionless_scene_has_its_parameters():
    s = v.Scene.from_dimensionless(0.37, 0.2, 4.0, theta_ratio=0.1)
    assert s.Q1 == pytest.approx(0.37, rel=1e-12)
    assert s.Q2 == pytest.approx(4.0, rel=1e-12)
    assert s.theta_ratio == pytest.approx(0.1)
    assert 0.2 * s.R > s.hertz.a_H


def test_defaults_of_a_scene():
    mat = v.Material.kelvin_voigt(nu=0.5, E=3e6, eta=10.0)
    s = v.Scene(mat, R=0.01, m=1e-3, v_z0=1.0)
    assert s.Theta == pytest.approx(0.4 * 1e-3 * 0.01**2)
    assert s.v_c0 == 0.0 and s.tangential_memory == "incremental"
    assert mat.G_inf == pytest.approx(1e6)
    assert np.isnan(s.Q2)
