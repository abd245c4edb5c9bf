"""Sweep backends and the store: Dask, shards, any chunk order, kill -9, dataset layout,
progress off a terminal, output checks before any work."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import vimpact as v
from tests.sweep import write
from vimpact import cli
from vimpact.sweep import load_spec, parts_dir, read_metadata, run_sweep, runner
from vimpact.sweep.parameters import chunk_parameters
from vimpact.tableformat import files, metadata

ROOT = Path(__file__).resolve().parents[2]

RANDOM_KV = """
model = "kelvin_voigt"
seed = 5
chunk_size = 3
[numerics]
steps = 100
elements = 20
[random]
rows = 14
E_Pa = [1e7, 1e9]
eta_Pa_s = [1.0, 1e4]
R_m = 0.01
m_kg = [1e-4, 1e-2]
v_z0_m_s = [0.5, 5.0]
v_x0_m_s = [-1.0, 1.0]
nu = { choice = [0.3, 0.7] }
"""

GRID_SS = """
model = "standard_solid"
chunk_size = 5
[numerics]
steps = 100
elements = 20
[grid]
Q1 = { start = 0.01, stop = 1.0, num = 4 }
Q2 = [0.1, 10.0]
nu = [0.0, 0.5]
"""


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The random sweep run in-process, in chunk order: the table every backend must give."""
    tmp = tmp_path_factory.mktemp("reference")
    spec = write(tmp, RANDOM_KV)
    return spec, run_sweep(spec, out=tmp / "reference.parquet", progress=False)


# ---- parameters per chunk -----------------------------------------------------

def test_grid_chunks_unravel_the_axes_q1_fastest(tmp_path):
    spec = load_spec(write(tmp_path, GRID_SS))
    mesh = np.meshgrid(*spec.axes.values(), indexing="ij")  # outermost first
    full = {k: m.ravel() for k, m in zip(spec.axes, mesh)}
    got = spec.parameters()
    assert spec.n_chunks == 4 and all(np.array_equal(got[k], full[k]) for k in full)
    assert list(got["Q1"][:4]) == list(spec.axes["Q1"])


def test_random_chunks_are_independent_of_order_and_size_bounded(tmp_path):
    spec = load_spec(write(tmp_path, RANDOM_KV))
    forward = [chunk_parameters(spec, c) for c in range(spec.n_chunks)]
    backward = [chunk_parameters(spec, c) for c in reversed(range(spec.n_chunks))][::-1]
    for a, b in zip(forward, backward):
        assert all(np.array_equal(a[k], b[k]) for k in a)
    assert [len(p["nu"]) for p in forward] == [3, 3, 3, 3, 2]
    # chunks are different streams of SeedSequence(seed, spawn_key=(chunk,))
    assert not np.array_equal(forward[0]["E_Pa"], forward[1]["E_Pa"])
    rng = np.random.default_rng(np.random.SeedSequence(5, spawn_key=(2,)))
    lo, hi = np.log(1e7), np.log(1e9)
    assert np.array_equal(forward[2]["E_Pa"], np.exp(rng.uniform(lo, hi, 3)))


def test_a_billion_rows_are_allowed_and_cost_one_chunk_of_memory(tmp_path):
    text = RANDOM_KV.replace("rows = 14", "rows = 1_000_000_000").replace(
        "chunk_size = 3", "chunk_size = 1000")
    spec = load_spec(write(tmp_path, text))
    assert spec.rows == 10**9 and spec.table_layout == "dataset"
    last = chunk_parameters(spec, spec.n_chunks - 1)
    assert len(last["E_Pa"]) == 1000 and spec.chunk_rows(spec.n_chunks - 1)[1] == 10**9


