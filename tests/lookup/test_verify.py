"""Measured interpolation error, grid refinement, Kelvin-Voigt rows, limits.

Real (small) tables on the continuum path: every number is compared with a
direct simulation the lookup did not see, or with a physical limit.
"""

import json

import numpy as np
import pandas as pd
import pytest

from vimpact.lookup.table import RestitutionTable
from vimpact.model.numerics import Numerics
from vimpact.model.validation import InputError
from vimpact.tablebuild.refine import grid_table, refine_grid
from vimpact.tablebuild.verify import (
    held_out_errors,
    held_out_points,
    interpolation_error,
    simulate_dimensionless,
    write_interpolation_error,
)

NUM = Numerics()  # continuum path, rtol 1e-8
Q1_NODES = np.geomspace(0.01, 10.0, 10)  # 3.3 per decade
NU_NODES = np.array([0.0, 0.25, 0.4, 0.5])


@pytest.fixture(scope="module")
def kv():
    """A 10 x 4 Kelvin-Voigt grid table (40 nodes), simulated directly."""
    return grid_table("kelvin_voigt", {"Q1": Q1_NODES, "nu": NU_NODES}, NUM)


def test_held_out_points_are_between_the_nodes():
    pts = held_out_points(["Q1", "nu"], [Q1_NODES, NU_NODES], n_random=50, seed=1)
    assert (pts["kind"] == "axis").sum() == 9 * 4 + 10 * 3
    assert (pts["kind"] == "centre").sum() == 9 * 3
    on_q1 = np.isclose(pts["Q1"].to_numpy()[:, None], Q1_NODES[None, :], rtol=1e-12).any(1)
    on_nu = np.isclose(pts["nu"].to_numpy()[:, None], NU_NODES[None, :], atol=1e-12).any(1)
    assert not np.any(on_q1 & on_nu)  # never a node


def test_stored_bound_holds_on_fresh_random_points(kv, tmp_path):
    result = interpolation_error(kv, n=100, seed=0)
    assert result["failed"] == 0 and result["points"] == 66 + 27 + 100
    # the table's nodes agree with a fresh simulation to the solver's accuracy
    assert max(result["node_error"].values()) < 1e-6
    path = write_interpolation_error(kv, result, tmp_path / "kv.parquet")
    table = RestitutionTable.open(path)
    bound = table.lookup(0.3, 0.3)["error_bound"]
    assert bound == {k: 1.5 * v["max"] for k, v in result["outputs"].items()}
    assert "interpolation   cubic: max error e_z" in str(table)
    fresh = held_out_errors(table, n=300, seed=12345, kinds=("random",))
    for name in ("e_z", "beta_x", "e_x"):
        assert fresh[f"{name}_err"].max() <= bound[name], name
    # a linear lookup has no stored bound (it was measured for cubic)
    assert table.lookup(0.3, 0.3, method="linear")["error_bound"] is None


def test_cubic_is_more_accurate_than_linear_between_nodes(kv):
    cubic = interpolation_error(kv, n=0, node_sample=0)["outputs"]
    linear = interpolation_error(kv, n=0, node_sample=0, method="linear")["outputs"]
    for name in ("e_z", "beta_x"):
        assert cubic[name]["max"] < 0.2 * linear[name]["max"], name


def test_refine_grid_meets_its_tolerance_and_says_where():
    tol = 1e-4
    axes, report = refine_grid("kelvin_voigt", {"Q1": [0.01, 0.1, 1.0], "nu": [0.0, 0.5]},
                               tol, NUM, n_random=100)
    assert report["met"] and report["stopped"] == "met"
    assert set(axes["Q1"]) >= {0.01, 0.1, 1.0} and len(axes["nu"]) > 2
    first = report["rounds"][0]
    assert first["inserted"] and all(c["max_error"] > tol for v in first["inserted"].values()
                                     for c in v)
    # an independent check on points refine never saw
    table = grid_table("kelvin_voigt", axes, NUM)
    fresh = held_out_errors(table, n=200, seed=7, kinds=("random",))
    assert fresh["e_z_err"].max() <= tol and fresh["beta_x_err"].max() <= tol
    json.dumps(report)  # storable as metadata
    with pytest.raises(InputError, match="tolerance = 0"):
        refine_grid("kelvin_voigt", {"Q1": [0.1, 1.0], "nu": [0.0, 0.5]}, 0.0)
    with pytest.raises(InputError, match="axes"):
        refine_grid("standard_solid", {"Q1": [0.1, 1.0], "nu": [0.0, 0.5]}, 1e-3)


