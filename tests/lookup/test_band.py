"""A standard-solid lookup below the main table's Q2: the band table, then the
Kelvin-Voigt limit (vimpact.lookup.band).

The routing checks use tables refined on a known function that reaches the shipped
Kelvin-Voigt table linearly in Q2 (the measured form of the limit, docs/physics.md
#standard-solid-limits), and compare with that function at points no refinement
used; the physics check compares the standard solid with the Kelvin-Voigt solid by
direct simulation as Q2 -> 0.
"""

import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from vimpact.lookup.adaptive import AdaptiveGrid, lattice_coordinates, refine_cells
from vimpact.lookup.band import BAND_FILE, BAND_SPEC, KELVIN_VOIGT_FILE
from vimpact.lookup.table import RestitutionTable
from vimpact.model.validation import InputError

ROOT = Path(__file__).resolve().parents[2]
KV_TABLE = ROOT / "sweeps" / "tables" / KELVIN_VOIGT_FILE
NU = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])
Q1_RANGE = (0.01, 10.0)
TOL = 1e-5  # the cells' check tolerance
SLOPE = 0.1  # d e / d Q2 at the Kelvin-Voigt limit (the measured ones are below 0.17)


@pytest.fixture(scope="module")
def kelvin_voigt():
    return RestitutionTable.open(KV_TABLE)


def truth(kv, q1, q2, nu):
    """Kelvin-Voigt values plus a term linear in Q2 (smooth in Q1, nu)."""
    q1, q2, nu = np.broadcast_arrays(q1, q2, nu)
    base = kv.lookup(q1, nu)
    return {"e_z": base["e_z"] + SLOPE * q2 / (1.0 + q1),
            "beta_x": base["beta_x"] + SLOPE * q2 * np.cos(np.log(q1)) * (1.0 + nu)}


def _table(kv, q2_range, bound, extra=None):
    bounds = np.array([Q1_RANGE, q2_range])

    def evaluate(keys):
        xy = lattice_coordinates(keys, bounds)
        t = truth(kv, xy[:, None, 0], xy[:, None, 1], NU[None, :])
        return np.stack([t["e_z"], t["beta_x"]], axis=-1)

    leaves, keys, values, report = refine_cells(evaluate, 2, len(NU), TOL, min_level=2,
                                                max_level=9)
    assert report["met"]
    grid = AdaptiveGrid(["Q1", "Q2"], bounds, leaves, keys, "nu", NU,
                        {"e_z": values[..., 0], "beta_x": values[..., 1]})
    cols = grid.rows()
    data = pd.DataFrame({"Q1": cols["Q1"], "Q2": cols["Q2"], "nu": cols["nu"],
                         "theta_ratio": 0.4, "e_z": cols["e_z"], "beta_x": cols["beta_x"],
                         "e_x": np.abs(cols["beta_x"]), "lattice_Q1": cols["lattice_Q1"],
                         "lattice_Q2": cols["lattice_Q2"], "status": "ok"})
    err = {"method": "cubic", "points": 1,
           "outputs": {k: {"max": bound / 1.5, "bound": bound} for k in ("e_z", "beta_x", "e_x")}}
    meta = {"model": "standard_solid", "mode": "adaptive",
            "adaptive": json.dumps(grid.to_metadata()), "grid_refinement": json.dumps(report),
            "interpolation_error": json.dumps(err), **(extra or {})}
    return RestitutionTable(data, meta)


GAP = 1.5 * SLOPE * 1e-5  # what the band records as its distance to the limit


@pytest.fixture(scope="module")
def tables(kelvin_voigt):
    main = _table(kelvin_voigt, (1e-3, 1e-2), 2e-5)
    limit = {"Q2": 1e-5, "points": 1, "seed": 0,
             "gap": {k: GAP for k in ("e_z", "beta_x", "e_x")}}
    band = _table(kelvin_voigt, (1e-5, 1e-3), 3e-5,
                  {"kelvin_voigt_limit": json.dumps(limit)})
    return main, band


