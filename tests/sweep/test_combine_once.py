"""The end of a sweep reads each part once and never reads the table it wrote back.

A one-chunk file-layout sweep is written straight to its table (no part); a small
one computed in one process is written from its chunks in memory (its parts, kept
for --resume, are not read back); either table is the one its parts would have
been combined into, byte for byte. Parts are
read (and hashed) once for their check, held in memory up to ``store.HOLD_ROWS``
rows and written from there; a larger table reads them once more to write them,
hashing the rows again: a part changed between its check and the write is
refused and the parts are kept. The table is checked by its footer (metadata
hash, stored content hash, rows); :func:`verify_table` accepts it.
"""

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from tests.sweep import GRID_KV, faults, write
from vimpact import cli
from vimpact.sweep import parts_dir, run_sweep, store
from vimpact.sweep.spec import load_spec
from vimpact.tableformat import files, integrity, metadata


class Reads:
    """Count the part files :func:`integrity.scan` and ``pq.read_table`` read."""

    def __init__(self, monkeypatch):
        self.scanned: list[str] = []
        self.read: list[str] = []
        scan, read_table = integrity.scan, pq.read_table

        def counted_scan(path, *args, **kwargs):
            self.scanned.append(path.name)
            return scan(path, *args, **kwargs)

        def counted_read(path, *args, **kwargs):
            self.read.append(getattr(path, "name", str(path)))
            return read_table(path, *args, **kwargs)
        monkeypatch.setattr(store, "scan", counted_scan)
        monkeypatch.setattr(pq, "read_table", counted_read)


def test_content_hash_fed_with_a_second_hash_gives_both_the_separate_digests():
    parts = [pa.table({"row": [0, 1], "e_z": [0.5, None], "s": ["ok", None]}),
             pa.table({"row": [2], "e_z": [float("nan")], "s": ["invalid"]})]
    whole = integrity.ContentHash()
    for part in parts:
        own = integrity.ContentHash().update(part, also=whole)
        assert own.hexdigest() == integrity.content_hash(part)
    assert whole.rows == 3
    assert whole.hexdigest() == integrity.content_hash(pa.concat_tables(parts))


def test_one_chunk_goes_straight_to_the_table_identical_to_its_combined_part(tmp_path,
                                                                          monkeypatch):
    spec = write(tmp_path, GRID_KV.format(chunk=6))
    reads = Reads(monkeypatch)
    out = run_sweep(spec, out=tmp_path / "straight.parquet", progress=False)
    assert reads.scanned == [] and reads.read == []  # nothing read back
    assert not parts_dir(out).exists() and not list(tmp_path.glob(".*.tmp"))
    assert integrity.verify_table(out) == ("ok: 6 rows, 1 row group(s), page checksums "
                                           "checked where stored, content hash verified")
    stored = metadata.read_metadata(out)
    assert stored["content_sha256"] == integrity.content_hash(pq.read_table(out))
    assert stored["paths"] and all(e["reasons"] for e in stored["paths"].values())
    # the same sweep as a shard (one part) then combined: one read of the part, same bytes
    other = tmp_path / "combined.parquet"
    run_sweep(spec, out=other, shard=(0, 1), progress=False)
    reads.scanned.clear()
    reads.read.clear()
    run_sweep(spec, out=other, combine=True, progress=False)
    assert reads.scanned == ["part-00000.parquet"] and reads.read == []
    assert other.read_bytes() == out.read_bytes()


def test_parts_are_read_once_and_the_table_is_not_read_back(tmp_path, monkeypatch):
    spec = write(tmp_path, GRID_KV.format(chunk=2))
    straight = run_sweep(write(tmp_path, GRID_KV.format(chunk=6), "one.toml"),
                         out=tmp_path / "one.parquet", progress=False)
    reads = Reads(monkeypatch)
    out = run_sweep(spec, out=tmp_path / "t.parquet", progress=False)
    # computed in this process: written from memory, its parts (for --resume) not read
    assert reads.scanned == [] and reads.read == []
    assert not parts_dir(out).exists()
    assert integrity.verify_table(out).startswith("ok: 6 rows, 3 row group(s)")
    # chunking changes the row groups, not the content hash
    assert metadata.read_metadata(out)["content_sha256"] \
        == metadata.read_metadata(straight)["content_sha256"]
    # the same parts from shards, then --combine: each read once, the same table
    other = tmp_path / "combined.parquet"
    run_sweep(spec, out=other, shard=(0, 1), progress=False)
    reads.scanned.clear()
    assert run_sweep(spec, out=other, combine=True, progress=False) == other
    assert reads.scanned == [f"part-0000{k}.parquet" for k in range(3)] and reads.read == []
    assert other.read_bytes() == out.read_bytes()


