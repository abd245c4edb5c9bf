"""Restitution tables: reading, metadata, grid lookup, e(v) curves and the `table` CLI.

The tables are made here with ``simulate_batch`` on ``Scene.from_dimensionless``
grids (tiny numerics) and written with pyarrow in the sweep driver's format
(:func:`make_table`), so the lookup is checked against simulations it did not
produce: its own grid rows, direct ``simulate`` calls at the same Q1, and
properties of interpolation (monotone, linear in log Q1 and nu).
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import vimpact
from vimpact import Material, Numerics, Scene, cli, simulate, simulate_batch
from vimpact.lookup.table import RestitutionTable
from vimpact.model.validation import InputError

NUM = Numerics(steps=100, elements=20)
Q1_GRID = np.logspace(-2, 1, 7)  # 0.01 .. 10, half a decade apart
NU_GRID = (0.0, 0.25, 0.5)
Q2_GRID = (0.1, 1.0, 10.0)
COLUMNS = ["Q1", "Q2", "nu", "theta_ratio", "e_z", "e_x", "beta_x", "t_contact_s", "u_max_m",
           "a_max_m", "energy_ratio", "status"]
UNITS = {"Q1": "1", "Q2": "1", "nu": "1", "theta_ratio": "1", "e_z": "1", "e_x": "1",
         "beta_x": "1", "t_contact_s": "s", "u_max_m": "m", "a_max_m": "m",
         "energy_ratio": "1", "status": "", "psi": "1", "mu": "1"}


def results_frame(scenes, numerics=NUM) -> pd.DataFrame:
    """``simulate_batch`` rows in the table's column names."""
    df = simulate_batch(scenes, numerics).rename(
        columns={"t_contact": "t_contact_s", "u_max": "u_max_m", "a_max": "a_max_m"})
    df["theta_ratio"] = [s.theta_ratio for s in scenes]
    return df[COLUMNS]


def write_table(path, df: pd.DataFrame, model: str, numerics=NUM, spec="tests") -> dict:
    """Write ``df`` as a restitution table (Parquet + vimpact metadata); return the metadata."""
    meta = {
        b"vimpact.model": model.encode(),
        b"vimpact.units": json.dumps(UNITS).encode(),
        b"vimpact.numerics": json.dumps(dataclasses.asdict(numerics)).encode(),
        b"vimpact.schema_version": b"1",
        b"vimpact.version": vimpact.__version__.encode(),
        b"vimpact.spec": spec.encode(),
    }
    arrow = pa.Table.from_pandas(df, preserve_index=False)
    pq.write_table(arrow.replace_schema_metadata({**(arrow.schema.metadata or {}), **meta}), path)
    return meta


def make_table(path, Q1=Q1_GRID, nu=NU_GRID, Q2=None, fail=(), numerics=NUM):
    """A grid table over ``Q1`` x [``Q2``] x ``nu`` at ``path``; rows ``fail``
    get a failure status and NaN outputs. Returns the metadata written."""
    scenes = [Scene.from_dimensionless(q1, n, q2)
              for q1 in Q1 for q2 in (Q2 if Q2 is not None else [None]) for n in nu]
    df = results_frame(scenes, numerics)
    for i in fail:
        df.loc[i, ["e_z", "e_x", "beta_x", "t_contact_s", "u_max_m", "a_max_m",
                   "energy_ratio"]] = np.nan
        df.loc[i, "status"] = "time_limit"
    return write_table(path, df, "kelvin_voigt" if Q2 is None else "standard_solid", numerics)


@pytest.fixture(scope="module")
def kv_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("tables") / "kv.parquet"
    make_table(path)
    return path


@pytest.fixture(scope="module")
def ss_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("tables") / "ss.parquet"
    make_table(path, Q1=Q1_GRID[::2], nu=(0.0, 0.5), Q2=Q2_GRID)
    return path


@pytest.fixture(scope="module")
def kv(kv_path):
    return RestitutionTable.open(kv_path)


# --------------------------------------------------------------------------
# reading and metadata
# --------------------------------------------------------------------------

def test_metadata_round_trips(tmp_path):
    path = tmp_path / "t.parquet"
    meta = make_table(path, Q1=Q1_GRID[:3], nu=(0.5,))
    table = RestitutionTable.open(path)
    assert table.metadata == {k.decode(): v.decode() for k, v in meta.items()}
    assert table.model == "kelvin_voigt"
    assert table.numerics == dataclasses.asdict(NUM)
    assert table.units["t_contact_s"] == "s"
    assert table.version == vimpact.__version__
    # constructor from a DataFrame + metadata, saved and read back: same rows and metadata
    again = RestitutionTable(table.data, {"model": "kelvin_voigt", "numerics": {"steps": 100},
                                          b"vimpact.spec": b"by hand"})
    again.save(tmp_path / "again.parquet")
    back = RestitutionTable.open(tmp_path / "again.parquet")
    hashes = {k for k in back.metadata if k.endswith("_sha256")}  # written fresh by save
    assert hashes == {"vimpact.content_sha256", "vimpact.metadata_sha256"}
    assert {k: v for k, v in back.metadata.items() if k not in hashes} == {"vimpact.model": "kelvin_voigt",
                             "vimpact.numerics": '{"steps": 100}', "vimpact.spec": "by hand"}
    pd.testing.assert_frame_equal(back.data, table.data)