@pytest.fixture
def folder(tables, tmp_path):
    main, band = tables
    main.save(tmp_path / "standard_solid_table.parquet")
    band.save(tmp_path / BAND_FILE)
    shutil.copy(KV_TABLE, tmp_path / KELVIN_VOIGT_FILE)
    return tmp_path


def test_below_the_range_the_band_and_then_the_limit_answer(folder, kelvin_voigt):
    main = RestitutionTable.open(folder / "standard_solid_table.parquet")
    rng = np.random.default_rng(5)
    n = 3000
    q1 = np.exp(rng.uniform(*np.log(Q1_RANGE), n))
    q2 = np.exp(rng.uniform(np.log(1e-8), np.log(1e-2), n))
    nu = rng.choice(NU, n)  # nodes: the nu interpolation of both kinds of table is exact
    out = main.lookup(q1, nu, Q2=q2)
    true = truth(kelvin_voigt, q1, q2, nu)
    for k in ("e_z", "beta_x"):
        err = np.abs(out[k] - true[k])
        # cells and nu interpolation: within twice the check tolerance; below the band,
        # the Kelvin-Voigt table itself, off the truth by the linear term only
        assert err[q2 >= 1e-5].max() <= 2 * TOL, k
        below = q2 < 1e-5
        assert below.sum() > 100
        np.testing.assert_array_equal(out[k][below], kelvin_voigt.lookup(q1[below],
                                                                         nu[below])[k])
        assert err[below].max() <= SLOPE * 1e-5 * 2.0
    np.testing.assert_array_equal(out["e_x"], np.abs(out["beta_x"]))
    # the bound is the largest of the tables used: the band's (3e-5) over the main's
    # (2e-5); the Kelvin-Voigt table's plus the band's recorded distance to the limit
    kv_bound = kelvin_voigt.error_bound()
    assert out["error_bound"]["e_z"] == pytest.approx(max(3e-5, kv_bound["e_z"] + GAP))
    above = main.lookup(q1[:5], nu[:5], Q2=np.full(5, 5e-3))
    assert above["error_bound"]["e_z"] == pytest.approx(2e-5)  # the main table's alone


def test_extrapolation_and_linear_stay_refused_below_the_range(folder):
    main = RestitutionTable.open(folder / "standard_solid_table.parquet")
    for kw in ({"extrapolate": True}, {"method": "linear"}):
        with pytest.raises(InputError, match="adaptive table"):
            main.lookup(1.0, 0.3, Q2=1e-7, **kw)


def test_the_seams_are_continuous(folder):
    main = RestitutionTable.open(folder / "standard_solid_table.parquet")
    q1 = np.geomspace(Q1_RANGE[0], Q1_RANGE[1] / 1.02, 200) * 1.01
    nu = np.resize(NU, 200)
    for seam, jump in ((1e-3, 2 * TOL), (1e-5, 2 * TOL + SLOPE * 1e-5)):
        up = main.lookup(q1, nu, Q2=np.full(200, seam * (1 + 1e-7)))
        down = main.lookup(q1, nu, Q2=np.full(200, seam * (1 - 1e-7)))
        for k in ("e_z", "beta_x"):
            assert np.max(np.abs(up[k] - down[k])) <= jump, (seam, k)


def test_a_scalar_below_the_range_gives_floats(folder):
    main = RestitutionTable.open(folder / "standard_solid_table.parquet")
    out = main.lookup(1.0, 0.3, Q2=1e-4)
    assert isinstance(out["e_z"], float) and 0.0 < out["e_z"] < 1.0


def test_without_the_band_the_refusal_names_its_spec(tables, tmp_path):
    main, _ = tables
    path = main.save(tmp_path / "standard_solid_table.parquet")
    table = RestitutionTable.open(path)
    with pytest.raises(InputError, match="Q2 = 0.0001 is outside") as exc:
        table.lookup(1.0, 0.3, Q2=1e-4)
    assert BAND_SPEC in str(exc.value) and BAND_FILE in str(exc.value)
    assert table.lookup(1.0, 0.3, Q2=1e-3)["e_z"] > 0.0  # its own range still answers


