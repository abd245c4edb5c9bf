"""Sweeps: spec validation, tables that match single runs, resume, collapse, metadata."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import vimpact as v
from tests.sweep import write
from vimpact import cli
from vimpact.engine.result import STATUS_CODE, STATUS_NAMES
from vimpact.sweep import SweepInterrupted, load_spec, parts_dir, read_metadata, run_sweep, runner
from vimpact.tableformat import schema

SWEEPS = Path(__file__).resolve().parents[2] / "sweeps"
TINY = v.Numerics(steps=100, elements=20)
NUMERICS = "[numerics]\nsteps = 100\nelements = 20\n"

RANDOM_KV = """
model = "kelvin_voigt"
seed = 7
chunk_size = 3
output = "kv.parquet"
""" + NUMERICS + """
[random]
rows = 8
E_Pa = 1e7
eta_Pa_s = [1.0, 1e4]
R_m = 0.01
m_kg = { choice = [1e-4, 1.0] }      # 1 kg: contact beyond 0.2 R
v_z0_m_s = [0.5, 5.0]
v_x0_m_s = [-1.0, 1.0]
omega0_rad_s = [-50.0, 50.0]
nu = { choice = [0.3, 0.7] }         # 0.7: not a valid Poisson ratio
"""

GRID_SS = """
model = "standard_solid"
chunk_size = 4
""" + NUMERICS + """
[grid]
Q1 = { start = 0.01, stop = 1.0, per_decade = 1 }
Q2 = [0.1, 10.0]
nu = [0.0, 0.5]
"""


def finished_rows_have_no_nan(df):
    outputs = ["e_z", "energy_ratio", "t_contact_s", "u_max_m", "a_max_m", "t_contact_rel"]
    finished = df.status.isin(["ok", "half_space", "vc0_zero"])
    assert not df.loc[finished, outputs].isna().any().any()
    assert not df.loc[df.status == "ok", ["e_x", "beta_x"]].isna().any().any()
    assert df.loc[~finished, "e_z"].isna().all()


# ---- spec validation ----------------------------------------------------------

@pytest.mark.parametrize("text, key", [
    ('model = "kelvin_voigt"\ncolour = 1\n[grid]\nQ1 = 0.1\nnu = 0.5\n', "colour"),
    ('model = "maxwell"\n[grid]\nQ1 = 0.1\nnu = 0.5\n', "model"),
    ('[grid]\nQ1 = 0.1\nnu = 0.5\n', "model"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = -0.1\nnu = 0.5\n', "grid.Q1"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = 0.1\nnu = [0.2, 0.6]\n', "grid.nu"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = 0.1\nQ2 = 1.0\nnu = 0.5\n', "grid.Q2"),
    ('model = "standard_solid"\n[grid]\nQ1 = 0.1\nnu = 0.5\n', "grid.Q2"),
    ('model = "standard_solid"\n[grid]\nQ1 = 0.1\nQ2 = 0\nnu = 0.5\n', "grid.Q2"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = {start = 0, stop = 1, per_decade = 5}\nnu = 0.5\n',
     "grid.Q1.start"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = {start = 1, stop = 10, step = 1}\nnu = 0.5\n', "step"),
    ('model = "prony"\n[grid]\nnu = 0.5\n', "grid"),
    ('model = "kelvin_voigt"\nchunk_size = 0\n[grid]\nQ1 = 0.1\nnu = 0.5\n', "chunk_size"),
    ('model = "kelvin_voigt"\n[numerics]\nsteps = 3\n[grid]\nQ1 = 0.1\nnu = 0.5\n',
     "numerics.steps"),
    ('model = "kelvin_voigt"\n[numerics]\npreset = "slow"\n[grid]\nQ1 = 0.1\nnu = 0.5\n',
     "numerics.preset"),
    ('model = "kelvin_voigt"\n[numerics]\ndt = 1e-3\n[grid]\nQ1 = 0.1\nnu = 0.5\n', "numerics.dt"),
    ('model = "kelvin_voigt"\n', "random/grid"),
    ('model = "kelvin_voigt"\n[random]\nrows = 3\nE_Pa = 1e7\neta_Pa_s = 1.0\nR_m = 0.1\n'
     'm_kg = 1.0\nv_z0_m_s = 1.0\nnu = 0.5\n', "seed"),
    ('model = "kelvin_voigt"\nseed = 1\n[random]\nrows = 3\nE_Pa = 1e7\nR_m = 0.1\nm_kg = 1.0\n'
     'v_z0_m_s = 1.0\nnu = 0.5\n', "random.eta_Pa_s"),
    ('model = "kelvin_voigt"\nseed = 1\n[random]\nrows = 3\nE_Pa = 1e7\nG_Pa = 1e7\n'
     'eta_Pa_s = 1.0\nR_m = 0.1\nm_kg = 1.0\nv_z0_m_s = 1.0\nnu = 0.5\n', "E_Pa/G_Pa"),
    ('model = "kelvin_voigt"\nseed = 1\n[random]\nrows = 3\nE_Pa = 1e7\neta_Pa_s = 1.0\n'
     'R_m = [0.1, 0.01]\nm_kg = 1.0\nv_z0_m_s = 1.0\nnu = 0.5\n', "random.R_m"),
    ('model = "kelvin_voigt"\nseed = 1\n[random]\nrows = 3\nE_Pa = 1e7\neta_Pa_s = 1.0\n'
     'R_m = 0.1\nm_kg = 1.0\nv_z0_m_s = {range = [-1, 5], log = true}\nnu = 0.5\n',
     "random.v_z0_m_s"),
    ('model = "kelvin_voigt"\nseed = 1\n[random]\nrows = 3\nE = 1e7\neta_Pa_s = 1.0\n'
     'R_m = 0.1\nm_kg = 1.0\nv_z0_m_s = 1.0\nnu = 0.5\n', "random.E"),
    ('model = "standard_solid"\nseed = 1\n[random]\nrows = 3\nG1_Pa = 1e7\nG2_Pa = "big"\n'
     'eta_Pa_s = 1.0\nR_m = 0.1\nm_kg = 1.0\nv_z0_m_s = 1.0\nnu = 0.5\n', "random.G2_Pa"),
    ('model = "kelvin_voigt"\n[grid\nQ1 = 0.1\n', "TOML"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = 0.1\nnu = 0.5\ntolerance = 0.5\n', "grid.tolerance"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = 0.1\nnu = 0.5\ntolerance = 1e-12\n',
     "grid.tolerance"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = 0.1\nnu = 0.5\ntolerance = [1e-5]\n',
     "grid.tolerance"),
    ('model = "kelvin_voigt"\n[grid]\nQ1 = 0.1\nnu = 0.5\ntolerance = nan\n', "grid.tolerance"),
])
def test_bad_spec_names_file_and_key(tmp_path, text, key):
    path = write(tmp_path, text, "bad_spec.toml")
    with pytest.raises(ValueError) as info:
        load_spec(path)
    message = str(info.value)
    assert "bad_spec.toml" in message and key in message
    assert "\n" not in message.strip() or key == "TOML"


def test_grid_tolerance_is_a_field_not_an_axis(tmp_path):
    plain = load_spec(write(tmp_path, GRID_SS, "plain.toml"))
    assert plain.grid_tolerance is None and plain.metadata()["grid_tolerance"] is None
    spec = load_spec(write(tmp_path, GRID_SS + "tolerance = 1e-5\n", "tol.toml"))
    assert spec.grid_tolerance == 1e-5 and spec.metadata()["grid_tolerance"] == 1e-5
    assert list(spec.axes) == list(plain.axes) and spec.rows == plain.rows == 12
    assert spec.columns() == plain.columns()
    for lo_hi in ("1e-9", "0.1"):  # both ends of the allowed range
        assert load_spec(write(tmp_path, GRID_SS + f"tolerance = {lo_hi}\n", "end.toml")) \
            .grid_tolerance == float(lo_hi)


def test_missing_spec_file(tmp_path):
    with pytest.raises(ValueError, match="nowhere.toml"):
        load_spec(tmp_path / "nowhere.toml")


def test_ranges_log_uniform_above_a_decade(tmp_path):
    spec = load_spec(write(tmp_path, """
