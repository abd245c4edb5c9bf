"""A one-chunk sweep written in row groups while it is computed (files.TableStream).

The rows of a chunk of more than ``ROW_GROUP_ROWS`` rows are computed in pieces of that
many rows and each piece is hashed and encoded on a thread while the next is computed
(the stream itself takes pieces of any rows and encodes a row group once its rows are
all there).
The table must be the one written from the whole chunk, byte for byte (the same row
groups, metadata and content hash, :mod:`tests.oracles.content_hash` row by row), and an
interruption between pieces must leave nothing behind.
"""

import threading
import time

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from tests.oracles.content_hash import definition_hash
from tests.sweep import write
from tests.sweep.faults import FullDisk
from vimpact.sweep import (
    SweepInterrupted,
    load_spec,
    parts_dir,
    read_metadata,
    run_sweep,
    runner,
)
from vimpact.tableformat import files
from vimpact.tableformat.integrity import verify_table

#: 24 rows (Q1 fastest), one chunk; pieces of 5 rows below: 5 row groups, the last of 4
GRID = """
model = "kelvin_voigt"
chunk_size = 24
tangential = "{tangential}"
[numerics]
steps = 100
elements = 20
[grid]
Q1 = {{ start = 0.01, stop = 1.0, num = 6 }}
nu = [0.0, 0.2, 0.4, 0.5]
"""

RANDOM = """
model = "standard_solid"
seed = 11
chunk_size = 13
[numerics]
steps = 100
elements = 20
[random]
rows = 13
G1_Pa = [1e7, 1e9]
G2_Pa = [1e6, 1e9]
eta_Pa_s = { choice = [0.0, 10.0, 1e3] }
R_m = 0.01
m_kg = [1e-4, 1e-2]
v_z0_m_s = [0.5, 5.0]
v_x0_m_s = [-1.0, 1.0]
nu = [0.0, 0.5]
"""


def _pieces(monkeypatch, rows=5):
    monkeypatch.setattr(files, "ROW_GROUP_ROWS", rows)


def _table_rows(monkeypatch, tmp_path, text, name):
    """The table of ``text`` written whole (one piece) and in pieces of 5 rows."""
    spec = write(tmp_path, text, f"{name}.toml")
    whole = run_sweep(spec, out=tmp_path / f"{name}_whole.parquet", progress=False)
    _pieces(monkeypatch)
    streamed = []
    monkeypatch.setattr(runner, "_stream_one_chunk",
                        lambda *a: streamed.append(1) or real_stream(*a))
    piecewise = run_sweep(spec, out=tmp_path / f"{name}_pieces.parquet", progress=False)
    assert streamed == [1]
    return spec, whole, piecewise


real_stream = runner._stream_one_chunk


@pytest.mark.parametrize("text", [GRID.format(tangential="none"),
                                  GRID.format(tangential="auto"), RANDOM],
                         ids=["grid_normal", "grid_oblique", "random_standard_solid"])