def test_a_band_that_does_not_meet_the_table_is_not_used(tables, kelvin_voigt, tmp_path):
    main, _ = tables
    main.save(tmp_path / "standard_solid_table.parquet")
    _table(kelvin_voigt, (1e-5, 5e-4), 3e-5).save(tmp_path / BAND_FILE)  # a gap below 1e-3
    table = RestitutionTable.open(tmp_path / "standard_solid_table.parquet")
    with pytest.raises(InputError, match="build it with"):
        table.lookup(1.0, 0.3, Q2=1e-4)


def test_a_band_without_the_kelvin_voigt_table_refuses_below_it(tables, tmp_path):
    _, band = tables
    table = RestitutionTable.open(band.save(tmp_path / BAND_FILE))
    assert table.lookup(1.0, 0.3, Q2=1e-4)["e_z"] > 0.0
    with pytest.raises(InputError, match=KELVIN_VOIGT_FILE):
        table.lookup(1.0, 0.3, Q2=1e-6)


def test_cli_answers_below_the_range_and_refuses_without_the_band(folder, tables, tmp_path,
                                                                   capsys):
    from vimpact.cli.main import main

    path = str(folder / "standard_solid_table.parquet")
    assert main(["table", "lookup", path, "--Q1", "1", "--Q2", "1e-4,1e-7",
                 "--nu", "0.3", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [r["Q2"] for r in rows] == [1e-4, 1e-7] and all(0 < r["e_z"] < 1 for r in rows)
    alone = tmp_path / "alone"
    alone.mkdir()
    tables[0].save(alone / "standard_solid_table.parquet")
    assert main(["table", "lookup", str(alone / "standard_solid_table.parquet"),
                 "--Q1", "1", "--Q2", "1e-4", "--nu", "0.3"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and BAND_SPEC in err[0]


def test_the_limit_measurement(tables):
    """kelvin_voigt_limit takes the largest difference of the two rheologies at the
    band's lowest Q2, times the bound factor; a failed impact is refused."""
    from vimpact.tablebuild.band import kelvin_voigt_limit
    from vimpact.tablebuild.verify import BOUND_FACTOR

    _, band = tables
    band.metadata["vimpact.numerics"] = json.dumps({"continuum": True})
    seen = {}

    def fake(model, Q1, nu, Q2=None, numerics=None, status="ok"):
        if model == "standard_solid":
            seen["Q2"] = np.unique(Q2)
        shift = np.zeros(len(Q1)) if Q2 is None else 3e-6 * Q1 / Q1.max()
        return pd.DataFrame({"e_z": 0.5 + shift, "beta_x": 0.1 - 2 * shift,
                             "e_x": np.abs(0.1 - 2 * shift), "status": status})

    result = kelvin_voigt_limit(band, n=50, seed=1, simulate=fake)
    assert seen["Q2"].tolist() == [pytest.approx(1e-5)]
    assert result["max"]["e_z"] == pytest.approx(3e-6)
    assert result["gap"]["beta_x"] == pytest.approx(BOUND_FACTOR * 6e-6)

    def failing(*args, **kw):
        return fake(*args, **kw, status="failed")

    with pytest.raises(InputError, match="failed"):
        kelvin_voigt_limit(band, n=5, simulate=failing)


@pytest.mark.slow
def test_standard_solid_reaches_kelvin_voigt_linearly_in_Q2():
    """Past the ridge the standard solid's distance to the Kelvin-Voigt impact shrinks
    in proportion to Q2 (the limit G2 -> inf), by direct simulation of both."""
    from vimpact.tablebuild.verify import simulate_dimensionless

    q1 = np.array([0.1, 1.0, 10.0])
    nu = np.full(3, 0.3)
    kv = simulate_dimensionless("kelvin_voigt", q1, nu)
    d = {}
    for q2 in (1e-4, 1e-5):
        ss = simulate_dimensionless("standard_solid", q1, nu, np.full(3, q2))
        d[q2] = ss["e_z"].to_numpy() - kv["e_z"].to_numpy()
    # the largest slope measured over Q1 = 1e-3 ... 100 is 0.167 (at Q1 near 1)
    assert np.all(np.abs(d[1e-4]) <= 0.2 * 1e-4)
    ratio = d[1e-4] / d[1e-5]
    assert np.all((ratio > 8.0) & (ratio < 12.0)), ratio


def test_a_band_that_has_not_measured_the_limit_says_how(kelvin_voigt, tmp_path):
    band = _table(kelvin_voigt, (1e-5, 1e-3), 3e-5)  # reaches the limit, no measurement
    shutil.copy(KV_TABLE, tmp_path / KELVIN_VOIGT_FILE)
    table = RestitutionTable.open(band.save(tmp_path / BAND_FILE))
    with pytest.raises(InputError, match="records its distance to that limit"):
        table.lookup(1.0, 0.3, Q2=1e-6)


def test_the_build_records_the_limit_of_a_table_that_reaches_it(tmp_path):
    """`table build` of a standard solid reaching Q2 = 1e-5 measures its distance to the
    Kelvin-Voigt limit (here of an analytic stand-in for the simulation, linear in Q2)."""
    from vimpact.tablebuild.adaptive import build_adaptive

    def fake(model, Q1, nu, Q2=None, **kw):
        q2 = np.zeros(len(Q1)) if Q2 is None else np.asarray(Q2)
        e_z = 0.9 / (1.0 + np.asarray(Q1)) + 0.1 * q2
        beta_x = 0.2 * np.log(Q1) * (1 + np.asarray(nu)) / 10 - 0.05 * q2
        return pd.DataFrame({"e_z": e_z, "beta_x": beta_x, "e_x": np.abs(beta_x),
                             "status": "ok"})

    spec = tmp_path / "band.toml"
    spec.write_text('model = "standard_solid"\noutput = "band.parquet"\n[grid]\n'
                    'Q1 = { start = 0.1, stop = 1, num = 2 }\n'
                    'Q2 = { start = 1e-5, stop = 1e-3, num = 2 }\nnu = [0.0, 0.5]\n'
                    'tolerance = 1e-3\nrefine = "adaptive"\nmin_level = 1\nmax_level = 4\n')
    table, _ = build_adaptive(spec, n_verify=5, simulate=fake)
    limit = table.meta("kelvin_voigt_limit")
    assert limit["Q2"] == pytest.approx(1e-5)
    assert limit["max"]["e_z"] == pytest.approx(1e-6) and limit["max"]["beta_x"] == \
        pytest.approx(5e-7)


def test_the_band_spec_tolerance_is_far_inside_the_table_tolerance():
    """The band is built at a looser rtol than the main table (its stiff-arm impacts are
    expensive); at random points of the band (not those its spec quotes) that is within
    a tenth of the band's tolerance of the same impacts at rtol 1e-11 (a convergence
    check of the kernel)."""
    from vimpact.model.numerics import Numerics
    from vimpact.sweep import load_spec
    from vimpact.tablebuild.verify import simulate_dimensionless

    spec = load_spec(ROOT / BAND_SPEC)
    rng = np.random.default_rng(2026)
    n = 16
    q1, nu, q2 = 10 ** rng.uniform(-3, 2, n), rng.uniform(0, 0.5, n), 10 ** rng.uniform(-5, -3, n)
    band = simulate_dimensionless("standard_solid", q1, nu, q2, numerics=spec.numerics)
    tight = simulate_dimensionless("standard_solid", q1, nu, q2,
                                   numerics=Numerics(rtol=1e-11))
    assert set(band["status"]) == {"ok"} == set(tight["status"])
    for k in ("e_z", "beta_x"):
        gap = np.max(np.abs(band[k].to_numpy() - tight[k].to_numpy()))
        assert gap <= 0.1 * spec.grid_tolerance, (k, gap)
