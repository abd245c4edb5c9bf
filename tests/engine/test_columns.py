"""The columnar batch path: scene columns in, result columns out; bad rows get a status.

References are the one-scene API (Scene objects through the same kernels), the
closed-form gross-slip law, and the linearity of the tangential problem in v_c0.
"""

import math

import numpy as np
import pandas as pd
import pytest

import vimpact as v
from vimpact.engine import pack
from vimpact.model.numerics import ELEMENT_TOLERANCE_FLOOR

FAST = v.Numerics.preset("fast")


def _columns(n=4):
    """Physical scenes of several rheologies as columns (SI units in the names)."""
    return pd.DataFrame({
        "nu": np.linspace(0.2, 0.5, n),
        "G_inf_Pa": np.full(n, 1e6),
        "eta0_Pa_s": [0.0, 30.0, 0.0, 10.0][:n],
        "G_arm1_Pa": [0.0, 0.0, 2e6, 5e5][:n],
        "tau_arm1_s": [1.0, 1.0, 1e-4, 3e-4][:n],
        "R_m": np.full(n, 0.01),
        "m_kg": np.full(n, 0.004),
        "v_z0_m_s": np.full(n, 0.3),
        "v_x0_m_s": [0.0, 0.2, 0.3, -0.1][:n],
        "omega0_rad_s": [0.0, 0.0, 5.0, 0.0][:n],
    })


def _scenes(df):
    out = []
    for _, r in df.iterrows():
        arms = [(r.G_arm1_Pa, r.tau_arm1_s)] if r.G_arm1_Pa > 0 else []
        mat = v.Material.prony(nu=r.nu, G_inf=r.G_inf_Pa, arms=arms, eta0=r.eta0_Pa_s)
        out.append(v.Scene(mat, R=r.R_m, m=r.m_kg, v_z0=r.v_z0_m_s, v_x0=r.v_x0_m_s,
                           omega0=r.omega0_rad_s, allow_large_contact=True))
    return out


def test_columns_equal_scene_objects_bit_for_bit():
    df = _columns()
    by_columns = v.simulate_batch(df.assign(model="prony"), FAST)
    by_scenes = v.simulate_batch(_scenes(df), FAST)
    assert list(by_columns.columns) == list(by_scenes.columns)
    for name in ("e_z", "beta_x", "t_contact", "energy_ratio", "status", "path"):
        assert by_columns[name].equals(by_scenes[name]), name


def test_bad_rows_get_invalid_and_leave_the_others_bit_identical():
    clean = _columns()
    bad = pd.concat([clean, clean.iloc[:4]], ignore_index=True).astype(object)
    bad.loc[4, "m_kg"] = -1.0
    bad.loc[5, "nu"] = 0.7
    bad.loc[6, "R_m"] = float("nan")
    bad.loc[7, "G_inf_Pa"] = "stiff"
    res_clean = v.simulate_batch(clean, FAST)
    res = v.simulate_batch(bad, FAST)
    assert list(res.status[4:]) == ["invalid"] * 4
    for row, name in zip(range(4, 8), ("m_kg", "nu", "R_m", "G_inf_Pa")):
        assert res.error[row].startswith(f"{name} = ") and "not allowed" in res.error[row]
        assert math.isnan(res.e_z[row])
    for name in ("e_z", "beta_x", "t_contact", "status"):
        assert res[name][:4].equals(res_clean[name]), name
    assert res.error[:4].isna().all()


def test_a_none_in_a_scene_list_is_one_bad_row():
    scenes = [v.Scene.from_dimensionless(0.1, 0.5), None]
    res = v.simulate_batch(scenes, FAST)
    assert list(res.status) == ["ok", "invalid"]
    assert "scenes[1]" in res.error[1]


def test_a_malformed_batch_is_an_input_error():
    with pytest.raises(v.InputError, match="required"):
        v.simulate_batch({"nu": [0.5]})
    with pytest.raises(v.InputError, match="unknown scene column"):
        v.simulate_batch(_columns().assign(speed=1.0))


def test_timings_are_reported():
    t = {}
    v.simulate_batch(_columns(), FAST, timings=t)
    assert 0.0 < t["kernel_s"] <= t["total_s"]


def test_held_spin_is_not_an_energy_gain():
    """Without rotation (Theta -> inf) only v_c0 = v_x0 + R omega0 matters
    (the tangential problem is linear in it); a large held spin pumps energy into
    v_x, which is physical, not an instability."""
    mat = v.Material.elastic(nu=0.5, G=1e6)
    plain = v.Scene(mat, R=0.01, m=0.004, v_z0=0.3, v_x0=0.2, rotation=False)
    spun = v.Scene(mat, R=0.01, m=0.004, v_z0=0.3, v_x0=0.2 + 0.01 * 1000.0, omega0=-1000.0,
                   rotation=False)
    a, b = v.simulate(plain), v.simulate(spun)
    assert a.status == b.status == "ok"
    assert b.e_z == pytest.approx(a.e_z, abs=1e-12)
    assert b.beta_x == pytest.approx(a.beta_x, abs=1e-9)
    assert b.omega_end == -1000.0