def test_old_tables_with_q2_zero_still_read(kv, tmp_path):
    old = kv.data.drop(columns="model").assign(Q2=0.0)  # how tables used to mark Kelvin-Voigt
    table = RestitutionTable(old, {"model": "kelvin_voigt"})
    assert table.data["Q2"].isna().all() and (table.data["model"] == "kelvin_voigt").all()
    assert table.lookup(0.3, 0.3)["e_z"] == kv.lookup(0.3, 0.3)["e_z"]
    path = table.save(tmp_path / "old.parquet")
    back = RestitutionTable.open(path)
    assert back.model == "kelvin_voigt" and back.data["Q2"].isna().all()
    # without metadata, Q2 = 0 everywhere is still Kelvin-Voigt
    assert RestitutionTable(old).model == "kelvin_voigt"


def test_merged_tables_keep_kelvin_voigt_rows_apart(kv):
    ss = grid_table("standard_solid", {"Q1": Q1_NODES[:3], "Q2": [0.1, 1.0], "nu": [0.0, 0.5]},
                    NUM)
    merged = pd.concat([ss.data.drop(columns="model"),
                        kv.data.drop(columns="model").assign(Q2=0.0)], ignore_index=True)
    table = RestitutionTable(merged, {"model": "standard_solid"})
    kv_rows = table.data["model"] == "kelvin_voigt"
    assert kv_rows.sum() == len(kv.data) and table.data.loc[kv_rows, "Q2"].isna().all()
    # the standard-solid grid is the standard-solid rows; no log 0 on its Q2 axis
    assert table.info()["grid"] == {"Q1": 3, "Q2": 2, "nu": 2}
    assert np.isfinite(table.lookup(0.02, 0.2, Q2=0.3)["e_z"])


@pytest.fixture(scope="module")
def limits():
    """Standard-solid table over Q2 = 1e-2 ... 1e4 and the Kelvin-Voigt and elastic impacts
    (Q1 >= 0.3: every impact on the continuum path, errors ~1e-8)."""
    q1, nu = np.geomspace(0.3, 3.0, 4), np.array([0.0, 0.25, 0.5])
    q2 = np.geomspace(1e-2, 1e4, 13)
    ss = grid_table("standard_solid", {"Q1": q1, "Q2": q2, "nu": nu}, NUM)
    kv = grid_table("kelvin_voigt", {"Q1": q1, "nu": nu}, NUM)
    elastic = simulate_dimensionless("kelvin_voigt", [0.0], [0.25], numerics=NUM)
    return ss, kv, elastic, q1, q2


def test_standard_solid_tends_to_kelvin_voigt_as_q2_falls(limits):
    """Q2 = G1/G2 -> 0 is G2 -> inf: the Kelvin-Voigt solid with the same Q1. Looked up
    at the table's smallest Q2 values (Q1 between nodes): the gap to the Kelvin-Voigt
    lookup shrinks with Q2, about in proportion (a first-order correction). At a Q1
    node: between the Q1 nodes both tables' own interpolation errors (~1e-3 at this
    coarse spacing) would hide a gap of that size."""
    ss, kv, _, q1, q2 = limits
    q = q1[1]
    small = q2[:4]  # 1e-2 ... 1e-1
    s = ss.lookup(q, 0.25, Q2=small)
    k = kv.lookup(q, 0.25)
    gap = np.abs(s["e_z"] - k["e_z"])
    assert np.all(np.diff(gap) > 0), gap
    ratio = gap / small
    assert ratio.max() < 3 * ratio.min(), ratio


