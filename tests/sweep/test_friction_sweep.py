"""Friction in sweep specs: the psi grid, mu and angle_deg draws, and the limits of
docs/physics.md#coulomb-friction: gross slip throughout and full stick (psi = 0)."""

import math

import numpy as np
import pandas as pd
import pytest

import vimpact as v
from tests.sweep import write
from vimpact.sweep import load_spec, run_sweep
from vimpact.sweep.parameters import engine_columns

#: A grid of the incidence psi: psi = 0 (full stick), 0.5 and 2 (stick and slip
#: mixed), 10 and 20 (above 4 chi: gross slip during the whole contact).
EXAMPLE = """
description = "Kelvin-Voigt, Q1 = 0.1, Coulomb friction mu = 0.3: a grid of the incidence psi"
model = "kelvin_voigt"
chunk_size = 10
output = "friction_psi.parquet"

[grid]
Q1 = 0.1
nu = [0.3, 0.5]
psi = [0.0, 0.5, 2.0, 10.0, 20.0]
mu = 0.3
"""
FRICTION_OUTPUTS = ["mu_eff", "rebound_angle_deg", "gross_slip_fraction", "friction_energy_J"]

RANDOM_FRICTION = """
model = "kelvin_voigt"
seed = 5
chunk_size = 4
[numerics]
preset = "fast"
[random]
rows = 6
E_Pa = 1e8
eta_Pa_s = 20.0
nu = 0.4
R_m = 0.01
m_kg = 0.004
v_z0_m_s = [0.5, 2.0]
angle_deg = [0.0, 80.0]
mu = { choice = [0.0, 0.25, "inf"] }
omega0_rad_s = [-30.0, 30.0]
"""


def stick_version(text: str) -> str:
    """The same spec without friction: no psi axis, no mu."""
    return "\n".join(line for line in text.splitlines()
                     if not line.startswith(("psi", "mu"))) + "\n"


@pytest.fixture(scope="module")
def example_tables(tmp_path_factory):
    """The psi grid and the same grid without friction, run with run_sweep."""
    tmp = tmp_path_factory.mktemp("friction")
    friction = pd.read_parquet(run_sweep(write(tmp, EXAMPLE), out=tmp / "friction.parquet",
                                         progress=False))
    stick_spec = write(tmp, stick_version(EXAMPLE), "stick.toml")
    stick = pd.read_parquet(run_sweep(stick_spec, out=tmp / "stick.parquet", progress=False))
    return friction, stick


# ---- a psi grid, run end to end --------------------------------------

def test_example_spec_layout(tmp_path):
    spec = load_spec(write(tmp_path, EXAMPLE))
    assert spec.has_friction and spec.grid_mu == 0.3
    assert list(spec.axes) == ["psi", "theta_ratio", "nu", "Q1"]  # Q1 fastest, psi slowest
    assert spec.rows == 10
    cols = spec.columns()
    assert {"mu", "psi", *FRICTION_OUTPUTS} <= set(cols)
    assert spec.units()["psi"] == "1" and spec.units()["friction_energy_J"] == "J"
    assert spec.units()["rebound_angle_deg"] == "deg"
    # the scene that explains a row is the one the engine ran
    p = spec.parameters()
    batches, inputs = engine_columns(spec, p)
    (rows, cols), = batches
    for i in range(spec.rows):
        scene = spec.scene(p, i)
        assert (scene.v_x0, scene.mu) == (cols["v_x0_m_s"][i], cols["mu"][i])
        assert scene.v_x0 == inputs["v_x0_m_s"][i] and scene.mu == inputs["mu"][i]
        nu = p["nu"][i]
        psi = 2 * (1 - nu) / (scene.mu * (2 - nu)) * scene.v_c0 / scene.v_z0
        assert psi == pytest.approx(p["psi"][i], rel=1e-14, abs=0)


