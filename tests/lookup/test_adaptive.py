"""Adaptive tables: refinement, lookup kernel, Parquet round trip, and the real kernel.

The analytic checks compare with the function the table was refined on, at points the
refinement never used; the polynomial check with the exactness of cubic Lagrange
interpolation; the physics checks with direct simulation at random off-node points.
"""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from vimpact.lookup.adaptive import _TICKS, AdaptiveGrid, lattice_coordinates, refine_cells
from vimpact.lookup.table import RestitutionTable
from vimpact.model.validation import InputError

ROOT = Path(__file__).resolve().parents[2]
BOUNDS = np.array([[1e-3, 100.0], [1e-3, 100.0]])
NU = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])


def ridge(lq1, lq2, nu):
    """A smooth function with a narrow ridge across the log plane (like the standard
    solid's change of course) and a nu dependence of beta_x's kind."""
    lq1, lq2, nu = np.broadcast_arrays(lq1, lq2, nu)
    a = 0.3 * np.tanh((lq1 + 0.5 * lq2 - 1.0) / 0.25) + 0.5
    b = 0.1 * np.sin(lq1) * np.cos(0.7 * lq2) * (1.0 + nu**2)
    return np.stack([a, b], axis=-1)


def evaluate(keys):
    lx = np.log(lattice_coordinates(keys, BOUNDS))
    return ridge(lx[:, None, 0], lx[:, None, 1], NU[None, :])


def build(tol, **kw):
    leaves, keys, values, report = refine_cells(evaluate, 2, len(NU), tol, max_level=12, **kw)
    grid = AdaptiveGrid(["Q1", "Q2"], BOUNDS, leaves, keys, "nu", NU,
                        {"e_z": values[..., 0], "beta_x": values[..., 1]})
    return grid, report


@pytest.fixture(scope="module")
def analytic():
    return build(5e-6)


@pytest.fixture(scope="module")
def coarse():
    """The same function to 5e-4: 4,180 nodes on leaves of levels 3 to 6 (the 5e-6 tree:
    43,675 on levels 4 to 8)."""
    return build(5e-4)


def random_points(n, seed):
    rng = np.random.default_rng(seed)
    lb = np.log(BOUNDS)
    return (np.exp(rng.uniform(*lb[0], n)), np.exp(rng.uniform(*lb[1], n)),
            rng.uniform(0.0, 0.5, n))


def test_refinement_meets_its_tolerance_at_points_it_never_used(analytic):
    grid, report = analytic
    assert report["met"], report["stopped"]
    q1, q2, nu = random_points(200_000, seed=7)
    out = grid({"Q1": q1, "Q2": q2, "nu": nu})
    true = ridge(np.log(q1), np.log(q2), nu)
    # the cells are held to 5e-6 at their check points; between them and across nu
    # (cubic in nu on nodes 0.1 apart, b is quadratic in nu: exact) the error may grow
    # by the interpolant's peak-to-check ratio, well inside 2x
    assert np.max(np.abs(out["e_z"] - true[:, 0])) <= 1e-5
    assert np.max(np.abs(out["beta_x"] - true[:, 1])) <= 1e-5
    # and the refinement was local: far fewer cells than a uniform grid at the finest level
    levels = grid.leaves[:, 0]
    assert levels.max() > levels.min() + 2
    assert len(levels) < 4 ** int(levels.max()) / 10


def test_coarser_tolerance_gives_fewer_cells_and_larger_error(analytic, coarse):
    fine, _ = analytic
    coarse, report = coarse
    assert report["met"] and len(coarse.leaves) < len(fine.leaves)
    q1, q2, nu = random_points(50_000, seed=8)
    true = ridge(np.log(q1), np.log(q2), nu)[:, 0]
    e_fine = np.max(np.abs(fine({"Q1": q1, "Q2": q2, "nu": nu})["e_z"] - true))
    e_coarse = np.max(np.abs(coarse({"Q1": q1, "Q2": q2, "nu": nu})["e_z"] - true))
    assert e_coarse <= 1e-3 and e_fine < e_coarse / 10


