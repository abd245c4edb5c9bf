"""The chunk size a grid sweep without ``chunk_size`` gets: chosen once from the measured
cost of its rows, recorded in the parts directory, reused by --resume, shards and
--combine; a random spec keeps its per-chunk draws; --workers on a small sweep says so."""

import json

import pyarrow.parquet as pq
import pytest

from tests.sweep import write
from vimpact.sweep import load_spec, parts_dir, read_metadata, run_sweep, runner
from vimpact.sweep.spec import (
    AUTO_CHUNK_ROWS,
    AUTO_CHUNK_SECONDS,
    CHUNK_SIZE_FILE,
    DEFAULT_CHUNK_SIZE,
    ONE_CHUNK_SECONDS,
)

GRID = """
model = "kelvin_voigt"
tangential = "none"
{chunk}
[grid]
Q1 = {{ start = 0.01, stop = 1.0, num = 20 }}
nu = [0.0, 0.5]
"""

RANDOM = """
model = "kelvin_voigt"
seed = 3
tangential = "none"
[random]
rows = 70
E_Pa = [1e7, 1e9]
eta_Pa_s = [1.0, 1e4]
R_m = 0.01
m_kg = [1e-4, 1e-2]
v_z0_m_s = [0.5, 5.0]
nu = 0.4
"""


def _choose(monkeypatch, sizes):
    """Make the runner choose ``sizes`` in turn (what a measurement would give)."""
    made = []

    def choose(spec, units=1):
        made.append(units)
        return {"chunk_size": sizes[len(made) - 1], "seconds_per_row": 1e-5, "probe_rows": 8,
                "units": units}

    monkeypatch.setattr(runner, "choose_chunk_size", choose)
    return made


def _table(path):
    """The rows of a table (a DataFrame: NaN equals NaN in ``equals``)."""
    return pq.read_table(path).to_pandas()


def test_a_spec_without_chunk_size_lets_the_runner_choose_a_grid_only(tmp_path):
    grid = load_spec(write(tmp_path, GRID.format(chunk=""), "grid.toml"))
    fixed = load_spec(write(tmp_path, GRID.format(chunk="chunk_size = 64"), "fixed.toml"))
    rand = load_spec(write(tmp_path, RANDOM, "random.toml"))
    assert grid.chooses_chunk_size and not fixed.chooses_chunk_size
    # random rows are drawn per chunk: the default chunk size keeps them
    assert not rand.chooses_chunk_size and rand.chunk_size == DEFAULT_CHUNK_SIZE
    out = run_sweep(write(tmp_path, RANDOM, "random.toml"), out=tmp_path / "r.parquet",
                    progress=False)
    assert read_metadata(out)["chunk_size"] == DEFAULT_CHUNK_SIZE


def test_the_chosen_size_is_recorded_and_gives_the_table_of_that_size(tmp_path, monkeypatch):
    _choose(monkeypatch, [7])
    spec = write(tmp_path, GRID.format(chunk=""))
    logged = []
    parts = parts_dir(tmp_path / "auto.parquet")
    chosen = runner.chunked(load_spec(spec), parts, True, 1, logged.append)
    assert chosen.chunk_size == 7 and chosen.n_chunks == 6  # 40 rows
    assert json.loads((parts / CHUNK_SIZE_FILE).read_text())["chunk_size"] == 7
    assert "7 rows per chunk" in logged[0]
    out = run_sweep(spec, out=tmp_path / "auto.parquet", progress=False)
    assert read_metadata(out)["chunk_size"] == 7
    assert not parts.exists()  # the record leaves with the parts
    same = run_sweep(write(tmp_path, GRID.format(chunk="chunk_size = 7"), "seven.toml"),
                     out=tmp_path / "seven.parquet", progress=False)
    assert _table(out).equals(_table(same))
    other = run_sweep(write(tmp_path, GRID.format(chunk="chunk_size = 64"), "one.toml"),
                      out=tmp_path / "one.parquet", progress=False)
    assert _table(out).equals(_table(other))  # grid rows do not depend on the chunking