def test_above_hold_rows_a_part_changed_after_its_check_is_refused(tmp_path, monkeypatch):
    """Parts read twice (check, then write): the rows are hashed again as written."""
    spec = write(tmp_path, GRID_KV.format(chunk=2))
    clean = run_sweep(spec, out=tmp_path / "clean.parquet", progress=False).read_bytes()
    monkeypatch.setattr(store, "HOLD_ROWS", 0)
    out = tmp_path / "t.parquet"
    parts = run_sweep(spec, out=out, shard=(0, 1), progress=False)
    reads = Reads(monkeypatch)
    assert run_sweep(spec, out=out, combine=True, progress=False) == out
    assert reads.scanned == [f"part-0000{k}.parquet" for k in range(3)]
    assert reads.read == reads.scanned  # read once more to be written, one at a time
    assert out.read_bytes() == clean  # the same table as the parts held in memory give
    out.unlink()
    run_sweep(spec, out=out, shard=(0, 1), progress=False)
    names = sorted(p.name for p in parts.glob("part-*.parquet"))
    real = pq.read_table

    def changed(path, *args, **kwargs):  # part 1 as it is after its check: e_z changed
        table = real(path, *args, **kwargs)
        if getattr(path, "name", "") != "part-00001.parquet":
            return table
        e_z = table["e_z"].to_pylist()
        e_z[0] += 1e-3
        k = table.schema.get_field_index("e_z")
        return table.set_column(k, table.schema.field(k), pa.array(e_z))
    monkeypatch.setattr(pq, "read_table", changed)
    with pytest.raises(ValueError, match="do not give the content hash") as info:
        run_sweep(spec, out=out, combine=True, progress=False)
    assert "kept" in str(info.value) and "--resume" in str(info.value)
    assert not out.exists() and not list(tmp_path.glob(".*.tmp"))
    assert sorted(p.name for p in parts.glob("part-*.parquet")) == names  # kept


def test_a_written_table_that_fails_its_footer_check_keeps_the_parts(tmp_path):
    spec = write(tmp_path, GRID_KV.format(chunk=6))
    out = run_sweep(spec, out=tmp_path / "t.parquet", progress=False)
    digest = metadata.read_metadata(out)["content_sha256"]
    store._check_written(out, tmp_path, 6, digest)  # passes
    for rows, stored in ((6, "0" * 64), (7, digest)):
        with pytest.raises(ValueError, match="fails its check") as info:
            store._check_written(out, tmp_path / "t.parquet.parts", rows, stored)
        assert "kept" in str(info.value) and "\n" not in str(info.value)
    faults.truncate(out, 0.9)
    with pytest.raises(ValueError, match="truncated"):
        store._check_written(out, None, 6, digest)


def test_full_disk_in_a_one_chunk_sweep_says_nothing_is_kept(tmp_path, monkeypatch, capsys):
    spec = write(tmp_path, GRID_KV.format(chunk=6))
    out = tmp_path / "t.parquet"
    disk = faults.FullDisk(files_ok=0)
    monkeypatch.setattr(files, "open", disk, raising=False)
    capsys.readouterr()
    assert cli.main(["sweep", str(spec), "--out", str(out)]) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if "rows/s" not in line]
    assert len(err) == 1 and "No space left on device" in err[0], err
    assert "nothing is kept" in err[0] and "make room" in err[0]
    assert disk.failures >= 1 and not out.exists() and not list(tmp_path.glob(".*.tmp"))
    monkeypatch.undo()
    assert cli.main(["sweep", str(spec), "--out", str(out)]) == 0
    assert integrity.verify_table(out).endswith("content hash verified")


def test_a_write_from_memory_needs_every_chunk(tmp_path):
    spec = load_spec(write(tmp_path, GRID_KV.format(chunk=2)))
    table = spec.schema().empty_table()
    with pytest.raises(ValueError, match="from all its chunks"):
        store.combine(spec, tmp_path / "p", tmp_path / "t.parquet", dict,
                      fresh=[(table, {"counts": {}, "paths": {}})])