def test_gross_slip_through_the_batch_path():
    """Large incidence: F_x = mu F_z throughout, so
    v_c,end = v_c0 - mu (1 + m R^2/Theta)(1 + e_z) v_z0 (docs/physics.md#coulomb-friction)."""
    mu = 0.1
    res = v.simulate(v.Scene.from_dimensionless(0.2, 0.5, mu=mu), FAST)  # v_c0 = v_z0 = 1
    assert res.path.endswith("friction]") and res.status == "ok"
    expected = 1.0 - mu * (1.0 + 1.0 / 0.4) * (1.0 + res.e_z)
    assert -res.beta_x == pytest.approx(expected, abs=1e-9)
    assert res.mu_eff == pytest.approx(mu, abs=1e-9)


def test_unreachable_tolerance_is_refused_on_the_element_path_only():
    numerics = v.Numerics.for_tolerance(1e-8)
    assert numerics.tolerance == 1e-8 < ELEMENT_TOLERANCE_FLOOR
    stick = v.simulate(v.Scene.from_dimensionless(0.1, 0.5), numerics)
    assert stick.status == "ok" and stick.path.startswith("continuum")
    with pytest.raises(v.InputError, match="smallest it reaches"):
        v.simulate(v.Scene.from_dimensionless(0.1, 0.5, mu=0.3), numerics)
    df = v.simulate_batch([v.Scene.from_dimensionless(0.1, 0.5, mu=0.3)], numerics)
    assert df.status[0] == "tolerance_unreachable" and math.isnan(df.e_z[0])


def test_cost_bounds_give_a_status():
    mat = v.Material.kelvin_voigt(nu=0.5, E=1e6, eta=10.0)
    scene = v.Scene(mat, R=0.01, m=0.004, v_z0=1.0, v_x0=1.0, Theta=1e-300, mu=0.5,
                    allow_large_contact=True)
    res = v.simulate(scene, FAST)
    assert res.status == "too_costly" and "steps per Hertz time" in res.error


def test_scales_outside_the_float_range_are_refused():
    mat = v.Material.kelvin_voigt(nu=0.5, E=1e6, eta=10.0)
    with pytest.raises(v.InputError, match="floating-point range"):
        v.Scene(mat, R=0.01, m=0.004, v_z0=1e200)
    df = _columns(2).assign(v_z0_m_s=[0.3, 1e200])
    res = v.simulate_batch(df, FAST)
    assert res.status[1] == "invalid" and "floating-point range" in res.error[1]
    assert res.status[0] != "invalid"


def test_a_continuum_row_that_hits_its_step_limit_is_handed_to_the_elements(monkeypatch):
    scene = v.Scene.from_dimensionless(0.1, 0.3, Q2=1.0)
    elements = v.simulate(scene, FAST.with_(continuum=False))
    monkeypatch.setattr(pack, "CONTINUUM_STICK_MAX_STEPS", 3)
    handed = v.simulate(scene, FAST)
    assert handed.status == "ok" and handed.path == elements.path
    assert handed.beta_x == elements.beta_x and handed.e_z == elements.e_z


def test_prony_arm_with_a_third_field_is_refused():
    with pytest.raises(v.InputError, match="arm 1"):
        v.Material.prony(nu=0.5, G_inf=1e6, arms=[(1e6, 1e-3, 5.0)])


def test_a_tiny_radius_is_blamed_on_the_radius():
    with pytest.raises(v.InputError, match="^R = "):
        v.Scene(v.Material.elastic(nu=0.5, G=1e6), R=1e-200, m=0.004, v_z0=1.0)


def test_string_inputs_are_refused_at_the_boundary():
    with pytest.raises(v.InputError, match="v_z0 = '1'"):
        v.Scene(v.Material.elastic(nu=0.5, G=1e6), R=0.01, m=0.004, v_z0="1")


def test_tolerance_is_refused_for_the_seed_memory():
    """The error model is measured with the incremental memory; the seed memory's
    beta_x converges more slowly (benchmarks/element_orders.py), so no tolerance is
    claimed for it: refused with the reason, while explicit numerics still run."""
    seed = v.Scene.from_dimensionless(0.0, 0.3, tangential_memory="seed")  # elastic
    numerics = v.Numerics.for_tolerance(1e-3)
    with pytest.raises(v.InputError, match="seed memory"):
        v.simulate(seed, numerics)
    df = v.simulate_batch([seed, v.Scene.from_dimensionless(0.0, 0.3)], numerics)
    assert df.status.tolist() == ["tolerance_unreachable", "ok"]
    assert "tolerance = 0.001" in df.error[0] and math.isnan(df.beta_x[0])
    assert v.simulate(seed, FAST).status == "ok"