def test_info_counts_statuses_ranges_and_grid(tmp_path):
    path = tmp_path / "t.parquet"
    make_table(path, fail=(4,))
    info = RestitutionTable.open(path).info()
    assert info["model"] == "kelvin_voigt"
    assert info["rows"] == 21 and info["ok_rows"] == 20
    assert info["statuses"] == {"ok": 20, "time_limit": 1}
    assert info["ranges"]["Q1"] == pytest.approx([0.01, 10.0], rel=1e-9)
    assert info["ranges"]["nu"] == [0.0, 0.5]
    assert "Q2" not in info["ranges"]
    assert info["grid"] == {"Q1": 7, "nu": 3} and info["failed_grid_points"] == 1
    assert info["numerics"]["steps"] == 100 and info["version"] == vimpact.__version__
    json.dumps(info)  # serializable
    text = str(RestitutionTable.open(path))
    for word in ("kelvin_voigt", "21 (20 ok)", "time_limit 1", "7 Q1 x 3 nu", "steps=100"):
        assert word in text


def test_model_inferred_without_metadata(kv, ss_path):
    assert RestitutionTable(kv.data).model == "kelvin_voigt"  # Q2 NaN
    assert RestitutionTable(kv.data.assign(Q2=0.0)).model == "kelvin_voigt"  # G2 -> inf limit
    assert RestitutionTable(RestitutionTable.open(ss_path).data).model == "standard_solid"


def test_missing_file_and_columns_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        RestitutionTable.open(tmp_path / "nope.parquet")
    (tmp_path / "bad.parquet").write_text("not parquet")
    with pytest.raises(ValueError, match="Parquet"):
        RestitutionTable.open(tmp_path / "bad.parquet")
    with pytest.raises(ValueError, match="e_z"):
        RestitutionTable(pd.DataFrame({"Q1": [0.1], "nu": [0.5], "status": ["ok"]}))


# --------------------------------------------------------------------------
# lookup
# --------------------------------------------------------------------------

@pytest.mark.parametrize("which", ["kv", "ss"])
def test_lookup_returns_the_rows_at_grid_points(which, kv_path, ss_path):
    table = RestitutionTable.open(kv_path if which == "kv" else ss_path)
    rows = table.ok
    q2 = rows["Q2"].to_numpy() if which == "ss" else None
    res = table.lookup(rows["Q1"].to_numpy(), rows["nu"].to_numpy(), q2)
    for name in ("e_z", "e_x", "beta_x"):
        np.testing.assert_allclose(res[name], rows[name].to_numpy(), rtol=0, atol=1e-12)
    # scalars in, floats out; the nominal grid values find the same rows
    one = rows.iloc[5]
    nominal = table.lookup(float(np.round(one.Q1, 12)), one.nu,
                           None if which == "kv" else float(np.round(one.Q2, 12)))
    assert isinstance(nominal["e_z"], float)
    assert nominal["e_z"] == pytest.approx(one.e_z, abs=1e-12)


def test_interpolation_is_linear_in_log_q1_and_nu(kv):
    rows = kv.ok

    def at(q1, nu):
        return rows[np.isclose(rows.Q1, q1, rtol=1e-9) & np.isclose(rows.nu, nu)].iloc[0]

    a, b = Q1_GRID[2], Q1_GRID[3]
    mid = kv.lookup(np.sqrt(a * b), 0.5, method="linear")  # halfway in log Q1
    assert mid["e_z"] == pytest.approx(0.5 * (at(a, 0.5).e_z + at(b, 0.5).e_z), abs=1e-12)
    mid = kv.lookup(a, 0.125, method="linear")  # halfway in nu
    assert mid["beta_x"] == pytest.approx(0.5 * (at(a, 0.0).beta_x + at(a, 0.25).beta_x),
                                          abs=1e-12)
    assert mid["e_x"] == pytest.approx(abs(mid["beta_x"]), abs=1e-15)


def test_interpolation_of_monotone_data_is_monotone(kv):
    rows = kv.ok.sort_values("Q1")
    for nu in NU_GRID:  # precondition: the table's e_z falls with Q1
        assert np.all(np.diff(rows[np.isclose(rows.nu, nu)].e_z) < 0)
    q1 = np.geomspace(Q1_GRID[0], Q1_GRID[-1], 400)
    for nu in (0.5, 0.37):
        e_z = kv.lookup(q1, nu)["e_z"]
        assert np.all(np.diff(e_z) <= 0) and np.all((e_z > 0) & (e_z < 1))


