"""The shipped Kelvin-Voigt friction table (``beta_x`` over ``Q1``, ``nu``, ``psi``): its
gross-slip part against the closed form, no overshoot over dense psi sweeps, its
stated error at fresh held-out points simulated here, and the shape-preserving
interpolant on its own."""

from pathlib import Path

import numpy as np
import pytest

from tests.sweep import write

ROOT = Path(__file__).resolve().parents[2]
TABLE = ROOT / "sweeps" / "tables" / "kelvin_voigt_friction_table.parquet"
SPEC = ROOT / "sweeps" / "kelvin_voigt_friction_table.toml"


@pytest.fixture(scope="module")
def table():
    from vimpact.lookup.table import RestitutionTable

    return RestitutionTable.open(TABLE)


def _points(table, n, seed):
    """Random Q1 (log-uniform) and nu inside the table."""
    info = table.info()["ranges"]
    rng = np.random.default_rng(seed)
    q1 = np.exp(rng.uniform(*np.log(info["Q1"]), n))
    nu = rng.uniform(*info["nu"], n)
    return q1, nu


def test_states_its_error_and_size(table):
    assert table.is_adaptive
    err = table.interpolation_error
    assert err is not None and err["points"] >= 2000
    assert err["outputs"]["beta_x"]["max"] <= 1e-4
    assert table.lookup(0.1, 0.3, psi=2.0)["error_bound"]["beta_x"] <= 1.5e-4
    assert TABLE.stat().st_size < 20e6
    build = table.meta("build")
    assert build["seconds"] > 0 and build["simulated"] > 0
    # what the spec makes today (re-run `vimpact table build` on the spec otherwise)
    assert table.meta("spec") == SPEC.read_text()


def test_gross_slip_is_the_closed_form(table):
    """At psi >= psi_s the contact slips throughout: beta_x = -1 + 2 chi (1 + e_z) / psi
    with the table's e_z (which friction does not change), at every psi up to 1e4."""
    from vimpact.lookup.friction import chi

    q1, nu = _points(table, 40, 1)
    onset = table.adaptive_grid().onset(q1, nu)
    for factor in (1.0, 1.001, 1.3, 3.0, 100.0, 1e4 / onset["psi_s"].max()):
        psi = factor * onset["psi_s"]
        out = table.lookup(q1, nu, psi=psi)
        closed = -1.0 + 2.0 * chi(nu, 0.4) * (1.0 + out["e_z"]) / psi
        np.testing.assert_allclose(out["beta_x"], closed, rtol=0, atol=1e-14)
        np.testing.assert_allclose(out["e_x"], np.abs(closed), rtol=0, atol=1e-14)
    # psi_s lies below psi_g (the closed form's zero) and above psi = 1 (first kink)
    assert np.all(onset["psi_s"] < onset["psi_g"]) and np.all(onset["psi_s"] > 1.0)


def test_no_overshoot_over_dense_psi_sweeps(table):
    """Over psi = 0 ... 2 psi_g (4000 points each) beta_x stays within its physical
    bounds: |beta_x| <= 1 and below the Coulomb bound -1 + psi_g / psi (|F_x| <= mu F_z,
    docs/physics.md#coulomb-friction) up to the table's stated error; and it is
    continuous at both kinks (psi = 1 and psi_s)."""
    q1, nu = _points(table, 12, 2)
    ends = table.info()["ranges"]
    q1 = np.concatenate([q1, ends["Q1"] * 2])
    nu = np.concatenate([nu, np.repeat(ends["nu"], 2)])
    bound = table.error_bound()["beta_x"]
    for a, b in zip(q1, nu):
        on = table.adaptive_grid().onset(a, b)
        psi = np.linspace(0.0, 2.0 * float(on["psi_g"]), 4000)
        beta = table.lookup(a, b, psi=psi)["beta_x"]
        assert np.all(np.isfinite(beta)) and np.all(np.abs(beta) <= 1.0)
        with np.errstate(divide="ignore"):
            coulomb = -1.0 + float(on["psi_g"]) / psi
        assert np.all(beta <= coulomb + bound), (a, b, np.max(beta - coulomb))
        for kink in (1.0, float(on["psi_s"])):
            near = table.lookup(a, b, psi=kink * np.array([1 - 1e-9, 1 + 1e-9]))["beta_x"]
            assert abs(near[1] - near[0]) < 1e-6, (a, b, kink, near)