def test_pieces_give_the_rows_and_content_hash_of_the_whole_chunk(monkeypatch, tmp_path, text):
    spec, whole, piecewise = _table_rows(monkeypatch, tmp_path, text, "t")
    a, b = pq.read_table(whole), pq.read_table(piecewise)
    assert a.schema.equals(b.schema, check_metadata=False) and a.num_rows == b.num_rows
    for name in a.column_names:  # NaN where NaN, the same bytes elsewhere
        x, y = a.column(name).to_pylist(), b.column(name).to_pylist()
        assert [repr(v) for v in x] == [repr(v) for v in y], name
    ma, mb = read_metadata(whole), read_metadata(piecewise)
    assert ma == mb  # the same paths, content hash, sweep hash
    assert mb["content_sha256"] == definition_hash(b)  # the row-by-row oracle
    assert pq.ParquetFile(whole).metadata.num_row_groups == 1
    groups = pq.ParquetFile(piecewise).metadata
    assert [groups.row_group(g).num_rows for g in range(groups.num_row_groups)] == \
        [5] * (a.num_rows // 5) + ([a.num_rows % 5] if a.num_rows % 5 else [])
    assert verify_table(piecewise).startswith(f"ok: {a.num_rows} rows")
    assert not parts_dir(piecewise).exists()


def test_streamed_table_is_byte_identical_to_the_parts_combined(monkeypatch, tmp_path):
    """The same sweep in 5-row row groups: streamed, and as a part combined (no stream)."""
    _pieces(monkeypatch)
    spec = write(tmp_path, GRID.format(tangential="auto"))
    streamed = run_sweep(spec, out=tmp_path / "streamed.parquet", progress=False)
    out = tmp_path / "combined.parquet"
    run_sweep(spec, out=out, shard=(0, 1), progress=False)  # the chunk as a part
    assert run_sweep(spec, out=out, combine=True, progress=False) == out
    assert pq.ParquetFile(out).metadata.num_row_groups == 5
    assert out.read_bytes() == streamed.read_bytes()


def test_table_stream_bytes_equal_write_atomic(monkeypatch, tmp_path):
    """A table written whole (both ways write_atomic takes) and from its row groups."""
    _pieces(monkeypatch, 4)
    n = 18
    table = pa.table({"row": np.arange(n), "x": np.linspace(0.0, 1.0, n),
                      "nan": np.full(n, np.nan),
                      "text": pa.array(["a", None, "bc"] * 6, type=pa.string())})
    meta = {b"vimpact.spec": b"{}", b"other": b"kept"}
    table = table.replace_schema_metadata(meta)
    plain = tmp_path / "plain.parquet"
    digest = files.write_atomic(table, plain)
    monkeypatch.setattr(files, "PARALLEL_HASH_BYTES", 0)  # hashed while encoded
    hashing = tmp_path / "hashing.parquet"
    assert files.write_atomic(table, hashing) == digest
    streamed = tmp_path / "streamed.parquet"
    with files.TableStream(streamed, table.schema) as stream:
        for lo in range(0, n, 4):
            stream.add(table.slice(lo, 4))
        assert not streamed.exists()  # replaced only when the block ends
        assert stream.finish(meta) == digest == definition_hash(table)
    assert plain.read_bytes() == hashing.read_bytes() == streamed.read_bytes()
    assert pq.ParquetFile(streamed).metadata.num_row_groups == 5


@pytest.mark.parametrize("cuts", [[0, 3, 7, 8, 10, 18], [0, 9, 18], [0, 1, 2, 3, 4, 17, 18]],
                         ids=["across_row_groups", "two_halves", "ones_then_rest"])
def test_table_stream_joins_pieces_into_the_same_row_groups(monkeypatch, tmp_path, cuts):
    """Pieces of any rows, across row groups: the file of the rows written whole."""
    _pieces(monkeypatch, 4)
    n = 18
    table = pa.table({"row": np.arange(n), "x": np.linspace(0.0, 1.0, n),
                      "text": pa.array(["a", None, "bc"] * 6, type=pa.string())})
    meta = {b"vimpact.spec": b"{}"}
    plain = tmp_path / "plain.parquet"
    digest = files.write_atomic(table.replace_schema_metadata(meta), plain)
    streamed = tmp_path / "streamed.parquet"
    with files.TableStream(streamed, table.schema) as stream:
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            stream.add(table.slice(lo, hi - lo))
        assert stream.finish(meta) == digest == definition_hash(table)
    assert plain.read_bytes() == streamed.read_bytes()
    assert pq.ParquetFile(streamed).metadata.num_row_groups == 5


def test_table_stream_closed_before_finish_keeps_the_old_file(monkeypatch, tmp_path):
    _pieces(monkeypatch, 4)
    table = pa.table({"x": np.arange(10.0)})
    path = tmp_path / "t.parquet"
    path.write_bytes(b"earlier")
    with pytest.raises(ValueError, match="closed before finish"):
        with files.TableStream(path, table.schema) as stream:
            stream.add(table.slice(0, 3))
            stream.add(table.slice(3, 4))
    assert path.read_bytes() == b"earlier"
    assert [p.name for p in tmp_path.iterdir()] == ["t.parquet"]  # no temporary left


def test_interruption_between_pieces_keeps_nothing_and_runs_again(monkeypatch, tmp_path):
    _pieces(monkeypatch)
    spec = write(tmp_path, GRID.format(tangential="none"))
    clean = run_sweep(spec, out=tmp_path / "clean.parquet", progress=False)
    out = tmp_path / "t.parquet"
    seen = []

    def interrupt(done, total):  # after the second piece: two row groups in the file
        seen.append(done)
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(SweepInterrupted, match="0 of 1 chunks"):
        run_sweep(spec, out=out, progress=interrupt)
    assert seen == [5, 10]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clean.parquet", "spec.toml"]
    again = []
    assert run_sweep(spec, out=out, resume=True, progress=lambda d, t: again.append(d)) == out
    assert again == [5, 10, 15, 20, 24]
    assert out.read_bytes() == clean.read_bytes()


def test_an_interruption_starts_no_piece_beyond_the_ones_queued(monkeypatch, tmp_path):
    """Pieces run and queued ahead (at most twice the pieces side by side) may finish;
    none is submitted after the interruption: the last piece is never computed."""
    _pieces(monkeypatch)
    spec = write(tmp_path, GRID.format(tangential="none"))
    real, parts = runner.compute_chunk, []

    def recorded(*args):
        parts.append(args[3])
        return real(*args)

    def interrupt(done, total):
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "compute_chunk", recorded)
    with pytest.raises(SweepInterrupted):
        run_sweep(spec, out=tmp_path / "t.parquet", progress=interrupt)
    assert 1 <= len(parts) <= 2 * runner.PIECES_IN_FLIGHT and (20, 24) not in parts
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spec.toml"]