def test_one_chosen_chunk_leaves_no_record_and_its_part_holds_the_size(tmp_path, monkeypatch):
    """A chosen chunk of all the rows makes no parts directory in process (nothing to
    resume: an interrupt leaves nothing behind); written as a part (a shard), the part's
    metadata gives its size to --combine, which chooses nothing."""
    made = _choose(monkeypatch, [40, 40])
    spec = write(tmp_path, GRID.format(chunk=""))
    out = tmp_path / "one.parquet"

    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(spec, out=out, progress=stop)
    assert not parts_dir(out).exists() and not out.exists()
    table = run_sweep(spec, out=out, progress=False)
    assert read_metadata(table)["chunk_size"] == 40 and made == [1, 1]
    shard = tmp_path / "shard.parquet"
    _choose(monkeypatch, [40])
    parts = run_sweep(spec, out=shard, shard=(0, 1), progress=False)
    assert sorted(p.name for p in parts.iterdir()) == ["part-00000.parquet"]
    made = _choose(monkeypatch, [])  # --combine must not choose
    run_sweep(spec, out=shard, combine=True, progress=False)
    assert made == [] and _table(shard).equals(_table(table))


def test_resume_uses_the_recorded_size(tmp_path, monkeypatch):
    made = _choose(monkeypatch, [7, 11])
    spec = write(tmp_path, GRID.format(chunk=""))
    out = tmp_path / "t.parquet"

    def stop(done, total):
        if done >= 14:
            raise KeyboardInterrupt

    with pytest.raises(runner.SweepInterrupted):
        run_sweep(spec, out=out, progress=stop)
    parts = parts_dir(out)
    assert len(list(parts.glob("part-*.parquet"))) == 2
    resumed = run_sweep(spec, out=out, resume=True, progress=False)
    assert made == [1]  # chosen once; the resumed run read the record
    assert read_metadata(resumed)["chunk_size"] == 7
    whole = run_sweep(write(tmp_path, GRID.format(chunk="chunk_size = 7"), "seven.toml"),
                      out=tmp_path / "whole.parquet", progress=False)
    assert _table(resumed).equals(_table(whole))


def test_resume_without_the_record_reads_the_size_from_the_parts(tmp_path, monkeypatch):
    _choose(monkeypatch, [7, 11])
    spec = write(tmp_path, GRID.format(chunk=""))
    out = tmp_path / "t.parquet"

    def stop(done, total):
        if done >= 7:
            raise KeyboardInterrupt

    with pytest.raises(runner.SweepInterrupted):
        run_sweep(spec, out=out, progress=stop)
    (parts_dir(out) / CHUNK_SIZE_FILE).unlink()
    assert runner.recorded_chunk_size(load_spec(spec), parts_dir(out)) == 7
    assert read_metadata(run_sweep(spec, out=out, resume=True, progress=False))["chunk_size"] == 7


def test_shards_and_combine_share_one_choice(tmp_path, monkeypatch):
    made = _choose(monkeypatch, [5, 9, 13])
    spec = write(tmp_path, GRID.format(chunk=""))
    out = tmp_path / "s.parquet"
    run_sweep(spec, out=out, shard=(1, 3), progress=False)
    run_sweep(spec, out=out, shard=(0, 3), progress=False)
    run_sweep(spec, out=out, shard=(2, 3), progress=False)
    assert made == [3]  # the first shard chose (for 3 shards), the others read it
    parts = parts_dir(out)
    sizes = {pq.read_schema(p).metadata[b"vimpact.chunk_size"] for p in parts.glob("part-*")}
    assert sizes == {b"5"} and len(list(parts.glob("part-*"))) == 8
    table = run_sweep(spec, out=out, combine=True, progress=False)
    assert read_metadata(table)["chunk_size"] == 5