@pytest.mark.parametrize("kw", [{}, {"max_nodes": 1000}], ids=["max_level", "max_nodes"])
def test_every_point_is_evaluated_once_and_kept_with_its_key(kw):
    """The refinement's bookkeeping: no lattice point goes to ``evaluate`` twice, the
    points of one call are distinct, and every returned value is ``evaluate``'s at the
    returned key (also where ``max_nodes`` stops the refinement)."""
    calls = []

    def counted(keys):
        calls.append(np.array(keys))
        return evaluate(keys)

    leaves, keys, values, report = refine_cells(counted, 2, len(NU), 1e-7, max_level=4, **kw)
    asked = np.concatenate(calls)
    assert len(np.unique(asked, axis=0)) == len(asked) == report["points"]
    assert np.array_equal(values, evaluate(keys))
    assert {tuple(key) for key in keys.tolist()} <= {tuple(key) for key in asked.tolist()}
    assert report["met"] is False and len(leaves) > 16


def test_lookup_reproduces_cubics_exactly():
    """Tensor-product cubic Lagrange per cell and cubic in nu: any polynomial of degree
    <= 3 in each of log Q1, log Q2 and nu is reproduced to round-off, on any tree."""
    def cubic(lq1, lq2, nu):
        lq1, lq2, nu = np.broadcast_arrays(lq1, lq2, nu)
        a = 0.01 * lq1**3 - 0.2 * lq1 * lq2**2 + 0.05 * lq2**3 + 1.0
        b = (0.02 * lq1**2 * lq2 + 0.3) * (1.0 - 2.0 * nu + 3.0 * nu**3)
        return np.stack([a, b], axis=-1)

    # an irregular tree: the root split, one quarter split twice more
    leaves = [[1, 1, 0], [1, 0, 1], [1, 1, 1]]
    leaves += [[2, i, j] for i in (0, 1) for j in (0, 1) if (i, j) != (0, 0)]
    leaves += [[3, i, j] for i in (0, 1) for j in (0, 1)]
    leaves = np.array(leaves)
    from vimpact.lookup.adaptive import _node_keys
    keys = np.unique(_node_keys(leaves[:, 0], leaves[:, 1:]).reshape(-1, 2), axis=0)
    lx = np.log(lattice_coordinates(keys, BOUNDS))
    nu_nodes = np.array([0.0, 0.1, 0.25, 0.3, 0.45, 0.5])
    v = cubic(lx[:, None, 0], lx[:, None, 1], nu_nodes[None, :])
    grid = AdaptiveGrid(["Q1", "Q2"], BOUNDS, leaves, keys, "nu", nu_nodes,
                        {"e_z": v[..., 0], "beta_x": v[..., 1]})
    q1, q2, nu = random_points(5000, seed=3)
    out = grid({"Q1": q1, "Q2": q2, "nu": nu})
    true = cubic(np.log(q1), np.log(q2), nu)
    assert np.max(np.abs(out["e_z"] - true[:, 0])) < 1e-11
    assert np.max(np.abs(out["beta_x"] - true[:, 1])) < 1e-11