@pytest.mark.slow
def test_lookup_meets_its_stated_error_at_fresh_points(table):
    """Points the build never used (another seed), simulated here with the table's
    numerics on the element path, psi across stick, microslip and gross slip: the
    lookup is within the table's stated bound (1.5 x its largest measured error)."""
    from vimpact.tablebuild.verify import numerics_of, simulate_dimensionless

    q1, nu = _points(table, 60, 12345)
    psi_s = table.adaptive_grid().onset(q1, nu)["psi_s"]
    psi = np.random.default_rng(6789).uniform(0.0, 1.25, q1.size) * psi_s
    sim = simulate_dimensionless("kelvin_voigt", q1, nu, psi=psi, mu=1.0,
                                 numerics=numerics_of(table))
    assert (sim["status"] == "ok").all()
    look = table.lookup(q1, nu, psi=psi)
    gap = np.abs(look["beta_x"] - sim["beta_x"].to_numpy())
    assert np.max(gap) <= table.error_bound()["beta_x"], (np.max(gap), q1[gap.argmax()],
                                                          nu[gap.argmax()], psi[gap.argmax()])


def test_shape_preserving_interpolant():
    """Hyman-limited cubic Hermite: exact for quadratics; monotone nodes give a
    monotone curve within the nodes' range (a cubic spline through a step swings past
    it); each segment between kinks is interpolated on its own."""
    from vimpact.kernels.adaptive_lookup import hyman_eval

    x = np.array([0.0, 0.1, 0.3, 0.35, 0.6, 1.0])
    kinks = np.array([0, 5], dtype=np.int64)
    q = 0.3 + 2.0 * x - 1.5 * x**2
    xs = np.linspace(0.0, 1.0, 501)
    got = np.array([hyman_eval(x, q, kinks, t) for t in xs])
    np.testing.assert_allclose(got, 0.3 + 2.0 * xs - 1.5 * xs**2, rtol=0, atol=1e-14)
    step = np.array([0.0, 0.0, 0.01, 0.99, 1.0, 1.0])
    got = np.array([hyman_eval(x, step, kinks, t) for t in xs])
    assert np.all(np.diff(got) >= -1e-15) and got.min() >= 0.0 and got.max() <= 1.0 + 1e-15
    # a kink at node 3: the line on each side is reproduced exactly
    v = np.where(x <= 0.35, x, 0.35 - 2.0 * (x - 0.35))
    got = np.array([hyman_eval(x, v, np.array([0, 3, 5], dtype=np.int64), t) for t in xs])
    np.testing.assert_allclose(got, np.where(xs <= 0.35, xs, 0.35 - 2.0 * (xs - 0.35)),
                               rtol=0, atol=1e-14)


@pytest.mark.parametrize("line, why", [
    ("psi_nodes = [11]", "two integers"),
    ("psi_nodes = [1, 48]", "integer >= 2"),
    ("psi_nodes = [31, 48]\npsi = 1.0", "no psi axis"),
])
def test_bad_psi_nodes_name_the_key(tmp_path, line, why):
    from vimpact.sweep import load_spec

    text = SPEC.read_text().replace("psi_nodes = [31, 48]", line)
    with pytest.raises(ValueError) as info:
        load_spec(write(tmp_path, text))
    assert "grid.psi_nodes" in str(info.value) and why in str(info.value)


SMALL = """
model = "kelvin_voigt"
output = "small.parquet"
[numerics]
preset = "fast"
[grid]
Q1 = { start = 0.05, stop = 0.2, num = 2 }
nu = [0.3, 0.4, 0.5]
tolerance = 2e-2
refine = "adaptive"
min_level = 0
max_level = 2
psi_nodes = [6, 8]
"""


@pytest.mark.slow
def test_small_build_is_reproduced_by_verify(tmp_path):
    """`table build` on a small friction spec: rows on the kinks (psi_s of every row at
    the last node is in gross slip: its beta_x is the closed form), and `table verify`
    with the build's points reproduces the stored error exactly."""
    from vimpact.cli.main import main
    from vimpact.lookup.table import RestitutionTable
    from vimpact.tablebuild.verify import interpolation_error

    spec = write(tmp_path, SMALL)
    assert main(["table", "build", str(spec), "--n", "40"]) == 0
    table = RestitutionTable.open(tmp_path / "small.parquet")
    stored = table.interpolation_error
    again = interpolation_error(table, n=40, seed=0)
    assert again["outputs"] == stored["outputs"]
    last = table.data[table.data["lattice_psi"] == table.data["lattice_psi"].max()]
    chi = (1 - last["nu"]) * 3.5 / (2 - last["nu"])
    np.testing.assert_allclose(last["beta_x"], -1 + 2 * chi * (1 + last["e_z"]) / last["psi"],
                               rtol=0, atol=1e-9)
    assert (table.data.loc[table.data["lattice_psi"] == 6 - 1, "psi"] == 1.0).all()