def test_gross_slip_rows_follow_the_closed_form(example_tables):
    """psi = 10, 20 > 4 chi: F_x = mu F_z during the whole contact, so
    v_c,end = v_c0 - mu (1 + m R^2/Theta) (1 + e_z) v_z0 for every rheology."""
    df, _ = example_tables
    assert (df.status == "ok").all()
    chi = (1 - df.nu) * (1 + 1 / df.theta_ratio) / (2 - df.nu)
    slip = df[df.psi > 4 * chi]
    assert len(slip) == 4
    v_c0 = slip.v_x0_m_s + slip.R_m * slip.omega0_rad_s
    # psi as the table says, from its own inputs (reference scene v_z0 = 1 m/s)
    psi = 2 * (1 - slip.nu) / (slip.mu * (2 - slip.nu)) * v_c0 / slip.v_z0_m_s
    np.testing.assert_allclose(psi, slip.psi, rtol=1e-14)
    v_c_end = v_c0 - slip.mu * (1 + 1 / slip.theta_ratio) * (1 + slip.e_z) * slip.v_z0_m_s
    # every element in contact slips, f_t = mu f_n, so the discrete tangential impulse is
    # mu times the normal one at every step: the identity holds to rounding (measured
    # 3e-15 of v_c0); gross_slip_fraction is below 1 by the first and last steps only
    assert (slip.gross_slip_fraction > 0.999).all()
    np.testing.assert_allclose(-slip.beta_x * v_c0, v_c_end, rtol=0, atol=1e-9 * v_c0.max())
    np.testing.assert_allclose(slip.mu_eff, slip.mu, rtol=1e-9)
    assert (slip.friction_energy_J > 0).all()


def test_psi_zero_rows_equal_the_stick_sweep(example_tables):
    df, stick = example_tables
    assert "psi" not in stick and "mu" not in stick  # a stick table has no friction inputs
    zero = df[df.psi == 0.0].reset_index(drop=True)
    assert (zero.mu == math.inf).all() and (zero.v_x0_m_s == 1.0).all()
    same = [c for c in stick.columns if c != "row"]
    pd.testing.assert_frame_equal(zero[same], stick[same])
    assert (zero.gross_slip_fraction == 0).all() and (zero.friction_energy_J == 0).all()


def test_friction_leaves_the_normal_problem_alone(example_tables):
    """MDR: the normal problem does not see the tangential one, so e_z and the contact
    time are those of the stick rows (other kernel: discretization error only)."""
    df, stick = example_tables
    for nu in (0.3, 0.5):
        ref = stick[stick.nu == nu].iloc[0]
        rows = df[(df.nu == nu) & (df.psi > 0)]
        np.testing.assert_allclose(rows.e_z, ref.e_z, rtol=1e-4)
        np.testing.assert_allclose(rows.t_contact_rel, ref.t_contact_rel, rtol=1e-3)


def test_small_psi_tends_to_full_stick(tmp_path):
    """psi -> 0 is the full-stick limit mu -> inf: beta_x approaches the stick value
    (all rows on the element path, so the discretization is the same)."""
    spec = write(tmp_path, """
model = "kelvin_voigt"
[numerics]
preset = "fast"
continuum = false
[grid]
Q1 = 0.1
nu = 0.5
psi = [0.0, 0.008, 0.04, 0.2, 1.0]
""")
    df = pd.read_parquet(run_sweep(spec, progress=False))
    assert (df.status == "ok").all() and df.psi.is_monotonic_increasing
    assert df.mu.iloc[0] == math.inf and (df.mu.iloc[1:] == 1.0).all()  # default [grid] mu
    gap = np.abs(df.beta_x.to_numpy()[1:] - df.beta_x.iloc[0])
    assert np.all(np.diff(gap) > 0), gap
    assert gap[0] < 0.1 * gap[-1]


# ---- random draws -----------------------------------------------------------------