def test_bad_inputs_are_refused(analytic):
    grid, _ = analytic
    with pytest.raises(InputError, match="Q1 = 200 is outside the table's range"):
        grid({"Q1": np.array([200.0]), "Q2": np.array([1.0]), "nu": np.array([0.3])})
    with pytest.raises(InputError, match="nu = 0.6 is outside"):
        grid({"Q1": np.array([1.0]), "Q2": np.array([1.0]), "nu": np.array([0.6])})
    with pytest.raises(InputError, match="tolerance"):
        refine_cells(evaluate, 2, len(NU), -1.0)
    with pytest.raises(InputError, match="overlaps"):
        AdaptiveGrid(["Q1"], BOUNDS[:1], [[1, 0], [1, 1], [2, 0]],
                     np.arange(0, _TICKS + 1, _TICKS // 12)[:, None], None, [0.0],
                     {"e_z": np.zeros((13, 1))})._kernel_arrays()


def _as_table(grid, report):
    cols = grid.rows()
    data = pd.DataFrame({"Q1": cols["Q1"], "Q2": cols["Q2"], "nu": cols["nu"],
                         "theta_ratio": 0.4, "e_z": cols["e_z"], "beta_x": cols["beta_x"],
                         "e_x": np.abs(cols["beta_x"]), "lattice_Q1": cols["lattice_Q1"],
                         "lattice_Q2": cols["lattice_Q2"], "status": "ok"})
    return RestitutionTable(data, {"model": "standard_solid", "mode": "adaptive",
                                   "adaptive": json.dumps(grid.to_metadata()),
                                   "grid_refinement": json.dumps(report)})


def test_parquet_round_trip(coarse, tmp_path):
    """Through a file and back, the lookups are bit for bit the grid's (on the coarser
    tree: the round trip does not depend on the number of cells, its file is a tenth)."""
    from vimpact.tableformat.integrity import verify_table

    grid, report = coarse
    table = _as_table(grid, report)
    path = table.save(tmp_path / "adaptive.parquet")
    verify_table(path)  # page checksums, content and metadata hashes written
    back = RestitutionTable.open(path)
    assert back.is_adaptive and back.info()["adaptive"]["leaves"] == len(grid.leaves)
    q1, q2, nu = random_points(20_000, seed=11)
    a = back.lookup(q1, nu, Q2=q2)
    b = grid({"Q1": q1, "Q2": q2, "nu": nu})
    np.testing.assert_array_equal(a["e_z"], b["e_z"])
    np.testing.assert_array_equal(a["beta_x"], b["beta_x"])
    np.testing.assert_array_equal(a["e_x"], np.abs(b["beta_x"]))
    # at a node the stored value comes back
    row = back.data.iloc[len(back.data) // 3]
    at = back.lookup(row["Q1"], row["nu"], Q2=row["Q2"])
    assert at["e_z"] == pytest.approx(row["e_z"], abs=1e-12)
    # extrapolation and linear lookups are refused, not silently cubic
    with pytest.raises(InputError, match="adaptive table"):
        back.lookup(1.0, 0.3, Q2=1.0, method="linear")


def test_damaged_structure_is_refused(coarse, tmp_path):
    grid, report = coarse
    table = _as_table(grid, report)
    table.data = table.data.iloc[16:].reset_index(drop=True)  # a leaf node's rows gone
    with pytest.raises(InputError):
        table.lookup(1.0, 0.3, Q2=1.0)


def test_info_of_a_damaged_adaptive_table_says_why(coarse):
    """The summary of a table whose cells cannot be rebuilt names the reason (with a
    recorded build too) instead of failing."""
    grid, report = coarse
    table = _as_table(grid, report)
    table.metadata["vimpact.build"] = json.dumps({"seconds": 1.0, "simulated": 10})
    table.data = table.data.iloc[16:].reset_index(drop=True)  # a leaf node's rows gone
    info = table.info()
    assert info["adaptive"] is None and "adaptive table" in info["grid_note"]
    assert "grid            none: adaptive table" in str(table)


def test_adaptive_spec_keys(tmp_path):
    from vimpact.sweep import load_spec, run_sweep

    body = ('model = "kelvin_voigt"\n[grid]\nQ1 = { start = 1e-3, stop = 100, num = 2 }\n'
            'nu = [0.0, 0.5]\nrefine = "adaptive"\n')
    (tmp_path / "a.toml").write_text(body)
    with pytest.raises(ValueError, match="grid.tolerance"):
        load_spec(tmp_path / "a.toml")
    (tmp_path / "b.toml").write_text(body + "tolerance = 1e-4\nmax_level = 40\n")
    with pytest.raises(ValueError, match="grid.max_level"):
        load_spec(tmp_path / "b.toml")
    (tmp_path / "c.toml").write_text(body.replace('refine = "adaptive"', 'refine = "quad"'))
    with pytest.raises(ValueError, match="grid.refine"):
        load_spec(tmp_path / "c.toml")
    (tmp_path / "d.toml").write_text(body + "tolerance = 1e-4\n")
    spec = load_spec(tmp_path / "d.toml")
    assert spec.grid_refine == "adaptive" and spec.grid_levels == (2, 16)
    with pytest.raises(ValueError, match="table build"):
        run_sweep(tmp_path / "d.toml", out=tmp_path / "d.parquet")


def test_kelvin_voigt_build_against_direct_simulation(tmp_path):
    """The real kernel: an adaptive Kelvin-Voigt table built to 1e-4, then looked up at
    random off-node points and compared with fresh direct simulations."""
    from vimpact.tablebuild.adaptive import build_adaptive
    from vimpact.tablebuild.verify import numerics_of, simulate_dimensionless

    spec = tmp_path / "kv.toml"
    spec.write_text('model = "kelvin_voigt"\noutput = "kv.parquet"\n[grid]\n'
                    'Q1 = { start = 1e-2, stop = 10, num = 2 }\n'
                    'nu = [0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.475, 0.5]\n'
                    'tolerance = 1e-4\nrefine = "adaptive"\nmin_level = 2\nmax_level = 8\n')
    table, path = build_adaptive(spec, n_verify=50)
    assert table.is_adaptive and table.meta("grid_refinement")["met"]
    stored = table.interpolation_error["outputs"]
    assert stored["e_z"]["max"] <= 1e-4 and stored["beta_x"]["max"] <= 1e-4
    rng = np.random.default_rng(2024)  # not the build's verification seed
    q1, nu = np.exp(rng.uniform(np.log(1e-2), np.log(10), 40)), rng.uniform(0, 0.5, 40)
    sim = simulate_dimensionless("kelvin_voigt", q1, nu, numerics=numerics_of(table))
    look = table.lookup(q1, nu)
    assert np.max(np.abs(look["e_z"] - sim["e_z"].to_numpy())) <= 1e-4
    assert np.max(np.abs(look["beta_x"] - sim["beta_x"].to_numpy())) <= 1e-4


def test_grid_only_views_are_refused_with_a_reason(coarse):
    grid, report = coarse
    table = _as_table(grid, report)
    with pytest.raises(InputError, match="adaptive table"):
        table.to_xarray()


@pytest.mark.slow
def test_standard_solid_refinement_on_a_ridge_meets_its_tolerance(tmp_path):
    """The real kernel where the standard solid changes course (Q2 = 0.01, Q1 near 4.4):
    a small adaptive table held to 1e-4 is within it at fresh random points."""
    from vimpact.tablebuild.adaptive import build_adaptive
    from vimpact.tablebuild.verify import numerics_of, simulate_dimensionless

    spec = tmp_path / "ss.toml"
    spec.write_text('model = "standard_solid"\noutput = "ss.parquet"\n[grid]\n'
                    'Q1 = { start = 3, stop = 6, num = 2 }\n'
                    'Q2 = { start = 0.008, stop = 0.012, num = 2 }\nnu = 0.5\n'
                    'tolerance = 1e-4\nrefine = "adaptive"\nmin_level = 1\nmax_level = 8\n')
    table, _ = build_adaptive(spec, n_verify=50)
    assert table.meta("grid_refinement")["met"]
    assert table.info()["adaptive"]["levels"][1] > 1  # it had to refine
    rng = np.random.default_rng(99)
    q1, q2 = np.exp(rng.uniform(np.log(3), np.log(6), 30)), np.exp(
        rng.uniform(np.log(0.008), np.log(0.012), 30))
    sim = simulate_dimensionless("standard_solid", q1, np.full(30, 0.5), q2,
                                 numerics=numerics_of(table))
    look = table.lookup(q1, 0.5, Q2=q2)
    for k in ("e_z", "beta_x"):
        assert np.max(np.abs(look[k] - sim[k].to_numpy())) <= 1e-4