def test_grid_rows_equal_the_dimensionless_scenes_bit_for_bit(tmp_path):
    """The vectorized reference scene is Scene.from_dimensionless, float for float."""
    spec = load_spec(write(tmp_path, GRID_SS))
    table = runner.compute_chunk(spec, 1).to_pandas()
    scenes = [v.Scene.from_dimensionless(r.Q1, r.nu, r.Q2, theta_ratio=r.theta_ratio)
              for r in table.itertuples()]
    ref = v.simulate_batch(scenes, spec.numerics)
    for col, src in runner.RESULTS.items():
        assert np.array_equal(table[col], ref[src], equal_nan=True), col
    assert np.array_equal(table.G1_Pa, [s.material.G_inf for s in scenes])
    assert np.array_equal(table.G2_Pa, [s.material.arms[0][0] for s in scenes])
    assert list(table.row) == list(range(5, 10))


@pytest.mark.parametrize("text", [
    'model = "standard_solid"\nseed = 3\nchunk_size = 6\n[numerics]\nsteps = 100\n'
    'elements = 20\n[random]\nrows = 6\nG1_Pa = [1e6, 1e9]\nG2_Pa = [1e6, 1e9]\n'
    'eta_Pa_s = {choice = [0.0, 10.0, 1e3]}\nR_m = 0.01\nm_kg = [1e-3, 1e-2]\n'
    'v_z0_m_s = 1.0\nv_x0_m_s = {choice = [0.0, 1.0]}\nnu = 0.4\n',
    'model = "prony"\nseed = 3\nchunk_size = 4\n[numerics]\nsteps = 100\nelements = 20\n'
    '[random]\nrows = 4\nG_Pa = [1e6, 1e8]\neta_Pa_s = [0, 10]\nR_m = 0.01\nm_kg = 1e-3\n'
    'v_z0_m_s = 1.0\nv_x0_m_s = 0.5\nnu = {choice = [0.4, 0.6]}\n'
    '[[random.arms]]\nG_Pa = [1e6, 1e8]\ntau_s = [1e-6, 1e-3]\n',
], ids=["standard_solid", "prony"])
def test_random_rows_equal_their_scenes_bit_for_bit(tmp_path, text):
    """The columnar chunk equals simulate_batch of the rows' Scene objects, float for
    float (a standard solid without dashpot has no arm; nu = 0.6 is an invalid row)."""
    spec = load_spec(write(tmp_path, text))
    table = runner.compute_chunk(spec, 0).to_pandas()
    params = spec.chunk_parameters(0)
    valid = []
    for i in range(len(table)):
        try:
            valid.append((i, spec.scene(params, i)))
        except ValueError as exc:
            assert table.status[i] == "invalid" and "nu" in table.error[i] and "nu" in str(exc)
    rows = [i for i, _ in valid]
    ref = v.simulate_batch([s for _, s in valid], spec.numerics)
    for col, src in runner.RESULTS.items():
        assert np.array_equal(table[col].to_numpy()[rows], ref[src], equal_nan=True), col
    assert list(table.status[rows]) == list(ref.status)
    if spec.model == "standard_solid":
        assert np.array_equal(table.Q2[rows], [s.Q2 for _, s in valid])  # inf without arm
        assert np.isinf(table.Q2[table.eta_Pa_s == 0]).all()


# ---- backends -----------------------------------------------------------------

def test_chunks_in_any_order_give_the_same_table(tmp_path, reference):
    spec, ref = reference
    order = [3, 0, 4, 2, 1]
    out = run_sweep(spec, out=tmp_path / "shuffled.parquet", progress=False, chunk_order=order)
    assert out.read_bytes() == ref.read_bytes()


def test_shards_then_combine_equal_the_whole(tmp_path, reference):
    spec, ref = reference
    out = tmp_path / "sharded.parquet"
    for i in range(3):
        assert run_sweep(spec, out=out, progress=False, shard=(i, 3)) == parts_dir(out)
        assert not out.exists()
    names = sorted(p.name for p in parts_dir(out).glob("part-*.parquet"))
    assert len(names) == 5
    assert run_sweep(spec, out=out, progress=False, combine=True) == out
    assert out.read_bytes() == ref.read_bytes() and not parts_dir(out).exists()