def test_random_mu_and_angle_columns(tmp_path):
    spec = load_spec(write(tmp_path, RANDOM_FRICTION))
    assert spec.has_friction
    cols = spec.columns()
    assert cols.index("angle_deg") < cols.index("mu") < cols.index("Q1")
    assert cols.index("theta_ratio") < cols.index("psi") < cols.index("e_z")
    p = spec.parameters()
    assert set(np.unique(p["mu"])) == {0.0, 0.25, math.inf}
    np.testing.assert_allclose(p["v_x0_m_s"], p["v_z0_m_s"] * np.tan(np.radians(p["angle_deg"])),
                               rtol=1e-15)
    _, inputs = engine_columns(spec, p)
    v_c0 = p["v_x0_m_s"] + p["R_m"] * p["omega0_rad_s"]
    expected = np.where(p["mu"] == math.inf, 0.0,
                        np.where(p["mu"] == 0.0, np.sign(v_c0) * np.inf,
                                 2 * 0.6 / (np.where(p["mu"] == 0, 1, p["mu"]) * 1.6)
                                 * v_c0 / p["v_z0_m_s"]))
    np.testing.assert_allclose(inputs["psi"], expected, rtol=1e-14)
    for i in range(spec.rows):  # the row's scene has its mu and angle
        scene = spec.scene(p, i)
        assert scene.mu == p["mu"][i] and scene.v_x0 == p["v_x0_m_s"][i]


def test_random_friction_rows_match_single_simulations(tmp_path):
    path = run_sweep(write(tmp_path, RANDOM_FRICTION), progress=False)
    df = pd.read_parquet(path)
    spec = load_spec(tmp_path / "spec.toml")
    p = spec.parameters()
    assert list(df.columns) == spec.columns()
    for i in range(spec.rows):
        res = v.simulate(spec.scene(p, i), spec.numerics)
        row = df.iloc[i]
        assert row.status == res.status
        for col, name in (("e_z", "e_z"), ("beta_x", "beta_x"), ("mu_eff", "mu_eff"),
                          ("rebound_angle_deg", "rebound_angle"),
                          ("gross_slip_fraction", "gross_slip_fraction"),
                          ("friction_energy_J", "friction_energy")):
            np.testing.assert_equal(row[col], getattr(res, name), err_msg=col)


def test_spec_without_friction_has_no_friction_inputs(tmp_path):
    stick = RANDOM_FRICTION.replace('mu = { choice = [0.0, 0.25, "inf"] }\n', "")
    spec = load_spec(write(tmp_path, stick))
    assert not spec.has_friction
    assert "mu" not in spec.columns() and "psi" not in spec.columns()
    assert "angle_deg" in spec.columns() and set(FRICTION_OUTPUTS) <= set(spec.columns())


# ---- bad friction keys -----------------------------------------------------------

GRID = 'model = "kelvin_voigt"\n[grid]\nQ1 = 0.1\nnu = 0.5\n'
RANDOM = ('model = "elastic"\nseed = 1\n[random]\nrows = 2\nG_Pa = 1e9\nnu = 0.3\nR_m = 0.01\n'
          'm_kg = 0.01\nv_z0_m_s = 1.0\n')


@pytest.mark.parametrize("text, key", [
    (GRID + "mu = 0.5\n", "grid.mu"),
    (GRID + "psi = [0, 1]\nmu = 0\n", "grid.mu"),
    (GRID + "psi = [0, 1]\nmu = inf\n", "grid.mu"),
    (GRID + "psi = [-1, 1]\n", "grid.psi"),
    (GRID + "psi = [0, inf]\n", "grid.psi"),
    (RANDOM + "mu = -0.1\n", "random.mu"),
    (RANDOM + "mu = [-0.1, 1]\n", "random.mu"),
    (RANDOM + "mu = { choice = [0.1, -1] }\n", "random.mu.choice"),
    (RANDOM + 'mu = "stick"\n', "random.mu"),
    (RANDOM + "angle_deg = 90\n", "random.angle_deg"),
    (RANDOM + "angle_deg = [0, 95]\n", "random.angle_deg"),
    (RANDOM + "angle_deg = 30\nv_x0_m_s = 1\n", "random.angle_deg/v_x0_m_s"),
])
def test_bad_friction_keys_name_the_key(tmp_path, text, key):
    with pytest.raises(ValueError) as info:
        load_spec(write(tmp_path, text, "bad_spec.toml"))
    message = str(info.value)
    assert "bad_spec.toml" in message and key in message and "\n" not in message