def test_combine_without_parts_chooses_nothing(tmp_path, monkeypatch):
    made = _choose(monkeypatch, [5])
    spec = write(tmp_path, GRID.format(chunk=""))
    with pytest.raises(ValueError, match="missing"):
        run_sweep(spec, out=tmp_path / "c.parquet", combine=True, progress=False)
    assert made == []


def test_the_rule_work_per_chunk_bounds_and_workers(tmp_path, monkeypatch):
    small = load_spec(write(tmp_path, GRID.format(chunk="")))  # 40 rows
    big = load_spec(write(tmp_path, GRID.format(chunk="").replace("num = 20", "num = 100_000"),
                          "big.toml"))  # 200,000 rows
    lo, hi = AUTO_CHUNK_ROWS
    for cost, want in ((1e-7, hi), (1e-1, lo), (1e-3, 1000)):
        monkeypatch.setattr(runner, "seconds_per_row", lambda s, cost=cost, **_: (cost, 8))
        assert runner.choose_chunk_size(big)["chunk_size"] == want
    monkeypatch.setattr(runner, "seconds_per_row", lambda s, **_: (1e-7, 8))
    assert runner.choose_chunk_size(small)["chunk_size"] == 40  # not more than the rows
    assert runner.choose_chunk_size(big, units=2)["chunk_size"] == 200_000 // 8


def test_a_sweep_of_little_work_is_one_chunk(tmp_path, monkeypatch):
    """Up to ONE_CHUNK_SECONDS of work (one process, at most AUTO_CHUNK_ROWS[1] rows) a
    sweep is one chunk (no part written and then the table); beyond it, chunks of about
    AUTO_CHUNK_SECONDS; with workers or shards, chunks to share."""
    small = load_spec(write(tmp_path, GRID.format(chunk="")))  # 40 rows
    for work, want in ((0.99 * ONE_CHUNK_SECONDS, 40),
                       (1.01 * ONE_CHUNK_SECONDS, int(AUTO_CHUNK_SECONDS * 40 / (
                           1.01 * ONE_CHUNK_SECONDS)))):  # 19 rows: about 1 s each
        monkeypatch.setattr(runner, "seconds_per_row", lambda s, c=work / 40, **_: (c, 8))
        assert runner.choose_chunk_size(small)["chunk_size"] == want
    # two workers: chunks to share (at least AUTO_CHUNK_ROWS[0] rows each)
    assert runner.choose_chunk_size(small, units=2)["chunk_size"] == AUTO_CHUNK_ROWS[0]
    big = load_spec(write(tmp_path, GRID.format(chunk="").replace("num = 20", "num = 60_000"),
                          "big.toml"))  # 120,000 rows: more than a chunk holds
    monkeypatch.setattr(runner, "seconds_per_row", lambda s, **_: (1e-9, 8))
    assert runner.choose_chunk_size(big)["chunk_size"] == AUTO_CHUNK_ROWS[1]


def test_the_probe_of_a_sweep_that_is_surely_one_chunk_stops_at_its_first_batch(
        tmp_path, monkeypatch):
    """The first probe batch's time per row bounds the cost from above (its fixed cost
    is in it): when even that makes the sweep at most ONE_CHUNK_SECONDS of work, it is
    one chunk without a longer probe; with two workers the probe goes on to
    PROBE_SECONDS. An engine of 1 ms per batch plus 0.1 ms per row stands in."""
    def engine(spec, cols, timings=None):
        if timings is not None:
            timings["total_s"] = timings.get("total_s", 0.0) + 1e-3 + 1e-4 * len(cols["nu"])
        return {}

    monkeypatch.setattr(runner, "run_batch", engine)
    spec = load_spec(write(tmp_path, GRID.format(chunk="").replace("num = 20", "num = 1000")))
    one = runner.choose_chunk_size(spec)  # 2000 rows: at most 0.23 s of work
    assert one["probe_rows"] == 64 and one["chunk_size"] == 2000
    assert one["seconds_per_row"] == pytest.approx(1e-4 + 1e-3 / 64)
    two = runner.choose_chunk_size(spec, units=2)
    assert two["probe_rows"] > 64 and two["probe_rows"] * 1e-4 + 1e-3 >= runner.PROBE_SECONDS