def test_lookup_broadcasts(kv):
    res = kv.lookup(np.array([[0.02], [0.2]]), np.array([0.0, 0.25, 0.5]))
    assert res["e_z"].shape == res["e_x"].shape == res["nu"].shape == (2, 3)
    # e_z does not depend on nu (docs/physics.md#dimensionless-parameters), so neither does its
    # interpolation, up to the time step (refined for the tangential mode, which
    # depends on nu): about 1e-4 at the coarse test numerics
    np.testing.assert_allclose(res["e_z"], res["e_z"][:, :1] * np.ones((1, 3)), atol=1e-3)
    with pytest.raises(ValueError, match="broadcast"):
        kv.lookup([0.1, 0.2], [0.1, 0.2, 0.3])


def test_out_of_range_names_parameter_value_and_range(kv):
    with pytest.raises(ValueError, match=r"Q1 = 20 is outside .*Q1 in \[0\.01, 10\]"):
        kv.lookup([0.1, 20.0], 0.5)
    with pytest.raises(ValueError, match=r"nu = 0\.6 .*nu in \[0, 0\.5\]"):
        kv.lookup(0.1, 0.6)
    with pytest.raises(ValueError, match="Q1 = nan"):
        kv.lookup(float("nan"), 0.5)


def test_extrapolate_continues_the_edge_cell(kv):
    rows = kv.ok[np.isclose(kv.ok.nu, 0.5)].sort_values("Q1")
    e0, e1 = rows.e_z.iloc[0], rows.e_z.iloc[1]
    q = Q1_GRID[0] * (Q1_GRID[1] / Q1_GRID[0]) ** -0.2  # a fifth of a cell below the table
    res = kv.lookup(q, 0.5, extrapolate=True, method="linear")
    assert res["e_z"] == pytest.approx(e0 + 0.2 * (e0 - e1), abs=1e-12) and res["e_z"] < 1
    # cubic: linear beyond the end node with its slope, which lies between the end
    # secant's value and 0 for this monotone data
    cubic = kv.lookup(q, 0.5, extrapolate=True)["e_z"]
    assert e0 <= cubic <= e0 + 3 * 0.2 * (e0 - e1)
    far = kv.lookup([1e-6, 1e3], 0.5, extrapolate=True)  # clipped to the physical bounds
    assert np.all((far["e_z"] >= 0) & (far["e_z"] <= 1) & (far["e_x"] >= 0) & (far["e_x"] <= 1))
    with pytest.raises(ValueError, match="Q1 = 0 cannot be extrapolated"):
        kv.lookup(0.0, 0.5, extrapolate=True)


def test_model_mismatch_errors(kv, ss_path):
    with pytest.raises(ValueError, match="Q2 = 1 is not allowed: this is a kelvin_voigt table"):
        kv.lookup(0.1, 0.5, Q2=1)
    ss = RestitutionTable.open(ss_path)
    with pytest.raises(ValueError, match="Q2 is missing: this is a standard_solid table"):
        ss.lookup(0.1, 0.5)
    res = ss.lookup(0.1, 0.5, Q2=[0.3, 3.0])
    assert np.all(np.diff(res["e_z"]) > 0)  # a stiffer arm (larger Q2) dissipates less


def test_standard_solid_interpolates_in_log_q2(ss_path):
    ss = RestitutionTable.open(ss_path)
    rows = ss.ok

    def sel(q2):
        return rows[np.isclose(rows.Q2, q2) & np.isclose(rows.Q1, 0.1)
                    & np.isclose(rows.nu, 0.0)].iloc[0]

    mid = ss.lookup(0.1, 0.0, Q2=np.sqrt(0.1 * 1.0), method="linear")
    assert mid["e_z"] == pytest.approx(0.5 * (sel(0.1).e_z + sel(1.0).e_z), abs=1e-12)


def test_failed_grid_points_give_nan_only_where_needed(tmp_path):
    path = tmp_path / "t.parquet"
    make_table(path, fail=(7,))  # Q1_GRID[2] (0.1), nu = 0.25
    table = RestitutionTable.open(path)
    assert np.isnan(table.lookup(0.1, 0.25)["e_z"])
    assert np.isnan(table.lookup(0.15, 0.3)["e_z"])  # a cell that touches it
    ok = table.lookup([0.1, 0.1, 0.02], [0.0, 0.5, 0.25])  # grid points beside it, far cells
    assert np.all(np.isfinite(ok["e_z"]))