def test_combine_refuses_missing_chunks(tmp_path, reference):
    spec, _ = reference
    out = tmp_path / "partial.parquet"
    run_sweep(spec, out=out, progress=False, shard=(1, 3))
    with pytest.raises(ValueError, match="3 of 5 chunks are missing"):
        run_sweep(spec, out=out, progress=False, combine=True)


@pytest.fixture(scope="module")
def dask_cluster():
    """A real LocalCluster of one worker process, shared by the tests that need one.

    One worker is enough for what these tests check (tasks run in another process, with
    one numba thread, and give the in-process table) and costs half the worker start-ups
    (each imports distributed, numba, the kernels, pandas and pyarrow). It also makes the
    sweep refill its queue: one worker has 4 task slots for the reference spec's 5 chunks.
    Two workers: the slow test_kill_9_during_a_dask_sweep_then_resume (``--workers 2``) and
    tests/faults/test_dask_cluster.py (one of the two killed).
    """
    pytest.importorskip("distributed")
    from distributed import Client
    cluster = runner.local_cluster(1)
    client = Client(cluster)
    yield cluster, client
    client.close()
    cluster.close()


def test_dask_cluster_equals_in_process_bit_for_bit(tmp_path, reference, dask_cluster):
    cluster, client = dask_cluster
    spec, ref = reference
    out = run_sweep(spec, out=tmp_path / "dask.parquet", progress=False,
                    scheduler=cluster.scheduler_address)
    assert out.read_bytes() == ref.read_bytes()


def test_dask_workers_run_numba_on_one_thread(tmp_path, reference, dask_cluster):
    cluster, client = dask_cluster

    def threads():
        import numba
        return os.environ.get("NUMBA_NUM_THREADS"), numba.config.NUMBA_NUM_THREADS

    assert set(client.run(threads).values()) == {("1", 1)}
    spec, _ = reference
    parts = tmp_path / "parts"
    parts.mkdir()
    summary = client.submit(runner._dask_task, load_spec(spec), 0, str(parts)).result()
    assert summary["numba_threads"] == 1 and summary["pid"] != os.getpid()
    assert summary["rows"] == 3 and sum(summary["counts"].values()) == 3