def test_standard_solid_tends_to_elastic_as_q2_grows(limits):
    """Q2 -> inf is G2 -> 0: the elastic impact (e_z -> 1); the gap falls like 1/Q2."""
    ss, _, elastic, q1, q2 = limits
    large = q2[-5:]  # 1e2 ... 1e4
    s = ss.lookup(np.sqrt(q1[1] * q1[2]), 0.25, Q2=large)
    assert elastic["e_z"].iloc[0] == pytest.approx(1.0, abs=1e-7)
    for name in ("e_z", "beta_x"):
        gap = np.abs(s[name] - elastic[name].iloc[0])
        assert np.all(np.diff(gap) < 0), (name, gap)
        assert gap[-1] < gap[0] / 30, (name, gap)


def test_to_xarray_labels_axes_or_says_it_is_missing(kv):
    try:
        import xarray  # noqa: F401
    except ImportError:
        with pytest.raises(InputError, match="xarray is not installed"):
            kv.to_xarray()
        return
    ds = kv.to_xarray()
    assert list(ds["e_z"].dims) == ["Q1", "nu"]
    assert ds["e_z"].attrs["units"] == "1"
    np.testing.assert_allclose(ds["Q1"].values, Q1_NODES, rtol=1e-12)
    row = kv.data.iloc[7]
    assert float(ds["beta_x"].sel(Q1=row.Q1, nu=row.nu)) == row.beta_x


def test_cli_verify_writes_the_bound_that_info_and_lookup_report(kv, tmp_path, capsys):
    from vimpact.cli.main import main

    fresh = {k: v for k, v in kv.metadata.items() if not k.endswith("interpolation_error")}
    path = str(RestitutionTable(kv.data, fresh).save(tmp_path / "kv.parquet"))
    assert main(["table", "verify", path, "--n", "20", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    assert RestitutionTable.open(path).interpolation_error is None  # not written without --write
    assert main(["table", "verify", path, "--n", "20", "--write"]) == 0
    assert "stored as vimpact.interpolation_error" in capsys.readouterr().out
    assert RestitutionTable.open(path).interpolation_error["outputs"] == first["outputs"]
    assert main(["table", "info", path]) == 0
    assert "interpolation   cubic: max error e_z" in capsys.readouterr().out
    assert main(["table", "lookup", path, "--Q1", "0.3", "--nu", "0.3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["error_bound"]["e_z"] == pytest.approx(1.5 * first["outputs"]["e_z"]["max"])
    assert main(["table", "lookup", path, "--Q1", "0.3", "--nu", "0.3", "--method", "linear"]) == 0
    assert "not measured for linear" in capsys.readouterr().out


def test_held_out_points_of_a_psi_table_are_the_sweeps_friction_scenes(tmp_path):
    """table verify on a psi grid simulates the sweep's scene at each held-out psi
    (friction coefficient mu, v_x0 from psi): in gross slip throughout (psi > 4 chi)
    its beta_x is the impulse balance of docs/physics.md#coulomb-friction,
    beta_x = -1 + 2 chi (1 + e_z) / psi, which the code does not use."""
    from vimpact.sweep import run_sweep

    spec = tmp_path / "psi.toml"
    spec.write_text('model = "kelvin_voigt"\nchunk_size = 8\n[numerics]\npreset = "fast"\n'
                    '[grid]\nQ1 = 0.1\nnu = [0.3, 0.5]\npsi = [10.0, 14.0, 20.0]\nmu = 0.3\n')
    table = RestitutionTable.open(run_sweep(spec, progress=False))
    err = held_out_errors(table, n=6, seed=3)
    assert len(err) and (err["status"] == "ok").all() and err["psi"].min() >= 10.0
    nu = err["nu"].to_numpy()
    chi = (1 - nu) * (1 + 1 / 0.4) / (2 - nu)
    expected = -1 + 2 * chi * (1 + err["e_z_sim"].to_numpy()) / err["psi"].to_numpy()
    np.testing.assert_allclose(err["beta_x_sim"].to_numpy(), expected, rtol=0, atol=1e-9)
    # the lookup between these nodes follows 1/psi closely (smooth in gross slip)
    assert err["beta_x_err"].max() < 1e-2
