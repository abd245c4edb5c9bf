"""The Python API's catalogue of bad inputs, one case per id.

- Constructors and ``simulate``: a bad input raises :class:`vimpact.InputError`
  (a ``ValueError``) whose message names the parameter; nothing else escapes.
- ``simulate_batch``: a bad row gets status ``invalid`` with the reason naming
  the column, and every other row is bit-identical to the same batch without it.
- Extreme admissible inputs give a status that says what happened, or numbers
  checked against a limit the code did not produce.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

import vimpact as v
from vimpact.reference.closed_forms import kelvin_voigt_continuum

FAST = v.Numerics.preset("fast")
KV = v.Material.kelvin_voigt(nu=0.3, E=1e9, eta=10.0)
SPHERE = dict(R=0.01, m=0.004, v_z0=1.0)


def scene(**changes) -> v.Scene:
    return v.Scene(**{"material": KV, **SPHERE, **changes})


# ---- constructors, simulate: InputError naming the parameter ------------------

API_ERRORS = [
    # Material
    ("elastic-E-nan", lambda: v.Material.elastic(nu=0.3, E=math.nan), "E = nan"),
    ("elastic-E-inf", lambda: v.Material.elastic(nu=0.3, E=math.inf), "E = inf"),
    ("elastic-E-negative", lambda: v.Material.elastic(nu=0.3, E=-1e9), "E = -1"),
    ("elastic-E-string", lambda: v.Material.elastic(nu=0.3, E="1e9"), "E = '1e9'"),
    ("elastic-E-bool", lambda: v.Material.elastic(nu=0.3, E=True), "E = True"),
    ("elastic-E-and-G", lambda: v.Material.elastic(nu=0.3, E=1e9, G=1e9), "G and E"),
    ("elastic-no-modulus", lambda: v.Material.elastic(nu=0.3), "G and E"),
    ("elastic-nu-0.7", lambda: v.Material.elastic(nu=0.7, E=1e9), "nu = 0.7"),
    ("elastic-nu-string", lambda: v.Material.elastic(nu="0.3", E=1e9), "nu = '0.3'"),
    ("kv-eta-negative", lambda: v.Material.kelvin_voigt(nu=0.3, E=1e9, eta=-1.0), "eta = -1"),
    ("kv-eta-nan", lambda: v.Material.kelvin_voigt(nu=0.3, E=1e9, eta=math.nan), "eta = nan"),
    ("sls-G1-inf", lambda: v.Material.standard_solid(0.3, math.inf, 1e6, 1.0), "G1 = inf"),
    ("sls-G2-zero", lambda: v.Material.standard_solid(0.3, 1e6, 0.0, 1.0), "G2 = 0"),
    ("sls-eta-string", lambda: v.Material.standard_solid(0.3, 1e6, 1e6, "1"), "eta = '1'"),
    ("prony-third-arm-field",
     lambda: v.Material.prony(nu=0.3, G_inf=1e6, arms=[(1e6, 1e-3, 5.0)]), "arm 1"),
    ("prony-arm-number", lambda: v.Material.prony(nu=0.3, G_inf=1e6, arms=[1e6]), "arm 1"),
    ("prony-arms-none", lambda: v.Material.prony(nu=0.3, G_inf=1e6, arms=None), "arms = None"),
    ("prony-arms-string", lambda: v.Material.prony(nu=0.3, G_inf=1e6, arms="1e6:1e-3"),
     "arms = '1e6:1e-3'"),
    ("prony-arm-tau-negative", lambda: v.Material.prony(nu=0.3, G_inf=1e6, arms=[(1e6, -1.0)]),
     "tau_1"),
    ("prony-arm-G-string", lambda: v.Material.prony(nu=0.3, G_inf=1e6, arms=[("a", 1e-3)]),
     "G_1"),
    ("prony-eta0-inf", lambda: v.Material.prony(nu=0.3, G_inf=1e6, arms=[], eta0=math.inf),
     "eta0 = inf"),
    ("material-model-unknown", lambda: v.Material("maxwell", 0.3, 1e6), "model = 'maxwell'"),
    ("material-elastic-with-arm", lambda: v.Material("elastic", 0.3, 1e6, ((1e6, 1e-3),)),
     "model = 'elastic'"),
    ("material-arm-not-a-pair", lambda: v.Material("prony", 0.3, 1e6, (1e6,)), "arm 1"),
    # Scene
    ("scene-material-string", lambda: v.Scene("rubber", **SPHERE), "material = 'rubber'"),
    ("scene-v_z0-string", lambda: scene(v_z0="1"), "v_z0 = '1'"),
    ("scene-v_z0-none", lambda: scene(v_z0=None), "v_z0 = None"),
    ("scene-v_z0-zero", lambda: scene(v_z0=0.0), "v_z0 = 0"),
    ("scene-v_z0-1e200", lambda: scene(v_z0=1e200), "v_z0 = 1e+200"),
    ("scene-v_z0-1e-200", lambda: scene(v_z0=1e-200), "v_z0 = 1e-200"),
    ("scene-v_z0-huge-int", lambda: scene(v_z0=10**400), "v_z0 = 1000"),
    ("scene-v_z0-complex", lambda: scene(v_z0=1 + 0j), "v_z0 = (1+0j)"),
    ("scene-v_z0-array", lambda: scene(v_z0=np.array([1.0])), "v_z0 = array"),
    ("scene-v_x0-1e300", lambda: scene(v_x0=1e300), "v_x0 = 1e+300"),
    ("scene-omega0-1e200", lambda: scene(omega0=1e200), "omega0 = 1e+200"),
    ("scene-R-zero", lambda: scene(R=0.0), "R = 0"),
    ("scene-R-1e-300", lambda: scene(R=1e-300), "R = 1e-300"),
    ("scene-m-negative", lambda: scene(m=-1.0), "m = -1"),
    ("scene-v_x0-nan", lambda: scene(v_x0=math.nan), "v_x0 = nan"),
    ("scene-omega0-inf", lambda: scene(omega0=-math.inf), "omega0 = -inf"),
    ("scene-Theta-zero", lambda: scene(Theta=0.0), "Theta = 0"),
    ("scene-Theta-string", lambda: scene(Theta="0.4"), "Theta = '0.4'"),
    ("scene-memory-unknown", lambda: scene(tangential_memory="total"), "tangential_memory"),
    ("scene-tangential-unknown", lambda: scene(tangential="slip"), "tangential = 'slip'"),
    ("scene-rotation-string", lambda: scene(rotation="yes"), "rotation = 'yes'"),
    ("scene-rotation-int", lambda: scene(rotation=1), "rotation = 1"),
    ("scene-large-contact-string", lambda: scene(allow_large_contact="no"),
     "allow_large_contact = 'no'"),
    ("scene-mu-negative", lambda: scene(mu=-1.0), "mu = -1"),
    ("scene-mu-nan", lambda: scene(mu=math.nan), "mu = nan"),
    ("scene-eta-1e120", lambda: v.Scene(v.Material.kelvin_voigt(nu=0.3, E=1e9, eta=1e120),
                                        **SPHERE), "eta0 = 1e+120"),
    ("dimensionless-Q1-1e300", lambda: v.Scene.from_dimensionless(1e300, 0.5), "Q1 = 1e+300"),
    ("dimensionless-Q1-nan", lambda: v.Scene.from_dimensionless(math.nan, 0.5), "Q1 = nan"),
    ("dimensionless-Q1-negative", lambda: v.Scene.from_dimensionless(-1.0, 0.5), "Q1 = -1"),
    ("dimensionless-Q2-zero", lambda: v.Scene.from_dimensionless(0.1, 0.5, 0.0), "Q2 = 0"),
    ("dimensionless-Q2-1e-300", lambda: v.Scene.from_dimensionless(0.1, 0.5, 1e-300),
     "Q2 = 1e-300"),
    ("dimensionless-nu-string", lambda: v.Scene.from_dimensionless(0.1, "0.5"), "nu = '0.5'"),
    ("dimensionless-theta-ratio-zero",
     lambda: v.Scene.from_dimensionless(0.1, 0.5, theta_ratio=0.0), "theta_ratio = 0"),
    # Numerics
    ("numerics-steps-1e9", lambda: v.Numerics(steps=10**9), "steps = 1000000000"),
    ("numerics-steps-3", lambda: v.Numerics(steps=3), "steps = 3"),
    ("numerics-steps-float", lambda: v.Numerics(steps=500.0), "steps = 500.0"),
    ("numerics-elements-1e8", lambda: v.Numerics(elements=10**8), "elements = 100000000"),
    ("numerics-elements-string", lambda: v.Numerics(elements="70"), "elements = '70'"),
    ("numerics-integrator", lambda: v.Numerics(integrator="rk4"), "integrator = 'rk4'"),
    ("numerics-rtol-nan", lambda: v.Numerics(rtol=math.nan), "rtol = nan"),
    ("numerics-max-time-zero", lambda: v.Numerics(max_time=0.0), "max_time = 0"),
    ("numerics-max-time-inf", lambda: v.Numerics(max_time=math.inf), "max_time = inf"),
    ("numerics-row-width", lambda: v.Numerics(row_width=0.5), "row_width = 0.5"),
    ("numerics-continuum-string", lambda: v.Numerics(continuum="yes"), "continuum = 'yes'"),
    ("numerics-tolerance-1", lambda: v.Numerics(tolerance=1.0), "tolerance = 1"),
    ("numerics-preset-unknown", lambda: v.Numerics.preset("turbo"), "'turbo'"),
    ("for-tolerance-1e-12", lambda: v.Numerics.for_tolerance(1e-12), "tolerance = 1e-12"),
    # simulate
    ("simulate-not-a-scene", lambda: v.simulate("scene"), "scene = 'scene'"),
    ("simulate-preset-unknown", lambda: v.simulate(scene(), "fastest"), "'fastest'"),
    ("simulate-numerics-number", lambda: v.simulate(scene(), 3), "numerics = 3"),
    ("simulate-half-space", lambda: v.simulate(scene(R=1e-30)), "a_max"),
    ("simulate-tolerance-unreachable",
     lambda: v.simulate(scene(v_x0=1.0, mu=0.3), v.Numerics.for_tolerance(1e-9)),
     "tolerance = 1e-09"),
    # simulate_batch: a malformed batch (not one bad row)
    ("batch-string", lambda: v.simulate_batch("scenes"), "scenes"),
    ("batch-number", lambda: v.simulate_batch(42), "scenes"),
    ("batch-preset-unknown", lambda: v.simulate_batch([scene()], "turbo"), "'turbo'"),
    ("batch-column-missing", lambda: v.simulate_batch({"nu": [0.5]}), "G_inf_Pa"),
    ("batch-column-unknown",
     lambda: v.simulate_batch({"nu": [0.5], "G_inf_Pa": [1e9], "R_m": [1.0], "m_kg": [1.0],
                               "v_z0_m_s": [1.0], "speed": [1.0]}), "'speed'"),
    ("batch-column-lengths",
     lambda: v.simulate_batch({"nu": [0.5, 0.5], "G_inf_Pa": [1e9], "R_m": [1.0],
                               "m_kg": [1.0], "v_z0_m_s": [1.0]}), "one length"),
    ("batch-arm-without-time",
     lambda: v.simulate_batch({"nu": [0.5], "G_inf_Pa": [1e9], "R_m": [1.0], "m_kg": [1.0],
                               "v_z0_m_s": [1.0], "G_arm1_Pa": [1e9]}), "tau_arm1_s"),
    ("batch-Theta-and-ratio",
     lambda: v.simulate_batch({"nu": [0.5], "G_inf_Pa": [1e9], "R_m": [1.0], "m_kg": [1.0],
                               "v_z0_m_s": [1.0], "Theta_kg_m2": [0.4], "theta_ratio": [0.4]}),
     "Theta_kg_m2"),
]


@pytest.mark.parametrize("make, name", [pytest.param(f, n, id=i) for i, f, n in API_ERRORS])
def test_api_refuses(make, name):
    with pytest.raises(v.InputError) as info:
        make()
    text = str(info.value)
    assert name in text and "\n" not in text, text


def test_a_valid_preset_name_is_accepted():
    """``simulate(scene, "fast")``: a preset name is a valid ``numerics``."""
    by_name, given = v.simulate(scene(), "fast"), v.simulate(scene(), FAST)
    assert by_name.status == "vc0_zero" and by_name.e_z == given.e_z


# ---- simulate_batch: one bad row, the others unchanged -------------------------

#: A clean batch: Kelvin-Voigt oblique and normal, a standard solid (arm columns).
CLEAN = pd.DataFrame({
    "nu": [0.3, 0.5, 0.49], "G_inf_Pa": [3.8e8, 1e8, 1e7], "eta0_Pa_s": [10.0, 0.0, 0.0],
    "G_arm1_Pa": [0.0, 0.0, 3e7], "tau_arm1_s": [1.0, 1.0, 2e-5],
    "R_m": [0.01, 0.02, 0.01], "m_kg": [0.004, 0.03, 0.004], "v_z0_m_s": [1.0, 2.0, 1.0],
    "v_x0_m_s": [0.5, 0.0, 0.8], "omega0_rad_s": [0.0, 0.0, -40.0],
    "theta_ratio": [0.4, 0.4, 0.4], "mu": [math.inf] * 3,
    "tangential": ["auto", "none", "auto"], "tangential_memory": ["incremental"] * 3,
    "rotation": [True, True, True], "model": ["kelvin_voigt", "elastic", "standard_solid"],
})

BAD_ROWS = [
    # (id, column, value, what the reason must contain)
    ("v_z0-1e-200", "v_z0_m_s", 1e-200, "floating-point"),
    ("v_z0-1e200", "v_z0_m_s", 1e200, "floating-point"),
    ("v_z0-zero", "v_z0_m_s", 0.0, "v_z0_m_s = 0"),
    ("v_z0-negative", "v_z0_m_s", -1.0, "v_z0_m_s = -1"),
    ("v_z0-nan", "v_z0_m_s", math.nan, "v_z0_m_s = nan"),
    ("v_z0-inf", "v_z0_m_s", math.inf, "v_z0_m_s = inf"),
    ("v_z0-string", "v_z0_m_s", "1", "v_z0_m_s = '1'"),
    ("v_z0-none", "v_z0_m_s", None, "v_z0_m_s = None"),
    ("v_z0-bool", "v_z0_m_s", True, "v_z0_m_s = True"),
    ("nu-0.7", "nu", 0.7, "nu = 0.7"),
    ("nu-nan", "nu", math.nan, "nu = nan"),
    ("G_inf-word", "G_inf_Pa", "stiff", "G_inf_Pa = 'stiff'"),
    ("G_inf-negative", "G_inf_Pa", -1.0, "G_inf_Pa = -1"),
    ("G_inf-inf", "G_inf_Pa", math.inf, "G_inf_Pa = inf"),
    ("eta0-negative", "eta0_Pa_s", -1.0, "eta0_Pa_s = -1"),
    ("eta0-1e300", "eta0_Pa_s", 1e300, "eta0_Pa_s = 1e+300"),
    ("v_x0-1e300", "v_x0_m_s", 1e300, "kinetic energy"),
    ("omega0-1e300", "omega0_rad_s", 1e300, "kinetic energy"),
    ("R-zero", "R_m", 0.0, "R_m = 0"),
    ("R-1e-300", "R_m", 1e-300, "floating-point"),
    ("m-negative", "m_kg", -1.0, "m_kg = -1"),
    ("v_x0-nan", "v_x0_m_s", math.nan, "v_x0_m_s = nan"),
    ("omega0-inf", "omega0_rad_s", math.inf, "omega0_rad_s = inf"),
    ("theta-ratio-zero", "theta_ratio", 0.0, "theta_ratio = 0"),
    ("mu-negative", "mu", -1.0, "mu = -1"),
    ("mu-nan", "mu", math.nan, "mu = nan"),
    ("arm-G-negative", "G_arm1_Pa", -1.0, "G_arm1_Pa = -1"),
    ("arm-tau-zero", "tau_arm1_s", 0.0, "tau_arm1_s = 0"),
    ("tangential-unknown", "tangential", "slip", "tangential = 'slip'"),
    ("memory-unknown", "tangential_memory", "total", "tangential_memory = 'total'"),
    ("rotation-string", "rotation", "yes", "rotation = 'yes'"),
    ("model-unknown", "model", "maxwell", "model = 'maxwell'"),
    ("model-misfit", "model", "elastic", "model = 'elastic'"),
]


def same_rows(got: pd.DataFrame, expected: pd.DataFrame) -> None:
    """Bit-identical outputs; ``error`` empty in both (its dtype follows the batch)."""
    outputs = [c for c in expected.columns if c != "error"]
    pd.testing.assert_frame_equal(got[outputs], expected[outputs], check_dtype=False)
    assert got.error.isna().all() and expected.error.isna().all()


@pytest.fixture(scope="module")
def clean_result() -> pd.DataFrame:
    return v.simulate_batch(CLEAN, FAST)


@pytest.mark.parametrize("column, value, reason",
                         [pytest.param(c, x, r, id=i) for i, c, x, r in BAD_ROWS])
def test_one_bad_row_is_invalid_and_the_others_unchanged(column, value, reason, clean_result):
    bad = pd.concat([CLEAN, CLEAN.iloc[:1]], ignore_index=True).astype(object)
    bad.at[3, column] = value
    res = v.simulate_batch(bad, FAST)
    assert res.status[3] == "invalid" and reason in res.error[3], res.error[3]
    assert all(math.isnan(res[name][3]) for name in ("e_z", "beta_x", "t_contact", "Q1"))
    same_rows(res.iloc[:3], clean_result)


def test_a_none_in_a_scene_list_is_one_bad_row():
    scenes = [scene(v_x0=0.5), None, "scene", v.Scene.from_dimensionless(0.1, 0.5)]
    res = v.simulate_batch(scenes, FAST)
    assert list(res.status) == ["ok", "invalid", "invalid", "ok"]
    assert "scenes[1] = None" in res.error[1] and "scenes[2] = 'scene'" in res.error[2]
    alone = v.simulate_batch([scenes[0], scenes[3]], FAST)
    same_rows(res.iloc[[0, 3]].reset_index(drop=True), alone)


# ---- extreme admissible inputs ----------------------------------------------------

@pytest.mark.parametrize("Q1", [1e20, 1e60, 1e99])
def test_overdamped_kelvin_voigt_follows_its_asymptote(Q1):
    """Far overdamped, the sphere stops within ~Q1^(-2/3) d and e_z = c Q1^(-5/3);
    c from the independent scipy reference at Q1 = 1e6 (where it has converged to 3e-7)."""
    c = kelvin_voigt_continuum(1e6).e_z * 1e6 ** (5.0 / 3.0)
    res = v.simulate(v.Scene.from_dimensionless(Q1, 0.5, tangential="none"), FAST)
    assert res.status == "normal_only"
    assert res.e_z * Q1 ** (5.0 / 3.0) == pytest.approx(c, rel=1e-5)


def test_oblique_overdamped_kelvin_voigt_is_a_status_with_a_reason():
    """Q1 = 6e99 oblique: the contact lasts a fraction of one element step; no number."""
    res = v.simulate(v.Scene.from_dimensionless(6e99, 0.5), FAST)
    assert res.status == "unresolved" and "time steps" in res.error
    assert math.isnan(res.e_z) and math.isnan(res.beta_x)


def test_explicit_euler_with_4_steps_is_never_ok():
    res = v.simulate(v.Scene.from_dimensionless(0.1, 0.5),
                     v.Numerics(integrator="euler", steps=4, elements=4, continuum=False))
    assert res.status == "unresolved" and math.isnan(res.e_z)


@pytest.mark.parametrize("v_z0", [1e-30, 1e30])
def test_speed_over_60_decades_gives_the_same_restitution(v_z0):
    """Restitution depends on Q1 (and nu, Theta/(m R^2)) only: a Kelvin-Voigt scene at
    1e-30 or 1e30 m/s, with eta scaled to keep Q1, gives the Q1 = 0.1 closed form."""
    base = v.Scene.from_dimensionless(0.1, 0.5, tangential="none")
    # T = d / v_z0 with d ~ v_z0^(4/5): eta / G = Q1 T / sqrt(15/32) scales as v_z0^(-1/5)
    mat = base.material
    eta = mat.eta0 * v_z0 ** (-0.2)
    s = v.Scene(v.Material.kelvin_voigt(nu=0.5, G=mat.G_inf, eta=eta), R=1.0, m=1.0,
                v_z0=v_z0, tangential="none", allow_large_contact=True)
    assert s.Q1 == pytest.approx(0.1, rel=1e-12)
    res = v.simulate(s, FAST)
    assert res.status in ("normal_only", "half_space")
    assert res.e_z == pytest.approx(kelvin_voigt_continuum(0.1).e_z, abs=1e-6)


#: Full stick (mu = inf) of the friction scenes below: the limit of a finite mu as
#: v_c0 / v_z0 -> 0 (the tangential force needed to stick shrinks with v_c0, the
#: normal force does not).
FRICTION = dict(nu=0.3, G_inf_Pa=3.8e8, eta0_Pa_s=10.0, R_m=0.01, m_kg=0.004, v_z0_m_s=1.0)


def _friction_rows(v_x0: float) -> pd.DataFrame:
    return pd.DataFrame([{**FRICTION, "v_x0_m_s": v_x0, "mu": mu} for mu in (0.3, math.inf)])


def test_friction_at_a_tiny_contact_point_speed_is_never_an_impossible_ok():
    """v_c0 = 1e-8 v_z0 with mu = 0.3: the friction kernel loses the tangential solution
    (it returned beta_x = 73 as ok); |beta_x| > 1 is impossible in a passive scene, so
    the row must not be ok."""
    res = v.simulate_batch(_friction_rows(1e-8), FAST)
    stick = res.beta_x[1]
    assert res.status[1] == "ok" and abs(stick) <= 1.0
    assert res.status[0] != "ok" or res.beta_x[0] == pytest.approx(stick, abs=1e-2)
    assert res.status[0] == "ok" or (isinstance(res.error[0], str) and math.isnan(res.beta_x[0]))


def test_friction_at_a_small_contact_point_speed_tends_to_full_stick():
    """mu v_z0 >> v_c0 is the limit mu -> inf (docs/physics.md#coulomb-friction): beta_x
    tends to the full-stick value as v_c0 / v_z0 -> 0. Before the fix (a sticking element
    leaving within a step had its tangential force drawn linearly to mu times a negative
    normal force) it went the other way: +0.50 at 1e-6, +0.76 at 1e-7, all ok."""
    elements = dataclasses.replace(FAST, continuum=False)  # the stick row on the same path and numerics
    gaps = []
    for v_x0 in (1e-4, 1e-6, 1e-8, 1e-10):
        res = v.simulate_batch(_friction_rows(v_x0), elements)
        assert res.status[0] == res.status[1] == "ok"
        gaps.append(abs(res.beta_x[0] - res.beta_x[1]))
    assert all(a > b for a, b in zip(gaps, gaps[1:]))  # monotone towards stick
    assert gaps[-1] < 1e-6


@pytest.mark.parametrize("mu", [1e20, 1e50, 1e300])
def test_an_enormous_friction_coefficient_is_full_stick(mu):
    """mu so large that psi < 1e-12: friction would move beta_x by at most ~psi, below
    rounding, while mu v_z0 / |v_c0| only feeds round-off (mu = 1e50 ended as
    unstable, NaN). Such a row is full stick, on the stick path, with the mu = inf
    numbers exactly; explain says why."""
    rows = pd.DataFrame([{**FRICTION, "v_x0_m_s": 0.5, "mu": m} for m in (mu, math.inf)])
    res = v.simulate_batch(rows, FAST)
    assert (res.status == "ok").all() and res.path[0] == res.path[1]
    assert res.beta_x[0] == res.beta_x[1] and res.e_z[0] == res.e_z[1]
    scene = v.Scene(material=v.Material.kelvin_voigt(nu=0.3, G=3.8e8, eta=10.0), R=0.01,
                    m=0.004, v_z0=1.0, v_x0=0.5, mu=mu)
    assert "psi is below 1e-12" in v.choose_path(scene, FAST).explain()