def test_random_draws_are_not_a_grid(tmp_path):
    rng = np.random.default_rng(1)
    scenes = [Scene.from_dimensionless(q, n) for q, n in
              zip(10 ** rng.uniform(-2, 1, 12), rng.uniform(0, 0.5, 12))]
    write_table(tmp_path / "r.parquet", results_frame(scenes), "kelvin_voigt")
    table = RestitutionTable.open(tmp_path / "r.parquet")
    with pytest.raises(ValueError, match="lookup needs a grid table.*12 distinct points"):
        table.lookup(0.1, 0.3)
    info = table.info()
    assert info["grid"] is None and "grid table" in info["grid_note"]
    # with one nu the draws fill a 1 x n "grid"; the sweep's mode metadata still tells
    nu = scenes[0].material.nu
    one_nu = results_frame(scenes[:1] + [Scene.from_dimensionless(0.3, nu)])
    path = tmp_path / "r1.parquet"
    write_table(path, one_nu, "kelvin_voigt")
    q1 = np.sqrt(scenes[0].Q1 * 0.3)
    assert np.isfinite(RestitutionTable.open(path).lookup(q1, nu)["e_z"])
    meta = {k.decode(): v.decode() for k, v in pq.read_schema(path).metadata.items()
            if k.startswith(b"vimpact.")}
    table = RestitutionTable(one_nu, {**meta, "vimpact.mode": "random"})
    with pytest.raises(ValueError, match=r"random draws \(vimpact.mode = random\).*"
                                         "sweeps/kelvin_voigt_table.toml"):
        table.lookup(q1, nu)


def test_several_theta_ratios_need_one(tmp_path):
    scenes = [Scene.from_dimensionless(q, 0.5, theta_ratio=t)
              for t in (0.4, 2 / 3) for q in Q1_GRID[:3]]
    write_table(tmp_path / "t.parquet", results_frame(scenes), "kelvin_voigt")
    table = RestitutionTable.open(tmp_path / "t.parquet")
    with pytest.raises(ValueError, match="theta_ratio is missing.*0.4, 0.666667"):
        table.lookup(0.1, 0.5)
    thin, hollow = (table.lookup(0.1, 0.5, theta_ratio=t) for t in (0.4, 2 / 3))
    # e_z does not depend on it; the runs differ only by the time step (refined
    # for the faster tangential mode), at the coarse test numerics about 2e-4
    assert thin["e_z"] == pytest.approx(hollow["e_z"], abs=1e-3)
    assert thin["e_x"] != pytest.approx(hollow["e_x"], abs=1e-3)
    with pytest.raises(InputError, match=r"theta_ratio = 0.3 is outside .*\[0.4, 0.666667\]"):
        table.lookup(0.1, 0.5, theta_ratio=0.3)
    with pytest.raises(InputError, match="theta_ratio = -0.5 is not allowed: must be > 0"):
        table.lookup(0.1, 0.5, theta_ratio=-0.5)


def test_theta_ratio_is_a_cubic_axis_in_log_theta(tmp_path):
    """Between theta_ratio nodes the lookup converges to direct simulation (held-out
    theta values it did not see) at high order when the log-spaced nodes are refined:
    error ratio > 8 per halving of the spacing (cubic: 16); at a node it is the row."""
    q1, nu = Q1_GRID[2:5], 0.3
    fine = np.geomspace(0.2, 0.8, 9)
    direct = results_frame([Scene.from_dimensionless(q, nu, theta_ratio=t)
                            for t in fine for q in q1])
    held_out = np.sqrt(fine[:-1] * fine[1:])
    ref = results_frame([Scene.from_dimensionless(q, nu, theta_ratio=t)
                         for t in held_out for q in q1])
    errors = []
    for step in (4, 2, 1):
        rows = direct[np.isin(direct.theta_ratio, fine[::step])]
        path = tmp_path / f"theta{step}.parquet"
        write_table(path, rows, "kelvin_voigt")
        table = RestitutionTable.open(path)
        if step > 1:  # nodes of the finest grid not in this one are held out
            pts = direct[~np.isin(direct.theta_ratio, fine[::step])]
        else:
            pts = ref
        got = table.lookup(pts.Q1.to_numpy(), nu, theta_ratio=pts.theta_ratio.to_numpy())
        errors.append(np.max(np.abs(got["beta_x"] - pts.beta_x.to_numpy())))
        assert table.info()["grid"] == {"Q1": 3, "nu": 1, "theta_ratio": len(fine[::step])}
    assert errors[0] / errors[1] > 8 and errors[1] / errors[2] > 8, errors
    at_node = table.lookup(q1, nu, theta_ratio=np.full(3, fine[3]))
    np.testing.assert_allclose(at_node["beta_x"], direct.beta_x[np.isclose(
        direct.theta_ratio, fine[3])].to_numpy(), rtol=0, atol=1e-12)