def test_disk_full_while_streaming_keeps_nothing(monkeypatch, tmp_path):
    _pieces(monkeypatch)
    spec = write(tmp_path, GRID.format(tangential="none"))
    out = tmp_path / "t.parquet"
    monkeypatch.setattr(files, "open", FullDisk(files_ok=0, bytes_into_next=600),
                        raising=False)
    with pytest.raises(OSError, match="nothing is kept"):
        run_sweep(spec, out=out, progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spec.toml"]


def test_a_part_of_a_chunk_outside_it_is_refused(tmp_path):
    spec = load_spec(write(tmp_path, GRID.format(tangential="none")))
    for part in ((0, 0), (5, 4), (-1, 3), (20, 25)):
        with pytest.raises(ValueError, match=r"part = .* is not allowed: must be rows"):
            runner.compute_chunk(spec, 0, None, part)


@pytest.mark.parametrize("text", [GRID.format(tangential="none"), RANDOM],
                         ids=["grid", "random"])
def test_a_parts_parameter_sets_are_the_chunks_there(tmp_path, text):
    """A part's parameter sets, made for its rows (a grid) or cut from the chunk's
    draws (random): the chunk's values in those rows, bit for bit."""
    spec = load_spec(write(tmp_path, text))
    whole = spec.chunk_parameters(0)
    n = len(whole["nu"])
    for lo, hi in ((0, n), (0, 1), (3, 11), (n - 2, n)):
        part = spec.chunk_parameters(0, (lo, hi))
        assert part.keys() == whole.keys()
        for k, v in whole.items():
            assert part[k].tobytes() == v[lo:hi].tobytes(), (k, lo, hi)
    with pytest.raises(ValueError, match=r"part = \(5, 5\) is not allowed"):
        spec.chunk_parameters(0, (5, 5))


@pytest.mark.parametrize("threads", [1, 2])
def test_pieces_share_the_numba_threads(monkeypatch, tmp_path, threads):
    """On two numba threads two pieces run side by side, one thread each (once the
    threading layer takes launches from two threads); on one thread, one at a time."""
    import numba

    if numba.config.NUMBA_NUM_THREADS < 2:  # type: ignore[attr-defined]
        pytest.skip("one numba thread on this machine")
    spec = write(tmp_path, GRID.format(tangential="none"))
    run_sweep(spec, out=tmp_path / "warm.parquet", progress=False)  # a parallel launch
    if not runner._launches_side_by_side():
        pytest.skip(f"numba's {numba.threading_layer()} layer: one launch at a time")
    _pieces(monkeypatch)
    real, lock = runner.compute_chunk, threading.Lock()
    active, most, used = [0], [0], []

    def counted(*args):
        with lock:
            active[0] += 1
            most[0] = max(most[0], active[0])
            used.append(numba.get_num_threads())
        try:
            time.sleep(0.05)  # long enough for the next piece to start beside it
            return real(*args)
        finally:
            with lock:
                active[0] -= 1

    monkeypatch.setattr(runner, "compute_chunk", counted)
    before = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        out = run_sweep(spec, out=tmp_path / "t.parquet", progress=False)
    finally:
        numba.set_num_threads(before)
    assert len(used) == 5 and most[0] == threads
    assert set(used) == {1}
    whole = read_metadata(tmp_path / "warm.parquet")  # (one row group)
    assert read_metadata(out)["content_sha256"] == whole["content_sha256"]