model = "elastic"
seed = 3
[random]
rows = 2000
G_Pa = [1e6, 1e9]
R_m = [0.01, 0.1]
m_kg = {range = [1.0, 2.0], log = true}
v_z0_m_s = {range = [1e-2, 1e2], log = false}
v_x0_m_s = [-1, 1]
nu = {choice = [0.0, 0.5]}
"""))
    kinds = {k: d.kind for k, d in spec.draws.items()}
    assert kinds == {"G_Pa": "log_uniform", "R_m": "uniform", "m_kg": "log_uniform",
                     "v_z0_m_s": "uniform", "v_x0_m_s": "uniform", "omega0_rad_s": "fixed",
                     "nu": "choice", "theta_ratio": "fixed"}
    p = spec.parameters()
    decade = np.floor(np.log10(p["G_Pa"]))
    assert set(np.unique(decade)) == {6, 7, 8}
    assert all(abs((decade == d).mean() - 1 / 3) < 0.05 for d in (6, 7, 8))
    assert set(np.unique(p["nu"])) == {0.0, 0.5}
    assert (p["omega0_rad_s"] == 0).all() and (p["theta_ratio"] == 0.4).all()
    again = load_spec(spec.path).parameters()  # same seed: same rows
    assert all(np.array_equal(p[k], again[k]) for k in p)


def test_shipped_specs_are_valid():
    specs = {p.stem: load_spec(p) for p in sorted(SWEEPS.glob("*.toml"))}
    assert {"fig5_1_kelvin_voigt_random", "fig5_2_3_kelvin_voigt_nu", "fig5_4_5_standard_solid_q2",
            "kelvin_voigt_table", "standard_solid_table"} <= set(specs)
    assert specs["fig5_1_kelvin_voigt_random"].rows == 300
    kv = specs["kelvin_voigt_table"]
    assert kv.axes["Q1"][0] == 1e-3 and kv.axes["Q1"][-1] >= 10
    assert np.allclose(np.diff(np.log10(kv.axes["Q1"])), 0.1)
    assert np.allclose(kv.axes["nu"], [0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.475, 0.5])
    assert list(specs["fig5_4_5_standard_solid_q2"].axes["Q2"]) == [0.01, 0.1, 1, 10, 100]
    default = v.Numerics.preset("default")
    for name, spec in specs.items():
        if name == "standard_solid_band":  # its stiff-arm impacts: a looser rtol, stated
            assert spec.numerics == dataclasses.replace(default, rtol=1e-6)
            assert spec.grid_tolerance >= 100 * spec.numerics.rtol
        else:
            assert spec.numerics == default
        assert spec.output.parent.name == "tables"


def test_shipped_tables_are_current():
    """Every shipped table was made by its spec with this package and schema version
    (stale otherwise: regenerate it with `vimpact sweep sweeps/NAME.toml`)."""
    from vimpact.sweep import store
    shipped = [load_spec(p) for p in sorted(SWEEPS.glob("*.toml"))]
    shipped = [s for s in shipped if s.output.exists()]
    assert len(shipped) >= 6
    stale = [s.path.name for s in shipped if not store.is_complete(s, s.output)]
    assert not stale, ("stale tables, regenerate with `vimpact sweep` (`vimpact table build` "
                       f"for an adaptive spec): {stale}")
    for spec in shipped:
        assert read_metadata(spec.output)["schema_version"] == schema.SCHEMA_VERSION


# ---- end to end ---------------------------------------------------------------

def test_random_sweep_matches_single_simulations(tmp_path):
    path = run_sweep(write(tmp_path, RANDOM_KV), progress=False)
    assert path == tmp_path / "kv.parquet" and not parts_dir(path).exists()
    df = pd.read_parquet(path)
    assert list(df.row) == list(range(8))
    assert set(df.status) == {"ok", "half_space", "invalid"}
    finished_rows_have_no_nan(df)
    invalid = df[df.status == "invalid"]
    assert (invalid.nu == 0.7).all() and invalid.error.str.contains("nu").all()
    assert invalid.Q1.isna().all() and df.error[df.status != "invalid"].isna().all()
    assert np.allclose(df.G_Pa, df.E_Pa / (2 * (1 + df.nu)))
    for r in df[df.status != "invalid"].itertuples():
        material = v.Material.kelvin_voigt(nu=r.nu, E=r.E_Pa, eta=r.eta_Pa_s)
        scene = v.Scene(material, R=r.R_m, m=r.m_kg, v_z0=r.v_z0_m_s, v_x0=r.v_x0_m_s,
                        omega0=r.omega0_rad_s, allow_large_contact=True)
        res = v.simulate(scene, TINY)
        assert res.status == r.status == ("half_space" if r.m_kg == 1.0 else "ok")
        for col, key in [("e_z", "e_z"), ("e_x", "e_x"), ("beta_x", "beta_x"),
                         ("t_contact_s", "t_contact"), ("a_max_m", "a_max"),
                         ("energy_ratio", "energy_ratio"), ("Q1", "Q1")]:
            assert getattr(r, col) == pytest.approx(getattr(res, key), rel=1e-12), col
        assert r.t_contact_rel == pytest.approx(res.t_contact / res.t_hertz, rel=1e-12)


GRID_KV = """
model = "kelvin_voigt"
chunk_size = 4
""" + NUMERICS + """
[grid]
Q1 = [0.01, 0.1, 1.0]
nu = [0.0, 0.5]
"""


def test_kelvin_voigt_grid_rows_have_no_q2_and_read_back(tmp_path):
    """A Kelvin-Voigt row has Q2 = NaN (G2 -> inf), never 0; the lookup reads the table
    and returns its rows at the nodes."""
    from vimpact.lookup.table import RestitutionTable
    path = run_sweep(write(tmp_path, GRID_KV), progress=False)
    df = pd.read_parquet(path)
    assert (df.status == "ok").all() and df.Q2.isna().all()
    assert "NaN" in read_metadata(path)["columns"]["Q2"]
    table = RestitutionTable.open(path)
    assert table.model == "kelvin_voigt"
    res = table.lookup(df.Q1.to_numpy(), df.nu.to_numpy())
    np.testing.assert_allclose(res["e_z"], df.e_z, rtol=1e-12)
    np.testing.assert_allclose(res["beta_x"], df.beta_x, rtol=1e-12)


def test_random_kelvin_voigt_rows_have_no_q2(tmp_path):
    df = pd.read_parquet(run_sweep(write(tmp_path, RANDOM_KV.replace("rows = 8", "rows = 2")),
                                   progress=False))
    assert df.Q2.isna().all()


def test_rows_name_their_rheology(tmp_path):
    df = pd.read_parquet(run_sweep(write(tmp_path, GRID_KV), progress=False))
    assert (df.model == "kelvin_voigt").all() and df.Q2.isna().all()


def test_grid_sweep_rows_are_dimensionless_scenes(tmp_path):
    path = run_sweep(write(tmp_path, GRID_SS), out=tmp_path / "out" / "ss.parquet",
                     progress=False)
    df = pd.read_parquet(path)
    assert len(df) == 3 * 2 * 2 and (df.status == "ok").all()
    finished_rows_have_no_nan(df)
    assert list(df.Q1[:3]) == [0.01, 0.1, 1.0]  # Q1 runs fastest, exact grid values
    assert list(df.Q2[:6]) == [0.1] * 3 + [10.0] * 3 and list(df.nu[:12:6]) == [0.0, 0.5]
    assert np.allclose(df.G1_Pa / df.G2_Pa, df.Q2)
    scenes = [v.Scene.from_dimensionless(r.Q1, r.nu, r.Q2) for r in df.itertuples()]
    for r, s in zip(df.itertuples(), scenes):
        assert s.Q1 == pytest.approx(r.Q1, rel=1e-12)
        res = v.simulate(s, TINY)
        assert (r.e_z, r.e_x, r.beta_x) == pytest.approx((res.e_z, res.e_x, res.beta_x), rel=1e-12)


def test_random_draws_collapse_onto_q1_and_q2(tmp_path):
    spec = """