def gross_slip_psi_table(path, psi_nodes, q1=Q1_GRID[2:5], nu=0.3, theta_ratio=0.4, mu=0.5):
    """A friction table over psi filled in the gross-slip regime from its closed form
    (docs/physics.md#coulomb-friction: ``F_x = mu F_z`` throughout, so
    ``beta_x = -1 + 2 chi (1 + e_z) / psi`` with ``chi = (1 - nu)(1 + 1/theta_ratio)/(2 - nu)``),
    ``e_z`` from a stick simulation (the normal impact does not feel friction).
    Returns the stick rows and ``chi``."""
    stick = results_frame([Scene.from_dimensionless(q, nu, theta_ratio=theta_ratio) for q in q1])
    chi = (1 - nu) * (1 + 1 / theta_ratio) / (2 - nu)
    frames = []
    for psi in psi_nodes:
        f = stick.copy()
        f["beta_x"] = -1.0 + 2.0 * chi * (1.0 + f.e_z) / psi
        f["e_x"] = f.beta_x.abs()
        f["psi"], f["mu"] = psi, mu
        frames.append(f)
    write_table(path, pd.concat(frames, ignore_index=True), "kelvin_voigt")
    return stick, chi


def test_psi_is_an_interpolation_axis(tmp_path):
    """On a psi axis the lookup converges to the gross-slip closed form between the nodes
    (order > 3 per halving of the spacing) and gives the rows at the nodes."""
    nu = 0.3
    errors = []
    for n in (7, 13, 25):
        nodes = np.linspace(6.0, 24.0, n)
        path = tmp_path / f"psi{n}.parquet"
        stick, chi = gross_slip_psi_table(path, nodes)
        table = RestitutionTable.open(path)
        psi = np.linspace(6.0, 24.0, 61)
        Q, P = np.meshgrid(stick.Q1.to_numpy(), psi, indexing="ij")
        got = table.lookup(Q, nu, psi=P)
        e_z = np.repeat(stick.e_z.to_numpy()[:, None], len(psi), axis=1)
        np.testing.assert_allclose(got["e_z"], e_z, rtol=0, atol=1e-12)  # not a psi function
        errors.append(np.max(np.abs(got["beta_x"] - (-1.0 + 2.0 * chi * (1.0 + e_z) / P))))
        assert table.info()["grid"] == {"Q1": 3, "nu": 1, "psi": n}
    assert errors[0] / errors[1] > 8 and errors[1] / errors[2] > 8, errors
    with pytest.raises(InputError, match="psi is missing.*6 .. 24"):
        table.lookup(0.1, nu)
    with pytest.raises(InputError, match=r"psi = 30 is outside .*psi in \[6, 24\]"):
        table.lookup(0.1, nu, psi=30.0)
    with pytest.raises(InputError, match="psi = -1.0 is not allowed: must be >= 0"):
        table.lookup(0.1, nu, psi=-1.0, extrapolate=True)


def test_a_psi_table_from_friction_simulations_reads_its_rows(tmp_path):
    """A table swept over psi by simulate_batch with Coulomb friction (psi set through mu at
    v_c0 = v_z0; psi = 0 is mu = inf, full stick): the lookup gives its rows at the nodes,
    and where gross slip holds throughout (largest psi) the rows follow the closed form
    beta_x = -1 + 2 chi (1 + e_z) / psi (docs/physics.md#coulomb-friction)."""
    nu, psis = 0.3, (0.0, 2.0, 8.0, 16.0)
    mus = [np.inf if p == 0 else 2 * (1 - nu) / (p * (2 - nu)) for p in psis]
    scenes = [Scene.from_dimensionless(q, nu, mu=mu) for mu in mus for q in (0.1, 1.0)]
    df = results_frame(scenes)
    df["psi"] = np.repeat(psis, 2)
    df["mu"] = np.repeat(mus, 2)
    write_table(tmp_path / "f.parquet", df, "kelvin_voigt")
    table = RestitutionTable.open(tmp_path / "f.parquet")
    got = table.lookup(df.Q1.to_numpy(), nu, psi=df.psi.to_numpy())
    np.testing.assert_allclose(got["beta_x"], df.beta_x.to_numpy(), rtol=0, atol=1e-12)
    assert table.info()["ranges"]["mu"][1] == np.inf
    chi = (1 - nu) * (1 + 1 / 0.4) / (2 - nu)
    last = df[df.psi == 16.0]
    # F_x = mu F_z at every step: the impulse balance holds to rounding
    np.testing.assert_allclose(last.beta_x, -1 + 2 * chi * (1 + last.e_z) / 16.0, atol=1e-12)


def test_the_only_theta_ratio_may_be_given_as_an_array(kv):
    same = kv.lookup([0.1, 0.2], 0.5, theta_ratio=[0.4, 0.4])
    assert same["e_z"].tolist() == kv.lookup([0.1, 0.2], 0.5)["e_z"].tolist()
    with pytest.raises(InputError, match=r"theta_ratio = 0.5 is not allowed: the table holds "
                                         r"Theta / \(m R\^2\) = 0.4 only"):
        kv.lookup([0.1, 0.2], 0.5, theta_ratio=[0.4, 0.5])