@pytest.mark.slow
def test_kill_9_during_a_dask_sweep_then_resume(tmp_path):
    """Kill the whole process group of `vimpact sweep --workers 2` once parts exist;
    --resume (in-process) gives the table of an uninterrupted run, byte for byte."""
    text = RANDOM_KV.replace("rows = 14", "rows = 24").replace("chunk_size = 3", "chunk_size = 2")
    text = text.replace("steps = 100", "steps = 3000").replace("elements = 20", "elements = 60")
    spec = write(tmp_path, text)
    out = tmp_path / "killed.parquet"
    proc = subprocess.Popen([sys.executable, "-m", "vimpact.cli", "sweep", str(spec), "--workers",
                             "2", "--out", str(out)], cwd=tmp_path, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    parts = parts_dir(out)
    deadline = time.monotonic() + 900  # a cold numba cache compiles for minutes
    while time.monotonic() < deadline and len(list(parts.glob("part-*.parquet"))) < 3:
        assert proc.poll() is None, "the sweep ended before it could be killed"
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    time.sleep(1.0)
    kept = len(list(parts.glob("part-*.parquet")))
    assert 3 <= kept < 12 and not out.exists()
    resumed = run_sweep(spec, out=out, resume=True, progress=False)
    full = run_sweep(spec, out=tmp_path / "full.parquet", progress=False)
    assert resumed.read_bytes() == full.read_bytes()


# ---- dataset layout -------------------------------------------------------------

def test_dataset_layout_reads_back_as_a_table(tmp_path, reference, main, capsys):
    spec, ref = reference
    ds_spec = write(tmp_path, 'layout = "dataset"\n' + RANDOM_KV, "dataset.toml")
    out = run_sweep(ds_spec, out=tmp_path / "ds.parquet", progress=False)
    assert out.is_dir() and (out / "_common_metadata").is_file()
    assert len(list(out.glob("part-*.parquet"))) == 5
    table = v.RestitutionTable.open(out)
    expected = v.RestitutionTable.open(ref).data
    pd.testing.assert_frame_equal(table.data, expected)
    pd.testing.assert_frame_equal(pd.read_parquet(out), pd.read_parquet(ref))
    meta = read_metadata(out)
    assert meta["layout"] == "dataset" and meta["rows"] == 14 and "chunk" not in meta
    assert table.meta("rows") == 14 and table.meta("paths") == read_metadata(ref)["paths"]
    assert table.model == "kelvin_voigt" and table.units["E_Pa"] == "Pa"
    assert main(["table", "info", str(out)]) == 0
    assert "14" in capsys.readouterr().out
    # an unfinished dataset is refused with a hint
    (out / "_common_metadata").unlink()
    with pytest.raises(ValueError, match="unfinished"):
        v.RestitutionTable.open(out)
    assert run_sweep(ds_spec, out=out, resume=True, progress=False) == out
    pd.testing.assert_frame_equal(v.RestitutionTable.open(out).data, expected)


def test_metadata_codec_round_trips():
    values = {"rows": 12, "seed": 3, "rotation": False, "paths": {"a": {"rows": 2}},
              "units": {"e_z": "1"}, "model": "prony", "description": "12"}
    raw = metadata.encode_metadata(values)
    assert raw[b"vimpact.rotation"] == b"false" and raw[b"vimpact.rows"] == b"12"
    assert metadata.decode_metadata(raw) == values


# ---- command line: progress, output checks, lock -----------------------------------

@pytest.fixture
def main():
    return cli.main


def test_progress_lines_off_a_terminal(tmp_path, main, capsys, monkeypatch):
    monkeypatch.setenv("VIMPACT_PROGRESS_SECONDS", "0")
    spec = write(tmp_path, GRID_SS)
    assert main(["sweep", str(spec), "--out", str(tmp_path / "p.parquet")]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if "rows/s" in line]
    assert len(lines) >= 4  # one per chunk, one at the end
    assert "5/16 rows" in lines[0] and "16/16 rows (100.0 %)" in lines[-1]


@pytest.mark.parametrize("make, what", [
    (lambda t: t / "a_directory.parquet", "is a directory"),
    (lambda t: t / "table.csv", "must end in .parquet"),
    (lambda t: t / "locked" / "x.parquet", "not a writable directory"),
])
def test_bad_output_is_refused_before_any_work(tmp_path, main, capsys, monkeypatch, make, what):
    (tmp_path / "a_directory.parquet").mkdir()
    (tmp_path / "locked").mkdir(mode=0o500)
    if what.startswith("not a writable") and os.access(tmp_path / "locked", os.W_OK):
        pytest.skip("running as a user who can write anywhere")
    monkeypatch.setattr(runner, "compute_chunk", lambda *a: pytest.fail("computed"))
    assert main(["sweep", str(write(tmp_path, GRID_SS)), "--out", str(make(tmp_path))]) == 2
    err = capsys.readouterr().err
    assert what in err and err.count("\n") == 1


def test_a_second_sweep_into_the_same_output_is_refused(tmp_path, main, capsys, monkeypatch):
    out = tmp_path / "t.parquet"
    monkeypatch.setattr(runner, "compute_chunk", lambda *a: pytest.fail("computed"))
    with files.OutputLock(out):
        assert main(["sweep", str(write(tmp_path, GRID_SS)), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "another sweep is writing" in err and str(out) in err
    assert not out.with_name("t.parquet.lock").exists()  # released and removed


def test_a_bad_output_key_in_the_spec_is_named_as_the_spec_key(tmp_path, main, capsys):
    spec = write(tmp_path, 'output = "t.csv"\n' + GRID_SS)
    assert main(["sweep", str(spec)]) == 2
    err = capsys.readouterr().err
    assert f"output (in {spec})" in err and "--out" not in err and err.count("\n") == 1