def test_workers_on_a_small_sweep_says_so(tmp_path, monkeypatch, capsys):
    """One stderr line, then the run goes on as asked (here the cluster is replaced
    by running the chunks in process)."""
    def no_cluster(spec, todo, parts, bar, done, workers, scheduler):
        for chunk in todo:
            runner.run_chunk(spec, chunk, str(parts))
            done[chunk] = parts / "x"

    monkeypatch.setattr(runner, "_run_dask", no_cluster)
    spec = write(tmp_path, GRID.format(chunk="chunk_size = 10"))
    run_sweep(spec, out=tmp_path / "w.parquet", workers=2, progress=False)
    lines = [x for x in capsys.readouterr().err.splitlines() if "--workers" in x]
    assert len(lines) == 1
    assert lines[0].startswith("vimpact sweep: --workers 2: this sweep (40 rows, about ")
    assert "too small to pay for starting a cluster" in lines[0]
    monkeypatch.setattr(runner, "seconds_per_row", lambda s, probe_chunks=8: (1.0, 8))
    run_sweep(spec, out=tmp_path / "big.parquet", workers=2, progress=False)
    assert "--workers" not in capsys.readouterr().err


def test_chunk_summary_counts_as_numpy_does():
    """The part summary (Arrow's counts) against a NumPy count of the same columns."""
    import numpy as np
    import pyarrow as pa

    rng = np.random.default_rng(4)
    n = 5000
    status = rng.choice(["ok", "normal_only", "invalid", "unstable"], n).astype(object)
    path = rng.choice(["continuum[kelvin_voigt,normal]", "elements[verlet,dashpot]", "z"], n)
    path = np.where(status == "invalid", None, path).astype(object)
    rows = np.arange(n) + 1000
    table = pa.table({"row": rows, "status": pa.array(status, pa.string()),
                      "path": pa.array(path, pa.string())})
    got = runner.chunk_summary(table)
    names, counts = np.unique(status.astype(str), return_counts=True)
    assert list(got["counts"].items()) == [(str(a), int(b)) for a, b in zip(names, counts)]
    has = path != None  # noqa: E711 - elementwise
    labels, first, count = np.unique(path[has].astype(str), return_index=True,
                                     return_counts=True)
    assert list(got["paths"].items()) == [
        (str(lab), {"rows": int(c), "first_row": int(rows[has][f])})
        for lab, f, c in zip(labels, first, count)]


@pytest.mark.parametrize("text", ["grid_oblique", "random_with_invalid"])
def test_summary_from_the_codes_is_the_tables(tmp_path, text):
    """compute_chunk's summary, counted from its status and path codes, against
    chunk_summary of the table it returns (whole chunks and parts of them)."""
    from tests.sweep.test_pipelined import GRID, RANDOM

    name, text = text, {"grid_oblique": GRID.format(tangential="auto"),
            # nu beyond 0.5 in some rows: invalid rows, with no path
            "random_with_invalid": RANDOM.replace("nu = [0.0, 0.5]", "nu = [0.3, 0.7]")}[text]
    spec = load_spec(write(tmp_path, text))
    seen = set()
    for chunk in range(spec.n_chunks):
        start, stop = spec.chunk_rows(chunk)
        for part in (None, (1, stop - start)):
            summary: dict = {}
            table = runner.compute_chunk(spec, chunk, None, part, None, summary)
            assert summary == runner.chunk_summary(table)
            seen |= set(summary["counts"])
    if name == "random_with_invalid":  # rows without a path, several statuses
        assert "invalid" in seen and len(seen) > 1