def test_psi_on_a_stick_table_is_refused(kv):
    with pytest.raises(InputError, match="psi = 1.0 is not allowed: the table has no psi column"):
        kv.lookup(0.1, 0.5, psi=1.0)


def test_kelvin_voigt_rows_read_as_q2_nan_with_model_or_old_q2_zero(tmp_path, kv):
    rows = kv.data.drop(columns=["model"])
    new, old = rows.assign(Q2=np.nan, model="kelvin_voigt"), rows.assign(Q2=0.0)
    for name, frame in (("new", new), ("old", old)):
        write_table(tmp_path / f"{name}.parquet", frame, "kelvin_voigt")
    a, b = (RestitutionTable.open(tmp_path / f"{n}.parquet") for n in ("new", "old"))
    assert np.isnan(b.data.Q2).all() and (b.data.model == "kelvin_voigt").all()
    q1, nu = np.geomspace(0.01, 10, 13), np.linspace(0, 0.5, 13)
    for method in ("cubic", "linear"):
        ra, rb = a.lookup(q1, nu, method=method), b.lookup(q1, nu, method=method)
        for k in ("e_z", "beta_x"):
            np.testing.assert_array_equal(ra[k], rb[k])


def test_to_xarray_carries_theta_and_psi_axes_with_units(tmp_path):
    xr = pytest.importorskip("xarray")
    gross_slip_psi_table(tmp_path / "psi.parquet", np.linspace(6.0, 24.0, 4))
    ds = RestitutionTable.open(tmp_path / "psi.parquet").to_xarray()
    assert isinstance(ds, xr.Dataset) and ds.e_z.dims == ("Q1", "nu", "psi")
    assert ds.psi.attrs["units"] == "1" and "incidence" in ds.psi.attrs["long_name"]


# --------------------------------------------------------------------------
# physical curves
# --------------------------------------------------------------------------

def test_restitution_curve_matches_direct_simulation(kv, tmp_path):
    # Q1 grows as v_z0^(1/5): speeds that put Q1 on grid nodes 0.1, 0.316, 1 exactly
    base = Scene.from_dimensionless(1.0, 0.5)  # Q1 = 1 at v_z0 = 1 m/s, a_H = 0.01 R
    material, R, m = base.material, base.R, base.m
    nodes = Q1_GRID[2:5]
    speeds = (nodes / base.Q1) ** 5
    between = float(np.sqrt(speeds[0] * speeds[1]))
    curve = kv.restitution_curve(material, R, m, np.r_[speeds, between])
    assert list(curve.columns) == ["v_z0_m_s", "Q1", "e_z", "e_x", "beta_x"]
    np.testing.assert_allclose(curve.Q1[:3], nodes, rtol=1e-12)
    direct = [simulate(Scene(material, R=R, m=m, v_z0=v, v_x0=0.3 * v), NUM)
              for v in np.r_[speeds, between]]
    for i, res in enumerate(direct[:3]):
        assert curve.e_z[i] == pytest.approx(res.e_z, abs=1e-9)
        assert curve.e_x[i] == pytest.approx(res.e_x, abs=1e-9)
        assert curve.beta_x[i] == pytest.approx(res.beta_x, abs=1e-9)
    # between nodes: within the interpolation error of a half-decade grid
    assert curve.e_z[3] == pytest.approx(direct[3].e_z, abs=0.03)

    out = tmp_path / "curve.csv"
    written = kv.export_curve(out, material, R, m, speeds)
    back = pd.read_csv(out)
    assert list(back.columns) == ["v_z0_m_s", "Q1", "e_z", "e_x", "beta_x"]
    np.testing.assert_allclose(back.e_z, written.e_z, rtol=1e-9)


def test_restitution_curve_checks_material_and_half_space(kv, ss_path):
    ss_material = Material.standard_solid(nu=0.5, G1=1e6, G2=1e6, eta=10.0)
    with pytest.raises(ValueError, match="'standard_solid' does not match the table's model "
                                         "'kelvin_voigt'"):
        kv.restitution_curve(ss_material, 0.01, 0.01, [1.0])
    soft = Material.kelvin_voigt(nu=0.5, E=1e5, eta=1.0)
    with pytest.raises(ValueError, match="exceeds 0.2 R"):
        kv.restitution_curve(soft, 0.01, 1.0, [10.0])
    with pytest.raises(ValueError, match="v_z0"):
        kv.restitution_curve(Material.kelvin_voigt(nu=0.5, E=1e7, eta=1.0), 0.01, 0.01, [-1.0])
    # the standard solid: Q2 = G1/G2 comes from the material
    curve = RestitutionTable.open(ss_path).restitution_curve(
        Material.standard_solid(nu=0.5, G1=1e7, G2=1e7, eta=30.0), 0.01, 0.01, [0.5, 1.0],
        extrapolate=True)
    assert list(curve.columns) == ["v_z0_m_s", "Q1", "Q2", "e_z", "e_x", "beta_x"]
    assert np.allclose(curve.Q2, 1.0) and curve.e_z.between(0, 1).all()