model = "standard_solid"
seed = 11
chunk_size = 5
""" + NUMERICS + """
[random]
rows = 10
G1_Pa = [1e7, 1e9]
G2_Pa = [1e7, 1e9]
eta_Pa_s = [1e2, 1e4]
R_m = [0.01, 0.1]
m_kg = [1e-3, 1e-2]
v_z0_m_s = [0.5, 5]
v_x0_m_s = [-2, 2]
omega0_rad_s = [-50, 50]
nu = [0.0, 0.5]
theta_ratio = [0.3, 0.5]
"""
    df = pd.read_parquet(run_sweep(write(tmp_path, spec), progress=False))
    assert (df.status == "ok").all() and df.Q1.max() / df.Q1.min() > 10
    assert np.allclose(df.Q2, df.G1_Pa / df.G2_Pa)
    # the same (Q1, Q2, nu, theta_ratio) with quite different physical scenes
    scenes = [v.Scene.from_dimensionless(r.Q1, r.nu, r.Q2, theta_ratio=r.theta_ratio)
              for r in df.itertuples()]
    ref = v.simulate_batch(scenes, TINY)
    for col in ("e_z", "e_x", "beta_x", "t_contact_rel", "u_max_rel", "a_max_rel"):
        ref_col = {"t_contact_rel": ref.t_contact / ref.t_hertz, "u_max_rel": ref.u_max / ref.d_hertz,
                   "a_max_rel": ref.a_max / ref.a_hertz}.get(col, ref.get(col))
        assert np.allclose(df[col], ref_col, rtol=1e-9, atol=1e-12), col


def test_metadata_round_trips(tmp_path):
    spec_path = write(tmp_path, RANDOM_KV)
    path = run_sweep(spec_path, progress=False)
    raw = pq.read_schema(path).metadata
    assert raw[b"vimpact.model"] == b"kelvin_voigt"
    meta = read_metadata(path)
    assert meta["schema_version"] == schema.SCHEMA_VERSION
    assert meta["model"] == "kelvin_voigt" and meta["mode"] == "random"
    assert meta["seed"] == 7 and meta["rows"] == 8
    assert meta["version"] == v.__version__
    assert v.Numerics(**meta["numerics"]) == TINY
    assert meta["spec"] == spec_path.read_text() and meta["spec_name"] == "spec.toml"
    columns = pq.read_schema(path).names
    assert list(meta["units"]) == columns and list(meta["columns"]) == columns
    assert meta["units"]["E_Pa"] == "Pa" and meta["units"]["eta_Pa_s"] == "Pa s"
    assert meta["units"]["v_z0_m_s"] == "m/s" and meta["units"]["t_contact_s"] == "s"
    assert meta["units"]["e_z"] == "1" and meta["units"]["Q1"] == "1"
    assert {"invalid", "half_space", "ok"} <= set(meta["statuses"])
    assert "chunk" not in meta  # part bookkeeping stays in the parts


# ---- interruption and resume ----------------------------------------------------

def interrupt_after(n_chunks):
    calls = []

    def progress(done, total):
        calls.append(done)
        if len(calls) == n_chunks:
            raise KeyboardInterrupt
    return progress


def test_resume_after_interruption_equals_uninterrupted_run(tmp_path):
    spec_path = write(tmp_path, RANDOM_KV)
    full = run_sweep(spec_path, out=tmp_path / "full.parquet", progress=False)
    out = tmp_path / "resumed.parquet"
    with pytest.raises(SweepInterrupted) as info:
        run_sweep(spec_path, out=out, progress=interrupt_after(2))
    assert isinstance(info.value, KeyboardInterrupt)
    assert "--resume" in str(info.value) and "2 of 3 chunks" in str(info.value)
    parts = parts_dir(out)
    assert sorted(p.name for p in parts.iterdir()) == ["part-00000.parquet", "part-00001.parquet"]
    assert not out.exists()
    with pytest.raises(ValueError, match="--resume"):
        run_sweep(spec_path, out=out, progress=False)
    (parts / "part-00000.parquet").unlink()  # as if lost: computed again
    (parts / ".part-00002.parquet.123.tmp").write_bytes(b"cut short by kill -9")
    computed = []
    assert run_sweep(spec_path, out=out, resume=True, progress=lambda d, t: computed.append(d)) == out
    assert computed == [6, 8]  # chunk 1 was kept; chunks 0 and 2 computed
    assert not parts.exists()
    pd.testing.assert_frame_equal(pd.read_parquet(out), pd.read_parquet(full))
    assert pq.read_schema(out).metadata == pq.read_schema(full).metadata
    assert out.read_bytes() == full.read_bytes()


def test_resume_refuses_parts_of_another_spec(tmp_path):
    spec_path = write(tmp_path, RANDOM_KV)
    with pytest.raises(SweepInterrupted):
        run_sweep(spec_path, progress=interrupt_after(1))
    spec_path.write_text(RANDOM_KV.replace("seed = 7", "seed = 8"))
    with pytest.raises(ValueError, match="another sweep"):
        run_sweep(spec_path, resume=True, progress=False)


def test_resume_of_a_finished_table_computes_nothing(tmp_path, monkeypatch):
    spec_path = write(tmp_path, GRID_SS)
    path = run_sweep(spec_path, progress=False)
    before = path.read_bytes()
    monkeypatch.setattr(runner, "compute_chunk", lambda *a: pytest.fail("recomputed"))
    assert run_sweep(spec_path, resume=True, progress=False) == path
    assert path.read_bytes() == before


# ---- command line -----------------------------------------------------------------

@pytest.fixture
def main():
    """The real ``vimpact`` entry point."""
    return cli.main


def test_cli_sweep_and_exit_codes(tmp_path, main, capsys, monkeypatch):
    spec_path = write(tmp_path, GRID_SS)
    out = tmp_path / "cli.parquet"
    assert main(["sweep", str(spec_path), "--out", str(out)]) == 0
    assert "12 rows (ok 12)" in capsys.readouterr().out
    assert len(pd.read_parquet(out)) == 12

    bad = write(tmp_path, GRID_SS.replace("nu = [0.0, 0.5]", "nu = [0.0, 0.9]"), "bad.toml")
    assert main(["sweep", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.toml" in err and "grid.nu" in err

    real = runner.compute_chunk
    calls = []

    def flaky(*args):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args)
    monkeypatch.setattr(runner, "compute_chunk", flaky)
    again = tmp_path / "again.parquet"
    assert main(["sweep", str(spec_path), "--out", str(again)]) == 130
    err = capsys.readouterr().err
    assert "1 of 3 chunks" in err and "--resume" in err and str(again) in err
    assert main(["sweep", str(spec_path), "--out", str(again)]) == 2  # parts: needs --resume
    assert "--resume" in capsys.readouterr().err
    monkeypatch.setattr(runner, "compute_chunk", real)
    assert main(["sweep", str(spec_path), "--out", str(again), "--resume"]) == 0
    assert again.read_bytes() == out.read_bytes()


def test_nan_without_a_status_becomes_non_finite(tmp_path):
    spec = load_spec(write(tmp_path, GRID_SS))
    cols = {"e_z": np.array([0.5, np.nan]), "e_x": np.array([np.nan, 0.1]),
            "beta_x": np.array([np.nan, 0.1])}
    cols.update({c: np.zeros(2) for c in schema.OUTPUTS if c not in cols})
    status = np.array([STATUS_CODE["vc0_zero"], STATUS_CODE["half_space"]], dtype=np.int8)
    error = np.array([None, None], dtype=object)
    runner.guard_nan(cols, status, error, np.array([True, False]), np.array([True, True]))
    assert [STATUS_NAMES[c] for c in status] == ["vc0_zero", "non_finite"] and "e_z" in error[1]
    assert error[0] is None and math.isnan(cols["t_contact_s"][1])
    assert spec.rows == 12 and dataclasses.asdict(spec.numerics)["steps"] == 100


def test_nan_guard_tells_explained_from_unexplained_tangential_nan():
    """e_x NaN where v_c0 = 0 explains it stays; where nothing explains it the row
    becomes non_finite naming e_x; a row without NaN and an unfinished row stay."""
    cols = {c: np.ones(4) for c in schema.OUTPUTS}
    cols["e_x"] = np.array([np.nan, np.nan, 0.2, np.nan])
    status = np.array([STATUS_CODE["vc0_zero"], STATUS_CODE["ok"], STATUS_CODE["ok"],
                       STATUS_CODE["time_limit"]], dtype=np.int8)
    error = np.array([None] * 4, dtype=object)
    bad = runner.guard_nan(cols, status, error, np.array([True, False, False, False]),
                           np.array([True, True, True, False]))
    assert list(bad) == [False, True, False, False]
    assert [STATUS_NAMES[c] for c in status] == ["vc0_zero", "non_finite", "ok", "time_limit"]
    assert "e_x" in error[1] and "e_z" not in error[1] and list(error[[0, 2, 3]]) == [None] * 3
    assert math.isnan(cols["e_z"][1]) and cols["e_z"][2] == 1.0


def test_one_value_viewed_in_every_row_is_checked_like_a_full_column():
    """A sweep hands the engine constant inputs as views of one value: checked once
    when good, and a bad one names every row as a full column does."""
    from vimpact.model.validation import check_column

    for value, rule in [(0.01, "positive"), (-1.0, "positive"), (np.inf, "friction"),
                        (np.nan, "finite"), (3, "non_negative")]:
        view = np.broadcast_to(np.asarray(value), (5,))
        got, want = np.empty(5, dtype=object), np.empty(5, dtype=object)
        x = check_column("R_m", view, rule, got)
        y = check_column("R_m", np.array(view), rule, want)
        assert x.dtype == y.dtype == np.float64 and x.flags.writeable
        assert np.array_equal(x, y, equal_nan=True) and list(got) == list(want)