def test_one_row_q1_q2_are_the_column_values():
    """Q_row (simulate()'s scalar form) gives exactly Q1[0], Q2[0] for every model, with
    and without an arm column (a standard solid or Prony series given without arms)."""
    from vimpact.engine.columns import SceneColumns

    mats = [v.Material.elastic(nu=0.3, E=1e9), v.Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5),
            v.Material.standard_solid(nu=0.4, G1=1e9, G2=3e9, eta=4e6),
            v.Material.prony(nu=0.5, G_inf=1e9, arms=[(2e9, 1e-4), (1e9, 1e-2)], eta0=3e3)]
    batches = [SceneColumns.from_scenes([v.Scene(mat, R=0.01, m=0.03, v_z0=1.0)])
               for mat in mats]
    for model in ("standard_solid", "prony", "kelvin_voigt", "elastic"):  # no arm column
        batches.append(SceneColumns.from_columns({
            "nu": [0.4], "G_inf_Pa": [1e9], "eta0_Pa_s": [2e3], "R_m": [0.01],
            "m_kg": [0.03], "v_z0_m_s": [1.0], "model": np.array([model], dtype=object)}))
    for cols in batches:
        q1, q2 = cols.Q_row()
        for got, want in ((q1, cols.Q1[0]), (q2, cols.Q2[0])):
            assert type(got) is type(want)
            assert got == want or (math.isnan(got) and math.isnan(want)), (got, want)


def test_refinement_of_one_tangential_flag_is_that_of_its_mask():
    """The element path's refinement with one tangential flag for all rows gives the
    factors of the row mask holding that flag, bit for bit (with and without arms; on
    one row without arms simulate()'s scalar form against the array form)."""
    from vimpact.engine import discretization
    from vimpact.engine.columns import SceneColumns
    from vimpact.kernels.layout import EULER, VERLET

    kv = v.Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5)
    sls = v.Material.standard_solid(nu=0.4, G1=1e9, G2=3e9, eta=4e6)
    scenes = [v.Scene(kv, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0, mu=0.3),
              v.Scene(kv, R=0.2, m=10.0, v_z0=3.0, v_x0=-1.0, Theta=1e-3 * 10.0 * 0.2**2),
              v.Scene(sls, R=0.01, m=0.03, v_z0=1.0, v_x0=0.5)]
    for rows in [scenes[0]], [scenes[1]], scenes[:2], scenes[2:], scenes:
        cols = SceneColumns.from_scenes(rows)
        for flag in (False, True):
            for integrator in (VERLET, EULER):
                for numerics in (v.Numerics(), v.Numerics.preset("fast")):
                    got = discretization.element_row(cols, numerics, flag, integrator)
                    if cols.G_arm.shape == (1, 0):  # simulate()'s scalar form answered
                        assert discretization._element_row_one(
                            cols, numerics, flag, integrator) is not None
                    want = discretization.element_row(
                        cols, numerics, np.full(len(cols), flag), integrator)
                    for key in want:
                        assert np.array_equal(got[key], want[key]), (key, flag)


def test_small_full_stick_batches_run_the_impact_kernel_with_the_batch_kernels_numbers(
        monkeypatch):
    """Up to ``CONTINUUM_STICK_SERIAL_ROWS`` full-stick continuum rows run the serial
    impact kernel row by row (a small run compiles no parallel batch kernel); more
    rows run the batch kernel. Both give the same numbers, bit for bit."""
    from vimpact.kernels import continuum_maxwell

    n = pack.CONTINUUM_STICK_SERIAL_ROWS
    scenes = [v.Scene.from_dimensionless(q1, nu, q2)
              for q1, nu, q2 in zip(np.geomspace(0.01, 3.0, n + 1), np.linspace(0.0, 0.5, n + 1),
                                    [None, 0.3, 3.0] * n)]
    launches = []
    batch = continuum_maxwell.maxwell_stick_batch

    def counted(*args):
        launches.append(len(args[0]))
        return batch(*args)

    monkeypatch.setattr(continuum_maxwell, "maxwell_stick_batch", counted)
    big = v.simulate_batch(scenes)
    small = v.simulate_batch(scenes[:n])
    assert launches == [n + 1]  # the small batch did not launch the batch kernel
    assert (big.path == "continuum[stick]").all() and (big.status == "ok").all()
    for key in ("e_z", "beta_x", "e_x", "t_contact", "u_max", "a_max", "n_steps"):
        assert np.array_equal(small[key].to_numpy(), big[key].to_numpy()[:n]), key