# --------------------------------------------------------------------------
# command line
# --------------------------------------------------------------------------

@pytest.fixture
def vimpact_main():
    """The real ``vimpact`` entry point."""
    return cli.main


def run(main, args, capsys):
    try:
        code = main(args)
    except SystemExit as exc:  # argparse's own checks
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_lookup_json(vimpact_main, kv, kv_path, capsys):
    code, out, err = run(vimpact_main, ["table", "lookup", str(kv_path), "--Q1", "0.02,0.1, 3",
                                        "--nu", "0.3", "--json"], capsys)
    assert code == 0, err
    doc = json.loads(out)
    assert doc["model"] == "kelvin_voigt" and len(doc["rows"]) == 3
    api = kv.lookup([0.02, 0.1, 3.0], 0.3)
    for i, row in enumerate(doc["rows"]):
        assert row["Q1"] == api["Q1"][i] and row["nu"] == 0.3
        assert row["e_z"] == pytest.approx(api["e_z"][i], abs=1e-15)
        assert row["e_x"] == pytest.approx(api["e_x"][i], abs=1e-15)
    code, out, _ = run(vimpact_main, ["table", "lookup", str(kv_path), "--Q1", "0.1", "--nu",
                                      "0.5"], capsys)
    assert code == 0 and "e_z" in out and "0.1" in out


@pytest.mark.parametrize("args, words", [
    (["--Q1", "50", "--nu", "0.5"], ["Q1 = 50", "[0.01, 10]"]),
    (["--Q1", "0.1", "--nu", "0.5", "--Q2", "1"], ["Q2", "kelvin_voigt"]),
    (["--Q1", "0.1,0.2", "--nu", "0.1,0.2,0.3"], ["--Q1 has 2 values", "--nu has 3 values"]),
    (["--Q1", "abc", "--nu", "0.5"], ["--Q1"]),
    (["--nu", "0.5"], ["--Q1"]),
])
def test_cli_lookup_bad_input_exits_2(args, words, vimpact_main, kv_path, capsys):
    code, out, err = run(vimpact_main, ["table", "lookup", str(kv_path), *args], capsys)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    for word in words:
        assert word in err


def test_cli_info(vimpact_main, kv_path, tmp_path, capsys):
    code, out, _ = run(vimpact_main, ["table", "info", str(kv_path), "--json"], capsys)
    assert code == 0
    doc = json.loads(out)
    assert doc["model"] == "kelvin_voigt" and doc["ok_rows"] == 21
    code, out, _ = run(vimpact_main, ["table", "info", str(kv_path)], capsys)
    assert code == 0 and "grid            7 Q1 x 3 nu" in out
    code, _, err = run(vimpact_main, ["table", "info", str(tmp_path / "missing.parquet")], capsys)
    assert code == 2 and "no such file" in err and len(err.strip().splitlines()) == 1


def test_cli_export(vimpact_main, kv_path, tmp_path, capsys):
    out_csv = tmp_path / "curve.csv"
    args = ["table", "export", str(kv_path), "--out", str(out_csv), "--E", "5e10", "--nu", "0.5",
            "--eta", "1e5", "--R", "0.2", "--m", "10", "--vz0-min", "0.1", "--vz0-max", "10",
            "--n", "9"]
    code, out, err = run(vimpact_main, args, capsys)
    assert code == 0, err
    curve = pd.read_csv(out_csv)
    assert list(curve.columns) == ["v_z0_m_s", "Q1", "e_z", "e_x", "beta_x"]
    assert len(curve) == 9 and curve.v_z0_m_s.iloc[-1] == pytest.approx(10.0)
    assert np.all(np.diff(curve.e_z) < 0)  # faster impacts: larger Q1, less restitution
    # the thesis example at 10 m/s has Q1 = 0.0412 (README)
    assert curve.Q1.iloc[-1] == pytest.approx(0.0411721, rel=1e-5)
    bad = args[:5] + ["--G1", "1e10", "--G2", "1e10"] + args[7:]
    code, _, err = run(vimpact_main, bad, capsys)
    assert code == 2 and "model 'standard_solid', but the table is 'kelvin_voigt'" in err
    code, _, err = run(vimpact_main, args[:-1] + ["1"], capsys)
    assert code == 2 and "--n = 1" in err


def test_cli_export_caps_n(vimpact_main, kv_path, tmp_path, capsys):
    from vimpact.cli.table import MAX_CURVE_POINTS
    from vimpact.lookup.table import MAX_CURVE_POINTS as TABLE_LIMIT

    assert MAX_CURVE_POINTS == TABLE_LIMIT == 100_000
    args = ["table", "export", str(kv_path), "--out", str(tmp_path / "c.csv"), "--E", "5e10",
            "--nu", "0.5", "--eta", "1e5", "--R", "0.2", "--m", "10", "--vz0-min", "0.1",
            "--vz0-max", "10", "--n", "100001"]
    code, _, err = run(vimpact_main, args, capsys)
    assert code == 2 and "--n = 100001 is not allowed: at most 100000 speeds" in err
    assert not (tmp_path / "c.csv").exists()


def test_cli_export_at_an_impact_angle_on_a_psi_table(vimpact_main, tmp_path, capsys):
    """psi = 2 (1 - nu) / (mu (2 - nu)) tan(angle) (worked out here by hand), the same at
    every speed; the curve is the table's lookup at that psi; stick tables refuse --mu."""
    nu, mu, angle = 0.3, 0.1, 60.0
    path = tmp_path / "psi.parquet"
    gross_slip_psi_table(path, np.linspace(6.0, 24.0, 7), nu=nu)
    material = Scene.from_dimensionless(0.3, nu).material  # Q1 = 0.3 at R = m = v = 1
    args = ["table", "export", str(path), "--out", str(tmp_path / "c.csv"),
            "--G", repr(material.G_inf), "--eta", repr(material.eta0), "--nu", str(nu),
            "--R", "1", "--m", "1", "--vz0-min", "0.5", "--vz0-max", "2", "--n", "5"]
    code, _, err = run(vimpact_main, args + ["--angle-deg", str(angle)], capsys)
    assert code == 2 and "--mu is missing" in err
    code, out, err = run(vimpact_main, args + ["--angle-deg", str(angle), "--mu", str(mu)],
                         capsys)
    assert code == 0, err
    psi = 2 * 0.7 / (0.1 * 1.7) * 3 ** 0.5  # tan 60 deg = sqrt 3
    curve = pd.read_csv(tmp_path / "c.csv")
    assert list(curve.columns) == ["v_z0_m_s", "Q1", "psi", "e_z", "e_x", "beta_x"]
    np.testing.assert_allclose(curve.psi, psi, rtol=1e-9)
    assert f"psi {psi:.4g} at 60 deg" in out
    look = RestitutionTable.open(path).lookup(curve.Q1.to_numpy(), nu, psi=psi)
    np.testing.assert_allclose(curve.beta_x, look["beta_x"], rtol=1e-9, atol=1e-12)
    assert np.all(curve.beta_x < 0)  # gross slip at this incidence reverses the contact point
    with pytest.raises(InputError, match=r"angle_deg = 90.0 is not allowed.*\[0, 90\)"):
        RestitutionTable.open(path).restitution_curve(material, 1.0, 1.0, [1.0], angle_deg=90.0,
                                                      mu=mu)


def test_cli_lookup_psi_and_theta_lists(vimpact_main, tmp_path, capsys):
    path = tmp_path / "psi.parquet"
    gross_slip_psi_table(path, np.linspace(6.0, 24.0, 4))
    code, out, err = run(vimpact_main, ["table", "lookup", str(path), "--Q1", "0.1,0.2",
                                        "--nu", "0.3", "--psi", "6,10", "--json"], capsys)
    assert code == 0, err
    rows = json.loads(out)["rows"]
    assert [r["psi"] for r in rows] == [6.0, 10.0] and rows[0]["Q1"] == 0.1
    direct = RestitutionTable.open(path).lookup([0.1, 0.2], 0.3, psi=[6.0, 10.0])
    assert [r["beta_x"] for r in rows] == pytest.approx(direct["beta_x"], abs=1e-15)
    code, _, err = run(vimpact_main, ["table", "lookup", str(path), "--Q1", "0.1", "--nu",
                                      "0.3", "--psi", "6,10,12", "--theta-ratio", "0.4,0.4"],
                       capsys)
    assert code == 2 and "--theta-ratio has 2 values, --psi has 3 values" in err


def test_cli_info_json_is_standard_with_mu_inf(vimpact_main, kv, tmp_path, capsys):
    path = tmp_path / "stick.parquet"
    write_table(path, kv.data.drop(columns=["model"]).assign(mu=np.inf), "kelvin_voigt")
    code, out, err = run(vimpact_main, ["table", "info", str(path), "--json"], capsys)
    assert code == 0, err
    info = json.loads(out, parse_constant=lambda c: pytest.fail(f"non-standard JSON {c}"))
    assert info["ranges"]["mu"] == ["inf", "inf"]
    assert "  mu              inf\n" in str(RestitutionTable.open(path))
    mixed = kv.data.drop(columns=["model"]).assign(mu=np.where(kv.data.Q1 > 1, np.inf, 0.3))
    write_table(path, mixed, "kelvin_voigt")
    assert "  mu              0.3 .. inf\n" in str(RestitutionTable.open(path))
